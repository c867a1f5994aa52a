/* SPDX-License-Identifier: MIT */
/* Unity tests of the Ouster packet decoder (lib/src/decode/lidet_ouster.c) on payloads built here: every profile's
 * layout, the azimuth rule, frame completion, the seam, jumps, fragments, every rejection reason, capacity. */
#include <string.h>

#include "lidet/lidet.h"
#include "test_util.h"

#define CAP LIDET_OUSTER_MAX_RETURNS
#define MAXPKT 65536u

LIDET_GUARDED(lidet_ouster_t, g);
static struct
{
    uint32_t pre[LIDET_CANARY_WORDS];
    lidet_return_t ws[CAP];
    uint32_t post[LIDET_CANARY_WORDS];
} g_out;
static lidet_ouster_attr_t attr[CAP];
static uint8_t pkt[MAXPKT];
static lidet_ouster_cfg_t cfg;
static lidet_ouster_result_t res;

void setUp(void)
{
    CANARY_FILL(g);
    CANARY_FILL(g_out);
    lidet_ouster_cfg_default(&cfg);
    cfg.pixels_per_column = 16u;
    cfg.columns_per_frame = 512u;
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

static void put32(uint8_t *p, uint32_t v)
{
    put16(p, v & 0xFFFFu);
    put16(p + 2, v >> 16);
}

static uint32_t pixel_bytes(lidet_ouster_profile_t p)
{
    return p == LIDET_OUSTER_RNG19_RFL8_SIG16_NIR16_DUAL ? 16u : p == LIDET_OUSTER_RNG15_RFL8_NIR8 ? 4u : 12u;
}

static uint32_t legacy(void)
{
    return cfg.profile == LIDET_OUSTER_LEGACY;
}

static uint32_t col_bytes(void)
{
    return (legacy() ? 20u : 12u) + cfg.pixels_per_column * pixel_bytes(cfg.profile);
}

static uint32_t pkt_bytes(void)
{
    return (legacy() ? 0u : 64u) + cfg.columns_per_packet * col_bytes();
}

static uint8_t *col_at(uint32_t c)
{
    return pkt + (legacy() ? 0u : 32u) + c * col_bytes();
}

/* The range written at column c (of the packet), row r: 1000 + 7 r + c mm (RNG15: x 8); second return + 500. */
static uint32_t range_at(uint32_t c, uint32_t r, uint32_t k)
{
    const uint32_t v = 1000u + 7u * r + c + 500u * k;
    return cfg.profile == LIDET_OUSTER_RNG15_RFL8_NIR8 ? 8u * v : v;
}

/* A payload of cfg's layout: frame `frame`, columns at measurement ids first_mid + c (wrapping into frame + 1:
 * LEGACY columns carry their own frame id), every pixel's range range_at, reflectivity r + 1, signal 100 + r,
 * flags 1; timestamps 1e6 + 1000 m ns; the header's init id 0x123456 and serial number 0x0102030405. */
static void make(uint32_t frame, uint32_t first_mid)
{
    uint32_t c, r;
    memset(pkt, 0, sizeof pkt);
    if (!legacy())
    {
        if (cfg.header == LIDET_OUSTER_HEADER_FUSA)
        {
            pkt[0] = 1u;
            put32(pkt, (0x123456u << 8) | 1u);
            put32(pkt + 4, frame);
            pkt[11] = 0x05u;
            put32(pkt + 12, 0x01020304u);
        }
        else
        {
            put16(pkt, 1u);
            put16(pkt + 2, frame & 0xFFFFu);
            put32(pkt + 4, 0x123456u);
            put32(pkt + 7, 0x02030405u);
            pkt[11] = 0x01u;
        }
    }
    for (c = 0; c < cfg.columns_per_packet; ++c)
    {
        uint8_t *col = col_at(c);
        const uint32_t m = (first_mid + c) % cfg.columns_per_frame;
        const uint32_t f = frame + (first_mid + c) / cfg.columns_per_frame;
        put32(col, 1000000u + 1000u * m);
        put16(col + 8, m);
        if (legacy())
        {
            put16(col + 10, f & 0xFFFFu);
            put32(col + 12, m * LIDET_OUSTER_ENCODER_TICKS / cfg.columns_per_frame);
            put32(col + col_bytes() - 4u, 0xFFFFFFFFu);
        }
        else
        {
            put16(col + 10, 1u);
        }
        for (r = 0; r < cfg.pixels_per_column; ++r)
        {
            uint8_t *px = col + (legacy() ? 16u : 12u) + r * pixel_bytes(cfg.profile);
            switch (cfg.profile)
            {
            case LIDET_OUSTER_LEGACY:
                put32(px, range_at(c, r, 0) | (1u << 28));
                put16(px + 4, r + 1u);
                put16(px + 6, 100u + r);
                break;
            case LIDET_OUSTER_RNG19_RFL8_SIG16_NIR16:
                put32(px, range_at(c, r, 0) | (1u << 19));
                px[4] = (uint8_t)(r + 1u);
                put16(px + 6, 100u + r);
                break;
            case LIDET_OUSTER_RNG19_RFL8_SIG16_NIR16_DUAL:
                put32(px, range_at(c, r, 0) | (1u << 19) | ((r + 1u) << 24));
                put32(px + 4, range_at(c, r, 1) | (1u << 19) | ((r + 2u) << 24));
                put16(px + 8, 100u + r);
                put16(px + 10, 200u + r);
                break;
            default:
                put16(px, range_at(c, r, 0) / 8u | 0x8000u);
                px[2] = (uint8_t)(r + 1u);
                break;
            }
        }
    }
}

static void set_range(uint32_t c, uint32_t r, uint32_t v)
{
    uint8_t *px = col_at(c) + (legacy() ? 16u : 12u) + r * pixel_bytes(cfg.profile);
    if (cfg.profile == LIDET_OUSTER_RNG15_RFL8_NIR8)
    {
        put16(px, v / 8u);
    }
    else
    {
        put32(px, v);
    }
    if (cfg.profile == LIDET_OUSTER_RNG19_RFL8_SIG16_NIR16_DUAL)
    {
        put32(px + 4, 0u);
    }
}

static void set_status(uint32_t c, uint32_t valid)
{
    if (legacy())
    {
        put32(col_at(c) + col_bytes() - 4u, valid ? 0xFFFFFFFFu : 0u);
    }
    else
    {
        put16(col_at(c) + 10, valid ? 1u : 0u);
    }
}

static void init(void)
{
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_ouster_init(&g.ws, &cfg));
}

