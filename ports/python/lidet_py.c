/* SPDX-License-Identifier: MIT */
/* Flat C entry points for the Python bindings (tools/lidet_tools/native/, ctypes).
 *
 * Every call works on an explicit scan context (lidet_py_ctx_new): the stages' states of one scan,
 * allocated on the host heap (this is a host port, not lib/). Nothing is global, so a call on one
 * context never sees another's scan: proposals read the clusters and the image of their own context.
 *
 * Configurations and statistics cross the boundary as the C structs themselves. Python learns their
 * layout by name from lidet_py_field (name, offset, size, kind of every field, offsets from offsetof),
 * so nothing is kept in step by hand, and the defaults come from the C cfg_default functions. */
#include <math.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>

#include "lidet/lidet.h"

#if defined(_WIN32)
#define LIDET_PY_API __declspec(dllexport)
#else
#define LIDET_PY_API __attribute__((visibility("default")))
#endif

/* one scan's states */
typedef struct
{
    lidet_proj_t proj;
    lidet_ground_t ground;
    lidet_cluster_t cluster;
    uint8_t ground_pix[LIDET_MAX_ROWS * LIDET_MAX_COLS];
    lidet_proposal_t proposal;
    int pixel_model;   /* LIDET_PY_PIXEL_*: what a compact pixel would hand the later stages */
    float pixel_q_m;   /* quantum of LIDET_PY_PIXEL_S16 */
    int proj_ready;    /* lidet_py_proj_init succeeded */
    int cluster_ready; /* a lidet_py_cluster_run succeeded (proposals may be made) */
} lidet_py_ctx_t;

LIDET_PY_API void *lidet_py_ctx_new(void)
{
    return calloc(1, sizeof(lidet_py_ctx_t));
}

LIDET_PY_API void lidet_py_ctx_free(void *ctx)
{
    free(ctx);
}

/* ---- struct layouts by name ------------------------------------------------------------------ */
typedef struct
{
    const char *type;
    const char *field;
    uint32_t offset;
    uint32_t size;
    char kind; /* 'f' float, 'u' unsigned integer, 'i' signed integer */
} py_field_t;

#define FLD(T, f, k) {#T, #f, (uint32_t)offsetof(T, f), (uint32_t)sizeof(((T *)0)->f), k}

