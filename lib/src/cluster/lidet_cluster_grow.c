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
#include "internal/lidet_qmath.h" /* lidet__q_umul32: the fill's row from the pixel index */

#if LIDET_HOST_SIMD && defined(__SSE2__)
#include <emmintrin.h>
#endif

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
#if defined(__x86_64__) || defined(__i386__)
    if (g->gap > 0.0f)
    {
        /* x86: both tests always computed, combined without a branch (the angle test's outcome is data and a
         * branch on it mispredicts; the gap test costs a few multiplications) */
        const float gg = g->gap + g->gpm * d2;
        return (v > g->tan_theta * u) & (u * u + v * v <= gg * gg);
    }
    return v > g->tan_theta * u;
#else
    /* in-order cores: the gap test only after the angle test passes (fewer instructions; the same outcome) */
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
#endif
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
#define GROW_TEST_EVERY 0
#include "internal/lidet_cluster_grow_body.h"
#undef GROW_RNG_T
#undef GROW_RANGES
#undef GROW_FN
#undef GROW_TEST_EVERY

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

#if LIDET_HOST_SIMD && defined(__SSE2__)
/* link_4mm on four pairs at once (SSE2): q's range fq against the ranges dn, beam pair tables sn, cs per lane;
 * the same IEEE operations in the same order as link_ordered (max / min of two exact integers are the integer
 * order's d1, d2), so the same outcome in every lane. Returns the lanes that join (all bits set) */
static inline __m128 link4_4mm(__m128 fq, __m128 dn, __m128 sn, __m128 cs, const lidet__grow_t *g)
{
    const __m128 d1 = _mm_max_ps(fq, dn), d2 = _mm_min_ps(fq, dn);
    const __m128 u = _mm_sub_ps(d1, _mm_mul_ps(d2, cs)), v = _mm_mul_ps(d2, sn);
    __m128 ok = _mm_cmpgt_ps(v, _mm_mul_ps(_mm_set1_ps(g->tan_theta), u));
    if (g->gap > 0.0f)
    {
        const __m128 gg = _mm_add_ps(_mm_set1_ps(g->gap), _mm_mul_ps(_mm_set1_ps(g->gpm), d2));
        ok = _mm_and_ps(ok, _mm_cmple_ps(_mm_add_ps(_mm_mul_ps(u, u), _mm_mul_ps(v, v)), _mm_mul_ps(gg, gg)));
    }
    return ok;
}

/* The 3 x 3 block of 16-bit values around the pixel at p (rows cols apart) as two vectors of 32-bit lanes:
 * *a = right, left, down, up; *b = down-left, down-right, up-left, up-right. Three 8-byte loads (columns
 * col - 1 .. col + 2 of the rows above, at and below: the caller keeps col + 2 within the row) and shuffles */
static inline void block3_16(const uint16_t *p, uint32_t cols, __m128i *a, __m128i *b)
{
    const __m128i z = _mm_setzero_si128();
    /* [col - 1, col, col + 1, col + 2] of each row */
    const __m128 m =
        _mm_castsi128_ps(_mm_unpacklo_epi16(_mm_loadl_epi64((const __m128i *)(const void *)(p - 1)), z));
    const __m128 d = _mm_castsi128_ps(
        _mm_unpacklo_epi16(_mm_loadl_epi64((const __m128i *)(const void *)(p + cols - 1u)), z));
    const __m128 u = _mm_castsi128_ps(
        _mm_unpacklo_epi16(_mm_loadl_epi64((const __m128i *)(const void *)(p - cols - 1u)), z));
    /* [m2, m0] and [d1, u1] (of [d0, u0, d1, u1]) */
    *a = _mm_castps_si128(_mm_shuffle_ps(m, _mm_unpacklo_ps(d, u), _MM_SHUFFLE(3, 2, 0, 2)));
    *b = _mm_castps_si128(_mm_shuffle_ps(d, u, _MM_SHUFFLE(2, 0, 2, 0)));
}

/* GROW_NEIGHBOURS of the compact copy (lidet_cluster_grow_body.h), SSE2 hosts: the first steps of the four
 * searches and the four diagonals of pixel q (row r, away from the edges, kc >= 2: columns col - 1 .. col + 2
 * in the row) as two vectors of four lanes: labels, ranges and the join test at once, each outcome a bit.
 * Measured on the 17 real KITTI scans (HDL-64, one x86-64 core): the stage's median 3.27 -> 2.80 ms with the
 * searches from the second step; most of the gain is the branches per neighbour (data that mispredicts) that
 * became bits, and the loads (three per plane, where scalar gathers of the eight cost more than they saved) */
