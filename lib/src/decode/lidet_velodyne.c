/* SPDX-License-Identifier: MIT */
/* Velodyne packet decoding (see lidet_velodyne.h and docs/DECODING.md). Integers only: part of both builds.
 * Timing and laser tables from the vendors' user manuals (VLP-16 rev. E section 9, VLP-32C rev. C section 9,
 * HDL-32E section 9): firing offsets, per-laser elevations and (VLP-32C) azimuth offsets. */
#include <string.h>

#include "lidet/lidet_velodyne.h"

#define BLOCKS 12u
#define BLOCK_BYTES 100u
#define POINTS 32u       /* data points per block */
#define FULL_CDEG 36000u /* one turn in 0.01 deg */
#define FINE 240u /* interpolation unit: 0.01 deg / 240 (240 = lcm of the models' block lengths in units) */
#define FULL_FINE (FULL_CDEG * FINE)
#define MODE_STRONGEST 0x37u
#define MODE_LAST 0x38u
#define MODE_DUAL 0x39u

/* Per model: the time unit of the firing table (ns), the block length in units, each data point's firing offset in
 * units, laser -> ring (ascending elevation), ring -> elevation (mdeg), laser -> azimuth offset (0.01 deg). */
typedef struct
{
    uint16_t unit_ns;
    uint8_t dist_mm; /* distance unit: 2 mm (VLP-16, HDL-32E) or 4 mm (VLP-32C) */
    uint8_t block_units;
    uint8_t n_rings;
    const uint8_t *off_units;  /* [POINTS] */
    const uint8_t *ring;       /* [POINTS]: data point -> ring */
    const int32_t *elev_mdeg;  /* [n_rings] by ring */
    const int16_t *delta_cdeg; /* [POINTS] or NULL */
} model_t;

/* VLP-16: lasers 0..15 fired 2.304 us apart, two sequences of 55.296 us (24 units) per block (48 units). */
static const uint8_t k_vlp16_off[POINTS] = {0,  1,  2,  3,  4,  5,  6,  7,  8,  9,  10, 11, 12, 13, 14, 15,
                                            24, 25, 26, 27, 28, 29, 30, 31, 32, 33, 34, 35, 36, 37, 38, 39};
/* laser i at -15 + 2 i deg (even i) or +1 + 2 (i - 1) / 2 ... : even lasers are rings 0..7, odd ones 8..15 */
static const uint8_t k_vlp16_ring[POINTS] = {0, 8, 1, 9, 2, 10, 3, 11, 4, 12, 5, 13, 6, 14, 7, 15,
                                             0, 8, 1, 9, 2, 10, 3, 11, 4, 12, 5, 13, 6, 14, 7, 15};
static const int32_t k_vlp16_elev[16] = {-15000, -13000, -11000, -9000, -7000, -5000, -3000, -1000,
                                         1000,   3000,   5000,   7000,  9000,  11000, 13000, 15000};

/* VLP-32C: lasers fired in pairs (0 and 1, 2 and 3, ...) 2.304 us apart, one 55.296 us sequence per block. */
static const uint8_t k_vlp32c_off[POINTS] = {0, 0, 1, 1, 2,  2,  3,  3,  4,  4,  5,  5,  6,  6,  7,  7,
                                             8, 8, 9, 9, 10, 10, 11, 11, 12, 12, 13, 13, 14, 14, 15, 15};
static const uint8_t k_vlp32c_ring[POINTS] = {0, 17, 15, 1, 2,  20, 18, 3,  4,  21, 19, 5,  6,  24, 22, 8,
                                              7, 25, 23, 9, 10, 27, 26, 12, 11, 29, 28, 13, 14, 31, 30, 16};
static const int32_t k_vlp32c_elev[32] = {-25000, -15639, -11310, -8843, -7254, -6148, -5333, -4667,
                                          -4000,  -3667,  -3333,  -3000, -2667, -2333, -2000, -1667,
                                          -1333,  -1000,  -667,   -333,  0,     333,   667,   1000,
                                          1333,   1667,   2333,   3333,  4667,  7000,  10333, 15000};
