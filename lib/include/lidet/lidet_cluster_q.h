/* SPDX-License-Identifier: MIT */
/**
 * @file lidet_cluster_q.h
 * @brief The integer clustering and proposals (docs/FIXED_POINT.md): lidet_cluster.h's depth clustering on a
 *        compact range image (int16 x, y, z and uint16 range in 4 mm steps), with integers only.
 *
 * Same algorithm, control flow and outputs as lidet_cluster.h (the flood fill, the rescue window walk, the
 * filters and records, the capacity and the canonical ids are the same source, internal/lidet_cluster_*_body.h);
 * the numeric kernels:
 *  - join test beta > theta: with d1 >= d2 the two ranges (4 mm steps) and alpha the angle of the two beams,
 *    d2 sin(alpha + theta) > d1 sin(theta) (the float stage's d2 sin a > tan(theta) (d1 - d2 cos a) multiplied
 *    by cos(theta): the law of sines), both sides uint32: S = sin(alpha + theta) (Q16, clamped at 0: a
 *    negative one fails) is a table built at init from the beams' BAM32 angles (img->row_elev_bam, the column
 *    step k 2^32 / n_cols, the diagonal pairs) with qmath sin/cos/atan2/isqrt; d <= 65535, S <= 65536;
 *  - gap bound: the distance of the two returns along their beams squared, (d1 - d2)^2 + d1 d2 H with
 *    H = 4 sin^2(alpha / 2) (Q30 table; = (d1 - d2 cos a)^2 + (d2 sin a)^2), against
 *    (gap + gap_per_m d2)^2, in uint64 (no square root); a range difference above the bound rejects first;
 *  - rescue distance: the squared 3D distance of the two pixels' int16 coordinates against
 *    (rescue_gap + rescue_gap_per_m min(d1, d2))^2 in uint32 (each |difference| is tested against the bound
 *    first); pixels whose ranges differ by more than the bound are not looked at;
 *  - records: member sums in int64; mean = sum / n rounded half away from zero; min, max; height = the
 *    mean's height above the plane of the seed's sector (lidet_plane_q_t: (n . mean >> 30, rounded) + d_4mm),
 *    or mean z + round(mount_height_mm / 4) without planes. A rescue group that joins a cluster adds its sums
 *    (the mean is the rounded mean of all members, exactly). Filters: extent (max - min) * 4 > max_extent_mm,
 *    height * 4 > max_mean_height_mm.
 *  - worst-case budgets (issue 19) as the float stage's: the rescue takes fragments while their pixels sum to at
 *    most max_fragment_pixels (n_dropped_fragment_budget), a pixel's searches bridge occluders while the run's
 *    count is below (max_bridge_per_pixel_q16 * candidates) >> 16 (n_bridge_steps);
 *  - refinement (split_people, join_cars; the rules of lidet_cluster.h, the control flow shared with the float
 *    stage in internal/lidet_refine_body.h), lib/src/cluster/lidet_refine_q.c: spans compared in mm (4 times
 *    the 4 mm span); cell = split_cell_mm + round(split_cell_per_m_q16 r_mm / 2^16), r_mm = max(|cx|, |cy|) +
 *    min(|cx|, |cy|) / 2 of the box centre (floored); a member's cell floor(4 (x - lo) / cell) by one product with
 *    ceil(2^40 / cell) and a shift (exact); person aspect wz 2^16 >= person_min_aspect_q16 max(wx, wy); joins:
 *    (4 gx)^2 + (4 gy)^2 > join_gap_mm^2 rejects, in uint64; records from int64 member sums (a join adds the
 *    joined cluster's sums: the mean stays the rounded mean of all members).
 * Per point: no division, no square root; one 32x32 -> 64 bit product per gap test. Tables: sin/cos/atan2/
 * isqrt at init (recomputed when the image geometry changes). The numpy reference is
 * codegen/lidet_ref/cluster_q.py (bit for bit).
 *
 * Proposals (lidet_proposal_q_make): the same resampled member indices as lidet_proposal_make
 * (lidet_proposal_indices), points minus the record's rounded mean (4 mm, int16, saturating), and the mean's
 * voxel: floor(atan2(y, x) / az_bin), floor(atan2(z, round(sqrt(x^2 + y^2))) / el_bin) (BAM32 angles and bins),
 * floor(round(sqrt(x^2 + y^2 + z^2)) / range_bin) (4 mm), clamped to int16.
 *
 * Memory: as lidet_cluster.h (uint16 label + int32 member per pixel) plus the records (56 B) and their sums
 * (24 B) per cluster slot and the refinement's scratch (as lidet_cluster.h's); lidet_cluster_q_bytes().
 */
