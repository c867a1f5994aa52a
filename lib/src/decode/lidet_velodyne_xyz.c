/* SPDX-License-Identifier: MIT */
/* Float build only: x, y, z of decoded Velodyne returns (lidet_velodyne.h, lidet_velodyne_xyz,
 * lidet_velodyne_decoder_xyz). The integer build leaves this file out (CMakeLists.txt): the integer detector
 * takes the returns themselves. */
#include <math.h>

#include "internal/lidet_math.h"
#include "lidet/lidet_velodyne.h"

#define MAX_RINGS LIDET_VELODYNE_MAX_LASERS

/* x, y, z of returns whose ring r has the elevation elev_mdeg[r] (n_rings entries) */
static lidet_status_t xyz_of(const int32_t *elev_mdeg, uint32_t n_rings, const lidet_return_t *returns,
                             uint32_t n, float *xyz, uint32_t stride)
{
    float ce[MAX_RINGS], se[MAX_RINGS];
    const float bam_to_rad = 2.0f * LIDET_PI_F / 65536.0f;
    lidet_status_t status = LIDET_OK;
    uint32_t i;
    if (stride < 3u || (n > 0u && (returns == 0 || xyz == 0)))
    {
        return LIDET_ERR_ARG;
    }
    for (i = 0; i < n_rings; ++i)
    {
        ce[i] = cosf((float)elev_mdeg[i] * (LIDET_DEG2RAD_F / 1000.0f));
        se[i] = sinf((float)elev_mdeg[i] * (LIDET_DEG2RAD_F / 1000.0f));
    }
    for (i = 0; i < n; ++i)
    {
        const lidet_return_t *r = &returns[i];
        float *p = xyz + (uint64_t)i * stride;
        if (r->ring >= n_rings)
        {
            p[0] = p[1] = p[2] = 0.0f;
            status = LIDET_ERR_ARG;
            continue;
        }
        {
            const float rm = (float)r->range_mm * 0.001f;
            const float a = (float)r->azimuth * bam_to_rad;
            const float rxy = rm * ce[r->ring];
            p[0] = rxy * cosf(a);
            p[1] = rxy * sinf(a);
            p[2] = rm * se[r->ring];
        }
    }
    return status;
}

lidet_status_t lidet_velodyne_xyz(lidet_velodyne_model_t model, const lidet_return_t *returns, uint32_t n,
                                  float *xyz, uint32_t stride)
{
    int32_t elev[MAX_RINGS];
    const uint32_t n_rings = lidet_velodyne_n_rings(model);
    uint32_t i;
    if (n_rings == 0u || n_rings > MAX_RINGS)
    {
        return LIDET_ERR_ARG;
    }
    for (i = 0; i < n_rings; ++i)
    {
        elev[i] = 0;
        (void)lidet_velodyne_ring_elev_mdeg(model, i, &elev[i]);
    }
    return xyz_of(elev, n_rings, returns, n, xyz, stride);
}

lidet_status_t lidet_velodyne_decoder_xyz(const lidet_velodyne_t *st, const lidet_return_t *returns,
                                          uint32_t n, float *xyz, uint32_t stride)
{
    if (st == 0)
    {
        return LIDET_ERR_ARG;
    }
    if (st->magic != LIDET_INIT_MAGIC || st->n_lasers == 0u || st->n_lasers > MAX_RINGS)
    {
        return LIDET_ERR_STATE;
    }
    return xyz_of(st->ring_elev_mdeg, st->n_lasers, returns, n, xyz, stride);
}
