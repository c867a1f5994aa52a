# SPDX-License-Identifier: MIT
"""SqueezeSeg's KITTI raw front views: ``kitti_raw_squeezeseg/*.npy``, 64 x 512 x 6 float32 (x, y, z,
intensity, range, label: 0 none, 1 car, 2 pedestrian, 3 cyclist).

* points: the non-empty pixels (any of x, y, z, intensity, range non-zero; empty pixels are all zeros) of KITTI
  raw's HDL-64E in its sensor frame; intensity 0-1. The view spans azimuths -45..45 degrees (512 columns):
  fov_half_rad = pi / 4. Mount height 1.73 m (KITTI's car; :func:`lidet_tools.real.fit.estimate_ground_z`
  gives 1.64-1.65 m on the 4 views).
* objects: no instance ids. The labelled points of each class are split by Euclidean clustering
  (:func:`lidet_tools.real.fit.connected_components`): 0.8 m link for cars, 0.5 m for pedestrians and
  cyclists; components with fewer than 5 points are skipped. Labels come from KITTI's boxes, so two cars
  parked closer than 0.8 m become one object (visible in the pictures as one long box).
* boxes: fitted to the visible points like SemanticKITTI's (:func:`lidet_tools.real.fit.fit_box_to_points`):
  approx_boxes=True, point_instance filled. Checked with BEV pictures coloured by object.
"""
from __future__ import annotations

import math
import pathlib

import numpy as np

from . import RealFrame, finite_points, need_file, stems
from .fit import boxes_from_objects, connected_components

SOURCE = "squeezeseg"
SUBDIR = "kitti_raw_squeezeseg"
MOUNT_HEIGHT_M = 1.73
FOV_HALF_RAD = math.pi / 4
MIN_POINTS = 5
#: label value -> (class, clustering link distance in metres)
CLASSES = {1: ("Car", 0.8), 2: ("Pedestrian", 0.5), 3: ("Cyclist", 0.5)}


def list_frames(root: pathlib.Path) -> list[str]:
    return sorted(stems(root / SUBDIR, ".npy"))


def read_npy(path) -> tuple[np.ndarray, np.ndarray]:
    """(points (N, 4) float32 of the non-empty finite pixels, labels (N,) int) of a SqueezeSeg .npy."""
    p = need_file(path)
    try:
        a = np.load(p, allow_pickle=False)
    except (ValueError, OSError, EOFError) as e:
        raise ValueError(f"{p}: not a readable .npy array ({e})") from None
    if a.ndim != 3 or a.shape[2] != 6:
        raise ValueError(f"{p}: expected an H x W x 6 array (x, y, z, intensity, range, label), got {a.shape}")
    flat = a.reshape(-1, 6).astype(np.float64)
    filled = np.any(flat[:, :5] != 0, axis=1)
    points, keep = finite_points(flat[filled, :4], p)
    lab = flat[filled, 5][keep]
    if not np.all(np.isin(lab, (0, 1, 2, 3))):
        bad = np.unique(lab[~np.isin(lab, (0, 1, 2, 3))])[:5]
        raise ValueError(f"{p}: labels must be 0-3, found {bad.tolist()}")
    return points, lab.astype(np.int64)


def load_frame(root: pathlib.Path, frame_id: str) -> RealFrame:
    points, lab = read_npy(root / SUBDIR / f"{frame_id}.npy")
    objects = []
    for value, (cls, link) in CLASSES.items():
        idx = np.flatnonzero(lab == value)
        if len(idx) == 0:
            continue
        comp = connected_components(points[idx, :3], link)
        objects += [(cls, idx[comp == k]) for k in range(comp.max() + 1)]
    boxes, inst = boxes_from_objects(points, objects, MIN_POINTS)
    return RealFrame(SOURCE, frame_id, points, boxes, FOV_HALF_RAD, "hdl64", MOUNT_HEIGHT_M, inst, True)
