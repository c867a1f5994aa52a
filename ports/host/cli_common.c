/* SPDX-License-Identifier: MIT */
#include <errno.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>

#include "cli.h"

void cli_usage(FILE *f, const char *cmd)
{
    fprintf(f,
            "usage: lidet %s SCAN.bin [--sensor NAME | --sensor-file F | --ouster-meta M |\n"
            "                 --velodyne-calib C [--cols N]]\n"
            "                 [--ring RING.bin] [--out FILE] [--png FILE] [--json] [--repeat N] [--mount-height M]\n"
            "       lidet %s [--sensor NAME | --sensor-file F | --ouster-meta M | --velodyne-calib C [--cols N]]\n"
            "                 [--mount-height M] --print-sensor\n"
            "  SCAN.bin   KITTI velodyne scan: float32 records x, y, z, remission (metres, sensor frame)\n"
            "  --sensor   hdl64 (default), vlp16, vlp32c, hdl32, os0-32, os0-64, os0-128, os1-32, os1-64,\n"
            "             os1-128, os2-32, os2-64, os2-128, pandar64 (docs/SENSORS.md)\n"
            "  --sensor-file  a sensor description (JSON, \"format\": \"lidet-sensor\"; docs/SENSORS.md)\n"
            "  --ouster-meta  an Ouster sensor's metadata JSON (beam table, columns; mount height 1.0 m\n"
            "             unless --mount-height)\n"
            "  --velodyne-calib  a Velodyne calibration: db.xml / VeloView XML, or velodyne_pointcloud's YAML\n"
            "             (beam table in ring order, lowest beam first; mount height 1.0 m unless --mount-height)\n"
            "  --cols     with --velodyne-calib: columns per revolution (default 1800; 2048 for 64 lasers)\n"
            "  --print-sensor  print the sensor as a lidet sensor description (JSON) and stop\n"
            "  --ring     optional uint16 ring index per point (sensor's ring order) instead of elevation\n"
            "  --json     print one JSON object (stage timings as <stage>_ms)\n"
            "  --repeat   run the stage N times and report the median time (file reading excluded)\n"
            "  --mount-height  the sensor's height above the ground in metres, in [0, 10] (default: the\n"
            "             profile's: hdl64 1.73, vlp16 0.5, ...); the ground and clustering stages use it\n"
            "  Options go before or after SCAN.bin, as --name VALUE or --name=VALUE; -- ends them.\n",
            cmd, cmd);
}

/* ---- the shared options (cli_options.c): the sensor, the scan's files and output ---- */

enum
{
    OPT_SENSOR,
    OPT_SENSOR_FILE,
    OPT_OUSTER_META,
    OPT_MOUNT_HEIGHT,
    OPT_PRINT_SENSOR,
    OPT_OUT,
    OPT_PNG,
    OPT_RING,
    OPT_JSON,
    OPT_REPEAT
};

const cli_opt_t cli_opts_sensor[] = {
    {"sensor", required_argument, OPT_SENSOR, "NAME: a sensor preset"},
    {"sensor-file", required_argument, OPT_SENSOR_FILE, "F: a lidet sensor description"},
    {"ouster-meta", required_argument, OPT_OUSTER_META, "M: an Ouster sensor's metadata"},
    {"mount-height", required_argument, OPT_MOUNT_HEIGHT, "M: metres in [0, 10]"},
    {"print-sensor", no_argument, OPT_PRINT_SENSOR, NULL},
    {NULL, 0, 0, NULL}};

const cli_opt_t cli_opts_io[] = {
    {"out", required_argument, OPT_OUT, "FILE; with --pcap a folder"},
    {"png", required_argument, OPT_PNG, "FILE"},
    {"ring", required_argument, OPT_RING, "RING.bin: a uint16 ring index per point"},
    {"json", no_argument, OPT_JSON, NULL},
    {"repeat", required_argument, OPT_REPEAT, "N: an integer in [1, 100000]"},
    {NULL, 0, 0, NULL}};

