/* SPDX-License-Identifier: MIT */
/**
 * @file lidet_detector_q.h
 * @brief The integer path's detections and their post-processing: the class size check, the rotated BEV IoU
 *        and the NMS, in integers only (lidet_q.h units; docs/FIXED_POINT.md).
 *
 * The same rules as the float detector (lidet_detector.h): a box whose l, w, h leave its class's plausible
 * range is dropped; detections are ordered by score (best first, ties by the lower cluster id) and one is
 * kept unless its BEV IoU with a kept one exceeds the threshold. The IoU: both boxes' corners in millimetres
 * relative to the first box's centre (Q30 sin/cos of the BAM32 yaw, rounded), Sutherland-Hodgman clipping with
 * int64 cross products (intersection points rounded to the millimetre), twice the areas by the shoelace
 * formula, IoU = 2 A_inter * 2^15 / (2 A_a + 2 A_b - 2 A_inter) rounded down. Mirrored bit for bit by
 * codegen/lidet_ref/post_q.py.
 */
#ifndef LIDET_DETECTOR_Q_H
#define LIDET_DETECTOR_Q_H

#include "lidet_cluster_q.h"
#include "lidet_detector_common.h" /* lidet_clock_fn, stage indices, outcomes */
#include "lidet_ground_q.h"
#include "lidet_image.h"
#include "lidet_pointnet_q.h"
#include "lidet_proj_q.h"
#include "lidet_q.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Box sizes the size check and the IoU accept: l, w, h in [1, LIDET_Q_BOX_MAX_MM] mm. */
#define LIDET_Q_BOX_MAX_MM 50000

/** @brief One detection of the integer path. */
typedef struct
{
    lidet_box_q_t box;      /**< sensor frame, mm, BAM32 yaw */
    int32_t score_q15;      /**< (0, 32768) */
    int32_t energy_cls_q16; /**< classifier energy (gate 1), Q16 nats */
    int32_t energy_box_q16; /**< box net energy (gate 2), Q16 nats */
    uint16_t cluster_id;    /**< 1-based id of the cluster it came from */
    uint8_t cls;            /**< lidet_class_t */
    uint8_t reserved;
    uint32_t n_points; /**< member points of that cluster (of its part, for a group split's detection) */
} lidet_detection_q_t;

/** @brief Plausible sizes per class (lidet_class_t order), l, w, h in mm. */
typedef struct
{
    int32_t min_mm[LIDET_N_CLASSES][3];
    int32_t max_mm[LIDET_N_CLASSES][3];
} lidet_size_limits_q_t;

/** @brief The default limits: the float detector's (docs/DETECTOR.md) in mm. */
void lidet_size_limits_q_default(lidet_size_limits_q_t *lim);

/** @brief 1 when box b's l, w, h lie within class cls's limits (bounds included), else 0 (also for NULL, a bad
 *         class or a size outside [1, LIDET_Q_BOX_MAX_MM]). */
int lidet_size_ok_q(const lidet_size_limits_q_t *lim, uint32_t cls, const lidet_box_q_t *b);

/**
 * @brief Rotated bird's-eye-view IoU of two boxes, Q15 (32768 = 1.0).
 * @return 0 for NULL boxes, sizes outside [1, LIDET_Q_BOX_MAX_MM], centres farther apart than both boxes'
 *         half diagonals or more than 2^20 mm apart, or no overlap.
 */
int32_t lidet_box_q_bev_iou(const lidet_box_q_t *a, const lidet_box_q_t *b);

/** @brief Insert det[n] into det[0..n), kept sorted by score (best first, ties: lower cluster id first). */
void lidet_detections_q_insert(lidet_detection_q_t *det, uint32_t n);

/**
 * @brief Greedy NMS over det[0..n) sorted by lidet_detections_q_insert: keeps a detection unless its BEV IoU
 *        with an already kept one is > iou_q15; between two detections of one cluster_id (the parts of one
 *        group cut) the bound is the larger of iou_q15 and 8192 (0.25). The kept ones move to the front in order.
 * @param[out] suppressed optional (NULL): 1 per input detection that was dropped, else 0 (input order).
 * @return the number kept; 0 for NULL det.
 */
uint32_t lidet_detections_q_nms(lidet_detection_q_t *det, uint32_t n, int32_t iou_q15, uint8_t *suppressed);

/* ---- the integer detector ------------------------------------------------------------------------- */

