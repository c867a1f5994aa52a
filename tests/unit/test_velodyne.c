/* SPDX-License-Identifier: MIT */
/* Unity tests of the Velodyne packet decoder (lib/src/decode/lidet_velodyne.c) on payloads built here: every
 * rejection reason, the firing-time interpolation, the seam, dual-return filters, truncation, jumps. */
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
    RUN_TEST(test_random_payloads);
    return UNITY_END();
}
