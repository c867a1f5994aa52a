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
 *   track run=R dets=N updates=U insn_...=.. tracks=T confirmed=C births=.. ...   the tracker after the detector
 *                                                       (lidet_tracker_q with LIDET_FIXED_POINT, else lidet_tracker):
 *                                                       run "default" = two updates on run default's detections
 *                                                       (the same scan twice, dt 0.1 s), run "synthetic" = 32 road
 *                                                       users over 20 scans at 10 Hz with ego motion, generated
 *                                                       here (track_scene): instructions per update (first: the
 *                                                       births; max, mean, min over the updates once every track
 *                                                       is confirmed; total: every update) and the last update's
 *                                                       counts
 *   trk R k ID CLASS STATE h0 .. h12 HITS MISSES AGE DET # readable   one track after run R's last update, in id
 *                                                       order (coasting and tentative ones too): the float32 bits
 *                                                       (integer build: the int32 values) of cx, cy, cz, l, w, h,
 *                                                       yaw, vx, vy, p_pp, p_pv, p_vv, score (hex)
 *   stack used=N size=S                                 stack high-water (painted at reset)
 *   lidet-fw: PASS | FAIL (...)
 * No stdio: the few number formats needed are here, so the image carries no printf. */
#include <stdint.h>
#include <string.h>

#include "fw_out.h"
#include "fw_port.h"
#include "fw_scan.h"
#include "lidet/lidet_detector.h"
#include "lidet/lidet_proj.h"
#include "lidet_weights.h"
#if LIDET_FIXED_POINT
#include "lidet/lidet_detector_q.h"
#include "lidet/lidet_track_q.h"
#else
#include "lidet/lidet_track.h"
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
/* The tracker after the detector (lidet_track_q.h / lidet_track.h; its capacities LIDET_TRACK_MAX_TRACKS and
 * LIDET_TRACK_MAX_DETS in config/<sensor>/lidet_user_config.h): state and workspace, ~8 KiB at 32 tracks and 32
 * detections, its own static object as a firmware would hold it. */
#if LIDET_FIXED_POINT
typedef lidet_tracker_q_t fw_tracker_t;
typedef lidet_tracker_q_cfg_t fw_tracker_cfg_t;
typedef lidet_track_q_t fw_track_t;
typedef lidet_ego_q_t fw_ego_t;
typedef lidet_detection_q_t fw_tdet_t;
#else
typedef lidet_tracker_t fw_tracker_t;
typedef lidet_tracker_cfg_t fw_tracker_cfg_t;
typedef lidet_track_t fw_track_t;
typedef lidet_ego_t fw_ego_t;
typedef lidet_detection_t fw_tdet_t;
#endif
static fw_tracker_t g_trk;

/* The tracker benchmark's road users (scene_det, track_scene): 32, over 20 scans at 10 Hz */
#define FW_TRK_OBJECTS 32u
#define FW_TRK_SCANS 20u
#define FW_TRK_DT_MS 100u
#if LIDET_TRACK_MAX_TRACKS < 32 || LIDET_TRACK_MAX_DETS < 32
#error "fw_detect.c's tracker benchmark needs LIDET_TRACK_MAX_TRACKS and LIDET_TRACK_MAX_DETS >= 32"
#endif

/* The test harness's own buffers of the tracker runs (one scan's generated detections, the tracks read back),
 * ~4 KiB: test data, not what a product holds, so they reuse the detector's memory once its last run is done
 * (fw_main reads the tracks and runs the benchmark after the last detector run). */
typedef struct
{
    fw_tdet_t det[FW_TRK_OBJECTS];
    fw_track_t out[LIDET_TRACK_MAX_TRACKS];
} fw_trk_bufs_t;
typedef union
{
    fw_detector_t det;
    fw_trk_bufs_t trk;
} fw_mem_t;
#ifdef LIDET_FW_DETECTOR_SECTION
static fw_mem_t g_mem __attribute__((section(LIDET_FW_DETECTOR_SECTION)));
#else
static fw_mem_t g_mem;
#endif
#define g_det (g_mem.det)
#define g_tb (g_mem.trk)

/* ---- output ---------------------------------------------------------------------------------------- */

