/* SPDX-License-Identifier: MIT */
/* Shared between lidet_ground_filter_q.c and lidet_ground_ransac_q.c (never installed). */
#ifndef LIDET_GROUND_Q_INTERNAL_H
#define LIDET_GROUND_Q_INTERNAL_H

#include "lidet/lidet_ground_q.h"
#include "lidet_qpix.h"
#include "lidet_simd.h"

/* R of a pixel in 4 mm / 2^LIDET_GROUND_Q_R_SHIFT steps (1/64 mm) */
#define LIDET_GROUND_Q_R_SHIFT 8
/* power iterations on the adjugate of the scatter matrix per refinement */
#define LIDET_GROUND_Q_POWER_ITERS 4
/* |c|^2 (4 mm steps, to the 4th) at or below this: a degenerate triple (the float stage's 1e-8 m^4) */
#define LIDET_GROUND_Q_MIN_CROSS2 39

/* A plane prepared for heights of int16 points with 32-bit products only (a Cortex-M0+ has no 32 x 32 -> 64
 * multiply): each Q30 normal component n = hi * 2^15 + lo, lo in [-2^14, 2^14), and
 * n . p = (sum hi p << 15) + sum lo p exactly. The sums fit int32: the hi part is (n . p) / 2^15 within
 * 1.5 * 2^15, |n . p| <= 2^30 |p| <= 2^30 * 56756 for a unit normal and int16 p, so below 1.87e9 (any partial
 * sum too); the lo part is at most 3 * 2^29. */
typedef struct
{
    int32_t hi[3], lo[3];
    int32_t n[3]; /* the normal itself, for cores with a 32 x 32 -> 64 multiply-accumulate */
    int64_t d;    /* D, 4 mm / 2^30 */
} lidet__ground_q_hplane_t;

static inline void lidet__ground_q_hplane(const int32_t n[3], int64_t d, lidet__ground_q_hplane_t *h)
{
    int k;
    for (k = 0; k < 3; ++k)
    {
        h->hi[k] = (int32_t)(((int64_t)n[k] + (1 << 14)) >> 15);
        h->lo[k] = n[k] - (int32_t)((uint32_t)h->hi[k] << 15);
        h->n[k] = n[k];
    }
    h->d = d;
}

/* n . p + D in 4 mm / 2^30, exact (as the int64 expression) */
static inline int64_t lidet__ground_q_height(const lidet__ground_q_hplane_t *h, int32_t x, int32_t y,
                                             int32_t z)
{
#if LIDET_Q_HAVE_MUL64
    /* three SMLAL from D (Cortex-M3 and up): the same exact value */
    return h->d + (int64_t)h->n[0] * x + (int64_t)h->n[1] * y + (int64_t)h->n[2] * z;
#else
    const int32_t a = h->hi[0] * x + h->hi[1] * y + h->hi[2] * z;
    const int32_t b = h->lo[0] * x + h->lo[1] * y + h->lo[2] * z;
    return (int64_t)a * 32768 + b + h->d;
#endif
}

/* LIDET_GROUND_Q_BAND32 (lidet_opt.h): the band test 0 <= n . p + D <= t from the 32-bit hi part
 * a = sum hi p = (n . p - sum lo p) / 2^15 where that decides, the exact height only for the points whose a lies
 * within the lo part's reach of the band's edges (lidet__ground_q_in_band; the same outcome every time). Compiled
 * everywhere, so that the host tests check it against the exact test. */

/* A band 0 <= h <= t of heights h = a 2^sh + b + D, a = sum hi p the int32 part, b = sum lo p with
 * |b| <= B = 2^15 sum |lo| (|p| <= 2^15 per axis; a prepared plane's split has sh = 15): a outside
 * [pos_lo, pos_lo + pos_span] is surely out of the band, a in [in_lo, in_lo + in_n) surely in, and any other a
 * needs the exact height. Both sets are clipped to int32 (a is one); an empty "surely in" set has in_n 0, and
 * an empty "possibly in" set is left as one value, which then takes the exact test. */
typedef struct
{
    int32_t pos_lo, in_lo;
    uint32_t pos_span, in_n;
} lidet__ground_q_band_t;

/* the band 0 <= a 2^sh + sum lo p + D <= t (0 <= t < 2^61, |D| < 2^61, sh <= 15; a prepared plane: its lo parts,
 * sh 15), for lidet__ground_q_in_band and the RANSAC's inlier counts (lidet_ground_filter_q.c; a function of its
 * own, out of its callers' frames) */
void lidet__ground_q_band(const int32_t lo[3], int64_t d, uint64_t t, unsigned sh, lidet__ground_q_band_t *b);

