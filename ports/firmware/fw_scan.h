/* SPDX-License-Identifier: MIT */
/**
 * @file fw_scan.h
 * @brief The scan stored in flash: generated at build time by tools/firmware/scan_to_c.py from a KITTI
 *        .bin (float32 x y z intensity) and its ring file (uint16 per point); never committed. The integer
 *        build has it twice: as points in mm and as the sensor's returns.
 */
#ifndef LIDET_FW_SCAN_H
#define LIDET_FW_SCAN_H

#include <stdint.h>

#include "lidet/lidet.h"

#ifdef __cplusplus
extern "C" {
#endif

extern const uint32_t fw_scan_n;        /**< points */
extern const float fw_scan_xyz[];       /**< fw_scan_n records of x, y, z (metres, stride 3); float build */
extern const int32_t fw_scan_xyz_mm[];  /**< the same in millimetres (scan_to_c.py --mm); integer build */
extern const uint16_t fw_scan_ring[];   /**< ring index per point (sensor's ring order), if fw_scan_has_ring */
extern const int fw_scan_has_ring;      /**< 1: fw_scan_ring is given; 0: rows from the elevation */
extern const char fw_scan_name[];       /**< source file, for the report */
#if LIDET_FIXED_POINT
/** the same scan as the sensor's returns (range, azimuth, ring; scan_to_c.py --mm with a ring file), if
 *  fw_scan_has_returns; integer build */
extern const lidet_return_t fw_scan_returns[];
extern const int fw_scan_has_returns;
#endif

#ifdef __cplusplus
}
#endif

#endif /* LIDET_FW_SCAN_H */
