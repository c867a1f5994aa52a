# SPDX-License-Identifier: MIT
"""ctypes bindings of the tracker (lib/include/lidet/lidet_track.h, docs/TRACKING.md).

`Tracker()` runs the C float tracker (ports/python/lidet_py_track.c) of the same shared library as
lidet_tools.native (liblidet_py.so, found by native.lib()); `Tracker(fixed=True)` the integer one
(lidet_tools.track.native_q.TrackerQ) behind the same interface. The numpy reference of the float tracker is
lidet_ref.track.
"""
from __future__ import annotations

import ctypes as C
import weakref

import numpy as np

from lidet_tools import native
from lidet_tools.native._lib import f32p as _f32p, i32p as _i32p, opt as _opt, u32p as _u32p

#: one record per track, in id order (the integer tracker returns the same fields, converted to SI units)
TRACK_DTYPE = np.dtype([
    ("id", "<u4"), ("cls", "u1"), ("state", "u1"),
    ("x", "<f4"), ("y", "<f4"), ("z", "<f4"), ("l", "<f4"), ("w", "<f4"), ("h", "<f4"), ("yaw", "<f4"),
    ("vx", "<f4"), ("vy", "<f4"), ("p_pp", "<f4"), ("p_pv", "<f4"), ("p_vv", "<f4"), ("score", "<f4"),
    ("hits", "<u4"), ("misses", "<u4"), ("age", "<u4"), ("det", "<i4")])

#: lidet_track_state_t, output flags, lidet_track_assign_t (lidet_track_common.h)
TENTATIVE, CONFIRMED, COASTING = 0, 1, 2
OUT_COASTING, OUT_TENTATIVE = 1, 2
ASSIGN = {"optimal": 0, "greedy": 1}
CLASSES = ("car", "cyclist", "pedestrian")

STATS = ("n_tracks", "n_confirmed", "n_births", "n_births_dropped", "n_deaths", "n_matched", "n_feasible_pairs",
         "n_dets_dropped", "n_bad_dets")

# the flat configuration of lidet_py_track_init: (C field name, floats)
_CFG = (("meas_sigma_m", 3), ("accel_sigma_mps2", 3), ("init_vel_sigma_mps", 3), ("gate_max_m", 3),
        ("gate_chi2", 1), ("class_penalty", 1), ("assign", 1), ("confirm_hits", 1), ("max_misses", 1),
        ("birth_min_score", 1), ("yaw_alpha", 1), ("size_alpha", 1), ("heading_speed_mps", 1),
        ("heading_from_velocity", 1), ("report_misses", 3))
_INT_FIELDS = {"assign", "confirm_hits", "max_misses", "heading_from_velocity", "report_misses"}
# docs/TRACKING.md's names (without the unit suffix) are accepted too
_ALIASES = {"meas_sigma": "meas_sigma_m", "accel_sigma": "accel_sigma_mps2", "init_vel_sigma": "init_vel_sigma_mps",
            "gate_max": "gate_max_m", "heading_speed": "heading_speed_mps"}

_ready = False
_sizes: dict | None = None


def _lib():
    """native.lib() with the tracker's entry points typed (once)."""
    global _ready, _sizes
    L = native.lib()
    if not _ready:
        V = C.c_void_p
        L.lidet_py_track_sizes.restype = None
        L.lidet_py_track_sizes.argtypes = [_u32p]
        L.lidet_py_track_new.restype = V
        L.lidet_py_track_new.argtypes = []
        L.lidet_py_track_free.restype = None
        L.lidet_py_track_free.argtypes = [V]
        L.lidet_py_track_cfg_default.restype = None
        L.lidet_py_track_cfg_default.argtypes = [_f32p]
        L.lidet_py_track_init.argtypes = [V, _f32p]
        L.lidet_py_track_reset.argtypes = [V]
        L.lidet_py_track_update.argtypes = [V, _opt(_f32p), C.c_uint32, C.c_uint32, C.c_float,
                                            _opt(_f32p)]
        L.lidet_py_track_tracks.restype = C.c_uint32
        L.lidet_py_track_tracks.argtypes = [V, _f32p, _i32p, C.c_uint32, C.c_uint32]
        L.lidet_py_track_stats.argtypes = [V, _u32p]
        s = np.zeros(6, np.uint32)
        L.lidet_py_track_sizes(s)
        _sizes = dict(zip(("ncfg", "nf", "ni", "max_tracks", "max_dets", "bytes"), (int(x) for x in s)))
        if _sizes["ncfg"] != sum(n for _, n in _CFG):
            raise RuntimeError("lidet_py_track.c and track/native.py disagree on the configuration layout")
        _ready = True
    return L


