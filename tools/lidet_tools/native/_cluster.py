# SPDX-License-Identifier: MIT
"""Clustering and proposals (lib/include/lidet/lidet_cluster.h, lidet_cluster_q.h): the float stage after the float
projection, its proposals from the same scan context, and both clusterings on one compact image."""
from __future__ import annotations

import ctypes as C
from dataclasses import dataclass, field

import numpy as np

from ..sensors import Sensor, get_sensor
from ._lib import (LidetError, ScanContext, V, addr, as_per_point, as_points, capacity, entry_points, f32p, i16p,
                   i32p, opt, record, to_dict, u8p, u16p, u32p, u64p)
from ._ground import ground_defaults
from ._proj import RangeImage, _copy_image, proj_defaults, proj_init


@entry_points
def _cluster_lib(L):
    L.lidet_py_cluster_default.restype = None
    L.lidet_py_cluster_default.argtypes = [C.c_uint32, C.c_uint32, C.c_float, V]
    L.lidet_py_proposal_default.restype = None
    L.lidet_py_proposal_default.argtypes = [V]
    L.lidet_py_cluster_run.argtypes = [V, opt(f32p), C.c_uint32, C.c_uint32, opt(u8p), opt(f32p), C.c_uint32, V,
                                       opt(u32p), opt(u16p), opt(i32p), opt(u32p), opt(f32p), C.c_uint32, opt(u32p), V]
    L.lidet_py_proposals.argtypes = [V, V, C.c_uint32, f32p, f32p, i16p, u32p]
    L.lidet_py_proposal_indices.argtypes = [opt(u32p), C.c_uint32, C.c_uint32, C.c_uint32, u32p]


# ---- the float stage (lidet_cluster.h) -----------------------------------------------------------------------

def cluster_defaults(sensor: str | Sensor = "hdl64") -> dict:
    """lidet_cluster_cfg_default for a preset name or a `Sensor` (field -> value), from C."""
    s = get_sensor(sensor) if isinstance(sensor, str) else sensor
    rec = record("lidet_cluster_cfg_t")
    _cluster_lib().lidet_py_cluster_default(s.rows, s.cols, s.mount_height_m, addr(rec))
    return to_dict(rec)


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
    pts, stride = as_points(points)
    n = len(pts)
    rows, cols = s.rows, s.cols
    cap = capacity()["max_clusters"]
    gm = None
    if ground is not None:
        gm = as_per_point(ground, n, "ground", np.uint8, 0, 1)
    pl = None
    if planes is not None:
        pl = np.ascontiguousarray(planes, dtype=np.float32).reshape(-1, 4)
    pl_out = np.zeros(n, np.uint32)
    pix = np.zeros((rows, cols), np.uint16)
    mem = np.zeros(rows * cols, np.int32)
    ru = np.zeros((cap, 4), np.uint32)
    rf = np.zeros((cap, 10), np.float32)
    nrec = np.zeros(1, np.uint32)
    stats = record("lidet_cluster_stats_t")
    st = _cluster_lib().lidet_py_cluster_run(ctx.ptr, pts if n else None, n, stride, gm if n else None, pl,
                                             plane_sectors(pl, c["plane_split_m"] > 0),
                                             addr(record("lidet_cluster_cfg_t", c)), pl_out if n else None, pix, mem,
                                             ru, rf, cap, nrec, addr(stats))
    if st < 0:
        raise LidetError(st, "lidet_cluster_run")
    k = int(nrec[0])
    sd = to_dict(stats)
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
    rec = record("lidet_proposal_cfg_t")
    _cluster_lib().lidet_py_proposal_default(addr(rec))
    return to_dict(rec)


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
        st = _cluster_lib().lidet_py_proposals(clusters.context.ptr, addr(record("lidet_proposal_cfg_t", c)), k, xyz,
                                               mean, vox, nsrc)
        if st < 0:
            raise LidetError(st, "lidet_proposal_make")
    return Proposals(xyz, mean, vox, nsrc)


def proposal_indices(n_src: int, n_out: int, seed: int = 0x5EED1234, pixels=None) -> np.ndarray:
    """The C resampling rule (lidet_proposal_indices): n_out member indices of a cluster whose n_src member pixels
    are `pixels` in member order (read when n_src > n_out; None there: LidetError LIDET_ERR_ARG)."""
    out = np.zeros(n_out, np.uint32)
    pix = None
    if pixels is not None:
        pix = np.ascontiguousarray(pixels, np.uint32)
        if pix.shape != (n_src,):
            raise ValueError(f"pixels: {n_src} member pixels expected, got shape {pix.shape}")
    st = _cluster_lib().lidet_py_proposal_indices(pix, n_src, n_out, seed & 0xFFFFFFFF, out)
    if st < 0:
        raise LidetError(st, "lidet_proposal_indices")
    return out


# ---- the integer stage, and both clusterings on one compact image (lib/include/lidet/lidet_cluster_q.h) ------