static const int16_t k_vlp32c_delta[POINTS] = {
    140, -420, 140, -140, 140, -140, 420, -140, 140, -420, 140, -140, 420, -140, 420, -140,
    140, -420, 140, -420, 420, -140, 140, -140, 140, -140, 140, -420, 420, -140, 140, -140};

/* HDL-32E: lasers 0..31 fired 1.152 us apart, one 46.08 us (40 units) sequence per block; even lasers -30.67 ..
 * -10.67 deg (rings 0..15), odd ones -9.33 .. +10.67 deg (rings 16..31). */
static const uint8_t k_hdl32e_off[POINTS] = {0,  1,  2,  3,  4,  5,  6,  7,  8,  9,  10, 11, 12, 13, 14, 15,
                                             16, 17, 18, 19, 20, 21, 22, 23, 24, 25, 26, 27, 28, 29, 30, 31};
static const uint8_t k_hdl32e_ring[POINTS] = {0, 16, 1, 17, 2,  18, 3,  19, 4,  20, 5,  21, 6,  22, 7,  23,
                                              8, 24, 9, 25, 10, 26, 11, 27, 12, 28, 13, 29, 14, 30, 15, 31};
static const int32_t k_hdl32e_elev[32] = {-30670, -29330, -28000, -26670, -25330, -24000, -22670, -21330,
                                          -20000, -18670, -17330, -16000, -14670, -13330, -12000, -10670,
                                          -9330,  -8000,  -6670,  -5330,  -4000,  -2670,  -1330,  0,
                                          1330,   2670,   4000,   5330,   6670,   8000,   9330,   10670};

static const model_t k_vlp16 = {2304u, 2u, 48u, 16u, k_vlp16_off, k_vlp16_ring, k_vlp16_elev, 0};
static const model_t k_vlp32c = {2304u,         4u, 24u, 32u, k_vlp32c_off, k_vlp32c_ring, k_vlp32c_elev,
                                 k_vlp32c_delta};
static const model_t k_hdl32e = {1152u, 2u, 40u, 32u, k_hdl32e_off, k_hdl32e_ring, k_hdl32e_elev, 0};

static const model_t *find_model(uint32_t product)
{
    switch (product)
    {
    case LIDET_VELODYNE_VLP16:
        return &k_vlp16;
    case LIDET_VELODYNE_VLP32C:
        return &k_vlp32c;
    case LIDET_VELODYNE_HDL32E:
        return &k_hdl32e;
    default:
        return 0;
    }
}

static uint32_t rd16(const uint8_t *p)
{
    return (uint32_t)p[0] | ((uint32_t)p[1] << 8);
}

static uint32_t rd32(const uint8_t *p)
{
    return rd16(p) | (rd16(p + 2) << 16);
}

/* forward step from a to b, 0.01 deg, [0, 35999] (both in [0, 35999]) */
static uint32_t fwd_cdeg(uint32_t a, uint32_t b)
{
    return (b + FULL_CDEG - a) % FULL_CDEG;
}

void lidet_velodyne_cfg_default(lidet_velodyne_cfg_t *cfg)
{
    if (cfg == 0)
    {
        return;
    }
    memset(cfg, 0, sizeof *cfg);
    cfg->model = LIDET_VELODYNE_AUTO;
    cfg->filter = LIDET_VELODYNE_RETURN_BOTH;
    cfg->seam_cdeg = 0u;
    cfg->max_step_cdeg = 1000u;
}

