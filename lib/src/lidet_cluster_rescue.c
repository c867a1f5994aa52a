/* SPDX-License-Identifier: MIT */
/* Clustering, the fragment rescue (see lidet_cluster.h): components below min_points joined to each
 * other and to the nearest kept cluster by the 3D distance of their returns. Mirrors
 * codegen/lidet_codegen/ref/cluster.py: cluster_ref (rescue pass). */
#include <string.h>

#include "internal/lidet_assert.h"
#include "internal/lidet_cluster_internal.h"

/* One pixel n (label l < LAB_PENDING, range dn) of the window of group pixel q (range dq): the two returns'
 * distance (from their coordinates) against gg = rgap + rgpm * (nearer range). Within it a fragment
 * pixel joins and a kept pixel is a contact (the nearest one wins, ties: the first met). */
static inline void rescue_link(lidet_cluster_state_t *c, lidet__rescue_t *rs, uint32_t n, uint32_t l, float dn, uint32_t q,
                               float dq, const lidet__grow_t *g, int compact)
{
    const lidet_range_image_t *img = &c->img;
    const float gg = g->rgap + g->rgpm * (dq < dn ? dq : dn);
    float xn, yn, zn, xq, yq, zq, dx, dy, dz;
    lidet__img_xyz(img, n, compact, &xn, &yn, &zn);
    lidet__img_xyz(img, q, compact, &xq, &yq, &zq);
    dx = xn - xq;
    dy = yn - yq;
    dz = zn - zq;
    const float dd = dx * dx + dy * dy + dz * dz;
    if (!(dd <= gg * gg))
    {
        return;
    }
    if (l == LAB_SMALL)
    {
        c->labels[n] = (uint16_t)LAB_PENDING;
        c->members[rs->tail++] = (int32_t)n;
    }
    else if (dd < rs->best_d2)
    {
        rs->best_d2 = dd;
        rs->best = l;
    }
}

/* The group pixel q whose window is looked at: its range dq and the ranges [lo, hi] whose difference
 * to dq can be within the gap. */
typedef struct
{
    uint32_t q;
    float dq, lo, hi;
} window_t;

/* Pixel n of q's window: looked at when it is a fragment or kept pixel (labels below LAB_PENDING;
 * visited, dropped and empty pixels are looked past) and its range lies in [lo, hi] (a bound of the
 * distance from below: most pixels stop here, before their coordinates are read) */
static inline void rescue_probe(lidet_cluster_state_t *c, lidet__rescue_t *rs, const uint16_t *lab,
                                const lidet_range_image_t *rng, uint32_t n, const window_t *w,
                                const lidet__grow_t *g, int compact)
{
    const uint32_t l = lab[n];
    const float dn = lidet__img_range_c(rng, n, compact);
    if (l < LAB_PENDING && dn >= w->lo && dn <= w->hi && n != w->q)
    {
        rescue_link(c, rs, n, l, dn, w->q, w->dq, g, compact);
    }
}

/* Breadth-first fill of the rescue group seeded at members[start]. Around each member q it looks at
 * every pixel of the window rescue_rows rows up and down and rescue_cols columns left and right
 * (wrapping), row by row from the top left, q itself excepted. Four labels at a time (a 64-bit
 * word) are skipped when all are LAB_PENDING or LAB_NONCAND (0xFFFE, 0xFFFF: the only labels with
 * every bit but the lowest set). Fragments are few (hundreds of pixels per scan), windows small. */
static inline void rescue_grow(lidet_cluster_state_t *c, const lidet__grow_t *g, uint32_t start, lidet__rescue_t *rs,
                               int compact)
{
    const int32_t *mem = c->members;
    const uint16_t *lab = c->labels;
    const lidet_range_image_t *rng = &c->img; /* ranges read through lidet__img_range_c */
    const uint32_t rows = g->rows, cols = g->cols, wr = g->rrows, wc = g->rcols;
    uint32_t head = start;
    while (head < rs->tail)
    {
        const uint32_t q = (uint32_t)mem[head++];
        const uint32_t r = q / cols, col = q - r * cols;
        const uint32_t r0 = r >= wr ? r - wr : 0u, r1 = r + wr < rows ? r + wr : rows - 1u;
        const uint32_t c0 = col >= wc ? col - wc : col + cols - wc; /* 2 wc < cols: none repeats */
        const float dq = lidet__img_range_c(rng, q, compact);
        /* |d - dq| <= rgap + rgpm * min(d, dq)  <=>  lo <= d <= hi */
        const float hi = dq * (1.0f + g->rgpm) + g->rgap, lo = (dq - g->rgap) / (1.0f + g->rgpm);
        window_t win;
        uint32_t rr, k;
        win.q = q;
        win.dq = dq;
        win.lo = lo;
        win.hi = hi;
        LIDET_ASSERT(rs->tail <= rows * cols);
        for (rr = r0; rr <= r1; ++rr)
        {
            const uint32_t base = rr * cols;
            if (c0 + 2u * wc < cols)
            {
                const uint32_t end = base + c0 + 2u * wc + 1u;
                uint32_t n = base + c0;
                for (; n + 4u <= end; n += 4u)
                {
                    uint64_t w4;
                    memcpy(&w4, &lab[n], sizeof w4);
                    if ((w4 | 0x0001000100010001u) != 0xFFFFFFFFFFFFFFFFu)
                    {
                        rescue_probe(c, rs, lab, rng, n, &win, g, compact);
                        rescue_probe(c, rs, lab, rng, n + 1u, &win, g, compact);
                        rescue_probe(c, rs, lab, rng, n + 2u, &win, g, compact);
                        rescue_probe(c, rs, lab, rng, n + 3u, &win, g, compact);
                    }
                }
                for (; n < end; ++n)
                {
                    rescue_probe(c, rs, lab, rng, n, &win, g, compact);
                }
            }
            else
            {
                uint32_t cc = c0;
                for (k = 0; k <= 2u * wc; ++k)
                {
                    rescue_probe(c, rs, lab, rng, base + cc, &win, g, compact);
                    cc = cc + 1u < cols ? cc + 1u : 0u;
                }
            }
        }
    }
}

void lidet__cluster_rescue_grow(lidet_cluster_state_t *c, const lidet__grow_t *g, uint32_t start, lidet__rescue_t *rs)
{
    /* two copies, with the image format a constant in each */
    if (lidet__img_compact(&c->img))
    {
        rescue_grow(c, g, start, rs, 1);
    }
    else
    {
        rescue_grow(c, g, start, rs, 0);
    }
}
