/* SPDX-License-Identifier: MIT */
/**
 * @file lidet_track_q.h
 * @brief The integer multi-object tracker (docs/TRACKING.md, "Integer build"): the float tracker's model and
 *        steps (lidet_track.h) on lidet_detection_q_t, with integers only (no float anywhere).
 *
 * Per track one constant-velocity Kalman filter per axis sharing one 2 x 2 covariance, ego compensation,
 * prediction with white-noise acceleration, gated Mahalanobis costs, the optimal (Hungarian, shortest augmenting
 * paths) or the greedy assignment, update / miss / birth, confirmation (docs/TRACKING.md). Units and formats:
 *  - position (x, y) of a track in 1/256 mm (Q8 mm), |x|, |y| <= LIDET_TRACK_Q_COORD_MAX_MM (a track predicted
 *    beyond dies, counted in n_deaths); velocity in 1/256 mm/s, each axis clamped to +-LIDET_TRACK_Q_VMAX_MMPS;
 *  - covariance per axis: p_pp in mm^2, p_pv in mm^2/s, p_vv in mm^2/s^2, int32; after every prediction and
 *    update p_pp, p_vv are clamped to [1, LIDET_TRACK_Q_P_MAX] and |p_pv| to floor(sqrt(p_pp p_vv - 1)) (so the
 *    matrix stays positive definite); the process noise terms saturate where they would pass the ceiling anyway;
 *  - z, l, w, h in mm, yaw in BAM32, averaged with Q15 weights: x += round(alpha (new - x) / 2^15);
 *  - cost m = round(d^2 2^16 / S) (Q16; d^2 in mm^2 from the Q8 centres), feasible when d^2 2^16 <= gate_chi2 S
 *    (exact) and d^2 <= gate_max^2; class_penalty and the infeasible cost gate_chi2 + class_penalty + 2^16 in Q16;
 *  - the class vote: the sum of the Q15 scores per class (uint32), all three halved when one reaches 2^30;
 *  - every division rounds half away from zero (lidet__q_div_round), every dropped fraction of a shift half up.
 * Mirrored bit for bit by codegen/lidet_ref/track_q.py.
 *
 * Memory: sizeof(lidet_tracker_q_t) = LIDET_TRACK_MAX_TRACKS * (90 + 4 LIDET_TRACK_MAX_DETS) + 2 LIDET_TRACK_MAX_DETS
 * + 33 max(LIDET_TRACK_MAX_TRACKS, LIDET_TRACK_MAX_DETS) + ~160 B (88 B a track slot, an int32 cost per track and
 * detection, the assignment's int64 potentials and distances): 24,560 B at the defaults (64, 64), on x86-64 and
 * Cortex-M alike; lidet_tracker_q_bytes().
 * Time per update: O(T D) costs with T tracks and D detections, then O(n^3) for the optimal assignment
 * (n = max(T, D)) or O(min(T, D) T D) for the greedy one. No allocation, no recursion.
 */
#ifndef LIDET_TRACK_Q_H
#define LIDET_TRACK_Q_H

#include "lidet_detector_q.h"
#include "lidet_q.h"
#include "lidet_track_common.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Largest |x|, |y|, |z| of a detection centre and |x|, |y| of a track, and largest |dx|, |dy| of an ego motion,
 *  mm (2^20: 1048 m). */
#define LIDET_TRACK_Q_COORD_MAX_MM 1048576
/** Largest l, w, h of a detection, mm (100 m; the float tracker's limit). */
#define LIDET_TRACK_Q_SIZE_MAX_MM 100000
/** Largest |vx|, |vy| of a track, mm/s (100 m/s); the filter's velocity is clamped to it. */
#define LIDET_TRACK_Q_VMAX_MMPS 100000
/** Ceiling of p_pp (mm^2) and p_vv (mm^2/s^2): 2^31 - 1 (a standard deviation of 46 m, 46 m/s). */
#define LIDET_TRACK_Q_P_MAX 2147483647
/** Largest dt of one update, ms (10 s). */
#define LIDET_TRACK_Q_DT_MAX_MS 10000u
/** Rows of the square assignment: the larger of the two capacities. */
#define LIDET_TRACK_Q_ASSIGN_N                                                                               \
    (LIDET_TRACK_MAX_TRACKS > LIDET_TRACK_MAX_DETS ? LIDET_TRACK_MAX_TRACKS : LIDET_TRACK_MAX_DETS)

