/* SPDX-License-Identifier: MIT */
/* The proposal refinement (lib/src/cluster/lidet_refine.c, cfg split_people) on hand-made scenes: a small
 * ray-cast range image (32 beams 0.5 deg apart from +2 deg, 2048 columns, sensor 1.73 m above a flat
 * ground that returns nothing) of upright cylinders (people) and boxes (cars). */
#include <math.h>
#include <string.h>

#include "lidet/lidet.h"
#include "test_refine_scene.h"
#include "unity.h"

static lidet_cluster_t g_cl;

/* the defaults, but joining generously (a small angle, 16 steps of hole bridging: 0.5 m at 10 m), so
 * that close objects come out of the depth clustering as one cluster, as they do on real streets */
static uint32_t run_with(const lidet_cluster_cfg_t *cfg)
{
    uint32_t n = 0;
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_cluster_init(&g_cl, cfg));
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_cluster_run(&g_cl, &g_img, NULL, NULL, 0));
    (void)lidet_cluster_records(&g_cl, &n);
    return n;
}

static uint32_t run(int split)
{
    lidet_cluster_cfg_t cfg;
    lidet_cluster_cfg_default(&cfg, NULL);
    cfg.theta_rad = 0.02f;
    cfg.max_steps = 16u;
    cfg.split_people = (uint32_t)split;
    return run_with(&cfg);
}

/* the records match a recount of the labels (counts, bounds, seed in raster order) */
static void assert_records_consistent(void)
{
    uint32_t n = 0, k;
    const lidet_cluster_rec_t *rec = lidet_cluster_records(&g_cl, &n);
    const uint16_t *lab = lidet_cluster_labels(&g_cl);
    const int32_t *mem = lidet_cluster_members(&g_cl);
    for (k = 0; k < n; ++k)
    {
        uint32_t cnt = 0, first = NPIX, i;
        int p;
        for (p = 0; p < NPIX; ++p)
        {
            if (lab[p] == k + 1u)
            {
                ++cnt;
                first = (uint32_t)p < first ? (uint32_t)p : first;
                TEST_ASSERT_TRUE(g_x[p] >= rec[k].min_m[0] && g_x[p] <= rec[k].max_m[0]);
                TEST_ASSERT_TRUE(g_y[p] >= rec[k].min_m[1] && g_y[p] <= rec[k].max_m[1]);
            }
        }
        TEST_ASSERT_EQUAL_UINT32(cnt, rec[k].n_points);
        TEST_ASSERT_EQUAL_UINT32(first, rec[k].seed_pixel);
        for (i = 0; i < rec[k].n_points; ++i)
        {
            TEST_ASSERT_EQUAL_UINT32(k + 1u, lab[mem[rec[k].first_member + i]]);
        }
        if (k > 0)
        {
            TEST_ASSERT_TRUE(rec[k - 1].seed_pixel < rec[k].seed_pixel); /* canonical order */
        }
    }
}

void setUp(void)
{
}

void tearDown(void)
{
}

/* two adults (body radius 0.22 m, 1.75 m tall) 0.4 m apart, 10 m ahead */
static void test_two_people_0_4m_apart(void)
{
    const obj_t s[2] = {{0, 10.0, -0.42, 0.22, 0.0, -1.73, 0.02}, {0, 10.0, 0.42, 0.22, 0.0, -1.73, 0.02}};
    render(s, 2, 0);
    TEST_ASSERT_EQUAL_UINT32(1, run(0)); /* the depth clustering merges them */
    TEST_ASSERT_EQUAL_UINT32(2, run(1));
    scene_one_to_one(lidet_cluster_labels(&g_cl), 2);
    assert_records_consistent();
    TEST_ASSERT_EQUAL_UINT32(1, lidet_cluster_stats(&g_cl)->n_split);
    TEST_ASSERT_EQUAL_UINT32(1, lidet_cluster_stats(&g_cl)->n_split_parts);
}

/* a person 0.25 m from a car's side (the car 4.4 x 1.8 x 1.4 m, 8-12.4 m ahead, the person between the
 * sensor and the car's flank); a person touching the car (closer than one 0.12 m cell) is not cut */
