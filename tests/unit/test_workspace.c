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
/* a change to the defaults for compare_on (NULL: none; set by test_workspace_edge_plane, which also skips the
 * float stages' tolerances: they were measured on the defaults) */
static void (*g_tweak)(lidet_workspace_cfg_t *cfg);
static int g_check_r; /* compare_on checks the workspace's R plane (a run that writes no edge plane there) */

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
    lidet_cluster_cfg_t ccfg = cfg->cluster;
    ccfg.plane_split_m =
        cfg->ground.ring_split_m; /* as the workspace: the whole plane table, far planes too */
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_ground_init(&g_ground.ws, &cfg->ground));
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_cluster_init(&g_cluster.ws, &ccfg));
    TEST_ASSERT_TRUE(LIDET_SUCCEEDED(lidet_ground_run(&g_ground.ws, img)));
    planes = lidet_ground_planes(&g_ground.ws, &ns);
    TEST_ASSERT_TRUE(
        LIDET_SUCCEEDED(lidet_cluster_run(&g_cluster.ws, img, lidet_ground_mask(&g_ground.ws), planes, ns)));
}

/* Agreement of the workspace with the float stages: ground labels (share of valid pixels with the same
 * label) and cluster ids (share of valid pixels whose ids correspond: a workspace cluster and a float
 * cluster correspond when each is the other's largest overlap; ids 0 correspond to each other). */
static uint32_t g_pairs[LIDET_MAX_CLUSTERS + 1][LIDET_MAX_CLUSTERS + 1]; /* [a][b]: pixels labelled a and b */
static uint32_t g_map_ab[LIDET_MAX_CLUSTERS + 1], g_map_ba[LIDET_MAX_CLUSTERS + 1];

static uint16_t kept(uint16_t l)
{
    return l <= LIDET_MAX_CLUSTERS ? l : 0u; /* labels of pixels in no kept cluster read as 0 */
}

/* map_ab[a] = the id b overlapping id a most (and map_ba the other way) over the valid pixels */
static void best_overlap(const uint16_t *a, const uint16_t *b, uint32_t npix, const uint8_t *valid)
{
    uint32_t p, la, lb;
    memset(g_pairs, 0, sizeof g_pairs);
    memset(g_map_ab, 0, sizeof g_map_ab);
    memset(g_map_ba, 0, sizeof g_map_ba);
    for (p = 0; p < npix; ++p)
    {
        if (valid[p])
            ++g_pairs[kept(a[p])][kept(b[p])];
    }
    for (la = 0; la <= LIDET_MAX_CLUSTERS; ++la)
    {
        for (lb = 0; lb <= LIDET_MAX_CLUSTERS; ++lb)
        {
            if (g_pairs[la][lb] > g_pairs[la][g_map_ab[la]])
                g_map_ab[la] = lb;
            if (g_pairs[la][lb] > g_pairs[g_map_ba[lb]][lb])
                g_map_ba[lb] = la;
        }
    }
}

/* Tolerances against the float stages, measured on the shipped scans and the 9 real scans of
 * ../shared/data/real (docs/MEMORY.md): the clustering alone agrees on >= 99.93 % of the pixels
 * (>= 99.83 % since the refinement of issue 15, which reads x and y, so a 4 mm step can move a point
 * into the next cell of its grid: KITTI 000000, one cut made differently); the
 * chain agrees on >= 98.7 % (ground) and >= 94.5 % (cluster ids, one real scan where a reseeded float
 * run agrees on 88.7 %), never more than 0.4 point below a reseeded float run. Since far planes are judged
 * at the split (far_max_step_m), the far cells of a climbing or falling road keep a plane of their own, which
 * RANSAC draws from fewer, less planar samples: on the shipped HDL-64 scan the chain agrees on 98.0 % (ground)
 * and a reseeded float run on 97.7 % (both 0.6 point lower than before). */
#define MIN_CLUSTER_STAGE_PCT 99.8
#define MIN_GROUND_PCT 97.5
#define MIN_CLUSTER_PCT 94.0
#define SEED_MARGIN_PCT 1.0

