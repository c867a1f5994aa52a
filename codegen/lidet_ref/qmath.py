# SPDX-License-Identifier: MIT
"""Integer math of the fixed-point build, bit for bit as lib/src/qmath/lidet_qmath.c (docs/FIXED_POINT.md).

Vectorized over numpy int64 arrays (every intermediate fits: the C code uses int64/uint64 the same way).
Floor division and arithmetic right shifts in numpy equal C's on the values used here: right shifts of
negative int64 in numpy are arithmetic, and divisions are only of non-negative values.
"""
from __future__ import annotations

import numpy as np

from lidet_ref.tables import N, atan_bam, sin_q30

SIN_Q30 = np.asarray(sin_q30(), dtype=np.int64)
ATAN_BAM = np.asarray(atan_bam(), dtype=np.int64)
QUARTER = 1 << 30
HALF = 1 << 31
TURN = 1 << 32


def rshift_round(v, s: int):
    """round(v / 2^s), halves up (arithmetic shift)."""
    return (np.asarray(v, dtype=np.int64) + (1 << (s - 1))) >> s


def div_round(n, d):
    """round(n / d), halves away from zero; d > 0."""
    n = np.asarray(n, dtype=np.int64)
    d = np.asarray(d, dtype=np.int64)
    pos = (n + d // 2) // d
    neg = -((-n + d // 2) // d)
    return np.where(n >= 0, pos, neg)


def isqrt(v):
    """floor(sqrt(v)) for 0 <= v < 2^63, exact (float estimate, then corrected)."""
    v = np.asarray(v, dtype=np.uint64)
    r = np.floor(np.sqrt(v.astype(np.float64))).astype(np.uint64)
    # the float estimate is off by at most a few units near 2^63: correct both ways
    for _ in range(3):
        r = np.where(r * r > v, r - 1, r)
        r1 = r + 1
        r = np.where(r1 * r1 <= v, r1, r)
    return r.astype(np.int64)


def sqrt_round(v):
    """round(sqrt(v)) as lidet__q_sqrt_round64."""
    v = np.asarray(v, dtype=np.int64)
    r = isqrt(v)
    return np.where(v - r * r > r, r + 1, r)


def _quarter_sin(p):
    i = p >> 20
    frac = p & 0xFFFFF
    s0 = SIN_Q30[np.minimum(i, N)]
    s1 = SIN_Q30[np.minimum(i + 1, N)]
    return np.where(i == N, s0, s0 + rshift_round((s1 - s0) * frac, 20))


def sin(a):
    """sin of BAM32 angles (any integer; taken modulo 2^32), Q30."""
    a = np.asarray(a, dtype=np.int64) & (TURN - 1)
    quadrant = a >> 30
    p = a & (QUARTER - 1)
    up = _quarter_sin(p)
    down = _quarter_sin(QUARTER - p)
    return np.select([quadrant == 0, quadrant == 1, quadrant == 2], [up, down, -up], -down)


def cos(a):
    return sin(np.asarray(a, dtype=np.int64) + QUARTER)


def decode_pixels(rng, row_elev_bam):
    """x, y, z (4 mm steps) of a range-only image's (rows, cols) ranges, as lib/src/internal/lidet_qpix.h decodes
    them: the row's beam elevation e, the column centre's angle t = floor((2c + 1) 2^31 / cols) from azimuth pi,
    their sines and cosines in Q15 (the Q30 values rounded), the ray ux = round(cos e (-cos t) / 2^15),
    uy = round(cos e sin t / 2^15), uz = sin e (Q15), then each coordinate round(range u / 2^15) (halves up).
    An empty pixel (range 0) decodes to 0, 0, 0."""
    r = np.asarray(rng, dtype=np.int64) & 0x7FFF  # valid ranges are <= 32750; the C masks to 15 bits
    rows, cols = r.shape
    e = np.asarray(row_elev_bam, dtype=np.int64)[:rows]
    ce, se = rshift_round(cos(e), 15)[:, None], rshift_round(sin(e), 15)[:, None]
    t = ((2 * np.arange(cols, dtype=np.int64) + 1) << 31) // cols
    ct, st = rshift_round(cos(t), 15)[None, :], rshift_round(sin(t), 15)[None, :]
    ux = rshift_round(ce * -ct, 15)
    uy = rshift_round(ce * st, 15)
    return rshift_round(r * ux, 15), rshift_round(r * uy, 15), rshift_round(r * se, 15)


def _octant_atan(n, d):
    d_safe = np.where(d == 0, 1, d)
    t = (n << 24) // d_safe
    i = t >> 14
    frac = t & 0x3FFF
    a0 = ATAN_BAM[np.minimum(i, N)]
    a1 = ATAN_BAM[np.minimum(i + 1, N)]
    return np.where(i == N, a0, a0 + rshift_round((a1 - a0) * frac, 14))


def atan2(y, x):
    """atan2(y, x) in signed BAM32 (int32 range; pi wraps to -2^31); atan2(0, 0) = 0."""
    y = np.asarray(y, dtype=np.int64)
    x = np.asarray(x, dtype=np.int64)
    ax, ay = np.abs(x), np.abs(y)
    a = np.where(ay <= ax, _octant_atan(ay, ax), QUARTER - _octant_atan(ax, ay))
    a = np.where(x < 0, HALF - a, a)
    a = np.where(y < 0, -a, a) & (TURN - 1)
    a = np.where(a >= HALF, a - TURN, a)
    return np.where((ax == 0) & (ay == 0), 0, a)


def urad_to_bam(urad):
    """microradians -> BAM32 as lidet__q_urad_to_bam."""
    return rshift_round(np.asarray(urad, dtype=np.int64) * 11468322278, 24)
