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
_i16p = np.ctypeslib.ndpointer(np.int16, flags="C_CONTIGUOUS")
_u16p = np.ctypeslib.ndpointer(np.uint16, flags="C_CONTIGUOUS")
_u8p = np.ctypeslib.ndpointer(np.uint8, flags="C_CONTIGUOUS")
_u32p = np.ctypeslib.ndpointer(np.uint32, flags="C_CONTIGUOUS")
_f32p = np.ctypeslib.ndpointer(np.float32, flags="C_CONTIGUOUS")
_u64p = np.ctypeslib.ndpointer(np.uint64, flags="C_CONTIGUOUS")


# ---- integer math (lib/src/qmath/lidet_qmath.c) ------------------------------------------------------

_QMATH_OPS = {"sin": 0, "cos": 1, "atan2": 2, "isqrt": 3, "sqrt_round": 4, "urad_to_bam": 5, "ground_r": 6}
_qmath_ready = False


def qmath(op: str, a, b=None) -> np.ndarray:
    """Evaluate one of lidet's integer math functions in C over arrays (for tests against ref.qmath).

    op: sin / cos (a: BAM32 angles, taken modulo 2^32), atan2 (a = y, b = x, int32), isqrt / sqrt_round (a, b:
    the high and low 32 bits of a uint64), urad_to_bam (a: microradians), ground_r (a: x^2 + y^2 as uint32; the
    ground stage's R, round(256 sqrt(a))). Returns int64.
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


# ---- post-processing: size check, BEV IoU, NMS (lib/src/detector/lidet_post_q.c) -------------------------

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
# ---- integer projection and sensor presets (lib/src/proj/lidet_proj_q.c, lidet_sensor_q.c) --------------------

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
                                      native._opt(_u16p), native._opt(_i32p), _i32p, _i16p, _u16p, _u32p, _i32p, C.c_void_p]
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


RETURN_DTYPE = np.dtype([("range_mm", "<u4"), ("azimuth", "<u2"), ("ring", "<u2")])  # lidet_return_t


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
    from lidet_tools.sensors import get_sensor

    L = _proj_q_lib()
    s = get_sensor(sensor) if isinstance(sensor, str) else sensor
    if returns is not None:
        returns = np.ascontiguousarray(returns, dtype=RETURN_DTYPE)
        points_mm, ring = np.zeros((len(returns), 3), np.int32), None
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
                           pp if 0 < n <= cap else None, idx, xyz, rng, stats, bam,
                           None if returns is None else returns.ctypes.data_as(C.c_void_p))
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


# ---- ground (lib/src/ground/lidet_ground_filter_q.c, lidet_ground_ransac_q.c) ---------------------------------------

_ground_q_ready = False


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
            np.zeros(3 * ns, np.uint8), native._record("lidet_ground_stats_t"))


def ground_q(img: CompactImage, sensor="hdl64", **cfg) -> GroundQResult:
    """The integer ground stage on a compact image; cfg overrides ground_q_defaults(sensor)."""
    full = ground_q_defaults(sensor)
    full.update(cfg)
    rows, cols, ns, mask, smp, src, stats = _ground_outputs(img, full)
    planes = np.zeros((3 * ns, 4), np.int32)
    pd = np.zeros(3 * ns, np.int64)
    st = _ground_q_lib().lidet_py_ground_q_run(_cfg_vec(full), rows, cols, img.x, img.y, img.z, img.range, mask,
                                               smp, planes, pd, src, native._addr(stats))
    if st < 0:
        raise native.LidetError(st, "lidet_ground_q_run")
    nc = (3 if native.far2_on(full) else 2) * ns  # near, far and the third cells' planes when on
    return GroundQResult(mask, smp, planes[:nc], pd[:nc], src[:nc], native._to_dict(stats), int(st))


def ground_float_compact(img: CompactImage, sensor="hdl64", **cfg):
    """The float ground stage on the same compact image: (mask, sample, planes (2 ns, 4) float32, 3 ns with the
    third cells, source, stats)."""
    full = native.ground_defaults(sensor)
    full.update(cfg)
    rows, cols, ns, mask, smp, src, stats = _ground_outputs(img, full)
    planes = np.zeros((3 * ns, 4), np.float32)
    st = _ground_q_lib().lidet_py_ground_float_compact(native._addr(native._record("lidet_ground_cfg_t", full)),
                                                       rows, cols, img.x, img.y, img.z, img.range, mask, smp,
                                                       planes, src, native._addr(stats))
    if st < 0:
        raise native.LidetError(st, "lidet_ground_run")
    nc = (3 if native.far2_on(full) else 2) * ns
    return mask, smp, planes[:nc], src[:nc], native._to_dict(stats)


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


def ground_pair(points, sensor="hdl64", seed_per_cell: int = 0):
    """Both ground stages on one compact image of `points`: (float per-point mask, integer per-point mask, the
    image, the integer result); per-point masks in input order (a point takes its pixel's label, 0 when it has
    none). seed_per_cell: both stages' RANSAC with one stream per cell (as the detectors' crop)."""
    img = project_compact(points, sensor)
    q = ground_q(img, sensor, seed_per_cell=seed_per_cell)
    fm = ground_float_compact(img, sensor, seed_per_cell=seed_per_cell)[0]
    pp = img.point_pixel

    def per_point(mask):
        return np.where(pp >= 0, mask.reshape(-1)[np.clip(pp, 0, None)], 0).astype(np.uint8)
    return per_point(fm), per_point(q.mask), img, q
# ---- integer clustering and proposals (lib/include/lidet/lidet_cluster_q.h) ----------------------------

#: lidet_cluster_q_cfg_t / lidet_proposal_q_cfg_t fields in declaration order (all 32-bit: passed as arrays)
CLUSTER_Q_FIELDS = ["theta_urad", "max_steps", "bridge_occluders", "diagonals", "max_gap_mm", "max_gap_per_m_q16",
                    "min_points", "max_extent_mm", "max_mean_height_mm", "mount_height_mm", "rescue_gap_mm",
                    "rescue_gap_per_m_q16", "rescue_rows", "rescue_cols", "max_fragment_pixels",
                    "max_bridge_per_pixel_q16", "split_people", "split_min_width_mm", "split_cell_mm",
                    "split_cell_per_m_q16", "person_max_width_mm", "person_min_height_mm", "person_min_aspect_q16",
                    "person_min_cols", "person_min_points", "join_cars", "join_gap_mm", "car_max_length_mm", "car_max_width_mm",
                    "car_max_height_mm", "car_min_length_mm", "upright_max_width_mm", "max_join_pieces",
                    "regrow_gap_mm", "regrow_gap_per_m_q16", "regrow_max_pixels", "regrow_max_height_mm",
                    "plane_split_mm"]
PROPOSAL_Q_FIELDS = ["n_points", "seed", "azimuth_bin_bam", "elevation_bin_bam", "range_bin_4mm"]
_cq_ready = False


def _cq_lib():
    global _cq_ready
    L = native.lib()
    if not _cq_ready:
        V = C.c_void_p
        i16p = np.ctypeslib.ndpointer(np.int16, flags="C_CONTIGUOUS")
        u16p = np.ctypeslib.ndpointer(np.uint16, flags="C_CONTIGUOUS")
        u8p = np.ctypeslib.ndpointer(np.uint8, flags="C_CONTIGUOUS")
        u32p = np.ctypeslib.ndpointer(np.uint32, flags="C_CONTIGUOUS")
        u64p = np.ctypeslib.ndpointer(np.uint64, flags="C_CONTIGUOUS")
        f32p = np.ctypeslib.ndpointer(np.float32, flags="C_CONTIGUOUS")
        o = native._opt
        L.lidet_py_cluster_q_sizes.restype = None
        L.lidet_py_cluster_q_sizes.argtypes = [u32p]
        L.lidet_py_cluster_q_default.restype = None
        L.lidet_py_cluster_q_default.argtypes = [C.c_uint32, C.c_uint32, _i32p, _i32p]
        L.lidet_py_cq_prepare.argtypes = [C.c_uint32, C.c_uint32, f32p, C.c_float, V, V, f32p, C.c_uint32, C.c_uint32,
                                          i16p, i16p, i16p, u16p, _i32p, f32p, _i32p, u8p, f32p]
        L.lidet_py_cluster_q_run.argtypes = [C.c_uint32, C.c_uint32, i16p, i16p, i16p, u16p, _i32p, o(u8p), o(_i32p),
                                             C.c_uint32, _i32p, _i32p, C.c_uint32, u16p, _i32p, _i32p, u32p, V, i16p,
                                             _i32p, i16p, u64p]
        L.lidet_py_cluster_f_compact.argtypes = [C.c_uint32, C.c_uint32, i16p, i16p, i16p, u16p, f32p, _i32p, o(u8p),
                                                 o(f32p), C.c_uint32, V, V, C.c_uint32, u16p, _i32p, u32p, f32p, u32p,
                                                 V, f32p, f32p, i16p, u64p]
        sizes = np.zeros(4, np.uint32)
        L.lidet_py_cluster_q_sizes(sizes)
        if sizes[0] != 4 * len(CLUSTER_Q_FIELDS) or sizes[1] != 4 * len(PROPOSAL_Q_FIELDS):
            raise RuntimeError(f"lidet_cluster_q_cfg_t / lidet_proposal_q_cfg_t layout changed: {sizes}")
        _cq_ready = True
    return L


def cluster_q_defaults(sensor="hdl64") -> tuple[dict, dict]:
    """(lidet_cluster_q_cfg_default, lidet_proposal_q_cfg_default) for a preset name or a Sensor, from C."""
    s = native.get_sensor(sensor) if isinstance(sensor, str) else sensor
    cq = np.zeros(len(CLUSTER_Q_FIELDS), np.int32)
    pq = np.zeros(len(PROPOSAL_Q_FIELDS), np.int32)
    _cq_lib().lidet_py_cluster_q_default(s.rows, int(round(s.mount_height_m * 1000)), cq, pq)
    return ({k: int(v) for k, v in zip(CLUSTER_Q_FIELDS, cq)},
            {k: int(np.uint32(np.int32(v))) for k, v in zip(PROPOSAL_Q_FIELDS, pq)})


def _cfg_array(fields, defaults: dict, cfg: dict, what: str) -> np.ndarray:
    full = dict(defaults)
    unknown = set(cfg) - set(full)
    if unknown:
        raise TypeError(f"unknown {what} field(s): {sorted(unknown)}")
    full.update(cfg)
    return np.array([np.uint32(int(full[k]) & 0xFFFFFFFF).view(np.int32) for k in fields], np.int32)


@dataclass
class CompactScan:
    """A scan as the integer clustering reads it: the float projection's compact image (4 mm steps) and the
    float ground stage's mask and near planes on it."""
    sensor: object
    x: np.ndarray            #: (rows, cols) int16, 4 mm
    y: np.ndarray
    z: np.ndarray
    range: np.ndarray        #: (rows, cols) uint16, 4 mm; 0 = empty
    row_elev_bam: np.ndarray  #: (rows,) int32
    row_elev_rad: np.ndarray  #: (rows,) float32
    point_pixel: np.ndarray  #: (n,) int32, -1 = not projected
    ground: np.ndarray       #: (rows, cols) uint8
    planes: np.ndarray       #: (n_sectors, 4) float32 (nx, ny, nz, d_m)

    @property
    def shape(self):
        return self.range.shape


