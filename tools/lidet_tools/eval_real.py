# SPDX-License-Identifier: MIT
"""`make eval-real`: the detector on the real labelled frames of ../shared/data/real, scored per source and class.

    python -m lidet_tools.eval_real [--root ../shared/data/real] [--side val] [--sources kitti,pandaset]
                                    [--out out/eval_real] [--fixed] [--model NAME] [--no-pictures] [--json]

The frames and their side (train / val) come from tools/lidet_tools/real/split.txt, fixed once; the figures of
docs/BENCHMARKS.md are those of the validation frames. Each frame is read by `lidet_tools.real` (boxes in the
sensor frame), run through the detector of the bindings (`native.detect`: the float detector, 360 degrees, the
source's sensor preset and mount height; `--fixed`: the integer detector, `native.detect_q`) and scored:

* ground truth: Car, Pedestrian, Cyclist boxes in the source's labelled field of view with at least
  ``--min-points`` (10) points inside (+ 0.1 m); every other labelled box (fewer points, vans, trucks,
  motorcycles, DontCare, ...) is an *ignore region*: a detection whose centre lies in one (+ 0.3 m) is neither
  right nor wrong;
* detections: in the labelled field of view, outside the ignore regions (on the KITTI frames also outside the
  DontCare image regions: the projected 2D box at least half inside one), of a class the source labels (KITTI-360:
  cars only);
* per class and range (within 20 m, within 40 m of the sensor, horizontal range of the box centre): recall and
  precision at the detector's operating point with the loose BEV overlaps (IoU >= 0.5 car, 0.25 pedestrian and
  cyclist; a detection matches at most one object, greedily by score), false positives per frame (all classes),
  AP R40 (`lidet_tools.eval.boxes_ap`: BEV and 3D, KITTI overlaps 0.7 / 0.5 / 0.5 and the loose ones);
* KITTI's own protocol on the KITTI frames (label_2 with 2D boxes, difficulties): AP R40 3D / BEV moderate;
* where each object within 40 m was lost (`lidet_tools.where_lost` over the points that won their pixel of the
  float projection, the ones the detector sees; either detector, but not through the CLI, i.e. not with `--set`,
  which gives no per-point labels), and the share of points seen per source: a
  sensor whose beams the preset does not describe (Argoverse's two stacked VLP-32C on `vlp32c`) loses many points
  to pixel collisions;
* a BEV picture per frame (ground truth green, detections by class, ignore regions grey) in OUT/pictures/.

Writes OUT/report.md and OUT/report.json and prints the report. Exit status 0; 2 when the folder is missing.

`--seeds K` runs the evaluation K times, each with another draw of the proposals' points (`--set proposal.seed=S`:
the default seed 0x5EED1234, then 1 .. K - 1), into OUT/seed_<S>/ (pictures of the first only), and writes
OUT/seeds.md and OUT/seeds.json: per seed the headline figures (all sources) with their mean, minimum and maximum.
On the 16 training frames the draw alone moves cars found by +-2, pedestrians by up to 4 and the false positives by
0.4 per frame (docs/EVALUATION.md, section 4): compare settings over several seeds (`lidet_tools.real.paired`
takes two such folders). `--vary ground` draws the ground stage's RANSAC hypotheses anew instead
(`--set stages.ground.seed=S`: the default 12345, then 1 .. K - 1), `--vary both` both together: the ground seed
alone moves the cars found on the training frames by as much as the proposals' draw (63-67 of 113).
"""
from __future__ import annotations

import argparse
import dataclasses
import json
import pathlib
import sys
import time
from dataclasses import dataclass, field

import numpy as np

from . import kitti, native
from .eval import boxes_ap, iou, kitti_ap
from .where_lost import STAGES, points_in_box, seen_points, where_lost

ROOT = pathlib.Path(__file__).resolve().parents[2]
SPLIT = pathlib.Path(__file__).resolve().parent / "real" / "split.txt"
CLASSES = ("Car", "Pedestrian", "Cyclist")
#: the loose BEV overlaps of issue 36's recall figures (and the KITTI ones, for AP)
LOOSE = {"Car": 0.5, "Pedestrian": 0.25, "Cyclist": 0.25}
RANGES = (20.0, 40.0)
IGNORE_MARGIN_M = 0.3
#: what a false positive covers, by the SemanticKITTI classes of the points in its box (frames with point labels)
FP_KINDS = (("vegetation, terrain", (70, 71, 72)), ("building, fence, structure", (50, 51, 52)),
            ("pole, sign, other object", (80, 81, 99)), ("road user (box off, or unlabelled)", tuple(range(10, 33)) +
                                                           tuple(range(252, 260))),
            ("ground", (40, 44, 48, 49, 60)))
#: sources whose labels cover only some classes: detections of the others cannot be judged and are not scored
LABELLED_CLASSES = {"kitti360": ("Car",)}


