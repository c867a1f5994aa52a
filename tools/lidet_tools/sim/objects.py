# SPDX-License-Identifier: MIT
"""Articulated shapes of road users and street furniture, built from analytic primitives.

Every builder works in an object frame (x forward, y left, z up, origin on the ground under the
object's centre) and returns a `Shape`: its parts plus the tight box that label files get.
`place()` moves a shape into the scene with a yaw and a ground height.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .raycast import BOX, CYLINDER, ELLIPSOID, PrimitiveList, rot_x, rot_y, rot_z

S = {  # SemanticKITTI ids used here
    "car": 10, "bicycle": 11, "truck": 18, "other-vehicle": 20, "person": 30, "bicyclist": 31,
    "building": 50, "fence": 51, "vegetation": 70, "trunk": 71, "pole": 80, "traffic-sign": 81,
    "other-object": 99,
}


@dataclass
class Part:
    kind: int
    center: np.ndarray
    half: np.ndarray
    R: np.ndarray
    sem: int
    albedo: float
    drop: float = 0.0
    transp: float = 0.0
    in_box: bool = True   # False: outside the labelled box (mirrors, as KITTI annotators leave them out)


@dataclass
class Shape:
    label: str            # label_2 / box-line class ('' for stuff without a box)
    sem: int              # SemanticKITTI class of the whole object
    parts: list = field(default_factory=list)
    thing: bool = True    # gets an instance id
    pad: tuple = (0.0, 0.0, 0.0)   # annotation margin added to the tight box (l, w, h), metres

    def add(self, kind, center, half, R=None, albedo=0.3, drop=0.0, transp=0.0, sem=None):
        self.parts.append(Part(kind, np.asarray(center, float), np.asarray(half, float),
                               np.eye(3) if R is None else np.asarray(R, float),
                               self.sem if sem is None else sem, albedo, drop, transp))

    def limb(self, p0, p1, radius, albedo=0.3, kind=ELLIPSOID, drop=0.0, transp=0.0, sem=None):
        """Ellipsoid (or cylinder / box) spanning segment p0-p1 with the given radius."""
        p0 = np.asarray(p0, float)
        p1 = np.asarray(p1, float)
        c, R, half_len = segment_frame(p0, p1)
        r = np.broadcast_to(np.asarray(radius, float), (2,))
        self.add(kind, c, [r[0], r[1], half_len], R, albedo, drop, transp, sem)

    def part_extents(self):
        """Per part: centre (k, 3), half extent of its axis-aligned box in the object frame (k, 3),
        kind (k,), in_box (k,). Computed once per shape (shapes are not edited after placement)."""
        cache = self.__dict__.setdefault("_ext", {})
        key = ("parts", len(self.parts))
        if key not in cache:
            R = np.stack([p.R for p in self.parts])
            half = np.stack([p.half for p in self.parts])
            kind = np.array([p.kind for p in self.parts])
            RH = R * half[:, None, :]
            e = np.where((kind == ELLIPSOID)[:, None], np.sqrt((RH ** 2).sum(2)), np.abs(RH).sum(2))
            cache[key] = (np.stack([p.center for p in self.parts]), e, kind,
                          np.array([p.in_box for p in self.parts]))
        return cache[key]

    def extent(self, all_parts=False):
        """(lo, hi) corners of the labelled box (parts with in_box, plus `pad`), object frame;
        all_parts: the tight box around every part, no pad."""
        cache = self.__dict__.setdefault("_ext", {})
        key = (bool(all_parts), len(self.parts))
        if key in cache:
            return cache[key]
        c, e, _, in_box = self.part_extents()
        m = np.ones(len(c), bool) if all_parts else in_box
        lo = (c[m] - e[m]).min(0)
        hi = (c[m] + e[m]).max(0)
        if not all_parts:
            pad = np.array([self.pad[0], self.pad[1], 0.0]) / 2
            lo, hi = lo - pad, hi + pad
            hi[2] += self.pad[2]
        cache[key] = (lo, hi)
        return lo, hi


def segment_frame(p0, p1):
    d = p1 - p0
    L = float(np.linalg.norm(d))
    z = d / max(L, 1e-9)
    if abs(z[0]) < 0.9:      # x = unit(e_x cross z)
        x = np.array([0.0, -z[2], z[1]])
    else:                    # x = unit(e_y cross z)
        x = np.array([z[2], 0.0, -z[0]])
    x /= np.sqrt(x @ x)
    y = np.array([z[1] * x[2] - z[2] * x[1], z[2] * x[0] - z[0] * x[2], z[0] * x[1] - z[1] * x[0]])
    return (p0 + p1) / 2.0, np.column_stack([x, y, z]), L / 2.0


def place(plist: PrimitiveList, shape: Shape, x, y, z, yaw, obj=-1):
    """Add the shape's parts to plist at ground point (x, y, z) with the given yaw.
    Returns the box (cx, cy, cz, l, w, h, yaw) in the level frame (centre of the tight box)."""
    Rz = rot_z(yaw)
    pos = np.array([x, y, z], float)
    for p in shape.parts:
        plist.add(p.kind, pos + Rz @ p.center, p.half, Rz @ p.R, p.sem, obj, p.albedo, p.drop, p.transp)
    lo, hi = shape.extent()
    c = pos + Rz @ ((lo + hi) / 2.0)
    size = hi - lo
    return np.array([c[0], c[1], c[2], size[0], size[1], size[2], yaw])


def collision_cylinders(shape: Shape, x, y, yaw):
    """One (x, y, r, z_lo, z_hi) cylinder per part, in the level frame (z above the ground).
    Labelled road users get one cylinder around their whole box, so nothing enters their box."""
    Rz = rot_z(yaw)
    if shape.label:
        lo, hi = shape.extent()
        lo2, hi2 = shape.extent(all_parts=True)
        lo, hi = np.minimum(lo, lo2), np.maximum(hi, hi2)
        c = Rz @ ((lo + hi) / 2)
        r = float(np.hypot(hi[0] - lo[0], hi[1] - lo[1]) / 2)
        return [(x + c[0], y + c[1], r, lo[2] - 0.3, hi[2] + 0.3)]
    out = []
    cs, es, kinds, _ = shape.part_extents()
    cw = cs @ Rz.T
    for c, e, ctr, kind in zip(cw, es, cs, kinds):
        zlo, zhi = ctr[2] - e[2], ctr[2] + e[2]
        long_ax = int(np.argmax(e[:2]))
        a, b = e[long_ax], e[1 - long_ax]
        if kind == BOX and a > 1.0 and a > 2.0 * b:
            # walls, fences, hedges: a row of circles along the long side instead of one huge circle
            n = int(np.ceil(a / max(b, 0.25)))
            step = a / n
            r = float(np.hypot(b, step))
            ax = Rz[:, long_ax]
            for k in range(n):
                off = -a + step * (2 * k + 1)
                out.append((x + c[0] + ax[0] * off, y + c[1] + ax[1] * off, r, zlo, zhi))
        else:
            out.append((x + c[0], y + c[1], float(np.hypot(e[0], e[1])), zlo, zhi))
    return out


def body_cylinders(shape: Shape, x, y, yaw, r_min=0.2):
    """Collision cylinders of the body alone (no annotation margin) for crowd scenes: circles of radius
    half the body's width (at least r_min) along its long axis, so people can stand 0.2 m apart and
    beside a car's flank although their labelled boxes then may overlap."""
    Rz = rot_z(yaw)
    lo, hi = shape.extent(all_parts=True)
    ext = hi - lo
    c = Rz @ ((lo + hi) / 2)
    ax = int(np.argmax(ext[:2]))
    r = max(float(ext[1 - ax]) / 2, r_min)
    n = max(1, int(np.ceil(float(ext[ax]) / (2 * r))))
    step = float(ext[ax]) / n
    d = Rz[:, ax]
    return [(x + c[0] + d[0] * (-ext[ax] / 2 + step * (k + 0.5)), y + c[1] + d[1] * (-ext[ax] / 2 + step * (k + 0.5)),
             r, lo[2], hi[2]) for k in range(n)]


