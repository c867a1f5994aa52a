/* SPDX-License-Identifier: MIT */
/* Integer ground stage: configuration, the sample filter, the sample gathering, the labels and the accessors
 * (lidet_ground_q.h; the plane fits are in lidet_ground_ransac_q.c). Integers only: no <math.h>, no float.
 * Mirrored bit for bit by codegen/lidet_ref/ground_q.py. */
#include "internal/lidet_q_gpr.h" /* first: no FPU register for 64-bit integers */

#include <string.h>

#include "internal/lidet_ground_internal.h"
#include "internal/lidet_ground_q_internal.h"
#include "internal/lidet_qmath.h"
#include "internal/lidet_qpix.h"
#include "internal/lidet_rng.h"

void lidet_ground_q_cfg_default(lidet_ground_q_cfg_t *cfg, uint32_t n_rows, int32_t mount_height_mm)
{
    int low;
    if (cfg == 0)
    {
        return;
    }
    memset(cfg, 0, sizeof *cfg);
    /* the two families of lidet_ground_cfg_default, every value rounded to its integer unit */
    low = n_rows <= 32u || mount_height_mm < 1000;
    cfg->fy_max_q16 = 13107u; /* 0.2 */
    cfg->fx_max_mm = low ? 200u : 1000u;
    cfg->gate_above_mm = 430;
    cfg->gate_below_mm = 8270;
    cfg->mount_height_mm = mount_height_mm;
    cfg->sample_step = low ? 1u : 4u;
    cfg->sample_col_step = low ? 1u : 4u;
    cfg->n_sectors = 32u;
    cfg->ransac_iters = 16u;
    cfg->eval_samples = 256u;
    cfg->confidence_q16 = 64881u; /* 0.99 */
    cfg->min_samples = 10u;
    cfg->min_inliers = 8u;
    cfg->refine_iters = low ? 2u : 1u;
    cfg->inlier_mm = 200u;
    cfg->max_tilt_urad = low ? 200000u : 100000u;
    cfg->max_height_dev_mm = low ? 500u : 1000u;
    cfg->ring_split_mm = low ? 0u : 15000u;
    cfg->far_max_step_mm = low ? 0u : 500u;
    cfg->far2_split_mm = low ? 0u : 30000u;
    cfg->fallback_sectors = 4u;
    cfg->seed = 12345u;
    cfg->seed_per_cell = 0u;
    cfg->ground_mm = low ? 200u : 150u;
    cfg->ground_per_m_q16 = 0u;
    cfg->below_factor_q16 = 131072u; /* 2.0 */
    cfg->veto_slope_q16 = low ? 98304u : 65536u;
    cfg->veto_min_dz_mm = 50u;
}

lidet_status_t lidet_ground_q_state_init(lidet_ground_q_state_t *g, const lidet_ground_q_cfg_t *cfg)
{
    uint64_t split2;
    if (g == 0 || cfg == 0)
    {
        return LIDET_ERR_ARG;
    }
    g->magic = 0;
    if (cfg->n_sectors > LIDET_GROUND_MAX_SECTORS)
    {
        return LIDET_ERR_BUFFER;
    }
    if (cfg->n_sectors < 1u || cfg->ransac_iters < 1u || cfg->ransac_iters > 1000u ||
        cfg->eval_samples < 3u || cfg->sample_step < 1u || cfg->sample_step > 16u ||
        cfg->sample_col_step < 1u || cfg->sample_col_step > 16u || cfg->min_samples < 3u ||
        cfg->min_inliers < 3u || cfg->refine_iters > 10u || cfg->fx_on_z > 1u ||
        cfg->require_descending > 1u || cfg->height_gate > 1u || cfg->fallback_sectors > cfg->n_sectors ||
        cfg->seed_per_cell > 1u)
    {
        return LIDET_ERR_CONFIG;
    }
    if (cfg->fy_max_q16 > 655360u || cfg->fx_max_mm < 1u || cfg->fx_max_mm > 100000u ||
        cfg->gate_above_mm < -5000 || cfg->gate_above_mm > 10000 || cfg->gate_below_mm < 0 ||
        cfg->gate_below_mm > 20000 || cfg->mount_height_mm < 0 || cfg->mount_height_mm > 10000 ||
        cfg->confidence_q16 > 65535u || cfg->inlier_mm < 1u || cfg->inlier_mm > 5000u ||
        cfg->max_tilt_urad < 1u || cfg->max_tilt_urad > 1570796u || cfg->max_height_dev_mm < 1u ||
        cfg->max_height_dev_mm > 20000u || cfg->ring_split_mm > 500000u || cfg->far_max_step_mm > 5000u ||
        cfg->far2_split_mm > 500000u || cfg->ground_mm < 1u || cfg->ground_mm > 5000u ||
        cfg->ground_per_m_q16 > 6554u || cfg->below_factor_q16 > 1310720u || cfg->veto_slope_q16 > 6553600u ||
        cfg->veto_min_dz_mm > 5000u)
    {
        return LIDET_ERR_CONFIG;
    }
    if (lidet__ground_q_far2_on(cfg) && 3u * cfg->n_sectors > 2u * LIDET_GROUND_MAX_SECTORS)
    {
        return LIDET_ERR_CONFIG; /* the third cells' planes share the near / far arrays */
    }
    g->cfg = *cfg;
    g->rng = lidet__rng_seed(cfg->seed);
    g->cos_tilt_q30 = lidet__q_cos((uint32_t)lidet__q_urad_to_bam((int32_t)cfg->max_tilt_urad));
    /* far: 16 (x^2 + y^2) >= split^2 (x, y in 4 mm steps, split in mm), i.e. x^2 + y^2 >= ceil(split^2 / 16);
     * x^2 + y^2 < 2^31 for int16 coordinates, so a larger threshold means "never far" */
    split2 = ((uint64_t)cfg->ring_split_mm * cfg->ring_split_mm + 15u) / 16u;
    g->split_v = cfg->ring_split_mm == 0u || split2 > 0xFFFFFFFFu ? 0xFFFFFFFFu : (uint32_t)split2;
    split2 = ((uint64_t)cfg->far2_split_mm * cfg->far2_split_mm + 15u) / 16u;
    g->split2_v = !lidet__ground_q_far2_on(cfg) || split2 > 0xFFFFFFFFu ? 0xFFFFFFFFu : (uint32_t)split2;
    g->n_rows = 0;
    g->n_cols = 0;
    memset(&g->stats, 0, sizeof g->stats);
    g->magic = LIDET_INIT_MAGIC;
    return LIDET_OK;
}

lidet_status_t lidet_ground_q_init(lidet_ground_q_t *g, const lidet_ground_q_cfg_t *cfg)
{
    return g == 0 ? LIDET_ERR_ARG : lidet_ground_q_state_init(&g->state, cfg);
}

/* round(sqrt(v) * 256) for v < 2^31, exactly lidet__q_sqrt_round64(v << 16): digit by digit on v * 2^16 with
 * 32-bit values only (remainder <= 2 root < 2^25), branch-free, no division: 16 integer and 8 fraction
 * digits. One digit step of one value: */
#define R_DIGITS (16 + LIDET_GROUND_Q_R_SHIFT)
static inline void r_digit(uint32_t bits, uint32_t *root, uint32_t *rem)
{
    const uint32_t rm = (*rem << 2) | bits, trial = (*root << 2) | 1u, ge = 0u - (uint32_t)(rm >= trial);
    *rem = rm - (trial & ge);
    *root = (*root << 1) | (ge & 1u);
}