def read_split(path=SPLIT) -> list:
    """[(source, frame_id, side)] in file order; ValueError on a malformed line or a frame listed twice."""
    out, seen = [], set()
    for ln, line in enumerate(pathlib.Path(path).read_text().splitlines(), 1):
        p = line.split("#", 1)[0].split()
        if not p:
            continue
        if len(p) != 3 or p[2] not in ("train", "val"):
            raise ValueError(f"{path}:{ln}: expected '<source> <frame_id> train|val', got {line.strip()!r}")
        if (p[0], p[1]) in seen:
            raise ValueError(f"{path}:{ln}: {p[0]} {p[1]} listed twice")
        seen.add((p[0], p[1]))
        out.append((p[0], p[1], p[2]))
    return out


@dataclass
class FrameResult:
    source: str
    frame_id: str
    n_points: int
    gt: list                 # evaluated Box3D (the three classes, enough points, in the field of view)
    gt_points: list          # points inside each
    ignore: list             # Box3D ignore regions
    dets: list               # Box3D detections kept for scoring (in the field of view, outside ignore regions)
    dets_all: list           # every detection of the run
    lost: list = field(default_factory=list)   # where_lost stage per gt (within 40 m); not through the CLI
    ms: float = 0.0
    seen_share: float | None = None   # share of the points that won their pixel (float detector's projection)
    fp_kinds: list = field(default_factory=list)   # with point labels: FP_KINDS name of each wrong detection <= 40 m
    calib: object = None     # kitti.Calib for the KITTI frames (official protocol)
    label2: list = field(default_factory=list)
    run: object = None       # the float run's native.Detections (clusters, outcomes, point labels); None with the CLI


def _in_fov(x, y, fov_half_rad) -> bool:
    return fov_half_rad is None or abs(float(np.arctan2(y, x))) <= fov_half_rad


def _arr(b) -> np.ndarray:
    return np.array([b.x, b.y, b.z, b.l, b.w, b.h, b.yaw], dtype=np.float64)


def _run_detector(fr, fixed: bool, model: str | None, sets=()):
    """(detections as Box3D, native.Detections (the integer run: `_QRun`) or None, milliseconds)."""
    if sets:
        return _run_cli(fr, fixed, model, sets)
    if fixed:
        return _run_fixed(fr, model)
    t0 = time.perf_counter()
    d = native.detect(fr.points, fr.sensor, model=model, mount_height_m=fr.mount_height_m)
    ms = (time.perf_counter() - t0) * 1e3
    out = [kitti.Box3D(native.CLASSES[int(c)], *map(float, b), float(s)) for c, s, b in zip(d.cls, d.score, d.box)]
    return out, d, ms


@dataclass
class _QRun:
    """The integer detector's run in the fields `where_lost` reads (boxes in metres and radians)."""
    cls: np.ndarray
    score: np.ndarray
    box: np.ndarray
    cluster_id: np.ndarray
    outcome: np.ndarray
    point_cluster: np.ndarray
    point_ground: np.ndarray
    stats: dict


def _q_family(fr, model: str | None) -> str:
    from . import native
    return model or (fr.sensor if f"cls_{fr.sensor}_s8" in native.pnq_models() else "hdl64")


def _run_fixed(fr, model: str | None):
    """The integer detector through the bindings (`native.detect_q`: int8 models, the scan in millimetres, the
    source's mount height), with its per-point labels for where_lost; boxes converted as `lidet detect --fixed`
    does (mm * 1e-3, BAM32 / (2^32 / 2 pi), score_q15 / 32768)."""
    from . import native
    mm = native.to_mm(fr.points)
    t0 = time.perf_counter()
    q = native.detect_q(mm, fr.sensor, model=_q_family(fr, model), mount_height_m=fr.mount_height_m,
                        point_labels=True)
    ms = (time.perf_counter() - t0) * 1e3
    b = q["boxes"].astype(np.float64)
    box = np.empty((len(b), 7), np.float32)
    box[:, :6] = (b[:, :6] * 1e-3).astype(np.float32)
    box[:, 6] = (b[:, 6] / (4294967296.0 / (2.0 * np.pi))).astype(np.float32)
    score = (q["score_q15"].astype(np.float64) / 32768.0).astype(np.float32)
    run = _QRun(q["cls"].astype(np.int64), score, box, q["cluster_id"].astype(np.int64), q["outcome"],
                q["point_cluster"], q["point_ground"], q["stats"])
    out = [kitti.Box3D(native.CLASSES[int(c)], *map(float, bx), float(sc)) for c, sc, bx in zip(run.cls, score, box)]
    return out, run, ms


def _run_cli(fr, fixed: bool, model: str | None, sets=()):
    """The detector through the host CLI: the integer one (`lidet detect --fixed`: int8 models, the scan in
    millimetres), or either with stage settings (`--set KEY=VALUE`, which the bindings do not take); the source's
    mount height as the float run's. Milliseconds are the CLI's total_ms."""
    import subprocess
    import tempfile

    from . import native
    from .detect import find_cli
    if fixed:
        fam = _q_family(fr, model)
    else:
        fam = model or native.default_family(fr.sensor)
    with tempfile.TemporaryDirectory() as td:
        scan = pathlib.Path(td) / "scan.bin"
        kitti.write_bin(scan, fr.points)
        cmd = [str(find_cli()), "detect", str(scan), "--sensor", fr.sensor, "--model", fam,
               "--mount-height", repr(float(fr.mount_height_m)), "--json"] + (["--fixed"] if fixed else [])
        for kv in sets:
            cmd += ["--set", kv]
        r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)}: {r.stderr.strip()}")
    js = json.loads(r.stdout)
    out = [kitti.Box3D(b["class"], b["x"], b["y"], b["z"], b["l"], b["w"], b["h"], b["yaw"], b["score"])
           for b in js["boxes"]]
    return out, None, float(js["total_ms"])


