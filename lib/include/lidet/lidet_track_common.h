/* SPDX-License-Identifier: MIT */
/**
 * @file lidet_track_common.h
 * @brief What the float (lidet_track.h) and the integer (lidet_track_q.h) trackers share: track states,
 *        output flags, assignment modes and the default heading class mask (docs/TRACKING.md). No numeric
 *        type in here.
 */
#ifndef LIDET_TRACK_COMMON_H
#define LIDET_TRACK_COMMON_H

#include "lidet_types.h"

#ifdef __cplusplus
extern "C" {
#endif

/** @brief A track's state. */
typedef enum
{
    LIDET_TRACK_TENTATIVE = 0, /**< born, fewer than confirm_hits hits; dies at its first miss */
    LIDET_TRACK_CONFIRMED = 1, /**< confirmed and updated by this scan's detection */
    LIDET_TRACK_COASTING = 2   /**< confirmed, missed this scan (predicted only; dies after max_misses) */
} lidet_track_state_t;

/** Output flag of the trackers' tracks call: also give the confirmed tracks that missed this scan. */
#define LIDET_TRACK_OUT_COASTING 1u
/** Output flag of the trackers' tracks call: also give the tentative tracks. */
#define LIDET_TRACK_OUT_TENTATIVE 2u

/** @brief How detections are assigned to tracks. */
typedef enum
{
    LIDET_TRACK_ASSIGN_OPTIMAL = 0, /**< minimum total cost (Hungarian method, shortest augmenting paths) */
    LIDET_TRACK_ASSIGN_GREEDY = 1   /**< cheapest feasible pair first (ties: lower slot, lower index) */
} lidet_track_assign_t;

/** Default heading_from_velocity: the classes (bits 1 << class) whose reported heading is the motion's
 *  direction when it is known: pedestrians and cyclists. */
#define LIDET_TRACK_HEADING_FROM_VELOCITY_DEFAULT                                                            \
    ((1u << LIDET_CLASS_PEDESTRIAN) | (1u << LIDET_CLASS_CYCLIST))

#ifdef __cplusplus
}
#endif

#endif /* LIDET_TRACK_COMMON_H */
