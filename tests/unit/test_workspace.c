/* SPDX-License-Identifier: MIT */
/* The detector workspace: the same results, bit for bit, as the standalone stages chained by hand on
 * the compact image (4 mm pixels) made by hand, and within set tolerances of the float stages, on the
 * simulated scans shipped in tests/data (and the real scans of ../shared/data/real when present);
 * per-point outputs optional; sizes that add up. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "lidet/lidet.h"
#include "lidet/lidet_workspace.h"
#include "test_util.h"

#define MAX_SCAN_POINTS 200000

LIDET_GUARDED(lidet_workspace_t, g_ws);
LIDET_GUARDED(lidet_proj_t, g_proj);
LIDET_GUARDED(lidet_ground_t, g_ground);
LIDET_GUARDED(lidet_cluster_t, g_cluster);
static float g_points[MAX_SCAN_POINTS * 4];
static int32_t g_pp[LIDET_MAX_POINTS];
static uint32_t g_ids_ws[LIDET_MAX_POINTS], g_ids_ref[LIDET_MAX_POINTS];
static uint8_t g_gnd_ws[LIDET_MAX_POINTS], g_gnd_ref[LIDET_MAX_POINTS];
static lidet_proposal_t g_prop_ws, g_prop_ref;

void setUp(void)
{
}

void tearDown(void)
{
}

static uint32_t load_scan(const char *rel)
{
    char path[512];
    FILE *f;
    size_t n;
    snprintf(path, sizeof path, "%s/%s", LIDET_SOURCE_DIR, rel);
    f = fopen(path, "rb");
    TEST_ASSERT_NOT_NULL_MESSAGE(f, path);
    n = fread(g_points, 4 * sizeof(float), MAX_SCAN_POINTS, f);
    fclose(f);
    TEST_ASSERT_TRUE(n > 1000u);
    return (uint32_t)n;
}

/* The reference of the workspace, bit for bit: the standalone stages chained by hand on a compact image
 * made by hand from the float projection (limited to the compact span, 131 m), rounded as the
 * projection rounds (floor(v * 250 + 0.5) in float; a valid pixel's range at least 1 step). */
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
        TEST_ASSERT_TRUE(img->range_m[p] <= LIDET_PIXEL_MAX_RANGE_M);
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

/* The stages chained by hand on `img` into the standalone states */
static void chain(lidet_range_image_t *img, const lidet_workspace_cfg_t *cfg)
{
    const lidet_plane_t *planes;
    uint32_t ns;
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_ground_init(&g_ground.ws, &cfg->ground));
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_cluster_init(&g_cluster.ws, &cfg->cluster));
    TEST_ASSERT_TRUE(LIDET_SUCCEEDED(lidet_ground_run(&g_ground.ws, img)));
    planes = lidet_ground_planes(&g_ground.ws, &ns);
    TEST_ASSERT_TRUE(LIDET_SUCCEEDED(lidet_cluster_run(&g_cluster.ws, img, lidet_ground_mask(&g_ground.ws), planes, ns)));
}

/* Agreement of the workspace with the float stages: ground labels (share of valid pixels with the same
 * label) and cluster ids (share of valid pixels whose ids correspond: a workspace cluster and a float
 * cluster correspond when each is the other's largest overlap; ids 0 correspond to each other). */
static uint32_t g_hist[LIDET_MAX_CLUSTERS + 2], g_map_ws[LIDET_MAX_CLUSTERS + 2], g_map_ref[LIDET_MAX_CLUSTERS + 2];

static void best_overlap(const uint16_t *a, const uint16_t *b, uint32_t npix, const uint8_t *valid, uint32_t *map)
{
    uint32_t la, p;
    for (la = 1; la <= LIDET_MAX_CLUSTERS; ++la)
    {
        uint32_t best = 0, best_n = 0, lb;
        memset(g_hist, 0, sizeof g_hist);
        for (p = 0; p < npix; ++p)
        {
            if (valid[p] && a[p] == la && b[p] <= LIDET_MAX_CLUSTERS)
                ++g_hist[b[p]];
        }
        for (lb = 0; lb <= LIDET_MAX_CLUSTERS; ++lb)
        {
            if (g_hist[lb] > best_n)
            {
                best_n = g_hist[lb];
                best = lb;
            }
        }
        map[la] = best;
    }
    map[0] = 0;
}