# ------------------------------------------------------------------------------------------------
# Vehicles

CAR_TYPES = ("sedan", "hatchback", "suv")


def paint(rng):
    """Car paint remission and dropout: dark paints return weakly and drop more."""
    a = float(rng.choice([0.055, 0.085, 0.12, 0.17, 0.24, 0.33, 0.45], p=[.18, .14, .16, .16, .14, .12, .10]))
    drop = 0.3 if a < 0.07 else (0.15 if a < 0.1 else 0.05)
    return a, drop


def car(rng, kind=None) -> Shape:
    kind = kind or str(rng.choice(CAR_TYPES, p=[0.4, 0.38, 0.22]))
    if kind == "sedan":
        L, W, H = rng.uniform(3.9, 4.8), rng.uniform(1.62, 1.82), rng.uniform(1.40, 1.52)
        cab0, cab1, roof0, roof1 = -0.34, 0.17, -0.22, 0.04   # fractions of L (rear .. front)
    elif kind == "hatchback":
        L, W, H = rng.uniform(3.5, 4.1), rng.uniform(1.55, 1.75), rng.uniform(1.42, 1.56)
        cab0, cab1, roof0, roof1 = -0.44, 0.16, -0.40, 0.02
    else:
        L, W, H = rng.uniform(4.1, 5.2), rng.uniform(1.74, 1.92), rng.uniform(1.62, 1.80)
        cab0, cab1, roof0, roof1 = -0.45, 0.17, -0.43, 0.06
    s = Shape("Car", S["car"])
    alb, drop = paint(rng)
    cl = rng.uniform(0.13, 0.2) + (0.05 if kind == "suv" else 0.0)
    belt = cl + rng.uniform(0.55, 0.65) + (0.1 if kind == "suv" else 0.0)
    hb = (belt - cl) / 2.0
    zc = (belt + cl) / 2.0
    nose = 0.35
    # lower body: straight middle plus rounded nose and tail (elliptic cylinders)
    s.add(BOX, [0, 0, zc], [L / 2 - nose, W / 2, hb], albedo=alb, drop=drop)
    for sx in (-1, 1):
        s.add(CYLINDER, [sx * (L / 2 - nose), 0, zc], [nose, W / 2 - 0.02, hb], albedo=alb, drop=drop)
    # cabin: side glass, roof, windscreen, rear window, dark interior
    x0, x1 = cab0 * L, cab1 * L
    r0, r1 = roof0 * L, roof1 * L
    roof_t = 0.06
    wc = W / 2 - 0.08
    s.add(BOX, [(r0 + r1) / 2, 0, (belt + H - roof_t) / 2], [(r1 - r0) / 2, wc, (H - roof_t - belt) / 2],
          albedo=0.05, drop=0.3, transp=0.7)
    s.add(BOX, [(r0 + r1) / 2, 0, H - roof_t / 2], [(r1 - r0) / 2 + 0.05, wc, roof_t / 2], albedo=alb, drop=drop)
    for pa, pb in (((x1, belt), (r1, H - roof_t)), ((x0, belt), (r0, H - roof_t))):
        s.limb([pa[0], 0, pa[1]], [pb[0], 0, pb[1]], [wc, 0.02], albedo=0.05, kind=BOX, drop=0.3, transp=0.7)
    # seats and dashboard: below the window line mostly, narrower than the cabin
    s.add(BOX, [(x0 + x1) / 2, 0, belt + 0.05], [(x1 - x0) / 2 - 0.15, wc - 0.25, 0.25], albedo=0.08, drop=0.4)
    # wheels
    r = rng.uniform(0.30, 0.36) + (0.03 if kind == "suv" else 0.0)
    wb = L / 2 - max(0.75, 0.18 * L)
    for sx in (-1, 1):
        for sy in (-1, 1):
            s.add(CYLINDER, [sx * wb, sy * (W / 2 - 0.12), r], [r, r, 0.11], rot_x(np.pi / 2),
                  albedo=0.04, drop=0.35)
    # mirrors
    for sy in (-1, 1):
        s.add(BOX, [x1 - 0.05, sy * (W / 2 + 0.06), belt + 0.12], [0.08, 0.07, 0.06], albedo=alb, drop=drop)
        s.parts[-1].in_box = False
    return s


