/* SPDX-License-Identifier: MIT */
/* Flat C entry points over the float tracker (lidet_track.h) for the Python bindings
 * (tools/lidet_tools/track/native.py). Host only: each tracker is allocated on the heap (lidet_py_track_new /
 * lidet_py_track_free), so several can run side by side.
 *
 * The configuration crosses as LIDET_PY_TRACK_NCFG floats in this order: meas_sigma_m[3], accel_sigma_mps2[3],
 * init_vel_sigma_mps[3], gate_max_m[3], gate_chi2, class_penalty, assign, confirm_hits, max_misses,
 * birth_min_score, yaw_alpha, size_alpha, heading_speed_mps, heading_from_velocity, report_misses[3] (the
 * integers as floats).
 * Detections: n rows of `stride` (>= 9) floats cls, x, y, z, l, w, h, yaw, score (a class that is not exactly 0,
 * 1 or 2 reaches the tracker as 255: a bad detection). Tracks: rows of LIDET_PY_TRACK_NF floats x, y, z, l, w,
 * h, yaw, vx, vy, p_pp, p_pv, p_vv, score and of LIDET_PY_TRACK_NI int32 id (as uint32 bits), cls, state, hits,
 * misses, age, det. */
#include <stdlib.h>
#include <string.h>

#include "lidet/lidet.h"

#if defined(_WIN32)
#define LIDET_PY_API __declspec(dllexport)
#else
#define LIDET_PY_API __attribute__((visibility("default")))
#endif

#define LIDET_PY_TRACK_NCFG 25u
#define LIDET_PY_TRACK_NF 13u
#define LIDET_PY_TRACK_NI 7u

/* a float holding an integer in [0, hi] (checked before the cast: a cast of an out-of-range float is UB) */
static int as_uint(float f, uint32_t hi, uint32_t *out)
{
    if (!(f >= 0.0f && f <= (float)hi) || f != (float)(uint32_t)f)
    {
        return 0;
    }
    *out = (uint32_t)f;
    return 1;
}

/* sizes: LIDET_PY_TRACK_NCFG, NF, NI, LIDET_TRACK_MAX_TRACKS, LIDET_TRACK_MAX_DETS, sizeof(lidet_tracker_t) */
LIDET_PY_API void lidet_py_track_sizes(uint32_t *out)
{
    out[0] = LIDET_PY_TRACK_NCFG;
    out[1] = LIDET_PY_TRACK_NF;
    out[2] = LIDET_PY_TRACK_NI;
    out[3] = LIDET_TRACK_MAX_TRACKS;
    out[4] = LIDET_TRACK_MAX_DETS;
    out[5] = lidet_tracker_bytes();
}

LIDET_PY_API void *lidet_py_track_new(void)
{
    return calloc(1, sizeof(lidet_tracker_t)); /* zeroed: not initialised (LIDET_ERR_STATE until init) */
}

LIDET_PY_API void lidet_py_track_free(void *t)
{
    free(t);
}

LIDET_PY_API void lidet_py_track_cfg_default(float *f)
{
    lidet_tracker_cfg_t c;
    uint32_t k;
    lidet_tracker_cfg_default(&c);
    for (k = 0; k < 3u; ++k)
    {
        f[k] = c.meas_sigma_m[k];
        f[3u + k] = c.accel_sigma_mps2[k];
        f[6u + k] = c.init_vel_sigma_mps[k];
        f[9u + k] = c.gate_max_m[k];
    }
    f[12] = c.gate_chi2;
    f[13] = c.class_penalty;
    f[14] = (float)c.assign;
    f[15] = (float)c.confirm_hits;
    f[16] = (float)c.max_misses;
    f[17] = c.birth_min_score;
    f[18] = c.yaw_alpha;
    f[19] = c.size_alpha;
    f[20] = c.heading_speed_mps;
    f[21] = (float)c.heading_from_velocity;
    for (k = 0; k < 3u; ++k)
    {
        f[22u + k] = (float)c.report_misses[k];
    }
}

/* lidet_tracker_init with the flat configuration; an integer field that is no integer in [0, 2^24] is
 * LIDET_ERR_CONFIG (as an out-of-range value would be) */
LIDET_PY_API int lidet_py_track_init(void *t, const float *f)
{
    lidet_tracker_cfg_t c;
    uint32_t k;
    if (t == NULL || f == NULL)
    {
        return LIDET_ERR_ARG;
    }
    memset(&c, 0, sizeof c);
    for (k = 0; k < 3u; ++k)
    {
        c.meas_sigma_m[k] = f[k];
        c.accel_sigma_mps2[k] = f[3u + k];
        c.init_vel_sigma_mps[k] = f[6u + k];
        c.gate_max_m[k] = f[9u + k];
    }
    c.gate_chi2 = f[12];
    c.class_penalty = f[13];
    if (!as_uint(f[14], 1u << 24, &c.assign) || !as_uint(f[15], 1u << 24, &c.confirm_hits) ||
        !as_uint(f[16], 1u << 24, &c.max_misses) || !as_uint(f[21], 1u << 24, &c.heading_from_velocity) ||
        !as_uint(f[22], 1u << 24, &c.report_misses[0]) || !as_uint(f[23], 1u << 24, &c.report_misses[1]) ||
        !as_uint(f[24], 1u << 24, &c.report_misses[2]))
    {
        return LIDET_ERR_CONFIG;
    }
    c.birth_min_score = f[17];
    c.yaw_alpha = f[18];
    c.size_alpha = f[19];
    c.heading_speed_mps = f[20];
    return lidet_tracker_init((lidet_tracker_t *)t, &c);
}

