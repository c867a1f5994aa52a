/* SPDX-License-Identifier: MIT */
/* Unity tests of the detector (lib/src/detector/lidet_detector.c): a synthetic scan (flat ground plus
 * vertical faces) through hand-made models whose outputs are known (every proposal a car with the car
 * template, centred on its cluster mean, heading along the azimuth), so the counts, the crop, the budget, the
 * order, the NMS and the decoded boxes can be checked exactly; the rotated BEV IoU by hand; init errors. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "lidet/lidet.h"
#include "test_util.h"

LIDET_GUARDED(lidet_detector_t, g);

/* ---- hand-made models: constant outputs from the biases -------------------------------------------- */
static const float z3[3] = {0, 0, 0};
static const float z1[1] = {0};
static const float cls_hw[1 * 3] = {0, 0, 0};
static const float cls_hb[3] = {5.0f, 0.0f, 0.0f}; /* car, energy -(5 + log(1 + 2 e^-5)) */
static const lidet_pn_layer_t cls_point[1] = {{3, 1, 1, z3, z1}};
static const lidet_pn_layer_t cls_head[1] = {{1, 3, 0, cls_hw, cls_hb}};
static float box_hw[4 * 39];
static float box_hb[39];
static const lidet_pn_layer_t box_point[1] = {{3, 1, 1, z3, z1}};
static const lidet_pn_layer_t box_head[1] = {{4, 39, 0, box_hw, box_hb}};
static const float mean_size[9] = {3.883f, 1.629f, 1.526f, 1.763f, 0.597f, 1.737f, 0.844f, 0.661f, 1.763f};
static lidet_pn_model_t m_cls, m_box;

static void make_models(void)
{
    memset(&m_cls, 0, sizeof m_cls);
    m_cls.format_version = LIDET_WEIGHTS_FORMAT_VERSION;
    m_cls.kind = LIDET_PN_CLASSIFIER;
    m_cls.n_stages = 1;
    m_cls.n_classes = LIDET_N_CLASSES;
    m_cls.n_points = 16;
    m_cls.stage[0].point = cls_point;
    m_cls.stage[0].head = cls_head;
    m_cls.stage[0].n_point = 1;
    m_cls.stage[0].n_head = 1;
    m_cls.energy_t = 1.0f;
    m_cls.gamma[0] = m_cls.gamma[1] = m_cls.gamma[2] = 0.0f;
    m_cls.pvle_bin[0] = m_cls.pvle_bin[1] = 10.0f * 0.0174532925f;
    m_cls.pvle_bin[2] = 1.0f;
    memset(box_hb, 0, sizeof box_hb);
    box_hb[3] = 4.0f;  /* heading bin 0 (along the azimuth), residual 0 */
    box_hb[27] = 4.0f; /* size template 0 (car), residual 0 */
    memset(&m_box, 0, sizeof m_box);
    m_box = m_cls;
    m_box.kind = LIDET_PN_BOX;
    m_box.n_heading_bins = 12;
    m_box.n_size_clusters = 3;
    m_box.stage[0].point = box_point;
    m_box.stage[0].head = box_head;
    m_box.stage[0].use_onehot = 1;
    m_box.mean_size_m = mean_size;
    m_box.gamma[0] = m_box.gamma[1] = m_box.gamma[2] = 100.0f;
}

/* ---- a synthetic scan -------------------------------------------------------------------------------- */
/* lidet_detector_cfg_default's gate1_large_car_margin for > 16 beams (0 for <= 16) */
#define LARGE_CAR_DEFAULT 1.0f
#define MAXP 120000
static float g_pts[MAXP * 4];
static uint32_t g_n;
static uint32_t g_rng = 12345u;

static float frand(void)
{
    g_rng ^= g_rng << 13;
    g_rng ^= g_rng >> 17;
    g_rng ^= g_rng << 5;
    return (float)(g_rng >> 8) / 16777216.0f;
}

static void add(float x, float y, float z)
{
    if (g_n < MAXP)
    {
        g_pts[4 * g_n] = x;
        g_pts[4 * g_n + 1] = y;
        g_pts[4 * g_n + 2] = z;
        g_pts[4 * g_n + 3] = 0.0f;
        ++g_n;
    }
}

/* a vertical face facing the sensor, centred at (x, y), width w, from the ground (z = -1.73) up h */
static void face(float x, float y, float w, float h, uint32_t n)
{
    const float r = sqrtf(x * x + y * y), tx = -y / r, ty = x / r;
    uint32_t i;
    for (i = 0; i < n; ++i)
    {
        const float u = (frand() - 0.5f) * w, v = frand() * h;
        add(x + u * tx, y + u * ty, -1.73f + 0.05f + v);
    }
}

static void scene(void)
{
    uint32_t i;
    g_n = 0;
    g_rng = 12345u;
    for (i = 0; i < 60000; ++i)
    {
        add((frand() - 0.5f) * 60.0f, (frand() - 0.5f) * 60.0f, -1.73f);
    }
    face(10.0f, 0.0f, 1.8f, 1.5f, 6000);  /* A: in front */
    face(8.0f, 6.0f, 0.6f, 1.7f, 3000);   /* B: 37 deg left, inside a 45 deg crop */
    face(-15.0f, 3.0f, 2.0f, 1.5f, 6000); /* C: behind */
}

static lidet_detector_cfg_t cfg;

void setUp(void)
{
    CANARY_FILL(g);
    make_models();
    lidet_detector_cfg_default(&cfg, lidet_sensor_find("hdl64"));
    cfg.proposal.n_points = 16;
}

void tearDown(void)
{
    CANARY_CHECK(g);
}

/* the car boxes' ground (car_ground_m) where its column span is special: a car 2.6 m ahead, whose widened footprint
 * holds the sensor (every column looked at), and one straight behind, whose span crosses the image's seam (two runs of
 * columns): both bottoms go down to the ground plane, the tops kept */
