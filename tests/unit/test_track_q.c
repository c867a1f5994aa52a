/* SPDX-License-Identifier: MIT */
/* Unity tests of the integer tracker (lib/src/track/lidet_track_q.c, lidet_track_q.h): configuration and argument
 * checks, a constant-velocity object (stable id, converged velocity), crossing objects, misses and deaths,
 * confirmation, the heading flip, ego motion (a static object gets ~0 ground velocity), capacities and truncation,
 * bad detections, optimal vs greedy assignment, and extreme values (positions near 2^20 mm, dt 10 s, huge
 * velocities and configurations at their limits) with the covariance kept positive definite. Bit-exactness with
 * the numpy reference is tested in tests/python/test_track_q.py. */
#include <math.h>
#include <string.h>

#include "lidet/lidet.h"
#include "lidet/lidet_track_q.h"
#include "test_util.h"

LIDET_GUARDED(lidet_tracker_q_t, g);

/* the scenarios need 16 detections and 8 tracks: capacities below skip them (TEST_IGNORE) */
#define NEED_DETS 16
#define NEED_TRACKS 8
#define MAXD ((LIDET_TRACK_MAX_DETS > NEED_DETS ? LIDET_TRACK_MAX_DETS : NEED_DETS) + 8)
#define MAXT (LIDET_TRACK_MAX_TRACKS > NEED_TRACKS ? LIDET_TRACK_MAX_TRACKS : NEED_TRACKS)
#define NEED_CAPACITY()                                                                                      \
    do                                                                                                       \
    {                                                                                                        \
        if (LIDET_TRACK_MAX_DETS < NEED_DETS || LIDET_TRACK_MAX_TRACKS < NEED_TRACKS)                        \
        {                                                                                                    \
            TEST_IGNORE_MESSAGE("needs LIDET_TRACK_MAX_DETS >= 16 and LIDET_TRACK_MAX_TRACKS >= 8");         \
        }                                                                                                    \
    } while (0)
static lidet_detection_q_t det[MAXD];
static lidet_track_q_t out[MAXT];
static uint32_t lcg_state = 12345u;

/* deterministic noise in [-amp, amp] mm */
static int32_t noise(int32_t amp)
{
    lcg_state = lcg_state * 1664525u + 1013904223u;
    return (int32_t)((lcg_state >> 8) % (uint32_t)(2 * amp + 1)) - amp;
}

static int32_t rad_to_bam(double a)
{
    double b = fmod(a, 2.0 * M_PI);
    int64_t v;
    if (b < 0.0)
    {
        b += 2.0 * M_PI;
    }
    v = (int64_t)floor(b * 4294967296.0 / (2.0 * M_PI) + 0.5);
    v = ((v + 2147483648LL) & 0xFFFFFFFFLL) - 2147483648LL;
    return (int32_t)v;
}

static double bam_to_rad(int32_t b)
{
    return (double)b * 2.0 * M_PI / 4294967296.0;
}

static lidet_detection_q_t make_det(uint8_t cls, int32_t x, int32_t y, int32_t yaw_bam, int32_t score)
{
    lidet_detection_q_t d;
    static const int32_t size[LIDET_N_CLASSES][3] = {{4200, 1800, 1500}, {1800, 600, 1700}, {600, 600, 1700}};
    memset(&d, 0, sizeof d);
    d.cls = cls;
    d.box.cx_mm = x;
    d.box.cy_mm = y;
    d.box.cz_mm = -800;
    d.box.l_mm = size[cls][0];
    d.box.w_mm = size[cls][1];
    d.box.h_mm = size[cls][2];
    d.box.yaw_bam = yaw_bam;
    d.score_q15 = score;
    return d;
}

static void init_cfg(const lidet_tracker_q_cfg_t *cfg)
{
    CANARY_FILL(g);
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_tracker_q_init(&g.ws, cfg));
}

static void init_default(void)
{
    lidet_tracker_q_cfg_t cfg;
    lidet_tracker_q_cfg_default(&cfg);
    init_cfg(&cfg);
}

/* the track with this id among the n of out, or NULL */
static const lidet_track_q_t *find(uint32_t n, uint32_t id)
{
    uint32_t i;
    for (i = 0; i < n; ++i)
    {
        if (out[i].id == id)
        {
            return &out[i];
        }
    }
    return NULL;
}

