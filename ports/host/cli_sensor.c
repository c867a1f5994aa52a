/* SPDX-License-Identifier: MIT */
/* Sensors from files for every command (docs/SENSORS.md): `--sensor-file F`, lidet's sensor description (JSON,
 * "format": "lidet-sensor", version 1), and `--ouster-meta M`, Ouster's sensor metadata JSON (flat, 2.x and
 * nested layouts), parsed with cJSON into a lidet_sensor_t, its integer twin (detect --fixed) and the model family.
 * `--print-sensor` prints the command's sensor as a description.
 *
 * The rules, their order and the messages are those of tools/lidet_tools/sensors.py (load_sensor_file,
 * load_ouster_metadata): a change here goes there too; tests/python/test_sensor_files.py compares the two on every
 * test file. Built without cJSON (LIDET_HAVE_CJSON unset) the two options exit with an error saying so.
 * `--velodyne-calib C` (Velodyne's calibrations, libxml2 / libyaml) is cli_velodyne_calib.c's; it hands its table to
 * cli_sensor_use_desc below, as these loaders do. */
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "cli.h"

#ifdef LIDET_HAVE_CJSON
#include <cjson/cJSON.h>
#endif

#define DEG2RAD_D (M_PI_D / 180.0)

static void set_family(cli_sensor_desc_t *d)
{
    /* the description's "model", else hdl64 for 32 beams or more and vlp16 below (sensors.py: model_family) */
    snprintf(d->family, sizeof d->family, "%s",
             d->model[0] != '\0' ? d->model
             : d->rows >= 32     ? "hdl64"
                                 : "vlp16");
}

/* Points the command's profiles at the sensor just read (a->desc; cli.h): the float one (the table in radians), the
 * integer one (microradians rounded half to even, as numpy's round: sensors.py Sensor.beam_elev_urad / _urad_fov). */
void cli_sensor_use_desc(cli_args_t *a)
{
    cli_sensor_desc_t *d = &a->desc;
    lidet_sensor_t *s = &a->sensor_mounted;
    lidet_sensor_q_t *q = &a->sensor_q_file;
    uint16_t i;
    for (i = 0; i < d->rows; ++i)
    {
        /* the file's radians when it gives radians (a velodyne_pointcloud YAML), else its degrees converted */
        const double rad = d->have_rad ? d->elev_rad_d[i] : d->elev_deg[i] * DEG2RAD_D;
        d->elev_rad[i] = (float)rad;
        d->elev_urad[i] = (int32_t)rint(rad * 1e6);
    }
    memset(s, 0, sizeof *s);
    s->name = d->name;
    s->n_rows = d->rows;
    s->n_cols = d->cols;
    s->beam_elev_rad =
        d->elev_rad; /* a uniform description too: the beam centres as a table, as the bindings */
    s->mount_height_m = (float)d->mount_height_m;
    s->max_range_m = (float)d->max_range_m;
    memset(q, 0, sizeof *q);
    q->name = d->name;
    q->n_rows = d->rows;
    q->n_cols = d->cols;
    if (d->uniform)
    {
        q->fov_up_urad = (int32_t)rint(d->fov_up_deg * DEG2RAD_D * 1e6);
        q->fov_down_urad = (int32_t)rint(d->fov_down_deg * DEG2RAD_D * 1e6);
    }
    else
    {
        q->beam_elev_urad = d->elev_urad;
    }
    q->mount_height_mm = (int32_t)rint(d->mount_height_m * 1000.0);
    q->max_range_mm = (int32_t)rint(d->max_range_m * 1000.0);
    set_family(d);
    a->sensor = d->name;
    a->family = d->family;
    a->sensor_profile = s;
    a->sensor_q = q;
}

#ifdef LIDET_HAVE_CJSON

/* what the loaders cannot use: the message without the path */
#define ERR_LEN 512

static int bad(char *err, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(err, ERR_LEN, fmt, ap);
    va_end(ap);
    return 1;
}

/* a "name" or "model": 1 to 63 of these bytes (printed into JSON and titles without escaping) */
static int name_byte(unsigned char c)
{
    return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '.' ||
           c == '_' || c == '+' || c == '-';
}

/* index of the first beam whose single-precision radians equal an earlier one's (*j: that one), or -1 */
static int first_same(const double *deg, int n, int *j)
{
    int i, k;
    for (i = 1; i < n; ++i)
    {
        const float r = (float)(deg[i] * DEG2RAD_D);
        for (k = 0; k < i; ++k)
        {
            if ((float)(deg[k] * DEG2RAD_D) == r)
            {
                *j = k;
                return i;
            }
        }
    }
    return -1;
}

