# SPDX-License-Identifier: MIT
"""Random KITTI-like ground truth and perturbed predictions, for tests and the evaluation benchmark.

Not a scan simulator: only labels. Objects are placed in the sensor frame in front of the car, moved
into the rectified camera frame with a :class:`kitti.Calib` and given the 2D box of their projected
corners (clipped to the image), a truncation from the clipped fraction and a random occlusion level;
each frame also gets DontCare regions. Predictions: most ground-truth objects re-detected with noisy
centre, size and heading and a score, a few missed, plus low-scoring false positives.
"""
from __future__ import annotations

import os

import numpy as np

from ..kitti import Calib

# class, mean (l, w, h), objects per frame (Poisson mean)
OBJECT_TYPES = (("Car", (3.9, 1.6, 1.55), 5.0), ("Van", (5.0, 1.9, 2.1), 0.5),
                ("Pedestrian", (0.8, 0.6, 1.75), 1.5), ("Cyclist", (1.75, 0.6, 1.7), 0.5),
                ("Person_sitting", (0.8, 0.6, 1.2), 0.1), ("Truck", (10.0, 2.5, 3.3), 0.2))


def _camera_fields(xyz, lwh, yaw, calib):
    """Sensor-frame boxes -> (loc bottom centre, ry, unclipped 2D boxes) in the camera frame."""
    T = calib.velo_to_rect()
    R, t = T[:3, :3], T[:3, 3]
    c = xyz @ R.T + t
    loc = c + np.stack([np.zeros(len(c)), lwh[:, 2] / 2, np.zeros(len(c))], 1)
    d = np.stack([np.cos(yaw), np.sin(yaw), np.zeros(len(yaw))], 1) @ R.T
    ry = np.arctan2(-d[:, 2], d[:, 0])
    sx = np.array([1, -1, -1, 1, 1, -1, -1, 1]) * 0.5
    sy = np.array([1, 1, -1, -1, 1, 1, -1, -1]) * 0.5
    sz = np.array([-1, -1, -1, -1, 1, 1, 1, 1]) * 0.5
    cs, sn = np.cos(yaw)[:, None], np.sin(yaw)[:, None]
    dx, dy, dz = sx * lwh[:, :1], sy * lwh[:, 1:2], sz * lwh[:, 2:3]
    corners = np.stack([xyz[:, :1] + cs * dx - sn * dy, xyz[:, 1:2] + sn * dx + cs * dy,
                        xyz[:, 2:3] + dz], 2)                              # (N, 8, 3)
    cam = corners @ R.T + t
    h = np.concatenate([cam, np.ones(cam.shape[:2] + (1,))], 2) @ calib.P2.T
    uv = h[..., :2] / np.maximum(h[..., 2:3], 1e-3)
    return loc, ry, np.stack([uv[..., 0].min(1), uv[..., 1].min(1), uv[..., 0].max(1), uv[..., 1].max(1)], 1)


def _clip_bbox(bb, calib):
    W, H = calib.image_size
    out = bb.copy()
    out[:, [0, 2]] = np.clip(bb[:, [0, 2]], 0, W - 1)
    out[:, [1, 3]] = np.clip(bb[:, [1, 3]], 0, H - 1)
    area = np.maximum((bb[:, 2] - bb[:, 0]) * (bb[:, 3] - bb[:, 1]), 1e-9)
    vis = np.maximum(out[:, 2] - out[:, 0], 0) * np.maximum(out[:, 3] - out[:, 1], 0)
    return out, np.clip(1.0 - vis / area, 0.0, 1.0)


