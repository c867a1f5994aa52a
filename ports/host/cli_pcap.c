/* SPDX-License-Identifier: MIT */
/* `lidet detect --pcap FILE`, `lidet track --pcap FILE`: a packet capture read with libpcap, the UDP datagrams to
 * the sensor's data port taken out of their Ethernet / IPv4 / UDP headers (every frame counted by kind), each payload
 * decoded (lidet_velodyne.h, lidet_ouster.h: one call per payload), and the decoder's returns gathered into scans
 * (docs/CAPTURES.md, "From a capture: lidet detect --pcap").
 *
 * Two passes over the file: the first counts the frames, runs the decoder alone and lists the scans to run (and
 * learns the Velodyne model from the packets when --sensor is not given); the second decodes again and hands the
 * commands one scan at a time (cli_capture_next), the same scans since the decoder is deterministic. So the
 * commands know before their first detection how many scans there are (lidet track's --ego and --dt-file, the
 * picture of the last scan) and what the sensor is, and a bad capture fails before any output.
 *
 * A scan is held in a buffer of LIDET_MAX_POINTS returns (the detector's input bound); returns past it are
 * counted and dropped, never written. The decoder writes each payload's returns into a buffer for a whole packet
 * first, so a boundary inside a full scan still gives the next scan its first returns.
 *
 * The decoders: a small table (k_lidars) chosen by --lidar: velodyne (the model from the product byte, an HDL-64E's
 * lower-bank flag, or --sensor; the hdl64 preset's rings from the top; with --velodyne-calib the unit's calibration
 * in the decoder and its description as the scans' sensor) and ouster (the packet format and beams from
 * --ouster-meta). Another is one more entry: its options checked, its decoder, its counts, its x, y, z.
 *
 * --print-sensor (cli_capture_print_sensor): pass 1 alone, then the scans' sensor printed (the one resolve set).
 *
 * Built without libpcap (LIDET_HAVE_PCAP unset: ports/host/CMakeLists.txt) --pcap exits with an error saying so. */
#define _DEFAULT_SOURCE 1 /* libpcap's headers use the BSD types (u_int, u_char) */
#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "cli.h"

#ifdef LIDET_HAVE_PCAP
#include <pcap/pcap.h>
#endif

/* ---- options ------------------------------------------------------------------------------------------------ */

void cli_pcap_opts_default(cli_pcap_opts_t *o)
{
    memset(o, 0, sizeof *o);
    o->lidar = "velodyne";
    o->png_scan = -1;
}

enum
{
    OPT_PCAP,
    OPT_LIDAR,
    OPT_PORT,
    OPT_FORCE_SENSOR,
    OPT_DUAL,
    OPT_PARTIAL,
    OPT_PNG_SCAN
};

const cli_opt_t cli_opts_pcap[] = {
    {"pcap", required_argument, OPT_PCAP, "FILE: a packet capture"},
    {"lidar", required_argument, OPT_LIDAR, "NAME: velodyne or ouster"},
    {"port", required_argument, OPT_PORT, "N: a UDP port in [1, 65535]"},
    {"force-sensor", no_argument, OPT_FORCE_SENSOR, NULL},
    {"dual", required_argument, OPT_DUAL, "MODE: both, last, strongest, first or second"},
    {"partial", no_argument, OPT_PARTIAL, NULL},
    {NULL, 0, 0, NULL}};

const cli_opt_t cli_opts_pcap_png_scan[] = {{"png-scan", required_argument, OPT_PNG_SCAN, "K: a scan number (from 0)"},
                                            {NULL, 0, 0, NULL}};

int cli_pcap_take(void *ctx, int id, const char *v)
{
    cli_pcap_opts_t *o = (cli_pcap_opts_t *)ctx;
    switch (id)
    {
    case OPT_PCAP:
        o->path = v;
        break;
    case OPT_FORCE_SENSOR:
        o->force_sensor = 1;
        break;
    case OPT_PARTIAL:
        o->partial = 1;
        break;
    case OPT_LIDAR:
        if (strcmp(v, "velodyne") != 0 && strcmp(v, "ouster") != 0)
        {
            fprintf(stderr, "lidet %s: --lidar velodyne or ouster, not '%s'\n", cli_cmd, v);
            return 1;
        }
        o->lidar = v;
        break;
    case OPT_DUAL:
        if (strcmp(v, "both") != 0 && strcmp(v, "last") != 0 && strcmp(v, "strongest") != 0 &&
            strcmp(v, "first") != 0 && strcmp(v, "second") != 0)
        {
            fprintf(stderr,
                    "lidet %s: --dual both, last or strongest (velodyne), first or second (ouster), not '%s'\n",
                    cli_cmd, v);
            return 1;
        }
        o->dual = v;
        break;
    default: /* OPT_PORT, OPT_PNG_SCAN */
    {
        char *end;
        const long n = strtol(v, &end, 10);
        const int port = id == OPT_PORT;
        if (end == v || *end != '\0' || n < (port ? 1 : 0) || n > (port ? 65535 : 100000000L))
        {
            fprintf(stderr, "lidet %s: --%s needs %s, got '%s'\n", cli_cmd, port ? "port" : "png-scan",
                    port ? "a UDP port in [1, 65535]" : "a scan number (from 0)", v);
            return 1;
        }
        if (port)
            o->port = (int)n;
        else
            o->png_scan = n;
        break;
    }
    }
    return 0;
}

void cli_pcap_usage(FILE *f, int detect)
{
    fprintf(f, "  --pcap FILE      a packet capture (pcap or pcapng, read with libpcap) instead of scan\n"
               "                   files: the UDP datagrams to the sensor's data port decoded\n"
               "                   (docs/DECODING.md), the detector run on each complete rotation;\n"
               "                   partial rotations (the capture's first and last) skipped; a summary\n"
               "                   on stderr (frames, decoder rejects, scans, time)\n"
               "  --lidar NAME     the sensor family: velodyne (default; VLP-16, VLP-32C, HDL-32E,\n"
               "                   HDL-64E S2/S3 single or dual return; the model from the packets or\n"
               "                   --sensor)\n"
               "                   or ouster (OS0/OS1/OS2, every packet profile; needs --ouster-meta M:\n"
               "                   its packet format and beams)\n"
               "  --port N         the sensor's data port (default: velodyne 2368, ouster the\n"
               "                   metadata's udp_port_lidar, else 7502)\n"
               "  --sensor NAME    velodyne: vlp16, vlp32c, hdl32 or hdl64; default: the packets' product\n"
               "                   byte (HDL-64E: its lower-bank flag)\n"
               "  --velodyne-calib C  velodyne, with --sensor: the unit's calibration (db.xml or YAML)\n"
               "                   applied by the decoder (rings by its elevations, rotational and\n"
               "                   distance corrections); the detector projects with its elevations\n"
               "  --force-sensor   velodyne: decode every packet as --sensor's model whatever its\n"
               "                   product byte\n"
               "  --print-sensor   the sensor the capture is decoded as (the packets' model, or the\n"
               "                   calibration), as a description; then stop\n"
               "  --dual MODE      dual-return packets: velodyne both (default: the last return, and\n"
               "                   the strongest where it differs), last or strongest; ouster both\n"
               "                   (default), first or second\n"
               "  --partial        also run the scans that are not one whole rotation (the capture's\n"
               "                   first and last, those ended by a jump), marked (partial), (aborted),\n"
               "                   (unfinished)\n");
    if (detect)
        fprintf(f, "  --png-scan K     with --pcap --png: draw scan K (default: the last one)\n"
                   "  --save-scans DIR the scans as KITTI files: DIR/velodyne/<K:06d>.bin (float32 x, y,\n"
                   "                   z, 0) and DIR/ring/<K:06d>.bin (uint16 ring per point), as the\n"
                   "                   float detector gets them\n"
                   "  Output with --pcap: per scan a line '# scan K: N returns, D detections, packets\n"
                   "  P..Q' (P..Q: the frames of the file holding its returns, from 0), then its boxes\n"
                   "  as --out lines; --json: one object per scan; --out DIR: DIR/<K:06d>.txt per scan;\n"
                   "  --png: the last scan (or --png-scan K). --fixed runs the integer detector on the\n"
                   "  decoded returns (lidet_detector_q_run_returns), the float detector their x, y, z\n"
                   "  (lidet_velodyne_decoder_xyz: the decoder's elevations; Ouster: the metadata's beam\n"
                   "  altitudes) with their rings\n");
}