/* every held track's covariance positive definite and bounded, its state in range */
static void check_invariants(void)
{
    uint32_t i, n = lidet_tracker_q_tracks(&g.ws, out, LIDET_TRACK_MAX_TRACKS,
                                           LIDET_TRACK_OUT_COASTING | LIDET_TRACK_OUT_TENTATIVE);
    TEST_ASSERT_EQUAL_UINT32(lidet_tracker_q_stats(&g.ws)->n_tracks, n);
    for (i = 0; i < n; ++i)
    {
        const lidet_track_q_t *k = &out[i];
        TEST_ASSERT_TRUE(k->p_pp >= 1 && k->p_vv >= 1);
        TEST_ASSERT_TRUE((int64_t)k->p_pv * k->p_pv < (int64_t)k->p_pp * k->p_vv);
        TEST_ASSERT_TRUE(k->vx_mmps >= -LIDET_TRACK_Q_VMAX_MMPS && k->vx_mmps <= LIDET_TRACK_Q_VMAX_MMPS);
        TEST_ASSERT_TRUE(k->vy_mmps >= -LIDET_TRACK_Q_VMAX_MMPS && k->vy_mmps <= LIDET_TRACK_Q_VMAX_MMPS);
        TEST_ASSERT_TRUE(k->box.cx_mm >= -LIDET_TRACK_Q_COORD_MAX_MM &&
                         k->box.cx_mm <= LIDET_TRACK_Q_COORD_MAX_MM);
        TEST_ASSERT_TRUE(k->box.cy_mm >= -LIDET_TRACK_Q_COORD_MAX_MM &&
                         k->box.cy_mm <= LIDET_TRACK_Q_COORD_MAX_MM);
        TEST_ASSERT_TRUE(k->cls < (uint8_t)LIDET_N_CLASSES && k->state <= (uint8_t)LIDET_TRACK_COASTING);
        TEST_ASSERT_TRUE(i == 0u || out[i - 1u].id < k->id); /* id order */
    }
    CANARY_CHECK(g);
}

void setUp(void)
{
}

void tearDown(void)
{
}

static void test_config_and_args(void)
{
    lidet_tracker_q_cfg_t cfg, bad;
    lidet_ego_q_t ego = {0, 0, 0};
    static lidet_tracker_q_t fresh; /* zeroed: not initialised */
    lidet_tracker_q_cfg_default(&cfg);
    TEST_ASSERT_EQUAL_INT32(603587, cfg.gate_chi2_q16);
    TEST_ASSERT_EQUAL_INT32(300, cfg.meas_sigma_mm[LIDET_CLASS_CAR]);
    TEST_ASSERT_EQUAL_UINT32(LIDET_TRACK_HEADING_FROM_VELOCITY_DEFAULT, cfg.heading_from_velocity);
    lidet_tracker_q_cfg_default(NULL);
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_ARG, lidet_tracker_q_init(NULL, &cfg));
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_ARG, lidet_tracker_q_init(&g.ws, NULL));
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_STATE, lidet_tracker_q_update(&fresh, NULL, 0, 100, NULL));
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_STATE, lidet_tracker_q_reset(&fresh));
    TEST_ASSERT_EQUAL_UINT32(0u, lidet_tracker_q_tracks(&fresh, out, 4, 3));
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_ARG, lidet_tracker_q_update(NULL, NULL, 0, 100, NULL));
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_ARG, lidet_tracker_q_reset(NULL));
    TEST_ASSERT_NULL(lidet_tracker_q_stats(NULL));
    /* each range, one past either end */
