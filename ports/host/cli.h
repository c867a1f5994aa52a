/* SPDX-License-Identifier: MIT */
/* Host CLI internals: shared option parsing, scan loading, timing and output helpers.
 * One file per subcommand (cli_<stage>.c) registers a function in cli_main.c's table. */
#ifndef LIDET_CLI_H
#define LIDET_CLI_H

#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include <getopt.h>

#include "lidet/lidet.h"

/* A sensor read from a file (--sensor-file: lidet's description, --ouster-meta: Ouster's metadata; cli_sensor.c;
 * --velodyne-calib: a Velodyne calibration, cli_velodyne_calib.c; docs/SENSORS.md), as read: the profiles of
 * cli_args_t point into it. */
typedef struct
{
    char name[64];                     /* the description's "name" (Ouster: the product line) */
    char model[64];                    /* the description's "model", "" when it gives none */
    char family[64];                   /* the float model family: model, else hdl64 (>= 32 rows) or vlp16 */
    int uniform;                       /* 1: given as fov_up_deg, fov_down_deg and rows; 0: as a table */
    double fov_up_deg, fov_down_deg;   /* uniform only */
    double elev_deg[LIDET_MAX_ROWS];   /* ring order: the table as read, or the uniform beam centres (a YAML
                                        calibration: its radians x 180 / pi), what --print-sensor prints */
    int have_rad;                      /* 1: the file gave radians (elev_rad_d), the table's source */
    double elev_rad_d[LIDET_MAX_ROWS]; /* ring order, radians as read (have_rad only) */
    float elev_rad[LIDET_MAX_ROWS];    /* the same in radians, single precision (lidet_sensor_t's table) */
    int32_t elev_urad[LIDET_MAX_ROWS]; /* and in microradians (lidet_sensor_q_t's table) */
    uint16_t rows, cols;
    double mount_height_m, max_range_m;
} cli_sensor_desc_t;

/* A Velodyne calibration's per-laser corrections (--velodyne-calib, cli_velodyne_calib.c), in the description's ring
 * order (lowest beam first) and in the units sensors.py's load_velodyne_calibration holds them: what the packet
 * decoder takes (lidet_velodyne_calib_t, through cli_velodyne_calib_table: `lidet detect / track --pcap`). */
typedef struct
{
    int n;                        /* lasers (0: no calibration read) */
    double distance_resolution_m; /* distLSB_ x 0.01 / distance_resolution; 0.002 when the file gives none */
    int laser_id[LIDET_MAX_ROWS]; /* id_ / laser_id: the laser's place in the packet's data block */
    double rot_rad[LIDET_MAX_ROWS]; /* rotCorrection_ x pi / 180 / rot_correction (radians) */
    double dist_m[LIDET_MAX_ROWS];  /* distCorrection_ x 0.01 / dist_correction (metres); 0 when absent */
} cli_velodyne_corr_t;

