/* SPDX-License-Identifier: MIT */
/* Unity tests of the spherical projection (lib/src/proj/lidet_proj.c). */
#include <math.h>
#include <string.h>

#include "lidet/lidet.h"
#include "test_util.h"

LIDET_GUARDED(lidet_proj_t, g);
static lidet_proj_cfg_t cfg;
static float pts[4096 * 4];

static const char *const k_names[] = {"hdl64",  "vlp16",  "vlp32c", "os1-64", "os1-128", "hdl32",  "os0-32",
                                      "os0-64", "os0-128", "os1-32", "os2-32", "os2-64",  "os2-128", "pandar64"};

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
    const lidet_sensor_t *s = lidet_sensor_find(name);
    TEST_ASSERT_NOT_NULL_MESSAGE(s, name);
    lidet_proj_cfg_default(&cfg, s);
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_proj_init(&g.ws, &cfg));
}

/* point at range r, azimuth az, elevation el (double-precision trigonometry: test side only) */
static void put(float *p, double r, double az, double el)
{
    p[0] = (float)(r * cos(el) * cos(az));
    p[1] = (float)(r * cos(el) * sin(az));
    p[2] = (float)(r * sin(el));
    p[3] = 0.5f;
}

static int expected_col(double az, int cols)
{
    double u = 0.5 * (1.0 - az / M_PI) * cols;
    int c = (int)floor(u);
    return c >= cols ? c - cols : c;
}

/* every preset: a point on each beam, at azimuths away from column edges, lands on that beam's row */
static void test_every_profile_beam_rows(void)
{
    unsigned k;
    for (k = 0; k < sizeof k_names / sizeof k_names[0]; ++k)
    {
        lidet_range_image_t img;
        int r, n = 0;
        init_sensor(k_names[k]);
        lidet_proj_image(&g.ws, &img);
        TEST_ASSERT_EQUAL_UINT16(lidet_sensor_find(k_names[k])->n_rows, img.n_rows);
        for (r = 0; r < img.n_rows; ++r)
        {
            /* centre of a column: az such that u = col + 0.5 */
            int col = (r * 37 + 11) % img.n_cols;
            double az = M_PI * (1.0 - 2.0 * (col + 0.5) / img.n_cols);
            put(&pts[4 * n++], 5.0 + r, az, (double)img.row_elev_rad[r]);
        }
        TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_proj_run(&g.ws, pts, (uint32_t)n, 4, NULL));
        TEST_ASSERT_EQUAL_UINT32((uint32_t)n, lidet_proj_stats(&g.ws)->n_projected);
        for (r = 0; r < img.n_rows; ++r)
        {
            int col = (r * 37 + 11) % img.n_cols;
            int pix = r * img.n_cols + col;
            TEST_ASSERT_EQUAL_INT32_MESSAGE(r, img.point_idx[pix], k_names[k]);
            TEST_ASSERT_CLOSE(5.0 + r, img.range_m[pix], 1e-4, 1e-6);
            TEST_ASSERT_CLOSE(sqrt((double)img.x_m[pix] * (double)img.x_m[pix] +
                                   (double)img.y_m[pix] * (double)img.y_m[pix]),
                              img.rxy_m[pix], 1e-5, 1e-6);
        }
        /* rows are sorted top to bottom */
        for (r = 1; r < img.n_rows; ++r)
        {
            TEST_ASSERT_TRUE(img.row_elev_rad[r] < img.row_elev_rad[r - 1]);
        }
    }
}

/* a uniform-fov profile reproduces the classic formula row = floor((fov_up - pitch) / step) */
static void test_uniform_profile_matches_formula(void)
{
    const double up = 22.5 * M_PI / 180.0, down = -22.5 * M_PI / 180.0;
    int i, n = 2000;
    lidet_range_image_t img;
    init_sensor("os1-64");
    for (i = 0; i < n; ++i)
    {
        double el = down + (up - down) * (i + 0.37) / n;
        put(&pts[4 * i], 10.0, 0.001 * i, el);
    }
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_proj_run(&g.ws, pts, (uint32_t)n, 4, NULL));
    lidet_proj_image(&g.ws, &img);
    for (i = 0; i < n; ++i)
    {
        double el = down + (up - down) * (i + 0.37) / n;
        int row = (int)floor((up - el) / ((up - down) / 64.0));
        uint32_t np;
        const int32_t *pp = lidet_proj_point_pixels(&g.ws, &np);
        TEST_ASSERT_EQUAL_UINT32((uint32_t)n, np);
        TEST_ASSERT_EQUAL_INT(row, pp[i] / img.n_cols);
    }
}