static inline uint32_t r_bits(uint32_t v, int i)
{
    return i >= 0 ? (v >> i) & 3u : 0u;
}

/* R digit by digit (r_of below v < 2^12, where its estimate of the fraction is loose) */
static int32_t r_of_digits(uint32_t v)
{
    uint32_t root = 0, rem = 0;
    int i = 30;
    if (v == 0u)
    {
        return 0; /* an empty pixel (most of a VLP-16 image's sky) */
    }
    while (i > 0 && (v >> i) == 0u)
    {
        i -= 2; /* a leading zero digit pair leaves root and remainder 0 */
    }
    for (; i > 30 - 2 * R_DIGITS; i -= 2)
    {
        r_digit(r_bits(v, i), &root, &rem);
    }
    return (int32_t)(root + (uint32_t)(rem > root));
}

/* R of one pixel, the same value as r_of_digits (round(sqrt(v 2^16)) for v < 2^31) in a fraction of its
 * instructions on cores with a divide instruction (the pixel-by-pixel rows of the firmware and the veto's
 * occasional test): s = floor(sqrt(v)) (lidet__q_isqrt32_inl: Newton's iteration in 32-bit integers), then the
 * root's 8 fraction bits f from the remainder D = v - s^2 and the exact test (256 s + f)^2 <= 2^16 v, i.e.
 * f (512 s + f) <= 2^16 D, in 64-bit products. The estimate 128 D / s is never below f (f 512 s <= 2^16 D) and
 * exceeds it by at most 255^2 / (512 s) + 1 < 3 for s >= 64: at most three steps down.
 * tests/python/test_ground_q.py compares it with Python's exact integer root */
#if !LIDET_Q_HAVE_DIV
/* no divide instruction (ARMv6-M: Cortex-M0+; RV32 without M): a library division would cost more than the digits */
static int32_t r_of(uint32_t v)
{
    return r_of_digits(v);
}
#else
static int32_t r_of(uint32_t v)
{
    uint32_t s, d, f;
    uint64_t lhs, rhs;
    if (v < (1u << 12))
    {
        return r_of_digits(v);
    }
    s = lidet__q_isqrt32_inl(v); /* >= 64 */
    d = v - s * s;               /* <= 2 s < 2^17 */
    f = (128u * d) / s;          /* 128 d < 2^24 */
    f = f < 255u ? f : 255u;     /* the root is below 256 (s + 1) */
    rhs = (uint64_t)d << 16;
    lhs = (uint64_t)f * (512u * s + f);
    while (lhs > rhs)
    {
        --f;
        lhs = (uint64_t)f * (512u * s + f);
    }
    /* round half up: the remainder 2^16 v - (256 s + f)^2 against the floor root */
    return (int32_t)(256u * s + f + (uint32_t)(rhs - lhs > 256u * s + f));
}
#endif

int32_t lidet__ground_q_r(uint32_t v)
{
    return r_of(v);
}

/* x^2 + y^2 of a pixel (4 mm steps squared; < 2^31 for int16 values) */
static inline uint32_t rxy2(const int16_t *x, const int16_t *y, uint32_t p)
{
    return (uint32_t)((int32_t)x[p] * x[p]) + (uint32_t)((int32_t)y[p] * y[p]);
}

/* x^2 + y^2 of row r's pixels into v (an image that stores x, y, z) */
static void row_rxy2(const lidet_range_image_t *img, uint32_t r, uint32_t *restrict v)
{
    const uint32_t cols = img->n_cols, base = r * cols;
    const int16_t *x = img->x_4mm + base, *y = img->y_4mm + base;
    uint32_t c;
    for (c = 0; c < cols; ++c)
    {
        v[c] = rxy2(x, y, c);
    }
}

/* R of a range-only image's pixel: its range times the cosine of its row's elevation (ce, Q15), in R steps
 * (4 mm / 2^8), rounded half up: round(rng ce / 2^7). The horizontal distance of the decoded point without the
 * square root (the decoded x, y are this ray's, rounded to 4 mm steps); rng < 2^15 and 0 <= ce <= 2^15, so the
 * product fits 32 bits. lidet_ref/ground_q.py: r_of_range */
static inline int32_t r_of_range(uint32_t rng, int32_t ce)
{
    return (int32_t)(((rng & 0x7FFFu) * (uint32_t)ce + 64u) >> 7);
}

/* R of pixel p (x^2 + y^2 = v) on a row of trig rt: from the range in a range-only image, else from v */
static inline int32_t r_pixel(const lidet_range_image_t *img, lidet__qpix_row_t rt, uint32_t p, uint32_t v)
{
    return lidet__qpix_range_only(img) ? r_of_range(img->range_4mm[p], rt.ce) : r_of(v);
}

/* R of a whole row r, digit step by digit step over the columns (the same values as r_of, but the column
 * loops are independent lanes that a compiler vectorises); v, rem: scratch of cols entries */
static void r_of_row(const lidet_range_image_t *img, uint32_t r, int32_t *restrict out, uint32_t *restrict v,
                     uint32_t *restrict rem)
{
    uint32_t *restrict root = (uint32_t *)out;
    const uint32_t cols = img->n_cols;
    uint32_t c;
    int i;
    row_rxy2(img, r, v);
#if !LIDET_GROUND_Q_SQRT_LANES
    (void)root;
    (void)rem;
    for (c = 0; c < cols; ++c)
    {
        out[c] = r_of(v[c]);
    }
    return;
#endif
    for (c = 0; c < cols; ++c)
    {
        root[c] = 0u;
        rem[c] = 0u;
    }
    for (i = 30; i > 30 - 2 * R_DIGITS; i -= 2)
    {
        for (c = 0; c < cols; ++c)
        {
            r_digit(r_bits(v[c], i), &root[c], &rem[c]);
        }
    }
    for (c = 0; c < cols; ++c)
    {
        root[c] += (uint32_t)(rem[c] > root[c]);
    }
}

/* R and z of a range-only image's row r, columns [ca, cb), in one pass over its ranges (z as lidet__qpix_decode
 * gives it) */
static inline void rz_of_range_span(const lidet_range_image_t *img, uint32_t r, uint32_t ca, uint32_t cb,
                                    int32_t *restrict out, int16_t *restrict z)
{
    const uint32_t cols = img->n_cols;
    const uint16_t *rng = img->range_4mm + (size_t)r * cols;
    const lidet__qpix_row_t rt = lidet__qpix_row(img, r);
    uint32_t c;
#if LIDET_GROUND_Q_SMMULR
    if (rt.ce >= 0)
    {
        /* r_of_range = (d ce + 2^6) >> 7 and rs15(d se) as SMMULR of d 2^16 and ce 2^9, 2 se (ce <= 2^15) */
        const int32_t ce9 = rt.ce * 512, se2 = rt.se * 2;
        for (c = ca; c < cb; ++c)
        {
            const int32_t d16 = (int32_t)((rng[c] & 0x7FFFu) << 16);
            out[c] = lidet__ground_q_smmulr(d16, ce9);
            z[c] = (int16_t)lidet__ground_q_smmulr(d16, se2);
        }
        return;
    }
#endif
    for (c = ca; c < cb; ++c)
    {
        const uint32_t d = rng[c] & 0x7FFFu;
        out[c] = r_of_range(d, rt.ce);
        z[c] = (int16_t)lidet__qpix_rs15((int32_t)d * rt.se);
    }
}

