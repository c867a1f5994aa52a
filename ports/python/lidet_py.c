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
static lidet_ground_t g_ground;

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
static int lidet_py_proj_run_outputs(float *out_img, int32_t *out_idx, int32_t *out_point_pixel,
                                     uint32_t *out_stats, float *out_row_elev);

LIDET_PY_API int lidet_py_proj_run(const float *pts, uint32_t n, uint32_t stride, const uint16_t *ring,
                                   float *out_img, int32_t *out_idx, int32_t *out_point_pixel, uint32_t *out_stats,
                                   float *out_row_elev)
{
    const int rc = lidet_proj_run(&g_proj, pts, n, stride, ring);
    if (rc < 0)
        return rc;
    lidet_py_proj_run_outputs(out_img, out_idx, out_point_pixel, out_stats, out_row_elev);
    return rc;
}

static int lidet_py_proj_run_outputs(float *out_img, int32_t *out_idx, int32_t *out_point_pixel,
                                     uint32_t *out_stats, float *out_row_elev)
{
    lidet_range_image_t img;
    const lidet_proj_stats_t *st;
    uint32_t npix, np;
    const int32_t *pp;
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
    return 0;
}

/* ---- ground stage ------------------------------------------------------------------------------
 * The configuration crosses the boundary as two flat arrays in this order (native.py: GROUND_F, GROUND_U):
 *   cfg_f[15]: fy_max fx_max_m gate_above_m gate_below_m mount_height_m inlier_m max_tilt_rad
 *              max_height_dev_m ground_m ground_m_per_m below_factor confidence ring_split_m veto_slope veto_min_dz_m
 *   cfg_u[13]: fx_on_z require_descending height_gate n_sectors ransac_iters eval_samples min_samples
 *              min_inliers refine_iters fallback_sectors seed sample_step sample_col_step */
static void ground_cfg_to_arrays(const lidet_ground_cfg_t *c, float *f, uint32_t *u)
{
    f[0] = c->fy_max;
    f[1] = c->fx_max_m;
    f[2] = c->gate_above_m;
    f[3] = c->gate_below_m;
    f[4] = c->mount_height_m;
    f[5] = c->inlier_m;
    f[6] = c->max_tilt_rad;
    f[7] = c->max_height_dev_m;
    f[8] = c->ground_m;
    f[9] = c->ground_m_per_m;
    f[10] = c->below_factor;
    f[11] = c->confidence;
    f[12] = c->ring_split_m;
    f[13] = c->veto_slope;
    f[14] = c->veto_min_dz_m;
    u[0] = c->fx_on_z;
    u[1] = c->require_descending;
    u[2] = c->height_gate;
    u[3] = c->n_sectors;
    u[4] = c->ransac_iters;
    u[5] = c->eval_samples;
    u[6] = c->min_samples;
    u[7] = c->min_inliers;
    u[8] = c->refine_iters;
    u[9] = c->fallback_sectors;
    u[10] = c->seed;
    u[11] = c->sample_step;
    u[12] = c->sample_col_step;
}

static int ground_cfg_from_arrays(lidet_ground_cfg_t *c, const float *f, const uint32_t *u)
{
    int i;
    for (i = 0; i < 10; ++i)
    {
        if (u[i] > 0xFFFFu)
            return LIDET_ERR_CONFIG;
    }
    c->fy_max = f[0];
    c->fx_max_m = f[1];
    c->gate_above_m = f[2];
    c->gate_below_m = f[3];
    c->mount_height_m = f[4];
    c->inlier_m = f[5];
    c->max_tilt_rad = f[6];
    c->max_height_dev_m = f[7];
    c->ground_m = f[8];
    c->ground_m_per_m = f[9];
    c->below_factor = f[10];
    c->confidence = f[11];
    c->ring_split_m = f[12];
    c->veto_slope = f[13];
    c->veto_min_dz_m = f[14];
    if (u[0] > 255u || u[1] > 255u || u[2] > 255u || u[8] > 255u)
        return LIDET_ERR_CONFIG;
    c->fx_on_z = (uint8_t)u[0];
    c->require_descending = (uint8_t)u[1];
    c->height_gate = (uint8_t)u[2];
    c->n_sectors = (uint16_t)u[3];
    c->ransac_iters = (uint16_t)u[4];
    c->eval_samples = (uint16_t)u[5];
    c->min_samples = (uint16_t)u[6];
    c->min_inliers = (uint16_t)u[7];
    c->refine_iters = (uint8_t)u[8];
    c->fallback_sectors = (uint16_t)u[9];
    c->seed = u[10];
    if (u[11] > 0xFFFFu)
        return LIDET_ERR_CONFIG;
    c->sample_step = (uint16_t)u[11];
    if (u[12] > 0xFFFFu)
        return LIDET_ERR_CONFIG;
    c->sample_col_step = (uint16_t)u[12];
    return LIDET_OK;
}