def compact_scan(points, sensor="hdl64") -> CompactScan:
    """Project (N, >=3) points into a compact image with the C projection and run the C ground stage on it
    (default configurations), as a detector workspace does."""
    s = native.get_sensor(sensor) if isinstance(sensor, str) else sensor
    pts, stride = native._as_points(points)
    n = len(pts)
    rows, cols = s.rows, s.cols
    gcfg = native.ground_defaults(s)
    ns = int(gcfg["n_sectors"])
    x, y, z = (np.zeros((rows, cols), np.int16) for _ in range(3))
    rng = np.zeros((rows, cols), np.uint16)
    eb = np.zeros(rows, np.int32)
    er = np.zeros(rows, np.float32)
    pp = np.full(max(n, 1), -1, np.int32)
    mask = np.zeros((rows, cols), np.uint8)
    planes = np.zeros((max(ns, 1), 4), np.float32)
    st = _cq_lib().lidet_py_cq_prepare(rows, cols, np.ascontiguousarray(s.beam_elev_rad, np.float32),
                                       s.mount_height_m, native._addr(native._record("lidet_proj_cfg_t",
                                                                                     native.proj_defaults())),
                                       native._addr(native._record("lidet_ground_cfg_t", gcfg)),
                                       pts if n else np.zeros((1, 3), np.float32), n, stride, x, y, z, rng, eb, er,
                                       pp, mask, planes)
    if st < 0:
        raise native.LidetError(st, "lidet_py_cq_prepare")
    return CompactScan(s, x, y, z, rng, eb, er, pp[:n], mask, planes[:ns])


