/* SPDX-License-Identifier: MIT */
/* Integer ground stage: RANSAC per cell with exact int64 plane arithmetic, the least-squares refinement by
 * power iteration on the adjugate of the inliers' scatter matrix, the checks and the fallback
 * (lidet_ground_q.h). Integers only. Mirrored bit for bit by codegen/lidet_ref/ground_q.py
 * (ransac_cell, refine). */
#include "internal/lidet_q_gpr.h" /* first: no FPU register for 64-bit integers */

#include <string.h>

#include "internal/lidet_assert.h"
#include "internal/lidet_ground_internal.h"
#include "internal/lidet_ground_q_internal.h"
#include "internal/lidet_qmath.h"
#include "internal/lidet_qpix.h"
#include "internal/lidet_rng.h"

#define ONE_Q30 ((int64_t)1 << 30)

static inline int64_t abs64(int64_t v)
{
    return v < 0 ? -v : v;
}

/* the smallest s with m >> s < 2^29 (values shifted by s, rounded, stay <= 2^29): the bit length of m less 29,
 * by a count of leading zeros where the core has one, else step by step */
static unsigned norm_shift(uint64_t m)
{
#if defined(__GNUC__) && (defined(__ARM_FEATURE_CLZ) || defined(__x86_64__) || defined(__riscv_zbb))
    const uint32_t hi = (uint32_t)(m >> 32);
    const unsigned bits = hi != 0u ? 64u - (unsigned)__builtin_clz(hi)
                                   : ((uint32_t)m != 0u ? 32u - (unsigned)__builtin_clz((uint32_t)m) : 0u);
    return bits > 29u ? bits - 29u : 0u;
#else
    unsigned s = 0;
    while ((m >> s) >= ((uint64_t)1 << 29))
    {
        ++s;
    }
    return s;
#endif
}

static inline int64_t shr(int64_t v, unsigned s)
{
    return s == 0u ? v : lidet__q_rshift_round(v, s);
}

/* the largest magnitude of n values */
static uint64_t max_abs(const int64_t *v, int n)
{
    uint64_t m = 0;
    int i;
    for (i = 0; i < n; ++i)
    {
        const uint64_t a = (uint64_t)abs64(v[i]);
        m = a > m ? a : m;
    }
    return m;
}

/* scales the n values down together (rounded shifts) until the largest magnitude is <= 2^29: products of two
 * stay below 2^58 */
static void scale_down(int64_t *v, int n)
{
    const unsigned s = norm_shift(max_abs(v, n));
    int i;
    for (i = 0; i < n; ++i)
    {
        v[i] = shr(v[i], s);
    }
}

/* a plane in the stage's internal form: Q30 unit normal, D in 4 mm / 2^30 */
typedef struct
{
    int32_t n[3];
    int64_t d;
} qplane_t;

/* v (any length, not all 0) to a Q30 unit vector; 0 when v is 0 */
static int unit_q30(const int64_t v_in[3], int32_t out[3])
{
    int64_t v[3];
    uint64_t len2;
    uint32_t len;
    int i;
    for (i = 0; i < 3; ++i)
    {
        v[i] = v_in[i];
    }
    scale_down(v, 3);
    len2 = (uint64_t)(v[0] * v[0]) + (uint64_t)(v[1] * v[1]) + (uint64_t)(v[2] * v[2]);
    len = lidet__q_sqrt_round64(len2);
    if (len == 0u)
    {
        return 0;
    }
    for (i = 0; i < 3; ++i)
    {
        out[i] = (int32_t)lidet__q_div_round(v[i] * ONE_Q30, (int64_t)len);
    }
    return 1;
}

/* a cell's samples: pixel indices, and where the cell fits, their coordinates decoded once (xyz: 3 int32 per
 * sample, in scratch the fits do not otherwise use) so RANSAC and the refinements read them instead of
 * decoding each sample up to four times */
typedef struct
{
    const lidet__ground_q_pix_t *img;
    const lidet_ground_sample_t *idx;
    const int32_t *xyz; /* NULL: decode */
    int32_t *spare;     /* with xyz: free int32 after the copy (the refinement's inliers), spare_n of them */
    uint32_t spare_n;
} cell_src_t;

static inline void pixel(const cell_src_t *src, uint32_t i, int32_t q[3])
{
    if (src->xyz != 0)
    {
        q[0] = src->xyz[3u * i];
        q[1] = src->xyz[3u * i + 1u];
        q[2] = src->xyz[3u * i + 2u];
        return;
    }
    lidet__ground_q_pix(src->img, src->idx[i], q); /* stored or decoded (lidet_qpix.h) */
}

/* the samples idx[0 .. n) of a range-only image decoded into xyz (3 int32 each), the same values as pixel's
 * decode: the samples of a cell run row by row, so a row's number (a division) and trig are taken only where
 * the row changes */
static void decode_cell(const lidet__ground_q_pix_t *gp, const lidet_ground_sample_t *idx, uint32_t n,
                        int32_t *xyz)
{
    const uint32_t cols = gp->img->n_cols;
    uint32_t i, base = 0u - cols; /* no row yet: p - base >= cols for every p */
    lidet__qpix_row_t rt;
#if LIDET_GROUND_Q_SMMULR
    const uint16_t *rng = gp->img->range_4mm;
    lidet__ground_q_rows_t rts;
    rts.nce = 0;
    rts.se2 = 0;
#endif
    rt.ce = 0;
    rt.se = 0;
    for (i = 0; i < n; ++i)
    {
        const uint32_t p = idx[i];
        if (p - base >= cols)
        {
            const uint32_t r = p / cols;
            base = r * cols;
            rt = lidet__qpix_row(gp->img, r);
#if LIDET_GROUND_Q_SMMULR
            rts = lidet__ground_q_rows(rt);
#endif
        }
#if LIDET_GROUND_Q_SMMULR
        lidet__ground_q_decode_s(rng[p], rts, gp->ct[p - base], gp->st[p - base], xyz + 3u * i);
#else
        lidet__ground_q_pix_rc(gp, rt, p - base, p, xyz + 3u * i);
#endif
    }
}

