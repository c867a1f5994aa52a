/* SPDX-License-Identifier: MIT */
/* The integer stage's proposal refinement (lib/src/cluster/lidet_refine_q.c) on the hand-made scenes of
 * test_refine_scene.h turned into compact images (4 mm steps): two people 0.4 m apart are cut apart, a car in
 * three pieces is joined, a car alone is not cut; the records match a recount of the labels (the mean is the
 * rounded mean of the members, exactly); the refinement's settings are checked. */
#include <math.h>
#include <string.h>

#include "lidet/lidet.h"
#include "test_refine_scene.h"
#include "test_util.h"
#include "unity.h"

LIDET_GUARDED(lidet_cluster_q_t, g);
static int16_t cx[NPIX], cy[NPIX], cz[NPIX];
static uint16_t crng[NPIX];
static int32_t elev_bam[ROWS];
static lidet_range_image_t cimg;

void setUp(void)
{
    CANARY_FILL(g);
}

void tearDown(void)
{
    CANARY_CHECK(g);
}

static int16_t q4(float v)
{
    return (int16_t)floor((double)v / 0.004 + 0.5);
}

/* the rendered scene as a compact image */
static void compact(void)
{
    int p, r;
    for (p = 0; p < NPIX; ++p)
    {
        cx[p] = q4(g_x[p]);
        cy[p] = q4(g_y[p]);
        cz[p] = q4(g_z[p]);
        crng[p] = (uint16_t)q4(g_r[p]);
    }
    for (r = 0; r < ROWS; ++r)
    {
        elev_bam[r] = (int32_t)floor((double)g_elev[r] / (2.0 * PI_D) * 4294967296.0 + 0.5);
    }
    memset(&cimg, 0, sizeof cimg);
    cimg.n_rows = ROWS;
    cimg.n_cols = COLS;
    cimg.x_4mm = cx;
    cimg.y_4mm = cy;
    cimg.z_4mm = cz;
    cimg.range_4mm = crng;
    cimg.row_elev_bam = elev_bam;
}

static uint32_t run_with(const lidet_cluster_q_cfg_t *cfg)
{
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_cluster_q_init(&g.ws, cfg));
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_cluster_q_run(&g.ws, &cimg, NULL, NULL, 0));
    return g.ws.state.n_recs;
}

/* the defaults (no sensor: the dense-sensor values), the refinement switched as asked */
static void cfg_of(lidet_cluster_q_cfg_t *cfg, int split, int join)
{
    lidet_cluster_q_cfg_default(cfg, 0, 1730);
    cfg->split_people = (uint32_t)split;
    cfg->join_cars = (uint32_t)join;
}

/* joining generously (as test_refine.c: a small angle, 16 steps of hole bridging) */
static uint32_t run_generous(int split)
{
    lidet_cluster_q_cfg_t cfg;
    cfg_of(&cfg, split, 1);
    cfg.theta_urad = 20000;
    cfg.max_steps = 16;
    return run_with(&cfg);
}