/** @brief Configuration of the integer detector. Fill with lidet_detector_q_cfg_default(). */
typedef struct
{
    lidet_proj_q_cfg_t proj;         /**< projection (holds the sensor) */
    lidet_ground_q_cfg_t ground;     /**< ground segmentation */
    lidet_cluster_q_cfg_t cluster;   /**< clustering */
    lidet_proposal_q_cfg_t proposal; /**< n_points is set from the models by init; seed and PVLE bins used */
    int32_t crop_half_bam;           /**< 0: 360 degrees; else keep clusters with |azimuth| <= this (BAM32;
                                          the KITTI camera field of view is 2^29); [0, 2^31 - 1]. A crop also
                                          sets ground.seed_per_cell (a RANSAC stream per ground cell, as the
                                          float detector's crop) */
    int32_t max_range_mm;         /**< clusters whose mean is farther (horizontally) are not classified; 0 =
                                          no limit; >= 0 */
    int32_t max_height_extent_mm; /**< clusters spanning more than this in z are not classified (outcome
                                          LIDET_DET_OUT_TALL); 0 = no limit; [0, 100000]; default 2500 */
    uint32_t max_proposals;       /**< [1, LIDET_MAX_CLUSTERS]: at most this many classified, nearest first */
    uint32_t max_boxes;           /**< [1, LIDET_MAX_CLUSTERS]: at most this many through the box net per scan
                                          (those passing gate 1, nearest first; the rest: outcome
                                          LIDET_DET_OUT_BUDGET, stats n_over_box_budget, LIDET_TRUNCATED); default
                                          48 (> 16 beams), 24: the float detector's max_boxes */
    uint8_t range_only;           /**< 1: the image stores only the range per pixel, x, y, z are decoded from
                                   row, column and range (lib/src/internal/lidet_qpix.h); default
                                   !LIDET_Q_PIXEL_XYZ; must be 1 when LIDET_Q_PIXEL_XYZ is 0 */
    uint8_t stream_sectors; /**< 1: a streamed scan (lidet_detector_q_stream_*) runs the ground stage on each
                                       sector of the image as soon as the stream has moved past it, so stream_end
                                       has less left to do; needs range_only 1 (LIDET_ERR_CONFIG otherwise) and
                                       sets ground.seed_per_cell (a RANSAC stream per ground cell). Every run's
                                       results are then those of a run with seed_per_cell on, streamed or not.
                                       Default 0 (docs/PORTING.md, "Streaming the returns") */
    uint8_t gate1;          /**< 1 (default): drop proposals failing gate 1 */
    uint8_t gate2;          /**< 1 (default): drop boxes failing gate 2 */
    int32_t gate1_margin_q16; /**< gate 1 passes when energy_q16 < the model's gamma_q16 + this (Q16 nats; the
                                          float detector's gate1_margin); [-20 * 65536, 20 * 65536], default 0 */
    int32_t gate2_margin_q16; /**< the same for gate 2; default 0 */
    int32_t gate1_class_margin_q16
        [LIDET_N_CLASSES]; /**< the float detector's gate1_class_margin in Q16 nats, added to gate1_margin_q16
                                           for a proposal of that class; [-20 * 65536, 20 * 65536]; default 0 */
    int32_t
        gate1_large_car_margin_q16; /**< the float detector's gate1_large_car_margin in Q16 nats, added to gate 1
                                             for a car whose cluster holds >= LIDET_DET_FLAT_MIN_POINTS member
                                             pixels; [0, 20 * 65536]; default 65536 for > 16 rows, 0 for <= 16 */
    uint8_t gate2_class[LIDET_N_CLASSES]; /**< 1: gate 2 judges this class, 0: it passes (the float detector's
                                               gate2_class); default car 1, cyclist 1, pedestrian 0 */
    uint8_t group_split; /**< the float detector's group_split (lidet_detector.h): default 1 for > 16 rows,
                                     0 for <= 16 */
    int32_t group_max_range_mm; /**< the float detector's group_max_range_m in mm; [0, 10^6], default 40000 */
    int32_t group_gate1_margin_q16; /**< the float detector's group_gate1_margin in Q16 nats; [0, 20 * 65536],
                                         default 2 * 65536 */
    int32_t min_score_q15
        [LIDET_N_CLASSES];       /**< the float detector's min_score in Q15 (a detection whose score_q15
                                                 is below is dropped, outcome LIDET_DET_OUT_SCORE); [0, 32768];
                                                 default car 19661 (0.6), cyclist and pedestrian 0 */
    int32_t car_min_z_spread_mm; /**< the float detector's car_min_z_spread_m in mm (the test in 4 mm steps:
                                      12 sum dz^2 < (this / 4)^2 n); [0, 10000]; 0: off; default 600 for > 16 rows, 0 for
                                      <= 16 */
    int32_t car_ground_mm; /**< the float detector's car_ground_m in mm (the footprint test and the ground's
                                median in integer steps: lidet_detector_common.h LIDET_DET_GROUND_*); [0, 10000];
                                0: off; default 1000. It reads the ground mask after the
                                networks, which a build with LIDET_Q_PIXEL_XYZ 0 does not keep: there it must be 0
                                (the default; LIDET_ERR_CONFIG otherwise) */
    int32_t
        score_box_weight_q16[LIDET_N_CLASSES]; /**< the float detector's score_box_weight in Q16: the score
                                                       is lidet_detector_q_score(E1 + round(w (E2 - gamma2)),
                                                       gamma1); [0, 4 * 65536]; default car 32768, others 0 */
    int32_t
        score_points_weight_q16[LIDET_N_CLASSES]; /**< the float detector's score_points_weight in Q16: minus
                                                          round(v (ln n - ln 64)) in that energy, ln n in Q16 from
                                                          the energies' log table; default car 6554, others 0 */
    int32_t nms_iou_q15;                          /**< [0, 32768]; default 3277 (0.1) */
    lidet_size_limits_q_t size;                   /**< plausible l, w, h per class */
    lidet_clock_fn clock; /**< optional timestamp source for stats.ticks (NULL: no timing) */
    void *clock_ctx;      /**< passed to clock */
} lidet_detector_q_cfg_t;

