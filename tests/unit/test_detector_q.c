/* SPDX-License-Identifier: MIT */
/* Unity tests of the integer detector (lib/src/detector/lidet_detector_q.c) with the generated int8 models on
 * the shipped simulated VLP-16 scan (converted to millimetres here): init errors, the run's invariants (score
 * order, size limits, outcomes adding up to the counts), the crop and the budget, determinism, canaries,
 * and bad points (integer limits, zero range, rings out of range). Agreement with the float detector and the
 * bit-exact reference are tested in tests/python/test_detector_q.py. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "lidet/lidet.h"
#include "lidet/lidet_detector_q.h"
#include "lidet_weights.h"
#include "test_util.h"

LIDET_GUARDED(lidet_detector_q_t, g);

#define MAX_PTS 60000
static int32_t pts[MAX_PTS * 3];
static uint32_t n_pts;
static const lidet_pointnet_q_model_t *m_cls, *m_box;
static const lidet_sensor_q_t *sensor;

static void load_scan(void)
{
    static float raw[MAX_PTS * 4];
    FILE *f = fopen(LIDET_SOURCE_DIR "/tests/data/sim_vlp16/velodyne/000000.bin", "rb");
    size_t n, i;
    TEST_ASSERT_NOT_NULL(f);
    n = fread(raw, 4 * sizeof(float), MAX_PTS, f);
    fclose(f);
    TEST_ASSERT_TRUE(n > 1000);
    for (i = 0; i < 3 * n; ++i)
    {
        const float v = raw[4 * (i / 3) + i % 3] * 1000.0f;
        pts[i] = (int32_t)(v >= 0.0f ? v + 0.5f : v - 0.5f);
    }
    n_pts = (uint32_t)n;
}

void setUp(void)
{
    sensor = lidet_sensor_q_find("vlp16");
    m_cls = lidet_pointnet_q_find(lidet_weights_models_s8, LIDET_WEIGHTS_N_MODELS_S8, "cls_vlp16_s8");
    m_box = lidet_pointnet_q_find(lidet_weights_models_s8, LIDET_WEIGHTS_N_MODELS_S8, "box_vlp16_s8");
    if (n_pts == 0)
    {
        load_scan();
    }
}

void tearDown(void)
{
}

static lidet_status_t init_default(lidet_detector_q_cfg_t *cfg)
{
    lidet_detector_q_cfg_default(cfg, sensor);
    return lidet_detector_q_init(&g.ws, cfg, m_cls, m_box);
}

static void test_init_errors(void)
{
    lidet_detector_q_cfg_t cfg;
    TEST_ASSERT_NOT_NULL(sensor);
    TEST_ASSERT_NOT_NULL(m_cls);
    TEST_ASSERT_NOT_NULL(m_box);
    lidet_detector_q_cfg_default(&cfg, sensor);
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_ARG, lidet_detector_q_init(NULL, &cfg, m_cls, m_box));
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_ARG, lidet_detector_q_init(&g.ws, NULL, m_cls, m_box));
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_ARG, lidet_detector_q_init(&g.ws, &cfg, NULL, m_box));
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_MODEL,
                          lidet_detector_q_init(&g.ws, &cfg, m_box, m_cls)); /* kinds swapped */
    cfg.nms_iou_q15 = 32769;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_detector_q_init(&g.ws, &cfg, m_cls, m_box));
    lidet_detector_q_cfg_default(&cfg, sensor);
    cfg.gate1_margin_q16 = 20 * 65536 + 1; /* the gates' margins: within +-20 nats */
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_detector_q_init(&g.ws, &cfg, m_cls, m_box));
    cfg.gate1_margin_q16 = 20 * 65536;
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_detector_q_init(&g.ws, &cfg, m_cls, m_box));
    cfg.gate2_margin_q16 = INT32_MIN;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_detector_q_init(&g.ws, &cfg, m_cls, m_box));
    lidet_detector_q_cfg_default(&cfg, sensor);
    TEST_ASSERT_EQUAL_UINT8(1, cfg.gate2_class[LIDET_CLASS_CAR]); /* gate 2 judges cars and cyclists */
    TEST_ASSERT_EQUAL_UINT8(1, cfg.gate2_class[LIDET_CLASS_CYCLIST]);
    TEST_ASSERT_EQUAL_UINT8(0, cfg.gate2_class[LIDET_CLASS_PEDESTRIAN]);
    cfg.gate2_class[LIDET_CLASS_CAR] = 2; /* a flag: 0 or 1 */
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_detector_q_init(&g.ws, &cfg, m_cls, m_box));
    lidet_detector_q_cfg_default(&cfg, sensor);
    cfg.group_split = 2; /* a flag: 0 or 1 */
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_detector_q_init(&g.ws, &cfg, m_cls, m_box));
    lidet_detector_q_cfg_default(&cfg, sensor);
    cfg.group_max_range_mm = -1; /* [0, 10^6] */
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_detector_q_init(&g.ws, &cfg, m_cls, m_box));
    lidet_detector_q_cfg_default(&cfg, sensor);
    cfg.min_score_q15[LIDET_CLASS_CYCLIST] = 32769; /* [0, 32768] */
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_detector_q_init(&g.ws, &cfg, m_cls, m_box));
    cfg.min_score_q15[LIDET_CLASS_CYCLIST] = -1;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_detector_q_init(&g.ws, &cfg, m_cls, m_box));
    lidet_detector_q_cfg_default(&cfg, sensor);
    cfg.gate1_class_margin_q16[LIDET_CLASS_PEDESTRIAN] = 20 * 65536 + 1; /* [-20, 20] nats */
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_detector_q_init(&g.ws, &cfg, m_cls, m_box));
    cfg.gate1_class_margin_q16[LIDET_CLASS_PEDESTRIAN] = -20 * 65536;
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_detector_q_init(&g.ws, &cfg, m_cls, m_box));
    lidet_detector_q_cfg_default(&cfg, sensor);
    cfg.gate1_large_car_margin_q16 = 20 * 65536 + 1; /* [0, 20] nats */
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_detector_q_init(&g.ws, &cfg, m_cls, m_box));
    cfg.gate1_large_car_margin_q16 = -1;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_detector_q_init(&g.ws, &cfg, m_cls, m_box));
    cfg.gate1_large_car_margin_q16 = 20 * 65536;
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_detector_q_init(&g.ws, &cfg, m_cls, m_box));
    lidet_detector_q_cfg_default(&cfg, sensor);
    cfg.group_gate1_margin_q16 = 20 * 65536 + 1; /* [0, 20] nats */
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_detector_q_init(&g.ws, &cfg, m_cls, m_box));
    cfg.group_gate1_margin_q16 = -1;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_detector_q_init(&g.ws, &cfg, m_cls, m_box));
    cfg.group_gate1_margin_q16 = 0;
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_detector_q_init(&g.ws, &cfg, m_cls, m_box));
    lidet_detector_q_cfg_default(&cfg, sensor);
    cfg.car_min_z_spread_mm = 10001; /* [0, 10000] */
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_detector_q_init(&g.ws, &cfg, m_cls, m_box));
    cfg.car_min_z_spread_mm = -1;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_detector_q_init(&g.ws, &cfg, m_cls, m_box));
    lidet_detector_q_cfg_default(&cfg, sensor);
    cfg.car_ground_mm = 10001; /* [0, 10000] */
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_detector_q_init(&g.ws, &cfg, m_cls, m_box));
    cfg.car_ground_mm = -1;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_detector_q_init(&g.ws, &cfg, m_cls, m_box));
    cfg.car_ground_mm = 1000; /* a build that does not keep the ground mask past the clustering refuses it */
    TEST_ASSERT_EQUAL_INT(LIDET_Q_PIXEL_XYZ ? LIDET_OK : LIDET_ERR_CONFIG,
                          lidet_detector_q_init(&g.ws, &cfg, m_cls, m_box));
    /* the group split, the operating point and the flat-surface test: on for > 16 rows, off for <= 16 */
    lidet_detector_q_cfg_default(&cfg, lidet_sensor_q_find("hdl64"));
    TEST_ASSERT_EQUAL_UINT8(1, cfg.group_split);
    TEST_ASSERT_EQUAL_INT32(40000, cfg.group_max_range_mm);
    TEST_ASSERT_EQUAL_INT32(2 * 65536, cfg.group_gate1_margin_q16);
    TEST_ASSERT_EQUAL_INT32(19661, cfg.min_score_q15[LIDET_CLASS_CAR]);
    TEST_ASSERT_EQUAL_INT32(0, cfg.min_score_q15[LIDET_CLASS_CYCLIST]);
    TEST_ASSERT_EQUAL_INT32(0, cfg.min_score_q15[LIDET_CLASS_PEDESTRIAN]);
    TEST_ASSERT_EQUAL_INT32(600, cfg.car_min_z_spread_mm);
    TEST_ASSERT_EQUAL_INT32(LIDET_Q_PIXEL_XYZ ? 1000 : 0, cfg.car_ground_mm);
    TEST_ASSERT_EQUAL_INT32(0,
                            cfg.gate1_class_margin_q16[LIDET_CLASS_CAR]); /* gate 1: the models' thresholds */
    TEST_ASSERT_EQUAL_INT32(0, cfg.gate1_class_margin_q16[LIDET_CLASS_CYCLIST]);
    TEST_ASSERT_EQUAL_INT32(0, cfg.gate1_class_margin_q16[LIDET_CLASS_PEDESTRIAN]);
    lidet_detector_q_cfg_default(&cfg, lidet_sensor_q_find("vlp16"));
    TEST_ASSERT_EQUAL_UINT8(0, cfg.group_split);
    TEST_ASSERT_EQUAL_INT32(0, cfg.gate1_class_margin_q16[LIDET_CLASS_PEDESTRIAN]);
    TEST_ASSERT_EQUAL_INT32(19661, cfg.min_score_q15[LIDET_CLASS_CAR]); /* the same for every sensor */
    TEST_ASSERT_EQUAL_INT32(0, cfg.min_score_q15[LIDET_CLASS_PEDESTRIAN]);
    TEST_ASSERT_EQUAL_INT32(0, cfg.car_min_z_spread_mm);
    TEST_ASSERT_EQUAL_INT32(LIDET_Q_PIXEL_XYZ ? 1000 : 0, cfg.car_ground_mm);
    TEST_ASSERT_EQUAL_INT32(0, cfg.gate1_large_car_margin_q16);
    lidet_detector_q_cfg_default(&cfg, sensor);
    cfg.max_proposals = 0;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_detector_q_init(&g.ws, &cfg, m_cls, m_box));
    lidet_detector_q_cfg_default(&cfg, sensor);
    cfg.max_height_extent_mm = -1; /* [0, 100000] */
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_detector_q_init(&g.ws, &cfg, m_cls, m_box));
    cfg.max_height_extent_mm = 100001;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_detector_q_init(&g.ws, &cfg, m_cls, m_box));
    lidet_detector_q_cfg_default(&cfg, sensor); /* the score's weight on gate 2's margin: [0, 4] in Q16 */
    TEST_ASSERT_EQUAL_INT32(32768, cfg.score_box_weight_q16[LIDET_CLASS_CAR]);
    TEST_ASSERT_EQUAL_INT32(0, cfg.score_box_weight_q16[LIDET_CLASS_PEDESTRIAN]);
    cfg.score_box_weight_q16[LIDET_CLASS_CYCLIST] = 4 * 65536;
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_detector_q_init(&g.ws, &cfg, m_cls, m_box));
    cfg.score_box_weight_q16[LIDET_CLASS_CYCLIST] = 4 * 65536 + 1;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_detector_q_init(&g.ws, &cfg, m_cls, m_box));
    cfg.score_box_weight_q16[LIDET_CLASS_CYCLIST] = -1;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_detector_q_init(&g.ws, &cfg, m_cls, m_box));
    cfg.score_box_weight_q16[LIDET_CLASS_CYCLIST] = 0;
    TEST_ASSERT_EQUAL_INT32(6554, cfg.score_points_weight_q16[LIDET_CLASS_CAR]);
    cfg.score_points_weight_q16[LIDET_CLASS_PEDESTRIAN] = 4 * 65536 + 1;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_detector_q_init(&g.ws, &cfg, m_cls, m_box));
    lidet_detector_q_cfg_default(&cfg, sensor);
    cfg.max_height_extent_mm = 0; /* no limit */
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_detector_q_init(&g.ws, &cfg, m_cls, m_box));
    lidet_detector_q_cfg_default(&cfg, sensor);
    cfg.size.min_mm[0][0] = 9000; /* min above max */
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_detector_q_init(&g.ws, &cfg, m_cls, m_box));
    lidet_detector_q_cfg_default(&cfg, sensor);
    cfg.proposal.range_bin_4mm = 500; /* 2 m voxels: not what the models were trained with */
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_MODEL, lidet_detector_q_init(&g.ws, &cfg, m_cls, m_box));
    lidet_detector_q_cfg_default(&cfg, sensor);
    {
        /* models trained on proposals from different z origins, or from none lidet knows */
        static lidet_pointnet_q_model_t zc, zb;
        zc = *m_cls;
        zb = *m_box;
        zb.z_origin = (uint8_t)(zc.z_origin ^ 1u);
        TEST_ASSERT_EQUAL_INT(LIDET_ERR_MODEL, lidet_detector_q_init(&g.ws, &cfg, &zc, &zb));
        zc.z_origin = zb.z_origin = 2u;
        TEST_ASSERT_EQUAL_INT(LIDET_ERR_MODEL, lidet_detector_q_init(&g.ws, &cfg, &zc, &zb));
        zc.z_origin = zb.z_origin = LIDET_PROPOSAL_Z_GROUND; /* both from the ground: accepted */
        TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_detector_q_init(&g.ws, &cfg, &zc, &zb));
        TEST_ASSERT_EQUAL_UINT32(LIDET_PROPOSAL_Z_GROUND, g.ws.cfg.proposal.z_origin);
        zb.z_origin = LIDET_PROPOSAL_Z_MEAN; /* a failed init leaves the state unusable again */
        TEST_ASSERT_EQUAL_INT(LIDET_ERR_MODEL, lidet_detector_q_init(&g.ws, &cfg, &zc, &zb));
    }
    /* a run before a successful init */
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_STATE, lidet_detector_q_run(&g.ws, pts, n_pts, 3, NULL, NULL));
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_ARG, lidet_detector_q_run(NULL, pts, n_pts, 3, NULL, NULL));
}

