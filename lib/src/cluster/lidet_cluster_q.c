/* SPDX-License-Identifier: MIT */
/* Integer clustering (lidet_cluster_q.h): configuration, the run, the filters and records of each component,
 * the rescue join, accessors. The bookkeeping and the run's driver are the float stage's
 * (lidet_cluster_run_body.h); the growth is in lidet_cluster_grow_q.c, the rescue in
 * lidet_cluster_rescue_q.c. Integer only. The numpy reference is codegen/lidet_ref/cluster_q.py (bit
 * for bit). */
#include <string.h>

#include "internal/lidet_assert.h"
#include "internal/lidet_cluster_q_internal.h"
#include "internal/lidet_qmath.h"
#include "internal/lidet_qpix.h"

void lidet_cluster_q_cfg_default(lidet_cluster_q_cfg_t *cfg, uint32_t n_rows, uint32_t mount_height_mm)
{
    /* lidet_cluster_cfg_default's values (measured there, docs/benchmarks/cluster.md), rounded to the integer
     * units */
    const int sparse = n_rows >= 1u && n_rows <= 16u;
    if (cfg == 0)
    {
        return;
    }
    memset(cfg, 0, sizeof *cfg);
    cfg->diagonals = 1u;
    cfg->max_gap_mm = 700u;
    cfg->theta_urad = sparse ? 120000u : 180000u;
    cfg->max_steps = 5u;
    cfg->max_steps = cfg->max_steps < STEPS ? cfg->max_steps : STEPS;
    cfg->bridge_occluders = sparse ? 0u : 1u;
    cfg->max_gap_per_m_q16 = sparse ? 2621u : 1638u; /* 0.04, 0.025 */
    cfg->min_points = 8u;
    cfg->max_extent_mm = 6000u;
    cfg->max_mean_height_mm = 2500;
    cfg->mount_height_mm = mount_height_mm;
    cfg->rescue_gap_mm = sparse ? 1000u : 800u;
    cfg->rescue_gap_per_m_q16 = 1966u; /* 0.03 */
    cfg->rescue_rows = sparse ? 1u : 2u;
    cfg->rescue_cols = 6u;
    /* worst-case bounds (issue 19) */
    cfg->max_fragment_pixels = sparse ? 2048u : 4096u;
    cfg->max_bridge_per_pixel_q16 = 131072u; /* 2.0 */
    cfg->regrow_gap_mm = sparse ? 0u : 350u;
    cfg->regrow_gap_per_m_q16 = sparse ? 0u : 1311u; /* 0.02 */
    cfg->regrow_max_pixels = 2000u;
    cfg->regrow_max_height_mm = 2500u;
    cfg->regrow_cut_mm = 0u;
    /* the refinement (issue 15) */
    cfg->split_people = 1u;
    cfg->split_min_width_mm = 700u;
    cfg->split_cell_mm = 120u;
    cfg->split_cell_per_m_q16 = 0u;
    cfg->person_max_width_mm = 1000u;
    cfg->person_min_height_mm = 900u;
    cfg->person_min_aspect_q16 = 117965u; /* 1.8 */
    cfg->person_min_cols = 2u;
    cfg->person_min_points = sparse ? 9u : 10u;
    cfg->join_cars = 1u;
    cfg->join_gap_mm = sparse ? 800u : 500u;
    cfg->car_max_length_mm = 5200u;
    cfg->car_max_width_mm = 2200u;
    cfg->car_max_height_mm = 2000u;
    cfg->car_min_length_mm = 2500u;
    cfg->upright_max_width_mm = 1300u;
    cfg->max_join_pieces = 256u;
}

/* the members' sums and bounds (lidet_cluster_stats_body.h) on the int16 pixels, int64 sums; the extent
 * (at most 65535 steps) in mm against the limit */
static inline void read_q(const lidet_cluster_q_state_t *c, uint32_t p, int32_t *x, int32_t *y, int32_t *z)
{
    int32_t v[3];
    lidet__qpix_xyz_m(&c->img, p, c->geo_row_m26, v); /* stored or decoded (lidet_qpix.h) */
    *x = v[0];
    *y = v[1];
    *z = v[2];
}

#define STATS_STATE_T lidet_cluster_q_state_t
#define STATS_V_T int32_t
#define STATS_S_T int64_t
#define STATS_BLOCK_SUMS 1
#define STATS_B_T int32_t /* 64 values within int16 each */
#define STATS_LIM_T uint32_t
#define STATS_READ(c, p, compact, x, y, z) read_q(c, p, x, y, z)
#define STATS_OVER(lo, hi, lim) ((uint32_t)((hi) - (lo)) * 4u > (lim))
#include "internal/lidet_cluster_stats_body.h"