void test_car_boxes_go_down_to_the_ground_near_and_behind(void)
{
    const lidet_detection_t *d;
    const lidet_cluster_rec_t *recs;
    uint32_t n = 0, k, i;
    scene();
    g_n = 60000u; /* the ground alone */
    face(2.6f, 0.0f, 1.8f, 1.5f, 6000);
    face(-20.0f, 0.3f, 1.8f, 1.5f, 6000);
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_detector_init(&g.ws, &cfg, &m_cls, &m_box));
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_detector_run(&g.ws, g_pts, g_n, 4, NULL, NULL));
    d = lidet_detector_detections(&g.ws, &n);
    recs = lidet_workspace_clusters(lidet_detector_workspace(&g.ws), NULL);
    TEST_ASSERT_EQUAL_UINT32(2, n);
    for (k = 0; k < n; ++k)
    {
        const lidet_cluster_rec_t *r = &recs[d[k].cluster_id - 1u];
        const float hl = 0.5f * d[k].box.l_m + cfg.car_ground_m,
                    dc = sqrtf(r->mean_m[0] * r->mean_m[0] + r->mean_m[1] * r->mean_m[1]);
        TEST_ASSERT_EQUAL_UINT8(LIDET_CLASS_CAR, d[k].cls);
        TEST_ASSERT_TRUE(r->mean_m[0] > 0.0f ? dc < hl
                                             : fabsf(r->mean_m[1]) < 1.0f); /* the two cases above */
        TEST_ASSERT_CLOSE(r->mean_m[2] + 0.763f, d[k].box.cz_m + 0.5f * d[k].box.h_m, 1e-4, 0);
        TEST_ASSERT_CLOSE(-1.73f, d[k].box.cz_m - 0.5f * d[k].box.h_m, 0.0101, 0);
    }
    /* without the ground around them (none within 1 m of either footprint): the boxes as the net gave them */
    for (i = 0; i < 60000u; ++i)
    {
        const float x = g_pts[4 * i], y = g_pts[4 * i + 1];
        if ((fabsf(x - 2.6f) < 4.0f && fabsf(y) < 3.0f) || (fabsf(x + 20.0f) < 4.0f && fabsf(y) < 3.0f))
        {
            g_pts[4 * i + 2] = 5.0f; /* lifted far out of the window (and out of the ground) */
        }
    }
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_detector_run(&g.ws, g_pts, g_n, 4, NULL, NULL));
    d = lidet_detector_detections(&g.ws, &n);
    recs = lidet_workspace_clusters(lidet_detector_workspace(&g.ws), NULL);
    TEST_ASSERT_TRUE(n >= 2u);
    for (k = 0; k < n; ++k)
    {
        if (d[k].box.cz_m < 2.0f) /* the two faces (the lifted points make clusters of their own, high up) */
        {
            TEST_ASSERT_CLOSE(1.526, d[k].box.h_m, 1e-5, 0);
        }
    }
}

/* a cluster taller than max_height_extent_m (a 3.5 m pole beside the three objects) is not classified */
void test_tall_clusters_are_not_classified(void)
{
    const lidet_detector_stats_t *s;
    const lidet_cluster_rec_t *recs;
    const uint8_t *oc;
    uint32_t nc = 0, k, n_tall = 0;
    scene();
    face(28.0f, -10.0f, 0.4f, 3.5f, 3000); /* at 30 m the top beam (+2 deg) still sees 2.7 m of it */
    TEST_ASSERT_CLOSE(2.5, cfg.max_height_extent_m, 1e-6, 0);
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_detector_init(&g.ws, &cfg, &m_cls, &m_box));
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_detector_run(&g.ws, g_pts, g_n, 4, NULL, NULL));
    s = lidet_detector_stats(&g.ws);
    TEST_ASSERT_EQUAL_UINT32(4, s->n_clusters);
    TEST_ASSERT_EQUAL_UINT32(1, s->n_too_tall);
    TEST_ASSERT_EQUAL_UINT32(3, s->n_classified);
    oc = lidet_detector_outcomes(&g.ws, &nc);
    recs = lidet_workspace_clusters(lidet_detector_workspace(&g.ws), NULL);
    for (k = 0; k < nc; ++k)
    {
        const float zext = recs[k].max_m[2] - recs[k].min_m[2];
        TEST_ASSERT_EQUAL_INT(zext > 2.5f, oc[k] == LIDET_DET_OUT_TALL);
        n_tall += oc[k] == LIDET_DET_OUT_TALL;
    }
    TEST_ASSERT_EQUAL_UINT32(1, n_tall);
    /* 0: no limit, the pole is classified too; a limit above it: the same */
    cfg.max_height_extent_m = 0.0f;
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_detector_init(&g.ws, &cfg, &m_cls, &m_box));
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_detector_run(&g.ws, g_pts, g_n, 4, NULL, NULL));
    TEST_ASSERT_EQUAL_UINT32(0, lidet_detector_stats(&g.ws)->n_too_tall);
    TEST_ASSERT_EQUAL_UINT32(4, lidet_detector_stats(&g.ws)->n_classified);
    cfg.max_height_extent_m = 4.0f;
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_detector_init(&g.ws, &cfg, &m_cls, &m_box));
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_detector_run(&g.ws, g_pts, g_n, 4, NULL, NULL));
    TEST_ASSERT_EQUAL_UINT32(4, lidet_detector_stats(&g.ws)->n_classified);
    /* out of range or not finite: refused */
    cfg.max_height_extent_m = -0.5f;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_detector_init(&g.ws, &cfg, &m_cls, &m_box));
    cfg.max_height_extent_m = 100.5f;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_detector_init(&g.ws, &cfg, &m_cls, &m_box));
    cfg.max_height_extent_m = NAN;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_detector_init(&g.ws, &cfg, &m_cls, &m_box));
}

/* runs the detector on the scene: three car boxes, each centred on its cluster's mean with the car template's
 * height (none moved to the ground) */
