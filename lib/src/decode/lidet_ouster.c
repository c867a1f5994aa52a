/* SPDX-License-Identifier: MIT */
/* Ouster packet decoding (see lidet_ouster.h and docs/OUSTER.md). Integers only: part of both builds.
 * Byte layouts: Ouster's OS1 manual ("Lidar Data Format", LEGACY), its firmware user manual ("Lidar Data") and
 * ouster-sdk's packet_format (ouster_client/src/parsing.cpp: offsets, masks and shifts of each profile's fields).
 * The pixel angle follows ouster-sdk's make_xyz_lut: encoder angle 2 pi (1 - measurement_id / columns_per_frame)
 * plus the beam's -beam_azimuth_angle, in the lidar frame. */
#include <string.h>

#include "lidet/lidet_ouster.h"

#define EUDP_HEADER_BYTES 32u /* packet header of the non-LEGACY profiles */
#define EUDP_FOOTER_BYTES 32u
#define EUDP_COL_HEADER_BYTES 12u
#define LEGACY_COL_HEADER_BYTES 16u
#define LEGACY_COL_FOOTER_BYTES 4u /* the column status */
#define LEGACY_VALID 0xFFFFFFFFu
#define MAX_PACKET_BYTES 65535u
#define MAX_COLS 16384u
#define MIN_COLS 16u
#define MAX_SN ((((uint64_t)1) << 40) - 1u)

static uint32_t rd16(const uint8_t *p)
{
    return (uint32_t)p[0] | ((uint32_t)p[1] << 8);
}

static uint32_t rd32(const uint8_t *p)
{
    return rd16(p) | (rd16(p + 2) << 16);
}

static uint64_t rd64(const uint8_t *p)
{
    return (uint64_t)rd32(p) | ((uint64_t)rd32(p + 4) << 32);
}

static uint32_t pixel_bytes(lidet_ouster_profile_t profile)
{
    switch (profile)
    {
    case LIDET_OUSTER_LEGACY:
    case LIDET_OUSTER_RNG19_RFL8_SIG16_NIR16:
        return 12u;
    case LIDET_OUSTER_RNG19_RFL8_SIG16_NIR16_DUAL:
        return 16u;
    case LIDET_OUSTER_RNG15_RFL8_NIR8:
        return 4u;
    default:
        return 0u;
    }
}

void lidet_ouster_cfg_default(lidet_ouster_cfg_t *cfg)
{
    if (cfg == 0)
    {
        return;
    }
    memset(cfg, 0, sizeof *cfg);
    cfg->profile = LIDET_OUSTER_RNG19_RFL8_SIG16_NIR16;
    cfg->header = LIDET_OUSTER_HEADER_STANDARD;
    cfg->filter = LIDET_OUSTER_RETURN_BOTH;
    cfg->columns_per_packet = 16u;
    cfg->azimuth_offset_bam = 32768u;
}

