/* SPDX-License-Identifier: MIT */
/**
 * @file lidet_q.h
 * @brief Units and shared types of the integer (fixed-point) path (docs/FIXED_POINT.md).
 *
 * The integer stages (lidet_*_q functions) are compiled in every build and are the only API of the
 * integer-only build (-DLIDET_FIXED_POINT=ON). They never touch float. Units:
 * - input points: int32 millimetres, records of `stride` int32 whose first three are x, y, z (sensor frame,
 *   lidet_types.h); |coordinate| <= LIDET_Q_COORD_MAX_MM, farther points are dropped and counted;
 * - range-image pixels and everything derived from them: 4 mm steps (LIDET_PIXEL_M), the compact image of
 *   lidet_image.h (int16 x, y, z; uint16 range);
 * - angles: BAM32, 2^32 = one turn (int32 for signed angles, uint32 where they wrap); sensor beam
 *   elevations are given in microradians;
 * - unit vectors, sines and cosines: Q30 (2^30 = 1.0); ratios and slopes: Q16;
 * - scores: Q15 (32768 = 1.0); energies: Q16 nats (65536 = 1.0);
 * - boxes out: millimetres and a BAM32 yaw.
 */
#ifndef LIDET_Q_H
#define LIDET_Q_H

#include "lidet_types.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Largest accepted |x|, |y|, |z| of an input point, mm (an int16 pixel in 4 mm steps holds +-131.07 m). */
#define LIDET_Q_COORD_MAX_MM 131000

/** Q formats (value = integer / 2^Q). */
#define LIDET_Q_UNIT 30   /**< unit vectors, sin, cos */
#define LIDET_Q_RATIO 16  /**< ratios, slopes */
#define LIDET_Q_SCORE 15  /**< scores in [0, 1] */
#define LIDET_Q_ENERGY 16 /**< energies, nats */

/**
 * @brief A ground plane in integer form: n . p >> 30 + d_4mm is the signed height of p (p in 4 mm steps)
 *        above the plane, in 4 mm steps; (nx, ny, nz) a Q30 unit normal pointing up (nz > 0).
 */
typedef struct
{
    int32_t nx, ny, nz; /**< Q30 */
    int32_t d_4mm;      /**< 4 mm steps */
} lidet_plane_q_t;

/** @brief One proposal of the integer path: what the int8 PointNets see. */
typedef struct
{
    int16_t xyz[LIDET_PROPOSAL_POINTS]
               [3];        /**< first n_points rows used: member points minus mean_4mm, 4 mm */
    int32_t mean_4mm[3];   /**< the cluster mean (sensor frame), 4 mm steps, rounded */
    int16_t voxel[3];      /**< azimuth, elevation, range bins of the mean (signed) */
    uint32_t n_points;     /**< rows of xyz filled */
    uint32_t n_points_src; /**< member pixels of the cluster */
} lidet_proposal_q_t;

/** @brief An oriented 3D box of the integer path (geometric centre, as lidet_box_t). */
typedef struct
{
    int32_t cx_mm, cy_mm, cz_mm; /**< centre */
    int32_t l_mm, w_mm, h_mm;    /**< length (along heading), width, height */
    int32_t yaw_bam;             /**< heading about +z from +x, signed BAM32 */
} lidet_box_q_t;

#ifdef __cplusplus
}
#endif

#endif /* LIDET_Q_H */
