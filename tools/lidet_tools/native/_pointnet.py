# SPDX-License-Identifier: MIT
"""PointNets over the models compiled into the bindings (lidet::weights): the float forward pass, classifier and
box net (lib/include/lidet/lidet_pointnet.h) and their int8 twins (lib/src/pointnet/lidet_pointnet_q.c)."""
from __future__ import annotations

import ctypes as C
from dataclasses import dataclass

import numpy as np

from ._lib import LidetError, entry_points, f32p, i16p, i32p, opt, u8p, u32p, u64p


@entry_points
def _pointnet_lib(L):
    L.lidet_py_pn_count.restype = C.c_uint32
    L.lidet_py_pn_info.argtypes = [C.c_uint32, C.c_char_p, u32p, f32p]
    L.lidet_py_pn_forward.argtypes = [C.c_uint32, C.c_uint32, C.c_uint32, f32p, f32p, opt(f32p), f32p]
    L.lidet_py_pn_classify.argtypes = [C.c_uint32, C.c_uint32, C.c_uint32, f32p, f32p, i16p, f32p, f32p, f32p, u8p,
                                       u8p]
    L.lidet_py_pn_box.argtypes = [C.c_uint32, C.c_uint32, C.c_uint32, f32p, f32p, i16p, u8p, f32p, f32p, u8p, u8p]
    L.lidet_py_pn_time.argtypes = [C.c_uint32, C.c_uint32, C.c_uint32, C.c_uint32, f32p, f32p, i16p, C.c_uint32,
                                   u64p]
    L.lidet_py_pnq_count.restype = C.c_uint32
    L.lidet_py_pnq_info.argtypes = [C.c_uint32, C.c_char_p, i32p]
    L.lidet_py_pnq_forward.argtypes = [C.c_uint32, C.c_uint32, C.c_uint32, i16p, i16p, opt(u8p), i32p]
    L.lidet_py_pnq_classify.argtypes = [C.c_uint32, C.c_uint32, C.c_uint32, i16p, i32p, i16p, i32p, i32p, i32p, u8p,
                                        u8p]
    L.lidet_py_pnq_box.argtypes = [C.c_uint32, C.c_uint32, C.c_uint32, i16p, i32p, i16p, u8p, i32p, i32p, u8p, u8p]
    L.lidet_py_pnq_energy.argtypes = [C.c_uint32, C.c_uint32, i32p, C.c_int32, i32p]
    L.lidet_py_pnq_time.argtypes = [C.c_uint32, C.c_uint32, C.c_uint32, C.c_uint32, i16p, i32p, i16p, C.c_uint32,
                                    u64p]


def _lookup(models: dict, model, what: str):
    if model not in models:
        raise KeyError(f"{what} {model!r} is not compiled into the bindings (have: {sorted(models)})")
    return models[model]


def _batch(xyz, mean, voxel, n_points: int, coord, mean_dtype):
    """A batch of proposals as the entry points take it: xyz (B, n_points, 3) of coord, mean (B, 3) of mean_dtype,
    voxel (B, 3) int16, and B."""
    xyz = np.ascontiguousarray(xyz, coord)
    if xyz.ndim != 3 or xyz.shape[1:] != (n_points, 3):
        raise ValueError(f"proposal points must be (B, {n_points}, 3), got {xyz.shape}")
    b = xyz.shape[0]
    mean = np.ascontiguousarray(mean, mean_dtype).reshape(b, 3)
    return xyz, mean, np.ascontiguousarray(voxel, np.int16).reshape(b, 3), b


# ---- float (lib/include/lidet/lidet_pointnet.h) ------------------------------------------------------------

@dataclass
class PnModel:
    """A model compiled into liblidet_py (weights/, lidet::weights)."""
    index: int
    name: str
    kind: str              #: "classifier" or "box"
    n_points: int
    n_outputs: int
    scratch_bytes: int
    n_stages: int
    n_heading_bins: int
    n_size_clusters: int
    gamma: np.ndarray
    energy_t: float
    pvle_bins: np.ndarray
    mean_sizes: np.ndarray


def pn_models() -> dict:
    """name -> PnModel for every model compiled into the bindings."""
    L = _pointnet_lib()
    out = {}
    for i in range(int(L.lidet_py_pn_count())):
        name = C.create_string_buffer(64)
        info = np.zeros(8, np.uint32)
        fl = np.zeros(32, np.float32)
        st = L.lidet_py_pn_info(i, name, info, fl)
        if st < 0:
            raise LidetError(st, f"model {name.value.decode()}")
        ns = int(info[6])
        out[name.value.decode()] = PnModel(i, name.value.decode(), {1: "classifier", 2: "box"}[int(info[0])],
                                           int(info[1]), int(info[2]), int(info[3]), int(info[4]), int(info[5]), ns,
                                           fl[0:3].copy(), float(fl[3]), fl[4:7].copy(), fl[7:7 + 3 * ns].reshape(-1, 3))
    return out