#if !LIDET_FIXED_POINT
static uint32_t bits(float f)
{
    uint32_t u;
    memcpy(&u, &f, sizeof u);
    return u;
}

#endif

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
 * the clock in the same order; s: their stats, which share the field names used here). A pair per box net pass:
 * the clusters' (n_boxed) and the group split's parts' (n_group_boxed), in the order they run */
#define rec_stages(r, s, out) rec_stages_((r), (s)->n_boxed + (s)->n_group_boxed, (s)->ticks, (out))
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
#define FW_PUT_HEX(v) fw_put_hex((uint32_t)(v))
#define FW_PUT_V fw_put_i
static const char *const k_val_labels[8] = {" # score_q15 ", " xyz_mm ", " ", " ", " lwh_mm ", " ", " ", " yaw_bam "};
#else
typedef float fw_val_t;
#define FW_VALUES(d)                                                                                               \
    {(d)->score, (d)->box.cx_m, (d)->box.cy_m, (d)->box.cz_m, (d)->box.l_m,                                        \
     (d)->box.w_m, (d)->box.h_m, (d)->box.yaw_rad, (d)->energy_cls, (d)->energy_box}
#define FW_PUT_HEX(v) fw_put_hex(bits(v))
#define FW_PUT_V fw_put_f
static const char *const k_val_labels[8] = {" # score ", " xyz ", " ", " ", " lwh ", " ", " ", " yaw "};
#endif

static void put_det(const char *name, uint32_t k, const fw_detection_t *d)
{
    const fw_val_t v[10] = FW_VALUES(d);
    uint32_t j;
    fw_put_s("det ");
    fw_put_s(name);
    fw_putc(' ');
    fw_put_u(k);
    fw_putc(' ');
    fw_put_s(d->cls < LIDET_N_CLASSES ? fw_class_names[d->cls] : "?");
    fw_putc(' ');
    fw_put_u(d->cluster_id);
    fw_putc(' ');
    fw_put_u(d->n_points);
    for (j = 0; j < 10u; ++j)
    {
        fw_putc(' ');
        FW_PUT_HEX(v[j]);
    }
    for (j = 0; j < 8u; ++j)
    {
        fw_put_s(k_val_labels[j]);
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
        fw_put_s("init run=");
        fw_put_s(name);
        fw_put_s(" failed status=");
        fw_put_i((int32_t)st);
        fw_putc('\n');
        return 1;
    }
    g_rec.n = 0u;
    t0 = fw_insn64();
    st = fw_run(&g_det);
    t1 = fw_insn64();
    s = fw_stats(&g_det);
    det = fw_detections(&g_det, &n_det);

    fw_put_s("stats run=");
    fw_put_s(name);
    fw_put_s(" status=");
    fw_put_i((int32_t)st);
    fw_put_kv("clusters", s->n_clusters);
    fw_put_kv("classified", s->n_classified);
    fw_put_kv("gate1_rejected", s->n_gate1_rejected);
    fw_put_kv("boxed", s->n_boxed);
    fw_put_kv("gate2_rejected", s->n_gate2_rejected);
    fw_put_kv("size_rejected", s->n_size_rejected);
    fw_put_kv("nms_suppressed", s->n_nms_suppressed);
    fw_put_kv("over_budget", s->n_over_budget);
    fw_put_kv("over_capacity", s->n_over_capacity);
    fw_put_kv("detections", n_det);
    fw_putc('\n');
    for (k = 0; k < n_det; ++k)
        put_det(name, k, &det[k]);
    if (fw_have_counter())
    {
        uint64_t stage64[LIDET_DET_N_STAGES];
        if (rec_stages(&g_rec, s, stage64) != 0)
        {
            fw_put_s("insn run=");
            fw_put_s(name);
            fw_put_s(" FAIL: the clock calls do not match the detector's stage order (fw_detect.c: rec_stages)\n");
            return 1;
        }
        fw_put_s("insn run=");
        fw_put_s(name);
        for (k = 0; k < LIDET_DET_N_STAGES; ++k)
        {
            fw_putc(' ');
            fw_put_s(stage_names[k]);
            fw_putc('=');
            fw_put_u64(stage64[k]);
        }
        fw_put_s(" scan="); /* 64 bits: the stages' uint32 counts are checked against it (run_fw.py) */
        fw_put_u64(t1 - t0);
        fw_putc('\n');
    }
    return LIDET_SUCCEEDED(st) ? 0 : 1;
}

