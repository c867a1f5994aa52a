/* SPDX-License-Identifier: MIT */
/**
 * @file lidet_velodyne.h
 * @brief Velodyne packet decoding: one UDP payload in, the detector's returns (lidet_return_t) out, with the
 *        scan completed where the rotation crosses a configurable azimuth (the seam).
 *
 * Sensors: VLP-16 (product byte 0x22), VLP-32C (0x28) and HDL-32E (0x21), return modes strongest (0x37), last
 * (0x38) and dual (0x39); HDL-64E S2 / S3 in single- and dual-return mode (no product or return-mode byte:
 * recognised by its lower-bank flag 0xDDFF, the dual layout by four blocks a firing). A data payload is 1206
 * bytes: 12 blocks of 100 bytes (flag, azimuth uint16 in 0.01 deg, 32 x (distance uint16 in 2 mm, VLP-32C 4 mm;
 * intensity uint8)), a uint32 timestamp (microseconds past the hour) and two bytes: VLP / HDL-32E the factory
 * bytes (return mode, product), HDL-64E a rotating status (type, value).
 * Little-endian. Block flags: bytes FF EE (0xEEFF read as a uint16); HDL-64E upper bank FF EE (lasers 0..31) and
 * lower bank FF DD (0xDDFF, lasers 32..63) alternating, the two blocks of a firing at one azimuth; HDL-64E dual
 * return: four blocks a firing at one azimuth (upper, lower: the strongest return; upper, lower: the last), three
 * firings a payload.
 *
 * Algorithm (docs/DECODING.md), per packet, in integers only:
 *  1. Validate the whole payload first (length, every block's flag and azimuth, the factory bytes, the blocks of
 *     one firing at one azimuth); a bad payload is rejected whole and counted by reason.
 *  2. Per firing (a block; a dual pair; an HDL-64E upper + lower pair, dual: two such pairs), the rotation step
 *     to the next firing's azimuth; the last reuses the step before it. Each data point's azimuth is the firing's
 *     plus step x its firing time / the firing's duration (the manuals' timing: VLP-16 2.304 us per laser,
 *     55.296 us per sequence, two sequences per block; VLP-32C lasers fired in pairs 2.304 us apart, one
 *     55.296 us sequence per block; HDL-32E 1.152 us per laser, 46.08 us per block; HDL-64E lasers j of both banks
 *     together, in groups of four 6 us apart at 0, 1.26, 2.46, 3.66 us, 48 us per firing; dual return: the same
 *     table stretched to a 57.6 us firing, the same interpolation), minus the laser's rotational correction
 *     (nominal: VLP-32C -+1.4 or -+4.2 deg, the others 0; or the caller's calibration).
 *  3. Each firing's azimuth is checked against the previous firing's (across packets too): a forward step of at
 *     most max_step_cdeg is the rotation, anything else (backwards, shuffled, lost packets) is an azimuth jump:
 *     the scan in progress is closed as aborted. A forward step across seam_cdeg closes it as a scan.
 *  4. Distances of 0 (no return) are skipped; the laser's distance correction (calibration) is added; in dual
 *     mode the return filter picks the last, the strongest, or both (the other block's return when it differs;
 *     the last return: a VLP / HDL-32E pair's first block, an HDL-64E firing's second upper + lower pair).
 * Rings: ring 0 = the lowest beam, upwards by elevation (the "vlp16", "vlp32c", "hdl32" presets' order; HDL-64E by
 * its nominal table, or by the calibration's elevations); cfg.ring_top_first numbers them downwards instead (the
 * "hdl64" preset's order, KITTI's). Azimuths are BAM16 counterclockwise from +x (x forward, y left, z up), i.e.
 * the Velodyne azimuth (clockwise) negated. A scan boundary falls between firings (a firing's returns all belong
 * to one scan).
 *
 * Memory: lidet_velodyne_t is 688 B on x86-64, 672 B on 32-bit targets (the per-laser tables of up to 64 lasers:
 * ring, rotational and distance correction, elevation by ring), lidet_velodyne_attr_t 8 B per return; ~1.1 KiB
 * of const tables; no allocation, no recursion. Time: O(384) per packet, a few multiplications and divisions by
 * constants per data point; a VLP-16 single-return block without attributes or calibration takes a fast path with
 * two divisions a block and none per point (the same returns; about 40 instructions per return on a Cortex-M4,
 * docs/DECODING.md). Outputs go into the caller's arrays (at most LIDET_VELODYNE_MAX_RETURNS per packet).
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
/** Most lasers of a model (HDL-64E): the size of a calibration table. */
#define LIDET_VELODYNE_MAX_LASERS 64u

/** @brief Sensor model: the product byte (factory byte 2) of its packets; AUTO takes the first valid packet's.
 *  The HDL-64E sends no product byte: its value is lidet's own (no Velodyne product uses it), and AUTO recognises
 *  it by its lower-bank block flag (0xDDFF). */