static const char *const k_fields[] = {
    "format",     "version",      "name",           "cols",        "rows", "beam_elevation_deg",
    "fov_up_deg", "fov_down_deg", "mount_height_m", "max_range_m", "model"};
#define N_FIELDS (sizeof k_fields / sizeof k_fields[0])
#define KNOWN_FIELDS                                                                                         \
    "format, version, name, cols, rows, beam_elevation_deg, fov_up_deg, fov_down_deg, mount_height_m, "      \
    "max_range_m, model"
#define NAME_RULE "must be 1 to 63 characters from A-Z a-z 0-9 . _ + -"
#define MAX_FILE_BYTES (16L << 20)
#define OUSTER_MAX_RANGE_M 120.0

static const cJSON *get(const cJSON *obj, const char *key)
{
    return cJSON_GetObjectItemCaseSensitive(
        obj, key); /* JSON keys are case-sensitive (cJSON_GetObjectItem is not) */
}

static const char *kind(const cJSON *v)
{
    if (cJSON_IsTrue(v))
        return "true";
    if (cJSON_IsFalse(v))
        return "false";
    if (cJSON_IsNull(v))
        return "null";
    if (cJSON_IsString(v))
        return "a string";
    if (cJSON_IsArray(v))
        return "an array";
    if (cJSON_IsObject(v))
        return "an object";
    return "a number";
}

/* a finite number */
static int number(const cJSON *v, const char *what, double *x, char *err)
{
    if (!cJSON_IsNumber(v))
        return bad(err, "%s: expected a number, got %s", what, kind(v));
    *x = v->valuedouble;
    if (!isfinite(*x))
        return bad(err, "%s: not a finite number", what);
    return 0;
}

/* a number with an integral value in [lo, hi] (macro: the capacity that bounds it, or "") */
static int integer(const cJSON *v, const char *what, double lo, double hi, const char *macro, long *out,
                   char *err)
{
    double x = 0.0;
    if (!cJSON_IsNumber(v))
        return bad(err, "%s: expected an integer, got %s", what, kind(v));
    x = v->valuedouble;
    if (!isfinite(x))
        return bad(err, "%s: not a finite number", what);
    if (x != floor(x))
        return bad(err, "%s: expected an integer, got %g", what, x);
    if (x < lo || x > hi)
        return bad(err, "%s: %g is outside [%.0f, %.0f]%s%s%s", what, x, lo, hi, macro[0] ? " (" : "", macro,
                   macro[0] ? ")" : "");
    *out = (long)x;
    return 0;
}

static int name_value(const cJSON *v, const char *what, char *out, size_t len, char *err)
{
    size_t n, i;
    if (!cJSON_IsString(v))
        return bad(err, "%s: expected a string, got %s", what, kind(v));
    n = strlen(v->valuestring);
    for (i = 0; i < n && name_byte((unsigned char)v->valuestring[i]); ++i)
    {
    }
    if (n < 1 || n > 63 || i < n || n >= len)
        return bad(err, "%s: " NAME_RULE, what);
    memcpy(out, v->valuestring, n + 1);
    return 0;
}

/* a beam table in degrees: 1..LIDET_MAX_ROWS finite numbers in (-90, 90), distinct in single precision radians */
static int elevations(const cJSON *v, const char *what, double *deg, uint16_t *rows, char *err)
{
    const cJSON *e;
    char w[160];
    int n, i = 0, j;
    double x = 0.0;
    if (!cJSON_IsArray(v))
        return bad(err, "%s: expected an array of numbers, got %s", what, kind(v));
    n = cJSON_GetArraySize(v);
    if (n < 1 || n > LIDET_MAX_ROWS)
        return bad(err, "%s: %d beams, outside [1, %d] (LIDET_MAX_ROWS)", what, n, LIDET_MAX_ROWS);
    cJSON_ArrayForEach(e, v)
    {
        snprintf(w, sizeof w, "%s[%d]", what, i);
        if (number(e, w, &x, err) != 0)
            return 1;
        if (!(x > -90.0 && x < 90.0))
            return bad(err, "%s: %g deg is outside (-90, 90)", w, x);
        deg[i++] = x;
    }
    i = first_same(deg, n, &j);
    if (i >= 0)
        return bad(err, "%s[%d]: the same elevation as [%d] (%g deg): beams must be distinct", what, i, j,
                   deg[i]);
    *rows = (uint16_t)n;
    return 0;
}