static uint8_t g_valid[LIDET_MAX_ROWS * LIDET_MAX_COLS];
static uint8_t g_gnd_f[LIDET_MAX_ROWS * LIDET_MAX_COLS], g_gnd_seed[LIDET_MAX_ROWS * LIDET_MAX_COLS];
static uint16_t g_lab_f[LIDET_MAX_ROWS * LIDET_MAX_COLS], g_lab_seed[LIDET_MAX_ROWS * LIDET_MAX_COLS];
static lidet_plane_t g_planes_f[2 * LIDET_GROUND_MAX_SECTORS];

/* share of the valid pixels (g_valid) whose ground labels agree (gnd_a, gnd_b NULL: not measured) and
 * whose cluster ids correspond */
static void agreement(const uint8_t *gnd_a, const uint16_t *lab_a, const uint8_t *gnd_b,
                      const uint16_t *lab_b, uint32_t npix, double *ground, double *cluster)
{
    uint32_t p, n = 0, same_g = 0, same_c = 0;
    best_overlap(lab_a, lab_b, npix, g_valid);
    for (p = 0; p < npix; ++p)
    {
        const uint16_t a = kept(lab_a[p]), b = kept(lab_b[p]);
        if (!g_valid[p])
            continue;
        ++n;
        same_g += (uint32_t)(gnd_a == NULL || gnd_a[p] == gnd_b[p]);
        same_c +=
            (uint32_t)((a == 0 && b == 0) || (a != 0 && b != 0 && g_map_ab[a] == b && g_map_ba[b] == a));
    }
    TEST_ASSERT_TRUE(n > 0u);
    *ground = 100.0 * same_g / n;
    *cluster = 100.0 * same_c / n;
}

/* The workspace against the float stages (the reference) on one scan: ground labels and cluster ids of
 * the whole chain, and of the clustering alone (on the workspace's image, with the float ground mask).
 * RANSAC draws its hypotheses from the samples, so a sample more or less moves a sector's plane as much
 * as another seed would: the chain's agreement is compared with that of the float stages with the next
 * seed (the noise floor), the clustering's alone with a fixed tolerance (it reads the ranges only). */
static void against_float(const char *rel, const lidet_workspace_cfg_t *cfg, uint32_t n)
{
    lidet_range_image_t img, wimg;
    lidet_workspace_cfg_t cfg_seed = *cfg;
    const lidet_plane_t *planes;
    uint32_t npix, ns, p;
    double agree_g, agree_c, noise_g, noise_c, stage_g, stage_c;

    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_proj_init(&g_proj.ws, &cfg->proj));
    TEST_ASSERT_TRUE(LIDET_SUCCEEDED(lidet_proj_run(&g_proj.ws, g_points, n, 4, NULL)));
    lidet_proj_image(&g_proj.ws, &img);
    lidet_workspace_image(&g_ws.ws, &wimg);
    npix = (uint32_t)img.n_rows * img.n_cols;
    for (p = 0; p < npix; ++p)
    {
        /* a pixel valid in either image (they differ only beyond 131 m) */
        g_valid[p] = (uint8_t)(img.range_m[p] > 0.0f || wimg.range_4mm[p] > 0u);
    }
    chain(&img, cfg);
    memcpy(g_gnd_f, lidet_ground_mask(&g_ground.ws), npix);
    memcpy(g_lab_f, lidet_cluster_labels(&g_cluster.ws), npix * sizeof(uint16_t));
    planes = lidet_ground_planes(&g_ground.ws, &ns);
    memcpy(g_planes_f, planes, 2u * ns * sizeof(lidet_plane_t));
    agreement(lidet_workspace_ground_mask(&g_ws.ws), lidet_workspace_labels(&g_ws.ws), g_gnd_f, g_lab_f, npix,
              &agree_g, &agree_c);
    /* the clustering alone on the compact image, with the float ground */
    TEST_ASSERT_TRUE(LIDET_SUCCEEDED(lidet_cluster_run(&g_cluster.ws, &wimg, g_gnd_f, g_planes_f, ns)));
    agreement(NULL, lidet_cluster_labels(&g_cluster.ws), NULL, g_lab_f, npix, &stage_g, &stage_c);
    /* the noise floor: the float stages with the next seed */
    cfg_seed.ground.seed = cfg->ground.seed + 1u;
    chain(&img, &cfg_seed);
    memcpy(g_gnd_seed, lidet_ground_mask(&g_ground.ws), npix);
    memcpy(g_lab_seed, lidet_cluster_labels(&g_cluster.ws), npix * sizeof(uint16_t));
    agreement(g_gnd_seed, g_lab_seed, g_gnd_f, g_lab_f, npix, &noise_g, &noise_c);
    printf("%s: 4 mm workspace vs float stages, %% of %u pixels: ground labels %.3f "
           "(float, next seed: %.3f), cluster ids %.3f (next seed: %.3f), clustering alone %.3f\n",
           rel, (unsigned)g_proj.ws.state.stats.n_pixels_filled, agree_g, noise_g, agree_c, noise_c, stage_c);
    (void)stage_g;
    TEST_ASSERT_TRUE_MESSAGE(stage_c >= MIN_CLUSTER_STAGE_PCT,
                             "clustering alone: agreement with the float stage");
    TEST_ASSERT_TRUE_MESSAGE(agree_g >= MIN_GROUND_PCT && agree_g >= noise_g - SEED_MARGIN_PCT,
                             "ground labels: agreement with the float stages");
    TEST_ASSERT_TRUE_MESSAGE(agree_c >= MIN_CLUSTER_PCT && agree_c >= noise_c - SEED_MARGIN_PCT,
                             "cluster ids: agreement with the float stages");
}

