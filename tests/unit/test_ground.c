/* SPDX-License-Identifier: MIT */
/* Unity tests of the ground stage (lib/src/ground/lidet_ground_filter.c, lidet_ground_ransac.c).
 * Scenes are ray-cast analytically: one ray per beam and column centre of the sensor, against
 * piecewise planes (ground) and axis-aligned boxes (obstacles); the points go through the real
 * projection, then the ground stage. Truth per point: which surface the ray hit. */
#include <math.h>
#include <string.h>

#include "lidet/lidet.h"
#include "test_util.h"

LIDET_GUARDED(lidet_proj_t, gp);
LIDET_GUARDED(lidet_ground_t, gg);
static lidet_proj_cfg_t pcfg;
static lidet_ground_cfg_t gcfg;

#define MAXP (64 * 2048)
static float pts[MAXP * 4];
static uint8_t truth[MAXP]; /* 1 ground surface, 0 obstacle */
static uint8_t labels[MAXP];
static uint32_t n_pts;

void setUp(void)
{
    CANARY_FILL(gp);
    CANARY_FILL(gg);
}

void tearDown(void)
{
    CANARY_CHECK(gp);
    CANARY_CHECK(gg);
}

/* ---- scenes ------------------------------------------------------------------------------- */
enum
{
    SC_FLAT,
    SC_SLOPE,
    SC_RAMP,
    SC_CURB
};

typedef struct
{
    double lo[3], hi[3];
} box_t;

typedef struct
{
    int kind;
    double h; /* sensor height above the (first) ground plane */
    int n_boxes;
    box_t boxes[4];
} scene_t;

/* ray t for the plane z = z0 + sx * x + sy * y (direction d from the origin); <0 = no hit */
static double hit_plane(const double d[3], double z0, double sx, double sy)
{
    const double den = d[2] - sx * d[0] - sy * d[1];
    double t;
    if (fabs(den) < 1e-12)
        return -1.0;
    t = z0 / den;
    return t > 0.0 ? t : -1.0;
}

static double hit_box(const double d[3], const box_t *b)
{
    double t0 = 0.0, t1 = 1e30;
    int k;
    for (k = 0; k < 3; ++k)
    {
        if (fabs(d[k]) < 1e-12)
        {
            if (0.0 < b->lo[k] || 0.0 > b->hi[k])
                return -1.0;
        }
        else
        {
            double a = b->lo[k] / d[k], c = b->hi[k] / d[k];
            if (a > c)
            {
                const double tmp = a;
                a = c;
                c = tmp;
            }
            t0 = a > t0 ? a : t0;
            t1 = c < t1 ? c : t1;
        }
    }
    return (t1 >= t0 && t0 > 0.0) ? t0 : -1.0;
}

/* nearest ground hit of the scene; returns t or -1 */
static double hit_ground(const scene_t *sc, const double d[3])
{
    double t, best = -1.0;
    switch (sc->kind)
    {
    case SC_FLAT:
        return hit_plane(d, -sc->h, 0.0, 0.0);
    case SC_SLOPE: /* rising 0.08 m per metre towards +x (4.6 deg) */
        return hit_plane(d, -sc->h, 0.08, 0.0);
    case SC_RAMP: /* flat up to x = 12 m, then rising at 0.15 (8.5 deg) */
        t = hit_plane(d, -sc->h, 0.0, 0.0);
        if (t > 0.0 && t * d[0] < 12.0)
            best = t;
        t = hit_plane(d, -sc->h - 0.15 * 12.0, 0.15, 0.0);
        if (t > 0.0 && t * d[0] >= 12.0 && (best < 0.0 || t < best))
            best = t;
        return best;
    default: /* SC_CURB: road for y > -4 m, a sidewalk 0.15 m higher for y <= -4 m */
        t = hit_plane(d, -sc->h, 0.0, 0.0);
        if (t > 0.0 && t * d[1] > -4.0)
            best = t;
        t = hit_plane(d, -sc->h + 0.15, 0.0, 0.0);
        if (t > 0.0 && t * d[1] <= -4.0 && (best < 0.0 || t < best))
            best = t;
        /* the curb's vertical face (y = -4, between the two heights) counts as ground too */
        if (d[1] < 0.0)
        {
            const double tf = -4.0 / d[1], zf = tf * d[2];
            if (zf >= -sc->h && zf <= -sc->h + 0.15 && (best < 0.0 || tf < best))
                best = tf;
        }
        return best;
    }
}