static lidet_status_t run(void)
{
    return lidet_ouster_packet(&g.ws, pkt, pkt_bytes(), g_out.ws, attr, CAP, &res);
}

static void test_init_validates(void)
{
    lidet_ouster_t st;
    lidet_ouster_cfg_t c;
    const int32_t bad_az[16] = {0, 180000};
    memset(&st, 0, sizeof st);
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_ARG, lidet_ouster_init(0, &cfg));
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_ARG, lidet_ouster_init(&st, 0));
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_STATE, lidet_ouster_packet(&st, pkt, 100u, g_out.ws, 0, CAP, &res));
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_STATE, lidet_ouster_reset(&st));
    TEST_ASSERT_EQUAL_UINT32(0u, lidet_ouster_packet_bytes(&st));
    TEST_ASSERT_EQUAL_UINT32(0u, lidet_ouster_max_returns(0));
    lidet_ouster_cfg_default(&c);
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_ouster_init(&st, &c)); /* beams and columns not set */
#define BAD(field, value)                                                                                    \
    do                                                                                                       \
    {                                                                                                        \
        c = cfg;                                                                                             \
        c.field = value;                                                                                     \
        TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_ouster_init(&st, &c));                                 \
    } while (0)
    BAD(profile, (lidet_ouster_profile_t)5);
    BAD(profile, (lidet_ouster_profile_t)0);
    BAD(header, (lidet_ouster_header_t)2);
    BAD(filter, (lidet_ouster_filter_t)3);
    BAD(pixels_per_column, 0u);
    BAD(pixels_per_column, 129u);
    BAD(columns_per_frame, 15u);
    BAD(columns_per_frame, 16385u);
    BAD(columns_per_packet, 0u);
    BAD(columns_per_packet, 17u);
    BAD(seam_col, 512u);
    BAD(max_step_cols, 513u);
    BAD(init_id, 0x1000000u);
    BAD(prod_sn, (uint64_t)1 << 40);
    BAD(beam_azimuth_mdeg, bad_az);
