/* SPDX-License-Identifier: MIT */
/* Flat C entry points over the integer post-processing (lidet_detector_q.h) and the float BEV IoU, for
 * tests/python/test_post_q.py (through tools/lidet_tools/native/_detector.py). */
#include <stddef.h>

#include "lidet/lidet.h"
#include "lidet/lidet_detector_q.h"

#if defined(_WIN32)
#define LIDET_PY_API __declspec(dllexport)
#else
#define LIDET_PY_API __attribute__((visibility("default")))
#endif

static void to_box(const int32_t *v, lidet_box_q_t *b)
{
    b->cx_mm = v[0];
    b->cy_mm = v[1];
    b->cz_mm = v[2];
    b->l_mm = v[3];
    b->w_mm = v[4];
    b->h_mm = v[5];
    b->yaw_bam = v[6];
}

/* n pairs of boxes (7 int32 each) -> Q15 IoU */
LIDET_PY_API int lidet_py_q_bev_iou(const int32_t *a, const int32_t *b, uint32_t n, int32_t *out)
{
    uint32_t i;
    if (a == NULL || b == NULL || out == NULL)
    {
        return LIDET_ERR_ARG;
    }
    for (i = 0; i < n; ++i)
    {
        lidet_box_q_t ba, bb;
        to_box(a + 7u * i, &ba);
        to_box(b + 7u * i, &bb);
        out[i] = lidet_box_q_bev_iou(&ba, &bb);
    }
    return LIDET_OK;
}

/* n pairs of float boxes (7 floats each: cx cy cz l w h yaw) -> float IoU (lidet_box_bev_iou) */
LIDET_PY_API int lidet_py_bev_iou(const float *a, const float *b, uint32_t n, float *out)
{
    uint32_t i;
    if (a == NULL || b == NULL || out == NULL)
    {
        return LIDET_ERR_ARG;
    }
    for (i = 0; i < n; ++i)
    {
        const float *u = a + 7u * i, *v = b + 7u * i;
        const lidet_box_t ba = {u[0], u[1], u[2], u[3], u[4], u[5], u[6]};
        const lidet_box_t bb = {v[0], v[1], v[2], v[3], v[4], v[5], v[6]};
        out[i] = lidet_box_bev_iou(&ba, &bb);
    }
    return LIDET_OK;
}

/* n detections: boxes (7 int32), score_q15, cluster_id, cls -> inserted one by one (sorted), size-checked
 * flags (size_ok out, in input order), then NMS; order_out: the kept detections' cluster ids in order;
 * suppressed: per sorted position. Returns the number kept, or a negative status. */
LIDET_PY_API int lidet_py_q_post(const int32_t *boxes, const int32_t *score, const uint16_t *cluster_id,
                                 const uint8_t *cls, uint32_t n, int32_t iou_q15, uint8_t *size_ok,
                                 uint16_t *order_out, uint8_t *suppressed)
{
    static lidet_detection_q_t det[LIDET_MAX_DETECTIONS];
    lidet_size_limits_q_t lim;
    uint32_t i;
    if (boxes == NULL || score == NULL || cluster_id == NULL || cls == NULL || size_ok == NULL ||
        order_out == NULL || suppressed == NULL || n > LIDET_MAX_DETECTIONS)
    {
        return LIDET_ERR_ARG;
    }
    lidet_size_limits_q_default(&lim);
    for (i = 0; i < n; ++i)
    {
        to_box(boxes + 7u * i, &det[i].box);
        det[i].score_q15 = score[i];
        det[i].cluster_id = cluster_id[i];
        det[i].cls = cls[i];
        size_ok[i] = (uint8_t)lidet_size_ok_q(&lim, cls[i], &det[i].box);
        lidet_detections_q_insert(det, i);
    }
    n = lidet_detections_q_nms(det, n, iou_q15, suppressed);
    for (i = 0; i < n; ++i)
    {
        order_out[i] = det[i].cluster_id;
    }
    return (int)n;
}