#: lidet_cluster_q_cfg_t / lidet_proposal_q_cfg_t fields in declaration order (all 32-bit: passed as arrays)
CLUSTER_Q_FIELDS = ["theta_urad", "max_steps", "bridge_occluders", "diagonals", "max_gap_mm", "max_gap_per_m_q16",
                    "min_points", "max_extent_mm", "max_mean_height_mm", "mount_height_mm", "rescue_gap_mm",
                    "rescue_gap_per_m_q16", "rescue_rows", "rescue_cols", "max_fragment_pixels",
                    "max_bridge_per_pixel_q16", "split_people", "split_min_width_mm", "split_cell_mm",
                    "split_cell_per_m_q16", "person_max_width_mm", "person_min_height_mm", "person_min_aspect_q16",
                    "person_min_cols", "person_min_points", "join_cars", "join_gap_mm", "car_max_length_mm", "car_max_width_mm",
                    "car_max_height_mm", "car_min_length_mm", "upright_max_width_mm", "max_join_pieces",
                    "regrow_gap_mm", "regrow_gap_per_m_q16", "regrow_max_pixels", "regrow_max_height_mm",
                    "regrow_cut_mm", "plane_split_mm"]
PROPOSAL_Q_FIELDS = ["n_points", "seed", "azimuth_bin_bam", "elevation_bin_bam", "range_bin_4mm", "z_origin"]


@entry_points
def _cluster_q_lib(L):
    L.lidet_py_cluster_q_sizes.restype = None
    L.lidet_py_cluster_q_sizes.argtypes = [u32p]
    L.lidet_py_cluster_q_default.restype = None
    L.lidet_py_cluster_q_default.argtypes = [C.c_uint32, C.c_uint32, i32p, i32p]
    L.lidet_py_cq_prepare.argtypes = [C.c_uint32, C.c_uint32, f32p, C.c_float, V, V, f32p, C.c_uint32, C.c_uint32,
                                      i16p, i16p, i16p, u16p, i32p, f32p, i32p, u8p, f32p]
    L.lidet_py_cluster_q_run.argtypes = [C.c_uint32, C.c_uint32, i16p, i16p, i16p, u16p, i32p, opt(u8p), opt(i32p),
                                         C.c_uint32, i32p, i32p, C.c_uint32, u16p, i32p, i32p, u32p, V, i16p, i32p,
                                         i16p, u64p]
    L.lidet_py_cluster_f_compact.argtypes = [C.c_uint32, C.c_uint32, i16p, i16p, i16p, u16p, f32p, i32p, opt(u8p),
                                             opt(f32p), C.c_uint32, V, V, C.c_uint32, u16p, i32p, u32p, f32p, u32p, V,
                                             f32p, f32p, i16p, u64p]
    sizes = np.zeros(4, np.uint32)
    L.lidet_py_cluster_q_sizes(sizes)
    if sizes[0] != 4 * len(CLUSTER_Q_FIELDS) or sizes[1] != 4 * len(PROPOSAL_Q_FIELDS):
        raise RuntimeError(f"lidet_cluster_q_cfg_t / lidet_proposal_q_cfg_t layout changed: {sizes}")


def cluster_q_defaults(sensor="hdl64") -> tuple[dict, dict]:
    """(lidet_cluster_q_cfg_default, lidet_proposal_q_cfg_default) for a preset name or a Sensor, from C."""
    s = get_sensor(sensor) if isinstance(sensor, str) else sensor
    cq = np.zeros(len(CLUSTER_Q_FIELDS), np.int32)
    pq = np.zeros(len(PROPOSAL_Q_FIELDS), np.int32)
    _cluster_q_lib().lidet_py_cluster_q_default(s.rows, int(round(s.mount_height_m * 1000)), cq, pq)
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
    s = get_sensor(sensor) if isinstance(sensor, str) else sensor
    pts, stride = as_points(points)
    n = len(pts)
    rows, cols = s.rows, s.cols
    gcfg = ground_defaults(s)
    ns = int(gcfg["n_sectors"])
    x, y, z = (np.zeros((rows, cols), np.int16) for _ in range(3))
    rng = np.zeros((rows, cols), np.uint16)
    eb = np.zeros(rows, np.int32)
    er = np.zeros(rows, np.float32)
    pp = np.full(max(n, 1), -1, np.int32)
    mask = np.zeros((rows, cols), np.uint8)
    planes = np.zeros((max(ns, 1), 4), np.float32)
    st = _cluster_q_lib().lidet_py_cq_prepare(rows, cols, np.ascontiguousarray(s.beam_elev_rad, np.float32),
                                              s.mount_height_m, addr(record("lidet_proj_cfg_t", proj_defaults())),
                                              addr(record("lidet_ground_cfg_t", gcfg)),
                                              pts if n else np.zeros((1, 3), np.float32), n, stride, x, y, z, rng, eb,
                                              er, pp, mask, planes)
    if st < 0:
        raise LidetError(st, "lidet_py_cq_prepare")
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
    cap = capacity()["max_clusters"]
    return {"lab": np.zeros((rows, cols), np.uint16), "mem": np.zeros(rows * cols, np.int32),
            "nrec": np.zeros(1, np.uint32), "stats": record("lidet_cluster_stats_t"),
            "pxyz": np.zeros((cap, npts, 3), np.int16 if coord == np.int32 else coord),
            "pmean": np.zeros((cap, 3), coord), "pvox": np.zeros((cap, 3), np.int16)}


