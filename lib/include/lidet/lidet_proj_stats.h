/* SPDX-License-Identifier: MIT */
/**
 * @file lidet_proj_stats.h
 * @brief The counts of a projection run, shared by the float (lidet_proj.h) and the integer (lidet_proj_q.h)
 *        projections. The fields name the float configuration's limits; the integer projection counts against
 *        its millimetre limits and leaves n_nonfinite 0. The image both produce: lidet_image.h.
 */
#ifndef LIDET_PROJ_STATS_H
#define LIDET_PROJ_STATS_H

#include "lidet_types.h"

#ifdef __cplusplus
extern "C" {
#endif

/** @brief Why points were not projected (counts of the last run). */
typedef struct
{
    uint32_t n_points_in;     /**< points passed to run */
    uint32_t n_projected;     /**< points that map to a pixel (winners and losers of a pixel) */
    uint32_t n_pixels_filled; /**< pixels holding a point */
    uint32_t n_nonfinite;     /**< x, y or z NaN or +-Inf */
    uint32_t n_too_close;     /**< range < min_range_m (zero range included) */
    uint32_t n_too_far;       /**< range > max_range_m */
    uint32_t n_out_of_fov;    /**< elevation outside the beams (+ margin) */
    uint32_t n_bad_ring;      /**< ring index >= n_rows (ring path only) */
    uint32_t n_truncated;     /**< points past LIDET_MAX_POINTS, not looked at */
    uint32_t n_out_of_window; /**< finite, in range, column outside the azimuth window (cfg azimuth_half_rad),
                                   whatever its elevation or ring (not in n_out_of_fov, n_bad_ring) */
} lidet_proj_stats_t;

#ifdef __cplusplus
}
#endif

#endif /* LIDET_PROJ_STATS_H */