/* ---- the tracker after the detector ------------------------------------------------------------------ */

#if LIDET_FIXED_POINT
typedef lidet_tracker_q_stats_t fw_trk_stats_t;
#define fw_trk_cfg_default lidet_tracker_q_cfg_default
#define fw_trk_init lidet_tracker_q_init
#define fw_trk_update(t, d, n, ego) lidet_tracker_q_update((t), (d), (n), FW_TRK_DT_MS, (ego))
#define fw_trk_tracks lidet_tracker_q_tracks
#define fw_trk_stats lidet_tracker_q_stats
#define fw_trk_bytes lidet_tracker_q_bytes
#else
typedef lidet_tracker_stats_t fw_trk_stats_t;
#define fw_trk_cfg_default lidet_tracker_cfg_default
#define fw_trk_init lidet_tracker_init
#define fw_trk_update(t, d, n, ego) lidet_tracker_update((t), (d), (n), 0.1f, (ego))
#define fw_trk_tracks lidet_tracker_tracks
#define fw_trk_stats lidet_tracker_stats
#define fw_trk_bytes lidet_tracker_bytes
#endif

/* The benchmark's scene, in integers only (so that both builds, on every core and on the host, see the same
 * scans): 32 road users in 4 lanes 8 m apart along the world's x (cars at +8 and -6 m/s, cyclists at +4,
 * pedestrians at -1.2; +-0.3 m/s along and +-0.1 m/s across by road user), 9 m apart in their lane, seen by a
 * sensor that moves 0.5 m forward and turns 2 pi / 512 (0.7 deg) to the left per scan (5 m/s, 7 deg/s), which the
 * tracker is given as its ego motion. Each detection's centre carries +-5 cm of uniform noise, its yaw +-0.02 rad,
 * its score is in [0.5, 0.87) (xorshift32), and the detections come in a different order every scan. */
#define FW_TRK_EGO_DX_MM 500
#define FW_TRK_EGO_DYAW_BAM 8388608   /* 2^23: 2 pi / 512 */
#define FW_TRK_EGO_COS_Q30 1073660973 /* round(cos(2 pi / 512) 2^30) */
#define FW_TRK_EGO_SIN_Q30 13176464   /* round(sin(2 pi / 512) 2^30) */

typedef struct
{
    int64_t px_q8, py_q8; /* the sensor's position in the world, 1/256 mm */
    int64_t c_q30, s_q30; /* cos, sin of its heading */
    uint32_t yaw_bam;     /* its heading */
    uint32_t rng;         /* xorshift32 state */
} fw_scene_t;

/* round(v / 2^s), halves away from zero (no shift of a negative value) */
static int64_t rsh_round(int64_t v, unsigned s)
{
    const int64_t h = (int64_t)1 << (s - 1u);
    return v >= 0 ? (v + h) >> s : -((-v + h) >> s);
}

static uint32_t xorshift32(uint32_t *st)
{
    uint32_t x = *st;
    x ^= x << 13;
    x ^= x >> 17;
    x ^= x << 5;
    *st = x;
    return x;
}

/* uint32 -> int32 two's complement without the implementation-defined conversion */
static int32_t wrap_i32(uint32_t a)
{
    return a < 0x80000000u ? (int32_t)a : (int32_t)(a - 0x80000000u) - INT32_MAX - 1;
}

static void scene_start(fw_scene_t *sc)
{
    sc->px_q8 = 0;
    sc->py_q8 = 0;
    sc->c_q30 = (int64_t)1 << 30;
    sc->s_q30 = 0;
    sc->yaw_bam = 0u;
    sc->rng = 0x2545f491u;
}

