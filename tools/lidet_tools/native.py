# SPDX-License-Identifier: MIT
"""Python bindings over the C library (ctypes + numpy), so tools and training see exactly what the
firmware computes.

The shared library `liblidet_py.so` is built by CMake (ports/python). It is found, in order, at
`$LIDET_LIB`, under `$LIDET_BUILD_DIR/ports/python/`, or under `<repo>/build/ports/python/`
(`make build` puts it there).

Every call works on an explicit scan context: a C object holding one scan's stage states. `project`,
`ground` and `cluster` each run on a fresh one, and what they return keeps it (`Clusters` keeps the
scan it clustered), so `proposals(clusters)` always reads the scan of that `cluster` call, whatever
ran in between. Configurations and statistics cross the boundary as the C structs themselves, by
field name: the layout (names, offsets, sizes) comes from the C side (`lidet_py_field`), and every
default from the C `*_cfg_default` functions.
"""
from __future__ import annotations

import ctypes as C
import os
import pathlib
import weakref
from dataclasses import dataclass, field

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
        V = C.c_void_p  # a scan context, or a struct passed by pointer (numpy record's address)
        _u8p = np.ctypeslib.ndpointer(np.uint8, flags="C_CONTIGUOUS")
        _u16p = np.ctypeslib.ndpointer(np.uint16, flags="C_CONTIGUOUS")
        _i16p = np.ctypeslib.ndpointer(np.int16, flags="C_CONTIGUOUS")
        L.lidet_py_ctx_new.restype = V
        L.lidet_py_ctx_new.argtypes = []
        L.lidet_py_ctx_free.restype = None
        L.lidet_py_ctx_free.argtypes = [V]
        L.lidet_py_field.argtypes = [C.c_uint32, C.POINTER(C.c_char_p), C.POINTER(C.c_uint32),
                                     C.POINTER(C.c_char_p), C.POINTER(C.c_uint32), C.POINTER(C.c_uint32),
                                     C.POINTER(C.c_char)]
        for f in ("lidet_py_proj_default", "lidet_py_proposal_default"):
            getattr(L, f).restype = None
            getattr(L, f).argtypes = [V]
        for f in ("lidet_py_ground_default", "lidet_py_cluster_default"):
            getattr(L, f).restype = None
            getattr(L, f).argtypes = [C.c_uint32, C.c_uint32, C.c_float, V]
        L.lidet_py_proj_init.argtypes = [V, C.c_uint32, C.c_uint32, _opt(_f32p), C.c_float, C.c_float, C.c_float, V]
        L.lidet_py_proj_run.argtypes = [V, _opt(_f32p), C.c_uint32, C.c_uint32, _opt(_u16p),
                                        _opt(_f32p), _opt(_i32p), _opt(_i32p), V, _opt(_f32p)]
        L.lidet_py_proj_copy.argtypes = [V, _opt(_f32p), _opt(_i32p), _opt(_i32p), V, _opt(_f32p)]
        L.lidet_py_ground_run.argtypes = [V, V, _opt(_u8p), _opt(_u8p), _opt(_u8p), _opt(_f32p), _opt(_u8p), V]
        L.lidet_py_ground_fit_plane.argtypes = [_f32p, _f32p, _f32p, C.c_uint32, _f32p, _opt(_f32p)]
        L.lidet_py_cluster_run.argtypes = [V, _opt(_f32p), C.c_uint32, C.c_uint32, _opt(_u8p), _opt(_f32p),
                                           C.c_uint32, V, _opt(_u32p), _opt(_u16p), _opt(_i32p),
                                           _opt(_u32p), _opt(_f32p), C.c_uint32, _opt(_u32p), V]
        L.lidet_py_proposals.argtypes = [V, V, C.c_uint32, _f32p, _f32p, _i16p, _u32p]
        L.lidet_py_proposal_indices.argtypes = [C.c_uint32, C.c_uint32, C.c_uint32, _u32p]
        L.lidet_py_ctx_pixel_model.argtypes = [V, C.c_int, C.c_float]
        _lib = L
    return _lib


_layouts: dict | None = None
_KIND = {("f", 4): "<f4", ("u", 1): "u1", ("u", 2): "<u2", ("u", 4): "<u4", ("i", 1): "i1", ("i", 2): "<i2",
         ("i", 4): "<i4"}


