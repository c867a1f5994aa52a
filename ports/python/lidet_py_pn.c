/* SPDX-License-Identifier: MIT */
/* Flat C entry points over the PointNet forward pass for the Python bindings (tools/lidet_tools/native/_pointnet.py):
 * the models of lidet::weights by index, batches of proposals looped in C. Host only: one static
 * scratch buffer, so calls are not reentrant. */
#include <string.h>
#include <time.h>

#include "lidet/lidet.h"
#include "lidet_weights.h"

#if defined(_WIN32)
#define LIDET_PY_API __declspec(dllexport)
#else
#define LIDET_PY_API __attribute__((visibility("default")))
#endif

#define SCRATCH_FLOATS 65536u
static float g_scratch[SCRATCH_FLOATS] LIDET_ALIGN(64); /* a cache line: the kernels' AVX-512 loads */
static lidet_pn_t g_pn[2];

static int bind(uint32_t slot, uint32_t index)
{
    if (index >= LIDET_WEIGHTS_N_MODELS)
    {
        return LIDET_ERR_NOT_FOUND;
    }
    /* slot 0 and 1 share the scratch: a run never overlaps another */
    return lidet_pn_init(&g_pn[slot], lidet_weights_models[index].model, g_scratch, sizeof g_scratch, NULL);
}

LIDET_PY_API uint32_t lidet_py_pn_count(void)
{
    return LIDET_WEIGHTS_N_MODELS;
}

/* name_buf: 64 bytes; info: kind, n_points, n_outputs, scratch_bytes, n_stages, heading bins, size
 * templates, format version; fl: gamma[3], energy_t, pvle_bin[3], mean sizes (up to 24) */
LIDET_PY_API int lidet_py_pn_info(uint32_t index, char *name_buf, uint32_t *info, float *fl)
{
    const lidet_pn_model_t *m;
    uint32_t i;
    if (index >= LIDET_WEIGHTS_N_MODELS)
    {
        return LIDET_ERR_NOT_FOUND;
    }
    m = lidet_weights_models[index].model;
    strncpy(name_buf, lidet_weights_models[index].name, 63);
    name_buf[63] = '\0';
    info[0] = m->kind;
    info[1] = m->n_points;
    info[2] = lidet_pn_n_outputs(m);
    info[3] = lidet_pn_scratch_bytes(m);
    info[4] = m->n_stages;
    info[5] = m->n_heading_bins;
    info[6] = m->n_size_clusters;
    info[7] = m->format_version;
    for (i = 0; i < 3; ++i)
    {
        fl[i] = m->gamma[i];
        fl[4 + i] = m->pvle_bin[i];
    }
    fl[3] = m->energy_t;
    for (i = 0; m->mean_size_m != NULL && i < 3u * m->n_size_clusters && i < 24u; ++i)
    {
        fl[7 + i] = m->mean_size_m[i];
    }
    return lidet_pn_check(m, 0, 0);
}

/* Raw network on a batch: points (batch, n, 3) in the model frame, voxel (batch, 3), onehot (batch, 3)
 * or NULL (classifier), out (batch, n_outputs). */
LIDET_PY_API int lidet_py_pn_forward(uint32_t index, uint32_t batch, uint32_t n, const float *points,
                                     const float *voxel, const float *onehot, float *out)
{
    uint32_t b, no;
    int rc = bind(0, index);
    if (rc < 0)
    {
        return rc;
    }
    no = lidet_pn_n_outputs(g_pn[0].model);
    for (b = 0; b < batch; ++b)
    {
        rc = lidet_pn_forward(&g_pn[0], points + (size_t)b * n * 3u, n, voxel + 3u * b,
                              onehot != NULL ? onehot + 3u * b : NULL, out + (size_t)b * no, no);
        if (rc < 0)
        {
            return rc;
        }
    }
    return 0;
}

static void to_proposal(lidet_proposal_t *p, uint32_t n, const float *xyz, const float *mean, const int16_t *voxel)
{
    memcpy(p->xyz, xyz, (size_t)n * 3u * sizeof(float));
    memcpy(p->mean_m, mean, 3u * sizeof(float));
    memcpy(p->voxel, voxel, 3u * sizeof(int16_t));
    p->n_points = n;
    p->n_points_src = n;
}

static lidet_proposal_t g_prop;

/* Classify a batch of proposals: xyz (batch, n, 3) centred, mean (batch, 3), voxel (batch, 3) int16.
 * Outputs per proposal: logits[3], prob[3], energy, class, gate-1 pass. */
