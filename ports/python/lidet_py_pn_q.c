/* SPDX-License-Identifier: MIT */
/* Flat C entry points over the int8 PointNets (lidet_pointnet_q.h) for the Python bindings
 * (tools/lidet_tools/native/_pointnet.py, section "int8"): the int8 models of lidet::weights by index,
 * batches of integer proposals looped in C. Host only: one static scratch, not reentrant. */
#include <string.h>
#include <time.h>

#include "lidet/lidet.h"
#include "lidet/lidet_pointnet_q.h"
#include "lidet_weights.h"

#if defined(_WIN32)
#define LIDET_PY_API __declspec(dllexport)
#else
#define LIDET_PY_API __attribute__((visibility("default")))
#endif

static int32_t g_scratch_q[16384];
static lidet_pointnet_q_t g_pnq[2];
static lidet_proposal_q_t g_prop_q;

static int bind_q(uint32_t slot, uint32_t index)
{
    if (index >= LIDET_WEIGHTS_N_MODELS_S8)
    {
        return LIDET_ERR_NOT_FOUND;
    }
    return lidet_pointnet_q_init(&g_pnq[slot], lidet_weights_models_s8[index].model, g_scratch_q, sizeof g_scratch_q,
                                 NULL);
}

LIDET_PY_API uint32_t lidet_py_pnq_count(void)
{
    return LIDET_WEIGHTS_N_MODELS_S8;
}

/* name_buf: 64 bytes; info: kind, n_points, n_outputs, scratch_bytes, n_stages, heading bins, size templates,
 * energy_t_q16, gamma_q16[3] */
LIDET_PY_API int lidet_py_pnq_info(uint32_t index, char *name_buf, int32_t *info)
{
    const lidet_pointnet_q_model_t *m;
    if (index >= LIDET_WEIGHTS_N_MODELS_S8)
    {
        return LIDET_ERR_NOT_FOUND;
    }
    m = lidet_weights_models_s8[index].model;
    strncpy(name_buf, lidet_weights_models_s8[index].name, 63);
    name_buf[63] = '\0';
    info[0] = m->kind;
    info[1] = m->n_points;
    info[2] = (int32_t)lidet_pointnet_q_n_outputs(m);
    info[3] = (int32_t)lidet_pointnet_q_scratch_bytes(m);
    info[4] = m->n_stages;
    info[5] = m->n_heading_bins;
    info[6] = m->n_size_clusters;
    info[7] = m->energy_t_q16;
    info[8] = m->gamma_q16[0];
    info[9] = m->gamma_q16[1];
    info[10] = m->gamma_q16[2];
    return lidet_pointnet_q_check(m, 0, 0);
}

/* Raw network: points (batch, n, 3) int16 mm (model frame), voxel (batch, 3), cls (batch), out (batch, n_out) */
LIDET_PY_API int lidet_py_pnq_forward(uint32_t index, uint32_t batch, uint32_t n, const int16_t *points,
                                      const int16_t *voxel, const uint8_t *cls, int32_t *out)
{
    uint32_t b, no;
    int rc = bind_q(0, index);
    if (rc < 0)
    {
        return rc;
    }
    no = lidet_pointnet_q_n_outputs(g_pnq[0].model);
    for (b = 0; b < batch; ++b)
    {
        rc = lidet_pointnet_q_forward(&g_pnq[0], points + (size_t)b * n * 3u, n, voxel + 3u * b,
                                      cls != NULL ? cls[b] : 0u, out + (size_t)b * no, no);
        if (rc < 0)
        {
            return rc;
        }
    }
    return 0;
}

static int to_proposal_q(uint32_t n, const int16_t *xyz, const int32_t *mean, const int16_t *voxel)
{
    if (n > LIDET_PROPOSAL_POINTS)
    {
        return LIDET_ERR_ARG;
    }
    memcpy(g_prop_q.xyz, xyz, (size_t)n * 3u * sizeof(int16_t));
    memcpy(g_prop_q.mean_4mm, mean, 3u * sizeof(int32_t));
    memcpy(g_prop_q.voxel, voxel, 3u * sizeof(int16_t));
    g_prop_q.n_points = n;
    g_prop_q.n_points_src = n;
    return 0;
}

/* Classify a batch: xyz (batch, n, 3) 4 mm steps, mean (batch, 3) 4 mm steps, voxel (batch, 3).
 * Outputs: logits (batch, 3) Q16, prob (batch, 3) Q15, energy Q16, class, pass. */
