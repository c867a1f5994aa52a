/* SPDX-License-Identifier: MIT */
/* `lidet track`: the detector and the tracker (docs/TRACKING.md) over a sequence of scans. Each scan goes through
 * the detector exactly as `lidet detect` runs it (float, or the integer detector with --fixed: cli_detect.c,
 * cli_detect_q.c), then through lidet_tracker_update (--fixed: lidet_tracker_q_update, with dt in ms and the ego
 * motion in mm and BAM32, converted here once, rounded half away from zero as lidet_ref.track_q does).
 * Outputs: track lines (stdout, --out DIR/<stem>.txt), lidet-eval track's prediction files (--out
 * DIR/tracks/<stem>.txt), KITTI tracking labels in the camera frame (--out DIR/label_02.txt, with a calibration),
 * one JSON object per scan (--json) and a bird's-eye view after the last scan with each track's tail, box and
 * velocity (--png). */
#include <dirent.h>
#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "cli.h"
#include "cli_font.h"

/* the tails of the picture: the last TAIL_LEN centres of up to TAIL_SLOTS tracks; a tail whose track was not
 * output for TAIL_STALE scans is dropped (and the stalest one when a new track needs a slot) */
#define TAIL_LEN 128
#define TAIL_SLOTS (2 * LIDET_TRACK_MAX_TRACKS)
#define TAIL_STALE 10
/* the picture's scene: as lidet detect's, 80 m x 80 m (--png-range M: 2 M x 2 M) */
#define BEV_W 800u
#define BEV_H 800u
#define BEV_RES CLI_PNG_RES(BEV_W)
/* the longest line of an --ego / --dt-file file */
#define LINE_MAX_CHARS 1024
/* dt of a scan, seconds: the float tracker takes (0, 10], the integer one [1, 10000] ms */
#define DT_MIN_S 0.001
#define DT_MAX_S 10.0
/* the ego translation per scan, metres (the float tracker's limit; the integer one's is 1048 m) */
#define EGO_MAX_M 1000.0

static const double k_bam_per_rad = 4294967296.0 / (2.0 * M_PI_D);

typedef struct
{
    uint32_t id;
    uint32_t last_seen; /* scan index of its last centre */
    uint32_t n, head;   /* centres held; the next write position (a ring of TAIL_LEN) */
    uint8_t used;
    float x[TAIL_LEN], y[TAIL_LEN];
} tail_t;

static lidet_tracker_t g_trk;
static lidet_tracker_q_t g_trkq;
static lidet_track_t g_out[LIDET_TRACK_MAX_TRACKS];
static lidet_track_q_t g_outq[LIDET_TRACK_MAX_TRACKS];
static lidet_detection_t g_det_q[LIDET_MAX_DETECTIONS];
static tail_t g_tail[TAIL_SLOTS];

static const char *const k_state_names[3] = {"tentative", "confirmed", "coasting"};

static void usage(void)
{
    fprintf(
        stderr,
        "usage: lidet track SCANS... | DIR | --pcap FILE [--sensor NAME | --sensor-file F | --ouster-meta M |\n"
        "                   --velodyne-calib C [--cols N]] [--mount-height M]\n"
        "                   [--model NAME] [--crop] [--fixed] [--set KEY=VALUE] [--rate HZ | --dt-file F]\n"
        "                   [--ego FILE | --ego none] [--calib FILE] [--out DIR] [--png FILE] [--json]\n"
        "                   [--coasting] [--tentative]\n"
        "  Each scan, in order, through the detector (as lidet detect; --fixed: lidet detect --fixed), then "
        "the\n"
        "  tracker (lidet_tracker_update; --fixed: the integer lidet_tracker_q_update, dt in ms and the ego "
        "motion\n"
        "  in mm and BAM32, rounded half away from zero). docs/TRACKING.md, \"lidet track\".\n"
        "  SCANS      KITTI velodyne scans (float32 x, y, z, remission), tracked in the order given\n"
        "  DIR        a folder with velodyne/*.bin (else *.bin), sorted by name; its poses.txt, when there "
        "is\n"
        "             one, is the ego motion (as --ego DIR/poses.txt) unless --ego is given\n"
        "  --rate HZ  the scan rate, [0.1, 1000] Hz: dt = 1 / HZ (default 10, or the t column of a "
        "poses.txt)\n"
        "  --dt-file F  one dt per scan in seconds, [0.001, 10], one a line ('#' comments); the first line "
        "is\n"
        "             the first scan's and is ignored\n"
        "  --ego FILE the sensor's motion from the previous scan to this one, in the previous scan's sensor\n"
        "             frame, one line per scan (the first line is the first scan's and is ignored):\n"
        "             'dx dy dyaw' (m, m, rad), or the 8 columns of lidet-sim --sequence's poses.txt,\n"
        "             'frame t x y yaw dx dy dyaw': dx dy dyaw read from columns 6-8 and, without --rate "
        "and\n"
        "             --dt-file, dt from the differences of t; |dx|, |dy| <= 1000 m, |dyaw| <= pi; lines "
        "past\n"
        "             the last scan ignored. --ego none: no ego motion (DIR/poses.txt not read)\n"
        "  --calib FILE  a KITTI calibration for every scan (label_02.txt). Default: SCAN_FOLDER/../calib/\n"
        "             <stem>.txt when it exists for every scan, else the one .txt file of that calib/ (a\n"
        "             sequence's, as lidet-sim --sequence and KITTI tracking have it); none: no "
        "label_02.txt\n"
        "  --out DIR  per scan DIR/<stem>.txt (the track lines below) and DIR/tracks/<stem>.txt (lidet-eval\n"
        "             track's predictions: 'id class x y z l w h yaw vx vy score'), and, with a "
        "calibration,\n"
        "             DIR/label_02.txt: KITTI tracking lines 'frame id type 0 0 alpha x1 y1 x2 y2 h w l x y "
        "z\n"
        "             rotation_y score' (camera frame, as lidet detect --kitti-out; boxes behind the camera "
        "left\n"
        "             out). DIR is made if missing\n"
        "  --png FILE a bird's-eye view after the last scan: its points (as lidet detect --png), each "
        "output\n"
        "             track's tail (its last %d centres, moved with the ego motion), box and id in the "
        "track's\n"
        "             colour, and its velocity as an arrow of 1 s of motion; 40 m each way around the\n"
        "             sensor (--png-range M: M metres, in [5, 200])\n"
        "  --json     one JSON object per scan instead of the lines: frame, scan, points, detections, "
        "statuses,\n"
        "             detect_ms, track_ms, the tracker's stats and the tracks with every field (state, "
        "velocity\n"
        "             covariance p_pp p_pv p_vv per axis, hits, misses, age, det: this scan's detection)\n"
        "  --coasting also the confirmed tracks that missed this scan; --tentative: also the tentative ones\n"
        "  Output (stdout): per scan one line '# frame F SCAN: D detections, T tracks (...)', then per "
        "track\n"
        "    'frame id class x y z l w h yaw vx vy score hits': the scan's sensor frame (box centre, size in "
        "m,\n"
        "    yaw in rad), the velocity over the ground in m/s, the last detection's score, the track's "
        "hits;\n"
        "    frame: the scan's number when its name (stem) is digits, else its index from 0\n"
        "  Options go before, between or after the scans, as --name VALUE or --name=VALUE; -- ends them.\n"
        "  --sensor, --sensor-file, --ouster-meta, --velodyne-calib, --cols, --mount-height, --print-sensor: as\n"
        "  lidet detect\n"
        "  (lidet detect --help). The detector's options, as lidet detect:\n",
        TAIL_LEN);
    cli_det_usage(stderr);
    fprintf(stderr,
            "  lidet track --pcap FILE [options]: the complete rotations of a packet capture, in order, as the\n"
            "  scans (named FILE#K, frame K, --out DIR/<K:06d>.txt); dt from the scans' first packets' sensor\n"
            "  timestamps (Velodyne: the payload's microseconds, unwrapped at the hour; clamped to [0.001, 10] s)\n"
            "  unless --rate or --dt-file; no ego motion unless --ego FILE (a line per scan); no calibration\n"
            "  unless --calib:\n");
    cli_pcap_usage(stderr, 0);
}

