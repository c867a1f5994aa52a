# SPDX-License-Identifier: MIT
"""The KITTI devkit's matching and AP computation, vectorized over frames (numpy).

Semantics follow ``computeStatistics`` / ``eval_class`` / ``getThresholds`` of the official devkit
(``evaluate_object_3d_offline.cpp``) and their Python port in OpenPCDet
(``kitti_object_eval_python/eval.py``: ``compute_statistics_jit``, ``get_thresholds``, ``get_mAP``,
``get_mAP_R40``). Per frame, the ground truth is visited in file order and greedily takes one
still-unassigned detection whose overlap exceeds the class threshold (strict ``>``):

* threshold pass (no false positives counted): the candidate with the highest score; a true positive
  (valid ground truth, valid detection) contributes its score to the list from which 41 score
  thresholds are drawn (one per recall step of 1/40);
* per threshold: detections scoring below it are dropped; the candidate with the largest overlap among
  valid detections, else the first ignored one; unmatched valid ground truth is a false negative,
  unassigned valid detections are false positives, except those inside a DontCare region (2D metric).

Flags per object, as in the devkit: ``ign_gt`` 0 valid, 1 ignored (neighbouring class, or outside the
difficulty), -1 not evaluated; ``ign_dt`` 0 valid, 1 ignored (too small), -1 not evaluated.

Vectorization: a frame where no detection is a candidate for two ground-truth objects (and no candidate
lies in a DontCare region) has no interaction between its ground-truth objects, so its counts follow
from per-object maxima in closed form for all thresholds at once. The remaining frames are replayed
exactly, densely over [threshold, frame, detection] arrays, one ground-truth slot at a time.
"""
from __future__ import annotations

import numpy as np

N_SAMPLE_PTS = 41


def get_thresholds(scores, num_gt: int, n_sample_pts: int = N_SAMPLE_PTS) -> np.ndarray:
    """Scores at which precision is sampled: the devkit's ``getThresholds`` (same float arithmetic)."""
    v = np.sort(np.asarray(scores, dtype=np.float64))[::-1]
    n = len(v)
    if n == 0 or num_gt <= 0:
        return v[:0]
    i = np.arange(n, dtype=np.float64)
    l_rec = (i + 1.0) / num_gt
    r_rec = np.where(np.arange(n) < n - 1, (i + 2.0) / num_gt, l_rec)
    out = []
    cur = 0.0
    start = 0
    step = 1.0 / (n_sample_pts - 1.0)
    while start < n:
        ok = ~((r_rec[start:] - cur) < (cur - l_rec[start:]))
        ok[-1] = True
        k = start + int(np.argmax(ok))
        out.append(v[k])
        cur += step
        start = k + 1
    # the devkit stores at most n_sample_pts values (it would overrun its array otherwise)
    return np.asarray(out[:n_sample_pts])


def ap_from_precision(prec) -> tuple[float, float]:
    """(AP|R11, AP|R40) in percent from the 41 interpolated precision samples."""
    p = np.asarray(prec, dtype=np.float64)
    return float(p[0::4].sum() / 11.0 * 100.0), float(p[1:].sum() / 40.0 * 100.0)


def _ranks(frame_of_obj, sel_frames_sorted, mask):
    """Objects of the selected frames (with mask): their indices, row (position of their frame in
    sel_frames_sorted) and column (rank within the frame, file order kept)."""
    idx = np.nonzero(mask & np.isin(frame_of_obj, sel_frames_sorted))[0]
    row = np.searchsorted(sel_frames_sorted, frame_of_obj[idx])
    col = np.arange(len(idx)) - np.searchsorted(row, row, side="left")
    return idx, row, col