/* Casts one ray per beam and column centre (elevations from the initialised projection), keeps
 * hits within 70 m. keep(az) may drop azimuth ranges (NULL keeps all). */
static void cast_scene(const scene_t *sc, int (*keep)(double az, int row))
{
    lidet_range_image_t img;
    int r, c, b;
    lidet_proj_image(&gp.ws, &img);
    n_pts = 0;
    for (r = 0; r < img.n_rows; ++r)
    {
        for (c = 0; c < img.n_cols; ++c)
        {
            const double az = M_PI * (1.0 - 2.0 * (c + 0.5) / img.n_cols);
            const double el = img.row_elev_rad[r];
            const double d[3] = {cos(el) * cos(az), cos(el) * sin(az), sin(el)};
            double t = hit_ground(sc, d), tb, floor_z = 0.0;
            int ground = 1;
            if (keep != NULL && !keep(az, r))
                continue;
            for (b = 0; b < sc->n_boxes; ++b)
            {
                tb = hit_box(d, &sc->boxes[b]);
                if (tb > 0.0 && (t < 0.0 || tb < t))
                {
                    t = tb;
                    ground = 0;
                    floor_z = sc->boxes[b].lo[2];
                }
            }
            if (t < 0.0 || t > 70.0 || n_pts >= MAXP)
                continue;
            pts[4 * n_pts + 0] = (float)(t * d[0]);
            pts[4 * n_pts + 1] = (float)(t * d[1]);
            pts[4 * n_pts + 2] = (float)(t * d[2]);
            pts[4 * n_pts + 3] = 0.0f;
            /* box points less than ground_m (+10 cm for plane tilt) above the box's floor are
             * ground by definition of the height test: not scored */
            truth[n_pts] = (uint8_t)(ground ? 1 : (t * d[2] < floor_z + (double)gcfg.ground_m + 0.1 ? 2 : 0));
            ++n_pts;
        }
    }
}

static void init_sensor(const char *name)
{
    const lidet_sensor_t *s = lidet_sensor_find(name);
    TEST_ASSERT_NOT_NULL(s);
    lidet_proj_cfg_default(&pcfg, s);
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_proj_init(&gp.ws, &pcfg));
    lidet_ground_cfg_default(&gcfg, s);
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_ground_init(&gg.ws, &gcfg));
}

/* projection + ground + per-point labels; returns the ground status */
static lidet_status_t run_all(void)
{
    lidet_range_image_t img;
    const int32_t *pp;
    uint32_t np;
    lidet_status_t st;
    TEST_ASSERT_TRUE(LIDET_SUCCEEDED(lidet_proj_run(&gp.ws, pts, n_pts, 4, NULL)));
    lidet_proj_image(&gp.ws, &img);
    st = lidet_ground_run(&gg.ws, &img);
    TEST_ASSERT_TRUE(LIDET_SUCCEEDED(st));
    pp = lidet_proj_point_pixels(&gp.ws, &np);
    TEST_ASSERT_EQUAL_UINT32(n_pts, np);
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_ground_point_labels(&gg.ws, pp, np, labels));
    return st;
}

/* share of truth==want points labelled `lab` */
static double share(int want, int lab, double (*sel)(uint32_t))
{
    uint32_t i, n = 0, k = 0;
    for (i = 0; i < n_pts; ++i)
    {
        if (truth[i] != want || (sel != NULL && sel(i) == 0.0))
            continue;
        ++n;
        k += labels[i] == lab;
    }
    return n ? (double)k / n : 1.0;
}

static double behind(uint32_t i)
{
    return pts[4 * i] < -1.0f ? 1.0 : 0.0;
}

static double before_ramp(uint32_t i)
{
    return pts[4 * i] < 10.0f ? 1.0 : 0.0;
}

static void add_car(scene_t *sc, double x, double y)
{
    box_t *b = &sc->boxes[sc->n_boxes++];
    b->lo[0] = x - 2.0;
    b->hi[0] = x + 2.0;
    b->lo[1] = y - 0.9;
    b->hi[1] = y + 0.9;
    b->lo[2] = -sc->h;
    b->hi[2] = -sc->h + 1.5;
}

