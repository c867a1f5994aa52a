/* SPDX-License-Identifier: MIT */
/* Unity tests of the depth clustering and the proposals (lib/src/cluster/lidet_cluster.c,
 * lidet_cluster_grow.c, lidet_cluster_rescue.c, lidet_proposal.c) on hand-drawn range images
 * (test_cluster_util.h: letters are ranges, '.' empty, 'g' ground). */
#include <math.h>
#include <string.h>

#include "internal/lidet_proposal_rule.h" /* the pick and its key */
#include "lidet/lidet.h"
#include "test_util.h"
#include "test_cluster_util.h"

LIDET_GUARDED(lidet_cluster_t, g);
static tcu_image_t t;
static lidet_cluster_cfg_t cfg;

void setUp(void)
{
    CANARY_FILL(g);
    tcu_cfg(&cfg);
}

void tearDown(void)
{
    CANARY_CHECK(g);
}

/* expected labels as art: '0' = none, '1'..'9' = canonical id */
static void expect_labels(const char *const *want, int rows)
{
    const uint16_t *lab = lidet_cluster_labels(&g.ws);
    const int cols = (int)strlen(want[0]);
    int r, c;
    for (r = 0; r < rows; ++r)
    {
        for (c = 0; c < cols; ++c)
        {
            char msg[64];
            sprintf(msg, "pixel row %d col %d", r, c);
            TEST_ASSERT_EQUAL_INT_MESSAGE(want[r][c] - '0', lab[r * cols + c], msg);
        }
    }
}

static void run(const char *const *art, int rows, const uint8_t *ground)
{
    tcu_draw(&t, art, rows);
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_cluster_init(&g.ws, &cfg));
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_cluster_run(&g.ws, &t.img, ground, NULL, 0));
}

/* two objects touching in the image, one 10 m away, one 30 m behind it: split at the depth jump */
static void test_depth_jump_splits(void)
{
    static const char *const art[] = {
        "................................",
        "....cccckkkk....................",
        "....cccckkkk....................",
        "....cccckkkk....................",
    };
    static const char *const want[] = {
        "00000000000000000000000000000000",
        "00001111222200000000000000000000",
        "00001111222200000000000000000000",
        "00001111222200000000000000000000",
    };
    run(art, 4, NULL);
    expect_labels(want, 4);
    TEST_ASSERT_EQUAL_UINT32(2, lidet_cluster_stats(&g.ws)->n_kept);
}

/* the angle criterion joins a slanted surface (small range steps) but not a jump */
static void test_slanted_surface_joins(void)
{
    static const char *const art[] = {
        "......cdefhi.......................z",
    };
    static const char *const want[] = {
        "000000111111000000000000000000000002",
    };
    run(art, 1, NULL);
    expect_labels(want, 1);
}

/* one object with holes (missing returns) joins through the bridging; without it, it splits */
static void test_hole_joins(void)
{
    static const char *const art[] = {
        "................................",
        "....cc.ccc......................",
        "....cc..cc......................",
        "....cc.ccc......................",
        "......................c.........",
        "......................c.........",
    };
    static const char *const want_bridged[] = {
        "00000000000000000000000000000000",
        "00001101110000000000000000000000",
        "00001100110000000000000000000000",
        "00001101110000000000000000000000",
        "00000000000000000000002000000000",
        "00000000000000000000002000000000",
    };
    static const char *const want_split[] = {
        "00000000000000000000000000000000",
        "00001102220000000000000000000000",
        "00001100220000000000000000000000",
        "00001102220000000000000000000000",
        "00000000000000000000003000000000",
        "00000000000000000000003000000000",
    };
    run(art, 6, NULL);
    expect_labels(want_bridged, 6);
    cfg.max_steps = 1;
    run(art, 6, NULL);
    expect_labels(want_split, 6);
}

/* a pole in front of a wall: with the occluder rule the wall stays one cluster behind it */
static void test_occluder_bridging(void)
{
    static const char *const art[] = {
        "......kkkkakkkkk................................................",
        "......kkkkakkkkk................................................",
        "......kkkkakkkkk................................................",
    };
    static const char *const want_bridged[] = {
        "0000001111211111000000000000000000000000000000000000000000000000",
        "0000001111211111000000000000000000000000000000000000000000000000",
        "0000001111211111000000000000000000000000000000000000000000000000",
    };
    static const char *const want_split[] = {
        "0000001111233333000000000000000000000000000000000000000000000000",
        "0000001111233333000000000000000000000000000000000000000000000000",
        "0000001111233333000000000000000000000000000000000000000000000000",
    };
    cfg.bridge_occluders = 1;
    run(art, 3, NULL);
    expect_labels(want_bridged, 3);
    cfg.bridge_occluders = 0;
    run(art, 3, NULL);
    expect_labels(want_split, 3);
}

/* diagonals: a staircase of returns (every other pixel missing) joins in the 8-neighbourhood only;
 * the diagonal search also wraps around the seam */
static void test_diagonals(void)
{
    static const char *const art[] = {
        "c.....................c.........",
        ".c.....................c........",
        "..c.....................c.......",
        ".......................c.......c",
        "c...............................",
    };
    static const char *const want8[] = {
        "10000000000000000000002000000000",
        "01000000000000000000000200000000",
        "00100000000000000000000020000000",
        "00000000000000000000000200000003",
        "30000000000000000000000000000000",
    };
    cfg.diagonals = 1;
    cfg.max_steps = 1;
    run(art, 5, NULL);
    expect_labels(want8, 5);
    TEST_ASSERT_EQUAL_UINT32(3, lidet_cluster_stats(&g.ws)->n_kept);
    cfg.diagonals = 0;
    run(art, 5, NULL);
    TEST_ASSERT_EQUAL_UINT32(9, lidet_cluster_stats(&g.ws)->n_kept);
}