static void check_invariants(const lidet_detector_q_cfg_t *cfg)
{
    uint32_t n, nc, i, counts[LIDET_DET_OUT_SCORE + 1] = {0};
    const lidet_detection_q_t *d = lidet_detector_q_detections(&g.ws, &n);
    const uint8_t *oc = lidet_detector_q_outcomes(&g.ws, &nc);
    const lidet_detector_q_stats_t *st = lidet_detector_q_stats(&g.ws);
    TEST_ASSERT_EQUAL_UINT32(st->n_detections, n);
    TEST_ASSERT_EQUAL_UINT32(st->n_clusters, nc);
    for (i = 0; i < n; ++i)
    {
        TEST_ASSERT_TRUE(d[i].score_q15 > 0 && d[i].score_q15 <= 32768);
        TEST_ASSERT_TRUE(lidet_size_ok_q(&cfg->size, d[i].cls, &d[i].box));
        TEST_ASSERT_TRUE(d[i].cluster_id >= 1 && d[i].cluster_id <= nc);
        TEST_ASSERT_EQUAL_UINT8(LIDET_DET_OUT_DETECTED, oc[d[i].cluster_id - 1u]);
        if (cfg->gate1)
        {
            TEST_ASSERT_TRUE(d[i].energy_cls_q16 < m_cls->gamma_q16[d[i].cls]);
        }
        if (i > 0)
        {
            TEST_ASSERT_TRUE(d[i - 1].score_q15 > d[i].score_q15 ||
                             (d[i - 1].score_q15 == d[i].score_q15 && d[i - 1].cluster_id < d[i].cluster_id));
        }
    }
    for (i = 0; i < nc; ++i)
    {
        TEST_ASSERT_TRUE(oc[i] >= 1 && oc[i] <= LIDET_DET_OUT_SCORE);
        ++counts[oc[i]];
    }
    TEST_ASSERT_EQUAL_UINT32(st->n_out_of_crop, counts[LIDET_DET_OUT_CROP]);
    TEST_ASSERT_EQUAL_UINT32(st->n_out_of_range, counts[LIDET_DET_OUT_RANGE]);
    TEST_ASSERT_EQUAL_UINT32(st->n_over_budget + st->n_over_box_budget, counts[LIDET_DET_OUT_BUDGET]);
    /* a cluster the group split cut keeps its rejection's count and has the outcome GROUP */
    TEST_ASSERT_TRUE(counts[LIDET_DET_OUT_GATE1] <= st->n_gate1_rejected);
    TEST_ASSERT_TRUE(counts[LIDET_DET_OUT_GATE2] <= st->n_gate2_rejected);
    TEST_ASSERT_TRUE(counts[LIDET_DET_OUT_SIZE] <= st->n_size_rejected);
    TEST_ASSERT_TRUE(counts[LIDET_DET_OUT_SCORE] <= st->n_score_rejected);
    TEST_ASSERT_EQUAL_UINT32(
        st->n_gate1_rejected + st->n_gate2_rejected + st->n_size_rejected + st->n_score_rejected,
        counts[LIDET_DET_OUT_GATE1] + counts[LIDET_DET_OUT_GATE2] + counts[LIDET_DET_OUT_SIZE] +
            counts[LIDET_DET_OUT_SCORE] + counts[LIDET_DET_OUT_GROUP]);
    TEST_ASSERT_EQUAL_UINT32(st->n_group_split, counts[LIDET_DET_OUT_GROUP]);
    TEST_ASSERT_TRUE(st->n_boxed + st->n_group_boxed <= cfg->max_boxes);
    TEST_ASSERT_TRUE(counts[LIDET_DET_OUT_NMS] <= st->n_nms_suppressed); /* a group keeps its outcome */
    TEST_ASSERT_TRUE(counts[LIDET_DET_OUT_DETECTED] <= n); /* a group's parts are detections of one cluster */
    TEST_ASSERT_EQUAL_UINT32(st->n_too_tall, counts[LIDET_DET_OUT_TALL]);
    TEST_ASSERT_EQUAL_UINT32(st->n_classified, st->n_gate1_rejected + st->n_over_box_budget + st->n_boxed);
    TEST_ASSERT_TRUE(st->n_boxed <= cfg->max_boxes);
}

