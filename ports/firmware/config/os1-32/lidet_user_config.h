/* SPDX-License-Identifier: MIT */
/**
 * @file lidet_user_config.h
 * @brief Capacities of the Ouster packet image (ports/firmware, LIDET_FW_SENSOR=os1-32, LIDET_FW_LIDAR=ouster):
 *        one Ouster OS1-32 frame in its default lidar mode (32 beams, 1024 columns, 10 Hz), single-return
 *        profile: at most 32 x 1024 = 32,768 returns a frame.
 *
 * Read by lidet_opt.h when LIDET_USER_CONFIG is defined; the image and its host reference (fw_host_ref_pkt_ouster,
 * tests/firmware.cmake) are built with this same file. config/vlp16's capacities, scaled to the 32 x 1024 image
 * (docs/FIRMWARE.md, "The Ouster packet image"; docs/MEMORY.md).
 */
#ifndef LIDET_USER_CONFIG_H
#define LIDET_USER_CONFIG_H

#define LIDET_MAX_ROWS 32       /* OS1-32: 32 beams */
#define LIDET_MAX_COLS 1024     /* lidar mode 1024x10 (512x20 fits too) */
#define LIDET_MAX_POINTS 32768  /* a frame: one return per pixel (single-return profile) */
#define LIDET_MAX_CLUSTERS 64   /* proposals per scan, as config/vlp16 (simulated OS1-32 scans: 20-60) */
#define LIDET_MAX_DETECTIONS 64 /* road users reported per scan (= clusters: never truncated) */
#define LIDET_REFINE_MAX_CELLS 2048  /* proposal refinement grid: 5.4 x 5.4 m at its 0.12 m cells */
#define LIDET_REFINE_MAX_POINTS 4096 /* pixels of one examined cluster (32 rings x 128 columns) */
/* the integer detector's pixel: the range only, x, y, z decoded from row, column and range where the stages read
 * them (config/vlp16; exact for the simulated OS1-32, whose returns lie on their beam's elevation and their
 * column's centre) */
#define LIDET_Q_PIXEL_XYZ 0
/* the int8 PointNet scratch the beams32 pair needs (box_beams32_s8: LIDET_POINTNET_Q_SCRATCH_BYTES(160, 192) =
 * 9,968 B at LIDET_PN_BLOCK 8, above cls_beams32_s8's 8,208 B; BOX_BEAMS32_S8_SCRATCH_BYTES) instead of the
 * library's 12,288 B; lidet_detector_q_init fails with LIDET_ERR_BUFFER when it is too small */
#ifndef LIDET_DETECTOR_Q_PN_SCRATCH
#define LIDET_DETECTOR_Q_PN_SCRATCH 9968
#endif

#endif /* LIDET_USER_CONFIG_H */
