# SPDX-License-Identifier: MIT
"""Ground segmentation (lib/include/lidet/lidet_ground.h, lidet_ground_q.h): the float stage after the float
projection, and both stages on one compact image (lib/src/ground/lidet_ground_filter_q.c,
lidet_ground_ransac_q.c)."""
from __future__ import annotations

import ctypes as C
from dataclasses import dataclass

import numpy as np

from ..sensors import Sensor, get_sensor
from ._lib import (LidetError, ScanContext, V, addr, capacity, entry_points, f32p, i16p, i32p, i64p, opt, record,
                   to_dict, u8p, u16p, u64p)
from ._proj import CompactImage, RangeImage, _project_into, proj_init, project_compact


@entry_points
def _ground_lib(L):
    L.lidet_py_ground_default.restype = None
    L.lidet_py_ground_default.argtypes = [C.c_uint32, C.c_uint32, C.c_float, V]
    L.lidet_py_ground_run.argtypes = [V, V, opt(u8p), opt(u8p), opt(u8p), opt(f32p), opt(u8p), V]
    L.lidet_py_ground_fit_plane.argtypes = [f32p, f32p, f32p, C.c_uint32, f32p, opt(f32p)]
    L.lidet_py_ground_q_field.restype = C.c_char_p
    L.lidet_py_ground_q_field.argtypes = [C.c_uint32]
    L.lidet_py_ground_q_default.argtypes = [C.c_uint32, C.c_int32, i64p]
    img = [C.c_uint32, C.c_uint32, i16p, i16p, i16p, u16p]
    L.lidet_py_ground_q_run.argtypes = [i64p, *img, opt(u8p), opt(u8p), opt(i32p), opt(i64p), opt(u8p), V]
    L.lidet_py_ground_float_compact.argtypes = [V, *img, opt(u8p), opt(u8p), opt(f32p), opt(u8p), V]
    L.lidet_py_ground_q_time.argtypes = [V, i64p, *img, C.c_uint32, u64p]


# ---- the float stage (lidet_ground.h) ------------------------------------------------------------------------

PLANE_SOURCE = {0: "fitted", 1: "neighbour", 2: "mount", 3: "near"}


def ground_defaults(sensor: str | Sensor = "hdl64") -> dict:
    """lidet_ground_cfg_default for a preset name or a `Sensor` (as a dict of field -> value), from C."""
    s = get_sensor(sensor) if isinstance(sensor, str) else sensor
    rec = record("lidet_ground_cfg_t")
    _ground_lib().lidet_py_ground_default(s.rows, s.cols, s.mount_height_m, addr(rec))
    return to_dict(rec)


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
    stats = record("lidet_ground_stats_t")
    cap = capacity()["max_points"]
    st = _ground_lib().lidet_py_ground_run(ctx.ptr, addr(record("lidet_ground_cfg_t", full)), mp, sp,
                                           mpt[: min(n, cap)] if n else None, planes, src, addr(stats))
    if st < 0:
        raise LidetError(st, "lidet_ground_run")
    three = far2_on(full)
    return GroundResult(mpt, mp, planes[:ns], planes[ns:2 * ns], to_dict(stats), sp, src[:(3 if three else 2) * ns], img,
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
    st = _ground_lib().lidet_py_ground_fit_plane(p[0].copy(), p[1].copy(), p[2].copy(), p.shape[1], plane, eig)
    if st < 0:
        raise LidetError(st, "lidet_ground_fit_plane")
    return plane, eig


# ---- the integer stage, and both stages on one compact image ------------------------------------------------

def ground_q_fields() -> list[str]:
    """Field names of lidet_ground_q_cfg_t, in the order the entry points take them."""
    L = _ground_lib()
    out, i = [], 0
    while (name := L.lidet_py_ground_q_field(i)) is not None:
        out.append(name.decode())
        i += 1
    return out


def ground_q_defaults(sensor="hdl64") -> dict:
    """lidet_ground_q_cfg_default for a preset name or a Sensor (field -> int)."""
    s = get_sensor(sensor) if isinstance(sensor, str) else sensor
    v = np.zeros(len(ground_q_fields()), np.int64)
    _ground_lib().lidet_py_ground_q_default(s.rows, int(round(s.mount_height_m * 1000)), v)
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
            np.zeros(3 * ns, np.uint8), record("lidet_ground_stats_t"))


def ground_q(img: CompactImage, sensor="hdl64", **cfg) -> GroundQResult:
    """The integer ground stage on a compact image; cfg overrides ground_q_defaults(sensor)."""
    full = ground_q_defaults(sensor)
    full.update(cfg)
    rows, cols, ns, mask, smp, src, stats = _ground_outputs(img, full)
    planes = np.zeros((3 * ns, 4), np.int32)
    pd = np.zeros(3 * ns, np.int64)
    st = _ground_lib().lidet_py_ground_q_run(_cfg_vec(full), rows, cols, img.x, img.y, img.z, img.range, mask,
                                             smp, planes, pd, src, addr(stats))
    if st < 0:
        raise LidetError(st, "lidet_ground_q_run")
    nc = (3 if far2_on(full) else 2) * ns  # near, far and the third cells' planes when on
    return GroundQResult(mask, smp, planes[:nc], pd[:nc], src[:nc], to_dict(stats), int(st))


def ground_float_compact(img: CompactImage, sensor="hdl64", **cfg):
    """The float ground stage on the same compact image: (mask, sample, planes (2 ns, 4) float32, 3 ns with the
    third cells, source, stats)."""
    full = ground_defaults(sensor)
    full.update(cfg)
    rows, cols, ns, mask, smp, src, stats = _ground_outputs(img, full)
    planes = np.zeros((3 * ns, 4), np.float32)
    st = _ground_lib().lidet_py_ground_float_compact(addr(record("lidet_ground_cfg_t", full)), rows, cols, img.x,
                                                     img.y, img.z, img.range, mask, smp, planes, src, addr(stats))
    if st < 0:
        raise LidetError(st, "lidet_ground_run")
    nc = (3 if far2_on(full) else 2) * ns
    return mask, smp, planes[:nc], src[:nc], to_dict(stats)


def ground_q_time(img: CompactImage, sensor="hdl64", repeats=100) -> tuple[float, float, float, float]:
    """Host timing (ms) of the float and the integer ground stage on one compact image, interleaved: (float median,
    integer median, float minimum, integer minimum)."""
    out = np.zeros(4, np.uint64)
    cf = record("lidet_ground_cfg_t", ground_defaults(sensor))
    rows, cols = img.shape
    st = _ground_lib().lidet_py_ground_q_time(addr(cf), _cfg_vec(ground_q_defaults(sensor)), rows, cols,
                                              img.x, img.y, img.z, img.range, repeats, out)
    if st < 0:
        raise LidetError(st, "lidet_py_ground_q_time")
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
