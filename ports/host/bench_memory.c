/* SPDX-License-Identifier: MIT */
/* Memory-model benchmark (issue 18, docs/MEMORY.md): the same scan through the two memory models of the
 * library, in the same run, interleaved, on one thread:
 *   stages     - the standalone stage objects (lidet_proj_t, lidet_ground_t, lidet_cluster_t: every table,
 *                output and scratch buffer of a stage in its own object, float image with R, the pixel of
 *                every input point), chained as a caller chains them (cluster height filter on the ground
 *                stage's planes): the memory model before issue 18;
 *   workspace  - lidet_workspace_run: one object, scratch overlaid, the compact 4 mm image, nothing per
 *                input point (what the detector runs);
 *   workspace+ - lidet_workspace_run with the per-point outputs asked for (point_pixel, then
 *                lidet_workspace_point_labels for the cluster id and the ground bit of every point), the
 *                outputs the stage objects always make.
 * Beside them, the clustering stage alone on the same ground mask (the stage objects'), once on the workspace's
 * compact image and once on the float image: the chains' clustering times differ also because their ground
 * masks do (RANSAC on 4 mm coordinates draws other planes), this pair compares the code on one input.
 * Each is timed in CPU time of this thread (CLOCK_THREAD_CPUTIME_ID), projection + ground + clustering,
 * median over --repeat runs. Also prints the bytes each model holds and how far their results agree
 * (ground labels and cluster membership per valid pixel: the compact image rounds coordinates to 4 mm).
 * One JSON object per scan on stdout (tools/bench/bench_memory.py reads them).
 *
 * usage: lidet_bench_memory --sensor hdl64 [--repeat 30] [--only stages|workspace] SCAN.bin...
 * (--only: run that model alone, for a profiler; its medians only are meaningful)
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "lidet/lidet.h"
#include "lidet/lidet_workspace.h"

static lidet_proj_t g_proj;
static lidet_ground_t g_ground;
static lidet_cluster_t g_cluster;
static lidet_workspace_t g_ws;
static lidet_cluster_t g_cluster_same; /* the clustering alone on both images, the same mask */
static uint8_t g_mask[LIDET_MAX_ROWS * LIDET_MAX_COLS];
static int32_t g_pp[LIDET_MAX_POINTS];
static uint32_t g_ids[LIDET_MAX_POINTS];
static uint8_t g_gnd[LIDET_MAX_POINTS];
static uint32_t g_ids_ref[LIDET_MAX_POINTS];
static uint8_t g_gnd_ref[LIDET_MAX_POINTS];

static float *read_scan(const char *path, uint32_t *n)
{
    FILE *f = fopen(path, "rb");
    long sz;
    float *p;
    if (f == NULL || fseek(f, 0, SEEK_END) != 0 || (sz = ftell(f)) < 0 || sz % 16 != 0 ||
        fseek(f, 0, SEEK_SET) != 0)
    {
        if (f)
            fclose(f);
        return NULL;
    }
    p = (float *)malloc((size_t)sz + 16u);
    if (p == NULL || fread(p, 1, (size_t)sz, f) != (size_t)sz)
    {
        free(p);
        fclose(f);
        return NULL;
    }
    fclose(f);
    *n = (uint32_t)(sz / 16);
    return p;
}

/* ticks: ns of projection, ground, clustering */
static lidet_status_t run_stages(const float *pts, uint32_t n, uint32_t ticks[3])
{
    lidet_range_image_t img;
    const lidet_plane_t *planes;
    uint32_t ns, t0 = cli_stage_clock_ns(NULL), t1, t2;
    lidet_status_t st = lidet_proj_run(&g_proj, pts, n, 4, NULL);
    if (!LIDET_SUCCEEDED(st))
        return st;
    lidet_proj_image(&g_proj, &img);
    t1 = cli_stage_clock_ns(NULL);
    st = lidet_ground_run(&g_ground, &img);
    if (!LIDET_SUCCEEDED(st))
        return st;
    t2 = cli_stage_clock_ns(NULL);
    planes = lidet_ground_planes(&g_ground, &ns);
    st = lidet_cluster_run(&g_cluster, &img, lidet_ground_mask(&g_ground), planes, ns);
    ticks[0] = t1 - t0;
    ticks[1] = t2 - t1;
    ticks[2] = cli_stage_clock_ns(NULL) - t2;
    return st;
}

static lidet_status_t run_workspace(const float *pts, uint32_t n, int per_point, uint32_t ticks[3])
{
    lidet_status_t st = lidet_workspace_run_timed(&g_ws, pts, n, 4, NULL, per_point ? g_pp : NULL,
                                                  cli_stage_clock_ns, NULL, ticks);
    if (!LIDET_SUCCEEDED(st) || !per_point)
        return st;
    return lidet_workspace_point_labels(&g_ws, g_pp, n < LIDET_MAX_POINTS ? n : LIDET_MAX_POINTS, g_ids,
                                        g_gnd);
}