def planes_to_q(planes) -> np.ndarray:
    """Float ground planes (S, 4) (nx, ny, nz, d_m) -> lidet_plane_q_t (S, 4) int32: Q30 normal, d in 4 mm steps
    (rounded), until the integer ground stage produces them."""
    p = np.asarray(planes, np.float64).reshape(-1, 4)
    out = np.empty(p.shape, np.int64)
    out[:, :3] = np.clip(np.round(p[:, :3] * (1 << 30)), -(1 << 31), (1 << 31) - 1)
    out[:, 3] = np.round(p[:, 3] / 0.004)
    return out.astype(np.int32)


@dataclass
class ClustersOnImage:
    """Clusters and proposals of one compact image (integer: 4 mm steps; float: metres)."""
    labels: np.ndarray        #: (rows, cols) uint16 canonical ids
    members: np.ndarray       #: (n_pixels_kept,) int32
    n_points: np.ndarray      #: (K,)
    first_member: np.ndarray
    seed_pixel: np.ndarray
    n_rescued: np.ndarray
    mean: np.ndarray          #: (K, 3)
    min: np.ndarray
    max: np.ndarray
    height: np.ndarray        #: (K,)
    stats: dict
    status: int
    prop_xyz: np.ndarray      #: (K, n_points, 3)
    prop_mean: np.ndarray     #: (K, 3)
    prop_voxel: np.ndarray    #: (K, 3) int16
    run_ns: np.ndarray        #: (repeat,) nanoseconds of each clustering run

    def __len__(self) -> int:
        return len(self.n_points)


