/* SPDX-License-Identifier: MIT */
/**
 * @file lidet_velodyne.h
 * @brief Velodyne packet decoding: one UDP payload in, the detector's returns (lidet_return_t) out, with the
 *        scan completed where the rotation crosses a configurable azimuth (the seam).
 *
 * Sensors: VLP-16 (product byte 0x22), VLP-32C (0x28) and HDL-32E (0x21); return modes strongest (0x37), last
 * (0x38) and dual (0x39). A data payload is 1206 bytes: 12 blocks of 100 bytes (flag 0xFFEE, azimuth uint16 in
 * 0.01 deg, 32 x (distance uint16 in 2 mm, VLP-32C 4 mm; intensity uint8)), a uint32 timestamp (microseconds
 * past the hour, the first firing of the packet) and the two factory bytes (return mode, product). Little-endian.
 *
 * Algorithm (docs/DECODING.md), per packet, in integers only:
 *  1. Validate the whole payload first (length, every block's flag and azimuth, both factory bytes, the two
 *     blocks of a dual pair at one azimuth); a bad payload is rejected whole and counted by reason.
 *  2. Per block (a dual pair counts as one block), the rotation step to the next block's azimuth; the last block
 *     reuses the step before it. Each data point's azimuth is the block's plus step x its firing time / the
 *     block's duration (the manuals' timing: VLP-16 2.304 us per laser, 55.296 us per sequence, two sequences
 *     per block; VLP-32C lasers fired in pairs 2.304 us apart, one 55.296 us sequence per block; HDL-32E 1.152 us
 *     per laser, 46.08 us per block), plus the laser's fixed azimuth offset (VLP-32C: +-1.4 or +-4.2 deg).
 *  3. Each block's azimuth is checked against the previous block's (across packets too): a forward step of at
 *     most max_step_cdeg is the rotation, anything else (backwards, shuffled, lost packets) is an azimuth jump:
 *     the scan in progress is closed as aborted. A forward step across seam_cdeg closes it as a scan.
 *  4. Distances of 0 (no return) are skipped; in dual mode the return filter picks the last, the strongest, or
 *     both (the second block's return when it differs from the last one).
 * Ring numbers are those of the lidet sensor presets (lib/src/proj/lidet_sensor.c: "vlp16", "vlp32c"):
 * ring 0 = the lowest beam, upwards by elevation (HDL-32E likewise: -30.67 deg .. +10.67 deg; its tables are
 * the manual's, not yet checked on a real HDL-32E capture). Azimuths are BAM16 counterclockwise from +x (x
 * forward, y left, z up), i.e. the Velodyne azimuth (clockwise) negated. A scan boundary falls between blocks
 * (a column is a block: a block's returns all belong to one scan).
 *
 * Memory: lidet_velodyne_t is 92 B, lidet_velodyne_attr_t 8 B per return; ~0.5 KiB of const tables; no
 * allocation, no recursion. Time: O(384) per packet, two 32-bit divisions per data point. Outputs go into the
 * caller's arrays (at most LIDET_VELODYNE_MAX_RETURNS per packet).
 */
#ifndef LIDET_VELODYNE_H
#define LIDET_VELODYNE_H

#include <stdint.h>

#include "lidet_proj_q.h"
#include "lidet_types.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Bytes of a Velodyne data payload (UDP port 2368). */
#define LIDET_VELODYNE_PAYLOAD_BYTES 1206u
/** Most returns one payload can produce (12 blocks x 32 data points). */
#define LIDET_VELODYNE_MAX_RETURNS 384u

/** @brief Sensor model: the product byte (factory byte 2) of its packets; AUTO takes the first valid packet's. */
typedef enum
{
    LIDET_VELODYNE_AUTO = 0,
    LIDET_VELODYNE_HDL32E = 0x21,
    LIDET_VELODYNE_VLP16 = 0x22,
    LIDET_VELODYNE_VLP32C = 0x28
} lidet_velodyne_model_t;

/** @brief Which returns of a dual-return packet to emit (single-return packets emit their one return). */
typedef enum
{
    LIDET_VELODYNE_RETURN_BOTH = 0,      /**< the last return, and the other one where it differs */
    LIDET_VELODYNE_RETURN_STRONGEST = 1, /**< per laser, the return of higher intensity (tie: the last) */
    LIDET_VELODYNE_RETURN_LAST = 2       /**< the last return */
} lidet_velodyne_filter_t;

/** Bits of lidet_velodyne_attr_t.flags: what the sensor says the return is (both bits: one return is both). */
#define LIDET_VELODYNE_FLAG_LAST 1u
#define LIDET_VELODYNE_FLAG_STRONGEST 2u