/* run the workspace and the standalone stages on one scan: every output equals the stages chained on
 * the compact image made by hand, and agrees with the float stages within the tolerances (the float
 * stages are the reference; the workspace differs from them by the 4 mm rounding only) */
static void compare_on(const char *rel, const char *sensor_name)
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

    TEST_ASSERT_NOT_NULL(s);
    n = load_scan(rel);
    if (n > LIDET_MAX_POINTS)
        n = LIDET_MAX_POINTS;
    CANARY_FILL(g_ws);
    CANARY_FILL(g_proj);
    CANARY_FILL(g_ground);
    CANARY_FILL(g_cluster);
    lidet_workspace_cfg_default(&cfg, s);
    if (g_tweak != NULL)
    {
        g_tweak(&cfg);
    }
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_workspace_init(&g_ws.ws, &cfg));

    /* the workspace, first without per-point outputs, then with them: the same results */
    st_ws = lidet_workspace_run(&g_ws.ws, g_points, n, 4, NULL, NULL);
    TEST_ASSERT_TRUE(LIDET_SUCCEEDED(st_ws));
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_ARG, lidet_workspace_point_labels(&g_ws.ws, NULL, 5, g_ids_ws, NULL));
    memset(g_pp, 0x55, sizeof g_pp);
    TEST_ASSERT_EQUAL_INT(st_ws, lidet_workspace_run(&g_ws.ws, g_points, n, 4, NULL, g_pp));
    CANARY_CHECK(g_ws);
    lidet_workspace_image(&g_ws.ws, &wimg);
    TEST_ASSERT_NULL(wimg.point_idx);
    TEST_ASSERT_NULL(wimg.x_m);
    npix = (uint32_t)wimg.n_rows * wimg.n_cols;
    /* R is the ground stage's scratch: the image of the last run has none (its plane holds the clustering's edges on
     * x86-64 hosts with AVX-512) */
    TEST_ASSERT_NULL(wimg.rxy_m);