/* azimuth +-180 deg wraps to column 0; just inside -180 is the last column; +x is the middle */
static void test_wraparound(void)
{
    lidet_range_image_t img;
    uint32_t n;
    const int32_t *pp;
    init_sensor("vlp16");
    lidet_proj_image(&g.ws, &img);
    put(&pts[0], 10.0, M_PI - 1e-4, 0.0);  /* just left of straight behind */
    put(&pts[4], 10.0, -M_PI + 1e-4, 0.0); /* just right of straight behind */
    pts[8] = -10.0f;
    pts[9] = 0.0f;
    pts[10] = 0.0f; /* exactly +180 */
    pts[12] = -10.0f;
    pts[13] = -0.0f;
    pts[14] = 0.5f; /* -0.0: exactly -180 */
    put(&pts[16], 10.0, 0.0, 0.0);
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_proj_run(&g.ws, pts, 5, 4, NULL));
    pp = lidet_proj_point_pixels(&g.ws, &n);
    TEST_ASSERT_EQUAL_INT(0, pp[0] % img.n_cols);
    TEST_ASSERT_EQUAL_INT(img.n_cols - 1, pp[1] % img.n_cols);
    TEST_ASSERT_EQUAL_INT(0, pp[2] % img.n_cols);
    TEST_ASSERT_EQUAL_INT(0, pp[3] % img.n_cols);
    TEST_ASSERT_EQUAL_INT(img.n_cols / 2, pp[4] % img.n_cols);
}

/* columns agree with the floor formula on a dense sweep (away from edges by > 2e-5 rad) */
static void test_columns_sweep(void)
{
    int i, n = 4000, checked = 0;
    uint32_t np;
    const int32_t *pp;
    init_sensor("hdl64");
    for (i = 0; i < n; ++i)
    {
        put(&pts[4 * i], 20.0, -M_PI + 2.0 * M_PI * (i + 0.5) / n, -0.05);
    }
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_proj_run(&g.ws, pts, (uint32_t)n, 4, NULL));
    pp = lidet_proj_point_pixels(&g.ws, &np);
    for (i = 0; i < n; ++i)
    {
        double az = atan2((double)pts[4 * i + 1], (double)pts[4 * i]);
        double u = 0.5 * (1.0 - az / M_PI) * 2048;
        if (fabs(u - floor(u + 0.5)) * (2.0 * M_PI / 2048) > 2e-5)
        {
            TEST_ASSERT_EQUAL_INT(expected_col(az, 2048), pp[i] % 2048);
            ++checked;
        }
    }
    TEST_ASSERT_TRUE(checked > n * 9 / 10);
}

/* the pseudo-azimuth key is monotonic in azimuth with the documented anchor values */
static void test_azimuth_key(void)
{
    float prev = -1.0f;
    int i;
    TEST_ASSERT_EQUAL_FLOAT(0.0f, lidet_proj_azimuth_key(-1.0f, 0.0f));
    TEST_ASSERT_EQUAL_FLOAT(0.0f, lidet_proj_azimuth_key(-1.0f, -0.0f));
    TEST_ASSERT_EQUAL_FLOAT(1.0f, lidet_proj_azimuth_key(0.0f, 1.0f));
    TEST_ASSERT_EQUAL_FLOAT(2.0f, lidet_proj_azimuth_key(1.0f, 0.0f));
    TEST_ASSERT_EQUAL_FLOAT(3.0f, lidet_proj_azimuth_key(0.0f, -1.0f));
    TEST_ASSERT_EQUAL_FLOAT(2.0f, lidet_proj_azimuth_key(0.0f, 0.0f));
    for (i = 0; i < 100000; ++i) /* azimuth from +pi down to -pi */
    {
        double a = M_PI - 2.0 * M_PI * (i + 0.5) / 100000.0;
        float k = lidet_proj_azimuth_key((float)(50.0 * cos(a)), (float)(50.0 * sin(a)));
        TEST_ASSERT_TRUE(k >= prev && k <= 4.0f);
        prev = k;
    }
}

/* points a hair either side of the seam (D a few ulp outside [0, 4]) stay inside the image */
static void test_seam_rounding(void)
{
    int i, n = 0;
    uint32_t np;
    const int32_t *pp;
    init_sensor("hdl64");
    for (i = 0; i < 200; ++i)
    {
        const float x = -(1.0f + 0.37f * (float)i);
        const float ys[4] = {1e-30f, -1e-30f, 1e-7f * (float)i, -1e-7f * (float)i};
        int k;
        for (k = 0; k < 4; ++k)
        {
            pts[4 * n] = x;
            pts[4 * n + 1] = ys[k];
            pts[4 * n + 2] = 0.05f * x;
            pts[4 * n + 3] = 0.0f;
            ++n;
        }
    }
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_proj_run(&g.ws, pts, (uint32_t)n, 4, NULL));
    pp = lidet_proj_point_pixels(&g.ws, &np);
    for (i = 0; i < n; ++i)
    {
        const int col = pp[i] % 2048;
        TEST_ASSERT_TRUE(pp[i] >= 0 && pp[i] < 64 * 2048);
        TEST_ASSERT_TRUE(col == 0 || col == 2047);
    }
}

