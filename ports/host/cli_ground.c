/* SPDX-License-Identifier: MIT */
/* `lidet ground`: projection + ground segmentation; per-point mask, bird's-eye picture, timings.
 * ground_ms is the median over --repeat runs of lidet_ground_run alone (file reading and projection
 * excluded); project_ms the median of lidet_proj_run; total_ms the median of both together. */
#include <stdlib.h>
#include <string.h>

#include "cli.h"

static lidet_proj_t g_proj;     /* ~7 MiB with the default capacities: static */
static lidet_ground_t g_ground; /* ~3.5 MiB */

/* Bird's-eye view, x up, y left, BEV_HALF_M metres each way around the sensor at BEV_PX_M metres per
 * pixel: ground points green, other points grey, the sensor as a red dot. */
#define BEV_SIZE 800
#define BEV_HALF_M 40.0f

static int write_bev_png(const char *path, const float *pts, uint32_t n, const uint8_t *label,
                         const char *title, const char *subtitle)
{
    static const cli_legend_t legend[3] = {
        {"ground", {40, 200, 60}}, {"not ground", {170, 170, 170}}, {"sensor", {230, 30, 30}}};
    uint8_t *rgb = (uint8_t *)calloc((size_t)BEV_SIZE * BEV_SIZE * 3u, 1);
    const float scale = (float)BEV_SIZE / (2.0f * BEV_HALF_M);
    uint32_t i;
    int pass, rc, dy, dx;
    if (rgb == NULL)
        return -1;
    /* non-ground first, ground on top, so thin ground rings stay visible between objects */
    for (pass = 0; pass < 2; ++pass)
    {
        for (i = 0; i < n; ++i)
        {
            const float x = pts[4 * i], y = pts[4 * i + 1];
            float u, v;
            int row, col;
            uint8_t *p;
            if ((label[i] != 0) != (pass == 1))
                continue;
            if (!(x > -BEV_HALF_M && x < BEV_HALF_M && y > -BEV_HALF_M && y < BEV_HALF_M))
                continue; /* also drops NaN */
            u = (BEV_HALF_M - x) * scale; /* image row: +x (forward) is up */
            v = (BEV_HALF_M - y) * scale; /* image col: +y (left) is left */
            row = (int)u;
            col = (int)v;
            if (row < 0 || row >= BEV_SIZE || col < 0 || col >= BEV_SIZE)
                continue;
            p = rgb + ((size_t)row * BEV_SIZE + (size_t)col) * 3u;
            if (pass == 1)
            {
                p[0] = 40;
                p[1] = 200;
                p[2] = 60;
            }
            else
            {
                p[0] = 170;
                p[1] = 170;
                p[2] = 170;
            }
        }
    }
    for (dy = -3; dy <= 3; ++dy)
    {
        for (dx = -3; dx <= 3; ++dx)
        {
            uint8_t *p = rgb + ((size_t)(BEV_SIZE / 2 + dy) * BEV_SIZE + (size_t)(BEV_SIZE / 2 + dx)) * 3u;
            p[0] = 230;
            p[1] = 30;
            p[2] = 30;
        }
    }
    rc = cli_bev_write(path, rgb, BEV_SIZE, BEV_SIZE, 1.0f / scale, title, subtitle, legend, 3);
    free(rgb);
    return rc;
}

/* `--set KEY=VALUE` overrides one lidet_ground_cfg_t field (for tuning and the filter comparison in
 * tools/bench/bench_ground.py). Returns 0, or 1 for an unknown key or a bad number. */
