# SPDX-License-Identifier: MIT
"""Evaluation of a proposal generator (clustering) against SemanticKITTI-style instance labels.

For every labelled road user (class + instance id) with >= `min_points` points:
- the best-matching cluster is the predicted id holding most of the object's points;
- precision = |object ∩ cluster| / |cluster|, recall = |object ∩ cluster| / |object| (points);
- outcome, in this order:
  * missed: no point of the object is in any cluster;
  * under-segmented: precision < 0.8 (the best cluster is mostly something else: merged);
  * recovered ("as one cluster"): precision >= 0.8 and recall >= 0.8;
  * over-segmented: the object's points lie in >= 2 clusters (split);
  * partial: otherwise (one cluster with < 80% of the object, the rest unclustered).
Results per class and per distance band of the object's centroid (horizontal range: 0-20, 20-40,
40+ m, and 0-40 m for the goals).

Usable on lidet's clusters (`native.cluster`), on any other per-point labelling (e.g. DBSCAN,
`tools/bench/bench_cluster.py`), and from the command line:

    python -m lidet_tools.cluster_eval DATA_DIR [--sensor hdl64] [--ground labels|flat] [--json]

DATA_DIR holds velodyne/*.bin and labels/*.label (SemanticKITTI ids, instance in the upper 16 bits;
the simulator writes that layout; ../shared/data/real/semantickitti has 3 labelled real scans).
"""
from __future__ import annotations

import argparse
import json
import pathlib
import sys
from dataclasses import asdict, dataclass

import numpy as np

#: evaluated classes: name -> SemanticKITTI ids (static, moving); other-vehicle is reported as info
CLASSES = {"car": (10, 252), "person": (30, 254), "bicyclist": (31, 253), "other-vehicle": (20, 259)}
GROUND_IDS = (40, 44, 48, 49, 60, 72)
BANDS = (("0-20", 0.0, 20.0), ("20-40", 20.0, 40.0), ("40+", 40.0, np.inf))
GOAL_BAND = ("0-40", 0.0, 40.0)
OUTCOMES = ("recovered", "over", "under", "partial", "missed")


@dataclass
class ObjectResult:
    scan: str
    cls: str
    instance: int
    n_points: int
    distance_m: float
    precision: float
    recall: float
    n_clusters: int  #: clusters holding at least one of its points
    outcome: str


def ground_mask(labels: np.ndarray) -> np.ndarray:
    """Per point: SemanticKITTI ground classes (road, parking, sidewalk, other-ground, lane marking, terrain)."""
    return np.isin(np.asarray(labels) & 0xFFFF, GROUND_IDS)


def evaluate_scan(pred: np.ndarray, labels: np.ndarray, points: np.ndarray, scan: str = "",
                  min_points: int = 10, thr: float = 0.8) -> list[ObjectResult]:
    """Per-object results of one scan. pred: (N,) cluster id per point (0 = none); labels: (N,)
    uint32 SemanticKITTI labels; points: (N, >=3)."""
    pred = np.asarray(pred).astype(np.int64)
    labels = np.asarray(labels, np.uint32)
    sem = (labels & 0xFFFF).astype(np.int64)
    inst = (labels >> 16).astype(np.int64)
    pts = np.asarray(points)[:, :3].astype(np.float64)
    if not (len(pred) == len(labels) == len(pts)):
        raise ValueError("pred, labels and points must have one entry per point")
    size = np.bincount(pred, minlength=1)
    out = []
    for name, ids in CLASSES.items():
        in_cls = np.isin(sem, ids)
        for iid in np.unique(inst[in_cls]):
            if iid == 0:
                continue  # unlabelled instance: not an object we can score
            obj = in_cls & (inst == iid)
            n = int(obj.sum())
            if n < min_points:
                continue
            c = pts[obj].mean(0)
            dist = float(np.hypot(c[0], c[1]))
            hit = pred[obj]
            hit = hit[hit > 0]
            if len(hit) == 0:
                out.append(ObjectResult(scan, name, int(iid), n, dist, 0.0, 0.0, 0, "missed"))
                continue
            cnt = np.bincount(hit)
            best = int(np.argmax(cnt))
            inter = float(cnt[best])
            p, r = inter / float(size[best]), inter / n
            ncl = int(np.count_nonzero(cnt))
            if p < thr:
                oc = "under"
            elif r >= thr:
                oc = "recovered"
            elif ncl >= 2:
                oc = "over"
            else:
                oc = "partial"
            out.append(ObjectResult(scan, name, int(iid), n, dist, p, r, ncl, oc))
    return out


