/* SPDX-License-Identifier: MIT */
/**
 * @file lidet_ground.h
 * @brief Ground segmentation on the range image: Sobel-inspired sample filter + one RANSAC plane
 *        per azimuth sector (Seppänen et al., "No GPU? No problem", section on ground removal).
 *
 * Algorithm (lib/src/ground/lidet_ground_filter.c, lib/src/ground/lidet_ground_ransac.c; numpy mirror in
 * codegen/lidet_ref/ground.py):
 *  1. Sample filter over the projection's R (horizontal range) and Z images. For pixel (r, c), with
 *     row r+1 the beam below and columns wrapping around:
 *       S_v = [[2, 1], [-2, -1]] on rows r, r+1 and cols c, c+1:  dZ = S_v*Z, dR = S_v*R;
 *       F_y = dZ / dR, tested without division as |dZ| <= fy_max * |dR| (and dR > 0 when
 *       require_descending: the lower beam must land closer, as it does on ground);
 *       S_u = [1, 2, -2, -1] on cols c-1..c+2 of row r: F_x = S_u*R (paper) or S_u*Z (the authors'
 *       released code, fx_on_z = 1), tested as |F_x| <= fx_max_m.
 *     Optional height gate (released code): the pixel's z must lie in
 *     [-mount_height_m - gate_below_m, -mount_height_m + gate_above_m].
 *     Every pixel the kernels touch must hold a point; the bottom row has no sample. With
 *     sample_step > 1 only rows 0, step, 2 step, ... are filtered, and with sample_col_step > 1
 *     only the samples of columns 0, k, 2k, ... go to RANSAC (speed knobs).
 *  2. Per azimuth sector (sector of column c = c * n_sectors / n_cols), RANSAC over the samples:
 *     a seeded xorshift32 (state) draws 3 samples, hypotheses tilted more than max_tilt_rad are
 *     rejected before scoring, the rest are scored on at most eval_samples evenly strided
 *     samples (inliers: |distance| <= inlier_m), stopping early once the best plane's inlier share
 *     makes a better draw unlikely (confidence). The best plane is optionally refined by least
 *     squares on all its inlier samples (3x3 covariance, smallest eigenvector by Jacobi
 *     rotations), refine_iters times. A plane is accepted when it has >= min_inliers inliers,
 *     a tilt <= max_tilt_rad and a height of the sensor above it within max_height_dev_m of
 *     mount_height_m.
 *     With ring_split_m > 0 each sector has two cells, near (R < ring_split_m) and far, each
 *     fitted on its own samples (a lidet extension: real ground bends between 3 m and 70 m).
 *     With far_max_step_m > 0 (the dense profiles' default, 0.5 m) a far plane is judged where it
 *     meets the near plane instead: at the split, on the sector's middle azimuth, the two planes'
 *     heights differ by at most far_max_step_m (the near plane after its fallback: near cells are
 *     fitted and fall back first). A road that climbs 6 degrees from 17 m ahead has a far plane
 *     3 m below the sensor at the origin, which the sensor-height test refused: its cars then
 *     merged with the road into clusters too wide to keep.
 *  3. Fallback for near cells with fewer than min_samples samples or no accepted plane: the plane
 *     of the nearest fitted near cell at most fallback_sectors away (ties: sector s-k before s+k),
 *     else the mount plane z = -mount_height_m (normal +z). A far cell without its own plane takes
 *     its sector's near plane.
 *  4. Ground pixel: holds a point and its signed height h above its cell's plane satisfies
 *     -below_m(R) < h < above_m(R), with above_m(R) = ground_m + ground_m_per_m * R and
 *     below_m(R) = below_factor * above_m(R) (R = horizontal range). With below_factor 1 and
 *     ground_m_per_m 0 this is the paper's |distance| < p_th.
 *  5. Vertical veto (veto_slope > 0, a lidet extension): a ground pixel is dropped when it and the
 *     pixel above it form a surface steeper than veto_slope (|dz| > veto_slope |dR|, |dz| >
 *     veto_min_dz_m): the lowest returns of walls, kerbs, bumpers and trunks.
 *
 * Memory: sizeof(lidet_ground_t) = LIDET_MAX_ROWS * LIDET_MAX_COLS * 2 B (ground and sample masks)
 * + LIDET_GROUND_MAX_SAMPLES * 4 B (the samples' pixels) + LIDET_GROUND_EVAL_MAX * 12 B (x, y, z of a
 * cell's scoring subset) + LIDET_GROUND_MAX_SECTORS * 50 B + ~200 B; defaults (128 x 2048, 262,144
 * samples): about 1.5 MiB; a VLP-16 build (16 x 1800, samples = pixels): about 0.18 MiB.
 * lidet_ground_bytes() returns the exact figure. Declare it static. The state alone
 * (lidet_ground_state_t) is what lives across runs; lidet_ground_run_buffers() runs on buffers the
 * caller places (a detector workspace overlays the scratch, lidet_workspace.h).
 * Time: O(n_rows * n_cols) for the filter and the labelling, O(n_sectors * ransac_iters *
 * eval_samples + refine_iters * n_samples) for the planes; no allocation, no recursion.
 */
