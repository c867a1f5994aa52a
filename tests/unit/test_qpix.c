/* SPDX-License-Identifier: MIT */
/* The integer path's range-only pixel (lib/src/internal/lidet_qpix.h): the projection's tables give exactly the
 * values computed without them; a point projected into a range-only image decodes back to itself within the
 * rounding (points cast on the beam elevations and column centres, both sensors' geometries); empty pixels decode
 * to 0; which images the integer stages accept. */
#include <math.h>
#include <string.h>

#include "internal/lidet_qpix.h"
#include "lidet/lidet_proj_q.h"
#include "test_util.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

static lidet_proj_q_state_t g_st;
static uint16_t g_rng[LIDET_MAX_ROWS * LIDET_MAX_COLS];
static int32_t g_key[LIDET_MAX_ROWS * LIDET_MAX_COLS];
static int32_t g_pts[LIDET_MAX_ROWS * LIDET_MAX_COLS * 3];
static uint16_t g_ring[LIDET_MAX_ROWS * LIDET_MAX_COLS];

void setUp(void)
{
}

void tearDown(void)
{
}

static void init_sensor(const char *name)
{
    lidet_proj_q_cfg_t cfg;
    lidet_proj_q_cfg_default(&cfg, lidet_sensor_q_find(name));
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_proj_q_init(&g_st, &cfg));
}

/* the tables hold exactly what is computed without them: every column, every row, two ranges */
static void check_tables_match(const char *name)
{
    lidet_range_image_t with, without;
    lidet_proj_q_buffers_t b;
    uint32_t r, c, rows, cols;
    init_sensor(name);
    memset(&b, 0, sizeof b);
    b.range_4mm = g_rng;
    lidet_proj_q_image(&g_st, &b, &with);
    TEST_ASSERT_NOT_NULL(with.row_trig_q15);
    TEST_ASSERT_NOT_NULL(with.col_trig_q15); /* both sensors' column counts are multiples of 4 */
    without = with;
    without.row_trig_q15 = 0;
    without.col_trig_q15 = 0;
    rows = with.n_rows;
    cols = with.n_cols;
    for (r = 0; r < rows; ++r)
    {
        for (c = 0; c < cols; ++c)
        {
            g_rng[r * cols + c] = (uint16_t)((r + c) % 2u == 0u ? 32750u : 1u + (c * 7u) % 9000u);
        }
    }
    for (r = 0; r < rows * cols; ++r)
    {
        int32_t a[3], d[3];
        lidet__qpix_xyz(&with, r, a);
        lidet__qpix_xyz(&without, r, d);
        TEST_ASSERT_EQUAL_INT32(d[0], a[0]);
        TEST_ASSERT_EQUAL_INT32(d[1], a[1]);
        TEST_ASSERT_EQUAL_INT32(d[2], a[2]);
    }
}

static void test_tables_match_the_computed_values(void)
{
    check_tables_match("vlp16");
    check_tables_match("hdl64");
}

/* points on every beam and column centre at 5-100 m, projected range-only with their rings, decode back within
 * the rounding: 4 mm steps of the range and the Q15 ray (<= 2 steps) */
