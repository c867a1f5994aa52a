/* SPDX-License-Identifier: MIT */
/* `lidet cluster`: projection, ground mask, depth clustering and proposals on one scan.
 * Ground: from a SemanticKITTI label file (--labels, classes 40 44 48 49 60 72), else the ground stage
 * (lidet_ground.h, with its per-sector planes for the height filter). */
#include <stdlib.h>
#include <string.h>

#include "cli.h"

static lidet_proj_t g_proj;
static lidet_cluster_t g_cl;
static uint8_t g_ground[LIDET_MAX_ROWS * LIDET_MAX_COLS];
static lidet_proposal_t g_prop;
static lidet_ground_t g_gnd;

static int is_ground_class(uint32_t label)
{
    const uint32_t s = label & 0xFFFFu;
    return s == 40u || s == 44u || s == 48u || s == 49u || s == 60u || s == 72u;
}

/* cluster id -> a bright colour (golden-ratio hue walk) */
static void id_colour(uint32_t id, uint8_t rgb[3])
{
    float t = (float)id * 0.61803398875f;
    t -= (float)(int)t;
    cli_colormap(0.15f + 0.85f * t, rgb);
}

/* bird's-eye view, +x up, +y left, 80 m x 80 m at 0.1 m per pixel: ground dark, other points grey,
 * clustered points in their cluster's colour */
static int write_bev_png(const char *path, const float *pts, uint32_t n, const uint32_t *ids,
                         const int32_t *pp, const uint8_t *ground_pix, const char *title,
                         const char *subtitle)
{
    cli_legend_t legend[5] = {{"", {0, 0, 0}},
                              {"", {0, 0, 0}},
                              {"clusters (a colour per id)", {0, 0, 0}},
                              {"other points", {110, 110, 110}},
                              {"ground", {40, 40, 48}}};
    const uint32_t W = 800, H = 800;
    const float res = 0.1f;
    uint8_t *rgb = (uint8_t *)calloc((size_t)W * H * 3u, 1);
    uint32_t i;
    int rc;
    if (rgb == NULL)
        return -1;
    for (i = 0; i < n; ++i)
    {
        const float x = pts[4 * i], y = pts[4 * i + 1];
        const float u = (float)W * 0.5f - y / res, v = (float)H * 0.5f - x / res;
        uint8_t c[3];
        uint8_t *px;
        if (!(u >= 0.0f && u < (float)W && v >= 0.0f && v < (float)H))
            continue;
        px = rgb + (((size_t)(uint32_t)v * W) + (uint32_t)u) * 3u;
        if (ids[i] > 0)
            id_colour(ids[i], c);
        else if (pp[i] >= 0 && ground_pix[pp[i]])
        {
            c[0] = 40;
            c[1] = 40;
            c[2] = 48;
            if (px[0] | px[1] | px[2])
                continue; /* never paint ground over something else */
        }
        else
        {
            c[0] = 110;
            c[1] = 110;
            c[2] = 110;
            if (px[0] > 110 || px[1] > 110 || px[2] > 110)
                continue; /* keep cluster colours */
        }
        px[0] = c[0];
        px[1] = c[1];
        px[2] = c[2];
    }
    id_colour(1, legend[0].rgb);
    id_colour(2, legend[1].rgb);
    id_colour(3, legend[2].rgb);
    rc = cli_bev_write(path, rgb, W, H, res, title, subtitle, legend, 5);
    free(rgb);
    return rc;
}

/* `--set KEY=VALUE` overrides one lidet_cluster_cfg_t field (also `lidet detect --set
 * stages.cluster.KEY=VALUE`). Returns 0, or 1 for an unknown key or a bad number. */