/** @brief Configuration of the integer tracker: docs/TRACKING.md's fields in integer units, per class in
 *         lidet_class_t order. Fill with lidet_tracker_q_cfg_default(); lidet_tracker_q_init checks the ranges. */
typedef struct
{
    int32_t meas_sigma_mm[LIDET_N_CLASSES];       /**< detection centre noise per axis; [1, 10000] */
    int32_t accel_sigma_mmps2[LIDET_N_CLASSES];   /**< white-noise acceleration; [0, 100000] */
    int32_t init_vel_sigma_mmps[LIDET_N_CLASSES]; /**< a new track's velocity deviation; [0, 46340] */
    int32_t gate_max_mm[LIDET_N_CLASSES];         /**< no association beyond; [1, 1000000] */
    int32_t gate_chi2_q16;                        /**< Mahalanobis gate, Q16; [1, 1000 * 65536] */
    int32_t class_penalty_q16;                    /**< if the classes differ, Q16; [0, 1000 * 65536] */
    uint32_t assign;                              /**< lidet_track_assign_t */
    uint32_t confirm_hits;                        /**< [1, 1000] */
    uint32_t max_misses;                          /**< [0, 1000] */
    uint32_t report_misses[LIDET_N_CLASSES];      /**< as lidet_tracker_cfg_t's; [0, 1000] */
    int32_t birth_min_score_q15;                  /**< [0, 32768] */
    int32_t yaw_alpha_q15;                        /**< weight of a new yaw; [0, 32768] */
    int32_t size_alpha_q15;                       /**< weight of a new z, l, w, h; [0, 32768] */
    int32_t heading_speed_mmps;                   /**< [0, LIDET_TRACK_Q_VMAX_MMPS] */
    uint32_t heading_from_velocity;               /**< bits 1 << lidet_class_t; < 1 << LIDET_N_CLASSES */
} lidet_tracker_q_cfg_t;

/** @brief The sensor's motion from the previous scan to this one, in the previous scan's sensor frame. */
typedef struct
{
    int32_t dx_mm, dy_mm; /**< translation; |.| <= LIDET_TRACK_Q_COORD_MAX_MM */
    int32_t dyaw_bam;     /**< rotation about +z, signed BAM32 */
} lidet_ego_q_t;

/** @brief One track as lidet_tracker_q_tracks gives it. */
typedef struct
{
    uint32_t id;   /**< 1, 2, ... (wraps to 1 after 2^32 - 1) */
    uint8_t cls;   /**< lidet_class_t: the vote's arg-max (first on ties) */
    uint8_t state; /**< lidet_track_state_t */
    uint16_t reserved;
    /** centre x, y from the filter (rounded to mm), averaged z, l, w, h; the reported yaw (docs/TRACKING.md,
     *  "The reported heading") */
    lidet_box_q_t box;
    int32_t vx_mmps, vy_mmps; /**< velocity over the ground in the current sensor axes, rounded to mm/s */
    int32_t p_pp;             /**< position variance per axis, mm^2 */
    int32_t p_pv;             /**< position-velocity covariance per axis, mm^2/s */
    int32_t p_vv;             /**< velocity variance per axis, mm^2/s^2 */
    int32_t score_q15;        /**< the last detection's score */
    uint32_t hits;            /**< detections assigned since birth (birth included) */
    uint32_t misses;          /**< scans in a row without a detection */
    uint32_t age;             /**< scans since birth (0 in the scan of its birth) */
    int32_t det_index;        /**< this scan's detection (index into the update's input), -1 when it missed */
} lidet_track_q_t;