#define BAD_CFG(field, value)                                                                                \
    do                                                                                                       \
    {                                                                                                        \
        bad = cfg;                                                                                           \
        bad.field = (value);                                                                                 \
        TEST_ASSERT_EQUAL_INT_MESSAGE(LIDET_ERR_CONFIG, lidet_tracker_q_init(&g.ws, &bad), #field);          \
    } while (0)
    BAD_CFG(meas_sigma_mm[0], 0);
    BAD_CFG(meas_sigma_mm[2], 10001);
    BAD_CFG(accel_sigma_mmps2[1], -1);
    BAD_CFG(accel_sigma_mmps2[1], 100001);
    BAD_CFG(init_vel_sigma_mmps[0], -1);
    BAD_CFG(init_vel_sigma_mmps[0], 46341);
    BAD_CFG(gate_max_mm[2], 0);
    BAD_CFG(gate_max_mm[2], 1000001);
    BAD_CFG(gate_chi2_q16, 0);
    BAD_CFG(gate_chi2_q16, 1000 * 65536 + 1);
    BAD_CFG(class_penalty_q16, -1);
    BAD_CFG(class_penalty_q16, 1000 * 65536 + 1);
    BAD_CFG(assign, 2u);
    BAD_CFG(confirm_hits, 0u);
    BAD_CFG(confirm_hits, 1001u);
    BAD_CFG(max_misses, 1001u);
    BAD_CFG(birth_min_score_q15, -1);
    BAD_CFG(birth_min_score_q15, 32769);
    BAD_CFG(yaw_alpha_q15, 32769);
    BAD_CFG(size_alpha_q15, -1);
    BAD_CFG(heading_speed_mmps, LIDET_TRACK_Q_VMAX_MMPS + 1);
    BAD_CFG(heading_from_velocity, 8u);
#undef BAD_CFG
    /* a refused init leaves the tracker unusable */
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_STATE, lidet_tracker_q_update(&g.ws, NULL, 0, 100, NULL));
    /* the limits themselves are accepted */
    bad = cfg;
    bad.meas_sigma_mm[0] = 10000;
    bad.accel_sigma_mmps2[0] = 100000;
    bad.init_vel_sigma_mmps[0] = 46340;
    bad.gate_max_mm[0] = 1000000;
    bad.gate_chi2_q16 = 1000 * 65536;
    bad.class_penalty_q16 = 1000 * 65536;
    bad.confirm_hits = 1000u;
    bad.max_misses = 1000u;
    bad.heading_speed_mmps = LIDET_TRACK_Q_VMAX_MMPS;
    bad.heading_from_velocity = 7u;
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_tracker_q_init(&g.ws, &bad));

    /* arguments: nothing changes on LIDET_ERR_ARG */
    init_default();
    det[0] = make_det(LIDET_CLASS_CAR, 10000, 0, 0, 30000);
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_tracker_q_update(&g.ws, det, 1, 100, NULL));
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_ARG, lidet_tracker_q_update(&g.ws, det, 1, 0, NULL));
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_ARG,
                          lidet_tracker_q_update(&g.ws, det, 1, LIDET_TRACK_Q_DT_MAX_MS + 1u, NULL));
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_ARG, lidet_tracker_q_update(&g.ws, NULL, 1, 100, NULL));
    ego.dx_mm = LIDET_TRACK_Q_COORD_MAX_MM + 1;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_ARG, lidet_tracker_q_update(&g.ws, det, 1, 100, &ego));
    ego.dx_mm = 0;
    ego.dy_mm = -LIDET_TRACK_Q_COORD_MAX_MM - 1;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_ARG, lidet_tracker_q_update(&g.ws, det, 1, 100, &ego));
    TEST_ASSERT_EQUAL_UINT32(1u, lidet_tracker_q_tracks(&g.ws, out, 4, LIDET_TRACK_OUT_TENTATIVE));
    TEST_ASSERT_EQUAL_UINT32(0u, out[0].age);
    TEST_ASSERT_EQUAL_UINT32(0u, lidet_tracker_q_tracks(&g.ws, NULL, 4, 3));
    TEST_ASSERT_EQUAL_UINT32(0u, lidet_tracker_q_tracks(&g.ws, out, 0, 3));
    /* an empty scan with NULL detections is fine; the tentative track dies */
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_tracker_q_update(&g.ws, NULL, 0, LIDET_TRACK_Q_DT_MAX_MS, NULL));
    TEST_ASSERT_EQUAL_UINT32(1u, lidet_tracker_q_stats(&g.ws)->n_deaths);
    TEST_ASSERT_EQUAL_UINT32(0u, lidet_tracker_q_stats(&g.ws)->n_tracks);
    TEST_ASSERT_EQUAL_UINT32(sizeof(lidet_tracker_q_t), lidet_tracker_q_bytes());
    CANARY_CHECK(g);
}

static void test_constant_velocity(void)
{
    uint32_t k, n, id = 0;
    init_default();
    for (k = 0; k < 80u; ++k)
    {
        const double t = 0.1 * k;
        const lidet_track_q_t *tr;
        det[0] = make_det(LIDET_CLASS_CAR, (int32_t)(10000 + 6000 * t) + noise(20),
                          (int32_t)(2000 - 1500 * t) + noise(20), rad_to_bam(atan2(-1.5, 6.0)), 28000);
        TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_tracker_q_update(&g.ws, det, 1, 100, NULL));
        n = lidet_tracker_q_tracks(&g.ws, out, LIDET_TRACK_MAX_TRACKS, 0);
        if (k == 0u)
        {
            TEST_ASSERT_EQUAL_UINT32(0u, n); /* tentative: not given without the flag */
            continue;
        }
        TEST_ASSERT_EQUAL_UINT32(1u, n); /* confirmed at its second hit */
        tr = &out[0];
        if (k == 1u)
        {
            id = tr->id;
        }
        TEST_ASSERT_EQUAL_UINT32(id, tr->id);
        TEST_ASSERT_EQUAL_UINT8(LIDET_TRACK_CONFIRMED, tr->state);
        TEST_ASSERT_EQUAL_UINT32(k + 1u, tr->hits);
        TEST_ASSERT_EQUAL_UINT32(k, tr->age);
        TEST_ASSERT_EQUAL_INT32(0, tr->det_index);
    }
    /* converged: within 5 cm/s of (6, -1.5) m/s, 3 cm of the true centre */
    TEST_ASSERT_INT32_WITHIN(50, 6000, out[0].vx_mmps);
    TEST_ASSERT_INT32_WITHIN(50, -1500, out[0].vy_mmps);
    TEST_ASSERT_INT32_WITHIN(30, 10000 + 6000 * 79 / 10, out[0].box.cx_mm);
    TEST_ASSERT_INT32_WITHIN(30, 2000 - 1500 * 79 / 10, out[0].box.cy_mm);
    TEST_ASSERT_EQUAL_UINT32(1u, lidet_tracker_q_stats(&g.ws)->n_matched);
    /* a car's reported yaw: the box yaw, pointing along the motion */
    TEST_ASSERT_TRUE(fabs(bam_to_rad(out[0].box.yaw_bam) - atan2(-1.5, 6.0)) < 0.01);
    check_invariants();
}