/* the whole row */
static void rz_of_range_row(const lidet_range_image_t *img, uint32_t r, int32_t *restrict out,
                            int16_t *restrict z)
{
    rz_of_range_span(img, r, 0u, img->n_cols, out, z);
}

/* R (and, in a range-only image, z) of row r into slot r % 2 (once per row) */
typedef struct
{
    const lidet_range_image_t *img;
    int32_t *slot[2];
    int16_t *zslot[2]; /* range-only image: the rows' z (over the square root's work rows, unused there) */
    uint32_t *v, *rem;
    int32_t row_in[2];
} r_rows_t;

static void r_rows_init(r_rows_t *rr, lidet_ground_q_scratch_t *sc, const lidet_range_image_t *img)
{
    rr->img = img;
    rr->slot[0] = sc->r_rows[0];
    rr->slot[1] = sc->r_rows[1];
    rr->zslot[0] = sc->r_v.z[0];
    rr->zslot[1] = sc->r_v.z[1];
    rr->v = sc->r_v.v;
    rr->rem = sc->r_rem;
    rr->row_in[0] = rr->row_in[1] = -1;
}

static const int32_t *r_row(r_rows_t *rr, uint32_t r)
{
    const uint32_t k = r & 1u;
    if (rr->row_in[k] != (int32_t)r)
    {
        if (lidet__qpix_range_only(rr->img))
        {
            rz_of_range_row(rr->img, r, rr->slot[k], rr->zslot[k]);
        }
        else
        {
            r_of_row(rr->img, r, rr->slot[k], rr->v, rr->rem);
        }
        rr->row_in[k] = (int32_t)r;
    }
    return rr->slot[k];
}

/* z of row r after r_row(rr, r): the image's row, or the range-only image's decoded one in slot r % 2 */
static const int16_t *z_row(const r_rows_t *rr, uint32_t r)
{
    return lidet__qpix_range_only(rr->img) ? rr->zslot[r & 1u] : rr->img->z_4mm + (size_t)r * rr->img->n_cols;
}

static inline int32_t abs32(int32_t v)
{
    return v < 0 ? -v : v;
}

/* |v| as an unsigned value: zero-extended to 64 bits by a compiler that sign-extends abs32's */
static inline uint32_t uabs32(int32_t v)
{
    return v < 0 ? 0u - (uint32_t)v : (uint32_t)v;
}

/* Pass 1 (lidet_ref/ground_q.py: sample_mask): the sample test of lidet_ground_filter.c with integer kernels.
 * dR in R steps (4 mm / 256), dZ in 4 mm: |dZ| <= fy |dR| is |dZ| * 2^24 <= fy_q16 * |dR|; F_x on R against
 * fx_max_mm * 64 (R steps), on Z as 4 |F_x| <= fx_max_mm. Every touched pixel holds a point (R > 0). Bitwise &
 * and no branch, as the float kernel: the column loop vectorises. */
static inline uint8_t sample_test(const int32_t *R0, const int32_t *R1, const int16_t *Z0, const int16_t *Z1,
                                  uint32_t cm1, uint32_t c, uint32_t cp1, uint32_t cp2,
                                  const lidet__ground_q_filt_t *f)
{
    const int32_t dr = (2 * R0[c] + R0[cp1]) - (2 * R1[c] + R1[cp1]);
    const int32_t dz = (2 * Z0[c] + Z0[cp1]) - (2 * Z1[c] + Z1[cp1]);
    const int32_t fxr = (R0[cm1] + 2 * R0[c]) - (2 * R0[cp1] + R0[cp2]);
    const int32_t fxz = (Z0[cm1] + 2 * Z0[c]) - (2 * Z0[cp1] + Z0[cp2]);
    const int pts = (R0[cm1] > 0) & (R0[c] > 0) & (R0[cp1] > 0) & (R0[cp2] > 0) & (R1[c] > 0) & (R1[cp1] > 0);
    const int fy = ((uint64_t)(uint32_t)abs32(dz) << 24) <= f->fy * (uint32_t)abs32(dr);
    const int fx = f->on_z ? 4 * abs32(fxz) <= f->fx_mm : abs32(fxr) <= f->fx_r;
    const int opt =
        ((f->desc == 0) | (dr > 0)) & ((f->gate == 0) | ((4 * Z0[c] >= f->z_lo) & (4 * Z0[c] <= f->z_hi)));
    return (uint8_t)(pts & fy & fx & opt);
}

/* The same test, leaving at the first condition that fails (cores without SIMD, where the branch-free form
 * costs every test on every pixel: most of a VLP-16 image's upper rows are empty and its obstacles fail the
 * slope test). The cheap tests first: the six pixels hold points, then the descending and height conditions,
 * the slope F_y, the horizontal F_x. */
#if defined(__GNUC__)
__attribute__((always_inline)) /* a call per pixel (nine arguments) cost as much as the test itself */
#endif
static inline uint8_t
sample_test_early(const int32_t *R0, const int32_t *R1, const int16_t *Z0, const int16_t *Z1, uint32_t cm1,
                  uint32_t c, uint32_t cp1, uint32_t cp2, const lidet__ground_q_filt_t *f)
{
    int32_t dr, dz;
    if (R0[c] <= 0 || R1[c] <= 0 || R0[cp1] <= 0 || R1[cp1] <= 0 || R0[cm1] <= 0 || R0[cp2] <= 0)
    {
        return 0;
    }
    dr = (2 * R0[c] + R0[cp1]) - (2 * R1[c] + R1[cp1]);
    if ((f->desc != 0 && dr <= 0) || (f->gate != 0 && (4 * Z0[c] < f->z_lo || 4 * Z0[c] > f->z_hi)))
    {
        return 0;
    }
    dz = (2 * Z0[c] + Z0[cp1]) - (2 * Z1[c] + Z1[cp1]);
    if (((uint64_t)(uint32_t)abs32(dz) << 24) > f->fy * (uint32_t)abs32(dr))
    {
        return 0;
    }
    if (f->on_z)
    {
        return (uint8_t)(4 * abs32((Z0[cm1] + 2 * Z0[c]) - (2 * Z0[cp1] + Z0[cp2])) <= f->fx_mm);
    }
    return (uint8_t)(abs32((R0[cm1] + 2 * R0[c]) - (2 * R0[cp1] + R0[cp2])) <= f->fx_r);
}

/* The early-exit test with the default switches (no descending condition, no height gate, F_x on R): the
 * configuration's values in registers, fy (<= 655360, init) as a 32-bit factor of one 32 x 32 -> 64 product */
#if defined(__GNUC__)
__attribute__((always_inline))
#endif
static inline uint8_t
sample_test_plain(const int32_t *R0, const int32_t *R1, const int16_t *Z0, const int16_t *Z1, uint32_t cm1,
                  uint32_t c, uint32_t cp1, uint32_t cp2, uint32_t fy, int32_t fx_r)
{
    const int32_t r0 = R0[c], r1 = R1[c], r0p = R0[cp1], r1p = R1[cp1];
    int32_t dr, dz;
    if (r0 <= 0 || r1 <= 0 || r0p <= 0 || r1p <= 0 || R0[cm1] <= 0 || R0[cp2] <= 0)
    {
        return 0;
    }
    dr = (2 * r0 + r0p) - (2 * r1 + r1p);
    dz = (2 * Z0[c] + Z0[cp1]) - (2 * Z1[c] + Z1[cp1]);
#if LIDET_Q_HAVE_MUL64
    if (((uint64_t)uabs32(dz) << 24) > lidet__q_umul32(fy, uabs32(dr)))
#else
    if (lidet__ground_q_shl24_gt(uabs32(dz), fy, uabs32(dr))) /* the 64-bit product only near the threshold */
#endif
    {
        return 0;
    }
    return (uint8_t)(abs32((R0[cm1] + 2 * r0) - (2 * r0p + R0[cp2])) <= fx_r);
}

