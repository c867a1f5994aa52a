/* SPDX-License-Identifier: MIT */
/* Unity tests of the integer clustering and proposals (lib/src/cluster/lidet_*_q.c) on
 * hand-drawn images (test_cluster_util.h) turned into compact images: the same labels as the float stage on
 * the same image, records and per-point ids, configuration and input checks, integer limits. */
#include <math.h>
#include <string.h>

#include "internal/lidet_cluster_q_internal.h"
#include "lidet/lidet.h"
#include "test_util.h"
#include "test_cluster_util.h"

LIDET_GUARDED(lidet_cluster_q_t, g);
static lidet_cluster_t f;
static tcu_image_t t;
static lidet_cluster_cfg_t fcfg;
static lidet_cluster_q_cfg_t qcfg;
static int16_t cx[TCU_MAX_PIX], cy[TCU_MAX_PIX], cz[TCU_MAX_PIX];
static uint16_t crng[TCU_MAX_PIX];
static int32_t elev_bam[64];
static lidet_range_image_t cimg;

void setUp(void)
{
    CANARY_FILL(g);
    tcu_cfg(&fcfg);
    /* tcu_cfg's permissive filters in integer units */
    lidet_cluster_q_cfg_default(&qcfg, 0, 1730);
    qcfg.theta_urad = 200000;
    qcfg.max_steps = 3;
    qcfg.min_points = 1;
    qcfg.max_extent_mm = 100000;
    qcfg.max_mean_height_mm = INT32_MAX;
    qcfg.max_gap_mm = 0;
    qcfg.max_gap_per_m_q16 = 0;
}

void tearDown(void)
{
    CANARY_CHECK(g);
}

static int16_t q4(float v)
{
    return (int16_t)floor((double)v / 0.004 + 0.5);
}

/* the drawing as a compact image (4 mm steps, round half up as the projection does) */
static void draw_compact(const char *const *art, int rows)
{
    int p, r;
    tcu_draw(&t, art, rows);
    for (p = 0; p < t.img.n_rows * t.img.n_cols; ++p)
    {
        cx[p] = q4(t.x[p]);
        cy[p] = q4(t.y[p]);
        cz[p] = q4(t.z[p]);
        crng[p] = (uint16_t)q4(t.r[p]);
    }
    for (r = 0; r < rows; ++r)
    {
        elev_bam[r] = (int32_t)floor((double)t.elev[r] / (2.0 * M_PI) * 4294967296.0 + 0.5);
    }
    memset(&cimg, 0, sizeof cimg);
    cimg.n_rows = t.img.n_rows;
    cimg.n_cols = t.img.n_cols;
    cimg.x_4mm = cx;
    cimg.y_4mm = cy;
    cimg.z_4mm = cz;
    cimg.range_4mm = crng;
    cimg.row_elev_rad = t.elev;
    cimg.row_elev_bam = elev_bam;
}

/* the integer and the float stage on the same compact image give the same ids */
static void expect_same_as_float(const char *const *art, int rows, const uint8_t *ground)
{
    int p;
    draw_compact(art, rows);
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_cluster_init(&f, &fcfg));
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_cluster_run(&f, &cimg, ground, NULL, 0));
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_cluster_q_init(&g.ws, &qcfg));
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_cluster_q_run(&g.ws, &cimg, ground, NULL, 0));
    TEST_ASSERT_EQUAL_UINT32(f.state.n_recs, g.ws.state.n_recs);
    for (p = 0; p < cimg.n_rows * cimg.n_cols; ++p)
    {
        TEST_ASSERT_EQUAL_UINT16(f.labels[p], g.ws.labels[p]);
    }
}