/* the caller's ring index decides the row (vlp16: ring 0 = lowest beam = last row) */
static void test_ring_index_path(void)
{
    uint16_t ring[3] = {0, 15, 16};
    uint32_t n;
    const int32_t *pp;
    lidet_range_image_t img;
    init_sensor("vlp16");
    lidet_proj_image(&g.ws, &img);
    put(&pts[0], 10.0, 0.3, 0.0); /* elevation 0 would be between beams; ring says lowest */
    put(&pts[4], 10.0, 0.6, 0.0);
    put(&pts[8], 10.0, 0.9, 0.0); /* ring 16 does not exist */
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_proj_run(&g.ws, pts, 3, 4, ring));
    pp = lidet_proj_point_pixels(&g.ws, &n);
    TEST_ASSERT_EQUAL_INT(15, pp[0] / img.n_cols);
    TEST_ASSERT_EQUAL_INT(0, pp[1] / img.n_cols);
    TEST_ASSERT_EQUAL_INT(-1, pp[2]);
    TEST_ASSERT_EQUAL_UINT32(1, lidet_proj_stats(&g.ws)->n_bad_ring);
    TEST_ASSERT_EQUAL_UINT32(2, lidet_proj_stats(&g.ws)->n_projected);
}

/* closest point wins regardless of order; exact ties keep the earlier point; losers keep the pixel */
static void test_closest_wins(void)
{
    uint32_t n;
    const int32_t *pp;
    lidet_range_image_t img;
    init_sensor("hdl64");
    lidet_proj_image(&g.ws, &img);
    put(&pts[0], 30.0, 0.2, -0.1);
    put(&pts[4], 12.0, 0.2, -0.1);
    put(&pts[8], 50.0, 0.2, -0.1);
    memcpy(&pts[12], &pts[4], 4 * sizeof(float)); /* exact tie with point 1 */
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_proj_run(&g.ws, pts, 4, 4, NULL));
    pp = lidet_proj_point_pixels(&g.ws, &n);
    TEST_ASSERT_EQUAL_INT(pp[0], pp[1]);
    TEST_ASSERT_EQUAL_INT(pp[0], pp[2]);
    TEST_ASSERT_EQUAL_INT(pp[0], pp[3]);
    TEST_ASSERT_EQUAL_INT32(1, img.point_idx[pp[0]]);
    TEST_ASSERT_CLOSE(12.0, img.range_m[pp[0]], 1e-4, 0.0);
    TEST_ASSERT_EQUAL_UINT32(1, lidet_proj_stats(&g.ws)->n_pixels_filled);
}

static void test_invalid_points_counted(void)
{
    uint32_t n, i;
    const int32_t *pp;
    const lidet_proj_stats_t *st;
    lidet_range_image_t img;
    const float nan = NAN, inf = INFINITY;
    float bad[9][4] = {
        {nan, 1.0f, 1.0f, 0.0f},    {1.0f, inf, 1.0f, 0.0f},   {1.0f, 1.0f, -inf, 0.0f}, /* non-finite */
        {0.0f, 0.0f, 0.0f, 0.0f},   {0.01f, 0.0f, 0.0f, 0.0f},                           /* too close */
        {1.0f, 0.0f, 1.0f, 0.0f},   /* +45 deg: out of fov */
        {0.0f, 0.0f, -5.0f, 0.0f},  /* straight down */
        {3e19f, 3e19f, 0.0f, 0.0f}, /* r^2 overflows */
        {10.0f, 0.0f, -0.5f, 0.0f}, /* valid */
    };
    init_sensor("hdl64");
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_proj_run(&g.ws, &bad[0][0], 9, 4, NULL));
    st = lidet_proj_stats(&g.ws);
    TEST_ASSERT_EQUAL_UINT32(9, st->n_points_in);
    TEST_ASSERT_EQUAL_UINT32(3, st->n_nonfinite);
    TEST_ASSERT_EQUAL_UINT32(2, st->n_too_close);
    TEST_ASSERT_EQUAL_UINT32(2, st->n_out_of_fov);
    TEST_ASSERT_EQUAL_UINT32(1, st->n_too_far);
    TEST_ASSERT_EQUAL_UINT32(1, st->n_projected);
    pp = lidet_proj_point_pixels(&g.ws, &n);
    for (i = 0; i < 8; ++i)
    {
        TEST_ASSERT_EQUAL_INT32(-1, pp[i]);
    }
    TEST_ASSERT_TRUE(pp[8] >= 0);
    /* every other pixel is empty and zero */
    lidet_proj_image(&g.ws, &img);
    for (i = 0; i < (uint32_t)img.n_rows * img.n_cols; ++i)
    {
        if ((int32_t)i != pp[8])
        {
            TEST_ASSERT_EQUAL_INT32(-1, img.point_idx[i]);
            TEST_ASSERT_EQUAL_FLOAT(0.0f, img.range_m[i]);
        }
    }
    /* max range, when set, drops far points */
    cfg.max_range_m = 5.0f;
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_proj_init(&g.ws, &cfg));
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_proj_run(&g.ws, &bad[8][0], 1, 4, NULL));
    TEST_ASSERT_EQUAL_UINT32(1, lidet_proj_stats(&g.ws)->n_too_far);
}