static const py_field_t k_fields[] = {
    /* lidet_proj_cfg_t (its sensor member travels as separate arguments) */
    FLD(lidet_proj_cfg_t, min_range_m, 'f'), FLD(lidet_proj_cfg_t, max_range_m, 'f'),
    FLD(lidet_proj_cfg_t, fov_margin_rad, 'f'), FLD(lidet_proj_cfg_t, azimuth_half_rad, 'f'),
    FLD(lidet_proj_stats_t, n_points_in, 'u'), FLD(lidet_proj_stats_t, n_projected, 'u'),
    FLD(lidet_proj_stats_t, n_pixels_filled, 'u'), FLD(lidet_proj_stats_t, n_nonfinite, 'u'),
    FLD(lidet_proj_stats_t, n_too_close, 'u'), FLD(lidet_proj_stats_t, n_too_far, 'u'),
    FLD(lidet_proj_stats_t, n_out_of_fov, 'u'), FLD(lidet_proj_stats_t, n_bad_ring, 'u'),
    FLD(lidet_proj_stats_t, n_truncated, 'u'), FLD(lidet_proj_stats_t, n_out_of_window, 'u'),
    FLD(lidet_ground_cfg_t, fy_max, 'f'), FLD(lidet_ground_cfg_t, fx_max_m, 'f'),
    FLD(lidet_ground_cfg_t, fx_on_z, 'u'), FLD(lidet_ground_cfg_t, require_descending, 'u'),
    FLD(lidet_ground_cfg_t, height_gate, 'u'), FLD(lidet_ground_cfg_t, gate_above_m, 'f'),
    FLD(lidet_ground_cfg_t, gate_below_m, 'f'), FLD(lidet_ground_cfg_t, mount_height_m, 'f'),
    FLD(lidet_ground_cfg_t, n_sectors, 'u'), FLD(lidet_ground_cfg_t, ransac_iters, 'u'),
    FLD(lidet_ground_cfg_t, sample_step, 'u'), FLD(lidet_ground_cfg_t, sample_col_step, 'u'),
    FLD(lidet_ground_cfg_t, eval_samples, 'u'), FLD(lidet_ground_cfg_t, min_samples, 'u'),
    FLD(lidet_ground_cfg_t, min_inliers, 'u'), FLD(lidet_ground_cfg_t, confidence, 'f'),
    FLD(lidet_ground_cfg_t, refine_iters, 'u'), FLD(lidet_ground_cfg_t, inlier_m, 'f'),
    FLD(lidet_ground_cfg_t, max_tilt_rad, 'f'), FLD(lidet_ground_cfg_t, max_height_dev_m, 'f'),
    FLD(lidet_ground_cfg_t, ring_split_m, 'f'), FLD(lidet_ground_cfg_t, far_max_step_m, 'f'),
    FLD(lidet_ground_cfg_t, far2_split_m, 'f'),
    FLD(lidet_ground_cfg_t, fallback_sectors, 'u'),
    FLD(lidet_ground_cfg_t, seed, 'u'), FLD(lidet_ground_cfg_t, seed_per_cell, 'u'),
    FLD(lidet_ground_cfg_t, azimuth_half_rad, 'f'),
    FLD(lidet_ground_cfg_t, ground_m, 'f'),
    FLD(lidet_ground_cfg_t, ground_m_per_m, 'f'), FLD(lidet_ground_cfg_t, below_factor, 'f'),
    FLD(lidet_ground_cfg_t, veto_slope, 'f'), FLD(lidet_ground_cfg_t, veto_min_dz_m, 'f'),
    FLD(lidet_ground_stats_t, n_samples, 'u'), FLD(lidet_ground_stats_t, n_samples_dropped, 'u'),
    FLD(lidet_ground_stats_t, n_ground, 'u'), FLD(lidet_ground_stats_t, n_sectors_fitted, 'u'),
    FLD(lidet_ground_stats_t, n_sectors_neighbour, 'u'), FLD(lidet_ground_stats_t, n_sectors_mount, 'u'),
    FLD(lidet_ground_stats_t, n_sectors_sparse, 'u'), FLD(lidet_ground_stats_t, n_sectors_rejected, 'u'),
    FLD(lidet_ground_stats_t, n_far_fitted, 'u'),
    FLD(lidet_ground_stats_t, n_far2_fitted, 'u'), FLD(lidet_ground_stats_t, n_vetoed, 'u'),
    FLD(lidet_ground_stats_t, n_hypotheses, 'u'),
    FLD(lidet_cluster_cfg_t, theta_rad, 'f'), FLD(lidet_cluster_cfg_t, max_steps, 'u'),
    FLD(lidet_cluster_cfg_t, bridge_occluders, 'u'), FLD(lidet_cluster_cfg_t, diagonals, 'u'),
    FLD(lidet_cluster_cfg_t, max_gap_m, 'f'), FLD(lidet_cluster_cfg_t, max_gap_per_m, 'f'),
    FLD(lidet_cluster_cfg_t, min_points, 'u'), FLD(lidet_cluster_cfg_t, max_extent_m, 'f'),
    FLD(lidet_cluster_cfg_t, max_mean_height_m, 'f'), FLD(lidet_cluster_cfg_t, mount_height_m, 'f'),
    FLD(lidet_cluster_cfg_t, rescue_gap_m, 'f'), FLD(lidet_cluster_cfg_t, rescue_gap_per_m, 'f'),
    FLD(lidet_cluster_cfg_t, rescue_rows, 'u'), FLD(lidet_cluster_cfg_t, rescue_cols, 'u'),
    FLD(lidet_cluster_cfg_t, split_people, 'u'), FLD(lidet_cluster_cfg_t, split_min_width_m, 'f'),
    FLD(lidet_cluster_cfg_t, split_cell_m, 'f'), FLD(lidet_cluster_cfg_t, split_cell_per_m, 'f'),
    FLD(lidet_cluster_cfg_t, person_max_width_m, 'f'), FLD(lidet_cluster_cfg_t, person_min_height_m, 'f'),
    FLD(lidet_cluster_cfg_t, person_min_aspect, 'f'), FLD(lidet_cluster_cfg_t, person_min_cols, 'u'),
    FLD(lidet_cluster_cfg_t, person_min_points, 'u'),
    FLD(lidet_cluster_cfg_t, join_cars, 'u'), FLD(lidet_cluster_cfg_t, join_gap_m, 'f'),
    FLD(lidet_cluster_cfg_t, car_max_length_m, 'f'), FLD(lidet_cluster_cfg_t, car_max_width_m, 'f'),
    FLD(lidet_cluster_cfg_t, car_max_height_m, 'f'), FLD(lidet_cluster_cfg_t, car_min_length_m, 'f'),
    FLD(lidet_cluster_cfg_t, upright_max_width_m, 'f'), FLD(lidet_cluster_cfg_t, azimuth_half_rad, 'f'),
    FLD(lidet_cluster_cfg_t, seed_half_rad, 'f'),
    FLD(lidet_cluster_cfg_t, max_join_pieces, 'u'),
    FLD(lidet_cluster_cfg_t, max_bridge_per_pixel, 'f'), FLD(lidet_cluster_cfg_t, max_fragment_pixels, 'u'),
    FLD(lidet_cluster_cfg_t, regrow_gap_m, 'f'), FLD(lidet_cluster_cfg_t, regrow_gap_per_m, 'f'),
    FLD(lidet_cluster_cfg_t, regrow_max_pixels, 'u'), FLD(lidet_cluster_cfg_t, regrow_max_height_m, 'f'),
    FLD(lidet_cluster_cfg_t, regrow_cut_m, 'f'),
    FLD(lidet_cluster_cfg_t, plane_split_m, 'f'),
    FLD(lidet_cluster_stats_t, n_candidates, 'u'), FLD(lidet_cluster_stats_t, n_found, 'u'),
    FLD(lidet_cluster_stats_t, n_fragments, 'u'), FLD(lidet_cluster_stats_t, n_rescue_joined, 'u'),
    FLD(lidet_cluster_stats_t, n_rescue_pixels, 'u'), FLD(lidet_cluster_stats_t, n_dropped_small, 'u'),
    FLD(lidet_cluster_stats_t, n_dropped_extent, 'u'), FLD(lidet_cluster_stats_t, n_dropped_height, 'u'),
    FLD(lidet_cluster_stats_t, n_dropped_capacity, 'u'), FLD(lidet_cluster_stats_t, n_kept, 'u'),
    FLD(lidet_cluster_stats_t, n_pixels_kept, 'u'), FLD(lidet_cluster_stats_t, n_queue_overflow, 'u'),
    FLD(lidet_cluster_stats_t, n_split, 'u'), FLD(lidet_cluster_stats_t, n_split_parts, 'u'),
    FLD(lidet_cluster_stats_t, n_split_skipped, 'u'), FLD(lidet_cluster_stats_t, n_joined, 'u'),
    FLD(lidet_cluster_stats_t, n_join_skipped, 'u'),
    FLD(lidet_cluster_stats_t, n_fragment_pixels, 'u'), FLD(lidet_cluster_stats_t, n_dropped_fragment_budget, 'u'),
    FLD(lidet_cluster_stats_t, n_bridge_steps, 'u'), FLD(lidet_cluster_stats_t, n_regrown, 'u'),
    FLD(lidet_cluster_stats_t, n_regrow_parts, 'u'),
    FLD(lidet_proposal_cfg_t, n_points, 'u'), FLD(lidet_proposal_cfg_t, seed, 'u'),
    FLD(lidet_proposal_cfg_t, azimuth_bin_rad, 'f'), FLD(lidet_proposal_cfg_t, elevation_bin_rad, 'f'),
    FLD(lidet_proposal_cfg_t, range_bin_m, 'f'), FLD(lidet_proposal_cfg_t, z_origin, 'u'),
};

