/* SPDX-License-Identifier: MIT */
/* Integer proposals (lidet_cluster_q.h): the float stage's resampling rule (internal/lidet_proposal_rule.h),
 * points minus the rounded mean in 4 mm steps, the mean's voxel from integer atan2 / square root. Integer
 * only. Mirrored by codegen/lidet_ref/cluster_q.py: make_proposal_q. Also the rule's member indices
 * (lidet__proposal_indices_of), which the float proposals share. */
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

/* the member of stratum [b0, b1) (b1 > b0) whose pixel has the smallest key: one pass, the best key in a register */
static inline uint32_t pick(const lidet_member_t *mem, uint32_t b0, uint32_t b1, uint32_t seed)
{
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
}

uint32_t lidet__proposal_pick(const lidet_member_t *mem, uint32_t b0, uint32_t b1, uint32_t seed)
{
    return pick(mem, b0, b1, seed);
}

#if LIDET_HOST_SIMD
/* Hosts: the keys of the cluster's members 256 at a time into a buffer (independent lanes, which compilers
 * vectorise; built for AVX2 too on x86-64, internal/lidet_simd.h), then each stratum's smallest from the buffer.
 * Strata are short (a few members for most clusters), so keys per stratum would leave the vector units idle. Keys
 * never tie: the members found are pick()'s. */
LIDET_CLONES_AVX2 static void picks(const lidet_member_t *mem, uint32_t n_src, uint32_t n_out, uint32_t seed,
                                    uint32_t *idx)
{
    enum
    {
        CHUNK = 256
    };
    uint32_t key[CHUNK];
    lidet__strata_t st;
    uint32_t c0, i = 0, b1, best = 0, best_key = 0xFFFFFFFFu;
    lidet__strata_init(&st, n_src, n_out);
    b1 = lidet__strata_next(&st);
    for (c0 = 0; c0 < n_src; c0 += CHUNK)
    {
        const uint32_t n = n_src - c0 < CHUNK ? n_src - c0 : CHUNK;
        uint32_t j;
        for (j = 0; j < n; ++j)
        {
            key[j] = lidet__proposal_key(seed, (uint32_t)mem[c0 + j]);
        }
        for (j = 0; j < n; ++j)
        {
            /* branch-free: a stratum of a few members makes "smaller than the best so far" a coin toss. The best
             * key restarts at the largest value; keys never tie, so "<=" can only meet that value itself */
            const uint32_t m = c0 + j, k = key[j];
            const int le = k <= best_key;
            best_key = le ? k : best_key;
            best = le ? m : best;
            if (m + 1u == b1) /* the stratum's last member */
            {
                idx[i++] = best;
                best_key = 0xFFFFFFFFu;
                b1 = lidet__strata_next(&st);
            }
        }
    }
}
#else
static void picks(const lidet_member_t *mem, uint32_t n_src, uint32_t n_out, uint32_t seed, uint32_t *idx)
{
    lidet__strata_t st;
    uint32_t i, b0 = 0;
    lidet__strata_init(&st, n_src, n_out);
    for (i = 0; i < n_out; ++i)
    {
        const uint32_t b1 = lidet__strata_next(&st);
        idx[i] = pick(mem, b0, b1, seed);
        b0 = b1;
    }
}
#endif

void lidet__proposal_indices_of(const lidet_member_t *mem, uint32_t n_src, uint32_t n_out, uint32_t seed,
                                uint32_t *idx)
{
    if (n_src > n_out)
    {
        picks(mem, n_src, n_out, seed, idx);
    }
    else
    {
        uint32_t i, s = lidet__proposal_rng_start(seed, n_src);
        for (i = 0; i < n_out; ++i)
        {
            idx[i] = lidet__proposal_next_index(&s, i, n_src);
        }
    }
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
    uint32_t i, npix, idx[LIDET_PROPOSAL_POINTS];
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
    lidet__proposal_indices_of(c->members + rec->first_member, rec->n_points, cfg->n_points, cfg->seed, idx);
    mx = rec->mean_4mm[0];
    my = rec->mean_4mm[1];
    mz = rec->mean_4mm[2];
    /* the points' z origin: the cluster mean, or the ground under it (the mean minus its height above the plane) */
    zo = cfg->z_origin == LIDET_PROPOSAL_Z_GROUND ? mz - rec->height_4mm : mz;
    for (i = 0; i < cfg->n_points; ++i)
    {
        const int32_t p = (int32_t)c->members[rec->first_member + idx[i]];
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