static void test_crossing_objects_keep_ids(void)
{
    /* two pedestrians crossing diagonally, passing 0.25 m apart; ids follow the objects */
    uint32_t k, n, id_a = 0, id_b = 0;
    NEED_CAPACITY();
    init_default();
    for (k = 0; k < 60u; ++k)
    {
        const double t = 0.1 * k;
        const lidet_track_q_t *ta, *tb;
        det[0] = make_det(LIDET_CLASS_PEDESTRIAN, (int32_t)(8000 + 1000 * t) + noise(15),
                          (int32_t)(-3000 + 1000 * t) + noise(15), 0, 25000);
        det[1] = make_det(LIDET_CLASS_PEDESTRIAN, (int32_t)(8250 + 1000 * t) + noise(15),
                          (int32_t)(3000 - 1000 * t) + noise(15), 0, 25000);
        TEST_ASSERT_TRUE(LIDET_SUCCEEDED(lidet_tracker_q_update(&g.ws, det, 2, 100, NULL)));
        n = lidet_tracker_q_tracks(&g.ws, out, LIDET_TRACK_MAX_TRACKS, LIDET_TRACK_OUT_COASTING);
        if (k == 0u)
        {
            continue;
        }
        TEST_ASSERT_EQUAL_UINT32(2u, n);
        ta = out[0].det_index == 0 ? &out[0] : &out[1];
        tb = out[0].det_index == 0 ? &out[1] : &out[0];
        TEST_ASSERT_EQUAL_INT32(0, ta->det_index);
        TEST_ASSERT_EQUAL_INT32(1, tb->det_index);
        if (k == 1u)
        {
            id_a = ta->id;
            id_b = tb->id;
        }
        TEST_ASSERT_EQUAL_UINT32(id_a, ta->id);
        TEST_ASSERT_EQUAL_UINT32(id_b, tb->id);
    }
    n = lidet_tracker_q_tracks(&g.ws, out, LIDET_TRACK_MAX_TRACKS, 0);
    TEST_ASSERT_NOT_NULL(find(n, id_a));
    TEST_ASSERT_NOT_NULL(find(n, id_b));
    TEST_ASSERT_INT32_WITHIN(60, 1000, find(n, id_a)->vx_mmps);
    TEST_ASSERT_INT32_WITHIN(60, 1000, find(n, id_a)->vy_mmps);
    TEST_ASSERT_INT32_WITHIN(60, 1000, find(n, id_b)->vx_mmps);
    TEST_ASSERT_INT32_WITHIN(60, -1000, find(n, id_b)->vy_mmps);
    /* pedestrians: the reported heading is the direction of motion (box yaw 0 here) */
    TEST_ASSERT_TRUE(fabs(bam_to_rad(find(n, id_a)->box.yaw_bam) - M_PI / 4) < 0.05);
    TEST_ASSERT_TRUE(fabs(bam_to_rad(find(n, id_b)->box.yaw_bam) + M_PI / 4) < 0.05);
    check_invariants();
}

