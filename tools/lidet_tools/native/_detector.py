# SPDX-License-Identifier: MIT
"""The whole detectors (lib/include/lidet/lidet_detector.h, lidet_detector_q.h), the integer path's
post-processing (size check, rotated BEV IoU, NMS: lib/src/detector/lidet_post_q.c), and the detectors' classified
candidates for the int8 accuracy ablations (ports/python/lidet_py_acc_q.c)."""
from __future__ import annotations

import ctypes as C
import warnings
from dataclasses import dataclass

import numpy as np

from ..sensors import Sensor, model_family
from ._lib import LidetError, as_points, capacity, entry_points, f32p, i16p, i32p, opt, u8p, u16p, u32p
from ._pointnet import _pnq, pn_models
from ._proj import RETURN_DTYPE


@entry_points
def _detector_lib(L):
    tail = [C.c_uint32, C.c_uint32, f32p, u32p, f32p, C.c_uint32, C.c_uint32, f32p, u32p, u8p, u32p, opt(u32p),
            opt(u8p), u32p]
    L.lidet_py_det_run.argtypes = [C.c_char_p] + tail
    L.lidet_py_det_run_table.argtypes = [C.c_char_p, C.c_uint32, C.c_uint32, f32p, C.c_float, C.c_float] + tail
    L.lidet_py_detq_run.argtypes = [C.c_char_p, C.c_char_p, C.c_char_p, i32p, i32p, C.c_uint32, C.c_uint32, i32p,
                                    u32p, u8p, u32p, u32p, C.c_void_p, opt(u32p), opt(u8p)]
    L.lidet_py_detq_bytes.restype = C.c_uint32
    L.lidet_py_q_bev_iou.argtypes = [i32p, i32p, C.c_uint32, i32p]
    L.lidet_py_bev_iou.argtypes = [f32p, f32p, C.c_uint32, f32p]
    L.lidet_py_q_post.argtypes = [i32p, i32p, u16p, u8p, C.c_uint32, C.c_int32, u8p, u16p, u8p]
    L.lidet_py_acc_cands.argtypes = [C.c_char_p, C.c_uint32, C.c_uint32, f32p, u32p, f32p, C.c_uint32, C.c_uint32,
                                     f32p, f32p, i16p, u32p, u32p, u32p]
    L.lidet_py_acc_cands_q.argtypes = [C.c_char_p, C.c_char_p, C.c_char_p, i32p, i32p, C.c_uint32, C.c_uint32, i16p,
                                       i32p, i16p, u32p, u32p, u32p]
    L.lidet_py_acc_cand_points.argtypes = [C.c_int, C.c_uint32, u32p]


# ---- the float detector (lib/include/lidet/lidet_detector.h) ------------------------------------------------

#: lidet_det_outcome_t values
OUTCOME = {1: "crop", 2: "range", 3: "budget", 4: "gate1", 5: "gate2", 6: "size", 7: "nms", 8: "capacity",
           9: "detected", 10: "tall", 11: "group", 12: "score"}
CLASSES = ("Car", "Cyclist", "Pedestrian")
_DET_STATS = ["n_clusters", "n_out_of_crop", "n_out_of_range", "n_over_budget", "n_classified", "n_gate1_rejected",
              "n_boxed", "n_gate2_rejected", "n_size_rejected", "n_nms_suppressed", "n_over_capacity",
              "n_detections", "status", "n_over_box_budget", "n_too_tall", "n_group_split", "n_group_classified",
              "n_group_boxed", "n_score_rejected", "n_points_in", "n_out_of_fov", "n_too_far"]


class LidetFrameWarning(UserWarning):
    """`detect` on a cloud that does not look like the sensor's scan (`frame_warning`)."""


