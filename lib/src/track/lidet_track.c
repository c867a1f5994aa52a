/* SPDX-License-Identifier: MIT */
/* The tracker, float build (lidet_track.h, docs/TRACKING.md). Mirrored operation for operation by
 * codegen/lidet_ref/track.py (float32 numpy): every expression below is written in the order the
 * reference evaluates it (one rounding per operation: the library is built with -ffp-contract=off), so the two
 * agree to the last bit except where libm's sinf / cosf / atan2f round differently from the reference's
 * correctly rounded values (tests/python/test_track.py states the tolerance). */
#include <math.h>
#include <string.h>

#include "internal/lidet_math.h"
#include "lidet/lidet_track.h"

#define TWO_PI_F 6.28318531f
#define MAX_DT_S 10.0f
#define MAX_EGO_M 1000.0f     /* a sensor moves at most 1 km between two scans (100 m/s over 10 s) */
#define MAX_CENTRE_M 10000.0f /* detections farther are skipped: keeps every sum and product finite */
#define MAX_SIZE_M 100.0f
#define HUNG_INF 1.0e30f /* above every potential: costs <= 2001, |u|, |v| <= N * 2001 */

void lidet_tracker_cfg_default(lidet_tracker_cfg_t *cfg)
{
    static const float meas[LIDET_N_CLASSES] = {0.30f, 0.25f, 0.20f};
    static const float accel[LIDET_N_CLASSES] = {2.0f, 2.5f, 1.5f};
    static const float vel[LIDET_N_CLASSES] = {10.0f, 6.0f, 3.0f};
    static const float gate[LIDET_N_CLASSES] = {4.0f, 3.0f, 2.0f};
    if (cfg == 0)
    {
        return;
    }
    memset(cfg, 0, sizeof *cfg);
    memcpy(cfg->meas_sigma_m, meas, sizeof meas);
    memcpy(cfg->accel_sigma_mps2, accel, sizeof accel);
    memcpy(cfg->init_vel_sigma_mps, vel, sizeof vel);
    memcpy(cfg->gate_max_m, gate, sizeof gate);
    cfg->gate_chi2 = 9.21f; /* chi-square, 2 dof, 99 % */
    cfg->class_penalty = 2.0f;
    cfg->assign = (uint32_t)LIDET_TRACK_ASSIGN_OPTIMAL;
    cfg->confirm_hits = 2u;
    cfg->max_misses = 12u;
    cfg->report_misses[LIDET_CLASS_CAR] = 1u;
    cfg->report_misses[LIDET_CLASS_CYCLIST] = 1u;
    cfg->report_misses[LIDET_CLASS_PEDESTRIAN] = 0u;
    cfg->birth_min_score = 0.0f;
    cfg->yaw_alpha = 0.5f;
    cfg->size_alpha = 0.3f;
    cfg->heading_speed_mps = 1.0f;
    cfg->heading_from_velocity = LIDET_TRACK_HEADING_FROM_VELOCITY_DEFAULT;
}

/* lo <= v <= hi, false for NaN */
static int in_range(float v, float lo, float hi)
{
    return v >= lo && v <= hi;
}

static int cfg_ok(const lidet_tracker_cfg_t *c)
{
    uint32_t k;
    for (k = 0; k < (uint32_t)LIDET_N_CLASSES; ++k)
    {
        if (!in_range(c->meas_sigma_m[k], 0.001f, 100.0f) ||
            !in_range(c->accel_sigma_mps2[k], 0.0f, 100.0f) ||
            !in_range(c->init_vel_sigma_mps[k], 0.0f, 100.0f) || !(c->gate_max_m[k] > 0.0f) ||
            !(c->gate_max_m[k] <= 1000.0f))
        {
            return 0;
        }
    }
    if (!(c->gate_chi2 > 0.0f) || !(c->gate_chi2 <= 1000.0f) || !in_range(c->class_penalty, 0.0f, 1000.0f))
    {
        return 0;
    }
    if (c->assign != (uint32_t)LIDET_TRACK_ASSIGN_OPTIMAL && c->assign != (uint32_t)LIDET_TRACK_ASSIGN_GREEDY)
    {
        return 0;
    }
    if (c->confirm_hits < 1u || c->confirm_hits > 1000u || c->max_misses > 1000u)
    {
        return 0;
    }
    for (k = 0; k < (uint32_t)LIDET_N_CLASSES; ++k)
    {
        if (c->report_misses[k] > 1000u)
        {
            return 0;
        }
    }
    if (!in_range(c->birth_min_score, 0.0f, 1.0f) || !in_range(c->yaw_alpha, 0.0f, 1.0f) ||
        !in_range(c->size_alpha, 0.0f, 1.0f) || !in_range(c->heading_speed_mps, 0.0f, 100.0f))
    {
        return 0;
    }
    return (c->heading_from_velocity >> LIDET_N_CLASSES) == 0u;
}

