/* SPDX-License-Identifier: MIT */
/* Velodyne packet decoding (see lidet_velodyne.h and docs/DECODING.md). Integers only: part of both builds.
 * Timing and laser tables from the vendors' user manuals (VLP-16 rev. E section 9, VLP-32C rev. C section 9,
 * HDL-32E section 9, HDL-64E S2 / S3 "Laser firing sequence and timing"): firing offsets, per-laser elevations and
 * (VLP-32C) azimuth offsets. The HDL-64E's laser order by elevation is the one published unit calibrations share
 * (docs/DECODING.md); its nominal elevations are the design's two blocks; its dual-return layout (four blocks a
 * firing: the strongest return's upper + lower pair, then the last return's) is velodyne_decoder's reading of the
 * S3 manual (docs/DECODING.md, "Dual return"). */
#include <string.h>

#include "lidet/lidet_velodyne.h"

#define BLOCKS 12u
#define BLOCK_BYTES 100u
#define POINTS 32u       /* data points per block */
#define FULL_CDEG 36000u /* one turn in 0.01 deg */
#define FINE 240u        /* interpolation unit: 0.01 deg / 240 */
#define FULL_FINE (FULL_CDEG * FINE)
#define MODE_STRONGEST 0x37u
#define MODE_LAST 0x38u
#define MODE_DUAL 0x39u
#define FLAG_UPPER                                                                                           \
    0xEEu /* the second byte of a block's flag: FF EE (every VLP / HDL-32E block, HDL-64E upper bank) */
#define FLAG_LOWER 0xDDu /* FF DD: HDL-64E lower bank */
#define ROT_MAX_CDEG 18000
#define ELEV_MAX_MDEG 90000

/* Per model: the time unit of the firing table (ns), a firing's length in units (a block; HDL-64E a pair of
 * blocks), the distance unit, the lasers, each data point's firing offset in units, laser -> nominal ring
 * (ascending elevation), ring -> nominal elevation (mdeg), laser -> nominal azimuth offset (0.01 deg, added). */
typedef struct
{
    uint16_t unit_ns;
    uint16_t block_units;
    uint8_t
        fine_num; /* FINE / block_units = fine_num / fine_den, reduced: VLP-16 5, VLP-32C 10, HDL-32E 6, */
    uint8_t fine_den; /* HDL-64E 3 / 10 */
    uint8_t dist_mm;  /* distance unit: 2 mm (VLP-16, HDL-32E, HDL-64E) or 4 mm (VLP-32C) */
    uint8_t n_lasers;
    uint8_t banks;             /* blocks of one firing: 1, or 2 (HDL-64E: upper, lower) */
    const uint16_t *off_units; /* [POINTS] */
    const uint8_t *laser_ring; /* [n_lasers] */
    const int32_t *elev_mdeg;  /* [n_lasers] by ring */
    const int16_t *delta_cdeg; /* [n_lasers] or NULL */
} model_t;

/* VLP-16: lasers 0..15 fired 2.304 us apart, two sequences of 55.296 us (24 units) per block (48 units). */
static const uint16_t k_vlp16_off[POINTS] = {0,  1,  2,  3,  4,  5,  6,  7,  8,  9,  10, 11, 12, 13, 14, 15,
                                             24, 25, 26, 27, 28, 29, 30, 31, 32, 33, 34, 35, 36, 37, 38, 39};
/* laser i at -15 + 2 i deg (even i) or +1 + 2 (i - 1) / 2 ... : even lasers are rings 0..7, odd ones 8..15 */
static const uint8_t k_vlp16_ring[16] = {0, 8, 1, 9, 2, 10, 3, 11, 4, 12, 5, 13, 6, 14, 7, 15};
static const int32_t k_vlp16_elev[16] = {-15000, -13000, -11000, -9000, -7000, -5000, -3000, -1000,
                                         1000,   3000,   5000,   7000,  9000,  11000, 13000, 15000};