static void three_boxes_as_the_net_gave(void)
{
    uint32_t n = 0, k;
    const lidet_detection_t *d;
    const lidet_cluster_rec_t *recs;
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_detector_run(&g.ws, g_pts, g_n, 4, NULL, NULL));
    d = lidet_detector_detections(&g.ws, &n);
    recs = lidet_workspace_clusters(lidet_detector_workspace(&g.ws), NULL);
    TEST_ASSERT_EQUAL_UINT32(3, n);
    for (k = 0; k < n; ++k)
    {
        TEST_ASSERT_CLOSE(recs[d[k].cluster_id - 1u].mean_m[2], d[k].box.cz_m, 1e-4, 0);
        TEST_ASSERT_CLOSE(1.526, d[k].box.h_m, 1e-5, 0);
    }
}

void test_three_objects_three_cars(void)
{
    const lidet_detection_t *d;
    const lidet_detector_stats_t *s;
    uint32_t n = 0, k;
    scene();
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_detector_init(&g.ws, &cfg, &m_cls, &m_box));
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_detector_run(&g.ws, g_pts, g_n, 4, NULL, NULL));
    s = lidet_detector_stats(&g.ws);
    d = lidet_detector_detections(&g.ws, &n);
    TEST_ASSERT_EQUAL_UINT32(3, s->n_clusters);
    TEST_ASSERT_EQUAL_UINT32(3, s->n_classified);
    TEST_ASSERT_EQUAL_UINT32(3, s->n_boxed);
    TEST_ASSERT_EQUAL_UINT32(0, s->n_gate1_rejected + s->n_gate2_rejected + s->n_size_rejected);
    TEST_ASSERT_EQUAL_UINT32(3, n);
    TEST_ASSERT_EQUAL_UINT32(3, s->n_detections);
    {
        uint32_t nc = 0;
        const uint8_t *oc = lidet_detector_outcomes(&g.ws, &nc);
        TEST_ASSERT_EQUAL_UINT32(3, nc);
        for (k = 0; k < nc; ++k)
        {
            TEST_ASSERT_EQUAL_UINT8(LIDET_DET_OUT_DETECTED, oc[k]);
        }
    }
    for (k = 0; k < n; ++k)
    {
        const lidet_cluster_rec_t *recs = lidet_workspace_clusters(lidet_detector_workspace(&g.ws), NULL);
        const lidet_cluster_rec_t *r = &recs[d[k].cluster_id - 1u];
        const float az = atan2f(r->mean_m[1], r->mean_m[0]);
        TEST_ASSERT_EQUAL_UINT8(LIDET_CLASS_CAR, d[k].cls);
        TEST_ASSERT_CLOSE(r->mean_m[0], d[k].box.cx_m, 1e-4, 0);
        TEST_ASSERT_CLOSE(r->mean_m[1], d[k].box.cy_m, 1e-4, 0);
        /* the box net's box is centred on the mean with the car template's height (its bottom 0.04-0.14 m above
         * the ground); car_ground_m (default 1 m) takes the bottom down to the ground plane z = -1.73 within half a
         * 2 cm bin, the top kept */
        TEST_ASSERT_CLOSE(r->mean_m[2] + 0.763f, d[k].box.cz_m + 0.5f * d[k].box.h_m, 1e-4, 0);
        TEST_ASSERT_CLOSE(-1.73f, d[k].box.cz_m - 0.5f * d[k].box.h_m, 0.0101, 0);
        TEST_ASSERT_TRUE(d[k].box.h_m > 1.526f + 0.02f);
        TEST_ASSERT_CLOSE(az, d[k].box.yaw_rad, 1e-4, 0);
        TEST_ASSERT_CLOSE(3.883, d[k].box.l_m, 1e-5, 0);
        TEST_ASSERT_EQUAL_UINT32(r->n_points, d[k].n_points);
        /* score = 1 / (1 + exp((E1 - gamma1) + w (E2 - gamma2) - v ln(n / 64))), E1 = -(5 + log(1 + 2 exp(-5))),
         * w = 0.5 and v = 0.1 for cars (score_box_weight's and score_points_weight's defaults) */
        TEST_ASSERT_CLOSE(0.5f, cfg.score_box_weight[LIDET_CLASS_CAR], 0.0, 0);
        TEST_ASSERT_CLOSE(1.0 / (1.0 + exp(-(5.0 + log(1.0 + 2.0 * exp(-5.0))) +
                                           0.5 * ((double)d[k].energy_box - (double)m_box.gamma[0]) -
                                           0.1 * log((double)d[k].n_points / 64.0))),
                          d[k].score, 1e-5, 0);
        TEST_ASSERT_TRUE(k == 0 || d[k - 1].cluster_id < d[k].cluster_id); /* equal scores: id order */
    }
    {
        /* the car boxes' ground off: the box net's boxes as they came, centred on the means */
        lidet_detector_cfg_t c = cfg;
        c.car_ground_m = 0.0f;
        TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_detector_init(&g.ws, &c, &m_cls, &m_box));
        three_boxes_as_the_net_gave();
    }
    {
        /* faces floating 0.6 m higher: their boxes' bottoms lie 0.64-0.74 m above the ground, beyond the 0.5 m a
         * box is stretched by, so the default leaves them as they came */
        uint32_t i;
        for (i = 60000u; i < g_n; ++i)
        {
            g_pts[4 * i + 2] += 0.6f;
        }
        TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_detector_init(&g.ws, &cfg, &m_cls, &m_box));
        three_boxes_as_the_net_gave();
        scene();
    }
    {
        /* weight 0: the classifier's energy alone; out of [0, 4]: refused */
        lidet_detector_cfg_t c = cfg;
        c.score_box_weight[LIDET_CLASS_CAR] = 0.0f;
        c.score_points_weight[LIDET_CLASS_CAR] = 0.0f;
        TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_detector_init(&g.ws, &c, &m_cls, &m_box));
        TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_detector_run(&g.ws, g_pts, g_n, 4, NULL, NULL));
        d = lidet_detector_detections(&g.ws, &n);
        TEST_ASSERT_EQUAL_UINT32(3, n);
        TEST_ASSERT_CLOSE(1.0 / (1.0 + exp(-(5.0 + log(1.0 + 2.0 * exp(-5.0))))), d[0].score, 1e-5, 0);
        c.score_box_weight[LIDET_CLASS_PEDESTRIAN] = 4.5f;
        TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_detector_init(&g.ws, &c, &m_cls, &m_box));
        c.score_box_weight[LIDET_CLASS_PEDESTRIAN] = -0.1f;
        TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_detector_init(&g.ws, &c, &m_cls, &m_box));
        c.score_box_weight[LIDET_CLASS_PEDESTRIAN] = 0.0f;
        c.score_points_weight[LIDET_CLASS_CYCLIST] = 4.01f;
        TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_detector_init(&g.ws, &c, &m_cls, &m_box));
    }
    {
        /* the operating point: a car scoring below min_score is dropped (outcome SCORE); the flat-surface test: the
         * three faces (1.5-1.7 m tall, hundreds of member pixels) spread about their height in z, so a test at
         * 1.0 m keeps them and one at 2.0 m calls them surfaces (outcome SIZE) */
        lidet_detector_cfg_t c = cfg;
        uint32_t nc = 0, k2;
        const uint8_t *oc;
        float top = 0.0f;
        c.score_box_weight[LIDET_CLASS_CAR] = 0.0f; /* the classifier's energy alone: scores about 0.995 */
        c.score_points_weight[LIDET_CLASS_CAR] = 0.0f;
        TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_detector_init(&g.ws, &c, &m_cls, &m_box));
        TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_detector_run(&g.ws, g_pts, g_n, 4, NULL, NULL));
        d = lidet_detector_detections(&g.ws, &n);
        for (k2 = 0; k2 < n; ++k2)
        {
            top = d[k2].score > top ? d[k2].score : top;
        }
        TEST_ASSERT_TRUE(n == 3 && top < 0.999f);
        c.min_score[LIDET_CLASS_CAR] = top + 1e-3f;
        TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_detector_init(&g.ws, &c, &m_cls, &m_box));
        TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_detector_run(&g.ws, g_pts, g_n, 4, NULL, NULL));
        lidet_detector_detections(&g.ws, &n);
        TEST_ASSERT_EQUAL_UINT32(0, n);
        TEST_ASSERT_EQUAL_UINT32(3, lidet_detector_stats(&g.ws)->n_score_rejected);
        oc = lidet_detector_outcomes(&g.ws, &nc);
        for (k2 = 0; k2 < nc; ++k2)
        {
            TEST_ASSERT_EQUAL_UINT8(LIDET_DET_OUT_SCORE, oc[k2]);
        }
        c.min_score[LIDET_CLASS_CAR] = 0.0f;
        c.car_min_z_spread_m = 1.0f;
        TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_detector_init(&g.ws, &c, &m_cls, &m_box));
        TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_detector_run(&g.ws, g_pts, g_n, 4, NULL, NULL));
        lidet_detector_detections(&g.ws, &n);
        TEST_ASSERT_EQUAL_UINT32(3, n);
        c.car_min_z_spread_m = 2.0f;
        TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_detector_init(&g.ws, &c, &m_cls, &m_box));
        TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_detector_run(&g.ws, g_pts, g_n, 4, NULL, NULL));
        lidet_detector_detections(&g.ws, &n);
        TEST_ASSERT_EQUAL_UINT32(0, n);
        TEST_ASSERT_EQUAL_UINT32(3, lidet_detector_stats(&g.ws)->n_size_rejected);
        oc = lidet_detector_outcomes(&g.ws, &nc);
        for (k2 = 0; k2 < nc; ++k2)
        {
            TEST_ASSERT_EQUAL_UINT8(LIDET_DET_OUT_SIZE, oc[k2]);
        }
    }
}

