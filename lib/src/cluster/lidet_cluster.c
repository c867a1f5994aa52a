/* SPDX-License-Identifier: MIT */
/* Depth clustering (see lidet_cluster.h for the algorithm and memory): configuration, the run (candidates,
 * first fill, rescue pass), the filters and records of each component, canonical ids, accessors. The
 * growth is in lidet_cluster_grow.c, the fragment rescue in lidet_cluster_rescue.c.
 * The numpy reference is codegen/lidet_ref/cluster.py: cluster_ref (these three files) and
 * proposal_indices / make_proposal (lidet_proposal.c). */
#include <math.h>
#include <string.h>

#include "internal/lidet_assert.h"
#include "internal/lidet_cluster_internal.h"
#include "internal/lidet_math.h"

void lidet_cluster_cfg_default(lidet_cluster_cfg_t *cfg, const lidet_sensor_t *sensor)
{
    /* <= 16 beams: some defaults of their own, measured on sparse scans (docs/benchmarks/cluster.md) */
    const int sparse = sensor != 0 && sensor->n_rows <= 16;
    if (cfg == 0)
    {
        return;
    }
    memset(cfg, 0, sizeof *cfg);
    /* measured on simulated (20 + 20 scans; checked on 12 + 12 scans of other seeds) and real
     * SemanticKITTI scans, docs/benchmarks/cluster.md: the 8-neighbourhood keeps the sparse, dotted returns
     * of car bodies together on every profile; a small angle joins the fragments of car bodies (grazing
     * hoods and roofs, dropouts) and the gap bound, growing with range, keeps neighbouring parked cars
     * apart (the merges the angle test alone made on real scans). Dense sensors (> 16 beams) also
     * bridge occluders; 16-beam images use no occluder rule (speed: >= 100x DBSCAN) */
    cfg->diagonals = 1;
    cfg->max_gap_m = 0.7f;
    if (sensor != 0 && sensor->n_rows <= 16)
    {
        cfg->theta_rad = 0.12f;
        cfg->max_steps = 5u; /* 4 before issue 15's crowd scenes (time: +1 %, docs/benchmarks/cluster.md) */
        cfg->bridge_occluders = 0;
        cfg->max_gap_per_m = 0.04f;
    }
    else
    {
        cfg->theta_rad = 0.18f;
        cfg->max_steps = 5u;
        cfg->bridge_occluders = 1;
        cfg->max_gap_per_m = 0.025f;
    }
    cfg->max_steps = cfg->max_steps < STEPS ? cfg->max_steps : STEPS;
    /* measured end to end with the shipped models (docs/journal/detector.md, "Smallest cluster"): 10 lost
     * sparse far objects and the VLP-16's pedestrians (simulated HDL-64 AP R40 3D moderate car 82.1 -> 84.0,
     * pedestrian 64.4 -> 68.8; VLP-16 pedestrians within 20 m +2 to +7 points at every mount) and changed
     * nothing on the real scans; each step lower adds proposals (VLP-16: 10 -> 8 -> 6 points, +16 / +40 %) */
    cfg->min_points = 8u;
    cfg->max_extent_m = 6.0f;
    cfg->max_mean_height_m = 2.5f;
    cfg->mount_height_m = sensor != 0 ? sensor->mount_height_m : 1.73f;
    /* measured (docs/benchmarks/cluster.md): see lidet_cluster.h */
    cfg->rescue_gap_m = sparse ? 1.0f : 0.8f;
    cfg->rescue_gap_per_m = 0.03f;
    cfg->rescue_rows = sparse ? 1u : 2u;
    cfg->rescue_cols = 6u;
    /* worst-case bounds (issue 19, docs/ROBUSTNESS.md) */
    cfg->max_fragment_pixels = sparse ? 2048u : 4096u;
    cfg->regrow_gap_m = sparse ? 0.0f : 0.35f;
    cfg->regrow_gap_per_m = sparse ? 0.0f : 0.02f;
    cfg->regrow_max_pixels = 2000u;
    cfg->regrow_max_height_m = 2.5f;
    cfg->regrow_cut_m = 0.0f; /* measured, not the default: docs/journal/real-streets.md */
    cfg->max_bridge_per_pixel = 2.0f;
    /* refinement (issue 15), measured on the simulated crowd scenes (docs/benchmarks/cluster.md); 16 beams:
     * person-sized parts cut off from 9 pixels, a longer join gap (with max_steps and
     * rescue_gap_m above, measured on simulated VLP-16 crowd scenes: lidet_cluster.h) */
    cfg->split_people = 1u;
    cfg->split_min_width_m = 0.7f;
    cfg->split_cell_m = 0.12f;
    cfg->split_cell_per_m = 0.0f;
    cfg->person_max_width_m = 1.0f;
    cfg->person_min_height_m = 0.9f;
    cfg->person_min_aspect = 1.8f;
    cfg->person_min_cols = 2u;
    cfg->person_min_points = sparse ? 9u : 10u;
    cfg->join_cars = 1u;
    cfg->join_gap_m = sparse ? 0.8f : 0.5f;
    cfg->car_max_length_m = 5.2f;
    cfg->car_max_width_m = 2.2f;
    cfg->car_max_height_m = 2.0f;
    cfg->car_min_length_m = 2.5f;
    cfg->upright_max_width_m = 1.3f;
    cfg->max_join_pieces = 256u;
    cfg->azimuth_half_rad = 0.0f;
}