lidet_status_t lidet_velodyne_init(lidet_velodyne_t *st, const lidet_velodyne_cfg_t *cfg)
{
    if (st == 0 || cfg == 0)
    {
        return LIDET_ERR_ARG;
    }
    if ((cfg->model != LIDET_VELODYNE_AUTO && find_model((uint32_t)cfg->model) == 0) ||
        (cfg->filter != LIDET_VELODYNE_RETURN_BOTH && cfg->filter != LIDET_VELODYNE_RETURN_STRONGEST &&
         cfg->filter != LIDET_VELODYNE_RETURN_LAST) ||
        cfg->seam_cdeg >= FULL_CDEG || cfg->max_step_cdeg == 0u || cfg->max_step_cdeg > FULL_CDEG / 2u ||
        cfg->force_model > 1u || (cfg->force_model && cfg->model == LIDET_VELODYNE_AUTO))
    {
        return LIDET_ERR_CONFIG;
    }
    memset(st, 0, sizeof *st);
    st->cfg = *cfg;
    st->model = (uint8_t)cfg->model;
    st->magic = LIDET_INIT_MAGIC;
    return LIDET_OK;
}

lidet_status_t lidet_velodyne_reset(lidet_velodyne_t *st)
{
    if (st == 0)
    {
        return LIDET_ERR_ARG;
    }
    if (st->magic != LIDET_INIT_MAGIC)
    {
        return LIDET_ERR_STATE;
    }
    st->model = (uint8_t)st->cfg.model;
    st->have_prev = 0u;
    st->from_seam = 0u;
    st->prev_cdeg = 0u;
    return LIDET_OK;
}

const lidet_velodyne_stats_t *lidet_velodyne_stats(const lidet_velodyne_t *st)
{
    return st != 0 ? &st->stats : 0;
}

uint32_t lidet_velodyne_n_rings(lidet_velodyne_model_t model)
{
    const model_t *m = find_model((uint32_t)model);
    return m != 0 ? m->n_rings : 0u;
}

lidet_status_t lidet_velodyne_ring_elev_mdeg(lidet_velodyne_model_t model, uint32_t ring, int32_t *out_mdeg)
{
    const model_t *m = find_model((uint32_t)model);
    if (out_mdeg == 0 || m == 0 || ring >= m->n_rings)
    {
        return LIDET_ERR_ARG;
    }
    *out_mdeg = m->elev_mdeg[ring];
    return LIDET_OK;
}

/* Checks the whole payload; returns the reason it is rejected, or NONE. */
static lidet_velodyne_reject_t check(const lidet_velodyne_t *st, const uint8_t *p, uint32_t len)
{
    uint32_t b, mode, product;
    if (p == 0)
    {
        return LIDET_VELODYNE_REJECT_NULL;
    }
    if (len != LIDET_VELODYNE_PAYLOAD_BYTES)
    {
        return LIDET_VELODYNE_REJECT_SIZE;
    }
    mode = p[1204];
    product = p[1205];
    if (!st->cfg.force_model && (find_model(product) == 0 || (st->model != 0u && product != st->model)))
    {
        return LIDET_VELODYNE_REJECT_PRODUCT;
    }
    if (mode != MODE_STRONGEST && mode != MODE_LAST && mode != MODE_DUAL)
    {
        return LIDET_VELODYNE_REJECT_MODE;
    }
    for (b = 0; b < BLOCKS; ++b)
    {
        const uint8_t *blk = p + b * BLOCK_BYTES;
        if (blk[0] != 0xFFu || blk[1] != 0xEEu)
        {
            return LIDET_VELODYNE_REJECT_FLAG;
        }
    }
    for (b = 0; b < BLOCKS; ++b)
    {
        const uint32_t az = rd16(p + b * BLOCK_BYTES + 2u);
        if (az >= FULL_CDEG || (mode == MODE_DUAL && (b & 1u) && az != rd16(p + (b - 1u) * BLOCK_BYTES + 2u)))
        {
            return LIDET_VELODYNE_REJECT_AZIMUTH;
        }
    }
    return LIDET_VELODYNE_REJECT_NONE;
}

