# SPDX-License-Identifier: MIT
"""Write a simulated scan in KITTI's folder layout.

    DIR/velodyne/NNNNNN.bin   float32 x, y, z, remission (sensor frame), ring by ring
    DIR/labels/NNNNNN.label   SemanticKITTI uint32 (class | instance << 16)
    DIR/label_2/NNNNNN.txt    KITTI objects in the rectified camera frame (virtual front camera)
    DIR/calib/NNNNNN.txt      P0..P3, R0_rect, Tr_velo_to_cam, Tr_imu_to_velo
    DIR/boxes/NNNNNN.txt      lidet sensor-frame box lines (all road users with >= 1 point, 360 deg)
    DIR/ring/NNNNNN.bin       uint16 ring index per point (ring order of sensors.py)
"""
from __future__ import annotations

import os

import numpy as np

from .. import kitti
from .simulate import ScanResult

SUBDIRS = ("velodyne", "labels", "label_2", "calib", "boxes", "ring")


def scan_paths(out_dir, name: str) -> dict:
    return {
        "velodyne": os.path.join(out_dir, "velodyne", f"{name}.bin"),
        "labels": os.path.join(out_dir, "labels", f"{name}.label"),
        "label_2": os.path.join(out_dir, "label_2", f"{name}.txt"),
        "calib": os.path.join(out_dir, "calib", f"{name}.txt"),
        "boxes": os.path.join(out_dir, "boxes", f"{name}.txt"),
        "ring": os.path.join(out_dir, "ring", f"{name}.bin"),
    }


def write_scan(out_dir, name: str, r: ScanResult) -> dict:
    p = scan_paths(out_dir, name)
    kitti.write_bin(p["velodyne"], r.points)
    kitti.write_label(p["labels"], r.sem, r.inst)
    kitti.write_label2(p["label_2"], r.label2)
    kitti.write_calib(p["calib"], r.calib)
    kitti.write_boxes(p["boxes"], r.boxes)
    os.makedirs(os.path.dirname(p["ring"]), exist_ok=True)
    np.asarray(r.ring, dtype="<u2").tofile(p["ring"])
    return p


def read_ring(path) -> np.ndarray:
    return np.fromfile(path, dtype="<u2")