static lidet_status_t init_done(lidet_cluster_state_t *c); /* lidet_cluster_run_body.h */

lidet_status_t lidet_cluster_state_init(lidet_cluster_state_t *c, const lidet_cluster_cfg_t *cfg)
{
    if (c == 0 || cfg == 0)
    {
        return LIDET_ERR_ARG;
    }
    c->magic = 0;
    if (!lidet__isfinite(cfg->theta_rad) || !(cfg->theta_rad > 0.0f) || !(cfg->theta_rad < 1.5f) ||
        cfg->max_steps < 1 || cfg->max_steps > STEPS || cfg->min_points < 1 ||
        !lidet__isfinite(cfg->max_extent_m) || !(cfg->max_extent_m > 0.0f) ||
        !lidet__isfinite(cfg->max_mean_height_m) || !lidet__isfinite(cfg->mount_height_m) ||
        cfg->mount_height_m < 0.0f || !lidet__isfinite(cfg->max_gap_m) || cfg->max_gap_m < 0.0f ||
        !lidet__isfinite(cfg->max_gap_per_m) || cfg->max_gap_per_m < 0.0f ||
        !(cfg->max_bridge_per_pixel >= 0.0f && cfg->max_bridge_per_pixel <= 64.0f) ||
        !(cfg->regrow_gap_m >= 0.0f && cfg->regrow_gap_m <= 100.0f) ||
        !(cfg->regrow_gap_per_m >= 0.0f && cfg->regrow_gap_per_m <= 1.0f) ||
        !(cfg->regrow_max_height_m > 0.0f && cfg->regrow_max_height_m <= 100.0f) ||
        !(cfg->regrow_cut_m >= 0.0f && cfg->regrow_cut_m <= 2.0f) ||
        !(cfg->plane_split_m >= 0.0f && cfg->plane_split_m <= 500.0f) ||
        !lidet__isfinite(cfg->rescue_gap_m) || cfg->rescue_gap_m < 0.0f ||
        !lidet__isfinite(cfg->rescue_gap_per_m) || cfg->rescue_gap_per_m < 0.0f ||
        cfg->rescue_rows > LIDET_MAX_ROWS || cfg->rescue_cols > RESCUE_MAX_COLS || cfg->split_people > 1u ||
        !lidet__isfinite(cfg->split_min_width_m) || !(cfg->split_min_width_m > 0.0f) ||
        !lidet__isfinite(cfg->split_cell_m) || !(cfg->split_cell_m > 0.0f) ||
        !lidet__isfinite(cfg->split_cell_per_m) || cfg->split_cell_per_m < 0.0f ||
        !lidet__isfinite(cfg->person_max_width_m) || !(cfg->person_max_width_m > 0.0f) ||
        !lidet__isfinite(cfg->person_min_height_m) || cfg->person_min_height_m < 0.0f ||
        !lidet__isfinite(cfg->person_min_aspect) || cfg->person_min_aspect < 0.0f || cfg->join_cars > 1u ||
        cfg->person_min_points < 1u || cfg->person_min_points > 1000000u ||
        !lidet__isfinite(cfg->azimuth_half_rad) || cfg->azimuth_half_rad < 0.0f ||
        cfg->azimuth_half_rad > LIDET_PI_F + 1e-6f || !(cfg->seed_half_rad >= 0.0f) ||
        !(cfg->seed_half_rad <= LIDET_PI_F + 1e-6f) || !lidet__isfinite(cfg->join_gap_m) ||
        cfg->join_gap_m < 0.0f || !lidet__isfinite(cfg->car_max_length_m) ||
        !(cfg->car_max_length_m > 0.0f) || !lidet__isfinite(cfg->car_max_width_m) ||
        !(cfg->car_max_width_m > 0.0f) || !lidet__isfinite(cfg->car_max_height_m) ||
        !(cfg->car_max_height_m > 0.0f) || !lidet__isfinite(cfg->car_min_length_m) ||
        cfg->car_min_length_m < 0.0f || !lidet__isfinite(cfg->upright_max_width_m) ||
        cfg->upright_max_width_m < 0.0f)
    {
        return LIDET_ERR_CONFIG;
    }
    c->cfg = *cfg;
    c->tan_theta = tanf(cfg->theta_rad);
    return init_done(c);
}

