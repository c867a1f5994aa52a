/* SPDX-License-Identifier: MIT */
/* Spherical projection (see lidet_proj.h for the algorithm and memory).
 * Mirrored by codegen/lidet_ref/proj.py (the numpy reference used by the tests). */
#include <math.h>
#include <string.h>

#include "internal/lidet_assert.h"
#include "internal/lidet_math.h"
#include "internal/lidet_pixel_rxy.h"
#include "internal/lidet_proj_rows.h"
#include "internal/lidet_simd.h"
#include "lidet/lidet_proj.h"

#if LIDET_HOST_SIMD && defined(__SSE2__)
#include <emmintrin.h>
#endif

/* keep every accepted elevation away from +-90 deg so its tangent stays finite */
#define MAX_ABS_ELEV_RAD 1.55f
#define PASS2_BLOCK 1024u /* pixels per pass-2 block: 5 planes x 4 KiB stay in L1 */

void lidet_proj_cfg_default(lidet_proj_cfg_t *cfg, const lidet_sensor_t *sensor)
{
    if (cfg == 0)
    {
        return;
    }
    memset(cfg, 0, sizeof *cfg);
    if (sensor != 0)
    {
        cfg->sensor = *sensor;
    }
    cfg->min_range_m = 0.1f;
    cfg->max_range_m = 0.0f;
    cfg->fov_margin_rad = 5.0f * LIDET_DEG2RAD_F;
    cfg->azimuth_half_rad = 0.0f;
}

/* run()'s block pre-test. Column c spans azimuths (pi - 2 pi (c + 1) / cols, pi - 2 pi c / cols] (u below), so the
 * window [win_lo, win_hi) spans (a1, a2] = (pi - 2 pi win_hi / cols, pi - 2 pi win_lo / cols]; each edge is turned
 * WIN_MARGIN_RAD outwards, far more than the rounding of the pseudo-azimuth the exact test reads (~1e-6 rad), so
 * a point the pre-test puts outside is outside for the exact test too. With the widened window W <= pi a point
 * lies outside iff cross(v1, p) < 0 or cross(p, v2) < 0 (v1, v2 its edges); wider, iff both are */
#define WIN_MARGIN_RAD 0.01f
static void init_window_test(lidet_proj_state_t *proj, uint32_t cols)
{
    const float step = 2.0f * LIDET_PI_F / (float)cols;
    const float a1 = LIDET_PI_F - step * (float)proj->win_hi - WIN_MARGIN_RAD;
    const float a2 = LIDET_PI_F - step * (float)proj->win_lo + WIN_MARGIN_RAD;
    proj->win_test = 0u;
    if ((proj->win_lo == 0u && proj->win_hi >= cols) || a2 - a1 >= 2.0f * LIDET_PI_F - 4.0f * WIN_MARGIN_RAD)
    {
        return; /* the whole scan, or a window whose margins would close the gap: no pre-test */
    }
    proj->win_edge[0] = cosf(a1);
    proj->win_edge[1] = sinf(a1);
    proj->win_edge[2] = cosf(a2);
    proj->win_edge[3] = sinf(a2);
    proj->win_test = a2 - a1 <= LIDET_PI_F ? 1u : 2u;
}

/* lidet__proj_rows_top_down's order on this file's elevations */
static int beam_above(const void *elev, uint32_t a, uint32_t b)
{
    const float *e = (const float *)elev;
    return e[a] > e[b];
}

static int in_range(float v, float lo, float hi)
{
    return lidet__isfinite(v) && v >= lo && v <= hi;
}

/* Column c spans u = (pi - azimuth) / (2 pi) in [c/cols, (c+1)/cols). In pseudo-azimuth terms, with
 * v = 4u = quadrant + f (f in [0, 1)), D(u) = quadrant + g(f pi/2), g(t) = sin t / (sin t + cos t)
 * (derived from the four quadrant cases of the pseudo-azimuth in key_block). Computing the edges from (quadrant,
 * f) keeps them exact at the quadrant seams, where sin/cos of pi-sized floats would lose the sign. */
static void init_columns(lidet_proj_state_t *proj, uint32_t cols)
{
    uint32_t c, k;
    for (c = 0; c <= cols; ++c)
    {
        const uint32_t quadrant = (4u * c) / cols;
        const float f = (float)((4u * c) % cols) / (float)cols;
        const float t = f * LIDET_HALF_PI_F;
        const float sn = sinf(t), cs = cosf(t);
        proj->col_edge_key[c] = (float)quadrant + sn / (sn + cs);
    }
    proj->col_edge_key[0] = -1.0f; /* below any D (which may be -1 ulp): ends the downward correction */
    proj->col_edge_key[cols] =
        5.0f; /* D <= 4 < 5: ends the upward correction (D = 4 stays in the last column) */
    /* bucket k covers D in [k/cols, (k+1)/cols); one more entry takes D = 4 exactly. A column is at
     * least pi/cols wide in D (dD/du is in [pi, 2 pi]), i.e. > 3 buckets, so a bucket's guess is off
     * by at most one column even when float rounding puts D into a neighbouring bucket. */
    proj->col_lut_scale = (float)cols;
    c = 0;
    for (k = 0; k <= 4u * cols; ++k)
    {
        const float d_low = (float)k / proj->col_lut_scale;
        while (c + 1 < cols && proj->col_edge_key[c + 1] <= d_low)
        {
            ++c;
        }
        proj->col_lut[k] = (uint16_t)c;
    }
    proj->col_single_step = 1;
    for (c = 1; c < cols; ++c) /* verify the spacing claim on the float edges */
    {
        if (proj->col_edge_key[c] - proj->col_edge_key[c - 1] <= 2.0f / proj->col_lut_scale)
        {
            proj->col_single_step = 0;
        }
    }
}

