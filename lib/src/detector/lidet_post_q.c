/* SPDX-License-Identifier: MIT */
/* The integer path's post-processing (lidet_detector_q.h): size check, rotated BEV IoU, score order, NMS.
 * Integers only; mirrored bit for bit by codegen/lidet_ref/post_q.py. */
#include <string.h>

#include "internal/lidet_group_common.h" /* LIDET_GROUP_NMS_IOU_Q15 */
#include "internal/lidet_qmath.h"
#include "lidet/lidet_detector_q.h"

/* the float detector's limits (lidet_detector.c) in mm */
static const int32_t SIZE_MIN_MM[LIDET_N_CLASSES][3] = {{2000, 1200, 900}, {800, 200, 800}, {200, 200, 700}};
static const int32_t SIZE_MAX_MM[LIDET_N_CLASSES][3] = {
    {7500, 3000, 3200}, {2600, 1500, 2400}, {1600, 1600, 2400}};

#define MAX_CENTRE_MM (1 << 20) /* centres farther apart never overlap (and keep the IoU's int64 bounded) */
#define MAX_VERTS 16

void lidet_size_limits_q_default(lidet_size_limits_q_t *lim)
{
    if (lim != 0)
    {
        memcpy(lim->min_mm, SIZE_MIN_MM, sizeof SIZE_MIN_MM);
        memcpy(lim->max_mm, SIZE_MAX_MM, sizeof SIZE_MAX_MM);
    }
}

static int size_valid(const lidet_box_q_t *b)
{
    return b->l_mm >= 1 && b->l_mm <= LIDET_Q_BOX_MAX_MM && b->w_mm >= 1 && b->w_mm <= LIDET_Q_BOX_MAX_MM &&
           b->h_mm >= 1 && b->h_mm <= LIDET_Q_BOX_MAX_MM;
}

int lidet_size_ok_q(const lidet_size_limits_q_t *lim, uint32_t cls, const lidet_box_q_t *b)
{
    uint32_t j;
    if (lim == 0 || b == 0 || cls >= (uint32_t)LIDET_N_CLASSES || !size_valid(b))
    {
        return 0;
    }
    for (j = 0; j < 3u; ++j)
    {
        const int32_t x = j == 0u ? b->l_mm : (j == 1u ? b->w_mm : b->h_mm);
        if (x < lim->min_mm[cls][j] || x > lim->max_mm[cls][j])
        {
            return 0;
        }
    }
    return 1;
}

/* corners of b, counter-clockwise, in half-millimetres relative to (ox, oy) (mm) */
static void corners(const lidet_box_q_t *b, int32_t ox, int32_t oy, int64_t *xy)
{
    const int64_t c = lidet__q_cos((uint32_t)b->yaw_bam), s = lidet__q_sin((uint32_t)b->yaw_bam);
    const int64_t cx = 2 * ((int64_t)b->cx_mm - ox), cy = 2 * ((int64_t)b->cy_mm - oy);
    const int64_t dl[4] = {b->l_mm, -(int64_t)b->l_mm, -(int64_t)b->l_mm, b->l_mm};
    const int64_t dw[4] = {b->w_mm, b->w_mm, -(int64_t)b->w_mm, -(int64_t)b->w_mm};
    uint32_t k;
    for (k = 0; k < 4u; ++k)
    {
        xy[2u * k] = cx + lidet__q_rshift_round(c * dl[k] - s * dw[k], 30);
        xy[2u * k + 1u] = cy + lidet__q_rshift_round(s * dl[k] + c * dw[k], 30);
    }
}

/* clip polygon p (n vertices, counter-clockwise) by the half-plane left of a -> b */
static uint32_t clip(const int64_t *p, uint32_t n, const int64_t *a, const int64_t *b, int64_t *out)
{
    uint32_t i, m = 0;
    for (i = 0; i < n && m + 2u <= MAX_VERTS; ++i)
    {
        const int64_t *u = p + 2u * i, *v = p + 2u * ((i + 1u) % n);
        const int64_t su = (b[0] - a[0]) * (u[1] - a[1]) - (b[1] - a[1]) * (u[0] - a[0]);
        const int64_t sv = (b[0] - a[0]) * (v[1] - a[1]) - (b[1] - a[1]) * (v[0] - a[0]);
        if (su >= 0)
        {
            out[2u * m] = u[0];
            out[2u * m + 1u] = u[1];
            ++m;
        }
        if ((su >= 0) != (sv >= 0))
        {
            /* u + t (v - u), t = su / (su - sv), rounded per coordinate */
            const int64_t num_sign = su - sv > 0 ? 1 : -1, den = (su - sv) * num_sign;
            out[2u * m] = u[0] + lidet__q_div_round(su * num_sign * (v[0] - u[0]), den);
            out[2u * m + 1u] = u[1] + lidet__q_div_round(su * num_sign * (v[1] - u[1]), den);
            ++m;
        }
    }
    return m;
}

