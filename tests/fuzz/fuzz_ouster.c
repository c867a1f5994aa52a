/* SPDX-License-Identifier: MIT */
/* libFuzzer harness: the Ouster packet decoder (lidet_ouster_init, lidet_ouster_packet, lidet_ouster_reset) on a
 * stream of payloads the input describes.
 *
 * Layout: a configuration (byte 0: profile % 4 -> LEGACY, DUAL, single, low data rate; bits 2-3 filter (3 is
 * invalid); bit 4 FUSA header; bit 5 init id and bit 6 serial number configured; bit 7 a beam azimuth table
 * follows. Byte 1: pixels per column 1 + b % 128. u16 columns per frame: bit 15 set, the low 15 bits raw (0 to
 * 32767: init refuses those outside [16, 16384]), else 16 + v % 113. Byte: columns per packet b % 18 (0 and 17
 * refused). u16 seam and u16 max step: bit 15 set, raw, else modulo the columns per frame (+ 1 for the step).
 * u16 azimuth offset. With bit 7, per beam a beam azimuth of int16 x 6 mdeg (some beyond +-180000: refused).
 * u32 init id and 6 bytes of serial number (raw: some beyond 24 / 40 bits: refused)), then up to 48 operations
 * of [op byte][room byte][u16 pixel seed][u16 argument]:
 *  - op % 16 == 0: 40 more input bytes, then a raw payload of u16 argument % (packet bytes + 64) bytes (the PRNG's,
 *    its first 40 those bytes); op % 16 == 1: a NULL payload; op % 16 == 2: lidet_ouster_reset;
 *  - otherwise a well-formed payload of the configured size: packet type 1, the configured (or, with op bit 4, a
 *    new) init id and serial number, columns at consecutive measurement ids from the stream's position, which the
 *    argument moves first (op bits 5-6: 1 a step of argument % 64 columns forward, 2 back, 3 a frame id jump);
 *    column i invalid when bit i of the argument's low byte is set and op bit 7 is set; LEGACY encoder counts
 *    from the measurement id; pixels from a PRNG seeded by the pixel seed (a quarter of the ranges 0).
 * Room: bit 0 set, lidet_ouster_max_returns (), else room >> 1 (0 to 127).
 *
 * Checks: init refuses exactly the invalid configurations and takes the valid ones; each payload is rejected for
 * exactly the reason the header documents, or decoded; every payload's status and result agree (a rejected payload emits nothing and leaves the rotation state as it was); nothing is written past
 * the room; each decoded payload's returns are, in order, those of an independent reading of the payload (the
 * profile's layout as docs/OUSTER.md gives it: ring, range, azimuth, measurement id, time, signal, reflectivity,
 * return index and flags), less the returns of a fragment between two scan boundaries and those past the room,
 * as the counts say; the scan tracking agrees with a mirror of its documented rule (the events, where the boundary
 * falls, fragments, jumps, lost columns); the counts add up (packets, rejections by reason, returns); and no scan is spliced from two
 * rotations: within each scan (the returns between two scan events, as a caller assembles them) the measurement
 * ids, counted from the seam, never decrease, so a scan never covers more than one turn. */
#include "fuzz_common.h"

#include "lidet/lidet_ouster.h"

#define MAX_PAYLOAD 65535u
#define MAX_OPS 48u

static lidet_ouster_t g_dec;
static lidet_return_t g_out[LIDET_OUSTER_MAX_RETURNS + 1];
static lidet_ouster_attr_t g_attr[LIDET_OUSTER_MAX_RETURNS + 1];
static lidet_return_t g_exp[LIDET_OUSTER_MAX_RETURNS];
static lidet_ouster_attr_t g_exp_attr[LIDET_OUSTER_MAX_RETURNS];
static uint8_t g_pkt[MAX_PAYLOAD + 64u];
/* the valid columns of the payload read_payload read last: frame id, measurement id, index of the first return */
static uint32_t g_col_frame[LIDET_OUSTER_MAX_COLS_PER_PACKET], g_col_mid[LIDET_OUSTER_MAX_COLS_PER_PACKET],
    g_col_first[LIDET_OUSTER_MAX_COLS_PER_PACKET], g_n_cols;

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static uint32_t rd16(const uint8_t *p)
{
    return (uint32_t)p[0] | ((uint32_t)p[1] << 8);
}

static uint32_t rd32(const uint8_t *p)
{
    return rd16(p) | (rd16(p + 2) << 16);
}

