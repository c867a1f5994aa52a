/* SPDX-License-Identifier: MIT */
/* The firmware application: the whole detector (lidet_detector.h; the integer detector lidet_detector_q.h when
 * built with LIDET_FIXED_POINT, on the scan in millimetres) on the scan stored in flash (fw_scan.h)
 * with the capacities of config/<FW_SENSOR>/lidet_user_config.h, twice: once with the default configuration
 * (gates and size checks as they are) and once with the gates and size checks off, so that many boxes reach
 * the output and the comparison with the host is not vacuous.
 * It prints, line by line (parsed by tools/firmware/run_fw.py, which compares them with the host build):
 *   lidet-fw board=... core=... build=float ...        the target
 *   mem detector_bytes=N                                sizeof(lidet_detector_t)
 *   calib n=N expected=E measured=M                     the instruction counter against a loop of known length
 *   stats run=R status=S clusters=... detections=D      the detector's counts
 *   det R k CLASS CLUSTER NPTS h0 .. h9 # readable      one detection: its cluster id and points, the float32
 *                                                       bits of score, cx, cy, cz, l, w, h, yaw, energy_cls,
 *                                                       energy_box (hex), then decimals for people; the
 *                                                       integer build prints its int32 values (score Q15, mm,
 *                                                       BAM32 yaw, Q16 energies) as 32-bit hex
 *   insn run=R project=.. ground=.. cluster=.. classify=.. box=.. post=.. scan=..   instructions per stage
 *   stack used=N size=S                                 stack high-water (painted at reset)
 *   lidet-fw: PASS | FAIL (...)
 * No stdio: the few number formats needed are here, so the image carries no printf. */
#include <stdint.h>
#include <string.h>

#include "fw_port.h"
#include "fw_scan.h"
#include "lidet/lidet_detector.h"
#include "lidet/lidet_proj.h"
#include "lidet_weights.h"
#if LIDET_FIXED_POINT
#include "lidet/lidet_detector_q.h"
#endif

/* The detector: ~1 MiB at the VLP-16 capacities (~4.4 MiB for HDL-64), in .bss. A board with several RAM banks
 * places it with a section attribute instead, e.g. -DLIDET_FW_DETECTOR_SECTION='".bss.sram2"' and a matching
 * output section in its linker script (docs/PORTING.md). */
#if LIDET_FIXED_POINT
typedef lidet_detector_q_t fw_detector_t;
typedef lidet_pointnet_q_model_t fw_model_t;
#define FW_BUILD "fixed"
#else
typedef lidet_detector_t fw_detector_t;
typedef lidet_pn_model_t fw_model_t;
#define FW_BUILD "float"
#endif
#ifdef LIDET_FW_DETECTOR_SECTION
static fw_detector_t g_det __attribute__((section(LIDET_FW_DETECTOR_SECTION)));
#else
static fw_detector_t g_det;
#endif

static const char *const k_class_names[LIDET_N_CLASSES] = {"Car", "Cyclist", "Pedestrian"};

/* ---- output ---------------------------------------------------------------------------------------- */

static void put_s(const char *s)
{
    while (*s != '\0')
        fw_putc(*s++);
}

static void put_u(uint32_t v)
{
    char b[11];
    int n = 0;
    do
    {
        b[n++] = (char)('0' + v % 10u);
        v /= 10u;
    } while (v != 0u);
    while (n > 0)
        fw_putc(b[--n]);
}

static void put_u64(uint64_t v)
{
    char b[21];
    int n = 0;
    do
    {
        b[n++] = (char)('0' + (unsigned)(v % 10u));
        v /= 10u;
    } while (v != 0u);
    while (n > 0)
        fw_putc(b[--n]);
}

static void put_i(int32_t v)
{
    if (v < 0)
    {
        fw_putc('-');
        put_u((uint32_t)(-(v + 1)) + 1u);
    }
    else
        put_u((uint32_t)v);
}

static void put_hex(uint32_t v)
{
    int k;
    for (k = 28; k >= 0; k -= 4)
        fw_putc("0123456789abcdef"[(v >> k) & 15u]);
}

#if !LIDET_FIXED_POINT
static uint32_t bits(float f)
{
    uint32_t u;
    memcpy(&u, &f, sizeof u);
    return u;
}

