/* SPDX-License-Identifier: MIT */
/* `lidet detect --fixed`: the same scan through the integer detector (lidet_detector_q.h). The scan is
 * converted to int32 millimetres (rounded half away from zero, as a driver delivering millimetres gives),
 * the float configuration after --crop/--set to the integer one, and the integer detections back to
 * lidet_detection_t for the CLI's outputs (lines, KITTI label_2, picture, JSON). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "lidet/lidet_detector_q.h"
#include "lidet_weights.h"

static lidet_detector_q_t g_detq;

static int32_t round_i32(double v)
{
    return (int32_t)(v >= 0.0 ? v + 0.5 : v - 0.5);
}

/* a point (mm) and its ring as the sensor reports it (lidet_return_t), the rule of tools/firmware/scan_to_c.py
 * and lidet_ref.proj_q.returns_of_points: range = round(sqrt(x^2 + y^2 + z^2)) (exact, halves up: the
 * float root corrected in integers), azimuth = round(atan2(y, x) 2^16 / 2 pi) mod 2^16 */
static lidet_return_t return_of_point(const int32_t *p, uint16_t ring)
{
    const uint64_t r2x4 = 4u * ((uint64_t)((int64_t)p[0] * p[0]) + (uint64_t)((int64_t)p[1] * p[1]) +
                                (uint64_t)((int64_t)p[2] * p[2]));
    uint64_t q = (uint64_t)sqrt((double)r2x4);
    lidet_return_t r;
    while (q * q > r2x4)
        --q;
    while ((q + 1u) * (q + 1u) <= r2x4)
        ++q;
    q = (q + 1u) >> 1;
    r.range_mm = q > 0xFFFFFFFFu ? 0xFFFFFFFFu : (uint32_t)q;
    r.azimuth =
        (uint16_t)((int64_t)floor(atan2((double)p[1], (double)p[0]) * (65536.0 / (2.0 * M_PI_D)) + 0.5) &
                   0xFFFF);
    r.ring = ring;
    return r;
}

