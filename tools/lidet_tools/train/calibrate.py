# SPDX-License-Identifier: MIT
"""int8 calibration of lidet's PointNets: the calibration file (<name>.calib.json) `python -m lidet_codegen emit
--int8` reads (docs/FIXED_POINT.md, section "int8 PointNets").

    python -m lidet_tools.train.calibrate weights/cls_hdl64.onnx --sensor hdl64 --out weights/cls_hdl64.calib.json
    python -m lidet_tools.train.calibrate --refit weights/cls_hdl64.onnx     # add the classifier's head_refit
    python -m lidet_tools.train.calibrate --report weights/cls_hdl64.onnx    # each int8 layer's error against float

The calibration proposals come from scans: the simulated sample of the sensor, freshly simulated scans
(lidet_tools.sim) and the real KITTI scans of the training side (or the user's own, --scans), through the C stages
(lidet_tools.native: ground, clustering, proposals) with fixed resampling seeds. The ranges, the refit and the
int8 model itself are lidet_codegen.quant's (activation_ranges, head_refit, quantize), from those proposals.
"""
from __future__ import annotations

import argparse
import hashlib
import json
import pathlib
import sys

import numpy as np

from lidet_codegen import quant as Q
from lidet_codegen.emit import EmitError, load

ROOT = pathlib.Path(__file__).resolve().parents[3]
CALIB_SEEDS = [0xCA11B000 + 7919 * k for k in range(4)]

#: freshly simulated scans added to the calibration set (seed 3015: neither training, the benchmarks, the tests
#: nor the refit use it): the shipped sample alone gave the VLP-16 232 proposals. With them and the refit on 32
#: scans, the raw argmax agreement of tests/python/test_pointnet_q.py went from 98.66 to 98.84 %
#: (docs/journal/fixed-point.md, "Agreement with float, and what was tried for it")
CALIB_SIM_SEED, CALIB_N_SIM = 3015, 8

#: the classifier's last-layer refit (`calibrate --refit`): fresh simulated scans (seed 3016: neither training,
#: the benchmarks nor the tests use it) added to the calibration proposals; the ridge weight toward the float layer
#: is lidet_codegen.quant.REFIT_MU. Measured on the test proposals of tests/python/test_pointnet_q.py
#: (docs/journal/fixed-point.md, "The classifier's last layer, refitted").
REFIT_SIM_SEED, REFIT_N_SIM = 3016, 32


def scan_list(sensor: str, real_dir=None, scan_dirs=None):
    """The calibration scans: the simulated sample of the sensor, then the real ones: with `scan_dirs` (folders
    holding velodyne/*.bin: a user's own scans, `calibrate --scans`) every scan of those, else for hdl64 the KITTI
    scans under real_dir/kitti/ less the validation frames of tools/lidet_tools/real/split.txt (the real-frame
    figures are measured on those; nothing that builds a model reads them). kitti/unlabeled/ holds KITTI object
    training scans under their own ids (000006-000010 are the files of training/), so the rule goes by id in both.
    A sensor without a shipped sample (tests/data/sim_<sensor>: hdl64 and vlp16 have one) calibrates on the freshly
    simulated scans alone."""
    sample = ROOT / f"tests/data/sim_{sensor}/velodyne/000000.bin"
    scans = [sample] if sample.exists() else []
    if scan_dirs:
        for d in scan_dirs:
            found = sorted(pathlib.Path(d, "velodyne").glob("*.bin"))
            if not found:
                raise EmitError(f"{d}: no velodyne/*.bin scans to calibrate on")
            scans += [f.resolve() for f in found]
    elif real_dir is not None and sensor == "hdl64":
        from lidet_tools.eval_real import read_split
        val = {f for src, f, side in read_split() if src == "kitti" and side == "val"}
        scans += [p for p in sorted(pathlib.Path(real_dir, "kitti").glob("*/velodyne/*.bin"))
                  if p.stem not in val]
    return scans


def proposals_of(scans, sensor: str, seeds, n_points: int = 64, z_origin: int = 0):
    """(xyz (B, N, 3) float32, mean (B, 3), voxel (B, 3) int16) of the scans (paths of KITTI .bin files, or
    point arrays) with every resampling seed; z_origin: the model's lidet_proposal_z_origin_t (mean: the origin)."""
    from lidet_tools import kitti, native
    xs, ms, vs = [], [], []
    for path in scans:
        pts = path if isinstance(path, np.ndarray) else kitti.read_bin(path)
        g = native.ground(pts, sensor)
        cl = native.cluster(pts, sensor, ground=g.mask_point, planes=g.planes)
        for s in seeds:
            p = native.proposals(cl, n_points=n_points, seed=s, z_origin=z_origin)
            xs.append(p.xyz)
            ms.append(p.mean)
            vs.append(p.voxel)
    return np.concatenate(xs), np.concatenate(ms), np.concatenate(vs)


