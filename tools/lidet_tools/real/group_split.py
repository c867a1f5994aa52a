# SPDX-License-Identifier: MIT
"""People walking side by side, split by the classifier's judgement: the prototype of the detectors' group split
(lidet_detector_cfg_t.group_split, docs/DETECTOR.md "People in groups"; docs/journal/real-streets.md has both
measurements). It runs on the detector's output, so with the split on (the default for > 16 beams) it measures what
a split with this rule (percentiles and a two-dimensional k-means) would add to the built one.

    python -m lidet_tools.real.group_split [--root ../shared/data/real] [--side train] [--person-m 0.7]

For every cluster of the float detector's run (`native.detect`, each frame's preset and mount height) that gave no
detection and is shaped like a group of people (the seen, non-ground points span 0.9-3.5 m along their principal
horizontal axis and 1.0-2.2 m in z, 3rd to 97th percentile; its mean within 40 m), the points are cut into k parts by
k-means on x, y (k from span / person_m, rounded, to span / 0.5 m, at least 2, at most 4; deterministic start: the
k quantiles along the principal axis), each part made a proposal as the C stage makes one
(`lidet_ref.cluster.make_proposal`) and classified by the shipped classifier (`native.pn_classify`). The largest k
whose parts are all Pedestrian and all pass gate 1 is kept (none: the cluster stays whole); each part is boxed by
the box net (`native.pn_box`). A part's box counts as a new detection of a labelled pedestrian the detector had not
found (loose BEV overlap 0.25, the labelled field of view, outside the ignore regions of `make eval-real`), or as a
new false one. Prints per frame and in all. Exit status 0; 2 when the folder is missing.
"""
from __future__ import annotations

import argparse
import pathlib
import sys

import numpy as np

PED = 2  # lidet_class_t


def kmeans_along_axis(xy: np.ndarray, k: int, iters: int = 20) -> np.ndarray:
    """Labels 0..k-1 of (n, 2) points by k-means, started from the points nearest the k quantiles of their
    projection on the principal axis (deterministic: no random start)."""
    xy = np.asarray(xy, np.float64)
    c = xy.mean(0)
    axis = np.linalg.svd(xy - c, full_matrices=False)[2][0]
    t = (xy - c) @ axis
    centres = np.array([xy[np.argmin(np.abs(t - q))] for q in np.quantile(t, (np.arange(k) + 0.5) / k)])
    lab = np.zeros(len(xy), np.int64)
    for _ in range(iters):
        lab = np.argmin(((xy[:, None] - centres[None]) ** 2).sum(-1), 1)
        new = np.array([xy[lab == j].mean(0) if (lab == j).any() else centres[j] for j in range(k)])
        if np.allclose(new, centres):
            break
        centres = new
    return lab


def group_shaped(pts: np.ndarray, max_range_m: float = 40.0) -> float | None:
    """The span (m) along the principal horizontal axis of a cluster's points when it is shaped like a group of
    people (span 0.9-3.5 m, z span 1.0-2.2 m, mean within max_range_m), else None."""
    if len(pts) < 20:
        return None
    c = pts[:, :2].mean(0)
    if np.hypot(*c) > max_range_m:
        return None
    axis = np.linalg.svd(pts[:, :2] - c, full_matrices=False)[2][0]
    t = (pts[:, :2] - c) @ axis
    span = float(np.percentile(t, 97) - np.percentile(t, 3))
    zspan = float(np.percentile(pts[:, 2], 97) - np.percentile(pts[:, 2], 3))
    return span if 0.9 <= span <= 3.5 and 1.0 <= zspan <= 2.2 else None


