/* SPDX-License-Identifier: MIT */
/* `lidet detect`: the whole detector (lidet_detector.h) on one scan, with the models of lidet::weights.
 * Outputs: a table (or --json), lidet's sensor-frame box lines (--out), KITTI label_2 lines in the camera
 * frame with the 2D box of the projected corners (--calib + --kitti-out, so lidet-eval kitti scores them),
 * and a bird's-eye view with the detections and, given --gt, the ground-truth boxes (--png). The options, the
 * configuration and the float run are shared with `lidet track` (cli.h: cli_det_option, cli_det_config,
 * cli_detect_f_init / _run / _ground), as are the calibration and the camera-frame conversion. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "cli.h"
#include "lidet_weights.h"

static lidet_detector_t g_det;

const char *const cli_class_names[LIDET_N_CLASSES] = {"Car", "Cyclist", "Pedestrian"};

/* ---- KITTI calibration and label_2 output (cli_read_calib, cli_kitti_box: lidet track's label_02 too) ---------- */

int cli_read_calib(const char *path, cli_calib_t *c)
{
    FILE *f = fopen(path, "r");
    char line[1024];
    int ln = 0;
    memset(c, 0, sizeof *c);
    c->R0[0] = c->R0[4] = c->R0[8] = 1.0;
    if (f == NULL)
    {
        fprintf(stderr, "lidet %s: cannot open calibration '%s'\n", cli_cmd, path);
        return 1;
    }
    while (fgets(line, sizeof line, f) != NULL)
    {
        char *colon = strchr(line, ':'), *p;
        double *dst = NULL;
        int n = 0, want = 0;
        ++ln;
        if (colon == NULL)
            continue;
        *colon = '\0';
        if (strcmp(line, "P2") == 0)
        {
            dst = c->P2;
            want = 12;
            c->have_p2 = 1;
        }
        else if (strcmp(line, "R0_rect") == 0 || strcmp(line, "R_rect") == 0)
        {
            dst = c->R0;
            want = 9;
        }
        else if (strcmp(line, "Tr_velo_to_cam") == 0 || strcmp(line, "Tr_velo_cam") == 0)
        {
            dst = c->Tr;
            want = 12;
            c->have_tr = 1;
        }
        if (dst == NULL)
            continue;
        p = colon + 1;
        while (n < want)
        {
            char *end;
            const double v = strtod(p, &end);
            if (end == p || !isfinite(v))
                break;
            dst[n++] = v;
            p = end;
        }
        if (n != want)
        {
            fprintf(stderr, "lidet %s: %s:%d: %s needs %d numbers\n", cli_cmd, path, ln, line, want);
            fclose(f);
            return 1;
        }
    }
    fclose(f);
    if (!c->have_p2 || !c->have_tr)
    {
        fprintf(stderr, "lidet %s: %s: P2 and Tr_velo_to_cam are required\n", cli_cmd, path);
        return 1;
    }
    return 0;
}

/* sensor frame -> rectified camera frame: R0 (Tr p) */
static void velo_to_rect(const cli_calib_t *c, const double p[3], double out[3])
{
    double q[3];
    int i;
    for (i = 0; i < 3; ++i)
        q[i] = c->Tr[4 * i] * p[0] + c->Tr[4 * i + 1] * p[1] + c->Tr[4 * i + 2] * p[2] + c->Tr[4 * i + 3];
    for (i = 0; i < 3; ++i)
        out[i] = c->R0[3 * i] * q[0] + c->R0[3 * i + 1] * q[1] + c->R0[3 * i + 2] * q[2];
}

static double wrap_pi(double a)
{
    while (a > M_PI_D)
        a -= 2.0 * M_PI_D;
    while (a <= -M_PI_D)
        a += 2.0 * M_PI_D;
    return a;
}

int cli_kitti_box(const cli_calib_t *c, const lidet_box_t *b, cli_kitti_t *out)
{
    const double cy = cos(b->yaw_rad), sy = sin(b->yaw_rad);
    double ctr[3], dir_s[3], dir_r[3], zero[3] = {0, 0, 0}, o_r[3];
    double x1 = 1e30, y1 = 1e30, x2 = -1e30, y2 = -1e30;
    int k;
    ctr[0] = b->cx_m;
    ctr[1] = b->cy_m;
    ctr[2] = b->cz_m;
    velo_to_rect(c, ctr, out->loc);
    out->loc[1] += 0.5 * b->h_m; /* KITTI stores the bottom centre; camera y points down */
    /* heading direction through the rotation part only */
    dir_s[0] = cy;
    dir_s[1] = sy;
    dir_s[2] = 0.0;
    velo_to_rect(c, dir_s, dir_r);
    velo_to_rect(c, zero, o_r);
    for (k = 0; k < 3; ++k)
        dir_r[k] -= o_r[k];
    out->ry = wrap_pi(atan2(-dir_r[2], dir_r[0]));
    out->alpha = wrap_pi(out->ry - atan2(out->loc[0], out->loc[2]));
    for (k = 0; k < 8; ++k)
    {
        const double dx = ((k & 3) == 0 || (k & 3) == 3 ? 0.5 : -0.5) * b->l_m;
        const double dy = ((k & 3) < 2 ? 0.5 : -0.5) * b->w_m;
        const double dz = (k < 4 ? -0.5 : 0.5) * b->h_m;
        double p[3], r[3], u, v, w;
        p[0] = b->cx_m + cy * dx - sy * dy;
        p[1] = b->cy_m + sy * dx + cy * dy;
        p[2] = b->cz_m + dz;
        velo_to_rect(c, p, r);
        if (r[2] < 0.1)
            return 1;
        u = c->P2[0] * r[0] + c->P2[1] * r[1] + c->P2[2] * r[2] + c->P2[3];
        v = c->P2[4] * r[0] + c->P2[5] * r[1] + c->P2[6] * r[2] + c->P2[7];
        w = c->P2[8] * r[0] + c->P2[9] * r[1] + c->P2[10] * r[2] + c->P2[11];
        u /= w;
        v /= w;
        x1 = u < x1 ? u : x1;
        x2 = u > x2 ? u : x2;
        y1 = v < y1 ? v : y1;
        y2 = v > y2 ? v : y2;
    }
    out->bbox[0] = x1 < 0 ? 0 : (x1 > 1241 ? 1241 : x1);
    out->bbox[2] = x2 < 0 ? 0 : (x2 > 1241 ? 1241 : x2);
    out->bbox[1] = y1 < 0 ? 0 : (y1 > 374 ? 374 : y1);
    out->bbox[3] = y2 < 0 ? 0 : (y2 > 374 ? 374 : y2);
    return 0;
}

/* One label_2 line; 0, or 1 when the box is behind the camera (not written). Image 1242 x 375. */
static int kitti_line(FILE *f, const cli_calib_t *c, const lidet_detection_t *d)
{
    const lidet_box_t *b = &d->box;
    cli_kitti_t k;
    if (cli_kitti_box(c, b, &k) != 0)
        return 1;
    fprintf(f, "%s 0.00 0 %.2f %.2f %.2f %.2f %.2f %.3f %.3f %.3f %.3f %.3f %.3f %.4f %.4f\n",
            cli_class_names[d->cls], k.alpha, k.bbox[0], k.bbox[1], k.bbox[2], k.bbox[3], (double)b->h_m,
            (double)b->w_m, (double)b->l_m, k.loc[0], k.loc[1], k.loc[2], k.ry, (double)d->score);
    return 0;
}

/* ---- ground truth in lidet's sensor-frame line format (for the picture) ------------------------- */

typedef struct
{
    lidet_box_t box;
    char cls[32];
} gt_t;

/* appends g to the growing array *out (*n entries, *cap allocated); 0, or 1 when out of memory */
static int gt_push(gt_t **out, uint32_t *n, uint32_t *cap, const gt_t *g)
{
    if (*n == *cap)
    {
        gt_t *t;
        *cap = *cap ? 2u * *cap : 16u;
        t = (gt_t *)realloc(*out, *cap * sizeof(gt_t));
        if (t == NULL)
            return 1;
        *out = t;
    }
    (*out)[(*n)++] = *g;
    return 0;
}