def frame_warning(stats: dict, sensor_name: str, unit: str = "m") -> str | None:
    """What looks wrong with a scan's frame, from the projection's counts in `stats` (n_points_in, n_out_of_fov,
    n_too_far), or None: the rule of the CLI's warning (ports/host/cli_common.c, cli_warn_frame; docs/ROBUSTNESS.md,
    "A cloud in another frame"): more than a tenth of the points outside the sensor's beams, or more than a quarter
    beyond the range the image keeps. unit "mm" (`detect_q`'s input): also more than a quarter closer than the
    minimum range (stats' n_too_close), what a cloud in metres given as millimetres gives."""
    if unit not in ("m", "mm"):
        raise ValueError(f"unit: 'm' or 'mm', got {unit!r}")
    n = int(stats.get("n_points_in", 0))
    if n < 100:
        return None
    out = []
    if int(stats["n_out_of_fov"]) > n // 10:
        out.append(f"{stats['n_out_of_fov']} of {n} points ({100 * stats['n_out_of_fov'] / n:.0f} %) lie outside the "
                   f"{sensor_name}'s beams: lidet reads x forward, y left, z up, in metres; a cloud upside down, in a "
                   f"camera's frame or from another sensor looks like this")
    if int(stats["n_too_far"]) > n // 4:
        out.append(f"{stats['n_too_far']} of {n} points ({100 * stats['n_too_far'] / n:.0f} %) lie beyond the range "
                   f"the image keeps: are the coordinates in {'millimetres' if unit == 'mm' else 'metres'}?")
    if unit == "mm" and int(stats.get("n_too_close", 0)) > n // 4:
        out.append(f"{stats['n_too_close']} of {n} points ({100 * stats['n_too_close'] / n:.0f} %) lie closer than "
                   f"the minimum range: detect_q takes millimetres (native.to_mm converts metres)")
    return "; ".join(out) or None


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


def _class_bits(flags) -> int:
    """Three per-class flags (lidet_class_t order) as the bits the bindings take."""
    f = [int(bool(v)) for v in flags]
    if len(f) != 3:
        raise ValueError(f"gate2_class needs 3 flags (Car, Cyclist, Pedestrian), got {flags!r}")
    return f[0] | f[1] << 1 | f[2] << 2


