/* SPDX-License-Identifier: MIT */
/* libFuzzer harness: the float tracker (lidet_tracker_init with fuzzed fields, then a stream of
 * lidet_tracker_update / lidet_tracker_reset / lidet_tracker_tracks calls; lidet_track.h, docs/TRACKING.md). The
 * fuzz library holds LIDET_TRACK_MAX_TRACKS 8 tracks and takes LIDET_TRACK_MAX_DETS 6 detections, so births
 * without a free slot and dropped detections come with a few objects.
 *
 * Input (reads past the end yield zeros):
 *  - configuration: cfg byte (bit 0 greedy assignment, bits 1-2 confirm_hits - 1, bits 3-7 max_misses), a poke
 *    count byte (% 8), then per poke a selector byte and a u32: selector & 0x7F picks a field (0-17 the float
 *    fields in lidet_tracker_cfg_t order: meas_sigma[3], accel_sigma[3], init_vel_sigma[3], gate_max[3],
 *    gate_chi2, class_penalty, birth_min_score, yaw_alpha, size_alpha, heading_speed; 18-24 assign,
 *    confirm_hits, max_misses, heading_from_velocity, report_misses[3]; others none); a float field takes the
 *    u32's bits when selector bit 7 is set, else (int32) u32 / 65536; a uint32 field takes the u32.
 *  - then up to FZ_MAX_UPDATES updates, each: op byte, out byte, then
 *    dt (op bits 0-1): 0 = 0.1 s; 1 = u8 * 0.05 s; 2 = a raw f32; 3 = u8 s: fz_dt_special[s % 12] (s >= 192:
 *      NaN, Inf or -Inf);
 *    ego (op bits 2-3): 0 = NULL; 1 = dx, dy i8 * 0.1 m, dyaw i8 * pi / 128; 2 = three raw f32; 3 = three u8
 *      indexing special() (NaN, Inf, -Inf, then fz_special);
 *    op bit 4: lidet_tracker_reset before the update; op bit 5: det = NULL (with whatever n the source gives);
 *    the detections (op bits 6-7): 0 = a new list: u8 n (% (LIDET_TRACK_MAX_DETS + 5)), then n detections;
 *      1 = the previous list moved by dx, dy i8 * 0.05 m; 2 = the previous list unchanged with a raw u32 n (any,
 *      0xFFFFFFFF included; the tracker reads at most LIDET_TRACK_MAX_DETS); 3 = none (n 0);
 *    a detection: kind byte (bits 0-1 class, 3: a raw class byte follows; bit 2 raw: cx cy cz l w h yaw score
 *      as eight raw f32, else compact: cx, cy i16 * 0.01 m, cz i8 * 0.1 m, l, w, h u8 * 0.05 m, yaw
 *      i8 * pi / 128, score u8 / 255; bit 3: a byte follows that sets field b & 7 to special(b >> 3));
 *    out byte: bits 0-1 the output flags, bits 2-5 cap, bit 6 out = NULL.
 * Checks after every call (FZ_CHECK): statuses as documented (LIDET_ERR_ARG exactly for the arguments the
 * header names, and then the whole tracker unchanged); the counts (births, deaths, matches, bad and dropped
 * detections) against the harness's own view; every output track: ids >= 1, increasing, of this reset's births,
 * class, state, hits / misses / age consistent with the state, finite box, velocity and covariance (p_pp,
 * p_vv >= 0, p_pv^2 <= p_pp p_vv), yaw in (-pi, pi], a new track exactly its detection. */
#include <math.h>

#include "fuzz_common.h"
#include "lidet/lidet_track.h"

#define FZ_MAX_UPDATES 64u
#define FZ_DET_BUF (LIDET_TRACK_MAX_DETS + 5u)
#define FZ_OUT (LIDET_TRACK_MAX_TRACKS + 2u)
#define FZ_PI_F 3.14159265f /* the library's LIDET_PI_F */

static lidet_tracker_t g_t, g_copy;
static lidet_detection_t g_det[FZ_DET_BUF];
static uint32_t g_n_list; /* detections of the last list (sources 0, 1) */
static lidet_track_t g_all[FZ_OUT], g_sub[FZ_OUT];