/* the first key given twice, in the order Python's json reports it (an object after its members' values) */
static const cJSON *first_duplicate(const cJSON *v)
{
    const cJSON *c, *d, *r;
    for (c = v->child; c != NULL; c = c->next)
    {
        r = first_duplicate(c);
        if (r != NULL)
            return r;
    }
    if (cJSON_IsObject(v))
    {
        for (c = v->child; c != NULL; c = c->next)
        {
            for (d = v->child; d != c; d = d->next)
            {
                if (strcmp(d->string, c->string) == 0)
                    return c;
            }
        }
    }
    return NULL;
}

/* reads and parses the file (a JSON object); the caller deletes *root */
static int read_json(const char *path, cJSON **root, char *err)
{
    struct stat st;
    FILE *f;
    char *buf;
    size_t size;
    const char *end = NULL;
    const cJSON *dup;
    *root = NULL;
    if (stat(path, &st) != 0)
        return bad(err, "cannot read: %s", strerror(errno));
    if (!S_ISREG(st.st_mode))
        return bad(err, "cannot read: not a regular file");
    if (st.st_size > MAX_FILE_BYTES)
        return bad(err, "larger than %ld MiB: not a sensor description", MAX_FILE_BYTES >> 20);
    size = (size_t)st.st_size;
    buf = (char *)malloc(size + 1u);
    f = fopen(path, "rb");
    if (buf == NULL || f == NULL || fread(buf, 1, size, f) != size)
    {
        if (f != NULL)
            fclose(f);
        free(buf);
        return bad(err, "cannot read: %s", f == NULL ? strerror(errno) : "read error");
    }
    fclose(f);
    buf[size] = '\0';
    *root = cJSON_ParseWithOpts(buf, &end, 1);
    if (*root == NULL)
    {
        const long at = end != NULL ? (long)(end - buf) : -1L;
        free(buf);
        return bad(err, "not valid JSON (error near byte %ld)", at);
    }
    free(buf);
    dup = first_duplicate(*root);
    if (dup != NULL)
        return bad(err, "\"%s\": given twice", dup->string);
    if (!cJSON_IsObject(*root))
        return bad(err, "the file must hold one JSON object");
    return 0;
}

