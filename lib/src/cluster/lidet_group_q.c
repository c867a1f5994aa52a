/* SPDX-License-Identifier: MIT */
/* The group split's rule in integers (internal/lidet_group_common.h has the rule; the float twin is lidet_group.c):
 * lengths in 4 mm steps, the axis from the integer atan2 in Q30, sums in 64 bits, divisions rounded half away
 * from zero, the bounds halved with a floor shift. Integer only. Mirrored bit for bit by
 * codegen/lidet_ref/group_q.py. */
#include <string.h>

#include "internal/lidet_cluster_q_internal.h"
#include "internal/lidet_group_q.h"
#include "internal/lidet_qmath.h"
#include "internal/lidet_qpix.h"

/* 1.0 and 2.2 m (z), 0.9 and 3.5 m (along the axis) in 4 mm steps, squared: the bounds on 12 var */
#define GROUP_Z_LO2 62500
#define GROUP_Z_HI2 302500
#define GROUP_S_LO2 50625
#define GROUP_S_HI2 765625

static void member_d(const lidet_group_q_t *g, const lidet_range_image_t *img, uint32_t p, int32_t d[3])
{
    int32_t v[3];
    lidet__qpix_xyz(img, p, v);
    d[0] = v[0] - g->mean[0];
    d[1] = v[1] - g->mean[1];
    d[2] = v[2] - g->mean[2];
}

/* the offset along the axis, round((dx c + dy s) / 2^30) */
static int32_t offset_t(const lidet_group_q_t *g, const int32_t d[3])
{
    return (int32_t)lidet__q_rshift_round((int64_t)d[0] * g->c + (int64_t)d[1] * g->s, 30u);
}

static uint32_t part_of(const lidet_group_q_t *g, int32_t t)
{
    uint32_t j = 0;
    while (j + 1u < g->k && g->bound[j] <= t)
    {
        ++j;
    }
    return j;
}

static int64_t abs64(int64_t v)
{
    return v < 0 ? -v : v;
}

int lidet__group_q_shape(const lidet_cluster_q_state_t *c, uint32_t ci, int32_t max_range_mm,
                         lidet_group_q_t *g)
{
    const lidet_cluster_q_rec_t *r = &c->recs[ci];
    const lidet_range_image_t *img = &c->img;
    const int64_t mr = (int64_t)max_range_mm;
    int64_t sxx = 0, syy = 0, sxy = 0, szz = 0, stt = 0, ay, ax, n;
    uint32_t i, sh = 0;
    int32_t half;
    memset(g, 0, sizeof *g);
    /* the mean within max_range_mm: (4 |m|)^2 <= range^2 */
    if (r->n_points < LIDET_GROUP_MIN_POINTS ||
        16 * ((int64_t)r->mean_4mm[0] * r->mean_4mm[0] + (int64_t)r->mean_4mm[1] * r->mean_4mm[1]) > mr * mr)
    {
        return 0;
    }
    memcpy(g->mean, r->mean_4mm, sizeof g->mean);
    for (i = 0; i < r->n_points; ++i)
    {
        int32_t d[3];
        member_d(g, img, (uint32_t)c->members[r->first_member + i], d);
        sxx += (int64_t)d[0] * d[0];
        syy += (int64_t)d[1] * d[1];
        sxy += (int64_t)d[0] * d[1];
        szz += (int64_t)d[2] * d[2];
    }
    n = (int64_t)r->n_points;
    if (12 * szz < GROUP_Z_LO2 * n || 12 * szz > GROUP_Z_HI2 * n)
    {
        return 0;
    }
    /* the axis: atan2(2 sxy, sxx - syy) / 2, both arguments shifted (floor) until they fit 30 bits */
    ay = 2 * sxy;
    ax = sxx - syy;
    while ((abs64(ay) >> sh) >= ((int64_t)1 << 30) || (abs64(ax) >> sh) >= ((int64_t)1 << 30))
    {
        ++sh;
    }
    half = lidet__q_atan2((int32_t)(ay >> sh), (int32_t)(ax >> sh)) >> 1;
    g->c = lidet__q_cos((uint32_t)half);
    g->s = lidet__q_sin((uint32_t)half);
    for (i = 0; i < r->n_points; ++i)
    {
        int32_t d[3], t;
        member_d(g, img, (uint32_t)c->members[r->first_member + i], d);
        t = offset_t(g, d);
        stt += (int64_t)t * t;
    }
    if (12 * stt < GROUP_S_LO2 * n || 12 * stt > GROUP_S_HI2 * n)
    {
        return 0;
    }
    g->spread = (int32_t)lidet__q_isqrt64((uint64_t)(12 * stt) / (uint64_t)n);
    /* round(spread / 0.5 m) and round(spread / 0.7 m), halves up */
    g->k_max = (uint32_t)(2 * g->spread + 125) / 250u;
    g->k_max = g->k_max < LIDET_GROUP_MAX_PARTS ? g->k_max : LIDET_GROUP_MAX_PARTS;
    g->k_min = (uint32_t)(2 * g->spread + 175) / 350u;
    g->k_min = g->k_min > 2u ? g->k_min : 2u;
    return g->k_min <= g->k_max;
}