/* ---- tests -------------------------------------------------------------------------------- */

static void test_flat_plane(void)
{
    scene_t sc = {SC_FLAT, 1.73, 0, {{{0}, {0}}}};
    const lidet_plane_t *pl;
    const uint8_t *src;
    uint32_t ns, s;
    init_sensor("hdl64");
    add_car(&sc, 10.0, 3.0);
    add_car(&sc, -8.0, -4.0);
    cast_scene(&sc, NULL);
    TEST_ASSERT_EQUAL_INT(LIDET_OK, run_all());
    TEST_ASSERT_TRUE(share(1, 1, NULL) >= 0.999); /* ground recall */
    TEST_ASSERT_TRUE(share(0, 0, NULL) >= 0.999); /* obstacles stay obstacles */
    pl = lidet_ground_planes(&gg.ws, &ns);
    src = lidet_ground_sector_source(&gg.ws);
    TEST_ASSERT_EQUAL_UINT32(32u, ns);
    TEST_ASSERT_EQUAL_UINT16(32u, lidet_ground_stats(&gg.ws)->n_sectors_fitted);
    for (s = 0; s < ns; ++s)
    {
        TEST_ASSERT_EQUAL_UINT8(LIDET_GROUND_PLANE_FITTED, src[s]);
        TEST_ASSERT_CLOSE(1.0, pl[s].nz, 1e-4, 0.0);
        TEST_ASSERT_CLOSE(1.73, pl[s].d_m, 0.01, 0.0);
    }
    /* the sample filter never marks an obstacle's side (flat roofs may pass: RANSAC drops them) */
    {
        lidet_range_image_t img;
        const uint8_t *smp = lidet_ground_samples(&gg.ws);
        uint32_t p, bad = 0, n = 0;
        lidet_proj_image(&gp.ws, &img);
        for (p = 0; p < (uint32_t)img.n_rows * img.n_cols; ++p)
        {
            n += smp[p];
            bad += smp[p] && img.z_m[p] > -1.73f + 0.3f && img.z_m[p] < -1.73f + 1.4f;
        }
        TEST_ASSERT_TRUE(n > 1000u);
        TEST_ASSERT_EQUAL_UINT32(0u, bad);
    }
}

static void test_sloped_plane(void)
{
    scene_t sc = {SC_SLOPE, 1.73, 0, {{{0}, {0}}}};
    const lidet_plane_t *pl;
    uint32_t ns, s;
    init_sensor("hdl64");
    cast_scene(&sc, NULL);
    TEST_ASSERT_EQUAL_INT(LIDET_OK, run_all());
    TEST_ASSERT_TRUE(share(1, 1, NULL) >= 0.995);
    pl = lidet_ground_planes(&gg.ws, &ns);
    for (s = 0; s < ns; ++s)
    {
        /* normal of z = -h + 0.08 x: (-0.08, 0, 1) / |.| */
        TEST_ASSERT_CLOSE(-0.08 / sqrt(1.0064), pl[s].nx, 2e-3, 0.0);
        TEST_ASSERT_CLOSE(0.0, pl[s].ny, 2e-3, 0.0);
        TEST_ASSERT_CLOSE(1.73 / sqrt(1.0064), pl[s].d_m, 0.02, 0.0);
    }
}

