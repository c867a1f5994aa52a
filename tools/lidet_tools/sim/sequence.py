# SPDX-License-Identifier: MIT
"""Simulated sequences (issue 38): one street scene whose road users move between scans, ids kept.

    lidet-sim --sequence 50 --sensor hdl64 --scenes 4 --seed 0 --out data/sim/seq_hdl64 [--ego-speed 8]

A sequence builds its scene once (scene.SceneBuilder, the single scans' streets), gives its road users a motion,
and for each scan moves them (and the sensor) and ray casts with simulate.cast_scene, the single scans' caster:

* **cars** of the driving lanes follow their lane at the lane's speed (5-14 m/s, changing by up to +-3 m/s over
  the sequence; one lane in ten stands), the parked ones stay; vans, trucks and buses alike;
* **cyclists** ride along the road at 3-6.5 m/s (15 % wait);
* **pedestrians** on a sidewalk walk along it at 0.9-1.6 m/s (share `walk` of the groups; a group, the people
  within 1.5 m of each other, walks together at one speed), a share `cross` of the walking ones alone cross the
  road to the far sidewalk instead, the ones placed on the road (crossings) walk across, the rest stand;
* the **sensor** stands (the default) or drives along its lane (a robot: its sidewalk) at `ego_speed` m/s with a
  gentle weave whose peak yaw rate is `ego_yaw_rate` rad/s; the scene is centred on its path.

Every motion is a straight line at a speed that may change smoothly (constant acceleration, braking). Motions
are checked against each other and the sensor at twice the scan rate (footprints: the labelled boxes grown by
0.1 m, the street furniture's collision cylinders): a road user whose way is blocked brakes (4 / 3 / 2 m/s^2 for
vehicles / cyclists / people) to stop short of the obstacle, else stands; anything that stands in the sensor's
way is left out of the scene. Per scan, the ground under each moving road user is lowered a few cm as for the
single scans' parked ones (scene.SceneBuilder.dig_pits). The sensor is level (its mount pitch and roll are
those of the whole sequence); a scan is instantaneous (no motion distortion within a sweep).

Output, per sequence `OUT/<seq:04d>/` (frames `%06d`):

    velodyne/, ring/, labels/, boxes/   as the single scans (writer.py), in the scan's sensor frame
    tracks/<frame>.txt   `id class x y z l w h yaw vx vy npts`: every labelled road user within the sensor's
                         range (also those without points), sensor frame, velocity over the ground in the scan's
                         sensor axes (m/s), npts its points in this scan; id = its instance id (labels/)
    label_02/<seq>.txt   KITTI tracking labels (camera frame, kitti.write_label02), calib/<seq>.txt its calib
    poses.txt            `frame t x y yaw dx dy dyaw`: the sensor's pose in the first scan's (level) frame and
                         the ego motion from the previous scan in the previous scan's frame (docs/TRACKING.md)
    meta.json            sensor, rate, dt, seed, index, options, mount, scene kind, counts

Deterministic: sequence `index` of run `seed` draws everything from SeedSequence([seed, index, 1]) (scene,
mount, motion, and one noise stream per scan), so (seed, index, options) fixes the bytes.
"""
from __future__ import annotations

import dataclasses
import json
import os
import sys
import time
import types
from dataclasses import dataclass, field

import numpy as np

from .. import kitti
from ..sensors import get_sensor
from . import writer
from .raycast import HeightField, Primitives
from .scene import Scene, SceneBuilder
from .sensor_model import SensorModel
from .simulate import _robot, _to_sensor_box, cast_scene

#: scan rates per sensor profile (Hz); the first is the default. Others: 10 Hz.
SCAN_RATES = {"hdl64": (10.0,), "vlp16": (10.0, 20.0), "vlp32c": (10.0, 20.0), "hdl32": (20.0,)}
VEHICLES = ("Car", "Van", "Truck", "Misc")
_SEQ_TAG = 1                 # SeedSequence([seed, index, _SEQ_TAG]): never the single scans' streams
_BOX_MARGIN = 0.1            # m added on every side of a labelled box for the motion collision checks
_BRAKE = {"vehicle": 4.0, "cyclist": 3.0, "person": 2.0}    # m/s^2
_GROUP_GAP = 1.5             # pedestrians closer than this (centres, m) form a group
_OVERHANG_M = 1.5            # street furniture starting above this height (canopies, lamp arms) blocks no one


def scan_rates(sensor_name: str) -> tuple:
    return SCAN_RATES.get(sensor_name, (10.0,))


@dataclass(frozen=True)
class SeqOptions:
    frames: int = 50
    rate_hz: float | None = None          # None: the profile's first rate (SCAN_RATES)
    ego_speed: float = 0.0                # m/s along the road
    ego_yaw_rate: float = 0.05            # rad/s, peak of the weave
    mount_height_m: float | None = None
    pitch_deg: float | None = None
    roll_deg: float | None = None
    scene_kind: str | None = None
    crowd: bool = False
    behind_cars: float = 0.0
    range_noise_m: float = 0.02
    dropout: float = 0.015
    walk: float = 0.65                    # share of sidewalk groups that walk
    cross: float = 0.2                    # share of walking lone pedestrians that cross the road


# ------------------------------------------------------------------------------------------------
# motion along a straight line


