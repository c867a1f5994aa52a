/* SPDX-License-Identifier: MIT */
/* Issue 18's memory goal, checked: the whole float detector (workspace, PointNet scratch, proposal,
 * detections) at the VLP-16 capacities (16 x 1800 pixels, 30,000 points, 64 clusters, 64 detections:
 * the capacities of lidet_port_probe, tests/CMakeLists.txt) fits 512 KiB. The check is at compile time
 * (a build that grows past it fails here) and again at run time; the workspace then runs on the shipped
 * VLP-16 scan at these capacities (2-byte ground samples, LIDET_DEBUG asserts on). */
#include <stdio.h>
#include <string.h>

#include "lidet/lidet.h"
#include "lidet/lidet_detector.h"
#include "lidet/lidet_detector_q.h"
#include "test_util.h"

#define BUDGET_BYTES (512u * 1024u)
#define BUDGET_Q_BYTES (256u * 1024u) /* issue 17/18: the integer build's RAM goal */

#if LIDET_MAX_ROWS != 16 || LIDET_MAX_COLS != 1800 || LIDET_MAX_POINTS != 30000 ||                       \
    LIDET_MAX_CLUSTERS != 64 || LIDET_MAX_DETECTIONS != 64
#error "test_vlp16_budget must be built with the VLP-16 capacities"
#endif
#if LIDET_Q_PIXEL_XYZ
#error "test_vlp16_budget checks the integer detector with the range-only pixel (LIDET_Q_PIXEL_XYZ 0)"
#endif

/* compile-time: a negative array size when the detector outgrows the budget (this host's layout, which is
 * at least the 32-bit target's: the structs hold pointers, no 64-bit member) */
typedef char lidet_vlp16_detector_fits_512_kib[sizeof(lidet_detector_t) <= BUDGET_BYTES ? 1 : -1];
/* the integer detector with the range-only pixel within 256 KiB (ports/firmware/config/vlp16: the integer
 * firmware's RAM is this less 8,160 B of int8 PointNet scratch its small models do not need, plus the tracker,
 * 8,264 B, ~1.3 KB of the application and 4 KiB of stack; docs/MEMORY.md) */
typedef char lidet_vlp16_detector_q_fits_256_kib[sizeof(lidet_detector_q_t) <= BUDGET_Q_BYTES ? 1 : -1];

/* the probe library's port (tests/port/lidet_port.h) counts its asserts here */
unsigned long lidet_port_test_checks;
unsigned long lidet_port_test_failures;

static lidet_workspace_t g_ws;
static float g_points[30000 * 4];

void setUp(void)
{
}

void tearDown(void)
{
}

static void test_detector_fits_512_kib(void)
{
    printf("VLP-16 capacities: detector %u B (workspace %u B), budget %u B\n",
           (unsigned)lidet_detector_bytes(), (unsigned)lidet_workspace_bytes(), BUDGET_BYTES);
    TEST_ASSERT_TRUE(lidet_detector_bytes() <= BUDGET_BYTES);
    TEST_ASSERT_EQUAL_UINT32(2u, sizeof(lidet_ground_sample_t));
}

static void test_integer_detector_fits_256_kib(void)
{
    lidet_detector_q_cfg_t cfg;
    printf("VLP-16 capacities: integer detector (range-only pixel) %u B, budget %u B\n",
           (unsigned)lidet_detector_q_bytes(), BUDGET_Q_BYTES);
    TEST_ASSERT_TRUE(lidet_detector_q_bytes() <= BUDGET_Q_BYTES);
    TEST_ASSERT_EQUAL_UINT32(2u, sizeof(lidet_member_t));
    /* the build's default is the range-only pixel */
    lidet_detector_q_cfg_default(&cfg, lidet_sensor_q_find("vlp16"));
    TEST_ASSERT_EQUAL_UINT8(1u, cfg.range_only);
}

static void test_workspace_runs_at_vlp16_capacities(void)
{
    char path[512];
    lidet_workspace_cfg_t cfg;
    lidet_workspace_stats_t st;
    uint32_t k;
    size_t n;
    FILE *f;
    snprintf(path, sizeof path, "%s/tests/data/sim_vlp16/velodyne/000000.bin", LIDET_SOURCE_DIR);
    f = fopen(path, "rb");
    TEST_ASSERT_NOT_NULL_MESSAGE(f, path);
    n = fread(g_points, 4 * sizeof(float), 30000, f);
    fclose(f);
    TEST_ASSERT_TRUE(n > 1000u);
    lidet_workspace_cfg_default(&cfg, lidet_sensor_find("vlp16"));
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_workspace_init(&g_ws, &cfg));
    TEST_ASSERT_TRUE(LIDET_SUCCEEDED(lidet_workspace_run(&g_ws, g_points, (uint32_t)n, 4, NULL, NULL)));
    lidet_workspace_stats(&g_ws, &st);
    TEST_ASSERT_TRUE(st.ground.n_samples > 100u);
    k = (uint32_t)st.ground.n_sectors_fitted + st.ground.n_sectors_neighbour + st.ground.n_sectors_mount;
    TEST_ASSERT_EQUAL_UINT32(cfg.ground.n_sectors, k);
    TEST_ASSERT_NOT_NULL(lidet_workspace_clusters(&g_ws, &k));
    TEST_ASSERT_TRUE(k > 3u);
    TEST_ASSERT_TRUE(lidet_port_test_checks > 0u);
    TEST_ASSERT_EQUAL_UINT32(0u, (uint32_t)lidet_port_test_failures);
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_detector_fits_512_kib);
    RUN_TEST(test_integer_detector_fits_256_kib);
    RUN_TEST(test_workspace_runs_at_vlp16_capacities);
    return UNITY_END();
}