static void test_misses_deaths_confirmation(void)
{
    lidet_tracker_q_cfg_t cfg;
    const lidet_tracker_q_stats_t *st = lidet_tracker_q_stats(&g.ws);
    uint32_t k, n;
    NEED_CAPACITY();
    lidet_tracker_q_cfg_default(&cfg);
    TEST_ASSERT_EQUAL_UINT32(12u, cfg.max_misses);
    cfg.max_misses = 3; /* short, to count the misses below */
    init_cfg(&cfg);
    det[0] = make_det(LIDET_CLASS_CAR, 20000, 0, 0, 30000);
    det[1] = make_det(LIDET_CLASS_CYCLIST, -20000, 5000, 0, 20000);
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_tracker_q_update(&g.ws, det, 2, 100, NULL));
    TEST_ASSERT_EQUAL_UINT32(2u, st->n_births);
    TEST_ASSERT_EQUAL_UINT32(2u, st->n_tracks);
    TEST_ASSERT_EQUAL_UINT32(0u, st->n_confirmed);
    TEST_ASSERT_EQUAL_UINT32(2u, lidet_tracker_q_tracks(&g.ws, out, 8, LIDET_TRACK_OUT_TENTATIVE));
    TEST_ASSERT_EQUAL_UINT32(1u, out[0].id);
    TEST_ASSERT_EQUAL_UINT32(2u, out[1].id);
    TEST_ASSERT_EQUAL_UINT8(LIDET_TRACK_TENTATIVE, out[0].state);
    /* the car is seen again (confirmed), the cyclist not (a tentative track dies at its first miss) */
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_tracker_q_update(&g.ws, det, 1, 100, NULL));
    TEST_ASSERT_EQUAL_UINT32(1u, st->n_deaths);
    TEST_ASSERT_EQUAL_UINT32(1u, st->n_confirmed);
    TEST_ASSERT_EQUAL_UINT32(1u, st->n_matched);
    /* a confirmed track coasts max_misses (3) scans, dies at the 4th */
    for (k = 1; k <= 3u; ++k)
    {
        TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_tracker_q_update(&g.ws, NULL, 0, 100, NULL));
        /* without the flag: reported while it has missed at most report_misses[car] (1) scans */
        TEST_ASSERT_EQUAL_UINT32(k <= cfg.report_misses[LIDET_CLASS_CAR] ? 1u : 0u,
                                 lidet_tracker_q_tracks(&g.ws, out, 8, 0));
        n = lidet_tracker_q_tracks(&g.ws, out, 8, LIDET_TRACK_OUT_COASTING);
        TEST_ASSERT_EQUAL_UINT32(1u, n);
        TEST_ASSERT_EQUAL_UINT8(LIDET_TRACK_COASTING, out[0].state);
        TEST_ASSERT_EQUAL_UINT32(k, out[0].misses);
        TEST_ASSERT_EQUAL_INT32(-1, out[0].det_index);
        TEST_ASSERT_EQUAL_UINT32(0u, st->n_deaths);
    }
    /* back after 3 misses: updated again */
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_tracker_q_update(&g.ws, det, 1, 100, NULL));
    TEST_ASSERT_EQUAL_UINT32(1u, lidet_tracker_q_tracks(&g.ws, out, 8, 0));
    TEST_ASSERT_EQUAL_UINT32(0u, out[0].misses);
    TEST_ASSERT_EQUAL_UINT32(3u, out[0].hits);
    for (k = 1; k <= 4u; ++k)
    {
        TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_tracker_q_update(&g.ws, NULL, 0, 100, NULL));
    }
    TEST_ASSERT_EQUAL_UINT32(1u, st->n_deaths);
    TEST_ASSERT_EQUAL_UINT32(0u, st->n_tracks);
    /* ids go on counting after deaths; reset restarts them */
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_tracker_q_update(&g.ws, det, 1, 100, NULL));
    TEST_ASSERT_EQUAL_UINT32(1u, lidet_tracker_q_tracks(&g.ws, out, 8, LIDET_TRACK_OUT_TENTATIVE));
    TEST_ASSERT_EQUAL_UINT32(3u, out[0].id);
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_tracker_q_reset(&g.ws));
    TEST_ASSERT_EQUAL_UINT32(0u, lidet_tracker_q_tracks(&g.ws, out, 8, 3));
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_tracker_q_update(&g.ws, det, 1, 100, NULL));
    TEST_ASSERT_EQUAL_UINT32(1u, lidet_tracker_q_tracks(&g.ws, out, 8, LIDET_TRACK_OUT_TENTATIVE));
    TEST_ASSERT_EQUAL_UINT32(1u, out[0].id);
    /* confirm_hits 1: confirmed in the scan of its birth; confirm_hits 3: at the third hit; birth_min_score */
    lidet_tracker_q_cfg_default(&cfg);
    cfg.confirm_hits = 1u;
    cfg.birth_min_score_q15 = 25000;
    init_cfg(&cfg);
    det[1] = make_det(LIDET_CLASS_CYCLIST, -20000, 5000, 0, 24999); /* below birth_min_score */
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_tracker_q_update(&g.ws, det, 2, 100, NULL));
    TEST_ASSERT_EQUAL_UINT32(1u, st->n_births);
    TEST_ASSERT_EQUAL_UINT32(1u, lidet_tracker_q_tracks(&g.ws, out, 8, 0));
    TEST_ASSERT_EQUAL_UINT8(LIDET_TRACK_CONFIRMED, out[0].state);
    cfg.confirm_hits = 3u;
    cfg.birth_min_score_q15 = 0;
    init_cfg(&cfg);
    for (k = 1; k <= 3u; ++k)
    {
        TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_tracker_q_update(&g.ws, det, 1, 100, NULL));
        TEST_ASSERT_EQUAL_UINT32(k == 3u ? 1u : 0u, lidet_tracker_q_stats(&g.ws)->n_confirmed);
    }
    check_invariants();
}

static void test_heading_flip(void)
{
    /* a parked car whose box yaw flips by pi every other scan: the average stays at the first yaw */
    const int32_t yaw0 = rad_to_bam(0.3);
    uint32_t k, n;
    init_default();
    for (k = 0; k < 20u; ++k)
    {
        const int32_t flip = (k & 1u) ? (int32_t)((uint32_t)yaw0 + 0x80000000u) : yaw0;
        det[0] = make_det(LIDET_CLASS_CAR, 15000, 3000, flip, 30000);
        TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_tracker_q_update(&g.ws, det, 1, 100, NULL));
    }
    n = lidet_tracker_q_tracks(&g.ws, out, 8, 0);
    TEST_ASSERT_EQUAL_UINT32(1u, n);
    TEST_ASSERT_INT32_WITHIN(4, yaw0, out[0].box.yaw_bam);
    /* a car driving along -x whose box yaw says +x: the reported yaw is turned to the motion */
    init_default();
    for (k = 0; k < 30u; ++k)
    {
        det[0] = make_det(LIDET_CLASS_CAR, (int32_t)(30000 - 800 * k), 1000, 0, 30000);
        TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_tracker_q_update(&g.ws, det, 1, 100, NULL));
    }
    n = lidet_tracker_q_tracks(&g.ws, out, 8, 0);
    TEST_ASSERT_EQUAL_UINT32(1u, n);
    TEST_ASSERT_INT32_WITHIN(100, -8000, out[0].vx_mmps);
    TEST_ASSERT_TRUE(fabs(fabs(bam_to_rad(out[0].box.yaw_bam)) - M_PI) < 1e-6);
    check_invariants();
}