typedef struct
{
    const char *scan_path; /* positional SCAN.bin */
    const char *sensor;    /* --sensor NAME (default hdl64); a file's sensor: its name */
    int sensor_given;      /* --sensor was on the command line (--pcap: else the packets say) */
    const char
        *sensor_arg; /* --sensor NAME as given (a file's sensor replaces a->sensor: --pcap --velodyne-calib
                               --sensor NAME names the decoder's model) */
    int capture;     /* set by detect / track before cli_args_finish when --pcap is given: --sensor may go
                               with --velodyne-calib (the model of the calibrated unit), and --print-sensor waits for
                               the capture's sensor (cli_capture_print_sensor) */
    const char *sensor_file; /* --sensor-file F: a lidet sensor description (JSON) */
    const char *ouster_meta; /* --ouster-meta M: Ouster's sensor metadata (JSON) */
    const char
        *velodyne_calib;   /* --velodyne-calib C: a Velodyne calibration (db.xml / VeloView XML, or YAML) */
    long velodyne_cols;    /* --cols N with --velodyne-calib (0: the default for its laser count) */
    int print_sensor;      /* --print-sensor: print the sensor as a lidet description and stop */
    const char *out_path;  /* --out FILE */
    const char *png_path;  /* --png FILE */
    const char *ring_path; /* --ring FILE (uint16 per point) */
    int json;              /* --json */
    int repeat;            /* --repeat N (>= 1) */
    double
        mount_height_m; /* --mount-height M: the sensor's height above the ground, m (< 0: the profile's) */
    /* loaded by cli_load */
    float *points; /* n_points * 4 floats (x, y, z, remission) */
    uint32_t n_points;
    uint16_t *ring; /* NULL unless --ring */
    const lidet_sensor_t
        *sensor_profile;           /* the preset, or sensor_mounted (--mount-height, a file's sensor) */
    lidet_sensor_t sensor_mounted; /* the preset with the --mount-height of the command line, or the
                                             file's sensor (its table in desc) */
    /* a file's sensor only (NULL for a preset): its float model family and its integer profile (detect --fixed;
     * the table in desc) */
    const char *family;
    const lidet_sensor_q_t *sensor_q;
    lidet_sensor_q_t sensor_q_file;
    cli_sensor_desc_t desc;
    cli_velodyne_corr_t vcorr; /* --velodyne-calib: the corrections beside the elevations (desc) */
} cli_args_t;

/* ---- command-line options (cli_options.c: getopt_long over option sets; the rules at the top of that file) ---- */
/* One long option of a set: its name (without "--"), has_arg (getopt.h: no_argument for a flag, required_argument,
 * optional_argument: only as --name=VALUE), the set's own number for it (what take receives), and what its value
 * is, for "--NAME needs a value (VALUE)" (NULL for a flag). A set's table ends with an entry whose name is NULL. */
typedef struct
{
    const char *name;
    int has_arg;
    int id;
    const char *value;
} cli_opt_t;
/* an option set: its table and the function that takes its options, in the order given, into ctx: take(ctx, id,
 * value) returns 0, or 1 after a message saying what was wrong with the value (value: NULL for a flag) */
typedef struct
{
    const cli_opt_t *opts;
    int (*take)(void *ctx, int id, const char *value);
    void *ctx;
} cli_optset_t;
/* the set of opts taken by take into ctx */
cli_optset_t cli_optset(const cli_opt_t *opts, int (*take)(void *ctx, int id, const char *value), void *ctx);
/* what cli_options_parse, cli_args_finish and cli_parse return */
#define CLI_PARSE_OK 0
#define CLI_PARSE_ERROR 1       /* said: the command exits with 1 */
#define CLI_PARSE_PRINTED 2     /* --print-sensor printed the sensor: the command exits with 0 */
#define CLI_PARSE_SENSOR_FILE 3 /* a sensor file could not be used (said): exit 1 */
#define CLI_PARSE_USAGE 4       /* -h / --help, or no scan: the command prints its usage and exits with 1 */
/* Parses argv[1..argc) (argv[0]: the subcommand's or the program's name, as getopt_long expects) with the options of
 * the n_sets sets: one getopt_long table built from them (a name declared twice is an internal error), each option
 * handed to its set's take in the order given; the positional arguments, in order, into pos (room for argc
 * entries) and their count into *n_pos. Messages start with who ("lidet detect"). Returns CLI_PARSE_OK,
 * CLI_PARSE_ERROR (an unknown option, a value missing or refused: said) or CLI_PARSE_USAGE (-h, --help). */
int cli_options_parse(int argc, char **argv, const char *who, const cli_optset_t *sets, int n_sets,
                      char **pos, int *n_pos);
/* the values of a repeatable option (--set KEY=VALUE) in the order given: v has room for argc of them */
typedef struct
{
    const char **v;
    int n;
} cli_list_t;
/* a take that appends value to the cli_list_t ctx, whatever the id */
int cli_list_take(void *list, int id, const char *value);