static int read_gt(const char *path, gt_t **out, uint32_t *n)
{
    FILE *f = fopen(path, "r");
    char line[512];
    uint32_t cap = 0;
    int ln = 0;
    *out = NULL;
    *n = 0;
    if (f == NULL)
    {
        fprintf(stderr, "lidet detect: cannot open '%s'\n", path);
        return 1;
    }
    while (fgets(line, sizeof line, f) != NULL)
    {
        gt_t g;
        float v[8];
        char *hash = strchr(line, '#');
        ++ln;
        if (hash != NULL)
            *hash = '\0';
        if (strspn(line, " \t\r\n") == strlen(line))
            continue;
        if (sscanf(line, "%31s %f %f %f %f %f %f %f %f", g.cls, &v[0], &v[1], &v[2], &v[3], &v[4], &v[5],
                   &v[6], &v[7]) != 9)
        {
            fprintf(stderr, "lidet detect: %s:%d: expected '<class> <x> <y> <z> <l> <w> <h> <yaw> <score>'\n",
                    path, ln);
            free(*out);
            fclose(f);
            return 1;
        }
        g.box.cx_m = v[0];
        g.box.cy_m = v[1];
        g.box.cz_m = v[2];
        g.box.l_m = v[3];
        g.box.w_m = v[4];
        g.box.h_m = v[5];
        g.box.yaw_rad = v[6];
        if (gt_push(out, n, &cap, &g) != 0)
        {
            free(*out);
            fclose(f);
            return 1;
        }
    }
    fclose(f);
    return 0;
}

/* rectified camera frame -> sensor frame: v = Tr_R^T (R0^T r - Tr_t) (both rotations orthonormal) */
static void rect_to_velo(const cli_calib_t *c, const double r[3], double v[3])
{
    double q[3];
    int i;
    for (i = 0; i < 3; ++i)
        q[i] = c->R0[i] * r[0] + c->R0[3 + i] * r[1] + c->R0[6 + i] * r[2] - c->Tr[4 * i + 3];
    for (i = 0; i < 3; ++i)
        v[i] = c->Tr[i] * q[0] + c->Tr[4 + i] * q[1] + c->Tr[8 + i] * q[2];
}

/* KITTI label_2 (camera frame, bottom centre) -> sensor-frame boxes; DontCare lines skipped */
static int read_gt_kitti(const char *path, const cli_calib_t *c, gt_t **out, uint32_t *n)
{
    FILE *f = fopen(path, "r");
    char line[512];
    uint32_t cap = 0;
    int ln = 0;
    *out = NULL;
    *n = 0;
    if (f == NULL)
    {
        fprintf(stderr, "lidet detect: cannot open '%s'\n", path);
        return 1;
    }
    while (fgets(line, sizeof line, f) != NULL)
    {
        gt_t g;
        double v[14], ctr[3], vel[3], d[3], o[3], zero[3] = {0, 0, 0}, dv[3];
        ++ln;
        if (strspn(line, " \t\r\n") == strlen(line))
            continue;
        if (sscanf(line, "%31s %lf %lf %lf %lf %lf %lf %lf %lf %lf %lf %lf %lf %lf %lf", g.cls, &v[0], &v[1],
                   &v[2], &v[3], &v[4], &v[5], &v[6], &v[7], &v[8], &v[9], &v[10], &v[11], &v[12],
                   &v[13]) != 15)
        {
            fprintf(stderr, "lidet detect: %s:%d: not a KITTI label_2 line (15 fields)\n", path, ln);
            free(*out);
            fclose(f);
            return 1;
        }
        if (strcmp(g.cls, "DontCare") == 0)
            continue;
        ctr[0] = v[10];
        ctr[1] = v[11] - 0.5 * v[7]; /* bottom centre -> centre (camera y down) */
        ctr[2] = v[12];
        rect_to_velo(c, ctr, vel);
        d[0] = cos(v[13]);
        d[1] = 0.0;
        d[2] = -sin(v[13]);
        rect_to_velo(c, d, dv);
        rect_to_velo(c, zero, o);
        g.box.cx_m = (float)vel[0];
        g.box.cy_m = (float)vel[1];
        g.box.cz_m = (float)vel[2];
        g.box.h_m = (float)v[7];
        g.box.w_m = (float)v[8];
        g.box.l_m = (float)v[9];
        g.box.yaw_rad = (float)atan2(dv[1] - o[1], dv[0] - o[0]);
        if (gt_push(out, n, &cap, &g) != 0)
        {
            free(*out);
            fclose(f);
            return 1;
        }
    }
    fclose(f);
    return 0;
}

/* ---- bird's-eye picture -------------------------------------------------------------------------- */

#define BEV_W 800u
#define BEV_H 800u
/* --png-range M: the picture shows M metres each way around the sensor (default 40: 0.1 m a pixel) */
#define BEV_RES CLI_PNG_RES(BEV_W)

static const uint8_t k_class_rgb[LIDET_N_CLASSES][3] = {{255, 80, 60}, {60, 220, 255}, {255, 220, 40}};
static const char *const k_class_legend[LIDET_N_CLASSES] = {"car", "cyclist", "pedestrian"};

/* the picture: points (obstacles grey, ground dark), ground truth, detections; framed by cli_bev_write with a
 * title (scan, sensor, models, total time, counts per class), axes, scale bar and legend */
static int write_png(const char *path, const float *pts, uint32_t n, const uint8_t *ground_pp,
                     const lidet_detection_t *det, uint32_t n_det, const gt_t *gt, uint32_t n_gt, int with_gt,
                     const char *title, uint32_t n_points)
{
    cli_legend_t legend[6];
    char subtitle[192];
    uint32_t per_class[LIDET_N_CLASSES] = {0};
    int n_legend = 0, k;
    uint8_t *rgb = (uint8_t *)calloc((size_t)BEV_W * BEV_H * 3u, 1);
    const uint8_t *grey = cli_rgb_obstacle, *dark = cli_rgb_ground, green[3] = {60, 230, 90};
    cli_scene_t sc;
    uint32_t i;
    int rc;
    if (rgb == NULL)
        return -1;
    sc.rgb = rgb;
    sc.w = BEV_W;
    sc.h = BEV_H;
    sc.res_m = BEV_RES;
    cli_scene_points(&sc, pts, n, ground_pp);
    for (i = 0; i < n_gt; ++i)
        cli_scene_box(&sc, &gt[i].box, green, 0);
    for (i = 0; i < n_det; ++i)
    {
        cli_scene_box(&sc, &det[i].box, k_class_rgb[det[i].cls], 1);
        per_class[det[i].cls]++;
    }
    snprintf(subtitle, sizeof subtitle, "%u points  %u detections: %u car, %u cyclist, %u pedestrian",
             n_points, n_det, per_class[0], per_class[1], per_class[2]);
    for (k = 0; k < LIDET_N_CLASSES; ++k)
    {
        legend[n_legend].label = k_class_legend[k];
        memcpy(legend[n_legend++].rgb, k_class_rgb[k], 3);
    }
    if (with_gt)
    {
        legend[n_legend].label = "ground truth";
        memcpy(legend[n_legend++].rgb, green, 3);
    }
    legend[n_legend].label = "obstacle points";
    memcpy(legend[n_legend++].rgb, grey, 3);
    if (ground_pp != NULL)
    {
        legend[n_legend].label = "ground points";
        memcpy(legend[n_legend++].rgb, dark, 3);
    }
    rc = cli_bev_write(path, rgb, BEV_W, BEV_H, BEV_RES, title, subtitle, legend, n_legend);
    free(rgb);
    return rc;
}

/* the detections as lidet's sensor-frame lines '<class> <x> <y> <z> <l> <w> <h> <yaw> <score>' (--out) */
static void box_lines(FILE *f, const lidet_detection_t *det, uint32_t n_det)
{
    uint32_t k;
    for (k = 0; k < n_det; ++k)
        fprintf(f, "%s %.4f %.4f %.4f %.4f %.4f %.4f %.5f %.4f\n", cli_class_names[det[k].cls],
                (double)det[k].box.cx_m, (double)det[k].box.cy_m, (double)det[k].box.cz_m,
                (double)det[k].box.l_m, (double)det[k].box.w_m, (double)det[k].box.h_m,
                (double)det[k].box.yaw_rad, (double)det[k].score);
}

/* the JSON object of a run (one line); scan: the capture's scan (--pcap: its number, kind, frames, returns and times
 * first), or NULL */
