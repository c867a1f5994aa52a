/* SPDX-License-Identifier: MIT */
/* Flat C entry points over the whole detector (lidet_detector.h) for the Python bindings: one scan in,
 * detections, per-cluster outcomes and per-point labels out; the sensor a preset by name (lidet_py_det_run) or a
 * table (lidet_py_det_run_table: a sensor read from a file, native.detect(points, Sensor)). Host only: one static
 * detector, so calls are not reentrant; each call initialises it (the configuration may change between calls). */
#include <stdlib.h>
#include <string.h>

#include "lidet/lidet.h"
#include "lidet_weights.h"

#if defined(_WIN32)
#define LIDET_PY_API __declspec(dllexport)
#else
#define LIDET_PY_API __attribute__((visibility("default")))
#endif

static lidet_detector_t g_det;
static int32_t g_pp[LIDET_MAX_POINTS];

/* fcfg: crop_half_rad, max_range_m, nms_iou, gate1_margin, gate2_margin, mount_height_m (< 0: the profile's),
 * min_score per class (3 entries, < 0: the default for the sensor), car_min_z_spread_m (< 0: the default),
 * gate1_class_margin per class (3 entries, NaN: the default), car_ground_m (< 0: the default),
 * group_gate1_margin (< 0: the default), gate1_large_car_margin (< 0: the default);
 * ucfg: max_proposals (0 = the default), gate1, gate2, refine (the clustering's split_people and join_cars),
 * gate2_class as bits (bit k: class k, lidet_class_t order; 0xFFFFFFFF = the default), group_split (0, 1;
 * 0xFFFFFFFF = the default for the sensor).
 * out_det: LIDET_MAX_DETECTIONS rows of 12 floats (class, score, energy_cls, energy_box, cx, cy, cz, l, w, h,
 * yaw, cluster id); out_outcome: LIDET_MAX_CLUSTERS bytes; out_point_cluster / out_point_ground: n entries
 * (may be NULL); out_stats: 22 uint32 (the lidet_detector_stats_t counts in order, the status, then
 * n_over_box_budget, n_too_tall, the three group counts, n_score_rejected, and the projection's n_points_in,
 * n_out_of_fov and n_too_far). */
static int det_run(const lidet_sensor_t *s, uint32_t cls_index, uint32_t box_index, const float *fcfg,
                   const uint32_t *ucfg, const float *pts, uint32_t n, uint32_t stride, float *out_det,
                   uint32_t *n_det, uint8_t *out_outcome, uint32_t *n_clusters, uint32_t *out_point_cluster,
                   uint8_t *out_point_ground, uint32_t *out_stats)
{
    lidet_sensor_t mounted;
    lidet_detector_cfg_t cfg;
    const lidet_detection_t *d;
    const lidet_detector_stats_t *st;
    const uint8_t *oc;
    uint32_t k, m = n < LIDET_MAX_POINTS ? n : LIDET_MAX_POINTS;
    int rc;
    if (s == NULL)
    {
        return LIDET_ERR_NOT_FOUND;
    }
    if (cls_index >= LIDET_WEIGHTS_N_MODELS || box_index >= LIDET_WEIGHTS_N_MODELS)
    {
        return LIDET_ERR_NOT_FOUND;
    }
    if (fcfg[5] >= 0.0f) /* the sensor's height above the ground; < 0: the profile's */
    {
        mounted = *s;
        mounted.mount_height_m = fcfg[5];
        s = &mounted;
    }
    lidet_detector_cfg_default(&cfg, s);
    cfg.crop_half_rad = fcfg[0];
    cfg.max_range_m = fcfg[1];
    cfg.nms_iou = fcfg[2];
    cfg.gate1_margin = fcfg[3];
    cfg.gate2_margin = fcfg[4];
    if (ucfg[0] != 0) /* 0: the C default for the sensor */
    {
        cfg.max_proposals = ucfg[0];
    }
    cfg.gate1 = (uint8_t)ucfg[1];
    cfg.gate2 = (uint8_t)ucfg[2];
    if (ucfg[4] != 0xFFFFFFFFu) /* the classes gate 2 judges; all ones: the default */
    {
        for (k = 0; k < LIDET_N_CLASSES; ++k)
        {
            cfg.gate2_class[k] = (uint8_t)((ucfg[4] >> k) & 1u);
        }
    }
    if (ucfg[5] != 0xFFFFFFFFu) /* the group split; all ones: the default for the sensor */
    {
        cfg.group_split = (uint8_t)(ucfg[5] != 0u);
    }
    for (k = 0; k < LIDET_N_CLASSES; ++k)
    {
        if (fcfg[6 + k] >= 0.0f) /* the operating point; < 0: the default for the sensor */
        {
            cfg.min_score[k] = fcfg[6 + k];
        }
    }
    if (fcfg[9] >= 0.0f) /* the cars' flat-surface test; < 0: the default */
    {
        cfg.car_min_z_spread_m = fcfg[9];
    }
    for (k = 0; k < LIDET_N_CLASSES; ++k)
    {
        if (fcfg[10 + k] == fcfg[10 + k]) /* gate 1's margin per class; NaN: the default */
        {
            cfg.gate1_class_margin[k] = fcfg[10 + k];
        }
    }
    if (fcfg[13] >= 0.0f) /* the car boxes' ground; < 0: the default */
    {
        cfg.car_ground_m = fcfg[13];
    }
    if (fcfg[14] >= 0.0f) /* the group split's gate-1 margin; < 0: the default */
    {
        cfg.group_gate1_margin = fcfg[14];
    }
    if (fcfg[15] >= 0.0f) /* gate 1's margin for cars in large clusters; < 0: the default */
    {
        cfg.gate1_large_car_margin = fcfg[15];
    }
    cfg.stages.cluster.split_people = ucfg[3] != 0u; /* the proposal refinement (lidet_refine.c) */
    cfg.stages.cluster.join_cars = ucfg[3] != 0u;
    rc = lidet_detector_init(&g_det, &cfg, lidet_weights_models[cls_index].model,
                             lidet_weights_models[box_index].model);
    if (rc != LIDET_OK)
    {
        return rc;
    }
    rc = lidet_detector_run(&g_det, pts, n, stride, NULL, g_pp);
    if (rc < 0)
    {
        return rc;
    }
    d = lidet_detector_detections(&g_det, n_det);
    for (k = 0; k < *n_det; ++k)
    {
        float *o = out_det + 12u * k;
        o[0] = (float)d[k].cls;
        o[1] = d[k].score;
        o[2] = d[k].energy_cls;
        o[3] = d[k].energy_box;
        o[4] = d[k].box.cx_m;
        o[5] = d[k].box.cy_m;
        o[6] = d[k].box.cz_m;
        o[7] = d[k].box.l_m;
        o[8] = d[k].box.w_m;
        o[9] = d[k].box.h_m;
        o[10] = d[k].box.yaw_rad;
        o[11] = (float)d[k].cluster_id;
    }
    oc = lidet_detector_outcomes(&g_det, n_clusters);
    memcpy(out_outcome, oc, *n_clusters);
    if (out_point_cluster != NULL || out_point_ground != NULL)
    {
        uint32_t *ids = out_point_cluster;
        uint8_t *gnd = out_point_ground;
        int r2 = lidet_workspace_point_labels(lidet_detector_workspace(&g_det), g_pp, m, ids, gnd);
        if (r2 != LIDET_OK)
        {
            return r2;
        }
        for (k = m; k < n; ++k)
        {
            if (ids != NULL)
                ids[k] = 0;
            if (gnd != NULL)
                gnd[k] = 0;
        }
    }
    st = lidet_detector_stats(&g_det);
    out_stats[0] = st->n_clusters;
    out_stats[1] = st->n_out_of_crop;
    out_stats[2] = st->n_out_of_range;
    out_stats[3] = st->n_over_budget;
    out_stats[4] = st->n_classified;
    out_stats[5] = st->n_gate1_rejected;
    out_stats[6] = st->n_boxed;
    out_stats[7] = st->n_gate2_rejected;
    out_stats[8] = st->n_size_rejected;
    out_stats[9] = st->n_nms_suppressed;
    out_stats[10] = st->n_over_capacity;
    out_stats[11] = st->n_detections;
    out_stats[12] = (uint32_t)rc;
    out_stats[13] = st->n_over_box_budget;
    out_stats[14] = st->n_too_tall;
    out_stats[15] = st->n_group_split;
    out_stats[16] = st->n_group_classified;
    out_stats[17] = st->n_group_boxed;
    out_stats[18] = st->n_score_rejected;
    out_stats[19] = st->stages.proj.n_points_in; /* the projection's counts: the bindings' frame check */
    out_stats[20] = st->stages.proj.n_out_of_fov;
    out_stats[21] = st->stages.proj.n_too_far;
    return rc;
}