static void test_ego_motion_static_object(void)
{
    /* the sensor drives at 10 m/s and turns at 0.2 rad/s; a parked car at (60, 8) m in the world: its track's
     * velocity over the ground stays ~0 */
    double sx = 0.0, sy = 0.0, syaw = 0.0;
    uint32_t k, n;
    const double dyaw = 0.02;
    init_default();
    for (k = 0; k < 50u; ++k)
    {
        lidet_ego_q_t ego;
        double wx, wy;
        if (k > 0u)
        {
            sx += cos(syaw) * 1.0;
            sy += sin(syaw) * 1.0;
            syaw += dyaw;
        }
        wx = 60.0 - sx;
        wy = 8.0 - sy;
        det[0] = make_det(LIDET_CLASS_CAR, (int32_t)floor(1000.0 * (cos(syaw) * wx + sin(syaw) * wy) + 0.5),
                          (int32_t)floor(1000.0 * (-sin(syaw) * wx + cos(syaw) * wy) + 0.5), 0, 30000);
        ego.dx_mm = 1000;
        ego.dy_mm = 0;
        ego.dyaw_bam = rad_to_bam(dyaw);
        TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_tracker_q_update(&g.ws, det, 1, 100, k > 0u ? &ego : NULL));
    }
    n = lidet_tracker_q_tracks(&g.ws, out, 8, 0);
    TEST_ASSERT_EQUAL_UINT32(1u, n);
    TEST_ASSERT_EQUAL_UINT32(1u, out[0].id);
    TEST_ASSERT_INT32_WITHIN(20, 0, out[0].vx_mmps);
    TEST_ASSERT_INT32_WITHIN(20, 0, out[0].vy_mmps);
    check_invariants();
}

static void test_capacity_and_truncation(void)
{
    const uint32_t md = LIDET_TRACK_MAX_DETS, mt = LIDET_TRACK_MAX_TRACKS;
    lidet_tracker_q_cfg_t cfg;
    const lidet_tracker_q_stats_t *st = lidet_tracker_q_stats(&g.ws);
    uint32_t j, n;
    NEED_CAPACITY();
    lidet_tracker_q_cfg_default(&cfg);
    cfg.confirm_hits = 1u;
    init_cfg(&cfg);
    /* more than LIDET_TRACK_MAX_DETS detections: the first are used, the rest counted */
    for (j = 0; j < MAXD; ++j)
    {
        det[j] = make_det(LIDET_CLASS_PEDESTRIAN, (int32_t)(5000 * (j % 16u)), (int32_t)(5000 * (j / 16u)), 0,
                          30000);
    }
    TEST_ASSERT_EQUAL_INT(LIDET_TRUNCATED, lidet_tracker_q_update(&g.ws, det, MAXD, 100, NULL));
    TEST_ASSERT_EQUAL_UINT32(MAXD - md, st->n_dets_dropped);
    TEST_ASSERT_EQUAL_UINT32(md < mt ? md : mt, st->n_births);
    TEST_ASSERT_EQUAL_UINT32(md > mt ? md - mt : 0u, st->n_births_dropped);
    /* the output cap: the lowest ids first, in order */
    n = lidet_tracker_q_tracks(&g.ws, out, 5, 0);
    TEST_ASSERT_EQUAL_UINT32(5u, n);
    for (j = 0; j < n; ++j)
    {
        TEST_ASSERT_EQUAL_UINT32(j + 1u, out[j].id);
    }
    /* every slot held (confirmed, coasting): new detections elsewhere find no free slot */
    if (md >= mt)
    {
        for (j = 0; j < md; ++j)
        {
            det[j].box.cx_mm -= 200000;
        }
        TEST_ASSERT_EQUAL_INT(LIDET_TRUNCATED, lidet_tracker_q_update(&g.ws, det, md, 100, NULL));
        TEST_ASSERT_EQUAL_UINT32(md, st->n_births_dropped);
        TEST_ASSERT_EQUAL_UINT32(0u, st->n_births);
        TEST_ASSERT_EQUAL_UINT32(mt, st->n_tracks);
        TEST_ASSERT_EQUAL_UINT32(mt, lidet_tracker_q_tracks(&g.ws, out, mt, LIDET_TRACK_OUT_COASTING));
    }
    check_invariants();
}

