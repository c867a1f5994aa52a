# SPDX-License-Identifier: MIT
"""The integer tables of the fixed-point build, computed in float64 and rounded half away from zero.

- sin_q30 / atan_bam: lib/src/qmath/lidet_qmath_tables.c (`python -m lidet_codegen qtables`), read by qmath.py;
- exp2_neg_q30 / log2_q30: lib/src/pointnet/lidet_pointnet_q_tables.c (`python -m lidet_codegen pnqtables`),
  read by pointnet_q.py.
The reference and the C files' generators (lidet_codegen.qtables, lidet_codegen.pnq_tables) take the tables from
these same functions, and tests regenerate the C files and compare them byte for byte, so C and reference can never
use different tables.
"""
from __future__ import annotations

import math

N = 1024  # qmath: table steps per quarter wave / per unit of tan
STEPS = 256  # pointnet_q: table steps per octave (2^-f) / per mantissa interval [1, 2] (log2)


def round_half_away(v: float) -> int:
    return int(math.floor(v + 0.5)) if v >= 0 else -int(math.floor(-v + 0.5))


def sin_q30() -> list[int]:
    """round(sin(i * (pi/2) / N) * 2^30), i = 0..N (a quarter wave, end point included)."""
    return [round_half_away(math.sin(i * (math.pi / 2) / N) * (1 << 30)) for i in range(N + 1)]


def atan_bam() -> list[int]:
    """round(atan(i / N) * 2^32 / (2 pi)), i = 0..N (atan on [0, 1] in BAM32 units: 2^32 a turn)."""
    return [round_half_away(math.atan(i / N) * (1 << 32) / (2 * math.pi)) for i in range(N + 1)]


def exp2_neg_q30() -> list[int]:
    """round(2^(-j / STEPS) * 2^30), j = 0..STEPS: 2^-f for the fraction f of a base-2 exponent, interpolated."""
    return [round_half_away(2.0 ** (-j / STEPS) * (1 << 30)) for j in range(STEPS + 1)]


def log2_q30() -> list[int]:
    """round(log2(1 + j / STEPS) * 2^30), j = 0..STEPS: log2 of a mantissa in [1, 2], interpolated."""
    return [round_half_away(math.log2(1.0 + j / STEPS) * (1 << 30)) for j in range(STEPS + 1)]