static void json_result(const cli_args_t *a, const char *chosen, const lidet_detector_cfg_t *cfg,
                        const lidet_detector_stats_t *ds, const lidet_detection_t *det, uint32_t n_det,
                        lidet_status_t st, const double *ms, const cli_scan_info_t *scan)
{
    uint32_t k;
    cli_json_begin(stdout);
    if (scan != NULL)
    {
        cli_json_int(stdout, "scan", scan->index);
        cli_json_str(stdout, "kind", cli_scan_kind(scan->kind));
        cli_json_int(stdout, "first_packet", scan->first_frame);
        cli_json_int(stdout, "last_packet", scan->last_frame);
        cli_json_int(stdout, "returns", scan->n_returns);
        cli_json_int(stdout, "excess_returns", scan->n_excess);
        fprintf(stdout, ", \"sensor_time_s\": %.6f, \"capture_time_s\": %.6f", (double)scan->t_us * 1e-6,
                scan->capture_s);
    }
    cli_json_str(stdout, "sensor", a->sensor);
    cli_json_str(stdout, "model", chosen);
    cli_json_int(stdout, "points", a->n_points);
    cli_json_int(stdout, "clusters", ds->n_clusters);
    cli_json_int(stdout, "out_of_crop", ds->n_out_of_crop);
    cli_json_int(stdout, "out_of_range", ds->n_out_of_range);
    cli_json_int(stdout, "too_tall", ds->n_too_tall);
    cli_json_int(stdout, "over_budget", ds->n_over_budget);
    cli_json_int(stdout, "budget", cfg->max_proposals);
    cli_json_int(stdout, "classified", ds->n_classified);
    cli_json_int(stdout, "gate1_rejected", ds->n_gate1_rejected);
    cli_json_int(stdout, "boxed", ds->n_boxed);
    cli_json_int(stdout, "box_budget", cfg->max_boxes);
    cli_json_int(stdout, "over_box_budget", ds->n_over_box_budget);
    cli_json_int(stdout, "gate2_rejected", ds->n_gate2_rejected);
    cli_json_int(stdout, "size_rejected", ds->n_size_rejected);
    cli_json_int(stdout, "nms_suppressed", ds->n_nms_suppressed);
    cli_json_int(stdout, "group_split", ds->n_group_split);
    cli_json_int(stdout, "group_classified", ds->n_group_classified);
    cli_json_int(stdout, "group_boxed", ds->n_group_boxed);
    cli_json_int(stdout, "score_rejected", ds->n_score_rejected);
    cli_json_int(stdout, "detections", n_det);
    cli_json_int(stdout, "status", st);
    cli_json_int(stdout, "repeat", a->repeat);
    cli_json_num(stdout, "project_ms", ms[LIDET_DET_STAGE_PROJECT]);
    cli_json_num(stdout, "ground_ms", ms[LIDET_DET_STAGE_GROUND]);
    cli_json_num(stdout, "cluster_ms", ms[LIDET_DET_STAGE_CLUSTER]);
    cli_json_num(stdout, "classify_ms", ms[LIDET_DET_STAGE_CLASSIFY]);
    cli_json_num(stdout, "box_ms", ms[LIDET_DET_STAGE_BOX]);
    cli_json_num(stdout, "post_ms", ms[LIDET_DET_STAGE_POST]);
    cli_json_num(stdout, "total_ms", ms[LIDET_DET_N_STAGES]);
    if (cli_fixed_stream > 0u)
    {
        cli_json_int(stdout, "stream_chunk", cli_fixed_stream);
        cli_json_num(stdout, "stream_end_ms", cli_stream_end_ms);
    }
    if (cli_fixed_stream_sectors)
    {
        cli_json_int(stdout, "stream_sectors", cli_stream_sectors_done);
    }
    fprintf(stdout, ", \"boxes\": [");
    for (k = 0; k < n_det; ++k)
        fprintf(
            stdout,
            "%s{\"class\": \"%s\", \"score\": %.5f, \"energy_cls\": %.4f, \"energy_box\": %.4f, "
            "\"x\": %.4f, \"y\": %.4f, \"z\": %.4f, \"l\": %.4f, \"w\": %.4f, \"h\": %.4f, \"yaw\": %.5f, "
            "\"cluster\": %u, \"cluster_points\": %u}",
            k ? ", " : "", cli_class_names[det[k].cls], (double)det[k].score, (double)det[k].energy_cls,
            (double)det[k].energy_box, (double)det[k].box.cx_m, (double)det[k].box.cy_m,
            (double)det[k].box.cz_m, (double)det[k].box.l_m, (double)det[k].box.w_m, (double)det[k].box.h_m,
            (double)det[k].box.yaw_rad, det[k].cluster_id, det[k].n_points);
    fprintf(stdout, "]");
    cli_json_end(stdout);
}

/* ---- options -------------------------------------------------------------------------------------- */

static int apply_set(lidet_detector_cfg_t *c, const char *kv)
{
    size_t klen;
    double v;
    if (cli_split_set(kv, &klen, &v) != 0)
        return 1;
    CLI_SET_FLOAT(c, kv, klen, v, crop_half_rad)
    CLI_SET_FLOAT(c, kv, klen, v, max_range_m)
    CLI_SET_FLOAT(c, kv, klen, v, max_height_extent_m)
    CLI_SET_FLOAT(c, kv, klen, v, nms_iou)
    CLI_SET_INT(c, kv, klen, v, max_proposals, uint32_t, 4294967295.0)
    CLI_SET_INT(c, kv, klen, v, max_boxes, uint32_t, 4294967295.0)
    CLI_SET_INT(c, kv, klen, v, gate1, uint8_t, 1)
    CLI_SET_INT(c, kv, klen, v, gate2, uint8_t, 1)
    CLI_SET_FLOAT(c, kv, klen, v, gate1_margin)
    CLI_SET_FLOAT(c, kv, klen, v, gate2_margin)
    CLI_SET_INT(c, kv, klen, v, group_split, uint8_t, 1)
    CLI_SET_FLOAT(c, kv, klen, v, group_max_range_m)
    CLI_SET_FLOAT(c, kv, klen, v, group_gate1_margin)
    CLI_SET_FLOAT(c, kv, klen, v, gate1_large_car_margin)
    CLI_SET_FLOAT(c, kv, klen, v, car_min_z_spread_m)
    CLI_SET_FLOAT(c, kv, klen, v, car_ground_m)
    CLI_SET_INT(c, kv, klen, v, proposal.seed, uint32_t, 4294967295.0)
    {
        /* score_box_weight.CLASS / score_points_weight.CLASS / gate2.CLASS, in lidet_class_t order */
        static const char *const names[LIDET_N_CLASSES] = {"score_box_weight.car", "score_box_weight.cyclist",
                                                           "score_box_weight.pedestrian"};
        static const char *const gnames[LIDET_N_CLASSES] = {"gate2.car", "gate2.cyclist", "gate2.pedestrian"};
        static const char *const pnames[LIDET_N_CLASSES] = {
            "score_points_weight.car", "score_points_weight.cyclist", "score_points_weight.pedestrian"};
        static const char *const mnames[LIDET_N_CLASSES] = {"min_score.car", "min_score.cyclist",
                                                            "min_score.pedestrian"};
        static const char *const g1names[LIDET_N_CLASSES] = {"gate1_margin.car", "gate1_margin.cyclist",
                                                             "gate1_margin.pedestrian"};
        int k;
        for (k = 0; k < LIDET_N_CLASSES; ++k)
        {
            if (klen == strlen(names[k]) && strncmp(kv, names[k], klen) == 0)
            {
                c->score_box_weight[k] = (float)v;
                return 0;
            }
            if (klen == strlen(pnames[k]) && strncmp(kv, pnames[k], klen) == 0)
            {
                c->score_points_weight[k] = (float)v;
                return 0;
            }
            if (klen == strlen(mnames[k]) && strncmp(kv, mnames[k], klen) == 0)
            {
                c->min_score[k] = (float)v;
                return 0;
            }
            if (klen == strlen(g1names[k]) && strncmp(kv, g1names[k], klen) == 0)
            {
                c->gate1_class_margin[k] = (float)v;
                return 0;
            }
            if (klen == strlen(gnames[k]) && strncmp(kv, gnames[k], klen) == 0)
            {
                if (v != 0.0 && v != 1.0)
                    return 1;
                c->gate2_class[k] = (uint8_t)v;
                return 0;
            }
        }
    }
    CLI_SET_FLOAT(c, kv, klen, v, stages.proj.azimuth_half_rad)
    CLI_SET_INT(c, kv, klen, v, stages.ground.seed_per_cell, uint8_t, 1)
    /* the ground stage's speed knobs (lidet_ground.h; the integer detector takes the same values) */
    CLI_SET_INT(c, kv, klen, v, stages.ground.sample_step, uint16_t, 16)
    CLI_SET_INT(c, kv, klen, v, stages.ground.sample_col_step, uint16_t, 16)
    CLI_SET_INT(c, kv, klen, v, stages.ground.ransac_iters, uint16_t, 1000)
    CLI_SET_INT(c, kv, klen, v, stages.ground.refine_iters, uint8_t, 10)
    /* any other ground field (the float detector; --fixed takes the speed knobs above only) */
    if (strncmp(kv, "stages.ground.", 14) == 0)
        return cli_ground_set(&c->stages.ground, kv + 14);
    /* any clustering field, the proposal refinement of issue 15 included */
    if (strncmp(kv, "stages.cluster.", 15) == 0)
        return cli_cluster_set(&c->stages.cluster, kv + 15);
    return 1;
}