/* the members' sums and bounds (lidet_cluster_stats_body.h) on float values */
#define STATS_STATE_T lidet_cluster_state_t
#define STATS_V_T float
#define STATS_S_T float
#define STATS_BLOCK_SUMS 0
#define STATS_LIM_T float
#define STATS_READ(c, p, compact, x, y, z) lidet__img_xyz(&(c)->img, p, compact, x, y, z)
#define STATS_OVER(lo, hi, lim) ((hi) - (lo) > (lim))
#include "internal/lidet_cluster_stats_body.h"

/* member_stats_of with the image format a constant in each copy */
static int member_stats(const lidet_cluster_state_t *c, uint32_t start, uint32_t tail, float max_extent,
                        float sum[3], float lo[3], float hi[3])
{
    return lidet__img_compact(&c->img) ? member_stats_of(c, start, tail, max_extent, sum, lo, hi, 1)
                                       : member_stats_of(c, start, tail, max_extent, sum, lo, hi, 0);
}

/* height of `mean` above the ground plane of the sector of the seed's column (or the flat ground) */
float lidet__cluster_height(const lidet_cluster_state_t *c, uint32_t seed, const float mean[3],
                            const lidet_plane_t *planes, uint32_t n_sectors)
{
    if (planes != 0)
    {
        /* seed < rows * cols so the product fits in 64 bits */
        const uint32_t col = seed % c->img.n_cols;
        /* col < 2^16: a 32-bit product for up to 2^16 sectors (a 64-bit division costs 2-4x a 32-bit one) */
        uint32_t s = n_sectors <= 0xFFFFu ? (col * n_sectors) / c->img.n_cols
                                          : (uint32_t)(((uint64_t)col * n_sectors) / c->img.n_cols);
        const lidet_plane_t *pl;
        s = s < n_sectors ? s : n_sectors - 1;
        pl = &planes[s];
        if (c->cfg.plane_split_m > 0.0f &&
            mean[0] * mean[0] + mean[1] * mean[1] >= c->cfg.plane_split_m * c->cfg.plane_split_m)
        {
            pl = &planes[n_sectors + s]; /* its sector's far plane */
        }
        return pl->nx * mean[0] + pl->ny * mean[1] + pl->nz * mean[2] + pl->d_m;
    }
    return mean[2] + c->cfg.mount_height_m;
}

/* the azimuth window (cfg azimuth_half_rad): column c spans azimuths pi (1 - 2 (c + 1) / n) .. pi (1 - 2 c / n),
 * straight ahead at c = n / 2; the candidates of the columns outside the window (one more column on each side)
 * become non-candidates. Sets [*lo, *hi) to the window's columns (every column without one); returns how many
 * candidates it took away. */