def _per_class(v, name: str, lo: float, hi: float):
    """None, or 3 numbers in [lo, hi] (lidet_class_t order: Car, Cyclist, Pedestrian) as floats."""
    if v is None:
        return None
    f = [float(x) for x in v]
    if len(f) != 3 or not all(lo <= x <= hi for x in f):
        raise ValueError(f"{name} needs 3 values in [{lo}, {hi}] (Car, Cyclist, Pedestrian), got {v!r}")
    return f


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
           mount_height_m: float | None = None, gate2_class=None, group_split: bool | None = None,
           min_score=None, car_min_z_spread_m: float | None = None, gate1_class_margin=None,
           car_ground_m: float | None = None, group_gate1_margin: float | None = None,
           gate1_large_car_margin: float | None = None) -> Detections:
    """lidet_detector_run on (N, >=3) points with the models cls_<model> / box_<model> compiled into the bindings
    (default: `default_family(sensor)`). sensor: a preset name (the C preset, lidet_sensor_find, as `lidet detect
    --sensor`) or a `Sensor` (its table in ring order, e.g. `sensors.load_sensor_file`, `load_ouster_metadata`, as
    `lidet detect --sensor-file`). max_proposals None: the
    C default for the sensor (lidet_detector_cfg_default). refine False: the clustering without its refinement
    (split_people, join_cars: lidet_refine.c; the integer detector refines too, lidet_refine_q.c, unless its
    cluster configuration turns it off). gate1_margin / gate2_margin:
    the gates' operating points (lidet_detector_cfg_t, nats added to the models' gammas). mount_height_m: the
    sensor's height above the ground in m, [0, 10] (None: the profile's; `lidet detect --mount-height`).
    gate2_class: 3 flags (Car, Cyclist, Pedestrian), the classes gate 2 judges (None: the C default,
    lidet_detector_cfg_t.gate2_class). group_split: people side by side split by the classifier's judgement
    (lidet_detector_cfg_t.group_split; None: the C default for the sensor, on for > 16 beams); a group's parts give
    detections with the cluster's id, and the cluster the outcome "group". min_score: 3 scores in [0, 1] (Car,
    Cyclist, Pedestrian), the operating point below which a detection is dropped (outcome "score"; None: the C
    default for the sensor, lidet_detector_cfg_t.min_score). car_min_z_spread_m: the cars' flat-surface test
    (lidet_detector_cfg_t.car_min_z_spread_m, outcome "size"; 0 turns it off; None: the C default).
    gate1_class_margin: 3 margins in nats in [-20, 20] (Car, Cyclist, Pedestrian) added to gate1_margin for a
    proposal of that class (None: the C default, 0 for every class). car_ground_m: car boxes stretched down to the
    ground pixels within this of their footprint (lidet_detector_cfg_t.car_ground_m; 0 turns it off; None: the C
    default, 1 m). group_gate1_margin: nats added to gate 1 when the group split judges a cut, in
    [0, 20] (lidet_detector_cfg_t.group_gate1_margin; None: the C default, 2). gate1_large_car_margin: nats added to
    gate 1 for a car whose cluster holds >= 100 member pixels, in [0, 20] (lidet_detector_cfg_t.gate1_large_car_margin;
    None: the C default)."""
    if max_proposals is not None and not (isinstance(max_proposals, (int, np.integer)) and max_proposals >= 1):
        raise ValueError(f"max_proposals must be a positive integer, got {max_proposals!r}")
    if not isinstance(sensor, (str, Sensor)):
        raise TypeError(f"sensor must be a preset name or a Sensor, got {type(sensor).__name__}")
    ms = pn_models()
    fam = model or default_family(sensor)
    if f"cls_{fam}" not in ms or f"box_{fam}" not in ms:
        raise KeyError(f"models cls_{fam} / box_{fam} are not compiled into the bindings (have: {sorted(ms)})")
    L = _detector_lib()
    pts, stride = as_points(points)
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
    ms3 = _per_class(min_score, "min_score", 0.0, 1.0)
    g1c = _per_class(gate1_class_margin, "gate1_class_margin", -20.0, 20.0)
    if car_min_z_spread_m is not None and not (0.0 <= float(car_min_z_spread_m) <= 10.0):
        raise ValueError(f"car_min_z_spread_m must be metres in [0, 10], got {car_min_z_spread_m!r}")
    if car_ground_m is not None and not (0.0 <= float(car_ground_m) <= 10.0):
        raise ValueError(f"car_ground_m must be metres in [0, 10], got {car_ground_m!r}")
    if group_gate1_margin is not None and not (0.0 <= float(group_gate1_margin) <= 20.0):
        raise ValueError(f"group_gate1_margin must be nats in [0, 20], got {group_gate1_margin!r}")
    if gate1_large_car_margin is not None and not (0.0 <= float(gate1_large_car_margin) <= 20.0):
        raise ValueError(f"gate1_large_car_margin must be nats in [0, 20], got {gate1_large_car_margin!r}")
    fc = np.array([crop_half_rad, max_range_m, nms_iou, gate1_margin, gate2_margin,
                   -1.0 if mount_height_m is None else mount_height_m,
                   *([-1.0] * 3 if ms3 is None else ms3),
                   -1.0 if car_min_z_spread_m is None else car_min_z_spread_m,
                   *([np.nan] * 3 if g1c is None else g1c),
                   -1.0 if car_ground_m is None else car_ground_m,
                   -1.0 if group_gate1_margin is None else group_gate1_margin,
                   -1.0 if gate1_large_car_margin is None else gate1_large_car_margin], np.float32)
    uc = np.array([max_proposals or 0, int(bool(gate1)), int(bool(gate2)), int(bool(refine)),
                   0xFFFFFFFF if gate2_class is None else _class_bits(gate2_class),
                   0xFFFFFFFF if group_split is None else int(bool(group_split))], np.uint32)
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
    stats = dict(zip(_DET_STATS, map(int, st)))
    w = frame_warning(stats, sensor if isinstance(sensor, str) else sensor.name)
    if w is not None:
        warnings.warn(w, LidetFrameWarning, stacklevel=2)
    return Detections(d[:, 0].astype(np.int64), d[:, 1].copy(), d[:, 2].copy(), d[:, 3].copy(), d[:, 4:11].copy(),
                      d[:, 11].astype(np.int64), oc[: int(nc[0])].copy(), pc[:n], pg[:n], stats)


# ---- the integer detector (lib/src/detector/lidet_detector_q.c) ---------------------------------------------

DETQ_STATS = ["n_clusters", "n_out_of_crop", "n_out_of_range", "n_over_budget", "n_classified", "n_gate1_rejected",
              "n_boxed", "n_gate2_rejected", "n_size_rejected", "n_nms_suppressed", "n_over_capacity", "n_detections",
              "n_over_box_budget", "n_too_tall", "n_group_split", "n_group_classified", "n_group_boxed",
              "n_score_rejected", "n_stream_sectors", "n_points_in", "n_out_of_fov", "n_too_far",
              "n_too_close"]


