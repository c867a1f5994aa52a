/* SPDX-License-Identifier: MIT */
/* Unity tests of the PointNet forward pass (lib/src/pointnet/lidet_pointnet.c, lib/src/nn/lidet_nn_f32.c) on
 * hand-made tiny models whose outputs are worked out by hand, a random model against a naive double
 * loop (block and tile edges), and malformed descriptors. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "internal/lidet_proposal_rule.h"
#include "lidet/lidet.h"
#include "test_util.h"

#define SCRATCH_FLOATS 8192
typedef struct
{
    float f[SCRATCH_FLOATS];
} scratch_t;
LIDET_GUARDED(scratch_t, g_scratch);
LIDET_GUARDED(lidet_pn_t, g_pn);

void setUp(void)
{
    CANARY_FILL(g_scratch);
    CANARY_FILL(g_pn);
}

void tearDown(void)
{
    CANARY_CHECK(g_scratch);
    CANARY_CHECK(g_pn);
}

/* ---- a hand-made classifier ------------------------------------------------------------------
 * point layer 3 -> 2: (x, y) with ReLU; max over points -> g = (max x, max y)
 * PVLE 3 -> 1: the range bin (ReLU); head [g0, g1, p] -> 3 logits: (g0, g1, p) minus (0, 0, 10) */
static const float c_p0_w[3 * 2] = {1, 0, /* in x */ 0, 1, /* in y */ 0, 0 /* in z */};
static const float c_p0_b[2] = {0, 0};
static const float c_v0_w[3 * 1] = {0, 0, 1};
static const float c_v0_b[1] = {0};
static const float c_h0_w[3 * 3] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
static const float c_h0_b[3] = {0, 0, -10};
static const lidet_pn_layer_t c_point[1] = {{3, 2, 1, c_p0_w, c_p0_b}};
static const lidet_pn_layer_t c_pvle[1] = {{3, 1, 1, c_v0_w, c_v0_b}};
static const lidet_pn_layer_t c_head[1] = {{3, 3, 0, c_h0_w, c_h0_b}};

static lidet_pn_model_t tiny_classifier(void)
{
    lidet_pn_model_t m;
    memset(&m, 0, sizeof m);
    m.format_version = LIDET_WEIGHTS_FORMAT_VERSION;
    m.kind = LIDET_PN_CLASSIFIER;
    m.precision = LIDET_PN_F32;
    m.n_stages = 1;
    m.n_classes = LIDET_N_CLASSES;
    m.n_points = 4;
    m.stage[0].point = c_point;
    m.stage[0].pvle = c_pvle;
    m.stage[0].head = c_head;
    m.stage[0].n_point = 1;
    m.stage[0].n_pvle = 1;
    m.stage[0].n_head = 1;
    m.energy_t = 1.0f;
    m.gamma[0] = m.gamma[1] = m.gamma[2] = -1.0f;
    m.name = "tiny";
    m.class_names = "Car,Cyclist,Pedestrian";
    return m;
}

static void init_ok(const lidet_pn_model_t *m)
{
    uint32_t need = 0;
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_pn_init(&g_pn.ws, m, g_scratch.ws.f, sizeof g_scratch.ws.f, &need));
    TEST_ASSERT_EQUAL_UINT32(lidet_pn_scratch_bytes(m), need);
}

