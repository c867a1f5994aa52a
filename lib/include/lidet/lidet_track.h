/* SPDX-License-Identifier: MIT */
/**
 * @file lidet_track.h
 * @brief Multi-object tracking across scans (docs/TRACKING.md), float build: the detector's boxes of one scan
 *        in, road users with a stable id, a smoothed box and a velocity over the ground out.
 *
 * Per track one constant-velocity Kalman filter per axis (x, y of the box centre in the current sensor frame,
 * vx, vy over the ground); with isotropic noise both axes share one 2 x 2 covariance (p_pp, p_pv, p_vv), so an
 * ego rotation leaves it unchanged. Per scan (lidet_tracker_update), in this order:
 *  1. check: dt in (0, 10] s, the ego motion finite; detections with a non-finite field, a class outside
 *     lidet_class_t, a size <= 0 (or a centre beyond 10 km, a size over 100 m) skipped and counted; at most
 *     LIDET_TRACK_MAX_DETS of them (the first), the rest counted;
 *  2. ego motion: every track into the new sensor frame, p <- R(-dyaw) (p - d), v <- R(-dyaw) v, yaw - dyaw;
 *  3. prediction with the track's class' white-noise acceleration accel_sigma;
 *  4. costs: m = d^2 / (p_pp + meas_sigma[k]^2) (chi-square, 2 dof); feasible when m <= gate_chi2 and
 *     d <= gate_max[track class]; + class_penalty when the classes differ;
 *  5. assignment: optimal (Hungarian method, shortest augmenting paths, on the square matrix of size
 *     max(tracks, detections) padded with gate_chi2 + class_penalty + 1) or greedy (cheapest feasible pair
 *     first; ties: lower slot, then lower detection index); assigned infeasible pairs are dropped;
 *  6. Kalman update of the assigned tracks (then |p_pv| clamped to sqrt(p_pp p_vv) against rounding); the
 *     detection's yaw (turned by pi when more than pi / 2 off: the box net's heading flip) and z, l, w, h
 *     averaged in; a class vote (sum of scores per class);
 *  7. misses: a tentative track dies at its first miss, a confirmed one after more than max_misses in a row;
 *  8. births: each unassigned detection with score >= birth_min_score starts a tentative track in the lowest
 *     free slot (ids from 1, wrapping to 1 after 2^32 - 1); no free slot: counted, LIDET_TRUNCATED;
 *  9. a tentative track with confirm_hits hits is confirmed.
 * The reported yaw follows the motion (heading_from_velocity classes) or is turned by pi when it points
 * against it, once the speed is at least heading_speed and known (|v|^2 >= 4 p_vv).
 * Numpy mirror: codegen/lidet_ref/track.py (same float32 operations in the same order).
 *
 * Memory: sizeof(lidet_tracker_t) = LIDET_TRACK_MAX_TRACKS * (88 + 4 LIDET_TRACK_MAX_DETS + 4) B
 * + LIDET_TRACK_MAX_DETS * 3 B + (max(LIDET_TRACK_MAX_TRACKS, LIDET_TRACK_MAX_DETS) + 1) * 17 B + ~140 B:
 * 23,716 B at the defaults (64 tracks, 64 detections; x86-64 and 32-bit targets alike), of which 16 KiB is the
 * cost matrix;
 * lidet_tracker_bytes() gives the exact figure. Declare it static.
 * Time per update: O(T D) for the costs (T tracks, D detections) plus O(N^3) for the optimal assignment
 * (N = max(T, D)) or O(T D) plus O(D) per row whose cheapest detection another row took (at most
 * O(min(T, D) T D)) for the greedy one; O(T^2) for lidet_tracker_tracks. No allocation, no recursion. Measured
 * on an x86-64 desktop core, 64 tracks and 64 detections: about 20 us per update (either assignment). Code:
 * 4.1 KB (Cortex-M4F, -Os).
 */
#ifndef LIDET_TRACK_H
#define LIDET_TRACK_H

