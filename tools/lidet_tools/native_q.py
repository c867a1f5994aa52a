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


# ---- int8 PointNets (lib/src/lidet_pointnet_q.c) over the int8 models of lidet::weights ---------

_i16p = np.ctypeslib.ndpointer(np.int16, flags="C_CONTIGUOUS")
_u8p = np.ctypeslib.ndpointer(np.uint8, flags="C_CONTIGUOUS")
_u64p = np.ctypeslib.ndpointer(np.uint64, flags="C_CONTIGUOUS")
_pnq_ready = False


def _pnq_lib():
    global _pnq_ready
    L = native.lib()
    if not _pnq_ready:
        L.lidet_py_pnq_count.restype = C.c_uint32
        L.lidet_py_pnq_info.argtypes = [C.c_uint32, C.c_char_p, _i32p]
        L.lidet_py_pnq_forward.argtypes = [C.c_uint32, C.c_uint32, C.c_uint32, _i16p, _i16p, native._opt(_u8p), _i32p]
        L.lidet_py_pnq_classify.argtypes = [C.c_uint32, C.c_uint32, C.c_uint32, _i16p, _i32p, _i16p, _i32p, _i32p,
                                            _i32p, _u8p, _u8p]
        L.lidet_py_pnq_box.argtypes = [C.c_uint32, C.c_uint32, C.c_uint32, _i16p, _i32p, _i16p, _u8p, _i32p, _i32p,
                                       _u8p, _u8p]
        L.lidet_py_pnq_energy.argtypes = [C.c_uint32, C.c_uint32, _i32p, C.c_int32, _i32p]
        L.lidet_py_pnq_time.argtypes = [C.c_uint32, C.c_uint32, C.c_uint32, C.c_uint32, _i16p, _i32p, _i16p,
                                        C.c_uint32, _u64p]
        _pnq_ready = True
    return L


def pnq_models() -> dict:
    """name -> dict(index, kind, n_points, n_outputs, scratch_bytes, ...) of every int8 model in the bindings."""
    L = _pnq_lib()
    out = {}
    for i in range(int(L.lidet_py_pnq_count())):
        name = C.create_string_buffer(64)
        info = np.zeros(11, np.int32)
        st = L.lidet_py_pnq_info(i, name, info)
        if st < 0:
            raise native.LidetError(st, f"int8 model {name.value.decode()}")
        out[name.value.decode()] = dict(index=i, kind={1: "classifier", 2: "box"}[int(info[0])],
                                        n_points=int(info[1]), n_outputs=int(info[2]), scratch_bytes=int(info[3]),
                                        n_stages=int(info[4]), n_heading_bins=int(info[5]),
                                        n_size_clusters=int(info[6]), energy_t_q16=int(info[7]),
                                        gamma_q16=info[8:11].copy())
    return out


def _pnq(model) -> dict:
    ms = pnq_models()
    if model not in ms:
        raise KeyError(f"int8 model {model!r} is not compiled into the bindings (have: {sorted(ms)})")
    return ms[model]


def _qbatch(xyz_4mm, mean_4mm, voxel, n_points):
    xyz = np.ascontiguousarray(xyz_4mm, np.int16)
    if xyz.ndim != 3 or xyz.shape[1:] != (n_points, 3):
        raise ValueError(f"proposal points must be (B, {n_points}, 3), got {xyz.shape}")
    b = xyz.shape[0]
    return (xyz, np.ascontiguousarray(mean_4mm, np.int32).reshape(b, 3),
            np.ascontiguousarray(voxel, np.int16).reshape(b, 3), b)