typedef struct
{
    const char *type;
    uint32_t size;
} py_struct_t;

static const py_struct_t k_structs[] = {
    {"lidet_proj_cfg_t", (uint32_t)sizeof(lidet_proj_cfg_t)},
    {"lidet_proj_stats_t", (uint32_t)sizeof(lidet_proj_stats_t)},
    {"lidet_ground_cfg_t", (uint32_t)sizeof(lidet_ground_cfg_t)},
    {"lidet_ground_stats_t", (uint32_t)sizeof(lidet_ground_stats_t)},
    {"lidet_cluster_cfg_t", (uint32_t)sizeof(lidet_cluster_cfg_t)},
    {"lidet_cluster_stats_t", (uint32_t)sizeof(lidet_cluster_stats_t)},
    {"lidet_proposal_cfg_t", (uint32_t)sizeof(lidet_proposal_cfg_t)},
};

/* Field number `index` of the table: its struct's name and size, its name, offset, size and kind.
 * Returns 0, or LIDET_ERR_NOT_FOUND past the end. */
LIDET_PY_API int lidet_py_field(uint32_t index, const char **type, uint32_t *type_size, const char **field,
                                uint32_t *offset, uint32_t *size, char *kind)
{
    uint32_t s;
    if (index >= sizeof k_fields / sizeof k_fields[0])
        return LIDET_ERR_NOT_FOUND;
    *type = k_fields[index].type;
    *field = k_fields[index].field;
    *offset = k_fields[index].offset;
    *size = k_fields[index].size;
    *kind = k_fields[index].kind;
    *type_size = 0;
    for (s = 0; s < sizeof k_structs / sizeof k_structs[0]; ++s)
    {
        if (strcmp(k_structs[s].type, *type) == 0)
            *type_size = k_structs[s].size;
    }
    return 0;
}

