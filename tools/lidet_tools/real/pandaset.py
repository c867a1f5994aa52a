# SPDX-License-Identifier: MIT
"""PandaSet scans as converted by Bynow76/pandaset (``pandaset/make_labels.py.txt``): ``pandaset/NNNNNN.bin``
(float32 x, y, z, intensity 0-255) and ``NNNNNN.txt`` (``class 0 x y z l w h yaw`` [points]).

What the conversion did, and how this reader undoes it (checked with BEV pictures and close-ups of every box of
all 5 frames, and numerically as stated):

* frame: the converter moved the Pandar64 points and the cuboid corners from world coordinates into the LiDAR
  *pose* frame (``lidar_points_to_ego``) and turned it to x forward, y left. The road rings are centred on
  (0, 0) within 0.3 m, so x, y are the LiDAR's; but the road lies only 0.1-0.4 m below z = 0 (the pose's
  origin is not the sensor in z: pandaset-devkit issue #80) and the lowest beam's (-25 degree) innermost road
  ring has a radius of 4.1-4.7 m (10th percentile of the nearest road point over 5-degree sectors), i.e. the
  sensor sits r tan(25 deg) = 1.91-2.20 m above the road: :data:`MOUNT_HEIGHT_M` = 2.05 m (the same method
  gives 1.64-1.84 m on KITTI's 1.73 m mount). The reader shifts points and
  boxes in z so that the road (:func:`lidet_tools.real.fit.estimate_ground_z`, per frame) lies at
  -MOUNT_HEIGHT_M. Intensities are kept as they are (0-255).
* boxes, two label formats, told apart per file by their digits (sizes in PandaSet are whole millimetres):
  - *corner* format (000000, 000800, 004000: h exact, exactly one of l, w exact): ``caculate_label`` on
    the 8 corners. Centre = corner mean (box centre: the box bottoms lie on the road in the pictures).
    yaw = the direction of the cuboid's *length* edge (PandaSet's dimensions.y; modulo pi). The length is
    exact; the width came out as w' = (3 w + sqrt(w^2 + h^2)) / 4 (one of its four "width" edges is a
    diagonal of the front face: deta7), inverted here exactly (:func:`unbias_width`: the inverted widths
    are again whole millimetres). When w' > length the converter swapped them *without turning yaw*:
    those lines have l = w', w = length. So a line whose l is exact is (l, w') along yaw; a line whose w
    is exact is (w, l') along yaw, i.e. the rectangle (l, w, yaw + pi/2) - the 90-degree-turned boxes of
    the pictures (mostly pedestrians). Where the digits do not decide (hand-made or rounded files), the
    points do (:func:`choose_by_points`). On the real files the digits always decide; where the points are
    decisive they agree with them in 228 of 244 lines (the others: near-square pedestrians in groups, or
    few points where the turned rectangle reaches a neighbour).
  - *extent* format (000200, 000500: no size exact): l, w, h are the x, y, z extents of the 8 corners
    (the commented-out lines of ``caculate_label``), yaw as above. The real length L and width W follow
    from the x / y extents (ex = L|cos| + W|sin|, ey = L|sin| + W|cos|); h stays the z extent (a tilted
    box's enclosing height). Where that 2x2 system is ill-conditioned (|cos 2 yaw| < 0.25, yaw near 45
    degrees) only L + W is known: it is split in the class prior's ratio.
  Boxes are then normalised to l >= w (no heading is known: the converter's yaw points along the length
  edge either way; yaw in [-pi, pi)).
* sensor: the `pandar64` preset (Hesai's nominal channel elevations, 0.167 deg apart near the horizon; 1800
  columns at 10 Hz): with it the projection keeps 86 % of the training frames' points in a pixel of their own,
  with `hdl64`'s table 60 %, and the ground stage finds samples in every sector.
* 000000.txt names classes TYPE_VEHICLE / TYPE_PEDESTRIAN / TYPE_CYCLIST (Waymo style) and has a 10th
  column: the number of points inside the box as written (it matches the count on 000000.bin exactly for all
  218 lines), so the boxes belong to this scan and the file is usable. Its boxes follow the corner format.
  TYPE_VEHICLE covers every vehicle: a box longer than 6 m or taller than 2.3 m -> 'Van' (ignored), else Car.
* classes: Car -> Car; Pedestrian, Pedestrian_with_Object, TYPE_PEDESTRIAN -> Pedestrian; Bicycle,
  TYPE_CYCLIST -> Cyclist when ridden, else 'Other' (PandaSet boxes a bicycle with its rider as one cuboid:
  ridden ones are 1.6-2.0 m tall with the rider's points above 1.2 m, parked ones 1.0-1.35 m; rule:
  h >= 1.5 m and not (>= 20 points inside and none above 1.2 m)); Pickup_Truck, trucks, Bus, Tram,
  Other_Vehicle_*, Towed_Object, Emergency_Vehicle -> 'Van'; Motorcycle, Motorized_Scooter,
  Personal_Mobility_Device, animals and unknown classes -> 'Other'; static clutter (Cones, Pylons, Signs,
  Construction_Signs, Road_Barriers, Temporary_Construction_Barriers, Rolling_Containers) is dropped (not a
  road user: a detection there is a false positive).
* labels cover 360 degrees: fov None. Many boxes lie far beyond the points (up to 200 m) or behind walls.
"""
from __future__ import annotations