/** @brief Why a payload was rejected (lidet_velodyne_result_t.reject; counted in lidet_velodyne_stats_t). */
typedef enum
{
    LIDET_VELODYNE_REJECT_NONE = 0,
    LIDET_VELODYNE_REJECT_NULL = 1,    /**< NULL payload */
    LIDET_VELODYNE_REJECT_SIZE = 2,    /**< length other than 1206 (position packets: 512) */
    LIDET_VELODYNE_REJECT_FLAG = 3,    /**< a block flag other than 0xFFEE */
    LIDET_VELODYNE_REJECT_PRODUCT = 4, /**< unknown product byte, or not the configured (or locked) model */
    LIDET_VELODYNE_REJECT_MODE = 5,    /**< unknown return-mode byte */
    LIDET_VELODYNE_REJECT_AZIMUTH = 6, /**< a block azimuth > 35999, or a dual pair at two azimuths */
    LIDET_VELODYNE_N_REJECT = 7
} lidet_velodyne_reject_t;

/** @brief How the scan in progress before a payload ended (lidet_velodyne_result_t.scan_event). */
typedef enum
{
    /** no boundary in this payload */
    LIDET_VELODYNE_SCAN_NONE = 0,
    /** crossed the seam, and the scan had started at the seam: one rotation */
    LIDET_VELODYNE_SCAN_COMPLETE = 1,
    /** crossed the seam, but the scan began mid-rotation (after init, reset or a jump): less than one rotation */
    LIDET_VELODYNE_SCAN_PARTIAL = 2,
    /** ended by an azimuth jump: its returns are not one rotation */
    LIDET_VELODYNE_SCAN_ABORTED = 3
} lidet_velodyne_scan_t;

/** @brief Configuration. Fill with lidet_velodyne_cfg_default(). */
typedef struct
{
    lidet_velodyne_model_t model;   /**< the sensor, or AUTO (default) */
    lidet_velodyne_filter_t filter; /**< dual-return packets: which returns (default BOTH) */
    /** a scan ends where the Velodyne azimuth crosses this, 0.01 deg clockwise from the sensor's front (+x);
     *  [0, 35999], default 0 */
    uint16_t seam_cdeg;
    /** largest forward step from one block to the next that is still the rotation, 0.01 deg; [1, 18000],
     *  default 1000 (one lost packet at 1200 rpm) */
    uint16_t max_step_cdeg;
    /** 1: decode every payload as `model` whatever its product byte (captures whose product byte is wrong:
     *  docs/DECODING.md); 0 (default): a payload of another product is rejected. Needs a model other than AUTO. */
    uint8_t force_model;
} lidet_velodyne_cfg_t;

/** @brief Counts since init (reset keeps them). */
typedef struct
{
    uint32_t n_packets; /**< payloads given (all, rejected ones included) */
    uint32_t n_decoded; /**< payloads decoded */
    /** payloads rejected, by lidet_velodyne_reject_t ([0] unused) */
    uint32_t n_rejected[LIDET_VELODYNE_N_REJECT];
    uint32_t n_returns;   /**< returns emitted */
    uint32_t n_truncated; /**< returns dropped for want of room (cap) */
    uint32_t n_jumps;     /**< azimuth jumps (steps backwards or above max_step_cdeg) */
    uint32_t n_scans;     /**< scans closed as COMPLETE */
    uint32_t n_partial;   /**< scans closed as PARTIAL */
    uint32_t n_aborted;   /**< scans closed as ABORTED */
    /** returns dropped as a fragment between two boundaries of one payload (never part of one rotation) */
    uint32_t n_fragment;
} lidet_velodyne_stats_t;

/** @brief Decoder state: caller-placed (static or stack), no heap. */
typedef struct
{
    uint32_t magic;
    lidet_velodyne_cfg_t cfg;
    uint8_t model;     /* the product byte decoded (0 until locked in AUTO) */
    uint8_t have_prev; /* prev_cdeg valid */
    uint8_t from_seam; /* the scan in progress began at a seam crossing */
    uint8_t pad;
    uint16_t prev_cdeg; /* the previous block's azimuth */
    lidet_velodyne_stats_t stats;
} lidet_velodyne_t;

/** @brief Per-return attributes, the optional companion of lidet_velodyne_packet's out (same indices). */
typedef struct
{
    uint32_t t_ns; /**< firing time after the payload's timestamp, ns (< 1.4 ms) */
    /** the Velodyne azimuth of the firing (interpolated, laser offset included), 0.01 deg clockwise from +x,
     *  [0, 35999] */
    uint16_t azimuth_cdeg;
    uint8_t intensity; /**< calibrated reflectivity */
    uint8_t flags;     /**< LIDET_VELODYNE_FLAG_* */
} lidet_velodyne_attr_t;

/** @brief What one payload gave. */
typedef struct
{
    uint32_t n_returns; /**< returns written to out (and attr) */
    /** with a scan event: out[0, scan_end) end the scan that was in progress, out[scan_end, n_returns) begin the
     *  next; without: n_returns */
    uint32_t scan_end;
    uint32_t time_us;    /**< the payload's timestamp, microseconds past the hour */
    uint8_t scan_event;  /**< lidet_velodyne_scan_t */
    uint8_t reject;      /**< lidet_velodyne_reject_t */
    uint8_t model;       /**< the product byte (0 when rejected before it was read) */
    uint8_t return_mode; /**< the return-mode byte (0x37, 0x38, 0x39; 0 when rejected before it was read) */
} lidet_velodyne_result_t;