static void test_empty_scan(void)
{
    init_sensor("vlp16");
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_proj_run(&g.ws, NULL, 0, 4, NULL));
    TEST_ASSERT_EQUAL_UINT32(0, lidet_proj_stats(&g.ws)->n_pixels_filled);
}

static void test_argument_and_config_errors(void)
{
    static lidet_proj_t fresh; /* zero: never initialised */
    lidet_sensor_t s;
    float dup[3] = {0.1f, 0.0f, 0.1f};
    float ok3[3] = {0.1f, 0.0f, -0.1f};
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_STATE, lidet_proj_run(&fresh, pts, 1, 4, NULL));
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_ARG, lidet_proj_init(NULL, &cfg));
    init_sensor("vlp16");
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_ARG, lidet_proj_run(&g.ws, NULL, 3, 4, NULL));
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_ARG, lidet_proj_run(&g.ws, pts, 3, 2, NULL));
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_ARG, lidet_proj_run(NULL, pts, 3, 4, NULL));

    memset(&s, 0, sizeof s);
    s.name = "custom";
    s.n_rows = 3;
    s.n_cols = 360;
    s.beam_elev_rad = dup;
    lidet_proj_cfg_default(&cfg, &s);
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_proj_init(&g.ws, &cfg));          /* duplicate elevations */
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_STATE, lidet_proj_run(&g.ws, pts, 1, 4, NULL)); /* failed init */
    cfg.sensor.beam_elev_rad = ok3;
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_proj_init(&g.ws, &cfg));
    cfg.sensor.n_cols = 4;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_proj_init(&g.ws, &cfg));
    cfg.sensor.n_cols = LIDET_MAX_COLS + 1;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_BUFFER, lidet_proj_init(&g.ws, &cfg));
    cfg.sensor.n_cols = 360;
    cfg.min_range_m = NAN;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_proj_init(&g.ws, &cfg));
    cfg.min_range_m = 1.0f;
    cfg.max_range_m = 0.5f;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_proj_init(&g.ws, &cfg));
    cfg.max_range_m = 2.0e6f; /* above the documented 1e6 m */
    cfg.min_range_m = 0.1f;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_proj_init(&g.ws, &cfg));
    cfg.max_range_m = 0.0f;
    cfg.sensor.beam_elev_rad = NULL; /* uniform fov, inverted */
    cfg.sensor.fov_up_rad = -0.1f;
    cfg.sensor.fov_down_rad = 0.1f;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_proj_init(&g.ws, &cfg));
    cfg.sensor.fov_up_rad = 0.1f;
    cfg.sensor.fov_down_rad = -0.1f;
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_proj_init(&g.ws, &cfg));
    TEST_ASSERT_NULL(lidet_sensor_find("nope"));
    TEST_ASSERT_NULL(lidet_sensor_find(NULL));
    TEST_ASSERT_NOT_NULL(lidet_sensor_at(0));
    TEST_ASSERT_NOT_NULL(lidet_sensor_at(sizeof k_names / sizeof k_names[0] - 1));
    TEST_ASSERT_NULL(lidet_sensor_at(sizeof k_names / sizeof k_names[0]));
    TEST_ASSERT_TRUE(strlen(lidet_status_str(LIDET_ERR_CONFIG)) > 0);
    TEST_ASSERT_EQUAL_UINT32(sizeof(lidet_proj_t), lidet_proj_bytes());
}

/* a custom table in arbitrary ring order is sorted into rows; rings map accordingly */
static void test_custom_ring_order(void)
{
    float elev[4] = {-0.05f, 0.1f, -0.2f,
                     0.0f}; /* rows: 0.1 (ring1), 0.0 (ring3), -0.05 (ring0), -0.2 (ring2) */
    uint16_t ring[4] = {0, 1, 2, 3};
    int expect_row[4] = {2, 0, 3, 1};
    lidet_sensor_t s;
    uint32_t n;
    int i;
    const int32_t *pp;
    memset(&s, 0, sizeof s);
    s.n_rows = 4;
    s.n_cols = 64;
    s.beam_elev_rad = elev;
    lidet_proj_cfg_default(&cfg, &s);
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_proj_init(&g.ws, &cfg));
    for (i = 0; i < 4; ++i)
    {
        put(&pts[4 * i], 10.0, 0.1 * i, elev[i]);
    }
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_proj_run(&g.ws, pts, 4, 4, NULL));
    pp = lidet_proj_point_pixels(&g.ws, &n);
    for (i = 0; i < 4; ++i)
    {
        TEST_ASSERT_EQUAL_INT(expect_row[i], pp[i] / 64);
    }
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_proj_run(&g.ws, pts, 4, 4, ring));
    for (i = 0; i < 4; ++i)
    {
        TEST_ASSERT_EQUAL_INT(expect_row[i], pp[i] / 64);
    }
}

