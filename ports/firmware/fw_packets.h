/* SPDX-License-Identifier: MIT */
/**
 * @file fw_packets.h
 * @brief The VLP-16 payloads stored in flash for the packet application (fw_packets.c): generated at build time by
 *        tools/firmware/packets_to_c.py from a KITTI .bin and its ring file (one rotation and a bit, begun half a
 *        packet before the seam); never committed.
 */
#ifndef LIDET_FW_PACKETS_H
#define LIDET_FW_PACKETS_H

#include <stdint.h>

#include "lidet/lidet_velodyne.h"

#ifdef __cplusplus
extern "C" {
#endif

extern const uint32_t fw_pkt_n;          /**< payloads */
extern const uint32_t fw_pkt_start_cdeg; /**< the first block's azimuth, 0.01 deg clockwise */
extern const char fw_pkt_name[];         /**< the scan they were made from, for the report */
/** the UDP payloads (port 2368), in arrival order */
extern const uint8_t fw_pkt_payload[][LIDET_VELODYNE_PAYLOAD_BYTES];

#ifdef __cplusplus
}
#endif

#endif /* LIDET_FW_PACKETS_H */