def detect_q(points_mm, sensor: str = "hdl64", model: str | None = None, crop_half_bam: int = 0,
             max_range_mm: int = 0, nms_iou_q15: int = 3277, max_proposals: int = 0, gate1: bool = True,
             gate2: bool = True, max_boxes: int = 0, gate1_margin_q16: int = 0, gate2_margin_q16: int = 0,
             range_only: bool | None = None, returns=None, gate2_class=None, group_split: bool | None = None,
             min_score_q15=None, car_min_z_spread_mm: int | None = None, gate1_class_margin_q16=None,
             car_ground_mm: int | None = None, group_gate1_margin_q16: int | None = None,
             gate1_large_car_margin_q16: int | None = None, stream_sectors: bool = False,
             stream: int = 0, mount_height_m: float | None = None, point_labels: bool = False) -> dict:
    """lidet_detector_q_run on (N, 3) int32 mm points with the int8 models cls_<model>_s8 / box_<model>_s8
    (returns: a RETURN_DTYPE array instead, lidet_detector_q_run_returns; points_mm is then ignored).
    gate*_margin_q16: the gates' operating points (lidet_detector_q_cfg_t, Q16 nats). range_only: the range-only
    pixel (lidet_detector_q_cfg_t.range_only; None = the build's default). gate2_class: 3 flags (Car, Cyclist,
    Pedestrian), the classes gate 2 judges (None: the C default). group_split: the float detector's (None: the C
    default for the sensor). min_score_q15 (3 values in [0, 32768]) and car_min_z_spread_mm: the float
    detector's min_score and car_min_z_spread_m (None: the C defaults). gate1_class_margin_q16: 3 values in
    [-20 * 65536, 20 * 65536], the float detector's gate1_class_margin in Q16 nats (None: the C default).
    car_ground_mm: the float detector's car_ground_m in mm (None: the C default). group_gate1_margin_q16: the float
    detector's group_gate1_margin in Q16 nats, [0, 20 * 65536] (None: the C default, 2 * 65536).
    gate1_large_car_margin_q16: the float detector's gate1_large_car_margin in Q16 nats, [0, 20 * 65536] (None: the C
    default). stream_sectors: lidet_detector_q_cfg_t.stream_sectors (the ground stage sector by sector while the returns
    stream in; needs the range-only pixel). stream > 0 (with returns): the returns streamed that many at a time
    (lidet_detector_q_stream_*) instead of one run; stats['n_stream_sectors'] counts the sectors done before the end.
    mount_height_m: the sensor's height above the ground, [0, 10] m, rounded to mm as `lidet detect --fixed
    --mount-height` does (None: the preset's). point_labels (not with a stream): the result also holds
    'point_cluster' (each point's cluster id, the winner's of its pixel as `detect`'s; 0: none) and 'point_ground'
    (1: the ground stage's), which `lidet_tools.where_lost` reads.

    Returns {'cls', 'score_q15', 'energy_cls_q16', 'energy_box_q16', 'boxes' (N, 7: cx cy cz l w h mm, yaw BAM32),
    'cluster_id', 'n_points', 'outcome', 'stats', 'status'}; stats also carry the projection's n_points_in,
    n_out_of_fov, n_too_far and n_too_close, and a cloud that does not look like the sensor's scan in millimetres
    (points, not returns) gives a LidetFrameWarning (`frame_warning(stats, sensor, unit="mm")`). A float array of
    points that are not whole millimetres is refused (TypeError): metres cast to integers would lose every point."""
    L = _detector_lib()
    if returns is not None:
        returns = np.ascontiguousarray(returns, dtype=RETURN_DTYPE)
        points_mm = np.zeros((len(returns), 3), np.int32)
    raw = np.asarray(points_mm)
    if raw.dtype.kind == "f" and not np.array_equal(raw, np.round(raw)):
        raise TypeError("points_mm: whole millimetres (an integer array); native.to_mm(points) converts metres")
    pts = np.ascontiguousarray(raw, dtype=np.int32)
    if pts.ndim != 2 or pts.shape[1] < 3:
        raise ValueError(f"points_mm must be (N, >=3) int32, got {pts.shape}")
    if mount_height_m is not None and not 0.0 <= float(mount_height_m) <= 10.0:
        raise ValueError(f"mount_height_m must lie in [0, 10] m, got {mount_height_m!r}")
    fam = model or sensor
    cap = capacity()
    det = np.zeros((cap["max_detections"], 13), np.int32)
    nd = np.zeros(1, np.uint32)
    oc = np.zeros(cap["max_clusters"], np.uint8)
    nc = np.zeros(1, np.uint32)
    st = np.zeros(len(DETQ_STATS), np.uint32)
    icfg = np.array([crop_half_bam, max_range_mm, nms_iou_q15, max_proposals, int(bool(gate1)), int(bool(gate2)),
                     max_boxes, gate1_margin_q16, gate2_margin_q16, -1 if range_only is None else int(bool(range_only)),
                     -1 if gate2_class is None else _class_bits(gate2_class),
                     -1 if group_split is None else int(bool(group_split)),
                     *([-1] * 3 if min_score_q15 is None else [int(x) for x in _per_class(min_score_q15, "min_score_q15", 0,
                                                                                             32768)]),
                     -1 if car_min_z_spread_mm is None else int(car_min_z_spread_mm),
                     *([np.iinfo(np.int32).min] * 3 if gate1_class_margin_q16 is None else
                       [int(x) for x in _per_class(gate1_class_margin_q16, "gate1_class_margin_q16", -20 * 65536,
                                                   20 * 65536)]),
                     -1 if car_ground_mm is None else int(car_ground_mm),
                     -1 if group_gate1_margin_q16 is None else int(group_gate1_margin_q16),
                     -1 if gate1_large_car_margin_q16 is None else int(gate1_large_car_margin_q16),
                     int(bool(stream_sectors)), int(stream),
                     -1 if mount_height_m is None else int(np.floor(float(mount_height_m) * 1000.0 + 0.5))], np.int32)
    if stream < 0 or (stream and returns is None):
        raise ValueError("stream: a count of returns per chunk (>= 0), with returns")
    if point_labels and stream:
        raise ValueError("point_labels: one run, not a stream")
    n = len(pts)
    if point_labels and n > cap["max_points"]:
        raise ValueError(f"point_labels: at most {cap['max_points']} points (the build's LIDET_MAX_POINTS), got {n}")
    pcl = np.zeros(max(n, 1), np.uint32) if point_labels else None
    pgr = np.zeros(max(n, 1), np.uint8) if point_labels else None
    rc = L.lidet_py_detq_run(sensor.encode(), f"cls_{fam}_s8".encode(), f"box_{fam}_s8".encode(), icfg,
                             pts if n else np.zeros((1, 3), np.int32), n, pts.shape[1], det, nd, oc, nc, st,
                             None if returns is None else returns.ctypes.data_as(C.c_void_p), pcl, pgr)
    if rc < 0:
        raise LidetError(rc, "lidet_detector_q")
    d = det[: int(nd[0])]
    stats = dict(zip(DETQ_STATS, map(int, st)))
    w = frame_warning(stats, sensor, unit="mm") if returns is None else None
    if w is not None:
        warnings.warn(w, LidetFrameWarning, stacklevel=2)
    return {"cls": d[:, 0].copy(), "score_q15": d[:, 1].copy(), "energy_cls_q16": d[:, 2].copy(),
            "energy_box_q16": d[:, 3].copy(), "boxes": d[:, 4:11].copy(), "cluster_id": d[:, 11].copy(),
            "n_points": d[:, 12].copy(), "outcome": oc[: int(nc[0])].copy(), "stats": stats,
            "status": int(rc), **({"point_cluster": pcl[:n], "point_ground": pgr[:n]} if point_labels else {})}


