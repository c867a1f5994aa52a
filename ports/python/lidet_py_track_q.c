/* SPDX-License-Identifier: MIT */
/* Flat C entry points over the integer tracker (lidet_track_q.h) for the Python bindings
 * (tools/lidet_tools/track/native_q.py); tests/python/test_track_q.py compares them with
 * codegen/lidet_ref/track_q.py. Host only: each tracker is allocated on the heap. */
#include <stdlib.h>
#include <string.h>

#include "internal/lidet_track_q_internal.h"
#include "lidet/lidet.h"
#include "lidet/lidet_track_q.h"

#if defined(_WIN32)
#define LIDET_PY_API __declspec(dllexport)
#else
#define LIDET_PY_API __attribute__((visibility("default")))
#endif

/* the flat configuration: lidet_ref/track_q.py CFG_FIELDS */
#define CFG_LEN 25u
/* one output track: lidet_ref/track_q.py TRACK_Q_FIELDS */
#define TRACK_LEN 20u

/* int64 -> int32 / uint32, saturated (an out-of-range value stays out of range for init's checks) */
static int32_t sat32(int64_t v)
{
    return v < INT32_MIN ? INT32_MIN : (v > INT32_MAX ? INT32_MAX : (int32_t)v);
}

static uint32_t satu32(int64_t v)
{
    return v < 0 || v > (int64_t)UINT32_MAX ? UINT32_MAX : (uint32_t)v;
}

LIDET_PY_API void *lidet_py_track_q_new(void)
{
    return calloc(1, sizeof(lidet_tracker_q_t));
}

LIDET_PY_API void lidet_py_track_q_free(void *t)
{
    free(t);
}

/* out: LIDET_TRACK_MAX_TRACKS, LIDET_TRACK_MAX_DETS, sizeof(lidet_tracker_q_t) */
LIDET_PY_API void lidet_py_track_q_capacity(uint32_t *out)
{
    if (out != NULL)
    {
        out[0] = LIDET_TRACK_MAX_TRACKS;
        out[1] = LIDET_TRACK_MAX_DETS;
        out[2] = lidet_tracker_q_bytes();
    }
}

/* lidet_tracker_q_cfg_default as the flat array */
LIDET_PY_API int lidet_py_track_q_cfg_default(int64_t *out)
{
    lidet_tracker_q_cfg_t c;
    uint32_t k, n = 0;
    if (out == NULL)
    {
        return LIDET_ERR_ARG;
    }
    lidet_tracker_q_cfg_default(&c);
    for (k = 0; k < 3u; ++k)
    {
        out[n + k] = c.meas_sigma_mm[k];
        out[n + 3u + k] = c.accel_sigma_mmps2[k];
        out[n + 6u + k] = c.init_vel_sigma_mmps[k];
        out[n + 9u + k] = c.gate_max_mm[k];
    }
    n = 12u;
    out[n++] = c.gate_chi2_q16;
    out[n++] = c.class_penalty_q16;
    out[n++] = c.assign;
    out[n++] = c.confirm_hits;
    out[n++] = c.max_misses;
    out[n++] = c.birth_min_score_q15;
    out[n++] = c.yaw_alpha_q15;
    out[n++] = c.size_alpha_q15;
    out[n++] = c.heading_speed_mmps;
    out[n++] = c.heading_from_velocity;
    for (k = 0; k < 3u; ++k)
    {
        out[n++] = c.report_misses[k];
    }
    return (int)n;
}

/* lidet_tracker_q_init with the flat configuration (n_cfg must be CFG_LEN) */
LIDET_PY_API int lidet_py_track_q_init(void *tp, const int64_t *cfg, uint32_t n_cfg)
{
    lidet_tracker_q_cfg_t c;
    uint32_t k, n = 12u;
    if (tp == NULL || cfg == NULL || n_cfg != CFG_LEN)
    {
        return LIDET_ERR_ARG;
    }
    for (k = 0; k < 3u; ++k)
    {
        c.meas_sigma_mm[k] = sat32(cfg[k]);
        c.accel_sigma_mmps2[k] = sat32(cfg[3u + k]);
        c.init_vel_sigma_mmps[k] = sat32(cfg[6u + k]);
        c.gate_max_mm[k] = sat32(cfg[9u + k]);
    }
    c.gate_chi2_q16 = sat32(cfg[n++]);
    c.class_penalty_q16 = sat32(cfg[n++]);
    c.assign = satu32(cfg[n++]);
    c.confirm_hits = satu32(cfg[n++]);
    c.max_misses = satu32(cfg[n++]);
    c.birth_min_score_q15 = sat32(cfg[n++]);
    c.yaw_alpha_q15 = sat32(cfg[n++]);
    c.size_alpha_q15 = sat32(cfg[n++]);
    c.heading_speed_mmps = sat32(cfg[n++]);
    c.heading_from_velocity = satu32(cfg[n++]);
    for (k = 0; k < 3u; ++k)
    {
        c.report_misses[k] = satu32(cfg[n++]);
    }
    return lidet_tracker_q_init((lidet_tracker_q_t *)tp, &c);
}

LIDET_PY_API int lidet_py_track_q_reset(void *tp)
{
    return lidet_tracker_q_reset((lidet_tracker_q_t *)tp);
}

