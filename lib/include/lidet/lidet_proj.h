/* SPDX-License-Identifier: MIT */
/**
 * @file lidet_proj.h
 * @brief Spherical projection: a point cloud -> a range image (rows = beams, cols = azimuth).
 *
 * Algorithm (eq. 1 of Seppänen et al., with nearest-beam rows):
 *  - column: azimuth = atan2(y, x); col = floor(0.5 * (1 - azimuth/pi) * n_cols), so +x is the middle
 *    column, azimuth decreases to the right and the seam (col 0 / n_cols - 1) is straight behind;
 *    columns wrap around (azimuth -pi and +pi both land in col 0).
 *  - row: the beam whose elevation is nearest to the point's elevation (the sensor's real per-beam
 *    table, not only a uniform formula), or the caller's per-point ring index when the sensor gives
 *    one. Row 0 is the highest beam.
 *  - several points in one pixel: the closest one (smallest range) wins; ties keep the earlier point.
 * No libm atan2/asin in the hot loop, and no approximation either: both tests are exact comparisons
 * against boundaries precomputed in init.
 *  - elevation: tan(elevation) = z / sqrt(x^2 + y^2) against the tangents of the mid-angles between
 *    beams (tan is monotonic), found through a lookup table plus at most a step or two;
 *  - azimuth: a "diamond" pseudo-angle D = 1 + x/(|x|+|y|) for y >= 0, 3 - x/(|x|+|y|) for y < 0
 *    (monotonic in azimuth, 0 at +-180 deg, 2 at +x, 4 just before -180 deg), against the D of
 *    every column edge, found the same way. One division, no polynomial; the only error is float
 *    rounding (max 1e-5 deg, measured in docs/benchmarks/proj.md).
 * Points that are NaN/Inf, closer than min_range_m, farther than max_range_m (if set; when writing a
 * compact image, farther than LIDET_PIXEL_MAX_RANGE_M = 131 m too), outside the vertical field of
 * view, or with an invalid ring index are counted per reason and skipped before any float -> int
 * conversion. The image is float (lidet_proj_t) or, into caller buffers, compact: int16 x, y, z and
 * uint16 range in 4 mm steps (lidet_proj_buffers_t, lidet_range_image_t), the float values rounded.
 *
 * Memory: lidet_proj_t holds every buffer, sizeof = LIDET_MAX_ROWS * LIDET_MAX_COLS * 24 B (x, y, z,
 * range, R as float, winning point as int32) + LIDET_MAX_POINTS * 4 B (pixel of each input point)
 * + LIDET_MAX_COLS * 12 B (column edges and their lookup table) + LIDET_PROJ_ROW_LUT * 1 B
 * + LIDET_MAX_ROWS * 9 B + ~100 B. Defaults (128 x 2048, 262,144 points): about 7.3 MiB; a VLP-16
 * build (16 x 1800, 30,000 points): about 0.8 MiB. lidet_proj_bytes() returns the exact figure.
 * Declare it `static`. The state alone (lidet_proj_state_t: configuration, tables, counts) is the
 * part that lives across runs; lidet_proj_run_buffers() writes into buffers the caller places, where
 * R and the per-point pixels are optional (a detector workspace, lidet_workspace.h, keeps neither).
 * Time: O(n_points + n_rows * n_cols) per run, no allocation, no recursion. Stack: run() keeps the keys
 * of a block of LIDET_PROJ_BLOCK points, 28 B each (1.75 KiB with the default 64; see lidet_opt.h).
 */
#ifndef LIDET_PROJ_H
#define LIDET_PROJ_H

#include "lidet_image.h"
#include "lidet_proj_stats.h"
#include "lidet_sensor.h"
#include "lidet_types.h"

