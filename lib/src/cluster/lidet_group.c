/* SPDX-License-Identifier: MIT */
/* The group split's rule in metres (internal/lidet_group_common.h has the rule; the integer twin is lidet_group_q.c):
 * the shape test, one k-means cut and a part's proposal, on a clustering's member pixels. */
#include <math.h>
#include <string.h>

#include "internal/lidet_cluster_internal.h"
#include "internal/lidet_group.h"
#include "internal/lidet_math.h"
#include "internal/lidet_pixel.h"

/* 1.0 and 2.2 m (z), 0.9 and 3.5 m (along the axis), squared: the bounds on 12 var */
#define GROUP_Z_LO2 1.0f
#define GROUP_Z_HI2 4.84f
#define GROUP_S_LO2 0.81f
#define GROUP_S_HI2 12.25f

/* a member's offset from the cluster mean along the axis: one expression everywhere (the cut and the proposals
 * must assign a member alike) */
static float offset_t(const lidet_group_t *g, const lidet_range_image_t *img, uint32_t p)
{
    return (lidet__img_x(img, p) - g->mean[0]) * g->c + (lidet__img_y(img, p) - g->mean[1]) * g->s;
}

static uint32_t part_of(const lidet_group_t *g, float t)
{
    uint32_t j = 0;
    while (j + 1u < g->k && g->bound[j] <= t)
    {
        ++j;
    }
    return j;
}

static uint32_t round_ratio(float v, float step)
{
    return (uint32_t)floorf(v / step + 0.5f);
}

int lidet__group_shape(const lidet_cluster_state_t *c, uint32_t ci, float max_range_m, lidet_group_t *g)
{
    const lidet_cluster_rec_t *r = &c->recs[ci];
    const lidet_range_image_t *img = &c->img;
    float sxx = 0.0f, syy = 0.0f, sxy = 0.0f, szz = 0.0f, stt = 0.0f, n, a;
    uint32_t i;
    memset(g, 0, sizeof *g);
    if (r->n_points < LIDET_GROUP_MIN_POINTS ||
        r->mean_m[0] * r->mean_m[0] + r->mean_m[1] * r->mean_m[1] > max_range_m * max_range_m)
    {
        return 0;
    }
    memcpy(g->mean, r->mean_m, sizeof g->mean);
    for (i = 0; i < r->n_points; ++i)
    {
        const uint32_t p = (uint32_t)c->members[r->first_member + i];
        const float dx = lidet__img_x(img, p) - g->mean[0], dy = lidet__img_y(img, p) - g->mean[1],
                    dz = lidet__img_z(img, p) - g->mean[2];
        sxx += dx * dx;
        syy += dy * dy;
        sxy += dx * dy;
        szz += dz * dz;
    }
    n = (float)r->n_points;
    if (!(12.0f * szz >= GROUP_Z_LO2 * n && 12.0f * szz <= GROUP_Z_HI2 * n))
    {
        return 0;
    }
    a = 0.5f * atan2f(2.0f * sxy, sxx - syy);
    g->c = cosf(a);
    g->s = sinf(a);
    for (i = 0; i < r->n_points; ++i)
    {
        const float t = offset_t(g, img, (uint32_t)c->members[r->first_member + i]);
        stt += t * t;
    }
    if (!(12.0f * stt >= GROUP_S_LO2 * n && 12.0f * stt <= GROUP_S_HI2 * n))
    {
        return 0;
    }
    g->spread = sqrtf(12.0f * stt / n);
    g->k_max = round_ratio(g->spread, 0.5f);
    g->k_max = g->k_max < LIDET_GROUP_MAX_PARTS ? g->k_max : LIDET_GROUP_MAX_PARTS;
    g->k_min = round_ratio(g->spread, 0.7f);
    g->k_min = g->k_min > 2u ? g->k_min : 2u;
    return g->k_min <= g->k_max;
}