static void test_same_labels_as_float(void)
{
    static const char *const jump[] = {
        "................................",
        "....cccckkkk....................",
        "....cccckkkk....................",
        "....cccckkkk....................",
    };
    static const char *const slant[] = {"......cdefhi.......................z"};
    static const char *const holes[] = {
        "................................", "....cc.ccc......................", "....cc..cc......................",
        "....cc.ccc......................", "......................c.........", "......................c.........",
    };
    static const char *const wrap[] = {"cc............................cc", "cc............................cc"};
    static const char *const pole[] = {
        "................................", "...eeeeaeeee....................", "...eeeeaeeee....................",
        "...eeeeaeeee....................",
    };
    expect_same_as_float(jump, 4, NULL);
    TEST_ASSERT_EQUAL_UINT32(2, g.ws.state.n_recs);
    expect_same_as_float(slant, 1, NULL);
    expect_same_as_float(holes, 6, NULL);
    expect_same_as_float(wrap, 2, NULL);
    TEST_ASSERT_EQUAL_UINT32(1, g.ws.state.n_recs); /* columns wrap */
    fcfg.bridge_occluders = 0;
    qcfg.bridge_occluders = 0;
    expect_same_as_float(pole, 4, NULL);
    fcfg.diagonals = 0;
    qcfg.diagonals = 0;
    fcfg.max_gap_m = 0.7f;
    qcfg.max_gap_mm = 700;
    expect_same_as_float(jump, 4, NULL);
    expect_same_as_float(holes, 6, NULL);
}

/* the fragment rescue: singletons beyond the bridging (4 columns apart, max_steps 3) join the block within
 * the rescue distance (1.4 deg columns at 10 m: 0.98 m < 0.8 m + 0.03 * 10 m); the same as the float stage */
static void test_rescue_same_as_float(void)
{
    static char rowbuf[3][257];
    static const char *art[3];
    int r, c;
    for (r = 0; r < 3; ++r)
    {
        memset(rowbuf[r], '.', 256);
        rowbuf[r][256] = 0;
        art[r] = rowbuf[r];
    }
    for (c = 100; c < 105; ++c)
    {
        rowbuf[1][c] = 'c';
        rowbuf[2][c] = 'c';
    }
    rowbuf[1][108] = 'c';
    rowbuf[1][112] = 'c';
    rowbuf[2][200] = 'c'; /* a lone fragment far from anything: dropped */
    tcu_rescue_cfg(&fcfg, 0.5f, 3, 0.8f, 0.03f);
    qcfg.theta_urad = 500000;
    qcfg.diagonals = 0;
    qcfg.bridge_occluders = 0;
    qcfg.min_points = 3;
    qcfg.rescue_gap_mm = 800;
    qcfg.rescue_gap_per_m_q16 = 1966;
    qcfg.rescue_rows = 1;
    qcfg.rescue_cols = 6;
    expect_same_as_float(art, 3, NULL);
    TEST_ASSERT_EQUAL_UINT32(1, g.ws.state.n_recs);
    TEST_ASSERT_EQUAL_UINT32(12, g.ws.state.recs[0].n_points);
    TEST_ASSERT_EQUAL_UINT32(2, g.ws.state.recs[0].n_rescued);
    TEST_ASSERT_EQUAL_UINT32(3, g.ws.state.stats.n_fragments);
    TEST_ASSERT_EQUAL_UINT32(1, g.ws.state.stats.n_rescue_joined);
    TEST_ASSERT_EQUAL_UINT32(1, g.ws.state.stats.n_dropped_small);
}

