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

from .sensors import Sensor, get_sensor, model_family

_ROOT = pathlib.Path(__file__).resolve().parents[2]
_lib = None

_status_names: dict | None = None


def status_names() -> dict:
    """{code: name} of every lidet_status_t, read from the C library's lidet_status_str ("NAME: text"), so the
    names are never copied by hand (codes -64..64; "unknown lidet status" marks the unused ones)."""
    global _status_names
    if _status_names is None:
        out = {}
        for code in range(-64, 65):
            txt = lib().lidet_py_status_str(code).decode()
            if txt.startswith("LIDET_") and ":" in txt:
                out[code] = txt.split(":", 1)[0]
        _status_names = out
    return dict(_status_names)


class LidetError(RuntimeError):
    """A negative lidet status."""

    def __init__(self, status: int, what: str):
        self.status = status
        self.name = status_names().get(status, f"status {status}")
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
        rec[k] = _checked(type_name, k, v, dt[k])
    return rec


def _checked(type_name: str, field: str, v, dtype: np.dtype):
    """A value for a C field, refused with a clear message instead of a silent cast: integer fields take
    integers (or integral floats) in range, float fields finite numbers (a NaN or a string would otherwise
    become garbage or undefined behaviour on the C side)."""
    where = f"{type_name}.{field}"
    if isinstance(v, (bool, np.bool_)):
        v = int(v)
    if isinstance(v, (str, bytes)) or not np.isscalar(v) or not isinstance(v, (int, float, np.number)):
        raise TypeError(f"{where}: expected a number, got {v!r}")
    if dtype.kind == "f":
        if not np.isfinite(v):
            raise ValueError(f"{where}: {v!r} is not finite")
        return v
    if not np.isfinite(v) or float(v) != int(v):
        raise ValueError(f"{where}: expected an integer, got {v!r}")
    info = np.iinfo(dtype)
    if not info.min <= int(v) <= info.max:
        raise ValueError(f"{where}: {v!r} outside [{info.min}, {info.max}]")
    return int(v)


def _to_dict(rec: np.ndarray) -> dict:
    return {k: (float(rec[k][0]) if rec.dtype[k].kind == "f" else int(rec[k][0])) for k in rec.dtype.names}


def _addr(rec: np.ndarray) -> int:
    return rec.ctypes.data


#: pixel models of lidet_py_ctx_pixel_model (what a more compact pixel would hand the stages)
PIXEL_MODELS = {"float": 0, "s16": 1, "recompute": 2, "real_elev": 3, "real_azimuth": 4}