def struct_layouts() -> dict:
    """C struct name -> numpy structured dtype with the C field names, offsets and total size (from the
    C side's offsetof table, so it follows the header: nothing is kept in step by hand)."""
    global _layouts
    if _layouts is None:
        fields: dict = {}
        i = 0
        while True:
            t, f = C.c_char_p(), C.c_char_p()
            tsize, off, size, kind = C.c_uint32(), C.c_uint32(), C.c_uint32(), C.c_char()
            if lib().lidet_py_field(i, C.byref(t), C.byref(tsize), C.byref(f), C.byref(off), C.byref(size),
                                    C.byref(kind)) != 0:
                break
            ent = fields.setdefault(t.value.decode(), {"names": [], "formats": [], "offsets": [],
                                                      "itemsize": int(tsize.value)})
            ent["names"].append(f.value.decode())
            ent["formats"].append(_KIND[(kind.value.decode(), int(size.value))])
            ent["offsets"].append(int(off.value))
            i += 1
        _layouts = {k: np.dtype(v) for k, v in fields.items()}
    return _layouts


def _record(type_name: str, values: dict | None = None) -> np.ndarray:
    """A zeroed C struct (numpy record, shape (1,)) with `values` set by field name."""
    dt = struct_layouts()[type_name]
    rec = np.zeros(1, dt)
    for k, v in (values or {}).items():
        if k not in dt.names:
            raise TypeError(f"{type_name} has no field {k!r}")
        rec[k] = v
    return rec


def _to_dict(rec: np.ndarray) -> dict:
    return {k: (float(rec[k][0]) if rec.dtype[k].kind == "f" else int(rec[k][0])) for k in rec.dtype.names}


def _addr(rec: np.ndarray) -> int:
    return rec.ctypes.data


#: pixel models of lidet_py_ctx_pixel_model (what a more compact pixel would hand the stages)
PIXEL_MODELS = {"float": 0, "s16": 1, "recompute": 2, "real_elev": 3, "real_azimuth": 4}


class ScanContext:
    """One scan's C states (lidet_py_ctx_t): the projection, ground and clustering of that scan only.
    Freed when the last object referring to it goes away.

    pixel_model (measurement only, docs/MEMORY.md): after each projection the image is rewritten as a
    pixel stored another way would decode: "float" (the library), "s16" (x, y, z, range rounded to
    multiples of q_m), "recompute" (x, y, z from the range, the beam's elevation and the column
    centre), "real_elev" / "real_azimuth" (one of the two angles kept exact)."""

    def __init__(self, pixel_model: str = "float", q_m: float = 0.004):
        self.ptr = lib().lidet_py_ctx_new()
        if not self.ptr:
            raise MemoryError("lidet_py_ctx_new")
        weakref.finalize(self, lib().lidet_py_ctx_free, self.ptr)
        if pixel_model != "float":
            st = lib().lidet_py_ctx_pixel_model(self.ptr, PIXEL_MODELS[pixel_model], q_m)
            if st < 0:
                raise LidetError(st, "lidet_py_ctx_pixel_model")


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



def _as_points(points) -> tuple[np.ndarray, int]:
    pts = np.ascontiguousarray(points, dtype=np.float32)
    if pts.ndim != 2 or pts.shape[1] < 3:
        raise ValueError(f"points must be (N, >=3) float32, got shape {pts.shape}")
    return pts, pts.shape[1]


def proj_defaults() -> dict:
    """lidet_proj_cfg_default's tunables (min_range_m, max_range_m, fov_margin_rad), from C."""
    rec = _record("lidet_proj_cfg_t")
    lib().lidet_py_proj_default(_addr(rec))
    return _to_dict(rec)


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
    st = lib().lidet_py_proj_init(ctx.ptr, s.rows, s.cols, elev, 0.0, 0.0, s.mount_height_m,
                                  _addr(_record("lidet_proj_cfg_t", full)))
    if st < 0:
        raise LidetError(st, "lidet_proj_init")
    return s, ctx


def _copy_image(ctx: ScanContext, s: Sensor, n: int, status: int) -> RangeImage:
    """The range image held by a context (copied out)."""
    rows, cols = s.rows, s.cols
    img = np.zeros((5, rows, cols), np.float32)
    idx = np.zeros((rows, cols), np.int32)
    stats = _record("lidet_proj_stats_t")
    row_elev = np.zeros(rows, np.float32)
    pp = np.full(n, -1, np.int32)
    st = lib().lidet_py_proj_copy(ctx.ptr, img, idx, pp[: min(n, capacity()["max_points"])] if n else None,
                                  _addr(stats), row_elev)
    if st < 0:
        raise LidetError(st, "lidet_py_proj_copy")
    return RangeImage(img[0], img[1], img[2], img[3], img[4], idx, pp, row_elev, _to_dict(stats), status)