/* the ground mask removes pixels; the records hold the rounded mean, the bounds and the flat-ground height */
static void test_records_and_point_labels(void)
{
    static const char *const art[] = {
        "................",
        "...ccc.....gggg.",
        "...ccc.....gggg.",
    };
    const lidet_cluster_q_rec_t *rec;
    int64_t sum[3] = {0, 0, 0};
    int32_t pp[4];
    uint32_t lab[4], p, a;
    draw_compact(art, 3);
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_cluster_q_init(&g.ws, &qcfg));
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_cluster_q_run(&g.ws, &cimg, t.ground, NULL, 0));
    TEST_ASSERT_EQUAL_UINT32(1, g.ws.state.n_recs);
    TEST_ASSERT_EQUAL_UINT32(6, g.ws.state.stats.n_candidates);
    rec = &g.ws.state.recs[0];
    TEST_ASSERT_EQUAL_UINT32(6, rec->n_points);
    TEST_ASSERT_EQUAL_UINT32(16 + 3, rec->seed_pixel);
    for (p = 0; p < 6; ++p)
    {
        const uint32_t px = (uint32_t)g.ws.members[rec->first_member + p];
        sum[0] += cx[px];
        sum[1] += cy[px];
        sum[2] += cz[px];
        for (a = 0; a < 3; ++a)
        {
            const int32_t v = a == 0 ? cx[px] : (a == 1 ? cy[px] : cz[px]);
            TEST_ASSERT_TRUE(v >= rec->min_4mm[a] && v <= rec->max_4mm[a]);
        }
    }
    for (a = 0; a < 3; ++a)
    {
        const double m = (double)sum[a] / 6.0;
        TEST_ASSERT_TRUE(fabs(m - rec->mean_4mm[a]) <= 0.5);
    }
    TEST_ASSERT_EQUAL_INT32(rec->mean_4mm[2] + 433, rec->height_4mm); /* 1730 mm / 4 = 432.5 -> 433 */
    pp[0] = 16 + 4;
    pp[1] = 16 + 12; /* ground */
    pp[2] = -1;
    pp[3] = 9999; /* outside the image */
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_cluster_q_point_labels(&g.ws.state, pp, 4, lab));
    TEST_ASSERT_EQUAL_UINT32(1, lab[0]);
    TEST_ASSERT_EQUAL_UINT32(0, lab[1]);
    TEST_ASSERT_EQUAL_UINT32(0, lab[2]);
    TEST_ASSERT_EQUAL_UINT32(0, lab[3]);
    /* the height filter, against a tilted plane this time: 2 m above it passes at 2.5 m, not at 1.5 m */
    {
        lidet_plane_q_t pl = {0, 0, 1 << 30, 0};
        pl.d_4mm = 500 - rec->mean_4mm[2];
        qcfg.max_mean_height_mm = 2500;
        TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_cluster_q_init(&g.ws, &qcfg));
        TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_cluster_q_run(&g.ws, &cimg, t.ground, &pl, 1));
        TEST_ASSERT_EQUAL_UINT32(1, g.ws.state.n_recs);
        TEST_ASSERT_EQUAL_INT32(500, g.ws.state.recs[0].height_4mm);
        qcfg.max_mean_height_mm = 1500;
        TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_cluster_q_init(&g.ws, &qcfg));
        TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_cluster_q_run(&g.ws, &cimg, t.ground, &pl, 1));
        TEST_ASSERT_EQUAL_UINT32(0, g.ws.state.n_recs);
        TEST_ASSERT_EQUAL_UINT32(1, g.ws.state.stats.n_dropped_height);
    }
}

