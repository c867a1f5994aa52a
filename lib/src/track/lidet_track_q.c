/* SPDX-License-Identifier: MIT */
/* The integer tracker (lidet_track_q.h, docs/TRACKING.md "Integer build"). Integers only. Mirrored bit for bit
 * by codegen/lidet_ref/track_q.py (the function of each step is named where it starts).
 *
 * Why every product below fits int64 (the bounds init and update enforce):
 * - positions |x| <= 2^28 (Q8 mm), detection centres the same, so a difference is < 2^30 and d^2 < 2^61;
 *   each |difference| is compared with gate_max 2^8 <= 2^28 before d^2 (< 2^57) is formed, so an innovation
 *   |e| of an update is < 2^29;
 * - velocities |v| <= 100000 * 2^8 < 2^25 (Q8 mm/s), dt <= 10^4 ms: v dt < 2^39;
 * - covariances p_pp, p_vv in [1, 2^31 - 1], |p_pv| < sqrt(p_pp p_vv) < 2^31: p_pv^2 < 2^62, and every sum of
 *   the prediction < 2^58 (2000 dt p_pv < 2^56, dt^2 p_vv < 2^58);
 * - S = p_pp + r < 2^32 (r <= 10^8 mm^2): gate_chi2 S < 2^58, p_pp e < 2^60, p_pv e < 2^60, p_pp r < 2^58;
 * - the process noise from g = dt^2 a (Q8 mm, capped at 2^25) and h = dt a (Q8 mm/s, capped at 2^24): the
 *   caps engage only where the term alone passes the covariance ceiling (g^2 / 4 >= 2^32 mm^2, h^2 >= 2^32).
 * Every division rounds half away from zero (lidet__q_div_round), every shift half up (lidet__q_rshift_round),
 * the same helpers the reference mirrors (qmath.div_round, qmath.rshift_round). */
#include "internal/lidet_q_gpr.h" /* first: no FPU register for 64-bit integers */

#include <string.h>

#include "internal/lidet_assert.h"
#include "internal/lidet_qmath.h"
#include "internal/lidet_track_q_internal.h"
#include "lidet/lidet_track_q.h"

#define COORD_MAX_Q8 ((int64_t)LIDET_TRACK_Q_COORD_MAX_MM * 256)
#define VMAX_Q8 ((int64_t)LIDET_TRACK_Q_VMAX_MMPS * 256)
#define P_MAX ((int64_t)LIDET_TRACK_Q_P_MAX)
#define G_CAP_Q8 ((int64_t)1 << 25) /* dt^2 a: 2^17 mm */
#define H_CAP_Q8 ((int64_t)1 << 24) /* dt a: 2^16 mm/s */
#define VOTE_HALVE (1u << 30)
#define HUNGARIAN_INF (INT64_MAX / 4)
#define ONE_Q16 65536

/* ---- small helpers ---------------------------------------------------------------------------- */

/* uint32 -> int32 two's complement without the implementation-defined conversion */
static int32_t wrap_bam(uint32_t a)
{
    return a < 0x80000000u ? (int32_t)a : (int32_t)(a - 0x80000000u) - INT32_MAX - 1;
}

static int64_t clamp64(int64_t v, int64_t lo, int64_t hi)
{
    return v < lo ? lo : (v > hi ? hi : v);
}

static int in_range(int32_t v, int32_t lo, int32_t hi)
{
    return v >= lo && v <= hi;
}

/* ref: _cov_guard. p_pp, p_vv in [1, P_MAX], |p_pv| <= P_MAX then p_pv^2 < p_pp p_vv (positive definite) */
static void cov_guard(lidet_track_q_slot_t *s, int64_t pp, int64_t pv, int64_t vv)
{
    pp = clamp64(pp, 1, P_MAX);
    vv = clamp64(vv, 1, P_MAX);
    pv = clamp64(pv, -P_MAX, P_MAX);
    if (pv * pv >= pp * vv)
    {
        const int64_t lim = (int64_t)lidet__q_isqrt64((uint64_t)(pp * vv - 1));
        pv = pv < 0 ? -lim : lim;
    }
    s->p_pp = (int32_t)pp;
    s->p_pv = (int32_t)pv;
    s->p_vv = (int32_t)vv;
}

/* the vote's arg-max, first on ties */
static uint8_t vote_class(const uint32_t *votes)
{
    uint32_t k, best = 0;
    for (k = 1; k < (uint32_t)LIDET_N_CLASSES; ++k)
    {
        if (votes[k] > votes[best])
        {
            best = k;
        }
    }
    return (uint8_t)best;
}