def _sim_scans(sensor: str, seed: int, n: int, first: int = 0) -> list:
    """The points of simulated scans first .. first + n - 1 of a run seed (calibration and refit sets)."""
    from lidet_tools.sim.simulate import simulate_scan
    return [simulate_scan(sensor, seed, k).points for k in range(first, first + n)]


def calibrate(onnx_path, sensor: str, real_dir=None, seeds=CALIB_SEEDS, scan_dirs=None) -> dict:
    """The calibration file of a model (scan_list: with scan_dirs, the user's scans replace the real KITTI ones; they
    are recorded relative to the repository when inside it, else by absolute path)."""
    onnx_path = pathlib.Path(onnx_path)
    model = load(onnx_path, onnx_path.stem)
    scans = scan_list(sensor, real_dir, scan_dirs)
    sims = _sim_scans(sensor, CALIB_SIM_SEED, CALIB_N_SIM)
    xyz, mean, vox = proposals_of(scans + sims, sensor, seeds, model.n_points, model.z_origin)
    rng = Q.activation_ranges(model, xyz, mean, vox, onnx_path.parent)

    def rel(p):
        if p.is_relative_to(ROOT):
            return p.relative_to(ROOT).as_posix()
        return p.as_posix() if scan_dirs else "real/" + "/".join(p.parts[-3:])

    return {"model": onnx_path.stem, "onnx_sha256": hashlib.sha256(onnx_path.read_bytes()).hexdigest(),
            "sensor": sensor, "seeds": [int(s) for s in seeds], "percentile": rng["percentile"],
            "ranges_per": rng["ranges_per"],
            "scans": [rel(p) for p in scans] + [f"sim/{CALIB_SIM_SEED}/{k}" for k in range(CALIB_N_SIM)],
            "n_proposals": int(len(xyz)), "n_points": int(model.n_points), "ranges": rng["ranges"],
            **({"z_origin": int(model.z_origin)} if model.z_origin else {})}


def refit(onnx_path, calib: dict, real_dir=None) -> dict:
    """The calibration file with `head_refit`: the classifier's last layer refitted (lidet_codegen.quant.head_refit)
    on the calibration proposals plus those of REFIT_N_SIM fresh simulated scans."""
    onnx_path = pathlib.Path(onnx_path)
    model = load(onnx_path, onnx_path.stem)
    Q.refit_check(model, onnx_path)
    if calib.get("onnx_sha256") != hashlib.sha256(onnx_path.read_bytes()).hexdigest():
        raise EmitError(f"{onnx_path}: the calibration file is of another model: recalibrate")
    base = {k: v for k, v in calib.items() if k != "head_refit"}
    data = calib_set(base, real_dir)
    if data is None:
        raise EmitError("refit: the calibration scans are not available")
    sims = _sim_scans(calib["sensor"], REFIT_SIM_SEED, REFIT_N_SIM)
    extra = proposals_of(sims, calib["sensor"], calib["seeds"], model.n_points, model.z_origin)
    xyz, mean, vox = (np.concatenate([a, b]) for a, b in zip(data, extra))
    fit = Q.head_refit(model, base, xyz, mean, vox)
    return dict(base, head_refit=dict(fit, sim_seed=REFIT_SIM_SEED, n_sim=REFIT_N_SIM))


def calib_set(calib: dict, real_dir=None):
    """Regenerate the calibration proposals a calibration file names (None when a scan is missing), with the
    model's points per proposal (`n_points`; 64 in files written before it was recorded) and z origin (`z_origin`,
    recorded for a model whose proposals start at the ground; absent: the cluster mean)."""
    paths, sims = [], []
    for s in calib["scans"]:
        if s.startswith("sim/"):  # a freshly simulated scan: sim/<seed>/<index>
            _, seed, k = s.split("/")
            sims.append((int(seed), int(k)))
        elif s.startswith("real/"):
            if real_dir is None:
                return None
            paths.append(pathlib.Path(real_dir, "kitti", *s.split("/")[1:]))
        elif pathlib.PurePosixPath(s).is_absolute():  # a user's scan outside the repository (calibrate --scans)
            paths.append(pathlib.Path(s))
        else:
            paths.append(ROOT / s)
    if not all(p.exists() for p in paths):
        return None
    sim_pts = [p for seed, k in sims for p in _sim_scans(calib["sensor"], seed, 1, first=k)]
    return proposals_of(paths + sim_pts, calib["sensor"], calib["seeds"], int(calib.get("n_points", 64)),
                        int(calib.get("z_origin", 0)))


