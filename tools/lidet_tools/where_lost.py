# SPDX-License-Identifier: MIT
"""Where a labelled road user is lost on its way through the detector: each ground-truth box is followed through
the stages by the points inside it and the detector's per-cluster outcomes (`native.detect`).

Stages, in the order they are tested (the first that applies is the object's):

* ``too few points``: fewer than the clustering's ``min_points`` points inside the box (+ 0.1 m);
* ``ground``: as few left once the ground stage's points are taken out;
* ``no cluster``: none of its non-ground points, or at most half of them, is in a kept cluster (its component was
  dropped by the clustering's filters: too wide, too tall, too many points; or it joined such a component, as a
  car chained to the kerb it stands on);
* ``split``: no cluster holds >= 70 % of the object's non-ground points, and more than half of them are in kept
  clusters (the object came out in pieces);
* ``merged``: the cluster holding most of them is < 70 % object (the object was joined with a neighbour);
* ``budget/crop``: the cluster was not classified (proposal budget, crop, range, capacity, too tall);
* ``gate 1`` / ``gate 2``: rejected by the classifier's / the box net's energy gate;
* ``size``, ``nms``: its box failed the size check / was suppressed by NMS;
* ``wrong class``: detected as another class;
* ``box off``: the right class but the box misses the overlap (the caller's `hit` test);
* ``detected``.

The simulated benchmark (tools/bench/bench_detect.py) and the real frames (`lidet_tools.eval_real`) use the same
function, so their tables read alike.
"""
from __future__ import annotations

from typing import Callable

import numpy as np

STAGES = ("too few points", "ground", "no cluster", "split", "merged", "budget/crop", "gate 1", "gate 2", "size",
          "score", "nms", "wrong class", "box off", "detected")
#: native.OUTCOME name -> stage, for clusters that did not become a detection
_OUTCOME_STAGE = {"crop": "budget/crop", "range": "budget/crop", "budget": "budget/crop", "capacity": "budget/crop",
                  "tall": "budget/crop", "gate1": "gate 1", "gate2": "gate 2", "size": "size", "score": "score", "nms": "nms"}
#: share of the object's non-ground points its cluster must hold, and share of the cluster that must be object
CLUSTER_SHARE = 0.7


def points_in_box(xyz: np.ndarray, box, margin: float = 0.1) -> np.ndarray:
    """Mask of the points inside box (x, y, z, l, w, h, yaw; centre) grown by margin metres on every side."""
    b = np.asarray(box, dtype=np.float64)
    c, s = np.cos(b[6]), np.sin(b[6])
    d = np.asarray(xyz, dtype=np.float64)[:, :3] - b[:3]
    u = c * d[:, 0] + s * d[:, 1]
    v = -s * d[:, 0] + c * d[:, 1]
    return (np.abs(u) <= b[3] / 2 + margin) & (np.abs(v) <= b[4] / 2 + margin) & (np.abs(d[:, 2]) <= b[5] / 2 + margin)


def seen_points(points: np.ndarray, sensor: str) -> np.ndarray:
    """Mask of the points that win their pixel of the detector's projection (`native.project`): the ones it sees."""
    from . import native
    img = native.project(points, sensor)
    seen = np.zeros(len(points), dtype=bool)
    seen[img.point_idx[img.point_idx >= 0]] = True
    return seen


def where_lost(points: np.ndarray, gt_boxes: np.ndarray, gt_cls: list, det, min_points: int,
               hit: Callable[[np.ndarray, np.ndarray, str], bool], classes=("Car", "Cyclist", "Pedestrian"),
               seen: np.ndarray | None = None) -> list:
    """The stage (one of STAGES) of each ground-truth box.

    points: (N, >=3) the scan the detector ran on; gt_boxes: (K, 7) sensor-frame boxes; gt_cls: their classes;
    det: `native.Detections` of that run; min_points: the clustering's min_points; classes: native.CLASSES (the
    index order of det.cls); hit(det_box, gt_box, cls) -> True when a detection of the right class counts.
    seen: optional (N,) mask of the points that won their pixel (`native.project(...).point_idx`): the detector
    sees only those, and a point that lost its pixel carries the winner's cluster id (lidet_cluster_point_labels),
    which can lie metres in front of it; with the mask every count is over the seen points alone. Without it,
    every point counts (the simulated benchmark's table)."""
    pc = det.point_cluster if seen is None else np.where(seen, det.point_cluster, 0)
    csize = np.bincount(pc.astype(np.int64), minlength=len(det.outcome) + 1)
    out = []
    for b, cls in zip(np.asarray(gt_boxes, dtype=np.float64).reshape(-1, 7), gt_cls):
        m = points_in_box(points, b)
        if seen is not None:
            m &= seen
        if m.sum() < min_points:
            out.append("too few points")
            continue
        ng = m & (det.point_ground == 0)
        if ng.sum() < min_points:
            out.append("ground")
            continue
        ids = pc[ng]
        ids = ids[ids > 0]
        if 2 * len(ids) <= ng.sum():
            out.append("no cluster")
            continue
        cid = int(np.bincount(ids).argmax())
        held = int((ids == cid).sum())
        if held < CLUSTER_SHARE * ng.sum():
            out.append("split")
            continue
        js = np.nonzero(det.cluster_id == cid)[0]
        # a cluster the group split cut into people: its parts' detections carry its id
        found = [j for j in js if classes[int(det.cls[j])] == cls and hit(det.box[j].astype(np.float64), b, cls)]
        if held < CLUSTER_SHARE * csize[cid]:
            out.append("detected" if found and _outcome_name(det.outcome[cid - 1]) == "group" else "merged")
            continue
        stage = _OUTCOME_STAGE.get(_outcome_name(det.outcome[cid - 1]))
        if stage is not None:
            out.append(stage)
            continue
        if found:
            out.append("detected")
            continue
        if len(js) == 0:  # a detection of a cluster always has its id; guard against a capacity-cut table
            out.append("budget/crop")
            continue
        j = int(js[0])
        if classes[int(det.cls[j])] != cls:
            out.append("wrong class")
            continue
        out.append("detected" if hit(det.box[j].astype(np.float64), b, cls) else "box off")
    return out


def _outcome_name(code) -> str:
    from . import native
    return native.OUTCOME.get(int(code), "?")
