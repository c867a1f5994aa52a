/* SPDX-License-Identifier: MIT */
/* The packet application (LIDET_FW_APP=packets; integer build only): what a board does with a lidar's UDP stream.
 * The payloads of one rotation and a bit (fw_packets.h, in flash) are decoded one at a time into a buffer of one
 * payload's returns and streamed into the integer detector (lidet_detector_q_stream_begin at the first seam,
 * _returns per payload, _end when the decoder reports the rotation COMPLETE): no buffer for the scan (docs/PORTING.md,
 * "Streaming the returns"). The decoder: a VLP-16's (lidet_velodyne_packet, LIDET_VELODYNE_MAX_RETURNS returns a
 * payload), or with FW_OUSTER=1 (LIDET_FW_LIDAR=ouster) an Ouster sensor's (lidet_ouster_packet, configured from the
 * metadata in fw_packets.h; 16 columns x LIDET_MAX_ROWS returns a payload; a frame completes when the next frame's
 * first payload arrives). Both decoders' scan events have the same values and meanings. Three runs: as fw_detect.c,
 * `default` (the configuration a user gets) and `open` (gates and size checks off, so that many boxes are compared),
 * and `sectors` (the default one with lidet_detector_q_cfg_t.stream_sectors: the ground stage done sector by sector
 * while the payloads arrive, so stream_end, the latency from the last payload, has less to do).
 * No tracker: its 8 KiB do not fit beside the decoder's buffers in the integer image's 256 KiB (run_fw.py).
 *
 * Built for the host with FW_PACKETS_HOST_REF=1 (fw_host_ref_pkt, tests/firmware.cmake) it is the reference the
 * images are compared with: the same payloads decoded into a buffer of the whole scan (docs/DECODING.md, "Use")
 * and the completed scan given to lidet_detector_q_run_returns at once. Lines (tools/firmware/run_fw.py):
 *   lidet-fw board=... core=... build=fixed app=packets sensor=vlp16 models=... scan=... packets=N start_cdeg=..
 *                                                    (Ouster: sensor=os1-32 ... packets=N lidar=ouster
 *                                                    payload_bytes=.. first_mid=..)
 *   mem detector_bytes=.. decoder_bytes=.. buffer_bytes=.. max_rows=.. ...   sizes, capacities
 *   calib n=N expected=E measured=M                  the instruction counter against loops of known length
 *   stats run=R status=S clusters=... detections=D proj_in=..   the detector's counts (fw_detect.c's, + projection)
 *   det R k CLASS CLUSTER NPTS h0 .. h9 # readable   one detection, int32 values as hex (fw_detect.c's format)
 *   decode run=R packets=.. decoded=.. returns=.. partial=.. complete=.. aborted=.. first=P last=Q scan_returns=N
 *                                                    the decoder's counts; the completed scan: payloads P..Q, returns
 *   digest run=default returns=N fnv1a=H             FNV-1a of the completed scan's returns (range, azimuth, ring),
 *                                                    from a second, untimed pass
 *   insn run=R decode=.. project=.. ground=.. cluster=.. classify=.. box=.. post=.. scan=..   instructions: decode =
 *                                                    the decoder over every payload, project = stream_begin,
 *                                                    every stream_returns and the projection's end, scan = all of it
 *   pktinsn run=R decode_max=.. stream_max=.. end=.. counter=..   the largest payload's decoding and stream_returns
 *                                                    call, stream_end (latency from the last packet), the counter
 *                                                    reads' own cost subtracted from decode
 *   stack used=N size=S
 *   lidet-fw: PASS | FAIL (...) */
#include <stdint.h>
#include <string.h>

#include "fw_out.h"
#include "fw_packets.h"
#include "fw_port.h"
#include "lidet/lidet_detector_q.h"
#include "lidet_weights.h"

#if !LIDET_FIXED_POINT
#error "fw_packets.c: the integer build only (LIDET_FW_FIXED=ON): the streaming API is the integer detector's"
#endif
#ifndef FW_PACKETS_HOST_REF
#define FW_PACKETS_HOST_REF 0
#endif
#ifndef FW_SENSOR
#define FW_SENSOR "vlp16"
#endif
#ifndef FW_MODELS_ID
#define FW_MODELS_ID vlp16s
#define FW_MODELS "vlp16s"
#endif
#define FW_XCAT(a, b) a##b
#define FW_CAT(a, b) FW_XCAT(a, b)