lidet_status_t lidet_proj_state_init(lidet_proj_state_t *proj, const lidet_proj_cfg_t *cfg)
{
    const lidet_sensor_t *s;
    float elev[LIDET_MAX_ROWS];
    uint8_t ring_of_row[LIDET_MAX_ROWS];
    float top_rad, bottom_rad, span;
    uint32_t rows, r, k;
    lidet_status_t status;

    if (proj == 0 || cfg == 0)
    {
        return LIDET_ERR_ARG;
    }
    proj->magic = 0;
    s = &cfg->sensor;
    status = lidet__proj_check_shape(s->n_rows, s->n_cols);
    if (status != LIDET_OK)
    {
        return status;
    }
    if (!in_range(cfg->min_range_m, 0.0f, 10.0f) || !in_range(cfg->fov_margin_rad, 0.0f, 0.5f) ||
        !in_range(cfg->max_range_m, 0.0f, 1.0e6f) ||
        (cfg->max_range_m > 0.0f && cfg->max_range_m <= cfg->min_range_m) ||
        !in_range(cfg->azimuth_half_rad, 0.0f, LIDET_PI_F + 1e-6f))
    {
        return LIDET_ERR_CONFIG;
    }
    rows = s->n_rows;

    /* beam elevations in ring order */
    if (s->beam_elev_rad != 0)
    {
        for (r = 0; r < rows; ++r)
        {
            if (!in_range(s->beam_elev_rad[r], -MAX_ABS_ELEV_RAD, MAX_ABS_ELEV_RAD))
            {
                return LIDET_ERR_CONFIG;
            }
            elev[r] = s->beam_elev_rad[r];
        }
    }
    else
    {
        float step;
        if (!in_range(s->fov_up_rad, -MAX_ABS_ELEV_RAD, MAX_ABS_ELEV_RAD) ||
            !in_range(s->fov_down_rad, -MAX_ABS_ELEV_RAD, MAX_ABS_ELEV_RAD) ||
            s->fov_up_rad <= s->fov_down_rad)
        {
            return LIDET_ERR_CONFIG;
        }
        step = (s->fov_up_rad - s->fov_down_rad) / (float)rows;
        for (r = 0; r < rows; ++r)
        {
            elev[r] = s->fov_up_rad - ((float)r + 0.5f) * step;
        }
    }

    /* rows = beams sorted top to bottom (insertion sort, stable: equal elevations keep ring order,
     * and are then rejected below) */
    lidet__proj_rows_top_down(rows, elev, beam_above, ring_of_row);
    for (r = 0; r < rows; ++r)
    {
        proj->row_elev_rad[r] = elev[ring_of_row[r]];
        /* BAM32 of an elevation in (-pi/2, pi/2): |value| < 2^30, exact to float's 24 bits (<= 64 BAM) */
        proj->row_elev_bam[r] = (int32_t)(proj->row_elev_rad[r] * 683565275.6f);
        proj->ring_to_row[ring_of_row[r]] = (uint8_t)r;
        if (r > 0 && !(proj->row_elev_rad[r] < proj->row_elev_rad[r - 1]))
        {
            return LIDET_ERR_CONFIG; /* two beams at the same elevation */
        }
    }

    /* rows r-1 and r meet at their mid-angle; compare tangents (monotonic) instead of angles. The
     * sentinels at both ends end run()'s correction loops without bounds tests. */
    proj->row_bound_tan[0] = 3.0e38f;
    for (r = 1; r < rows; ++r)
    {
        proj->row_bound_tan[r] = tanf(0.5f * (proj->row_elev_rad[r - 1] + proj->row_elev_rad[r]));
    }
    proj->row_bound_tan[rows] = -3.0e38f;
    if (s->beam_elev_rad != 0)
    {
        top_rad = proj->row_elev_rad[0] + cfg->fov_margin_rad;
        bottom_rad = proj->row_elev_rad[rows - 1] - cfg->fov_margin_rad;
    }
    else
    {
        top_rad = s->fov_up_rad + cfg->fov_margin_rad;
        bottom_rad = s->fov_down_rad - cfg->fov_margin_rad;
    }
    top_rad = top_rad > MAX_ABS_ELEV_RAD ? MAX_ABS_ELEV_RAD : top_rad;
    bottom_rad = bottom_rad < -MAX_ABS_ELEV_RAD ? -MAX_ABS_ELEV_RAD : bottom_rad;
    proj->tan_hi = tanf(top_rad);
    proj->tan_lo = tanf(bottom_rad);
    span = proj->tan_hi - proj->tan_lo;
    proj->lut_scale = (float)LIDET_PROJ_ROW_LUT / span;
    if (!(span > 0.0f) || !lidet__isfinite(proj->lut_scale))
    {
        /* a field of view (beams + margin) of zero or denormal width: no bucket size (run() would convert
         * 0 * Inf to an integer; issue 19, found by fuzz_proj) */
        return LIDET_ERR_CONFIG;
    }

    /* bucket k covers tan in [lo + k/scale, lo + (k+1)/scale): store the row of its top end, the
     * smallest row any tan in the bucket can have; run() walks down from there (usually 0-1 step) */
    r = 0;
    for (k = LIDET_PROJ_ROW_LUT + 1u; k-- > 0;) /* entry LIDET_PROJ_ROW_LUT takes tan == tan_hi */
    {
        const float t_top = proj->tan_lo + (float)(k + 1u) / proj->lut_scale;
        while (proj->row_bound_tan[r + 1] > t_top)
        {
            ++r;
        }
        proj->row_lut[k] = (uint8_t)r;
    }
    /* With every pair of neighbouring row boundaries more than two buckets apart, the bucket's guess
     * is off by at most one row (also when rounding moves tan into the next bucket), so run() makes one
     * branch-free correction step each way. Dense custom tables fall back to correction loops. */
    proj->row_single_step = 1;
    for (r = 2; r < rows; ++r)
    {
        if (proj->row_bound_tan[r - 1] - proj->row_bound_tan[r] <= 2.0f / proj->lut_scale)
        {
            proj->row_single_step = 0;
        }
    }
    init_columns(proj, s->n_cols);
    lidet__azimuth_window_cols(cfg->azimuth_half_rad, s->n_cols, &proj->win_lo, &proj->win_hi);
    init_window_test(proj, s->n_cols);
    proj->cfg = *cfg;
    proj->cfg.sensor.beam_elev_rad = 0; /* not retained: the caller's table may go away */
    proj->n_points = 0;
    memset(&proj->stats, 0, sizeof proj->stats);
    proj->magic = LIDET_INIT_MAGIC;
    return LIDET_OK;
}

lidet_status_t lidet_proj_init(lidet_proj_t *proj, const lidet_proj_cfg_t *cfg)
{
    if (proj == 0)
    {
        return LIDET_ERR_ARG;
    }
    return lidet_proj_state_init(&proj->state, cfg);
}

/* Pass 1 works on blocks of KEY_BLOCK points (stack: 7 arrays of KEY_BLOCK x 4 B, 1.75 KiB by default):
 *  (a) key_block: range test, tan(elevation), pseudo-azimuth and both lookup-table buckets of every
 *      point, in one loop without branches or table accesses, which compilers vectorize (SSE2: 4
 *      points per sqrt and per division);
 *  (b) table lookups and exact corrections, point by point, giving each point its pixel;
 *  (c) the closest-point test over the block's projected points, in a loop of its own.
 * Measured on 11 real KITTI scans (min of 40 runs, whole run): 11.7 ns/point, against 16.4 with keys,
 * lookups and the closest-point test in one loop per point, and 20.6 with (a) apart but (b) and (c)
 * in one loop: (c)'s read-modify-writes of the image stall when interleaved with (b)'s table loads. */
#define KEY_BLOCK ((uint32_t)LIDET_PROJ_BLOCK) /* lidet_opt.h, 64 by default */
#define KEY_RANGE_OK 1                         /* min2 <= r^2 <= max2 (so x, y, z finite) */
#define KEY_FOV_OK 2                           /* tan(elevation) in [tan_lo, tan_hi] (so not NaN) */
#define KEY_DEN_OK 4                           /* 1 / ((|x|+|y|) * rxy) finite and > 0: t and d are defined */
#define KEY_ALL 7