/* share of points valid in both (projected, the same in both up to 131 m) whose ground bit agrees, and whose
 * cluster membership agrees up to renaming: two points share a cluster in one result iff they do in the other,
 * checked against each point's first partner (the first point seen with its id) */
static void agreement(uint32_t n, double *ground_pct, double *cluster_pct)
{
    static uint32_t first_ref[LIDET_MAX_POINTS], first_ws[LIDET_MAX_POINTS];
    static uint32_t seen_ref[LIDET_MAX_CLUSTERS + 2u], seen_ws[LIDET_MAX_CLUSTERS + 2u];
    uint32_t i, both = 0, g_ok = 0, c_ok = 0;
    memset(seen_ref, 0xFF, sizeof seen_ref);
    memset(seen_ws, 0xFF, sizeof seen_ws);
    for (i = 0; i < n; ++i)
    {
        const uint32_t a = g_ids_ref[i], b = g_ids[i];
        first_ref[i] = a == 0 || a > LIDET_MAX_CLUSTERS
                           ? i
                           : (seen_ref[a] == 0xFFFFFFFFu ? (seen_ref[a] = i) : seen_ref[a]);
        first_ws[i] = b == 0 || b > LIDET_MAX_CLUSTERS
                          ? i
                          : (seen_ws[b] == 0xFFFFFFFFu ? (seen_ws[b] = i) : seen_ws[b]);
    }
    for (i = 0; i < n; ++i)
    {
        if (g_pp[i] < 0 || lidet_proj_point_pixels(&g_proj, NULL)[i] < 0)
            continue;
        ++both;
        g_ok += g_gnd[i] == g_gnd_ref[i];
        /* the same partner in both, and clustered in both or in neither */
        c_ok += (g_ids[i] == 0) == (g_ids_ref[i] == 0) && first_ref[i] == first_ws[i];
    }
    *ground_pct = both ? 100.0 * g_ok / both : 100.0;
    *cluster_pct = both ? 100.0 * c_ok / both : 100.0;
}

/* medians of the clustering alone on the compact and on the float image, the stage objects' ground mask and
 * planes (run_stages and run_workspace ran on this scan last); t: 2 * repeat doubles */
static void cluster_same_mask(int repeat, double *t, double *ms_compact, double *ms_float)
{
    lidet_range_image_t wimg, fimg;
    uint32_t ns = 0;
    const lidet_plane_t *planes = lidet_ground_planes(&g_ground, &ns);
    int i;
    lidet_workspace_image(&g_ws, &wimg);
    lidet_proj_image(&g_proj, &fimg);
    memcpy(g_mask, lidet_ground_mask(&g_ground), (size_t)fimg.n_rows * fimg.n_cols);
    for (i = 0; i < repeat; ++i)
    {
        double t0 = cli_cpu_ms();
        (void)lidet_cluster_run(&g_cluster_same, &wimg, g_mask, planes, ns);
        t[i] = cli_cpu_ms() - t0;
        t0 = cli_cpu_ms();
        (void)lidet_cluster_run(&g_cluster_same, &fimg, g_mask, planes, ns);
        t[repeat + i] = cli_cpu_ms() - t0;
    }
    *ms_compact = cli_median(t, repeat);
    *ms_float = cli_median(t + repeat, repeat);
}

/* the options (cli_options.c): the benchmarks' shared set (cli_opts_bench: --sensor, --repeat) and --only */
static const cli_opt_t k_opts[] = {{"only", required_argument, 0, "stages or workspace"}, {NULL, 0, 0, NULL}};

static int take_only(void *ctx, int id, const char *v)
{
    int *only = (int *)ctx;
    (void)id;
    if (strcmp(v, "stages") != 0 && strcmp(v, "workspace") != 0)
    {
        fprintf(stderr, "lidet_bench_memory: --only stages or --only workspace, not '%s'\n", v);
        return 1;
    }
    *only = strcmp(v, "workspace") == 0;
    return 0;
}