int cli_ground_set(lidet_ground_cfg_t *c, const char *kv)
{
    size_t klen;
    double v;
    if (cli_split_set(kv, &klen, &v) != 0)
        return 1;
    CLI_SET_FLOAT(c, kv, klen, v, fy_max)
    CLI_SET_FLOAT(c, kv, klen, v, fx_max_m)
    CLI_SET_FLOAT(c, kv, klen, v, gate_above_m)
    CLI_SET_FLOAT(c, kv, klen, v, gate_below_m)
    CLI_SET_FLOAT(c, kv, klen, v, mount_height_m)
    CLI_SET_FLOAT(c, kv, klen, v, inlier_m)
    CLI_SET_FLOAT(c, kv, klen, v, max_tilt_rad)
    CLI_SET_FLOAT(c, kv, klen, v, max_height_dev_m)
    CLI_SET_FLOAT(c, kv, klen, v, ground_m)
    CLI_SET_FLOAT(c, kv, klen, v, ground_m_per_m)
    CLI_SET_FLOAT(c, kv, klen, v, below_factor)
    CLI_SET_FLOAT(c, kv, klen, v, confidence)
    CLI_SET_FLOAT(c, kv, klen, v, ring_split_m)
    CLI_SET_FLOAT(c, kv, klen, v, far_max_step_m)
    CLI_SET_FLOAT(c, kv, klen, v, far2_split_m)
    CLI_SET_FLOAT(c, kv, klen, v, veto_slope)
    CLI_SET_FLOAT(c, kv, klen, v, veto_min_dz_m)
    CLI_SET_FLOAT(c, kv, klen, v, azimuth_half_rad)
    CLI_SET_INT(c, kv, klen, v, fx_on_z, uint8_t, 1)
    CLI_SET_INT(c, kv, klen, v, require_descending, uint8_t, 1)
    CLI_SET_INT(c, kv, klen, v, height_gate, uint8_t, 1)
    CLI_SET_INT(c, kv, klen, v, refine_iters, uint8_t, 255)
    CLI_SET_INT(c, kv, klen, v, n_sectors, uint16_t, 65535)
    CLI_SET_INT(c, kv, klen, v, ransac_iters, uint16_t, 65535)
    CLI_SET_INT(c, kv, klen, v, eval_samples, uint16_t, 65535)
    CLI_SET_INT(c, kv, klen, v, sample_step, uint16_t, 65535)
    CLI_SET_INT(c, kv, klen, v, sample_col_step, uint16_t, 65535)
    CLI_SET_INT(c, kv, klen, v, min_samples, uint16_t, 65535)
    CLI_SET_INT(c, kv, klen, v, min_inliers, uint16_t, 65535)
    CLI_SET_INT(c, kv, klen, v, fallback_sectors, uint16_t, 65535)
    CLI_SET_INT(c, kv, klen, v, seed, uint32_t, 4294967295.0)
    CLI_SET_INT(c, kv, klen, v, seed_per_cell, uint8_t, 1)
    return 1;
}

/* lidet ground's own option: --set KEY=VALUE, repeatable, gathered in order (checked once the configuration is made) */
static const cli_opt_t k_ground_opts[] = {{"set", required_argument, 0, "KEY=VALUE"}, {NULL, 0, 0, NULL}};