static uint32_t window_out(const lidet_cluster_cfg_t *cfg, uint32_t rows, uint32_t cols, uint16_t *lab,
                           uint32_t *lo, uint32_t *hi)
{
    uint32_t c_lo, c_hi, r, col, out = 0;
    *lo = 0u;
    *hi = cols;
    if (!(cfg->azimuth_half_rad > 0.0f && cfg->azimuth_half_rad < LIDET_PI_F))
    {
        return 0;
    }
    lidet__azimuth_window_cols(cfg->azimuth_half_rad, cols, &c_lo, &c_hi);
    *lo = c_lo;
    *hi = c_hi;
    for (r = 0; r < rows; ++r)
    {
        /* the two runs outside [c_lo, c_hi), each a loop without branches (it vectorises) */
        uint16_t *row = lab + (size_t)r * cols;
        for (col = 0; col < c_lo; ++col)
        {
            out += (uint32_t)(row[col] == (uint16_t)LAB_FREE);
            row[col] = (uint16_t)LAB_NONCAND;
        }
        for (col = c_hi; col < cols; ++col)
        {
            out += (uint32_t)(row[col] == (uint16_t)LAB_FREE);
            row[col] = (uint16_t)LAB_NONCAND;
        }
    }
    return out;
}

/* the numeric kernels of the shared filters and records (lidet_cluster_run_body.h) */
typedef struct
{
    float sum[3], lo[3], hi[3], mean[3], h;
} summary_t;

static int summarise(const lidet_cluster_state_t *c, uint32_t start, uint32_t tail, int small, summary_t *s)
{
    return member_stats(c, start, tail, small ? 3.0e38f : c->cfg.max_extent_m, s->sum, s->lo, s->hi);
}

static int mean_height_ok(const lidet_cluster_state_t *c, uint32_t n, uint32_t seed, summary_t *s,
                          const lidet_plane_t *planes, uint32_t n_sectors)
{
    const float inv = 1.0f / (float)n;
    s->mean[0] = s->sum[0] * inv;
    s->mean[1] = s->sum[1] * inv;
    s->mean[2] = s->sum[2] * inv;
    s->h = lidet__cluster_height(c, seed, s->mean, planes, n_sectors);
    return s->h <= c->cfg.max_mean_height_m;
}

static void record_sums(lidet_cluster_state_t *c, uint32_t slot, const summary_t *s)
{
    (void)c; /* the float record keeps its mean only */
    (void)slot;
    (void)s;
}

/* mean = (mean * n_old + group sum) / n_new, in float */
static void join_mean(lidet_cluster_state_t *c, uint32_t slot, uint32_t n, const summary_t *s)
{
    lidet_cluster_rec_t *rec = &c->recs[slot];
    const float inv = 1.0f / (float)(rec->n_points + n);
    uint32_t i;
    for (i = 0; i < 3; ++i)
    {
        rec->mean_m[i] = (rec->mean_m[i] * (float)rec->n_points + s->sum[i]) * inv;
    }
}

static void reheight(lidet_cluster_state_t *c, uint32_t slot, const lidet_plane_t *planes, uint32_t n_sectors)
{
    lidet_cluster_rec_t *rec = &c->recs[slot];
    rec->height_m = lidet__cluster_height(c, rec->seed_pixel, rec->mean_m, planes, n_sectors);
}

static int rescue_on(const lidet_cluster_state_t *c)
{
    return c->cfg.rescue_gap_m > 0.0f;
}

/* a component the regrowth takes: low enough (its full bounds) */
static int regrow_fits(const lidet_cluster_state_t *c, const summary_t *s)
{
    return s->hi[2] - s->lo[2] <= c->cfg.regrow_max_height_m;
}

/* a pixel the regrowth leaves out (cfg regrow_cut_m): less than the cut above its ground plane */
static int regrow_cut(const lidet_cluster_state_t *c, uint32_t p, const lidet_plane_t *planes,
                      uint32_t n_sectors)
{
    float v[3];
    if (!(c->cfg.regrow_cut_m > 0.0f))
    {
        return 0;
    }
    lidet__img_xyz(&c->img, p, lidet__img_compact(&c->img), &v[0], &v[1], &v[2]);
    return lidet__cluster_height(c, p, v, planes, n_sectors) < c->cfg.regrow_cut_m;
}

