# SPDX-License-Identifier: MIT
"""ctypes bindings of lidet's integer (fixed-point) path: the integer math, stages and PointNets.

Same shared library as lidet_tools.native (liblidet_py.so); kept in its own module so the integer path's
wrappers live apart from the float ones. Each area below configures its own entry points on first use.
"""
from __future__ import annotations

import ctypes as C
from dataclasses import dataclass

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
# ---- integer projection and sensor presets (lib/src/lidet_proj_q.c, lib/src/lidet_sensor_q.c) ---------------

_u16p = np.ctypeslib.ndpointer(np.uint16, flags="C_CONTIGUOUS")
_i16p = np.ctypeslib.ndpointer(np.int16, flags="C_CONTIGUOUS")
_u32p = np.ctypeslib.ndpointer(np.uint32, flags="C_CONTIGUOUS")
_proj_q_ready = False
PROJ_Q_STATS = ("n_points_in", "n_projected", "n_pixels_filled", "n_nonfinite", "n_too_close", "n_too_far",
                "n_out_of_fov", "n_bad_ring", "n_truncated")


def _proj_q_lib():
    global _proj_q_ready
    L = native.lib()
    if not _proj_q_ready:
        L.lidet_py_sensor_q.argtypes = [C.c_uint32, C.c_char_p, _u32p, _i32p, _i32p]
        L.lidet_py_isqrt32.argtypes = [_u32p, C.c_uint32, _i64p]
        L.lidet_py_proj_q.argtypes = [_i32p, native._opt(_i32p), _i32p, native._opt(_i32p), C.c_uint32, C.c_uint32,
                                      native._opt(_u16p), native._opt(_i32p), _i32p, _i16p, _u16p, _u32p, _i32p]
        _proj_q_ready = True
    return L


def sensors_q() -> dict:
    """The C integer presets: name -> dict(rows, cols, elev_urad (ring order, uniform ones expanded),
    fov_urad ((up, down) or None for a table), mount_height_mm, max_range_mm)."""
    L = _proj_q_lib()
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
            raise native.LidetError(st, "lidet_py_sensor_q")
        res[name.value.decode()] = dict(rows=int(rc[0]), cols=int(rc[1]), elev_urad=elev[: rc[0]].copy(),
                                        fov_urad=None if ints[4] else (int(ints[0]), int(ints[1])),
                                        mount_height_mm=int(ints[2]), max_range_mm=int(ints[3]))
        i += 1


def project_q(points_mm, sensor="hdl64", ring=None, min_range_mm: int = 100, max_range_mm: int = 0,
              fov_margin_urad: int = 87266) -> dict:
    """The C integer projection of (N, >=3) int32 mm points (x, y, z first). sensor: a preset name or a
    sensors.Sensor (its integer profile: beam_elev_urad, or fov_urad for a uniform one). Returns the keys of
    lidet_codegen.ref.proj_q.project (point_pixel, point_idx, x_4mm, y_4mm, z_4mm, range_4mm, stats,
    row_elev_bam) and status."""
    from lidet_tools.sensors import get_sensor

    L = _proj_q_lib()
    s = get_sensor(sensor) if isinstance(sensor, str) else sensor
    pts = np.asarray(points_mm)
    if pts.ndim != 2 or not 3 <= pts.shape[1] <= native.MAX_STRIDE or pts.dtype.kind not in "iu":
        raise ValueError(f"points_mm must be integer (N, 3..{native.MAX_STRIDE}), got {pts.dtype} {pts.shape}")
    pts = np.ascontiguousarray(pts, dtype=np.int32)
    n, stride = pts.shape
    npix = s.rows * s.cols
    fov = s.fov_urad if s.fov_urad is not None else (0, 0)
    sens = np.array([s.rows, s.cols, fov[0], fov[1]], np.int32)
    elev = None if s.fov_urad is not None else np.ascontiguousarray(s.beam_elev_urad, dtype=np.int32)
    cfg = np.array([min_range_mm, max_range_mm, fov_margin_urad], np.int32)
    rg = None if ring is None else native._as_per_point(ring, n, "ring", np.uint16, 0, 0xFFFF)
    cap = native.capacity()["max_points"]
    pp = np.full(n, -1, np.int32)
    idx = np.zeros(npix, np.int32)
    xyz = np.zeros(3 * npix, np.int16)
    rng = np.zeros(npix, np.uint16)
    stats = np.zeros(9, np.uint32)
    bam = np.zeros(s.rows, np.int32)
    st = L.lidet_py_proj_q(sens, elev, cfg, pts.ravel() if n else None, n, stride, rg,
                           pp if 0 < n <= cap else None, idx, xyz, rng, stats, bam)
    if st < 0:
        raise native.LidetError(st, "lidet_proj_q")
    return dict(point_pixel=pp, point_idx=idx, x_4mm=xyz[:npix], y_4mm=xyz[npix:2 * npix], z_4mm=xyz[2 * npix:],
                range_4mm=rng, stats=dict(zip(PROJ_Q_STATS, map(int, stats))), row_elev_bam=bam, status=int(st))