const char *cli_scan_kind(uint8_t kind)
{
    return kind == LIDET_VELODYNE_SCAN_COMPLETE  ? "complete"
           : kind == LIDET_VELODYNE_SCAN_PARTIAL ? "partial"
           : kind == LIDET_VELODYNE_SCAN_ABORTED ? "aborted"
                                                 : "unfinished";
}

#ifndef LIDET_HAVE_PCAP

int cli_capture_open(const cli_pcap_opts_t *o, cli_args_t *a, cli_capture_t **out)
{
    (void)o;
    (void)a;
    *out = NULL;
    fprintf(stderr,
            "lidet %s: --pcap: this lidet was built without libpcap (apt-get install libpcap-dev, then rebuild; make "
            "deps installs it)\n",
            cli_cmd);
    return 1;
}
int cli_capture_print_sensor(const cli_pcap_opts_t *o, cli_args_t *a)
{
    cli_capture_t *c = NULL;
    return cli_capture_open(o, a, &c); /* says that this lidet was built without libpcap */
}
uint32_t cli_capture_n_scans(const cli_capture_t *c)
{
    (void)c;
    return 0;
}
const cli_scan_info_t *cli_capture_info(const cli_capture_t *c, uint32_t k)
{
    (void)c;
    (void)k;
    return NULL;
}
int cli_capture_next(cli_capture_t *c, cli_args_t *a, const lidet_return_t **rets, cli_scan_info_t *info)
{
    (void)c;
    (void)a;
    (void)rets;
    (void)info;
    return -1;
}
int cli_capture_summary(const cli_capture_t *c, FILE *f, const double *det_ms, uint32_t n_run)
{
    (void)c;
    (void)f;
    (void)det_ms;
    (void)n_run;
    return 1;
}
void cli_capture_close(cli_capture_t *c)
{
    (void)c;
}

#else /* LIDET_HAVE_PCAP */

/* ---- frames: the UDP payload of a captured frame ----------------------------------------------------------- */

enum
{
    FRAME_PORT = 0,     /* UDP to the data port: the payload is the decoder's */
    FRAME_OTHER_PORT,   /* UDP to another port (Velodyne position packets: 8308) */
    FRAME_NOT_UDP,      /* not IPv4 (ARP, IPv6, ...) or IPv4 but not UDP */
    FRAME_TRUNCATED,    /* cut short by the capture (snap length): a header or the datagram past its bytes */
    FRAME_FRAGMENT,     /* an IPv4 fragment: not reassembled, ignored */
    FRAME_MALFORMED,    /* whole, but its lengths disagree (an IP header length below 20, an IPv4 total or UDP
                           length past the frame or below its headers) */
    N_FRAME_KINDS
};

static uint32_t be16(const uint8_t *p)
{
    return ((uint32_t)p[0] << 8) | p[1];
}

/* The IPv4 / UDP datagram at ip (avail captured bytes): its kind, and for UDP its payload and destination port. */
static int ipv4_udp(const uint8_t *ip, uint32_t avail, const uint8_t **pl, uint32_t *len, uint32_t *dport)
{
    uint32_t ihl, total, ulen;
    if (avail < 1u)
        return FRAME_TRUNCATED;
    if ((ip[0] >> 4) != 4u)
        return FRAME_NOT_UDP; /* IPv6 and anything else */
    if (avail < 20u)
        return FRAME_TRUNCATED;
    ihl = (uint32_t)(ip[0] & 15u) * 4u;
    total = be16(ip + 2);
    if (ihl < 20u || total < ihl || total > avail) /* bad header length, or bytes past the capture */
        return FRAME_TRUNCATED;
    if ((be16(ip + 6) & 0x3FFFu) != 0u) /* more fragments, or an offset: a piece of a datagram */
        return FRAME_FRAGMENT;
    if (ip[9] != 17u)
        return FRAME_NOT_UDP;
    if (total - ihl < 8u)
        return FRAME_TRUNCATED;
    ulen = be16(ip + ihl + 4);
    if (ulen < 8u || ulen > total - ihl)
        return FRAME_TRUNCATED;
    *dport = be16(ip + ihl + 2);
    *pl = ip + ihl + 8;
    *len = ulen - 8u;
    return FRAME_PORT;
}

/* A frame of link type `link` (caplen bytes captured): its kind; for UDP its payload, length and port. */
static int frame_udp(int link, const uint8_t *f, uint32_t caplen, const uint8_t **pl, uint32_t *len, uint32_t *dport)
{
    uint32_t off, type;
    int tags;
    switch (link)
    {
    case DLT_EN10MB:
        if (caplen < 14u)
            return FRAME_TRUNCATED;
        type = be16(f + 12);
        off = 14u;
        break;
    case DLT_LINUX_SLL: /* Linux "any" captures: 16-byte header, the protocol last */
        if (caplen < 16u)
            return FRAME_TRUNCATED;
        type = be16(f + 14);
        off = 16u;
        break;
#ifdef DLT_LINUX_SLL2
    case DLT_LINUX_SLL2: /* 20-byte header, the protocol first */
        if (caplen < 20u)
            return FRAME_TRUNCATED;
        type = be16(f);
        off = 20u;
        break;
#endif
    default: /* DLT_RAW, DLT_IPV4: the IP header first */
        type = 0x0800u;
        off = 0u;
        break;
    }
    for (tags = 0; tags < 2 && (type == 0x8100u || type == 0x88A8u); ++tags) /* 802.1Q / 802.1ad tags */
    {
        if (caplen < off + 4u)
            return FRAME_TRUNCATED;
        type = be16(f + off + 2u);
        off += 4u;
    }
    if (type != 0x0800u)
        return FRAME_NOT_UDP;
    return ipv4_udp(f + off, caplen - off, pl, len, dport);
}

static int link_supported(int link)
{
    return link == DLT_EN10MB || link == DLT_LINUX_SLL || link == DLT_RAW
#ifdef DLT_LINUX_SLL2
           || link == DLT_LINUX_SLL2
#endif
#ifdef DLT_IPV4
           || link == DLT_IPV4
#endif
        ;
}