def _project_into(ctx: ScanContext, s: Sensor, points, ring=None) -> RangeImage:
    pts, stride = _as_points(points)
    n = len(pts)
    rg = None
    if ring is not None:
        rg = np.ascontiguousarray(ring, dtype=np.uint16)
        if rg.shape != (n,):
            raise ValueError(f"ring must have one entry per point ({n}), got {rg.shape}")
    st = lib().lidet_py_proj_run(ctx.ptr, pts if n else None, n, stride, rg, None, None, None, None, None)
    if st < 0:
        raise LidetError(st, "lidet_proj_run")
    return _copy_image(ctx, s, n, int(st))


def project(points, sensor: str | Sensor = "hdl64", ring=None, **cfg) -> RangeImage:
    """Project (N, >=3) points (x, y, z first) with the C library, on a scan context of its own.
    `ring`: optional (N,) uint16. cfg: fields of lidet_proj_cfg_t."""
    s, ctx = proj_init(sensor, **cfg)
    return _project_into(ctx, s, points, ring)


# --------------------------------------------------------------------------------------------
# Ground stage (lidet_ground.h)

PLANE_SOURCE = {0: "fitted", 1: "neighbour", 2: "mount", 3: "near"}


def ground_defaults(sensor: str | Sensor = "hdl64") -> dict:
    """lidet_ground_cfg_default for a preset name or a `Sensor` (as a dict of field -> value), from C."""
    s = get_sensor(sensor) if isinstance(sensor, str) else sensor
    rec = _record("lidet_ground_cfg_t")
    lib().lidet_py_ground_default(s.rows, s.cols, s.mount_height_m, _addr(rec))
    return _to_dict(rec)


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


def ground(points, sensor: str | Sensor = "hdl64", ring=None, proj_cfg: dict | None = None,
           context: ScanContext | None = None, **cfg) -> GroundResult:
    """Project (N, >=3) points with the C projection, then segment the ground with the C ground stage,
    on a scan context of its own. `cfg` overrides fields of lidet_ground_cfg_default(sensor) (names as in
    lidet_ground_cfg_t). context: a fresh ScanContext to run on (e.g. with a pixel model); default a new one."""
    s, ctx = proj_init(sensor, ctx=context, **(proj_cfg or {}))
    full = ground_defaults(s)
    unknown = set(cfg) - set(full)
    if unknown:
        raise TypeError(f"unknown ground config field(s): {sorted(unknown)}")
    full.update(cfg)
    img = _project_into(ctx, s, points, ring)
    n = len(img.point_pixel)
    rows, cols = img.shape
    ns = int(full["n_sectors"])
    mp = np.zeros((rows, cols), np.uint8)
    sp = np.zeros((rows, cols), np.uint8)
    mpt = np.zeros(n, np.uint8)
    planes = np.zeros((2 * max(ns, 1), 4), np.float32)
    src = np.zeros(2 * max(ns, 1), np.uint8)
    stats = _record("lidet_ground_stats_t")
    cap = capacity()["max_points"]
    st = lib().lidet_py_ground_run(ctx.ptr, _addr(_record("lidet_ground_cfg_t", full)), mp, sp,
                                   mpt[: min(n, cap)] if n else None, planes, src, _addr(stats))
    if st < 0:
        raise LidetError(st, "lidet_ground_run")
    return GroundResult(mpt, mp, planes[:ns], planes[ns:2 * ns], _to_dict(stats), sp, src[:2 * ns], img, int(st))


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

def cluster_defaults(sensor: str | Sensor = "hdl64") -> dict:
    """lidet_cluster_cfg_default for a preset name or a `Sensor` (field -> value), from C."""
    s = get_sensor(sensor) if isinstance(sensor, str) else sensor
    rec = _record("lidet_cluster_cfg_t")
    lib().lidet_py_cluster_default(s.rows, s.cols, s.mount_height_m, _addr(rec))
    return _to_dict(rec)


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
    context: ScanContext | None = field(default=None, repr=False)  #: the scan these clusters belong to

    def __len__(self) -> int:
        return len(self.n_points)