/* height of `mean` above the plane of the seed column's sector (or the flat ground at -mount), 4 mm steps */
int32_t lidet__cluster_q_height(const lidet_cluster_q_state_t *c, uint32_t seed, const int32_t mean[3],
                                const lidet_plane_q_t *planes, uint32_t n_sectors)
{
    int64_t h;
    if (planes != 0)
    {
        const uint32_t col = seed % c->img.n_cols;
        /* col n_sectors in 32 bits where it fits (col < 2^16): a 32-bit division, not a 64-bit library call on
         * the cores without a divide instruction (as the float stage's) */
        uint32_t s = n_sectors <= 0xFFFFu ? (col * n_sectors) / c->img.n_cols
                                          : (uint32_t)(((uint64_t)col * n_sectors) / c->img.n_cols);
        const lidet_plane_q_t *pl;
        s = s < n_sectors ? s : n_sectors - 1u;
        pl = &planes[s];
        if (c->cfg.plane_split_mm > 0u && 16 * ((int64_t)mean[0] * mean[0] + (int64_t)mean[1] * mean[1]) >=
                                              (int64_t)c->cfg.plane_split_mm * c->cfg.plane_split_mm)
        {
            pl = &planes[n_sectors + s]; /* its sector's far plane */
        }
        /* |mean| <= 2^15, |n| <= 2^31: the sum is below 2^49 */
        h = lidet__q_rshift_round(
                (int64_t)pl->nx * mean[0] + (int64_t)pl->ny * mean[1] + (int64_t)pl->nz * mean[2], 30) +
            pl->d_4mm;
    }
    else
    {
        h = (int64_t)mean[2] + lidet__q_div_round((int64_t)c->cfg.mount_height_mm, 4);
    }
    return h > 0x7FFFFFFF ? 0x7FFFFFFF : (h < -0x7FFFFFFF ? -0x7FFFFFFF : (int32_t)h);
}

static void mean_of(const int64_t sum[3], uint32_t n, int32_t mean[3])
{
    uint32_t a;
    for (a = 0; a < 3; ++a)
    {
        mean[a] = (int32_t)lidet__q_div_round(sum[a], (int64_t)n);
    }
}

/* the numeric kernels of the shared filters and records (lidet_cluster_run_body.h), in integers */
typedef struct
{
    int64_t sum[3];
    int32_t lo[3], hi[3], mean[3], h;
} summary_q_t;

static int summarise(const lidet_cluster_q_state_t *c, uint32_t start, uint32_t tail, int small,
                     summary_q_t *s)
{
    return member_stats_of(c, start, tail, small ? 0xFFFFFFFFu : c->cfg.max_extent_mm, s->sum, s->lo, s->hi,
                           1);
}

static int mean_height_ok(const lidet_cluster_q_state_t *c, uint32_t n, uint32_t seed, summary_q_t *s,
                          const lidet_plane_q_t *planes, uint32_t n_sectors)
{
    mean_of(s->sum, n, s->mean);
    s->h = lidet__cluster_q_height(c, seed, s->mean, planes, n_sectors);
    return (int64_t)s->h * 4 <= c->cfg.max_mean_height_mm;
}

static void record_sums(lidet_cluster_q_state_t *c, uint32_t slot, const summary_q_t *s)
{
    uint32_t i;
    for (i = 0; i < 3; ++i)
    {
        c->sums[slot][i] = s->sum[i];
    }
}

/* the group's sums are added: the mean is the rounded mean of all members, exactly */
static void join_mean(lidet_cluster_q_state_t *c, uint32_t slot, uint32_t n, const summary_q_t *s)
{
    uint32_t i;
    for (i = 0; i < 3; ++i)
    {
        c->sums[slot][i] += s->sum[i];
    }
    mean_of(c->sums[slot], c->recs[slot].n_points + n, c->recs[slot].mean_4mm);
}

static void reheight(lidet_cluster_q_state_t *c, uint32_t slot, const lidet_plane_q_t *planes,
                     uint32_t n_sectors)
{
    lidet_cluster_q_rec_t *rec = &c->recs[slot];
    rec->height_4mm = lidet__cluster_q_height(c, rec->seed_pixel, rec->mean_4mm, planes, n_sectors);
}

static int rescue_on(const lidet_cluster_q_state_t *c)
{
    return c->cfg.rescue_gap_mm > 0u;
}

/* a component the regrowth takes: low enough (its full bounds, 4 mm steps) */
static int regrow_fits(const lidet_cluster_q_state_t *c, const summary_q_t *s)
{
    return 4 * ((int64_t)s->hi[2] - s->lo[2]) <= (int64_t)c->cfg.regrow_max_height_mm;
}

