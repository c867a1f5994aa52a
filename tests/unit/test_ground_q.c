/* SPDX-License-Identifier: MIT */
/* Unity tests of the integer ground stage (lib/src/ground/lidet_ground_filter_q.c, lidet_ground_ransac_q.c)
 * on compact range images built here: a VLP-16-like fan of beams ray-cast against a ground plane (flat or
 * sloped) and a wall, rounded to 4 mm steps; plus bad input: arguments, configuration, images at the int16
 * limits, empty images. */
#include <math.h>
#include <string.h>

#include "internal/lidet_ground_q_internal.h"
#include "lidet/lidet.h"
#include "test_util.h"

#define ROWS 16
#define COLS 900

LIDET_GUARDED(lidet_ground_q_t, gq);
static lidet_ground_q_cfg_t cfg;
static int16_t X[ROWS * COLS], Y[ROWS * COLS], Z[ROWS * COLS];
static uint16_t RG[ROWS * COLS];
static uint8_t truth[ROWS * COLS]; /* 1 ground, 2 obstacle higher than 0.3 m above the ground, 0 other / empty */
static lidet_range_image_t img;

void setUp(void)
{
    CANARY_FILL(gq);
    lidet_ground_q_cfg_default(&cfg, ROWS, 500);
}

void tearDown(void)
{
    CANARY_CHECK(gq);
}

static int16_t q4(double m)
{
    return (int16_t)floor(m / 0.004 + 0.5);
}

/* ground z = -h + sx * x; a wall x = wall_x (for |y| < 3 m, below z = 1 m) when wall_x > 0 */
static void cast(double h, double sx, double wall_x)
{
    int r, c;
    memset(&img, 0, sizeof img);
    memset(truth, 0, sizeof truth);
    for (r = 0; r < ROWS; ++r)
    {
        const double el = (15.0 - 2.0 * r) * M_PI / 180.0;
        for (c = 0; c < COLS; ++c)
        {
            const double az = M_PI - (c + 0.5) * 2.0 * M_PI / COLS;
            const double d[3] = {cos(el) * cos(az), cos(el) * sin(az), sin(el)};
            const int p = r * COLS + c;
            const double den = d[2] - sx * d[0];
            double t = den < -1e-9 ? -h / den : 1e30, p3[3];
            int kind = 1;
            if (wall_x > 0.0 && d[0] > 1e-9)
            {
                const double tw = wall_x / d[0];
                if (tw < t && fabs(tw * d[1]) < 3.0 && tw * d[2] < 1.0)
                {
                    t = tw;
                    kind = 2;
                }
            }
            if (t > 80.0)
            {
                X[p] = Y[p] = Z[p] = 0;
                RG[p] = 0;
                continue;
            }
            p3[0] = t * d[0];
            p3[1] = t * d[1];
            p3[2] = t * d[2];
            X[p] = q4(p3[0]);
            Y[p] = q4(p3[1]);
            Z[p] = q4(p3[2]);
            RG[p] = (uint16_t)floor(t / 0.004 + 0.5);
            truth[p] = (uint8_t)(kind == 1 ? 1 : (p3[2] > -h + sx * p3[0] + 0.3 ? 2 : 0));
        }
    }
    img.n_rows = ROWS;
    img.n_cols = COLS;
    img.x_4mm = X;
    img.y_4mm = Y;
    img.z_4mm = Z;
    img.range_4mm = RG;
}

static void count(uint32_t *g_ok, uint32_t *g_n, uint32_t *o_ground, uint32_t *o_n)
{
    const uint8_t *m = lidet_ground_q_mask(&gq.ws);
    int p;
    *g_ok = *g_n = *o_ground = *o_n = 0;
    for (p = 0; p < ROWS * COLS; ++p)
    {
        *g_ok += truth[p] == 1 && m[p];
        *g_n += truth[p] == 1;
        *o_ground += truth[p] == 2 && m[p];
        *o_n += truth[p] == 2;
        if (RG[p] == 0)
            TEST_ASSERT_EQUAL_UINT8(0, m[p]);
    }
}