def isqrt32(v) -> np.ndarray:
    """lidet__q_isqrt32 (floor sqrt in 32-bit arithmetic) over uint32 values, as int64."""
    a = np.ascontiguousarray(np.asarray(v, dtype=np.int64).astype(np.uint32))
    out = np.zeros(a.shape, np.int64)
    st = _proj_q_lib().lidet_py_isqrt32(a.ravel(), a.size, out.ravel())
    if st != 0:
        raise native.LidetError(st, "lidet_py_isqrt32")
    return out


# ---- ground (lib/src/lidet_ground_q.c, lidet_ground_q_fit.c) ---------------------------------------

_ground_q_ready = False
_i16p = np.ctypeslib.ndpointer(np.int16, flags="C_CONTIGUOUS")
_u16p = np.ctypeslib.ndpointer(np.uint16, flags="C_CONTIGUOUS")
_u8p = np.ctypeslib.ndpointer(np.uint8, flags="C_CONTIGUOUS")
_f32p = np.ctypeslib.ndpointer(np.float32, flags="C_CONTIGUOUS")
_u64p = np.ctypeslib.ndpointer(np.uint64, flags="C_CONTIGUOUS")


def _ground_q_lib():
    global _ground_q_ready
    L = native.lib()
    if not _ground_q_ready:
        V = C.c_void_p
        o = native._opt
        L.lidet_py_ground_q_project.argtypes = [V, _f32p, C.c_uint32, C.c_uint32, _i16p, _i16p, _i16p, _u16p,
                                                o(_i32p), o(_i32p)]
        L.lidet_py_ground_q_field.restype = C.c_char_p
        L.lidet_py_ground_q_field.argtypes = [C.c_uint32]
        L.lidet_py_ground_q_default.argtypes = [C.c_uint32, C.c_int32, _i64p]
        img = [C.c_uint32, C.c_uint32, _i16p, _i16p, _i16p, _u16p]
        L.lidet_py_ground_q_run.argtypes = [_i64p, *img, o(_u8p), o(_u8p), o(_i32p), o(_i64p), o(_u8p), V]
        L.lidet_py_ground_float_compact.argtypes = [V, *img, o(_u8p), o(_u8p), o(_f32p), o(_u8p), V]
        L.lidet_py_ground_q_time.argtypes = [V, _i64p, *img, C.c_uint32, _u64p]
        _ground_q_ready = True
    return L


def ground_q_fields() -> list[str]:
    """Field names of lidet_ground_q_cfg_t, in the order the entry points take them."""
    L = _ground_q_lib()
    out, i = [], 0
    while (name := L.lidet_py_ground_q_field(i)) is not None:
        out.append(name.decode())
        i += 1
    return out


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
    s, ctx = native.proj_init(sensor, **proj_cfg)
    pts, stride = native._as_points(points)
    n = len(pts)
    rows, cols = s.rows, s.cols
    x, y, z = (np.zeros((rows, cols), np.int16) for _ in range(3))
    r = np.zeros((rows, cols), np.uint16)
    pp = np.full(n, -1, np.int32)
    elev = np.zeros(rows, np.int32)
    L = _ground_q_lib()
    st = L.lidet_py_ground_q_project(ctx.ptr, pts if n else np.zeros(3, np.float32), n, stride, x, y, z, r,
                                     pp if n else None, elev)
    if st < 0:
        raise native.LidetError(st, "lidet_proj_run_buffers")
    return CompactImage(x, y, z, r, pp, elev, int(st))


def ground_q_defaults(sensor="hdl64") -> dict:
    """lidet_ground_q_cfg_default for a preset name or a Sensor (field -> int)."""
    s = native.get_sensor(sensor) if isinstance(sensor, str) else sensor
    v = np.zeros(len(ground_q_fields()), np.int64)
    _ground_q_lib().lidet_py_ground_q_default(s.rows, int(round(s.mount_height_m * 1000)), v)
    return dict(zip(ground_q_fields(), (int(a) for a in v)))


