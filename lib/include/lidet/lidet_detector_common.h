/* SPDX-License-Identifier: MIT */
/**
 * @file lidet_detector_common.h
 * @brief What the float detector (lidet_detector.h, with its workspace lidet_workspace.h) and the integer detector
 *        (lidet_detector_q.h) share: the clock callback, the indices of the timed stages and what became of each
 *        cluster. No numeric type in here.
 */
#ifndef LIDET_DETECTOR_COMMON_H
#define LIDET_DETECTOR_COMMON_H

#include "lidet_types.h"

#ifdef __cplusplus
extern "C" {
#endif

/** @brief Member pixels a car's cluster needs before the flat-surface test judges it (lidet_detector_cfg_t
 *         car_min_z_spread_m): fewer are a far or partly hidden car, whose roof alone can be flat. */
#define LIDET_DET_FLAT_MIN_POINTS 100u

/** @brief The car boxes' ground (lidet_detector_cfg_t car_ground_m, lidet_detector_q_cfg_t car_ground_mm): a car
 *         box is stretched down to the median height of the ground pixels around it when at least this many lie
 *         within LIDET_DET_GROUND_WINDOW_MM of its bottom, the median taken in bins of LIDET_DET_GROUND_BIN_MM over
 *         [bottom - window, bottom + window), and only when the box's bottom lies above it by less than
 *         LIDET_DET_GROUND_MAX_LIFT_MM (docs/DETECTOR.md, "Car boxes down to the ground"). */
#define LIDET_DET_GROUND_MIN_PIXELS 5u
#define LIDET_DET_GROUND_WINDOW_MM 1000
#define LIDET_DET_GROUND_BIN_MM 20
#define LIDET_DET_GROUND_MAX_LIFT_MM 500
/** @brief The histogram's bins (2 windows / bin) */
#define LIDET_DET_GROUND_BINS (2 * LIDET_DET_GROUND_WINDOW_MM / LIDET_DET_GROUND_BIN_MM)

/** @brief A timestamp source (e.g. a cycle counter or a monotonic clock); ticks in the caller's unit. */
typedef uint32_t (*lidet_clock_fn)(void *ctx);

/** @brief Stages timed by the detector (indices of lidet_detector_stats_t.ticks and lidet_detector_q_stats_t.ticks;
 *         the first three are lidet_workspace_run_timed's ticks). */
enum
{
    LIDET_DET_STAGE_PROJECT = 0,  /**< projection */
    LIDET_DET_STAGE_GROUND = 1,   /**< ground segmentation */
    LIDET_DET_STAGE_CLUSTER = 2,  /**< clustering */
    LIDET_DET_STAGE_CLASSIFY = 3, /**< candidate ordering, proposals, classifier */
    LIDET_DET_STAGE_BOX = 4,      /**< box net */
    LIDET_DET_STAGE_POST = 5,     /**< size check, NMS */
    LIDET_DET_N_STAGES = 6
};

/** @brief What became of each kept cluster in the last run (lidet_detector_outcomes, lidet_detector_q_outcomes). */
typedef enum
{
    LIDET_DET_OUT_CROP = 1,     /**< outside the azimuth window */
    LIDET_DET_OUT_RANGE = 2,    /**< beyond max_range_m */
    LIDET_DET_OUT_BUDGET = 3,   /**< past max_proposals, or passed gate 1 past max_boxes */
    LIDET_DET_OUT_GATE1 = 4,    /**< classified, rejected by gate 1 */
    LIDET_DET_OUT_GATE2 = 5,    /**< boxed, rejected by gate 2 */
    LIDET_DET_OUT_SIZE = 6,     /**< boxed, impossible size for its class (or a non-finite centre or yaw), or
                                     a car whose cluster is a flat surface (lidet_detector_cfg_t
                                     car_min_z_spread_m) */
    LIDET_DET_OUT_NMS = 7,      /**< suppressed by the NMS */
    LIDET_DET_OUT_CAPACITY = 8, /**< past LIDET_MAX_DETECTIONS */
    LIDET_DET_OUT_DETECTED = 9, /**< a detection of the output */
    LIDET_DET_OUT_TALL = 10,    /**< taller than max_height_extent_m: no road user, not classified */
    LIDET_DET_OUT_GROUP = 11,   /**< no detection of its own, split into people by the group split: its parts'
                                     detections carry its id (lidet_detector_cfg_t group_split) */
    LIDET_DET_OUT_SCORE = 12 /**< its detection scored below its class's min_score (lidet_detector_cfg_t) */
} lidet_det_outcome_t;

#ifdef __cplusplus
}
#endif

#endif /* LIDET_DETECTOR_COMMON_H */
