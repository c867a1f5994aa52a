/* SPDX-License-Identifier: MIT */
/* Ground stage: configuration, the Sobel-inspired sample filter, the per-pixel labelling and the
 * accessors (algorithm in lidet_ground.h). The plane fits live in lidet_ground_ransac.c.
 * Mirrored by codegen/lidet_ref/ground.py (sample_mask, label_pixels). */
#include <string.h>

#include "internal/lidet_assert.h"
#include "internal/lidet_ground_float_internal.h"
#include "internal/lidet_math.h"
#include "internal/lidet_pixel.h"
#include "internal/lidet_pixel_rxy.h"
#include "internal/lidet_rng.h"
#include "internal/lidet_simd.h"

/* Defaults measured by tools/bench/bench_ground.py and coordinate-descent sweeps (docs/GROUND.md) on
 * the real SemanticKITTI scans and 20 simulated scans per profile. Two families:
 *  - a tall car mount with many beams (hdl64; also os1-*): filter every 4th row (samples of every
 *    4th column), sectors split at
 *    15 m into a near and a far plane, 0.15 m above / 0.3 m below the plane is ground;
 *  - a low robot mount or few beams (vlp16 at 0.5 m; also vlp32c): every row and every sample, one
 *    plane per sector, 0.2 m above / 0.4 m below, a tighter F_x, a steeper veto and a plane height
 *    closer to the mount height. */
void lidet_ground_cfg_default(lidet_ground_cfg_t *cfg, const lidet_sensor_t *sensor)
{
    float mount = 1.73f;
    uint32_t rows = 64u;
    int low;
    if (cfg == 0)
    {
        return;
    }
    memset(cfg, 0, sizeof *cfg);
    if (sensor != 0)
    {
        mount = sensor->mount_height_m;
        rows = sensor->n_rows;
    }
    low = rows <= 32u || mount < 1.0f;
    /* sample filter: the paper's (S_u on R, |F_y| <= 0.2, no height gate) */
    cfg->fy_max = 0.2f;
    cfg->fx_max_m = low ? 0.2f : 1.0f;
    cfg->fx_on_z = 0u;
    cfg->require_descending = 0u;
    cfg->height_gate = 0u;
    cfg->gate_above_m = 0.43f; /* released code on KITTI: z < -1.3 m at a 1.73 m mount */
    cfg->gate_below_m = 8.27f; /* ... and z > -10 m */
    cfg->mount_height_m = mount;
    cfg->sample_step = low ? 1u : 4u;
    cfg->sample_col_step = low ? 1u : 4u;
    /* RANSAC */
    cfg->n_sectors = 32u;
    cfg->ransac_iters = 16u;
    cfg->eval_samples = 256u;
    cfg->confidence = 0.99f;
    cfg->min_samples = 10u;
    cfg->min_inliers = 8u;
    cfg->refine_iters = low ? 2u : 1u;
    cfg->inlier_m = 0.2f;
    cfg->max_tilt_rad = low ? 0.2f : 0.1f;
    cfg->max_height_dev_m = low ? 0.5f : 1.0f;
    cfg->ring_split_m = low ? 0.0f : 15.0f;
    cfg->far_max_step_m = low ? 0.0f : 0.5f;
    cfg->far2_split_m = low ? 0.0f : 30.0f;
    cfg->fallback_sectors = 4u;
    cfg->seed = 12345u;
    cfg->seed_per_cell = 0u;
    /* labelling */
    cfg->ground_m = low ? 0.2f : 0.15f;
    cfg->ground_m_per_m = 0.0f;
    cfg->below_factor = 2.0f;
    cfg->veto_slope = low ? 1.5f : 1.0f;
    cfg->veto_min_dz_m = 0.05f;
}

static int in_range(float v, float lo, float hi)
{
    return lidet__isfinite(v) && v >= lo && v <= hi;
}

lidet_status_t lidet_ground_state_init(lidet_ground_state_t *g, const lidet_ground_cfg_t *cfg)
{
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
        cfg->seed_per_cell > 1u || !in_range(cfg->azimuth_half_rad, 0.0f, LIDET_PI_F + 1e-6f))
    {
        return LIDET_ERR_CONFIG;
    }
    if (!in_range(cfg->fy_max, 0.0f, 10.0f) || !in_range(cfg->fx_max_m, 0.0f, 100.0f) ||
        cfg->fx_max_m <= 0.0f || !in_range(cfg->gate_above_m, -5.0f, 10.0f) ||
        !in_range(cfg->gate_below_m, 0.0f, 20.0f) || !in_range(cfg->mount_height_m, 0.0f, 10.0f) ||
        !in_range(cfg->inlier_m, 0.0f, 5.0f) || cfg->inlier_m <= 0.0f ||
        !in_range(cfg->max_tilt_rad, 0.0f, LIDET_HALF_PI_F) || cfg->max_tilt_rad <= 0.0f ||
        cfg->max_tilt_rad >= LIDET_HALF_PI_F || !in_range(cfg->max_height_dev_m, 0.0f, 20.0f) ||
        cfg->max_height_dev_m <= 0.0f || !in_range(cfg->ground_m, 0.0f, 5.0f) || cfg->ground_m <= 0.0f ||
        !in_range(cfg->ground_m_per_m, 0.0f, 0.1f) || !in_range(cfg->below_factor, 0.0f, 20.0f) ||
        !in_range(cfg->confidence, 0.0f, 0.999999f) || !in_range(cfg->ring_split_m, 0.0f, 500.0f) ||
        !in_range(cfg->far_max_step_m, 0.0f, 5.0f) || !in_range(cfg->far2_split_m, 0.0f, 500.0f) ||
        !in_range(cfg->veto_slope, 0.0f, 100.0f) || !in_range(cfg->veto_min_dz_m, 0.0f, 5.0f))
    {
        return LIDET_ERR_CONFIG;
    }
    if (lidet__ground_far2_on(cfg) && 3u * cfg->n_sectors > 2u * LIDET_GROUND_MAX_SECTORS)
    {
        return LIDET_ERR_CONFIG; /* the third cells' planes share the near / far arrays */
    }
    g->cfg = *cfg;
    g->rng = lidet__rng_seed(cfg->seed);
    g->n_rows = 0;
    g->n_cols = 0;
    memset(&g->stats, 0, sizeof g->stats);
    g->magic = LIDET_INIT_MAGIC;
    return LIDET_OK;
}

