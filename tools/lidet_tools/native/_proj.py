# SPDX-License-Identifier: MIT
"""Projection and sensor presets (lib/include/lidet/lidet_proj.h, lidet_proj_q.h, lidet_sensor.h,
lidet_sensor_q.h): the float projection on a scan context, its compact path, and the integer projection of
millimetre points or of the sensor's returns."""
from __future__ import annotations

import ctypes as C
from dataclasses import dataclass

import numpy as np

from ..sensors import Sensor, get_sensor
from ._lib import (MAX_STRIDE, LidetError, ScanContext, V, addr, as_per_point, as_points, capacity, entry_points,
                   f32p, i16p, i32p, opt, record, to_dict, u16p, u32p)


@entry_points
def _proj_lib(L):
    L.lidet_py_sensor.argtypes = [C.c_uint32, C.c_char_p, u32p, f32p, C.POINTER(C.c_float)]
    L.lidet_py_proj_default.restype = None
    L.lidet_py_proj_default.argtypes = [V]
    L.lidet_py_proj_init.argtypes = [V, C.c_uint32, C.c_uint32, opt(f32p), C.c_float, C.c_float, C.c_float, V]
    L.lidet_py_proj_run.argtypes = [V, opt(f32p), C.c_uint32, C.c_uint32, opt(u16p), opt(f32p), opt(i32p),
                                    opt(i32p), V, opt(f32p)]
    L.lidet_py_proj_copy.argtypes = [V, opt(f32p), opt(i32p), opt(i32p), V, opt(f32p)]
    L.lidet_py_ground_q_project.argtypes = [V, f32p, C.c_uint32, C.c_uint32, i16p, i16p, i16p, u16p, opt(i32p),
                                            opt(i32p)]
    L.lidet_py_sensor_q.argtypes = [C.c_uint32, C.c_char_p, u32p, i32p, i32p]
    L.lidet_py_proj_q.argtypes = [i32p, opt(i32p), i32p, opt(i32p), C.c_uint32, C.c_uint32, opt(u16p), opt(i32p),
                                  i32p, i16p, u16p, u32p, i32p, V]


# ---- sensor presets ------------------------------------------------------------------------------------------

def c_sensors() -> dict:
    """The C library's presets: name -> (rows, cols, elevations in ring order (rad), mount height)."""
    L = _proj_lib()
    res = {}
    i = 0
    while True:
        name = C.create_string_buffer(64)
        rc = np.zeros(2, np.uint32)
        elev = np.zeros(256, np.float32)
        mh = C.c_float()
        if L.lidet_py_sensor(i, name, rc, elev, C.byref(mh)) != 0:
            return res
        res[name.value.decode()] = (int(rc[0]), int(rc[1]), elev[: rc[0]].copy(), float(mh.value))
        i += 1


def sensors_q() -> dict:
    """The C integer presets: name -> dict(rows, cols, elev_urad (ring order, uniform ones expanded),
    fov_urad ((up, down) or None for a table), mount_height_mm, max_range_mm)."""
    L = _proj_lib()
    res = {}
    i = 0
    while True:
        name = C.create_string_buffer(64)
        rc = np.zeros(2, np.uint32)
        elev = np.zeros(256, np.int32)
        ints = np.zeros(5, np.int32)
        st = L.lidet_py_sensor_q(i, name, rc, elev, ints)
        if st == -6:
            return res
        if st != 0:
            raise LidetError(st, "lidet_py_sensor_q")
        res[name.value.decode()] = dict(rows=int(rc[0]), cols=int(rc[1]), elev_urad=elev[: rc[0]].copy(),
                                        fov_urad=None if ints[4] else (int(ints[0]), int(ints[1])),
                                        mount_height_mm=int(ints[2]), max_range_mm=int(ints[3]))
        i += 1


# ---- the float projection (lidet_proj.h) ---------------------------------------------------------------------

@dataclass
class RangeImage:
    """Output of `project`. Images are (rows, cols); row 0 = top beam."""
    x: np.ndarray
    y: np.ndarray
    z: np.ndarray
    range: np.ndarray
    rxy: np.ndarray
    point_idx: np.ndarray    #: (rows, cols) int32 index of the winning input point, -1 = empty
    point_pixel: np.ndarray  #: (n,) int32 flat pixel of each input point, -1 = not projected
    row_elev: np.ndarray     #: (rows,) beam elevation per row, radians
    stats: dict
    status: int

    @property
    def valid(self) -> np.ndarray:
        return self.point_idx >= 0

    @property
    def shape(self):
        return self.point_idx.shape