def detector_q_bytes() -> int:
    """sizeof(lidet_detector_q_t) of the bindings' build."""
    return int(_detector_lib().lidet_py_detq_bytes())


# ---- post-processing: size check, BEV IoU, NMS (lib/src/detector/lidet_post_q.c) -----------------------------

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
    _detector_lib().lidet_py_q_bev_iou(a, b, len(a), out)
    return out


def bev_iou_float(a, b) -> np.ndarray:
    """The float detector's rotated BEV IoU (lidet_box_bev_iou) of box pairs (N, 7): metres and radians."""
    a, b = _boxes(a, np.float32), _boxes(b, np.float32)
    out = np.zeros(len(a), dtype=np.float32)
    _detector_lib().lidet_py_bev_iou(a, b, len(a), out)
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
    k = _detector_lib().lidet_py_q_post(boxes, score, cid, cl, n, int(iou_q15), size_ok, order, supp)
    if k < 0:
        raise ValueError(f"lidet_py_q_post: status {k} (more than LIDET_MAX_DETECTIONS detections?)")
    return {"size_ok": size_ok.astype(bool), "kept": order[:k].tolist(), "suppressed": supp.tolist()}


# ---- the detectors' candidate proposals, for the int8 accuracy ablations (ports/python/lidet_py_acc_q.c) ----