/* x + round(alpha (v - x) / 2^15) */
static int32_t blend(int32_t x, int32_t v, int32_t alpha_q15)
{
    return (int32_t)(x + lidet__q_rshift_round((int64_t)alpha_q15 * ((int64_t)v - x), 15));
}

/* ---- configuration ------------------------------------------------------------------------------ */

void lidet_tracker_q_cfg_default(lidet_tracker_q_cfg_t *cfg)
{
    static const int32_t meas[LIDET_N_CLASSES] = {300, 250, 200};
    static const int32_t accel[LIDET_N_CLASSES] = {2000, 2500, 1500};
    static const int32_t vel[LIDET_N_CLASSES] = {10000, 6000, 3000};
    static const int32_t gate[LIDET_N_CLASSES] = {4000, 3000, 2000};
    if (cfg == 0)
    {
        return;
    }
    memset(cfg, 0, sizeof *cfg);
    memcpy(cfg->meas_sigma_mm, meas, sizeof meas);
    memcpy(cfg->accel_sigma_mmps2, accel, sizeof accel);
    memcpy(cfg->init_vel_sigma_mmps, vel, sizeof vel);
    memcpy(cfg->gate_max_mm, gate, sizeof gate);
    cfg->gate_chi2_q16 = 603587; /* 9.21 */
    cfg->class_penalty_q16 = 2 * ONE_Q16;
    cfg->assign = (uint32_t)LIDET_TRACK_ASSIGN_OPTIMAL;
    cfg->confirm_hits = 2;
    cfg->max_misses = 12;
    cfg->report_misses[LIDET_CLASS_CAR] = 1u;
    cfg->report_misses[LIDET_CLASS_CYCLIST] = 1u;
    cfg->report_misses[LIDET_CLASS_PEDESTRIAN] = 0u;
    cfg->birth_min_score_q15 = 0;
    cfg->yaw_alpha_q15 = 16384; /* 0.5 */
    cfg->size_alpha_q15 = 9830; /* 0.3 */
    cfg->heading_speed_mmps = 1000;
    cfg->heading_from_velocity = LIDET_TRACK_HEADING_FROM_VELOCITY_DEFAULT;
}

static int cfg_ok(const lidet_tracker_q_cfg_t *c)
{
    uint32_t k;
    for (k = 0; k < (uint32_t)LIDET_N_CLASSES; ++k)
    {
        if (!in_range(c->meas_sigma_mm[k], 1, 10000) || !in_range(c->accel_sigma_mmps2[k], 0, 100000) ||
            !in_range(c->init_vel_sigma_mmps[k], 0, 46340) || !in_range(c->gate_max_mm[k], 1, 1000000))
        {
            return 0;
        }
    }
    return in_range(c->gate_chi2_q16, 1, 1000 * ONE_Q16) &&
           in_range(c->class_penalty_q16, 0, 1000 * ONE_Q16) &&
           (c->assign == (uint32_t)LIDET_TRACK_ASSIGN_OPTIMAL ||
            c->assign == (uint32_t)LIDET_TRACK_ASSIGN_GREEDY) &&
           c->confirm_hits >= 1u && c->confirm_hits <= 1000u && c->max_misses <= 1000u &&
           in_range(c->birth_min_score_q15, 0, 32768) && in_range(c->yaw_alpha_q15, 0, 32768) &&
           in_range(c->size_alpha_q15, 0, 32768) &&
           in_range(c->heading_speed_mmps, 0, LIDET_TRACK_Q_VMAX_MMPS) &&
           c->heading_from_velocity < (1u << LIDET_N_CLASSES) && c->report_misses[0] <= 1000u &&
           c->report_misses[1] <= 1000u && c->report_misses[2] <= 1000u;
}

lidet_status_t lidet_tracker_q_init(lidet_tracker_q_t *t, const lidet_tracker_q_cfg_t *cfg)
{
    if (t == 0 || cfg == 0)
    {
        return LIDET_ERR_ARG;
    }
    t->magic = 0;
    if (!cfg_ok(cfg))
    {
        return LIDET_ERR_CONFIG;
    }
    t->cfg = *cfg;
    t->magic = LIDET_INIT_MAGIC;
    return lidet_tracker_q_reset(t);
}

lidet_status_t lidet_tracker_q_reset(lidet_tracker_q_t *t)
{
    if (t == 0)
    {
        return LIDET_ERR_ARG;
    }
    if (t->magic != LIDET_INIT_MAGIC)
    {
        return LIDET_ERR_STATE;
    }
    memset(t->slot, 0, sizeof t->slot);
    memset(&t->stats, 0, sizeof t->stats);
    t->next_id = 1;
    return LIDET_OK;
}