#if defined(__GNUC__)
__attribute__((noinline)) /* fy a plain 32-bit argument: one 32 x 32 -> 64 multiply (inlined, the compiler's
                           * range of the caller's uint64_t made it a 64 x 64 one) */
#endif
static void
sample_row_plain(const int32_t *R0, const int32_t *R1, const int16_t *Z0, const int16_t *Z1, uint32_t cols,
                 const lidet__ground_q_filt_t *f, uint8_t *out)
{
    const uint32_t fy = (uint32_t)f->fy;
    const int32_t fx_r = f->fx_r;
    uint32_t c;
    out[0] = sample_test_plain(R0, R1, Z0, Z1, cols - 1u, 0u, 1u, 2u, fy, fx_r);
    for (c = 1; c + 2u < cols; ++c)
    {
        out[c] = sample_test_plain(R0, R1, Z0, Z1, c - 1u, c, c + 1u, c + 2u, fy, fx_r);
    }
    out[cols - 2u] = sample_test_plain(R0, R1, Z0, Z1, cols - 3u, cols - 2u, cols - 1u, 0u, fy, fx_r);
    out[cols - 1u] = sample_test_plain(R0, R1, Z0, Z1, cols - 2u, cols - 1u, 0u, 1u, fy, fx_r);
}

/* one row pair's tests into out[0 .. cols), columns wrapping around; early: the kernel (a constant where
 * inlined) */
static inline void sample_row(const int32_t *R0, const int32_t *R1, const int16_t *Z0, const int16_t *Z1,
                              uint32_t cols, const lidet__ground_q_filt_t *f, uint8_t *out, const int early)
{
    uint32_t c;
#define SAMPLE_TEST(cm1, c0, cp1, cp2)                                                                       \
    (early ? sample_test_early(R0, R1, Z0, Z1, cm1, c0, cp1, cp2, f)                                         \
           : sample_test(R0, R1, Z0, Z1, cm1, c0, cp1, cp2, f))
    out[0] = SAMPLE_TEST(cols - 1u, 0u, 1u, 2u);
    for (c = 1; c + 2u < cols; ++c)
    {
        out[c] = SAMPLE_TEST(c - 1u, c, c + 1u, c + 2u);
    }
    out[cols - 2u] = SAMPLE_TEST(cols - 3u, cols - 2u, cols - 1u, 0u);
    out[cols - 1u] = SAMPLE_TEST(cols - 2u, cols - 1u, 0u, 1u);
#undef SAMPLE_TEST
}

void lidet__ground_q_sample_row(const int32_t *R0, const int32_t *R1, const int16_t *Z0, const int16_t *Z1,
                                uint32_t cols, const lidet__ground_q_filt_t *f, uint8_t *out, int early)
{
    if (early && !f->on_z && !f->desc && !f->gate && f->fy <= 0xFFFFFFFFu)
    {
        sample_row_plain(R0, R1, Z0, Z1, cols, f, out);
    }
    else if (early)
    {
        sample_row(R0, R1, Z0, Z1, cols, f, out, 1);
    }
    else
    {
        sample_row(R0, R1, Z0, Z1, cols, f, out, 0);
    }
}

/* the sample test's thresholds in the integer units */
static void filt_setup(const lidet_ground_q_state_t *g, lidet__ground_q_filt_t *f)
{
    f->fy = g->cfg.fy_max_q16;
    f->fx_r = (int32_t)g->cfg.fx_max_mm * (1 << (LIDET_GROUND_Q_R_SHIFT - 2)); /* mm in R steps */
    f->fx_mm = (int32_t)g->cfg.fx_max_mm;
    f->on_z = g->cfg.fx_on_z;
    f->desc = g->cfg.require_descending;
    f->gate = g->cfg.height_gate;
    f->z_lo = -g->cfg.mount_height_mm - g->cfg.gate_below_mm;
    f->z_hi = -g->cfg.mount_height_mm + g->cfg.gate_above_mm;
}

static void filter_rows(const lidet_ground_q_state_t *g, lidet_ground_q_scratch_t *sc, r_rows_t *rr,
                        const lidet_range_image_t *img)
{
    uint8_t *sample = sc->sample;
    const uint32_t rows = img->n_rows, cols = img->n_cols, step = g->cfg.sample_step;
    lidet__ground_q_filt_t f;
    uint32_t r;
    filt_setup(g, &f);
    /* the rows no pair writes (the last, and those off the step grid) cleared; the others are written whole */
    for (r = 0; r < rows; ++r)
    {
        if (r + 1u >= rows || r % step != 0u)
        {
            memset(sample + (size_t)r * cols, 0, cols);
        }
    }
    for (r = 0; r + 1u < rows; r += step)
    {
        const int32_t *R0 = r_row(rr, r), *R1 = r_row(rr, r + 1u);
        const int16_t *Z0 = z_row(rr, r), *Z1 = z_row(rr, r + 1u);
        lidet__ground_q_sample_row(R0, R1, Z0, Z1, cols, &f, sample + (size_t)r * cols,
                                   !LIDET_GROUND_Q_SQRT_LANES);
    }
}

/* Pass 2 (lidet_ref/ground_q.py: gather_samples): the samples of the step grid grouped by cell, near ones from the
 * buffer's start upwards, far ones from its end downwards (the float stage's order); past the buffer they are
 * dropped and counted. Sector s's samples at the cursors *lo, *hi (counted in *total); gather_samples runs the
 * sectors in order, the streamed run one at a time. */
#if defined(__GNUC__)
__attribute__((always_inline))
#endif
static inline void
gather_sector(const lidet_ground_q_state_t *g, lidet_ground_q_scratch_t *sc, const lidet__ground_q_pix_t *gp,
              uint32_t s, uint32_t *lo_io, uint32_t *hi_io, uint32_t *total_io)
{
    const lidet_range_image_t *img = gp->img;
    const uint32_t rows = img->n_rows, cols = img->n_cols, ns = g->cfg.n_sectors, step = g->cfg.sample_step;
    const uint32_t cstep = g->cfg.sample_col_step, split_v = g->split_v;
    lidet_ground_sample_t *const si = sc->sample_pix;
    const uint32_t c0 = lidet__ground_sector_col(s, ns, cols),
                   c1 = lidet__ground_sector_col(s + 1u, ns, cols);
    uint32_t r, c, lo = *lo_io, hi = *hi_io, total = *total_io;
    const uint32_t near_start = lo, far_end = hi;
    for (r = 0; r + 1u < rows; r += step)
    {
        const uint32_t base = r * cols;
        const lidet__qpix_row_t rt = lidet__qpix_row(img, r);
        for (c = c0 + (cstep - c0 % cstep) % cstep; c < c1; c += cstep)
        {
            if (sc->sample[base + c] != 0u)
            {
                ++total;
                if (lo < hi)
                {
                    int far = 0;
                    if (split_v != 0xFFFFFFFFu) /* else every sample is near (x^2 + y^2 < 2^31) */
                    {
                        int32_t q[3];
                        lidet__ground_q_pix_rc(gp, rt, c, base + c, q);
                        far = (uint32_t)(q[0] * q[0]) + (uint32_t)(q[1] * q[1]) >= split_v;
                    }
                    si[far ? --hi : lo++] = (lidet_ground_sample_t)(base + c);
                }
            }
        }
    }
    lidet__ground_cell_span(sc->cell_first, sc->cell_n, s, ns, near_start, lo, hi, far_end);
    *lo_io = lo;
    *hi_io = hi;
    *total_io = total;
}

