# SPDX-License-Identifier: MIT
"""A deliberately literal, loop-per-object restatement of the KITTI devkit's per-frame matching
(computeStatistics / getThresholds / eval_class), written from the devkit's documented behaviour.
Slow; used only as the test oracle of the vectorized engine in lidet_tools.eval.engine."""
import numpy as np

NO_DETECTION = -10000000.0


def compute_statistics(ov, ign_gt, ign_dt, scores, dc_hit, min_overlap, compute_fp, thresh=0.0):
    """ov[j][i]: overlap of detection j with ground truth i (one frame)."""
    nd, ng = len(ign_dt), len(ign_gt)
    assigned = [False] * nd
    ignored_threshold = [compute_fp and scores[j] < thresh for j in range(nd)]
    tp = fp = fn = 0
    tp_scores = []
    for i in range(ng):
        if ign_gt[i] == -1:
            continue
        det_idx, valid_detection, max_overlap, assigned_ignored_det = -1, NO_DETECTION, 0.0, False
        for j in range(nd):
            if ign_dt[j] == -1 or assigned[j] or ignored_threshold[j]:
                continue
            o = ov[j][i]
            if not compute_fp and o > min_overlap and scores[j] > valid_detection:
                det_idx, valid_detection = j, scores[j]
            elif compute_fp and o > min_overlap and (o > max_overlap or assigned_ignored_det) \
                    and ign_dt[j] == 0:
                max_overlap, det_idx, valid_detection, assigned_ignored_det = o, j, 1, False
            elif compute_fp and o > min_overlap and valid_detection == NO_DETECTION and ign_dt[j] == 1:
                det_idx, valid_detection, assigned_ignored_det = j, 1, True
        if valid_detection == NO_DETECTION and ign_gt[i] == 0:
            fn += 1
        elif valid_detection != NO_DETECTION and (ign_gt[i] == 1 or ign_dt[det_idx] == 1):
            assigned[det_idx] = True
        elif valid_detection != NO_DETECTION:
            tp += 1
            tp_scores.append(scores[det_idx])
            assigned[det_idx] = True
    if compute_fp:
        for j in range(nd):
            if not (assigned[j] or ign_dt[j] == -1 or ign_dt[j] == 1 or ignored_threshold[j]):
                fp += 1
        nstuff = 0
        for j in range(nd):
            if assigned[j] or ign_dt[j] in (-1, 1) or ignored_threshold[j]:
                continue
            if dc_hit[j]:
                assigned[j] = True
                nstuff += 1
        fp -= nstuff
    return tp, fp, fn, tp_scores


def get_thresholds(v, n_gt, n_pts=41):
    v = sorted(v, reverse=True)
    t, cur = [], 0.0
    for i in range(len(v)):
        l_recall = (i + 1) / n_gt
        r_recall = (i + 2) / n_gt if i < len(v) - 1 else l_recall
        if (r_recall - cur) < (cur - l_recall) and i < len(v) - 1:
            continue
        t.append(v[i])
        cur += 1.0 / (n_pts - 1.0)
    return t


def eval_class(frames, min_overlap):
    """frames: list of dicts(ov (nd, ng), ign_gt, ign_dt, scores, dc_hit). Returns (R11, R40, prec)."""
    v, n_gt = [], 0
    for fr in frames:
        n_gt += sum(1 for g in fr["ign_gt"] if g == 0)
        v += compute_statistics(fr["ov"], fr["ign_gt"], fr["ign_dt"], fr["scores"], fr["dc_hit"],
                                min_overlap, False)[3]
    thr = get_thresholds(v, n_gt)
    prec = [0.0] * 41
    for k, t in enumerate(thr[:41]):
        tp = fp = fn = 0
        for fr in frames:
            a, b, c, _ = compute_statistics(fr["ov"], fr["ign_gt"], fr["ign_dt"], fr["scores"],
                                            fr["dc_hit"], min_overlap, True, t)
            tp, fp, fn = tp + a, fp + b, fn + c
        prec[k] = tp / (tp + fp) if tp + fp else 0.0
    for k in range(41):
        prec[k] = max(prec[k:])
    return sum(prec[0::4]) / 11 * 100, sum(prec[1:]) / 40 * 100, np.array(prec)