/* ---- defaults (the C cfg_default functions, for a sensor given by its shape and mount) ---------- */
static void py_sensor(lidet_sensor_t *s, uint32_t rows, uint32_t cols, float mount_height_m)
{
    memset(s, 0, sizeof *s);
    s->name = "python";
    s->n_rows = (uint16_t)(rows > 0xFFFFu ? 0xFFFFu : rows);
    s->n_cols = (uint16_t)(cols > 0xFFFFu ? 0xFFFFu : cols);
    s->mount_height_m = mount_height_m;
}

LIDET_PY_API void lidet_py_proj_default(lidet_proj_cfg_t *out)
{
    lidet_proj_cfg_default(out, NULL);
}

LIDET_PY_API void lidet_py_ground_default(uint32_t rows, uint32_t cols, float mount_height_m, lidet_ground_cfg_t *out)
{
    lidet_sensor_t s;
    py_sensor(&s, rows, cols, mount_height_m);
    lidet_ground_cfg_default(out, &s);
}

LIDET_PY_API void lidet_py_cluster_default(uint32_t rows, uint32_t cols, float mount_height_m, lidet_cluster_cfg_t *out)
{
    lidet_sensor_t s;
    py_sensor(&s, rows, cols, mount_height_m);
    lidet_cluster_cfg_default(out, &s);
}

LIDET_PY_API void lidet_py_proposal_default(lidet_proposal_cfg_t *out)
{
    lidet_proposal_cfg_default(out);
}

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

/* ---- pixel models: measuring what a more compact pixel than float x, y, z, range would cost ------
 * After each projection the context's image is rewritten as a pixel stored another way would decode
 * (the stages then run unchanged on it): the accuracy a storage choice costs (docs/journal/memory.md, "What a compact
 * pixel would cost"). */
enum
{
    LIDET_PY_PIXEL_FLOAT = 0,        /* the real point (what the library stores) */
    LIDET_PY_PIXEL_S16 = 1,          /* x, y, z and range rounded to multiples of q (int16 / uint16 storage) */
    LIDET_PY_PIXEL_RECOMPUTE = 2,    /* range only; x, y, z from the beam's elevation and the column centre */
    LIDET_PY_PIXEL_REAL_ELEV = 3,    /* range and the real elevation; azimuth of the column centre */
    LIDET_PY_PIXEL_REAL_AZIMUTH = 4  /* range and the real azimuth; elevation of the beam */
};

LIDET_PY_API int lidet_py_ctx_pixel_model(lidet_py_ctx_t *ctx, int model, float q_m)
{
    if (ctx == NULL || model < LIDET_PY_PIXEL_FLOAT || model > LIDET_PY_PIXEL_REAL_AZIMUTH ||
        (model == LIDET_PY_PIXEL_S16 && !(q_m > 0.0f)))
        return LIDET_ERR_ARG;
    ctx->pixel_model = model;
    ctx->pixel_q_m = q_m;
    return 0;
}