static uint8_t g_valid[LIDET_MAX_ROWS * LIDET_MAX_COLS];

static void agreement(const uint8_t *gnd_ref, const uint16_t *lab_ref, const lidet_range_image_t *img, double *ground,
                      double *cluster)
{
    const uint32_t npix = (uint32_t)img->n_rows * img->n_cols;
    const uint8_t *gnd_ws = lidet_workspace_ground_mask(&g_ws.ws);
    const uint16_t *lab_ws = lidet_workspace_labels(&g_ws.ws);
    uint16_t a, b;
    uint32_t p, n = 0, same_g = 0, same_c = 0, max_id = 0;
    for (p = 0; p < npix; ++p)
    {
        /* a pixel valid in either image (they differ only beyond 131 m) */
        g_valid[p] = (uint8_t)(img->range_m[p] > 0.0f || g_ws.ws.range_4mm[p] > 0u);
    }
    for (p = 0; p < npix; ++p)
    {
        a = lab_ws[p] <= LIDET_MAX_CLUSTERS ? lab_ws[p] : 0; /* non-kept labels read as 0 */
        b = lab_ref[p] <= LIDET_MAX_CLUSTERS ? lab_ref[p] : 0;
        max_id = a > max_id ? a : max_id;
        max_id = b > max_id ? b : max_id;
    }
    TEST_ASSERT_TRUE(max_id <= LIDET_MAX_CLUSTERS);
    best_overlap(lab_ws, lab_ref, npix, g_valid, g_map_ws);
    best_overlap(lab_ref, lab_ws, npix, g_valid, g_map_ref);
    for (p = 0; p < npix; ++p)
    {
        if (!g_valid[p])
            continue;
        a = lab_ws[p] <= LIDET_MAX_CLUSTERS ? lab_ws[p] : 0;
        b = lab_ref[p] <= LIDET_MAX_CLUSTERS ? lab_ref[p] : 0;
        ++n;
        same_g += (uint32_t)(gnd_ws[p] == gnd_ref[p]);
        same_c += (uint32_t)((a == 0 && b == 0) || (a != 0 && b != 0 && g_map_ws[a] == b && g_map_ref[b] == a));
    }
    TEST_ASSERT_TRUE(n > 0u);
    *ground = 100.0 * same_g / n;
    *cluster = 100.0 * same_c / n;
}

/* run the workspace and the standalone stages on one scan: every output equals the stages chained on
 * the compact image made by hand, and agrees with the float stages within the tolerances (the float
 * stages are the reference; the workspace differs from them by the 4 mm rounding only) */
