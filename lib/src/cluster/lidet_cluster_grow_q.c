/* SPDX-License-Identifier: MIT */
/* Integer clustering, the growth (lidet_cluster_q.h): the angle tables of the image geometry, the integer
 * join test and the flood fill (the float stage's, lidet_cluster_grow_body.h, with integer ranges and
 * tables). Mirrors codegen/lidet_ref/cluster_q.py: tables, link. */
#include <string.h>

#include "internal/lidet_assert.h"
#include "internal/lidet_cluster_q_internal.h"
#include "internal/lidet_qmath.h"
#include "internal/lidet_qpix.h"

/* 4 sin^2(alpha / 2) in Q30 from sin(alpha / 2) in Q30, rounded, saturated at 2^32 - 1 (alpha = pi) */
static uint32_t h_of(int32_t sin_half)
{
    const int64_t v = lidet__q_rshift_round((int64_t)sin_half * sin_half, 28);
    return v > 0xFFFFFFFF ? 0xFFFFFFFFu : (uint32_t)v;
}

/* S = sin(alpha + theta) in Q16 (clamped at 0) and H = 4 sin^2(alpha / 2) in Q30 of an angle alpha in
 * [0, pi] (BAM32) */
static void tab_of(int32_t theta_bam, uint32_t alpha, uint32_t *s, uint32_t *h)
{
    const int64_t sa = lidet__q_rshift_round(lidet__q_sin(alpha + (uint32_t)theta_bam), 14);
    *s = sa > 0 ? (uint32_t)sa : 0u;
    *h = h_of(lidet__q_sin(alpha >> 1));
}

/* |a - b| of two signed BAM32 angles (beam elevations, within +-pi/2) */
static uint32_t bam_diff(int32_t a, int32_t b)
{
    const int64_t d = (int64_t)a - b;
    return (uint32_t)(d < 0 ? -d : d);
}

void lidet__cluster_q_setup_geometry(lidet_cluster_q_state_t *c, const lidet_range_image_t *img)
{
    const uint32_t rows = img->n_rows, cols = img->n_cols;
    const int32_t *e = img->row_elev_bam;
    uint32_t r, k, a1 = 0;
    if (c->geo_rows == rows && c->geo_cols == cols && memcmp(c->geo_elev_bam, e, rows * sizeof(int32_t)) == 0)
    {
        return;
    }
    for (k = 1; k <= STEPS; ++k)
    {
        /* k 2^32 / cols rounded, reduced to at most pi (the two beams' angle) */
        uint32_t a = (uint32_t)((((uint64_t)(k % cols) << 32) + cols / 2u) / cols);
        a = a > LIDET_Q_BAM_HALF ? 0u - a : a;
        a1 = k == 1u ? a : a1;
        tab_of(c->theta_bam, a, &c->col_s[k - 1], &c->col_h[k - 1]);
    }
    for (r = 0; r < rows; ++r)
    {
        c->geo_elev_bam[r] = e[r];
        for (k = 1; k <= STEPS; ++k)
        {
            tab_of(c->theta_bam, r + k < rows ? bam_diff(e[r], e[r + k]) : 0u, &c->row_s[r * STEPS + k - 1],
                   &c->row_h[r * STEPS + k - 1]);
        }
    }
    /* diagonal pairs (r, c) - (r + 1, c +- 1): 4 sin^2(alpha / 2) = 2 (1 - cos alpha)
     * = 4 sin^2((e1 - e2) / 2) + cos e1 cos e2 4 sin^2(dc / 2) (no cancellation), then alpha / 2 = atan2 of
     * sin(alpha / 2) = sqrt(H) / 2 and its cosine, for S */
    {
        const uint32_t hc = h_of(lidet__q_sin(a1 >> 1));
        for (r = 0; r + 1u < rows; ++r)
        {
            const uint32_t h1 = h_of(lidet__q_sin(bam_diff(e[r], e[r + 1u]) >> 1));
            const int64_t c12 = lidet__q_rshift_round(
                (int64_t)lidet__q_cos((uint32_t)e[r]) * lidet__q_cos((uint32_t)e[r + 1u]), 30);
            const uint64_t h = (uint64_t)h1 + (uint64_t)lidet__q_rshift_round(c12 * hc, 30);
            const uint32_t hh = h > 0xFFFFFFFFu ? 0xFFFFFFFFu : (uint32_t)h;
            uint32_t sh = (lidet__q_isqrt64((uint64_t)hh << 30) + 1u) >> 1; /* sin(alpha / 2), Q30 */
            uint32_t ch, dummy;
            sh = sh > (uint32_t)LIDET_Q_ONE_Q30 ? (uint32_t)LIDET_Q_ONE_Q30 : sh;
            ch = lidet__q_isqrt64(((uint64_t)1 << 60) - (uint64_t)sh * sh);
            tab_of(c->theta_bam, (uint32_t)lidet__q_atan2((int32_t)sh, (int32_t)ch) * 2u, &c->diag_s[r],
                   &dummy);
            c->diag_h[r] = hh;
        }
    }
    c->geo_rows = (uint16_t)rows;
    c->geo_cols = (uint16_t)cols;
    c->geo_row_m26 = lidet__q_row_m26(rows, cols);
}