/* ---- assignment (ref: hungarian, greedy) ------------------------------------------------------- */

/* the square matrix's entry (1-based row i, column j): the cost, or big for an infeasible or padding pair */
static int64_t entry(const lidet_tracker_q_t *t, uint32_t i, uint32_t j, uint32_t nr, uint32_t nc,
                     int64_t big)
{
    return i <= nr && j <= nc ? (int64_t)t->cost[(i - 1u) * LIDET_TRACK_MAX_DETS + (j - 1u)] : big;
}

/* Minimum-cost assignment of the square n x n matrix, n = max(nr, nc): the Hungarian method with potentials and
 * shortest augmenting paths (Kuhn-Munkres as in Jonker-Volgenant's Dijkstra form), rows added one by one; exact
 * on integers; ties go to the lowest column of the scan (strict <), so the result is deterministic. */
static void hungarian(lidet_tracker_q_t *t, uint32_t nr, uint32_t nc, int64_t big)
{
    const uint32_t n = nr > nc ? nr : nc;
    int64_t *u = t->pot_u, *v = t->pot_v, *minv = t->minv;
    uint16_t *match = t->match, *way = t->way;
    uint8_t *used = t->used;
    uint32_t i, j;
    for (j = 0; j <= n; ++j)
    {
        u[j] = 0;
        v[j] = 0;
        match[j] = 0;
        way[j] = 0;
    }
    for (i = 1; i <= n; ++i)
    {
        uint32_t j0 = 0;
        match[0] = (uint16_t)i;
        for (j = 0; j <= n; ++j)
        {
            minv[j] = HUNGARIAN_INF;
            used[j] = 0;
        }
        do
        {
            const uint32_t i0 = match[j0];
            uint32_t j1 = 0;
            int64_t delta = HUNGARIAN_INF;
            used[j0] = 1;
            for (j = 1; j <= n; ++j)
            {
                if (!used[j])
                {
                    const int64_t cur = entry(t, i0, j, nr, nc, big) - u[i0] - v[j];
                    if (cur < minv[j])
                    {
                        minv[j] = cur;
                        way[j] = (uint16_t)j0;
                    }
                    if (minv[j] < delta)
                    {
                        delta = minv[j];
                        j1 = j;
                    }
                }
            }
            LIDET_ASSERT(j1 != 0u);
            if (j1 == 0u) /* cannot happen (a free column always exists); keeps the loop bounded */
            {
                break;
            }
            for (j = 0; j <= n; ++j)
            {
                if (used[j])
                {
                    u[match[j]] += delta;
                    v[j] -= delta;
                }
                else
                {
                    minv[j] -= delta;
                }
            }
            j0 = j1;
        } while (match[j0] != 0u);
        do
        {
            const uint32_t j1 = way[j0];
            match[j0] = match[j1];
            j0 = j1;
        } while (j0 != 0u);
    }
    for (i = 0; i < n; ++i)
    {
        t->row_col[i] = -1;
        t->col_row[i] = -1;
    }
    for (j = 1; j <= n; ++j)
    {
        i = match[j];
        if (i >= 1u && i <= nr && j <= nc &&
            (int64_t)t->cost[(i - 1u) * LIDET_TRACK_MAX_DETS + (j - 1u)] < big)
        {
            t->row_col[i - 1u] = (int16_t)(j - 1u);
            t->col_row[j - 1u] = (int16_t)(i - 1u);
        }
    }
}

/* repeatedly the cheapest remaining pair below big; ties: lower row, then lower column */
static void greedy(lidet_tracker_q_t *t, uint32_t nr, uint32_t nc, int32_t big)
{
    const uint32_t n = nr > nc ? nr : nc;
    uint32_t i, j, left = nr < nc ? nr : nc;
    for (i = 0; i < n; ++i)
    {
        t->row_col[i] = -1;
        t->col_row[i] = -1;
    }
    while (left > 0u)
    {
        int32_t best = big;
        uint32_t bi = 0, bj = 0;
        for (i = 0; i < nr; ++i)
        {
            const int32_t *row = t->cost + i * LIDET_TRACK_MAX_DETS;
            if (t->row_col[i] >= 0)
            {
                continue;
            }
            for (j = 0; j < nc; ++j)
            {
                if (row[j] < best && t->col_row[j] < 0)
                {
                    best = row[j];
                    bi = i;
                    bj = j;
                }
            }
        }
        if (best >= big)
        {
            break;
        }
        t->row_col[bi] = (int16_t)bj;
        t->col_row[bj] = (int16_t)bi;
        --left;
    }
}