def synth_kitti(n_frames: int, seed: int = 0, calib: Calib | None = None, p_detect: float = 0.85,
                fp_per_frame: float = 1.5):
    """Returns (gt_lines, pred_lines): per frame, a list of label_2 lines (predictions with scores)."""
    rng = np.random.default_rng(seed)
    calib = calib or Calib()
    gt_out = [[] for _ in range(n_frames)]
    pr_out = [[] for _ in range(n_frames)]
    recs = []  # (frame, type, xyz, lwh, yaw)
    for name, size, lam in OBJECT_TYPES:
        n = rng.poisson(lam, n_frames)
        fr = np.repeat(np.arange(n_frames), n)
        k = len(fr)
        x = rng.uniform(4.0, 70.0, k)
        y = rng.uniform(-0.6, 0.6, k) * x
        lwh = np.asarray(size) * rng.normal(1.0, 0.06, (k, 3))
        z = -1.73 + lwh[:, 2] / 2 + rng.normal(0, 0.05, k)
        recs.append((fr, np.full(k, name, dtype=object), np.stack([x, y, z], 1), lwh,
                     rng.uniform(-np.pi, np.pi, k)))
    fr = np.concatenate([r[0] for r in recs])
    typ = np.concatenate([r[1] for r in recs])
    xyz = np.concatenate([r[2] for r in recs])
    lwh = np.concatenate([r[3] for r in recs])
    yaw = np.concatenate([r[4] for r in recs])
    order = np.argsort(fr, kind="stable")
    fr, typ, xyz, lwh, yaw = fr[order], typ[order], xyz[order], lwh[order], yaw[order]
    loc, ry, bb = _camera_fields(xyz, lwh, yaw, calib)
    bbc, trunc = _clip_bbox(bb, calib)
    occ = rng.choice([0, 1, 2, 3], len(fr), p=[0.55, 0.25, 0.15, 0.05])
    alpha = ry - np.arctan2(loc[:, 0], loc[:, 2])
    for i in range(len(fr)):
        gt_out[fr[i]].append(
            f"{typ[i]} {trunc[i]:.2f} {occ[i]} {alpha[i]:.2f} {bbc[i, 0]:.2f} {bbc[i, 1]:.2f} "
            f"{bbc[i, 2]:.2f} {bbc[i, 3]:.2f} {lwh[i, 2]:.2f} {lwh[i, 1]:.2f} {lwh[i, 0]:.2f} "
            f"{loc[i, 0]:.2f} {loc[i, 1]:.2f} {loc[i, 2]:.2f} {ry[i]:.2f}")
    # DontCare regions
    ndc = rng.poisson(1.5, n_frames)
    for f in range(n_frames):
        for _ in range(ndc[f]):
            u, v = rng.uniform(0, 1200), rng.uniform(150, 220)
            w, h = rng.uniform(10, 80), rng.uniform(8, 30)
            gt_out[f].append(f"DontCare -1 -1 -10 {u:.2f} {v:.2f} {u + w:.2f} {v + h:.2f} "
                             "-1 -1 -1 -1000 -1000 -1000 -10")
    # predictions: re-detections with noise, then false positives
    det = rng.uniform(size=len(fr)) < p_detect
    rng_m = np.hypot(xyz[:, 0], xyz[:, 1])
    pxyz = xyz + rng.normal(0, 1, xyz.shape) * (0.03 + 0.0015 * rng_m)[:, None]
    plwh = lwh * rng.normal(1.0, 0.03, lwh.shape)
    pyaw = yaw + rng.normal(0, 0.05, len(yaw))
    score = np.clip(rng.beta(5, 2, len(fr)) - 0.003 * rng_m, 0.01, 1.0)
    ptyp = typ.copy()
    ptyp[(typ == "Van") & (rng.uniform(size=len(typ)) < 0.3)] = "Car"
    nfp = rng.poisson(fp_per_frame, n_frames)
    ffp = np.repeat(np.arange(n_frames), nfp)
    k = len(ffp)
    fx = rng.uniform(4, 60, k)
    ftyp = rng.choice(["Car", "Pedestrian", "Cyclist"], k, p=[0.6, 0.3, 0.1])
    fsize = np.array([dict((t, s) for t, s, _ in OBJECT_TYPES)[t] for t in ftyp]).reshape(-1, 3)
    fxyz = np.stack([fx, rng.uniform(-0.6, 0.6, k) * fx, -1.73 + fsize[:, 2] / 2], 1)
    allf = np.concatenate([fr[det], ffp])
    allt = np.concatenate([ptyp[det], ftyp])
    axyz = np.concatenate([pxyz[det], fxyz])
    alwh = np.concatenate([plwh[det], fsize])
    ayaw = np.concatenate([pyaw[det], rng.uniform(-np.pi, np.pi, k)])
    asc = np.concatenate([score[det], rng.beta(2, 5, k)])
    loc, ry, bb = _camera_fields(axyz, alwh, ayaw, calib)
    bbc, _ = _clip_bbox(bb, calib)
    alpha = ry - np.arctan2(loc[:, 0], loc[:, 2])
    for i in np.argsort(allf, kind="stable"):
        pr_out[allf[i]].append(
            f"{allt[i]} -1 -1 {alpha[i]:.2f} {bbc[i, 0]:.2f} {bbc[i, 1]:.2f} {bbc[i, 2]:.2f} "
            f"{bbc[i, 3]:.2f} {alwh[i, 2]:.2f} {alwh[i, 1]:.2f} {alwh[i, 0]:.2f} {loc[i, 0]:.2f} "
            f"{loc[i, 1]:.2f} {loc[i, 2]:.2f} {ry[i]:.2f} {asc[i]:.4f}")
    return gt_out, pr_out


def write_frames(out_dir, frames) -> list:
    """Write per-frame line lists as <out_dir>/<000000>.txt; returns the frame ids."""
    os.makedirs(out_dir, exist_ok=True)
    ids = []
    for i, lines in enumerate(frames):
        fid = f"{i:06d}"
        with open(os.path.join(out_dir, fid + ".txt"), "w") as f:
            f.write("\n".join(lines) + ("\n" if lines else ""))
        ids.append(fid)
    return ids
