# SPDX-License-Identifier: MIT
"""Run trackers over simulated sequences and compare them (issue 38): lidet's tracker
(lidet_tools.track.native.Tracker, the C float tracker) against the AB3DMOT-style peer (peer.py), fed the same
detections, scored by eval.py.

    python -m lidet_tools.track.run SEQ_DIR [SEQ_DIR ...] [--source detector|gt|both] [--out PRED_DIR] [--json F]

SEQ_DIR: sequence folders of `lidet-sim --sequence` (velodyne/, tracks/, poses.txt, meta.json). Detections:

* `detector`: lidet's C detector (lidet_tools.native.detect, the float models of the sequence's sensor, liblidet_py.so
  of $LIDET_BUILD_DIR or build/) on every scan;
* `gt`: the ground truth's Car / Cyclist / Pedestrian boxes with >= `min_points` points, with noise and dropouts
  (`GtNoise`: centre, size and yaw noise, heading flips, missed detections, false positives; seeded), a check
  that does not depend on the detector.

Both trackers get per scan the (n, 9) detections (cls, x, y, z, l, w, h, yaw, score; sensor frame), dt from
poses.txt and the ego motion (dx, dy, dyaw) from poses.txt (--no-ego: none), and report their confirmed tracks of
the scan (flags 0). With --out, each tracker's tracks go to PRED_DIR/<source>/<tracker>/<seq>/tracks/<frame>.txt
(`lidet-eval track` reads them). The table gives each tracker's metrics and the ratio lidet / peer.
"""
from __future__ import annotations

import argparse
import json
import pathlib
import sys
import time
from dataclasses import dataclass, field

import numpy as np

from . import eval as tev
from .peer import PeerTracker

#: lidet_class_t: the detector's and trackers' class indices
CLS_INDEX = {"Car": 0, "Cyclist": 1, "Pedestrian": 2}


@dataclass
class Sequence:
    path: pathlib.Path
    meta: dict
    poses: np.ndarray            # (F, 8) frame t x y yaw dx dy dyaw
    names: list                  # frame file stems
    gt: list                     # eval frame dicts (read_tracks)

    @property
    def name(self) -> str:
        return self.path.name

    def dts(self) -> np.ndarray:
        t = self.poses[:, 1]
        return np.r_[self.meta["dt_s"], np.diff(t)]

    def egos(self, use_ego: bool = True) -> list:
        if not use_ego:
            return [None] * len(self.names)
        return [None] + [self.poses[k, 5:8].copy() for k in range(1, len(self.names))]


def load_sequence(seq_dir) -> Sequence:
    from ..sim.sequence import read_poses
    d = pathlib.Path(seq_dir)
    meta = json.loads((d / "meta.json").read_text())
    poses = read_poses(d / "poses.txt")
    names = [p.stem for p in sorted((d / "tracks").glob("*.txt"))]
    if len(names) != len(poses):
        raise ValueError(f"{d}: {len(names)} tracks files for {len(poses)} poses")
    return Sequence(d, meta, poses, names, tev.load_gt(d))


# ------------------------------------------------------------------------------------------------
# detections


def detect_sequence(seq: Sequence, model: str | None = None) -> list:
    """lidet's C detector on every scan of the sequence -> per scan an (n, 9) float32 array."""
    from .. import kitti, native
    out = []
    for n in seq.names:
        pts = kitti.read_bin(seq.path / "velodyne" / f"{n}.bin")
        det = native.detect(pts, seq.meta["sensor"], model=model, mount_height_m=seq.meta["mount"]["height_m"])
        d = np.zeros((len(det.cls), 9), np.float32)
        d[:, 0] = det.cls
        d[:, 1:8] = det.box
        d[:, 8] = det.score
        out.append(d)
    return out


@dataclass
class GtNoise:
    """Detections made from ground truth: per class centre noise (m, per axis), size noise (relative), yaw noise
    (rad), heading flips (probability), missed detections (probability), false positives (Poisson mean per scan,
    uniform within fp_range_m, class by fp_class_p)."""
    sigma_xy: dict = field(default_factory=lambda: {0: 0.15, 1: 0.12, 2: 0.10})
    sigma_z: float = 0.05
    sigma_size: float = 0.04
    sigma_yaw: float = 0.05
    p_flip: dict = field(default_factory=lambda: {0: 0.05, 1: 0.1, 2: 0.3})
    p_drop: float = 0.1
    fp_rate: float = 0.5
    fp_range_m: float = 40.0
    fp_class_p: tuple = (0.4, 0.2, 0.4)
    min_points: int = tev.MIN_POINTS
    seed: int = 0