/** @brief Counts of the last run (the fields of lidet_detector_stats_t, the integer stages' counts). */
typedef struct
{
    uint32_t n_clusters, n_out_of_crop, n_out_of_range, n_over_budget, n_classified, n_gate1_rejected,
        n_boxed, n_gate2_rejected, n_size_rejected, n_nms_suppressed, n_over_capacity, n_detections;
    uint32_t n_over_box_budget; /**< passed gate 1 past max_boxes (not boxed) */
    uint32_t n_too_tall;        /**< taller than max_height_extent_mm (not classified) */
    uint32_t n_group_split, n_group_classified, n_group_boxed; /**< the float detector's group split counts */
    uint32_t n_score_rejected;                                 /**< the float detector's n_score_rejected */
    uint32_t n_stream_sectors; /**< cfg.stream_sectors: ground sectors done while the scan streamed in, before
                                    stream_end (0 when a return came back to a done sector's columns: stream_end
                                    then ran the whole stage) */
    uint32_t ticks[LIDET_DET_N_STAGES]; /**< clock ticks per stage (0 without a clock) */
    lidet_proj_stats_t proj;
    lidet_ground_stats_t ground;
    lidet_cluster_stats_t cluster;
} lidet_detector_q_stats_t;

/** @brief The integer detector: every buffer of every integer stage. Declare it static. */
typedef struct
{
    uint32_t magic;
    lidet_detector_q_cfg_t cfg;
    lidet_proj_q_state_t proj;
    lidet_ground_q_state_t ground;
    lidet_cluster_q_state_t cluster;
    /* per pixel: the compact image (LIDET_Q_PIXEL_XYZ 0: the range only, x, y, z decoded where read) */
#if LIDET_Q_PIXEL_XYZ
    int16_t x_4mm[LIDET_MAX_ROWS * LIDET_MAX_COLS];
    int16_t y_4mm[LIDET_MAX_ROWS * LIDET_MAX_COLS];
    int16_t z_4mm[LIDET_MAX_ROWS * LIDET_MAX_COLS];
#endif
    uint16_t range_4mm[LIDET_MAX_ROWS * LIDET_MAX_COLS];
#if LIDET_Q_PIXEL_XYZ
    uint8_t mask[LIDET_MAX_ROWS * LIDET_MAX_COLS]; /* the ground mask (LIDET_Q_PIXEL_XYZ 0: overlaid below) */
#endif
    /* overlaid, as the float workspace does: the projection's winning point per pixel (range-only: its key;
     * read by nothing after the projection: per-point outputs come from the caller's point_pixel), the ground
     * stage's scratch (dead after the ground stage; LIDET_Q_PIXEL_XYZ 0: its sample mask, the first bytes, then
     * holds the ground mask, a byte per pixel, until the clustering has marked its candidates, so the ground
     * mask does not outlive the run), then the clustering's outputs
     * (written by the clustering, read by the proposals; the members, written after the marking, first) */
    union
    {
        int32_t point_idx[LIDET_MAX_ROWS * LIDET_MAX_COLS]; /* during the projection only */
        lidet_ground_q_scratch_t ground;                    /* during the ground stage only */
        struct
        {
            lidet_member_t members[LIDET_MAX_ROWS * LIDET_MAX_COLS];
            uint16_t labels[LIDET_MAX_ROWS * LIDET_MAX_COLS];
        } cluster; /* from the clustering on */
    } scratch;
    /* the networks' (the members are alive meanwhile); 32-byte aligned as lidet_detector_t's */
    int32_t pn_scratch[LIDET_DETECTOR_Q_PN_SCRATCH / 4] LIDET_ALIGN(32);
    lidet_pointnet_q_t cls, box;
    lidet_proposal_q_t proposal;
    uint16_t order[LIDET_MAX_CLUSTERS];                /* candidate clusters, nearest first */
    uint32_t key[LIDET_MAX_CLUSTERS];                  /* their squared horizontal ranges (4 mm steps) */
    lidet_detection_q_t det[LIDET_MAX_DETECTIONS + 1]; /* + 1: a candidate before the capacity check */
    uint8_t outcome[LIDET_MAX_CLUSTERS];               /* lidet_det_outcome_t per kept cluster */
    uint32_t n_det;
    lidet_detector_q_stats_t stats;
    uint32_t stream_ticks; /* a stream's projection ticks so far (lidet_detector_q_stream_*) */
    /* cfg.stream_sectors: the stream's progress in columns travelled from its first return's column (the image's
     * columns in the order the returns visit them: dir +1 or -1, 0 until known) */
    uint16_t stream_first_col, stream_start_col, stream_pos, stream_done, stream_next;
    uint16_t stream_spread_u; /* the widest chunk's azimuth spread so far (2^15 - azimuth units) */
    uint16_t stream_late_u,
        stream_late_span; /* the azimuths (as 2^15 - azimuth) of the done sectors' columns:
                                                 [late_u, late_u + late_span] mod 2^16 */
    int8_t stream_dir;
    uint8_t stream_flags; /* LIDET__DETQ_STREAM_* (lidet_detector_q.c) */
} lidet_detector_q_t;