typedef struct
{
    float t[KEY_BLOCK];       /* tan(elevation) */
    float d[KEY_BLOCK];       /* pseudo-azimuth */
    float r2[KEY_BLOCK];      /* squared range */
    int32_t row_k[KEY_BLOCK]; /* row_lut bucket; reused by (b) for the pixel of the k-th projected point */
    int32_t col_k[KEY_BLOCK]; /* col_lut bucket; reused by (b) for the block index of that point */
    int32_t flags[KEY_BLOCK]; /* KEY_* */
    int32_t pix[KEY_BLOCK];   /* (b): pixel of each point, -1 = not projected; copied to point_pixel */
} key_block_t;

/* the terms both key_block and the window's pre-test compute from a point: its squared horizontal range, its
 * squared range (x^2 + y^2, then + z^2: the range test's exact expression, so both give the same bits) and
 * |x| + |y| */
static inline float range_terms(float x, float y, float z, float *rxy2, float *s)
{
    *rxy2 = x * x + y * y;
    *s = fabsf(x) + fabsf(y);
    return *rxy2 + z * z;
}

/* the count a point that failed the range test goes to (NaN or Inf, too close, or too far: beyond max_range_m, or
 * so large that r^2 overflows), r2 its squared range */
static inline void count_out_of_range(const float *pt, float r2, float min2, lidet_proj_stats_t *st)
{
    if (!lidet__isfinite(pt[0]) || !lidet__isfinite(pt[1]) || !lidet__isfinite(pt[2]))
        ++st->n_nonfinite;
    else if (r2 < min2)
        ++st->n_too_close;
    else
        ++st->n_too_far;
}

/* (a) above: the two per-point keys from one division and one square root,
 *   tan(elevation) t = z / rxy, and the pseudo-azimuth ("diamond angle") in [0, 4]
 *   d = 1 + x/(|x|+|y|) for y >= 0, 3 - x/(|x|+|y|) for y < 0,
 * monotonic in azimuth: 0 at +-pi, 1 at +pi/2, 2 at 0, 3 at -pi/2, -> 4 towards -pi. With
 * inv = 1 / ((|x|+|y|) rxy): x/(|x|+|y|) = x rxy inv and z/rxy = z (|x|+|y|) inv. There is no branch:
 * with den = 0, inv = +inf makes t +-inf or NaN (rejected by the field-of-view test) and d NaN (replaced by 2 in run() on the ring
 * path). Every float -> int conversion is of a clamped value (NaN clamps to the low end), so invalid
 * points get harmless buckets and no UB. Written so that GCC/Clang if-convert it under the default FP
 * semantics: selects of operands, no arithmetic inside a condition (an add that may trap is not
 * speculated, which blocks vectorization). */
static inline void key_block(key_block_t *kb, const float *pts, uint32_t m, uint32_t stride, float min2,
                             float max2, float tan_lo, float tan_hi, float row_scale, float col_scale,
                             float last_col_bucket)
{
    uint32_t j;
    for (j = 0; j < m; ++j)
    {
        const float *pt = pts + (size_t)j * stride;
        const float x = pt[0], y = pt[1], z = pt[2];
        float rxy2, s;
        const float r2 = range_terms(x, y, z, &rxy2, &s);
        const float rxy = sqrtf(rxy2);
        const float den = s * rxy;
        const float inv = 1.0f / den;
        const float q = x * rxy * inv;
        const float t = z * s * inv;
        const float d0 = (y >= 0.0f ? 1.0f : 3.0f) + (y >= 0.0f ? q : -q); /* 1 + q or 3 - q (= 3 + -q) */
        /* rounding can put d a few ulp outside [0, 4] (at +-pi: 1 + q with q = -1 - ulp): clamped, so the
         * column corrections in run() never step past the edge table (issue 19, found by fuzz_ground) */
        const float d1 = d0 >= 0.0f ? d0 : 0.0f;
        const float d = d1 <= 4.0f ? d1 : 4.0f;
        const int32_t range_ok = (r2 >= min2) & (r2 <= max2);
        const int32_t fov_ok = (t >= tan_lo) & (t <= tan_hi);
        const float tc0 = t >= tan_lo ? t : tan_lo; /* t itself when fov_ok */
        const float tc = tc0 <= tan_hi ? tc0 : tan_hi;
        float uc = d * col_scale;
        uc = uc >= 0.0f ? uc : 0.0f;                       /* also NaN */
        uc = uc <= last_col_bucket ? uc : last_col_bucket; /* d may exceed 4 by a few ulp */
        kb->t[j] = t;
        kb->d[j] = d;
        kb->r2[j] = r2;
        kb->row_k[j] = (int32_t)((tc - tan_lo) * row_scale); /* in [0, LIDET_PROJ_ROW_LUT] */
        kb->col_k[j] = (int32_t)uc;                          /* in [0, 4 cols] */
        /* t and d are defined only where 1 / den is finite and non-zero: den 0 (x = y = 0), a denormal den
         * (|x|, |y| < ~1e-19 m: inv overflows, d would be +-inf and walk the column search out of the table)
         * and an overflowing den (rxy > ~1.3e19 m: inv 0, t and d meaningless) are all not DEN_OK */
        kb->flags[j] = range_ok | (fov_ok << 1) | ((int32_t)((inv > 0.0f) & (inv <= 3.4028235e38f)) << 2);
    }
}

/* key_block of KITTI-style records (stride 4), also built for AVX2 on x86-64 hosts (internal/lidet_simd.h):
 * 8 points per square root and per division; lanes independent, so the same bits at every width */
LIDET_CLONES_AVX2 static void key_block4(key_block_t *kb, const float *pts, uint32_t m, float min2,
                                         float max2, float tan_lo, float tan_hi, float row_scale,
                                         float col_scale, float last_col_bucket)
{
    key_block(kb, pts, m, 4u, min2, max2, tan_lo, tan_hi, row_scale, col_scale, last_col_bucket);
}

/* run()'s pre-test of one block in the azimuth window (init_window_test): returns 1 when every point fails the
 * range test (range_terms, as key_block) or lies surely outside the window, with the count of those in
 * range in *n_in; 0 otherwise. A point counts as outside only with |x| + |y| >= 1e-15 m and x^2 + y^2 <= 1e36
 * m^2, where key_block's pseudo-azimuth is defined and accurate (1 / den normal). One loop of selects and two
 * reductions, which compilers vectorize */
static inline uint32_t outside_block(const float *pts, uint32_t m, uint32_t stride, float min2, float max2,
                                     const float *e, int wide, uint32_t *n_in)
{
    uint32_t j, all = 1u, nin = 0u;
    for (j = 0; j < m; ++j)
    {
        const float *pt = pts + (size_t)j * stride;
        const float x = pt[0], y = pt[1], z = pt[2];
        float rxy2, s;
        const float r2 = range_terms(x, y, z, &rxy2, &s);
        const float c1 = e[0] * y - e[1] * x; /* cross(v1, p) */
        const float c2 = x * e[3] - y * e[2]; /* cross(p, v2) */
        const uint32_t range_ok = (uint32_t)((r2 >= min2) & (r2 <= max2));
        const uint32_t out =
            wide ? (uint32_t)((c1 < 0.0f) & (c2 < 0.0f)) : (uint32_t)((c1 < 0.0f) | (c2 < 0.0f));
        const uint32_t sure = out & (uint32_t)((s >= 1.0e-15f) & (rxy2 <= 1.0e36f));
        all &= (range_ok ^ 1u) | sure;
        nin += range_ok;
    }
    *n_in = nin;
    return all;
}