void test_classifier_by_hand(void)
{
    static lidet_pn_model_t m;
    lidet_proposal_t p;
    lidet_pn_class_out_t o;
    float e;
    m = tiny_classifier();
    init_ok(&m);
    memset(&p, 0, sizeof p);
    /* mean on +x: the model frame equals the sensor frame (azimuth 0) */
    p.mean_m[0] = 12.0f;
    p.n_points = 4;
    p.xyz[0][0] = 1.0f;
    p.xyz[1][1] = 2.0f;
    p.xyz[2][0] = -3.0f;
    p.xyz[3][2] = 5.0f;
    p.voxel[2] = 12; /* range bin */
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_pn_classify(&g_pn.ws, &p, &o));
    TEST_ASSERT_CLOSE(1.0, o.logits[0], 1e-6, 0);
    TEST_ASSERT_CLOSE(2.0, o.logits[1], 1e-6, 0);
    TEST_ASSERT_CLOSE(2.0, o.logits[2], 1e-6, 0); /* 12 - 10 */
    e = -(2.0f + logf(expf(-1.0f) + 1.0f + 1.0f));
    TEST_ASSERT_CLOSE(e, o.energy, 1e-5, 0);
    TEST_ASSERT_EQUAL_UINT8(LIDET_CLASS_CYCLIST, o.cls); /* first of the tied maxima */
    TEST_ASSERT_CLOSE(expf(1.0f + e), o.prob[0], 1e-6, 1e-5);
    TEST_ASSERT_CLOSE(1.0, o.prob[0] + o.prob[1] + o.prob[2], 1e-6, 0);
    TEST_ASSERT_EQUAL_UINT8(1, o.pass); /* e = -3.55 < -1 */

    /* mean on +y (azimuth 90 deg): the model frame turns (x, y) into (y, -x) */
    p.mean_m[0] = 0.0f;
    p.mean_m[1] = 12.0f;
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_pn_classify(&g_pn.ws, &p, &o));
    TEST_ASSERT_CLOSE(2.0, o.logits[0], 1e-6, 0); /* max y = 2 */
    TEST_ASSERT_CLOSE(3.0, o.logits[1], 1e-6, 0); /* max -x = 3 */
    m.gamma[LIDET_CLASS_CYCLIST] = -10.0f;
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_pn_classify(&g_pn.ws, &p, &o));
    TEST_ASSERT_EQUAL_UINT8(0, o.pass);
}

void test_energy_is_stable(void)
{
    const float big[3] = {1000.0f, 1000.0f, -1000.0f};
    const float v[2] = {0.5f, -0.25f};
    TEST_ASSERT_CLOSE(-(1000.0 + log(2.0)), lidet_pn_energy(big, 3, 1.0f), 1e-3, 0);
    TEST_ASSERT_CLOSE(-2.0 * log(exp(0.25) + exp(-0.125)), lidet_pn_energy(v, 2, 2.0f), 1e-6, 0);
    TEST_ASSERT_CLOSE(0.0, lidet_pn_energy(v, 0, 1.0f), 0, 0);
}

/* ---- a hand-made box net ------------------------------------------------------------------------
 * H = 2 heading bins, S = 1 size template. T-Net: points (no ReLU) -> max -> [g | onehot] -> g:
 * centre = (max x, max y, max z) of the model-frame points. Box stage: constant outputs from biases. */
static const float b_tp_w[3 * 3] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
static const float b_tp_b[3] = {0, 0, 0};
static const float b_th_w[6 * 3] = {1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 0, 0, 0, 0, 0, 0};
static const float b_th_b[3] = {0, 0, 0};
static float b_bp_w[3 * 2];
static const float b_bp_b[2] = {0, 0};
static float b_bh_w[5 * 11];
/* centre residual, heading scores (bin 1 wins), heading residuals, size score, size residual */
static float b_bh_b[11] = {0.5f, -0.25f, 1.0f, 0.0f,  3.0f, 0.0f,
                           0.5f, 2.0f,   0.1f, -0.5f, 0.0f}; /* [6]: see below */
static const float b_size[3] = {4.0f, 2.0f, 1.5f};
static const lidet_pn_layer_t b_tpoint[1] = {{3, 3, 0, b_tp_w, b_tp_b}};
static const lidet_pn_layer_t b_thead[1] = {{6, 3, 0, b_th_w, b_th_b}};
static const lidet_pn_layer_t b_bpoint[1] = {{3, 2, 1, b_bp_w, b_bp_b}};
static const lidet_pn_layer_t b_bhead[1] = {{5, 11, 0, b_bh_w, b_bh_b}};

