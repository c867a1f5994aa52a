# SPDX-License-Identifier: MIT
"""Integer math (lib/src/qmath/lidet_qmath.c, ports/python/lidet_py_q.c): the functions the integer stages are
built on, evaluated in C over arrays for the tests against lidet_ref.qmath."""
from __future__ import annotations

import ctypes as C

import numpy as np

from ._lib import LidetError, entry_points, i32p, i64p, opt, u32p

_QMATH_OPS = {"sin": 0, "cos": 1, "atan2": 2, "isqrt": 3, "sqrt_round": 4, "urad_to_bam": 5, "ground_r": 6}


@entry_points
def _qmath_lib(L):
    L.lidet_py_qmath.argtypes = [C.c_uint32, i32p, opt(i32p), C.c_uint32, i64p]
    L.lidet_py_isqrt32.argtypes = [u32p, C.c_uint32, i64p]


def qmath(op: str, a, b=None) -> np.ndarray:
    """Evaluate one of lidet's integer math functions in C over arrays (for tests against ref.qmath).

    op: sin / cos (a: BAM32 angles, taken modulo 2^32), atan2 (a = y, b = x, int32), isqrt / sqrt_round (a, b:
    the high and low 32 bits of a uint64), urad_to_bam (a: microradians), ground_r (a: x^2 + y^2 as uint32; the
    ground stage's R, round(256 sqrt(a))). Returns int64.
    """
    L = _qmath_lib()
    if op not in _QMATH_OPS:
        raise ValueError(f"unknown op {op!r}; one of {sorted(_QMATH_OPS)}")
    a32 = np.ascontiguousarray((np.asarray(a, dtype=np.int64) & 0xFFFFFFFF).astype(np.uint32).view(np.int32))
    b32 = None
    if b is not None:
        b32 = np.ascontiguousarray((np.asarray(b, dtype=np.int64) & 0xFFFFFFFF).astype(np.uint32).view(np.int32))
        if b32.shape != a32.shape:
            raise ValueError("a and b must have the same shape")
    out = np.zeros(a32.shape, dtype=np.int64)
    st = L.lidet_py_qmath(_QMATH_OPS[op], a32.ravel(), None if b32 is None else b32.ravel(), a32.size, out.ravel())
    if st != 0:
        raise ValueError(f"lidet_py_qmath: status {st}")
    return out


def isqrt32(v) -> np.ndarray:
    """lidet__q_isqrt32 (floor sqrt in 32-bit arithmetic) over uint32 values, as int64."""
    a = np.ascontiguousarray(np.asarray(v, dtype=np.int64).astype(np.uint32))
    out = np.zeros(a.shape, np.int64)
    st = _qmath_lib().lidet_py_isqrt32(a.ravel(), a.size, out.ravel())
    if st != 0:
        raise LidetError(st, "lidet_py_isqrt32")
    return out