LIDET_PY_API int lidet_py_pnq_classify(uint32_t index, uint32_t batch, uint32_t n, const int16_t *xyz,
                                       const int32_t *mean, const int16_t *voxel, int32_t *logits, int32_t *prob,
                                       int32_t *energy, uint8_t *cls, uint8_t *pass)
{
    uint32_t b;
    lidet_pointnet_q_class_out_t o;
    int rc = bind_q(0, index);
    for (b = 0; rc >= 0 && b < batch; ++b)
    {
        rc = to_proposal_q(n, xyz + (size_t)b * n * 3u, mean + 3u * b, voxel + 3u * b);
        if (rc >= 0)
        {
            rc = lidet_pointnet_q_classify(&g_pnq[0], &g_prop_q, &o);
        }
        if (rc >= 0)
        {
            memcpy(logits + 3u * b, o.logits_q16, sizeof o.logits_q16);
            memcpy(prob + 3u * b, o.prob_q15, sizeof o.prob_q15);
            energy[b] = o.energy_q16;
            cls[b] = o.cls;
            pass[b] = o.pass;
        }
    }
    return rc < 0 ? rc : 0;
}

/* Boxes of a batch of proposals of classes cls. Outputs: box (cx cy cz l w h mm, yaw BAM32), energies
 * (heading, size, total) Q16, heading bin and size template, pass. */
LIDET_PY_API int lidet_py_pnq_box(uint32_t index, uint32_t batch, uint32_t n, const int16_t *xyz, const int32_t *mean,
                                  const int16_t *voxel, const uint8_t *cls, int32_t *box, int32_t *energy,
                                  uint8_t *bins, uint8_t *pass)
{
    uint32_t b;
    lidet_pointnet_q_box_out_t o;
    int rc = bind_q(0, index);
    for (b = 0; rc >= 0 && b < batch; ++b)
    {
        rc = to_proposal_q(n, xyz + (size_t)b * n * 3u, mean + 3u * b, voxel + 3u * b);
        if (rc >= 0)
        {
            rc = lidet_pointnet_q_box(&g_pnq[0], &g_prop_q, cls[b], &o);
        }
        if (rc >= 0)
        {
            box[7u * b + 0u] = o.box.cx_mm;
            box[7u * b + 1u] = o.box.cy_mm;
            box[7u * b + 2u] = o.box.cz_mm;
            box[7u * b + 3u] = o.box.l_mm;
            box[7u * b + 4u] = o.box.w_mm;
            box[7u * b + 5u] = o.box.h_mm;
            box[7u * b + 6u] = o.box.yaw_bam;
            energy[3u * b] = o.energy_heading_q16;
            energy[3u * b + 1u] = o.energy_size_q16;
            energy[3u * b + 2u] = o.energy_q16;
            bins[2u * b] = o.heading_bin;
            bins[2u * b + 1u] = o.size_cluster;
            pass[b] = o.pass;
        }
    }
    return rc < 0 ? rc : 0;
}

/* Energy of each row of v (rows, n) Q16 at temperature t_q16 */
LIDET_PY_API int lidet_py_pnq_energy(uint32_t rows, uint32_t n, const int32_t *v, int32_t t_q16, int32_t *out)
{
    uint32_t r;
    for (r = 0; r < rows; ++r)
    {
        out[r] = lidet_pointnet_q_energy(v + (size_t)r * n, n, t_q16);
    }
    return 0;
}

static uint64_t now_ns_q(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (uint64_t)ts.tv_sec * 1000000000u + (uint64_t)ts.tv_nsec;
}

/* Timing (bench_pointnet): fastest of `repeats` passes of classify and of box over a batch, ns per batch */
LIDET_PY_API int lidet_py_pnq_time(uint32_t cls_index, uint32_t box_index, uint32_t batch, uint32_t n,
                                   const int16_t *xyz, const int32_t *mean, const int16_t *voxel, uint32_t repeats,
                                   uint64_t *out_ns)
{
    uint32_t r, b;
    lidet_pointnet_q_class_out_t co;
    lidet_pointnet_q_box_out_t bo;
    int rc = bind_q(0, cls_index);
    if (rc >= 0)
    {
        rc = bind_q(1, box_index);
    }
    if (rc < 0)
    {
        return rc;
    }
    out_ns[0] = out_ns[1] = UINT64_MAX;
    for (r = 0; r < repeats; ++r)
    {
        uint64_t t0 = now_ns_q(), t1;
        for (b = 0; b < batch && rc >= 0; ++b)
        {
            rc = to_proposal_q(n, xyz + (size_t)b * n * 3u, mean + 3u * b, voxel + 3u * b);
            rc |= lidet_pointnet_q_classify(&g_pnq[0], &g_prop_q, &co);
        }
        t1 = now_ns_q();
        out_ns[0] = t1 - t0 < out_ns[0] ? t1 - t0 : out_ns[0];
        t0 = now_ns_q();
        for (b = 0; b < batch && rc >= 0; ++b)
        {
            rc = to_proposal_q(n, xyz + (size_t)b * n * 3u, mean + 3u * b, voxel + 3u * b);
            rc |= lidet_pointnet_q_box(&g_pnq[1], &g_prop_q, b % 3u, &bo);
        }
        t1 = now_ns_q();
        out_ns[1] = t1 - t0 < out_ns[1] ? t1 - t0 : out_ns[1];
    }
    return rc < 0 ? rc : 0;
}