def proj_defaults() -> dict:
    """lidet_proj_cfg_default's tunables (min_range_m, max_range_m, fov_margin_rad, azimuth_half_rad), from C."""
    rec = record("lidet_proj_cfg_t")
    _proj_lib().lidet_py_proj_default(addr(rec))
    return to_dict(rec)


def proj_init(sensor: str | Sensor = "hdl64", ctx: ScanContext | None = None, **cfg) -> tuple[Sensor, ScanContext]:
    """Initialise the C projection of a scan context (a new one unless given) for a preset name or a
    `Sensor` (custom table). cfg: fields of lidet_proj_cfg_t (defaults: `proj_defaults()`)."""
    s = get_sensor(sensor) if isinstance(sensor, str) else sensor
    full = proj_defaults()
    unknown = set(cfg) - set(full)
    if unknown:
        raise TypeError(f"unknown projection config field(s): {sorted(unknown)}")
    full.update(cfg)
    ctx = ctx or ScanContext()
    elev = np.ascontiguousarray(s.beam_elev_rad, dtype=np.float32)
    st = _proj_lib().lidet_py_proj_init(ctx.ptr, s.rows, s.cols, elev, 0.0, 0.0, s.mount_height_m,
                                        addr(record("lidet_proj_cfg_t", full)))
    if st < 0:
        raise LidetError(st, "lidet_proj_init")
    return s, ctx


def _copy_image(ctx: ScanContext, s: Sensor, n: int, status: int) -> RangeImage:
    """The range image held by a context (copied out)."""
    rows, cols = s.rows, s.cols
    img = np.zeros((5, rows, cols), np.float32)
    idx = np.zeros((rows, cols), np.int32)
    stats = record("lidet_proj_stats_t")
    row_elev = np.zeros(rows, np.float32)
    pp = np.full(n, -1, np.int32)
    st = _proj_lib().lidet_py_proj_copy(ctx.ptr, img, idx, pp[: min(n, capacity()["max_points"])] if n else None,
                                        addr(stats), row_elev)
    if st < 0:
        raise LidetError(st, "lidet_py_proj_copy")
    return RangeImage(img[0], img[1], img[2], img[3], img[4], idx, pp, row_elev, to_dict(stats), status)


def _project_into(ctx: ScanContext, s: Sensor, points, ring=None) -> RangeImage:
    pts, stride = as_points(points)
    n = len(pts)
    rg = None
    if ring is not None:
        # out-of-range rings (>= rows) are the C side's to count (n_bad_ring); what does not fit the uint16
        # the C function takes, or is not a whole number, is refused here
        rg = as_per_point(ring, n, "ring", np.uint16, 0, 0xFFFF)
    st = _proj_lib().lidet_py_proj_run(ctx.ptr, pts if n else None, n, stride, rg, None, None, None, None, None)
    if st < 0:
        raise LidetError(st, "lidet_proj_run")
    return _copy_image(ctx, s, n, int(st))


def project(points, sensor: str | Sensor = "hdl64", ring=None, **cfg) -> RangeImage:
    """Project (N, >=3) points (x, y, z first) with the C library, on a scan context of its own.
    `ring`: optional (N,) uint16. cfg: fields of lidet_proj_cfg_t."""
    s, ctx = proj_init(sensor, **cfg)
    return _project_into(ctx, s, points, ring)


# ---- the float projection's compact path (as the detector workspace runs it) --------------------------------

@dataclass
class CompactImage:
    """A compact range image (lidet_proj.h): (rows, cols) int16 x, y, z and uint16 range in 4 mm steps."""
    x: np.ndarray
    y: np.ndarray
    z: np.ndarray
    range: np.ndarray
    point_pixel: np.ndarray  #: (n,) int32 pixel of each input point, -1 = none
    row_elev_bam: np.ndarray  #: (rows,) int32
    status: int

    @property
    def shape(self):
        return self.x.shape


def project_compact(points, sensor="hdl64", **proj_cfg) -> CompactImage:
    """Project (N, >=3) float points into a compact image with the float projection's compact path (as the
    detector workspace does)."""
    s, ctx = proj_init(sensor, **proj_cfg)
    pts, stride = as_points(points)
    n = len(pts)
    rows, cols = s.rows, s.cols
    x, y, z = (np.zeros((rows, cols), np.int16) for _ in range(3))
    r = np.zeros((rows, cols), np.uint16)
    pp = np.full(n, -1, np.int32)
    elev = np.zeros(rows, np.int32)
    st = _proj_lib().lidet_py_ground_q_project(ctx.ptr, pts if n else np.zeros(3, np.float32), n, stride, x, y, z,
                                               r, pp if n else None, elev)
    if st < 0:
        raise LidetError(st, "lidet_proj_run_buffers")
    return CompactImage(x, y, z, r, pp, elev, int(st))