/* ---- the decoders ------------------------------------------------------------------------------------------ */

/* one payload through a decoder */
typedef struct
{
    uint32_t n_returns; /* returns written to the capture's packet buffer */
    uint32_t scan_end;  /* with an event: [0, scan_end) close the scan in progress, the rest begin the next */
    uint8_t event;      /* lidet_velodyne_scan_t (lidet_ouster_scan_t has the same values and meaning) */
    uint8_t decoded;    /* 0: rejected (counted by the decoder) */
    int64_t t_us;       /* the payload's sensor time, microseconds, monotonic across the capture */
} pkt_t;

/* what a decoder counted in pass 1 (the summary's generic part) */
typedef struct
{
    uint32_t n_packets, n_decoded, n_partial, n_aborted;
} dec_counts_t;

typedef struct lidar_s lidar_t;

#define N_OTHER_PORTS 8
/* the most returns one payload gives: Ouster's bound (16 columns x 128 beams x 2) covers Velodyne's 384 */
#define PKT_MAX_RETURNS                                                                                      \
    (LIDET_OUSTER_MAX_RETURNS > LIDET_VELODYNE_MAX_RETURNS ? LIDET_OUSTER_MAX_RETURNS : LIDET_VELODYNE_MAX_RETURNS)

struct cli_capture
{
    cli_pcap_opts_t o;
    const lidar_t *lidar;
    uint32_t port;
    int dec_model;      /* Velodyne: the model the decoder is configured with (0: its AUTO), both passes alike */
    int model;          /* Velodyne: the scans' model (--sensor's, else the packets'); Ouster: 1 */
    const char *sensor; /* the lidet sensor of the scans */
    /* the file */
    pcap_t *h;
    int link;
    int pass;       /* 1: indexing, 2: running */
    uint32_t frame; /* frames read in this pass */
    int eof;        /* this pass has read the whole file (or stopped at a damaged record) */
    int damaged;    /* pass 1 stopped at a damaged record (message in err) */
    char err[PCAP_ERRBUF_SIZE + 64];
    /* counts of pass 1 */
    uint32_t n_frames, kinds[N_FRAME_KINDS];
    uint32_t other_port[N_OTHER_PORTS], other_count[N_OTHER_PORTS];
    dec_counts_t dc;
    /* the Velodyne decoder */
    lidet_velodyne_t vd;
    lidet_velodyne_stats_t vstats; /* pass 1's */
    int calibrated;                /* --velodyne-calib: the unit's calibration (vcal) given to the decoder */
    const char *calib_path;
    lidet_velodyne_calib_t vcal;
    uint8_t return_mode;
    uint32_t t_prev_raw;
    int64_t t_us;
    int have_t;
    /* the Ouster decoder (--ouster-meta: the packet format, the beam altitudes in ring order) */
    lidet_ouster_t od;
    lidet_ouster_stats_t ostats; /* pass 1's */
    cli_ouster_fmt_t ofmt;
    uint16_t o_rows, o_cols;
    float o_elev_rad[LIDET_MAX_ROWS];
    /* scans */
    cli_scan_info_t *scans; /* pass 1: the scans to run */
    uint32_t n_scans, cap_scans;
    uint32_t n_given;                            /* scans handed out in this pass */
    uint32_t n_complete;                         /* pass 1: complete rotations */
    uint32_t n_unfinished, n_unfinished_returns; /* pass 1: the scan in progress at the end */
    uint64_t n_excess;                           /* pass 1: returns past LIDET_MAX_POINTS, all scans */
    uint32_t n_excess_scans;
    int in_scan;
    cli_scan_info_t cur;
    /* the returns of a boundary packet that begin the next scan, taken in at the next call */
    int pend;
    uint32_t pend_from, pend_n, pend_frame;
    int64_t pend_t;
    double pend_cap;
    double decode_ms; /* pass 2: reading, decoding, x, y, z */
    lidet_return_t pkt[PKT_MAX_RETURNS];
    lidet_return_t *buf; /* LIDET_MAX_POINTS */
    float *xyz;          /* 4 per return */
    uint16_t *ring;
};

struct lidar_s
{
    const char *name;
    /* the command line's sensor and options checked, the decoder's configuration and data port chosen: 0, or 1
     * with a message */
    int (*setup)(cli_capture_t *c, cli_args_t *a);
    /* the decoder (both passes alike): 0, or 1 with a message */
    int (*init)(cli_capture_t *c);
    /* one payload into c->pkt */
    void (*packet)(cli_capture_t *c, const uint8_t *p, uint32_t len, pkt_t *r);
    /* after pass 1: the decoder's counts; whether any packet was decoded (else no_data says why) */
    void (*counts)(cli_capture_t *c);
    void (*no_data)(const cli_capture_t *c, FILE *f);
    /* after pass 1: the scans' sensor into a (Velodyne without --sensor: the packets' model) */
    void (*resolve)(cli_capture_t *c, cli_args_t *a);
    /* at the end of the capture: 1 when the scan in progress is nonetheless whole (Ouster: it began at the frame's
     * first column and ended at its last), 0 */
    int (*whole_at_end)(const cli_capture_t *c);
    /* x, y, z, 0 records (4 floats) of n returns */
    int (*xyz)(const cli_capture_t *c, const lidet_return_t *r, uint32_t n, float *xyz);
    /* the decoder's counts (pass 1), one line */
    void (*report)(const cli_capture_t *c, FILE *f);
};

/* the scans' preset into a (the --mount-height of the command line kept) */
static void set_sensor(cli_args_t *a, const char *name)
{
    a->sensor = name;
    a->sensor_profile = lidet_sensor_find(name);
    if (a->mount_height_m >= 0.0 && a->sensor_profile != NULL)
    {
        a->sensor_mounted = *a->sensor_profile;
        a->sensor_mounted.mount_height_m = (float)a->mount_height_m;
        a->sensor_profile = &a->sensor_mounted;
    }
}

/* -- Velodyne (lidet_velodyne.h) -- */

static const char *vel_sensor_of(int model)
{
    switch (model)
    {
    case LIDET_VELODYNE_VLP16:
        return "vlp16";
    case LIDET_VELODYNE_VLP32C:
        return "vlp32c";
    case LIDET_VELODYNE_HDL32E:
        return "hdl32";
    case LIDET_VELODYNE_HDL64E:
        return "hdl64"; /* the preset numbers its rings from the top: the decoder's ring_top_first */
    default:
        return NULL;
    }
}

static int vel_model_of(const char *sensor)
{
    if (strcmp(sensor, "vlp16") == 0)
        return LIDET_VELODYNE_VLP16;
    if (strcmp(sensor, "vlp32c") == 0)
        return LIDET_VELODYNE_VLP32C;
    if (strcmp(sensor, "hdl32") == 0)
        return LIDET_VELODYNE_HDL32E;
    if (strcmp(sensor, "hdl64") == 0)
        return LIDET_VELODYNE_HDL64E;
    return 0;
}