static void check_round_trip(const char *name)
{
    lidet_proj_q_buffers_t b;
    lidet_range_image_t img;
    uint32_t r, c, rows, cols, n = 0, worst = 0;
    init_sensor(name);
    rows = g_st.cfg.sensor.n_rows;
    cols = g_st.cfg.sensor.n_cols;
    for (r = 0; r < rows; ++r)
    {
        const double el = g_st.row_elev_urad[r] * 1e-6;
        uint32_t ring = 0;
        while (g_st.ring_to_row[ring] != r)
        {
            ++ring;
        }
        for (c = 0; c < cols; ++c)
        {
            const double az = M_PI - (c + 0.5) * 2.0 * M_PI / cols, d = 5000.0 + 95000.0 * ((c * 37u + r) % 101u) / 100.0;
            g_pts[3 * n] = (int32_t)floor(d * cos(el) * cos(az) + 0.5);
            g_pts[3 * n + 1] = (int32_t)floor(d * cos(el) * sin(az) + 0.5);
            g_pts[3 * n + 2] = (int32_t)floor(d * sin(el) + 0.5);
            g_ring[n] = (uint16_t)ring;
            ++n;
        }
    }
    memset(&b, 0, sizeof b);
    b.range_4mm = g_rng;
    b.point_idx = g_key;
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_proj_q_run(&g_st, &b, g_pts, n, 3, g_ring));
    TEST_ASSERT_EQUAL_UINT32(n, g_st.stats.n_pixels_filled);
    lidet_proj_q_image(&g_st, &b, &img);
    TEST_ASSERT_NULL(img.x_4mm);
    TEST_ASSERT_NULL(img.point_idx); /* the buffer held the keys */
    TEST_ASSERT_TRUE(lidet__qpix_image_ok(&img));
    for (r = 0; r < n; ++r)
    {
        const uint32_t row = g_st.ring_to_row[g_ring[r]], col = r % cols, p = row * cols + col;
        int32_t v[3], k;
        lidet__qpix_xyz(&img, p, v);
        for (k = 0; k < 3; ++k)
        {
            const int32_t e = v[k] * 4 - g_pts[3 * r + k];
            const uint32_t ae = (uint32_t)(e < 0 ? -e : e);
            worst = ae > worst ? ae : worst;
        }
    }
    /* 2 mm of the range's and the coordinates' rounding, the Q15 ray's at 100 m (~4 mm) */
    TEST_ASSERT_TRUE_MESSAGE(worst <= 12u, name);
    TEST_ASSERT_TRUE(worst > 0u); /* the comparison looked at something */
}

static void test_projected_points_decode_back(void)
{
    check_round_trip("vlp16");
    check_round_trip("hdl64");
}

static void test_empty_pixels_and_accepted_images(void)
{
    lidet_proj_q_buffers_t b;
    lidet_range_image_t img, bad;
    int16_t x[4];
    int32_t v[3];
    init_sensor("vlp16");
    memset(&b, 0, sizeof b);
    memset(g_rng, 0, sizeof g_rng);
    b.range_4mm = g_rng;
    lidet_proj_q_image(&g_st, &b, &img);
    lidet__qpix_xyz(&img, 5u * img.n_cols + 451u, v);
    TEST_ASSERT_EQUAL_INT32(0, v[0]);
    TEST_ASSERT_EQUAL_INT32(0, v[1]);
    TEST_ASSERT_EQUAL_INT32(0, v[2]);
    TEST_ASSERT_TRUE(lidet__qpix_image_ok(&img));
    bad = img;
    bad.row_elev_bam = 0; /* nothing to decode from */
    TEST_ASSERT_FALSE(lidet__qpix_image_ok(&bad));
    bad = img;
    bad.range_4mm = 0;
    TEST_ASSERT_FALSE(lidet__qpix_image_ok(&bad));
    bad = img;
    bad.x_4mm = x; /* x without y, z */
    TEST_ASSERT_FALSE(lidet__qpix_image_ok(&bad));
    bad.y_4mm = x;
    bad.z_4mm = x;
    TEST_ASSERT_TRUE(lidet__qpix_image_ok(&bad));
    /* the projection: x, y, z all given or none */
    b.x_4mm = x;
    b.point_idx = g_key;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_ARG, lidet_proj_q_run(&g_st, &b, g_pts, 0, 3, 0));
}

/* lidet__q_div_round (internal/lidet_qmath.h) takes a 32-bit division where the rounded dividend and the divisor
 * fit 32 bits: the same quotients as the int64 rule round(n / d), halves away from zero, on both sides of that
 * boundary, for both signs, at the halves and at random */
static int64_t div_round_ref(int64_t n, int64_t d)
{
    return n >= 0 ? (n + d / 2) / d : -((-n + d / 2) / d);
}

