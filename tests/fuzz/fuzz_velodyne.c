/* SPDX-License-Identifier: MIT */
/* libFuzzer harness: the Velodyne packet decoder (lidet_velodyne_init, lidet_velodyne_packet) on a stream of
 * payloads the input describes. Layout: 7 header bytes (model, filter, seam u16, max step u16, flags: bit 0
 * force_model, bit 1 repair), then packets of [u16 length (mod 1400)][u8 room][length bytes]. With repair, a
 * 1206-byte payload gets valid flags, azimuths, factory bytes and dual pairs, so the decoding paths are reached.
 * Checks: nothing past the room, scan_end <= n_returns, rings and azimuths in range, counts that add up. */
#include "fuzz_common.h"

static lidet_velodyne_t g_dec;
static lidet_return_t g_out[LIDET_VELODYNE_MAX_RETURNS + 1];
static lidet_velodyne_attr_t g_attr[LIDET_VELODYNE_MAX_RETURNS + 1];
static uint8_t g_pkt[1400];

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

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static const lidet_velodyne_model_t models[4] = {LIDET_VELODYNE_AUTO, LIDET_VELODYNE_HDL32E,
                                                     LIDET_VELODYNE_VLP16, LIDET_VELODYNE_VLP32C};
    fz_in_t in = {data, size};
    lidet_velodyne_cfg_t cfg;
    lidet_velodyne_result_t res;
    const lidet_velodyne_stats_t *s;
    uint32_t flags, n_packets = 0, sum, i;
    lidet_velodyne_cfg_default(&cfg);
    cfg.model = models[fz_u8(&in) % 4u];
    cfg.filter = (lidet_velodyne_filter_t)(fz_u8(&in) % 3u);
    cfg.seam_cdeg = (uint16_t)(fz_u16(&in) % 36000u);
    cfg.max_step_cdeg = (uint16_t)(1u + fz_u16(&in) % 18000u);
    flags = fz_u8(&in);
    cfg.force_model = (uint8_t)(flags & 1u);
    if (lidet_velodyne_init(&g_dec, &cfg) != LIDET_OK)
    {
        FZ_CHECK(cfg.force_model && cfg.model == LIDET_VELODYNE_AUTO);
        return 0;
    }
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
            repair(g_pkt, g_pkt[1204]);
        }
        g_out[room].range_mm = 0xA5A5A5A5u;
        st = lidet_velodyne_packet(&g_dec, len == 0u && (flags & 4u) ? NULL : g_pkt, len, g_out, g_attr, room,
                                   &res);
        ++n_packets;
        FZ_CHECK(g_out[room].range_mm == 0xA5A5A5A5u);
        FZ_CHECK(st == LIDET_OK || st == LIDET_TRUNCATED || st == LIDET_ERR_MODEL);
        FZ_CHECK((st == LIDET_ERR_MODEL) == (res.reject != LIDET_VELODYNE_REJECT_NONE));
        FZ_CHECK(res.n_returns <= room && res.scan_end <= res.n_returns);
        FZ_CHECK(res.scan_event <= LIDET_VELODYNE_SCAN_ABORTED);
        for (i = 0; i < res.n_returns; ++i)
        {
            FZ_CHECK(g_out[i].ring < 32u && g_out[i].range_mm > 0u && g_out[i].range_mm <= 4u * 65535u);
            FZ_CHECK(g_attr[i].azimuth_cdeg < 36000u && g_attr[i].t_ns < 1400000u);
        }
    }
    s = lidet_velodyne_stats(&g_dec);
    sum = s->n_decoded;
    for (i = 1; i < LIDET_VELODYNE_N_REJECT; ++i)
    {
        sum += s->n_rejected[i];
    }
    FZ_CHECK(s->n_packets == n_packets && sum == n_packets);
    FZ_CHECK(s->n_scans + s->n_partial + s->n_aborted <= 12u * n_packets);
    return 0;
}