int main(int argc, char **argv)
{
    const char *sensor_name;
    const lidet_sensor_t *sensor;
    lidet_workspace_cfg_t cfg;
    lidet_workspace_sizes_t sz;
    int repeat, a, rc = 0, only, n_pos = 0;
    double *t;
    char **pos = (char **)malloc(sizeof(char *) * (size_t)(argc + 1));
    cli_bench_opts_t o;
    cli_optset_t sets[2];

    if (pos == NULL)
        return 1;
    o.who = "lidet_bench_memory";
    o.sensor = "hdl64";
    o.repeat = 30;
    only = -1;
    sets[0] = cli_optset(cli_opts_bench, cli_bench_take, &o);
    sets[1] = cli_optset(k_opts, take_only, &only);
    a = cli_options_parse(argc, argv, "lidet_bench_memory", sets, 2, pos, &n_pos);
    if (a != CLI_PARSE_OK)
    {
        if (a == CLI_PARSE_USAGE)
            fprintf(
                stderr,
                "usage: lidet_bench_memory --sensor S [--repeat N] [--only stages|workspace] SCAN.bin...\n");
        free(pos);
        return 2;
    }
    sensor_name = o.sensor;
    repeat = o.repeat;
    cli_stage_clock_cpu = 1; /* the workspace's stage clock in this thread's CPU time */
    sensor = lidet_sensor_find(sensor_name);
    if (sensor == NULL || n_pos == 0)
    {
        fprintf(stderr, "lidet_bench_memory: %s\n", sensor == NULL ? "unknown sensor" : "need scans");
        free(pos);
        return 2;
    }
    lidet_workspace_cfg_default(&cfg, sensor);
    if (lidet_workspace_init(&g_ws, &cfg) != LIDET_OK || lidet_proj_init(&g_proj, &cfg.proj) != LIDET_OK ||
        lidet_ground_init(&g_ground, &cfg.ground) != LIDET_OK ||
        lidet_cluster_init(&g_cluster, &cfg.cluster) != LIDET_OK ||
        lidet_cluster_init(&g_cluster_same, &cfg.cluster) != LIDET_OK)
    {
        fprintf(stderr, "lidet_bench_memory: init failed (capacities too small for %s?)\n", sensor_name);
        return 1;
    }
    lidet_workspace_sizes(&sz);
    t = (double *)malloc(sizeof(double) * (size_t)repeat * 12u);
    if (t == NULL)
        return 1;
    for (a = 0; a < n_pos; ++a)
    {
        uint32_t n = 0, m;
        float *pts = read_scan(pos[a], &n);
        double ms[3][4], ag, ac, same_c, same_f;
        uint32_t tk[3];
        int i, k, s;
        if (pts == NULL)
        {
            fprintf(stderr, "lidet_bench_memory: cannot read %s (missing, or not records of 4 floats)\n",
                    pos[a]);
            rc = 1;
            continue;
        }
        m = n < LIDET_MAX_POINTS ? n : LIDET_MAX_POINTS;
        /* warm-up, and the results compared */
        if (!LIDET_SUCCEEDED(run_stages(pts, n, tk)) || !LIDET_SUCCEEDED(run_workspace(pts, n, 1, tk)) ||
            !LIDET_SUCCEEDED(lidet_cluster_point_labels(&g_cluster, lidet_proj_point_pixels(&g_proj, NULL), m,
                                                        g_ids_ref)) ||
            !LIDET_SUCCEEDED(
                lidet_ground_point_labels(&g_ground, lidet_proj_point_pixels(&g_proj, NULL), m, g_gnd_ref)))
        {
            fprintf(stderr, "lidet_bench_memory: a stage failed on %s\n", pos[a]);
            free(pts);
            rc = 1;
            continue;
        }
        agreement(m, &ag, &ac);
        /* interleaved: one run of each model per round; t[(model * 4 + part) * repeat + round], part 3 = the
         * whole call (per-point labels included for workspace+) */
        for (i = 0; i < repeat; ++i)
        {
            for (k = 0; k < 3; ++k)
            {
                double t0;
                if (only >= 0 && k != only)
                    continue;
                t0 = cli_cpu_ms();
                if (k == 0)
                    (void)run_stages(pts, n, tk);
                else
                    (void)run_workspace(pts, n, k == 2, tk);
                t[(k * 4 + 3) * repeat + i] = cli_cpu_ms() - t0;
                for (s = 0; s < 3; ++s)
                    t[(k * 4 + s) * repeat + i] = (double)tk[s] * 1e-6;
            }
        }
        for (k = 0; k < 3; ++k)
            for (s = 0; s < 4; ++s)
                ms[k][s] = cli_median(t + (k * 4 + s) * repeat, repeat);
        printf("{\"scan\": \"%s\", \"sensor\": \"%s\", \"points\": %u, \"repeat\": %d, ", pos[a], sensor_name,
               (unsigned)n, repeat);
        for (k = 0; k < 3; ++k)
        {
            static const char *const name[3] = {"stages", "workspace", "workspace_per_point"};
            printf(
                "\"%s_ms\": %.4f, \"%s_project_ms\": %.4f, \"%s_ground_ms\": %.4f, \"%s_cluster_ms\": %.4f, ",
                name[k], ms[k][3], name[k], ms[k][0], name[k], ms[k][1], name[k], ms[k][2]);
        }
        (void)run_stages(pts, n, tk);
        (void)run_workspace(pts, n, 0, tk);
        cluster_same_mask(repeat, t, &same_c, &same_f);
        printf("\"same_mask_cluster_compact_ms\": %.4f, \"same_mask_cluster_float_ms\": %.4f, ", same_c,
               same_f);
        printf("\"stages_bytes\": %u, \"workspace_bytes\": %u, \"ground_agree_pct\": %.3f, "
               "\"cluster_agree_pct\": %.3f}\n",
               (unsigned)sz.stages_standalone, (unsigned)sz.total, ag, ac);
        fflush(stdout);
        free(pts);
    }
    free(t);
    free(pos);
    return rc;
}