/* ---- small helpers ----------------------------------------------------------------------------------------- */

static char *str_cat3(const char *a, const char *b, const char *c)
{
    const size_t la = strlen(a), lb = strlen(b), lc = strlen(c);
    char *s = (char *)malloc(la + lb + lc + 1u);
    if (s == NULL)
        return NULL;
    memcpy(s, a, la);
    memcpy(s + la, b, lb);
    memcpy(s + la + lb, c, lc + 1u);
    return s;
}

/* the folder of a path ("." when it has none), allocated */
static char *folder_of(const char *path)
{
    const char *s = strrchr(path, '/');
    char *f;
    if (s == NULL)
        return str_cat3(".", "", "");
    if (s == path)
        return str_cat3("/", "", "");
    f = (char *)malloc((size_t)(s - path) + 1u);
    if (f == NULL)
        return NULL;
    memcpy(f, path, (size_t)(s - path));
    f[s - path] = '\0';
    return f;
}

/* the file name without its extension, allocated */
static char *stem_of(const char *path)
{
    const char *b = cli_basename(path), *dot = strrchr(b, '.');
    const size_t n = dot != NULL && dot != b ? (size_t)(dot - b) : strlen(b);
    char *s = (char *)malloc(n + 1u);
    if (s == NULL)
        return NULL;
    memcpy(s, b, n);
    s[n] = '\0';
    return s;
}

static int is_dir(const char *path)
{
    struct stat st;
    return stat(path, &st) == 0 && S_ISDIR(st.st_mode);
}

static int is_file(const char *path)
{
    struct stat st;
    return stat(path, &st) == 0 && S_ISREG(st.st_mode);
}

static int ends_with(const char *s, const char *suffix)
{
    const size_t n = strlen(s), m = strlen(suffix);
    return n >= m && strcmp(s + n - m, suffix) == 0;
}

static int cmp_str(const void *a, const void *b)
{
    return strcmp(*(const char *const *)a, *(const char *const *)b);
}

/* rounded half away from zero (|v| < 2^62) */
static int64_t rha(double v)
{
    return (int64_t)(v >= 0.0 ? floor(v + 0.5) : -floor(-v + 0.5));
}

/* a string as a JSON string (quotes, backslashes and control characters escaped) */
static void json_string(FILE *f, const char *s)
{
    fputc('"', f);
    for (; *s != '\0'; ++s)
    {
        const unsigned char c = (unsigned char)*s;
        if (c == '"' || c == '\\')
            fprintf(f, "\\%c", c);
        else if (c < 0x20)
            fprintf(f, "\\u%04x", c);
        else
            fputc(c, f);
    }
    fputc('"', f);
}

/* ---- the scans ----------------------------------------------------------------------------------------------- */

/* the *.bin files of a folder, sorted by name, appended to *list (*n of them, *cap allocated): 0, or 1 */
static int list_bins(const char *dir, char ***list, uint32_t *n, uint32_t *cap)
{
    DIR *d = opendir(dir);
    struct dirent *e;
    uint32_t first = *n;
    if (d == NULL)
    {
        fprintf(stderr, "lidet track: cannot open the folder '%s': %s\n", dir, strerror(errno));
        return 1;
    }
    while ((e = readdir(d)) != NULL)
    {
        char *p;
        if (e->d_name[0] == '.' || !ends_with(e->d_name, ".bin"))
            continue;
        if (*n == *cap)
        {
            char **t;
            *cap = *cap ? 2u * *cap : 64u;
            t = (char **)realloc(*list, sizeof(char *) * *cap);
            if (t == NULL)
            {
                closedir(d);
                return 1;
            }
            *list = t;
        }
        p = str_cat3(dir, "/", e->d_name);
        if (p == NULL)
        {
            closedir(d);
            return 1;
        }
        (*list)[(*n)++] = p;
    }
    closedir(d);
    if (*n > first) /* an empty folder: *list may still be NULL, which qsort must not get */
        qsort(*list + first, *n - first, sizeof(char *), cmp_str);
    return 0;
}

/* a scan that cannot be read whole: the message cli_load gives, before any scan is run */
static int check_scan(const char *path)
{
    struct stat st;
    if (stat(path, &st) != 0)
    {
        fprintf(stderr, "lidet: cannot open scan '%s': %s\n", path, strerror(errno));
        return 1;
    }
    if (!S_ISREG(st.st_mode))
    {
        fprintf(stderr, "lidet: scan '%s' is not a regular file\n", path);
        return 1;
    }
    if ((size_t)st.st_size % 16u != 0)
    {
        fprintf(
            stderr,
            "lidet: scan '%s' has %lld bytes, not a multiple of 16: truncated or not a KITTI-format file\n",
            path, (long long)st.st_size);
        return 1;
    }
    return 0;
}

/* ---- --ego, --dt-file ------------------------------------------------------------------------------------------ */

/* Reads the numbers of each line of a text file ('#' starts a comment, blank lines skipped) into rows of ncol
 * values (every line must have ncol of them, or, when ncol is 0, the count of the first line: 3 or 8 for an ego
 * file), for the first n_rows lines; 0, or 1 with a message (missing, unreadable, a bad number, a short file). */
static int read_rows(const char *path, const char *what, uint32_t n_rows, int *ncol, double *rows, int ego)
{
    FILE *f = fopen(path, "r");
    char line[LINE_MAX_CHARS + 2];
    uint32_t got = 0, extra = 0;
    int ln = 0;
    if (f == NULL)
    {
        fprintf(stderr, "lidet track: cannot open the %s '%s': %s\n", what, path, strerror(errno));
        return 1;
    }
    while (fgets(line, sizeof line, f) != NULL)
    {
        const size_t len = strlen(line);
        char *p = line, *hash;
        double v[9];
        int n = 0;
        ++ln;
        if (len > LINE_MAX_CHARS && line[len - 1] != '\n')
        {
            fprintf(stderr, "lidet track: %s:%d: line longer than %d characters\n", path, ln, LINE_MAX_CHARS);
            fclose(f);
            return 1;
        }
        hash = strchr(line, '#');
        if (hash != NULL)
            *hash = '\0';
        for (;;)
        {
            char *end;
            double x;
            while (*p == ' ' || *p == '\t' || *p == '\r' || *p == '\n')
                ++p;
            if (*p == '\0')
                break;
            x = strtod(p, &end);
            if (end == p || (*end != '\0' && *end != ' ' && *end != '\t' && *end != '\r' && *end != '\n') ||
                !isfinite(x))
            {
                fprintf(stderr, "lidet track: %s:%d: '%.*s' is not a finite number\n", path, ln,
                        (int)strcspn(p, " \t\r\n"), p);
                fclose(f);
                return 1;
            }
            if (n == 9)
            {
                n = 10; /* too many: reported below */
                break;
            }
            v[n++] = x;
            p = end;
        }
        if (n == 0)
            continue;
        if (*ncol == 0)
            *ncol = n;
        if (n != *ncol || (ego && n != 3 && n != 8))
        {
            if (ego)
                fprintf(stderr,
                        "lidet track: %s:%d: expected 'dx dy dyaw' (3 numbers) or poses.txt's 'frame t x y "
                        "yaw dx dy "
                        "dyaw' (8) on every line, got %d%s\n",
                        path, ln, n > 9 ? 10 : n, n > 9 ? " or more" : "");
            else
                fprintf(stderr, "lidet track: %s:%d: expected one dt in seconds, got %d numbers\n", path, ln,
                        n);
            fclose(f);
            return 1;
        }
        if (got < n_rows)
            memcpy(rows + (size_t)got++ * (size_t)n, v, sizeof(double) * (size_t)n);
        else
            ++extra;
    }
    if (ferror(f))
    {
        fprintf(stderr, "lidet track: cannot read the %s '%s'\n", what, path);
        fclose(f);
        return 1;
    }
    fclose(f);
    if (got < n_rows)
    {
        fprintf(stderr,
                "lidet track: the %s '%s' has %u lines for %u scans (one a scan, the first one's included)\n",
                what, path, got, n_rows);
        return 1;
    }
    if (extra > 0)
        fprintf(stderr, "lidet track: note: the %s '%s' has %u lines past the last scan: ignored\n", what,
                path, extra);
    return 0;
}