import math
import pathlib

import numpy as np

from ..kitti import Box3D, read_bin
from . import RealFrame, finite_points, need_file, stems
from .fit import CLASS_PRIORS, estimate_ground_z, normalize_lw, points_in_box

SOURCE = "pandaset"
SUBDIR = "pandaset"
MOUNT_HEIGHT_M = 2.05

_VAN = {"Pickup_Truck", "Medium-sized_Truck", "Semi-truck", "Bus", "Tram_/_Subway", "Towed_Object",
        "Emergency_Vehicle", "Other_Vehicle_-_Construction_Vehicle", "Other_Vehicle_-_Uncommon",
        "Other_Vehicle_-_Pedicab"}
_DROP = {"Cones", "Pylons", "Signs", "Construction_Signs", "Road_Barriers", "Temporary_Construction_Barriers",
         "Rolling_Containers"}
_PED = {"Pedestrian", "Pedestrian_with_Object", "TYPE_PEDESTRIAN"}
_BIKE = {"Bicycle", "TYPE_CYCLIST"}
#: a bicycle box at least this tall includes its rider
RIDDEN_MIN_H_M = 1.5
RIDER_Z_M = 1.2
#: |cos 2 yaw| below this: extents do not separate length and width
EXTENT_MIN_DET = 0.25


#: the lidet preset of the Hesai Pandar64: its own beam table (the hdl64 one, used before, kept 60 % of the training
#: frames' points in their own pixel, this one 86 %; docs/SENSORS.md)
SENSOR = "pandar64"


def list_frames(root: pathlib.Path) -> list[str]:
    base = root / SUBDIR
    return sorted(stems(base, ".bin") & stems(base, ".txt"))


def _mm_exact(v: float) -> bool:
    return abs(v * 1000.0 - round(v * 1000.0)) < 1e-6


def unbias_width(w_biased: float, h: float) -> float:
    """Invert the converter's width w' = (3 w + sqrt(w^2 + h^2)) / 4 (w <= 4 w' / 3): w = (3 w' - sqrt(w'^2 +
    h^2 / 2)) / 2. Returns w_biased unchanged when there is no positive solution (w' <= h / 4)."""
    w = (3.0 * w_biased - math.sqrt(w_biased * w_biased + h * h / 2.0)) / 2.0
    return w if w > 0 else w_biased


def choose_by_points(xyz: np.ndarray, a: Box3D, b: Box3D, margin_m: float = 0.3) -> tuple[Box3D, int, int]:
    """(the candidate holding more points, points in a, points in b) of two candidate boxes of one object,
    counting points above the box bottom + 0.1 m (no road) within the union of both footprints enlarged by
    margin_m. Ties keep a."""
    zb = a.z - a.h / 2 + 0.1
    sel = xyz[xyz[:, 2] >= zb]
    na, nb = int(points_in_box(sel, a).sum()), int(points_in_box(sel, b).sum())
    return (b if nb > na else a), na, nb