def _outputs(rows: int, cols: int, npts: int, coord) -> dict:
    """The arrays a clustering binding fills (capacity-sized; coord: the proposals' and means' dtype)."""
    cap = native.capacity()["max_clusters"]
    return {"lab": np.zeros((rows, cols), np.uint16), "mem": np.zeros(rows * cols, np.int32),
            "nrec": np.zeros(1, np.uint32), "stats": native._record("lidet_cluster_stats_t"),
            "pxyz": np.zeros((cap, npts, 3), np.int16 if coord == np.int32 else coord),
            "pmean": np.zeros((cap, 3), coord), "pvox": np.zeros((cap, 3), np.int16)}


def _result(o: dict, st: int, what: str, ints, floats, ns) -> ClustersOnImage:
    """ClustersOnImage from the filled arrays: ints (K, >= 4) n_points, first_member, seed_pixel, n_rescued;
    floats (K, 10) mean, min, max, height (the same array as ints for the integer stage)."""
    if st < 0:
        raise native.LidetError(st, what)
    k = int(o["nrec"][0])
    sd = native._to_dict(o["stats"])
    i, f = ints[:k], floats[:k]
    return ClustersOnImage(o["lab"], o["mem"][: sd["n_pixels_kept"]].copy(), *(i[:, j].copy() for j in range(4)),
                           f[:, 0:3].copy(), f[:, 3:6].copy(), f[:, 6:9].copy(), f[:, 9].copy(), sd, int(st),
                           o["pxyz"][:k].copy(), o["pmean"][:k].copy(), o["pvox"][:k].copy(), ns)