/* ---- --dump: every result of the scan, bit for bit (determinism tests, issue 19) -------------------- */

/* Binary, host byte order: "LDTD", n_points, n_clusters, n_detections (uint32); per point its cluster id
 * (uint32) then its ground flag (uint8), 0 past LIDET_MAX_POINTS; per kept cluster n_points, seed_pixel,
 * n_rescued (uint32), mean, min, max (3 float32 each), outcome (uint32), then its proposal (the detector's
 * proposal configuration: n_points rows of x, y, z float32, the mean, the 3 voxel bins as uint32); per
 * detection class, cluster id, n_points (uint32), score, energy_cls, energy_box and the box (cx, cy, cz,
 * l, w, h, yaw) as float32. Written field by field: no struct padding reaches the file. */
static int write_dump(const char *path, const int32_t *pp, uint32_t n_points)
{
    const lidet_workspace_t *ws = lidet_detector_workspace(&g_det);
    const uint32_t np = n_points < LIDET_MAX_POINTS ? n_points : LIDET_MAX_POINTS;
    const lidet_cluster_rec_t *recs;
    const lidet_detection_t *det;
    const uint8_t *oc;
    uint32_t n_cl = 0, n_det = 0, n_oc = 0, i, k, *ids;
    uint8_t *gnd;
    lidet_proposal_cfg_t pc;
    static lidet_proposal_t prop;
    FILE *f;
    int bad;
    recs = lidet_workspace_clusters(ws, &n_cl);
    det = lidet_detector_detections(&g_det, &n_det);
    oc = lidet_detector_outcomes(&g_det, &n_oc);
    ids = (uint32_t *)calloc((size_t)n_points + 1u, sizeof *ids);
    gnd = (uint8_t *)calloc((size_t)n_points + 1u, 1);
    f = fopen(path, "wb");
    bad = ids == NULL || gnd == NULL || f == NULL || n_oc != n_cl ||
          lidet_workspace_point_labels(ws, pp, np, ids, gnd) != LIDET_OK;
    bad = bad || fwrite("LDTD", 1, 4, f) != 4 || cli_put_u32(f, n_points) || cli_put_u32(f, n_cl) ||
          cli_put_u32(f, n_det);
    for (i = 0; !bad && i < n_points; ++i)
        bad = cli_put_u32(f, ids[i]) || fputc(gnd[i], f) == EOF;
    lidet_proposal_cfg_default(&pc);
    pc.n_points = g_det.cfg.proposal.n_points;
    for (k = 0; !bad && k < n_cl; ++k)
    {
        bad = cli_put_u32(f, recs[k].n_points) || cli_put_u32(f, recs[k].seed_pixel) ||
              cli_put_u32(f, recs[k].n_rescued) || cli_put_u32(f, oc[k]);
        for (i = 0; !bad && i < 3; ++i)
            bad = cli_put_f32(f, recs[k].mean_m[i]) || cli_put_f32(f, recs[k].min_m[i]) ||
                  cli_put_f32(f, recs[k].max_m[i]);
        bad = bad || lidet_workspace_proposal(ws, k, &pc, &prop) != LIDET_OK ||
              fwrite(prop.xyz, sizeof(float) * 3u, prop.n_points, f) != prop.n_points;
        for (i = 0; !bad && i < 3; ++i)
            bad = cli_put_f32(f, prop.mean_m[i]) || cli_put_u32(f, (uint32_t)(int32_t)prop.voxel[i]);
    }
    for (k = 0; !bad && k < n_det; ++k)
        bad = cli_put_u32(f, det[k].cls) || cli_put_u32(f, det[k].cluster_id) ||
              cli_put_u32(f, det[k].n_points) || cli_put_f32(f, det[k].score) ||
              cli_put_f32(f, det[k].energy_cls) || cli_put_f32(f, det[k].energy_box) ||
              cli_put_f32(f, det[k].box.cx_m) || cli_put_f32(f, det[k].box.cy_m) ||
              cli_put_f32(f, det[k].box.cz_m) || cli_put_f32(f, det[k].box.l_m) ||
              cli_put_f32(f, det[k].box.w_m) || cli_put_f32(f, det[k].box.h_m) ||
              cli_put_f32(f, det[k].box.yaw_rad);
    if (f != NULL && fclose(f) != 0)
        bad = 1;
    free(ids);
    free(gnd);
    return bad ? -1 : 0;
}

void cli_det_usage(FILE *f)
{
    fprintf(f, "  --model NAME     model family: weights cls_NAME + box_NAME (default: the sensor's family,\n"
               "                   else hdl64; a --sensor-file's \"model\", else hdl64 for >= 32 rows and\n"
               "                   vlp16 below); available:");
    {
        uint32_t i;
        for (i = 0; i < LIDET_WEIGHTS_N_MODELS; ++i)
            fprintf(f, " %s", lidet_weights_models[i].name);
    }
    fprintf(
        f, "\n  --crop           keep the KITTI camera field of view only (|azimuth| <= 45 deg)\n"
           "  --fixed          the integer detector (lidet_detector_q.h: int8 models, no float; the scan\n"
           "                   converted to millimetres); the same outputs\n"
           "  --range-only     with --fixed: the range-only pixel of the integer firmware (x, y, z\n"
           "                   decoded from row, column and range; lidet_detector_q_cfg_t.range_only)\n"
           "  --stream N       with --fixed and the scan as returns (--returns, --pcap): the returns\n"
           "                   streamed into the detector N at a time, as a driver feeds packets\n"
           "                   (lidet_detector_q_stream_*; the same results); --json adds\n"
           "                   stream_end_ms, the time from the last chunk to the detections\n"
           "  --stream-sectors with --fixed: the ground stage run sector by sector while the scan\n"
           "                   streams in (lidet_detector_q_cfg_t.stream_sectors, the range-only pixel;\n"
           "                   a RANSAC stream per ground cell); --json adds stream_sectors, the\n"
           "                   sectors done before the end\n"
           "  --cpu-clock      stage and total times (--json *_ms) in this thread's CPU time, not wall time\n"
           "                   (what other processes on a busy machine do not inflate)\n"
           "  --set KEY=VALUE  override a lidet_detector_cfg_t field: crop_half_rad, max_range_m,\n"
           "                   max_height_extent_m (0: classify tall clusters too),\n"
           "                   nms_iou, max_proposals, max_boxes, gate1, gate2, gate1_margin,\n"
           "                   gate2_margin (nats added to the models' gates),\n"
           "                   gate1_margin.car|cyclist|pedestrian (nats added to gate1_margin\n"
           "                   for that class; default 0), gate1_large_car_margin (nats added\n"
           "                   to gate 1 for a car whose cluster holds >= 100 pixels; default\n"
           "                   1 for > 16 beams, 0 for <= 16),\n"
           "                   gate2.car|cyclist|pedestrian (0 or 1: whether gate 2\n"
           "                   judges the class; default 1, 1, 0),\n"
           "                   group_split (0 or 1: people side by side in one cluster\n"
           "                   split by the classifier's judgement; default 1 for > 16\n"
           "                   beams), group_max_range_m (default 40), group_gate1_margin\n"
           "                   (nats added to gate 1 when a cut into people is judged;\n"
           "                   default 2),\n"
           "                   min_score.car|cyclist|pedestrian (the operating point: detections\n"
           "                   scoring below are dropped; default 0.6, 0, 0),\n"
           "                   car_min_z_spread_m (a car's cluster of >= 100\n"
           "                   pixels flatter than this in z is a surface; 0: off; default 0.6\n"
           "                   for > 16 beams, 0 for <= 16), car_ground_m (car boxes stretched\n"
           "                   down to the ground pixels within this of the footprint; 0: off;\n"
           "                   default 1), proposal.seed (the\n"
           "                   resampling's seed, default 0x5EED1234 = 1592594996: another draw of\n"
           "                   64 points from each cluster; --fixed takes it too),\n"
           "                   score_box_weight.car|cyclist|pedestrian (the score's weight on gate 2's\n"
           "                   margin), score_points_weight.CLASS (on ln(points / 64));\n"
           "                   stages.cluster.KEY: a\n"
           "                   lidet_cluster_cfg_t field as in lidet cluster --set (e.g.\n"
           "                   stages.cluster.split_people=0: no proposal refinement);\n"
           "                   stages.proj.azimuth_half_rad: the projection's window and\n"
           "                   stages.ground.seed_per_cell: a RANSAC stream per ground cell (the crop\n"
           "                   sets both: the clustering's window + one ground sector, and 1)\n"
           "                   stages.ground.KEY: a lidet_ground_cfg_t field as in lidet ground\n"
           "                   --set (e.g. stages.ground.far_max_step_m=0: far planes judged by the\n"
           "                   sensor's height); --fixed takes sample_step, sample_col_step,\n"
           "                   ransac_iters, refine_iters, seed, seed_per_cell, far_max_step_m,\n"
           "                   far2_split_m and the\n"
           "                   clustering's\n"
           "                   split_people, join_cars and regrow_* fields, in integer units\n");
}

