/* SPDX-License-Identifier: MIT */
/**
 * @file lidet_ouster.h
 * @brief Ouster packet decoding: one lidar UDP payload in, the detector's returns (lidet_return_t) out, with the
 *        scan completed where the frame id changes (or at a configurable column), in the Velodyne decoder's shape.
 *
 * Sensors: Ouster OS0 / OS1 / OS2, 16 to 128 beams (pixels per column), 512 / 1024 / 2048 columns per frame,
 * packet profiles (udp_profile_lidar) LEGACY, RNG19_RFL8_SIG16_NIR16 (single return), RNG19_RFL8_SIG16_NIR16_DUAL
 * and RNG15_RFL8_NIR8 (low data rate). Little-endian throughout. Byte layouts (docs/OUSTER.md; sources:
 * Ouster's OS1 manual, "Lidar Data Format" section, for LEGACY; the firmware user manual's "Lidar Data" page and
 * ouster-sdk's packet_format (ouster_client/src/parsing.cpp) for the others):
 *  - LEGACY: no packet header. columns_per_packet columns of timestamp u64 (ns), measurement id u16, frame id u16,
 *    encoder count u32, then pixels_per_column pixels of 12 bytes (range u32 & 0xFFFFF mm, reflectivity u16 at 4,
 *    signal u16 at 6, near-IR u16 at 8; flags: byte 3 >> 4), then a status u32 (0xFFFFFFFF valid, 0 invalid).
 *  - The other profiles: a 32-byte packet header (STANDARD, firmware 2.x: packet type u16 = 1, frame id u16 at 2,
 *    init id u24 at 4, serial number u40 at 7; FUSA: packet type u8 = 1, init id u24 at 1, frame id u32 at 4,
 *    serial number u40 at 11), columns of a 12-byte header (timestamp u64, measurement id u16, status u16 whose
 *    bit 0 is "valid") and pixels, then a 32-byte footer. Pixels: RNG19_RFL8_SIG16_NIR16 12 bytes (range u32 &
 *    0x7FFFF mm, flags byte 2 >> 3, reflectivity u8 at 4, signal u16 at 6, near-IR u16 at 8);
 *    RNG19_RFL8_SIG16_NIR16_DUAL 16 bytes (first return: range & 0x7FFFF, flags byte 2 >> 3, reflectivity byte 3;
 *    second return the same at 4..7; signal u16 at 8 and 10, near-IR u16 at 12); RNG15_RFL8_NIR8 4 bytes (range
 *    u16 & 0x7FFF in 8 mm, flags byte 1 >> 7, reflectivity byte 2, near-IR byte 3).
 *
 * Algorithm (docs/OUSTER.md), per packet, in integers only:
 *  1. Validate the whole payload first: its length for the profile, the packet header (packet type, optionally
 *     the sensor's init id and serial number), every valid column's measurement id (< columns per frame) and
 *     (LEGACY) encoder count, and the order of the valid columns (frame id, measurement id) after the last one
 *     decoded; a bad payload is rejected whole and counted by reason. Invalid columns (status) are skipped.
 *  2. Each valid column's step from the previous one (across packets): (frame ids apart) x columns per frame +
 *     (measurement ids apart). A step of at most max_step_cols is the rotation (lost columns are counted); a
 *     larger one (a frame id jump), or a new init id in the packet header (the sensor re-initialised), closes the
 *     scan in progress as aborted. A step across seam_col closes it as a
 *     scan: with seam_col 0 (default) exactly where the frame id changes, i.e. one scan per Ouster frame.
 *  3. Each pixel's azimuth (BAM16, counterclockwise from +x of the output frame): azimuth_offset_bam - the
 *     column's encoder angle (measurement id / columns per frame of a turn, ouster-sdk's angle) - the beam's
 *     azimuth offset (beam_azimuth_angles), as ouster-sdk's XYZ lookup table turns a pixel. The default offset
 *     (half a turn) is ouster-sdk's lidar_to_sensor_transform: x forward, away from the connector.
 *  4. Ranges of 0 (no return) are skipped; DUAL emits each pixel's first and/or second return (filter).
 * The ring is the pixel's row (the beam index of the metadata's beam tables: row 0 is the top beam). The beam
 * origin offset (lidar_origin_to_beam_origin_mm) and the lidar frame's height in the sensor frame are not part
 * of lidet_return_t: points computed from ring, azimuth and range are seen from the lidar origin
 * (tools/lidet_tools/ouster.py computes ouster-sdk's x, y, z).
 *
 * Memory: lidet_ouster_t is 408 B on x86-64, 392 B on a Cortex-M0+ (256 of them the beam offset table),
 * lidet_ouster_attr_t 12 B per return; no const tables, no allocation, no recursion; 2.2 KiB of Cortex-M0+ code
 * (-Os). Time: O(columns_per_packet x pixels_per_column) per packet, one 32-bit division per column. Outputs go
 * into the caller's arrays (at most lidet_ouster_max_returns() per packet).
 */