static void test_ramp_two_planes(void)
{
    /* one plane per sector cannot follow a kink: behind the sensor everything is flat and must be
     * ground; ahead, the flat part before the ramp is ground, and the ramp itself is ground near
     * the kink (within ground_m). Documented limitation: far up the ramp it is not. */
    scene_t sc = {SC_RAMP, 1.73, 0, {{{0}, {0}}}};
    uint32_t n_far;
    init_sensor("hdl64");
    add_car(&sc, -10.0, 3.0);
    cast_scene(&sc, NULL);
    run_all();
    TEST_ASSERT_TRUE(share(1, 1, behind) >= 0.999);
    TEST_ASSERT_TRUE(share(1, 1, before_ramp) >= 0.95);
    TEST_ASSERT_TRUE(share(1, 1, NULL) >= 0.80);
    TEST_ASSERT_TRUE(share(0, 0, NULL) >= 0.999);
    /* near/far cells split at 12 m (the kink) and a tilt limit above the ramp's 8.5 deg. Judged by the
     * sensor's height above it (far_max_step_m 0), the ramp's plane, 3.46 m below the sensor, is refused */
    gcfg.ring_split_m = 12.0f;
    gcfg.max_tilt_rad = 0.2f;
    gcfg.far_max_step_m = 0.0f;
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_ground_init(&gg.ws, &gcfg));
    run_all();
    n_far = lidet_ground_stats(&gg.ws)->n_far_fitted;
    TEST_ASSERT_TRUE(share(1, 1, NULL) < 0.90);
    /* judged by where it meets the near plane at the split (the default step): the far cells ahead fit the
     * ramp itself, so most of the ramp becomes ground too (2.0 m of max_height_dev_m gave 0.96 here: the kink
     * is a line at x = 12 m, so the sectors 45 degrees off the axis meet the flat near plane 0.5 m above the
     * ramp's at the split and keep it) */
    gcfg.far_max_step_m = 0.5f;
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_ground_init(&gg.ws, &gcfg));
    run_all();
    TEST_ASSERT_TRUE(lidet_ground_stats(&gg.ws)->n_far_fitted >= n_far + 8u);
    TEST_ASSERT_TRUE(share(1, 1, behind) >= 0.999);
    TEST_ASSERT_TRUE(share(1, 1, NULL) >= 0.95);
    TEST_ASSERT_TRUE(share(0, 0, NULL) >= 0.999);
}

static void test_curb_step(void)
{
    /* a 15 cm curb: road and sidewalk are both ground (the step is below ground_m) */
    scene_t sc = {SC_CURB, 1.73, 0, {{{0}, {0}}}};
    init_sensor("hdl64");
    add_car(&sc, 6.0, -7.0); /* a car parked on the sidewalk */
    sc.boxes[0].lo[2] += 0.15;
    cast_scene(&sc, NULL);
    run_all();
    TEST_ASSERT_TRUE(share(1, 1, NULL) >= 0.99);
    TEST_ASSERT_TRUE(share(0, 0, NULL) >= 0.999);
}

/* drops sectors 4..6 entirely and keeps only the bottom row in sector 12 (no samples: the bottom row
 * has no beam below it) */
static int keep_holes(double az, int row)
{
    const double u = 0.5 * (1.0 - az / M_PI); /* column fraction in [0, 1) */
    const int s = (int)(u * 32.0);
    if (s >= 4 && s <= 6)
        return 0;
    if (s == 12)
        return row >= 63;
    return 1;
}

static void test_empty_and_sparse_sectors(void)
{
    scene_t sc = {SC_FLAT, 1.73, 0, {{{0}, {0}}}};
    const uint8_t *src;
    const lidet_plane_t *pl;
    const lidet_ground_stats_t *st;
    uint32_t ns, s;
    init_sensor("hdl64");
    cast_scene(&sc, keep_holes);
    run_all();
    st = lidet_ground_stats(&gg.ws);
    src = lidet_ground_sector_source(&gg.ws);
    pl = lidet_ground_planes(&gg.ws, &ns);
    TEST_ASSERT_EQUAL_UINT16(4u, st->n_sectors_sparse);
    TEST_ASSERT_EQUAL_UINT16(28u, st->n_sectors_fitted);
    TEST_ASSERT_EQUAL_UINT16(4u, st->n_sectors_neighbour);
    TEST_ASSERT_EQUAL_UINT16(0u, st->n_sectors_mount);
    for (s = 4; s <= 6; ++s)
        TEST_ASSERT_EQUAL_UINT8(LIDET_GROUND_PLANE_NEIGHBOUR, src[s]);
    TEST_ASSERT_EQUAL_UINT8(LIDET_GROUND_PLANE_NEIGHBOUR, src[12]);
    TEST_ASSERT_EQUAL_MEMORY(&pl[3], &pl[4], sizeof pl[0]); /* nearest: s-1 before s+1 */
    TEST_ASSERT_EQUAL_MEMORY(&pl[7], &pl[6], sizeof pl[0]);
    TEST_ASSERT_TRUE(share(1, 1, NULL) >= 0.999); /* the sparse sector's ring is still ground */

    /* no neighbour allowed: the mount plane */
    gcfg.fallback_sectors = 0;
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_ground_init(&gg.ws, &gcfg));
    run_all();
    st = lidet_ground_stats(&gg.ws);
    TEST_ASSERT_EQUAL_UINT16(4u, st->n_sectors_mount);
    pl = lidet_ground_planes(&gg.ws, &ns);
    TEST_ASSERT_EQUAL_FLOAT(1.0f, pl[5].nz);
    TEST_ASSERT_EQUAL_FLOAT(1.73f, pl[5].d_m);
    TEST_ASSERT_TRUE(share(1, 1, NULL) >= 0.999);

    /* an empty scan: every sector falls back to the mount plane, nothing is ground */
    n_pts = 0;
    TEST_ASSERT_EQUAL_INT(LIDET_OK, run_all());
    st = lidet_ground_stats(&gg.ws);
    TEST_ASSERT_EQUAL_UINT32(0u, st->n_samples);
    TEST_ASSERT_EQUAL_UINT32(0u, st->n_ground);
    TEST_ASSERT_EQUAL_UINT16(32u, st->n_sectors_mount);
}

