# SPDX-License-Identifier: MIT
"""A small synthetic street scene for pictures and tests: a 32-beam sensor 1.73 m above flat ground,
rays cast against boxes (road users, walls), so objects cast shadows as in a real scan. Not the
project's scan simulator (lidet_tools.sim); only enough to show what the plots look like."""
from __future__ import annotations

import numpy as np

from ..kitti import Box3D

MOUNT_M = 1.73


def _cast(origin_dirs, boxes):
    """Ray (from the origin) parameter of the first hit with each box: (R, B) array, inf if none."""
    d = origin_dirs
    out = np.full((len(d), len(boxes)), np.inf)
    for k, b in enumerate(boxes):
        c, s = np.cos(-b.yaw), np.sin(-b.yaw)
        o = np.array([-b.x, -b.y, -b.z])
        o = np.array([c * o[0] - s * o[1], s * o[0] + c * o[1], o[2]])
        dl = np.stack([c * d[:, 0] - s * d[:, 1], s * d[:, 0] + c * d[:, 1], d[:, 2]], 1)
        half = np.array([b.l, b.w, b.h]) / 2
        with np.errstate(divide="ignore", invalid="ignore"):
            t1 = (-half - o) / dl
            t2 = (half - o) / dl
        tmin = np.nanmax(np.minimum(t1, t2), axis=1)
        tmax = np.nanmin(np.maximum(t1, t2), axis=1)
        hit = (tmax >= tmin) & (tmin > 0)
        out[hit, k] = tmin[hit]
    return out


def demo_scene(seed: int = 3, n_az: int = 1800):
    """Returns (points (N, 4), cluster ids (N,), ground mask (N,), gt boxes, predicted boxes)."""
    rng = np.random.default_rng(seed)
    z0 = -MOUNT_M
    users = [
        Box3D("Car", 9.0, -2.0, z0 + 0.75, 4.2, 1.8, 1.5, 0.05),
        Box3D("Car", 17.0, 3.2, z0 + 0.75, 4.0, 1.7, 1.5, np.pi + 0.02),
        Box3D("Car", 27.0, -2.5, z0 + 0.78, 4.5, 1.8, 1.56, 0.1),
        Box3D("Car", -12.0, 2.8, z0 + 0.75, 4.1, 1.7, 1.5, np.pi),
        Box3D("Car", 38.0, 3.0, z0 + 0.75, 4.0, 1.7, 1.5, np.pi - 0.05),
        Box3D("Car", 6.0, 8.0, z0 + 0.75, 4.0, 1.7, 1.5, 1.57),
        Box3D("Pedestrian", 12.0, 7.0, z0 + 0.88, 0.7, 0.6, 1.76, 1.6),
        Box3D("Pedestrian", 14.5, -7.5, z0 + 0.85, 0.8, 0.6, 1.7, -1.5),
        Box3D("Pedestrian", -5.0, -7.0, z0 + 0.85, 0.7, 0.6, 1.7, 0.0),
        Box3D("Cyclist", 21.0, 0.5, z0 + 0.85, 1.8, 0.6, 1.7, 0.0),
    ]
    walls = [Box3D("wall", 10.0, 11.5, z0 + 3.0, 40.0, 1.0, 6.0, 0.0),
             Box3D("wall", 44.0, 11.5, z0 + 3.0, 16.0, 1.0, 6.0, 0.0),
             Box3D("wall", 0.0, -11.5, z0 + 2.5, 24.0, 1.0, 5.0, 0.0),
             Box3D("wall", 35.0, -11.5, z0 + 2.5, 30.0, 1.0, 5.0, 0.0),
             Box3D("wall", -30.0, 0.0, z0 + 2.0, 1.0, 30.0, 4.0, 0.0),
             Box3D("pole", 19.0, -6.5, z0 + 2.0, 0.3, 0.3, 4.0, 0.0),
             Box3D("pole", 30.0, 6.5, z0 + 2.0, 0.3, 0.3, 4.0, 0.0)]
    elev = np.deg2rad(np.linspace(-24.9, 4.0, 32))
    az = np.linspace(-np.pi, np.pi, n_az, endpoint=False)
    E, A = np.meshgrid(elev, az, indexing="ij")
    d = np.stack([np.cos(E) * np.cos(A), np.cos(E) * np.sin(A), np.sin(E)], -1).reshape(-1, 3)
    t_obj = _cast(d, users + walls)
    with np.errstate(divide="ignore"):
        t_ground = np.where(d[:, 2] < 0, z0 / d[:, 2], np.inf)
    t_all = np.concatenate([t_ground[:, None], t_obj], 1)
    which = np.argmin(t_all, 1)
    t = t_all[np.arange(len(d)), which]
    keep = np.isfinite(t) & (t < 80.0)
    t = t[keep] + rng.normal(0, 0.01, keep.sum())
    which = which[keep]
    xyz = d[keep] * t[:, None]
    pts = np.concatenate([xyz, rng.uniform(0.1, 0.6, (len(xyz), 1))], 1).astype(np.float32)
    ground = which == 0
    clusters = np.where(ground, 0, which)          # one cluster per object, 0 = no cluster
    preds = []
    for i, b in enumerate(users):
        if i == 4:
            continue  # a missed car
        preds.append(Box3D(b.cls, b.x + rng.normal(0, 0.15), b.y + rng.normal(0, 0.1), b.z, b.l * 0.97,
                           b.w, b.h, b.yaw + rng.normal(0, 0.05), float(np.clip(rng.beta(6, 2), 0, 1))))
    preds.append(Box3D("Pedestrian", 19.0, -6.5, z0 + 0.9, 0.6, 0.6, 1.8, 0.0, 0.41))  # the pole
    return pts, clusters, ground, users, preds
