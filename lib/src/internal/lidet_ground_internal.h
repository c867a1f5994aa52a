/* SPDX-License-Identifier: MIT */
/* What both ground stages share, the float one (lidet_ground_filter.c, lidet_ground_ransac.c) and the integer one
 * (their _q twins): run checks, the sample buffer's cells, the per-cell control flow and the fallback. Only the
 * shared public types (lidet_ground_common.h, lidet_image.h): the float stage's own declarations are in
 * lidet_ground_float_internal.h, the integer stage's in lidet_ground_q_internal.h. Never installed. */
#ifndef LIDET_GROUND_INTERNAL_H
#define LIDET_GROUND_INTERNAL_H

#include <string.h>

#include "internal/lidet_assert.h"
#include "lidet/lidet_ground_common.h"
#include "lidet/lidet_image.h"

/* first column of sector s: the smallest c with c * n_sectors / n_cols >= s */
static inline uint32_t lidet__ground_sector_col(uint32_t s, uint32_t n_sectors, uint32_t n_cols)
{
    return (s * n_cols + n_sectors - 1u) / n_sectors;
}

/* The checks of both stages' runs, in this order: LIDET_ERR_STATE (not initialised), LIDET_ERR_ARG (the image
 * lacks a plane the stage reads), LIDET_ERR_BUFFER (larger than the build's capacity), LIDET_ERR_CONFIG (no row,
 * fewer than 4 columns or fewer columns than sectors); else LIDET_OK, and the stage's counts are zeroed. */
static inline lidet_status_t lidet__ground_run_check(int inited, int planes_ok,
                                                     const lidet_range_image_t *img, uint32_t n_sectors,
                                                     lidet_ground_stats_t *stats)
{
    if (!inited)
    {
        return LIDET_ERR_STATE;
    }
    if (!planes_ok)
    {
        return LIDET_ERR_ARG;
    }
    if (img->n_rows > LIDET_MAX_ROWS || img->n_cols > LIDET_MAX_COLS)
    {
        return LIDET_ERR_BUFFER;
    }
    if (img->n_rows < 1u || img->n_cols < 4u || img->n_cols < n_sectors)
    {
        return LIDET_ERR_CONFIG;
    }
    memset(stats, 0, sizeof *stats);
    return LIDET_OK;
}

/* The sample buffer of both stages' gathering: near samples of sector s fill it upwards from near_start to lo,
 * far ones downwards from far_end to hi (cells s and ns + s); after the last sector the counts: `total`
 * samples met, those past the buffer dropped. */
/* the third cell per sector is on (lidet_ground_cfg_t far2_split_m): a split, and this beyond it */
#define lidet__ground_far2_on(cfg) ((cfg)->ring_split_m > 0.0f && (cfg)->far2_split_m > (cfg)->ring_split_m)

/* the integer stage's test (mm) */
#define lidet__ground_q_far2_on(cfg)                                                                         \
    ((cfg)->ring_split_mm > 0u && (cfg)->far2_split_mm > (cfg)->ring_split_mm)

static inline void lidet__ground_cell_span(uint32_t *cell_first, uint32_t *cell_n, uint32_t s, uint32_t ns,
                                           uint32_t near_start, uint32_t lo, uint32_t hi, uint32_t far_end)
{
    cell_first[s] = near_start;
    cell_n[s] = lo - near_start;
    cell_first[ns + s] = hi;
    cell_n[ns + s] = far_end - hi;
}

static inline void lidet__ground_sample_counts(lidet_ground_stats_t *stats, uint32_t total, uint32_t lo,
                                               uint32_t hi)
{
    stats->n_samples = total;
    stats->n_samples_dropped = total - (lo + (LIDET_GROUND_MAX_SAMPLES - hi));
}

/* Per-point labels from a pixel mask of npix pixels (both stages' point_labels_of): a point takes its pixel's
 * label, 0 when it has none (-1) or the index is outside the image. inited: the stage's state is initialised.
 * LIDET_ERR_ARG (NULL mask, NULL arrays with n_points > 0), LIDET_ERR_STATE, else LIDET_OK. */