/* max_gap_m: neighbours further apart than the gap do not join even when the angle test passes */
static void test_max_gap(void)
{
    static const char *const art[] = {
        "..cc.cc.........................",
    };
    /* 10 m, columns 11.25 deg apart: neighbours ~2 m apart, across the hole ~3.9 m */
    cfg.max_gap_m = 0.0f;
    run(art, 1, NULL);
    TEST_ASSERT_EQUAL_UINT32(1, lidet_cluster_stats(&g.ws)->n_kept);
    cfg.max_gap_m = 3.0f;
    run(art, 1, NULL);
    TEST_ASSERT_EQUAL_UINT32(2, lidet_cluster_stats(&g.ws)->n_kept);
    cfg.max_gap_m = 1.0f;
    run(art, 1, NULL);
    TEST_ASSERT_EQUAL_UINT32(4, lidet_cluster_stats(&g.ws)->n_kept);
    cfg.max_gap_m = -1.0f;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_cluster_init(&g.ws, &cfg));
    /* the bound grows with range: 1 m + 0.1 m per metre at 10 m = 2 m, neighbours (1.96 m) join,
     * the pair across the hole (3.9 m) does not */
    cfg.max_gap_m = 1.0f;
    cfg.max_gap_per_m = 0.1f;
    run(art, 1, NULL);
    TEST_ASSERT_EQUAL_UINT32(2, lidet_cluster_stats(&g.ws)->n_kept);
    cfg.max_gap_per_m = -0.1f;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_cluster_init(&g.ws, &cfg));
}

/* vertical bridging uses the real beam angles and also steps over ground pixels */
static void test_vertical_hole_and_ground(void)
{
    static const char *const art[] = {
        "...c....",
        "...g....",
        "...c....",
        "...g....",
        "...g....",
        "...c....",
    };
    static const char *const want[] = {
        "00010000",
        "00000000",
        "00010000",
        "00000000",
        "00000000",
        "00010000",
    };
    uint8_t ground[48];
    tcu_draw(&t, art, 6);
    memcpy(ground, t.ground, sizeof ground);
    run(art, 6, ground);
    expect_labels(want, 6);
    TEST_ASSERT_EQUAL_UINT32(3, lidet_cluster_stats(&g.ws)->n_candidates);
    /* without the mask the ground pixels (10 m, like the object) are part of it */
    run(art, 6, NULL);
    TEST_ASSERT_EQUAL_UINT32(6, lidet_cluster_stats(&g.ws)->n_pixels_kept);
    /* steps limited to 2: the gap of two ground rows (3 steps) is not bridged */
    cfg.max_steps = 2;
    run(art, 6, ground);
    TEST_ASSERT_EQUAL_UINT32(2, lidet_cluster_stats(&g.ws)->n_kept);
}

/* an object straddling the seam (columns 0 and cols-1) is one cluster, also across a hole */
static void test_wraparound_joins(void)
{
    static const char *const art[] = {
        "cc..........................z.cc",
        "c.............................cc",
        "cc....kk......................c.",
    };
    static const char *const want[] = {
        "11..........................2.11",
        "1.............................11",
        "11....33......................1.",
    };
    char w0[3][33];
    const char *want_digits[3];
    int r, c;
    for (r = 0; r < 3; ++r)
    {
        for (c = 0; c < 32; ++c)
            w0[r][c] = want[r][c] == '.' ? '0' : want[r][c];
        w0[r][32] = '\0';
        want_digits[r] = w0[r];
    }
    run(art, 3, NULL);
    expect_labels(want_digits, 3);
    TEST_ASSERT_EQUAL_UINT32(3, lidet_cluster_stats(&g.ws)->n_kept);
}

/* the regrowth (regrow_gap_m): two blocks, one at 5 m (a) and one at 7.5 m (b) beside it, chained by a loose gap
 * bound (2.6 m between them along the beams) into a component too wide for max_extent_m: grown again with a gap
 * that each block's own returns meet (0.5-0.74 m apart) and the jump does not, it gives the two blocks back */
static void test_regrow_over_extent(void)
{
    static const char *const art[] = {
        "..........aabb..................................................",
        "..........aabb..................................................",
        "..........aabb..................................................",
        "..........aabb..................................................",
    };
    static const char *const want[] = {
        "0000000000112200000000000000000000000000000000000000000000000000",
        "0000000000112200000000000000000000000000000000000000000000000000",
        "0000000000112200000000000000000000000000000000000000000000000000",
        "0000000000112200000000000000000000000000000000000000000000000000",
    };
    const lidet_cluster_stats_t *st;
    cfg.theta_rad = 0.1f;
    cfg.max_gap_m = 3.0f;
    cfg.max_extent_m = 2.0f;
    run(art, 4, NULL);
    st = lidet_cluster_stats(&g.ws);
    TEST_ASSERT_EQUAL_UINT32(1, st->n_dropped_extent); /* off: dropped */
    TEST_ASSERT_EQUAL_UINT32(0, st->n_kept);
    TEST_ASSERT_EQUAL_UINT32(0, st->n_regrown);
    cfg.regrow_gap_m = 0.8f;
    cfg.regrow_gap_per_m = 0.0f;
    run(art, 4, NULL);
    expect_labels(want, 4);
    st = lidet_cluster_stats(&g.ws);
    TEST_ASSERT_EQUAL_UINT32(1, st->n_regrown);
    TEST_ASSERT_EQUAL_UINT32(2, st->n_regrow_parts);
    TEST_ASSERT_EQUAL_UINT32(0, st->n_dropped_extent);
    TEST_ASSERT_EQUAL_UINT32(2, st->n_kept);
    /* a gap below the blocks' own spacing cuts b into its columns too: a (2 columns, 0.49 m apart at 5 m, but
     * 0.17 m between rows) stays whole */
    cfg.regrow_gap_m = 0.6f;
    run(art, 4, NULL);
    st = lidet_cluster_stats(&g.ws);
    TEST_ASSERT_EQUAL_UINT32(3, st->n_regrow_parts);
    TEST_ASSERT_EQUAL_UINT32(3, st->n_kept);
    /* too tall (the component spans 0.78 m in z) or too large (16 pixels): dropped as before */
    cfg.regrow_gap_m = 0.8f;
    cfg.regrow_max_height_m = 0.5f;
    run(art, 4, NULL);
    TEST_ASSERT_EQUAL_UINT32(1, lidet_cluster_stats(&g.ws)->n_dropped_extent);
    TEST_ASSERT_EQUAL_UINT32(0, lidet_cluster_stats(&g.ws)->n_regrown);
    cfg.regrow_max_height_m = 2.5f;
    cfg.regrow_max_pixels = 15u;
    run(art, 4, NULL);
    TEST_ASSERT_EQUAL_UINT32(1, lidet_cluster_stats(&g.ws)->n_dropped_extent);
    TEST_ASSERT_EQUAL_UINT32(0, lidet_cluster_stats(&g.ws)->n_kept);
    cfg.regrow_max_pixels = 16u;
    run(art, 4, NULL);
    TEST_ASSERT_EQUAL_UINT32(2, lidet_cluster_stats(&g.ws)->n_kept);
    /* bad values refused */
    cfg.regrow_gap_m = -1.0f;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_cluster_init(&g.ws, &cfg));
    cfg.regrow_gap_m = 0.8f;
    cfg.regrow_max_height_m = 0.0f;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_cluster_init(&g.ws, &cfg));
}