/* a += the scatter terms (xx xy xz yy yz zz) of one point, 64-bit products */
#if defined(__GNUC__)
__attribute__((always_inline))
#endif
static inline void
scatter_add64(int64_t a[6], int32_t x, int32_t y, int32_t z)
{
    a[0] += (int64_t)x * x;
    a[1] += (int64_t)x * y;
    a[2] += (int64_t)x * z;
    a[3] += (int64_t)y * y;
    a[4] += (int64_t)y * z;
    a[5] += (int64_t)z * z;
}

/* a -= the same */
#if defined(__GNUC__)
__attribute__((always_inline))
#endif
static inline void
scatter_sub64(int64_t a[6], int32_t x, int32_t y, int32_t z)
{
    a[0] -= (int64_t)x * x;
    a[1] -= (int64_t)x * y;
    a[2] -= (int64_t)x * z;
    a[3] -= (int64_t)y * y;
    a[4] -= (int64_t)y * z;
    a[5] -= (int64_t)z * z;
}

#if !LIDET_Q_HAVE_MUL64
/* the same added (neg 0) or taken out (neg 1) on the cores without a 32 x 32 -> 64 multiply: 32-bit products where
 * every coordinate is within +-46340 (a product below 2^31), the 64-bit ones (library calls) elsewhere */
#if defined(__GNUC__)
__attribute__((always_inline))
#endif
static inline void
scatter_acc32(int64_t a[6], int32_t x, int32_t y, int32_t z, int neg)
{
    int64_t t[6];
    int k;
    if (x >= -46340 && x <= 46340 && y >= -46340 && y <= 46340 && z >= -46340 && z <= 46340)
    {
        t[0] = x * x;
        t[1] = x * y;
        t[2] = x * z;
        t[3] = y * y;
        t[4] = y * z;
        t[5] = z * z;
    }
    else
    {
        t[0] = t[1] = t[2] = t[3] = t[4] = t[5] = 0;
        scatter_add64(t, x, y, z);
    }
    for (k = 0; k < 6; ++k)
    {
        a[k] = neg ? a[k] - t[k] : a[k] + t[k];
    }
}
#endif

/* The refinement's sums over the inliers' differences d (3 int32 each, m < 2^11 of them, |d| < 2^16) from the
 * cell's decoded copy: S1 += sum d (int32 partial sums: |sum| < 2^27) and S2 += sum d d^T (xx xy xz yy yz zz) in
 * exact int64, in two passes of three 64-bit sums each, so each pass keeps its sums in registers (one pass of six
 * spilled them to the stack on a Cortex-M4: a load and a store around each multiply-accumulate). The same sums.
 * Without a 32 x 32 -> 64 multiply (ARMv6-M) one pass of 32-bit products (scatter_acc32). */
#if defined(__GNUC__)
__attribute__((noinline))
#endif
static void
inlier_sums(const int32_t *d, uint32_t m, int64_t s1[3], int64_t a[6])
{
    const int32_t *p, *const end = d + 3u * m;
#if !LIDET_Q_HAVE_MUL64
    int32_t u0 = 0, u1 = 0, u2 = 0;
    for (p = d; p != end; p += 3)
    {
        u0 += p[0];
        u1 += p[1];
        u2 += p[2];
        scatter_acc32(a, p[0], p[1], p[2], 0);
    }
    s1[0] += u0;
    s1[1] += u1;
    s1[2] += u2;
#else
    int64_t a0 = a[0], a1 = a[1], a2 = a[2], a3 = a[3], a4 = a[4], a5 = a[5];
    int32_t t0 = 0, t1 = 0, t2 = 0;
    for (p = d; p != end; p += 3)
    {
        const int32_t x = p[0], y = p[1], z = p[2];
        a0 += (int64_t)x * x;
        a1 += (int64_t)x * y;
        a2 += (int64_t)x * z;
        t0 += x;
    }
    for (p = d; p != end; p += 3)
    {
        const int32_t y = p[1], z = p[2];
        a3 += (int64_t)y * y;
        a4 += (int64_t)y * z;
        a5 += (int64_t)z * z;
        t1 += y;
        t2 += z;
    }
    s1[0] += t0;
    s1[1] += t1;
    s1[2] += t2;
    a[0] = a0;
    a[1] = a1;
    a[2] = a2;
    a[3] = a3;
    a[4] = a4;
    a[5] = a5;
#endif
}

/* d = q - first added to the sums (in) or taken out of them */
#if defined(__GNUC__)
__attribute__((noinline)) /* off changed_sides' loop: its registers stay for the test */
#endif
static void
side_change(const int32_t q[3], const int32_t first[3], int in, int64_t s1[3], int64_t a[6])
{
    const int32_t dx = q[0] - first[0], dy = q[1] - first[1], dz = q[2] - first[2];
    if (in)
    {
        s1[0] += dx;
        s1[1] += dy;
        s1[2] += dz;
#if LIDET_Q_HAVE_MUL64
        scatter_add64(a, dx, dy, dz);
#else
        scatter_acc32(a, dx, dy, dz, 0);
#endif
    }
    else
    {
        s1[0] -= dx;
        s1[1] -= dy;
        s1[2] -= dz;
#if LIDET_Q_HAVE_MUL64
        scatter_sub64(a, dx, dy, dz);
#else
        scatter_acc32(a, dx, dy, dz, 1);
#endif
    }
}

