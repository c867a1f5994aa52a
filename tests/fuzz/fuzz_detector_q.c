/* SPDX-License-Identifier: MIT */
/* libFuzzer harness: the integer detector (lidet_detector_q_init with fuzzed knobs, lidet_detector_q_run and,
 * on the same bytes read as the sensor's returns, lidet_detector_q_run_returns and the same returns streamed in
 * chunks, lidet_detector_q_stream_*, which must give the same results bit for bit (with stream_sectors on half of
 * the range-only inputs, the returns then sorted by azimuth):
 * integer projection, ground, clustering, proposals, the int8 PointNets (the tiny models of
 * tests/fuzz/models), gates, size check, NMS) on any integer sensor and any int32 millimetre scan the input
 * describes (INT32_MIN/MAX coordinates, zero range, rings out of range). Checks the counts and outcomes agree,
 * the detections are sorted, in range and of Q15 score, per-point pixels in range.
 *
 * Input: rows, cols, flags, tile (as fuzz_common.h; flags 0x01 beam table, 0x02 rings, bits 2-3 stride - 3,
 * 0x20 rows/cols raw, 0x40 raw projection limits), the beam table (n_rows int32 microradians) or fov_up,
 * fov_down (int32 microradians), one mount-height byte (x 250 mm), [min range mm, max range mm, fov margin
 * urad as int32], the knobs (detector_q_knobs), then the points: records of `stride` int32 (mm), any value. */
#include "fuzz_common.h"
#include "fuzz_models.h"
#include "lidet/lidet_detector_q.h"
#include "lidet/lidet_sensor_q.h"

static lidet_detector_q_t g_det;
static int32_t g_pts[FZ_MAX_IN * FZ_MAX_STRIDE];
static int32_t g_pp[LIDET_MAX_POINTS];
static lidet_return_t g_ret[FZ_MAX_IN]; /* the same bytes read as the sensor's returns */
static int32_t g_elev[256];

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static void sensor_q(fz_in_t *in, fz_scan_t *s, lidet_sensor_q_t *q, lidet_proj_q_cfg_t *pc)
{
    const uint8_t b_rows = fz_u8(in), b_cols = fz_u8(in);
    uint32_t i;
    memset(s, 0, sizeof *s);
    memset(q, 0, sizeof *q);
    s->flags = fz_u8(in);
    s->stride = 3u + ((s->flags >> 2) & 3u);
    s->tile = 1u + (fz_u8(in) % FZ_MAX_TILE);
    q->name = "fuzz";
    if (s->flags & FZ_FLAG_RAW_DIM)
    {
        q->n_rows = b_rows;
        q->n_cols = (uint16_t)(4u * b_cols);
    }
    else
    {
        q->n_rows = (uint16_t)(1u + b_rows % LIDET_MAX_ROWS);
        q->n_cols = (uint16_t)(8u + b_cols % (LIDET_MAX_COLS - 7u));
    }
    if (s->flags & FZ_FLAG_TABLE)
    {
        for (i = 0; i < q->n_rows && i < 256u; ++i)
        {
            g_elev[i] = (int32_t)fz_u32(in);
        }
        q->beam_elev_urad = g_elev;
    }
    else
    {
        q->fov_up_urad = (int32_t)fz_u32(in);
        q->fov_down_urad = (int32_t)fz_u32(in);
    }
    q->mount_height_mm = 250 * (int32_t)(fz_u8(in) % 17u); /* 0 .. 4 m */
    q->max_range_mm = 100000;
    lidet_proj_q_cfg_default(pc, q);
    if (s->flags & FZ_FLAG_RAW_CFG)
    {
        pc->min_range_mm = (int32_t)fz_u32(in);
        pc->max_range_mm = (int32_t)fz_u32(in);
        pc->fov_margin_urad = (int32_t)fz_u32(in);
    }
}

/* one of the configuration's 32-bit fields overwritten with a raw value: the init's validation */
static void poke_u32(fz_in_t *in, uint32_t *const *fields, uint32_t n_fields)
{
    const uint8_t sel = fz_u8(in);
    const uint32_t v = fz_u32(in);
    if (sel < n_fields)
    {
        *fields[sel] = v;
    }
}