#ifndef LIDET_OUSTER_H
#define LIDET_OUSTER_H

#include <stdint.h>

#include "lidet_proj_q.h"
#include "lidet_types.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Most beams (pixels per column) a configuration may have. */
#define LIDET_OUSTER_MAX_BEAMS 128u
/** Most columns per packet a configuration may have (Ouster sensors send 16). */
#define LIDET_OUSTER_MAX_COLS_PER_PACKET 16u
/** Most returns one payload can produce under any configuration (16 columns x 128 beams x 2 returns). */
#define LIDET_OUSTER_MAX_RETURNS (LIDET_OUSTER_MAX_COLS_PER_PACKET * LIDET_OUSTER_MAX_BEAMS * 2u)
/** Encoder counts per turn of a LEGACY column header (counts are in [0, 90112)). */
#define LIDET_OUSTER_ENCODER_TICKS 90112u

/** @brief The lidar packet profile (udp_profile_lidar); the numbers are ouster-sdk's UDPProfileLidar values. */
typedef enum
{
    /** 12-byte pixels, a frame id in each column, no packet header */
    LIDET_OUSTER_LEGACY = 1,
    /** 16-byte pixels, two returns */
    LIDET_OUSTER_RNG19_RFL8_SIG16_NIR16_DUAL = 2,
    /** 12-byte pixels, single return (the sensors' default) */
    LIDET_OUSTER_RNG19_RFL8_SIG16_NIR16 = 3,
    /** 4-byte pixels, range in 8 mm */
    LIDET_OUSTER_RNG15_RFL8_NIR8 = 4
} lidet_ouster_profile_t;

/** @brief The 32-byte packet header of the non-LEGACY profiles (the metadata's header_type). */
typedef enum
{
    /** packet type u16, frame id u16 (firmware 2.x: the captures tested) */
    LIDET_OUSTER_HEADER_STANDARD = 0,
    /** packet type u8, frame id u32 (header_type "FUSA") */
    LIDET_OUSTER_HEADER_FUSA = 1
} lidet_ouster_header_t;

/** @brief Which returns of a DUAL packet to emit (the other profiles have one). */
typedef enum
{
    /** each non-zero return of the pixel, the first one first */
    LIDET_OUSTER_RETURN_BOTH = 0,
    /** the packet's first return (the strongest in the sensors' default return order) */
    LIDET_OUSTER_RETURN_FIRST = 1,
    /** the packet's second return */
    LIDET_OUSTER_RETURN_SECOND = 2
} lidet_ouster_filter_t;

