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
 * codegen/lidet_codegen/ref/post_q.py.
 */
#ifndef LIDET_DETECTOR_Q_H
#define LIDET_DETECTOR_Q_H

#include "lidet_q.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Box sizes the size check and the IoU accept: l, w, h in [1, LIDET_Q_BOX_MAX_MM] mm. */
#define LIDET_Q_BOX_MAX_MM 50000

/** @brief One detection of the integer path. */
typedef struct
{
    lidet_box_q_t box;        /**< sensor frame, mm, BAM32 yaw */
    int32_t score_q15;        /**< (0, 32768) */
    int32_t energy_cls_q16;   /**< classifier energy (gate 1), Q16 nats */
    int32_t energy_box_q16;   /**< box net energy (gate 2), Q16 nats */
    uint16_t cluster_id;      /**< 1-based id of the cluster it came from */
    uint8_t cls;              /**< lidet_class_t */
    uint8_t reserved;
    uint32_t n_points;        /**< member points of that cluster */
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
 *        with an already kept one is > iou_q15; the kept ones move to the front in order.
 * @param[out] suppressed optional (NULL): 1 per input detection that was dropped, else 0 (input order).
 * @return the number kept; 0 for NULL det.
 */
uint32_t lidet_detections_q_nms(lidet_detection_q_t *det, uint32_t n, int32_t iou_q15, uint8_t *suppressed);

#ifdef __cplusplus
}
#endif

#endif /* LIDET_DETECTOR_Q_H */
