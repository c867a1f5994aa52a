/* SPDX-License-Identifier: MIT */
/* Proposals: a kept cluster resampled to N centred points plus its mean's spherical voxel (see
 * lidet_cluster.h). Mirrored exactly by codegen/lidet_ref/cluster.py: proposal_indices,
 * make_proposal; training reads proposals through the Python bindings of these functions. */
#include <math.h>
#include <string.h>

#include "internal/lidet_cluster_internal.h"
#include "internal/lidet_math.h"
#include "internal/lidet_pixel.h"
#include "internal/lidet_proposal_rule.h"
#include "lidet/lidet_cluster.h"

void lidet_proposal_cfg_default(lidet_proposal_cfg_t *cfg)
{
    if (cfg == 0)
    {
        return;
    }
    memset(cfg, 0, sizeof *cfg);
    cfg->n_points = 64u < LIDET_PROPOSAL_POINTS ? 64u : LIDET_PROPOSAL_POINTS;
    cfg->seed = 0x5EED1234u;
    cfg->azimuth_bin_rad = 10.0f * LIDET_DEG2RAD_F;
    cfg->elevation_bin_rad = 10.0f * LIDET_DEG2RAD_F;
    cfg->range_bin_m = 1.0f;
}

lidet_status_t lidet_proposal_indices(const lidet_member_t *pixels, uint32_t n_src, uint32_t n_out,
                                      uint32_t seed, uint32_t *out)
{
    if (out == 0 || n_src == 0 || n_out == 0 || (pixels == 0 && n_src > n_out))
    {
        return LIDET_ERR_ARG;
    }
    lidet__proposal_indices_of(pixels, n_src, n_out, seed, out);
    return LIDET_OK;
}

/* floor(v / bin) as int16, saturating; v and bin finite, bin > 0 */
static int16_t bin_of(float v, float bin)
{
    const float f = floorf(v / bin);
    if (!(f > -32768.0f))
    {
        return (int16_t)-32768;
    }
    if (!(f < 32767.0f))
    {
        return (int16_t)32767;
    }
    return (int16_t)f;
}

void lidet__proposal_voxel(float mx, float my, float mz, const lidet_proposal_cfg_t *cfg, int16_t voxel[3])
{
    const float rxy = sqrtf(mx * mx + my * my);
    voxel[0] = bin_of(atan2f(my, mx), cfg->azimuth_bin_rad);
    voxel[1] = bin_of(atan2f(mz, rxy), cfg->elevation_bin_rad);
    voxel[2] = bin_of(sqrtf(mx * mx + my * my + mz * mz), cfg->range_bin_m);
}

lidet_status_t lidet_proposal_make(const lidet_cluster_t *c, uint32_t cluster_index,
                                   const lidet_proposal_cfg_t *cfg, lidet_proposal_t *out)
{
    return c == 0 ? LIDET_ERR_ARG : lidet_proposal_make_of(&c->state, cluster_index, cfg, out);
}

lidet_status_t lidet_proposal_make_of(const lidet_cluster_state_t *c, uint32_t cluster_index,
                                      const lidet_proposal_cfg_t *cfg, lidet_proposal_t *out)
{
    const lidet_cluster_rec_t *rec;
    const lidet_range_image_t *img;
    uint32_t i, npix, idx[LIDET_PROPOSAL_POINTS];
    float mx, my, mz, zo;

    if (c == 0 || cfg == 0 || out == 0)
    {
        return LIDET_ERR_ARG;
    }
    if (c->magic != LIDET_INIT_MAGIC || c->members == 0 || !lidet__img_complete(&c->img))
    {
        return LIDET_ERR_STATE;
    }
    if (cfg->n_points < 1 || cfg->n_points > LIDET_PROPOSAL_POINTS ||
        !lidet__isfinite(cfg->azimuth_bin_rad) || !(cfg->azimuth_bin_rad > 0.0f) ||
        !lidet__isfinite(cfg->elevation_bin_rad) || !(cfg->elevation_bin_rad > 0.0f) ||
        !lidet__isfinite(cfg->range_bin_m) || !(cfg->range_bin_m > 0.0f) ||
        cfg->z_origin > LIDET_PROPOSAL_Z_GROUND)
    {
        return LIDET_ERR_CONFIG;
    }
    if (cluster_index >= c->n_recs)
    {
        return LIDET_ERR_ARG;
    }
    rec = &c->recs[cluster_index];
    img = &c->img;
    npix = (uint32_t)img->n_rows * img->n_cols;
    lidet__proposal_indices_of(c->members + rec->first_member, rec->n_points, cfg->n_points, cfg->seed, idx);
    mx = rec->mean_m[0];
    my = rec->mean_m[1];
    mz = rec->mean_m[2];
    /* the points' z origin: the cluster mean, or the ground under it (mean minus its height above the plane) */
    zo = cfg->z_origin == LIDET_PROPOSAL_Z_GROUND ? mz - rec->height_m : mz;
    for (i = 0; i < cfg->n_points; ++i)
    {
        const int32_t p = (int32_t)c->members[rec->first_member + idx[i]];
        if (p < 0 || (uint32_t)p >= npix)
        {
            return LIDET_ERR_STATE; /* cannot happen after a run; guards a stale state */
        }
        out->xyz[i][0] = lidet__img_x(img, (uint32_t)p) - mx;
        out->xyz[i][1] = lidet__img_y(img, (uint32_t)p) - my;
        out->xyz[i][2] = lidet__img_z(img, (uint32_t)p) - zo;
    }
    out->mean_m[0] = mx;
    out->mean_m[1] = my;
    out->mean_m[2] = zo;
    lidet__proposal_voxel(mx, my, mz, cfg, out->voxel);
    out->n_points = cfg->n_points;
    out->n_points_src = rec->n_points;
    return LIDET_OK;
}
