/* SPDX-License-Identifier: MIT */
/* Macro template: the detector's per-candidate loop (det_candidates): for every candidate cluster, nearest
 * first, the proposal, the classifier and gate 1, the box budget, the box net and gate 2, the class size check
 * (and the cars' flat-surface test), the operating point (min_score), and the detection (kept sorted by score, the lowest dropped past LIDET_MAX_DETECTIONS), with each cluster's
 * outcome and the counts.
 *
 * Instantiated by (each #include once, after #defining the parameters below):
 *   lib/src/detector/lidet_detector.c    the float detector: lidet_detector_t, lidet_pn_class_out_t,
 *                                       lidet_pn_box_out_t, lidet_detection_t (float energies and scores)
 *   lib/src/detector/lidet_detector_q.c  the integer detector: lidet_detector_q_t, lidet_pointnet_q_class_out_t,
 *                                       lidet_pointnet_q_box_out_t, lidet_detection_q_t (Q16 energies, Q15
 *                                       scores)
 *
 * Parameters:
 *   DET_T                 the detector (members cfg.gate1, cfg.gate2, cfg.gate2_class, cfg.max_boxes, order,
 *                         outcome, det, n_det, stats)
 *   DET_CLS_OUT_T         the classifier's output (member cls read here)
 *   DET_BOX_OUT_T         the box net's output (member box read here)
 *   DET_DETECTION_T       one detection (members box, cls, cluster_id)
 *   DET_PROPOSAL(d, ci)   make cluster ci's proposal; a lidet_status_t
 *   DET_CLASSIFY(d, co)   classify it into *co; a lidet_status_t
 *   DET_BOX(d, cls, bo)   box it as class cls into *bo; a lidet_status_t
 *   DET_SIZE_OK(d, cls, box)  1 when the box's size is plausible for class cls
 *   DET_FLAT(d, ci)       1 when cluster ci is a flat surface (the cars' test, cfg car_min_z_spread_*)
 *   DET_GROUND(d, box)    stretch car box *box down to the ground around it (cfg car_ground_*; a no-op when off)
 *   DET_SCORE_OK(d, t)    1 when detection *t (filled) scores at least its class's min_score
 *   DET_GATE1_PASS(d, co)  1 when the classifier's energy lies below the model's gamma of the class plus the
 *                         configured margins, gate1_margin and the class's gate1_class_margin (the output's own
 *                         `pass` is the margin-0 decision)
 *   DET_GROUP_GATE1_PASS(d, co)  DET_GATE1_PASS with the group split's margin (cfg group_gate1_margin*) added:
 *                         the judgement of a cut
 *   DET_GATE2_PASS(d, cls, bo)  the same for the box net's energy
 *   DET_FILL(d, t, ci, co, bo)  the build's own fields of detection *t (score, energies, point count; the loop
 *                         sets box, cls and cluster_id)
 *   DET_INSERT(det, n)    move det[n] into det[0..n), kept sorted by score
 *   DET_NOW(d)            the detector's clock (a uint32_t tick count)
 *   DET_GROUP_T           the group split's state (internal/lidet_group.h, internal/lidet_group_q.h)
 *   DET_GROUP_ON(d)       1 when the group split is on (cfg group_split)
 *   DET_GROUP_SHAPE(d, ci, g)  1 when cluster ci is shaped like a group (fills *g)
 *   DET_GROUP_CUT(d, ci, g, k)  cut it into k parts; 1 when every part is large enough
 *   DET_GROUP_PROPOSAL(d, ci, g, j)  make part j's proposal; a lidet_status_t
 * Defines: static lidet_status_t det_candidates(DET_T *d, uint32_t n_cand, lidet_status_t *worst,
 * uint32_t *box_ticks). An error status (cannot happen after a successful init and run) ends the loop and is
 * returned; otherwise LIDET_OK, with *worst set to LIDET_TRUNCATED when the box budget or the detection capacity
 * was reached.
 *
 * Why a template: the two detectors must decide alike (the same gates in the same order, the same budget and
 * capacity drops, the same outcome codes and counts: tests/python/test_detector_q.py compares the integer
 * detector with the float one and with the chained references), and their detector, output and detection types
 * differ. C99 has no generic function over those types; a plain function would need void pointers and about
 * ten callbacks plus accessors for the outcome, detection and statistics arrays. The loop runs once per
 * candidate (tens per scan, each costing a PointNet pass), so speed does not decide here: the template keeps
 * the shared decisions in one place with each build's types checked by the compiler.
 * Not a public header; include nowhere else. */