def summarize(results: list[ObjectResult]) -> dict:
    """{class: {band: {n, recovered, over, under, partial, missed (rates), precision, recall (means)}}},
    bands 0-20, 20-40, 40+, 0-40 and all."""
    bands = list(BANDS) + [GOAL_BAND, ("all", 0.0, np.inf)]
    res: dict = {}
    for name in CLASSES:
        rs = [r for r in results if r.cls == name]
        res[name] = {}
        for b, lo, hi in bands:
            sel = [r for r in rs if lo <= r.distance_m < hi]
            d = {"n": len(sel)}
            for oc in OUTCOMES:
                d[oc] = (sum(r.outcome == oc for r in sel) / len(sel)) if sel else float("nan")
            d["precision"] = float(np.mean([r.precision for r in sel])) if sel else float("nan")
            d["recall"] = float(np.mean([r.recall for r in sel])) if sel else float("nan")
            res[name][b] = d
    return res


def _pct(v: float) -> str:
    return "-" if v != v else f"{100 * v:.0f}%"


def markdown(summary: dict, title: str = "") -> str:
    """A table: one row per class and band (recovered as one cluster, over, under, missed+partial, P, R)."""
    lines = []
    if title:
        lines.append(f"**{title}**\n")
    lines.append("| class | band (m) | objects | recovered | over-seg | under-seg | partial/missed | precision | recall |")
    lines.append("|---|---|---:|---:|---:|---:|---:|---:|---:|")
    for name, per in summary.items():
        for b, d in per.items():
            if d["n"] == 0:
                continue
            miss = d["partial"] + d["missed"]
            lines.append(f"| {name} | {b} | {d['n']} | {_pct(d['recovered'])} | {_pct(d['over'])} | "
                         f"{_pct(d['under'])} | {_pct(miss)} | {d['precision']:.2f} | {d['recall']:.2f} |")
    return "\n".join(lines) + "\n"


def scans(data_dir: pathlib.Path):
    """(name, points (N, 4), labels (N,)) for every velodyne/*.bin with a labels/*.label."""
    data_dir = pathlib.Path(data_dir)
    for f in sorted((data_dir / "velodyne").glob("*.bin")):
        lf = data_dir / "labels" / (f.stem + ".label")
        if not lf.exists():
            continue
        pts = np.fromfile(f, np.float32).reshape(-1, 4)
        lab = np.fromfile(lf, np.uint32)
        if len(lab) != len(pts):
            raise ValueError(f"{lf}: {len(lab)} labels for {len(pts)} points")
        yield f.stem, pts, lab


#: KITTI label_2 types scored on the object frames -> the SemanticKITTI class they are scored as; Truck, Tram,
#: Misc and DontCare are not scored (their points stay unlabelled: neither ground nor an object)
KITTI_TYPES = {"Car": 10, "Van": 10, "Pedestrian": 30, "Person_sitting": 30, "Cyclist": 31}
#: an object's points on the KITTI frames: inside its label_2 box grown by BOX_MARGIN_M in length, width and at
#: the top, at least BOX_FLOOR_M above the box's bottom (the ground it stands on stays out), not ground
BOX_MARGIN_M = 0.1
BOX_FLOOR_M = 0.1


def kitti_box_labels(points: np.ndarray, objects, calib, ground: np.ndarray, margin_m: float = BOX_MARGIN_M,
                     floor_m: float = BOX_FLOOR_M) -> np.ndarray:
    """SemanticKITTI-style labels (uint32 per point) for `evaluate_scan` from KITTI label_2 boxes: ground points
    (the (N,) mask given, e.g. the ground stage's) get class 40; the points of each Car / Van, Pedestrian /
    Person_sitting and Cyclist box (KITTI_TYPES; camera frame -> sensor frame through calib) that are inside it
    grown by margin_m along its length, its width and above its top, at least floor_m above its bottom and not
    ground get its class, instance = 1 + the object's line index; a point inside two boxes goes to the first."""
    from .kitti import kitti_to_box
    xyz = np.asarray(points)[:, :3].astype(np.float64)
    ground = np.asarray(ground).astype(bool)
    if len(ground) != len(xyz):
        raise ValueError(f"{len(ground)} ground flags for {len(xyz)} points")
    sem = np.where(ground, 40, 0).astype(np.uint32)
    inst = np.zeros(len(xyz), np.uint32)
    for i, o in enumerate(objects):
        cls = KITTI_TYPES.get(o.type)
        if cls is None:
            continue
        b = kitti_to_box(o, calib)
        c, s = np.cos(b.yaw), np.sin(b.yaw)
        d = xyz - np.array([b.x, b.y, b.z])
        u = c * d[:, 0] + s * d[:, 1]
        v = -s * d[:, 0] + c * d[:, 1]
        inside = ((np.abs(u) <= b.l / 2 + margin_m) & (np.abs(v) <= b.w / 2 + margin_m) &
                  (d[:, 2] >= -b.h / 2 + floor_m) & (d[:, 2] <= b.h / 2 + margin_m) & ~ground & (inst == 0))
        sem[inside] = cls
        inst[inside] = i + 1
    return (inst << 16) | sem


