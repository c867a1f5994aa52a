/* SPDX-License-Identifier: MIT */
/* Clustering, the fragment rescue (see lidet_cluster.h): components below min_points joined to each
 * other and to the nearest kept cluster by the 3D distance of their returns. Mirrors
 * codegen/lidet_ref/cluster.py: cluster_ref (rescue pass). */
#include <string.h>

#include "internal/lidet_assert.h"
#include "internal/lidet_cluster_internal.h"

/* One pixel n (label l < LAB_PENDING, range dn) of the window of group pixel q (range dq): the two returns'
 * distance (from their coordinates) against gg = rgap + rgpm * (nearer range). Within it a fragment
 * pixel joins and a kept pixel is a contact (the nearest one wins, ties: the first met). */
static inline void rescue_link(lidet_cluster_state_t *c, lidet__rescue_t *rs, uint32_t n, uint32_t l,
                               float dn, uint32_t q, float dq, const lidet__grow_t *g, int compact)
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
    LIDET__RESCUE_ACCEPT(c, rs, n, l, dd);
}

/* The group pixel q whose window is looked at: its range dq and the ranges [lo, hi] whose difference
 * to dq can be within the gap. */
typedef struct
{
    uint32_t q;
    float dq, lo, hi;
} window_t;

/* group pixel q's range and the bounds: |d - dq| <= rgap + rgpm * min(d, dq)  <=>  lo <= d <= hi */
static inline void window_set(const lidet_cluster_state_t *c, window_t *w, uint32_t q, const lidet__grow_t *g,
                              int compact)
{
    const float dq = lidet__img_range_c(&c->img, q, compact);
    w->q = q;
    w->dq = dq;
    w->hi = dq * (1.0f + g->rgpm) + g->rgap;
    w->lo = (dq - g->rgap) / (1.0f + g->rgpm);
}

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

/* the window walk (lidet_cluster_rescue_body.h) with the float stage's types */
#define RESCUE_STATE_T lidet_cluster_state_t
#define RESCUE_PARAM_T lidet__grow_t
#define RESCUE_RS_T lidet__rescue_t
#define RESCUE_WIN_T window_t
#define RESCUE_WIN_SET window_set
#define RESCUE_PROBE(c, rs, lab, n, win, g, compact) rescue_probe(c, rs, lab, &(c)->img, n, win, g, compact)
#include "internal/lidet_cluster_rescue_body.h"

void lidet__cluster_rescue_grow(lidet_cluster_state_t *c, const lidet__grow_t *g, uint32_t start,
                                lidet__rescue_t *rs)
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