/* the regrowth's cut (regrow_cut_m): a block (a car, columns 10-11 at 5 m) standing on a kerb-high strip (the bottom
 * row, 20 columns at 5 m: 10 m long, 0.09 m above the plane z = 0) that chains it into a component too wide for
 * max_extent_m. The regrowth alone gives the same component back (the strip's returns are 0.49 m apart, inside its
 * gap bound): dropped. With the cut the pixels less than regrow_cut_m above the plane (the bottom row, 0.09 m; the
 * rows above are at 0.26 m and more) are left out and the block is kept; with the sector plane (lidet_plane_t) and
 * with the flat ground (no planes: z + mount_height_m) alike */
static void test_regrow_cut(void)
{
    static const char *const art[] = {
        "..........aa....................................................",
        "..........aa....................................................",
        "..........aa....................................................",
        "..........aaaaaaaaaaaaaaaaaaaa..................................",
    };
    static const char *const want[] = {
        "0000000000110000000000000000000000000000000000000000000000000000",
        "0000000000110000000000000000000000000000000000000000000000000000",
        "0000000000110000000000000000000000000000000000000000000000000000",
        "0000000000000000000000000000000000000000000000000000000000000000",
    };
    const lidet_plane_t plane = {0.0f, 0.0f, 1.0f, 0.0f};
    const lidet_cluster_stats_t *st;
    int with_plane;
    cfg.theta_rad = 0.1f;
    cfg.max_gap_m = 3.0f;
    cfg.max_extent_m = 2.0f;
    cfg.regrow_gap_m = 0.8f;
    cfg.regrow_gap_per_m = 0.0f;
    cfg.mount_height_m = 0.0f; /* the flat ground at z = 0 too */
    for (with_plane = 0; with_plane < 2; ++with_plane)
    {
        tcu_draw(&t, art, 4);
        cfg.regrow_cut_m = 0.0f;
        TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_cluster_init(&g.ws, &cfg));
        TEST_ASSERT_EQUAL_INT(LIDET_OK,
                              lidet_cluster_run(&g.ws, &t.img, NULL, with_plane ? &plane : NULL, with_plane ? 1 : 0));
        st = lidet_cluster_stats(&g.ws);
        TEST_ASSERT_EQUAL_UINT32(1, st->n_regrown);
        TEST_ASSERT_EQUAL_UINT32(1, st->n_regrow_parts); /* the same component again */
        TEST_ASSERT_EQUAL_UINT32(1, st->n_dropped_extent);
        TEST_ASSERT_EQUAL_UINT32(0, st->n_kept);
        cfg.regrow_cut_m = 0.2f;
        TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_cluster_init(&g.ws, &cfg));
        TEST_ASSERT_EQUAL_INT(LIDET_OK,
                              lidet_cluster_run(&g.ws, &t.img, NULL, with_plane ? &plane : NULL, with_plane ? 1 : 0));
        expect_labels(want, 4);
        st = lidet_cluster_stats(&g.ws);
        TEST_ASSERT_EQUAL_UINT32(1, st->n_regrown);
        TEST_ASSERT_EQUAL_UINT32(1, st->n_regrow_parts);
        TEST_ASSERT_EQUAL_UINT32(0, st->n_dropped_extent);
        TEST_ASSERT_EQUAL_UINT32(1, st->n_kept);
        TEST_ASSERT_EQUAL_UINT32(6, lidet_cluster_records(&g.ws, NULL)[0].n_points);
    }
    /* a cut as high as the block leaves nothing to regrow; bad values refused */
    cfg.regrow_cut_m = 2.0f;
    run(art, 4, NULL);
    TEST_ASSERT_EQUAL_UINT32(0, lidet_cluster_stats(&g.ws)->n_kept);
    TEST_ASSERT_EQUAL_UINT32(0, lidet_cluster_stats(&g.ws)->n_regrow_parts);
    cfg.regrow_cut_m = 2.01f;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_cluster_init(&g.ws, &cfg));
    cfg.regrow_cut_m = -0.01f;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_cluster_init(&g.ws, &cfg));
    cfg.regrow_cut_m = NAN;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_cluster_init(&g.ws, &cfg));
}

/* plane_split_m: planes holds the near and the far plane of each sector; a mean at or beyond the split is measured
 * against the far one (a block at 10 m: 5 m above the near plane here, 1 m above the far one) */
static void test_far_plane_height(void)
{
    static const char *const art[] = {
        "..............................cc................................",
        "..............................cc................................",
        "..............................cc................................",
    };
    const lidet_plane_t planes[2] = {{0.0f, 0.0f, 1.0f, 5.0f}, {0.0f, 0.0f, 1.0f, 0.0f}};
    cfg.max_mean_height_m = 2.5f;
    tcu_draw(&t, art, 3);
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_cluster_init(&g.ws, &cfg));
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_cluster_run(&g.ws, &t.img, NULL, planes, 1));
    TEST_ASSERT_EQUAL_UINT32(1, lidet_cluster_stats(&g.ws)->n_dropped_height); /* near plane only */
    cfg.plane_split_m = 8.0f;
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_cluster_init(&g.ws, &cfg));
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_cluster_run(&g.ws, &t.img, NULL, planes, 1));
    TEST_ASSERT_EQUAL_UINT32(1, lidet_cluster_stats(&g.ws)->n_kept);
    TEST_ASSERT_CLOSE(lidet_cluster_records(&g.ws, NULL)[0].mean_m[2], lidet_cluster_records(&g.ws, NULL)[0].height_m,
                      1e-5, 0);
    cfg.plane_split_m = 12.0f; /* the block lies nearer than the split */
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_cluster_init(&g.ws, &cfg));
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_cluster_run(&g.ws, &t.img, NULL, planes, 1));
    TEST_ASSERT_EQUAL_UINT32(0, lidet_cluster_stats(&g.ws)->n_kept);
    cfg.plane_split_m = -1.0f;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_cluster_init(&g.ws, &cfg));
}