static int vel_setup(cli_capture_t *c, cli_args_t *a)
{
    if (a->sensor_file != NULL || a->ouster_meta != NULL)
    {
        fprintf(stderr,
                "lidet %s: --pcap with --lidar velodyne takes the sensor from the packets or --sensor (vlp16, "
                "vlp32c, hdl32, hdl64; with --velodyne-calib the unit's calibration), not %s\n",
                cli_cmd, a->sensor_file != NULL ? "--sensor-file" : "--ouster-meta (--lidar ouster reads it)");
        return 1;
    }
    if (a->velodyne_calib != NULL && !a->sensor_given)
    {
        fprintf(stderr,
                "lidet %s: --velodyne-calib with --pcap needs --sensor vlp16, vlp32c, hdl32 or hdl64: the model of "
                "the calibrated unit (the decoder applies the calibration from the first packet on)\n",
                cli_cmd);
        return 1;
    }
    if (c->o.dual != NULL && strcmp(c->o.dual, "both") != 0 && strcmp(c->o.dual, "last") != 0 &&
        strcmp(c->o.dual, "strongest") != 0)
    {
        fprintf(stderr, "lidet %s: --dual with --lidar velodyne: both, last or strongest, not '%s'\n", cli_cmd,
                c->o.dual);
        return 1;
    }
    if (a->sensor_given)
    {
        const char *name = a->sensor_arg != NULL ? a->sensor_arg : a->sensor;
        c->model = c->dec_model = vel_model_of(name);
        if (c->model == 0)
        {
            fprintf(stderr,
                    "lidet %s: --sensor %s: the velodyne decoder's returns are those of vlp16, vlp32c, hdl32 or hdl64 "
                    "(or leave --sensor out: the packets say)\n",
                    cli_cmd, name);
            return 1;
        }
        c->sensor = vel_sensor_of(c->model);
        if (a->velodyne_calib != NULL)
        {
            /* the unit's table for the decoder (calibration_table's rules); the scans' sensor is the calibration's
             * description (cli_args_finish loaded it), its rings lowest first as the decoder numbers them */
            char err[256];
            if (cli_velodyne_calib_table(a, c->model, &c->vcal, err, sizeof err) != 0)
            {
                fprintf(stderr, "lidet %s: %s: %s (--sensor %s)\n", cli_cmd, a->velodyne_calib, err, name);
                return 1;
            }
            c->calibrated = 1;
            c->calib_path = a->velodyne_calib;
        }
    }
    else if (c->o.force_sensor)
    {
        fprintf(stderr, "lidet %s: --force-sensor needs --sensor (the model to decode every packet as)\n", cli_cmd);
        return 1;
    }
    c->port = c->o.port > 0 ? (uint32_t)c->o.port : 2368u;
    return 0;
}

static int vel_init(cli_capture_t *c)
{
    lidet_velodyne_cfg_t cfg;
    lidet_status_t st;
    lidet_velodyne_cfg_default(&cfg);
    cfg.model = (lidet_velodyne_model_t)c->dec_model;
    cfg.filter = c->o.dual == NULL || strcmp(c->o.dual, "both") == 0 ? LIDET_VELODYNE_RETURN_BOTH
                 : strcmp(c->o.dual, "last") == 0                    ? LIDET_VELODYNE_RETURN_LAST
                                                                     : LIDET_VELODYNE_RETURN_STRONGEST;
    cfg.force_model = (uint8_t)(c->o.force_sensor != 0);
    /* the hdl64 preset numbers its rings from the top (c->model: known in pass 2 also under AUTO, where pass 1 locked
     * it; pass 1 reads no ring); a calibration's description from the bottom, as the decoder by default */
    cfg.ring_top_first = (uint8_t)(c->model == LIDET_VELODYNE_HDL64E && !c->calibrated);
    cfg.calib = c->calibrated ? &c->vcal : NULL;
    st = lidet_velodyne_init(&c->vd, &cfg);
    if (st != LIDET_OK)
    {
        fprintf(stderr, "lidet %s: the Velodyne decoder%s%s: %s\n", cli_cmd,
                c->calibrated ? " refused the calibration " : "", c->calibrated ? c->calib_path : "",
                lidet_status_str(st));
        return 1;
    }
    c->have_t = 0;
    c->t_us = 0;
    return 0;
}

static void vel_packet(cli_capture_t *c, const uint8_t *p, uint32_t len, pkt_t *r)
{
    lidet_velodyne_result_t res;
    const lidet_status_t st = lidet_velodyne_packet(&c->vd, p, len, c->pkt, NULL, PKT_MAX_RETURNS, &res);
    memset(r, 0, sizeof *r);
    if (!LIDET_SUCCEEDED(st))
        return; /* rejected: counted in the decoder's stats by reason */
    r->decoded = 1;
    r->n_returns = res.n_returns;
    r->scan_end = res.scan_end;
    r->event = res.scan_event;
    if (c->return_mode == 0)
        c->return_mode = res.return_mode;
    /* microseconds past the hour: unwrapped (the nearest of +-1/2 hour to the previous packet's) */
    if (!c->have_t)
    {
        c->t_us = res.time_us;
        c->have_t = 1;
    }
    else
    {
        int64_t d = (int64_t)res.time_us - (int64_t)c->t_prev_raw;
        if (d < -1800000000LL)
            d += 3600000000LL;
        else if (d > 1800000000LL)
            d -= 3600000000LL;
        c->t_us += d;
    }
    c->t_prev_raw = res.time_us;
    r->t_us = c->t_us;
}

static void vel_counts(cli_capture_t *c)
{
    c->vstats = c->vd.stats;
    c->dc.n_packets = c->vstats.n_packets;
    c->dc.n_decoded = c->vstats.n_decoded;
    c->dc.n_partial = c->vstats.n_partial;
    c->dc.n_aborted = c->vstats.n_aborted;
}

static void vel_resolve(cli_capture_t *c, cli_args_t *a)
{
    if (c->model == 0) /* AUTO: the packets' model (locked by the first decoded one), and its preset */
        c->model = c->vd.model;
    c->sensor = vel_sensor_of(c->model);
    if (!a->sensor_given)
        set_sensor(a, c->sensor);
}

static int vel_whole_at_end(const cli_capture_t *c)
{
    (void)c;
    return 0; /* a rotation is known whole only when the next one begins */
}

static int vel_xyz(const cli_capture_t *c, const lidet_return_t *r, uint32_t n, float *xyz)
{
    uint32_t i;
    /* the decoder's own elevations: the model's nominal table or the calibration's, in its ring order */
    if (lidet_velodyne_decoder_xyz(&c->vd, r, n, xyz, 4u) != LIDET_OK)
        return 1;
    for (i = 0; i < n; ++i)
        xyz[4u * i + 3u] = 0.0f; /* no remission: the detector reads x, y, z */
    return 0;
}

