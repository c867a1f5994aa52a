/* SPDX-License-Identifier: MIT */
/**
 * @file lidet_workspace.h
 * @brief The detector workspace: projection -> ground -> clustering (-> proposals) on one object
 *        whose size is the peak of the stages' memory, not the sum (the future lidet_detector_t
 *        grows from it when the PointNets land).
 *
 * Memory model. Every stage's memory is split three ways:
 *  - state (lidet_proj_state_t, lidet_ground_state_t, lidet_cluster_state_t): configuration, the
 *    tables derived in init, the small outputs (planes, cluster records) and the counts. Lives across
 *    runs; no per-pixel array.
 *  - outputs a later stage (or the caller) still reads: the image's x, y, z and range (read up to the
 *    proposals), the ground mask (read by the clustering, and a result), the cluster labels and
 *    members (read by the proposals).
 *  - scratch, alive only during its own stage's run: the projection's winning point per pixel; the
 *    ground stage's R image, sample mask and samples.
 * Stages run one after the other, so the workspace overlays (a union) the projection's scratch, the
 * ground stage's scratch and the clustering's outputs, none of which is alive while another is.
 * What the workspace does not keep, by design (a firmware that wants boxes pays for none of it):
 *  - R = sqrt(x^2 + y^2) per pixel (unless LIDET_WORKSPACE_KEEP_R, the default on 64-bit targets with more
 *    than 65536 pixels: lidet_opt.h): the ground stage recomputes it row by row (two rows of scratch), from the
 *    decoded coordinates, with the expression the projection uses when it keeps R (the same bits);
 *  - the winning point's index per pixel (point_idx): scratch of the projection; validity is range > 0;
 *  - per-point outputs (the pixel of every input point, 4 B per point): only when the caller passes
 *    a buffer of LIDET_MAX_POINTS entries to lidet_workspace_run; per-point labels are then derived
 *    from it (lidet_workspace_point_labels).
 * The image is compact (8 B per pixel instead of 16): x, y, z as int16 and the range as uint16, all in
 * 4 mm steps (lidet_range_image_t, LIDET_PIXEL_M), the real point's coordinates rounded, which the ground
 * filter, the cluster statistics and the proposals decode where they read them. Points beyond
 * LIDET_PIXEL_MAX_RANGE_M (131 m, the int16 span) are dropped by the projection and counted as too far.
 * Results are those of the stages chained by hand on that compact image, bit for bit, and differ from
 * the float stages by the rounding only: the clustering alone agrees on >= 99.9 % of the pixels; the
 * ground stage's RANSAC, fed a sample more or less, moves a plane as another seed would (measured in
 * docs/MEMORY.md, asserted in tests/unit/test_workspace.c).
 *
 * Bytes (lidet_workspace_sizes reports each part): states ~ LIDET_MAX_COLS * 12 B + LIDET_PROJ_ROW_LUT B
 * + LIDET_MAX_CLUSTERS * 60 B + LIDET_GROUND_MAX_SECTORS * 34 B; per pixel 9 B (x, y, z, range, ground
 * mask) + the overlay, the largest of 4 B (projection), 1 B + (LIDET_GROUND_MAX_SAMPLES / pixels) * 4 B
 * + 24 B per column (ground) and 6 B (clustering). Declare it static, or place it with the port's section
 * macro
 * (LIDET_WORKSPACE_SECTION, lidet_port.h).
 * Time: the sum of the three stages, plus two passes over the pixels for R (vectorised). No allocation.
 */
#ifndef LIDET_WORKSPACE_H
#define LIDET_WORKSPACE_H

#include "lidet_cluster.h"
#include "lidet_detector_common.h" /* lidet_clock_fn */
#include "lidet_ground.h"
#include "lidet_proj.h"
#include "lidet_sensor.h"
#include "lidet_types.h"

