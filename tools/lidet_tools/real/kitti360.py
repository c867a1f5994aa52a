# SPDX-License-Identifier: MIT
"""KITTI-360 scans with car boxes: ``kitti360/velodyne/00000NNNNN.bin``, ``bboxes_3D_cam0/BBoxes_N.json``,
``calibration/calib_cam_to_velo.txt``.

Conventions found (checked with BEV pictures and box close-ups of all 12 frames, ``show --crops``):

* points: velodyne .bin (HDL-64E), sensor frame.
* boxes: a json list of {"index": int, "corners_cam0": 8 x [x, y, z]} in camera-0 coordinates; the 3x4
  calib_cam_to_velo maps them into the velodyne frame. No rectification: with R_rect_00 of perspective.txt
  (0.4 degrees) or its inverse the points fit the boxes no better (share of the cars' near points inside,
  :func:`lidet_tools.real.fit.box_point_share`: 0.951 as given, 0.951 / 0.948 rectified), so corners are used
  as they are. The corner order of SOURCE_README is *not* the files' (their corners 0 and 2 are the top ones):
  :func:`lidet_tools.real.fit.box_from_corners` is order-free (edges at one corner) and raises ValueError on
  corners that do not form a cuboid. The boxes are upright in the world, so tilted by the car's pitch in the
  velodyne frame (0.3-2.7 degrees here); the yaw-only Box3D keeps their exact l, w, h and centre. The files
  carry no heading: yaw is the long side's direction modulo pi, in [-pi/2, pi/2). Many are perpendicular
  parked cars (checked in the pictures: the box rows match the cars' fronts).
* chains: a car annotated at several times along its path appears as a chain of boxes; boxes are one chain
  when they share an "index", or overlap in BEV with the same l, w, h within 5 cm (:func:`chain_groups`;
  neighbouring parked cars' boxes touch but differ in size). Of each chain the box with the most points
  inside is kept, and only boxes with at least :data:`MIN_POINTS` point inside. In the 12 files here every
  index is unique and no two overlapping boxes share a size, so no chain occurs: the boxes dropped (the
  files hold 243, 108 kept) are those without points (far away, or hidden).
* classes: Car only. Labels cover 360 degrees (cars behind the vehicle are boxed too): fov None.
* mount height: 1.73 m, the median over the 12 scans of :func:`lidet_tools.real.fit.estimate_ground_z`
  (1.72 m; per scan 1.52-1.95 m on sloped streets).
"""
from __future__ import annotations

import json
import pathlib
import re

import numpy as np

from ..kitti import Box3D, box_corners, read_bin
from . import RealFrame, finite_points, need_dir, need_file
from .fit import box_from_corners, points_in_box

SOURCE = "kitti360"
SUBDIR = "kitti360"
MOUNT_HEIGHT_M = 1.73
#: a kept box holds at least this many points
MIN_POINTS = 1
#: boxes of one chain (one car at several times) have the same l, w, h within this (metres)
CHAIN_SIZE_TOL_M = 0.05

_JSON_RE = re.compile(r"^BBoxes_(\d+)\.json$")


def list_frames(root: pathlib.Path) -> list[str]:
    """Ids '00000NNNNN' (the velodyne stems) having a BBoxes_N.json."""
    base = root / SUBDIR
    ids = []
    for name in sorted(p.name for p in need_dir(base / "bboxes_3D_cam0").iterdir()):
        m = _JSON_RE.match(name)
        if m and (base / "velodyne" / f"{int(m.group(1)):010d}.bin").is_file():
            ids.append(f"{int(m.group(1)):010d}")
    return sorted(ids)


def read_cam_to_velo(path) -> np.ndarray:
    """(4, 4) camera-0 -> velodyne transform from a file of 12 numbers (3x4 row-major)."""
    p = need_file(path)
    try:
        v = np.array(p.read_text().split(), dtype=np.float64)
    except ValueError:
        raise ValueError(f"{p}: non-numeric value") from None
    if v.size != 12 or not np.all(np.isfinite(v)):
        raise ValueError(f"{p}: expected 12 finite numbers (3x4 camera-0 -> velodyne), got {v.size}")
    T = np.eye(4)
    T[:3] = v.reshape(3, 4)
    if abs(np.linalg.det(T[:3, :3]) - 1.0) > 1e-3:
        raise ValueError(f"{p}: rotation part is not a rotation (det {np.linalg.det(T[:3, :3]):.4f})")
    return T