static void test_run_invariants_and_determinism(void)
{
    static lidet_detection_q_t first[LIDET_MAX_DETECTIONS];
    lidet_detector_q_cfg_t cfg;
    uint32_t n1, n2;
    CANARY_FILL(g);
    TEST_ASSERT_EQUAL_INT(LIDET_OK, init_default(&cfg));
    TEST_ASSERT_TRUE(LIDET_SUCCEEDED(lidet_detector_q_run(&g.ws, pts, n_pts, 3, NULL, NULL)));
    check_invariants(&cfg);
    memcpy(first, lidet_detector_q_detections(&g.ws, &n1), sizeof first);
    TEST_ASSERT_TRUE(n1 >= 3); /* the sample holds cars and pedestrians the float detector finds */
    TEST_ASSERT_TRUE(LIDET_SUCCEEDED(lidet_detector_q_run(&g.ws, pts, n_pts, 3, NULL, NULL)));
    TEST_ASSERT_EQUAL_MEMORY(first, lidet_detector_q_detections(&g.ws, &n2), n1 * sizeof first[0]);
    TEST_ASSERT_EQUAL_UINT32(n1, n2);
    CANARY_CHECK(g);
}

static void test_crop_and_budget(void)
{
    lidet_detector_q_cfg_t cfg;
    uint32_t n, i, all;
    const lidet_detection_q_t *d;
    TEST_ASSERT_EQUAL_INT(LIDET_OK, init_default(&cfg));
    TEST_ASSERT_TRUE(LIDET_SUCCEEDED(lidet_detector_q_run(&g.ws, pts, n_pts, 3, NULL, NULL)));
    /* the candidates: every cluster not taller than max_height_extent_mm (the sample has such clusters) */
    TEST_ASSERT_EQUAL_INT32(2500, cfg.max_height_extent_mm);
    TEST_ASSERT_TRUE(lidet_detector_q_stats(&g.ws)->n_too_tall > 0u);
    all = lidet_detector_q_stats(&g.ws)->n_clusters - lidet_detector_q_stats(&g.ws)->n_too_tall;
    lidet_detector_q_cfg_default(&cfg, sensor);
    cfg.crop_half_bam = 1 << 29; /* 45 degrees */
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_detector_q_init(&g.ws, &cfg, m_cls, m_box));
    TEST_ASSERT_TRUE(LIDET_SUCCEEDED(lidet_detector_q_run(&g.ws, pts, n_pts, 3, NULL, NULL)));
    check_invariants(&cfg);
    TEST_ASSERT_TRUE(lidet_detector_q_stats(&g.ws)->n_out_of_crop > all / 2u);
    d = lidet_detector_q_detections(&g.ws, &n);
    for (i = 0; i < n; ++i) /* the window is on the cluster mean; a box centre stays close to it */
    {
        TEST_ASSERT_TRUE(d[i].box.cx_mm > 0);
        TEST_ASSERT_TRUE(abs(d[i].box.cy_mm) <= d[i].box.cx_mm + 2000);
    }
    lidet_detector_q_cfg_default(&cfg, sensor);
    cfg.max_proposals = 3;
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_detector_q_init(&g.ws, &cfg, m_cls, m_box));
    TEST_ASSERT_EQUAL_INT(LIDET_TRUNCATED, lidet_detector_q_run(&g.ws, pts, n_pts, 3, NULL, NULL));
    check_invariants(&cfg);
    TEST_ASSERT_EQUAL_UINT32(3u, lidet_detector_q_stats(&g.ws)->n_classified);
    TEST_ASSERT_EQUAL_UINT32(all - 3u, lidet_detector_q_stats(&g.ws)->n_over_budget);
    lidet_detector_q_cfg_default(&cfg, sensor);
    cfg.gate1 = 0;
    cfg.gate2 = 0;
    cfg.max_boxes = LIDET_MAX_CLUSTERS;
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_detector_q_init(&g.ws, &cfg, m_cls, m_box));
    TEST_ASSERT_TRUE(LIDET_SUCCEEDED(lidet_detector_q_run(&g.ws, pts, n_pts, 3, NULL, NULL)));
    check_invariants(&cfg);
    TEST_ASSERT_EQUAL_UINT32(all, lidet_detector_q_stats(&g.ws)->n_boxed);
    /* the box budget (issue 19): gate 1 off, so every candidate reaches it; the first max_boxes nearest are
     * boxed, the rest counted, LIDET_TRUNCATED */
    cfg.max_boxes = 2;
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_detector_q_init(&g.ws, &cfg, m_cls, m_box));
    TEST_ASSERT_EQUAL_INT(LIDET_TRUNCATED, lidet_detector_q_run(&g.ws, pts, n_pts, 3, NULL, NULL));
    check_invariants(&cfg);
    TEST_ASSERT_EQUAL_UINT32(2u, lidet_detector_q_stats(&g.ws)->n_boxed);
    TEST_ASSERT_EQUAL_UINT32(all - 2u, lidet_detector_q_stats(&g.ws)->n_over_box_budget);
    cfg.max_boxes = 0;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_detector_q_init(&g.ws, &cfg, m_cls, m_box));
    cfg.max_boxes = LIDET_MAX_CLUSTERS + 1u;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_detector_q_init(&g.ws, &cfg, m_cls, m_box));
}

