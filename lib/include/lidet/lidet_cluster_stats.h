/* SPDX-License-Identifier: MIT */
/**
 * @file lidet_cluster_stats.h
 * @brief The counts of a clustering run, shared by the float (lidet_cluster.h) and the integer (lidet_cluster_q.h)
 *        clusterings. The fields name the float configuration's parameters (max_extent_m ...); the integer
 *        clustering counts the same events against its integer ones (max_extent_mm ...). No numeric type in here.
 */
#ifndef LIDET_CLUSTER_STATS_H
#define LIDET_CLUSTER_STATS_H

#include "lidet_types.h"

#ifdef __cplusplus
extern "C" {
#endif

/** @brief Counts of the last run (each dropped cluster is counted once, by the first filter it fails). */
typedef struct
{
    uint32_t n_candidates;       /**< non-ground pixels holding a point */
    uint32_t n_found;            /**< connected components of the first flood fill (before any filter; the
                                       regrowth's parts included) */
    uint32_t n_fragments;        /**< of them, below min_points and handed to the rescue (0 when it is off) */
    uint32_t n_rescue_joined;    /**< rescue groups that joined a kept cluster */
    uint32_t n_rescue_pixels;    /**< fragment pixels the rescue put into kept clusters (joined or new) */
    uint32_t n_dropped_small;    /**< fewer than min_points pixels: components of the first fill when
                                       the rescue is off; rescue groups that joined nothing when it is on */
    uint32_t n_dropped_extent;   /**< extent above max_extent_m */
    uint32_t n_dropped_height;   /**< mean height above max_mean_height_m */
    uint32_t n_dropped_capacity; /**< passed the filters but dropped for LIDET_MAX_CLUSTERS (rescue
                                       groups included) */
    uint32_t n_kept;             /**< clusters in the output */
    uint32_t n_pixels_kept;      /**< pixels labelled with a kept cluster */
    uint32_t n_queue_overflow;   /**< always 0: the queue holds every pixel (kept for the record) */
    uint32_t n_split;            /**< refinement: clusters cut into parts */
    uint32_t n_split_parts;      /**< refinement: new clusters the cuts made */
    uint32_t n_split_skipped;    /**< refinement: clusters examined but too large for the grid caps */
    uint32_t n_joined;           /**< refinement: clusters joined into another (car fragments) */
    uint32_t n_join_skipped;     /**< refinement: car pieces past max_join_pieces (joined nothing) */
    uint32_t n_fragment_pixels;  /**< pixels of the fragments handed to the rescue */
    uint32_t n_dropped_fragment_budget; /**< fragments dropped past max_fragment_pixels */
    uint32_t n_bridge_steps;            /**< nearer candidates stepped over (occluder bridging) */
    uint32_t n_regrown;      /**< over-extent components grown again with the tighter gap (regrow_gap_m) */
    uint32_t n_regrow_parts; /**< the parts they gave (each then kept, a fragment or dropped by a filter) */
} lidet_cluster_stats_t;

#ifdef __cplusplus
}
#endif

#endif /* LIDET_CLUSTER_STATS_H */