/* the records match a recount of the labels: counts, seeds, bounds, the rounded mean, canonical order */
static void assert_records_consistent(void)
{
    const lidet_cluster_q_state_t *st = &g.ws.state;
    uint32_t k;
    for (k = 0; k < st->n_recs; ++k)
    {
        const lidet_cluster_q_rec_t *r = &st->recs[k];
        int64_t sum[3] = {0, 0, 0};
        int32_t lo[3] = {INT32_MAX, INT32_MAX, INT32_MAX}, hi[3] = {INT32_MIN, INT32_MIN, INT32_MIN};
        uint32_t cnt = 0, first = NPIX, i, a;
        int p;
        for (p = 0; p < NPIX; ++p)
        {
            const int32_t v[3] = {cx[p], cy[p], cz[p]};
            if (g.ws.labels[p] != k + 1u)
            {
                continue;
            }
            ++cnt;
            first = (uint32_t)p < first ? (uint32_t)p : first;
            for (a = 0; a < 3u; ++a)
            {
                sum[a] += v[a];
                lo[a] = v[a] < lo[a] ? v[a] : lo[a];
                hi[a] = v[a] > hi[a] ? v[a] : hi[a];
            }
        }
        TEST_ASSERT_EQUAL_UINT32(cnt, r->n_points);
        TEST_ASSERT_EQUAL_UINT32(first, r->seed_pixel);
        for (a = 0; a < 3u; ++a)
        {
            /* round half away from zero */
            const int64_t m = sum[a] >= 0 ? (sum[a] + (int64_t)cnt / 2) / (int64_t)cnt
                                          : -((-sum[a] + (int64_t)cnt / 2) / (int64_t)cnt);
            TEST_ASSERT_EQUAL_INT32((int32_t)m, r->mean_4mm[a]);
            TEST_ASSERT_EQUAL_INT32(lo[a], r->min_4mm[a]);
            TEST_ASSERT_EQUAL_INT32(hi[a], r->max_4mm[a]);
        }
        for (i = 0; i < r->n_points; ++i)
        {
            TEST_ASSERT_EQUAL_UINT32(k + 1u, g.ws.labels[g.ws.members[r->first_member + i]]);
        }
        if (k > 0)
        {
            TEST_ASSERT_TRUE(st->recs[k - 1].seed_pixel < r->seed_pixel);
        }
    }
}

static void test_two_people_0_4m_apart(void)
{
    const obj_t s[2] = {{0, 10.0, -0.42, 0.22, 0.0, -1.73, 0.02}, {0, 10.0, 0.42, 0.22, 0.0, -1.73, 0.02}};
    render(s, 2, 0);
    compact();
    TEST_ASSERT_EQUAL_UINT32(1, run_generous(0)); /* the depth clustering merges them */
    TEST_ASSERT_EQUAL_UINT32(0, g.ws.state.stats.n_split);
    TEST_ASSERT_EQUAL_UINT32(2, run_generous(1));
    scene_one_to_one(g.ws.labels, 2);
    assert_records_consistent();
    TEST_ASSERT_EQUAL_UINT32(1, g.ws.state.stats.n_split);
    TEST_ASSERT_EQUAL_UINT32(1, g.ws.state.stats.n_split_parts);
    TEST_ASSERT_EQUAL_UINT32(2, g.ws.state.stats.n_kept);
}

static void test_person_beside_car(void)
{
    const obj_t s[2] = {{1, 8.0, 1.0, 12.4, 2.8, -1.60, -0.25}, {0, 10.0, 0.53, 0.22, 0.0, -1.73, 0.02}};
    render(s, 2, 0);
    compact();
    TEST_ASSERT_EQUAL_UINT32(1, run_generous(0));
    TEST_ASSERT_EQUAL_UINT32(2, run_generous(1));
    scene_one_to_one(g.ws.labels, 2);
    assert_records_consistent();
}

static void test_car_in_three_pieces_joined(void)
{
    const obj_t s[1] = {{1, 8.0, 1.0, 12.4, 2.8, -1.70, -0.20}};
    lidet_cluster_q_cfg_t cfg;
    render(s, 1, car_bands);
    compact();
    cfg_of(&cfg, 1, 0);
    TEST_ASSERT_EQUAL_UINT32(3, run_with(&cfg));
    cfg_of(&cfg, 1, 1);
    TEST_ASSERT_EQUAL_UINT32(1, run_with(&cfg));
    TEST_ASSERT_EQUAL_UINT32(2, g.ws.state.stats.n_joined);
    TEST_ASSERT_EQUAL_UINT32(0, g.ws.state.stats.n_split);
    TEST_ASSERT_EQUAL_UINT32(1, g.ws.state.stats.n_kept);
    scene_one_to_one(g.ws.labels, 1);
    assert_records_consistent();
    /* the rule is what joins them: a union that must be longer than any car joins nothing */
    cfg.car_min_length_mm = 6000;
    TEST_ASSERT_EQUAL_UINT32(3, run_with(&cfg));
    TEST_ASSERT_EQUAL_UINT32(0, g.ws.state.stats.n_joined);
}

