/* SPDX-License-Identifier: MIT */
/* libFuzzer harness: the Velodyne packet decoder (lidet_velodyne_init, lidet_velodyne_packet) on a stream of
 * payloads the input describes. Layout: 7 header bytes (model, filter, seam u16, max step u16, flags: bit 0
 * force_model, bit 1 repair, bit 2 a zero-length packet is NULL, bit 3 the model is the HDL-64E whatever the model
 * byte says, bit 4 a calibration follows, bit 5 ring_top_first), with bit 4 a calibration of the model's lasers
 * (per laser: elevation i16 x 3 mdeg, rotational correction i16 (0.01 deg), distance correction i16 (mm); out of
 * range values included), then packets of [u16 length (mod 1400)][u8 room][length bytes]. With repair, a 1206-byte
 * payload gets valid flags, azimuths, factory bytes and dual pairs (HDL-64E: alternating banks, a firing's blocks
 * at one azimuth, one in eight the dual-return layout of four blocks a firing), so the decoding paths are
 * reached. Checks: init refuses exactly the invalid configurations, nothing past the room, scan_end <=
 * n_returns, rings (the model's lasers), ranges and azimuths in range, counts that add up, an HDL-64E payload's
 * mode (0x39 exactly for the dual layout), a dual payload's one return a laser per firing but with BOTH; and a
 * second decoder, fed the same payloads without the attribute array (which takes the per-block fast path of
 * single-return VLP-16 blocks), gives the same returns, results and counts. */
#include "fuzz_common.h"

static lidet_velodyne_t g_dec, g_dec2;
static lidet_return_t g_out[LIDET_VELODYNE_MAX_RETURNS + 1], g_out2[LIDET_VELODYNE_MAX_RETURNS + 1];
static lidet_velodyne_attr_t g_attr[LIDET_VELODYNE_MAX_RETURNS + 1];
static uint8_t g_pkt[1400];
static lidet_velodyne_calib_t g_cal;

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static void repair(uint8_t *p, uint32_t sel)
{
    static const uint8_t products[3] = {0x21u, 0x22u, 0x28u};
    const uint8_t mode = (uint8_t)(0x37u + sel % 3u);
    uint32_t b;
    for (b = 0; b < 12u; ++b)
    {
        uint8_t *blk = p + 100u * b;
        uint32_t az = ((uint32_t)blk[2] | ((uint32_t)blk[3] << 8)) % 36000u;
        if (mode == 0x39u && (b & 1u))
        {
            az = (uint32_t)blk[-98] | ((uint32_t)blk[-97] << 8);
        }
        blk[0] = 0xFFu;
        blk[1] = 0xEEu;
        blk[2] = (uint8_t)(az & 0xFFu);
        blk[3] = (uint8_t)(az >> 8);
    }
    p[1204] = mode;
    p[1205] = products[(sel / 3u) % 3u];
}

/* the HDL-64E layout: upper and lower banks alternating, a firing's blocks at the first one's azimuth (two blocks,
 * or four for the dual-return layout) */