static void usage_extra(void)
{
    cli_det_usage(stderr);
    fprintf(stderr,
            "  --calib FILE     KITTI calibration (P2, R0_rect, Tr_velo_to_cam) for --kitti-out\n"
            "  --kitti-out FILE label_2 lines in the camera frame (2D box from the projected corners)\n"
            "  --gt FILE        ground-truth boxes (lidet's sensor-frame lines) drawn in --png\n"
            "  --gt-kitti FILE  ground truth as KITTI label_2 (with --calib) drawn in --png\n"
            "  --png-range M    --png shows M metres each way around the sensor, in [5, 200] (default\n"
            "                   40; a room: 10)\n"
            "  --returns        with --fixed and --ring: the scan fed as the sensor's returns (range,\n"
            "                   azimuth, ring: lidet_detector_q_run_returns), as the firmware takes it\n"
            "  --out FILE       detections as '<class> <x> <y> <z> <l> <w> <h> <yaw> <score>' lines\n"
            "  --dump FILE      every result bit for bit (per-point labels, clusters, proposals,\n"
            "                   detections; binary, see write_dump in cli_detect.c; with --fixed the\n"
            "                   integer detector's labels, outcomes, counts and detections,\n"
            "                   cli_detect_q_dump in cli_detect_q.c)\n"
            "  lidet detect --pcap FILE [options]: the scans of a packet capture (Velodyne):\n");
    cli_pcap_usage(stderr, 1);
}

enum
{
    OPT_MODEL,
    OPT_SET,
    OPT_CROP,
    OPT_FIXED,
    OPT_RANGE_ONLY,
    OPT_STREAM,
    OPT_STREAM_SECTORS,
    OPT_CPU_CLOCK
};

const cli_opt_t cli_opts_det[] = {{"model", required_argument, OPT_MODEL, "NAME: a model family of weights/"},
                                  {"set", required_argument, OPT_SET, "KEY=VALUE"},
                                  {"crop", no_argument, OPT_CROP, NULL},
                                  {"fixed", no_argument, OPT_FIXED, NULL},
                                  {"range-only", no_argument, OPT_RANGE_ONLY, NULL},
                                  {"stream", required_argument, OPT_STREAM, "N: returns per chunk, 1 to 1000000"},
                                  {"stream-sectors", no_argument, OPT_STREAM_SECTORS, NULL},
                                  {"cpu-clock", no_argument, OPT_CPU_CLOCK, NULL},
                                  {NULL, 0, 0, NULL}};

int cli_det_take(void *ctx, int id, const char *v)
{
    cli_det_opts_t *o = (cli_det_opts_t *)ctx;
    switch (id)
    {
    case OPT_MODEL:
        o->family = v;
        break;
    case OPT_SET: /* checked by cli_det_config, against the configuration */
        o->sets[o->n_sets++] = v;
        break;
    case OPT_CROP:
        o->crop = 1;
        break;
    case OPT_FIXED:
        o->fixed = 1;
        break;
    case OPT_RANGE_ONLY:
        cli_fixed_range_only = 1;
        break;
    case OPT_STREAM:
    {
        char *end = NULL;
        const unsigned long n = strtoul(v, &end, 10);
        if (end == v || *end != '\0' || v[0] == '-' || n < 1ul || n > 1000000ul)
        {
            fprintf(stderr, "lidet %s: --stream %s: returns per chunk, 1 to 1000000\n", cli_cmd, v);
            return 1;
        }
        cli_fixed_stream = (uint32_t)n;
        break;
    }
    case OPT_STREAM_SECTORS:
        cli_fixed_stream_sectors = 1;
        break;
    default: /* OPT_CPU_CLOCK */
        cli_stage_clock_cpu = 1;
        break;
    }
    return 0;
}

static int pick_models(const char *family, const char *sensor, const lidet_pn_model_t **cls,
                       const lidet_pn_model_t **box, char *chosen, size_t chosen_len)
{
    char name[96];
    const char *fams[2];
    int k;
    fams[0] = family != NULL ? family : sensor;
    fams[1] = family != NULL ? NULL : "hdl64";
    for (k = 0; k < 2 && fams[k] != NULL; ++k)
    {
        snprintf(name, sizeof name, "cls_%s", fams[k]);
        *cls = lidet_pn_find(lidet_weights_models, LIDET_WEIGHTS_N_MODELS, name);
        snprintf(name, sizeof name, "box_%s", fams[k]);
        *box = lidet_pn_find(lidet_weights_models, LIDET_WEIGHTS_N_MODELS, name);
        if (*cls != NULL && *box != NULL)
        {
            snprintf(chosen, chosen_len, "%s", fams[k]);
            return 0;
        }
    }
    fprintf(stderr, "lidet %s: no models cls_%s / box_%s in weights/ (lidet %s --help lists them)\n", cli_cmd,
            fams[0], fams[0], cli_cmd);
    return 1;
}

int cli_det_config(const cli_args_t *a, const cli_det_opts_t *o, lidet_detector_cfg_t *cfg,
                   const lidet_pn_model_t **mc, const lidet_pn_model_t **mb, char *chosen, size_t chosen_len)
{
    int i;
    if ((cli_fixed_range_only || cli_fixed_returns || cli_fixed_stream || cli_fixed_stream_sectors) && !o->fixed)
    {
        fprintf(stderr, "lidet %s: --%s is a setting of the integer detector: add --fixed\n", cli_cmd,
                cli_fixed_returns          ? "returns"
                : cli_fixed_stream         ? "stream"
                : cli_fixed_stream_sectors ? "stream-sectors"
                                           : "range-only");
        return 1;
    }
    /* a file's sensor: its own family (the description's "model", else by rows), without the fallback */
    if (pick_models(o->family != NULL ? o->family : a->family, a->sensor, mc, mb, chosen, chosen_len) != 0)
        return 1;
    lidet_detector_cfg_default(cfg, a->sensor_profile);
    if (o->crop)
        cfg->crop_half_rad = (float)(M_PI_D / 4.0);
    for (i = 0; i < o->n_sets; ++i)
    {
        if (apply_set(cfg, o->sets[i]) != 0)
        {
            fprintf(stderr, "lidet %s: bad --set '%s' (KEY=VALUE with a lidet_detector_cfg_t field)\n",
                    cli_cmd, o->sets[i]);
            return 1;
        }
    }
    return 0;
}

int cli_detect_f_init(const lidet_detector_cfg_t *cfg, const lidet_pn_model_t *mc, const lidet_pn_model_t *mb)
{
    lidet_detector_cfg_t c = *cfg;
    lidet_status_t st;
    c.clock = cli_stage_clock_ns;
    st = lidet_detector_init(&g_det, &c, mc, mb);
    if (st != LIDET_OK)
    {
        fprintf(stderr, "lidet %s: init (configuration or models): %s\n", cli_cmd, lidet_status_str(st));
        return 1;
    }
    return 0;
}