def split_group(pts: np.ndarray, family: str, span: float, person_m: float = 0.7):
    """The boxes (k, 7) of the largest split whose parts the classifier calls Pedestrian, each passing gate 1;
    None when no split qualifies."""
    from lidet_ref.cluster import make_proposal

    from .. import native
    gamma = native.pn_models()[f"cls_{family}"].gamma[PED]
    best = None
    for k in range(max(2, int(round(span / person_m))), min(4, int(round(span / 0.5))) + 1):
        lab = kmeans_along_axis(pts[:, :2], k)
        parts = [pts[lab == j] for j in range(k)]
        if min(len(p) for p in parts) < 8:
            continue
        # the parts' points stand in member order; their indices stand in for pixels (the same law of draws)
        props = [make_proposal(p, pixels=np.arange(len(p))) for p in parts]
        xyz, mean, vox = (np.stack([p[i] for p in props]) for i in range(3))
        c = native.pn_classify(f"cls_{family}", xyz, mean, vox)
        if np.all(c["cls"] == PED) and np.all(c["energy"] < gamma):
            best = native.pn_box(f"box_{family}", xyz, mean, vox, np.full(k, PED))["box"].astype(np.float64)
    return best


def frame_gain(fr, person_m: float = 0.7) -> dict:
    """New pedestrians found and new false detections on one `real.RealFrame`, and the clusters split."""
    from .. import native
    from ..eval import iou
    from ..eval_real import IGNORE_MARGIN_M, LABELLED_CLASSES, _arr, _in_fov, evaluate_frame
    from ..where_lost import points_in_box, seen_points
    r = evaluate_frame(fr)
    d = r.run  # the float detector's run that was scored
    fam = native.default_family(fr.sensor)
    seen = seen_points(fr.points, fr.sensor)
    xyz = fr.points[:, :3].astype(np.float64)
    peds = [g for g in r.gt if g.cls == "Pedestrian"]

    def hits(b):
        return [i for i, g in enumerate(peds) if float(iou.iou_bev_pairs(b[None], _arr(g)[None])[0]) >= 0.25]

    found = [False] * len(peds)
    for b in r.dets:
        if b.cls == "Pedestrian":
            for i in hits(_arr(b)):
                found[i] = True
    scored = "Pedestrian" in LABELLED_CLASSES.get(fr.source, ("Pedestrian",))
    out = dict(split=0, new_tp=0, new_fp=0)
    detected = {int(c) for c in d.cluster_id}
    for cid in range(1, len(d.outcome) + 1):
        if cid in detected:
            continue
        pts = xyz[seen & (d.point_cluster == cid) & (d.point_ground == 0)]
        span = group_shaped(pts)
        boxes = None if span is None else split_group(pts, fam, span, person_m)
        if boxes is None:
            continue
        out["split"] += 1
        for b in boxes:
            if not scored or not _in_fov(b[0], b[1], fr.fov_half_rad):
                continue
            if any(points_in_box(b[None, :3], _arr(g), IGNORE_MARGIN_M)[0] for g in r.ignore):
                continue
            h = hits(b)
            new = [i for i in h if not found[i]]
            if new:
                found[new[0]] = True
                out["new_tp"] += 1
            elif not h:
                out["new_fp"] += 1
    out["peds"] = len(peds)
    out["found"] = sum(found)
    return out


def main(argv=None) -> int:
    from .. import real
    from ..eval_real import add_frame_args, read_split
    ap = argparse.ArgumentParser(prog="python -m lidet_tools.real.group_split", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    add_frame_args(ap)
    ap.add_argument("--side", choices=("train", "val"), default="train")
    ap.add_argument("--person-m", type=float, default=0.7, help="the span one person takes in a group (m)")
    a = ap.parse_args(argv)
    if not pathlib.Path(a.root).is_dir():
        print(f"group_split: {a.root} not found", file=sys.stderr)
        return 2
    tot = dict(split=0, new_tp=0, new_fp=0, peds=0, found=0)
    print("| source | frame | clusters split | pedestrians newly found | new false detections | pedestrians (all ranges) |")
    print("|---|---|---:|---:|---:|---:|")
    for src, fid, side in read_split(a.split):
        if side != a.side:
            continue
        g = frame_gain(real.load_frame(a.root, src, fid), a.person_m)
        for k in tot:
            tot[k] += g[k]
        print(f"| {src} | {fid} | {g['split']} | {g['new_tp']} | {g['new_fp']} | {g['peds']} |")
    print(f"| all | | {tot['split']} | {tot['new_tp']} | {tot['new_fp']} | {tot['peds']} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