typedef enum
{
    LIDET_VELODYNE_AUTO = 0,
    LIDET_VELODYNE_HDL32E = 0x21,
    LIDET_VELODYNE_VLP16 = 0x22,
    LIDET_VELODYNE_VLP32C = 0x28,
    /** HDL-64E S2, S2.1, S3 (single and dual return) */
    LIDET_VELODYNE_HDL64E = 0x64
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
    LIDET_VELODYNE_REJECT_NULL = 1, /**< NULL payload */
    LIDET_VELODYNE_REJECT_SIZE = 2, /**< length other than 1206 (position packets: 512) */
    /** a block flag other than 0xEEFF (HDL-64E: other than 0xEEFF, 0xDDFF alternating) */
    LIDET_VELODYNE_REJECT_FLAG = 3,
    /** unknown product byte, or not the configured (or locked) model (a VLP / HDL-32E payload to an HDL-64E
     *  decoder) */
    LIDET_VELODYNE_REJECT_PRODUCT = 4,
    LIDET_VELODYNE_REJECT_MODE = 5, /**< unknown return-mode byte */
    /** a block azimuth > 35999, or the blocks of one firing at two azimuths */
    LIDET_VELODYNE_REJECT_AZIMUTH = 6,
    /** a layout this decoder does not decode; none at present (HDL-64E dual-return payloads, once counted here,
     *  are decoded): kept so that the counts keep their places */
    LIDET_VELODYNE_REJECT_UNSUPPORTED = 7,
    LIDET_VELODYNE_N_REJECT = 8
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

/** @brief One laser's calibration (a db.xml point, a velodyne_pointcloud YAML laser), in integer units. */
typedef struct
{
    /** elevation (vertCorrection_ / vert_correction), millidegrees, (-90 000, 90 000) */
    int32_t vert_mdeg;
    /** rotational correction (rotCorrection_ / rot_correction), 0.01 deg, [-18 000, 18 000], Velodyne's sign:
     *  the laser's azimuth (clockwise) is the firing's rotational position minus it */
    int16_t rot_cdeg;
    /** distance correction (distCorrection_ / dist_correction), mm, added to every range of the laser */
    int16_t dist_mm;
} lidet_velodyne_laser_calib_t;

/** @brief A unit's calibration, filled by the caller (lib/ parses no files; the host tools read db.xml and
 *  YAML: docs/VELODYNE_CALIBRATION.md). Only the elevations, rotational and distance corrections are used (no
 *  offsets, focal or two-point corrections). */
typedef struct
{
    /** the model's lasers: 16 (VLP-16), 32 (VLP-32C, HDL-32E), 64 (HDL-64E) */
    uint32_t n_lasers;
    /** by laser id (db.xml's id_, YAML's laser_id): the data point's place in its block (VLP-16: 0..15, a block's
     *  points j and j + 16 are laser j); HDL-64E: upper-bank point j is laser j, lower-bank point j laser 32 + j */
    lidet_velodyne_laser_calib_t laser[LIDET_VELODYNE_MAX_LASERS];
} lidet_velodyne_calib_t;

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
    /** 0 (default): ring 0 = the lowest beam, upwards by elevation; 1: ring 0 = the highest, downwards (the
     *  "hdl64" preset's ring order, KITTI's: set it when the returns feed that preset) */
    uint8_t ring_top_first;
    /** NULL (default): the model's nominal tables (elevations, VLP-32C azimuth offsets, no distance correction);
     *  else the unit's calibration, n_lasers = the model's lasers (needs a model other than AUTO): rings ordered by
     *  its elevations (ties: the lower laser id first), rotational and distance corrections applied. Read by init
     *  only (copied): it need not outlive init. */
    const lidet_velodyne_calib_t *calib;
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
    /** returns dropped because the calibration's distance correction left no positive range */
    uint32_t n_short_range;
} lidet_velodyne_stats_t;

/** @brief Decoder state: caller-placed (static or stack), no heap. */
typedef struct
{
    uint32_t magic;
    lidet_velodyne_cfg_t cfg; /* as given (calib is not read after init: NULL here) */
    uint8_t model;            /* the model decoded (0 until locked in AUTO) */
    uint8_t have_prev;        /* prev_cdeg valid */
    uint8_t from_seam;        /* the scan in progress began at a seam crossing */
    uint8_t n_lasers;         /* lasers of the tables below (0: not built yet, AUTO before its lock) */
    uint16_t prev_cdeg;       /* the previous firing's azimuth */
    uint8_t calibrated;       /* the tables are the caller's calibration */
    uint8_t pad;
    lidet_velodyne_stats_t stats;
    uint8_t ring[LIDET_VELODYNE_MAX_LASERS];           /* laser id -> emitted ring */
    int16_t rot_cdeg[LIDET_VELODYNE_MAX_LASERS];       /* laser id -> rotational correction (subtracted) */
    int16_t dist_mm[LIDET_VELODYNE_MAX_LASERS];        /* laser id -> distance correction (added) */
    int32_t ring_elev_mdeg[LIDET_VELODYNE_MAX_LASERS]; /* emitted ring -> elevation */
} lidet_velodyne_t;

