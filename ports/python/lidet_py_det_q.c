/* SPDX-License-Identifier: MIT */
/* Flat C entry point over the integer detector (lidet_detector_q.h) for the Python bindings
 * (tools/lidet_tools/native/_detector.py: detect_q). Host only: one static detector (not reentrant); each call
 * initialises it. */
#include <string.h>

#include "lidet/lidet.h"
#include "lidet/lidet_detector_q.h"
#include "lidet_py_detq.h"
#include "lidet_weights.h"

#if defined(_WIN32)
#define LIDET_PY_API __declspec(dllexport)
#else
#define LIDET_PY_API __attribute__((visibility("default")))
#endif

static lidet_detector_q_t g_detq;

int lidet_py__detq_init_run(lidet_detector_q_t *det, const char *sensor, const char *cls_name,
                            const char *box_name, const int32_t *icfg, const int32_t *pts_mm, uint32_t n,
                            uint32_t stride, const lidet_return_t *returns, int32_t *point_pixel)
{
    static lidet_sensor_q_t mounted; /* the preset at another mount height (outlives the run) */
    const lidet_sensor_q_t *s = lidet_sensor_q_find(sensor);
    const lidet_pointnet_q_model_t *mc, *mb;
    lidet_detector_q_cfg_t cfg;
    int rc;
    if (s == NULL)
    {
        return LIDET_ERR_NOT_FOUND;
    }
    mc = lidet_pointnet_q_find(lidet_weights_models_s8, LIDET_WEIGHTS_N_MODELS_S8, cls_name);
    mb = lidet_pointnet_q_find(lidet_weights_models_s8, LIDET_WEIGHTS_N_MODELS_S8, box_name);
    if (mc == NULL || mb == NULL)
    {
        return LIDET_ERR_NOT_FOUND;
    }
    if (icfg[24] >= 0) /* the mount height in mm, as lidet detect --fixed --mount-height sets it */
    {
        if (icfg[24] > 10000)
        {
            return LIDET_ERR_CONFIG;
        }
        mounted = *s;
        mounted.mount_height_mm = icfg[24];
        s = &mounted;
    }
    lidet_detector_q_cfg_default(&cfg, s);
    cfg.crop_half_bam = icfg[0];
    cfg.max_range_mm = icfg[1];
    cfg.nms_iou_q15 = icfg[2];
    if (icfg[3] != 0)
    {
        cfg.max_proposals = (uint32_t)icfg[3];
    }
    cfg.gate1 = (uint8_t)icfg[4];
    cfg.gate2 = (uint8_t)icfg[5];
    if (icfg[6] != 0)
    {
        cfg.max_boxes = (uint32_t)icfg[6];
    }
    cfg.gate1_margin_q16 = icfg[7];
    cfg.gate2_margin_q16 = icfg[8];
    if (icfg[10] >= 0) /* the classes gate 2 judges, as bits (class k: bit k); -1: the default */
    {
        int k;
        for (k = 0; k < LIDET_N_CLASSES; ++k)
        {
            cfg.gate2_class[k] = (uint8_t)((icfg[10] >> k) & 1);
        }
    }
    if (icfg[11] >= 0) /* the group split; -1: the default for the sensor */
    {
        cfg.group_split = (uint8_t)(icfg[11] != 0);
    }
    {
        int k;
        for (k = 0; k < LIDET_N_CLASSES; ++k)
        {
            if (icfg[12 + k] >= 0) /* the operating point per class; -1: the default for the sensor */
            {
                cfg.min_score_q15[k] = icfg[12 + k];
            }
        }
    }
    if (icfg[15] >= 0) /* the cars' flat-surface test; -1: the default */
    {
        cfg.car_min_z_spread_mm = icfg[15];
    }
    {
        int k;
        for (k = 0; k < LIDET_N_CLASSES; ++k)
        {
            if (icfg[16 + k] != INT32_MIN) /* gate 1's margin per class; INT32_MIN: the default */
            {
                cfg.gate1_class_margin_q16[k] = icfg[16 + k];
            }
        }
    }
    if (icfg[19] >= 0) /* the car boxes' ground; -1: the default */
    {
        cfg.car_ground_mm = icfg[19];
    }
    if (icfg[20] >= 0) /* the group split's gate-1 margin; -1: the default */
    {
        cfg.group_gate1_margin_q16 = icfg[20];
    }
    if (icfg[21] >= 0) /* gate 1's margin for cars in large clusters; -1: the default */
    {
        cfg.gate1_large_car_margin_q16 = icfg[21];
    }
    if (icfg[9] >= 0) /* -1: the build's default */
    {
        cfg.range_only = (uint8_t)icfg[9];
    }
    cfg.stream_sectors = (uint8_t)(icfg[22] == 1); /* the ground stage sector by sector while streamed */
    rc = lidet_detector_q_init(det, &cfg, mc, mb);
    if (rc != LIDET_OK)
    {
        return rc;
    }
    if (returns != NULL && icfg[23] > 0)
    {
        /* the returns streamed icfg[23] at a time (lidet_detector_q_stream_*) */
        uint32_t at = 0;
        rc = lidet_detector_q_stream_begin(det);
        while (rc == LIDET_OK && at < n)
        {
            const uint32_t m = n - at < (uint32_t)icfg[23] ? n - at : (uint32_t)icfg[23];
            const int sr = lidet_detector_q_stream_returns(det, returns + at, m, NULL);
            rc = LIDET_SUCCEEDED(sr) ? LIDET_OK : sr;
            at += m;
        }
        return rc == LIDET_OK ? lidet_detector_q_stream_end(det) : rc;
    }
    return returns != NULL ? lidet_detector_q_run_returns(det, returns, n, point_pixel)
                           : lidet_detector_q_run(det, pts_mm, n, stride, NULL, point_pixel);
}