/* Defaults of lidet_ground_cfg_default for a sensor with `rows` beams mounted at mount_height_m. */
LIDET_PY_API int lidet_py_ground_default(uint32_t rows, uint32_t cols, float mount_height_m, float *cfg_f,
                                         uint32_t *cfg_u)
{
    lidet_ground_cfg_t c;
    lidet_sensor_t s;
    memset(&s, 0, sizeof s);
    s.name = "python";
    s.n_rows = (uint16_t)(rows > 0xFFFFu ? 0xFFFFu : rows);
    s.n_cols = (uint16_t)(cols > 0xFFFFu ? 0xFFFFu : cols);
    s.mount_height_m = mount_height_m;
    lidet_ground_cfg_default(&c, &s);
    ground_cfg_to_arrays(&c, cfg_f, cfg_u);
    return 0;
}

/* Initialise the ground stage and run it on the image of the last lidet_py_proj_run. Outputs (any may
 * be NULL): mask_pixel / sample_pixel rows*cols bytes, mask_point n_points bytes (n_points = the
 * projection's point count), planes 8*n_sectors floats (nx ny nz d; near planes, then far planes),
 * source 2*n_sectors bytes (same order), stats 12 uint32 (0 n_samples n_samples_dropped n_ground fitted
 * neighbour mount sparse rejected hypotheses far_fitted vetoed). */