def _pn(model) -> PnModel:
    return model if isinstance(model, PnModel) else _lookup(pn_models(), model, "model")


def pn_forward(model, points, voxel, onehot=None) -> np.ndarray:
    """The raw network (lidet_pn_forward) on model-frame points (B, N, 3), voxel (B, 3) floats and, for a
    box net, onehot (B, 3): (B, n_outputs) = logits, or [T-Net centre (3) | box values]."""
    m = _pn(model)
    pts = np.ascontiguousarray(points, np.float32)
    if pts.ndim != 3 or pts.shape[1:] != (m.n_points, 3):
        raise ValueError(f"points must be (B, {m.n_points}, 3), got {pts.shape}")
    b = pts.shape[0]
    vox = np.ascontiguousarray(voxel, np.float32).reshape(b, 3)
    oh = None
    if m.kind == "box":
        if onehot is None:
            raise ValueError("a box net needs onehot (B, 3)")
        oh = np.ascontiguousarray(onehot, np.float32).reshape(b, 3)
    out = np.zeros((b, m.n_outputs), np.float32)
    if b:
        st = _pointnet_lib().lidet_py_pn_forward(m.index, b, m.n_points, pts, vox, oh, out)
        if st < 0:
            raise LidetError(st, "lidet_pn_forward")
    return out


def pn_classify(model, xyz, mean, voxel) -> dict:
    """lidet_pn_classify on a batch of proposals (xyz (B, N, 3) centred, mean (B, 3), voxel (B, 3) int):
    logits, prob, energy, cls, passed (gate 1)."""
    m = _pn(model)
    xyz, mean, voxel, b = _batch(xyz, mean, voxel, m.n_points, np.float32, np.float32)
    lo, pr = np.zeros((b, 3), np.float32), np.zeros((b, 3), np.float32)
    en, cl, ps = np.zeros(b, np.float32), np.zeros(b, np.uint8), np.zeros(b, np.uint8)
    if b:
        st = _pointnet_lib().lidet_py_pn_classify(m.index, b, m.n_points, xyz, mean, voxel, lo, pr, en, cl, ps)
        if st < 0:
            raise LidetError(st, "lidet_pn_classify")
    return dict(logits=lo, prob=pr, energy=en, cls=cl, passed=ps.astype(bool))


def pn_box(model, xyz, mean, voxel, cls) -> dict:
    """lidet_pn_box on a batch: box (B, 7) cx cy cz l w h yaw (sensor frame), energy_heading, energy_size,
    energy, heading_bin, size_cluster, passed (gate 2)."""
    m = _pn(model)
    xyz, mean, voxel, b = _batch(xyz, mean, voxel, m.n_points, np.float32, np.float32)
    cls = np.ascontiguousarray(np.broadcast_to(np.asarray(cls, np.uint8), (b,)))
    bx, en = np.zeros((b, 7), np.float32), np.zeros((b, 3), np.float32)
    bins, ps = np.zeros((b, 2), np.uint8), np.zeros(b, np.uint8)
    if b:
        st = _pointnet_lib().lidet_py_pn_box(m.index, b, m.n_points, xyz, mean, voxel, cls, bx, en, bins, ps)
        if st < 0:
            raise LidetError(st, "lidet_pn_box")
    return dict(box=bx, energy_heading=en[:, 0], energy_size=en[:, 1], energy=en[:, 2], heading_bin=bins[:, 0],
                size_cluster=bins[:, 1], passed=ps.astype(bool))


def pn_time(cls_model, box_model, xyz, mean, voxel, repeats: int = 5) -> tuple[float, float]:
    """Seconds per proposal of lidet_pn_classify and lidet_pn_box (fastest of `repeats` passes over the batch)."""
    mc, mb = _pn(cls_model), _pn(box_model)
    xyz, mean, voxel, b = _batch(xyz, mean, voxel, mc.n_points, np.float32, np.float32)
    ns = np.zeros(2, np.uint64)
    st = _pointnet_lib().lidet_py_pn_time(mc.index, mb.index, b, mc.n_points, xyz, mean, voxel, repeats, ns)
    if st < 0:
        raise LidetError(st, "lidet_py_pn_time")
    return float(ns[0]) * 1e-9 / b, float(ns[1]) * 1e-9 / b


# ---- int8 (lib/src/pointnet/lidet_pointnet_q.c) ------------------------------------------------------------

def pnq_models() -> dict:
    """name -> dict(index, kind, n_points, n_outputs, scratch_bytes, ...) of every int8 model in the bindings."""
    L = _pointnet_lib()
    out = {}
    for i in range(int(L.lidet_py_pnq_count())):
        name = C.create_string_buffer(64)
        info = np.zeros(11, np.int32)
        st = L.lidet_py_pnq_info(i, name, info)
        if st < 0:
            raise LidetError(st, f"int8 model {name.value.decode()}")
        out[name.value.decode()] = dict(index=i, kind={1: "classifier", 2: "box"}[int(info[0])],
                                        n_points=int(info[1]), n_outputs=int(info[2]), scratch_bytes=int(info[3]),
                                        n_stages=int(info[4]), n_heading_bins=int(info[5]),
                                        n_size_clusters=int(info[6]), energy_t_q16=int(info[7]),
                                        gamma_q16=info[8:11].copy())
    return out


