/* SPDX-License-Identifier: MIT */
/* Unity tests of the Velodyne packet decoder (lib/src/decode/lidet_velodyne.c) on payloads built here: every
 * rejection reason, the firing-time interpolation, the seam, dual-return filters, truncation, jumps; the HDL-64E's
 * two banks, its ring order against the hdl64 preset, its dual-return layout with every filter; calibrations
 * (rings by their elevations, rotational and distance corrections) on every model. */
#include <math.h>
#include <string.h>

#include "lidet/lidet.h"
#include "test_util.h"

#define CAP LIDET_VELODYNE_MAX_RETURNS

LIDET_GUARDED(lidet_velodyne_t, g);
static struct
{
    uint32_t pre[LIDET_CANARY_WORDS];
    lidet_return_t ws[CAP];
    uint32_t post[LIDET_CANARY_WORDS];
} g_out;
static lidet_velodyne_attr_t attr[CAP];
static uint8_t pkt[LIDET_VELODYNE_PAYLOAD_BYTES + 8];
static lidet_velodyne_cfg_t cfg;
static lidet_velodyne_result_t res;

void setUp(void)
{
    CANARY_FILL(g);
    CANARY_FILL(g_out);
    lidet_velodyne_cfg_default(&cfg);
}

void tearDown(void)
{
    CANARY_CHECK(g);
    CANARY_CHECK(g_out);
}

static void put16(uint8_t *p, uint32_t v)
{
    p[0] = (uint8_t)(v & 0xFFu);
    p[1] = (uint8_t)(v >> 8);
}

/* A payload: block b at azimuth (az0 + b * step) mod 36000 (dual: pairs share one), every data point j of block b
 * at distance dist + j (units of the sensor), intensity j + b; timestamp 1000 us. */
static void make(uint32_t product, uint32_t mode, uint32_t az0, uint32_t step, uint32_t dist)
{
    uint32_t b, j;
    memset(pkt, 0, sizeof pkt);
    for (b = 0; b < 12u; ++b)
    {
        uint8_t *blk = pkt + 100u * b;
        const uint32_t k = mode == 0x39u ? b / 2u : b;
        blk[0] = 0xFFu;
        blk[1] = 0xEEu;
        put16(blk + 2, (az0 + k * step) % 36000u);
        for (j = 0; j < 32u; ++j)
        {
            put16(blk + 4u + 3u * j, dist + j);
            blk[4u + 3u * j + 2u] = (uint8_t)(j + b);
        }
    }
    pkt[1200] = 0xE8u; /* 1000 us */
    pkt[1201] = 0x03u;
    pkt[1204] = (uint8_t)mode;
    pkt[1205] = (uint8_t)product;
}

static void set_point(uint32_t block, uint32_t j, uint32_t dist, uint32_t intensity)
{
    put16(pkt + 100u * block + 4u + 3u * j, dist);
    pkt[100u * block + 4u + 3u * j + 2u] = (uint8_t)intensity;
}

static lidet_status_t run(void)
{
    return lidet_velodyne_packet(&g.ws, pkt, LIDET_VELODYNE_PAYLOAD_BYTES, g_out.ws, attr, CAP, &res);
}

static void init(void)
{
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_velodyne_init(&g.ws, &cfg));
}

static void test_init_validates(void)
{
    lidet_velodyne_t st;
    lidet_velodyne_cfg_t c;
    memset(&st, 0, sizeof st);
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_ARG, lidet_velodyne_init(0, &cfg));
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_ARG, lidet_velodyne_init(&st, 0));
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_STATE, lidet_velodyne_packet(&st, pkt, LIDET_VELODYNE_PAYLOAD_BYTES,
                                                                 g_out.ws, 0, CAP, &res));
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_STATE, lidet_velodyne_reset(&st));
    c = cfg;
    c.model = (lidet_velodyne_model_t)0x99;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_velodyne_init(&st, &c));
    c = cfg;
    c.filter = (lidet_velodyne_filter_t)7;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_velodyne_init(&st, &c));
    c = cfg;
    c.seam_cdeg = 36000u;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_velodyne_init(&st, &c));
    c = cfg;
    c.max_step_cdeg = 0u;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_velodyne_init(&st, &c));
    c.max_step_cdeg = 18001u;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_velodyne_init(&st, &c));
    c = cfg;
    c.force_model = 1u; /* needs a model */
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_velodyne_init(&st, &c));
    c.model = LIDET_VELODYNE_VLP16;
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_velodyne_init(&st, &c));
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_ARG,
                          lidet_velodyne_packet(&st, pkt, LIDET_VELODYNE_PAYLOAD_BYTES, g_out.ws, 0, CAP, 0));
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_ARG,
                          lidet_velodyne_packet(&st, pkt, LIDET_VELODYNE_PAYLOAD_BYTES, 0, 0, 1u, &res));
    TEST_ASSERT_EQUAL_UINT32(16u, lidet_velodyne_n_rings(LIDET_VELODYNE_VLP16));
    TEST_ASSERT_EQUAL_UINT32(0u, lidet_velodyne_n_rings(LIDET_VELODYNE_AUTO));
}

/* one rejection: status, reason, count, nothing written, the rotation state untouched */
static void expect_reject(const uint8_t *p, uint32_t len, lidet_velodyne_reject_t why)
{
    const lidet_velodyne_t before = g.ws;
    uint32_t i;
    for (i = 0; i < CAP; ++i)
    {
        g_out.ws[i].range_mm = 0xA5A5A5A5u;
    }
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_MODEL, lidet_velodyne_packet(&g.ws, p, len, g_out.ws, attr, CAP, &res));
    TEST_ASSERT_EQUAL_UINT8(why, res.reject);
    TEST_ASSERT_EQUAL_UINT32(0u, res.n_returns);
    TEST_ASSERT_EQUAL_UINT32(before.stats.n_rejected[why] + 1u, g.ws.stats.n_rejected[why]);
    TEST_ASSERT_EQUAL_UINT32(before.stats.n_packets + 1u, g.ws.stats.n_packets);
    TEST_ASSERT_EQUAL_UINT32(before.stats.n_decoded, g.ws.stats.n_decoded);
    TEST_ASSERT_EQUAL_UINT16(before.prev_cdeg, g.ws.prev_cdeg);
    TEST_ASSERT_EQUAL_UINT8(before.have_prev, g.ws.have_prev);
    for (i = 0; i < CAP; ++i)
    {
        TEST_ASSERT_EQUAL_HEX32(0xA5A5A5A5u, g_out.ws[i].range_mm);
    }
}

static void test_rejections_are_counted(void)
{
    cfg.model = LIDET_VELODYNE_VLP16;
    init();
    make(0x22u, 0x37u, 1000u, 40u, 500u);
    TEST_ASSERT_EQUAL_INT(LIDET_OK, run()); /* a good one first: the state has a rotation */
    expect_reject(0, LIDET_VELODYNE_PAYLOAD_BYTES, LIDET_VELODYNE_REJECT_NULL);
    make(0x22u, 0x37u, 1480u, 40u, 500u);
    expect_reject(pkt, 1205u, LIDET_VELODYNE_REJECT_SIZE);
    expect_reject(pkt, 1207u, LIDET_VELODYNE_REJECT_SIZE);
    expect_reject(pkt, 512u, LIDET_VELODYNE_REJECT_SIZE);
    expect_reject(pkt, 0u, LIDET_VELODYNE_REJECT_SIZE);
    pkt[1205] = 0x99u; /* unknown product */
    expect_reject(pkt, LIDET_VELODYNE_PAYLOAD_BYTES, LIDET_VELODYNE_REJECT_PRODUCT);
    pkt[1205] = 0x28u; /* known, not the configured VLP-16 */
    expect_reject(pkt, LIDET_VELODYNE_PAYLOAD_BYTES, LIDET_VELODYNE_REJECT_PRODUCT);
    pkt[1205] = 0x22u;
    pkt[1204] = 0x00u;
    expect_reject(pkt, LIDET_VELODYNE_PAYLOAD_BYTES, LIDET_VELODYNE_REJECT_MODE);
    pkt[1204] = 0x37u;
    pkt[100u * 11u + 1u] = 0xDDu; /* the last block's flag (a lower-bank HDL-64E block: not decoded here) */
    expect_reject(pkt, LIDET_VELODYNE_PAYLOAD_BYTES, LIDET_VELODYNE_REJECT_FLAG);
    make(0x22u, 0x37u, 1480u, 40u, 500u);
    put16(pkt + 100u * 5u + 2u, 36000u);
    expect_reject(pkt, LIDET_VELODYNE_PAYLOAD_BYTES, LIDET_VELODYNE_REJECT_AZIMUTH);
    put16(pkt + 100u * 5u + 2u, 65535u);
    expect_reject(pkt, LIDET_VELODYNE_PAYLOAD_BYTES, LIDET_VELODYNE_REJECT_AZIMUTH);
    make(0x22u, 0x39u, 1480u, 40u, 500u);
    put16(pkt + 100u * 3u + 2u, 1600u); /* a dual pair at two azimuths */
    expect_reject(pkt, LIDET_VELODYNE_PAYLOAD_BYTES, LIDET_VELODYNE_REJECT_AZIMUTH);
    /* decoding resumes where it was */
    make(0x22u, 0x37u, 1480u, 40u, 500u);
    TEST_ASSERT_EQUAL_INT(LIDET_OK, run());
    TEST_ASSERT_EQUAL_UINT32(0u, g.ws.stats.n_jumps);
    TEST_ASSERT_EQUAL_UINT32(2u, g.ws.stats.n_decoded);
    TEST_ASSERT_EQUAL_UINT32(14u, g.ws.stats.n_packets);
    /* AUTO locks on the first product it decodes */
    cfg.model = LIDET_VELODYNE_AUTO;
    init();
    make(0x28u, 0x37u, 0u, 20u, 500u);
    TEST_ASSERT_EQUAL_INT(LIDET_OK, run());
    TEST_ASSERT_EQUAL_UINT8(0x28u, res.model);
    make(0x22u, 0x37u, 240u, 20u, 500u);
    expect_reject(pkt, LIDET_VELODYNE_PAYLOAD_BYTES, LIDET_VELODYNE_REJECT_PRODUCT);
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_velodyne_reset(&g.ws)); /* reset releases the lock */
    TEST_ASSERT_EQUAL_INT(LIDET_OK, run());
    /* force_model decodes whatever the product byte says */
    cfg.model = LIDET_VELODYNE_VLP16;
    cfg.force_model = 1u;
    init();
    make(0x21u, 0x37u, 0u, 40u, 500u);
    TEST_ASSERT_EQUAL_INT(LIDET_OK, run());
    TEST_ASSERT_EQUAL_UINT32(384u, res.n_returns);
    TEST_ASSERT_EQUAL_UINT16(8u, g_out.ws[1].ring); /* VLP-16 rings, not HDL-32E ones */
}