static lidet_pn_model_t tiny_box(void)
{
    lidet_pn_model_t m;
    memset(&m, 0, sizeof m);
    m.format_version = LIDET_WEIGHTS_FORMAT_VERSION;
    m.kind = LIDET_PN_BOX;
    m.precision = LIDET_PN_F32;
    m.n_stages = 2;
    m.n_classes = LIDET_N_CLASSES;
    m.n_points = 3;
    m.n_heading_bins = 2;
    m.n_size_clusters = 1;
    m.stage[0].point = b_tpoint;
    m.stage[0].head = b_thead;
    m.stage[0].n_point = 1;
    m.stage[0].n_head = 1;
    m.stage[0].use_onehot = 1;
    m.stage[1].point = b_bpoint;
    m.stage[1].head = b_bhead;
    m.stage[1].n_point = 1;
    m.stage[1].n_head = 1;
    m.stage[1].use_onehot = 1;
    m.mean_size_m = b_size;
    m.energy_t = 1.0f;
    m.gamma[0] = m.gamma[1] = m.gamma[2] = 0.0f;
    m.name = "tinybox";
    return m;
}

void test_box_by_hand(void)
{
    static lidet_pn_model_t m;
    lidet_proposal_t p;
    lidet_pn_box_out_t o;
    float raw[3 + 11];
    const float onehot[3] = {0, 1, 0};
    const float vox[3] = {0, 0, 0};
    const float pts[9] = {1, 2, 3, -1, 0, 0, 0, -2, 1};
    const double pi = 3.14159265358979;
    double eh, es, yaw;
    m = tiny_box();
    init_ok(&m);
    /* raw outputs on model-frame points: T-Net centre = per-axis max */
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_pn_forward(&g_pn.ws, pts, 3, vox, onehot, raw, 14));
    TEST_ASSERT_CLOSE(1.0, raw[0], 1e-6, 0);
    TEST_ASSERT_CLOSE(2.0, raw[1], 1e-6, 0);
    TEST_ASSERT_CLOSE(3.0, raw[2], 1e-6, 0);
    TEST_ASSERT_CLOSE(0.5, raw[3], 1e-6, 0);
    TEST_ASSERT_CLOSE(0.0, raw[13], 1e-6, 0);

    /* decoded: mean at azimuth 90 deg, so model (x, y) -> sensor (-y, x) */
    memset(&p, 0, sizeof p);
    p.n_points = 3;
    p.mean_m[1] = 10.0f;
    p.mean_m[2] = -1.0f;
    memcpy(&p.xyz[0][0], pts, sizeof pts);
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_pn_box(&g_pn.ws, &p, LIDET_CLASS_CYCLIST, &o));
    /* model-frame points: (x, y) -> (y, -x): (2, -1, 3), (0, 1, 0), (-2, 0, 1); max = (2, 1, 3);
     * centre = (2, 1, 3) + (0.5, -0.25, 1) = (2.5, 0.75, 4) -> sensor (-0.75, 10 + 2.5, -1 + 4) */
    TEST_ASSERT_CLOSE(-0.75, o.box.cx_m, 1e-5, 0);
    TEST_ASSERT_CLOSE(12.5, o.box.cy_m, 1e-5, 0);
    TEST_ASSERT_CLOSE(3.0, o.box.cz_m, 1e-5, 0);
    TEST_ASSERT_EQUAL_UINT8(1, o.heading_bin);
    TEST_ASSERT_EQUAL_UINT8(0, o.size_cluster);
    /* yaw = bin 1 * pi + residual 0.5 * (pi / 2) + azimuth pi / 2 = 1.75 pi -> -0.25 pi */
    yaw = -0.25 * pi;
    TEST_ASSERT_CLOSE(yaw, o.box.yaw_rad, 1e-5, 0);
    TEST_ASSERT_CLOSE(4.0 * 1.1, o.box.l_m, 1e-5, 0);
    TEST_ASSERT_CLOSE(2.0 * 0.5, o.box.w_m, 1e-5, 0);
    TEST_ASSERT_CLOSE(1.5, o.box.h_m, 1e-5, 0);
    eh = -(3.0 + log(exp(-3.0) + 1.0));
    es = -2.0; /* one size score: -logsumexp(2) */
    TEST_ASSERT_CLOSE(eh, o.energy_heading, 1e-5, 0);
    TEST_ASSERT_CLOSE(es, o.energy_size, 1e-5, 0);
    TEST_ASSERT_CLOSE(eh + es, o.energy, 1e-5, 0);
    TEST_ASSERT_EQUAL_UINT8(1, o.pass);
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_ARG, lidet_pn_box(&g_pn.ws, &p, 3, &o));
}