int cli_args_take(void *ctx, int id, const char *v)
{
    cli_args_t *a = (cli_args_t *)ctx;
    char *end;
    switch (id)
    {
    case OPT_SENSOR:
        a->sensor = v;
        a->sensor_arg = v;
        a->sensor_given = 1;
        break;
    case OPT_SENSOR_FILE:
        a->sensor_file = v;
        break;
    case OPT_OUSTER_META:
        a->ouster_meta = v;
        break;
    case OPT_MOUNT_HEIGHT:
    {
        const double m = strtod(v, &end);
        /* !(m >= 0 && m <= 10) also refuses NaN */
        if (end == v || *end != '\0' || !(m >= 0.0 && m <= 10.0))
        {
            fprintf(stderr, "lidet %s: --mount-height needs metres in [0, 10], got '%s'\n", cli_cmd, v);
            return 1;
        }
        a->mount_height_m = m;
        break;
    }
    case OPT_PRINT_SENSOR:
        a->print_sensor = 1;
        break;
    case OPT_OUT:
        a->out_path = v;
        break;
    case OPT_PNG:
        a->png_path = v;
        break;
    case OPT_RING:
        a->ring_path = v;
        break;
    case OPT_JSON:
        a->json = 1;
        break;
    default: /* OPT_REPEAT */
    {
        const long n = strtol(v, &end, 10);
        if (end == v || *end != '\0' || n < 1 || n > 100000)
        {
            fprintf(stderr, "lidet %s: --repeat needs an integer in [1, 100000], got '%s'\n", cli_cmd, v);
            return 1;
        }
        a->repeat = (int)n;
        break;
    }
    }
    return 0;
}

float cli_png_half_m = 40.0f;

int cli_png_range(const char *v)
{
    char *end;
    const double m = strtod(v, &end);
    /* !(m >= 5 && m <= 200) also refuses NaN */
    if (end == v || *end != '\0' || !(m >= 5.0 && m <= 200.0))
    {
        fprintf(stderr, "lidet %s: --png-range needs metres in [5, 200], got '%s'\n", cli_cmd, v);
        return 1;
    }
    cli_png_half_m = (float)m;
    return 0;
}

/* The real labelled frames of ../shared/data/real put at most 0.5 % of their points outside their presets' beams
 * (KITTI, KITTI-360, SemanticKITTI 0 %, PandaSet 0.1-0.4 %, Argoverse 0.5 %); a KITTI scan turned upside down (y
 * and z negated) puts 48 % there, half of its points then lying above an HDL-64's top beam
 * (tests/python/test_cli_detect.py, docs/ROBUSTNESS.md "A cloud in another frame") */
int cli_warn_frame(const char *who, const char *scan, const lidet_proj_stats_t *ps, const lidet_sensor_t *s)
{
    const double deg = 180.0 / 3.14159265358979, pct = ps->n_points_in > 0u ? 100.0 / ps->n_points_in : 0.0;
    const uint32_t n = ps->n_points_in;
    const char *sep = scan != NULL ? ": " : "";
    int k = 0;
    if (n < 100u)
        return 0; /* too few points to judge a frame by */
    if (scan == NULL)
        scan = "";
    if (ps->n_out_of_fov > n / 10u)
    {
        /* the beams' span: the table's extremes, or the uniform field of view */
        double lo = (double)s->fov_down_rad * deg, hi = (double)s->fov_up_rad * deg;
        uint32_t r;
        for (r = 0; s->beam_elev_rad != NULL && r < s->n_rows; ++r)
        {
            const double e = (double)s->beam_elev_rad[r] * deg;
            lo = r == 0u || e < lo ? e : lo;
            hi = r == 0u || e > hi ? e : hi;
        }
        fprintf(stderr,
                "%s: warning: %s%s%u of %u points (%.0f %%) lie outside the %s's beams (%.1f to %.1f degrees): "
                "lidet reads x forward, y left, z up, in metres; a cloud upside down, in a camera's frame or "
                "from another sensor looks like this (--sensor NAME, --sensor-file F)\n",
                who, scan, sep, (unsigned)ps->n_out_of_fov, (unsigned)n, ps->n_out_of_fov * pct,
                s->name != NULL ? s->name : "sensor", lo, hi);
        ++k;
    }
    if (ps->n_too_far > n / 4u)
    {
        fprintf(stderr,
                "%s: warning: %s%s%u of %u points (%.0f %%) lie beyond the range the image keeps: are the "
                "coordinates in metres?\n",
                who, scan, sep, (unsigned)ps->n_too_far, (unsigned)n, ps->n_too_far * pct);
        ++k;
    }
    return k;
}

void cli_args_default(cli_args_t *a)
{
    memset(a, 0, sizeof *a);
    a->sensor = "hdl64";
    a->repeat = 1;
    a->mount_height_m = -1.0;
}

int cli_args_optsets(cli_args_t *a, int io, cli_optset_t *sets)
{
    int n = 0;
    sets[n++] = cli_optset(cli_opts_sensor, cli_args_take, a);
    sets[n++] = cli_optset(cli_opts_velodyne_calib, cli_velodyne_calib_take, a);
    if (io)
    {
        sets[n++] = cli_optset(cli_opts_io, cli_args_take, a);
    }
    return n;
}