/* fixed-point decimal with 4 digits (readability only; the comparison reads the hex bits) */
static void put_f(float f)
{
    uint32_t whole, frac;
    if (!(f == f))
    {
        put_s("nan");
        return;
    }
    if (f < 0.0f)
    {
        fw_putc('-');
        f = -f;
    }
    if (f >= 1.0e6f)
    {
        put_s("big");
        return;
    }
    whole = (uint32_t)f;
    frac = (uint32_t)((f - (float)whole) * 10000.0f + 0.5f);
    if (frac >= 10000u)
    {
        ++whole;
        frac -= 10000u;
    }
    put_u(whole);
    fw_putc('.');
    fw_putc((char)('0' + frac / 1000u));
    fw_putc((char)('0' + frac / 100u % 10u));
    fw_putc((char)('0' + frac / 10u % 10u));
    fw_putc((char)('0' + frac % 10u));
}

#endif

static void put_kv(const char *key, uint32_t v)
{
    fw_putc(' ');
    put_s(key);
    fw_putc('=');
    put_u(v);
}

/* ---- models ---------------------------------------------------------------------------------------- */

/* The sensor of the build (FW_SENSOR, with its capacities in config/<sensor>/lidet_user_config.h) */
#ifndef FW_SENSOR
#define FW_SENSOR "vlp16"
#endif

/* The sensor's own models (weights/cls_<sensor>, box_<sensor>), referenced by name: only these two are
 * linked (each model is its own object in the weights archive; the index lidet_weights_models, which
 * would pull in every model, is not referenced). FW_SENSOR_ID is the sensor as an identifier; FW_MODELS_ID the
 * model family (LIDET_FW_MODELS; the sensor's own by default). */
#ifndef FW_SENSOR_ID
#define FW_SENSOR_ID vlp16
#endif
#ifndef FW_MODELS_ID
#define FW_MODELS_ID FW_SENSOR_ID
#define FW_MODELS FW_SENSOR
#endif
#define FW_XCAT(a, b) a##b
#define FW_CAT(a, b) FW_XCAT(a, b)
static const char *pick_models(const fw_model_t **cls, const fw_model_t **box)
{
#if LIDET_FIXED_POINT
    *cls = &FW_CAT(FW_CAT(lidet_model_cls_, FW_MODELS_ID), _s8);
    *box = &FW_CAT(FW_CAT(lidet_model_box_, FW_MODELS_ID), _s8);
    return FW_MODELS "_s8";
#else
    *cls = &FW_CAT(lidet_model_cls_, FW_MODELS_ID);
    *box = &FW_CAT(lidet_model_box_, FW_MODELS_ID);
    return FW_MODELS;
#endif
}

/* ---- 64-bit stage counts ------------------------------------------------------------------------------ */

/* The detector's per-stage ticks are uint32 (lidet_detector_stats_t), and a scan on a core without FPU runs
 * past 2^32 instructions (the Cortex-M3's box net alone: ~5.5 G). So the clock hook also records every
 * 64-bit timestamp it hands out, and the stages are rebuilt from them in the order the detector takes them:
 * 4 calls around projection, ground and clustering (lidet_workspace_run_timed), the classification start,
 * a pair around each box net, the classification end, and a pair around the post-processing. The low 32 bits
 * of every rebuilt stage must equal the detector's own ticks, which checks that order at every run. */
#define REC_MAX (8u + 2u * LIDET_MAX_CLUSTERS)

typedef struct
{
    uint64_t t[REC_MAX];
    uint32_t n;
} rec_t;

static rec_t g_rec;

static uint32_t rec_clock(void *ctx)
{
    rec_t *r = (rec_t *)ctx;
    const uint64_t v = fw_insn64();
    if (r->n < REC_MAX)
        r->t[r->n] = v;
    ++r->n;
    return (uint32_t)v;
}

/* -> 0 and out[] filled, or 1 when the recorded calls do not match the detector's order (both detectors call
 * the clock in the same order; s: their stats, which share the field names used here) */