lidet_status_t lidet_ouster_init(lidet_ouster_t *st, const lidet_ouster_cfg_t *cfg)
{
    uint32_t px, legacy, col_bytes, packet_bytes, r;
    if (st == 0 || cfg == 0)
    {
        return LIDET_ERR_ARG;
    }
    px = pixel_bytes(cfg->profile);
    if (px == 0u ||
        (cfg->header != LIDET_OUSTER_HEADER_STANDARD && cfg->header != LIDET_OUSTER_HEADER_FUSA) ||
        (cfg->filter != LIDET_OUSTER_RETURN_BOTH && cfg->filter != LIDET_OUSTER_RETURN_FIRST &&
         cfg->filter != LIDET_OUSTER_RETURN_SECOND) ||
        cfg->pixels_per_column < 1u || cfg->pixels_per_column > LIDET_OUSTER_MAX_BEAMS ||
        cfg->columns_per_frame < MIN_COLS || cfg->columns_per_frame > MAX_COLS ||
        cfg->columns_per_packet < 1u || cfg->columns_per_packet > LIDET_OUSTER_MAX_COLS_PER_PACKET ||
        cfg->seam_col >= cfg->columns_per_frame || cfg->max_step_cols > cfg->columns_per_frame ||
        cfg->init_id > 0xFFFFFFu || cfg->prod_sn > MAX_SN)
    {
        return LIDET_ERR_CONFIG;
    }
    legacy = cfg->profile == LIDET_OUSTER_LEGACY;
    /* <= 16 + 128 x 16 + 4 bytes per column, <= 16 columns: no overflow before the 65535 check */
    col_bytes = (legacy ? LEGACY_COL_HEADER_BYTES + LEGACY_COL_FOOTER_BYTES : EUDP_COL_HEADER_BYTES) +
                cfg->pixels_per_column * px;
    packet_bytes =
        (legacy ? 0u : EUDP_HEADER_BYTES + EUDP_FOOTER_BYTES) + cfg->columns_per_packet * col_bytes;
    if (packet_bytes > MAX_PACKET_BYTES)
    {
        return LIDET_ERR_CONFIG;
    }
    if (cfg->beam_azimuth_mdeg != 0)
    {
        for (r = 0; r < cfg->pixels_per_column; ++r)
        {
            const int32_t a = cfg->beam_azimuth_mdeg[r];
            if (a <= -180000 || a >= 180000)
            {
                return LIDET_ERR_CONFIG;
            }
        }
    }
    memset(st, 0, sizeof *st);
    st->cfg = *cfg;
    st->cfg.beam_azimuth_mdeg = 0; /* read here only: the caller's table need not outlive init */
    if (st->cfg.max_step_cols == 0u)
    {
        st->cfg.max_step_cols = cfg->columns_per_frame;
    }
    st->packet_bytes = packet_bytes;
    st->col_bytes = (uint16_t)col_bytes;
    st->pixel_bytes = (uint8_t)px;
    if (cfg->beam_azimuth_mdeg != 0)
    {
        for (r = 0; r < cfg->pixels_per_column; ++r)
        {
            /* BAM16 = mdeg x 65536 / 360000 = mdeg x 1024 / 5625, rounded half away from zero; |mdeg x 1024| <
             * 1.9e8 */
            const int32_t n = cfg->beam_azimuth_mdeg[r] * 1024;
            const int32_t bam = n >= 0 ? (n + 2812) / 5625 : -((-n + 2812) / 5625);
            st->beam_az_bam[r] = (uint16_t)((uint32_t)bam & 0xFFFFu);
        }
    }
    st->magic = LIDET_INIT_MAGIC;
    return LIDET_OK;
}

lidet_status_t lidet_ouster_reset(lidet_ouster_t *st)
{
    if (st == 0)
    {
        return LIDET_ERR_ARG;
    }
    if (st->magic != LIDET_INIT_MAGIC)
    {
        return LIDET_ERR_STATE;
    }
    st->have_prev = 0u;
    st->from_seam = 0u;
    st->prev_frame = 0u;
    st->prev_mid = 0u;
    return LIDET_OK;
}

const lidet_ouster_stats_t *lidet_ouster_stats(const lidet_ouster_t *st)
{
    return st != 0 ? &st->stats : 0;
}

uint32_t lidet_ouster_packet_bytes(const lidet_ouster_t *st)
{
    return st != 0 && st->magic == LIDET_INIT_MAGIC ? st->packet_bytes : 0u;
}

uint32_t lidet_ouster_max_returns(const lidet_ouster_t *st)
{
    uint32_t n;
    if (st == 0 || st->magic != LIDET_INIT_MAGIC)
    {
        return 0u;
    }
    n = (uint32_t)st->cfg.columns_per_packet * st->cfg.pixels_per_column;
    return st->cfg.profile == LIDET_OUSTER_RNG19_RFL8_SIG16_NIR16_DUAL &&
                   st->cfg.filter == LIDET_OUSTER_RETURN_BOTH
               ? 2u * n
               : n;
}

/* Where the columns start, and the packet's frame id (non-LEGACY). */
static const uint8_t *first_col(const lidet_ouster_t *st, const uint8_t *p)
{
    return st->cfg.profile == LIDET_OUSTER_LEGACY ? p : p + EUDP_HEADER_BYTES;
}

static uint32_t packet_frame(const lidet_ouster_t *st, const uint8_t *p)
{
    return st->cfg.header == LIDET_OUSTER_HEADER_FUSA ? rd32(p + 4) : rd16(p + 2);
}

static uint32_t packet_init_id(const lidet_ouster_t *st, const uint8_t *p)
{
    return (st->cfg.header == LIDET_OUSTER_HEADER_FUSA ? rd32(p) >> 8 : rd32(p + 4)) & 0xFFFFFFu;
}

/* A non-LEGACY payload whose init id differs from the previous decoded one's: the sensor re-initialised (or
 * another sensor): its columns are not compared with the previous ones. */
static int restarted(const lidet_ouster_t *st, const uint8_t *p)
{
    return st->have_prev && st->cfg.profile != LIDET_OUSTER_LEGACY &&
           packet_init_id(st, p) != st->prev_init_id;
}