def worn(s: Shape, rng) -> Shape:
    """Crowd scenes (issue 15): a car as real ones at 20-40 m look: more often dark paint (weak returns,
    more dropout), glass that returns less, wheels and sills that drop out. Changes the parts' albedo and
    dropout only (the geometry and the box stay)."""
    dark = rng.random() < 0.35
    for p in s.parts:
        if p.transp > 0.0:                   # glass: fewer returns through and off it
            p.drop = max(p.drop, 0.5)
        elif p.kind == CYLINDER and p.albedo <= 0.04 + 1e-9:   # tyres
            p.drop = 0.7
        elif dark and p.albedo > 0.04:       # dark paint (body, roof, mirrors; not the seats)
            p.albedo = min(p.albedo, 0.055)
            p.drop = max(p.drop, 0.45)
    return s


def van(rng) -> Shape:
    L, W, H = rng.uniform(4.6, 5.6), rng.uniform(1.9, 2.05), rng.uniform(1.9, 2.4)
    s = Shape("Van", S["other-vehicle"])
    alb, drop = paint(rng)
    cl = 0.2
    hood = 0.7
    s.add(BOX, [-hood / 2, 0, (cl + H) / 2], [(L - hood) / 2, W / 2, (H - cl) / 2], albedo=alb, drop=drop)
    s.add(BOX, [L / 2 - hood / 2, 0, (cl + 1.05) / 2], [hood / 2, W / 2 - 0.03, (1.05 - cl) / 2], albedo=alb, drop=drop)
    s.limb([L / 2 - hood, 0, H - 0.1], [L / 2 - 0.1, 0, 1.05], [W / 2 - 0.08, 0.02], albedo=0.05, kind=BOX,
           drop=0.3, transp=0.8)
    r = 0.34
    for sx in (-1, 1):
        for sy in (-1, 1):
            s.add(CYLINDER, [sx * (L / 2 - 0.85), sy * (W / 2 - 0.12), r], [r, r, 0.11], rot_x(np.pi / 2),
                  albedo=0.04, drop=0.35)
    return s