/** @brief Why a payload was rejected (lidet_ouster_result_t.reject; counted in lidet_ouster_stats_t). */
typedef enum
{
    LIDET_OUSTER_REJECT_NONE = 0,
    LIDET_OUSTER_REJECT_NULL = 1, /**< NULL payload */
    /** shorter than the profile's packet (lidet_ouster_packet_bytes): a cut datagram, a smaller profile or beam
     *  count, an IMU packet (48 bytes) */
    LIDET_OUSTER_REJECT_TRUNCATED = 2,
    LIDET_OUSTER_REJECT_SIZE = 3, /**< longer than the profile's packet: a larger profile or beam count */
    /** packet type other than 1, another sensor's init id or serial number (when configured), a valid column's
     *  measurement id >= columns_per_frame, a LEGACY encoder count >= 90112 */
    LIDET_OUSTER_REJECT_HEADER = 4,
    LIDET_OUSTER_REJECT_STATUS = 5, /**< no valid column (column status) */
    /** a valid column not after the one before it (within the payload, or the last one decoded): the same frame
     *  at a measurement id not above it, or the frame before: a repeated or late packet */
    LIDET_OUSTER_REJECT_ORDER = 6,
    LIDET_OUSTER_N_REJECT = 7
} lidet_ouster_reject_t;

/** @brief How the scan in progress before a payload ended (lidet_ouster_result_t.scan_event). */
typedef enum
{
    /** no boundary in this payload */
    LIDET_OUSTER_SCAN_NONE = 0,
    /** crossed the seam (default: the frame id changed), and the scan had begun at the seam: one frame */
    LIDET_OUSTER_SCAN_COMPLETE = 1,
    /** crossed the seam, but the scan began mid-rotation (after init, reset or a jump, at a column other than
     *  seam_col): less than one frame */
    LIDET_OUSTER_SCAN_PARTIAL = 2,
    /** ended by a jump (frame id or measurement id ahead by more than max_step_cols columns, or a new init id) */
    LIDET_OUSTER_SCAN_ABORTED = 3
} lidet_ouster_scan_t;

/** @brief Configuration: the sensor's metadata (lidar_data_format / beam_intrinsics), converted by the caller.
 *  Fill with lidet_ouster_cfg_default(), then set at least pixels_per_column and columns_per_frame. */
typedef struct
{
    lidet_ouster_profile_t profile; /**< udp_profile_lidar (default RNG19_RFL8_SIG16_NIR16) */
    lidet_ouster_header_t header;   /**< header_type of the non-LEGACY profiles (default STANDARD) */
    lidet_ouster_filter_t filter;   /**< DUAL: which returns (default BOTH) */
    uint16_t pixels_per_column;     /**< beams, [1, 128] (no default: 0 is refused) */
    uint16_t columns_per_frame;     /**< [16, 16384], e.g. 512, 1024, 2048 (no default: 0 is refused) */
    uint16_t columns_per_packet;    /**< [1, 16], default 16 */
    /** a scan begins at this measurement id: [0, columns_per_frame), default 0 (Ouster's frames) */
    uint16_t seam_col;
    /** largest step from one valid column to the next that is still the rotation, columns;
     *  [1, columns_per_frame], 0 (default) = columns_per_frame (one turn: any loss short of a whole frame) */
    uint16_t max_step_cols;
    /** added to every azimuth, BAM16: the turn from Ouster's lidar frame (x towards the connector) to the output
     *  frame. Default 32768 (half a turn: ouster-sdk's default lidar_to_sensor_transform, x forward) */
    uint16_t azimuth_offset_bam;
    /** beam_azimuth_angles in millidegrees, pixels_per_column entries in (-180000, 180000), read by init only;
     *  NULL: all 0 */
    const int32_t *beam_azimuth_mdeg;
    /** non-LEGACY: the sensor's init id (24 bits, the metadata's initialization_id); 0 (default): any */
    uint32_t init_id;
    /** non-LEGACY: the sensor's serial number (40 bits, prod_sn); 0 (default): any */
    uint64_t prod_sn;
} lidet_ouster_cfg_t;