/* filters: min points, extent, height; each dropped cluster counted once */
static void test_filters(void)
{
    static const char *const art[] = {
        "..cc.........a..................................................",
        "..cc.........a..........................................zzzzzzzz",
        "..cc.........a..................................................",
    };
    const lidet_cluster_stats_t *st;
    cfg.min_points = 4;
    run(art, 3, NULL);
    st = lidet_cluster_stats(&g.ws);
    TEST_ASSERT_EQUAL_UINT32(3, st->n_found);
    TEST_ASSERT_EQUAL_UINT32(1, st->n_dropped_small);
    TEST_ASSERT_EQUAL_UINT32(2, st->n_kept);
    /* the 8-pixel arc at 70 m spans ~ 8 * 5.6 deg: > 6 m wide */
    cfg.max_extent_m = 6.0f;
    run(art, 3, NULL);
    st = lidet_cluster_stats(&g.ws);
    TEST_ASSERT_EQUAL_UINT32(1, st->n_dropped_extent);
    TEST_ASSERT_EQUAL_UINT32(1, st->n_kept);
    TEST_ASSERT_EQUAL_UINT32(1, st->n_fragments); /* the 'a' column, rescued by nothing */
    /* flat ground 1.73 m below: the 10 m block's mean (row 1 at +5 deg: z ~ 0.87 m) is 2.6 m high;
     * the 'a' fragment (5 m: 2.17 m high) is dropped for height before the rescue */
    cfg.max_mean_height_m = 2.0f;
    run(art, 3, NULL);
    st = lidet_cluster_stats(&g.ws);
    TEST_ASSERT_EQUAL_UINT32(2, st->n_dropped_height);
    TEST_ASSERT_EQUAL_UINT32(0, st->n_fragments);
    TEST_ASSERT_EQUAL_UINT32(0, st->n_dropped_small);
    TEST_ASSERT_EQUAL_UINT32(0, st->n_kept);
    /* a tilted plane per sector: sector 0 says everything is low -> kept again */
    {
        lidet_plane_t planes[2] = {{0.0f, 0.0f, 1.0f, -5.0f}, {0.0f, 0.0f, 1.0f, 1.73f}};
        TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_cluster_run(&g.ws, &t.img, NULL, planes, 2));
        TEST_ASSERT_EQUAL_UINT32(1, lidet_cluster_stats(&g.ws)->n_kept);
        TEST_ASSERT_CLOSE(lidet_cluster_records(&g.ws, NULL)[0].mean_m[2] - 5.0f,
                          lidet_cluster_records(&g.ws, NULL)[0].height_m, 1e-5, 0);
        TEST_ASSERT_EQUAL_INT(LIDET_ERR_ARG, lidet_cluster_run(&g.ws, &t.img, NULL, planes, 0));
    }
}

/* set pixel p of the drawing to a return at range_m (same beam direction) */
static void set_range(int p, int cols, float range_m)
{
    const int r = p / cols, c = p % cols;
    const double az = M_PI * (1.0 - 2.0 * (c + 0.5) / cols), el = t.elev[r];
    t.x[p] = (float)((double)range_m * cos(el) * cos(az));
    t.y[p] = (float)((double)range_m * cos(el) * sin(az));
    t.z[p] = (float)((double)range_m * sin(el));
    t.r[p] = range_m;
    t.rxy[p] = (float)((double)range_m * cos(el));
}

/* Fragment rescue (256 columns, 1.4 deg each; theta 0.5 rad, no diagonals, no occluder bridging):
 *  - A: row 1, cols 100..109 at 10 m (kept); row 0 has 4 returns at 11 m at cols 100, 102, 104,
 *    106 (the far side seen through glass): they join each other (bridged holes) but fail the angle
 *    test to A (beta 0.33 < 0.5): a fragment of 4 (< min_points 6) about 1.06 m from A -> joins A;
 *  - B: row 2, cols 20..31 alternating 20 m / 21 m: every pixel a singleton for the angle test
 *    (beta 0.45), 1.1 m apart -> one rescue group of 12, a cluster of its own;
 *  - C: row 2, cols 200..202 at 30 m: a fragment of 3 with nothing near -> dropped. */