/* the samples of the cell's decoded copy xyz whose side of the band (|h| <= thr as h + thr in [0, t2]) differs
 * from their flag fl: flag flipped, d = q - first added to or taken out of the sums; returns the new count */
#if defined(__GNUC__)
__attribute__((noinline)) /* its own frame: the test's constants in registers */
#endif
static uint32_t
changed_sides(const int32_t *xyz, uint32_t n, uint8_t *fl, const lidet__ground_q_hplane_t *hp, uint64_t t2,
              const int32_t first[3], uint32_t m, int64_t s1[3], int64_t a[6])
{
    const lidet__ground_q_hplane_t h = *hp; /* a local copy: the flags' stores cannot alias it (registers) */
    const int32_t *p = xyz, *const end = xyz + 3u * n;
#if LIDET_GROUND_Q_BAND32
    lidet__ground_q_band_t bd;
    lidet__ground_q_band(h.lo, h.d, t2, 15u, &bd);
#endif
    for (; p != end; p += 3, ++fl)
    {
        const int32_t x = p[0], y = p[1], z = p[2];
#if LIDET_GROUND_Q_BAND32
        const uint8_t in = (uint8_t)lidet__ground_q_in_band(&h, &bd, t2, x, y, z);
#else
        const uint8_t in = (uint8_t)((uint64_t)lidet__ground_q_height(&h, x, y, z) <= t2);
#endif
        if (in != *fl)
        {
            *fl = in;
            m = in ? m + 1u : m - 1u;
            side_change(p, first, in, s1, a);
        }
    }
    return m;
}

/* the refinement's inlier sums carried from one of its iterations to the next (the cell's decoded copy): with
 * each sample's side kept as a flag, an iteration adds and removes only the
 * samples whose side changed, the same exact sums as a pass over its inliers (the planes of two iterations
 * differ little, so most samples keep their side) */
typedef struct
{
    int have; /* sums and flags of the previous iteration's plane */
    uint32_t m;
    int64_t s1[3], a[6];
} refine_acc_t;

/* refine's inlier sums where the cell's decoded copy leaves room in the spare ints: the first iteration copies the
 * inliers' differences there and sums them (inlier_sums), later ones add or take out the samples that changed side
 * (changed_sides), ra keeping the sums. Returns 0 (nothing set) where that does not apply, else 1 with *m, s1 and a
 * set */
#if defined(__GNUC__)
__attribute__((always_inline))
#endif
static inline int
spare_sums(const cell_src_t *img, uint32_t n, const lidet__ground_q_hplane_t *hp, int64_t thr,
           const int32_t first[3], refine_acc_t *ra, uint32_t *m_out, int64_t s1[3], int64_t a[6])
{
    uint32_t m;
    if (!(img->xyz != 0 && 3u * n + (n + 3u) / 4u <= img->spare_n && n < 2048u))
    {
        return 0;
    }
    {
        /* each sample's side in flags after the spare ints the first iteration copies its inliers to */
        uint8_t *const fl = (uint8_t *)(void *)(img->spare + 3u * n);
        const int32_t *p = img->xyz, *const end = img->xyz + 3u * n;
        const uint64_t t2 = 2u * (uint64_t)thr;
        if (!ra->have)
        {
            /* the inliers' differences d = q - first copied into the spare ints, then their sums (inlier_sums) */
            int32_t *o = img->spare;
            uint8_t *f = fl;
#if LIDET_GROUND_Q_BAND32
            lidet__ground_q_band_t bd;
            lidet__ground_q_band(hp->lo, hp->d, t2, 15u, &bd);
#endif
            for (; p != end; p += 3, ++f)
            {
                const int32_t x = p[0], y = p[1], z = p[2];
#if LIDET_GROUND_Q_BAND32
                const uint8_t in = (uint8_t)lidet__ground_q_in_band(hp, &bd, t2, x, y, z);
#else
                const uint8_t in = (uint8_t)((uint64_t)lidet__ground_q_height(hp, x, y, z) <= t2);
#endif
                *f = in;
                if (in)
                {
                    o[0] = x - first[0];
                    o[1] = y - first[1];
                    o[2] = z - first[2];
                    o += 3;
                }
            }
            m = (uint32_t)(o - img->spare) / 3u;
            inlier_sums(img->spare, m, s1, a);
        }
        else
        {
            /* the previous iteration's sums, the samples that changed side added or taken out */
            m = ra->m;
            memcpy(s1, ra->s1, sizeof ra->s1);
            memcpy(a, ra->a, sizeof ra->a);
            m = changed_sides(img->xyz, n, fl, hp, t2, first, m, s1, a);
        }
        ra->have = 1;
        ra->m = m;
        memcpy(ra->s1, s1, sizeof ra->s1);
        memcpy(ra->a, a, sizeof ra->a);
    }
    *m_out = m;
    return 1;
}