/* VLP-32C: lasers fired in pairs (0 and 1, 2 and 3, ...) 2.304 us apart, one 55.296 us sequence per block. */
static const uint16_t k_vlp32c_off[POINTS] = {0, 0, 1, 1, 2,  2,  3,  3,  4,  4,  5,  5,  6,  6,  7,  7,
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
static const uint16_t k_hdl32e_off[POINTS] = {0,  1,  2,  3,  4,  5,  6,  7,  8,  9,  10, 11, 12, 13, 14, 15,
                                              16, 17, 18, 19, 20, 21, 22, 23, 24, 25, 26, 27, 28, 29, 30, 31};
static const uint8_t k_hdl32e_ring[POINTS] = {0, 16, 1, 17, 2,  18, 3,  19, 4,  20, 5,  21, 6,  22, 7,  23,
                                              8, 24, 9, 25, 10, 26, 11, 27, 12, 28, 13, 29, 14, 30, 15, 31};
static const int32_t k_hdl32e_elev[32] = {-30670, -29330, -28000, -26670, -25330, -24000, -22670, -21330,
                                          -20000, -18670, -17330, -16000, -14670, -13330, -12000, -10670,
                                          -9330,  -8000,  -6670,  -5330,  -4000,  -2670,  -1330,  0,
                                          1330,   2670,   4000,   5330,   6670,   8000,   9330,   10670};

/* HDL-64E (single return): laser j of the upper block and laser j of the lower block fire together; within a
 * block the lasers fire in groups of four, a group every 6 us, at 0, 1.26, 2.46, 3.66 us into it; a firing of
 * both blocks lasts 48 us (800 units of 60 ns). */
static const uint16_t k_hdl64e_off[POINTS] = {0,   21,  41,  61,  100, 121, 141, 161, 200, 221, 241,
                                              261, 300, 321, 341, 361, 400, 421, 441, 461, 500, 521,
                                              541, 561, 600, 621, 641, 661, 700, 721, 741, 761};
/* laser id -> ring by elevation, lowest first: the lower block (lasers 32..63) holds rings 0..31, the upper
 * (0..31) rings 32..63, each in the interleaved order published unit calibrations share */
static const uint8_t k_hdl64e_ring[64] = {36, 37, 58, 59, 38, 39, 32, 33, 40, 41, 34, 35, 48, 49, 42, 43,
                                          50, 51, 44, 45, 52, 53, 46, 47, 60, 61, 54, 55, 62, 63, 56, 57,
                                          4,  5,  26, 27, 6,  7,  0,  1,  8,  9,  2,  3,  16, 17, 10, 11,
                                          18, 19, 12, 13, 20, 21, 14, 15, 28, 29, 22, 23, 30, 31, 24, 25};
/* the design's blocks: lower -24.333 .. -8.833 deg every 0.5 deg, upper -8.333 .. +2 deg every 1/3 deg */
static const int32_t k_hdl64e_elev[64] = {
    -24333, -23833, -23333, -22833, -22333, -21833, -21333, -20833, -20333, -19833, -19333, -18833, -18333,
    -17833, -17333, -16833, -16333, -15833, -15333, -14833, -14333, -13833, -13333, -12833, -12333, -11833,
    -11333, -10833, -10333, -9833,  -9333,  -8833,  -8333,  -8000,  -7667,  -7333,  -7000,  -6667,  -6333,
    -6000,  -5667,  -5333,  -5000,  -4667,  -4333,  -4000,  -3667,  -3333,  -3000,  -2667,  -2333,  -2000,
    -1667,  -1333,  -1000,  -667,   -333,   0,      333,    667,    1000,   1333,   1667,   2000};

static const model_t k_vlp16 = {2304u, 48u, 5u, 1u, 2u, 16u, 1u, k_vlp16_off, k_vlp16_ring, k_vlp16_elev, 0};
static const model_t k_vlp32c = {2304u,         24u,           10u,           1u, 4u, 32u, 1u, k_vlp32c_off,
                                 k_vlp32c_ring, k_vlp32c_elev, k_vlp32c_delta};
static const model_t k_hdl32e = {1152u,         40u,           6u, 1u, 2u, 32u, 1u, k_hdl32e_off,
                                 k_hdl32e_ring, k_hdl32e_elev, 0};
static const model_t k_hdl64e = {60u,           800u,          3u, 10u, 2u, 64u, 2u, k_hdl64e_off,
                                 k_hdl64e_ring, k_hdl64e_elev, 0};
/* HDL-64E dual return: the same table (the same share of a firing per data point, so the same interpolation)
 * stretched to the dual firing's 57.6 us (800 units of 72 ns; 5,789 payloads of three firings a second) */
static const model_t k_hdl64e_dual = {72u,           800u,          3u, 10u, 2u, 64u, 2u, k_hdl64e_off,
                                      k_hdl64e_ring, k_hdl64e_elev, 0};

/* the model of a VLP / HDL-32E product byte (never the HDL-64E, which sends none) */
static const model_t *find_product(uint32_t product)
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

static const model_t *find_model(uint32_t model)
{
    return model == LIDET_VELODYNE_HDL64E ? &k_hdl64e : find_product(model);
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

/* The per-laser tables of the state: the calibration's (rings by its elevations, ties by laser id), or the
 * model's nominal ones; in the ring order of cfg.ring_top_first. */
static void build_tables(lidet_velodyne_t *st, const model_t *m, const lidet_velodyne_calib_t *cal)
{
    const uint32_t n = m->n_lasers;
    uint32_t i, k;
    for (i = 0; i < n; ++i)
    {
        uint32_t rank;
        int32_t elev;
        if (cal != 0)
        {
            elev = cal->laser[i].vert_mdeg;
            rank = 0;
            for (k = 0; k < n; ++k)
            {
                const int32_t e = cal->laser[k].vert_mdeg;
                rank += e < elev || (e == elev && k < i);
            }
            st->rot_cdeg[i] = cal->laser[i].rot_cdeg;
            st->dist_mm[i] = cal->laser[i].dist_mm;
        }
        else
        {
            rank = m->laser_ring[i];
            elev = m->elev_mdeg[rank];
            st->rot_cdeg[i] = (int16_t)(m->delta_cdeg != 0 ? -m->delta_cdeg[i] : 0);
            st->dist_mm[i] = 0;
        }
        if (st->cfg.ring_top_first)
        {
            rank = n - 1u - rank;
        }
        st->ring[i] = (uint8_t)rank;
        st->ring_elev_mdeg[rank] = elev;
    }
    st->n_lasers = (uint8_t)n;
    st->calibrated = (uint8_t)(cal != 0);
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
    cfg->ring_top_first = 0u;
    cfg->calib = 0;
}

static int calib_ok(const lidet_velodyne_calib_t *cal, const model_t *m)
{
    uint32_t i;
    if (m == 0 || cal->n_lasers != m->n_lasers)
    {
        return 0;
    }
    for (i = 0; i < cal->n_lasers; ++i)
    {
        const lidet_velodyne_laser_calib_t *l = &cal->laser[i];
        if (l->vert_mdeg <= -ELEV_MAX_MDEG || l->vert_mdeg >= ELEV_MAX_MDEG || l->rot_cdeg < -ROT_MAX_CDEG ||
            l->rot_cdeg > ROT_MAX_CDEG)
        {
            return 0;
        }
    }
    return 1;
}

lidet_status_t lidet_velodyne_init(lidet_velodyne_t *st, const lidet_velodyne_cfg_t *cfg)
{
    const model_t *m;
    if (st == 0 || cfg == 0)
    {
        return LIDET_ERR_ARG;
    }
    m = find_model((uint32_t)cfg->model);
    if ((cfg->model != LIDET_VELODYNE_AUTO && m == 0) ||
        (cfg->filter != LIDET_VELODYNE_RETURN_BOTH && cfg->filter != LIDET_VELODYNE_RETURN_STRONGEST &&
         cfg->filter != LIDET_VELODYNE_RETURN_LAST) ||
        cfg->seam_cdeg >= FULL_CDEG || cfg->max_step_cdeg == 0u || cfg->max_step_cdeg > FULL_CDEG / 2u ||
        cfg->force_model > 1u || (cfg->force_model && cfg->model == LIDET_VELODYNE_AUTO) ||
        cfg->ring_top_first > 1u || (cfg->calib != 0 && !calib_ok(cfg->calib, m)))
    {
        return LIDET_ERR_CONFIG;
    }
    memset(st, 0, sizeof *st);
    st->cfg = *cfg;
    st->cfg.calib = 0; /* read here only: the caller's table need not outlive init */
    st->model = (uint8_t)cfg->model;
    if (m != 0)
    {
        build_tables(st, m, cfg->calib);
    }
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
    if (st->model == 0u)
    {
        st->n_lasers =
            0u; /* AUTO: the tables follow the next lock (never calibrated: a calibration needs a model) */
    }
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
    return m != 0 ? m->n_lasers : 0u;
}

lidet_status_t lidet_velodyne_ring_elev_mdeg(lidet_velodyne_model_t model, uint32_t ring, int32_t *out_mdeg)
{
    const model_t *m = find_model((uint32_t)model);
    if (out_mdeg == 0 || m == 0 || ring >= m->n_lasers)
    {
        return LIDET_ERR_ARG;
    }
    *out_mdeg = m->elev_mdeg[ring];
    return LIDET_OK;
}

uint32_t lidet_velodyne_decoder_n_rings(const lidet_velodyne_t *st)
{
    return st != 0 && st->magic == LIDET_INIT_MAGIC ? st->n_lasers : 0u;
}

lidet_status_t lidet_velodyne_decoder_elev_mdeg(const lidet_velodyne_t *st, uint32_t ring, int32_t *out_mdeg)
{
    if (st == 0 || out_mdeg == 0)
    {
        return LIDET_ERR_ARG;
    }
    if (st->magic != LIDET_INIT_MAGIC || st->n_lasers == 0u)
    {
        return LIDET_ERR_STATE;
    }
    if (ring >= st->n_lasers)
    {
        return LIDET_ERR_ARG;
    }
    *out_mdeg = st->ring_elev_mdeg[ring];
    return LIDET_OK;
}

/* an HDL-64E payload in the dual-return layout: four blocks a firing (upper, lower: the strongest return; upper,
 * lower: the last), so blocks 0 and 2 at one azimuth; single-return firings are 48 us apart, at least 0.08 deg at
 * the slowest spin (300 rpm) */
static int hdl64e_dual(const uint8_t *p)
{
    return rd16(p + 2u) == rd16(p + 2u * BLOCK_BYTES + 2u);
}

/* HDL-64E payload checks: flags alternating upper / lower, a firing's blocks (two; dual: four) at one azimuth */
static lidet_velodyne_reject_t check_hdl64e(const lidet_velodyne_t *st, const uint8_t *p, uint32_t n_lower)
{
    const uint32_t per_firing = hdl64e_dual(p) ? 4u : 2u;
    uint32_t b;
    if (n_lower == 0u && !st->cfg.force_model && find_product(p[1205]) != 0)
    {
        return LIDET_VELODYNE_REJECT_PRODUCT; /* a VLP / HDL-32E payload to an HDL-64E decoder */
    }
    for (b = 0; b < BLOCKS; ++b)
    {
        const uint8_t *blk = p + b * BLOCK_BYTES;
        if (blk[0] != 0xFFu || blk[1] != ((b & 1u) ? FLAG_LOWER : FLAG_UPPER))
        {
            return LIDET_VELODYNE_REJECT_FLAG;
        }
    }
    for (b = 0; b < BLOCKS; ++b)
    {
        const uint32_t az = rd16(p + b * BLOCK_BYTES + 2u);
        if (az >= FULL_CDEG || az != rd16(p + (b - b % per_firing) * BLOCK_BYTES + 2u))
        {
            return LIDET_VELODYNE_REJECT_AZIMUTH;
        }
    }
    return LIDET_VELODYNE_REJECT_NONE;
}

/* Checks the whole payload; returns the reason it is rejected, or NONE (then *model: the model to decode as). */
static lidet_velodyne_reject_t check(const lidet_velodyne_t *st, const uint8_t *p, uint32_t len,
                                     uint32_t *model)
{
    uint32_t b, mode, product, n_lower = 0;
    if (p == 0)
    {
        return LIDET_VELODYNE_REJECT_NULL;
    }
    if (len != LIDET_VELODYNE_PAYLOAD_BYTES)
    {
        return LIDET_VELODYNE_REJECT_SIZE;
    }
    for (b = 0; b < BLOCKS; ++b)
    {
        n_lower += p[b * BLOCK_BYTES] == 0xFFu && p[b * BLOCK_BYTES + 1u] == FLAG_LOWER;
    }
    if (st->model == LIDET_VELODYNE_HDL64E || (st->model == 0u && n_lower > 0u))
    {
        *model = n_lower > 0u ? LIDET_VELODYNE_HDL64E : p[1205]; /* what the payload says it is */
        return check_hdl64e(st, p, n_lower);
    }
    mode = p[1204];
    product = p[1205];
    *model = st->cfg.force_model ? st->model : product;
    if (!st->cfg.force_model && (find_product(product) == 0 || (st->model != 0u && product != st->model)))
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
        if (blk[0] != 0xFFu || blk[1] != FLAG_UPPER)
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
    uint32_t dist_mm; /* the model's distance unit */
    int32_t corr_mm;  /* the laser's distance correction */
    uint32_t ring;    /* the laser's ring */
    uint32_t az_fine; /* the laser's firing azimuth, clockwise, FINE units, [0, FULL_FINE) */
    uint32_t t_ns;
} sink_t;

static inline void emit(sink_t *s, uint32_t dist, uint32_t intensity, uint32_t flags)
{
    /* dist <= 65535: dist * 4 + 32767 < 2^31 */
    const int32_t range_mm = (int32_t)(dist * s->dist_mm) + s->corr_mm;
    /* az_fine < 8 640 000: az_fine * 128 < 2^31; BAM16 = az * 65536 / 8 640 000 = az * 128 / 16 875, rounded */
    const uint32_t bam_cw = (s->az_fine * 128u + 8437u) / 16875u;
    if (range_mm <= 0)
    {
        ++s->stats->n_short_range;
        return;
    }
    if (s->n >= s->cap)
    {
        ++s->stats->n_truncated;
        return;
    }
    s->out[s->n].range_mm = (uint32_t)range_mm;
    s->out[s->n].azimuth = (uint16_t)((65536u - bam_cw) & 0xFFFFu);
    s->out[s->n].ring = (uint16_t)s->ring;
    if (s->attr != 0)
    {
        s->attr[s->n].t_ns = s->t_ns;
        s->attr[s->n].azimuth_cdeg = (uint16_t)(((s->az_fine + FINE / 2u) / FINE) % FULL_CDEG);
        s->attr[s->n].intensity = (uint8_t)intensity;
        s->attr[s->n].flags = (uint8_t)flags;
    }
    ++s->n;
    ++s->stats->n_returns;
}

/* Scan tracking on firing azimuth az (the firing's own, never an interpolated one, which may overshoot): a jump
 * beyond max_step_cdeg aborts the scan in progress, crossing the seam closes it (complete when it began at the
 * seam); either boundary lands at output index s->n */
static void track_scan(lidet_velodyne_t *st, lidet_velodyne_result_t *res, sink_t *s, uint32_t az)
{
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
            s->n = boundary(st, res, s->n, LIDET_VELODYNE_SCAN_ABORTED);
            st->from_seam = 0u;
        }
        else if (fwd_cdeg(st->cfg.seam_cdeg, st->prev_cdeg) + d >= FULL_CDEG)
        {
            s->n = boundary(st, res, s->n,
                            st->from_seam ? LIDET_VELODYNE_SCAN_COMPLETE : LIDET_VELODYNE_SCAN_PARTIAL);
            st->from_seam = 1u;
        }
    }
    st->prev_cdeg = (uint16_t)az;
}