/* the sensor's motion to the next scan: 0.5 m along its heading, then the turn */
static void scene_advance(fw_scene_t *sc)
{
    const int64_t c = sc->c_q30, sn = sc->s_q30;
    sc->px_q8 += rsh_round(c * (FW_TRK_EGO_DX_MM * 256), 30);
    sc->py_q8 += rsh_round(sn * (FW_TRK_EGO_DX_MM * 256), 30);
    sc->c_q30 = rsh_round(c * FW_TRK_EGO_COS_Q30 - sn * FW_TRK_EGO_SIN_Q30, 30);
    sc->s_q30 = rsh_round(sn * FW_TRK_EGO_COS_Q30 + c * FW_TRK_EGO_SIN_Q30, 30);
    sc->yaw_bam += (uint32_t)FW_TRK_EGO_DYAW_BAM;
}

/* detection j of scan `scan` in the sensor frame: mm, BAM32, Q15 (the integer detection's units) */
typedef struct
{
    int32_t cx_mm, cy_mm, cz_mm, l_mm, w_mm, h_mm, yaw_bam, score_q15;
    uint8_t cls;
} fw_gen_det_t;

static void scene_det(fw_scene_t *sc, uint32_t scan, uint32_t j, fw_gen_det_t *o)
{
    static const int32_t lane_y[4] = {-12000, -4000, 4000, 12000};
    static const int32_t lane_vx[4] = {8000, 4000, -1200, -6000};
    static const uint8_t lane_cls[4] = {LIDET_CLASS_CAR, LIDET_CLASS_CYCLIST, LIDET_CLASS_PEDESTRIAN,
                                        LIDET_CLASS_CAR};
    static const int32_t size[LIDET_N_CLASSES][4] = {
        {-700, 4200, 1800, 1600}, {-900, 1800, 600, 1700}, {-900, 600, 600, 1750}}; /* cz, l, w, h */
    const uint32_t k = (j + 5u * scan) % FW_TRK_OBJECTS, lane = k / 8u, i = k % 8u;
    const int32_t vx = lane_vx[lane] + ((int32_t)(i % 3u) - 1) * 300, vy = (i & 1u) != 0u ? 100 : -100;
    /* the road user in the world (mm; exact: the speeds are multiples of 10 mm/s), then in the sensor frame */
    const int64_t xw = -31500 + 9000 * (int64_t)i + (int64_t)vx * scan / 10;
    const int64_t yw = lane_y[lane] + (int64_t)vy * scan / 10;
    const int64_t dx = xw * 256 - sc->px_q8, dy = yw * 256 - sc->py_q8;
    const uint8_t cls = lane_cls[lane];
    o->cx_mm = (int32_t)rsh_round(sc->c_q30 * dx + sc->s_q30 * dy, 38);
    o->cy_mm = (int32_t)rsh_round(sc->c_q30 * dy - sc->s_q30 * dx, 38);
    o->cx_mm += (int32_t)(xorshift32(&sc->rng) % 101u) - 50;
    o->cy_mm += (int32_t)(xorshift32(&sc->rng) % 101u) - 50;
    o->cz_mm = size[cls][0];
    o->l_mm = size[cls][1];
    o->w_mm = size[cls][2];
    o->h_mm = size[cls][3];
    o->yaw_bam = wrap_i32((vx > 0 ? 0u : 0x80000000u) - sc->yaw_bam +
                          (uint32_t)((int32_t)(xorshift32(&sc->rng) % 27340001u) - 13670000)); /* +-0.02 rad */
    o->score_q15 = 16384 + (int32_t)(xorshift32(&sc->rng) % 12000u);
    o->cls = cls;
}

#if LIDET_FIXED_POINT
static const fw_ego_t k_trk_ego = {FW_TRK_EGO_DX_MM, 0, FW_TRK_EGO_DYAW_BAM};

static void to_tdet(const fw_gen_det_t *g, uint32_t j, fw_tdet_t *d)
{
    memset(d, 0, sizeof *d);
    d->box.cx_mm = g->cx_mm;
    d->box.cy_mm = g->cy_mm;
    d->box.cz_mm = g->cz_mm;
    d->box.l_mm = g->l_mm;
    d->box.w_mm = g->w_mm;
    d->box.h_mm = g->h_mm;
    d->box.yaw_bam = g->yaw_bam;
    d->score_q15 = g->score_q15;
    d->cls = g->cls;
    d->cluster_id = (uint16_t)(j + 1u);
}
#else
#define FW_BAM_RAD 1.46291807926715968e-9f /* 2 pi / 2^32 */
static const fw_ego_t k_trk_ego = {0.5f, 0.0f, FW_BAM_RAD * FW_TRK_EGO_DYAW_BAM}; /* FW_TRK_EGO_DX_MM, _DYAW_BAM */