/* --ego FILE: ego[3 k] = dx, dy, dyaw of scan k; t_dt: with poses.txt's 8 columns, dt of scan k (k >= 1) from the
 * t column, else t_dt[0] = -1 */
static int read_ego(const char *path, uint32_t n_scans, double *ego, double *t_dt)
{
    int ncol = 0;
    uint32_t k;
    double *rows = (double *)malloc(sizeof(double) * 8u * (size_t)n_scans);
    if (rows == NULL)
        return 1;
    if (read_rows(path, "ego motion file", n_scans, &ncol, rows, 1) != 0)
    {
        free(rows);
        return 1;
    }
    t_dt[0] = -1.0;
    for (k = 0; k < n_scans; ++k)
    {
        const double *r = rows + (size_t)k * (size_t)ncol + (ncol == 8 ? 5u : 0u);
        if (!(fabs(r[0]) <= EGO_MAX_M && fabs(r[1]) <= EGO_MAX_M && fabs(r[2]) <= M_PI_D))
        {
            fprintf(stderr,
                    "lidet track: %s: scan %u's ego motion (%g, %g, %g) is out of range (|dx|, |dy| <= %g m, "
                    "|dyaw| <= "
                    "pi)\n",
                    path, k, r[0], r[1], r[2], EGO_MAX_M);
            free(rows);
            return 1;
        }
        memcpy(ego + 3u * (size_t)k, r, 3u * sizeof(double));
        if (ncol == 8 && k > 0)
        {
            const double dt = rows[(size_t)k * 8u + 1u] - rows[(size_t)(k - 1u) * 8u + 1u];
            if (!(dt >= DT_MIN_S && dt <= DT_MAX_S))
            {
                fprintf(stderr,
                        "lidet track: %s: t goes from %g to %g s at scan %u: dt must be in [%g, %g] s (or "
                        "give --rate "
                        "/ --dt-file)\n",
                        path, rows[(size_t)(k - 1u) * 8u + 1u], rows[(size_t)k * 8u + 1u], k, DT_MIN_S,
                        DT_MAX_S);
                free(rows);
                return 1;
            }
            t_dt[k] = dt;
        }
    }
    if (ncol == 8)
        t_dt[0] = 0.0;
    free(rows);
    return 0;
}

static int read_dt(const char *path, uint32_t n_scans, double *dt)
{
    int ncol = 1;
    uint32_t k;
    if (read_rows(path, "dt file", n_scans, &ncol, dt, 0) != 0)
        return 1;
    for (k = 1; k < n_scans; ++k)
    {
        if (!(dt[k] >= DT_MIN_S && dt[k] <= DT_MAX_S))
        {
            fprintf(stderr, "lidet track: %s: scan %u's dt %g s is outside [%g, %g] s\n", path, k, dt[k],
                    DT_MIN_S, DT_MAX_S);
            return 1;
        }
    }
    return 0;
}

/* ---- calibration (label_02.txt) ------------------------------------------------------------------------------- */

/* the one .txt file of a folder, allocated; NULL when there are none or several */
static char *only_txt(const char *dir)
{
    DIR *d = opendir(dir);
    struct dirent *e;
    char *found = NULL;
    int n = 0;
    if (d == NULL)
        return NULL;
    while ((e = readdir(d)) != NULL)
    {
        if (e->d_name[0] == '.' || !ends_with(e->d_name, ".txt"))
            continue;
        if (++n == 1)
            found = str_cat3(dir, "/", e->d_name);
    }
    closedir(d);
    if (n != 1 || (found != NULL && !is_file(found)))
    {
        free(found);
        return NULL;
    }
    return found;
}

/* Where each scan's calibration is: calib_paths[k] (all set) or one_calib (every scan); neither: none (a message
 * why on stderr). 0, or 1 when out of memory. */
static int find_calibs(char **scans, char **stems, uint32_t n, char ***calib_paths, char **one_calib)
{
    char **cp = (char **)calloc(n + 1u, sizeof(char *));
    char *common = NULL;
    uint32_t k;
    int all = 1, same = 1;
    *calib_paths = NULL;
    *one_calib = NULL;
    if (cp == NULL)
        return 1;
    for (k = 0; k < n; ++k)
    {
        char *folder = folder_of(scans[k]), *cal_dir, *p;
        if (folder == NULL)
            goto oom;
        cal_dir = str_cat3(folder, "/../calib", "");
        free(folder);
        if (cal_dir == NULL)
            goto oom;
        p = (char *)malloc(strlen(cal_dir) + strlen(stems[k]) + 6u);
        if (p == NULL)
        {
            free(cal_dir);
            goto oom;
        }
        sprintf(p, "%s/%s.txt", cal_dir, stems[k]);
        cp[k] = p;
        if (!is_file(p))
            all = 0;
        if (common == NULL)
            common = cal_dir;
        else
        {
            if (strcmp(common, cal_dir) != 0)
                same = 0;
            free(cal_dir);
        }
    }
    if (all)
    {
        *calib_paths = cp;
        free(common);
        return 0;
    }
    for (k = 0; k < n; ++k)
        free(cp[k]);
    free(cp);
    if (same && common != NULL)
        *one_calib = only_txt(common);
    if (*one_calib == NULL)
        fprintf(
            stderr,
            "lidet track: no calibration (SCAN_FOLDER/../calib/<stem>.txt for every scan, a calib/ with one "
            ".txt, or --calib FILE): label_02.txt is not written\n");
    free(common);
    return 0;
oom:
    for (k = 0; k < n; ++k)
        free(cp[k]);
    free(cp);
    free(common);
    return 1;
}

/* ---- the tails --------------------------------------------------------------------------------------------- */

/* every tail into the new sensor frame: p <- R(-dyaw) (p - d) */
static void tails_ego(const double *e)
{
    const double c = cos(e[2]), s = sin(e[2]);
    uint32_t i, j;
    for (i = 0; i < TAIL_SLOTS; ++i)
    {
        tail_t *t = &g_tail[i];
        if (!t->used)
            continue;
        for (j = 0; j < TAIL_LEN; ++j)
        {
            const double x = (double)t->x[j] - e[0], y = (double)t->y[j] - e[1];
            t->x[j] = (float)(c * x + s * y);
            t->y[j] = (float)(-s * x + c * y);
        }
    }
}

static void tails_add(const lidet_track_t *tr, uint32_t n, uint32_t scan)
{
    uint32_t i, j;
    for (i = 0; i < n; ++i)
    {
        tail_t *t = NULL;
        for (j = 0; j < TAIL_SLOTS && t == NULL; ++j)
            if (g_tail[j].used && g_tail[j].id == tr[i].id)
                t = &g_tail[j];
        if (t == NULL)
        {
            /* a free slot, else the stalest tail not seen this scan */
            for (j = 0; j < TAIL_SLOTS; ++j)
            {
                if (!g_tail[j].used)
                {
                    t = &g_tail[j];
                    break;
                }
                if (g_tail[j].last_seen != scan && (t == NULL || g_tail[j].last_seen < t->last_seen))
                    t = &g_tail[j];
            }
            if (t == NULL) /* not with n <= LIDET_TRACK_MAX_TRACKS < TAIL_SLOTS */
                continue;
            memset(t, 0, sizeof *t);
            t->used = 1;
            t->id = tr[i].id;
        }
        t->x[t->head] = tr[i].box.cx_m;
        t->y[t->head] = tr[i].box.cy_m;
        t->head = (t->head + 1u) % TAIL_LEN;
        t->n = t->n < TAIL_LEN ? t->n + 1u : TAIL_LEN;
        t->last_seen = scan;
    }
    for (j = 0; j < TAIL_SLOTS; ++j)
        if (g_tail[j].used && scan - g_tail[j].last_seen > TAIL_STALE)
            g_tail[j].used = 0;
}