#undef BAD
    c = cfg; /* 128 beams x 16 columns of 16-byte pixels: 33 024 bytes, still a datagram */
    c.profile = LIDET_OUSTER_RNG19_RFL8_SIG16_NIR16_DUAL;
    c.pixels_per_column = 128u;
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_ouster_init(&st, &c));
    TEST_ASSERT_EQUAL_UINT32(32u + 16u * (12u + 128u * 16u) + 32u, lidet_ouster_packet_bytes(&st));
    TEST_ASSERT_EQUAL_UINT32(LIDET_OUSTER_MAX_RETURNS, lidet_ouster_max_returns(&st));
    c.filter = LIDET_OUSTER_RETURN_FIRST;
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_ouster_init(&st, &c));
    TEST_ASSERT_EQUAL_UINT32(LIDET_OUSTER_MAX_RETURNS / 2u, lidet_ouster_max_returns(&st));
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_ARG, lidet_ouster_packet(&st, pkt, 100u, g_out.ws, 0, CAP, 0));
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_ARG, lidet_ouster_packet(&st, pkt, 100u, 0, 0, 1u, &res));
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_ARG, lidet_ouster_packet(0, pkt, 100u, g_out.ws, 0, CAP, &res));
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_ouster_reset(&st));
    TEST_ASSERT_NULL(lidet_ouster_stats(0));
    TEST_ASSERT_EQUAL_UINT32(12u, sizeof(lidet_ouster_attr_t));
    TEST_ASSERT_TRUE(sizeof(lidet_ouster_t) <= 420u);
}

static void test_packet_sizes(void)
{
    /* the captures of ../shared/data/packets/ouster: OS1-64 and OS1-32 LEGACY, OS2-128 single, OS0-128 low data
     * rate, OS0-32 dual (the last two both 8448 bytes) */
    static const struct
    {
        lidet_ouster_profile_t profile;
        uint16_t beams;
        uint32_t bytes;
    } k[] = {{LIDET_OUSTER_LEGACY, 64u, 12608u},
             {LIDET_OUSTER_LEGACY, 32u, 6464u},
             {LIDET_OUSTER_RNG19_RFL8_SIG16_NIR16, 128u, 24832u},
             {LIDET_OUSTER_RNG15_RFL8_NIR8, 128u, 8448u},
             {LIDET_OUSTER_RNG19_RFL8_SIG16_NIR16_DUAL, 32u, 8448u},
             {LIDET_OUSTER_RNG19_RFL8_SIG16_NIR16, 16u, 3328u}};
    uint32_t i;
    for (i = 0; i < sizeof k / sizeof k[0]; ++i)
    {
        cfg.profile = k[i].profile;
        cfg.pixels_per_column = k[i].beams;
        cfg.columns_per_frame = 1024u;
        init();
        TEST_ASSERT_EQUAL_UINT32(k[i].bytes, lidet_ouster_packet_bytes(&g.ws));
        TEST_ASSERT_EQUAL_UINT32(k[i].bytes, pkt_bytes());
    }
}