def pnq_forward(model: str, points_mm, voxel, cls=None) -> np.ndarray:
    """lidet_pointnet_q_forward on a batch of model-frame points (B, N, 3) int16 mm: (B, n_outputs) Q16."""
    m = _pnq(model)
    pts = np.ascontiguousarray(points_mm, np.int16)
    b = pts.shape[0]
    vox = np.ascontiguousarray(voxel, np.int16).reshape(b, 3)
    c = None if cls is None else np.ascontiguousarray(np.broadcast_to(np.asarray(cls, np.uint8), (b,)))
    out = np.zeros((b, m["n_outputs"]), np.int32)
    if b:
        st = _pnq_lib().lidet_py_pnq_forward(m["index"], b, m["n_points"], pts, vox, c, out)
        if st < 0:
            raise native.LidetError(st, "lidet_pointnet_q_forward")
    return out


def pnq_classify(model: str, xyz_4mm, mean_4mm, voxel) -> dict:
    """lidet_pointnet_q_classify on a batch of integer proposals: logits (Q16), prob (Q15), energy (Q16), cls,
    passed."""
    m = _pnq(model)
    xyz, mean, vox, b = _qbatch(xyz_4mm, mean_4mm, voxel, m["n_points"])
    lo, pr = np.zeros((b, 3), np.int32), np.zeros((b, 3), np.int32)
    en, cl, ps = np.zeros(b, np.int32), np.zeros(b, np.uint8), np.zeros(b, np.uint8)
    if b:
        st = _pnq_lib().lidet_py_pnq_classify(m["index"], b, m["n_points"], xyz, mean, vox, lo, pr, en, cl, ps)
        if st < 0:
            raise native.LidetError(st, "lidet_pointnet_q_classify")
    return dict(logits=lo, prob=pr, energy=en, cls=cl, passed=ps.astype(bool))


def pnq_box(model: str, xyz_4mm, mean_4mm, voxel, cls) -> dict:
    """lidet_pointnet_q_box on a batch: box (B, 7) cx cy cz l w h (mm) yaw (BAM32), energies (Q16), bins, passed."""
    m = _pnq(model)
    xyz, mean, vox, b = _qbatch(xyz_4mm, mean_4mm, voxel, m["n_points"])
    c = np.ascontiguousarray(np.broadcast_to(np.asarray(cls, np.uint8), (b,)))
    bx, en = np.zeros((b, 7), np.int32), np.zeros((b, 3), np.int32)
    bins, ps = np.zeros((b, 2), np.uint8), np.zeros(b, np.uint8)
    if b:
        st = _pnq_lib().lidet_py_pnq_box(m["index"], b, m["n_points"], xyz, mean, vox, c, bx, en, bins, ps)
        if st < 0:
            raise native.LidetError(st, "lidet_pointnet_q_box")
    return dict(box=bx, energy_heading=en[:, 0], energy_size=en[:, 1], energy=en[:, 2], heading_bin=bins[:, 0],
                size_cluster=bins[:, 1], passed=ps.astype(bool))


def pnq_energy(v_q16, t_q16: int = 65536) -> np.ndarray:
    """lidet_pointnet_q_energy of each row of v (rows, n) Q16."""
    v = np.ascontiguousarray(np.atleast_2d(v_q16), np.int32)
    out = np.zeros(v.shape[0], np.int32)
    _pnq_lib().lidet_py_pnq_energy(v.shape[0], v.shape[1], v, int(t_q16), out)
    return out


def pnq_time(cls_model: str, box_model: str, xyz_4mm, mean_4mm, voxel, repeats: int = 5) -> tuple[float, float]:
    """Seconds per proposal of lidet_pointnet_q_classify and lidet_pointnet_q_box (fastest of `repeats`)."""
    mc, mb = _pnq(cls_model), _pnq(box_model)
    xyz, mean, vox, b = _qbatch(xyz_4mm, mean_4mm, voxel, mc["n_points"])
    ns = np.zeros(2, np.uint64)
    st = _pnq_lib().lidet_py_pnq_time(mc["index"], mb["index"], b, mc["n_points"], xyz, mean, vox, repeats, ns)
    if st < 0:
        raise native.LidetError(st, "lidet_py_pnq_time")
    return float(ns[0]) * 1e-9 / b, float(ns[1]) * 1e-9 / b
