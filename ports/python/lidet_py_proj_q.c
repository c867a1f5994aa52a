/* SPDX-License-Identifier: MIT */
/* Flat C entry points over the integer projection and the integer sensor presets for the Python bindings
 * (tools/lidet_tools/native/_proj.py: sensors_q, project_q); tests compare them with codegen/lidet_ref/proj_q.py. */
#include <stddef.h>
#include <stdlib.h>
#include <string.h>

#include "internal/lidet_qmath.h"
#include "lidet/lidet.h"

#if defined(_WIN32)
#define LIDET_PY_API __declspec(dllexport)
#else
#define LIDET_PY_API __attribute__((visibility("default")))
#endif

/* Integer preset number `index`: name (64 bytes), rows/cols, the beam elevations in ring order (microradians,
 * expanded by lidet_sensor_q_elevations for a uniform fov), ints = fov_up, fov_down (urad), mount height,
 * max range (mm), has_table. -6 past the end. */
LIDET_PY_API int lidet_py_sensor_q(uint32_t index, char *name_buf, uint32_t *rows_cols, int32_t *elev_urad,
                                   int32_t *ints)
{
    const lidet_sensor_q_t *s = lidet_sensor_q_at(index);
    if (s == NULL)
        return LIDET_ERR_NOT_FOUND;
    strncpy(name_buf, s->name, 63);
    name_buf[63] = '\0';
    rows_cols[0] = s->n_rows;
    rows_cols[1] = s->n_cols;
    ints[0] = s->fov_up_urad;
    ints[1] = s->fov_down_urad;
    ints[2] = s->mount_height_mm;
    ints[3] = s->max_range_mm;
    ints[4] = s->beam_elev_urad != NULL;
    return lidet_sensor_q_elevations(s, elev_urad);
}

/* One integer projection on a heap state and heap buffers. sensor_ints = rows, cols, fov_up, fov_down (used
 * when elev_urad is NULL); cfg_ints = min_range_mm, max_range_mm, fov_margin_urad. Outputs: point_pixel (n,
 * may be NULL), point_idx / range_4mm (rows*cols), xyz_4mm (3*rows*cols: x, y, z planes), stats (9 counts,
 * lidet_proj_stats_t order), row_elev_bam (rows). returns: n lidet_return_t instead of the points
 * (lidet_proj_q_run_returns; points, stride and ring ignored), or NULL. Returns the run's status (or init's error). */
LIDET_PY_API int lidet_py_proj_q(const int32_t *sensor_ints, const int32_t *elev_urad, const int32_t *cfg_ints,
                                 const int32_t *points, uint32_t n, uint32_t stride, const uint16_t *ring,
                                 int32_t *point_pixel, int32_t *point_idx, int16_t *xyz_4mm, uint16_t *range_4mm,
                                 uint32_t *stats, int32_t *row_elev_bam, const lidet_return_t *returns)
{
    lidet_proj_q_cfg_t cfg;
    lidet_proj_q_buffers_t b;
    lidet_proj_q_state_t *st;
    uint32_t npix;
    int status;
    if (sensor_ints == NULL || cfg_ints == NULL || point_idx == NULL || xyz_4mm == NULL || range_4mm == NULL ||
        stats == NULL || row_elev_bam == NULL || (point_pixel != NULL && n > LIDET_MAX_POINTS))
        return LIDET_ERR_ARG;
    lidet_proj_q_cfg_default(&cfg, NULL);
    cfg.sensor.name = "py";
    cfg.sensor.n_rows = (uint16_t)sensor_ints[0];
    cfg.sensor.n_cols = (uint16_t)sensor_ints[1];
    cfg.sensor.beam_elev_urad = elev_urad;
    cfg.sensor.fov_up_urad = sensor_ints[2];
    cfg.sensor.fov_down_urad = sensor_ints[3];
    cfg.min_range_mm = cfg_ints[0];
    cfg.max_range_mm = cfg_ints[1];
    cfg.fov_margin_urad = cfg_ints[2];
    st = (lidet_proj_q_state_t *)malloc(sizeof *st);
    if (st == NULL)
        return LIDET_ERR_BUFFER;
    status = lidet_proj_q_init(st, &cfg);
    if (status == LIDET_OK)
    {
        npix = (uint32_t)cfg.sensor.n_rows * cfg.sensor.n_cols;
        b.x_4mm = xyz_4mm;
        b.y_4mm = xyz_4mm + npix;
        b.z_4mm = xyz_4mm + 2u * npix;
        b.range_4mm = range_4mm;
        b.point_idx = point_idx;
        b.point_pixel = point_pixel;
        status = returns != NULL ? lidet_proj_q_run_returns(st, &b, returns, n)
                                 : lidet_proj_q_run(st, &b, points, n, stride, ring);
        if (status >= 0)
        {
            const lidet_proj_stats_t *s = lidet_proj_q_stats(st);
            stats[0] = s->n_points_in;
            stats[1] = s->n_projected;
            stats[2] = s->n_pixels_filled;
            stats[3] = s->n_nonfinite;
            stats[4] = s->n_too_close;
            stats[5] = s->n_too_far;
            stats[6] = s->n_out_of_fov;
            stats[7] = s->n_bad_ring;
            stats[8] = s->n_truncated;
            memcpy(row_elev_bam, st->row_elev_bam, cfg.sensor.n_rows * sizeof row_elev_bam[0]);
        }
    }
    free(st);
    return status;
}

/* lidet__q_isqrt32 over an array (the 32-bit root the projection takes per filled pixel) */
LIDET_PY_API int lidet_py_isqrt32(const uint32_t *v, uint32_t n, int64_t *out)
{
    uint32_t i;
    if (v == NULL || out == NULL)
        return LIDET_ERR_ARG;
    for (i = 0; i < n; ++i)
        out[i] = lidet__q_isqrt32(v[i]);
    return LIDET_OK;
}