/* ---- the decoder: one payload in, its returns out, the same calls for both (fw_packets.h) ---------------- */
#if FW_OUSTER
typedef lidet_ouster_t fw_dec_t;
typedef lidet_ouster_cfg_t fw_dec_cfg_t;
typedef lidet_ouster_result_t fw_dec_result_t;
typedef lidet_ouster_stats_t fw_dec_stats_t;
#define FW_SCAN_NONE LIDET_OUSTER_SCAN_NONE
#define FW_SCAN_COMPLETE LIDET_OUSTER_SCAN_COMPLETE
#define FW_SCAN_PARTIAL LIDET_OUSTER_SCAN_PARTIAL
#define FW_SCAN_ABORTED LIDET_OUSTER_SCAN_ABORTED
/* one payload's returns: 16 columns of single-return pixels at the capacities' beams (checked: fw_main) */
#define FW_MAX_RETURNS (LIDET_OUSTER_MAX_COLS_PER_PACKET * LIDET_MAX_ROWS)
#define FW_PAYLOAD(k) (fw_pkt_payload + (k)*fw_pkt_bytes)
#define FW_PAYLOAD_BYTES fw_pkt_bytes
#define fw_dec_init lidet_ouster_init
#define fw_dec_packet lidet_ouster_packet
#define fw_dec_stats lidet_ouster_stats

/* the decoder's configuration: the sensor's metadata (fw_pkt_ouster, made with the payloads) */
static void dec_cfg(fw_dec_cfg_t *c)
{
    lidet_ouster_cfg_default(c);
    c->profile = (lidet_ouster_profile_t)fw_pkt_ouster.profile;
    c->pixels_per_column = fw_pkt_ouster.pixels_per_column;
    c->columns_per_frame = fw_pkt_ouster.columns_per_frame;
    c->columns_per_packet = fw_pkt_ouster.columns_per_packet;
    c->beam_azimuth_mdeg = fw_pkt_ouster.beam_azimuth_mdeg;
    c->init_id = fw_pkt_ouster.init_id;
    /* (in two halves: a 64-bit copy may go through an FPU register where the core has one) */
    c->prod_sn = (uint64_t)fw_pkt_ouster.prod_sn_hi << 32 | fw_pkt_ouster.prod_sn_lo;
}
#else
typedef lidet_velodyne_t fw_dec_t;
typedef lidet_velodyne_cfg_t fw_dec_cfg_t;
typedef lidet_velodyne_result_t fw_dec_result_t;
typedef lidet_velodyne_stats_t fw_dec_stats_t;
#define FW_SCAN_NONE LIDET_VELODYNE_SCAN_NONE
#define FW_SCAN_COMPLETE LIDET_VELODYNE_SCAN_COMPLETE
#define FW_SCAN_PARTIAL LIDET_VELODYNE_SCAN_PARTIAL
#define FW_SCAN_ABORTED LIDET_VELODYNE_SCAN_ABORTED
#define FW_MAX_RETURNS LIDET_VELODYNE_MAX_RETURNS
#define FW_PAYLOAD(k) fw_pkt_payload[k]
#define FW_PAYLOAD_BYTES LIDET_VELODYNE_PAYLOAD_BYTES
#define fw_dec_init lidet_velodyne_init
#define fw_dec_packet lidet_velodyne_packet
#define fw_dec_stats lidet_velodyne_stats

static void dec_cfg(fw_dec_cfg_t *c)
{
    lidet_velodyne_cfg_default(c);
    c->model = LIDET_VELODYNE_VLP16;
}
#endif

/* What a product holds: the detector, the decoder and one payload's returns. */
static lidet_detector_q_t g_det;
static fw_dec_t g_dec;
static lidet_return_t g_out[FW_MAX_RETURNS];
#if FW_PACKETS_HOST_REF
/* the host reference's scan buffer (docs/DECODING.md, "Use"): a whole scan, then one more payload's returns */
static lidet_return_t g_scan[LIDET_MAX_POINTS + FW_MAX_RETURNS];
#endif