#ifndef LIDET_GROUND_H
#define LIDET_GROUND_H

#include "lidet_ground_common.h" /* plane sources, lidet_ground_stats_t, lidet_ground_sample_t */
#include "lidet_image.h"
#include "lidet_proj.h"
#include "lidet_sensor.h"
#include "lidet_types.h"

#ifdef __cplusplus
extern "C" {
#endif

/**
 * @brief Runtime configuration of the ground stage. Fill with lidet_ground_cfg_default(), which
 *        picks per-profile values (see docs/GROUND.md for how each default was measured).
 */
typedef struct
{
    /* ---- sample filter ---- */
    float fy_max;               /**< f_th1: max |F_y| = |S_v*Z / S_v*R|, the slope dz/dR between two
                                   beams (dimensionless); [0, 10], typical 0.1-0.3 (0.2 ~ 11 deg) */
    float fx_max_m;             /**< f_th2: max |F_x| = |S_u*R| (or |S_u*Z|), metres; (0, 100],
                                   typical 0.3-2 m */
    uint8_t fx_on_z;            /**< 0: F_x = S_u*R (paper), 1: F_x = S_u*Z (authors' released code) */
    uint8_t require_descending; /**< 1: also require dR > 0 (the lower beam lands closer, true on
                                   any ground the sensor looks down on); 0: the paper's |F_y| only */
    uint8_t height_gate;        /**< 1: samples must also pass the height gate (released code) */
    float gate_above_m;         /**< gate: max height above the nominal ground z = -mount_height_m,
                                   metres; [-5, 10], typical 0.3-0.5 (released KITTI: 0.43) */
    float gate_below_m;         /**< gate: max depth below the nominal ground, metres; [0, 20],
                                   typical 1-8 (released KITTI: 8.27, i.e. z > -10 m) */
    float mount_height_m;       /**< sensor optical centre above the ground, metres; [0, 10]; from the
                                   sensor profile. Used by the gate, the height check and the
                                   mount-plane fallback */
    /* ---- RANSAC per sector ---- */
    uint16_t n_sectors;       /**< azimuth sectors over 360 deg; [1, min(n_cols, LIDET_GROUND_MAX_SECTORS)],
                                   default 32 (11.25 deg) */
    uint16_t ransac_iters;    /**< hypotheses per sector; [1, 1000], typical 8-30 */
    uint16_t sample_step;     /**< the filter runs on rows 0, step, 2 step, ... only: a speed knob
                                   (planes need far fewer points than the image holds); [1, 16],
                                   1 = every row (paper), typical 1-4 */
    uint16_t sample_col_step; /**< RANSAC takes the samples of columns 0, k, 2k, ... of the filtered
                                   rows only (a speed knob); [1, 16], 1 = every sample (paper),
                                   typical 1-4 */
    uint16_t eval_samples;    /**< samples a hypothesis is scored on (evenly strided subset);
                                   [3, 65535], typical 64-512 */
    uint16_t min_samples;     /**< fewer samples in a sector: fallback; [3, 65535], typical 10-30 */
    uint16_t min_inliers;     /**< fewer inliers (among the scored subset): fallback; [3, 65535] */
    float confidence;         /**< adaptive RANSAC stop: after a new best plane with inlier share w,
                                   stop once (1 - w^3)^(hypotheses drawn) <= 1 - confidence;
                                   [0, 0.999999], 0 = always ransac_iters, typical 0.99 */
    uint8_t refine_iters;     /**< least-squares refinements on the inliers; [0, 10], 0 = plain RANSAC */
    float inlier_m;           /**< RANSAC inlier distance, metres; (0, 5], typical 0.1-0.3 */
    float max_tilt_rad;       /**< max angle between a plane normal and +z, radians; (0, pi/2),
                                   typical 0.1-0.35 (the released code used 0.1) */
    float max_height_dev_m;   /**< accepted |sensor height above the plane - mount_height_m|,
                                   metres; (0, 20], typical 0.5-1.5 */
    float ring_split_m;       /**< each sector is split at this horizontal range (metres) into a
                                   near and a far part with a plane each (ground is rarely one plane
                                   from 3 m to 70 m); 0 = one plane per sector (paper); [0, 500],
                                   typical 10-20 m */
    float far_max_step_m; /**< with ring_split_m > 0 and this > 0, a far plane is accepted when it meets its
                                   sector's near plane at the split within this height step (metres) instead of
                                   by the sensor's height above it: a road that climbs or falls beyond the
                                   split; 0 = the height test for far planes too; [0, 5] */
    float far2_split_m;   /**< a third cell per sector: with ring_split_m > 0 and this beyond it, the
                                   far cell's samples at or beyond this range get a plane of their own, judged
                                   where it meets the far plane at this range (far_max_step_m; the sensor-height
                                   test when that is 0), and the pixels at or beyond it take that plane (else the
                                   far plane); a road bends more than once over 15-70 m. Needs 3 * n_sectors <=
                                   2 * LIDET_GROUND_MAX_SECTORS (the planes share the near / far arrays); 0 = off;
                                   [0, 500]; default 30 on dense profiles, 0 on 16 beams and low mounts */
    uint16_t fallback_sectors; /**< how far (in sectors, either side) a fitted neighbour may be;
                                   [0, n_sectors] */
    uint32_t seed;             /**< xorshift32 seed (0 is replaced by a fixed non-zero value);
                                   re-applied at every run, so runs are deterministic */
    uint8_t seed_per_cell;     /**< 0 (default): one random stream through the cells in order; 1: each
                                   cell draws from a stream of its own (seed mixed with the cell index), so
                                   a cell's plane depends on its own samples alone and a windowed scan
                                   (lidet_proj_cfg_t azimuth_half_rad) gets, inside the window, the planes
                                   of the whole scan (the detector's crop sets it) */
    float azimuth_half_rad;    /**< 0 (default): the whole image; in (0, pi): the image holds no point outside
                                   the columns within this azimuth of straight ahead (one more each side: a
                                   projection with the same azimuth_half_rad, or a smaller one), so the stage
                                   filters, samples and labels only the sectors those columns touch (the
                                   others hold no sample and no ground): the same planes and labels as
                                   without, in the time of the window. Pixels outside those sectors are
                                   never ground. The detector's crop sets it to the projection's window; a
                                   workspace refuses (LIDET_ERR_CONFIG) a projection window wider than it,
                                   or none */
    /* ---- labelling ---- */
    float ground_m;       /**< p_th: max height above the sector plane for ground, metres;
                                   (0, 5], typical 0.1-0.3 */
    float ground_m_per_m; /**< p_th grows by this much per metre of horizontal range (far
                                   ground is noisier and the plane is extrapolated); [0, 0.1],
                                   typical 0-0.01; 0 = the paper's constant p_th */
    float below_factor;   /**< the tolerance below the plane is below_factor * the one above;
                                   [0, 20], 1 = symmetric (paper) */
    float veto_slope;     /**< vertical veto (a lidet extension): a pixel within the tolerance
                                   is not ground when it and the pixel above it (next beam up)
                                   are steeper than this, |dz| > veto_slope * |dR| (wall feet,
                                   kerb faces, bumpers, trunks); 0 = off (paper); [0, 100],
                                   typical 1-2 (1 = 45 deg) */
    float veto_min_dz_m;  /**< ... and only when |dz| > this (metres; ignores range noise on
                                   flat ground); [0, 5], typical 0.03-0.1 */
} lidet_ground_cfg_t;

/**
 * @brief What the ground stage keeps across runs and its small outputs: configuration, generator,
 *        planes, their sources and the counts (no per-pixel array; ~ LIDET_GROUND_MAX_SECTORS * 34 B).
 */
typedef struct
{
    uint32_t magic;
    lidet_ground_cfg_t cfg;
    uint32_t rng;                                       /* xorshift32 state */
    uint16_t n_rows, n_cols;                            /* of the last image */
    lidet_plane_t planes[2 * LIDET_GROUND_MAX_SECTORS]; /* near planes, then far planes */
    uint8_t source[2 * LIDET_GROUND_MAX_SECTORS];       /* lidet_ground_plane_source_t, same order */
    lidet_ground_stats_t stats;
} lidet_ground_state_t;

/**
 * @brief Scratch of one ground run: nothing in it is read after the run returns except the sample
 *        mask (lidet_ground_samples, a diagnostic). A detector workspace overlays it with the other
 *        stages' scratch. LIDET_MAX_ROWS * LIDET_MAX_COLS B + LIDET_GROUND_MAX_SAMPLES * 2 or 4 B (a
 *        sample is its pixel, lidet_ground_sample_t: RANSAC reads its coordinates from the image)
 *        + LIDET_GROUND_EVAL_MAX * 12 B
 *        + LIDET_GROUND_MAX_SECTORS * 16 B + LIDET_MAX_COLS * 24 B (two rows of R, for images without R;
 *        two rows of z and one of x and y, decoded, for a compact image).
 */
typedef struct
{
    uint8_t sample[LIDET_MAX_ROWS * LIDET_MAX_COLS];            /* 1 sample of the filter */
    lidet_ground_sample_t sample_pix[LIDET_GROUND_MAX_SAMPLES]; /* samples (their pixels), grouped by cell */
    float ev_x_m[LIDET_GROUND_EVAL_MAX];                        /* a cell's strided scoring subset */
    float ev_y_m[LIDET_GROUND_EVAL_MAX];
    float ev_z_m[LIDET_GROUND_EVAL_MAX];
    /* cells: k = s (near part of sector s) and k = n_sectors + s (far part); the samples of cell k
     * are sample_pix[cell_first[k] .. cell_first[k] + cell_n[k]) */
    uint32_t cell_first[2 * LIDET_GROUND_MAX_SECTORS];
    uint32_t cell_n[2 * LIDET_GROUND_MAX_SECTORS];
    float rxy_rows[2][LIDET_MAX_COLS]; /* R of two rows, computed when the image has no R */
    float z_rows[2][LIDET_MAX_COLS];   /* compact image: z of two rows, decoded */
    float x_row[LIDET_MAX_COLS];       /* compact image: x and y of one row, decoded */
    float y_row[LIDET_MAX_COLS];
} lidet_ground_scratch_t;

/** @brief Ground stage with every buffer inside (the standalone form): state, the ground mask (the
 *         output the clustering reads) and the scratch. Caller-owned; declare it static (it is large). */
typedef struct
{
    lidet_ground_state_t state;
    uint8_t mask[LIDET_MAX_ROWS * LIDET_MAX_COLS]; /* 1 ground, 0 not / empty */
    lidet_ground_scratch_t scratch;
} lidet_ground_t;

/**
 * @brief Defaults for a sensor profile (per-profile values measured on simulated and real scans).
 * @param[out] cfg    filled; never NULL-dereferenced (NULL: no-op).
 * @param[in]  sensor profile (its mount height and beam count choose the defaults); NULL gives the
 *                    hdl64-like defaults with mount_height_m 1.73.
 */
void lidet_ground_cfg_default(lidet_ground_cfg_t *cfg, const lidet_sensor_t *sensor);

/**
 * @brief Validate the configuration and reset the state. No allocation.
 * @param[out] g   state (caller-owned, static storage recommended).
 * @param[in]  cfg configuration (copied).
 * @return LIDET_OK; LIDET_ERR_ARG (NULL); LIDET_ERR_BUFFER (n_sectors > LIDET_GROUND_MAX_SECTORS);
 *         LIDET_ERR_CONFIG (a value outside its documented range, or not finite).
 */
lidet_status_t lidet_ground_init(lidet_ground_t *g, const lidet_ground_cfg_t *cfg);

/**
 * @brief Segment the ground of one range image.
 * @param[in,out] g   initialised state; its mask, samples and planes are overwritten.
 * @param[in]     img range image from lidet_proj_image (or built by hand with the same contract:
 *                    row 0 = top beam, rows ordered by decreasing elevation, empty pixels 0 in every
 *                    float array). x, y, z are read; R when given (else computed row by row);
 *                    point_idx is not read. A compact image (x_m NULL, x_4mm ... set, as a
 *                    workspace's) is read too: its rows are decoded into the scratch, R computed
 *                    from the decoded x, y. Not retained.
 * @return LIDET_OK; LIDET_TRUNCATED when more than LIDET_GROUND_MAX_SAMPLES pixels passed the filter
 *         (the excess, last sectors first, is counted in stats.n_samples_dropped and not used);
 *         LIDET_ERR_ARG (NULL, NULL x, y or z); LIDET_ERR_STATE (not initialised);
 *         LIDET_ERR_BUFFER (image larger than LIDET_MAX_ROWS x LIDET_MAX_COLS);
 *         LIDET_ERR_CONFIG (image has fewer columns than n_sectors).
 */
lidet_status_t lidet_ground_run(lidet_ground_t *g, const lidet_range_image_t *img);

/**
 * @brief Ground mask of the last run: n_rows * n_cols bytes, row-major like the image, 1 ground,
 *        0 not ground or empty. A view into g, valid until the next run/init.
 */
const uint8_t *lidet_ground_mask(const lidet_ground_t *g);

/** @brief Sample mask of the last run (1 = passed the filter), same layout as the ground mask. */
const uint8_t *lidet_ground_samples(const lidet_ground_t *g);

/**
 * @brief Planes of the last run, one per sector (sector of column c = c * n_sectors / n_cols): the
 *        near planes (horizontal range < ring_split_m; the whole sector when ring_split_m is 0).
 *        The far planes follow in the same array: planes[n_sectors + s] (equal to the near plane
 *        when the far part had no plane of its own), then, with far2_split_m, the third cells' planes
 *        planes[2 n_sectors + s] (equal to the far plane when the cell had no plane of its own).
 * @param[out] n_sectors number of sectors (may be NULL).
 * @return a view into g of 2 * n_sectors planes (3 * n_sectors with far2_split_m; valid until the next
 *         run/init), unit normals, nz > 0.
 */
const lidet_plane_t *lidet_ground_planes(const lidet_ground_t *g, uint32_t *n_sectors);

/** @brief Source of each plane (lidet_ground_plane_source_t values), 2 * n_sectors bytes in the
 *         order of lidet_ground_planes (near, then far). */
const uint8_t *lidet_ground_sector_source(const lidet_ground_t *g);

/**
 * @brief Per-point labels: every input point, in input order.
 * @param[in]  g           state after a run.
 * @param[in]  point_pixel pixel of each input point (lidet_proj_point_pixels), -1 = not projected;
 *                         a point that lost its pixel to a closer one takes the pixel's label.
 * @param[in]  n_points    entries of point_pixel and out.
 * @param[out] out         n_points bytes: 1 ground, 0 not (also for unprojected points and
 *                         out-of-image pixel indices). May not alias point_pixel.
 * @return LIDET_OK; LIDET_ERR_ARG (NULL with n_points > 0); LIDET_ERR_STATE (not initialised).
 */
lidet_status_t lidet_ground_point_labels(const lidet_ground_t *g, const int32_t *point_pixel,
                                         uint32_t n_points, uint8_t *out);

/** @brief Counts of the last run. */
const lidet_ground_stats_t *lidet_ground_stats(const lidet_ground_t *g);

/** @brief sizeof(lidet_ground_t): the bytes firmware must place for this stage. */
uint32_t lidet_ground_bytes(void);

/** @brief lidet_ground_init on the state alone, for a caller that places the buffers itself. */
lidet_status_t lidet_ground_state_init(lidet_ground_state_t *st, const lidet_ground_cfg_t *cfg);

/**
 * @brief lidet_ground_run on caller-placed buffers; same results, bit for bit.
 * @param[in,out] st      initialised state (planes, sources and stats are written).
 * @param[out]    scratch the run's scratch (its sample mask stays readable until it is reused).
 * @param[out]    mask    n_rows * n_cols bytes: the ground mask.
 * @param[in]     img     range image; rxy_m and point_idx may be NULL (without R the stage computes it
 *                        row by row from x and y, exactly as the projection would: same results).
 * @return as lidet_ground_run.
 */
lidet_status_t lidet_ground_run_buffers(lidet_ground_state_t *st, lidet_ground_scratch_t *scratch,
                                        uint8_t *mask, const lidet_range_image_t *img);

/** @brief Per-point labels from a state and the mask it produced (lidet_ground_point_labels). */
lidet_status_t lidet_ground_point_labels_of(const lidet_ground_state_t *st, const uint8_t *mask,
                                            const int32_t *point_pixel, uint32_t n_points, uint8_t *out);

/** @brief sizeof(lidet_ground_state_t) and sizeof(lidet_ground_scratch_t). */
uint32_t lidet_ground_state_bytes(void);
uint32_t lidet_ground_scratch_bytes(void);

/**
 * @brief Least-squares plane through weighted-free points (exposed for the Eigen cross-check).
 *        Centroid + 3x3 covariance, normal = eigenvector of the smallest eigenvalue (cyclic Jacobi).
 * @param[in]  x_m,y_m,z_m n coordinates, metres.
 * @param[in]  n           >= 3.
 * @param[out] plane       normal with nz >= 0 (flipped if needed), d so n.p + d = 0 at the centroid.
 * @param[out] eigvals     optional (may be NULL): the 3 covariance eigenvalues, ascending.
 * @return LIDET_OK; LIDET_ERR_ARG (NULL, n < 3, or a degenerate set: all points on a line).
 */
lidet_status_t lidet_ground_fit_plane(const float *x_m, const float *y_m, const float *z_m, uint32_t n,
                                      lidet_plane_t *plane, float *eigvals);

#ifdef __cplusplus
}
#endif

#endif /* LIDET_GROUND_H */