static void vel_report(const cli_capture_t *c, FILE *f)
{
    const lidet_velodyne_stats_t *s = &c->vstats;
    /* the HDL-64E's payload has no return-mode byte: the decoder reports 0x39 for its dual-return layout */
    const char *mode = c->model == LIDET_VELODYNE_HDL64E && s->n_decoded > 0u && c->return_mode != 0x39u
                           ? "single return"
                       : c->return_mode == 0x37u                            ? "strongest return"
                       : c->return_mode == 0x38u                            ? "last return"
                       : c->return_mode == 0x39u                            ? "dual return"
                                                                            : "no data";
    uint32_t k, rej = 0;
    for (k = 1; k < LIDET_VELODYNE_N_REJECT; ++k)
        rej += s->n_rejected[k];
    fprintf(f,
            "lidet %s: decoder velodyne %s (%s%s%s%s): %u packets: %u decoded, %u rejected (size %u, product %u, "
            "mode %u, flag %u, azimuth %u, unsupported %u); %u azimuth jumps; %u returns between two boundaries of a "
            "packet dropped",
            cli_cmd, c->sensor != NULL ? c->sensor : "?", mode, c->o.force_sensor ? ", --force-sensor" : "",
            c->calibrated ? ", calibration " : "", c->calibrated ? c->calib_path : "", s->n_packets, s->n_decoded,
            rej, s->n_rejected[LIDET_VELODYNE_REJECT_SIZE], s->n_rejected[LIDET_VELODYNE_REJECT_PRODUCT],
            s->n_rejected[LIDET_VELODYNE_REJECT_MODE], s->n_rejected[LIDET_VELODYNE_REJECT_FLAG],
            s->n_rejected[LIDET_VELODYNE_REJECT_AZIMUTH], s->n_rejected[LIDET_VELODYNE_REJECT_UNSUPPORTED],
            s->n_jumps, s->n_fragment);
    if (c->calibrated)
        fprintf(f, "; %u returns the distance correction left at or below 0 m dropped", s->n_short_range);
    fprintf(f, "\n");
}

static void vel_no_data(const cli_capture_t *c, FILE *f)
{
    const lidet_velodyne_stats_t *s = &c->vstats;
    fprintf(f, "lidet %s: '%s': none of the %u packets to port %u is Velodyne data of ", cli_cmd, c->o.path,
            s->n_packets, c->port);
    if (c->model != 0)
        fprintf(f, "the model of --sensor %s", vel_sensor_of(c->model));
    else
        fprintf(f, "a known model (VLP-16, VLP-32C, HDL-32E, HDL-64E)");
    fprintf(f,
            "; the decoder rejected them: size %u (a data payload is 1206 bytes), product byte %u, return mode "
            "%u, block flag %u, azimuth %u, unsupported %u (HDL-64E dual return)%s\n",
            s->n_rejected[LIDET_VELODYNE_REJECT_SIZE], s->n_rejected[LIDET_VELODYNE_REJECT_PRODUCT],
            s->n_rejected[LIDET_VELODYNE_REJECT_MODE], s->n_rejected[LIDET_VELODYNE_REJECT_FLAG],
            s->n_rejected[LIDET_VELODYNE_REJECT_AZIMUTH], s->n_rejected[LIDET_VELODYNE_REJECT_UNSUPPORTED],
            s->n_rejected[LIDET_VELODYNE_REJECT_PRODUCT] > 0u && c->model != 0
                ? " (--force-sensor decodes them as --sensor's model; without --sensor the packets' model is used)"
                : "");
}

/* -- Ouster (lidet_ouster.h), its packet format and beams from --ouster-meta -- */

static const char *ous_profile_name(int profile)
{
    static const char *const names[] = {"LEGACY", "RNG19_RFL8_SIG16_NIR16_DUAL", "RNG19_RFL8_SIG16_NIR16",
                                        "RNG15_RFL8_NIR8"};
    return profile >= 1 && profile <= 4 ? names[profile - 1] : "?";
}

static int ous_setup(cli_capture_t *c, cli_args_t *a)
{
    uint32_t r;
    if (a->ouster_meta == NULL)
    {
        fprintf(stderr, "lidet %s: --lidar ouster needs the sensor's metadata: --ouster-meta M (its packet format "
                        "and beams)\n", cli_cmd);
        return 1;
    }
    if (c->o.force_sensor)
    {
        fprintf(stderr, "lidet %s: --force-sensor is the velodyne decoder's (the product byte)\n", cli_cmd);
        return 1;
    }
    if (c->o.dual != NULL && strcmp(c->o.dual, "both") != 0 && strcmp(c->o.dual, "first") != 0 &&
        strcmp(c->o.dual, "second") != 0)
    {
        fprintf(stderr, "lidet %s: --dual with --lidar ouster: both, first or second, not '%s'\n", cli_cmd,
                c->o.dual);
        return 1;
    }
    if (a->desc.rows < 1u || a->desc.rows > LIDET_OUSTER_MAX_BEAMS || a->desc.cols < 16u)
    {
        fprintf(stderr,
                "lidet %s: %s: %u beams and %u columns: the Ouster decoder takes 1..%u beams, >= 16 columns\n",
                cli_cmd, a->ouster_meta, (unsigned)a->desc.rows, (unsigned)a->desc.cols,
                (unsigned)LIDET_OUSTER_MAX_BEAMS);
        return 1;
    }
    if (cli_ouster_format(a, &c->ofmt) != 0)
        return 1;
    c->o_rows = a->desc.rows;
    c->o_cols = a->desc.cols;
    for (r = 0; r < c->o_rows; ++r)
        c->o_elev_rad[r] = a->desc.elev_rad[r];
    c->model = 1;
    c->sensor = a->sensor;
    c->port = c->o.port > 0 ? (uint32_t)c->o.port : c->ofmt.udp_port_lidar;
    return 0;
}

static int ous_init(cli_capture_t *c)
{
    lidet_ouster_cfg_t cfg;
    lidet_status_t st;
    lidet_ouster_cfg_default(&cfg);
    cfg.profile = (lidet_ouster_profile_t)c->ofmt.profile;
    cfg.header = (lidet_ouster_header_t)c->ofmt.header;
    cfg.filter = c->o.dual == NULL || strcmp(c->o.dual, "both") == 0 ? LIDET_OUSTER_RETURN_BOTH
                 : strcmp(c->o.dual, "first") == 0                   ? LIDET_OUSTER_RETURN_FIRST
                                                                     : LIDET_OUSTER_RETURN_SECOND;
    cfg.pixels_per_column = c->o_rows;
    cfg.columns_per_frame = c->o_cols;
    cfg.columns_per_packet = c->ofmt.columns_per_packet;
    cfg.azimuth_offset_bam = c->ofmt.azimuth_offset_bam;
    cfg.beam_azimuth_mdeg = c->ofmt.beam_azimuth_mdeg;
    cfg.init_id = c->ofmt.init_id;
    cfg.prod_sn = c->ofmt.prod_sn;
    st = lidet_ouster_init(&c->od, &cfg);
    if (st != LIDET_OK)
    {
        fprintf(stderr, "lidet %s: the Ouster decoder (the metadata's packet format): %s\n", cli_cmd,
                lidet_status_str(st));
        return 1;
    }
    return 0;
}

static void ous_packet(cli_capture_t *c, const uint8_t *p, uint32_t len, pkt_t *r)
{
    lidet_ouster_result_t res;
    const lidet_status_t st = lidet_ouster_packet(&c->od, p, len, c->pkt, NULL, PKT_MAX_RETURNS, &res);
    memset(r, 0, sizeof *r);
    if (!LIDET_SUCCEEDED(st))
        return;
    r->decoded = 1;
    r->n_returns = res.n_returns;
    r->scan_end = res.scan_end;
    r->event = res.scan_event;
    r->t_us = (int64_t)(res.time_ns / 1000u); /* the first valid column's timestamp */
}

