# SPDX-License-Identifier: MIT
"""The integer projection, bit for bit as lib/src/proj/lidet_proj_q.c (docs/FIXED_POINT.md, "Projection").

Init in Python integers (exact, as the C init's int64), the per-point work vectorized over numpy int64 (every
intermediate fits: z^2 2^q is formed only below 2^63, n (x^2 + y^2) < 2^62, column products < 2^50).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from lidet_ref import qmath

COORD_MAX_MM = 131000
MAX_R2 = 131000 * 131000
MAX_ELEV_URAD = 1100000
EDGE_ONE = 1 << 29
BOUND_N_LIMIT = 1 << 27
STATS = ("n_points_in", "n_projected", "n_pixels_filled", "n_nonfinite", "n_too_close", "n_too_far",
         "n_out_of_fov", "n_bad_ring", "n_truncated")


def uniform_elevations(fov_up_urad: int, fov_down_urad: int, rows: int) -> np.ndarray:
    """lidet_sensor_q_elevations for a uniform fov: up - round((2i + 1) (up - down) / (2 rows))."""
    span = fov_up_urad - fov_down_urad
    i = np.arange(rows, dtype=np.int64)
    return fov_up_urad - qmath.div_round((2 * i + 1) * span, 2 * rows)


def _bound(a_bam: int):
    """(n, q, sign, tan Q30) of the boundary at a_bam, as make_bound."""
    sn, cs = int(qmath.sin(a_bam)), int(qmath.cos(a_bam))
    t = int(qmath.div_round(sn << 30, cs))
    v = t * t
    sh = 0
    while (v >> sh) >= BOUND_N_LIMIT:
        sh += 1
    n = int(qmath.rshift_round(v, sh)) if sh else v
    return n, 60 - sh, (t > 0) - (t < 0), t


def _below(a, b) -> bool:
    """bound_below: tangent a < tangent b, exactly, on the (n, q, sign) representations."""
    if a[2] != b[2]:
        return a[2] < b[2]
    qm = max(int(a[1]), int(b[1]))
    ma, mb = int(a[0]) << (qm - int(a[1])), int(b[0]) << (qm - int(b[1]))
    return ma < mb if a[2] > 0 else (ma > mb if a[2] < 0 else False)


def _clamp(u: int) -> int:
    return max(-MAX_ELEV_URAD, min(MAX_ELEV_URAD, u))


@dataclass
class Tables:
    rows: int
    cols: int
    row_elev_urad: np.ndarray
    row_elev_bam: np.ndarray
    ring_to_row: np.ndarray
    bound: np.ndarray      #: (rows + 1, 3) n, q, sign; rows 0 and `rows` unused
    fov_hi: tuple
    fov_lo: tuple
    col_edge: np.ndarray   #: (cols + 1,) Q29
    col_lut: np.ndarray    #: (4 cols + 1,)


def init(elev_urad_ring_order, cols: int, fov_margin_urad: int = 87266, fov_urad=None) -> Tables:
    """The tables of lidet_proj_q_init. elev_urad: the beams in ring order (microradians); fov_urad: (up, down)
    of a uniform sensor (its edges then bound the field of view, as in C). Raises ValueError where C returns
    LIDET_ERR_CONFIG."""
    elev = np.asarray(elev_urad_ring_order, dtype=np.int64)
    rows = len(elev)
    if np.any(np.abs(elev) > MAX_ELEV_URAD):
        raise ValueError("CONFIG: elevation beyond +-1.1 rad")
    order = np.argsort(-elev, kind="stable")
    row_elev = elev[order]
    if np.any(np.diff(row_elev) >= 0):
        raise ValueError("CONFIG: two beams at the same elevation")
    ring_to_row = np.empty(rows, np.int64)
    ring_to_row[order] = np.arange(rows)
    if fov_urad is None:
        top, bottom = _clamp(int(row_elev[0]) + fov_margin_urad), _clamp(int(row_elev[-1]) - fov_margin_urad)
    else:
        top, bottom = _clamp(fov_urad[0] + fov_margin_urad), _clamp(fov_urad[1] - fov_margin_urad)
    hi = _bound(int(qmath.urad_to_bam(top)))
    bound = np.zeros((rows + 1, 3), np.int64)
    t_prev = hi[3]
    for r in range(1, rows):
        s = int(qmath.urad_to_bam(int(row_elev[r - 1]) + int(row_elev[r])))
        b = _bound(int(qmath.rshift_round(s, 1)))
        if b[3] >= t_prev or (r > 1 and not _below(b, bound[r - 1])):
            raise ValueError("CONFIG: boundaries not strictly decreasing")
        t_prev = b[3]
        bound[r] = b[:3]
    lo = _bound(int(qmath.urad_to_bam(bottom)))
    if lo[3] >= t_prev:
        raise ValueError("CONFIG: field of view below the last boundary")
    c = np.arange(cols, dtype=np.int64)
    quadrant = (4 * c) // cols
    t_bam = qmath.div_round(((4 * c) % cols) << 30, cols)
    sn, cs = qmath.sin(t_bam), qmath.cos(t_bam)
    edge = np.empty(cols + 1, np.int64)
    edge[:cols] = quadrant * EDGE_ONE + qmath.div_round(sn * EDGE_ONE, sn + cs)
    edge[cols] = 5 * EDGE_ONE
    if np.any(np.diff(edge[:cols]) * cols <= EDGE_ONE):
        raise ValueError("CONFIG: column narrower than a bucket")
    k = np.arange(4 * cols + 1, dtype=np.int64)
    lut = np.searchsorted(edge[1:cols] * cols, k * EDGE_ONE, side="right").astype(np.int64)
    return Tables(rows, cols, row_elev, qmath.urad_to_bam(row_elev), ring_to_row, bound, hi[:3], lo[:3], edge, lut)


def cmp_tan(z, z2, rxy2, n, q, sign):
    """sign(z / rxy - T) as cmp_tan (vectorized; n, q, sign scalars or arrays)."""
    sz = np.sign(z)
    sat = (z2 >> (63 - q)) != 0
    lhs = np.where(sat, 0, z2) << q
    rhs = n * rxy2
    mag = np.where(sat, 1, np.sign(lhs - rhs))
    same = np.where(sz == 0, 0, np.where(sz > 0, mag, -mag))
    return np.where(sz != sign, np.where(sz > sign, 1, -1), same)


def _winners(pix, ok, key, npix: int):
    """The winner of each pixel among the points with ok: the smallest key, ties the earlier point; -1 = empty."""
    point_idx = np.full(npix, -1, np.int64)
    idx = np.nonzero(ok)[0]
    o = np.lexsort((idx, key[idx], pix[idx]))
    sp = pix[idx][o]
    first = np.ones(len(sp), bool)
    first[1:] = sp[1:] != sp[:-1]
    point_idx[sp[first]] = idx[o][first]
    return point_idx


def project(points_mm, tab: Tables, min_range_mm: int = 100, max_range_mm: int = 0, ring=None,
            max_points: int = 262144):
    """lidet_proj_q_run. Returns dict: point_pixel (n,), point_idx, x_4mm, y_4mm, z_4mm, range_4mm
    (rows * cols each, int64), stats (dict of the counts)."""
    p_all = np.asarray(points_mm, dtype=np.int64)
    n_in = len(p_all)
    n = min(n_in, max_points)
    p = p_all[:n, :3]
    x, y, z = p[:, 0], p[:, 1], p[:, 2]
    rows, cols, npix = tab.rows, tab.cols, tab.rows * tab.cols
    min2 = max(min_range_mm * min_range_mm, 1)
    max2 = min(max_range_mm * max_range_mm if max_range_mm > 0 else MAX_R2, MAX_R2)
    stats = dict.fromkeys(STATS, 0)
    stats["n_points_in"], stats["n_truncated"] = n_in, n_in - n

    coord_bad = (np.abs(p) > COORD_MAX_MM).any(1)
    pc = np.where(coord_bad[:, None], 0, p)
    xs, ys, zs = pc[:, 0], pc[:, 1], pc[:, 2]
    rxy2 = xs * xs + ys * ys
    z2 = zs * zs
    r2 = rxy2 + z2
    close = ~coord_bad & (r2 < min2)
    far = coord_bad | (~close & (r2 > max2))
    ok = ~coord_bad & ~close & ~far
    stats["n_too_close"], stats["n_too_far"] = int(close.sum()), int(far.sum())
    if ring is not None:
        rg = np.asarray(ring, dtype=np.int64)[:n]
        bad = ok & (rg >= rows)
        stats["n_bad_ring"] = int(bad.sum())
        ok &= ~bad
        row = tab.ring_to_row[np.clip(rg, 0, rows - 1)]
    else:
        out = ok & ((cmp_tan(zs, z2, rxy2, *tab.fov_hi) > 0) | (cmp_tan(zs, z2, rxy2, *tab.fov_lo) < 0))
        stats["n_out_of_fov"] = int(out.sum())
        ok &= ~out
        lo = np.zeros(n, np.int64)
        hi = np.full(n, rows - 1, np.int64)
        while np.any(lo < hi):
            act = lo < hi
            mid = (lo + hi) >> 1
            b = tab.bound[np.minimum(mid + 1, rows)]
            c = cmp_tan(zs, z2, rxy2, b[:, 0], b[:, 1], b[:, 2])
            hi = np.where(act & (c >= 0), mid, hi)
            lo = np.where(act & (c < 0), mid + 1, lo)
        row = lo
    s = np.abs(xs) + np.abs(ys)
    num = np.where(ys >= 0, s + xs, 3 * s - xs)
    zero = s == 0
    s = np.where(zero, 1, s)
    num = np.where(zero, 2, num)
    bucket = (num * cols) // s
    col = tab.col_lut[bucket]
    col = col + (tab.col_edge[col + 1] * s <= num * EDGE_ONE)
    pix = np.where(ok, row * cols + col, -1)
    stats["n_projected"] = int(ok.sum())

    key = r2 >> 2  # the winner test compares floor(r^2 / 4): squared ranges in 4 mm^2 steps
    point_idx = _winners(pix, ok, key, npix)
    filled = point_idx >= 0
    w = np.where(filled, point_idx, 0)
    planes = [np.where(filled, (p[w, k] + 2) >> 2, 0) if n else np.zeros(npix, np.int64) for k in range(3)]
    rq = (qmath.isqrt(key[w]) + 1) >> 1 if n else np.zeros(npix, np.int64)
    range_4mm = np.where(filled, np.maximum(rq, 1), 0)
    stats["n_pixels_filled"] = int(filled.sum())
    return dict(point_pixel=pix, point_idx=point_idx, x_4mm=planes[0], y_4mm=planes[1], z_4mm=planes[2],
                range_4mm=range_4mm, stats=stats, row_elev_bam=tab.row_elev_bam)


def project_returns(range_mm, azimuth, ring, tab: Tables, min_range_mm: int = 100, max_range_mm: int = 0,
                    max_points: int = 262144):
    """lidet_proj_q_run_returns: returns (range in mm, azimuth in BAM16 counterclockwise from +x, ring) -> the
    same dict as project(). The ring's row; column floor(((0x8000 - azimuth) mod 2^16) cols / 2^16); range 0 or
    below min_range_mm too close, above max_range_mm (when set) or 131 000 mm too far; the nearest return wins a
    pixel (ties: the earlier); range_4mm = max((range + 2) >> 2, 1); x, y, z decoded from row, column and range
    (qmath.decode_pixels), the planes an image with coordinates stores."""
    rg_all = np.asarray(range_mm, dtype=np.int64)
    n_in = len(rg_all)
    n = min(n_in, max_points)
    rg = rg_all[:n]
    az = np.asarray(azimuth, dtype=np.int64)[:n]
    ri = np.asarray(ring, dtype=np.int64)[:n]
    rows, cols, npix = tab.rows, tab.cols, tab.rows * tab.cols
    lo = max(min_range_mm, 1)
    hi = min(max_range_mm, COORD_MAX_MM) if max_range_mm > 0 else COORD_MAX_MM
    stats = dict.fromkeys(STATS, 0)
    stats["n_points_in"], stats["n_truncated"] = n_in, n_in - n
    close = rg < lo
    far = ~close & (rg > hi)
    bad = ~close & ~far & (ri >= rows)
    ok = ~close & ~far & ~bad
    stats["n_too_close"], stats["n_too_far"], stats["n_bad_ring"] = int(close.sum()), int(far.sum()), int(bad.sum())
    row = tab.ring_to_row[np.clip(ri, 0, rows - 1)]
    col = (((0x8000 - az) & 0xFFFF) * cols) >> 16
    pix = np.where(ok, row * cols + col, -1)
    stats["n_projected"] = int(ok.sum())
    point_idx = _winners(pix, ok, rg, npix)
    filled = point_idx >= 0
    w = np.where(filled, point_idx, 0)
    range_4mm = np.where(filled, np.maximum((rg[w] + 2) >> 2, 1), 0) if n else np.zeros(npix, np.int64)
    x, y, z = qmath.decode_pixels(range_4mm.reshape(rows, cols), tab.row_elev_bam)
    stats["n_pixels_filled"] = int(filled.sum())
    return dict(point_pixel=pix, point_idx=point_idx, x_4mm=x.ravel(), y_4mm=y.ravel(), z_4mm=z.ravel(),
                range_4mm=range_4mm, stats=stats, row_elev_bam=tab.row_elev_bam)


def returns_of_points(points_mm, ring):
    """Scan points (int mm) and their rings -> returns (range_mm, azimuth, ring) as a spinning sensor reports
    them: range = round(sqrt(x^2 + y^2 + z^2)) (exact, halves up), azimuth = round(atan2(y, x) 2^16 / 2 pi)
    mod 2^16 (float64). A conversion for tests and tools, not part of the mirrored C."""
    p = np.asarray(points_mm, dtype=np.int64)[:, :3]
    r2 = (p * p).sum(1)
    rng = (qmath.isqrt(4 * r2) + 1) >> 1
    az = np.round(np.arctan2(p[:, 1], p[:, 0]) * (65536.0 / (2.0 * np.pi))).astype(np.int64) & 0xFFFF
    return rng, az, np.asarray(ring, dtype=np.int64)