/* The benchmarks' shared options (lidet_bench_proj, lidet_bench_memory): --sensor NAME and --repeat N (an integer in
 * [1, 1000000]), taken into a cli_bench_opts_t by cli_bench_take; `who` names the program in its messages. */
typedef struct
{
    const char *who;
    const char *sensor;
    int repeat;
} cli_bench_opts_t;
extern const cli_opt_t cli_opts_bench[];
int cli_bench_take(void *opts, int id, const char *value);

/* The shared option sets of cli_args_t (cli_common.c), taken by cli_args_take: the sensor (--sensor NAME,
 * --sensor-file F, --ouster-meta M, --mount-height M, --print-sensor) and the scan's files and output (--out FILE,
 * --png FILE, --ring FILE, --json, --repeat N); cli_velodyne_calib.c's --velodyne-calib C and --cols N, taken by
 * cli_velodyne_calib_take. */
extern const cli_opt_t cli_opts_sensor[];
extern const cli_opt_t cli_opts_io[];
extern const cli_opt_t cli_opts_velodyne_calib[];
int cli_args_take(void *a, int id, const char *value);
int cli_velodyne_calib_take(void *a, int id, const char *value);
/* --png-range M (detect, track): metres in [5, 200] into cli_png_half_m; 1 with a message when refused */
int cli_png_range(const char *v);
/* the half width of detect's and track's bird's-eye pictures, metres (default 40), and their metres per pixel
 * for a scene w pixels wide */
extern float cli_png_half_m;
#define CLI_PNG_RES(w) (cli_png_half_m / (0.5f * (float)(w)))
/* A point cloud that does not look like sensor s's scan, from its projection's counts (ps): more than a tenth of
 * the points outside the beams' elevations (a cloud upside down, in a camera's frame, or from another sensor), or
 * more than a quarter beyond the range the image keeps (coordinates in millimetres or centimetres). Prints a
 * warning per cause to stderr, headed `who` (with what `scan` names, if not NULL); returns how many it printed */
int cli_warn_frame(const char *who, const char *scan, const lidet_proj_stats_t *ps, const lidet_sensor_t *s);
/* a's defaults (sensor hdl64, repeat 1, the profile's mount height) */
void cli_args_default(cli_args_t *a);
/* the shared sets over a into sets[]: the sensor and the Velodyne calibration, and with io also cli_opts_io;
 * returns how many (2 or 3) */
int cli_args_optsets(cli_args_t *a, int io, cli_optset_t *sets);
/* After the options: the scan from the positional arguments (one; none only with --print-sensor; a second is
 * "unexpected argument"), then the sensor: one of --sensor / --sensor-file / --ouster-meta / --velodyne-calib (with
 * a->capture --sensor may go with --velodyne-calib), the file read or the preset found, --mount-height applied,
 * --print-sensor printed (with a->capture not: the command prints the capture's sensor). Returns CLI_PARSE_OK,
 * CLI_PARSE_ERROR, CLI_PARSE_PRINTED, CLI_PARSE_SENSOR_FILE or CLI_PARSE_USAGE (no scan). */
int cli_args_finish(cli_args_t *a, char *const *pos, int n_pos, const char *cmd);
/* The whole of it for a command that takes one scan: cli_args_default, cli_options_parse with the shared sets (io
 * included) and the command's own n_own sets, cli_args_finish. Returns as cli_args_finish. */
int cli_parse(int argc, char **argv, const char *cmd, cli_args_t *a, const cli_optset_t *own, int n_own);
/* the usage lines of the shared options (lidet CMD SCAN.bin ...) */
void cli_usage(FILE *f, const char *cmd);
/* Reads a->sensor_file or a->ouster_meta into a->desc and points the profiles at it (cli_sensor.c). Returns 0, or
 * prints "lidet CMD: FILE: problem" (or that this lidet was built without cJSON) and returns 1. */
