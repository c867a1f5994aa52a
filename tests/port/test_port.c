/* SPDX-License-Identifier: MIT */
/* The port layer: a library built with tests/port/lidet_port.h uses the port's assert (it counts the
 * checks of a run) and lets the firmware place the workspace in a section of its choice. */
#include <stdio.h>
#include <string.h>

#include "lidet/lidet_workspace.h"
#include "test_util.h"

unsigned long lidet_port_test_checks;
unsigned long lidet_port_test_failures;

/* the firmware's declaration: the section comes from the port header, the library is not edited */
static lidet_workspace_t ws LIDET_WORKSPACE_SECTION LIDET_ALIGN(32);
extern char __start_lidet_ws[], __stop_lidet_ws[]; /* GNU ld: bounds of a section named like a C identifier */
static float g_points[40000 * 4];

void setUp(void)
{
}

void tearDown(void)
{
}

static void test_workspace_in_the_ports_section(void)
{
    const char *p = (const char *)&ws;
    TEST_ASSERT_TRUE(p >= __start_lidet_ws);
    TEST_ASSERT_TRUE(p + sizeof ws <= __stop_lidet_ws);
    TEST_ASSERT_EQUAL_UINT32(0, (uint32_t)((uintptr_t)p % 32u));
}

static void test_library_asserts_go_to_the_port(void)
{
    char path[512];
    lidet_workspace_cfg_t cfg;
    FILE *f;
    size_t n;
    uint32_t k = 0;
    snprintf(path, sizeof path, "%s/tests/data/sim_vlp16/velodyne/000000.bin", LIDET_SOURCE_DIR);
    f = fopen(path, "rb");
    TEST_ASSERT_NOT_NULL(f);
    n = fread(g_points, 4 * sizeof(float), 40000, f);
    fclose(f);
    lidet_workspace_cfg_default(&cfg, lidet_sensor_find("vlp16"));
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_workspace_init(&ws, &cfg));
    lidet_port_test_checks = 0;
    TEST_ASSERT_TRUE(LIDET_SUCCEEDED(lidet_workspace_run(&ws, g_points, (uint32_t)n, 4, NULL, NULL)));
    lidet_workspace_clusters(&ws, &k);
    TEST_ASSERT_TRUE(k > 0u);
    TEST_ASSERT_TRUE(lidet_port_test_checks > 1000u); /* one per projected point at least */
    TEST_ASSERT_EQUAL_UINT32(0, (uint32_t)lidet_port_test_failures);
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_workspace_in_the_ports_section);
    RUN_TEST(test_library_asserts_go_to_the_port);
    return UNITY_END();
}
