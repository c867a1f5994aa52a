# SPDX-License-Identifier: MIT
"""The integer detector, bit for bit as lib/src/detector/lidet_detector_q.c: the integer stages' references chained
(proj_q -> ground_q -> cluster_q -> proposals -> pointnet_q -> post_q) with the detector's own rules (the
candidate window, range and order, the budget, the gates, the size check, the score and the NMS).

Configurations are the C structs' fields as dicts (tests read the C defaults through the bindings); models are
the quantized models of lidet_codegen.quant (the same the C descriptors are generated from).
"""
from __future__ import annotations

import numpy as np

from lidet_ref import cluster_q, ground_q, group_q, pointnet_q, post_q, proj_q, qmath

(OUT_CROP, OUT_RANGE, OUT_BUDGET, OUT_GATE1, OUT_GATE2, OUT_SIZE, OUT_NMS, OUT_CAPACITY, OUT_DETECTED, OUT_TALL,
 OUT_GROUP, OUT_SCORE) = range(1, 13)
#: LIDET_DET_FLAT_MIN_POINTS: member pixels a car's cluster needs before the flat-surface test judges it
FLAT_MIN_POINTS = 100
#: lidet_detector_common.h LIDET_DET_GROUND_*: the car boxes' ground (lidet_detector_q.c car_to_ground)
GROUND_MIN_PIXELS, GROUND_WINDOW_MM, GROUND_BIN_MM, GROUND_MAX_LIFT_MM = 5, 1000, 20, 500
#: lidet_detector_q_cfg_default's gate2_class: gate 2 judges cars and cyclists, pedestrians pass it
GATE2_CLASS = (1, 1, 0)


LN64_Q16 = 272557  # round(ln(64) * 2^16)


def score_q15(energy_q16: int, gamma_q16: int) -> int:
    """1 / (1 + exp(E - gamma)) in Q15 (lidet_detector_q_score)."""
    t = int(energy_q16) - int(gamma_q16)
    e = 1 << 30 if t == 0 else int(pointnet_q._exp_neg(np.array([abs(t)], np.int64))[0])
    one = 1 << 30
    return (e << 15) // (one + e) if t >= 0 else (one << 15) // (one + e)


def detection_score_q15(e_cls: int, e_box: int, n_points: int, gamma_cls: int, gamma_box: int, w_q16: int,
                        v_q16: int) -> int:
    """A detection's score (lidet_detector_q.c fill_detection): score_q15 of E1 + round(w (E2 - gamma2)) -
    round(v ln(n / 64)) (Q16, saturated to int32) against gamma1; the ln term only where v is not 0."""
    e = e_cls + int(qmath.rshift_round((e_box - gamma_box) * w_q16, 16))
    if v_q16:
        ln_n = int(pointnet_q._ln_q16(np.int64(max(n_points, 1)) << 30)) - LN64_Q16
        e -= int(qmath.rshift_round(ln_n * v_q16, 16))
    return score_q15(min(max(e, -(1 << 31)), (1 << 31) - 1), gamma_cls)


def candidates(recs, det_cfg: dict, outcome: list) -> tuple[list, bool]:
    """Kept clusters in the azimuth window, not taller than max_height_extent_mm (0: no limit; the z span in 4 mm
    steps times 4) and in range, nearest first (ties: lower index), at most max_proposals."""
    h = int(det_cfg["crop_half_bam"])
    cs = int(qmath.sin(h)) if h > 0 else 0
    cc = int(qmath.cos(h)) if h > 0 else 0
    mr = int(det_cfg["max_range_mm"])
    tall = int(det_cfg["max_height_extent_mm"])
    cand = []
    for i, r in enumerate(recs):
        x, y = int(r.mean[0]), int(r.mean[1])
        r2 = x * x + y * y
        if h > 0 and not (x * cs >= abs(y) * cc):
            outcome[i] = OUT_CROP
            continue
        if tall > 0 and 4 * (int(r.max[2]) - int(r.min[2])) > tall:
            outcome[i] = OUT_TALL
            continue
        if mr > 0 and 16 * r2 > mr * mr:
            outcome[i] = OUT_RANGE
            continue
        cand.append((r2, i))
    cand.sort()
    truncated = len(cand) > det_cfg["max_proposals"]
    for _, i in cand[det_cfg["max_proposals"]:]:
        outcome[i] = OUT_BUDGET
    return [i for _, i in cand[: det_cfg["max_proposals"]]], truncated