def cluster_q(scan: CompactScan, planes_q=None, use_ground: bool = True, repeat: int = 1, proposal_cfg=None,
              **cfg) -> ClustersOnImage:
    """lidet_cluster_q_run on a compact scan (planes_q: (S, 4) int32 lidet_plane_q_t, or None: flat ground) and
    lidet_proposal_q_make for every kept cluster. cfg: fields of lidet_cluster_q_cfg_t."""
    L = _cq_lib()
    dc, dp = cluster_q_defaults(scan.sensor)
    c = _cfg_array(CLUSTER_Q_FIELDS, dc, cfg, "lidet_cluster_q_cfg_t")
    p = _cfg_array(PROPOSAL_Q_FIELDS, dp, proposal_cfg or {}, "lidet_proposal_q_cfg_t")
    rows, cols = scan.shape
    cap = native.capacity()["max_clusters"]
    pl = None if planes_q is None else np.ascontiguousarray(planes_q, np.int32).reshape(-1, 4)
    o = _outputs(rows, cols, int(p[0]), np.int32)
    recs = np.zeros((cap, 14), np.int32)
    ns = np.zeros(max(repeat, 1), np.uint64)
    st = L.lidet_py_cluster_q_run(rows, cols, scan.x, scan.y, scan.z, scan.range, scan.row_elev_bam,
                                  scan.ground if use_ground else None, pl,
                                  native.plane_sectors(pl, c[CLUSTER_Q_FIELDS.index("plane_split_mm")] > 0), c, p, repeat,
                                  o["lab"], o["mem"], recs, o["nrec"], native._addr(o["stats"]), o["pxyz"], o["pmean"],
                                  o["pvox"], ns)
    return _result(o, st, "lidet_cluster_q_run", recs, recs[:, 4:14], ns)


def cluster_f_compact(scan: CompactScan, planes=None, use_ground: bool = True, repeat: int = 1,
                      proposal_cfg=None, **cfg) -> ClustersOnImage:
    """The float clustering (lidet_cluster_run_buffers) and proposals on the same compact image.
    planes: (S, 4) float (nx, ny, nz, d_m) or None. cfg: fields of lidet_cluster_cfg_t."""
    L = _cq_lib()
    c = native.cluster_defaults(scan.sensor)
    unknown = set(cfg) - set(c)
    if unknown:
        raise TypeError(f"unknown cluster option(s): {sorted(unknown)}")
    c.update(cfg)
    pc = native.proposal_defaults()
    pc.update(proposal_cfg or {})
    rows, cols = scan.shape
    cap = native.capacity()["max_clusters"]
    pl = None if planes is None else np.ascontiguousarray(planes, np.float32).reshape(-1, 4)
    o = _outputs(rows, cols, int(pc["n_points"]), np.float32)
    ru = np.zeros((cap, 4), np.uint32)
    rf = np.zeros((cap, 10), np.float32)
    ns = np.zeros(max(repeat, 1), np.uint64)
    st = L.lidet_py_cluster_f_compact(rows, cols, scan.x, scan.y, scan.z, scan.range, scan.row_elev_rad,
                                      scan.row_elev_bam, scan.ground if use_ground else None, pl,
                                      native.plane_sectors(pl, c["plane_split_m"] > 0),
                                      native._addr(native._record("lidet_cluster_cfg_t", c)),
                                      native._addr(native._record("lidet_proposal_cfg_t", pc)), repeat, o["lab"],
                                      o["mem"], ru, rf, o["nrec"], native._addr(o["stats"]), o["pxyz"], o["pmean"],
                                      o["pvox"], ns)
    return _result(o, st, "lidet_cluster_run (compact)", ru, rf, ns)

# ---- int8 PointNets (lib/src/pointnet/lidet_pointnet_q.c) over the int8 models of lidet::weights ---------

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


# ---- the integer detector (lib/src/detector/lidet_detector_q.c) ---------------------------------------------

DETQ_STATS = ["n_clusters", "n_out_of_crop", "n_out_of_range", "n_over_budget", "n_classified", "n_gate1_rejected",
              "n_boxed", "n_gate2_rejected", "n_size_rejected", "n_nms_suppressed", "n_over_capacity", "n_detections",
              "n_over_box_budget", "n_too_tall"]
_detq_ready = False


def to_mm(points) -> np.ndarray:
    """(N, >=3) float points in metres -> (N, 3) int32 millimetres, rounded half away from zero (what a driver
    delivering millimetres gives)."""
    p = np.asarray(points, dtype=np.float64)[:, :3]
    return (np.sign(p) * np.floor(np.abs(p) * 1000.0 + 0.5)).astype(np.int32)