/* beta > theta  <=>  d2 sin(alpha + theta) > d1 sin(theta) (d1 >= d2; uint32: d <= 65535, S <= 65536). With
 * the gap bound, (d1 - d2)^2 + d1 d2 H <= gg^2, gg = gap + gpm d2 (the distance of the two returns along
 * their beams; a range difference above gg rejects first) */
static inline int link_q(uint32_t da, uint32_t db, uint32_t s, uint32_t h, const lidet__grow_q_t *g)
{
    const uint32_t d1 = da > db ? da : db;
    const uint32_t d2 = da > db ? db : da;
    if (!(d2 * s > d1 * g->sin_t))
    {
        return 0;
    }
    if (g->gap_on != 0u)
    {
        const uint32_t gg = g->gap + ((d2 * g->gpm + 32768u) >> 16);
        const uint32_t dd = d1 - d2;
        if (dd > gg)
        {
            return 0;
        }
#if LIDET_Q_HAVE_MUL64
        /* ((x >> 29) + 1) >> 1 = (x + 2^29) >> 30, x <= (2^32 - 1)^2 (no overflow): one 64-bit shift */
        return (uint64_t)dd * dd + ((lidet__q_umul32(d1 * d2, h) + ((uint64_t)1 << 29)) >> 30) <=
               lidet__q_umul32(gg, gg);
#else
        return lidet__cluster_q_gap_ok(dd, gg, d1 * d2, h); /* the 64-bit products only near the bound */
#endif
    }
    return 1;
}

/* the flood fill (lidet_cluster_grow_body.h) on the integer stage's types */
#define GROW_D_T uint32_t
#define GROW_TAB_T uint32_t
#define GROW_TA(c, t) ((c)->t##_s)
#define GROW_TB(c, t) ((c)->t##_h)
#define GROW_LINK link_q
#define GROW_STATE_T lidet_cluster_q_state_t
#define GROW_PARAM_T lidet__grow_q_t
#define GROW_RNG_T uint16_t
#define GROW_RANGES(img) ((img)->range_4mm)
#define GROW_FN(name) name##_q
/* one test per candidate where it was measured faster (x86-64: the real KITTI scans' clustering); on the Arm
 * and RISC-V images the HDL-64 scan's clustering took 7.2 M (Cortex-M7) and 5.0 M (RV32IMAFC) instructions more */
#if defined(__x86_64__) || defined(__i386__)
#define GROW_TEST_EVERY 1
#else
#define GROW_TEST_EVERY 0
#endif
#include "internal/lidet_cluster_grow_body.h"

/* the fill, a function per occluder rule (the rule a constant in each: on the Cortex-M4 image 4 % fewer
 * instructions in the flood fill than one function taking the rule as an argument, lidet_cluster_grow.c's form) */
#if defined(__GNUC__)
__attribute__((noinline))
#endif
static uint32_t
fill_q(lidet_cluster_q_state_t *c, const lidet__grow_q_t *g, uint32_t start, uint32_t tail)
{
    return grow_q(c, g, start, tail, 0);
}

#if defined(__GNUC__)
__attribute__((noinline))
#endif
static uint32_t
fill_occl_q(lidet_cluster_q_state_t *c, const lidet__grow_q_t *g, uint32_t start, uint32_t tail)
{
    return grow_q(c, g, start, tail, 1);
}

uint32_t lidet__cluster_q_grow(lidet_cluster_q_state_t *c, const lidet__grow_q_t *g, uint32_t start,
                               uint32_t tail)
{
    return c->cfg.bridge_occluders != 0 ? fill_occl_q(c, g, start, tail) : fill_q(c, g, start, tail);
}
