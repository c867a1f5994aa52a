# SPDX-License-Identifier: MIT
"""Python bindings over the C library (ctypes + numpy), so tools and training see exactly what the
firmware computes.

The shared library `liblidet_py.so` is built by CMake (ports/python). It is found, in order, at
`$LIDET_LIB`, under `$LIDET_BUILD_DIR/ports/python/`, or under `<repo>/build/ports/python/`
(`make build` puts it there).

Every function takes numpy arrays and returns numpy arrays; nothing is retained by the C side
between calls except the stage's own workspace (so these calls are not thread-safe).
"""
from __future__ import annotations

import ctypes as C
import os
import pathlib
from dataclasses import dataclass

import numpy as np

from .sensors import Sensor, get_sensor

_ROOT = pathlib.Path(__file__).resolve().parents[2]
_lib = None

STATUS = {0: "LIDET_OK", 1: "LIDET_TRUNCATED", -1: "LIDET_ERR_ARG", -2: "LIDET_ERR_CONFIG",
          -3: "LIDET_ERR_BUFFER", -4: "LIDET_ERR_MODEL", -5: "LIDET_ERR_STATE", -6: "LIDET_ERR_NOT_FOUND"}


class LidetError(RuntimeError):
    """A negative lidet status."""

    def __init__(self, status: int, what: str):
        self.status = status
        super().__init__(f"{what}: {lib().lidet_py_status_str(status).decode()}")


def _find_library() -> pathlib.Path:
    cands = []
    if os.environ.get("LIDET_LIB"):
        cands.append(pathlib.Path(os.environ["LIDET_LIB"]))
    if os.environ.get("LIDET_BUILD_DIR"):
        cands.append(pathlib.Path(os.environ["LIDET_BUILD_DIR"]) / "ports" / "python" / "liblidet_py.so")
    cands.append(_ROOT / "build" / "ports" / "python" / "liblidet_py.so")
    for c in cands:
        if c.exists():
            return c
    raise FileNotFoundError("liblidet_py.so not found (tried: " + ", ".join(map(str, cands)) +
                            "); build it with `make build` or set LIDET_LIB")


_f32p = np.ctypeslib.ndpointer(np.float32, flags="C_CONTIGUOUS")
_i32p = np.ctypeslib.ndpointer(np.int32, flags="C_CONTIGUOUS")
_u32p = np.ctypeslib.ndpointer(np.uint32, flags="C_CONTIGUOUS")


def _opt(ptype):
    """ndpointer that also accepts None (NULL)."""
    class _Opt(ptype):  # type: ignore[misc, valid-type]
        @classmethod
        def from_param(cls, obj):
            return None if obj is None else ptype.from_param(obj)
    return _Opt


def lib():
    """The loaded shared library (loaded once)."""
    global _lib
    if _lib is None:
        L = C.CDLL(str(_find_library()))
        L.lidet_py_status_str.restype = C.c_char_p
        L.lidet_py_status_str.argtypes = [C.c_int]
        L.lidet_py_capacity.argtypes = [_u32p]
        L.lidet_py_sensor.argtypes = [C.c_uint32, C.c_char_p, _u32p, _f32p, C.POINTER(C.c_float)]
        L.lidet_py_proj_init.argtypes = [C.c_uint32, C.c_uint32, _opt(_f32p), C.c_float, C.c_float,
                                         C.c_float, C.c_float, C.c_float, C.c_float]
        L.lidet_py_proj_run.argtypes = [_opt(_f32p), C.c_uint32, C.c_uint32,
                                        _opt(np.ctypeslib.ndpointer(np.uint16, flags="C_CONTIGUOUS")),
                                        _opt(_f32p), _opt(_i32p), _opt(_i32p), _opt(_u32p), _opt(_f32p)]
        _u8p = np.ctypeslib.ndpointer(np.uint8, flags="C_CONTIGUOUS")
        L.lidet_py_ground_default.argtypes = [C.c_uint32, C.c_uint32, C.c_float, _f32p, _u32p]
        L.lidet_py_ground_run.argtypes = [_f32p, _u32p, _opt(_u8p), _opt(_u8p), _opt(_u8p), _opt(_f32p),
                                          _opt(_u8p), _opt(_u32p)]
        L.lidet_py_ground_fit_plane.argtypes = [_f32p, _f32p, _f32p, C.c_uint32, _f32p, _opt(_f32p)]
        _u16p = np.ctypeslib.ndpointer(np.uint16, flags="C_CONTIGUOUS")
        _i16p = np.ctypeslib.ndpointer(np.int16, flags="C_CONTIGUOUS")
        L.lidet_py_cluster_run.argtypes = [_opt(_f32p), C.c_uint32, C.c_uint32, _opt(_u8p), _opt(_f32p),
                                           C.c_uint32, _f32p, _u32p, _opt(_u32p), _opt(_u16p), _opt(_i32p),
                                           _opt(_u32p), _opt(_f32p), C.c_uint32, _opt(_u32p), _opt(_u32p)]
        L.lidet_py_proposals.argtypes = [C.c_uint32, C.c_uint32, C.c_float, C.c_float, C.c_float, C.c_uint32,
                                         _f32p, _f32p, _i16p, _u32p]
        L.lidet_py_proj_copy.argtypes = [_opt(_f32p), _opt(_i32p), _opt(_i32p), _opt(_u32p), _opt(_f32p)]
        L.lidet_py_proposal_indices.argtypes = [C.c_uint32, C.c_uint32, C.c_uint32, _u32p]
        _lib = L
    return _lib