/* what the hi part a says of band b: 0 surely out, 1 surely in, -1 near an edge (the exact height decides) */
static inline int lidet__ground_q_band_of(const lidet__ground_q_band_t *b, int32_t a)
{
    if ((uint32_t)a - (uint32_t)b->pos_lo > b->pos_span)
    {
        return 0;
    }
    return (uint32_t)a - (uint32_t)b->in_lo < b->in_n ? 1 : -1;
}

/* (uint64_t)(n . p + D) <= t, i.e. 0 <= n . p + D <= t, for band b = lidet__ground_q_band(h->lo, h->d, t, 15): the
 * 32-bit hi part decides unless it lies near an edge (the same outcome as the exact test) */
static inline int lidet__ground_q_in_band(const lidet__ground_q_hplane_t *h, const lidet__ground_q_band_t *b,
                                          uint64_t t, int32_t x, int32_t y, int32_t z)
{
    const int r = lidet__ground_q_band_of(b, h->hi[0] * x + h->hi[1] * y + h->hi[2] * z);
    return r >= 0 ? r : (uint64_t)lidet__ground_q_height(h, x, y, z) <= t;
}

/* c = ch 2^sh + cl for a vector of |c| <= 2^29 with sh the fewest bits (<= 15) that leave |ch| <= 2^14 (|cl| <=
 * 2^(sh - 1)): ch . q is then exact in int32 for int16 q and carries as much of c . q as it can (a fixed split at
 * 2^15 leaves a short vector all in cl). Returns sh. */
static inline unsigned lidet__ground_q_split(const int32_t c[3], int32_t ch[3], int32_t cl[3])
{
    uint32_t mx = 0u;
    unsigned sh = 0u;
    int k;
    for (k = 0; k < 3; ++k)
    {
        const uint32_t m = c[k] < 0 ? 0u - (uint32_t)c[k] : (uint32_t)c[k];
        mx = m > mx ? m : mx;
    }
    while (sh < 15u && (mx >> sh) >= (1u << 14))
    {
        ++sh;
    }
    for (k = 0; k < 3; ++k)
    {
        ch[k] = sh == 0u ? c[k] : (int32_t)(((int64_t)c[k] + ((int64_t)1 << (sh - 1u))) >> sh);
        cl[k] = c[k] - (int32_t)((uint32_t)ch[k] << sh);
    }
    return sh;
}

/* (uint64_t)z << 24 > (uint64_t)f r, exactly (the sample test's slope condition): where z < 2^24, f < 2^20 and
 * r < 2^27, from f = fh 2^8 + fl and r = rh 2^8 + rl, f r lies in [fh rh 2^16, (fh rh + fh + rh + 1) 2^16) (the
 * bound below 2^31: no wrap), so one 32-bit product decides unless z 2^8 falls in that window; elsewhere the exact
 * 64-bit product (the cores without a 32 x 32 -> 64 multiply take this form; compiled everywhere, so that the host
 * tests check it) */
static inline int lidet__ground_q_shl24_gt(uint32_t z, uint32_t f, uint32_t r)
{
    if (((z >> 24) | (f >> 20) | (r >> 27)) == 0u)
    {
        const uint32_t fh = f >> 8, rh = r >> 8, lo = fh * rh, z8 = z << 8;
        if (z8 >= lo + fh + rh + 1u)
        {
            return 1;
        }
        if (z8 <= lo)
        {
            return 0;
        }
    }
    return ((uint64_t)z << 24) > lidet__q_umul32(f, r);
}

/* LIDET_GROUND_Q_SQRT_LANES (lidet_opt.h; SIMD hosts or not). The rows of R: 1 = column-wise lanes (each digit
 * step of the square root over the whole row: a compiler vectorises the column loop on SIMD hosts), 0 = pixel by
 * pixel with root and remainder in registers (cores without SIMD: fewer loads and stores). The sample test: 1 =
 * branch-free, 0 = leaving at the first failed condition. Same values either way. */

/* R of a pixel from v = x^2 + y^2 (4 mm steps squared, v < 2^31): round(sqrt(v) 2^LIDET_GROUND_Q_R_SHIFT), exact
 * (lidet_ground_filter_q.c; exposed for the tests) */
int32_t lidet__ground_q_r(uint32_t v);

/* Pass 1's sample test settings (lidet_ground_filter_q.c: the filter's thresholds in the integer units) */
typedef struct
{
    uint64_t fy;
    int32_t fx_r, fx_mm, z_lo, z_hi;
    int on_z, desc, gate;
} lidet__ground_q_filt_t;