/* the same scene in metres and radians (IEEE single precision: the same bits on every core) */
static void to_tdet(const fw_gen_det_t *g, uint32_t j, fw_tdet_t *d)
{
    memset(d, 0, sizeof *d);
    d->box.cx_m = (float)g->cx_mm * 0.001f;
    d->box.cy_m = (float)g->cy_mm * 0.001f;
    d->box.cz_m = (float)g->cz_mm * 0.001f;
    d->box.l_m = (float)g->l_mm * 0.001f;
    d->box.w_m = (float)g->w_mm * 0.001f;
    d->box.h_m = (float)g->h_mm * 0.001f;
    d->box.yaw_rad = (float)g->yaw_bam * FW_BAM_RAD;
    d->score = (float)g->score_q15 * (1.0f / 32768.0f);
    d->cls = g->cls;
    d->cluster_id = j + 1u;
}
#endif

/* One track: its 13 values (cx, cy, cz, l, w, h, yaw, vx, vy, p_pp, p_pv, p_vv, score) as hex words, which
 * run_fw.py compares with the host, hits, misses, age and detection index, then x, y, vx, vy readable. */
#if LIDET_FIXED_POINT
#define FW_TRACK_VALUES(t)                                                                                         \
    {(t)->box.cx_mm, (t)->box.cy_mm, (t)->box.cz_mm, (t)->box.l_mm, (t)->box.w_mm, (t)->box.h_mm,                 \
     (t)->box.yaw_bam, (t)->vx_mmps, (t)->vy_mmps, (t)->p_pp, (t)->p_pv, (t)->p_vv, (t)->score_q15}
#else
#define FW_TRACK_VALUES(t)                                                                                         \
    {(t)->box.cx_m, (t)->box.cy_m, (t)->box.cz_m, (t)->box.l_m, (t)->box.w_m, (t)->box.h_m, (t)->box.yaw_rad,      \
     (t)->vx_mps, (t)->vy_mps, (t)->p_pp_m2, (t)->p_pv, (t)->p_vv, (t)->score}
#endif

static void put_track(const char *run, uint32_t k, const fw_track_t *t)
{
    static const char *const state_names[3] = {"tentative", "confirmed", "coasting"};
    const fw_val_t v[13] = FW_TRACK_VALUES(t);
    uint32_t j;
    fw_put_s("trk ");
    fw_put_s(run);
    fw_putc(' ');
    fw_put_u(k);
    fw_putc(' ');
    fw_put_u(t->id);
    fw_putc(' ');
    fw_put_s(t->cls < LIDET_N_CLASSES ? fw_class_names[t->cls] : "?");
    fw_putc(' ');
    fw_put_s(t->state < 3u ? state_names[t->state] : "?");
    for (j = 0; j < 13u; ++j)
    {
        fw_putc(' ');
        FW_PUT_HEX(v[j]);
    }
    fw_putc(' ');
    fw_put_u(t->hits);
    fw_putc(' ');
    fw_put_u(t->misses);
    fw_putc(' ');
    fw_put_u(t->age);
    fw_putc(' ');
    fw_put_i(t->det_index);
    fw_put_s(" # xy ");
    FW_PUT_V(v[0]);
    fw_putc(' ');
    FW_PUT_V(v[1]);
    fw_put_s(" v ");
    FW_PUT_V(v[7]);
    fw_putc(' ');
    FW_PUT_V(v[8]);
    fw_putc('\n');
}

/* the summary line of one tracker run (insn: n_insn named counts, printed only with a counter) and its tracks,
 * read back into the harness's buffer (the detector's memory: called after the last detector run) */