void lidet__track_q_assign(lidet_tracker_q_t *t, uint32_t n_rows, uint32_t n_cols, int32_t big, uint32_t mode)
{
    LIDET_ASSERT(n_rows <= LIDET_TRACK_MAX_TRACKS && n_cols <= LIDET_TRACK_MAX_DETS);
    if (mode == (uint32_t)LIDET_TRACK_ASSIGN_GREEDY)
    {
        greedy(t, n_rows, n_cols, big);
    }
    else
    {
        hungarian(t, n_rows, n_cols, big);
    }
}

/* ---- one scan ------------------------------------------------------------------------------------ */

static int det_ok(const lidet_detection_q_t *d)
{
    const lidet_box_q_t *b = &d->box;
    const int32_t m = LIDET_TRACK_Q_COORD_MAX_MM;
    return d->cls < (uint8_t)LIDET_N_CLASSES && in_range(b->l_mm, 1, LIDET_TRACK_Q_SIZE_MAX_MM) &&
           in_range(b->w_mm, 1, LIDET_TRACK_Q_SIZE_MAX_MM) &&
           in_range(b->h_mm, 1, LIDET_TRACK_Q_SIZE_MAX_MM) && in_range(d->score_q15, 0, 32768) &&
           in_range(b->cx_mm, -m, m) && in_range(b->cy_mm, -m, m) && in_range(b->cz_mm, -m, m);
}

/* ref: _ego_predict. The ego motion (p <- R(-dyaw) (p - d), v <- R(-dyaw) v, yaw <- yaw - dyaw), then the
 * prediction with the track's class; 0 when the track leaves the coordinate range */
static int ego_predict(const lidet_tracker_q_cfg_t *cfg, lidet_track_q_slot_t *s, uint32_t dt_ms,
                       const lidet_ego_q_t *ego, int64_t c, int64_t sn)
{
    const int64_t T = (int64_t)dt_ms, a = cfg->accel_sigma_mmps2[s->cls];
    int64_t x = s->x_q8, y = s->y_q8, vx = s->vx_q8, vy = s->vy_q8, g, h;
    const int64_t pp = s->p_pp, pv = s->p_pv, vv = s->p_vv;
    if (ego != 0)
    {
        const int64_t px = x - (int64_t)ego->dx_mm * 256, py = y - (int64_t)ego->dy_mm * 256;
        const int64_t wx = vx, wy = vy;
        x = lidet__q_rshift_round(c * px + sn * py, 30);
        y = lidet__q_rshift_round(c * py - sn * px, 30);
        vx = clamp64(lidet__q_rshift_round(c * wx + sn * wy, 30), -VMAX_Q8, VMAX_Q8);
        vy = clamp64(lidet__q_rshift_round(c * wy - sn * wx, 30), -VMAX_Q8, VMAX_Q8);
        s->yaw_bam = wrap_bam((uint32_t)s->yaw_bam - (uint32_t)ego->dyaw_bam);
    }
    x += lidet__q_div_round(vx * T, 1000);
    y += lidet__q_div_round(vy * T, 1000);
    s->vx_q8 = (int32_t)vx;
    s->vy_q8 = (int32_t)vy;
    if (x < -COORD_MAX_Q8 || x > COORD_MAX_Q8 || y < -COORD_MAX_Q8 || y > COORD_MAX_Q8)
    {
        return 0;
    }
    s->x_q8 = (int32_t)x;
    s->y_q8 = (int32_t)y;
    /* white-noise acceleration: g = dt^2 a (Q8 mm), h = dt a (Q8 mm/s); Q = [[g^2/4, g h/2], [g h/2, h^2]] */
    g = lidet__q_div_round((T * T * a) * 256, 1000000);
    h = lidet__q_div_round((T * a) * 256, 1000);
    g = g < G_CAP_Q8 ? g : G_CAP_Q8;
    h = h < H_CAP_Q8 ? h : H_CAP_Q8;
    cov_guard(s,
              pp + lidet__q_div_round(2000 * T * pv + T * T * vv, 1000000) + lidet__q_rshift_round(g * g, 18),
              pv + lidet__q_div_round(T * vv, 1000) + lidet__q_rshift_round(g * h, 17),
              vv + lidet__q_rshift_round(h * h, 16));
    return 1;
}

