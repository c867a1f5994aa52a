# SPDX-License-Identifier: MIT
"""Seeded street scenes: ground heightfield with surface classes, and placed objects.

A scene is laid out in road coordinates (u along the road, v across it, road centre at v = 0) and
turned into the level sensor frame (sensor at the origin, `mount_height_m` above the local ground).
Cross-section from the centre outwards: lanes (with dashed paint), an optional parking lane, a curb
(10-20 cm) up to the sidewalk, a verge of terrain/grass (rough, sloped up to ~8 deg), then buildings,
walls, fences and vegetation. Variants: straight street, intersection with crosswalks, parking lot,
suburban street (wide grass verges, houses, fences). The road grade changes by up to ~6 deg ahead or
behind the sensor, terrain gets bumps and dips.

Road users are placed where they belong: moving traffic in lanes, parked rows, pedestrians (alone, in
groups, children) on sidewalks and crossings, cyclists near the road edge. Footprints never overlap.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from . import objects as ob
from .crowd import behind_cars, crowds
from .raycast import HeightField, PrimitiveList

# surface codes of the ground grid -> SemanticKITTI class and remission
ROAD, PAINT, PARKING, SIDEWALK, OTHER_GROUND, TERRAIN = range(6)
SURF_SEM = np.array([40, 40, 44, 48, 49, 72], np.int32)
SURF_ALB = np.array([0.255, 0.5, 0.38, 0.385, 0.3, 0.40])   # calibrated on SemanticKITTI class means
SURF_ROUGH_DROP = np.array([0.0, 0.0, 0.0, 0.0, 0.0, 0.02])

SCENE_TYPES = ("street", "intersection", "parking", "suburban")


@dataclass
class SceneObject:
    label: str          # label_2 class ('' for stuff)
    sem: int
    box: np.ndarray     # cx, cy, cz, l, w, h, yaw (level frame)
    obj: int            # index into the primitives' obj field
    instance: int       # SemanticKITTI instance id (0 for stuff)


@dataclass
class Scene:
    kind: str
    ground: HeightField
    prims: object
    objects: list = field(default_factory=list)


class _Placer:
    """Collision-free placement: every part is a vertical cylinder (x, y, r, z_lo, z_hi) above the
    local ground; two objects collide when any two of their cylinders overlap in plan and height."""

    def __init__(self, keep_out):
        self.c = np.array([[0.0, 0.0, keep_out, -1.0, 3.0]])
        self.own = np.array([-1])   # owner (object index) of each cylinder, -1 = the sensor

    def free(self, cyl, margin, ignore=None):
        """ignore: an object index whose cylinders are not tested (crowd scenes: a person beside it)."""
        a = self.c
        c = np.asarray(cyl, dtype=np.float64)
        d = np.hypot(a[None, :, 0] - c[:, None, 0], a[None, :, 1] - c[:, None, 1])
        hit = ((d < a[None, :, 2] + c[:, None, 2] + margin) & (a[None, :, 3] < c[:, None, 4])
               & (a[None, :, 4] > c[:, None, 3]))
        if ignore is not None:
            hit &= (self.own != ignore)[None, :]
        return not hit.any()

    def take(self, cyl, owner=-1):
        self.c = np.vstack([self.c, np.asarray(cyl)])
        self.own = np.concatenate([self.own, np.full(len(cyl), owner)])


class SceneBuilder:
    def __init__(self, rng, mount_height_m, max_range_m, kind=None, robot=False, res=0.3, crowd=False,
                 behind_cars=0.0):
        self.rng = rng
        self.crowd = crowd
        self.behind_cars = float(behind_cars)
        self.parked: set[int] = set()  # object indices of the parked cars (rows and lots)
        self.H = mount_height_m
        self.kind = kind or str(rng.choice(SCENE_TYPES, p=[0.4, 0.25, 0.15, 0.2]))
        self.robot = robot
        self.res = res
        self.half = float(min(max_range_m, 80.0))
        self.plist = PrimitiveList()
        self.objects: list[SceneObject] = []
        self.n_inst = 0
        self.placer = _Placer(1.0 if robot else 3.0)
        self.pits = []

    # -- layout ------------------------------------------------------------------------------
    def layout(self):
        r = self.rng
        k = self.kind
        self.lane_w = r.uniform(3.0, 3.6)
        self.n_lanes = int(r.choice([2, 2, 3, 4])) if k != "suburban" else 2
        self.Wr = self.n_lanes * self.lane_w / 2.0
        side = {}
        for s in (1, -1):
            d = {}
            d["park"] = r.uniform(2.2, 2.6) if (r.random() < (0.75 if k == "street" else 0.4)) else 0.0
            d["curb"] = r.uniform(0.10, 0.20)
            d["walk"] = r.uniform(1.8, 4.5) if k != "suburban" else r.uniform(1.5, 2.5)
            d["verge"] = r.uniform(0.0, 2.0) if k in ("street", "intersection") else r.uniform(2.0, 6.0)
            d["slope"] = np.tan(np.radians(r.uniform(-8, 8)))
            d["slope_len"] = r.uniform(3.0, 12.0)
            d["setback"] = r.uniform(0.0, 2.5) if k != "suburban" else r.uniform(2.0, 7.0)
            d["v_curb"] = self.Wr + d["park"]
            d["v_walk_out"] = d["v_curb"] + d["walk"]
            d["v_build"] = d["v_walk_out"] + d["verge"] + d["setback"]
            side[s] = d
        if k == "parking":
            s0 = int(r.choice([1, -1]))
            side[s0]["lot"] = (side[s0]["v_curb"] + 0.0, side[s0]["v_curb"] + r.uniform(20, 35))
            side[s0]["v_walk_out"] = side[s0]["lot"][1] + 2.0
            side[s0]["v_build"] = side[s0]["v_walk_out"] + r.uniform(1, 8)
        self.side = side
        self.psi = r.normal(0.0, 0.06) if not self.robot else r.uniform(-0.4, 0.4)
        # sensor position across the road
        if self.robot and r.random() < 0.5:
            s = int(r.choice([1, -1]))
            d = side[s]
            self.v_s = s * r.uniform(d["v_curb"] + 0.6, d["v_walk_out"] - 0.4) if d["walk"] > 1.2 else 0.0
        else:
            lane = int(r.integers(0, self.n_lanes // 2 if self.n_lanes > 1 else 1))
            self.v_s = -(lane + 0.5) * self.lane_w
        self.u_x = r.uniform(8, 35) * r.choice([1, -1]) if k == "intersection" else None
        self.Wx = r.uniform(3.0, 4.0) * 2 if k == "intersection" else 0.0

    def to_level(self, u, v):
        c, s = np.cos(self.psi), np.sin(self.psi)
        vv = v - self.v_s
        return c * u - s * vv, s * u + c * vv

    def to_road(self, x, y):
        c, s = float(np.cos(self.psi)), float(np.sin(self.psi))   # python floats keep float32 grids float32
        return c * x + s * y, -s * x + c * y + self.v_s

    # -- ground ------------------------------------------------------------------------------
    def ground(self):
        r = self.rng
        n = int(2 * self.half / self.res) + 1
        ax = (-self.half + self.res * np.arange(n)).astype(np.float32)
        X, Y = np.meshgrid(ax, ax)
        U, V = self.to_road(X, Y)
        A = np.abs(V)
        sgn = np.where(V >= 0, 1, -1)
        code = np.full(X.shape, TERRAIN, np.int8)
        z = np.zeros(X.shape, np.float32)

        pos = (V < 0).astype(np.int8)

        def per_side(key):
            return np.take(np.array([self.side[1][key], self.side[-1][key]], np.float32), pos)

        v_curb = per_side("v_curb")
        v_walk = per_side("v_walk_out")
        curb_h = per_side("curb")
        slope = per_side("slope")
        slope_len = per_side("slope_len")
        park = per_side("park")
        road = A < self.Wr
        code[road] = ROAD
        code[(A >= self.Wr) & (A < v_curb) & (park > 0)] = PARKING
        walk = (A >= v_curb) & (A < v_walk)
        code[walk] = SIDEWALK
        raised = A >= v_curb
        for s in (1, -1):
            lot = self.side[s].get("lot")
            if lot is not None:
                m = (sgn == s) & (A >= lot[0]) & (A < lot[1])
                code[m] = PARKING
                raised &= ~m
                walk &= ~m
        # cross street
        if self.u_x is not None:
            xr = np.abs(U - self.u_x) < self.Wx / 2
            code[xr] = ROAD
            raised &= ~xr
            # crosswalk stripes on the main road, next to the cross street
            for e in (-1, 1):
                cw = np.nonzero((np.abs(U - float(self.u_x + e * (self.Wx / 2 + 2.0))) < 1.5) & road)
                vv = V[cw]
                white = vv - np.floor(vv) < 0.5          # 0.5 m stripes across the road
                code[cw[0][white], cw[1][white]] = PAINT
        # lane markings: dashed lines between lanes, solid edge lines
        u9 = U * np.float32(1.0 / 9.0)
        dash = (u9 - np.floor(u9)) < np.float32(1.0 / 3.0)
        for i in range(1, self.n_lanes):
            vl = float(-self.Wr + i * self.lane_w)
            code[(np.abs(V - vl) < 0.07) & dash & road] = PAINT
        code[(np.abs(A - (self.Wr - 0.25)) < 0.06) & road] = PAINT
        # occasional gravel/driveway strips in the verge
        if r.random() < 0.5:
            ud = r.uniform(-40, 40)
            m = (np.abs(U - ud) < r.uniform(1.5, 3.0)) & (A >= v_walk) & (code == TERRAIN)
            code[m] = OTHER_GROUND
        # heights: grade changes ahead/behind, camber, curb, verge slopes, undulation, bumps
        for e in (1, -1):
            u1 = float(r.uniform(10, 40))
            g = float(np.tan(np.radians(r.uniform(-6, 6))))
            s_ = np.maximum(e * U - u1, 0.0)
            z += g * (s_ - 4.0 * (1 - np.exp(-s_ / 4.0)))
        z -= 0.02 * np.clip(A / float(max(self.Wr, 1e-3)), 0, 1)             # camber
        z += np.where(raised, curb_h, 0.0)
        verge = raised & ~walk
        z += np.where(verge, slope * np.clip(A - v_walk, 0.0, slope_len), 0.0)
        for _ in range(3):
            kx, ky = (float(k) for k in r.normal(0, 1, 2))
            lam = float(r.uniform(20, 60))
            amp = float(r.uniform(0.02, 0.08))
            f = 2 * np.pi / (lam * np.hypot(kx, ky) + 1e-9)
            ph = float(r.uniform(0, 6.3))
            # sin(a x + b y + ph) = sin(a x + ph) cos(b y) + cos(a x + ph) sin(b y): 1-D trig only
            sx, cx_ = np.sin(kx * f * ax + ph), np.cos(kx * f * ax + ph)
            sy, cy_ = np.sin(ky * f * ax), np.cos(ky * f * ax)
            z += amp * (cy_[:, None] * sx[None, :] + sy[:, None] * cx_[None, :])
        terr = code == TERRAIN
        bumps = np.zeros_like(z)
        for _ in range(int(r.integers(4, 12))):
            cx, cy = (float(c) for c in r.uniform(-self.half, self.half, 2))
            sig = float(r.uniform(1.0, 5.0))
            amp = float(r.uniform(-0.4, 0.4))
            i0, i1 = np.clip(np.round((np.array([cx - 3 * sig, cx + 3 * sig]) + self.half) / self.res), 0, n).astype(int)
            j0, j1 = np.clip(np.round((np.array([cy - 3 * sig, cy + 3 * sig]) + self.half) / self.res), 0, n).astype(int)
            bumps[j0:j1, i0:i1] += amp * np.exp(-((X[j0:j1, i0:i1] - cx) ** 2 + (Y[j0:j1, i0:i1] - cy) ** 2)
                                                / (2 * sig * sig))
        rough = r.standard_normal(X.shape, dtype=np.float32) * float(r.uniform(0.015, 0.04))
        z += np.where(terr, bumps + rough, 0.0)
        # the sensor sits mount_height above the local ground
        i0 = n // 2
        z += -self.H - z[i0, i0]
        self.hf = HeightField(float(ax[0]), float(ax[0]), self.res, z, code)

    # -- placement helpers ---------------------------------------------------------------------
    def put(self, shape: ob.Shape, u, v, yaw_road, check=True, margin=0.25):
        x, y = self.to_level(u, v)
        yaw = float(np.angle(np.exp(1j * (yaw_road + self.psi))))
        return self.put_level(shape, x, y, yaw, check, margin)

    def put_level(self, shape: ob.Shape, x, y, yaw, check=True, margin=0.25, body=False, ignore=None):
        """Place at level-frame (x, y) with a level-frame yaw. body: collide with the body only (crowd
        scenes: road users may stand closer than their annotation boxes, so boxes may overlap);
        ignore: an object index not tested (the car or pole a person stands beside)."""
        if abs(x) > self.half - 2 or abs(y) > self.half - 2:
            return None
        cyl = ob.body_cylinders(shape, x, y, yaw) if body else ob.collision_cylinders(shape, x, y, yaw)
        if check and not self.placer.free(cyl, margin, ignore):
            return None
        if check:
            self.placer.take(cyl, len(self.objects))
        zg = float(self.hf.height(np.array([x]), np.array([y]))[0])
        idx = len(self.objects)
        inst = 0
        if shape.thing:
            self.n_inst += 1
            inst = self.n_inst
        box = ob.place(self.plist, shape, x, y, zg, yaw, obj=idx)
        self.objects.append(SceneObject(shape.label, shape.sem, box, idx, inst))
        if shape.label:
            self.pits.append(box)
        return box

    def vehicle(self, moving=True):
        p = self.rng.random()
        if p < (0.82 if moving else 0.9):
            return ob.car(self.rng) if not self.crowd else ob.worn(ob.car(self.rng), self.rng)
        if p < 0.92:
            return ob.van(self.rng)
        return ob.truck(self.rng) if self.rng.random() < 0.6 else ob.bus(self.rng)

    # -- content -------------------------------------------------------------------------------
    def traffic(self):
        r = self.rng
        dens = r.uniform(0.2, 1.0)
        for i in range(self.n_lanes):
            vc = -self.Wr + (i + 0.5) * self.lane_w
            forward = vc < 0
            u = r.uniform(-75, -60)
            while u < 75:
                u += r.uniform(10, 50) / dens
                sh = self.vehicle(True)
                yaw = (0.0 if forward else np.pi) + r.normal(0, 0.03)
                self.put(sh, u, vc + r.normal(0, 0.25), yaw)
        # parked rows
        for s in (1, -1):
            d = self.side[s]
            if d["park"] > 0:
                u = r.uniform(-75, -65)
                fill = r.uniform(0.3, 0.9)
                while u < 75:
                    sh = self.vehicle(False)
                    lo, hi = sh.extent()
                    L = hi[0] - lo[0]
                    u += L / 2
                    if r.random() < fill:
                        yaw = (0.0 if s < 0 else np.pi) + r.normal(0, 0.04) + (np.pi if r.random() < 0.1 else 0)
                        if self.put(sh, u, s * (self.Wr + d["park"] / 2 + r.normal(0, 0.1)), yaw, margin=0.05) is not None:
                            self.parked.add(len(self.objects) - 1)
                    u += L / 2 + r.uniform(0.6, 2.5)
            lot = d.get("lot")
            if lot is not None:
                row_v = lot[0] + 3.0
                while row_v < lot[1] - 2.5:
                    for rowside in (-1, 1):
                        vv = row_v + rowside * 2.6
                        if vv > lot[1] - 2.5:
                            continue
                        u = r.uniform(-40, -30)
                        while u < 40:
                            if r.random() < 0.75:
                                sh = ob.car(r) if r.random() < 0.92 else ob.van(r)
                                yaw = s * np.pi / 2 * rowside + r.normal(0, 0.05)
                                if self.put(sh, u, s * vv, yaw, margin=0.05) is not None:
                                    self.parked.add(len(self.objects) - 1)
                            u += r.uniform(2.5, 2.9)
                    row_v += 5.2 + 6.5
        # cyclists
        for _ in range(int(r.poisson(1.6))):
            s = int(r.choice([1, -1]))
            forward = s < 0
            if r.random() < 0.75:       # near the road edge, with the traffic
                v = s * (self.Wr - r.uniform(0.5, 1.2))
                yaw = (0.0 if forward else np.pi) + r.normal(0, 0.1)
            else:                       # on the sidewalk, either way
                d = self.side[s]
                v = s * r.uniform(d["v_curb"] + 0.5, max(d["v_curb"] + 0.6, d["v_walk_out"] - 0.5))
                yaw = (0.0 if r.random() < 0.5 else np.pi) + r.normal(0, 0.15)
            self.put(ob.cyclist(r), r.uniform(-45, 45), v, yaw)

    def people(self):
        r = self.rng
        lam = {"street": 5, "intersection": 7, "parking": 4, "suburban": 2}[self.kind] * r.uniform(0.3, 1.6)
        for _ in range(int(r.poisson(lam))):
            s = int(r.choice([1, -1]))
            d = self.side[s]
            u = r.uniform(-50, 50)
            v = s * r.uniform(d["v_curb"] + 0.4, max(d["v_curb"] + 0.5, d["v_walk_out"] - 0.3))
            n = 1 if r.random() < 0.7 else int(r.integers(2, 5))
            yaw0 = (0.0 if r.random() < 0.5 else np.pi) + r.normal(0, 0.2)
            walking = bool(r.random() < 0.65)
            for k in range(n):
                child = n > 1 and k > 0 and r.random() < 0.3
                du, dv = (0.0, 0.0) if k == 0 else r.normal(0, 0.8, 2)
                yaw = yaw0 + (r.normal(0, 0.2) if walking else r.uniform(-np.pi, np.pi))
                self.put(ob.pedestrian(r, child=child, walking=walking), u + du, v + dv, yaw, margin=0.1)
        # crossing pedestrians
        if self.u_x is not None or r.random() < 0.2:
            uc = (self.u_x + self.Wx / 2 + 2.0) if self.u_x is not None else r.uniform(-30, 30)
            for _ in range(int(r.poisson(2.0))):
                yaw = np.pi / 2 * r.choice([1, -1]) + r.normal(0, 0.15)
                self.put(ob.pedestrian(r, walking=True), uc + r.normal(0, 0.6), r.uniform(-self.Wr, self.Wr), yaw,
                         margin=0.1)
        # pedestrians in parking lots
        for s in (1, -1):
            lot = self.side[s].get("lot")
            if lot is not None:
                for _ in range(int(r.poisson(3))):
                    self.put(ob.pedestrian(r), r.uniform(-35, 35), s * r.uniform(*lot), r.uniform(-np.pi, np.pi),
                             margin=0.1)

    def furniture(self):
        r = self.rng
        for s in (1, -1):
            d = self.side[s]
            vc = d["v_curb"] + 0.5
            # lamp posts and signs along the curb
            u = r.uniform(-75, -60)
            gap = r.uniform(18, 35)
            while u < 75:
                self.put(ob.pole(r, "lamp"), u, s * vc, np.pi / 2 * s + np.pi, margin=0.1)
                u += gap
            for _ in range(int(r.integers(1, 5))):
                self.put(ob.pole(r, "sign"), r.uniform(-60, 60), s * (vc + r.uniform(-0.2, 0.3)), r.uniform(-3, 3),
                         margin=0.1)
            # street trees
            if r.random() < 0.8:
                u = r.uniform(-75, -65)
                gap = r.uniform(6, 14)
                vt = vc + 0.4 if d["walk"] > 2.5 else d["v_walk_out"] + min(d["verge"], 2.0) / 2 + 0.5
                while u < 75:
                    if r.random() < 0.8:
                        self.put(ob.tree(r), u + r.normal(0, 0.5), s * vt, 0.0, margin=0.0)
                    u += gap
            # clutter on the sidewalk
            for _ in range(int(r.poisson(4))):
                v = s * r.uniform(d["v_curb"] + 0.3, max(d["v_curb"] + 0.4, d["v_walk_out"] - 0.3))
                sh = ob.parked_bicycle(r) if r.random() < 0.15 else ob.clutter(r)
                self.put(sh, r.uniform(-60, 60), v, r.uniform(-np.pi, np.pi), margin=0.1)
            # bushes along the outer edge of the sidewalk
            for _ in range(int(r.poisson(r.uniform(2, 12)))):
                v = s * (d["v_walk_out"] + r.uniform(0.3, 1.5))
                self.put(ob.bush(r), r.uniform(-70, 70), v, 0.0, margin=0.0)
            # verge vegetation
            if d["verge"] > 1.0:
                for _ in range(int(r.poisson((d["verge"] + d["setback"]) * 6))):
                    v = s * r.uniform(d["v_walk_out"] + 0.5, d["v_walk_out"] + d["verge"] + d["setback"])
                    sh = ob.bush(r) if r.random() < 0.6 else ob.tree(r)
                    self.put(sh, r.uniform(-70, 70), v, 0.0, margin=0.0)
        if self.u_x is not None:
            for e in (1, -1):
                for s in (1, -1):
                    self.put(ob.pole(r, "light"), self.u_x + e * (self.Wx / 2 + 0.8),
                             s * (self.side[s]["v_curb"] + 0.4), 0.0, margin=0.1)

    def structures(self):
        r = self.rng
        for s in (1, -1):
            d = self.side[s]
            vb = d["v_build"]
            sub = self.kind == "suburban"
            # fence or wall along the property line (suburban / some streets)
            if sub or r.random() < 0.3:
                vf = d["v_walk_out"] + d["verge"] + 0.3 if not sub else d["v_build"] - r.uniform(2, 4)
                fh = r.uniform(1.0, 2.0)
                solid = r.random() < 0.4
                u = -78.0
                while u < 78:
                    seg = r.uniform(6, 20)
                    if r.random() < 0.85 and not self._in_cross(u + seg / 2, seg):
                        sh = ob.stuff(50 if solid and fh > 1.5 else 51)
                        sh.add(ob.BOX, [0, 0, fh / 2], [seg / 2, 0.05 if not solid else 0.12, fh / 2],
                               albedo=r.uniform(0.2, 0.45), transp=0.0 if solid else 0.45)
                        self.put(sh, u + seg / 2, s * vf, 0.0, margin=0.05)
                    u += seg + r.uniform(0.5, 4.0)
            # hedges in front of the buildings
            if r.random() < (0.8 if sub else 0.5):
                vh = max(d["v_build"] - r.uniform(0.8, 2.0), d["v_walk_out"] + 0.7)
                u = -78.0
                while u < 78:
                    seg = r.uniform(4, 15)
                    if r.random() < 0.7 and not self._in_cross(u + seg / 2, seg):
                        hh = r.uniform(0.8, 2.2)
                        sh = ob.stuff(70)
                        sh.add(ob.BOX, [0, 0, hh / 2], [seg / 2, r.uniform(0.3, 0.7), hh / 2], albedo=0.33,
                               transp=0.25)
                        self.put(sh, u + seg / 2, s * vh, 0.0, margin=0.05)
                    u += seg + r.uniform(1.0, 8.0)
            if r.random() < 0.08:
                continue  # open field on this side
            u = -78.0
            while u < 78:
                wdt = r.uniform(8, 14) if sub else r.uniform(10, 35)
                if not self._in_cross(u + wdt / 2, wdt):
                    depth = r.uniform(8, 20)
                    hgt = r.uniform(5, 9) if sub else r.uniform(6, 22)
                    sh = ob.stuff(50)
                    vv = vb + r.uniform(0, 2) + depth / 2
                    sh.add(ob.BOX, [0, 0, hgt / 2], [wdt / 2, depth / 2, hgt / 2], albedo=r.uniform(0.3, 0.65))
                    if r.random() < 0.4:
                        h2 = hgt * r.uniform(0.3, 0.7)
                        sh.add(ob.BOX, [0, -depth / 2 - 0.8, h2 / 2], [wdt / 2 * 0.8, 0.8, h2 / 2],
                               albedo=r.uniform(0.25, 0.5))
                    self.put(sh, u + wdt / 2, s * vv, 0.0 if s > 0 else np.pi, check=False)
                u += wdt + (r.uniform(3, 15) if sub else r.uniform(0, 5))

    def cross_street(self):
        """Corner buildings and trees along the cross street of an intersection."""
        if self.u_x is None:
            return
        r = self.rng
        for e in (1, -1):
            for s in (1, -1):
                vb = self.side[s]["v_build"]
                v = vb + r.uniform(0, 3)
                while v < 75:
                    wdt = r.uniform(10, 30)
                    depth = r.uniform(8, 16)
                    hgt = r.uniform(6, 20)
                    sh = ob.stuff(50)
                    sh.add(ob.BOX, [0, 0, hgt / 2], [wdt / 2, depth / 2, hgt / 2], albedo=r.uniform(0.3, 0.65))
                    uu = self.u_x + e * (self.Wx / 2 + 3.0 + r.uniform(0, 3) + depth / 2)
                    self.put(sh, uu, s * (v + wdt / 2), np.pi / 2, check=False)
                    v += wdt + r.uniform(0, 6)
                for _ in range(int(r.integers(2, 7))):
                    uu = self.u_x + e * (self.Wx / 2 + 1.0)
                    self.put(ob.tree(r), uu, s * r.uniform(vb, 70), 0.0, margin=0.0)

    def _in_cross(self, u, length):
        return self.u_x is not None and abs(u - self.u_x) < (self.Wx + length) / 2 + 1.0

    def dig_pits(self):
        """Lower the ground under road users a few cm, so their boxes hold no ground points
        (and each stands on its own flat patch)."""
        hf = self.hf
        for b in self.pits:
            cx, cy, cz, l, w, h, yaw = b
            zb = cz - h / 2 - 0.06
            rr = np.hypot(l, w) / 2 + 0.5
            i0 = int(max(0, (cx - rr - hf.x0) / hf.res))
            i1 = int(min(hf.z.shape[1] - 1, (cx + rr - hf.x0) / hf.res + 1))
            j0 = int(max(0, (cy - rr - hf.y0) / hf.res))
            j1 = int(min(hf.z.shape[0] - 1, (cy + rr - hf.y0) / hf.res + 1))
            if i1 <= i0 or j1 <= j0:
                continue
            xs = hf.x0 + hf.res * np.arange(i0, i1 + 1)
            ys = hf.y0 + hf.res * np.arange(j0, j1 + 1)
            Xs, Ys = np.meshgrid(xs, ys)
            c, s = np.cos(yaw), np.sin(yaw)
            lx = c * (Xs - cx) + s * (Ys - cy)
            ly = -s * (Xs - cx) + c * (Ys - cy)
            m = (np.abs(lx) < l / 2 + 0.4) & (np.abs(ly) < w / 2 + 0.4)
            sub = hf.z[j0:j1 + 1, i0:i1 + 1]
            sub[m] = np.minimum(sub[m], zb)
        hf.refresh()

    def build(self) -> Scene:
        self.layout()
        self.ground()
        self.structures()
        self.cross_street()
        self.traffic()
        self.people()
        self.furniture()
        if self.crowd:
            crowds(self)
        if self.behind_cars > 0.0:
            behind_cars(self, self.behind_cars)
        self.dig_pits()
        return Scene(self.kind, self.hf, self.plist.freeze(), self.objects)


def make_scene(rng, mount_height_m, max_range_m, kind=None, robot=False, crowd=False, behind_cars=0.0) -> Scene:
    """crowd: add the crowded street content of crowd.py (issue 15) after the default content. behind_cars: the
    mean number of people (or rows of people) standing behind parked cars added last (crowd.behind_cars); 0, the
    default, draws nothing, so the scene is the one it was without the option."""
    return SceneBuilder(rng, mount_height_m, max_range_m, kind, robot, crowd=crowd, behind_cars=behind_cars).build()