/* outside_block of KITTI-style records (stride 4), also built for AVX2 (as key_block4) */
LIDET_CLONES_AVX2 static uint32_t outside_block4(const float *pts, uint32_t m, float min2, float max2,
                                                 const float *e, int wide, uint32_t *n_in)
{
    return outside_block(pts, m, 4u, min2, max2, e, wide, n_in);
}

float lidet_proj_azimuth_key(float x, float y)
{
    /* the very arithmetic run() bins on (one point through key_block), so tests measure exactly that */
    const float pt[3] = {x, y, 0.0f};
    key_block_t kb;
    key_block(&kb, pt, 1u, 3u, 0.0f, 3.0e38f, -1.0f, 1.0f, 1.0f, 1.0f, 4.0f);
    return (kb.flags[0] & KEY_DEN_OK) ? kb.d[0] : 2.0f;
}

/* v in 4 mm steps, rounded half up (floor(v / 0.004 + 0.5), as tools/bench/bench_pixel.py's s16 model);
 * |v| <= LIDET_PIXEL_MAX_RANGE_M, so it fits int16. Branch-free floor of a truncating conversion. */
static inline int32_t to_4mm(float v)
{
    const float t = v * LIDET_PIXEL_PER_M + 0.5f;
    const int32_t i = (int32_t)t;
    return i - (int32_t)(t < (float)i);
}

/* the record an empty pixel's gather reads (masked to +0 anyway) */
static const float k_zero_rec[4] = {0.0f, 0.0f, 0.0f, 0.0f}; /* 4: a whole record for gather_winners4 */

/* (a) of pass 2: the winners' coordinates of m pixels (idx: their winning points, -1 = none) into x, y, z, an
 * empty pixel reading record 0 masked to +0 (no branch: 21 % of KITTI pixels are empty, scattered); returns
 * how many hold a winner */
static inline uint32_t gather_winners(const int32_t *idx, const float *src, uint32_t stride, uint32_t m,
                                      float *x, float *y, float *z)
{
    uint32_t j, filled = 0;
    for (j = 0; j < m; ++j)
    {
        const int32_t k = idx[j];
        const uint32_t keep = 0u - (uint32_t)(k >= 0); /* all ones for a winner, else 0 */
        const float *pt = src + (size_t)((uint32_t)k & keep) * stride;
        uint32_t ux, uy, uz;
        memcpy(&ux, &pt[0], sizeof ux);
        memcpy(&uy, &pt[1], sizeof uy);
        memcpy(&uz, &pt[2], sizeof uz);
        ux &= keep;
        uy &= keep;
        uz &= keep;
        memcpy(&x[j], &ux, sizeof ux);
        memcpy(&y[j], &uy, sizeof uy);
        memcpy(&z[j], &uz, sizeof uz);
        filled += keep & 1u;
    }
    return filled;
}

#if LIDET_HOST_SIMD && defined(__SSE2__)
/* gather_winners of KITTI-style records (stride 4), SSE2 hosts: four pixels at a time, each winner's record read
 * whole (16 bytes: in the caller's array, records of 4 floats) and the four transposed into x, y, z lanes, masked
 * as gather_winners masks (the same bits); the rest of the m pixels as there */
static inline uint32_t gather_winners4(const int32_t *idx, const float *src, uint32_t m, float *x, float *y,
                                       float *z)
{
    uint32_t j, filled = 0;
    for (j = 0; j + 4u <= m; j += 4u)
    {
        const __m128i kv = _mm_loadu_si128((const __m128i *)(const void *)(idx + j));
        const __m128 keep = _mm_castsi128_ps(_mm_cmpgt_epi32(kv, _mm_set1_epi32(-1)));
        const int32_t k0 = idx[j], k1 = idx[j + 1u], k2 = idx[j + 2u], k3 = idx[j + 3u];
        __m128 r0 = _mm_loadu_ps(src + (size_t)((uint32_t)k0 & (0u - (uint32_t)(k0 >= 0))) * 4u);
        __m128 r1 = _mm_loadu_ps(src + (size_t)((uint32_t)k1 & (0u - (uint32_t)(k1 >= 0))) * 4u);
        __m128 r2 = _mm_loadu_ps(src + (size_t)((uint32_t)k2 & (0u - (uint32_t)(k2 >= 0))) * 4u);
        __m128 r3 = _mm_loadu_ps(src + (size_t)((uint32_t)k3 & (0u - (uint32_t)(k3 >= 0))) * 4u);
        _MM_TRANSPOSE4_PS(r0, r1, r2, r3);
        _mm_storeu_ps(x + j, _mm_and_ps(r0, keep));
        _mm_storeu_ps(y + j, _mm_and_ps(r1, keep));
        _mm_storeu_ps(z + j, _mm_and_ps(r2, keep));
        filled += (uint32_t)(0x4332322132212110ull >> (4u * (uint32_t)_mm_movemask_ps(keep))) & 15u;
    }
    return filled + gather_winners(idx + j, src, 4u, m - j, x + j, y + j, z + j);
}
#define GATHER_WINNERS(idx, src, stride, m, x, y, z)                                                         \
    ((stride) == 4u ? gather_winners4(idx, src, m, x, y, z) : gather_winners(idx, src, stride, m, x, y, z))
#else
#define GATHER_WINNERS gather_winners
#endif

/* (b) of pass2_compact: the rounding of one block, a loop without branches or indexed loads (an AVX2 variant on
 * x86-64 hosts, internal/lidet_simd.h; the gather (a) stays a plain loop: compiled for AVX2 it becomes hardware
 * gathers, measured slower) */
LIDET_CLONES_AVX2 static void round_block(const float *bx, const float *by, const float *bz, uint32_t m,
                                          int16_t *xo, int16_t *yo, int16_t *zo, uint16_t *ro)
{
    uint32_t j;
    for (j = 0; j < m; ++j)
    {
        /* a winner's squared range, the very expression of pass 1 (key_block: x^2 + y^2, then + z^2; no
         * contraction), so the same bits (<= max2 <= 131^2 m^2 by the range test); 0 for an empty pixel */
        const float r = sqrtf((bx[j] * bx[j] + by[j] * by[j]) + bz[j] * bz[j]);
        const int32_t rq = to_4mm(r);
        xo[j] = (int16_t)to_4mm(bx[j]);
        yo[j] = (int16_t)to_4mm(by[j]);
        zo[j] = (int16_t)to_4mm(bz[j]);
        ro[j] = (uint16_t)(rq + (int32_t)((r > 0.0f) & (rq == 0)));
    }
}

/* Pass 2 of a compact image (see pass 2 below for the float one): each winner's coordinates and range,
 * rounded to 4 mm steps; the range is the float path's sqrtf of the same squared range (recomputed from the
 * gathered coordinates by pass 1's expression, so pass 2 need not read pass 1's keys back), so the compact
 * image is the float image rounded. A valid pixel's range is >= 1 step
 * (a point closer than 2 mm, possible with min_range_m 0, would otherwise read as empty). In blocks of
 * COMPACT_BLOCK pixels (2.25 KiB of stack): (a) a branch-free gather of the winners' coordinates (an
 * empty pixel reads record 0 masked to +0); (b) the rounding, in a loop without
 * branches that compilers vectorise. */