/* BAM16 counterclockwise from +x of a Velodyne azimuth (clockwise) in 0.01 deg */
static uint16_t bam_of_cdeg(double cdeg)
{
    long v = lround(-cdeg * 65536.0 / 36000.0);
    return (uint16_t)(((v % 65536) + 65536) % 65536);
}

static void test_vlp16_interpolation_and_rings(void)
{
    uint32_t b, j, n = 0;
    init();
    make(0x22u, 0x37u, 9000u, 40u, 1000u);
    TEST_ASSERT_EQUAL_INT(LIDET_OK, run());
    TEST_ASSERT_EQUAL_UINT32(384u, res.n_returns);
    TEST_ASSERT_EQUAL_UINT32(1000u, res.time_us);
    TEST_ASSERT_EQUAL_UINT8(LIDET_VELODYNE_SCAN_NONE, res.scan_event);
    TEST_ASSERT_EQUAL_UINT32(384u, res.scan_end);
    for (b = 0; b < 12u; ++b)
    {
        for (j = 0; j < 32u; ++j, ++n)
        {
            const uint32_t laser = j % 16u, seq = j / 16u;
            /* firing time: block b at 110.592 us, sequence at 55.296 us, laser at 2.304 us */
            const uint32_t t_ns = b * 110592u + seq * 55296u + laser * 2304u;
            const double az = 9000.0 + 40.0 * b + 40.0 * (double)(seq * 55296u + laser * 2304u) / 110592.0;
            const uint32_t ring = (laser % 2u) ? 8u + laser / 2u : laser / 2u;
            int32_t elev;
            TEST_ASSERT_EQUAL_UINT32(2u * (1000u + j), g_out.ws[n].range_mm);
            TEST_ASSERT_EQUAL_UINT16(ring, g_out.ws[n].ring);
            TEST_ASSERT_EQUAL_UINT32(t_ns, attr[n].t_ns);
            TEST_ASSERT_EQUAL_UINT16((uint16_t)lround(az), attr[n].azimuth_cdeg);
            TEST_ASSERT_INT_WITHIN(1, bam_of_cdeg(az), g_out.ws[n].azimuth);
            TEST_ASSERT_EQUAL_UINT8(j + b, attr[n].intensity);
            TEST_ASSERT_EQUAL_UINT8(LIDET_VELODYNE_FLAG_STRONGEST, attr[n].flags);
            /* the ring's elevation is the manual's for the laser: -15 + 2 laser (even), 1 + 2 (laser - 1) / 2 (odd) */
            TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_velodyne_ring_elev_mdeg(LIDET_VELODYNE_VLP16, ring, &elev));
            TEST_ASSERT_EQUAL_INT32(
                (laser % 2u) ? 1000 + 2000 * (int32_t)(laser / 2u) : -15000 + 1000 * (int32_t)laser, elev);
        }
    }
    /* 90 deg clockwise (the sensor's right) is -y: BAM16 49152 */
    TEST_ASSERT_EQUAL_UINT16(49152u, g_out.ws[0].azimuth);
    /* the ring order is the vlp16 preset's (ascending elevation) */
    {
        const lidet_sensor_t *s = lidet_sensor_find("vlp16");
        uint32_t r;
        TEST_ASSERT_NOT_NULL(s);
        for (r = 0; r < 16u; ++r)
        {
            int32_t e;
            TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_velodyne_ring_elev_mdeg(LIDET_VELODYNE_VLP16, r, &e));
            TEST_ASSERT_CLOSE(s->beam_elev_rad[r], e * (M_PI / 180000.0), 1e-6, 0.0);
        }
    }
}

static void test_vlp32c_pairs_offsets_and_units(void)
{
    static const int16_t delta[32] = {140,  -420, 140,  -140, 140,  -140, 420,  -140, 140,  -420, 140,
                                      -140, 420,  -140, 420,  -140, 140,  -420, 140,  -420, 420,  -140,
                                      140,  -140, 140,  -140, 140,  -420, 420,  -140, 140,  -140};
    const lidet_sensor_t *s = lidet_sensor_find("vlp32c");
    uint32_t j, r;
    init();
    make(0x28u, 0x37u, 100u, 20u, 1000u);
    TEST_ASSERT_EQUAL_INT(LIDET_OK, run());
    TEST_ASSERT_EQUAL_UINT32(384u, res.n_returns);
    for (j = 0; j < 32u; ++j)
    {
        const lidet_return_t *o = &g_out.ws[32u + j]; /* block 1 */
        /* pairs fire together, 2.304 us apart, one 55.296 us sequence per block */
        const double az = fmod(36000.0 + 120.0 + 20.0 * (double)(j / 2u) / 24.0 + delta[j], 36000.0);
        int32_t elev;
        TEST_ASSERT_EQUAL_UINT32(4u * (1000u + j), o->range_mm); /* 4 mm units */
        TEST_ASSERT_EQUAL_UINT32(55296u + (j / 2u) * 2304u, attr[32u + j].t_ns);
        TEST_ASSERT_EQUAL_UINT16((uint16_t)lround(az), attr[32u + j].azimuth_cdeg);
        TEST_ASSERT_INT_WITHIN(1, bam_of_cdeg(az), o->azimuth);
        TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_velodyne_ring_elev_mdeg(LIDET_VELODYNE_VLP32C, o->ring, &elev));
        if (j == 0u)
        {
            TEST_ASSERT_EQUAL_INT32(-25000, elev);
        }
        if (j == 29u)
        {
            TEST_ASSERT_EQUAL_INT32(15000, elev);
        }
    }
    /* the laser at -4.2 deg on block 0 at 1 deg: wraps below 0 */
    make(0x28u, 0x37u, 100u, 20u, 1000u);
    TEST_ASSERT_EQUAL_INT(LIDET_OK, run());
    TEST_ASSERT_EQUAL_UINT16((uint16_t)(36000u + 100u - 420u), attr[1].azimuth_cdeg);
    /* every ring once, in the vlp32c preset's order */
    TEST_ASSERT_NOT_NULL(s);
    for (r = 0; r < 32u; ++r)
    {
        int32_t e;
        uint32_t k, hits = 0;
        for (k = 0; k < 32u; ++k)
        {
            hits += g_out.ws[k].ring == r;
        }
        TEST_ASSERT_EQUAL_UINT32(1u, hits);
        TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_velodyne_ring_elev_mdeg(LIDET_VELODYNE_VLP32C, r, &e));
        TEST_ASSERT_CLOSE(s->beam_elev_rad[r], e * (M_PI / 180000.0), 2e-6, 0.0);
    }
}

static void test_hdl32e_timing(void)
{
    int32_t lo, hi;
    init();
    make(0x21u, 0x37u, 0u, 16u, 1000u);
    TEST_ASSERT_EQUAL_INT(LIDET_OK, run());
    /* one laser every 1.152 us, 46.08 us per block; 2 mm units */
    TEST_ASSERT_EQUAL_UINT32(46080u + 5u * 1152u, attr[32u + 5u].t_ns);
    TEST_ASSERT_EQUAL_UINT16((uint16_t)lround(16.0 + 16.0 * 5.0 / 40.0), attr[32u + 5u].azimuth_cdeg);
    TEST_ASSERT_EQUAL_UINT32(2u * 1005u, g_out.ws[5].range_mm);
    TEST_ASSERT_EQUAL_UINT16(0u, g_out.ws[0].ring);
    TEST_ASSERT_EQUAL_UINT16(16u, g_out.ws[1].ring);
    TEST_ASSERT_EQUAL_UINT16(31u, g_out.ws[31].ring);
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_velodyne_ring_elev_mdeg(LIDET_VELODYNE_HDL32E, 0u, &lo));
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_velodyne_ring_elev_mdeg(LIDET_VELODYNE_HDL32E, 31u, &hi));
    TEST_ASSERT_EQUAL_INT32(-30670, lo);
    TEST_ASSERT_EQUAL_INT32(10670, hi);
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_ARG, lidet_velodyne_ring_elev_mdeg(LIDET_VELODYNE_HDL32E, 32u, &hi));
}

/* Feeds VLP-16 packets of 12 blocks x 40 cdeg from az0 until n_packets; counts events */
static void test_seam_completes_scans(void)
{
    uint32_t p, az = 35000u, n_complete = 0, n_partial = 0, fill = 0, last_fill = 0;
    cfg.seam_cdeg = 0u;
    init();
    for (p = 0; p < 200u; ++p)
    {
        make(0x22u, 0x37u, az, 40u, 1000u);
        TEST_ASSERT_EQUAL_INT(LIDET_OK, run());
        if (res.scan_event != LIDET_VELODYNE_SCAN_NONE)
        {
            /* the block that crossed the seam starts the next scan: its first return */
            const uint32_t b = res.scan_end / 32u;
            TEST_ASSERT_EQUAL_UINT32(0u, res.scan_end % 32u);
            TEST_ASSERT_TRUE((az + 40u * b) % 36000u < 40u);
            TEST_ASSERT_TRUE(b == 0u || (az + 40u * (b - 1u)) % 36000u >= 35960u);
            if (res.scan_event == LIDET_VELODYNE_SCAN_COMPLETE)
            {
                /* one rotation: 900 blocks of 32 returns */
                TEST_ASSERT_EQUAL_UINT32(900u * 32u, fill + res.scan_end);
                ++n_complete;
            }
            else
            {
                TEST_ASSERT_EQUAL_UINT8(LIDET_VELODYNE_SCAN_PARTIAL, res.scan_event);
                TEST_ASSERT_EQUAL_UINT32(0u, n_complete);
                ++n_partial;
            }
            last_fill = fill + res.scan_end;
            fill = res.n_returns - res.scan_end;
        }
        else
        {
            fill += res.n_returns;
        }
        az = (az + 480u) % 36000u;
    }
    TEST_ASSERT_EQUAL_UINT32(1u, n_partial);
    TEST_ASSERT_EQUAL_UINT32(2u, n_complete); /* 200 packets x 4.8 deg = 960 deg from 350 deg */
    TEST_ASSERT_EQUAL_UINT32(2u, g.ws.stats.n_scans);
    TEST_ASSERT_EQUAL_UINT32(900u * 32u, last_fill);
    /* another seam: 180 deg, crossed inside the first packet (block 5): the scan before it began mid-rotation */
    cfg.seam_cdeg = 18000u;
    init();
    make(0x22u, 0x37u, 17800u, 40u, 1000u);
    TEST_ASSERT_EQUAL_INT(LIDET_OK, run());
    TEST_ASSERT_EQUAL_UINT8(LIDET_VELODYNE_SCAN_PARTIAL, res.scan_event);
    TEST_ASSERT_EQUAL_UINT32(5u * 32u, res.scan_end);
    TEST_ASSERT_EQUAL_UINT16(18000u, attr[res.scan_end].azimuth_cdeg);
}