/** @brief Defaults: AUTO model, both returns, seam 0, max step 1000 (10 deg). NULL: nothing. */
void lidet_velodyne_cfg_default(lidet_velodyne_cfg_t *cfg);

/**
 * @brief Validate the configuration and clear the state (counts included).
 * @return LIDET_OK; LIDET_ERR_ARG (NULL); LIDET_ERR_CONFIG (unknown model or filter, seam > 35999, max_step 0 or
 *         above 18000, force_model other than 0 or 1, or with AUTO).
 */
lidet_status_t lidet_velodyne_init(lidet_velodyne_t *st, const lidet_velodyne_cfg_t *cfg);

/**
 * @brief Forget the rotation (the next scan is PARTIAL) and an AUTO model's lock; the counts stay.
 * @return LIDET_OK; LIDET_ERR_ARG (NULL); LIDET_ERR_STATE (not initialised).
 */
lidet_status_t lidet_velodyne_reset(lidet_velodyne_t *st);

/**
 * @brief Decode one UDP payload.
 *
 * Returns come in firing order (block by block, a block's lasers in packet order). When the payload holds a scan
 * boundary (res->scan_event), out[0, res->scan_end) close the scan in progress and the rest begin the next; when
 * it holds two (e.g. a seam crossing, then a jump), the returns between them are dropped (n_fragment), so no
 * emitted scan mixes two rotations. A typical caller decodes into its scan buffer at the fill position and, on
 * an event, hands the first scan_end returns with the buffer to the detector (COMPLETE) or drops them (else).
 *
 * @param[in,out] st      the state (lidet_velodyne_init).
 * @param[in]     payload the UDP payload; may be NULL (rejected, counted).
 * @param[in]     len     its length in bytes.
 * @param[out]    out     cap returns: ring, azimuth (BAM16, counterclockwise from +x), range_mm (in the
 *                        sensor's 2 mm steps, VLP-32C 4 mm); NULL only when cap is 0.
 * @param[out]    attr    optional (NULL: not produced): cap entries, the same returns' time, Velodyne azimuth,
 *                        intensity and flags. Must not alias out.
 * @param[in]     cap     room in out (and attr); LIDET_VELODYNE_MAX_RETURNS always suffices.
 * @param[out]    res     what the payload gave (always filled, also when rejected).
 * @return LIDET_OK; LIDET_TRUNCATED (returns past cap dropped, n_truncated; the scan tracking is unaffected);
 *         LIDET_ERR_MODEL (payload rejected: res->reject says why, nothing emitted, the rotation state unchanged);
 *         LIDET_ERR_ARG (NULL st or res, or NULL out with cap > 0); LIDET_ERR_STATE (not initialised).
 */
lidet_status_t lidet_velodyne_packet(lidet_velodyne_t *st, const uint8_t *payload, uint32_t len,
                                     lidet_return_t *out, lidet_velodyne_attr_t *attr, uint32_t cap,
                                     lidet_velodyne_result_t *res);

/** @brief Counts since init (NULL for a NULL state). */
const lidet_velodyne_stats_t *lidet_velodyne_stats(const lidet_velodyne_t *st);

/**
 * @brief A laser's elevation: millidegrees, for a model and ring (ring order of this header).
 * @return LIDET_OK; LIDET_ERR_ARG (NULL out, unknown model, ring >= the model's lasers).
 */
lidet_status_t lidet_velodyne_ring_elev_mdeg(lidet_velodyne_model_t model, uint32_t ring, int32_t *out_mdeg);

/** @brief Lasers (rings) of a model: 16 or 32; 0 for an unknown model. */
uint32_t lidet_velodyne_n_rings(lidet_velodyne_model_t model);

#if !defined(LIDET_FIXED_POINT) || !LIDET_FIXED_POINT
/**
 * @brief Float build only: x, y, z (metres, x forward, y left, z up) of decoded returns, from each return's ring
 *        (the model's elevation table), azimuth and range: x = r cos(e) cos(a), y = r cos(e) sin(a), z = r sin(e).
 * @param[out] xyz n records of `stride` floats (>= 3), x y z first; must not alias returns.
 * @return LIDET_OK; LIDET_ERR_ARG (NULL with n > 0, stride < 3, unknown model, a ring out of range: its point
 *         is set to 0, 0, 0 and the others are still converted).
 */
lidet_status_t lidet_velodyne_xyz(lidet_velodyne_model_t model, const lidet_return_t *returns, uint32_t n,
                                  float *xyz, uint32_t stride);
#endif

#ifdef __cplusplus
}
#endif

#endif /* LIDET_VELODYNE_H */