def report(onnx_path, calib_path, real_dir=None) -> list | None:
    """Each layer's error of the int8 model (the model quantized with its calibration file, as emit --int8 builds
    it) against float on the calibration proposals the file names: lidet_codegen.quant.layer_errors, printed.
    None (and a line saying so) when a scan of the set is not available."""
    onnx_path, calib_path = pathlib.Path(onnx_path), pathlib.Path(calib_path)
    calib = json.loads(calib_path.read_text())
    if calib.get("onnx_sha256") != hashlib.sha256(onnx_path.read_bytes()).hexdigest():
        raise EmitError(f"{calib_path}: calibrated on another {onnx_path.name} (sha256 differs): recalibrate")
    qm = Q.quantize(load(onnx_path, onnx_path.stem), calib)
    data = calib_set(calib, real_dir)
    print(f"{onnx_path} + {calib_path}: int8 {qm.kind}, per-layer error against float")
    if data is None:
        print("  per-layer error: skipped (calibration scans not available)")
        return None
    errs = Q.layer_errors(qm, *data, folder=onnx_path.parent)
    for nm, mx, mn in errs:
        print(f"  {nm:12s} max abs error {mx:.5f}  mean abs error {mn:.5f}")
    return errs


def _model_sensor(path) -> str:
    """The sensor a model was trained for: its ONNX metadata lidet.sensor (the family vlp16s says vlp16), else the
    name's suffix (cls_hdl64 -> hdl64)."""
    import onnx
    meta = {m.key: m.value for m in onnx.load(str(path), load_external_data=False).metadata_props}
    return meta.get("lidet.sensor") or pathlib.Path(path).stem.split("_")[-1]


def main(argv=None) -> int:
    """python -m lidet_tools.train.calibrate MODEL.onnx --sensor S --out FILE"""
    ap = argparse.ArgumentParser(prog="python -m lidet_tools.train.calibrate",
                                 description="per-tensor activation ranges of a model on proposals of the simulated "
                                             "sample scan (fixed resampling seeds) and the real scans when present")
    ap.add_argument("onnx", nargs="+")
    ap.add_argument("--sensor", help="hdl64 or vlp16 (default: the model's lidet.sensor metadata, else the model "
                                     "name's suffix)")
    ap.add_argument("--real", default=str(ROOT.parent / "shared" / "data" / "real"),
                    help="real scans folder (used when present; KITTI HDL-64 scans for hdl64 models)")
    ap.add_argument("--scans", action="append", default=None, metavar="DIR",
                    help="calibrate on the scans DIR/velodyne/*.bin (repeatable; e.g. the scans a model was fine-tuned "
                         "on) instead of the real KITTI scans of --real")
    ap.add_argument("--out", help="calibration file (default: beside the model, <name>.calib.json)")
    mode = ap.add_mutually_exclusive_group()
    mode.add_argument("--refit", action="store_true",
                      help="classifiers: keep the calibration file's ranges and add the refitted last layer "
                           "(head_refit; lidet_codegen.quant.head_refit)")
    mode.add_argument("--report", action="store_true",
                      help="write nothing: print each layer's error of the int8 model (the calibration file beside "
                           "the model, or --out) against float on the proposals that file names (needs its scans)")
    a = ap.parse_args(argv)
    real = pathlib.Path(a.real) if (pathlib.Path(a.real) / "kitti").exists() else None
    for d in a.scans or []:
        if not any(pathlib.Path(d, "velodyne").glob("*.bin")):
            ap.error(f"--scans {d}: no velodyne/*.bin scans there")
    for p in a.onnx:
        p = pathlib.Path(p)
        out = pathlib.Path(a.out) if a.out and len(a.onnx) == 1 else p.with_suffix(".calib.json")
        if a.report:
            report(p, out, real)
            continue
        if a.refit:
            cal = refit(p, json.loads(p.with_suffix(".calib.json").read_text()), real)
            print(f"{p} -> {out}: last layer refitted on {cal['head_refit']['n_proposals']} proposals")
        else:
            cal = calibrate(p, a.sensor or _model_sensor(p), real, scan_dirs=a.scans)
            print(f"{p} -> {out}: {cal['n_proposals']} proposals of {len(cal['scans'])} scans x "
                  f"{len(cal['seeds'])} seeds")
        out.write_text(json.dumps(cal, indent=1, sort_keys=True) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
