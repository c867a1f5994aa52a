# SPDX-License-Identifier: MIT
"""numpy reference of the integer ground stage (lib/src/ground/lidet_ground_filter_q.c, lidet_ground_ransac_q.c),
bit for bit.

Input: a compact range image, (rows, cols) int16 x, y, z in 4 mm steps; configuration: a dict with the fields of
lidet_ground_q_cfg_t (native.ground_q_defaults gives the C defaults). Every value is an exact integer: pixel
arrays in numpy int64 (no intermediate exceeds 2^63 here, as in the C code), per-cell scalars in Python ints
(the C code never overflows its int64, so unbounded ints give the same values). The same random draws as the C
stage (ref/rng.py). Steps: `sample_mask`, `gather_samples`, `ransac_cell` (+ `refine`), `fit_sectors`,
`label_pixels`; `ground` chains them and returns the mask, the sample mask, the planes and D, the sources and
the counts.
"""
from __future__ import annotations

import numpy as np

from . import qmath
from .rng import XorShift32, cell

FITTED, NEIGHBOUR, MOUNT, NEAR = 0, 1, 2, 3
R_SHIFT = 8  # R in 4 mm / 2^8 steps (1/64 mm)
POWER_ITERS = 4
MIN_CROSS2 = 39
ONE = 1 << 30


def sector_col(s: int, ns: int, cols: int) -> int:
    return (s * cols + ns - 1) // ns


def rxy2(X, Y):
    X = np.asarray(X, np.int64)
    Y = np.asarray(Y, np.int64)
    return X * X + Y * Y


def r_of(v):
    """round(256 sqrt(v)) (R in 1/64 mm steps)."""
    return qmath.sqrt_round(np.asarray(v, np.int64) << (2 * R_SHIFT))


def r_of_range(rng, row_elev_bam):
    """R of a range-only image's pixels ((rows, cols) ranges): round(range cos(e) / 2^7) with the row's elevation
    e as lidet_qpix.h's Q15 cosine (lidet_ground_filter_q.c: r_of_range); the image's R when it keeps only the range."""
    r = np.asarray(rng, np.int64) & 0x7FFF
    e = np.asarray(row_elev_bam, np.int64)[:r.shape[0]]
    ce = qmath.rshift_round(qmath.cos(e), 15)[:, None]
    return (r * ce + 64) >> 7


def _rs(v: int, s: int) -> int:
    return (v + (1 << (s - 1))) >> s