/* refine's inlier sums in one pass over the samples (the general path): adds to s1 and a, returns the inliers */
#if defined(__GNUC__)
__attribute__((always_inline))
#endif
static inline uint32_t
pass_sums(const cell_src_t *img, uint32_t n, const lidet__ground_q_hplane_t *hp, int64_t thr,
          const int32_t first[3], int64_t s1[3], int64_t a[6])
{
    uint32_t i = 0, m = 0;
    int32_t q[3];
#if LIDET_GROUND_Q_BAND32
    lidet__ground_q_band_t bd;
    lidet__ground_q_band(hp->lo, hp->d, 2u * (uint64_t)thr, 15u, &bd);
#endif
    /* one pass over the samples (each decoded once): the inliers' sums S1 = sum d and S2 = sum d d^T of
     * d = q - first, exact in int64 (|d| < 2^16: below n 2^32 for n samples); the cell's decoded copy read
     * directly where there is one. S1 is summed in int32 over blocks of 2^14 samples (|sum| < 2^30), each block
     * added to the int64 sum: the 64-bit sums stay out of the sample loop */
    while (i < n)
    {
        const uint32_t blk_end = n - i > 16384u ? i + 16384u : n;
        int32_t t0 = 0, t1 = 0, t2 = 0;
        for (; i < blk_end; ++i)
        {
            int32_t x, y, z;
            if (img->xyz != 0)
            {
                const int32_t *p = img->xyz + 3u * i;
                x = p[0];
                y = p[1];
                z = p[2];
            }
            else
            {
                pixel(img, i, q);
                x = q[0];
                y = q[1];
                z = q[2];
            }
#if LIDET_GROUND_Q_BAND32
            if (!lidet__ground_q_in_band(hp, &bd, 2u * (uint64_t)thr, x, y, z))
#else
            if ((uint64_t)lidet__ground_q_height(hp, x, y, z) > 2u * (uint64_t)thr)
#endif
            {
                continue;
            }
            x -= first[0];
            y -= first[1];
            z -= first[2];
            ++m;
            t0 += x;
            t1 += y;
            t2 += z;
#if LIDET_Q_HAVE_MUL64
            scatter_add64(a, x, y, z); /* one SMLAL each (Cortex-M3 and up) */
#else
            scatter_acc32(a, x, y, z, 0); /* the products fit int32: no 64-bit multiplication helper */
#endif
        }
        s1[0] += t0;
        s1[1] += t1;
        s1[2] += t2;
    }
    return m;
}

/* The least-squares plane through the inliers (|height| <= thr) of cur among the cell's samples: their
 * centroid c0 (rounded to 4 mm steps) and scatter matrix about c0 in exact int64 sums, the normal by
 * power iteration on the adjugate of the scatter matrix starting from cur's normal (the adjugate's dominant
 * eigenvector is the scatter's least one; the ratio of a ground patch's two smallest spreads makes a few
 * iterations exact), D through the exact mean. Returns 0 (out untouched) for fewer than 3 inliers or points
 * (nearly) on a line. */

static int refine(const cell_src_t *img, uint32_t n, const qplane_t *cur, int64_t thr, qplane_t *out,
                  refine_acc_t *ra)
{
    int64_t s1[3] = {0, 0, 0}, e[3], a[6] = {0, 0, 0, 0, 0, 0}, dl[3], b[6], v[3], nd, mm;
    int32_t first[3], c0[3], nv[3];
    uint64_t ma, mb;
    uint32_t m = 0;
    int k, it;
    lidet__ground_q_hplane_t hp;
    /* |h| <= thr as 0 <= h + thr <= 2 thr: D carries thr (one unsigned comparison per sample) */
    lidet__ground_q_hplane(cur->n, cur->d + thr, &hp);
    pixel(img, 0u, first);
    if (!spare_sums(img, n, &hp, thr, first, ra, &m, s1, a))
    {
        m = pass_sums(img, n, &hp, thr, first, s1, a);
    }
    if (m < 3u)
    {
        return 0;
    }
    /* the centroid rounded to 4 mm steps, c0 = first + dl; about it (exact integer identities, so the same
     * sums as a second pass over q - c0 would give): e = sum (d - dl) = S1 - m dl and
     * a = sum (d - dl)(d - dl)^T = S2 - dl S1^T - S1 dl^T + m dl dl^T (|dl| < 2^16: every term below
     * n 2^33, far inside int64 for any cell the sample buffer holds) */
    mm = (int64_t)m;
    for (k = 0; k < 3; ++k)
    {
        dl[k] = lidet__q_div_round(s1[k], mm);
        c0[k] = first[k] + (int32_t)dl[k];
        e[k] = s1[k] - mm * dl[k];
    }
    a[0] += mm * dl[0] * dl[0] - 2 * dl[0] * s1[0];
    a[1] += mm * dl[0] * dl[1] - dl[0] * s1[1] - s1[0] * dl[1];
    a[2] += mm * dl[0] * dl[2] - dl[0] * s1[2] - s1[0] * dl[2];
    a[3] += mm * dl[1] * dl[1] - 2 * dl[1] * s1[1];
    a[4] += mm * dl[1] * dl[2] - dl[1] * s1[2] - s1[1] * dl[2];
    a[5] += mm * dl[2] * dl[2] - 2 * dl[2] * s1[2];
    /* scatter a = (xx xy xz yy yz zz) scaled to <= 2^29, its adjugate b (entries < 2^59) */
    scale_down(a, 6);
    ma = max_abs(a, 6);
    b[0] = a[3] * a[5] - a[4] * a[4];
    b[1] = a[2] * a[4] - a[1] * a[5];
    b[2] = a[1] * a[4] - a[2] * a[3];
    b[3] = a[0] * a[5] - a[2] * a[2];
    b[4] = a[1] * a[2] - a[0] * a[4];
    b[5] = a[0] * a[3] - a[1] * a[1];
    mb = max_abs(b, 6);
    /* a line (or a point): the adjugate's largest eigenvalue l2 l3 is below 2^-23 l3^2 */
    if (mb == 0u || mb < ((ma * ma) >> 23))
    {
        return 0;
    }
    scale_down(b, 6);
    nv[0] = cur->n[0];
    nv[1] = cur->n[1];
    nv[2] = cur->n[2];
    for (it = 0; it < LIDET_GROUND_Q_POWER_ITERS; ++it)
    {
        v[0] = b[0] * nv[0] + b[1] * nv[1] + b[2] * nv[2];
        v[1] = b[1] * nv[0] + b[3] * nv[1] + b[4] * nv[2];
        v[2] = b[2] * nv[0] + b[4] * nv[1] + b[5] * nv[2];
        if (!unit_q30(v, nv))
        {
            return 0;
        }
    }
    if (nv[2] < 0)
    {
        nv[0] = -nv[0];
        nv[1] = -nv[1];
        nv[2] = -nv[2];
    }
    /* D = -(n . mean), mean = c0 + e / m (|e| <= m / 2 per axis) */
    nd = (int64_t)nv[0] * e[0] + (int64_t)nv[1] * e[1] + (int64_t)nv[2] * e[2];
    out->n[0] = nv[0];
    out->n[1] = nv[1];
    out->n[2] = nv[2];
    out->d = -((int64_t)nv[0] * c0[0] + (int64_t)nv[1] * c0[1] + (int64_t)nv[2] * c0[2]) -
             lidet__q_div_round(nd, (int64_t)m);
    return 1;
}