/* ---- output (no stdio) ----------------------------------------------------------------------------- */

/* one detection: fw_detect.c's `det` line (the integer build's int32 values as hex, then readable) */
static void put_det(const char *run, uint32_t k, const lidet_detection_q_t *d)
{
    static const char *const labels[8] = {" # score_q15 ", " xyz_mm ", " ", " ",
                                          " lwh_mm ",      " ",        " ", " yaw_bam "};
    const int32_t v[10] = {d->score_q15, d->box.cx_mm, d->box.cy_mm,   d->box.cz_mm,      d->box.l_mm,
                           d->box.w_mm,  d->box.h_mm,  d->box.yaw_bam, d->energy_cls_q16, d->energy_box_q16};
    uint32_t j;
    fw_put_s("det ");
    fw_put_s(run);
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
        fw_put_hex((uint32_t)v[j]);
    }
    for (j = 0; j < 8u; ++j)
    {
        fw_put_s(labels[j]);
        fw_put_i(v[j]);
    }
    fw_putc('\n');
}

/* ---- the detector's clock hook: 64-bit stage counts without a timestamp buffer ---------------------------- */

/* The stages' ticks are uint32 (lidet_detector_q_stats_t); the hook rebuilds them in 64 bits as it is called,
 * from the order the streaming detector calls it in. While streaming, in pairs: stream_begin and each
 * stream_returns around their projection work. Then stream_end: k = 0 before the projection's end, 1 after it,
 * 2 after the ground stage, 3 after the clustering, 4 at the classification's start, then a pair per box net pass
 * (the group split's parts' too), the classification's end, the post-processing's start and end (8 + 2 boxes
 * calls, as lidet_detector_q_run's).
 * From k = 5 on, the intervals of odd k are the classification's and of even k the box nets', but for the last
 * two: the gap before the post-processing (even) and the post-processing (odd). So two sums and the last two
 * intervals suffice (fw_detect.c keeps every timestamp instead: 1 KiB of RAM a product would not hold). */
typedef struct
{
    uint64_t prev;    /* the last timestamp */
    uint64_t project; /* the projection's intervals */
    uint64_t ground, cluster;
    uint64_t odd, even;  /* stream_end's intervals from k = 5 on, by the parity of k */
    uint64_t last[2];    /* the last two of them: [1] the last */
    uint64_t stream_max; /* the largest stream_returns interval */
    uint32_t n;          /* calls in this phase */
    uint32_t end_phase;  /* 0: streaming, 1: inside stream_end */
} seq_t;

static seq_t g_seq;

static uint32_t seq_clock(void *ctx)
{
    seq_t *q = (seq_t *)ctx;
    const uint64_t v = fw_insn64();
    const uint64_t d = v - q->prev;
    if (!q->end_phase)
    {
        if ((q->n & 1u) != 0u)
        {
            q->project += d;
            q->stream_max = q->n > 1u && d > q->stream_max ? d : q->stream_max; /* not stream_begin's */
        }
    }
    else if (q->n == 1u)
        q->project += d;
    else if (q->n == 2u)
        q->ground = d;
    else if (q->n == 3u)
        q->cluster = d;
    else if (q->n >= 5u)
    {
        if ((q->n & 1u) != 0u)
            q->odd += d;
        else
            q->even += d;
        q->last[0] = q->last[1];
        q->last[1] = d;
    }
    q->prev = v;
    ++q->n;
    return (uint32_t)v;
}

/* -> 0 and out[] filled (LIDET_DET_STAGE_* order), or 1 when the calls do not match the detector's order: the
 * count of stream_end's calls, and the low 32 bits of every rebuilt stage against the detector's own ticks */