/* ref: _update. The Kalman update per axis with r = meas_sigma[k]^2, then the box, the vote, the counts */
static void update_track(const lidet_tracker_q_cfg_t *cfg, lidet_track_q_slot_t *s,
                         const lidet_detection_q_t *d, int32_t j)
{
    const uint32_t k = d->cls;
    const int64_t r = (int64_t)cfg->meas_sigma_mm[k] * cfg->meas_sigma_mm[k];
    const int64_t pp = s->p_pp, pv = s->p_pv, vv = s->p_vv, S = pp + r;
    const int64_t ex = (int64_t)d->box.cx_mm * 256 - s->x_q8, ey = (int64_t)d->box.cy_mm * 256 - s->y_q8;
    int32_t dyaw;
    s->x_q8 = (int32_t)(s->x_q8 + lidet__q_div_round(pp * ex, S));
    s->y_q8 = (int32_t)(s->y_q8 + lidet__q_div_round(pp * ey, S));
    s->vx_q8 = (int32_t)clamp64(s->vx_q8 + lidet__q_div_round(pv * ex, S), -VMAX_Q8, VMAX_Q8);
    s->vy_q8 = (int32_t)clamp64(s->vy_q8 + lidet__q_div_round(pv * ey, S), -VMAX_Q8, VMAX_Q8);
    cov_guard(s, lidet__q_div_round(pp * r, S), lidet__q_div_round(pv * r, S),
              vv - lidet__q_div_round(pv * pv, S));
    /* yaw: the detection's turned by pi when it differs by more than pi / 2 (the heading flip), then averaged */
    dyaw = wrap_bam((uint32_t)d->box.yaw_bam - (uint32_t)s->yaw_bam);
    if (dyaw > (int32_t)LIDET_Q_BAM_QUARTER || dyaw < -(int32_t)LIDET_Q_BAM_QUARTER)
    {
        dyaw = wrap_bam((uint32_t)dyaw + LIDET_Q_BAM_HALF);
    }
    s->yaw_bam = wrap_bam((uint32_t)s->yaw_bam +
                          (uint32_t)(int32_t)lidet__q_rshift_round((int64_t)cfg->yaw_alpha_q15 * dyaw, 15));
    s->cz_mm = blend(s->cz_mm, d->box.cz_mm, cfg->size_alpha_q15);
    s->l_mm = blend(s->l_mm, d->box.l_mm, cfg->size_alpha_q15);
    s->w_mm = blend(s->w_mm, d->box.w_mm, cfg->size_alpha_q15);
    s->h_mm = blend(s->h_mm, d->box.h_mm, cfg->size_alpha_q15);
    s->votes[k] += (uint32_t)d->score_q15;
    if (s->votes[k] >= VOTE_HALVE)
    {
        uint32_t q;
        for (q = 0; q < (uint32_t)LIDET_N_CLASSES; ++q)
        {
            s->votes[q] >>= 1;
        }
    }
    s->cls = vote_class(s->votes);
    s->hits += s->hits < UINT32_MAX ? 1u : 0u;
    s->misses = 0;
    s->score_q15 = d->score_q15;
    s->det_index = j;
    if (s->state == (uint8_t)LIDET_TRACK_COASTING)
    {
        s->state = (uint8_t)LIDET_TRACK_CONFIRMED;
    }
}

static void birth(const lidet_tracker_q_cfg_t *cfg, lidet_track_q_slot_t *s, const lidet_detection_q_t *d,
                  int32_t j, uint32_t id)
{
    const uint32_t k = d->cls;
    memset(s, 0, sizeof *s);
    s->x_q8 = d->box.cx_mm * 256;
    s->y_q8 = d->box.cy_mm * 256;
    cov_guard(s, (int64_t)cfg->meas_sigma_mm[k] * cfg->meas_sigma_mm[k], 0,
              (int64_t)cfg->init_vel_sigma_mmps[k] * cfg->init_vel_sigma_mmps[k]);
    s->cz_mm = d->box.cz_mm;
    s->l_mm = d->box.l_mm;
    s->w_mm = d->box.w_mm;
    s->h_mm = d->box.h_mm;
    s->yaw_bam = d->box.yaw_bam;
    s->votes[k] = (uint32_t)d->score_q15;
    s->cls = (uint8_t)k;
    s->id = id;
    s->score_q15 = d->score_q15;
    s->hits = 1;
    s->det_index = j;
    s->active = 1;
    s->state = (uint8_t)LIDET_TRACK_TENTATIVE;
}

/* 1. the detections used: the first LIDET_TRACK_MAX_DETS, the valid ones in order (the columns t->col_det);
 * returns their count */