#ifdef __cplusplus
extern "C" {
#endif

/** @brief Runtime configuration of the projection. Fill with lidet_proj_cfg_default(). */
typedef struct
{
    lidet_sensor_t sensor;  /**< the sensor (its table is copied by init) */
    float min_range_m;      /**< points closer than this are dropped (zero range included);
                                [0, 10], default 0.1 m */
    float max_range_m;      /**< points farther are dropped; [0, 1e6], 0 = no limit (default) */
    float fov_margin_rad;   /**< how far above the top beam / below the bottom beam a point may lie
                                and still map to the edge row; [0, 0.5], default 5 deg (0.0873): the
                                lasers sit centimetres off the optical centre, so close returns appear
                                degrees outside the table (real KITTI: top-beam points at 4 m show up
                                to 2.5 deg above it). For a uniform fov (table NULL) the margin is
                                added to fov_up / fov_down. */
    float azimuth_half_rad; /**< 0 (default): the whole scan; in (0, pi): only points whose column lies within
                                 this of straight ahead (+x), one more column each side, are projected, the
                                 others counted in n_out_of_window (the pixels outside stay empty); >= pi: the
                                 whole scan. The detector's crop sets it (lidet_detector.h). Points outside
                                 the window are counted there before any elevation or ring test */
} lidet_proj_cfg_t;

/**
 * @brief What the projection keeps across runs: the configuration, the row and column tables derived
 *        in init, and the counts of the last run (no per-pixel array). About 12 B per column + 9 B per
 *        row + LIDET_PROJ_ROW_LUT B: 24 KiB for a VLP-16 build. lidet_proj_t embeds one; a detector
 *        workspace (lidet_workspace.h) embeds one beside its own buffers.
 */
typedef struct
{
    uint32_t magic;
    lidet_proj_cfg_t cfg;
    /* derived in init */
    float row_elev_rad[LIDET_MAX_ROWS];      /* beam elevations, row order (descending) */
    int32_t row_elev_bam[LIDET_MAX_ROWS];    /* the same in BAM32, for the integer stages */
    float row_bound_tan[LIDET_MAX_ROWS + 1]; /* [r] = tan of the mid-angle between rows r-1 and r;
                                               sentinels [0] = +big, [n_rows] = -big */
    uint8_t ring_to_row[LIDET_MAX_ROWS];     /* ring index -> row */
    uint8_t row_lut[LIDET_PROJ_ROW_LUT + 1]; /* tan(elevation) bucket -> row of its top end */
    float tan_lo, tan_hi, lut_scale;         /* accepted tan(elevation) range, buckets per unit */
    uint8_t row_single_step; /* 1: boundaries > 2 buckets apart, one correction step is exact */
    uint8_t col_single_step; /* same for the column edges */
    float col_edge_key[LIDET_MAX_COLS + 1];   /* pseudo-azimuth D of the left edge of each column;
                                                 [n_cols] = 5 (> any D), a sentinel */
    uint16_t col_lut[4 * LIDET_MAX_COLS + 1]; /* D bucket (width 1/n_cols) -> column of its low end */
    float col_lut_scale;                      /* n_cols: buckets per unit of D */
    uint32_t win_lo, win_hi; /* the azimuth window's columns [win_lo, win_hi) (0, n_cols: all) */
    float win_edge[4];       /* run()'s block pre-test: directions (x, y) of the window's two edges, each
                                turned a margin outwards (lidet_proj.c), low azimuth edge first */
    uint8_t win_test;        /* 0: no pre-test (no window); 1: window + margins <= pi; 2: wider */
    uint32_t n_points;       /* points of the last run (<= LIDET_MAX_POINTS) */
    lidet_proj_stats_t stats;
} lidet_proj_state_t;

/**
 * @brief Where a run writes: caller-owned arrays of n_rows * n_cols pixels (row-major) unless noted.
 * Used by lidet_proj_run_buffers(), so that a workspace can place each array where its lifetime
 * allows (lidet_workspace.h overlays point_idx with the later stages' scratch).
 */
typedef struct
{
    float *x_m, *y_m, *z_m;         /**< the winning point's coordinates (0 for empty pixels); required for a
                                 float image; all NULL for a compact image */
    float *range_m;                 /**< float image: its range, > 0 exactly for valid pixels, else 0 */
    int16_t *x_4mm, *y_4mm, *z_4mm; /**< compact image (x_m NULL): the coordinates in 4 mm steps; points
                                         beyond LIDET_PIXEL_MAX_RANGE_M are then dropped (n_too_far) */
    uint16_t *range_4mm;  /**< compact image: the range in 4 mm steps, >= 1 for valid pixels, else 0 */
    float *rxy_m;         /**< optional (NULL: not produced): R = sqrt(x^2 + y^2) of the float
                                 coordinates, or of a compact image's decoded 4 mm values (the ground
                                 stage's expression: the same bits as it computes); the ground stage
                                 computes it itself when the image has none */
    int32_t *point_idx;   /**< required: the winning input point of each pixel, -1 = empty. The run
                                 needs it as scratch; keep it only if per-pixel -> point is wanted.
                                 A compact run keeps each pixel's best squared range in rxy_m when
                                 the image has that plane, else in range_4mm and z_4mm, until the
                                 winners' values are written there when the run returns */
    int32_t *point_pixel; /**< optional (NULL: not produced): LIDET_MAX_POINTS entries, the pixel of
                                 each input point (per-point outputs: 4 B per point) */
} lidet_proj_buffers_t;

/** @brief Projection state with every buffer inside (the standalone form of the stage): the state
 *         plus the buffers of lidet_proj_buffers_t, all produced. Caller-owned; declare it static. */
typedef struct
{
    lidet_proj_state_t state;
    /* outputs of the last run */
    float x_m[LIDET_MAX_ROWS * LIDET_MAX_COLS];
    float y_m[LIDET_MAX_ROWS * LIDET_MAX_COLS];
    float z_m[LIDET_MAX_ROWS * LIDET_MAX_COLS];
    float range_m[LIDET_MAX_ROWS * LIDET_MAX_COLS];
    float rxy_m[LIDET_MAX_ROWS * LIDET_MAX_COLS];
    int32_t point_idx[LIDET_MAX_ROWS * LIDET_MAX_COLS];
    int32_t point_pixel[LIDET_MAX_POINTS]; /* pixel of every input point, -1 = not projected */
} lidet_proj_t;

/**
 * @brief Default configuration for a sensor.
 * @param[out] cfg    filled with defaults (min range 0.1 m, no max range, 5 deg fov margin).
 * @param[in]  sensor profile to copy (a preset from lidet_sensor_find, or your own); may be NULL,
 *                    in which case cfg->sensor is zeroed and init will fail until it is set.
 */
void lidet_proj_cfg_default(lidet_proj_cfg_t *cfg, const lidet_sensor_t *sensor);

/**
 * @brief Validate the configuration and precompute the tables. Call once (or again to change
 *        sensor); no allocation.
 * @param[out] proj state to initialise (caller-owned, static storage recommended).
 * @param[in]  cfg  configuration; the sensor's beam table is copied, cfg may be freed afterwards.
 * @return LIDET_OK; LIDET_ERR_ARG (NULL); LIDET_ERR_BUFFER (n_rows > LIDET_MAX_ROWS or
 *         n_cols > LIDET_MAX_COLS); LIDET_ERR_CONFIG (n_rows 0, n_cols < 8, elevations not finite,
 *         outside (-pi/2, pi/2) or not distinct, fov_up <= fov_down, ranges or margin out of range, a
 *         field of view (beams + margin) of zero width, e.g. one beam and no margin, or below ~1e-37 rad).
 */
lidet_status_t lidet_proj_init(lidet_proj_t *proj, const lidet_proj_cfg_t *cfg);

/**
 * @brief Project one scan.
 * @param[in,out] proj     initialised state; its image and point_pixel are overwritten.
 * @param[in]     points   n_points records of `stride` floats, x y z first (metres, sensor frame);
 *                         may be NULL only when n_points == 0. Not modified, not retained.
 * @param[in]     n_points number of records. Only the first LIDET_MAX_POINTS are processed.
 * @param[in]     stride   floats per record, >= 3 (4 for KITTI .bin).
 * @param[in]     ring     optional per-point ring index (sensor's ring order, < n_rows), or NULL
 *                         to choose rows by elevation.
 * @return LIDET_OK; LIDET_TRUNCATED when n_points > LIDET_MAX_POINTS (the rest is counted in
 *         stats.n_truncated and not looked at); LIDET_ERR_ARG (NULL state, NULL points with
 *         n_points > 0, stride < 3); LIDET_ERR_STATE (not initialised).
 */
lidet_status_t lidet_proj_run(lidet_proj_t *proj, const float *points, uint32_t n_points, uint32_t stride,
                              const uint16_t *ring);

/**
 * @brief A view of the range image of the last run (valid until the next run/init).
 * @param[in]  proj initialised state.
 * @param[out] img  filled with pointers into proj.
 */
void lidet_proj_image(const lidet_proj_t *proj, lidet_range_image_t *img);

/**
 * @brief Pixel of each input point of the last run: `*n_points` entries, -1 = not projected.
 * Every input point that maps to a pixel gets its pixel, also those that lost the pixel to a
 * closer point (so per-point labels can be given to every point). Valid until the next run.
 */
const int32_t *lidet_proj_point_pixels(const lidet_proj_t *proj, uint32_t *n_points);

/** @brief Counts of the last run. */
const lidet_proj_stats_t *lidet_proj_stats(const lidet_proj_t *proj);

/** @brief sizeof(lidet_proj_t): the bytes firmware must place for this stage. */
uint32_t lidet_proj_bytes(void);

/**
 * @brief lidet_proj_init on the state alone (the tables), for a caller that places the buffers itself.
 * @return as lidet_proj_init.
 */
lidet_status_t lidet_proj_state_init(lidet_proj_state_t *st, const lidet_proj_cfg_t *cfg);

/**
 * @brief lidet_proj_run writing into caller-placed buffers (see lidet_proj_buffers_t for which are
 *        optional). Same results, bit for bit, as lidet_proj_run.
 * @return as lidet_proj_run; LIDET_ERR_ARG also when a required buffer is NULL.
 */
lidet_status_t lidet_proj_run_buffers(lidet_proj_state_t *st, const lidet_proj_buffers_t *buf,
                                      const float *points, uint32_t n_points, uint32_t stride,
                                      const uint16_t *ring);

/**
 * @brief The range image view of buffers filled by lidet_proj_run_buffers (rxy_m and point_idx as
 *        given, possibly NULL: pass NULL there when the array no longer holds this run's values).
 */
void lidet_proj_image_of(const lidet_proj_state_t *st, const lidet_proj_buffers_t *buf,
                         lidet_range_image_t *img);

/** @brief sizeof(lidet_proj_state_t): the bytes that live across runs (tables and counts). */
uint32_t lidet_proj_state_bytes(void);

/**
 * @brief The pseudo-azimuth the projection bins columns on (exposed for tests and benchmarks):
 *        D = 1 + x/(|x|+|y|) for y >= 0, 3 - x/(|x|+|y|) for y < 0; in [0, 4], increasing as the
 *        azimuth atan2(y, x) decreases from +pi to -pi (column = floor(D / 4 * n_cols) up to the
 *        exact edge table). Returns 2 (straight ahead) for x = y = 0.
 */
float lidet_proj_azimuth_key(float x, float y);

#ifdef __cplusplus
}
#endif

#endif /* LIDET_PROJ_H */