static int seq_stages(const seq_t *q, const lidet_detector_q_stats_t *s, uint64_t out[LIDET_DET_N_STAGES])
{
    uint32_t k;
    if (!q->end_phase || q->n != 8u + 2u * (s->n_boxed + s->n_group_boxed)) /* a pair per box net pass, parts too */
        return 1;
    out[LIDET_DET_STAGE_PROJECT] = q->project;
    out[LIDET_DET_STAGE_GROUND] = q->ground;
    out[LIDET_DET_STAGE_CLUSTER] = q->cluster;
    out[LIDET_DET_STAGE_CLASSIFY] = q->odd - q->last[1];
    out[LIDET_DET_STAGE_BOX] = q->even - q->last[0];
    out[LIDET_DET_STAGE_POST] = q->last[1];
    for (k = 0; k < LIDET_DET_N_STAGES; ++k)
        if ((uint32_t)out[k] != s->ticks[k])
            return 1;
    return 0;
}

/* ---- one run ----------------------------------------------------------------------------------------- */

typedef struct
{
    uint32_t n_partial, n_complete, n_aborted; /* scan events seen */
    uint32_t first, last;                      /* payloads holding the completed scan's returns */
    uint32_t scan_returns;                     /* its returns */
    uint64_t counter;                          /* instructions of two back-to-back counter reads */
    uint64_t decode, decode_max;               /* the decoder: every payload, the largest */
    uint64_t end;                              /* lidet_detector_q_stream_end */
} pkt_t;

static void count_event(pkt_t *p, uint32_t ev)
{
    p->n_partial += ev == FW_SCAN_PARTIAL;
    p->n_complete += ev == FW_SCAN_COMPLETE;
    p->n_aborted += ev == FW_SCAN_ABORTED;
}

/* decode payload k into g_out, its instructions added to p (minus the counter's own) */
static lidet_status_t decode_one(uint32_t k, pkt_t *p, fw_dec_result_t *r)
{
    const uint64_t t0 = fw_insn64();
    const lidet_status_t s =
        fw_dec_packet(&g_dec, FW_PAYLOAD(k), FW_PAYLOAD_BYTES, g_out, 0, FW_MAX_RETURNS, r);
    const uint64_t d = fw_insn64() - t0 - p->counter;
    p->decode += d;
    p->decode_max = d > p->decode_max ? d : p->decode_max;
    count_event(p, r->scan_event);
    return s;
}

#if !FW_PACKETS_HOST_REF
/* The board: each payload decoded and streamed; the scan ends inside the payload whose event is COMPLETE. Before
 * the first seam no stream is open (the partial rotation's returns are dropped, as a product drops them). */
static __attribute__((noinline)) lidet_status_t run_packets(pkt_t *p)
{
    int open = 0;
    uint32_t k, from;
    for (k = 0; k < fw_pkt_n; ++k)
    {
        fw_dec_result_t r;
        lidet_status_t s = decode_one(k, p, &r);
        if (s != LIDET_OK)
            return s < 0 ? s : LIDET_ERR_STATE; /* a rejected or truncated payload: none is expected here */
        if (r.scan_event == FW_SCAN_COMPLETE && open)
        {
            s = lidet_detector_q_stream_returns(&g_det, g_out, r.scan_end, 0);
            if (!LIDET_SUCCEEDED(s))
                return s;
            p->scan_returns += r.scan_end;
            p->last = k;
            g_seq.end_phase = 1u;
            g_seq.n = 0u;
            p->end = fw_insn64();
            s = lidet_detector_q_stream_end(&g_det);
            p->end = fw_insn64() - p->end - p->counter;
            return s;
        }
        /* without an event every return is the scan's (scan_end = n_returns); with one, those from scan_end on */
        from = 0u;
        if (r.scan_event != FW_SCAN_NONE)
        {
            /* a new rotation begins at the seam (after a partial, aborted or, in a product, a completed one) */
            s = lidet_detector_q_stream_begin(&g_det);
            if (s != LIDET_OK)
                return s;
            open = 1;
            from = r.scan_end;
            p->first = k;
            p->scan_returns = 0u;
        }
        if (open)
        {
            s = lidet_detector_q_stream_returns(&g_det, g_out + from, r.n_returns - from, 0);
            if (!LIDET_SUCCEEDED(s))
                return s;
            p->scan_returns += r.n_returns - from;
        }
    }
    return LIDET_ERR_STATE; /* no complete rotation */
}
#else
/* The host reference: docs/DECODING.md's loop, each payload decoded into a buffer of the whole scan, the completed
 * scan given to lidet_detector_q_run_returns at once. */