/* The fast path (the firmware's case: a VLP-16 single-return block, no attributes, no calibration, room for the
 * whole block): the returns the general path (decode_firing) would emit, without its per-point work, written
 * from o on; returns how many. With X = a * 128 + 8437 (a: the point's azimuth in FINE units), emit()'s bam_cw =
 * floor(X / 16875), and FULL_FINE * 128 = 16875 * 2^16: a turn more or less changes only the quotient's bits
 * above 16, so no wrap is needed, and along the block X grows by step * fine_num * 128 per firing unit: quotient
 * and remainder are carried from point to point (two divisions per block, none per point). 97 -> 43 instructions
 * per return on the Cortex-M4 (docs/DECODING.md, "On a microcontroller"); fuzz_velodyne checks it against the
 * general path on every payload. */
static uint32_t decode_fast(const lidet_velodyne_t *st, const model_t *m, const uint8_t *first, uint32_t az,
                            uint32_t step, lidet_return_t *o)
{
    /* VLP-16: two sequences of 16 lasers, firing units 0..15 and 24..39 */
    const uint8_t *pt = first + 4u;
    const uint32_t f128 = step * m->fine_num * 128u, dq = f128 / 16875u, dr = f128 % 16875u;
    const uint32_t x = az * FINE * 128u + 8437u;
    const uint8_t *ring = st->ring;
    const lidet_return_t *const o0 = o;
    uint32_t q = x / 16875u, r = x % 16875u, seq, k;
    for (seq = 0; seq < 2u; ++seq)
    {
        for (k = 0; k < 16u; ++k, pt += 3)
        {
            const uint32_t d0 = (uint32_t)pt[0] | ((uint32_t)pt[1] << 8);
            if (d0 != 0u)
            {
                o->range_mm = d0 * 2u;
                o->azimuth = (uint16_t)(0u - q);
                o->ring = ring[k];
                ++o;
            }
            q += dq;
            r += dr;
            if (r >= 16875u)
            {
                r -= 16875u;
                ++q;
            }
        }
        for (k = 0; k < 8u; ++k) /* units 16..23: the gap between the sequences */
        {
            q += dq;
            r += dr;
            if (r >= 16875u)
            {
                r -= 16875u;
                ++q;
            }
        }
    }
    return (uint32_t)(o - o0);
}

