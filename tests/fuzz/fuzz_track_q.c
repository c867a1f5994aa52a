/* SPDX-License-Identifier: MIT */
/* libFuzzer harness: the integer tracker (lidet_tracker_q_init with fuzzed fields, then a stream of
 * lidet_tracker_q_update / lidet_tracker_q_reset / lidet_tracker_q_tracks calls; lidet_track_q.h, docs/TRACKING.md
 * "Integer build"), at the fuzz library's capacities (8 tracks, 6 detections). The layout of fuzz_track.c in
 * integer units:
 *  - configuration: cfg byte (bit 0 greedy, bits 1-2 confirm_hits - 1, bits 3-7 max_misses), a poke count byte
 *    (% 8), per poke a selector byte and a u32: selector & 0x7F picks a field in lidet_tracker_q_cfg_t order
 *    (0-11 meas_sigma[3], accel_sigma[3], init_vel_sigma[3], gate_max[3]; 12-21 gate_chi2, class_penalty,
 *    assign, confirm_hits, max_misses, birth_min_score, yaw_alpha, size_alpha, heading_speed,
 *    heading_from_velocity; 22-24 report_misses[3]; others none), set to the u32, or with selector bit 7 to
 *    fz_special[u32 % 16];
 *  - up to FZ_MAX_UPDATES updates: op byte, out byte, then
 *    dt (op bits 0-1): 0 = 100 ms; 1 = u8 * 50 ms; 2 = a raw u32; 3 = u8 indexing fz_dt_special;
 *    ego (op bits 2-3): 0 = NULL; 1 = dx, dy i8 * 100 mm, dyaw i8 * 2^24 BAM; 2 = three raw int32; 3 = three u8
 *      indexing fz_special;
 *    op bit 4: reset before the update; op bit 5: det = NULL; detections (op bits 6-7) as fuzz_track.c (a
 *      new list of u8 % (LIDET_TRACK_MAX_DETS + 5) detections; the previous one moved by i8 * 50 mm; the previous
 *      one with a raw u32 n; none);
 *    a detection: kind byte (bits 0-1 class, 3: a raw class byte follows; bit 2 raw: cx cy cz l w h yaw score as
 *      eight raw int32, else compact: cx, cy i16 * 10 mm, cz i8 * 100 mm, l, w, h u8 * 20 mm, yaw i8 * 2^24,
 *      score u8 * 129; bit 3: a byte follows that sets field b & 7 to fz_special[b >> 3]);
 *    out byte: bits 0-1 the output flags, bits 2-5 cap, bit 6 out = NULL.
 * Checks (FZ_CHECK): statuses as documented (LIDET_ERR_ARG exactly for the arguments the header names, the
 * tracker then unchanged), the counts against the harness's own view, every output track: ids >= 1, increasing,
 * of this reset's births, class, state, hits / misses / age consistent with the state, the covariance in its
 * documented bounds (p_pp, p_vv in [1, LIDET_TRACK_Q_P_MAX], p_pv^2 < p_pp p_vv), centre and velocity within
 * LIDET_TRACK_Q_COORD_MAX_MM and LIDET_TRACK_Q_VMAX_MMPS, sizes in [1, LIDET_TRACK_Q_SIZE_MAX_MM], a new track
 * exactly its detection. */
#include "fuzz_common.h"
#include "lidet/lidet_track_q.h"

#define FZ_MAX_UPDATES 64u
#define FZ_DET_BUF (LIDET_TRACK_MAX_DETS + 5u)
#define FZ_OUT (LIDET_TRACK_MAX_TRACKS + 2u)
#define FZ_CMAX LIDET_TRACK_Q_COORD_MAX_MM

static lidet_tracker_q_t g_t, g_copy;
static lidet_detection_q_t g_det[FZ_DET_BUF];
static uint32_t g_n_list;
static lidet_track_q_t g_all[FZ_OUT], g_sub[FZ_OUT];

static const int32_t fz_special[16] = {INT32_MIN,   INT32_MAX,  -1,           0,      1,      FZ_CMAX,
                                       FZ_CMAX + 1, -FZ_CMAX,   -FZ_CMAX - 1, 100000, 100001, 32768,
                                       32769,       0x40000000, -0x40000000,  46341};