static void test_all_points_nan(void)
{
    uint32_t i, p, sum = 0;
    const uint8_t *mask;
    init_sensor("hdl64");
    n_pts = 5000;
    for (i = 0; i < n_pts; ++i)
    {
        pts[4 * i + 0] = NAN;
        pts[4 * i + 1] = (i % 3) ? NAN : 1.0f;
        pts[4 * i + 2] = NAN;
        pts[4 * i + 3] = 0.0f;
    }
    TEST_ASSERT_EQUAL_INT(LIDET_OK, run_all());
    mask = lidet_ground_mask(&gg.ws);
    for (p = 0; p < 64u * 2048u; ++p)
        sum += mask[p];
    TEST_ASSERT_EQUAL_UINT32(0u, sum);
    for (i = 0; i < n_pts; ++i)
        TEST_ASSERT_EQUAL_UINT8(0u, labels[i]);
    TEST_ASSERT_EQUAL_UINT16(32u, lidet_ground_stats(&gg.ws)->n_sectors_mount);
}

static int keep_one_row(double az, int row)
{
    (void)az;
    return row == 15; /* vlp16: the lowest beam, -15 deg */
}

static void test_single_ring(void)
{
    /* one beam: the vertical kernel has no row below, so no samples; every sector takes the mount
     * plane, which still labels the ring on flat ground at the mount height */
    scene_t sc = {SC_FLAT, 0.5, 0, {{{0}, {0}}}};
    init_sensor("vlp16");
    cast_scene(&sc, keep_one_row);
    TEST_ASSERT_TRUE(n_pts > 1000u);
    run_all();
    TEST_ASSERT_EQUAL_UINT32(0u, lidet_ground_stats(&gg.ws)->n_samples);
    TEST_ASSERT_EQUAL_UINT16(32u, lidet_ground_stats(&gg.ws)->n_sectors_mount);
    TEST_ASSERT_TRUE(share(1, 1, NULL) >= 0.999);
}

static void test_vlp16_low_mount(void)
{
    scene_t sc = {SC_FLAT, 0.5, 0, {{{0}, {0}}}};
    init_sensor("vlp16");
    sc.boxes[0].lo[0] = 4.0;
    sc.boxes[0].hi[0] = 6.0;
    sc.boxes[0].lo[1] = -1.0;
    sc.boxes[0].hi[1] = 1.0;
    sc.boxes[0].lo[2] = -0.5;
    sc.boxes[0].hi[2] = 1.0;
    sc.n_boxes = 1;
    cast_scene(&sc, NULL);
    run_all();
    TEST_ASSERT_TRUE(share(1, 1, NULL) >= 0.99);
    TEST_ASSERT_TRUE(share(0, 0, NULL) >= 0.99);
}

