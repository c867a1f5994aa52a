/* SPDX-License-Identifier: MIT */
/**
 * @file fw_packets.h
 * @brief The lidar payloads stored in flash for the packet application (fw_packets.c): generated at build time by
 *        tools/firmware/packets_to_c.py from a KITTI .bin and its ring file (one rotation and a bit); never
 *        committed. VLP-16 payloads (default), or with FW_OUSTER=1 (LIDET_FW_LIDAR=ouster) Ouster lidar payloads
 *        and the sensor metadata the decoder is configured with.
 */
#ifndef LIDET_FW_PACKETS_H
#define LIDET_FW_PACKETS_H

#include <stdint.h>

#ifndef FW_OUSTER
#define FW_OUSTER 0
#endif
#if FW_OUSTER
#include "lidet/lidet_ouster.h"
#else
#include "lidet/lidet_velodyne.h"
#endif

#ifdef __cplusplus
extern "C" {
#endif

extern const uint32_t fw_pkt_n;  /**< payloads */
extern const char fw_pkt_name[]; /**< the scan they were made from, for the report */
#if FW_OUSTER
/** @brief What the decoder needs of the sensor's metadata (lidet_ouster_cfg_t's fields of the same names). */
typedef struct
{
    uint32_t profile; /**< lidet_ouster_profile_t (udp_profile_lidar) */
    uint16_t pixels_per_column;
    uint16_t columns_per_frame;
    uint16_t columns_per_packet;
    uint32_t init_id;
    uint32_t prod_sn_lo;                               /**< prod_sn's low 32 bits */
    uint32_t prod_sn_hi;                               /**< its high 8 bits */
    int32_t beam_azimuth_mdeg[LIDET_OUSTER_MAX_BEAMS]; /**< pixels_per_column entries */
} fw_ouster_meta_t;

extern const fw_ouster_meta_t fw_pkt_ouster; /**< the sensor the payloads come from */
extern const uint32_t fw_pkt_bytes;          /**< bytes of each payload */
extern const uint32_t fw_pkt_first_mid;      /**< the first payload's first measurement id */
/** the lidar UDP payloads (port 7502), in arrival order, fw_pkt_bytes each */
extern const uint8_t fw_pkt_payload[];
#else
extern const uint32_t fw_pkt_start_cdeg; /**< the first block's azimuth, 0.01 deg clockwise */
/** the UDP payloads (port 2368), in arrival order */
extern const uint8_t fw_pkt_payload[][LIDET_VELODYNE_PAYLOAD_BYTES];
#endif

#ifdef __cplusplus
}
#endif

#endif /* LIDET_FW_PACKETS_H */