static void compare_on(const char *rel, const char *sensor_name, double min_ground_pct, double min_cluster_pct)
{
    const lidet_sensor_t *s = lidet_sensor_find(sensor_name);
    lidet_workspace_cfg_t cfg, cfg_ref;
    lidet_proposal_cfg_t pcfg;
    lidet_range_image_t img, qimg, wimg;
    const lidet_plane_t *planes;
    const lidet_cluster_rec_t *rec_ws, *rec_ref;
    uint32_t n, npix, ns, k_ws, k_ref, i, np;
    lidet_status_t st_ws, st;
    lidet_workspace_stats_t wst;
    double agree_g, agree_c;

    TEST_ASSERT_NOT_NULL(s);
    n = load_scan(rel);
    if (n > LIDET_MAX_POINTS)
        n = LIDET_MAX_POINTS;
    CANARY_FILL(g_ws);
    CANARY_FILL(g_proj);
    CANARY_FILL(g_ground);
    CANARY_FILL(g_cluster);
    lidet_workspace_cfg_default(&cfg, s);
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_workspace_init(&g_ws.ws, &cfg));

    /* the workspace, first without per-point outputs, then with them: the same results */
    st_ws = lidet_workspace_run(&g_ws.ws, g_points, n, 4, NULL, NULL);
    TEST_ASSERT_TRUE(LIDET_SUCCEEDED(st_ws));
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_ARG, lidet_workspace_point_labels(&g_ws.ws, NULL, 5, g_ids_ws, NULL));
    memset(g_pp, 0x55, sizeof g_pp);
    TEST_ASSERT_EQUAL_INT(st_ws, lidet_workspace_run(&g_ws.ws, g_points, n, 4, NULL, g_pp));
    CANARY_CHECK(g_ws);
    lidet_workspace_image(&g_ws.ws, &wimg);
    TEST_ASSERT_NULL(wimg.rxy_m);
    TEST_ASSERT_NULL(wimg.point_idx);
    TEST_ASSERT_NULL(wimg.x_m);
    npix = (uint32_t)wimg.n_rows * wimg.n_cols;

    /* 1. the float stages (the reference): agreement within the tolerances */
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_proj_init(&g_proj.ws, &cfg.proj));
    TEST_ASSERT_TRUE(LIDET_SUCCEEDED(lidet_proj_run(&g_proj.ws, g_points, n, 4, NULL)));
    lidet_proj_image(&g_proj.ws, &img);
    chain(&img, &cfg);
    agreement(lidet_ground_mask(&g_ground.ws), lidet_cluster_labels(&g_cluster.ws), &img, &agree_g, &agree_c);
    printf("%s: workspace (4 mm pixels) vs float stages: ground labels %.3f %%, cluster ids %.3f %% of %u pixels\n",
           rel, agree_g, agree_c, (unsigned)g_proj.ws.state.stats.n_pixels_filled);
    TEST_ASSERT_TRUE_MESSAGE(agree_g >= min_ground_pct, "ground labels: agreement with the float stages");
    TEST_ASSERT_TRUE_MESSAGE(agree_c >= min_cluster_pct, "cluster ids: agreement with the float stages");

    /* 2. the stages chained by hand on the compact image: equal, bit for bit */
    cfg_ref = cfg;
    cfg_ref.proj.max_range_m = LIDET_PIXEL_MAX_RANGE_M; /* the compact span, as the workspace's projection */
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_proj_init(&g_proj.ws, &cfg_ref.proj));
    st = lidet_proj_run(&g_proj.ws, g_points, n, 4, NULL);
    TEST_ASSERT_TRUE(LIDET_SUCCEEDED(st));
    lidet_proj_image(&g_proj.ws, &img);
    compact_by_hand(&img, &qimg);
    chain(&qimg, &cfg);
    CANARY_CHECK(g_proj);
    CANARY_CHECK(g_ground);
    CANARY_CHECK(g_cluster);

    TEST_ASSERT_EQUAL_UINT16(img.n_rows, wimg.n_rows);
    TEST_ASSERT_EQUAL_UINT16(img.n_cols, wimg.n_cols);
    TEST_ASSERT_EQUAL_MEMORY(g_qx, wimg.x_4mm, npix * sizeof(int16_t));
    TEST_ASSERT_EQUAL_MEMORY(g_qy, wimg.y_4mm, npix * sizeof(int16_t));
    TEST_ASSERT_EQUAL_MEMORY(g_qz, wimg.z_4mm, npix * sizeof(int16_t));
    TEST_ASSERT_EQUAL_MEMORY(g_qr, wimg.range_4mm, npix * sizeof(uint16_t));
    planes = lidet_ground_planes(&g_ground.ws, &ns);
    TEST_ASSERT_EQUAL_MEMORY(lidet_ground_mask(&g_ground.ws), lidet_workspace_ground_mask(&g_ws.ws), npix);
    TEST_ASSERT_EQUAL_MEMORY(planes, lidet_workspace_planes(&g_ws.ws, NULL), 2u * ns * sizeof(lidet_plane_t));
    TEST_ASSERT_EQUAL_MEMORY(lidet_cluster_labels(&g_cluster.ws), lidet_workspace_labels(&g_ws.ws),
                             npix * sizeof(uint16_t));
    rec_ref = lidet_cluster_records(&g_cluster.ws, &k_ref);
    rec_ws = lidet_workspace_clusters(&g_ws.ws, &k_ws);
    TEST_ASSERT_EQUAL_UINT32(k_ref, k_ws);
    TEST_ASSERT_TRUE(k_ws > 3u); /* a real scene: something to compare */
    TEST_ASSERT_EQUAL_MEMORY(rec_ref, rec_ws, k_ws * sizeof(lidet_cluster_rec_t));
    TEST_ASSERT_EQUAL_MEMORY(lidet_cluster_members(&g_cluster.ws), lidet_workspace_members(&g_ws.ws),
                             lidet_cluster_stats(&g_cluster.ws)->n_pixels_kept * sizeof(int32_t));
    lidet_workspace_stats(&g_ws.ws, &wst);
    TEST_ASSERT_EQUAL_MEMORY(lidet_cluster_stats(&g_cluster.ws), &wst.cluster, sizeof wst.cluster);
    TEST_ASSERT_EQUAL_MEMORY(lidet_ground_stats(&g_ground.ws), &wst.ground, sizeof wst.ground);
    TEST_ASSERT_EQUAL_MEMORY(lidet_proj_stats(&g_proj.ws), &wst.proj, sizeof wst.proj);

    /* proposals read the workspace's own (compact) copies of the points */
    lidet_proposal_cfg_default(&pcfg);
    for (i = 0; i < k_ws; ++i)
    {
        memset(&g_prop_ws, 0, sizeof g_prop_ws);
        memset(&g_prop_ref, 0, sizeof g_prop_ref);
        TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_proposal_make(&g_cluster.ws, i, &pcfg, &g_prop_ref));
        TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_workspace_proposal(&g_ws.ws, i, &pcfg, &g_prop_ws));
        TEST_ASSERT_EQUAL_MEMORY(&g_prop_ref, &g_prop_ws, sizeof g_prop_ws);
    }
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_ARG, lidet_workspace_proposal(&g_ws.ws, k_ws, &pcfg, &g_prop_ws));

    /* per-point outputs from the caller's buffer */
    TEST_ASSERT_EQUAL_MEMORY(lidet_proj_point_pixels(&g_proj.ws, &np), g_pp, n * sizeof(int32_t));
    TEST_ASSERT_EQUAL_UINT32(n, np);
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_workspace_point_labels(&g_ws.ws, g_pp, n, g_ids_ws, g_gnd_ws));
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_cluster_point_labels(&g_cluster.ws, g_pp, n, g_ids_ref));
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_ground_point_labels(&g_ground.ws, g_pp, n, g_gnd_ref));
    TEST_ASSERT_EQUAL_MEMORY(g_ids_ref, g_ids_ws, n * sizeof(uint32_t));
    TEST_ASSERT_EQUAL_MEMORY(g_gnd_ref, g_gnd_ws, n);
}

