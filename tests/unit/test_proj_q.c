/* SPDX-License-Identifier: MIT */
/* Unity tests of the integer projection (lib/src/proj/lidet_proj_q.c) and the integer sensor presets. */
#include <math.h>
#include <string.h>

#include "lidet/lidet.h"
#include "test_util.h"

#define NPIX (LIDET_MAX_ROWS * LIDET_MAX_COLS)

LIDET_GUARDED(lidet_proj_q_state_t, g);
static int16_t bx[NPIX], by[NPIX], bz[NPIX];
static uint16_t brange[NPIX];
static int32_t bidx[NPIX];
static int32_t bpix[LIDET_MAX_POINTS];
static int32_t pts[(LIDET_MAX_POINTS + 3) * 3];
static lidet_proj_q_buffers_t buf = {bx, by, bz, brange, bidx, bpix};
static lidet_proj_q_cfg_t cfg;

void setUp(void)
{
    CANARY_FILL(g);
}

void tearDown(void)
{
    CANARY_CHECK(g);
}

static void init_sensor(const char *name)
{
    const lidet_sensor_q_t *s = lidet_sensor_q_find(name);
    TEST_ASSERT_NOT_NULL_MESSAGE(s, name);
    lidet_proj_q_cfg_default(&cfg, s);
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_proj_q_init(&g.ws, &cfg));
}

/* a point in mm at range r (m), azimuth az, elevation el (double trigonometry: test side only) */
static void put(int32_t *p, double r, double az, double el)
{
    p[0] = (int32_t)lround(1000.0 * r * cos(el) * cos(az));
    p[1] = (int32_t)lround(1000.0 * r * cos(el) * sin(az));
    p[2] = (int32_t)lround(1000.0 * r * sin(el));
}

/* the presets: same names and shapes as the float ones, elevations the float ones rounded to microradians */
static void test_presets_match_float(void)
{
    uint32_t i;
    for (i = 0; lidet_sensor_at(i) != 0; ++i)
    {
        const lidet_sensor_t *f = lidet_sensor_at(i);
        const lidet_sensor_q_t *q = lidet_sensor_q_at(i);
        int32_t e[LIDET_MAX_ROWS];
        uint32_t r;
        TEST_ASSERT_NOT_NULL(q);
        TEST_ASSERT_EQUAL_STRING(f->name, q->name);
        TEST_ASSERT_EQUAL_PTR(q, lidet_sensor_q_find(f->name));
        TEST_ASSERT_EQUAL_UINT16(f->n_rows, q->n_rows);
        TEST_ASSERT_EQUAL_UINT16(f->n_cols, q->n_cols);
        TEST_ASSERT_EQUAL_INT32((int32_t)lround((double)f->mount_height_m * 1000.0), q->mount_height_mm);
        TEST_ASSERT_EQUAL_INT32((int32_t)lround((double)f->max_range_m * 1000.0), q->max_range_mm);
        TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_sensor_q_elevations(q, e));
        for (r = 0; r < q->n_rows && r < LIDET_MAX_ROWS; ++r)
        {
            const double up = (double)f->fov_up_rad, down = (double)f->fov_down_rad;
            const double ef = f->beam_elev_rad != 0 ? (double)f->beam_elev_rad[r] : up - (r + 0.5) * (up - down) / f->n_rows;
            TEST_ASSERT_TRUE(fabs(e[r] - 1e6 * ef) <= 1.0);
        }
    }
    TEST_ASSERT_NULL(lidet_sensor_q_at(i));
    TEST_ASSERT_NULL(lidet_sensor_q_find("nope"));
    TEST_ASSERT_NULL(lidet_sensor_q_find(0));
}

/* every preset: a point on each beam at a column centre lands on that beam's row and column; row_elev_bam is
 * the microradians in BAM32 */
static void test_every_profile_beam_rows_and_columns(void)
{
    const lidet_sensor_q_t *s;
    uint32_t k;
    for (k = 0; (s = lidet_sensor_q_at(k)) != 0; ++k)
    {
        lidet_range_image_t img;
        uint32_t r, n = 0, cols = s->n_cols;
        if (s->n_rows > LIDET_MAX_ROWS || s->n_cols > LIDET_MAX_COLS)
            continue;
        init_sensor(s->name);
        for (r = 0; r < s->n_rows; ++r)
        {
            const uint32_t c = (r * 37u + 5u) % cols;
            const double az = M_PI * (1.0 - 2.0 * (c + 0.5) / cols);
            put(&pts[3 * n++], 5.0 + (r % 50u), az, g.ws.row_elev_urad[r] * 1e-6);
        }
        TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_proj_q_run(&g.ws, &buf, pts, n, 3u, 0));
        TEST_ASSERT_EQUAL_UINT32(n, g.ws.stats.n_projected);
        lidet_proj_q_image(&g.ws, &buf, &img);
        TEST_ASSERT_NULL(img.x_m);
        TEST_ASSERT_NULL(img.row_elev_rad);
        for (r = 0; r < s->n_rows; ++r)
        {
            const uint32_t c = (r * 37u + 5u) % cols;
            TEST_ASSERT_EQUAL_INT32((int32_t)(r * cols + c), bpix[r]);
            TEST_ASSERT_EQUAL_INT32((int32_t)r, bidx[r * cols + c]);
            TEST_ASSERT_TRUE(fabs(img.row_elev_bam[r] - (double)lround(g.ws.row_elev_urad[r] * 1e-6 * 683565275.576)) <= 1.0);
            if (r > 0)
            {
                TEST_ASSERT_TRUE(g.ws.row_elev_urad[r] < g.ws.row_elev_urad[r - 1]);
            }
        }
    }
}