/* a detection t filled at det[n_det]: insert it by score; past LIDET_MAX_DETECTIONS the lowest goes */
static void det_insert(DET_T *d, lidet_status_t *worst)
{
    DET_INSERT(d->det, d->n_det);
    ++d->n_det;
    if (d->n_det > LIDET_MAX_DETECTIONS)
    {
        --d->n_det; /* the lowest score goes */
        if (d->outcome[d->det[d->n_det].cluster_id - 1u] == LIDET_DET_OUT_DETECTED)
        {
            d->outcome[d->det[d->n_det].cluster_id - 1u] = LIDET_DET_OUT_CAPACITY;
        }
        ++d->stats.n_over_capacity;
        *worst = LIDET_TRUNCATED;
    }
}

/* The group split of cluster ci (classified, no detection): the cuts from k_max down; the first whose every part
 * the classifier calls a pedestrian (or a rider) passing gate 1 widened by the group margin (DET_GROUP_GATE1_PASS)
 * is kept, each part that passes gate 1 itself then boxed, judged and sized as a cluster is, its detections
 * carrying the cluster's id (outcome LIDET_DET_OUT_GROUP when one is kept, n_group_split).
 * The parts' passes count in n_group_classified and n_group_boxed, not in the per-cluster counts, and the box
 * budget holds for them (n_boxed + n_group_boxed <= max_boxes); a part past it ends the split. */
#if defined(__GNUC__)
__attribute__((noinline)) /* its parts' outputs stay out of the candidate loop's frame (no 16-beam default
                             calls it) */
#endif
static lidet_status_t
det_group(DET_T *d, uint32_t ci, lidet_status_t *worst, uint32_t *box_ticks)
{
    DET_GROUP_T g;
    DET_CLS_OUT_T co[LIDET_GROUP_MAX_PARTS];
    uint32_t k, j;
    lidet_status_t s;
    if (!DET_GROUP_SHAPE(d, ci, &g))
    {
        return LIDET_OK;
    }
    for (k = g.k_max; k >= g.k_min; --k)
    {
        int ok = DET_GROUP_CUT(d, ci, &g, k), n_ped = 0;
        for (j = 0; j < k && ok; ++j)
        {
            s = DET_GROUP_PROPOSAL(d, ci, &g, j);
            if (s == LIDET_OK)
            {
                s = DET_CLASSIFY(d, &co[j]);
            }
            if (s != LIDET_OK)
            {
                return s;
            }
            ++d->stats.n_group_classified;
            /* a person on foot, or one the classifier takes for a rider: each part passing the group's gate 1
             * as its class (a real person among others who looks a little out of distribution does not veto
             * the cut; the part gives a detection only if it passes gate 1 itself, below) */
            ok = (co[j].cls == LIDET_CLASS_PEDESTRIAN || co[j].cls == LIDET_CLASS_CYCLIST) &&
                 DET_GROUP_GATE1_PASS(d, &co[j]);
            n_ped += co[j].cls == LIDET_CLASS_PEDESTRIAN;
        }
        if (!ok || n_ped == 0)
        {
            continue;
        }
        for (j = 0; j < k; ++j)
        {
            DET_BOX_OUT_T bo;
            DET_DETECTION_T *t;
            uint32_t tb;
            if (!DET_GATE1_PASS(d, &co[j]))
            {
                continue; /* within the group's margin only: no detection, no box net pass */
            }
            if (d->stats.n_boxed + d->stats.n_group_boxed >= d->cfg.max_boxes)
            {
                *worst = LIDET_TRUNCATED;
                break;
            }
            s = DET_GROUP_PROPOSAL(d, ci, &g, j); /* the proposal buffer holds the last part classified */
            if (s != LIDET_OK)
            {
                return s;
            }
            tb = DET_NOW(d);
            co[j].cls =
                LIDET_CLASS_PEDESTRIAN; /* every part of a group is boxed and scored as a person on foot */
            s = DET_BOX(d, co[j].cls, &bo);
            *box_ticks += DET_NOW(d) - tb;
            if (s != LIDET_OK)
            {
                return s;
            }
            ++d->stats.n_group_boxed;
            if ((d->cfg.gate2 && d->cfg.gate2_class[co[j].cls] && !DET_GATE2_PASS(d, co[j].cls, &bo)) ||
                !DET_SIZE_OK(d, co[j].cls, &bo.box))
            {
                continue;
            }
            t = &d->det[d->n_det];
            t->box = bo.box;
            t->cls = co[j].cls;
            t->cluster_id = ci + 1u;
            DET_FILL(d, t, ci, &co[j], &bo);
            if (!DET_SCORE_OK(
                    d, t)) /* a part below the operating point (not counted: the counts are per cluster) */
            {
                continue;
            }
            if (d->outcome[ci] != LIDET_DET_OUT_GROUP)
            {
                d->outcome[ci] = LIDET_DET_OUT_GROUP;
                ++d->stats.n_group_split;
            }
            det_insert(d, worst);
        }
        break;
    }
    return LIDET_OK;
}