/* The inlier count of hypothesis (c, p0, thr_l) over the cell's scoring subset (copied: the contiguous copy
 * sc->ev_*, n_eval samples; else the samples 0, stride, ... of n): a sample is an inlier when
 * 4 |c . (q - p0)| <= thr_l. With `have`, a count that can no longer beat best_cnt stops early (its count decides
 * nothing else, so the fitted planes are those of the full count). */
static uint32_t count_inliers(const lidet_ground_q_scratch_t *sc, const cell_src_t *img, uint32_t n,
                              uint32_t stride, uint32_t n_eval, int copied, const int64_t c[3],
                              const int32_t p0[3], int64_t thr_l, int have, uint32_t best_cnt)
{
    /* a sample is an inlier when 4 |h| <= thr_l, i.e. |h| <= t = floor(thr_l / 4), i.e. h + t in [0, 2t]
     * (one unsigned comparison); c is within 2^29 after scale_down, so each product is one 32 x 32 -> 64
     * multiply(-accumulate) */
    const int32_t c0 = (int32_t)c[0], c1 = (int32_t)c[1], c2 = (int32_t)c[2];
    const int64_t t = thr_l >> 2;
    const uint64_t t2 = 2u * (uint64_t)t;
    uint32_t i, cnt = 0;
    if (copied)
    {
        /* h + t = c . q + (t - c . p0): the constant is each sum's start (exact in int64: |c . q| < 2^47) */
        const int64_t h0 = t - ((int64_t)c0 * p0[0] + (int64_t)c1 * p0[1] + (int64_t)c2 * p0[2]);
#if LIDET_GROUND_Q_BAND32
        /* the band h + t in [0, 2t] in terms of a = ch . q with c = ch 2^sh + cl (lidet__ground_q_split: the hi part
         * as large as int32 allows), decided from a alone unless it lies near an edge (lidet__ground_q_in_band's
         * test) */
        int32_t ch[3], cl[3];
        lidet__ground_q_band_t bd;
        const int32_t cc[3] = {c0, c1, c2};
        const unsigned sh = lidet__ground_q_split(cc, ch, cl);
        lidet__ground_q_band(cl, h0, t2, sh, &bd);
#elif !LIDET_Q_HAVE_MUL64
        /* c split into two sums of three 32-bit products (lidet__ground_q_split) */
        int32_t ch[3], cl[3];
        const int32_t cc[3] = {c0, c1, c2};
        const unsigned sh = lidet__ground_q_split(cc, ch, cl);
#endif
        /* in blocks of 32 samples; a hypothesis that can no longer beat the best count stops */
        for (i = 0; i < n_eval && (!have || cnt + (n_eval - i) > best_cnt);)
        {
            const uint32_t end = n_eval - i > 32u ? i + 32u : n_eval;
            for (; i < end; ++i)
            {
#if LIDET_GROUND_Q_BAND32
                /* the hi part decides unless it lies near an edge of the band (lidet__ground_q_in_band) */
                const int32_t x = sc->ev_x[i], y = sc->ev_y[i], z = sc->ev_z[i];
                const int32_t ah = ch[0] * x + ch[1] * y + ch[2] * z;
                const int r = lidet__ground_q_band_of(&bd, ah);
                if (r >= 0)
                {
                    cnt += (uint32_t)r;
                }
                else
                {
                    const int64_t ht =
                        h0 + (int64_t)ah * ((int64_t)1 << sh) + (cl[0] * x + cl[1] * y + cl[2] * z);
                    cnt += (uint32_t)((uint64_t)ht <= t2);
                }
#else
#if LIDET_Q_HAVE_MUL64
                const int64_t ht =
                    h0 + (int64_t)c0 * sc->ev_x[i] + (int64_t)c1 * sc->ev_y[i] + (int64_t)c2 * sc->ev_z[i];
#else
                /* c = ch 2^sh + cl (|ch|, |cl| <= 2^14) against int16 samples: two sums of three 32-bit products
                 * (each < 2^29), the same exact value without the 64 x 64 multiply helper */
                const int32_t x = sc->ev_x[i], y = sc->ev_y[i], z = sc->ev_z[i];
                const int64_t ht = h0 + (int64_t)(ch[0] * x + ch[1] * y + ch[2] * z) * ((int64_t)1 << sh) +
                                   (cl[0] * x + cl[1] * y + cl[2] * z);
#endif
#if defined(__GNUC__) && defined(__thumb2__) && !defined(__ARM_BIG_ENDIAN)
                /* the unsigned comparison's carry added directly (GCC made it a conditional 0 / 1 and an add) */
                uint32_t tmp;
                __asm__("cmp %Q[t2], %Q[h]\n\t"
                        "sbcs %[tmp], %R[t2], %R[h]\n\t"
                        "adc %[cnt], %[cnt], #0"
                        : [cnt] "+r"(cnt), [tmp] "=r"(tmp)
                        : [t2] "r"(t2), [h] "r"(ht)
                        : "cc");
#else
                cnt += (uint32_t)((uint64_t)ht <= t2);
#endif
#endif
            }
        }
    }
    else
    {
        for (i = 0; i < n; i += stride)
        {
            int32_t q[3];
            int64_t h;
            pixel(img, i, q);
            h = (int64_t)c0 * (q[0] - p0[0]) + (int64_t)c1 * (q[1] - p0[1]) + (int64_t)c2 * (q[2] - p0[2]);
            cnt += (uint32_t)((uint64_t)(h + t) <= t2);
        }
    }
    return cnt;
}

