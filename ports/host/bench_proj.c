/* SPDX-License-Identifier: MIT */
/* Projection benchmark: lidet_proj_run versus a plain libm projection (atan2f for the column,
 * asinf for the elevation, nearest beam by binary search, same closest-wins rule and the same
 * output arrays) on the same scans, in the same run, interleaved; beside them the compact image a
 * detector workspace keeps, from the float projection (lidet_proj_run_buffers) and from the integer
 * one (lidet_proj_q_run on the points in mm, round(1000 x), converted before timing). Also measures the angular error of
 * lidet's azimuth and elevation tests against a double-precision reference, and the row/column
 * agreement with it. Prints one JSON object per scan and a summary object (tools/bench reads them).
 *
 * usage: lidet_bench_proj --sensor hdl64 [--repeat 30] [--clock wall|cpu] SCAN.bin...
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "cli.h"
#include "lidet/lidet.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

static lidet_proj_t g_proj;

/* baseline state (same sizes as lidet's) */
static float b_x[LIDET_MAX_ROWS * LIDET_MAX_COLS], b_y[LIDET_MAX_ROWS * LIDET_MAX_COLS],
    b_z[LIDET_MAX_ROWS * LIDET_MAX_COLS], b_r[LIDET_MAX_ROWS * LIDET_MAX_COLS],
    b_rxy[LIDET_MAX_ROWS * LIDET_MAX_COLS];
static int32_t b_idx[LIDET_MAX_ROWS * LIDET_MAX_COLS];
static int32_t b_pp[LIDET_MAX_POINTS];
static float b_mid_rad[LIDET_MAX_ROWS]; /* mid-angles between rows, descending */

/* compact images: the float projection's and the integer projection's (same layout) */
static int16_t c_x[LIDET_MAX_ROWS * LIDET_MAX_COLS], c_y[LIDET_MAX_ROWS * LIDET_MAX_COLS],
    c_z[LIDET_MAX_ROWS * LIDET_MAX_COLS];
static uint16_t c_r[LIDET_MAX_ROWS * LIDET_MAX_COLS];
static lidet_proj_q_state_t g_proj_q;

static clockid_t g_clock = CLOCK_MONOTONIC; /* --clock cpu: CLOCK_PROCESS_CPUTIME_ID (a loaded machine
                                                preempts the longer runs: wall time then says little) */

static double now_ms(void)
{
    struct timespec ts;
    clock_gettime(g_clock, &ts);
    return (double)ts.tv_sec * 1e3 + (double)ts.tv_nsec * 1e-6;
}