/**
 * @brief Defaults for an integer sensor profile: each integer stage's defaults, 360 degrees, at most 256
 *        proposals (128 for <= 16 beams), both gates on, NMS at BEV IoU 0.1, the class size limits (mm).
 */
void lidet_detector_q_cfg_default(lidet_detector_q_cfg_t *cfg, const lidet_sensor_q_t *sensor);

/**
 * @brief Initialise the integer stages and bind the two int8 models (checked as lidet_detector_init does).
 * @return LIDET_OK; LIDET_ERR_ARG; LIDET_ERR_CONFIG (a field out of range) or a stage's init error;
 *         LIDET_ERR_MODEL (a model fails lidet_pointnet_q_check, different points per proposal, PVLE bins other
 *         than the proposal configuration's); LIDET_ERR_BUFFER (scratch too small).
 */
lidet_status_t lidet_detector_q_init(lidet_detector_q_t *d, const lidet_detector_q_cfg_t *cfg,
                                     const lidet_pointnet_q_model_t *cls,
                                     const lidet_pointnet_q_model_t *box);

/**
 * @brief Detect road users in one scan of int32 mm points (records of `stride` int32, x y z first).
 * @param ring        optional ring index per point, or NULL; point_pixel: optional LIDET_MAX_POINTS int32, or NULL.
 * @return as lidet_detector_run.
 */
lidet_status_t lidet_detector_q_run(lidet_detector_q_t *d, const int32_t *points_mm, uint32_t n_points,
                                    uint32_t stride, const uint16_t *ring, int32_t *point_pixel);

/**
 * @brief Detect road users in one scan given as the sensor's returns (ring, azimuth, range: lidet_return_t,
 *        lidet_proj_q_run_returns): the projection without square roots or column searches, the rest as
 *        lidet_detector_q_run. The firmware's way in when the driver has the sensor's packets
 *        (docs/PORTING.md, "Feeding the detector").
 * @param point_pixel optional LIDET_MAX_POINTS int32 (the pixel of each return, -1 = dropped), or NULL.
 * @return as lidet_detector_q_run (LIDET_ERR_ARG: NULL returns with n_returns > 0).
 */
