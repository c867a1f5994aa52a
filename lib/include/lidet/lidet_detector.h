/* SPDX-License-Identifier: MIT */
/**
 * @file lidet_detector.h
 * @brief The whole detector in one object: projection -> ground -> clustering -> proposals ->
 *        classifier + gate 1 -> box net + gate 2 -> size check -> BEV non-maximum suppression.
 *
 * One lidet_detector_t holds every buffer of every stage (the stage workspace of lidet_workspace.h,
 * whose scratch is overlaid, plus the PointNet scratch, one proposal and the detections); a firmware
 * declares one static object (or places it with the port's section macro) and calls
 * lidet_detector_run once per scan. Every stage stays callable alone; this only chains them.
 *
 * Per scan:
 *  1. lidet_workspace_run: projection, ground, clustering (lidet_workspace.h).
 *  2. Candidate clusters: those whose mean lies in the azimuth window (|azimuth| <= crop_half_rad, when
 *     set: the KITTI camera field of view is pi/4) and within max_range_m; at most max_proposals of
 *     them, nearest first (ties: lower cluster id), so the networks' time per scan is bounded whatever
 *     the scan holds. The rest is counted, not classified.
 *  3. Per candidate: the proposal (lidet_proposal_make with the models' points per proposal), the
 *     classifier (gate 1: energy < gamma_c[class]), then the box net with that class (gate 2:
 *     heading + size energy < gamma_b[class]), for at most max_boxes of them per scan (nearest first).
 *     Either gate can be switched off (evaluation).
 *  4. Boxes of impossible size for their class (outside [size_min, size_max] per dimension), or with a
 *     non-finite centre or yaw, are dropped.
 *  5. Non-maximum suppression in bird's-eye view: detections sorted by score (ties: cluster id); one
 *     whose rotated BEV IoU with a kept detection of any class exceeds nms_iou is dropped; between two
 *     parts of one group cut (one cluster id) the bound is the larger of nms_iou and 0.25.
 * Score: 1 / (1 + exp(E_c - gamma_c[class])), monotonic in the classifier energy, 0.5 at gate 1's
 * threshold (the authors' score is also a function of the classifier energy alone).
 *
 * Memory: sizeof(lidet_detector_t) = lidet_workspace_bytes() + LIDET_DETECTOR_PN_SCRATCH
 * + sizeof(lidet_proposal_t) + LIDET_MAX_CLUSTERS * 9 B + LIDET_MAX_DETECTIONS * sizeof(lidet_detection_t)
 * + ~600 B; lidet_detector_bytes() returns it (docs/MEMORY.md has the table per sensor configuration).
 * Time: the stages + max_proposals * (classifier + box net) + O(K log K) to order K clusters
 * + O(D^2) for the NMS of D detections. No allocation, no recursion.
 */
#ifndef LIDET_DETECTOR_H
#define LIDET_DETECTOR_H

#include "lidet_detector_common.h" /* lidet_clock_fn, stage indices, outcomes */
#include "lidet_pointnet.h"
#include "lidet_types.h"
#include "lidet_workspace.h"