/* Every profile, 16 to 128 beams, 512 to 2048 columns: each pixel decoded where it was written. */
static void test_profiles_decode_exactly(void)
{
    static const lidet_ouster_profile_t profiles[] = {
        LIDET_OUSTER_LEGACY, LIDET_OUSTER_RNG19_RFL8_SIG16_NIR16, LIDET_OUSTER_RNG19_RFL8_SIG16_NIR16_DUAL,
        LIDET_OUSTER_RNG15_RFL8_NIR8};
    static const uint16_t beams[] = {16u, 32u, 64u, 128u};
    static const uint16_t cols[] = {512u, 1024u, 2048u};
    static int32_t az_mdeg[128];
    uint32_t p, b, w, r;
    for (r = 0; r < 128u; ++r)
    {
        az_mdeg[r] = (int32_t)(r % 7u) * 1500 - 4500; /* -4.5 .. +4.5 deg */
    }
    for (p = 0; p < 4u; ++p)
    {
        for (b = 0; b < 4u; ++b)
        {
            for (w = 0; w < 3u; ++w)
            {
                const uint32_t dual = profiles[p] == LIDET_OUSTER_RNG19_RFL8_SIG16_NIR16_DUAL;
                const uint32_t mid0 = cols[w] / 2u;
                uint32_t c, i = 0;
                lidet_ouster_cfg_default(&cfg);
                cfg.profile = profiles[p];
                cfg.pixels_per_column = beams[b];
                cfg.columns_per_frame = cols[w];
                cfg.beam_azimuth_mdeg = az_mdeg;
                init();
                make(9u, mid0);
                set_range(3u, 5u, 0u); /* a zero range: skipped */
                TEST_ASSERT_EQUAL_INT(LIDET_OK, run());
                TEST_ASSERT_EQUAL_UINT32(16u * beams[b] * (dual ? 2u : 1u) - (dual ? 2u : 1u), res.n_returns);
                TEST_ASSERT_EQUAL_UINT8(LIDET_OUSTER_SCAN_NONE, res.scan_event);
                TEST_ASSERT_EQUAL_UINT32(9u, res.frame_id);
                TEST_ASSERT_EQUAL_UINT16(16u, res.n_valid_cols);
                TEST_ASSERT_EQUAL_UINT64(1000000u + 1000u * mid0, res.time_ns);
                for (c = 0; c < 16u; ++c)
                {
                    const uint32_t m = mid0 + c;
                    for (r = 0; r < beams[b]; ++r)
                    {
                        uint32_t k;
                        /* offset - m / W of a turn - the beam's offset (round(mdeg x 1024 / 5625)) */
                        const int32_t n = az_mdeg[r] * 1024;
                        const int32_t beam = n >= 0 ? (n + 2812) / 5625 : -((-n + 2812) / 5625);
                        const uint32_t bam =
                            (uint32_t)(32768 - (int32_t)((m * 65536u + cols[w] / 2u) / cols[w]) - beam) &
                            0xFFFFu;
                        if (c == 3u && r == 5u)
                        {
                            continue;
                        }
                        for (k = 0; k < (dual ? 2u : 1u); ++k, ++i)
                        {
                            TEST_ASSERT_EQUAL_UINT32(range_at(c, r, k), g_out.ws[i].range_mm);
                            TEST_ASSERT_EQUAL_UINT16(r, g_out.ws[i].ring);
                            TEST_ASSERT_EQUAL_UINT16(bam, g_out.ws[i].azimuth);
                            TEST_ASSERT_EQUAL_UINT16(m, attr[i].measurement_id);
                            TEST_ASSERT_EQUAL_UINT32(1000u * c, attr[i].t_ns);
                            TEST_ASSERT_EQUAL_UINT8(k, attr[i].return_index);
                            TEST_ASSERT_EQUAL_UINT16(r + 1u + k, attr[i].reflectivity);
                            TEST_ASSERT_EQUAL_UINT16(
                                profiles[p] == LIDET_OUSTER_RNG15_RFL8_NIR8 ? 0u : 100u + r + 100u * k,
                                attr[i].signal);
                            TEST_ASSERT_EQUAL_UINT8(1u, attr[i].flags);
                        }
                    }
                }
                TEST_ASSERT_EQUAL_UINT32(res.n_returns, i);
            }
        }
    }
}

static void test_dual_filters(void)
{
    cfg.profile = LIDET_OUSTER_RNG19_RFL8_SIG16_NIR16_DUAL;
    cfg.filter = LIDET_OUSTER_RETURN_FIRST;
    init();
    make(1u, 0u);
    TEST_ASSERT_EQUAL_INT(LIDET_OK, run());
    TEST_ASSERT_EQUAL_UINT32(256u, res.n_returns);
    TEST_ASSERT_EQUAL_UINT32(range_at(0u, 1u, 0u), g_out.ws[1].range_mm);
    cfg.filter = LIDET_OUSTER_RETURN_SECOND;
    init();
    TEST_ASSERT_EQUAL_INT(LIDET_OK, run());
    TEST_ASSERT_EQUAL_UINT32(256u, res.n_returns);
    TEST_ASSERT_EQUAL_UINT32(range_at(0u, 1u, 1u), g_out.ws[1].range_mm);
    TEST_ASSERT_EQUAL_UINT8(1u, attr[1].return_index);
}