static void test_flat_ground_and_wall(void)
{
    uint32_t g_ok, g_n, o_g, o_n, s, ns, n_flat = 0;
    const lidet_plane_q_t *pl;
    const uint8_t *src;
    cast(0.5, 0.0, 8.0);
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_ground_q_init(&gq.ws, &cfg));
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_ground_q_run(&gq.ws, &img));
    count(&g_ok, &g_n, &o_g, &o_n);
    TEST_ASSERT_TRUE(g_n > 3000u && o_n > 50u);
    TEST_ASSERT_TRUE(g_ok >= g_n * 99u / 100u);
    TEST_ASSERT_EQUAL_UINT32(0, o_g);
    TEST_ASSERT_EQUAL_UINT32(g_ok, lidet_ground_q_stats(&gq.ws)->n_ground);
    pl = lidet_ground_q_planes(&gq.ws, &ns);
    src = lidet_ground_q_sector_source(&gq.ws);
    TEST_ASSERT_EQUAL_UINT32(cfg.n_sectors, ns);
    TEST_ASSERT_TRUE(lidet_ground_q_stats(&gq.ws)->n_sectors_fitted >= 28u);
    for (s = 0; s < ns; ++s)
    {
        if (src[s] != LIDET_GROUND_PLANE_FITTED)
            continue;
        /* the plane z = -0.5 m: normal +z within 2e-3, d = 125 steps of 4 mm (+-1); the sectors that see the
         * wall may tilt their plane within max_tilt (the wall's foot lies within inlier_mm of the ground) */
        n_flat += pl[s].nz >= (int32_t)((1 << 30) - 2200) && pl[s].d_4mm >= 124 && pl[s].d_4mm <= 126;
        TEST_ASSERT_TRUE(pl[s].nz >= gq.ws.state.cos_tilt_q30);
    }
    TEST_ASSERT_TRUE(n_flat >= 26u);
}

static void test_sloped_ground_normal(void)
{
    const double sx = 0.05, len = sqrt(1.0 + sx * sx);
    uint32_t s, ns, n_fit = 0;
    const lidet_plane_q_t *pl;
    cast(0.5, sx, 0.0);
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_ground_q_init(&gq.ws, &cfg));
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_ground_q_run(&gq.ws, &img));
    pl = lidet_ground_q_planes(&gq.ws, &ns);
    for (s = 0; s < ns; ++s)
    {
        if (lidet_ground_q_sector_source(&gq.ws)[s] != LIDET_GROUND_PLANE_FITTED)
            continue;
        ++n_fit;
        /* n = (-sx, 0, 1) / len: the least-squares normal of 4 mm-rounded points, within 2e-3 */
        TEST_ASSERT_CLOSE(-sx / len, pl[s].nx / 1073741824.0, 2e-3, 0.0);
        TEST_ASSERT_CLOSE(0.0, pl[s].ny / 1073741824.0, 2e-3, 0.0);
        TEST_ASSERT_CLOSE(1.0 / len, pl[s].nz / 1073741824.0, 2e-3, 0.0);
    }
    TEST_ASSERT_TRUE(n_fit >= 24u);
}

static void test_deterministic_and_point_labels(void)
{
    static uint8_t m1[ROWS * COLS], out[4];
    const int32_t pp[4] = {-1, 5 * COLS + 3, ROWS * COLS, 15 * COLS + 100};
    lidet_ground_stats_t st;
    cast(0.5, 0.0, 8.0);
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_ground_q_init(&gq.ws, &cfg));
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_ground_q_run(&gq.ws, &img));
    memcpy(m1, lidet_ground_q_mask(&gq.ws), sizeof m1);
    st = *lidet_ground_q_stats(&gq.ws);
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_ground_q_run(&gq.ws, &img));
    TEST_ASSERT_EQUAL_MEMORY(m1, lidet_ground_q_mask(&gq.ws), sizeof m1);
    TEST_ASSERT_EQUAL_MEMORY(&st, lidet_ground_q_stats(&gq.ws), sizeof st);
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_ground_q_point_labels_of(&gq.ws.state, gq.ws.mask, pp, 4, out));
    TEST_ASSERT_EQUAL_UINT8(0, out[0]);
    TEST_ASSERT_EQUAL_UINT8(m1[pp[1]], out[1]);
    TEST_ASSERT_EQUAL_UINT8(0, out[2]);
    TEST_ASSERT_EQUAL_UINT8(m1[pp[3]], out[3]);
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_ARG, lidet_ground_q_point_labels_of(&gq.ws.state, gq.ws.mask, NULL, 4, out));
}