LIDET_PY_API int lidet_py_ground_run(const float *cfg_f, const uint32_t *cfg_u, uint8_t *mask_pixel,
                                     uint8_t *sample_pixel, uint8_t *mask_point, float *planes, uint8_t *source,
                                     uint32_t *stats)
{
    lidet_ground_cfg_t c;
    lidet_range_image_t img;
    const lidet_ground_stats_t *st;
    const int32_t *pp;
    uint32_t npix, np, ns, s;
    int rc;
    lidet_ground_cfg_default(&c, NULL);
    rc = ground_cfg_from_arrays(&c, cfg_f, cfg_u);
    if (rc < 0)
        return rc;
    rc = lidet_ground_init(&g_ground, &c);
    if (rc < 0)
        return rc;
    lidet_proj_image(&g_proj, &img);
    rc = lidet_ground_run(&g_ground, &img);
    if (rc < 0)
        return rc;
    npix = (uint32_t)img.n_rows * img.n_cols;
    if (mask_pixel != NULL)
        memcpy(mask_pixel, lidet_ground_mask(&g_ground), npix);
    if (sample_pixel != NULL)
        memcpy(sample_pixel, lidet_ground_samples(&g_ground), npix);
    pp = lidet_proj_point_pixels(&g_proj, &np);
    if (mask_point != NULL)
    {
        const int r2 = lidet_ground_point_labels(&g_ground, pp, np, mask_point);
        if (r2 < 0)
            return r2;
    }
    {
        const lidet_plane_t *pl = lidet_ground_planes(&g_ground, &ns);
        const uint8_t *src = lidet_ground_sector_source(&g_ground);
        for (s = 0; s < 2u * ns; ++s)
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
    }
    st = lidet_ground_stats(&g_ground);
    if (stats != NULL)
    {
        stats[0] = 0;
        stats[1] = st->n_samples;
        stats[2] = st->n_samples_dropped;
        stats[3] = st->n_ground;
        stats[4] = st->n_sectors_fitted;
        stats[5] = st->n_sectors_neighbour;
        stats[6] = st->n_sectors_mount;
        stats[7] = st->n_sectors_sparse;
        stats[8] = st->n_sectors_rejected;
        stats[9] = st->n_hypotheses;
        stats[10] = st->n_far_fitted;
        stats[11] = st->n_vetoed;
    }
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
static lidet_cluster_t g_cluster;
static uint8_t g_ground_pix[LIDET_MAX_ROWS * LIDET_MAX_COLS];

/* Project with the state of lidet_py_proj_init, then cluster. ground_per_point: n bytes (1 = ground)
 * or NULL; a pixel is ground when its winning point is. planes: n_sectors * 4 floats (nx, ny, nz, d)
 * or NULL. cfg_f: theta_rad, max_extent_m, max_mean_height_m, mount_height_m,
 * max_gap_m, max_gap_per_m, rescue_gap_m, rescue_gap_per_m; cfg_u: max_steps,
 * min_points, bridge_occluders, diagonals, rescue_rows, rescue_cols. Outputs (any may be NULL): out_point_labels n uint32 (0 for points past capacity),
 * out_pixel_labels rows * cols uint16, out_members rows * cols int32 (first n_pixels_kept used),
 * out_rec_u max_recs * 4 uint32 (n_points, first_member, seed_pixel, n_rescued), out_rec_f max_recs * 10
 * floats (mean xyz, min xyz, max xyz, height), out_n_recs, out_stats 12 uint32 (n_candidates, n_found,
 * n_dropped_small, _extent, _height, _capacity, n_kept, n_pixels_kept, n_queue_overflow, n_fragments,
 * n_rescue_joined, n_rescue_pixels). */
LIDET_PY_API int lidet_py_cluster_run(const float *pts, uint32_t n, uint32_t stride, const uint8_t *ground_per_point,
                                      const float *planes, uint32_t n_sectors, const float *cfg_f,
                                      const uint32_t *cfg_u, uint32_t *out_point_labels, uint16_t *out_pixel_labels,
                                      int32_t *out_members, uint32_t *out_rec_u, float *out_rec_f, uint32_t max_recs,
                                      uint32_t *out_n_recs, uint32_t *out_stats)
{
    lidet_range_image_t img;
    lidet_cluster_cfg_t cfg;
    lidet_plane_t pl[256];
    const lidet_cluster_rec_t *rec;
    const lidet_cluster_stats_t *st;
    uint32_t npix, p, k, np;
    const int32_t *pp;
    int rc;
    rc = lidet_proj_run(&g_proj, pts, n, stride, NULL);
    if (rc < 0)
        return rc;
    lidet_proj_image(&g_proj, &img);
    npix = (uint32_t)img.n_rows * img.n_cols;
    if (ground_per_point != NULL)
    {
        for (p = 0; p < npix; ++p)
            g_ground_pix[p] = (uint8_t)(img.point_idx[p] >= 0 && ground_per_point[img.point_idx[p]] != 0);
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
    lidet_cluster_cfg_default(&cfg, NULL);
    cfg.theta_rad = cfg_f[0];
    cfg.max_extent_m = cfg_f[1];
    cfg.max_mean_height_m = cfg_f[2];
    cfg.mount_height_m = cfg_f[3];
    cfg.max_gap_m = cfg_f[4];
    cfg.max_gap_per_m = cfg_f[5];
    cfg.rescue_gap_m = cfg_f[6];
    cfg.rescue_gap_per_m = cfg_f[7];
    cfg.max_steps = cfg_u[0];
    cfg.min_points = cfg_u[1];
    cfg.bridge_occluders = cfg_u[2];
    cfg.diagonals = cfg_u[3];
    cfg.rescue_rows = cfg_u[4];
    cfg.rescue_cols = cfg_u[5];
    rc = lidet_cluster_init(&g_cluster, &cfg);
    if (rc < 0)
        return rc;
    rc = lidet_cluster_run(&g_cluster, &img, ground_per_point != NULL ? g_ground_pix : NULL,
                           planes != NULL ? pl : NULL, n_sectors);
    if (rc < 0)
        return rc;
    pp = lidet_proj_point_pixels(&g_proj, &np);
    if (out_point_labels != NULL)
    {
        lidet_cluster_point_labels(&g_cluster, pp, np, out_point_labels);
        for (p = np; p < n; ++p)
            out_point_labels[p] = 0;
    }
    if (out_pixel_labels != NULL)
        memcpy(out_pixel_labels, lidet_cluster_labels(&g_cluster), npix * sizeof(uint16_t));
    st = lidet_cluster_stats(&g_cluster);
    if (out_members != NULL)
        memcpy(out_members, lidet_cluster_members(&g_cluster), st->n_pixels_kept * sizeof(int32_t));
    rec = lidet_cluster_records(&g_cluster, &k);
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
    {
        out_stats[0] = st->n_candidates;
        out_stats[1] = st->n_found;
        out_stats[2] = st->n_dropped_small;
        out_stats[3] = st->n_dropped_extent;
        out_stats[4] = st->n_dropped_height;
        out_stats[5] = st->n_dropped_capacity;
        out_stats[6] = st->n_kept;
        out_stats[7] = st->n_pixels_kept;
        out_stats[8] = st->n_queue_overflow;
        out_stats[9] = st->n_fragments;
        out_stats[10] = st->n_rescue_joined;
        out_stats[11] = st->n_rescue_pixels;
    }
    return rc;
}

/* Proposals of every kept cluster of the last lidet_py_cluster_run (its scan must still be alive on
 * the Python side: the range image points into the projection state, which holds copies).
 * out_xyz: n_clusters * n_points * 3 floats, out_mean: n_clusters * 3, out_voxel: n_clusters * 3
 * int16, out_n_src: n_clusters uint32. */
LIDET_PY_API int lidet_py_proposals(uint32_t n_points, uint32_t seed, float az_bin_rad, float el_bin_rad,
                                    float range_bin_m, uint32_t n_clusters, float *out_xyz, float *out_mean,
                                    int16_t *out_voxel, uint32_t *out_n_src)
{
    static lidet_proposal_t pr;
    lidet_proposal_cfg_t cfg;
    uint32_t i;
    lidet_proposal_cfg_default(&cfg);
    cfg.n_points = n_points;
    cfg.seed = seed;
    cfg.azimuth_bin_rad = az_bin_rad;
    cfg.elevation_bin_rad = el_bin_rad;
    cfg.range_bin_m = range_bin_m;
    for (i = 0; i < n_clusters; ++i)
    {
        const int rc = lidet_proposal_make(&g_cluster, i, &cfg, &pr);
        if (rc < 0)
            return rc;
        memcpy(out_xyz + (size_t)i * n_points * 3, pr.xyz, (size_t)n_points * 3 * sizeof(float));
        memcpy(out_mean + 3 * i, pr.mean_m, 3 * sizeof(float));
        memcpy(out_voxel + 3 * i, pr.voxel, 3 * sizeof(int16_t));
        out_n_src[i] = pr.n_points_src;
    }
    return 0;
}

LIDET_PY_API int lidet_py_proposal_indices(uint32_t n_src, uint32_t n_out, uint32_t seed, uint32_t *out)
{
    return lidet_proposal_indices(n_src, n_out, seed, out);
}

/* The image of the last projection, copied out without running again (same layout as
 * lidet_py_proj_run's outputs; any output may be NULL). */
LIDET_PY_API int lidet_py_proj_copy(float *out_img, int32_t *out_idx, int32_t *out_point_pixel, uint32_t *out_stats,
                                    float *out_row_elev)
{
    return lidet_py_proj_run_outputs(out_img, out_idx, out_point_pixel, out_stats, out_row_elev);
}