static void ous_counts(cli_capture_t *c)
{
    c->ostats = c->od.stats;
    c->dc.n_packets = c->ostats.n_packets;
    c->dc.n_decoded = c->ostats.n_decoded;
    c->dc.n_partial = c->ostats.n_partial;
    c->dc.n_aborted = c->ostats.n_aborted;
}

static void ous_resolve(cli_capture_t *c, cli_args_t *a)
{
    (void)c;
    (void)a; /* the metadata's sensor, loaded by cli_parse */
}

static int ous_whole_at_end(const cli_capture_t *c)
{
    return c->od.have_prev && c->od.from_seam && c->od.prev_mid + 1u == c->o_cols;
}

static int ous_xyz(const cli_capture_t *c, const lidet_return_t *r, uint32_t n, float *xyz)
{
    /* from the lidar origin (lidet_ouster.h): x = R cos(e) cos(a), y = R cos(e) sin(a), z = R sin(e), e the
     * metadata's beam altitude of the return's row (ring) */
    const float bam_to_rad = (float)(2.0 * M_PI_D / 65536.0);
    float ce[LIDET_MAX_ROWS], se[LIDET_MAX_ROWS];
    uint32_t i;
    for (i = 0; i < c->o_rows; ++i)
    {
        ce[i] = cosf(c->o_elev_rad[i]);
        se[i] = sinf(c->o_elev_rad[i]);
    }
    for (i = 0; i < n; ++i)
    {
        float *p = xyz + 4u * (size_t)i;
        const float rm = (float)r[i].range_mm * 0.001f, a = (float)r[i].azimuth * bam_to_rad;
        if (r[i].ring >= c->o_rows)
            return 1;
        p[0] = rm * ce[r[i].ring] * cosf(a);
        p[1] = rm * ce[r[i].ring] * sinf(a);
        p[2] = rm * se[r[i].ring];
        p[3] = 0.0f;
    }
    return 0;
}

static void ous_report(const cli_capture_t *c, FILE *f)
{
    const lidet_ouster_stats_t *s = &c->ostats;
    uint32_t k, rej = 0;
    for (k = 1; k < LIDET_OUSTER_N_REJECT; ++k)
        rej += s->n_rejected[k];
    fprintf(f,
            "lidet %s: decoder ouster %s (%s, %u x %u): %u packets: %u decoded, %u rejected (truncated %u, size %u, "
            "header %u, status %u, order %u); %u invalid columns, %u lost columns, %u frame id jumps; %u returns "
            "between two boundaries of a packet dropped\n",
            cli_cmd, c->sensor != NULL ? c->sensor : "?", ous_profile_name(c->ofmt.profile),
            (unsigned)c->o_rows, (unsigned)c->o_cols, s->n_packets, s->n_decoded, rej,
            s->n_rejected[LIDET_OUSTER_REJECT_TRUNCATED], s->n_rejected[LIDET_OUSTER_REJECT_SIZE],
            s->n_rejected[LIDET_OUSTER_REJECT_HEADER], s->n_rejected[LIDET_OUSTER_REJECT_STATUS],
            s->n_rejected[LIDET_OUSTER_REJECT_ORDER], s->n_invalid_cols, s->n_lost_cols, s->n_jumps, s->n_fragment);
}

static void ous_no_data(const cli_capture_t *c, FILE *f)
{
    const lidet_ouster_stats_t *s = &c->ostats;
    fprintf(f,
            "lidet %s: '%s': none of the %u packets to port %u is lidar data of the metadata's format (%s, %u beams, "
            "%u bytes a packet); the decoder rejected them: truncated %u, size %u, header %u (another sensor's init "
            "id or serial number?), status %u, order %u\n",
            cli_cmd, c->o.path, s->n_packets, c->port, ous_profile_name(c->ofmt.profile),
            (unsigned)c->o_rows, lidet_ouster_packet_bytes(&c->od), s->n_rejected[LIDET_OUSTER_REJECT_TRUNCATED],
            s->n_rejected[LIDET_OUSTER_REJECT_SIZE], s->n_rejected[LIDET_OUSTER_REJECT_HEADER],
            s->n_rejected[LIDET_OUSTER_REJECT_STATUS], s->n_rejected[LIDET_OUSTER_REJECT_ORDER]);
}

static const lidar_t k_lidars[] = {
    {"velodyne", vel_setup, vel_init, vel_packet, vel_counts, vel_no_data, vel_resolve, vel_whole_at_end, vel_xyz,
     vel_report},
    {"ouster", ous_setup, ous_init, ous_packet, ous_counts, ous_no_data, ous_resolve, ous_whole_at_end, ous_xyz,
     ous_report},
};

/* ---- reading ------------------------------------------------------------------------------------------------ */

static int open_file(cli_capture_t *c)
{
    char eb[PCAP_ERRBUF_SIZE];
    struct stat st;
    eb[0] = '\0';
    if (stat(c->o.path, &st) != 0)
    {
        fprintf(stderr, "lidet %s: cannot open the capture '%s': %s\n", cli_cmd, c->o.path, strerror(errno));
        return 1;
    }
    if (!S_ISREG(st.st_mode))
    {
        fprintf(stderr, "lidet %s: the capture '%s' is not a file\n", cli_cmd, c->o.path);
        return 1;
    }
    if (st.st_size == 0)
    {
        fprintf(stderr, "lidet %s: the capture '%s' is empty (0 bytes)\n", cli_cmd, c->o.path);
        return 1;
    }
#ifdef PCAP_TSTAMP_PRECISION_MICRO
    c->h = pcap_open_offline_with_tstamp_precision(c->o.path, PCAP_TSTAMP_PRECISION_MICRO, eb);
#else
    c->h = pcap_open_offline(c->o.path, eb);
#endif
    if (c->h == NULL)
    {
        fprintf(stderr, "lidet %s: cannot read the capture '%s': %s (a pcap or pcapng file is needed)\n", cli_cmd,
                c->o.path, eb[0] != '\0' ? eb : "libpcap refused it");
        return 1;
    }
    c->link = pcap_datalink(c->h);
    if (!link_supported(c->link))
    {
        const char *name = pcap_datalink_val_to_name(c->link);
        fprintf(stderr,
                "lidet %s: '%s': link type %d (%s) is not read: Ethernet, Linux cooked (SLL) or raw IP frames\n",
                cli_cmd, c->o.path, c->link, name != NULL ? name : "unknown");
        pcap_close(c->h);
        c->h = NULL;
        return 1;
    }
    c->frame = 0;
    c->eof = 0;
    c->n_given = 0;
    c->in_scan = 0;
    c->pend = 0;
    return 0;
}

/* appends n returns to the scan in progress, up to LIDET_MAX_POINTS (the excess counted) */
static void append(cli_capture_t *c, const lidet_return_t *r, uint32_t n)
{
    const uint32_t room = (uint32_t)LIDET_MAX_POINTS - c->cur.n_returns;
    const uint32_t take = n < room ? n : room;
    memcpy(c->buf + c->cur.n_returns, r, sizeof(lidet_return_t) * take);
    c->cur.n_returns += take;
    c->cur.n_excess += n - take;
}