int cli_detect_q_run(const cli_args_t *a, const lidet_detector_cfg_t *fcfg, const char *family,
                     lidet_detection_t *det, uint32_t *n_det, lidet_detector_stats_t *ds, double *ms,
                     uint8_t *point_ground, uint32_t *point_cluster, lidet_status_t *status,
                     const lidet_return_t *returns)
{
    const double bam_per_rad = 4294967296.0 / (2.0 * M_PI_D);
    /* a file's sensor brings its integer profile (cli_sensor.c) */
    const lidet_sensor_q_t *s = a->sensor_q != NULL ? a->sensor_q : lidet_sensor_q_find(a->sensor);
    lidet_sensor_q_t mounted;
    const lidet_pointnet_q_model_t *mc, *mb;
    const lidet_detection_q_t *dq;
    const lidet_detector_q_stats_t *st;
    lidet_detector_q_cfg_t cfg;
    char name[80];
    uint32_t np = a->n_points < LIDET_MAX_POINTS ? a->n_points : LIDET_MAX_POINTS, k;
    int32_t *pts, *pp;
    lidet_return_t *rets = NULL;
    const lidet_return_t *run_rets = returns;
    double *t, *stream_end;
    int i;
    if (s == NULL)
    {
        fprintf(stderr, "lidet %s --fixed: no integer profile for sensor '%s'\n", cli_cmd, a->sensor);
        return 1;
    }
    snprintf(name, sizeof name, "cls_%s_s8", family);
    mc = lidet_pointnet_q_find(lidet_weights_models_s8, LIDET_WEIGHTS_N_MODELS_S8, name);
    snprintf(name, sizeof name, "box_%s_s8", family);
    mb = lidet_pointnet_q_find(lidet_weights_models_s8, LIDET_WEIGHTS_N_MODELS_S8, name);
    if (mc == NULL || mb == NULL)
    {
        fprintf(stderr, "lidet %s --fixed: no int8 models cls_%s_s8 / box_%s_s8 in weights/\n", cli_cmd,
                family, family);
        return 1;
    }
    if (a->mount_height_m >= 0.0) /* --mount-height, in mm as the integer profile holds it */
    {
        mounted = *s;
        mounted.mount_height_mm = round_i32(a->mount_height_m * 1000.0);
        s = &mounted;
    }
    lidet_detector_q_cfg_default(&cfg, s);
    cfg.crop_half_bam = fcfg->crop_half_rad >= (float)M_PI_D
                            ? 0x7FFFFFFF
                            : round_i32((double)fcfg->crop_half_rad * bam_per_rad);
    cfg.max_range_mm = round_i32((double)fcfg->max_range_m * 1000.0);
    cfg.max_height_extent_mm = round_i32((double)fcfg->max_height_extent_m * 1000.0);
    cfg.max_proposals = fcfg->max_proposals;
    cfg.max_boxes = fcfg->max_boxes;
    /* the refinement's switches (its thresholds stay the integer defaults) */
    cfg.cluster.split_people = fcfg->stages.cluster.split_people;
    cfg.cluster.join_cars = fcfg->stages.cluster.join_cars;
    cfg.ground.sample_step = fcfg->stages.ground.sample_step;
    cfg.ground.sample_col_step = fcfg->stages.ground.sample_col_step;
    cfg.ground.ransac_iters = fcfg->stages.ground.ransac_iters;
    cfg.ground.refine_iters = fcfg->stages.ground.refine_iters;
    cfg.ground.seed = fcfg->stages.ground.seed; /* the RANSAC's draws: the same streams as the float stage's */
    cfg.ground.seed_per_cell = fcfg->stages.ground.seed_per_cell;
    /* the far-plane, third-cell and regrowth rules, in integer units (the float defaults round to the integer ones exactly) */
    cfg.ground.far_max_step_mm = (uint32_t)round_i32((double)fcfg->stages.ground.far_max_step_m * 1000.0);
    cfg.ground.far2_split_mm = (uint32_t)round_i32((double)fcfg->stages.ground.far2_split_m * 1000.0);
    cfg.cluster.regrow_gap_mm = (uint32_t)round_i32((double)fcfg->stages.cluster.regrow_gap_m * 1000.0);
    cfg.cluster.regrow_gap_per_m_q16 =
        (uint32_t)round_i32((double)fcfg->stages.cluster.regrow_gap_per_m * 65536.0);
    cfg.cluster.regrow_max_pixels = fcfg->stages.cluster.regrow_max_pixels;
    cfg.cluster.regrow_max_height_mm =
        (uint32_t)round_i32((double)fcfg->stages.cluster.regrow_max_height_m * 1000.0);
    cfg.cluster.regrow_cut_mm = (uint32_t)round_i32((double)fcfg->stages.cluster.regrow_cut_m * 1000.0);
    cfg.group_split = fcfg->group_split;
    cfg.group_max_range_mm = round_i32((double)fcfg->group_max_range_m * 1000.0);
    cfg.group_gate1_margin_q16 = round_i32((double)fcfg->group_gate1_margin * 65536.0);
    cfg.gate1_large_car_margin_q16 = round_i32((double)fcfg->gate1_large_car_margin * 65536.0);
    cfg.car_min_z_spread_mm = round_i32((double)fcfg->car_min_z_spread_m * 1000.0);
    cfg.car_ground_mm = round_i32((double)fcfg->car_ground_m * 1000.0);
    cfg.proposal.seed = fcfg->proposal.seed;
    cfg.gate1 = fcfg->gate1;
    cfg.gate2 = fcfg->gate2;
    cfg.gate1_margin_q16 = round_i32((double)fcfg->gate1_margin * 65536.0);
    cfg.gate2_margin_q16 = round_i32((double)fcfg->gate2_margin * 65536.0);
    for (k = 0; k < LIDET_N_CLASSES; ++k)
    {
        cfg.gate2_class[k] = fcfg->gate2_class[k];
        cfg.score_box_weight_q16[k] = round_i32((double)fcfg->score_box_weight[k] * 65536.0);
        cfg.min_score_q15[k] = round_i32((double)fcfg->min_score[k] * 32768.0);
        cfg.gate1_class_margin_q16[k] = round_i32((double)fcfg->gate1_class_margin[k] * 65536.0);
        cfg.score_points_weight_q16[k] = round_i32((double)fcfg->score_points_weight[k] * 65536.0);
    }
    cfg.nms_iou_q15 = round_i32((double)fcfg->nms_iou * 32768.0);
    if (cli_fixed_range_only || cli_fixed_stream_sectors)
    {
        cfg.range_only = 1u; /* the firmware's pixel: x, y, z decoded from row, column and range */
    }
    cfg.stream_sectors = (uint8_t)(cli_fixed_stream_sectors != 0);
    cfg.clock = cli_stage_clock_ns;
    *status = lidet_detector_q_init(&g_detq, &cfg, mc, mb);
    if (*status != LIDET_OK)
    {
        fprintf(stderr, "lidet %s --fixed: init (configuration or models): %s\n", cli_cmd,
                lidet_status_str(*status));
        return 1;
    }
    pts = (int32_t *)malloc(sizeof(int32_t) * 3u * (size_t)(np + 1u));
    pp = (int32_t *)malloc(sizeof(int32_t) * LIDET_MAX_POINTS);
    t = (double *)malloc(sizeof(double) * (size_t)a->repeat * (LIDET_DET_N_STAGES + 2u));
    if (pts == NULL || pp == NULL || t == NULL)
    {
        free(pts);
        free(pp);
        free(t);
        return 1;
    }
    stream_end = t + (size_t)a->repeat * (LIDET_DET_N_STAGES + 1u); /* --stream: each run's stream_end time */
    for (k = 0; returns == NULL && k < np; ++k)
    {
        /* clamped to the int32 range first: a 1e19 m point must stay a (rejected) huge value, not UB */
        for (i = 0; i < 3; ++i)
        {
            const double v = (double)a->points[4u * k + (uint32_t)i] * 1000.0;
            pts[3u * k + (uint32_t)i] =
                v != v ? 0 : (v > 2.0e9 ? 2000000000 : (v < -2.0e9 ? -2000000000 : round_i32(v)));
        }
    }
    if (cli_fixed_returns && returns == NULL)
    {
        if (a->ring == NULL)
        {
            fprintf(stderr, "lidet detect --returns: needs the scan's rings (--ring FILE)\n");
            free(pts);
            free(pp);
            free(t);
            return 1;
        }
        rets = (lidet_return_t *)malloc(sizeof(lidet_return_t) * (size_t)(np + 1u));
        if (rets == NULL)
        {
            free(pts);
            free(pp);
            free(t);
            return 1;
        }
        for (k = 0; k < np; ++k)
            rets[k] = return_of_point(pts + 3u * k, a->ring[k]);
        run_rets = rets;
    }
    if (cli_fixed_stream > 0u && run_rets == NULL)
    {
        fprintf(stderr, "lidet %s --stream: needs the scan as the sensor's returns (--returns --ring FILE, or "
                        "--pcap)\n",
                cli_cmd);
        free(pts);
        free(pp);
        free(t);
        free(rets);
        return 1;
    }
    for (i = 0; i < a->repeat; ++i)
    {
        const double t0 = cli_stage_clock_cpu ? cli_cpu_ms() : cli_now_ms();
        if (cli_fixed_stream > 0u)
        {
            /* a chunk at a time, as a driver feeds packets; stream_end timed alone (the latency) */
            uint32_t at = 0;
            double te;
            *status = lidet_detector_q_stream_begin(&g_detq);
            while (LIDET_SUCCEEDED(*status) && at < np)
            {
                const uint32_t m = np - at < cli_fixed_stream ? np - at : cli_fixed_stream;
                const lidet_status_t sr =
                    lidet_detector_q_stream_returns(&g_detq, run_rets + at, m, i == 0 ? pp + at : NULL);
                *status = LIDET_SUCCEEDED(sr) ? *status : sr;
                at += m;
            }
            te = cli_stage_clock_cpu ? cli_cpu_ms() : cli_now_ms();
            if (LIDET_SUCCEEDED(*status))
            {
                const lidet_status_t se = lidet_detector_q_stream_end(&g_detq);
                *status = se != LIDET_OK ? se : *status;
            }
            stream_end[i] = (cli_stage_clock_cpu ? cli_cpu_ms() : cli_now_ms()) - te;
        }
        else
        {
            *status = run_rets != NULL ? lidet_detector_q_run_returns(&g_detq, run_rets, np, i == 0 ? pp : NULL)
                                       : lidet_detector_q_run(&g_detq, pts, np, 3, a->ring, i == 0 ? pp : NULL);
        }
        t[(size_t)LIDET_DET_N_STAGES * (size_t)a->repeat + (size_t)i] =
            (cli_stage_clock_cpu ? cli_cpu_ms() : cli_now_ms()) - t0;
        if (!LIDET_SUCCEEDED(*status))
        {
            fprintf(stderr, "lidet %s --fixed: %s\n", cli_cmd, lidet_status_str(*status));
            free(pts);
            free(pp);
            free(t);
            free(rets);
            return 1;
        }
        st = lidet_detector_q_stats(&g_detq);
        for (k = 0; k < LIDET_DET_N_STAGES; ++k)
            t[(size_t)k * (size_t)a->repeat + (size_t)i] = (double)st->ticks[k] * 1e-6;
    }
    for (k = 0; k <= LIDET_DET_N_STAGES; ++k)
        ms[k] = cli_median(t + (size_t)k * (size_t)a->repeat, a->repeat);
    cli_stream_end_ms = cli_fixed_stream > 0u ? cli_median(stream_end, a->repeat) : 0.0;
    free(t);
    st = lidet_detector_q_stats(&g_detq);
    cli_stream_sectors_done = st->n_stream_sectors;
    memset(ds, 0, sizeof *ds);
    ds->n_clusters = st->n_clusters;
    ds->n_out_of_crop = st->n_out_of_crop;
    ds->n_out_of_range = st->n_out_of_range;
    ds->n_over_budget = st->n_over_budget;
    ds->n_classified = st->n_classified;
    ds->n_gate1_rejected = st->n_gate1_rejected;
    ds->n_boxed = st->n_boxed;
    ds->n_gate2_rejected = st->n_gate2_rejected;
    ds->n_size_rejected = st->n_size_rejected;
    ds->n_nms_suppressed = st->n_nms_suppressed;
    ds->n_over_capacity = st->n_over_capacity;
    ds->n_over_box_budget = st->n_over_box_budget;
    ds->n_too_tall = st->n_too_tall;
    ds->n_group_split = st->n_group_split;
    ds->n_group_classified = st->n_group_classified;
    ds->n_group_boxed = st->n_group_boxed;
    ds->n_score_rejected = st->n_score_rejected;
    ds->n_detections = st->n_detections;
    ds->stages.ground = st->ground; /* the same counts (lidet detect's mount-height warning reads them) */
    ds->stages.proj = st->proj;     /* and its frame check (cli_warn_frame) */
    dq = lidet_detector_q_detections(&g_detq, n_det);
    for (k = 0; k < *n_det; ++k)
    {
        det[k].box.cx_m = (float)(dq[k].box.cx_mm * 1e-3);
        det[k].box.cy_m = (float)(dq[k].box.cy_mm * 1e-3);
        det[k].box.cz_m = (float)(dq[k].box.cz_mm * 1e-3);
        det[k].box.l_m = (float)(dq[k].box.l_mm * 1e-3);
        det[k].box.w_m = (float)(dq[k].box.w_mm * 1e-3);
        det[k].box.h_m = (float)(dq[k].box.h_mm * 1e-3);
        det[k].box.yaw_rad = (float)(dq[k].box.yaw_bam / bam_per_rad);
        det[k].cls = dq[k].cls;
        det[k].score = (float)(dq[k].score_q15 / 32768.0);
        det[k].energy_cls = (float)(dq[k].energy_cls_q16 / 65536.0);
        det[k].energy_box = (float)(dq[k].energy_box_q16 / 65536.0);
        det[k].cluster_id = dq[k].cluster_id;
        det[k].n_points = dq[k].n_points;
    }
    for (k = 0; k < np; ++k)
    {
        const int32_t p = pp[k];
        if (point_ground != NULL)
            point_ground[k] = p >= 0 ? g_detq.mask[p] : 0u;
        if (point_cluster != NULL)
            point_cluster[k] = p >= 0 ? g_detq.scratch.cluster.labels[p] : 0u;
    }
    free(pts);
    free(pp);
    free(rets);
    return 0;
}