# ---- the integer projection (lib/src/proj/lidet_proj_q.c, lidet_sensor_q.c) ----------------------------------

PROJ_Q_STATS = ("n_points_in", "n_projected", "n_pixels_filled", "n_nonfinite", "n_too_close", "n_too_far",
                "n_out_of_fov", "n_bad_ring", "n_truncated")
RETURN_DTYPE = np.dtype([("range_mm", "<u4"), ("azimuth", "<u2"), ("ring", "<u2")])  # lidet_return_t


def to_mm(points) -> np.ndarray:
    """(N, >=3) float points in metres -> (N, 3) int32 millimetres, rounded half away from zero (what a driver
    delivering millimetres gives)."""
    p = np.asarray(points, dtype=np.float64)[:, :3]
    return (np.sign(p) * np.floor(np.abs(p) * 1000.0 + 0.5)).astype(np.int32)


def as_returns(range_mm, azimuth, ring) -> np.ndarray:
    """Three per-return arrays -> the C array of lidet_return_t (range in mm, azimuth in BAM16, ring)."""
    rg = np.asarray(range_mm)
    out = np.zeros(len(rg), RETURN_DTYPE)
    for k, v, hi in (("range_mm", rg, 0xFFFFFFFF), ("azimuth", azimuth, 0xFFFF), ("ring", ring, 0xFFFF)):
        v = np.asarray(v)
        if v.shape != rg.shape or (v.size and (v.min() < 0 or v.max() > hi)):
            raise ValueError(f"{k}: {v.shape} values in [{v.min() if v.size else 0}, {v.max() if v.size else 0}] "
                             f"for {rg.shape} returns (need 0..{hi})")
        out[k] = v
    return out


def project_q(points_mm, sensor="hdl64", ring=None, min_range_mm: int = 100, max_range_mm: int = 0,
              fov_margin_urad: int = 87266, returns=None) -> dict:
    """The C integer projection of (N, >=3) int32 mm points (x, y, z first). sensor: a preset name or a
    sensors.Sensor (its integer profile: beam_elev_urad, or fov_urad for a uniform one). Returns the keys of
    lidet_ref.proj_q.project (point_pixel, point_idx, x_4mm, y_4mm, z_4mm, range_4mm, stats,
    row_elev_bam) and status. returns: a RETURN_DTYPE array (as_returns) instead of the points
    (lidet_proj_q_run_returns; points_mm and ring are then ignored, pass None)."""
    L = _proj_lib()
    s = get_sensor(sensor) if isinstance(sensor, str) else sensor
    if returns is not None:
        returns = np.ascontiguousarray(returns, dtype=RETURN_DTYPE)
        points_mm, ring = np.zeros((len(returns), 3), np.int32), None
    pts = np.asarray(points_mm)
    if pts.ndim != 2 or not 3 <= pts.shape[1] <= MAX_STRIDE or pts.dtype.kind not in "iu":
        raise ValueError(f"points_mm must be integer (N, 3..{MAX_STRIDE}), got {pts.dtype} {pts.shape}")
    pts = np.ascontiguousarray(pts, dtype=np.int32)
    n, stride = pts.shape
    npix = s.rows * s.cols
    fov = s.fov_urad if s.fov_urad is not None else (0, 0)
    sens = np.array([s.rows, s.cols, fov[0], fov[1]], np.int32)
    elev = None if s.fov_urad is not None else np.ascontiguousarray(s.beam_elev_urad, dtype=np.int32)
    cfg = np.array([min_range_mm, max_range_mm, fov_margin_urad], np.int32)
    rg = None if ring is None else as_per_point(ring, n, "ring", np.uint16, 0, 0xFFFF)
    cap = capacity()["max_points"]
    pp = np.full(n, -1, np.int32)
    idx = np.zeros(npix, np.int32)
    xyz = np.zeros(3 * npix, np.int16)
    rng = np.zeros(npix, np.uint16)
    stats = np.zeros(9, np.uint32)
    bam = np.zeros(s.rows, np.int32)
    st = L.lidet_py_proj_q(sens, elev, cfg, pts.ravel() if n else None, n, stride, rg,
                           pp if 0 < n <= cap else None, idx, xyz, rng, stats, bam,
                           None if returns is None else returns.ctypes.data_as(C.c_void_p))
    if st < 0:
        raise LidetError(st, "lidet_proj_q")
    return dict(point_pixel=pp, point_idx=idx, x_4mm=xyz[:npix], y_4mm=xyz[npix:2 * npix], z_4mm=xyz[2 * npix:],
                range_4mm=rng, stats=dict(zip(PROJ_Q_STATS, map(int, stats))), row_elev_bam=bam, status=int(st))