static const float fz_special[16] = {
    0.0f,     -0.0f,    -1.0f,  1e30f,   -1e30f, 3.4028235e38f, -3.4028235e38f, 1.4e-45f,
    10000.0f, 10001.0f, 100.0f, 100.01f, 1e-30f, 3.14159265f,   -3.14159265f,   1000.0f};
static const uint32_t fz_special_bits[3] = {0x7FC00000u, 0x7F800000u, 0xFF800000u}; /* NaN, Inf, -Inf */
static const float fz_dt_special[12] = {0.0f,     -0.0f, -0.1f, 10.0f, 10.000001f, 1e-30f,
                                        1.4e-45f, 1e30f, 0.1f,  1.0f,  9.99f,      0.01f};

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static float bits_f32(uint32_t u)
{
    float f;
    memcpy(&f, &u, sizeof f);
    return f;
}

/* index i: the first 3 are NaN, Inf, -Inf, then fz_special */
static float special(uint32_t i)
{
    i %= 19u;
    return i < 3u ? bits_f32(fz_special_bits[i]) : fz_special[i - 3u];
}

static int in_range(float v, float lo, float hi)
{
    return v >= lo && v <= hi;
}

/* the ranges lidet_track.h documents for lidet_tracker_cfg_t */
static int cfg_valid(const lidet_tracker_cfg_t *c)
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
    return c->gate_chi2 > 0.0f && c->gate_chi2 <= 1000.0f && in_range(c->class_penalty, 0.0f, 1000.0f) &&
           c->assign <= 1u && c->confirm_hits >= 1u && c->confirm_hits <= 1000u && c->max_misses <= 1000u &&
           c->report_misses[0] <= 1000u && c->report_misses[1] <= 1000u && c->report_misses[2] <= 1000u &&
           in_range(c->birth_min_score, 0.0f, 1.0f) && in_range(c->yaw_alpha, 0.0f, 1.0f) &&
           in_range(c->size_alpha, 0.0f, 1.0f) && in_range(c->heading_speed_mps, 0.0f, 100.0f) &&
           c->heading_from_velocity < (1u << LIDET_N_CLASSES);
}

static void read_cfg(fz_in_t *in, lidet_tracker_cfg_t *c)
{
    float *const f[18] = {&c->meas_sigma_m[0],
                          &c->meas_sigma_m[1],
                          &c->meas_sigma_m[2],
                          &c->accel_sigma_mps2[0],
                          &c->accel_sigma_mps2[1],
                          &c->accel_sigma_mps2[2],
                          &c->init_vel_sigma_mps[0],
                          &c->init_vel_sigma_mps[1],
                          &c->init_vel_sigma_mps[2],
                          &c->gate_max_m[0],
                          &c->gate_max_m[1],
                          &c->gate_max_m[2],
                          &c->gate_chi2,
                          &c->class_penalty,
                          &c->birth_min_score,
                          &c->yaw_alpha,
                          &c->size_alpha,
                          &c->heading_speed_mps};
    uint32_t *const u[7] = {
        &c->assign,           &c->confirm_hits,     &c->max_misses,      &c->heading_from_velocity,
        &c->report_misses[0], &c->report_misses[1], &c->report_misses[2]};
    const uint32_t b = fz_u8(in);
    uint32_t n, i;
    lidet_tracker_cfg_default(c);
    c->assign = b & 1u;
    c->confirm_hits = 1u + ((b >> 1) & 3u);
    c->max_misses = b >> 3;
    n = fz_u8(in) % 8u;
    for (i = 0; i < n; ++i)
    {
        const uint32_t sel = fz_u8(in), v = fz_u32(in), k = sel & 0x7Fu;
        if (k < 18u)
        {
            *f[k] = (sel & 0x80u) ? bits_f32(v) : (float)(int32_t)v * (1.0f / 65536.0f);
        }
        else if (k < 25u)
        {
            *u[k - 18u] = v;
        }
    }
}

/* what lidet_tracker_update skips (n_bad_dets): a non-finite field, a class outside lidet_class_t, a size <= 0 or
 * over 100 m, a centre coordinate beyond 10 km */