#define rec_stages(r, s, out) rec_stages_((r), (s)->n_boxed, (s)->ticks, (out))
static int rec_stages_(const rec_t *r, uint32_t nb, const uint32_t *ticks, uint64_t out[LIDET_DET_N_STAGES])
{
    uint64_t box = 0u;
    uint32_t k;
    if (r->n != 8u + 2u * nb || r->n > REC_MAX)
        return 1;
    out[LIDET_DET_STAGE_PROJECT] = r->t[1] - r->t[0];
    out[LIDET_DET_STAGE_GROUND] = r->t[2] - r->t[1];
    out[LIDET_DET_STAGE_CLUSTER] = r->t[3] - r->t[2];
    for (k = 0; k < nb; ++k)
        box += r->t[6u + 2u * k] - r->t[5u + 2u * k];
    out[LIDET_DET_STAGE_BOX] = box;
    out[LIDET_DET_STAGE_CLASSIFY] = (r->t[5u + 2u * nb] - r->t[4]) - box;
    out[LIDET_DET_STAGE_POST] = r->t[7u + 2u * nb] - r->t[6u + 2u * nb];
    for (k = 0; k < LIDET_DET_N_STAGES; ++k)
        if ((uint32_t)out[k] != ticks[k])
            return 1;
    return 0;
}

/* ---- one run ---------------------------------------------------------------------------------------- */

#if LIDET_FIXED_POINT
typedef lidet_detector_q_cfg_t fw_cfg_t;
typedef lidet_detector_q_stats_t fw_stats_t;
typedef lidet_detection_q_t fw_detection_t;
#define fw_init lidet_detector_q_init
/* the scan as the sensor's returns where the build has them (the firmware's way in: docs/PORTING.md), else, and
 * in run "points", as points in mm */
static int g_points;
#define fw_run(d)                                                                                                  \
    (fw_scan_has_returns && !g_points                                                                            \
         ? lidet_detector_q_run_returns((d), fw_scan_returns, fw_scan_n, 0)                                      \
         : lidet_detector_q_run((d), fw_scan_xyz_mm, fw_scan_n, 3u, fw_scan_has_ring ? fw_scan_ring : 0, 0))
#define fw_stats lidet_detector_q_stats
#define fw_detections lidet_detector_q_detections
#else
typedef lidet_detector_cfg_t fw_cfg_t;
typedef lidet_detector_stats_t fw_stats_t;
typedef lidet_detection_t fw_detection_t;
#define fw_init lidet_detector_init
#define fw_run(d) lidet_detector_run((d), fw_scan_xyz, fw_scan_n, 3u, fw_scan_has_ring ? fw_scan_ring : 0, 0)
#define fw_stats lidet_detector_stats
#define fw_detections lidet_detector_detections
#endif

/* One detection: its 10 values (score, box x y z l w h yaw, both energies) as hex words, which run_fw.py compares
 * with the host, then the first 8 again in readable form after a '#' (integers in the fixed build). */
#if LIDET_FIXED_POINT
typedef int32_t fw_val_t;
#define FW_VALUES(d)                                                                                               \
    {(d)->score_q15, (d)->box.cx_mm, (d)->box.cy_mm, (d)->box.cz_mm,  (d)->box.l_mm,                               \
     (d)->box.w_mm,  (d)->box.h_mm,  (d)->box.yaw_bam, (d)->energy_cls_q16, (d)->energy_box_q16}
#define FW_PUT_HEX(v) put_hex((uint32_t)(v))
#define FW_PUT_V put_i
static const char *const k_val_labels[8] = {" # score_q15 ", " xyz_mm ", " ", " ", " lwh_mm ", " ", " ", " yaw_bam "};
#else
typedef float fw_val_t;
#define FW_VALUES(d)                                                                                               \
    {(d)->score, (d)->box.cx_m, (d)->box.cy_m, (d)->box.cz_m, (d)->box.l_m,                                        \
     (d)->box.w_m, (d)->box.h_m, (d)->box.yaw_rad, (d)->energy_cls, (d)->energy_box}
#define FW_PUT_HEX(v) put_hex(bits(v))
#define FW_PUT_V put_f
static const char *const k_val_labels[8] = {" # score ", " xyz ", " ", " ", " lwh ", " ", " ", " yaw "};
#endif

