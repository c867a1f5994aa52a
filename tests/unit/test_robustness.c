/* SPDX-License-Identifier: MIT */
/* Regression tests of the projection bugs the fuzz harnesses found (issue 19, docs/ROBUSTNESS.md; the
 * PointNet one is in test_pointnet.c); the crashing inputs themselves are replayed from
 * tests/fuzz/regressions by the fuzz_replay_* tests. */
#include <math.h>
#include <string.h>

#include "lidet/lidet.h"
#include "test_util.h"

LIDET_GUARDED(lidet_proj_t, g);

void setUp(void)
{
    CANARY_FILL(g);
}

void tearDown(void)
{
    CANARY_CHECK(g);
}

static void init_vlp16(void)
{
    lidet_proj_cfg_t cfg;
    lidet_proj_cfg_default(&cfg, lidet_sensor_find("vlp16"));
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_proj_init(&g.ws, &cfg));
}

/* fuzz_ground: on the ring path, |x|, |y| ~ 1e-20 (a denormal (|x|+|y|) * R) made the pseudo-azimuth +Inf
 * and the column search walked past the edge table: a pixel outside the image. Such a point lies on the z
 * axis: it takes the straight-ahead column, as x = y = 0 does. */
static void test_ring_path_tiny_xy_stays_in_image(void)
{
    static const float xs[] = {-2.7e-20f, 2.7e-20f, -1e-21f, 5e-23f, 0.0f};
    float pts[5 * 3];
    uint16_t ring[5];
    const int32_t *pp;
    uint32_t i, n;
    init_vlp16();
    for (i = 0; i < 5; ++i)
    {
        pts[3 * i] = xs[i];
        pts[3 * i + 1] = i == 3 ? -1e-22f : 0.0f;
        pts[3 * i + 2] = 5.0f;
        ring[i] = (uint16_t)i;
    }
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_proj_run(&g.ws, pts, 5, 3, ring));
    pp = lidet_proj_point_pixels(&g.ws, &n);
    TEST_ASSERT_EQUAL_UINT32(5, n);
    for (i = 0; i < 5; ++i)
    {
        /* the column of x = y = 0 (i = 4), whatever the tiny x, y */
        TEST_ASSERT_TRUE(pp[i] >= 0 && pp[i] < 16 * 1800);
        TEST_ASSERT_EQUAL_INT32(pp[4] % 1800, pp[i] % 1800);
    }
}

/* (|x|+|y|) * R overflowing (R > ~1.3e19 m, accepted without a max range) gave 1 / den = 0 and a column of
 * +-90 degrees whatever the azimuth; now such a point is not projected (counted out of the field of view) */
static void test_overflowing_denominator_not_projected(void)
{
    const float pts[2 * 3] = {1.2e19f, 1.2e19f, 0.0f, 10.0f, 10.0f, 0.0f};
    const int32_t *pp;
    uint32_t n;
    init_vlp16();
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_proj_run(&g.ws, pts, 2, 3, NULL));
    pp = lidet_proj_point_pixels(&g.ws, &n);
    TEST_ASSERT_EQUAL_INT32(-1, pp[0]);
    TEST_ASSERT_TRUE(pp[1] >= 0);
    TEST_ASSERT_EQUAL_UINT32(1, lidet_proj_stats(&g.ws)->n_out_of_fov);
}

/* fuzz_proj: a field of view of zero or denormal width (one beam and no margin; a uniform fov of 2e-41 rad)
 * was accepted, and run() converted 0 * Inf (the lookup-table scale) to an integer: undefined behaviour */
static void test_zero_width_field_of_view_rejected(void)
{
    static const float one_beam[1] = {-0.1f};
    lidet_proj_cfg_t cfg;
    lidet_sensor_t s;
    memset(&s, 0, sizeof s);
    s.n_rows = 1;
    s.n_cols = 64;
    s.beam_elev_rad = one_beam;
    lidet_proj_cfg_default(&cfg, &s);
    cfg.fov_margin_rad = 0.0f;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_proj_init(&g.ws, &cfg));
    cfg.fov_margin_rad = 0.01f; /* the same beam with a margin: fine */
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_proj_init(&g.ws, &cfg));
    s.n_rows = 2;
    s.beam_elev_rad = NULL;
    s.fov_up_rad = 2.2e-41f;
    s.fov_down_rad = 0.0f;
    lidet_proj_cfg_default(&cfg, &s);
    cfg.fov_margin_rad = 0.0f;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_proj_init(&g.ws, &cfg));
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_ring_path_tiny_xy_stays_in_image);
    RUN_TEST(test_overflowing_denominator_not_projected);
    RUN_TEST(test_zero_width_field_of_view_rejected);
    return UNITY_END();
}