class Profile:
    """Distance along a path over time: segments (t0, s0, v0, a) of constant acceleration, speed clamped at 0."""

    def __init__(self, segs):
        self.segs = [tuple(float(x) for x in s) for s in segs]

    @classmethod
    def constant(cls, v0: float, a: float = 0.0) -> "Profile":
        return cls([(0.0, 0.0, v0, a)])

    def at(self, t):
        """(s, v) at times t (array)."""
        t = np.asarray(t, dtype=np.float64)
        s = np.zeros_like(t)
        v = np.zeros_like(t)
        for i, (t0, s0, v0, a) in enumerate(self.segs):
            t1 = self.segs[i + 1][0] if i + 1 < len(self.segs) else np.inf
            m = (t >= t0) & (t < t1) if i else (t < t1)
            dt = np.maximum(t[m] - t0, 0.0)
            t_stop = v0 / -a if a < 0 else np.inf
            de = np.minimum(dt, t_stop)
            s[m] = s0 + v0 * de + 0.5 * a * de * de
            v[m] = np.maximum(v0 + a * de, 0.0)
        return s, v

    def moving(self, t_end: float) -> bool:
        ts = np.linspace(0.0, t_end, 64)
        return bool(self.at(ts)[1].max() > 1e-6)

    def brake_to(self, s_lim: float, b: float, t_end: float, step: float = 0.01):
        """The profile braking at b m/s^2 from the latest time it can still stop at or before s_lim; None when
        even braking at once does not."""
        ts = np.arange(0.0, t_end + step, step)
        s, v = self.at(ts)
        ok = s + v * v / (2.0 * b) <= s_lim + 1e-9
        if not ok[0]:
            return None
        bad = np.nonzero(~ok)[0]
        if bad.size == 0:
            return self
        k = int(bad[0]) - 1
        tb, sb, vb = float(ts[k]), float(s[k]), float(v[k])
        segs = [sg for sg in self.segs if sg[0] < tb] + [(tb, sb, vb, -b if vb > 0 else 0.0)]
        return Profile(segs)


@dataclass
class Motion:
    """One moving unit: a road user or a group walking together."""
    objs: list                     # object indices
    kind: str                      # vehicle | cyclist | person
    d: np.ndarray                  # (2,) unit direction (scene frame)
    prof: Profile
    yaw: dict = field(default_factory=dict)   # object index -> new yaw (scene frame); absent: as placed


# ------------------------------------------------------------------------------------------------
# the scene builder of a sequence


class _SeqBuilder(SceneBuilder):
    """SceneBuilder whose pits are dug later (per scan for the moving road users) and whose sensor, when it
    drives on the road, sits on a forward lane's centre line."""

    def __init__(self, *a, ego_moves=False, **k):
        super().__init__(*a, **k)
        self.ego_moves = ego_moves

    def layout(self):
        super().layout()
        if self.ego_moves and abs(self.v_s) < self.Wr:
            vc = -self.Wr + (np.arange(self.n_lanes) + 0.5) * self.lane_w
            fwd = vc[vc < 0]
            if fwd.size:
                self.v_s = float(fwd[np.argmin(np.abs(fwd - self.v_s))])

    def dig_pits(self):
        pass


def _rot2(a):
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, -s], [s, c]])


def _rot3(a):
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def _wrap(a):
    return (np.asarray(a) + np.pi) % (2.0 * np.pi) - np.pi


# ------------------------------------------------------------------------------------------------
# footprints and collisions


def _obb_overlap(c1, h1, y1, c2, h2, y2):
    """Oriented rectangles overlap (separating axes): centres (..., 2), half sizes (..., 2), yaws (...)."""
    c1, c2 = np.asarray(c1, float), np.asarray(c2, float)
    h1, h2 = np.asarray(h1, float), np.asarray(h2, float)
    y1, y2 = np.asarray(y1, float), np.asarray(y2, float)
    u1 = np.stack([np.cos(y1), np.sin(y1)], -1)
    v1 = np.stack([-np.sin(y1), np.cos(y1)], -1)
    u2 = np.stack([np.cos(y2), np.sin(y2)], -1)
    v2 = np.stack([-np.sin(y2), np.cos(y2)], -1)
    d = c2 - c1
    sep = np.zeros(np.broadcast_shapes(d.shape[:-1], u1.shape[:-1], u2.shape[:-1]), bool)
    for ax in (u1, v1, u2, v2):
        r1 = h1[..., 0] * np.abs((ax * u1).sum(-1)) + h1[..., 1] * np.abs((ax * v1).sum(-1))
        r2 = h2[..., 0] * np.abs((ax * u2).sum(-1)) + h2[..., 1] * np.abs((ax * v2).sum(-1))
        sep |= np.abs((ax * d).sum(-1)) > r1 + r2
    return ~sep


def _obb_circle(c, h, yaw, p, r):
    """Oriented rectangle (centre c (..., 2), half sizes h (..., 2), yaw (...)) meets circle (p (..., 2), r)."""
    c, p = np.asarray(c, float), np.asarray(p, float)
    h = np.asarray(h, float)
    yaw = np.asarray(yaw, float)
    d = p - c
    cs, sn = np.cos(yaw), np.sin(yaw)
    lx = cs * d[..., 0] + sn * d[..., 1]
    ly = -sn * d[..., 0] + cs * d[..., 1]
    qx = lx - np.clip(lx, -h[..., 0], h[..., 0])
    qy = ly - np.clip(ly, -h[..., 1], h[..., 1])
    return qx * qx + qy * qy <= np.asarray(r, float) ** 2


@dataclass
class _Ego:
    xy: np.ndarray      # (T, 2) sensor position at the check times (scene frame)
    yaw: np.ndarray     # (T,)
    half: np.ndarray    # footprint half sizes
    off: float          # footprint centre ahead of the sensor (m)
    zr: tuple           # height range of the body above the ground

    def centres(self):
        return self.xy + self.off * np.stack([np.cos(self.yaw), np.sin(self.yaw)], 1)


