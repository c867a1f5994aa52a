/* SPDX-License-Identifier: MIT */
/**
 * @file lidet_ground_common.h
 * @brief What the float (lidet_ground.h) and the integer (lidet_ground_q.h) ground stages share: where a cell's
 *        plane came from, the counts of a run and the sample type. No numeric type in here (the planes are
 *        lidet_plane_t, lidet_types.h, and lidet_plane_q_t, lidet_q.h).
 */
#ifndef LIDET_GROUND_COMMON_H
#define LIDET_GROUND_COMMON_H

#include "lidet_types.h"

#ifdef __cplusplus
extern "C" {
#endif

/** @brief Where a sector's plane came from (lidet_ground_sector_source). */
typedef enum
{
    LIDET_GROUND_PLANE_FITTED = 0,    /**< RANSAC (+ refinement) on the sector's own samples */
    LIDET_GROUND_PLANE_NEIGHBOUR = 1, /**< copied from the nearest fitted sector */
    LIDET_GROUND_PLANE_MOUNT = 2,     /**< the mount plane z = -mount_height_m */
    LIDET_GROUND_PLANE_NEAR = 3       /**< far part of a sector without its own plane: the sector's
                                           near plane (also every far part when ring_split_m is 0) */
} lidet_ground_plane_source_t;

/** @brief Counts of the last run. */
typedef struct
{
    uint32_t n_samples;           /**< samples handed to RANSAC (passed the filter, on the step grid) */
    uint32_t n_samples_dropped;   /**< samples past LIDET_GROUND_MAX_SAMPLES (not used; status TRUNCATED) */
    uint32_t n_ground;            /**< pixels labelled ground */
    uint16_t n_sectors_fitted;    /**< near cells (whole sectors when ring_split_m is 0) with own plane */
    uint16_t n_sectors_neighbour; /**< near cells that took a neighbour's plane */
    uint16_t n_sectors_mount;     /**< near cells that took the mount plane */
    uint16_t n_sectors_sparse;    /**< near cells with fewer than min_samples samples */
    uint16_t n_sectors_rejected;  /**< near cells whose best plane failed the inlier/tilt/height checks */
    uint16_t n_far_fitted;        /**< far cells with their own plane (0 when ring_split_m is 0) */
    uint16_t n_far2_fitted;       /**< third cells (far2_split_m) with their own plane */
    uint32_t n_vetoed;            /**< pixels within the plane tolerance removed by the vertical veto */
    uint32_t n_hypotheses;        /**< RANSAC hypotheses scored (after degenerate/tilt rejection) */
} lidet_ground_stats_t;

/** @brief A ground sample: its pixel index. 2 B when every pixel index of the build fits (LIDET_MAX_ROWS
 *         * LIDET_MAX_COLS <= 65536, e.g. VLP-16 16 x 1800), else 4 B. */
#if LIDET_MAX_ROWS * LIDET_MAX_COLS <= 65536L
typedef uint16_t lidet_ground_sample_t;
#else
typedef uint32_t lidet_ground_sample_t;
#endif

#ifdef __cplusplus
}
#endif

#endif /* LIDET_GROUND_COMMON_H */