#ifdef __cplusplus
extern "C" {
#endif

/** @brief Configuration. Fill with lidet_detector_cfg_default(). */
typedef struct
{
    lidet_workspace_cfg_t stages;  /**< projection, ground, clustering */
    lidet_proposal_cfg_t proposal; /**< n_points is set from the models by init; seed and PVLE bins used */
    float crop_half_rad;           /**< 0: 360 degrees; else keep clusters with |azimuth| <= this (KITTI
                                         camera field of view: pi/4); (0, pi]. It also sets the stages'
                                         windows (docs/DETECTOR.md, Crop): the clustering's (crop + 15 deg),
                                         the projection's (one ground sector more), and the ground's
                                         seed_per_cell */
    float max_range_m;             /**< clusters whose mean is farther are not classified; 0 = no limit */
    float max_height_extent_m;     /**< clusters whose points span more than this in z (a tree, a pole, a
                                         wall) are not classified: no road user is that tall; 0 = no limit;
                                         [0, 100]; default 2.5 (measured: docs/DETECTOR.md, "Tall clusters") */
    uint32_t max_proposals;        /**< at most this many clusters classified per scan, nearest first;
                                         [1, LIDET_MAX_CLUSTERS]; default 256 (> 16 beams), 128 (<= 16 beams),
                                         capped by LIDET_MAX_CLUSTERS */
    uint32_t max_boxes; /**< at most this many proposals through the box net per scan (those passing
                                         gate 1, nearest first); the rest get outcome LIDET_DET_OUT_BUDGET
                                         (stats n_over_box_budget, status LIDET_TRUNCATED): bounds the box
                                         net's time whatever the scan. [1, LIDET_MAX_CLUSTERS]; default 48 (> 16
                                         beams), 24 (<= 16 beams): > 2x the most gate-1 passes seen on a real
                                         scan (21, docs/ROBUSTNESS.md) */
    uint8_t gate1;      /**< 1 (default): drop proposals failing gate 1 */
    uint8_t gate2;      /**< 1 (default): drop boxes failing gate 2 */
    float
        gate1_margin; /**< the operating point of gate 1: a proposal passes when its energy < the model's gamma
                                         + this (nats); 0 (default): the model's threshold, which keeps 95 % of
                                         the validation road users; > 0 keeps more of them and more clutter
                                         (measured: docs/DETECTOR.md); [-20, 20] */
    float gate2_margin; /**< the same for gate 2 (the box net's gamma); [-20, 20], default 0 */
    float gate1_class_margin
        [LIDET_N_CLASSES]; /**< added to gate1_margin for a proposal the classifier calls this class
                                           (lidet_class_t order; nats, [-20, 20]); default 0: the models'
                                           thresholds. E.g. 1 for pedestrians keeps more real people that the
                                           networks trained on simulated ones find out of distribution, and
                                           more clutter (measured: docs/DETECTOR.md, "Gates") */
    float
        gate1_large_car_margin; /**< added to gate 1's threshold for a proposal the classifier calls a car whose
                                       cluster holds at least LIDET_DET_FLAT_MIN_POINTS member pixels (nats, [0,
                                       20]): real cars that the networks trained on simulated ones find a little out
                                       of distribution are mostly large clusters, the clutter a wider car gate lets
                                       through mostly small ones. Default 1 for > 16 beams, 0 for <= 16
                                       (measured: docs/DETECTOR.md, "Gates") */
    uint8_t gate2_class[LIDET_N_CLASSES]; /**< 1: gate 2 judges this class (lidet_class_t order), 0: its boxes
                                               pass gate 2 whatever the box net's energy (the energy is still
                                               reported). Default car 1, cyclist 1, pedestrian 0: a pedestrian's
                                               heading is ambiguous, and on real scans gate 2 dropped more real
                                               pedestrians than clutter (measured: docs/DETECTOR.md, "Gate 2 per
                                               class") */
    uint8_t group_split; /**< 1: a classified cluster that gave no detection and is shaped like people side by
                              side (z spread 1.0-2.2 m, 0.9-3.5 m along its principal horizontal axis, >= 20
                              points) is cut along that axis into 2-4 parts (one-dimensional k-means); the cut
                              stands when the classifier calls every part a pedestrian or a cyclist passing gate 1
                              widened by group_gate1_margin (one at least a pedestrian), and each part that passes
                              gate 1 itself is then boxed as a pedestrian; its detections carry the cluster's id
                              (outcome LIDET_DET_OUT_GROUP). Up to 9 more
                              classifier passes per such cluster. Default 1 for > 16 beams, 0 for <= 16 (measured
                              on the real frames: docs/DETECTOR.md, "People in groups") */
    float group_max_range_m; /**< the group split examines clusters whose mean lies within this (horizontal);
                                  [0, 1000], default 40 */
    float
        group_gate1_margin; /**< nats added to gate 1's threshold when the group split judges a cut (does the
                                   classifier call every part a person?); a part still gives a detection only
                                   when it passes gate 1 itself. [0, 20], default 2: one real person of a group
                                   who looks out of distribution no longer vetoes the cut of the others
                                   (measured: docs/DETECTOR.md, "People in groups"); 0: every part must pass */
    float min_score
        [LIDET_N_CLASSES]; /**< the operating point: a detection scoring below its class's value (lidet_class_t
                                           order) is dropped, outcome LIDET_DET_OUT_SCORE (stats n_score_rejected);
                                           a group split's part likewise. [0, 1]; 0 keeps every detection that
                                           passed the gates. Default car 0.6, cyclist and pedestrian 0 (measured on the real frames and the
                                           simulated presets: docs/DETECTOR.md, "Operating point") */
    float
        car_min_z_spread_m; /**< a car whose cluster holds at least LIDET_DET_FLAT_MIN_POINTS member pixels and
                                   spreads less than this in z (sqrt(12 var z), the length of a uniform spread of
                                   that variance) is a flat surface the ground stage kept (a raised pavement, a
                                   terrace, a verge), not a car: outcome LIDET_DET_OUT_SIZE. [0, 10]; 0 turns the
                                   test off; default 0.6 for > 16 beams, 0 for <= 16 (docs/DETECTOR.md, "Flat surfaces") */
    float
        car_ground_m; /**< a car box is stretched down to the ground pixels around it, its top kept: the median
                             height of the ground pixels whose point lies within this of the box's footprint and
                             within 1 m of its bottom (at least 5; lidet_detector_common.h LIDET_DET_GROUND_*), when
                             the bottom lies 0-0.5 m above it (the ground stage takes a car's lowest returns for
                             road). [0, 10]; 0 turns it off; default 1 (docs/DETECTOR.md, "Car boxes down to the ground") */
    float score_box_weight
        [LIDET_N_CLASSES]; /**< the detection score is 1 / (1 + e^-(m1 + w m2)), m1 = gamma1 - E1
                                                  and m2 = gamma2 - E2 the two gates' margins (the models' gammas),
                                                  w this, per class (lidet_class_t order); [0, 4]. Default car
                                                  0.5, cyclist and pedestrian 0: the box net's confidence ranks
                                                  cars' boxes better (docs/DETECTOR.md, Score) */
    float score_points_weight[LIDET_N_CLASSES]; /**< and + v ln(n / 64) inside the exponent, n the cluster's
                                                     points, v this per class; [0, 4]. Default car 0.1, others
                                                     0: among cars the ones with more points have better boxes */
    float nms_iou; /**< BEV IoU above which the lower-scored detection is dropped; [0, 1],
                                         default 0.1 (detections come from disjoint clusters) */
    float size_min_m[LIDET_N_CLASSES][3]; /**< plausible l, w, h per class (lidet_class_t order) */
    float size_max_m[LIDET_N_CLASSES][3];
    lidet_clock_fn clock; /**< optional timestamp source for stats.ticks (NULL: no timing) */
    void *clock_ctx;      /**< passed to clock */
} lidet_detector_cfg_t;

/** @brief One detection (sensor frame). */
typedef struct
{
    lidet_box_t box;     /**< centre, l w h, yaw */
    uint8_t cls;         /**< lidet_class_t */
    float score;         /**< (0, 1), see the file comment */
    float energy_cls;    /**< classifier energy (gate 1) */
    float energy_box;    /**< box net energy, heading + size (gate 2) */
    uint32_t cluster_id; /**< 1-based id of its cluster in the last run (lidet_workspace_labels) */
    uint32_t n_points;   /**< member pixels of that cluster (of its part, for a group split's detection) */
} lidet_detection_t;

/** @brief Counts of the last run. */
typedef struct
{
    uint32_t n_clusters;        /**< kept clusters */
    uint32_t n_out_of_crop;     /**< clusters whose mean lies outside the crop (the crop + 15 deg window
                                             of the clustering keeps the rest of the scan out) */
    uint32_t n_out_of_range;    /**< beyond max_range_m */
    uint32_t n_over_budget;     /**< past max_proposals (farthest first) */
    uint32_t n_classified;      /**< proposals through the classifier */
    uint32_t n_gate1_rejected;  /**< failed gate 1 */
    uint32_t n_boxed;           /**< proposals through the box net */
    uint32_t n_gate2_rejected;  /**< failed gate 2 */
    uint32_t n_size_rejected;   /**< boxes of impossible size */
    uint32_t n_nms_suppressed;  /**< dropped by the NMS */
    uint32_t n_over_capacity;   /**< detections past LIDET_MAX_DETECTIONS (lowest scores) */
    uint32_t n_detections;      /**< in the output */
    uint32_t n_over_box_budget; /**< passed gate 1 past max_boxes (not boxed) */
    uint32_t n_too_tall;        /**< taller than max_height_extent_m (not classified) */
    uint32_t n_group_split; /**< clusters the group split cut into people (outcome LIDET_DET_OUT_GROUP; their
                                     rejection above still counts them: the counts above are per cluster) */
    uint32_t n_group_classified; /**< classifier passes on the group split's parts (not in n_classified) */
    uint32_t n_group_boxed; /**< box net passes on its parts (not in n_boxed; n_boxed + this <= max_boxes) */
    uint32_t
        n_score_rejected; /**< clusters whose detection scored below min_score (outcome LIDET_DET_OUT_SCORE,
                                    or GROUP when the group split then cut it; a part's score is not counted) */
    uint32_t ticks[LIDET_DET_N_STAGES]; /**< clock ticks per stage (0 without a clock) */
    lidet_workspace_stats_t stages;     /**< the stages' own counts */
} lidet_detector_stats_t;

/** @brief The detector. Caller-owned, fixed size; declare it static. Read results through the functions. */
typedef struct
{
    uint32_t magic;
    lidet_detector_cfg_t cfg;
    lidet_workspace_t ws;
    lidet_pn_t cls, box;
    /* 64-byte aligned (a cache line): the host kernels' AVX2 / AVX-512 loads then stay within cache lines (an
     * offset of 16 cost the classifier 12-19 % on x86-64 with AVX2; 32 instead of 64 cost 10-17 % with AVX-512) */
    float pn_scratch[LIDET_DETECTOR_PN_SCRATCH / 4] LIDET_ALIGN(64);
    lidet_proposal_t proposal;
    uint16_t order[LIDET_MAX_CLUSTERS];              /* candidate clusters, nearest first */
    uint32_t key[LIDET_MAX_CLUSTERS];                /* their squared horizontal ranges (float bits, >= 0) */
    lidet_detection_t det[LIDET_MAX_DETECTIONS + 1]; /* + 1: a candidate before the capacity check */
    uint8_t outcome[LIDET_MAX_CLUSTERS];             /* lidet_det_outcome_t per kept cluster */
    uint32_t n_det;
    lidet_detector_stats_t stats;
} lidet_detector_t;

/**
 * @brief Defaults for a sensor: each stage's defaults, 64 points per proposal, 360 degrees, at most 256
 *        proposals (128 for <= 16 beams), both gates on, NMS at BEV IoU 0.1, the class size ranges of
 *        docs/DETECTOR.md.
 */
void lidet_detector_cfg_default(lidet_detector_cfg_t *cfg, const lidet_sensor_t *sensor);

/**
 * @brief Initialise the stages and bind the two models (checked: format version, kinds, dimensions,
 *        the same points per proposal, which must fit LIDET_PROPOSAL_POINTS, and the scratch they need).
 * @param[out] d   detector (caller-owned, static).
 * @param[in]  cfg configuration (copied).
 * @param[in]  cls classifier model (retained; generated models are static const).
 * @param[in]  box box-net model (retained).
 * @return LIDET_OK; LIDET_ERR_ARG (NULL); LIDET_ERR_CONFIG (a detector field out of range) or a stage's
 *         init error; LIDET_ERR_MODEL (a model fails lidet_pn_check, wrong kind, different points per
 *         proposal, or PVLE bins other than the proposal configuration's); LIDET_ERR_BUFFER (a model
 *         needs more than LIDET_DETECTOR_PN_SCRATCH bytes of scratch).
 */
lidet_status_t lidet_detector_init(lidet_detector_t *d, const lidet_detector_cfg_t *cfg,
                                   const lidet_pn_model_t *cls, const lidet_pn_model_t *box);

/**
 * @brief Detect road users in one scan.
 * @param[in,out] d           initialised detector; the previous scan's results are overwritten.
 * @param[in]     points      n_points records of `stride` floats, x y z first (metres, sensor frame).
 * @param[in]     n_points    records (only the first LIDET_MAX_POINTS are read).
 * @param[in]     stride      floats per record (>= 3; 4 for KITTI .bin).
 * @param[in]     ring        optional ring index per point, or NULL.
 * @param[out]    point_pixel optional LIDET_MAX_POINTS int32 for per-point labels, or NULL.
 * @return LIDET_OK; LIDET_TRUNCATED when a stage truncated, clusters were over the proposal budget or
 *         detections over capacity (stats say which); a stage's error (nothing detected).
 */
lidet_status_t lidet_detector_run(lidet_detector_t *d, const float *points, uint32_t n_points,
                                  uint32_t stride, const uint16_t *ring, int32_t *point_pixel);

/** @brief Detections of the last run, best score first (valid until the next run). */
const lidet_detection_t *lidet_detector_detections(const lidet_detector_t *d, uint32_t *n_detections);

/**
 * @brief What became of each kept cluster of the last run (lidet_det_outcome_t values, index = cluster
 *        id - 1): where a road user was lost (evaluation, debugging). Valid until the next run.
 */
const uint8_t *lidet_detector_outcomes(const lidet_detector_t *d, uint32_t *n_clusters);

/** @brief Counts (and ticks) of the last run. */
const lidet_detector_stats_t *lidet_detector_stats(const lidet_detector_t *d);

/** @brief The stage workspace (range image, ground mask, clusters of the last run). */
const lidet_workspace_t *lidet_detector_workspace(const lidet_detector_t *d);

/** @brief sizeof(lidet_detector_t): the bytes a firmware must place. */
uint32_t lidet_detector_bytes(void);

/**
 * @brief Rotated bird's-eye-view IoU of two boxes (footprints in x-y; exposed for tests and tools).
 * @return intersection area / union area in [0, 1]; 0 for degenerate boxes.
 */
float lidet_box_bev_iou(const lidet_box_t *a, const lidet_box_t *b);

#ifdef __cplusplus
}
#endif

#endif /* LIDET_DETECTOR_H */