#if LIDET_WORKSPACE_KEEP_R
    if (g_check_r)
    {
        /* a run whose clustering writes no edge plane (the regrowth's cut): R as the projection kept it, exactly the
         * ground stage's own expression on the decoded 4 mm values (so the stages chained by hand below, on a
         * compact image without R, must give the same bits) */
        uint32_t p;
        for (p = 0; p < npix; ++p)
        {
            const float x = (float)wimg.x_4mm[p] * LIDET_PIXEL_M, y = (float)wimg.y_4mm[p] * LIDET_PIXEL_M;
            const float r = sqrtf(x * x + y * y);
            TEST_ASSERT_EQUAL_MEMORY(&r, &g_ws.ws.r.rxy_m[p], sizeof r);
        }
    }
#endif

    /* 1. the float stages (the reference): agreement within the tolerances */
    if (g_tweak == NULL)
    {
        against_float(rel, &cfg, n);
    }

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

static void test_workspace_matches_stages_vlp16(void)
{
    compare_on("tests/data/sim_vlp16/velodyne/000000.bin", "vlp16");
}

static void test_workspace_matches_stages_hdl64(void)
{
    compare_on("tests/data/sim_hdl64/velodyne/000000.bin", "hdl64");
}

/* real HDL-64 scans of ../shared/data/real, when present (not shipped: KITTI licence) */
static void test_workspace_real_scans(void)
{
    static const char *const scans[] = {"../shared/data/real/semantickitti/velodyne/00_000000.bin",
                                        "../shared/data/real/semantickitti/velodyne/00_000001.bin",
                                        "../shared/data/real/semantickitti/velodyne/00_000002.bin",
                                        "../shared/data/real/semantickitti/velodyne/00_000003.bin",
                                        "../shared/data/real/semantickitti/velodyne/00_000004.bin",
                                        "../shared/data/real/semantickitti/velodyne/00_000005.bin",
                                        "../shared/data/real/kitti/training/velodyne/000000.bin",
                                        "../shared/data/real/kitti/training/velodyne/000001.bin",
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
        compare_on(scans[i], "hdl64");
        ++ran;
    }
    if (ran == 0u)
        TEST_IGNORE_MESSAGE("../shared/data/real not present");
}

/* The workspace's flood fill decides its searches beforehand in an edge plane on x86-64 hosts with AVX-512
 * (lidet_cluster_grow.c, lidet__cluster_edges); the standalone stage chained by hand in compare_on has no plane
 * and runs the searches as it goes. Both must give the same clusters, members, labels and counts bit for bit, on
 * the defaults (the tests above) and where the plane's rules change: the bridging budget spent mid-fill (the
 * pixels after it expanded without the occluder rule), the occluder rule off (a search ends at its first
 * candidate), no diagonals, no gap bound, max_steps 7 (the plane's limit) and 8 (no plane), the regrowth's cut
 * (no plane) */
static void tweak_budget(lidet_workspace_cfg_t *cfg)
{
    cfg->cluster.max_bridge_per_pixel = 0.05f;
}
static void tweak_no_occluders(lidet_workspace_cfg_t *cfg)
{
    cfg->cluster.bridge_occluders = 0u;
}
static void tweak_no_diagonals(lidet_workspace_cfg_t *cfg)
{
    cfg->cluster.diagonals = 0u;
    cfg->cluster.max_gap_m = 0.0f;
}
static void tweak_steps7(lidet_workspace_cfg_t *cfg)
{
    cfg->cluster.max_steps = 7u;
}
static void tweak_steps8(lidet_workspace_cfg_t *cfg)
{
    cfg->cluster.max_steps = 8u;
}
static void tweak_cut(lidet_workspace_cfg_t *cfg)
{
    cfg->cluster.regrow_cut_m = 0.3f;
}

