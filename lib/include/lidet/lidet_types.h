/* SPDX-License-Identifier: MIT */
/**
 * @file lidet_types.h
 * @brief Status codes, the coordinate frame, and the point and box types shared by every stage.
 *
 * Frame (fixed for the whole library): origin at the sensor's optical centre, x forward, y left,
 * z up (right-handed); lengths in metres (`_m`), angles in radians (`_rad`), yaw about +z measured
 * from +x towards +y. Point clouds are arrays of float32 records of `stride` floats whose first
 * three are x, y, z (KITTI .bin records are x, y, z, remission: stride 4).
 */
#ifndef LIDET_TYPES_H
#define LIDET_TYPES_H

#include <stdint.h>

#include "lidet_opt.h"

#ifdef __cplusplus
extern "C" {
#endif

/** A cluster's member pixel (its pixel index, row * n_cols + col): 2 B when every pixel index of the build fits
 *  16 bits (LIDET_MAX_ROWS * LIDET_MAX_COLS <= 65536, e.g. VLP-16 16 x 1800), else 4 B. The clusterings' members
 *  arrays (float and integer) hold this type. */
#if LIDET_MAX_ROWS * LIDET_MAX_COLS <= 65536L
typedef uint16_t lidet_member_t;
#else
typedef int32_t lidet_member_t;
#endif

/**
 * @brief Result of every lidet call. 0 is success, positive values are success with a remark,
 *        negative values are errors (nothing useful was produced).
 */
typedef enum
{
    LIDET_OK = 0,            /**< success */
    LIDET_TRUNCATED = 1,     /**< success, but the input exceeded a capacity: the excess was dropped
                                  deterministically and counted in the stage's stats */
    LIDET_ERR_ARG = -1,      /**< a NULL pointer or an argument out of range */
    LIDET_ERR_CONFIG = -2,   /**< a configuration value is out of range or inconsistent */
    LIDET_ERR_BUFFER = -3,   /**< a buffer or compile-time capacity is too small for the request */
    LIDET_ERR_MODEL = -4,    /**< model shape, format or version mismatch */
    LIDET_ERR_STATE = -5,    /**< the state was not initialised by the stage's init */
    LIDET_ERR_NOT_FOUND = -6 /**< a named item (e.g. sensor profile) does not exist */
} lidet_status_t;

/** @brief True for LIDET_OK and the positive (success with remark) statuses. */
#define LIDET_SUCCEEDED(st) ((st) >= 0)

/**
 * @brief Human-readable name of a status ("LIDET_OK: success", ...); never NULL.
 * Returns "" when built with LIDET_ENABLE_STATUS_STRINGS 0.
 */
const char *lidet_status_str(lidet_status_t status);

/** @brief A point in the sensor frame (metres). */
typedef struct
{
    float x_m;
    float y_m;
    float z_m;
} lidet_point_t;

/** @brief Object classes, in the order of the classifier's logits. */
typedef enum
{
    LIDET_CLASS_CAR = 0,
    LIDET_CLASS_CYCLIST = 1,
    LIDET_CLASS_PEDESTRIAN = 2,
    LIDET_N_CLASSES = 3
} lidet_class_t;

/**
 * @brief An oriented 3D box in the sensor frame.
 * The centre is the box's geometric centre (not the bottom, unlike KITTI's camera labels);
 * l runs along the heading, w across it, h along +z.
 */
typedef struct
{
    float cx_m, cy_m, cz_m; /**< centre */
    float l_m, w_m, h_m;    /**< length (along heading), width, height */
    float yaw_rad;          /**< heading about +z from +x, in (-pi, pi] */
} lidet_box_t;

/**
 * @brief The origin of a proposal's z (x and y are always centred on the cluster mean).
 *
 * LIDET_PROPOSAL_Z_MEAN: the points minus the cluster mean, as in Frustum PointNets.
 * LIDET_PROPOSAL_Z_GROUND: z is measured from the ground under the mean (the cluster's plane, the same one its
 * height filter reads: mean z minus the record's height above it, lidet_cluster_rec_t height_m or
 * lidet_cluster_q_rec_t height_4mm), and the proposal's mean_m[2] is that ground
 * height, so boxes decode from it. A person seen only from the waist up over a parked car then keeps the heights of
 * a whole person's upper half instead of looking like a short object centred on 0.
 */
typedef enum
{
    LIDET_PROPOSAL_Z_MEAN = 0,
    LIDET_PROPOSAL_Z_GROUND = 1
} lidet_proposal_z_origin_t;

/**
 * @brief A plane n . p + d = 0 in the sensor frame: (nx, ny, nz) unit normal pointing up (nz > 0),
 * so n . p + d is the signed height of p above the plane (metres). The ground stage produces one per
 * azimuth sector; later stages (cluster height filter) read them.
 */
typedef struct
{
    float nx, ny, nz;
    float d_m;
} lidet_plane_t;

/** Format version of generated weight files (weights/): a generated file whose version differs fails
 *  to compile, and lidet_pn_init rejects a descriptor of another version (LIDET_ERR_MODEL). */
#define LIDET_WEIGHTS_FORMAT_VERSION 1

/** @brief Magic value stored by every stage's init, checked by its run (LIDET_ERR_STATE). */
#define LIDET_INIT_MAGIC 0x6C646574u /* "ldet" */

#ifdef __cplusplus
}
#endif

#endif /* LIDET_TYPES_H */