static void test_bad_points(void)
{
    static int32_t bad[3 * 4000];
    static uint16_t ring[4000];
    lidet_detector_q_cfg_t cfg;
    uint32_t i, n;
    lidet_status_t s;
    for (i = 0; i < 4000u; ++i)
    {
        const int32_t v[6] = {INT32_MAX, INT32_MIN, 0, 131000, -131001, 1};
        bad[3 * i] = v[i % 6u];
        bad[3 * i + 1] = v[(i / 6u) % 6u];
        bad[3 * i + 2] = v[(i / 36u) % 6u];
        ring[i] = (uint16_t)(i * 7919u);
    }
    CANARY_FILL(g);
    TEST_ASSERT_EQUAL_INT(LIDET_OK, init_default(&cfg));
    s = lidet_detector_q_run(&g.ws, bad, 4000, 3, NULL, NULL);
    TEST_ASSERT_TRUE(LIDET_SUCCEEDED(s));
    s = lidet_detector_q_run(&g.ws, bad, 4000, 3, ring, NULL);
    TEST_ASSERT_TRUE(LIDET_SUCCEEDED(s));
    TEST_ASSERT_TRUE(lidet_detector_q_stats(&g.ws)->proj.n_bad_ring > 0u);
    s = lidet_detector_q_run(&g.ws, bad, 0, 3, NULL, NULL); /* empty scan */
    TEST_ASSERT_TRUE(LIDET_SUCCEEDED(s));
    lidet_detector_q_detections(&g.ws, &n);
    TEST_ASSERT_EQUAL_UINT32(0u, n);
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_ARG,
                          lidet_detector_q_run(&g.ws, bad, 10, 2, NULL, NULL)); /* stride < 3 */
    CANARY_CHECK(g);
}