def capacity() -> dict:
    """Compile-time capacities of the built library (lidet_opt.h)."""
    out = np.zeros(6, np.uint32)
    lib().lidet_py_capacity(out)
    keys = ["max_rows", "max_cols", "max_points", "max_clusters", "proposal_points", "max_detections"]
    return dict(zip(keys, map(int, out)))


def c_sensors() -> dict:
    """The C library's presets: name -> (rows, cols, elevations in ring order (rad), mount height)."""
    res = {}
    i = 0
    while True:
        name = C.create_string_buffer(64)
        rc = np.zeros(2, np.uint32)
        elev = np.zeros(256, np.float32)
        mh = C.c_float()
        if lib().lidet_py_sensor(i, name, rc, elev, C.byref(mh)) != 0:
            return res
        res[name.value.decode()] = (int(rc[0]), int(rc[1]), elev[: rc[0]].copy(), float(mh.value))
        i += 1


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


_STAT_KEYS = ["n_points_in", "n_projected", "n_pixels_filled", "n_nonfinite", "n_too_close",
              "n_too_far", "n_out_of_fov", "n_bad_ring", "n_truncated"]


def _as_points(points) -> tuple[np.ndarray, int]:
    pts = np.ascontiguousarray(points, dtype=np.float32)
    if pts.ndim != 2 or pts.shape[1] < 3:
        raise ValueError(f"points must be (N, >=3) float32, got shape {pts.shape}")
    return pts, pts.shape[1]


def proj_init(sensor: str | Sensor = "hdl64", min_range_m: float = 0.1, max_range_m: float = 0.0,
              fov_margin_rad: float = np.radians(5.0)) -> Sensor:
    """Initialise the C projection for a preset name or a `Sensor` (custom table)."""
    s = get_sensor(sensor) if isinstance(sensor, str) else sensor
    elev = np.ascontiguousarray(s.beam_elev_rad, dtype=np.float32)
    st = lib().lidet_py_proj_init(s.rows, s.cols, elev, 0.0, 0.0, s.mount_height_m, min_range_m,
                                  max_range_m, fov_margin_rad)
    if st < 0:
        raise LidetError(st, "lidet_proj_init")
    return s