static void test_jumps_abort_and_fragments_drop(void)
{
    init();
    make(0x22u, 0x37u, 1000u, 40u, 1000u);
    TEST_ASSERT_EQUAL_INT(LIDET_OK, run());
    /* the same packet again: a step back */
    TEST_ASSERT_EQUAL_INT(LIDET_OK, run());
    TEST_ASSERT_EQUAL_UINT8(LIDET_VELODYNE_SCAN_ABORTED, res.scan_event);
    TEST_ASSERT_EQUAL_UINT32(0u, res.scan_end);
    TEST_ASSERT_EQUAL_UINT32(384u, res.n_returns);
    TEST_ASSERT_EQUAL_UINT32(1u, g.ws.stats.n_jumps);
    /* a forward jump above max_step (lost packets): also aborted */
    make(0x22u, 0x37u, 1000u + 480u + 1100u, 40u, 1000u);
    TEST_ASSERT_EQUAL_INT(LIDET_OK, run());
    TEST_ASSERT_EQUAL_UINT8(LIDET_VELODYNE_SCAN_ABORTED, res.scan_event);
    TEST_ASSERT_EQUAL_UINT32(2u, g.ws.stats.n_jumps);
    TEST_ASSERT_EQUAL_UINT32(2u, g.ws.stats.n_aborted);
    /* one lost packet (4.8 deg) is still the rotation */
    make(0x22u, 0x37u, 2580u + 480u + 480u, 40u, 1000u);
    TEST_ASSERT_EQUAL_INT(LIDET_OK, run());
    TEST_ASSERT_EQUAL_UINT8(LIDET_VELODYNE_SCAN_NONE, res.scan_event);
    /* a seam crossing at block 3, then a jump at block 8 in one payload: blocks 3..7 are dropped */
    init();
    make(0x22u, 0x37u, 35400u, 40u, 1000u);
    TEST_ASSERT_EQUAL_INT(LIDET_OK, run());
    make(0x22u, 0x37u, 35880u, 40u, 1000u); /* blocks at 358.8, 359.2, 359.6, 0.0, ... */
    put16(pkt + 100u * 8u + 2u, 20000u);
    put16(pkt + 100u * 9u + 2u, 20040u);
    put16(pkt + 100u * 10u + 2u, 20080u);
    put16(pkt + 100u * 11u + 2u, 20120u);
    TEST_ASSERT_EQUAL_INT(LIDET_OK, run());
    TEST_ASSERT_EQUAL_UINT8(LIDET_VELODYNE_SCAN_PARTIAL, res.scan_event);
    TEST_ASSERT_EQUAL_UINT32(3u * 32u, res.scan_end);
    TEST_ASSERT_EQUAL_UINT32(3u * 32u + 4u * 32u, res.n_returns); /* blocks 0..2, then 8..11 */
    TEST_ASSERT_EQUAL_UINT32(5u * 32u, g.ws.stats.n_fragment);
    TEST_ASSERT_EQUAL_UINT32(1u, g.ws.stats.n_jumps);
    TEST_ASSERT_EQUAL_UINT16(20000u, attr[res.scan_end].azimuth_cdeg);
    TEST_ASSERT_EQUAL_UINT32(2u * 384u - 5u * 32u, g.ws.stats.n_returns);
    /* the sensor standing still: never a scan, every packet a jump */
    init();
    make(0x22u, 0x37u, 100u, 40u, 1000u);
    {
        uint32_t p;
        for (p = 0; p < 10u; ++p)
        {
            TEST_ASSERT_EQUAL_INT(LIDET_OK, run());
        }
    }
    TEST_ASSERT_EQUAL_UINT32(9u, g.ws.stats.n_jumps);
    TEST_ASSERT_EQUAL_UINT32(0u, g.ws.stats.n_scans);
}

static void test_dual_returns(void)
{
    uint32_t j;
    make(0x22u, 0x39u, 1000u, 40u, 0u);
    for (j = 0; j < 32u; ++j)
    {
        set_point(0u, j, 0u, 0u); /* pair 0: empty, except */
        set_point(1u, j, 0u, 0u);
    }
    set_point(0u, 0u, 500u, 10u); /* laser 0: identical returns */
    set_point(1u, 0u, 500u, 10u);
    set_point(0u, 1u, 600u, 10u); /* laser 1: last weaker than the other */
    set_point(1u, 1u, 400u, 50u);
    set_point(0u, 2u, 700u, 60u); /* laser 2: last stronger; the other is the second strongest */
    set_point(1u, 2u, 300u, 20u);
    set_point(1u, 3u, 900u, 30u); /* laser 3: only the other block */
    /* both */
    init();
    TEST_ASSERT_EQUAL_INT(LIDET_OK, run());
    TEST_ASSERT_EQUAL_UINT32(1000u, g_out.ws[0].range_mm);
    TEST_ASSERT_EQUAL_UINT8(LIDET_VELODYNE_FLAG_LAST | LIDET_VELODYNE_FLAG_STRONGEST, attr[0].flags);
    TEST_ASSERT_EQUAL_UINT32(1200u, g_out.ws[1].range_mm);
    TEST_ASSERT_EQUAL_UINT8(LIDET_VELODYNE_FLAG_LAST, attr[1].flags);
    TEST_ASSERT_EQUAL_UINT32(800u, g_out.ws[2].range_mm);
    TEST_ASSERT_EQUAL_UINT8(LIDET_VELODYNE_FLAG_STRONGEST, attr[2].flags);
    TEST_ASSERT_EQUAL_UINT16(g_out.ws[1].ring, g_out.ws[2].ring);
    TEST_ASSERT_EQUAL_UINT16(g_out.ws[1].azimuth, g_out.ws[2].azimuth);
    TEST_ASSERT_EQUAL_UINT32(1400u, g_out.ws[3].range_mm);
    TEST_ASSERT_EQUAL_UINT8(LIDET_VELODYNE_FLAG_LAST | LIDET_VELODYNE_FLAG_STRONGEST, attr[3].flags);
    TEST_ASSERT_EQUAL_UINT32(600u, g_out.ws[4].range_mm);
    TEST_ASSERT_EQUAL_UINT8(0u, attr[4].flags);
    TEST_ASSERT_EQUAL_UINT32(1800u, g_out.ws[5].range_mm);
    TEST_ASSERT_EQUAL_UINT8(LIDET_VELODYNE_FLAG_STRONGEST, attr[5].flags);
    TEST_ASSERT_EQUAL_UINT32(6u + 5u * 31u, res.n_returns); /* pairs 1..5: identical returns, laser 0 empty */
    /* pair timing: pair k at k x 110.592 us (return 6: pair 1, laser 1) */
    TEST_ASSERT_EQUAL_UINT32(110592u + 2304u, attr[6].t_ns);
    /* last */
    cfg.filter = LIDET_VELODYNE_RETURN_LAST;
    init();
    TEST_ASSERT_EQUAL_INT(LIDET_OK, run());
    TEST_ASSERT_EQUAL_UINT32(3u + 5u * 31u, res.n_returns);
    TEST_ASSERT_EQUAL_UINT32(1000u, g_out.ws[0].range_mm);
    TEST_ASSERT_EQUAL_UINT32(1200u, g_out.ws[1].range_mm);
    TEST_ASSERT_EQUAL_UINT32(1400u, g_out.ws[2].range_mm);
    /* strongest */
    cfg.filter = LIDET_VELODYNE_RETURN_STRONGEST;
    init();
    TEST_ASSERT_EQUAL_INT(LIDET_OK, run());
    TEST_ASSERT_EQUAL_UINT32(4u + 5u * 31u, res.n_returns);
    TEST_ASSERT_EQUAL_UINT32(1000u, g_out.ws[0].range_mm);
    TEST_ASSERT_EQUAL_UINT32(800u, g_out.ws[1].range_mm);
    TEST_ASSERT_EQUAL_UINT32(1400u, g_out.ws[2].range_mm);
    TEST_ASSERT_EQUAL_UINT32(1800u, g_out.ws[3].range_mm);
    /* single-return modes flag their one return */
    make(0x22u, 0x38u, 1000u, 40u, 100u);
    TEST_ASSERT_EQUAL_INT(LIDET_OK, run());
    TEST_ASSERT_EQUAL_UINT8(LIDET_VELODYNE_FLAG_LAST, attr[0].flags);
    TEST_ASSERT_EQUAL_UINT32(384u, res.n_returns);
}

static void test_truncation_never_writes_past_cap(void)
{
    uint32_t i;
    init();
    make(0x22u, 0x37u, 1000u, 40u, 1000u);
    for (i = 0; i < CAP; ++i)
    {
        g_out.ws[i].range_mm = 0xA5A5A5A5u;
    }
    TEST_ASSERT_EQUAL_INT(LIDET_TRUNCATED, lidet_velodyne_packet(&g.ws, pkt, LIDET_VELODYNE_PAYLOAD_BYTES,
                                                                 g_out.ws, 0, 100u, &res));
    TEST_ASSERT_EQUAL_UINT32(100u, res.n_returns);
    TEST_ASSERT_EQUAL_UINT32(284u, g.ws.stats.n_truncated);
    TEST_ASSERT_EQUAL_UINT32(100u, g.ws.stats.n_returns);
    TEST_ASSERT_EQUAL_UINT32(2000u, g_out.ws[0].range_mm);
    for (i = 100u; i < CAP; ++i)
    {
        TEST_ASSERT_EQUAL_HEX32(0xA5A5A5A5u, g_out.ws[i].range_mm);
    }
    /* cap 0 with out NULL: everything counted, the rotation still tracked */
    make(0x22u, 0x37u, 1480u, 40u, 1000u);
    TEST_ASSERT_EQUAL_INT(LIDET_TRUNCATED,
                          lidet_velodyne_packet(&g.ws, pkt, LIDET_VELODYNE_PAYLOAD_BYTES, 0, 0, 0u, &res));
    TEST_ASSERT_EQUAL_UINT32(1920u, g.ws.prev_cdeg);
    TEST_ASSERT_EQUAL_UINT32(0u, g.ws.stats.n_jumps);
}

static void test_xyz_of_returns(void)
{
    lidet_return_t r[3];
    float xyz[3 * 4];
    r[0].range_mm = 10000u; /* ring 7 of the VLP-16: -1 deg; azimuth 90 deg clockwise: -y */
    r[0].ring = 7u;
    r[0].azimuth = 49152u;
    r[1].range_mm = 2000u; /* ring 15: +15 deg, straight ahead */
    r[1].ring = 15u;
    r[1].azimuth = 0u;
    r[2] = r[1];
    r[2].ring = 16u; /* no such ring */
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_ARG, lidet_velodyne_xyz(LIDET_VELODYNE_VLP16, r, 3u, xyz, 4u));
    TEST_ASSERT_CLOSE(0.0, xyz[0], 1e-5, 0.0);
    TEST_ASSERT_CLOSE(-10.0 * cos(M_PI / 180.0), xyz[1], 1e-5, 1e-6);
    TEST_ASSERT_CLOSE(-10.0 * sin(M_PI / 180.0), xyz[2], 1e-5, 1e-6);
    TEST_ASSERT_CLOSE(2.0 * cos(M_PI / 12.0), xyz[4], 1e-6, 1e-6);
    TEST_ASSERT_CLOSE(0.0, xyz[5], 1e-6, 0.0);
    TEST_ASSERT_CLOSE(2.0 * sin(M_PI / 12.0), xyz[6], 1e-6, 1e-6);
    TEST_ASSERT_CLOSE(0.0, xyz[8], 0.0, 0.0);
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_ARG, lidet_velodyne_xyz(LIDET_VELODYNE_VLP16, r, 1u, xyz, 2u));
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_ARG, lidet_velodyne_xyz(LIDET_VELODYNE_AUTO, r, 1u, xyz, 3u));
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_velodyne_xyz(LIDET_VELODYNE_VLP16, 0, 0u, 0, 3u));
}