/* the scan as the sensor's returns (ring by elevation order of the vlp16 profile, as the simulator wrote it) */
#define MAX_RET (LIDET_MAX_POINTS + 4096)
static lidet_return_t ret[MAX_RET];
static int32_t pix_all[LIDET_MAX_POINTS], pix_chunk[MAX_RET];

static uint32_t make_returns(void)
{
    static uint16_t ring[MAX_PTS];
    FILE *f = fopen(LIDET_SOURCE_DIR "/tests/data/sim_vlp16/ring/000000.bin", "rb");
    uint32_t i;
    size_t n;
    TEST_ASSERT_NOT_NULL(f);
    n = fread(ring, sizeof ring[0], MAX_PTS, f);
    fclose(f);
    TEST_ASSERT_EQUAL_UINT32(n_pts, (uint32_t)n);
    for (i = 0; i < n_pts; ++i)
    {
        const double x = pts[3 * i], y = pts[3 * i + 1], z = pts[3 * i + 2];
        const double a = atan2(y, x) * 65536.0 / (2.0 * 3.14159265358979323846);
        ret[i].range_mm = (uint32_t)(sqrt(x * x + y * y + z * z) + 0.5);
        ret[i].azimuth = (uint16_t)(int32_t)floor(a + 0.5);
        ret[i].ring = ring[i];
    }
    return n_pts;
}

/* everything a run leaves behind, but the clock */
typedef struct
{
    lidet_status_t s;
    uint32_t n_det, n_out;
    lidet_detection_q_t det[LIDET_MAX_DETECTIONS];
    uint8_t out[LIDET_MAX_CLUSTERS];
    lidet_detector_q_stats_t st;
    uint16_t range[LIDET_MAX_ROWS * LIDET_MAX_COLS];
} run_t;

static void keep(run_t *r, lidet_status_t s)
{
    const lidet_detection_q_t *d = lidet_detector_q_detections(&g.ws, &r->n_det);
    const uint8_t *o = lidet_detector_q_outcomes(&g.ws, &r->n_out);
    memset(r->det, 0, sizeof r->det);
    memset(r->out, 0, sizeof r->out);
    r->s = s;
    memcpy(r->det, d, r->n_det * sizeof d[0]);
    memcpy(r->out, o, r->n_out);
    r->st = *lidet_detector_q_stats(&g.ws);
    memset(r->st.ticks, 0, sizeof r->st.ticks);
    memcpy(r->range, g.ws.range_4mm, sizeof r->range);
}