/* the regrowth's flood fill constants (cfg regrow_gap_m > 0): the first fill's with the tighter gap bound */
static int regrow_param(const lidet_cluster_state_t *c, const lidet__grow_t *lk, lidet__grow_t *out)
{
    if (!(c->cfg.regrow_gap_m > 0.0f))
    {
        return 0;
    }
    *out = *lk;
    out->edges = 0; /* decided with the first fill's gap bound */
    out->gap = c->cfg.regrow_gap_m;
    out->gpm = c->cfg.regrow_gap_per_m;
    return 1;
}

/* the shared bookkeeping (capacity, filters, records, canonical ids, the run's driver) with the float
 * stage's types */
#define RUN_STATE_T lidet_cluster_state_t
#define RUN_REC_T lidet_cluster_rec_t
#define RUN_PARAM_T lidet__grow_t
#define RUN_PLANE_T lidet_plane_t
#define RUN_SUMMARY_T summary_t
#define RUN_MEAN(r) ((r)->mean_m)
#define RUN_MIN(r) ((r)->min_m)
#define RUN_MAX(r) ((r)->max_m)
#define RUN_HEIGHT(r) ((r)->height_m)
#define RUN_GROW lidet__cluster_grow
#define RUN_RESCUE_T lidet__rescue_t
#define RUN_RESCUE_FAR 3.0e38f
#define RUN_RESCUE_GROW lidet__cluster_rescue_grow
#define RUN_FRAGMENT_BUDGET(c) ((c)->cfg.max_fragment_pixels)
#define RUN_REFINE_SPLIT lidet__refine_split
#define RUN_REFINE_JOIN lidet__refine_join
#include "internal/lidet_cluster_run_body.h"

lidet_status_t lidet_cluster_run_buffers(lidet_cluster_state_t *c, uint16_t *labels, lidet_member_t *members,
                                         const lidet_range_image_t *img, const uint8_t *ground_mask,
                                         const lidet_plane_t *planes, uint32_t n_sectors)
{
    return lidet__cluster_run_edges(c, labels, members, 0, img, ground_mask, planes, n_sectors);
}

lidet_status_t lidet__cluster_run_edges(lidet_cluster_state_t *c, uint16_t *labels, lidet_member_t *members,
                                        uint32_t *edges, const lidet_range_image_t *img,
                                        const uint8_t *ground_mask, const lidet_plane_t *planes,
                                        uint32_t n_sectors)
{
    uint32_t rows, cols, npix, p;
    uint16_t *lab;
    lidet__grow_t lk;
    lidet_cluster_stats_t st;
    run_span_t sp;

    const lidet_status_t chk = run_check(c, labels, members, img, planes, n_sectors);
    if (chk != LIDET_OK)
    {
        return chk;
    }
    rows = img->n_rows;
    cols = img->n_cols;
    if (img->row_elev_rad == 0 || !lidet__img_complete(img))
    {
        return LIDET_ERR_ARG;
    }
    npix = rows * cols;
    sp.rows = rows;
    sp.cols = cols;
    lidet__cluster_setup_geometry(c, img);
    run_bind(c, labels, members, img, &st);
    lab = c->labels;
    LIDET__GROW_GEOMETRY(lk, rows, cols, c->cfg);
    lk.tan_theta = c->tan_theta;
    lk.gap = c->cfg.max_gap_m;
    lk.gpm = c->cfg.max_gap_per_m;
    lk.rgap = c->cfg.rescue_gap_m;
    lk.rgpm = c->cfg.rescue_gap_per_m;
    lk.bridge_max = 0xFFFFFFFFu; /* set once the candidates are counted */
    lk.bridged = &st.n_bridge_steps;
    lk.edges = 0;

    /* candidates: FREE (0) or NONCAND (0xFFFF) = cand - 1 in 16 bits; no branch, so it vectorises.
     * A pixel holds a point iff its range is > 0 (the image contract; point_idx may be absent) */
    {
        const float *prng = img->range_m;
        uint32_t n_cand = 0;
        if (lidet__img_compact(img))
        {
            /* compact image: a valid pixel has range_4mm >= 1 */
            n_cand = lidet__cluster_mark_4mm(img->range_4mm, ground_mask, npix, lab);
        }
        else if (ground_mask != 0)
        {
            for (p = 0; p < npix; ++p)
            {
                const uint32_t cand = (uint32_t)(prng[p] > 0.0f) & (uint32_t)(ground_mask[p] == 0);
                lab[p] = (uint16_t)(cand - 1u);
                n_cand += cand;
            }
        }
        else
        {
            for (p = 0; p < npix; ++p)
            {
                const uint32_t cand = (uint32_t)(prng[p] > 0.0f);
                lab[p] = (uint16_t)(cand - 1u);
                n_cand += cand;
            }
        }
        n_cand -= window_out(&c->cfg, img->n_rows, img->n_cols, lab, &sp.lo, &sp.hi);
        /* the seed columns (cfg seed_half_rad), within the window */
        lidet__azimuth_window_cols(c->cfg.seed_half_rad, cols, &sp.seed_lo, &sp.seed_hi);
        sp.seed_lo = sp.seed_lo > sp.lo ? sp.seed_lo : sp.lo;
        sp.seed_hi = sp.seed_hi < sp.hi ? sp.seed_hi : sp.hi;
        st.n_candidates = n_cand;
        if (c->cfg.max_bridge_per_pixel > 0.0f)
        {
            /* <= 64 * 2^24 * 4: fits */
            lk.bridge_max = (uint32_t)(c->cfg.max_bridge_per_pixel * (float)n_cand);
        }
    }
    if (edges != 0)
    {
        lk.edges = lidet__cluster_edges(c, &lk, edges);
    }

    run_fills(c, &lk, &sp, planes, n_sectors, &st);
    run_refine(c, &sp, planes, n_sectors, &st); /* lidet_refine.c, issue 15 */
    c->stats = st;
    return st.n_dropped_capacity > 0 ? LIDET_TRUNCATED : LIDET_OK;
}