int cli_sensor_load(cli_args_t *a, const char *cmd);
/* The same for a->velodyne_calib (cli_velodyne_calib.c, the rules of sensors.py load_velodyne_calibration): the
 * table in ring order (lowest beam first), columns a->velodyne_cols or the laser count's default; the other
 * corrections into a->vcorr. 0, or 1 after "lidet CMD: FILE: problem" (or that this lidet was built without
 * libxml2 / libyaml). */
int cli_velodyne_calib_load(cli_args_t *a, const char *cmd);
/* The Velodyne decoder's calibration table of the calibration loaded into a (desc, vcorr) for a model
 * (lidet_velodyne_model_t other than AUTO), by the rules of tools/lidet_tools/velodyne.py calibration_table: per
 * laser id the elevation (mdeg), rotational correction (0.01 deg) and distance correction (mm), each rounded to the
 * nearest (half to even, as numpy). 0; or 1 with calibration_table's message in err (another number of lasers,
 * laser ids other than 0 .. n-1, a distance resolution other than the packets' unit, a distance correction beyond
 * +-32.767 m). */
int cli_velodyne_calib_table(const cli_args_t *a, int model, lidet_velodyne_calib_t *t, char *err,
                             size_t err_len);
/* Points a's profiles (float, integer, family) at a->desc once a loader has filled it (cli_sensor.c). */
void cli_sensor_use_desc(cli_args_t *a);
/* The packet format of Ouster's metadata (--ouster-meta; the rules of tools/lidet_tools/ouster.py load_metadata):
 * what lidet_ouster_cfg_t takes besides the beam count and columns (a->desc) */
typedef struct
{
    int profile;                 /* lidet_ouster_profile_t (udp_profile_lidar; absent: LEGACY) */
    int header;                  /* lidet_ouster_header_t (header_type; absent: STANDARD) */
    uint16_t columns_per_packet; /* absent: 16 */
    uint16_t
        azimuth_offset_bam; /* the turn of lidar_to_sensor_transform about z (absent: ouster-sdk's half turn) */
    uint32_t init_id;       /* initialization_id (0: unknown, not checked) */
    uint64_t prod_sn;       /* prod_sn (0: unknown, not checked) */
    uint32_t udp_port_lidar;                   /* absent: 7502 */
    int32_t beam_azimuth_mdeg[LIDET_MAX_ROWS]; /* beam_azimuth_angles (absent: 0) */
} cli_ouster_fmt_t;
/* Reads it from a->ouster_meta (a->desc already loaded): 0, or 1 with a message. */
int cli_ouster_format(const cli_args_t *a, cli_ouster_fmt_t *o);
/* Prints the command's sensor as a lidet sensor description (JSON, version 1) after --mount-height. */
void cli_sensor_print(const cli_args_t *a, FILE *f);
/* Reads the scan (and ring file); clear error and 1 on a missing, truncated or odd-sized file. */
int cli_load(cli_args_t *a);
void cli_free(cli_args_t *a);
/* the running subcommand's name (cli_main.c sets it; default "detect"): the shared helpers' messages read
 * "lidet <cmd>: ..." */
extern const char *cli_cmd;
/* Monotonic clock in milliseconds. */
double cli_now_ms(void);
/* CPU time of the calling thread in ms (wall time where the platform has no thread clock): timings on
 * a loaded machine, where other processes take the core in the middle of a run */
double cli_cpu_ms(void);
/* the detectors' stage clock (cfg.clock): nanoseconds modulo 2^32 of the monotonic clock, or of this thread's
 * CPU time after `lidet detect --cpu-clock` set cli_stage_clock_cpu (stage times a busy machine does not
 * inflate) */
extern int cli_stage_clock_cpu;
/* `lidet detect --fixed --range-only`: the integer detector with the range-only pixel of the integer firmware
 * (lidet_detector_q_cfg_t.range_only) */