static int col_valid(const lidet_ouster_t *st, const uint8_t *col)
{
    if (st->cfg.profile == LIDET_OUSTER_LEGACY)
    {
        return rd32(col + st->col_bytes - LEGACY_COL_FOOTER_BYTES) == LEGACY_VALID;
    }
    return (col[10] & 1u) != 0u;
}

static uint32_t frame_mask(const lidet_ouster_t *st)
{
    return st->cfg.profile != LIDET_OUSTER_LEGACY && st->cfg.header == LIDET_OUSTER_HEADER_FUSA ? 0xFFFFFFFFu
                                                                                                : 0xFFFFu;
}

/* The step from column (f0, m0) to (f1, m1), columns: 0 when (f1, m1) does not come after (f0, m0) (the same
 * frame at a measurement id not above m0, or the frame before), else the step, capped at cpf + 1 (a jump: more
 * than max_step_cols <= cpf). */
static uint32_t col_step(const lidet_ouster_t *st, uint32_t f0, uint32_t m0, uint32_t f1, uint32_t m1)
{
    const uint32_t mask = frame_mask(st);
    const uint32_t df = (f1 - f0) & mask;
    const uint32_t cpf = st->cfg.columns_per_frame;
    if (df == 0u)
    {
        return m1 > m0 ? m1 - m0 : 0u;
    }
    if (df == mask)
    {
        return 0u;
    }
    if (df == 1u)
    {
        return cpf + m1 - m0; /* m0, m1 < cpf: in [1, 2 cpf) */
    }
    return cpf + 1u;
}

/* Checks the whole payload; returns the reason it is rejected, or NONE. */
static lidet_ouster_reject_t check(const lidet_ouster_t *st, const uint8_t *p, uint32_t len)
{
    const int legacy = st->cfg.profile == LIDET_OUSTER_LEGACY;
    const uint8_t *col;
    uint32_t c, n_valid = 0u, have, f0 = st->prev_frame, m0 = st->prev_mid, frame = 0u;
    if (p == 0)
    {
        return LIDET_OUSTER_REJECT_NULL;
    }
    if (len < st->packet_bytes)
    {
        return LIDET_OUSTER_REJECT_TRUNCATED;
    }
    if (len > st->packet_bytes)
    {
        return LIDET_OUSTER_REJECT_SIZE;
    }
    if (!legacy)
    {
        const int fusa = st->cfg.header == LIDET_OUSTER_HEADER_FUSA;
        const uint32_t type = fusa ? p[0] : rd16(p);
        const uint32_t init_id = packet_init_id(st, p);
        const uint64_t sn = (fusa ? (uint64_t)p[11] | ((uint64_t)rd32(p + 12) << 8)
                                  : (uint64_t)rd32(p + 7) | ((uint64_t)p[11] << 32));
        if (type != 1u || (st->cfg.init_id != 0u && init_id != st->cfg.init_id) ||
            (st->cfg.prod_sn != 0u && sn != st->cfg.prod_sn))
        {
            return LIDET_OUSTER_REJECT_HEADER;
        }
        frame = packet_frame(st, p);
    }
    have = st->have_prev && !restarted(st, p);
    col = first_col(st, p);
    for (c = 0; c < st->cfg.columns_per_packet; ++c, col += st->col_bytes)
    {
        uint32_t m;
        if (!col_valid(st, col))
        {
            continue;
        }
        m = rd16(col + 8);
        if (m >= st->cfg.columns_per_frame || (legacy && rd32(col + 12) >= LIDET_OUSTER_ENCODER_TICKS))
        {
            return LIDET_OUSTER_REJECT_HEADER;
        }
        if (legacy)
        {
            frame = rd16(col + 10);
        }
        if (have && col_step(st, f0, m0, frame, m) == 0u)
        {
            return LIDET_OUSTER_REJECT_ORDER;
        }
        have = 1u;
        f0 = frame;
        m0 = m;
        ++n_valid;
    }
    return n_valid == 0u ? LIDET_OUSTER_REJECT_STATUS : LIDET_OUSTER_REJECT_NONE;
}