static void test_empty_image_takes_the_mount_plane(void)
{
    uint32_t s, ns;
    const lidet_plane_q_t *pl;
    cast(0.5, 0.0, 0.0);
    memset(X, 0, sizeof X);
    memset(Y, 0, sizeof Y);
    memset(Z, 0, sizeof Z);
    memset(RG, 0, sizeof RG);
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_ground_q_init(&gq.ws, &cfg));
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_ground_q_run(&gq.ws, &img));
    TEST_ASSERT_EQUAL_UINT32(0, lidet_ground_q_stats(&gq.ws)->n_ground);
    TEST_ASSERT_EQUAL_UINT32(cfg.n_sectors, lidet_ground_q_stats(&gq.ws)->n_sectors_mount);
    pl = lidet_ground_q_planes(&gq.ws, &ns);
    for (s = 0; s < 2u * ns; ++s)
    {
        TEST_ASSERT_EQUAL_INT32(1 << 30, pl[s].nz);
        TEST_ASSERT_EQUAL_INT32(125, pl[s].d_4mm);
    }
}

/* coordinates at the int16 limits, every pixel: no overflow (the sanitizer build runs this), sane counts */
static void test_coordinates_at_the_limits(void)
{
    int p, k;
    const lidet_ground_stats_t *st;
    cast(0.5, 0.0, 0.0);
    for (k = 0; k < 3; ++k)
    {
        for (p = 0; p < ROWS * COLS; ++p)
        {
            const int16_t a = (int16_t)((p + k) % 3 == 0 ? -32768 : ((p + k) % 3 == 1 ? 32767 : (p % 7) - 3));
            X[p] = a;
            Y[p] = (int16_t)(k == 0 ? a : -32768);
            Z[p] = (int16_t)((p / COLS) % 2 ? 32767 : -32768);
            RG[p] = 65535u;
        }
        lidet_ground_q_cfg_default(&cfg, ROWS, 500);
        cfg.ring_split_mm = k == 2 ? 500000u : 15000u; /* the split threshold past what int16 reaches, and not */
        cfg.ground_per_m_q16 = k == 1 ? 6554u : 0u;
        cfg.below_factor_q16 = 1310720u;
        cfg.fy_max_q16 = 655360u;
        cfg.fx_max_mm = 100000u;
        cfg.max_tilt_urad = 1570796u;
        cfg.max_height_dev_mm = 20000u;
        cfg.refine_iters = 10u;
        TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_ground_q_init(&gq.ws, &cfg));
        TEST_ASSERT_TRUE(lidet_ground_q_run(&gq.ws, &img) >= 0);
        st = lidet_ground_q_stats(&gq.ws);
        TEST_ASSERT_TRUE(st->n_ground + st->n_vetoed <= ROWS * COLS);
        TEST_ASSERT_EQUAL_UINT32(cfg.n_sectors, st->n_sectors_fitted + st->n_sectors_neighbour + st->n_sectors_mount);
    }
}