static const uint32_t fz_dt_special[8] = {0u, 1u, 10000u, 10001u, 0xFFFFFFFFu, 0x80000000u, 100u, 5000u};

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static int in_range(int32_t v, int32_t lo, int32_t hi)
{
    return v >= lo && v <= hi;
}

/* the ranges lidet_track_q.h documents for lidet_tracker_q_cfg_t */
static int cfg_valid(const lidet_tracker_q_cfg_t *c)
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
    return in_range(c->gate_chi2_q16, 1, 1000 * 65536) && in_range(c->class_penalty_q16, 0, 1000 * 65536) &&
           c->assign <= 1u && c->confirm_hits >= 1u && c->confirm_hits <= 1000u && c->max_misses <= 1000u &&
           c->report_misses[0] <= 1000u && c->report_misses[1] <= 1000u && c->report_misses[2] <= 1000u &&
           in_range(c->birth_min_score_q15, 0, 32768) && in_range(c->yaw_alpha_q15, 0, 32768) &&
           in_range(c->size_alpha_q15, 0, 32768) &&
           in_range(c->heading_speed_mmps, 0, LIDET_TRACK_Q_VMAX_MMPS) &&
           c->heading_from_velocity < (1u << LIDET_N_CLASSES);
}

static void read_cfg(fz_in_t *in, lidet_tracker_q_cfg_t *c)
{
    int32_t *const f[22] = {&c->meas_sigma_mm[0],
                            &c->meas_sigma_mm[1],
                            &c->meas_sigma_mm[2],
                            &c->accel_sigma_mmps2[0],
                            &c->accel_sigma_mmps2[1],
                            &c->accel_sigma_mmps2[2],
                            &c->init_vel_sigma_mmps[0],
                            &c->init_vel_sigma_mmps[1],
                            &c->init_vel_sigma_mmps[2],
                            &c->gate_max_mm[0],
                            &c->gate_max_mm[1],
                            &c->gate_max_mm[2],
                            &c->gate_chi2_q16,
                            &c->class_penalty_q16,
                            NULL,
                            NULL,
                            NULL,
                            &c->birth_min_score_q15,
                            &c->yaw_alpha_q15,
                            &c->size_alpha_q15,
                            &c->heading_speed_mmps,
                            NULL};
    uint32_t *const g[7] = {
        &c->assign,           &c->confirm_hits,     &c->max_misses,      &c->heading_from_velocity,
        &c->report_misses[0], &c->report_misses[1], &c->report_misses[2]};
    const uint32_t b = fz_u8(in);
    uint32_t n, i;
    lidet_tracker_q_cfg_default(c);
    c->assign = b & 1u;
    c->confirm_hits = 1u + ((b >> 1) & 3u);
    c->max_misses = b >> 3;
    n = fz_u8(in) % 8u;
    for (i = 0; i < n; ++i)
    {
        const uint32_t sel = fz_u8(in), u = fz_u32(in), k = sel & 0x7Fu;
        const int32_t v = (sel & 0x80u) ? fz_special[u % 16u] : (int32_t)u;
        if (k < 22u && f[k] != NULL)
        {
            *f[k] = v;
        }
        else if (k < 25u)
        {
            *g[k >= 21u ? k - 18u : k - 14u] = (uint32_t)v;
        }
    }
}

/* what lidet_tracker_q_update skips (n_bad_dets) */
static int det_valid(const lidet_detection_q_t *d)
{
    const lidet_box_q_t *b = &d->box;
    return d->cls < (uint8_t)LIDET_N_CLASSES && in_range(b->l_mm, 1, LIDET_TRACK_Q_SIZE_MAX_MM) &&
           in_range(b->w_mm, 1, LIDET_TRACK_Q_SIZE_MAX_MM) &&
           in_range(b->h_mm, 1, LIDET_TRACK_Q_SIZE_MAX_MM) && in_range(d->score_q15, 0, 32768) &&
           in_range(b->cx_mm, -FZ_CMAX, FZ_CMAX) && in_range(b->cy_mm, -FZ_CMAX, FZ_CMAX) &&
           in_range(b->cz_mm, -FZ_CMAX, FZ_CMAX);
}