lidet_status_t lidet_tracker_init(lidet_tracker_t *t, const lidet_tracker_cfg_t *cfg)
{
    if (t == 0 || cfg == 0)
    {
        return LIDET_ERR_ARG;
    }
    if (!cfg_ok(cfg))
    {
        return LIDET_ERR_CONFIG;
    }
    memset(t, 0, sizeof *t);
    t->cfg = *cfg;
    t->next_id = 1u;
    t->magic = LIDET_INIT_MAGIC;
    return LIDET_OK;
}

lidet_status_t lidet_tracker_reset(lidet_tracker_t *t)
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
    t->next_id = 1u;
    return LIDET_OK;
}

/* ref: wrap_pi. An angle into (-pi, pi]; fmodf is exact, so each loop runs at most once (as lidet_pointnet.c's).
 * Every angle here is finite (inputs are checked), the guard only keeps a NaN a NaN. */
static float wrap_pi(float a)
{
    if (!lidet__isfinite(a))
    {
        return a - a;
    }
    if (a > TWO_PI_F || a < -TWO_PI_F)
    {
        a = fmodf(a, TWO_PI_F);
    }
    while (a > LIDET_PI_F)
    {
        a -= TWO_PI_F;
    }
    while (a <= -LIDET_PI_F)
    {
        a += TWO_PI_F;
    }
    return a;
}

/* ref: det_ok. What the tracker reads of a detection is finite, the class known, the size positive, and the
 * centre within MAX_CENTRE_M and the size within MAX_SIZE_M (so that no sum of the update can overflow). */
static int det_ok(const lidet_detection_t *d)
{
    const lidet_box_t *b = &d->box;
    if (d->cls >= (uint8_t)LIDET_N_CLASSES || !lidet__isfinite(b->yaw_rad) || !lidet__isfinite(d->score))
    {
        return 0;
    }
    return in_range(b->cx_m, -MAX_CENTRE_M, MAX_CENTRE_M) && in_range(b->cy_m, -MAX_CENTRE_M, MAX_CENTRE_M) &&
           in_range(b->cz_m, -MAX_CENTRE_M, MAX_CENTRE_M) && b->l_m > 0.0f && b->l_m <= MAX_SIZE_M &&
           b->w_m > 0.0f && b->w_m <= MAX_SIZE_M && b->h_m > 0.0f && b->h_m <= MAX_SIZE_M;
}

/* ref: Tracker._ego. Into the new sensor frame: p <- R(-dyaw) (p - d), v <- R(-dyaw) v, yaw - dyaw. */
static void ego_motion(lidet_tracker_t *t, const lidet_ego_t *ego)
{
    const float c = cosf(ego->dyaw_rad), s = sinf(ego->dyaw_rad);
    uint32_t i;
    for (i = 0; i < (uint32_t)LIDET_TRACK_MAX_TRACKS; ++i)
    {
        lidet_tracker_slot_t *k = &t->slot[i];
        float px, py, vx, vy;
        if (!k->used)
        {
            continue;
        }
        px = k->x_m - ego->dx_m;
        py = k->y_m - ego->dy_m;
        vx = k->vx_mps;
        vy = k->vy_mps;
        k->x_m = c * px + s * py;
        k->y_m = c * py - s * px;
        k->vx_mps = c * vx + s * vy;
        k->vy_mps = c * vy - s * vx;
        k->yaw_rad = wrap_pi(k->yaw_rad - ego->dyaw_rad);
    }
}