def candidates_float(points, sensor: str = "hdl64", model: str | None = None, crop_half_rad: float = 0.0,
                     max_range_m: float = 0.0, refine: bool = False) -> dict:
    """The float detector's classified candidates of one scan, nearest first: {'xyz' (K, N, 3) m centred,
    'mean' (K, 3) m, 'voxel' (K, 3), 'cluster_id' (K,), 'n_points' (K,) the cluster's size}: the proposals its
    classifier sees."""
    L = _detector_lib()
    fam = model or sensor
    ms = pn_models()
    pts, stride = as_points(points)
    n = len(pts)
    cap = capacity()["max_clusters"]
    npt = ms[f"cls_{fam}"].n_points
    xyz, mean = np.zeros((cap, npt, 3), np.float32), np.zeros((cap, 3), np.float32)
    vox, cid = np.zeros((cap, 3), np.int16), np.zeros(cap, np.uint32)
    nc, npo = np.zeros(1, np.uint32), np.zeros(1, np.uint32)
    rc = L.lidet_py_acc_cands(sensor.encode(), ms[f"cls_{fam}"].index, ms[f"box_{fam}"].index,
                              np.array([crop_half_rad, max_range_m], np.float32),
                              np.array([0, int(bool(refine))], np.uint32), pts if n else np.zeros((1, 4), np.float32),
                              n, stride, xyz, mean, vox, cid, nc, npo)
    if rc < 0:
        raise LidetError(rc, "lidet_py_acc_cands")
    k = int(nc[0])
    return dict(xyz=xyz[:k], mean=mean[:k], voxel=vox[:k], cluster_id=cid[:k], n_points=_cand_points(L, 0, k))


def candidates_q(points_mm, sensor: str = "hdl64", model: str | None = None, crop_half_bam: int = 0,
                 max_range_mm: int = 0) -> dict:
    """The integer detector's classified candidates of one scan (int32 mm points), nearest first: {'xyz'
    (K, N, 3) 4 mm centred, 'mean' (K, 3) 4 mm, 'voxel' (K, 3), 'cluster_id' (K,), 'n_points' (K,)}."""
    L = _detector_lib()
    fam = model or sensor
    pts = np.ascontiguousarray(points_mm, dtype=np.int32)
    n = len(pts)
    cap = capacity()["max_clusters"]
    npt = _pnq(f"cls_{fam}_s8")["n_points"]
    xyz, mean = np.zeros((cap, npt, 3), np.int16), np.zeros((cap, 3), np.int32)
    vox, cid = np.zeros((cap, 3), np.int16), np.zeros(cap, np.uint32)
    nc, npo = np.zeros(1, np.uint32), np.zeros(1, np.uint32)
    rc = L.lidet_py_acc_cands_q(sensor.encode(), f"cls_{fam}_s8".encode(), f"box_{fam}_s8".encode(),
                                np.array([crop_half_bam, max_range_mm, 0], np.int32),
                                pts if n else np.zeros((1, 3), np.int32), n, pts.shape[1], xyz, mean, vox, cid, nc, npo)
    if rc < 0:
        raise LidetError(rc, "lidet_py_acc_cands_q")
    k = int(nc[0])
    return dict(xyz=xyz[:k], mean=mean[:k], voxel=vox[:k], cluster_id=cid[:k], n_points=_cand_points(L, 1, k))


def _cand_points(L, q: int, k: int) -> np.ndarray:
    """The cluster sizes (points) of the last candidates_float (q 0) / candidates_q (q 1) run's k candidates."""
    out = np.zeros(max(k, 1), np.uint32)
    rc = L.lidet_py_acc_cand_points(int(q), int(k), out)
    if rc < 0:
        raise LidetError(rc, "lidet_py_acc_cand_points")
    return out[:k]
