/* SPDX-License-Identifier: MIT */
/* Clustering, the fragment rescue (see lidet_cluster.h): components below min_points joined to each
 * other and to the nearest kept cluster by the 3D distance of their returns. Mirrors
 * codegen/lidet_ref/cluster.py: cluster_ref (rescue pass). */
#include <string.h>

#include "internal/lidet_assert.h"
#include "internal/lidet_cluster_internal.h"

#if LIDET_HOST_SIMD && defined(__SSE2__)
#include <emmintrin.h>
#endif

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

#if LIDET_HOST_SIMD && defined(__SSE2__)
/* rescue_probe's pretest (label below LAB_PENDING, range in [lo, hi]) of the 8 pixels p .. p + 7 of a compact
 * image at once: bit i for pixel p + i (the same float range and compares as lidet__img_range_c) */
static inline uint32_t probe8_4mm(const uint16_t *lab, const uint16_t *rng, uint32_t p, const window_t *w)
{
    const __m128i z = _mm_setzero_si128();
    const __m128i l = _mm_loadu_si128((const __m128i *)(const void *)(lab + p));
    /* LAB_PENDING and LAB_NONCAND (0xFFFE, 0xFFFF) are the labels whose bits but the lowest are all set */
    const __m128i late = _mm_cmpeq_epi16(_mm_or_si128(l, _mm_set1_epi16(1)), _mm_set1_epi16(-1));
    const uint32_t lm = ~(uint32_t)_mm_movemask_epi8(_mm_packs_epi16(late, z)) & 0xFFu;
    const __m128i v = _mm_loadu_si128((const __m128i *)(const void *)(rng + p));
    const __m128 m = _mm_set1_ps(LIDET_PIXEL_M), lo = _mm_set1_ps(w->lo), hi = _mm_set1_ps(w->hi);
    const __m128 d0 = _mm_mul_ps(_mm_cvtepi32_ps(_mm_unpacklo_epi16(v, z)), m);
    const __m128 d1 = _mm_mul_ps(_mm_cvtepi32_ps(_mm_unpackhi_epi16(v, z)), m);
    const uint32_t in0 = (uint32_t)_mm_movemask_ps(_mm_and_ps(_mm_cmpge_ps(d0, lo), _mm_cmple_ps(d0, hi)));
    const uint32_t in1 = (uint32_t)_mm_movemask_ps(_mm_and_ps(_mm_cmpge_ps(d1, lo), _mm_cmple_ps(d1, hi)));
    return lm & (in0 | (in1 << 4));
}

/* RESCUE_ROW of a compact image (SSE2 hosts): window pixels [b, e) of one row (8 to 16 of them) pretested 8 at
 * a time (two loads that may overlap), then rescue_link on those that pass, in order: a pixel's pretest reads
 * what rescue_probe would (in the row only a pixel that joins changes its own label). 0 (not made) for a float
 * image or another row length. Measured on the 17 real KITTI scans: the stage's median 2.80 -> 2.65 ms */
static inline int rescue_row(lidet_cluster_state_t *c, lidet__rescue_t *rs, const uint16_t *lab, uint32_t b,
                             uint32_t e, const window_t *w, const lidet__grow_t *g, int compact)
{
    const uint16_t *rng = c->img.range_4mm;
    uint32_t m;
    if (!compact || e - b < 8u || e - b > 16u)
    {
        return 0;
    }
    m = probe8_4mm(lab, rng, b, w) | (probe8_4mm(lab, rng, e - 8u, w) << (e - 8u - b));
    if (w->q >= b && w->q < e)
    {
        m &= ~(1u << (w->q - b));
    }
    while (m != 0u)
    {
        const uint32_t n = b + (uint32_t)__builtin_ctz(m);
        m &= m - 1u;
        rescue_link(c, rs, n, lab[n], lidet__pix_m(rng[n]), w->q, w->dq, g, 1);
    }
    return 1;
}
#define RESCUE_ROW(c, rs, lab, b, e, win, g, compact) rescue_row(c, rs, lab, b, e, win, g, compact)
#endif

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