static void test_bad_detections(void)
{
    const lidet_tracker_q_stats_t *st = lidet_tracker_q_stats(&g.ws);
    const int32_t m = LIDET_TRACK_Q_COORD_MAX_MM;
    uint32_t j;
    NEED_CAPACITY();
    init_default();
    for (j = 0; j < 12u; ++j)
    {
        det[j] = make_det(LIDET_CLASS_CAR, 10000 + 10000 * (int32_t)j, 0, 0, 30000);
    }
    det[0].cls = 3;
    det[1].cls = 255;
    det[2].box.l_mm = 0;
    det[3].box.w_mm = -5;
    det[4].box.h_mm = LIDET_TRACK_Q_SIZE_MAX_MM + 1;
    det[5].box.cx_mm = m + 1;
    det[6].box.cy_mm = -m - 1;
    det[7].box.cz_mm = INT32_MIN;
    det[8].score_q15 = -1;
    det[9].score_q15 = 32769;
    det[10].box.cx_mm = m; /* at the limit: valid */
    det[11].box.cx_mm = INT32_MAX;
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_tracker_q_update(&g.ws, det, 12, 100, NULL));
    TEST_ASSERT_EQUAL_UINT32(11u, st->n_bad_dets);
    TEST_ASSERT_EQUAL_UINT32(1u, st->n_births);
    TEST_ASSERT_EQUAL_UINT32(1u, lidet_tracker_q_tracks(&g.ws, out, 8, LIDET_TRACK_OUT_TENTATIVE));
    TEST_ASSERT_EQUAL_INT32(10, out[0].det_index);
    TEST_ASSERT_EQUAL_INT32(m, out[0].box.cx_mm);
    check_invariants();
}

/* two tracks 0.9 m apart, then detections 0.4 m from the first (0.5 m from the second) and 0.45 m behind the
 * first (out of the second's gate): greedy takes the cheapest pair and leaves the second track without one, the
 * optimal assignment matches both */
static uint32_t run_assign_case(uint32_t mode)
{
    lidet_tracker_q_cfg_t cfg;
    uint32_t k;
    lidet_tracker_q_cfg_default(&cfg);
    cfg.assign = mode;
    init_cfg(&cfg);
    for (k = 0; k < 10u; ++k)
    {
        det[0] = make_det(LIDET_CLASS_PEDESTRIAN, 10000, 0, 0, 30000);
        det[1] = make_det(LIDET_CLASS_PEDESTRIAN, 10000, 900, 0, 30000);
        TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_tracker_q_update(&g.ws, det, 2, 100, NULL));
    }
    det[0] = make_det(LIDET_CLASS_PEDESTRIAN, 10000, 400, 0, 30000);
    det[1] = make_det(LIDET_CLASS_PEDESTRIAN, 10000, -450, 0, 30000);
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_tracker_q_update(&g.ws, det, 2, 100, NULL));
    TEST_ASSERT_EQUAL_UINT32(3u, lidet_tracker_q_stats(&g.ws)->n_feasible_pairs);
    check_invariants();
    return lidet_tracker_q_stats(&g.ws)->n_matched;
}

static void test_optimal_vs_greedy(void)
{
    uint32_t n;
    NEED_CAPACITY();
    TEST_ASSERT_EQUAL_UINT32(1u, run_assign_case(LIDET_TRACK_ASSIGN_GREEDY));
    TEST_ASSERT_EQUAL_UINT32(1u, lidet_tracker_q_stats(&g.ws)->n_births);
    n = lidet_tracker_q_tracks(&g.ws, out, 8, LIDET_TRACK_OUT_COASTING);
    TEST_ASSERT_EQUAL_UINT32(2u, n);
    TEST_ASSERT_EQUAL_INT32(0, out[0].det_index);
    TEST_ASSERT_EQUAL_INT32(-1, out[1].det_index);
    TEST_ASSERT_EQUAL_UINT32(2u, run_assign_case(LIDET_TRACK_ASSIGN_OPTIMAL));
    TEST_ASSERT_EQUAL_UINT32(0u, lidet_tracker_q_stats(&g.ws)->n_births);
    n = lidet_tracker_q_tracks(&g.ws, out, 8, LIDET_TRACK_OUT_COASTING);
    TEST_ASSERT_EQUAL_UINT32(2u, n);
    TEST_ASSERT_EQUAL_INT32(1, out[0].det_index);
    TEST_ASSERT_EQUAL_INT32(0, out[1].det_index);
}