static void put_tracker_run(const char *run, uint32_t n_det, uint32_t n_upd, lidet_status_t st,
                            const char *const *insn_names, const uint64_t *insn, uint32_t n_insn)
{
    const fw_trk_stats_t *ts = fw_trk_stats(&g_trk);
    uint32_t k, n;
    fw_put_s("track run=");
    fw_put_s(run);
    fw_put_kv("dets", n_det);
    fw_put_kv("updates", n_upd);
    for (k = 0; k < n_insn && fw_have_counter(); ++k)
    {
        fw_put_s(" insn_");
        fw_put_s(insn_names[k]);
        fw_putc('=');
        fw_put_u64(insn[k]);
    }
    fw_put_s(" status=");
    fw_put_i((int32_t)st);
    fw_put_kv("tracks", ts->n_tracks);
    fw_put_kv("confirmed", ts->n_confirmed);
    fw_put_kv("births", ts->n_births);
    fw_put_kv("births_dropped", ts->n_births_dropped);
    fw_put_kv("deaths", ts->n_deaths);
    fw_put_kv("matched", ts->n_matched);
    fw_put_kv("feasible", ts->n_feasible_pairs);
    fw_put_kv("dets_dropped", ts->n_dets_dropped);
    fw_put_kv("bad_dets", ts->n_bad_dets);
    fw_putc('\n');
    n = fw_trk_tracks(&g_trk, g_tb.out, LIDET_TRACK_MAX_TRACKS, LIDET_TRACK_OUT_COASTING | LIDET_TRACK_OUT_TENTATIVE);
    for (k = 0; k < n; ++k)
        put_track(run, k, &g_tb.out[k]);
}

/* Run default's detections into the tracker, twice (the same scan 0.1 s later, the sensor still): the tracker
 * as a firmware runs it, on the detector's output in place. Its tracks are read at the end (put_tracker_run).
 * track_detections and track_scene are not inlined: their locals stay off fw_main's frame, which is under the
 * detector's deepest stack (the integer images reserve 4 KiB, run_fw.py fails above 80 % of it). */
static uint64_t g_trk_det_insn[3]; /* first, second update, both */
static uint32_t g_trk_det_n;
static lidet_status_t g_trk_det_st;

static __attribute__((noinline)) int track_detections(void)
{
    fw_tracker_cfg_t tc;
    const fw_detection_t *det;
    uint32_t u;
    fw_trk_cfg_default(&tc);
    if (fw_trk_init(&g_trk, &tc) != LIDET_OK)
        return 1;
    det = fw_detections(&g_det, &g_trk_det_n);
    for (u = 0; u < 2u; ++u)
    {
        const uint64_t t0 = fw_insn64();
        g_trk_det_st = fw_trk_update(&g_trk, det, g_trk_det_n, 0);
        g_trk_det_insn[u] = fw_insn64() - t0;
        g_trk_det_insn[2] += g_trk_det_insn[u];
        if (!LIDET_SUCCEEDED(g_trk_det_st))
            return 1;
    }
    return 0;
}

/* The benchmark: the scene's 20 scans; instructions of every update; the updates from the third scan on have
 * 32 confirmed tracks and 32 detections (checked: else the image fails). The tracker's state from
 * track_detections is read out first. */
static __attribute__((noinline)) int track_scene(void)
{
    static const char *const det_names[3] = {"first", "second", "total"};
    static const char *const names[6] = {"first", "second", "max", "mean", "min", "total"};
    fw_tracker_cfg_t tc;
    fw_scene_t sc;
    fw_gen_det_t g;
    uint64_t insn[6] = {0u, 0u, 0u, 0u, UINT64_MAX, 0u}, sum = 0u;
    uint32_t scan, j, n_meas = 0u;
    lidet_status_t st = LIDET_OK;
    int bad = 0;

    put_tracker_run("default", g_trk_det_n, 2u, g_trk_det_st, det_names, g_trk_det_insn, 3u);

    fw_trk_cfg_default(&tc);
    if (fw_trk_init(&g_trk, &tc) != LIDET_OK)
        return 1;
    scene_start(&sc);
    for (scan = 0; scan < FW_TRK_SCANS; ++scan)
    {
        const fw_trk_stats_t *ts;
        uint64_t t0, d;
        for (j = 0; j < FW_TRK_OBJECTS; ++j)
        {
            scene_det(&sc, scan, j, &g);
            to_tdet(&g, j, &g_tb.det[j]);
        }
        t0 = fw_insn64();
        st = fw_trk_update(&g_trk, g_tb.det, FW_TRK_OBJECTS, scan > 0u ? &k_trk_ego : 0);
        d = fw_insn64() - t0;
        ts = fw_trk_stats(&g_trk);
        insn[5] += d;
        bad |= st != LIDET_OK;
        if (scan < 2u)
        {
            insn[scan] = d;
        }
        else
        {
            bad |= ts->n_tracks != FW_TRK_OBJECTS || ts->n_confirmed != FW_TRK_OBJECTS ||
                   ts->n_matched != FW_TRK_OBJECTS;
            insn[2] = d > insn[2] ? d : insn[2];
            insn[4] = d < insn[4] ? d : insn[4];
            sum += d;
            ++n_meas;
        }
        scene_advance(&sc);
    }
    insn[3] = n_meas > 0u ? (sum + n_meas / 2u) / n_meas : 0u;
    put_tracker_run("synthetic", FW_TRK_OBJECTS, FW_TRK_SCANS, st, names, insn, 6u);
    if (bad)
        fw_put_s("track run=synthetic FAIL: not 32 confirmed tracks matched in every update from the third scan\n");
    return bad;
}