LIDET_PY_API int lidet_py_det_run(const char *sensor, uint32_t cls_index, uint32_t box_index,
                                  const float *fcfg, const uint32_t *ucfg, const float *pts, uint32_t n,
                                  uint32_t stride, float *out_det, uint32_t *n_det, uint8_t *out_outcome,
                                  uint32_t *n_clusters, uint32_t *out_point_cluster,
                                  uint8_t *out_point_ground, uint32_t *out_stats)
{
    /* a preset: exactly the profile lidet_sensor_find gives the CLI's --sensor */
    return det_run(lidet_sensor_find(sensor), cls_index, box_index, fcfg, ucfg, pts, n, stride, out_det,
                   n_det, out_outcome, n_clusters, out_point_cluster, out_point_ground, out_stats);
}

/* The same with the sensor given as its table: rows x cols, elev_rad (rows elevations in ring order, radians),
 * mount height and nominal range in metres (name informational, may be NULL). Errors of the table (count, order,
 * duplicates) come back from lidet_detector_init as LIDET_ERR_CONFIG. */
LIDET_PY_API int lidet_py_det_run_table(const char *name, uint32_t rows, uint32_t cols, const float *elev_rad,
                                        float mount_height_m, float max_range_m, uint32_t cls_index,
                                        uint32_t box_index, const float *fcfg, const uint32_t *ucfg,
                                        const float *pts, uint32_t n, uint32_t stride, float *out_det,
                                        uint32_t *n_det, uint8_t *out_outcome, uint32_t *n_clusters,
                                        uint32_t *out_point_cluster, uint8_t *out_point_ground,
                                        uint32_t *out_stats)
{
    lidet_sensor_t s;
    if (elev_rad == NULL || rows == 0u || rows > LIDET_MAX_ROWS || cols > LIDET_MAX_COLS)
    {
        return LIDET_ERR_CONFIG;
    }
    memset(&s, 0, sizeof s);
    s.name = name;
    s.n_rows = (uint16_t)rows;
    s.n_cols = (uint16_t)cols;
    s.beam_elev_rad = elev_rad;
    s.mount_height_m = mount_height_m;
    s.max_range_m = max_range_m;
    return det_run(&s, cls_index, box_index, fcfg, ucfg, pts, n, stride, out_det, n_det, out_outcome,
                   n_clusters, out_point_cluster, out_point_ground, out_stats);
}
