# SPDX-License-Identifier: MIT
"""KITTI 3D object evaluation (2D, BEV and 3D AP, |R11 and |R40), as the official devkit applies it.

Rules (``evaluate_object_3d_offline.cpp``; OpenPCDet ``kitti_object_eval_python/eval.py``):

* classes Car, Pedestrian, Cyclist (also Van, Person_sitting, Truck); names compared case-insensitively;
* IoU thresholds (strict ``>``) per metric and class: ``MIN_OVERLAP["strict"]`` (Car 0.7, Pedestrian 0.5,
  Cyclist 0.5 everywhere) and ``MIN_OVERLAP["loose"]`` (2D unchanged; BEV and 3D Car 0.5, others 0.25);
* difficulty from the ground truth's 2D box height, occlusion and truncation: easy/moderate/hard =
  min height 40/25/25 px, max occlusion 0/1/2, max truncation 0.15/0.30/0.50; outside it the ground
  truth is ignored (neither hit nor miss);
* Van is a neighbouring class of Car and Person_sitting of Pedestrian: such ground truth is ignored;
  detections of any other class are not evaluated;
* detections whose 2D box is lower than the difficulty's minimum height are ignored (never false
  positives, they may still absorb a ground-truth object);
* DontCare regions: a detection left unassigned whose 2D box lies inside one (intersection over the
  detection's area above the class threshold) is no false positive. The devkit does this for the 2D
  metric only (in BEV/3D the DontCare boxes have no extent); ``dontcare_all_metrics=True`` applies the 2D
  test to BEV and 3D as well (an option, not the devkit);
* 41 score thresholds from the true positives' scores, precision max-to-the-right,
  AP|R11 = mean of samples 0, 4, ..., 40; AP|R40 = mean of samples 1..40.

Flavours for the few places the two reference codes differ: ``"kitti"`` (C++ devkit: ground truth too
small when ``height < min``, detection height truncated to an integer) and ``"openpcdet"`` (``height <=
min`` for ground truth, float detection height). AOS is not computed.
A class/difficulty without valid ground truth has no AP: reported as None (the devkit prints 0).
"""
from __future__ import annotations

import os
import sys
from dataclasses import dataclass

import numpy as np

from . import engine, iou

CLASSES = ("Car", "Pedestrian", "Cyclist", "Van", "Person_sitting", "Truck")
DIFFICULTIES = ("easy", "moderate", "hard")
METRICS = ("3d", "bev", "2d")
MIN_HEIGHT = (40.0, 25.0, 25.0)
MAX_OCCLUSION = (0, 1, 2)
MAX_TRUNCATION = (0.15, 0.30, 0.50)
NEIGHBOUR = {"car": "van", "pedestrian": "person_sitting"}
_T = dict(car=0.7, pedestrian=0.5, cyclist=0.5, van=0.7, person_sitting=0.5, truck=0.7)
_L = dict(car=0.5, pedestrian=0.25, cyclist=0.25, van=0.5, person_sitting=0.25, truck=0.5)
_L2 = dict(car=0.7, pedestrian=0.5, cyclist=0.5, van=0.7, person_sitting=0.5, truck=0.5)
MIN_OVERLAP = {
    "strict": {"2d": _T, "bev": _T, "3d": _T},
    "loose": {"2d": _L2, "bev": _L, "3d": _L},
}


@dataclass
class LabelSet:
    """label_2 objects of many frames, concatenated in frame order (file order within a frame)."""
    frame_ids: list
    frame: np.ndarray      # (N,) int64 frame index
    name: np.ndarray       # (N,) lower-case class names
    truncated: np.ndarray  # (N,)
    occluded: np.ndarray   # (N,)
    bbox: np.ndarray       # (N, 4) x1 y1 x2 y2
    boxes: np.ndarray      # (N, 7) generic boxes (see iou.py)
    score: np.ndarray      # (N,) 1.0 where the file has no score

    @property
    def n_frames(self) -> int:
        return len(self.frame_ids)


def _parse_label2_text(text: str, path: str):
    rows = []
    for ln, line in enumerate(text.splitlines(), 1):
        p = line.split()
        if not p:
            continue
        if len(p) not in (15, 16):
            raise ValueError(f"{path}:{ln}: expected 15 or 16 fields, got {len(p)}")
        rows.append(p)
    return rows