#define COMPACT_BLOCK 192u
static uint32_t pass2_compact(const lidet_proj_buffers_t *buf, const float *points, uint32_t stride,
                              uint32_t begin, uint32_t end, int any)
{
    const float *const src = any ? points : k_zero_rec; /* points may be NULL if n = 0 */
    const int32_t *const idx = buf->point_idx;
    int16_t *const xo = buf->x_4mm, *const yo = buf->y_4mm, *const zo = buf->z_4mm;
    uint16_t *const ro = buf->range_4mm;
    float *const rxy = buf->rxy_m; /* optional: R of the rounded x, y */
    float bx[COMPACT_BLOCK], by[COMPACT_BLOCK], bz[COMPACT_BLOCK];
    uint32_t base, filled = 0;
    for (base = begin; base < end; base += COMPACT_BLOCK)
    {
        const uint32_t m = end - base < COMPACT_BLOCK ? end - base : COMPACT_BLOCK;
        filled += GATHER_WINNERS(idx + base, src, stride, m, bx, by, bz);
        round_block(bx, by, bz, m, xo + base, yo + base, zo + base, ro + base);
        /* R in a second streaming loop: fused into round_block it did not vectorise (VLP-16 0.18 -> 0.27 ms) */
        if (rxy != 0)
        {
            lidet__rxy_4mm(xo + base, yo + base, m, rxy + base);
        }
    }
    return filled;
}

/* Pass 2 of a float image over pixels [begin, end), in blocks that stay in L1 (see pass2()) */
static uint32_t pass2_float(const lidet_proj_buffers_t *buf, const float *points, uint32_t stride,
                            uint32_t begin, uint32_t end, float max2, int any)
{
    const float *const src = any ? points : k_zero_rec; /* points may be NULL if n = 0 */
    float *const xo = buf->x_m, *const yo = buf->y_m, *const zo = buf->z_m;
    float *const ro = buf->rxy_m, *const rng = buf->range_m; /* ro may be NULL */
    const int32_t *const idx = buf->point_idx;
    uint32_t filled = 0, base, pix;
    for (base = begin; base < end; base += PASS2_BLOCK)
    {
        const uint32_t stop = end - base < PASS2_BLOCK ? end : base + PASS2_BLOCK;
        filled += GATHER_WINNERS(idx + base, src, stride, stop - base, xo + base, yo + base, zo + base);
        if (ro != 0)
        {
            for (pix = base; pix < stop; ++pix)
            {
                const float x = xo[pix], y = yo[pix], b = rng[pix];
                ro[pix] = lidet__rxy(x, y);
                rng[pix] = b <= max2 ? sqrtf(b) : 0.0f;
            }
        }
        else
        {
            for (pix = base; pix < stop; ++pix)
            {
                const float b = rng[pix];
                rng[pix] = b <= max2 ? sqrtf(b) : 0.0f;
            }
        }
    }
    return filled;
}

/* The pixels [begin, end) of every plane of the output image set to empty (0) */
static void clear_pixels(const lidet_proj_buffers_t *buf, int compact, uint32_t begin, uint32_t end)
{
    const size_t n = (size_t)(end - begin);
    if (n == 0u)
    {
        return;
    }
    if (compact)
    {
        memset(buf->x_4mm + begin, 0, n * sizeof buf->x_4mm[0]);
        memset(buf->y_4mm + begin, 0, n * sizeof buf->y_4mm[0]);
        memset(buf->z_4mm + begin, 0, n * sizeof buf->z_4mm[0]);
        memset(buf->range_4mm + begin, 0, n * sizeof buf->range_4mm[0]);
    }
    else
    {
        memset(buf->x_m + begin, 0, n * sizeof buf->x_m[0]);
        memset(buf->y_m + begin, 0, n * sizeof buf->y_m[0]);
        memset(buf->z_m + begin, 0, n * sizeof buf->z_m[0]);
        memset(buf->range_m + begin, 0, n * sizeof buf->range_m[0]);
    }
    if (buf->rxy_m != 0)
    {
        memset(buf->rxy_m + begin, 0, n * sizeof buf->rxy_m[0]);
    }
}

/* pass 1's constants, read once from the state and the configuration: kept in locals (the stores of pass 1 could
 * alias the state's float fields otherwise) */
typedef struct
{
    float min2, max2; /* squared range limits */
    float tan_lo, tan_hi, row_scale, col_scale, last_col_bucket;
    float win_dlo, win_dhi; /* the azimuth window's keys: col_edge[win_lo], col_edge[win_hi] */
    int row_single, col_single;
    const float *row_bound;
    const float *col_edge;
    const uint8_t *row_lut;
    const uint16_t *col_lut;
    const uint8_t *ring_to_row;
    uint32_t rows, cols;
} pass1_t;

/* The azimuth window's block pre-test of pass 1: a block wholly outside the window (a third to two thirds of a
 * scan, whose points come in azimuth order, with the camera crop) is counted without its keys. Returns 1 when
 * the block was counted that way (its points' pixels -1), 0 when its points go through (a) - (c). */
static int block_outside_window(const lidet_proj_state_t *proj, const pass1_t *k, const float *points,
                                uint32_t stride, uint32_t base, uint32_t m, int32_t *point_pixel,
                                lidet_proj_stats_t *st)
{
    uint32_t nin, j;
    const int wide = proj->win_test == 2u;
    const uint32_t all = stride == 4u ? outside_block4(points + (size_t)base * 4u, m, k->min2, k->max2,
                                                       proj->win_edge, wide, &nin)
                                      : outside_block(points + (size_t)base * stride, m, stride, k->min2,
                                                      k->max2, proj->win_edge, wide, &nin);
    if (!all)
    {
        return 0;
    }
    st->n_out_of_window += nin;
    for (j = 0; nin < m && j < m; ++j)
    {
        /* the block's points out of range, classified as in (b) */
        const float *pt = points + (size_t)(base + j) * stride;
        float rxy2, sa;
        const float r2 = range_terms(pt[0], pt[1], pt[2], &rxy2, &sa);
        if (!((r2 >= k->min2) & (r2 <= k->max2)))
            count_out_of_range(pt, r2, k->min2, st);
    }
    if (point_pixel != 0)
    {
        memset(point_pixel + base, 0xFF, m * sizeof point_pixel[0]);
    }
    return 1;
}

/* (b) of pass 1: the pixel of each of the block's m points (kb->pix, -1 = not projected; a point that is not is
 * counted by its reason), and the projected ones listed in point order: kb->row_k[i] their pixels and
 * kb->col_k[i] their block indices. Returns how many were projected. */
