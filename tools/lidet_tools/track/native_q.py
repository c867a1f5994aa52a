# SPDX-License-Identifier: MIT
"""ctypes bindings of the integer tracker (lib/src/track/lidet_track_q.c, lidet_track_q.h) in liblidet_py.so
(ports/python/lidet_py_track_q.c), loaded by lidet_tools.native's loader ($LIDET_LIB, $LIDET_BUILD_DIR, build/).

`TrackerQ(**cfg)` takes the float tracker's configuration fields in SI units (meas_sigma_m=..., gate_chi2=...) or
the integer ones (meas_sigma_mm=..., gate_chi2_q16=...), converted by codegen/lidet_ref/track_q.py's
cfg_from. `update` quantises float detections exactly as the detector's integer path has them
(ref.track_q.quantise_dets) and returns TRACK_DTYPE records in SI units; `update_q` takes and returns the raw
integer rows (ref.track_q.TRACK_Q_FIELDS).
"""
from __future__ import annotations

import ctypes as C

import numpy as np

from lidet_ref import track_q as ref
from lidet_tools import native
from lidet_tools.native._lib import i32p as _i32p, i64p as _i64p, opt as _opt, u32p as _u32p

_ready = False

TRACK_DTYPE = ref.TRACK_DTYPE
TRACK_Q_FIELDS = ref.TRACK_Q_FIELDS
STATS = ref.STATS


def _lib():
    global _ready
    L = native.lib()
    if not _ready:
        V = C.c_void_p
        L.lidet_py_track_q_new.restype = V
        L.lidet_py_track_q_new.argtypes = []
        L.lidet_py_track_q_free.restype = None
        L.lidet_py_track_q_free.argtypes = [V]
        L.lidet_py_track_q_capacity.restype = None
        L.lidet_py_track_q_capacity.argtypes = [_u32p]
        L.lidet_py_track_q_cfg_default.argtypes = [_i64p]
        L.lidet_py_track_q_init.argtypes = [V, _i64p, C.c_uint32]
        L.lidet_py_track_q_reset.argtypes = [V]
        L.lidet_py_track_q_update.argtypes = [V, _opt(_i32p), C.c_uint32, C.c_uint32, _opt(_i32p)]
        L.lidet_py_track_q_tracks.argtypes = [V, C.c_uint32, C.c_uint32, _i64p]
        L.lidet_py_track_q_stats.argtypes = [V, _u32p]
        L.lidet_py_track_q_assign.argtypes = [_i32p, C.c_uint32, C.c_uint32, C.c_int32, C.c_uint32, _i32p]
        _ready = True
    return L


def capacity() -> dict:
    """{'max_tracks', 'max_dets', 'bytes'}: LIDET_TRACK_MAX_TRACKS, LIDET_TRACK_MAX_DETS and
    sizeof(lidet_tracker_q_t) of the bindings' build."""
    out = np.zeros(3, np.uint32)
    _lib().lidet_py_track_q_capacity(out)
    return {"max_tracks": int(out[0]), "max_dets": int(out[1]), "bytes": int(out[2])}


def cfg_default_c() -> np.ndarray:
    """lidet_tracker_q_cfg_default as the flat array (ref.track_q.CFG_FIELDS)."""
    out = np.zeros(ref.CFG_LEN, np.int64)
    n = _lib().lidet_py_track_q_cfg_default(out)
    if n != ref.CFG_LEN:
        raise RuntimeError(f"lidet_py_track_q_cfg_default: {n} fields, expected {ref.CFG_LEN}")
    return out


def assign_q(cost, big: int, mode: int = ref.ASSIGN_OPTIMAL) -> np.ndarray:
    """The C assignment alone (lidet__track_q_assign) on an int cost matrix (entries in [0, big]): row -> column,
    -1 for none (or only at cost big). mode: ref.ASSIGN_OPTIMAL or ref.ASSIGN_GREEDY."""
    c = np.ascontiguousarray(cost, dtype=np.int32)
    if c.ndim != 2:
        raise ValueError("cost must be 2-D")
    out = np.zeros(max(c.shape[0], 1), np.int32)
    st = _lib().lidet_py_track_q_assign(c, c.shape[0], c.shape[1], int(big), int(mode), out)
    if st < 0:
        raise native.LidetError(st, "lidet_py_track_q_assign")
    return out[: c.shape[0]].astype(np.int64)