_FP_SIZE = {0: (4.3, 1.8, 1.5), 1: (1.8, 0.6, 1.7), 2: (0.8, 0.65, 1.75)}


def gt_detections(seq: Sequence, noise: GtNoise = GtNoise(), seq_index: int = 0) -> list:
    """Per scan an (n, 9) float32 array of noisy ground-truth detections (deterministic: seed, seq_index)."""
    rng = np.random.default_rng(np.random.SeedSequence([int(noise.seed), int(seq_index), 38]))
    out = []
    for f in seq.gt:
        rows = []
        for i in range(len(f["id"])):
            c = CLS_INDEX.get(str(f["cls"][i]))
            u = rng.random(6)
            g = rng.standard_normal(7)
            if c is None or f["npts"][i] < noise.min_points or u[0] < noise.p_drop:
                continue
            x, y, z, l, w, h, yaw = f["box"][i]
            s = noise.sigma_xy[c]
            yaw = yaw + noise.sigma_yaw * g[3] + (np.pi if u[1] < noise.p_flip[c] else 0.0)
            rows.append([c, x + s * g[0], y + s * g[1], z + noise.sigma_z * g[2],
                         l * (1 + noise.sigma_size * g[4]), w * (1 + noise.sigma_size * g[5]),
                         h * (1 + noise.sigma_size * g[6]), (yaw + np.pi) % (2 * np.pi) - np.pi, 0.5 + 0.5 * u[2]])
        for _ in range(int(rng.poisson(noise.fp_rate))):
            c = int(rng.choice(3, p=noise.fp_class_p))
            r, a = noise.fp_range_m * np.sqrt(rng.random()), rng.uniform(-np.pi, np.pi)
            l, w, h = _FP_SIZE[c]
            rows.append([c, r * np.cos(a), r * np.sin(a), -0.8, l, w, h, rng.uniform(-np.pi, np.pi),
                         0.3 + 0.4 * rng.random()])
        out.append(np.asarray(rows, np.float32).reshape(-1, 9))
    return out


# ------------------------------------------------------------------------------------------------
# trackers


def lidet_factory():
    """lidet's C float tracker, or raises with the reason it is not available."""
    from .native import Tracker
    Tracker()                       # fails here when liblidet_py.so has no tracker
    return lambda: Tracker(fixed=False)


def default_trackers() -> tuple[dict, dict]:
    """({name: factory}, {name: why not available}): lidet (when its bindings are built) and the peer."""
    have, missing = {}, {}
    try:
        have["lidet"] = lidet_factory()
    except Exception as e:  # noqa: BLE001 (an old build, no library, a missing symbol: say why, run the rest)
        missing["lidet"] = f"{type(e).__name__}: {e}"
    have["peer"] = PeerTracker
    return have, missing


def run_tracker(tracker, dets: list, dts, egos, flags: int = 0) -> tuple[list, float]:
    """Feeds one sequence; returns (per scan the tracker's output, mean ms per update)."""
    outs = []
    t0 = time.perf_counter()
    for d, dt, e in zip(dets, dts, egos):
        outs.append(tracker.update(d, float(dt), e, flags))
    ms = (time.perf_counter() - t0) * 1000.0 / max(len(dets), 1)
    return outs, ms


def run(seqs: list, dets_by_seq: list, trackers: dict, use_ego: bool = True, out_dir=None, eval_kw=None) -> dict:
    """Every tracker over every sequence with the same detections -> {name: eval result + "ms_per_scan"}."""
    res = {}
    for name, make in trackers.items():
        pairs, ms = [], []
        for seq, dets in zip(seqs, dets_by_seq):
            tr = make()
            outs, m = run_tracker(tr, dets, seq.dts(), seq.egos(use_ego))
            ms.append(m)
            pairs.append((seq.gt, outs))
            if out_dir is not None:
                for n, o in zip(seq.names, outs):
                    tev.write_tracks(pathlib.Path(out_dir) / name / seq.name / "tracks" / f"{n}.txt", o)
        r = tev.evaluate(pairs, names=[s.name for s in seqs], **(eval_kw or {}))
        r["ms_per_scan"] = float(np.mean(ms)) if ms else None
        res[name] = r
    return res