/* run() works on blocks of points (vectorizable keys, then lookups, then the closest-point test): the
 * result must not depend on the block split nor on the record stride. 300 points (not a multiple of
 * the block) with invalid ones at block edges and repeated pixels across blocks, projected with
 * strides 4, 3 and 6 and one point at a time, must give the same image, pixels and counts. */
#define NB 300
static float st_pts[NB * 6];
static float ref_x[64 * 2048], ref_range[64 * 2048], ref_rxy[64 * 2048];
static int32_t ref_idx[64 * 2048], ref_pp[NB];

static void project_strided(uint32_t stride, lidet_proj_stats_t *out)
{
    uint32_t i, k;
    for (i = 0; i < NB; ++i)
    {
        for (k = 0; k < stride; ++k)
        {
            st_pts[i * stride + k] = k < 3 ? pts[4 * i + k] : -7.0f;
        }
    }
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_proj_run(&g.ws, st_pts, NB, stride, NULL));
    *out = *lidet_proj_stats(&g.ws);
}

static void test_blocks_and_strides_agree(void)
{
    const float nan = NAN, inf = INFINITY;
    const int bad_at[8] = {0, 63, 64, 65, 127, 128, 200, 299};
    const float bad[8][3] = {{nan, 1.0f, 1.0f},   {1.0f, inf, 1.0f},  {0.0f, 0.0f, 0.0f},
                             {0.0f, 0.0f, -5.0f}, {1.0f, 0.0f, 1.0f}, {3e19f, 3e19f, 0.0f},
                             {0.01f, 0.0f, 0.0f}, {0.0f, 0.0f, 4.0f}};
    const uint32_t npix = 64u * 2048u;
    lidet_proj_stats_t st4, st;
    lidet_range_image_t img;
    const int32_t *pp;
    uint32_t i, n, strides[2] = {3, 6};
    uint32_t seed = 12345u;
    init_sensor("hdl64");
    lidet_proj_image(&g.ws, &img);
    for (i = 0; i < NB; ++i)
    {
        double az, el, r;
        seed = seed * 1664525u + 1013904223u;
        az = -M_PI + 2.0 * M_PI * (double)(seed >> 8) / 16777216.0;
        seed = seed * 1664525u + 1013904223u;
        el = -0.43 + 0.47 * (double)(seed >> 8) / 16777216.0;
        seed = seed * 1664525u + 1013904223u;
        r = 1.0 + 60.0 * (double)(seed >> 8) / 16777216.0;
        put(&pts[4 * i], r, az, el);
    }
    for (i = 0; i < 40; ++i) /* the same directions again, some closer, some farther, blocks later */
    {
        const float f = (i % 2) ? 0.5f : 2.0f;
        pts[4 * (150 + i)] = f * pts[4 * i];
        pts[4 * (150 + i) + 1] = f * pts[4 * i + 1];
        pts[4 * (150 + i) + 2] = f * pts[4 * i + 2];
    }
    memcpy(&pts[4 * 260], &pts[4 * 20], 4 * sizeof(float)); /* exact tie, blocks apart */
    for (i = 0; i < 8; ++i)
    {
        memcpy(&pts[4 * bad_at[i]], bad[i], 3 * sizeof(float));
    }
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_proj_run(&g.ws, pts, NB, 4, NULL));
    st4 = *lidet_proj_stats(&g.ws);
    TEST_ASSERT_EQUAL_UINT32(NB - 8, st4.n_projected);
    TEST_ASSERT_EQUAL_UINT32(2, st4.n_nonfinite);
    TEST_ASSERT_EQUAL_UINT32(2, st4.n_too_close);
    TEST_ASSERT_EQUAL_UINT32(1, st4.n_too_far);
    TEST_ASSERT_EQUAL_UINT32(3, st4.n_out_of_fov);
    pp = lidet_proj_point_pixels(&g.ws, &n);
    TEST_ASSERT_EQUAL_INT32(20, img.point_idx[pp[260]]);
    memcpy(ref_pp, pp, sizeof ref_pp);
    memcpy(ref_x, img.x_m, sizeof ref_x);
    memcpy(ref_range, img.range_m, sizeof ref_range);
    memcpy(ref_rxy, img.rxy_m, sizeof ref_rxy);
    memcpy(ref_idx, img.point_idx, sizeof ref_idx);
    for (i = 0; i < 2; ++i)
    {
        project_strided(strides[i], &st);
        TEST_ASSERT_EQUAL_MEMORY(&st4, &st, sizeof st);
        TEST_ASSERT_EQUAL_MEMORY(ref_pp, pp, sizeof ref_pp);
        TEST_ASSERT_EQUAL_MEMORY(ref_x, img.x_m, npix * sizeof(float));
        TEST_ASSERT_EQUAL_MEMORY(ref_range, img.range_m, npix * sizeof(float));
        TEST_ASSERT_EQUAL_MEMORY(ref_rxy, img.rxy_m, npix * sizeof(float));
        TEST_ASSERT_EQUAL_MEMORY(ref_idx, img.point_idx, npix * sizeof(int32_t));
    }
    for (i = 0; i < NB; ++i) /* one point per run: a block of one */
    {
        TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_proj_run(&g.ws, &pts[4 * i], 1, 4, NULL));
        TEST_ASSERT_EQUAL_INT32(ref_pp[i], pp[0]);
        if (pp[0] >= 0 && ref_idx[pp[0]] == (int32_t)i)
        {
            TEST_ASSERT_EQUAL_FLOAT(ref_range[pp[0]], img.range_m[pp[0]]);
            TEST_ASSERT_EQUAL_FLOAT(ref_rxy[pp[0]], img.rxy_m[pp[0]]);
        }
    }
}