/* ---- HDL-64E -------------------------------------------------------------------------------------------------- */

/* the lasers of the published HDL-64E calibrations sorted by elevation, lowest first (upper bank: lasers 0..31,
 * lower bank: 32..63) */
static const uint8_t k_hdl64e_ascending[64] = {
    38, 39, 42, 43, 32, 33, 36, 37, 40, 41, 46, 47, 50, 51, 54, 55, 44, 45, 48, 49, 52, 53,
    58, 59, 62, 63, 34, 35, 56, 57, 60, 61, 6,  7,  10, 11, 0,  1,  4,  5,  8,  9,  14, 15,
    18, 19, 22, 23, 12, 13, 16, 17, 20, 21, 26, 27, 30, 31, 2,  3,  24, 25, 28, 29};

/* An HDL-64E single-return payload: firing f (blocks 2f upper, 2f + 1 lower) at (az0 + f * step) mod 36000, data
 * point j of block b at distance dist + j + 32 (b & 1) (2 mm), intensity j + b; timestamp 1000 us; status 'H', 7. */
static void make64(uint32_t az0, uint32_t step, uint32_t dist)
{
    uint32_t b, j;
    memset(pkt, 0, sizeof pkt);
    for (b = 0; b < 12u; ++b)
    {
        uint8_t *blk = pkt + 100u * b;
        blk[0] = 0xFFu;
        blk[1] = (b & 1u) ? 0xDDu : 0xEEu;
        put16(blk + 2, (az0 + (b / 2u) * step) % 36000u);
        for (j = 0; j < 32u; ++j)
        {
            put16(blk + 4u + 3u * j, dist + j + 32u * (b & 1u));
            blk[4u + 3u * j + 2u] = (uint8_t)(j + b);
        }
    }
    pkt[1200] = 0xE8u;
    pkt[1201] = 0x03u;
    pkt[1204] = 0x48u;
    pkt[1205] = 7u;
}

/* The interpolation rule: the firing's azimuth plus step x (time into the firing / its length) in 1/240 of 0.01
 * deg (rounded), minus the rotational correction, then rounded to 0.01 deg. */
static uint16_t rule_cdeg(uint32_t az, uint32_t step, uint32_t off_units, uint32_t firing_units,
                          int32_t rot_cdeg)
{
    const int64_t fine = (int64_t)az * 240 +
                         ((int64_t)step * 240 * off_units + firing_units / 2u) / firing_units -
                         (int64_t)rot_cdeg * 240 + 36000 * 240;
    return (uint16_t)(((fine % (36000 * 240)) + 120) / 240 % 36000);
}

/* a - b in BAM16 steps, across the wrap: [-32768, 32767] */
static int32_t bam_diff(uint16_t a, uint16_t b)
{
    return (int32_t)(int16_t)(uint16_t)(a - b);
}

/* the time of data point j into its HDL-64E firing: groups of four every 6 us, at 0, 1.26, 2.46, 3.66 us */
static uint32_t hdl64e_off_ns(uint32_t j)
{
    static const uint32_t in_group[4] = {0u, 1260u, 2460u, 3660u};
    return (j / 4u) * 6000u + in_group[j % 4u];
}

static void test_hdl64e_banks_timing_and_rings(void)
{
    uint32_t f, bank, j, n = 0, r;
    uint32_t seen[64];
    cfg.model = LIDET_VELODYNE_HDL64E;
    init();
    make64(35900u, 18u, 1000u);
    TEST_ASSERT_EQUAL_INT(LIDET_OK, run());
    TEST_ASSERT_EQUAL_UINT32(384u, res.n_returns);
    TEST_ASSERT_EQUAL_UINT8(LIDET_VELODYNE_HDL64E, res.model);
    TEST_ASSERT_EQUAL_UINT8(0u, res.return_mode); /* the HDL-64E's payload has no return-mode byte */
    TEST_ASSERT_EQUAL_UINT32(1000u, res.time_us);
    memset(seen, 0, sizeof seen);
    for (f = 0; f < 6u; ++f)
    {
        for (bank = 0; bank < 2u; ++bank)
        {
            for (j = 0; j < 32u; ++j, ++n)
            {
                const uint32_t laser = 32u * bank + j, off_ns = hdl64e_off_ns(j);
                const uint32_t az = (35900u + 18u * f) % 36000u;
                const uint16_t cdeg = rule_cdeg(az, 18u, off_ns / 60u, 800u, 0);
                uint32_t rank = 0;
                while (k_hdl64e_ascending[rank] != laser)
                {
                    ++rank;
                }
                /* upper block then lower block of each firing, in packet order; the lower bank's laser j fires with
                 * the upper bank's laser j */
                TEST_ASSERT_EQUAL_UINT32(2u * (1000u + j + 32u * bank), g_out.ws[n].range_mm);
                TEST_ASSERT_EQUAL_UINT16(rank, g_out.ws[n].ring);
                TEST_ASSERT_EQUAL_UINT32(f * 48000u + off_ns, attr[n].t_ns);
                TEST_ASSERT_EQUAL_UINT16(cdeg, attr[n].azimuth_cdeg);
                TEST_ASSERT_INT_WITHIN(1, 0, bam_diff(bam_of_cdeg(cdeg), g_out.ws[n].azimuth));
                TEST_ASSERT_EQUAL_UINT8(2u * f + bank + j, attr[n].intensity);
                TEST_ASSERT_EQUAL_UINT8(0u, attr[n].flags); /* the payload does not say which return */
                ++seen[rank];
            }
        }
    }
    for (r = 0; r < 64u; ++r)
    {
        TEST_ASSERT_EQUAL_UINT32(6u, seen[r]); /* every ring once per firing */
    }
    /* the last laser of a firing: 45.66 us into 48 us of an 0.18 deg step */
    TEST_ASSERT_EQUAL_UINT16((35900u + 17u) % 36000u, attr[63].azimuth_cdeg);
    /* the nominal table: the lower block -24.333 .. -8.833 deg every 0.5 deg, the upper -8.333 .. +2 every 1/3 */
    TEST_ASSERT_EQUAL_UINT32(64u, lidet_velodyne_n_rings(LIDET_VELODYNE_HDL64E));
    TEST_ASSERT_EQUAL_UINT32(64u, lidet_velodyne_decoder_n_rings(&g.ws));
    for (r = 0; r < 64u; ++r)
    {
        int32_t e, ed;
        const int32_t want = r < 32u ? -24333 + 500 * (int32_t)r : 2000 - ((63 - (int32_t)r) * 1000 + 1) / 3;
        TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_velodyne_ring_elev_mdeg(LIDET_VELODYNE_HDL64E, r, &e));
        TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_velodyne_decoder_elev_mdeg(&g.ws, r, &ed));
        TEST_ASSERT_INT_WITHIN(1, want, e);
        TEST_ASSERT_EQUAL_INT32(e, ed);
    }
}

/* The hdl64 preset numbers its rings top to bottom (KITTI's order): ring_top_first gives that order, and the
 * nominal elevations lie within 1 deg of the preset's KITTI-measured ones, ring by ring. */
static void test_hdl64e_ring_order_matches_hdl64_preset(void)
{
    const lidet_sensor_t *s = lidet_sensor_find("hdl64");
    uint32_t r, i;
    TEST_ASSERT_NOT_NULL(s);
    TEST_ASSERT_EQUAL_UINT32(64u, s->n_rows);
    cfg.model = LIDET_VELODYNE_HDL64E;
    cfg.ring_top_first = 1u;
    init();
    make64(1000u, 18u, 1000u);
    TEST_ASSERT_EQUAL_INT(LIDET_OK, run());
    for (r = 0; r < 64u; ++r)
    {
        int32_t e, up;
        TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_velodyne_decoder_elev_mdeg(&g.ws, r, &e));
        TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_velodyne_ring_elev_mdeg(LIDET_VELODYNE_HDL64E, 63u - r, &up));
        TEST_ASSERT_EQUAL_INT32(up, e);
        TEST_ASSERT_CLOSE(s->beam_elev_rad[r], e * (M_PI / 180000.0), 1.0 * M_PI / 180.0, 0.0);
        if (r > 0u)
        {
            TEST_ASSERT_TRUE(s->beam_elev_rad[r] < s->beam_elev_rad[r - 1u]);
        }
    }
    /* the first return, upper laser 0: nominal ring 36 from the bottom, 27 from the top */
    TEST_ASSERT_EQUAL_UINT16(27u, g_out.ws[0].ring);
    for (i = 0; i < 64u; ++i) /* firing 0: upper lasers 0..31, then lower lasers 32..63 */
    {
        TEST_ASSERT_EQUAL_UINT8(i, k_hdl64e_ascending[63u - g_out.ws[i].ring]);
    }
}