static void test_workspace_edge_plane(void)
{
    static void (*const tweaks[])(lidet_workspace_cfg_t *) = {tweak_budget,      tweak_no_occluders,
                                                               tweak_no_diagonals, tweak_steps7,
                                                               tweak_steps8,       tweak_cut};
    uint32_t i;
#if LIDET_WORKSPACE_KEEP_R
    uint32_t p, written = 0;
    g_tweak = NULL;
    compare_on("tests/data/sim_hdl64/velodyne/000000.bin", "hdl64");
    for (p = 0; p < (uint32_t)LIDET_MAX_ROWS * LIDET_MAX_COLS; ++p)
    {
        written += g_ws.ws.r.edges[p] >> 31; /* a word written for a candidate */
    }
    printf("edge plane: %u words written on the simulated HDL-64 scan (0: this CPU or build does not use it)\n",
           (unsigned)written);
#if LIDET_HOST_SIMD && defined(__GNUC__) && defined(__x86_64__)
    if (__builtin_cpu_supports("avx512f"))
    {
        TEST_ASSERT_TRUE(written > 10000u);
    }
#endif
#endif
    for (i = 0; i < sizeof tweaks / sizeof tweaks[0]; ++i)
    {
        g_tweak = tweaks[i];
        g_check_r = tweaks[i] == tweak_cut;
        compare_on("tests/data/sim_hdl64/velodyne/000000.bin", "hdl64");
        compare_on("tests/data/sim_vlp16/velodyne/000000.bin", "vlp16");
    }
    g_tweak = NULL;
    g_check_r = 0;
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
    /* a ground window needs a projection window within it: none, or a wider one, is refused */
    cfg.ground.azimuth_half_rad = 1.0f;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_workspace_init(&g_ws.ws, &cfg));
    cfg.proj.azimuth_half_rad = 1.2f;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_workspace_init(&g_ws.ws, &cfg));
    cfg.proj.azimuth_half_rad = 1.0f;
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_workspace_init(&g_ws.ws, &cfg));
    cfg.ground.azimuth_half_rad = 0.0f;
    cfg.proj.azimuth_half_rad = 0.0f;
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_workspace_init(&g_ws.ws, &cfg));
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_STATE, lidet_workspace_proposal(&g_ws.ws, 0, &pcfg, p));
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_STATE, lidet_workspace_point_labels(&g_ws.ws, g_pp, 0, NULL, NULL));
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_ARG, lidet_workspace_run(&g_ws.ws, g_points, 10, 2, NULL, NULL));
    /* an empty scan runs through every stage */
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_workspace_run(&g_ws.ws, NULL, 0, 4, NULL, NULL));
    TEST_ASSERT_NOT_NULL(lidet_workspace_clusters(&g_ws.ws, &pcfg.n_points));
    TEST_ASSERT_EQUAL_UINT32(0, pcfg.n_points);
}

/* The compact image spans +-131 m: farther points are dropped by the projection and counted as too far,
 * never wrapped into int16; points within it keep their coordinates to 2 mm (half a step) */