static int det_valid(const lidet_detection_t *d)
{
    const lidet_box_t *b = &d->box;
    return d->cls < (uint8_t)LIDET_N_CLASSES && isfinite(b->yaw_rad) && isfinite(d->score) &&
           in_range(b->cx_m, -10000.0f, 10000.0f) && in_range(b->cy_m, -10000.0f, 10000.0f) &&
           in_range(b->cz_m, -10000.0f, 10000.0f) && b->l_m > 0.0f && b->l_m <= 100.0f && b->w_m > 0.0f &&
           b->w_m <= 100.0f && b->h_m > 0.0f && b->h_m <= 100.0f;
}

static void read_det(fz_in_t *in, lidet_detection_t *d)
{
    const uint32_t kind = fz_u8(in);
    float *const field[8] = {&d->box.cx_m, &d->box.cy_m, &d->box.cz_m,    &d->box.l_m,
                             &d->box.w_m,  &d->box.h_m,  &d->box.yaw_rad, &d->score};
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
            *field[i] = fz_f32(in);
        }
    }
    else
    {
        d->box.cx_m = (float)(int16_t)fz_u16(in) * 0.01f;
        d->box.cy_m = (float)(int16_t)fz_u16(in) * 0.01f;
        d->box.cz_m = (float)(int8_t)fz_u8(in) * 0.1f;
        d->box.l_m = (float)fz_u8(in) * 0.05f;
        d->box.w_m = (float)fz_u8(in) * 0.05f;
        d->box.h_m = (float)fz_u8(in) * 0.05f;
        d->box.yaw_rad = (float)(int8_t)fz_u8(in) * (FZ_PI_F / 128.0f);
        d->score = (float)fz_u8(in) * (1.0f / 255.0f);
    }
    if (kind & 8u)
    {
        const uint32_t s = fz_u8(in);
        *field[s & 7u] = special(s >> 3);
    }
    d->cluster_id = 1u;
    d->n_points = 10u;
}

static void check_stats_zero(const lidet_tracker_stats_t *s)
{
    FZ_CHECK(s->n_tracks == 0u && s->n_confirmed == 0u && s->n_births == 0u && s->n_births_dropped == 0u &&
             s->n_deaths == 0u && s->n_matched == 0u && s->n_feasible_pairs == 0u &&
             s->n_dets_dropped == 0u && s->n_bad_dets == 0u);
}

static int same_track(const lidet_track_t *a, const lidet_track_t *b)
{
    return a->id == b->id && a->cls == b->cls && a->state == b->state &&
           !memcmp(&a->box, &b->box, sizeof a->box) && !memcmp(&a->vx_mps, &b->vx_mps, 6u * sizeof(float)) &&
           a->hits == b->hits && a->misses == b->misses && a->age == b->age && a->det_index == b->det_index;
}

/* what lidet_tracker_tracks gives for flags: confirmed tracks, coasting ones with LIDET_TRACK_OUT_COASTING or
 * while they have missed at most report_misses[class] scans, tentative ones with LIDET_TRACK_OUT_TENTATIVE */