static void test_person_beside_car(void)
{
    const obj_t s[2] = {{1, 8.0, 1.0, 12.4, 2.8, -1.60, -0.25}, {0, 10.0, 0.53, 0.22, 0.0, -1.73, 0.02}};
    render(s, 2, 0);
    TEST_ASSERT_EQUAL_UINT32(1, run(0));
    TEST_ASSERT_EQUAL_UINT32(2, run(1));
    scene_one_to_one(lidet_cluster_labels(&g_cl), 2);
    assert_records_consistent();
}

/* a group of three 0.3-0.5 m apart and a child (1.2 m) 0.3 m from an adult */
static void test_group_with_child(void)
{
    const obj_t s[4] = {{0, 12.0, -0.9, 0.22, 0.0, -1.73, 0.02},
                        {0, 12.0, -0.1, 0.22, 0.0, -1.73, 0.05},
                        {0, 12.2, 0.64, 0.22, 0.0, -1.73, 0.0},
                        {0, 12.0, 1.3, 0.16, 0.0, -1.73, -0.53}};
    render(s, 4, 0);
    TEST_ASSERT_TRUE(run(0) < 4);
    TEST_ASSERT_EQUAL_UINT32(4, run(1));
    scene_one_to_one(lidet_cluster_labels(&g_cl), 4);
    assert_records_consistent();
}

/* a car (4.4 x 1.8 x 1.5 m, 8 m ahead and 1 m to the left: its rear and its right flank seen) with two
 * bands of five beams lost (car_bands: dark paint, glass): the depth clustering (defaults) gives three
 * pieces, one above the other; the refinement joins them into one and cuts nothing */

static uint32_t run_defaults(int split, int join)
{
    lidet_cluster_cfg_t cfg;
    lidet_cluster_cfg_default(&cfg, NULL);
    cfg.split_people = (uint32_t)split;
    cfg.join_cars = (uint32_t)join;
    return run_with(&cfg);
}

static void test_car_in_three_pieces_joined(void)
{
    const obj_t s[1] = {{1, 8.0, 1.0, 12.4, 2.8, -1.70, -0.20}};
    render(s, 1, car_bands);
    TEST_ASSERT_EQUAL_UINT32(3, run_defaults(1, 0));
    TEST_ASSERT_EQUAL_UINT32(1, run_defaults(1, 1));
    TEST_ASSERT_EQUAL_UINT32(2, lidet_cluster_stats(&g_cl)->n_joined);
    TEST_ASSERT_EQUAL_UINT32(0, lidet_cluster_stats(&g_cl)->n_split);
    scene_one_to_one(lidet_cluster_labels(&g_cl), 1);
    assert_records_consistent();
}

/* the join budget: with max_join_pieces 2 only the first two pieces (slot order) take part, the third joins
 * nothing and is counted; 0 lifts the budget; validation of the field is not needed (any value is valid) */
static void test_join_budget(void)
{
    const obj_t s[1] = {{1, 8.0, 1.0, 12.4, 2.8, -1.70, -0.20}};
    lidet_cluster_cfg_t cfg;
    render(s, 1, car_bands);
    lidet_cluster_cfg_default(&cfg, NULL);
    TEST_ASSERT_EQUAL_UINT32(256u, cfg.max_join_pieces);
    cfg.max_join_pieces = 2u;
    TEST_ASSERT_EQUAL_UINT32(2, run_with(&cfg));
    TEST_ASSERT_EQUAL_UINT32(1, lidet_cluster_stats(&g_cl)->n_joined);
    TEST_ASSERT_EQUAL_UINT32(1, lidet_cluster_stats(&g_cl)->n_join_skipped);
    assert_records_consistent();
    cfg.max_join_pieces = 1u;
    TEST_ASSERT_EQUAL_UINT32(3, run_with(&cfg));
    TEST_ASSERT_EQUAL_UINT32(0, lidet_cluster_stats(&g_cl)->n_joined);
    TEST_ASSERT_EQUAL_UINT32(2, lidet_cluster_stats(&g_cl)->n_join_skipped);
    cfg.max_join_pieces = 0u;
    TEST_ASSERT_EQUAL_UINT32(1, run_with(&cfg));
    TEST_ASSERT_EQUAL_UINT32(0, lidet_cluster_stats(&g_cl)->n_join_skipped);
}