class _World:
    """The road users' footprints over the check times, the street furniture's cylinders, and the greedy
    assignment of motions (each checked against the sensor and everything decided before it, and against the
    standing poses of everything not yet decided)."""

    def __init__(self, b: _SeqBuilder, ts: np.ndarray, ego: _Ego):
        self.b = b
        self.ts = ts
        self.ego = ego
        objs = b.objects
        n = len(objs)
        self.n = n
        self.lab = np.array([bool(o.label) for o in objs], bool)
        self.box = np.array([o.box for o in objs], float).reshape(n, 7)
        self.half = self.box[:, 3:5] / 2 + _BOX_MARGIN
        own = b.placer.own
        keep = (own >= 0)
        keep[keep] &= ~self.lab[own[keep]]
        self.cyl = b.placer.c[keep]              # stuff: x, y, r, z_lo, z_hi
        self.cyl_own = own[keep]
        # decided trajectories: object -> (xy (T, 2), yaw)
        self.traj: dict = {}
        self.motion_of: dict = {}              # object -> its decided Motion (moving ones)
        self.removed = np.zeros(n, bool)

    def static_xy(self, i):
        return np.broadcast_to(self.box[i, :2], (len(self.ts), 2))

    def _ego_hits_box(self, xy, yaw, half, zr):
        e = self.ego
        if not (zr[0] < e.zr[1] and zr[1] > e.zr[0]):
            return np.zeros(len(self.ts), bool)
        return _obb_overlap(e.centres(), e.half, e.yaw, xy, half, yaw)

    def ego_blocked(self):
        """Objects whose standing pose meets the sensor's footprint at some time."""
        e = self.ego
        out = np.zeros(self.n, bool)
        ec = e.centres()
        lo, hi = ec.min(0) - np.hypot(*e.half) - 0.5, ec.max(0) + np.hypot(*e.half) + 0.5
        for i in np.nonzero(self.lab)[0]:
            c = self.box[i, :2]
            rr = np.hypot(*self.half[i])
            if (c + rr < lo).any() or (c - rr > hi).any():
                continue
            out[i] = self._ego_hits_box(self.static_xy(i), self.box[i, 6], self.half[i],
                                        (-0.3, self.box[i, 5] + 0.3)).any()
        if len(self.cyl):
            c = self.cyl
            cz = (c[:, 3] < min(e.zr[1], _OVERHANG_M)) & (c[:, 4] > e.zr[0])
            near = cz & (c[:, :2] + c[:, 2:3] >= lo).all(1) & (c[:, :2] - c[:, 2:3] <= hi).all(1)
            for k in np.nonzero(near)[0]:
                if _obb_circle(ec, e.half, e.yaw, self.cyl[k, :2], self.cyl[k, 2]).any():
                    out[self.cyl_own[k]] = True
        return out

    def first_hit(self, members, xys, yaws, pending):
        """First check-time index at which any member (positions xys[m] (T, 2), yaw yaws[m]) meets the sensor,
        a decided road user, a pending one (standing), or street furniture below _OVERHANG_M (canopies, lamp
        arms and signs overhang); None when free. Also returns the objects met then (-1: the sensor, -2:
        furniture)."""
        T = len(self.ts)
        first = {}
        mem = set(members)

        def note(key, h):
            idx = np.nonzero(h)[0]
            if idx.size and (key not in first or idx[0] < first[key]):
                first[key] = int(idx[0])
        others = [j for j in np.nonzero(self.lab & ~self.removed)[0] if j not in mem]
        for m in members:
            xy, yaw, half = xys[m], yaws[m], self.half[m]
            zr = (-0.3, self.box[m, 5] + 0.3)
            rr = float(np.hypot(*half))
            lo, hi = xy.min(0) - rr, xy.max(0) + rr
            note(-1, self._ego_hits_box(xy, yaw, half, zr))
            for j in others:
                if j in self.traj:
                    oxy, oyaw = self.traj[j]
                elif pending[j]:
                    oxy, oyaw = self.static_xy(j), self.box[j, 6]
                else:
                    continue
                orr = float(np.hypot(*self.half[j]))
                if (oxy.max(0) + orr < lo).any() or (oxy.min(0) - orr > hi).any():
                    continue
                note(int(j), _obb_overlap(xy, half, yaw, oxy, self.half[j], oyaw))
            if len(self.cyl):
                c = self.cyl
                ok = ~self.removed[self.cyl_own] & (c[:, 3] < min(zr[1], _OVERHANG_M)) & (c[:, 4] > zr[0])
                ok &= (c[:, :2] + c[:, 2:3] >= lo).all(1) & (c[:, :2] - c[:, 2:3] <= hi).all(1)
                if ok.any():
                    cc = c[ok]
                    note(-2, _obb_circle(xy[:, None, :], half, yaw, cc[None, :, :2], cc[None, :, 2]).any(1))
        if not first:
            return None, []
        k = min(first.values())
        return k, sorted(j for j, v in first.items() if v == k)

    def _try(self, mo: Motion, pending):
        s, _v = mo.prof.at(self.ts)
        xys = {m: self.box[m, :2] + s[:, None] * mo.d[None, :] for m in mo.objs}
        yaws = {m: mo.yaw.get(m, self.box[m, 6]) for m in mo.objs}
        k, who = self.first_hit(mo.objs, xys, yaws, pending)
        return k, who, s, xys, yaws

    def place(self, mo: Motion, pending, t_end):
        """Decide a motion. Tried in turn: as proposed; following a road user met going the same way (its
        speed profile, so the gap stays); for people, turned up to 0.16 rad (stepping around a pole); braking
        short of the first obstacle (three tries; one too fast to stop in time starts the sequence braking, at
        the speed that stops it there). Returns the final Motion, or None: it stands."""
        tries = [mo]
        if mo.kind == "person":
            for da in (0.08, -0.08, 0.16, -0.16):
                R = _rot2(da)
                tries.append(dataclasses.replace(mo, d=R @ mo.d, yaw={m: y + da for m, y in mo.yaw.items()}))
        first = None
        for cand in tries:
            k, who, s, xys, yaws = self._try(cand, pending)
            if k is not None and k > 0:
                # a road user going the same way: follow it
                lead = [self.motion_of[j] for j in who if j >= 0 and j in self.motion_of]
                lead = [ld for ld in lead if float(ld.d @ cand.d) > 0.95]
                if lead:
                    fol = dataclasses.replace(cand, prof=lead[0].prof)
                    k2, who2, s2, xys2, yaws2 = self._try(fol, pending)
                    if k2 is None:
                        cand, k, xys, yaws = fol, None, xys2, yaws2
            if k is None:
                return self._accept(cand, xys, yaws)
            if first is None:
                first = (cand, k, s)
        cand, k, s = first
        prof = cand.prof
        for _ in range(3):
            if k == 0:
                return None
            # stop short of where it was at the last free check time, less a little room
            s_lim = float(s[k - 1]) - (1.0 if mo.kind == "vehicle" else 0.3)
            if s_lim <= 0.0:
                return None
            bk = _BRAKE[mo.kind]
            p2 = prof.brake_to(s_lim, bk, t_end)
            if p2 is None:
                # too fast to stop in time: it was braking already, from the speed that stops it there
                v0 = min(float(prof.at(np.zeros(1))[1][0]), float(np.sqrt(2.0 * bk * s_lim)))
                p2 = Profile([(0.0, 0.0, v0, -bk)])
            prof = p2
            cand = dataclasses.replace(cand, prof=prof)
            k, who, s, xys, yaws = self._try(cand, pending)
            if k is None:
                return self._accept(cand, xys, yaws)
        return None

    def _accept(self, mo, xys, yaws):
        for m in mo.objs:
            self.traj[m] = (xys[m], yaws[m])
            self.motion_of[m] = mo
        return mo


