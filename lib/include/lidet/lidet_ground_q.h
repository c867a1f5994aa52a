/* SPDX-License-Identifier: MIT */
/**
 * @file lidet_ground_q.h
 * @brief Integer ground segmentation (the integer path, docs/FIXED_POINT.md): the algorithm of lidet_ground.h
 *        on a compact range image (int16 x, y, z in 4 mm steps), with integers only.
 *
 * Same steps, order and random draws as the float stage (lidet_ground.h), in integer form
 * (lib/src/ground/lidet_ground_filter_q.c filter, gathering, labels; lib/src/ground/lidet_ground_ransac_q.c
 * RANSAC, refinement, fallback; numpy mirror codegen/lidet_ref/ground_q.py, bit for bit):
 *  - R (horizontal range) of a pixel in 4 mm / 256 steps (1/64 mm), computed row by row as the rows are
 *    needed: round(sqrt(x^2 + y^2) * 256) in an image that stores x, y, z (an exact integer square root of a
 *    47-bit value); in a range-only image round(range * ce / 2^7), ce the row elevation's Q15 cosine that its
 *    x, y, z are decoded with (lidet_qpix.h): the decoded ray's horizontal distance, with no square root;
 *  - sample filter: dZ = S_v*Z (4 mm), dR = S_v*R, |dZ| * 2^24 <= fy_max_q16 * |dR| (cross-multiplied),
 *    F_x = S_u*R (or S_u*Z), |F_x| against fx_max_mm exactly (64 R steps a millimetre);
 *  - near / far: x^2 + y^2 >= ceil(ring_split_mm^2 / 16) (a squared comparison, threshold from init);
 *  - RANSAC hypothesis: c = (p1 - p0) x (p2 - p0) in int64 (4 mm vectors, exact), degenerate when
 *    |c|^2 <= 39 (the float stage's 1e-8 m^4), tilt |cz| * 2^30 >= cos_q30(max_tilt) * |c| with
 *    |c| = round(sqrt(|c|^2)); inlier: 4 |c . (p - p0)| <= inlier_mm * |c| (no division, no unit normal);
 *  - adaptive stop: w = inliers / scored in Q30 (one division per new best plane), (1 - w^3)^k by repeated
 *    Q30 products against 1 - confidence (no log);
 *  - refinement: the inliers' integer centroid and scatter matrix (exact int64 sums), the normal by power
 *    iteration on the adjugate of the scatter matrix (its dominant eigenvector is the smallest one of the
 *    scatter: the least-squares normal), Q30 unit normal by an integer square root;
 *  - plane height h = n . p + D in 4 mm / 2^30 (n Q30, D int64, exact), band -below < h < above with the
 *    tolerances in mm turned into the same unit exactly; vertical veto |dz| * 2^24 > veto_slope_q16 * |dR|
 *    and 4 |dz| > veto_min_dz_mm.
 * Outputs as the float stage: a ground mask per pixel (1 ground), planes per cell (lidet_plane_q_t: Q30
 * normal, d in 4 mm steps; the labels use the unrounded D), their sources, the counts (lidet_ground_stats_t).
 *
 * Memory: lidet_ground_q_state_t ~ LIDET_GROUND_MAX_SECTORS * 50 B; lidet_ground_q_scratch_t = a sample mask
 * byte per pixel + LIDET_GROUND_MAX_SAMPLES sample indices + LIDET_GROUND_EVAL_MAX * 6 B + LIDET_MAX_COLS * 16 B
 * (two rows of R, the square root's work rows) + LIDET_GROUND_MAX_SECTORS * 16 B. No allocation, no recursion, no float.
 */
#ifndef LIDET_GROUND_Q_H
#define LIDET_GROUND_Q_H

#include "lidet_ground_common.h"
#include "lidet_image.h"
#include "lidet_q.h"