/* columns: +x is the middle column, straight behind is column 0 (y >= 0) or the last (y < 0), +y is a quarter */
static void test_columns_and_seam(void)
{
    const int32_t p[] = {10000, 0, 0, -10000, 0, 0, -10000, -1, 0, 0, 10000, 0, 0, -10000, 0, 7071, 7071, 0};
    init_sensor("vlp16");
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_proj_q_run(&g.ws, &buf, p, 6u, 3u, 0));
    TEST_ASSERT_EQUAL_INT32(900, bpix[0] % 1800);
    TEST_ASSERT_EQUAL_INT32(0, bpix[1] % 1800);
    TEST_ASSERT_EQUAL_INT32(1799, bpix[2] % 1800);
    TEST_ASSERT_EQUAL_INT32(450, bpix[3] % 1800);
    TEST_ASSERT_EQUAL_INT32(1350, bpix[4] % 1800);
    TEST_ASSERT_EQUAL_INT32(675, bpix[5] % 1800); /* 45 deg: the left edge of column 675 */
    /* a sweep at column centres, all columns */
    {
        uint32_t c;
        for (c = 0; c < 1800u; ++c)
            put(&pts[3 * c], 20.0, M_PI * (1.0 - 2.0 * (c + 0.5) / 1800.0), 0.0);
        TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_proj_q_run(&g.ws, &buf, pts, 1800u, 3u, 0));
        for (c = 0; c < 1800u; ++c)
        {
            TEST_ASSERT_EQUAL_INT32((int32_t)c, bpix[c] % 1800);
        }
    }
}

/* the closest point wins (ties keep the earlier), the image holds it in 4 mm steps, range rounded half up */
static void test_closest_wins_and_rounding(void)
{
    const int32_t p[] = {20000, 0, 0, 1002, 0, 0, 1002, 0, 0, -6, 2000, 1, 1002, 0, 1};
    lidet_range_image_t img;
    uint32_t pix;
    init_sensor("vlp16");
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_proj_q_run(&g.ws, &buf, p, 5u, 3u, 0));
    pix = (uint32_t)bpix[0];
    TEST_ASSERT_EQUAL_INT32(bpix[0], bpix[1]);
    TEST_ASSERT_EQUAL_INT32(bpix[0], bpix[2]);
    TEST_ASSERT_EQUAL_INT32(bpix[0], bpix[4]);
    TEST_ASSERT_EQUAL_INT32(1, bidx[pix]); /* 1002 mm: tie with point 2, the earlier wins; point 4 (r^2 + 1) has the same floor(r^2 / 4) */
    lidet_proj_q_image(&g.ws, &buf, &img);
    TEST_ASSERT_EQUAL_INT16(251, img.x_4mm[pix]); /* 1002 / 4 = 250.5 -> 251 */
    TEST_ASSERT_EQUAL_UINT16(251, img.range_4mm[pix]);
    pix = (uint32_t)bpix[3];
    TEST_ASSERT_EQUAL_INT16(-1, img.x_4mm[pix]); /* -6 / 4 = -1.5 -> -1 (half up) */
    TEST_ASSERT_EQUAL_INT16(500, img.y_4mm[pix]);
    TEST_ASSERT_EQUAL_UINT16(500, img.range_4mm[pix]);
    TEST_ASSERT_EQUAL_UINT32(2u, g.ws.stats.n_pixels_filled); /* points 0..2 and 4 share a pixel, 3 has its own */
}