def dontcare_test(calib, label2: list, min_ioa: float = 0.5):
    """For KITTI frames: a test of whether a sensor-frame detection falls in one of the frame's DontCare regions
    (2D image boxes without a 3D extent): its projected 2D box (kitti.box_to_kitti through P2, clipped to the image)
    lies at least min_ioa inside one, as the devkit assigns detections to DontCare regions. None without any."""
    regions = [o.bbox for o in label2 if o.type == "DontCare"]
    if not regions:
        return None

    def inside(b) -> bool:
        if b.x <= 0.5:  # behind or beside the camera: no image box
            return False
        x1, y1, x2, y2 = kitti.box_to_kitti(b, calib).bbox
        area = max(x2 - x1, 0.0) * max(y2 - y1, 0.0)
        if area <= 0.0:
            return False
        for r in regions:
            w = min(x2, r[2]) - max(x1, r[0])
            h = min(y2, r[3]) - max(y1, r[1])
            if w > 0 and h > 0 and w * h >= min_ioa * area:
                return True
        return False
    return inside


def evaluate_frame(fr, fixed=False, model=None, min_points=10, sets=(), dontcare=None) -> FrameResult:
    """Run the detector on one `real.RealFrame` and sort its boxes into ground truth, ignore regions and
    detections (dontcare: dontcare_test's test, for KITTI frames)."""
    xyz = fr.points[:, :3]
    gt, gt_pts, ignore = [], [], []
    for b in fr.boxes:
        if not _in_fov(b.x, b.y, fr.fov_half_rad):
            continue
        n = int(points_in_box(xyz, _arr(b)).sum())
        if b.cls in CLASSES and n >= min_points:
            gt.append(b)
            gt_pts.append(n)
        else:
            ignore.append(b)
    dets_all, d, ms = _run_detector(fr, fixed, model, sets)
    dets = []
    labelled = LABELLED_CLASSES.get(fr.source, CLASSES)
    for b in dets_all:
        if b.cls not in labelled or not _in_fov(b.x, b.y, fr.fov_half_rad):
            continue
        c = np.array([[b.x, b.y, b.z]])
        if any(points_in_box(c, _arr(g), IGNORE_MARGIN_M)[0] for g in ignore):
            continue
        if dontcare is not None and dontcare(b):
            continue
        dets.append(b)
    res = FrameResult(fr.source, fr.frame_id, len(fr.points), gt, gt_pts, ignore, dets, dets_all, ms=ms, run=d)
    if getattr(fr, "point_semantic", None) is not None:
        res.fp_kinds = fp_kinds(fr.points, fr.point_semantic, gt, dets)
    if d is not None:
        near = [g for g in gt if np.hypot(g.x, g.y) <= RANGES[-1]]
        few = int(native.cluster_defaults(fr.sensor)["min_points"])

        def hit(db, gb, cls):
            return float(iou.iou_bev_pairs(db[None], gb[None])[0]) >= LOOSE[cls]

        seen = seen_points(fr.points, fr.sensor)
        res.seen_share = float(seen.mean())
        stages = where_lost(fr.points, np.array([_arr(g) for g in near]).reshape(-1, 7), [g.cls for g in near], d,
                            few, hit, native.CLASSES, seen=seen)
        res.lost = list(zip([g.cls for g in near], stages))
    return res


def fp_kinds(points, sem, gt: list, dets: list, max_range: float = RANGES[-1]) -> list:
    """What each detection within max_range that overlaps no object of its class (loose BEV overlap) covers: the
    FP_KINDS group holding most labelled points of its box, 'other' for the rest, 'empty' without points."""
    out = []
    for d in dets:
        if np.hypot(d.x, d.y) > max_range:
            continue
        g = [x for x in gt if x.cls == d.cls]
        if g and iou.iou_bev(_arr(d)[None], np.array([_arr(x) for x in g])).max() >= LOOSE[d.cls]:
            continue
        lab = np.asarray(sem)[points_in_box(points, _arr(d))]
        if len(lab) == 0:
            out.append("empty")
            continue
        counts = [(int(np.isin(lab, ids).sum()), name) for name, ids in FP_KINDS]
        n, name = max(counts)
        out.append(name if n > 0 else "other")
    return out