/** @brief Counts since init (reset keeps them). */
typedef struct
{
    uint32_t n_packets; /**< payloads given (all, rejected ones included) */
    uint32_t n_decoded; /**< payloads decoded */
    /** payloads rejected, by lidet_ouster_reject_t ([0] unused) */
    uint32_t n_rejected[LIDET_OUSTER_N_REJECT];
    uint32_t n_returns;      /**< returns emitted */
    uint32_t n_truncated;    /**< returns dropped for want of room (cap) */
    uint32_t n_invalid_cols; /**< columns of decoded payloads skipped for their status */
    /** columns missing inside the rotation (steps above one column but within max_step_cols: lost packets, or
     *  columns outside the sensor's column window) */
    uint32_t n_lost_cols;
    /** steps above max_step_cols (frame id jumps), and (non-LEGACY) a new init id: the sensor re-initialised */
    uint32_t n_jumps;
    uint32_t n_scans;   /**< scans closed as COMPLETE */
    uint32_t n_partial; /**< scans closed as PARTIAL */
    uint32_t n_aborted; /**< scans closed as ABORTED */
    /** returns dropped as a fragment between two boundaries of one payload (never part of one rotation) */
    uint32_t n_fragment;
} lidet_ouster_stats_t;

/** @brief Decoder state: caller-placed (static or stack), no heap. */
typedef struct
{
    uint32_t magic;
    lidet_ouster_cfg_t cfg; /* as given (beam_azimuth_mdeg is not read after init) */
    uint32_t packet_bytes;  /* the profile's payload length */
    uint32_t prev_frame;    /* the previous valid column's frame id */
    uint32_t prev_init_id;  /* the init id of the previous decoded payload (non-LEGACY) */
    uint16_t col_bytes;     /* one column: header, pixels, (LEGACY) status */
    uint16_t prev_mid;      /* the previous valid column's measurement id */
    uint8_t pixel_bytes;
    uint8_t have_prev; /* prev_* valid */
    uint8_t from_seam; /* the scan in progress began at the seam */
    uint8_t pad;
    uint16_t beam_az_bam[LIDET_OUSTER_MAX_BEAMS]; /* beam azimuth offsets, BAM16 (mod 2^16) */
    lidet_ouster_stats_t stats;
} lidet_ouster_t;

/** @brief Per-return attributes, the optional companion of lidet_ouster_packet's out (same indices). */
typedef struct
{
    uint32_t t_ns;           /**< the column's timestamp minus the payload's (res.time_ns), ns, mod 2^32 */
    uint16_t measurement_id; /**< the column's measurement id, [0, columns_per_frame) */
    uint16_t signal;         /**< signal photons (RNG15_RFL8_NIR8: 0) */
    uint16_t reflectivity;   /**< calibrated reflectivity (LEGACY: 16 bits; the others: 8) */
    uint8_t return_index;    /**< 0: the pixel's first return, 1: its second (DUAL) */
    uint8_t flags;           /**< the pixel's flags field (profile-specific bits, 0 where it has none) */
} lidet_ouster_attr_t;

/** @brief What one payload gave. */
typedef struct
{
    uint32_t n_returns; /**< returns written to out (and attr) */
    /** with a scan event: out[0, scan_end) end the scan that was in progress, out[scan_end, n_returns) begin the
     *  next; without: n_returns */
    uint32_t scan_end;
    uint64_t time_ns;      /**< the first valid column's timestamp, ns (0 when rejected before it was read) */
    uint32_t frame_id;     /**< the packet's frame id (LEGACY: its first valid column's) */
    uint16_t n_valid_cols; /**< columns decoded (status valid) */
    uint8_t scan_event;    /**< lidet_ouster_scan_t */
    uint8_t reject;        /**< lidet_ouster_reject_t */
} lidet_ouster_result_t;

/** @brief Defaults: RNG19_RFL8_SIG16_NIR16, STANDARD header, both returns, 16 columns per packet, seam 0, max step
 *  one frame, azimuth offset half a turn, no beam offsets, any sensor; pixels_per_column and columns_per_frame 0
 *  (to be set). NULL: nothing. */