/* ref: Tracker._predict. Constant velocity with white-noise acceleration a = accel_sigma[class]:
 * p_pp + 2 dt p_pv + dt^2 p_vv + dt^4 a^2 / 4, p_pv + dt p_vv + dt^3 a^2 / 2, p_vv + dt^2 a^2. Age + 1. */
static void predict(lidet_tracker_t *t, float dt)
{
    const float dt2 = dt * dt, dt3 = dt2 * dt, dt4 = dt2 * dt2, two_dt = 2.0f * dt;
    float q_pp[LIDET_N_CLASSES], q_pv[LIDET_N_CLASSES], q_vv[LIDET_N_CLASSES];
    uint32_t i;
    for (i = 0; i < (uint32_t)LIDET_N_CLASSES; ++i)
    {
        const float q = t->cfg.accel_sigma_mps2[i] * t->cfg.accel_sigma_mps2[i];
        q_pp[i] = (dt4 * q) * 0.25f;
        q_pv[i] = (dt3 * q) * 0.5f;
        q_vv[i] = dt2 * q;
    }
    for (i = 0; i < (uint32_t)LIDET_TRACK_MAX_TRACKS; ++i)
    {
        lidet_tracker_slot_t *k = &t->slot[i];
        float pp, pv, vv;
        if (!k->used)
        {
            continue;
        }
        k->x_m = k->x_m + k->vx_mps * dt;
        k->y_m = k->y_m + k->vy_mps * dt;
        pp = ((k->p_pp + two_dt * k->p_pv) + dt2 * k->p_vv) + q_pp[k->cls];
        pv = (k->p_pv + dt * k->p_vv) + q_pv[k->cls];
        vv = k->p_vv + q_vv[k->cls];
        k->p_pp = pp;
        k->p_pv = pv;
        k->p_vv = vv;
        k->age = k->age < 0xFFFFFFFFu ? k->age + 1u : k->age;
    }
}

/* ref: Tracker._costs. Rows: the live slots in slot order; columns: the valid detections in index order.
 * Infeasible pairs cost big (> every feasible cost: m <= gate_chi2, + class_penalty at most). */
static uint32_t costs(lidet_tracker_t *t, const lidet_detection_t *det, uint32_t nt, uint32_t nd, float big)
{
    uint32_t r, c, n_feasible = 0;
    for (r = 0; r < nt; ++r)
    {
        const lidet_tracker_slot_t *k = &t->slot[t->row_slot[r]];
        const float gm2 = t->cfg.gate_max_m[k->cls] * t->cfg.gate_max_m[k->cls];
        for (c = 0; c < nd; ++c)
        {
            const lidet_detection_t *d = &det[t->col_det[c]];
            const float ms = t->cfg.meas_sigma_m[d->cls];
            const float ex = d->box.cx_m - k->x_m, ey = d->box.cy_m - k->y_m;
            const float d2 = ex * ex + ey * ey;
            const float m = d2 / (k->p_pp + ms * ms);
            float cost = big;
            if (m <= t->cfg.gate_chi2 && d2 <= gm2)
            {
                cost = d->cls != k->cls ? m + t->cfg.class_penalty : m;
                ++n_feasible;
            }
            t->cost[r * nd + c] = cost;
        }
    }
    return n_feasible;
}

/* ref: hungarian. Minimum-cost assignment of the n x n matrix, n = max(nt, nd), whose entries outside the
 * nt x nd cost block are big: shortest augmenting paths with row and column potentials (Jonker-Volgenant
 * style, O(n^3)), rows added in order, columns scanned in order, ties to the lower column. Every loop is
 * bounded: each inner pass adds a column to the path tree, at most n per row. Sets row_col. */
