/* SPDX-License-Identifier: MIT */
/**
 * @file lidet_proj_q.h
 * @brief Spherical projection of the integer path: int32 mm points -> the compact range image
 *        (lidet_range_image_t of lidet_image.h: int16 x, y, z and uint16 range in 4 mm steps).
 *
 * The rules of lidet_proj.h, in integers (docs/FIXED_POINT.md, "Projection"):
 *  - row: the beam nearest in elevation, or the ring's row when the driver gives ring ids. The row boundaries
 *    are the tangents of the mid-angles between beams, computed in init from lidet_qmath's sin/cos of the
 *    mid-angle in BAM32 (tangent in Q30, kept squared as n / 2^q with n < 2^27 and q <= 60). A point is at or
 *    above boundary T when z / rxy >= T: signs first, then z^2 * 2^q against n * (x^2 + y^2), exact in 64 bits
 *    (no square root, no division); the row is the previous point's when its two boundaries confirm it (scans
 *    come ring by ring), else a binary search over the boundaries (log2(rows) tests). Ties go to the upper row,
 *    as in the float projection. The field of view (top beam + margin, bottom beam - margin, both clamped to
 *    +-LIDET_Q_MAX_ELEV_URAD) uses the same test, on the edge rows only.
 *  - column: the pseudo-azimuth D = (|x|+|y| + x) / (|x|+|y|) for y >= 0, (3 (|x|+|y|) - x) / (|x|+|y|) for y < 0
 *    of lidet_proj.h, against the column edges (Q29, from qmath sin/cos) by cross-multiplication (a 32-bit test
 *    first, 64 bits near an edge): the previous point's column or a neighbour when they confirm it, else the
 *    bucket floor(D n_cols) (one 32-bit unsigned division), a table and one step up.
 *  - the closest point wins a pixel: the squared ranges compared in 4 mm^2 steps, floor(r^2 / 4) (< 2^32; the float
 *    projection compares float32 squares, coarser beyond 5.8 m), ties keep the earlier point; only the winners get a
 *    square root (exact, 32-bit): range_4mm = round(sqrt(r^2) / 4) (>= 1 for a valid pixel).
 * Points with |x|, |y| or |z| > LIDET_Q_COORD_MAX_MM or a range above max_range_mm (or 131 000 mm, the compact
 * image's limit) count as n_too_far; closer than min_range_mm, or at zero range, as n_too_close; n_nonfinite
 * stays 0. No float anywhere, no 64-bit division per point.
 *
 * Memory: lidet_proj_q_state_t (the tables) is about 33 B per row + 14 B per column + ~130 B (VLP-16 build:
 * 25 KiB, of which 3.6 KiB are the range-only image's column table); the buffers are the caller's
 * (lidet_proj_q_buffers_t), 12 B per pixel (range-only: 6 B, of which 4 B scratch) + optionally 4 B per point.
 * Time: O(n_points log2(n_rows) + n_rows n_cols) per run (Cortex-M0+ code: 16.0 M instructions for the 23 252
 * points of the simulated VLP-16 sample, docs/FIXED_POINT.md); no allocation, no recursion, little stack.
 */
#ifndef LIDET_PROJ_Q_H
#define LIDET_PROJ_Q_H

#include "lidet_image.h"
#include "lidet_proj_stats.h"
#include "lidet_q.h"
#include "lidet_sensor_q.h"