static uint32_t pixels_of_block(const lidet_proj_state_t *proj, const pass1_t *k, key_block_t *kb,
                                const float *points, uint32_t stride, const uint16_t *ring, uint32_t base,
                                uint32_t m, lidet_proj_stats_t *st)
{
    const uint32_t rows = k->rows, cols = k->cols;
    const float *const row_bound = k->row_bound;
    const float *const col_edge = k->col_edge;
    /* the rest of k in locals too: the int32 stores into kb below may alias k's integer fields */
    const uint8_t *const row_lut = k->row_lut;
    const uint16_t *const col_lut = k->col_lut;
    const uint8_t *const ring_to_row = k->ring_to_row;
    const int row_single = k->row_single, col_single = k->col_single;
    const float win_dlo = k->win_dlo, win_dhi = k->win_dhi, col_scale = k->col_scale, min2 = k->min2;
    uint32_t j, nw = 0;
    (void)proj; /* read by the assertion only */
    for (j = 0; j < m; ++j)
    {
        const uint32_t i = base + j;
        const float t = kb->t[j];
        float d = kb->d[j];
        int32_t row, col, col_k = kb->col_k[j];
        uint32_t pix;
        if (kb->flags[j] != KEY_ALL)
        {
            /* one test covered NaN, Inf, overflow and both range limits; classify only now */
            if (!(kb->flags[j] & KEY_RANGE_OK))
            {
                count_out_of_range(points + (size_t)i * stride, kb->r2[j], min2, st);
                kb->pix[j] = -1;
                continue;
            }
            if (!(kb->flags[j] & KEY_DEN_OK))
            {
                if (ring == 0) /* no azimuth (x = y = 0, or ~1e-19): no elevation either */
                {
                    ++st->n_out_of_fov;
                    kb->pix[j] = -1;
                    continue;
                }
                d = 2.0f; /* ring path: straight ahead */
                col_k = (int32_t)(d * col_scale);
            }
        }
        /* the azimuth window, before the elevation and ring tests (as the block pre-test) and the row and
         * column searches: column c holds exactly the keys col_edge[c] <= d < col_edge[c + 1], so this is
         * the test of the column the search would find */
        if (!(d >= win_dlo && d < win_dhi))
        {
            ++st->n_out_of_window;
            kb->pix[j] = -1;
            continue;
        }
        if (ring == 0 ? !(kb->flags[j] & KEY_FOV_OK) : ring[i] >= rows)
        {
            /* elevation outside the beams (+ margin), or a ring index past the rows */
            if (ring == 0)
                ++st->n_out_of_fov;
            else
                ++st->n_bad_ring;
            kb->pix[j] = -1;
            continue;
        }
        if (ring != 0)
        {
            row = ring_to_row[ring[i]];
        }
        else
        {
            row = row_lut[kb->row_k[j]];
            /* exact nearest beam: correct the bucket's guess against the mid-angle tangents (ties
             * go to the upper row); the sentinels stop the loops of the dense-table fallback */
            if (row_single)
            {
                /* the second test reads the boundary the first one moved to (both loaded at once) */
                const float b0 = row_bound[row], b1 = row_bound[row + 1];
                const int32_t up = (int32_t)(b0 <= t);
                row += (int32_t)((up ? b0 : b1) > t) - up;
            }
            else
            {
                while (row_bound[row] <= t)
                    --row;
                while (row_bound[row + 1] > t)
                    ++row;
            }
        }
        col = col_lut[col_k];
        if (col_single)
        {
            const float e0 = col_edge[col], e1 = col_edge[col + 1];
            const int32_t left = (int32_t)(e0 > d);
            col += (int32_t)((left ? e0 : e1) <= d) - left;
        }
        else
        {
            while (col_edge[col] > d)
                --col;
            while (col_edge[col + 1] <= d)
                ++col;
        }
        LIDET_ASSERT((uint32_t)col >= proj->win_lo && (uint32_t)col < proj->win_hi);
        pix = (uint32_t)row * cols + (uint32_t)col;
        LIDET_ASSERT(pix < rows * cols);
        kb->pix[j] = (int32_t)pix;
        /* nw <= j: the entries rewritten here have been read already */
        kb->row_k[nw] = (int32_t)pix;
        kb->col_k[nw] = (int32_t)j;
        ++nw;
    }
    return nw;
}

/* whether (b) may take pixels_all_in for the block's m points: every one has its keys (KEY_ALL) and lies in the
 * azimuth window (pixels_of_block's tests); a loop without branches, which compilers vectorize */
static int block_all_in(const key_block_t *kb, uint32_t m, float win_dlo, float win_dhi)
{
    uint32_t j;
    int32_t ok = 1;
    for (j = 0; j < m; ++j)
    {
        ok &= (int32_t)(kb->flags[j] == KEY_ALL) & (int32_t)(kb->d[j] >= win_dlo) &
              (int32_t)(kb->d[j] < win_dhi);
    }
    return ok;
}

/* (b) of a block that block_all_in passed, on the elevation path (no ring) with one correction step each way
 * (row_single, col_single): pixels_of_block's pixels (kb->pix only: every point projected, so (c) reads them
 * there, keep_closest_all), in a loop without branches (the block's tests made once). Also built for AVX2 on
 * x86-64 hosts (internal/lidet_simd.h; a scalar loop, whose selects of two floats become one blend there: the HDL-64
 * projection of real KITTI scans 0.95 -> 0.92 ms, one x86-64 core). Returns m */
LIDET_CLONES_AVX2 static uint32_t pixels_all_in(const lidet_proj_state_t *proj, const pass1_t *k,
                                                key_block_t *kb, uint32_t m)
{
    const uint32_t cols = k->cols;
    const float *const row_bound = k->row_bound;
    const float *const col_edge = k->col_edge;
    const uint8_t *const row_lut = k->row_lut;
    const uint16_t *const col_lut = k->col_lut;
    uint32_t j;
    (void)proj; /* read by the assertion only */
    for (j = 0; j < m; ++j)
    {
        const float t = kb->t[j], d = kb->d[j];
        int32_t row = row_lut[kb->row_k[j]], col = col_lut[kb->col_k[j]];
        uint32_t pix;
        /* pixels_of_block's one-step corrections, with both boundaries of the guess loaded at once: the second
         * test reads the boundary the first one moved to (row_bound[row + 1] after row -= 1 is row_bound[row]) */
        const float b0 = row_bound[row], b1 = row_bound[row + 1], e0 = col_edge[col], e1 = col_edge[col + 1];
        const int32_t up = (int32_t)(b0 <= t), left = (int32_t)(e0 > d);
        row += (int32_t)((up ? b0 : b1) > t) - up;
        col += (int32_t)((left ? e0 : e1) <= d) - left;
        LIDET_ASSERT((uint32_t)col >= proj->win_lo && (uint32_t)col < proj->win_hi);
        pix = (uint32_t)row * cols + (uint32_t)col;
        kb->pix[j] = (int32_t)pix;
    }
    return m;
}

/* (c) of pass 1, in point order: the closest point per pixel among the block's nw projected points (strict test,
 * exact ties keep the earlier point); the winner's squared range is kept in best (a float plane: a float image's
 * range_m, or a compact image's rxy_m when it has one), else (a compact image without R) its bits in range_4mm
 * (high half) and z_4mm (low half) */