/* a dual-return pair's returns (d0, i0: the first block's, the last return; d1, i1: the second block's, the
 * strongest, or the second strongest when the strongest is the last one, VLP-16 manual 9.3.2.2), as the
 * configured filter keeps them */
static inline void emit_dual(sink_t *s, uint32_t filter, uint32_t d0, uint32_t i0, uint32_t d1, uint32_t i1)
{
    const int second = d1 != 0u && d1 != d0;                   /* a distinct other return */
    const int second_strong = second && (d0 == 0u || i1 > i0); /* it is the strongest */
    if (filter == LIDET_VELODYNE_RETURN_STRONGEST)
    {
        if (second_strong)
        {
            emit(s, d1, i1, LIDET_VELODYNE_FLAG_STRONGEST);
        }
        else if (d0 != 0u)
        {
            emit(s, d0, i0, LIDET_VELODYNE_FLAG_LAST | LIDET_VELODYNE_FLAG_STRONGEST);
        }
    }
    else
    {
        if (d0 != 0u)
        {
            emit(s, d0, i0, LIDET_VELODYNE_FLAG_LAST | (second_strong ? 0u : LIDET_VELODYNE_FLAG_STRONGEST));
        }
        if (filter == LIDET_VELODYNE_RETURN_BOTH && second)
        {
            emit(s, d1, i1, second_strong ? LIDET_VELODYNE_FLAG_STRONGEST : 0u);
        }
    }
}