static int cmpd(const void *a, const void *b)
{
    const double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static double median(double *v, int n)
{
    qsort(v, (size_t)n, sizeof v[0], cmpd);
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

/* exact inverse of lidet's pseudo-azimuth (in double): the azimuth lidet effectively binned */
static double key_to_azimuth(float key)
{
    const double d = key;
    int quadrant = (int)floor(d);
    double g, theta, u;
    quadrant = quadrant > 3 ? 3 : quadrant;
    g = d - quadrant;
    theta = atan2(g, 1.0 - g); /* g = sin/(sin+cos) */
    u = (quadrant + theta / (M_PI / 2.0)) / 4.0;
    return M_PI * (1.0 - 2.0 * u);
}

/* the plain projection: libm trigonometry per point */
static void baseline_run(const float *pts, uint32_t n, int rows, int cols, float lo_rad, float hi_rad)
{
    const int npix = rows * cols;
    uint32_t i;
    int pix;
    memset(b_idx, 0xFF, sizeof(int32_t) * (size_t)npix);
    for (i = 0; i < n; ++i)
    {
        const float x = pts[4 * i], y = pts[4 * i + 1], z = pts[4 * i + 2];
        const float r = sqrtf(x * x + y * y + z * z);
        float pitch, yaw;
        int row, col, lo, hi;
        b_pp[i] = -1;
        if (!isfinite(r) || r < 0.1f)
            continue;
        pitch = asinf(z / r);
        if (!(pitch >= lo_rad && pitch <= hi_rad))
            continue;
        yaw = atan2f(y, x);
        col = (int)(0.5f * (1.0f - yaw / 3.14159265f) * (float)cols);
        col = col >= cols ? col - cols : (col < 0 ? 0 : col);
        /* nearest beam: first mid-angle below the pitch, binary search */
        lo = 0;
        hi = rows - 1;
        while (lo < hi)
        {
            const int m = (lo + hi) / 2;
            if (b_mid_rad[m] > pitch)
                lo = m + 1;
            else
                hi = m;
        }
        row = lo;
        pix = row * cols + col;
        b_pp[i] = pix;
        if (b_idx[pix] < 0 || r < b_r[pix])
        {
            b_idx[pix] = (int32_t)i;
            b_r[pix] = r;
        }
    }
    for (pix = 0; pix < npix; ++pix)
    {
        const int32_t k = b_idx[pix];
        if (k < 0)
        {
            b_x[pix] = b_y[pix] = b_z[pix] = b_r[pix] = b_rxy[pix] = 0.0f;
        }
        else
        {
            b_x[pix] = pts[4 * k];
            b_y[pix] = pts[4 * k + 1];
            b_z[pix] = pts[4 * k + 2];
            b_rxy[pix] = sqrtf(b_x[pix] * b_x[pix] + b_y[pix] * b_y[pix]);
        }
    }
}

/* the options (cli_options.c): the benchmarks' shared set (cli_opts_bench: --sensor, --repeat) and --clock */
static const cli_opt_t k_opts[] = {{"clock", required_argument, 0, "wall or cpu"}, {NULL, 0, 0, NULL}};

static int take_clock(void *ctx, int id, const char *v)
{
    (void)ctx;
    (void)id;
    if (strcmp(v, "wall") != 0 && strcmp(v, "cpu") != 0)
    {
        fprintf(stderr, "lidet_bench_proj: --clock wall or cpu, not '%s'\n", v);
        return 1;
    }
    g_clock = strcmp(v, "cpu") == 0 ? CLOCK_PROCESS_CPUTIME_ID : CLOCK_MONOTONIC;
    return 0;
}

int main(int argc, char **argv)
{
    const char *sensor;
    int repeat, a, n_files = 0, n_pos = 0;
    char **pos;
    cli_bench_opts_t o;
    cli_optset_t sets[2];
    double sum_pts = 0, sum_lidet_ms = 0, sum_base_ms = 0, sum_compact_ms = 0, sum_q_ms = 0, worst_az_deg = 0,
           worst_el_deg = 0;
    lidet_proj_q_cfg_t cfg_q;
    lidet_proj_buffers_t cbuf;
    lidet_proj_q_buffers_t qbuf;
    double agree_row = 0, agree_col = 0, agree_n = 0, fill_sum = 0;
    lidet_proj_cfg_t cfg;
    lidet_range_image_t img;
    int rows, cols, r;
    float lo_rad, hi_rad;

    pos = (char **)malloc(sizeof(char *) * (size_t)(argc + 1));
    if (pos == NULL)
        return 1;
    o.who = "lidet_bench_proj";
    o.sensor = "hdl64";
    o.repeat = 30;
    sets[0] = cli_optset(cli_opts_bench, cli_bench_take, &o);
    sets[1] = cli_optset(k_opts, take_clock, NULL);
    a = cli_options_parse(argc, argv, "lidet_bench_proj", sets, 2, pos, &n_pos);
    sensor = o.sensor;
    repeat = o.repeat;
    if (a == CLI_PARSE_OK && lidet_sensor_find(sensor) == NULL)
    {
        fprintf(stderr, "lidet_bench_proj: unknown sensor '%s'\n", sensor);
        a = CLI_PARSE_USAGE;
    }
    if (a != CLI_PARSE_OK)
    {
        if (a == CLI_PARSE_USAGE)
            fprintf(stderr,
                    "usage: lidet_bench_proj --sensor NAME [--repeat N] [--clock wall|cpu] SCAN.bin...\n");
        free(pos);
        return 1;
    }
    lidet_proj_cfg_default(&cfg, lidet_sensor_find(sensor));
    if (lidet_proj_init(&g_proj, &cfg) != LIDET_OK)
        return 1;
    lidet_proj_q_cfg_default(&cfg_q, lidet_sensor_q_find(sensor));
    if (lidet_proj_q_init(&g_proj_q, &cfg_q) != LIDET_OK)
        return 1;
    memset(&cbuf, 0, sizeof cbuf);
    cbuf.x_4mm = c_x;
    cbuf.y_4mm = c_y;
    cbuf.z_4mm = c_z;
    cbuf.range_4mm = c_r;
    cbuf.point_idx = b_idx;
    qbuf.x_4mm = c_x;
    qbuf.y_4mm = c_y;
    qbuf.z_4mm = c_z;
    qbuf.range_4mm = c_r;
    qbuf.point_idx = b_idx;
    qbuf.point_pixel = NULL;
    lidet_proj_image(&g_proj, &img);
    rows = img.n_rows;
    cols = img.n_cols;
    for (r = 0; r + 1 < rows; ++r)
        b_mid_rad[r] = 0.5f * (img.row_elev_rad[r] + img.row_elev_rad[r + 1]);
    b_mid_rad[rows - 1] = -10.0f;
    hi_rad = img.row_elev_rad[0] + cfg.fov_margin_rad;
    lo_rad = img.row_elev_rad[rows - 1] - cfg.fov_margin_rad;

    for (a = 0; a < n_pos; ++a)
    {
        const char *path = pos[a];
        FILE *f;
        long size;
        float *pts;
        int32_t *pts_mm;
        uint32_t n, i, np;
        double *tl, *tb, *tc, *tq, ml, mb, mc, mq;
        const int32_t *pp;
        int k;
        f = fopen(path, "rb");
        if (f == NULL)
        {
            fprintf(stderr, "cannot open %s\n", path);
            return 1;
        }
        fseek(f, 0, SEEK_END);
        size = ftell(f);
        fseek(f, 0, SEEK_SET);
        if (size <= 0 || size % 16 != 0)
        {
            fprintf(stderr, "%s: not a KITTI scan\n", path);
            fclose(f);
            return 1;
        }
        n = (uint32_t)(size / 16);
        pts = (float *)malloc((size_t)size);
        if (pts == NULL || fread(pts, 1, (size_t)size, f) != (size_t)size)
        {
            fclose(f);
            return 1;
        }
        fclose(f);
        pts_mm = (int32_t *)malloc((size_t)size); /* 4 int32 per point: x, y, z in mm, remission unused */
        if (pts_mm == NULL)
            return 1;
        for (i = 0; i < 4u * n; ++i)
            pts_mm[i] = (int32_t)lround((double)pts[i] * 1000.0);
        tl = (double *)malloc(sizeof(double) * (size_t)repeat);
        tb = (double *)malloc(sizeof(double) * (size_t)repeat);
        tc = (double *)malloc(sizeof(double) * (size_t)repeat);
        tq = (double *)malloc(sizeof(double) * (size_t)repeat);
        for (k = 0; k < repeat; ++k) /* interleaved, so both see the same machine state */
        {
            double t0 = now_ms();
            lidet_proj_run(&g_proj, pts, n, 4, NULL);
            tl[k] = now_ms() - t0;
            t0 = now_ms();
            baseline_run(pts, n, rows, cols, lo_rad, hi_rad);
            tb[k] = now_ms() - t0;
            t0 = now_ms();
            lidet_proj_run_buffers(&g_proj.state, &cbuf, pts, n, 4, NULL);
            tc[k] = now_ms() - t0;
            t0 = now_ms();
            lidet_proj_q_run(&g_proj_q, &qbuf, pts_mm, n, 4, NULL);
            tq[k] = now_ms() - t0;
        }
        ml = median(tl, repeat);
        mb = median(tb, repeat);
        mc = median(tc, repeat);
        mq = median(tq, repeat);
        free(tl);
        free(tb);
        free(tc);
        free(tq);
        free(pts_mm);

        /* accuracy against double precision */
        pp = lidet_proj_point_pixels(&g_proj, &np);
        {
            double w_az = 0, w_el = 0;
            uint32_t same_row = 0, same_col = 0, cnt = 0;
            for (i = 0; i < n; ++i)
            {
                const double x = pts[4 * i], y = pts[4 * i + 1], z = pts[4 * i + 2];
                const double rxy = sqrt(x * x + y * y);
                double az_err, el_err, az, el, u;
                int row_ref, col_ref;
                if (pp[i] < 0 || rxy <= 0.0)
                    continue;
                az = atan2(y, x);
                az_err = fabs(key_to_azimuth(lidet_proj_azimuth_key((float)x, (float)y)) - az);
                az_err = az_err > M_PI ? 2.0 * M_PI - az_err : az_err;
                /* lidet decides the row on tan(el) = z / rxy computed in float */
                el = atan2(z, rxy);
                el_err = fabs(atan((double)(pts[4 * i + 2] / sqrtf(pts[4 * i] * pts[4 * i] +
                                                                   pts[4 * i + 1] * pts[4 * i + 1]))) -
                              el);
                w_az = az_err > w_az ? az_err : w_az;
                w_el = el_err > w_el ? el_err : w_el;
                /* double-precision reference pixel */
                u = 0.5 * (1.0 - az / M_PI) * cols;
                col_ref = (int)floor(u);
                col_ref = col_ref >= cols ? col_ref - cols : col_ref;
                row_ref = 0;
                while (row_ref + 1 < rows &&
                       0.5 * ((double)img.row_elev_rad[row_ref] + (double)img.row_elev_rad[row_ref + 1]) > el)
                    ++row_ref;
                same_row += (uint32_t)(pp[i] / cols == row_ref);
                same_col += (uint32_t)(pp[i] % cols == col_ref);
                ++cnt;
            }
            w_az *= 180.0 / M_PI;
            w_el *= 180.0 / M_PI;
            worst_az_deg = w_az > worst_az_deg ? w_az : worst_az_deg;
            worst_el_deg = w_el > worst_el_deg ? w_el : worst_el_deg;
            agree_row += same_row;
            agree_col += same_col;
            agree_n += cnt;
            fill_sum += (double)lidet_proj_stats(&g_proj)->n_pixels_filled / (double)(rows * cols);
            printf("{\"scan\": \"%s\", \"points\": %u, \"projected\": %u, \"fill_ratio\": %.4f, "
                   "\"lidet_ms\": %.4f, "
                   "\"libm_ms\": %.4f, \"lidet_ns_per_point\": %.2f, \"libm_ns_per_point\": %.2f, "
                   "\"speedup\": %.2f, "
                   "\"max_az_err_deg\": %.6f, \"max_el_err_deg\": %.6f, \"row_agree\": %.6f, \"col_agree\": "
                   "%.6f, "
                   "\"compact_ns_per_point\": %.2f, \"int_ns_per_point\": %.2f}\n",
                   path, n, lidet_proj_stats(&g_proj)->n_projected,
                   (double)lidet_proj_stats(&g_proj)->n_pixels_filled / (double)(rows * cols), ml, mb,
                   ml * 1e6 / n, mb * 1e6 / n, mb / ml, w_az, w_el, cnt ? (double)same_row / cnt : 0.0,
                   cnt ? (double)same_col / cnt : 0.0, mc * 1e6 / n, mq * 1e6 / n);
        }
        sum_pts += n;
        sum_lidet_ms += ml;
        sum_base_ms += mb;
        sum_compact_ms += mc;
        sum_q_ms += mq;
        ++n_files;
        free(pts);
    }
    if (n_files > 0)
    {
        printf("{\"summary\": true, \"sensor\": \"%s\", \"scans\": %d, \"repeat\": %d, "
               "\"lidet_ns_per_point\": %.2f, "
               "\"libm_ns_per_point\": %.2f, \"speedup\": %.2f, \"max_az_err_deg\": %.6f, "
               "\"max_el_err_deg\": %.6f, "
               "\"row_agree\": %.6f, \"col_agree\": %.6f, \"mean_fill_ratio\": %.4f, "
               "\"compact_ns_per_point\": %.2f, "
               "\"int_ns_per_point\": %.2f}\n",
               sensor, n_files, repeat, sum_lidet_ms * 1e6 / sum_pts, sum_base_ms * 1e6 / sum_pts,
               sum_base_ms / sum_lidet_ms, worst_az_deg, worst_el_deg, agree_row / agree_n,
               agree_col / agree_n, fill_sum / n_files, sum_compact_ms * 1e6 / sum_pts,
               sum_q_ms * 1e6 / sum_pts);
    }
    free(pos);
    return 0;
}