/* a version-1 lidet sensor description (sensors.py: _description) */
static int read_description(const cJSON *root, cli_sensor_desc_t *d, char *err)
{
    const cJSON *v, *c;
    long n;
    size_t k;
    int table;
    v = get(root, "format");
    if (!cJSON_IsString(v) || strcmp(v->valuestring, "lidet-sensor") != 0)
    {
        const char *hint =
            get(root, "beam_altitude_angles") != NULL || get(root, "beam_intrinsics") != NULL
                ? ": this looks like Ouster metadata, read it with --ouster-meta (load_ouster_metadata)"
                : "";
        return bad(err, "\"format\": %s%s",
                   v == NULL ? "missing (expected \"lidet-sensor\")" : "expected \"lidet-sensor\"", hint);
    }
    v = get(root, "version");
    if (v == NULL)
        return bad(err, "\"version\": missing");
    if (integer(v, "\"version\"", 0.0, 1000000.0, "", &n, err) != 0)
        return 1;
    if (n != 1)
        return bad(err, "\"version\": %ld is not supported (this build reads version 1)", n);
    for (c = root->child; c != NULL; c = c->next)
    {
        for (k = 0; k < N_FIELDS && strcmp(c->string, k_fields[k]) != 0; ++k)
        {
        }
        if (k == N_FIELDS)
            return bad(err, "\"%s\": unknown field (known: " KNOWN_FIELDS ")", c->string);
    }
    if (get(root, "name") == NULL)
        return bad(err, "\"name\": missing");
    if (get(root, "cols") == NULL)
        return bad(err, "\"cols\": missing");
    if (name_value(get(root, "name"), "\"name\"", d->name, sizeof d->name, err) != 0)
        return 1;
    if (integer(get(root, "cols"), "\"cols\"", 8.0, (double)LIDET_MAX_COLS, "LIDET_MAX_COLS", &n, err) != 0)
        return 1;
    d->cols = (uint16_t)n;
    table = get(root, "beam_elevation_deg") != NULL;
    if (table && (get(root, "fov_up_deg") != NULL || get(root, "fov_down_deg") != NULL))
        return bad(err, "\"beam_elevation_deg\": give the beam table or \"fov_up_deg\", \"fov_down_deg\" and "
                        "\"rows\", not both");
    if (table)
    {
        if (elevations(get(root, "beam_elevation_deg"), "\"beam_elevation_deg\"", d->elev_deg, &d->rows,
                       err) != 0)
            return 1;
        v = get(root, "rows");
        if (v != NULL)
        {
            if (integer(v, "\"rows\"", 1.0, (double)LIDET_MAX_ROWS, "LIDET_MAX_ROWS", &n, err) != 0)
                return 1;
            if (n != (long)d->rows)
                return bad(err, "\"rows\": %ld does not match the %u entries of \"beam_elevation_deg\"", n,
                           (unsigned)d->rows);
        }
    }
    else
    {
        static const char *const edges[2] = {"fov_up_deg", "fov_down_deg"};
        double e[2], step;
        int i, j;
        if (get(root, "fov_up_deg") == NULL && get(root, "fov_down_deg") == NULL)
            return bad(
                err,
                "\"beam_elevation_deg\": missing (or give \"fov_up_deg\", \"fov_down_deg\" and \"rows\")");
        for (i = 0; i < 2; ++i)
        {
            if (get(root, edges[i]) == NULL)
                return bad(err, "\"%s\": missing", edges[i]);
        }
        if (get(root, "rows") == NULL)
            return bad(err, "\"rows\": missing (needed with \"fov_up_deg\" and \"fov_down_deg\")");
        for (i = 0; i < 2; ++i)
        {
            char w[32];
            snprintf(w, sizeof w, "\"%s\"", edges[i]);
            if (number(get(root, edges[i]), w, &e[i], err) != 0)
                return 1;
            if (!(e[i] > -90.0 && e[i] < 90.0))
                return bad(err, "%s: %g deg is outside (-90, 90)", w, e[i]);
        }
        if (!(e[0] > e[1]))
            return bad(err, "\"fov_up_deg\": %g deg is not above \"fov_down_deg\" (%g deg)", e[0], e[1]);
        if (integer(get(root, "rows"), "\"rows\"", 1.0, (double)LIDET_MAX_ROWS, "LIDET_MAX_ROWS", &n, err) !=
            0)
            return 1;
        /* the uniform beam centres (sensors.py: uniform_beams, the same operations in double) */
        d->uniform = 1;
        d->fov_up_deg = e[0];
        d->fov_down_deg = e[1];
        d->rows = (uint16_t)n;
        step = (e[0] - e[1]) / (double)n;
        for (i = 0; i < (int)n; ++i)
            d->elev_deg[i] = e[0] - ((double)i + 0.5) * step;
        if (first_same(d->elev_deg, (int)n, &j) >= 0)
            return bad(err,
                       "\"rows\": %ld beams between \"fov_down_deg\" and \"fov_up_deg\" are not distinct in "
                       "single precision",
                       n);
    }
    if (get(root, "mount_height_m") == NULL)
        return bad(err, "\"mount_height_m\": missing");
    if (get(root, "max_range_m") == NULL)
        return bad(err, "\"max_range_m\": missing");
    if (number(get(root, "mount_height_m"), "\"mount_height_m\"", &d->mount_height_m, err) != 0)
        return 1;
    if (!(d->mount_height_m >= 0.0 && d->mount_height_m <= 10.0))
        return bad(err, "\"mount_height_m\": %g is outside [0, 10]", d->mount_height_m);
    if (number(get(root, "max_range_m"), "\"max_range_m\"", &d->max_range_m, err) != 0)
        return 1;
    if (!(d->max_range_m > 0.0 && d->max_range_m <= 1000.0))
        return bad(err, "\"max_range_m\": %g is outside (0, 1000]", d->max_range_m);
    v = get(root, "model");
    if (v != NULL && name_value(v, "\"model\"", d->model, sizeof d->model, err) != 0)
        return 1;
    return 0;
}

/* where a field of Ouster's metadata lives: the first of `secs` holding it, else the top level; *path names it */
static const cJSON *find(const cJSON *root, const char *const *secs, int n_secs, const char *key, char *path,
                         size_t len)
{
    const cJSON *v;
    int i;
    for (i = 0; i < n_secs; ++i)
    {
        const cJSON *s = get(root, secs[i]);
        v = s != NULL ? get(s, key) : NULL;
        if (v != NULL)
        {
            snprintf(path, len, "\"%s.%s\"", secs[i], key);
            return v;
        }
    }
    v = get(root, key);
    snprintf(path, len, "\"%s\"", key);
    return v;
}