int cli_cluster_set(lidet_cluster_cfg_t *c, const char *kv)
{
    size_t klen;
    double v;
    if (cli_split_set(kv, &klen, &v) != 0)
        return 1;
    CLI_SET_FLOAT(c, kv, klen, v, theta_rad)
    CLI_SET_FLOAT(c, kv, klen, v, max_gap_m)
    CLI_SET_FLOAT(c, kv, klen, v, max_gap_per_m)
    CLI_SET_FLOAT(c, kv, klen, v, max_extent_m)
    CLI_SET_FLOAT(c, kv, klen, v, max_mean_height_m)
    CLI_SET_FLOAT(c, kv, klen, v, mount_height_m)
    CLI_SET_FLOAT(c, kv, klen, v, rescue_gap_m)
    CLI_SET_FLOAT(c, kv, klen, v, rescue_gap_per_m)
    CLI_SET_FLOAT(c, kv, klen, v, max_bridge_per_pixel)
    CLI_SET_FLOAT(c, kv, klen, v, regrow_gap_m)
    CLI_SET_FLOAT(c, kv, klen, v, regrow_gap_per_m)
    CLI_SET_INT(c, kv, klen, v, regrow_max_pixels, uint32_t, 4294967295.0)
    CLI_SET_FLOAT(c, kv, klen, v, regrow_max_height_m)
    CLI_SET_FLOAT(c, kv, klen, v, regrow_cut_m)
    CLI_SET_FLOAT(c, kv, klen, v, plane_split_m)
    CLI_SET_INT(c, kv, klen, v, max_steps, uint32_t, 4294967295.0)
    CLI_SET_INT(c, kv, klen, v, bridge_occluders, uint32_t, 1)
    CLI_SET_INT(c, kv, klen, v, diagonals, uint32_t, 1)
    CLI_SET_INT(c, kv, klen, v, min_points, uint32_t, 4294967295.0)
    CLI_SET_INT(c, kv, klen, v, rescue_rows, uint32_t, 4294967295.0)
    CLI_SET_INT(c, kv, klen, v, rescue_cols, uint32_t, 4294967295.0)
    CLI_SET_INT(c, kv, klen, v, split_people, uint32_t, 1)
    CLI_SET_FLOAT(c, kv, klen, v, split_min_width_m)
    CLI_SET_FLOAT(c, kv, klen, v, split_cell_m)
    CLI_SET_FLOAT(c, kv, klen, v, split_cell_per_m)
    CLI_SET_FLOAT(c, kv, klen, v, person_max_width_m)
    CLI_SET_FLOAT(c, kv, klen, v, person_min_height_m)
    CLI_SET_FLOAT(c, kv, klen, v, person_min_aspect)
    CLI_SET_INT(c, kv, klen, v, person_min_cols, uint32_t, 65535)
    CLI_SET_INT(c, kv, klen, v, person_min_points, uint32_t, 1000000)
    CLI_SET_INT(c, kv, klen, v, join_cars, uint32_t, 1)
    CLI_SET_FLOAT(c, kv, klen, v, join_gap_m)
    CLI_SET_FLOAT(c, kv, klen, v, car_max_length_m)
    CLI_SET_FLOAT(c, kv, klen, v, car_max_width_m)
    CLI_SET_FLOAT(c, kv, klen, v, car_max_height_m)
    CLI_SET_FLOAT(c, kv, klen, v, car_min_length_m)
    CLI_SET_FLOAT(c, kv, klen, v, upright_max_width_m)
    CLI_SET_INT(c, kv, klen, v, max_fragment_pixels, uint32_t, 4294967295.0)
    CLI_SET_INT(c, kv, klen, v, max_join_pieces, uint32_t, 4294967295.0)
    CLI_SET_FLOAT(c, kv, klen, v, azimuth_half_rad)

    return 1;
}

static int fail(cli_args_t *a, const char *what, lidet_status_t st)
{
    fprintf(stderr, "lidet cluster: %s: %s\n", what, lidet_status_str(st));
    cli_free(a);
    return 1;
}

/* lidet cluster's own options: --labels FILE, --set KEY=VALUE (repeatable, checked once the configuration is made) */
enum
{
    OPT_LABELS,
    OPT_SET
};

static const cli_opt_t k_cluster_opts[] = {
    {"labels", required_argument, OPT_LABELS, "FILE: a SemanticKITTI .label file"},
    {"set", required_argument, OPT_SET, "KEY=VALUE"},
    {NULL, 0, 0, NULL}};

typedef struct
{
    const char *labels;
    cli_list_t set;
} cluster_opts_t;

static int cluster_take(void *ctx, int id, const char *v)
{
    cluster_opts_t *o = (cluster_opts_t *)ctx;
    if (id == OPT_LABELS)
    {
        o->labels = v;
        return 0;
    }
    return cli_list_take(&o->set, id, v);
}