def decode_box(cls: str, v: list[float], fmt: str, xyz: np.ndarray) -> tuple[Box3D, str]:
    """Sensor-frame box of one line's (x, y, z, l, w, h, yaw) in format 'corner' or 'extent' (see the module
    docstring), with how it was decided: 'digits' (corner format, the exact size is the length), 'points' (corner
    format, the digits do not tell), 'extents' (extent format, solved), 'prior' (extent format near 45 degrees:
    L + W split in the class prior's ratio). xyz: the scan's points in the file's frame."""
    x, y, z, l, w, h, yaw = v
    if fmt == "corner":
        le, we = _mm_exact(l), _mm_exact(w)
        a = Box3D(cls, x, y, z, l, unbias_width(w, h), h, yaw)              # not swapped: l is the length
        b = Box3D(cls, x, y, z, w, unbias_width(l, h), h, yaw)              # swapped: w is the length
        if le != we:
            return (a if le else b), "digits"
        if l <= w:          # cannot be swapped (the converter swapped only when w' > length)
            return a, "digits"
        best, _, _ = choose_by_points(xyz, a, b)
        return best, "points"
    c, s = abs(math.cos(yaw)), abs(math.sin(yaw))
    det = c * c - s * s
    if abs(det) >= EXTENT_MIN_DET:
        L = (c * l - s * w) / det
        W = (c * w - s * l) / det
        if L > 0 and W > 0:
            return Box3D(cls, x, y, z, L, W, h, yaw), "extents"
    # near 45 degrees the extents give only L + W = (ex + ey) / (|cos| + |sin|): split it in the class
    # prior's ratio (yaw still runs along the length edge)
    pl, pw, _ = CLASS_PRIORS.get(cls, CLASS_PRIORS["Other"])
    tot = (l + w) / max(c + s, 1e-9)
    return Box3D(cls, x, y, z, tot * pl / (pl + pw), tot * pw / (pl + pw), h, yaw), "prior"


def _map_class(name: str, b: Box3D, xyz: np.ndarray) -> str | None:
    """RealFrame class of a decoded box; None: drop the box."""
    if name in _DROP:
        return None
    if name in ("Car",):
        return "Car"
    if name == "TYPE_VEHICLE":
        return "Van" if (max(b.l, b.w) > 6.0 or b.h > 2.3) else "Car"
    if name in _PED:
        return "Pedestrian"
    if name in _BIKE:
        inside = xyz[points_in_box(xyz, b)]
        rider = int((inside[:, 2] > b.z - b.h / 2 + RIDER_Z_M).sum())
        ridden = b.h >= RIDDEN_MIN_H_M and not (len(inside) >= 20 and rider == 0)
        return "Cyclist" if ridden else "Other"
    if name in _VAN:
        return "Van"
    return "Other"


def read_labels(path, xyz: np.ndarray) -> tuple[list[Box3D], list[str], str]:
    """(boxes in the file's frame, how each orientation was decided, the file's format 'corner' | 'extent')."""
    p = need_file(path)
    rows = []
    for ln, line in enumerate(p.read_text().splitlines(), 1):
        t = line.split()
        if not t:
            continue
        if len(t) not in (9, 10):
            raise ValueError(f"{p}:{ln}: expected 'class 0 x y z l w h yaw [points]' (9 or 10 fields), "
                             f"got {len(t)}")
        try:
            v = [float(s) for s in t[2:9]]
        except ValueError:
            raise ValueError(f"{p}:{ln}: non-numeric field") from None
        if not all(math.isfinite(a) for a in v):
            raise ValueError(f"{p}:{ln}: non-finite field (nan or inf)")
        if min(v[3:6]) <= 0:
            raise ValueError(f"{p}:{ln}: box size must be > 0, got l w h {v[3]} {v[4]} {v[5]}")
        rows.append((t[0], v))
    # the corner format has an exact (whole-millimetre) height on every line
    fmt = "corner" if rows and all(_mm_exact(v[5]) for _, v in rows) else "extent"
    boxes, how = [], []
    for name, v in rows:
        b, h = decode_box(name, v, fmt, xyz)
        cls = _map_class(name, b, xyz)
        if cls is None:
            continue
        b.cls = cls
        boxes.append(normalize_lw(b))
        how.append(h)
    return boxes, how, fmt


def load_frame(root: pathlib.Path, frame_id: str) -> RealFrame:
    base = root / SUBDIR
    vel = need_file(base / f"{frame_id}.bin")
    points, _ = finite_points(read_bin(vel), vel)
    boxes, _, _ = read_labels(base / f"{frame_id}.txt", points)
    gz = estimate_ground_z(points)
    if not math.isfinite(gz):
        raise ValueError(f"{vel}: no road points within 3-20 m to place the sensor height")
    dz = -(gz + MOUNT_HEIGHT_M)
    points[:, 2] += np.float32(dz)
    for b in boxes:
        b.z += dz
    return RealFrame(SOURCE, frame_id, points, boxes, None, SENSOR, MOUNT_HEIGHT_M)
