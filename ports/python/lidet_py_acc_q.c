/* SPDX-License-Identifier: MIT */
/* The candidate proposals of both detectors, for the int8 accuracy ablations (tools/bench/ablate_q.py:
 * integer geometry with the float nets, float geometry with the int8 nets). Each entry point runs its detector
 * on one scan (the detector's own static copy: not reentrant), then rebuilds the proposal of every classified
 * candidate, in the detector's order (nearest first), from the run's clustering: the proposals the detector's
 * classifier saw, bit for bit. Host only. */
#include <string.h>

#include "lidet/lidet.h"
#include "lidet/lidet_detector_q.h"
#include "lidet_weights.h"
#include "lidet_py_detq.h"

#if defined(_WIN32)
#define LIDET_PY_API __declspec(dllexport)
#else
#define LIDET_PY_API __attribute__((visibility("default")))
#endif

static lidet_detector_t g_acc_det;
static lidet_detector_q_t g_acc_detq;
static lidet_proposal_t g_prop;
static lidet_proposal_q_t g_prop_q;

static int make_f(uint32_t ci, void *prop)
{
    return lidet_workspace_proposal(lidet_detector_workspace(&g_acc_det), ci, &g_acc_det.cfg.proposal,
                                    (lidet_proposal_t *)prop);
}

static int make_q(uint32_t ci, void *prop)
{
    return lidet_proposal_q_make(&g_acc_detq.cluster, ci, &g_acc_detq.cfg.proposal, (lidet_proposal_q_t *)prop);
}

/* After a run with status rc (returned as is when < 0): the proposal of each of the n candidates order[0..n)
 * made by make() into *prop, whose points (np x 3 of elem bytes), mean and voxel (pts, pmean, pvox: inside *prop)
 * are copied into the k-th output rows. Returns rc, or make()'s error. */
static int put_cands(int rc, uint32_t n, uint32_t np, const uint16_t *order, int (*make)(uint32_t, void *),
                     void *prop, const void *pts, size_t elem, const void *pmean, size_t mean_bytes,
                     const int16_t *pvox, void *xyz, void *mean, int16_t *voxel, uint32_t *cluster_id,
                     uint32_t *n_cand, uint32_t *n_points)
{
    uint32_t k;
    if (rc < 0)
    {
        return rc;
    }
    *n_cand = n;
    *n_points = np;
    for (k = 0; k < n; ++k)
    {
        const int r = make(order[k], prop);
        if (r != LIDET_OK)
        {
            return r;
        }
        memcpy((char *)xyz + k * np * 3u * elem, pts, np * 3u * elem);
        memcpy((char *)mean + k * mean_bytes, pmean, mean_bytes);
        memcpy(voxel + 3u * k, pvox, 3u * sizeof(int16_t));
        cluster_id[k] = order[k] + 1u;
    }
    return rc;
}

/* fcfg: crop_half_rad, max_range_m; ucfg: max_proposals (0 = the default), refine. Per candidate k (at most
 * LIDET_MAX_CLUSTERS): xyz[k] n_points x 3 floats (metres, minus the mean), mean[k] 3 floats, voxel[k] 3 int16,
 * cluster_id[k] (1-based). n_points: the models' points per proposal. Returns the run's status. */