void lidet_ouster_cfg_default(lidet_ouster_cfg_t *cfg);

/**
 * @brief Validate the configuration, convert the beam offsets and clear the state (counts included).
 * @return LIDET_OK; LIDET_ERR_ARG (NULL); LIDET_ERR_CONFIG (unknown profile, header or filter, pixels_per_column
 *         outside [1, 128], columns_per_frame outside [16, 16384], columns_per_packet outside [1, 16], a packet
 *         above 65535 bytes, seam_col >= columns_per_frame, max_step_cols > columns_per_frame, a beam offset
 *         outside (-180000, 180000) mdeg, init_id above 24 bits, prod_sn above 40 bits).
 */
lidet_status_t lidet_ouster_init(lidet_ouster_t *st, const lidet_ouster_cfg_t *cfg);

/**
 * @brief Forget the rotation (the next scan is PARTIAL unless it begins at seam_col); the counts stay.
 * @return LIDET_OK; LIDET_ERR_ARG (NULL); LIDET_ERR_STATE (not initialised).
 */
lidet_status_t lidet_ouster_reset(lidet_ouster_t *st);

/**
 * @brief Decode one lidar UDP payload (port 7502 by default).
 *
 * Returns come column by column (packet order), a column's pixels by row, a DUAL pixel's first return before its
 * second. When the payload holds a scan boundary (res->scan_event), out[0, res->scan_end) close the scan in
 * progress and the rest begin the next; when it holds two, the returns between them are dropped (n_fragment).
 * A typical caller decodes into its scan buffer at the fill position and, on an event, hands the first scan_end
 * returns with the buffer to the detector (COMPLETE) or drops them (else): lidet_velodyne_packet's contract.
 *
 * @param[in,out] st      the state (lidet_ouster_init).
 * @param[in]     payload the UDP payload; may be NULL (rejected, counted).
 * @param[in]     len     its length in bytes.
 * @param[out]    out     cap returns: ring (the beam's row), azimuth (BAM16, counterclockwise from +x),
 *                        range_mm (RNG15_RFL8_NIR8: in 8 mm steps); NULL only when cap is 0.
 * @param[out]    attr    optional (NULL: not produced): cap entries, the same returns' time, measurement id,
 *                        signal, reflectivity, return index and flags. Must not alias out.
 * @param[in]     cap     room in out (and attr); lidet_ouster_max_returns() always suffices.
 * @param[out]    res     what the payload gave (always filled, also when rejected).
 * @return LIDET_OK; LIDET_TRUNCATED (returns past cap dropped, n_truncated; the scan tracking is unaffected);
 *         LIDET_ERR_MODEL (payload rejected: res->reject says why, nothing emitted, the rotation state unchanged);
 *         LIDET_ERR_ARG (NULL st or res, or NULL out with cap > 0); LIDET_ERR_STATE (not initialised).
 */
lidet_status_t lidet_ouster_packet(lidet_ouster_t *st, const uint8_t *payload, uint32_t len,
                                   lidet_return_t *out, lidet_ouster_attr_t *attr, uint32_t cap,
                                   lidet_ouster_result_t *res);

/** @brief Counts since init (NULL for a NULL state). */
const lidet_ouster_stats_t *lidet_ouster_stats(const lidet_ouster_t *st);

/** @brief Bytes of a lidar payload of the initialised configuration (0 for NULL or an uninitialised state). */
uint32_t lidet_ouster_packet_bytes(const lidet_ouster_t *st);

/** @brief Most returns one payload can give under the initialised configuration (columns x beams, x 2 for DUAL
 *  with filter BOTH); 0 for NULL or an uninitialised state. */
uint32_t lidet_ouster_max_returns(const lidet_ouster_t *st);

#ifdef __cplusplus
}
#endif

#endif /* LIDET_OUSTER_H */
