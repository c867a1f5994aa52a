# SPDX-License-Identifier: MIT
"""KITTI 3D object frames: ``kitti/training/{velodyne,calib,label_2}/NNNNNN.{bin,txt}``.

* points: velodyne .bin, already the sensor frame (HDL-64E, x forward, y left, z up).
* boxes: label_2 lines in the rectified camera frame (bottom centre, ry about camera y) -> sensor frame with
  :func:`lidet_tools.kitti.kitti_to_box` (Tr_velo_to_cam and R0_rect). Checked with BEV pictures: the boxes
  enclose their cars', pedestrians' and cyclists' points on all 9 frames.
* classes: Car, Pedestrian, Cyclist evaluated; Van, Truck -> 'Van'; Person_sitting -> 'Person_sitting';
  Tram, Misc -> 'DontCare'. DontCare lines carry no 3D box (location -1000, size -1): they are dropped, so
  ``boxes`` holds 3D objects only.
* field of view: label_2 annotates what the left colour camera sees. :func:`camera_fov_half_rad` gives the
  mean of the image's left and right half angles from P2 and the image width (1242 px, KITTI's, as
  :class:`lidet_tools.kitti.Calib` assumes; the file does not store it): about 40.7 degrees.
* mount height: 1.73 m (KITTI's documented HDL-64E mount); :func:`lidet_tools.real.fit.estimate_ground_z` on
  the 9 frames gives 1.59-1.77 m, median 1.71 m.

:func:`read_kitti_frame` is shared with the Argoverse reader (same file layout, other class names).
"""
from __future__ import annotations

import math
import pathlib
from typing import Callable

import numpy as np

from .. import kitti as kio
from . import RealFrame, finite_points, need_dir, need_file, stems

SOURCE = "kitti"
SUBDIR = "kitti/training"
MOUNT_HEIGHT_M = 1.73

_CLASS_MAP = {"Car": "Car", "Pedestrian": "Pedestrian", "Cyclist": "Cyclist", "Van": "Van", "Truck": "Van",
              "Person_sitting": "Person_sitting"}


def map_class(name: str) -> str:
    """KITTI class -> RealFrame class (anything unknown -> 'DontCare')."""
    return _CLASS_MAP.get(name, "DontCare")


def camera_fov_half_rad(calib: kio.Calib) -> float:
    """Mean of the left and right half angles of the P2 camera's image (calib.image_size width)."""
    fx, cx = calib.P2[0, 0], calib.P2[0, 2]
    if fx <= 0:
        raise ValueError(f"P2 focal length {fx} <= 0")
    width = calib.image_size[0]
    return 0.5 * (math.atan2(cx, fx) + math.atan2(width - cx, fx))


def list_frames(root: pathlib.Path) -> list[str]:
    return list_kitti_layout(root / SUBDIR)


def list_kitti_layout(base: pathlib.Path) -> list[str]:
    """Stems having a label_2 .txt, a velodyne .bin and a calib .txt under base."""
    return sorted(stems(base / "label_2", ".txt") & stems(base / "velodyne", ".bin")
                  & stems(base / "calib", ".txt"))


def read_kitti_frame(base: pathlib.Path, frame_id: str, map_cls: Callable[[str], str]):
    """(points (N, 4) float32 finite, sensor-frame boxes, calib) of base/{velodyne,calib,label_2}/frame_id.
    Label objects without a 3D box (any size <= 0, as KITTI's DontCare lines) are dropped."""
    need_dir(base)
    vel = need_file(base / "velodyne" / f"{frame_id}.bin")
    cal_p = need_file(base / "calib" / f"{frame_id}.txt")
    lab = need_file(base / "label_2" / f"{frame_id}.txt")
    points, _ = finite_points(kio.read_bin(vel), vel)
    calib = kio.read_calib(cal_p)
    if abs(np.linalg.det(calib.velo_to_rect()[:3, :3])) < 1e-6:
        raise ValueError(f"{cal_p}: R0_rect @ Tr_velo_to_cam is singular")
    boxes = []
    for obj in kio.read_label2(lab):
        if min(obj.h, obj.w, obj.l) <= 0:
            continue
        b = kio.kitti_to_box(obj, calib)
        b.cls = map_cls(obj.type)
        boxes.append(b)
    return points, boxes, calib


def load_frame(root: pathlib.Path, frame_id: str) -> RealFrame:
    points, boxes, calib = read_kitti_frame(root / SUBDIR, frame_id, map_class)
    return RealFrame(SOURCE, frame_id, points, boxes, camera_fov_half_rad(calib), "hdl64", MOUNT_HEIGHT_M)