def _cfg_vec(cfg: dict) -> np.ndarray:
    names = ground_q_fields()
    unknown = set(cfg) - set(names)
    if unknown:
        raise TypeError(f"unknown ground_q config field(s): {sorted(unknown)}")
    return np.array([int(cfg[k]) for k in names], np.int64)


@dataclass
class GroundQResult:
    mask: np.ndarray     #: (rows, cols) uint8
    sample: np.ndarray   #: (rows, cols) uint8
    planes: np.ndarray   #: (2 ns, 4) int32 nx, ny, nz (Q30), d_4mm; near then far
    plane_d: np.ndarray  #: (2 ns,) int64 D in 4 mm / 2^30
    source: np.ndarray   #: (2 ns,) uint8
    stats: dict
    status: int


def _ground_outputs(img: CompactImage, cfg: dict):
    """rows, cols, n_sectors and zeroed outputs (mask, sample mask, sources, stats record) of a ground run."""
    rows, cols = img.shape
    ns = int(cfg["n_sectors"])
    return (rows, cols, ns, np.zeros((rows, cols), np.uint8), np.zeros((rows, cols), np.uint8),
            np.zeros(2 * ns, np.uint8), native._record("lidet_ground_stats_t"))


def ground_q(img: CompactImage, sensor="hdl64", **cfg) -> GroundQResult:
    """The integer ground stage on a compact image; cfg overrides ground_q_defaults(sensor)."""
    full = ground_q_defaults(sensor)
    full.update(cfg)
    rows, cols, ns, mask, smp, src, stats = _ground_outputs(img, full)
    planes = np.zeros((2 * ns, 4), np.int32)
    pd = np.zeros(2 * ns, np.int64)
    st = _ground_q_lib().lidet_py_ground_q_run(_cfg_vec(full), rows, cols, img.x, img.y, img.z, img.range, mask,
                                               smp, planes, pd, src, native._addr(stats))
    if st < 0:
        raise native.LidetError(st, "lidet_ground_q_run")
    return GroundQResult(mask, smp, planes, pd, src, native._to_dict(stats), int(st))


def ground_float_compact(img: CompactImage, sensor="hdl64", **cfg):
    """The float ground stage on the same compact image: (mask, sample, planes (2 ns, 4) float32, source,
    stats)."""
    full = native.ground_defaults(sensor)
    full.update(cfg)
    rows, cols, ns, mask, smp, src, stats = _ground_outputs(img, full)
    planes = np.zeros((2 * ns, 4), np.float32)
    st = _ground_q_lib().lidet_py_ground_float_compact(native._addr(native._record("lidet_ground_cfg_t", full)),
                                                       rows, cols, img.x, img.y, img.z, img.range, mask, smp,
                                                       planes, src, native._addr(stats))
    if st < 0:
        raise native.LidetError(st, "lidet_ground_run")
    return mask, smp, planes, src, native._to_dict(stats)


def ground_q_time(img: CompactImage, sensor="hdl64", repeats=100) -> tuple[float, float, float, float]:
    """Host timing (ms) of the float and the integer ground stage on one compact image, interleaved: (float median,
    integer median, float minimum, integer minimum)."""
    out = np.zeros(4, np.uint64)
    cf = native._record("lidet_ground_cfg_t", native.ground_defaults(sensor))
    rows, cols = img.shape
    st = _ground_q_lib().lidet_py_ground_q_time(native._addr(cf), _cfg_vec(ground_q_defaults(sensor)), rows, cols,
                                                img.x, img.y, img.z, img.range, repeats, out)
    if st < 0:
        raise native.LidetError(st, "lidet_py_ground_q_time")
    return tuple(float(v) / 1e6 for v in out)


def ground_pair(points, sensor="hdl64"):
    """Both ground stages on one compact image of `points`: (float per-point mask, integer per-point mask, the
    image, the integer result); per-point masks in input order (a point takes its pixel's label, 0 when it has
    none)."""
    img = project_compact(points, sensor)
    q = ground_q(img, sensor)
    fm = ground_float_compact(img, sensor)[0]
    pp = img.point_pixel

    def per_point(mask):
        return np.where(pp >= 0, mask.reshape(-1)[np.clip(pp, 0, None)], 0).astype(np.uint8)
    return per_point(fm), per_point(q.mask), img, q