def pr_statistics(n_frames, gt_frame, ign_gt, dt_frame, ign_dt, score, pair_dt, pair_gt, pair_ov,
                  min_overlap, dc_hit=None, n_sample_pts: int = N_SAMPLE_PTS, exact: bool = False) -> dict:
    """Precision/recall statistics of one (class, difficulty, metric, IoU threshold) over all frames.

    gt_frame, dt_frame: frame index of every object, sorted ascending (objects in file order within
    a frame). ign_gt, ign_dt: the devkit's flags. score: detection scores. pair_dt, pair_gt, pair_ov:
    overlaps of same-frame (detection, ground truth) pairs; pairs not listed overlap 0. dc_hit: per
    detection, True where the devkit would assign it to a DontCare region (None: no DontCare handling).
    Returns dict(n_gt, thresholds, tp, fp, fn, precision (41, max to the right), recall (41), ap_r11, ap_r40).

    exact: every true positive's score is a threshold, and the 41 precision samples are the interpolated
    precision at recall 0, 1/40, ..., 1 (the largest precision at that recall or above). The devkit's
    thresholds (exact False) take one score per recall step of 1/40 and read the i-th threshold's precision as
    that of recall i/40, which holds only where the class has many more than 40 objects: with n < 40 objects
    every true positive adds one sample, so AP|R40 cannot exceed about n / 40 (a set of 15 cars found with
    precision 1 scores 29). The two agree on large sets; `lidet_tools.eval_real` (a few real frames) uses exact.
    """
    gt_frame = np.asarray(gt_frame, dtype=np.int64)
    dt_frame = np.asarray(dt_frame, dtype=np.int64)
    ign_gt = np.asarray(ign_gt, dtype=np.int8)
    ign_dt = np.asarray(ign_dt, dtype=np.int8)
    score = np.asarray(score, dtype=np.float64)
    pair_dt = np.asarray(pair_dt, dtype=np.int64)
    pair_gt = np.asarray(pair_gt, dtype=np.int64)
    pair_ov = np.asarray(pair_ov, dtype=np.float64)
    if dc_hit is None:
        dc_hit = np.zeros(len(score), dtype=bool)
    dc_hit = np.asarray(dc_hit, dtype=bool)
    n_gt = int((ign_gt == 0).sum())

    # candidate pairs: overlap above the threshold, both objects evaluated
    c = (pair_ov > min_overlap) & (ign_dt[pair_dt] != -1) & (ign_gt[pair_gt] != -1)
    cd, cg, co = pair_dt[c], pair_gt[c], pair_ov[c]

    # frames needing the exact replay: a detection candidate for >1 ground truth, or a candidate
    # detection inside a DontCare region
    n_cand_of_dt = np.bincount(cd, minlength=len(score))
    slow_dt = (n_cand_of_dt > 1) | ((n_cand_of_dt > 0) & dc_hit)
    slow_frames = np.unique(dt_frame[slow_dt])
    slow_f = np.zeros(n_frames, dtype=bool)
    slow_f[slow_frames] = True
    fast_pair = ~slow_f[dt_frame[cd]]
    fd, fg = cd[fast_pair], cg[fast_pair]

    # ---------------- threshold pass ----------------
    tp_scores = []
    if len(fd):
        order = np.lexsort((fd, -score[fd], fg))
        g_sorted = fg[order]
        first = np.r_[True, g_sorted[1:] != g_sorted[:-1]]
        gsel, dsel = g_sorted[first], fd[order][first]
        ok = (ign_gt[gsel] == 0) & (ign_dt[dsel] == 0)
        tp_scores.append(score[dsel[ok]])

    dense = None
    if len(slow_frames):
        dense = _dense_slow(slow_frames, gt_frame, ign_gt, dt_frame, ign_dt, score, dc_hit,
                            cd, cg, co)
        tp_scores.append(_replay_thresholds(dense))
    all_tp = np.concatenate(tp_scores) if tp_scores else np.zeros(0)
    thr = np.unique(all_tp)[::-1] if exact else get_thresholds(all_tp, n_gt, n_sample_pts)
    T = len(thr)

    # ---------------- per-threshold pass: fast frames in closed form ----------------
    tp = np.zeros(T, dtype=np.int64)
    fp = np.zeros(T, dtype=np.int64)
    fn = np.zeros(T, dtype=np.int64)
    if T:
        fast_gt = ~slow_f[gt_frame]
        fast_dt = ~slow_f[dt_frame]
        n_valid_fast = int(((ign_gt == 0) & fast_gt).sum())
        s0 = np.full(len(ign_gt), -np.inf)
        s1 = np.full(len(ign_gt), -np.inf)
        is0 = ign_dt[fd] == 0
        np.maximum.at(s0, fg[is0], score[fd[is0]])
        np.maximum.at(s1, fg[~is0], score[fd[~is0]])
        gi = np.unique(fg)
        has0 = s0[gi][None, :] >= thr[:, None]
        has1 = s1[gi][None, :] >= thr[:, None]
        valid = (ign_gt[gi] == 0)[None, :]
        tp += (has0 & valid).sum(1)
        fn += n_valid_fast - (has0 & valid).sum(1) - (~has0 & has1 & valid).sum(1)

        def count_ge(mask):
            s = np.sort(score[mask])
            return len(s) - np.searchsorted(s, thr, side="left")

        fp += (count_ge(fast_dt & (ign_dt == 0)) - has0.sum(1)
               - count_ge(fast_dt & (ign_dt == 0) & dc_hit))
        if dense is not None:
            t2, f2, n2 = _replay_counts(dense, thr)
            tp += t2
            fp += f2
            fn += n2

    prec = np.zeros(n_sample_pts)
    rec = np.zeros(n_sample_pts)
    if T and exact:
        p_t, r_t = tp / np.maximum(tp + fp, 1), tp / np.maximum(tp + fn, 1)
        rec = np.linspace(0.0, 1.0, n_sample_pts)
        best = np.maximum.accumulate(p_t[np.argsort(r_t)][::-1])[::-1]  # max precision at recall >= r_t (sorted)
        k = np.searchsorted(np.sort(r_t), rec - 1e-12, side="left")
        prec = np.where(k < T, best[np.minimum(k, T - 1)], 0.0)
    elif T:
        prec[:T] = tp / np.maximum(tp + fp, 1)
        rec[:T] = tp / np.maximum(tp + fn, 1)
        prec = np.maximum.accumulate(prec[::-1])[::-1]
    r11, r40 = ap_from_precision(prec)
    return dict(n_gt=n_gt, thresholds=thr, tp=tp, fp=fp, fn=fn, precision=prec, recall=rec,
                ap_r11=r11, ap_r40=r40)