static void gather_samples(lidet_ground_q_state_t *g, lidet_ground_q_scratch_t *sc,
                           const lidet__ground_q_pix_t *gp)
{
    uint32_t s, lo = 0, hi = LIDET_GROUND_MAX_SAMPLES, total = 0;
    for (s = 0; s < g->cfg.n_sectors; ++s)
    {
        gather_sector(g, sc, gp, s, &lo, &hi, &total);
    }
    lidet__ground_sample_counts(&g->stats, total, lo, hi);
}

/* ---- the band test from the hi part (LIDET_GROUND_Q_BAND32, lidet_ground_q_internal.h) ---- */
static int64_t clip32(int64_t v)
{
    return v < INT32_MIN ? INT32_MIN : (v > INT32_MAX ? INT32_MAX : v);
}

/* lidet_ground_q_internal.h */
void lidet__ground_q_band(const int32_t lo[3], int64_t d, uint64_t t, unsigned sh, lidet__ground_q_band_t *b)
{
    const int64_t bmax = ((int64_t)uabs32(lo[0]) + uabs32(lo[1]) + uabs32(lo[2])) * 32768;
    const int64_t tt = (int64_t)t;
    /* floors of quotients by 2^sh as arithmetic shifts, as the stage's other shifts of signed values;
     * possibly in: a 2^sh + D + B >= 0 and a 2^sh + D - B <= t */
    const int64_t plo = -((d + bmax) >> sh), phi = (tt - d + bmax) >> sh;
    /* surely in: a 2^sh + D - B >= 0 and a 2^sh + D + B <= t */
    const int64_t ilo = -((d - bmax) >> sh), ihi = (tt - d - bmax) >> sh;
    const int64_t pl = clip32(plo), ph = clip32(phi);
    const int64_t il = clip32(ilo), ih = clip32(ihi);
    if (pl > ph || plo > INT32_MAX || phi < INT32_MIN)
    {
        b->pos_lo = 0; /* nothing possibly in: a = 0 alone goes on, to the exact test */
        b->pos_span = 0u;
    }
    else
    {
        b->pos_lo = (int32_t)pl;
        b->pos_span = (uint32_t)(ph - pl);
    }
    if (il > ih || ilo > INT32_MAX || ihi < INT32_MIN)
    {
        b->in_lo = 0;
        b->in_n = 0u;
    }
    else
    {
        b->in_lo = (int32_t)il;
        b->in_n = ih - il + 1 > (int64_t)0xFFFFFFFFu ? 0xFFFFFFFFu
                                                     : (uint32_t)(ih - il + 1); /* one a fewer: exact */
    }
}

/* Pass 3 (lidet_ref/ground_q.py: label_pixels): ground = holds a point, -below < h < above with h = n . p + D in
 * 4 mm / 2^30 (the tolerances in mm are exact in that unit: 1 mm = 2^28), and not vetoed: the pixel above
 * (row - 1) holds a point, 4 |dz| > veto_min_dz_mm and |dz| * 2^24 > veto_slope_q16 * |dR|. R is computed only
 * where a test needs it: the veto's slope test of an in-band pixel with a step of more than veto_min_dz_mm
 * (rare on the ground), or every pixel with a tolerance growing with range. */
/* the labelling's constants and counts */
typedef struct
{
    const lidet_range_image_t *img;
    const lidet__ground_q_pix_t *gp;
    uint8_t *mask;
    int32_t *z_up; /* per column: z of the pixel above (row r - 1), NO_POINT where it holds none */
    int64_t above0, below0, bf, slope, k;
    uint64_t band; /* above0 + below0 - 1: the fixed tolerance's band, one unsigned comparison (label_span) */
    int32_t min_dz;
    uint32_t split_v, split2_v, n_ground, n_vetoed;
} label_t;

/* a sector's third-cell plane (split2_v < UINT32_MAX): its pixels' height in 64 bits, the same exact n . p */
typedef struct
{
    int32_t n[3];
    int64_t d;
} far2_plane_t;

#define NO_POINT INT32_MIN /* z_up of an empty pixel (a decoded z is within +-2^15) */

/* the veto's slope test of an in-band pixel p whose step to the pixel above exceeds veto_min_dz_mm (R is needed
 * only then): |dz| * 2^24 > veto_slope_q16 * |R(above) - R(p)| */
#if defined(__GNUC__)
__attribute__((noinline)) /* off the labelling loop: its registers stay for the common pixel */
#endif
static int
veto_slope(const label_t *L, lidet__qpix_row_t rt, lidet__qpix_row_t rtu, uint32_t c, uint32_t p, uint32_t up,
           uint32_t v, int32_t dz)
{
    uint32_t vu = 0;
    if (!lidet__qpix_range_only(L->img))
    {
        /* x^2 + y^2 of the pixel above, for its R (a range-only image's R needs its range alone) */
        int32_t U[3];
        lidet__ground_q_pix_rc(L->gp, rtu, c, p - up, U);
        vu = (uint32_t)(U[0] * U[0]) + (uint32_t)(U[1] * U[1]);
    }
    return ((int64_t)dz << 24) >
           L->slope * abs32(r_pixel(L->img, rtu, p - up, vu) - r_pixel(L->img, rt, p, v));
}

/* Columns [c0, c1) of row r (base = r cols) against one cell pair's planes hp (two: far pixels take hp[1]; a
 * constant where inlined, as is ro, the range-only image). ground = holds a point, -below < h < above with
 * h = n . p + D, not vetoed; each pixel's z (or NO_POINT) replaces the pixel above's in z_up for the next row. */