static void test_ransac_determinism(void)
{
    static lidet_plane_t first[32];
    static uint8_t mask1[64 * 2048];
    scene_t sc = {SC_CURB, 1.73, 0, {{{0}, {0}}}};
    uint32_t ns;
    const lidet_plane_t *pl;
    init_sensor("hdl64");
    add_car(&sc, 8.0, 2.0);
    cast_scene(&sc, NULL);
    run_all();
    pl = lidet_ground_planes(&gg.ws, &ns);
    memcpy(first, pl, sizeof first);
    memcpy(mask1, lidet_ground_mask(&gg.ws), sizeof mask1);
    /* the same state again, and a fresh init with the same seed: identical planes and mask */
    run_all();
    TEST_ASSERT_EQUAL_MEMORY(first, lidet_ground_planes(&gg.ws, &ns), sizeof first);
    TEST_ASSERT_EQUAL_MEMORY(mask1, lidet_ground_mask(&gg.ws), sizeof mask1);
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_ground_init(&gg.ws, &gcfg));
    run_all();
    TEST_ASSERT_EQUAL_MEMORY(first, lidet_ground_planes(&gg.ws, &ns), sizeof first);
    /* another seed draws other triples but finds the same ground */
    gcfg.seed = 777u;
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_ground_init(&gg.ws, &gcfg));
    run_all();
    pl = lidet_ground_planes(&gg.ws, &ns);
    TEST_ASSERT_CLOSE(first[0].d_m, pl[0].d_m, 0.05, 0.0);
    TEST_ASSERT_TRUE(share(1, 1, NULL) >= 0.99);
}

/* the column window (cfg azimuth_half_rad): on an image a projection with the same window made (no point outside
 * it), the stage works on the window's sectors only and gives what it gives without the window: the same planes,
 * sample mask, ground mask and counts, bit for bit; for a narrow, a wide and a near-whole window, on three scenes
 * and two sensors */
static void test_azimuth_window_same_result(void)
{
    static const float halves[4] = {0.3f, 1.0f, 1.19f, 2.9f};
    static uint8_t mask_w[64 * 2048], samp_w[64 * 2048];
    static lidet_plane_t planes_w[2 * LIDET_GROUND_MAX_SECTORS];
    const int kinds[3] = {SC_RAMP, SC_CURB, SC_FLAT};
    uint32_t k, w;
    for (k = 0; k < 3u; ++k)
    {
        for (w = 0; w < 4u; ++w)
        {
            /* hdl64 on the ramp and the curb; vlp16 (no second plane, its own sectors) on flat ground */
            scene_t sc = {kinds[k], k == 2u ? 0.5 : 1.73, 0, {{{0}, {0}}}};
            lidet_ground_stats_t st_w;
            const lidet_plane_t *pl;
            uint32_t ns = 0, npix;
            lidet_range_image_t img;
            init_sensor(k == 2u ? "vlp16" : "hdl64");
            add_car(&sc, 9.0, -1.5);
            add_car(&sc, 20.0, 4.0);
            pcfg.azimuth_half_rad = halves[w];
            TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_proj_init(&gp.ws, &pcfg));
            cast_scene(&sc, NULL);
            lidet_proj_image(&gp.ws, &img);
            npix = (uint32_t)img.n_rows * img.n_cols;
            gcfg.azimuth_half_rad = halves[w];
            TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_ground_init(&gg.ws, &gcfg));
            run_all();
            memcpy(mask_w, lidet_ground_mask(&gg.ws), npix);
            memcpy(samp_w, lidet_ground_samples(&gg.ws), npix);
            pl = lidet_ground_planes(&gg.ws, &ns);
            memcpy(planes_w, pl, 2u * ns * sizeof planes_w[0]);
            st_w = *lidet_ground_stats(&gg.ws);
            TEST_ASSERT_TRUE(st_w.n_ground > 1000u);
            gcfg.azimuth_half_rad = 0.0f;
            TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_ground_init(&gg.ws, &gcfg));
            run_all();
            TEST_ASSERT_EQUAL_MEMORY(mask_w, lidet_ground_mask(&gg.ws), npix);
            TEST_ASSERT_EQUAL_MEMORY(samp_w, lidet_ground_samples(&gg.ws), npix);
            pl = lidet_ground_planes(&gg.ws, &ns);
            TEST_ASSERT_EQUAL_MEMORY(planes_w, pl, 2u * ns * sizeof planes_w[0]);
            TEST_ASSERT_EQUAL_MEMORY(&st_w, lidet_ground_stats(&gg.ws), sizeof st_w);
        }
    }
    /* out of range: refused */
    gcfg.azimuth_half_rad = -0.1f;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_ground_init(&gg.ws, &gcfg));
    gcfg.azimuth_half_rad = NAN;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_ground_init(&gg.ws, &gcfg));
    gcfg.azimuth_half_rad = 0.0f;
    pcfg.azimuth_half_rad = 0.0f;
}

