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

/* ---- the first fill's searches decided beforehand (x86-64 hosts with AVX-512) ---------------------------------
 * The fill spent most of its time deciding, pixel by pixel, where each of the four searches ends: branches on data
 * that mispredict, on loads from four directions. Where a search ends, whether it joins there and how many occluders
 * it steps over depend on the ranges and on which pixels are candidates, not on what the fill has visited
 * (GROW_TEST_EVERY: a search ends at its first candidate that passes the join test or is not nearer than its pixel, or
 * without the occluder rule at its first candidate; it takes that pixel when it is free). So before the first fill
 * (lidet__cluster_edges) every candidate's four searches and four diagonals are run a row at a time, sixteen pixels a
 * vector (a step is a contiguous load of sixteen labels and ranges, its table entry the same for the whole row), and
 * each pixel's outcome is kept in a word of the edge plane (the detector workspace lends its R plane, which only the
 * ground stage reads: lidet_workspace.h): the step at which each search joins (0: none), the diagonals that pass the
 * test, the occluders stepped over. The fill (fill_edges) then takes the free ones in the expansion's order. Each test
 * is link4_4mm's, the same IEEE operations in the same order, so the fill takes the same pixels in the same order and
 * counts the same bridged steps as grow_4mm.
 * A pixel has no word (it is expanded as before) in the columns within max_steps of the image's edges, whose searches
 * wrap, and once the run's bridging budget is spent. The plane is not used for the regrowth's fills (another gap
 * bound), with the regrowth's cut (cfg regrow_cut_m > 0: a cut pixel stops being a candidate during the fill, which
 * would change the searches through it), for max_steps > 7 (3 bits a search), and where the CPU has no AVX-512
 * (checked at run time).
 * Real KITTI scans (HDL-64, 360 degrees, one AMD EPYC core): see docs/journal/detector.md, "The fill's searches
 * decided beforehand". */
#if LIDET_HOST_SIMD && LIDET__TARGET_X86_64_GNU
#include <immintrin.h>
#define LIDET__GROW_EDGES 1
/* a word of the edge plane: bits 0-2, 3-5, 6-8, 9-11 the step at which the right, left, down, up search joins (0:
 * none); bits 12-15 the diagonals down-left, down-right, up-left, up-right that pass the test; bits 16-20 the
 * occluders the four searches step over; EDGE_VALID set on every word written for a candidate */
#define EDGE_VALID 0x80000000u
#define EDGE_BRIDGED_SHIFT 16u
#define EDGE_DIAG_SHIFT 12u
#define EDGE_MAX_STEPS 7u

#define EDGE_TARGET __attribute__((target("avx512f")))
/* link_4mm on sixteen pairs (AVX-512): link4_4mm's operations */
EDGE_TARGET static inline __mmask16 link16_4mm(__m512 fq, __m512 dn, __m512 sn, __m512 cs, __m512 tan_theta,
                                               __m512 gap, __m512 gpm, int use_gap)
{
    const __m512 d1 = _mm512_max_ps(fq, dn), d2 = _mm512_min_ps(fq, dn);
    const __m512 u = _mm512_sub_ps(d1, _mm512_mul_ps(d2, cs)), v = _mm512_mul_ps(d2, sn);
    __mmask16 ok = _mm512_cmp_ps_mask(v, _mm512_mul_ps(tan_theta, u), _CMP_GT_OQ);
    if (use_gap)
    {
        const __m512 gg = _mm512_add_ps(gap, _mm512_mul_ps(gpm, d2));
        ok &= _mm512_cmp_ps_mask(_mm512_add_ps(_mm512_mul_ps(u, u), _mm512_mul_ps(v, v)),
                                 _mm512_mul_ps(gg, gg), _CMP_LE_OQ);
    }
    return ok;
}

EDGE_TARGET static inline __m512i load16_u16(const uint16_t *p)
{
    return _mm512_cvtepu16_epi32(_mm256_loadu_si256((const __m256i *)(const void *)p));
}

/* one search of sixteen pixels q .. q + 15 (candidates `active`, ranges fq): steps k = 1 .. nk at q + k step,
 * tables sn, cs at (k - 1) gs. Returns the step at which each lane joins (0: none) and adds the occluders
 * each lane steps over to *br */