static void test_fragment_rescue(void)
{
    enum { COLS = 256, ROWS = 3 };
    static char rowbuf[ROWS][COLS + 1];
    const char *art[ROWS];
    const lidet_cluster_rec_t *rec;
    const lidet_cluster_stats_t *st;
    const uint16_t *lab;
    uint32_t n, i;
    int r, c;
    for (r = 0; r < ROWS; ++r)
    {
        memset(rowbuf[r], '.', COLS);
        rowbuf[r][COLS] = '\0';
        art[r] = rowbuf[r];
    }
    for (c = 100; c < 110; ++c)
        rowbuf[1][c] = 'c';
    for (c = 100; c <= 106; c += 2)
        rowbuf[0][c] = 'c';
    for (c = 20; c < 32; ++c)
        rowbuf[2][c] = 'c';
    for (c = 200; c < 203; ++c)
        rowbuf[2][c] = 'c';
    tcu_rescue_cfg(&cfg, 0.5f, 6, 0.8f, 0.03f);
    tcu_draw(&t, art, ROWS);
    for (c = 100; c <= 106; c += 2)
        set_range(c, COLS, 11.0f);
    for (c = 20; c < 32; ++c)
        set_range(2 * COLS + c, COLS, (c & 1) ? 21.0f : 20.0f);
    for (c = 200; c < 203; ++c)
        set_range(2 * COLS + c, COLS, 30.0f);

    /* without the rescue: A alone */
    cfg.rescue_gap_m = 0.0f;
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_cluster_init(&g.ws, &cfg));
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_cluster_run(&g.ws, &t.img, NULL, NULL, 0));
    st = lidet_cluster_stats(&g.ws);
    TEST_ASSERT_EQUAL_UINT32(1, st->n_kept);
    TEST_ASSERT_EQUAL_UINT32(15, st->n_found); /* A, the 11 m fragment, 12 singletons, C */
    TEST_ASSERT_EQUAL_UINT32(14, st->n_dropped_small);
    TEST_ASSERT_EQUAL_UINT32(0, st->n_fragments);
    TEST_ASSERT_EQUAL_UINT32(10, lidet_cluster_records(&g.ws, NULL)[0].n_points);

    cfg.rescue_gap_m = 0.8f;
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_cluster_init(&g.ws, &cfg));
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_cluster_run(&g.ws, &t.img, NULL, NULL, 0));
    st = lidet_cluster_stats(&g.ws);
    lab = lidet_cluster_labels(&g.ws);
    rec = lidet_cluster_records(&g.ws, &n);
    TEST_ASSERT_EQUAL_UINT32(15, st->n_found);
    TEST_ASSERT_EQUAL_UINT32(14, st->n_fragments);
    TEST_ASSERT_EQUAL_UINT32(1, st->n_rescue_joined);
    TEST_ASSERT_EQUAL_UINT32(16, st->n_rescue_pixels);
    TEST_ASSERT_EQUAL_UINT32(1, st->n_dropped_small); /* C */
    TEST_ASSERT_EQUAL_UINT32(2, n);
    /* ids in raster order of the first pixel: A's rescued pixel (0, 100) is its first, before B's
     * (2, 20): A = 1, B = 2 (without the rescue A's first pixel was (1, 100)) */
    TEST_ASSERT_EQUAL_UINT32(14, rec[0].n_points);
    TEST_ASSERT_EQUAL_UINT32(4, rec[0].n_rescued);
    TEST_ASSERT_EQUAL_UINT32(100, rec[0].seed_pixel);
    TEST_ASSERT_EQUAL_UINT32(12, rec[1].n_points);
    TEST_ASSERT_EQUAL_UINT32(12, rec[1].n_rescued);
    TEST_ASSERT_EQUAL_UINT32(2 * COLS + 20, rec[1].seed_pixel);
    for (c = 100; c <= 106; c += 2)
        TEST_ASSERT_EQUAL_UINT16(1, lab[c]);
    for (c = 20; c < 32; ++c)
        TEST_ASSERT_EQUAL_UINT16(2, lab[2 * COLS + c]);
    for (c = 200; c < 203; ++c)
        TEST_ASSERT_EQUAL_UINT16(0, lab[2 * COLS + c]);
    /* A's record covers its 14 members: bounds and mean */
    {
        double s[3] = {0, 0, 0};
        const int32_t *mem = lidet_cluster_members(&g.ws);
        for (i = 0; i < rec[0].n_points; ++i)
        {
            const int32_t p = mem[rec[0].first_member + i];
            TEST_ASSERT_EQUAL_UINT16(1, lab[p]);
            s[0] += (double)t.x[p];
            s[1] += (double)t.y[p];
            s[2] += (double)t.z[p];
            TEST_ASSERT_TRUE(t.x[p] >= rec[0].min_m[0] && t.x[p] <= rec[0].max_m[0]);
            TEST_ASSERT_TRUE(t.y[p] >= rec[0].min_m[1] && t.y[p] <= rec[0].max_m[1]);
            TEST_ASSERT_TRUE(t.z[p] >= rec[0].min_m[2] && t.z[p] <= rec[0].max_m[2]);
        }
        for (i = 0; i < 3; ++i)
            TEST_ASSERT_CLOSE(s[i] / 14.0, rec[0].mean_m[i], 1e-4, 1e-5);
        TEST_ASSERT_CLOSE(rec[0].mean_m[2] + cfg.mount_height_m, rec[0].height_m, 1e-5, 0);
    }
    /* a smaller rescue distance (0.5 m) rescues nothing here */
    cfg.rescue_gap_m = 0.5f;
    cfg.rescue_gap_per_m = 0.0f;
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_cluster_init(&g.ws, &cfg));
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_cluster_run(&g.ws, &t.img, NULL, NULL, 0));
    TEST_ASSERT_EQUAL_UINT32(0, lidet_cluster_stats(&g.ws)->n_rescue_pixels);
    TEST_ASSERT_EQUAL_UINT32(1, lidet_cluster_stats(&g.ws)->n_kept);
}

/* records: counts, bounds, means and member lists agree with the labels; determinism */
static void test_records_members_determinism(void)
{
    static const char *const art[] = {
        "....kk.......c..........a.a.a.a.",
        "...ckk.......c..........aaaaaaa.",
        "...cc........c..........a.....a.",
    };
    uint16_t first[96];
    uint32_t n, i, j, total = 0;
    const lidet_cluster_rec_t *rec;
    const int32_t *mem;
    run(art, 3, NULL);
    memcpy(first, lidet_cluster_labels(&g.ws), sizeof first);
    rec = lidet_cluster_records(&g.ws, &n);
    mem = lidet_cluster_members(&g.ws);
    TEST_ASSERT_EQUAL_UINT32(4, n);
    for (i = 0; i < n; ++i)
    {
        double s[3] = {0, 0, 0};
        TEST_ASSERT_EQUAL_UINT32(total, rec[i].first_member);
        for (j = 0; j < rec[i].n_points; ++j)
        {
            const int32_t p = mem[rec[i].first_member + j];
            TEST_ASSERT_EQUAL_UINT16(i + 1, first[p]);
            if (j > 0)
            {
                TEST_ASSERT_TRUE(p > mem[rec[i].first_member + j - 1]); /* raster order */
            }
            else
            {
                TEST_ASSERT_EQUAL_UINT32((uint32_t)p, rec[i].seed_pixel);
            }
            s[0] += (double)t.x[p];
            s[1] += (double)t.y[p];
            s[2] += (double)t.z[p];
            TEST_ASSERT_TRUE(t.x[p] >= rec[i].min_m[0] && t.x[p] <= rec[i].max_m[0]);
            TEST_ASSERT_TRUE(t.z[p] >= rec[i].min_m[2] && t.z[p] <= rec[i].max_m[2]);
        }
        TEST_ASSERT_CLOSE(s[0] / rec[i].n_points, rec[i].mean_m[0], 1e-4, 1e-5);
        TEST_ASSERT_CLOSE(s[2] / rec[i].n_points, rec[i].mean_m[2], 1e-4, 1e-5);
        total += rec[i].n_points;
    }
    TEST_ASSERT_EQUAL_UINT32(total, lidet_cluster_stats(&g.ws)->n_pixels_kept);
    /* ids in raster order of first pixel: 'k' block (row 0 col 4) = 1, 'c' (row 0 col 13) = 2,
     * 'a' comb = 3, the left 'c' L-shape (row 1 col 3) = 4 */
    TEST_ASSERT_EQUAL_UINT16(1, first[4]);
    TEST_ASSERT_EQUAL_UINT16(2, first[13]);
    TEST_ASSERT_EQUAL_UINT16(3, first[24]);
    TEST_ASSERT_EQUAL_UINT16(4, first[32 + 3]);
    TEST_ASSERT_EQUAL_UINT32(13, rec[2].n_points);
    /* a second run on the same input gives the same bytes */
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_cluster_run(&g.ws, &t.img, NULL, NULL, 0));
    TEST_ASSERT_EQUAL_MEMORY(first, lidet_cluster_labels(&g.ws), sizeof first);
}