/* Closes the scan in progress at output index n (see lidet_velodyne_packet); returns the new fill count. */
static uint32_t boundary(lidet_velodyne_t *st, lidet_velodyne_result_t *res, uint32_t n, uint8_t kind)
{
    if (res->scan_event == LIDET_VELODYNE_SCAN_NONE)
    {
        res->scan_event = kind;
        res->scan_end = n;
        if (kind == LIDET_VELODYNE_SCAN_COMPLETE)
        {
            ++st->stats.n_scans;
        }
        else if (kind == LIDET_VELODYNE_SCAN_PARTIAL)
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

typedef struct
{
    lidet_return_t *out;
    lidet_velodyne_attr_t *attr;
    uint32_t cap;
    uint32_t n;
    lidet_velodyne_stats_t *stats;
    uint32_t dist_mm;
} sink_t;

static void emit(sink_t *s, uint32_t dist, uint32_t ring, uint32_t az_fine, uint32_t t_ns, uint32_t intensity,
                 uint32_t flags)
{
    /* az_fine < 8 640 000: az_fine * 128 < 2^31; BAM16 = az * 65536 / 8 640 000 = az * 128 / 16 875, rounded */
    const uint32_t bam_cw = (az_fine * 128u + 8437u) / 16875u;
    if (s->n >= s->cap)
    {
        ++s->stats->n_truncated;
        return;
    }
    s->out[s->n].range_mm = dist * s->dist_mm;
    s->out[s->n].azimuth = (uint16_t)((65536u - bam_cw) & 0xFFFFu);
    s->out[s->n].ring = (uint16_t)ring;
    if (s->attr != 0)
    {
        s->attr[s->n].t_ns = t_ns;
        s->attr[s->n].azimuth_cdeg = (uint16_t)(((az_fine + FINE / 2u) / FINE) % FULL_CDEG);
        s->attr[s->n].intensity = (uint8_t)intensity;
        s->attr[s->n].flags = (uint8_t)flags;
    }
    ++s->n;
    ++s->stats->n_returns;
}

lidet_status_t lidet_velodyne_packet(lidet_velodyne_t *st, const uint8_t *payload, uint32_t len,
                                     lidet_return_t *out, lidet_velodyne_attr_t *attr, uint32_t cap,
                                     lidet_velodyne_result_t *res)
{
    const model_t *m;
    uint32_t mode, dual, n_groups, g, step_prev = 0u, trunc0;
    lidet_velodyne_reject_t why;
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
    if (payload != 0 && len == LIDET_VELODYNE_PAYLOAD_BYTES)
    {
        res->return_mode = payload[1204];
        res->model = payload[1205];
        res->time_us = rd32(payload + 1200);
    }
    if (why != LIDET_VELODYNE_REJECT_NONE)
    {
        res->reject = (uint8_t)why;
        ++st->stats.n_rejected[why];
        return LIDET_ERR_MODEL;
    }
    ++st->stats.n_decoded;
    mode = payload[1204];
    if (!st->cfg.force_model)
    {
        st->model = payload[1205]; /* locks AUTO */
    }
    m = find_model(st->model);
    dual = mode == MODE_DUAL;
    n_groups = dual ? BLOCKS / 2u : BLOCKS; /* a dual pair is one firing group */
    s.out = out;
    s.attr = attr;
    s.cap = cap;
    s.n = 0u;
    s.stats = &st->stats;
    s.dist_mm = m->dist_mm;
    trunc0 = st->stats.n_truncated;
    for (g = 0; g < n_groups; ++g)
    {
        const uint8_t *blk = payload + (dual ? 2u * g : g) * BLOCK_BYTES;
        const uint8_t *other = dual ? blk + BLOCK_BYTES : 0;
        const uint32_t az = rd16(blk + 2);
        uint32_t step, j;
        /* the rotation from this group to the next: interpolates the firings inside this one */
        if (g + 1u < n_groups)
        {
            step = fwd_cdeg(az, rd16(payload + (dual ? 2u * (g + 1u) : g + 1u) * BLOCK_BYTES + 2u));
            if (step > st->cfg.max_step_cdeg)
            {
                step = step_prev; /* a jump inside the payload (counted below, at the next group) */
            }
            step_prev = step;
        }
        else
        {
            step = step_prev; /* the last group: the step before it (constant speed over one packet) */
        }
        /* scan tracking on the groups' own azimuths (never the interpolated ones, which may overshoot) */
        if (!st->have_prev)
        {
            st->have_prev = 1u;
            st->from_seam = 0u;
        }
        else
        {
            const uint32_t d = fwd_cdeg(st->prev_cdeg, az);
            if (d > st->cfg.max_step_cdeg)
            {
                ++st->stats.n_jumps;
                s.n = boundary(st, res, s.n, LIDET_VELODYNE_SCAN_ABORTED);
                st->from_seam = 0u;
            }
            else if (fwd_cdeg(st->cfg.seam_cdeg, st->prev_cdeg) + d >= FULL_CDEG)
            {
                s.n = boundary(st, res, s.n,
                               st->from_seam ? LIDET_VELODYNE_SCAN_COMPLETE : LIDET_VELODYNE_SCAN_PARTIAL);
                st->from_seam = 1u;
            }
        }
        st->prev_cdeg = (uint16_t)az;
        for (j = 0; j < POINTS; ++j)
        {
            const uint8_t *pt = blk + 4u + 3u * j;
            const uint32_t off = m->off_units[j];
            const uint32_t t_ns = (g * m->block_units + off) * m->unit_ns;
            const int32_t delta = m->delta_cdeg != 0 ? (int32_t)m->delta_cdeg[j] * (int32_t)FINE : 0;
            /* az + step * off / block_units + delta, in FINE units; step <= 18000: < 2^31 before the modulo */
            const uint32_t az_fine = (uint32_t)((int32_t)(az * FINE + step * off * (FINE / m->block_units)) +
                                                delta + (int32_t)FULL_FINE) %
                                     FULL_FINE;
            const uint32_t d0 = rd16(pt), i0 = pt[2];
            const uint32_t ring = m->ring[j];
            if (!dual)
            {
                if (d0 != 0u)
                {
                    emit(&s, d0, ring, az_fine, t_ns, i0,
                         mode == MODE_LAST ? LIDET_VELODYNE_FLAG_LAST : LIDET_VELODYNE_FLAG_STRONGEST);
                }
            }
            else
            {
                /* first block: the last return; second: the strongest, or the second strongest when the
                 * strongest is the last one (VLP-16 manual 9.3.2.2) */
                const uint32_t d1 = rd16(other + 4u + 3u * j), i1 = other[4u + 3u * j + 2u];
                const int second = d1 != 0u && d1 != d0;                   /* a distinct other return */
                const int second_strong = second && (d0 == 0u || i1 > i0); /* it is the strongest */
                if (st->cfg.filter == LIDET_VELODYNE_RETURN_STRONGEST)
                {
                    if (second_strong)
                    {
                        emit(&s, d1, ring, az_fine, t_ns, i1, LIDET_VELODYNE_FLAG_STRONGEST);
                    }
                    else if (d0 != 0u)
                    {
                        emit(&s, d0, ring, az_fine, t_ns, i0,
                             LIDET_VELODYNE_FLAG_LAST | LIDET_VELODYNE_FLAG_STRONGEST);
                    }
                }
                else
                {
                    if (d0 != 0u)
                    {
                        emit(&s, d0, ring, az_fine, t_ns, i0,
                             LIDET_VELODYNE_FLAG_LAST | (second_strong ? 0u : LIDET_VELODYNE_FLAG_STRONGEST));
                    }
                    if (st->cfg.filter == LIDET_VELODYNE_RETURN_BOTH && second)
                    {
                        emit(&s, d1, ring, az_fine, t_ns, i1,
                             second_strong ? LIDET_VELODYNE_FLAG_STRONGEST : 0u);
                    }
                }
            }
        }
    }
    res->n_returns = s.n;
    if (res->scan_event == LIDET_VELODYNE_SCAN_NONE)
    {
        res->scan_end = s.n;
    }
    return st->stats.n_truncated != trunc0 ? LIDET_TRUNCATED : LIDET_OK;
}