static void repair_hdl64e(uint8_t *p, uint32_t sel)
{
    const uint32_t per_firing = sel % 8u == 0u ? 4u : 2u;
    uint32_t b;
    for (b = 0; b < 12u; ++b)
    {
        uint8_t *blk = p + 100u * b;
        const uint8_t *src = p + 100u * (b / per_firing * per_firing);
        const uint32_t az = ((uint32_t)src[2] | ((uint32_t)src[3] << 8)) % 36000u;
        blk[0] = 0xFFu;
        blk[1] = (b & 1u) ? 0xDDu : 0xEEu;
        blk[2] = (uint8_t)(az & 0xFFu);
        blk[3] = (uint8_t)(az >> 8);
    }
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static const lidet_velodyne_model_t models[4] = {LIDET_VELODYNE_AUTO, LIDET_VELODYNE_HDL32E,
                                                     LIDET_VELODYNE_VLP16, LIDET_VELODYNE_VLP32C};
    fz_in_t in = {data, size};
    lidet_velodyne_cfg_t cfg;
    lidet_velodyne_result_t res;
    const lidet_velodyne_stats_t *s;
    uint32_t flags, n_packets = 0, sum, i, n_rings;
    int cal_ok = 1;
    lidet_status_t init;
    lidet_velodyne_cfg_default(&cfg);
    cfg.model = models[fz_u8(&in) % 4u];
    cfg.filter = (lidet_velodyne_filter_t)(fz_u8(&in) % 3u);
    cfg.seam_cdeg = (uint16_t)(fz_u16(&in) % 36000u);
    cfg.max_step_cdeg = (uint16_t)(1u + fz_u16(&in) % 18000u);
    flags = fz_u8(&in);
    cfg.force_model = (uint8_t)(flags & 1u);
    cfg.ring_top_first = (uint8_t)((flags >> 5) & 1u);
    if (flags & 8u)
    {
        cfg.model = LIDET_VELODYNE_HDL64E;
    }
    if (flags & 16u)
    {
        g_cal.n_lasers = lidet_velodyne_n_rings(cfg.model);
        for (i = 0; i < g_cal.n_lasers; ++i)
        {
            g_cal.laser[i].vert_mdeg = 3 * (int32_t)(int16_t)fz_u16(&in);
            g_cal.laser[i].rot_cdeg = (int16_t)fz_u16(&in);
            g_cal.laser[i].dist_mm = (int16_t)fz_u16(&in);
            cal_ok &= g_cal.laser[i].vert_mdeg > -90000 && g_cal.laser[i].vert_mdeg < 90000 &&
                      g_cal.laser[i].rot_cdeg >= -18000 && g_cal.laser[i].rot_cdeg <= 18000;
        }
        cal_ok &= cfg.model != LIDET_VELODYNE_AUTO;
        cfg.calib = &g_cal;
    }
    init = lidet_velodyne_init(&g_dec, &cfg);
    FZ_CHECK((init == LIDET_OK) == (cal_ok && !(cfg.force_model && cfg.model == LIDET_VELODYNE_AUTO)));
    if (init != LIDET_OK)
    {
        FZ_CHECK(init == LIDET_ERR_CONFIG);
        return 0;
    }
    FZ_CHECK(g_dec.cfg.calib == 0);
    FZ_CHECK(lidet_velodyne_init(&g_dec2, &cfg) == LIDET_OK);
    while (in.n > 0 && n_packets < 64u)
    {
        const uint32_t len = fz_u16(&in) % 1400u;
        const uint32_t room = fz_u8(&in) % 2u ? LIDET_VELODYNE_MAX_RETURNS : fz_u8(&in);
        lidet_status_t st;
        memset(g_pkt, 0, sizeof g_pkt);
        for (i = 0; i < len; ++i)
        {
            g_pkt[i] = fz_u8(&in);
        }
        if ((flags & 2u) && len == LIDET_VELODYNE_PAYLOAD_BYTES)
        {
            if (cfg.model == LIDET_VELODYNE_HDL64E ||
                (cfg.model == LIDET_VELODYNE_AUTO && g_pkt[1205] % 4u == 0u))
            {
                repair_hdl64e(g_pkt, g_pkt[1204]);
            }
            else
            {
                repair(g_pkt, g_pkt[1204]);
            }
        }
        g_out[room].range_mm = 0xA5A5A5A5u;
        st = lidet_velodyne_packet(&g_dec, len == 0u && (flags & 4u) ? NULL : g_pkt, len, g_out, g_attr, room,
                                   &res);
        ++n_packets;
        {
            lidet_velodyne_result_t res2;
            const lidet_status_t st2 = lidet_velodyne_packet(
                &g_dec2, len == 0u && (flags & 4u) ? NULL : g_pkt, len, g_out2, NULL, room, &res2);
            FZ_CHECK(st2 == st && memcmp(&res2, &res, sizeof res) == 0);
            FZ_CHECK(memcmp(g_out2, g_out, res.n_returns * sizeof g_out[0]) == 0);
        }
        FZ_CHECK(g_out[room].range_mm == 0xA5A5A5A5u);
        FZ_CHECK(st == LIDET_OK || st == LIDET_TRUNCATED || st == LIDET_ERR_MODEL);
        FZ_CHECK((st == LIDET_ERR_MODEL) == (res.reject != LIDET_VELODYNE_REJECT_NONE));
        FZ_CHECK(res.n_returns <= room && res.scan_end <= res.n_returns);
        FZ_CHECK(res.scan_event <= LIDET_VELODYNE_SCAN_ABORTED);
        FZ_CHECK(res.reject < LIDET_VELODYNE_N_REJECT);
        if (st == LIDET_ERR_MODEL)
        {
            continue;
        }
        n_rings = lidet_velodyne_decoder_n_rings(&g_dec);
        FZ_CHECK(n_rings == lidet_velodyne_n_rings((lidet_velodyne_model_t)g_dec.model));
        FZ_CHECK(g_dec.model != LIDET_VELODYNE_HDL64E ||
                 (res.model == LIDET_VELODYNE_HDL64E &&
                  res.return_mode == (g_pkt[2] == g_pkt[202] && g_pkt[3] == g_pkt[203] ? 0x39u : 0u)));
        /* one return a laser and firing (a dual payload: 6 x 32 points, HDL-64E 3 x 64) but with BOTH */
        FZ_CHECK(res.return_mode != 0x39u || cfg.filter == LIDET_VELODYNE_RETURN_BOTH ||
                 res.n_returns <= LIDET_VELODYNE_MAX_RETURNS / 2u);
        for (i = 0; i < res.n_returns; ++i)
        {
            int32_t e;
            FZ_CHECK(g_out[i].ring < n_rings && g_out[i].range_mm > 0u &&
                     g_out[i].range_mm <= 4u * 65535u + (cfg.calib != 0 ? 32767u : 0u));
            FZ_CHECK(g_attr[i].azimuth_cdeg < 36000u && g_attr[i].t_ns < 1400000u);
            FZ_CHECK(lidet_velodyne_decoder_elev_mdeg(&g_dec, g_out[i].ring, &e) == LIDET_OK);
            FZ_CHECK(e > -90000 && e < 90000);
        }
    }
    s = lidet_velodyne_stats(&g_dec);
    FZ_CHECK(memcmp(s, lidet_velodyne_stats(&g_dec2), sizeof *s) == 0);
    sum = s->n_decoded;
    for (i = 1; i < LIDET_VELODYNE_N_REJECT; ++i)
    {
        sum += s->n_rejected[i];
    }
    FZ_CHECK(s->n_packets == n_packets && sum == n_packets);
    FZ_CHECK(s->n_scans + s->n_partial + s->n_aborted <= 12u * n_packets);
    FZ_CHECK(cfg.calib != 0 || s->n_short_range == 0u);
    return 0;
}