EDGE_TARGET static inline __m512i search16_4mm(const uint16_t *lab, const uint16_t *rng, uint32_t q,
                                               int32_t step, uint32_t nk, const float *sn, const float *cs,
                                               int32_t gs, __m512 fq, __mmask16 active, __m512 tan_theta,
                                               __m512 gap, __m512 gpm, int use_gap, int occl, __m512i *br)
{
    const __m512i nonc = _mm512_set1_epi32((int)LAB_NONCAND), one = _mm512_set1_epi32(1);
    __m512i js = _mm512_setzero_si512(), b = *br;
    uint32_t k;
    for (k = 1u; k <= nk; ++k)
    {
        const uint32_t n = (uint32_t)((int32_t)q + (int32_t)k * step);
        const __m512 dn = _mm512_cvtepi32_ps(load16_u16(rng + n));
        const __mmask16 lk =
            link16_4mm(fq, dn, _mm512_set1_ps(sn[(int32_t)(k - 1u) * gs]),
                       _mm512_set1_ps(cs[(int32_t)(k - 1u) * gs]), tan_theta, gap, gpm, use_gap);
        const __mmask16 nr = _mm512_cmp_ps_mask(dn, fq, _CMP_LT_OQ);
        const __mmask16 cand = (__mmask16)(active & ~_mm512_cmpeq_epi32_mask(load16_u16(lab + n), nonc));
        /* the end: with the occluder rule the first candidate that joins or is not nearer, else the first */
        const __mmask16 end = (__mmask16)(occl ? cand & (lk | ~nr) : cand);
        js = _mm512_mask_mov_epi32(js, (__mmask16)(end & lk), _mm512_set1_epi32((int)k));
        b = _mm512_mask_add_epi32(b, (__mmask16)(cand & ~end), b, one); /* stepped over an occluder */
        active = (__mmask16)(active & ~end);
        if (active == 0)
        {
            break;
        }
    }
    *br = b;
    return js;
}

/* one diagonal of sixteen pixels: `bit` in the lanes whose neighbour at n passes the test */
EDGE_TARGET static inline __m512i diag16_4mm(const uint16_t *rng, uint32_t n, float sn, float cs, __m512 fq,
                                             __m512 tan_theta, __m512 gap, __m512 gpm, int use_gap,
                                             uint32_t bit)
{
    const __m512 dn = _mm512_cvtepi32_ps(load16_u16(rng + n));
    const __mmask16 lk =
        link16_4mm(fq, dn, _mm512_set1_ps(sn), _mm512_set1_ps(cs), tan_theta, gap, gpm, use_gap);
    return _mm512_maskz_mov_epi32(lk, _mm512_set1_epi32((int)bit));
}

