/* SPDX-License-Identifier: MIT */
/* libFuzzer harness: the whole detector (lidet_detector_init, lidet_detector_run: workspace stages on a
 * compact image, candidate order and proposal budget, both PointNets (the tiny models of tests/fuzz/models), gates,
 * size check, NMS), on any scan and sensor the input describes, with fuzzed detector knobs. Checks the
 * counts and outcomes agree and the detections are sorted, in range and of finite score. */
#include <math.h>

#include "fuzz_common.h"
#include "fuzz_models.h"

static lidet_detector_t g_det;
static int32_t g_pp[LIDET_MAX_POINTS];
static uint32_t g_cid[LIDET_MAX_POINTS];
static uint8_t g_gnd[LIDET_MAX_POINTS];

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static void detector_knobs(fz_in_t *in, lidet_detector_cfg_t *c, uint8_t *vlp, uint8_t *per_point)
{
    float *const fl[] = {&c->crop_half_rad, &c->max_range_m, &c->nms_iou, &c->size_min_m[0][0],
                         &c->size_max_m[1][2], &c->proposal.range_bin_m, &c->gate1_margin, &c->gate2_margin,
                         &c->gate1_class_margin[LIDET_CLASS_PEDESTRIAN], &c->group_gate1_margin,
                         &c->gate1_large_car_margin};
    const uint8_t f = fz_u8(in);
    *vlp = f & 1u;
    *per_point = (f >> 1) & 1u;
    c->gate1 = (f >> 2) & 1u;
    c->gate2 = (f >> 3) & 1u;
    if (f & 0x10u)
    {
        c->crop_half_rad = 0.0f;
    }
    c->max_proposals = fz_u8(in) % (LIDET_MAX_CLUSTERS + 2u);
    c->max_boxes = fz_u8(in) % (LIDET_MAX_CLUSTERS + 2u);
    c->stages.cluster.min_points = 1u + fz_u8(in) % 12u;
    c->stages.ground.n_sectors = (uint16_t)(1u + fz_u8(in) % LIDET_GROUND_MAX_SECTORS);
    fz_poke_f32(in, fl, (uint32_t)(sizeof fl / sizeof fl[0]));
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    fz_in_t in = {data, size};
    fz_scan_t s;
    lidet_detector_cfg_t cfg;
    const lidet_detector_stats_t *ds;
    const lidet_detection_t *det;
    const uint8_t *out;
    const lidet_pn_model_t *cls, *box;
    uint8_t vlp, per_point;
    uint32_t n_det, n_cl, i, n_detected = 0, n_budget = 0;
    lidet_status_t st;
    fz_scan_header(&in, &s);
    lidet_detector_cfg_default(&cfg, &s.sensor);
    cfg.stages.proj = s.proj;
    detector_knobs(&in, &cfg, &vlp, &per_point);
    fz_scan_points(&in, &s);
    /* the tiny models of tests/fuzz/models: the same detector code at ~200x fewer multiply-adds per proposal
     * (the committed models run through it in the unit, determinism and sanitizer tests); the hdl64 /
     * vlp16 bit picks the points per proposal: 16 or, as in the committed models, 64 */
    cls = fz_tiny_model(0, vlp);
    box = fz_tiny_model(1, vlp);
    st = lidet_detector_init(&g_det, &cfg, cls, box);
    if (st != LIDET_OK)
    {
        FZ_CHECK(st < 0);
        FZ_CHECK(lidet_detector_run(&g_det, s.pts, s.n_points, s.stride, s.ring, NULL) == LIDET_ERR_STATE);
        return 0;
    }
    st = lidet_detector_run(&g_det, s.pts, s.n_points, s.stride, s.ring, per_point ? g_pp : NULL);
    FZ_CHECK(LIDET_SUCCEEDED(st) || st == LIDET_ERR_CONFIG); /* CONFIG: fewer columns than ground sectors */
    if (!LIDET_SUCCEEDED(st))
    {
        return 0;
    }
    ds = lidet_detector_stats(&g_det);
    det = lidet_detector_detections(&g_det, &n_det);
    out = lidet_detector_outcomes(&g_det, &n_cl);
    FZ_CHECK(n_det == ds->n_detections && n_det <= LIDET_MAX_DETECTIONS && n_cl == ds->n_clusters);
    fz_check_proj_stats(&ds->stages.proj, s.n_points, (uint32_t)s.sensor.n_rows * s.sensor.n_cols);
    FZ_CHECK(ds->n_classified <= cfg.max_proposals && ds->n_boxed <= ds->n_classified);
    for (i = 0; i < n_cl; ++i)
    {
        FZ_CHECK(out[i] >= 1 && out[i] <= LIDET_DET_OUT_SCORE);
        n_detected += out[i] == LIDET_DET_OUT_DETECTED;
        n_budget += out[i] == LIDET_DET_OUT_BUDGET;
    }
    /* a group split's cluster gives up to 4 detections */
    FZ_CHECK(n_detected <= n_det && n_det <= n_detected + 4u * ds->n_group_split &&
             n_budget == ds->n_over_budget + ds->n_over_box_budget);
    FZ_CHECK(ds->n_boxed <= cfg.max_boxes);
    for (i = 0; i < n_det; ++i)
    {
        FZ_CHECK(det[i].cls < LIDET_N_CLASSES && det[i].cluster_id >= 1 && det[i].cluster_id <= n_cl);
        FZ_CHECK(det[i].score >= 0.0f && det[i].score <= 1.0f);
        FZ_CHECK(i == 0 || det[i].score <= det[i - 1].score);
    }
    if (per_point)
    {
        const uint32_t n = s.n_points < LIDET_MAX_POINTS ? s.n_points : LIDET_MAX_POINTS;
        FZ_CHECK(lidet_workspace_point_labels(lidet_detector_workspace(&g_det), g_pp, n, g_cid, g_gnd) == LIDET_OK);
        for (i = 0; i < n; ++i)
        {
            FZ_CHECK(g_cid[i] <= n_cl && g_gnd[i] <= 1);
        }
    }
    return 0;
}