static void same_run(const run_t *a, const run_t *b)
{
    TEST_ASSERT_EQUAL_INT(a->s, b->s);
    TEST_ASSERT_EQUAL_UINT32(a->n_det, b->n_det);
    TEST_ASSERT_EQUAL_UINT32(a->n_out, b->n_out);
    TEST_ASSERT_EQUAL_MEMORY(a->det, b->det, sizeof a->det);
    TEST_ASSERT_EQUAL_MEMORY(a->out, b->out, sizeof a->out);
    TEST_ASSERT_EQUAL_MEMORY(&a->st, &b->st, sizeof a->st);
    TEST_ASSERT_EQUAL_MEMORY(a->range, b->range, sizeof a->range);
}

/* the returns streamed in chunks of the sizes cycled from sizes[] (0 included): each chunk's pixels into its own
 * slice of pix_chunk */
static lidet_status_t stream(uint32_t n, const uint32_t *sizes, uint32_t n_sizes)
{
    uint32_t at = 0, k = 0;
    lidet_status_t s, worst = LIDET_OK;
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_detector_q_stream_begin(&g.ws));
    while (at < n)
    {
        uint32_t m = sizes[k++ % n_sizes];
        m = m < n - at ? m : n - at;
        s = lidet_detector_q_stream_returns(&g.ws, ret + at, m, pix_chunk + at);
        TEST_ASSERT_TRUE(LIDET_SUCCEEDED(s));
        worst = s != LIDET_OK ? s : worst;
        at += m;
    }
    s = lidet_detector_q_stream_end(&g.ws);
    TEST_ASSERT_TRUE(s == worst || (worst == LIDET_OK && LIDET_SUCCEEDED(s)));
    return s;
}

static void test_streamed_returns_equal_the_whole_scan(void)
{
    static run_t whole, part;
    static const uint32_t packets[] = {384u};                     /* a VLP-16 payload's returns */
    static const uint32_t odd[] = {1u, 0u, 7u, 1000u, 3u, 5000u}; /* empty and uneven chunks */
    lidet_detector_q_cfg_t cfg;
    uint32_t n = make_returns(), mode, i;
    for (mode = 0; mode < 2; ++mode) /* the range-only image (the firmware's), then x, y, z stored */
    {
        lidet_detector_q_cfg_default(&cfg, sensor);
        cfg.range_only = (uint8_t)(mode == 0);
        CANARY_FILL(g);
        TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_detector_q_init(&g.ws, &cfg, m_cls, m_box));
        keep(&whole, lidet_detector_q_run_returns(&g.ws, ret, n, pix_all));
        TEST_ASSERT_TRUE(LIDET_SUCCEEDED(whole.s));
        TEST_ASSERT_TRUE(whole.n_det >= 3);
        keep(&part, stream(n, packets, 1));
        same_run(&whole, &part);
        TEST_ASSERT_EQUAL_MEMORY(pix_all, pix_chunk, n * sizeof pix_all[0]);
        memset(pix_chunk, 0x5A, sizeof pix_chunk);
        keep(&part, stream(n, odd, 6));
        same_run(&whole, &part);
        TEST_ASSERT_EQUAL_MEMORY(pix_all, pix_chunk, n * sizeof pix_all[0]);
        /* the scan in reverse order of its packets (a seam elsewhere): the same image and detections */
        TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_detector_q_stream_begin(&g.ws));
        for (i = (n + 383u) / 384u; i-- > 0;)
        {
            const uint32_t a = 384u * i, m = n - a < 384u ? n - a : 384u;
            TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_detector_q_stream_returns(&g.ws, ret + a, m, NULL));
        }
        keep(&part, lidet_detector_q_stream_end(&g.ws));
        same_run(&whole, &part);
        CANARY_CHECK(g);
    }
}

/* ---- stream_sectors: the ground stage while the scan streams in ---- */
static lidet_return_t sret[LIDET_MAX_POINTS];

/* the simulated scan `name` (vlp16 or hdl64, its first frame) as returns into sret, in the order a spinning sensor
 * sends them: by image column from the one of azimuth seam_bam (dir +1: columns upwards, -1: downwards) */
static uint32_t sorted_returns(const char *name, int dir, uint16_t seam_bam)
{
    static float raw[LIDET_MAX_POINTS * 4];
    static uint16_t ring[LIDET_MAX_POINTS];
    static uint32_t key[LIDET_MAX_POINTS];
    char path[512];
    FILE *f;
    size_t n, i, k;
    snprintf(path, sizeof path, LIDET_SOURCE_DIR "/tests/data/sim_%s/velodyne/000000.bin", name);
    f = fopen(path, "rb");
    TEST_ASSERT_NOT_NULL(f);
    n = fread(raw, 4 * sizeof(float), LIDET_MAX_POINTS, f);
    fclose(f);
    snprintf(path, sizeof path, LIDET_SOURCE_DIR "/tests/data/sim_%s/ring/000000.bin", name);
    f = fopen(path, "rb");
    TEST_ASSERT_NOT_NULL(f);
    TEST_ASSERT_EQUAL_UINT32((uint32_t)n, (uint32_t)fread(ring, sizeof ring[0], LIDET_MAX_POINTS, f));
    fclose(f);
    TEST_ASSERT_TRUE(n > 1000u);
    for (i = 0; i < n; ++i)
    {
        const double x = 1000.0 * (double)raw[4 * i], y = 1000.0 * (double)raw[4 * i + 1],
                     z = 1000.0 * (double)raw[4 * i + 2];
        const double a = atan2(y, x) * 65536.0 / (2.0 * 3.14159265358979323846);
        lidet_return_t r;
        r.range_mm = (uint32_t)(sqrt(x * x + y * y + z * z) + 0.5);
        r.azimuth = (uint16_t)(int32_t)floor(a + 0.5);
        r.ring = ring[i];
        sret[i] = r;
        /* the column order from the seam's column: (2^15 - azimuth) mod 2^16 from the seam's, mod 2^16 */
        key[i] = (uint32_t)(uint16_t)((uint16_t)(0x8000u - r.azimuth) - (uint16_t)(0x8000u - seam_bam));
        if (dir < 0)
        {
            key[i] = (uint32_t)(uint16_t)(0u - key[i]);
        }
    }
    /* insertion sort by key, stable (the firmware's packets keep their firing order within a column) */
    for (i = 1; i < n; ++i)
    {
        const lidet_return_t r = sret[i];
        const uint32_t kk = key[i];
        for (k = i; k > 0 && key[k - 1] > kk; --k)
        {
            sret[k] = sret[k - 1];
            key[k] = key[k - 1];
        }
        sret[k] = r;
        key[k] = kk;
    }
    return (uint32_t)n;
}