def _div(n: int, d: int) -> int:
    return (n + d // 2) // d if n >= 0 else -((-n + d // 2) // d)


def _isqrt_round(v: int) -> int:
    return int(qmath.sqrt_round(np.int64(v)))


def _norm_shift(m: int) -> int:
    s = 0
    while (m >> s) >= (1 << 29):
        s += 1
    return s


def _shr(v: int, s: int) -> int:
    return v if s == 0 else _rs(v, s)


def split_v(cfg) -> int:
    sp = int(cfg["ring_split_mm"])
    v = (sp * sp + 15) // 16
    return 0xFFFFFFFF if sp == 0 or v > 0xFFFFFFFF else v


def sample_mask(X, Y, Z, cfg, R=None) -> np.ndarray:
    """(rows, cols) uint8: the integer sample filter. R: the pixels' R (r_of_range) for a range-only image; None:
    from x and y (an image that stores them)."""
    Z = np.asarray(Z, np.int64)
    R = r_of(rxy2(X, Y)) if R is None else np.asarray(R, np.int64)
    rows, cols = Z.shape
    out = np.zeros((rows, cols), np.uint8)
    fy = int(cfg["fy_max_q16"])
    fx_r = int(cfg["fx_max_mm"]) * (1 << (R_SHIFT - 2))
    mount = int(cfg["mount_height_mm"])
    z_lo, z_hi = -mount - int(cfg["gate_below_mm"]), -mount + int(cfg["gate_above_mm"])
    nxt = lambda a, k: np.roll(a, -k)  # noqa: E731  a[c + k], wrapping
    for r in range(0, rows - 1, int(cfg["sample_step"])):
        R0, R1, Z0, Z1 = R[r], R[r + 1], Z[r], Z[r + 1]
        dr = (2 * R0 + nxt(R0, 1)) - (2 * R1 + nxt(R1, 1))
        dz = (2 * Z0 + nxt(Z0, 1)) - (2 * Z1 + nxt(Z1, 1))
        ok = ((np.roll(R0, 1) > 0) & (R0 > 0) & (nxt(R0, 1) > 0) & (nxt(R0, 2) > 0) & (R1 > 0) & (nxt(R1, 1) > 0))
        ok &= (np.abs(dz) << 24) <= fy * np.abs(dr)
        if cfg["fx_on_z"]:
            fx = (np.roll(Z0, 1) + 2 * Z0) - (2 * nxt(Z0, 1) + nxt(Z0, 2))
            ok &= 4 * np.abs(fx) <= int(cfg["fx_max_mm"])
        else:
            fx = (np.roll(R0, 1) + 2 * R0) - (2 * nxt(R0, 1) + nxt(R0, 2))
            ok &= np.abs(fx) <= fx_r
        if cfg["require_descending"]:
            ok &= dr > 0
        if cfg["height_gate"]:
            ok &= (4 * Z0 >= z_lo) & (4 * Z0 <= z_hi)
        out[r] = ok
    return out


def gather_samples(sample, X, Y, cfg):
    """Per cell (near cells 0..ns-1, then far cells) the flat pixel indices of its samples, in the C buffer's
    order (near: raster order; far: reverse raster order). Assumes the buffer holds every sample."""
    rows, cols = sample.shape
    ns, step, cstep = int(cfg["n_sectors"]), int(cfg["sample_step"]), int(cfg["sample_col_step"])
    far_v = rxy2(X, Y).ravel() >= split_v(cfg)
    rr = np.arange(0, rows - 1, step)
    near, far = [], []
    for s in range(ns):
        c0, c1 = sector_col(s, ns, cols), sector_col(s + 1, ns, cols)
        cc = np.arange(c0 + (cstep - c0 % cstep) % cstep, c1, cstep)
        pix = (rr[:, None] * cols + cc[None, :]).ravel()
        pix = pix[sample.ravel()[pix] != 0]
        f = far_v[pix]
        near.append(pix[~f])
        far.append(pix[f][::-1])
    return near + far


def refine(P, cur, thr):
    """Least-squares plane of the inliers of cur = (n (3 ints, Q30), D) among the points P ((n, 3) int64), or
    None: integer centroid, exact scatter, power iteration on the adjugate."""
    n0 = np.array(cur[0], np.int64)
    h = P @ n0 + cur[1]
    inl = P[np.abs(h) <= thr]
    m = len(inl)
    if m < 3:
        return None
    first = P[0]
    s1 = [int(v) for v in (inl - first).sum(0)]
    c0 = [int(first[k]) + _div(s1[k], m) for k in range(3)]
    q = inl - np.array(c0, np.int64)
    e = [int(v) for v in q.sum(0)]
    x, y, z = q[:, 0], q[:, 1], q[:, 2]
    a = [int((x * x).sum()), int((x * y).sum()), int((x * z).sum()), int((y * y).sum()), int((y * z).sum()),
         int((z * z).sum())]
    s = _norm_shift(max(abs(t) for t in a))
    a = [_shr(t, s) for t in a]
    ma = max(abs(t) for t in a)
    b = [a[3] * a[5] - a[4] * a[4], a[2] * a[4] - a[1] * a[5], a[1] * a[4] - a[2] * a[3],
         a[0] * a[5] - a[2] * a[2], a[1] * a[2] - a[0] * a[4], a[0] * a[3] - a[1] * a[1]]
    mb = max(abs(t) for t in b)
    if mb == 0 or mb < ((ma * ma) >> 23):
        return None
    s = _norm_shift(mb)
    b = [_shr(t, s) for t in b]
    nv = list(cur[0])
    for _ in range(POWER_ITERS):
        v = [b[0] * nv[0] + b[1] * nv[1] + b[2] * nv[2], b[1] * nv[0] + b[3] * nv[1] + b[4] * nv[2],
             b[2] * nv[0] + b[4] * nv[1] + b[5] * nv[2]]
        nv = _unit(v)
        if nv is None:
            return None
    if nv[2] < 0:
        nv = [-t for t in nv]
    nd = nv[0] * e[0] + nv[1] * e[1] + nv[2] * e[2]
    d = -(nv[0] * c0[0] + nv[1] * c0[1] + nv[2] * c0[2]) - _div(nd, m)
    return nv, d


def _unit(v):
    s = _norm_shift(max(abs(t) for t in v))
    v = [_shr(t, s) for t in v]
    ln = _isqrt_round(v[0] * v[0] + v[1] * v[1] + v[2] * v[2])
    if ln == 0:
        return None
    return [_div(t * ONE, ln) for t in v]


def ransac_cell(P, rng: XorShift32, cfg, stats, far_step: bool = False):
    """One cell's plane (n (Q30 ints), D) or None; P: (n, 3) int64 samples in buffer order. far_step: a far
    cell under far_max_step_mm (no test of the sensor's height; the caller tests the step, far_meets)."""
    n = len(P)
    ev = int(cfg["eval_samples"])
    stride = (n + ev - 1) // ev
    n_eval = (n + stride - 1) // stride
    E = P[::stride]
    cos_t = int(qmath.cos(qmath.urad_to_bam(int(cfg["max_tilt_urad"]))))
    inl = int(cfg["inlier_mm"])
    conf = int(cfg["confidence_q16"])
    miss_max = (65536 - conf) << 14
    best = None
    best_cnt = 0
    for it in range(int(cfg["ransac_iters"])):
        i0, i1, i2 = rng.below(n), rng.below(n), rng.below(n)
        if i0 == i1 or i0 == i2 or i1 == i2:
            continue
        p0, p1, p2 = ([int(t) for t in P[i]] for i in (i0, i1, i2))
        u = [p1[k] - p0[k] for k in range(3)]
        w = [p2[k] - p0[k] for k in range(3)]
        c = [u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]]
        s = _norm_shift(max(abs(t) for t in c))
        c = [_shr(t, s) for t in c]
        len2 = c[0] * c[0] + c[1] * c[1] + c[2] * c[2]
        if len2 <= MIN_CROSS2:
            continue
        ln = _isqrt_round(len2)
        if abs(c[2]) * ONE < cos_t * ln:
            continue
        stats["n_hypotheses"] += 1
        h = (E - np.array(p0, np.int64)) @ np.array(c, np.int64)
        cnt = int(np.count_nonzero(4 * np.abs(h) <= inl * ln))
        if best is None or cnt > best_cnt:
            best, best_cnt = (c, p0, ln), cnt
            if conf > 0:
                wq = _div(cnt * ONE, n_eval)
                q = ONE - _rs(_rs(wq * wq, 30) * wq, 30)
                miss = ONE
                k = 0
                while k <= it and miss > miss_max:
                    miss = _rs(miss * q, 30)
                    k += 1
                if miss <= miss_max:
                    break
    if best is None or best_cnt < int(cfg["min_inliers"]):
        return None
    c, p0, ln = best
    sg = -1 if c[2] < 0 else 1
    nv = [_div(sg * t * ONE, ln) for t in c]
    plane = (nv, -(nv[0] * p0[0] + nv[1] * p0[1] + nv[2] * p0[2]))
    for _ in range(int(cfg["refine_iters"])):
        p = refine(P, plane, inl << 28)
        if p is None or p[0][2] < cos_t:
            break
        plane = p
    nv, d = plane
    if nv[2] < cos_t or (not far_step and
                         abs(d - (int(cfg["mount_height_mm"]) << 28)) > (int(cfg["max_height_dev_mm"]) << 28)):
        return None
    return plane