/* one rejection: status, reason, count, nothing written, the rotation state untouched */
static void expect_reject(const uint8_t *p, uint32_t len, lidet_ouster_reject_t why)
{
    const lidet_ouster_t before = g.ws;
    uint32_t i;
    for (i = 0; i < CAP; ++i)
    {
        g_out.ws[i].range_mm = 0xA5A5A5A5u;
    }
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_MODEL, lidet_ouster_packet(&g.ws, p, len, g_out.ws, attr, CAP, &res));
    TEST_ASSERT_EQUAL_UINT8(why, res.reject);
    TEST_ASSERT_EQUAL_UINT32(0u, res.n_returns);
    TEST_ASSERT_EQUAL_UINT32(before.stats.n_rejected[why] + 1u, g.ws.stats.n_rejected[why]);
    TEST_ASSERT_EQUAL_UINT32(before.stats.n_packets + 1u, g.ws.stats.n_packets);
    TEST_ASSERT_EQUAL_UINT32(before.stats.n_decoded, g.ws.stats.n_decoded);
    TEST_ASSERT_EQUAL_UINT32(before.prev_frame, g.ws.prev_frame);
    TEST_ASSERT_EQUAL_UINT16(before.prev_mid, g.ws.prev_mid);
    TEST_ASSERT_EQUAL_UINT8(before.have_prev, g.ws.have_prev);
    for (i = 0; i < CAP; ++i)
    {
        TEST_ASSERT_EQUAL_HEX32(0xA5A5A5A5u, g_out.ws[i].range_mm);
    }
}

static void test_rejections_are_counted(void)
{
    cfg.init_id = 0x123456u;
    cfg.prod_sn = 0x0102030405u;
    init();
    make(7u, 32u);
    TEST_ASSERT_EQUAL_INT(LIDET_OK, run()); /* a good one first: the state has a rotation */
    expect_reject(0, pkt_bytes(), LIDET_OUSTER_REJECT_NULL);
    make(7u, 48u);
    expect_reject(pkt, pkt_bytes() - 1u, LIDET_OUSTER_REJECT_TRUNCATED);
    expect_reject(pkt, 0u, LIDET_OUSTER_REJECT_TRUNCATED);
    expect_reject(pkt, 48u, LIDET_OUSTER_REJECT_TRUNCATED); /* an IMU packet */
    expect_reject(pkt, pkt_bytes() + 1u, LIDET_OUSTER_REJECT_SIZE);
    pkt[0] = 2u; /* packet type */
    expect_reject(pkt, pkt_bytes(), LIDET_OUSTER_REJECT_HEADER);
    make(7u, 48u);
    pkt[4] ^= 1u; /* init id */
    expect_reject(pkt, pkt_bytes(), LIDET_OUSTER_REJECT_HEADER);
    make(7u, 48u);
    pkt[11] ^= 1u; /* serial number's top byte */
    expect_reject(pkt, pkt_bytes(), LIDET_OUSTER_REJECT_HEADER);
    make(7u, 48u);
    put16(col_at(15u) + 8, 512u); /* measurement id >= columns per frame */
    expect_reject(pkt, pkt_bytes(), LIDET_OUSTER_REJECT_HEADER);
    make(7u, 48u);
    for (uint32_t c = 0; c < 16u; ++c)
    {
        set_status(c, 0u);
    }
    expect_reject(pkt, pkt_bytes(), LIDET_OUSTER_REJECT_STATUS);
    make(7u, 32u); /* repeated */
    expect_reject(pkt, pkt_bytes(), LIDET_OUSTER_REJECT_ORDER);
    make(7u, 16u); /* late */
    expect_reject(pkt, pkt_bytes(), LIDET_OUSTER_REJECT_ORDER);
    make(6u, 480u); /* the frame before */
    expect_reject(pkt, pkt_bytes(), LIDET_OUSTER_REJECT_ORDER);
    make(7u, 48u);
    put16(col_at(9u) + 8, 50u); /* out of order inside the payload */
    expect_reject(pkt, pkt_bytes(), LIDET_OUSTER_REJECT_ORDER);
    /* decoding resumes where it was */
    make(7u, 48u);
    TEST_ASSERT_EQUAL_INT(LIDET_OK, run());
    TEST_ASSERT_EQUAL_UINT32(0u, g.ws.stats.n_jumps);
    TEST_ASSERT_EQUAL_UINT32(0u, g.ws.stats.n_lost_cols);
    TEST_ASSERT_EQUAL_UINT32(2u, g.ws.stats.n_decoded);
    TEST_ASSERT_EQUAL_UINT32(16u, g.ws.stats.n_packets);
    /* invalid columns of a decoded packet: skipped, counted */
    make(7u, 64u);
    set_status(0u, 0u);
    set_status(15u, 0u);
    TEST_ASSERT_EQUAL_INT(LIDET_OK, run());
    TEST_ASSERT_EQUAL_UINT32(14u * 16u, res.n_returns);
    TEST_ASSERT_EQUAL_UINT32(2u, g.ws.stats.n_invalid_cols);
    TEST_ASSERT_EQUAL_UINT16(65u, attr[0].measurement_id);
    TEST_ASSERT_EQUAL_UINT64(1000000u + 65000u, res.time_ns);
    /* LEGACY: an encoder count past a turn, a status word other than all ones */
    cfg.profile = LIDET_OUSTER_LEGACY;
    init();
    make(7u, 0u);
    put32(col_at(2u) + 12, LIDET_OUSTER_ENCODER_TICKS);
    expect_reject(pkt, pkt_bytes(), LIDET_OUSTER_REJECT_HEADER);
    make(7u, 0u);
    put32(col_at(2u) + col_bytes() - 4u, 0xFFFFFFFEu);
    TEST_ASSERT_EQUAL_INT(LIDET_OK, run());
    TEST_ASSERT_EQUAL_UINT32(15u * 16u, res.n_returns);
}