def _dense_slow(frames, gt_frame, ign_gt, dt_frame, ign_dt, score, dc_hit, cd, cg, co):
    """Dense [frame, det, gt] arrays of the frames that need the exact replay (evaluated objects only)."""
    gi, grow, gcol = _ranks(gt_frame, frames, ign_gt != -1)
    di, drow, dcol = _ranks(dt_frame, frames, ign_dt != -1)
    F = len(frames)
    G = int(gcol.max()) + 1 if len(gcol) else 0
    D = int(dcol.max()) + 1 if len(dcol) else 0
    ign_g = np.full((F, G), -1, dtype=np.int8)
    ign_g[grow, gcol] = ign_gt[gi]
    ign_d = np.full((F, D), -1, dtype=np.int8)
    ign_d[drow, dcol] = ign_dt[di]
    sc = np.full((F, D), -np.inf)
    sc[drow, dcol] = score[di]
    dch = np.zeros((F, D), dtype=bool)
    dch[drow, dcol] = dc_hit[di]
    # map candidate pairs of these frames into the dense grid
    gpos = np.full(len(ign_gt), -1, dtype=np.int64)
    gpos[gi] = gcol
    dpos = np.full(len(ign_dt), -1, dtype=np.int64)
    dpos[di] = dcol
    rowof = np.full(int(max(dt_frame.max(initial=-1), gt_frame.max(initial=-1))) + 1, -1, np.int64)
    rowof[frames] = np.arange(F)
    m = np.isin(dt_frame[cd], frames)
    ov = np.zeros((F, D, G))
    cand = np.zeros((F, D, G), dtype=bool)
    r, dd, gg = rowof[dt_frame[cd[m]]], dpos[cd[m]], gpos[cg[m]]
    ov[r, dd, gg] = co[m]
    cand[r, dd, gg] = True
    return dict(ign_g=ign_g, ign_d=ign_d, score=sc, dc=dch, ov=ov, cand=cand)


def _replay_thresholds(d):
    """Threshold pass over the dense frames: scores of the true positives."""
    ign_g, ign_d, sc, ov, cand = d["ign_g"], d["ign_d"], d["score"], d["ov"], d["cand"]
    F, D = ign_d.shape
    rows = np.arange(F)
    assigned = np.zeros((F, D), dtype=bool)
    out = []
    for i in range(ign_g.shape[1]):
        ca = cand[:, :, i] & ~assigned & (ign_d != -1)
        has = ca.any(1)
        if not has.any():
            continue
        j = np.argmax(np.where(ca, sc, -np.inf), axis=1)
        tp = has & (ign_g[:, i] == 0) & (ign_d[rows, j] == 0)
        out.append(sc[rows[tp], j[tp]])
        assigned[rows[has], j[has]] = True
    return np.concatenate(out) if out else np.zeros(0)


def _replay_counts(d, thr):
    """Per-threshold pass over the dense frames: (tp, fp, fn), each of shape (T,)."""
    ign_g, ign_d, sc, ov, cand, dc = d["ign_g"], d["ign_d"], d["score"], d["ov"], d["cand"], d["dc"]
    F, D = ign_d.shape
    T = len(thr)
    elig = (ign_d != -1)[None] & (sc[None] >= thr[:, None, None])
    is0 = (ign_d == 0)[None]
    is1 = (ign_d == 1)[None]
    assigned = np.zeros((T, F, D), dtype=bool)
    tp = np.zeros(T, dtype=np.int64)
    fn = np.zeros(T, dtype=np.int64)
    for i in range(ign_g.shape[1]):
        valid = (ign_g[:, i] == 0)[None, :]
        ca = elig & ~assigned & cand[None, :, :, i]
        c0 = ca & is0
        has0 = c0.any(2)
        has1 = (ca & is1).any(2)
        tp += (has0 & valid).sum(1)
        fn += (~has0 & ~has1 & valid).sum(1)
        has = has0 | has1
        if not has.any():
            continue
        j0 = np.argmax(np.where(c0, ov[None, :, :, i], -np.inf), axis=2)
        j1 = np.argmax(ca & is1, axis=2)
        j = np.where(has0, j0, j1)
        tt, ff = np.nonzero(has)
        assigned[tt, ff, j[tt, ff]] = True
    fp = (elig & is0 & ~assigned & ~dc[None]).sum((1, 2))
    return tp, fp, fn