static int wanted(const lidet_track_t *o, uint32_t flags)
{
    return o->state == (uint8_t)LIDET_TRACK_CONFIRMED ||
           (o->state == (uint8_t)LIDET_TRACK_COASTING &&
            ((flags & LIDET_TRACK_OUT_COASTING) || o->misses <= g_t.cfg.report_misses[o->cls])) ||
           (o->state == (uint8_t)LIDET_TRACK_TENTATIVE && (flags & LIDET_TRACK_OUT_TENTATIVE));
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    fz_in_t in = {data, size};
    lidet_tracker_cfg_t cfg;
    const lidet_tracker_stats_t *st;
    uint32_t live = 0, issued = 0, n_updates = 0, last_n_use = 0, i;
    lidet_status_t rc;
    memset(&g_t, 0, sizeof g_t);
    memset(g_det, 0, sizeof g_det);
    g_n_list = 0;
    read_cfg(&in, &cfg);
    /* before init: NULL arguments, no state */
    FZ_CHECK(lidet_tracker_init(NULL, &cfg) == LIDET_ERR_ARG &&
             lidet_tracker_init(&g_t, NULL) == LIDET_ERR_ARG);
    FZ_CHECK(lidet_tracker_update(NULL, NULL, 0, 0.1f, NULL) == LIDET_ERR_ARG);
    FZ_CHECK(lidet_tracker_update(&g_t, NULL, 0, 0.1f, NULL) == LIDET_ERR_STATE);
    FZ_CHECK(lidet_tracker_reset(NULL) == LIDET_ERR_ARG && lidet_tracker_reset(&g_t) == LIDET_ERR_STATE);
    FZ_CHECK(lidet_tracker_tracks(&g_t, g_all, FZ_OUT, 3u) == 0u && lidet_tracker_stats(NULL) == NULL);
    FZ_CHECK(lidet_tracker_bytes() == (uint32_t)sizeof(lidet_tracker_t));
    lidet_tracker_cfg_default(NULL); /* a no-op */
    rc = lidet_tracker_init(&g_t, &cfg);
    FZ_CHECK(rc == (cfg_valid(&cfg) ? LIDET_OK : LIDET_ERR_CONFIG));
    if (rc != LIDET_OK)
    {
        FZ_CHECK(lidet_tracker_update(&g_t, NULL, 0, 0.1f, NULL) == LIDET_ERR_STATE);
        return 0;
    }
    st = lidet_tracker_stats(&g_t);
    FZ_CHECK(st != NULL);
    check_stats_zero(st);
    while (in.n > 0 && n_updates < FZ_MAX_UPDATES)
    {
        const uint32_t op = fz_u8(&in), outb = fz_u8(&in), src = op >> 6;
        lidet_ego_t ego_v;
        const lidet_ego_t *ego = NULL;
        const lidet_detection_t *det;
        float dt;
        uint32_t n = 0, n_use, n_valid = 0, n_eligible = 0, n_all, n_sub, n_conf = 0, n_fresh = 0, cap, flags;
        int arg_bad;
        ++n_updates;
        switch (op & 3u)
        {
        case 0:
            dt = 0.1f;
            break;
        case 1:
            dt = (float)fz_u8(&in) * 0.05f;
            break;
        case 2:
            dt = fz_f32(&in);
            break;
        default:
        {
            const uint32_t s = fz_u8(&in);
            dt = s >= 12u * 16u ? bits_f32(fz_special_bits[s % 3u]) : fz_dt_special[s % 12u];
        }
        }
        switch ((op >> 2) & 3u)
        {
        case 1:
            ego_v.dx_m = (float)(int8_t)fz_u8(&in) * 0.1f;
            ego_v.dy_m = (float)(int8_t)fz_u8(&in) * 0.1f;
            ego_v.dyaw_rad = (float)(int8_t)fz_u8(&in) * (FZ_PI_F / 128.0f);
            ego = &ego_v;
            break;
        case 2:
            ego_v.dx_m = fz_f32(&in);
            ego_v.dy_m = fz_f32(&in);
            ego_v.dyaw_rad = fz_f32(&in);
            ego = &ego_v;
            break;
        case 3:
            ego_v.dx_m = special(fz_u8(&in));
            ego_v.dy_m = special(fz_u8(&in));
            ego_v.dyaw_rad = special(fz_u8(&in));
            ego = &ego_v;
            break;
        default:
            break;
        }
        if (op & 0x10u)
        {
            FZ_CHECK(lidet_tracker_reset(&g_t) == LIDET_OK);
            check_stats_zero(st);
            FZ_CHECK(lidet_tracker_tracks(&g_t, g_all, FZ_OUT, 3u) == 0u);
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
            const float dx = (float)(int8_t)fz_u8(&in) * 0.05f, dy = (float)(int8_t)fz_u8(&in) * 0.05f;
            for (i = 0; i < g_n_list; ++i)
            {
                g_det[i].box.cx_m += dx;
                g_det[i].box.cy_m += dy;
            }
            n = g_n_list;
        }
        else if (src == 2u)
        {
            n = fz_u32(&in);
        }
        det = (op & 0x20u) ? NULL : g_det;
        arg_bad = (det == NULL && n > 0u) || !(dt > 0.0f && dt <= 10.0f) ||
                  (ego != NULL &&
                   (!in_range(ego->dx_m, -1000.0f, 1000.0f) || !in_range(ego->dy_m, -1000.0f, 1000.0f) ||
                    !in_range(ego->dyaw_rad, -FZ_PI_F, FZ_PI_F)));
        n_use = n < (uint32_t)LIDET_TRACK_MAX_DETS ? n : (uint32_t)LIDET_TRACK_MAX_DETS;
        if (det != NULL)
        {
            for (i = 0; i < n_use; ++i)
            {
                if (det_valid(&det[i]))
                {
                    ++n_valid;
                    n_eligible += det[i].score >= g_t.cfg.birth_min_score ? 1u : 0u;
                }
            }
        }
        memcpy(&g_copy, &g_t, sizeof g_t);
        rc = lidet_tracker_update(&g_t, det, n, dt, ego);
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
            lidet_tracker_tracks(&g_t, g_all, FZ_OUT, LIDET_TRACK_OUT_COASTING | LIDET_TRACK_OUT_TENTATIVE);
        FZ_CHECK(n_all == live);
        for (i = 0; i < n_all; ++i)
        {
            const lidet_track_t *o = &g_all[i];
            const lidet_box_t *b = &o->box;
            const double pp = (double)o->p_pp_m2, pv = (double)o->p_pv, vv = (double)o->p_vv;
            FZ_CHECK(o->id >= 1u && o->id <= issued && (i == 0u || o->id > g_all[i - 1u].id));
            FZ_CHECK(o->cls < (uint8_t)LIDET_N_CLASSES && o->state <= (uint8_t)LIDET_TRACK_COASTING);
            FZ_CHECK(isfinite(b->cx_m) && isfinite(b->cy_m) && isfinite(b->cz_m) && isfinite(o->vx_mps) &&
                     isfinite(o->vy_mps) && isfinite(o->score));
            FZ_CHECK(in_range(b->l_m, 0.0f, 100.0f) && in_range(b->w_m, 0.0f, 100.0f) &&
                     in_range(b->h_m, 0.0f, 100.0f) && in_range(b->cz_m, -10000.0f, 10000.0f));
            FZ_CHECK(b->yaw_rad > -FZ_PI_F && b->yaw_rad <= FZ_PI_F);
            FZ_CHECK(isfinite(o->p_pp_m2) && isfinite(o->p_pv) && isfinite(o->p_vv));
            FZ_CHECK(pp >= 0.0 && vv >= 0.0 && pv * pv <= pp * vv * (1.0 + 1e-3) + 1e-12);
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
                const lidet_detection_t *d = &g_det[o->det_index];
                FZ_CHECK(det != NULL && det_valid(d) && o->score == d->score);
                if (o->age == 0u) /* born in this update: the detection itself, at rest */
                {
                    const float ms = g_t.cfg.meas_sigma_m[d->cls], vs = g_t.cfg.init_vel_sigma_mps[d->cls];
                    FZ_CHECK(o->cls == d->cls);
                    FZ_CHECK(b->cx_m == d->box.cx_m && b->cy_m == d->box.cy_m && b->cz_m == d->box.cz_m &&
                             b->l_m == d->box.l_m && b->w_m == d->box.w_m && b->h_m == d->box.h_m);
                    FZ_CHECK(o->vx_mps == 0.0f && o->vy_mps == 0.0f && o->p_pv == 0.0f &&
                             o->p_pp_m2 == ms * ms && o->p_vv == vs * vs &&
                             d->score >= g_t.cfg.birth_min_score);
                }
            }
        }
        FZ_CHECK(n_conf == st->n_confirmed && n_fresh == st->n_matched + st->n_births);
        flags = outb & 3u;
        cap = (outb >> 2) & 15u;
        if (outb & 0x40u)
        {
            FZ_CHECK(lidet_tracker_tracks(&g_t, NULL, cap, flags) == 0u);
        }
        else
        {
            uint32_t k = 0;
            cap = cap < FZ_OUT ? cap : FZ_OUT;
            memset(g_sub, 0, sizeof g_sub);
            n_sub = lidet_tracker_tracks(&g_t, g_sub, cap, flags);
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
            if (n_sub < cap) /* not cut by cap: every wanted track */
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