int lidet__group_q_cut(const lidet_cluster_q_state_t *c, uint32_t ci, lidet_group_q_t *g, uint32_t k)
{
    const lidet_cluster_q_rec_t *r = &c->recs[ci];
    const lidet_range_image_t *img = &c->img;
    int32_t centre[LIDET_GROUP_MAX_PARTS];
    int64_t sum[LIDET_GROUP_MAX_PARTS][4];
    uint32_t it, i, j;
    g->k = k;
    for (j = 0; j < k; ++j)
    {
        centre[j] =
            (int32_t)lidet__q_div_round(((int64_t)(2u * j + 1u) - (int64_t)k) * g->spread, 2 * (int64_t)k);
    }
    for (it = 0; it < LIDET_GROUP_ITERS; ++it)
    {
        int moved = 0;
        for (j = 0; j + 1u < k; ++j)
        {
            g->bound[j] = (centre[j] + centre[j + 1u]) >> 1; /* floor (lidet_opt.h: arithmetic shifts) */
        }
        memset(sum, 0, sizeof sum);
        memset(g->n, 0, sizeof g->n);
        for (i = 0; i < r->n_points; ++i)
        {
            int32_t d[3], t;
            uint32_t q;
            member_d(g, img, (uint32_t)c->members[r->first_member + i], d);
            t = offset_t(g, d);
            q = part_of(g, t);
            ++g->n[q];
            sum[q][0] += t;
            sum[q][1] += d[0];
            sum[q][2] += d[1];
            sum[q][3] += d[2];
        }
        for (j = 0; j < k; ++j)
        {
            if (g->n[j] > 0u)
            {
                const int64_t nj = (int64_t)g->n[j];
                const int32_t m = (int32_t)lidet__q_div_round(sum[j][0], nj);
                moved |= m != centre[j];
                centre[j] = m;
                g->part_mean[j][0] = g->mean[0] + (int32_t)lidet__q_div_round(sum[j][1], nj);
                g->part_mean[j][1] = g->mean[1] + (int32_t)lidet__q_div_round(sum[j][2], nj);
                g->part_mean[j][2] = g->mean[2] + (int32_t)lidet__q_div_round(sum[j][3], nj);
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

static int16_t sat16(int32_t v)
{
    return (int16_t)(v < -32768 ? -32768 : (v > 32767 ? 32767 : v));
}

lidet_status_t lidet__group_q_proposal(const lidet_cluster_q_state_t *c, uint32_t ci,
                                       const lidet_group_q_t *g, uint32_t part,
                                       const lidet_proposal_q_cfg_t *cfg, lidet_proposal_q_t *out)
{
    const lidet_cluster_q_rec_t *r = &c->recs[ci];
    const lidet_range_image_t *img = &c->img;
    const uint32_t n_src = g->n[part], n_out = cfg->n_points;
    const int32_t mx = g->part_mean[part][0], my = g->part_mean[part][1], mz = g->part_mean[part][2];
    /* a ground-origin model measures z from the cluster's ground under its mean */
    const int32_t zo = cfg->z_origin == LIDET_PROPOSAL_Z_GROUND ? r->mean_4mm[2] - r->height_4mm : mz;
    int32_t d[3];
    lidet_status_t st;
    if (n_src == 0u || n_out < 1u || n_out > LIDET_PROPOSAL_POINTS)
    {
        return LIDET_ERR_ARG;
    }
    /* IN_PART and WRITE compute the member's offsets from the cluster mean in d */
#define GP_IN_PART(m)                                                                                        \
    (member_d(g, img, (uint32_t)c->members[r->first_member + (m)], d), part_of(g, offset_t(g, d)) == part)
#define GP_PIXEL(m) ((uint32_t)c->members[r->first_member + (m)])
#define GP_WRITE(i, m)                                                                                       \
    (member_d(g, img, GP_PIXEL(m), d), out->xyz[i][0] = sat16(d[0] + g->mean[0] - mx),                       \
     out->xyz[i][1] = sat16(d[1] + g->mean[1] - my), out->xyz[i][2] = sat16(d[2] + g->mean[2] - zo))
#define GP_COPY(i, k) memcpy(out->xyz[i], out->xyz[k], sizeof out->xyz[i])
    LIDET__GROUP_RESAMPLE(cfg->seed, n_src, n_out, r->n_points, GP_PIXEL, GP_IN_PART, GP_WRITE, GP_COPY, st);
#undef GP_PIXEL
#undef GP_IN_PART
#undef GP_WRITE
#undef GP_COPY
    if (st != LIDET_OK)
    {
        return st;
    }
    out->mean_4mm[0] = mx;
    out->mean_4mm[1] = my;
    out->mean_4mm[2] = zo;
    lidet__proposal_q_voxel(mx, my, mz, cfg, out->voxel);
    out->n_points = n_out;
    out->n_points_src = n_src;
    return LIDET_OK;
}