int cli_ground(int argc, char **argv)
{
    cli_args_t a;
    lidet_proj_cfg_t pcfg;
    lidet_ground_cfg_t gcfg;
    lidet_range_image_t img;
    lidet_status_t st = LIDET_OK, gst = LIDET_OK;
    const lidet_ground_stats_t *gs;
    const int32_t *pp;
    uint8_t *label = NULL;
    double *tp = NULL, *tg = NULL, *tt = NULL, proj_ms, ground_ms, total_ms;
    char title[256], subtitle[160];
    uint32_t np = 0, i, n_ground_points = 0;
    int k, ret = 1;

    const char **sets = (const char **)malloc(sizeof(char *) * (size_t)(argc + 1));
    cli_list_t set_list;
    cli_optset_t own;
    set_list.v = sets;
    set_list.n = 0;
    own = cli_optset(k_ground_opts, cli_list_take, &set_list);
    if (sets == NULL)
        return 1;
    k = cli_parse(argc, argv, "ground", &a, &own, 1);
    if (k == CLI_PARSE_USAGE)
    {
        cli_usage(stderr, "ground");
        fprintf(stderr,
                "  --set KEY=VALUE  override a lidet_ground_cfg_t field (repeatable), e.g. --set ground_m=0.2\n");
    }
    if (k != CLI_PARSE_OK || cli_load(&a) != 0)
    {
        free(sets);
        return k == CLI_PARSE_PRINTED ? 0 : 1;
    }
    lidet_proj_cfg_default(&pcfg, a.sensor_profile);
    lidet_ground_cfg_default(&gcfg, a.sensor_profile);
    for (k = 0; k < set_list.n; ++k)
    {
        if (cli_ground_set(&gcfg, sets[k]) != 0)
        {
            fprintf(stderr, "lidet ground: bad --set '%s' (KEY=VALUE with a lidet_ground_cfg_t field)\n", sets[k]);
            free(sets);
            cli_free(&a);
            return 1;
        }
    }
    free(sets);
    st = lidet_proj_init(&g_proj, &pcfg);
    if (st == LIDET_OK)
        st = lidet_ground_init(&g_ground, &gcfg);
    if (st != LIDET_OK)
    {
        fprintf(stderr, "lidet ground: init failed: %s\n", lidet_status_str(st));
        goto done;
    }
    tp = (double *)malloc(sizeof(double) * (size_t)a.repeat);
    tg = (double *)malloc(sizeof(double) * (size_t)a.repeat);
    tt = (double *)malloc(sizeof(double) * (size_t)a.repeat);
    label = (uint8_t *)malloc(a.n_points > 0 ? a.n_points : 1u);
    if (tp == NULL || tg == NULL || tt == NULL || label == NULL)
        goto done;
    for (k = 0; k < a.repeat; ++k)
    {
        const double t0 = cli_now_ms();
        double t1;
        st = lidet_proj_run(&g_proj, a.points, a.n_points, 4, a.ring);
        t1 = cli_now_ms();
        if (!LIDET_SUCCEEDED(st))
        {
            fprintf(stderr, "lidet ground: projection: %s\n", lidet_status_str(st));
            goto done;
        }
        lidet_proj_image(&g_proj, &img);
        gst = lidet_ground_run(&g_ground, &img);
        tp[k] = t1 - t0;
        tg[k] = cli_now_ms() - t1;
        tt[k] = tp[k] + tg[k];
        if (!LIDET_SUCCEEDED(gst))
        {
            fprintf(stderr, "lidet ground: %s\n", lidet_status_str(gst));
            goto done;
        }
    }
    proj_ms = cli_median(tp, a.repeat);
    ground_ms = cli_median(tg, a.repeat);
    total_ms = cli_median(tt, a.repeat);
    pp = lidet_proj_point_pixels(&g_proj, &np);
    for (i = np; i < a.n_points; ++i)
        label[i] = 0; /* past LIDET_MAX_POINTS: not processed, not ground */
    if (lidet_ground_point_labels(&g_ground, pp, np, label) != LIDET_OK)
        goto done;
    for (i = 0; i < a.n_points; ++i)
        n_ground_points += label[i];
    gs = lidet_ground_stats(&g_ground);
    (void)cli_warn_frame("lidet ground", NULL, lidet_proj_stats(&g_proj), a.sensor_profile);

    if (a.out_path != NULL)
    {
        /* one uint8 per input point, input order: 1 ground, 0 not */
        FILE *f = fopen(a.out_path, "wb");
        if (f == NULL || (a.n_points > 0 && fwrite(label, 1, a.n_points, f) != a.n_points) || fclose(f) != 0)
        {
            fprintf(stderr, "lidet ground: cannot write '%s'\n", a.out_path);
            goto done;
        }
    }
    if (a.png_path != NULL)
    {
        snprintf(title, sizeof title, "ground  %s  %s  %.1f ms", cli_basename(a.scan_path), a.sensor,
                 total_ms);
        if (a.repeat > 1)
            snprintf(title + strlen(title), sizeof title - strlen(title), ", median of %d", a.repeat);
        snprintf(subtitle, sizeof subtitle, "%u points  ground %u (%.1f%%)", a.n_points, n_ground_points,
                 a.n_points ? 100.0 * n_ground_points / a.n_points : 0.0);
    }
    if (a.png_path != NULL && write_bev_png(a.png_path, a.points, a.n_points, label, title, subtitle) != 0)
    {
        fprintf(stderr, "lidet ground: cannot write '%s'\n", a.png_path);
        goto done;
    }
    if (a.json)
    {
        cli_json_begin(stdout);
        cli_json_str(stdout, "sensor", a.sensor);
        cli_json_int(stdout, "points", a.n_points);
        cli_json_int(stdout, "ground_points", n_ground_points);
        cli_json_int(stdout, "valid_pixels", lidet_proj_stats(&g_proj)->n_pixels_filled);
        cli_json_int(stdout, "ground_pixels", gs->n_ground);
        cli_json_int(stdout, "samples", gs->n_samples);
        cli_json_int(stdout, "samples_dropped", gs->n_samples_dropped);
        cli_json_int(stdout, "sectors", gcfg.n_sectors);
        cli_json_int(stdout, "sectors_fitted", gs->n_sectors_fitted);
        cli_json_int(stdout, "sectors_neighbour", gs->n_sectors_neighbour);
        cli_json_int(stdout, "sectors_mount", gs->n_sectors_mount);
        cli_json_int(stdout, "far_fitted", gs->n_far_fitted);
        cli_json_int(stdout, "vetoed_pixels", gs->n_vetoed);
        cli_json_int(stdout, "hypotheses", gs->n_hypotheses);
        cli_json_int(stdout, "repeat", a.repeat);
        cli_json_num(stdout, "project_ms", proj_ms);
        cli_json_num(stdout, "ground_ms", ground_ms);
        cli_json_num(stdout, "total_ms", total_ms);
        cli_json_end(stdout);
    }
    else
    {
        printf("scan            %s (%s)\n", a.scan_path, a.sensor);
        printf("points          %u, ground %u (%.1f%%)\n", a.n_points, n_ground_points,
               a.n_points ? 100.0 * n_ground_points / a.n_points : 0.0);
        printf("pixels          %u valid, %u ground, %u samples\n", lidet_proj_stats(&g_proj)->n_pixels_filled,
               gs->n_ground, gs->n_samples);
        printf("sectors         %u: %u fitted, %u from a neighbour, %u mount plane\n", gcfg.n_sectors,
               gs->n_sectors_fitted, gs->n_sectors_neighbour, gs->n_sectors_mount);
        printf("project_ms      %.3f (median of %d)\n", proj_ms, a.repeat);
        printf("ground_ms       %.3f (median of %d)\n", ground_ms, a.repeat);
        if (a.out_path != NULL)
            printf("mask            %s (uint8 per point)\n", a.out_path);
        if (a.png_path != NULL)
            printf("picture         %s\n", a.png_path);
    }
    ret = 0;
done:
    free(tp);
    free(tg);
    free(tt);
    free(label);
    cli_free(&a);
    return ret;
}