def detect(points_mm, tab, proj_cfg: dict, ground_cfg: dict, cluster_cfg: dict, proposal_cfg: dict, det_cfg: dict,
           cls_model, box_model, max_clusters: int, max_detections: int, max_points: int, range_only: bool = False,
           returns=None) -> dict:
    """The whole integer detector on (N, 3) int32 mm points. det_cfg: crop_half_bam, max_range_mm, max_height_extent_mm,
    max_proposals, max_boxes, gate1, gate2, nms_iou_q15, size_min (3x3 mm), size_max, score_box_weight_q16 (3), score_points_weight_q16 (3), and optionally gate1_margin_q16 / gate2_margin_q16
    (0 when absent: the models' gammas), stream_sectors (0 when absent; 1: a RANSAC stream per ground cell, as
    lidet_detector_q_cfg_t.stream_sectors sets), gate2_class (3 flags, lidet_class_t order: the classes gate 2 judges;
    GATE2_CLASS when absent, the C default), group_split (0 when absent; the C default is 1 for > 16 rows) and
    group_max_range_mm (40000 when absent), min_score_q15 (3, the operating point; 0s when absent: off; the C
    default is 19661 for cars), gate1_class_margin_q16 (3, added to gate1_margin_q16 per class; 0s
    when absent, the C default), group_gate1_margin_q16 (added to gate 1 when the group split judges a cut; 0 when
    absent: every part must pass; the C default is 2 * 65536), gate1_large_car_margin_q16 (added to gate 1 for a
    car whose cluster holds >= FLAT_MIN_POINTS members; 0 when absent), car_min_z_spread_mm (the cars'
    flat-surface test; 0 when absent: off; the C default is 600) and car_ground_mm (car boxes down to the ground
    around them, `ground_box`; 0 when absent: off; the C default is 1000). range_only: the image keeps only the range, every stage reads x, y, z
    decoded from row, column and range (qmath.decode_pixels; lidet_detector_q_cfg_t range_only). Returns detections
    (dicts), outcomes, stats. returns: (range_mm, azimuth, ring) instead of points_mm (lidet_detector_q_run_returns:
    proj_q.project_returns)."""
    if returns is not None:
        pj = proj_q.project_returns(*returns, tab, proj_cfg["min_range_mm"], proj_cfg["max_range_mm"],
                                    max_points=max_points)
    else:
        pj = proj_q.project(points_mm, tab, proj_cfg["min_range_mm"], proj_cfg["max_range_mm"], max_points=max_points)
    rows, cols = tab.rows, tab.cols
    X, Y, Z, R = (np.asarray(pj[k], np.int64).reshape(rows, cols) for k in ("x_4mm", "y_4mm", "z_4mm", "range_4mm"))
    RG = None  # the ground stage's R: from x, y, or from the range of a range-only image
    if range_only:
        X, Y, Z = qmath.decode_pixels(R, tab.row_elev_bam)
        RG = ground_q.r_of_range(R, tab.row_elev_bam)
    if int(det_cfg["crop_half_bam"]) > 0 or int(det_cfg.get("stream_sectors", 0)):
        # the crop, or the ground streamed sector by sector: a RANSAC stream per ground cell (lidet_detector_q_init;
        # a streamed run's results are the whole scan's with it, so the reference has no streaming of its own)
        ground_cfg = dict(ground_cfg, seed_per_cell=1)
    mask, _, planes, _, _, _ = ground_q.ground(X, Y, Z, ground_cfg, RG)
    ns = int(ground_cfg["n_sectors"])
    # the whole plane table, the far planes beyond the ground's split (lidet_detector_q_init sets plane_split_mm)
    split = int(ground_cfg["ring_split_mm"])
    cluster_cfg = dict(cluster_cfg, plane_split_mm=split)
    labels, members, recs, _ = cluster_q.cluster_q_ref(X, Y, Z, R, tab.row_elev_bam, mask,
                                                      planes[:2 * ns] if split > 0 else planes[:ns], cluster_cfg,
                                                      max_clusters)
    pcfg = dict(proposal_cfg, n_points=int(cls_model.n_points), z_origin=int(getattr(cls_model, "z_origin", 0)))
    outcome = [0] * len(recs)
    order, truncated = candidates(recs, det_cfg, outcome)
    stats = dict(n_clusters=len(recs), n_too_tall=outcome.count(OUT_TALL), n_classified=0, n_gate1_rejected=0,
                 n_boxed=0, n_gate2_rejected=0, n_size_rejected=0, n_nms_suppressed=0, n_over_capacity=0,
                 n_over_box_budget=0, n_group_split=0, n_group_classified=0, n_group_boxed=0, n_score_rejected=0)
    dets = []
    g2c = det_cfg.get("gate2_class", GATE2_CLASS)
    g1m, g2m = int(det_cfg.get("gate1_margin_q16", 0)), int(det_cfg.get("gate2_margin_q16", 0))
    Xf, Yf, Zf = X.ravel(), Y.ravel(), Z.ravel()

    min_score = [int(v) for v in det_cfg.get("min_score_q15", (0, 0, 0))]
    g1c = [int(v) for v in det_cfg.get("gate1_class_margin_q16", (0, 0, 0))]
    flat_mm = int(det_cfg.get("car_min_z_spread_mm", 0))

    def flat(ci):
        """lidet_detector_q.c flat_surface: >= FLAT_MIN_POINTS members and 192 sum dz^2 < t^2 n (t in mm)."""
        rec = recs[ci]
        if flat_mm <= 0 or rec.n_points < FLAT_MIN_POINTS:
            return False
        pix = np.asarray(members, np.int64)[rec.first_member: rec.first_member + rec.n_points]
        dz = Zf[pix] - int(rec.mean[2])
        return 192 * int(np.dot(dz, dz)) < flat_mm * flat_mm * int(rec.n_points)

    ground_mm = int(det_cfg.get("car_ground_mm", 0))
    ground_px = (np.asarray(mask).reshape(rows, cols) != 0) & (R > 0)

    def column(x, y):
        """lidet_detector_q.c column_q: floor((2^31 - atan2) mod 2^32 * cols / 2^32)."""
        return (((1 << 31) - int(qmath.atan2(y, x))) & 0xFFFFFFFF) * cols >> 32

    def ground_box(box):
        """lidet_detector_q.c car_to_ground: the car box [cx, cy, cz, l, w, h, yaw] stretched down to the lower median
        (20 mm bins over +-1 m of its bottom) of the ground pixels within car_ground_mm of its footprint, in the
        columns its corners span (one more each side; every column when the footprint holds the sensor), when its
        bottom lies 0-0.5 m above it; at least 5 pixels."""
        if ground_mm <= 0:
            return box
        cx, cy, cz, ln, wd, h, yaw = box
        c, s = int(qmath.cos(yaw)), int(qmath.sin(yaw))
        a2, w2 = ln + 2 * ground_mm, wd + 2 * ground_mm
        big_l, big_w = a2 << 30, w2 << 30

        def inside(dx, dy):
            u2, v2 = 2 * (c * dx + s * dy), 2 * (c * dy - s * dx)
            return (np.abs(u2) <= big_l) & (np.abs(v2) <= big_w)

        if inside(-cx, -cy):
            sel_cols = np.arange(cols)
        else:
            cc, offs = column(cx, cy), [0]
            for k in range(4):
                a, w = (a2 if k & 1 else -a2), (w2 if k & 2 else -w2)
                x = cx + int(qmath.rshift_round(c * a - s * w, 31))
                y = cy + int(qmath.rshift_round(s * a + c * w, 31))
                o = column(x, y) - cc
                offs.append(o - cols if o > cols // 2 else (o + cols if o < -(cols // 2) else o))
            sel_cols = (cc + min(offs) - 1 + np.arange(min(max(offs) - min(offs) + 3, cols))) % cols
        gx, gy, gz, ok = X[:, sel_cols], Y[:, sel_cols], Z[:, sel_cols], ground_px[:, sel_cols]
        t = 8 * gz - (2 * cz - h - 2 * GROUND_WINDOW_MM)
        ok = ok & (t >= 0) & (t < 4 * GROUND_WINDOW_MM) & inside(4 * gx - cx, 4 * gy - cy)
        n = int(ok.sum())
        if n < GROUND_MIN_PIXELS:
            return box
        hist = np.bincount(t[ok] // (2 * GROUND_BIN_MM), minlength=2 * GROUND_WINDOW_MM // GROUND_BIN_MM)
        i = int(np.argmax(np.cumsum(hist) >= (n + 1) // 2))
        lift2 = 2 * GROUND_WINDOW_MM - (2 * i + 1) * GROUND_BIN_MM
        if 0 < lift2 < 2 * GROUND_MAX_LIFT_MM:
            return [cx, cy, cz - lift2 // 4, ln, wd, h + lift2 // 2, yaw]
        return box

    g1g = int(det_cfg.get("group_gate1_margin_q16", 0))
    g1l = int(det_cfg.get("gate1_large_car_margin_q16", 0))

    def gate1_pass(cls, energy, extra=0):
        return energy < int(cls_model.gamma_q16[cls]) + g1m + g1c[cls] + extra

    def add(d):
        """the detector's insertion (after every entry with a higher score or an equal score and a lower id);
        past max_detections the lowest goes (a cluster marked detected becomes capacity). Returns truncated."""
        k = len(dets)
        while k > 0 and (dets[k - 1]["score_q15"] < d["score_q15"] or
                         (dets[k - 1]["score_q15"] == d["score_q15"] and dets[k - 1]["cluster_id"] > d["cluster_id"])):
            k -= 1
        dets.insert(k, d)
        if len(dets) > max_detections:
            gone = dets.pop()
            if outcome[gone["cluster_id"] - 1] == OUT_DETECTED:
                outcome[gone["cluster_id"] - 1] = OUT_CAPACITY
            stats["n_over_capacity"] += 1
            return True
        return False

    def detection(ci, cls, energy, b, n_points):
        return dict(box=[int(v) for v in b["box"][0]], cls=cls,
                    score_q15=detection_score_q15(energy, int(b["energy"][0]), n_points, int(cls_model.gamma_q16[cls]),
                                                  int(box_model.gamma_q16[cls]), int(det_cfg["score_box_weight_q16"][cls]),
                                                  int(det_cfg["score_points_weight_q16"][cls])),
                    energy_cls_q16=energy, energy_box_q16=int(b["energy"][0]), cluster_id=ci + 1, n_points=n_points)

    def group(ci):
        """the group split of a classified cluster that gave no detection (lidet_detector_body.h det_group)."""
        nonlocal truncated
        rec = recs[ci]
        g = group_q.shape(rec, members, Xf, Yf, Zf, int(det_cfg.get("group_max_range_mm", 40000)))
        if g is None:
            return
        for k in range(g.k_max, g.k_min - 1, -1):
            ok = group_q.cut(rec, members, Xf, Yf, Zf, g, k)
            parts, n_ped = [], 0
            for j in range(k):
                if not ok:
                    break
                xyz, mean, vox, n_src = group_q.proposal(rec, members, Xf, Yf, Zf, g, j, pcfg)
                c = pointnet_q.classify(cls_model, xyz[None].astype(np.int64), mean[None], vox[None])
                stats["n_group_classified"] += 1
                cls, energy = int(c["cls"][0]), int(c["energy"][0])
                # lidet_class_t: 1 cyclist, 2 pedestrian; the cut judged with the group's margin
                ok = cls in (1, 2) and gate1_pass(cls, energy, g1g)
                n_ped += cls == 2
                parts.append((xyz, mean, vox, n_src, energy, cls))
            if not ok or n_ped == 0:
                continue
            cls = 2  # every part is boxed and scored as a pedestrian
            for xyz, mean, vox, n_src, energy, pcls in parts:
                if not gate1_pass(pcls, energy):  # within the group's margin only: no box net pass
                    continue
                if stats["n_boxed"] + stats["n_group_boxed"] >= det_cfg["max_boxes"]:
                    truncated = True
                    break
                b = pointnet_q.box(box_model, xyz[None].astype(np.int64), mean[None], vox[None], cls)
                stats["n_group_boxed"] += 1
                if (det_cfg["gate2"] and g2c[cls] and not int(b["energy"][0]) < int(box_model.gamma_q16[cls]) + g2m) or \
                        not post_q.size_ok(cls, [int(v) for v in b["box"][0]], det_cfg["size_min"], det_cfg["size_max"]):
                    continue
                d = detection(ci, cls, energy, b, n_src)
                if d["score_q15"] < min_score[cls]:  # not counted: the counts are per cluster
                    continue
                if outcome[ci] != OUT_GROUP:
                    outcome[ci] = OUT_GROUP
                    stats["n_group_split"] += 1
                truncated |= add(d)
            return

    group_on = int(det_cfg.get("group_split", 0))
    for ci in order:
        xyz, mean, vox = cluster_q.make_proposal_q(recs[ci], members, X, Y, Z, pcfg)
        c = pointnet_q.classify(cls_model, xyz[None].astype(np.int64), mean[None], vox[None])
        cls, energy = int(c["cls"][0]), int(c["energy"][0])
        stats["n_classified"] += 1
        # a car in a cluster of >= FLAT_MIN_POINTS members: gate 1 widened by the large-car margin
        large = g1l if cls == 0 and recs[ci].n_points >= FLAT_MIN_POINTS else 0
        if det_cfg["gate1"] and not gate1_pass(cls, energy, large):
            outcome[ci] = OUT_GATE1
            stats["n_gate1_rejected"] += 1
            if group_on:
                group(ci)
            continue
        if stats["n_boxed"] + stats["n_group_boxed"] >= det_cfg["max_boxes"]:  # the box budget (the groups' too)
            outcome[ci] = OUT_BUDGET
            stats["n_over_box_budget"] += 1
            truncated = True
            continue
        b = pointnet_q.box(box_model, xyz[None].astype(np.int64), mean[None], vox[None], cls)
        stats["n_boxed"] += 1
        e_box = int(b["energy"][0])
        if det_cfg["gate2"] and g2c[cls] and not e_box < int(box_model.gamma_q16[cls]) + g2m:
            outcome[ci] = OUT_GATE2
            stats["n_gate2_rejected"] += 1
            if group_on:
                group(ci)
            continue
        if not post_q.size_ok(cls, [int(v) for v in b["box"][0]], det_cfg["size_min"], det_cfg["size_max"]) or \
                (cls == 0 and flat(ci)):
            outcome[ci] = OUT_SIZE
            stats["n_size_rejected"] += 1
            if group_on:
                group(ci)
            continue
        d = detection(ci, cls, energy, b, recs[ci].n_points)
        if d["score_q15"] < min_score[cls]:
            outcome[ci] = OUT_SCORE
            stats["n_score_rejected"] += 1
            if group_on:
                group(ci)
            continue
        if cls == 0:
            d["box"] = ground_box(d["box"])
        outcome[ci] = OUT_DETECTED
        truncated |= add(d)
    kept, flags = post_q.nms(dets, int(det_cfg["nms_iou_q15"]))
    for d, f in zip(dets, flags):
        if f:
            if outcome[d["cluster_id"] - 1] == OUT_DETECTED:  # a group keeps its outcome
                outcome[d["cluster_id"] - 1] = OUT_NMS
            stats["n_nms_suppressed"] += 1
    stats["n_detections"] = len(kept)
    return dict(detections=kept, outcome=outcome, stats=stats, truncated=truncated)
