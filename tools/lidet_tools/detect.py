# SPDX-License-Identifier: MIT
"""Run the detector (`lidet detect`, the host CLI: exactly what the firmware computes) over a KITTI-format
folder and write a prediction folder that `lidet-eval kitti` / `lidet-eval boxes` score.

    python -m lidet_tools.detect KITTI_DIR --out PRED_DIR [--sensor hdl64] [--crop] [--model NAME] [--fixed [--range-only] [--returns]] [--ring] [--mount-height M]
        [--jobs 2]

KITTI_DIR holds velodyne/<id>.bin and, for label_2 output, calib/<id>.txt. PRED_DIR receives label_2/<id>.txt
(camera frame, 2D box from the projected corners; only when calib/ exists), boxes/<id>.txt (lidet's
sensor-frame lines) and timing.json (per-frame `lidet detect --json` stage times).
"""
from __future__ import annotations

import argparse
import concurrent.futures as cf
import json
import os
import pathlib
import re
import subprocess
import sys

ROOT = pathlib.Path(__file__).resolve().parents[2]


def find_cli() -> pathlib.Path:
    """The host CLI of $LIDET_BUILD_DIR, else build/."""
    exe = pathlib.Path(os.environ.get("LIDET_BUILD_DIR", ROOT / "build")) / "ports" / "host" / "lidet"
    if not exe.exists():
        raise FileNotFoundError(f"{exe} not built (make build, or set LIDET_BUILD_DIR)")
    return exe


def detect_frame(exe, bin_path, out_dir, calib=None, sensor="hdl64", crop=False, model=None, extra=()) -> dict:
    """One frame: writes boxes/<id>.txt (and label_2/<id>.txt with calib); returns the CLI's JSON."""
    fid = pathlib.Path(bin_path).stem
    out_dir = pathlib.Path(out_dir)
    cmd = [str(exe), "detect", str(bin_path), "--sensor", sensor, "--json",
           "--out", str(out_dir / "boxes" / f"{fid}.txt")]
    if calib is not None:
        cmd += ["--calib", str(calib), "--kitti-out", str(out_dir / "label_2" / f"{fid}.txt")]
    if crop:
        cmd.append("--crop")
    if model:
        cmd += ["--model", model]
    cmd += list(extra)
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)}\n{r.stderr.strip()}")
    js = json.loads(r.stdout)
    js["warnings"] = [w for w in r.stderr.splitlines() if ": warning: " in w]
    return js


def run_folder(kitti_dir, out_dir, sensor="hdl64", crop=False, model=None, jobs=1, extra=(), progress=True,
               ring=False) -> list:
    """Every velodyne/*.bin of kitti_dir; ring: with each scan's ring/<id>.bin (an error where one is missing)."""
    kitti_dir, out_dir = pathlib.Path(kitti_dir), pathlib.Path(out_dir)
    scans = sorted((kitti_dir / "velodyne").glob("*.bin"))
    if not scans:
        raise FileNotFoundError(f"no scans in {kitti_dir / 'velodyne'}")
    (out_dir / "boxes").mkdir(parents=True, exist_ok=True)
    have_calib = (kitti_dir / "calib").is_dir()
    if have_calib:
        (out_dir / "label_2").mkdir(parents=True, exist_ok=True)
    exe = find_cli()

    def one(p):
        calib = kitti_dir / "calib" / f"{p.stem}.txt" if have_calib else None
        if calib is not None and not calib.exists():
            raise FileNotFoundError(f"{calib} missing for {p}")
        more = list(extra)
        if ring:
            rp = kitti_dir / "ring" / f"{p.stem}.bin"
            if not rp.exists():
                raise FileNotFoundError(f"{rp} missing for {p} (--ring)")
            more += ["--ring", str(rp)]
        return p.stem, detect_frame(exe, p, out_dir, calib, sensor, crop, model, more)

    results, warned = [], []
    it = scans
    try:
        from tqdm import tqdm
        bar = tqdm(total=len(scans), desc="lidet detect", disable=not progress)
    except ImportError:  # pragma: no cover
        bar = None
    with cf.ThreadPoolExecutor(max_workers=max(1, jobs)) as ex:
        for fid, js in ex.map(one, it):
            results.append(dict(frame=fid, **{k: v for k, v in js.items() if k not in ("boxes", "warnings")},
                                n_boxes=len(js.get("boxes", []))))
            warned.extend((fid, w) for w in js.get("warnings", []))
            if bar is not None:
                bar.update(1)
    if bar is not None:
        bar.close()
    (out_dir / "timing.json").write_text(json.dumps(results, indent=1))
    _summarise_warnings(warned, len(scans))
    return results