static inline lidet_status_t lidet__ground_point_labels(int inited, const uint8_t *mask, uint32_t npix,
                                                        const int32_t *point_pixel, uint32_t n_points,
                                                        uint8_t *out)
{
    uint32_t i;
    if (mask == 0 || ((point_pixel == 0 || out == 0) && n_points > 0u))
    {
        return LIDET_ERR_ARG;
    }
    if (!inited)
    {
        return LIDET_ERR_STATE;
    }
    for (i = 0; i < n_points; ++i)
    {
        const int32_t p = point_pixel[i];
        out[i] = (p >= 0 && (uint32_t)p < npix) ? mask[p] : 0u;
    }
    return LIDET_OK;
}

/* The per-cell control flow of both ground stages (the float one, lidet_ground_ransac.c, and the integer one,
 * lidet_ground_ransac_q.c); numeric-agnostic, the planes are the caller's. Cells: k < ns the near part of
 * sector k, k >= ns the far part of sector k - ns; only the first n_cells (ns, or 2 ns with a split) are
 * fitted, each with at least min_samples samples, in this order (the RNG runs in it). fit(ctx, k) fits cell
 * k and returns 1 when its plane passed the checks; copy(ctx, dst, src) sets the plane of cell dst to that
 * of cell src (src < 0: the mount plane). Then the fallback: a near cell without its own plane takes the
 * nearest FITTED near cell at most `reach` sectors away (s - k before s + k), else the mount plane; a far
 * cell without its own plane takes its sector's near plane. Fills source and the cell counts of stats. */
typedef int (*lidet__ground_fit_fn)(void *ctx, uint32_t k);
typedef void (*lidet__ground_copy_fn)(void *ctx, uint32_t dst, int32_t src);
/* beyond(ctx, p): sample pixel p lies at or beyond far2_split (the third cells) */
typedef int (*lidet__ground_beyond_fn)(void *ctx, lidet_ground_sample_t p);

/* cell k (a near one below ns) fitted when it holds min_samples samples; source and counts */
static inline void lidet__ground_fit_one(uint8_t *source, const uint32_t *cell_n, uint32_t ns,
                                         uint32_t n_cells, uint32_t min_samples, lidet_ground_stats_t *stats,
                                         lidet__ground_fit_fn fit, void *ctx, uint32_t k)
{
    const int near = k < ns;
    source[k] = near ? LIDET_GROUND_PLANE_MOUNT : LIDET_GROUND_PLANE_NEAR;
    if (k >= n_cells || cell_n[k] < min_samples)
    {
        stats->n_sectors_sparse += (uint16_t)near;
        return;
    }
    if (fit(ctx, k))
    {
        source[k] = LIDET_GROUND_PLANE_FITTED;
        if (near)
            ++stats->n_sectors_fitted;
        else
            ++stats->n_far_fitted;
    }
    else
    {
        stats->n_sectors_rejected += (uint16_t)near;
    }
}

/* the near cells' fallback: a near cell without its own plane takes the nearest FITTED near cell at most `reach`
 * sectors away (s - k before s + k), else the mount plane */
static inline void lidet__ground_near_fallback(uint8_t *source, uint32_t ns, uint32_t reach,
                                               lidet_ground_stats_t *stats, lidet__ground_copy_fn copy,
                                               void *ctx)
{
    uint32_t s, k;
    for (s = 0; s < ns; ++s)
    {
        int32_t from = -1;
        if (source[s] == LIDET_GROUND_PLANE_FITTED)
        {
            continue;
        }
        for (k = 1; k <= reach && from < 0; ++k)
        {
            const uint32_t left = (s + ns - (k % ns)) % ns, right = (s + k) % ns;
            if (source[left] == LIDET_GROUND_PLANE_FITTED)
                from = (int32_t)left;
            else if (source[right] == LIDET_GROUND_PLANE_FITTED)
                from = (int32_t)right;
        }
        copy(ctx, s, from);
        if (from >= 0)
        {
            source[s] = LIDET_GROUND_PLANE_NEIGHBOUR; /* never FITTED: not a source for others */
            ++stats->n_sectors_neighbour;
        }
        else
        {
            ++stats->n_sectors_mount;
        }
    }
}