static void test_frames_complete_scans(void)
{
    uint32_t k, n_ret = 0;
    init();
    /* a whole frame from measurement id 0: the next frame id closes it as COMPLETE */
    for (k = 0; k < 32u; ++k)
    {
        make(100u, 16u * k);
        TEST_ASSERT_EQUAL_INT(LIDET_OK, run());
        TEST_ASSERT_EQUAL_UINT8(LIDET_OUSTER_SCAN_NONE, res.scan_event);
        n_ret += res.n_returns;
    }
    TEST_ASSERT_EQUAL_UINT32(512u * 16u, n_ret);
    make(101u, 0u);
    TEST_ASSERT_EQUAL_INT(LIDET_OK, run());
    TEST_ASSERT_EQUAL_UINT8(LIDET_OUSTER_SCAN_COMPLETE, res.scan_event);
    TEST_ASSERT_EQUAL_UINT32(0u, res.scan_end);
    TEST_ASSERT_EQUAL_UINT32(1u, g.ws.stats.n_scans);
    /* lost packets: counted, the frame still completes */
    make(101u, 64u);
    TEST_ASSERT_EQUAL_INT(LIDET_OK, run());
    TEST_ASSERT_EQUAL_UINT32(48u, g.ws.stats.n_lost_cols);
    make(102u, 0u);
    TEST_ASSERT_EQUAL_INT(LIDET_OK, run());
    TEST_ASSERT_EQUAL_UINT8(LIDET_OUSTER_SCAN_COMPLETE, res.scan_event);
    /* a frame id jump: ABORTED; the scan after it began at measurement id 0: whole */
    make(110u, 0u);
    TEST_ASSERT_EQUAL_INT(LIDET_OK, run());
    TEST_ASSERT_EQUAL_UINT8(LIDET_OUSTER_SCAN_ABORTED, res.scan_event);
    TEST_ASSERT_EQUAL_UINT32(1u, g.ws.stats.n_jumps);
    make(111u, 0u);
    TEST_ASSERT_EQUAL_INT(LIDET_OK, run());
    TEST_ASSERT_EQUAL_UINT8(LIDET_OUSTER_SCAN_COMPLETE, res.scan_event);
    /* after a reset mid-frame: PARTIAL */
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_ouster_reset(&g.ws));
    make(111u, 256u);
    TEST_ASSERT_EQUAL_INT(LIDET_OK, run());
    make(112u, 0u);
    TEST_ASSERT_EQUAL_INT(LIDET_OK, run());
    TEST_ASSERT_EQUAL_UINT8(LIDET_OUSTER_SCAN_PARTIAL, res.scan_event);
    TEST_ASSERT_EQUAL_UINT32(1u, g.ws.stats.n_partial);
    /* the 16-bit frame id wraps */
    make(0xFFFFu, 496u);
    TEST_ASSERT_EQUAL_INT(LIDET_OK, run());
    TEST_ASSERT_EQUAL_UINT8(LIDET_OUSTER_SCAN_ABORTED, res.scan_event);
    make(0u, 0u);
    TEST_ASSERT_EQUAL_INT(LIDET_OK, run());
    TEST_ASSERT_EQUAL_UINT8(LIDET_OUSTER_SCAN_PARTIAL, res.scan_event);
    TEST_ASSERT_EQUAL_UINT32(2u, g.ws.stats.n_jumps);
}