/* tolerances against the float stages (issue 16's agreement targets for the integer build) */
#define MIN_GROUND_PCT 90.0
#define MIN_CLUSTER_PCT 90.0

static void test_workspace_matches_stages_vlp16(void)
{
    compare_on("tests/data/sim_vlp16/velodyne/000000.bin", "vlp16", MIN_GROUND_PCT, MIN_CLUSTER_PCT);
}

static void test_workspace_matches_stages_hdl64(void)
{
    compare_on("tests/data/sim_hdl64/velodyne/000000.bin", "hdl64", MIN_GROUND_PCT, MIN_CLUSTER_PCT);
}

/* real HDL-64 scans of ../shared/data/real, when present (not shipped: KITTI licence) */
static void test_workspace_real_scans(void)
{
    static const char *const scans[] = {
        "../shared/data/real/semantickitti/velodyne/00_000000.bin", "../shared/data/real/semantickitti/velodyne/00_000001.bin",
        "../shared/data/real/semantickitti/velodyne/00_000002.bin", "../shared/data/real/semantickitti/velodyne/00_000003.bin",
        "../shared/data/real/semantickitti/velodyne/00_000004.bin", "../shared/data/real/semantickitti/velodyne/00_000005.bin",
        "../shared/data/real/kitti/training/velodyne/000000.bin",   "../shared/data/real/kitti/training/velodyne/000001.bin",
        "../shared/data/real/kitti/training/velodyne/000002.bin"};
    char path[512];
    FILE *f;
    uint32_t i, ran = 0;
    for (i = 0; i < sizeof scans / sizeof scans[0]; ++i)
    {
        snprintf(path, sizeof path, "%s/%s", LIDET_SOURCE_DIR, scans[i]);
        f = fopen(path, "rb");
        if (f == NULL)
            continue;
        fclose(f);
        compare_on(scans[i], "hdl64", MIN_GROUND_PCT, MIN_CLUSTER_PCT);
        ++ran;
    }
    if (ran == 0u)
        TEST_IGNORE_MESSAGE("../shared/data/real not present");
}

