/* SPDX-License-Identifier: MIT */
/* Clustering, the growth (see lidet_cluster.h): the join test of two neighbouring returns, the
 * directional searches with hole and occluder bridging, and the breadth-first flood fill. The hot
 * loop of the stage and the unit a port overrides. Mirrors codegen/lidet_ref/cluster.py:
 * cluster_ref (link, search, grow). */
#include <math.h>
#include <string.h>

#include "internal/lidet_assert.h"
#include "internal/lidet_cluster_internal.h"
#include "internal/lidet_math.h"

void lidet__cluster_setup_geometry(lidet_cluster_state_t *c, const lidet_range_image_t *img)
{
    const uint32_t rows = img->n_rows, cols = img->n_cols;
    uint32_t r, k;
    if (c->geo_rows == rows && c->geo_cols == cols &&
        memcmp(c->geo_elev, img->row_elev_rad, rows * sizeof(float)) == 0)
    {
        return;
    }
    for (k = 1; k <= STEPS; ++k)
    {
        /* k * 2pi / cols, reduced to at most pi (the two beams' angle) */
        const float a = LIDET_PI_F * 2.0f * (float)(k % cols) / (float)cols;
        const float a2 = a > LIDET_PI_F ? 2.0f * LIDET_PI_F - a : a;
        c->col_sin[k - 1] = sinf(a2);
        c->col_cos[k - 1] = cosf(a2);
    }
    for (r = 0; r < rows; ++r)
    {
        c->geo_elev[r] = img->row_elev_rad[r];
        for (k = 1; k <= STEPS; ++k)
        {
            float a = r + k < rows ? img->row_elev_rad[r] - img->row_elev_rad[r + k] : 0.0f;
            a = a < 0.0f ? -a : a;
            c->row_sin[r * STEPS + k - 1] = sinf(a);
            c->row_cos[r * STEPS + k - 1] = cosf(a);
        }
    }
    /* diagonal pairs (r, c) - (r + 1, c +- 1): cos of the angle between the two beam directions */
    {
        const float cd = cosf(2.0f * LIDET_PI_F / (float)cols);
        for (r = 0; r + 1 < rows; ++r)
        {
            const float e1 = img->row_elev_rad[r], e2 = img->row_elev_rad[r + 1];
            float cs = sinf(e1) * sinf(e2) + cosf(e1) * cosf(e2) * cd;
            cs = cs > 1.0f ? 1.0f : (cs < -1.0f ? -1.0f : cs);
            c->diag_cos[r] = cs;
            c->diag_sin[r] = sqrtf(1.0f - cs * cs);
        }
    }
    c->geo_rows = (uint16_t)rows;
    c->geo_cols = (uint16_t)cols;
}

/* beta > theta  <=>  d2 sin(a) > tan(theta) (d1 - d2 cos(a)), d1 >= d2 (true when the bracket <= 0), for the
 * two ranges ordered (d1 the larger).
 * With gap > 0 the two returns must also lie within gap + gap_per_m * d2 of each other; their
 * distance along the two beams is sqrt((d1 - d2 cos a)^2 + (d2 sin a)^2), from the same two terms
 * (no point coordinates are read) */
static inline int link_ordered(float d1, float d2, float sn, float cs, const lidet__grow_t *g)
{
    const float u = d1 - d2 * cs, v = d2 * sn;
    if (!(v > g->tan_theta * u))
    {
        return 0;
    }
    if (g->gap > 0.0f)
    {
        const float gg = g->gap + g->gpm * d2;
        return u * u + v * v <= gg * gg;
    }
    return 1;
}

static inline int link(float da, float db, float sn, float cs, const lidet__grow_t *g)
{
    return link_ordered(da > db ? da : db, da > db ? db : da, sn, cs, g);
}

/* the float stage's parameters of the flood fill template (lidet_cluster_grow_body.h) */
#define GROW_D_T float
#define GROW_TAB_T float
#define GROW_TA(c, t) ((c)->t##_sin)
#define GROW_TB(c, t) ((c)->t##_cos)
#define GROW_LINK link
#define GROW_STATE_T lidet_cluster_state_t
#define GROW_PARAM_T lidet__grow_t

/* the flood fill on a float image (ranges in metres) */
#define GROW_RNG_T float
#define GROW_RANGES(img) ((img)->range_m)
#define GROW_FN(name) name##_m
#include "internal/lidet_cluster_grow_body.h"
#undef GROW_RNG_T
#undef GROW_RANGES
#undef GROW_FN

/* the flood fill on a compact image (ranges in 4 mm steps): the ranges are read as integers, ordered as integers
 * (a select, where the float order compiled to a branch that mispredicts) and converted exactly (< 2^16) for the
 * same float tests: the same results as reading them as floats */
static inline int link_4mm(uint32_t da, uint32_t db, float sn, float cs, const lidet__grow_t *g)
{
    const uint32_t d1 = da > db ? da : db;
    const uint32_t d2 = da > db ? db : da;
    return link_ordered((float)d1, (float)d2, sn, cs, g);
}
#undef GROW_D_T
#undef GROW_LINK
#define GROW_D_T uint32_t
#define GROW_LINK link_4mm
#define GROW_RNG_T uint16_t
#define GROW_RANGES(img) ((img)->range_4mm)
#define GROW_FN(name) name##_4mm
#include "internal/lidet_cluster_grow_body.h"
#undef GROW_RNG_T
#undef GROW_RANGES
#undef GROW_FN

/* each image format's fill, a function of its own with the occluder rule an argument (each holds the expansion
 * with and without the rule: grow in lidet_cluster_grow_body.h). On an x86-64 host a function per rule, the
 * integer stage's form (lidet_cluster_grow_q.c), ran the HDL-64 fill of real KITTI scans 1.5 % slower */
#if defined(__GNUC__)
__attribute__((noinline))
#endif
static uint32_t
fill_m(lidet_cluster_state_t *c, const lidet__grow_t *g, uint32_t start, uint32_t tail, int occl)
{
    return grow_m(c, g, start, tail, occl);
}

#if defined(__GNUC__)
__attribute__((noinline))
#endif
static uint32_t
fill_4mm(lidet_cluster_state_t *c, const lidet__grow_t *g, uint32_t start, uint32_t tail, int occl)
{
    return grow_4mm(c, g, start, tail, occl);
}

uint32_t lidet__cluster_grow(lidet_cluster_state_t *c, const lidet__grow_t *g, uint32_t start, uint32_t tail)
{
    lidet__grow_t gs;
    if (!lidet__img_compact(&c->img))
    {
        return fill_m(c, g, start, tail, c->cfg.bridge_occluders != 0);
    }
    /* ranges in 4 mm steps: the angle test is homogeneous in them; the gap bound in steps (gap_per_m is
     * a ratio) */
    gs = *g;
    gs.gap = g->gap * LIDET_PIXEL_PER_M;
    return fill_4mm(c, &gs, start, tail, c->cfg.bridge_occluders != 0);
}
