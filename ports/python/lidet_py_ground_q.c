/* SPDX-License-Identifier: MIT */
/* Flat C entry points of the integer ground stage for the Python bindings (tools/lidet_tools/native/_ground.py;
 * project_compact in tools/lidet_tools/native/_proj.py): a compact image from a context's projection (as a
 * detector workspace makes it), the integer stage and the float stage on that same image, and their host timing.
 * Host only (heap). */
#include <stddef.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "lidet/lidet.h"

#if defined(_WIN32)
#define LIDET_PY_API __declspec(dllexport)
#else
#define LIDET_PY_API __attribute__((visibility("default")))
#endif

/* lidet_py.c */
lidet_proj_state_t *lidet_py_ctx_proj_state(void *ctx);
void lidet_py_ground_planes_out(const lidet_ground_t *g, float *planes, uint8_t *source, lidet_ground_stats_t *stats);

/* Project a scan with the context's projection into a compact image: x4, y4, z4 (int16), r4 (uint16) of
 * rows * cols pixels, point_pixel (n entries, may be NULL), row_elev_bam (rows, may be NULL). */
LIDET_PY_API int lidet_py_ground_q_project(void *ctx, const float *pts, uint32_t n, uint32_t stride, int16_t *x4,
                                           int16_t *y4, int16_t *z4, uint16_t *r4, int32_t *point_pixel,
                                           int32_t *row_elev_bam)
{
    lidet_proj_state_t *st = lidet_py_ctx_proj_state(ctx);
    lidet_proj_buffers_t b;
    lidet_range_image_t img;
    int rc;
    if (st == NULL)
        return LIDET_ERR_STATE;
    memset(&b, 0, sizeof b);
    b.x_4mm = x4;
    b.y_4mm = y4;
    b.z_4mm = z4;
    b.range_4mm = r4;
    b.point_idx = (int32_t *)malloc(sizeof(int32_t) * LIDET_MAX_ROWS * LIDET_MAX_COLS);
    b.point_pixel = point_pixel != NULL ? (int32_t *)malloc(sizeof(int32_t) * LIDET_MAX_POINTS) : NULL;
    if (b.point_idx == NULL || (point_pixel != NULL && b.point_pixel == NULL))
    {
        free(b.point_idx);
        free(b.point_pixel);
        return LIDET_ERR_BUFFER;
    }
    rc = lidet_proj_run_buffers(st, &b, pts, n, stride, NULL);
    if (rc >= 0)
    {
        lidet_proj_image_of(st, &b, &img);
        if (point_pixel != NULL)
            memcpy(point_pixel, b.point_pixel, sizeof(int32_t) * (n < LIDET_MAX_POINTS ? n : LIDET_MAX_POINTS));
        if (row_elev_bam != NULL)
            memcpy(row_elev_bam, img.row_elev_bam, sizeof(int32_t) * img.n_rows);
    }
    free(b.point_idx);
    free(b.point_pixel);
    return rc;
}

/* ---- the integer configuration as a vector of int64 in the order of k_cfg_fields ---------------------- */
typedef struct
{
    const char *name;
    uint32_t offset, size;
    int is_signed;
} qfield_t;

#define QF(f, sg) {#f, (uint32_t)offsetof(lidet_ground_q_cfg_t, f), (uint32_t)sizeof(((lidet_ground_q_cfg_t *)0)->f), sg}
static const qfield_t k_cfg_fields[] = {
    QF(fy_max_q16, 0), QF(fx_max_mm, 0), QF(fx_on_z, 0), QF(require_descending, 0), QF(height_gate, 0),
    QF(refine_iters, 0), QF(seed_per_cell, 0), QF(gate_above_mm, 1), QF(gate_below_mm, 1), QF(mount_height_mm, 1), QF(n_sectors, 0),
    QF(ransac_iters, 0), QF(sample_step, 0), QF(sample_col_step, 0), QF(eval_samples, 0), QF(min_samples, 0),
    QF(min_inliers, 0), QF(fallback_sectors, 0), QF(confidence_q16, 0), QF(inlier_mm, 0), QF(max_tilt_urad, 0),
    QF(max_height_dev_mm, 0), QF(ring_split_mm, 0), QF(far_max_step_mm, 0), QF(far2_split_mm, 0), QF(seed, 0), QF(ground_mm, 0), QF(ground_per_m_q16, 0),
    QF(below_factor_q16, 0), QF(veto_slope_q16, 0), QF(veto_min_dz_mm, 0)};
#define N_QF (sizeof k_cfg_fields / sizeof k_cfg_fields[0])

/* name of field i (NULL past the end) */
LIDET_PY_API const char *lidet_py_ground_q_field(uint32_t i)
{
    return i < N_QF ? k_cfg_fields[i].name : NULL;
}