static void wr16(uint8_t *p, uint32_t v)
{
    p[0] = (uint8_t)(v & 0xFFu);
    p[1] = (uint8_t)((v >> 8) & 0xFFu);
}

static void wr32(uint8_t *p, uint32_t v)
{
    wr16(p, v & 0xFFFFu);
    wr16(p + 2, v >> 16);
}

static uint32_t xorshift(uint32_t *s)
{
    uint32_t x = *s;
    x ^= x << 13;
    x ^= x >> 17;
    x ^= x << 5;
    *s = x;
    return x;
}

static uint32_t pixel_bytes(lidet_ouster_profile_t p)
{
    return p == LIDET_OUSTER_RNG19_RFL8_SIG16_NIR16_DUAL ? 16u
                                                         : (p == LIDET_OUSTER_RNG15_RFL8_NIR8 ? 4u : 12u);
}

/* the harness's own reading of a payload the decoder took: every return in the decoder's documented order (column
 * by column, a column's pixels by row, a DUAL pixel's first return first), azimuths with the decoder's beam table
 * (checked against the configuration separately). Returns the count. */
static uint32_t read_payload(const lidet_ouster_cfg_t *cfg, const uint16_t *beam_bam, const uint8_t *p)
{
    const int legacy = cfg->profile == LIDET_OUSTER_LEGACY;
    const uint32_t px = pixel_bytes(cfg->profile), ppc = cfg->pixels_per_column, cpf = cfg->columns_per_frame;
    const uint32_t col_bytes = (legacy ? 20u : 12u) + ppc * px;
    const uint8_t *col = legacy ? p : p + 32;
    uint32_t c, r, n = 0, t0 = 0;
    int first = 1;
    g_n_cols = 0;
    for (c = 0; c < cfg->columns_per_packet; ++c, col += col_bytes)
    {
        const int valid = legacy ? rd32(col + col_bytes - 4u) == 0xFFFFFFFFu : (col[10] & 1u) != 0u;
        const uint32_t m = rd16(col + 8), t = rd32(col);
        const uint8_t *q = col + (legacy ? 16u : 12u);
        uint32_t col_bam;
        if (!valid)
        {
            continue;
        }
        if (first)
        {
            t0 = t;
            first = 0;
        }
        g_col_frame[g_n_cols] =
            legacy ? rd16(col + 10) : (cfg->header == LIDET_OUSTER_HEADER_FUSA ? rd32(p + 4) : rd16(p + 2));
        g_col_mid[g_n_cols] = m;
        g_col_first[g_n_cols++] = n;
        /* the encoder angle: m / cpf of a turn, clockwise, rounded to BAM16 */
        col_bam = cfg->azimuth_offset_bam + 65536u - (uint32_t)(((uint64_t)m * 65536u + cpf / 2u) / cpf);
        for (r = 0; r < ppc; ++r, q += px)
        {
            uint32_t rng[2] = {0u, 0u}, refl[2] = {0u, 0u}, sig[2] = {0u, 0u}, fl[2] = {0u, 0u}, k;
            switch (cfg->profile)
            {
            case LIDET_OUSTER_LEGACY:
                rng[0] = rd32(q) & 0xFFFFFu;
                fl[0] = q[3] >> 4;
                refl[0] = rd16(q + 4);
                sig[0] = rd16(q + 6);
                break;
            case LIDET_OUSTER_RNG19_RFL8_SIG16_NIR16:
                rng[0] = rd32(q) & 0x7FFFFu;
                fl[0] = q[2] >> 3;
                refl[0] = q[4];
                sig[0] = rd16(q + 6);
                break;
            case LIDET_OUSTER_RNG19_RFL8_SIG16_NIR16_DUAL:
                rng[0] = cfg->filter == LIDET_OUSTER_RETURN_SECOND ? 0u : rd32(q) & 0x7FFFFu;
                fl[0] = q[2] >> 3;
                refl[0] = q[3];
                sig[0] = rd16(q + 8);
                rng[1] = cfg->filter == LIDET_OUSTER_RETURN_FIRST ? 0u : rd32(q + 4) & 0x7FFFFu;
                fl[1] = q[6] >> 3;
                refl[1] = q[7];
                sig[1] = rd16(q + 10);
                break;
            default:
                rng[0] = (rd16(q) & 0x7FFFu) * 8u;
                fl[0] = q[1] >> 7;
                refl[0] = q[2];
                break;
            }
            for (k = 0; k < 2u; ++k)
            {
                if (rng[k] == 0u)
                {
                    continue;
                }
                g_exp[n].range_mm = rng[k];
                g_exp[n].ring = (uint16_t)r;
                g_exp[n].azimuth = (uint16_t)((col_bam - beam_bam[r]) & 0xFFFFu);
                memset(&g_exp_attr[n], 0, sizeof g_exp_attr[n]);
                g_exp_attr[n].t_ns = t - t0; /* the low 32 bits of the 64-bit difference */
                g_exp_attr[n].measurement_id = (uint16_t)m;
                g_exp_attr[n].signal = (uint16_t)sig[k];
                g_exp_attr[n].reflectivity = (uint16_t)refl[k];
                g_exp_attr[n].return_index = (uint8_t)k;
                g_exp_attr[n].flags = (uint8_t)fl[k];
                ++n;
            }
        }
    }
    return n;
}

