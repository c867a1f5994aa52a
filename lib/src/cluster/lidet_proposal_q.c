/* SPDX-License-Identifier: MIT */
/* Integer proposals (lidet_cluster_q.h): the float stage's resampling rule (internal/lidet_proposal_rule.h),
 * points minus the rounded mean in 4 mm steps, the mean's voxel from integer atan2 / square root. Integer
 * only. Mirrored by codegen/lidet_ref/cluster_q.py: make_proposal_q. Also the rule's pick of a large
 * cluster's member (lidet__proposal_pick), which the float proposals share. */
#include <string.h>

#include "internal/lidet_cluster_q_internal.h"
#include "internal/lidet_proposal_rule.h"
#include "internal/lidet_qmath.h"
#include "internal/lidet_qpix.h"
#include "internal/lidet_simd.h"
#include "lidet/lidet_cluster_q.h"

void lidet_proposal_q_cfg_default(lidet_proposal_q_cfg_t *cfg)
{
    if (cfg == 0)
    {
        return;
    }
    memset(cfg, 0, sizeof *cfg);
    cfg->n_points = 64u < LIDET_PROPOSAL_POINTS ? 64u : LIDET_PROPOSAL_POINTS;
    cfg->seed = 0x5EED1234u;
    cfg->azimuth_bin_bam = 119304647u; /* 10 deg = 2^32 / 36, rounded */
    cfg->elevation_bin_bam = 119304647u;
    cfg->range_bin_4mm = 250u; /* 1 m */
}

#if LIDET_HOST_SIMD
/* Hosts: the keys of up to 64 members at a time into a buffer, their minimum, then its position: the first two
 * loops have independent lanes, which compilers vectorise (and build for AVX2 too, internal/lidet_simd.h); keys
 * never tie, so the member found is the one the plain loop below finds. */
#define PICK_CHUNK 64u
LIDET_CLONES_AVX2 static uint32_t pick_chunked(const lidet_member_t *mem, uint32_t b0, uint32_t b1,
                                               uint32_t seed)
{
    uint32_t key[PICK_CHUNK];
    uint32_t m0, best = b0, best_key = 0xFFFFFFFFu;
    for (m0 = b0; m0 < b1; m0 += PICK_CHUNK)
    {
        const uint32_t n = b1 - m0 < PICK_CHUNK ? b1 - m0 : PICK_CHUNK;
        uint32_t j, lo = 0xFFFFFFFFu;
        for (j = 0; j < n; ++j)
        {
            key[j] = lidet__proposal_key(seed, (uint32_t)mem[m0 + j]);
        }
        for (j = 0; j < n; ++j)
        {
            lo = key[j] < lo ? key[j] : lo;
        }
        if (lo < best_key || m0 == b0)
        {
            for (j = 0; key[j] != lo; ++j)
            {
            }
            best_key = lo;
            best = m0 + j;
        }
    }
    return best;
}
#endif

uint32_t lidet__proposal_pick(const lidet_member_t *mem, uint32_t b0, uint32_t b1, uint32_t seed)
{
#if LIDET_HOST_SIMD
    return pick_chunked(mem, b0, b1, seed);
#else
    /* cores without SIMD: one pass, the best key in a register */
    uint32_t m, best = b0, key = lidet__proposal_key(seed, (uint32_t)mem[b0]);
    for (m = b0 + 1u; m < b1; ++m)
    {
        const uint32_t k = lidet__proposal_key(seed, (uint32_t)mem[m]);
        if (k < key)
        {
            key = k;
            best = m;
        }
    }
    return best;
#endif
}

/* floor(v / bin) as int16, saturating; bin >= 1 */
static int16_t bin_q(int64_t v, uint32_t bin)
{
    const int64_t f = v >= 0 ? v / (int64_t)bin : -((-v + (int64_t)bin - 1) / (int64_t)bin);
    return (int16_t)(f < -32768 ? -32768 : (f > 32767 ? 32767 : f));
}