/* The RANSAC draws of one cell (the float stage's best_hypothesis): ransac_iters triples of its n samples, a
 * hypothesis the exact cross product c of two 4 mm difference vectors (scaled within 2^29), rejected when
 * degenerate or tilted beyond max_tilt, else scored by count_inliers; the highest count wins (ties: the first),
 * with the adaptive stop. Returns 1 with the best hypothesis (best_c, best_p0, its length *best_len) and
 * *best_cnt set when any was scored. */
static int best_hypothesis_q(lidet_ground_q_state_t *g, const lidet_ground_q_scratch_t *sc,
                             const cell_src_t *img, uint32_t n, uint32_t stride, uint32_t n_eval, int copied,
                             int64_t best_c[3], int32_t best_p0[3], uint32_t *best_len, uint32_t *best_cnt)
{
    const lidet_ground_q_cfg_t *cfg = &g->cfg;
    const int64_t cos_t = g->cos_tilt_q30, inl = cfg->inlier_mm;
    const int64_t miss_max = (int64_t)(65536u - cfg->confidence_q16) << 14;
    uint32_t it;
    int have = 0;
    for (it = 0; it < cfg->ransac_iters; ++it)
    {
        const uint32_t i0 = lidet__rng_below(&g->rng, n);
        const uint32_t i1 = lidet__rng_below(&g->rng, n);
        const uint32_t i2 = lidet__rng_below(&g->rng, n);
        int32_t p0[3], p1[3], p2[3];
        int64_t c[3], len2;
        uint32_t len, cnt;
        if (i0 == i1 || i0 == i2 || i1 == i2)
        {
            continue;
        }
        pixel(img, i0, p0);
        pixel(img, i1, p1);
        pixel(img, i2, p2);
        {
            const int64_t ux = p1[0] - p0[0], uy = p1[1] - p0[1], uz = p1[2] - p0[2];
            const int64_t vx = p2[0] - p0[0], vy = p2[1] - p0[1], vz = p2[2] - p0[2];
            c[0] = uy * vz - uz * vy;
            c[1] = uz * vx - ux * vz;
            c[2] = ux * vy - uy * vx;
        }
        /* |c| < 2^34; beyond 2^29 (sides of tens of metres both) it is scaled down, rounded */
        scale_down(c, 3);
        len2 = c[0] * c[0] + c[1] * c[1] + c[2] * c[2];
        if (len2 <= LIDET_GROUND_Q_MIN_CROSS2)
        {
            continue;
        }
        len = lidet__q_sqrt_round64((uint64_t)len2);
        /* tilted beyond max_tilt: |cz| < cos(max_tilt) |c| */
        if (abs64(c[2]) * ONE_Q30 < cos_t * (int64_t)len)
        {
            continue;
        }
        ++g->stats.n_hypotheses;
        cnt = count_inliers(sc, img, n, stride, n_eval, copied, c, p0, inl * (int64_t)len, have, *best_cnt);
        if (!have || cnt > *best_cnt)
        {
            memcpy(best_c, c, 3 * sizeof best_c[0]);
            memcpy(best_p0, p0, 3 * sizeof best_p0[0]);
            *best_len = len;
            *best_cnt = cnt;
            have = 1;
            /* adaptive stop without log: (1 - w^3)^(it + 1) <= 1 - confidence, all in Q30 (the power is
             * non-increasing, so the first factor that crosses the bound decides) */
            if (cfg->confidence_q16 > 0u)
            {
                const int64_t w = lidet__q_div_round((int64_t)cnt * ONE_Q30, (int64_t)n_eval);
                const int64_t q = ONE_Q30 - lidet__q_rshift_round(lidet__q_rshift_round(w * w, 30) * w, 30);
                int64_t miss = ONE_Q30;
                uint32_t k;
                for (k = 0; k <= it && miss > miss_max; ++k)
                {
                    miss = lidet__q_rshift_round(miss * q, 30);
                }
                if (miss <= miss_max)
                {
                    break;
                }
            }
        }
    }
    return have;
}

/* RANSAC on one cell (lidet_ref/ground_q.py: ransac_cell): the float stage's draws and control flow
 * (best_hypothesis_q), the hypothesis as a plane, its refinements (refine), the checks. A hypothesis is the exact
 * cross product c of two 4 mm difference vectors, a sample its inlier when 4 |c . (p - p0)| <= inlier_mm * |c|.
 * Returns 1 with *out set when the plane passes every check. */