def match(gt: list, dets: list, cls: str, max_range: float, thr: float) -> tuple[int, int, int, int]:
    """(objects, found, detections, right) of one class within max_range at BEV IoU >= thr: each detection,
    strongest first, takes the unmatched object it overlaps most. A detection that overlaps an object of its
    class beyond max_range (up to 2 m further) is not counted at all."""
    g = [x for x in gt if x.cls == cls]
    d = sorted((x for x in dets if x.cls == cls and np.hypot(x.x, x.y) <= max_range), key=lambda x: -x.score)
    if not d:
        return int(sum(np.hypot(x.x, x.y) <= max_range for x in g)), 0, 0, 0
    ov = iou.iou_bev(np.array([_arr(x) for x in d]), np.array([_arr(x) for x in g]).reshape(-1, 7)) if g else \
        np.zeros((len(d), 0))
    inr = np.array([np.hypot(x.x, x.y) <= max_range for x in g], dtype=bool)
    used = np.zeros(len(g), dtype=bool)
    found = n_det = right = 0
    for i in range(len(d)):
        cand = np.where(~used & (ov[i] >= thr))[0] if len(g) else np.zeros(0, np.int64)
        if len(cand):
            k = cand[np.argmax(ov[i, cand])]
            used[k] = True
            if inr[k]:
                found += 1
                right += 1
                n_det += 1
            # a match beyond max_range: neither counted nor missed
            continue
        n_det += 1
    return int(inr.sum()), found, n_det, right


def frame_counts(r) -> dict:
    """One frame's tallies at the loose overlaps, {range: {class: [objects, found, detections, right]}}: what
    report.json keeps per frame, so that two runs can be compared frame by frame (lidet_tools.real.paired)."""
    return {f"{rng:g}": {c: list(match(r.gt, r.dets, c, rng, LOOSE[c])) for c in CLASSES} for rng in RANGES}


def _boxset(frames: list) -> boxes_ap.BoxSet:
    return boxes_ap.boxset_from_frames(frames)


def ap_table(results: list) -> dict:
    """AP R40 per class, metric, overlap and range (boxes_ap.evaluate with the bands 'within 20 m' / 'within 40 m')."""
    bands = tuple((f"{r:g} m", 0.0, r) for r in RANGES)
    gt, dt = _boxset([r.gt for r in results]), _boxset([r.dets for r in results])
    out = {}
    for ov in ("kitti", "loose"):
        res = boxes_ap.evaluate(gt, dt, classes=CLASSES, overlap=ov, bands=bands, exact=True)
        out[ov] = {c: {m: res["ap"][c][m]["R40"] for m in ("bev", "3d")} for c in CLASSES}
    return out


def kitti_official(results: list, exact: bool = True) -> dict | None:
    """KITTI's protocol (label_2, difficulties) on the KITTI frames: AP R40 moderate per class, 3D and BEV
    (exact: interpolated at every true positive, see engine.pr_statistics; False: the devkit's sampling)."""
    ks = [r for r in results if r.calib is not None]
    if not ks:
        return None
    gts, dts = [], []
    for r in ks:
        gts.append(r.label2)
        dts.append([kitti.box_to_kitti(b, r.calib, score=b.score) for b in r.dets_all
                    if b.x > 0.5 and _in_fov(b.x, b.y, np.radians(45.0))])
    res = kitti_ap.evaluate(kitti_ap.labelset_from_objects(gts), kitti_ap.labelset_from_objects(dts),
                            metrics=("3d", "bev", "2d"), exact=exact)
    return {c: {m: res["ap"][c][m]["R40"] for m in ("3d", "bev")} for c in CLASSES}


def summarize(results: list) -> dict:
    """Per source (and 'all'): frames, objects, recall / precision per class and range, FP per frame, AP, where lost."""
    groups = {}
    tallies = {id(r): frame_counts(r) for r in results}  # matched once per frame; every group sums them
    for r in results:
        groups.setdefault(r.source, []).append(r)
    if len(groups) > 1:
        groups["all"] = list(results)
    out = {}
    for src, rs in groups.items():
        s = {"frames": len(rs), "classes": {}, "fp_per_frame": {}, "ms_median": float(np.median([r.ms for r in rs]))}
        shares = [r.seen_share for r in rs if r.seen_share is not None]
        s["seen_share"] = float(np.mean(shares)) if shares else None
        for rng in RANGES:
            fp = 0
            for c in CLASSES:
                n_obj = found = n_det = right = 0
                for r in rs:
                    a, b, cnt, ok = tallies[id(r)][f"{rng:g}"][c]
                    n_obj, found, n_det, right = n_obj + a, found + b, n_det + cnt, right + ok
                fp += n_det - right
                s["classes"].setdefault(c, {})[f"{rng:g}"] = {
                    "objects": n_obj, "found": found, "detections": n_det,
                    "recall": found / n_obj if n_obj else None, "precision": right / n_det if n_det else None}
            s["fp_per_frame"][f"{rng:g}"] = fp / len(rs)
        s["ap"] = ap_table(rs)
        lost = {c: dict.fromkeys(STAGES, 0) for c in CLASSES}
        for r in rs:
            for c, st in r.lost:
                lost[c][st] += 1
        s["where_lost"] = lost
        kinds = [k for r in rs for k in r.fp_kinds]
        if kinds:
            s["fp_kinds"] = {k: kinds.count(k) for k in sorted(set(kinds))}
        if src != "all":
            s["kitti_official"] = kitti_official(rs)
            s["kitti_devkit"] = kitti_official(rs, exact=False)
        out[src] = s
    return out


def _f(v) -> str:
    return "-" if v is None else f"{v:.2f}"