/* det: n rows of 9 int32 (cls, cx, cy, cz, l, w, h in mm, yaw BAM32, score Q15; a class outside 0-255 becomes 255);
 * ego: 3 int32 (dx_mm, dy_mm, dyaw_bam) or NULL. Returns the status. */
LIDET_PY_API int lidet_py_track_q_update(void *tp, const int32_t *det, uint32_t n, uint32_t dt_ms,
                                         const int32_t *ego)
{
    lidet_detection_q_t *d = NULL;
    lidet_ego_q_t e;
    uint32_t i;
    int st;
    if (tp == NULL || (det == NULL && n > 0u))
    {
        return LIDET_ERR_ARG;
    }
    if (n > 0u)
    {
        d = (lidet_detection_q_t *)calloc(n, sizeof *d);
        if (d == NULL)
        {
            return LIDET_ERR_BUFFER;
        }
    }
    for (i = 0; i < n; ++i)
    {
        const int32_t *v = det + 9u * i;
        d[i].cls = (uint8_t)(v[0] < 0 || v[0] > 255 ? 255 : v[0]);
        d[i].box.cx_mm = v[1];
        d[i].box.cy_mm = v[2];
        d[i].box.cz_mm = v[3];
        d[i].box.l_mm = v[4];
        d[i].box.w_mm = v[5];
        d[i].box.h_mm = v[6];
        d[i].box.yaw_bam = v[7];
        d[i].score_q15 = v[8];
        d[i].cluster_id = (uint16_t)(i + 1u);
    }
    if (ego != NULL)
    {
        e.dx_mm = ego[0];
        e.dy_mm = ego[1];
        e.dyaw_bam = ego[2];
    }
    st = lidet_tracker_q_update((lidet_tracker_q_t *)tp, d, n, dt_ms, ego != NULL ? &e : NULL);
    free(d);
    return st;
}

/* up to cap tracks as rows of TRACK_LEN int64 (lidet_ref/track_q.py TRACK_Q_FIELDS); returns the count */
LIDET_PY_API int lidet_py_track_q_tracks(const void *tp, uint32_t cap, uint32_t flags, int64_t *out)
{
    lidet_track_q_t *tr;
    uint32_t i, n;
    if (tp == NULL || out == NULL)
    {
        return LIDET_ERR_ARG;
    }
    tr = (lidet_track_q_t *)calloc(cap > 0u ? cap : 1u, sizeof *tr);
    if (tr == NULL)
    {
        return LIDET_ERR_BUFFER;
    }
    n = lidet_tracker_q_tracks((const lidet_tracker_q_t *)tp, tr, cap, flags);
    for (i = 0; i < n; ++i)
    {
        const lidet_track_q_t *k = &tr[i];
        int64_t *o = out + TRACK_LEN * i;
        o[0] = k->id;
        o[1] = k->cls;
        o[2] = k->state;
        o[3] = k->box.cx_mm;
        o[4] = k->box.cy_mm;
        o[5] = k->box.cz_mm;
        o[6] = k->box.l_mm;
        o[7] = k->box.w_mm;
        o[8] = k->box.h_mm;
        o[9] = k->box.yaw_bam;
        o[10] = k->vx_mmps;
        o[11] = k->vy_mmps;
        o[12] = k->p_pp;
        o[13] = k->p_pv;
        o[14] = k->p_vv;
        o[15] = k->score_q15;
        o[16] = k->hits;
        o[17] = k->misses;
        o[18] = k->age;
        o[19] = k->det_index;
    }
    free(tr);
    return (int)n;
}

/* the 9 counts of lidet_tracker_q_stats_t in order */
LIDET_PY_API int lidet_py_track_q_stats(const void *tp, uint32_t *out)
{
    const lidet_tracker_q_stats_t *s = lidet_tracker_q_stats((const lidet_tracker_q_t *)tp);
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

/* the assignment alone (lidet__track_q_assign) on an n_rows x n_cols int32 cost matrix (row-major, entries in
 * [0, big]); row_col: n_rows int32 (-1: none). */
LIDET_PY_API int lidet_py_track_q_assign(const int32_t *cost, uint32_t n_rows, uint32_t n_cols, int32_t big,
                                         uint32_t mode, int32_t *row_col)
{
    lidet_tracker_q_t *t;
    uint32_t i, j;
    if (cost == NULL || row_col == NULL || n_rows > LIDET_TRACK_MAX_TRACKS || n_cols > LIDET_TRACK_MAX_DETS ||
        big < 1)
    {
        return LIDET_ERR_ARG;
    }
    for (i = 0; i < n_rows * n_cols; ++i)
    {
        if (cost[i] < 0 || cost[i] > big)
        {
            return LIDET_ERR_ARG;
        }
    }
    t = (lidet_tracker_q_t *)calloc(1, sizeof *t);
    if (t == NULL)
    {
        return LIDET_ERR_BUFFER;
    }
    for (i = 0; i < n_rows; ++i)
    {
        for (j = 0; j < n_cols; ++j)
        {
            t->cost[i * LIDET_TRACK_MAX_DETS + j] = cost[i * n_cols + j];
        }
    }
    if (n_rows > 0u && n_cols > 0u)
    {
        lidet__track_q_assign(t, n_rows, n_cols, big, mode);
    }
    for (i = 0; i < n_rows; ++i)
    {
        row_col[i] = n_cols > 0u ? t->row_col[i] : -1;
    }
    free(t);
    return LIDET_OK;
}