/* ---- a random model against a naive double loop: block and tile edges --------------------------- */
#define RP 13 /* points: not a multiple of the block */
static float r_w[4][64 * 64], r_b[4][64];

static double naive(const lidet_pn_layer_t *l, int n, const double *in, double *out)
{
    int o, i;
    for (o = 0; o < l[n].n_out; ++o)
    {
        double s = l[n].b[o];
        for (i = 0; i < l[n].n_in; ++i)
        {
            s += in[i] * (double)l[n].w_t[i * l[n].n_out + o];
        }
        out[o] = l[n].relu && s < 0 ? 0 : s;
    }
    return 0;
}

void test_random_model_matches_double_loop(void)
{
    static lidet_pn_model_t m;
    static lidet_pn_layer_t point[3], pvle[1], head[2];
    const uint16_t pw[3] = {7, 9, 13}, hw[2] = {5, 3};
    float pts[RP * 3], vox[3] = {3.0f, -1.0f, 25.0f}, out[3];
    double a[64], b2[64], g[64], cat[64];
    int k, i, l, j;
    srand(7);
    for (k = 0; k < 4; ++k)
    {
        for (i = 0; i < 64 * 64; ++i)
        {
            r_w[k][i] = (float)(rand() % 2001 - 1000) / 1000.0f;
        }
        for (i = 0; i < 64; ++i)
        {
            r_b[k][i] = (float)(rand() % 201 - 100) / 100.0f;
        }
    }
    for (l = 0; l < 3; ++l)
    {
        point[l].n_in = l == 0 ? 3 : pw[l - 1];
        point[l].n_out = pw[l];
        point[l].relu = (uint8_t)(l != 1); /* a layer without ReLU in the middle */
        point[l].w_t = r_w[l];
        point[l].b = r_b[l];
    }
    pvle[0].n_in = 3;
    pvle[0].n_out = 6;
    pvle[0].relu = 1;
    pvle[0].w_t = r_w[3];
    pvle[0].b = r_b[3];
    head[0].n_in = 13 + 6;
    head[0].n_out = hw[0];
    head[0].relu = 1;
    head[0].w_t = r_w[3] + 100;
    head[0].b = r_b[3] + 10;
    head[1].n_in = hw[0];
    head[1].n_out = hw[1];
    head[1].relu = 0;
    head[1].w_t = r_w[2] + 500;
    head[1].b = r_b[2] + 20;
    m = tiny_classifier();
    m.n_points = RP;
    m.stage[0].point = point;
    m.stage[0].n_point = 3;
    m.stage[0].pvle = pvle;
    m.stage[0].head = head;
    m.stage[0].n_head = 2;
    init_ok(&m);
    TEST_ASSERT_EQUAL_UINT32(LIDET_PN_SCRATCH_BYTES(13, 19), lidet_pn_scratch_bytes(&m));
    for (i = 0; i < RP * 3; ++i)
    {
        pts[i] = (float)(rand() % 2001 - 1000) / 500.0f;
    }
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_pn_forward(&g_pn.ws, pts, RP, vox, NULL, out, 3));
    for (j = 0; j < 13; ++j)
    {
        g[j] = -1e300;
    }
    for (k = 0; k < RP; ++k)
    {
        for (i = 0; i < 3; ++i)
        {
            a[i] = pts[3 * k + i];
        }
        naive(point, 0, a, b2);
        naive(point, 1, b2, a);
        naive(point, 2, a, b2);
        for (j = 0; j < 13; ++j)
        {
            g[j] = b2[j] > g[j] ? b2[j] : g[j];
        }
    }
    for (j = 0; j < 13; ++j)
    {
        cat[j] = g[j];
    }
    a[0] = vox[0];
    a[1] = vox[1];
    a[2] = vox[2];
    naive(pvle, 0, a, cat + 13);
    naive(head, 0, cat, a);
    naive(head, 1, a, b2);
    for (j = 0; j < 3; ++j)
    {
        TEST_ASSERT_CLOSE(b2[j], out[j], 1e-4, 1e-5);
    }
}