/* Filter parameters in locals (so the compiler keeps them in registers across the stores). The
 * optional tests are folded into always-on comparisons (dr > dr_min, z_lo <= z <= z_hi) with
 * infinite bounds when disabled, so the loop body has no branch and vectorises. */
typedef struct
{
    float fy_max, fx_max, z_lo, z_hi, dr_min;
} filt_t;

/* Sample test of one pixel of row r, given its column c and the wrapped neighbours cm1 = c-1,
 * cp1 = c+1, cp2 = c+2. R0/Z0: row r, R1/Z1: row r+1, F0: the channel S_u runs over (R or Z of
 * row r). Every touched pixel must hold a point (R > 0; empty pixels are 0 by the image contract).
 * Bitwise & instead of && on purpose: all operands are cheap and branch-free code vectorises. */
static inline float min2f(float a, float b)
{
    return a < b ? a : b; /* compiles to minss/minps; fminf would be a libm call in strict C99 */
}

static inline float max2f(float a, float b)
{
    return a > b ? a : b;
}

static inline uint8_t sample_test(const float *R0, const float *R1, const float *Z0, const float *Z1,
                                  const float *F0, uint32_t cm1, uint32_t c, uint32_t cp1, uint32_t cp2,
                                  const filt_t *f, int opt)
{
    const float dr = (2.0f * R0[c] + R0[cp1]) - (2.0f * R1[c] + R1[cp1]);
    const float dz = (2.0f * Z0[c] + Z0[cp1]) - (2.0f * Z1[c] + Z1[cp1]);
    const float fx = (F0[cm1] + 2.0f * F0[c]) - (2.0f * F0[cp1] + F0[cp2]);
    /* every touched pixel holds a point: the smallest R is > 0 (empty pixels are exactly 0) */
    const float rmin = min2f(min2f(min2f(R0[cm1], R0[c]), min2f(R0[cp1], R0[cp2])), min2f(R1[c], R1[cp1]));
    const int tests = (rmin > 0.0f) & (fabsf(dz) <= f->fy_max * fabsf(dr)) & (fabsf(fx) <= f->fx_max);
    /* opt is a constant at every call: without the optional tests they cost nothing */
    return (uint8_t)(opt ? tests & (dr > f->dr_min) & (Z0[c] >= f->z_lo) & (Z0[c] <= f->z_hi) : tests);
}

/* one row of the sample mask over columns [c_lo, c_hi); the whole row (c_lo 0, c_hi cols) wraps around: the
 * first and the last two columns take their neighbours modulo cols; a window's span lies two columns clear of
 * the edges (gspan_t), so its neighbours never wrap */
static inline void filter_row(const float *R0, const float *R1, const float *Z0, const float *Z1,
                              const float *F0, uint32_t cols, uint32_t c_lo, uint32_t c_hi, const filt_t *f,
                              uint8_t *out, int opt)
{
    uint32_t c;
    if (c_lo > 0u)
    {
        for (c = c_lo; c < c_hi; ++c)
        {
            out[c] = sample_test(R0, R1, Z0, Z1, F0, c - 1u, c, c + 1u, c + 2u, f, opt);
        }
        return;
    }
    out[0] = sample_test(R0, R1, Z0, Z1, F0, cols - 1u, 0u, 1u, 2u, f, opt);
    for (c = 1; c + 2u < cols; ++c)
    {
        out[c] = sample_test(R0, R1, Z0, Z1, F0, c - 1u, c, c + 1u, c + 2u, f, opt);
    }
    out[cols - 2u] = sample_test(R0, R1, Z0, Z1, F0, cols - 3u, cols - 2u, cols - 1u, 0u, f, opt);
    out[cols - 1u] = sample_test(R0, R1, Z0, Z1, F0, cols - 2u, cols - 1u, 0u, 1u, f, opt);
}

/* Rows of R (and, for a compact image, of x, y, z): the image's own rows where it has them (a float image:
 * pointers into it; R when the image keeps R), else computed on demand into scratch rows: R of row r and
 * z of row r in slot r % 2 (so rows r and r + 1, or r - 1 and r, are available together), x and y of one
 * row. R is always the projection's expression (lidet__rxy) on the float coordinates the stage reads:
 * for a float image the same bits as a stored R; for a compact image, on the decoded 4 mm values. A pass
 * over the rows in increasing order computes each row once. */

