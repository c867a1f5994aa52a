# SPDX-License-Identifier: MIT
"""Sensor-frame evaluation protocol for sensors without a camera (e.g. a VLP-16 on a small robot).

Input: lidet's sensor-frame box lines ``<class> <x> <y> <z> <l> <w> <h> <yaw> <score>`` (one file per
frame, ground truth and predictions matched by file stem). The KITTI devkit's matching and AP
(:mod:`lidet_tools.eval.engine`) are applied with distance bands instead of difficulty:

* band of an object = horizontal range of its box centre, sqrt(x^2 + y^2): ``0-20``, ``20-40``, ``40+`` m
  (and ``all``);
* ground truth of the class inside the band is valid; outside the band, or of the neighbouring class
  (Van for Car, Person_sitting for Pedestrian), it is ignored (neither hit nor miss);
* detections of the class outside the band are ignored (never false positives, but they may still
  absorb a ground-truth object near the band edge), the analogue of the devkit's minimum 2D height;
  detections of other classes are not evaluated;
* no DontCare, no 2D metric; 3D and BEV AP|R11 and AP|R40 at the KITTI thresholds
  (``overlap="kitti"``: Car 0.7, Pedestrian 0.5, Cyclist 0.5) or at 0.25 for every class
  (``overlap="0.25"``, the paper's protocol for its robot dataset), or at 0.5 car / 0.25 the others
  (``overlap="loose"``, the real-scan figures of `lidet_tools.eval_real`).
"""
from __future__ import annotations

import os
import sys
from dataclasses import dataclass

import numpy as np

from . import engine, iou
from .kitti_ap import CLASSES, NEIGHBOUR, MIN_OVERLAP as KITTI_MIN_OVERLAP, frame_pairs

BANDS = (("0-20", 0.0, 20.0), ("20-40", 20.0, 40.0), ("40+", 40.0, np.inf), ("all", 0.0, np.inf))
METRICS = ("3d", "bev")
MIN_OVERLAP = {
    "kitti": {m: KITTI_MIN_OVERLAP["strict"][m] for m in METRICS},
    "0.25": {m: {c.lower(): 0.25 for c in CLASSES} for m in METRICS},
    # issue 36's real-scan figures: car 0.5, the others 0.25 (kitti_ap's "loose" BEV / 3D thresholds)
    "loose": {m: KITTI_MIN_OVERLAP["loose"][m] for m in METRICS},
}


@dataclass
class BoxSet:
    frame_ids: list
    frame: np.ndarray   # (N,) int64
    name: np.ndarray    # (N,) lower-case
    boxes: np.ndarray   # (N, 7) x y z l w h yaw (sensor frame = generic layout)
    score: np.ndarray   # (N,)

    @property
    def n_frames(self) -> int:
        return len(self.frame_ids)

    @property
    def range_m(self) -> np.ndarray:
        return np.hypot(self.boxes[:, 0], self.boxes[:, 1])


def _stems(d):
    out = {}
    for f in sorted(os.listdir(d)):
        p = os.path.join(d, f)
        if f.startswith(".") or not os.path.isfile(p):
            continue
        out.setdefault(os.path.splitext(f)[0], p)
    return out


def load_boxes_dir(box_dir, frame_ids=None, missing_ok: bool = False) -> BoxSet:
    """Read every box file of box_dir (or those whose stem is in frame_ids, in that order)."""
    files = _stems(os.fspath(box_dir))
    if frame_ids is None:
        frame_ids = list(files)
    names, vals, frame = [], [], []
    for fi, fid in enumerate(frame_ids):
        path = files.get(fid)
        if path is None:
            if missing_ok:
                continue
            raise FileNotFoundError(f"{box_dir}: no box file for frame {fid}")
        with open(path) as f:
            for ln, line in enumerate(f, 1):
                p = line.split("#", 1)[0].split()
                if not p:
                    continue
                if len(p) != 9:
                    raise ValueError(f"{path}:{ln}: expected 9 fields "
                                     f"'<class> <x> <y> <z> <l> <w> <h> <yaw> <score>', got {len(p)}")
                names.append(p[0].lower())
                vals.append(p[1:])
                frame.append(fi)
    try:
        v = np.array(vals, dtype=np.float64).reshape(-1, 8)
    except ValueError:
        raise ValueError(f"{box_dir}: non-numeric field in a box file") from None
    return BoxSet(list(frame_ids), np.array(frame, dtype=np.int64),
                  np.array(names, dtype=str) if names else np.zeros(0, dtype="<U1"), v[:, :7], v[:, 7])