static void cfg_to_vec(const lidet_ground_q_cfg_t *c, int64_t *v)
{
    uint32_t i;
    for (i = 0; i < N_QF; ++i)
    {
        const unsigned char *p = (const unsigned char *)c + k_cfg_fields[i].offset;
        switch (k_cfg_fields[i].size)
        {
        case 1: v[i] = *(const uint8_t *)p; break;
        case 2: v[i] = *(const uint16_t *)p; break;
        default: v[i] = k_cfg_fields[i].is_signed ? (int64_t) * (const int32_t *)p : (int64_t) * (const uint32_t *)p;
        }
    }
}

/* refuses a value its field cannot hold (the stage's init checks the ranges) */
static int vec_to_cfg(const int64_t *v, lidet_ground_q_cfg_t *c)
{
    uint32_t i;
    memset(c, 0, sizeof *c);
    for (i = 0; i < N_QF; ++i)
    {
        unsigned char *p = (unsigned char *)c + k_cfg_fields[i].offset;
        const uint32_t sz = k_cfg_fields[i].size;
        const int64_t lo = k_cfg_fields[i].is_signed ? -((int64_t)1 << (8 * sz - 1)) : 0;
        const int64_t hi = k_cfg_fields[i].is_signed ? ((int64_t)1 << (8 * sz - 1)) - 1 : ((int64_t)1 << (8 * sz)) - 1;
        if (v[i] < lo || v[i] > hi)
            return LIDET_ERR_ARG;
        switch (sz)
        {
        case 1: *(uint8_t *)p = (uint8_t)v[i]; break;
        case 2: *(uint16_t *)p = (uint16_t)v[i]; break;
        default:
            if (k_cfg_fields[i].is_signed)
                *(int32_t *)p = (int32_t)v[i];
            else
                *(uint32_t *)p = (uint32_t)v[i];
        }
    }
    return LIDET_OK;
}

LIDET_PY_API void lidet_py_ground_q_default(uint32_t rows, int32_t mount_mm, int64_t *out)
{
    lidet_ground_q_cfg_t c;
    lidet_ground_q_cfg_default(&c, rows, mount_mm);
    cfg_to_vec(&c, out);
}

static void compact_image(lidet_range_image_t *img, uint32_t rows, uint32_t cols, const int16_t *x4,
                          const int16_t *y4, const int16_t *z4, const uint16_t *r4)
{
    memset(img, 0, sizeof *img);
    img->n_rows = (uint16_t)rows;
    img->n_cols = (uint16_t)cols;
    img->x_4mm = x4;
    img->y_4mm = y4;
    img->z_4mm = z4;
    img->range_4mm = r4;
}

/* The integer stage on a compact image. Outputs (any may be NULL): mask / sample rows * cols bytes, planes
 * 2 n_sectors * 4 int32 (nx ny nz d_4mm), plane_d 2 n_sectors int64 (D in 4 mm / 2^30), source 2 n_sectors
 * bytes, stats a lidet_ground_stats_t. */
LIDET_PY_API int lidet_py_ground_q_run(const int64_t *cfgv, uint32_t rows, uint32_t cols, const int16_t *x4,
                                       const int16_t *y4, const int16_t *z4, const uint16_t *r4, uint8_t *mask,
                                       uint8_t *sample, int32_t *planes, int64_t *plane_d, uint8_t *source,
                                       lidet_ground_stats_t *stats)
{
    lidet_ground_q_cfg_t c;
    lidet_range_image_t img;
    lidet_ground_q_t *g;
    uint32_t npix = rows * cols, s;
    int rc;
    if (cfgv == NULL || rows > 0xFFFFu || cols > 0xFFFFu)
        return LIDET_ERR_ARG;
    rc = vec_to_cfg(cfgv, &c);
    if (rc < 0)
        return rc;
    g = (lidet_ground_q_t *)malloc(sizeof *g);
    if (g == NULL)
        return LIDET_ERR_BUFFER;
    rc = lidet_ground_q_init(g, &c);
    compact_image(&img, rows, cols, x4, y4, z4, r4);
    if (rc >= 0)
        rc = lidet_ground_q_run(g, &img);
    if (rc >= 0)
    {
        if (mask != NULL)
            memcpy(mask, lidet_ground_q_mask(g), npix);
        if (sample != NULL)
            memcpy(sample, lidet_ground_q_samples(g), npix);
        {
            /* near, far and, with the third cells, theirs */
            const uint32_t n_cells =
                (c.ring_split_mm > 0u && c.far2_split_mm > c.ring_split_mm ? 3u : 2u) * c.n_sectors;
            for (s = 0; s < n_cells; ++s)
            {
                if (planes != NULL)
                {
                    planes[4 * s + 0] = g->state.planes[s].nx;
                    planes[4 * s + 1] = g->state.planes[s].ny;
                    planes[4 * s + 2] = g->state.planes[s].nz;
                    planes[4 * s + 3] = g->state.planes[s].d_4mm;
                }
                if (plane_d != NULL)
                    plane_d[s] = g->state.plane_d[s];
                if (source != NULL)
                    source[s] = g->state.source[s];
            }
        }
        if (stats != NULL)
            *stats = g->state.stats;
    }
    free(g);
    return rc;
}