/* i8 * 2^24 as a BAM32 angle, without a signed overflow */
static int32_t bam_of(uint32_t b)
{
    return (int32_t)(int8_t)b * 16777216;
}

static void read_det(fz_in_t *in, lidet_detection_q_t *d)
{
    const uint32_t kind = fz_u8(in);
    int32_t *const field[8] = {&d->box.cx_mm, &d->box.cy_mm, &d->box.cz_mm,   &d->box.l_mm,
                               &d->box.w_mm,  &d->box.h_mm,  &d->box.yaw_bam, &d->score_q15};
    uint32_t i;
    memset(d, 0, sizeof *d);
    d->cls = (uint8_t)(kind & 3u);
    if (d->cls == 3u)
    {
        d->cls = fz_u8(in);
    }
    if (kind & 4u)
    {
        for (i = 0; i < 8u; ++i)
        {
            *field[i] = (int32_t)fz_u32(in);
        }
    }
    else
    {
        d->box.cx_mm = (int32_t)(int16_t)fz_u16(in) * 10;
        d->box.cy_mm = (int32_t)(int16_t)fz_u16(in) * 10;
        d->box.cz_mm = (int32_t)(int8_t)fz_u8(in) * 100;
        d->box.l_mm = (int32_t)fz_u8(in) * 20;
        d->box.w_mm = (int32_t)fz_u8(in) * 20;
        d->box.h_mm = (int32_t)fz_u8(in) * 20;
        d->box.yaw_bam = bam_of(fz_u8(in));
        d->score_q15 = (int32_t)fz_u8(in) * 129;
    }
    if (kind & 8u)
    {
        const uint32_t s = fz_u8(in);
        *field[s & 7u] = fz_special[(s >> 3) % 16u];
    }
    d->cluster_id = 1u;
    d->n_points = 10u;
}

/* x + dx, saturated to int32 */
static int32_t add_sat(int32_t x, int32_t dx)
{
    const int64_t v = (int64_t)x + dx;
    return v > INT32_MAX ? INT32_MAX : (v < INT32_MIN ? INT32_MIN : (int32_t)v);
}

static void check_stats_zero(const lidet_tracker_q_stats_t *s)
{
    FZ_CHECK(s->n_tracks == 0u && s->n_confirmed == 0u && s->n_births == 0u && s->n_births_dropped == 0u &&
             s->n_deaths == 0u && s->n_matched == 0u && s->n_feasible_pairs == 0u &&
             s->n_dets_dropped == 0u && s->n_bad_dets == 0u);
}

static int same_track(const lidet_track_q_t *a, const lidet_track_q_t *b)
{
    return a->id == b->id && a->cls == b->cls && a->state == b->state &&
           !memcmp(&a->box, &b->box, sizeof a->box) && a->vx_mmps == b->vx_mmps && a->vy_mmps == b->vy_mmps &&
           a->p_pp == b->p_pp && a->p_pv == b->p_pv && a->p_vv == b->p_vv && a->score_q15 == b->score_q15 &&
           a->hits == b->hits && a->misses == b->misses && a->age == b->age && a->det_index == b->det_index;
}

/* what lidet_tracker_q_tracks gives for flags: confirmed tracks, coasting ones with LIDET_TRACK_OUT_COASTING or
 * while they have missed at most report_misses[class] scans, tentative ones with LIDET_TRACK_OUT_TENTATIVE */
static int wanted(const lidet_track_q_t *o, uint32_t flags)
{
    return o->state == (uint8_t)LIDET_TRACK_CONFIRMED ||
           (o->state == (uint8_t)LIDET_TRACK_COASTING &&
            ((flags & LIDET_TRACK_OUT_COASTING) || o->misses <= g_t.cfg.report_misses[o->cls])) ||
           (o->state == (uint8_t)LIDET_TRACK_TENTATIVE && (flags & LIDET_TRACK_OUT_TENTATIVE));
}