int lidet__group_cut(const lidet_cluster_state_t *c, uint32_t ci, lidet_group_t *g, uint32_t k)
{
    const lidet_cluster_rec_t *r = &c->recs[ci];
    const lidet_range_image_t *img = &c->img;
    float centre[LIDET_GROUP_MAX_PARTS], sum[LIDET_GROUP_MAX_PARTS][4];
    uint32_t it, i, j;
    g->k = k;
    for (j = 0; j < k; ++j)
    {
        centre[j] = -0.5f * g->spread + ((float)j + 0.5f) * g->spread / (float)k;
    }
    for (it = 0; it < LIDET_GROUP_ITERS; ++it)
    {
        int moved = 0;
        for (j = 0; j + 1u < k; ++j)
        {
            g->bound[j] = 0.5f * (centre[j] + centre[j + 1u]);
        }
        memset(sum, 0, sizeof sum);
        memset(g->n, 0, sizeof g->n);
        for (i = 0; i < r->n_points; ++i)
        {
            const uint32_t p = (uint32_t)c->members[r->first_member + i];
            const float t = offset_t(g, img, p);
            const uint32_t q = part_of(g, t);
            ++g->n[q];
            sum[q][0] += t;
            sum[q][1] += lidet__img_x(img, p) - g->mean[0];
            sum[q][2] += lidet__img_y(img, p) - g->mean[1];
            sum[q][3] += lidet__img_z(img, p) - g->mean[2];
        }
        for (j = 0; j < k; ++j)
        {
            if (g->n[j] > 0u)
            {
                const float m = sum[j][0] / (float)g->n[j];
                moved |= m != centre[j];
                centre[j] = m;
                g->part_mean[j][0] = g->mean[0] + sum[j][1] / (float)g->n[j];
                g->part_mean[j][1] = g->mean[1] + sum[j][2] / (float)g->n[j];
                g->part_mean[j][2] = g->mean[2] + sum[j][3] / (float)g->n[j];
            }
        }
        if (!moved)
        {
            break;
        }
    }
    for (j = 0; j < k; ++j)
    {
        if (g->n[j] < LIDET_GROUP_MIN_PART)
        {
            return 0;
        }
    }
    return 1;
}

lidet_status_t lidet__group_proposal(const lidet_cluster_state_t *c, uint32_t ci, const lidet_group_t *g,
                                     uint32_t part, const lidet_proposal_cfg_t *cfg, lidet_proposal_t *out)
{
    const lidet_cluster_rec_t *r = &c->recs[ci];
    const lidet_range_image_t *img = &c->img;
    const uint32_t n_src = g->n[part], n_out = cfg->n_points;
    const float mx = g->part_mean[part][0], my = g->part_mean[part][1], mz = g->part_mean[part][2];
    /* a ground-origin model measures z from the cluster's ground under its mean */
    const float zo = cfg->z_origin == LIDET_PROPOSAL_Z_GROUND ? r->mean_m[2] - r->height_m : mz;
    lidet_status_t st;
    if (n_src == 0u || n_out < 1u || n_out > LIDET_PROPOSAL_POINTS)
    {
        return LIDET_ERR_ARG;
    }
#define GP_MEMBER(m) ((uint32_t)c->members[r->first_member + (m)])
#define GP_IN_PART(m) (part_of(g, offset_t(g, img, GP_MEMBER(m))) == part)
#define GP_WRITE(i, m)                                                                                       \
    (out->xyz[i][0] = lidet__img_x(img, GP_MEMBER(m)) - mx,                                                  \
     out->xyz[i][1] = lidet__img_y(img, GP_MEMBER(m)) - my,                                                  \
     out->xyz[i][2] = lidet__img_z(img, GP_MEMBER(m)) - zo)
#define GP_COPY(i, k) memcpy(out->xyz[i], out->xyz[k], sizeof out->xyz[i])
    LIDET__GROUP_RESAMPLE(cfg->seed, n_src, n_out, r->n_points, GP_IN_PART, GP_WRITE, GP_COPY, st);
#undef GP_MEMBER
#undef GP_IN_PART
#undef GP_WRITE
#undef GP_COPY
    if (st != LIDET_OK)
    {
        return st;
    }
    out->mean_m[0] = mx;
    out->mean_m[1] = my;
    out->mean_m[2] = zo;
    lidet__proposal_voxel(mx, my, mz, cfg, out->voxel);
    out->n_points = n_out;
    out->n_points_src = n_src;
    return LIDET_OK;
}