extern int cli_fixed_range_only;
/* lidet detect --returns: with --fixed and --ring, the scan fed as the sensor's returns (lidet_detector_q_run_returns) */
extern int cli_fixed_returns;
/* `lidet detect / track --fixed --stream N`: the scan's returns (--returns, --pcap) streamed into the integer detector
 * N at a time (lidet_detector_q_stream_*), the time of stream_end (the latency after the last chunk) measured;
 * --stream-sectors: lidet_detector_q_cfg_t.stream_sectors (and the range-only pixel it needs). The last run's: the
 * sectors done before stream_end (stats.n_stream_sectors) and the median stream_end time */
extern uint32_t cli_fixed_stream;
extern int cli_fixed_stream_sectors;
extern uint32_t cli_stream_sectors_done;
extern double cli_stream_end_ms;
uint32_t cli_stage_clock_ns(void *ctx);
/* Median of n values (sorts in place). */
double cli_median(double *v, int n);
/* JSON helpers: open object, key/values with separators, close. */
void cli_json_begin(FILE *f);
void cli_json_num(FILE *f, const char *key, double v);
void cli_json_int(FILE *f, const char *key, long long v);
void cli_json_str(FILE *f, const char *key, const char *v);
void cli_json_end(FILE *f);
/* one uint32 / float in host byte order into a binary --dump file (detect --dump, --fixed --dump): 0, or -1 when
 * the write fails */
int cli_put_u32(FILE *f, uint32_t v);
int cli_put_f32(FILE *f, float v);

/* `--set KEY=VALUE` overrides of one configuration struct's fields. cli_split_set splits kv into the
 * key length and the number; 0, or 1 when there is no '=' or the value is not a number. Inside a
 * function `int apply(cfg_t *c, const char *kv)` that has called it (locals klen, v), CLI_SET_FLOAT
 * and CLI_SET_INT return 0 when the key names that field (1 for an integer out of [0, maxv]). */