/* ---- malformed descriptors and arguments ------------------------------------------------------- */
void test_bad_descriptors(void)
{
    static lidet_pn_model_t m;
    static lidet_pn_layer_t bad[1];
    uint32_t need = 0;
    float out[3], pts[12] = {0}, vox[3] = {0};
    m = tiny_classifier();
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_pn_check(&m, LIDET_PN_CLASSIFIER, 4));
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_MODEL, lidet_pn_check(&m, LIDET_PN_BOX, 4));
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_MODEL, lidet_pn_check(&m, LIDET_PN_CLASSIFIER, 64));
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_ARG, lidet_pn_check(NULL, 0, 0));

    m.format_version = LIDET_WEIGHTS_FORMAT_VERSION + 1;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_MODEL,
                          lidet_pn_init(&g_pn.ws, &m, g_scratch.ws.f, sizeof g_scratch.ws.f, &need));
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_STATE, lidet_pn_forward(&g_pn.ws, pts, 4, vox, NULL, out, 3));
    m = tiny_classifier();
    m.n_points = LIDET_PROPOSAL_POINTS + 1;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_MODEL, lidet_pn_check(&m, 0, 0));
    m = tiny_classifier();
    m.precision = 7;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_MODEL, lidet_pn_check(&m, 0, 0));
    m = tiny_classifier();
    m.energy_t = 0.0f;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_MODEL, lidet_pn_check(&m, 0, 0));
    m = tiny_classifier();
    m.stage[0].n_point = 0;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_MODEL, lidet_pn_check(&m, 0, 0));
    TEST_ASSERT_EQUAL_UINT32(0, lidet_pn_scratch_bytes(&m));
    /* widths that do not chain: a head taking 4 inputs after 2 + 1 */
    m = tiny_classifier();
    bad[0] = c_head[0];
    bad[0].n_in = 4;
    m.stage[0].head = bad;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_MODEL, lidet_pn_check(&m, 0, 0));
    /* a NULL weight array, a zero-width layer, too many layers */
    bad[0] = c_head[0];
    bad[0].w_t = NULL;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_MODEL, lidet_pn_check(&m, 0, 0));
    bad[0] = c_point[0];
    bad[0].n_out = 0;
    m = tiny_classifier();
    m.stage[0].point = bad;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_MODEL, lidet_pn_check(&m, 0, 0));
    m = tiny_classifier();
    m.stage[0].n_head = LIDET_PN_MAX_LAYERS + 1;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_MODEL, lidet_pn_check(&m, 0, 0));
    /* a classifier with 2 logits; a box net without size templates */
    m = tiny_classifier();
    bad[0] = c_head[0];
    bad[0].n_out = 2;
    m.stage[0].head = bad;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_MODEL, lidet_pn_check(&m, 0, 0));
    m = tiny_box();
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_pn_check(&m, LIDET_PN_BOX, 3));
    m.mean_size_m = NULL;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_MODEL, lidet_pn_check(&m, 0, 0));
    m = tiny_box();
    m.n_heading_bins = 3; /* the head has 11 outputs for H = 2 */
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_MODEL, lidet_pn_check(&m, 0, 0));

    /* scratch: too small -> LIDET_ERR_BUFFER with the size; NULL to ask; misaligned */
    m = tiny_classifier();
    need = 0;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_BUFFER, lidet_pn_init(&g_pn.ws, &m, g_scratch.ws.f, 16, &need));
    TEST_ASSERT_EQUAL_UINT32(lidet_pn_scratch_bytes(&m), need);
    TEST_ASSERT_TRUE(need > 16);
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_BUFFER, lidet_pn_init(&g_pn.ws, &m, NULL, 0, &need));
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_ARG,
                          lidet_pn_init(&g_pn.ws, &m, (char *)g_scratch.ws.f + 1, need + 8, NULL));
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_ARG,
                          lidet_pn_init(NULL, &m, g_scratch.ws.f, sizeof g_scratch.ws.f, NULL));

    /* run-time arguments */
    init_ok(&m);
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_ARG, lidet_pn_forward(&g_pn.ws, pts, 3, vox, NULL, out, 3));
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_ARG, lidet_pn_forward(&g_pn.ws, pts, 4, vox, NULL, out, 2));
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_ARG, lidet_pn_forward(&g_pn.ws, NULL, 4, vox, NULL, out, 3));
    {
        lidet_proposal_t p;
        lidet_pn_box_out_t bo;
        lidet_pn_class_out_t co;
        memset(&p, 0, sizeof p);
        p.n_points = 5;
        TEST_ASSERT_EQUAL_INT(LIDET_ERR_ARG, lidet_pn_classify(&g_pn.ws, &p, &co));
        p.n_points = 4;
        TEST_ASSERT_EQUAL_INT(LIDET_ERR_MODEL, lidet_pn_box(&g_pn.ws, &p, 0, &bo));
    }
}