/* The compact image's row decoding (streaming loops: AVX2 variants on x86-64 hosts, internal/lidet_simd.h) */
/* out[c] = R of float x, y */
LIDET_CLONES_AVX2 static void rxy_of(const float *x, const float *y, uint32_t cols, float *out)
{
    uint32_t c;
    for (c = 0; c < cols; ++c)
    {
        out[c] = lidet__rxy(x[c], y[c]);
    }
}
/* out[c] = z decoded */
LIDET_CLONES_AVX2 static void decode_z(const int16_t *z, uint32_t cols, float *out)
{
    uint32_t c;
    for (c = 0; c < cols; ++c)
    {
        out[c] = lidet__pix_m(z[c]);
    }
}
/* x, y and z decoded, and R from x and y */
LIDET_CLONES_AVX2 static void decode_xyzr(const int16_t *x, const int16_t *y, const int16_t *z, uint32_t cols,
                                          float *ox, float *oy, float *oz, float *orxy)
{
    uint32_t c;
    for (c = 0; c < cols; ++c)
    {
        const float xm = lidet__pix_m(x[c]), ym = lidet__pix_m(y[c]);
        ox[c] = xm;
        oy[c] = ym;
        oz[c] = lidet__pix_m(z[c]);
        orxy[c] = lidet__rxy(xm, ym);
    }
}
/* x, y and z decoded (a compact image that keeps R) */
LIDET_CLONES_AVX2 static void decode_xyz(const int16_t *x, const int16_t *y, const int16_t *z, uint32_t cols,
                                         float *ox, float *oy, float *oz)
{
    uint32_t c;
    for (c = 0; c < cols; ++c)
    {
        ox[c] = lidet__pix_m(x[c]);
        oy[c] = lidet__pix_m(y[c]);
        oz[c] = lidet__pix_m(z[c]);
    }
}
/* R of the decoded x, y, and z decoded */
LIDET_CLONES_AVX2 static void decode_rz(const int16_t *x, const int16_t *y, const int16_t *z, uint32_t cols,
                                        float *orxy, float *oz)
{
    uint32_t c;
    for (c = 0; c < cols; ++c)
    {
        orxy[c] = lidet__rxy(lidet__pix_m(x[c]), lidet__pix_m(y[c]));
        oz[c] = lidet__pix_m(z[c]);
    }
}
typedef struct
{
    const lidet_range_image_t *img;
    const float *img_rxy; /* the image's R, or NULL */
    float *slot[2], *zslot[2], *xrow, *yrow;
    int32_t row_in[2], zrow_in[2], xyrow_in; /* row held by each slot, -1 = none */
    uint32_t cols;
    uint32_t d0, dn; /* the columns decoded: [d0, d0 + dn) (the whole row without a window) */
    int compact;
} rxy_rows_t;

/* the part of the image a run works on (cfg azimuth_half_rad): sectors [s_lo, s_hi), their columns [c_lo, c_hi);
 * the whole image without a window, or when the window's sectors come within two columns of the image's edges
 * (so the filter's neighbours never wrap). Columns outside hold no point (the window's contract). */
typedef struct
{
    uint32_t s_lo, s_hi, c_lo, c_hi;
    int whole;
} gspan_t;

static void span_of(const lidet_ground_cfg_t *cfg, uint32_t cols, gspan_t *sp)
{
    const uint32_t ns = cfg->n_sectors;
    uint32_t w_lo, w_hi;
    lidet__azimuth_window_cols(cfg->azimuth_half_rad, cols, &w_lo, &w_hi);
    sp->s_lo = (uint32_t)(((uint64_t)w_lo * ns) / cols); /* the sector holding column w_lo */
    sp->s_hi = (uint32_t)(((uint64_t)(w_hi - 1u) * ns) / cols) + 1u;
    sp->c_lo = lidet__ground_sector_col(sp->s_lo, ns, cols);
    sp->c_hi = lidet__ground_sector_col(sp->s_hi, ns, cols);
    sp->whole = w_lo == 0u || w_hi >= cols || sp->c_lo < 2u || sp->c_hi + 2u > cols;
    if (sp->whole)
    {
        sp->s_lo = 0u;
        sp->s_hi = ns;
        sp->c_lo = 0u;
        sp->c_hi = cols;
    }
}

static void rxy_rows_init(rxy_rows_t *rr, lidet_ground_scratch_t *sc, const lidet_range_image_t *img,
                          const gspan_t *sp)
{
    /* a window: its columns and the filter's neighbours (one left, two right), which hold no point */
    rr->d0 = sp->whole ? 0u : sp->c_lo - 1u;
    rr->dn = sp->whole ? img->n_cols : sp->c_hi + 2u - rr->d0;
    rr->img = img;
    rr->compact = lidet__img_compact(img);
    /* a float image's R, or a compact image's (the same expression on its decoded values) */
    rr->img_rxy = img->rxy_m;
    rr->slot[0] = sc->rxy_rows[0];
    rr->slot[1] = sc->rxy_rows[1];
    rr->zslot[0] = sc->z_rows[0];
    rr->zslot[1] = sc->z_rows[1];
    rr->xrow = sc->x_row;
    rr->yrow = sc->y_row;
    rr->row_in[0] = rr->row_in[1] = -1;
    rr->zrow_in[0] = rr->zrow_in[1] = -1;
    rr->xyrow_in = -1;
    rr->cols = img->n_cols;
}