#define EDGE_LANES 16u
EDGE_TARGET static void edges_simd(const lidet_cluster_state_t *c, const lidet__grow_t *g, uint32_t *edges)
{
    const uint16_t *lab = c->labels, *rng = c->img.range_4mm;
    const uint32_t rows = g->rows, cols = g->cols, ks = g->ks, kc = g->kc;
    const __m512 tan_theta = _mm512_set1_ps(g->tan_theta), gap = _mm512_set1_ps(g->gap),
                 gpm = _mm512_set1_ps(g->gpm);
    const int use_gap = g->gap > 0.0f, occl = c->cfg.bridge_occluders != 0u;
    const __m512i nonc = _mm512_set1_epi32((int)LAB_NONCAND);
    /* blocks of sixteen columns in [kc, cols - kc); the columns outside them run the expansion (no valid word) */
    const uint32_t c_lo = kc, n_blk = (cols - 2u * kc) / EDGE_LANES, c_hi = c_lo + EDGE_LANES * n_blk;
    uint32_t r, b, cc;
    for (r = 0; r < rows; ++r)
    {
        const uint32_t nd = rows - 1u - r < ks ? rows - 1u - r : ks, nu = r < ks ? r : ks;
        const uint32_t rowbase = r * cols;
        for (cc = 0; cc < c_lo; ++cc)
        {
            edges[rowbase + cc] = 0u;
        }
        for (cc = c_hi; cc < cols; ++cc)
        {
            edges[rowbase + cc] = 0u;
        }
        for (b = 0; b < n_blk; ++b)
        {
            const uint32_t q = rowbase + c_lo + EDGE_LANES * b;
            const __mmask16 candq = (__mmask16)~_mm512_cmpeq_epi32_mask(load16_u16(lab + q), nonc);
            __m512i w, br = _mm512_setzero_si512(), js;
            __m512 fq;
            if (candq == 0)
            {
                continue; /* no candidate: never expanded, its words never read */
            }
            fq = _mm512_cvtepi32_ps(load16_u16(rng + q));
            w = _mm512_set1_epi32((int)EDGE_VALID);
            js = search16_4mm(lab, rng, q, 1, kc, c->col_sin, c->col_cos, 1, fq, candq, tan_theta, gap, gpm,
                              use_gap, occl, &br);
            w = _mm512_or_si512(w, js);
            js = search16_4mm(lab, rng, q, -1, kc, c->col_sin, c->col_cos, 1, fq, candq, tan_theta, gap, gpm,
                              use_gap, occl, &br);
            w = _mm512_or_si512(w, _mm512_slli_epi32(js, 3));
            if (nd > 0u)
            {
                js = search16_4mm(lab, rng, q, (int32_t)cols, nd, c->row_sin + r * STEPS,
                                  c->row_cos + r * STEPS, 1, fq, candq, tan_theta, gap, gpm, use_gap, occl,
                                  &br);
                w = _mm512_or_si512(w, _mm512_slli_epi32(js, 6));
            }
            if (nu > 0u)
            {
                js = search16_4mm(lab, rng, q, -(int32_t)cols, nu, c->row_sin + (r - 1u) * STEPS,
                                  c->row_cos + (r - 1u) * STEPS, 1 - (int32_t)STEPS, fq, candq, tan_theta,
                                  gap, gpm, use_gap, occl, &br);
                w = _mm512_or_si512(w, _mm512_slli_epi32(js, 9));
            }
            if (g->diag)
            {
                if (r + 1u < rows)
                {
                    w = _mm512_or_si512(w, diag16_4mm(rng, q + cols - 1u, c->diag_sin[r], c->diag_cos[r], fq,
                                                      tan_theta, gap, gpm, use_gap, 1u << EDGE_DIAG_SHIFT));
                    w = _mm512_or_si512(w, diag16_4mm(rng, q + cols + 1u, c->diag_sin[r], c->diag_cos[r], fq,
                                                      tan_theta, gap, gpm, use_gap, 2u << EDGE_DIAG_SHIFT));
                }
                if (r > 0u)
                {
                    w = _mm512_or_si512(w, diag16_4mm(rng, q - cols - 1u, c->diag_sin[r - 1u],
                                                      c->diag_cos[r - 1u], fq, tan_theta, gap, gpm, use_gap,
                                                      4u << EDGE_DIAG_SHIFT));
                    w = _mm512_or_si512(w, diag16_4mm(rng, q - cols + 1u, c->diag_sin[r - 1u],
                                                      c->diag_cos[r - 1u], fq, tan_theta, gap, gpm, use_gap,
                                                      8u << EDGE_DIAG_SHIFT));
                }
            }
            w = _mm512_or_si512(w, _mm512_slli_epi32(br, (int)EDGE_BRIDGED_SHIFT));
            _mm512_storeu_si512((void *)(edges + q), w);
        }
    }
}

const uint32_t *lidet__cluster_edges(const lidet_cluster_state_t *c, const lidet__grow_t *g, uint32_t *edges)
{
    if (edges == 0 || !lidet__img_compact(&c->img) || g->ks < 1u || g->ks > EDGE_MAX_STEPS ||
        g->kc != g->ks || c->cfg.regrow_cut_m > 0.0f || g->cols < 2u * g->kc + EDGE_LANES ||
        !__builtin_cpu_supports("avx512f"))
    {
        return 0;
    }
    {
        /* the compact copy's gap bound in 4 mm steps (lidet__cluster_grow) */
        lidet__grow_t gs = *g;
        gs.gap = g->gap * LIDET_PIXEL_PER_M;
        edges_simd(c, &gs, edges);
    }
    return edges;
}