/** @brief Counts of the last lidet_tracker_q_update (n_tracks, n_confirmed: after it). */
typedef struct
{
    uint32_t n_tracks;         /**< tracks held (any state) */
    uint32_t n_confirmed;      /**< of which confirmed (updated or coasting) */
    uint32_t n_births;         /**< tracks started */
    uint32_t n_births_dropped; /**< births without a free slot (LIDET_TRUNCATED) */
    uint32_t n_deaths;         /**< tracks ended (misses, or predicted beyond LIDET_TRACK_Q_COORD_MAX_MM) */
    uint32_t n_matched;        /**< track-detection pairs assigned */
    uint32_t n_feasible_pairs; /**< pairs within the gates */
    uint32_t n_dets_dropped;   /**< detections past LIDET_TRACK_MAX_DETS (LIDET_TRUNCATED) */
    /** detections skipped: a class outside lidet_class_t, a size outside [1, LIDET_TRACK_Q_SIZE_MAX_MM], a score
     *  outside [0, 32768], a centre coordinate beyond +-LIDET_TRACK_Q_COORD_MAX_MM */
    uint32_t n_bad_dets;
} lidet_tracker_q_stats_t;

/** @brief One track slot of lidet_tracker_q_t (internal state; read tracks with lidet_tracker_q_tracks). */
typedef struct
{
    int32_t x_q8, y_q8;              /**< centre, 1/256 mm */
    int32_t vx_q8, vy_q8;            /**< velocity, 1/256 mm/s */
    int32_t p_pp, p_pv, p_vv;        /**< covariance per axis (lidet_track_q_t units) */
    int32_t cz_mm, l_mm, w_mm, h_mm; /**< averaged */
    int32_t yaw_bam;                 /**< averaged box yaw (heading flip folded out) */
    uint32_t votes[LIDET_N_CLASSES]; /**< Q15 score sums */
    uint32_t id;
    int32_t score_q15;
    uint32_t hits, misses, age;
    int32_t det_index;
    uint8_t active; /**< 1: the slot holds a track */
    uint8_t state;  /**< lidet_track_state_t */
    uint8_t cls;    /**< the vote's arg-max */
    uint8_t reserved;
} lidet_track_q_slot_t;

/** @brief The integer tracker: its state and the assignment's workspace. Declare it static. */
typedef struct
{
    uint32_t magic;
    lidet_tracker_q_cfg_t cfg;
    uint32_t next_id;
    lidet_tracker_q_stats_t stats;
    lidet_track_q_slot_t slot[LIDET_TRACK_MAX_TRACKS];
    /* the costs, Q16: row = a track (slot order), column = a valid detection (input order) */
    int32_t cost[LIDET_TRACK_MAX_TRACKS * LIDET_TRACK_MAX_DETS];
    uint16_t row_slot[LIDET_TRACK_MAX_TRACKS]; /* the rows' slots */
    uint16_t col_det[LIDET_TRACK_MAX_DETS];    /* the columns' detection indices */
    int16_t row_col[LIDET_TRACK_Q_ASSIGN_N];   /* assigned column per row, -1: none */
    int16_t col_row[LIDET_TRACK_Q_ASSIGN_N];   /* assigned row per column, -1: none */
    /* the Hungarian method's potentials, distances and path (index 0 is the virtual row/column) */
    int64_t pot_u[LIDET_TRACK_Q_ASSIGN_N + 1], pot_v[LIDET_TRACK_Q_ASSIGN_N + 1];
    int64_t minv[LIDET_TRACK_Q_ASSIGN_N + 1];
    uint16_t match[LIDET_TRACK_Q_ASSIGN_N + 1], way[LIDET_TRACK_Q_ASSIGN_N + 1];
    uint8_t used[LIDET_TRACK_Q_ASSIGN_N + 1];
} lidet_tracker_q_t;