/* Closes the scan in progress at output index n (see lidet_ouster_packet); returns the new fill count. */
static uint32_t boundary(lidet_ouster_t *st, lidet_ouster_result_t *res, uint32_t n, uint8_t kind)
{
    if (res->scan_event == LIDET_OUSTER_SCAN_NONE)
    {
        res->scan_event = kind;
        res->scan_end = n;
        if (kind == LIDET_OUSTER_SCAN_COMPLETE)
        {
            ++st->stats.n_scans;
        }
        else if (kind == LIDET_OUSTER_SCAN_PARTIAL)
        {
            ++st->stats.n_partial;
        }
        else
        {
            ++st->stats.n_aborted;
        }
        return n;
    }
    /* a second boundary in one payload: what lies between the two is a piece of no rotation */
    st->stats.n_fragment += n - res->scan_end;
    st->stats.n_returns -= n - res->scan_end;
    return res->scan_end;
}

/* Scan tracking at a valid column (frame f, measurement id m); returns the new fill count. */
static uint32_t track(lidet_ouster_t *st, lidet_ouster_result_t *res, uint32_t n, uint32_t f, uint32_t m)
{
    const uint32_t cpf = st->cfg.columns_per_frame, seam = st->cfg.seam_col;
    if (!st->have_prev)
    {
        st->have_prev = 1u;
        st->from_seam = m == seam; /* a first column at the seam begins a whole scan */
    }
    else
    {
        const uint32_t d = col_step(st, st->prev_frame, st->prev_mid, f, m); /* >= 1: check() passed */
        if (d > st->cfg.max_step_cols)
        {
            ++st->stats.n_jumps;
            n = boundary(st, res, n, LIDET_OUSTER_SCAN_ABORTED);
            st->from_seam = m == seam;
        }
        else
        {
            st->stats.n_lost_cols += d - 1u;
            /* the seam lies in (prev, this]: the distance from the seam to prev plus the step reaches a turn
             * (d <= cpf: at most one crossing) */
            if ((st->prev_mid + cpf - seam) % cpf + d >= cpf)
            {
                n = boundary(st, res, n,
                             st->from_seam ? LIDET_OUSTER_SCAN_COMPLETE : LIDET_OUSTER_SCAN_PARTIAL);
                st->from_seam = 1u;
            }
        }
    }
    st->prev_frame = f;
    st->prev_mid = (uint16_t)m;
    return n;
}

typedef struct
{
    lidet_return_t *out;
    lidet_ouster_attr_t *attr;
    uint32_t cap;
    uint32_t n;
    lidet_ouster_stats_t *stats;
} sink_t;

static void emit(sink_t *s, uint32_t range_mm, uint32_t ring, uint32_t bam, const lidet_ouster_attr_t *a)
{
    if (s->n >= s->cap)
    {
        ++s->stats->n_truncated;
        return;
    }
    s->out[s->n].range_mm = range_mm;
    s->out[s->n].azimuth = (uint16_t)(bam & 0xFFFFu);
    s->out[s->n].ring = (uint16_t)ring;
    if (s->attr != 0)
    {
        s->attr[s->n] = *a;
    }
    ++s->n;
    ++s->stats->n_returns;
}

/* The pixels of one valid column. */
static void decode_col(const lidet_ouster_t *st, sink_t *s, const uint8_t *col, uint32_t col_bam,
                       uint32_t t_ns)
{
    const lidet_ouster_profile_t profile = st->cfg.profile;
    const uint8_t *px =
        col + (profile == LIDET_OUSTER_LEGACY ? LEGACY_COL_HEADER_BYTES : EUDP_COL_HEADER_BYTES);
    lidet_ouster_attr_t a;
    uint32_t r;
    a.t_ns = t_ns;
    a.measurement_id = (uint16_t)rd16(col + 8);
    for (r = 0; r < st->cfg.pixels_per_column; ++r, px += st->pixel_bytes)
    {
        const uint32_t bam = col_bam - st->beam_az_bam[r]; /* mod 2^16 at emit */
        a.return_index = 0u;
        switch (profile)
        {
        case LIDET_OUSTER_LEGACY:
        {
            const uint32_t range = rd32(px) & 0xFFFFFu;
            if (range != 0u)
            {
                a.flags = (uint8_t)(px[3] >> 4);
                a.reflectivity = (uint16_t)rd16(px + 4);
                a.signal = (uint16_t)rd16(px + 6);
                emit(s, range, r, bam, &a);
            }
            break;
        }
        case LIDET_OUSTER_RNG19_RFL8_SIG16_NIR16:
        {
            const uint32_t range = rd32(px) & 0x7FFFFu;
            if (range != 0u)
            {
                a.flags = (uint8_t)(px[2] >> 3);
                a.reflectivity = px[4];
                a.signal = (uint16_t)rd16(px + 6);
                emit(s, range, r, bam, &a);
            }
            break;
        }
        case LIDET_OUSTER_RNG19_RFL8_SIG16_NIR16_DUAL:
        {
            const uint32_t r0 = rd32(px) & 0x7FFFFu, r1 = rd32(px + 4) & 0x7FFFFu;
            if (r0 != 0u && st->cfg.filter != LIDET_OUSTER_RETURN_SECOND)
            {
                a.flags = (uint8_t)(px[2] >> 3);
                a.reflectivity = px[3];
                a.signal = (uint16_t)rd16(px + 8);
                emit(s, r0, r, bam, &a);
            }
            if (r1 != 0u && st->cfg.filter != LIDET_OUSTER_RETURN_FIRST)
            {
                a.return_index = 1u;
                a.flags = (uint8_t)(px[6] >> 3);
                a.reflectivity = px[7];
                a.signal = (uint16_t)rd16(px + 10);
                emit(s, r1, r, bam, &a);
            }
            break;
        }
        default: /* RNG15_RFL8_NIR8 (init admits no other) */
        {
            const uint32_t range = rd16(px) & 0x7FFFu;
            if (range != 0u)
            {
                a.flags = (uint8_t)(px[1] >> 7);
                a.reflectivity = px[2];
                a.signal = 0u;
                emit(s, range * 8u, r, bam, &a);
            }
            break;
        }
        }
    }
}