def capacity() -> dict:
    """The build's LIDET_TRACK_MAX_TRACKS (max_tracks), LIDET_TRACK_MAX_DETS (max_dets) and
    sizeof(lidet_tracker_t) (bytes)."""
    _lib()
    assert _sizes is not None
    return {k: _sizes[k] for k in ("max_tracks", "max_dets", "bytes")}


def cfg_default() -> dict:
    """lidet_tracker_cfg_default by C field name (per-class fields as lists in lidet_class_t order)."""
    L = _lib()
    assert _sizes is not None
    f = np.zeros(_sizes["ncfg"], np.float32)
    L.lidet_py_track_cfg_default(f)
    out, i = {}, 0
    for name, n in _CFG:
        vals = [float(v) for v in f[i:i + n]]
        out[name] = vals if n > 1 else (int(vals[0]) if name in _INT_FIELDS else vals[0])
        i += n
    return out


def _flat_cfg(overrides: dict) -> tuple[dict, np.ndarray]:
    cfg = cfg_default()
    for key, v in overrides.items():
        name = _ALIASES.get(key, key)
        if name not in cfg:
            raise TypeError(f"unknown tracker setting {key!r} (one of {sorted(cfg)})")
        if name == "assign" and isinstance(v, str):
            if v not in ASSIGN:
                raise ValueError(f"assign: {v!r} is not one of {sorted(ASSIGN)}")
            v = ASSIGN[v]
        if name == "heading_from_velocity" and not np.isscalar(v):
            v = sum(1 << (CLASSES.index(c) if isinstance(c, str) else int(c)) for c in v)
        if isinstance(cfg[name], list):
            arr = np.broadcast_to(np.asarray(v, dtype=np.float64), (3,))
            if name in _INT_FIELDS and not np.all(arr == np.floor(arr)):
                raise ValueError(f"{name}: expected integers, got {v!r}")
            v = [int(x) for x in arr] if name in _INT_FIELDS else [float(x) for x in arr]
        elif name in _INT_FIELDS:
            if isinstance(v, (bool, np.bool_)) or float(v) != int(v):
                raise ValueError(f"{name}: expected an integer, got {v!r}")
            v = int(v)
        else:
            v = float(v)
        cfg[name] = v
    flat = np.concatenate([np.atleast_1d(np.asarray(cfg[n], np.float64)) for n, _ in _CFG]).astype(np.float32)
    return cfg, flat


def _dets(dets) -> np.ndarray:
    d = np.ascontiguousarray(np.asarray(dets, dtype=np.float32))
    if d.size == 0:
        return np.zeros((0, 9), np.float32)
    if d.ndim != 2 or d.shape[1] != 9:
        raise ValueError(f"detections: expected an (n, 9) array (cls, x, y, z, l, w, h, yaw, score), got "
                         f"shape {d.shape}")
    return d