static void test_config_and_arguments(void)
{
    static const char *const art[] = {"..cc..", "..cc.."};
    lidet_cluster_q_cfg_t bad;
    lidet_range_image_t img;
    int i;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_ARG, lidet_cluster_q_init(NULL, &qcfg));
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_ARG, lidet_cluster_q_init(&g.ws, NULL));
    for (i = 0; i < 10; ++i)
    {
        bad = qcfg;
        switch (i)
        {
        case 8: bad.regrow_cut_mm = 2001; break;
        case 0: bad.theta_urad = 0; break;
        case 1: bad.theta_urad = 1500000; break;
        case 2: bad.max_steps = 0; break;
        case 3: bad.max_steps = LIDET_CLUSTER_MAX_STEPS + 1; break;
        case 4: bad.min_points = 0; break;
        case 5: bad.max_extent_mm = 0; break;
        case 6: bad.max_gap_per_m_q16 = 65537; break;
        case 7: bad.rescue_gap_mm = 10001; break;
        default: bad.rescue_cols = 16; break;
        }
        TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_cluster_q_init(&g.ws, &bad));
    }
    draw_compact(art, 2);
    /* not initialised (the failed init above cleared the magic) */
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_STATE, lidet_cluster_q_run(&g.ws, &cimg, NULL, NULL, 0));
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_cluster_q_init(&g.ws, &qcfg));
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_ARG, lidet_cluster_q_run(&g.ws, NULL, NULL, NULL, 0));
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_ARG, lidet_cluster_q_run(&g.ws, &cimg, NULL, (const lidet_plane_q_t *)elev_bam, 0));
    img = cimg;
    img.x_m = t.x; /* a float image */
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_ARG, lidet_cluster_q_run(&g.ws, &img, NULL, NULL, 0));
    img = cimg;
    img.row_elev_bam = NULL;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_ARG, lidet_cluster_q_run(&g.ws, &img, NULL, NULL, 0));
    img = cimg;
    img.n_cols = 1;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_BUFFER, lidet_cluster_q_run(&g.ws, &img, NULL, NULL, 0));
    img.n_cols = LIDET_MAX_COLS + 1;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_BUFFER, lidet_cluster_q_run(&g.ws, &img, NULL, NULL, 0));
}

/* coordinates and ranges at the integer limits, extreme elevations and planes: a status, no overflow (the
 * sanitizer build runs this) */
static void test_integer_limits(void)
{
    static const char *const art[] = {"cccccccc", "cccccccc", "cccccccc", "cccccccc"};
    lidet_plane_q_t pl[2] = {{INT32_MAX, INT32_MIN, INT32_MAX, INT32_MIN}, {0, 0, 1 << 30, INT32_MAX}};
    lidet_proposal_q_cfg_t pc;
    lidet_proposal_q_t pr;
    int p;
    draw_compact(art, 4);
    for (p = 0; p < 32; ++p)
    {
        cx[p] = (int16_t)(p % 2 ? 32767 : -32768);
        cy[p] = (int16_t)(p % 3 ? -32768 : 32767);
        cz[p] = (int16_t)(p % 5 ? 32767 : -32768);
        crng[p] = (uint16_t)(p % 4 ? 65535 : 1);
    }
    elev_bam[0] = INT32_MAX;
    elev_bam[1] = INT32_MIN;
    elev_bam[2] = 0;
    elev_bam[3] = 1 << 30;
    qcfg.max_gap_mm = 1000000;
    qcfg.max_gap_per_m_q16 = 65536;
    qcfg.rescue_gap_mm = 10000;
    qcfg.rescue_gap_per_m_q16 = 16384;
    qcfg.min_points = 3;
    qcfg.max_extent_mm = 1000000;
    qcfg.max_mean_height_mm = INT32_MIN;
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_cluster_q_init(&g.ws, &qcfg));
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_cluster_q_run(&g.ws, &cimg, NULL, pl, 2));
    TEST_ASSERT_EQUAL_UINT32(32, g.ws.state.stats.n_candidates);
    qcfg.max_mean_height_mm = INT32_MAX;
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_cluster_q_init(&g.ws, &qcfg));
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_cluster_q_run(&g.ws, &cimg, NULL, pl, 2));
    TEST_ASSERT_TRUE(g.ws.state.n_recs >= 1);
    lidet_proposal_q_cfg_default(&pc);
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_proposal_q_make(&g.ws.state, 0, &pc, &pr));
    TEST_ASSERT_EQUAL_UINT32(g.ws.state.recs[0].n_points, pr.n_points_src);
}

