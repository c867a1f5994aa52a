/* SPDX-License-Identifier: MIT */
/* The detector workspace: the same results, bit for bit, as the standalone stages chained by hand,
 * on the simulated scans shipped in tests/data; per-point outputs optional; sizes that add up. */
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

/* run the workspace and the three standalone stages on one scan and compare every output */
static void compare_on(const char *rel, const char *sensor_name)
{
    const lidet_sensor_t *s = lidet_sensor_find(sensor_name);
    lidet_workspace_cfg_t cfg;
    lidet_proposal_cfg_t pcfg;
    lidet_range_image_t img, wimg;
    const lidet_plane_t *planes;
    const lidet_cluster_rec_t *rec_ws, *rec_ref;
    uint32_t n, npix, ns, k_ws, k_ref, i, np;
    lidet_status_t st_ws, st;
    lidet_workspace_stats_t wst;

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
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_proj_init(&g_proj.ws, &cfg.proj));
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_ground_init(&g_ground.ws, &cfg.ground));
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_cluster_init(&g_cluster.ws, &cfg.cluster));

    /* the reference: the stages chained by hand, as ports/host/cli_cluster.c does */
    st = lidet_proj_run(&g_proj.ws, g_points, n, 4, NULL);
    TEST_ASSERT_TRUE(LIDET_SUCCEEDED(st));
    lidet_proj_image(&g_proj.ws, &img);
    TEST_ASSERT_TRUE(LIDET_SUCCEEDED(lidet_ground_run(&g_ground.ws, &img)));
    planes = lidet_ground_planes(&g_ground.ws, &ns);
    TEST_ASSERT_TRUE(LIDET_SUCCEEDED(lidet_cluster_run(&g_cluster.ws, &img, lidet_ground_mask(&g_ground.ws), planes, ns)));

    /* the workspace, first without per-point outputs, then with them: the same results */
    st_ws = lidet_workspace_run(&g_ws.ws, g_points, n, 4, NULL, NULL);
    TEST_ASSERT_TRUE(LIDET_SUCCEEDED(st_ws));
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_ARG, lidet_workspace_point_labels(&g_ws.ws, NULL, 5, g_ids_ws, NULL));
    memset(g_pp, 0x55, sizeof g_pp);
    TEST_ASSERT_EQUAL_INT(st_ws, lidet_workspace_run(&g_ws.ws, g_points, n, 4, NULL, g_pp));
    CANARY_CHECK(g_ws);
    CANARY_CHECK(g_proj);
    CANARY_CHECK(g_ground);
    CANARY_CHECK(g_cluster);

    lidet_workspace_image(&g_ws.ws, &wimg);
    TEST_ASSERT_NULL(wimg.rxy_m);
    TEST_ASSERT_NULL(wimg.point_idx);
    TEST_ASSERT_EQUAL_UINT16(img.n_rows, wimg.n_rows);
    TEST_ASSERT_EQUAL_UINT16(img.n_cols, wimg.n_cols);
    npix = (uint32_t)img.n_rows * img.n_cols;
    TEST_ASSERT_EQUAL_MEMORY(img.x_m, wimg.x_m, npix * sizeof(float));
    TEST_ASSERT_EQUAL_MEMORY(img.y_m, wimg.y_m, npix * sizeof(float));
    TEST_ASSERT_EQUAL_MEMORY(img.z_m, wimg.z_m, npix * sizeof(float));
    TEST_ASSERT_EQUAL_MEMORY(img.range_m, wimg.range_m, npix * sizeof(float));
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

    /* proposals read the workspace's own copies of the points */
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

static void test_workspace_matches_stages_vlp16(void)
{
    compare_on("tests/data/sim_vlp16/velodyne/000000.bin", "vlp16");
}

static void test_workspace_matches_stages_hdl64(void)
{
    compare_on("tests/data/sim_hdl64/velodyne/000000.bin", "hdl64");
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
    TEST_ASSERT_EQUAL_UINT32(16u * LIDET_MAX_ROWS * LIDET_MAX_COLS, s.image);
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
    return UNITY_END();
}