lidet_status_t lidet_cluster_init(lidet_cluster_t *c, const lidet_cluster_cfg_t *cfg)
{
    return c == 0 ? LIDET_ERR_ARG : lidet_cluster_state_init(&c->state, cfg);
}

lidet_status_t lidet_cluster_run(lidet_cluster_t *c, const lidet_range_image_t *img,
                                 const uint8_t *ground_mask, const lidet_plane_t *planes, uint32_t n_sectors)
{
    if (c == 0)
    {
        return LIDET_ERR_ARG;
    }
    return lidet_cluster_run_buffers(&c->state, c->labels, c->members, img, ground_mask, planes, n_sectors);
}

const uint16_t *lidet_cluster_labels(const lidet_cluster_t *c)
{
    return c == 0 ? 0 : c->labels;
}

const lidet_cluster_rec_t *lidet_cluster_records(const lidet_cluster_t *c, uint32_t *n_clusters)
{
    if (c == 0)
    {
        return 0;
    }
    if (n_clusters != 0)
    {
        *n_clusters = c->state.n_recs;
    }
    return c->state.recs;
}

const lidet_member_t *lidet_cluster_members(const lidet_cluster_t *c)
{
    return c == 0 ? 0 : c->members;
}

const lidet_cluster_stats_t *lidet_cluster_stats(const lidet_cluster_t *c)
{
    return c == 0 ? 0 : &c->state.stats;
}

lidet_status_t lidet_cluster_point_labels_of(const lidet_cluster_state_t *c, const int32_t *point_pixel,
                                             uint32_t n_points, uint32_t *out)
{
    return labels_of_points(c, point_pixel, n_points, out);
}

lidet_status_t lidet_cluster_point_labels(const lidet_cluster_t *c, const int32_t *point_pixel,
                                          uint32_t n_points, uint32_t *out)
{
    return c == 0 ? LIDET_ERR_ARG : lidet_cluster_point_labels_of(&c->state, point_pixel, n_points, out);
}

uint32_t lidet_cluster_bytes(void)
{
    return (uint32_t)sizeof(lidet_cluster_t);
}

uint32_t lidet_cluster_state_bytes(void)
{
    return (uint32_t)sizeof(lidet_cluster_state_t);
}