int cli_cluster(int argc, char **argv)
{
    cli_args_t a;
    lidet_proj_cfg_t pcfg;
    lidet_cluster_cfg_t ccfg;
    lidet_proposal_cfg_t prcfg;
    lidet_range_image_t img;
    lidet_status_t st;
    const lidet_cluster_stats_t *cs;
    const char *labels_path = NULL;
    int use_stage = 0; /* ground from the ground stage, rerun every repetition */
    const lidet_plane_t *planes = NULL;
    uint32_t n_sectors = 0;
    double ms_gnd = 0.0;
    char title[256], subtitle[160];
    const char **sets;
    cluster_opts_t own;
    cli_optset_t own_set;
    int nsets = 0, i;
    double *t_proj, *t_clu, *t_prop, *t_gnd, *t_cpu, ms_proj, ms_clu, ms_prop, ms_cpu;
    uint32_t npix, p, n_pp, k, n_rec;
    const int32_t *pp;
    uint32_t *ids;

    sets = (const char **)malloc(sizeof(char *) * (size_t)(argc + 1));
    if (sets == NULL)
        return 1;
    own.set.v = sets;
    own.set.n = 0;
    own.labels = NULL;
    own_set = cli_optset(k_cluster_opts, cluster_take, &own);
    i = cli_parse(argc, argv, "cluster", &a, &own_set, 1);
    labels_path = own.labels;
    nsets = own.set.n;
    if (i != CLI_PARSE_OK)
    {
        if (i == CLI_PARSE_USAGE)
        {
            cli_usage(stderr, "cluster");
            fprintf(stderr, "  --labels   SemanticKITTI .label file: its ground classes are the ground mask\n"
                            "             (default: the ground stage, with its per-sector planes)\n"
                            "  --set KEY=VALUE  override a lidet_cluster_cfg_t field (repeatable), e.g.\n"
                            "             --set rescue_gap_m=0 (no fragment rescue),\n"
                            "             --set split_people=0 (people are not cut out of wide clusters),\n"
                            "             --set join_cars=0 (car fragments are not joined)\n");
        }
        free(sets);
        return i == CLI_PARSE_PRINTED ? 0 : 1;
    }
    if (cli_load(&a) != 0)
    {
        free(sets);
        return 1;
    }
    lidet_proj_cfg_default(&pcfg, a.sensor_profile);
    st = lidet_proj_init(&g_proj, &pcfg);
    if (st != LIDET_OK)
    {
        free(sets);
        return fail(&a, "projection init", st);
    }
    lidet_cluster_cfg_default(&ccfg, a.sensor_profile);
    if (labels_path == NULL)
    {
        /* the ground stage's planes are passed whole (near, then far): far means take the far plane */
        lidet_ground_cfg_t g0;
        lidet_ground_cfg_default(&g0, a.sensor_profile);
        ccfg.plane_split_m = g0.ring_split_m;
    }
    for (i = 0; i < nsets; ++i)
    {
        if (cli_cluster_set(&ccfg, sets[i]) != 0)
        {
            fprintf(stderr, "lidet cluster: bad --set '%s' (KEY=VALUE with a lidet_cluster_cfg_t field)\n", sets[i]);
            free(sets);
            cli_free(&a);
            return 1;
        }
    }
    free(sets);
    st = lidet_cluster_init(&g_cl, &ccfg);
    if (st != LIDET_OK)
        return fail(&a, "cluster init", st);
    lidet_proposal_cfg_default(&prcfg);

    t_proj = (double *)malloc(sizeof(double) * (size_t)a.repeat * 5u);
    ids = (uint32_t *)malloc(sizeof(uint32_t) * (size_t)(a.n_points > 0 ? a.n_points : 1));
    if (t_proj == NULL || ids == NULL)
    {
        free(t_proj);
        free(ids);
        cli_free(&a);
        return 1;
    }
    t_clu = t_proj + a.repeat;
    t_prop = t_clu + a.repeat;
    t_gnd = t_prop + a.repeat;
    t_cpu = t_gnd + a.repeat;

    /* ground mask of the scan (computed once: it is not this stage's time) */
    st = lidet_proj_run(&g_proj, a.points, a.n_points, 4, a.ring);
    if (!LIDET_SUCCEEDED(st))
        return fail(&a, "projection", st);
    lidet_proj_image(&g_proj, &img);
    npix = (uint32_t)img.n_rows * img.n_cols;
    if (labels_path != NULL)
    {
        FILE *f = fopen(labels_path, "rb");
        uint32_t *lab = (uint32_t *)malloc(sizeof(uint32_t) * (size_t)(a.n_points > 0 ? a.n_points : 1));
        size_t got = (f != NULL && lab != NULL) ? fread(lab, sizeof(uint32_t), a.n_points, f) : 0;
        /* exactly one label per point: a longer file belongs to another scan */
        const int extra = f != NULL && got == a.n_points && fgetc(f) != EOF;
        if (f != NULL)
            fclose(f);
        if (got != a.n_points || extra)
        {
            fprintf(stderr, "lidet cluster: '%s' must hold exactly %u labels (one uint32 per point)\n", labels_path,
                    a.n_points);
            free(lab);
            free(t_proj);
            free(ids);
            cli_free(&a);
            return 1;
        }
        for (p = 0; p < npix; ++p)
            g_ground[p] = (uint8_t)(img.point_idx[p] >= 0 && is_ground_class(lab[img.point_idx[p]]));
        free(lab);
    }
    else
    {
        lidet_ground_cfg_t gcfg;
        lidet_ground_cfg_default(&gcfg, a.sensor_profile);
        st = lidet_ground_init(&g_gnd, &gcfg);
        if (st != LIDET_OK)
            return fail(&a, "ground init", st);
        use_stage = 1;
    }

    for (i = 0; i < a.repeat; ++i)
    {
        double t0 = cli_now_ms(), c0;
        st = lidet_proj_run(&g_proj, a.points, a.n_points, 4, a.ring);
        t_proj[i] = cli_now_ms() - t0;
        if (!LIDET_SUCCEEDED(st))
            return fail(&a, "projection", st);
        lidet_proj_image(&g_proj, &img);
        if (use_stage)
        {
            t0 = cli_now_ms();
            st = lidet_ground_run(&g_gnd, &img);
            t_gnd[i] = cli_now_ms() - t0;
            if (!LIDET_SUCCEEDED(st))
                return fail(&a, "ground", st);
            memcpy(g_ground, lidet_ground_mask(&g_gnd), npix);
            planes = lidet_ground_planes(&g_gnd, &n_sectors);
        }
        t0 = cli_now_ms();
        c0 = cli_cpu_ms();
        st = lidet_cluster_run(&g_cl, &img, g_ground, planes, n_sectors);
        t_cpu[i] = cli_cpu_ms() - c0;
        t_clu[i] = cli_now_ms() - t0;
        if (!LIDET_SUCCEEDED(st))
            return fail(&a, "clustering", st);
        lidet_cluster_records(&g_cl, &n_rec);
        t0 = cli_now_ms();
        for (k = 0; k < n_rec; ++k)
        {
            st = lidet_proposal_make(&g_cl, k, &prcfg, &g_prop);
            if (st != LIDET_OK)
                return fail(&a, "proposal", st);
        }
        t_prop[i] = cli_now_ms() - t0;
    }
    ms_proj = cli_median(t_proj, a.repeat);
    ms_clu = cli_median(t_clu, a.repeat);
    ms_cpu = cli_median(t_cpu, a.repeat);
    ms_prop = cli_median(t_prop, a.repeat);
    if (use_stage)
        ms_gnd = cli_median(t_gnd, a.repeat);
    free(t_proj);
    cs = lidet_cluster_stats(&g_cl);
    (void)cli_warn_frame("lidet cluster", NULL, lidet_proj_stats(&g_proj), a.sensor_profile);
    pp = lidet_proj_point_pixels(&g_proj, &n_pp);
    lidet_cluster_point_labels(&g_cl, pp, n_pp, ids);
    for (p = n_pp; p < a.n_points; ++p)
        ids[p] = 0; /* past LIDET_MAX_POINTS */

    if (a.out_path != NULL)
    {
        FILE *f = fopen(a.out_path, "wb");
        if (f == NULL || fwrite(ids, sizeof ids[0], a.n_points, f) != a.n_points || fclose(f) != 0)
        {
            fprintf(stderr, "lidet cluster: cannot write '%s'\n", a.out_path);
            free(ids);
            cli_free(&a);
            return 1;
        }
    }
    if (a.png_path != NULL)
    {
        snprintf(title, sizeof title, "cluster  %s  %s (ground: %s)  %.1f ms", cli_basename(a.scan_path),
                 a.sensor, labels_path != NULL ? "labels" : "stage", ms_proj + ms_gnd + ms_clu + ms_prop);
        if (a.repeat > 1)
            snprintf(title + strlen(title), sizeof title - strlen(title), ", median of %d", a.repeat);
        snprintf(subtitle, sizeof subtitle, "%u points  %u clusters", a.n_points, cs->n_kept);
    }
    if (a.png_path != NULL &&
        write_bev_png(a.png_path, a.points, n_pp, ids, pp, g_ground, title, subtitle) != 0)
    {
        fprintf(stderr, "lidet cluster: cannot write '%s'\n", a.png_path);
        free(ids);
        cli_free(&a);
        return 1;
    }
    if (a.json)
    {
        cli_json_begin(stdout);
        cli_json_str(stdout, "sensor", a.sensor);
        cli_json_int(stdout, "points", a.n_points);
        cli_json_str(stdout, "ground", labels_path != NULL ? "labels" : "stage");
        cli_json_int(stdout, "candidates", cs->n_candidates);
        cli_json_int(stdout, "found", cs->n_found);
        cli_json_int(stdout, "dropped_small", cs->n_dropped_small);
        cli_json_int(stdout, "dropped_extent", cs->n_dropped_extent);
        cli_json_int(stdout, "dropped_height", cs->n_dropped_height);
        cli_json_int(stdout, "dropped_capacity", cs->n_dropped_capacity);
        cli_json_int(stdout, "fragments", cs->n_fragments);
        cli_json_int(stdout, "rescue_joined", cs->n_rescue_joined);
        cli_json_int(stdout, "rescue_pixels", cs->n_rescue_pixels);
        cli_json_int(stdout, "split", cs->n_split);
        cli_json_int(stdout, "split_parts", cs->n_split_parts);
        cli_json_int(stdout, "joined", cs->n_joined);
        cli_json_int(stdout, "join_skipped", cs->n_join_skipped);
        cli_json_int(stdout, "fragment_pixels", cs->n_fragment_pixels);
        cli_json_int(stdout, "dropped_fragment_budget", cs->n_dropped_fragment_budget);
        cli_json_int(stdout, "bridge_steps", cs->n_bridge_steps);
        cli_json_int(stdout, "clusters", cs->n_kept);
        cli_json_int(stdout, "proposals", cs->n_kept);
        cli_json_int(stdout, "proposal_points", prcfg.n_points);
        cli_json_num(stdout, "theta_rad", ccfg.theta_rad);
        cli_json_int(stdout, "max_steps", ccfg.max_steps);
        cli_json_int(stdout, "repeat", a.repeat);
        cli_json_num(stdout, "project_ms", ms_proj);
        if (use_stage)
            cli_json_num(stdout, "ground_ms", ms_gnd);
        cli_json_num(stdout, "cluster_ms", ms_clu);
        cli_json_num(stdout, "cluster_cpu_ms", ms_cpu);
        cli_json_num(stdout, "proposal_ms", ms_prop);
        cli_json_num(stdout, "total_ms", ms_proj + ms_gnd + ms_clu + ms_prop);
        cli_json_end(stdout);
    }
    else
    {
        printf("scan            %s (%s)\n", a.scan_path, a.sensor);
        printf("points          %u, non-ground pixels %u (ground: %s)\n", a.n_points, cs->n_candidates,
               labels_path != NULL ? labels_path : "ground stage");
        printf("clusters        %u kept of %u found (dropped: small %u, extent %u, height %u, capacity %u)\n",
               cs->n_kept, cs->n_found, cs->n_dropped_small, cs->n_dropped_extent, cs->n_dropped_height,
               cs->n_dropped_capacity);
        printf("rescue          %u fragments (%u pixels, %u past the budget); %u groups joined clusters, %u pixels "
               "kept\n",
               cs->n_fragments, cs->n_fragment_pixels, cs->n_dropped_fragment_budget, cs->n_rescue_joined,
               cs->n_rescue_pixels);
        printf("refinement      %u clusters cut into %u more (people); %u car fragments joined\n", cs->n_split,
               cs->n_split_parts, cs->n_joined);
        printf("proposals       %u x %u points\n", cs->n_kept, prcfg.n_points);
        printf("cluster_ms      %.3f (median of %d; CPU %.3f; projection %.3f, proposals %.3f)\n", ms_clu,
               a.repeat, ms_cpu, ms_proj, ms_prop);
        if (a.png_path != NULL)
            printf("picture         %s\n", a.png_path);
    }
    free(ids);
    cli_free(&a);
    return 0;
}