/* "<columns>x<rate>": 1-5 digits, 'x', 1-3 digits; the columns, or -1 */
static long mode_columns(const char *s)
{
    long cols = 0;
    int nd = 0, nr = 0;
    while (s[nd] >= '0' && s[nd] <= '9' && nd < 6)
    {
        cols = cols * 10 + (s[nd] - '0');
        ++nd;
    }
    if (nd < 1 || nd > 5 || s[nd] != 'x')
        return -1;
    s += nd + 1;
    while (s[nr] >= '0' && s[nr] <= '9' && nr < 4)
        ++nr;
    return nr >= 1 && nr <= 3 && s[nr] == '\0' ? cols : -1;
}

/* Ouster's sensor metadata (sensors.py: _ouster) */
static int read_ouster(const cJSON *root, cli_sensor_desc_t *d, char *err)
{
    static const char *const k_secs[] = {"beam_intrinsics", "lidar_data_format", "data_format",
                                         "config_params", "sensor_info"};
    static const char *const beam[] = {"beam_intrinsics"};
    static const char *const fmt[] = {"lidar_data_format", "data_format"};
    static const char *const cfg[] = {"config_params"};
    static const char *const info[] = {"sensor_info"};
    char alt_f[96], f[96], cpf_f[96], mode_f[96];
    const cJSON *v, *cpf, *mode;
    long n, cols = -1, mcols = -1;
    int i;
    v = get(root, "format");
    if (cJSON_IsString(v) && strcmp(v->valuestring, "lidet-sensor") == 0)
        return bad(
            err,
            "\"format\": this is a lidet sensor description, read it with --sensor-file (load_sensor_file)");
    if (get(root, "packet_hash") != NULL)
        return bad(
            err,
            "\"packet_hash\": this is an ouster-sdk packet digest (hashes of decoded fields), not sensor "
            "metadata");
    for (i = 0; i < (int)(sizeof k_secs / sizeof k_secs[0]); ++i)
    {
        v = get(root, k_secs[i]);
        if (v != NULL && !cJSON_IsObject(v))
            return bad(err, "\"%s\": expected an object, got %s", k_secs[i], kind(v));
    }
    v = find(root, beam, 1, "beam_altitude_angles", alt_f, sizeof alt_f);
    if (v == NULL)
        return bad(err,
                   "\"beam_altitude_angles\": missing (neither in \"beam_intrinsics\" nor at the top level): "
                   "not Ouster sensor metadata?");
    if (elevations(v, alt_f, d->elev_deg, &d->rows, err) != 0)
        return 1;
    v = find(root, beam, 1, "beam_azimuth_angles", f, sizeof f);
    if (v != NULL) /* read and validated; the Ouster decoder takes them (cli_ouster_format), the projection not */
    {
        const cJSON *e;
        char w[128];
        double x = 0.0;
        if (!cJSON_IsArray(v))
            return bad(err, "%s: expected an array of numbers, got %s", f, kind(v));
        if (cJSON_GetArraySize(v) != (int)d->rows)
            return bad(err, "%s: %d entries for %u beams", f, cJSON_GetArraySize(v), (unsigned)d->rows);
        i = 0;
        cJSON_ArrayForEach(e, v)
        {
            snprintf(w, sizeof w, "%s[%d]", f, i++);
            if (number(e, w, &x, err) != 0)
                return 1;
            if (!(x > -180.0 && x < 180.0))
                return bad(err, "%s: %g deg is outside (-180, 180)", w, x);
        }
    }
    v = find(root, fmt, 2, "pixels_per_column", f, sizeof f);
    if (v != NULL)
    {
        if (integer(v, f, 1.0, 65535.0, "", &n, err) != 0)
            return 1;
        if (n != (long)d->rows)
            return bad(err, "%s: %ld but %s has %u entries", f, n, alt_f, (unsigned)d->rows);
    }
    cpf = find(root, fmt, 2, "columns_per_frame", cpf_f, sizeof cpf_f);
    mode = find(root, cfg, 1, "lidar_mode", mode_f, sizeof mode_f);
    if (cpf != NULL && integer(cpf, cpf_f, 8.0, (double)LIDET_MAX_COLS, "LIDET_MAX_COLS", &cols, err) != 0)
        return 1;
    if (mode != NULL)
    {
        mcols = cJSON_IsString(mode) ? mode_columns(mode->valuestring) : -1;
        if (mcols < 0)
            return bad(err, "%s: expected \"<columns>x<rate>\" such as \"1024x10\"", mode_f);
    }
    if (cpf == NULL && mode == NULL)
        return bad(err, "\"lidar_mode\": missing (and no \"columns_per_frame\")");
    if (cpf != NULL && mode != NULL && cols != mcols)
        return bad(err, "%s: %ld columns, but %s is %ld", mode_f, mcols, cpf_f, cols);
    if (cpf == NULL)
    {
        if (mcols < 8 || mcols > LIDET_MAX_COLS)
            return bad(err, "%s: %ld columns, outside [8, %d] (LIDET_MAX_COLS)", mode_f, mcols,
                       LIDET_MAX_COLS);
        cols = mcols;
    }
    d->cols = (uint16_t)cols;
    v = find(root, beam, 1, "lidar_origin_to_beam_origin_mm", f, sizeof f);
    if (v != NULL) /* read and validated, not used (docs/SENSORS.md) */
    {
        double x = 0.0;
        if (number(v, f, &x, err) != 0)
            return 1;
    }
    snprintf(d->name, sizeof d->name, "ouster-%u", (unsigned)d->rows);
    v = find(root, info, 1, "prod_line", f, sizeof f);
    if (v != NULL)
    {
        /* the product line in lower case, other bytes as '-', at most 63 (sensors.py: _ouster_name) */
        size_t k;
        if (!cJSON_IsString(v))
            return bad(err, "%s: expected a string, got %s", f, kind(v));
        for (k = 0; k < 63 && v->valuestring[k] != '\0'; ++k)
        {
            unsigned char c = (unsigned char)v->valuestring[k];
            c = (unsigned char)(c >= 'A' && c <= 'Z' ? c + 32 : c);
            d->name[k] = (char)(name_byte(c) ? c : '-');
        }
        if (k > 0)
            d->name[k] = '\0';
        else
            snprintf(d->name, sizeof d->name, "ouster-%u", (unsigned)d->rows);
    }
    d->mount_height_m = 1.0; /* not in Ouster's file: --mount-height overrides it */
    d->max_range_m = OUSTER_MAX_RANGE_M;
    return 0;
}