def detect_q(points_mm, sensor: str = "hdl64", model: str | None = None, crop_half_bam: int = 0,
             max_range_mm: int = 0, nms_iou_q15: int = 3277, max_proposals: int = 0, gate1: bool = True,
             gate2: bool = True, max_boxes: int = 0, gate1_margin_q16: int = 0, gate2_margin_q16: int = 0,
             range_only: bool | None = None, returns=None) -> dict:
    """lidet_detector_q_run on (N, 3) int32 mm points with the int8 models cls_<model>_s8 / box_<model>_s8
    (returns: a RETURN_DTYPE array instead, lidet_detector_q_run_returns; points_mm is then ignored).
    gate*_margin_q16: the gates' operating points (lidet_detector_q_cfg_t, Q16 nats). range_only: the range-only
    pixel (lidet_detector_q_cfg_t.range_only; None = the build's default).

    Returns {'cls', 'score_q15', 'energy_cls_q16', 'energy_box_q16', 'boxes' (N, 7: cx cy cz l w h mm, yaw BAM32),
    'cluster_id', 'n_points', 'outcome', 'stats', 'status'}."""
    global _detq_ready
    L = native.lib()
    if not _detq_ready:
        u8p = np.ctypeslib.ndpointer(np.uint8, flags="C_CONTIGUOUS")
        u32p = np.ctypeslib.ndpointer(np.uint32, flags="C_CONTIGUOUS")
        L.lidet_py_detq_run.argtypes = [C.c_char_p, C.c_char_p, C.c_char_p, _i32p, _i32p, C.c_uint32, C.c_uint32,
                                        _i32p, u32p, u8p, u32p, u32p, C.c_void_p]
        L.lidet_py_detq_bytes.restype = C.c_uint32
        _detq_ready = True
    if returns is not None:
        returns = np.ascontiguousarray(returns, dtype=RETURN_DTYPE)
        points_mm = np.zeros((len(returns), 3), np.int32)
    pts = np.ascontiguousarray(points_mm, dtype=np.int32)
    if pts.ndim != 2 or pts.shape[1] < 3:
        raise ValueError(f"points_mm must be (N, >=3) int32, got {pts.shape}")
    fam = model or sensor
    cap = native.capacity()
    det = np.zeros((cap["max_detections"], 13), np.int32)
    nd = np.zeros(1, np.uint32)
    oc = np.zeros(cap["max_clusters"], np.uint8)
    nc = np.zeros(1, np.uint32)
    st = np.zeros(len(DETQ_STATS), np.uint32)
    icfg = np.array([crop_half_bam, max_range_mm, nms_iou_q15, max_proposals, int(bool(gate1)), int(bool(gate2)),
                     max_boxes, gate1_margin_q16, gate2_margin_q16, -1 if range_only is None else int(bool(range_only))],
                    np.int32)
    n = len(pts)
    rc = L.lidet_py_detq_run(sensor.encode(), f"cls_{fam}_s8".encode(), f"box_{fam}_s8".encode(), icfg,
                             pts if n else np.zeros((1, 3), np.int32), n, pts.shape[1], det, nd, oc, nc, st,
                             None if returns is None else returns.ctypes.data_as(C.c_void_p))
    if rc < 0:
        raise native.LidetError(rc, "lidet_detector_q")
    d = det[: int(nd[0])]
    return {"cls": d[:, 0].copy(), "score_q15": d[:, 1].copy(), "energy_cls_q16": d[:, 2].copy(),
            "energy_box_q16": d[:, 3].copy(), "boxes": d[:, 4:11].copy(), "cluster_id": d[:, 11].copy(),
            "n_points": d[:, 12].copy(), "outcome": oc[: int(nc[0])].copy(), "stats": dict(zip(DETQ_STATS, map(int, st))),
            "status": int(rc)}


def detector_q_bytes() -> int:
    """sizeof(lidet_detector_q_t) of the bindings' build."""
    L = native.lib()
    L.lidet_py_detq_bytes.restype = C.c_uint32
    return int(L.lidet_py_detq_bytes())


# ---- the detectors' candidate proposals, for the int8 accuracy ablations (ports/python/lidet_py_acc_q.c) ----

_acc_ready = False