static void start_scan(cli_capture_t *c, uint32_t frame, int64_t t_us, double cap_s)
{
    memset(&c->cur, 0, sizeof c->cur);
    c->cur.first_frame = c->cur.last_frame = frame;
    c->cur.t_us = t_us;
    c->cur.capture_s = cap_s;
    c->in_scan = 1;
}

static void note_other_port(cli_capture_t *c, uint32_t port)
{
    uint32_t k, least = 0;
    for (k = 0; k < N_OTHER_PORTS; ++k)
    {
        if (c->other_count[k] > 0u && c->other_port[k] == port)
        {
            ++c->other_count[k];
            return;
        }
        if (c->other_count[k] < c->other_count[least])
            least = k;
    }
    if (c->other_count[least] == 0u)
    {
        c->other_port[least] = port;
        c->other_count[least] = 1u;
    }
}

/* Reads on to the end of the next scan to hand out: 1 (its returns in c->buf, *info), or 0 at the end of the file
 * (or at a damaged record: pass 1 notes it in c->damaged, c->err). */
static int advance(cli_capture_t *c, cli_scan_info_t *info)
{
    if (c->pend)
    {
        start_scan(c, c->pend_frame, c->pend_t, c->pend_cap);
        append(c, c->pkt + c->pend_from, c->pend_n - c->pend_from);
        c->pend = 0;
    }
    while (!c->eof)
    {
        struct pcap_pkthdr *hdr;
        const u_char *data;
        const uint8_t *pl = NULL;
        uint32_t len = 0, dport = 0, frame;
        double cap_s;
        pkt_t r;
        int kind;
        const int rc = pcap_next_ex(c->h, &hdr, &data);
        if (rc == PCAP_ERROR_BREAK || rc == 0)
        {
            c->eof = 1;
            break;
        }
        if (rc != 1)
        {
            /* a damaged record (a file cut short): the end of what can be read; the summary says so */
            if (c->pass == 1)
            {
                snprintf(c->err, sizeof c->err, "%s", pcap_geterr(c->h));
                c->damaged = 1;
            }
            c->eof = 1;
            break;
        }
        frame = c->frame++;
        kind = frame_udp(c->link, data, hdr->caplen, &pl, &len, &dport);
        if (kind == FRAME_PORT && dport != c->port)
            kind = FRAME_OTHER_PORT;
        if (kind == FRAME_TRUNCATED && hdr->caplen >= hdr->len)
            kind = FRAME_MALFORMED; /* nothing was cut: the headers are wrong */
        if (c->pass == 1)
        {
            ++c->n_frames;
            ++c->kinds[kind];
            if (kind == FRAME_OTHER_PORT)
                note_other_port(c, dport);
        }
        if (kind != FRAME_PORT)
            continue;
        c->lidar->packet(c, pl, len, &r);
        if (!r.decoded)
            continue;
        cap_s = (double)hdr->ts.tv_sec + (double)hdr->ts.tv_usec * 1e-6;
        if (!c->in_scan)
            start_scan(c, frame, r.t_us, cap_s);
        if (r.event == LIDET_VELODYNE_SCAN_NONE)
        {
            append(c, c->pkt, r.n_returns);
            c->cur.last_frame = frame;
            continue;
        }
        append(c, c->pkt, r.scan_end);
        c->cur.last_frame = frame;
        c->cur.kind = r.event;
        c->pend = 1;
        c->pend_from = r.scan_end;
        c->pend_n = r.n_returns;
        c->pend_frame = frame;
        c->pend_t = r.t_us;
        c->pend_cap = cap_s;
        if (r.event == LIDET_VELODYNE_SCAN_COMPLETE || c->o.partial)
        {
            *info = c->cur;
            info->index = c->n_given++;
            return 1;
        }
        start_scan(c, c->pend_frame, c->pend_t, c->pend_cap);
        append(c, c->pkt + c->pend_from, c->pend_n - c->pend_from);
        c->pend = 0;
    }
    if (c->in_scan)
    {
        const int whole = c->lidar->whole_at_end(c);
        c->in_scan = 0;
        if (c->pass == 1 && !whole)
        {
            c->n_unfinished = 1;
            c->n_unfinished_returns = c->cur.n_returns;
        }
        if (whole || c->o.partial)
        {
            c->cur.kind = whole ? LIDET_VELODYNE_SCAN_COMPLETE : LIDET_VELODYNE_SCAN_NONE;
            *info = c->cur;
            info->index = c->n_given++;
            return 1;
        }
    }
    return 0;
}

/* ---- the interface (cli.h) ------------------------------------------------------------------------------------ */

void cli_capture_close(cli_capture_t *c)
{
    if (c == NULL)
        return;
    if (c->h != NULL)
        pcap_close(c->h);
    free(c->scans);
    free(c->buf);
    free(c->xyz);
    free(c->ring);
    free(c);
}

/* pass 1 (cli_capture_open): the capture read once, frames counted, the scans listed, the sensor resolved into a;
 * need_scans 0 (--print-sensor): a capture without a scan to run is no error. 0 and *out, or 1 with a message. */