def _p(v) -> str:
    """An AP (already in percent)."""
    return "-" if v is None else f"{v:.1f}"


def format_report(summary: dict, meta: dict) -> str:
    L = [f"Real labelled frames, side `{meta['side']}` of tools/lidet_tools/real/split.txt, detector: "
         f"{meta['detector']}. Command: `{meta['command']}`.", "",
         "Recall and precision at the detector's operating point, BEV IoU >= 0.5 car / 0.25 pedestrian and cyclist, "
         f"objects with >= {meta['min_points']} points in the labelled field of view; FP/frame: detections of any "
         "class matching no object, per frame; points seen: the share of the scan's points that win a pixel of the "
         "projection (the rest collide with another point of the same pixel).", "",
         "| source | frames | range | car found | car prec. | ped found | ped prec. | cyc found | cyc prec. | FP/frame | "
         "ms/frame | points seen |", "|---|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for src, s in summary.items():
        for rng in RANGES:
            k = f"{rng:g}"
            row = [src, str(s["frames"]), f"<= {k} m"]
            for c in CLASSES:
                v = s["classes"][c][k]
                row.append(f"{v['found']} / {v['objects']}" + (f" ({_f(v['recall'])})" if v["objects"] else ""))
                row.append(_f(v["precision"]))
            row += [f"{s['fp_per_frame'][k]:.2f}", f"{s['ms_median']:.1f}",
                    "-" if s.get("seen_share") is None else f"{100 * s['seen_share']:.0f} %"]
            L.append("| " + " | ".join(row) + " |")
    L += ["", "AP R40 (percent; `lidet_tools.eval.boxes_ap`, sensor frame, the objects above within the range; KITTI "
          "overlaps 0.7 / 0.5 / 0.5, loose 0.5 / 0.25 / 0.25; interpolated at every true positive, `exact`):", "",
          "| source | range | car 3D | car BEV | car BEV loose | ped 3D | ped BEV | ped BEV loose | cyc 3D | cyc BEV | "
          "cyc BEV loose |", "|---|---|" + "---:|" * 9]
    for src, s in summary.items():
        for rng in RANGES:
            k = f"{rng:g} m"
            row = [src, f"<= {k}"]
            for c in CLASSES:
                row += [_p(s["ap"]["kitti"][c]["3d"][k]), _p(s["ap"]["kitti"][c]["bev"][k]),
                        _p(s["ap"]["loose"][c]["bev"][k])]
            L.append("| " + " | ".join(row) + " |")
    ko = [(src, s) for src, s in summary.items() if s.get("kitti_official")]
    if ko:
        L += ["", "KITTI's protocol on the KITTI frames (label_2, camera frame, difficulties, strict overlaps 0.7 / 0.5 / "
              "0.5), AP R40 moderate: interpolated at every true positive, and (devkit) with the devkit's 41 score "
              "thresholds, which cap AP near n / 40 for a class of n < 40 objects:", "",
              "| source | frames | car 3D | car BEV | ped 3D | ped BEV | cyc 3D | cyc BEV | car 3D (devkit) |",
              "|---|---:|" + "---:|" * 7]
        for src, s in ko:
            k, dk = s["kitti_official"], s["kitti_devkit"]
            row = [src, str(s["frames"])]
            for c in CLASSES:
                row += [_p(k[c]["3d"].get("moderate")), _p(k[c]["bev"].get("moderate"))]
            row.append(_p(dk["Car"]["3d"].get("moderate")))
            L.append("| " + " | ".join(row) + " |")
    fk = [(src, s) for src, s in summary.items() if s.get("fp_kinds") and src != "all"]
    if fk:
        L += ["", "What the wrong detections within 40 m cover, on the frames with per-point labels (the labelled class "
              "group holding most points of the box):", "", "| source | frames | wrong detections | what they cover |",
              "|---|---:|---:|---|"]
        for src, s in fk:
            k = s["fp_kinds"]
            L.append(f"| {src} | {s['frames']} | {sum(k.values())} | " +
                     ", ".join(f"{name} {n}" for name, n in sorted(k.items(), key=lambda x: -x[1])) + " |")
    if any(sum(sum(v.values()) for v in s["where_lost"].values()) for s in summary.values()):
        L += ["", f"Where the objects within 40 m were lost (`lidet_tools.where_lost`; the {meta['detector'].split(',')[0]} detector):", "",
              "| source | class | " + " | ".join(STAGES) + " |", "|---|---|" + "---:|" * len(STAGES)]
        for src, s in summary.items():
            for c in CLASSES:
                row = s["where_lost"][c]
                if sum(row.values()):
                    L.append(f"| {src} | {c} ({sum(row.values())}) | " + " | ".join(str(row[x]) for x in STAGES) + " |")
    return "\n".join(L) + "\n"


def _json_num(v):
    """numpy scalars in the JSON report."""
    if isinstance(v, np.generic):
        return v.item()
    raise TypeError(f"not JSON serializable: {type(v).__name__}")


def picture(r: FrameResult, fr, path) -> None:
    """BEV of the frame: ground truth (green), every detection of the run (dashed, by class), ignore regions
    (dark, dashed) and the labelled field of view (dotted wedge)."""
    import matplotlib.pyplot as plt

    from .viz.bev import box_outline, plot_bev
    n = {c: sum(g.cls == c for g in r.gt) for c in CLASSES}
    title = (f"{r.source} {r.frame_id} ({fr.sensor}, {r.n_points} points, {r.ms:.1f} ms)\n"
             f"ground truth {n['Car']} car / {n['Pedestrian']} ped / {n['Cyclist']} cyc; "
             f"{len(r.dets_all)} detections, {len(r.dets)} scored; grey: {len(r.ignore)} ignored boxes")
    fig = plot_bev(fr.points, gt_boxes=r.gt, pred_boxes=r.dets_all, title=title, view_m=45.0, show_gt_class=True)
    ax = fig.axes[0]
    for g in r.ignore:
        if np.hypot(g.x, g.y) < 70 and g.l > 0 and g.w > 0:
            o = box_outline(g)
            ax.plot(o[:, 0], o[:, 1], color="#7f7f7f", lw=1.0, ls="-.", zorder=4)
    if fr.fov_half_rad is not None:
        for sgn in (-1.0, 1.0):
            a = sgn * fr.fov_half_rad
            ax.plot([0, 64 * np.cos(a)], [0, 64 * np.sin(a)], ls=":", lw=1.2, color="#444444", zorder=3)
    fig.savefig(path)
    plt.close(fig)


def add_frame_args(ap: argparse.ArgumentParser) -> None:
    """--root and --split, as every command over the real frames takes them."""
    ap.add_argument("--root", default=str(ROOT.parent / "shared" / "data" / "real"),
                    help="the real frames (default ../shared/data/real beside the repository)")
    ap.add_argument("--split", default=str(SPLIT), help="the split file (default: the repository's)")


#: the resampling seeds of `--seeds K`: the detectors' default (lidet_proposal_cfg_t.seed), then 1, 2, ...
DEFAULT_PROPOSAL_SEED = 0x5EED1234
#: the ground RANSAC's seeds of `--seeds K --vary ground|both`: the stage's default (lidet_ground_cfg_t.seed), then
#: 1, 2, ...
DEFAULT_GROUND_SEED = 12345
#: what `--seeds K` draws anew in each run: the proposals' points, the ground stage's RANSAC hypotheses, or both
VARY = {"proposal": ("proposal.seed",), "ground": ("stages.ground.seed",),
        "both": ("proposal.seed", "stages.ground.seed")}
_VARY_TEXT = {"proposal": "draws of the proposals' points (`--set proposal.seed=S`)",
              "ground": "draws of the ground stage's RANSAC hypotheses (`--set stages.ground.seed=S`)",
              "both": "draws of the proposals' points and of the ground stage's RANSAC hypotheses together "
                      "(`--set proposal.seed=S --set stages.ground.seed=S`)"}


def seed_list(k: int, default: int = DEFAULT_PROPOSAL_SEED) -> list[int]:
    """The first k seeds of `--seeds`: the default seed, then 1 .. k - 1."""
    return [default] + list(range(1, k))


def vary_sets(vary: str, j: int) -> list[str]:
    """The --set arguments of run j (0: the defaults) of `--seeds K --vary VARY`."""
    return [f"{key}={seed_list(j + 1, DEFAULT_PROPOSAL_SEED if key == 'proposal.seed' else DEFAULT_GROUND_SEED)[j]}"
            for key in VARY[vary]]


def _headline(sm: dict) -> dict:
    """The headline figures of seeds.md from a report's summary (its 'all' entry): per range the objects found per
    class, false positives per frame, and the car and pedestrian AP R40 (3D at KITTI's overlaps, BEV loose); with
    KITTI frames among the sources, also their car and pedestrian AP3D moderate by KITTI's protocol. A summary of
    one source has no 'all' entry: that source's."""
    a = sm["all"] if "all" in sm else next(iter(sm.values()))
    cl, ap3, loose = a["classes"], a["ap"]["kitti"], a["ap"]["loose"]
    out = {}
    for rng in ("20", "40"):
        for c in CLASSES:
            out[f"{c} found {rng} m"] = cl[c][rng]["found"]
        out[f"FP/frame {rng} m"] = a["fp_per_frame"][rng]
        out[f"car AP3D {rng} m"] = ap3["Car"]["3d"][f"{rng} m"]
        out[f"car AP BEV loose {rng} m"] = loose["Car"]["bev"][f"{rng} m"]
        out[f"ped AP3D {rng} m"] = ap3["Pedestrian"]["3d"][f"{rng} m"]
        out[f"ped AP BEV loose {rng} m"] = loose["Pedestrian"]["bev"][f"{rng} m"]
    # KITTI's protocol on the KITTI frames (camera frame, difficulties), the figure the goal names
    ko = (sm.get("kitti") or {}).get("kitti_official") if "all" in sm else None
    for c, short in (("Car", "car"), ("Pedestrian", "ped")):
        if ko:
            out[f"KITTI frames: {short} AP3D moderate"] = ko[c]["3d"]["moderate"]
    return out


def seeds_report(rows: dict, meta: dict) -> tuple[str, dict]:
    """seeds.md text and seeds.json dict from {seed: headline dict} (_headline) of the same frames."""
    seeds = list(rows)
    keys = list(rows[seeds[0]])
    objs = meta.get("objects", {})
    stats = {}
    for k in keys:
        v = [rows[s][k] for s in seeds if rows[s][k] is not None]
        stats[k] = None if not v else {"mean": float(np.mean(v)), "min": float(np.min(v)), "max": float(np.max(v))}
    L = [f"Real labelled frames, side `{meta['side']}`, detector: {meta['detector']}; {len(seeds)} "
         f"{_VARY_TEXT[meta.get('vary', 'proposal')]}. Command: `" + meta["command"] + "`.", "",
         "| figure | " + " | ".join("default" if j == 0 else f"seed {s}" for j, s in enumerate(seeds)) +
         " | mean | min - max |",
         "|---|" + "---:|" * (len(seeds) + 2)]

    def fmt(k, v):
        if v is None:
            return "-"
        return f"{v:.0f}" if " found " in k else f"{v:.2f}" if k.startswith("FP") else f"{v:.1f}"
    for k in keys:
        st = stats[k]
        name = k + (f" (of {objs[k]})" if k in objs else "")
        cells = [fmt(k, rows[s][k]) for s in seeds]
        mean = None if st is None else f"{st['mean']:.2f}" if k.startswith("FP") else f"{st['mean']:.1f}"
        tail = ["-", "-"] if st is None else [mean, f"{fmt(k, st['min'])} - {fmt(k, st['max'])}"]
        L.append(f"| {name} | " + " | ".join(cells + tail) + " |")
    return "\n".join(L) + "\n", {"meta": meta, "seeds": seeds, "per_seed": {str(s): rows[s] for s in seeds},
                                  "stats": stats}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m lidet_tools.eval_real", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    add_frame_args(ap)
    ap.add_argument("--side", choices=("val", "train", "all"), default="val")
    ap.add_argument("--sources", help="comma-separated sources (default: every source in the split)")
    ap.add_argument("--out", default="out/eval_real", help="report.md, report.json, pictures/")
    ap.add_argument("--fixed", action="store_true", help="the integer detector (int8 models, millimetres)")
    ap.add_argument("--model", help="model family (default: the sensor's)")
    ap.add_argument("--min-points", type=int, default=10, help="objects with fewer points are ignored (default 10)")
    ap.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                    help="a stage setting (lidet detect --set; the run goes through the CLI, without the where-lost "
                         "table)")
    ap.add_argument("--as-sensor", metavar="NAME",
                    help="thin the 64-beam frames (hdl64, pandar64) to the beams of this preset (vlp16, vlp32c: "
                         "lidet_tools.real.thin) and run its detector on them; frames of other sensors are left out")
    ap.add_argument("--round-mm", action="store_true",
                    help="feed the detector each scan rounded to whole millimetres, the input the integer detector "
                         "takes (`--fixed` rounds it so anyway): a float run on it tells the integer arithmetic's "
                         "effect apart from the input's rounding")
    ap.add_argument("--seeds", type=int, default=1, metavar="K",
                    help="K draws of the proposals' points (the default seed, then 1 .. K - 1) into OUT/seed_<S>/, "
                         "and OUT/seeds.md with each seed's headline figures, their mean and range (default 1: one "
                         "run with the detector's own seed)")
    ap.add_argument("--vary", choices=sorted(VARY), default="proposal",
                    help="what --seeds draws anew: the proposals' points (default), the ground stage's RANSAC "
                         "hypotheses (stages.ground.seed: its default 12345, then 1 .. K - 1), or both together; "
                         "the ground seed moves the real figures about as much as the proposals' draw")
    ap.add_argument("--no-pictures", action="store_true")
    ap.add_argument("--json", action="store_true", help="print report.json instead of the tables")
    a = ap.parse_args(argv)
    if a.seeds < 1 or a.seeds > 64:
        ap.error(f"--seeds must be in [1, 64], got {a.seeds}")
    if a.vary != "proposal" and a.seeds < 2:
        ap.error("--vary needs --seeds K with K >= 2")
    if a.seeds > 1:
        for key in VARY[a.vary]:
            if any(kv.split("=", 1)[0].strip() == key for kv in a.set):
                ap.error(f"--seeds sets {key} itself: leave --set {key} out")
        return _main_seeds(ap, a)
    return _evaluate(ap, a)