static void test_workspace_errors(void)
{
    lidet_workspace_cfg_t cfg;
    lidet_proposal_cfg_t pcfg;
    lidet_proposal_t *p = &g_prop_ws;
    memset(&g_ws.ws, 0, sizeof g_ws.ws);
    lidet_workspace_cfg_default(&cfg, lidet_sensor_find("vlp16"));
    lidet_proposal_cfg_default(&pcfg);
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_STATE, lidet_workspace_run(&g_ws.ws, g_points, 0, 4, NULL, NULL));
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_ARG, lidet_workspace_run(NULL, g_points, 0, 4, NULL, NULL));
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_ARG, lidet_workspace_init(&g_ws.ws, NULL));
    cfg.cluster.min_points = 0;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_workspace_init(&g_ws.ws, &cfg));
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_STATE, lidet_workspace_run(&g_ws.ws, g_points, 0, 4, NULL, NULL));
    cfg.cluster.min_points = 10;
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_workspace_init(&g_ws.ws, &cfg));
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_STATE, lidet_workspace_proposal(&g_ws.ws, 0, &pcfg, p));
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_STATE, lidet_workspace_point_labels(&g_ws.ws, g_pp, 0, NULL, NULL));
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_ARG, lidet_workspace_run(&g_ws.ws, g_points, 10, 2, NULL, NULL));
    /* an empty scan runs through every stage */
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_workspace_run(&g_ws.ws, NULL, 0, 4, NULL, NULL));
    TEST_ASSERT_NOT_NULL(lidet_workspace_clusters(&g_ws.ws, &pcfg.n_points));
    TEST_ASSERT_EQUAL_UINT32(0, pcfg.n_points);
}

static void test_workspace_sizes(void)
{
    lidet_workspace_sizes_t s;
    uint32_t big;
    lidet_workspace_sizes(&s);
    TEST_ASSERT_EQUAL_UINT32(sizeof(lidet_workspace_t), s.total);
    TEST_ASSERT_EQUAL_UINT32(lidet_workspace_bytes(), s.total);
    TEST_ASSERT_EQUAL_UINT32(sizeof(lidet_proj_state_t), s.proj_state);
    TEST_ASSERT_EQUAL_UINT32(lidet_proj_state_bytes(), s.proj_state);
    TEST_ASSERT_EQUAL_UINT32(lidet_ground_state_bytes(), s.ground_state);
    TEST_ASSERT_EQUAL_UINT32(lidet_cluster_state_bytes(), s.cluster_state);
    TEST_ASSERT_EQUAL_UINT32(8u * LIDET_MAX_ROWS * LIDET_MAX_COLS, s.image); /* int16 x, y, z, range */
    TEST_ASSERT_EQUAL_UINT32(LIDET_MAX_ROWS * LIDET_MAX_COLS, s.ground_mask);
    TEST_ASSERT_EQUAL_UINT32(4u * LIDET_MAX_ROWS * LIDET_MAX_COLS, s.overlay_proj);
    TEST_ASSERT_EQUAL_UINT32(6u * LIDET_MAX_ROWS * LIDET_MAX_COLS, s.overlay_cluster);
    TEST_ASSERT_EQUAL_UINT32(lidet_ground_scratch_bytes(), s.overlay_ground); /* R is not stored: two rows of it */
    /* the overlay is the peak of its parts, not the sum */
    big = s.overlay_proj > s.overlay_ground ? s.overlay_proj : s.overlay_ground;
    big = big > s.overlay_cluster ? big : s.overlay_cluster;
    TEST_ASSERT_TRUE(s.overlay >= big && s.overlay < big + 16u);
    TEST_ASSERT_TRUE(s.total >= s.proj_state + s.ground_state + s.cluster_state + s.image + s.ground_mask + s.overlay);
    TEST_ASSERT_TRUE(s.total < s.proj_state + s.ground_state + s.cluster_state + s.image + s.ground_mask + s.overlay + 64u);
    TEST_ASSERT_EQUAL_UINT32(lidet_proj_bytes() + lidet_ground_bytes() + lidet_cluster_bytes(), s.stages_standalone);
    TEST_ASSERT_TRUE(s.total < s.stages_standalone);
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_workspace_sizes);
    RUN_TEST(test_workspace_errors);
    RUN_TEST(test_workspace_matches_stages_vlp16);
    RUN_TEST(test_workspace_matches_stages_hdl64);
    RUN_TEST(test_workspace_real_scans);
    return UNITY_END();
}