def truck(rng) -> Shape:
    L, W = rng.uniform(6.5, 10.0), rng.uniform(2.3, 2.55)
    Hc, Hb = rng.uniform(2.7, 3.2), rng.uniform(3.0, 3.8)
    s = Shape("Truck", S["truck"])
    alb, drop = paint(rng)
    cab = 2.2
    s.add(BOX, [L / 2 - cab / 2, 0, (0.5 + Hc) / 2], [cab / 2, W / 2 - 0.05, (Hc - 0.5) / 2], albedo=alb, drop=drop)
    s.add(BOX, [-cab / 2 - 0.1, 0, (0.9 + Hb) / 2], [(L - cab - 0.2) / 2, W / 2, (Hb - 0.9) / 2],
          albedo=float(rng.uniform(0.2, 0.5)))
    r = 0.5
    for x in (L / 2 - 1.2, -L / 2 + 1.6, -L / 2 + 2.9):
        for sy in (-1, 1):
            s.add(CYLINDER, [x, sy * (W / 2 - 0.2), r], [r, r, 0.18], rot_x(np.pi / 2), albedo=0.04, drop=0.35)
    return s


def bus(rng) -> Shape:
    """Buses: SemanticKITTI other-vehicle (20); label_2 'Misc' (KITTI has no bus class)."""
    L, W, H = rng.uniform(10.0, 12.5), rng.uniform(2.45, 2.55), rng.uniform(2.9, 3.2)
    s = Shape("Misc", S["other-vehicle"])
    alb = float(rng.uniform(0.25, 0.5))
    s.add(BOX, [0, 0, (0.35 + 1.1) / 2], [L / 2, W / 2, (1.1 - 0.35) / 2], albedo=alb)
    s.add(BOX, [0, 0, (1.1 + 2.5) / 2], [L / 2 - 0.05, W / 2 - 0.03, 0.7], albedo=0.05, drop=0.3, transp=0.6)
    s.add(BOX, [0, 0, (2.5 + H) / 2], [L / 2, W / 2, (H - 2.5) / 2], albedo=alb)
    s.add(BOX, [0, 0, 1.8], [L / 2 - 0.3, W / 2 - 0.15, 0.6], albedo=0.15)
    r = 0.5
    for x in (L / 2 - 2.5, -L / 2 + 3.0):
        for sy in (-1, 1):
            s.add(CYLINDER, [x, sy * (W / 2 - 0.2), r], [r, r, 0.16], rot_x(np.pi / 2), albedo=0.04, drop=0.35)
    return s