static void test_car_alone_not_cut(void)
{
    const obj_t s[1] = {{1, 14.0, -3.0, 18.4, -1.2, -1.60, -0.25}};
    render(s, 1, 0);
    compact();
    TEST_ASSERT_EQUAL_UINT32(1, run_generous(1));
    TEST_ASSERT_EQUAL_UINT32(0, g.ws.state.stats.n_split);
}

/* the car seen as two slices of test_refine.c (0.65 m apart in x-y, six empty beams between them): the dense
 * sensors' defaults keep two clusters, the 16-beam defaults (join gap 800 mm) join them */
static uint32_t run_rows(uint32_t n_rows)
{
    lidet_cluster_q_cfg_t cfg;
    lidet_cluster_q_cfg_default(&cfg, n_rows, 1730);
    return run_with(&cfg);
}

static void test_car_slices_joined_16_beams(void)
{
    const obj_t s[2] = {{1, 8.0, 1.0, 10.0, 2.8, -1.70, -1.00}, {1, 10.65, 1.0, 12.4, 2.8, -0.50, 0.00}};
    render(s, 2, 0);
    compact();
    TEST_ASSERT_EQUAL_UINT32(2, run_rows(64));
    TEST_ASSERT_EQUAL_UINT32(0, g.ws.state.stats.n_joined);
    TEST_ASSERT_EQUAL_UINT32(1, run_rows(16));
    TEST_ASSERT_EQUAL_UINT32(1, g.ws.state.stats.n_joined);
    assert_records_consistent();
}

/* person_min_points (test_refine.c's test): the two people each below min_points are cut apart only when a
 * part of person_min_points pixels may leave */
static void test_person_min_points(void)
{
    const obj_t s[2] = {{0, 10.0, -0.42, 0.22, 0.0, -1.73, 0.02}, {0, 10.0, 0.42, 0.22, 0.0, -1.73, 0.02}};
    lidet_cluster_q_cfg_t cfg;
    uint32_t n_a, n_b, n_small;
    render(s, 2, 0);
    compact();
    TEST_ASSERT_EQUAL_UINT32(2, run_generous(1));
    n_a = g.ws.state.recs[0].n_points;
    n_b = g.ws.state.recs[1].n_points;
    n_small = n_a < n_b ? n_a : n_b;
    cfg_of(&cfg, 1, 1);
    cfg.theta_urad = 20000;
    cfg.max_steps = 16;
    cfg.min_points = (n_a > n_b ? n_a : n_b) + 1u;
    cfg.person_min_points = cfg.min_points;
    TEST_ASSERT_EQUAL_UINT32(1, run_with(&cfg));
    TEST_ASSERT_EQUAL_UINT32(0, g.ws.state.stats.n_split);
    cfg.person_min_points = n_small;
    TEST_ASSERT_EQUAL_UINT32(2, run_with(&cfg));
    TEST_ASSERT_EQUAL_UINT32(1, g.ws.state.stats.n_split);
    scene_one_to_one(g.ws.labels, 2);
    assert_records_consistent();
    TEST_ASSERT_TRUE(g.ws.state.recs[0].n_points < cfg.min_points && g.ws.state.recs[1].n_points < cfg.min_points);
    cfg.person_min_points = n_small + 1u;
    TEST_ASSERT_EQUAL_UINT32(1, run_with(&cfg));
    cfg.person_min_points = 0u;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_cluster_q_init(&g.ws, &cfg));
    cfg.person_min_points = 1000001u;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_cluster_q_init(&g.ws, &cfg));
}

#define REFUSED(field, value)                                                                                \
    do                                                                                                       \
    {                                                                                                        \
        lidet_cluster_q_cfg_t bad_ = cfg;                                                                    \
        bad_.field = (value);                                                                                \
        TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_cluster_q_init(&g.ws, &bad_));                          \
    } while (0)