/* The general path: firing g (its first block at `first`, azimuth az, step the rotation to the next firing), every
 * point's azimuth interpolated in FINE units and its return(s) emitted into s. The banks of an HDL-64E firing one
 * after the other (upper, then lower). Dual return: per laser the last return and the other block's, read side by
 * side: a VLP / HDL-32E pair's first block (the last return) and second; an HDL-64E firing's second block pair (the
 * last return: upper, lower) and first (the strongest). */
static void decode_firing(const lidet_velodyne_t *st, const model_t *m, sink_t *s, const uint8_t *first,
                          uint32_t az, uint32_t step, uint32_t g, uint32_t mode)
{
    const int dual = mode == MODE_DUAL;
    uint32_t bank, j;
    for (bank = 0; bank < m->banks; ++bank)
    {
        const uint8_t *blk = first + bank * BLOCK_BYTES; /* single return; HDL-64E dual: the strongest */
        const uint8_t *other = 0;
        if (dual)
        {
            other = m->banks == 2u ? blk : blk + BLOCK_BYTES;
            blk = m->banks == 2u ? blk + 2u * BLOCK_BYTES : blk;
        }
        for (j = 0; j < POINTS; ++j)
        {
            const uint8_t *pt = blk + 4u + 3u * j;
            const uint32_t d0 = rd16(pt), i0 = pt[2];
            const uint32_t d1 = dual ? rd16(other + 4u + 3u * j) : 0u,
                           i1 = dual ? other[4u + 3u * j + 2u] : 0u;
            const uint32_t off = m->off_units[j];
            const uint32_t laser = bank * POINTS + (j & (m->n_lasers - 1u)); /* 16, 32 or 64 lasers */
            uint32_t interp;
            int32_t a;
            if (d0 == 0u && d1 == 0u)
            {
                continue; /* no return */
            }
            /* az + step * off / block_units - rot, in FINE units, rounded half up: step * off * FINE /
             * block_units = step * off * fine_num / fine_den (exact when fine_den is 1); step <= 18 000, off <
             * block_units <= 800, fine_num <= 10: < 2^28; a in [-FULL_FINE / 2, 2 FULL_FINE) */
            interp = m->fine_den == 1u ? step * off * m->fine_num
                                       : (step * off * m->fine_num + m->fine_den / 2u) / m->fine_den;
            a = (int32_t)(az * FINE + interp) - (int32_t)st->rot_cdeg[laser] * (int32_t)FINE;
            a += a < 0 ? (int32_t)FULL_FINE : 0;
            a -= a >= (int32_t)FULL_FINE ? (int32_t)FULL_FINE : 0;
            a -= a >= (int32_t)FULL_FINE ? (int32_t)FULL_FINE : 0;
            s->az_fine = (uint32_t)a;
            s->t_ns = (g * m->block_units + off) * m->unit_ns;
            s->ring = st->ring[laser];
            s->corr_mm = st->dist_mm[laser];
            if (!dual)
            {
                if (d0 != 0u)
                {
                    emit(s, d0, i0,
                         m->banks == 2u      ? 0u
                         : mode == MODE_LAST ? LIDET_VELODYNE_FLAG_LAST
                                             : LIDET_VELODYNE_FLAG_STRONGEST);
                }
            }
            else
            {
                emit_dual(s, st->cfg.filter, d0, i0, d1, i1);
            }
        }
    }
}