int cli_detect_f_run(const cli_args_t *a, int32_t *pp, double *ms, const lidet_detection_t **det,
                     uint32_t *n_det, const lidet_detector_stats_t **ds, lidet_status_t *status)
{
    const int repeat = a->repeat > 0 ? a->repeat : 1;
    const lidet_detector_stats_t *s;
    double *t = (double *)malloc(sizeof(double) * (size_t)repeat * (LIDET_DET_N_STAGES + 1u));
    uint32_t k;
    int i;
    if (t == NULL)
    {
        fprintf(stderr, "lidet %s: out of memory\n", cli_cmd);
        return 1;
    }
    for (i = 0; i < repeat; ++i)
    {
        const double t0 = cli_stage_clock_cpu ? cli_cpu_ms() : cli_now_ms();
        *status = lidet_detector_run(&g_det, a->points, a->n_points, 4, a->ring, i == 0 ? pp : NULL);
        t[(size_t)LIDET_DET_N_STAGES * (size_t)repeat + (size_t)i] =
            (cli_stage_clock_cpu ? cli_cpu_ms() : cli_now_ms()) - t0;
        if (!LIDET_SUCCEEDED(*status))
        {
            fprintf(stderr, "lidet %s: detector: %s\n", cli_cmd, lidet_status_str(*status));
            free(t);
            return 1;
        }
        s = lidet_detector_stats(&g_det);
        for (k = 0; k < LIDET_DET_N_STAGES; ++k)
            t[(size_t)k * (size_t)repeat + (size_t)i] = (double)s->ticks[k] * 1e-6;
    }
    for (k = 0; k <= LIDET_DET_N_STAGES; ++k)
        ms[k] = cli_median(t + (size_t)k * (size_t)repeat, repeat);
    free(t);
    *ds = lidet_detector_stats(&g_det);
    *det = lidet_detector_detections(&g_det, n_det);
    return 0;
}

int cli_detect_f_ground(const int32_t *pp, uint32_t n_points, uint8_t *point_ground)
{
    const uint32_t np = n_points < LIDET_MAX_POINTS ? n_points : LIDET_MAX_POINTS;
    uint32_t *ids = (uint32_t *)malloc(sizeof(uint32_t) * (size_t)(np + 1u));
    int rc = ids == NULL || lidet_workspace_point_labels(lidet_detector_workspace(&g_det), pp, np, ids,
                                                         point_ground) != LIDET_OK;
    free(ids);
    return rc;
}

/* ---- --pcap: every scan of a capture (cli_pcap.c) ------------------------------------------------------- */

/* --save-scans DIR: the scan as KITTI files, DIR/velodyne/<K:06d>.bin (float32 x, y, z, 0) and DIR/ring/<K:06d>.bin
 * (uint16 ring per point): what `lidet detect FILE --ring RING` and the Python tools read. 0, or 1 with a message. */
static int save_scan(const char *dir, uint32_t k, const cli_args_t *a)
{
    const size_t len = strlen(dir) + 32u;
    char *path = (char *)malloc(len);
    int bad = path == NULL, sub;
    for (sub = 0; sub < 2 && !bad; ++sub)
    {
        FILE *f;
        snprintf(path, len, "%s/%s/%06u.bin", dir, sub ? "ring" : "velodyne", k);
        f = fopen(path, "wb");
        bad = f == NULL || (sub ? fwrite(a->ring, sizeof(uint16_t), a->n_points, f)
                                : fwrite(a->points, 4u * sizeof(float), a->n_points, f)) != a->n_points;
        if (f != NULL && fclose(f) != 0)
            bad = 1;
        if (bad)
            fprintf(stderr, "lidet detect: cannot write '%s'\n", path);
    }
    free(path);
    return bad;
}

/* `lidet detect --pcap FILE`: per scan of the capture a header line and its box lines (or a JSON object), --out
 * DIR/<K:06d>.txt, --png the last scan (or --png-scan K); the capture's summary on stderr. */
static int detect_pcap(cli_args_t *a, const cli_det_opts_t *o, const cli_pcap_opts_t *po,
                       const char *save_dir)
{
    static lidet_detection_t det_q[LIDET_MAX_DETECTIONS];
    static lidet_detector_stats_t ds_q;
    cli_capture_t *cap = NULL;
    lidet_detector_cfg_t cfg;
    const lidet_pn_model_t *mc = NULL, *mb = NULL;
    const lidet_return_t *rets;
    cli_scan_info_t info;
    char chosen[64], label[80];
    int32_t *pp = NULL;
    uint8_t *gp = NULL;
    double *det_ms = NULL;
    uint32_t n_scans, png_k, n_run = 0;
    int rc = 1, got, warned = 0;

    if (cli_capture_open(po, a, &cap) != 0)
        return 1;
    n_scans = cli_capture_n_scans(cap);
    if (po->png_scan >= 0 && (uint32_t)po->png_scan >= n_scans)
    {
        fprintf(stderr, "lidet detect: --png-scan %ld: the capture gives %u scans (0..%u)\n", po->png_scan,
                n_scans, n_scans - 1u);
        goto done;
    }
    png_k = po->png_scan >= 0 ? (uint32_t)po->png_scan : n_scans - 1u;
    if (cli_det_config(a, o, &cfg, &mc, &mb, chosen, sizeof chosen) != 0)
        goto done;
    snprintf(label, sizeof label, "%s%s", chosen, o->fixed ? " int8" : "");
    if (a->out_path != NULL && cli_make_dir(a->out_path) != 0)
        goto done;
    if (save_dir != NULL)
    {
        const size_t len = strlen(save_dir) + 16u;
        char *sub = (char *)malloc(len);
        int bad = sub == NULL;
        if (!bad)
        {
            snprintf(sub, len, "%s/velodyne", save_dir);
            bad = cli_make_dir(sub) != 0;
        }
        if (!bad)
        {
            snprintf(sub, len, "%s/ring", save_dir);
            bad = cli_make_dir(sub) != 0;
        }
        free(sub);
        if (bad)
            goto done;
    }
    pp = (int32_t *)malloc(sizeof(int32_t) * LIDET_MAX_POINTS);
    gp = (uint8_t *)malloc((size_t)LIDET_MAX_POINTS + 1u);
    det_ms = (double *)malloc(sizeof(double) * n_scans);
    if (pp == NULL || gp == NULL || det_ms == NULL)
        goto done;
    if (!o->fixed && cli_detect_f_init(&cfg, mc, mb) != 0)
        goto done;
    while ((got = cli_capture_next(cap, a, &rets, &info)) == 1)
    {
        const int draw = a->png_path != NULL && info.index == png_k;
        const lidet_detector_stats_t *ds;
        const lidet_detection_t *det;
        lidet_status_t st = LIDET_OK;
        double ms[LIDET_DET_N_STAGES + 1];
        uint32_t n_det = 0;
        if (o->fixed)
        {
            if (cli_detect_q_run(a, &cfg, chosen, det_q, &n_det, &ds_q, ms, draw ? gp : NULL, NULL, &st,
                                 rets) != 0)
                goto done;
            det = det_q;
            ds = &ds_q;
        }
        else if (cli_detect_f_run(a, pp, ms, &det, &n_det, &ds, &st) != 0)
            goto done;
        det_ms[n_run++] = ms[LIDET_DET_N_STAGES];
        if (!warned && 2u * (uint32_t)ds->stages.ground.n_sectors_rejected > cfg.stages.ground.n_sectors)
        {
            fprintf(stderr,
                    "lidet detect: warning: scan %u: the ground stage refused the planes of %u of %u "
                    "sectors: is the "
                    "mount height right? (--mount-height M; noted once)\n",
                    info.index, (unsigned)ds->stages.ground.n_sectors_rejected,
                    (unsigned)cfg.stages.ground.n_sectors);
            warned = 1;
        }
        if (a->json)
            json_result(a, label, &cfg, ds, det, n_det, st, ms, &info);
        else
        {
            printf("# scan %u: %u returns, %u detections, packets %u..%u", info.index, info.n_returns, n_det,
                   info.first_frame, info.last_frame);
            if (info.kind != LIDET_VELODYNE_SCAN_COMPLETE)
                printf(" (%s)", cli_scan_kind(info.kind));
            if (info.n_excess > 0u)
                printf("; %u returns past LIDET_MAX_POINTS dropped", info.n_excess);
            printf("\n");
            box_lines(stdout, det, n_det);
        }
        if (a->out_path != NULL)
        {
            const size_t len = strlen(a->out_path) + 16u;
            char *path = (char *)malloc(len);
            FILE *f;
            if (path == NULL)
                goto done;
            snprintf(path, len, "%s/%06u.txt", a->out_path, info.index);
            f = fopen(path, "w");
            if (f != NULL)
                box_lines(f, det, n_det);
            if (f == NULL || fclose(f) != 0)
            {
                fprintf(stderr, "lidet detect: cannot write '%s'\n", path);
                free(path);
                goto done;
            }
            free(path);
        }
        if (save_dir != NULL && save_scan(save_dir, info.index, a) != 0)
            goto done;
        if (draw)
        {
            char title[256];
            snprintf(title, sizeof title, "detect%s  %s scan %u (packets %u..%u)  %s (models %s)  %.1f ms",
                     o->fixed ? " --fixed" : "", cli_basename(po->path), info.index, info.first_frame,
                     info.last_frame, a->sensor, label, ms[LIDET_DET_N_STAGES]);
            if ((!o->fixed && cli_detect_f_ground(pp, a->n_points, gp) != 0) ||
                write_png(a->png_path, a->points, a->n_points, gp, det, n_det, NULL, 0, 0, title,
                          a->n_points) != 0)
            {
                fprintf(stderr, "lidet detect: cannot write the picture '%s'\n", a->png_path);
                goto done;
            }
        }
    }
    if (got < 0 || fflush(stdout) != 0)
        goto done;
    rc = cli_capture_summary(cap, stderr, det_ms, n_run);
done:
    a->points = NULL; /* the capture's buffers */
    a->ring = NULL;
    cli_capture_close(cap);
    free(pp);
    free(gp);
    free(det_ms);
    return rc;
}