def load_label_dir(label_dir, frame_ids=None, missing_ok: bool = False) -> LabelSet:
    """Read ``<label_dir>/<id>.txt`` for every id (default: every .txt in the folder, sorted).
    With missing_ok, an absent file is an empty frame (a detector that found nothing)."""
    label_dir = os.fspath(label_dir)
    if frame_ids is None:
        frame_ids = sorted(f[:-4] for f in os.listdir(label_dir) if f.endswith(".txt"))
    names, nums, frame = [], [], []
    for fi, fid in enumerate(frame_ids):
        path = os.path.join(label_dir, f"{fid}.txt")
        try:
            with open(path) as f:
                text = f.read()
        except FileNotFoundError:
            if missing_ok:
                continue
            raise
        for p in _parse_label2_text(text, path):
            names.append(p[0].lower())
            nums.append(p[1:] if len(p) == 16 else p[1:] + ["1.0"])
            frame.append(fi)
    try:
        v = np.array(nums, dtype=np.float64).reshape(-1, 15)
    except ValueError:
        raise ValueError(f"{label_dir}: non-numeric field in a label file") from None
    return LabelSet(
        frame_ids=list(frame_ids), frame=np.array(frame, dtype=np.int64),
        name=np.array(names, dtype=str) if names else np.zeros(0, dtype="<U1"),
        truncated=v[:, 0], occluded=v[:, 1], bbox=v[:, 3:7],
        boxes=iou.boxes_from_camera(v[:, 7:10], v[:, 10:13], v[:, 13]), score=v[:, 14])


def labelset_from_objects(frames) -> LabelSet:
    """LabelSet from a list (one entry per frame) of lists of ``kitti.KittiObject``."""
    names, rows, fr = [], [], []
    for fi, objs in enumerate(frames):
        for o in objs:
            names.append(o.type.lower())
            rows.append([o.truncated, o.occluded, o.alpha, *o.bbox, o.h, o.w, o.l, *o.loc, o.ry,
                         1.0 if o.score is None else o.score])
            fr.append(fi)
    v = np.array(rows, dtype=np.float64).reshape(-1, 15)
    return LabelSet(list(range(len(frames))), np.array(fr, dtype=np.int64),
                    np.array(names, dtype=str) if names else np.zeros(0, dtype="<U1"),
                    v[:, 0], v[:, 1], v[:, 3:7], iou.boxes_from_camera(v[:, 7:10], v[:, 10:13], v[:, 13]),
                    v[:, 14])


def frame_pairs(a_frame, b_frame, n_frames):
    """All same-frame pairs of two frame-sorted object lists: (index into a, index into b)."""
    na = np.bincount(a_frame, minlength=n_frames)
    nb = np.bincount(b_frame, minlength=n_frames)
    oa = np.cumsum(na) - na
    ob = np.cumsum(nb) - nb
    npair = na * nb
    P = int(npair.sum())
    f = np.repeat(np.arange(n_frames), npair)
    k = np.arange(P) - np.repeat(np.cumsum(npair) - npair, npair)
    nbf = np.maximum(nb[f], 1)
    return oa[f] + k // nbf, ob[f] + k % nbf


@dataclass
class Overlaps:
    """Same-frame (detection, ground truth) pairs with their 2D, BEV and 3D IoU, and the largest
    intersection-over-detection-area of each detection with a DontCare region."""
    pair_dt: np.ndarray
    pair_gt: np.ndarray
    ov: dict
    dc_ioa: np.ndarray


def compute_overlaps(gt: LabelSet, dt: LabelSet, metrics=METRICS) -> Overlaps:
    if gt.n_frames != dt.n_frames:
        raise ValueError("ground truth and detections must cover the same frames")
    n = gt.n_frames
    is_dc = gt.name == "dontcare"
    obj = np.nonzero(~is_dc)[0]
    ia, ib = frame_pairs(dt.frame, gt.frame[obj], n)
    pg = obj[ib]
    ov = {}
    if "2d" in metrics:
        ov["2d"] = iou.iou_2d_pairs(dt.bbox[ia], gt.bbox[pg])
    if "bev" in metrics:
        ov["bev"] = iou.iou_bev_pairs(dt.boxes[ia], gt.boxes[pg])
    if "3d" in metrics:
        ov["3d"] = iou.iou_3d_pairs(dt.boxes[ia], gt.boxes[pg])
    dc = np.nonzero(is_dc)[0]
    ja, jb = frame_pairs(dt.frame, gt.frame[dc], n)
    dc_ioa = np.zeros(len(dt.frame))
    if len(ja):
        np.maximum.at(dc_ioa, ja, iou.iou_2d_pairs(dt.bbox[ja], gt.bbox[dc[jb]], criterion=0))
    return Overlaps(ia, pg, ov, dc_ioa)


def ignore_flags(gt: LabelSet, dt: LabelSet, cls: str, difficulty: int, flavour: str = "kitti"):
    """The devkit's ``cleanData``: (ign_gt, ign_dt) int8 arrays for one class and difficulty."""
    c = cls.lower()
    valid = np.where(gt.name == c, 1, np.where(gt.name == NEIGHBOUR.get(c, "\0"), 0, -1))
    h = gt.bbox[:, 3] - gt.bbox[:, 1]
    small = h <= MIN_HEIGHT[difficulty] if flavour == "openpcdet" else h < MIN_HEIGHT[difficulty]
    ignore = (gt.occluded > MAX_OCCLUSION[difficulty]) | (gt.truncated > MAX_TRUNCATION[difficulty]) | small
    ign_gt = np.where((valid == 1) & ~ignore, 0, np.where((valid == 0) | ((valid == 1) & ignore), 1, -1))
    hd = np.abs(dt.bbox[:, 3] - dt.bbox[:, 1])
    if flavour != "openpcdet":
        hd = np.trunc(hd)  # C++: int32_t height = fabs(y1 - y2)
    ign_dt = np.where(hd < MIN_HEIGHT[difficulty], 1, np.where(dt.name == c, 0, -1))
    return ign_gt.astype(np.int8), ign_dt.astype(np.int8)