/* bad input: int32 limits, zero range, beyond the coordinate limit, straight up, min range 0 */
static void test_limits_are_counted(void)
{
    const int32_t p[] = {INT32_MIN, 0, 0, 0, INT32_MAX, 0, 0, 0, INT32_MIN, 0, 0, 0, 131001, 0, 0,
                         131000, 0, 0, 0, 0, 5000, 93000, 93000, 0, 1, 0, 0, 0, 0, -1};
    init_sensor("hdl64");
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_proj_q_run(&g.ws, &buf, p, 10u, 3u, 0));
    TEST_ASSERT_EQUAL_UINT32(5u, g.ws.stats.n_too_far); /* 3 at the int32 limits, 131001, 93 m x 93 m */
    TEST_ASSERT_EQUAL_UINT32(3u, g.ws.stats.n_too_close); /* zero range, 1 mm, 1 mm */
    TEST_ASSERT_EQUAL_UINT32(1u, g.ws.stats.n_out_of_fov); /* straight up */
    TEST_ASSERT_EQUAL_UINT32(1u, g.ws.stats.n_projected);
    TEST_ASSERT_EQUAL_INT16(32750, bx[bpix[5]]);
    cfg.min_range_mm = 0;
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_proj_q_init(&g.ws, &cfg));
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_proj_q_run(&g.ws, &buf, p, 10u, 3u, 0));
    TEST_ASSERT_EQUAL_UINT32(1u, g.ws.stats.n_too_close); /* zero range still is */
    TEST_ASSERT_EQUAL_UINT32(1u, brange[bpix[8]]);        /* 1 mm: a valid pixel reads >= 1 */
    TEST_ASSERT_EQUAL_INT32(-1, bpix[9]);                 /* straight down: out of the fov */
}

static void test_ring_path(void)
{
    const int32_t p[] = {10000, 0, 0, 10000, 0, 0, 0, 0, 3000, 10000, 0, 50000};
    const uint16_t ring[] = {0, 16, 15, 3};
    init_sensor("vlp16");
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_proj_q_run(&g.ws, &buf, p, 4u, 3u, ring));
    TEST_ASSERT_EQUAL_UINT32(1u, g.ws.stats.n_bad_ring);
    TEST_ASSERT_EQUAL_UINT32(0u, g.ws.stats.n_out_of_fov);
    TEST_ASSERT_EQUAL_INT32(15 * 1800 + 900, bpix[0]); /* ring 0 = lowest beam = row 15 */
    TEST_ASSERT_EQUAL_INT32(-1, bpix[1]);
    TEST_ASSERT_EQUAL_INT32(900, bpix[2]);             /* x = y = 0: straight ahead, top row */
    TEST_ASSERT_EQUAL_INT32(12 * 1800 + 900, bpix[3]); /* ring order, not elevation */
}

static void test_errors_and_truncation(void)
{
    lidet_proj_q_buffers_t b = buf;
    lidet_sensor_q_t s;
    const int32_t dup[2] = {1000, 1000}, steep[2] = {1100001, 0};
    uint32_t i;
    memset(&g.ws, 0, sizeof g.ws);
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_STATE, lidet_proj_q_run(&g.ws, &buf, pts, 1u, 3u, 0));
    init_sensor("vlp16");
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_ARG, lidet_proj_q_run(0, &buf, pts, 1u, 3u, 0));
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_ARG, lidet_proj_q_run(&g.ws, &buf, pts, 1u, 2u, 0));
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_ARG, lidet_proj_q_run(&g.ws, &buf, 0, 1u, 3u, 0));
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_proj_q_run(&g.ws, &buf, 0, 0u, 3u, 0));
    b.range_4mm = 0;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_ARG, lidet_proj_q_run(&g.ws, &b, pts, 1u, 3u, 0));
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_ARG, lidet_proj_q_init(0, &cfg));
    s = cfg.sensor;
    cfg.sensor.n_rows = 2;
    cfg.sensor.beam_elev_urad = dup;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_proj_q_init(&g.ws, &cfg));
    cfg.sensor.beam_elev_urad = steep;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_proj_q_init(&g.ws, &cfg));
    cfg.sensor.beam_elev_urad = 0; /* uniform: fov_up <= fov_down */
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_proj_q_init(&g.ws, &cfg));
    cfg.sensor = s;
    cfg.sensor.n_cols = 7;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_proj_q_init(&g.ws, &cfg));
    cfg.sensor.n_cols = LIDET_MAX_COLS + 1;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_BUFFER, lidet_proj_q_init(&g.ws, &cfg));
    cfg.sensor = s;
    cfg.fov_margin_urad = -1;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_proj_q_init(&g.ws, &cfg));
    cfg.fov_margin_urad = 0;
    cfg.max_range_mm = 50;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_proj_q_init(&g.ws, &cfg));
    /* truncation: points past LIDET_MAX_POINTS are counted, not looked at */
    init_sensor("vlp16");
    for (i = 0; i < LIDET_MAX_POINTS + 3u; ++i)
    {
        pts[3 * i] = 5000 + (int32_t)(i % 1000u);
        pts[3 * i + 1] = (int32_t)(i % 977u) - 488;
        pts[3 * i + 2] = 0;
    }
    TEST_ASSERT_EQUAL_INT(LIDET_TRUNCATED, lidet_proj_q_run(&g.ws, &buf, pts, LIDET_MAX_POINTS + 3u, 3u, 0));
    TEST_ASSERT_EQUAL_UINT32(3u, g.ws.stats.n_truncated);
    TEST_ASSERT_EQUAL_UINT32(LIDET_MAX_POINTS, g.ws.stats.n_projected);
    TEST_ASSERT_TRUE(lidet_proj_q_state_bytes() == sizeof(lidet_proj_q_state_t));
}