static void test_extreme_values(void)
{
    lidet_tracker_q_cfg_t cfg;
    const lidet_tracker_q_stats_t *st = lidet_tracker_q_stats(&g.ws);
    const int32_t m = LIDET_TRACK_Q_COORD_MAX_MM;
    lidet_ego_q_t ego;
    uint32_t k, j, c;
    NEED_CAPACITY();
    /* every configuration value at the end of its range that makes numbers large */
    lidet_tracker_q_cfg_default(&cfg);
    for (c = 0; c < (uint32_t)LIDET_N_CLASSES; ++c)
    {
        cfg.meas_sigma_mm[c] = 10000;
        cfg.accel_sigma_mmps2[c] = 100000;
        cfg.init_vel_sigma_mmps[c] = 46340;
        cfg.gate_max_mm[c] = 1000000;
    }
    cfg.gate_chi2_q16 = 1000 * 65536;
    cfg.class_penalty_q16 = 1000 * 65536;
    cfg.confirm_hits = 1u;
    cfg.max_misses = 1000u;
    for (j = 0; j < 2u; ++j)
    {
        cfg.assign = j;
        init_cfg(&cfg);
        for (k = 0; k < 40u; ++k)
        {
            /* corners of the coordinate range, jumping across it; dt 10 s or 1 ms; extreme ego motions */
            const uint32_t dt = (k % 3u == 0u) ? LIDET_TRACK_Q_DT_MAX_MS : (k % 3u == 1u ? 1u : 100u);
            det[0] = make_det(LIDET_CLASS_CAR, (k & 1u) ? m : -m, (k & 2u) ? m : -m, INT32_MIN, 32768);
            det[1] = make_det(LIDET_CLASS_CYCLIST, m - (int32_t)(k * 1000u), -m + (int32_t)(k * 37u),
                              INT32_MAX, 0);
            det[2] = make_det(LIDET_CLASS_PEDESTRIAN, 0, (k & 1u) ? m : 0, 0, 16384);
            det[2].box.l_mm = LIDET_TRACK_Q_SIZE_MAX_MM;
            det[2].box.cz_mm = (k & 1u) ? m : -m;
            ego.dx_mm = (k & 4u) ? m : -m;
            ego.dy_mm = (k & 8u) ? -m : m;
            ego.dyaw_bam = (int32_t)(k * 0x2F000000u);
            TEST_ASSERT_TRUE(
                LIDET_SUCCEEDED(lidet_tracker_q_update(&g.ws, det, 3, dt, (k % 5u == 4u) ? &ego : NULL)));
            check_invariants();
        }
    }
    /* a fast track leaves the coordinate range: it dies there (counted), never wraps */
    lidet_tracker_q_cfg_default(&cfg);
    cfg.gate_max_mm[LIDET_CLASS_CAR] = 100000;
    cfg.gate_chi2_q16 = 1000 * 65536;
    init_cfg(&cfg);
    for (k = 0; k < 12u; ++k)
    {
        det[0] = make_det(LIDET_CLASS_CAR, m - 100000 + (int32_t)k * 9000, 0, 0, 30000); /* 90 m/s */
        TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_tracker_q_update(&g.ws, det, 1, 100, NULL));
        check_invariants();
    }
    TEST_ASSERT_EQUAL_UINT32(1u, lidet_tracker_q_tracks(&g.ws, out, 8, 0));
    TEST_ASSERT_INT32_WITHIN(2000, 90000, out[0].vx_mmps);
    /* coasting for 10 s at 90 m/s: predicted 900 m on, beyond 2^20 mm */
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_tracker_q_update(&g.ws, NULL, 0, LIDET_TRACK_Q_DT_MAX_MS, NULL));
    TEST_ASSERT_EQUAL_UINT32(1u, st->n_deaths);
    TEST_ASSERT_EQUAL_UINT32(0u, st->n_tracks);
    /* a long coast at dt 10 s: the covariance saturates at its ceiling, stays positive definite */
    init_default();
    det[0] = make_det(LIDET_CLASS_CAR, 0, 0, 0, 30000);
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_tracker_q_update(&g.ws, det, 1, 100, NULL));
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_tracker_q_update(&g.ws, det, 1, 100, NULL));
    for (k = 0; k < 8u; ++k)
    {
        TEST_ASSERT_EQUAL_INT(LIDET_OK,
                              lidet_tracker_q_update(&g.ws, NULL, 0, LIDET_TRACK_Q_DT_MAX_MS, NULL));
        check_invariants();
    }
    TEST_ASSERT_EQUAL_UINT32(1u, lidet_tracker_q_tracks(&g.ws, out, 8, LIDET_TRACK_OUT_COASTING));
    TEST_ASSERT_EQUAL_INT32(LIDET_TRACK_Q_P_MAX, out[0].p_pp);
    TEST_ASSERT_EQUAL_INT32(LIDET_TRACK_Q_P_MAX, out[0].p_vv);
    /* and picks its object up again */
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_tracker_q_update(&g.ws, det, 1, 100, NULL));
    TEST_ASSERT_EQUAL_UINT32(1u, lidet_tracker_q_tracks(&g.ws, out, 8, 0));
    TEST_ASSERT_EQUAL_UINT32(1u, out[0].id);
    TEST_ASSERT_TRUE(out[0].p_pp < 90000);
    check_invariants();
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_config_and_args);
    RUN_TEST(test_constant_velocity);
    RUN_TEST(test_crossing_objects_keep_ids);
    RUN_TEST(test_misses_deaths_confirmation);
    RUN_TEST(test_heading_flip);
    RUN_TEST(test_ego_motion_static_object);
    RUN_TEST(test_capacity_and_truncation);
    RUN_TEST(test_bad_detections);
    RUN_TEST(test_optimal_vs_greedy);
    RUN_TEST(test_extreme_values);
    return UNITY_END();
}