static int capture_read(const cli_pcap_opts_t *o, cli_args_t *a, cli_capture_t **out, int need_scans)
{
    cli_capture_t *c;
    cli_scan_info_t info;
    uint32_t k;
    int rc;
    *out = NULL;
    c = (cli_capture_t *)calloc(1, sizeof *c);
    if (c == NULL)
        return 1;
    c->o = *o;
    for (k = 0; k < sizeof k_lidars / sizeof k_lidars[0]; ++k)
        if (strcmp(o->lidar, k_lidars[k].name) == 0)
            c->lidar = &k_lidars[k];
    if (c->lidar == NULL || c->lidar->setup(c, a) != 0)
    {
        if (c->lidar == NULL)
            fprintf(stderr, "lidet %s: --lidar %s: no such decoder (velodyne, ouster)\n", cli_cmd, o->lidar);
        cli_capture_close(c);
        return 1;
    }
    c->buf = (lidet_return_t *)malloc(sizeof(lidet_return_t) * (size_t)LIDET_MAX_POINTS);
    c->xyz = (float *)malloc(sizeof(float) * 4u * (size_t)LIDET_MAX_POINTS);
    c->ring = (uint16_t *)malloc(sizeof(uint16_t) * (size_t)LIDET_MAX_POINTS);
    if (c->buf == NULL || c->xyz == NULL || c->ring == NULL || open_file(c) != 0 || c->lidar->init(c) != 0)
    {
        cli_capture_close(c);
        return 1;
    }
    /* pass 1: the frames counted, the scans listed */
    c->pass = 1;
    while ((rc = advance(c, &info)) == 1)
    {
        if (info.kind == LIDET_VELODYNE_SCAN_COMPLETE)
            ++c->n_complete;
        if (c->n_scans == c->cap_scans)
        {
            cli_scan_info_t *t;
            c->cap_scans = c->cap_scans ? 2u * c->cap_scans : 64u;
            t = (cli_scan_info_t *)realloc(c->scans, sizeof(cli_scan_info_t) * c->cap_scans);
            if (t == NULL)
            {
                cli_capture_close(c);
                return 1;
            }
            c->scans = t;
        }
        c->scans[c->n_scans++] = info;
    }
    (void)rc;
    c->lidar->counts(c);
    for (k = 0; k < c->n_scans; ++k)
    {
        c->n_excess += c->scans[k].n_excess;
        c->n_excess_scans += c->scans[k].n_excess > 0u;
    }
    if (c->damaged && c->n_frames == 0u)
    {
        fprintf(stderr, "lidet %s: '%s': no whole frame: %s\n", cli_cmd, o->path, c->err);
        cli_capture_close(c);
        return 1;
    }
    if (c->n_frames == 0u)
    {
        fprintf(stderr, "lidet %s: the capture '%s' holds no packet\n", cli_cmd, o->path);
        cli_capture_close(c);
        return 1;
    }
    if (c->kinds[FRAME_PORT] == 0u)
    {
        uint32_t best = 0;
        for (k = 1; k < N_OTHER_PORTS; ++k)
            if (c->other_count[k] > c->other_count[best])
                best = k;
        fprintf(stderr,
                "lidet %s: '%s' has no UDP packet to port %u: of its %u frames %u are UDP to other ports", cli_cmd,
                o->path, c->port, c->n_frames, c->kinds[FRAME_OTHER_PORT]);
        if (c->other_count[best] > 0u)
            fprintf(stderr, " (the most to port %u: %u)", c->other_port[best], c->other_count[best]);
        fprintf(stderr, ", %u not UDP over IPv4, %u truncated, %u malformed, %u IPv4 fragments (--port N: the data "
                        "port)\n",
                c->kinds[FRAME_NOT_UDP], c->kinds[FRAME_TRUNCATED], c->kinds[FRAME_MALFORMED],
                c->kinds[FRAME_FRAGMENT]);
        cli_capture_close(c);
        return 1;
    }
    if (c->dc.n_decoded == 0u)
    {
        c->lidar->no_data(c, stderr);
        cli_capture_close(c);
        return 1;
    }
    c->lidar->resolve(c, a);
    if (c->n_scans == 0u && need_scans)
    {
        (void)cli_capture_summary(c, stderr, NULL, 0);
        fprintf(stderr,
                "lidet %s: '%s' holds no complete rotation (%u partial, %u ended by a jump, %u unfinished at the "
                "end): --partial runs the detector on those\n",
                cli_cmd, o->path, c->dc.n_partial, c->dc.n_aborted, c->n_unfinished);
        cli_capture_close(c);
        return 1;
    }
    /* pass 2 starts at the first cli_capture_next */
    pcap_close(c->h);
    c->h = NULL;
    *out = c;
    return 0;
}

int cli_capture_open(const cli_pcap_opts_t *o, cli_args_t *a, cli_capture_t **out)
{
    return capture_read(o, a, out, 1);
}

int cli_capture_print_sensor(const cli_pcap_opts_t *o, cli_args_t *a)
{
    cli_capture_t *c = NULL;
    /* the decoder run over the capture as for the scans: the model locked by the first decoded packet under AUTO,
     * and a capture the decoder takes nothing of refused with the same message */
    if (capture_read(o, a, &c, 0) != 0)
        return 1;
    cli_capture_close(c);
    cli_sensor_print(a, stdout);
    return fflush(stdout) != 0;
}

uint32_t cli_capture_n_scans(const cli_capture_t *c)
{
    return c != NULL ? c->n_scans : 0u;
}

const cli_scan_info_t *cli_capture_info(const cli_capture_t *c, uint32_t k)
{
    return c != NULL && k < c->n_scans ? &c->scans[k] : NULL;
}

int cli_capture_next(cli_capture_t *c, cli_args_t *a, const lidet_return_t **rets, cli_scan_info_t *info)
{
    double t0;
    uint32_t i;
    int rc;
    if (c->n_given >= c->n_scans && c->pass == 2)
        return 0;
    t0 = cli_stage_clock_cpu ? cli_cpu_ms() : cli_now_ms();
    if (c->pass == 1)
    {
        if (open_file(c) != 0)
            return -1;
        if (c->lidar->init(c) != 0)
            return -1;
        c->pass = 2;
    }
    rc = advance(c, info);
    if (rc != 1 || info->first_frame != c->scans[info->index].first_frame ||
        info->last_frame != c->scans[info->index].last_frame ||
        info->n_returns != c->scans[info->index].n_returns)
    {
        fprintf(stderr, "lidet %s: '%s' read differently the second time: has it changed?\n", cli_cmd, c->o.path);
        return -1;
    }
    if (c->lidar->xyz(c, c->buf, info->n_returns, c->xyz) != 0)
    {
        fprintf(stderr, "lidet %s: a return of scan %u has no ring of the sensor\n", cli_cmd, info->index);
        return -1;
    }
    for (i = 0; i < info->n_returns; ++i)
        c->ring[i] = c->buf[i].ring;
    a->points = c->xyz;
    a->ring = c->ring;
    a->n_points = info->n_returns;
    *rets = c->buf;
    c->decode_ms += (cli_stage_clock_cpu ? cli_cpu_ms() : cli_now_ms()) - t0;
    return 1;
}


int cli_capture_summary(const cli_capture_t *c, FILE *f, const double *det_ms, uint32_t n_run)
{
    fprintf(f,
            "lidet %s: capture '%s': %u frames: %u UDP to port %u, %u UDP to other ports, %u not UDP over IPv4, %u "
            "truncated, %u malformed, %u IPv4 fragments (ignored)\n",
            cli_cmd, c->o.path, c->n_frames, c->kinds[FRAME_PORT], c->port, c->kinds[FRAME_OTHER_PORT],
            c->kinds[FRAME_NOT_UDP], c->kinds[FRAME_TRUNCATED], c->kinds[FRAME_MALFORMED], c->kinds[FRAME_FRAGMENT]);
    c->lidar->report(c, f);
    fprintf(f,
            "lidet %s: scans: %u complete; %s: %u partial (begun mid-rotation), %u aborted (jumps), %u "
            "unfinished at the end (%u returns); %llu returns past LIDET_MAX_POINTS (%u) dropped in %u scans\n",
            cli_cmd, c->n_complete, c->o.partial ? "also run" : "skipped", c->dc.n_partial, c->dc.n_aborted,
            c->n_unfinished, c->n_unfinished_returns, (unsigned long long)c->n_excess, (unsigned)LIDET_MAX_POINTS,
            c->n_excess_scans);
    if (det_ms != NULL && n_run > 0u)
    {
        double sum = 0.0, mx = 0.0;
        uint32_t k;
        for (k = 0; k < n_run; ++k)
        {
            sum += det_ms[k];
            mx = det_ms[k] > mx ? det_ms[k] : mx;
        }
        fprintf(f,
                "lidet %s: time: reading and decoding %.2f ms a scan (%.2f ms for %u scans), detector %.2f ms a "
                "scan (mean of %u, max %.2f)\n",
                cli_cmd, c->decode_ms / n_run, c->decode_ms, n_run, sum / n_run, n_run, mx);
    }
    if (c->damaged)
    {
        fprintf(f,
                "lidet %s: '%s' is cut short or damaged at its frame %u (libpcap: %s): the scans before it were run, "
                "the rest of the file cannot be read\n",
                cli_cmd, c->o.path, c->n_frames, c->err);
        return 1;
    }
    return 0;
}

#endif /* LIDET_HAVE_PCAP */