#if defined(__GNUC__)
__attribute__((always_inline))
#endif
static inline void
label_span(label_t *L, uint32_t c0, uint32_t c1, uint32_t base, uint32_t up, lidet__qpix_row_t rt,
           lidet__qpix_row_t rtu, const lidet__ground_q_hplane_t *hp, const lidet__ground_q_band_t *bd,
           const far2_plane_t *f2, const int two, const int ro, const int kz)
{
    const uint16_t *rng = L->img->range_4mm;
    const int32_t *ct = L->gp->ct, *st = L->gp->st;
#if LIDET_GROUND_Q_SMMULR
    const lidet__ground_q_rows_t rts = lidet__ground_q_rows(rt);
#endif
    int32_t *z_up = L->z_up;
    uint8_t *mask = L->mask;
    const int64_t above0 = L->above0, below0 = L->below0;
    uint32_t c, n_ground = 0, n_vetoed = 0;
    for (c = c0; c < c1; ++c)
    {
        const uint32_t p = base + c;
        const int32_t zu = z_up[c];
        int32_t P[3];
        uint32_t v;
        int64_t h, above = above0, below = below0;
        int in, nz, vt = 0;
        if (ro)
        {
            const uint32_t r15 = rng[p] & 0x7FFFu;
            if (r15 == 0u)
            {
                mask[p] = 0; /* an empty pixel (x = y = 0): never ground, never vetoed */
                z_up[c] = NO_POINT;
                continue;
            }
#if LIDET_GROUND_Q_SMMULR
            lidet__ground_q_decode_r16((int32_t)(r15 << 16), rts, ct[c], st[c], P);
#else
            lidet__qpix_decode(rng[p], rt, ct[c], st[c], P);
#endif
        }
        else
        {
            lidet__qpix_stored(L->img, p, P);
        }
        nz = (P[0] | P[1]) != 0; /* x^2 + y^2 != 0 */
        if (kz && !nz)
        {
            mask[p] = 0; /* x = y = 0: not in the band, never vetoed, no point above the next row's */
            z_up[c] = NO_POINT;
            continue;
        }
        v = (uint32_t)(P[0] * P[0]) + (uint32_t)(P[1] * P[1]);
        if (LIDET_GROUND_Q_BAND32 && kz && !two)
        {
            h = 0; /* the band test below, from the 32-bit hi part where that decides */
        }
        else if (two && v >= L->split2_v)
        {
            h = (int64_t)f2->n[0] * P[0] + (int64_t)f2->n[1] * P[1] + (int64_t)f2->n[2] * P[2] + f2->d;
        }
        else
        {
            h = lidet__ground_q_height(&hp[two && v >= L->split_v], P[0], P[1], P[2]);
        }
        if (!kz && L->k != 0)
        {
            /* R steps are 1/64 mm: k R / 2^16 mm = (k R) << 6 in 4 mm / 2^30 */
            above = L->above0 + ((L->k * r_pixel(L->img, rt, p, v)) << 6);
            below = lidet__q_rshift_round(L->bf * above, 16);
        }
        if (kz)
        {
            /* -below0 < h < above0 as 0 <= h + below0 - 1 < above0 + below0 - 1: the planes' D carries
             * below0 - 1 (label_rows) */
            in = LIDET_GROUND_Q_BAND32 && !two
                     ? lidet__ground_q_in_band(&hp[0], bd, L->band - 1u, P[0], P[1], P[2])
                     : (uint64_t)h < L->band; /* nz here */
        }
        else
        {
            in = nz & (h < above) & (h > -below);
        }
        z_up[c] = nz ? P[2] : NO_POINT;
        if (in && zu != NO_POINT)
        {
            /* the pixel above holds a point: the veto (a step of more than veto_min_dz_mm, then the slope) */
            const int32_t dz = abs32(zu - P[2]);
            if ((4 * dz > L->min_dz) & (L->slope > 0))
            {
                if (ro)
                {
                    /* veto_slope's test with the two ranges' R in line (veto_slope_q16 <= 6553600, init: the
                     * product one 32 x 32 -> 64 multiply) */
                    const int32_t dr = r_of_range(rng[p - up], rtu.ce) - r_of_range(rng[p], rt.ce);
                    vt = ((uint64_t)(uint32_t)dz << 24) > lidet__q_umul32((uint32_t)L->slope, uabs32(dr));
                }
                else
                {
                    vt = veto_slope(L, rt, rtu, c, p, up, v, dz);
                }
            }
        }
        mask[p] = (uint8_t)(in & !vt);
        n_ground += (uint32_t)(in & !vt);
        n_vetoed += (uint32_t)vt;
    }
    L->n_ground += n_ground;
    L->n_vetoed += n_vetoed;
}

/* the near / far (/ third) cells' kernels, out of label_rows: their frame is not on the stack of the 16-beam
 * images, which have one plane per sector (the two-cell copies spilled more on ARMv6-M) */
#if defined(__GNUC__)
__attribute__((noinline))
#endif
static void
label_span_two(label_t *L, uint32_t c0, uint32_t c1, uint32_t base, uint32_t up, lidet__qpix_row_t rt,
               lidet__qpix_row_t rtu, const lidet__ground_q_hplane_t *hp, int ro,
               const lidet_ground_q_state_t *g, uint32_t s)
{
    far2_plane_t f2;
    f2.n[0] = 0;
    f2.n[1] = 0;
    f2.n[2] = 0;
    f2.d = 0;
    if (L->split2_v != 0xFFFFFFFFu)
    {
        const uint32_t k = 2u * g->cfg.n_sectors + s;
        f2.n[0] = g->planes[k].nx;
        f2.n[1] = g->planes[k].ny;
        f2.n[2] = g->planes[k].nz;
        f2.d = g->plane_d[k];
    }
    if (ro)
    {
        label_span(L, c0, c1, base, up, rt, rtu, hp, 0, &f2, 1, 1, 0);
    }
    else
    {
        label_span(L, c0, c1, base, up, rt, rtu, hp, 0, &f2, 1, 0, 0);
    }
}

/* the labelling's constants, its counts at 0 (z_up: the free row of R, cols entries, set by the caller) */
static void label_setup(label_t *L, const lidet_ground_q_state_t *g, lidet_ground_q_scratch_t *sc,
                        uint8_t *mask, const lidet__ground_q_pix_t *gp)
{
    L->img = gp->img;
    L->gp = gp;
    L->mask = mask;
    L->z_up = sc->r_rows[0]; /* free after the fits */
    L->above0 = (int64_t)g->cfg.ground_mm << 28;
    L->k = g->cfg.ground_per_m_q16;
    L->bf = g->cfg.below_factor_q16;
    L->slope = g->cfg.veto_slope_q16;
    L->below0 = lidet__q_rshift_round(L->bf * L->above0, 16);
    L->band = (uint64_t)(L->above0 + L->below0 - 1); /* above0 >= 2^28, below0 >= 0 */
    L->min_dz = (int32_t)g->cfg.veto_min_dz_mm;
    L->split_v = g->split_v;
    L->split2_v = g->split2_v;
    L->n_ground = 0;
    L->n_vetoed = 0;
}

/* row r of sector s (z_up holds row r - 1's z of the sector's columns; rt, rtu: rows r and r - 1's trig; two: near
 * and far cells; ro: a range-only image) */
#if defined(__GNUC__)
__attribute__((always_inline))
#endif
static inline void
label_cell(label_t *L, const lidet_ground_q_state_t *g, uint32_t r, uint32_t s, lidet__qpix_row_t rt,
           lidet__qpix_row_t rtu, const int two, const int ro)
{
    const lidet_range_image_t *img = L->img;
    const uint32_t cols = img->n_cols, ns = g->cfg.n_sectors;
    const uint32_t base = r * cols, up = r > 0u ? cols : 0u;
    const uint32_t c0 = lidet__ground_sector_col(s, ns, cols),
                   c1 = lidet__ground_sector_col(s + 1u, ns, cols);
    lidet__ground_q_hplane_t hp[2];
    uint32_t c;
    for (c = 0; c < 2u; ++c)
    {
        const lidet_plane_q_t *pl = &g->planes[c * ns + s];
        int32_t nn[3];
        nn[0] = pl->nx;
        nn[1] = pl->ny;
        nn[2] = pl->nz;
        lidet__ground_q_hplane(nn, g->plane_d[c * ns + s], &hp[c]);
    }

    /* the kernels: near and far cells or one, range-only image or stored x, y, z; a range-only image's also with
     * the fixed tolerance (ground_per_m_q16 0) as a constant */
    if (two)
    {
        label_span_two(L, c0, c1, base, up, rt, rtu, hp, ro, g, s);
    }
    else if (ro)
    {
        if (L->k == 0)
        {
            lidet__ground_q_band_t bd;
            hp[0].d += L->below0 - 1; /* the band test's offset (label_span, kz) */
            if (LIDET_GROUND_Q_BAND32)
            {
                lidet__ground_q_band(hp[0].lo, hp[0].d, L->band - 1u, 15u, &bd);
            }
            label_span(L, c0, c1, base, up, rt, rtu, hp, &bd, 0, 0, 1, 1);
        }
        else
        {
            label_span(L, c0, c1, base, up, rt, rtu, hp, 0, 0, 0, 1, 0);
        }
    }
    else
    {
        label_span(L, c0, c1, base, up, rt, rtu, hp, 0, 0, 0, 0, 0);
    }
}