void test_find(void)
{
    static lidet_pn_model_t m;
    lidet_pn_entry_t table[2];
    m = tiny_classifier();
    table[0].name = "a";
    table[0].model = NULL;
    table[1].name = "tiny";
    table[1].model = &m;
    TEST_ASSERT_EQUAL_PTR(&m, lidet_pn_find(table, 2, "tiny"));
    TEST_ASSERT_NULL(lidet_pn_find(table, 2, "nope"));
    TEST_ASSERT_NULL(lidet_pn_find(NULL, 2, "tiny"));
}

/* fuzz_pointnet (issue 19, docs/ROBUSTNESS.md): a heading residual of 1e30 or Inf (hostile points drive the
 * box net there) made the heading wrap loop forever. tiny_box's winning bin 1 has its residual at b_bh_b[6];
 * the yaw comes back in (-pi, pi] (finite heading) or NaN (infinite one: residual * pi / 2 overflows) */
static void test_box_heading_wrap_terminates(void)
{
    static const float residuals[] = {1e30f, -1e37f, 12345.678f, -3e38f, INFINITY};
    const float saved = b_bh_b[6];
    const float pts[9] = {1, 2, 3, -1, 0, 0, 0, -2, 1};
    static lidet_pn_model_t m;
    lidet_proposal_t p;
    lidet_pn_box_out_t o;
    uint32_t i;
    m = tiny_box();
    init_ok(&m);
    memset(&p, 0, sizeof p);
    p.n_points = 3;
    p.mean_m[0] = 10.0f;
    memcpy(&p.xyz[0][0], pts, sizeof pts);
    for (i = 0; i < sizeof residuals / sizeof residuals[0]; ++i)
    {
        b_bh_b[6] = residuals[i];
        TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_pn_box(&g_pn.ws, &p, LIDET_CLASS_CAR, &o));
        if (i >= 3)
        {
            TEST_ASSERT_TRUE(isnan(o.box.yaw_rad));
        }
        else
        {
            TEST_ASSERT_TRUE(o.box.yaw_rad > -3.14159274f && o.box.yaw_rad <= 3.14159274f);
        }
    }
    b_bh_b[6] = saved;
}

/* LIDET__PROPOSAL_DISTINCT_ROWS_HASHED (the float PointNets' lookup of a proposal's repeated rows) gives the
 * linear search's result on every row set: random sets of 2-320 rows (past the table's 255 first rows too) whose
 * first rows repeat values, later rows mostly copies of first ones, sometimes a row of their own, a copy with
 * -0 for +0, or a NaN copy; with a hash of the row's bits, a weak one (x's low bits) and one bucket for all */