static void keep_closest(const lidet_proj_buffers_t *buf, float *best, const key_block_t *kb, uint32_t base,
                         uint32_t nw)
{
    int32_t *const point_idx = buf->point_idx;
    uint32_t j;
    if (best != 0)
    {
        for (j = 0; j < nw; ++j)
        {
            const uint32_t p = (uint32_t)kb->row_k[j];
            const uint32_t jj = (uint32_t)kb->col_k[j];
            const float r2 = kb->r2[jj];
            if (r2 < best[p])
            {
                best[p] = r2;
                point_idx[p] = (int32_t)(base + jj);
            }
        }
    }
    else
    {
        uint16_t *const key_hi = buf->range_4mm; /* compact image: its bits, high and low halves */
        int16_t *const key_lo = buf->z_4mm;
        for (j = 0; j < nw; ++j)
        {
            const uint32_t p = (uint32_t)kb->row_k[j];
            const uint32_t jj = (uint32_t)kb->col_k[j];
            const uint32_t key = ((uint32_t)key_hi[p] << 16) | (uint16_t)key_lo[p];
            uint32_t r2;
            memcpy(&r2, &kb->r2[jj], sizeof r2);
            /* r2 < the key, as unsigned 32-bit values (r2 >= 0 here: the range test passed) */
            if (r2 < key)
            {
                key_hi[p] = (uint16_t)(r2 >> 16);
                key_lo[p] = (int16_t)(uint16_t)(r2 & 0xFFFFu); /* two's complement: C99 int16_t */
                point_idx[p] = (int32_t)(base + jj);
            }
        }
    }
}

/* (c) after pixels_all_in (every point of the block projected): keep_closest with the block's points in order, read
 * from kb->pix and kb->r2 directly */
static void keep_closest_all(const lidet_proj_buffers_t *buf, float *best, const key_block_t *kb,
                             uint32_t base, uint32_t m)
{
    int32_t *const point_idx = buf->point_idx;
    uint32_t j;
    for (j = 0; j < m; ++j)
    {
        const uint32_t p = (uint32_t)kb->pix[j];
        const float r2 = kb->r2[j];
        if (r2 < best[p])
        {
            best[p] = r2;
            point_idx[p] = (int32_t)(base + j);
        }
    }
}

/* Pass 1, over points in blocks (see KEY_BLOCK): pixel of each point and the closest point per pixel. best (range_m,
 * or a compact image's rxy_m) holds the winner's squared range until pass 2, starting at 3.39e38 (every byte 0x7F),
 * above any accepted r^2 (max2 <= 3.0e38), so the winner test needs no emptiness check. A block whose points all
 * pass its tests (most of a full scan's) takes pixels_all_in and keep_closest_all, the others pixels_of_block and
 * keep_closest (the same pixels and winners). Returns the number of points projected. */
static uint32_t pass1(const lidet_proj_state_t *proj, const lidet_proj_buffers_t *buf, const float *points,
                      uint32_t n, uint32_t stride, const uint16_t *ring, float min2, float max2, int compact,
                      lidet_proj_stats_t *st)
{
    const uint32_t npix = proj->cfg.sensor.n_rows * proj->cfg.sensor.n_cols;
    /* the winners' squared ranges: a float image's range plane; a compact image's R plane, which pass 2 rewrites
     * (one 4-byte load and store per point, where the two halves below take two each: 0.05 ms of the 1.2 ms
     * HDL-64 projection of real KITTI scans, one x86-64 core) */
    float *const best = !compact ? buf->range_m : buf->rxy_m;
    memset(buf->point_idx, 0xFF, (size_t)npix * sizeof buf->point_idx[0]);
    if (best != 0)
    {
        memset(best, 0x7F, (size_t)npix * sizeof best[0]);
    }
    else
    {
        /* a compact image without R: the squared range's bits, high half in range_4mm and low half in z_4mm
         * until pass 2 (a positive float orders as its bits do, so the winner test is the float one, exactly) */
        memset(buf->range_4mm, 0x7F, (size_t)npix * sizeof buf->range_4mm[0]);
        memset(buf->z_4mm, 0x7F, (size_t)npix * sizeof buf->z_4mm[0]);
    }
    {
        pass1_t k;
        int32_t *const point_pixel = buf->point_pixel; /* may be NULL: per-point outputs not wanted */
        uint32_t base, projected = 0;
        key_block_t kb;
        k.min2 = min2;
        k.max2 = max2;
        k.tan_lo = proj->tan_lo;
        k.tan_hi = proj->tan_hi;
        k.row_scale = proj->lut_scale;
        k.col_scale = proj->col_lut_scale;
        k.rows = proj->cfg.sensor.n_rows;
        k.cols = proj->cfg.sensor.n_cols;
        k.last_col_bucket = (float)(4u * k.cols);
        k.row_single = proj->row_single_step;
        k.col_single = proj->col_single_step;
        k.row_bound = proj->row_bound_tan;
        k.col_edge = proj->col_edge_key;
        k.win_dlo = k.col_edge[proj->win_lo];
        k.win_dhi = k.col_edge[proj->win_hi]; /* [n_cols]: > any d */
        k.row_lut = proj->row_lut;
        k.col_lut = proj->col_lut;
        k.ring_to_row = proj->ring_to_row;

        for (base = 0; base < n; base += KEY_BLOCK)
        {
            const uint32_t m = n - base < KEY_BLOCK ? n - base : KEY_BLOCK;
            uint32_t nw;
            if (proj->win_test != 0u &&
                block_outside_window(proj, &k, points, stride, base, m, point_pixel, st))
            {
                continue;
            }
            /* (a); KITTI-style records (stride 4) get their own copy, with a constant stride */
            if (stride == 4u)
                key_block4(&kb, points + (size_t)base * 4u, m, k.min2, k.max2, k.tan_lo, k.tan_hi,
                           k.row_scale, k.col_scale, k.last_col_bucket);
            else
                key_block(&kb, points + (size_t)base * stride, m, stride, k.min2, k.max2, k.tan_lo, k.tan_hi,
                          k.row_scale, k.col_scale, k.last_col_bucket);
            /* (b), (c) */
            if (ring == 0 && best != 0 && k.row_single && k.col_single &&
                block_all_in(&kb, m, k.win_dlo, k.win_dhi))
            {
                nw = pixels_all_in(proj, &k, &kb, m);
                keep_closest_all(buf, best, &kb, base, nw);
            }
            else
            {
                nw = pixels_of_block(proj, &k, &kb, points, stride, ring, base, m, st);
                keep_closest(buf, best, &kb, base, nw);
            }
            projected += nw;
            if (point_pixel != 0) /* per-point outputs only when asked for */
            {
                memcpy(point_pixel + base, kb.pix, m * sizeof kb.pix[0]);
            }
        }
        return projected;
    }
}

/* Pass 2, over pixels, in blocks that stay in L1: (a) gather each winner's coordinates, an empty pixel reading
 * record 0 masked to +0 (no branch: 21 % of KITTI pixels are empty, scattered); (b) the square roots of the block
 * in a loop compilers vectorize: R from x and y, the range from the squared range (0x7F7F7F7F > max2 marks an
 * empty pixel). Writing the coordinates here rather than on every win in pass 1 keeps pass 1's working set at
 * two arrays (index + squared range): measured 16.6 vs 17.8 ns/point on real KITTI scans, six scattered 512 KiB
 * arrays overflow L2. Returns the number of pixels filled. */