/* one row pair's sample tests into out[0 .. cols) (cols >= 4), R of rows r, r + 1 and their z: early = 0 the
 * branch-free kernel (SIMD hosts; it vectorises), 1 the early-exit one (cores without SIMD); the same values
 * (tests/unit/test_ground_q.c). The stage picks one with LIDET_GROUND_Q_SQRT_LANES. */
void lidet__ground_q_sample_row(const int32_t *R0, const int32_t *R1, const int16_t *Z0, const int16_t *Z1,
                                uint32_t cols, const lidet__ground_q_filt_t *f, uint8_t *out, int early);

/* LIDET_GROUND_Q_SMMULR: 1 on cores with SMMULR (the Arm DSP extension), where a range-only pixel's decode takes
 * each of lidet__qpix_decode's five rounded products rs15(a b) = (a b + 2^14) >> 15 as one SMMULR of operands
 * scaled by 2^17 together: (a' b' + 2^31) >> 32 with a' b' = a b 2^17, the same value (floor of the same exact
 * quotient). The scaled operands stay within int32: -ce 2^16 >= -2^31 (ce <= 2^15), 2 ct, 2 st, 2 se, 2 u
 * (|.| <= 2^16), r 2^16 < 2^31 (r < 2^15). */
#if defined(__ARM_FEATURE_DSP) && __ARM_FEATURE_DSP && defined(__GNUC__)
#define LIDET_GROUND_Q_SMMULR 1
/* (a b + 2^31) >> 32 */
static inline int32_t lidet__ground_q_smmulr(int32_t a, int32_t b)
{
    int32_t r;
    __asm__("smmulr %0, %1, %2" : "=r"(r) : "r"(a), "r"(b));
    return r;
}
#else
#define LIDET_GROUND_Q_SMMULR 0
#endif

/* a row's trig scaled for lidet__ground_q_decode_s: nce = -ce 2^16, se2 = 2 se */
typedef struct
{
    int32_t nce, se2;
} lidet__ground_q_rows_t;

static inline lidet__ground_q_rows_t lidet__ground_q_rows(lidet__qpix_row_t rt)
{
    lidet__ground_q_rows_t t;
    t.nce = (int32_t)(-(int64_t)rt.ce * 65536);
    t.se2 = rt.se * 2;
    return t;
}

#if LIDET_GROUND_Q_SMMULR
/* lidet__qpix_decode's x, y, z from the scaled row trig t, the column's ct2 = 2 ct and nst2 = -2 st (the tables of
 * lidet__ground_q_pix_t on these cores) and r16 = (rng & 0x7FFF) 2^16: ux = rs15(-ce ct), uy = rs15(ce st), then
 * rs15(r ux), rs15(r uy), rs15(r se) */
static inline void lidet__ground_q_decode_r16(int32_t r16, lidet__ground_q_rows_t t, int32_t ct2,
                                              int32_t nst2, int32_t v[3])
{
    const int32_t ux2 = lidet__ground_q_smmulr(t.nce, ct2) * 2, uy2 = lidet__ground_q_smmulr(t.nce, nst2) * 2;
    v[0] = lidet__ground_q_smmulr(r16, ux2);
    v[1] = lidet__ground_q_smmulr(r16, uy2);
    v[2] = lidet__ground_q_smmulr(r16, t.se2);
}

/* the same from the pixel's stored range */
static inline void lidet__ground_q_decode_s(uint32_t rng, lidet__ground_q_rows_t t, int32_t ct2, int32_t nst2,
                                            int32_t v[3])
{
    lidet__ground_q_decode_r16((int32_t)((rng & 0x7FFFu) << 16), t, ct2, nst2, v);
}
#endif

/* The pixels of the passes after the filter (gathering, fits, labels). A range-only image's columns' cosines
 * and sines (lidet__qpix_col) are computed once per run into scratch the filter alone uses (r_rem, r_v), so a
 * decode reads them instead of folding the quarter-turn table's quadrant each time: the same values. */
typedef struct
{
    const lidet_range_image_t *img;
    /* NULL: an image that stores x, y, z; where LIDET_GROUND_Q_SMMULR, 2 ct and -2 st (lidet__ground_q_decode_s) */
    const int32_t *ct, *st;
} lidet__ground_q_pix_t;