def evaluate(gt: LabelSet, dt: LabelSet, classes=("Car", "Pedestrian", "Cyclist"), metrics=METRICS,
             overlap: str = "strict", flavour: str = "kitti", dontcare_all_metrics: bool = False,
             overlaps: Overlaps | None = None, exact: bool = False) -> dict:
    """Evaluate detections against ground truth. Returns ``{"ap": {cls: {metric: {"R11"|"R40":
    {difficulty: AP}}}}, "curves": {cls: {metric: {difficulty: stats}}}, ...}`` where stats is the
    dict of :func:`engine.pr_statistics`. exact: AP from every true positive's score (engine.pr_statistics; the
    devkit's sampling caps AP|R40 near n / 40 for a class of n < 40 objects)."""
    if overlap not in MIN_OVERLAP:
        raise ValueError(f"overlap must be one of {sorted(MIN_OVERLAP)}")
    if flavour not in ("kitti", "openpcdet"):
        raise ValueError("flavour must be 'kitti' or 'openpcdet'")
    canon = {c.lower(): c for c in CLASSES}
    for c in classes:
        if c.lower() not in canon:
            raise ValueError(f"unknown class {c!r}; KITTI classes: {', '.join(CLASSES)}")
    ovl = overlaps if overlaps is not None else compute_overlaps(gt, dt, metrics)
    ap, curves = {}, {}
    for cls in classes:
        name = canon[cls.lower()]
        ap[name], curves[name] = {}, {}
        for m in metrics:
            thr = MIN_OVERLAP[overlap][m][name.lower()]
            ap[name][m] = {"R11": {}, "R40": {}}
            curves[name][m] = {}
            for d, dname in enumerate(DIFFICULTIES):
                ign_gt, ign_dt = ignore_flags(gt, dt, name, d, flavour)
                dc_hit = None
                if m == "2d" or dontcare_all_metrics:
                    dc_hit = ovl.dc_ioa > thr
                st = engine.pr_statistics(gt.n_frames, gt.frame, ign_gt, dt.frame, ign_dt, dt.score,
                                          ovl.pair_dt, ovl.pair_gt, ovl.ov[m], thr, dc_hit, exact=exact)
                st["min_overlap"] = thr
                curves[name][m][dname] = st
                ok = st["n_gt"] > 0
                ap[name][m]["R11"][dname] = st["ap_r11"] if ok else None
                ap[name][m]["R40"][dname] = st["ap_r40"] if ok else None
    return {"ap": ap, "curves": curves, "overlap": overlap, "flavour": flavour,
            "n_frames": gt.n_frames, "keys": list(DIFFICULTIES)}


def evaluate_dirs(gt_dir, pred_dir, frame_ids=None, warn=True, **kw) -> dict:
    """Evaluate every frame of gt_dir (or the listed ids) against pred_dir; a missing prediction
    file counts as a frame without detections."""
    gt = load_label_dir(gt_dir, frame_ids)
    if gt.n_frames == 0:
        raise ValueError(f"{gt_dir}: no label files (<id>.txt)")
    if warn:
        missing = [f for f in gt.frame_ids if not os.path.exists(os.path.join(pred_dir, f"{f}.txt"))]
        if missing:
            print(f"lidet-eval: {len(missing)} of {gt.n_frames} frames have no prediction file "
                  f"(counted as no detections), e.g. {missing[0]}.txt", file=sys.stderr)
    dt = load_label_dir(pred_dir, gt.frame_ids, missing_ok=True)
    return evaluate(gt, dt, **kw)


def format_table(res: dict, title: str) -> str:
    """Human-readable table of res['ap']."""
    keys = res["keys"]
    w = max(8, max(len(k) for k in keys))
    lines = [title, f"{'class':<15} {'metric':<6} {'IoU':>5}  "
             + "AP|R11 " + " ".join(f"{k:>{w}}" for k in keys) + "   AP|R40 "
             + " ".join(f"{k:>{w}}" for k in keys)]

    def f(x):
        return f"{'-':>{w}}" if x is None else f"{x:>{w}.2f}"
    for cls, per in res["ap"].items():
        for m, v in per.items():
            thr = next(iter(res["curves"][cls][m].values()))["min_overlap"]
            lines.append(f"{cls:<15} {m:<6} {thr:>5.2f}  " + " " * 7 + " ".join(f(v["R11"][k]) for k in keys)
                         + "   " + " " * 7 + " ".join(f(v["R40"][k]) for k in keys))
    return "\n".join(lines)