def _acc_lib():
    global _acc_ready
    L = native.lib()
    if not _acc_ready:
        L.lidet_py_acc_cands.argtypes = [C.c_char_p, C.c_uint32, C.c_uint32, _f32p, _u32p, _f32p, C.c_uint32,
                                         C.c_uint32, _f32p, _f32p, _i16p, _u32p, _u32p, _u32p]
        L.lidet_py_acc_cands_q.argtypes = [C.c_char_p, C.c_char_p, C.c_char_p, _i32p, _i32p, C.c_uint32, C.c_uint32,
                                           _i16p, _i32p, _i16p, _u32p, _u32p, _u32p]
        L.lidet_py_acc_cand_points.argtypes = [C.c_int, C.c_uint32, _u32p]
        _acc_ready = True
    return L


def candidates_float(points, sensor: str = "hdl64", model: str | None = None, crop_half_rad: float = 0.0,
                     max_range_m: float = 0.0, refine: bool = False) -> dict:
    """The float detector's classified candidates of one scan, nearest first: {'xyz' (K, N, 3) m centred,
    'mean' (K, 3) m, 'voxel' (K, 3), 'cluster_id' (K,), 'n_points' (K,) the cluster's size}: the proposals its
    classifier sees."""
    L = _acc_lib()
    fam = model or sensor
    ms = native.pn_models()
    pts, stride = native._as_points(points)
    n = len(pts)
    cap = native.capacity()["max_clusters"]
    npt = ms[f"cls_{fam}"].n_points
    xyz, mean = np.zeros((cap, npt, 3), np.float32), np.zeros((cap, 3), np.float32)
    vox, cid = np.zeros((cap, 3), np.int16), np.zeros(cap, np.uint32)
    nc, npo = np.zeros(1, np.uint32), np.zeros(1, np.uint32)
    rc = L.lidet_py_acc_cands(sensor.encode(), ms[f"cls_{fam}"].index, ms[f"box_{fam}"].index,
                              np.array([crop_half_rad, max_range_m], np.float32),
                              np.array([0, int(bool(refine))], np.uint32), pts if n else np.zeros((1, 4), np.float32),
                              n, stride, xyz, mean, vox, cid, nc, npo)
    if rc < 0:
        raise native.LidetError(rc, "lidet_py_acc_cands")
    k = int(nc[0])
    return dict(xyz=xyz[:k], mean=mean[:k], voxel=vox[:k], cluster_id=cid[:k], n_points=_cand_points(L, 0, k))


def candidates_q(points_mm, sensor: str = "hdl64", model: str | None = None, crop_half_bam: int = 0,
                 max_range_mm: int = 0) -> dict:
    """The integer detector's classified candidates of one scan (int32 mm points), nearest first: {'xyz'
    (K, N, 3) 4 mm centred, 'mean' (K, 3) 4 mm, 'voxel' (K, 3), 'cluster_id' (K,), 'n_points' (K,)}."""
    L = _acc_lib()
    fam = model or sensor
    pts = np.ascontiguousarray(points_mm, dtype=np.int32)
    n = len(pts)
    cap = native.capacity()["max_clusters"]
    npt = _pnq(f"cls_{fam}_s8")["n_points"]
    xyz, mean = np.zeros((cap, npt, 3), np.int16), np.zeros((cap, 3), np.int32)
    vox, cid = np.zeros((cap, 3), np.int16), np.zeros(cap, np.uint32)
    nc, npo = np.zeros(1, np.uint32), np.zeros(1, np.uint32)
    rc = L.lidet_py_acc_cands_q(sensor.encode(), f"cls_{fam}_s8".encode(), f"box_{fam}_s8".encode(),
                                np.array([crop_half_bam, max_range_mm, 0], np.int32),
                                pts if n else np.zeros((1, 3), np.int32), n, pts.shape[1], xyz, mean, vox, cid, nc, npo)
    if rc < 0:
        raise native.LidetError(rc, "lidet_py_acc_cands_q")
    k = int(nc[0])
    return dict(xyz=xyz[:k], mean=mean[:k], voxel=vox[:k], cluster_id=cid[:k], n_points=_cand_points(L, 1, k))


def _cand_points(L, q: int, k: int) -> np.ndarray:
    """The cluster sizes (points) of the last candidates_float (q 0) / candidates_q (q 1) run's k candidates."""
    out = np.zeros(max(k, 1), np.uint32)
    rc = L.lidet_py_acc_cand_points(int(q), int(k), out)
    if rc < 0:
        raise native.LidetError(rc, "lidet_py_acc_cand_points")
    return out[:k]