/* sret[0, n) streamed in chunks of `chunk` (chunk_order: 0 in order, 1 every other chunk held back to the end) */
static lidet_status_t stream_sret(uint32_t n, uint32_t chunk, int held_back)
{
    uint32_t a, pass;
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_detector_q_stream_begin(&g.ws));
    for (pass = 0; pass < (held_back ? 2u : 1u); ++pass)
    {
        for (a = 0; a < n; a += chunk)
        {
            const uint32_t m = n - a < chunk ? n - a : chunk;
            if (held_back && ((a / chunk) & 1u) != pass)
            {
                continue;
            }
            TEST_ASSERT_TRUE(LIDET_SUCCEEDED(lidet_detector_q_stream_returns(&g.ws, sret + a, m, NULL)));
        }
    }
    return lidet_detector_q_stream_end(&g.ws);
}

static void test_streamed_sectors_equal_the_whole_scan(void)
{
    static run_t whole, part;
    static const char *const names[] = {"vlp16", "hdl64"};
    lidet_detector_q_cfg_t cfg;
    uint32_t k, n;
    for (k = 0; k < 2u; ++k)
    {
        const lidet_sensor_q_t *sn = lidet_sensor_q_find(names[k]);
        const lidet_pointnet_q_model_t *mc = lidet_pointnet_q_find(
            lidet_weights_models_s8, LIDET_WEIGHTS_N_MODELS_S8, k == 0 ? "cls_vlp16_s8" : "cls_hdl64_s8");
        const lidet_pointnet_q_model_t *mb = lidet_pointnet_q_find(
            lidet_weights_models_s8, LIDET_WEIGHTS_N_MODELS_S8, k == 0 ? "box_vlp16_s8" : "box_hdl64_s8");
        uint32_t ns, dir;
        TEST_ASSERT_NOT_NULL(sn);
        TEST_ASSERT_NOT_NULL(mc);
        TEST_ASSERT_NOT_NULL(mb);
        lidet_detector_q_cfg_default(&cfg, sn);
        cfg.stream_sectors = 1u;
        cfg.range_only = 0u; /* the streamed ground needs the range-only image */
        TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_detector_q_init(&g.ws, &cfg, mc, mb));
        cfg.range_only = 1u;
        cfg.stream_sectors = 2u;
        TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_detector_q_init(&g.ws, &cfg, mc, mb));
        cfg.stream_sectors = 1u;
        CANARY_FILL(g);
        TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_detector_q_init(&g.ws, &cfg, mc, mb));
        TEST_ASSERT_EQUAL_UINT8(1u, g.ws.cfg.ground.seed_per_cell);
        ns = g.ws.cfg.ground.n_sectors;
        for (dir = 0; dir < 2u; ++dir)
        {
            /* a seam 30 degrees off the image's first column, columns up (Velodyne) or down */
            n = sorted_returns(names[k], dir == 0u ? 1 : -1, (uint16_t)(0x8000u + 5461u));
            keep(&whole, lidet_detector_q_run_returns(&g.ws, sret, n, NULL));
            TEST_ASSERT_TRUE(LIDET_SUCCEEDED(whole.s));
            TEST_ASSERT_TRUE(whole.n_det >= 2u);
            TEST_ASSERT_EQUAL_UINT32(0u, whole.st.n_stream_sectors);
            keep(&part, stream_sret(n, 384u, 0));
            /* most sectors done before stream_end; the first one and those the margin holds back after it */
            TEST_ASSERT_TRUE(part.st.n_stream_sectors + 4u >= ns - ns / 16u);
            TEST_ASSERT_TRUE(part.st.n_stream_sectors < ns);
            part.st.n_stream_sectors = 0;
            same_run(&whole, &part);
            TEST_ASSERT_EQUAL_MEMORY(whole.range, g.ws.range_4mm, sizeof whole.range);
            /* every other packet held back to the end: returns come back to done sectors, and stream_end runs the
             * whole stage: the same results */
            keep(&part, stream_sret(n, 384u, 1));
            TEST_ASSERT_EQUAL_UINT32(0u, part.st.n_stream_sectors);
            same_run(&whole, &part);
        }
        CANARY_CHECK(g);
    }
}

