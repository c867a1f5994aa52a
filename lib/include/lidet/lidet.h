/* SPDX-License-Identifier: MIT */
/**
 * @file lidet.h
 * @brief lidet: road-user detection in one LiDAR scan on one CPU core or a microcontroller.
 *
 * Umbrella header. The pipeline, each stage callable alone over caller-owned memory:
 *   points -> lidet_proj (range image) -> ground mask -> clusters (proposals) -> PointNets
 *   -> lidet_tracker (tracks across scans, lidet_track.h).
 * Frame: x forward, y left, z up, metres, radians (lidet_types.h). No allocation, no stdio, no
 * double anywhere in the library; capacities are compile-time (lidet_opt.h).
 * Method: Seppänen et al., "No GPU? No problem: an ultra fast 3D detection of road users with a
 * simple proposal generator and energy-based out-of-distribution PointNets".
 */
#ifndef LIDET_H
#define LIDET_H

#define LIDET_VERSION_MAJOR 0
#define LIDET_VERSION_MINOR 1
#define LIDET_VERSION_PATCH 0
#define LIDET_VERSION_STRING "0.1.0"

#include "lidet_cluster.h"
#include "lidet_cluster_q.h"
#include "lidet_cluster_stats.h"
#include "lidet_detector.h"
#include "lidet_detector_common.h"
#include "lidet_detector_q.h"
#include "lidet_ground.h"
#include "lidet_ground_common.h"
#include "lidet_ground_q.h"
#include "lidet_image.h"
#include "lidet_opt.h"
#include "lidet_ouster.h"
#include "lidet_pointnet.h"
#include "lidet_pointnet_common.h"
#include "lidet_pointnet_q.h"
#include "lidet_proj.h"
#include "lidet_proj_q.h"
#include "lidet_proj_stats.h"
#include "lidet_q.h"
#include "lidet_sensor.h"
#include "lidet_sensor_q.h"
#include "lidet_track.h"
#include "lidet_track_common.h"
#include "lidet_track_q.h"
#include "lidet_types.h"
#include "lidet_velodyne.h"
#include "lidet_workspace.h"

#ifdef __cplusplus
extern "C" {
#endif

/** @brief The library version as "MAJOR.MINOR.PATCH" (static storage). */
const char *lidet_version(void);

#ifdef __cplusplus
}
#endif

#endif /* LIDET_H */
