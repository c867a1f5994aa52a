/* SPDX-License-Identifier: MIT */
/* Proposal refinement after the clustering (issue 15; the rule is written in lidet_cluster.h, cfg
 * split_people): people standing 0.2-1 m apart, or beside a car, a pole or a wall, come out of the depth
 * clustering as one cluster. A cluster wider than one person is drawn on a finer bird's-eye-view grid
 * and its person-sized connected parts are cut off into clusters of their own.
 *
 * Runs on the canonical output of the clustering (each cluster's members contiguous, in raster order)
 * and leaves labels and records for one more canonical pass (lidet_cluster.c). Bounded: per examined
 * cluster O(members + cells) with cells <= LIDET_REFINE_MAX_CELLS and parts <= LIDET_REFINE_MAX_PARTS
 * (a cluster needing more is left whole and counted); all scratch is in the state. Deterministic: parts
 * are numbered in the order of the cluster's members, cells filled breadth-first. Decisions use
 * subtractions, one product by the inverse cell size, truncation to a cell index and compares: the
 * integer stage does the same in 4 mm steps (lidet_refine_q.c). The control flow is shared with it
 * (internal/lidet_refine_body.h); this file holds the float kernels. The numpy reference is refine_ref in
 * codegen/lidet_ref/cluster.py. */
#include <string.h>

#include "internal/lidet_cluster_internal.h"

/* one examined cluster's grid: its box corner in x, y, the cell size and its inverse */
typedef struct
{
    float lo[2], cs, inv;
} geom_t;

/* examined: wider than split_min_width_m in x or y, at least person_min_height_m in z */
static int refine_examined(const lidet_cluster_cfg_t *cfg, const lidet_cluster_rec_t *rec)
{
    const float ex = rec->max_m[0] - rec->min_m[0], ey = rec->max_m[1] - rec->min_m[1];
    return (ex > cfg->split_min_width_m || ey > cfg->split_min_width_m) &&
           rec->max_m[2] - rec->min_m[2] >= cfg->person_min_height_m;
}

/* the cell grows with the range of the box centre, max(|x|, |y|) + min(|x|, |y|) / 2 (no sqrt) */
static int refine_grid(const lidet_cluster_cfg_t *cfg, const lidet_cluster_rec_t *rec, geom_t *g,
                       uint32_t *nx, uint32_t *ny)
{
    const float ex = rec->max_m[0] - rec->min_m[0], ey = rec->max_m[1] - rec->min_m[1];
    float ax = 0.5f * (rec->min_m[0] + rec->max_m[0]), ay = 0.5f * (rec->min_m[1] + rec->max_m[1]), r;
    ax = ax < 0.0f ? -ax : ax;
    ay = ay < 0.0f ? -ay : ay;
    r = ax > ay ? ax + 0.5f * ay : ay + 0.5f * ax;
    g->cs = cfg->split_cell_m + cfg->split_cell_per_m * r;
    g->inv = 1.0f / g->cs;
    g->lo[0] = rec->min_m[0];
    g->lo[1] = rec->min_m[1];
    /* a grid of LIDET_REFINE_MAX_CELLS cells or more along a side is refused before the conversion (a tiny
     * configured cell would otherwise convert an out-of-range float to an integer: undefined; found by
     * fuzz_proposal). The same decision as the caller's cap on nx, ny */
    if (!(ex * g->inv < (float)LIDET_REFINE_MAX_CELLS) || !(ey * g->inv < (float)LIDET_REFINE_MAX_CELLS))
    {
        return 0;
    }
    *nx = (uint32_t)(ex * g->inv) + 1u;
    *ny = (uint32_t)(ey * g->inv) + 1u;
    return 1;
}

/* cell of member pixel p: its x, y relative to the box corner, times the inverse cell, truncated and
 * clamped to the grid */
static uint32_t refine_cell(const lidet_cluster_state_t *c, uint32_t p, const geom_t *g, uint32_t nx,
                            uint32_t ny)
{
    float x, y, z;
    uint32_t ix, iy;
    lidet__img_xyz(&c->img, p, lidet__img_compact(&c->img), &x, &y, &z);
    ix = (uint32_t)((x - g->lo[0]) * g->inv);
    iy = (uint32_t)((y - g->lo[1]) * g->inv);
    ix = ix < nx ? ix : nx - 1u;
    iy = iy < ny ? iy : ny - 1u;
    return iy * nx + ix;
}

static float refine_z(const lidet_cluster_state_t *c, uint32_t p)
{
    return lidet__img_z(&c->img, p);
}

static int refine_person(const lidet_cluster_cfg_t *cfg, const geom_t *g, uint32_t n, uint32_t sx,
                         uint32_t sy, float zlo, float zhi, uint32_t ncols)
{
    const float wx = (float)sx * g->cs, wy = (float)sy * g->cs, wz = zhi - zlo;
    (void)n;
    return wx <= cfg->person_max_width_m && wy <= cfg->person_max_width_m && wz >= cfg->person_min_height_m &&
           wz >= cfg->person_min_aspect * (wx > wy ? wx : wy) && ncols >= cfg->person_min_cols;
}