#ifdef __cplusplus
extern "C" {
#endif

/** @brief Configuration of the integer projection. Fill with lidet_proj_q_cfg_default(). */
typedef struct
{
    lidet_sensor_q_t sensor; /**< the sensor (its table is copied by init) */
    int32_t min_range_mm; /**< closer points are dropped (zero range always is); [0, 10 000], default 100 */
    int32_t max_range_mm; /**< farther points are dropped; [0, 1e9], 0 = no limit (default); at most 131 000
                                  takes effect (the compact image's limit) */
    int32_t fov_margin_urad; /**< as lidet_proj_cfg_t.fov_margin_rad; [0, 500 000], default 87 266 (5 deg) */
} lidet_proj_q_cfg_t;

/** @brief A row boundary: tan(angle)^2 = n / 2^q, sign = the sign of tan (0: the horizon, n = 0). */
typedef struct
{
    uint64_t z2_max; /**< 2^(63 - q) - 1: a larger z^2 makes z^2 2^q exceed any n (x^2 + y^2) */
    uint32_t n;
    uint8_t q;
    int8_t sign;
} lidet_proj_q_bound_t;

/** @brief What lives across runs: configuration, tables derived in init, counts of the last run. */
typedef struct
{
    uint32_t magic;
    lidet_proj_q_cfg_t cfg;
    int32_t row_elev_urad[LIDET_MAX_ROWS];              /* beam elevations, row order (descending) */
    int32_t row_elev_bam[LIDET_MAX_ROWS];               /* the same in BAM32 */
    lidet_proj_q_bound_t row_bound[LIDET_MAX_ROWS + 1]; /* [r] = mid-angle between rows r-1 and r, r >= 1 */
    lidet_proj_q_bound_t fov_hi, fov_lo;                /* accepted elevation range (margin included) */
    uint8_t ring_to_row[LIDET_MAX_ROWS];                /* ring index -> row */
    uint32_t col_edge_q29[LIDET_MAX_COLS + 1];          /* D of each column's left edge, Q29; [n_cols] = 5 */
    uint16_t col_lut[4 * LIDET_MAX_COLS + 1];           /* bucket floor(D n_cols) -> column of its low end */
    int32_t row_trig_q15[2 * LIDET_MAX_ROWS];           /* cos, sin of each row's elevation (Q15) */
    int32_t col_trig_q15[2 * (LIDET_MAX_COLS / 4)]; /* sin, cos (Q15) of the first quarter's column centres */
    uint8_t has_col_trig;                           /* 1: col_trig_q15 filled (n_cols a multiple of 4) */
    uint32_t n_points;                              /* points of the last run (<= LIDET_MAX_POINTS) */
    lidet_proj_stats_t stats;                       /* counts of the last run (n_nonfinite always 0) */
    uint8_t stream_open;                            /* 1: between lidet_proj_q_returns_begin and _end */
} lidet_proj_q_state_t;

/** @brief Caller-owned outputs of a run: n_rows * n_cols pixels each unless noted. */
typedef struct
{
    /** the winner's coordinates in 4 mm steps (0 when empty); all three NULL: a range-only image (the later
     *  integer stages decode x, y, z from row, column and range: lib/src/internal/lidet_qpix.h) */
    int16_t *x_4mm, *y_4mm, *z_4mm;
    uint16_t *range_4mm; /**< required: its range in 4 mm steps, >= 1 when valid, else 0 */
    /** required: winning input point, -1 = empty; range-only: the run's scratch (each pixel's winner key), not
     *  an output (the image's point_idx is NULL) */
    int32_t *point_idx;
    int32_t *point_pixel; /**< optional (NULL = not produced): LIDET_MAX_POINTS entries, the pixel of
                                         each input point, -1 = not projected */
} lidet_proj_q_buffers_t;

/** @brief Defaults (min range 100 mm, no max range, 87 266 urad margin) for a sensor (may be NULL: zeroed). */
void lidet_proj_q_cfg_default(lidet_proj_q_cfg_t *cfg, const lidet_sensor_q_t *sensor);

/**
 * @brief Validate the configuration and build the tables.
 * @return LIDET_OK; LIDET_ERR_ARG (NULL); LIDET_ERR_BUFFER (n_rows > LIDET_MAX_ROWS, n_cols > LIDET_MAX_COLS);
 *         LIDET_ERR_CONFIG (n_rows 0, n_cols < 8, elevations beyond +-LIDET_Q_MAX_ELEV_URAD or not distinct
 *         enough to order their boundaries, fov_up <= fov_down, ranges or margin out of range).
 */
lidet_status_t lidet_proj_q_init(lidet_proj_q_state_t *st, const lidet_proj_q_cfg_t *cfg);

/**
 * @brief Project one scan.
 * @param[in]     points n_points records of `stride` int32 (x, y, z first, mm); NULL only when n_points is 0.
 * @param[in]     ring   optional ring index per point (< n_rows), or NULL for rows by elevation.
 * @return LIDET_OK; LIDET_TRUNCATED (points past LIDET_MAX_POINTS not looked at, n_truncated); LIDET_ERR_ARG
 *         (NULL state/buffers/points, stride < 3); LIDET_ERR_STATE (not initialised).
 */
lidet_status_t lidet_proj_q_run(lidet_proj_q_state_t *st, const lidet_proj_q_buffers_t *buf,
                                const int32_t *points, uint32_t n_points, uint32_t stride,
                                const uint16_t *ring);

/**
 * @brief One return as a spinning sensor reports it: the laser's ring, the azimuth of its firing and the
 *        distance along the beam (a VLP-16 packet's block azimuth, laser id and distance, in these units).
 *
 * Feeding returns skips what a driver would otherwise compute per point and the projection undo: no sine or
 * cosine to make x, y, z, no square root and no column search to get them back (docs/PORTING.md, "Feeding the
 * detector"). 8 bytes per return.
 */
typedef struct
{
    uint32_t range_mm; /**< distance along the beam in mm; 0 = no return (counted as too close) */
    uint16_t azimuth;  /**< BAM16: 65 536 per turn, counterclockwise from +x (the angle of atan2(y, x)) */
    uint16_t ring;     /**< the sensor's ring (laser) index, as the ring argument of lidet_proj_q_run */
} lidet_return_t;

/**
 * @brief Project one scan given as returns (lidet_return_t): the same image as lidet_proj_q_run would make of
 *        the points, up to where a return sits in its pixel.
 *
 * Rules (docs/FIXED_POINT.md, "Projection"; codegen/lidet_ref/proj_q.py project_returns):
 *  - row: the ring's row; a ring >= n_rows counts as n_bad_ring;
 *  - column: c = floor(((0x8000 - azimuth) mod 2^16) n_cols / 2^16), the column lidet_proj_q_run numbers by
 *    u = (pi - azimuth) / 2 pi;
 *  - range_mm 0 or below min_range_mm: n_too_close; above max_range_mm (when set) or 131 000 mm: n_too_far;
 *  - the nearest return wins a pixel (ties keep the earlier one); range_4mm = round(range_mm / 4), >= 1;
 *  - an image that stores x, y, z gets them decoded from row, column and range (the range-only image's rule,
 *    lib/src/internal/lidet_qpix.h), so both image kinds give the later stages the same coordinates.
 * About 35 instructions per return on a Cortex-M4 (lidet_proj_q_run: about 160 per point).
 * @return as lidet_proj_q_run (LIDET_ERR_ARG: NULL state/buffers, or NULL returns with n_returns > 0).
 */
lidet_status_t lidet_proj_q_run_returns(lidet_proj_q_state_t *st, const lidet_proj_q_buffers_t *buf,
                                        const lidet_return_t *returns, uint32_t n_returns);

/**
 * @brief Project one scan's returns as they arrive (a packet at a time), without holding the scan: begin clears
 *        the image, each add projects a chunk into it, end finishes it. The image, the stats and n_points equal
 *        lidet_proj_q_run_returns' on the chunks' concatenation, bit for bit, however the scan is cut (its first
 *        pass is order-independent: the nearest return per pixel, ties to the earlier one).
 *
 * The same buffers (the same image arrays) must be given to every call of one scan; buf->point_pixel may differ per
 * call: when set, it receives the pixel of each return of *that* chunk (n_returns entries, -1 = dropped), so a
 * caller without a scan buffer still gets per-return labels chunk by chunk (entries of returns past
 * LIDET_MAX_POINTS are not written). point_idx (an image that stores x, y, z)
 * numbers the returns across the whole scan. As in lidet_proj_q_run_returns, returns past LIDET_MAX_POINTS in
 * one scan are counted in n_truncated and not looked at. lidet_proj_q_run and lidet_proj_q_run_returns close an
 * open stream (its returns are lost).
 * @return begin: LIDET_OK; LIDET_ERR_ARG (NULL state/buffers, x / y / z not all set or all NULL); LIDET_ERR_STATE
 *         (not initialised). add: LIDET_OK; LIDET_TRUNCATED (this chunk crossed LIDET_MAX_POINTS); LIDET_ERR_ARG
 *         (as begin, or NULL returns with n_returns > 0); LIDET_ERR_STATE (no stream open). end: LIDET_OK or
 *         LIDET_TRUNCATED (the scan's returns past LIDET_MAX_POINTS were dropped); LIDET_ERR_ARG; LIDET_ERR_STATE
 *         (no stream open).
 */
lidet_status_t lidet_proj_q_returns_begin(lidet_proj_q_state_t *st, const lidet_proj_q_buffers_t *buf);
/** @brief One chunk of the open scan (lidet_proj_q_returns_begin). */
lidet_status_t lidet_proj_q_returns_add(lidet_proj_q_state_t *st, const lidet_proj_q_buffers_t *buf,
                                        const lidet_return_t *returns, uint32_t n_returns);
/** @brief Finish the open scan (lidet_proj_q_returns_begin): the image and the stats are those of the scan. */
lidet_status_t lidet_proj_q_returns_end(lidet_proj_q_state_t *st, const lidet_proj_q_buffers_t *buf);

/** @brief The compact range image of buffers filled by lidet_proj_q_run (row_elev_rad NULL, row_elev_bam set). */
void lidet_proj_q_image(const lidet_proj_q_state_t *st, const lidet_proj_q_buffers_t *buf,
                        lidet_range_image_t *img);

/** @brief Counts of the last run (NULL for a NULL state). */
const lidet_proj_stats_t *lidet_proj_q_stats(const lidet_proj_q_state_t *st);

/** @brief sizeof(lidet_proj_q_state_t). */
uint32_t lidet_proj_q_state_bytes(void);

#ifdef __cplusplus
}
#endif

#endif /* LIDET_PROJ_Q_H */
