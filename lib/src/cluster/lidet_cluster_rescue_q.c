/* SPDX-License-Identifier: MIT */
/* Integer clustering, the fragment rescue (lidet_cluster_q.h): the float stage's window walk
 * (lidet_cluster_rescue_body.h) with the integer distance test. Mirrors
 * codegen/lidet_ref/cluster_q.py (rescue pass). */
#include <string.h>

#include "internal/lidet_assert.h"
#include "internal/lidet_cluster_q_internal.h"
#include "internal/lidet_qpix.h"

/* group pixel q whose window is looked at, and its range */
typedef struct
{
    uint32_t q, dq;
    int32_t v[3]; /* q's x, y, z (stored or decoded) */
} window_q_t;

static inline void window_set_q(const lidet_cluster_q_state_t *c, window_q_t *w, uint32_t q,
                                const lidet__grow_q_t *g, int compact)
{
    (void)g;
    (void)compact;
    w->q = q;
    w->dq = c->img.range_4mm[q];
    lidet__qpix_xyz_m(&c->img, q, c->geo_row_m26, w->v);
}

/* |a - b| of two int16 coordinates <= gg (no overflow: int32) */
static inline int near_q(int32_t a, int32_t b, int32_t gg)
{
    const int32_t d = a - b;
    return d <= gg && -d <= gg;
}

/* Pixel n of q's window: a fragment or kept pixel (label below LAB_PENDING), not q, whose range differs from
 * q's by at most gg = rgap + rgpm min(dn, dq) and whose coordinates lie within gg of q's (each axis, then
 * the squared distance, uint32: gg <= 2500 + 16384 steps). Within it a fragment pixel joins and a kept pixel
 * is a contact (the nearest one wins, ties: the first met). */
static inline void probe_q(lidet_cluster_q_state_t *c, lidet__rescue_q_t *rs, const uint16_t *lab, uint32_t n,
                           const window_q_t *w, const lidet__grow_q_t *g)
{
    const uint32_t l = lab[n];
    const lidet_range_image_t *img = &c->img;
    uint32_t dn, lo, gg, dd;
    int32_t dx, dy, dz, v[3];
    if (l >= LAB_PENDING || n == w->q)
    {
        return;
    }
    dn = img->range_4mm[n];
    lo = dn < w->dq ? dn : w->dq;
    gg = g->rgap + ((lo * g->rgpm + 32768u) >> 16);
    if ((dn < w->dq ? w->dq - dn : dn - w->dq) > gg)
    {
        return;
    }
    lidet__qpix_xyz_m(img, n, c->geo_row_m26, v); /* stored or decoded (lidet_qpix.h) */
    if (!near_q(v[0], w->v[0], (int32_t)gg) || !near_q(v[1], w->v[1], (int32_t)gg) ||
        !near_q(v[2], w->v[2], (int32_t)gg))
    {
        return;
    }
    dx = v[0] - w->v[0];
    dy = v[1] - w->v[1];
    dz = v[2] - w->v[2];
    dd = (uint32_t)(dx * dx) + (uint32_t)(dy * dy) + (uint32_t)(dz * dz);
    if (dd > gg * gg)
    {
        return;
    }
    LIDET__RESCUE_ACCEPT(c, rs, n, l, dd);
}

/* the window walk (lidet_cluster_rescue_body.h) with the integer stage's types */
#define RESCUE_STATE_T lidet_cluster_q_state_t
#define RESCUE_PARAM_T lidet__grow_q_t
#define RESCUE_RS_T lidet__rescue_q_t
#define RESCUE_WIN_T window_q_t
#define RESCUE_WIN_SET window_set_q
#define RESCUE_PROBE(c, rs, lab, n, win, g, compact) probe_q(c, rs, lab, n, win, g)
#include "internal/lidet_cluster_rescue_body.h"

void lidet__cluster_q_rescue_grow(lidet_cluster_q_state_t *c, const lidet__grow_q_t *g, uint32_t start,
                                  lidet__rescue_q_t *rs)
{
    rescue_grow(c, g, start, rs, 1);
}