# ------------------------------------------------------------------------------------------------


def _ego_path(b: _SeqBuilder, opts: SeqOptions, ts: np.ndarray, rng):
    """Sensor positions (T, 2) and headings (T,) in the scene frame at times ts."""
    v = float(opts.ego_speed)
    if v <= 0.0:
        return np.zeros((len(ts), 2)), np.zeros(len(ts))
    yr = float(opts.ego_yaw_rate)
    T = float(ts[-1]) if len(ts) else 0.0
    if yr > 0:
        om = max(2 * np.pi / 8.0, float(np.sqrt(yr * v / 0.8)))   # weave amplitude <= 0.8 m
        Y = yr / om
    else:
        om, Y = 1.0, 0.0
    ph = float(rng.uniform(0, 2 * np.pi))
    tf = np.arange(0.0, T + 0.0025, 0.0025)
    h = Y * np.sin(om * tf + ph)
    du, dv = v * np.cos(h), v * np.sin(h)
    u = np.concatenate([[0.0], np.cumsum((du[1:] + du[:-1]) / 2 * np.diff(tf))])
    w = np.concatenate([[0.0], np.cumsum((dv[1:] + dv[:-1]) / 2 * np.diff(tf))])
    u -= (u.min() + u.max()) / 2
    w -= (w.min() + w.max()) / 2
    uu, ww, hh = np.interp(ts, tf, u), np.interp(ts, tf, w), np.interp(ts, tf, h)
    x, y = b.to_level(uu, b.v_s + ww)
    return np.stack([x, y], 1), hh + b.psi


def _road_side(b, v):
    """Where a road coordinate v lies: 'road', 'walk' (sidewalk) or 'other', and its side (+1 / -1)."""
    s = 1 if v >= 0 else -1
    A = abs(v)
    d = b.side[s]
    if A < b.Wr:
        return "road", s
    if d["v_curb"] <= A < d["v_walk_out"]:
        return "walk", s
    return "other", s