def _plane_z_at(n, d, x, y) -> int:
    return int(qmath.div_round(-(int(n[0]) * x + int(n[1]) * y + int(d)), int(n[2])))


def far_meets(s: int, ns: int, cfg, plane, near_n, near_d) -> bool:
    """lidet_ground_ransac_q.c far_meets: the far plane meets sector s's near plane at the split, at the sector's
    middle azimuth (BAM32 2^31 - floor((2 s + 1) 2^31 / ns)), within far_max_step_mm (4 |dz| <= step)."""
    az = (0x80000000 - (((2 * s + 1) << 31) // ns)) & 0xFFFFFFFF
    sp = int(cfg["ring_split_mm"])
    x = int(qmath.rshift_round(sp * int(qmath.cos(az)), 32))
    y = int(qmath.rshift_round(sp * int(qmath.sin(az)), 32))
    dz = _plane_z_at(plane[0], plane[1], x, y) - _plane_z_at(near_n, near_d, x, y)
    return 4 * abs(dz) <= int(cfg["far_max_step_mm"])


def fit_sectors(cells, XYZ, cfg, stats):
    """(2 ns, 3) int64 normals, (2 ns,) D, sources, with the fallback (lidet__ground_cells)."""
    ns = int(cfg["n_sectors"])
    n_cells = 2 * ns if int(cfg["ring_split_mm"]) > 0 else ns
    rng = XorShift32(int(cfg["seed"]))
    per_cell = bool(cfg.get("seed_per_cell", 0))
    N = np.zeros((2 * ns, 3), np.int64)
    D = np.zeros(2 * ns, np.int64)
    src = np.array([MOUNT] * ns + [NEAR] * ns, np.uint8)
    step = int(cfg.get("far_max_step_mm", 0)) > 0
    for k in range(2 * ns):
        near = k < ns
        if k == ns:  # the near fallback before the far fits (lidet__ground_cells): their test reads it
            for s in range(ns):
                if src[s] == FITTED:
                    continue
                frm = -1
                for j in range(1, int(cfg["fallback_sectors"]) + 1):
                    left, right = (s - j) % ns, (s + j) % ns
                    if src[left] == FITTED:
                        frm = left
                        break
                    if src[right] == FITTED:
                        frm = right
                        break
                if frm >= 0:
                    N[s], D[s], src[s] = N[frm], D[frm], NEIGHBOUR
                    stats["n_sectors_neighbour"] += 1
                else:
                    N[s], D[s] = (0, 0, ONE), int(cfg["mount_height_mm"]) << 28
                    stats["n_sectors_mount"] += 1
        if k >= n_cells or len(cells[k]) < int(cfg["min_samples"]):
            stats["n_sectors_sparse"] += near
            continue
        if per_cell:  # a stream of its own per cell (lidet__rng_cell), as the float stage's seed_per_cell
            rng = XorShift32(cell(int(cfg["seed"]), k))
        far_step = not near and step
        p = ransac_cell(XYZ[cells[k]], rng, cfg, stats, far_step)
        if p is not None and far_step and not far_meets(k - ns, ns, cfg, p, N[k - ns], D[k - ns]):
            p = None
        if p is not None:
            N[k], D[k], src[k] = p[0], p[1], FITTED
            stats["n_sectors_fitted" if near else "n_far_fitted"] += 1
        else:
            stats["n_sectors_rejected"] += near
    for s in range(ns):
        if src[ns + s] != FITTED:
            N[ns + s], D[ns + s], src[ns + s] = N[s], D[s], NEAR
    if not far2_on(cfg):
        return N, D, src
    # the third cells (lidet__ground_far2_cells, lidet_ground_internal.h): each far cell's samples with
    # x^2 + y^2 >= split2_v, in their order, fitted after every other cell, judged against the far plane at
    # far2_split_mm
    N = np.vstack([N, N[ns:2 * ns]])
    D = np.concatenate([D, D[ns:2 * ns]])
    src = np.concatenate([src, np.full(ns, NEAR, np.uint8)])
    v2 = split2_v(cfg)
    for s in range(ns):
        idx = np.asarray(cells[ns + s], np.int64)
        P = XYZ[idx]
        sel = idx[(P[:, 0] * P[:, 0] + P[:, 1] * P[:, 1]) >= v2]
        if len(sel) < int(cfg["min_samples"]):
            continue
        if per_cell:
            rng = XorShift32(cell(int(cfg["seed"]), 2 * ns + s))
        p = ransac_cell(XYZ[sel], rng, cfg, stats, step)
        if p is not None and step and not far_meets(s, ns, dict(cfg, ring_split_mm=cfg["far2_split_mm"]), p,
                                                    N[ns + s], D[ns + s]):
            p = None
        if p is not None:
            N[2 * ns + s], D[2 * ns + s], src[2 * ns + s] = p[0], p[1], FITTED
            stats["n_far2_fitted"] += 1
    return N, D, src


def far2_on(cfg) -> bool:
    """The third cells are on: a split, and far2_split_mm beyond it."""
    return int(cfg["ring_split_mm"]) > 0 and int(cfg.get("far2_split_mm", 0)) > int(cfg["ring_split_mm"])


def split2_v(cfg) -> int:
    sp = int(cfg.get("far2_split_mm", 0))
    v = (sp * sp + 15) // 16
    return 0xFFFFFFFF if not far2_on(cfg) or v > 0xFFFFFFFF else v


def label_pixels(X, Y, Z, N, D, cfg, stats, R=None) -> np.ndarray:
    """(rows, cols) uint8 ground mask (band test and vertical veto); R as in sample_mask."""
    X, Y, Z = (np.asarray(A, np.int64) for A in (X, Y, Z))
    rows, cols = X.shape
    ns = int(cfg["n_sectors"])
    v = rxy2(X, Y)
    far = v >= split_v(cfg)
    cell = ((np.arange(cols) * ns) // cols)[None, :] + ns * far
    if int(cfg["ring_split_mm"]) > 0:
        cell = cell + ns * (v >= split2_v(cfg))  # the third cells (beyond far2_split_mm, when on)
    h = N[cell, 0] * X + N[cell, 1] * Y + N[cell, 2] * Z + D[cell]
    above0 = int(cfg["ground_mm"]) << 28
    bf = int(cfg["below_factor_q16"])
    k = int(cfg["ground_per_m_q16"])
    R = r_of(v) if R is None else np.asarray(R, np.int64)
    if k:
        above = above0 + ((k * R) << 6)
        below = qmath.rshift_round(bf * above, 16)
    else:
        above, below = above0, _rs(bf * above0, 16)
    inb = (v > 0) & (h < above) & (h > -below)
    vt = np.zeros_like(inb)
    slope = int(cfg["veto_slope_q16"])
    if slope > 0:
        dz = np.abs(Z[:-1] - Z[1:])
        dr = np.abs(R[:-1] - R[1:])
        vt[1:] = inb[1:] & (v[:-1] > 0) & (4 * dz > int(cfg["veto_min_dz_mm"])) & ((dz << 24) > slope * dr)
    stats["n_ground"] = int(np.count_nonzero(inb & ~vt))
    stats["n_vetoed"] = int(np.count_nonzero(vt))
    return (inb & ~vt).astype(np.uint8)


def ground(X, Y, Z, cfg, R=None):
    """The whole stage: (mask, sample mask, planes (2 ns, 4) int32 as lidet_plane_q_t, D (2 ns,) int64,
    sources, counts). R: r_of_range of a range-only image's ranges (its x, y, z decoded); None for an image that
    stores x, y, z."""
    X, Y, Z = (np.asarray(A, np.int64) for A in (X, Y, Z))
    stats = dict.fromkeys(("n_samples", "n_samples_dropped", "n_ground", "n_sectors_fitted", "n_sectors_neighbour",
                           "n_sectors_mount", "n_sectors_sparse", "n_sectors_rejected", "n_far_fitted",
                           "n_far2_fitted", "n_vetoed", "n_hypotheses"), 0)
    smp = sample_mask(X, Y, Z, cfg, R)
    cells = gather_samples(smp, X, Y, cfg)
    stats["n_samples"] = int(sum(len(c) for c in cells))
    XYZ = np.stack([X.ravel(), Y.ravel(), Z.ravel()], 1)
    N, D, src = fit_sectors(cells, XYZ, cfg, stats)
    mask = label_pixels(X, Y, Z, N, D, cfg, stats, R)
    planes = np.concatenate([N, qmath.rshift_round(D, 30)[:, None]], 1).astype(np.int32)
    return mask, smp, planes, D, src, stats