static int64_t clamp_p(int64_t v)
{
    return v < 1 ? 1 : (v > LIDET_TRACK_Q_P_MAX ? LIDET_TRACK_Q_P_MAX : v);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    fz_in_t in = {data, size};
    lidet_tracker_q_cfg_t cfg;
    const lidet_tracker_q_stats_t *st;
    uint32_t live = 0, issued = 0, n_updates = 0, last_n_use = 0, i;
    lidet_status_t rc;
    memset(&g_t, 0, sizeof g_t);
    memset(g_det, 0, sizeof g_det);
    g_n_list = 0;
    read_cfg(&in, &cfg);
    /* before init: NULL arguments, no state */
    FZ_CHECK(lidet_tracker_q_init(NULL, &cfg) == LIDET_ERR_ARG &&
             lidet_tracker_q_init(&g_t, NULL) == LIDET_ERR_ARG);
    FZ_CHECK(lidet_tracker_q_update(NULL, NULL, 0, 100u, NULL) == LIDET_ERR_ARG);
    FZ_CHECK(lidet_tracker_q_update(&g_t, NULL, 0, 100u, NULL) == LIDET_ERR_STATE);
    FZ_CHECK(lidet_tracker_q_reset(NULL) == LIDET_ERR_ARG && lidet_tracker_q_reset(&g_t) == LIDET_ERR_STATE);
    FZ_CHECK(lidet_tracker_q_tracks(&g_t, g_all, FZ_OUT, 3u) == 0u && lidet_tracker_q_stats(NULL) == NULL);
    FZ_CHECK(lidet_tracker_q_bytes() == (uint32_t)sizeof(lidet_tracker_q_t));
    lidet_tracker_q_cfg_default(NULL); /* a no-op */
    rc = lidet_tracker_q_init(&g_t, &cfg);
    FZ_CHECK(rc == (cfg_valid(&cfg) ? LIDET_OK : LIDET_ERR_CONFIG));
    if (rc != LIDET_OK)
    {
        FZ_CHECK(lidet_tracker_q_update(&g_t, NULL, 0, 100u, NULL) == LIDET_ERR_STATE);
        return 0;
    }
    st = lidet_tracker_q_stats(&g_t);
    FZ_CHECK(st != NULL);
    check_stats_zero(st);
    while (in.n > 0 && n_updates < FZ_MAX_UPDATES)
    {
        const uint32_t op = fz_u8(&in), outb = fz_u8(&in), src = op >> 6;
        lidet_ego_q_t ego_v;
        const lidet_ego_q_t *ego = NULL;
        const lidet_detection_q_t *det;
        uint32_t dt, n = 0, n_use, n_valid = 0, n_eligible = 0, n_all, n_sub, n_conf = 0, n_fresh = 0, cap,
                     flags;
        int arg_bad;
        ++n_updates;
        switch (op & 3u)
        {
        case 0:
            dt = 100u;
            break;
        case 1:
            dt = fz_u8(&in) * 50u;
            break;
        case 2:
            dt = fz_u32(&in);
            break;
        default:
            dt = fz_dt_special[fz_u8(&in) % 8u];
            break;
        }
        switch ((op >> 2) & 3u)
        {
        case 1:
            ego_v.dx_mm = (int32_t)(int8_t)fz_u8(&in) * 100;
            ego_v.dy_mm = (int32_t)(int8_t)fz_u8(&in) * 100;
            ego_v.dyaw_bam = bam_of(fz_u8(&in));
            ego = &ego_v;
            break;
        case 2:
            ego_v.dx_mm = (int32_t)fz_u32(&in);
            ego_v.dy_mm = (int32_t)fz_u32(&in);
            ego_v.dyaw_bam = (int32_t)fz_u32(&in);
            ego = &ego_v;
            break;
        case 3:
            ego_v.dx_mm = fz_special[fz_u8(&in) % 16u];
            ego_v.dy_mm = fz_special[fz_u8(&in) % 16u];
            ego_v.dyaw_bam = fz_special[fz_u8(&in) % 16u];
            ego = &ego_v;
            break;
        default:
            break;
        }
        if (op & 0x10u)
        {
            FZ_CHECK(lidet_tracker_q_reset(&g_t) == LIDET_OK);
            check_stats_zero(st);
            FZ_CHECK(lidet_tracker_q_tracks(&g_t, g_all, FZ_OUT, 3u) == 0u);
            live = 0;
            issued = 0;
        }
        if (src == 0u)
        {
            g_n_list = fz_u8(&in) % FZ_DET_BUF;
            for (i = 0; i < g_n_list; ++i)
            {
                read_det(&in, &g_det[i]);
            }
            n = g_n_list;
        }
        else if (src == 1u)
        {
            const int32_t dx = (int32_t)(int8_t)fz_u8(&in) * 50, dy = (int32_t)(int8_t)fz_u8(&in) * 50;
            for (i = 0; i < g_n_list; ++i)
            {
                g_det[i].box.cx_mm = add_sat(g_det[i].box.cx_mm, dx);
                g_det[i].box.cy_mm = add_sat(g_det[i].box.cy_mm, dy);
            }
            n = g_n_list;
        }
        else if (src == 2u)
        {
            n = fz_u32(&in);
        }
        det = (op & 0x20u) ? NULL : g_det;
        arg_bad = (det == NULL && n > 0u) || dt == 0u || dt > LIDET_TRACK_Q_DT_MAX_MS ||
                  (ego != NULL &&
                   (!in_range(ego->dx_mm, -FZ_CMAX, FZ_CMAX) || !in_range(ego->dy_mm, -FZ_CMAX, FZ_CMAX)));
        n_use = n < (uint32_t)LIDET_TRACK_MAX_DETS ? n : (uint32_t)LIDET_TRACK_MAX_DETS;
        if (det != NULL)
        {
            for (i = 0; i < n_use; ++i)
            {
                if (det_valid(&det[i]))
                {
                    ++n_valid;
                    n_eligible += det[i].score_q15 >= g_t.cfg.birth_min_score_q15 ? 1u : 0u;
                }
            }
        }
        memcpy(&g_copy, &g_t, sizeof g_t);
        rc = lidet_tracker_q_update(&g_t, det, n, dt, ego);
        if (arg_bad)
        {
            FZ_CHECK(rc == LIDET_ERR_ARG);
            FZ_CHECK(memcmp(&g_copy, &g_t, sizeof g_t) == 0);
        }
        else
        {
            FZ_CHECK(rc == LIDET_OK || rc == LIDET_TRUNCATED);
            FZ_CHECK((rc == LIDET_TRUNCATED) == (st->n_dets_dropped > 0u || st->n_births_dropped > 0u));
            FZ_CHECK(st->n_dets_dropped == n - n_use && st->n_bad_dets == n_use - n_valid);
            FZ_CHECK(st->n_tracks <= (uint32_t)LIDET_TRACK_MAX_TRACKS && st->n_confirmed <= st->n_tracks);
            FZ_CHECK(st->n_feasible_pairs <= live * n_valid && st->n_matched <= st->n_feasible_pairs);
            FZ_CHECK(st->n_matched <= live && st->n_matched <= n_valid &&
                     st->n_deaths <= live - st->n_matched);
            FZ_CHECK(st->n_tracks == live + st->n_births - st->n_deaths);
            FZ_CHECK(st->n_births + st->n_births_dropped <= n_valid - st->n_matched);
            FZ_CHECK(st->n_births + st->n_births_dropped + st->n_matched >= n_eligible);
            FZ_CHECK(st->n_births_dropped == 0u || st->n_tracks == (uint32_t)LIDET_TRACK_MAX_TRACKS);
            live = st->n_tracks;
            issued += st->n_births;
            last_n_use = n_use;
        }
        /* every track, then the fuzzed flags and cap */
        memset(g_all, 0, sizeof g_all);
        n_all =
            lidet_tracker_q_tracks(&g_t, g_all, FZ_OUT, LIDET_TRACK_OUT_COASTING | LIDET_TRACK_OUT_TENTATIVE);
        FZ_CHECK(n_all == live);
        for (i = 0; i < n_all; ++i)
        {
            const lidet_track_q_t *o = &g_all[i];
            const lidet_box_q_t *b = &o->box;
            FZ_CHECK(o->id >= 1u && o->id <= issued && (i == 0u || o->id > g_all[i - 1u].id));
            FZ_CHECK(o->cls < (uint8_t)LIDET_N_CLASSES && o->state <= (uint8_t)LIDET_TRACK_COASTING);
            FZ_CHECK(in_range(b->cx_mm, -FZ_CMAX, FZ_CMAX) && in_range(b->cy_mm, -FZ_CMAX, FZ_CMAX) &&
                     in_range(b->cz_mm, -FZ_CMAX, FZ_CMAX));
            FZ_CHECK(in_range(b->l_mm, 1, LIDET_TRACK_Q_SIZE_MAX_MM) &&
                     in_range(b->w_mm, 1, LIDET_TRACK_Q_SIZE_MAX_MM) &&
                     in_range(b->h_mm, 1, LIDET_TRACK_Q_SIZE_MAX_MM));
            FZ_CHECK(in_range(o->vx_mmps, -LIDET_TRACK_Q_VMAX_MMPS, LIDET_TRACK_Q_VMAX_MMPS) &&
                     in_range(o->vy_mmps, -LIDET_TRACK_Q_VMAX_MMPS, LIDET_TRACK_Q_VMAX_MMPS));
            FZ_CHECK(o->p_pp >= 1 && o->p_vv >= 1 && (int64_t)o->p_pv * o->p_pv < (int64_t)o->p_pp * o->p_vv);
            FZ_CHECK(in_range(o->score_q15, 0, 32768) && o->reserved == 0u);
            FZ_CHECK(o->hits >= 1u && (uint64_t)o->hits + o->misses <= (uint64_t)o->age + 1u);
            FZ_CHECK(o->det_index >= -1 && o->det_index < (int32_t)last_n_use);
            if (o->state == (uint8_t)LIDET_TRACK_COASTING)
            {
                FZ_CHECK(o->misses >= 1u && o->misses <= g_t.cfg.max_misses && o->det_index == -1);
            }
            else
            {
                FZ_CHECK(o->misses == 0u && o->det_index >= 0);
            }
            if (o->state == (uint8_t)LIDET_TRACK_TENTATIVE)
            {
                FZ_CHECK(o->hits < g_t.cfg.confirm_hits);
            }
            else
            {
                FZ_CHECK(o->hits >= g_t.cfg.confirm_hits);
                ++n_conf;
            }
            n_fresh += o->det_index >= 0 ? 1u : 0u;
            if (o->age == 0u)
            {
                FZ_CHECK(o->id > issued - st->n_births && o->hits == 1u && o->det_index >= 0);
            }
            else
            {
                FZ_CHECK(o->id <= issued - st->n_births);
            }
            if (o->det_index >= 0 && !arg_bad) /* this update's detection (else the one of an earlier list) */
            {
                const lidet_detection_q_t *d = &g_det[o->det_index];
                FZ_CHECK(det != NULL && det_valid(d) && o->score_q15 == d->score_q15);
                if (o->age == 0u) /* born in this update: the detection itself, at rest */
                {
                    const int64_t ms = g_t.cfg.meas_sigma_mm[d->cls],
                                  vs = g_t.cfg.init_vel_sigma_mmps[d->cls];
                    FZ_CHECK(o->cls == d->cls && !memcmp(b, &d->box, sizeof *b));
                    FZ_CHECK(o->vx_mmps == 0 && o->vy_mmps == 0 && o->p_pv == 0 &&
                             o->p_pp == clamp_p(ms * ms) && o->p_vv == clamp_p(vs * vs) &&
                             d->score_q15 >= g_t.cfg.birth_min_score_q15);
                }
            }
        }
        FZ_CHECK(n_conf == st->n_confirmed && n_fresh == st->n_matched + st->n_births);
        flags = outb & 3u;
        cap = (outb >> 2) & 15u;
        if (outb & 0x40u)
        {
            FZ_CHECK(lidet_tracker_q_tracks(&g_t, NULL, cap, flags) == 0u);
        }
        else
        {
            uint32_t k = 0;
            cap = cap < FZ_OUT ? cap : FZ_OUT;
            memset(g_sub, 0, sizeof g_sub);
            n_sub = lidet_tracker_q_tracks(&g_t, g_sub, cap, flags);
            FZ_CHECK(n_sub <= cap && n_sub <= live);
            for (i = 0; i < n_all && k < n_sub; ++i)
            {
                if (wanted(&g_all[i], flags))
                {
                    FZ_CHECK(same_track(&g_all[i], &g_sub[k]));
                    ++k;
                }
            }
            FZ_CHECK(k == n_sub);
            if (n_sub < cap)
            {
                for (; i < n_all; ++i)
                {
                    FZ_CHECK(!wanted(&g_all[i], flags));
                }
            }
        }
    }
    return 0;
}