class ScanContext:
    """One scan's C states (lidet_py_ctx_t): the projection, ground and clustering of that scan only.
    Freed when the last object referring to it goes away.

    pixel_model (measurement only, docs/journal/memory.md, "What a compact pixel would cost"): after each projection
    the image is rewritten as a
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



#: most floats per point record the bindings accept (x, y, z, remission and a few extra channels)
MAX_STRIDE = 16


def _as_points(points) -> tuple[np.ndarray, int]:
    arr = np.asarray(points)
    if arr.dtype.kind not in "fiu":
        raise TypeError(f"points must be numeric, got dtype {arr.dtype}")
    if arr.ndim != 2 or not 3 <= arr.shape[1] <= MAX_STRIDE:
        hint = " (transposed? points are rows)" if arr.ndim == 2 and 3 <= arr.shape[0] <= MAX_STRIDE else ""
        raise ValueError(f"points must be (N, 3..{MAX_STRIDE}): x, y, z first; got shape {arr.shape}{hint}")
    return np.ascontiguousarray(arr, dtype=np.float32), arr.shape[1]


def _as_per_point(values, n: int, what: str, dtype, lo: int, hi: int) -> np.ndarray:
    """(n,) integer values in [lo, hi]: booleans, integers, or floats that are whole numbers; anything else
    (strings, NaN, 3.7, 65539 for a uint16) is a ValueError, never a silent cast."""
    a = np.asarray(values)
    if a.shape != (n,):
        raise ValueError(f"{what} must have one entry per point ({n}), got shape {a.shape}")
    if a.dtype.kind == "b":
        a = a.astype(np.int64)
    elif a.dtype.kind == "f":
        if not np.all(np.isfinite(a)) or np.any(a != np.round(a)):
            raise ValueError(f"{what}: non-integer or non-finite values")
    elif a.dtype.kind not in "iu":
        raise TypeError(f"{what} must be integers or booleans, got dtype {a.dtype}")
    if n and (a.min() < lo or a.max() > hi):
        raise ValueError(f"{what}: values outside [{lo}, {hi}] (min {a.min()}, max {a.max()})")
    return np.ascontiguousarray(a, dtype=dtype)


def proj_defaults() -> dict:
    """lidet_proj_cfg_default's tunables (min_range_m, max_range_m, fov_margin_rad, azimuth_half_rad), from C."""
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
        # out-of-range rings (>= rows) are the C side's to count (n_bad_ring); what does not fit the uint16
        # the C function takes, or is not a whole number, is refused here
        rg = _as_per_point(ring, n, "ring", np.uint16, 0, 0xFFFF)
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
    source: np.ndarray        #: (2 * n_sectors,) uint8 near then far (3 * n_sectors with the third cells): 0 fitted,
                              #: 1 neighbour, 2 mount, 3 the cell inside it
    image: RangeImage
    status: int
    planes_far2: np.ndarray | None = None  #: (n_sectors, 4) the third cells' planes (far2_split_m), else None

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
    planes = np.zeros((3 * max(ns, 1), 4), np.float32)
    src = np.zeros(3 * max(ns, 1), np.uint8)
    stats = _record("lidet_ground_stats_t")
    cap = capacity()["max_points"]
    st = lib().lidet_py_ground_run(ctx.ptr, _addr(_record("lidet_ground_cfg_t", full)), mp, sp,
                                   mpt[: min(n, cap)] if n else None, planes, src, _addr(stats))
    if st < 0:
        raise LidetError(st, "lidet_ground_run")
    three = far2_on(full)
    return GroundResult(mpt, mp, planes[:ns], planes[ns:2 * ns], _to_dict(stats), sp, src[:(3 if three else 2) * ns], img,
                        int(st), planes[2 * ns:3 * ns] if three else None)


def far2_on(cfg: dict) -> bool:
    """The ground stage's third cells are on (lidet_ground_cfg_t far2_split_m beyond ring_split_m, or the integer
    stage's _mm fields)."""
    if "far2_split_mm" in cfg:
        return int(cfg["ring_split_mm"]) > 0 and int(cfg["far2_split_mm"]) > int(cfg["ring_split_mm"])
    return float(cfg.get("ring_split_m", 0.0)) > 0 and float(cfg.get("far2_split_m", 0.0)) > float(cfg["ring_split_m"])


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


def plane_sectors(planes, split) -> int:
    """n_sectors for lidet_cluster_run given a plane table: its length, or half of it with a plane split
    (plane_split_m / plane_split_mm > 0: near planes, then far planes); 0 without planes. An odd table with a split
    is refused (the C would read past it)."""
    if planes is None:
        return 0
    if split:
        if len(planes) % 2:
            raise ValueError(f"with a plane split the planes hold near then far planes: an even count, got {len(planes)}")
        return len(planes) // 2
    return len(planes)