# ------------------------------------------------------------------------------------------------
# People


def pedestrian(rng, height=None, child=False, walking=None) -> Shape:
    """A person from ellipsoid body parts: head, torso, pelvis, thighs, shins, upper and lower arms."""
    if height is None:
        height = rng.uniform(1.0, 1.4) if child else float(np.clip(rng.normal(1.72, 0.09), 1.5, 1.98))
    h = float(height)
    w = h / 1.75 * rng.uniform(0.9, 1.12)      # girth scale
    walking = bool(rng.random() < 0.65) if walking is None else walking
    phase = rng.uniform(0, 2 * np.pi)
    # gait: each leg swings up to 0.4-0.55 rad (a 0.6-0.9 m step); sqrt-shaped, as legs spend most of
    # a stride apart rather than passing each other
    amp = rng.uniform(0.4, 0.55) if walking else rng.uniform(0.0, 0.06)
    sp = np.sin(phase)
    phi = amp * np.sign(sp) * np.sqrt(abs(sp))
    # KITTI annotators draw pedestrian boxes looser than the body (mean l 0.84, w 0.66 m)
    s = Shape("Pedestrian", S["person"], pad=(0.3, 0.1, 0.0))
    cloth_top = float(rng.uniform(0.06, 0.45))
    cloth_leg = float(rng.uniform(0.05, 0.35))
    drop_top = 0.25 if cloth_top < 0.08 else 0.05
    hip_z = 0.53 * h
    sh_z = 0.815 * h
    s.add(ELLIPSOID, [0, 0, h - 0.065 * h], [0.09 * w, 0.08 * w, 0.065 * h], albedo=0.3)       # head
    s.add(ELLIPSOID, [0, 0, 0.87 * h - 0.01], [0.05 * w, 0.05 * w, 0.03 * h], albedo=0.3)       # neck
    s.add(ELLIPSOID, [0.01, 0, (sh_z + hip_z) / 2 + 0.02 * h], [0.11 * w, 0.19 * w, 0.17 * h],
          albedo=cloth_top, drop=drop_top)                                                      # torso
    s.add(ELLIPSOID, [0, 0, hip_z + 0.02], [0.1 * w, 0.16 * w, 0.07 * h], albedo=cloth_leg)     # pelvis
    thigh = 0.245 * h
    shin = 0.255 * h
    for side, sgn in ((1, 1.0), (-1, -1.0)):
        a = sgn * phi                                    # + = leg forward
        hip = np.array([0.0, side * 0.085 * w, hip_z])
        knee = hip + thigh * np.array([np.sin(a), 0, -np.cos(a)])
        bend = 0.45 * max(0.0, -a) + 0.05 if walking else 0.02
        ankle = knee + shin * np.array([np.sin(a - bend), 0, -np.cos(a - bend)])
        ankle[2] = max(ankle[2], 0.06)
        s.limb(hip, knee, 0.075 * w, albedo=cloth_leg)
        s.limb(knee, ankle, 0.055 * w, albedo=cloth_leg)
        s.add(ELLIPSOID, ankle + np.array([0.05, 0, -0.03]), [0.12 * w, 0.05 * w, 0.04], albedo=0.1)  # foot
        # arms swing against the legs
        b = -0.7 * a
        sh = np.array([0.0, side * 0.2 * w, sh_z])
        elbow = sh + 0.17 * h * np.array([np.sin(b), side * 0.12, -np.cos(b)])
        fb = 0.3 if walking else 0.1
        hand = elbow + 0.16 * h * np.array([np.sin(b + fb), side * 0.05, -np.cos(b + fb)])
        s.limb(sh, elbow, 0.045 * w, albedo=cloth_top, drop=drop_top)
        s.limb(elbow, hand, 0.038 * w, albedo=0.3)
    return s