/* the columns [ca, cb) of the tables (a range-only image; the streamed run fills a sector's at a time) */
static inline void lidet__ground_q_pix_span(lidet__ground_q_pix_t *gp, lidet_ground_q_scratch_t *sc,
                                            const lidet_range_image_t *img, uint32_t ca, uint32_t cb)
{
    int32_t *ct = (int32_t *)sc->r_rem, *st = (int32_t *)sc->r_v.v;
    uint32_t c;
    gp->img = img;
    for (c = ca; c < cb; ++c)
    {
        lidet__qpix_col(img, c, &ct[c], &st[c]);
#if LIDET_GROUND_Q_SMMULR
        ct[c] *= 2;
        st[c] *= -2;
#endif
    }
    gp->ct = ct;
    gp->st = st;
}

static inline void lidet__ground_q_pix_init(lidet__ground_q_pix_t *gp, lidet_ground_q_scratch_t *sc,
                                            const lidet_range_image_t *img)
{
    gp->img = img;
    gp->ct = 0;
    gp->st = 0;
    if (lidet__qpix_range_only(img))
    {
        lidet__ground_q_pix_span(gp, sc, img, 0u, img->n_cols);
    }
}

/* x, y, z of pixel p = r cols + c with row r's trig rt at hand */
static inline void lidet__ground_q_pix_rc(const lidet__ground_q_pix_t *gp, lidet__qpix_row_t rt, uint32_t c,
                                          uint32_t p, int32_t v[3])
{
    if (gp->ct == 0)
    {
        lidet__qpix_stored(gp->img, p, v);
        return;
    }
#if LIDET_GROUND_Q_SMMULR
    lidet__ground_q_decode_s(gp->img->range_4mm[p], lidet__ground_q_rows(rt), gp->ct[c], gp->st[c], v);
#else
    lidet__qpix_decode(gp->img->range_4mm[p], rt, gp->ct[c], gp->st[c], v);
#endif
}

/* x, y, z of pixel p */
static inline void lidet__ground_q_pix(const lidet__ground_q_pix_t *gp, uint32_t p, int32_t v[3])
{
    uint32_t r;
    if (gp->ct == 0)
    {
        lidet__qpix_stored(gp->img, p, v);
        return;
    }
    r = p / gp->img->n_cols;
    lidet__ground_q_pix_rc(gp, lidet__qpix_row(gp->img, r), p - r * gp->img->n_cols, p, v);
}

/* Fits one plane per cell from the gathered samples, applies the fallback (lidet_ground_ransac_q.c). */
void lidet__ground_q_fit_sectors(lidet_ground_q_state_t *g, lidet_ground_q_scratch_t *sc,
                                 const lidet__ground_q_pix_t *gp);

/* The same sector by sector, for the streamed run (lidet_ground_ransac_q.c): sector s's near cell; the near cells'
 * fallback (after every near cell); the rest of sector s (far and third cells) once its near plane is final. */
void lidet__ground_q_fit_near(lidet_ground_q_state_t *g, lidet_ground_q_scratch_t *sc,
                              const lidet__ground_q_pix_t *gp, uint32_t s);
void lidet__ground_q_fallback(lidet_ground_q_state_t *g, lidet_ground_q_scratch_t *sc,
                              const lidet__ground_q_pix_t *gp);
void lidet__ground_q_fit_rest(lidet_ground_q_state_t *g, lidet_ground_q_scratch_t *sc,
                              const lidet__ground_q_pix_t *gp, uint32_t s);

/* The stage while a range-only image fills, sector by sector (lidet_ground_filter_q.c; the integer detector's
 * stream_sectors): begin once the image's buffers are set (the run's checks; LIDET_ERR_CONFIG without
 * seed_per_cell or on an image with stored x, y, z), then lidet__ground_q_stream_sector for each sector whose
 * columns and their neighbours' (two on each side) will not change any more, in any order, then
 * lidet__ground_q_stream_end on the finished image, which does the sectors not done yet, the fallback, and the
 * sectors that waited for it. With seed_per_cell the planes, sources, mask and counts are those of
 * lidet_ground_q_run_buffers on the finished image, bit for bit, provided no sample is dropped (stream_end's
 * LIDET_TRUNCATED: the buffer's order, hence which samples are dropped, then follows the sectors' order) and no
 * done sector's columns (or their neighbours) changed after it was done: the caller's to check. */
lidet_status_t lidet__ground_q_stream_begin(lidet_ground_q_state_t *g, const lidet_range_image_t *img);
void lidet__ground_q_stream_sector(lidet_ground_q_state_t *g, lidet_ground_q_scratch_t *sc, uint8_t *mask,
                                   const lidet_range_image_t *img, uint32_t s);
lidet_status_t lidet__ground_q_stream_end(lidet_ground_q_state_t *g, lidet_ground_q_scratch_t *sc,
                                          uint8_t *mask, const lidet_range_image_t *img);

#endif