/* lidet_py_detq_run: icfg: crop_half_bam, max_range_mm, nms_iou_q15, max_proposals (0 = default), gate1, gate2,
 * max_boxes (0 = default), gate1_margin_q16, gate2_margin_q16, range_only (-1 = the build's default, 0, 1),
 * gate2_class as bits (bit k: class k; -1 = the default), group_split (0, 1; -1 = the default for the sensor),
 * min_score_q15 per class (3 entries, -1 = the default), car_min_z_spread_mm (-1 = the default),
 * gate1_class_margin_q16 per class (3 entries, INT32_MIN = the default), car_ground_mm (-1 = the default),
 * group_gate1_margin_q16 (-1 = the default), gate1_large_car_margin_q16 (-1 = the default), stream_sectors (1: on),
 * stream chunk (returns per lidet_detector_q_stream_returns call; 0: one run), mount height in mm (-1 = the preset's).
 * out_det: LIDET_MAX_DETECTIONS rows of 13 int32 (class, score_q15, energy_cls_q16, energy_box_q16, cx, cy, cz,
 * l, w, h (mm), yaw_bam, cluster id, n_points); out_outcome: LIDET_MAX_CLUSTERS bytes; out_stats: 23 uint32 (the
 * counts of lidet_detector_q_stats_t in order, then n_over_box_budget, n_too_tall, the three group counts and
 * n_score_rejected, n_stream_sectors, then the projection's n_points_in, n_out_of_fov, n_too_far and n_too_close).
 * returns: n lidet_return_t instead of the points (lidet_detector_q_run_returns; pts_mm ignored), or NULL. out_point_cluster (n uint32) and
 * out_point_ground (n bytes), both or neither (NULL): each point's cluster id and ground label (not with a stream).
 * Returns the run's status. */
