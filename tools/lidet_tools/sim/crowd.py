# SPDX-License-Identifier: MIT
"""Crowded street content (issue 15), added to a scene by `make_scene(..., crowd=True)` /
`lidet-sim --crowd` after the default content (which it leaves as it is):

- groups of 2-6 people, each 0.2-1.0 m (body to body) from another member: walking together side by
  side, waiting at a crossing, standing and talking; a third of the members after the first are
  children;
- people standing 0.15-0.6 m beside a parked car's flank, a pole, a bin or bench, a fence or a
  building's wall;
- cyclists passing 0.3-1.0 m beside a parked car;
- pedestrians pushing a bicycle (the bicycle 0.1-0.3 m beside them, class bicycle with an instance).

`behind_cars` (`make_scene(..., behind_cars=RATE)`, `lidet-sim --behind-cars RATE`, the hdl64 family's training
scans) adds, on its own or on top of either content, people standing on the pavement just behind the parked cars,
alone or two to four side by side: the view of a street lined with parked cars, where a sensor on the road sees
them from the waist or the chest up (real validation pedestrians are seen from 0.8-1.2 m above their feet,
docs/journal/real-streets.md).

Everything within about 40 m of the sensor, where the proposal goals are set. Placement collides
bodies, not annotation boxes (objects.body_cylinders), so the boxes of close people may overlap and a
point inside one box may belong to its neighbour (the default scenes keep that invariant; these do
not). Cars of crowd scenes are `objects.worn`.
"""
from __future__ import annotations

import numpy as np

from . import objects as ob

BODY_R = 0.25     # body radius of an adult used to space group members (m)
NEAR_M = 40.0     # crowd content goes within this horizontal range


def _near(x, y):
    return np.hypot(x, y) < NEAR_M


def _sidewalk_point(b, r):
    """A random (u, v) on a sidewalk (or a crossing) within NEAR_M, in road coordinates."""
    s = int(r.choice([1, -1]))
    d = b.side[s]
    if b.u_x is not None and r.random() < 0.35:
        return b.u_x + b.Wx / 2 + 2.0 + r.normal(0, 0.5), r.uniform(-b.Wr, b.Wr)
    return r.uniform(-35, 35), s * r.uniform(d["v_curb"] + 0.4, max(d["v_curb"] + 0.5, d["v_walk_out"] - 0.3))


def _box_point(cx, cy, yaw, lx, ly):
    """Level-frame (x, y) of the point (lx, ly) in the frame of a box centred at (cx, cy) turned by yaw."""
    c, s = np.cos(yaw), np.sin(yaw)
    return cx + c * lx - s * ly, cy + s * lx + c * ly


def _group(b, r):
    u, v = _sidewalk_point(b, r)
    x0, y0 = b.to_level(u, v)
    if not _near(x0, y0):
        return
    n = int(r.integers(2, 7))
    mode = str(r.choice(["walk", "wait", "talk"]))
    yaw0 = float(r.uniform(-np.pi, np.pi))
    pos = []
    for k in range(n):
        child = k > 0 and r.random() < 0.33
        walking = mode == "walk"
        sh = ob.pedestrian(r, child=child, walking=walking)
        yaw = yaw0 + r.normal(0, 0.15) if mode != "talk" else float(r.uniform(-np.pi, np.pi))
        for _ in range(6):
            if k == 0:
                x, y = x0, y0
            else:
                px, py = pos[int(r.integers(0, len(pos)))]
                gap = r.uniform(0.2, 1.0)
                # walking groups go side by side (across the heading), others all around
                a = yaw0 + np.pi / 2 * r.choice([1, -1]) + r.normal(0, 0.3) if walking else r.uniform(-np.pi, np.pi)
                dist = 2 * BODY_R + gap
                x, y = px + dist * np.cos(a), py + dist * np.sin(a)
            if b.put_level(sh, x, y, yaw, margin=0.0, body=True) is not None:
                pos.append((x, y))
                break
        if not pos:
            return


def _anchors(b):
    """Objects a person may stand beside: parked or any cars, poles, clutter, fences and walls (index, box)."""
    out = []
    for i, o in enumerate(b.objects):
        cx, cy = o.box[0], o.box[1]
        if not _near(cx, cy):
            continue
        if o.label == "Car" or o.sem in (80, 99, 51) or (o.sem == 50 and o.box[3] < 40):
            out.append((i, o.box))
    return out