def project(points, sensor: str | Sensor = "hdl64", ring=None, **cfg) -> RangeImage:
    """Project (N, >=3) points (x, y, z first) with the C library. `ring`: optional (N,) uint16."""
    s = proj_init(sensor, **cfg)
    pts, stride = _as_points(points)
    n = len(pts)
    cap = capacity()["max_points"]
    rows, cols = s.rows, s.cols
    img = np.zeros((5, rows, cols), np.float32)
    idx = np.zeros((rows, cols), np.int32)
    pp = np.full(n, -1, np.int32)
    stats = np.zeros(9, np.uint32)
    row_elev = np.zeros(rows, np.float32)
    rg = None
    if ring is not None:
        rg = np.ascontiguousarray(ring, dtype=np.uint16)
        if rg.shape != (n,):
            raise ValueError(f"ring must have one entry per point ({n}), got {rg.shape}")
    st = lib().lidet_py_proj_run(pts if n else None, n, stride, rg, img, idx, pp[: min(n, cap)] if n else None,
                                 stats, row_elev)
    if st < 0:
        raise LidetError(st, "lidet_proj_run")
    return RangeImage(img[0], img[1], img[2], img[3], img[4], idx, pp, row_elev,
                      dict(zip(_STAT_KEYS, map(int, stats))), int(st))


# --------------------------------------------------------------------------------------------
# Ground stage (lidet_ground.h)

#: float and integer fields of lidet_ground_cfg_t, in the order of ports/python/lidet_py.c
GROUND_F = ["fy_max", "fx_max_m", "gate_above_m", "gate_below_m", "mount_height_m", "inlier_m",
            "max_tilt_rad", "max_height_dev_m", "ground_m", "ground_m_per_m", "below_factor", "confidence", "ring_split_m",
            "veto_slope", "veto_min_dz_m"]
GROUND_U = ["fx_on_z", "require_descending", "height_gate", "n_sectors", "ransac_iters", "eval_samples",
            "min_samples", "min_inliers", "refine_iters", "fallback_sectors", "seed", "sample_step",
            "sample_col_step"]
_GROUND_STATS = ["_unused", "n_samples", "n_samples_dropped", "n_ground", "n_sectors_fitted",
                 "n_sectors_neighbour", "n_sectors_mount", "n_sectors_sparse", "n_sectors_rejected",
                 "n_hypotheses", "n_far_fitted", "n_vetoed"]
PLANE_SOURCE = {0: "fitted", 1: "neighbour", 2: "mount", 3: "near"}


def ground_defaults(sensor: str | Sensor = "hdl64") -> dict:
    """lidet_ground_cfg_default for a preset name or a `Sensor` (as a dict of field -> value)."""
    s = get_sensor(sensor) if isinstance(sensor, str) else sensor
    f = np.zeros(len(GROUND_F), np.float32)
    u = np.zeros(len(GROUND_U), np.uint32)
    lib().lidet_py_ground_default(s.rows, s.cols, s.mount_height_m, f, u)
    out = {k: float(v) for k, v in zip(GROUND_F, f)}
    out.update({k: int(v) for k, v in zip(GROUND_U, u)})
    return out


@dataclass
class GroundResult:
    """Output of `ground`."""
    mask_point: np.ndarray   #: (n,) uint8 per input point, input order: 1 ground, 0 not (or not projected)
    mask_pixel: np.ndarray   #: (rows, cols) uint8 per pixel
    planes: np.ndarray       #: (n_sectors, 4) float32 near planes (nx, ny, nz, d): n.p + d = height above
    planes_far: np.ndarray   #: (n_sectors, 4) far planes (horizontal range >= ring_split_m)
    stats: dict
    sample_pixel: np.ndarray  #: (rows, cols) uint8: pixels that passed the sample filter
    source: np.ndarray        #: (2 * n_sectors,) uint8 near then far: 0 fitted, 1 neighbour, 2 mount, 3 near
    image: RangeImage
    status: int

    def __iter__(self):
        """Unpacks as (mask_point, mask_pixel, planes, stats)."""
        return iter((self.mask_point, self.mask_pixel, self.planes, self.stats))