/* a pixel the regrowth leaves out (cfg regrow_cut_mm): less than the cut above its ground plane, the plane a mean
 * there would be measured against (4 mm steps) */
static int regrow_cut(const lidet_cluster_q_state_t *c, uint32_t p, const lidet_plane_q_t *planes,
                      uint32_t n_sectors)
{
    int32_t v[3];
    if (c->cfg.regrow_cut_mm == 0u)
    {
        return 0;
    }
    read_q(c, p, &v[0], &v[1], &v[2]);
    return 4 * (int64_t)lidet__cluster_q_height(c, p, v, planes, n_sectors) < (int64_t)c->cfg.regrow_cut_mm;
}

/* the regrowth's flood fill constants (cfg regrow_gap_mm > 0): the first fill's with the tighter gap bound (in
 * 4 mm steps, as the first fill's) */
static int regrow_param(const lidet_cluster_q_state_t *c, const lidet__grow_q_t *lk, lidet__grow_q_t *out)
{
    if (c->cfg.regrow_gap_mm == 0u)
    {
        return 0;
    }
    *out = *lk;
    out->gap_on = 1;
    out->gap = (uint32_t)lidet__q_div_round((int64_t)c->cfg.regrow_gap_mm, 4);
    out->gpm = c->cfg.regrow_gap_per_m_q16;
    return 1;
}

/* the shared bookkeeping (capacity, filters, records, canonical ids, the run's driver) with the integer
 * stage's types */
#define RUN_STATE_T lidet_cluster_q_state_t
#define RUN_REC_T lidet_cluster_q_rec_t
#define RUN_PARAM_T lidet__grow_q_t
#define RUN_PLANE_T lidet_plane_q_t
#define RUN_SUMMARY_T summary_q_t
#define RUN_MEAN(r) ((r)->mean_4mm)
#define RUN_MIN(r) ((r)->min_4mm)
#define RUN_MAX(r) ((r)->max_4mm)
#define RUN_HEIGHT(r) ((r)->height_4mm)
#define RUN_GROW lidet__cluster_q_grow
#define RUN_RESCUE_T lidet__rescue_q_t
#define RUN_RESCUE_FAR 0xFFFFFFFFu
#define RUN_RESCUE_GROW lidet__cluster_q_rescue_grow
#define RUN_FRAGMENT_BUDGET(c) ((c)->cfg.max_fragment_pixels)
#define RUN_REFINE_SPLIT lidet__refine_q_split
#define RUN_REFINE_JOIN lidet__refine_q_join
#include "internal/lidet_cluster_run_body.h"

lidet_status_t lidet_cluster_q_state_init(lidet_cluster_q_state_t *c, const lidet_cluster_q_cfg_t *cfg)
{
    if (c == 0 || cfg == 0)
    {
        return LIDET_ERR_ARG;
    }
    c->magic = 0;
    if (cfg->theta_urad == 0u || cfg->theta_urad >= 1500000u || cfg->max_steps < 1u ||
        cfg->max_steps > STEPS || cfg->min_points < 1u || cfg->max_extent_mm == 0u ||
        cfg->max_extent_mm > 1000000u || cfg->max_gap_mm > 1000000u || cfg->max_gap_per_m_q16 > 65536u ||
        cfg->mount_height_mm > 100000u || cfg->rescue_gap_mm > 10000u || cfg->rescue_gap_per_m_q16 > 16384u ||
        cfg->rescue_rows > LIDET_MAX_ROWS || cfg->rescue_cols > RESCUE_MAX_COLS ||
        cfg->max_bridge_per_pixel_q16 > (64u << 16) || cfg->split_people > 1u ||
        cfg->regrow_gap_mm > 100000u || cfg->regrow_gap_per_m_q16 > 65536u ||
        cfg->regrow_max_height_mm == 0u || cfg->regrow_max_height_mm > 100000u ||
        cfg->regrow_cut_mm > 2000u || cfg->plane_split_mm > 500000u || cfg->split_min_width_mm == 0u ||
        cfg->split_min_width_mm > 1000000u || cfg->split_cell_mm == 0u || cfg->split_cell_mm > 100000u ||
        cfg->split_cell_per_m_q16 > 65536u || cfg->person_max_width_mm == 0u ||
        cfg->person_max_width_mm > 1000000u || cfg->person_min_height_mm > 1000000u ||
        cfg->person_min_aspect_q16 > (100u << 16) || cfg->person_min_points < 1u ||
        cfg->person_min_points > 1000000u || cfg->join_cars > 1u || cfg->join_gap_mm > 1000000u ||
        cfg->car_max_length_mm == 0u || cfg->car_max_length_mm > 1000000u || cfg->car_max_width_mm == 0u ||
        cfg->car_max_width_mm > 1000000u || cfg->car_max_height_mm == 0u ||
        cfg->car_max_height_mm > 1000000u || cfg->car_min_length_mm > 1000000u ||
        cfg->upright_max_width_mm > 1000000u)
    {
        return LIDET_ERR_CONFIG;
    }
    c->cfg = *cfg;
    c->theta_bam = lidet__q_urad_to_bam((int32_t)cfg->theta_urad);
    c->sin_theta_q16 = (uint32_t)lidet__q_rshift_round(lidet__q_sin((uint32_t)c->theta_bam), 14);
    c->geo_row_m26 = 0u; /* set with the geometry on the first run (lidet__cluster_q_setup_geometry) */
    return init_done(c);
}

