#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Ground segmentation: lidet versus Patchwork++ (pypatchworkpp, default parameters) and Open3D
`segment_plane` (0.2 m, 100 iterations), on the same scans, in one process pinned to one core.

* lidet is timed by the host CLI (`lidet ground SCAN --json --repeat N`): `ground_ms` is the median
  of the ground stage alone (lidet_ground_run), `total_ms` of projection + ground; file reading
  excluded. Its per-point mask comes from the same CLI call (`--out`). The CLI inherits this
  process's CPU affinity, so all three run on the same core.
* Patchwork++: median wall time of `estimateGround(points)` (the whole call, N repeats).
* Open3D: median wall time of `segment_plane` on a prepared PointCloud (construction excluded).
* Accuracy: precision / recall / IoU against SemanticKITTI labels (ground = 40, 44, 48, 49, 60, 72;
  IoU also with terrain 72 as non-ground), summed over every point of every scan.
* The filter comparison (paper S_u*R versus the authors' released S_u*Z + height gate) runs the CLI
  with `--set` overrides on the same scans.

Sets: the real labeled SemanticKITTI scans in ../shared/data/real/semantickitti (skipped when
absent) and simulated hdl64 / vlp16 scans from `lidet_tools.sim` (generated into data/ when the
simulator is installed; reported as pending otherwise). Runnable alone:
`python tools/bench/bench_ground.py --build build --real ../shared/data/real [--quick]`.
"""
from __future__ import annotations

import json
import os
import pathlib
import statistics
import subprocess
import sys
import tempfile
import time

os.environ.setdefault("OMP_NUM_THREADS", "1")  # Open3D: one thread, like the others

import numpy as np  # noqa: E402

ROOT = pathlib.Path(__file__).resolve().parents[2]
sys.path[:0] = [str(ROOT / "tools"), str(ROOT / "codegen")]

from lidet_tools import ground_eval, kitti  # noqa: E402

SIM_SCENES = 20
SIM_SEED = 2026


def _pin_one_core() -> str:
    try:
        cores = sorted(os.sched_getaffinity(0))
        os.sched_setaffinity(0, {cores[-1]})
        return f"core {cores[-1]}"
    except (AttributeError, OSError):
        return "unpinned"


def _lidet_cli(build) -> pathlib.Path:
    return pathlib.Path(build) / "ports" / "host" / "lidet"


def run_lidet(build, scan, sensor, repeat, sets=()):
    """(json, per-point bool mask) of one CLI call."""
    with tempfile.TemporaryDirectory() as td:
        out = pathlib.Path(td) / "mask.bin"
        cmd = [str(_lidet_cli(build)), "ground", str(scan), "--sensor", sensor, "--json", "--repeat", str(repeat),
               "--out", str(out)]
        for kv in sets:
            cmd += ["--set", kv]
        j = json.loads(subprocess.run(cmd, check=True, capture_output=True, text=True).stdout)
        return j, np.fromfile(out, np.uint8).astype(bool)


def _patchwork(sensor_height):
    try:
        import pypatchworkpp
    except ImportError:
        return None
    p = pypatchworkpp.Parameters()
    p.verbose = False
    if sensor_height is not None:
        p.sensor_height = sensor_height
    pw = pypatchworkpp.patchworkpp(p)

    def predict(pts, repeat):
        ts = []
        for _ in range(repeat):
            t0 = time.perf_counter()
            pw.estimateGround(pts)
            ts.append((time.perf_counter() - t0) * 1e3)
        mask = np.zeros(len(pts), bool)
        mask[np.asarray(pw.getGroundIndices(), np.int64)] = True
        return statistics.median(ts), mask
    return predict


def _open3d():
    try:
        import open3d as o3d
    except ImportError:
        return None
    try:
        o3d.utility.random.seed(0)
    except AttributeError:
        pass

    def predict(pts, repeat):
        pc = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(pts[:, :3].astype(np.float64)))
        ts, inl = [], []
        for _ in range(repeat):
            t0 = time.perf_counter()
            _, inl = pc.segment_plane(distance_threshold=0.2, ransac_n=3, num_iterations=100)
            ts.append((time.perf_counter() - t0) * 1e3)
        mask = np.zeros(len(pts), bool)
        mask[np.asarray(inl, np.int64)] = True
        return statistics.median(ts), mask
    return predict


def _acc():
    return {d: np.zeros(4, np.int64) for d in ground_eval.DEFINITIONS}


def _add(acc, pred, sem):
    for d in acc:
        acc[d] += ground_eval.confusion(pred, ground_eval.ground_truth(sem, d))


def compare_set(build, pairs, sensor, mount, repeat):
    """Rows of the side-by-side table for one set of labeled scans."""
    methods = {"lidet": None}
    pw, o3 = _patchwork(mount if sensor != "hdl64" else None), _open3d()
    if pw:
        methods["Patchwork++"] = pw
    if o3:
        methods["Open3D segment_plane"] = o3
    acc = {m: _acc() for m in methods}
    ms = {m: [] for m in methods}
    tot = []
    for b, lab in pairs:
        pts = kitti.read_bin(b)
        sem, _ = kitti.read_label(lab, len(pts))
        j, mask = run_lidet(build, b, sensor, repeat)
        ms["lidet"].append(j["ground_ms"])
        tot.append(j["total_ms"])
        _add(acc["lidet"], mask, sem)
        for m, fn in methods.items():
            if fn is None:
                continue
            t, mk = fn(pts, max(3, repeat // 10))
            ms[m].append(t)
            _add(acc[m], mk, sem)
    out = {}
    for m in methods:
        out[m] = {"ms": statistics.median(ms[m]), **{d: ground_eval.metrics(acc[m][d]) for d in acc[m]}}
    out["lidet"]["total_ms"] = statistics.median(tot)
    return out


def _table(res, label):
    lid = res["lidet"]
    lines = [f"**{label}**", "",
             "| method | P | R | Acc | IoU | IoU (terrain = not ground) | median ms/scan | ratio (peer ms / lidet ms) |",
             "|---|---:|---:|---:|---:|---:|---:|---|"]
    for m, r in res.items():
        a, b = r["with_terrain"], r["no_terrain"]
        if m == "lidet":
            timing = f"{r['ms']:.3f} (ground) / {r['total_ms']:.3f} (projection + ground)"
            ratio = "1"
        else:
            timing = f"{r['ms']:.2f}"
            ratio = (f"**{r['ms'] / lid['ms']:.0f}x** vs ground stage, {r['ms'] / lid['total_ms']:.1f}x vs "
                     "projection + ground")
        lines.append(f"| {m} | {a['precision']:.3f} | {a['recall']:.3f} | {a['accuracy']:.3f} | {a['iou']:.3f} | "
                     f"{b['iou']:.3f} | {timing} | {ratio} |")
    return lines


PURE = ["sample_step=1", "sample_col_step=1", "ring_split_m=0", "veto_slope=0", "ground_m=0.2", "below_factor=1"]
FILTERS = {
    "lidet defaults: paper filter F_x = S_u*R": [],
    "defaults, released F_x = S_u*Z, no gate": ["fx_on_z=1"],
    "defaults, released filter F_x = S_u*Z + height gate": ["fx_on_z=1", "height_gate=1"],
    "defaults, paper filter + height gate": ["height_gate=1"],
    "defaults without the vertical veto": ["veto_slope=0"],
    "defaults without the near/far split": ["ring_split_m=0"],
    "paper as published (every pixel, 1 plane/sector, abs(d) < 0.2 m, no veto)": PURE,
    "released as published (same, S_u*Z + height gate)": PURE + ["fx_on_z=1", "height_gate=1"],
}


def filter_table(build, pairs, sensor, repeat):
    lines = ["| filter variant (`--set`) | P | R | IoU | IoU (terrain = not ground) | samples/scan | ground_ms |",
             "|---|---:|---:|---:|---:|---:|---:|"]
    for name, sets in FILTERS.items():
        acc, ms, smp = _acc(), [], []
        for b, lab in pairs:
            sem, _ = kitti.read_label(lab)
            j, mask = run_lidet(build, b, sensor, repeat, sets)
            _add(acc, mask, sem)
            ms.append(j["ground_ms"])
            smp.append(j["samples"])
        a, n = ground_eval.metrics(acc["with_terrain"]), ground_eval.metrics(acc["no_terrain"])
        lines.append(f"| {name} {' '.join('`' + s + '`' for s in sets) if len(sets) < 4 else ''} | {a['precision']:.3f} | {a['recall']:.3f} | "
                     f"{a['iou']:.4f} | {n['iou']:.4f} | {statistics.mean(smp):.0f} | {statistics.median(ms):.3f} |")
    return lines


def sim_pairs(sensor, n):
    """Labeled simulated scans in data/sim_ground_<sensor> (generated once); [] without the simulator."""
    d = ROOT / "data" / f"sim_ground_{sensor}"
    pairs, _ = ground_eval.find_scans([d]) if d.exists() else ([], [])
    if len(pairs) >= n:
        return pairs[:n]
    try:
        from lidet_tools.sim import cli as simcli
    except ImportError:
        return []
    simcli.main(["--sensor", sensor, "--scenes", str(n), "--seed", str(SIM_SEED), "--out", str(d)])
    pairs, _ = ground_eval.find_scans([d])
    return pairs[:n]


def _sets(args, quick, lines):
    """The labeled scan sets: (sensor, mount, pairs, label); notes about missing ones go to lines."""
    real_pairs, _ = ground_eval.find_scans([pathlib.Path(args.real) / "semantickitti"])
    sets = []
    if real_pairs:
        sets.append(("hdl64", 1.73, real_pairs, f"Real SemanticKITTI, sequence 00 scans "
                     f"{', '.join(p[0].stem for p in real_pairs)} (hdl64)"))
    else:
        lines += ["Real SemanticKITTI scans not present (../shared/data/real/semantickitti): skipped.", ""]
    for sensor, mount in (("hdl64", 1.73), ("vlp16", 0.5)):
        pairs = sim_pairs(sensor, 5 if quick else SIM_SCENES)
        if pairs:
            sets.append((sensor, mount, pairs, f"Simulated {sensor} (lidet-sim --sensor {sensor} --scenes {len(pairs)} "
                         f"--seed {SIM_SEED})"))
        else:
            lines += [f"Simulated {sensor} scans: pending (lidet_tools.sim not available in this checkout).", ""]
    return sets


def run(args) -> str:
    quick = getattr(args, "quick", False)
    repeat = 10 if quick else 50
    core = _pin_one_core()
    build = pathlib.Path(args.build)
    lines = ["## Ground segmentation (issue 5)", ""]
    if not _lidet_cli(build).exists():
        return "\n".join(lines + [f"`{_lidet_cli(build)}` not built: skipped.", ""])
    missing = [n for n, f in (("Patchwork++ (pypatchworkpp)", _patchwork(None)), ("Open3D", _open3d())) if f is None]
    if missing:
        lines += [f"Not importable here, rows skipped: {', '.join(missing)} (`pip install -r requirements-bench.txt`).", ""]
    sets = _sets(args, quick, lines)
    results = {}
    filter_sets = []
    for sensor, mount, pairs, label in sets:
        res = compare_set(build, pairs, sensor, mount, repeat)
        results[label] = res
        lines += _table(res, label) + [""]
        if sensor == "hdl64":
            filter_sets.append((pairs, label))
    lines += [f"Command: `make bench` (or `python tools/bench/bench_ground.py --build build --real ../shared/data/real`); "
              f"one process pinned to one core ({core}), Open3D with OMP_NUM_THREADS=1. lidet: "
              f"`build/ports/host/lidet ground SCAN --sensor S --json --repeat {repeat} --out MASK`, median of "
              f"`ground_ms` (the stage alone) and of `total_ms` (projection + ground) per scan, then the median over "
              "scans; Patchwork++: median wall time of `estimateGround` (whole call, default `Parameters()`; "
              "`sensor_height` set to the profile's mount height for the non-hdl64 sets); Open3D: median wall time of "
              "`segment_plane(0.2, 3, 100)` (point-cloud construction excluded). P/R/Acc/IoU over every point of "
              "every scan of the set, ground = SemanticKITTI 40, 44, 48, 49, 60, 72.", ""]
    for pairs, label in filter_sets:
        lines += [f"**Sample filter: the paper versus the authors' released code, and what each lidet extension "
                  f"adds: {label}** (`--set` overrides of the defaults; \"as published\" = `"
                  + " ".join(PURE) + "`)", ""] + filter_table(build, pairs, "hdl64", max(5, repeat // 5)) + [""]
    lines += q_table(sets, repeat)
    return "\n".join(lines)


def q_table(sets, repeat):
    """The integer ground stage (lidet_ground_q, issue 16) next to the float one on the same compact images (the
    float projection's compact path, as a detector workspace): share of points with equal ground labels, IoU of
    each against the labels, host medians of each stage alone (interleaved in one process)."""
    try:
        from lidet_tools import native
        native.ground_q_fields()
    except (ImportError, OSError, FileNotFoundError) as e:
        return [f"Integer ground stage: bindings not available ({e}): skipped.", ""]
    lines = ["**Integer ground stage (`lidet_ground_q`) next to the float one, same compact images**", "",
             "| set | scans | points | ground labels equal | IoU float | IoU integer | float ms (median / min) | "
             "integer ms (median / min) |",
             "|---|---:|---:|---:|---:|---:|---:|---:|"]
    for sensor, _mount, pairs, label in sets:
        same = total = 0
        cf = cq = 0
        tf, tq, mf, mq = [], [], [], []
        for b, lab in pairs:
            pts = kitti.read_bin(b)
            sem, _ = kitti.read_label(lab, len(pts))
            fm, qm, img, _ = native.ground_pair(pts, sensor)
            same += int(np.count_nonzero(fm == qm))
            total += len(pts)
            truth = ground_eval.ground_truth(sem)
            cf = cf + ground_eval.confusion(fm.astype(bool), truth)
            cq = cq + ground_eval.confusion(qm.astype(bool), truth)
            a, b2, c, d = native.ground_q_time(img, sensor, repeat)
            tf.append(a)
            tq.append(b2)
            mf.append(c)
            mq.append(d)
        lines.append(f"| {label} | {len(pairs)} | {total} | {100 * same / total:.4f} % | "
                     f"{ground_eval.metrics(cf)['iou']:.4f} | {ground_eval.metrics(cq)['iou']:.4f} | "
                     f"{statistics.median(tf):.3f} / {statistics.median(mf):.3f} | "
                     f"{statistics.median(tq):.3f} / {statistics.median(mq):.3f} |")
    lines += ["", f"Ground labels per input point (a point takes its pixel's label); IoU with ground = SemanticKITTI "
              f"40, 44, 48, 49, 60, 72; ms: median over the scans of each stage's median and fastest of {repeat} runs "
              "(`lidet_py_ground_q_time`, the two stages alternating; on a loaded machine the longer integer runs are "
              "preempted more often, the fastest run is the steadier figure). Alone: "
              "`python tools/bench/bench_ground.py --q-only`.", ""]
    return lines


def run_q_only(args) -> str:
    lines = ["## Integer ground stage (issue 16)", ""]
    sets = _sets(args, args.quick, lines)
    return "\n".join(lines + q_table(sets, 10 if args.quick else 50))


if __name__ == "__main__":
    from run_bench import standalone  # the script's own folder is on sys.path

    if "--q-only" in sys.argv:
        sys.argv.remove("--q-only")
        standalone(run_q_only, __doc__.split("\n\n")[0])
    else:
        standalone(run, __doc__.split("\n\n")[0])
