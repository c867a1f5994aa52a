# SPDX-License-Identifier: MIT
"""SemanticKITTI scans: ``semantickitti/velodyne/STEM.bin`` + ``semantickitti/labels/STEM.label`` (uint32 per
point: lower 16 bits class, upper 16 bits instance). Only stems with a .label are listed (00_000003-5 have
none).

* points: KITTI's HDL-64E, sensor frame; mount height 1.73 m (KITTI's car; the road-labelled points (40) at
  3-20 m lie 1.77-1.82 m below the sensor, :func:`lidet_tools.real.fit.estimate_ground_z` gives 1.81-1.94 m:
  cambered and sloped roads). Labels cover 360 degrees: fov None.
* objects: the points of one (class, instance id) pair; class ids with instance 0 (none given) are split by
  Euclidean clustering (0.5 m). Classes: car 10 / moving-car 252 -> Car; person 30 / 254 -> Pedestrian;
  bicyclist 31 / 253 (the rider) joined with every bicycle (11) instance within 1 m of it -> Cyclist, a
  bicycle without a rider -> 'Other'; truck 18 / 258, other-vehicle 20 / 259, bus 13 / 257, on-rails
  16 / 256 -> 'Van'; motorcyclist 32 / 255 joined with a motorcycle (15) within 1 m, or either alone ->
  'Other'. Objects with fewer than 5 points are skipped.
* boxes: no annotated boxes exist; each is fitted to its visible points (:func:`lidet_tools.real.fit.
  fit_box_to_points`: L-shape yaw, extended to the class prior away from the sensor, z from the points):
  approx_boxes=True, and point_instance gives every labelled point's box. Checked with BEV pictures coloured
  by instance: every box covers its instance's points; far cars seen from one end grow away from the sensor.
"""
from __future__ import annotations

import pathlib

import numpy as np

from ..kitti import read_bin, read_label
from . import RealFrame, finite_points, need_file, stems
from .fit import boxes_from_objects, connected_components

SOURCE = "semantickitti"
SUBDIR = "semantickitti"
MOUNT_HEIGHT_M = 1.73
MIN_POINTS = 5
#: rider and vehicle closer than this (metres, nearest points) are one object
JOIN_M = 1.0
#: link distance splitting points of a thing class that carry no instance id
CLUSTER_M = 0.5

_CLASS = {10: "Car", 252: "Car", 30: "Pedestrian", 254: "Pedestrian", 18: "Van", 258: "Van", 20: "Van",
          259: "Van", 13: "Van", 257: "Van", 16: "Van", 256: "Van"}
#: rider class ids -> (vehicle class id they ride, class of the joined object)
_RIDERS = {31: (11, "Cyclist"), 253: (11, "Cyclist"), 32: (15, "Other"), 255: (15, "Other")}
_RIDDEN = {11: "Other", 15: "Other"}   # a vehicle without rider
THING_IDS = tuple(_CLASS) + tuple(_RIDERS) + tuple(_RIDDEN)


def list_frames(root: pathlib.Path) -> list[str]:
    base = root / SUBDIR
    return sorted(stems(base / "velodyne", ".bin") & stems(base / "labels", ".label"))


def _groups(points: np.ndarray, sem: np.ndarray, ins: np.ndarray) -> dict[tuple[int, int], np.ndarray]:
    """{(class id, instance key): point indices} of the thing classes; instance-0 points are split into
    clusters given negative keys."""
    out: dict[tuple[int, int], np.ndarray] = {}
    for c in THING_IDS:
        idx = np.flatnonzero(sem == c)
        if len(idx) == 0:
            continue
        for i in np.unique(ins[idx]):
            sub = idx[ins[idx] == i]
            if i != 0:
                out[(int(c), int(i))] = sub
                continue
            lab = connected_components(points[sub, :3], CLUSTER_M)
            for k in range(lab.max() + 1):
                out[(int(c), -1 - k)] = sub[lab == k]
    return out


def _min_dist(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.sqrt(((a[:, None, :3] - b[None, :, :3]) ** 2).sum(-1).min()))


def objects_from_labels(points: np.ndarray, sem: np.ndarray, ins: np.ndarray) -> list[tuple[str, np.ndarray]]:
    """[(class, point indices)] of the labelled objects (riders joined with their vehicles, see above)."""
    groups = _groups(points, sem, ins)
    used: set[tuple[int, int]] = set()
    objects = []
    for key, idx in groups.items():
        if key[0] in _RIDERS:
            veh_id, cls = _RIDERS[key[0]]
            parts = [idx]
            for vkey, vidx in groups.items():
                if vkey[0] == veh_id and vkey not in used and _min_dist(points[idx], points[vidx]) <= JOIN_M:
                    parts.append(vidx)
                    used.add(vkey)
            objects.append((cls, np.concatenate(parts)))
    for key, idx in groups.items():
        if key[0] in _CLASS:
            objects.append((_CLASS[key[0]], idx))
        elif key[0] in _RIDDEN and key not in used:
            objects.append((_RIDDEN[key[0]], idx))
    return objects


def load_frame(root: pathlib.Path, frame_id: str) -> RealFrame:
    base = root / SUBDIR
    vel = need_file(base / "velodyne" / f"{frame_id}.bin")
    lab = need_file(base / "labels" / f"{frame_id}.label")
    raw = read_bin(vel)
    sem, ins = read_label(lab, len(raw))
    points, keep = finite_points(raw, vel)
    sem, ins = sem[keep], ins[keep]
    boxes, inst = boxes_from_objects(points, objects_from_labels(points, sem, ins), MIN_POINTS)
    return RealFrame(SOURCE, frame_id, points, boxes, None, "hdl64", MOUNT_HEIGHT_M, inst, True,
                     point_semantic=sem.astype(np.int32))