static const float *rxy_row(rxy_rows_t *rr, uint32_t r)
{
    const uint32_t cols = rr->cols, k = r & 1u;
    float *out = rr->slot[k];
    if (rr->img_rxy != 0)
    {
        return rr->img_rxy + (size_t)r * cols;
    }
    if (rr->row_in[k] != (int32_t)r)
    {
        const size_t base = (size_t)r * cols + rr->d0;
        if (!rr->compact)
        {
            rxy_of(rr->img->x_m + base, rr->img->y_m + base, rr->dn, out + rr->d0);
        }
        else
        {
            lidet__rxy_4mm(rr->img->x_4mm + base, rr->img->y_4mm + base, rr->dn, out + rr->d0);
        }
        rr->row_in[k] = (int32_t)r;
    }
    return out;
}

/* z of row r: the image's row, or (compact image) decoded into slot r % 2 */
static const float *z_row(rxy_rows_t *rr, uint32_t r)
{
    const uint32_t cols = rr->cols, k = r & 1u;
    const size_t base = (size_t)r * cols;
    if (!rr->compact)
    {
        return rr->img->z_m + base;
    }
    if (rr->zrow_in[k] != (int32_t)r)
    {
        decode_z(rr->img->z_4mm + base + rr->d0, rr->dn, rr->zslot[k] + rr->d0);
        rr->zrow_in[k] = (int32_t)r;
    }
    return rr->zslot[k];
}

/* x and y of row r: the image's rows, or (compact image) decoded into the one x and y scratch row; a compact
 * image's z and R of row r go to their slots in the same loop (the label pass asks for x and y first, then z
 * and R) */
static void xy_row(rxy_rows_t *rr, uint32_t r, const float **X, const float **Y)
{
    const uint32_t cols = rr->cols, k = r & 1u;
    const size_t base = (size_t)r * cols;
    if (!rr->compact)
    {
        *X = rr->img->x_m + base;
        *Y = rr->img->y_m + base;
        return;
    }
    if (rr->xyrow_in != (int32_t)r)
    {
        const lidet_range_image_t *img = rr->img;
        const size_t b = base + rr->d0;
        const uint32_t d0 = rr->d0;
        if (rr->img_rxy != 0)
        {
            decode_xyz(img->x_4mm + b, img->y_4mm + b, img->z_4mm + b, rr->dn, rr->xrow + d0, rr->yrow + d0,
                       rr->zslot[k] + d0);
        }
        else
        {
            decode_xyzr(img->x_4mm + b, img->y_4mm + b, img->z_4mm + b, rr->dn, rr->xrow + d0, rr->yrow + d0,
                        rr->zslot[k] + d0, rr->slot[k] + d0);
            rr->row_in[k] = (int32_t)r;
        }
        rr->xyrow_in = (int32_t)r;
        rr->zrow_in[k] = (int32_t)r;
    }
    *X = rr->xrow;
    *Y = rr->yrow;
}

/* R and z of row r (the filter pass): a compact image's two decoded in one loop when neither is held */
static void rz_row(rxy_rows_t *rr, uint32_t r, const float **R, const float **Z)
{
    const uint32_t k = r & 1u;
    if (rr->compact && rr->img_rxy == 0 && rr->row_in[k] != (int32_t)r && rr->zrow_in[k] != (int32_t)r)
    {
        const size_t base = (size_t)r * rr->cols + rr->d0;
        const lidet_range_image_t *img = rr->img;
        decode_rz(img->x_4mm + base, img->y_4mm + base, img->z_4mm + base, rr->dn, rr->slot[k] + rr->d0,
                  rr->zslot[k] + rr->d0);
        rr->row_in[k] = (int32_t)r;
        rr->zrow_in[k] = (int32_t)r;
    }
    *R = rxy_row(rr, r);
    *Z = z_row(rr, r);
}

/* Pass 1 (mirrors lidet_ref/ground.py: sample_mask): the sample mask, row by row. */
static void filter_rows(const lidet_ground_state_t *g, uint8_t *sample, rxy_rows_t *rr,
                        const lidet_range_image_t *img, const gspan_t *sp)
{
    const uint32_t rows = img->n_rows, cols = img->n_cols;
    const uint32_t step = g->cfg.sample_step;
    const int opt = g->cfg.require_descending || g->cfg.height_gate;
    filt_t f;
    uint32_t r;
    f.fy_max = g->cfg.fy_max;
    f.fx_max = g->cfg.fx_max_m;
    f.dr_min = g->cfg.require_descending ? 0.0f : -3.0e38f;
    f.z_lo = g->cfg.height_gate ? -g->cfg.mount_height_m - g->cfg.gate_below_m : -3.0e38f;
    f.z_hi = g->cfg.height_gate ? -g->cfg.mount_height_m + g->cfg.gate_above_m : 3.0e38f;
    /* rows off the step grid and the bottom row (no beam below it) hold no sample */
    memset(sample, 0, (size_t)rows * cols);
    for (r = 0; r + 1u < rows; r += step)
    {
        const float *R0, *R1, *Z0, *Z1, *F0;
        rz_row(rr, r, &R0, &Z0);
        rz_row(rr, r + 1u, &R1, &Z1);
        F0 = g->cfg.fx_on_z ? Z0 : R0;
        uint8_t *out = sample + (size_t)r * cols;
        const filt_t fl = f;
        if (opt)
        {
            filter_row(R0, R1, Z0, Z1, F0, cols, sp->c_lo, sp->c_hi, &fl, out, 1);
        }
        else
        {
            filter_row(R0, R1, Z0, Z1, F0, cols, sp->c_lo, sp->c_hi, &fl, out, 0);
        }
    }
}