#include "lidet_detector.h"
#include "lidet_track_common.h"
#include "lidet_types.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Size of the optimal assignment's square matrix at most: max(LIDET_TRACK_MAX_TRACKS, LIDET_TRACK_MAX_DETS). */
#define LIDET_TRACK_ASSIGN_SIZE                                                                              \
    (LIDET_TRACK_MAX_TRACKS > LIDET_TRACK_MAX_DETS ? LIDET_TRACK_MAX_TRACKS : LIDET_TRACK_MAX_DETS)

/**
 * @brief Configuration (docs/TRACKING.md, Configuration). Fill with lidet_tracker_cfg_default(). Per-class
 *        arrays are indexed by lidet_class_t (car, cyclist, pedestrian).
 */
typedef struct
{
    float meas_sigma_m[LIDET_N_CLASSES];     /**< detection centre noise per axis, metres; [0.001, 100];
                                                    default 0.30, 0.25, 0.20 */
    float accel_sigma_mps2[LIDET_N_CLASSES]; /**< white-noise acceleration, m/s^2; [0, 100]; default 2.0, 2.5,
                                                    1.5 */
    float init_vel_sigma_mps[LIDET_N_CLASSES]; /**< a new track's velocity standard deviation, m/s; [0, 100];
                                                    default 10, 6, 3 */
    float gate_max_m[LIDET_N_CLASSES];         /**< no association beyond this centre distance (the track's
                                                    class), metres; (0, 1000]; default 4.0, 3.0, 2.0 */
    float gate_chi2;                         /**< Mahalanobis gate (2 dof); (0, 1000]; default 9.21 (99 %) */
    float class_penalty;                     /**< cost added when the classes differ; [0, 1000]; default 2 */
    uint32_t assign;                         /**< lidet_track_assign_t; default LIDET_TRACK_ASSIGN_OPTIMAL */
    uint32_t confirm_hits;                   /**< hits that confirm a tentative track; [1, 1000]; default 2 */
    uint32_t max_misses;                     /**< misses in a row a confirmed track survives; [0, 1000];
                                                    default 12 */
    uint32_t report_misses[LIDET_N_CLASSES]; /**< lidet_tracker_tracks without LIDET_TRACK_OUT_COASTING still
                                                    reports a confirmed track of the class that has missed at
                                                    most this many scans in a row (its predicted box, state
                                                    COASTING, det_index -1); [0, 1000]; default 1, 1, 0 */
    float birth_min_score;                   /**< detections scored below start no track; [0, 1]; default 0 */
    float yaw_alpha;                         /**< weight of a new yaw in the average; [0, 1]; default 0.5 */
    float size_alpha;                        /**< weight of a new z, l, w, h; [0, 1]; default 0.3 */
    float heading_speed_mps;                 /**< speed from which the reported heading follows the motion,
                                                    m/s; [0, 100]; default 1.0 */
    uint32_t heading_from_velocity;          /**< classes (bits 1 << lidet_class_t) whose reported heading
                                                    is the direction of motion; no bit >= LIDET_N_CLASSES;
                                                    default LIDET_TRACK_HEADING_FROM_VELOCITY_DEFAULT */
} lidet_tracker_cfg_t;

/** @brief The sensor's motion from the previous scan to this one, in the previous scan's sensor frame. */
typedef struct
{
    float dx_m;     /**< translation along the previous x, metres; |dx_m| <= 1000 */
    float dy_m;     /**< translation along the previous y, metres; |dy_m| <= 1000 */
    float dyaw_rad; /**< rotation about +z, radians; [-pi, pi] */
} lidet_ego_t;