void test_crop_budget_range_and_gates(void)
{
    const lidet_detector_stats_t *s;
    const lidet_detection_t *d;
    uint32_t n = 0;
    scene();
    /* the gates and the size check alone: the operating point off (the gammas moved below make the scores tiny) */
    memset(cfg.min_score, 0, sizeof cfg.min_score);
    cfg.crop_half_rad = 0.25f * 3.14159265f;
    /* the crop's window on the clustering lifted (pi): C is clustered, then left out by the crop */
    cfg.stages.cluster.azimuth_half_rad = 3.14159265f;
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_detector_init(&g.ws, &cfg, &m_cls, &m_box));
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_detector_run(&g.ws, g_pts, g_n, 4, NULL, NULL));
    s = lidet_detector_stats(&g.ws);
    TEST_ASSERT_EQUAL_UINT32(3, s->n_clusters);
    TEST_ASSERT_EQUAL_UINT32(1, s->n_out_of_crop); /* C, behind */
    TEST_ASSERT_EQUAL_UINT32(2, s->n_classified);
    TEST_ASSERT_EQUAL_UINT32(0, s->stages.proj.n_out_of_window); /* the projection's window follows: none */
    {
        /* the default: the crop sets the clustering's window (crop + 15 deg) and the projection's (one ground
         * sector more): C's points are not projected, the same two detections come out, bit for bit */
        lidet_detection_t both[2];
        uint32_t n2 = 0, k, cand_all = s->stages.cluster.n_candidates;
        d = lidet_detector_detections(&g.ws, &n);
        TEST_ASSERT_EQUAL_UINT32(2, n);
        memcpy(both, d, sizeof both);
        cfg.stages.cluster.azimuth_half_rad = 0.0f;
        TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_detector_init(&g.ws, &cfg, &m_cls, &m_box));
        TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_detector_run(&g.ws, g_pts, g_n, 4, NULL, NULL));
        s = lidet_detector_stats(&g.ws);
        TEST_ASSERT_EQUAL_UINT32(2, s->n_clusters);
        TEST_ASSERT_EQUAL_UINT32(0, s->n_out_of_crop);
        TEST_ASSERT_TRUE(s->stages.cluster.n_candidates < cand_all);
        TEST_ASSERT_TRUE(s->stages.proj.n_out_of_window > 0u); /* C, behind, is not projected */
        d = lidet_detector_detections(&g.ws, &n2);
        TEST_ASSERT_EQUAL_UINT32(2, n2);
        {
            /* the same detections; only the cluster ids differ (C, no longer a cluster, had one of them) */
            lidet_detection_t win[2];
            memcpy(win, d, sizeof win);
            for (k = 0; k < 2u; ++k)
            {
                TEST_ASSERT_TRUE(win[k].cluster_id >= 1 && win[k].cluster_id <= 2);
                win[k].cluster_id = both[k].cluster_id;
            }
            TEST_ASSERT_EQUAL_MEMORY(both, win, sizeof both);
        }
    }

    /* budget of one: the nearest (B at 10 m, before A at ~10 m? B is at sqrt(100) = 10, A at 10): the
     * range ties break by cluster id; the other is over the budget and the status says so */
    cfg.crop_half_rad = 0.0f;
    cfg.max_proposals = 1;
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_detector_init(&g.ws, &cfg, &m_cls, &m_box));
    TEST_ASSERT_EQUAL_INT(LIDET_TRUNCATED, lidet_detector_run(&g.ws, g_pts, g_n, 4, NULL, NULL));
    s = lidet_detector_stats(&g.ws);
    d = lidet_detector_detections(&g.ws, &n);
    TEST_ASSERT_EQUAL_UINT32(2, s->n_over_budget);
    TEST_ASSERT_EQUAL_UINT32(1, n);
    {
        uint32_t nc = 0, k, nb = 0;
        const uint8_t *oc = lidet_detector_outcomes(&g.ws, &nc);
        for (k = 0; k < nc; ++k)
        {
            nb += oc[k] == LIDET_DET_OUT_BUDGET;
        }
        TEST_ASSERT_EQUAL_UINT32(2, nb);
        TEST_ASSERT_EQUAL_UINT8(LIDET_DET_OUT_DETECTED, oc[d[0].cluster_id - 1u]);
    }
    TEST_ASSERT_TRUE(d[0].box.cx_m > 0.0f); /* not C at 15 m */

    /* range limit 12 m drops C */
    cfg.max_proposals = 64;
    cfg.max_range_m = 12.0f;
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_detector_init(&g.ws, &cfg, &m_cls, &m_box));
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_detector_run(&g.ws, g_pts, g_n, 4, NULL, NULL));
    TEST_ASSERT_EQUAL_UINT32(1, lidet_detector_stats(&g.ws)->n_out_of_range);

    /* gate 1: a threshold below the energy rejects every proposal; gate off lets them through (the large-car
     * margin, 1 nat by default for this 64-beam sensor, off until its own check below) */
    cfg.max_range_m = 0.0f;
    cfg.gate1_large_car_margin = 0.0f;
    m_cls.gamma[0] = -6.0f;
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_detector_init(&g.ws, &cfg, &m_cls, &m_box));
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_detector_run(&g.ws, g_pts, g_n, 4, NULL, NULL));
    TEST_ASSERT_EQUAL_UINT32(3, lidet_detector_stats(&g.ws)->n_gate1_rejected);
    lidet_detector_detections(&g.ws, &n);
    TEST_ASSERT_EQUAL_UINT32(0, n);
    cfg.gate1 = 0;
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_detector_init(&g.ws, &cfg, &m_cls, &m_box));
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_detector_run(&g.ws, g_pts, g_n, 4, NULL, NULL));
    {
        /* the operating points: every gate-1 energy lies at or above gamma (-6); a margin that lifts gamma above
         * the largest lets all three through with the gate on, and gate 2 with its gamma 0.5 above the largest
         * box energy keeps all, then with a margin of -1 rejects at least that one */
        const lidet_detection_t *dd = lidet_detector_detections(&g.ws, &n);
        float e1 = -1e30f, e2 = -1e30f;
        uint32_t k;
        for (k = 0; k < n; ++k)
        {
            e1 = dd[k].energy_cls > e1 ? dd[k].energy_cls : e1;
            e2 = dd[k].energy_box > e2 ? dd[k].energy_box : e2;
        }
        TEST_ASSERT_EQUAL_UINT32(3, n);
        TEST_ASSERT_TRUE(e1 >= -6.0f && e1 < 12.0f);
        cfg.gate1 = 1;
        cfg.gate1_margin = e1 + 6.0f + 0.5f;
        TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_detector_init(&g.ws, &cfg, &m_cls, &m_box));
        TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_detector_run(&g.ws, g_pts, g_n, 4, NULL, NULL));
        TEST_ASSERT_EQUAL_UINT32(0, lidet_detector_stats(&g.ws)->n_gate1_rejected);
        lidet_detector_detections(&g.ws, &n);
        TEST_ASSERT_EQUAL_UINT32(3, n);
        {
            /* the same margin per class: given to the proposals' class (car) it lets them through, given to
             * another class it does not */
            lidet_detector_cfg_t c1 = cfg;
            c1.gate1_margin = 0.0f;
            c1.gate1_class_margin[LIDET_CLASS_CAR] = e1 + 6.0f + 0.5f;
            c1.gate1_class_margin[LIDET_CLASS_PEDESTRIAN] = 0.0f;
            TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_detector_init(&g.ws, &c1, &m_cls, &m_box));
            TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_detector_run(&g.ws, g_pts, g_n, 4, NULL, NULL));
            TEST_ASSERT_EQUAL_UINT32(0, lidet_detector_stats(&g.ws)->n_gate1_rejected);
            c1.gate1_class_margin[LIDET_CLASS_CAR] = 0.0f;
            c1.gate1_class_margin[LIDET_CLASS_PEDESTRIAN] = e1 + 6.0f + 0.5f;
            TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_detector_init(&g.ws, &c1, &m_cls, &m_box));
            TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_detector_run(&g.ws, g_pts, g_n, 4, NULL, NULL));
            TEST_ASSERT_EQUAL_UINT32(3, lidet_detector_stats(&g.ws)->n_gate1_rejected);
            /* the large-car margin: the car proposals of clusters of >= LIDET_DET_FLAT_MIN_POINTS members pass,
             * the smaller ones stay rejected */
            c1.gate1_class_margin[LIDET_CLASS_PEDESTRIAN] = 0.0f;
            c1.gate1_large_car_margin = e1 + 6.0f + 0.5f;
            TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_detector_init(&g.ws, &c1, &m_cls, &m_box));
            TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_detector_run(&g.ws, g_pts, g_n, 4, NULL, NULL));
            {
                uint32_t nl = 0, k2, big = 0;
                const lidet_detection_t *dl = lidet_detector_detections(&g.ws, &nl);
                for (k2 = 0; k2 < nl; ++k2)
                {
                    TEST_ASSERT_TRUE(dl[k2].n_points >= LIDET_DET_FLAT_MIN_POINTS);
                    big += 1u;
                }
                TEST_ASSERT_TRUE(big >= 1u);
                TEST_ASSERT_EQUAL_UINT32(3u - big, lidet_detector_stats(&g.ws)->n_gate1_rejected);
            }
            TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_detector_init(&g.ws, &cfg, &m_cls, &m_box));
        }
        m_box.gamma[0] = e2 + 0.5f;
        TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_detector_init(&g.ws, &cfg, &m_cls, &m_box));
        TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_detector_run(&g.ws, g_pts, g_n, 4, NULL, NULL));
        TEST_ASSERT_EQUAL_UINT32(0, lidet_detector_stats(&g.ws)->n_gate2_rejected);
        cfg.gate2_margin = -1.0f;
        TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_detector_init(&g.ws, &cfg, &m_cls, &m_box));
        TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_detector_run(&g.ws, g_pts, g_n, 4, NULL, NULL));
        TEST_ASSERT_TRUE(lidet_detector_stats(&g.ws)->n_gate2_rejected >= 1u);
        cfg.gate1_margin = 0.0f;
        cfg.gate2_margin = 0.0f;
        cfg.gate1 = 0;
    }
    /* gate 2 and the size check */
    m_box.gamma[0] = -100.0f;
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_detector_init(&g.ws, &cfg, &m_cls, &m_box));
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_detector_run(&g.ws, g_pts, g_n, 4, NULL, NULL));
    TEST_ASSERT_EQUAL_UINT32(3, lidet_detector_stats(&g.ws)->n_gate2_rejected);
    {
        /* gate 2 per class: the default judges cars and cyclists, not pedestrians; a class it does not judge
         * passes whatever its box energy (the three detections here are cars) */
        uint32_t nd;
        lidet_detector_cfg_t d0;
        lidet_detector_cfg_default(&d0, lidet_sensor_find("hdl64"));
        TEST_ASSERT_EQUAL_UINT8(1, d0.gate2_class[LIDET_CLASS_CAR]);
        TEST_ASSERT_EQUAL_UINT8(1, d0.gate2_class[LIDET_CLASS_CYCLIST]);
        TEST_ASSERT_EQUAL_UINT8(0, d0.gate2_class[LIDET_CLASS_PEDESTRIAN]);
        cfg.gate2_class[LIDET_CLASS_CAR] = 0;
        TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_detector_init(&g.ws, &cfg, &m_cls, &m_box));
        TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_detector_run(&g.ws, g_pts, g_n, 4, NULL, NULL));
        TEST_ASSERT_EQUAL_UINT32(0, lidet_detector_stats(&g.ws)->n_gate2_rejected);
        lidet_detector_detections(&g.ws, &nd);
        TEST_ASSERT_EQUAL_UINT32(3, nd);
        cfg.gate2_class[LIDET_CLASS_CAR] = 1;
    }
    m_box.gamma[0] = 100.0f;
    cfg.size_max_m[LIDET_CLASS_CAR][0] = 3.0f;
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_detector_init(&g.ws, &cfg, &m_cls, &m_box));
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_detector_run(&g.ws, g_pts, g_n, 4, NULL, NULL));
    TEST_ASSERT_EQUAL_UINT32(3, lidet_detector_stats(&g.ws)->n_size_rejected);
}