def _evaluate(ap, a, echo: bool = True) -> int:
    """One evaluation with the parsed arguments `a` (ap: their parser, for its errors); prints the report when echo."""
    from . import real
    from .real import thin
    if a.as_sensor:
        from .sensors import SENSORS
        if a.as_sensor not in SENSORS or a.as_sensor in real.HDL64_LIKE:
            ap.error(f"--as-sensor: a preset sparser than hdl64 "
                     f"({', '.join(n for n in SENSORS if n not in real.HDL64_LIKE)})")
    root = pathlib.Path(a.root)
    if not root.is_dir():
        print(f"eval_real: {root} not found (the real frames live in ../shared/data/real; nothing to do)",
              file=sys.stderr)
        return 2
    frames = [(s, f) for s, f, side in read_split(a.split) if a.side in ("all", side)]
    if a.sources:
        want = a.sources.split(",")
        bad = sorted(set(want) - set(real.SOURCES))
        if bad:
            ap.error(f"unknown source(s) {', '.join(bad)}; sources: {', '.join(real.SOURCES)}")
        frames = [x for x in frames if x[0] in want]
    out = pathlib.Path(a.out)
    (out / "pictures").mkdir(parents=True, exist_ok=True)
    results = []
    for src, fid in frames:
        try:
            fr = real.load_frame(root, src, fid)
        except FileNotFoundError as e:
            print(f"eval_real: skipping {src} {fid}: {e}", file=sys.stderr)
            continue
        if a.as_sensor:
            if fr.sensor not in real.HDL64_LIKE:
                continue
            fr = dataclasses.replace(fr, points=thin.thin(fr.points, fr.sensor, a.as_sensor), sensor=a.as_sensor,
                                     point_instance=None, point_semantic=None)
        if a.round_mm:
            pts = fr.points.copy()
            pts[:, :3] = (np.round(pts[:, :3].astype(np.float64) * 1000.0) / 1000.0).astype(pts.dtype)
            fr = dataclasses.replace(fr, points=pts)
        calib, label2, dc = None, [], None
        if src == "kitti":
            base = root / "kitti" / "training"
            calib = kitti.read_calib(base / "calib" / f"{fid}.txt")
            label2 = kitti.read_label2(base / "label_2" / f"{fid}.txt")
            dc = dontcare_test(calib, label2)
        r = evaluate_frame(fr, a.fixed, a.model, a.min_points, a.set, dontcare=dc)
        r.calib, r.label2 = calib, label2
        results.append(r)
        if not a.no_pictures:
            picture(r, fr, out / "pictures" / f"{src}_{fid}.png")
    if not results:
        print("eval_real: no frames", file=sys.stderr)
        return 2
    summary = summarize(results)
    cmd = "python -m lidet_tools.eval_real" + (f" --side {a.side}" if a.side != "val" else "") + \
        (" --fixed" if a.fixed else "") + (f" --sources {a.sources}" if a.sources else "") + \
        (f" --as-sensor {a.as_sensor}" if a.as_sensor else "") + (f" --model {a.model}" if a.model else "") + \
        (" --round-mm" if a.round_mm else "") + "".join(f" --set {kv}" for kv in a.set)
    meta = {"side": a.side, "detector": ("integer (int8)" if a.fixed else "float") +
            (f", HDL-64 frames thinned to {a.as_sensor}" if a.as_sensor else "") + (f", models {a.model}" if a.model else "") +
            (", scans rounded to millimetres" if a.round_mm else "") +
            "".join(f", {kv}" for kv in a.set), "command": cmd, "min_points": a.min_points}
    text = format_report(summary, meta)
    (out / "report.md").write_text(text)
    per_frame = [{"source": r.source, "frame": r.frame_id, "objects": len(r.gt), "detections": len(r.dets),
                  "ms": r.ms, "lost": r.lost, "counts": frame_counts(r)} for r in results]
    (out / "report.json").write_text(json.dumps({"meta": meta, "summary": summary, "frames": per_frame}, indent=1, default=_json_num))
    if echo:
        print(json.dumps(summary, indent=1, default=_json_num) if a.json else text)
    return 0