static void label_rows(lidet_ground_q_state_t *g, lidet_ground_q_scratch_t *sc, uint8_t *mask,
                       const lidet__ground_q_pix_t *gp)
{
    const uint32_t rows = gp->img->n_rows, cols = gp->img->n_cols, ns = g->cfg.n_sectors;
    const int two = g->split_v != 0xFFFFFFFFu, ro = gp->ct != 0;
    label_t L;
    uint32_t r, s, c;
    label_setup(&L, g, sc, mask, gp);
    for (c = 0; c < cols; ++c)
    {
        L.z_up[c] = NO_POINT; /* row 0 has no pixel above: never vetoed */
    }
    for (r = 0; r < rows; ++r)
    {
        const lidet__qpix_row_t rt = lidet__qpix_row(gp->img, r),
                                rtu = lidet__qpix_row(gp->img, r > 0u ? r - 1u : 0u);
        for (s = 0; s < ns; ++s)
        {
            label_cell(&L, g, r, s, rt, rtu, two, ro);
        }
    }
    g->stats.n_ground = L.n_ground;
    g->stats.n_vetoed = L.n_vetoed;
}

lidet_status_t lidet_ground_q_run_buffers(lidet_ground_q_state_t *g, lidet_ground_q_scratch_t *scratch,
                                          uint8_t *mask, const lidet_range_image_t *img)
{
    lidet__ground_q_pix_t gp;
    r_rows_t rr;
    lidet_status_t st;
    if (g == 0 || scratch == 0 || mask == 0 || img == 0)
    {
        return LIDET_ERR_ARG;
    }
    /* a compact image only: x, y, z in 4 mm steps */
    st = lidet__ground_run_check(g->magic == LIDET_INIT_MAGIC, lidet__qpix_image_ok(img), img,
                                 g->cfg.n_sectors, &g->stats);
    if (st != LIDET_OK)
    {
        return st;
    }
    g->n_rows = img->n_rows;
    g->n_cols = img->n_cols;
    g->rng = lidet__rng_seed(g->cfg.seed);
    r_rows_init(&rr, scratch, img);
    filter_rows(g, scratch, &rr, img);
    lidet__ground_q_pix_init(&gp, scratch, img); /* into the filter's scratch, free from here on */
    gather_samples(g, scratch, &gp);
    lidet__ground_q_fit_sectors(g, scratch, &gp);
    label_rows(g, scratch, mask, &gp);
    return g->stats.n_samples_dropped > 0u ? LIDET_TRUNCATED : LIDET_OK;
}

/* ---- the streamed run, sector by sector (lib/src/internal/lidet_ground_q_internal.h) ---------------------- */

/* R and z of row r's columns c0 - 1 .. c1 + 1 (wrapping around), the ones sector [c0, c1)'s sample tests read */
static void rz_of_sector(const lidet_range_image_t *img, uint32_t r, uint32_t c0, uint32_t c1, int32_t *out,
                         int16_t *z)
{
    const uint32_t cols = img->n_cols, end = c1 + 2u;
    rz_of_range_span(img, r, c0 > 0u ? c0 - 1u : 0u, end < cols ? end : cols, out, z);
    if (c0 == 0u)
    {
        rz_of_range_span(img, r, cols - 1u, cols, out, z);
    }
    if (end > cols)
    {
        rz_of_range_span(img, r, 0u, end - cols, out, z);
    }
}

/* the sample test of column c of a row pair (c - 1 .. c + 2 wrapping around), plain: the default switches */
#if defined(__GNUC__)
__attribute__((always_inline))
#endif
static inline uint8_t
sample_wrap(const int32_t *R0, const int32_t *R1, const int16_t *Z0, const int16_t *Z1, uint32_t c,
            uint32_t cols, const lidet__ground_q_filt_t *f, const int plain)
{
    const uint32_t cm1 = c > 0u ? c - 1u : cols - 1u, cp1 = c + 1u < cols ? c + 1u : c + 1u - cols,
                   cp2 = c + 2u < cols ? c + 2u : c + 2u - cols;
    return plain ? sample_test_plain(R0, R1, Z0, Z1, cm1, c, cp1, cp2, (uint32_t)f->fy, f->fx_r)
                 : sample_test_early(R0, R1, Z0, Z1, cm1, c, cp1, cp2, f);
}

/* the tests of columns [c0, c1) of one row pair: the columns whose neighbours do not wrap in a loop of their own */
#if defined(__GNUC__)
__attribute__((always_inline))
#endif
static inline void
sample_span(const int32_t *R0, const int32_t *R1, const int16_t *Z0, const int16_t *Z1, uint32_t c0,
            uint32_t c1, uint32_t cols, const lidet__ground_q_filt_t *f, uint8_t *out, const int plain)
{
    const uint32_t a = c0 > 0u ? c0 : 1u, b = c1 + 2u < cols ? c1 : cols - 2u;
    uint32_t c;
    for (c = c0; c < a && c < c1; ++c)
    {
        out[c] = sample_wrap(R0, R1, Z0, Z1, c, cols, f, plain);
    }
    for (c = a; c < b; ++c)
    {
        out[c] = plain
                     ? sample_test_plain(R0, R1, Z0, Z1, c - 1u, c, c + 1u, c + 2u, (uint32_t)f->fy, f->fx_r)
                     : sample_test_early(R0, R1, Z0, Z1, c - 1u, c, c + 1u, c + 2u, f);
    }
    for (c = b > a ? b : a; c < c1; ++c)
    {
        out[c] = sample_wrap(R0, R1, Z0, Z1, c, cols, f, plain);
    }
}

/* Pass 1 on sector s's columns alone (filter_rows' tests on them; the early-exit kernels, whose values are the
 * branch-free one's). R and z of a row are computed once (slot r % 2, as r_row's) */
static void filter_sector(const lidet_ground_q_state_t *g, lidet_ground_q_scratch_t *sc,
                          const lidet_range_image_t *img, uint32_t s)
{
    const uint32_t rows = img->n_rows, cols = img->n_cols, ns = g->cfg.n_sectors, step = g->cfg.sample_step;
    const uint32_t c0 = lidet__ground_sector_col(s, ns, cols),
                   c1 = lidet__ground_sector_col(s + 1u, ns, cols);
    lidet__ground_q_filt_t f;
    uint32_t r, k, have = 0xFFFFFFFFu; /* the row in the slot of parity have & 1 */
    filt_setup(g, &f);
    for (r = 0; r < rows; ++r)
    {
        memset(sc->sample + (size_t)r * cols + c0, 0, c1 - c0);
    }
    for (r = 0; r + 1u < rows; r += step)
    {
        uint8_t *out = sc->sample + (size_t)r * cols;
        for (k = r; k <= r + 1u; ++k)
        {
            if (k != have)
            {
                rz_of_sector(img, k, c0, c1, sc->r_rows[k & 1u], sc->r_v.z[k & 1u]);
            }
        }
        have = r + 1u;
        if (!f.on_z && !f.desc && !f.gate && f.fy <= 0xFFFFFFFFu) /* lidet__ground_q_sample_row's choice */
        {
            sample_span(sc->r_rows[r & 1u], sc->r_rows[(r + 1u) & 1u], sc->r_v.z[r & 1u],
                        sc->r_v.z[(r + 1u) & 1u], c0, c1, cols, &f, out, 1);
        }
        else
        {
            sample_span(sc->r_rows[r & 1u], sc->r_rows[(r + 1u) & 1u], sc->r_v.z[r & 1u],
                        sc->r_v.z[(r + 1u) & 1u], c0, c1, cols, &f, out, 0);
        }
    }
}