def read_boxes_json(path, cam_to_velo: np.ndarray) -> list[tuple[int, Box3D]]:
    """[(index, velodyne-frame Box3D 'Car')] of every json entry. Raises ValueError on a malformed entry or on
    corners that do not form a box."""
    p = need_file(path)
    try:
        objs = json.loads(p.read_text())
    except json.JSONDecodeError as e:
        raise ValueError(f"{p}: not valid json ({e.msg} at line {e.lineno})") from None
    if not isinstance(objs, list):
        raise ValueError(f"{p}: expected a json list of objects")
    out = []
    for k, o in enumerate(objs):
        try:
            idx = int(o["index"])
            c = np.array(o["corners_cam0"], dtype=np.float64)
        except (KeyError, TypeError, ValueError):
            raise ValueError(f"{p}: entry {k}: expected {{'index': int, 'corners_cam0': 8 x [x, y, z]}}") from None
        if c.shape != (8, 3) or not np.all(np.isfinite(c)):
            raise ValueError(f"{p}: entry {k} (index {idx}): corners_cam0 must be 8 finite [x, y, z], "
                             f"got shape {c.shape}")
        v = c @ cam_to_velo[:3, :3].T + cam_to_velo[:3, 3]
        try:
            b = box_from_corners(v, "Car")
        except ValueError as e:
            raise ValueError(f"{p}: entry {k} (index {idx}): {e}") from None
        out.append((idx, b))
    return out


def _overlap(a: Box3D, b: Box3D) -> bool:
    """BEV rectangles intersect (separating-axis test)."""
    ca, cb = box_corners(a)[:4, :2], box_corners(b)[:4, :2]
    for yaw in (a.yaw, b.yaw):
        for ax in (np.array([np.cos(yaw), np.sin(yaw)]), np.array([-np.sin(yaw), np.cos(yaw)])):
            pa, pb = ca @ ax, cb @ ax
            if pa.max() < pb.min() or pb.max() < pa.min():
                return False
    return True


def chain_groups(boxes: list[Box3D], indices: list[int] | None = None,
                 size_tol_m: float = CHAIN_SIZE_TOL_M) -> list[int]:
    """Chain id per box: boxes are linked when they share an index, or when their BEV rectangles overlap and
    l, w, h agree within size_tol_m (one car's size does not change along its path; neighbouring parked cars'
    boxes touch but differ in size); chains are the connected groups (ids 0.. in order of first box)."""
    n = len(boxes)
    parent = list(range(n))

    def find(i: int) -> int:
        while parent[i] != i:
            parent[i] = parent[parent[i]]
            i = parent[i]
        return i

    for i in range(n):
        for j in range(i + 1, n):
            a, b = boxes[i], boxes[j]
            same = indices is not None and indices[i] == indices[j]
            if same or (max(abs(a.l - b.l), abs(a.w - b.w), abs(a.h - b.h)) <= size_tol_m and _overlap(a, b)):
                parent[find(j)] = find(i)
    ids: dict[int, int] = {}
    return [ids.setdefault(find(i), len(ids)) for i in range(n)]


def load_frame(root: pathlib.Path, frame_id: str) -> RealFrame:
    base = root / SUBDIR
    if not frame_id.isdigit():
        raise ValueError(f"kitti360 frame id must be digits (the velodyne stem), got {frame_id!r}")
    vel = need_file(base / "velodyne" / f"{frame_id}.bin")
    points, _ = finite_points(read_bin(vel), vel)
    T = read_cam_to_velo(base / "calibration" / "calib_cam_to_velo.txt")
    entries = read_boxes_json(base / "bboxes_3D_cam0" / f"BBoxes_{int(frame_id)}.json", T)
    boxes = [b for _, b in entries]
    counts = [int(points_in_box(points, b).sum()) for b in boxes]
    best: dict[int, int] = {}
    for k, g in enumerate(chain_groups(boxes, [i for i, _ in entries])):
        if g not in best or counts[k] > counts[best[g]]:
            best[g] = k
    kept = [boxes[k] for k in sorted(best.values()) if counts[k] >= MIN_POINTS]
    return RealFrame(SOURCE, frame_id, points, kept, None, "hdl64", MOUNT_HEIGHT_M)