/* lidet detect's own options (beside the shared sets: cli_options.c) */
enum
{
    OPT_CALIB,
    OPT_KITTI_OUT,
    OPT_GT,
    OPT_GT_KITTI,
    OPT_DUMP,
    OPT_SAVE_SCANS,
    OPT_PNG_RANGE,
    OPT_RETURNS
};

static const cli_opt_t k_detect_opts[] = {
    {"calib", required_argument, OPT_CALIB, "FILE: a KITTI calibration"},
    {"kitti-out", required_argument, OPT_KITTI_OUT, "FILE"},
    {"gt", required_argument, OPT_GT, "FILE: ground-truth boxes"},
    {"gt-kitti", required_argument, OPT_GT_KITTI, "FILE: KITTI label_2 lines"},
    {"dump", required_argument, OPT_DUMP, "FILE"},
    {"save-scans", required_argument, OPT_SAVE_SCANS, "DIR"},
    {"png-range", required_argument, OPT_PNG_RANGE, "M: metres in [5, 200]"},
    {"returns", no_argument, OPT_RETURNS, NULL},
    {NULL, 0, 0, NULL}};

typedef struct
{
    const char *calib, *kitti_out, *gt, *gt_kitti, *dump, *save_dir;
} detect_paths_t;

static int detect_take(void *ctx, int id, const char *v)
{
    detect_paths_t *d = (detect_paths_t *)ctx;
    switch (id)
    {
    case OPT_CALIB:
        d->calib = v;
        break;
    case OPT_KITTI_OUT:
        d->kitti_out = v;
        break;
    case OPT_GT:
        d->gt = v;
        break;
    case OPT_GT_KITTI:
        d->gt_kitti = v;
        break;
    case OPT_DUMP:
        d->dump = v;
        break;
    case OPT_SAVE_SCANS:
        d->save_dir = v;
        break;
    case OPT_PNG_RANGE:
        return cli_png_range(v);
    default: /* OPT_RETURNS */
        cli_fixed_returns = 1;
        break;
    }
    return 0;
}