def _main_seeds(ap, a) -> int:
    """`--seeds K`: one evaluation per seed into OUT/seed_<S>/ (the seed's --set after the others), then
    OUT/seeds.md and seeds.json."""
    out = pathlib.Path(a.out)
    rows, meta = {}, None
    default = DEFAULT_GROUND_SEED if a.vary == "ground" else DEFAULT_PROPOSAL_SEED
    for j, sd in enumerate(seed_list(a.seeds, default)):
        sub = out / f"seed_{sd}"
        one = argparse.Namespace(**vars(a))
        one.set, one.out, one.json = a.set + vary_sets(a.vary, j), str(sub), False
        one.no_pictures = a.no_pictures or j > 0
        rc = _evaluate(ap, one, echo=False)  # each seed's report is in its folder
        if rc != 0:
            return rc
        rep = json.loads((sub / "report.json").read_text())
        rows[sd] = _headline(rep["summary"])
        if meta is None:
            sm = rep["summary"]
            cl = (sm["all"] if "all" in sm else next(iter(sm.values())))["classes"]
            meta = dict(rep["meta"])
            # the seeds' own --set are the last ones: cut them, name --seeds (and --vary) instead
            first = VARY[a.vary][0]
            meta["command"] = (meta["command"].split(f" --set {first}=")[0] + f" --seeds {a.seeds}" +
                               ("" if a.vary == "proposal" else f" --vary {a.vary}"))
            meta["detector"] = meta["detector"].split(f", {first}=")[0]
            meta["vary"] = a.vary
            meta["objects"] = {f"{c} found {r} m": cl[c][r]["objects"] for c in CLASSES for r in ("20", "40")}
    text, js = seeds_report(rows, meta)
    (out / "seeds.md").write_text(text)
    (out / "seeds.json").write_text(json.dumps(js, indent=1, default=_json_num))
    print(json.dumps(js, indent=1, default=_json_num) if a.json else text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