def _propose(b: _SeqBuilder, opts: SeqOptions, rng, T: float, ego_lane_v):
    """Motions proposed for the labelled road users, in the order they are decided."""
    objs = b.objects
    along = np.array([np.cos(b.psi), np.sin(b.psi)])
    across = np.array([-np.sin(b.psi), np.cos(b.psi)])
    lanes: dict = {}
    cyc, cross, walk, other = [], [], [], []
    vc = -b.Wr + (np.arange(b.n_lanes) + 0.5) * b.lane_w
    for o in objs:
        if not o.label or o.label == "DontCare":
            continue
        u, v = b.to_road(o.box[0], o.box[1])
        where, s = _road_side(b, float(v))
        if o.label in VEHICLES:
            if o.obj in b.parked or where != "road":
                continue
            ln = int(np.argmin(np.abs(vc - v)))
            lanes.setdefault(ln, []).append((float(u), o.obj))
        elif o.label == "Cyclist":
            cyc.append(o.obj)
        elif o.label == "Pedestrian":
            in_x = b.u_x is not None and abs(u - b.u_x) < b.Wx / 2
            if where == "road" or in_x:
                cross.append(o.obj)
            elif where == "walk":
                walk.append(o.obj)
            else:
                other.append(o.obj)
    out_cross, out_along, out_other = [], [], []

    def along_key(mo):
        # leader first: the farthest along its way
        return -max(float((objs[i].box[:2] @ mo.d)) for i in mo.objs)
    for ln in sorted(lanes):
        fwd = vc[ln] < 0
        if ego_lane_v is not None and abs(vc[ln] - b.v_s) < b.lane_w / 2 and fwd:
            v0, a = ego_lane_v, 0.0
        elif rng.random() < 0.1:
            v0, a = 0.0, 0.0
        else:
            v0 = float(rng.uniform(5.0, 14.0))
            v1 = float(np.clip(v0 + rng.uniform(-3.0, 3.0), 0.0, 16.0))
            a = (v1 - v0) / max(T, 1e-6)
        d = along if fwd else -along
        cars = sorted(lanes[ln], key=lambda x: -x[0] if fwd else x[0])   # leader first
        for _, i in cars:
            if v0 > 0:
                out_along.append(Motion([i], "vehicle", d, Profile.constant(v0, a)))
    for i in cyc:
        go = rng.random() < 0.85
        v0 = float(rng.uniform(3.0, 6.5))
        v1 = float(np.clip(v0 + rng.uniform(-1.0, 1.0), 0.0, 8.0))
        sg = 1.0 if np.cos(objs[i].box[6] - b.psi) >= 0 else -1.0
        if go:
            out_along.append(Motion([i], "cyclist", sg * along, Profile.constant(v0, (v1 - v0) / max(T, 1e-6))))
    for i in cross:
        go = rng.random() < 0.9
        sp = float(rng.uniform(1.0, 1.6))
        _, v = b.to_road(objs[i].box[0], objs[i].box[1])
        sg = 1.0 if np.sin(objs[i].box[6] - b.psi) >= 0 else -1.0
        yaw = float(np.arctan2(sg * across[1], sg * across[0]) + rng.normal(0, 0.1))
        target = sg * (b.side[int(sg)]["v_curb"] + rng.uniform(0.6, 1.5))
        dist = (target - float(v)) * sg
        if go and dist > 0.5:
            prof = Profile.constant(sp).brake_to(dist, _BRAKE["person"], T)
            if prof is not None:
                out_cross.append(Motion([i], "person", sg * across, prof, {i: yaw}))
    # sidewalk groups: connected components of people closer than _GROUP_GAP
    walk = sorted(walk)
    left = set(walk)
    groups = []
    for i in walk:
        if i not in left:
            continue
        comp, stack = [], [i]
        left.discard(i)
        while stack:
            k = stack.pop()
            comp.append(k)
            for j in sorted(left):
                if np.hypot(*(objs[j].box[:2] - objs[k].box[:2])) < _GROUP_GAP:
                    left.discard(j)
                    stack.append(j)
        groups.append(sorted(comp))
    for g in groups:
        go = rng.random() < opts.walk
        sp = float(rng.uniform(0.9, 1.6))
        crosses = len(g) == 1 and rng.random() < opts.cross
        jit = rng.normal(0, 0.08, len(g))
        if not go:
            continue
        if crosses:
            i = g[0]
            _, v = b.to_road(objs[i].box[0], objs[i].box[1])
            sg = -1.0 if v >= 0 else 1.0
            target = sg * (b.side[int(sg)]["v_curb"] + rng.uniform(0.6, 1.5))
            dist = (target - float(v)) * sg
            d = sg * across
            prof = Profile.constant(sp).brake_to(dist, _BRAKE["person"], T)
            if prof is None:
                continue
        else:
            sg = 1.0 if np.cos(objs[g[0]].box[6] - b.psi) >= 0 else -1.0
            d = sg * along
            prof = Profile.constant(sp)
        head = float(np.arctan2(d[1], d[0]))
        mo = Motion(list(g), "person", d, prof, {m: head + float(j) for m, j in zip(g, jit)})
        (out_cross if crosses else out_along).append(mo)
    for i in other:
        go = rng.random() < 0.5
        sp = float(rng.uniform(0.8, 1.4))
        yaw = float(objs[i].box[6])
        if go:
            out_other.append(Motion([i], "person", np.array([np.cos(yaw), np.sin(yaw)]), Profile.constant(sp)))
    # people crossing first (the traffic yields to them), then everything going along the road, leader first
    # (a follower can take its leader's speed), then the rest
    keys = [along_key(mo) for mo in out_along]
    out_along = [out_along[i] for i in np.argsort(keys, kind="stable")]
    return out_cross + out_along + out_other


@dataclass
class SequencePlan:
    """A sequence's scene and motions, before ray casting."""
    builder: _SeqBuilder
    prims: Primitives           # the scene's primitives as built (scene frame)
    sm: SensorModel
    ts: np.ndarray              # frame times (s)
    ego_xy: np.ndarray          # (F, 2) sensor positions, scene frame
    ego_yaw: np.ndarray         # (F,)
    ego_z: np.ndarray           # (F,) sensor height in the scene frame
    motions: list               # decided Motions
    removed: np.ndarray         # (n_objects,) bool
    frame_rngs: list
    meta: dict