lidet_status_t lidet_velodyne_packet(lidet_velodyne_t *st, const uint8_t *payload, uint32_t len,
                                     lidet_return_t *out, lidet_velodyne_attr_t *attr, uint32_t cap,
                                     lidet_velodyne_result_t *res)
{
    const model_t *m;
    uint32_t mode, dual, per_group, n_groups, g, step_prev = 0u, trunc0, model = 0u;
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
    why = check(st, payload, len, &model);
    if (payload != 0 && len == LIDET_VELODYNE_PAYLOAD_BYTES)
    {
        const int hdl64e = model == LIDET_VELODYNE_HDL64E;
        res->return_mode = hdl64e ? 0u : payload[1204];
        res->model = hdl64e ? (uint8_t)LIDET_VELODYNE_HDL64E : payload[1205];
        res->time_us = rd32(payload + 1200);
    }
    if (why != LIDET_VELODYNE_REJECT_NONE)
    {
        res->reject = (uint8_t)why;
        ++st->stats.n_rejected[why];
        return LIDET_ERR_MODEL;
    }
    ++st->stats.n_decoded;
    if (st->model == 0u)
    {
        st->model = (uint8_t)model; /* locks AUTO */
    }
    m = find_model(st->model);
    if (st->n_lasers == 0u)
    {
        build_tables(st, m, 0);
    }
    if (m->banks == 2u)
    {
        /* HDL-64E: no return-mode byte; the layout says (res->return_mode reports it) */
        mode = hdl64e_dual(payload) ? MODE_DUAL : MODE_STRONGEST;
        m = mode == MODE_DUAL ? &k_hdl64e_dual : m;
        res->return_mode = (uint8_t)(mode == MODE_DUAL ? MODE_DUAL : 0u);
    }
    else
    {
        mode = payload[1204];
    }
    dual = mode == MODE_DUAL;
    /* blocks of one firing: a VLP / HDL-32E block or dual pair, an HDL-64E bank pair or (dual) two bank pairs */
    per_group = m->banks * (dual ? 2u : 1u);
    n_groups = BLOCKS / per_group;
    s.out = out;
    s.attr = attr;
    s.cap = cap;
    s.n = 0u;
    s.stats = &st->stats;
    s.dist_mm = m->dist_mm;
    trunc0 = st->stats.n_truncated;
    for (g = 0; g < n_groups; ++g)
    {
        const uint8_t *first = payload + g * per_group * BLOCK_BYTES;
        const uint32_t az = rd16(first + 2);
        uint32_t step;
        /* the rotation from this firing to the next: interpolates the firings inside this one */
        if (g + 1u < n_groups)
        {
            step = fwd_cdeg(az, rd16(first + per_group * BLOCK_BYTES + 2u));
            if (step > st->cfg.max_step_cdeg)
            {
                step = step_prev; /* a jump inside the payload (counted below, at the next firing) */
            }
            step_prev = step;
        }
        else
        {
            step = step_prev; /* the last firing: the step before it (constant speed over one packet) */
        }
        track_scan(st, res, &s, az);
        if (!dual && attr == 0 && m->fine_den == 1u && m->banks == 1u && m->delta_cdeg == 0 &&
            !st->calibrated && m->n_lasers == 16u && s.n + POINTS <= cap)
        {
            const uint32_t k = decode_fast(st, m, first, az, step, out + s.n);
            s.n += k;
            st->stats.n_returns += k;
            continue;
        }
        decode_firing(st, m, &s, first, az, step, g, mode);
    }
    res->n_returns = s.n;
    if (res->scan_event == LIDET_VELODYNE_SCAN_NONE)
    {
        res->scan_end = s.n;
    }
    return st->stats.n_truncated != trunc0 ? LIDET_TRUNCATED : LIDET_OK;
}