static int16_t sat16(int32_t v)
{
    return (int16_t)(v < -32768 ? -32768 : (v > 32767 ? 32767 : v));
}

void lidet__proposal_q_voxel(int32_t mx, int32_t my, int32_t mz, const lidet_proposal_q_cfg_t *cfg,
                             int16_t voxel[3])
{
    /* a mean lies within the int16 pixels it averages: the squares fit in 64 bits, the roots in int32 */
    const int64_t rxy2 = (int64_t)mx * mx + (int64_t)my * my;
    voxel[0] = bin_q(lidet__q_atan2(my, mx), cfg->azimuth_bin_bam);
    voxel[1] =
        bin_q(lidet__q_atan2(mz, (int32_t)lidet__q_sqrt_round64((uint64_t)rxy2)), cfg->elevation_bin_bam);
    voxel[2] = bin_q(lidet__q_sqrt_round64((uint64_t)(rxy2 + (int64_t)mz * mz)), cfg->range_bin_4mm);
}

lidet_status_t lidet_proposal_q_make(const lidet_cluster_q_state_t *c, uint32_t cluster_index,
                                     const lidet_proposal_q_cfg_t *cfg, lidet_proposal_q_t *out)
{
    const lidet_cluster_q_rec_t *rec;
    const lidet_range_image_t *img;
    uint32_t i, npix, state;
    int32_t mx, my, mz, zo;

    if (c == 0 || cfg == 0 || out == 0)
    {
        return LIDET_ERR_ARG;
    }
    img = &c->img;
    if (c->magic != LIDET_INIT_MAGIC || c->members == 0 || !lidet__qpix_image_ok(img))
    {
        return LIDET_ERR_STATE;
    }
    if (cfg->n_points < 1u || cfg->n_points > LIDET_PROPOSAL_POINTS || cfg->azimuth_bin_bam == 0u ||
        cfg->azimuth_bin_bam > LIDET_Q_BAM_HALF || cfg->elevation_bin_bam == 0u ||
        cfg->elevation_bin_bam > LIDET_Q_BAM_HALF || cfg->range_bin_4mm == 0u ||
        cfg->z_origin > LIDET_PROPOSAL_Z_GROUND)
    {
        return LIDET_ERR_CONFIG;
    }
    if (cluster_index >= c->n_recs)
    {
        return LIDET_ERR_ARG;
    }
    rec = &c->recs[cluster_index];
    npix = (uint32_t)img->n_rows * img->n_cols;
    state = lidet__proposal_rng_start(cfg->seed, rec->n_points);
    mx = rec->mean_4mm[0];
    my = rec->mean_4mm[1];
    mz = rec->mean_4mm[2];
    /* the points' z origin: the cluster mean, or the ground under it (the mean minus its height above the plane) */
    zo = cfg->z_origin == LIDET_PROPOSAL_Z_GROUND ? mz - rec->height_4mm : mz;
    for (i = 0; i < cfg->n_points; ++i)
    {
        const int32_t p =
            (int32_t)c->members[rec->first_member + lidet__proposal_member(c->members + rec->first_member,
                                                                           &state, i, rec->n_points,
                                                                           cfg->n_points, cfg->seed)];
        int32_t v[3];
        if (p < 0 || (uint32_t)p >= npix)
        {
            return LIDET_ERR_STATE; /* cannot happen after a run; guards a stale state */
        }
        lidet__qpix_xyz(img, (uint32_t)p, v); /* stored or decoded (lidet_qpix.h) */
        out->xyz[i][0] = sat16(v[0] - mx);
        out->xyz[i][1] = sat16(v[1] - my);
        out->xyz[i][2] = sat16(v[2] - zo);
    }
    out->mean_4mm[0] = mx;
    out->mean_4mm[1] = my;
    out->mean_4mm[2] = zo;
    lidet__proposal_q_voxel(mx, my, mz, cfg, out->voxel);
    out->n_points = cfg->n_points;
    out->n_points_src = rec->n_points;
    return LIDET_OK;
}
