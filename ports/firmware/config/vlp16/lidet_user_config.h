/* SPDX-License-Identifier: MIT */
/**
 * @file lidet_user_config.h
 * @brief Capacities of the firmware images (ports/firmware): one Velodyne VLP-16 (16 beams, 1800 columns
 *        at 0.2 deg, at most ~29k returns per revolution in single-return mode).
 *
 * Read by lidet_opt.h when LIDET_USER_CONFIG is defined. The firmware images and the host reference
 * program they are compared with (fw_host_ref, tests/firmware.cmake) are built with this same file, so both run the
 * detector with identical capacities. Copy it next to your own firmware and adapt it (docs/PORTING.md).
 */
#ifndef LIDET_USER_CONFIG_H
#define LIDET_USER_CONFIG_H

#define LIDET_MAX_ROWS 16        /* VLP-16: 16 rings */
#define LIDET_MAX_COLS 1800      /* 360 deg / 0.2 deg (600 rpm) */
#define LIDET_MAX_POINTS 30000   /* 16 x 1800 = 28800 returns + margin; more are counted, not read */
#define LIDET_MAX_CLUSTERS 64    /* proposals per scan (the detector classifies at most this many) */
#define LIDET_MAX_DETECTIONS 64  /* road users reported per scan (= clusters: never truncated) */
#define LIDET_REFINE_MAX_CELLS 2048  /* proposal refinement grid: 5.4 x 5.4 m at its 0.12 m cells */
#define LIDET_REFINE_MAX_POINTS 2048 /* pixels of one examined cluster (16 rings x 128 columns) */
/* the integer detector's pixel: the range only, x, y, z decoded from row, column and range where the stages read
 * them (exact for a VLP-16, whose returns lie on their ring's elevation): lidet_detector_q_t 255,728 B instead of
 * 457,328 B, within issue 17's 256 KiB of RAM (docs/MEMORY.md). The float detector is not affected. */
#define LIDET_Q_PIXEL_XYZ 0

#endif /* LIDET_USER_CONFIG_H */