static void test_workspace_compact_span(void)
{
    static const float far_pts[][4] = {{130.9f, 0.0f, 0.0f, 0.0f},   /* kept: 32725 steps */
                                       {0.0f, -130.0f, -1.0f, 0.0f}, /* kept */
                                       {131.5f, 0.0f, 0.0f, 0.0f},   /* beyond 131 m: dropped */
                                       {-200.0f, 10.0f, 0.0f, 0.0f}, /* dropped (would wrap int16) */
                                       {0.0f, 0.0f, 0.05f, 0.0f}};   /* too close */
    lidet_workspace_cfg_t cfg;
    lidet_workspace_stats_t st;
    lidet_range_image_t wimg;
    uint32_t p, npix, n_valid = 0;
    lidet_workspace_cfg_default(&cfg, lidet_sensor_find("vlp16"));
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_workspace_init(&g_ws.ws, &cfg));
    TEST_ASSERT_TRUE(LIDET_SUCCEEDED(lidet_workspace_run(&g_ws.ws, &far_pts[0][0], 5, 4, NULL, NULL)));
    lidet_workspace_stats(&g_ws.ws, &st);
    TEST_ASSERT_EQUAL_UINT32(2u, st.proj.n_too_far);
    TEST_ASSERT_EQUAL_UINT32(1u, st.proj.n_too_close);
    TEST_ASSERT_EQUAL_UINT32(2u, st.proj.n_pixels_filled);
    lidet_workspace_image(&g_ws.ws, &wimg);
    npix = (uint32_t)wimg.n_rows * wimg.n_cols;
    for (p = 0; p < npix; ++p)
    {
        if (wimg.range_4mm[p] == 0u)
        {
            TEST_ASSERT_TRUE(wimg.x_4mm[p] == 0 && wimg.y_4mm[p] == 0 && wimg.z_4mm[p] == 0);
            continue;
        }
        ++n_valid;
        if (wimg.x_4mm[p] > 0)
        {
            TEST_ASSERT_EQUAL_INT16(32725, wimg.x_4mm[p]); /* 130.9 m */
            TEST_ASSERT_EQUAL_UINT16(32725, wimg.range_4mm[p]);
        }
        else
        {
            TEST_ASSERT_EQUAL_INT16(-32500, wimg.y_4mm[p]);
            TEST_ASSERT_EQUAL_INT16(-250, wimg.z_4mm[p]);
            TEST_ASSERT_EQUAL_UINT16(32501, wimg.range_4mm[p]); /* 130.0038 m */
        }
    }
    TEST_ASSERT_EQUAL_UINT32(2u, n_valid);
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
    /* int16 x, y, z, range, and float R when kept */
    TEST_ASSERT_EQUAL_UINT32((8u + 4u * LIDET_WORKSPACE_KEEP_R) * LIDET_MAX_ROWS * LIDET_MAX_COLS, s.image);
    TEST_ASSERT_EQUAL_UINT32(LIDET_MAX_ROWS * LIDET_MAX_COLS, s.ground_mask);
    TEST_ASSERT_EQUAL_UINT32(4u * LIDET_MAX_ROWS * LIDET_MAX_COLS, s.overlay_proj);
    TEST_ASSERT_EQUAL_UINT32(6u * LIDET_MAX_ROWS * LIDET_MAX_COLS, s.overlay_cluster);
    TEST_ASSERT_EQUAL_UINT32(lidet_ground_scratch_bytes(),
                             s.overlay_ground); /* R is not stored: two rows of it */
    /* the overlay is the peak of its parts, not the sum */
    big = s.overlay_proj > s.overlay_ground ? s.overlay_proj : s.overlay_ground;
    big = big > s.overlay_cluster ? big : s.overlay_cluster;
    TEST_ASSERT_TRUE(s.overlay >= big && s.overlay < big + 16u);
    TEST_ASSERT_TRUE(s.total >= s.proj_state + s.ground_state + s.cluster_state + s.image + s.ground_mask +
                                    s.alias_gap + s.overlay);
    TEST_ASSERT_TRUE(s.total < s.proj_state + s.ground_state + s.cluster_state + s.image + s.ground_mask +
                                   s.alias_gap + s.overlay + 64u);
#if defined(__x86_64__)
    {
        /* the gap puts a pixel's label 2 KiB + 64 B (+ alignment) from its range, modulo 4 KiB */
        const size_t d = (size_t)((const uint8_t *)&g_ws.ws.overlay.cluster.labels[0] -
                                  (const uint8_t *)&g_ws.ws.range_4mm[0]);
        TEST_ASSERT_TRUE(s.alias_gap >= 64u && s.alias_gap < 4096u + 64u);
        TEST_ASSERT_TRUE(d % 4096u >= 2048u && d % 4096u < 2048u + 64u + 16u);
    }
#else
    TEST_ASSERT_EQUAL_UINT32(0u, s.alias_gap);
#endif
    TEST_ASSERT_EQUAL_UINT32(lidet_proj_bytes() + lidet_ground_bytes() + lidet_cluster_bytes(),
                             s.stages_standalone);
    TEST_ASSERT_TRUE(s.total < s.stages_standalone);
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_workspace_sizes);
    RUN_TEST(test_workspace_errors);
    RUN_TEST(test_workspace_compact_span);
    RUN_TEST(test_workspace_matches_stages_vlp16);
    RUN_TEST(test_workspace_matches_stages_hdl64);
    RUN_TEST(test_workspace_real_scans);
    RUN_TEST(test_workspace_edge_plane);
    return UNITY_END();
}
