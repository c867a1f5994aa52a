/* SPDX-License-Identifier: MIT */
/* Integer clustering, the proposal refinement (lidet_cluster_q.h): lidet_refine.c's cuts of person-sized parts
 * and joins of car fragments with the control flow of internal/lidet_refine_body.h and integer kernels. Pixels
 * and records are in 4 mm steps, the thresholds in mm (a span s in steps is compared as 4 s); the cell size in
 * mm, cell_mm + round(cell_per_m_q16 r_mm / 2^16) with r_mm = max(|cx|, |cy|) + min(|cx|, |cy|) / 2 of the box
 * centre (floored, in 2 mm steps, then doubled); a member's cell floor(4 (x - lo) / cs) by one product with
 * ceil(2^40 / cs) and a shift (exact: 4 (x - lo) < 2^18, cs < 2^22); the aspect test wz 2^16 >= aspect_q16
 * max(wx, wy) and the joins' gap test (4 gx)^2 + (4 gy)^2 > gap_mm^2 in uint64 (no square root, no division
 * per point). Records: int64 member sums, the mean rounded (lidet__q_div_round), the height of lidet_cluster_q.c.
 * Integer only. Mirrored bit for bit by refine_q in codegen/lidet_ref/cluster_q.py. */
#include <string.h>

#include "internal/lidet_cluster_q_internal.h"
#include "internal/lidet_qmath.h"
#include "internal/lidet_qpix.h"

/* one examined cluster's grid: its box corner (4 mm steps), the cell (mm) and ceil(2^40 / cell) */
typedef struct
{
    int32_t lo[2];
    uint32_t cs;
    uint64_t inv;
} geom_q_t;

static uint32_t span_mm(int32_t lo, int32_t hi)
{
    return (uint32_t)(hi - lo) * 4u; /* int16 coordinates: <= 262140 */
}

static int refine_examined(const lidet_cluster_q_cfg_t *cfg, const lidet_cluster_q_rec_t *rec)
{
    return (span_mm(rec->min_4mm[0], rec->max_4mm[0]) > cfg->split_min_width_mm ||
            span_mm(rec->min_4mm[1], rec->max_4mm[1]) > cfg->split_min_width_mm) &&
           span_mm(rec->min_4mm[2], rec->max_4mm[2]) >= cfg->person_min_height_mm;
}

static int refine_grid(const lidet_cluster_q_cfg_t *cfg, const lidet_cluster_q_rec_t *rec, geom_q_t *g,
                       uint32_t *nx, uint32_t *ny)
{
    const int32_t sx = rec->min_4mm[0] + rec->max_4mm[0],
                  sy = rec->min_4mm[1] + rec->max_4mm[1]; /* 2 mm steps */
    const uint32_t ax = (uint32_t)(sx < 0 ? -sx : sx), ay = (uint32_t)(sy < 0 ? -sy : sy);
    const uint32_t r_mm = 2u * (ax > ay ? ax + (ay >> 1) : ay + (ax >> 1)); /* < 2^19 */
    g->cs = cfg->split_cell_mm + (uint32_t)(((uint64_t)cfg->split_cell_per_m_q16 * r_mm + 32768u) >> 16);
    g->inv = (((uint64_t)1 << 40) + g->cs - 1u) / g->cs;
    g->lo[0] = rec->min_4mm[0];
    g->lo[1] = rec->min_4mm[1];
    *nx = span_mm(rec->min_4mm[0], rec->max_4mm[0]) / g->cs + 1u;
    *ny = span_mm(rec->min_4mm[1], rec->max_4mm[1]) / g->cs + 1u;
    return 1;
}

static uint32_t refine_cell(const lidet_cluster_q_state_t *c, uint32_t p, const geom_q_t *g, uint32_t nx,
                            uint32_t ny)
{
    int32_t v[3];
    uint32_t ix, iy;
    lidet__qpix_xyz_m(&c->img, p, c->geo_row_m26, v); /* stored or decoded (lidet_qpix.h) */
    ix = (uint32_t)(((uint64_t)span_mm(g->lo[0], v[0]) * g->inv) >> 40);
    iy = (uint32_t)(((uint64_t)span_mm(g->lo[1], v[1]) * g->inv) >> 40);
    ix = ix < nx ? ix : nx - 1u;
    iy = iy < ny ? iy : ny - 1u;
    return iy * nx + ix;
}

static int32_t refine_z(const lidet_cluster_q_state_t *c, uint32_t p)
{
    int32_t v[3];
    lidet__qpix_xyz_m(&c->img, p, c->geo_row_m26, v);
    return v[2];
}

static int refine_person(const lidet_cluster_q_cfg_t *cfg, const geom_q_t *g, uint32_t n, uint32_t sx,
                         uint32_t sy, int32_t zlo, int32_t zhi, uint32_t ncols)
{
    const uint64_t wx = (uint64_t)sx * g->cs, wy = (uint64_t)sy * g->cs, wz = span_mm(zlo, zhi);
    (void)n;
    return wx <= cfg->person_max_width_mm && wy <= cfg->person_max_width_mm &&
           wz >= cfg->person_min_height_mm &&
           (wz << 16) >= (uint64_t)cfg->person_min_aspect_q16 * (wx > wy ? wx : wy) &&
           ncols >= cfg->person_min_cols;
}

/* the rounded mean of the member sums (the sums kept beside it) */
static void refine_mean(lidet_cluster_q_state_t *c, uint32_t slot, const int64_t sum[3])
{
    lidet_cluster_q_rec_t *r = &c->recs[slot];
    uint32_t i;
    for (i = 0; i < 3u; ++i)
    {
        c->sums[slot][i] = sum[i];
        r->mean_4mm[i] = (int32_t)lidet__q_div_round(sum[i], (int64_t)r->n_points);
    }
}