static lidet_status_t run_packets(pkt_t *p)
{
    int open = 0;
    uint32_t k, fill = 0u;
    for (k = 0; k < fw_pkt_n; ++k)
    {
        fw_dec_result_t r;
        lidet_status_t s = decode_one(k, p, &r);
        if (s != LIDET_OK)
            return s < 0 ? s : LIDET_ERR_STATE;
        if (fill + r.n_returns > LIDET_MAX_POINTS + FW_MAX_RETURNS)
            return LIDET_ERR_BUFFER; /* not with these payloads: the comparison needs the whole scan */
        memcpy(g_scan + fill, g_out, r.n_returns * sizeof g_out[0]);
        if (r.scan_event == FW_SCAN_COMPLETE && open)
        {
            p->scan_returns = fill + r.scan_end;
            p->last = k;
            return lidet_detector_q_run_returns(&g_det, g_scan, fill + r.scan_end, 0);
        }
        if (r.scan_event != FW_SCAN_NONE)
        {
            memmove(g_scan, g_scan + fill + r.scan_end, (r.n_returns - r.scan_end) * sizeof g_scan[0]);
            fill = r.n_returns - r.scan_end; /* the next scan's first returns */
            p->first = k;
            open = 1;
        }
        else
            fill += r.n_returns;
    }
    return LIDET_ERR_STATE;
}
#endif

static const lidet_pointnet_q_model_t *const k_cls = &FW_CAT(FW_CAT(lidet_model_cls_, FW_MODELS_ID), _s8);
static const lidet_pointnet_q_model_t *const k_box = &FW_CAT(FW_CAT(lidet_model_box_, FW_MODELS_ID), _s8);

/* the counts and instructions of a run (not inlined: its frame stays off the detector's deepest stack) */
static __attribute__((noinline)) int report(const char *name, lidet_status_t st, const pkt_t *p,
                                            uint64_t scan)
{
    static const char *const stage_names[LIDET_DET_N_STAGES] = {"project",  "ground", "cluster",
                                                                "classify", "box",    "post"};
    const lidet_detector_q_stats_t *s = lidet_detector_q_stats(&g_det);
    const fw_dec_stats_t *vs = fw_dec_stats(&g_dec);
    uint32_t n_det = 0, k;
    const lidet_detection_q_t *det = lidet_detector_q_detections(&g_det, &n_det);
    uint64_t stage64[LIDET_DET_N_STAGES];

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
    fw_put_kv("proj_in", s->proj.n_points_in);
    fw_put_kv("proj_projected", s->proj.n_projected);
    fw_put_kv("proj_filled", s->proj.n_pixels_filled);
    fw_put_kv("proj_truncated", s->proj.n_truncated);
    fw_putc('\n');
    for (k = 0; k < n_det; ++k)
        put_det(name, k, &det[k]);
    fw_put_s("decode run=");
    fw_put_s(name);
    fw_put_kv("packets", vs->n_packets);
    fw_put_kv("decoded", vs->n_decoded);
    fw_put_kv("returns", vs->n_returns);
    fw_put_kv("partial", p->n_partial);
    fw_put_kv("complete", p->n_complete);
    fw_put_kv("aborted", p->n_aborted);
    fw_put_kv("first", p->first);
    fw_put_kv("last", p->last);
    fw_put_kv("scan_returns", p->scan_returns);
    fw_putc('\n');
    if (!fw_have_counter() || FW_PACKETS_HOST_REF)
        return LIDET_SUCCEEDED(st) ? 0 : 1;
    if (!LIDET_SUCCEEDED(st) || seq_stages(&g_seq, s, stage64) != 0)
    {
        fw_put_s("insn run=");
        fw_put_s(name);
        fw_put_s(" FAIL: the clock calls do not match the streaming detector's order (fw_packets.c: "
                 "seq_stages)\n");
        return 1;
    }
    fw_put_s("insn run=");
    fw_put_s(name);
    fw_put_kv64("decode", p->decode);
    for (k = 0; k < LIDET_DET_N_STAGES; ++k)
        fw_put_kv64(stage_names[k], stage64[k]);
    fw_put_kv64("scan", scan);
    fw_putc('\n');
    fw_put_s("pktinsn run=");
    fw_put_s(name);
    fw_put_kv64("decode_max", p->decode_max);
    fw_put_kv64("stream_max", g_seq.stream_max);
    fw_put_kv64("end", p->end);
    fw_put_kv64("counter", p->counter);
    fw_putc('\n');
    return 0;
}