/* Pass 2 (mirrors lidet_ref/ground.py: gather_samples): the samples' pixels grouped by cell, so each cell's
 * RANSAC reads one contiguous block of indices (4 B a sample, where a copy of the coordinates took 12 B:
 * RANSAC reads them from the image). Only columns on the column grid (c % sample_col_step
 * == 0) of the filtered rows are taken (hdl64 defaults: every 4th row, every 4th column). Near
 * samples (R < ring_split_m) fill the buffer upwards from its start, far ones downwards from its
 * end, so one pass serves both cells of a sector (far cells hold their samples in reverse raster
 * order). While the free space covers every candidate of a sector, the copy is branch-free: every
 * candidate is written to the next free slot of its end, and the mask bit decides whether that end
 * advances (samples come in no predictable pattern). Past LIDET_GROUND_MAX_SAMPLES, samples are
 * dropped (in sector and raster order) and counted. */
/* R of one pixel, as rxy_row computes it */
static inline float pixel_rxy(const lidet_range_image_t *img, uint32_t p)
{
    return lidet__rxy(lidet__img_x(img, p), lidet__img_y(img, p));
}

static void gather_samples(lidet_ground_state_t *g, lidet_ground_scratch_t *sc,
                           const lidet_range_image_t *img, const gspan_t *sp)
{
    const uint32_t rows = img->n_rows, cols = img->n_cols, ns = g->cfg.n_sectors, step = g->cfg.sample_step;
    const uint32_t cstep = g->cfg.sample_col_step;
    const int two = g->cfg.ring_split_m > 0.0f;
    const float split = two ? g->cfg.ring_split_m : 3.0e38f;
    lidet_ground_sample_t *const si = sc->sample_pix;
    uint32_t s, r, c, lo = 0, hi = LIDET_GROUND_MAX_SAMPLES, total = 0;
    for (s = 0; s < ns; ++s)
    {
        const uint32_t c0 = lidet__ground_sector_col(s, ns, cols);
        const uint32_t c1 = lidet__ground_sector_col(s + 1u, ns, cols);
        const uint32_t cstart = c0 + (cstep - c0 % cstep) % cstep;
        const int roomy = hi - lo >= rows * (c1 - c0);
        const uint32_t near_start = lo, far_end = hi;
        for (r = 0; r + 1u < rows && s >= sp->s_lo && s < sp->s_hi; r += step) /* outside a window: none */
        {
            const size_t base = (size_t)r * cols;
            const uint8_t *m = sc->sample + base;
            /* R decides near or far only with a split: the image's, else computed for the sector's columns of
             * this row into a scratch row (free between the filter and the label pass), at the same columns */
            const float *R = img->rxy_m != 0 ? img->rxy_m + base : 0;
            if (two && R == 0 && roomy && cstart < c1)
            {
                float *tmp = sc->rxy_rows[0];
                if (lidet__img_compact(img))
                {
                    lidet__rxy_4mm(img->x_4mm + base + cstart, img->y_4mm + base + cstart, c1 - cstart,
                                   tmp + cstart);
                }
                else
                {
                    rxy_of(img->x_m + base + cstart, img->y_m + base + cstart, c1 - cstart, tmp + cstart);
                }
                R = tmp;
            }
            if (roomy)
            {
                for (c = cstart; c < c1; c += cstep)
                {
                    const float rc = !two ? 0.0f : R[c];
                    const uint32_t far = (uint32_t)(rc >= split), take = m[c];
                    const uint32_t k = far ? hi - 1u : lo; /* lo < hi: roomy leaves a slot per candidate */
                    si[k] = (lidet_ground_sample_t)(base + c);
                    lo += take & (far ^ 1u);
                    hi -= take & far;
                }
            }
            else
            {
                for (c = cstart; c < c1; c += cstep)
                {
                    if (m[c] != 0u)
                    {
                        ++total;
                        if (lo < hi)
                        {
                            const float rc =
                                !two ? 0.0f : (R != 0 ? R[c] : pixel_rxy(img, (uint32_t)base + c));
                            const uint32_t k = rc >= split ? --hi : lo++;
                            si[k] = (lidet_ground_sample_t)(base + c);
                        }
                    }
                }
            }
        }
        if (roomy)
        {
            total += (lo - near_start) + (far_end - hi);
        }
        lidet__ground_cell_span(sc->cell_first, sc->cell_n, s, ns, near_start, lo, hi, far_end);
    }
    lidet__ground_sample_counts(&g->stats, total, lo, hi);
}