static void test_restart_aborts(void)
{
    init();
    make(300u, 256u);
    TEST_ASSERT_EQUAL_INT(LIDET_OK, run());
    make(0u, 16u);   /* frame ids start over */
    pkt[4] ^= 0x5Au; /* a new init id: the sensor re-initialised */
    TEST_ASSERT_EQUAL_INT(LIDET_OK, run());
    TEST_ASSERT_EQUAL_UINT8(LIDET_OUSTER_SCAN_ABORTED, res.scan_event);
    TEST_ASSERT_EQUAL_UINT32(0u, res.scan_end);
    TEST_ASSERT_EQUAL_UINT32(1u, g.ws.stats.n_jumps);
    make(0u, 0u); /* the old init id again, at an earlier measurement id: a restart, not a late packet */
    TEST_ASSERT_EQUAL_INT(LIDET_OK, run());
    TEST_ASSERT_EQUAL_UINT8(LIDET_OUSTER_SCAN_ABORTED, res.scan_event);
    TEST_ASSERT_EQUAL_UINT32(2u, g.ws.stats.n_jumps);
    make(0u, 0u); /* the same packet again: repeated */
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_MODEL, run());
    TEST_ASSERT_EQUAL_UINT8(LIDET_OUSTER_REJECT_ORDER, res.reject);
    /* a pinned init id rejects the other sensor session instead */
    cfg.init_id = 0x123456u;
    init();
    make(300u, 256u);
    TEST_ASSERT_EQUAL_INT(LIDET_OK, run());
    pkt[4] ^= 0x5Au;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_MODEL, run());
    TEST_ASSERT_EQUAL_UINT8(LIDET_OUSTER_REJECT_HEADER, res.reject);
}

static void test_seam_and_fragments(void)
{
    /* a seam at column 200: the boundary falls inside the payload of columns 192..207 */
    cfg.seam_col = 200u;
    init();
    make(5u, 208u);
    TEST_ASSERT_EQUAL_INT(LIDET_OK, run());
    TEST_ASSERT_EQUAL_UINT8(LIDET_OUSTER_SCAN_NONE, res.scan_event);
    make(6u, 192u); /* frame 6: crosses the seam at its 9th column, after 8 x 16 returns */
    TEST_ASSERT_EQUAL_INT(LIDET_OK, run());
    TEST_ASSERT_EQUAL_UINT8(LIDET_OUSTER_SCAN_PARTIAL, res.scan_event);
    TEST_ASSERT_EQUAL_UINT32(8u * 16u, res.scan_end);
    TEST_ASSERT_EQUAL_UINT16(200u, attr[res.scan_end].measurement_id);
    make(7u, 192u);
    TEST_ASSERT_EQUAL_INT(LIDET_OK, run());
    TEST_ASSERT_EQUAL_UINT8(LIDET_OUSTER_SCAN_COMPLETE, res.scan_event);
    /* LEGACY: a frame change, then a jump, inside one payload: the columns between are a fragment */
    lidet_ouster_cfg_default(&cfg);
    cfg.profile = LIDET_OUSTER_LEGACY;
    cfg.pixels_per_column = 16u;
    cfg.columns_per_frame = 512u;
    cfg.max_step_cols = 100u;
    init();
    make(3u, 480u);
    TEST_ASSERT_EQUAL_INT(LIDET_OK, run());
    make(3u, 504u); /* 504..511 of frame 3, 0..7 of frame 4 */
    put16(col_at(12u) + 8, 300u);
    put16(col_at(13u) + 8, 301u);
    put16(col_at(14u) + 8, 302u);
    put16(col_at(15u) + 8, 303u);
    TEST_ASSERT_EQUAL_INT(LIDET_OK, run());
    TEST_ASSERT_EQUAL_UINT8(LIDET_OUSTER_SCAN_PARTIAL, res.scan_event); /* began at 480 */
    TEST_ASSERT_EQUAL_UINT32(8u * 16u, res.scan_end);
    TEST_ASSERT_EQUAL_UINT32(4u * 16u, g.ws.stats.n_fragment); /* columns 0..3 of frame 4 */
    TEST_ASSERT_EQUAL_UINT32(12u * 16u, res.n_returns);
    TEST_ASSERT_EQUAL_UINT16(300u, attr[res.scan_end].measurement_id);
    TEST_ASSERT_EQUAL_UINT32(1u, g.ws.stats.n_jumps);
    TEST_ASSERT_EQUAL_UINT32(0u, g.ws.stats.n_aborted); /* the second boundary of the payload: no scan */
    TEST_ASSERT_EQUAL_UINT32(g.ws.stats.n_returns, 16u * 16u + 12u * 16u);
}

