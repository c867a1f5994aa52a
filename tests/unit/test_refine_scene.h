/* SPDX-License-Identifier: MIT */
/* Hand-made refinement scenes for the Unity tests of the float (test_refine.c) and integer
 * (test_refine_q.c) refinement: a small ray-cast range image (32 beams 0.5 deg apart from +2 deg, 2048
 * columns, sensor 1.73 m above a flat ground that returns nothing) of upright cylinders (people) and boxes
 * (cars). Include once per test. */
#ifndef TEST_REFINE_SCENE_H
#define TEST_REFINE_SCENE_H

#include <math.h>
#include <string.h>

#include "lidet/lidet.h"
#include "unity.h"

#define PI_D 3.14159265358979323846
#define ROWS 32
#define COLS 2048
#define NPIX (ROWS * COLS)
#define MAXOBJ 4

typedef struct
{
    int kind;        /* 0 cylinder (cx, cy, r), 1 box (x0, y0, x1, y1) */
    double a, b, c, d;
    double z0, z1;   /* vertical extent (sensor frame) */
} obj_t;

static float g_x[NPIX], g_y[NPIX], g_z[NPIX], g_r[NPIX], g_rxy[NPIX], g_elev[ROWS];
static int32_t g_idx[NPIX];
static uint8_t g_obj[NPIX]; /* object index + 1 of each pixel's return, 0 = none */
static lidet_range_image_t g_img;

static double hit_cylinder(const obj_t *o, double dx, double dy)
{
    /* |t d - c|^2 = r^2 in the plane (|d| = 1) */
    const double b = dx * o->a + dy * o->b, cc = o->a * o->a + o->b * o->b - o->c * o->c;
    const double disc = b * b - cc;
    return disc < 0.0 ? -1.0 : b - sqrt(disc);
}

static double hit_box(const obj_t *o, double dx, double dy)
{
    double t0 = 0.0, t1 = 1e9;
    const double lo[2] = {o->a, o->b}, hi[2] = {o->c, o->d}, d[2] = {dx, dy};
    int k;
    for (k = 0; k < 2; ++k)
    {
        if (fabs(d[k]) < 1e-12)
        {
            if (lo[k] > 0.0 || hi[k] < 0.0)
                return -1.0;
            continue;
        }
        {
            const double ta = lo[k] / d[k], tb = hi[k] / d[k];
            const double t_in = ta < tb ? ta : tb, t_out = ta < tb ? tb : ta; /* entering and leaving the slab */
            t0 = t_in > t0 ? t_in : t0;
            t1 = t_out < t1 ? t_out : t1;
        }
    }
    return t0 <= t1 ? t0 : -1.0;
}

/* ray-cast the scene; `drop(row, col)` nonzero removes that pixel's return (dropouts) */
static void render(const obj_t *objs, int n, int (*drop)(int row, int col))
{
    int r, c, i, np = 0;
    for (r = 0; r < ROWS; ++r)
        g_elev[r] = (float)((2.0 - 0.5 * r) * PI_D / 180.0);
    for (r = 0; r < ROWS; ++r)
    {
        const double el = g_elev[r], ce = cos(el), se = sin(el);
        for (c = 0; c < COLS; ++c)
        {
            const int p = r * COLS + c;
            const double az = PI_D * (1.0 - 2.0 * (c + 0.5) / COLS);
            const double dx = cos(az), dy = sin(az); /* horizontal unit direction */
            double best = 1e9;
            int who = -1;
            for (i = 0; i < n; ++i)
            {
                const double t = objs[i].kind == 0 ? hit_cylinder(&objs[i], dx, dy) : hit_box(&objs[i], dx, dy);
                const double z = t * se / ce;
                if (t > 0.0 && t < best && z >= objs[i].z0 && z <= objs[i].z1)
                {
                    best = t;
                    who = i;
                }
            }
            g_idx[p] = -1;
            g_obj[p] = 0;
            g_x[p] = g_y[p] = g_z[p] = g_r[p] = g_rxy[p] = 0.0f;
            if (who < 0 || (drop != 0 && drop(r, c)))
                continue;
            g_x[p] = (float)(best * dx);
            g_y[p] = (float)(best * dy);
            g_z[p] = (float)(best * se / ce);
            g_rxy[p] = (float)best;
            g_r[p] = (float)(best / ce);
            g_idx[p] = np++;
            g_obj[p] = (uint8_t)(who + 1);
        }
    }
    memset(&g_img, 0, sizeof g_img);
    g_img.n_rows = ROWS;
    g_img.n_cols = COLS;
    g_img.x_m = g_x;
    g_img.y_m = g_y;
    g_img.z_m = g_z;
    g_img.range_m = g_r;
    g_img.rxy_m = g_rxy;
    g_img.point_idx = g_idx;
    g_img.row_elev_rad = g_elev;
}

/* two bands of five beams lost (a car's dark paint, its glass) */
static int car_bands(int row, int col)
{
    (void)col;
    return (row >= 12 && row < 17) || (row >= 20 && row < 25);
}

/* every cluster holds returns of one object only, and each object's returns lie in one cluster */
static void scene_one_to_one(const uint16_t *lab, int n_obj)
{
    uint32_t owner[64], cl_of[MAXOBJ + 1];
    int p, i;
    memset(owner, 0, sizeof owner);
    memset(cl_of, 0, sizeof cl_of);
    for (p = 0; p < NPIX; ++p)
    {
        if (lab[p] == 0)
            continue;
        TEST_ASSERT_TRUE(lab[p] < 64);
        TEST_ASSERT_TRUE(g_obj[p] > 0);
        if (owner[lab[p]] == 0)
            owner[lab[p]] = g_obj[p];
        TEST_ASSERT_EQUAL_UINT32(owner[lab[p]], g_obj[p]); /* one object per cluster */
        if (cl_of[g_obj[p]] == 0)
            cl_of[g_obj[p]] = lab[p];
        TEST_ASSERT_EQUAL_UINT32(cl_of[g_obj[p]], lab[p]); /* one cluster per object */
    }
    for (i = 1; i <= n_obj; ++i)
    {
        TEST_ASSERT_TRUE(cl_of[i] != 0);
    }
}

#endif