static void test_hdl64e_auto_and_rejections(void)
{
    uint32_t b;
    /* AUTO recognises it by its lower-bank flags and locks on it */
    init();
    make64(1000u, 18u, 500u);
    TEST_ASSERT_EQUAL_INT(LIDET_OK, run());
    TEST_ASSERT_EQUAL_UINT8(LIDET_VELODYNE_HDL64E, res.model);
    TEST_ASSERT_EQUAL_UINT32(64u, lidet_velodyne_decoder_n_rings(&g.ws));
    make(0x22u, 0x37u, 1108u, 40u, 500u);
    expect_reject(pkt, LIDET_VELODYNE_PAYLOAD_BYTES, LIDET_VELODYNE_REJECT_PRODUCT); /* a VLP-16 now */
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_velodyne_reset(&g.ws));
    TEST_ASSERT_EQUAL_UINT32(0u, lidet_velodyne_decoder_n_rings(&g.ws));
    TEST_ASSERT_EQUAL_INT(LIDET_OK, run());
    TEST_ASSERT_EQUAL_UINT8(0x22u, res.model);
    make64(1200u, 18u, 500u);
    expect_reject(pkt, LIDET_VELODYNE_PAYLOAD_BYTES,
                  LIDET_VELODYNE_REJECT_PRODUCT); /* status byte 7: no product */
    /* configured: every malformation counted by reason, the rotation state untouched */
    cfg.model = LIDET_VELODYNE_HDL64E;
    init();
    make64(1000u, 18u, 500u);
    TEST_ASSERT_EQUAL_INT(LIDET_OK, run());
    make64(1108u, 18u, 500u);
    expect_reject(pkt, 1205u, LIDET_VELODYNE_REJECT_SIZE);
    expect_reject(pkt, 512u, LIDET_VELODYNE_REJECT_SIZE);
    expect_reject(0, LIDET_VELODYNE_PAYLOAD_BYTES, LIDET_VELODYNE_REJECT_NULL);
    pkt[100u * 3u + 1u] = 0xEEu; /* two upper blocks in a row */
    expect_reject(pkt, LIDET_VELODYNE_PAYLOAD_BYTES, LIDET_VELODYNE_REJECT_FLAG);
    pkt[100u * 3u + 1u] = 0xCCu; /* a VLS-128 bank */
    expect_reject(pkt, LIDET_VELODYNE_PAYLOAD_BYTES, LIDET_VELODYNE_REJECT_FLAG);
    pkt[100u * 3u + 1u] = 0xDDu;
    pkt[0] = 0xFEu;
    expect_reject(pkt, LIDET_VELODYNE_PAYLOAD_BYTES, LIDET_VELODYNE_REJECT_FLAG);
    make64(1108u, 18u, 500u);
    for (b = 0; b < 12u; ++b) /* lower bank first */
    {
        pkt[100u * b + 1u] = (b & 1u) ? 0xEEu : 0xDDu;
    }
    expect_reject(pkt, LIDET_VELODYNE_PAYLOAD_BYTES, LIDET_VELODYNE_REJECT_FLAG);
    make64(1108u, 18u, 500u);
    put16(pkt + 100u * 7u + 2u, 1108u + 3u * 18u + 1u); /* a firing's lower block at another azimuth */
    expect_reject(pkt, LIDET_VELODYNE_PAYLOAD_BYTES, LIDET_VELODYNE_REJECT_AZIMUTH);
    make64(1108u, 18u, 500u);
    put16(pkt + 100u * 4u + 2u, 36000u);
    put16(pkt + 100u * 5u + 2u, 36000u);
    expect_reject(pkt, LIDET_VELODYNE_PAYLOAD_BYTES, LIDET_VELODYNE_REJECT_AZIMUTH);
    make64(1108u, 18u, 500u);
    /* a dual layout (firings of four blocks) whose second firing's last pair is elsewhere */
    for (b = 0; b < 12u; ++b)
    {
        put16(pkt + 100u * b + 2u, 1108u + (b / 4u) * 21u + (b == 6u || b == 7u));
    }
    expect_reject(pkt, LIDET_VELODYNE_PAYLOAD_BYTES, LIDET_VELODYNE_REJECT_AZIMUTH);
    make(0x22u, 0x37u, 1108u, 40u, 500u); /* a VLP-16 payload to an HDL-64E decoder */
    expect_reject(pkt, LIDET_VELODYNE_PAYLOAD_BYTES, LIDET_VELODYNE_REJECT_PRODUCT);
    pkt[1205] = 0x99u; /* no known product: its flags are not the HDL-64E's */
    expect_reject(pkt, LIDET_VELODYNE_PAYLOAD_BYTES, LIDET_VELODYNE_REJECT_FLAG);
    make64(1108u, 18u, 500u);
    TEST_ASSERT_EQUAL_INT(LIDET_OK, run());
    TEST_ASSERT_EQUAL_UINT32(0u, g.ws.stats.n_jumps);
    TEST_ASSERT_EQUAL_UINT32(2u, g.ws.stats.n_decoded);
    /* an HDL-64E payload to a VLP-16 decoder: its status byte is no product */
    cfg.model = LIDET_VELODYNE_VLP16;
    init();
    expect_reject(pkt, LIDET_VELODYNE_PAYLOAD_BYTES, LIDET_VELODYNE_REJECT_PRODUCT);
    /* forced HDL-64E: a VLP-16 payload's flags are still not the HDL-64E's */
    cfg.model = LIDET_VELODYNE_HDL64E;
    cfg.force_model = 1u;
    init();
    make(0x22u, 0x37u, 1108u, 40u, 500u);
    expect_reject(pkt, LIDET_VELODYNE_PAYLOAD_BYTES, LIDET_VELODYNE_REJECT_FLAG);
    make64(1108u, 18u, 500u);
    TEST_ASSERT_EQUAL_INT(LIDET_OK, run());
}

/* after run() on an HDL-64E payload whose firings, 0.18 deg apart, start at az (0.01 deg): a scan that ended in it
 * ended at the firing that crossed the seam (it starts the next scan), and a complete scan holds the 2,000 firings of
 * a turn. fill: the returns of the scan in progress; last: the size of the last scan that ended */
static void seam_bookkeeping(uint32_t az, uint32_t *fill, uint32_t *last, uint32_t *n_complete)
{
    if (res.scan_event != LIDET_VELODYNE_SCAN_NONE)
    {
        const uint32_t f = res.scan_end / 64u;
        TEST_ASSERT_EQUAL_UINT32(0u, res.scan_end % 64u);
        TEST_ASSERT_TRUE((az + 18u * f) % 36000u < 18u);
        if (res.scan_event == LIDET_VELODYNE_SCAN_COMPLETE)
        {
            TEST_ASSERT_EQUAL_UINT32(2000u * 64u, *fill + res.scan_end);
            ++*n_complete;
        }
        *last = *fill + res.scan_end;
        *fill = res.n_returns - res.scan_end;
    }
    else
    {
        *fill += res.n_returns;
    }
}

static void test_hdl64e_seam_and_jumps(void)
{
    uint32_t p, az = 35100u, n_complete = 0, fill = 0, last = 0;
    cfg.model = LIDET_VELODYNE_HDL64E;
    init();
    for (p = 0; p < 600u; ++p) /* 6 firings of 0.18 deg a packet: 2000 firings a turn */
    {
        make64(az, 18u, 1000u);
        TEST_ASSERT_EQUAL_INT(LIDET_OK, run());
        seam_bookkeeping(az, &fill, &last, &n_complete);
        az = (az + 108u) % 36000u;
    }
    TEST_ASSERT_EQUAL_UINT32(1u, n_complete); /* 600 x 1.08 deg = 648 deg from 351 deg */
    TEST_ASSERT_EQUAL_UINT32(1u, g.ws.stats.n_partial);
    TEST_ASSERT_EQUAL_UINT32(2000u * 64u, last);
    /* the same payload again: a jump back, the scan in progress aborted */
    make64((az + 36000u - 108u) % 36000u, 18u, 1000u);
    TEST_ASSERT_EQUAL_INT(LIDET_OK, run());
    TEST_ASSERT_EQUAL_UINT8(LIDET_VELODYNE_SCAN_ABORTED, res.scan_event);
    TEST_ASSERT_EQUAL_UINT32(1u, g.ws.stats.n_jumps);
}

/* ---- calibrations --------------------------------------------------------------------------------------------- */

static lidet_velodyne_calib_t cal;

/* ---- HDL-64E dual return ------------------------------------------------------------------------------------- */

/* An HDL-64E dual-return payload: firing f at (az0 + f * step) mod 36000 in blocks 4f (upper bank) and 4f + 1
 * (lower), the strongest return, and 4f + 2 (upper), 4f + 3 (lower), the last return; by default one return a
 * laser (both pairs alike, as the sensor repeats a lone return): data point j of bank k at distance
 * dist + j + 32 k (2 mm), intensity j + 2 f + k; timestamp 1000 us; status 'H', 7. */
static void make64d(uint32_t az0, uint32_t step, uint32_t dist)
{
    uint32_t b, j;
    memset(pkt, 0, sizeof pkt);
    for (b = 0; b < 12u; ++b)
    {
        uint8_t *blk = pkt + 100u * b;
        blk[0] = 0xFFu;
        blk[1] = (b & 1u) ? 0xDDu : 0xEEu;
        put16(blk + 2, (az0 + (b / 4u) * step) % 36000u);
        for (j = 0; j < 32u; ++j)
        {
            put16(blk + 4u + 3u * j, dist + j + 32u * (b & 1u));
            blk[4u + 3u * j + 2u] = (uint8_t)(j + 2u * (b / 4u) + (b & 1u));
        }
    }
    pkt[1200] = 0xE8u;
    pkt[1201] = 0x03u;
    pkt[1204] = 0x48u;
    pkt[1205] = 7u;
}

/* firing f, bank k (0 upper, 1 lower), laser j: the strongest pair's return (d_s, i_s), the last's (d_l, i_l) */
static void set64d(uint32_t f, uint32_t k, uint32_t j, uint32_t d_s, uint32_t i_s, uint32_t d_l, uint32_t i_l)
{
    set_point(4u * f + k, j, d_s, i_s);
    set_point(4u * f + 2u + k, j, d_l, i_l);
}

static uint32_t rank64(uint32_t laser)
{
    uint32_t rank = 0;
    while (k_hdl64e_ascending[rank] != laser)
    {
        ++rank;
    }
    return rank;
}

/* One return as the test expects it: index n of the output, its firing, laser, range (mm), intensity, flags;
 * the ring, time (57.6 us firings: the 48 us table stretched, 72 ns units) and azimuth (the single-return rule)
 * follow. */
static void expect64d(uint32_t n, uint32_t az0, uint32_t f, uint32_t laser, uint32_t range_mm,
                      uint32_t intensity, uint32_t flags)
{
    const uint32_t j = laser % 32u, off_units = hdl64e_off_ns(j) / 60u;
    const uint16_t cdeg = rule_cdeg((az0 + 21u * f) % 36000u, 21u, off_units, 800u, 0);
    TEST_ASSERT_TRUE(n < res.n_returns);
    TEST_ASSERT_EQUAL_UINT32(range_mm, g_out.ws[n].range_mm);
    TEST_ASSERT_EQUAL_UINT16(rank64(laser), g_out.ws[n].ring);
    TEST_ASSERT_EQUAL_UINT32(f * 57600u + off_units * 72u, attr[n].t_ns);
    TEST_ASSERT_EQUAL_UINT16(cdeg, attr[n].azimuth_cdeg);
    TEST_ASSERT_INT_WITHIN(1, 0, bam_diff(bam_of_cdeg(cdeg), g_out.ws[n].azimuth));
    TEST_ASSERT_EQUAL_UINT8(intensity, attr[n].intensity);
    TEST_ASSERT_EQUAL_UINT8(flags, attr[n].flags);
}