lidet_status_t lidet_detector_q_run_returns(lidet_detector_q_t *d, const lidet_return_t *returns,
                                            uint32_t n_returns, int32_t *point_pixel);

/**
 * @brief The sensor's returns streamed into the detector a chunk (a packet) at a time, so a board needs no buffer
 *        for the scan (docs/PORTING.md, "Streaming the returns"): begin clears the image, each call of
 *        lidet_detector_q_stream_returns projects one chunk into it (about 35 instructions per return on a
 *        Cortex-M4), end runs the ground stage, the clustering, the networks and the NMS on the finished image.
 *
 * The detections, outcomes, stats and image equal lidet_detector_q_run_returns' on the chunks' concatenation, bit
 * for bit, however the scan is cut (lidet_proj_q_returns_begin). stats.ticks[PROJECT] sums the three calls'
 * projection time; the rest of the stages run inside end, so the latency from a scan's last packet to its
 * detections is end's time. With cfg.stream_sectors (a range-only image), stream_returns also runs the ground
 * stage on every sector the stream has moved past (its columns and two on each side a margin behind the chunk's
 * last return: 1/32 turn, or the widest chunk's azimuth spread so far if more, + 4 columns; the first return's
 * sector and those within the margin after it wait for end, where the rotation's last returns land), so end does
 * only the rest of it: the results are still run_returns' (which then draws a RANSAC stream per ground cell too), bit for bit, in
 * any order of the returns; a return that comes back to a done sector's columns makes end run the whole ground
 * stage again (stats.n_stream_sectors 0). ticks[PROJECT] then holds that ground work too. Nothing else may run on the detector between begin and end: a run
 * (lidet_detector_q_run, _run_returns) or a new begin drops an open stream.
 * @param point_pixel optional: n_returns int32 for *this chunk* (each return's pixel, -1 = dropped), or NULL.
 * @return begin: LIDET_OK; LIDET_ERR_ARG (NULL); LIDET_ERR_STATE (not initialised). stream_returns: LIDET_OK;
 *         LIDET_TRUNCATED (the scan passed LIDET_MAX_POINTS returns: the rest are counted, not projected);
 *         LIDET_ERR_ARG (NULL d, NULL returns with n_returns > 0); LIDET_ERR_STATE (no stream open). end: as
 *         lidet_detector_q_run_returns; LIDET_ERR_STATE (no stream open).
 */
lidet_status_t lidet_detector_q_stream_begin(lidet_detector_q_t *d);
/** @brief One chunk of the open stream's returns (lidet_detector_q_stream_begin). */
lidet_status_t lidet_detector_q_stream_returns(lidet_detector_q_t *d, const lidet_return_t *returns,
                                               uint32_t n_returns, int32_t *point_pixel);
/** @brief Detect road users in the open stream's scan (lidet_detector_q_stream_begin). */
lidet_status_t lidet_detector_q_stream_end(lidet_detector_q_t *d);

/** @brief Detections of the last run, best score first. */
const lidet_detection_q_t *lidet_detector_q_detections(const lidet_detector_q_t *d, uint32_t *n_detections);

/** @brief Outcome per kept cluster of the last run (lidet_det_outcome_t, index = cluster id - 1). */
const uint8_t *lidet_detector_q_outcomes(const lidet_detector_q_t *d, uint32_t *n_clusters);

/** @brief Counts of the last run. */
const lidet_detector_q_stats_t *lidet_detector_q_stats(const lidet_detector_q_t *d);

/** @brief The compact range image of the last run (views into d; point_idx is NULL: overlaid after the
 *         projection, per-point results come from lidet_detector_q_run's point_pixel; range-only: x_4mm,
 *         y_4mm, z_4mm NULL, the decoding tables set). */
void lidet_detector_q_image(const lidet_detector_q_t *d, lidet_range_image_t *img);

/** @brief sizeof(lidet_detector_q_t). */
uint32_t lidet_detector_q_bytes(void);

/** @brief score = 1 / (1 + exp(energy - gamma)) in Q15, from Q16 nats: the float detector's score. */
int32_t lidet_detector_q_score(int32_t energy_q16, int32_t gamma_q16);

#ifdef __cplusplus
}
#endif

#endif /* LIDET_DETECTOR_Q_H */