/* the window's block pre-test (lidet_proj.c outside_block): a sweep in azimuth order (blocks wholly outside the
 * window are counted without their keys) and the same points shuffled (no such block) give the same pixels and the
 * same counts, for a narrow, a half-turn and a wide window, on the elevation and the ring paths, with NaN, too
 * close, too far, out-of-field and bad-ring points inside and outside the window; a point outside the window counts
 * there whatever else is wrong with it, except NaN and range */
#define SW 4096u
static float sw_pts[SW * 4], sh_pts[SW * 5];
static uint16_t sw_ring[SW], sh_ring[SW];
static float sw_range[64 * 2048];
static int32_t sw_pp[SW], sh_pp[SW];

static void sweep_run(const float *p, uint32_t stride, const uint16_t *ring, lidet_proj_stats_t *st,
                      int32_t *pp, float *range)
{
    lidet_range_image_t img;
    const int32_t *q;
    uint32_t n;
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_proj_run(&g.ws, p, SW, stride, ring));
    *st = *lidet_proj_stats(&g.ws);
    q = lidet_proj_point_pixels(&g.ws, &n);
    TEST_ASSERT_EQUAL_UINT32(SW, n);
    memcpy(pp, q, SW * sizeof *pp);
    lidet_proj_image(&g.ws, &img);
    memcpy(range, img.range_m, (size_t)img.n_rows * img.n_cols * sizeof *range);
}