/* the hand-built payload of test_hdl64e_dual_filters: firing 0 holds every case of a laser's two returns */
static void make64d_cases(void)
{
    make64d(35990u, 21u, 1000u);              /* three firings 0.21 deg apart across the seam's azimuth */
    set64d(0u, 0u, 1u, 400u, 50u, 600u, 10u); /* laser 1: the last weaker than the other */
    set64d(0u, 0u, 2u, 300u, 20u, 700u,
           60u);                           /* laser 2: the last the strongest; the other second strongest */
    set64d(0u, 0u, 3u, 900u, 30u, 0u, 0u); /* laser 3: only the strongest pair */
    set64d(0u, 0u, 4u, 0u, 0u, 0u, 0u);    /* laser 4: no return */
    set64d(0u, 0u, 5u, 450u, 40u, 500u, 40u); /* laser 5: two returns of equal intensity */
    set64d(0u, 1u, 0u, 200u, 90u, 800u, 5u);  /* laser 32: the last weaker */
    set64d(0u, 1u, 7u, 0u, 0u, 333u, 70u);    /* laser 39: only the last pair */
}

/* the returns of lasers left alike (one return each) from output index n: firing f, bank, points [from, to) */
static uint32_t expect64d_alike(uint32_t n, uint32_t f, uint32_t bank, uint32_t from, uint32_t to)
{
    uint32_t j;
    for (j = from; j < to; ++j)
    {
        expect64d(n++, 35990u, f, 32u * bank + j, 2u * (1000u + j + 32u * bank), j + 2u * f + bank,
                  LIDET_VELODYNE_FLAG_LAST | LIDET_VELODYNE_FLAG_STRONGEST);
    }
    return n;
}

static void test_hdl64e_dual_filters(void)
{
    const uint32_t L = LIDET_VELODYNE_FLAG_LAST, S = LIDET_VELODYNE_FLAG_STRONGEST;
    uint32_t n, f;
    /* both (default): per laser the last return, then the other where its distance differs */
    cfg.model = LIDET_VELODYNE_HDL64E;
    init();
    make64d_cases();
    TEST_ASSERT_EQUAL_INT(LIDET_OK, run());
    TEST_ASSERT_EQUAL_UINT8(LIDET_VELODYNE_HDL64E, res.model);
    TEST_ASSERT_EQUAL_UINT8(0x39u, res.return_mode); /* the layout, reported as the dual-return mode */
    TEST_ASSERT_EQUAL_UINT32(1000u, res.time_us);
    TEST_ASSERT_EQUAL_UINT8(LIDET_VELODYNE_REJECT_NONE, res.reject);
    n = 0;
    expect64d(n++, 35990u, 0u, 0u, 2000u, 0u, L | S); /* laser 0: alike, once */
    expect64d(n++, 35990u, 0u, 1u, 1200u, 10u, L);
    expect64d(n++, 35990u, 0u, 1u, 800u, 50u, S);
    expect64d(n++, 35990u, 0u, 2u, 1400u, 60u, L | S);
    expect64d(n++, 35990u, 0u, 2u, 600u, 20u, 0u);
    expect64d(n++, 35990u, 0u, 3u, 1800u, 30u, S);
    expect64d(n++, 35990u, 0u, 5u, 1000u, 40u, L | S); /* tie: the last is the strongest */
    expect64d(n++, 35990u, 0u, 5u, 900u, 40u, 0u);
    n = expect64d_alike(n, 0u, 0u, 6u, 32u);
    expect64d(n++, 35990u, 0u, 32u, 1600u, 5u, L);
    expect64d(n++, 35990u, 0u, 32u, 400u, 90u, S);
    n = expect64d_alike(n, 0u, 1u, 1u, 7u);
    expect64d(n++, 35990u, 0u, 39u, 666u, 70u, L | S); /* laser 39: its one return, whatever the filter */
    n = expect64d_alike(n, 0u, 1u, 8u, 32u);
    for (f = 1; f < 3u; ++f) /* firings 1, 2: the upper bank, then the lower */
    {
        n = expect64d_alike(n, f, 0u, 0u, 32u);
        n = expect64d_alike(n, f, 1u, 0u, 32u);
    }
    TEST_ASSERT_EQUAL_UINT32(n, res.n_returns);
    TEST_ASSERT_EQUAL_UINT32(8u + 26u + 2u + 31u + 128u, res.n_returns);
    TEST_ASSERT_EQUAL_UINT32(res.n_returns, g.ws.stats.n_returns);
    /* the last return of a firing's last laser: 45.66 us of 48 into a 0.21 deg step (as in single return) */
    TEST_ASSERT_EQUAL_UINT16((35990u + 2u * 21u + 20u) % 36000u, attr[res.n_returns - 1u].azimuth_cdeg);
    /* last */
    cfg.filter = LIDET_VELODYNE_RETURN_LAST;
    init();
    TEST_ASSERT_EQUAL_INT(LIDET_OK, run());
    n = 0;
    expect64d(n++, 35990u, 0u, 0u, 2000u, 0u, L | S);
    expect64d(n++, 35990u, 0u, 1u, 1200u, 10u, L);
    expect64d(n++, 35990u, 0u, 2u, 1400u, 60u, L | S);
    expect64d(n++, 35990u, 0u, 5u, 1000u, 40u, L | S); /* laser 3 (no last return) and 4 (none) skipped */
    n = expect64d_alike(n, 0u, 0u, 6u, 32u);
    expect64d(n++, 35990u, 0u, 32u, 1600u, 5u, L);
    n = expect64d_alike(n, 0u, 1u, 1u, 7u);
    expect64d(n++, 35990u, 0u, 39u, 666u, 70u, L | S);
    n = expect64d_alike(n, 0u, 1u, 8u, 32u);
    for (f = 1; f < 3u; ++f)
    {
        n = expect64d_alike(n, f, 0u, 0u, 32u);
        n = expect64d_alike(n, f, 1u, 0u, 32u);
    }
    TEST_ASSERT_EQUAL_UINT32(n, res.n_returns);
    TEST_ASSERT_EQUAL_UINT32(4u + 26u + 1u + 31u + 128u, res.n_returns);
    /* strongest: per laser the return of higher intensity (tie: the last) */
    cfg.filter = LIDET_VELODYNE_RETURN_STRONGEST;
    init();
    TEST_ASSERT_EQUAL_INT(LIDET_OK, run());
    n = 0;
    expect64d(n++, 35990u, 0u, 0u, 2000u, 0u, L | S);
    expect64d(n++, 35990u, 0u, 1u, 800u, 50u, S);
    expect64d(n++, 35990u, 0u, 2u, 1400u, 60u, L | S);
    expect64d(n++, 35990u, 0u, 3u, 1800u, 30u, S);
    expect64d(n++, 35990u, 0u, 5u, 1000u, 40u, L | S);
    n = expect64d_alike(n, 0u, 0u, 6u, 32u);
    expect64d(n++, 35990u, 0u, 32u, 400u, 90u, S);
    n = expect64d_alike(n, 0u, 1u, 1u, 7u);
    expect64d(n++, 35990u, 0u, 39u, 666u, 70u, L | S);
    n = expect64d_alike(n, 0u, 1u, 8u, 32u);
    for (f = 1; f < 3u; ++f)
    {
        n = expect64d_alike(n, f, 0u, 0u, 32u);
        n = expect64d_alike(n, f, 1u, 0u, 32u);
    }
    TEST_ASSERT_EQUAL_UINT32(n, res.n_returns);
    TEST_ASSERT_EQUAL_UINT32(5u + 26u + 1u + 31u + 128u, res.n_returns);
    /* AUTO takes it for an HDL-64E by its flags and decodes it alike; a single-return payload after it too */
    lidet_velodyne_cfg_default(&cfg);
    init();
    TEST_ASSERT_EQUAL_INT(LIDET_OK, run());
    TEST_ASSERT_EQUAL_UINT8(LIDET_VELODYNE_HDL64E, res.model);
    TEST_ASSERT_EQUAL_UINT32(8u + 26u + 2u + 31u + 128u, res.n_returns);
    make64(63u, 18u, 1000u); /* 0.21 deg after the dual payload's last firing */
    TEST_ASSERT_EQUAL_INT(LIDET_OK, run());
    TEST_ASSERT_EQUAL_UINT8(0u, res.return_mode);
    TEST_ASSERT_EQUAL_UINT32(384u, res.n_returns);
    TEST_ASSERT_EQUAL_UINT32(0u, g.ws.stats.n_jumps);
    /* a calibration applies to both pairs alike: laser 1's two returns keep their ring, move by its corrections */
    memset(&cal, 0, sizeof cal);
    cal.n_lasers = 64u;
    for (f = 0; f < 64u; ++f)
    {
        TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_velodyne_ring_elev_mdeg(LIDET_VELODYNE_HDL64E, rank64(f),
                                                                      &cal.laser[f].vert_mdeg));
    }
    cal.laser[1].rot_cdeg = 150;
    cal.laser[1].dist_mm = -700;
    cfg.model = LIDET_VELODYNE_HDL64E;
    cfg.calib = &cal;
    init();
    make64d_cases();
    TEST_ASSERT_EQUAL_INT(LIDET_OK, run());
    TEST_ASSERT_EQUAL_UINT32(500u, g_out.ws[1].range_mm);
    TEST_ASSERT_EQUAL_UINT32(100u, g_out.ws[2].range_mm);
    TEST_ASSERT_EQUAL_UINT16(rank64(1u), g_out.ws[2].ring);
    TEST_ASSERT_EQUAL_UINT16(rule_cdeg(35990u, 21u, 21u, 800u, 150), attr[1].azimuth_cdeg);
    TEST_ASSERT_EQUAL_UINT16(attr[1].azimuth_cdeg, attr[2].azimuth_cdeg);
    cfg.calib = 0;
}

/* malformed dual payloads (truncated, oversized, a firing's four blocks at two azimuths, bad flags) are counted by
 * reason and change nothing; a dual payload decoded into a small room is cut at the room and counted */