static void test_arguments_and_config(void)
{
    static float fx[ROWS * COLS];
    lidet_range_image_t bad;
    lidet_ground_q_cfg_t c;
    cast(0.5, 0.0, 0.0);
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_ARG, lidet_ground_q_init(NULL, &cfg));
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_ARG, lidet_ground_q_init(&gq.ws, NULL));
    memset(&gq.ws.state, 0, sizeof gq.ws.state);
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_STATE, lidet_ground_q_run(&gq.ws, &img));
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_ground_q_init(&gq.ws, &cfg));
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_ARG, lidet_ground_q_run(&gq.ws, NULL));
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_ARG, lidet_ground_q_run(NULL, &img));
    bad = img;
    bad.x_m = fx; /* a float image */
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_ARG, lidet_ground_q_run(&gq.ws, &bad));
    bad = img;
    bad.z_4mm = NULL;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_ARG, lidet_ground_q_run(&gq.ws, &bad));
    bad = img;
    bad.n_rows = LIDET_MAX_ROWS + 1;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_BUFFER, lidet_ground_q_run(&gq.ws, &bad));
    bad = img;
    bad.n_cols = 16; /* fewer columns than sectors */
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_ground_q_run(&gq.ws, &bad));
    c = cfg;
    c.n_sectors = LIDET_GROUND_MAX_SECTORS + 1;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_BUFFER, lidet_ground_q_init(&gq.ws, &c));
    c = cfg;
    c.inlier_mm = 0;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_ground_q_init(&gq.ws, &c));
    c = cfg;
    c.max_tilt_urad = 1570797u;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_ground_q_init(&gq.ws, &c));
    c = cfg;
    c.sample_step = 0;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_ground_q_init(&gq.ws, &c));
    c = cfg;
    c.mount_height_mm = -1;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_ground_q_init(&gq.ws, &c));
    c = cfg;
    c.seed_per_cell = 2u;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_ground_q_init(&gq.ws, &c));
    /* the defaults' two families */
    lidet_ground_q_cfg_default(&c, 64, 1730);
    TEST_ASSERT_EQUAL_UINT16(4, c.sample_step);
    TEST_ASSERT_EQUAL_UINT32(15000u, c.ring_split_mm);
    lidet_ground_q_cfg_default(&c, 16, 500);
    TEST_ASSERT_EQUAL_UINT16(1, c.sample_step);
    TEST_ASSERT_EQUAL_UINT32(0u, c.ring_split_mm);
    TEST_ASSERT_NULL(lidet_ground_q_mask(NULL));
    TEST_ASSERT_NULL(lidet_ground_q_planes(NULL, NULL));
}

/* The sample test's two kernels (branch-free on SIMD hosts, early exit on cores without SIMD) give the same
 * samples: random row pairs (empty pixels, ranges and heights near every threshold, rising and falling) under
 * random settings (F_x on R or z, descending required or not, height gate on or off). The early kernel is what
 * the firmware images run; this host build runs the other. */
static uint32_t lcg(uint32_t *s)
{
    *s = *s * 1664525u + 1013904223u;
    return *s >> 8;
}

void test_sample_kernels_agree(void)
{
    enum
    {
        C = 64
    };
    static int32_t R0[C], R1[C];
    static int16_t Z0[C], Z1[C];
    uint8_t a[C], b[C];
    uint32_t s = 12345u, trial, c, n_set = 0, n_clear = 0;
    for (trial = 0; trial < 20000u; ++trial)
    {
        const uint32_t cols = 4u + lcg(&s) % (C - 3u);
        lidet__ground_q_filt_t f;
        f.fy = (uint64_t)(lcg(&s) % 200000u);
        f.fx_mm = (int32_t)(lcg(&s) % 1200u);
        f.fx_r = f.fx_mm * 64;
        f.on_z = (int)(lcg(&s) & 1u);
        f.desc = (int)(lcg(&s) & 1u);
        f.gate = (int)(lcg(&s) & 1u);
        f.z_lo = -2000 - (int32_t)(lcg(&s) % 2000u);
        f.z_hi = -2000 + (int32_t)(lcg(&s) % 2000u);
        for (c = 0; c < cols; ++c)
        {
            /* a ground-like fan: R0 beyond R1 by a step, z a little apart; some pixels empty, some noise */
            const int32_t base = 64 * (int32_t)(500u + lcg(&s) % 4000u);
            R1[c] = lcg(&s) % 8u == 0u ? 0 : base;
            R0[c] = lcg(&s) % 8u == 0u ? 0 : base + (int32_t)(lcg(&s) % 4096u) - 1024;
            Z1[c] = (int16_t)(-500 + (int32_t)(lcg(&s) % 100u));
            Z0[c] = (int16_t)(Z1[c] + (int32_t)(lcg(&s) % 64u) - 16);
        }
        lidet__ground_q_sample_row(R0, R1, Z0, Z1, cols, &f, a, 0);
        lidet__ground_q_sample_row(R0, R1, Z0, Z1, cols, &f, b, 1);
        TEST_ASSERT_EQUAL_UINT8_ARRAY(a, b, cols);
        for (c = 0; c < cols; ++c)
        {
            n_set += a[c];
            n_clear += 1u - a[c];
        }
    }
    /* both outcomes occur often: the test reaches every condition */
    TEST_ASSERT_GREATER_THAN_UINT32(10000u, n_set);
    TEST_ASSERT_GREATER_THAN_UINT32(50000u, n_clear);
}