/* Pass 3 (mirrors lidet_ref/ground.py: label_pixels, veto_vertical): ground = holds a point and
 * -below < height < above, height above the pixel's cell plane (near or far part of its sector),
 * and not vetoed. Empty pixels are excluded by R > 0 (the image contract: empty pixels are exactly
 * 0, and their coordinates 0 may lie within ground_m of a plane).
 * Vertical veto: a pixel is not ground when it and the pixel above it (the next beam up, same
 * column, holding a point) form a steep surface, |dz| > veto_slope * |dR| and |dz| > veto_min_dz_m:
 * the foot of a wall, a kerb face, a bumper or a trunk, whose lowest returns lie within ground_m of
 * the ground, while ground seen from above has the beam above landing much farther (|dR| >> |dz|).
 * Row 0 compares with itself (dz = 0: never vetoed); veto_slope 0 disables it (min dz = +huge).
 *
 * Speed (this pass dominates the stage): rows are cut into chunks of at most LABEL_CHUNK columns
 * within one sector. A chunk whose points all lie on one side of ring_split_m (the common case:
 * one beam over a short arc sees mostly the ground at one distance) is tested against that plane
 * only; mixed chunks test both planes and select by bits. With a constant tolerance the band test
 * is one compare, |h - mid| < half (mid and half fold -below and above together). Kernels write
 * 0 / -1 words to a small stack buffer, so the loops stay 4 lanes wide (no uint8 packing inside
 * them, which made the compiler unroll 16 pixels and spill registers); a second loop packs bytes
 * and counts. All loops are branch-free so that they vectorise. */
#define LABEL_CHUNK 64u

typedef struct
{
    float split, split2, slope, min_dz, mid, half; /* constant tolerance: |h - mid| < half */
    float g0, k, bf;                               /* general tolerance: -bf (g0 + k R) < h < g0 + k R */
} label_par_t;

/* veto word of pixel c: -1 when vetoed */
static inline int32_t veto(const float *R, const float *Z, const float *Ru, const float *Zu, uint32_t c,
                           const label_par_t *lp)
{
    const float dz = fabsf(Zu[c] - Z[c]), dr = fabsf(Ru[c] - R[c]);
    return -(int32_t)((Ru[c] > 0.0f) & (dz > max2f(lp->slope * dr, lp->min_dz)));
}

static inline float height(const lidet_plane_t *p, const float *X, const float *Y, const float *Z, uint32_t c)
{
    return p->nx * X[c] + p->ny * Y[c] + p->nz * Z[c] + p->d_m;
}

/* in-band word of a pixel holding a point at range r: the near plane's test below split, else the far's */
static inline int32_t pick(float r, float split, int32_t in_near, int32_t in_far)
{
    const int32_t near = -(int32_t)(r < split);
    return -(int32_t)(r > 0.0f) & ((near & in_near) | (~near & in_far));
}

/* one plane (d already shifted by -mid), constant tolerance; returns the vetoed count */
static uint32_t label_one(const float *X, const float *Y, const float *Z, const float *R, const float *Ru,
                          const float *Zu, uint32_t c0, uint32_t n, lidet_plane_t p, const label_par_t *lp,
                          int32_t *restrict o)
{
    uint32_t j, nv = 0;
    for (j = 0; j < n; ++j)
    {
        const uint32_t c = c0 + j;
        const int32_t in = -(int32_t)((R[c] > 0.0f) & (fabsf(height(&p, X, Y, Z, c)) < lp->half));
        const int32_t vt = veto(R, Z, Ru, Zu, c, lp);
        o[j] = in & ~vt;
        nv -= (uint32_t)(in & vt);
    }
    return nv;
}

/* near plane p below split, far plane q from it (both d shifted by -mid), constant tolerance; or,
 * general != 0, the tolerance growing with range (ground_m_per_m > 0, planes unshifted). general is
 * a constant at both calls. Returns the vetoed count. */
static inline uint32_t label_two(const float *X, const float *Y, const float *Z, const float *R,
                                 const float *Ru, const float *Zu, uint32_t c0, uint32_t n, lidet_plane_t p,
                                 lidet_plane_t q, const label_par_t *lp, int32_t *restrict o, int general)
{
    uint32_t j, nv = 0;
    for (j = 0; j < n; ++j)
    {
        const uint32_t c = c0 + j;
        const float hn = height(&p, X, Y, Z, c), hf = height(&q, X, Y, Z, c);
        const float above = lp->g0 + lp->k * R[c], below = -lp->bf * above;
        const int32_t in_n =
            general ? -(int32_t)((hn < above) & (hn > below)) : -(int32_t)(fabsf(hn) < lp->half);
        const int32_t in_f =
            general ? -(int32_t)((hf < above) & (hf > below)) : -(int32_t)(fabsf(hf) < lp->half);
        const int32_t in = pick(R[c], lp->split, in_n, in_f), vt = veto(R, Z, Ru, Zu, c, lp);
        o[j] = in & ~vt;
        nv -= (uint32_t)(in & vt);
    }
    return nv;
}

/* the third cells (far2_split_m): near plane p below split, far plane q below split2, q2 from it; otherwise as
 * label_two (general a constant at both calls). Returns the vetoed count. */