def _pnq(model) -> dict:
    return _lookup(pnq_models(), model, "int8 model")


def pnq_forward(model: str, points_mm, voxel, cls=None) -> np.ndarray:
    """lidet_pointnet_q_forward on a batch of model-frame points (B, N, 3) int16 mm: (B, n_outputs) Q16."""
    m = _pnq(model)
    pts = np.ascontiguousarray(points_mm, np.int16)
    b = pts.shape[0]
    vox = np.ascontiguousarray(voxel, np.int16).reshape(b, 3)
    c = None if cls is None else np.ascontiguousarray(np.broadcast_to(np.asarray(cls, np.uint8), (b,)))
    out = np.zeros((b, m["n_outputs"]), np.int32)
    if b:
        st = _pointnet_lib().lidet_py_pnq_forward(m["index"], b, m["n_points"], pts, vox, c, out)
        if st < 0:
            raise LidetError(st, "lidet_pointnet_q_forward")
    return out


def pnq_classify(model: str, xyz_4mm, mean_4mm, voxel) -> dict:
    """lidet_pointnet_q_classify on a batch of integer proposals: logits (Q16), prob (Q15), energy (Q16), cls,
    passed."""
    m = _pnq(model)
    xyz, mean, vox, b = _batch(xyz_4mm, mean_4mm, voxel, m["n_points"], np.int16, np.int32)
    lo, pr = np.zeros((b, 3), np.int32), np.zeros((b, 3), np.int32)
    en, cl, ps = np.zeros(b, np.int32), np.zeros(b, np.uint8), np.zeros(b, np.uint8)
    if b:
        st = _pointnet_lib().lidet_py_pnq_classify(m["index"], b, m["n_points"], xyz, mean, vox, lo, pr, en, cl, ps)
        if st < 0:
            raise LidetError(st, "lidet_pointnet_q_classify")
    return dict(logits=lo, prob=pr, energy=en, cls=cl, passed=ps.astype(bool))


def pnq_box(model: str, xyz_4mm, mean_4mm, voxel, cls) -> dict:
    """lidet_pointnet_q_box on a batch: box (B, 7) cx cy cz l w h (mm) yaw (BAM32), energies (Q16), bins, passed."""
    m = _pnq(model)
    xyz, mean, vox, b = _batch(xyz_4mm, mean_4mm, voxel, m["n_points"], np.int16, np.int32)
    c = np.ascontiguousarray(np.broadcast_to(np.asarray(cls, np.uint8), (b,)))
    bx, en = np.zeros((b, 7), np.int32), np.zeros((b, 3), np.int32)
    bins, ps = np.zeros((b, 2), np.uint8), np.zeros(b, np.uint8)
    if b:
        st = _pointnet_lib().lidet_py_pnq_box(m["index"], b, m["n_points"], xyz, mean, vox, c, bx, en, bins, ps)
        if st < 0:
            raise LidetError(st, "lidet_pointnet_q_box")
    return dict(box=bx, energy_heading=en[:, 0], energy_size=en[:, 1], energy=en[:, 2], heading_bin=bins[:, 0],
                size_cluster=bins[:, 1], passed=ps.astype(bool))


def pnq_energy(v_q16, t_q16: int = 65536) -> np.ndarray:
    """lidet_pointnet_q_energy of each row of v (rows, n) Q16."""
    v = np.ascontiguousarray(np.atleast_2d(v_q16), np.int32)
    out = np.zeros(v.shape[0], np.int32)
    _pointnet_lib().lidet_py_pnq_energy(v.shape[0], v.shape[1], v, int(t_q16), out)
    return out


def pnq_time(cls_model: str, box_model: str, xyz_4mm, mean_4mm, voxel, repeats: int = 5) -> tuple[float, float]:
    """Seconds per proposal of lidet_pointnet_q_classify and lidet_pointnet_q_box (fastest of `repeats`)."""
    mc, mb = _pnq(cls_model), _pnq(box_model)
    xyz, mean, vox, b = _batch(xyz_4mm, mean_4mm, voxel, mc["n_points"], np.int16, np.int32)
    ns = np.zeros(2, np.uint64)
    st = _pointnet_lib().lidet_py_pnq_time(mc["index"], mb["index"], b, mc["n_points"], xyz, mean, vox, repeats, ns)
    if st < 0:
        raise LidetError(st, "lidet_py_pnq_time")
    return float(ns[0]) * 1e-9 / b, float(ns[1]) * 1e-9 / b