static void test_stream_states_and_truncation(void)
{
    static run_t whole, part;
    static const uint32_t sizes[] = {4096u};
    lidet_detector_q_cfg_t cfg;
    uint32_t n = make_returns(), i;
    TEST_ASSERT_EQUAL_INT(LIDET_OK, init_default(&cfg));
    /* no stream open: before begin, after end, after a run in between */
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_STATE, lidet_detector_q_stream_returns(&g.ws, ret, 10u, NULL));
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_STATE, lidet_detector_q_stream_end(&g.ws));
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_detector_q_stream_begin(&g.ws));
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_ARG, lidet_detector_q_stream_returns(&g.ws, NULL, 1u, NULL));
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_detector_q_stream_returns(&g.ws, NULL, 0u, NULL));
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_ARG, lidet_detector_q_stream_returns(NULL, ret, 1u, NULL));
    TEST_ASSERT_TRUE(LIDET_SUCCEEDED(lidet_detector_q_run(&g.ws, pts, n_pts, 3, NULL, NULL)));
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_STATE, lidet_detector_q_stream_returns(&g.ws, ret, 10u, NULL));
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_detector_q_stream_begin(&g.ws));
    TEST_ASSERT_TRUE(LIDET_SUCCEEDED(lidet_detector_q_stream_end(&g.ws))); /* an empty scan */
    TEST_ASSERT_EQUAL_UINT32(0u, lidet_detector_q_stats(&g.ws)->n_detections);
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_STATE, lidet_detector_q_stream_end(&g.ws));
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_ARG, lidet_detector_q_stream_begin(NULL));
    /* more returns than LIDET_MAX_POINTS: the scan repeated; the same truncation as one run on them all */
    for (i = n; i < MAX_RET; ++i)
    {
        ret[i] = ret[i % n];
    }
    keep(&whole, lidet_detector_q_run_returns(&g.ws, ret, MAX_RET, NULL));
    TEST_ASSERT_EQUAL_INT(LIDET_TRUNCATED, whole.s);
    TEST_ASSERT_EQUAL_UINT32(MAX_RET - LIDET_MAX_POINTS, whole.st.proj.n_truncated);
    keep(&part, stream(MAX_RET, sizes, 1));
    same_run(&whole, &part);
}

static void test_score(void)
{
    TEST_ASSERT_EQUAL_INT32(16384, lidet_detector_q_score(-5 * 65536, -5 * 65536));
    TEST_ASSERT_TRUE(lidet_detector_q_score(-9 * 65536, -5 * 65536) > 32000);
    TEST_ASSERT_TRUE(lidet_detector_q_score(-1 * 65536, -5 * 65536) < 700);
    TEST_ASSERT_TRUE(lidet_detector_q_score(-6 * 65536, -5 * 65536) >
                     lidet_detector_q_score(-4 * 65536, -5 * 65536));
    TEST_ASSERT_EQUAL_INT32(0, lidet_detector_q_score(INT32_MAX, INT32_MIN));
    TEST_ASSERT_EQUAL_INT32(32768, lidet_detector_q_score(INT32_MIN, INT32_MAX));
}

/* two people side by side: boxes 1.0 x 0.7 m whose centres lie 0.65 m apart (BEV IoU 0.212) or 0.3 m apart (0.538) */
static lidet_detection_q_t det_at(int32_t cx_mm, int32_t score_q15, uint16_t cluster_id)
{
    lidet_detection_q_t d;
    memset(&d, 0, sizeof d);
    d.box.cx_mm = cx_mm;
    d.box.l_mm = 1000;
    d.box.w_mm = 700;
    d.box.h_mm = 1700;
    d.score_q15 = score_q15;
    d.cluster_id = cluster_id;
    d.cls = LIDET_CLASS_PEDESTRIAN;
    return d;
}

static void test_nms_of_a_group_cut(void)
{
    lidet_detection_q_t d[2];
    uint8_t sup[2];
    d[0] = det_at(10000, 30000, 5);
    d[1] = det_at(10650, 20000, 6);
    TEST_ASSERT_TRUE(lidet_box_q_bev_iou(&d[0].box, &d[1].box) > 6553); /* > 0.2 */
    TEST_ASSERT_TRUE(lidet_box_q_bev_iou(&d[0].box, &d[1].box) <= 8192);
    /* two clusters: the lower one goes at the default 0.1 */
    TEST_ASSERT_EQUAL_UINT32(1, lidet_detections_q_nms(d, 2, 3277, sup));
    TEST_ASSERT_EQUAL_UINT8(1, sup[1]);
    /* two parts of one group cut (one cluster id): both stand below 0.25 */
    d[0] = det_at(10000, 30000, 5);
    d[1] = det_at(10650, 20000, 5);
    TEST_ASSERT_EQUAL_UINT32(2, lidet_detections_q_nms(d, 2, 3277, sup));
    TEST_ASSERT_EQUAL_UINT8(0, sup[1]);
    /* one person cut twice: past 0.25 the lower part goes, and the larger nms bound holds for parts too */
    d[1] = det_at(10300, 20000, 5);
    TEST_ASSERT_TRUE(lidet_box_q_bev_iou(&d[0].box, &d[1].box) > 8192);
    TEST_ASSERT_EQUAL_UINT32(1, lidet_detections_q_nms(d, 2, 3277, sup));
    d[1] = det_at(10300, 20000, 5);
    TEST_ASSERT_EQUAL_UINT32(2, lidet_detections_q_nms(d, 2, 32768, sup));
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_init_errors);
    RUN_TEST(test_run_invariants_and_determinism);
    RUN_TEST(test_crop_and_budget);
    RUN_TEST(test_bad_points);
    RUN_TEST(test_streamed_returns_equal_the_whole_scan);
    RUN_TEST(test_streamed_sectors_equal_the_whole_scan);
    RUN_TEST(test_stream_states_and_truncation);
    RUN_TEST(test_score);
    RUN_TEST(test_nms_of_a_group_cut);
    return UNITY_END();
}