/* per-point labels: every input point in input order; unprojected points 0 */
static void test_point_labels(void)
{
    static const char *const art[] = {
        "..cc....kk..",
    };
    int32_t pp[6] = {2, 3, 8, -1, 2, 1000};
    uint32_t out[6];
    run(art, 1, NULL);
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_cluster_point_labels(&g.ws, pp, 6, out));
    TEST_ASSERT_EQUAL_UINT32(1, out[0]);
    TEST_ASSERT_EQUAL_UINT32(1, out[1]);
    TEST_ASSERT_EQUAL_UINT32(2, out[2]);
    TEST_ASSERT_EQUAL_UINT32(0, out[3]);
    TEST_ASSERT_EQUAL_UINT32(1, out[4]);
    TEST_ASSERT_EQUAL_UINT32(0, out[5]);
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_ARG, lidet_cluster_point_labels(&g.ws, NULL, 6, out));
}

/* empty image, all ground, bad config, not initialised */
static void test_edge_cases(void)
{
    static const char *const empty[] = {"........", "........"};
    static const char *const allg[] = {"gggggggg", "gggggggg"};
    lidet_cluster_cfg_t bad;
    uint8_t ground[16];
    run(empty, 2, NULL);
    TEST_ASSERT_EQUAL_UINT32(0, lidet_cluster_stats(&g.ws)->n_found);
    tcu_draw(&t, allg, 2);
    memcpy(ground, t.ground, sizeof ground);
    run(allg, 2, ground);
    TEST_ASSERT_EQUAL_UINT32(0, lidet_cluster_stats(&g.ws)->n_candidates);
    bad = cfg;
    bad.theta_rad = 0.0f;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_cluster_init(&g.ws, &bad));
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_STATE, lidet_cluster_run(&g.ws, &t.img, NULL, NULL, 0));
    bad = cfg;
    bad.max_steps = LIDET_CLUSTER_MAX_STEPS + 1;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_cluster_init(&g.ws, &bad));
    bad = cfg;
    bad.min_points = 0;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_cluster_init(&g.ws, &bad));
    bad = cfg;
    bad.rescue_gap_m = -0.1f;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_cluster_init(&g.ws, &bad));
    bad = cfg;
    bad.rescue_gap_per_m = NAN;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_cluster_init(&g.ws, &bad));
    bad = cfg;
    bad.rescue_cols = 16;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_cluster_init(&g.ws, &bad));
    bad = cfg;
    bad.rescue_rows = LIDET_MAX_ROWS + 1;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_cluster_init(&g.ws, &bad));
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_ARG, lidet_cluster_init(NULL, &cfg));
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_cluster_init(&g.ws, &cfg));
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_ARG, lidet_cluster_run(&g.ws, NULL, NULL, NULL, 0));
    TEST_ASSERT_EQUAL_UINT32(sizeof(lidet_cluster_t), lidet_cluster_bytes());
}

/* default thresholds per profile */
static void test_defaults_per_profile(void)
{
    lidet_cluster_cfg_t d;
    lidet_cluster_cfg_default(&d, lidet_sensor_find("hdl64"));
    TEST_ASSERT_EQUAL_UINT32(8, d.min_points);
    TEST_ASSERT_EQUAL_UINT32(5, d.max_steps);
    TEST_ASSERT_EQUAL_UINT32(1, d.bridge_occluders);
    TEST_ASSERT_EQUAL_UINT32(1, d.diagonals);
    TEST_ASSERT_CLOSE(1.73, d.mount_height_m, 1e-3, 0);
    TEST_ASSERT_TRUE(d.theta_rad > 0.0f && d.theta_rad < 0.8f);
    TEST_ASSERT_TRUE(d.max_gap_m > 0.0f && d.max_gap_per_m > 0.0f);
    TEST_ASSERT_TRUE(d.rescue_gap_m > 0.0f);
    TEST_ASSERT_EQUAL_UINT32(2, d.rescue_rows);
    TEST_ASSERT_CLOSE(0.8, d.rescue_gap_m, 1e-6, 0);
    TEST_ASSERT_CLOSE(0.7, d.split_min_width_m, 1e-6, 0);
    TEST_ASSERT_EQUAL_UINT32(2, d.person_min_cols);
    TEST_ASSERT_CLOSE(0.5, d.join_gap_m, 1e-6, 0);
    TEST_ASSERT_EQUAL_UINT32(10, d.person_min_points);
    /* <= 16 beams (issue 15, measured on simulated VLP-16 crowd scenes: lidet_cluster.h) */
    lidet_cluster_cfg_default(&d, lidet_sensor_find("vlp16"));
    TEST_ASSERT_EQUAL_UINT32(1, d.rescue_rows);
    TEST_ASSERT_TRUE(d.theta_rad > 0.0f && d.theta_rad < 0.8f);
    TEST_ASSERT_EQUAL_UINT32(5, d.max_steps);
    TEST_ASSERT_EQUAL_UINT32(8, d.min_points);
    TEST_ASSERT_EQUAL_UINT32(9, d.person_min_points);
    TEST_ASSERT_CLOSE(1.0, d.rescue_gap_m, 1e-6, 0);
    TEST_ASSERT_CLOSE(0.7, d.split_min_width_m, 1e-6, 0);
    TEST_ASSERT_CLOSE(0.8, d.join_gap_m, 1e-6, 0);
    TEST_ASSERT_EQUAL_UINT32(0, d.bridge_occluders);
    TEST_ASSERT_TRUE(d.max_gap_m > 0.0f && d.max_gap_per_m > 0.0f);
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_cluster_init(&g.ws, &d));
}

/* the resampling rule: deterministic, in range, every member once when small, one member of each stratum when large,
 * chosen by the members' pixels */
