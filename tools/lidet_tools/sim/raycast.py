# SPDX-License-Identifier: MIT
"""Vectorized ray casting against analytic primitives and a heightfield ground.

All rays start at the sensor origin (0, 0, 0) of the *level* simulation frame (x fwd, y left, z up),
so each primitive's ray origin in its own unit frame is a constant.

Primitives are affine images of unit shapes: a point p is inside primitive k when
q = M_k (p - c_k) lies in the unit shape, with
  * BOX       the cube [-1, 1]^3,
  * ELLIPSOID the unit sphere,
  * CYLINDER  x^2 + y^2 <= 1, |z| <= 1 (axis = local z).
M_k = diag(1 / half_extents) R_k^T, so boxes, ellipsoids and cylinders of any orientation share one code path.

Culling: every primitive has a bounding sphere; only the rays of its (row, column) window in the ray grid
are tested, so the work is the sum of the objects' angular footprints, not rays x primitives.

The ground is a heightfield on a regular grid (bilinear heights, nearest-cell class codes). A ray is
bracketed by sampling it inside the vertical band [zmin, zmax] of the field, then refined by regula falsi.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

BOX, ELLIPSOID, CYLINDER = 0, 1, 2


@dataclass
class Primitives:
    """Struct of arrays, one entry per primitive (see module doc)."""
    kind: np.ndarray      # (P,) int8
    center: np.ndarray    # (P, 3)
    M: np.ndarray         # (P, 3, 3) world -> unit frame
    radius: np.ndarray    # (P,) bounding-sphere radius
    sem: np.ndarray       # (P,) SemanticKITTI class
    obj: np.ndarray       # (P,) object index (-1: stuff)
    albedo: np.ndarray    # (P,) mean remission at normal incidence
    drop: np.ndarray      # (P,) extra dropout probability (dark paint, tyres)
    transp: np.ndarray    # (P,) probability that a ray passes through (glass, leaves, spokes)
    A: np.ndarray = None  # (P, 3, 3) unit frame -> world (R diag(half)), for bounding corners

    def __len__(self):
        return len(self.kind)


class PrimitiveList:
    """Accumulates primitives; `freeze()` returns the arrays."""

    def __init__(self):
        self.rows = []

    def add(self, kind, center, half, R=None, sem=0, obj=-1, albedo=0.3, drop=0.0, transp=0.0):
        half = np.maximum(np.asarray(half, dtype=np.float64), 1e-3)
        R = np.eye(3) if R is None else np.asarray(R, dtype=np.float64)
        M = (R / half[None, :]).T  # diag(1/half) @ R^T
        rad = float(np.max(half)) if kind == ELLIPSOID else float(np.linalg.norm(half))
        self.rows.append((kind, np.asarray(center, dtype=np.float64), M, rad, sem, obj, albedo, drop, transp))

    def freeze(self) -> Primitives:
        if not self.rows:
            z = np.zeros(0)
            return Primitives(z.astype(np.int8), np.zeros((0, 3)), np.zeros((0, 3, 3)), z,
                              z.astype(np.int32), z.astype(np.int32), z, z, z, np.zeros((0, 3, 3)))
        k, c, M, r, s, o, a, d, t = zip(*self.rows)
        M = np.array(M)
        return Primitives(np.array(k, np.int8), np.array(c), M, np.array(r),
                          np.array(s, np.int32), np.array(o, np.int32), np.array(a, np.float64),
                          np.array(d, np.float64), np.array(t, np.float64), np.linalg.inv(M))


def rot_z(a):
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def rot_y(a):
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def rot_x(a):
    c, s = np.cos(a), np.sin(a)
    return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])


# ------------------------------------------------------------------------------------------------
# Ray grid


@dataclass
class RayGrid:
    """Rays in row-major (row, col) order; rows sorted top to bottom by *nominal* elevation."""
    dirs: np.ndarray        # (rows*cols, 3) unit directions in the level frame
    rows: int
    cols: int
    elev_rows: np.ndarray   # (rows,) nominal elevation of each row (descending)
    tilt_rad: float         # bound on |elevation change| caused by mount pitch/roll


_SIGNS = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)], float)


def cull_pairs(prims: Primitives, grid: RayGrid):
    """(ray index, primitive index) pairs whose ray lies in the primitive's angular window.

    The window comes from the corners of the primitive's oriented bounding box: the azimuth range of
    the corners bounds the azimuths of a convex body seen from outside its plan; the elevation range
    uses the nearest and farthest horizontal distances of the plan (an edge passing close overhead is
    steeper than its corners)."""
    P = len(prims)
    if P == 0:
        return np.zeros(0, np.int64), np.zeros(0, np.int64)
    corners = prims.center[:, None, :] + np.einsum("pij,kj->pki", prims.A, _SIGNS)   # (P, 8, 3)
    c = prims.center
    az_c = np.arctan2(c[:, 1], c[:, 0])
    dxy_c = np.hypot(c[:, 0], c[:, 1])
    rxy = np.hypot(corners[:, :, 0] - c[:, None, 0], corners[:, :, 1] - c[:, None, 1]).max(1)
    da = np.angle(np.exp(1j * (np.arctan2(corners[:, :, 1], corners[:, :, 0]) - az_c[:, None])))
    inside = dxy_c <= rxy * 1.0001 + 0.05
    a_hi = az_c + da.max(1) + 1e-3
    a_lo = az_c + da.min(1) - 1e-3
    dmin = np.maximum(dxy_c - rxy, 1e-3)
    dmax = dxy_c + rxy
    zmax = corners[:, :, 2].max(1)
    zmin = corners[:, :, 2].min(1)
    el_hi = np.where(zmax >= 0, np.arctan2(zmax, dmin), np.arctan2(zmax, dmax)) + grid.tilt_rad + 1e-3
    el_lo = np.where(zmin < 0, np.arctan2(zmin, dmin), np.arctan2(zmin, dmax)) - grid.tilt_rad - 1e-3
    el_hi = np.where(inside, np.pi, el_hi)
    el_lo = np.where(inside, -np.pi, el_lo)
    asc = grid.elev_rows[::-1]  # ascending
    n = grid.rows
    r0 = n - np.searchsorted(asc, el_hi, side="right")
    r1 = n - 1 - np.searchsorted(asc, el_lo, side="left")
    cols = grid.cols
    # col = floor(0.5 * (1 - az / pi) * cols); az decreases with col
    c_lo = np.floor(0.5 * (1.0 - a_hi / np.pi) * cols).astype(np.int64)
    c_hi = np.floor(0.5 * (1.0 - a_lo / np.pi) * cols).astype(np.int64)
    c_lo = np.where(inside, 0, c_lo)
    c_hi = np.where(inside, cols - 1, c_hi)
    nc = np.minimum(c_hi - c_lo + 1, cols)
    nr = np.maximum(r1 - r0 + 1, 0)
    cnt = nr * nc
    total = int(cnt.sum())
    if total == 0:
        return np.zeros(0, np.int64), np.zeros(0, np.int64)
    pidx = np.repeat(np.arange(P), cnt)
    start = np.cumsum(cnt) - cnt
    local = np.arange(total) - np.repeat(start, cnt)
    ncp = nc[pidx]
    row = r0[pidx] + local // ncp
    col = (c_lo[pidx] + local % ncp) % cols
    return row * cols + col, pidx


def intersect_pairs(prims: Primitives, dirs: np.ndarray, ray: np.ndarray, pidx: np.ndarray):
    """Entry distance t (inf on a miss) and unit-frame hit normal for each pair."""
    # np.take(axis=0) instead of fancy row indexing: same result, many times faster
    # float32 halves the memory traffic; 1e-7 relative is < 0.1 mm at 120 m
    M = np.take(prims.M.reshape(-1, 9).astype(np.float32), pidx, axis=0)                  # (n, 9)
    o = np.take(-np.einsum("pij,pj->pi", prims.M, prims.center).astype(np.float32), pidx, axis=0)
    dr = np.take(dirs.astype(np.float32), ray, axis=0)
    d = np.empty_like(dr)
    for i in range(3):
        d[:, i] = M[:, 3 * i] * dr[:, 0] + M[:, 3 * i + 1] * dr[:, 1] + M[:, 3 * i + 2] * dr[:, 2]
    t = np.full(len(ray), np.inf, np.float32)
    nrm = np.zeros((len(ray), 3), np.float32)
    kind = prims.kind[pidx]

    m = np.nonzero(kind == BOX)[0]
    if m.size:
        oo, dd = np.take(o, m, axis=0), np.take(d, m, axis=0)
        with np.errstate(divide="ignore", invalid="ignore"):
            inv = np.float32(1.0) / np.where(np.abs(dd) < 1e-12, np.float32(1e-12), dd)
        t1 = (-1.0 - oo) * inv
        t2 = (1.0 - oo) * inv
        tn = np.minimum(t1, t2)
        tf = np.maximum(t1, t2)
        axis = np.argmax(tn, axis=1)
        tmin = tn[np.arange(len(tn)), axis]
        tmax = tf.min(axis=1)
        ok = (tmax >= tmin) & (tmin > 1e-6)
        tb = np.where(ok, tmin, np.inf)
        nb = np.zeros_like(oo)
        nb[np.arange(len(nb)), axis] = -np.sign(dd[np.arange(len(dd)), axis])
        t[m] = tb
        nrm[m] = nb

    m = np.nonzero(kind == ELLIPSOID)[0]
    if m.size:
        oo, dd = np.take(o, m, axis=0), np.take(d, m, axis=0)
        # closest approach first (no cancellation in float32): p = o + tc d, h2 = 1 - |p|^2
        a = (dd * dd).sum(1)
        tc = -(oo * dd).sum(1) / a
        pc = oo + tc[:, None] * dd
        h2 = 1.0 - (pc * pc).sum(1)
        ok = (h2 >= 0) & ((oo * oo).sum(1) > 1.0)
        te = tc - np.sqrt(np.where(ok, h2, 0.0) / a)
        ok &= te > 1e-6
        te = np.where(ok, te, np.inf)
        t[m] = te
        nrm[m] = oo + np.where(ok, te, 0.0)[:, None] * dd

    m = np.nonzero(kind == CYLINDER)[0]
    if m.size:
        oo, dd = np.take(o, m, axis=0), np.take(d, m, axis=0)
        a = dd[:, 0] ** 2 + dd[:, 1] ** 2
        a_ = np.where(a > 1e-18, a, 1.0)
        tc = -(oo[:, 0] * dd[:, 0] + oo[:, 1] * dd[:, 1]) / a_
        px = oo[:, 0] + tc * dd[:, 0]
        py = oo[:, 1] + tc * dd[:, 1]
        h2 = 1.0 - (px * px + py * py)
        ok = (h2 >= 0) & (oo[:, 0] ** 2 + oo[:, 1] ** 2 > 1.0) & (a > 1e-18)
        ts = tc - np.sqrt(np.where(ok, h2, 0.0) / a_)
        zs = oo[:, 2] + ts * dd[:, 2]
        ok &= (ts > 1e-6) & (np.abs(zs) <= 1.0)
        ts = np.where(ok, ts, np.inf)
        # caps: the ray enters through the cap on the origin's side
        zc = np.where(oo[:, 2] > 0, 1.0, -1.0)
        with np.errstate(divide="ignore", invalid="ignore"):
            tc = (zc - oo[:, 2]) / np.where(np.abs(dd[:, 2]) < 1e-12, 1e-12, dd[:, 2])
        xc = oo[:, 0] + tc * dd[:, 0]
        yc = oo[:, 1] + tc * dd[:, 1]
        okc = (np.abs(oo[:, 2]) > 1.0) & (tc > 1e-6) & (xc * xc + yc * yc <= 1.0)
        tc = np.where(okc, tc, np.inf)
        use_cap = tc < ts
        tt = np.minimum(ts, tc)
        n_side = oo + np.where(np.isfinite(ts), ts, 0.0)[:, None] * dd
        n_side[:, 2] = 0.0
        n_cap = np.zeros_like(oo)
        n_cap[:, 2] = zc
        t[m] = tt
        nrm[m] = np.where(use_cap[:, None], n_cap, n_side)
    return t.astype(np.float64), nrm.astype(np.float64)


def world_normals(prims: Primitives, pidx: np.ndarray, nrm_local: np.ndarray) -> np.ndarray:
    """Unit-frame normal -> level-frame unit normal (n_world ~ M^T n_local)."""
    n = np.einsum("nji,nj->ni", np.take(prims.M, pidx, axis=0), nrm_local)
    return n / np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-12)


# ------------------------------------------------------------------------------------------------
# Heightfield ground


_RING_CACHE: dict = {}


def _ring_index(shape, x0, y0, res):
    """Grid points sorted by 1 m ring of horizontal distance to the origin (cached per grid)."""
    key = (shape, x0, y0, res)
    if key not in _RING_CACHE:
        xs = x0 + res * np.arange(shape[1])
        ys = y0 + res * np.arange(shape[0])
        r = np.hypot(xs[None, :], ys[:, None]).ravel()
        b = np.floor(r).astype(np.int64)
        perm = np.argsort(b, kind="stable")
        nb = int(b.max()) + 1
        starts = np.searchsorted(b[perm], np.arange(nb))
        if len(_RING_CACHE) > 4:
            _RING_CACHE.clear()
        _RING_CACHE[key] = (perm, starts, nb)
    return _RING_CACHE[key]


class HeightField:
    """Ground heights on a regular grid (row = y, col = x) with bilinear interpolation, and a
    SemanticKITTI class code per cell (nearest cell). Each cell keeps its bilinear coefficients
    (z00, dz_x, dz_y, dz_xy) side by side, so one height costs one gather."""

    def __init__(self, x0, y0, res, z, code):
        self.x0, self.y0, self.res = float(x0), float(y0), float(res)
        self.z = np.asarray(z)
        self.code = code
        self.refresh()

    def refresh(self):
        """Recompute the interpolation table after editing `z`."""
        z = self.z.astype(np.float32)
        zp = np.pad(z, ((0, 1), (0, 1)), mode="edge")
        z00, z01, z10, z11 = zp[:-1, :-1], zp[:-1, 1:], zp[1:, :-1], zp[1:, 1:]
        self._coef = np.stack([z00, z01 - z00, z10 - z00, z11 - z10 - z01 + z00], -1).reshape(-1, 4)
        self._zmin, self._zmax = float(z.min()), float(z.max())
        # radial profile: min / max height of the grid points per 1 m ring around the sensor, widened by
        # one ring on each side (a bilinear patch spans < 0.5 m of radius); beyond the grid's inscribed
        # circle heights are clamped edge values, so the global extremes apply there
        perm, starts, nb = _ring_index(z.shape, self.x0, self.y0, self.res)
        zs = z.ravel()[perm]
        lo = np.minimum.reduceat(zs, starts)
        hi = np.maximum.reduceat(zs, starts)
        lo = np.minimum(np.minimum(lo, np.r_[lo[1:], lo[-1]]), np.r_[lo[0], lo[:-1]])
        hi = np.maximum(np.maximum(hi, np.r_[hi[1:], hi[-1]]), np.r_[hi[0], hi[:-1]])
        half = min(-self.x0, -self.y0, self.x0 + self.res * (z.shape[1] - 1), self.y0 + self.res * (z.shape[0] - 1))
        edge = np.arange(nb) + 2 > half
        lo[edge] = self._zmin
        hi[edge] = self._zmax
        self._ring_zmin, self._ring_zmax = lo.astype(np.float64) - 0.01, hi.astype(np.float64) + 0.01

    def _lookup(self, x, y):
        ny, nx = self.z.shape
        inv = np.float32(1.0 / self.res)
        fx = (np.asarray(x, np.float32) - np.float32(self.x0)) * inv
        fy = (np.asarray(y, np.float32) - np.float32(self.y0)) * inv
        np.clip(fx, 0.0, nx - 1.001, out=fx)
        np.clip(fy, 0.0, ny - 1.001, out=fy)
        ix = fx.astype(np.int64)
        iy = fy.astype(np.int64)
        fx -= ix
        fy -= iy
        c = np.take(self._coef, iy * nx + ix, axis=0)   # (much faster than fancy row indexing)
        return c, fx, fy

    def height(self, x, y):
        c, ax, ay = self._lookup(x, y)
        return c[:, 0] + ax * c[:, 1] + ay * (c[:, 2] + ax * c[:, 3])

    def cls(self, x, y):
        ny, nx = self.z.shape
        ix = np.clip(np.rint((np.asarray(x) - self.x0) / self.res), 0, nx - 1).astype(np.int64)
        iy = np.clip(np.rint((np.asarray(y) - self.y0) / self.res), 0, ny - 1).astype(np.int64)
        return self.code[iy, ix]

    def normal(self, x, y):
        c, ax, ay = self._lookup(x, y)
        gx = (c[:, 1] + ay * c[:, 3]) / self.res
        gy = (c[:, 2] + ax * c[:, 3]) / self.res
        n = np.stack([-gx, -gy, np.ones_like(gx)], 1).astype(np.float64)
        return n / np.linalg.norm(n, axis=1, keepdims=True)


def _ring_band(hf: HeightField, dirs: np.ndarray, grid: RayGrid):
    """Per ray, the stretch [t_lo, t_hi] where it can first meet the ground: from the first ring whose
    highest point the ray may reach, to the end of the first ring whose lowest point it is surely below.
    Worked out per row of the grid with the row's elevation widened by the mount tilt."""
    zlo, zhi = hf._ring_zmin, hf._ring_zmax
    nb = len(zlo)
    e0 = np.arange(nb, dtype=np.float64)
    e1 = e0 + 1.0
    tan_lo = np.tan(grid.elev_rows - grid.tilt_rad)[:, None]
    tan_hi = np.tan(grid.elev_rows + grid.tilt_rad)[:, None]
    zmin_ray = np.minimum(e0 * tan_lo, e1 * tan_lo)          # (rows, rings)
    zmax_ray = np.maximum(e0 * tan_hi, e1 * tan_hi)
    possible = zmin_ray <= zhi[None, :]
    below = zmax_ray < zlo[None, :]
    below[:, -1] = True
    # rising rays: above every farther ring from here on
    zhi_after = np.maximum.accumulate(zhi[::-1])[::-1]
    above = (zmin_ray > zhi_after[None, :]) & (tan_lo >= 0)     # only rays that never descend
    k_lo = np.where(possible.any(1), np.argmax(possible, 1), nb)
    k_hi = np.argmax(below, 1)
    s_lo = np.where(k_lo < nb, k_lo, np.inf)
    s_hi = np.where(k_hi < nb - 1, k_hi + 1.0, np.inf)
    k_ab = np.where(above.any(1), np.argmax(above, 1), nb)
    s_hi = np.minimum(s_hi, np.where(k_ab < nb, k_ab + 0.0, np.inf))
    s_lo = np.repeat(s_lo, grid.cols)
    s_hi = np.repeat(s_hi, grid.cols)
    ch = np.maximum(np.hypot(dirs[:, 0], dirs[:, 1]), 1e-9)
    return s_lo / ch, s_hi / ch