static uint32_t select_dets(lidet_tracker_q_t *t, const lidet_detection_q_t *det, uint32_t n_use)
{
    uint32_t j, nc = 0;
    for (j = 0; j < n_use; ++j)
    {
        if (det_ok(&det[j]))
        {
            t->col_det[nc++] = (uint16_t)j;
        }
        else
        {
            ++t->stats.n_bad_dets;
        }
    }
    return nc;
}

/* 2.-3. ego motion and prediction of every active track (ref: _ego_predict); a track leaving the coordinate range
 * dies. The live tracks' slots become the rows (t->row_slot); returns their count */
static uint32_t predict_tracks(lidet_tracker_q_t *t, uint32_t dt_ms, const lidet_ego_q_t *ego)
{
    int64_t c = 0, sn = 0;
    uint32_t i, nr = 0;
    if (ego != 0)
    {
        c = lidet__q_cos((uint32_t)ego->dyaw_bam);
        sn = lidet__q_sin((uint32_t)ego->dyaw_bam);
    }
    for (i = 0; i < (uint32_t)LIDET_TRACK_MAX_TRACKS; ++i)
    {
        lidet_track_q_slot_t *s = &t->slot[i];
        if (!s->active)
        {
            continue;
        }
        s->age += s->age < UINT32_MAX ? 1u : 0u;
        s->det_index = -1;
        if (!ego_predict(&t->cfg, s, dt_ms, ego, c, sn))
        {
            s->active = 0;
            ++t->stats.n_deaths;
            continue;
        }
        t->row_slot[nr++] = (uint16_t)i;
    }
    return nr;
}

/* 4. gated costs (ref: _costs), Q16: bigc for a pair outside the gates */
static void costs(lidet_tracker_q_t *t, const lidet_detection_q_t *det, uint32_t nr, uint32_t nc,
                  int32_t bigc)
{
    const lidet_tracker_q_cfg_t *cfg = &t->cfg;
    lidet_tracker_q_stats_t *st = &t->stats;
    uint32_t i, j;
    for (i = 0; i < nr; ++i)
    {
        const lidet_track_q_slot_t *s = &t->slot[t->row_slot[i]];
        const int64_t gm = (int64_t)cfg->gate_max_mm[s->cls] * 256, gm2 = gm * gm;
        int32_t *row = t->cost + i * LIDET_TRACK_MAX_DETS;
        for (j = 0; j < nc; ++j)
        {
            const lidet_detection_q_t *d = &det[t->col_det[j]];
            const int64_t dx = (int64_t)d->box.cx_mm * 256 - s->x_q8,
                          dy = (int64_t)d->box.cy_mm * 256 - s->y_q8;
            const int64_t adx = dx < 0 ? -dx : dx, ady = dy < 0 ? -dy : dy;
            int64_t d2, S;
            row[j] = bigc;
            if (adx > gm || ady > gm)
            {
                continue;
            }
            d2 = dx * dx + dy * dy; /* Q16 mm^2 */
            S = (int64_t)s->p_pp + (int64_t)cfg->meas_sigma_mm[d->cls] * cfg->meas_sigma_mm[d->cls];
            if (d2 > gm2 || d2 > (int64_t)cfg->gate_chi2_q16 * S)
            {
                continue;
            }
            row[j] = (int32_t)(lidet__q_div_round(d2, S) + (d->cls != s->cls ? cfg->class_penalty_q16 : 0));
            ++st->n_feasible_pairs;
        }
    }
}

/* 6.-7. update the assigned tracks, count the misses (ref: _update, _miss) */
static void update_or_miss(lidet_tracker_q_t *t, const lidet_detection_q_t *det, uint32_t nr)
{
    const lidet_tracker_q_cfg_t *cfg = &t->cfg;
    lidet_tracker_q_stats_t *st = &t->stats;
    uint32_t i;
    for (i = 0; i < nr; ++i)
    {
        lidet_track_q_slot_t *s = &t->slot[t->row_slot[i]];
        const int32_t col = t->row_col[i];
        if (col >= 0)
        {
            const uint32_t dj = t->col_det[col];
            update_track(cfg, s, &det[dj], (int32_t)dj);
            ++st->n_matched;
            continue;
        }
        s->misses += s->misses < UINT32_MAX ? 1u : 0u;
        if (s->state == (uint8_t)LIDET_TRACK_TENTATIVE || s->misses > cfg->max_misses)
        {
            s->active = 0;
            ++st->n_deaths;
        }
        else
        {
            s->state = (uint8_t)LIDET_TRACK_COASTING;
        }
    }
}