/** @brief One track as lidet_tracker_tracks gives it (current sensor frame, velocities over the ground). */
typedef struct
{
    uint32_t id;       /**< stable id, >= 1 */
    uint8_t cls;       /**< lidet_class_t: the arg-max of the score votes (first on ties) */
    uint8_t state;     /**< lidet_track_state_t */
    lidet_box_t box;   /**< centre x, y from the filter; z, l, w, h averaged; the reported yaw */
    float vx_mps;      /**< velocity over the ground along the current sensor x, m/s */
    float vy_mps;      /**< ... along y */
    float p_pp_m2;     /**< position variance per axis, m^2 */
    float p_pv;        /**< position-velocity covariance per axis, m^2/s */
    float p_vv;        /**< velocity variance per axis, m^2/s^2 */
    float score;       /**< score of the last detection */
    uint32_t hits;     /**< detections assigned since birth (the birth's included) */
    uint32_t misses;   /**< scans in a row without a detection */
    uint32_t age;      /**< scans since birth (0 in the birth scan) */
    int32_t det_index; /**< index of this scan's detection in the update's array; -1 when coasting */
} lidet_track_t;

/** @brief Counts of the last update (n_tracks, n_confirmed: after it). */
typedef struct
{
    uint32_t n_tracks;         /**< live tracks */
    uint32_t n_confirmed;      /**< live confirmed tracks (updated or coasting) */
    uint32_t n_births;         /**< tracks born */
    uint32_t n_births_dropped; /**< births without a free slot (status LIDET_TRUNCATED) */
    uint32_t n_deaths;         /**< tracks that died (tentative and confirmed) */
    uint32_t n_matched;        /**< tracks updated by a detection */
    uint32_t n_feasible_pairs; /**< track-detection pairs inside the gates */
    uint32_t n_dets_dropped;   /**< detections past LIDET_TRACK_MAX_DETS (status LIDET_TRUNCATED) */
    uint32_t n_bad_dets;       /**< detections skipped: non-finite field, bad class, size <= 0 or too large */
} lidet_tracker_stats_t;

/** @brief A track slot of the state (internal; read tracks through lidet_tracker_tracks). 88 B. */
typedef struct
{
    uint32_t id;
    float x_m, y_m, vx_mps, vy_mps; /* filter state */
    float p_pp, p_pv, p_vv;         /* shared per-axis covariance */
    float z_m, l_m, w_m, h_m;       /* averaged box */
    float yaw_rad;                  /* averaged box yaw, heading flips folded out, (-pi, pi] */
    float votes[LIDET_N_CLASSES];   /* sum of the scores per class */
    float score;
    uint32_t hits, misses, age;
    int32_t det_index;
    uint8_t used;  /* 1: a live track */
    uint8_t state; /* lidet_track_state_t */
    uint8_t cls;   /* arg-max of votes */
    uint8_t pad;
} lidet_tracker_slot_t;

/** @brief The tracker: state across scans and the assignment's workspace. Caller-owned, fixed size; declare it
 *         static. */
typedef struct
{
    uint32_t magic;
    lidet_tracker_cfg_t cfg;
    uint32_t next_id;
    lidet_tracker_slot_t slot[LIDET_TRACK_MAX_TRACKS];
    lidet_tracker_stats_t stats;
    /* workspace of one update (not read across updates) */
    float cost[LIDET_TRACK_MAX_TRACKS * LIDET_TRACK_MAX_DETS]; /* rows: live slots; cols: valid dets */
    float hu[LIDET_TRACK_ASSIGN_SIZE + 1];                     /* Hungarian row potentials (1-based) */
    float hv[LIDET_TRACK_ASSIGN_SIZE + 1];                     /* column potentials */
    float hminv[LIDET_TRACK_ASSIGN_SIZE + 1];                  /* shortest path slack per column; greedy: the
                                                                  cheapest free cost of each row */
    uint16_t hp[LIDET_TRACK_ASSIGN_SIZE + 1];                  /* row matched to each column (0: none) */
    uint16_t hway[LIDET_TRACK_ASSIGN_SIZE + 1];                /* previous column on the path; greedy: the
                                                                  cheapest free column of each row */
    uint8_t hused[LIDET_TRACK_ASSIGN_SIZE + 1];                /* column in the path tree */
    uint16_t row_slot[LIDET_TRACK_MAX_TRACKS];                 /* slot of each row */
    int16_t row_col[LIDET_TRACK_MAX_TRACKS];                   /* column assigned to each row, -1: none */
    uint16_t col_det[LIDET_TRACK_MAX_DETS];                    /* detection index of each column */
    uint8_t col_taken[LIDET_TRACK_MAX_DETS];                   /* 1: column assigned */
} lidet_tracker_t;