static inline void neighbours_4mm(const lidet_cluster_state_t *c, const lidet__grow_t *g, uint32_t q,
                                  uint32_t r, uint32_t dq, int occl, uint32_t *take, uint32_t *redo,
                                  uint32_t *nonc)
{
    const uint32_t ru = (r - 1u) * STEPS;
    __m128i la, lb, ria, rib;
    block3_16(c->labels + q, g->cols, &la, &lb);
    block3_16(c->img.range_4mm + q, g->cols, &ria, &rib);
    {
        const __m128 ra = _mm_cvtepi32_ps(ria), rb = _mm_cvtepi32_ps(rib), fq = _mm_set1_ps((float)dq);
        const __m128 ka = link4_4mm(
            fq, ra, _mm_setr_ps(c->col_sin[0], c->col_sin[0], c->row_sin[r * STEPS], c->row_sin[ru]),
            _mm_setr_ps(c->col_cos[0], c->col_cos[0], c->row_cos[r * STEPS], c->row_cos[ru]), g);
        const uint32_t link_a = (uint32_t)_mm_movemask_ps(ka);
        const uint32_t free_a =
            (uint32_t)_mm_movemask_ps(_mm_castsi128_ps(_mm_cmpeq_epi32(la, _mm_setzero_si128())));
        const uint32_t nonc_a = (uint32_t)_mm_movemask_ps(
            _mm_castsi128_ps(_mm_cmpeq_epi32(la, _mm_set1_epi32((int)LAB_NONCAND))));
        const uint32_t near_a = (uint32_t)_mm_movemask_ps(_mm_cmplt_ps(ra, fq));
        uint32_t tb = 0u;
        if (g->diag)
        {
            const __m128 kb = link4_4mm(
                fq, rb, _mm_setr_ps(c->diag_sin[r], c->diag_sin[r], c->diag_sin[r - 1u], c->diag_sin[r - 1u]),
                _mm_setr_ps(c->diag_cos[r], c->diag_cos[r], c->diag_cos[r - 1u], c->diag_cos[r - 1u]), g);
            tb = (uint32_t)_mm_movemask_ps(kb) &
                 (uint32_t)_mm_movemask_ps(_mm_castsi128_ps(_mm_cmpeq_epi32(lb, _mm_setzero_si128())));
        }
        /* a free candidate that passes the test joins (and ends its search); with the occluder rule a nearer
         * candidate that fails it is an occluder the search steps over: that search is run */
        *take = (free_a & link_a) | (tb << 4);
        *redo = nonc_a | (occl ? near_a & ~link_a & ~nonc_a : 0u);
        *nonc = nonc_a;
    }
}
#define GROW_NEIGHBOURS(c, g, q, r, dq, occl, take, redo, nonc)                                              \
    neighbours_4mm(c, g, q, r, dq, occl, take, redo, nonc)
/* bits set in a 4-bit mask (a nibble per mask value) */
#define GROW_POP4(m) ((uint32_t)(0x4332322132212110ull >> (4u * (m))) & 15u)

/* the first set bit of a 4-bit mask, 4 for none (a nibble per mask value) */
#define CTZ4(m) ((uint32_t)(0x0102010301020104ull >> (4u * (m))) & 15u)

/* GROW_FN(search) with the occluder rule and nk <= 4 steps (lidet_cluster_grow_body.h: GROW_SEARCH4), SSE2
 * hosts: the searches that go on past their first step (57 % of the pixels expanded on real KITTI scan 000000
 * have one, about 2.3 steps each). The labels and ranges of the (up to) four steps from n0 read at once (one
 * 8-byte load each along a row, scalar gathers across rows; lanes past nk repeat the first step and are masked
 * off), the join test on the four lanes (link4_4mm, the same outcome as link_4mm), and the search's end as the
 * first candidate that joins or is not nearer than q: the same joins and the same count of bridged occluders
 * (the candidates before the end) as the scalar loop, without its branches per step (data that mispredicts).
 * Measured on the 17 real KITTI scans (HDL-64, x86-64, per scan the fastest of 5 medians of 10, mean over the
 * scans): the stage 2.56 -> 2.30 ms; the searches along a row alone 2.45 ms. A branch-free take of the end
 * pixel measured slower (2.34 -> 2.46 ms) */