#ifndef LIDET_CLUSTER_Q_H
#define LIDET_CLUSTER_Q_H

#include "lidet_cluster_stats.h"
#include "lidet_image.h"
#include "lidet_q.h"
#include "lidet_types.h"

#ifdef __cplusplus
extern "C" {
#endif

/** @brief Configuration of the integer clustering: lidet_cluster_cfg_t in integer units. Defaults
 *         (lidet_cluster_q_cfg_default) are the float defaults rounded. */
typedef struct
{
    uint32_t theta_urad;        /**< theta, microradians, (0, 1500000); default 180000 (> 16 beams), 120000 */
    uint32_t max_steps;         /**< [1, LIDET_CLUSTER_MAX_STEPS]; default 5 */
    uint32_t bridge_occluders;  /**< 0/1; default 1 (> 16 beams), 0 */
    uint32_t diagonals;         /**< 0/1; default 1 */
    uint32_t max_gap_mm;        /**< 0: angle test alone; <= 1000000; default 700 */
    uint32_t max_gap_per_m_q16; /**< growth per metre of range (Q16 ratio), <= 65536; default 1638 (0.025,
                                        > 16 beams), 2621 (0.04) */
    uint32_t min_points;        /**< >= 1; default 8 (as the float build) */
    uint32_t max_extent_mm;     /**< (0, 1000000]; default 6000 */
    int32_t max_mean_height_mm; /**< default 2500; INT32_MAX disables the filter */
    uint32_t mount_height_mm;   /**< flat ground at -mount when no planes; <= 100000 */
    uint32_t rescue_gap_mm;     /**< 0 disables the rescue; <= 10000; default 800 (> 16 rows), 1000 (<= 16) */
    uint32_t rescue_gap_per_m_q16; /**< <= 16384 (0.25 per metre); default 1966 (0.03) */
    uint32_t rescue_rows;          /**< <= LIDET_MAX_ROWS; default 1 (<= 16 beams), 2 */
    uint32_t rescue_cols;          /**< <= 15; default 6 */
    /* worst-case bounds (issue 19): lidet_cluster_cfg_t's, same semantics */
    uint32_t max_fragment_pixels; /**< rescue budget in fragment pixels (0 = none); default 4096 (> 16 beams),
                                        2048 */
    uint32_t
        max_bridge_per_pixel_q16; /**< occluder bridging budget per candidate pixel, Q16, <= 64 << 16 (0 =
                                        none); the run bridges while its count is below
                                        (this * candidates) >> 16; default 131072 (2.0) */
    /* the proposal refinement (lidet_refine.c's rules in integer units; lidet_cluster_cfg_t's defaults rounded) */
    uint32_t split_people;          /**< 0/1; default 1 */
    uint32_t split_min_width_mm;    /**< (0, 1000000]; default 700 */
    uint32_t split_cell_mm;         /**< (0, 100000]; default 120 */
    uint32_t split_cell_per_m_q16;  /**< <= 65536; default 0 */
    uint32_t person_max_width_mm;   /**< (0, 1000000]; default 1000 */
    uint32_t person_min_height_mm;  /**< <= 1000000; default 900 */
    uint32_t person_min_aspect_q16; /**< <= 100 << 16; default 117965 (1.8) */
    uint32_t person_min_cols;       /**< default 2 */
    uint32_t person_min_points;     /**< [1, 1000000]; default 10 (> 16 rows), 9 (<= 16 rows) */
    uint32_t join_cars;             /**< 0/1; default 1 */
    uint32_t join_gap_mm;           /**< <= 1000000; default 500 (> 16 rows), 800 (<= 16 rows) */
    uint32_t car_max_length_mm;     /**< (0, 1000000]; default 5200 */
    uint32_t car_max_width_mm;      /**< (0, 1000000]; default 2200 */
    uint32_t car_max_height_mm;     /**< (0, 1000000]; default 2000 */
    uint32_t car_min_length_mm;     /**< <= 1000000; default 2500 */
    uint32_t upright_max_width_mm;  /**< <= 1000000; default 1300 */
    uint32_t max_join_pieces;       /**< join budget as lidet_cluster_cfg_t's; 0 = no limit; default 256 */
    /* the regrowth of over-extent components (lidet_cluster_cfg_t regrow_gap_m, regrow_gap_per_m) */
    uint32_t regrow_gap_mm;        /**< 0 = off (dropped); <= 100000; default 350 (> 16 rows), 0 (<= 16) */
    uint32_t regrow_gap_per_m_q16; /**< <= 65536; default 1311 (0.02), 0 (<= 16 rows) */
    uint32_t regrow_max_pixels;    /**< as lidet_cluster_cfg_t's; 0 = no limit */
    uint32_t regrow_max_height_mm; /**< as lidet_cluster_cfg_t's regrow_max_height_m; (0, 100000] */
    uint32_t regrow_cut_mm;        /**< as lidet_cluster_cfg_t's regrow_cut_m; [0, 2000] */
    uint32_t
        plane_split_mm; /**< lidet_cluster_cfg_t's plane_split_m: > 0, planes holds 2 n_sectors planes and
                                        a mean with 16 (x^2 + y^2) >= plane_split_mm^2 takes its sector's far plane;
                                        <= 500000; default 0 (lidet_detector_q sets the ground's ring_split_mm) */
} lidet_cluster_q_cfg_t;

/** @brief One kept cluster, 4 mm steps. */
typedef struct
{
    uint32_t n_points;     /**< member pixels */
    uint32_t first_member; /**< index of its first member in the member array */
    uint32_t seed_pixel;   /**< its first pixel in raster order */
    uint32_t n_rescued;    /**< member pixels that came from fragments */
    int32_t mean_4mm[3];   /**< mean of the members, rounded half away from zero */
    int32_t min_4mm[3];    /**< axis-aligned bounds */
    int32_t max_4mm[3];
    int32_t height_4mm; /**< the mean's height above the ground plane used by the filter */
} lidet_cluster_q_rec_t;

/** @brief State of the integer clustering (configuration, tables, records of the last run). */
typedef struct
{
    uint32_t magic;
    lidet_cluster_q_cfg_t cfg;
    uint32_t sin_theta_q16; /* sin(theta), Q16 */
    int32_t theta_bam;
    /* derived from the image's geometry on the first run (and when it changes): S = sin(alpha + theta) Q16
     * (clamped at 0), H = 4 sin^2(alpha / 2) Q30 (saturated), same layout as the float stage's sin/cos */
    uint16_t geo_rows, geo_cols;
    uint32_t
        geo_row_m26; /* a pixel's row as (p m) >> 26 on cores without a divide (lidet_qpix.h), 0: p / cols */
    int32_t geo_elev_bam[LIDET_MAX_ROWS];
    uint32_t col_s[LIDET_CLUSTER_MAX_STEPS], col_h[LIDET_CLUSTER_MAX_STEPS];
    uint32_t row_s[LIDET_MAX_ROWS * LIDET_CLUSTER_MAX_STEPS];
    uint32_t row_h[LIDET_MAX_ROWS * LIDET_CLUSTER_MAX_STEPS];
    uint32_t diag_s[LIDET_MAX_ROWS], diag_h[LIDET_MAX_ROWS];
    /* outputs of the last run */
    lidet_cluster_q_rec_t recs[LIDET_MAX_CLUSTERS];
    int64_t sums[LIDET_MAX_CLUSTERS][3];      /* scratch: member sums per slot during a run */
    uint16_t order[LIDET_MAX_CLUSTERS];       /* scratch: slots in seed order */
    uint16_t slot_id[LIDET_MAX_CLUSTERS + 1]; /* scratch: slot + 1 -> canonical id */
    lidet_range_image_t img;                  /* the image of the last run (a view) */
    uint16_t *labels;
    lidet_member_t *members;
    uint32_t n_recs;
    lidet_cluster_stats_t stats;
    /* scratch of the refinement (lidet_refine_q.c; as lidet_cluster_state_t's, z in 4 mm steps) */
    uint16_t rf_grid[LIDET_REFINE_MAX_CELLS];
    uint16_t rf_queue[LIDET_REFINE_MAX_CELLS];
    uint16_t rf_cell[LIDET_REFINE_MAX_POINTS];
    uint16_t rf_target[LIDET_REFINE_MAX_PARTS];
    uint32_t rf_n[LIDET_REFINE_MAX_PARTS];
    uint16_t rf_box[LIDET_REFINE_MAX_PARTS][4];
    int32_t rf_z[LIDET_REFINE_MAX_PARTS][2];
    uint16_t rf_col[LIDET_REFINE_MAX_PARTS][2];
} lidet_cluster_q_state_t;

/** @brief The integer clustering with its per-pixel buffers (declare it static). */
typedef struct
{
    lidet_cluster_q_state_t state;
    uint16_t labels[LIDET_MAX_ROWS * LIDET_MAX_COLS];
    lidet_member_t members[LIDET_MAX_ROWS * LIDET_MAX_COLS];
} lidet_cluster_q_t;

/**
 * @brief Default configuration (the float defaults of lidet_cluster_cfg_default rounded).
 * @param n_rows           the sensor's beams (<= 16 picks the sparse-sensor values).
 * @param mount_height_mm  copied.
 */
void lidet_cluster_q_cfg_default(lidet_cluster_q_cfg_t *cfg, uint32_t n_rows, uint32_t mount_height_mm);

/** @return LIDET_OK; LIDET_ERR_ARG (NULL); LIDET_ERR_CONFIG (a field outside its documented range). */
lidet_status_t lidet_cluster_q_state_init(lidet_cluster_q_state_t *st, const lidet_cluster_q_cfg_t *cfg);

/** @brief lidet_cluster_q_state_init on the standalone form. */
lidet_status_t lidet_cluster_q_init(lidet_cluster_q_t *c, const lidet_cluster_q_cfg_t *cfg);

/**
 * @brief Cluster one compact range image into caller-placed buffers.
 * @param labels   n_rows * n_cols uint16: canonical ids out (0 = none).
 * @param members  n_rows * n_cols int32: member pixels out, cluster after cluster, raster order.
 * @param img      a compact image (x_m NULL; x_4mm, y_4mm, z_4mm, range_4mm set) with row_elev_bam.
 * @param ground_mask  n_rows * n_cols bytes, 1 = ground, or NULL.
 * @param planes   n_sectors planes (sector of column c = c * n_sectors / n_cols) or NULL (flat ground).
 * @return LIDET_OK; LIDET_TRUNCATED (capacity drops, counted); LIDET_ERR_ARG (NULL, planes with n_sectors 0,
 *         a float image, row_elev_bam NULL, an incomplete image); LIDET_ERR_BUFFER (image size);
 *         LIDET_ERR_STATE (not initialised).
 */
lidet_status_t lidet_cluster_q_run_buffers(lidet_cluster_q_state_t *st, uint16_t *labels,
                                           lidet_member_t *members, const lidet_range_image_t *img,
                                           const uint8_t *ground_mask, const lidet_plane_q_t *planes,
                                           uint32_t n_sectors);

/** @brief lidet_cluster_q_run_buffers on the standalone form's buffers. */
lidet_status_t lidet_cluster_q_run(lidet_cluster_q_t *c, const lidet_range_image_t *img,
                                   const uint8_t *ground_mask, const lidet_plane_q_t *planes,
                                   uint32_t n_sectors);

/** @brief Cluster id of every input point (point_pixel -1 or outside the image -> 0); as
 *         lidet_cluster_point_labels. @return LIDET_OK; LIDET_ERR_ARG; LIDET_ERR_STATE (never run). */
lidet_status_t lidet_cluster_q_point_labels(const lidet_cluster_q_state_t *st, const int32_t *point_pixel,
                                            uint32_t n_points, uint32_t *out);

/** @brief sizeof(lidet_cluster_q_t). */
uint32_t lidet_cluster_q_bytes(void);

/** @brief How integer proposals are built (lidet_proposal_cfg_t in integer units). */
typedef struct
{
    uint32_t n_points;          /**< [1, LIDET_PROPOSAL_POINTS]; default 64 (or the capacity) */
    uint32_t seed;              /**< default 0x5EED1234 */
    uint32_t azimuth_bin_bam;   /**< (0, 2^31]; default 119304647 (10 deg) */
    uint32_t elevation_bin_bam; /**< (0, 2^31]; default 119304647 */
    uint32_t range_bin_4mm;     /**< >= 1; default 250 (1 m) */
    uint32_t z_origin; /**< lidet_proposal_z_origin_t; default LIDET_PROPOSAL_Z_MEAN (the detector sets
                                     the models') */
} lidet_proposal_q_cfg_t;

/** @brief Default integer proposal configuration (the float defaults rounded). */
void lidet_proposal_q_cfg_default(lidet_proposal_q_cfg_t *cfg);

/**
 * @brief The proposal of kept cluster `cluster_index` of the state's last run (its image must be unchanged).
 * @return LIDET_OK; LIDET_ERR_ARG (NULL, index out of range); LIDET_ERR_CONFIG; LIDET_ERR_STATE (never run).
 */
lidet_status_t lidet_proposal_q_make(const lidet_cluster_q_state_t *st, uint32_t cluster_index,
                                     const lidet_proposal_q_cfg_t *cfg, lidet_proposal_q_t *out);

#ifdef __cplusplus
}
#endif

#endif /* LIDET_CLUSTER_Q_H */