static inline uint32_t label_three(const float *X, const float *Y, const float *Z, const float *R,
                                   const float *Ru, const float *Zu, uint32_t c0, uint32_t n, lidet_plane_t p,
                                   lidet_plane_t q, lidet_plane_t q2, const label_par_t *lp,
                                   int32_t *restrict o, int general)
{
    uint32_t j, nv = 0;
    for (j = 0; j < n; ++j)
    {
        const uint32_t c = c0 + j;
        const float hn = height(&p, X, Y, Z, c), hf = height(&q, X, Y, Z, c), h2 = height(&q2, X, Y, Z, c);
        const float above = lp->g0 + lp->k * R[c], below = -lp->bf * above;
        const int32_t in_n =
            general ? -(int32_t)((hn < above) & (hn > below)) : -(int32_t)(fabsf(hn) < lp->half);
        const int32_t in_f =
            general ? -(int32_t)((hf < above) & (hf > below)) : -(int32_t)(fabsf(hf) < lp->half);
        const int32_t in_2 =
            general ? -(int32_t)((h2 < above) & (h2 > below)) : -(int32_t)(fabsf(h2) < lp->half);
        const int32_t f2 = -(int32_t)(R[c] >= lp->split2);
        const int32_t in = pick(R[c], lp->split, in_n, (f2 & in_2) | (~f2 & in_f)),
                      vt = veto(R, Z, Ru, Zu, c, lp);
        o[j] = in & ~vt;
        nv -= (uint32_t)(in & vt);
    }
    return nv;
}

static void label_rows(lidet_ground_state_t *g, uint8_t *mask, rxy_rows_t *rr, const lidet_range_image_t *img,
                       const gspan_t *sp)
{
    const uint32_t rows = img->n_rows, cols = img->n_cols, ns = g->cfg.n_sectors;
    const float g0 = g->cfg.ground_m, below0 = g->cfg.below_factor * g0;
    const int two = g->cfg.ring_split_m > 0.0f, general = g->cfg.ground_m_per_m > 0.0f;
    const int three = lidet__ground_far2_on(&g->cfg);
    const uint32_t s_lo = sp->s_lo, s_hi = sp->s_hi, c_lo = sp->c_lo, c_hi = sp->c_hi;
    label_par_t lp;
    int32_t o[LABEL_CHUNK];
    uint32_t r, s, c, j, n_ground = 0, n_vetoed = 0;
    lp.split = two ? g->cfg.ring_split_m : 3.0e38f;
    lp.split2 = three ? g->cfg.far2_split_m : 3.0e38f;
    lp.slope = g->cfg.veto_slope;
    lp.min_dz = g->cfg.veto_slope > 0.0f ? g->cfg.veto_min_dz_m : 3.0e38f;
    lp.mid = 0.5f * (g0 - below0);
    lp.half = 0.5f * (g0 + below0);
    lp.g0 = g0;
    lp.k = g->cfg.ground_m_per_m;
    lp.bf = g->cfg.below_factor;
    for (r = 0; r < rows; ++r)
    {
        const size_t base = (size_t)r * cols;
        const float *X, *Y, *Z, *R, *Ru, *Zu;
        uint8_t *out = mask + base;
        xy_row(rr, r, &X, &Y); /* first: a compact image's z and R of row r are decoded with them */
        Z = z_row(rr, r);
        R = rxy_row(rr, r);
        Ru = r > 0u ? rxy_row(rr, r - 1u) : R;
        Zu = r > 0u ? z_row(rr, r - 1u) : Z;
        /* outside a window's sectors: no point, so no ground */
        memset(out, 0, c_lo);
        memset(out + c_hi, 0, cols - c_hi);
        for (s = 0; s < ns; ++s)
        {
            /* (a loop from s_lo measured 2x slower per pixel with GCC 12: kept from 0) */
            if (s < s_lo || s >= s_hi)
            {
                continue;
            }
            const uint32_t c1 = lidet__ground_sector_col(s + 1u, ns, cols);
            lidet_plane_t p = g->planes[s], q = g->planes[ns + s], q2 = three ? g->planes[2u * ns + s] : q;
            uint32_t cnt = 0, nv = 0;
            if (!general)
            {
                p.d_m -= lp.mid;
                q.d_m -= lp.mid;
                q2.d_m -= lp.mid;
            }
            for (c = lidet__ground_sector_col(s, ns, cols); c < c1; c += LABEL_CHUNK)
            {
                const uint32_t n = c1 - c < LABEL_CHUNK ? c1 - c : LABEL_CHUNK;
                if (general && three)
                {
                    nv += label_three(X, Y, Z, R, Ru, Zu, c, n, p, q, q2, &lp, o, 1);
                }
                else if (general)
                {
                    nv += label_two(X, Y, Z, R, Ru, Zu, c, n, p, q, &lp, o, 1);
                }
                else if (!two)
                {
                    nv += label_one(X, Y, Z, R, Ru, Zu, c, n, p, &lp, o);
                }
                else
                {
                    /* all points near, all far, or mixed (empty pixels count as neither); with the third
                     * cells also all beyond far2_split_m, or a mix with some there */
                    uint32_t n_pts = 0, n_far = 0, n_far2 = 0;
                    for (j = 0; j < n; ++j)
                    {
                        n_pts += (uint32_t)(R[c + j] > 0.0f);
                        n_far += (uint32_t)(R[c + j] >= lp.split);
                        n_far2 += (uint32_t)(R[c + j] >= lp.split2);
                    }
                    if (n_far == 0u)
                    {
                        nv += label_one(X, Y, Z, R, Ru, Zu, c, n, p, &lp, o);
                    }
                    else if (n_far2 == 0u && n_far == n_pts)
                    {
                        nv += label_one(X, Y, Z, R, Ru, Zu, c, n, q, &lp, o);
                    }
                    else if (n_far2 == 0u)
                    {
                        nv += label_two(X, Y, Z, R, Ru, Zu, c, n, p, q, &lp, o, 0);
                    }
                    else if (n_far2 == n_pts)
                    {
                        nv += label_one(X, Y, Z, R, Ru, Zu, c, n, q2, &lp, o);
                    }
                    else
                    {
                        nv += label_three(X, Y, Z, R, Ru, Zu, c, n, p, q, q2, &lp, o, 0);
                    }
                }
                for (j = 0; j < n; ++j)
                {
                    out[c + j] = (uint8_t)(o[j] & 1);
                    cnt -= (uint32_t)o[j];
                }
            }
            n_ground += cnt;
            n_vetoed += nv;
        }
    }
    g->stats.n_ground = n_ground;
    g->stats.n_vetoed = n_vetoed;
}