static inline void lidet__ground_cells(uint8_t *source, const uint32_t *cell_n, uint32_t ns, uint32_t n_cells,
                                       uint32_t min_samples, uint32_t reach, lidet_ground_stats_t *stats,
                                       lidet__ground_fit_fn fit, lidet__ground_copy_fn copy, void *ctx)
{
    uint32_t s, k;
    /* one loop over the cells (one call site of fit: the stages inline it there), near ones first; the near
     * fallback between them, so a far cell's test reads its sector's final near plane (the fallback draws no
     * random number: the stream of draws is that of fitting every cell in order) */
    for (k = 0; k < 2u * ns; ++k)
    {
        if (k == ns)
        {
            lidet__ground_near_fallback(source, ns, reach, stats, copy, ctx);
        }
        lidet__ground_fit_one(source, cell_n, ns, n_cells, min_samples, stats, fit, ctx, k);
    }
    for (s = 0; s < ns; ++s)
    {
        if (source[ns + s] != LIDET_GROUND_PLANE_FITTED)
        {
            copy(ctx, ns + s, (int32_t)s);
            source[ns + s] = LIDET_GROUND_PLANE_NEAR;
        }
    }
}

/* The third cells' control flow (far2_split_m / far2_split_mm), after lidet__ground_cells, for both stages: sector
 * s's far samples that beyond() selects are moved to the front of its far block (one pass; those keep their
 * order, and the far fit is done, so the block's order is free), become cell 2 ns + s (its span in cell_first /
 * cell_n: 3 ns <= 2 LIDET_GROUND_MAX_SECTORS, init checks it) and are fitted by fit(ctx, 2 ns + s), which judges a
 * third cell's plane against the far plane at far2_split (the step) or by the sensor's height; without a plane, or
 * with fewer than min_samples samples, the cell takes the far plane (copy). */
/* one sector's third cell (the body of lidet__ground_far2_cells' loop, below; the integer stage's streamed run calls
 * it sector by sector) */
static inline void lidet__ground_far2_cell(uint8_t *source, uint32_t *cell_first, uint32_t *cell_n,
                                           lidet_ground_sample_t *sample_pix, uint32_t ns,
                                           uint32_t min_samples, lidet_ground_stats_t *stats,
                                           lidet__ground_beyond_fn beyond, lidet__ground_fit_fn fit,
                                           lidet__ground_copy_fn copy, void *ctx, uint32_t s)
{
    const uint32_t kf = ns + s, k = 2u * ns + s, a = cell_first[kf], n = cell_n[kf];
    lidet_ground_sample_t *idx = sample_pix + a;
    uint32_t i, m = 0;
    LIDET_ASSERT(a + n <= LIDET_GROUND_MAX_SAMPLES);
    for (i = 0; i < n; ++i)
    {
        if (beyond(ctx, idx[i]))
        {
            const lidet_ground_sample_t t = idx[i];
            idx[i] = idx[m];
            idx[m] = t;
            ++m;
        }
    }
    cell_first[k] = a;
    cell_n[k] = m;
    if (m >= min_samples && fit(ctx, k))
    {
        source[k] = LIDET_GROUND_PLANE_FITTED;
        ++stats->n_far2_fitted;
    }
    else
    {
        copy(ctx, k, (int32_t)kf);
        source[k] = LIDET_GROUND_PLANE_NEAR; /* the cell inside it */
    }
}

static inline void lidet__ground_far2_cells(uint8_t *source, uint32_t *cell_first, uint32_t *cell_n,
                                            lidet_ground_sample_t *sample_pix, uint32_t ns,
                                            uint32_t min_samples, lidet_ground_stats_t *stats,
                                            lidet__ground_beyond_fn beyond, lidet__ground_fit_fn fit,
                                            lidet__ground_copy_fn copy, void *ctx)
{
    uint32_t s;
    for (s = 0; s < ns; ++s)
    {
        lidet__ground_far2_cell(source, cell_first, cell_n, sample_pix, ns, min_samples, stats, beyond, fit,
                                copy, ctx, s);
    }
}

#endif
