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
 * them (exact for a VLP-16, whose returns lie on their ring's elevation): lidet_detector_q_t 255,904 B on
 * arm-none-eabi instead of ~447 KiB (247,744 B with the int8 scratch below), within issue 17's 256 KiB of RAM
 * (docs/MEMORY.md). The float detector is not affected. */
#define LIDET_Q_PIXEL_XYZ 0
/* the integer detector's int8 PointNet scratch: what the integer images' small pair needs (vlp16s_s8:
 * LIDET_POINTNET_Q_SCRATCH_BYTES(64, 80) = 4,128 B at LIDET_PN_BLOCK 8; CLS_/BOX_VLP16S_S8_SCRATCH_BYTES) instead of
 * the library's 12,288 B, sized for the full int8 models. The scratch's size changes no result (the networks use
 * what their widths need; lidet_detector_q_init fails with LIDET_ERR_BUFFER when it is too small), and the 8,160 B
 * it frees hold the tracker (docs/TRACKING.md, "On the board"). An integer image with the full int8 models
 * (-DLIDET_FW_MODELS=vlp16) needs the library's size back: -DLIDET_DETECTOR_Q_PN_SCRATCH=12288. The float detector
 * (LIDET_DETECTOR_PN_SCRATCH) is not affected. */
#ifndef LIDET_DETECTOR_Q_PN_SCRATCH
#define LIDET_DETECTOR_Q_PN_SCRATCH 4128
#endif
/* the tracker after the detector (docs/TRACKING.md, "On the board"): 32 tracks; 32 detections per update, above
 * what the detector gives for this sensor (at most max_boxes = 24 boxes per scan by default for <= 16 beams; with
 * more, the tracker takes the 32 best and counts the rest) and the 32 road users of the images' tracker benchmark
 * (fw_detect.c). lidet_tracker_q_t 8,272 B, lidet_tracker_t 7,844 B. */
#define LIDET_TRACK_MAX_TRACKS 32
#define LIDET_TRACK_MAX_DETS 32

#endif /* LIDET_USER_CONFIG_H */