/* Pass 3 on sector s's columns alone (label_rows' kernels; the counts added to the stage's) */
static void label_sector(lidet_ground_q_state_t *g, lidet_ground_q_scratch_t *sc, uint8_t *mask,
                         const lidet__ground_q_pix_t *gp, uint32_t s)
{
    const uint32_t rows = gp->img->n_rows, cols = gp->img->n_cols, ns = g->cfg.n_sectors;
    const uint32_t c0 = lidet__ground_sector_col(s, ns, cols),
                   c1 = lidet__ground_sector_col(s + 1u, ns, cols);
    label_t L;
    uint32_t r, c;
    label_setup(&L, g, sc, mask, gp);
    for (c = c0; c < c1; ++c)
    {
        L.z_up[c] = NO_POINT;
    }
    for (r = 0; r < rows; ++r)
    {
        label_cell(&L, g, r, s, lidet__qpix_row(gp->img, r), lidet__qpix_row(gp->img, r > 0u ? r - 1u : 0u),
                   g->split_v != 0xFFFFFFFFu, gp->ct != 0);
    }
    g->stats.n_ground += L.n_ground;
    g->stats.n_vetoed += L.n_vetoed;
}

/* a sector not yet done by the streamed run (its near cell's source; the run's other sources are never this) */
#define STREAM_PENDING 0xFFu

lidet_status_t lidet__ground_q_stream_begin(lidet_ground_q_state_t *g, const lidet_range_image_t *img)
{
    lidet_status_t st;
    uint32_t s;
    if (g == 0 || img == 0)
    {
        return LIDET_ERR_ARG;
    }
    st = lidet__ground_run_check(g->magic == LIDET_INIT_MAGIC, lidet__qpix_image_ok(img), img,
                                 g->cfg.n_sectors, &g->stats);
    if (st != LIDET_OK)
    {
        return st;
    }
    if (!lidet__qpix_range_only(img) || !g->cfg.seed_per_cell)
    {
        return LIDET_ERR_CONFIG;
    }
    g->n_rows = img->n_rows;
    g->n_cols = img->n_cols;
    g->rng = lidet__rng_seed(g->cfg.seed);
    for (s = 0; s < g->cfg.n_sectors; ++s)
    {
        g->source[s] = STREAM_PENDING;
    }
    g->stream_lo = 0;
    g->stream_hi = LIDET_GROUND_MAX_SAMPLES;
    g->stream_total = 0;
    return LIDET_OK;
}

void lidet__ground_q_stream_sector(lidet_ground_q_state_t *g, lidet_ground_q_scratch_t *sc, uint8_t *mask,
                                   const lidet_range_image_t *img, uint32_t s)
{
    const uint32_t ns = g->cfg.n_sectors, cols = img->n_cols;
    lidet__ground_q_pix_t gp;
    if (s >= ns || g->source[s] != STREAM_PENDING)
    {
        return;
    }
    filter_sector(g, sc, img, s);
    /* the columns' tables over the filter's rows of z, dead from here on */
    lidet__ground_q_pix_span(&gp, sc, img, lidet__ground_sector_col(s, ns, cols),
                             lidet__ground_sector_col(s + 1u, ns, cols));
    gather_sector(g, sc, &gp, s, &g->stream_lo, &g->stream_hi, &g->stream_total);
    lidet__ground_q_fit_near(g, sc, &gp, s);
    if (g->source[s] == LIDET_GROUND_PLANE_FITTED)
    {
        /* its own plane: final, so the rest of the sector is too */
        lidet__ground_q_fit_rest(g, sc, &gp, s);
        label_sector(g, sc, mask, &gp, s);
    }
}

lidet_status_t lidet__ground_q_stream_end(lidet_ground_q_state_t *g, lidet_ground_q_scratch_t *sc,
                                          uint8_t *mask, const lidet_range_image_t *img)
{
    const uint32_t ns = g->cfg.n_sectors, cols = img->n_cols;
    lidet__ground_q_pix_t gp;
    uint32_t s;
    for (s = 0; s < ns; ++s)
    {
        lidet__ground_q_stream_sector(g, sc, mask, img, s);
    }
    /* the near cells without a plane of their own take their neighbours' (the planes themselves: no table) */
    gp.img = img;
    gp.ct = gp.st = 0;
    lidet__ground_q_fallback(g, sc, &gp);
    for (s = 0; s < ns; ++s)
    {
        if (g->source[s] != LIDET_GROUND_PLANE_FITTED) /* neighbour or mount: done now */
        {
            lidet__ground_q_pix_span(&gp, sc, img, lidet__ground_sector_col(s, ns, cols),
                                     lidet__ground_sector_col(s + 1u, ns, cols));
            lidet__ground_q_fit_rest(g, sc, &gp, s);
            label_sector(g, sc, mask, &gp, s);
        }
    }
    lidet__ground_sample_counts(&g->stats, g->stream_total, g->stream_lo, g->stream_hi);
    return g->stats.n_samples_dropped > 0u ? LIDET_TRUNCATED : LIDET_OK;
}

lidet_status_t lidet_ground_q_run(lidet_ground_q_t *g, const lidet_range_image_t *img)
{
    return g == 0 ? LIDET_ERR_ARG : lidet_ground_q_run_buffers(&g->state, &g->scratch, g->mask, img);
}

const uint8_t *lidet_ground_q_mask(const lidet_ground_q_t *g)
{
    return g == 0 ? 0 : g->mask;
}

const uint8_t *lidet_ground_q_samples(const lidet_ground_q_t *g)
{
    return g == 0 ? 0 : g->scratch.sample;
}

const lidet_plane_q_t *lidet_ground_q_planes(const lidet_ground_q_t *g, uint32_t *n_sectors)
{
    if (g != 0 && n_sectors != 0)
    {
        *n_sectors = g->state.cfg.n_sectors;
    }
    return g == 0 ? 0 : g->state.planes;
}

const uint8_t *lidet_ground_q_sector_source(const lidet_ground_q_t *g)
{
    return g == 0 ? 0 : g->state.source;
}

const lidet_ground_stats_t *lidet_ground_q_stats(const lidet_ground_q_t *g)
{
    return g == 0 ? 0 : &g->state.stats;
}

lidet_status_t lidet_ground_q_point_labels_of(const lidet_ground_q_state_t *g, const uint8_t *mask,
                                              const int32_t *point_pixel, uint32_t n_points, uint8_t *out)
{
    return g == 0 ? LIDET_ERR_ARG
                  : lidet__ground_point_labels(g->magic == LIDET_INIT_MAGIC, mask,
                                               (uint32_t)g->n_rows * g->n_cols, point_pixel, n_points, out);
}