static void apply_pixel_model(lidet_py_ctx_t *ctx)
{
    lidet_proj_t *pj = &ctx->proj;
    const uint32_t rows = pj->state.cfg.sensor.n_rows, cols = pj->state.cfg.sensor.n_cols;
    const double q = ctx->pixel_q_m;
    uint32_t r, c;
    if (ctx->pixel_model == LIDET_PY_PIXEL_FLOAT)
        return;
    for (r = 0; r < rows; ++r)
    {
        for (c = 0; c < cols; ++c)
        {
            const uint32_t p = r * cols + c;
            const double rng = pj->range_m[p], x = pj->x_m[p], y = pj->y_m[p], z = pj->z_m[p];
            double el, az, nx, ny, nz;
            if (!(rng > 0.0))
                continue;
            if (ctx->pixel_model == LIDET_PY_PIXEL_S16)
            {
                nx = floor(x / q + 0.5) * q;
                ny = floor(y / q + 0.5) * q;
                nz = floor(z / q + 0.5) * q;
                pj->range_m[p] = (float)(floor(rng / q + 0.5) * q);
            }
            else
            {
                const double az_col = 3.14159265358979323846 * (1.0 - 2.0 * ((double)c + 0.5) / (double)cols);
                const double el_row = pj->state.row_elev_rad[r];
                el = ctx->pixel_model == LIDET_PY_PIXEL_REAL_ELEV ? asin(z / rng) : el_row;
                az = ctx->pixel_model == LIDET_PY_PIXEL_REAL_AZIMUTH ? atan2(y, x) : az_col;
                nx = rng * cos(el) * cos(az);
                ny = rng * cos(el) * sin(az);
                nz = rng * sin(el);
            }
            pj->x_m[p] = (float)nx;
            pj->y_m[p] = (float)ny;
            pj->z_m[p] = (float)nz;
            pj->rxy_m[p] = sqrtf(pj->x_m[p] * pj->x_m[p] + pj->y_m[p] * pj->y_m[p]);
        }
    }
}

/* ---- projection ------------------------------------------------------------------------------- */

/* Initialise the context's projection. elev_rad may be NULL (uniform fov); cfg: a lidet_proj_cfg_t whose
 * sensor member is ignored (the sensor is given by the other arguments). */
LIDET_PY_API int lidet_py_proj_init(lidet_py_ctx_t *ctx, uint32_t rows, uint32_t cols, const float *elev_rad,
                                    float fov_up_rad, float fov_down_rad, float mount_height_m,
                                    const lidet_proj_cfg_t *cfg)
{
    lidet_proj_cfg_t c;
    lidet_sensor_t s;
    int rc;
    if (ctx == NULL || cfg == NULL)
        return LIDET_ERR_ARG;
    if (rows > 0xFFFFu || cols > 0xFFFFu)
        return LIDET_ERR_BUFFER;
    py_sensor(&s, rows, cols, mount_height_m);
    s.beam_elev_rad = elev_rad;
    s.fov_up_rad = fov_up_rad;
    s.fov_down_rad = fov_down_rad;
    c = *cfg;
    c.sensor = s;
    ctx->proj_ready = 0;
    ctx->cluster_ready = 0;
    rc = lidet_proj_init(&ctx->proj, &c);
    ctx->proj_ready = rc == LIDET_OK;
    return rc;
}

/* Copy the context's image out. out_img: 5 * rows * cols floats (x, y, z, range, rxy planes),
 * out_idx: rows * cols int32, out_point_pixel: the projection's point count int32, out_stats: a
 * lidet_proj_stats_t, out_row_elev: rows floats. Any output may be NULL. */
LIDET_PY_API int lidet_py_proj_copy(lidet_py_ctx_t *ctx, float *out_img, int32_t *out_idx, int32_t *out_point_pixel,
                                    lidet_proj_stats_t *out_stats, float *out_row_elev)
{
    lidet_range_image_t img;
    uint32_t npix, np;
    const int32_t *pp;
    if (ctx == NULL || !ctx->proj_ready)
        return LIDET_ERR_STATE;
    lidet_proj_image(&ctx->proj, &img);
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
    pp = lidet_proj_point_pixels(&ctx->proj, &np);
    if (out_point_pixel != NULL)
        memcpy(out_point_pixel, pp, np * sizeof(int32_t));
    if (out_stats != NULL)
        *out_stats = *lidet_proj_stats(&ctx->proj);
    if (out_row_elev != NULL)
        memcpy(out_row_elev, img.row_elev_rad, img.n_rows * sizeof(float));
    return 0;
}