def _bicycle(s: Shape, rng, sem, alb=None):
    alb = float(rng.uniform(0.1, 0.4)) if alb is None else alb
    r = 0.34
    for x in (-0.52, 0.52):
        s.add(CYLINDER, [x, 0, r], [r, r, 0.02], rot_x(np.pi / 2), albedo=0.06, drop=0.2, transp=0.65, sem=sem)
    tube = 0.025
    for p0, p1 in (([-0.52, 0, r], [-0.15, 0, 0.85]), ([0.0, 0, 0.32], [0.43, 0, 0.82]),
                   ([-0.15, 0, 0.85], [0.43, 0, 0.82]), ([0.52, 0, r], [0.43, 0, 0.95]),
                   ([-0.52, 0, r], [0.0, 0, 0.32])):
        s.limb(p0, p1, tube, albedo=alb, kind=CYLINDER, sem=sem)
    s.add(BOX, [0.43, 0, 0.97], [0.03, 0.28, 0.02], albedo=alb, sem=sem)             # handlebar
    s.add(ELLIPSOID, [-0.17, 0, 0.9], [0.13, 0.07, 0.03], albedo=0.08, sem=sem)      # saddle


def cyclist(rng) -> Shape:
    """Bicycle plus a leaning rider; the whole object is class bicyclist (31) with one instance."""
    s = Shape("Cyclist", S["bicyclist"], pad=(0.05, 0.05, 0.0))
    _bicycle(s, rng, S["bicyclist"])
    h = float(np.clip(rng.normal(1.75, 0.08), 1.55, 1.95))
    k = h / 1.75
    cloth = float(rng.uniform(0.06, 0.45))
    lean = rng.uniform(0.45, 0.8)                       # torso angle from vertical
    hip = np.array([-0.17, 0.0, 0.95])
    torso_len = 0.55 * k
    sh = hip + torso_len * np.array([np.sin(lean), 0, np.cos(lean)])
    s.limb(hip, sh, [0.19 * k, 0.12 * k], albedo=cloth)
    head = sh + 0.22 * k * np.array([np.sin(lean * 0.5), 0, np.cos(lean * 0.5)])
    s.add(ELLIPSOID, head, [0.1 * k, 0.085 * k, 0.11 * k], albedo=0.3)
    s.add(ELLIPSOID, hip, [0.11 * k, 0.15 * k, 0.08 * k], albedo=cloth)
    ph = rng.uniform(0, 2 * np.pi)
    crank = np.array([0.0, 0.0, 0.32])
    for side, sgn in ((1, 1.0), (-1, -1.0)):
        hp = hip + np.array([0, side * 0.09 * k, 0])
        pedal = crank + np.array([0.17 * np.cos(ph + (sgn < 0) * np.pi), side * 0.12,
                                  0.17 * np.sin(ph + (sgn < 0) * np.pi)])
        mid = (hp + pedal) / 2
        d = np.linalg.norm(pedal - hp)
        lt = 0.47 * k
        bend = np.sqrt(max(lt ** 2 - (d / 2) ** 2, 0.0))
        knee = mid + np.array([bend, 0, 0.0])
        s.limb(hp, knee, 0.075 * k, albedo=cloth)
        s.limb(knee, pedal, 0.055 * k, albedo=cloth)
        shs = sh + np.array([0, side * 0.19 * k, 0])
        hand = np.array([0.43, side * 0.24, 0.98])
        s.limb(shs, hand, 0.045 * k, albedo=cloth)
    return s


def parked_bicycle(rng) -> Shape:
    s = Shape("", S["bicycle"])
    _bicycle(s, rng, S["bicycle"])
    return s


# ------------------------------------------------------------------------------------------------
# Street furniture and vegetation (stuff: no instance id, no box)


def stuff(sem) -> Shape:
    return Shape("", sem, thing=False)