lidet_status_t lidet_ouster_packet(lidet_ouster_t *st, const uint8_t *payload, uint32_t len,
                                   lidet_return_t *out, lidet_ouster_attr_t *attr, uint32_t cap,
                                   lidet_ouster_result_t *res)
{
    lidet_ouster_reject_t why;
    const uint8_t *col;
    uint32_t c, frame = 0u, trunc0, cpf;
    int legacy, first = 1, restart;
    sink_t s;
    if (st == 0 || res == 0 || (out == 0 && cap > 0u))
    {
        return LIDET_ERR_ARG;
    }
    memset(res, 0, sizeof *res);
    if (st->magic != LIDET_INIT_MAGIC)
    {
        return LIDET_ERR_STATE;
    }
    ++st->stats.n_packets;
    why = check(st, payload, len);
    if (why != LIDET_OUSTER_REJECT_NONE)
    {
        res->reject = (uint8_t)why;
        ++st->stats.n_rejected[why];
        return LIDET_ERR_MODEL;
    }
    ++st->stats.n_decoded;
    legacy = st->cfg.profile == LIDET_OUSTER_LEGACY;
    cpf = st->cfg.columns_per_frame;
    restart = restarted(st, payload);
    if (!legacy)
    {
        frame = packet_frame(st, payload);
        res->frame_id = frame;
        st->prev_init_id = packet_init_id(st, payload);
    }
    s.out = out;
    s.attr = attr;
    s.cap = cap;
    s.n = 0u;
    s.stats = &st->stats;
    trunc0 = st->stats.n_truncated;
    col = first_col(st, payload);
    for (c = 0; c < st->cfg.columns_per_packet; ++c, col += st->col_bytes)
    {
        uint32_t m, col_bam;
        uint64_t ts;
        if (!col_valid(st, col))
        {
            ++st->stats.n_invalid_cols;
            continue;
        }
        m = rd16(col + 8);
        ts = rd64(col);
        if (legacy)
        {
            frame = rd16(col + 10);
        }
        if (first)
        {
            first = 0;
            res->time_ns = ts;
            res->frame_id = frame;
            if (restart)
            {
                /* a new sensor session: the scan in progress ends here, aborted, and the next starts afresh */
                ++st->stats.n_jumps;
                s.n = boundary(st, res, s.n, LIDET_OUSTER_SCAN_ABORTED);
                st->have_prev = 0u;
            }
        }
        ++res->n_valid_cols;
        s.n = track(st, res, s.n, frame, m);
        /* the encoder angle, clockwise: m / cpf of a turn in BAM16, rounded (m < cpf <= 16384: m 65536 < 2^31) */
        col_bam = (uint32_t)st->cfg.azimuth_offset_bam + 65536u - (m * 65536u + cpf / 2u) / cpf;
        decode_col(st, &s, col, col_bam, (uint32_t)(ts - res->time_ns));
    }
    res->n_returns = s.n;
    if (res->scan_event == LIDET_OUSTER_SCAN_NONE)
    {
        res->scan_end = s.n;
    }
    return st->stats.n_truncated != trunc0 ? LIDET_TRUNCATED : LIDET_OK;
}