int cli_sensor_load(cli_args_t *a, const char *cmd)
{
    const char *path = a->sensor_file != NULL ? a->sensor_file : a->ouster_meta;
    char err[ERR_LEN];
    cJSON *root;
    int rc;
    memset(&a->desc, 0, sizeof a->desc);
    err[0] = '\0';
    rc = read_json(path, &root, err);
    if (rc == 0)
        rc =
            a->sensor_file != NULL ? read_description(root, &a->desc, err) : read_ouster(root, &a->desc, err);
    cJSON_Delete(root);
    if (rc != 0)
    {
        fprintf(stderr, "lidet %s: %s: %s\n", cmd, path, err);
        return 1;
    }
    cli_sensor_use_desc(a);
    return 0;
}

/* ---- the packet format of Ouster's metadata (lidet detect / track --pcap --lidar ouster; ouster.py: load_metadata) */

static const char *const k_profiles[] = {"LEGACY", "RNG19_RFL8_SIG16_NIR16_DUAL", "RNG19_RFL8_SIG16_NIR16",
                                         "RNG15_RFL8_NIR8"};

/* a string field that must be one of names (absent, null or "": dflt); its index, or -1 with the message */
static int one_of(const cJSON *v, const char *what, const char *const *names, int n, int dflt, char *err)
{
    int i;
    if (v == NULL || cJSON_IsNull(v) || (cJSON_IsString(v) && v->valuestring[0] == '\0'))
        return dflt;
    if (!cJSON_IsString(v))
        return bad(err, "%s: expected a string, got %s", what, kind(v)) - 2;
    for (i = 0; i < n; ++i)
        if (strcmp(v->valuestring, names[i]) == 0)
            return i;
    return bad(err, "%s: '%s' is not decoded", what, v->valuestring) - 2;
}