class Tracker:
    """The tracker of docs/TRACKING.md over one sequence of scans.

    Tracker(fixed=False, **cfg): the C float tracker; settings by C field name (meas_sigma_m, gate_chi2, ...,
    or the spec's names meas_sigma, gate_max, heading_speed, ...), per-class ones as a scalar or 3 values
    (car, cyclist, pedestrian); assign "optimal" / "greedy"; heading_from_velocity a bit mask or class names.
    Tracker(fixed=True, **cfg): the integer tracker (lidet_tools.track.native_q.TrackerQ, its own settings).
    Errors of the C library raise native.LidetError.
    """

    def __init__(self, fixed: bool = False, **cfg):
        self.fixed = bool(fixed)
        self._impl = None
        self._t = None
        if self.fixed:
            try:
                from .native_q import TrackerQ
            except ImportError as e:
                raise ImportError("Tracker(fixed=True) needs the integer tracker's bindings "
                                  "(lidet_tools.track.native_q.TrackerQ), which are not available: " + str(e)) from e
            self._impl = TrackerQ(**cfg)
            return
        L = _lib()
        self.cfg, flat = _flat_cfg(cfg)
        t = L.lidet_py_track_new()
        if not t:
            raise MemoryError("lidet_py_track_new")
        self._t = t
        self._finalizer = weakref.finalize(self, L.lidet_py_track_free, t)
        st = L.lidet_py_track_init(t, flat)
        if st < 0:
            raise native.LidetError(st, "lidet_tracker_init")
        self.status = 0

    def update(self, dets, dt_s: float, ego=None, flags: int = 0) -> np.ndarray:
        """One scan: dets an (n, 9) array (cls, x, y, z, l, w, h, yaw, score; sensor frame, metres, radians),
        dt_s the time since the previous scan, ego None or the sensor's motion (dx, dy, dyaw) since it, in the
        previous scan's frame. Returns the tracks (TRACK_DTYPE, id order; coasting and tentative ones as flags
        asks: OUT_COASTING | OUT_TENTATIVE). self.status: 0, or 1 (LIDET_TRUNCATED: see stats())."""
        if self._impl is not None:
            return self._impl.update(dets, dt_s, ego=ego, flags=flags)
        d = _dets(dets)
        e = None
        if ego is not None:
            e = np.ascontiguousarray(np.asarray(ego, dtype=np.float32).reshape(-1))
            if e.shape != (3,):
                raise ValueError("ego: expected (dx, dy, dyaw)")
        st = _lib().lidet_py_track_update(self._t, d if len(d) else None, len(d), 9, float(dt_s), e)
        if st < 0:
            raise native.LidetError(st, "lidet_tracker_update")
        self.status = st
        return self.tracks(flags)

    def tracks(self, flags: int = 0) -> np.ndarray:
        """The tracks after the last update (lidet_tracker_tracks), TRACK_DTYPE in id order."""
        if self._impl is not None:
            return self._impl.tracks(flags)
        L = _lib()
        cap = _sizes["max_tracks"]  # type: ignore[index]
        f = np.zeros((cap, _sizes["nf"]), np.float32)  # type: ignore[index]
        q = np.zeros((cap, _sizes["ni"]), np.int32)  # type: ignore[index]
        n = int(L.lidet_py_track_tracks(self._t, f, q, cap, int(flags)))
        out = np.zeros(n, TRACK_DTYPE)
        for k, name in enumerate(("x", "y", "z", "l", "w", "h", "yaw", "vx", "vy", "p_pp", "p_pv", "p_vv", "score")):
            out[name] = f[:n, k]
        out["id"] = q[:n, 0].view(np.uint32)
        out["cls"] = q[:n, 1]
        out["state"] = q[:n, 2]
        out["hits"] = q[:n, 3].view(np.uint32)
        out["misses"] = q[:n, 4].view(np.uint32)
        out["age"] = q[:n, 5].view(np.uint32)
        out["det"] = q[:n, 6]
        return out

    def reset(self) -> None:
        """Drop every track; ids restart at 1 (the configuration stays)."""
        if self._impl is not None:
            self._impl.reset()
            return
        st = _lib().lidet_py_track_reset(self._t)
        if st < 0:
            raise native.LidetError(st, "lidet_tracker_reset")

    def stats(self) -> dict:
        """The counts of the last update (lidet_tracker_stats_t) by field name."""
        if self._impl is not None:
            return self._impl.stats()
        s = np.zeros(len(STATS), np.uint32)
        _lib().lidet_py_track_stats(self._t, s)
        return {k: int(v) for k, v in zip(STATS, s)}

    def __getattr__(self, name):
        # the integer tracker's own attributes (its configuration, status, ...) through the wrapper
        impl = self.__dict__.get("_impl")
        if impl is not None:
            return getattr(impl, name)
        raise AttributeError(name)