const lidet_detection_q_t *cli_detect_q_detections(uint32_t *n_det)
{
    return lidet_detector_q_detections(&g_detq, n_det);
}

/* ---- --fixed --dump: the integer detector's results bit for bit (the float detector's: write_dump in
 * cli_detect.c) ---------------------------------------------------------------------------------------- */

/* Binary, host byte order: "LDTQ", n_points, n_clusters, n_detections (uint32); per point its cluster label
 * (uint32) then its ground flag (uint8), 0 past LIDET_MAX_POINTS; per kept cluster its outcome
 * (lidet_det_outcome_t, uint32); the run's counts (lidet_detector_q_stats_t from n_clusters to n_too_tall, 14
 * uint32); per detection class, cluster id, n_points (uint32), then score_q15, energy_cls_q16, energy_box_q16
 * and the box (cx, cy, cz, l, w, h in mm, yaw in BAM32) as int32. Written field by field: no struct padding
 * reaches the file. */
int cli_detect_q_dump(const char *path, uint32_t n_points, const uint32_t *point_cluster,
                      const uint8_t *point_ground)
{
    const uint32_t np = n_points < LIDET_MAX_POINTS ? n_points : LIDET_MAX_POINTS;
    const lidet_detector_q_stats_t *st = lidet_detector_q_stats(&g_detq);
    const lidet_detection_q_t *dq;
    const uint8_t *oc;
    uint32_t n_det = 0, n_oc = 0, i;
    FILE *f = fopen(path, "wb");
    int bad;
    dq = lidet_detector_q_detections(&g_detq, &n_det);
    oc = lidet_detector_q_outcomes(&g_detq, &n_oc);
    bad = f == NULL || dq == NULL || oc == NULL || point_cluster == NULL || point_ground == NULL;
    bad = bad || fwrite("LDTQ", 1, 4, f) != 4 || cli_put_u32(f, n_points) || cli_put_u32(f, n_oc) ||
          cli_put_u32(f, n_det);
    for (i = 0; !bad && i < n_points; ++i)
        bad = cli_put_u32(f, i < np ? point_cluster[i] : 0u) || fputc(i < np ? point_ground[i] : 0, f) == EOF;
    for (i = 0; !bad && i < n_oc; ++i)
        bad = cli_put_u32(f, oc[i]);
    bad = bad || cli_put_u32(f, st->n_clusters) || cli_put_u32(f, st->n_out_of_crop) ||
          cli_put_u32(f, st->n_out_of_range) || cli_put_u32(f, st->n_over_budget) ||
          cli_put_u32(f, st->n_classified) || cli_put_u32(f, st->n_gate1_rejected) ||
          cli_put_u32(f, st->n_boxed) || cli_put_u32(f, st->n_gate2_rejected) ||
          cli_put_u32(f, st->n_size_rejected) || cli_put_u32(f, st->n_nms_suppressed) ||
          cli_put_u32(f, st->n_over_capacity) || cli_put_u32(f, st->n_detections) ||
          cli_put_u32(f, st->n_over_box_budget) || cli_put_u32(f, st->n_too_tall);
    for (i = 0; !bad && i < n_det; ++i)
        bad = cli_put_u32(f, dq[i].cls) || cli_put_u32(f, dq[i].cluster_id) ||
              cli_put_u32(f, dq[i].n_points) || cli_put_u32(f, (uint32_t)dq[i].score_q15) ||
              cli_put_u32(f, (uint32_t)dq[i].energy_cls_q16) ||
              cli_put_u32(f, (uint32_t)dq[i].energy_box_q16) || cli_put_u32(f, (uint32_t)dq[i].box.cx_mm) ||
              cli_put_u32(f, (uint32_t)dq[i].box.cy_mm) || cli_put_u32(f, (uint32_t)dq[i].box.cz_mm) ||
              cli_put_u32(f, (uint32_t)dq[i].box.l_mm) || cli_put_u32(f, (uint32_t)dq[i].box.w_mm) ||
              cli_put_u32(f, (uint32_t)dq[i].box.h_mm) || cli_put_u32(f, (uint32_t)dq[i].box.yaw_bam);
    if (f != NULL && fclose(f) != 0)
        bad = 1;
    return bad ? -1 : 0;
}