def _summarise_warnings(warned: list, n_scans: int) -> None:
    """The CLI's warnings (a cloud in another frame, a mount height the ground refuses), once per kind with how many
    scans drew it, on stderr: the per-scan runs capture the CLI's stderr."""
    kinds: dict = {}
    for fid, w in warned:
        key = re.sub(r"[-+]?\d[\d.]*", "#", w)  # the same warning with other counts
        kinds.setdefault(key, []).append((fid, w))
    for hits in kinds.values():
        fid, w = hits[0]
        print(f"lidet_tools.detect: {len(hits)} of {n_scans} scans warned, the first ({fid}): {w}", file=sys.stderr)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m lidet_tools.detect", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("kitti_dir", help="folder with velodyne/ (and calib/ for label_2 output)")
    ap.add_argument("--out", required=True, help="prediction folder (label_2/, boxes/, timing.json)")
    ap.add_argument("--sensor", default="hdl64")
    ap.add_argument("--crop", action="store_true", help="KITTI camera field of view only (|azimuth| <= 45 deg)")
    ap.add_argument("--model", help="model family (weights cls_NAME + box_NAME); default: the sensor's")
    ap.add_argument("--jobs", type=int, default=1, help="frames in parallel (one process each)")
    ap.add_argument("--set", action="append", default=[], help="KEY=VALUE passed to lidet detect --set")
    ap.add_argument("--fixed", action="store_true", help="the integer detector (lidet detect --fixed: int8 models)")
    ap.add_argument("--range-only", action="store_true",
                    help="with --fixed: the integer firmware's range-only pixel (lidet detect --range-only)")
    ap.add_argument("--returns", action="store_true",
                    help="with --fixed and --ring: each scan fed as the sensor's returns (range, azimuth, ring), as "
                         "the integer firmware takes it (lidet detect --returns)")
    ap.add_argument("--ring", action="store_true",
                    help="pass each scan's ring indices (KITTI_DIR/ring/<id>.bin, uint16 per point: lidet-sim "
                         "writes them) as the firmware's driver does (lidet detect --ring)")
    ap.add_argument("--mount-height", type=float, metavar="M",
                    help="the sensor's height above the ground in m (default: the sensor profile's)")
    a = ap.parse_args(argv)
    if a.range_only and not a.fixed:
        ap.error("--range-only is a setting of the integer detector: add --fixed")
    extra = [x for kv in a.set for x in ("--set", kv)] + (["--fixed"] if a.fixed else [])
    extra += ["--range-only"] if a.range_only else []
    if a.returns and not (a.fixed and a.ring):
        ap.error("--returns feeds the integer detector the scan's returns: add --fixed and --ring")
    extra += ["--returns"] if a.returns else []
    if a.mount_height is not None:
        extra += ["--mount-height", repr(a.mount_height)]
    try:
        res = run_folder(a.kitti_dir, a.out, a.sensor, a.crop, a.model, a.jobs, extra, ring=a.ring)
    except (FileNotFoundError, RuntimeError) as e:
        print(f"lidet_tools.detect: error: {e}", file=sys.stderr)
        return 1
    tot = sorted(r["total_ms"] for r in res)
    print(f"{len(res)} frames -> {a.out}: {sum(r['n_boxes'] for r in res)} detections, "
          f"median total_ms {tot[len(tot) // 2]:.2f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
