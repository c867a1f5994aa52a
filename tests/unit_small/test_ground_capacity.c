/* SPDX-License-Identifier: MIT */
/* Ground stage against the library built with tiny capacities (16 x 64 pixels,
 * LIDET_GROUND_MAX_SAMPLES 100): more samples than slots are dropped deterministically, counted,
 * reported as LIDET_TRUNCATED, and nothing is written past a buffer (canaries). The range image is
 * built by hand (flat ground under a VLP-16-like fan), following the image contract. */
#include <math.h>
#include <string.h>

#include "lidet/lidet.h"
#include "test_util.h"

#define ROWS 16
#define COLS 64

LIDET_GUARDED(lidet_ground_t, g);
static float X[ROWS * COLS], Y[ROWS * COLS], Z[ROWS * COLS], RG[ROWS * COLS], RXY[ROWS * COLS];
static int32_t IDX[ROWS * COLS];
static float ELEV[ROWS];

void setUp(void)
{
    CANARY_FILL(g);
}

void tearDown(void)
{
    CANARY_CHECK(g);
}

static void flat_image(lidet_range_image_t *img, double h)
{
    int r, c;
    memset(img, 0, sizeof *img);
    for (r = 0; r < ROWS; ++r)
    {
        ELEV[r] = (float)((15.0 - 2.0 * r) * M_PI / 180.0); /* row 0 = top beam */
        for (c = 0; c < COLS; ++c)
        {
            const int p = r * COLS + c;
            const double az = M_PI * (1.0 - 2.0 * (c + 0.5) / COLS);
            X[p] = Y[p] = Z[p] = RG[p] = RXY[p] = 0.0f;
            IDX[p] = -1;
            if (ELEV[r] < -0.01f)
            {
                const double rxy = h / tan(-(double)ELEV[r]);
                X[p] = (float)(rxy * cos(az));
                Y[p] = (float)(rxy * sin(az));
                Z[p] = (float)-h;
                RXY[p] = (float)rxy;
                RG[p] = (float)sqrt(rxy * rxy + h * h);
                IDX[p] = p;
            }
        }
    }
    img->n_rows = ROWS;
    img->n_cols = COLS;
    img->x_m = X;
    img->y_m = Y;
    img->z_m = Z;
    img->range_m = RG;
    img->rxy_m = RXY;
    img->point_idx = IDX;
    img->row_elev_rad = ELEV;
}

static void test_samples_over_capacity(void)
{
    lidet_ground_cfg_t cfg;
    lidet_range_image_t img;
    const lidet_ground_stats_t *st;
    const uint8_t *mask;
    uint32_t p, n_ground = 0, n_valid = 0;
    flat_image(&img, 0.5);
    lidet_ground_cfg_default(&cfg, lidet_sensor_find("vlp16"));
    cfg.n_sectors = 4;
    cfg.ring_split_m = 2.5f; /* both ends of the sample buffer in use */
    cfg.min_samples = 5;
    cfg.min_inliers = 5;
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_ground_init(&g.ws, &cfg));
    TEST_ASSERT_EQUAL_INT(LIDET_TRUNCATED, lidet_ground_run(&g.ws, &img));
    st = lidet_ground_stats(&g.ws);
    TEST_ASSERT_TRUE(st->n_samples > LIDET_GROUND_MAX_SAMPLES);
    TEST_ASSERT_EQUAL_UINT32(st->n_samples - LIDET_GROUND_MAX_SAMPLES, st->n_samples_dropped);
    /* sector 0 fills the buffer in raster order: its far rows first (from the back), then 4 near
     * samples (from the front) before the two ends meet; later sectors get nothing */
    TEST_ASSERT_EQUAL_UINT16(1u, st->n_far_fitted);
    TEST_ASSERT_EQUAL_UINT16(4u, st->n_sectors_sparse);
    mask = lidet_ground_mask(&g.ws);
    for (p = 0; p < ROWS * COLS; ++p)
    {
        n_valid += IDX[p] >= 0;
        n_ground += mask[p];
    }
    TEST_ASSERT_EQUAL_UINT32(n_valid, n_ground); /* flat ground: every point is ground */
    /* one plane per sector (split off): sector 0 keeps the first 100 samples and fits */
    cfg.ring_split_m = 0.0f;
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_ground_init(&g.ws, &cfg));
    TEST_ASSERT_EQUAL_INT(LIDET_TRUNCATED, lidet_ground_run(&g.ws, &img));
    st = lidet_ground_stats(&g.ws);
    TEST_ASSERT_EQUAL_UINT16(1u, st->n_sectors_fitted);
    TEST_ASSERT_EQUAL_UINT16(3u, st->n_sectors_neighbour);
    TEST_ASSERT_EQUAL_UINT32(n_valid, st->n_ground);
}

static void test_image_larger_than_capacity(void)
{
    lidet_ground_cfg_t cfg;
    lidet_range_image_t img;
    flat_image(&img, 0.5);
    lidet_ground_cfg_default(&cfg, lidet_sensor_find("vlp16"));
    cfg.n_sectors = 4;
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_ground_init(&g.ws, &cfg));
    img.n_cols = COLS + 1;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_BUFFER, lidet_ground_run(&g.ws, &img));
    cfg.n_sectors = LIDET_GROUND_MAX_SECTORS + 1;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_BUFFER, lidet_ground_init(&g.ws, &cfg));
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_samples_over_capacity);
    RUN_TEST(test_image_larger_than_capacity);
    return UNITY_END();
}