static void test_window_pretest_order_independent(void)
{
    static const float halves[3] = {0.7854f, 1.5f, 2.6f}; /* 45 deg (+ margins < pi), ~86 deg (> pi), wide */
    uint32_t perm[SW], i, k, w, path, seed = 4242u;
    init_sensor("hdl64");
    for (i = 0; i < SW; ++i)
    {
        /* 16 turns of 256 points, like a ring-ordered scan, each turn starting pi / 32 further (so that blocks
         * end at many distances from the window's edges); every 37th point broken in one of six ways */
        const double az =
            M_PI - 2.0 * M_PI * (double)(i % 256u) / 256.0 - M_PI / 32.0 * (double)(i / 256u) - 0.001;
        float *p = &sw_pts[4 * i];
        put(p, 4.0 + 0.01 * (double)i, az, -0.3 + 0.02 * (double)(i / 256u));
        sw_ring[i] = (uint16_t)(i / 256u);
        switch (i % 37u == 5u ? (i / 37u) % 6u : 9u)
        {
        case 0:
            p[1] = NAN;
            break;
        case 1:
            p[0] = 0.01f;
            p[1] = 0.02f;
            p[2] = 0.0f;
            break; /* too close */
        case 2:
            p[0] *= 1.0e6f;
            p[1] *= 1.0e6f;
            p[2] *= 1.0e6f;
            break; /* too far (max_range set below) */
        case 3:
            p[2] = 3.0f * sqrtf(p[0] * p[0] + p[1] * p[1]);
            break; /* above the field of view */
        case 4:
            sw_ring[i] = 200u;
            break; /* a ring past the rows (ring path) */
        case 5:
            p[0] = INFINITY;
            break;
        default:
            break;
        }
    }
    for (i = 0; i < SW; ++i)
        perm[i] = i;
    for (i = SW - 1u; i > 0u; --i)
    {
        uint32_t j, t;
        seed = seed * 1664525u + 1013904223u;
        j = (seed >> 8) % (i + 1u);
        t = perm[i];
        perm[i] = perm[j];
        perm[j] = t;
    }
    for (w = 0; w < 3u; ++w)
    {
        for (path = 0; path < 2u; ++path)
        {
            lidet_proj_stats_t a, b;
            uint32_t stride = path == 0u ? 4u : 5u, sum;
            cfg.azimuth_half_rad = halves[w];
            cfg.max_range_m = 200.0f;
            TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_proj_init(&g.ws, &cfg));
            for (i = 0; i < SW; ++i)
            {
                for (k = 0; k < stride; ++k)
                    sh_pts[stride * i + k] = k < 4u ? sw_pts[4 * perm[i] + k] : -1.0f;
                sh_ring[i] = sw_ring[perm[i]];
            }
            sweep_run(sw_pts, 4u, path == 1u ? sw_ring : NULL, &a, sw_pp, sw_range);
            {
                lidet_range_image_t img;
                lidet_proj_image(&g.ws, &img);
                sweep_run(sh_pts, stride, path == 1u ? sh_ring : NULL, &b, sh_pp, ref_range);
                for (i = 0; i < (uint32_t)img.n_rows * img.n_cols; ++i)
                    TEST_ASSERT_EQUAL_FLOAT(sw_range[i], ref_range[i]);
            }
            for (i = 0; i < SW; ++i)
                TEST_ASSERT_EQUAL_INT32(sw_pp[perm[i]], sh_pp[i]);
            TEST_ASSERT_EQUAL_MEMORY(&a, &b, sizeof a);
            sum = a.n_projected + a.n_nonfinite + a.n_too_close + a.n_too_far + a.n_out_of_fov +
                  a.n_bad_ring + a.n_out_of_window;
            TEST_ASSERT_EQUAL_UINT32(SW, sum);
            TEST_ASSERT_TRUE(a.n_out_of_window > SW / 16u && a.n_projected > SW / 8u);
            TEST_ASSERT_TRUE(a.n_nonfinite >= 30u && a.n_too_close >= 10u && a.n_too_far >= 10u);
            /* the broken points inside the window are counted as what is wrong with them */
            TEST_ASSERT_TRUE(path == 0u ? a.n_out_of_fov > 0u && a.n_bad_ring == 0u
                                        : a.n_bad_ring > 0u && a.n_out_of_fov == 0u);
        }
    }
    cfg.azimuth_half_rad = 0.0f;
    cfg.max_range_m = 0.0f;
}

/* the azimuth window (cfg azimuth_half_rad): the points of its columns land where they land without it, the
 * others are counted and leave their pixels empty; pi is the whole scan; bad values are refused */