static int refine_car_piece(const lidet_cluster_q_cfg_t *cfg, const lidet_cluster_q_rec_t *r)
{
    const uint32_t wx = span_mm(r->min_4mm[0], r->max_4mm[0]), wy = span_mm(r->min_4mm[1], r->max_4mm[1]);
    const uint32_t wz = span_mm(r->min_4mm[2], r->max_4mm[2]);
    const int upright =
        wx <= cfg->upright_max_width_mm && wy <= cfg->upright_max_width_mm && wz >= cfg->person_min_height_mm;
    return !upright && wz <= cfg->car_max_height_mm && (wx > wy ? wx : wy) <= cfg->car_max_length_mm &&
           (wx > wy ? wy : wx) <= cfg->car_max_width_mm;
}

static int refine_joinable(const lidet_cluster_q_cfg_t *cfg, const lidet_cluster_q_rec_t *a,
                           const lidet_cluster_q_rec_t *b)
{
    int32_t gx = b->min_4mm[0] - a->max_4mm[0], gy = b->min_4mm[1] - a->max_4mm[1];
    uint32_t ux, uy, uz;
    gx = a->min_4mm[0] - b->max_4mm[0] > gx ? a->min_4mm[0] - b->max_4mm[0] : gx;
    gy = a->min_4mm[1] - b->max_4mm[1] > gy ? a->min_4mm[1] - b->max_4mm[1] : gy;
    gx = gx > 0 ? 4 * gx : 0;
    gy = gy > 0 ? 4 * gy : 0;
    if ((uint64_t)((int64_t)gx * gx + (int64_t)gy * gy) > (uint64_t)cfg->join_gap_mm * cfg->join_gap_mm)
    {
        return 0;
    }
    ux = span_mm(a->min_4mm[0] < b->min_4mm[0] ? a->min_4mm[0] : b->min_4mm[0],
                 a->max_4mm[0] > b->max_4mm[0] ? a->max_4mm[0] : b->max_4mm[0]);
    uy = span_mm(a->min_4mm[1] < b->min_4mm[1] ? a->min_4mm[1] : b->min_4mm[1],
                 a->max_4mm[1] > b->max_4mm[1] ? a->max_4mm[1] : b->max_4mm[1]);
    uz = span_mm(a->min_4mm[2] < b->min_4mm[2] ? a->min_4mm[2] : b->min_4mm[2],
                 a->max_4mm[2] > b->max_4mm[2] ? a->max_4mm[2] : b->max_4mm[2]);
    return uz <= cfg->car_max_height_mm && (ux > uy ? ux : uy) <= cfg->car_max_length_mm &&
           (ux > uy ? ux : uy) >= cfg->car_min_length_mm && (ux > uy ? uy : ux) <= cfg->car_max_width_mm;
}

/* the member sums of a record whose members are its canonical range */
static void sums_of(const lidet_cluster_q_state_t *c, const lidet_cluster_q_rec_t *r, int64_t s[3])
{
    uint32_t m;
    s[0] = 0;
    s[1] = 0;
    s[2] = 0;
    for (m = r->first_member; m < r->first_member + r->n_points; ++m)
    {
        int32_t v[3];
        lidet__qpix_xyz_m(&c->img, (uint32_t)c->members[m], c->geo_row_m26, v);
        s[0] += v[0];
        s[1] += v[1];
        s[2] += v[2];
    }
}

/* b's sums into a's (a's from its members at its first join: the run's sums are by slot, the canonical pass
 * reordered the records): the mean is the rounded mean of all members, exactly */
static void refine_join_mean(lidet_cluster_q_state_t *c, uint32_t i, uint32_t j, int first)
{
    lidet_cluster_q_rec_t *a = &c->recs[i];
    const lidet_cluster_q_rec_t *b = &c->recs[j];
    int64_t sb[3];
    uint32_t d;
    if (first)
    {
        sums_of(c, a, c->sums[i]);
    }
    sums_of(c, b, sb);
    for (d = 0; d < 3u; ++d)
    {
        c->sums[i][d] += sb[d];
        a->mean_4mm[d] = (int32_t)lidet__q_div_round(c->sums[i][d], (int64_t)(a->n_points + b->n_points));
    }
}

/* the control flow (lidet_refine_body.h) on the integer stage's types */
#define REFINE_STATE_T lidet_cluster_q_state_t
#define REFINE_REC_T lidet_cluster_q_rec_t
#define REFINE_CFG_T lidet_cluster_q_cfg_t
#define REFINE_PLANE_T lidet_plane_q_t
#define REFINE_GEOM_T geom_q_t
#define REFINE_Z_T int32_t
#define REFINE_Z_FAR 0x7FFFFFFF
#define REFINE_V_T int32_t
#define REFINE_S_T int64_t
#define REFINE_READ(c, p, v) lidet__qpix_xyz_m(&(c)->img, p, (c)->geo_row_m26, v)
#define REFINE_MIN(r) ((r)->min_4mm)
#define REFINE_MAX(r) ((r)->max_4mm)
#define REFINE_MEAN(r) ((r)->mean_4mm)
#define REFINE_H(r) ((r)->height_4mm)
#define REFINE_HEIGHT lidet__cluster_q_height
#define REFINE_SPLIT_FN lidet__refine_q_split
#define REFINE_JOIN_FN lidet__refine_q_join
#include "internal/lidet_refine_body.h"