/* returns (range, azimuth, ring): the ring's row, the column of the azimuth (straight ahead, +x, is the middle
 * column as in lidet_proj_q_run; +y a quarter turn before), round(range / 4); the nearest of a pixel wins;
 * limits and bad arguments are counted or refused */
static void test_returns(void)
{
    static lidet_return_t ret[6];
    const lidet_proj_stats_t *st;
    uint32_t cols;
    lidet_proj_q_buffers_t ro = {0, 0, 0, brange, bidx, bpix};
    init_sensor("vlp16");
    cols = cfg.sensor.n_cols;
    ret[0].range_mm = 10001u; /* ahead */
    ret[0].azimuth = 0u;
    ret[0].ring = 0u;
    ret[1].range_mm = 6000u; /* left, +y */
    ret[1].azimuth = 0x4000u;
    ret[1].ring = 1u;
    ret[2] = ret[1]; /* the same pixel, nearer: wins */
    ret[2].range_mm = 5999u;
    ret[3].range_mm = 0u; /* no return */
    ret[4] = ret[0];
    ret[4].ring = 16u; /* no such ring */
    ret[5] = ret[0];
    ret[5].range_mm = 131001u; /* past the compact image */
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_proj_q_run_returns(&g.ws, &buf, ret, 6u));
    st = lidet_proj_q_stats(&g.ws);
    TEST_ASSERT_EQUAL_UINT32(3u, st->n_projected);
    TEST_ASSERT_EQUAL_UINT32(2u, st->n_pixels_filled);
    TEST_ASSERT_EQUAL_UINT32(1u, st->n_too_close);
    TEST_ASSERT_EQUAL_UINT32(1u, st->n_too_far);
    TEST_ASSERT_EQUAL_UINT32(1u, st->n_bad_ring);
    TEST_ASSERT_EQUAL_INT32((int32_t)(g.ws.ring_to_row[0] * cols + cols / 2u), bpix[0]);
    TEST_ASSERT_EQUAL_INT32((int32_t)(g.ws.ring_to_row[1] * cols + cols / 4u), bpix[1]);
    TEST_ASSERT_EQUAL_INT32(bpix[1], bpix[2]);
    TEST_ASSERT_EQUAL_INT32(-1, bpix[3]);
    TEST_ASSERT_EQUAL_UINT16(2500u, brange[bpix[0]]);
    TEST_ASSERT_EQUAL_UINT16(1500u, brange[bpix[1]]);
    TEST_ASSERT_EQUAL_INT32(2, bidx[bpix[1]]);
    /* decoded at the column centre (half a column, 0.1 deg, off the azimuth) and the beam's elevation */
    TEST_ASSERT_TRUE(bx[bpix[0]] > 2400 && by[bpix[0]] > -10 && by[bpix[0]] < 10);
    TEST_ASSERT_TRUE(by[bpix[1]] > 1400 && bx[bpix[1]] > -10 && bx[bpix[1]] < 10);
    /* the range-only image: the same ranges */
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_proj_q_run_returns(&g.ws, &ro, ret, 6u));
    TEST_ASSERT_EQUAL_UINT16(2500u, brange[bpix[0]]);
    TEST_ASSERT_EQUAL_UINT16(1500u, brange[bpix[1]]);
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_proj_q_run_returns(&g.ws, &ro, 0, 0u));
    TEST_ASSERT_EQUAL_UINT32(0u, lidet_proj_q_stats(&g.ws)->n_pixels_filled);
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_ARG, lidet_proj_q_run_returns(&g.ws, &ro, 0, 1u));
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_ARG, lidet_proj_q_run_returns(0, &ro, ret, 1u));
    ro.y_4mm = by; /* x, y, z all or none */
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_ARG, lidet_proj_q_run_returns(&g.ws, &ro, ret, 1u));
    g.ws.magic = 0;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_STATE, lidet_proj_q_run_returns(&g.ws, &buf, ret, 1u));
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_presets_match_float);
    RUN_TEST(test_every_profile_beam_rows_and_columns);
    RUN_TEST(test_columns_and_seam);
    RUN_TEST(test_closest_wins_and_rounding);
    RUN_TEST(test_limits_are_counted);
    RUN_TEST(test_ring_path);
    RUN_TEST(test_errors_and_truncation);
    RUN_TEST(test_returns);
    return UNITY_END();
}