def _beside(b, r, anchors):
    if not anchors:
        return
    i, (cx, cy, cz, l, w, h, yaw) = anchors[int(r.integers(0, len(anchors)))]
    gap = r.uniform(0.15, 0.6)
    sh = ob.pedestrian(r, child=r.random() < 0.15)
    # a point outside one face of the anchor's box: along its side, `gap` off the face
    if r.random() < 0.75 or l < 0.6:
        lx, ly = r.uniform(-0.45, 0.45) * l, (w / 2 + gap + BODY_R) * r.choice([1, -1])
    else:
        lx, ly = (l / 2 + gap + BODY_R) * r.choice([1, -1]), r.uniform(-0.4, 0.4) * w
    x, y = _box_point(cx, cy, yaw, lx, ly)
    b.put_level(sh, x, y, float(r.uniform(-np.pi, np.pi)), margin=0.0, body=True, ignore=i)


def _cyclist_by_car(b, r, anchors):
    cars = [(i, bx) for i, bx in anchors if b.objects[i].label == "Car"]
    if not cars:
        return
    i, (cx, cy, cz, l, w, h, yaw) = cars[int(r.integers(0, len(cars)))]
    sh = ob.cyclist(r)
    gap = r.uniform(0.3, 1.0)
    side = r.choice([1, -1])
    lx, ly = r.uniform(-0.5, 0.5) * l, side * (w / 2 + gap + 0.3)
    x, y = _box_point(cx, cy, yaw, lx, ly)
    b.put_level(sh, x, y, yaw + (np.pi if r.random() < 0.5 else 0.0) + r.normal(0, 0.05), margin=0.0, body=True,
                ignore=i)


def _pusher(b, r):
    u, v = _sidewalk_point(b, r)
    x, y = b.to_level(u, v)
    if not _near(x, y):
        return
    yaw = float(r.uniform(-np.pi, np.pi))
    if b.put_level(ob.pedestrian(r, walking=True), x, y, yaw, margin=0.0, body=True) is None:
        return
    side = r.choice([1, -1])
    off = BODY_R + r.uniform(0.1, 0.3) + 0.05
    bx, by = x - side * off * np.sin(yaw), y + side * off * np.cos(yaw)
    b.put_level(ob.parked_bicycle(r), bx + 0.35 * np.cos(yaw), by + 0.35 * np.sin(yaw), yaw, margin=0.0, body=True)


def crowds(b) -> None:
    """Add the crowd content to a SceneBuilder `b` (after its default content, before the pits)."""
    r = b.rng
    for _ in range(int(r.poisson(3.0))):
        _group(b, r)
    anchors = _anchors(b)
    for _ in range(int(r.poisson(4.0))):
        _beside(b, r, anchors)
    for _ in range(int(r.poisson(1.5))):
        _cyclist_by_car(b, r, anchors)
    for _ in range(int(r.poisson(1.0))):
        _pusher(b, r)


def _behind_car(b, r, cars):
    """One person or a row of 2-4 standing 0.1-0.9 m behind a parked car's far flank (the side away from the sensor's
    road), along the car."""
    i, (cx, cy, cz, l, w, h, yaw) = cars[int(r.integers(0, len(cars)))]
    c, s = np.cos(yaw), np.sin(yaw)
    # the car's flank farther from the sensor: its local +y or -y, whichever points away from the origin
    far = 1.0 if (-s * cx + c * cy) >= 0.0 else -1.0
    n = 1 if r.random() < 0.6 else int(r.integers(2, 5))
    gap = r.uniform(0.1, 0.9)
    walking = bool(r.random() < 0.4)
    yaw_p = yaw + (np.pi if r.random() < 0.5 else 0.0) + r.normal(0, 0.2) if walking else float(r.uniform(-np.pi, np.pi))
    lx0 = r.uniform(-0.45, 0.45) * l
    for k in range(n):
        lx = lx0 + (k - (n - 1) / 2.0) * (2 * BODY_R + r.uniform(0.1, 0.5))
        ly = far * (w / 2 + gap + BODY_R + r.normal(0, 0.1))
        x, y = _box_point(cx, cy, yaw, lx, ly)
        if not _near(x, y):
            continue
        sh = ob.pedestrian(r, child=k > 0 and r.random() < 0.2, walking=walking)
        b.put_level(sh, x, y, yaw_p + r.normal(0, 0.1), margin=0.0, body=True, ignore=i)


def behind_cars(b, rate: float) -> None:
    """Add Poisson(rate) people or rows of people behind parked vehicles within NEAR_M to a SceneBuilder `b` (the
    parked rows and lots; none when the scene has no parked vehicle)."""
    r = b.rng
    cars = [(i, o.box) for i, o in enumerate(b.objects) if o.label in ("Car", "Van", "Truck")
            and _near(o.box[0], o.box[1]) and i in b.parked]
    if not cars:
        return
    for _ in range(int(r.poisson(rate))):
        _behind_car(b, r, cars)