static void put_det(const char *name, uint32_t k, const fw_detection_t *d)
{
    const fw_val_t v[10] = FW_VALUES(d);
    uint32_t j;
    put_s("det ");
    put_s(name);
    fw_putc(' ');
    put_u(k);
    fw_putc(' ');
    put_s(d->cls < LIDET_N_CLASSES ? k_class_names[d->cls] : "?");
    fw_putc(' ');
    put_u(d->cluster_id);
    fw_putc(' ');
    put_u(d->n_points);
    for (j = 0; j < 10u; ++j)
    {
        fw_putc(' ');
        FW_PUT_HEX(v[j]);
    }
    for (j = 0; j < 8u; ++j)
    {
        put_s(k_val_labels[j]);
        FW_PUT_V(v[j]);
    }
    fw_putc('\n');
}

static int run_once(const char *name, const fw_cfg_t *cfg, const fw_model_t *mc, const fw_model_t *mb)
{
    static const char *const stage_names[LIDET_DET_N_STAGES] = {"project", "ground", "cluster",
                                                                 "classify", "box", "post"};
    const fw_stats_t *s;
    const fw_detection_t *det;
    lidet_status_t st;
    uint32_t n_det = 0, k;
    uint64_t t0, t1;

    st = fw_init(&g_det, cfg, mc, mb);
    if (st != LIDET_OK)
    {
        put_s("init run=");
        put_s(name);
        put_s(" failed status=");
        put_i((int32_t)st);
        fw_putc('\n');
        return 1;
    }
    g_rec.n = 0u;
    t0 = fw_insn64();
    st = fw_run(&g_det);
    t1 = fw_insn64();
    s = fw_stats(&g_det);
    det = fw_detections(&g_det, &n_det);

    put_s("stats run=");
    put_s(name);
    put_s(" status=");
    put_i((int32_t)st);
    put_kv("clusters", s->n_clusters);
    put_kv("classified", s->n_classified);
    put_kv("gate1_rejected", s->n_gate1_rejected);
    put_kv("boxed", s->n_boxed);
    put_kv("gate2_rejected", s->n_gate2_rejected);
    put_kv("size_rejected", s->n_size_rejected);
    put_kv("nms_suppressed", s->n_nms_suppressed);
    put_kv("over_budget", s->n_over_budget);
    put_kv("over_capacity", s->n_over_capacity);
    put_kv("detections", n_det);
    fw_putc('\n');
    for (k = 0; k < n_det; ++k)
        put_det(name, k, &det[k]);
    if (fw_have_counter())
    {
        uint64_t stage64[LIDET_DET_N_STAGES];
        if (rec_stages(&g_rec, s, stage64) != 0)
        {
            put_s("insn run=");
            put_s(name);
            put_s(" FAIL: the clock calls do not match the detector's stage order (fw_detect.c: rec_stages)\n");
            return 1;
        }
        put_s("insn run=");
        put_s(name);
        for (k = 0; k < LIDET_DET_N_STAGES; ++k)
        {
            fw_putc(' ');
            put_s(stage_names[k]);
            fw_putc('=');
            put_u64(stage64[k]);
        }
        put_s(" scan="); /* 64 bits: the stages' uint32 counts are checked against it (run_fw.py) */
        put_u64(t1 - t0);
        fw_putc('\n');
    }
    return LIDET_SUCCEEDED(st) ? 0 : 1;
}

/* The counter against loops of known length. measure() is one function whatever n is (n arrives in a
 * register), so the instructions around the loop are the same in every call; the difference of two loops
 * removes them (and the clock calls), so measured must equal expected exactly. */
static __attribute__((noinline)) uint32_t measure(uint32_t n)
{
    const uint32_t t0 = fw_clock(0);
    fw_spin(n);
    return fw_clock(0) - t0;
}

static int calibrate(void)
{
    static volatile uint32_t lens[4] = {1u, 1000u, 12345u, 1000000u}; /* volatile: no constant folding */
    uint32_t base, k;
    int bad = 0;
    base = measure(lens[0]);
    for (k = 1; k < 4u; ++k)
    {
        const uint32_t n = lens[k];
        const uint32_t measured = measure(n) - base;
        const uint32_t expected = fw_spin_insn(n) - fw_spin_insn(lens[0]);
        put_s("calib");
        put_kv("n", n);
        put_kv("expected", expected);
        put_kv("measured", measured);
        fw_putc('\n');
        bad |= measured != expected;
    }
    /* a loop longer than a 32-bit tick counter can hold at 6.4 ticks per instruction (MPS2: 671 M): the
     * counter must be extended past its wrap. Here the wrap handler's few instructions count too. */
    {
        static volatile uint32_t long_n = 350000000u;
        const uint32_t n = long_n;
        const uint32_t measured = measure(n) - base;
        const uint32_t expected = fw_spin_insn(n) - fw_spin_insn(lens[0]);
        put_s("calib_long");
        put_kv("n", n);
        put_kv("expected", expected);
        put_kv("measured", measured);
        fw_putc('\n');
        bad |= measured < expected || measured - expected > 64u;
    }
    return bad;
}

