/* SPDX-License-Identifier: MIT */
/**
 * @file lidet_user_config.h
 * @brief Capacities of the KITTI-like firmware image (ports/firmware, LIDET_FW_SENSOR=hdl64): one Velodyne
 *        HDL-64E revolution as KITTI records it (64 beams, 2048 columns, ~120k returns). About 5 MiB of RAM:
 *        built only for targets with that much (QEMU virt), next to the VLP-16 images (config/vlp16).
 */
#ifndef LIDET_USER_CONFIG_H
#define LIDET_USER_CONFIG_H

#define LIDET_MAX_ROWS 64
#define LIDET_MAX_COLS 2048
#define LIDET_MAX_POINTS 131072  /* KITTI scans: 100k-130k returns */
#define LIDET_MAX_CLUSTERS 1024  /* the host default: a street scene has a few hundred clusters */
#define LIDET_MAX_DETECTIONS 128

#endif /* LIDET_USER_CONFIG_H */