def cluster(points, sensor: str | Sensor = "hdl64", ground=None, planes=None, with_image: bool = False,
            proj_cfg: dict | None = None, context: ScanContext | None = None, **cfg) -> Clusters:
    """Project `points` (N, >=3) and cluster the non-ground pixels with the C library.

    ground: optional (N,) bool/uint8 per point (1 = ground; a pixel is ground when its winning point
    is), e.g. SemanticKITTI ground labels or the ground stage's per-point mask. planes: optional
    (S, 4) (nx, ny, nz, d) per azimuth sector for the height filter (None: flat ground at
    -mount_height_m). cfg: theta_rad, max_steps, bridge_occluders, diagonals, max_gap_m, max_gap_per_m, min_points,
    max_extent_m, max_mean_height_m, mount_height_m, rescue_gap_m, rescue_gap_per_m, rescue_rows, rescue_cols,
    max_fragment_pixels, max_bridge_per_pixel (defaults: `cluster_defaults(sensor)`).
    """
    s, ctx = proj_init(sensor, ctx=context, **(proj_cfg or {}))
    c = cluster_defaults(s)
    unknown = set(cfg) - set(c)
    if unknown:
        raise TypeError(f"unknown cluster option(s): {sorted(unknown)}")
    c.update(cfg)
    for flag in ("bridge_occluders", "diagonals"):
        if c[flag] not in (0, 1, True, False):
            raise ValueError(f"{flag} must be 0/1 or a bool, got {c[flag]!r}")
    pts, stride = _as_points(points)
    n = len(pts)
    rows, cols = s.rows, s.cols
    cap = capacity()["max_clusters"]
    gm = None
    if ground is not None:
        gm = _as_per_point(ground, n, "ground", np.uint8, 0, 1)
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
                                    plane_sectors(pl, c["plane_split_m"] > 0), _addr(_record("lidet_cluster_cfg_t", c)),
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


# ---- the whole detector (lib/include/lidet/lidet_detector.h) -------------------------------------------

#: lidet_det_outcome_t values
OUTCOME = {1: "crop", 2: "range", 3: "budget", 4: "gate1", 5: "gate2", 6: "size", 7: "nms", 8: "capacity",
           9: "detected", 10: "tall"}
CLASSES = ("Car", "Cyclist", "Pedestrian")
_DET_STATS = ["n_clusters", "n_out_of_crop", "n_out_of_range", "n_over_budget", "n_classified", "n_gate1_rejected",
              "n_boxed", "n_gate2_rejected", "n_size_rejected", "n_nms_suppressed", "n_over_capacity",
              "n_detections", "status", "n_over_box_budget", "n_too_tall"]


@dataclass
class Detections:
    """Output of `detect`: the detector's boxes (sensor frame), what became of each cluster, per-point labels."""
    cls: np.ndarray           #: (D,) class index (0 Car, 1 Cyclist, 2 Pedestrian)
    score: np.ndarray         #: (D,)
    energy_cls: np.ndarray    #: (D,) gate-1 energy
    energy_box: np.ndarray    #: (D,) gate-2 energy
    box: np.ndarray           #: (D, 7) cx cy cz l w h yaw
    cluster_id: np.ndarray    #: (D,) 1-based cluster id
    outcome: np.ndarray       #: (K,) uint8 per kept cluster (OUTCOME names)
    point_cluster: np.ndarray  #: (N,) cluster id per input point (0 = none)
    point_ground: np.ndarray  #: (N,) 1 = ground
    stats: dict


def default_family(sensor: str | Sensor) -> str:
    """The float model family the detector runs for a preset name: the sensor's own when the bindings hold its
    pair, else hdl64; for a `Sensor` (e.g. read from a file): its model, else hdl64 for >= 32 rows and vlp16 below
    (`sensors.model_family`)."""
    if isinstance(sensor, Sensor):
        return model_family(sensor)
    ms = pn_models()
    return sensor if f"cls_{sensor}" in ms and f"box_{sensor}" in ms else "hdl64"