int fw_main(void)
{
    fw_cfg_t cfg;
    const fw_model_t *mc = 0, *mb = 0;
#if LIDET_FIXED_POINT
    const lidet_sensor_q_t *sensor = lidet_sensor_q_find(FW_SENSOR);
#else
    const lidet_sensor_t *sensor = lidet_sensor_find(FW_SENSOR);
#endif
    const char *family = pick_models(&mc, &mb);
    int bad = 0, c;

    put_s("lidet-fw board=");
    put_s(fw_board_name);
    put_s(" core=");
    put_s(fw_core_name);
    put_s(" build=" FW_BUILD " sensor=" FW_SENSOR " models=");
    put_s(family != 0 ? family : "none");
    put_s(" scan=");
    put_s(fw_scan_name);
    put_kv("points", fw_scan_n);
    put_kv("ring", (uint32_t)fw_scan_has_ring);
#if LIDET_FIXED_POINT
    put_kv("returns", (uint32_t)fw_scan_has_returns);
#endif
    fw_putc('\n');
    put_s("mem");
#if LIDET_FIXED_POINT
    put_kv("detector_bytes", lidet_detector_q_bytes());
#else
    put_kv("detector_bytes", lidet_detector_bytes());
#endif
    put_kv("max_rows", LIDET_MAX_ROWS);
    put_kv("max_cols", LIDET_MAX_COLS);
    put_kv("max_points", LIDET_MAX_POINTS);
    put_kv("max_clusters", LIDET_MAX_CLUSTERS);
    fw_putc('\n');
    if (family == 0 || sensor == 0)
    {
        put_s("lidet-fw: FAIL (no models or no " FW_SENSOR " sensor profile)\n");
        return 1;
    }
    if (fw_have_counter() && calibrate() != 0)
    {
        put_s("lidet-fw: FAIL (instruction counter does not match the calibration loop)\n");
        return 1;
    }

    /* run 1: the configuration a user gets (gates and size checks on) */
#if LIDET_FIXED_POINT
    lidet_detector_q_cfg_default(&cfg, sensor);
#else
    lidet_detector_cfg_default(&cfg, sensor);
#endif
    cfg.clock = rec_clock;
    cfg.clock_ctx = &g_rec;
    bad |= run_once("default", &cfg, mc, mb);
    /* run 2: gates and size checks off, so that every classified proposal is boxed and reported */
    cfg.gate1 = 0u;
    cfg.gate2 = 0u;
    for (c = 0; c < LIDET_N_CLASSES; ++c)
    {
        int j;
        for (j = 0; j < 3; ++j)
        {
#if LIDET_FIXED_POINT
            cfg.size.min_mm[c][j] = 1;
            cfg.size.max_mm[c][j] = LIDET_Q_BOX_MAX_MM;
#else
            cfg.size_min_m[c][j] = 0.0f;
            cfg.size_max_m[c][j] = 1000.0f;
#endif
        }
    }
    bad |= run_once("open", &cfg, mc, mb);
#if LIDET_FIXED_POINT
    if (fw_scan_has_returns)
    {
        /* run 3: the configuration of run 1 on the same scan as points in mm (lidet_detector_q_run: the
         * projection from x, y, z) */
        lidet_detector_q_cfg_default(&cfg, sensor);
        cfg.clock = rec_clock;
        cfg.clock_ctx = &g_rec;
        g_points = 1;
        bad |= run_once("points", &cfg, mc, mb);
    }
#endif

    put_s("stack");
    put_kv("used", fw_stack_used());
    put_kv("size", fw_stack_size());
    fw_putc('\n');
    put_s(bad ? "lidet-fw: FAIL (a detector run failed)\n" : "lidet-fw: PASS\n");
    return bad;
}