def ground(points, sensor: str | Sensor = "hdl64", ring=None, proj_cfg: dict | None = None, **cfg) -> GroundResult:
    """Project (N, >=3) points with the C projection, then segment the ground with the C ground stage.
    `cfg` overrides fields of lidet_ground_cfg_default(sensor) (names as in lidet_ground_cfg_t)."""
    s = get_sensor(sensor) if isinstance(sensor, str) else sensor
    full = ground_defaults(s)
    unknown = set(cfg) - set(full)
    if unknown:
        raise TypeError(f"unknown ground config field(s): {sorted(unknown)}")
    full.update(cfg)
    img = project(points, s, ring=ring, **(proj_cfg or {}))
    f = np.array([full[k] for k in GROUND_F], np.float32)
    u = np.array([full[k] for k in GROUND_U], np.uint32)
    n = len(img.point_pixel)
    rows, cols = img.shape
    ns = int(full["n_sectors"])
    mp = np.zeros((rows, cols), np.uint8)
    sp = np.zeros((rows, cols), np.uint8)
    mpt = np.zeros(n, np.uint8)
    planes = np.zeros((2 * max(ns, 1), 4), np.float32)
    src = np.zeros(2 * max(ns, 1), np.uint8)
    stats = np.zeros(len(_GROUND_STATS), np.uint32)
    cap = capacity()["max_points"]
    st = lib().lidet_py_ground_run(f, u, mp, sp, mpt[: min(n, cap)] if n else None, planes, src, stats)
    if st < 0:
        raise LidetError(st, "lidet_ground_run")
    return GroundResult(mpt, mp, planes[:ns], planes[ns:2 * ns], dict(zip(_GROUND_STATS, map(int, stats))), sp,
                        src[:2 * ns], img, int(st))


def ground_fit_plane(xyz) -> tuple[np.ndarray, np.ndarray]:
    """lidet_ground_fit_plane on (N, 3) points: ((nx, ny, nz, d), eigenvalues ascending)."""
    p = np.ascontiguousarray(np.asarray(xyz, np.float32)[:, :3].T)
    plane = np.zeros(4, np.float32)
    eig = np.zeros(3, np.float32)
    st = lib().lidet_py_ground_fit_plane(p[0].copy(), p[1].copy(), p[2].copy(), p.shape[1], plane, eig)
    if st < 0:
        raise LidetError(st, "lidet_ground_fit_plane")
    return plane, eig


# ---- clustering and proposals (lib/include/lidet/lidet_cluster.h) -------------------------------

#: per-profile defaults of lidet_cluster_cfg_default (kept identical by tests/python/test_bindings_cluster.py)
def cluster_defaults(sensor: str | Sensor = "hdl64") -> dict:
    s = get_sensor(sensor) if isinstance(sensor, str) else sensor
    sparse = s.rows <= 16
    return dict(theta_rad=0.12 if sparse else 0.18, max_steps=4 if sparse else 5, bridge_occluders=0 if sparse else 1,
                diagonals=1, max_gap_m=0.7, max_gap_per_m=0.04 if sparse else 0.025, min_points=10, max_extent_m=6.0,
                max_mean_height_m=2.5, mount_height_m=float(s.mount_height_m), rescue_gap_m=0.8,
                rescue_gap_per_m=0.03, rescue_rows=1 if sparse else 2, rescue_cols=6)


_CLUSTER_STAT_KEYS = ["n_candidates", "n_found", "n_dropped_small", "n_dropped_extent", "n_dropped_height",
                      "n_dropped_capacity", "n_kept", "n_pixels_kept", "n_queue_overflow", "n_fragments",
                      "n_rescue_joined", "n_rescue_pixels"]


@dataclass
class Clusters:
    """Output of `cluster`. Ids are canonical (1-based, raster order of first pixel), 0 = none."""
    point_labels: np.ndarray  #: (N,) uint32 cluster id per input point, input order
    pixel_labels: np.ndarray  #: (rows, cols) uint16
    members: np.ndarray       #: (n_pixels_kept,) int32 flat pixels, cluster after cluster, raster order
    n_points: np.ndarray      #: (K,) member pixels per cluster
    first_member: np.ndarray  #: (K,) index into members
    seed_pixel: np.ndarray    #: (K,) first pixel (raster order)
    n_rescued: np.ndarray     #: (K,) member pixels that came from fragments (the rescue pass)
    mean: np.ndarray          #: (K, 3) float32
    min: np.ndarray           #: (K, 3)
    max: np.ndarray           #: (K, 3)
    height: np.ndarray        #: (K,) mean height above the ground plane used by the filter
    stats: dict
    status: int
    image: RangeImage | None = None  #: the projection of the same call (when asked for)

    def __len__(self) -> int:
        return len(self.n_points)