/* a wall straight ahead (+x, the middle columns) at 10 m: the voxel of its mean, the centred points */
static void test_proposal(void)
{
    static const char *const art[] = {
        "................................",
        "..............cccc..............",
        "..............cccc..............",
    };
    lidet_proposal_q_cfg_t pc;
    lidet_proposal_q_t pr;
    const lidet_cluster_q_rec_t *rec;
    uint32_t idx[LIDET_PROPOSAL_POINTS], i;
    draw_compact(art, 3);
    lidet_proposal_q_cfg_default(&pc);
    memset(&g.ws.state, 0, sizeof g.ws.state);
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_STATE, lidet_proposal_q_make(&g.ws.state, 0, &pc, &pr)); /* never run */
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_cluster_q_init(&g.ws, &qcfg));
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_cluster_q_run(&g.ws, &cimg, NULL, NULL, 0));
    TEST_ASSERT_EQUAL_UINT32(1, g.ws.state.n_recs);
    rec = &g.ws.state.recs[0];
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_ARG, lidet_proposal_q_make(&g.ws.state, 1, &pc, &pr));
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_ARG, lidet_proposal_q_make(NULL, 0, &pc, &pr));
    pc.range_bin_4mm = 0;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_proposal_q_make(&g.ws.state, 0, &pc, &pr));
    lidet_proposal_q_cfg_default(&pc);
    pc.n_points = LIDET_PROPOSAL_POINTS + 1u;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_proposal_q_make(&g.ws.state, 0, &pc, &pr));
    lidet_proposal_q_cfg_default(&pc);
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_proposal_q_make(&g.ws.state, 0, &pc, &pr));
    TEST_ASSERT_EQUAL_UINT32(8, pr.n_points_src);
    /* azimuth about 0 (+x, either side of the column edge), elevation a few degrees (bin 0), range ~10 m */
    TEST_ASSERT_TRUE(pr.voxel[0] == 0 || pr.voxel[0] == -1);
    TEST_ASSERT_EQUAL_INT16(0, pr.voxel[1]);
    TEST_ASSERT_TRUE(pr.voxel[2] == 9 || pr.voxel[2] == 10);
    /* the points are the resampled members minus the rounded mean (the float stage's indices) */
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_proposal_indices(g.ws.members + rec->first_member, rec->n_points,
                                                           pc.n_points, pc.seed, idx));
    for (i = 0; i < pc.n_points; ++i)
    {
        const int32_t px = g.ws.members[rec->first_member + idx[i]];
        TEST_ASSERT_EQUAL_INT16(cx[px] - rec->mean_4mm[0], pr.xyz[i][0]);
        TEST_ASSERT_EQUAL_INT16(cy[px] - rec->mean_4mm[1], pr.xyz[i][1]);
        TEST_ASSERT_EQUAL_INT16(cz[px] - rec->mean_4mm[2], pr.xyz[i][2]);
    }
    /* z from the ground under the mean: the mean's height above its plane added to every z, mean z lowered by it */
    pc.z_origin = LIDET_PROPOSAL_Z_GROUND;
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_proposal_q_make(&g.ws.state, 0, &pc, &pr));
    TEST_ASSERT_TRUE(rec->height_4mm > 100);
    TEST_ASSERT_EQUAL_INT32(rec->mean_4mm[2] - rec->height_4mm, pr.mean_4mm[2]);
    for (i = 0; i < pc.n_points; ++i)
    {
        const int32_t px = g.ws.members[rec->first_member + idx[i]];
        TEST_ASSERT_EQUAL_INT16(cx[px] - rec->mean_4mm[0], pr.xyz[i][0]);
        TEST_ASSERT_EQUAL_INT16(cz[px] - rec->mean_4mm[2] + rec->height_4mm, pr.xyz[i][2]);
    }
    pc.z_origin = LIDET_PROPOSAL_Z_GROUND + 1u;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_proposal_q_make(&g.ws.state, 0, &pc, &pr));
}

/* The join test's gap bound on the cores without a 32 x 32 -> 64 multiply (lidet__cluster_q_gap_ok): the exact
 * 64-bit comparison on random ranges, angles and gaps (near and far from the bound, gaps above 2^16 too) and on the
 * corners of its operands */