LIDET_PY_API int lidet_py_acc_cands(const char *sensor, uint32_t cls_index, uint32_t box_index, const float *fcfg,
                                    const uint32_t *ucfg, const float *pts, uint32_t n, uint32_t stride,
                                    float *xyz, float *mean, int16_t *voxel, uint32_t *cluster_id, uint32_t *n_cand,
                                    uint32_t *n_points)
{
    const lidet_sensor_t *s = lidet_sensor_find(sensor);
    lidet_detector_cfg_t cfg;
    int rc;
    if (s == NULL || cls_index >= LIDET_WEIGHTS_N_MODELS || box_index >= LIDET_WEIGHTS_N_MODELS)
    {
        return LIDET_ERR_NOT_FOUND;
    }
    lidet_detector_cfg_default(&cfg, s);
    cfg.crop_half_rad = fcfg[0];
    cfg.max_range_m = fcfg[1];
    if (ucfg[0] != 0)
    {
        cfg.max_proposals = ucfg[0];
    }
    cfg.stages.cluster.split_people = ucfg[1] != 0u;
    cfg.stages.cluster.join_cars = ucfg[1] != 0u;
    cfg.group_split = 0u; /* the candidates are the clusters classified: no group's parts among them */
    rc = lidet_detector_init(&g_acc_det, &cfg, lidet_weights_models[cls_index].model,
                             lidet_weights_models[box_index].model);
    if (rc == LIDET_OK)
    {
        rc = lidet_detector_run(&g_acc_det, pts, n, stride, NULL, NULL);
    }
    return put_cands(rc, lidet_detector_stats(&g_acc_det)->n_classified, g_acc_det.cfg.proposal.n_points,
                     g_acc_det.order, make_f, &g_prop, g_prop.xyz, sizeof(float), g_prop.mean_m, sizeof g_prop.mean_m,
                     g_prop.voxel, xyz, mean, voxel, cluster_id, n_cand, n_points);
}

/* The integer detector's candidates: icfg: crop_half_bam, max_range_mm, max_proposals (0 = the default);
 * xyz[k] n_points x 3 int16 (4 mm steps, minus the mean), mean[k] 3 int32 (4 mm), voxel[k] 3 int16. */
LIDET_PY_API int lidet_py_acc_cands_q(const char *sensor, const char *cls_name, const char *box_name,
                                      const int32_t *icfg, const int32_t *pts_mm, uint32_t n, uint32_t stride,
                                      int16_t *xyz, int32_t *mean, int16_t *voxel, uint32_t *cluster_id,
                                      uint32_t *n_cand, uint32_t *n_points)
{
    /* NMS, gates, box budget, pixel, gate 2's classes: the defaults; no group split (the candidates are the
     * clusters classified); the layout of lidet_py_detq_run's icfg */
    const int32_t cfg6[LIDET_PY_DETQ_ICFG] = {icfg[0], icfg[1], 3277, icfg[2], 1, 1, 0, 0, 0, -1, -1,
                                              0, -1, -1, -1, -1, INT32_MIN, INT32_MIN, INT32_MIN, -1, -1, -1,
                                              0, 0, -1};
    const int rc =
        lidet_py__detq_init_run(&g_acc_detq, sensor, cls_name, box_name, cfg6, pts_mm, n, stride, NULL, NULL);
    return put_cands(rc, lidet_detector_q_stats(&g_acc_detq)->n_classified, g_acc_detq.cfg.proposal.n_points,
                     g_acc_detq.order, make_q, &g_prop_q, g_prop_q.xyz, sizeof(int16_t), g_prop_q.mean_4mm,
                     sizeof g_prop_q.mean_4mm, g_prop_q.voxel, xyz, mean, voxel, cluster_id, n_cand, n_points);
}

/* The cluster size (lidet_cluster_rec_t / _q_t n_points: what the detectors' score reads) of the last run's
 * candidates, in the same order: q = 0 the float detector's (lidet_py_acc_cands), 1 the integer one's. */
LIDET_PY_API int lidet_py_acc_cand_points(int q, uint32_t n_cand, uint32_t *out)
{
    uint32_t k;
    if (q)
    {
        if (n_cand > lidet_detector_q_stats(&g_acc_detq)->n_classified)
        {
            return LIDET_ERR_ARG;
        }
        for (k = 0; k < n_cand; ++k)
        {
            out[k] = g_acc_detq.cluster.recs[g_acc_detq.order[k]].n_points;
        }
        return LIDET_OK;
    }
    if (n_cand > lidet_detector_stats(&g_acc_det)->n_classified)
    {
        return LIDET_ERR_ARG;
    }
    {
        uint32_t nc = 0;
        const lidet_cluster_rec_t *recs = lidet_workspace_clusters(lidet_detector_workspace(&g_acc_det), &nc);
        for (k = 0; k < n_cand; ++k)
        {
            out[k] = recs[g_acc_det.order[k]].n_points;
        }
    }
    return LIDET_OK;
}