void test_nms_drops_overlapping_boxes(void)
{
    const lidet_detector_stats_t *s;
    uint32_t n = 0;
    /* two faces on one ray, 2.5 m apart: separate clusters whose car boxes (3.9 m long) overlap */
    g_n = 0;
    g_rng = 99u;
    {
        uint32_t i;
        for (i = 0; i < 60000; ++i)
        {
            add((frand() - 0.5f) * 60.0f, (frand() - 0.5f) * 60.0f, -1.73f);
        }
    }
    face(10.0f, 0.0f, 1.0f, 0.8f, 4000);
    face(12.5f, 0.0f, 3.0f, 2.0f, 8000);
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_detector_init(&g.ws, &cfg, &m_cls, &m_box));
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_detector_run(&g.ws, g_pts, g_n, 4, NULL, NULL));
    s = lidet_detector_stats(&g.ws);
    lidet_detector_detections(&g.ws, &n);
    TEST_ASSERT_TRUE(s->n_boxed >= 2);
    TEST_ASSERT_EQUAL_UINT32(s->n_boxed - s->n_nms_suppressed, n);
    TEST_ASSERT_TRUE(s->n_nms_suppressed >= 1);
    {
        uint32_t nc = 0, k, nn = 0;
        const uint8_t *oc = lidet_detector_outcomes(&g.ws, &nc);
        for (k = 0; k < nc; ++k)
        {
            nn += oc[k] == LIDET_DET_OUT_NMS;
        }
        TEST_ASSERT_EQUAL_UINT32(s->n_nms_suppressed, nn);
    }
    /* with the threshold at 1 nothing is suppressed */
    cfg.nms_iou = 1.0f;
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_detector_init(&g.ws, &cfg, &m_cls, &m_box));
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_detector_run(&g.ws, g_pts, g_n, 4, NULL, NULL));
    TEST_ASSERT_EQUAL_UINT32(0, lidet_detector_stats(&g.ws)->n_nms_suppressed);
}