def kitti_scans(kitti_dir: pathlib.Path, sensor: str = "hdl64"):
    """(name, points (N, 4), labels (N,)) for every velodyne/*.bin of a KITTI object folder with label_2/ and
    calib/: `kitti_box_labels` with the ground stage's mask (the C ground stage, its defaults for `sensor`; what
    `lidet cluster` without --labels uses)."""
    from . import kitti, native
    kitti_dir = pathlib.Path(kitti_dir)
    for f in sorted((kitti_dir / "velodyne").glob("*.bin")):
        lf, cf = kitti_dir / "label_2" / f"{f.stem}.txt", kitti_dir / "calib" / f"{f.stem}.txt"
        if not (lf.exists() and cf.exists()):
            continue
        pts = kitti.read_bin(f)
        g = native.ground(pts, sensor).mask_point.astype(bool)
        yield f.stem, pts, kitti_box_labels(pts, kitti.read_label2(lf), kitti.read_calib(cf), g)


def flat_ground(points: np.ndarray, mount_height_m: float, margin_m: float = 0.25) -> np.ndarray:
    """The CLI's fallback ground: z below -(mount height - margin)."""
    return np.asarray(points)[:, 2] < -(mount_height_m - margin_m)


def evaluate_lidet(data_dir, sensor: str = "hdl64", ground: str = "labels", thr: float = 0.8,
                   **cfg) -> list[ObjectResult]:
    """Cluster every scan of data_dir with the C library (bindings) and evaluate."""
    from . import native
    from .sensors import get_sensor
    s = get_sensor(sensor)
    out = []
    for name, pts, lab in scans(data_dir):
        gm = ground_mask(lab) if ground == "labels" else flat_ground(pts, s.mount_height_m)
        c = native.cluster(pts, sensor, ground=gm, **cfg)
        out += evaluate_scan(c.point_labels, lab, pts, scan=name, thr=thr)
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m lidet_tools.cluster_eval", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("data", type=pathlib.Path, help="folder with velodyne/ and labels/")
    ap.add_argument("--sensor", default="hdl64")
    ap.add_argument("--ground", choices=["labels", "flat"], default="labels",
                    help="ground mask: SemanticKITTI ground classes (isolates the clustering), or a flat cut")
    ap.add_argument("--theta", type=float, default=None, help="theta_rad (default: the profile's)")
    ap.add_argument("--max-steps", type=int, default=None)
    ap.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                    help="any other cluster option, e.g. --set diagonals=0 --set bridge_occluders=0")
    ap.add_argument("--thr", type=float, default=0.8,
                    help="precision and recall a recovered object needs (issue 15's proposal recall: 0.7)")
    ap.add_argument("--json", action="store_true", help="print the summary as JSON")
    a = ap.parse_args(argv)
    cfg = {}
    if a.theta is not None:
        cfg["theta_rad"] = a.theta
    if a.max_steps is not None:
        cfg["max_steps"] = a.max_steps
    for kv in a.set:
        k, _, v = kv.partition("=")
        cfg[k] = float(v) if "." in v or "e" in v.lower() else int(v)
    res = evaluate_lidet(a.data, a.sensor, a.ground, a.thr, **cfg)
    if not res:
        print(f"no labelled road users with >= 10 points under {a.data}", file=sys.stderr)
        return 1
    summ = summarize(res)
    if a.json:
        print(json.dumps({"summary": summ, "objects": [asdict(r) for r in res]}, default=float))
    else:
        print(markdown(summ, f"lidet clusters on {a.data} ({a.sensor}, ground from {a.ground})"))
    return 0


if __name__ == "__main__":
    sys.exit(main())