static void detector_q_knobs(fz_in_t *in, lidet_detector_q_cfg_t *c, uint8_t *p64, uint8_t *per_point)
{
    uint32_t *const f32[] = {
        (uint32_t *)&c->crop_half_bam, (uint32_t *)&c->max_range_mm, (uint32_t *)&c->nms_iou_q15,
        (uint32_t *)&c->size.min_mm[0][0], (uint32_t *)&c->size.max_mm[1][2], &c->proposal.range_bin_4mm,
        &c->proposal.azimuth_bin_bam, &c->cluster.theta_urad, &c->cluster.max_gap_mm,
        &c->cluster.max_gap_per_m_q16, &c->cluster.max_extent_mm, (uint32_t *)&c->cluster.max_mean_height_mm,
        &c->cluster.rescue_gap_mm, &c->cluster.rescue_cols, &c->ground.inlier_mm, &c->ground.max_tilt_urad,
        &c->ground.confidence_q16, &c->ground.ground_mm, &c->ground.veto_slope_q16, &c->ground.ring_split_mm,
        &c->ground.seed, &c->proposal.seed, &c->max_boxes, &c->cluster.max_fragment_pixels,
        &c->cluster.max_bridge_per_pixel_q16, &c->cluster.split_cell_mm, &c->cluster.split_min_width_mm,
        &c->cluster.person_min_aspect_q16, &c->cluster.join_gap_mm, &c->cluster.car_min_length_mm,
        (uint32_t *)&c->gate1_margin_q16, (uint32_t *)&c->gate2_margin_q16,
        (uint32_t *)&c->gate1_class_margin_q16[LIDET_CLASS_PEDESTRIAN], (uint32_t *)&c->group_gate1_margin_q16,
        (uint32_t *)&c->gate1_large_car_margin_q16};
    const uint8_t f = fz_u8(in);
    *p64 = f & 1u;
    *per_point = (f >> 1) & 1u;
    c->gate1 = (f >> 2) & 1u;
    c->gate2 = (f >> 3) & 1u;
    if (f & 0x10u)
    {
        c->crop_half_bam = 0;
    }
    c->cluster.bridge_occluders = (f >> 5) & 1u;
    c->cluster.diagonals = (f >> 6) & 1u;
    if (f & 0x80u)
    {
        c->cluster.split_people = 0u; /* the refinement off (default on) */
        c->cluster.join_cars = 0u;
    }
    c->max_proposals = fz_u8(in) % (LIDET_MAX_CLUSTERS + 2u);
    {
        /* one byte: min_points from its value, the range-only pixel (x, y, z decoded, lidet_qpix.h) from its top bit
         * (the input's byte layout, and so the corpus, unchanged) */
        const uint8_t b = fz_u8(in);
        c->cluster.min_points = 1u + b % 12u;
        c->range_only = (uint8_t)(b >> 7);
    }
    c->ground.n_sectors = (uint16_t)(1u + fz_u8(in) % LIDET_GROUND_MAX_SECTORS);
    /* the ground stage streamed sector by sector on half of the range-only inputs (an odd sector count; the
     * input's layout unchanged) */
    c->stream_sectors = (uint8_t)(c->range_only & (c->ground.n_sectors & 1u));
    c->cluster.max_steps = fz_u8(in) % (LIDET_CLUSTER_MAX_STEPS + 2u);
    poke_u32(in, f32, (uint32_t)(sizeof f32 / sizeof f32[0]));
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    fz_in_t in = {data, size};
    fz_scan_t s;
    lidet_sensor_q_t sensor;
    lidet_detector_q_cfg_t cfg;
    const lidet_detector_q_stats_t *ds;
    const lidet_detection_q_t *det;
    const uint8_t *out;
    uint8_t p64, per_point;
    uint32_t n_det, n_cl, i, n_detected = 0, n_pix;
    lidet_status_t st;
    lidet_proj_q_cfg_t pc;
    sensor_q(&in, &s, &sensor, &pc);
    lidet_detector_q_cfg_default(&cfg, &sensor);
    cfg.proj = pc;
    detector_q_knobs(&in, &cfg, &p64, &per_point);
    fz_scan_points(&in, &s); /* raw 4-byte values: read back as int32 */
    memcpy(g_pts, s.pts, (size_t)s.n_points * s.stride * sizeof(int32_t));
    st = lidet_detector_q_init(&g_det, &cfg, tiny_s8_model(0, p64), tiny_s8_model(1, p64));
    if (st != LIDET_OK)
    {
        FZ_CHECK(st < 0);
        FZ_CHECK(lidet_detector_q_run(&g_det, g_pts, s.n_points, s.stride, s.ring, NULL) == LIDET_ERR_STATE);
        return 0;
    }
    st = lidet_detector_q_run(&g_det, g_pts, s.n_points, s.stride, s.ring, per_point ? g_pp : NULL);
    FZ_CHECK(LIDET_SUCCEEDED(st) || st == LIDET_ERR_CONFIG); /* CONFIG: fewer columns than ground sectors */
    if (!LIDET_SUCCEEDED(st))
    {
        return 0;
    }
    ds = lidet_detector_q_stats(&g_det);
    det = lidet_detector_q_detections(&g_det, &n_det);
    out = lidet_detector_q_outcomes(&g_det, &n_cl);
    n_pix = (uint32_t)sensor.n_rows * sensor.n_cols;
    FZ_CHECK(n_det == ds->n_detections && n_det <= LIDET_MAX_DETECTIONS && n_cl == ds->n_clusters);
    fz_check_proj_stats(&ds->proj, s.n_points, n_pix);
    FZ_CHECK(ds->n_classified <= cfg.max_proposals && ds->n_boxed <= ds->n_classified);
    FZ_CHECK(ds->n_boxed <= cfg.max_boxes && ds->n_classified == ds->n_gate1_rejected + ds->n_over_box_budget +
                                                                  ds->n_boxed);
    for (i = 0; i < n_cl; ++i)
    {
        FZ_CHECK(out[i] >= 1 && out[i] <= LIDET_DET_OUT_SCORE);
        n_detected += out[i] == LIDET_DET_OUT_DETECTED;
    }
    FZ_CHECK(n_detected <= n_det && n_det <= n_detected + 4u * ds->n_group_split); /* up to 4 per group */
    for (i = 0; i < n_det; ++i)
    {
        FZ_CHECK(det[i].cls < LIDET_N_CLASSES && det[i].cluster_id >= 1 && det[i].cluster_id <= n_cl);
        FZ_CHECK(det[i].score_q15 >= 0 && det[i].score_q15 <= 32768);
        FZ_CHECK(i == 0 || det[i].score_q15 <= det[i - 1].score_q15);
    }
    if (per_point)
    {
        const uint32_t n = s.n_points < LIDET_MAX_POINTS ? s.n_points : LIDET_MAX_POINTS;
        for (i = 0; i < n; ++i)
        {
            FZ_CHECK(g_pp[i] >= -1 && g_pp[i] < (int32_t)n_pix);
        }
    }
    /* the same scan's first three values of each record as returns (any range, azimuth and ring; rings past
     * the sensor's counted): lidet_detector_q_run_returns on the same detector */
    for (i = 0; i < s.n_points; ++i)
    {
        g_ret[i].range_mm = (uint32_t)g_pts[i * s.stride];
        g_ret[i].azimuth = (uint16_t)g_pts[i * s.stride + 1u];
        g_ret[i].ring = (uint16_t)g_pts[i * s.stride + 2u];
    }
    if (cfg.stream_sectors)
    {
        /* in the order a spinning sensor sends them, to 1/256 turn (a counting sort on 2^15 - azimuth's top byte),
         * so the stream does sectors before its end; the image does not depend on the order */
        static lidet_return_t tmp[FZ_MAX_IN];
        uint32_t at[257];
        memset(at, 0, sizeof at);
        for (i = 0; i < s.n_points; ++i)
        {
            ++at[1u + (((uint16_t)(0x8000u - g_ret[i].azimuth)) >> 8)];
        }
        for (i = 1; i < 257u; ++i)
        {
            at[i] += at[i - 1u];
        }
        for (i = 0; i < s.n_points; ++i)
        {
            tmp[at[((uint16_t)(0x8000u - g_ret[i].azimuth)) >> 8]++] = g_ret[i];
        }
        memcpy(g_ret, tmp, (size_t)s.n_points * sizeof g_ret[0]);
    }
    st = lidet_detector_q_run_returns(&g_det, g_ret, s.n_points, per_point ? g_pp : NULL);
    FZ_CHECK(LIDET_SUCCEEDED(st));
    ds = lidet_detector_q_stats(&g_det);
    det = lidet_detector_q_detections(&g_det, &n_det);
    FZ_CHECK(n_det == ds->n_detections && n_det <= LIDET_MAX_DETECTIONS);
    FZ_CHECK(ds->proj.n_projected + ds->proj.n_too_close + ds->proj.n_too_far + ds->proj.n_bad_ring +
                 ds->proj.n_truncated ==
             s.n_points);
    FZ_CHECK(ds->proj.n_pixels_filled <= ds->proj.n_projected && ds->proj.n_pixels_filled <= n_pix);
    if (per_point)
    {
        const uint32_t n = s.n_points < LIDET_MAX_POINTS ? s.n_points : LIDET_MAX_POINTS;
        for (i = 0; i < n; ++i)
        {
            FZ_CHECK(g_pp[i] >= -1 && g_pp[i] < (int32_t)n_pix);
        }
    }
    /* the same returns streamed in chunks whose sizes the scan's own bytes pick (0 .. 511): the detections, the
     * outcomes and the counts equal run_returns' bit for bit (lidet_detector_q_stream_*) */
    {
        static lidet_detection_q_t d0[LIDET_MAX_DETECTIONS];
        static uint8_t o0[LIDET_MAX_CLUSTERS];
        static lidet_detector_q_stats_t s0;
        uint32_t n0 = n_det, nc0 = 0, at = 0, k = 0, n1, nc1;
        const uint8_t *o = lidet_detector_q_outcomes(&g_det, &nc0);
        memcpy(d0, det, n0 * sizeof d0[0]);
        memcpy(o0, o, nc0);
        s0 = *ds;
        FZ_CHECK(lidet_detector_q_stream_begin(&g_det) == LIDET_OK);
        while (at < s.n_points)
        {
            /* chunks of up to 511 returns, up to 7 with stream_sectors (packets of a sparse scan) */
            uint32_t m =
                (uint32_t)g_pts[(k++ * 7u) % (s.n_points * s.stride)] & (cfg.stream_sectors ? 7u : 511u);
            m = m < s.n_points - at ? m : s.n_points - at;
            FZ_CHECK(LIDET_SUCCEEDED(lidet_detector_q_stream_returns(&g_det, g_ret + at, m, NULL)));
            at += m;
            if (k > 4u * s.n_points + 8u) /* chunks of 0 only: the rest in one */
            {
                FZ_CHECK(LIDET_SUCCEEDED(
                    lidet_detector_q_stream_returns(&g_det, g_ret + at, s.n_points - at, NULL)));
                at = s.n_points;
            }
        }
        FZ_CHECK(lidet_detector_q_stream_end(&g_det) == st);
        det = lidet_detector_q_detections(&g_det, &n1);
        o = lidet_detector_q_outcomes(&g_det, &nc1);
        ds = lidet_detector_q_stats(&g_det);
        FZ_CHECK(n1 == n0 && nc1 == nc0);
        FZ_CHECK(memcmp(det, d0, n0 * sizeof d0[0]) == 0 && memcmp(o, o0, nc0) == 0);
        FZ_CHECK(memcmp(&ds->proj, &s0.proj, sizeof s0.proj) == 0 && ds->n_detections == s0.n_detections &&
                 ds->n_classified == s0.n_classified && ds->n_boxed == s0.n_boxed);
        /* the streamed ground (stream_sectors) gives the whole stage's planes, mask and counts */
        FZ_CHECK(memcmp(&ds->ground, &s0.ground, sizeof s0.ground) == 0 &&
                 memcmp(&ds->cluster, &s0.cluster, sizeof s0.cluster) == 0);
        FZ_CHECK(s0.n_stream_sectors == 0u &&
                 ds->n_stream_sectors < (cfg.stream_sectors ? cfg.ground.n_sectors : 1u));
    }
    return 0;
}