static int read_ouster_format(const cJSON *root, const cli_sensor_desc_t *d, cli_ouster_fmt_t *o, char *err)
{
    static const char *const headers[] = {"STANDARD", "FUSA"};
    static const char *const beam[] = {"beam_intrinsics"};
    static const char *const fmt[] = {"lidar_data_format", "data_format"};
    static const char *const fmt_cfg[] = {"lidar_data_format", "data_format", "config_params"};
    static const char *const cfg[] = {"config_params"};
    static const char *const info[] = {"sensor_info"};
    static const char *const intr[] = {"lidar_intrinsics"};
    char f[96];
    const cJSON *v;
    long n;
    int i;
    memset(o, 0, sizeof *o);
    i = one_of(find(root, fmt_cfg, 3, "udp_profile_lidar", f, sizeof f), f, k_profiles, 4, 0, err);
    if (i < 0)
        return 1;
    o->profile = i + 1; /* lidet_ouster_profile_t: LEGACY 1 .. RNG15_RFL8_NIR8 4 */
    o->columns_per_packet = 16;
    v = find(root, fmt, 2, "columns_per_packet", f, sizeof f);
    if (v != NULL && !cJSON_IsNull(v))
    {
        if (integer(v, f, 1.0, 16.0, "", &n, err) != 0)
            return 1;
        o->columns_per_packet = (uint16_t)n;
    }
    i = one_of(find(root, fmt_cfg, 3, "header_type", f, sizeof f), f, headers, 2, 0, err);
    if (i < 0)
        return 1;
    o->header = i;
    v = find(root, beam, 1, "beam_azimuth_angles", f, sizeof f);
    if (v != NULL) /* validated by read_ouster: an array of rows numbers in (-180, 180) */
    {
        const cJSON *e;
        i = 0;
        cJSON_ArrayForEach(e, v)
        {
            if (i < (int)d->rows && i < LIDET_MAX_ROWS)
                o->beam_azimuth_mdeg[i] = (int32_t)floor(e->valuedouble * 1000.0 + 0.5);
            ++i;
        }
    }
    o->azimuth_offset_bam = 32768u; /* ouster-sdk's default lidar_to_sensor_transform: half a turn about z */
    v = find(root, intr, 1, "lidar_to_sensor_transform", f, sizeof f);
    if (v != NULL && !cJSON_IsNull(v))
    {
        double m[16], yaw;
        const cJSON *e;
        if (!cJSON_IsArray(v) || cJSON_GetArraySize(v) != 16)
            return bad(err, "%s: expected 16 finite numbers (a 4 x 4 matrix)", f);
        i = 0;
        cJSON_ArrayForEach(e, v)
        {
            if (number(e, f, &m[i++], err) != 0)
                return 1;
        }
        if (fabs(m[8]) > 1e-6 || fabs(m[9]) > 1e-6 || fabs(m[10] - 1.0) > 1e-6 || fabs(m[2]) > 1e-6 ||
            fabs(m[6]) > 1e-6)
            return bad(err, "%s: not a turn about z: the decoder's azimuth cannot say it", f);
        yaw = atan2(m[4], m[0]);
        o->azimuth_offset_bam = (uint16_t)((long)floor(yaw / (2.0 * M_PI_D) * 65536.0 + 0.5) & 0xFFFF);
    }
    v = find(root, info, 1, "initialization_id", f, sizeof f);
    if (cJSON_IsNumber(v) && v->valuedouble >= 0.0 && v->valuedouble < 16777216.0)
        o->init_id = (uint32_t)v->valuedouble;
    v = find(root, info, 1, "prod_sn", f, sizeof f);
    if (cJSON_IsNumber(v) && v->valuedouble >= 0.0 && v->valuedouble < 1099511627776.0)
        o->prod_sn = (uint64_t)v->valuedouble;
    else if (cJSON_IsString(v))
    {
        char *end;
        const unsigned long long sn = strtoull(v->valuestring, &end, 10);
        if (end != v->valuestring && *end == '\0' && sn < 1099511627776ULL)
            o->prod_sn = (uint64_t)sn;
    }
    o->udp_port_lidar = 7502u;
    v = find(root, cfg, 1, "udp_port_lidar", f, sizeof f);
    if (v != NULL && !cJSON_IsNull(v) && !(cJSON_IsNumber(v) && v->valuedouble == 0.0))
    {
        if (integer(v, f, 1.0, 65535.0, "", &n, err) != 0)
            return 1;
        o->udp_port_lidar = (uint32_t)n;
    }
    return 0;
}

