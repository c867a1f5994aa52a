/* SPDX-License-Identifier: MIT */
/* `lidet project`: runs the projection stage alone and reports what happened to every point. */
#include <stdlib.h>

#include "cli.h"

static lidet_proj_t g_proj; /* ~7 MiB with the default capacities: static, never on the stack */

/* Range image as a picture: one image row per beam repeated `scale` times, colour = range
 * (square-root scale, 0..80 m), black = empty pixel. */
static int write_range_png(const char *path, const lidet_proj_t *proj)
{
    lidet_range_image_t img;
    uint32_t r, c, k, scale, h;
    uint8_t *rgb;
    int rc;
    lidet_proj_image(proj, &img);
    scale = img.n_rows >= 128 ? 2u : (img.n_rows >= 64 ? 4u : 16u);
    h = img.n_rows * scale;
    rgb = (uint8_t *)calloc((size_t)h * img.n_cols * 3u, 1);
    if (rgb == NULL)
        return -1;
    for (r = 0; r < img.n_rows; ++r)
    {
        for (c = 0; c < img.n_cols; ++c)
        {
            const uint32_t pix = r * img.n_cols + c;
            uint8_t col[3] = {0, 0, 0};
            if (img.point_idx[pix] >= 0)
            {
                float t = img.range_m[pix] / 80.0f;
                t = t > 1.0f ? 1.0f : t;
                /* sqrt without libm double: a few Newton steps are plenty for a colour */
                {
                    float s = 0.5f * (t + 0.25f);
                    int it;
                    for (it = 0; it < 6; ++it)
                        s = 0.5f * (s + t / (s > 1e-6f ? s : 1e-6f));
                    cli_colormap(1.0f - s, col);
                }
            }
            for (k = 0; k < scale; ++k)
            {
                uint8_t *p = rgb + (((size_t)(r * scale + k) * img.n_cols) + c) * 3u;
                p[0] = col[0];
                p[1] = col[1];
                p[2] = col[2];
            }
        }
    }
    rc = lidet_png_write_rgb(path, rgb, img.n_cols, h);
    free(rgb);
    return rc;
}

int cli_project(int argc, char **argv)
{
    cli_args_t a;
    lidet_proj_cfg_t cfg;
    lidet_status_t st = LIDET_OK;
    const lidet_proj_stats_t *s;
    double *times, ms;
    int i;

    i = cli_parse(argc, argv, "project", &a, NULL, 0);
    if (i == CLI_PARSE_USAGE)
        cli_usage(stderr, "project");
    if (i != CLI_PARSE_OK || cli_load(&a) != 0)
        return i == CLI_PARSE_PRINTED ? 0 : 1;
    lidet_proj_cfg_default(&cfg, a.sensor_profile);
    st = lidet_proj_init(&g_proj, &cfg);
    if (st != LIDET_OK)
    {
        fprintf(stderr, "lidet project: init failed: %s\n", lidet_status_str(st));
        cli_free(&a);
        return 1;
    }
    times = (double *)malloc(sizeof(double) * (size_t)a.repeat);
    if (times == NULL)
    {
        cli_free(&a);
        return 1;
    }
    for (i = 0; i < a.repeat; ++i)
    {
        const double t0 = cli_now_ms();
        st = lidet_proj_run(&g_proj, a.points, a.n_points, 4, a.ring);
        times[i] = cli_now_ms() - t0;
        if (!LIDET_SUCCEEDED(st))
        {
            fprintf(stderr, "lidet project: %s\n", lidet_status_str(st));
            free(times);
            cli_free(&a);
            return 1;
        }
    }
    ms = cli_median(times, a.repeat);
    free(times);
    s = lidet_proj_stats(&g_proj);
    (void)cli_warn_frame("lidet project", NULL, s, a.sensor_profile);

    if (a.out_path != NULL)
    {
        /* int32 pixel index (row * cols + col) per input point, -1 = not projected */
        uint32_t n;
        const int32_t *pp = lidet_proj_point_pixels(&g_proj, &n);
        FILE *f = fopen(a.out_path, "wb");
        int bad = f == NULL || fwrite(pp, sizeof pp[0], n, f) != n;
        uint32_t k;
        /* every input point gets an entry, also those past LIDET_MAX_POINTS (not projected: -1) */
        for (k = n; !bad && k < a.n_points; ++k)
        {
            const int32_t none = -1;
            bad = fwrite(&none, sizeof none, 1, f) != 1;
        }
        if (f != NULL && fclose(f) != 0)
            bad = 1;
        if (bad)
        {
            fprintf(stderr, "lidet project: cannot write '%s'\n", a.out_path);
            cli_free(&a);
            return 1;
        }
    }
    if (a.png_path != NULL && write_range_png(a.png_path, &g_proj) != 0)
    {
        fprintf(stderr, "lidet project: cannot write '%s'\n", a.png_path);
        cli_free(&a);
        return 1;
    }
    {
        const uint32_t npix = (uint32_t)cfg.sensor.n_rows * cfg.sensor.n_cols;
        const double fill = (double)s->n_pixels_filled / (double)npix;
        const uint32_t dropped =
            s->n_nonfinite + s->n_too_close + s->n_too_far + s->n_out_of_fov + s->n_bad_ring + s->n_truncated;
        if (a.json)
        {
            cli_json_begin(stdout);
            cli_json_str(stdout, "sensor", a.sensor);
            cli_json_int(stdout, "points", s->n_points_in);
            cli_json_int(stdout, "projected", s->n_projected);
            cli_json_int(stdout, "dropped", dropped);
            cli_json_int(stdout, "dropped_nonfinite", s->n_nonfinite);
            cli_json_int(stdout, "dropped_too_close", s->n_too_close);
            cli_json_int(stdout, "dropped_too_far", s->n_too_far);
            cli_json_int(stdout, "dropped_out_of_fov", s->n_out_of_fov);
            cli_json_int(stdout, "dropped_bad_ring", s->n_bad_ring);
            cli_json_int(stdout, "dropped_truncated", s->n_truncated);
            cli_json_int(stdout, "rows", cfg.sensor.n_rows);
            cli_json_int(stdout, "cols", cfg.sensor.n_cols);
            cli_json_int(stdout, "pixels_filled", s->n_pixels_filled);
            cli_json_num(stdout, "fill_ratio", fill);
            cli_json_int(stdout, "repeat", a.repeat);
            cli_json_num(stdout, "project_ms", ms);
            cli_json_num(stdout, "total_ms", ms);
            cli_json_end(stdout);
        }
        else
        {
            printf("scan            %s (%s, %u x %u)\n", a.scan_path, a.sensor, cfg.sensor.n_rows, cfg.sensor.n_cols);
            printf("points read     %u\n", s->n_points_in);
            printf("projected       %u (%.2f%%)\n", s->n_projected,
                   s->n_points_in ? 100.0 * s->n_projected / s->n_points_in : 0.0);
            printf("dropped         %u: non-finite %u, too close %u, too far %u, out of fov %u, bad ring %u, "
                   "over capacity %u\n",
                   dropped, s->n_nonfinite, s->n_too_close, s->n_too_far, s->n_out_of_fov, s->n_bad_ring,
                   s->n_truncated);
            printf("pixels filled   %u of %u (fill ratio %.3f)\n", s->n_pixels_filled, npix, fill);
            printf("project_ms      %.3f (median of %d)\n", ms, a.repeat);
            if (a.png_path != NULL)
                printf("picture         %s\n", a.png_path);
        }
    }
    cli_free(&a);
    return 0;
}