int fw_main(void)
{
    /* the configuration lives in .bss, not on the stack under the detector's deepest call (the Cortex-M0+ image
     * has its stack's 80 % headroom to keep) */
    static fw_cfg_t cfg;
    const fw_model_t *mc = 0, *mb = 0;
#if LIDET_FIXED_POINT
    const lidet_sensor_q_t *sensor = lidet_sensor_q_find(FW_SENSOR);
#else
    const lidet_sensor_t *sensor = lidet_sensor_find(FW_SENSOR);
#endif
    const char *family = pick_models(&mc, &mb);
    int bad = 0, c;

    fw_put_s("lidet-fw board=");
    fw_put_s(fw_board_name);
    fw_put_s(" core=");
    fw_put_s(fw_core_name);
    fw_put_s(" build=" FW_BUILD " sensor=" FW_SENSOR " models=");
    fw_put_s(family != 0 ? family : "none");
    fw_put_s(" scan=");
    fw_put_s(fw_scan_name);
    fw_put_kv("points", fw_scan_n);
    fw_put_kv("ring", (uint32_t)fw_scan_has_ring);
#if LIDET_FIXED_POINT
    fw_put_kv("returns", (uint32_t)fw_scan_has_returns);
#endif
    fw_putc('\n');
    fw_put_s("mem");
#if LIDET_FIXED_POINT
    fw_put_kv("detector_bytes", lidet_detector_q_bytes());
#else
    fw_put_kv("detector_bytes", lidet_detector_bytes());
#endif
    fw_put_kv("max_rows", LIDET_MAX_ROWS);
    fw_put_kv("max_cols", LIDET_MAX_COLS);
    fw_put_kv("max_points", LIDET_MAX_POINTS);
    fw_put_kv("max_clusters", LIDET_MAX_CLUSTERS);
    fw_put_kv("tracker_bytes", fw_trk_bytes());
    fw_put_kv("track_max_tracks", LIDET_TRACK_MAX_TRACKS);
    fw_put_kv("track_max_dets", LIDET_TRACK_MAX_DETS);
    fw_putc('\n');
    if (family == 0 || sensor == 0)
    {
        fw_put_s("lidet-fw: FAIL (no models or no " FW_SENSOR " sensor profile)\n");
        return 1;
    }
    if (fw_have_counter() && fw_calibrate(1) != 0)
    {
        fw_put_s("lidet-fw: FAIL (instruction counter does not match the calibration loop)\n");
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
    /* the tracker after it, on its detections (read out at the end) */
    bad |= track_detections();
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
    /* the detector's work is done: the tracker runs' tracks and the benchmark (its buffers reuse the detector's
     * memory) */
    bad |= track_scene();

    fw_put_s("stack");
    fw_put_kv("used", fw_stack_used());
    fw_put_kv("size", fw_stack_size());
    fw_putc('\n');
    fw_put_s(bad ? "lidet-fw: FAIL (a detector or tracker run failed)\n" : "lidet-fw: PASS\n");
    return bad;
}