class TrackerQ:
    """lidet_tracker_q_t in C. Configuration overrides by field name (ref.track_q.cfg_from); ValueError when
    lidet_tracker_q_init refuses it."""

    def __init__(self, **cfg_overrides):
        self.cfg = ref.cfg_from(**cfg_overrides)
        self._L = _lib()
        self._t = self._L.lidet_py_track_q_new()
        if not self._t:
            raise MemoryError("lidet_py_track_q_new")
        cap = capacity()
        self.max_tracks, self.max_dets = cap["max_tracks"], cap["max_dets"]
        st = self._L.lidet_py_track_q_init(self._t, ref.cfg_to_array(self.cfg), ref.CFG_LEN)
        if st < 0:
            raise ValueError(f"lidet_tracker_q_init: {native.status_names().get(st, st)}")
        self.status = 0

    def __del__(self):
        t, self._t = getattr(self, "_t", None), None
        if t:
            self._L.lidet_py_track_q_free(t)

    def reset(self) -> None:
        """lidet_tracker_q_reset."""
        st = self._L.lidet_py_track_q_reset(self._t)
        if st < 0:
            raise native.LidetError(st, "lidet_tracker_q_reset")

    def update_q(self, dets_q, dt_ms: int, ego_q=None, flags: int = 0, check: bool = True) -> np.ndarray:
        """lidet_tracker_q_update on int rows (n, 9) (cls, cx_mm, cy_mm, cz_mm, l_mm, w_mm, h_mm, yaw_bam,
        score_q15), dt in ms, ego (dx_mm, dy_mm, dyaw_bam) or None; then lidet_tracker_q_tracks(flags): int64
        rows of TRACK_Q_FIELDS. The status is kept in .status; a negative one raises LidetError when check."""
        d = np.asarray(dets_q, dtype=np.int64).reshape(-1, 9)
        d = np.ascontiguousarray(np.clip(d, -(2**31), 2**31 - 1).astype(np.int32))
        e = None if ego_q is None else np.ascontiguousarray(np.clip(np.asarray(ego_q, np.int64).reshape(3), -(2**31), 2**31 - 1), np.int32)
        st = self._L.lidet_py_track_q_update(self._t, d if len(d) else None, len(d),
                                             int(np.clip(int(dt_ms), 0, 2**32 - 1)), e)
        self.status = int(st)
        if st < 0 and check:
            raise native.LidetError(st, "lidet_tracker_q_update")
        return self.tracks_q(flags)

    def tracks_q(self, flags: int = 0, cap: int | None = None) -> np.ndarray:
        """lidet_tracker_q_tracks: int64 rows of TRACK_Q_FIELDS in id order."""
        cap = self.max_tracks if cap is None else int(cap)
        out = np.zeros((max(cap, 1), len(TRACK_Q_FIELDS)), np.int64)
        n = self._L.lidet_py_track_q_tracks(self._t, cap, int(flags), out)
        if n < 0:
            raise native.LidetError(n, "lidet_tracker_q_tracks")
        return out[:n].copy()

    def update(self, dets, dt_s: float, ego=None, flags: int = 0) -> np.ndarray:
        """One scan of float detections (n, 9): cls, x, y, z, l, w, h (m), yaw (rad), score; dt in seconds; ego
        (dx, dy, dyaw) in m and rad or None. Quantised by ref.track_q (quantise_dets, quantise_dt,
        quantise_ego), run in C; returns TRACK_DTYPE records in SI units."""
        rows = self.update_q(ref.quantise_dets(dets), ref.quantise_dt(dt_s), ref.quantise_ego(ego), flags)
        return ref.tracks_to_si(rows)

    def tracks(self, flags: int = 0) -> np.ndarray:
        """The tracks (TRACK_DTYPE, SI units) of the last update."""
        return ref.tracks_to_si(self.tracks_q(flags))

    def stats(self) -> dict:
        """lidet_tracker_q_stats of the last update."""
        out = np.zeros(len(STATS), np.uint32)
        st = self._L.lidet_py_track_q_stats(self._t, out)
        if st < 0:
            raise native.LidetError(st, "lidet_tracker_q_stats")
        return dict(zip(STATS, map(int, out)))