int cli_ouster_format(const cli_args_t *a, cli_ouster_fmt_t *o)
{
    char err[ERR_LEN];
    cJSON *root;
    int rc;
    err[0] = '\0';
    rc = read_json(a->ouster_meta, &root, err);
    if (rc == 0)
        rc = read_ouster_format(root, &a->desc, o, err);
    cJSON_Delete(root);
    if (rc != 0)
        fprintf(stderr, "lidet %s: %s: %s\n", cli_cmd, a->ouster_meta, err);
    return rc;
}

#else /* built without cJSON */

int cli_sensor_load(cli_args_t *a, const char *cmd)
{
    fprintf(
        stderr,
        "lidet %s: %s needs cJSON, and this lidet was built without it (apt-get install libcjson-dev, then "
        "reconfigure and rebuild)\n",
        cmd, a->sensor_file != NULL ? "--sensor-file" : "--ouster-meta");
    return 1;
}

int cli_ouster_format(const cli_args_t *a, cli_ouster_fmt_t *o)
{
    (void)a;
    memset(o, 0, sizeof *o);
    fprintf(stderr, "lidet %s: --ouster-meta needs cJSON, and this lidet was built without it\n", cli_cmd);
    return 1;
}

#endif

/* ---- --print-sensor ------------------------------------------------------------------------------------ */

/* the shortest of %.15g .. %.17g that reads back as v */
static void put_double(FILE *f, double v)
{
    char buf[40];
    int p;
    for (p = 15; p <= 17; ++p)
    {
        snprintf(buf, sizeof buf, "%.*g", p, v);
        if (strtod(buf, NULL) == v)
            break;
    }
    fputs(buf, f);
}

/* a single-precision value, shortest that reads back as it */
static void put_float(FILE *f, float v)
{
    char buf[40];
    int p;
    for (p = 6; p <= 9; ++p)
    {
        snprintf(buf, sizeof buf, "%.*g", p, (double)v);
        if ((float)strtod(buf, NULL) == v)
            break;
    }
    fputs(buf, f);
}

/* a preset's angle (single-precision radians) in degrees, shortest that a description turns back into it */
static void put_deg_of(FILE *f, float rad)
{
    char buf[40];
    int p;
    for (p = 6; p <= 17; ++p)
    {
        snprintf(buf, sizeof buf, "%.*g", p, (double)rad / DEG2RAD_D);
        if ((float)(strtod(buf, NULL) * DEG2RAD_D) == rad)
            break;
    }
    fputs(buf, f);
}

void cli_sensor_print(const cli_args_t *a, FILE *f)
{
    const lidet_sensor_t *s = a->sensor_profile;
    const int from_file = a->family != NULL;
    const int uniform = from_file ? a->desc.uniform : s->beam_elev_rad == NULL;
    uint16_t i;
    fprintf(f,
            "{\n  \"format\": \"lidet-sensor\",\n  \"version\": 1,\n  \"name\": \"%s\",\n  \"cols\": %u,\n",
            from_file ? a->desc.name : s->name, (unsigned)s->n_cols);
    if (uniform)
    {
        fputs("  \"fov_up_deg\": ", f);
        from_file ? put_double(f, a->desc.fov_up_deg) : put_deg_of(f, s->fov_up_rad);
        fputs(",\n  \"fov_down_deg\": ", f);
        from_file ? put_double(f, a->desc.fov_down_deg) : put_deg_of(f, s->fov_down_rad);
        fprintf(f, ",\n  \"rows\": %u,\n", (unsigned)s->n_rows);
    }
    else
    {
        fputs("  \"beam_elevation_deg\": [", f);
        for (i = 0; i < s->n_rows; ++i)
        {
            fputs(i == 0 ? "" : i % 8 == 0 ? ",\n    " : ", ", f);
            from_file ? put_double(f, a->desc.elev_deg[i]) : put_deg_of(f, s->beam_elev_rad[i]);
        }
        fputs("],\n", f);
    }
    fputs("  \"mount_height_m\": ", f);
    from_file ? put_double(f, a->desc.mount_height_m) : put_float(f, s->mount_height_m);
    fputs(",\n  \"max_range_m\": ", f);
    from_file ? put_double(f, a->desc.max_range_m) : put_float(f, s->max_range_m);
    if (from_file && a->desc.model[0] != '\0')
        fprintf(f, ",\n  \"model\": \"%s\"", a->desc.model);
    fputs("\n}\n", f);
}