static float g_dr[320][3];
static uint32_t dr_bits(float v)
{
    uint32_t b;
    memcpy(&b, &v, sizeof b);
    return b;
}
static uint32_t dr_hash_bits(uint32_t i)
{
    return lidet__proposal_row_hash(dr_bits(g_dr[i][0]), dr_bits(g_dr[i][1]), dr_bits(g_dr[i][2]));
}
static uint32_t dr_hash_weak(uint32_t i)
{
    return dr_bits(g_dr[i][0]) & 127u;
}
static uint32_t dr_hash_one(uint32_t i)
{
    (void)i;
    return 5u;
}
static uint32_t dr_next(uint32_t *s)
{
    *s = *s * 1664525u + 1013904223u;
    return *s >> 8;
}

void test_distinct_rows_hashed_matches_linear(void)
{
    static const float pool[6] = {0.0f, 1.5f, -2.25f, 0.004f, 1e30f, -7.0f};
    uint32_t s = 12345u, trial, i, k, n_src_seen = 0, n_out_seen = 0;
    for (trial = 0; trial < 4000u; ++trial)
    {
        const uint32_t n_out = 2u + dr_next(&s) % 319u;
        const uint32_t n_src = 1u + dr_next(&s) % n_out;
        const uint32_t odd = 1u + dr_next(&s) % 4u; /* how later rows may differ: 1 in n_out * odd */
        uint32_t lin, h[3];
        for (i = 0; i < n_src; ++i)
        {
            for (k = 0; k < 3u; ++k)
            {
                const uint32_t u = dr_next(&s);
                g_dr[i][k] = u % 4u == 0u ? (float)(u % 1000u) * 0.01f : pool[u % 6u];
            }
            if (dr_next(&s) % 50u == 0u)
            {
                g_dr[i][dr_next(&s) % 3u] = NAN;
            }
        }
        for (i = n_src; i < n_out; ++i)
        {
            const uint32_t u = dr_next(&s) % (n_out * odd);
            memcpy(g_dr[i], g_dr[dr_next(&s) % n_src], sizeof g_dr[i]);
            if (u == 0u)
            {
                g_dr[i][0] = 3.25f + (float)i; /* a row of its own */
            }
            else if (u == 1u)
            {
                g_dr[i][1] = g_dr[i][1] == 0.0f ? -g_dr[i][1] : g_dr[i][1]; /* +0 <-> -0 where zero */
            }
            else if (u == 2u)
            {
                g_dr[i][2] = NAN;
            }
        }
#define ROW_EQ(a, b)                                                                                         \
    (g_dr[a][0] == g_dr[b][0] && g_dr[a][1] == g_dr[b][1] && g_dr[a][2] == g_dr[b][2] &&                     \
     memcmp(g_dr[a], g_dr[b], sizeof g_dr[a]) == 0)
        LIDET__PROPOSAL_DISTINCT_ROWS(n_out, n_src, ROW_EQ, lin);
        LIDET__PROPOSAL_DISTINCT_ROWS_HASHED(n_out, n_src, ROW_EQ, dr_hash_bits, h[0]);
        LIDET__PROPOSAL_DISTINCT_ROWS_HASHED(n_out, n_src, ROW_EQ, dr_hash_weak, h[1]);
        LIDET__PROPOSAL_DISTINCT_ROWS_HASHED(n_out, n_src, ROW_EQ, dr_hash_one, h[2]);
#undef ROW_EQ
        TEST_ASSERT_EQUAL_UINT32(lin, h[0]);
        TEST_ASSERT_EQUAL_UINT32(lin, h[1]);
        TEST_ASSERT_EQUAL_UINT32(lin, h[2]);
        n_src_seen += lin == n_src && n_src < n_out;
        n_out_seen += lin == n_out && n_src < n_out;
    }
    /* both outcomes occur often, with the table and past it */
    TEST_ASSERT_TRUE(n_src_seen > 500u);
    TEST_ASSERT_TRUE(n_out_seen > 500u);
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_classifier_by_hand);
    RUN_TEST(test_energy_is_stable);
    RUN_TEST(test_box_by_hand);
    RUN_TEST(test_random_model_matches_double_loop);
    RUN_TEST(test_bad_descriptors);
    RUN_TEST(test_find);
    RUN_TEST(test_box_heading_wrap_terminates);
    RUN_TEST(test_distinct_rows_hashed_matches_linear);
    return UNITY_END();
}