/** @brief docs/TRACKING.md's defaults in integer units: meas_sigma 300, 250, 200 mm; accel_sigma 2000, 2500,
 *         1500 mm/s^2; init_vel_sigma 10000, 6000, 3000 mm/s; gate_max 4000, 3000, 2000 mm; gate_chi2 603587
 *         (9.21); class_penalty 131072 (2.0); optimal; confirm_hits 2; max_misses 12; report_misses 1, 1, 0; birth_min_score 0;
 *         yaw_alpha 16384 (0.5); size_alpha 9830 (0.3); heading_speed 1000 mm/s; pedestrian and cyclist.
 *  @param[out] cfg filled; ignored when NULL. */
void lidet_tracker_q_cfg_default(lidet_tracker_q_cfg_t *cfg);

/**
 * @brief Check the configuration, keep a copy and start with no track (ids from 1).
 * @param[out] t  the tracker (caller-owned, e.g. static)
 * @param[in]  cfg copied
 * @return LIDET_OK; LIDET_ERR_ARG (NULL); LIDET_ERR_CONFIG (a field out of its range).
 */
lidet_status_t lidet_tracker_q_init(lidet_tracker_q_t *t, const lidet_tracker_q_cfg_t *cfg);

/** @brief Drop every track, ids from 1 again, zero the counts; the configuration stays.
 *  @return LIDET_OK; LIDET_ERR_ARG (NULL); LIDET_ERR_STATE (not initialised). */
lidet_status_t lidet_tracker_q_reset(lidet_tracker_q_t *t);

/**
 * @brief One scan (docs/TRACKING.md, "One scan").
 * @param[in,out] t     an initialised tracker
 * @param[in]     det   n_det detections (best score first, as the detector writes them); NULL when n_det is 0
 * @param         n_det any count: the first LIDET_TRACK_MAX_DETS are used, the rest counted (n_dets_dropped)
 * @param         dt_ms time since the previous scan, [1, LIDET_TRACK_Q_DT_MAX_MS]
 * @param[in]     ego   the sensor's motion since the previous scan, or NULL (it did not move)
 * @return LIDET_OK; LIDET_TRUNCATED (detections dropped or births without a slot); LIDET_ERR_ARG (NULL, dt out of
 *         range, an ego translation beyond LIDET_TRACK_Q_COORD_MAX_MM: nothing changes); LIDET_ERR_STATE.
 */
lidet_status_t lidet_tracker_q_update(lidet_tracker_q_t *t, const lidet_detection_q_t *det, uint32_t n_det,
                                      uint32_t dt_ms, const lidet_ego_q_t *ego);

/**
 * @brief Copy the tracks, in id order: confirmed tracks updated by the last scan always, coasting ones with
 *        LIDET_TRACK_OUT_COASTING, tentative ones with LIDET_TRACK_OUT_TENTATIVE.
 * @param[in]  t     the tracker
 * @param[out] out   room for cap tracks (the lowest ids first when more qualify)
 * @param      flags LIDET_TRACK_OUT_* bits
 * @return the number written; 0 for NULL t or out, or an uninitialised tracker.
 */
uint32_t lidet_tracker_q_tracks(const lidet_tracker_q_t *t, lidet_track_q_t *out, uint32_t cap,
                                uint32_t flags);

/** @brief Counts of the last update; NULL for NULL t. */
const lidet_tracker_q_stats_t *lidet_tracker_q_stats(const lidet_tracker_q_t *t);

/** @brief sizeof(lidet_tracker_q_t). */
uint32_t lidet_tracker_q_bytes(void);

#ifdef __cplusplus
}
#endif

#endif /* LIDET_TRACK_Q_H */