static void hungarian(lidet_tracker_t *t, uint32_t nt, uint32_t nd, float big)
{
    const uint32_t n = nt > nd ? nt : nd;
    float *u = t->hu, *v = t->hv, *minv = t->hminv;
    uint16_t *p = t->hp, *way = t->hway;
    uint8_t *used = t->hused;
    uint32_t i, j;
    for (j = 0; j <= n; ++j)
    {
        u[j] = 0.0f;
        v[j] = 0.0f;
        p[j] = 0u;
        way[j] = 0u;
    }
    for (i = 1; i <= n; ++i)
    {
        uint32_t j0 = 0, steps;
        p[0] = (uint16_t)i;
        for (j = 0; j <= n; ++j)
        {
            minv[j] = HUNG_INF;
            used[j] = 0u;
        }
        for (steps = 0; steps <= n; ++steps)
        {
            const uint32_t i0 = p[j0];
            float delta = HUNG_INF;
            uint32_t j1 = 0;
            used[j0] = 1u;
            for (j = 1; j <= n; ++j)
            {
                if (!used[j])
                {
                    const float a = i0 <= nt && j <= nd ? t->cost[(i0 - 1u) * nd + (j - 1u)] : big;
                    const float cur = (a - u[i0]) - v[j];
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
            if (j1 == 0u) /* never with finite costs (a free column always remains); keeps the loop bounded */
            {
                break;
            }
            for (j = 0; j <= n; ++j)
            {
                if (used[j])
                {
                    u[p[j]] = u[p[j]] + delta;
                    v[j] = v[j] - delta;
                }
                else
                {
                    minv[j] = minv[j] - delta;
                }
            }
            j0 = j1;
            if (p[j0] == 0u)
            {
                break;
            }
        }
        while (j0 != 0u) /* augment along the path */
        {
            const uint32_t j1 = way[j0];
            p[j0] = p[j1];
            j0 = j1;
        }
    }
    for (j = 1; j <= n; ++j)
    {
        const uint32_t r = p[j];
        if (r >= 1u && r <= nt && j <= nd && t->cost[(r - 1u) * nd + (j - 1u)] < big)
        {
            t->row_col[r - 1u] = (int16_t)(j - 1u);
            t->col_taken[j - 1u] = 1u;
        }
    }
}

/* the cheapest free column of row r (lowest column on ties) into best_col / best_cost; nd: none (cost big) */
static void row_best(lidet_tracker_t *t, uint32_t r, uint32_t nd, float big)
{
    uint32_t c, bc = nd;
    float best = big;
    for (c = 0; c < nd; ++c)
    {
        if (!t->col_taken[c] && t->cost[r * nd + c] < best)
        {
            best = t->cost[r * nd + c];
            bc = c;
        }
    }
    t->hway[r] = (uint16_t)bc;
    t->hminv[r] = best;
}

/* ref: greedy. Repeatedly the feasible pair of lowest cost among free rows and columns; ties: lower row (slot),
 * then lower column (detection index). Each row keeps its cheapest free column (in the Hungarian method's
 * arrays, unused here), recomputed only when another row takes it: O(T D) plus O(D) per such row. Sets
 * row_col. */
static void greedy(lidet_tracker_t *t, uint32_t nt, uint32_t nd, float big)
{
    uint32_t r;
    for (r = 0; r < nt; ++r)
    {
        row_best(t, r, nd, big);
    }
    for (;;)
    {
        float best = big;
        uint32_t br = nt, bc;
        for (r = 0; r < nt; ++r)
        {
            if (t->row_col[r] < 0 && t->hminv[r] < best)
            {
                best = t->hminv[r];
                br = r;
            }
        }
        if (br == nt)
        {
            return;
        }
        bc = t->hway[br];
        t->row_col[br] = (int16_t)bc;
        t->col_taken[bc] = 1u;
        for (r = 0; r < nt; ++r)
        {
            if (t->row_col[r] < 0 && t->hway[r] == bc)
            {
                row_best(t, r, nd, big);
            }
        }
    }
}

/* first arg-max of the votes */
static uint8_t vote_class(const float *votes)
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

/* ref: Tracker._update_track. The Kalman update per axis (measurement noise r = meas_sigma[det class]^2), the
 * yaw with the heading flip folded out, the averaged box, the class vote. */
static void update_track(const lidet_tracker_cfg_t *cfg, lidet_tracker_slot_t *k, const lidet_detection_t *d,
                         uint32_t index)
{
    const float ms = cfg->meas_sigma_m[d->cls];
    const float s = k->p_pp + ms * ms;
    const float kp = k->p_pp / s, kv = k->p_pv / s;
    const float ex = d->box.cx_m - k->x_m, ey = d->box.cy_m - k->y_m;
    float vv, dyaw;
    k->x_m = k->x_m + kp * ex;
    k->y_m = k->y_m + kp * ey;
    k->vx_mps = k->vx_mps + kv * ex;
    k->vy_mps = k->vy_mps + kv * ey;
    vv = k->p_vv - kv * k->p_pv;
    k->p_vv = vv > 0.0f ? vv : 0.0f; /* >= 0 exactly; rounding could go below when r << p_pp */
    k->p_pp = (1.0f - kp) * k->p_pp;
    k->p_pv = (1.0f - kp) * k->p_pv;
    /* |p_pv| <= sqrt(p_pp p_vv), as the integer build's cov_guard: with r << p_pp and a nearly singular prior (a
     * tiny meas_sigma, no process noise, a long dt), 1 - kp and p_vv - kv p_pv lose most of their digits and could
     * leave p_pv^2 above p_pp p_vv (tests/fuzz/regressions/track/covariance_not_psd_after_update.bin) */
    if (k->p_pv * k->p_pv > k->p_pp * k->p_vv)
    {
        const float lim = sqrtf(k->p_pp * k->p_vv);
        k->p_pv = k->p_pv < 0.0f ? -lim : lim;
    }
    dyaw = wrap_pi(d->box.yaw_rad - k->yaw_rad);
    if (dyaw > LIDET_HALF_PI_F)
    {
        dyaw -= LIDET_PI_F;
    }
    else if (dyaw < -LIDET_HALF_PI_F)
    {
        dyaw += LIDET_PI_F;
    }
    k->yaw_rad = wrap_pi(k->yaw_rad + cfg->yaw_alpha * dyaw);
    k->z_m = k->z_m + cfg->size_alpha * (d->box.cz_m - k->z_m);
    k->l_m = k->l_m + cfg->size_alpha * (d->box.l_m - k->l_m);
    k->w_m = k->w_m + cfg->size_alpha * (d->box.w_m - k->w_m);
    k->h_m = k->h_m + cfg->size_alpha * (d->box.h_m - k->h_m);
    k->votes[d->cls] = k->votes[d->cls] + d->score;
    k->cls = vote_class(k->votes);
    k->score = d->score;
    k->hits = k->hits < 0xFFFFFFFFu ? k->hits + 1u : k->hits;
    k->misses = 0u;
    k->det_index = (int32_t)index;
    if (k->state == (uint8_t)LIDET_TRACK_COASTING)
    {
        k->state = (uint8_t)LIDET_TRACK_CONFIRMED;
    }
}

/* ref: Tracker._birth. A tentative track on detection d: v = 0, p_pp = r, p_pv = 0, p_vv = init_vel_sigma^2. */
static void birth(const lidet_tracker_cfg_t *cfg, lidet_tracker_slot_t *k, const lidet_detection_t *d,
                  uint32_t index, uint32_t id)
{
    const float ms = cfg->meas_sigma_m[d->cls], vs = cfg->init_vel_sigma_mps[d->cls];
    memset(k, 0, sizeof *k);
    k->used = 1u;
    k->id = id;
    k->state = (uint8_t)LIDET_TRACK_TENTATIVE;
    k->cls = d->cls;
    k->x_m = d->box.cx_m;
    k->y_m = d->box.cy_m;
    k->p_pp = ms * ms;
    k->p_vv = vs * vs;
    k->z_m = d->box.cz_m;
    k->l_m = d->box.l_m;
    k->w_m = d->box.w_m;
    k->h_m = d->box.h_m;
    k->yaw_rad = wrap_pi(d->box.yaw_rad);
    k->votes[d->cls] = d->score;
    k->score = d->score;
    k->hits = 1u;
    k->det_index = (int32_t)index;
}

lidet_status_t lidet_tracker_update(lidet_tracker_t *t, const lidet_detection_t *det, uint32_t n_det,
                                    float dt_s, const lidet_ego_t *ego)
{
    lidet_tracker_stats_t *st;
    const lidet_tracker_cfg_t *cfg;
    uint32_t n_use, nd = 0, nt = 0, i, r, c, free_slot = 0;
    float big;
    if (t == 0)
    {
        return LIDET_ERR_ARG;
    }
    if (t->magic != LIDET_INIT_MAGIC)
    {
        return LIDET_ERR_STATE;
    }
    if ((det == 0 && n_det > 0u) || !(dt_s > 0.0f) || !(dt_s <= MAX_DT_S))
    {
        return LIDET_ERR_ARG;
    }
    if (ego != 0 &&
        (!in_range(ego->dx_m, -MAX_EGO_M, MAX_EGO_M) || !in_range(ego->dy_m, -MAX_EGO_M, MAX_EGO_M) ||
         !in_range(ego->dyaw_rad, -LIDET_PI_F, LIDET_PI_F)))
    {
        return LIDET_ERR_ARG;
    }
    cfg = &t->cfg;
    st = &t->stats;
    memset(st, 0, sizeof *st);
    /* 1. the detections used: the first LIDET_TRACK_MAX_DETS, the valid ones among them */
    n_use = n_det < (uint32_t)LIDET_TRACK_MAX_DETS ? n_det : (uint32_t)LIDET_TRACK_MAX_DETS;
    st->n_dets_dropped = n_det - n_use;
    for (i = 0; i < n_use; ++i)
    {
        if (det_ok(&det[i]))
        {
            t->col_det[nd++] = (uint16_t)i;
        }
        else
        {
            ++st->n_bad_dets;
        }
    }
    /* 2., 3. ego motion, prediction */
    if (ego != 0)
    {
        ego_motion(t, ego);
    }
    predict(t, dt_s);
    /* 4., 5. costs and assignment */
    for (i = 0; i < (uint32_t)LIDET_TRACK_MAX_TRACKS; ++i)
    {
        if (t->slot[i].used)
        {
            t->row_slot[nt] = (uint16_t)i;
            t->row_col[nt] = -1;
            ++nt;
        }
    }
    memset(t->col_taken, 0, nd);
    big = (cfg->gate_chi2 + cfg->class_penalty) + 1.0f;
    st->n_feasible_pairs = costs(t, det, nt, nd, big);
    if (nt > 0u && nd > 0u && st->n_feasible_pairs > 0u)
    {
        if (cfg->assign == (uint32_t)LIDET_TRACK_ASSIGN_GREEDY)
        {
            greedy(t, nt, nd, big);
        }
        else
        {
            hungarian(t, nt, nd, big);
        }
    }
    /* 6., 7. updates and misses */
    for (r = 0; r < nt; ++r)
    {
        lidet_tracker_slot_t *k = &t->slot[t->row_slot[r]];
        if (t->row_col[r] >= 0)
        {
            const uint32_t j = t->col_det[t->row_col[r]];
            update_track(cfg, k, &det[j], j);
            ++st->n_matched;
            continue;
        }
        k->misses = k->misses < 0xFFFFFFFFu ? k->misses + 1u : k->misses;
        k->det_index = -1;
        if (k->state == (uint8_t)LIDET_TRACK_TENTATIVE || k->misses > cfg->max_misses)
        {
            k->used = 0u;
            ++st->n_deaths;
        }
        else
        {
            k->state = (uint8_t)LIDET_TRACK_COASTING;
        }
    }
    /* 8. births in the lowest free slots, detection order */
    for (c = 0; c < nd; ++c)
    {
        const uint32_t j = t->col_det[c];
        if (t->col_taken[c] || !(det[j].score >= cfg->birth_min_score))
        {
            continue;
        }
        while (free_slot < (uint32_t)LIDET_TRACK_MAX_TRACKS && t->slot[free_slot].used)
        {
            ++free_slot;
        }
        if (free_slot == (uint32_t)LIDET_TRACK_MAX_TRACKS)
        {
            ++st->n_births_dropped;
            continue;
        }
        birth(cfg, &t->slot[free_slot], &det[j], j, t->next_id);
        t->next_id = t->next_id == 0xFFFFFFFFu ? 1u : t->next_id + 1u;
        ++st->n_births;
    }
    /* 9. confirmation; counts */
    for (i = 0; i < (uint32_t)LIDET_TRACK_MAX_TRACKS; ++i)
    {
        lidet_tracker_slot_t *k = &t->slot[i];
        if (!k->used)
        {
            continue;
        }
        if (k->state == (uint8_t)LIDET_TRACK_TENTATIVE && k->hits >= cfg->confirm_hits)
        {
            k->state = (uint8_t)LIDET_TRACK_CONFIRMED;
        }
        ++st->n_tracks;
        st->n_confirmed += k->state != (uint8_t)LIDET_TRACK_TENTATIVE ? 1u : 0u;
    }
    return st->n_dets_dropped > 0u || st->n_births_dropped > 0u ? LIDET_TRUNCATED : LIDET_OK;
}

/* ref: Tracker._reported_yaw. The direction of motion (heading_from_velocity classes) or the box yaw turned to
 * point along the motion, once the speed is >= heading_speed, non-zero and known (|v|^2 >= 4 p_vv). */
static float reported_yaw(const lidet_tracker_cfg_t *cfg, const lidet_tracker_slot_t *k)
{
    const float sp2 = k->vx_mps * k->vx_mps + k->vy_mps * k->vy_mps;
    float hd, dd;
    if (!(sp2 > 0.0f) || !(sp2 >= cfg->heading_speed_mps * cfg->heading_speed_mps) ||
        !(sp2 >= 4.0f * k->p_vv))
    {
        return k->yaw_rad;
    }
    hd = wrap_pi(atan2f(k->vy_mps, k->vx_mps));
    if ((cfg->heading_from_velocity >> k->cls) & 1u)
    {
        return hd;
    }
    dd = wrap_pi(hd - k->yaw_rad);
    return dd > LIDET_HALF_PI_F || dd < -LIDET_HALF_PI_F ? wrap_pi(k->yaw_rad + LIDET_PI_F) : k->yaw_rad;
}

uint32_t lidet_tracker_tracks(const lidet_tracker_t *t, lidet_track_t *out, uint32_t cap, uint32_t flags)
{
    uint32_t n = 0, last = 0, have_last = 0;
    if (t == 0 || t->magic != LIDET_INIT_MAGIC || (out == 0 && cap > 0u))
    {
        return 0;
    }
    while (n < cap)
    {
        const lidet_tracker_slot_t *best = 0;
        uint32_t i;
        for (i = 0; i < (uint32_t)LIDET_TRACK_MAX_TRACKS; ++i)
        {
            const lidet_tracker_slot_t *k = &t->slot[i];
            if (!k->used || (have_last && k->id <= last) || (best != 0 && k->id >= best->id))
            {
                continue;
            }
            if ((k->state == (uint8_t)LIDET_TRACK_COASTING && !(flags & LIDET_TRACK_OUT_COASTING) &&
                 k->misses > t->cfg.report_misses[k->cls]) ||
                (k->state == (uint8_t)LIDET_TRACK_TENTATIVE && !(flags & LIDET_TRACK_OUT_TENTATIVE)))
            {
                continue;
            }
            best = k;
        }
        if (best == 0)
        {
            break;
        }
        {
            lidet_track_t *o = &out[n++];
            o->id = best->id;
            o->cls = best->cls;
            o->state = best->state;
            o->box.cx_m = best->x_m;
            o->box.cy_m = best->y_m;
            o->box.cz_m = best->z_m;
            o->box.l_m = best->l_m;
            o->box.w_m = best->w_m;
            o->box.h_m = best->h_m;
            o->box.yaw_rad = reported_yaw(&t->cfg, best);
            o->vx_mps = best->vx_mps;
            o->vy_mps = best->vy_mps;
            o->p_pp_m2 = best->p_pp;
            o->p_pv = best->p_pv;
            o->p_vv = best->p_vv;
            o->score = best->score;
            o->hits = best->hits;
            o->misses = best->misses;
            o->age = best->age;
            o->det_index = best->det_index;
        }
        last = best->id;
        have_last = 1u;
    }
    return n;
}

const lidet_tracker_stats_t *lidet_tracker_stats(const lidet_tracker_t *t)
{
    return t == 0 ? 0 : &t->stats;
}

uint32_t lidet_tracker_bytes(void)
{
    return (uint32_t)sizeof(lidet_tracker_t);
}
