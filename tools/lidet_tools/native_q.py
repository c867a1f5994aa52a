# SPDX-License-Identifier: MIT
"""ctypes bindings of lidet's integer (fixed-point) path: the integer math, stages and PointNets.

Same shared library as lidet_tools.native (liblidet_py.so); kept in its own module so the integer path's
wrappers live apart from the float ones. Each area below configures its own entry points on first use.
"""
from __future__ import annotations

import ctypes as C

import numpy as np

from lidet_tools import native

_i32p = np.ctypeslib.ndpointer(np.int32, flags="C_CONTIGUOUS")
_i64p = np.ctypeslib.ndpointer(np.int64, flags="C_CONTIGUOUS")

# ---- integer math (lib/src/lidet_qmath.c) ------------------------------------------------------

_QMATH_OPS = {"sin": 0, "cos": 1, "atan2": 2, "isqrt": 3, "sqrt_round": 4, "urad_to_bam": 5}
_qmath_ready = False


def qmath(op: str, a, b=None) -> np.ndarray:
    """Evaluate one of lidet's integer math functions in C over arrays (for tests against ref.qmath).

    op: sin / cos (a: BAM32 angles, taken modulo 2^32), atan2 (a = y, b = x, int32), isqrt / sqrt_round (a, b:
    the high and low 32 bits of a uint64), urad_to_bam (a: microradians). Returns int64.
    """
    global _qmath_ready
    L = native.lib()
    if not _qmath_ready:
        L.lidet_py_qmath.argtypes = [C.c_uint32, _i32p, native._opt(_i32p), C.c_uint32, _i64p]
        _qmath_ready = True
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