/* Project a scan with the context's projection, then copy the outputs (as lidet_py_proj_copy). */
LIDET_PY_API int lidet_py_proj_run(lidet_py_ctx_t *ctx, const float *pts, uint32_t n, uint32_t stride,
                                   const uint16_t *ring, float *out_img, int32_t *out_idx, int32_t *out_point_pixel,
                                   lidet_proj_stats_t *out_stats, float *out_row_elev)
{
    int rc;
    if (ctx == NULL || !ctx->proj_ready)
        return LIDET_ERR_STATE;
    ctx->cluster_ready = 0; /* the image changes under any earlier clusters */
    rc = lidet_proj_run(&ctx->proj, pts, n, stride, ring);
    if (rc < 0)
        return rc;
    apply_pixel_model(ctx);
    lidet_py_proj_copy(ctx, out_img, out_idx, out_point_pixel, out_stats, out_row_elev);
    return rc;
}

/* The context's projection state (NULL before lidet_py_proj_init succeeded): lidet_py_ground_q.c projects
 * into a compact image with it, as a detector workspace does. */
LIDET_PY_API lidet_proj_state_t *lidet_py_ctx_proj_state(lidet_py_ctx_t *ctx)
{
    return ctx != NULL && ctx->proj_ready ? &ctx->proj.state : NULL;
}

/* ---- ground stage ----------------------------------------------------------------------------- */

/* The planes (8 n_sectors floats: nx ny nz d, near planes then far planes), sources (2 n_sectors bytes) and
 * counts of a ground run; any may be NULL. Also used by lidet_py_ground_q.c. */
void lidet_py_ground_planes_out(const lidet_ground_t *g, float *planes, uint8_t *source, lidet_ground_stats_t *stats)
{
    uint32_t ns, s;
    const lidet_plane_t *pl = lidet_ground_planes(g, &ns);
    const uint8_t *src = lidet_ground_sector_source(g);
    const lidet_ground_cfg_t *cfg = &g->state.cfg;
    /* near, far and, with the third cells (far2_split_m beyond ring_split_m), their planes */
    const uint32_t n_cells = (cfg->ring_split_m > 0.0f && cfg->far2_split_m > cfg->ring_split_m ? 3u : 2u) * ns;
    for (s = 0; s < n_cells; ++s)
    {
        if (planes != NULL)
        {
            planes[4 * s + 0] = pl[s].nx;
            planes[4 * s + 1] = pl[s].ny;
            planes[4 * s + 2] = pl[s].nz;
            planes[4 * s + 3] = pl[s].d_m;
        }
        if (source != NULL)
            source[s] = src[s];
    }
    if (stats != NULL)
        *stats = *lidet_ground_stats(g);
}

/* Initialise the context's ground stage with cfg and run it on the context's image. Outputs (any may
 * be NULL): mask_pixel / sample_pixel rows*cols bytes, mask_point n_points bytes (the projection's
 * point count), planes 8*n_sectors floats (nx ny nz d; near planes, then far planes), source
 * 2*n_sectors bytes (same order), stats a lidet_ground_stats_t. */
LIDET_PY_API int lidet_py_ground_run(lidet_py_ctx_t *ctx, const lidet_ground_cfg_t *cfg, uint8_t *mask_pixel,
                                     uint8_t *sample_pixel, uint8_t *mask_point, float *planes, uint8_t *source,
                                     lidet_ground_stats_t *stats)
{
    lidet_range_image_t img;
    const int32_t *pp;
    uint32_t npix, np;
    int rc;
    if (ctx == NULL || !ctx->proj_ready)
        return LIDET_ERR_STATE;
    if (cfg == NULL)
        return LIDET_ERR_ARG;
    rc = lidet_ground_init(&ctx->ground, cfg);
    if (rc < 0)
        return rc;
    lidet_proj_image(&ctx->proj, &img);
    rc = lidet_ground_run(&ctx->ground, &img);
    if (rc < 0)
        return rc;
    npix = (uint32_t)img.n_rows * img.n_cols;
    if (mask_pixel != NULL)
        memcpy(mask_pixel, lidet_ground_mask(&ctx->ground), npix);
    if (sample_pixel != NULL)
        memcpy(sample_pixel, lidet_ground_samples(&ctx->ground), npix);
    pp = lidet_proj_point_pixels(&ctx->proj, &np);
    if (mask_point != NULL)
    {
        const int r2 = lidet_ground_point_labels(&ctx->ground, pp, np, mask_point);
        if (r2 < 0)
            return r2;
    }
    lidet_py_ground_planes_out(&ctx->ground, planes, source, stats);
    return rc;
}

