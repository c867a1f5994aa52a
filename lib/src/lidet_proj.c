/* SPDX-License-Identifier: MIT */
/* Spherical projection (see lidet_proj.h for the algorithm and memory).
 * Mirrored by codegen/lidet_codegen/ref/proj.py (the numpy reference used by the tests). */
#include <math.h>
#include <string.h>

#include "internal/lidet_assert.h"
#include "internal/lidet_math.h"
#include "lidet/lidet_proj.h"

#define DEG2RAD 0.0174532925f
/* keep every accepted elevation away from +-90 deg so its tangent stays finite */
#define MAX_ABS_ELEV_RAD 1.55f

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
    cfg->fov_margin_rad = 5.0f * DEG2RAD;
}

static int in_range(float v, float lo, float hi)
{
    return lidet__isfinite(v) && v >= lo && v <= hi;
}

/* Column c spans u = (pi - azimuth) / (2 pi) in [c/cols, (c+1)/cols). In pseudo-azimuth terms, with
 * v = 4u = quadrant + f (f in [0, 1)), D(u) = quadrant + g(f pi/2), g(t) = sin t / (sin t + cos t)
 * (derived from the four quadrant cases of lidet__azimuth_key). Computing the edges from (quadrant,
 * f) keeps them exact at the quadrant seams, where sin/cos of pi-sized floats would lose the sign. */
static void init_columns(lidet_proj_t *proj, uint32_t cols)
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
    proj->col_edge_key[0] = -1.0f;   /* below any D (which may be -1 ulp): ends the downward correction */
    proj->col_edge_key[cols] = 5.0f; /* D <= 4 < 5: ends the upward correction (D = 4 stays in the last column) */
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

lidet_status_t lidet_proj_init(lidet_proj_t *proj, const lidet_proj_cfg_t *cfg)
{
    const lidet_sensor_t *s;
    float elev[LIDET_MAX_ROWS];
    uint8_t ring_of_row[LIDET_MAX_ROWS];
    float top_rad, bottom_rad, span;
    uint32_t rows, r, k;

    if (proj == 0 || cfg == 0)
    {
        return LIDET_ERR_ARG;
    }
    proj->magic = 0;
    s = &cfg->sensor;
    if (s->n_rows == 0 || s->n_cols < 8)
    {
        return LIDET_ERR_CONFIG;
    }
    if (s->n_rows > LIDET_MAX_ROWS || s->n_cols > LIDET_MAX_COLS)
    {
        return LIDET_ERR_BUFFER;
    }
    if (!in_range(cfg->min_range_m, 0.0f, 10.0f) || !in_range(cfg->fov_margin_rad, 0.0f, 0.5f) ||
        !in_range(cfg->max_range_m, 0.0f, 1.0e6f) ||
        (cfg->max_range_m > 0.0f && cfg->max_range_m <= cfg->min_range_m))
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
            !in_range(s->fov_down_rad, -MAX_ABS_ELEV_RAD, MAX_ABS_ELEV_RAD) || s->fov_up_rad <= s->fov_down_rad)
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
    for (r = 0; r < rows; ++r)
    {
        uint32_t j = r;
        while (j > 0 && elev[ring_of_row[j - 1]] < elev[r])
        {
            ring_of_row[j] = ring_of_row[j - 1];
            --j;
        }
        ring_of_row[j] = (uint8_t)r;
    }
    for (r = 0; r < rows; ++r)
    {
        proj->row_elev_rad[r] = elev[ring_of_row[r]];
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
    proj->cfg = *cfg;
    proj->cfg.sensor.beam_elev_rad = 0; /* not retained: the caller's table may go away */
    proj->n_points = 0;
    memset(&proj->stats, 0, sizeof proj->stats);
    proj->magic = LIDET_INIT_MAGIC;
    return LIDET_OK;
}

float lidet_proj_azimuth_key(float x, float y)
{
    float t, d, rxy;
    lidet__proj_keys(x, y, 0.0f, x * x + y * y, &t, &d, &rxy);
    return d;
}