/* The scan tracking as lidet_ouster.h states it, in positions counted along the rotation: a step of at most
 * max_step_cols columns from the previous valid column is the rotation (the columns between are lost), a larger one
 * a jump that ends the scan as ABORTED, as does a new init id (non-LEGACY); a step that passes a multiple of a turn
 * after the seam ends it as COMPLETE when the scan began at the seam (PARTIAL otherwise). */
typedef struct
{
    int have, whole;
    uint32_t frame, mid, init_id;
    uint32_t n_jumps, n_lost, n_events[4];
} mirror_t;

typedef struct
{
    uint32_t kind, first, last; /* the first event's kind and return index, the last event's return index */
} events_t;

static void mirror_event(mirror_t *mr, events_t *ev, uint32_t kind, uint32_t at)
{
    if (ev->kind == LIDET_OUSTER_SCAN_NONE)
    {
        ev->kind = kind;
        ev->first = at;
        ++mr->n_events[kind];
    }
    ev->last = at;
}

static void mirror_payload(mirror_t *mr, const lidet_ouster_cfg_t *cfg, const uint8_t *p, events_t *ev)
{
    const int legacy = cfg->profile == LIDET_OUSTER_LEGACY, fusa = cfg->header == LIDET_OUSTER_HEADER_FUSA;
    const uint32_t cpf = cfg->columns_per_frame, seam = cfg->seam_col;
    const uint32_t frames = !legacy && fusa ? 0xFFFFFFFFu : 0xFFFFu; /* frame ids modulo frames + 1 */
    uint32_t c;
    ev->kind = LIDET_OUSTER_SCAN_NONE;
    ev->first = ev->last = 0;
    if (!legacy)
    {
        const uint32_t id = (fusa ? rd32(p) >> 8 : rd32(p + 4)) & 0xFFFFFFu;
        if (mr->have && id != mr->init_id)
        {
            ++mr->n_jumps;
            mirror_event(mr, ev, LIDET_OUSTER_SCAN_ABORTED, 0u); /* before the first valid column's returns */
            mr->have = 0;
        }
        mr->init_id = id;
    }
    for (c = 0; c < g_n_cols; ++c)
    {
        const uint32_t f = g_col_frame[c], m = g_col_mid[c];
        if (mr->have)
        {
            /* positions: frame x cpf + mid, the frame counted on from the previous one (modulo its width) */
            const uint64_t df = (uint64_t)((f - mr->frame) & frames);
            const uint64_t step =
                df * cpf + m - mr->mid; /* >= 1: the payload was not rejected for its order */
            FZ_CHECK(step >= 1u && df < frames);
            if (step > cfg->max_step_cols)
            {
                ++mr->n_jumps;
                mirror_event(mr, ev, LIDET_OUSTER_SCAN_ABORTED, g_col_first[c]);
                mr->whole = m == seam;
            }
            else
            {
                /* turns completed since the seam: before and after the step */
                const uint64_t before = (mr->mid + cpf - seam) % cpf;
                mr->n_lost += (uint32_t)step - 1u;
                if ((before + step) / cpf >= 1u)
                {
                    mirror_event(mr, ev, mr->whole ? LIDET_OUSTER_SCAN_COMPLETE : LIDET_OUSTER_SCAN_PARTIAL,
                                 g_col_first[c]);
                    mr->whole = 1;
                }
            }
        }
        else
        {
            mr->have = 1;
            mr->whole = m == seam;
        }
        mr->frame = f;
        mr->mid = m;
    }
}

/* The rejection lidet_ouster.h documents for a payload, given the mirror's rotation state: NULL, then the length,
 * the packet header (type 1, the configured init id and serial number), then column by column the valid ones'
 * measurement id (< cpf) and LEGACY encoder count (< 90112) and their order after the previous valid column (the
 * last decoded one's unless the init id changed), then no valid column at all. */