static void test_hdl64e_dual_rejections(void)
{
    uint32_t i, b;
    cfg.model = LIDET_VELODYNE_HDL64E;
    init();
    make64d(1000u, 21u, 500u);
    TEST_ASSERT_EQUAL_INT(LIDET_OK, run());
    make64d(1063u, 21u, 500u);
    expect_reject(pkt, 1205u, LIDET_VELODYNE_REJECT_SIZE);
    expect_reject(pkt, 1207u, LIDET_VELODYNE_REJECT_SIZE);
    expect_reject(pkt, 600u, LIDET_VELODYNE_REJECT_SIZE); /* cut after the second firing */
    expect_reject(pkt, 0u, LIDET_VELODYNE_REJECT_SIZE);
    put16(pkt + 100u * 3u + 2u, 1064u); /* firing 0: the last pair's lower block elsewhere */
    expect_reject(pkt, LIDET_VELODYNE_PAYLOAD_BYTES, LIDET_VELODYNE_REJECT_AZIMUTH);
    make64d(1063u, 21u, 500u);
    put16(pkt + 100u * 10u + 2u, 1063u + 2u * 21u + 1u); /* firing 2: its last pair elsewhere */
    put16(pkt + 100u * 11u + 2u, 1063u + 2u * 21u + 1u);
    expect_reject(pkt, LIDET_VELODYNE_PAYLOAD_BYTES, LIDET_VELODYNE_REJECT_AZIMUTH);
    make64d(1063u, 21u, 500u);
    for (b = 8u; b < 12u; ++b) /* firing 2 beyond the circle */
    {
        put16(pkt + 100u * b + 2u, 36000u);
    }
    expect_reject(pkt, LIDET_VELODYNE_PAYLOAD_BYTES, LIDET_VELODYNE_REJECT_AZIMUTH);
    make64d(1063u, 21u, 500u);
    pkt[100u * 2u + 1u] = 0xDDu; /* the last pair's upper block flagged lower */
    expect_reject(pkt, LIDET_VELODYNE_PAYLOAD_BYTES, LIDET_VELODYNE_REJECT_FLAG);
    TEST_ASSERT_EQUAL_UINT32(0u, g.ws.stats.n_rejected[LIDET_VELODYNE_REJECT_UNSUPPORTED]);
    TEST_ASSERT_EQUAL_UINT32(1u, g.ws.stats.n_decoded);
    /* a whole dual payload into a room of 100: the rest counted, nothing written past it, the rotation tracked */
    make64d(1063u, 21u, 500u);
    for (i = 0; i < CAP; ++i)
    {
        g_out.ws[i].range_mm = 0xA5A5A5A5u;
    }
    TEST_ASSERT_EQUAL_INT(LIDET_TRUNCATED, lidet_velodyne_packet(&g.ws, pkt, LIDET_VELODYNE_PAYLOAD_BYTES,
                                                                 g_out.ws, attr, 100u, &res));
    TEST_ASSERT_EQUAL_UINT32(100u, res.n_returns);
    TEST_ASSERT_EQUAL_UINT32(192u - 100u, g.ws.stats.n_truncated);
    for (i = 100u; i < CAP; ++i)
    {
        TEST_ASSERT_EQUAL_HEX32(0xA5A5A5A5u, g_out.ws[i].range_mm);
    }
    TEST_ASSERT_EQUAL_UINT16(1063u + 2u * 21u, g.ws.prev_cdeg);
    TEST_ASSERT_EQUAL_UINT32(0u, g.ws.stats.n_jumps);
    TEST_ASSERT_EQUAL_UINT32(2u, g.ws.stats.n_decoded);
}

/* dual payloads over a full turn: three firings of 0.18 deg a payload, scans closed between firings at the seam, a
 * complete rotation of 2000 firings x 64 lasers (the last returns) */
static void test_hdl64e_dual_seam(void)
{
    uint32_t p, az = 35100u, n_complete = 0, fill = 0, last = 0;
    cfg.model = LIDET_VELODYNE_HDL64E;
    cfg.filter = LIDET_VELODYNE_RETURN_LAST;
    init();
    for (p = 0; p < 1200u; ++p)
    {
        make64d(az, 18u, 1000u);
        TEST_ASSERT_EQUAL_INT(LIDET_OK, run());
        TEST_ASSERT_EQUAL_UINT32(192u, res.n_returns);
        seam_bookkeeping(az, &fill, &last, &n_complete);
        az = (az + 54u) % 36000u;
    }
    TEST_ASSERT_EQUAL_UINT32(1u, n_complete); /* 1200 x 0.54 deg = 648 deg from 351 deg */
    TEST_ASSERT_EQUAL_UINT32(1u, g.ws.stats.n_partial);
    TEST_ASSERT_EQUAL_UINT32(2000u * 64u, last);
    TEST_ASSERT_EQUAL_UINT32(0u, g.ws.stats.n_jumps);
}

static void test_calibration_validated_and_copied(void)
{
    lidet_velodyne_t st;
    lidet_velodyne_cfg_t c;
    uint32_t i;
    memset(&cal, 0, sizeof cal);
    cal.n_lasers = 16u;
    for (i = 0; i < 16u; ++i)
    {
        cal.laser[i].vert_mdeg = -15000 + 2000 * (int32_t)i;
    }
    c = cfg;
    c.calib = &cal; /* needs a model */
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_velodyne_init(&st, &c));
    c.model = LIDET_VELODYNE_VLP32C; /* 32 lasers */
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_velodyne_init(&st, &c));
    c.model = LIDET_VELODYNE_VLP16;
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_velodyne_init(&st, &c));
    TEST_ASSERT_NULL(st.cfg.calib); /* not kept */
    cal.laser[3].vert_mdeg = 90000;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_velodyne_init(&st, &c));
    cal.laser[3].vert_mdeg = -90000;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_velodyne_init(&st, &c));
    cal.laser[3].vert_mdeg = 0;
    cal.laser[5].rot_cdeg = 18001;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_velodyne_init(&st, &c));
    cal.laser[5].rot_cdeg = -18000;
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_velodyne_init(&st, &c));
    c.ring_top_first = 2u;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_velodyne_init(&st, &c));
    /* decoder tables before AUTO's lock: none */
    c = cfg;
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_velodyne_init(&st, &c));
    {
        int32_t e;
        TEST_ASSERT_EQUAL_INT(LIDET_ERR_STATE, lidet_velodyne_decoder_elev_mdeg(&st, 0u, &e));
        TEST_ASSERT_EQUAL_INT(LIDET_ERR_ARG, lidet_velodyne_decoder_elev_mdeg(&st, 0u, 0));
        TEST_ASSERT_EQUAL_UINT32(0u, lidet_velodyne_decoder_n_rings(&st));
        TEST_ASSERT_EQUAL_UINT32(0u, lidet_velodyne_decoder_n_rings(0));
    }
}

/* A VLP-16 calibration that reorders the rings (laser 0 made the highest beam), shifts each laser's azimuth and
 * distance, and takes one laser's ranges below zero: every return as the rule says. */
static void test_calibration_vlp16_applied_exactly(void)
{
    uint32_t b, j, n = 0, i;
    int32_t rank_of[16];
    memset(&cal, 0, sizeof cal);
    cal.n_lasers = 16u;
    for (i = 0; i < 16u; ++i)
    {
        cal.laser[i].vert_mdeg = (i % 2u) ? 1000 + 2000 * (int32_t)(i / 2u) : -15000 + 1000 * (int32_t)i;
        cal.laser[i].rot_cdeg = (int16_t)(37 * (int32_t)i - 300);
        cal.laser[i].dist_mm = (int16_t)(11 * (int32_t)i - 60);
    }
    cal.laser[0].vert_mdeg = 20000; /* now the highest: ring 15, the others move down one */
    cal.laser[6].dist_mm = -32767;  /* every range of laser 6 (< 2.2 m here) left below zero */
    cal.laser[9].rot_cdeg = -18000; /* half a turn */
    for (i = 0; i < 16u; ++i)
    {
        uint32_t k;
        rank_of[i] = 0;
        for (k = 0; k < 16u; ++k)
        {
            rank_of[i] += cal.laser[k].vert_mdeg < cal.laser[i].vert_mdeg;
        }
    }
    TEST_ASSERT_EQUAL_INT32(15, rank_of[0]);
    cfg.model = LIDET_VELODYNE_VLP16;
    cfg.calib = &cal;
    init();
    memset(&cal, 0xA5, sizeof cal); /* read by init only */
    make(0x22u, 0x37u, 35990u, 40u, 1000u);
    TEST_ASSERT_EQUAL_INT(LIDET_OK, run());
    TEST_ASSERT_EQUAL_UINT32(384u - 24u, res.n_returns);
    TEST_ASSERT_EQUAL_UINT32(24u, g.ws.stats.n_short_range);
    TEST_ASSERT_EQUAL_UINT32(384u - 24u, g.ws.stats.n_returns);
    for (b = 0; b < 12u; ++b)
    {
        for (j = 0; j < 32u; ++j)
        {
            const uint32_t laser = j % 16u, off = (j / 16u) * 24u + laser;
            const int32_t rot = laser == 9u ? -18000 : 37 * (int32_t)laser - 300;
            const int32_t dist = 11 * (int32_t)laser - 60;
            const uint16_t cdeg = rule_cdeg((35990u + 40u * b) % 36000u, 40u, off, 48u, rot);
            int32_t e;
            if (laser == 6u)
            {
                continue; /* dropped: counted in n_short_range */
            }
            TEST_ASSERT_EQUAL_UINT32((uint32_t)(2 * (int32_t)(1000u + j) + dist), g_out.ws[n].range_mm);
            TEST_ASSERT_EQUAL_UINT16((uint16_t)rank_of[laser], g_out.ws[n].ring);
            TEST_ASSERT_EQUAL_UINT16(cdeg, attr[n].azimuth_cdeg);
            TEST_ASSERT_INT_WITHIN(1, 0, bam_diff(bam_of_cdeg(cdeg), g_out.ws[n].azimuth));
            TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_velodyne_decoder_elev_mdeg(&g.ws, g_out.ws[n].ring, &e));
            TEST_ASSERT_EQUAL_INT32(laser == 0u    ? 20000
                                    : (laser % 2u) ? 1000 + 2000 * (int32_t)(laser / 2u)
                                                   : -15000 + 1000 * (int32_t)laser,
                                    e);
            ++n;
        }
    }
    TEST_ASSERT_EQUAL_UINT32(n, res.n_returns);
    /* x, y, z from the calibration's elevations */
    {
        float xyz[3];
        TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_velodyne_decoder_xyz(&g.ws, g_out.ws, 1u, xyz, 3u));
        TEST_ASSERT_CLOSE((2000.0 - 60.0) / 1000.0 * sin(20.0 * M_PI / 180.0), xyz[2], 1e-5, 1e-5);
    }
    /* ring_top_first numbers the same rings from the top */
    memset(&cal, 0, sizeof cal);
    cal.n_lasers = 16u;
    for (i = 0; i < 16u; ++i)
    {
        cal.laser[i].vert_mdeg = (i % 2u) ? 1000 + 2000 * (int32_t)(i / 2u) : -15000 + 1000 * (int32_t)i;
    }
    cfg.ring_top_first = 1u;
    init();
    make(0x22u, 0x37u, 1000u, 40u, 1000u);
    TEST_ASSERT_EQUAL_INT(LIDET_OK, run());
    TEST_ASSERT_EQUAL_UINT16(15u, g_out.ws[0].ring); /* laser 0, -15 deg: the lowest */
    TEST_ASSERT_EQUAL_UINT16(7u, g_out.ws[1].ring);  /* laser 1, +1 deg */
}

/* A calibration equal to a model's nominal tables decodes bit for bit as no calibration (VLP-32C: its azimuth
 * offsets are a rotational correction of the opposite sign), and one HDL-64E laser's corrections move its returns
 * only. */