void test_deterministic_and_empty(void)
{
    static lidet_detection_t first[LIDET_MAX_DETECTIONS];
    const lidet_detection_t *d;
    uint32_t n = 0, n2 = 0;
    scene();
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_detector_init(&g.ws, &cfg, &m_cls, &m_box));
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_detector_run(&g.ws, g_pts, g_n, 4, NULL, NULL));
    d = lidet_detector_detections(&g.ws, &n);
    memcpy(first, d, n * sizeof *d);
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_detector_run(&g.ws, g_pts, g_n, 4, NULL, NULL));
    d = lidet_detector_detections(&g.ws, &n2);
    TEST_ASSERT_EQUAL_UINT32(n, n2);
    TEST_ASSERT_EQUAL_MEMORY(first, d, n * sizeof *d);
    /* no points: no clusters, no detections, OK */
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_detector_run(&g.ws, g_pts, 0, 4, NULL, NULL));
    lidet_detector_detections(&g.ws, &n);
    TEST_ASSERT_EQUAL_UINT32(0, n);
    /* NaN points are counted by the projection, never crash the detector */
    g_pts[0] = g_pts[1] = g_pts[2] = NAN;
    TEST_ASSERT_TRUE(LIDET_SUCCEEDED(lidet_detector_run(&g.ws, g_pts, g_n, 4, NULL, NULL)));
    TEST_ASSERT_EQUAL_UINT32(1, lidet_detector_stats(&g.ws)->stages.proj.n_nonfinite);
}