static uint32_t gap_lcg(uint32_t *s)
{
    *s = *s * 1664525u + 1013904223u;
    return *s;
}

static int gap_ref(uint32_t dd, uint32_t gg, uint32_t x, uint32_t h)
{
    return (uint64_t)dd * dd + (((uint64_t)x * h + ((uint64_t)1 << 29)) >> 30) <= (uint64_t)gg * gg;
}

void test_gap_bound_from_32_bit_products(void)
{
    static const uint32_t xs[] = {0u, 1u, 65535u, 65536u, 0xFFFE0001u, 0xFFFFFFFFu};
    static const uint32_t hs[] = {0u, 1u, 13000u, 65535u, 65536u, 1300000u, 0x40000000u, 0xFFFFFFFFu};
    static const uint32_t gs[] = {0u, 1u, 175u, 65535u, 65536u, 0xFFFFFFFFu};
    uint32_t s = 2024u, k, i, j, m, n_ok = 0, n_no = 0;
    for (i = 0; i < sizeof xs / sizeof xs[0]; ++i)
        for (j = 0; j < sizeof hs / sizeof hs[0]; ++j)
            for (m = 0; m < sizeof gs / sizeof gs[0]; ++m)
            {
                const uint32_t gg = gs[m], dd = gg < 65535u ? gg : 65535u;
                TEST_ASSERT_EQUAL_INT(gap_ref(dd, gg, xs[i], hs[j]), lidet__cluster_q_gap_ok(dd, gg, xs[i], hs[j]));
                TEST_ASSERT_EQUAL_INT(gap_ref(0u, gg, xs[i], hs[j]), lidet__cluster_q_gap_ok(0u, gg, xs[i], hs[j]));
            }
    for (k = 0; k < 500000u; ++k)
    {
        const uint32_t d1 = 1u + gap_lcg(&s) % 65535u, d2 = 1u + gap_lcg(&s) % d1;
        const uint32_t x = d1 * d2, h = gap_lcg(&s) >> (gap_lcg(&s) % 32u);
        const uint32_t gg = k % 50u == 0u ? gap_lcg(&s) >> (gap_lcg(&s) % 16u) : 1u + gap_lcg(&s) % 3000u;
        uint32_t dd = gap_lcg(&s) % (gg < 65535u ? gg + 1u : 65536u);
        int ref;
        if (k % 2u == 0u && gg < 65536u)
        {
            /* dd near the bound: dd^2 + cross = gg^2 within a few units */
            const uint64_t cross = ((uint64_t)x * h + ((uint64_t)1 << 29)) >> 30, g2 = (uint64_t)gg * gg;
            if (cross <= g2)
            {
                /* the largest dd with dd^2 <= gg^2 - cross, moved by -1..+1 */
                const uint64_t r = g2 - cross;
                uint64_t root = (uint64_t)sqrt((double)r);
                while (root * root > r)
                {
                    --root;
                }
                while ((root + 1u) * (root + 1u) <= r)
                {
                    ++root;
                }
                root = root + (gap_lcg(&s) % 3u);
                root = root > 0u ? root - 1u : 0u;
                dd = root > gg ? gg : (uint32_t)root;
            }
        }
        ref = gap_ref(dd, gg, x, h);
        TEST_ASSERT_EQUAL_INT(ref, lidet__cluster_q_gap_ok(dd, gg, x, h));
        n_ok += (uint32_t)ref;
        n_no += (uint32_t)!ref;
    }
    TEST_ASSERT_GREATER_THAN_UINT32(50000u, n_ok);
    TEST_ASSERT_GREATER_THAN_UINT32(50000u, n_no);
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_same_labels_as_float);
    RUN_TEST(test_rescue_same_as_float);
    RUN_TEST(test_records_and_point_labels);
    RUN_TEST(test_config_and_arguments);
    RUN_TEST(test_integer_limits);
    RUN_TEST(test_proposal);
    RUN_TEST(test_gap_bound_from_32_bit_products);
    return UNITY_END();
}