def detect(points, sensor: str | Sensor = "hdl64", model: str | None = None, crop_half_rad: float = 0.0,
           max_range_m: float = 0.0, nms_iou: float = 0.1, max_proposals: int | None = None, gate1: bool = True,
           gate2: bool = True, refine: bool = True, gate1_margin: float = 0.0, gate2_margin: float = 0.0,
           mount_height_m: float | None = None) -> Detections:
    """lidet_detector_run on (N, >=3) points with the models cls_<model> / box_<model> compiled into the bindings
    (default: `default_family(sensor)`). sensor: a preset name (the C preset, lidet_sensor_find, as `lidet detect
    --sensor`) or a `Sensor` (its table in ring order, e.g. `sensors.load_sensor_file`, `load_ouster_metadata`, as
    `lidet detect --sensor-file`). max_proposals None: the
    C default for the sensor (lidet_detector_cfg_default). refine False: the clustering without its refinement
    (split_people, join_cars: lidet_refine.c), as the integer detector runs it today. gate1_margin / gate2_margin:
    the gates' operating points (lidet_detector_cfg_t, nats added to the models' gammas). mount_height_m: the
    sensor's height above the ground in m, [0, 10] (None: the profile's; `lidet detect --mount-height`)."""
    if max_proposals is not None and not (isinstance(max_proposals, (int, np.integer)) and max_proposals >= 1):
        raise ValueError(f"max_proposals must be a positive integer, got {max_proposals!r}")
    if not isinstance(sensor, (str, Sensor)):
        raise TypeError(f"sensor must be a preset name or a Sensor, got {type(sensor).__name__}")
    ms = pn_models()
    fam = model or default_family(sensor)
    if f"cls_{fam}" not in ms or f"box_{fam}" not in ms:
        raise KeyError(f"models cls_{fam} / box_{fam} are not compiled into the bindings (have: {sorted(ms)})")
    L = lib()
    if not getattr(L, "_det_ready", False):
        _u8p = np.ctypeslib.ndpointer(np.uint8, flags="C_CONTIGUOUS")
        tail = [C.c_uint32, C.c_uint32, _f32p, _u32p, _f32p, C.c_uint32, C.c_uint32, _f32p, _u32p, _u8p, _u32p,
                _opt(_u32p), _opt(_u8p), _u32p]
        L.lidet_py_det_run.argtypes = [C.c_char_p] + tail
        L.lidet_py_det_run_table.argtypes = [C.c_char_p, C.c_uint32, C.c_uint32, _f32p, C.c_float, C.c_float] + tail
        L._det_ready = True
    pts, stride = _as_points(points)
    n = len(pts)
    cap = capacity()
    det = np.zeros((cap["max_detections"], 12), np.float32)
    nd = np.zeros(1, np.uint32)
    oc = np.zeros(cap["max_clusters"], np.uint8)
    nc = np.zeros(1, np.uint32)
    pc = np.zeros(max(n, 1), np.uint32)
    pg = np.zeros(max(n, 1), np.uint8)
    st = np.zeros(len(_DET_STATS), np.uint32)
    if mount_height_m is not None and not (0.0 <= float(mount_height_m) <= 10.0):
        raise ValueError(f"mount_height_m must be metres in [0, 10], got {mount_height_m!r}")
    fc = np.array([crop_half_rad, max_range_m, nms_iou, gate1_margin, gate2_margin,
                   -1.0 if mount_height_m is None else mount_height_m], np.float32)
    uc = np.array([max_proposals or 0, int(bool(gate1)), int(bool(gate2)), int(bool(refine))], np.uint32)
    args = (ms[f"cls_{fam}"].index, ms[f"box_{fam}"].index, fc, uc, pts if n else np.zeros((1, 4), np.float32), n,
            stride, det, nd, oc, nc, pc, pg, st)
    if isinstance(sensor, str):
        rc = L.lidet_py_det_run(sensor.encode(), *args)
    else:
        elev = np.ascontiguousarray(sensor.beam_elev_rad, dtype=np.float32)
        if elev.shape != (sensor.rows,):
            raise ValueError(f"sensor {sensor.name!r}: {elev.shape} elevations for {sensor.rows} rows")
        rc = L.lidet_py_det_run_table(sensor.name.encode(), sensor.rows, sensor.cols, elev, sensor.mount_height_m,
                                      sensor.max_range_m, *args)
    if rc < 0:
        raise LidetError(rc, "lidet_detector")
    d = det[: int(nd[0])]
    return Detections(d[:, 0].astype(np.int64), d[:, 1].copy(), d[:, 2].copy(), d[:, 3].copy(), d[:, 4:11].copy(),
                      d[:, 11].astype(np.int64), oc[: int(nc[0])].copy(), pc[:n], pg[:n],
                      dict(zip(_DET_STATS, map(int, st))))
