/* SPDX-License-Identifier: MIT */
/* Flat C entry points for the Python bindings (tools/lidet_tools/native.py, ctypes).
 * Host only: each stage's workspace is a static object here, so calls are not reentrant. Arrays
 * are caller-allocated numpy buffers whose sizes the Python side derives from the same inputs. */
#include <string.h>

#include "lidet/lidet.h"

#if defined(_WIN32)
#define LIDET_PY_API __declspec(dllexport)
#else
#define LIDET_PY_API __attribute__((visibility("default")))
#endif

static lidet_proj_t g_proj;

LIDET_PY_API int lidet_py_capacity(uint32_t *out)
{
    out[0] = LIDET_MAX_ROWS;
    out[1] = LIDET_MAX_COLS;
    out[2] = LIDET_MAX_POINTS;
    out[3] = LIDET_MAX_CLUSTERS;
    out[4] = LIDET_PROPOSAL_POINTS;
    out[5] = LIDET_MAX_DETECTIONS;
    return 0;
}

/* Preset number `index`: name into name_buf (64 bytes), rows/cols, elevations in ring order (rows floats,
 * the uniform-fov presets expanded exactly as lidet_proj_init does), mount height. -6 past the end. */
LIDET_PY_API int lidet_py_sensor(uint32_t index, char *name_buf, uint32_t *rows_cols, float *elev_rad,
                                 float *mount_height_m)
{
    const lidet_sensor_t *s = lidet_sensor_at(index);
    uint32_t r;
    if (s == NULL)
        return LIDET_ERR_NOT_FOUND;
    strncpy(name_buf, s->name, 63);
    name_buf[63] = '\0';
    rows_cols[0] = s->n_rows;
    rows_cols[1] = s->n_cols;
    for (r = 0; r < s->n_rows; ++r)
    {
        if (s->beam_elev_rad != NULL)
            elev_rad[r] = s->beam_elev_rad[r];
        else
            elev_rad[r] = s->fov_up_rad - ((float)r + 0.5f) * ((s->fov_up_rad - s->fov_down_rad) / (float)s->n_rows);
    }
    *mount_height_m = s->mount_height_m;
    return 0;
}

/* Initialise the projection. elev_rad may be NULL (uniform fov). */
LIDET_PY_API int lidet_py_proj_init(uint32_t rows, uint32_t cols, const float *elev_rad, float fov_up_rad,
                                    float fov_down_rad, float mount_height_m, float min_range_m, float max_range_m,
                                    float fov_margin_rad)
{
    lidet_proj_cfg_t cfg;
    lidet_sensor_t s;
    memset(&s, 0, sizeof s);
    s.name = "python";
    if (rows > 0xFFFFu || cols > 0xFFFFu)
        return LIDET_ERR_BUFFER;
    s.n_rows = (uint16_t)rows;
    s.n_cols = (uint16_t)cols;
    s.beam_elev_rad = elev_rad;
    s.fov_up_rad = fov_up_rad;
    s.fov_down_rad = fov_down_rad;
    s.mount_height_m = mount_height_m;
    lidet_proj_cfg_default(&cfg, &s);
    cfg.min_range_m = min_range_m;
    cfg.max_range_m = max_range_m;
    cfg.fov_margin_rad = fov_margin_rad;
    return lidet_proj_init(&g_proj, &cfg);
}

/* Run the projection; copy the image out. out_img: 5 * rows * cols floats (x, y, z, range, rxy planes),
 * out_idx: rows * cols int32, out_point_pixel: min(n, LIDET_MAX_POINTS) int32, out_stats: 9 uint32,
 * out_row_elev: rows floats. Any output may be NULL. */
LIDET_PY_API int lidet_py_proj_run(const float *pts, uint32_t n, uint32_t stride, const uint16_t *ring,
                                   float *out_img, int32_t *out_idx, int32_t *out_point_pixel, uint32_t *out_stats,
                                   float *out_row_elev)
{
    lidet_range_image_t img;
    const lidet_proj_stats_t *st;
    uint32_t npix, np;
    const int32_t *pp;
    const int rc = lidet_proj_run(&g_proj, pts, n, stride, ring);
    if (rc < 0)
        return rc;
    lidet_proj_image(&g_proj, &img);
    npix = (uint32_t)img.n_rows * img.n_cols;
    if (out_img != NULL)
    {
        memcpy(out_img, img.x_m, npix * sizeof(float));
        memcpy(out_img + npix, img.y_m, npix * sizeof(float));
        memcpy(out_img + 2 * npix, img.z_m, npix * sizeof(float));
        memcpy(out_img + 3 * npix, img.range_m, npix * sizeof(float));
        memcpy(out_img + 4 * npix, img.rxy_m, npix * sizeof(float));
    }
    if (out_idx != NULL)
        memcpy(out_idx, img.point_idx, npix * sizeof(int32_t));
    pp = lidet_proj_point_pixels(&g_proj, &np);
    if (out_point_pixel != NULL)
        memcpy(out_point_pixel, pp, np * sizeof(int32_t));
    st = lidet_proj_stats(&g_proj);
    if (out_stats != NULL)
    {
        out_stats[0] = st->n_points_in;
        out_stats[1] = st->n_projected;
        out_stats[2] = st->n_pixels_filled;
        out_stats[3] = st->n_nonfinite;
        out_stats[4] = st->n_too_close;
        out_stats[5] = st->n_too_far;
        out_stats[6] = st->n_out_of_fov;
        out_stats[7] = st->n_bad_ring;
        out_stats[8] = st->n_truncated;
    }
    if (out_row_elev != NULL)
        memcpy(out_row_elev, img.row_elev_rad, img.n_rows * sizeof(float));
    return rc;
}

LIDET_PY_API const char *lidet_py_status_str(int status)
{
    return lidet_status_str((lidet_status_t)status);
}
