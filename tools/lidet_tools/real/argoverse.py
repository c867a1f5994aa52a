# SPDX-License-Identifier: MIT
"""Argoverse 1 frames converted to KITTI's layout: ``argoverse1_kitti/{velodyne,calib,label_2}/NNNNNN``.

Conventions found (checked with BEV pictures and close-ups of every box, ``show --crops``):

* points: the two stacked VLP-32C of the Argoverse car merged, in the *vehicle* frame (origin on the rear axle,
  x forward, y left, z up: the road is at z = -0.41 m), intensity always 1.0. The elevation histogram holds
  two VLP-32C beam tables, one mirrored (one sensor upside down). The reader moves the origin to the upper
  (upright) LiDAR at :data:`LIDAR_IN_VEHICLE_M` = (1.29, 0.10, 1.58) m, measured by
  :func:`estimate_lidar_origin`: the innermost road ring (the upright sensor's -25 degree beam) is a circle
  around the sensor (centre = x, y; least-squares circle fit, residual 0.10 m) whose radius r puts the sensor
  r tan(25 deg) = 1.99 m above the road (z). Same on the 3 frames to 1 cm.
* boxes: label_2 lines (bottom centre, rectified camera frame) -> :func:`lidet_tools.kitti.kitti_to_box`
  with the file's R0_rect (a 4.3 degree rotation) *applied*: without it the boxes miss their points (boxes
  holding >= 80 % of their near points, :func:`lidet_tools.real.fit.box_point_share`: 11 of 50 without,
  55 of 61 with it); P0 / P1 are zeros and unused. The label_2 location is the cuboid's *centre* (Argoverse's
  own convention), not KITTI's bottom centre: read as a bottom centre, every box stood h / 2 too high (box tops
  0.9 m above the highest points of their cars, 1.05 m above those of their pedestrians, median within 40 m; with
  the centre read as such, 0.07 m and 0.16 m, as on the other sources: :func:`centre_lift`). Then shifted like the
  points.
* classes (case-insensitive: the files have 'Car', 'PEDESTRIAN', 'ON_ROAD_OBSTACLE'): car / vehicle -> Car,
  pedestrian -> Pedestrian, cyclist / bicyclist -> Cyclist, large_vehicle / bus / trailer / truck / van /
  emergency_vehicle -> Van, anything else -> Other.
* field of view: the converter kept the objects in front of the front camera (centres from x = 3.7 m to 212 m,
  azimuths -43..60 degrees, none behind: the parked cars at x = -3 and -8 m in the pictures are unboxed),
  not only those inside its (616 px wide) image: many boxes have a 2D box clipped to [0, 0] or [615, 615].
  So labels exist over the front half-plane: :data:`FOV_HALF_RAD` = pi / 2.
* ground: the files lost most road points beyond ~8 m (the road's share of points is 6-13 % past 10 m
  against 36-53 % in KITTI), so :func:`lidet_tools.real.fit.estimate_ground_z` does not apply here.
* mount height: 1.99 m (the upright sensor over the road, as above).
"""
from __future__ import annotations

import math
import pathlib

import numpy as np

from .. import kitti as kio
from . import RealFrame
from .kitti import list_kitti_layout, read_kitti_frame

SOURCE = "argoverse"
SUBDIR = "argoverse1_kitti"
#: the upright VLP-32C in the vehicle frame of the files (see the module docstring)
LIDAR_IN_VEHICLE_M = (1.29, 0.10, 1.58)
MOUNT_HEIGHT_M = 1.99
#: labels exist within this azimuth of the sensor's x axis: the front half-plane (see the module docstring)
FOV_HALF_RAD = math.pi / 2
LOWEST_BEAM_RAD = math.radians(25.0)

_CLASS_MAP = {"car": "Car", "vehicle": "Car", "pedestrian": "Pedestrian", "cyclist": "Cyclist",
              "bicyclist": "Cyclist", "large_vehicle": "Van", "bus": "Van", "trailer": "Van", "truck": "Van",
              "van": "Van", "emergency_vehicle": "Van"}


def map_class(name: str) -> str:
    """Argoverse class name (any case) -> RealFrame class."""
    return _CLASS_MAP.get(name.lower(), "Other")


def list_frames(root: pathlib.Path) -> list[str]:
    return list_kitti_layout(root / SUBDIR)


def estimate_lidar_origin(points_vehicle: np.ndarray, ground_band=(-0.8, 0.0)) -> tuple[float, float, float]:
    """(x, y, z) of the upright LiDAR in the files' vehicle frame from one scan: circle fit of the innermost
    road ring (points with z in ground_band, within 0.3 m of the first dense 0.1 m bin of horizontal distance
    from (1.3, 0)); z = road z + radius * tan(25 deg) (the VLP-32C's lowest beam)."""
    p = np.asarray(points_vehicle, dtype=np.float64)
    g = p[(p[:, 2] > ground_band[0]) & (p[:, 2] < ground_band[1])]
    r = np.hypot(g[:, 0] - 1.3, g[:, 1])
    hist, edges = np.histogram(r, bins=np.arange(0.0, 10.0, 0.1))
    dense = np.flatnonzero(hist > 100)
    if len(dense) == 0:
        raise ValueError("no dense road ring within 10 m")
    r0 = edges[dense[0]]
    ring = g[(r > r0 - 0.3) & (r < r0 + 0.6)]
    x, y = ring[:, 0], ring[:, 1]
    sol = np.linalg.lstsq(np.stack([x, y, np.ones_like(x)], 1), x * x + y * y, rcond=None)[0]
    cx, cy = sol[0] / 2, sol[1] / 2
    rad = math.sqrt(sol[2] + cx * cx + cy * cy)
    return float(cx), float(cy), float(np.median(ring[:, 2]) + rad * math.tan(LOWEST_BEAM_RAD))


def centre_lift(calib, h: float) -> np.ndarray:
    """The sensor-frame vector by which `kio.kitti_to_box` lifts a label_2 location to a box centre (h / 2 along
    the rectified camera's -y): these files' locations are already the centres, so the reader takes it back."""
    a, b = calib.cam_to_velo_points(np.array([[0.0, 0.0, 0.0], [0.0, -h / 2.0, 0.0]], dtype=np.float64))
    return np.asarray(b - a, dtype=np.float64)


def load_frame(root: pathlib.Path, frame_id: str) -> RealFrame:
    points, boxes, calib = read_kitti_frame(root / SUBDIR, frame_id, map_class)
    o = np.array(LIDAR_IN_VEHICLE_M, dtype=np.float64)
    points[:, :3] = (points[:, :3].astype(np.float64) - o).astype(np.float32)
    moved = []
    for b in boxes:
        c = np.array([b.x, b.y, b.z], dtype=np.float64) - centre_lift(calib, b.h) - o
        moved.append(kio.Box3D(b.cls, float(c[0]), float(c[1]), float(c[2]), b.l, b.w, b.h, b.yaw, b.score))
    return RealFrame(SOURCE, frame_id, points, moved, FOV_HALF_RAD, "vlp32c", MOUNT_HEIGHT_M)