def cluster(points, sensor: str | Sensor = "hdl64", ground=None, planes=None, with_image: bool = False,
            proj_cfg: dict | None = None, **cfg) -> Clusters:
    """Project `points` (N, >=3) and cluster the non-ground pixels with the C library.

    ground: optional (N,) bool/uint8 per point (1 = ground; a pixel is ground when its winning point
    is), e.g. SemanticKITTI ground labels or the ground stage's per-point mask. planes: optional
    (S, 4) (nx, ny, nz, d) per azimuth sector for the height filter (None: flat ground at
    -mount_height_m). cfg: theta_rad, max_steps, bridge_occluders, diagonals, max_gap_m, max_gap_per_m, min_points,
    max_extent_m, max_mean_height_m, mount_height_m, rescue_gap_m, rescue_gap_per_m, rescue_rows, rescue_cols (defaults:
    `cluster_defaults(sensor)`).
    """
    s = proj_init(sensor, **(proj_cfg or {}))
    c = cluster_defaults(s)
    unknown = set(cfg) - set(c)
    if unknown:
        raise TypeError(f"unknown cluster option(s): {sorted(unknown)}")
    c.update(cfg)
    pts, stride = _as_points(points)
    n = len(pts)
    rows, cols = s.rows, s.cols
    cap = capacity()["max_clusters"]
    gm = None
    if ground is not None:
        gm = np.ascontiguousarray(np.asarray(ground).astype(bool), dtype=np.uint8)
        if gm.shape != (n,):
            raise ValueError(f"ground must have one entry per point ({n}), got {gm.shape}")
    pl = None
    if planes is not None:
        pl = np.ascontiguousarray(planes, dtype=np.float32).reshape(-1, 4)
    cfg_f = np.array([c["theta_rad"], c["max_extent_m"], c["max_mean_height_m"], c["mount_height_m"],
                      c["max_gap_m"], c["max_gap_per_m"], c["rescue_gap_m"], c["rescue_gap_per_m"]], np.float32)
    cfg_u = np.array([c["max_steps"], c["min_points"], int(bool(c["bridge_occluders"])), int(bool(c["diagonals"])),
                      c["rescue_rows"], c["rescue_cols"]], np.uint32)
    pl_out = np.zeros(n, np.uint32)
    pix = np.zeros((rows, cols), np.uint16)
    mem = np.zeros(rows * cols, np.int32)
    ru = np.zeros((cap, 4), np.uint32)
    rf = np.zeros((cap, 10), np.float32)
    nrec = np.zeros(1, np.uint32)
    stats = np.zeros(len(_CLUSTER_STAT_KEYS), np.uint32)
    st = lib().lidet_py_cluster_run(pts if n else None, n, stride, gm if n else None, pl,
                                    0 if pl is None else len(pl), cfg_f, cfg_u, pl_out if n else None, pix, mem,
                                    ru, rf, cap, nrec, stats)
    if st < 0:
        raise LidetError(st, "lidet_cluster_run")
    k = int(nrec[0])
    sd = dict(zip(_CLUSTER_STAT_KEYS, map(int, stats)))
    img = None
    if with_image:
        img = _last_image(s, n)
    return Clusters(pl_out, pix, mem[: sd["n_pixels_kept"]].copy(), ru[:k, 0].copy(), ru[:k, 1].copy(),
                    ru[:k, 2].copy(), ru[:k, 3].copy(), rf[:k, 0:3].copy(), rf[:k, 3:6].copy(), rf[:k, 6:9].copy(),
                    rf[:k, 9].copy(), sd, int(st), img)


def _last_image(s: Sensor, n: int) -> RangeImage:
    """The range image of the last projection (re-read from the C state without running again)."""
    rows, cols = s.rows, s.cols
    img = np.zeros((5, rows, cols), np.float32)
    idx = np.zeros((rows, cols), np.int32)
    stats = np.zeros(9, np.uint32)
    row_elev = np.zeros(rows, np.float32)
    pp = np.full(n, -1, np.int32)
    lib().lidet_py_proj_copy(img, idx, pp[: min(n, capacity()["max_points"])] if n else None, stats, row_elev)
    return RangeImage(img[0], img[1], img[2], img[3], img[4], idx, pp, row_elev,
                      dict(zip(_STAT_KEYS, map(int, stats))), 0)