def plan_sequence(sensor, seed: int = 0, index: int = 0, opts: SeqOptions = SeqOptions()) -> SequencePlan:
    sensor = get_sensor(sensor) if isinstance(sensor, str) else sensor
    if opts.frames < 1:
        raise ValueError("frames must be >= 1")
    rate = float(opts.rate_hz if opts.rate_hz is not None else scan_rates(sensor.name)[0])
    if rate not in scan_rates(sensor.name):
        raise ValueError(f"{sensor.name}: scan rate {rate:g} Hz is not one of {scan_rates(sensor.name)}")
    dt = 1.0 / rate
    H = float(sensor.mount_height_m if opts.mount_height_m is None else opts.mount_height_m)
    root = np.random.SeedSequence([int(seed), int(index), _SEQ_TAG])
    scene_ss, mount_ss, motion_ss, noise_ss = root.spawn(4)
    scene_rng, mount_rng, motion_rng = (np.random.default_rng(s) for s in (scene_ss, mount_ss, motion_ss))
    pitch = np.radians(opts.pitch_deg) if opts.pitch_deg is not None else np.radians(
        np.clip(mount_rng.normal(0, 0.25), -0.6, 0.6))
    roll = np.radians(opts.roll_deg) if opts.roll_deg is not None else np.radians(
        np.clip(mount_rng.normal(0, 0.25), -0.6, 0.6))
    robot = _robot(H)
    b = _SeqBuilder(scene_rng, H, sensor.max_range_m, opts.scene_kind, robot, crowd=opts.crowd,
                    behind_cars=opts.behind_cars, ego_moves=opts.ego_speed > 0)
    scene0 = b.build()
    sm = SensorModel(sensor, H, float(pitch), float(roll), range_noise_m=opts.range_noise_m, dropout=opts.dropout,
                     min_range_m=0.3 if robot else 1.0)
    F = int(opts.frames)
    ts_check = np.arange(2 * (F - 1) + 1) * (dt / 2)
    ts = ts_check[::2]
    T = float(ts_check[-1])
    exy, eyaw = _ego_path(b, opts, ts_check, motion_rng)
    half = np.array([2.3, 0.95]) if not robot else np.array([0.35, 0.3])
    ego = _Ego(exy, eyaw, half, -0.6 if not robot else 0.0, (-0.3, 2.0 if not robot else H + 0.3))
    w = _World(b, ts_check, ego)
    blocked = w.ego_blocked()
    proposals = _propose(b, opts, motion_rng, T, opts.ego_speed if opts.ego_speed > 0 else None)
    cand = set(i for mo in proposals for i in mo.objs)
    # standing things in the sensor's way go; moving candidates may still drive off ahead of it
    w.removed = blocked & ~np.isin(np.arange(w.n), sorted(cand))
    pending = w.lab & ~w.removed & ~blocked     # what may yet stand where it is (a blocked one cannot)
    decided = []
    for mo in proposals:
        fin = w.place(mo, pending, T)
        for i in mo.objs:
            pending[i] = False
        if fin is not None and fin.prof.moving(T):
            decided.append(fin)
        else:
            for i in mo.objs:
                w.traj.pop(i, None)
                w.motion_of.pop(i, None)
                if blocked[i]:
                    w.removed[i] = True
                else:
                    w.traj[i] = (w.static_xy(i), w.box[i, 6])
    # heights: the sensor stays mount_height above the (undug) ground
    hf = b.hf
    g0 = float(hf.height(np.zeros(1), np.zeros(1))[0])
    ez = hf.height(exy[::2, 0], exy[::2, 1]).astype(np.float64) - g0
    frame_rngs = [np.random.default_rng(s) for s in noise_ss.spawn(F)]
    n_move = {}
    for mo in decided:
        for i in mo.objs:
            n_move[b.objects[i].label] = n_move.get(b.objects[i].label, 0) + 1
    meta = {"sensor": sensor.name, "rate_hz": rate, "dt_s": dt, "seed": int(seed), "index": int(index),
            "frames": F, "scene_kind": b.kind, "robot": bool(robot),
            "mount": {"height_m": H, "pitch_deg": float(np.degrees(pitch)), "roll_deg": float(np.degrees(roll))},
            "options": dataclasses.asdict(opts),
            "moving": dict(sorted(n_move.items())), "removed": int(w.removed.sum())}
    return SequencePlan(b, scene0.prims, sm, ts, exy[::2], eyaw[::2], ez, decided, w.removed.copy(), frame_rngs, meta)


class _TurnedGround:
    """A HeightField seen from axes turned by theta (the field is translated already): what cast_scene and
    raycast.intersect_ground use of a ground (height, cls, normal, the height bounds and the radial profile,
    which a turn about the sensor leaves as they are)."""

    def __init__(self, hf: HeightField, theta: float):
        self.hf = hf
        self.c, self.s = float(np.cos(theta)), float(np.sin(theta))
        self._zmin, self._zmax = hf._zmin, hf._zmax
        self._ring_zmin, self._ring_zmax = hf._ring_zmin, hf._ring_zmax

    def _to(self, x, y):
        return self.c * x - self.s * y, self.s * x + self.c * y

    def height(self, x, y):
        return self.hf.height(*self._to(x, y))

    def cls(self, x, y):
        return self.hf.cls(*self._to(x, y))

    def normal(self, x, y):
        n = self.hf.normal(*self._to(x, y))
        out = n.copy()
        out[:, 0] = self.c * n[:, 0] + self.s * n[:, 1]
        out[:, 1] = -self.s * n[:, 0] + self.c * n[:, 1]
        return out


@dataclass
class Frame:
    """One scan of a sequence: the simulator's ScanResult and the ground truth of its road users."""
    index: int
    t: float
    scan: object                # simulate.ScanResult (sensor frame)
    tracks: list                # dicts: id, cls, box (7,), v (2,), npts, obj
    pose: np.ndarray            # x, y, yaw in the first scan's level frame
    ego: np.ndarray             # dx, dy, dyaw from the previous scan (zeros for the first)


def _object_state(plan: SequencePlan, k: int):
    """Per object at frame k: box centres (n, 3), yaws (n,), velocities (n, 2) in the scene frame, and which move."""
    b = plan.builder
    t = plan.ts[k]
    n = len(b.objects)
    box = np.array([o.box for o in b.objects], float).reshape(n, 7)
    c = box[:, :3].copy()
    yaw = box[:, 6].copy()
    vel = np.zeros((n, 2))
    moving = np.zeros(n, bool)
    hf = b.hf
    for mo in plan.motions:
        s, v = mo.prof.at(np.array([t]))
        for i in mo.objs:
            xy = box[i, :2] + s[0] * mo.d
            dz = float(hf.height(xy[:1], xy[1:])[0] - hf.height(box[i, :1], box[i, 1:2])[0])
            c[i] = [xy[0], xy[1], box[i, 2] + dz]
            yaw[i] = mo.yaw.get(i, box[i, 6])
            vel[i] = v[0] * mo.d
            moving[i] = True
    return c, yaw, vel, moving