/* The band test from the 32-bit hi part (lidet__ground_q_in_band, what the ARMv6-M and RV32 images run; this host
 * build takes the exact 64-bit height) gives the exact test's outcome: random unit normals (tilted up to about 60
 * degrees), offsets and bands, points spread over the int16 range and points placed within a few 4 mm steps of either
 * edge of the band, where the lo part decides; every path of the test is taken (surely out, surely in, exact). */
static void q30_unit(int32_t *n, uint32_t *s)
{
    int64_t v[3], len2;
    uint32_t len, k;
    v[0] = (int64_t)(lcg(s) % 2000001u) - 1000000;
    v[1] = (int64_t)(lcg(s) % 2000001u) - 1000000;
    v[2] = 600000 + (int64_t)(lcg(s) % 1400000u);
    len2 = v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
    len = lidet__q_isqrt64((uint64_t)len2);
    for (k = 0; k < 3u; ++k)
    {
        n[k] = (int32_t)lidet__q_div_round(v[k] * ((int64_t)1 << 30), (int64_t)len);
    }
}

void test_band_test_from_the_hi_part(void)
{
    uint32_t s = 777u, trial, j, n_in = 0, n_out = 0, n_edge = 0;
    for (trial = 0; trial < 4000u; ++trial)
    {
        int32_t n[3];
        lidet__ground_q_hplane_t h;
        lidet__ground_q_band_t b;
        /* D: the plane 0.5-2.5 m below the sensor (4 mm / 2^30), plus the band's offset; t: a band of 2-60 cm */
        const int64_t d = ((int64_t)(100 + lcg(&s) % 600u) << 30) + (int64_t)(lcg(&s) % 50u) * ((int64_t)1 << 28);
        const uint64_t t = (uint64_t)(5 + lcg(&s) % 150u) << 30;
        q30_unit(n, &s);
        lidet__ground_q_hplane(n, d, &h);
        lidet__ground_q_band(h.lo, h.d, t, 15u, &b);
        for (j = 0; j < 64u; ++j)
        {
            int32_t p[3];
            int64_t hh;
            int exact, fast;
            p[0] = (int32_t)(lcg(&s) % 65536u) - 32768;
            p[1] = (int32_t)(lcg(&s) % 65536u) - 32768;
            p[2] = (int32_t)(lcg(&s) % 2001u) - 1000; /* x, y halved below: |p| within 2^15 steps, as an image's */
            p[0] /= 2;
            p[1] /= 2;
            if (j % 4u != 0u)
            {
                /* z on the band's lower edge (1) or upper edge (3) within +-8 steps, where the lo part decides, or
                 * anywhere in the band (2) */
                const int64_t e = j % 4u == 1u ? 0 : (j % 4u == 3u ? (int64_t)t : (int64_t)(t / 2u));
                const int64_t num = e - d - (int64_t)n[0] * p[0] - (int64_t)n[1] * p[1];
                const int64_t w = j % 4u == 2u ? (int64_t)(t >> 31) : 8;
                int64_t z = num / n[2] + (int64_t)(lcg(&s) % (uint32_t)(2 * w + 1)) - w;
                z = z < -32768 ? -32768 : (z > 32767 ? 32767 : z);
                p[2] = (int32_t)z;
            }
            hh = lidet__ground_q_height(&h, p[0], p[1], p[2]);
            exact = (uint64_t)hh <= t;
            fast = lidet__ground_q_in_band(&h, &b, t, p[0], p[1], p[2]);
            TEST_ASSERT_EQUAL_INT(exact, fast);
            n_in += (uint32_t)exact;
            n_out += (uint32_t)!exact;
            {
                const int32_t a = h.hi[0] * p[0] + h.hi[1] * p[1] + h.hi[2] * p[2];
                n_edge += (uint32_t)((uint32_t)a - (uint32_t)b.pos_lo <= b.pos_span &&
                                     !((uint32_t)a - (uint32_t)b.in_lo < b.in_n));
            }
        }
    }
    TEST_ASSERT_GREATER_THAN_UINT32(20000u, n_in);
    TEST_ASSERT_GREATER_THAN_UINT32(20000u, n_out);
    TEST_ASSERT_GREATER_THAN_UINT32(2000u, n_edge); /* the exact fallback is exercised */
}