static pkt_t g_pkt;

static int run_once(const char *name, lidet_detector_q_cfg_t *cfg)
{
    fw_dec_cfg_t vc;
    lidet_status_t st;
    uint64_t t0, t1;

    cfg->clock = seq_clock;
    cfg->clock_ctx = &g_seq;
    dec_cfg(&vc);
    st = lidet_detector_q_init(&g_det, cfg, k_cls, k_box);
    if (st == LIDET_OK)
        st = fw_dec_init(&g_dec, &vc);
    if (st != LIDET_OK)
    {
        fw_put_s("init run=");
        fw_put_s(name);
        fw_put_s(" failed status=");
        fw_put_i((int32_t)st);
        fw_putc('\n');
        return 1;
    }
    memset(&g_seq, 0, sizeof g_seq);
    memset(&g_pkt, 0, sizeof g_pkt);
    t0 = fw_insn64();
    t1 = fw_insn64();
    g_pkt.counter = t1 - t0;
    g_seq.prev = t0 = fw_insn64();
    st = run_packets(&g_pkt);
    t1 = fw_insn64();
    return report(name, st, &g_pkt, t1 - t0);
}

/* ---- the completed scan's returns, as this core decodes them ------------------------------------------ */

/* FNV-1a (32 bits) over each return's range (4 bytes), azimuth and ring (2 each), little-endian */
static uint32_t fnv_return(uint32_t h, const lidet_return_t *r)
{
    const uint32_t w[3] = {r->range_mm, r->azimuth, r->ring};
    const uint32_t nb[3] = {4u, 2u, 2u};
    uint32_t j, b;
    for (j = 0; j < 3u; ++j)
        for (b = 0; b < nb[j]; ++b)
        {
            h ^= (w[j] >> (8u * b)) & 0xFFu;
            h *= 16777619u;
        }
    return h;
}

/* A second, untimed pass over the payloads (a fresh decoder): the digest of the completed scan's returns, which
 * run_fw.py compares with the host's, so a decoding difference shows before the detector's. -> 0, or 1. */
static __attribute__((noinline)) int scan_digest(const char *name)
{
    fw_dec_cfg_t vc;
    uint32_t k, i, h = 2166136261u, n = 0u;
    int open = 0, done = 0;
    dec_cfg(&vc);
    if (fw_dec_init(&g_dec, &vc) != LIDET_OK)
        return 1;
    for (k = 0; k < fw_pkt_n && !done; ++k)
    {
        fw_dec_result_t r;
        uint32_t from = 0u, to;
        if (fw_dec_packet(&g_dec, FW_PAYLOAD(k), FW_PAYLOAD_BYTES, g_out, 0, FW_MAX_RETURNS, &r) != LIDET_OK)
            return 1;
        to = r.n_returns;
        if (r.scan_event == FW_SCAN_COMPLETE && open)
        {
            to = r.scan_end;
            done = 1;
        }
        else if (r.scan_event != FW_SCAN_NONE)
        {
            open = 1;
            h = 2166136261u;
            n = 0u;
            from = r.scan_end;
        }
        for (i = from; open && i < to; ++i)
            h = fnv_return(h, &g_out[i]);
        n += open ? to - from : 0u;
    }
    fw_put_s("digest run=");
    fw_put_s(name);
    fw_put_kv("returns", n);
    fw_put_s(" fnv1a=");
    fw_put_hex(h);
    fw_putc('\n');
    return !done;
}