static void test_calibration_of_nominal_tables_is_identity(void)
{
    static lidet_return_t ref[CAP];
    static lidet_velodyne_attr_t ref_attr[CAP];
    static const int16_t delta[32] = {140,  -420, 140,  -140, 140,  -140, 420,  -140, 140,  -420, 140,
                                      -140, 420,  -140, 420,  -140, 140,  -420, 140,  -420, 420,  -140,
                                      140,  -140, 140,  -140, 140,  -420, 420,  -140, 140,  -140};
    static const uint8_t ring32[32] = {0, 17, 15, 1, 2,  20, 18, 3,  4,  21, 19, 5,  6,  24, 22, 8,
                                       7, 25, 23, 9, 10, 27, 26, 12, 11, 29, 28, 13, 14, 31, 30, 16};
    uint32_t i, n;
    cfg.model = LIDET_VELODYNE_VLP32C;
    init();
    make(0x28u, 0x37u, 35950u, 20u, 1000u);
    TEST_ASSERT_EQUAL_INT(LIDET_OK, run());
    n = res.n_returns;
    memcpy(ref, g_out.ws, sizeof ref);
    memcpy(ref_attr, attr, sizeof ref_attr);
    memset(&cal, 0, sizeof cal);
    cal.n_lasers = 32u;
    for (i = 0; i < 32u; ++i)
    {
        TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_velodyne_ring_elev_mdeg(LIDET_VELODYNE_VLP32C, ring32[i],
                                                                      &cal.laser[i].vert_mdeg));
        cal.laser[i].rot_cdeg = (int16_t)-delta[i];
    }
    cfg.calib = &cal;
    init();
    TEST_ASSERT_EQUAL_INT(LIDET_OK, run());
    TEST_ASSERT_EQUAL_UINT32(n, res.n_returns);
    TEST_ASSERT_EQUAL_MEMORY(ref, g_out.ws, n * sizeof ref[0]);
    TEST_ASSERT_EQUAL_MEMORY(ref_attr, attr, n * sizeof ref_attr[0]);
    /* HDL-64E: the nominal table as a calibration, then laser 40 (lower bank, point 8) moved */
    cfg.model = LIDET_VELODYNE_HDL64E;
    cfg.calib = 0;
    init();
    make64(500u, 18u, 2000u);
    TEST_ASSERT_EQUAL_INT(LIDET_OK, run());
    memcpy(ref, g_out.ws, sizeof ref);
    memcpy(ref_attr, attr, sizeof ref_attr);
    memset(&cal, 0, sizeof cal);
    cal.n_lasers = 64u;
    for (i = 0; i < 64u; ++i)
    {
        uint32_t r = 0;
        while (k_hdl64e_ascending[r] != i)
        {
            ++r;
        }
        TEST_ASSERT_EQUAL_INT(
            LIDET_OK, lidet_velodyne_ring_elev_mdeg(LIDET_VELODYNE_HDL64E, r, &cal.laser[i].vert_mdeg));
    }
    cal.laser[40].rot_cdeg = 250;
    cal.laser[40].dist_mm = 1234;
    cfg.calib = &cal;
    init();
    TEST_ASSERT_EQUAL_INT(LIDET_OK, run());
    TEST_ASSERT_EQUAL_UINT32(384u, res.n_returns);
    for (i = 0; i < 384u; ++i)
    {
        const int moved = (i % 64u) == 32u + 8u;
        TEST_ASSERT_EQUAL_UINT16(ref[i].ring, g_out.ws[i].ring);
        TEST_ASSERT_EQUAL_UINT32(ref[i].range_mm + (moved ? 1234u : 0u), g_out.ws[i].range_mm);
        TEST_ASSERT_EQUAL_UINT16((ref_attr[i].azimuth_cdeg + (moved ? 36000u - 250u : 0u)) % 36000u,
                                 attr[i].azimuth_cdeg);
    }
}

/* the library's bytes-as-packets robustness: random payloads of the right length, every byte pattern of the header
 * fields; counted, never out of bounds (the canaries and ASan builds check) */
static void test_random_payloads(void)
{
    uint32_t seed = 37u, p, i;
    init();
    for (p = 0; p < 2000u; ++p)
    {
        for (i = 0; i < LIDET_VELODYNE_PAYLOAD_BYTES; ++i)
        {
            seed ^= seed << 13;
            seed ^= seed >> 17;
            seed ^= seed << 5;
            pkt[i] = (uint8_t)seed;
        }
        if (p % 2u)
        {
            for (i = 0; i < 12u; ++i)
            {
                pkt[100u * i] = 0xFFu;
                pkt[100u * i + 1u] = 0xEEu;
                put16(pkt + 100u * i + 2u,
                      (uint32_t)(pkt[100u * i + 2u] | (pkt[100u * i + 3u] << 8)) % 36000u);
            }
            pkt[1204] = (uint8_t)(0x37u + (p / 2u) % 3u);
            pkt[1205] = (uint8_t)((p / 6u) % 3u == 0u ? 0x21u : (p / 6u) % 3u == 1u ? 0x22u : 0x28u);
            if (pkt[1204] == 0x39u)
            {
                for (i = 1; i < 12u; i += 2u)
                {
                    pkt[100u * i + 2u] = pkt[100u * (i - 1u) + 2u];
                    pkt[100u * i + 3u] = pkt[100u * (i - 1u) + 3u];
                }
            }
            lidet_velodyne_reset(&g.ws);
        }
        (void)lidet_velodyne_packet(&g.ws, pkt, LIDET_VELODYNE_PAYLOAD_BYTES, g_out.ws, attr, 1u + p % CAP,
                                    &res);
        TEST_ASSERT_TRUE(res.n_returns <= 1u + p % CAP);
        TEST_ASSERT_TRUE(res.scan_end <= res.n_returns);
        for (i = 0; i < res.n_returns; ++i)
        {
            TEST_ASSERT_TRUE(g_out.ws[i].ring < 32u);
            TEST_ASSERT_TRUE(attr[i].azimuth_cdeg < 36000u);
        }
    }
    TEST_ASSERT_EQUAL_UINT32(2000u, g.ws.stats.n_packets);
    TEST_ASSERT_TRUE(g.ws.stats.n_decoded > 0u && g.ws.stats.n_decoded < 2000u);
}

/* random payloads repaired into the HDL-64E layout (alternating banks, a firing's blocks at one azimuth, one in
 * eight a dual layout), decoded by AUTO, an HDL-64E decoder and a calibrated one: counted, never out of bounds */
static void test_random_hdl64e_payloads(void)
{
    uint32_t seed = 64u, p, i, k, n_dual;
    memset(&cal, 0, sizeof cal);
    cal.n_lasers = 64u;
    for (i = 0; i < 64u; ++i)
    {
        cal.laser[i].vert_mdeg = (int32_t)(i % 7u) * 1000 - 3000; /* ties: rings by laser id */
        cal.laser[i].rot_cdeg = (int16_t)((int32_t)i * 561 - 18000);
        cal.laser[i].dist_mm = (int16_t)((int32_t)i * 1000 - 32000);
    }
    for (k = 0; k < 3u; ++k)
    {
        lidet_velodyne_cfg_default(&cfg);
        cfg.model = k == 0u ? LIDET_VELODYNE_AUTO : LIDET_VELODYNE_HDL64E;
        cfg.calib = k == 2u ? &cal : 0;
        cfg.ring_top_first = (uint8_t)(k == 2u);
        init();
        n_dual = 0u;
        for (p = 0; p < 1000u; ++p)
        {
            for (i = 0; i < LIDET_VELODYNE_PAYLOAD_BYTES; ++i)
            {
                seed ^= seed << 13;
                seed ^= seed >> 17;
                seed ^= seed << 5;
                pkt[i] = (uint8_t)seed;
            }
            if (p % 2u)
            {
                for (i = 0; i < 12u; ++i)
                {
                    const uint32_t src = (p % 16u == 1u) ? i / 4u * 4u : i / 2u * 2u;
                    pkt[100u * i] = 0xFFu;
                    pkt[100u * i + 1u] = (i & 1u) ? 0xDDu : 0xEEu;
                    put16(pkt + 100u * i + 2u,
                          (uint32_t)(pkt[100u * src + 2u] | (pkt[100u * src + 3u] << 8)) % 36000u);
                }
            }
            if (LIDET_SUCCEEDED(lidet_velodyne_packet(&g.ws, pkt, LIDET_VELODYNE_PAYLOAD_BYTES, g_out.ws,
                                                      attr, 1u + p % CAP, &res)))
            {
                n_dual += res.return_mode == 0x39u;
                TEST_ASSERT_TRUE(res.return_mode == 0u || res.return_mode == 0x39u);
            }
            TEST_ASSERT_TRUE(res.n_returns <= 1u + p % CAP);
            TEST_ASSERT_TRUE(res.scan_end <= res.n_returns);
            for (i = 0; i < res.n_returns; ++i)
            {
                TEST_ASSERT_TRUE(g_out.ws[i].ring < 64u);
                TEST_ASSERT_TRUE(g_out.ws[i].range_mm > 0u && g_out.ws[i].range_mm <= 2u * 65535u + 32767u);
                TEST_ASSERT_TRUE(attr[i].azimuth_cdeg < 36000u && attr[i].t_ns < 288000u);
            }
        }
        TEST_ASSERT_EQUAL_UINT32(1000u, g.ws.stats.n_packets);
        TEST_ASSERT_TRUE(g.ws.stats.n_decoded > 300u && g.ws.stats.n_decoded <= 500u);
        TEST_ASSERT_EQUAL_UINT32(0u, g.ws.stats.n_rejected[LIDET_VELODYNE_REJECT_UNSUPPORTED]);
        TEST_ASSERT_TRUE(n_dual > 20u); /* the dual layouts decoded */
        if (k == 2u)
        {
            TEST_ASSERT_TRUE(g.ws.stats.n_short_range > 0u);
        }
    }
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_init_validates);
    RUN_TEST(test_rejections_are_counted);
    RUN_TEST(test_vlp16_interpolation_and_rings);
    RUN_TEST(test_vlp32c_pairs_offsets_and_units);
    RUN_TEST(test_hdl32e_timing);
    RUN_TEST(test_seam_completes_scans);
    RUN_TEST(test_jumps_abort_and_fragments_drop);
    RUN_TEST(test_dual_returns);
    RUN_TEST(test_truncation_never_writes_past_cap);
    RUN_TEST(test_xyz_of_returns);
    RUN_TEST(test_hdl64e_banks_timing_and_rings);
    RUN_TEST(test_hdl64e_ring_order_matches_hdl64_preset);
    RUN_TEST(test_hdl64e_auto_and_rejections);
    RUN_TEST(test_hdl64e_seam_and_jumps);
    RUN_TEST(test_hdl64e_dual_filters);
    RUN_TEST(test_hdl64e_dual_rejections);
    RUN_TEST(test_hdl64e_dual_seam);
    RUN_TEST(test_calibration_validated_and_copied);
    RUN_TEST(test_calibration_vlp16_applied_exactly);
    RUN_TEST(test_calibration_of_nominal_tables_is_identity);
    RUN_TEST(test_random_payloads);
    RUN_TEST(test_random_hdl64e_payloads);
    return UNITY_END();
}