lidet_status_t lidet_ground_run_buffers(lidet_ground_state_t *g, lidet_ground_scratch_t *scratch,
                                        uint8_t *mask, const lidet_range_image_t *img)
{
    rxy_rows_t rr;
    gspan_t sp;
    lidet_status_t st;
    if (g == 0 || scratch == 0 || mask == 0 || img == 0)
    {
        return LIDET_ERR_ARG;
    }
    st = lidet__ground_run_check(g->magic == LIDET_INIT_MAGIC,
                                 lidet__img_compact(img)
                                     ? (img->x_4mm != 0 && img->y_4mm != 0 && img->z_4mm != 0)
                                     : (img->y_m != 0 && img->z_m != 0),
                                 img, g->cfg.n_sectors, &g->stats);
    if (st != LIDET_OK)
    {
        return st;
    }
    g->n_rows = img->n_rows;
    g->n_cols = img->n_cols;
    g->rng = lidet__rng_seed(g->cfg.seed); /* every run starts from the seed: deterministic per scan */
    span_of(&g->cfg, img->n_cols, &sp);
    rxy_rows_init(&rr, scratch, img, &sp);
    filter_rows(g, scratch->sample, &rr, img, &sp);
    gather_samples(g, scratch, img, &sp);
    lidet__ground_fit_sectors(g, scratch, img);
    rxy_rows_init(&rr, scratch, img, &sp); /* the label pass recomputes the rows it needs */
    label_rows(g, mask, &rr, img, &sp);
    return g->stats.n_samples_dropped > 0u ? LIDET_TRUNCATED : LIDET_OK;
}

lidet_status_t lidet_ground_init(lidet_ground_t *g, const lidet_ground_cfg_t *cfg)
{
    return g == 0 ? LIDET_ERR_ARG : lidet_ground_state_init(&g->state, cfg);
}

lidet_status_t lidet_ground_run(lidet_ground_t *g, const lidet_range_image_t *img)
{
    if (g == 0)
    {
        return LIDET_ERR_ARG;
    }
    return lidet_ground_run_buffers(&g->state, &g->scratch, g->mask, img);
}

const uint8_t *lidet_ground_mask(const lidet_ground_t *g)
{
    return g == 0 ? 0 : g->mask;
}

const uint8_t *lidet_ground_samples(const lidet_ground_t *g)
{
    return g == 0 ? 0 : g->scratch.sample;
}

const lidet_plane_t *lidet_ground_planes(const lidet_ground_t *g, uint32_t *n_sectors)
{
    if (g == 0)
    {
        return 0;
    }
    if (n_sectors != 0)
    {
        *n_sectors = g->state.cfg.n_sectors;
    }
    return g->state.planes;
}

const uint8_t *lidet_ground_sector_source(const lidet_ground_t *g)
{
    return g == 0 ? 0 : g->state.source;
}

lidet_status_t lidet_ground_point_labels_of(const lidet_ground_state_t *g, const uint8_t *mask,
                                            const int32_t *point_pixel, uint32_t n_points, uint8_t *out)
{
    return g == 0 ? LIDET_ERR_ARG
                  : lidet__ground_point_labels(g->magic == LIDET_INIT_MAGIC, mask,
                                               (uint32_t)g->n_rows * g->n_cols, point_pixel, n_points, out);
}

lidet_status_t lidet_ground_point_labels(const lidet_ground_t *g, const int32_t *point_pixel,
                                         uint32_t n_points, uint8_t *out)
{
    return g == 0 ? LIDET_ERR_ARG
                  : lidet_ground_point_labels_of(&g->state, g->mask, point_pixel, n_points, out);
}

const lidet_ground_stats_t *lidet_ground_stats(const lidet_ground_t *g)
{
    return g == 0 ? 0 : &g->state.stats;
}

uint32_t lidet_ground_bytes(void)
{
    return (uint32_t)sizeof(lidet_ground_t);
}

uint32_t lidet_ground_state_bytes(void)
{
    return (uint32_t)sizeof(lidet_ground_state_t);
}

uint32_t lidet_ground_scratch_bytes(void)
{
    return (uint32_t)sizeof(lidet_ground_scratch_t);
}