def simulate_sequence(sensor, seed: int = 0, index: int = 0, opts: SeqOptions = SeqOptions(), plan=None):
    """Yields the Frames of sequence `index` of run `seed`."""
    plan = plan or plan_sequence(sensor, seed, index, opts)
    b = plan.builder
    sm = plan.sm
    prims = plan.prims
    n = len(b.objects)
    box0 = np.array([o.box for o in b.objects], float).reshape(n, 7)
    keep = ~plan.removed[prims.obj]
    # per primitive of a moving object: its offset from the box centre turned to the new yaw, and M, A turned
    mov_obj = np.zeros(n, bool)
    turn = np.zeros(n)
    for mo in plan.motions:
        for i in mo.objs:
            mov_obj[i] = True
            turn[i] = mo.yaw.get(i, box0[i, 6]) - box0[i, 6]
    pm = mov_obj[prims.obj] & keep
    R = np.stack([_rot3(a) for a in turn[prims.obj[pm]]]) if pm.any() else np.zeros((0, 3, 3))
    rel = np.einsum("pij,pj->pi", R, prims.center[pm] - box0[prims.obj[pm], :3])
    M_t = prims.M[pm] @ np.transpose(R, (0, 2, 1))
    A_t = R @ prims.A[pm]
    # ground: static road users' pits once, moving ones' per scan
    hf = b.hf
    z_static = hf.z.copy()
    statics = [box0[i] for i in range(n) if b.objects[i].label and not plan.removed[i] and not mov_obj[i]]
    SceneBuilder.dig_pits(types.SimpleNamespace(hf=_PitField(hf, z_static), pits=statics))
    pose0 = (plan.ego_xy[0], plan.ego_yaw[0])
    labelled = [i for i in range(n) if b.objects[i].label and not plan.removed[i]]
    for k in range(len(plan.ts)):
        c, yaw, vel, moving = _object_state(plan, k)
        center = prims.center.copy()
        M, A = prims.M.copy(), prims.A.copy()
        center[pm] = rel + c[prims.obj[pm]]
        M[pm], A[pm] = M_t, A_t
        P = np.array([plan.ego_xy[k, 0], plan.ego_xy[k, 1], plan.ego_z[k]])
        th = float(plan.ego_yaw[k])
        Re = _rot3(th)
        pk = Primitives(prims.kind[keep], (center[keep] - P) @ Re, M[keep] @ Re, prims.radius[keep],
                        prims.sem[keep], prims.obj[keep], prims.albedo[keep], prims.drop[keep], prims.transp[keep],
                        np.einsum("ji,pjk->pik", Re, A[keep]))
        z = z_static.copy()
        pits = [np.r_[c[i], box0[i, 3:6], yaw[i]] for i in range(n) if mov_obj[i]]
        if pits:
            SceneBuilder.dig_pits(types.SimpleNamespace(hf=_PitField(hf, z), pits=pits))
        g = HeightField(hf.x0 - P[0], hf.y0 - P[1], hf.res, z - np.float32(P[2]), hf.code)
        ground = _TurnedGround(g, th) if th != 0.0 else g
        R2 = _rot2(-th)
        objs_k = []
        for o in b.objects:
            i = o.obj
            cc = R2 @ (c[i, :2] - P[:2])
            bx = np.array([cc[0], cc[1], c[i, 2] - P[2], box0[i, 3], box0[i, 4], box0[i, 5],
                           float(_wrap(yaw[i] - th))])
            objs_k.append(dataclasses.replace(o, box=bx))
        scene = Scene(b.kind, ground, pk, objs_k)
        r = cast_scene(scene, sm, plan.frame_rngs[k])
        Rm = sm.R_mount
        tracks = []
        for i in labelled:
            o = objs_k[i]
            if np.hypot(o.box[0], o.box[1]) > sm.sensor.max_range_m:
                continue
            sb = _to_sensor_box(o, Rm)
            vs = Rm.T @ np.r_[R2 @ vel[i], 0.0]
            tracks.append({"id": int(o.instance), "cls": o.label, "obj": i, "npts": int(r.n_points_obj[i]),
                           "box": np.array([sb.x, sb.y, sb.z, sb.l, sb.w, sb.h, sb.yaw]), "v": vs[:2].copy()})
        pose = _rel_pose(pose0, (plan.ego_xy[k], th))
        ego = _rel_pose((plan.ego_xy[k - 1], plan.ego_yaw[k - 1]), (plan.ego_xy[k], th)) if k else np.zeros(3)
        yield Frame(k, float(plan.ts[k]), r, tracks, pose, ego)


class _PitField:
    """What SceneBuilder.dig_pits uses of a HeightField, over another z array (no refresh)."""

    def __init__(self, hf, z):
        self.x0, self.y0, self.res, self.z = hf.x0, hf.y0, hf.res, z

    def refresh(self):
        pass


def _rel_pose(a, b):
    """Pose b in the frame of pose a: (x, y, yaw)."""
    (pa, ya), (pb, yb) = a, b
    d = _rot2(-float(ya)) @ (np.asarray(pb, float) - np.asarray(pa, float))
    return np.array([d[0], d[1], float(_wrap(float(yb) - float(ya)))])


# ------------------------------------------------------------------------------------------------
# writing