/* 8. births in the lowest free slots, detections in input order; returns LIDET_TRUNCATED when a birth found no
 * free slot, else LIDET_OK */
static lidet_status_t births(lidet_tracker_q_t *t, const lidet_detection_q_t *det, uint32_t nc)
{
    const lidet_tracker_q_cfg_t *cfg = &t->cfg;
    lidet_tracker_q_stats_t *st = &t->stats;
    lidet_status_t ret = LIDET_OK;
    uint32_t i = 0, j;
    for (j = 0; j < nc; ++j)
    {
        const lidet_detection_q_t *d = &det[t->col_det[j]];
        if (t->col_row[j] >= 0 || d->score_q15 < cfg->birth_min_score_q15)
        {
            continue;
        }
        while (i < (uint32_t)LIDET_TRACK_MAX_TRACKS && t->slot[i].active)
        {
            ++i;
        }
        if (i == (uint32_t)LIDET_TRACK_MAX_TRACKS)
        {
            ++st->n_births_dropped;
            ret = LIDET_TRUNCATED;
            continue;
        }
        birth(cfg, &t->slot[i], d, (int32_t)t->col_det[j], t->next_id);
        t->next_id = t->next_id == UINT32_MAX ? 1u : t->next_id + 1u;
        ++st->n_births;
    }
    return ret;
}

lidet_status_t lidet_tracker_q_update(lidet_tracker_q_t *t, const lidet_detection_q_t *det, uint32_t n_det,
                                      uint32_t dt_ms, const lidet_ego_q_t *ego)
{
    const lidet_tracker_q_cfg_t *cfg;
    lidet_tracker_q_stats_t *st;
    uint32_t i, j, nr, nc, n_use;
    int32_t bigc;
    lidet_status_t ret = LIDET_OK;
    if (t == 0)
    {
        return LIDET_ERR_ARG;
    }
    if (t->magic != LIDET_INIT_MAGIC)
    {
        return LIDET_ERR_STATE;
    }
    if ((det == 0 && n_det > 0u) || dt_ms == 0u || dt_ms > LIDET_TRACK_Q_DT_MAX_MS ||
        (ego != 0 && (!in_range(ego->dx_mm, -LIDET_TRACK_Q_COORD_MAX_MM, LIDET_TRACK_Q_COORD_MAX_MM) ||
                      !in_range(ego->dy_mm, -LIDET_TRACK_Q_COORD_MAX_MM, LIDET_TRACK_Q_COORD_MAX_MM))))
    {
        return LIDET_ERR_ARG;
    }
    cfg = &t->cfg;
    st = &t->stats;
    memset(st, 0, sizeof *st);
    bigc = cfg->gate_chi2_q16 + cfg->class_penalty_q16 + ONE_Q16;

    /* 1. the detections used */
    n_use = n_det < (uint32_t)LIDET_TRACK_MAX_DETS ? n_det : (uint32_t)LIDET_TRACK_MAX_DETS;
    st->n_dets_dropped = n_det - n_use;
    if (st->n_dets_dropped > 0u)
    {
        ret = LIDET_TRUNCATED;
    }
    nc = select_dets(t, det, n_use);
    /* 2.-3. ego motion and prediction; 4. gated costs */
    nr = predict_tracks(t, dt_ms, ego);
    costs(t, det, nr, nc, bigc);

    /* 5. assignment */
    if (nr > 0u && nc > 0u && st->n_feasible_pairs > 0u)
    {
        lidet__track_q_assign(t, nr, nc, bigc, cfg->assign);
    }
    else
    {
        for (i = 0; i < nr; ++i)
        {
            t->row_col[i] = -1;
        }
        for (j = 0; j < nc; ++j)
        {
            t->col_row[j] = -1;
        }
    }

    /* 6.-7. updates and misses; 8. births */
    update_or_miss(t, det, nr);
    if (births(t, det, nc) != LIDET_OK)
    {
        ret = LIDET_TRUNCATED;
    }

    /* 9. confirmation; the counts */
    for (i = 0; i < (uint32_t)LIDET_TRACK_MAX_TRACKS; ++i)
    {
        lidet_track_q_slot_t *s = &t->slot[i];
        if (!s->active)
        {
            continue;
        }
        if (s->state == (uint8_t)LIDET_TRACK_TENTATIVE && s->hits >= cfg->confirm_hits)
        {
            s->state = (uint8_t)LIDET_TRACK_CONFIRMED;
        }
        ++st->n_tracks;
        st->n_confirmed += s->state != (uint8_t)LIDET_TRACK_TENTATIVE ? 1u : 0u;
    }
    return ret;
}