#if defined(__GNUC__)
__attribute__((always_inline)) /* into its one caller: one frame on the deepest stack of the 16-beam images */
#endif
static inline int
fit_cell_q(lidet_ground_q_state_t *g, lidet_ground_q_scratch_t *sc, const lidet__ground_q_pix_t *gp,
           const lidet_ground_sample_t *idx, uint32_t n, int far_step, qplane_t *out)
{
    cell_src_t src, *const img = &src;
    const lidet_ground_q_cfg_t *cfg = &g->cfg;
    const uint32_t stride = (n + cfg->eval_samples - 1u) / cfg->eval_samples;
    const uint32_t n_eval = (n + stride - 1u) / stride;
    const int copied = n_eval <= LIDET_GROUND_EVAL_MAX;
    const int64_t cos_t = g->cos_tilt_q30;
    int64_t best_c[3] = {0, 0, 0};
    int32_t best_p0[3] = {0, 0, 0};
    uint32_t best_len = 0, best_cnt = 0, r, i;
    qplane_t best;
    refine_acc_t ra; /* 80 bytes of stack (ARMv6-M's deepest frame is here) */
    src.img = gp;
    src.idx = idx;
    src.xyz = 0;
    src.spare = 0;
    src.spare_n = 0;
    if (gp->ct != 0 &&
        3u * n <= sizeof sc->r_rows / sizeof(int32_t)) /* a range-only image's cell that fits */
    {
        int32_t *xyz = &sc->r_rows[0][0];
        decode_cell(gp, idx, n, xyz);
        src.xyz = xyz;
        src.spare = xyz + 3u * n;
        src.spare_n = (uint32_t)(sizeof sc->r_rows / sizeof(int32_t)) - 3u * n;
    }
    if (copied)
    {
        for (i = 0; i < n_eval; ++i)
        {
            int32_t q[3];
            pixel(img, i * stride, q);
            sc->ev_x[i] = (int16_t)q[0];
            sc->ev_y[i] = (int16_t)q[1];
            sc->ev_z[i] = (int16_t)q[2];
        }
    }
    if (!best_hypothesis_q(g, sc, img, n, stride, n_eval, copied, best_c, best_p0, &best_len, &best_cnt) ||
        best_cnt < cfg->min_inliers)
    {
        return 0;
    }
    /* the hypothesis as a unit normal (up) and D */
    for (i = 0; i < 3u; ++i)
    {
        const int64_t ci = best_c[2] < 0 ? -best_c[i] : best_c[i];
        best.n[i] = (int32_t)lidet__q_div_round(ci * ONE_Q30, (int64_t)best_len);
    }
    best.d = -((int64_t)best.n[0] * best_p0[0] + (int64_t)best.n[1] * best_p0[1] +
               (int64_t)best.n[2] * best_p0[2]);
    ra.have = 0;
    for (r = 0; r < cfg->refine_iters; ++r)
    {
        qplane_t p;
        if (!refine(img, n, &best, (int64_t)cfg->inlier_mm << 28, &p, &ra) || p.n[2] < cos_t)
        {
            break; /* keep the last good plane */
        }
        best = p;
    }
    if (best.n[2] < cos_t || (!far_step && abs64(best.d - ((int64_t)cfg->mount_height_mm << 28)) >
                                               (int64_t)cfg->max_height_dev_mm << 28))
    {
        return 0;
    }
    *out = best;
    return 1;
}

/* z (4 mm) of the plane (n, d) over the point (x, y) (4 mm): -(n_x x + n_y y + d) / n_z, rounded */
static int32_t plane_z_at(const int32_t n[3], int64_t d, int32_t x, int32_t y)
{
    return (int32_t)lidet__q_div_round(-((int64_t)n[0] * x + (int64_t)n[1] * y + d), (int64_t)n[2]);
}

/* far cell k's plane p meets its sector's (final) near plane at the split, at the sector's middle azimuth
 * pi (1 - (2 s + 1) / ns) (BAM32 2^31 - floor((2 s + 1) 2^31 / ns)), within far_max_step_mm: 4 |z_far - z_near|
 * <= the step (the float stage's far_max_step_m test, lidet_ground_ransac.c) */
#if defined(__GNUC__)
__attribute__((noinline)) /* out of fit_cell's frame (the 16-beam images never call it) */
#endif
static int
far_meets(const lidet_ground_q_state_t *g, uint32_t k, const qplane_t *p)
{
    const uint32_t ns = g->cfg.n_sectors, s = k % ns, inner = k - ns;
    const uint32_t az = 0x80000000u - (uint32_t)(((uint64_t)(2u * s + 1u) << 31) / ns);
    /* a far cell meets its near plane at ring_split_mm; a third cell its far plane at far2_split_mm */
    const int64_t split = (int64_t)(k < 2u * ns ? g->cfg.ring_split_mm : g->cfg.far2_split_mm);
    const int32_t x = (int32_t)lidet__q_rshift_round(split * lidet__q_cos(az), 32);
    const int32_t y = (int32_t)lidet__q_rshift_round(split * lidet__q_sin(az), 32);
    int32_t nn[3];
    int64_t dz;
    nn[0] = g->planes[inner].nx;
    nn[1] = g->planes[inner].ny;
    nn[2] = g->planes[inner].nz;
    dz = (int64_t)plane_z_at(p->n, p->d, x, y) - plane_z_at(nn, g->plane_d[inner], x, y);
    return 4 * abs64(dz) <= (int64_t)g->cfg.far_max_step_mm;
}

/* the integer stage's side of lidet__ground_cells */
typedef struct
{
    lidet_ground_q_state_t *g;
    lidet_ground_q_scratch_t *sc;
    const lidet__ground_q_pix_t *img;
} fit_ctx_t;

static void set_plane(lidet_ground_q_state_t *g, uint32_t k, const qplane_t *p)
{
    g->planes[k].nx = p->n[0];
    g->planes[k].ny = p->n[1];
    g->planes[k].nz = p->n[2];
    g->planes[k].d_4mm = (int32_t)lidet__q_rshift_round(p->d, 30);
    g->plane_d[k] = p->d;
}

static int fit_cell(void *ctx, uint32_t k)
{
    fit_ctx_t *f = (fit_ctx_t *)ctx;
    const uint32_t a = f->sc->cell_first[k], n = f->sc->cell_n[k];
    const int far_step = k >= f->g->cfg.n_sectors && f->g->cfg.far_max_step_mm > 0u;
    qplane_t p;
    LIDET_ASSERT(a + n <= LIDET_GROUND_MAX_SAMPLES);
    if (f->g->cfg.seed_per_cell)
    {
        f->g->rng = lidet__rng_cell(f->g->cfg.seed, k);
    }
    if (!fit_cell_q(f->g, f->sc, f->img, f->sc->sample_pix + a, n, far_step, &p) ||
        (far_step && !far_meets(f->g, k, &p)))
    {
        return 0;
    }
    set_plane(f->g, k, &p);
    return 1;
}

