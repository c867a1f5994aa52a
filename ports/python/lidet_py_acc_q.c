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

#if defined(_WIN32)
#define LIDET_PY_API __declspec(dllexport)
#else
#define LIDET_PY_API __attribute__((visibility("default")))
#endif

static lidet_detector_t g_acc_det;
static lidet_detector_q_t g_acc_detq;

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
    uint32_t k, np;
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
    rc = lidet_detector_init(&g_acc_det, &cfg, lidet_weights_models[cls_index].model,
                             lidet_weights_models[box_index].model);
    if (rc == LIDET_OK)
    {
        rc = lidet_detector_run(&g_acc_det, pts, n, stride, NULL, NULL);
    }
    if (rc < 0)
    {
        return rc;
    }
    np = g_acc_det.cfg.proposal.n_points;
    *n_points = np;
    *n_cand = lidet_detector_stats(&g_acc_det)->n_classified;
    for (k = 0; k < *n_cand; ++k)
    {
        const uint32_t ci = g_acc_det.order[k];
        lidet_proposal_t p;
        const int r2 = lidet_workspace_proposal(lidet_detector_workspace(&g_acc_det), ci, &g_acc_det.cfg.proposal, &p);
        if (r2 != LIDET_OK)
        {
            return r2;
        }
        memcpy(xyz + (size_t)k * np * 3u, p.xyz, sizeof(float) * np * 3u);
        memcpy(mean + 3u * k, p.mean_m, sizeof p.mean_m);
        memcpy(voxel + 3u * k, p.voxel, sizeof p.voxel);
        cluster_id[k] = ci + 1u;
    }
    return rc;
}

/* The integer detector's candidates: icfg: crop_half_bam, max_range_mm, max_proposals (0 = the default);
 * xyz[k] n_points x 3 int16 (4 mm steps, minus the mean), mean[k] 3 int32 (4 mm), voxel[k] 3 int16. */
LIDET_PY_API int lidet_py_acc_cands_q(const char *sensor, const char *cls_name, const char *box_name,
                                      const int32_t *icfg, const int32_t *pts_mm, uint32_t n, uint32_t stride,
                                      int16_t *xyz, int32_t *mean, int16_t *voxel, uint32_t *cluster_id,
                                      uint32_t *n_cand, uint32_t *n_points)
{
    const lidet_sensor_q_t *s = lidet_sensor_q_find(sensor);
    const lidet_pointnet_q_model_t *mc, *mb;
    lidet_detector_q_cfg_t cfg;
    uint32_t k, np;
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
    lidet_detector_q_cfg_default(&cfg, s);
    cfg.crop_half_bam = icfg[0];
    cfg.max_range_mm = icfg[1];
    if (icfg[2] != 0)
    {
        cfg.max_proposals = (uint32_t)icfg[2];
    }
    rc = lidet_detector_q_init(&g_acc_detq, &cfg, mc, mb);
    if (rc == LIDET_OK)
    {
        rc = lidet_detector_q_run(&g_acc_detq, pts_mm, n, stride, NULL, NULL);
    }
    if (rc < 0)
    {
        return rc;
    }
    np = g_acc_detq.cfg.proposal.n_points;
    *n_points = np;
    *n_cand = lidet_detector_q_stats(&g_acc_detq)->n_classified;
    for (k = 0; k < *n_cand; ++k)
    {
        const uint32_t ci = g_acc_detq.order[k];
        lidet_proposal_q_t p;
        const int r2 = lidet_proposal_q_make(&g_acc_detq.cluster, ci, &g_acc_detq.cfg.proposal, &p);
        if (r2 != LIDET_OK)
        {
            return r2;
        }
        memcpy(xyz + (size_t)k * np * 3u, p.xyz, sizeof(int16_t) * np * 3u);
        memcpy(mean + 3u * k, p.mean_4mm, sizeof p.mean_4mm);
        memcpy(voxel + 3u * k, p.voxel, sizeof p.voxel);
        cluster_id[k] = ci + 1u;
    }
    return rc;
}
