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


# ---- post-processing: size check, BEV IoU, NMS (lib/src/lidet_post_q.c) -------------------------

_post_ready = False


def _post_lib():
    global _post_ready
    L = native.lib()
    if not _post_ready:
        f32p = np.ctypeslib.ndpointer(np.float32, flags="C_CONTIGUOUS")
        u16p = np.ctypeslib.ndpointer(np.uint16, flags="C_CONTIGUOUS")
        u8p = np.ctypeslib.ndpointer(np.uint8, flags="C_CONTIGUOUS")
        L.lidet_py_q_bev_iou.argtypes = [_i32p, _i32p, C.c_uint32, _i32p]
        L.lidet_py_bev_iou.argtypes = [f32p, f32p, C.c_uint32, f32p]
        L.lidet_py_q_post.argtypes = [_i32p, _i32p, u16p, u8p, C.c_uint32, C.c_int32, u8p, u16p, u8p]
        _post_ready = True
    return L


def _boxes(a, dtype) -> np.ndarray:
    a = np.ascontiguousarray(a, dtype=dtype)
    if a.ndim != 2 or a.shape[1] != 7:
        raise ValueError(f"boxes must be (N, 7), got {a.shape}")
    return a


def bev_iou_q(a, b) -> np.ndarray:
    """Q15 rotated BEV IoU of box pairs (N, 7) int32 (cx cy cz l w h in mm, yaw BAM32), in C."""
    a, b = _boxes(a, np.int32), _boxes(b, np.int32)
    if a.shape != b.shape:
        raise ValueError("a and b must have the same shape")
    out = np.zeros(len(a), dtype=np.int32)
    _post_lib().lidet_py_q_bev_iou(a, b, len(a), out)
    return out


def bev_iou_float(a, b) -> np.ndarray:
    """The float detector's rotated BEV IoU (lidet_box_bev_iou) of box pairs (N, 7): metres and radians."""
    a, b = _boxes(a, np.float32), _boxes(b, np.float32)
    out = np.zeros(len(a), dtype=np.float32)
    _post_lib().lidet_py_bev_iou(a, b, len(a), out)
    return out


def post_q(boxes, score_q15, cluster_id, cls, iou_q15: int) -> dict:
    """Size check + score order + NMS of the integer path in C: {'size_ok', 'kept' (cluster ids in order),
    'suppressed' (per sorted position)}."""
    boxes = _boxes(boxes, np.int32)
    n = len(boxes)
    score = np.ascontiguousarray(score_q15, dtype=np.int32)
    cid = np.ascontiguousarray(cluster_id, dtype=np.uint16)
    cl = np.ascontiguousarray(cls, dtype=np.uint8)
    size_ok = np.zeros(n, np.uint8)
    order = np.zeros(n, np.uint16)
    supp = np.zeros(n, np.uint8)
    k = _post_lib().lidet_py_q_post(boxes, score, cid, cl, n, int(iou_q15), size_ok, order, supp)
    if k < 0:
        raise ValueError(f"lidet_py_q_post: status {k} (more than LIDET_MAX_DETECTIONS detections?)")
    return {"size_ok": size_ok.astype(bool), "kept": order[:k].tolist(), "suppressed": supp.tolist()}