def cluster(points, sensor: str | Sensor = "hdl64", ground=None, planes=None, with_image: bool = False,
            proj_cfg: dict | None = None, context: ScanContext | None = None, **cfg) -> Clusters:
    """Project `points` (N, >=3) and cluster the non-ground pixels with the C library.

    ground: optional (N,) bool/uint8 per point (1 = ground; a pixel is ground when its winning point
    is), e.g. SemanticKITTI ground labels or the ground stage's per-point mask. planes: optional
    (S, 4) (nx, ny, nz, d) per azimuth sector for the height filter (None: flat ground at
    -mount_height_m). cfg: theta_rad, max_steps, bridge_occluders, diagonals, max_gap_m, max_gap_per_m, min_points,
    max_extent_m, max_mean_height_m, mount_height_m, rescue_gap_m, rescue_gap_per_m, rescue_rows, rescue_cols (defaults:
    `cluster_defaults(sensor)`).
    """
    s, ctx = proj_init(sensor, ctx=context, **(proj_cfg or {}))
    c = cluster_defaults(s)
    unknown = set(cfg) - set(c)
    if unknown:
        raise TypeError(f"unknown cluster option(s): {sorted(unknown)}")
    c.update(cfg)
    c["bridge_occluders"] = int(bool(c["bridge_occluders"]))
    c["diagonals"] = int(bool(c["diagonals"]))
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
    pl_out = np.zeros(n, np.uint32)
    pix = np.zeros((rows, cols), np.uint16)
    mem = np.zeros(rows * cols, np.int32)
    ru = np.zeros((cap, 4), np.uint32)
    rf = np.zeros((cap, 10), np.float32)
    nrec = np.zeros(1, np.uint32)
    stats = _record("lidet_cluster_stats_t")
    st = lib().lidet_py_cluster_run(ctx.ptr, pts if n else None, n, stride, gm if n else None, pl,
                                    0 if pl is None else len(pl), _addr(_record("lidet_cluster_cfg_t", c)),
                                    pl_out if n else None, pix, mem, ru, rf, cap, nrec, _addr(stats))
    if st < 0:
        raise LidetError(st, "lidet_cluster_run")
    k = int(nrec[0])
    sd = _to_dict(stats)
    img = _copy_image(ctx, s, n, 0) if with_image else None
    return Clusters(pl_out, pix, mem[: sd["n_pixels_kept"]].copy(), ru[:k, 0].copy(), ru[:k, 1].copy(),
                    ru[:k, 2].copy(), ru[:k, 3].copy(), rf[:k, 0:3].copy(), rf[:k, 3:6].copy(), rf[:k, 6:9].copy(),
                    rf[:k, 9].copy(), sd, int(st), img, ctx)


@dataclass
class Proposals:
    """What the PointNets see, one row per kept cluster of the last `cluster` call."""
    xyz: np.ndarray    #: (K, n_points, 3) float32, centred on `mean`
    mean: np.ndarray   #: (K, 3) cluster means (sensor frame)
    voxel: np.ndarray  #: (K, 3) int16 azimuth, elevation, range bins of the mean
    n_src: np.ndarray  #: (K,) member pixels per cluster


def proposal_defaults() -> dict:
    """lidet_proposal_cfg_default, from C."""
    rec = _record("lidet_proposal_cfg_t")
    lib().lidet_py_proposal_default(_addr(rec))
    return _to_dict(rec)


def proposals(clusters: Clusters, n_clusters: int | None = None, **cfg) -> Proposals:
    """Proposals of the kept clusters of `clusters` (the result of a `cluster` call), made by
    lidet_proposal_make exactly as the firmware makes them, from that call's own scan (its context):
    later `project`, `ground` or `cluster` calls do not change them. n_clusters: only the first ones
    (default: all). cfg: fields of lidet_proposal_cfg_t (n_points, seed, azimuth_bin_rad,
    elevation_bin_rad, range_bin_m)."""
    if not isinstance(clusters, Clusters) or clusters.context is None:
        raise TypeError("proposals() takes the Clusters returned by cluster() (the scan to read), "
                        "e.g. proposals(c, n_points=64)")
    c = proposal_defaults()
    unknown = set(cfg) - set(c)
    if unknown:
        raise TypeError(f"unknown proposal option(s): {sorted(unknown)}")
    c.update(cfg)
    c["seed"] = int(c["seed"]) & 0xFFFFFFFF
    k = len(clusters) if n_clusters is None else int(n_clusters)
    if not 0 <= k <= len(clusters):
        raise ValueError(f"n_clusters must be in [0, {len(clusters)}], got {k}")
    n = int(c["n_points"])
    xyz = np.zeros((k, n, 3), np.float32)
    mean = np.zeros((k, 3), np.float32)
    vox = np.zeros((k, 3), np.int16)
    nsrc = np.zeros(k, np.uint32)
    if k:
        st = lib().lidet_py_proposals(clusters.context.ptr, _addr(_record("lidet_proposal_cfg_t", c)), k, xyz, mean,
                                      vox, nsrc)
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