static void copy_plane(void *ctx, uint32_t dst, int32_t src)
{
    lidet_ground_q_state_t *g = ((fit_ctx_t *)ctx)->g;
    if (src >= 0)
    {
        g->planes[dst] = g->planes[src];
        g->plane_d[dst] = g->plane_d[src];
    }
    else
    {
        /* the mount plane z = -mount: n = +z, D = mount (mm -> 4 mm / 2^30) */
        qplane_t m;
        m.n[0] = 0;
        m.n[1] = 0;
        m.n[2] = (int32_t)ONE_Q30;
        m.d = (int64_t)g->cfg.mount_height_mm << 28;
        set_plane(g, dst, &m);
    }
}

/* a sample with x^2 + y^2 >= split2_v (the third cells) */
static int beyond_far2(void *ctx, lidet_ground_sample_t p)
{
    const fit_ctx_t *f = (const fit_ctx_t *)ctx;
    const uint32_t px = (uint32_t)p, cols = f->img->img->n_cols;
    int32_t q[3];
    lidet__ground_q_pix_rc(f->img, lidet__qpix_row(f->img->img, px / cols), px % cols, px, q);
    return (uint32_t)(q[0] * q[0]) + (uint32_t)(q[1] * q[1]) >= f->g->split2_v;
}

/* the third cells (lidet__ground_far2_cells), out of line: its loop's frame stays off the 16-beam images' stack,
 * which never run it */
#if defined(__GNUC__)
__attribute__((noinline))
#endif
static void
fit_far2(fit_ctx_t *f)
{
    lidet_ground_q_scratch_t *sc = f->sc;
    lidet__ground_far2_cells(f->g->source, sc->cell_first, sc->cell_n, sc->sample_pix, f->g->cfg.n_sectors,
                             f->g->cfg.min_samples, &f->g->stats, beyond_far2, fit_cell, copy_plane, f);
}

void lidet__ground_q_fit_sectors(lidet_ground_q_state_t *g, lidet_ground_q_scratch_t *sc,
                                 const lidet__ground_q_pix_t *img)
{
    const uint32_t ns = g->cfg.n_sectors;
    fit_ctx_t f;
    f.g = g;
    f.sc = sc;
    f.img = img;
    lidet__ground_cells(g->source, sc->cell_n, ns, g->cfg.ring_split_mm > 0u ? 2u * ns : ns,
                        g->cfg.min_samples, g->cfg.fallback_sectors, &g->stats, fit_cell, copy_plane, &f);
    if (g->split2_v != 0xFFFFFFFFu)
    {
        fit_far2(&f);
    }
}

/* The streamed run's steps (lidet_ground_filter_q.c, lidet__ground_q_stream_*), each the part of
 * lidet__ground_q_fit_sectors that reads one sector: the near cell's fit; the near cells' fallback once every near
 * cell is fitted; the rest of a sector (its far cell, judged against its final near plane, that cell's fallback to
 * the near plane, the third cell) once its near plane is final. With a stream per cell (seed_per_cell) a cell's
 * plane reads its own samples only, so any order of the sectors gives lidet__ground_q_fit_sectors' planes,
 * sources and counts. */
static fit_ctx_t fit_ctx(lidet_ground_q_state_t *g, lidet_ground_q_scratch_t *sc,
                         const lidet__ground_q_pix_t *img)
{
    fit_ctx_t f;
    f.g = g;
    f.sc = sc;
    f.img = img;
    return f;
}

void lidet__ground_q_fit_near(lidet_ground_q_state_t *g, lidet_ground_q_scratch_t *sc,
                              const lidet__ground_q_pix_t *img, uint32_t s)
{
    const uint32_t ns = g->cfg.n_sectors;
    fit_ctx_t f = fit_ctx(g, sc, img);
    lidet__ground_fit_one(g->source, sc->cell_n, ns, g->cfg.ring_split_mm > 0u ? 2u * ns : ns,
                          g->cfg.min_samples, &g->stats, fit_cell, &f, s);
}

void lidet__ground_q_fallback(lidet_ground_q_state_t *g, lidet_ground_q_scratch_t *sc,
                              const lidet__ground_q_pix_t *img)
{
    fit_ctx_t f = fit_ctx(g, sc, img);
    lidet__ground_near_fallback(g->source, g->cfg.n_sectors, g->cfg.fallback_sectors, &g->stats, copy_plane,
                                &f);
}

void lidet__ground_q_fit_rest(lidet_ground_q_state_t *g, lidet_ground_q_scratch_t *sc,
                              const lidet__ground_q_pix_t *img, uint32_t s)
{
    const uint32_t ns = g->cfg.n_sectors, kf = ns + s;
    fit_ctx_t f = fit_ctx(g, sc, img);
    lidet__ground_fit_one(g->source, sc->cell_n, ns, g->cfg.ring_split_mm > 0u ? 2u * ns : ns,
                          g->cfg.min_samples, &g->stats, fit_cell, &f, kf);
    if (g->source[kf] != LIDET_GROUND_PLANE_FITTED)
    {
        copy_plane(&f, kf, (int32_t)s);
        g->source[kf] = LIDET_GROUND_PLANE_NEAR;
    }
    if (g->split2_v != 0xFFFFFFFFu)
    {
        lidet__ground_far2_cell(g->source, sc->cell_first, sc->cell_n, sc->sample_pix, ns, g->cfg.min_samples,
                                &g->stats, beyond_far2, fit_cell, copy_plane, &f, s);
    }
}