static uint32_t pass2(const lidet_proj_state_t *proj, const lidet_proj_buffers_t *buf, const float *points,
                      uint32_t stride, float max2, int compact, int any)
{
    const uint32_t rows = proj->cfg.sensor.n_rows, cols = proj->cfg.sensor.n_cols;
    if (proj->win_lo > 0u || proj->win_hi < cols)
    {
        /* an azimuth window: pass 2 over its columns only, the pixels beside it cleared (no point reached them) */
        uint32_t r, filled = 0;
        for (r = 0; r < rows; ++r)
        {
            const uint32_t base = r * cols;
            clear_pixels(buf, compact, base, base + proj->win_lo);
            clear_pixels(buf, compact, base + proj->win_hi, base + cols);
            filled +=
                compact
                    ? pass2_compact(buf, points, stride, base + proj->win_lo, base + proj->win_hi, any)
                    : pass2_float(buf, points, stride, base + proj->win_lo, base + proj->win_hi, max2, any);
        }
        return filled;
    }
    if (compact)
    {
        return pass2_compact(buf, points, stride, 0u, rows * cols, any);
    }
    return pass2_float(buf, points, stride, 0u, rows * cols, max2, any);
}

lidet_status_t lidet_proj_run_buffers(lidet_proj_state_t *proj, const lidet_proj_buffers_t *buf,
                                      const float *points, uint32_t n_points, uint32_t stride,
                                      const uint16_t *ring)
{
    uint32_t n;
    float min2, max2;
    lidet_proj_stats_t st;
    int compact;

    if (proj == 0 || buf == 0 || stride < 3 || (points == 0 && n_points > 0))
    {
        return LIDET_ERR_ARG;
    }
    compact = buf->x_m == 0;
    if (buf->point_idx == 0 || (!compact && (buf->y_m == 0 || buf->z_m == 0 || buf->range_m == 0)) ||
        (compact && (buf->x_4mm == 0 || buf->y_4mm == 0 || buf->z_4mm == 0 || buf->range_4mm == 0)))
    {
        return LIDET_ERR_ARG;
    }
    if (proj->magic != LIDET_INIT_MAGIC)
    {
        return LIDET_ERR_STATE;
    }
    n = n_points > LIDET_MAX_POINTS ? LIDET_MAX_POINTS : n_points;
    memset(&st, 0, sizeof st);
    st.n_points_in = n_points;
    st.n_truncated = n_points - n;
    /* squared limits; zero range is always "too close", no limit means "finite" */
    min2 = proj->cfg.min_range_m * proj->cfg.min_range_m;
    min2 = min2 > 1.0e-30f ? min2 : 1.0e-30f;
    max2 = proj->cfg.max_range_m > 0.0f ? proj->cfg.max_range_m * proj->cfg.max_range_m : 3.0e38f;
    if (compact && max2 > LIDET_PIXEL_MAX_RANGE_M * LIDET_PIXEL_MAX_RANGE_M)
    {
        /* a compact image holds int16 coordinates in 4 mm steps: farther points are dropped, never wrapped */
        max2 = LIDET_PIXEL_MAX_RANGE_M * LIDET_PIXEL_MAX_RANGE_M;
    }
    st.n_projected = pass1(proj, buf, points, n, stride, ring, min2, max2, compact, &st);
    st.n_pixels_filled = pass2(proj, buf, points, stride, max2, compact, st.n_projected > 0);
    proj->n_points = n;
    proj->stats = st;
    return st.n_truncated > 0 ? LIDET_TRUNCATED : LIDET_OK;
}

static void own_buffers(lidet_proj_t *proj, lidet_proj_buffers_t *b)
{
    b->x_m = proj->x_m;
    b->y_m = proj->y_m;
    b->z_m = proj->z_m;
    b->range_m = proj->range_m;
    b->x_4mm = 0;
    b->y_4mm = 0;
    b->z_4mm = 0;
    b->range_4mm = 0;
    b->rxy_m = proj->rxy_m;
    b->point_idx = proj->point_idx;
    b->point_pixel = proj->point_pixel;
}

lidet_status_t lidet_proj_run(lidet_proj_t *proj, const float *points, uint32_t n_points, uint32_t stride,
                              const uint16_t *ring)
{
    lidet_proj_buffers_t b;
    if (proj == 0)
    {
        return LIDET_ERR_ARG;
    }
    own_buffers(proj, &b);
    return lidet_proj_run_buffers(&proj->state, &b, points, n_points, stride, ring);
}

void lidet_proj_image_of(const lidet_proj_state_t *st, const lidet_proj_buffers_t *buf,
                         lidet_range_image_t *img)
{
    if (st == 0 || buf == 0 || img == 0)
    {
        return;
    }
    img->n_rows = st->cfg.sensor.n_rows;
    img->n_cols = st->cfg.sensor.n_cols;
    img->x_m = buf->x_m;
    img->y_m = buf->y_m;
    img->z_m = buf->z_m;
    img->range_m = buf->range_m;
    img->x_4mm = buf->x_4mm;
    img->y_4mm = buf->y_4mm;
    img->z_4mm = buf->z_4mm;
    img->range_4mm = buf->range_4mm;
    img->rxy_m = buf->rxy_m;
    img->point_idx = buf->point_idx;
    img->row_elev_rad = st->row_elev_rad;
    img->row_elev_bam = st->row_elev_bam;
}

void lidet_proj_image(const lidet_proj_t *proj, lidet_range_image_t *img)
{
    if (proj == 0 || img == 0)
    {
        return;
    }
    img->n_rows = proj->state.cfg.sensor.n_rows;
    img->n_cols = proj->state.cfg.sensor.n_cols;
    img->x_m = proj->x_m;
    img->y_m = proj->y_m;
    img->z_m = proj->z_m;
    img->range_m = proj->range_m;
    img->x_4mm = 0;
    img->y_4mm = 0;
    img->z_4mm = 0;
    img->range_4mm = 0;
    img->rxy_m = proj->rxy_m;
    img->point_idx = proj->point_idx;
    img->row_elev_rad = proj->state.row_elev_rad;
    img->row_elev_bam = proj->state.row_elev_bam;
}

const int32_t *lidet_proj_point_pixels(const lidet_proj_t *proj, uint32_t *n_points)
{
    if (proj == 0)
    {
        return 0;
    }
    if (n_points != 0)
    {
        *n_points = proj->state.n_points;
    }
    return proj->point_pixel;
}

const lidet_proj_stats_t *lidet_proj_stats(const lidet_proj_t *proj)
{
    return proj == 0 ? 0 : &proj->state.stats;
}

uint32_t lidet_proj_bytes(void)
{
    return (uint32_t)sizeof(lidet_proj_t);
}

uint32_t lidet_proj_state_bytes(void)
{
    return (uint32_t)sizeof(lidet_proj_state_t);
}
