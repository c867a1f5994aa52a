# SPDX-License-Identifier: MIT
"""Simulated against real road users, as the detector sees them: per class and distance band, side by side, the
points an object gets (those that win their pixel), the span of those points along the object's own axes, and
what the detector made of the objects whose cluster was clean (`lidet_tools.where_lost`): passed gate 1, passed
both gates, detected.

    python -m lidet_tools.real.compare [--root ../shared/data/real] [--side train] [--sim-scans 60] [--seed 1000]

Real: the frames of one side of tools/lidet_tools/real/split.txt whose sensor is the HDL-64 profile (KITTI,
KITTI-360, PandaSet, SemanticKITTI, SqueezeSeg; the boxes of SemanticKITTI and SqueezeSeg are fitted to the visible
points, which makes their spans read a little short). Simulated: `lidet-sim --sensor hdl64` scans of a training
seed. Both run through the same float detector (`native.detect`, 360 degrees, each frame's mount height). The
PointNets read x, y, z only, so intensity is not compared. "seen from" is the 5th percentile of an object's seen
points above its box bottom (median per band): how much of it is hidden from below, e.g. people behind parked cars.
`--all-sensors` adds the frames of other sensors (Argoverse), each run on its own preset.
"""
from __future__ import annotations

import argparse
import pathlib
import sys

import numpy as np

from .. import native
from ..where_lost import points_in_box, seen_points, where_lost
from . import HDL64_LIKE

CLASSES = ("Car", "Pedestrian", "Cyclist")
BANDS = ((0.0, 15.0), (15.0, 30.0), (30.0, 45.0))
#: where_lost stages of an object whose cluster was clean (mostly the object, most of the object)
CLEAN = ("budget/crop", "gate 1", "gate 2", "size", "nms", "wrong class", "box off", "detected")


def object_rows(points, boxes, det, seen, sensor: str) -> list:
    """One dict per Car / Pedestrian / Cyclist box within 45 m: class, range, seen points, spans of those points
    along the box's length, width and height axes (5-95 %), and where_lost's stage (loose BEV hit)."""
    from ..eval.iou import iou_bev_pairs
    thr = {"Car": 0.5, "Pedestrian": 0.25, "Cyclist": 0.25}
    keep = [b for b in boxes if b.cls in CLASSES and np.hypot(b.x, b.y) < BANDS[-1][1]]
    arr = np.array([[b.x, b.y, b.z, b.l, b.w, b.h, b.yaw] for b in keep]).reshape(-1, 7)
    few = int(native.cluster_defaults(sensor)["min_points"])
    stages = where_lost(points, arr, [b.cls for b in keep], det, few,
                        lambda d, g, c: float(iou_bev_pairs(d[None], g[None])[0]) >= thr[c], native.CLASSES, seen)
    rows = []
    for b, a, st in zip(keep, arr, stages):
        m = points_in_box(points, a) & seen
        p = points[m, :3].astype(np.float64) - a[:3]
        c, s = np.cos(a[6]), np.sin(a[6])
        u, v = c * p[:, 0] + s * p[:, 1], -s * p[:, 0] + c * p[:, 1]
        span = [float(np.subtract(*np.percentile(q, [95, 5]))) if len(q) >= 5 else np.nan for q in (u, v, p[:, 2])]
        # how much of the object is hidden from below (a person behind a parked car, a car behind a wall): the
        # 5th percentile of its seen points' z above the box bottom
        low = float(np.percentile(p[:, 2], 5) + a[5] / 2) if len(p) >= 5 else np.nan
        rows.append(dict(cls=b.cls, range=float(np.hypot(a[0], a[1])), n=int(m.sum()), span=span, low=low, stage=st))
    return rows


def real_rows(root, side: str = "train", all_sensors: bool = False) -> list:
    from . import load_frame
    from ..eval_real import read_split
    rows = []
    for src, fid, sd in read_split():
        if sd != side:
            continue
        fr = load_frame(root, src, fid)
        if fr.sensor not in HDL64_LIKE and not all_sensors:
            continue
        det = native.detect(fr.points, fr.sensor, mount_height_m=fr.mount_height_m)
        rows += object_rows(fr.points, fr.boxes, det, seen_points(fr.points, fr.sensor), fr.sensor)
    return rows


def sim_rows(n_scans: int, seed: int) -> list:
    from ..sim.simulate import simulate_scan
    rows = []
    for i in range(n_scans):
        r = simulate_scan("hdl64", seed, i)
        det = native.detect(r.points, "hdl64")
        rows += object_rows(r.points, r.boxes, det, seen_points(r.points, "hdl64"), "hdl64")
    return rows


def _med(v) -> str:
    v = [x for x in v if np.isfinite(x)]
    return "-" if not v else f"{np.median(v):.2f}" if np.median(v) < 10 else f"{np.median(v):.0f}"


def _share(rows, stages) -> str:
    clean = [r for r in rows if r["stage"] in CLEAN]
    if not clean:
        return "-"
    return f"{sum(r['stage'] in stages for r in clean) / len(clean):.2f}"


def table(sim: list, real: list) -> str:
    """Markdown: per class and band, simulated | real for each quantity."""
    L = ["| class | band (m) | objects sim / real | points | span l (m) | span w (m) | span h (m) | seen from (m) | "
         "clean cluster | clean: pass gate 1 | clean: pass both gates | clean: detected |",
         "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"]
    past1 = ("gate 2", "size", "nms", "wrong class", "box off", "detected")
    past2 = ("size", "nms", "wrong class", "box off", "detected")
    for c in CLASSES:
        for lo, hi in BANDS:
            s = [r for r in sim if r["cls"] == c and lo <= r["range"] < hi]
            q = [r for r in real if r["cls"] == c and lo <= r["range"] < hi]
            if not s and not q:
                continue
            cells = [f"{len(s)} / {len(q)}"]
            cells.append(f"{_med([r['n'] for r in s])} / {_med([r['n'] for r in q])}")
            for k in range(3):
                cells.append(f"{_med([r['span'][k] for r in s])} / {_med([r['span'][k] for r in q])}")
            cells.append(f"{_med([r['low'] for r in s])} / {_med([r['low'] for r in q])}")
            for rr in (None, past1, past2, ("detected",)):
                if rr is None:
                    f = lambda x: "-" if not x else f"{sum(r['stage'] in CLEAN for r in x) / len(x):.2f}"  # noqa: E731
                    cells.append(f"{f(s)} / {f(q)}")
                else:
                    cells.append(f"{_share(s, rr)} / {_share(q, rr)}")
            L.append(f"| {c} | {lo:g}-{hi:g} | " + " | ".join(cells) + " |")
    return "\n".join(L) + "\n"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m lidet_tools.real.compare", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--root", default=str(pathlib.Path(__file__).resolve().parents[3].parent / "shared" / "data" / "real"))
    ap.add_argument("--side", choices=("train", "val"), default="train")
    ap.add_argument("--sim-scans", type=int, default=60)
    ap.add_argument("--seed", type=int, default=1000, help="simulator seed (1000: the hdl64 family's training seed)")
    ap.add_argument("--all-sensors", action="store_true",
                    help="also the frames of other sensors (Argoverse's VLP-32C), each on its own preset")
    a = ap.parse_args(argv)
    if not pathlib.Path(a.root).is_dir():
        print(f"compare: {a.root} not found", file=sys.stderr)
        return 2
    print(table(sim_rows(a.sim_scans, a.seed), real_rows(a.root, a.side, a.all_sensors)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