/* The float stage on the same compact image (it decodes the 4 mm values): mask, sample rows * cols bytes,
 * planes 2 n_sectors * 4 floats, source, stats (any may be NULL). */
LIDET_PY_API int lidet_py_ground_float_compact(const lidet_ground_cfg_t *cfg, uint32_t rows, uint32_t cols,
                                               const int16_t *x4, const int16_t *y4, const int16_t *z4,
                                               const uint16_t *r4, uint8_t *mask, uint8_t *sample, float *planes,
                                               uint8_t *source, lidet_ground_stats_t *stats)
{
    lidet_range_image_t img;
    lidet_ground_t *g;
    uint32_t npix = rows * cols;
    int rc;
    if (cfg == NULL || rows > 0xFFFFu || cols > 0xFFFFu)
        return LIDET_ERR_ARG;
    g = (lidet_ground_t *)malloc(sizeof *g);
    if (g == NULL)
        return LIDET_ERR_BUFFER;
    rc = lidet_ground_init(g, cfg);
    compact_image(&img, rows, cols, x4, y4, z4, r4);
    if (rc >= 0)
        rc = lidet_ground_run(g, &img);
    if (rc >= 0)
    {
        if (mask != NULL)
            memcpy(mask, lidet_ground_mask(g), npix);
        if (sample != NULL)
            memcpy(sample, lidet_ground_samples(g), npix);
        lidet_py_ground_planes_out(g, planes, source, stats);
    }
    free(g);
    return rc;
}

static uint64_t now_ns(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (uint64_t)ts.tv_sec * 1000000000u + (uint64_t)ts.tv_nsec;
}

static int cmp_u64(const void *a, const void *b)
{
    const uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return x < y ? -1 : x > y;
}

/* Host timing of both stages on one compact image, interleaved run by run, over `repeats` runs each (1..1000):
 * out_ns[0], [1] the float and the integer stage's medians, out_ns[2], [3] their fastest runs (a loaded machine
 * preempts the longer runs more often: the minimum is the steadier figure there). */
LIDET_PY_API int lidet_py_ground_q_time(const lidet_ground_cfg_t *cfg_f, const int64_t *cfgv, uint32_t rows,
                                        uint32_t cols, const int16_t *x4, const int16_t *y4, const int16_t *z4,
                                        const uint16_t *r4, uint32_t repeats, uint64_t *out_ns)
{
    lidet_ground_q_cfg_t c;
    lidet_range_image_t img;
    lidet_ground_t *gf;
    lidet_ground_q_t *gq;
    uint64_t tf[1000], tq[1000];
    uint32_t i;
    int rc;
    if (cfg_f == NULL || cfgv == NULL || out_ns == NULL || repeats < 1u || repeats > 1000u)
        return LIDET_ERR_ARG;
    rc = vec_to_cfg(cfgv, &c);
    if (rc < 0)
        return rc;
    gf = (lidet_ground_t *)malloc(sizeof *gf);
    gq = (lidet_ground_q_t *)malloc(sizeof *gq);
    if (gf == NULL || gq == NULL)
    {
        free(gf);
        free(gq);
        return LIDET_ERR_BUFFER;
    }
    compact_image(&img, rows, cols, x4, y4, z4, r4);
    rc = lidet_ground_init(gf, cfg_f);
    if (rc >= 0)
        rc = lidet_ground_q_init(gq, &c);
    for (i = 0; i < repeats && rc >= 0; ++i)
    {
        uint64_t t0 = now_ns();
        rc = lidet_ground_run(gf, &img);
        tf[i] = now_ns() - t0;
        if (rc < 0)
            break;
        t0 = now_ns();
        rc = lidet_ground_q_run(gq, &img);
        tq[i] = now_ns() - t0;
    }
    if (rc >= 0)
    {
        qsort(tf, repeats, sizeof tf[0], cmp_u64);
        qsort(tq, repeats, sizeof tq[0], cmp_u64);
        out_ns[0] = tf[repeats / 2];
        out_ns[1] = tq[repeats / 2];
        out_ns[2] = tf[0];
        out_ns[3] = tq[0];
    }
    free(gf);
    free(gq);
    return rc;
}