/* Least-squares plane (lidet_ground_fit_plane): plane 4 floats, eig 3 floats (may be NULL). */
LIDET_PY_API int lidet_py_ground_fit_plane(const float *x, const float *y, const float *z, uint32_t n, float *plane,
                                           float *eig)
{
    lidet_plane_t p;
    const int rc = lidet_ground_fit_plane(x, y, z, n, &p, eig);
    if (rc < 0)
        return rc;
    plane[0] = p.nx;
    plane[1] = p.ny;
    plane[2] = p.nz;
    plane[3] = p.d_m;
    return rc;
}

LIDET_PY_API const char *lidet_py_status_str(int status)
{
    return lidet_status_str((lidet_status_t)status);
}

/* ---- clustering + proposals ------------------------------------------------------------------ */

/* Project with the context's projection, then cluster. ground_per_point: n bytes (1 = ground) or NULL; a
 * pixel is ground when its winning point is. planes: n_sectors * 4 floats (nx, ny, nz, d) or NULL.
 * Outputs (any may be NULL): out_point_labels n uint32 (0 for points past capacity), out_pixel_labels
 * rows * cols uint16, out_members rows * cols int32 (first n_pixels_kept used), out_rec_u max_recs * 4
 * uint32 (n_points, first_member, seed_pixel, n_rescued), out_rec_f max_recs * 10 floats (mean xyz, min
 * xyz, max xyz, height), out_n_recs, out_stats a lidet_cluster_stats_t. */
LIDET_PY_API int lidet_py_cluster_run(lidet_py_ctx_t *ctx, const float *pts, uint32_t n, uint32_t stride,
                                      const uint8_t *ground_per_point, const float *planes, uint32_t n_sectors,
                                      const lidet_cluster_cfg_t *cfg, uint32_t *out_point_labels,
                                      uint16_t *out_pixel_labels, int32_t *out_members, uint32_t *out_rec_u,
                                      float *out_rec_f, uint32_t max_recs, uint32_t *out_n_recs,
                                      lidet_cluster_stats_t *out_stats)
{
    lidet_range_image_t img;
    lidet_plane_t pl[256];
    const lidet_cluster_rec_t *rec;
    const lidet_cluster_stats_t *st;
    uint32_t npix, p, k, np;
    const int32_t *pp;
    int rc;
    if (ctx == NULL || !ctx->proj_ready)
        return LIDET_ERR_STATE;
    if (cfg == NULL)
        return LIDET_ERR_ARG;
    ctx->cluster_ready = 0;
    rc = lidet_proj_run(&ctx->proj, pts, n, stride, NULL);
    if (rc < 0)
        return rc;
    apply_pixel_model(ctx);
    lidet_proj_image(&ctx->proj, &img);
    npix = (uint32_t)img.n_rows * img.n_cols;
    if (ground_per_point != NULL)
    {
        for (p = 0; p < npix; ++p)
            ctx->ground_pix[p] = (uint8_t)(img.point_idx[p] >= 0 && ground_per_point[img.point_idx[p]] != 0);
    }
    if (planes != NULL)
    {
        if (n_sectors == 0 || n_sectors > 256)
            return LIDET_ERR_ARG;
        for (k = 0; k < n_sectors; ++k)
        {
            pl[k].nx = planes[4 * k];
            pl[k].ny = planes[4 * k + 1];
            pl[k].nz = planes[4 * k + 2];
            pl[k].d_m = planes[4 * k + 3];
        }
    }
    rc = lidet_cluster_init(&ctx->cluster, cfg);
    if (rc < 0)
        return rc;
    rc = lidet_cluster_run(&ctx->cluster, &img, ground_per_point != NULL ? ctx->ground_pix : NULL,
                           planes != NULL ? pl : NULL, n_sectors);
    if (rc < 0)
        return rc;
    ctx->cluster_ready = 1;
    pp = lidet_proj_point_pixels(&ctx->proj, &np);
    if (out_point_labels != NULL)
    {
        lidet_cluster_point_labels(&ctx->cluster, pp, np, out_point_labels);
        for (p = np; p < n; ++p)
            out_point_labels[p] = 0;
    }
    if (out_pixel_labels != NULL)
        memcpy(out_pixel_labels, lidet_cluster_labels(&ctx->cluster), npix * sizeof(uint16_t));
    st = lidet_cluster_stats(&ctx->cluster);
    if (out_members != NULL)
        memcpy(out_members, lidet_cluster_members(&ctx->cluster), st->n_pixels_kept * sizeof(int32_t));
    rec = lidet_cluster_records(&ctx->cluster, &k);
    if (out_n_recs != NULL)
        *out_n_recs = k;
    for (p = 0; p < k && p < max_recs; ++p)
    {
        if (out_rec_u != NULL)
        {
            out_rec_u[4 * p] = rec[p].n_points;
            out_rec_u[4 * p + 1] = rec[p].first_member;
            out_rec_u[4 * p + 2] = rec[p].seed_pixel;
            out_rec_u[4 * p + 3] = rec[p].n_rescued;
        }
        if (out_rec_f != NULL)
        {
            float *f = out_rec_f + 10 * p;
            memcpy(f, rec[p].mean_m, 3 * sizeof(float));
            memcpy(f + 3, rec[p].min_m, 3 * sizeof(float));
            memcpy(f + 6, rec[p].max_m, 3 * sizeof(float));
            f[9] = rec[p].height_m;
        }
    }
    if (out_stats != NULL)
        *out_stats = *st;
    return rc;
}

