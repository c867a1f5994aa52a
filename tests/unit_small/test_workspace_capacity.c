/* SPDX-License-Identifier: MIT */
/* The detector workspace against a library built with tiny capacities (LIDET_MAX_POINTS 64, 16 x 64
 * pixels, 8 clusters): truncation in the projection and capacity drops in the clustering come back
 * as LIDET_TRUNCATED, the results still equal the stages chained by hand (on the compact image made
 * by hand), and nothing is written past
 * a buffer. */
#include <math.h>
#include <string.h>

#include "lidet/lidet.h"
#include "lidet/lidet_workspace.h"
#include "test_util.h"

LIDET_GUARDED(lidet_workspace_t, g_ws);
LIDET_GUARDED(lidet_proj_t, g_proj);
LIDET_GUARDED(lidet_ground_t, g_ground);
LIDET_GUARDED(lidet_cluster_t, g_cluster);
static float pts[200 * 4];
static int32_t g_pp[LIDET_MAX_POINTS + 8];

void setUp(void)
{
    CANARY_FILL(g_ws);
    CANARY_FILL(g_proj);
    CANARY_FILL(g_ground);
    CANARY_FILL(g_cluster);
}

void tearDown(void)
{
    CANARY_CHECK(g_ws);
    CANARY_CHECK(g_proj);
    CANARY_CHECK(g_ground);
    CANARY_CHECK(g_cluster);
}

/* 12 small objects 30 deg apart at 10 m (5 returns each, one per beam from -3 to +5 deg), then 140
 * more points that the capacity cuts off */
static uint32_t scene(void)
{
    uint32_t i = 0, b, k;
    for (b = 0; b < 12; ++b)
    {
        const double az = (30.0 * b + 7.0) * M_PI / 180.0;
        for (k = 0; k < 5; ++k)
        {
            const double el = (-3.0 + 2.0 * k) * M_PI / 180.0;
            pts[4 * i] = (float)(10.0 * cos(el) * cos(az));
            pts[4 * i + 1] = (float)(10.0 * cos(el) * sin(az));
            pts[4 * i + 2] = (float)(10.0 * sin(el));
            pts[4 * i + 3] = 0.0f;
            ++i;
        }
    }
    for (; i < 200; ++i)
    {
        pts[4 * i] = 30.0f;
        pts[4 * i + 1] = (float)i * 0.01f;
        pts[4 * i + 2] = 0.0f;
        pts[4 * i + 3] = 0.0f;
    }
    return i;
}

/* the compact image of a float image, rounded as the projection rounds (see tests/unit/test_workspace.c) */
static int16_t g_qx[LIDET_MAX_ROWS * LIDET_MAX_COLS], g_qy[LIDET_MAX_ROWS * LIDET_MAX_COLS];
static int16_t g_qz[LIDET_MAX_ROWS * LIDET_MAX_COLS];
static uint16_t g_qr[LIDET_MAX_ROWS * LIDET_MAX_COLS];

static int32_t q4mm(float v)
{
    return (int32_t)floorf(v * LIDET_PIXEL_PER_M + 0.5f);
}

static void compact_by_hand(const lidet_range_image_t *img, lidet_range_image_t *q)
{
    const uint32_t npix = (uint32_t)img->n_rows * img->n_cols;
    uint32_t p;
    for (p = 0; p < npix; ++p)
    {
        const int32_t r = q4mm(img->range_m[p]);
        g_qx[p] = (int16_t)q4mm(img->x_m[p]);
        g_qy[p] = (int16_t)q4mm(img->y_m[p]);
        g_qz[p] = (int16_t)q4mm(img->z_m[p]);
        g_qr[p] = (uint16_t)(img->range_m[p] > 0.0f && r < 1 ? 1 : r);
    }
    *q = *img;
    q->x_m = q->y_m = q->z_m = q->range_m = q->rxy_m = NULL;
    q->point_idx = NULL;
    q->x_4mm = g_qx;
    q->y_4mm = g_qy;
    q->z_4mm = g_qz;
    q->range_4mm = g_qr;
}

static void config(lidet_workspace_cfg_t *cfg)
{
    const lidet_sensor_t *s = lidet_sensor_find("vlp16");
    lidet_workspace_cfg_default(cfg, s);
    cfg->proj.sensor.n_cols = 64;
    cfg->ground.n_sectors = 8;
    cfg->ground.fallback_sectors = 2;
    cfg->cluster.min_points = 1;
    cfg->cluster.max_mean_height_m = 1e30f;
    cfg->cluster.rescue_gap_m = 0.0f;
}