static void test_filter_variants(void)
{
    /* the authors' released filter (S_u on Z + height gate) also finds the flat ground */
    scene_t sc = {SC_FLAT, 1.73, 0, {{{0}, {0}}}};
    init_sensor("hdl64");
    add_car(&sc, 10.0, 0.0);
    gcfg.fx_on_z = 1;
    gcfg.height_gate = 1;
    gcfg.require_descending = 0;
    gcfg.sample_step = 1;
    gcfg.sample_col_step = 1;
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_ground_init(&gg.ws, &gcfg));
    cast_scene(&sc, NULL);
    run_all();
    TEST_ASSERT_TRUE(share(1, 1, NULL) >= 0.999);
    TEST_ASSERT_TRUE(share(0, 0, NULL) >= 0.999);
    /* a gate that excludes the ground leaves no samples */
    gcfg.gate_above_m = -0.5f;
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_ground_init(&gg.ws, &gcfg));
    run_all();
    TEST_ASSERT_EQUAL_UINT32(0u, lidet_ground_stats(&gg.ws)->n_samples);
}

static void test_vertical_veto(void)
{
    /* a wall 6 m ahead: its lowest returns lie within ground_m of the floor (ground by height);
     * the veto removes them because the beam above lands on the wall too (steep), and keeps the
     * real ground */
    scene_t sc = {SC_FLAT, 1.73, 1, {{{6.0, -6.0, -1.73}, {6.3, 6.0, 1.0}}}};
    uint32_t i, foot = 0, foot_ground = 0;
    init_sensor("hdl64");
    cast_scene(&sc, NULL);
    gcfg.veto_slope = 0.0f;
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_ground_init(&gg.ws, &gcfg));
    run_all();
    for (i = 0; i < n_pts; ++i)
        foot_ground += truth[i] == 2 && labels[i];
    TEST_ASSERT_TRUE(foot_ground > 5u); /* without the veto the wall foot is ground */
    TEST_ASSERT_EQUAL_UINT32(0u, lidet_ground_stats(&gg.ws)->n_vetoed);
    gcfg.veto_slope = 1.0f;
    gcfg.veto_min_dz_m = 0.05f;
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_ground_init(&gg.ws, &gcfg));
    run_all();
    foot_ground = 0;
    for (i = 0; i < n_pts; ++i)
    {
        foot += truth[i] == 2;
        foot_ground += truth[i] == 2 && labels[i];
    }
    TEST_ASSERT_TRUE(foot > 5u);
    TEST_ASSERT_TRUE(foot_ground * 10u <= foot); /* at most 10 % of the foot left */
    TEST_ASSERT_TRUE(lidet_ground_stats(&gg.ws)->n_vetoed > 0u);
    TEST_ASSERT_TRUE(share(1, 1, NULL) >= 0.995);
    TEST_ASSERT_TRUE(share(0, 0, NULL) >= 0.999);
}

static void test_fit_plane(void)
{
    /* points on z = 0.1 x - 0.2 y - 1.5 with a small grid spread */
    static float x[100], y[100], z[100];
    lidet_plane_t p;
    float eig[3];
    const double nrm = sqrt(0.01 + 0.04 + 1.0);
    int i;
    for (i = 0; i < 100; ++i)
    {
        x[i] = 5.0f + (float)(i % 10);
        y[i] = -3.0f + 0.7f * (float)(i / 10);
        z[i] = 0.1f * x[i] - 0.2f * y[i] - 1.5f;
    }
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_ground_fit_plane(x, y, z, 100, &p, eig));
    TEST_ASSERT_CLOSE(-0.1 / nrm, p.nx, 1e-4, 0.0);
    TEST_ASSERT_CLOSE(0.2 / nrm, p.ny, 1e-4, 0.0);
    TEST_ASSERT_CLOSE(1.0 / nrm, p.nz, 1e-4, 0.0);
    TEST_ASSERT_CLOSE(1.5 / nrm, p.d_m, 1e-3, 0.0);
    TEST_ASSERT_TRUE(eig[0] <= eig[1] && eig[1] <= eig[2]);
    TEST_ASSERT_CLOSE(0.0, eig[0], 1e-4, 0.0);
    /* collinear points: no plane */
    for (i = 0; i < 100; ++i)
    {
        y[i] = 0.0f;
        z[i] = 0.5f * x[i];
    }
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_ARG, lidet_ground_fit_plane(x, y, z, 100, &p, NULL));
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_ARG, lidet_ground_fit_plane(x, y, z, 2, &p, NULL));
}