LIDET_PY_API int lidet_py_track_reset(void *t)
{
    return lidet_tracker_reset((lidet_tracker_t *)t);
}

/* lidet_tracker_update on n rows of `stride` floats (stride >= 9; dets may be NULL when n is 0); ego: 3 floats
 * dx, dy, dyaw or NULL. The detections are converted in a heap buffer (all n of them: the tracker itself
 * counts those past LIDET_TRACK_MAX_DETS). */
LIDET_PY_API int lidet_py_track_update(void *t, const float *dets, uint32_t n, uint32_t stride, float dt_s,
                                       const float *ego)
{
    lidet_detection_t *d = NULL;
    lidet_ego_t e;
    uint32_t i;
    int rc;
    if (t == NULL || (dets == NULL && n > 0u) || (n > 0u && stride < 9u))
    {
        return LIDET_ERR_ARG;
    }
    if (n > 0u)
    {
        d = (lidet_detection_t *)calloc(n, sizeof *d);
        if (d == NULL)
        {
            return LIDET_ERR_BUFFER;
        }
    }
    for (i = 0; i < n; ++i)
    {
        const float *r = dets + (size_t)i * stride;
        d[i].cls = r[0] == 0.0f ? 0u : (r[0] == 1.0f ? 1u : (r[0] == 2.0f ? 2u : 255u));
        d[i].box.cx_m = r[1];
        d[i].box.cy_m = r[2];
        d[i].box.cz_m = r[3];
        d[i].box.l_m = r[4];
        d[i].box.w_m = r[5];
        d[i].box.h_m = r[6];
        d[i].box.yaw_rad = r[7];
        d[i].score = r[8];
    }
    if (ego != NULL)
    {
        e.dx_m = ego[0];
        e.dy_m = ego[1];
        e.dyaw_rad = ego[2];
    }
    rc = lidet_tracker_update((lidet_tracker_t *)t, d, n, dt_s, ego != NULL ? &e : NULL);
    free(d);
    return rc;
}

/* lidet_tracker_tracks into out_f (cap x LIDET_PY_TRACK_NF) and out_i (cap x LIDET_PY_TRACK_NI); returns the
 * tracks written. One lidet_track_t at a time, so no buffer beyond the caller's. */
LIDET_PY_API uint32_t lidet_py_track_tracks(const void *t, float *out_f, int32_t *out_i, uint32_t cap,
                                            uint32_t flags)
{
    const lidet_tracker_t *tr = (const lidet_tracker_t *)t;
    lidet_track_t buf[LIDET_TRACK_MAX_TRACKS];
    uint32_t n, k;
    if (tr == NULL || out_f == NULL || out_i == NULL)
    {
        return 0;
    }
    n = lidet_tracker_tracks(tr, buf, cap < LIDET_TRACK_MAX_TRACKS ? cap : LIDET_TRACK_MAX_TRACKS, flags);
    for (k = 0; k < n; ++k)
    {
        const lidet_track_t *o = &buf[k];
        float *f = out_f + (size_t)k * LIDET_PY_TRACK_NF;
        int32_t *q = out_i + (size_t)k * LIDET_PY_TRACK_NI;
        f[0] = o->box.cx_m;
        f[1] = o->box.cy_m;
        f[2] = o->box.cz_m;
        f[3] = o->box.l_m;
        f[4] = o->box.w_m;
        f[5] = o->box.h_m;
        f[6] = o->box.yaw_rad;
        f[7] = o->vx_mps;
        f[8] = o->vy_mps;
        f[9] = o->p_pp_m2;
        f[10] = o->p_pv;
        f[11] = o->p_vv;
        f[12] = o->score;
        memcpy(&q[0], &o->id, sizeof o->id);
        q[1] = o->cls;
        q[2] = o->state;
        memcpy(&q[3], &o->hits, sizeof o->hits);
        memcpy(&q[4], &o->misses, sizeof o->misses);
        memcpy(&q[5], &o->age, sizeof o->age);
        q[6] = o->det_index;
    }
    return n;
}

/* the lidet_tracker_stats_t counts in order (9 uint32); LIDET_ERR_ARG for NULL */
LIDET_PY_API int lidet_py_track_stats(const void *t, uint32_t *out)
{
    const lidet_tracker_stats_t *s = lidet_tracker_stats((const lidet_tracker_t *)t);
    if (s == NULL || out == NULL)
    {
        return LIDET_ERR_ARG;
    }
    out[0] = s->n_tracks;
    out[1] = s->n_confirmed;
    out[2] = s->n_births;
    out[3] = s->n_births_dropped;
    out[4] = s->n_deaths;
    out[5] = s->n_matched;
    out[6] = s->n_feasible_pairs;
    out[7] = s->n_dets_dropped;
    out[8] = s->n_bad_dets;
    return LIDET_OK;
}