def _result(o: dict, st: int, what: str, ints, floats, ns) -> ClustersOnImage:
    """ClustersOnImage from the filled arrays: ints (K, >= 4) n_points, first_member, seed_pixel, n_rescued;
    floats (K, 10) mean, min, max, height (the same array as ints for the integer stage)."""
    if st < 0:
        raise LidetError(st, what)
    k = int(o["nrec"][0])
    sd = to_dict(o["stats"])
    i, f = ints[:k], floats[:k]
    return ClustersOnImage(o["lab"], o["mem"][: sd["n_pixels_kept"]].copy(), *(i[:, j].copy() for j in range(4)),
                           f[:, 0:3].copy(), f[:, 3:6].copy(), f[:, 6:9].copy(), f[:, 9].copy(), sd, int(st),
                           o["pxyz"][:k].copy(), o["pmean"][:k].copy(), o["pvox"][:k].copy(), ns)


def cluster_q(scan: CompactScan, planes_q=None, use_ground: bool = True, repeat: int = 1, proposal_cfg=None,
              **cfg) -> ClustersOnImage:
    """lidet_cluster_q_run on a compact scan (planes_q: (S, 4) int32 lidet_plane_q_t, or None: flat ground) and
    lidet_proposal_q_make for every kept cluster. cfg: fields of lidet_cluster_q_cfg_t."""
    L = _cluster_q_lib()
    dc, dp = cluster_q_defaults(scan.sensor)
    c = _cfg_array(CLUSTER_Q_FIELDS, dc, cfg, "lidet_cluster_q_cfg_t")
    p = _cfg_array(PROPOSAL_Q_FIELDS, dp, proposal_cfg or {}, "lidet_proposal_q_cfg_t")
    rows, cols = scan.shape
    cap = capacity()["max_clusters"]
    pl = None if planes_q is None else np.ascontiguousarray(planes_q, np.int32).reshape(-1, 4)
    o = _outputs(rows, cols, int(p[0]), np.int32)
    recs = np.zeros((cap, 14), np.int32)
    ns = np.zeros(max(repeat, 1), np.uint64)
    st = L.lidet_py_cluster_q_run(rows, cols, scan.x, scan.y, scan.z, scan.range, scan.row_elev_bam,
                                  scan.ground if use_ground else None, pl,
                                  plane_sectors(pl, c[CLUSTER_Q_FIELDS.index("plane_split_mm")] > 0), c, p, repeat,
                                  o["lab"], o["mem"], recs, o["nrec"], addr(o["stats"]), o["pxyz"], o["pmean"],
                                  o["pvox"], ns)
    return _result(o, st, "lidet_cluster_q_run", recs, recs[:, 4:14], ns)


def cluster_f_compact(scan: CompactScan, planes=None, use_ground: bool = True, repeat: int = 1,
                      proposal_cfg=None, **cfg) -> ClustersOnImage:
    """The float clustering (lidet_cluster_run_buffers) and proposals on the same compact image.
    planes: (S, 4) float (nx, ny, nz, d_m) or None. cfg: fields of lidet_cluster_cfg_t."""
    L = _cluster_q_lib()
    c = cluster_defaults(scan.sensor)
    unknown = set(cfg) - set(c)
    if unknown:
        raise TypeError(f"unknown cluster option(s): {sorted(unknown)}")
    c.update(cfg)
    pc = proposal_defaults()
    pc.update(proposal_cfg or {})
    rows, cols = scan.shape
    cap = capacity()["max_clusters"]
    pl = None if planes is None else np.ascontiguousarray(planes, np.float32).reshape(-1, 4)
    o = _outputs(rows, cols, int(pc["n_points"]), np.float32)
    ru = np.zeros((cap, 4), np.uint32)
    rf = np.zeros((cap, 10), np.float32)
    ns = np.zeros(max(repeat, 1), np.uint64)
    st = L.lidet_py_cluster_f_compact(rows, cols, scan.x, scan.y, scan.z, scan.range, scan.row_elev_rad,
                                      scan.row_elev_bam, scan.ground if use_ground else None, pl,
                                      plane_sectors(pl, c["plane_split_m"] > 0),
                                      addr(record("lidet_cluster_cfg_t", c)),
                                      addr(record("lidet_proposal_cfg_t", pc)), repeat, o["lab"],
                                      o["mem"], ru, rf, o["nrec"], addr(o["stats"]), o["pxyz"], o["pmean"],
                                      o["pvox"], ns)
    return _result(o, st, "lidet_cluster_run (compact)", ru, rf, ns)