/* ---- output ---------------------------------------------------------------------------------------- */

/* ref: _report. The reported heading: the motion's direction (heading classes) or the box yaw turned to it, once
 * |v| >= heading_speed and |v|^2 >= 4 p_vv */
static void report(const lidet_tracker_q_cfg_t *cfg, const lidet_track_q_slot_t *s, lidet_track_q_t *o)
{
    const int64_t vx = s->vx_q8, vy = s->vy_q8, v2 = vx * vx + vy * vy; /* Q16 (mm/s)^2 */
    const int64_t hs = (int64_t)cfg->heading_speed_mmps * 256;
    int32_t yaw = s->yaw_bam;
    if (v2 > 0 && v2 >= hs * hs && v2 >= ((int64_t)4 * s->p_vv) * 65536)
    {
        const int32_t mot = lidet__q_atan2(s->vy_q8, s->vx_q8);
        if ((cfg->heading_from_velocity >> s->cls) & 1u)
        {
            yaw = mot;
        }
        else
        {
            const int32_t dd = wrap_bam((uint32_t)yaw - (uint32_t)mot);
            if (dd > (int32_t)LIDET_Q_BAM_QUARTER || dd < -(int32_t)LIDET_Q_BAM_QUARTER)
            {
                yaw = wrap_bam((uint32_t)yaw + LIDET_Q_BAM_HALF);
            }
        }
    }
    o->id = s->id;
    o->cls = s->cls;
    o->state = s->state;
    o->reserved = 0;
    o->box.cx_mm = (int32_t)lidet__q_rshift_round(s->x_q8, 8);
    o->box.cy_mm = (int32_t)lidet__q_rshift_round(s->y_q8, 8);
    o->box.cz_mm = s->cz_mm;
    o->box.l_mm = s->l_mm;
    o->box.w_mm = s->w_mm;
    o->box.h_mm = s->h_mm;
    o->box.yaw_bam = yaw;
    o->vx_mmps = (int32_t)lidet__q_rshift_round(s->vx_q8, 8);
    o->vy_mmps = (int32_t)lidet__q_rshift_round(s->vy_q8, 8);
    o->p_pp = s->p_pp;
    o->p_pv = s->p_pv;
    o->p_vv = s->p_vv;
    o->score_q15 = s->score_q15;
    o->hits = s->hits;
    o->misses = s->misses;
    o->age = s->age;
    o->det_index = s->det_index;
}

static int wanted(const lidet_tracker_q_cfg_t *cfg, const lidet_track_q_slot_t *s, uint32_t flags)
{
    return s->active &&
           (s->state == (uint8_t)LIDET_TRACK_CONFIRMED ||
            (s->state == (uint8_t)LIDET_TRACK_COASTING &&
             ((flags & LIDET_TRACK_OUT_COASTING) != 0u || s->misses <= cfg->report_misses[s->cls])) ||
            (s->state == (uint8_t)LIDET_TRACK_TENTATIVE && (flags & LIDET_TRACK_OUT_TENTATIVE) != 0u));
}

uint32_t lidet_tracker_q_tracks(const lidet_tracker_q_t *t, lidet_track_q_t *out, uint32_t cap,
                                uint32_t flags)
{
    uint32_t n = 0, last = 0;
    if (t == 0 || out == 0 || t->magic != LIDET_INIT_MAGIC)
    {
        return 0;
    }
    /* in id order without a sort buffer: each pass takes the lowest id above the previous one (ids are unique) */
    while (n < cap)
    {
        uint32_t i, best = LIDET_TRACK_MAX_TRACKS;
        for (i = 0; i < (uint32_t)LIDET_TRACK_MAX_TRACKS; ++i)
        {
            const lidet_track_q_slot_t *s = &t->slot[i];
            if (wanted(&t->cfg, s, flags) && s->id > last &&
                (best == LIDET_TRACK_MAX_TRACKS || s->id < t->slot[best].id))
            {
                best = i;
            }
        }
        if (best == LIDET_TRACK_MAX_TRACKS)
        {
            break;
        }
        report(&t->cfg, &t->slot[best], &out[n++]);
        last = t->slot[best].id;
    }
    return n;
}

const lidet_tracker_q_stats_t *lidet_tracker_q_stats(const lidet_tracker_q_t *t)
{
    return t == 0 ? 0 : &t->stats;
}

uint32_t lidet_tracker_q_bytes(void)
{
    return (uint32_t)sizeof(lidet_tracker_q_t);
}