void test_div_round_on_both_sides_of_32_bits(void)
{
    static const int64_t ds[] = {1, 2, 3, 7, 250, 65535, 0x7FFFFFFF, 0xFFFFFFFFLL, 0x100000000LL, 0x200000003LL};
    uint32_t i, j, state = 12345u;
    for (i = 0; i < sizeof ds / sizeof ds[0]; ++i)
    {
        const int64_t d = ds[i], edge = ((int64_t)1 << 32) - d / 2; /* the first |n| past the 32-bit path */
        const int64_t ns[] = {0, 1, d / 2, d / 2 + 1, d - 1, d, 3 * d / 2, edge - 2, edge - 1, edge, edge + 1,
                              (int64_t)1 << 40, ((int64_t)1 << 62) - d};
        for (j = 0; j < sizeof ns / sizeof ns[0]; ++j)
        {
            TEST_ASSERT_EQUAL_INT64(div_round_ref(ns[j], d), lidet__q_div_round(ns[j], d));
            TEST_ASSERT_EQUAL_INT64(div_round_ref(-ns[j], d), lidet__q_div_round(-ns[j], d));
        }
        for (j = 0; j < 2000u; ++j)
        {
            int64_t n;
            state ^= state << 13;
            state ^= state >> 17;
            state ^= state << 5;
            n = (int64_t)(state >> (j % 8u)) * (j % 3u == 0u ? 1 : (int64_t)(j % 5u) + 1);
            n = j & 1u ? -n : n;
            TEST_ASSERT_EQUAL_INT64(div_round_ref(n, d), lidet__q_div_round(n, d));
        }
    }
}

/* the row of a pixel as (p m) >> 26 (the cores without a divide instruction): wherever lidet__q_row_m26
 * gives an m, every pixel's row is p / cols; and it gives one for the sensors' image sizes */
static void test_row_without_a_divide(void)
{
    static const uint32_t sizes[][2] = {{16, 1800}, {32, 1800}, {32, 1024}, {64, 2048}, {64, 1800},
                                        {32, 1085}, {64, 1024}, {16, 2}, {1, 3}, {7, 999}};
    uint32_t k, cols, p;
    for (k = 0; k < sizeof sizes / sizeof sizes[0]; ++k)
    {
        const uint32_t rows = sizes[k][0], c = sizes[k][1], m = lidet__q_row_m26(rows, c);
        TEST_ASSERT_TRUE(m != 0u);
        for (p = 0; p < rows * c; ++p)
            TEST_ASSERT_EQUAL_UINT32(p / c, (p * m) >> 26);
    }
    /* 128 rows: p m would pass 32 bits, so the row is divided */
    TEST_ASSERT_EQUAL_UINT32(0u, lidet__q_row_m26(128, 2048));
    TEST_ASSERT_EQUAL_UINT32(0u, lidet__q_row_m26(128, 1024));
    /* every width up to 2048 at 16 and 64 rows: exact where given, and given up to 64 rows */
    for (cols = 2; cols <= 2048u; ++cols)
    {
        const uint32_t m16 = lidet__q_row_m26(16, cols), m64 = lidet__q_row_m26(64, cols);
        TEST_ASSERT_TRUE(m16 != 0u);
        for (p = 0; p < 16u * cols; p += 1u + p / 4096u)
            TEST_ASSERT_EQUAL_UINT32(p / cols, (p * m16) >> 26);
        if (m64 != 0u)
            for (p = 0; p < 64u * cols; p += 1u + p / 4096u)
                TEST_ASSERT_EQUAL_UINT32(p / cols, (p * m64) >> 26);
    }
    TEST_ASSERT_EQUAL_UINT32(0u, lidet__q_row_m26(0, 1800));
    TEST_ASSERT_EQUAL_UINT32(0u, lidet__q_row_m26(16, 0));
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_tables_match_the_computed_values);
    RUN_TEST(test_projected_points_decode_back);
    RUN_TEST(test_empty_pixels_and_accepted_images);
    RUN_TEST(test_div_round_on_both_sides_of_32_bits);
    RUN_TEST(test_row_without_a_divide);
    return UNITY_END();
}