#ifdef __cplusplus
extern "C" {
#endif

#define LIDET__WS_PIXELS (LIDET_MAX_ROWS * LIDET_MAX_COLS)

/* x86-64 hosts: a gap before the overlay, so that a pixel's cluster label lies about 2 KiB (modulo 4 KiB) from
 * its range. The flood fill writes labels and reads the ranges and labels of the pixels around (one row up or
 * down: 2 B x cols apart); with the planes a multiple of 4 KiB apart (every image of a power-of-two size, e.g.
 * 64 x 2048) an x86 core takes a load after such a store for a possible dependence on it (4K aliasing) and
 * waits. Measured (lidet_bench_memory, HDL-64 samples and the 11 real KITTI scans): the workspace's clustering
 * 2-5 % faster with the gap. Derived from the target alone (never from a user macro), so the library and its
 * callers agree on the layout; other targets have no gap (their cores do not pay for it). */
#if defined(__x86_64__) || defined(_M_X64)
#define LIDET__WS_ALIAS_GAP                                                                                  \
    (64u + (6144u - ((3u + 4u * LIDET_WORKSPACE_KEEP_R + (uint32_t)sizeof(lidet_member_t)) *                 \
                     (uint32_t)LIDET__WS_PIXELS) %                                                           \
                        4096u) %                                                                             \
               4096u)
#endif

/** @brief Configuration of every stage the workspace runs. Fill with lidet_workspace_cfg_default(). */
typedef struct
{
    lidet_proj_cfg_t proj;
    lidet_ground_cfg_t ground;
    lidet_cluster_cfg_t cluster;
} lidet_workspace_cfg_t;

/** @brief Counts of the last run of each stage. */
typedef struct
{
    lidet_proj_stats_t proj;
    lidet_ground_stats_t ground;
    lidet_cluster_stats_t cluster;
} lidet_workspace_stats_t;

/** @brief The workspace. Caller-owned, fixed size (sizeof = lidet_workspace_bytes()). Fields are
 *         public only so that sizeof works; read results through the functions below. */
typedef struct
{
    uint32_t magic;
    lidet_proj_state_t proj;
    lidet_ground_state_t ground;
    lidet_cluster_state_t cluster;
    /* outputs read up to the end of the scan: the compact image (4 mm steps, see lidet_range_image_t) */
    int16_t x_4mm[LIDET__WS_PIXELS];
    int16_t y_4mm[LIDET__WS_PIXELS];
    int16_t z_4mm[LIDET__WS_PIXELS];
    uint16_t range_4mm[LIDET__WS_PIXELS];
    uint8_t ground_mask[LIDET__WS_PIXELS];
#if LIDET_WORKSPACE_KEEP_R
    /* R of each pixel's decoded x, y (LIDET_WORKSPACE_KEEP_R: 64-bit targets, large images; lidet_opt.h), read by
     * the ground stage alone; then, on x86-64 hosts with AVX-512, the clustering's edge plane: every candidate's
     * searches decided before its flood fill, sixteen pixels at a time (lidet_cluster_grow.c; the same clusters,
     * found faster) */
    union
    {
        float rxy_m[LIDET__WS_PIXELS];
        uint32_t edges[LIDET__WS_PIXELS];
    } r;
#endif
#ifdef LIDET__WS_ALIAS_GAP
    uint8_t alias_gap[LIDET__WS_ALIAS_GAP]; /* never read or written: see LIDET__WS_ALIAS_GAP */
#endif
    /* one of these is alive at a time */
    union
    {
        int32_t proj_point_idx[LIDET__WS_PIXELS]; /* projection: winning point per pixel */
        lidet_ground_scratch_t ground;            /* sample mask, samples, two rows of R */
        struct
        {
            lidet_member_t members[LIDET__WS_PIXELS]; /* clustering outputs, read by the proposals */
            uint16_t labels[LIDET__WS_PIXELS];
        } cluster;
    } overlay;
} lidet_workspace_t;

/** @brief Sizes in bytes of the parts of lidet_workspace_t (this build's capacities). */
typedef struct
{
    uint32_t proj_state, ground_state, cluster_state; /**< the three states (tables, small outputs) */
    /** x, y, z, range planes (int16, 4 mm steps), and R (float) with LIDET_WORKSPACE_KEEP_R */
    uint32_t image;
    uint32_t ground_mask;       /**< the ground mask */
    uint32_t overlay_proj;      /**< projection scratch (point_idx) */
    uint32_t overlay_ground;    /**< ground scratch (sample mask, samples, two rows of R) */
    uint32_t overlay_cluster;   /**< cluster labels and members */
    uint32_t overlay;           /**< the overlay: the largest of the three */
    uint32_t alias_gap;         /**< x86-64 hosts: the gap before the overlay (LIDET__WS_ALIAS_GAP), else 0 */
    uint32_t total;             /**< sizeof(lidet_workspace_t) */
    uint32_t stages_standalone; /**< lidet_proj_bytes() + lidet_ground_bytes() +
                                                           lidet_cluster_bytes(), for comparison */
} lidet_workspace_sizes_t;

/**
 * @brief Defaults of every stage for a sensor (each stage's own cfg_default).
 * @param[out] cfg    filled (NULL: no-op).
 * @param[in]  sensor profile (copied into cfg->proj.sensor); NULL leaves the sensor zeroed.
 */
void lidet_workspace_cfg_default(lidet_workspace_cfg_t *cfg, const lidet_sensor_t *sensor);

/**
 * @brief Initialise every stage (each stage's init, in pipeline order). No allocation.
 * @return LIDET_OK or the first failing stage's error (LIDET_ERR_ARG, _CONFIG, _BUFFER).
 */
lidet_status_t lidet_workspace_init(lidet_workspace_t *ws, const lidet_workspace_cfg_t *cfg);

/**
 * @brief Projection, ground segmentation and clustering of one scan: the standalone stages chained by
 *        hand (the cluster height filter reads the ground stage's near planes), on the compact image
 *        (the same results up to the 4 mm rounding of the pixels; points beyond 131 m dropped).
 * @param[in,out] ws          initialised workspace; every result of the previous scan is overwritten.
 * @param[in]     points      n_points records of `stride` floats (x, y, z first); read only during
 *                            this call (the workspace keeps the winners' coordinates).
 * @param[in]     ring        optional per-point ring index, or NULL (as lidet_proj_run).
 * @param[out]    point_pixel optional: LIDET_MAX_POINTS int32, the pixel of each input point (-1 =
 *                            not projected), needed only for per-point labels; NULL = not produced.
 * @return LIDET_OK; LIDET_TRUNCATED when a stage truncated (stats say which); the first error of a
 *         stage (LIDET_ERR_ARG, _STATE, _BUFFER, _CONFIG): later stages then did not run.
 */
lidet_status_t lidet_workspace_run(lidet_workspace_t *ws, const float *points, uint32_t n_points,
                                   uint32_t stride, const uint16_t *ring, int32_t *point_pixel);

/**
 * @brief lidet_workspace_run with per-stage timing: ticks[0..2] receive the clock differences around the
 *        projection, the ground stage and the clustering (0 for a stage that did not run). clock may be
 *        NULL (no timing; ticks, if given, are zeroed); ticks may be NULL. Same results as lidet_workspace_run.
 */
lidet_status_t lidet_workspace_run_timed(lidet_workspace_t *ws, const float *points, uint32_t n_points,
                                         uint32_t stride, const uint16_t *ring, int32_t *point_pixel,
                                         lidet_clock_fn clock, void *clock_ctx, uint32_t ticks[3]);

/** @brief The range image of the last run: a compact image (x_m ... range_m, rxy_m and point_idx NULL: R and the
 *         winners are scratch of the stages; x_4mm, y_4mm, z_4mm, range_4mm set: decode as value * LIDET_PIXEL_M
 *         metres). */
void lidet_workspace_image(const lidet_workspace_t *ws, lidet_range_image_t *img);

/** @brief Ground mask of the last run (n_rows * n_cols bytes, 1 = ground). */
const uint8_t *lidet_workspace_ground_mask(const lidet_workspace_t *ws);

/** @brief Ground planes of the last run (near then far, as lidet_ground_planes). */
const lidet_plane_t *lidet_workspace_planes(const lidet_workspace_t *ws, uint32_t *n_sectors);

/** @brief Kept clusters of the last run (as lidet_cluster_records). */
const lidet_cluster_rec_t *lidet_workspace_clusters(const lidet_workspace_t *ws, uint32_t *n_clusters);

/** @brief Per-pixel cluster ids of the last run (as lidet_cluster_labels). */
const uint16_t *lidet_workspace_labels(const lidet_workspace_t *ws);

/** @brief Member pixels of the last run (as lidet_cluster_members). */
const lidet_member_t *lidet_workspace_members(const lidet_workspace_t *ws);

/** @brief The proposal of kept cluster `cluster_index` of the last run (as lidet_proposal_make). */
lidet_status_t lidet_workspace_proposal(const lidet_workspace_t *ws, uint32_t cluster_index,
                                        const lidet_proposal_cfg_t *cfg, lidet_proposal_t *out);

/**
 * @brief Per-point labels from the point_pixel buffer the last run filled.
 * @param[in]  point_pixel the buffer passed to lidet_workspace_run, n_points entries.
 * @param[out] cluster_id  n_points cluster ids (0 = none), or NULL.
 * @param[out] ground      n_points bytes (1 = ground), or NULL.
 * @return LIDET_OK; LIDET_ERR_ARG (NULL ws or point_pixel with n_points > 0); LIDET_ERR_STATE (never run).
 */
lidet_status_t lidet_workspace_point_labels(const lidet_workspace_t *ws, const int32_t *point_pixel,
                                            uint32_t n_points, uint32_t *cluster_id, uint8_t *ground);

/** @brief Counts of the last run of each stage (copied). */
void lidet_workspace_stats(const lidet_workspace_t *ws, lidet_workspace_stats_t *out);

/** @brief sizeof(lidet_workspace_t): the bytes firmware must place. */
uint32_t lidet_workspace_bytes(void);

/** @brief The size of every part of the workspace (sizeof of each member; nothing is estimated). */
void lidet_workspace_sizes(lidet_workspace_sizes_t *out);

#ifdef __cplusplus
}
#endif

#endif /* LIDET_WORKSPACE_H */