static uint32_t expect_reject(const mirror_t *mr, const lidet_ouster_cfg_t *cfg, const uint8_t *p,
                              uint32_t len, uint32_t packet_bytes)
{
    const int legacy = cfg->profile == LIDET_OUSTER_LEGACY, fusa = cfg->header == LIDET_OUSTER_HEADER_FUSA;
    const uint32_t frames = !legacy && fusa ? 0xFFFFFFFFu : 0xFFFFu;
    const uint32_t col_bytes = (legacy ? 20u : 12u) + cfg->pixels_per_column * pixel_bytes(cfg->profile);
    uint32_t c, f0 = mr->frame, m0 = mr->mid, frame = 0, n_valid = 0;
    int have = mr->have;
    const uint8_t *col;
    if (p == NULL)
    {
        return LIDET_OUSTER_REJECT_NULL;
    }
    if (len != packet_bytes)
    {
        return len < packet_bytes ? LIDET_OUSTER_REJECT_TRUNCATED : LIDET_OUSTER_REJECT_SIZE;
    }
    if (!legacy)
    {
        const uint32_t type = fusa ? p[0] : rd16(p), id = (fusa ? rd32(p) >> 8 : rd32(p + 4)) & 0xFFFFFFu;
        const uint64_t sn = fusa ? (uint64_t)p[11] | ((uint64_t)rd32(p + 12) << 8)
                                 : (uint64_t)rd32(p + 7) | ((uint64_t)p[11] << 32);
        if (type != 1u || (cfg->init_id != 0u && id != cfg->init_id) ||
            (cfg->prod_sn != 0u && sn != cfg->prod_sn))
        {
            return LIDET_OUSTER_REJECT_HEADER;
        }
        have = have && id == mr->init_id;
        frame = fusa ? rd32(p + 4) : rd16(p + 2);
    }
    for (c = 0, col = legacy ? p : p + 32; c < cfg->columns_per_packet; ++c, col += col_bytes)
    {
        uint32_t m;
        if (legacy ? rd32(col + col_bytes - 4u) != 0xFFFFFFFFu : (col[10] & 1u) == 0u)
        {
            continue;
        }
        m = rd16(col + 8);
        if (m >= cfg->columns_per_frame || (legacy && rd32(col + 12) >= LIDET_OUSTER_ENCODER_TICKS))
        {
            return LIDET_OUSTER_REJECT_HEADER;
        }
        if (legacy)
        {
            frame = rd16(col + 10);
        }
        if (have && ((((frame - f0) & frames) == 0u && m <= m0) || ((frame - f0) & frames) == frames))
        {
            return LIDET_OUSTER_REJECT_ORDER;
        }
        have = 1;
        f0 = frame;
        m0 = m;
        ++n_valid;
    }
    return n_valid == 0u ? LIDET_OUSTER_REJECT_STATUS : LIDET_OUSTER_REJECT_NONE;
}

static int same_return(uint32_t i, uint32_t j)
{
    const lidet_ouster_attr_t *a = &g_attr[i], *b = &g_exp_attr[j];
    return g_out[i].range_mm == g_exp[j].range_mm && g_out[i].ring == g_exp[j].ring &&
           g_out[i].azimuth == g_exp[j].azimuth && a->t_ns == b->t_ns &&
           a->measurement_id == b->measurement_id && a->signal == b->signal &&
           a->reflectivity == b->reflectivity && a->return_index == b->return_index && a->flags == b->flags;
}

/* the scan a caller assembles: its last return's measurement id counted from the seam, and whether it has one */
typedef struct
{
    uint32_t key;
    int open;
} scan_t;

static void scan_add(scan_t *s, const lidet_ouster_cfg_t *cfg, uint32_t from, uint32_t to)
{
    uint32_t i;
    for (i = from; i < to; ++i)
    {
        const uint32_t key =
            (g_attr[i].measurement_id + cfg->columns_per_frame - cfg->seam_col) % cfg->columns_per_frame;
        FZ_CHECK(!s->open ||
                 key >= s->key); /* within a scan, never back past the seam: one rotation at most */
        s->key = key;
        s->open = 1;
    }
}

