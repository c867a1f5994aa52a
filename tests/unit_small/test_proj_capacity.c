/* SPDX-License-Identifier: MIT */
/* Projection against a library built with tiny capacities (LIDET_MAX_POINTS 64, 16 x 64 pixels):
 * over-capacity scans are truncated with a status and counted, nothing is written past a buffer. */
#include <math.h>
#include <string.h>

#include "lidet/lidet.h"
#include "test_util.h"

LIDET_GUARDED(lidet_proj_t, g);
static float pts[200 * 4];

void setUp(void)
{
    CANARY_FILL(g);
}

void tearDown(void)
{
    CANARY_CHECK(g);
}

static void test_truncated_scan(void)
{
    lidet_proj_cfg_t cfg;
    uint32_t i, n;
    const int32_t *pp;
    const lidet_proj_stats_t *st;
    lidet_proj_cfg_default(&cfg, lidet_sensor_find("vlp16"));
    cfg.sensor.n_cols = 64;
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_proj_init(&g.ws, &cfg));
    for (i = 0; i < 200; ++i)
    {
        double az = 2.0 * M_PI * i / 200.0;
        pts[4 * i] = (float)(10.0 * cos(az));
        pts[4 * i + 1] = (float)(10.0 * sin(az));
        pts[4 * i + 2] = -1.0f;
        pts[4 * i + 3] = 0.0f;
    }
    TEST_ASSERT_EQUAL_INT(LIDET_TRUNCATED, lidet_proj_run(&g.ws, pts, 200, 4, NULL));
    st = lidet_proj_stats(&g.ws);
    TEST_ASSERT_EQUAL_UINT32(200, st->n_points_in);
    TEST_ASSERT_EQUAL_UINT32(200 - LIDET_MAX_POINTS, st->n_truncated);
    TEST_ASSERT_EQUAL_UINT32(LIDET_MAX_POINTS, st->n_projected);
    pp = lidet_proj_point_pixels(&g.ws, &n);
    TEST_ASSERT_EQUAL_UINT32(LIDET_MAX_POINTS, n);
    TEST_ASSERT_TRUE(pp[LIDET_MAX_POINTS - 1] >= 0);
    /* exactly at capacity: not truncated */
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_proj_run(&g.ws, pts, LIDET_MAX_POINTS, 4, NULL));
}

static void test_sensor_larger_than_capacity(void)
{
    lidet_proj_cfg_t cfg;
    lidet_proj_cfg_default(&cfg, lidet_sensor_find("hdl64"));
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_BUFFER, lidet_proj_init(&g.ws, &cfg));
    lidet_proj_cfg_default(&cfg, lidet_sensor_find("vlp16")); /* 1800 cols > 64 */
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_BUFFER, lidet_proj_init(&g.ws, &cfg));
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_truncated_scan);
    RUN_TEST(test_sensor_larger_than_capacity);
    return UNITY_END();
}