@dataclass
class Proposals:
    """What the PointNets see, one row per kept cluster of the last `cluster` call."""
    xyz: np.ndarray    #: (K, n_points, 3) float32, centred on `mean`
    mean: np.ndarray   #: (K, 3) cluster means (sensor frame)
    voxel: np.ndarray  #: (K, 3) int16 azimuth, elevation, range bins of the mean
    n_src: np.ndarray  #: (K,) member pixels per cluster


def proposal_defaults() -> dict:
    return dict(n_points=min(64, capacity()["proposal_points"]), seed=0x5EED1234,
                azimuth_bin_rad=float(np.float32(np.radians(10.0))),
                elevation_bin_rad=float(np.float32(np.radians(10.0))), range_bin_m=1.0)


def proposals(n_clusters: int | None = None, **cfg) -> Proposals:
    """Proposals of the kept clusters of the last `cluster` call (lidet_proposal_make, exactly as the
    firmware builds them). cfg: n_points, seed, azimuth_bin_rad, elevation_bin_rad, range_bin_m."""
    c = proposal_defaults()
    unknown = set(cfg) - set(c)
    if unknown:
        raise TypeError(f"unknown proposal option(s): {sorted(unknown)}")
    c.update(cfg)
    if n_clusters is None:
        raise ValueError("pass n_clusters=len(clusters) of the last cluster() call")
    k, n = int(n_clusters), int(c["n_points"])
    xyz = np.zeros((k, n, 3), np.float32)
    mean = np.zeros((k, 3), np.float32)
    vox = np.zeros((k, 3), np.int16)
    nsrc = np.zeros(k, np.uint32)
    if k:
        st = lib().lidet_py_proposals(n, int(c["seed"]) & 0xFFFFFFFF, c["azimuth_bin_rad"], c["elevation_bin_rad"],
                                      c["range_bin_m"], k, xyz, mean, vox, nsrc)
        if st < 0:
            raise LidetError(st, "lidet_proposal_make")
    return Proposals(xyz, mean, vox, nsrc)


def proposal_indices(n_src: int, n_out: int, seed: int = 0x5EED1234) -> np.ndarray:
    """The C resampling rule (lidet_proposal_indices): n_out member indices."""
    out = np.zeros(n_out, np.uint32)
    st = lib().lidet_py_proposal_indices(n_src, n_out, seed & 0xFFFFFFFF, out)
    if st < 0:
        raise LidetError(st, "lidet_proposal_indices")
    return out


# ---- PointNets (lib/include/lidet/lidet_pointnet.h) over the models of lidet::weights ---------------

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


def _pn_lib():
    L = lib()
    if not getattr(L, "_pn_ready", False):
        _u8p = np.ctypeslib.ndpointer(np.uint8, flags="C_CONTIGUOUS")
        _i16p = np.ctypeslib.ndpointer(np.int16, flags="C_CONTIGUOUS")
        _u64p = np.ctypeslib.ndpointer(np.uint64, flags="C_CONTIGUOUS")
        L.lidet_py_pn_count.restype = C.c_uint32
        L.lidet_py_pn_info.argtypes = [C.c_uint32, C.c_char_p, _u32p, _f32p]
        L.lidet_py_pn_forward.argtypes = [C.c_uint32, C.c_uint32, C.c_uint32, _f32p, _f32p, _opt(_f32p), _f32p]
        L.lidet_py_pn_classify.argtypes = [C.c_uint32, C.c_uint32, C.c_uint32, _f32p, _f32p, _i16p, _f32p, _f32p,
                                           _f32p, _u8p, _u8p]
        L.lidet_py_pn_box.argtypes = [C.c_uint32, C.c_uint32, C.c_uint32, _f32p, _f32p, _i16p, _u8p, _f32p, _f32p,
                                      _u8p, _u8p]
        L.lidet_py_pn_time.argtypes = [C.c_uint32, C.c_uint32, C.c_uint32, C.c_uint32, _f32p, _f32p, _i16p,
                                       C.c_uint32, _u64p]
        L._pn_ready = True
    return L