lidet_status_t lidet_proj_run(lidet_proj_t *proj, const float *points, uint32_t n_points, uint32_t stride,
                              const uint16_t *ring)
{
    uint32_t n, i, rows, cols, npix, pix;
    float min2, max2;
    lidet_proj_stats_t st;

    if (proj == 0 || stride < 3 || (points == 0 && n_points > 0))
    {
        return LIDET_ERR_ARG;
    }
    if (proj->magic != LIDET_INIT_MAGIC)
    {
        return LIDET_ERR_STATE;
    }
    rows = proj->cfg.sensor.n_rows;
    cols = proj->cfg.sensor.n_cols;
    npix = rows * cols;
    n = n_points > LIDET_MAX_POINTS ? LIDET_MAX_POINTS : n_points;
    memset(&st, 0, sizeof st);
    st.n_points_in = n_points;
    st.n_truncated = n_points - n;
    /* squared limits; zero range is always "too close", no limit means "finite" */
    min2 = proj->cfg.min_range_m * proj->cfg.min_range_m;
    min2 = min2 > 1.0e-30f ? min2 : 1.0e-30f;
    max2 = proj->cfg.max_range_m > 0.0f ? proj->cfg.max_range_m * proj->cfg.max_range_m : 3.0e38f;

    /* pass 1, over points: pixel of each point and the closest point per pixel. range_m holds the
     * winner's squared range until pass 2, starting at 3.39e38 (every byte 0x7F), above any accepted r^2 (max2 <= 3.0e38), so the winner test needs no emptiness check.
     * Invariants live in locals: the stores below could alias the state's float fields otherwise. */
    memset(proj->point_idx, 0xFF, (size_t)npix * sizeof proj->point_idx[0]);
    memset(proj->range_m, 0x7F, (size_t)npix * sizeof proj->range_m[0]);
    {
        const float tan_lo = proj->tan_lo, tan_hi = proj->tan_hi, row_scale = proj->lut_scale;
        const float col_scale = proj->col_lut_scale;
        const int32_t last_col_bucket = 4 * (int32_t)cols;
        const int row_single = proj->row_single_step, col_single = proj->col_single_step;
        const float *const row_bound = proj->row_bound_tan;
        const float *const col_edge = proj->col_edge_key;
        const uint8_t *const row_lut = proj->row_lut;
        const uint16_t *const col_lut = proj->col_lut;
        const uint8_t *const ring_to_row = proj->ring_to_row;
        int32_t *const point_idx = proj->point_idx;
        int32_t *const point_pixel = proj->point_pixel;
        float *const best = proj->range_m;

        for (i = 0; i < n; ++i)
        {
            const float *pt = points + (size_t)i * stride;
            const float x = pt[0], y = pt[1], z = pt[2];
            const float rxy2 = x * x + y * y;
            const float r2 = rxy2 + z * z;
            float t, d, rxy;
            int32_t row, col, k;

            /* one test covers NaN, Inf, overflow and both range limits; classify only when it fails */
            if (!(r2 >= min2 && r2 <= max2))
            {
                if (!lidet__isfinite(x) || !lidet__isfinite(y) || !lidet__isfinite(z))
                    ++st.n_nonfinite;
                else if (r2 < min2)
                    ++st.n_too_close;
                else
                    ++st.n_too_far; /* beyond max_range_m, or so large that r^2 overflows */
                point_pixel[i] = -1;
                continue;
            }
            lidet__proj_keys(x, y, z, rxy2, &t, &d, &rxy);
            if (ring != 0)
            {
                if (ring[i] >= rows)
                {
                    ++st.n_bad_ring;
                    point_pixel[i] = -1;
                    continue;
                }
                row = ring_to_row[ring[i]];
            }
            else
            {
                if (!(t >= tan_lo && t <= tan_hi)) /* also rejects NaN: never cast */
                {
                    ++st.n_out_of_fov;
                    point_pixel[i] = -1;
                    continue;
                }
                k = (int32_t)((t - tan_lo) * row_scale); /* in [0, LIDET_PROJ_ROW_LUT] */
                row = row_lut[k];
                /* exact nearest beam: correct the bucket's guess against the mid-angle tangents (ties
                 * go to the upper row); the sentinels stop the loops of the dense-table fallback */
                if (row_single)
                {
                    row -= (int32_t)(row_bound[row] <= t);
                    row += (int32_t)(row_bound[row + 1] > t);
                }
                else
                {
                    while (row_bound[row] <= t)
                        --row;
                    while (row_bound[row + 1] > t)
                        ++row;
                }
            }
            k = (int32_t)(d * col_scale); /* d in [0, 4] up to rounding: k in [0, 4 cols] */
            k = k > last_col_bucket ? last_col_bucket : k;
            col = col_lut[k];
            if (col_single)
            {
                col -= (int32_t)(col_edge[col] > d);
                col += (int32_t)(col_edge[col + 1] <= d);
            }
            else
            {
                while (col_edge[col] > d)
                    --col;
                while (col_edge[col + 1] <= d)
                    ++col;
            }
            pix = (uint32_t)row * cols + (uint32_t)col;
            LIDET_ASSERT(pix < npix);
            point_pixel[i] = (int32_t)pix;
            ++st.n_projected;
            if (r2 < best[pix]) /* strict: exact ties keep the earlier point */
            {
                best[pix] = r2;
                point_idx[pix] = (int32_t)i;
            }
        }
    }

    /* pass 2, over pixels (sequential): gather each winner's coordinates, squared range -> range,
     * zeros for empty pixels. Writing the coordinates here rather than on every win in pass 1 keeps
     * pass 1's working set at two arrays (index + squared range): measured 16.6 vs 17.8 ns/point on
     * real KITTI scans, because six scattered 512 KiB arrays overflow L2. */
    {
        float *const range = proj->range_m;
        const int32_t *const idx = proj->point_idx;
        uint32_t filled = 0;
        for (pix = 0; pix < npix; ++pix)
        {
            const int32_t k = idx[pix];
            if (k >= 0)
            {
                const float *pt = points + (size_t)k * stride;
                const float x = pt[0], y = pt[1];
                proj->x_m[pix] = x;
                proj->y_m[pix] = y;
                proj->z_m[pix] = pt[2];
                proj->rxy_m[pix] = sqrtf(x * x + y * y);
                range[pix] = sqrtf(range[pix]);
                ++filled;
            }
            else
            {
                proj->x_m[pix] = 0.0f;
                proj->y_m[pix] = 0.0f;
                proj->z_m[pix] = 0.0f;
                proj->rxy_m[pix] = 0.0f;
                range[pix] = 0.0f;
            }
        }
        st.n_pixels_filled = filled;
    }
    proj->n_points = n;
    proj->stats = st;
    return st.n_truncated > 0 ? LIDET_TRUNCATED : LIDET_OK;
}

void lidet_proj_image(const lidet_proj_t *proj, lidet_range_image_t *img)
{
    if (proj == 0 || img == 0)
    {
        return;
    }
    img->n_rows = proj->cfg.sensor.n_rows;
    img->n_cols = proj->cfg.sensor.n_cols;
    img->x_m = proj->x_m;
    img->y_m = proj->y_m;
    img->z_m = proj->z_m;
    img->range_m = proj->range_m;
    img->rxy_m = proj->rxy_m;
    img->point_idx = proj->point_idx;
    img->row_elev_rad = proj->row_elev_rad;
}

const int32_t *lidet_proj_point_pixels(const lidet_proj_t *proj, uint32_t *n_points)
{
    if (proj == 0)
    {
        return 0;
    }
    if (n_points != 0)
    {
        *n_points = proj->n_points;
    }
    return proj->point_pixel;
}

const lidet_proj_stats_t *lidet_proj_stats(const lidet_proj_t *proj)
{
    return proj == 0 ? 0 : &proj->stats;
}

uint32_t lidet_proj_bytes(void)
{
    return (uint32_t)sizeof(lidet_proj_t);
}