static void test_config_and_arguments(void)
{
    lidet_ground_cfg_t c;
    lidet_range_image_t img;
    int32_t pix[4] = {-1, 0, 64 * 2048 + 5, -7};
    uint8_t out[4] = {9, 9, 9, 9};
    init_sensor("hdl64");
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_ARG, lidet_ground_init(NULL, &gcfg));
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_ARG, lidet_ground_init(&gg.ws, NULL));
    c = gcfg;
    c.n_sectors = LIDET_GROUND_MAX_SECTORS + 1;
    c.fallback_sectors = 0;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_BUFFER, lidet_ground_init(&gg.ws, &c));
    c = gcfg;
    c.ground_m = NAN;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_ground_init(&gg.ws, &c));
    c = gcfg;
    c.max_tilt_rad = 2.0f;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_ground_init(&gg.ws, &c));
    c = gcfg;
    c.n_sectors = 0;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_ground_init(&gg.ws, &c));
    c = gcfg;
    c.sample_step = 0;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_ground_init(&gg.ws, &c));
    c = gcfg;
    c.sample_col_step = 17;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_ground_init(&gg.ws, &c));
    /* a failed init leaves the state unusable */
    lidet_proj_image(&gp.ws, &img);
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_STATE, lidet_ground_run(&gg.ws, &img));
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_STATE, lidet_ground_point_labels(&gg.ws, pix, 4, out));
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_ground_init(&gg.ws, &gcfg));
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_ARG, lidet_ground_run(&gg.ws, NULL));
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_ARG, lidet_ground_run(NULL, &img));
    n_pts = 0;
    run_all();
    /* unprojected (-1, negative) and out-of-image pixel indices give 0 */
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_ground_point_labels(&gg.ws, pix, 4, out));
    TEST_ASSERT_EQUAL_UINT8(0, out[0]);
    TEST_ASSERT_EQUAL_UINT8(0, out[2]);
    TEST_ASSERT_EQUAL_UINT8(0, out[3]);
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_ARG, lidet_ground_point_labels(&gg.ws, NULL, 4, out));
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_ground_point_labels(&gg.ws, NULL, 0, NULL));
    /* more sectors than columns */
    c = gcfg;
    c.n_sectors = 200;
    /* the third cells' planes share the near / far arrays: 3 * 200 > 2 * LIDET_GROUND_MAX_SECTORS */
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_ground_init(&gg.ws, &c));
    c.far2_split_m = 0.0f;
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_ground_init(&gg.ws, &c));
    img.n_cols = 100;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_ground_run(&gg.ws, &img));
    TEST_ASSERT_EQUAL_UINT32((uint32_t)sizeof(lidet_ground_t), lidet_ground_bytes());
    /* vlp16 defaults differ from hdl64 (low mount) */
    lidet_ground_cfg_default(&c, lidet_sensor_find("vlp16"));
    TEST_ASSERT_EQUAL_FLOAT(0.5f, c.mount_height_m);
    lidet_ground_cfg_default(&c, NULL);
    TEST_ASSERT_EQUAL_FLOAT(1.73f, c.mount_height_m);
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_ground_init(&gg.ws, &c));
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_flat_plane);
    RUN_TEST(test_sloped_plane);
    RUN_TEST(test_ramp_two_planes);
    RUN_TEST(test_curb_step);
    RUN_TEST(test_empty_and_sparse_sectors);
    RUN_TEST(test_all_points_nan);
    RUN_TEST(test_single_ring);
    RUN_TEST(test_vlp16_low_mount);
    RUN_TEST(test_ransac_determinism);
    RUN_TEST(test_filter_variants);
    RUN_TEST(test_vertical_veto);
    RUN_TEST(test_azimuth_window_same_result);
    RUN_TEST(test_fit_plane);
    RUN_TEST(test_config_and_arguments);
    return UNITY_END();
}