int fw_main(void)
{
    const lidet_sensor_q_t *sensor = lidet_sensor_q_find(FW_SENSOR);
    static lidet_detector_q_cfg_t cfg; /* in .bss, not on the stack under the detector (fw_detect.c) */
    int bad = 0, c, j;

    fw_put_s("lidet-fw board=");
    fw_put_s(fw_board_name);
    fw_put_s(" core=");
    fw_put_s(fw_core_name);
    fw_put_s(" build=fixed app=packets sensor=" FW_SENSOR " models=" FW_MODELS "_s8 scan=");
    fw_put_s(fw_pkt_name);
    fw_put_kv("packets", fw_pkt_n);
#if FW_OUSTER
    fw_put_s(" lidar=ouster");
    fw_put_kv("payload_bytes", fw_pkt_bytes);
    fw_put_kv("first_mid", fw_pkt_first_mid);
#else
    fw_put_kv("start_cdeg", fw_pkt_start_cdeg);
#endif
    fw_putc('\n');
    fw_put_s("mem");
    fw_put_kv("detector_bytes", lidet_detector_q_bytes());
    fw_put_kv("decoder_bytes", (uint32_t)sizeof g_dec);
    fw_put_kv("buffer_bytes", (uint32_t)sizeof g_out);
    fw_put_kv("max_rows", LIDET_MAX_ROWS);
    fw_put_kv("max_cols", LIDET_MAX_COLS);
    fw_put_kv("max_points", LIDET_MAX_POINTS);
    fw_put_kv("max_clusters", LIDET_MAX_CLUSTERS);
    fw_put_kv("max_returns", FW_MAX_RETURNS);
    fw_putc('\n');
    if (sensor == 0)
    {
        fw_put_s("lidet-fw: FAIL (no " FW_SENSOR " sensor profile)\n");
        return 1;
    }
#if FW_OUSTER
    {
        /* the metadata against the capacities: one payload's returns fit g_out, the payloads are the profile's */
        fw_dec_cfg_t oc;
        dec_cfg(&oc);
        if (fw_dec_init(&g_dec, &oc) != LIDET_OK || lidet_ouster_max_returns(&g_dec) > FW_MAX_RETURNS ||
            lidet_ouster_packet_bytes(&g_dec) != fw_pkt_bytes || oc.pixels_per_column != sensor->n_rows ||
            oc.columns_per_frame != sensor->n_cols)
        {
            fw_put_s(
                "lidet-fw: FAIL (the Ouster metadata does not fit the decoder, the buffer or the " FW_SENSOR
                " profile)\n");
            return 1;
        }
    }
#endif
    if (fw_have_counter() && fw_calibrate(0) != 0)
    {
        fw_put_s("lidet-fw: FAIL (instruction counter does not match the calibration loop)\n");
        return 1;
    }
    /* run 1: the configuration a user gets */
    lidet_detector_q_cfg_default(&cfg, sensor);
    bad |= run_once("default", &cfg);
    /* run 2: gates and size checks off, so that every classified proposal is boxed and reported */
    cfg.gate1 = 0u;
    cfg.gate2 = 0u;
    for (c = 0; c < LIDET_N_CLASSES; ++c)
        for (j = 0; j < 3; ++j)
        {
            cfg.size.min_mm[c][j] = 1;
            cfg.size.max_mm[c][j] = LIDET_Q_BOX_MAX_MM;
        }
    bad |= run_once("open", &cfg);
    /* run 3: the default configuration with the ground stage streamed sector by sector (stream_sectors): the
     * latency from the last payload to the detections (pktinsn end) against run 1's */
    lidet_detector_q_cfg_default(&cfg, sensor);
    cfg.stream_sectors = 1u;
    bad |= run_once("sectors", &cfg);
    bad |= scan_digest("default");

    fw_put_s("stack");
    fw_put_kv("used", fw_stack_used());
    fw_put_kv("size", fw_stack_size());
    fw_putc('\n');
    fw_put_s(bad ? "lidet-fw: FAIL (a run failed)\n" : "lidet-fw: PASS\n");
    return bad;
}