/** @brief The defaults of docs/TRACKING.md's configuration table. @param[out] cfg filled (NULL: no-op). */
void lidet_tracker_cfg_default(lidet_tracker_cfg_t *cfg);

/**
 * @brief Validate the configuration and start with no track (next id 1).
 * @param[out] t   tracker (caller-owned, static).
 * @param[in]  cfg configuration (copied).
 * @return LIDET_OK; LIDET_ERR_ARG (NULL); LIDET_ERR_CONFIG (a field outside its documented range, or not
 *         finite; nothing is initialised).
 */
lidet_status_t lidet_tracker_init(lidet_tracker_t *t, const lidet_tracker_cfg_t *cfg);

/**
 * @brief Drop every track, restart the ids at 1 and clear the counts; the configuration stays.
 * @return LIDET_OK; LIDET_ERR_ARG (NULL); LIDET_ERR_STATE (not initialised).
 */
lidet_status_t lidet_tracker_reset(lidet_tracker_t *t);

/**
 * @brief Advance by one scan: ego motion, prediction, association, update, misses, births (file comment).
 * @param[in,out] t     initialised tracker.
 * @param[in]     det   n_det detections of this scan (the detector's, best score first), sensor frame; not
 *                      retained. May be NULL when n_det is 0.
 * @param[in]     n_det detections; only the first LIDET_TRACK_MAX_DETS are used.
 * @param[in]     dt_s  time since the previous scan, seconds; (0, 10].
 * @param[in]     ego   the sensor's motion since the previous scan (lidet_ego_t), or NULL: it did not move.
 * @return LIDET_OK; LIDET_TRUNCATED (detections past LIDET_TRACK_MAX_DETS or births without a free slot,
 *         counted in the stats; the update is complete otherwise); LIDET_ERR_ARG (NULL t, NULL det with
 *         n_det > 0, dt or ego out of range or not finite: nothing changes); LIDET_ERR_STATE (not
 *         initialised).
 */
lidet_status_t lidet_tracker_update(lidet_tracker_t *t, const lidet_detection_t *det, uint32_t n_det,
                                    float dt_s, const lidet_ego_t *ego);

/**
 * @brief Copy the tracks in id order: confirmed tracks updated by the last update always, and those that missed
 *        at most cfg.report_misses[class] scans in a row; every confirmed track that missed it with
 *        LIDET_TRACK_OUT_COASTING, tentative ones with LIDET_TRACK_OUT_TENTATIVE.
 * @param[in]  t     tracker (0 for NULL or not initialised).
 * @param[out] out   cap tracks; may be NULL when cap is 0.
 * @param[in]  cap   entries of out; the tracks past it (highest ids) are not copied.
 * @param[in]  flags LIDET_TRACK_OUT_COASTING | LIDET_TRACK_OUT_TENTATIVE, or 0.
 * @return tracks written (<= cap).
 */
uint32_t lidet_tracker_tracks(const lidet_tracker_t *t, lidet_track_t *out, uint32_t cap, uint32_t flags);

/** @brief Counts of the last update (NULL for NULL t). */
const lidet_tracker_stats_t *lidet_tracker_stats(const lidet_tracker_t *t);

/** @brief sizeof(lidet_tracker_t): the bytes a firmware must place. */
uint32_t lidet_tracker_bytes(void);

#ifdef __cplusplus
}
#endif

#endif /* LIDET_TRACK_H */