void test_init_errors(void)
{
    lidet_detector_cfg_t c;
    lidet_pn_model_t other, other_box;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_ARG, lidet_detector_init(NULL, &cfg, &m_cls, &m_box));
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_ARG, lidet_detector_init(&g.ws, &cfg, NULL, &m_box));
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_MODEL,
                          lidet_detector_init(&g.ws, &cfg, &m_box, &m_cls)); /* kinds swapped */
    other = m_box;
    other.n_points = 32; /* another points-per-proposal setting */
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_MODEL, lidet_detector_init(&g.ws, &cfg, &m_cls, &other));
    other = m_box;
    other.pvle_bin[2] = 2.0f; /* trained on other voxels */
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_MODEL, lidet_detector_init(&g.ws, &cfg, &m_cls, &other));
    other = m_box;
    other.z_origin = (uint8_t)(m_cls.z_origin ^ 1u); /* trained on proposals from another z origin */
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_MODEL, lidet_detector_init(&g.ws, &cfg, &m_cls, &other));
    other = m_cls;
    other_box = m_box;
    other.z_origin = other_box.z_origin = 2u; /* not a lidet_proposal_z_origin_t */
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_MODEL, lidet_detector_init(&g.ws, &cfg, &other, &other_box));
    other = m_cls;
    other.format_version = 99;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_MODEL, lidet_detector_init(&g.ws, &cfg, &other, &m_box));
    c = cfg;
    c.max_proposals = 0;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_detector_init(&g.ws, &c, &m_cls, &m_box));
    c = cfg;
    c.nms_iou = NAN;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_detector_init(&g.ws, &c, &m_cls, &m_box));
    c = cfg;
    c.gate1_margin = NAN;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_detector_init(&g.ws, &c, &m_cls, &m_box));
    c = cfg;
    c.gate2_margin = 20.5f;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_detector_init(&g.ws, &c, &m_cls, &m_box));
    c = cfg;
    c.gate2_class[LIDET_CLASS_PEDESTRIAN] = 2; /* a flag: 0 or 1 */
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_detector_init(&g.ws, &c, &m_cls, &m_box));
    c = cfg;
    c.group_split = 2; /* a flag: 0 or 1 */
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_detector_init(&g.ws, &c, &m_cls, &m_box));
    c = cfg;
    c.group_max_range_m = -1.0f; /* [0, 1000] */
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_detector_init(&g.ws, &c, &m_cls, &m_box));
    c.group_max_range_m = NAN;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_detector_init(&g.ws, &c, &m_cls, &m_box));
    c = cfg;
    c.group_gate1_margin = -0.5f; /* [0, 20] */
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_detector_init(&g.ws, &c, &m_cls, &m_box));
    c.group_gate1_margin = 20.5f;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_detector_init(&g.ws, &c, &m_cls, &m_box));
    c.group_gate1_margin = NAN;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_detector_init(&g.ws, &c, &m_cls, &m_box));
    c.group_gate1_margin = 0.0f;
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_detector_init(&g.ws, &c, &m_cls, &m_box));
    c = cfg;
    c.min_score[LIDET_CLASS_PEDESTRIAN] = 1.5f; /* [0, 1] */
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_detector_init(&g.ws, &c, &m_cls, &m_box));
    c.min_score[LIDET_CLASS_PEDESTRIAN] = NAN;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_detector_init(&g.ws, &c, &m_cls, &m_box));
    c = cfg;
    c.gate1_class_margin[LIDET_CLASS_CYCLIST] = -20.5f; /* [-20, 20] */
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_detector_init(&g.ws, &c, &m_cls, &m_box));
    c.gate1_class_margin[LIDET_CLASS_CYCLIST] = NAN;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_detector_init(&g.ws, &c, &m_cls, &m_box));
    c = cfg;
    c.gate1_large_car_margin = -0.5f; /* [0, 20] */
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_detector_init(&g.ws, &c, &m_cls, &m_box));
    c.gate1_large_car_margin = 20.5f;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_detector_init(&g.ws, &c, &m_cls, &m_box));
    c.gate1_large_car_margin = NAN;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_detector_init(&g.ws, &c, &m_cls, &m_box));
    c.gate1_large_car_margin = 20.0f;
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_detector_init(&g.ws, &c, &m_cls, &m_box));
    c = cfg;
    c.car_min_z_spread_m = -0.1f; /* [0, 10] */
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_detector_init(&g.ws, &c, &m_cls, &m_box));
    c.car_min_z_spread_m = INFINITY;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_detector_init(&g.ws, &c, &m_cls, &m_box));
    c = cfg;
    c.car_ground_m = -0.1f; /* [0, 10] */
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_detector_init(&g.ws, &c, &m_cls, &m_box));
    c.car_ground_m = NAN;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_detector_init(&g.ws, &c, &m_cls, &m_box));
    c.car_ground_m = 10.5f;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_detector_init(&g.ws, &c, &m_cls, &m_box));
    {
        /* the group split, the large cars' gate and the flat-surface test: on for > 16 beams, off for <= 16; the
         * operating point and the car boxes' ground: the same for every sensor */
        lidet_detector_cfg_t d0;
        lidet_detector_cfg_default(&d0, lidet_sensor_find("hdl64"));
        TEST_ASSERT_EQUAL_UINT8(1, d0.group_split);
        TEST_ASSERT_EQUAL_FLOAT(40.0f, d0.group_max_range_m);
        TEST_ASSERT_EQUAL_FLOAT(2.0f, d0.group_gate1_margin);
        TEST_ASSERT_EQUAL_FLOAT(0.6f, d0.min_score[LIDET_CLASS_CAR]);
        TEST_ASSERT_EQUAL_FLOAT(0.0f, d0.min_score[LIDET_CLASS_CYCLIST]);
        TEST_ASSERT_EQUAL_FLOAT(0.0f, d0.min_score[LIDET_CLASS_PEDESTRIAN]);
        TEST_ASSERT_EQUAL_FLOAT(0.6f, d0.car_min_z_spread_m);
        TEST_ASSERT_EQUAL_FLOAT(1.0f, d0.car_ground_m);
        TEST_ASSERT_EQUAL_FLOAT(0.0f,
                                d0.gate1_class_margin[LIDET_CLASS_CAR]); /* gate 1: the models' thresholds */
        TEST_ASSERT_EQUAL_FLOAT(0.0f, d0.gate1_class_margin[LIDET_CLASS_CYCLIST]);
        TEST_ASSERT_EQUAL_FLOAT(0.0f, d0.gate1_class_margin[LIDET_CLASS_PEDESTRIAN]);
        TEST_ASSERT_EQUAL_FLOAT(LARGE_CAR_DEFAULT, d0.gate1_large_car_margin);
        lidet_detector_cfg_default(&d0, lidet_sensor_find("vlp16"));
        TEST_ASSERT_EQUAL_FLOAT(0.0f, d0.gate1_large_car_margin);
        TEST_ASSERT_EQUAL_UINT8(0, d0.group_split);
        TEST_ASSERT_EQUAL_FLOAT(0.0f, d0.gate1_class_margin[LIDET_CLASS_PEDESTRIAN]);
        TEST_ASSERT_EQUAL_FLOAT(0.6f, d0.min_score[LIDET_CLASS_CAR]);
        TEST_ASSERT_EQUAL_FLOAT(0.0f, d0.min_score[LIDET_CLASS_PEDESTRIAN]);
        TEST_ASSERT_EQUAL_FLOAT(0.0f, d0.car_min_z_spread_m);
        TEST_ASSERT_EQUAL_FLOAT(1.0f, d0.car_ground_m);
    }
    c = cfg;
    c.size_min_m[1][2] = 5.0f;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_detector_init(&g.ws, &c, &m_cls, &m_box));
    c = cfg;
    c.stages.cluster.theta_rad = -1.0f; /* a stage's own validation */
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_detector_init(&g.ws, &c, &m_cls, &m_box));
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_STATE, lidet_detector_run(&g.ws, g_pts, 0, 4, NULL, NULL));
    TEST_ASSERT_EQUAL_UINT32(sizeof(lidet_detector_t), lidet_detector_bytes());
}