int32_t lidet_box_q_bev_iou(const lidet_box_q_t *a, const lidet_box_q_t *b)
{
    int64_t pa[8], pb[8], buf0[2 * MAX_VERTS], buf1[2 * MAX_VERTS], dx, dy, rab, inter2 = 0, union2;
    uint32_t n = 4u, k;
    if (a == 0 || b == 0 || !size_valid(a) || !size_valid(b))
    {
        return 0;
    }
    dx = (int64_t)b->cx_mm - a->cx_mm;
    dy = (int64_t)b->cy_mm - a->cy_mm;
    if (dx > MAX_CENTRE_MM || dx < -MAX_CENTRE_MM || dy > MAX_CENTRE_MM || dy < -MAX_CENTRE_MM)
    {
        return 0;
    }
    /* farther apart than both half diagonals (bounded by (l + w) / 2 each): no overlap; in half-mm */
    rab = (int64_t)a->l_mm + a->w_mm + b->l_mm + b->w_mm;
    if (4 * (dx * dx + dy * dy) > rab * rab)
    {
        return 0;
    }
    corners(a, a->cx_mm, a->cy_mm, pa);
    corners(b, a->cx_mm, a->cy_mm, pb);
    memcpy(buf0, pa, sizeof pa);
    for (k = 0; k < 4u && n > 0u; ++k)
    {
        n = clip(buf0, n, pb + 2u * k, pb + 2u * ((k + 1u) % 4u), buf1);
        memcpy(buf0, buf1, 2u * n * sizeof(int64_t));
    }
    if (n < 3u)
    {
        return 0;
    }
    for (k = 0; k < n; ++k)
    {
        const int64_t *u = buf0 + 2u * k, *v = buf0 + 2u * ((k + 1u) % n);
        inter2 += u[0] * v[1] - v[0] * u[1];
    }
    inter2 = inter2 < 0 ? -inter2 : inter2; /* twice the area, half-mm^2 */
    /* twice a box's area in half-mm^2: 2 * (2 l)(2 w) = 8 l w */
    union2 = 8 * ((int64_t)a->l_mm * a->w_mm + (int64_t)b->l_mm * b->w_mm) - inter2;
    if (inter2 == 0 || union2 <= 0)
    {
        return 0;
    }
    return (int32_t)((inter2 << 15) / union2);
}

void lidet_detections_q_insert(lidet_detection_q_t *det, uint32_t n)
{
    lidet_detection_q_t t;
    uint32_t i = n;
    if (det == 0)
    {
        return;
    }
    t = det[n];
    while (i > 0u && (det[i - 1u].score_q15 < t.score_q15 ||
                      (det[i - 1u].score_q15 == t.score_q15 && det[i - 1u].cluster_id > t.cluster_id)))
    {
        det[i] = det[i - 1u];
        --i;
    }
    det[i] = t;
}

uint32_t lidet_detections_q_nms(lidet_detection_q_t *det, uint32_t n, int32_t iou_q15, uint8_t *suppressed)
{
    const int32_t own = iou_q15 > LIDET_GROUP_NMS_IOU_Q15 ? iou_q15 : LIDET_GROUP_NMS_IOU_Q15;
    uint32_t i, j, kept = 0;
    if (det == 0)
    {
        return 0;
    }
    for (i = 0; i < n; ++i)
    {
        int drop = 0;
        for (j = 0; j < kept && !drop; ++j)
        {
            /* two parts of one group cut (one cluster id): past LIDET_GROUP_NMS_IOU_Q15 as well */
            drop = lidet_box_q_bev_iou(&det[i].box, &det[j].box) >
                   (det[i].cluster_id != det[j].cluster_id ? iou_q15 : own);
        }
        if (suppressed != 0)
        {
            suppressed[i] = (uint8_t)drop;
        }
        if (!drop)
        {
            det[kept++] = det[i];
        }
    }
    return kept;
}