def pn_models() -> dict:
    """name -> PnModel for every model compiled into the bindings."""
    L = _pn_lib()
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
    if isinstance(model, PnModel):
        return model
    ms = pn_models()
    if model not in ms:
        raise KeyError(f"model {model!r} is not compiled into the bindings (have: {sorted(ms)})")
    return ms[model]


def _batch_arrays(xyz, mean, voxel, n_points):
    xyz = np.ascontiguousarray(xyz, np.float32)
    if xyz.ndim != 3 or xyz.shape[1:] != (n_points, 3):
        raise ValueError(f"proposal points must be (B, {n_points}, 3), got {xyz.shape}")
    b = xyz.shape[0]
    mean = np.ascontiguousarray(mean, np.float32).reshape(b, 3)
    voxel = np.ascontiguousarray(voxel, np.int16).reshape(b, 3)
    return xyz, mean, voxel, b


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
        st = _pn_lib().lidet_py_pn_forward(m.index, b, m.n_points, pts, vox, oh, out)
        if st < 0:
            raise LidetError(st, "lidet_pn_forward")
    return out


def pn_classify(model, xyz, mean, voxel) -> dict:
    """lidet_pn_classify on a batch of proposals (xyz (B, N, 3) centred, mean (B, 3), voxel (B, 3) int):
    logits, prob, energy, cls, passed (gate 1)."""
    m = _pn(model)
    xyz, mean, voxel, b = _batch_arrays(xyz, mean, voxel, m.n_points)
    lo, pr = np.zeros((b, 3), np.float32), np.zeros((b, 3), np.float32)
    en, cl, ps = np.zeros(b, np.float32), np.zeros(b, np.uint8), np.zeros(b, np.uint8)
    if b:
        st = _pn_lib().lidet_py_pn_classify(m.index, b, m.n_points, xyz, mean, voxel, lo, pr, en, cl, ps)
        if st < 0:
            raise LidetError(st, "lidet_pn_classify")
    return dict(logits=lo, prob=pr, energy=en, cls=cl, passed=ps.astype(bool))


def pn_box(model, xyz, mean, voxel, cls) -> dict:
    """lidet_pn_box on a batch: box (B, 7) cx cy cz l w h yaw (sensor frame), energy_heading, energy_size,
    energy, heading_bin, size_cluster, passed (gate 2)."""
    m = _pn(model)
    xyz, mean, voxel, b = _batch_arrays(xyz, mean, voxel, m.n_points)
    cls = np.ascontiguousarray(np.broadcast_to(np.asarray(cls, np.uint8), (b,)))
    bx, en = np.zeros((b, 7), np.float32), np.zeros((b, 3), np.float32)
    bins, ps = np.zeros((b, 2), np.uint8), np.zeros(b, np.uint8)
    if b:
        st = _pn_lib().lidet_py_pn_box(m.index, b, m.n_points, xyz, mean, voxel, cls, bx, en, bins, ps)
        if st < 0:
            raise LidetError(st, "lidet_pn_box")
    return dict(box=bx, energy_heading=en[:, 0], energy_size=en[:, 1], energy=en[:, 2], heading_bin=bins[:, 0],
                size_cluster=bins[:, 1], passed=ps.astype(bool))


def pn_time(cls_model, box_model, xyz, mean, voxel, repeats: int = 5) -> tuple[float, float]:
    """Seconds per proposal of lidet_pn_classify and lidet_pn_box (fastest of `repeats` passes over the batch)."""
    mc, mb = _pn(cls_model), _pn(box_model)
    xyz, mean, voxel, b = _batch_arrays(xyz, mean, voxel, mc.n_points)
    ns = np.zeros(2, np.uint64)
    st = _pn_lib().lidet_py_pn_time(mc.index, mb.index, b, mc.n_points, xyz, mean, voxel, repeats, ns)
    if st < 0:
        raise LidetError(st, "lidet_py_pn_time")
    return float(ns[0]) * 1e-9 / b, float(ns[1]) * 1e-9 / b
