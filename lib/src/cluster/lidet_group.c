/* SPDX-License-Identifier: MIT */
/* The group split's rule in metres (internal/lidet_group_common.h has the rule; the integer twin is lidet_group_q.c):
 * the shape test, one k-means cut and a part's proposal, on a clustering's member pixels. */
#include <math.h>
#include <string.h>

#include "internal/lidet_cluster_internal.h"
#include "internal/lidet_group.h"
#include "internal/lidet_math.h"
#include "internal/lidet_pixel.h"

/* the cut's passes in SSE2 (assign_sse2): one lane per part, the rule's four parts in one vector */
#if LIDET_HOST_SIMD && defined(__SSE2__)
#define GROUP_SSE2 1
#include <emmintrin.h>
typedef char lidet__group_parts_fill_a_vector[LIDET_GROUP_MAX_PARTS == 4u ? 1 : -1];
#else
#define GROUP_SSE2 0
#endif

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

/* the part means (x, y, z) of the last pass' assignment (g's bounds and counts, every part non-empty): the
 * sums in member order that pass would have made (the passes sum t alone) */
static void part_means(const lidet_cluster_state_t *c, const lidet_cluster_rec_t *r, lidet_group_t *g,
                       const float *t_of)
{
    const lidet_range_image_t *img = &c->img;
    float sum[LIDET_GROUP_MAX_PARTS][3];
    uint32_t i, j;
    memset(sum, 0, sizeof sum);
    for (i = 0; i < r->n_points; ++i)
    {
        const uint32_t p = (uint32_t)c->members[r->first_member + i];
        const uint32_t q = part_of(g, t_of != 0 ? t_of[i] : offset_t(g, img, p));
        sum[q][0] += lidet__img_x(img, p) - g->mean[0];
        sum[q][1] += lidet__img_y(img, p) - g->mean[1];
        sum[q][2] += lidet__img_z(img, p) - g->mean[2];
    }
    for (j = 0; j < g->k; ++j)
    {
        g->part_mean[j][0] = g->mean[0] + sum[j][0] / (float)g->n[j];
        g->part_mean[j][1] = g->mean[1] + sum[j][1] / (float)g->n[j];
        g->part_mean[j][2] = g->mean[2] + sum[j][2] / (float)g->n[j];
    }
}

#if GROUP_SSE2
/* assign in SSE2, lane j part j, over the kept offsets or, for a cluster past the scratch, offsets made again each
 * pass (real KITTI scan 000000: its group cuts 5.5 -> 4.9 % of the detector's run, perf). The bounds' tests in
 * one compare (b <= t per lane, as part_of), the part the run of passed tests from the first (part_of's loop), t
 * added to its part's lane and +0 to the others. A sum that starts at +0 is never -0 (rounding to nearest, x + y
 * is -0 only when both are), so adding +0 leaves its bits: each lane sums its part's t in member order, bit for
 * bit the scalar pass (any t, NaN included). It keeps the sums in a register where the scalar pass adds through
 * memory, part by part (a load waiting on the last store) */
static void assign_sse2(const lidet_cluster_state_t *c, const lidet_cluster_rec_t *r, const float *t_of,
                        const lidet_group_t *g, uint32_t n_out[LIDET_GROUP_MAX_PARTS],
                        float sum_out[LIDET_GROUP_MAX_PARTS])
{
    static const uint8_t run_of[8] = {0, 1, 0, 2, 0, 1, 0, 3}; /* trailing 1 bits of 3 tests */
    const __m128 b = _mm_setr_ps(g->bound[0], g->bound[1], g->bound[2], 0.0f);
    const __m128i lane = _mm_setr_epi32(0, 1, 2, 3);
    const int live = g->k > 1u ? (1 << (g->k - 1u)) - 1 : 0; /* tests of the k - 1 bounds */
    __m128 sum = _mm_setzero_ps();
    __m128i n = _mm_setzero_si128();
    uint32_t i;
    for (i = 0; i < r->n_points; ++i)
    {
        /* a cluster past the scratch: its offsets made again each pass (the same values) */
        const __m128 t = _mm_set1_ps(
            t_of != 0 ? t_of[i] : offset_t(g, &c->img, (uint32_t)c->members[r->first_member + i]));
        const int q = run_of[_mm_movemask_ps(_mm_cmple_ps(b, t)) & live];
        const __m128i on = _mm_cmpeq_epi32(_mm_set1_epi32(q), lane);
        sum = _mm_add_ps(sum, _mm_and_ps(t, _mm_castsi128_ps(on)));
        n = _mm_sub_epi32(n, on);
    }
    _mm_storeu_ps(sum_out, sum);
    _mm_storeu_si128((__m128i *)n_out, n);
}
#endif

/* one k-means pass: members per part and their sum of t into n, sum; t the kept offsets t_of, or offset_t */
static void assign(const lidet_cluster_state_t *c, const lidet_cluster_rec_t *r, const lidet_group_t *g,
                   const float *t_of, uint32_t n[LIDET_GROUP_MAX_PARTS], float sum[LIDET_GROUP_MAX_PARTS])
{
#if GROUP_SSE2
    assign_sse2(c, r, t_of, g, n, sum);
#else
    uint32_t i;
    memset(sum, 0, LIDET_GROUP_MAX_PARTS * sizeof sum[0]);
    memset(n, 0, LIDET_GROUP_MAX_PARTS * sizeof n[0]);
    for (i = 0; i < r->n_points; ++i)
    {
        const float t = t_of != 0 ? t_of[i] : offset_t(g, &c->img, (uint32_t)c->members[r->first_member + i]);
        const uint32_t q = part_of(g, t);
        ++n[q];
        sum[q] += t;
    }
#endif
}

/* Rule 3. A member's offset t is computed once into the caller's scratch (when the cluster fits) and the
 * passes read it back; they sum t alone, and the part means (x, y, z) are made once, after the last pass, for
 * a cut that stands (a failed cut's means are never read). The same values summed in the same order as by
 * passes that decoded every member and summed x, y, z each time, so the same bits. Measured on the 17 real
 * KITTI HDL-64 scans (the float detector: 13 cuts a scan, 4.6 passes of 375 members each): 0.117 -> 0.060 ms
 * a scan (perf) with the SSE2 pass; the kept offsets with the scalar pass alone gained little (that pass
 * waits on its sums' stores) */
int lidet__group_cut(const lidet_cluster_state_t *c, uint32_t ci, lidet_group_t *g, uint32_t k,
                     float *scratch, uint32_t n_scratch)
{
    const lidet_cluster_rec_t *r = &c->recs[ci];
    float centre[LIDET_GROUP_MAX_PARTS], sum[LIDET_GROUP_MAX_PARTS];
    const float *t_of = r->n_points <= n_scratch ? scratch : 0;
    uint32_t it, i, j;
    g->k = k;
    if (t_of != 0)
    {
        for (i = 0; i < r->n_points; ++i)
        {
            scratch[i] = offset_t(g, &c->img, (uint32_t)c->members[r->first_member + i]);
        }
    }
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
        assign(c, r, g, t_of, g->n, sum);
        for (j = 0; j < k; ++j)
        {
            if (g->n[j] > 0u)
            {
                const float m = sum[j] / (float)g->n[j];
                moved |= m != centre[j];
                centre[j] = m;
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
    part_means(c, r, g, t_of);
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
    LIDET__GROUP_RESAMPLE(cfg->seed, n_src, n_out, r->n_points, GP_MEMBER, GP_IN_PART, GP_WRITE, GP_COPY, st);
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