/* ---- the picture ------------------------------------------------------------------------------------------ */

static const uint8_t k_palette[12][3] = {{255, 80, 60},   {60, 220, 255},  {255, 220, 40},  {120, 255, 90},
                                         {255, 100, 220}, {100, 140, 255}, {255, 160, 40},  {40, 255, 200},
                                         {200, 120, 255}, {220, 255, 120}, {255, 130, 140}, {120, 200, 255}};
static const uint8_t k_arrow_rgb[3] = {235, 235, 235};

static const uint8_t *id_rgb(uint32_t id)
{
    return k_palette[(id - 1u) % 12u];
}

static int write_png(const char *path, const float *pts, uint32_t np, const uint8_t *ground,
                     const lidet_track_t *tr, uint32_t n_tr, uint32_t scan, const char *title,
                     const char *subtitle)
{
    cli_legend_t legend[8];
    cli_scene_t sc;
    int n_legend = 0, rc;
    uint32_t i, j;
    sc.rgb = (uint8_t *)calloc((size_t)BEV_W * BEV_H * 3u, 1);
    if (sc.rgb == NULL)
        return -1;
    sc.w = BEV_W;
    sc.h = BEV_H;
    sc.res_m = BEV_RES;
    cli_scene_points(&sc, pts, np, ground);
    /* tails of the tracks output by the last scan, oldest centre first */
    for (i = 0; i < TAIL_SLOTS; ++i)
    {
        const tail_t *t = &g_tail[i];
        if (!t->used || t->last_seen != scan)
            continue;
        for (j = 1; j < t->n; ++j)
        {
            const uint32_t a = (t->head + TAIL_LEN - t->n + j - 1u) % TAIL_LEN, b = (a + 1u) % TAIL_LEN;
            cli_scene_line(&sc, t->x[a], t->y[a], t->x[b], t->y[b], id_rgb(t->id));
        }
    }
    for (i = 0; i < n_tr; ++i)
    {
        const lidet_box_t *b = &tr[i].box;
        const float vx = tr[i].vx_mps, vy = tr[i].vy_mps, speed = sqrtf(vx * vx + vy * vy);
        char label[16];
        cli_scene_box(&sc, b, id_rgb(tr[i].id), 1);
        if (speed * 1.0f >= 2.0f * BEV_RES) /* an arrow of 1 s of motion, head 25 deg either side */
        {
            const float tx = b->cx_m + vx, ty = b->cy_m + vy, head = speed < 2.0f ? 0.3f * speed : 0.6f;
            const float ux = vx / speed, uy = vy / speed, c = 0.9063f, s = 0.4226f;
            cli_scene_line(&sc, b->cx_m, b->cy_m, tx, ty, k_arrow_rgb);
            cli_scene_line(&sc, tx, ty, tx - head * (c * ux - s * uy), ty - head * (s * ux + c * uy),
                           k_arrow_rgb);
            cli_scene_line(&sc, tx, ty, tx - head * (c * ux + s * uy), ty - head * (-s * ux + c * uy),
                           k_arrow_rgb);
        }
        {
            /* the id beside the box (the font clips at the scene's edges) */
            const float u = (float)BEV_W * 0.5f - b->cy_m / BEV_RES,
                        v = (float)BEV_H * 0.5f - b->cx_m / BEV_RES;
            if (u > -100.0f && u < (float)BEV_W + 100.0f && v > -100.0f && v < (float)BEV_H + 100.0f)
            {
                snprintf(label, sizeof label, "%u", tr[i].id);
                cli_font_draw(sc.rgb, BEV_W, BEV_H, (int)u + 8, (int)v - 12, label, id_rgb(tr[i].id), 1);
            }
        }
    }
    legend[n_legend].label = "";
    memcpy(legend[n_legend++].rgb, k_palette[0], 3);
    legend[n_legend].label = "";
    memcpy(legend[n_legend++].rgb, k_palette[1], 3);
    legend[n_legend].label = "";
    memcpy(legend[n_legend++].rgb, k_palette[2], 3);
    legend[n_legend].label = "track: box, id, tail (colour by id)";
    memcpy(legend[n_legend++].rgb, k_palette[3], 3);
    legend[n_legend].label = "velocity (1 s)";
    memcpy(legend[n_legend++].rgb, k_arrow_rgb, 3);
    legend[n_legend].label = "obstacle points";
    memcpy(legend[n_legend++].rgb, cli_rgb_obstacle, 3);
    if (ground != NULL)
    {
        legend[n_legend].label = "ground points";
        memcpy(legend[n_legend++].rgb, cli_rgb_ground, 3);
    }
    rc = cli_bev_write(path, sc.rgb, BEV_W, BEV_H, BEV_RES, title, subtitle, legend, n_legend);
    free(sc.rgb);
    return rc;
}

/* ---- outputs per scan ------------------------------------------------------------------------------------- */

static void track_line(FILE *f, uint32_t frame, const lidet_track_t *t)
{
    fprintf(f, "%u %u %s %.6f %.6f %.6f %.6f %.6f %.6f %.6f %.6f %.6f %.6f %u\n", frame, t->id,
            cli_class_names[t->cls], (double)t->box.cx_m, (double)t->box.cy_m, (double)t->box.cz_m,
            (double)t->box.l_m, (double)t->box.w_m, (double)t->box.h_m, (double)t->box.yaw_rad,
            (double)t->vx_mps, (double)t->vy_mps, (double)t->score, t->hits);
}

/* lidet-eval track's prediction line (lidet_tools.track.eval.read_tracks) */
static void eval_line(FILE *f, const lidet_track_t *t)
{
    fprintf(f, "%u %s %.6f %.6f %.6f %.6f %.6f %.6f %.6f %.6f %.6f %.6f\n", t->id, cli_class_names[t->cls],
            (double)t->box.cx_m, (double)t->box.cy_m, (double)t->box.cz_m, (double)t->box.l_m,
            (double)t->box.w_m, (double)t->box.h_m, (double)t->box.yaw_rad, (double)t->vx_mps,
            (double)t->vy_mps, (double)t->score);
}

static void json_scan(FILE *f, uint32_t frame, const char *scan, uint32_t n_points, uint32_t n_det,
                      int det_status, int trk_status, double det_ms, double trk_ms,
                      const lidet_tracker_stats_t *s, const lidet_track_t *tr, uint32_t n_tr)
{
    uint32_t i;
    fprintf(f, "{\"frame\": %u, \"scan\": ", frame);
    json_string(f, scan);
    fprintf(f,
            ", \"points\": %u, \"detections\": %u, \"detector_status\": %d, \"tracker_status\": %d, "
            "\"detect_ms\": %.6g, \"track_ms\": %.6g, \"stats\": {\"n_tracks\": %u, \"n_confirmed\": %u, "
            "\"n_births\": %u, \"n_births_dropped\": %u, \"n_deaths\": %u, \"n_matched\": %u, "
            "\"n_feasible_pairs\": %u, \"n_dets_dropped\": %u, \"n_bad_dets\": %u}, \"tracks\": [",
            n_points, n_det, det_status, trk_status, det_ms, trk_ms, s->n_tracks, s->n_confirmed, s->n_births,
            s->n_births_dropped, s->n_deaths, s->n_matched, s->n_feasible_pairs, s->n_dets_dropped,
            s->n_bad_dets);
    for (i = 0; i < n_tr; ++i)
    {
        const lidet_track_t *t = &tr[i];
        fprintf(f,
                "%s{\"id\": %u, \"class\": \"%s\", \"state\": \"%s\", \"x\": %.9g, \"y\": %.9g, \"z\": %.9g, "
                "\"l\": %.9g, \"w\": %.9g, \"h\": %.9g, \"yaw\": %.9g, \"vx\": %.9g, \"vy\": %.9g, "
                "\"p_pp\": %.9g, \"p_pv\": %.9g, \"p_vv\": %.9g, \"score\": %.9g, \"hits\": %u, \"misses\": %u, "
                "\"age\": %u, \"det\": %d}",
                i ? ", " : "", t->id, cli_class_names[t->cls], k_state_names[t->state < 3 ? t->state : 0],
                (double)t->box.cx_m, (double)t->box.cy_m, (double)t->box.cz_m, (double)t->box.l_m,
                (double)t->box.w_m, (double)t->box.h_m, (double)t->box.yaw_rad, (double)t->vx_mps,
                (double)t->vy_mps, (double)t->p_pp_m2, (double)t->p_pv, (double)t->p_vv, (double)t->score,
                t->hits, t->misses, t->age, (int)t->det_index);
    }
    fprintf(f, "]}\n");
}