/* the mean of the member sums (float) */
static void refine_mean(lidet_cluster_state_t *c, uint32_t slot, const float sum[3])
{
    lidet_cluster_rec_t *r = &c->recs[slot];
    uint32_t i;
    for (i = 0; i < 3u; ++i)
    {
        r->mean_m[i] = sum[i] / (float)r->n_points;
    }
}

/* a join candidate by its own box: not upright (a person, a cyclist, a pole: narrow in x and y, tall),
 * and it fits a car */
static int refine_car_piece(const lidet_cluster_cfg_t *cfg, const lidet_cluster_rec_t *r)
{
    const float wx = r->max_m[0] - r->min_m[0], wy = r->max_m[1] - r->min_m[1],
                wz = r->max_m[2] - r->min_m[2];
    const int upright =
        wx <= cfg->upright_max_width_m && wy <= cfg->upright_max_width_m && wz >= cfg->person_min_height_m;
    return !upright && wz <= cfg->car_max_height_m && (wx > wy ? wx : wy) <= cfg->car_max_length_m &&
           (wx > wy ? wy : wx) <= cfg->car_max_width_m;
}

/* can cluster b join a (boxes): near enough, and the union fits a car */
static int refine_joinable(const lidet_cluster_cfg_t *cfg, const lidet_cluster_rec_t *a,
                           const lidet_cluster_rec_t *b)
{
    float gx = b->min_m[0] - a->max_m[0], gy = b->min_m[1] - a->max_m[1], ux, uy, uz, lo, hi;
    const float g2 = cfg->join_gap_m * cfg->join_gap_m;
    gx = a->min_m[0] - b->max_m[0] > gx ? a->min_m[0] - b->max_m[0] : gx;
    gy = a->min_m[1] - b->max_m[1] > gy ? a->min_m[1] - b->max_m[1] : gy;
    gx = gx > 0.0f ? gx : 0.0f;
    gy = gy > 0.0f ? gy : 0.0f;
    if (gx * gx + gy * gy > g2)
    {
        return 0;
    }
    lo = a->min_m[0] < b->min_m[0] ? a->min_m[0] : b->min_m[0];
    hi = a->max_m[0] > b->max_m[0] ? a->max_m[0] : b->max_m[0];
    ux = hi - lo;
    lo = a->min_m[1] < b->min_m[1] ? a->min_m[1] : b->min_m[1];
    hi = a->max_m[1] > b->max_m[1] ? a->max_m[1] : b->max_m[1];
    uy = hi - lo;
    lo = a->min_m[2] < b->min_m[2] ? a->min_m[2] : b->min_m[2];
    hi = a->max_m[2] > b->max_m[2] ? a->max_m[2] : b->max_m[2];
    uz = hi - lo;
    return uz <= cfg->car_max_height_m && (ux > uy ? ux : uy) <= cfg->car_max_length_m &&
           (ux > uy ? ux : uy) >= cfg->car_min_length_m && (ux > uy ? uy : ux) <= cfg->car_max_width_m;
}

/* b's mean into a's (float, weighted by the counts) */
static void refine_join_mean(lidet_cluster_state_t *c, uint32_t i, uint32_t j, int first)
{
    lidet_cluster_rec_t *a = &c->recs[i];
    const lidet_cluster_rec_t *b = &c->recs[j];
    const float inv = 1.0f / (float)(a->n_points + b->n_points);
    uint32_t d;
    (void)first;
    for (d = 0; d < 3u; ++d)
    {
        a->mean_m[d] = (a->mean_m[d] * (float)a->n_points + b->mean_m[d] * (float)b->n_points) * inv;
    }
}

/* the control flow (lidet_refine_body.h) on the float stage's types */
#define REFINE_STATE_T lidet_cluster_state_t
#define REFINE_REC_T lidet_cluster_rec_t
#define REFINE_CFG_T lidet_cluster_cfg_t
#define REFINE_PLANE_T lidet_plane_t
#define REFINE_GEOM_T geom_t
#define REFINE_Z_T float
#define REFINE_Z_FAR 3.0e38f
#define REFINE_V_T float
#define REFINE_S_T float
#define REFINE_READ(c, p, v)                                                                                 \
    lidet__img_xyz(&(c)->img, p, lidet__img_compact(&(c)->img), &(v)[0], &(v)[1], &(v)[2])
#define REFINE_MIN(r) ((r)->min_m)
#define REFINE_MAX(r) ((r)->max_m)
#define REFINE_MEAN(r) ((r)->mean_m)
#define REFINE_H(r) ((r)->height_m)
#define REFINE_HEIGHT lidet__cluster_height
#define REFINE_SPLIT_FN lidet__refine_split
#define REFINE_JOIN_FN lidet__refine_join
#include "internal/lidet_refine_body.h"