int cli_args_finish(cli_args_t *a, char *const *pos, int n_pos, const char *cmd)
{
    if (n_pos > 1)
    {
        fprintf(stderr, "lidet %s: unexpected argument %s\n", cmd, pos[1]);
        return CLI_PARSE_ERROR;
    }
    if (n_pos == 1)
        a->scan_path = pos[0];
    if (a->scan_path == NULL && !a->print_sensor)
        return CLI_PARSE_USAGE;
    /* a capture's --sensor names the decoder's model, which a --velodyne-calib needs (cli_pcap.c) */
    if ((a->sensor_file != NULL) + (a->ouster_meta != NULL) + (a->velodyne_calib != NULL) +
            (a->sensor_given && !(a->capture && a->velodyne_calib != NULL)) >
        1)
    {
        fprintf(stderr, "lidet %s: give one of --sensor, --sensor-file, --ouster-meta and --velodyne-calib\n", cmd);
        return CLI_PARSE_ERROR;
    }
    if (a->velodyne_cols > 0 && a->velodyne_calib == NULL)
    {
        fprintf(stderr, "lidet %s: --cols goes with --velodyne-calib (the presets and the other files give their "
                        "columns)\n", cmd);
        return CLI_PARSE_ERROR;
    }
    if (a->sensor_file != NULL || a->ouster_meta != NULL || a->velodyne_calib != NULL)
    {
        /* the file's sensor: a->sensor_mounted (its table in a->desc), its family and integer profile */
        if ((a->velodyne_calib != NULL ? cli_velodyne_calib_load(a, cmd) : cli_sensor_load(a, cmd)) != 0)
            return CLI_PARSE_SENSOR_FILE;
    }
    else
    {
        a->sensor_profile = lidet_sensor_find(a->sensor);
        if (a->sensor_profile == NULL)
        {
            uint32_t k;
            fprintf(stderr, "lidet %s: unknown sensor '%s' (known:", cmd, a->sensor);
            for (k = 0; lidet_sensor_at(k) != NULL; ++k)
                fprintf(stderr, "%s %s", k ? "," : "", lidet_sensor_at(k)->name);
            fprintf(stderr, ")\n");
            return CLI_PARSE_ERROR;
        }
    }
    if (a->mount_height_m >= 0.0)
    {
        if (a->sensor_profile != &a->sensor_mounted)
            a->sensor_mounted = *a->sensor_profile;
        a->sensor_mounted.mount_height_m = (float)a->mount_height_m;
        a->sensor_profile = &a->sensor_mounted;
        a->desc.mount_height_m = a->mount_height_m; /* what --print-sensor prints for a file's sensor */
    }
    if (a->print_sensor && !a->capture) /* a capture's sensor: cli_capture_print_sensor, once it is known */
    {
        cli_sensor_print(a, stdout);
        return CLI_PARSE_PRINTED;
    }
    return CLI_PARSE_OK;
}

int cli_parse(int argc, char **argv, const char *cmd, cli_args_t *a, const cli_optset_t *own, int n_own)
{
    cli_optset_t sets[8];
    char who[64];
    char **pos = (char **)malloc(sizeof(char *) * (size_t)(argc + 1));
    int n, k, n_pos = 0, rc;
    cli_args_default(a);
    if (pos == NULL)
    {
        fprintf(stderr, "lidet %s: out of memory\n", cmd);
        return CLI_PARSE_ERROR;
    }
    n = cli_args_optsets(a, 1, sets);
    for (k = 0; k < n_own && n < (int)(sizeof sets / sizeof sets[0]); ++k)
        sets[n++] = own[k];
    snprintf(who, sizeof who, "lidet %s", cmd);
    rc = cli_options_parse(argc, argv, who, sets, n, pos, &n_pos);
    if (rc == CLI_PARSE_OK)
        rc = cli_args_finish(a, pos, n_pos, cmd);
    free(pos);
    return rc;
}

/* Reads a whole file whose size must be a multiple of `unit` bytes. */
static int read_file(const char *path, size_t unit, void **data, size_t *n_units, const char *what)
{
    struct stat st;
    FILE *f;
    size_t size;
    if (stat(path, &st) != 0)
    {
        fprintf(stderr, "lidet: cannot open %s '%s': %s\n", what, path, strerror(errno));
        return 1;
    }
    if (!S_ISREG(st.st_mode))
    {
        fprintf(stderr, "lidet: %s '%s' is not a regular file\n", what, path);
        return 1;
    }
    size = (size_t)st.st_size;
    if (size % unit != 0)
    {
        fprintf(stderr,
                "lidet: %s '%s' has %zu bytes, not a multiple of %zu: truncated or not a KITTI-format file\n",
                what, path, size, unit);
        return 1;
    }
    *data = malloc(size > 0 ? size : 1);
    f = fopen(path, "rb");
    if (*data == NULL || f == NULL || (size > 0 && fread(*data, 1, size, f) != size))
    {
        fprintf(stderr, "lidet: cannot read %s '%s'\n", what, path);
        if (f != NULL)
            fclose(f);
        free(*data);
        *data = NULL;
        return 1;
    }
    fclose(f);
    *n_units = size / unit;
    return 0;
}

