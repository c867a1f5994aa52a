/* SPDX-License-Identifier: MIT */
/**
 * @file lidet_image.h
 * @brief The range image every stage after the projection reads, float (lidet_proj.h, lidet_ground.h,
 *        lidet_cluster.h, lidet_workspace.h) and integer (lidet_proj_q.h, lidet_ground_q.h, lidet_cluster_q.h,
 *        lidet_detector_q.h), and the unit of its compact pixels. Declared here so that neither twin owns it.
 *
 * Who fills which fields:
 *  - the float projection's own image (lidet_proj_t, lidet_proj_image): x_m, y_m, z_m, range_m, rxy_m,
 *    point_idx, row_elev_rad, row_elev_bam; the compact fields NULL;
 *  - a compact image of the float path (lidet_proj_run_buffers into x_4mm ..., a workspace's): x_4mm, y_4mm,
 *    z_4mm, range_4mm, row_elev_rad, row_elev_bam, rxy_m and point_idx where kept; x_m NULL;
 *  - the integer projection (lidet_proj_q_image, lidet_detector_q_image): x_4mm, y_4mm, z_4mm (all three NULL
 *    for a range-only image), range_4mm, point_idx, row_elev_bam, row_trig_q15, col_trig_q15; every float
 *    pointer NULL. The integer stages never read through a float pointer: they only require x_m to be NULL
 *    (a float image is LIDET_ERR_ARG there).
 */
#ifndef LIDET_IMAGE_H
#define LIDET_IMAGE_H

#include "lidet_types.h"

#ifdef __cplusplus
extern "C" {
#endif

/** @brief Unit of the compact image (a detector workspace's pixels, lidet_workspace.h): 4 mm, so int16
 *         x, y, z span +-131 m. Fixed (the field names say it: x_4mm ...). */
#define LIDET_PIXEL_M 0.004f
#define LIDET_PIXEL_PER_M 250.0f
/** @brief A compact image holds points up to this range (32750 steps of 4 mm, a margin below the int16
 *         limit for rounding): the projection drops farther points when it writes a compact image
 *         (counted in n_too_far, as points beyond max_range_m), so no coordinate ever wraps. */
#define LIDET_PIXEL_MAX_RANGE_M 131.0f

/**
 * @brief The range image: row-major arrays of n_rows * n_cols pixels, pixel = row * n_cols + col.
 * Empty pixels hold 0 in every float array and -1 in point_idx. A view into lidet_proj_t (or the
 * buffers of lidet_proj_run_buffers), valid until the next run or init on the same state.
 *
 * Two pixel formats. A float image (what lidet_proj_t produces, the reference) sets x_m, y_m, z_m,
 * range_m. A compact image (what a detector workspace keeps: 8 B per pixel instead of 16) sets x_m to
 * NULL and x_4mm, y_4mm, z_4mm, range_4mm instead: the same point rounded to 4 mm steps (round half
 * up, floor(v / 0.004 + 0.5)); a valid pixel has range_4mm >= 1, an empty one 0 everywhere. Every
 * stage reads both formats and decodes a compact value as (float)v * LIDET_PIXEL_M where it reads it.
 * The format is decided by x_m: non-NULL = float (the compact fields are then not read).
 */
typedef struct
{
    uint16_t n_rows;
    uint16_t n_cols;
    const float *x_m;            /**< x of the pixel's point; NULL for a compact image */
    const float *y_m;            /**< y */
    const float *z_m;            /**< z */
    const float *range_m;        /**< sqrt(x^2 + y^2 + z^2); > 0 exactly for valid pixels */
    const int16_t *x_4mm;        /**< compact image only (x_m NULL): x in 4 mm steps */
    const int16_t *y_4mm;        /**< compact: y */
    const int16_t *z_4mm;        /**< compact: z */
    const uint16_t *range_4mm;   /**< compact: the range (of the float point, then rounded); >= 1 exactly
                                    for valid pixels */
    const float *rxy_m;          /**< R = sqrt(x^2 + y^2), the horizontal range (of a compact image's
                                    decoded values); may be NULL (a detector workspace keeps it only with
                                    LIDET_WORKSPACE_KEEP_R: else the ground stage computes it) */
    const int32_t *point_idx;    /**< index of the winning input point, -1 = empty; may be NULL (a
                                    workspace overlays it with later scratch). Validity is range_m > 0,
                                    which the later stages read (the two agree on every image) */
    const float *row_elev_rad;   /**< n_rows beam elevations in row order (row 0 = top) */
    const int32_t *row_elev_bam; /**< the same elevations as signed BAM32 (lidet_q.h: 2^32 a turn), what the
                                      integer stages read; the float projection rounds its float ones */
    const int32_t *row_trig_q15; /**< integer range-only image (x_4mm, y_4mm, z_4mm NULL): cos, sin of each
                                      row's elevation (Q15, 2 per row), or NULL (computed where read) */
    const int32_t *col_trig_q15; /**< the same: sin, cos (Q15) of the first quarter's column-centre angles
                                      (n_cols / 4 pairs, n_cols a multiple of 4), or NULL (computed where
                                      read); lib/src/internal/lidet_qpix.h */
} lidet_range_image_t;

#ifdef __cplusplus
}
#endif

#endif /* LIDET_IMAGE_H */