static void test_proposal_indices(void)
{
    static lidet_member_t pix[1001];
    uint32_t a[128], b[128], i, same;
    uint8_t seen[1000];
    static const uint32_t golden[8] = {1, 16, 34, 38, 54, 70, 81, 88};
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_proposal_indices(0, 10, 64, 7, a)); /* pixels not read */
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_proposal_indices(0, 10, 64, 7, b));
    TEST_ASSERT_EQUAL_MEMORY(a, b, 64 * sizeof a[0]);
    for (i = 0; i < 10; ++i)
        TEST_ASSERT_EQUAL_UINT32(i, a[i]);
    for (i = 0; i < 64; ++i)
        TEST_ASSERT_TRUE(a[i] < 10);
    for (i = 0; i < 1001; ++i)
        pix[i] = (lidet_member_t)(3u * i + 7u);
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_proposal_indices(pix, 1000, 128, 7, a));
    memset(seen, 0, sizeof seen);
    for (i = 0; i < 128; ++i)
    {
        TEST_ASSERT_TRUE(a[i] < 1000);
        TEST_ASSERT_EQUAL_UINT8(0, seen[a[i]]);
        seen[a[i]] = 1;
        TEST_ASSERT_TRUE(a[i] >= i * 1000 / 128 && a[i] < (i + 1) * 1000 / 128);
    }
    /* another seed gives another pattern */
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_proposal_indices(pix, 1000, 128, 8, b));
    TEST_ASSERT_TRUE(memcmp(a, b, 128 * sizeof a[0]) != 0);
    /* one pixel more at the end: every stratum past the first few moves, yet most picks keep their pixel */
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_proposal_indices(pix, 1001, 128, 7, b));
    for (i = 0, same = 0; i < 128; ++i)
        same += pix[a[i]] == pix[b[i]];
    TEST_ASSERT_TRUE(same >= 110u); /* 116; the earlier draw kept 11 */
    /* and one pixel more at the front (pixel 1, below the others): every member's index moves by one as well */
    {
        static lidet_member_t front[1001];
        front[0] = 1;
        memcpy(front + 1, pix, 1000 * sizeof pix[0]);
        TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_proposal_indices(front, 1001, 128, 7, b));
        for (i = 0, same = 0; i < 128; ++i)
            same += pix[a[i]] == front[b[i]];
        TEST_ASSERT_TRUE(same >= 96u); /* 108 (codegen/lidet_ref); the earlier draw by the member count kept 10 */
    }
    /* golden values (codegen/lidet_ref/cluster.py: proposal_indices gives the same): pixels 11, 16, ..., 506 */
    for (i = 0; i < 100; ++i)
        pix[i] = (lidet_member_t)(5u * i + 11u);
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_proposal_indices(pix, 100, 8, 0x5EED1234u, a));
    TEST_ASSERT_EQUAL_UINT32_ARRAY(golden, a, 8);
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_proposal_indices(0, 5, 8, 0x5EED1234u, a));
    TEST_ASSERT_EQUAL_UINT32(0, a[0]);
    TEST_ASSERT_EQUAL_UINT32(4, a[4]);
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_ARG, lidet_proposal_indices(pix, 0, 8, 1, a));
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_ARG, lidet_proposal_indices(pix, 5, 0, 1, a));
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_ARG,
                          lidet_proposal_indices(0, 100, 8, 1, a)); /* a large cluster needs them */
}

/* the member of pix[lo .. hi - 1] whose pixel has the smallest key, by the definition */
static uint32_t smallest_key(const lidet_member_t *pix, uint32_t lo, uint32_t hi, uint32_t seed)
{
    uint32_t best = lo, m;
    for (m = lo + 1u; m < hi; ++m)
        if (lidet__proposal_key(seed, (uint32_t)pix[m]) < lidet__proposal_key(seed, (uint32_t)pix[best]))
            best = m;
    return best;
}

/* a large cluster's member indices (on SIMD hosts the keys of 256 members at a time, elsewhere one pass per stratum:
 * lidet_proposal_q.c) are, stratum by stratum, the member with the smallest key: cluster sizes around the chunk's,
 * keys from every part of the range; and lidet__proposal_pick alone on strata of every length up to 200 */
static void test_proposal_pick_is_the_smallest_key(void)
{
    static lidet_member_t pix[1100];
    uint32_t len, b0, i, seed = 0x5EED1234u, trial, idx[LIDET_PROPOSAL_POINTS];
    static const uint32_t sizes[] = {65, 100, 255, 256, 257, 511, 513, 1024, 1100};
    for (trial = 0; trial < 4u; ++trial)
    {
        for (i = 0; i < 1100u; ++i)
            pix[i] = (lidet_member_t)((i * 2654435761u + trial * 977u) % 60000u);
        for (len = 1; len <= 200u; ++len)
        {
            for (b0 = 0; b0 + len <= 400u; b0 += 37u)
                TEST_ASSERT_EQUAL_UINT32(smallest_key(pix, b0, b0 + len, seed),
                                         lidet__proposal_pick(pix, b0, b0 + len, seed));
        }
        for (i = 0; i < sizeof sizes / sizeof sizes[0]; ++i)
        {
            const uint32_t n_src = sizes[i], n_out = 64u;
            uint32_t k;
            TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_proposal_indices(pix, n_src, n_out, seed, idx));
            for (k = 0; k < n_out; ++k)
                TEST_ASSERT_EQUAL_UINT32(smallest_key(pix, k * n_src / n_out, (k + 1u) * n_src / n_out, seed), idx[k]);
        }
        seed = seed * 747796405u + 1u;
    }
    /* the strata's bounds walked without divisions: floor(i n_src / n_out), at small and large counts */
    {
        static const uint32_t big[] = {65535u, 65536u, 131072u, 1000003u, 4000000000u};
        uint32_t n_out, n_src, k;
        for (n_out = 1; n_out <= 130u; n_out += 3u)
        {
            for (k = 0; k < 6u + sizeof big / sizeof big[0]; ++k)
            {
                lidet__strata_t st;
                n_src = k < 6u ? n_out + 1u + k * 97u : big[k - 6u];
                if (n_src <= n_out)
                    continue;
                lidet__strata_init(&st, n_src, n_out);
                TEST_ASSERT_EQUAL_UINT32(0, st.b);
                for (i = 1; i <= n_out; ++i)
                    TEST_ASSERT_EQUAL_UINT32((uint32_t)((uint64_t)i * n_src / n_out), lidet__strata_next(&st));
            }
        }
    }
    /* the key: a bijection of the pixel (no ties), MurmurHash3's finaliser of seed ^ (p * 0x9E3779B9) */
    TEST_ASSERT_EQUAL_UINT32(4066478028u, lidet__proposal_key(0x5EED1234u, 0u));
    TEST_ASSERT_EQUAL_UINT32(1913050917u, lidet__proposal_key(0x5EED1234u, 1u));
    TEST_ASSERT_EQUAL_UINT32(2599926878u, lidet__proposal_key(0x5EED1234u, 11u));
}