static void test_truncation_and_capacity_drops(void)
{
    lidet_workspace_cfg_t cfg;
    lidet_workspace_stats_t wst;
    lidet_range_image_t fimg, img, wimg;
    const lidet_plane_t *planes;
    const lidet_cluster_rec_t *rw, *rc;
    uint32_t n = scene(), ns, kw, kc, npix;
    lidet_status_t st;

    config(&cfg);
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_workspace_init(&g_ws.ws, &cfg));
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_proj_init(&g_proj.ws, &cfg.proj));
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_ground_init(&g_ground.ws, &cfg.ground));
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_cluster_init(&g_cluster.ws, &cfg.cluster));

    g_pp[LIDET_MAX_POINTS] = 0x12345678; /* the per-point buffer holds LIDET_MAX_POINTS entries */
    st = lidet_workspace_run(&g_ws.ws, pts, n, 4, NULL, g_pp);
    TEST_ASSERT_EQUAL_INT(LIDET_TRUNCATED, st);
    TEST_ASSERT_EQUAL_INT32(0x12345678, g_pp[LIDET_MAX_POINTS]);
    lidet_workspace_stats(&g_ws.ws, &wst);
    TEST_ASSERT_EQUAL_UINT32(200 - LIDET_MAX_POINTS, wst.proj.n_truncated);
    TEST_ASSERT_TRUE(wst.cluster.n_found >= 12u);
    TEST_ASSERT_EQUAL_UINT32(LIDET_MAX_CLUSTERS, wst.cluster.n_kept);
    TEST_ASSERT_TRUE(wst.cluster.n_dropped_capacity > 0u);

    /* the same through the standalone stages (on the compact image made by hand) */
    TEST_ASSERT_EQUAL_INT(LIDET_TRUNCATED, lidet_proj_run(&g_proj.ws, pts, n, 4, NULL));
    lidet_proj_image(&g_proj.ws, &fimg);
    compact_by_hand(&fimg, &img);
    TEST_ASSERT_TRUE(LIDET_SUCCEEDED(lidet_ground_run(&g_ground.ws, &img)));
    planes = lidet_ground_planes(&g_ground.ws, &ns);
    TEST_ASSERT_EQUAL_INT(LIDET_TRUNCATED,
                          lidet_cluster_run(&g_cluster.ws, &img, lidet_ground_mask(&g_ground.ws), planes, ns));
    lidet_workspace_image(&g_ws.ws, &wimg);
    npix = (uint32_t)img.n_rows * img.n_cols;
    TEST_ASSERT_EQUAL_MEMORY(img.x_4mm, wimg.x_4mm, npix * sizeof(int16_t));
    TEST_ASSERT_EQUAL_MEMORY(img.range_4mm, wimg.range_4mm, npix * sizeof(uint16_t));
    TEST_ASSERT_EQUAL_MEMORY(lidet_ground_mask(&g_ground.ws), lidet_workspace_ground_mask(&g_ws.ws), npix);
    TEST_ASSERT_EQUAL_MEMORY(lidet_cluster_labels(&g_cluster.ws), lidet_workspace_labels(&g_ws.ws),
                             npix * sizeof(uint16_t));
    rc = lidet_cluster_records(&g_cluster.ws, &kc);
    rw = lidet_workspace_clusters(&g_ws.ws, &kw);
    TEST_ASSERT_EQUAL_UINT32(kc, kw);
    TEST_ASSERT_EQUAL_MEMORY(rc, rw, kw * sizeof(lidet_cluster_rec_t));
    TEST_ASSERT_EQUAL_MEMORY(lidet_proj_point_pixels(&g_proj.ws, NULL), g_pp, LIDET_MAX_POINTS * sizeof(int32_t));
}

static void test_sizes_at_tiny_capacities(void)
{
    lidet_workspace_sizes_t s;
    lidet_workspace_sizes(&s);
    /* 16 x 64 pixels: 8 B image (int16 x, y, z, range) + 1 B mask per pixel, the overlay the largest of
     * its parts */
    TEST_ASSERT_EQUAL_UINT32(8u * 1024u, s.image);
    TEST_ASSERT_EQUAL_UINT32(1024u, s.ground_mask);
    TEST_ASSERT_EQUAL_UINT32(lidet_ground_scratch_bytes(), s.overlay_ground);
    TEST_ASSERT_TRUE(s.overlay >= s.overlay_ground && s.overlay >= s.overlay_cluster && s.overlay >= s.overlay_proj);
    TEST_ASSERT_EQUAL_UINT32(sizeof(lidet_workspace_t), lidet_workspace_bytes());
    TEST_ASSERT_TRUE(s.total < s.stages_standalone);
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_truncation_and_capacity_drops);
    RUN_TEST(test_sizes_at_tiny_capacities);
    return UNITY_END();
}