static lidet_status_t det_candidates(DET_T *d, uint32_t n_cand, lidet_status_t *worst, uint32_t *box_ticks)
{
    uint32_t i;
    for (i = 0; i < n_cand; ++i)
    {
        const uint32_t ci = d->order[i];
        DET_CLS_OUT_T co;
        DET_BOX_OUT_T bo;
        DET_DETECTION_T *t;
        lidet_status_t s;
        uint32_t tb;
        s = DET_PROPOSAL(d, ci);
        if (s == LIDET_OK)
        {
            s = DET_CLASSIFY(d, &co);
        }
        if (s != LIDET_OK)
        {
            return s;
        }
        ++d->stats.n_classified;
        if (d->cfg.gate1 && !DET_GATE1_PASS(d, &co))
        {
            d->outcome[ci] = LIDET_DET_OUT_GATE1;
            ++d->stats.n_gate1_rejected;
            goto no_detection;
        }
        if (d->stats.n_boxed + d->stats.n_group_boxed >= d->cfg.max_boxes)
        {
            d->outcome[ci] = LIDET_DET_OUT_BUDGET;
            ++d->stats.n_over_box_budget;
            *worst = LIDET_TRUNCATED;
            continue;
        }
        tb = DET_NOW(d);
        s = DET_BOX(d, co.cls, &bo);
        *box_ticks += DET_NOW(d) - tb;
        if (s != LIDET_OK)
        {
            return s;
        }
        ++d->stats.n_boxed;
        if (d->cfg.gate2 && d->cfg.gate2_class[co.cls] && !DET_GATE2_PASS(d, co.cls, &bo))
        {
            d->outcome[ci] = LIDET_DET_OUT_GATE2;
            ++d->stats.n_gate2_rejected;
            goto no_detection;
        }
        if (!DET_SIZE_OK(d, co.cls, &bo.box) || (co.cls == LIDET_CLASS_CAR && DET_FLAT(d, ci)))
        {
            d->outcome[ci] = LIDET_DET_OUT_SIZE;
            ++d->stats.n_size_rejected;
            goto no_detection;
        }
        t = &d->det[d->n_det];
        t->box = bo.box;
        t->cls = co.cls;
        t->cluster_id = ci + 1u;
        DET_FILL(d, t, ci, &co, &bo);
        if (!DET_SCORE_OK(d, t))
        {
            d->outcome[ci] = LIDET_DET_OUT_SCORE;
            ++d->stats.n_score_rejected;
            goto no_detection;
        }
        if (co.cls == LIDET_CLASS_CAR)
        {
            DET_GROUND(d, &t->box);
        }
        d->outcome[ci] = LIDET_DET_OUT_DETECTED;
        det_insert(d, worst);
        continue;
    no_detection:
        /* a classified cluster that gave no detection: people side by side in one cluster? */
        if (DET_GROUP_ON(d))
        {
            s = det_group(d, ci, worst, box_ticks);
            if (s != LIDET_OK)
            {
                return s;
            }
        }
    }
    return LIDET_OK;
}