def intersect_ground(hf: HeightField, dirs: np.ndarray, t_max, n_samples: int = 9,
                     n_refine: int = 7, grid: RayGrid | None = None) -> np.ndarray:
    """Distance along each unit ray to the first crossing of the heightfield (inf: none).
    t_max: scalar or per-ray bound (e.g. the nearest object hit: the ground behind it is not searched).
    grid: the RayGrid the rays come from (rows x cols); narrows each ray's search with the field's
    radial height profile."""
    t = np.full(len(dirs), np.inf)
    zmin, zmax = hf._zmin - 0.01, hf._zmax + 0.01
    dz = dirs[:, 2]
    if grid is not None:
        t_lo, t_hi = _ring_band(hf, dirs, grid)
    else:
        # ray z(t) = dz * t; restrict to the band zmin <= z <= zmax
        with np.errstate(divide="ignore", invalid="ignore"):
            t_lo = np.where(dz < 0, zmax / dz, 0.0)
            t_hi = np.where(dz < 0, zmin / dz, np.where(dz > 0, zmax / dz, np.inf))
    t_lo = np.maximum(t_lo, 0.05)
    t_hi = np.minimum(t_hi, t_max)
    cand = np.nonzero((t_hi > t_lo) & ((dz < 0) | (zmax > 0)))[0]
    if cand.size == 0:
        return t
    d = np.take(dirs, cand, axis=0).astype(np.float32)
    lo, hi = t_lo[cand].astype(np.float32), t_hi[cand].astype(np.float32)
    s = np.linspace(0.0, 1.0, n_samples, dtype=np.float32)
    ts = lo[:, None] + (hi - lo)[:, None] * s[None, :]          # (n, S)
    px = d[:, 0:1] * ts
    py = d[:, 1:2] * ts
    f = d[:, 2:3] * ts - hf.height(px.ravel(), py.ravel()).reshape(ts.shape)
    below = f <= 0
    has = below.any(1)
    j = np.argmax(below, axis=1)
    keep = has & (j > 0)
    rows = np.nonzero(keep)[0]
    j = j[keep]
    a = ts[rows, j - 1]
    b = ts[rows, j]
    fa = f[rows, j - 1]
    fb = f[rows, j]
    dd = np.take(d, rows, axis=0)
    for _ in range(n_refine):
        # regula falsi, guarded towards bisection
        m = a + (b - a) * np.clip(fa / np.maximum(fa - fb, 1e-12), 0.1, 0.9)
        fm = dd[:, 2] * m - hf.height(dd[:, 0] * m, dd[:, 1] * m)
        pos = fm > 0
        a = np.where(pos, m, a)
        fa = np.where(pos, fm, fa)
        b = np.where(pos, b, m)
        fb = np.where(pos, fb, fm)
    tt = a + (b - a) * np.clip(fa / np.maximum(fa - fb, 1e-12), 0.0, 1.0)
    t[cand[rows]] = tt.astype(np.float64)
    return t