def detection_stats(seqs, dets_by_seq) -> dict:
    n = sum(len(d) for ds in dets_by_seq for d in ds)
    f = sum(len(ds) for ds in dets_by_seq)
    return {"scans": f, "detections": n, "per_scan": n / max(f, 1)}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m lidet_tools.track.run", description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("seqs", nargs="+", help="sequence folders (lidet-sim --sequence)")
    ap.add_argument("--source", choices=("detector", "gt", "both"), default="both",
                    help="detections: lidet's C detector, noisy ground truth, or both (default)")
    ap.add_argument("--model", help="detector model family (default: the sensor's)")
    ap.add_argument("--no-ego", action="store_true", help="give the trackers no ego motion")
    ap.add_argument("--out", help="write each tracker's tracks under OUT/<source>/<tracker>/<seq>/tracks/")
    ap.add_argument("--json", help="write the results to this JSON file")
    ap.add_argument("--range", type=float, default=tev.MAX_RANGE_M, help="evaluation range (m, default 40)")
    ap.add_argument("--min-points", type=int, default=tev.MIN_POINTS, help="ground truth with fewer points is ignored")
    ap.add_argument("--noise-seed", type=int, default=0, help="seed of the noisy ground-truth detections")
    ap.add_argument("--drop", type=float, default=GtNoise.p_drop, help="gt source: missed-detection probability")
    ap.add_argument("--fp-rate", type=float, default=GtNoise.fp_rate, help="gt source: false positives per scan")
    ap.add_argument("--trackers", default="lidet,peer", help="comma list of lidet, peer")
    a = ap.parse_args(argv)
    try:
        seqs = [load_sequence(s) for s in a.seqs]
    except (OSError, ValueError) as e:
        print(f"track.run: error: {e}", file=sys.stderr)
        return 2
    have, missing = default_trackers()
    want = [t.strip() for t in a.trackers.split(",") if t.strip()]
    trackers = {k: have[k] for k in want if k in have}
    for k in want:
        if k in missing:
            print(f"track.run: {k} tracker not available ({missing[k]}); running {', '.join(trackers)}",
                  file=sys.stderr)
    sources = ("detector", "gt") if a.source == "both" else (a.source,)
    kw = {"max_range_m": a.range, "min_points": a.min_points}
    report = {"sequences": [str(s.path) for s in seqs], "frames": sum(len(s.names) for s in seqs),
              "unavailable": missing, "results": {}}
    for src in sources:
        t0 = time.perf_counter()
        if src == "detector":
            try:
                dets = [detect_sequence(s, a.model) for s in seqs]
            except (FileNotFoundError, OSError, KeyError) as e:
                print(f"track.run: detector not available ({e}); skipping --source detector", file=sys.stderr)
                continue
        else:
            nz = GtNoise(p_drop=a.drop, fp_rate=a.fp_rate, seed=a.noise_seed, min_points=a.min_points)
            dets = [gt_detections(s, nz, i) for i, s in enumerate(seqs)]
        t_det = time.perf_counter() - t0
        out = pathlib.Path(a.out) / src if a.out else None
        res = run(seqs, dets, trackers, use_ego=not a.no_ego, out_dir=out, eval_kw=kw)
        ds = detection_stats(seqs, dets)
        title = (f"source '{src}': {len(seqs)} sequences, {ds['scans']} scans, {ds['per_scan']:.1f} detections/scan "
                 f"({t_det:.1f} s); range {a.range:g} m, >= {a.min_points} points; "
                 + ", ".join(f"{k} {r['ms_per_scan']:.2f} ms/scan" for k, r in res.items()))
        print(tev.compare_table(res, title))
        print()
        report["results"][src] = {"detections": ds, **res}
    if a.json:
        pathlib.Path(a.json).write_text(json.dumps(report, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