/* two cars nose to tail 1.2 m apart, the join gap widened to 1.5 m: their union is longer than a car,
 * so no cluster takes both; allowing a 12 m car joins them (the rule is what keeps them apart) */
static uint32_t run_join(float gap_m, float max_len_m)
{
    lidet_cluster_cfg_t cfg;
    lidet_cluster_cfg_default(&cfg, NULL);
    cfg.join_gap_m = gap_m;
    cfg.car_max_length_m = max_len_m;
    return run_with(&cfg);
}

static int cars_mixed(void)
{
    const uint16_t *lab = lidet_cluster_labels(&g_cl);
    uint32_t owner[64], p;
    memset(owner, 0, sizeof owner);
    for (p = 0; p < NPIX; ++p)
    {
        if (lab[p] == 0)
        {
            continue;
        }
        TEST_ASSERT_TRUE(lab[p] < 64u);
        if (owner[lab[p]] == 0)
        {
            owner[lab[p]] = g_obj[p];
        }
        if (owner[lab[p]] != g_obj[p])
        {
            return 1;
        }
    }
    return 0;
}

static void test_two_cars_not_joined(void)
{
    const obj_t s[2] = {{1, 8.0, 1.0, 12.4, 2.8, -1.70, -0.20}, {1, 13.6, 1.0, 18.0, 2.8, -1.70, -0.20}};
    render(s, 2, 0);
    TEST_ASSERT_TRUE(run_join(1.5f, 5.2f) >= 2u);
    TEST_ASSERT_FALSE(cars_mixed());
    (void)run_join(1.5f, 12.0f);
    TEST_ASSERT_TRUE(cars_mixed());
}

/* person_min_points: the two people of the test above, each below min_points (raised above their pixel
 * counts, their union still above it): with person_min_points = min_points nothing is cut (no part is big
 * enough to leave); with person_min_points at most a person's pixels one of them is cut off and kept as a
 * cluster of its own below min_points; one more than the smaller person's pixels cuts nothing again */
static void test_person_min_points(void)
{
    const obj_t s[2] = {{0, 10.0, -0.42, 0.22, 0.0, -1.73, 0.02}, {0, 10.0, 0.42, 0.22, 0.0, -1.73, 0.02}};
    lidet_cluster_cfg_t cfg;
    uint32_t n_a, n_b, n_small, i, n;
    const lidet_cluster_rec_t *r;
    render(s, 2, 0);
    TEST_ASSERT_EQUAL_UINT32(2, run(1));
    r = lidet_cluster_records(&g_cl, &n);
    n_a = r[0].n_points;
    n_b = r[1].n_points;
    n_small = n_a < n_b ? n_a : n_b;
    lidet_cluster_cfg_default(&cfg, NULL);
    cfg.theta_rad = 0.02f;
    cfg.max_steps = 16u;
    cfg.min_points = (n_a > n_b ? n_a : n_b) + 1u;
    TEST_ASSERT_TRUE(n_a + n_b >= cfg.min_points);
    cfg.person_min_points = cfg.min_points;
    TEST_ASSERT_EQUAL_UINT32(1, run_with(&cfg));
    TEST_ASSERT_EQUAL_UINT32(0, lidet_cluster_stats(&g_cl)->n_split);
    cfg.person_min_points = n_small;
    TEST_ASSERT_EQUAL_UINT32(2, run_with(&cfg));
    TEST_ASSERT_EQUAL_UINT32(1, lidet_cluster_stats(&g_cl)->n_split);
    scene_one_to_one(lidet_cluster_labels(&g_cl), 2);
    assert_records_consistent();
    r = lidet_cluster_records(&g_cl, &n);
    for (i = 0; i < n; ++i)
    {
        TEST_ASSERT_TRUE(r[i].n_points < cfg.min_points);
    }
    cfg.person_min_points = n_small + 1u; /* the larger one could leave, but it is the one that stays */
    TEST_ASSERT_EQUAL_UINT32(1, run_with(&cfg));
    cfg.person_min_points = 0u;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_cluster_init(&g_cl, &cfg));
    cfg.person_min_points = 1000001u;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_cluster_init(&g_cl, &cfg));
}