def write_sequence(out_dir, sensor, seed: int = 0, index: int = 0, opts: SeqOptions = SeqOptions()) -> dict:
    """Simulate and write sequence `index` into out_dir/<index:04d>/; returns its meta dict."""
    plan = plan_sequence(sensor, seed, index, opts)
    name = f"{index:04d}"
    d = os.path.join(out_dir, name)
    rows, poses = [], []
    n_gt = 0
    for fr in simulate_sequence(sensor, seed, index, opts, plan):
        fn = f"{fr.index:06d}"
        _write_scan(d, fn, fr.scan)
        write_tracks(os.path.join(d, "tracks", f"{fn}.txt"), fr.tracks)
        n_gt += len(fr.tracks)
        ids = {t["obj"]: t["id"] for t in fr.tracks}
        for ko, oi in zip(fr.scan.label2, fr.scan.label2_obj):
            tid = -1 if ko.type == "DontCare" else ids.get(oi, plan.builder.objects[oi].instance)
            rows.append((fr.index, tid, ko))
        poses.append((fr.index, fr.t, *fr.pose, *fr.ego))
    kitti.write_label02(os.path.join(d, "label_02", f"{name}.txt"), rows)
    kitti.write_calib(os.path.join(d, "calib", f"{name}.txt"), kitti.Calib())
    with open(os.path.join(d, "poses.txt"), "w") as f:
        f.write("# frame t x y yaw dx dy dyaw: the sensor's pose in the first scan's frame; the ego motion from the "
                "previous scan in the previous scan's frame (m, rad)\n")
        for p in poses:
            f.write(f"{p[0]:d} {p[1]:.4f} {p[2]:.5f} {p[3]:.5f} {p[4]:.6f} {p[5]:.5f} {p[6]:.5f} {p[7]:.6f}\n")
    meta = dict(plan.meta, name=name, n_track_lines=n_gt)
    with open(os.path.join(d, "meta.json"), "w") as f:
        json.dump(meta, f, indent=1, sort_keys=True)
        f.write("\n")
    return meta


def _write_scan(d, name, r) -> None:
    """The per-scan files of writer.write_scan but label_2/ and calib/ (a sequence has label_02/ and one calib)."""
    p = writer.scan_paths(d, name)
    kitti.write_bin(p["velodyne"], r.points)
    kitti.write_label(p["labels"], r.sem, r.inst)
    kitti.write_boxes(p["boxes"], r.boxes)
    os.makedirs(os.path.dirname(p["ring"]), exist_ok=True)
    np.asarray(r.ring, dtype="<u2").tofile(p["ring"])


TRACKS_HEADER = "# id class x y z l w h yaw vx vy npts (sensor frame; velocity over the ground, m/s)\n"


def write_tracks(path, tracks) -> None:
    os.makedirs(os.path.dirname(path), exist_ok=True)
    with open(path, "w") as f:
        f.write(TRACKS_HEADER)
        for t in tracks:
            x, y, z, l, w, h, yaw = t["box"]
            f.write(f"{t['id']:d} {t['cls']} {x:.4f} {y:.4f} {z:.4f} {l:.4f} {w:.4f} {h:.4f} {yaw:.5f} "
                    f"{t['v'][0]:.4f} {t['v'][1]:.4f} {t['npts']:d}\n")


def read_poses(path) -> np.ndarray:
    """poses.txt -> (F, 8) float64: frame t x y yaw dx dy dyaw."""
    return np.loadtxt(path, comments="#", ndmin=2)


# ------------------------------------------------------------------------------------------------
# CLI (lidet-sim --sequence FRAMES)


def opts_from_args(a) -> SeqOptions:
    return SeqOptions(frames=a.sequence, rate_hz=a.rate, ego_speed=a.ego_speed, ego_yaw_rate=a.ego_yaw_rate,
                      mount_height_m=a.mount_height, pitch_deg=a.pitch_deg, roll_deg=a.roll_deg, scene_kind=a.scene,
                      crowd=a.crowd, behind_cars=a.behind_cars, range_noise_m=a.range_noise, dropout=a.dropout)


def _one(args, i):
    out, sensor, seed, opts = args
    return write_sequence(out, sensor, seed, i, opts)


def main_from_args(a) -> int:
    """`lidet-sim --sequence FRAMES ...`: --scenes sequences from --start."""
    import functools
    try:
        opts = opts_from_args(a)
        if not 0.0 <= opts.ego_speed <= 30.0:
            raise ValueError("--ego-speed must be in [0, 30] m/s")
        if not 0.0 <= opts.ego_yaw_rate <= 0.5:
            raise ValueError("--ego-yaw-rate must be in [0, 0.5] rad/s")
        rate = opts.rate_hz if opts.rate_hz is not None else scan_rates(a.sensor)[0]
        if rate not in scan_rates(a.sensor):
            hz = ", ".join(f"{r:g}" for r in scan_rates(a.sensor))
            raise ValueError(f"--rate {rate:g}: {a.sensor} scans at {hz} Hz")
        if a.sequence < 1 or a.sequence > 10000:
            raise ValueError("--sequence FRAMES must be in [1, 10000]")
    except ValueError as e:
        print(f"lidet-sim: {e}", file=sys.stderr)
        return 2
    idx = range(a.start, a.start + a.scenes)
    job = functools.partial(_one, (a.out, a.sensor, a.seed, opts))
    t0 = time.perf_counter()
    bar = None
    if not a.no_progress:
        from tqdm import tqdm
        bar = tqdm(total=a.scenes, desc=f"lidet-sim {a.sensor} sequences", unit="seq")
    if a.jobs > 1 and a.scenes > 1:
        import multiprocessing as mp
        with mp.get_context("spawn").Pool(min(a.jobs, a.scenes)) as pool:
            for _ in pool.imap_unordered(job, idx):
                if bar is not None:
                    bar.update(1)
    else:
        for i in idx:
            job(i)
            if bar is not None:
                bar.update(1)
    if bar is not None:
        bar.close()
    dt = time.perf_counter() - t0
    n = a.scenes * a.sequence
    print(f"lidet-sim: {a.scenes} sequences x {a.sequence} scans of {a.sensor} at {rate:g} Hz in {dt:.2f} s "
          f"({n / max(dt, 1e-9):.2f} scans/s) -> {a.out}", file=sys.stderr)
    return 0