int cli_load(cli_args_t *a)
{
    void *buf = NULL;
    size_t n = 0;
    if (read_file(a->scan_path, 16, &buf, &n, "scan") != 0)
    {
        return 1;
    }
    if (n > 0xFFFFFFFFu)
    {
        fprintf(stderr, "lidet: scan '%s' has too many points\n", a->scan_path);
        free(buf);
        return 1;
    }
    a->points = (float *)buf;
    a->n_points = (uint32_t)n;
    if (a->ring_path != NULL)
    {
        size_t nr = 0;
        if (read_file(a->ring_path, 2, &buf, &nr, "ring file") != 0)
        {
            cli_free(a); /* the scan read above */
            return 1;
        }
        if (nr != n)
        {
            fprintf(stderr, "lidet: ring file '%s' has %zu entries for %zu points\n", a->ring_path, nr, n);
            free(buf);
            cli_free(a);
            return 1;
        }
        a->ring = (uint16_t *)buf;
    }
    return 0;
}

void cli_free(cli_args_t *a)
{
    free(a->points);
    free(a->ring);
    a->points = NULL;
    a->ring = NULL;
}

double cli_now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec * 1e3 + (double)ts.tv_nsec * 1e-6;
}

const char *cli_cmd = "detect";
int cli_stage_clock_cpu = 0;
int cli_fixed_range_only = 0;
int cli_fixed_returns = 0;
uint32_t cli_fixed_stream = 0;
int cli_fixed_stream_sectors = 0;
uint32_t cli_stream_sectors_done = 0;
double cli_stream_end_ms = 0.0;

uint32_t cli_stage_clock_ns(void *ctx)
{
    struct timespec ts;
    (void)ctx;
#ifdef CLOCK_THREAD_CPUTIME_ID
    clock_gettime(cli_stage_clock_cpu ? CLOCK_THREAD_CPUTIME_ID : CLOCK_MONOTONIC, &ts);
#else
    clock_gettime(CLOCK_MONOTONIC, &ts);
#endif
    return (uint32_t)((uint64_t)ts.tv_sec * 1000000000u + (uint64_t)ts.tv_nsec);
}

double cli_cpu_ms(void)
{
#ifdef CLOCK_THREAD_CPUTIME_ID
    struct timespec ts;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return (double)ts.tv_sec * 1e3 + (double)ts.tv_nsec * 1e-6;
#else
    return cli_now_ms();
#endif
}

static int cmp_double(const void *a, const void *b)
{
    const double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

int cli_split_set(const char *kv, size_t *klen, double *v)
{
    const char *eq = strchr(kv, '=');
    char *end;
    if (eq == NULL || eq == kv)
        return 1;
    *klen = (size_t)(eq - kv);
    *v = strtod(eq + 1, &end);
    /* NaN, +-inf (and their spellings "nan", "inf") are refused here: casting them to an integer field
     * would be undefined, and no float field takes them either */
    if (*end != '\0' || end == eq + 1 || !(*v == *v) || *v > 1.0e300 || *v < -1.0e300)
        return 1;
    return 0;
}

double cli_median(double *v, int n)
{
    if (n <= 0)
        return 0.0;
    qsort(v, (size_t)n, sizeof v[0], cmp_double);
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

static int json_first;

void cli_json_begin(FILE *f)
{
    fputc('{', f);
    json_first = 1;
}

static void json_key(FILE *f, const char *key)
{
    fprintf(f, "%s\"%s\": ", json_first ? "" : ", ", key);
    json_first = 0;
}

void cli_json_num(FILE *f, const char *key, double v)
{
    json_key(f, key);
    fprintf(f, "%.6g", v);
}

void cli_json_int(FILE *f, const char *key, long long v)
{
    json_key(f, key);
    fprintf(f, "%lld", v);
}

void cli_json_str(FILE *f, const char *key, const char *v)
{
    json_key(f, key);
    fprintf(f, "\"%s\"", v);
}

void cli_json_end(FILE *f)
{
    fputs("}\n", f);
}

int cli_put_u32(FILE *f, uint32_t v)
{
    return fwrite(&v, sizeof v, 1, f) == 1 ? 0 : -1;
}

int cli_put_f32(FILE *f, float v)
{
    return fwrite(&v, sizeof v, 1, f) == 1 ? 0 : -1;
}