#ifdef __cplusplus
extern "C" {
#endif

/**
 * @brief Integer configuration (the fields of lidet_ground_cfg_t in mm, Q16 and microradians; the defaults
 *        are the float defaults rounded). Ranges as the float stage's.
 */
typedef struct
{
    uint32_t fy_max_q16;        /**< f_th1, Q16; [0, 655360] (0.2 -> 13107) */
    uint32_t fx_max_mm;         /**< f_th2, mm; (0, 100000] */
    uint8_t fx_on_z;            /**< 0: F_x = S_u*R, 1: S_u*Z */
    uint8_t require_descending; /**< 1: also dR > 0 */
    uint8_t height_gate;        /**< 1: z within [-mount - gate_below, -mount + gate_above] */
    uint8_t refine_iters;       /**< least-squares refinements; [0, 10] */
    uint8_t seed_per_cell;      /**< 0: one random stream through the cells in order; 1: a stream per cell
                                     (lidet_ground_cfg_t.seed_per_cell: the same streams as the float stage) */
    int32_t gate_above_mm;      /**< [-5000, 10000] */
    int32_t gate_below_mm;      /**< [0, 20000] */
    int32_t mount_height_mm;    /**< [0, 10000] */
    uint16_t n_sectors;         /**< [1, min(n_cols, LIDET_GROUND_MAX_SECTORS)] */
    uint16_t ransac_iters;      /**< [1, 1000] */
    uint16_t sample_step;       /**< [1, 16] */
    uint16_t sample_col_step;   /**< [1, 16] */
    uint16_t eval_samples;      /**< [3, 65535] */
    uint16_t min_samples;       /**< [3, 65535] */
    uint16_t min_inliers;       /**< [3, 65535] */
    uint16_t fallback_sectors;  /**< [0, n_sectors] */
    uint32_t confidence_q16; /**< adaptive stop, Q16; [0, 65535], 0 = always ransac_iters (0.99 -> 64881) */
    uint32_t inlier_mm;      /**< (0, 5000] */
    uint32_t max_tilt_urad;  /**< (0, 1570796] */
    uint32_t max_height_dev_mm; /**< (0, 20000] */
    uint32_t ring_split_mm;     /**< [0, 500000], 0 = one plane per sector */
    uint32_t far_max_step_mm;   /**< [0, 5000]; > 0 with a split: a far plane is accepted when it meets its
                                     sector's near plane at the split within this step (the float stage's
                                     far_max_step_m), not by the sensor's height above it */
    uint32_t far2_split_mm;    /**< [0, 500000]; the third cells (lidet_ground_cfg_t far2_split_m) when beyond
                                     ring_split_mm; needs 3 n_sectors <= 2 LIDET_GROUND_MAX_SECTORS */
    uint32_t seed;             /**< xorshift32 seed (0 -> fixed non-zero) */
    uint32_t ground_mm;        /**< p_th, mm; (0, 5000] */
    uint32_t ground_per_m_q16; /**< p_th growth per metre of range (mm/mm), Q16; [0, 6554] */
    uint32_t below_factor_q16; /**< below tolerance = this * above, Q16; [0, 1310720] */
    uint32_t veto_slope_q16;   /**< vertical veto slope, Q16; [0, 6553600], 0 = off */
    uint32_t veto_min_dz_mm;   /**< [0, 5000] */
} lidet_ground_q_cfg_t;

/** @brief What lives across runs: configuration, tables from init, planes, sources, counts. */
typedef struct
{
    uint32_t magic;
    lidet_ground_q_cfg_t cfg;
    uint32_t rng;
    uint16_t n_rows, n_cols;
    int32_t cos_tilt_q30; /* cos(max_tilt), from init */
    uint32_t split_v;     /* far: x^2 + y^2 >= split_v (4 mm steps squared); UINT32_MAX: no split */
    uint32_t split2_v;    /* the third cells: x^2 + y^2 >= split2_v; UINT32_MAX: none */
    lidet_plane_q_t planes[2 * LIDET_GROUND_MAX_SECTORS]; /* near planes, then far planes */
    int64_t plane_d[2 * LIDET_GROUND_MAX_SECTORS]; /* D of each plane, 4 mm / 2^30 (the labels use it) */
    uint8_t source[2 * LIDET_GROUND_MAX_SECTORS];  /* lidet_ground_plane_source_t */
    lidet_ground_stats_t stats;
    uint32_t stream_lo, stream_hi,
        stream_total; /* a streamed run's sample buffer so far (the integer detector's
                                                    stream_sectors: lib/src/internal/lidet_ground_q_internal.h) */
} lidet_ground_q_state_t;

/** @brief Scratch of one run (only the sample mask is read after it, as a diagnostic). */
typedef struct
{
    uint8_t sample[LIDET_MAX_ROWS * LIDET_MAX_COLS];
    lidet_ground_sample_t sample_pix[LIDET_GROUND_MAX_SAMPLES];
    int16_t ev_x[LIDET_GROUND_EVAL_MAX], ev_y[LIDET_GROUND_EVAL_MAX], ev_z[LIDET_GROUND_EVAL_MAX];
    uint32_t cell_first[2 * LIDET_GROUND_MAX_SECTORS];
    uint32_t cell_n[2 * LIDET_GROUND_MAX_SECTORS];
    int32_t r_rows[2][LIDET_MAX_COLS]; /* R of two rows, 4 mm / 256 */
    union
    {
        uint32_t v[LIDET_MAX_COLS]; /* x^2 + y^2 and the square root's remainder of the row being computed */
        int16_t z[2][LIDET_MAX_COLS]; /* range-only image: the filter's two rows of z (decoded) */
    } r_v;
    uint32_t r_rem[LIDET_MAX_COLS];
} lidet_ground_q_scratch_t;

/** @brief The integer stage with every buffer inside. Declare it static (it is large). */
typedef struct
{
    lidet_ground_q_state_t state;
    uint8_t mask[LIDET_MAX_ROWS * LIDET_MAX_COLS];
    lidet_ground_q_scratch_t scratch;
} lidet_ground_q_t;

/**
 * @brief Defaults: the float defaults (lidet_ground_cfg_default) rounded, by the same two families.
 * @param[out] cfg             filled (NULL: no-op).
 * @param[in]  n_rows          the sensor's beams (<= 32: the low family).
 * @param[in]  mount_height_mm the sensor's mount height (< 1000: the low family).
 */
void lidet_ground_q_cfg_default(lidet_ground_q_cfg_t *cfg, uint32_t n_rows, int32_t mount_height_mm);

/** @brief Validate cfg, build the tables (cos of the tilt, split threshold), reset the state.
 *  @return LIDET_OK; LIDET_ERR_ARG (NULL); LIDET_ERR_BUFFER (n_sectors > LIDET_GROUND_MAX_SECTORS);
 *          LIDET_ERR_CONFIG (a value outside its range). */
lidet_status_t lidet_ground_q_state_init(lidet_ground_q_state_t *st, const lidet_ground_q_cfg_t *cfg);
lidet_status_t lidet_ground_q_init(lidet_ground_q_t *g, const lidet_ground_q_cfg_t *cfg);

/**
 * @brief Segment the ground of one compact range image (x_m NULL; x_4mm, y_4mm, z_4mm read, or decoded from
 *        range_4mm and the row elevations when all three are NULL: lib/src/internal/lidet_qpix.h; a pixel holds
 *        a point when x^2 + y^2 > 0, as the float stage's R > 0). mask may be scratch->sample (the sample mask
 *        is dead once the samples are gathered; the integer detector overlays them so).
 * @return LIDET_OK; LIDET_TRUNCATED (samples past LIDET_GROUND_MAX_SAMPLES, counted); LIDET_ERR_ARG (NULL, a
 *         float image, missing coordinates); LIDET_ERR_STATE; LIDET_ERR_BUFFER (image too large);
 *         LIDET_ERR_CONFIG (fewer than 4 columns or than n_sectors).
 */
lidet_status_t lidet_ground_q_run_buffers(lidet_ground_q_state_t *st, lidet_ground_q_scratch_t *scratch,
                                          uint8_t *mask, const lidet_range_image_t *img);
lidet_status_t lidet_ground_q_run(lidet_ground_q_t *g, const lidet_range_image_t *img);

/** @brief Views into g, valid until the next run/init: the ground mask, the sample mask (n_rows * n_cols bytes),
 *         the 2 * n_sectors planes (near, then far) and their sources, the counts. */
const uint8_t *lidet_ground_q_mask(const lidet_ground_q_t *g);
const uint8_t *lidet_ground_q_samples(const lidet_ground_q_t *g);
const lidet_plane_q_t *lidet_ground_q_planes(const lidet_ground_q_t *g, uint32_t *n_sectors);
const uint8_t *lidet_ground_q_sector_source(const lidet_ground_q_t *g);
const lidet_ground_stats_t *lidet_ground_q_stats(const lidet_ground_q_t *g);

/** @brief Per-point labels (as lidet_ground_point_labels_of). */
lidet_status_t lidet_ground_q_point_labels_of(const lidet_ground_q_state_t *st, const uint8_t *mask,
                                              const int32_t *point_pixel, uint32_t n_points, uint8_t *out);

#ifdef __cplusplus
}
#endif

#endif /* LIDET_GROUND_Q_H */