/* proposals: centred on the cluster mean, deterministic, voxel of the mean */
static void test_proposal_centred(void)
{
    static const char *const art[] = {
        "..........................cccc..",
        "..........................cccc..",
        "..........................cccc..",
        "..........................cccc..",
    };
    lidet_proposal_cfg_t pc;
    static lidet_proposal_t a, b;
    const lidet_cluster_rec_t *rec;
    double s[3] = {0, 0, 0}, az, el, rr;
    uint32_t i;
    run(art, 4, NULL);
    rec = lidet_cluster_records(&g.ws, NULL);
    lidet_proposal_cfg_default(&pc);
    TEST_ASSERT_EQUAL_UINT32(64, pc.n_points);
    pc.n_points = 16; /* = the cluster's size: every member exactly once */
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_proposal_make(&g.ws, 0, &pc, &a));
    TEST_ASSERT_EQUAL_UINT32(16, a.n_points_src);
    for (i = 0; i < 16; ++i)
    {
        s[0] += (double)a.xyz[i][0];
        s[1] += (double)a.xyz[i][1];
        s[2] += (double)a.xyz[i][2];
    }
    TEST_ASSERT_CLOSE(0.0, s[0] / 16, 1e-5, 0);
    TEST_ASSERT_CLOSE(0.0, s[1] / 16, 1e-5, 0);
    TEST_ASSERT_CLOSE(0.0, s[2] / 16, 1e-5, 0);
    for (i = 0; i < 3; ++i)
        TEST_ASSERT_EQUAL_FLOAT(rec[0].mean_m[i], a.mean_m[i]);
    /* 64 points: deterministic, every point a member minus the mean */
    pc.n_points = 64;
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_proposal_make(&g.ws, 0, &pc, &a));
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_proposal_make(&g.ws, 0, &pc, &b));
    TEST_ASSERT_EQUAL_MEMORY(&a, &b, sizeof a);
    for (i = 0; i < 64; ++i)
    {
        const double x = a.xyz[i][0] + a.mean_m[0], y = a.xyz[i][1] + a.mean_m[1];
        const double rxy = sqrt(x * x + y * y);
        TEST_ASSERT_CLOSE(10.0 * cos(atan2(a.xyz[i][2] + a.mean_m[2], rxy)), rxy, 1e-4, 0);
    }
    /* the voxel of the mean: signed floor bins */
    az = atan2(a.mean_m[1], a.mean_m[0]);
    el = atan2(a.mean_m[2], sqrt((double)a.mean_m[0] * (double)a.mean_m[0] + (double)a.mean_m[1] * (double)a.mean_m[1]));
    rr = sqrt((double)a.mean_m[0] * (double)a.mean_m[0] + (double)a.mean_m[1] * (double)a.mean_m[1] +
              (double)a.mean_m[2] * (double)a.mean_m[2]);
    TEST_ASSERT_EQUAL_INT16((int16_t)floor(az / (10.0 * M_PI / 180.0)), a.voxel[0]);
    TEST_ASSERT_EQUAL_INT16((int16_t)floor(el / (10.0 * M_PI / 180.0)), a.voxel[1]);
    TEST_ASSERT_EQUAL_INT16((int16_t)floor(rr), a.voxel[2]);
    TEST_ASSERT_TRUE(a.voxel[0] < 0); /* right of +x: negative azimuth */
    /* z from the ground under the mean: the same points, shifted up by the record's height; the same voxel */
    TEST_ASSERT_EQUAL_UINT32(LIDET_PROPOSAL_Z_MEAN, pc.z_origin);
    pc.z_origin = LIDET_PROPOSAL_Z_GROUND;
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_proposal_make(&g.ws, 0, &pc, &b));
    TEST_ASSERT_TRUE(rec[0].height_m > 0.5f);
    TEST_ASSERT_EQUAL_FLOAT(rec[0].mean_m[2] - rec[0].height_m, b.mean_m[2]);
    TEST_ASSERT_EQUAL_MEMORY(a.voxel, b.voxel, sizeof a.voxel);
    for (i = 0; i < 64; ++i)
    {
        TEST_ASSERT_EQUAL_FLOAT(a.xyz[i][0], b.xyz[i][0]);
        TEST_ASSERT_EQUAL_FLOAT(a.xyz[i][1], b.xyz[i][1]);
        TEST_ASSERT_CLOSE(a.xyz[i][2] + rec[0].height_m, b.xyz[i][2], 1e-5, 0);
        TEST_ASSERT_CLOSE(a.xyz[i][2] + a.mean_m[2], b.xyz[i][2] + b.mean_m[2], 1e-5, 0);
    }
    /* errors */
    pc.z_origin = LIDET_PROPOSAL_Z_GROUND + 1;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_proposal_make(&g.ws, 0, &pc, &a));
    pc.z_origin = LIDET_PROPOSAL_Z_MEAN;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_ARG, lidet_proposal_make(&g.ws, 1, &pc, &a));
    pc.n_points = LIDET_PROPOSAL_POINTS + 1;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_CONFIG, lidet_proposal_make(&g.ws, 0, &pc, &a));
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_depth_jump_splits);
    RUN_TEST(test_slanted_surface_joins);
    RUN_TEST(test_hole_joins);
    RUN_TEST(test_occluder_bridging);
    RUN_TEST(test_diagonals);
    RUN_TEST(test_max_gap);
    RUN_TEST(test_vertical_hole_and_ground);
    RUN_TEST(test_wraparound_joins);
    RUN_TEST(test_filters);
    RUN_TEST(test_regrow_over_extent);
    RUN_TEST(test_regrow_cut);
    RUN_TEST(test_far_plane_height);
    RUN_TEST(test_fragment_rescue);
    RUN_TEST(test_records_members_determinism);
    RUN_TEST(test_point_labels);
    RUN_TEST(test_edge_cases);
    RUN_TEST(test_defaults_per_profile);
    RUN_TEST(test_proposal_indices);
    RUN_TEST(test_proposal_pick_is_the_smallest_key);
    RUN_TEST(test_proposal_centred);
    return UNITY_END();
}