LIDET_PY_API int lidet_py_pn_classify(uint32_t index, uint32_t batch, uint32_t n, const float *xyz, const float *mean,
                                      const int16_t *voxel, float *out_logits, float *out_prob, float *out_energy,
                                      uint8_t *out_cls, uint8_t *out_pass)
{
    uint32_t b;
    lidet_pn_class_out_t o;
    int rc = bind(0, index);
    if (rc < 0)
    {
        return rc;
    }
    if (n > LIDET_PROPOSAL_POINTS)
    {
        return LIDET_ERR_ARG;
    }
    for (b = 0; b < batch; ++b)
    {
        to_proposal(&g_prop, n, xyz + (size_t)b * n * 3u, mean + 3u * b, voxel + 3u * b);
        rc = lidet_pn_classify(&g_pn[0], &g_prop, &o);
        if (rc < 0)
        {
            return rc;
        }
        memcpy(out_logits + 3u * b, o.logits, 3u * sizeof(float));
        memcpy(out_prob + 3u * b, o.prob, 3u * sizeof(float));
        out_energy[b] = o.energy;
        out_cls[b] = o.cls;
        out_pass[b] = o.pass;
    }
    return 0;
}

/* Boxes of a batch of proposals of the given classes. Outputs: box (cx cy cz l w h yaw), energies
 * (heading, size, total), heading bin and size template, gate-2 pass. */
LIDET_PY_API int lidet_py_pn_box(uint32_t index, uint32_t batch, uint32_t n, const float *xyz, const float *mean,
                                 const int16_t *voxel, const uint8_t *cls, float *out_box, float *out_energy,
                                 uint8_t *out_bins, uint8_t *out_pass)
{
    uint32_t b;
    lidet_pn_box_out_t o;
    int rc = bind(0, index);
    if (rc < 0)
    {
        return rc;
    }
    if (n > LIDET_PROPOSAL_POINTS)
    {
        return LIDET_ERR_ARG;
    }
    for (b = 0; b < batch; ++b)
    {
        to_proposal(&g_prop, n, xyz + (size_t)b * n * 3u, mean + 3u * b, voxel + 3u * b);
        rc = lidet_pn_box(&g_pn[0], &g_prop, cls[b], &o);
        if (rc < 0)
        {
            return rc;
        }
        memcpy(out_box + 7u * b, &o.box, 7u * sizeof(float));
        out_energy[3u * b] = o.energy_heading;
        out_energy[3u * b + 1u] = o.energy_size;
        out_energy[3u * b + 2u] = o.energy;
        out_bins[2u * b] = o.heading_bin;
        out_bins[2u * b + 1u] = o.size_cluster;
        out_pass[b] = o.pass;
    }
    return 0;
}

static uint64_t now_ns(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (uint64_t)ts.tv_sec * 1000000000u + (uint64_t)ts.tv_nsec;
}

/* Timing for make bench: `repeats` passes of lidet_pn_classify (model cls_index) and of lidet_pn_box
 * (box_index, with the classifier's class) over a batch of proposals; out_ns[0], [1]: the fastest
 * pass of each, in ns for the whole batch. */
LIDET_PY_API int lidet_py_pn_time(uint32_t cls_index, uint32_t box_index, uint32_t batch, uint32_t n, const float *xyz,
                                  const float *mean, const int16_t *voxel, uint32_t repeats, uint64_t *out_ns)
{
    uint32_t r, b;
    lidet_pn_class_out_t co;
    lidet_pn_box_out_t bo;
    int rc = bind(0, cls_index);
    if (rc >= 0)
    {
        rc = bind(1, box_index);
    }
    if (rc < 0)
    {
        return rc;
    }
    if (n > LIDET_PROPOSAL_POINTS)
    {
        return LIDET_ERR_ARG;
    }
    out_ns[0] = out_ns[1] = UINT64_MAX;
    for (r = 0; r < repeats; ++r)
    {
        uint64_t t0 = now_ns(), t1;
        for (b = 0; b < batch; ++b)
        {
            to_proposal(&g_prop, n, xyz + (size_t)b * n * 3u, mean + 3u * b, voxel + 3u * b);
            rc = lidet_pn_classify(&g_pn[0], &g_prop, &co);
        }
        t1 = now_ns();
        out_ns[0] = t1 - t0 < out_ns[0] ? t1 - t0 : out_ns[0];
        t0 = now_ns();
        for (b = 0; b < batch; ++b)
        {
            to_proposal(&g_prop, n, xyz + (size_t)b * n * 3u, mean + 3u * b, voxel + 3u * b);
            rc |= lidet_pn_box(&g_pn[1], &g_prop, (uint32_t)(b % 3u), &bo);
        }
        t1 = now_ns();
        out_ns[1] = t1 - t0 < out_ns[1] ? t1 - t0 : out_ns[1];
        if (rc < 0)
        {
            return rc;
        }
    }
    return 0;
}