LIDET_PY_API int lidet_py_detq_run(const char *sensor, const char *cls_name, const char *box_name,
                                   const int32_t *icfg, const int32_t *pts_mm, uint32_t n, uint32_t stride,
                                   int32_t *out_det, uint32_t *n_det, uint8_t *out_outcome,
                                   uint32_t *n_clusters, uint32_t *out_stats, const lidet_return_t *returns,
                                   uint32_t *out_point_cluster, uint8_t *out_point_ground)
{
    static int32_t point_pixel[LIDET_MAX_POINTS];
    const int per_point = out_point_cluster != NULL && out_point_ground != NULL;
    const lidet_detection_q_t *d;
    const lidet_detector_q_stats_t *st;
    const uint8_t *oc;
    uint32_t k;
    int rc;
    if (lidet_sensor_q_find(sensor) == NULL || icfg == NULL || out_det == NULL || n_det == NULL ||
        out_outcome == NULL || n_clusters == NULL || out_stats == NULL)
    {
        return lidet_sensor_q_find(sensor) == NULL ? LIDET_ERR_NOT_FOUND : LIDET_ERR_ARG;
    }
    if (per_point && (n > LIDET_MAX_POINTS || (returns != NULL && icfg[23] > 0)))
    {
        return LIDET_ERR_ARG; /* per-point labels: one run of at most LIDET_MAX_POINTS points or returns */
    }
    rc = lidet_py__detq_init_run(&g_detq, sensor, cls_name, box_name, icfg, pts_mm, n, stride, returns,
                                 per_point ? point_pixel : NULL);
    if (rc < 0)
    {
        return rc;
    }
    if (per_point)
    {
        /* each point's cluster id (the winner's of its pixel; 0: none) and ground label, from the run's buffers
         * (the ground mask of the build with x, y, z per pixel; without it, none is kept: every point 0) */
        int s = lidet_cluster_q_point_labels(&g_detq.cluster, point_pixel, n, out_point_cluster);
#if LIDET_Q_PIXEL_XYZ
        if (s == LIDET_OK)
        {
            s = lidet_ground_q_point_labels_of(&g_detq.ground, g_detq.mask, point_pixel, n, out_point_ground);
        }
#else
        memset(out_point_ground, 0, n);
#endif
        if (s != LIDET_OK)
        {
            return s;
        }
    }
    d = lidet_detector_q_detections(&g_detq, n_det);
    for (k = 0; k < *n_det; ++k)
    {
        int32_t *o = out_det + 13u * k;
        o[0] = d[k].cls;
        o[1] = d[k].score_q15;
        o[2] = d[k].energy_cls_q16;
        o[3] = d[k].energy_box_q16;
        o[4] = d[k].box.cx_mm;
        o[5] = d[k].box.cy_mm;
        o[6] = d[k].box.cz_mm;
        o[7] = d[k].box.l_mm;
        o[8] = d[k].box.w_mm;
        o[9] = d[k].box.h_mm;
        o[10] = d[k].box.yaw_bam;
        o[11] = d[k].cluster_id;
        o[12] = (int32_t)d[k].n_points;
    }
    oc = lidet_detector_q_outcomes(&g_detq, n_clusters);
    memcpy(out_outcome, oc, *n_clusters);
    st = lidet_detector_q_stats(&g_detq);
    {
        const uint32_t v[23] = {
            st->n_clusters,        st->n_out_of_crop,    st->n_out_of_range,  st->n_over_budget,
            st->n_classified,      st->n_gate1_rejected, st->n_boxed,         st->n_gate2_rejected,
            st->n_size_rejected,   st->n_nms_suppressed, st->n_over_capacity, st->n_detections,
            st->n_over_box_budget, st->n_too_tall,       st->n_group_split,   st->n_group_classified,
            st->n_group_boxed,     st->n_score_rejected, st->n_stream_sectors,
            /* the projection's counts: the bindings' frame check (native.frame_warning) */
            st->proj.n_points_in,  st->proj.n_out_of_fov, st->proj.n_too_far,   st->proj.n_too_close};
        memcpy(out_stats, v, sizeof v);
    }
    return rc;
}

LIDET_PY_API uint32_t lidet_py_detq_bytes(void)
{
    return lidet_detector_q_bytes();
}