int cli_split_set(const char *kv, size_t *klen, double *v);
#define CLI_SET_FLOAT(c, kv, klen, v, name)                                                                  \
    if ((klen) == sizeof #name - 1 && strncmp((kv), #name, (klen)) == 0)                                     \
    {                                                                                                        \
        (c)->name = (float)(v);                                                                              \
        return 0;                                                                                            \
    }
#define CLI_SET_INT(c, kv, klen, v, name, type, maxv)                                                        \
    if ((klen) == sizeof #name - 1 && strncmp((kv), #name, (klen)) == 0)                                     \
    {                                                                                                        \
        if ((v) < 0.0 || (v) > (double)(maxv) || (v) != (double)(long long)(v))                              \
            return 1;                                                                                        \
        (c)->name = (type)(v);                                                                               \
        return 0;                                                                                            \
    }

/* `--set KEY=VALUE` on a clustering configuration (cli_cluster.c): 0, or 1 for an unknown key or a bad value */
int cli_cluster_set(lidet_cluster_cfg_t *c, const char *kv);
/* the same on a ground configuration (cli_ground.c) */
int cli_ground_set(lidet_ground_cfg_t *c, const char *kv);

/* ---- the detector as `lidet detect` runs it, shared with `lidet track` (cli_detect.c, cli_detect_q.c) ---- */
/* the class names of lidet_class_t (KITTI's: Car, Cyclist, Pedestrian) */
extern const char *const cli_class_names[LIDET_N_CLASSES];
/* the detector's command-line options */
typedef struct
{
    const char *family; /* --model NAME (NULL: the sensor's family) */
    const char **sets;  /* --set KEY=VALUE: n_sets of them; the caller gives room for argc */
    int n_sets;
    int crop;  /* --crop */
    int fixed; /* --fixed: the integer detector */
} cli_det_opts_t;
/* the detector's option set (lidet detect, lidet track): --model NAME, --set KEY=VALUE, --crop, --fixed,
 * --range-only, --cpu-clock; cli_det_take takes them into a cli_det_opts_t (the last two: the globals below) */
extern const cli_opt_t cli_opts_det[];
int cli_det_take(void *o, int id, const char *value);
/* the usage lines of those options */
void cli_det_usage(FILE *f);
/* the float configuration of the sensor (a->sensor_profile) with --crop and --set, and the models (--model,
 * else the sensor's family); --range-only / --returns without --fixed refused. 0, or 1 with a message. */
int cli_det_config(const cli_args_t *a, const cli_det_opts_t *o, lidet_detector_cfg_t *cfg,
                   const lidet_pn_model_t **mc, const lidet_pn_model_t **mb, char *chosen, size_t chosen_len);
/* the float detector (one static lidet_detector_t): init with cfg (its clock set to cli_stage_clock_ns), then
 * any number of runs on a->points (a->repeat times: ms[] the medians of the LIDET_DET_N_STAGES stage times and
 * the total); pp (LIDET_MAX_POINTS entries, or NULL) gets each point's pixel for cli_detect_f_ground. det, ds:
 * the detector's own arrays, valid until the next run. 0, or 1 with a message. */
int cli_detect_f_init(const lidet_detector_cfg_t *cfg, const lidet_pn_model_t *mc,
                      const lidet_pn_model_t *mb);
int cli_detect_f_run(const cli_args_t *a, int32_t *pp, double *ms, const lidet_detection_t **det,
                     uint32_t *n_det, const lidet_detector_stats_t **ds, lidet_status_t *status);
/* the last float run's ground flag per point (min(n_points, LIDET_MAX_POINTS) entries) from its pp: 0 or 1 */
int cli_detect_f_ground(const int32_t *pp, uint32_t n_points, uint8_t *point_ground);
/* the last cli_detect_q_run's detections in integer units (the integer detector's array) */
const lidet_detection_q_t *cli_detect_q_detections(uint32_t *n_det);

/* ---- KITTI calibration and boxes in the camera frame (cli_detect.c) ---- */
typedef struct
{
    double P2[12], R0[9], Tr[12];
    int have_p2, have_tr;
} cli_calib_t;
/* a KITTI calib file (P2, R0_rect, Tr_velo_to_cam): 0, or 1 with a message */
int cli_read_calib(const char *path, cli_calib_t *c);
/* a box in KITTI's label terms: observation angle, 2D box (x1 y1 x2 y2 in the 1242 x 375 image), bottom centre
 * in the rectified camera frame, rotation_y */
typedef struct
{
    double alpha, bbox[4], loc[3], ry;
} cli_kitti_t;
/* a sensor-frame box in the camera frame: 0, or 1 when a corner is behind the camera (z < 0.1 m) */
int cli_kitti_box(const cli_calib_t *c, const lidet_box_t *b, cli_kitti_t *out);

/* Subcommands: argc, argv from the subcommand's name on (argv[0] "detect", ...) */
int cli_project(int argc, char **argv);
int cli_ground(int argc, char **argv);
int cli_cluster(int argc, char **argv);
int cli_detect(int argc, char **argv);
int cli_track(int argc, char **argv);
/* `lidet detect --fixed` (cli_detect_q.c): the scan through the integer detector, results as float detections;
 * ms: LIDET_DET_N_STAGES + 1 medians; point_ground / point_cluster optional (n_points entries). returns: NULL (the
 * scan's points, or with --returns their returns), or a->n_points returns the sensor gave (--pcap), fed as they
 * are (lidet_detector_q_run_returns). */
int cli_detect_q_run(const cli_args_t *a, const lidet_detector_cfg_t *fcfg, const char *family,
                     lidet_detection_t *det, uint32_t *n_det, lidet_detector_stats_t *ds, double *ms,
                     uint8_t *point_ground, uint32_t *point_cluster, lidet_status_t *status,
                     const lidet_return_t *returns);
/* `lidet detect --fixed --dump FILE` (cli_detect_q.c): the last integer run's results bit for bit (format at
 * cli_detect_q_dump); point_cluster / point_ground: n_points entries as cli_detect_q_run filled them. 0 or -1. */
int cli_detect_q_dump(const char *path, uint32_t n_points, const uint32_t *point_cluster,
                      const uint8_t *point_ground);

/* ---- packet captures: lidet detect --pcap, lidet track --pcap (cli_pcap.c, docs/CAPTURES.md) ---- */
typedef struct
{
    const char *path;  /* --pcap FILE (NULL: scans from files) */
    const char *lidar; /* --lidar velodyne (default) | ouster (with --ouster-meta M) */
    int port; /* --port N: the data port (0: the lidar's: Velodyne 2368, Ouster the metadata's, 7502) */
    int force_sensor; /* --force-sensor: every packet decoded as --sensor's model (lidet_velodyne_cfg_t.force_model) */
    const char
        *dual;   /* --dual: both | last | strongest (Velodyne), both | first | second (Ouster); NULL: both */
    int partial; /* --partial: also the scans that are not one whole rotation */
    long png_scan; /* --png-scan K (detect): the scan drawn by --png (-1: the last) */
} cli_pcap_opts_t;
/* one scan of a capture */
typedef struct
{
    uint32_t index; /* K: its number among the scans run, from 0 */
    uint8_t kind;   /* lidet_velodyne_scan_t (lidet_ouster_scan_t alike): COMPLETE; with --partial
                                         also PARTIAL, ABORTED and NONE (unfinished at the end of the capture) */
    uint32_t first_frame, last_frame; /* P..Q: the frames of the file (from 0) that hold its returns */
    uint32_t n_returns;               /* returns in the scan (<= LIDET_MAX_POINTS) */
    uint32_t n_excess;                /* returns past LIDET_MAX_POINTS: counted, dropped */
    int64_t t_us; /* the sensor's time of its first packet, us (Velodyne: the payload's timestamp, unwrapped
                         across the hour; Ouster: its first valid column's timestamp) */
    double capture_s; /* the capture's (pcap) timestamp of that packet, s */
} cli_scan_info_t;
typedef struct cli_capture cli_capture_t;
void cli_pcap_opts_default(cli_pcap_opts_t *o);
/* the capture's option set (--pcap FILE, --lidar NAME, --port N, --force-sensor, --dual MODE, --partial) and
 * lidet detect's --png-scan K, both taken by cli_pcap_take into a cli_pcap_opts_t (a bad value: its message, 1) */
extern const cli_opt_t cli_opts_pcap[];
extern const cli_opt_t cli_opts_pcap_png_scan[];
int cli_pcap_take(void *o, int id, const char *value);
/* their usage lines (detect: with --png-scan and the output format) */
void cli_pcap_usage(FILE *f, int detect);
/* Reads the whole capture once (frames counted, the decoder run, the scans listed) and, when --sensor was not
 * given, sets a's sensor (and its --mount-height) to the packets' model. 0 and *c; or 1 with a message (no libpcap
 * in this build, not a capture, no packet, none on the port, no data the decoder takes, no scan to run). */
int cli_capture_open(const cli_pcap_opts_t *o, cli_args_t *a, cli_capture_t **c);
/* --print-sensor with --pcap: the sensor the capture's scans are decoded as (--sensor's model, else the first
 * decoded packet's; --velodyne-calib: the calibration's; --lidar ouster: the metadata's), printed on stdout as
 * cli_sensor_print does, after reading the capture as cli_capture_open does (it need not hold a whole rotation).
 * 0, or 1 with cli_capture_open's messages. */
int cli_capture_print_sensor(const cli_pcap_opts_t *o, cli_args_t *a);
/* the scans listed by cli_capture_open (the number cli_capture_next gives) */
uint32_t cli_capture_n_scans(const cli_capture_t *c);
/* scan k of those (k < cli_capture_n_scans), as pass 1 listed it; NULL past them */
const cli_scan_info_t *cli_capture_info(const cli_capture_t *c, uint32_t k);
/* The next scan: 1 with a->points (x, y, z, 0), a->ring, a->n_points and *returns (the decoder's) pointing into c
 * (valid until the next call; not to be freed) and *info; 0 after the last; -1 with a message. */
int cli_capture_next(cli_capture_t *c, cli_args_t *a, const lidet_return_t **returns, cli_scan_info_t *info);
/* The summary (frames, decoder counts, scans, time: det_ms[n_run] the detector's per scan, may be NULL). 1 when
 * the capture was damaged or cut short (said), else 0: the command's exit status. */
int cli_capture_summary(const cli_capture_t *c, FILE *f, const double *det_ms, uint32_t n_run);
void cli_capture_close(cli_capture_t *c);
/* "complete", "partial", "aborted", "unfinished" */
const char *cli_scan_kind(uint8_t kind);

#define M_PI_D 3.14159265358979323846

/* PNG writer (8-bit RGB, no compression library needed). Returns 0 or -1. */
int lidet_png_write_rgb(const char *path, const uint8_t *rgb, uint32_t width, uint32_t height);
/* A perceptual colour map: t in [0, 1] -> rgb. */
void cli_colormap(float t, uint8_t rgb[3]);

/* One legend entry of a bird's-eye-view picture: a colour swatch and its label. */
typedef struct
{
    const char *label;
    uint8_t rgb[3];
} cli_legend_t;
/* Writes a bird's-eye view (cli_bev.c): the scene (sw x sh RGB pixels of res_m metres, the sensor at the centre,
 * +x up, +y left) in a larger canvas with the title and subtitle (wrapped at their double spaces where too
 * wide), axes in metres (ticks every 10 m and labels every 20 m for a view of 30 m or more each way, 5 / 10 m
 * from 15 m, 2 / 4 m from 6 m, 1 / 2 m below), a scale bar one tick long and the legend (an entry with an
 * empty label: a swatch sharing the next entry's label). Deterministic for the same inputs. Returns 0 or -1. */
int cli_bev_write(const char *path, const uint8_t *scene, uint32_t sw, uint32_t sh, float res_m,
                  const char *title, const char *subtitle, const cli_legend_t *items, int n_items);
/* A scene of a bird's-eye view: w x h RGB pixels of res_m metres, the sensor at the centre, +x up, +y left
 * (cli_bev.c). Drawing clips at its edges. */
typedef struct
{
    uint8_t *rgb;
    uint32_t w, h;
    float res_m;
} cli_scene_t;
/* the points' colours: obstacle (grey) and ground (dark) */
extern const uint8_t cli_rgb_obstacle[3], cli_rgb_ground[3];
void cli_scene_put(const cli_scene_t *s, int u, int v, const uint8_t c[3]);
/* a line between two sensor-frame points, two pixels wide */
void cli_scene_line(const cli_scene_t *s, float x0, float y0, float x1, float y1, const uint8_t c[3]);
/* a box's outline, with heading: a tick from its centre to its front */
void cli_scene_box(const cli_scene_t *s, const lidet_box_t *b, const uint8_t c[3], int heading);
/* points (x, y, z, remission records) as `lidet detect --png` draws them: obstacles grey, ground (ground[i] != 0;
 * ground NULL: none) dark where no other point is */
void cli_scene_points(const cli_scene_t *s, const float *pts, uint32_t n, const uint8_t *ground);
/* makes a folder and the folders above it that are missing (mkdir -p; cli_track.c): 0, or 1 with a message */
int cli_make_dir(const char *path);
/* the file name of a path (after its last '/') */
const char *cli_basename(const char *path);

#endif