def boxset_from_frames(frames) -> BoxSet:
    """BoxSet from a list (one entry per frame) of lists of ``kitti.Box3D``."""
    names, vals, fr = [], [], []
    for fi, boxes in enumerate(frames):
        for b in boxes:
            names.append(b.cls.lower())
            vals.append([b.x, b.y, b.z, b.l, b.w, b.h, b.yaw, b.score])
            fr.append(fi)
    v = np.array(vals, dtype=np.float64).reshape(-1, 8)
    return BoxSet(list(range(len(frames))), np.array(fr, dtype=np.int64),
                  np.array(names, dtype=str) if names else np.zeros(0, dtype="<U1"), v[:, :7], v[:, 7])


def evaluate(gt: BoxSet, dt: BoxSet, classes=("Car", "Pedestrian", "Cyclist"), metrics=METRICS,
             overlap: str = "kitti", bands=BANDS, exact: bool = False) -> dict:
    """Same result layout as :func:`kitti_ap.evaluate`, with band names in place of difficulties. exact: AP from
    every true positive's score (:func:`engine.pr_statistics`; for sets of fewer than ~40 objects a class)."""
    if overlap not in MIN_OVERLAP:
        raise ValueError(f"overlap must be one of {sorted(MIN_OVERLAP)}")
    if gt.n_frames != dt.n_frames:
        raise ValueError("ground truth and detections must cover the same frames")
    canon = {c.lower(): c for c in CLASSES}
    for c in classes:
        if c.lower() not in canon:
            raise ValueError(f"unknown class {c!r}; classes: {', '.join(CLASSES)}")
    pd, pg = frame_pairs(dt.frame, gt.frame, gt.n_frames)
    ov = {}
    if "bev" in metrics:
        ov["bev"] = iou.iou_bev_pairs(dt.boxes[pd], gt.boxes[pg])
    if "3d" in metrics:
        ov["3d"] = iou.iou_3d_pairs(dt.boxes[pd], gt.boxes[pg])
    rg, rd = gt.range_m, dt.range_m
    ap, curves = {}, {}
    for cls in classes:
        name = canon[cls.lower()]
        c = name.lower()
        valid = np.where(gt.name == c, 1, np.where(gt.name == NEIGHBOUR.get(c, "\0"), 0, -1))
        ap[name], curves[name] = {}, {}
        for m in metrics:
            thr = MIN_OVERLAP[overlap][m][c]
            ap[name][m] = {"R11": {}, "R40": {}}
            curves[name][m] = {}
            for bname, lo, hi in bands:
                in_g = (rg >= lo) & (rg < hi)
                in_d = (rd >= lo) & (rd < hi)
                ign_gt = np.where((valid == 1) & in_g, 0, np.where(valid >= 0, 1, -1))
                ign_dt = np.where(dt.name == c, np.where(in_d, 0, 1), -1)
                st = engine.pr_statistics(gt.n_frames, gt.frame, ign_gt, dt.frame, ign_dt, dt.score,
                                          pd, pg, ov[m], thr, exact=exact)
                st["min_overlap"] = thr
                curves[name][m][bname] = st
                ok = st["n_gt"] > 0
                ap[name][m]["R11"][bname] = st["ap_r11"] if ok else None
                ap[name][m]["R40"][bname] = st["ap_r40"] if ok else None
    return {"ap": ap, "curves": curves, "overlap": overlap, "n_frames": gt.n_frames,
            "keys": [b[0] for b in bands]}


def evaluate_dirs(gt_dir, pred_dir, warn=True, **kw) -> dict:
    gt = load_boxes_dir(gt_dir)
    if gt.n_frames == 0:
        raise ValueError(f"{gt_dir}: no box files")
    dt = load_boxes_dir(pred_dir, gt.frame_ids, missing_ok=True)
    if warn:
        have = set(_stems(os.fspath(pred_dir)))
        missing = [f for f in gt.frame_ids if f not in have]
        if missing:
            print(f"lidet-eval: {len(missing)} of {gt.n_frames} frames have no prediction file "
                  f"(counted as no detections), e.g. {missing[0]}", file=sys.stderr)
    return evaluate(gt, dt, **kw)