def tree(rng) -> Shape:
    s = stuff(S["vegetation"])
    th = rng.uniform(1.8, 3.5)                     # canopy bottom above the ground
    tr = rng.uniform(0.1, 0.25)
    cr = rng.uniform(1.5, 3.5)
    ch = cr * rng.uniform(0.8, 1.4)
    zc = th + ch
    s.add(CYLINDER, [0, 0, zc / 2], [tr, tr, zc / 2], albedo=0.31, sem=S["trunk"])
    s.add(ELLIPSOID, [0, 0, zc], [cr, cr, ch], albedo=0.33, transp=0.45, drop=0.05)
    if rng.random() < 0.5:
        s.add(ELLIPSOID, [rng.uniform(-0.6, 0.6), rng.uniform(-0.6, 0.6), zc + ch * 0.6],
              [cr * 0.7, cr * 0.7, ch * 0.6], albedo=0.33, transp=0.45)
    return s


def bush(rng) -> Shape:
    s = stuff(S["vegetation"])
    r = rng.uniform(0.4, 1.2)
    s.add(ELLIPSOID, [0, 0, r * 0.6], [r, r * rng.uniform(0.7, 1.3), r * 0.8], albedo=0.33, transp=0.3)
    return s


def pole(rng, kind="lamp") -> Shape:
    s = stuff(S["pole"])
    if kind == "lamp":
        h = rng.uniform(5.0, 9.0)
        r = rng.uniform(0.07, 0.13)
        s.add(CYLINDER, [0, 0, h / 2], [r, r, h / 2], albedo=0.2)
        s.add(BOX, [0.7, 0, h - 0.1], [0.7, 0.05, 0.04], albedo=0.2)
        s.add(BOX, [1.35, 0, h - 0.2], [0.25, 0.12, 0.08], albedo=0.3)
    elif kind == "sign":
        h = rng.uniform(2.2, 3.0)
        s.add(CYLINDER, [0, 0, h / 2], [0.04, 0.04, h / 2], albedo=0.2)
        if rng.random() < 0.5:
            s.add(BOX, [0, 0, h + 0.3], [0.02, 0.32, 0.32], albedo=0.45, sem=S["traffic-sign"])
        else:
            s.add(CYLINDER, [0, 0, h + 0.3], [0.35, 0.35, 0.015], rot_y(np.pi / 2), albedo=0.45,
                  sem=S["traffic-sign"])
    else:  # traffic light
        h = rng.uniform(3.0, 4.0)
        s.add(CYLINDER, [0, 0, h / 2], [0.08, 0.08, h / 2], albedo=0.2)
        s.add(BOX, [0, 0, h + 0.45], [0.15, 0.18, 0.45], albedo=0.15, sem=S["traffic-sign"])
    return s


def clutter(rng, kind=None) -> Shape:
    kind = kind or str(rng.choice(["bin", "bench", "bollard", "scooter", "box"]))
    s = stuff(S["other-object"])
    a = float(rng.uniform(0.1, 0.5))
    if kind == "bin":
        if rng.random() < 0.5:
            s.add(BOX, [0, 0, 0.55], [0.3, 0.3, 0.55], albedo=a)
        else:
            s.add(CYLINDER, [0, 0, 0.45], [0.28, 0.28, 0.45], albedo=a)
    elif kind == "bench":
        s.add(BOX, [0, 0, 0.45], [0.9, 0.22, 0.03], albedo=a)
        s.add(BOX, [0, -0.22, 0.7], [0.9, 0.03, 0.2], rot_x(0.15), albedo=a)
        for sx in (-1, 1):
            s.add(BOX, [sx * 0.8, 0, 0.22], [0.03, 0.2, 0.22], albedo=0.2)
    elif kind == "bollard":
        s.add(CYLINDER, [0, 0, 0.45], [0.1, 0.1, 0.45], albedo=a)
    elif kind == "scooter":
        s.add(BOX, [0, 0, 0.12], [0.5, 0.08, 0.04], albedo=0.1)
        s.limb([0.45, 0, 0.1], [0.42, 0, 1.05], 0.025, albedo=0.2, kind=CYLINDER)
        s.add(BOX, [0.42, 0, 1.05], [0.02, 0.22, 0.02], albedo=0.2)
        for x in (-0.45, 0.45):
            s.add(CYLINDER, [x, 0, 0.1], [0.1, 0.1, 0.03], rot_x(np.pi / 2), albedo=0.05)
    else:
        d = rng.uniform(0.4, 1.2, 3)
        s.add(BOX, [0, 0, d[2] / 2], d / 2, albedo=a)
    return s