/* The RANSAC's inlier count from the hi part (count_inliers with LIDET_GROUND_Q_BAND32): hypotheses c of every
 * size up to 2^29 (short cross products leave a split shift of a few bits, long ones 15) split by
 * lidet__ground_q_split, the band h + t in [0, 2t] of samples near and far from the plane through p0: the same
 * count as the exact 64-bit products. */
void test_inlier_band_of_any_hypothesis(void)
{
    uint32_t s = 4242u, trial, j, n_exact = 0, n_in = 0, n_sh[16] = {0};
    for (trial = 0; trial < 3000u; ++trial)
    {
        const unsigned bits = 1u + lcg(&s) % 29u; /* |c| below 2^bits */
        int32_t c[3], ch[3], cl[3], p0[3];
        lidet__ground_q_band_t b;
        unsigned sh, k;
        int64_t t, h0;
        for (k = 0; k < 3u; ++k)
        {
            c[k] = (int32_t)(((lcg(&s) << 8) ^ lcg(&s)) % (1u << bits)) * ((lcg(&s) & 1u) ? 1 : -1); /* 32 bits */
            p0[k] = (int32_t)(lcg(&s) % 20001u) - 10000;
        }
        sh = lidet__ground_q_split(c, ch, cl);
        n_sh[sh] += 1u;
        for (k = 0; k < 3u; ++k)
        {
            TEST_ASSERT_TRUE(ch[k] <= (1 << 14) && ch[k] >= -(1 << 14));
            TEST_ASSERT_EQUAL_INT64((int64_t)c[k], (int64_t)ch[k] * ((int64_t)1 << sh) + cl[k]);
        }
        /* the inlier distance 5-60 cm times |c| (4 mm units): t = thr |c| roughly, as count_inliers' thr_l / 4 */
        t = (int64_t)(12 + lcg(&s) % 140u) * (int64_t)(1u << (bits > 1u ? bits - 1u : 0u));
        h0 = t - ((int64_t)c[0] * p0[0] + (int64_t)c[1] * p0[1] + (int64_t)c[2] * p0[2]);
        lidet__ground_q_band(cl, h0, 2u * (uint64_t)t, sh, &b);
        for (j = 0; j < 64u; ++j)
        {
            int32_t q[3];
            int64_t ht;
            int r, fast;
            for (k = 0; k < 3u; ++k)
            {
                const int32_t spread = j % 2u == 0u ? 400 : 16000; /* near p0 (many inliers), or anywhere */
                int32_t v = p0[k] + (int32_t)(lcg(&s) % (uint32_t)(2 * spread + 1)) - spread;
                q[k] = v < -32768 ? -32768 : (v > 32767 ? 32767 : v);
            }
            ht = h0 + (int64_t)c[0] * q[0] + (int64_t)c[1] * q[1] + (int64_t)c[2] * q[2];
            r = lidet__ground_q_band_of(&b, ch[0] * q[0] + ch[1] * q[1] + ch[2] * q[2]);
            fast = r >= 0 ? r : (uint64_t)ht <= 2u * (uint64_t)t;
            TEST_ASSERT_EQUAL_INT((uint64_t)ht <= 2u * (uint64_t)t, fast);
            n_exact += (uint32_t)(r < 0);
            n_in += (uint32_t)fast;
        }
    }
    TEST_ASSERT_GREATER_THAN_UINT32(10000u, n_in);
    TEST_ASSERT_GREATER_THAN_UINT32(100u, n_exact);
    TEST_ASSERT_GREATER_THAN_UINT32(0u, n_sh[0]);
    TEST_ASSERT_GREATER_THAN_UINT32(0u, n_sh[15]);
}