/* the integer tracker's tracks in SI units (lidet_ref.track_q.tracks_to_si) */
static void tracks_from_q(const lidet_track_q_t *q, uint32_t n, lidet_track_t *out)
{
    uint32_t i;
    for (i = 0; i < n; ++i)
    {
        lidet_track_t *t = &out[i];
        memset(t, 0, sizeof *t);
        t->id = q[i].id;
        t->cls = q[i].cls;
        t->state = q[i].state;
        t->box.cx_m = (float)((double)q[i].box.cx_mm / 1000.0);
        t->box.cy_m = (float)((double)q[i].box.cy_mm / 1000.0);
        t->box.cz_m = (float)((double)q[i].box.cz_mm / 1000.0);
        t->box.l_m = (float)((double)q[i].box.l_mm / 1000.0);
        t->box.w_m = (float)((double)q[i].box.w_mm / 1000.0);
        t->box.h_m = (float)((double)q[i].box.h_mm / 1000.0);
        t->box.yaw_rad = (float)((double)q[i].box.yaw_bam / k_bam_per_rad);
        t->vx_mps = (float)((double)q[i].vx_mmps / 1000.0);
        t->vy_mps = (float)((double)q[i].vy_mmps / 1000.0);
        t->p_pp_m2 = (float)((double)q[i].p_pp / 1e6);
        t->p_pv = (float)((double)q[i].p_pv / 1e6);
        t->p_vv = (float)((double)q[i].p_vv / 1e6);
        t->score = (float)((double)q[i].score_q15 / 32768.0);
        t->hits = q[i].hits;
        t->misses = q[i].misses;
        t->age = q[i].age;
        t->det_index = q[i].det_index;
    }
}

/* ---- the command --------------------------------------------------------------------------------------------- */

typedef struct
{
    char **scans;     /* paths, allocated */
    char **stems;     /* file names without extension, allocated */
    uint32_t *frames; /* the number of each scan (its stem's, or its index) */
    uint32_t n;
    double *dt;         /* seconds per scan (dt[0] unused) */
    double *ego;        /* 3 per scan, or NULL: no ego motion */
    char **calib_paths; /* per scan, or NULL */
    char *one_calib;    /* for every scan, or NULL */
} seq_t;

static void seq_free(seq_t *q)
{
    uint32_t k;
    for (k = 0; k < q->n; ++k)
    {
        if (q->scans != NULL)
            free(q->scans[k]);
        if (q->stems != NULL)
            free(q->stems[k]);
        if (q->calib_paths != NULL)
            free(q->calib_paths[k]);
    }
    free(q->scans);
    free(q->stems);
    free(q->frames);
    free(q->dt);
    free(q->ego);
    free(q->calib_paths);
    free(q->one_calib);
    memset(q, 0, sizeof *q);
}

int cli_make_dir(const char *path)
{
    char *p, *c;
    int rc = 0;
    if (path[0] == '\0')
    {
        fprintf(stderr, "lidet %s: --out needs a folder name\n", cli_cmd);
        return 1;
    }
    p = str_cat3(path, "", "");
    if (p == NULL)
        return 1;
    for (c = p + 1; rc == 0; ++c)
    {
        const char keep = *c;
        if (keep != '/' && keep != '\0')
            continue;
        *c = '\0';
        if (mkdir(p, 0777) != 0 && errno != EEXIST)
        {
            fprintf(stderr, "lidet %s: cannot make the folder '%s': %s\n", cli_cmd, p, strerror(errno));
            rc = 1;
        }
        *c = keep;
        if (keep == '\0')
            break;
    }
    free(p);
    if (rc == 0 && !is_dir(path))
    {
        fprintf(stderr, "lidet %s: '%s' is not a folder\n", cli_cmd, path);
        rc = 1;
    }
    return rc;
}

static FILE *open_out(const char *dir, const char *sub, const char *name)
{
    const size_t len = strlen(dir) + strlen(sub) + strlen(name) + 8u;
    char *p = (char *)malloc(len);
    FILE *f;
    if (p == NULL)
        return NULL;
    snprintf(p, len, "%s/%s%s", dir, sub, name);
    f = fopen(p, "w");
    if (f == NULL)
        fprintf(stderr, "lidet track: cannot write '%s': %s\n", p, strerror(errno));
    free(p);
    return f;
}

/* lidet track's own options (beside the shared sets: cli_options.c) */
enum
{
    OPT_JSON,
    OPT_COASTING,
    OPT_TENTATIVE,
    OPT_RATE,
    OPT_DT_FILE,
    OPT_EGO,
    OPT_OUT,
    OPT_PNG,
    OPT_CALIB,
    OPT_PNG_RANGE,
    OPT_PNG_SCAN
};

static const cli_opt_t k_track_opts[] = {{"json", no_argument, OPT_JSON, NULL},
                                         {"coasting", no_argument, OPT_COASTING, NULL},
                                         {"tentative", no_argument, OPT_TENTATIVE, NULL},
                                         {"rate", required_argument, OPT_RATE, "HZ: a scan rate in [0.1, 1000]"},
                                         {"dt-file", required_argument, OPT_DT_FILE, "F: one dt per scan"},
                                         {"ego", required_argument, OPT_EGO, "FILE, or none"},
                                         {"out", required_argument, OPT_OUT, "DIR"},
                                         {"png", required_argument, OPT_PNG, "FILE"},
                                         {"calib", required_argument, OPT_CALIB, "FILE: a KITTI calibration"},
                                         {"png-range", required_argument, OPT_PNG_RANGE, "M: metres in [5, 200]"},
                                         /* lidet detect's, refused with a word on what --png draws here */
                                         {"png-scan", optional_argument, OPT_PNG_SCAN, NULL},
                                         {NULL, 0, 0, NULL}};

typedef struct
{
    const char *ego_path, *dt_path, *out_dir, *png_path, *calib_path;
    double rate;
    int json, rate_given, ego_none;
    uint32_t flags;
} track_opts_t;

static int track_take(void *ctx, int id, const char *v)
{
    track_opts_t *t = (track_opts_t *)ctx;
    switch (id)
    {
    case OPT_JSON:
        t->json = 1;
        break;
    case OPT_COASTING:
        t->flags |= LIDET_TRACK_OUT_COASTING;
        break;
    case OPT_TENTATIVE:
        t->flags |= LIDET_TRACK_OUT_TENTATIVE;
        break;
    case OPT_RATE:
    {
        char *end;
        t->rate = strtod(v, &end);
        if (end == v || *end != '\0' || !(t->rate >= 0.1 && t->rate <= 1000.0))
        {
            fprintf(stderr, "lidet track: --rate needs a scan rate in [0.1, 1000] Hz, got '%s'\n", v);
            return 1;
        }
        t->rate_given = 1;
        break;
    }
    case OPT_DT_FILE:
        t->dt_path = v;
        break;
    case OPT_EGO:
        t->ego_none = strcmp(v, "none") == 0;
        t->ego_path = t->ego_none ? NULL : v;
        break;
    case OPT_OUT:
        t->out_dir = v;
        break;
    case OPT_PNG:
        t->png_path = v;
        break;
    case OPT_CALIB:
        t->calib_path = v;
        break;
    case OPT_PNG_RANGE:
        return cli_png_range(v);
    default: /* OPT_PNG_SCAN */
        fprintf(stderr, "lidet track: --png draws the last scan (--png-scan is lidet detect's)\n");
        return 1;
    }
    return 0;
}