static inline uint32_t search4_4mm(uint16_t *lab, lidet_member_t *mem, const uint16_t *rng, uint32_t tail,
                                   uint32_t dq, uint32_t n0, int32_t step, uint32_t nk, const float *sn,
                                   const float *cs, int32_t gs, const lidet__grow_t *g)
{
    const __m128i z = _mm_setzero_si128();
    __m128i l, ri;
    __m128 tsn, tcs;
    if (step == 1)
    {
        l = _mm_unpacklo_epi16(_mm_loadl_epi64((const __m128i *)(const void *)(lab + n0)), z);
        ri = _mm_unpacklo_epi16(_mm_loadl_epi64((const __m128i *)(const void *)(rng + n0)), z);
    }
    else if (step == -1)
    {
        l = _mm_shuffle_epi32(
            _mm_unpacklo_epi16(_mm_loadl_epi64((const __m128i *)(const void *)(lab + n0 - 3u)), z),
            _MM_SHUFFLE(0, 1, 2, 3));
        ri = _mm_shuffle_epi32(
            _mm_unpacklo_epi16(_mm_loadl_epi64((const __m128i *)(const void *)(rng + n0 - 3u)), z),
            _MM_SHUFFLE(0, 1, 2, 3));
    }
    else
    {
        const int32_t s1 = nk > 1u ? step : 0, s2 = nk > 2u ? 2 * step : 0, s3 = nk > 3u ? 3 * step : 0;
        l = _mm_setr_epi32(lab[n0], lab[(int32_t)n0 + s1], lab[(int32_t)n0 + s2], lab[(int32_t)n0 + s3]);
        ri = _mm_setr_epi32(rng[n0], rng[(int32_t)n0 + s1], rng[(int32_t)n0 + s2], rng[(int32_t)n0 + s3]);
    }
    /* the lanes past nk read inside the image: along a row columns col +- 2 .. 5 (a row above and below q),
     * across rows and in the tables with a stride the first step's entries again; a table with a stride of 1
     * (rows r and r + k, and the columns' table from k = 2) holds 4 entries from sn when STEPS >= 5 */
    if (gs == 1 && STEPS >= 5u)
    {
        tsn = _mm_loadu_ps(sn);
        tcs = _mm_loadu_ps(cs);
    }
    else
    {
        const int32_t t1 = nk > 1u ? gs : 0, t2 = nk > 2u ? 2 * gs : 0, t3 = nk > 3u ? 3 * gs : 0;
        tsn = _mm_setr_ps(sn[0], sn[t1], sn[t2], sn[t3]);
        tcs = _mm_setr_ps(cs[0], cs[t1], cs[t2], cs[t3]);
    }
    {
        const __m128 fq = _mm_set1_ps((float)dq), dn = _mm_cvtepi32_ps(ri);
        const uint32_t valid = (1u << nk) - 1u;
        const uint32_t nonc =
            (uint32_t)_mm_movemask_ps(_mm_castsi128_ps(_mm_cmpeq_epi32(l, _mm_set1_epi32((int)LAB_NONCAND))));
        const uint32_t fre = (uint32_t)_mm_movemask_ps(_mm_castsi128_ps(_mm_cmpeq_epi32(l, z)));
        const uint32_t lnk = (uint32_t)_mm_movemask_ps(link4_4mm(fq, dn, tsn, tcs, g));
        const uint32_t near = (uint32_t)_mm_movemask_ps(_mm_cmplt_ps(dn, fq));
        const uint32_t cand = valid & ~nonc;
        const uint32_t e = CTZ4(cand & (lnk | ~near)); /* the step that ends the search; 4: none */
        *g->bridged += GROW_POP4(cand & ((1u << e) - 1u));
        if (((lnk & fre) >> e) & 1u)
        {
            tail = lidet__cluster_take(lab, mem, tail, (uint32_t)((int32_t)n0 + (int32_t)e * step));
        }
    }
    return tail;
}
#define GROW_SEARCH4(lab, mem, rng, tail, dq, n0, step, nk, sn, cs, gs, g)                                   \
    search4_4mm(lab, mem, rng, tail, dq, n0, step, nk, sn, cs, gs, g)
#endif
#define GROW_RNG_T uint16_t
#define GROW_RANGES(img) ((img)->range_4mm)
#define GROW_FN(name) name##_4mm
/* one test per candidate where it was measured faster (x86-64: the real KITTI scans' clustering); on the Arm
 * and RISC-V images the HDL-64 scan's clustering took 7.2 M (Cortex-M7) and 5.0 M (RV32IMAFC) instructions more */
#if defined(__x86_64__) || defined(__i386__)
#define GROW_TEST_EVERY 1
#else
#define GROW_TEST_EVERY 0
#endif
#include "internal/lidet_cluster_grow_body.h"
#undef GROW_RNG_T
#undef GROW_RANGES
#undef GROW_FN
#undef GROW_NEIGHBOURS
#undef GROW_POP4
#undef GROW_SEARCH4
#undef CTZ4

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