/* the defaults of a sensor kind (> 16 beams: 64 rows; <= 16: 16) are the float defaults rounded */
static void check_defaults(lidet_cluster_q_cfg_t *cfg, const char *sensor)
{
    const lidet_sensor_t *s = lidet_sensor_find(sensor);
    lidet_cluster_cfg_t f;
    TEST_ASSERT_NOT_NULL(s);
    lidet_cluster_q_cfg_default(cfg, s->n_rows, 1730);
    lidet_cluster_cfg_default(&f, s);
    TEST_ASSERT_EQUAL_UINT32(f.split_people, cfg->split_people);
    TEST_ASSERT_EQUAL_UINT32(f.join_cars, cfg->join_cars);
    TEST_ASSERT_EQUAL_UINT32(f.person_min_cols, cfg->person_min_cols);
    TEST_ASSERT_EQUAL_UINT32(f.max_fragment_pixels, cfg->max_fragment_pixels);
    TEST_ASSERT_EQUAL_UINT32(f.min_points, cfg->min_points);
    TEST_ASSERT_EQUAL_UINT32(f.max_steps, cfg->max_steps);
    TEST_ASSERT_EQUAL_UINT32(f.person_min_points, cfg->person_min_points);
    TEST_ASSERT_EQUAL_UINT32((uint32_t)lround(f.split_cell_m * 1000.0f), cfg->split_cell_mm);
    TEST_ASSERT_EQUAL_UINT32((uint32_t)lround(f.car_max_length_m * 1000.0f), cfg->car_max_length_mm);
    TEST_ASSERT_EQUAL_UINT32((uint32_t)lround(f.rescue_gap_m * 1000.0f), cfg->rescue_gap_mm);
    TEST_ASSERT_EQUAL_UINT32((uint32_t)lround(f.split_min_width_m * 1000.0f), cfg->split_min_width_mm);
    TEST_ASSERT_EQUAL_UINT32((uint32_t)lround(f.join_gap_m * 1000.0f), cfg->join_gap_mm);
    TEST_ASSERT_EQUAL_UINT32((uint32_t)lround(f.person_min_aspect * 65536.0f), cfg->person_min_aspect_q16);
    TEST_ASSERT_EQUAL_UINT32((uint32_t)lround(f.max_bridge_per_pixel * 65536.0f), cfg->max_bridge_per_pixel_q16);
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_cluster_q_init(&g.ws, cfg));
}

/* the defaults are the float defaults rounded (both kinds of sensor: issue 15's 16-beam values); bad settings
 * are refused */
static void test_defaults_and_config(void)
{
    lidet_cluster_q_cfg_t cfg;
    check_defaults(&cfg, "vlp16");
    TEST_ASSERT_EQUAL_UINT32(9u, cfg.person_min_points);
    check_defaults(&cfg, "hdl64");
    TEST_ASSERT_EQUAL_UINT32(10u, cfg.person_min_points);
    REFUSED(split_people, 2u);
    REFUSED(join_cars, 2u);
    REFUSED(split_cell_mm, 0u);
    REFUSED(split_cell_mm, 100001u);
    REFUSED(split_min_width_mm, 0u);
    REFUSED(split_cell_per_m_q16, 65537u);
    REFUSED(person_max_width_mm, 0u);
    REFUSED(person_min_aspect_q16, (100u << 16) + 1u);
    REFUSED(car_max_width_mm, 0u);
    REFUSED(car_max_length_mm, 1000001u);
    REFUSED(max_bridge_per_pixel_q16, (64u << 16) + 1u);
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_two_people_0_4m_apart);
    RUN_TEST(test_person_beside_car);
    RUN_TEST(test_car_in_three_pieces_joined);
    RUN_TEST(test_car_alone_not_cut);
    RUN_TEST(test_car_slices_joined_16_beams);
    RUN_TEST(test_person_min_points);
    RUN_TEST(test_defaults_and_config);
    return UNITY_END();
}