int cli_track(int argc, char **argv)
{
    cli_args_t a;
    cli_det_opts_t o;
    seq_t q;
    lidet_detector_cfg_t cfg;
    const lidet_pn_model_t *mc = NULL, *mb = NULL;
    char chosen[64], **pos = NULL, *poses = NULL;
    const char *ego_path, *dt_path, *out_dir, *png_path, *calib_path;
    double rate;
    double *t_dt = NULL;
    int npos = 0, i, json, rate_given, ego_none, rc = 1, warned_mount = 0, warned_trunc = 0, warned_frame = 0;
    uint32_t flags, k, cap = 0, n_tr = 0;
    int32_t *pp = NULL;
    uint8_t *gp = NULL;
    FILE *label02 = NULL;
    cli_calib_t calib;
    int have_calib = 0, print_sensor;
    cli_pcap_opts_t po;
    cli_capture_t *capt = NULL;
    const lidet_return_t *rets = NULL;
    double *det_ms = NULL;
    track_opts_t topt;
    cli_optset_t sets[8];
    int n_sets;

    memset(&o, 0, sizeof o);
    memset(&topt, 0, sizeof topt);
    topt.rate = 10.0;
    cli_pcap_opts_default(&po);
    memset(&q, 0, sizeof q);
    cli_args_default(&a);
    pos = (char **)malloc(sizeof(char *) * (size_t)(argc + 1));
    o.sets = (const char **)malloc(sizeof(char *) * (size_t)(argc + 1));
    if (pos == NULL || o.sets == NULL)
        goto done;
    /* the sensor (no scan-file options: --out, --png and --json are ours), the detector, the capture, then ours */
    n_sets = cli_args_optsets(&a, 0, sets);
    sets[n_sets++] = cli_optset(cli_opts_det, cli_det_take, &o);
    sets[n_sets++] = cli_optset(cli_opts_pcap, cli_pcap_take, &po);
    sets[n_sets++] = cli_optset(k_track_opts, track_take, &topt);
    i = cli_options_parse(argc, argv, "lidet track", sets, n_sets, pos, &npos);
    if (i == CLI_PARSE_USAGE)
        usage();
    if (i != CLI_PARSE_OK)
        goto done;
    ego_path = topt.ego_path;
    dt_path = topt.dt_path;
    out_dir = topt.out_dir;
    png_path = topt.png_path;
    calib_path = topt.calib_path;
    rate = topt.rate;
    json = topt.json;
    rate_given = topt.rate_given;
    ego_none = topt.ego_none;
    flags = topt.flags;
    print_sensor = a.print_sensor;
    if (rate_given && dt_path != NULL)
    {
        fprintf(stderr, "lidet track: give --rate or --dt-file, not both\n");
        goto done;
    }
    if (po.path == NULL && (po.port != 0 || po.force_sensor || po.partial || po.dual != NULL ||
                            strcmp(po.lidar, "velodyne") != 0))
    {
        fprintf(stderr, "lidet track: --lidar, --port, --force-sensor, --dual and --partial go with --pcap FILE\n");
        goto done;
    }
    if (po.path != NULL && npos > 0)
    {
        fprintf(stderr, "lidet track: give scans (SCANS... | DIR) or --pcap FILE, not both ('%s')\n", pos[0]);
        goto done;
    }
    if (npos == 0 && !print_sensor && po.path == NULL)
    {
        usage();
        goto done;
    }
    /* the sensor: as lidet detect's, with the first scan (or the capture, or --print-sensor alone) */
    {
        char *first = npos > 0 ? pos[0] : (char *)po.path;
        a.capture = po.path != NULL; /* --sensor may name a --velodyne-calib's model; --print-sensor: the capture's */
        i = cli_args_finish(&a, &first, first != NULL ? 1 : 0, "track");
    }
    if (i == CLI_PARSE_PRINTED)
    {
        rc = 0;
        goto done;
    }
    if (i != CLI_PARSE_OK)
    {
        if (i == CLI_PARSE_ERROR)
            fprintf(stderr, "(lidet track --help: the options of lidet track)\n");
        goto done;
    }
    if (po.path != NULL && print_sensor) /* the sensor the capture is decoded as */
    {
        rc = cli_capture_print_sensor(&po, &a);
        goto done;
    }
    /* a capture: read once (its scans listed, the sensor from the packets unless --sensor) */
    if (po.path != NULL && cli_capture_open(&po, &a, &capt) != 0)
        goto done;
    if (cli_det_config(&a, &o, &cfg, &mc, &mb, chosen, sizeof chosen) != 0)
        goto done;

    /* the scans */
    if (capt != NULL)
    {
        /* named FILE#K, --out files <K:06d>.txt, frame K */
        const size_t len = strlen(po.path) + 16u;
        q.n = cli_capture_n_scans(capt);
        q.scans = (char **)calloc((size_t)q.n + 1u, sizeof(char *));
        det_ms = (double *)malloc(sizeof(double) * ((size_t)q.n + 1u));
        if (q.scans == NULL || det_ms == NULL)
            goto done;
        for (k = 0; k < q.n; ++k)
        {
            q.scans[k] = (char *)malloc(len);
            if (q.scans[k] == NULL)
                goto done;
            snprintf(q.scans[k], len, "%s#%u", po.path, k);
        }
    }
    else
    {
        char *dir_in = NULL;
        if (npos == 1 && is_dir(pos[0]))
        {
            char *vel = str_cat3(pos[0], "/velodyne", "");
            if (vel == NULL || list_bins(is_dir(vel) ? vel : pos[0], &q.scans, &q.n, &cap) != 0)
            {
                free(vel);
                goto done;
            }
            free(vel);
            if (q.n == 0)
            {
                fprintf(stderr, "lidet track: no scans (*.bin) in '%s/velodyne' or '%s'\n", pos[0], pos[0]);
                goto done;
            }
            dir_in = pos[0];
        }
        else
        {
            q.scans = (char **)calloc((size_t)npos + 1u, sizeof(char *));
            if (q.scans == NULL)
                goto done;
            for (i = 0; i < npos; ++i)
            {
                if (is_dir(pos[i]))
                {
                    fprintf(stderr, "lidet track: '%s' is a folder: give one folder alone, or scans\n",
                            pos[i]);
                    goto done;
                }
                q.scans[q.n++] = str_cat3(pos[i], "", "");
                if (q.scans[q.n - 1u] == NULL)
                    goto done;
            }
        }
        if (q.n == 0)
        {
            usage();
            goto done;
        }
        for (k = 0; k < q.n; ++k)
            if (check_scan(q.scans[k]) != 0)
                goto done;
        if (dir_in != NULL && ego_path == NULL && !ego_none)
        {
            poses = str_cat3(dir_in, "/poses.txt", "");
            if (poses == NULL)
                goto done;
            if (is_file(poses))
                ego_path = poses;
        }
    }
    q.stems = (char **)calloc(q.n, sizeof(char *));
    q.frames = (uint32_t *)malloc(sizeof(uint32_t) * q.n);
    q.dt = (double *)malloc(sizeof(double) * q.n);
    t_dt = (double *)malloc(sizeof(double) * q.n);
    if (q.stems == NULL || q.frames == NULL || q.dt == NULL || t_dt == NULL)
        goto done;
    for (k = 0; k < q.n; ++k)
    {
        const char *s;
        if (capt != NULL)
        {
            q.stems[k] = (char *)malloc(16u);
            if (q.stems[k] != NULL)
                snprintf(q.stems[k], 16u, "%06u", k);
        }
        else
            q.stems[k] = stem_of(q.scans[k]);
        if (q.stems[k] == NULL)
            goto done;
        s = q.stems[k];
        q.frames[k] = k;
        if (s[0] != '\0' && strlen(s) <= 9 && strspn(s, "0123456789") == strlen(s))
            q.frames[k] = (uint32_t)strtoul(s, NULL, 10);
    }
    if (out_dir != NULL)
    {
        /* two scans of one name would write one file */
        char **sorted = (char **)malloc(sizeof(char *) * q.n);
        if (sorted == NULL)
            goto done;
        memcpy(sorted, q.stems, sizeof(char *) * q.n);
        qsort(sorted, q.n, sizeof(char *), cmp_str);
        for (k = 1; k < q.n; ++k)
        {
            if (strcmp(sorted[k - 1u], sorted[k]) == 0)
            {
                fprintf(stderr, "lidet track: two scans are named '%s': their --out files would be one\n",
                        sorted[k]);
                free(sorted);
                goto done;
            }
        }
        free(sorted);
    }

    /* dt and the ego motion */
    t_dt[0] = -1.0;
    if (ego_path != NULL)
    {
        q.ego = (double *)malloc(sizeof(double) * 3u * q.n);
        if (q.ego == NULL || read_ego(ego_path, q.n, q.ego, t_dt) != 0)
            goto done;
    }
    if (dt_path != NULL)
    {
        if (read_dt(dt_path, q.n, q.dt) != 0)
            goto done;
    }
    else if (capt != NULL && !rate_given)
    {
        /* the capture's: the difference of the scans' first packets' sensor times (cli_scan_info_t.t_us) */
        uint32_t n_clamped = 0;
        for (k = 1; k < q.n; ++k)
        {
            const double dt = (double)(cli_capture_info(capt, k)->t_us - cli_capture_info(capt, k - 1u)->t_us) * 1e-6;
            q.dt[k] = dt < DT_MIN_S ? DT_MIN_S : (dt > DT_MAX_S ? DT_MAX_S : dt);
            n_clamped += q.dt[k] != dt;
        }
        if (n_clamped > 0u)
            fprintf(stderr,
                    "lidet track: note: %u scans are less than %g s or more than %g s after the one before (the "
                    "packets' timestamps): dt clamped to that range\n",
                    n_clamped, DT_MIN_S, DT_MAX_S);
    }
    else
    {
        for (k = 0; k < q.n; ++k)
            q.dt[k] = !rate_given && t_dt[0] >= 0.0 && k > 0 ? t_dt[k] : 1.0 / rate;
    }
    q.dt[0] = q.n > 1 ? q.dt[1] : 1.0 / rate; /* the first scan's: no track to predict, any valid value */

    /* the calibration of label_02.txt */
    if (out_dir != NULL)
    {
        if (calib_path != NULL)
        {
            if (cli_read_calib(calib_path, &calib) != 0)
                goto done;
            have_calib = 1;
        }
        else if (capt == NULL) /* a capture has no calibration folder: --calib only */
        {
            if (find_calibs(q.scans, q.stems, q.n, &q.calib_paths, &q.one_calib) != 0)
                goto done;
            if (q.one_calib != NULL)
            {
                if (cli_read_calib(q.one_calib, &calib) != 0)
                    goto done;
                have_calib = 1;
            }
            have_calib |= q.calib_paths != NULL;
        }
        if (cli_make_dir(out_dir) != 0)
            goto done;
        {
            char *tracks = str_cat3(out_dir, "/tracks", "");
            if (tracks == NULL || cli_make_dir(tracks) != 0)
            {
                free(tracks);
                goto done;
            }
            free(tracks);
        }
        if (have_calib && (label02 = open_out(out_dir, "", "label_02.txt")) == NULL)
            goto done;
    }

    /* the detector and the tracker */
    pp = (int32_t *)malloc(sizeof(int32_t) * LIDET_MAX_POINTS);
    if (pp == NULL)
        goto done;
    if (o.fixed)
    {
        lidet_tracker_q_cfg_t tc;
        lidet_status_t st;
        lidet_tracker_q_cfg_default(&tc);
        st = lidet_tracker_q_init(&g_trkq, &tc);
        if (st != LIDET_OK)
        {
            fprintf(stderr, "lidet track: lidet_tracker_q_init: %s\n", lidet_status_str(st));
            goto done;
        }
    }
    else
    {
        lidet_tracker_cfg_t tc;
        lidet_status_t st;
        lidet_tracker_cfg_default(&tc);
        st = lidet_tracker_init(&g_trk, &tc);
        if (st != LIDET_OK)
        {
            fprintf(stderr, "lidet track: lidet_tracker_init: %s\n", lidet_status_str(st));
            goto done;
        }
        if (cli_detect_f_init(&cfg, mc, mb) != 0)
            goto done;
    }
    memset(g_tail, 0, sizeof g_tail);
    if (!json)
        printf("# columns: frame id class x y z l w h yaw vx vy score hits (sensor frame: m, rad; velocity "
               "over the ground, m/s)\n");

    for (k = 0; k < q.n; ++k)
    {
        const int last = k + 1u == q.n;
        const lidet_detection_t *det = NULL;
        const lidet_detector_stats_t *ds = NULL;
        static lidet_detector_stats_t ds_q;
        const lidet_tracker_stats_t *ts;
        lidet_tracker_stats_t ts_q;
        lidet_status_t det_st = LIDET_OK, trk_st;
        double ms[LIDET_DET_N_STAGES + 1], t0, trk_ms;
        uint32_t n_det = 0, j;
        const double *e = q.ego != NULL && k > 0 ? q.ego + 3u * (size_t)k : NULL;

        if (capt != NULL)
        {
            cli_scan_info_t info;
            if (cli_capture_next(capt, &a, &rets, &info) != 1)
                goto done;
        }
        else
        {
            cli_free(&a);
            a.scan_path = q.scans[k];
            if (cli_load(&a) != 0)
                goto done;
        }
        if (o.fixed)
        {
            const uint32_t np = a.n_points < LIDET_MAX_POINTS ? a.n_points : LIDET_MAX_POINTS;
            const lidet_detection_q_t *dq;
            uint32_t nq = 0;
            lidet_ego_q_t eq;
            free(gp);
            gp = NULL;
            if (last && png_path != NULL && (gp = (uint8_t *)malloc((size_t)np + 1u)) == NULL)
                goto done;
            if (cli_detect_q_run(&a, &cfg, chosen, g_det_q, &n_det, &ds_q, ms, gp, NULL, &det_st, rets) != 0)
                goto done;
            det = g_det_q;
            ds = &ds_q;
            dq = cli_detect_q_detections(&nq);
            if (e != NULL)
            {
                double r = fmod(e[2], 2.0 * M_PI_D);
                if (r < 0.0)
                    r += 2.0 * M_PI_D;
                eq.dx_mm = (int32_t)rha(e[0] * 1000.0);
                eq.dy_mm = (int32_t)rha(e[1] * 1000.0);
                eq.dyaw_bam = (int32_t)(uint32_t)((uint64_t)rha(r * k_bam_per_rad) & 0xFFFFFFFFu);
            }
            t0 = cli_stage_clock_cpu ? cli_cpu_ms() : cli_now_ms();
            trk_st = lidet_tracker_q_update(&g_trkq, dq, nq, (uint32_t)rha(q.dt[k] * 1000.0),
                                            e != NULL ? &eq : NULL);
            n_tr = lidet_tracker_q_tracks(&g_trkq, g_outq, LIDET_TRACK_MAX_TRACKS, flags);
            trk_ms = (cli_stage_clock_cpu ? cli_cpu_ms() : cli_now_ms()) - t0;
            tracks_from_q(g_outq, n_tr, g_out);
            {
                const lidet_tracker_q_stats_t *s = lidet_tracker_q_stats(&g_trkq);
                ts_q.n_tracks = s->n_tracks;
                ts_q.n_confirmed = s->n_confirmed;
                ts_q.n_births = s->n_births;
                ts_q.n_births_dropped = s->n_births_dropped;
                ts_q.n_deaths = s->n_deaths;
                ts_q.n_matched = s->n_matched;
                ts_q.n_feasible_pairs = s->n_feasible_pairs;
                ts_q.n_dets_dropped = s->n_dets_dropped;
                ts_q.n_bad_dets = s->n_bad_dets;
            }
            ts = &ts_q;
        }
        else
        {
            lidet_ego_t ef;
            if (cli_detect_f_run(&a, pp, ms, &det, &n_det, &ds, &det_st) != 0)
                goto done;
            if (e != NULL)
            {
                ef.dx_m = (float)e[0];
                ef.dy_m = (float)e[1];
                ef.dyaw_rad = (float)e[2];
            }
            t0 = cli_stage_clock_cpu ? cli_cpu_ms() : cli_now_ms();
            trk_st = lidet_tracker_update(&g_trk, det, n_det, (float)q.dt[k], e != NULL ? &ef : NULL);
            n_tr = lidet_tracker_tracks(&g_trk, g_out, LIDET_TRACK_MAX_TRACKS, flags);
            trk_ms = (cli_stage_clock_cpu ? cli_cpu_ms() : cli_now_ms()) - t0;
            ts = lidet_tracker_stats(&g_trk);
        }
        if (det_ms != NULL)
            det_ms[k] = ms[LIDET_DET_N_STAGES];
        if (!LIDET_SUCCEEDED(trk_st))
        {
            fprintf(stderr, "lidet track: %s: the tracker: %s\n", q.scans[k], lidet_status_str(trk_st));
            goto done;
        }
        if (trk_st == LIDET_TRUNCATED && !warned_trunc)
        {
            fprintf(stderr,
                    "lidet track: note: %s: %u detections past LIDET_TRACK_MAX_DETS (%u), %u births "
                    "without a free track (LIDET_TRACK_MAX_TRACKS %u); counted in the stats (--json), noted "
                    "once\n",
                    q.scans[k], ts->n_dets_dropped, (unsigned)LIDET_TRACK_MAX_DETS, ts->n_births_dropped,
                    (unsigned)LIDET_TRACK_MAX_TRACKS);
            warned_trunc = 1;
        }
        if (!warned_frame)
            warned_frame = cli_warn_frame("lidet track", q.scans[k], &ds->stages.proj, a.sensor_profile) > 0;
        if (!warned_mount &&
            2u * (uint32_t)ds->stages.ground.n_sectors_rejected > cfg.stages.ground.n_sectors)
        {
            fprintf(stderr,
                    "lidet track: warning: %s: the ground stage refused the planes of %u of %u sectors: "
                    "is the mount height right? (--mount-height M; python -m lidet_tools.mount SCANS "
                    "estimates it; noted once)\n",
                    q.scans[k], (unsigned)ds->stages.ground.n_sectors_rejected,
                    (unsigned)cfg.stages.ground.n_sectors);
            warned_mount = 1;
        }
        if (e != NULL)
            tails_ego(e);
        tails_add(g_out, n_tr, k);

        /* outputs */
        if (json)
            json_scan(stdout, q.frames[k], q.scans[k], a.n_points, n_det, (int)det_st, (int)trk_st,
                      ms[LIDET_DET_N_STAGES], trk_ms, ts, g_out, n_tr);
        else
        {
            printf("# frame %u %s: %u detections, %u tracks (%u live, %u born, %u died; detector %.2f "
                   "ms, tracker %.3f ms)\n",
                   q.frames[k], q.scans[k], n_det, n_tr, ts->n_tracks, ts->n_births, ts->n_deaths,
                   ms[LIDET_DET_N_STAGES], trk_ms);
            for (j = 0; j < n_tr; ++j)
                track_line(stdout, q.frames[k], &g_out[j]);
        }
        if (out_dir != NULL)
        {
            char *name = str_cat3(q.stems[k], ".txt", "");
            FILE *f = name != NULL ? open_out(out_dir, "", name) : NULL;
            FILE *g = name != NULL ? open_out(out_dir, "tracks/", name) : NULL;
            int bad;
            free(name);
            if (f == NULL || g == NULL)
            {
                if (f != NULL)
                    fclose(f);
                if (g != NULL)
                    fclose(g);
                goto done;
            }
            fprintf(g,
                    "# id class x y z l w h yaw vx vy score (sensor frame; velocity over the ground, m/s)\n");
            for (j = 0; j < n_tr; ++j)
            {
                track_line(f, q.frames[k], &g_out[j]);
                eval_line(g, &g_out[j]);
            }
            bad = fclose(f) != 0;
            bad |= fclose(g) != 0;
            if (bad)
            {
                fprintf(stderr, "lidet track: cannot write the track files of '%s' in '%s'\n", q.stems[k],
                        out_dir);
                goto done;
            }
            if (label02 != NULL)
            {
                if (q.calib_paths != NULL && cli_read_calib(q.calib_paths[k], &calib) != 0)
                    goto done;
                for (j = 0; j < n_tr; ++j)
                {
                    const lidet_track_t *t = &g_out[j];
                    cli_kitti_t kb;
                    if (cli_kitti_box(&calib, &t->box, &kb) != 0)
                        continue;
                    fprintf(label02,
                            "%u %u %s 0 0 %.6f %.2f %.2f %.2f %.2f %.6f %.6f %.6f %.6f %.6f %.6f %.6f %.6f\n",
                            q.frames[k], t->id, cli_class_names[t->cls], kb.alpha, kb.bbox[0], kb.bbox[1],
                            kb.bbox[2], kb.bbox[3], (double)t->box.h_m, (double)t->box.w_m,
                            (double)t->box.l_m, kb.loc[0], kb.loc[1], kb.loc[2], kb.ry, (double)t->score);
                }
            }
        }
        if (last && png_path != NULL)
        {
            const uint32_t np = a.n_points < LIDET_MAX_POINTS ? a.n_points : LIDET_MAX_POINTS;
            uint32_t per_class[LIDET_N_CLASSES] = {0};
            char title[512], subtitle[512];
            if (!o.fixed)
            {
                gp = (uint8_t *)malloc((size_t)np + 1u);
                if (gp == NULL || cli_detect_f_ground(pp, a.n_points, gp) != 0)
                {
                    fprintf(stderr, "lidet track: cannot label the last scan's ground points\n");
                    goto done;
                }
            }
            for (j = 0; j < n_tr; ++j)
                per_class[g_out[j].cls]++;
            snprintf(title, sizeof title, "track%s  %s .. %s (%u scans)  %s (models %s%s)",
                     o.fixed ? " --fixed" : "", cli_basename(q.scans[0]), cli_basename(q.scans[k]), q.n,
                     a.sensor, chosen, o.fixed ? " int8" : "");
            /* no timing in the picture: the same scans give the same bytes */
            snprintf(
                subtitle, sizeof subtitle,
                "last scan: %u tracks: %u car, %u cyclist, %u pedestrian  tails: up to %d centres%s  arrows: "
                "1 s of motion",
                n_tr, per_class[0], per_class[1], per_class[2], TAIL_LEN,
                q.ego != NULL ? ", moved with the ego motion" : "");
            if (write_png(png_path, a.points, np, gp, g_out, n_tr, k, title, subtitle) != 0)
            {
                fprintf(stderr, "lidet track: cannot write the picture '%s'\n", png_path);
                goto done;
            }
        }
    }
    if (label02 != NULL)
    {
        const int bad = fclose(label02) != 0;
        label02 = NULL;
        if (bad)
        {
            fprintf(stderr, "lidet track: cannot write '%s/label_02.txt'\n", out_dir);
            goto done;
        }
    }
    if (fflush(stdout) != 0)
        goto done;
    rc = capt != NULL ? cli_capture_summary(capt, stderr, det_ms, q.n) : 0;
done:
    if (label02 != NULL)
        fclose(label02);
    if (capt != NULL)
    {
        a.points = NULL; /* the capture's buffers */
        a.ring = NULL;
        cli_capture_close(capt);
    }
    free(det_ms);
    cli_free(&a);
    seq_free(&q);
    free(t_dt);
    free(poses);
    free(pp);
    free(gp);
    free(pos);
    free((void *)o.sets);
    return rc;
}