/* a pixel of the first fill without a word (an edge column) or past the bridging budget: its expansion */
#if defined(__GNUC__)
__attribute__((noinline))
#endif
static uint32_t
expand_edgeless(lidet_cluster_state_t *c, const lidet__grow_t *g, uint32_t tail, uint32_t q)
{
    const uint32_t r = g->row_magic != 0u ? (uint32_t)(lidet__q_umul32(q, g->row_magic) >> 32) : q / g->cols;
    return c->cfg.bridge_occluders != 0u && *g->bridged < g->bridge_max ? expand_4mm(c, g, tail, q, r, 1)
                                                                        : expand_4mm(c, g, tail, q, r, 0);
}

/* the first fill with the searches decided beforehand (grow_4mm's fill with the plane): each pixel's joins in the
 * expansion's order (right, left, down, up, then the diagonals), the free ones taken; a pixel without a word or
 * past the bridging budget expanded as in grow_4mm. The eight pixels a join may take are distinct (a search that
 * does not join names q itself, never free), so each is read, written at the tail and marked without a branch:
 * the tail moves on only past a free one, and a pixel that was not free keeps its label (measured against
 * branches on each: real KITTI scans' clustering 0.2 ms faster) */
__attribute__((noinline, target("avx2"))) static uint32_t
fill_edges(lidet_cluster_state_t *c, const lidet__grow_t *g, uint32_t start, uint32_t tail)
{
    uint16_t *lab = c->labels;
    lidet_member_t *mem = c->members;
    const uint32_t *ed = g->edges;
    const uint32_t cols = g->cols, npix = g->rows * g->cols;
    const int32_t sc = (int32_t)cols;
    /* a word's fields (the four searches' join steps, the four diagonals' bits) and the offsets they scale */
    const __m256i shift = _mm256_setr_epi32(0, 3, 6, 9, 12, 13, 14, 15);
    const __m256i field = _mm256_setr_epi32(7, 7, 7, 7, 1, 1, 1, 1);
    const __m256i mult = _mm256_setr_epi32(1, -1, sc, -sc, sc - 1, sc + 1, -sc - 1, -sc + 1);
    uint32_t head = start;
    while (head < tail)
    {
        const uint32_t q = (uint32_t)mem[head++];
        const uint32_t e = ed[q];
        if (head + 3u < tail)
        {
            __builtin_prefetch(ed + mem[head + 3u]);
        }
        if ((e & EDGE_VALID) != 0u && *g->bridged < g->bridge_max && tail + 8u <= npix)
        {
            /* the eight pixels a join may take (q itself where none), from the word's fields at once, then each
             * in turn: written at the tail, which moves on only when it was free, and marked (the members'
             * buffer holds the eight writes: tail + 8 <= rows * cols) */
            uint32_t n[8], k;
            const __m256i f = _mm256_and_si256(_mm256_srlv_epi32(_mm256_set1_epi32((int)e), shift), field);
            _mm256_storeu_si256((__m256i *)(void *)n,
                                _mm256_add_epi32(_mm256_set1_epi32((int)q), _mm256_mullo_epi32(f, mult)));
            *g->bridged += (e >> EDGE_BRIDGED_SHIFT) & 31u;
            for (k = 0; k < 8u; ++k)
            {
                const uint32_t l = lab[n[k]], ok = l == LAB_FREE;
                mem[tail] = (lidet_member_t)n[k];
                lab[n[k]] = (uint16_t)(l | (LAB_PENDING & (0u - ok)));
                tail += ok;
            }
        }
        else
        {
            tail = expand_edgeless(c, g, tail, q);
        }
    }
    return tail;
}
#else
const uint32_t *lidet__cluster_edges(const lidet_cluster_state_t *c, const lidet__grow_t *g, uint32_t *edges)
{
    (void)c;
    (void)g;
    (void)edges;
    return 0;
}
#endif

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
#ifdef LIDET__GROW_EDGES
    if (g->edges != 0)
    {
        return fill_edges(c, &gs, start, tail);
    }
#endif
    return fill_4mm(c, &gs, start, tail, c->cfg.bridge_occluders != 0);
}