static void test_fusa_header(void)
{
    cfg.header = LIDET_OUSTER_HEADER_FUSA;
    cfg.init_id = 0x123456u;
    cfg.prod_sn = 0x0102030405u;
    init();
    make(70000u, 496u);
    TEST_ASSERT_EQUAL_INT(LIDET_OK, run());
    TEST_ASSERT_EQUAL_UINT32(70000u, res.frame_id);
    make(70001u, 0u);
    TEST_ASSERT_EQUAL_INT(LIDET_OK, run());
    TEST_ASSERT_EQUAL_UINT8(LIDET_OUSTER_SCAN_PARTIAL, res.scan_event);
    make(0x10000u + 70001u, 16u); /* 32-bit frame ids: 65536 frames later is a jump */
    TEST_ASSERT_EQUAL_INT(LIDET_OK, run());
    TEST_ASSERT_EQUAL_UINT8(LIDET_OUSTER_SCAN_ABORTED, res.scan_event);
    pkt[0] = 2u;
    expect_reject(pkt, pkt_bytes(), LIDET_OUSTER_REJECT_HEADER);
}

static void test_capacity(void)
{
    lidet_status_t s;
    uint32_t i;
    init();
    make(1u, 0u);
    for (i = 0; i < CAP; ++i)
    {
        g_out.ws[i].range_mm = 0xA5A5A5A5u;
    }
    s = lidet_ouster_packet(&g.ws, pkt, pkt_bytes(), g_out.ws, attr, 100u, &res);
    TEST_ASSERT_EQUAL_INT(LIDET_TRUNCATED, s);
    TEST_ASSERT_EQUAL_UINT32(100u, res.n_returns);
    TEST_ASSERT_EQUAL_UINT32(256u - 100u, g.ws.stats.n_truncated);
    for (i = 100u; i < CAP; ++i)
    {
        TEST_ASSERT_EQUAL_HEX32(0xA5A5A5A5u, g_out.ws[i].range_mm);
    }
    /* cap 0 and no output: counted, the tracking goes on (the frame began at column 0: COMPLETE, its 496 lost
     * columns counted) */
    make(2u, 0u);
    TEST_ASSERT_EQUAL_INT(LIDET_TRUNCATED, lidet_ouster_packet(&g.ws, pkt, pkt_bytes(), 0, 0, 0u, &res));
    TEST_ASSERT_EQUAL_UINT8(LIDET_OUSTER_SCAN_COMPLETE, res.scan_event);
    TEST_ASSERT_EQUAL_UINT32(496u, g.ws.stats.n_lost_cols);
    TEST_ASSERT_EQUAL_UINT32(0u, res.scan_end);
    TEST_ASSERT_EQUAL_UINT32(256u - 100u + 256u, g.ws.stats.n_truncated);
    TEST_ASSERT_EQUAL_UINT32(100u, g.ws.stats.n_returns);
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_init_validates);
    RUN_TEST(test_packet_sizes);
    RUN_TEST(test_profiles_decode_exactly);
    RUN_TEST(test_dual_filters);
    RUN_TEST(test_rejections_are_counted);
    RUN_TEST(test_frames_complete_scans);
    RUN_TEST(test_restart_aborts);
    RUN_TEST(test_seam_and_fragments);
    RUN_TEST(test_fusa_header);
    RUN_TEST(test_capacity);
    return UNITY_END();
}