lidet_status_t lidet_cluster_q_init(lidet_cluster_q_t *c, const lidet_cluster_q_cfg_t *cfg)
{
    return c == 0 ? LIDET_ERR_ARG : lidet_cluster_q_state_init(&c->state, cfg);
}

lidet_status_t lidet_cluster_q_run_buffers(lidet_cluster_q_state_t *c, uint16_t *labels,
                                           lidet_member_t *members, const lidet_range_image_t *img,
                                           const uint8_t *ground_mask, const lidet_plane_q_t *planes,
                                           uint32_t n_sectors)
{
    lidet__grow_q_t lk;
    lidet_cluster_stats_t st;
    uint32_t npix;
    run_span_t sp;
    lidet_status_t chk = run_check(c, labels, members, img, planes, n_sectors);
    /* a compact image with its BAM32 elevations */
    if (chk == LIDET_OK && (!lidet__qpix_image_ok(img) || img->range_4mm == 0 || img->row_elev_bam == 0))
    {
        chk = LIDET_ERR_ARG;
    }
    if (chk != LIDET_OK)
    {
        return chk;
    }
    npix = (uint32_t)img->n_rows * img->n_cols;
    lidet__cluster_q_setup_geometry(c, img);
    run_bind(c, labels, members, img, &st);
    LIDET__GROW_GEOMETRY(lk, img->n_rows, img->n_cols, c->cfg);
    lk.sin_t = c->sin_theta_q16;
    lk.gap_on = c->cfg.max_gap_mm > 0u;
    lk.gap = (uint32_t)lidet__q_div_round((int64_t)c->cfg.max_gap_mm, 4);
    lk.gpm = c->cfg.max_gap_per_m_q16;
    lk.rgap = (uint32_t)lidet__q_div_round((int64_t)c->cfg.rescue_gap_mm, 4);
    lk.rgpm = c->cfg.rescue_gap_per_m_q16;
    lk.bridged = &st.n_bridge_steps;
    st.n_candidates = lidet__cluster_mark_4mm(img->range_4mm, ground_mask, npix, labels);
    /* the bridging budget (issue 19, as the float stage's max_bridge_per_pixel): <= 2^22 * 2^18 >> 16, fits */
    lk.bridge_max = c->cfg.max_bridge_per_pixel_q16 > 0u
                        ? (uint32_t)(((uint64_t)c->cfg.max_bridge_per_pixel_q16 * st.n_candidates) >> 16)
                        : 0xFFFFFFFFu;
    sp.rows = img->n_rows; /* no azimuth window: every column */
    sp.cols = img->n_cols;
    sp.lo = 0u;
    sp.hi = img->n_cols;
    sp.seed_lo = 0u;
    sp.seed_hi = img->n_cols;
    run_fills(c, &lk, &sp, planes, n_sectors, &st);
    run_refine(c, &sp, planes, n_sectors, &st); /* lidet_refine_q.c */
    c->stats = st;
    return st.n_dropped_capacity > 0 ? LIDET_TRUNCATED : LIDET_OK;
}

lidet_status_t lidet_cluster_q_run(lidet_cluster_q_t *c, const lidet_range_image_t *img,
                                   const uint8_t *ground_mask, const lidet_plane_q_t *planes,
                                   uint32_t n_sectors)
{
    return c == 0 ? LIDET_ERR_ARG
                  : lidet_cluster_q_run_buffers(&c->state, c->labels, c->members, img, ground_mask, planes,
                                                n_sectors);
}

lidet_status_t lidet_cluster_q_point_labels(const lidet_cluster_q_state_t *c, const int32_t *point_pixel,
                                            uint32_t n_points, uint32_t *out)
{
    return labels_of_points(c, point_pixel, n_points, out);
}

uint32_t lidet_cluster_q_bytes(void)
{
    return (uint32_t)sizeof(lidet_cluster_q_t);
}