/* a well-formed payload: see the file's comment */
static void make_payload(const lidet_ouster_cfg_t *cfg, uint32_t len, uint32_t op, uint32_t arg,
                         uint32_t seed, uint32_t *frame, uint32_t *mid, uint32_t *session)
{
    const int legacy = cfg->profile == LIDET_OUSTER_LEGACY, fusa = cfg->header == LIDET_OUSTER_HEADER_FUSA;
    const uint32_t px = pixel_bytes(cfg->profile), ppc = cfg->pixels_per_column, cpf = cfg->columns_per_frame;
    const uint32_t col_bytes = (legacy ? 20u : 12u) + ppc * px;
    const uint32_t move = (op >> 5) & 3u;
    uint8_t *col = legacy ? g_pkt : g_pkt + 32;
    uint32_t c, i, s = seed * 2654435761u + 1u, init_id, fr;
    uint64_t sn;
    if (move == 1u)
    {
        *mid += arg % 64u;
    }
    else if (move == 2u)
    {
        *mid += cpf - (arg % 64u) % cpf;
        *frame -= 1u;
    }
    else if (move == 3u)
    {
        *frame += 2u + arg % 5u;
    }
    *frame += *mid / cpf;
    *mid %= cpf;
    if (op & 16u)
    {
        *session += 1u;
    }
    init_id = cfg->init_id != 0u && !(op & 16u) ? cfg->init_id : (*session * 40503u) & 0xFFFFFFu;
    sn = cfg->prod_sn != 0u && !(op & 16u) ? cfg->prod_sn : 12345678u + *session;
    for (i = 0; i < len; ++i)
    {
        g_pkt[i] = (uint8_t)(xorshift(&s) & 0xFFu);
    }
    fr = *frame & (fusa ? 0xFFFFFFFFu : 0xFFFFu);
    if (!legacy)
    {
        memset(g_pkt, 0, 32);
        if (fusa)
        {
            g_pkt[0] = 1u;
            wr32(g_pkt, 1u | (init_id << 8));
            wr32(g_pkt + 4, fr);
            g_pkt[11] = (uint8_t)(sn & 0xFFu);
            wr32(g_pkt + 12, (uint32_t)(sn >> 8));
        }
        else
        {
            wr16(g_pkt, 1u);
            wr16(g_pkt + 2, fr);
            wr32(g_pkt + 4, init_id); /* 24 bits; byte 7 is the serial number's first */
            wr32(g_pkt + 7, (uint32_t)(sn & 0xFFFFFFFFu));
            g_pkt[11] = (uint8_t)((sn >> 32) & 0xFFu);
        }
    }
    for (c = 0; c < cfg->columns_per_packet; ++c, col += col_bytes)
    {
        const int invalid = (op & 128u) && ((arg >> c) & 1u);
        uint8_t *q = col + (legacy ? 16u : 12u);
        wr32(col, 1000000u * *frame + 10000u * *mid + (xorshift(&s) & 0xFFu)); /* timestamp, low word */
        wr32(col + 4, xorshift(&s) & 3u);                                      /* and high word */
        wr16(col + 8, *mid);
        if (legacy)
        {
            wr16(col + 10, *frame & 0xFFFFu);
            wr32(col + 12, (uint32_t)(((uint64_t)*mid * LIDET_OUSTER_ENCODER_TICKS) / cpf));
            wr32(col + col_bytes - 4u, invalid ? 0u : 0xFFFFFFFFu);
        }
        else
        {
            col[10] = (uint8_t)(invalid ? col[10] & 0xFEu : col[10] | 1u);
        }
        for (i = 0; i < ppc; ++i, q += px)
        {
            /* a quarter of the ranges 0 (each return of a DUAL pixel on its own) */
            if ((xorshift(&s) & 3u) == 0u)
            {
                if (cfg->profile == LIDET_OUSTER_RNG15_RFL8_NIR8)
                {
                    q[0] = 0u;
                    q[1] &= 0x80u;
                }
                else
                {
                    q[0] = q[1] = 0u;
                    q[2] &= legacy ? 0xF0u : 0xF8u;
                }
            }
            if (cfg->profile == LIDET_OUSTER_RNG19_RFL8_SIG16_NIR16_DUAL && (xorshift(&s) & 3u) == 0u)
            {
                q[4] = q[5] = 0u;
                q[6] &= 0xF8u;
            }
        }
        if (++*mid == cpf)
        {
            *mid = 0u;
            ++*frame;
        }
    }
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static const lidet_ouster_profile_t profiles[4] = {
        LIDET_OUSTER_LEGACY, LIDET_OUSTER_RNG19_RFL8_SIG16_NIR16_DUAL, LIDET_OUSTER_RNG19_RFL8_SIG16_NIR16,
        LIDET_OUSTER_RNG15_RFL8_NIR8};
    static int32_t beam_mdeg[LIDET_OUSTER_MAX_BEAMS];
    fz_in_t in = {data, size};
    lidet_ouster_cfg_t cfg;
    lidet_ouster_result_t res;
    lidet_ouster_stats_t before;
    uint32_t rejected[LIDET_OUSTER_N_REJECT] = {0};
    uint32_t b0, v, i, px, packet_bytes, n_packets = 0, n_ops = 0, frame, mid = 0, session = 1,
                                         decoded_returns = 0;
    int valid, table_ok = 1;
    scan_t scan = {0u, 0};
    mirror_t mirror;
    events_t ev;
    lidet_status_t init;

    lidet_ouster_cfg_default(&cfg);
    b0 = fz_u8(&in);
    cfg.profile = profiles[b0 % 4u];
    cfg.filter = (lidet_ouster_filter_t)((b0 >> 2) & 3u);
    cfg.header = (b0 & 16u) ? LIDET_OUSTER_HEADER_FUSA : LIDET_OUSTER_HEADER_STANDARD;
    cfg.pixels_per_column = (uint16_t)(1u + fz_u8(&in) % 128u);
    v = fz_u16(&in);
    cfg.columns_per_frame = (uint16_t)((v & 0x8000u) ? v & 0x7FFFu : 16u + v % 113u);
    cfg.columns_per_packet = (uint16_t)(fz_u8(&in) % 18u);
    v = fz_u16(&in);
    cfg.seam_col =
        (uint16_t)((v & 0x8000u) || cfg.columns_per_frame == 0u ? v & 0x7FFFu : v % cfg.columns_per_frame);
    v = fz_u16(&in);
    cfg.max_step_cols =
        (uint16_t)((v & 0x8000u) || cfg.columns_per_frame == 0u ? v & 0x7FFFu
                                                                : v % (cfg.columns_per_frame + 1u));
    cfg.azimuth_offset_bam = fz_u16(&in);
    if (b0 & 128u)
    {
        for (i = 0; i < cfg.pixels_per_column; ++i)
        {
            beam_mdeg[i] = 6 * (int32_t)(int16_t)fz_u16(&in);
            table_ok &= beam_mdeg[i] > -180000 && beam_mdeg[i] < 180000;
        }
        cfg.beam_azimuth_mdeg = beam_mdeg;
    }
    cfg.init_id = (b0 & 32u) ? fz_u32(&in) >> (fz_u8(&in) % 9u) : 0u;
    cfg.prod_sn =
        (b0 & 64u) ? ((uint64_t)fz_u32(&in) | ((uint64_t)fz_u16(&in) << 32)) >> (fz_u8(&in) % 9u) : 0u;

    px = pixel_bytes(cfg.profile);
    packet_bytes = (cfg.profile == LIDET_OUSTER_LEGACY ? 0u : 64u) +
                   (uint32_t)cfg.columns_per_packet *
                       ((cfg.profile == LIDET_OUSTER_LEGACY ? 20u : 12u) + cfg.pixels_per_column * px);
    valid = cfg.filter <= LIDET_OUSTER_RETURN_SECOND && cfg.columns_per_frame >= 16u &&
            cfg.columns_per_frame <= 16384u && cfg.columns_per_packet >= 1u &&
            cfg.columns_per_packet <= 16u && cfg.seam_col < cfg.columns_per_frame &&
            cfg.max_step_cols <= cfg.columns_per_frame && cfg.init_id <= 0xFFFFFFu &&
            cfg.prod_sn < ((uint64_t)1 << 40) && packet_bytes <= MAX_PAYLOAD && table_ok;
    init = lidet_ouster_init(&g_dec, &cfg);
    FZ_CHECK((init == LIDET_OK) == valid);
    if (init != LIDET_OK)
    {
        FZ_CHECK(init == LIDET_ERR_CONFIG);
        return 0;
    }
    FZ_CHECK(lidet_ouster_packet_bytes(&g_dec) == packet_bytes);
    FZ_CHECK(
        lidet_ouster_max_returns(&g_dec) ==
        (uint32_t)cfg.columns_per_packet * cfg.pixels_per_column *
            (cfg.profile == LIDET_OUSTER_RNG19_RFL8_SIG16_NIR16_DUAL && cfg.filter == LIDET_OUSTER_RETURN_BOTH
                 ? 2u
                 : 1u));
    if (cfg.max_step_cols == 0u)
    {
        cfg.max_step_cols = cfg.columns_per_frame; /* the decoder's reading of 0 */
    }
    /* the beam table, BAM16 of the millidegrees within one step */
    for (i = 0; i < cfg.pixels_per_column; ++i)
    {
        const double want = cfg.beam_azimuth_mdeg != 0 ? beam_mdeg[i] * 65536.0 / 360000.0 : 0.0;
        const double got = (double)(int16_t)g_dec.beam_az_bam[i];
        FZ_CHECK(got - want <= 0.5 + 1e-9 && want - got <= 0.5 + 1e-9);
    }
    frame = fz_u16(&in);
    memset(&mirror, 0, sizeof mirror);

    while (in.n > 0 && n_ops < MAX_OPS)
    {
        const uint32_t op = fz_u8(&in), room_b = fz_u8(&in), seed = fz_u16(&in), arg = fz_u16(&in);
        const uint32_t room = (room_b & 1u) ? lidet_ouster_max_returns(&g_dec) : room_b >> 1;
        const uint8_t *payload = g_pkt;
        uint32_t len = packet_bytes, n_exp = 0, want_reject;
        lidet_ouster_t state_before;
        lidet_status_t st;
        ++n_ops;
        if (op % 16u == 2u)
        {
            FZ_CHECK(lidet_ouster_reset(&g_dec) == LIDET_OK);
            FZ_CHECK(!g_dec.have_prev);
            scan.open = 0; /* the caller drops what it assembled */
            mirror.have = 0;
            continue;
        }
        if (op % 16u == 0u)
        {
            uint8_t head[40];
            uint32_t s = seed + 7u;
            for (i = 0; i < sizeof head; ++i)
            {
                head[i] = fz_u8(&in);
            }
            len = arg % (packet_bytes + 64u);
            for (i = 0; i < len; ++i)
            {
                g_pkt[i] = i < sizeof head ? head[i] : (uint8_t)(xorshift(&s) & 0xFFu);
            }
        }
        else if (op % 16u == 1u)
        {
            payload = NULL;
            len = 0;
        }
        else
        {
            make_payload(&cfg, len, op, arg, seed, &frame, &mid, &session);
        }
        before = *lidet_ouster_stats(&g_dec);
        state_before = g_dec;
        want_reject = expect_reject(&mirror, &cfg, payload, len, packet_bytes);
        g_out[room].range_mm = 0xA5A5A5A5u;
        g_attr[room].t_ns = 0x5A5A5A5Au;
        st = lidet_ouster_packet(&g_dec, payload, len, g_out, g_attr, room, &res);
        ++n_packets;
        FZ_CHECK(g_out[room].range_mm == 0xA5A5A5A5u && g_attr[room].t_ns == 0x5A5A5A5Au);
        FZ_CHECK(st == LIDET_OK || st == LIDET_TRUNCATED || st == LIDET_ERR_MODEL);
        FZ_CHECK((st == LIDET_ERR_MODEL) == (res.reject != LIDET_OUSTER_REJECT_NONE));
        FZ_CHECK(res.reject < LIDET_OUSTER_N_REJECT && res.scan_event <= LIDET_OUSTER_SCAN_ABORTED);
        FZ_CHECK(res.reject == want_reject);
        FZ_CHECK(res.n_returns <= room && res.scan_end <= res.n_returns);
        if (st == LIDET_ERR_MODEL)
        {
            /* nothing emitted, the rotation state and every count but the rejection's as they were */
            FZ_CHECK(res.n_returns == 0u && res.scan_event == LIDET_OUSTER_SCAN_NONE);
            FZ_CHECK(g_dec.have_prev == state_before.have_prev && g_dec.from_seam == state_before.from_seam &&
                     g_dec.prev_frame == state_before.prev_frame && g_dec.prev_mid == state_before.prev_mid &&
                     g_dec.prev_init_id == state_before.prev_init_id);
            FZ_CHECK(g_dec.stats.n_rejected[res.reject] == before.n_rejected[res.reject] + 1u);
            FZ_CHECK(payload != NULL || res.reject == LIDET_OUSTER_REJECT_NULL);
            FZ_CHECK(res.reject != LIDET_OUSTER_REJECT_TRUNCATED || len < packet_bytes);
            FZ_CHECK(res.reject != LIDET_OUSTER_REJECT_SIZE || len > packet_bytes);
            ++rejected[res.reject];
            continue;
        }
        FZ_CHECK(payload != NULL && len == packet_bytes);
        /* the returns against the harness's reading of the payload */
        n_exp = read_payload(&cfg, g_dec.beam_az_bam, payload);
        mirror_payload(&mirror, &cfg, payload, &ev);
        {
            const uint32_t frag = g_dec.stats.n_fragment - before.n_fragment;
            const uint32_t trunc = g_dec.stats.n_truncated - before.n_truncated;
            /* the scan tracking: the same events, jumps and lost columns as the mirror's; without truncation the
             * same boundary and fragment */
            FZ_CHECK(res.scan_event == ev.kind);
            FZ_CHECK(g_dec.stats.n_jumps == mirror.n_jumps && g_dec.stats.n_lost_cols == mirror.n_lost);
            FZ_CHECK(g_dec.stats.n_scans == mirror.n_events[LIDET_OUSTER_SCAN_COMPLETE] &&
                     g_dec.stats.n_partial == mirror.n_events[LIDET_OUSTER_SCAN_PARTIAL] &&
                     g_dec.stats.n_aborted == mirror.n_events[LIDET_OUSTER_SCAN_ABORTED]);
            if (trunc == 0u)
            {
                FZ_CHECK(ev.kind == LIDET_OUSTER_SCAN_NONE
                             ? res.scan_end == res.n_returns
                             : res.scan_end == ev.first && frag == ev.last - ev.first);
            }
            FZ_CHECK(g_dec.stats.n_returns - before.n_returns == res.n_returns);
            FZ_CHECK(res.n_returns + frag + trunc == n_exp);
            FZ_CHECK((st == LIDET_TRUNCATED) == (trunc > 0u));
            FZ_CHECK(frag == 0u || res.scan_event != LIDET_OUSTER_SCAN_NONE);
            for (i = 0; i < res.scan_end; ++i)
            {
                FZ_CHECK(same_return(i, i));
            }
            if (trunc == 0u)
            {
                for (i = res.scan_end; i < res.n_returns; ++i)
                {
                    FZ_CHECK(same_return(i, i + frag));
                }
            }
            for (i = 0; i < res.n_returns; ++i)
            {
                FZ_CHECK(g_out[i].ring < cfg.pixels_per_column && g_out[i].range_mm > 0u);
                FZ_CHECK(g_attr[i].measurement_id < cfg.columns_per_frame && g_attr[i].return_index <= 1u);
            }
        }
        FZ_CHECK(res.n_valid_cols <= cfg.columns_per_packet && res.n_valid_cols > 0u);
        /* the scans as a caller assembles them (lidet_ouster_packet's contract) */
        scan_add(&scan, &cfg, 0u, res.scan_end);
        if (res.scan_event != LIDET_OUSTER_SCAN_NONE)
        {
            scan.open = 0;
        }
        scan_add(&scan, &cfg, res.scan_end, res.n_returns);
        decoded_returns += res.n_returns;
    }
    {
        const lidet_ouster_stats_t *s = lidet_ouster_stats(&g_dec);
        uint32_t sum = s->n_decoded;
        for (i = 1; i < LIDET_OUSTER_N_REJECT; ++i)
        {
            FZ_CHECK(s->n_rejected[i] == rejected[i]);
            sum += s->n_rejected[i];
        }
        FZ_CHECK(s->n_rejected[0] == 0u);
        FZ_CHECK(s->n_packets == n_packets && sum == n_packets);
        FZ_CHECK(s->n_returns == decoded_returns);
        FZ_CHECK(s->n_scans + s->n_partial + s->n_aborted <= s->n_decoded); /* one event a payload at most */
#ifdef FZ_VERBOSE
        fprintf(
            stderr,
            "ouster: %u payloads: %u decoded, rejected %u %u %u %u %u %u; returns %u; scans %u, partial %u, "
            "aborted %u; fragment %u, truncated %u, lost columns %u, jumps %u, invalid columns %u\n",
            (unsigned)s->n_packets, (unsigned)s->n_decoded, (unsigned)s->n_rejected[1],
            (unsigned)s->n_rejected[2], (unsigned)s->n_rejected[3], (unsigned)s->n_rejected[4],
            (unsigned)s->n_rejected[5], (unsigned)s->n_rejected[6], (unsigned)s->n_returns,
            (unsigned)s->n_scans, (unsigned)s->n_partial, (unsigned)s->n_aborted, (unsigned)s->n_fragment,
            (unsigned)s->n_truncated, (unsigned)s->n_lost_cols, (unsigned)s->n_jumps,
            (unsigned)s->n_invalid_cols);
#endif
    }
    return 0;
}
