/* SPDX-License-Identifier: MIT */
/* Hand-drawn range images for the clustering tests: one character per pixel.
 *   '.' = empty pixel, 'g' = ground pixel at 10 m, 'a'..'z' (except g) = a return at range
 *   5 m + 2.5 m * (letter - 'a') (a = 5 m, b = 7.5 m, c = 10 m, e = 15 m, i = 25 m ...).
 * Rows are 2 deg apart (row 0 at +7 deg), columns split 360 deg like the projection
 * (azimuth of column c = pi * (1 - 2 (c + 0.5) / cols)). Header-only: included by one test file. */
#ifndef LIDET_TEST_CLUSTER_UTIL_H
#define LIDET_TEST_CLUSTER_UTIL_H

#include <math.h>
#include <string.h>

#include "lidet/lidet.h"

#define TCU_MAX_PIX 4096

typedef struct
{
    float x[TCU_MAX_PIX], y[TCU_MAX_PIX], z[TCU_MAX_PIX], r[TCU_MAX_PIX], rxy[TCU_MAX_PIX];
    int32_t idx[TCU_MAX_PIX];
    uint8_t ground[TCU_MAX_PIX];
    float elev[64];
    lidet_range_image_t img;
} tcu_image_t;

/* rows strings of equal length (the columns) */
static void tcu_draw(tcu_image_t *t, const char *const *art, int rows)
{
    const int cols = (int)strlen(art[0]);
    int r, c, n = 0;
    memset(t, 0, sizeof *t);
    for (r = 0; r < rows; ++r)
    {
        t->elev[r] = (float)((7.0 - 2.0 * r) * M_PI / 180.0);
    }
    for (r = 0; r < rows; ++r)
    {
        for (c = 0; c < cols; ++c)
        {
            const int p = r * cols + c;
            const char ch = art[r][c];
            double range, az, el;
            t->idx[p] = -1;
            if (ch == '.')
                continue;
            range = ch == 'g' ? 10.0 : 5.0 + 2.5 * (ch - 'a');
            az = M_PI * (1.0 - 2.0 * (c + 0.5) / cols);
            el = t->elev[r];
            t->x[p] = (float)(range * cos(el) * cos(az));
            t->y[p] = (float)(range * cos(el) * sin(az));
            t->z[p] = (float)(range * sin(el));
            t->r[p] = (float)range;
            t->rxy[p] = (float)(range * cos(el));
            t->idx[p] = n++;
            t->ground[p] = ch == 'g';
        }
    }
    t->img.n_rows = (uint16_t)rows;
    t->img.n_cols = (uint16_t)cols;
    t->img.x_m = t->x;
    t->img.y_m = t->y;
    t->img.z_m = t->z;
    t->img.range_m = t->r;
    t->img.rxy_m = t->rxy;
    t->img.point_idx = t->idx;
    t->img.row_elev_rad = t->elev;
}

/* permissive filters so tiny drawings survive */
static void tcu_cfg(lidet_cluster_cfg_t *cfg)
{
    lidet_cluster_cfg_default(cfg, NULL);
    cfg->theta_rad = 0.2f;
    cfg->max_steps = 3; /* columns here are ~10 deg wide, not 0.2: 9 steps would span 90 deg */
    cfg->min_points = 1;
    cfg->max_extent_m = 100.0f;
    cfg->max_mean_height_m = 1e30f;
    cfg->max_gap_m = 0.0f; /* the angle test alone (the defaults' gap bound is for real-sized images) */
    cfg->max_gap_per_m = 0.0f;
    cfg->regrow_gap_m = 0.0f; /* over-extent components dropped (the regrowth's gap is for real-sized images) */
}

/* the rescue scenes: 4-neighbourhood without occluder bridging (every singleton stays one), the
 * fragment rescue over 1 row and 6 columns */
static void tcu_rescue_cfg(lidet_cluster_cfg_t *cfg, float theta_rad, uint32_t min_points, float gap_m,
                           float gap_per_m)
{
    tcu_cfg(cfg);
    cfg->theta_rad = theta_rad;
    cfg->diagonals = 0;
    cfg->bridge_occluders = 0;
    cfg->min_points = min_points;
    cfg->rescue_gap_m = gap_m;
    cfg->rescue_gap_per_m = gap_per_m;
    cfg->rescue_rows = 1;
    cfg->rescue_cols = 6;
}

#endif