/* a car seen as two slices (issue 15, the VLP-16 defaults): the low body (8-10 m ahead, up to 0.7 m above the
 * ground) and, 0.65 m further and six empty beams higher, the cabin (10.65-12.4 m): no pixel path joins them
 * (more empty rows than max_steps), their boxes lie 0.65 m apart in x-y. The dense sensors' defaults (join gap
 * 0.5 m) keep two clusters; the 16-beam defaults (0.8 m) join them into one */
static uint32_t run_profile(const char *sensor)
{
    lidet_cluster_cfg_t cfg;
    lidet_cluster_cfg_default(&cfg, lidet_sensor_find(sensor));
    return run_with(&cfg);
}

static void test_car_slices_joined_16_beams(void)
{
    const obj_t s[2] = {{1, 8.0, 1.0, 10.0, 2.8, -1.70, -1.00}, {1, 10.65, 1.0, 12.4, 2.8, -0.50, 0.00}};
    render(s, 2, 0);
    TEST_ASSERT_EQUAL_UINT32(2, run_profile("hdl64"));
    TEST_ASSERT_EQUAL_UINT32(0, lidet_cluster_stats(&g_cl)->n_joined);
    TEST_ASSERT_EQUAL_UINT32(1, run_profile("vlp16"));
    TEST_ASSERT_EQUAL_UINT32(1, lidet_cluster_stats(&g_cl)->n_joined);
    assert_records_consistent();
}

/* one car alone is never cut */
static void test_car_alone_not_cut(void)
{
    const obj_t s[1] = {{1, 14.0, -3.0, 18.4, -1.2, -1.60, -0.25}};
    render(s, 1, 0);
    TEST_ASSERT_EQUAL_UINT32(1, run(1));
    TEST_ASSERT_EQUAL_UINT32(0, lidet_cluster_stats(&g_cl)->n_split);
}

/* a copy of cfg with one field set is refused by init */
#define REFUSED(field, value)                                                                                \
    do                                                                                                       \
    {                                                                                                        \
        lidet_cluster_cfg_t bad_ = cfg;                                                                      \
        bad_.field = (value);                                                                                \
        TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_cluster_init(&g_cl, &bad_));                           \
    } while (0)

/* the same input gives the same labels (deterministic), and bad refinement settings are refused */
static void test_deterministic_and_config(void)
{
    static uint16_t first[NPIX];
    const obj_t s[2] = {{0, 10.0, -0.42, 0.22, 0.0, -1.73, 0.02}, {0, 10.0, 0.42, 0.22, 0.0, -1.73, 0.02}};
    lidet_cluster_cfg_t cfg;
    render(s, 2, 0);
    (void)run(1);
    memcpy(first, lidet_cluster_labels(&g_cl), sizeof first);
    (void)run(1);
    TEST_ASSERT_EQUAL_MEMORY(first, lidet_cluster_labels(&g_cl), sizeof first);
    lidet_cluster_cfg_default(&cfg, NULL);
    TEST_ASSERT_EQUAL_UINT32(1, cfg.split_people);
    TEST_ASSERT_EQUAL_UINT32(1, cfg.join_cars);
    REFUSED(split_people, 2u);
    REFUSED(split_cell_m, 0.0f);
    REFUSED(person_min_aspect, -1.0f);
    REFUSED(join_cars, 3u);
    REFUSED(car_max_width_m, -1.0f);
    REFUSED(split_min_width_m, (float)NAN);
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_two_people_0_4m_apart);
    RUN_TEST(test_person_beside_car);
    RUN_TEST(test_group_with_child);
    RUN_TEST(test_car_in_three_pieces_joined);
    RUN_TEST(test_join_budget);
    RUN_TEST(test_two_cars_not_joined);
    RUN_TEST(test_car_slices_joined_16_beams);
    RUN_TEST(test_person_min_points);
    RUN_TEST(test_car_alone_not_cut);
    RUN_TEST(test_deterministic_and_config);
    return UNITY_END();
}