/** @brief Per-return attributes, the optional companion of lidet_velodyne_packet's out (same indices). */
typedef struct
{
    /** firing time after the payload's first firing, ns (< 1.4 ms): VLP / HDL-32E the payload's timestamp;
     *  HDL-64E stamps the end of the packet (docs/DECODING.md) */
    uint32_t t_ns;
    /** the Velodyne azimuth of the firing (interpolated, the laser's rotational correction applied), 0.01 deg
     *  clockwise from +x, [0, 35999] */
    uint16_t azimuth_cdeg;
    uint8_t intensity; /**< calibrated reflectivity */
    /** LIDET_VELODYNE_FLAG_* (HDL-64E single return: 0, its payload does not say which return it is; dual
     *  return: as the other models') */
    uint8_t flags;
} lidet_velodyne_attr_t;

/** @brief What one payload gave. */
typedef struct
{
    uint32_t n_returns; /**< returns written to out (and attr) */
    /** with a scan event: out[0, scan_end) end the scan that was in progress, out[scan_end, n_returns) begin the
     *  next; without: n_returns */
    uint32_t scan_end;
    uint32_t time_us;   /**< the payload's timestamp, microseconds past the hour */
    uint8_t scan_event; /**< lidet_velodyne_scan_t */
    uint8_t reject;     /**< lidet_velodyne_reject_t */
    /** the product byte (0 when rejected before it was read); LIDET_VELODYNE_HDL64E for an HDL-64E payload (one
     *  with lower-bank flags) */
    uint8_t model;
    /** the return-mode byte (0x37, 0x38, 0x39; 0 when rejected before it was read); HDL-64E, whose payload has
     *  none: 0x39 for a decoded dual-return layout, else 0 */
    uint8_t return_mode;
} lidet_velodyne_result_t;

/** @brief Defaults: AUTO model, both returns, seam 0, max step 1000 (10 deg). NULL: nothing. */
void lidet_velodyne_cfg_default(lidet_velodyne_cfg_t *cfg);

/**
 * @brief Validate the configuration and clear the state (counts included); a calibration is copied here.
 * @return LIDET_OK; LIDET_ERR_ARG (NULL); LIDET_ERR_CONFIG (unknown model or filter, seam > 35999, max_step 0 or
 *         above 18000, force_model or ring_top_first other than 0 or 1, force_model with AUTO; a calibration with
 *         AUTO, with n_lasers other than the model's, an elevation outside (-90 000, 90 000) mdeg or a rotational
 *         correction outside [-18 000, 18 000]).
 */
lidet_status_t lidet_velodyne_init(lidet_velodyne_t *st, const lidet_velodyne_cfg_t *cfg);

/**
 * @brief Forget the rotation (the next scan is PARTIAL) and an AUTO model's lock; the counts and a calibration
 *        stay.
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
 *                        sensor's 2 mm steps, VLP-32C 4 mm, plus the laser's distance correction); NULL only
 *                        when cap is 0.
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
 * @brief A ring's nominal elevation: millidegrees, for a model and ring (ring 0 = the lowest beam; no calibration).
 *        HDL-64E: the design's two blocks, -24.333 .. -8.833 deg every 0.5 deg and -8.333 .. +2 deg every 1/3 deg
 *        (a unit's own calibration differs by up to about 1 deg: docs/DECODING.md).
 * @return LIDET_OK; LIDET_ERR_ARG (NULL out, unknown model, ring >= the model's lasers).
 */
lidet_status_t lidet_velodyne_ring_elev_mdeg(lidet_velodyne_model_t model, uint32_t ring, int32_t *out_mdeg);

/** @brief Lasers (rings) of a model: 16, 32 or 64; 0 for an unknown model. */
uint32_t lidet_velodyne_n_rings(lidet_velodyne_model_t model);

/**
 * @brief The elevation of a ring as this decoder numbers its returns: the calibration's, else the model's nominal
 *        one, in the decoder's ring order (cfg.ring_top_first).
 * @return LIDET_OK; LIDET_ERR_ARG (NULL st or out, ring >= the model's lasers); LIDET_ERR_STATE (not initialised,
 *         or AUTO before its first decoded payload).
 */
lidet_status_t lidet_velodyne_decoder_elev_mdeg(const lidet_velodyne_t *st, uint32_t ring, int32_t *out_mdeg);

/** @brief Rings of the returns this decoder emits: 16, 32 or 64; 0 before AUTO's first decoded payload or for a
 *  state not initialised (NULL: 0). */
uint32_t lidet_velodyne_decoder_n_rings(const lidet_velodyne_t *st);

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

/**
 * @brief Float build only: lidet_velodyne_xyz with the decoder's own elevations (lidet_velodyne_decoder_elev_mdeg:
 *        a calibration's, the ring order of cfg.ring_top_first).
 * @return LIDET_OK; LIDET_ERR_ARG (as lidet_velodyne_xyz, NULL st); LIDET_ERR_STATE (not initialised, or AUTO
 *         before its first decoded payload).
 */
lidet_status_t lidet_velodyne_decoder_xyz(const lidet_velodyne_t *st, const lidet_return_t *returns,
                                          uint32_t n, float *xyz, uint32_t stride);
#endif

#ifdef __cplusplus
}
#endif

#endif /* LIDET_VELODYNE_H */