static void test_azimuth_window(void)
{
    const uint32_t cols = 2048u, npix = 64u * 2048u;
    const float w = 0.25f * 3.14159265f;
    const float half = w * (float)cols / (2.0f * 3.14159265f);
    const uint32_t lo = (uint32_t)(0.5f * (float)cols - half - 1.0f),
                   hi = (uint32_t)(0.5f * (float)cols + half + 1.0f) + 1u;
    lidet_range_image_t img;
    const int32_t *pp;
    uint32_t i, n, out = 0, inside = 0;
    uint32_t seed = 777u;
    for (i = 0; i < NB; ++i)
    {
        double az, el;
        seed = seed * 1664525u + 1013904223u;
        az = -M_PI + 2.0 * M_PI * (double)(seed >> 8) / 16777216.0;
        seed = seed * 1664525u + 1013904223u;
        el = -0.4 + 0.42 * (double)(seed >> 8) / 16777216.0;
        put(&pts[4 * i], 5.0 + 0.1 * (double)i, az, el);
    }
    init_sensor("hdl64");
    lidet_proj_image(&g.ws, &img);
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_proj_run(&g.ws, pts, NB, 4, NULL));
    TEST_ASSERT_EQUAL_UINT32(NB, lidet_proj_stats(&g.ws)->n_projected);
    TEST_ASSERT_EQUAL_UINT32(0, lidet_proj_stats(&g.ws)->n_out_of_window);
    pp = lidet_proj_point_pixels(&g.ws, &n);
    memcpy(ref_pp, pp, sizeof ref_pp);
    memcpy(ref_x, img.x_m, sizeof ref_x);
    memcpy(ref_range, img.range_m, sizeof ref_range);
    memcpy(ref_rxy, img.rxy_m, sizeof ref_rxy);
    memcpy(ref_idx, img.point_idx, sizeof ref_idx);

    cfg.azimuth_half_rad = w;
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_proj_init(&g.ws, &cfg));
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_proj_run(&g.ws, pts, NB, 4, NULL));
    for (i = 0; i < NB; ++i)
    {
        const uint32_t c = (uint32_t)ref_pp[i] % cols;
        if (c >= lo && c < hi)
        {
            TEST_ASSERT_EQUAL_INT32(ref_pp[i], pp[i]);
            ++inside;
        }
        else
        {
            TEST_ASSERT_EQUAL_INT32(-1, pp[i]);
            ++out;
        }
    }
    TEST_ASSERT_TRUE(inside > 40u && out > 150u); /* a quarter of the points or so inside */
    TEST_ASSERT_EQUAL_UINT32(out, lidet_proj_stats(&g.ws)->n_out_of_window);
    TEST_ASSERT_EQUAL_UINT32(inside, lidet_proj_stats(&g.ws)->n_projected);
    for (i = 0; i < npix; ++i)
    {
        const uint32_t c = i % cols;
        if (c >= lo && c < hi)
        {
            TEST_ASSERT_EQUAL_FLOAT(ref_x[i], img.x_m[i]);
            TEST_ASSERT_EQUAL_FLOAT(ref_range[i], img.range_m[i]);
            TEST_ASSERT_EQUAL_FLOAT(ref_rxy[i], img.rxy_m[i]);
            TEST_ASSERT_EQUAL_INT32(ref_idx[i], img.point_idx[i]);
        }
        else
        {
            TEST_ASSERT_EQUAL_FLOAT(0.0f, img.x_m[i]);
            TEST_ASSERT_EQUAL_FLOAT(0.0f, img.range_m[i]);
            TEST_ASSERT_EQUAL_FLOAT(0.0f, img.rxy_m[i]);
            TEST_ASSERT_EQUAL_INT32(-1, img.point_idx[i]);
        }
    }
    /* a run without points still leaves the pixels beside the window empty (not the previous scan's) */
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_proj_run(&g.ws, pts, 0, 4, NULL));
    for (i = 0; i < npix; ++i)
    {
        TEST_ASSERT_EQUAL_FLOAT(0.0f, img.range_m[i]);
    }

    cfg.azimuth_half_rad = 3.14159265f; /* pi: the whole scan */
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_proj_init(&g.ws, &cfg));
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_proj_run(&g.ws, pts, NB, 4, NULL));
    TEST_ASSERT_EQUAL_INT32_ARRAY(ref_pp, pp, NB);
    cfg.azimuth_half_rad = -0.1f;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_proj_init(&g.ws, &cfg));
    cfg.azimuth_half_rad = 4.0f;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_proj_init(&g.ws, &cfg));
    cfg.azimuth_half_rad = NAN;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_proj_init(&g.ws, &cfg));
}

/* ring path: a point straight above or below the sensor (x = y = 0) has no azimuth; it goes to the
 * straight-ahead column of its ring's row */
static void test_ring_path_vertical_point(void)
{
    uint16_t ring[2] = {3, 7};
    const float p[8] = {0.0f, 0.0f, 5.0f, 0.0f, 10.0f, 0.0f, 0.0f, 0.0f};
    uint32_t n;
    const int32_t *pp;
    lidet_range_image_t img;
    init_sensor("vlp16");
    lidet_proj_image(&g.ws, &img);
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_proj_run(&g.ws, p, 2, 4, ring));
    pp = lidet_proj_point_pixels(&g.ws, &n);
    TEST_ASSERT_EQUAL_UINT32(2, lidet_proj_stats(&g.ws)->n_projected);
    TEST_ASSERT_EQUAL_INT(img.n_cols / 2, pp[0] % img.n_cols);
    TEST_ASSERT_EQUAL_INT(img.n_cols / 2, pp[1] % img.n_cols);
    TEST_ASSERT_EQUAL_FLOAT(0.0f, img.rxy_m[pp[0]]);
    TEST_ASSERT_EQUAL_FLOAT(5.0f, img.range_m[pp[0]]);
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_every_profile_beam_rows);
    RUN_TEST(test_uniform_profile_matches_formula);
    RUN_TEST(test_wraparound);
    RUN_TEST(test_columns_sweep);
    RUN_TEST(test_azimuth_key);
    RUN_TEST(test_seam_rounding);
    RUN_TEST(test_ring_index_path);
    RUN_TEST(test_closest_wins);
    RUN_TEST(test_invalid_points_counted);
    RUN_TEST(test_empty_scan);
    RUN_TEST(test_argument_and_config_errors);
    RUN_TEST(test_custom_ring_order);
    RUN_TEST(test_blocks_and_strides_agree);
    RUN_TEST(test_azimuth_window);
    RUN_TEST(test_window_pretest_order_independent);
    RUN_TEST(test_ring_path_vertical_point);
    return UNITY_END();
}