/* Proposals of the first n_clusters kept clusters of the context's last lidet_py_cluster_run (the
 * context holds that scan's image: no other call can change it). out_xyz: n_clusters * n_points * 3
 * floats, out_mean: n_clusters * 3, out_voxel: n_clusters * 3 int16, out_n_src: n_clusters uint32. */
LIDET_PY_API int lidet_py_proposals(lidet_py_ctx_t *ctx, const lidet_proposal_cfg_t *cfg, uint32_t n_clusters,
                                    float *out_xyz, float *out_mean, int16_t *out_voxel, uint32_t *out_n_src)
{
    lidet_proposal_t *const pr = &ctx->proposal;
    uint32_t i, k;
    if (ctx == NULL)
        return LIDET_ERR_ARG;
    if (!ctx->cluster_ready)
        return LIDET_ERR_STATE;
    if (cfg == NULL)
        return LIDET_ERR_ARG;
    lidet_cluster_records(&ctx->cluster, &k);
    if (n_clusters > k)
        return LIDET_ERR_ARG;
    for (i = 0; i < n_clusters; ++i)
    {
        const int rc = lidet_proposal_make(&ctx->cluster, i, cfg, pr);
        if (rc < 0)
            return rc;
        memcpy(out_xyz + (size_t)i * cfg->n_points * 3, pr->xyz, (size_t)cfg->n_points * 3 * sizeof(float));
        memcpy(out_mean + 3 * i, pr->mean_m, 3 * sizeof(float));
        memcpy(out_voxel + 3 * i, pr->voxel, 3 * sizeof(int16_t));
        out_n_src[i] = pr->n_points_src;
    }
    return 0;
}

/* pixels: the cluster's n_src member pixels (NULL: not needed when n_src <= n_out), converted to lidet_member_t */
LIDET_PY_API int lidet_py_proposal_indices(const uint32_t *pixels, uint32_t n_src, uint32_t n_out,
                                           uint32_t seed, uint32_t *out)
{
    lidet_member_t *m = 0;
    lidet_status_t st;
    uint32_t i;
    if (pixels != 0 && n_src > 0u)
    {
        m = (lidet_member_t *)malloc((size_t)n_src * sizeof *m);
        if (m == 0)
        {
            return LIDET_ERR_BUFFER;
        }
        for (i = 0; i < n_src; ++i)
        {
            m[i] = (lidet_member_t)pixels[i];
        }
    }
    st = lidet_proposal_indices(m, n_src, n_out, seed, out);
    free(m);
    return st;
}