void test_bev_iou_by_hand(void)
{
    lidet_box_t a, b;
    memset(&a, 0, sizeof a);
    a.l_m = 4.0f;
    a.w_m = 2.0f;
    a.h_m = 1.5f;
    b = a;
    TEST_ASSERT_CLOSE(1.0, lidet_box_bev_iou(&a, &b), 1e-5, 0);
    b.cx_m = 2.0f; /* half overlap: 4 / (8 + 8 - 4) */
    TEST_ASSERT_CLOSE(1.0 / 3.0, lidet_box_bev_iou(&a, &b), 1e-5, 0);
    b.cx_m = 10.0f;
    TEST_ASSERT_CLOSE(0.0, lidet_box_bev_iou(&a, &b), 0, 0);
    /* a 2 x 2 square and the same square turned 45 deg: intersection = the octagon, 8 (sqrt 2 - 1) */
    a.l_m = a.w_m = 2.0f;
    b = a;
    b.yaw_rad = 0.25f * 3.14159265f;
    {
        const double inter = 8.0 * (sqrt(2.0) - 1.0);
        TEST_ASSERT_CLOSE(inter / (8.0 - inter), lidet_box_bev_iou(&a, &b), 1e-4, 0);
    }
    b.l_m = 0.0f;
    TEST_ASSERT_CLOSE(0.0, lidet_box_bev_iou(&a, &b), 0, 0);
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_three_objects_three_cars);
    RUN_TEST(test_car_boxes_go_down_to_the_ground_near_and_behind);
    RUN_TEST(test_tall_clusters_are_not_classified);
    RUN_TEST(test_crop_budget_range_and_gates);
    RUN_TEST(test_nms_drops_overlapping_boxes);
    RUN_TEST(test_deterministic_and_empty);
    RUN_TEST(test_init_errors);
    RUN_TEST(test_bev_iou_by_hand);
    return UNITY_END();
}