/* The sample test's slope condition without a 32 x 32 -> 64 multiply (lidet__ground_q_shl24_gt, the ARMv6-M images'
 * form): the exact comparison on random operands of every size (inside and outside its fast path's ranges) and on
 * operands placed at the threshold, where the 64-bit product decides */
void test_slope_condition_from_32_bit_products(void)
{
    uint32_t s = 99u, k, n_true = 0, n_false = 0;
    for (k = 0; k < 400000u; ++k)
    {
        const uint32_t f = ((lcg(&s) << 8) ^ lcg(&s)) >> (lcg(&s) % 16u);
        const uint32_t r = ((lcg(&s) << 8) ^ lcg(&s)) >> (lcg(&s) % 16u);
        uint32_t z = ((lcg(&s) << 8) ^ lcg(&s)) >> (lcg(&s) % 24u);
        int exact;
        if (k % 2u == 0u)
        {
            /* z at f r / 2^24 within +-2 */
            const uint64_t q = ((uint64_t)f * r) >> 24;
            z = (uint32_t)(q > 0xFFFFFFFDu ? 0xFFFFFFFDu : q) + lcg(&s) % 5u;
            z = z >= 2u ? z - 2u : z;
        }
        exact = ((uint64_t)z << 24) > (uint64_t)f * r;
        TEST_ASSERT_EQUAL_INT(exact, lidet__ground_q_shl24_gt(z, f, r));
        n_true += (uint32_t)exact;
        n_false += (uint32_t)!exact;
    }
    /* the corners of the fast path's ranges (its window's bound at its largest) */
    {
        static const uint32_t fs[] = {0u, 1u, 255u, 256u, (1u << 20) - 1u, 1u << 20, 0xFFFFFFFFu};
        static const uint32_t rs[] = {0u, 1u, 255u, 256u, (1u << 27) - 1u, 1u << 27, (1u << 28) - 1u, 0xFFFFFFFFu};
        static const uint32_t zs[] = {0u, 1u, (1u << 24) - 1u, 1u << 24, 0xFFFFFFFFu};
        uint32_t i, j, m;
        for (i = 0; i < sizeof fs / sizeof fs[0]; ++i)
            for (j = 0; j < sizeof rs / sizeof rs[0]; ++j)
                for (m = 0; m < sizeof zs / sizeof zs[0]; ++m)
                {
                    const uint64_t q = ((uint64_t)fs[i] * rs[j]) >> 24;
                    TEST_ASSERT_EQUAL_INT(((uint64_t)zs[m] << 24) > (uint64_t)fs[i] * rs[j],
                                          lidet__ground_q_shl24_gt(zs[m], fs[i], rs[j]));
                    if (q < 0xFFFFFFFFu)
                    {
                        const uint32_t z = (uint32_t)q;
                        TEST_ASSERT_EQUAL_INT(((uint64_t)z << 24) > (uint64_t)fs[i] * rs[j],
                                              lidet__ground_q_shl24_gt(z, fs[i], rs[j]));
                        TEST_ASSERT_EQUAL_INT(((uint64_t)(z + 1u) << 24) > (uint64_t)fs[i] * rs[j],
                                              lidet__ground_q_shl24_gt(z + 1u, fs[i], rs[j]));
                    }
                }
    }
    TEST_ASSERT_GREATER_THAN_UINT32(100000u, n_true);
    TEST_ASSERT_GREATER_THAN_UINT32(100000u, n_false);
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_flat_ground_and_wall);
    RUN_TEST(test_sloped_ground_normal);
    RUN_TEST(test_deterministic_and_point_labels);
    RUN_TEST(test_empty_image_takes_the_mount_plane);
    RUN_TEST(test_coordinates_at_the_limits);
    RUN_TEST(test_arguments_and_config);
    RUN_TEST(test_sample_kernels_agree);
    RUN_TEST(test_band_test_from_the_hi_part);
    RUN_TEST(test_inlier_band_of_any_hypothesis);
    RUN_TEST(test_slope_condition_from_32_bit_products);
    return UNITY_END();
}