int cli_detect(int argc, char **argv)
{
    cli_args_t a;
    lidet_detector_cfg_t cfg;
    const lidet_pn_model_t *mc = NULL, *mb = NULL;
    const lidet_detector_stats_t *ds;
    const lidet_detection_t *det;
    lidet_status_t st = LIDET_OK;
    const char *calib_path, *kitti_path, *gt_path, *gt_kitti_path, *dump_path, *save_dir;
    char chosen[64];
    char **pos;
    cli_det_opts_t o;
    cli_pcap_opts_t po;
    detect_paths_t paths;
    cli_optset_t sets[8];
    int n_pos = 0, n_sets, i, fixed = 0;
    static lidet_detection_t det_q[LIDET_MAX_DETECTIONS];
    static lidet_detector_stats_t ds_q;
    double ms[LIDET_DET_N_STAGES + 1];
    uint32_t n_det = 0, k;
    int32_t *pp = NULL;
    uint8_t *gp = NULL;
    uint32_t *gp_ids = NULL; /* --fixed --dump: the integer run's per-point cluster labels */

    memset(&o, 0, sizeof o);
    memset(&paths, 0, sizeof paths);
    cli_pcap_opts_default(&po);
    cli_args_default(&a);
    pos = (char **)malloc(sizeof(char *) * (size_t)(argc + 1));
    o.sets = (const char **)malloc(sizeof(char *) * (size_t)(argc + 1));
    if (pos == NULL || o.sets == NULL)
    {
        free(pos);
        free((void *)o.sets);
        return 1;
    }
    /* the sensor, the scan's files and output, the detector, the capture, then ours */
    n_sets = cli_args_optsets(&a, 1, sets);
    sets[n_sets++] = cli_optset(cli_opts_det, cli_det_take, &o);
    sets[n_sets++] = cli_optset(cli_opts_pcap, cli_pcap_take, &po);
    sets[n_sets++] = cli_optset(cli_opts_pcap_png_scan, cli_pcap_take, &po);
    sets[n_sets++] = cli_optset(k_detect_opts, detect_take, &paths);
    i = cli_options_parse(argc, argv, "lidet detect", sets, n_sets, pos, &n_pos);
    calib_path = paths.calib;
    kitti_path = paths.kitti_out;
    gt_path = paths.gt;
    gt_kitti_path = paths.gt_kitti;
    dump_path = paths.dump;
    save_dir = paths.save_dir;
    fixed = o.fixed;
    if (i == CLI_PARSE_OK && po.path == NULL &&
        (po.port != 0 || po.force_sensor || po.partial || po.png_scan >= 0 || po.dual != NULL ||
         strcmp(po.lidar, "velodyne") != 0 || save_dir != NULL))
    {
        fprintf(
            stderr,
            "lidet detect: --lidar, --port, --force-sensor, --dual, --partial, --png-scan and --save-scans "
            "go with --pcap FILE\n");
        i = CLI_PARSE_ERROR;
    }
    if (i == CLI_PARSE_OK && po.path != NULL)
    {
        const char *one = calib_path != NULL      ? "--calib"
                          : kitti_path != NULL    ? "--kitti-out"
                          : gt_path != NULL       ? "--gt"
                          : gt_kitti_path != NULL ? "--gt-kitti"
                          : dump_path != NULL     ? "--dump"
                          : a.ring_path != NULL   ? "--ring"
                          : n_pos > 0             ? pos[0]
                                                  : NULL;
        if (one != NULL)
        {
            fprintf(
                stderr,
                "lidet detect: %s goes with one scan file, not with --pcap (its scans are the capture's)\n",
                one);
            i = CLI_PARSE_ERROR;
        }
        pos[0] = (char *)po.path; /* the scans' source */
        n_pos = 1;
        cli_fixed_returns = 0; /* --fixed feeds the decoded returns as they are */
        a.capture = 1; /* --sensor may name a --velodyne-calib's model; --print-sensor: the capture's */
    }
    if (i == CLI_PARSE_OK)
        i = cli_args_finish(&a, pos, n_pos, "detect");
    free(pos);
    if (i != CLI_PARSE_OK)
    {
        if (i == CLI_PARSE_USAGE)
        {
            cli_usage(stderr, "detect");
            usage_extra();
        }
        free((void *)o.sets);
        return i == CLI_PARSE_PRINTED ? 0 : 1;
    }
    if (po.path != NULL)
    {
        i = a.print_sensor ? cli_capture_print_sensor(&po, &a) : detect_pcap(&a, &o, &po, save_dir);
        free((void *)o.sets);
        return i;
    }
    /* --range-only / --returns without --fixed, the models, --crop and --set */
    i = cli_det_config(&a, &o, &cfg, &mc, &mb, chosen, sizeof chosen);
    free((void *)o.sets);
    if (i != 0)
        return 1;
    if ((kitti_path != NULL || gt_kitti_path != NULL) && calib_path == NULL)
    {
        fprintf(stderr, "lidet detect: --kitti-out and --gt-kitti need --calib\n");
        return 1;
    }
    if (cli_load(&a) != 0)
        return 1;
    if (fixed)
    {
        /* the integer detector; per-point ground labels for the picture come with it */
        uint32_t np = a.n_points < LIDET_MAX_POINTS ? a.n_points : LIDET_MAX_POINTS;
        gp = (uint8_t *)malloc((size_t)np + 1u);
        if (dump_path != NULL) /* the per-point cluster labels too */
            gp_ids = (uint32_t *)malloc(sizeof(uint32_t) * ((size_t)np + 1u));
        if (gp == NULL || (dump_path != NULL && gp_ids == NULL) ||
            cli_detect_q_run(&a, &cfg, chosen, det_q, &n_det, &ds_q, ms, gp, gp_ids, &st, NULL) != 0)
        {
            free(gp);
            free(gp_ids);
            cli_free(&a);
            return 1;
        }
        ds = &ds_q;
        det = det_q;
        strncat(chosen, " int8", sizeof chosen - strlen(chosen) - 1u);
        goto outputs;
    }
    pp = (int32_t *)malloc(sizeof(int32_t) * LIDET_MAX_POINTS);
    if (pp == NULL || cli_detect_f_init(&cfg, mc, mb) != 0 ||
        cli_detect_f_run(&a, pp, ms, &det, &n_det, &ds, &st) != 0)
    {
        free(pp);
        cli_free(&a);
        return 1;
    }

outputs:
    if (a.out_path != NULL)
    {
        FILE *f = fopen(a.out_path, "w");
        if (f != NULL)
            box_lines(f, det, n_det);
        if (f == NULL || fclose(f) != 0)
        {
            fprintf(stderr, "lidet detect: cannot write '%s'\n", a.out_path);
            free(gp_ids);
            free(pp);
            cli_free(&a);
            return 1;
        }
    }
    if (dump_path != NULL && (fixed ? cli_detect_q_dump(dump_path, a.n_points, gp_ids, gp)
                                    : write_dump(dump_path, pp, a.n_points)) != 0)
    {
        fprintf(stderr, "lidet detect: cannot write '%s'\n", dump_path);
        free(gp_ids);
        free(pp);
        cli_free(&a);
        return 1;
    }
    free(gp_ids);
    gp_ids = NULL;
    if (kitti_path != NULL)
    {
        cli_calib_t c;
        FILE *f;
        uint32_t written = 0;
        if (cli_read_calib(calib_path, &c) != 0)
        {
            free(pp);
            cli_free(&a);
            return 1;
        }
        f = fopen(kitti_path, "w");
        for (k = 0; f != NULL && k < n_det; ++k)
            written += kitti_line(f, &c, &det[k]) == 0 ? 1u : 0u;
        if (f != NULL && written == 0)
            fprintf(
                f, "DontCare -1 -1 -10 0 0 0 0 -1 -1 -1 -1000 -1000 -1000 -10 0\n"); /* KITTI's empty frame */
        if (f == NULL || fclose(f) != 0)
        {
            fprintf(stderr, "lidet detect: cannot write '%s'\n", kitti_path);
            free(pp);
            cli_free(&a);
            return 1;
        }
    }
    if (a.png_path != NULL)
    {
        gt_t *gt = NULL;
        cli_calib_t gcal;
        uint32_t n_gt = 0, np = a.n_points < LIDET_MAX_POINTS ? a.n_points : LIDET_MAX_POINTS;
        char title[256];
        snprintf(title, sizeof title, "detect%s  %s  %s (models %s)  %.1f ms", fixed ? " --fixed" : "",
                 cli_basename(a.scan_path), a.sensor, chosen, ms[LIDET_DET_N_STAGES]);
        if (a.repeat > 1)
            snprintf(title + strlen(title), sizeof title - strlen(title), ", median of %d", a.repeat);
        if (gp == NULL)
            gp = (uint8_t *)malloc((size_t)np + 1u);
        else
            fixed = 2; /* the integer run filled gp */
        if (gp == NULL || (fixed != 2 && cli_detect_f_ground(pp, a.n_points, gp) != 0) ||
            (gt_path != NULL && read_gt(gt_path, &gt, &n_gt) != 0) ||
            (gt_kitti_path != NULL && (cli_read_calib(calib_path, &gcal) != 0 ||
                                       read_gt_kitti(gt_kitti_path, &gcal, &gt, &n_gt) != 0)) ||
            write_png(a.png_path, a.points, np, gp, det, n_det, gt, n_gt,
                      gt_path != NULL || gt_kitti_path != NULL, title, a.n_points) != 0)
        {
            fprintf(stderr, "lidet detect: cannot write the picture '%s'\n", a.png_path);
            free(gp);
            free(gt);
            free(pp);
            cli_free(&a);
            return 1;
        }
        free(gt);
    }
    (void)cli_warn_frame("lidet detect", NULL, &ds->stages.proj, a.sensor_profile);
    {
        /* a mount height far from the real one makes the ground stage refuse most sectors' planes (their
         * height is checked against it) and fall back to planes at the wrong height: the ground is then
         * left in the clusters and whole road users are lost (docs/DETECTOR.md, Mount height) */
        const lidet_ground_stats_t *gs = &ds->stages.ground;
        const uint32_t ns = cfg.stages.ground.n_sectors;
        if (2u * (uint32_t)gs->n_sectors_rejected > ns)
            fprintf(stderr,
                    "lidet detect: warning: the ground stage refused the planes of %u of %u sectors (each is "
                    "checked against a ground %.2f m below the sensor, +-%.2f m): is the mount height right? "
                    "(--mount-height M; python -m lidet_tools.mount SCANS estimates it)\n",
                    (unsigned)gs->n_sectors_rejected, (unsigned)ns, (double)cfg.stages.ground.mount_height_m,
                    (double)cfg.stages.ground.max_height_dev_m);
    }
    if (a.json)
        json_result(&a, chosen, &cfg, ds, det, n_det, st, ms, NULL);
    else
    {
        printf("scan         %s (%s, models %s)\n", a.scan_path, a.sensor, chosen);
        printf("clusters     %u: %u classified (%u outside the crop, %u taller than %.1f m, %u beyond range, "
               "%u over "
               "the budget of %u)\n",
               ds->n_clusters, ds->n_classified, ds->n_out_of_crop, ds->n_too_tall,
               (double)cfg.max_height_extent_m, ds->n_out_of_range, ds->n_over_budget, cfg.max_proposals);
        printf(
            "gates        %u rejected by gate 1, %u by gate 2; %u impossible sizes, %u suppressed by NMS\n",
            ds->n_gate1_rejected, ds->n_gate2_rejected, ds->n_size_rejected, ds->n_nms_suppressed);
        printf("time (ms)    project %.3f  ground %.3f  cluster %.3f  classify %.3f  box %.3f  total %.3f"
               " (median of %d)\n",
               ms[LIDET_DET_STAGE_PROJECT], ms[LIDET_DET_STAGE_GROUND], ms[LIDET_DET_STAGE_CLUSTER],
               ms[LIDET_DET_STAGE_CLASSIFY], ms[LIDET_DET_STAGE_BOX], ms[LIDET_DET_N_STAGES], a.repeat);
        printf("detections   %u\n", n_det);
        if (n_det > 0)
            printf("  %-10s %6s %8s %8s %7s %7s %7s %5s %5s %5s %7s %6s\n", "class", "score", "E_cls",
                   "E_box", "x", "y", "z", "l", "w", "h", "yaw", "points");
        for (k = 0; k < n_det; ++k)
            printf("  %-10s %6.3f %8.3f %8.3f %7.2f %7.2f %7.2f %5.2f %5.2f %5.2f %7.3f %6u\n",
                   cli_class_names[det[k].cls], (double)det[k].score, (double)det[k].energy_cls,
                   (double)det[k].energy_box, (double)det[k].box.cx_m, (double)det[k].box.cy_m,
                   (double)det[k].box.cz_m, (double)det[k].box.l_m, (double)det[k].box.w_m,
                   (double)det[k].box.h_m, (double)det[k].box.yaw_rad, det[k].n_points);
        if (a.png_path != NULL)
            printf("picture      %s (detections: car red, cyclist cyan, pedestrian yellow; ground truth "
                   "green)\n",
                   a.png_path);
    }
    free(gp);
    free(pp);
    cli_free(&a);
    return 0;
}
