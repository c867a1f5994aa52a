/* SPDX-License-Identifier: MIT */
/* The int8 PointNets (lidet_pointnet_q.h): a hand-made classifier whose outputs are worked out by hand (model
 * frame at azimuth 0 and 90 degrees, the max over the points, requantization, Q16 logits, energy, scores), the
 * integer energy against ln values, malformed descriptors, scratch and state errors, and the generated int8
 * models of weights/ (valid, scratch macros, they run). Bit-exactness against the numpy reference on real and
 * simulated proposals is in tests/python/test_pointnet_q.py. */
#include <string.h>

#include "lidet/lidet.h"
#include "lidet/lidet_pointnet_q.h"
#include "lidet_weights.h"
#include "test_util.h"

static int32_t g_scratch[8192];

void setUp(void)
{
}

void tearDown(void)
{
}

/* point layer 3 -> 2: ch0 = x, ch1 = y (mm), requant round(acc / 2) - 128 (ReLU, zero point -128) */
static const int8_t k_w0[6] = {1, 0, 0, 1, 0, 0};
static const int32_t k_b0[2] = {0, 0};
static const int32_t k_lb[2] = {-128, -128}, k_lb_bad[2] = {-128, -127}; /* b - 128 sum_i w[i][o], and one off */
static const int32_t k_m0[2] = {1 << 30, 1 << 30};
static const uint8_t k_s0[2] = {31, 31};
/* head 2 -> 3, Q16 out: out = acc * 2^16, acc = b + g . W */
static const int8_t k_w1[6] = {1, 0, -1, 0, 1, 0};
static const int32_t k_b1[3] = {256, 0, 0};
static const int32_t k_m1[3] = {1 << 30, 1 << 30, 1 << 30};
static const uint8_t k_s1[3] = {14, 14, 14};

static lidet_pointnet_q_layer_t g_point[1], g_head[1];
static lidet_pointnet_q_model_t g_model;

static void make_model(void)
{
    const lidet_pointnet_q_layer_t p = {3, 2, 1, LIDET_PNQ_OUT_S8, -128, k_w0, k_b0, k_m0, k_s0, 0, 0};
    const lidet_pointnet_q_layer_t h = {2, 3, 0, LIDET_PNQ_OUT_Q16, 0, k_w1, k_b1, k_m1, k_s1, 0, 0};
    g_point[0] = p;
    g_head[0] = h;
    memset(&g_model, 0, sizeof g_model);
    g_model.format_version = LIDET_WEIGHTS_FORMAT_VERSION;
    g_model.kind = LIDET_PN_CLASSIFIER;
    g_model.precision = LIDET_PN_S8;
    g_model.n_stages = 1;
    g_model.n_classes = LIDET_N_CLASSES;
    g_model.n_points = 2;
    g_model.stage[0].point = g_point;
    g_model.stage[0].head = g_head;
    g_model.stage[0].n_point = 1;
    g_model.stage[0].n_head = 1;
    g_model.pvle_bin[0] = g_model.pvle_bin[1] = 174533;
    g_model.pvle_bin[2] = 1000;
    g_model.energy_t_q16 = 65536;
    g_model.gamma_q16[0] = g_model.gamma_q16[1] = g_model.gamma_q16[2] = -100 * 65536;
    g_model.name = "hand";
}

static void make_proposal(lidet_proposal_q_t *p, int32_t mx, int32_t my)
{
    memset(p, 0, sizeof *p);
    p->n_points = 2;
    p->xyz[0][0] = 10; /* 4 mm steps */
    p->xyz[0][1] = 3;
    p->xyz[1][0] = -5;
    p->xyz[1][1] = 20;
    p->xyz[1][2] = 7;
    p->mean_4mm[0] = mx;
    p->mean_4mm[1] = my;
}

void test_hand_classifier_azimuth_0_and_90(void)
{
    static lidet_pointnet_q_t pn;
    lidet_pointnet_q_class_out_t o;
    lidet_proposal_q_t p;
    make_model();
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_pointnet_q_init(&pn, &g_model, g_scratch, sizeof g_scratch, NULL));
    /* azimuth 0: model frame = sensor frame in mm: (40, 12), (-20, 80); max x 40, max y 80 ->
     * g = (20 - 128, 40 - 128) = (-108, -88); logits 256 - 108 = 148, -88, 108 */
    make_proposal(&p, 1000, 0);
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_pointnet_q_classify(&pn, &p, &o));
    TEST_ASSERT_EQUAL_INT32(148 * 65536, o.logits_q16[0]);
    TEST_ASSERT_EQUAL_INT32(-88 * 65536, o.logits_q16[1]);
    TEST_ASSERT_EQUAL_INT32(108 * 65536, o.logits_q16[2]);
    TEST_ASSERT_EQUAL_UINT8(0, o.cls);
    /* the others are 40 nats and more below: exp cut to 0, energy exactly -148, score exactly 1 */
    TEST_ASSERT_EQUAL_INT32(-148 * 65536, o.energy_q16);
    TEST_ASSERT_EQUAL_INT32(32768, o.prob_q15[0]);
    TEST_ASSERT_EQUAL_INT32(0, o.prob_q15[2]);
    TEST_ASSERT_EQUAL_UINT8(1, o.pass);
    /* azimuth 90 degrees: x' = y, y' = -x: (12, -40), (80, 20) -> g = (-88, -118); logits 168, -118, 88 */
    make_proposal(&p, 0, 1000);
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_pointnet_q_classify(&pn, &p, &o));
    TEST_ASSERT_EQUAL_INT32(168 * 65536, o.logits_q16[0]);
    TEST_ASSERT_EQUAL_INT32(-118 * 65536, o.logits_q16[1]);
    TEST_ASSERT_EQUAL_INT32(88 * 65536, o.logits_q16[2]);
    /* the raw network on model-frame points (mm) gives the same */
    {
        const int16_t pts[6] = {12, -40, 0, 80, 20, 28};
        const int16_t vox[3] = {0, 0, 0};
        int32_t out[3];
        TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_pointnet_q_forward(&pn, pts, 2, vox, 0, out, 3));
        TEST_ASSERT_EQUAL_INT32(168 * 65536, out[0]);
        TEST_ASSERT_EQUAL_INT32(88 * 65536, out[2]);
        TEST_ASSERT_EQUAL_INT(LIDET_ERR_ARG, lidet_pointnet_q_forward(&pn, pts, 3, vox, 0, out, 3));
        TEST_ASSERT_EQUAL_INT(LIDET_ERR_ARG, lidet_pointnet_q_forward(&pn, pts, 2, vox, 0, out, 2));
    }
}

void test_energy(void)
{
    const int32_t zeros[3] = {0, 0, 0};
    const int32_t two[2] = {65536, 0};
    const int32_t ext[2] = {INT32_MAX, INT32_MIN};
    /* -ln 3 = -1.0986123 nats = -71998.6 Q16 */
    TEST_ASSERT_INT32_WITHIN(2, -71999, lidet_pointnet_q_energy(zeros, 3, 65536));
    /* -(1 + ln(1 + e^-1)) = -1.3132617 = -86066.1 Q16 */
    TEST_ASSERT_INT32_WITHIN(2, -86066, lidet_pointnet_q_energy(two, 2, 65536));
    /* T = 2: -2 ln 3 */
    TEST_ASSERT_INT32_WITHIN(3, -143997, lidet_pointnet_q_energy(zeros, 3, 131072));
    /* extremes saturate, no overflow */
    TEST_ASSERT_EQUAL_INT32(-INT32_MAX, lidet_pointnet_q_energy(ext, 2, 65536));
    TEST_ASSERT_EQUAL_INT32(0, lidet_pointnet_q_energy(zeros, 0, 65536));
    TEST_ASSERT_EQUAL_INT32(0, lidet_pointnet_q_energy(zeros, 3, 0));
}

void test_malformed_descriptors(void)
{
    static const int32_t big_b[2] = {1 << 29, 0};
    static const uint8_t bad_s[2] = {0, 31};
    static lidet_pointnet_q_t pn;
    lidet_pointnet_q_model_t m;
    lidet_pointnet_q_layer_t p0;
    make_model();
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_pointnet_q_check(&g_model, LIDET_PN_CLASSIFIER, 2));
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_ARG, lidet_pointnet_q_check(NULL, 0, 0));
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_MODEL, lidet_pointnet_q_check(&g_model, LIDET_PN_BOX, 0));
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_MODEL, lidet_pointnet_q_check(&g_model, 0, 64));
#define EXPECT_BAD(stmt)                                                                                         \
    do                                                                                                           \
    {                                                                                                            \
        make_model();                                                                                            \
        m = g_model;                                                                                             \
        p0 = g_point[0];                                                                                         \
        stmt;                                                                                                    \
        g_point[0] = p0;                                                                                         \
        TEST_ASSERT_EQUAL_INT(LIDET_ERR_MODEL, lidet_pointnet_q_check(&m, 0, 0));                                \
        TEST_ASSERT_EQUAL_INT(LIDET_ERR_MODEL, lidet_pointnet_q_init(&pn, &m, g_scratch, sizeof g_scratch, NULL)); \
        TEST_ASSERT_EQUAL_UINT32(0, lidet_pointnet_q_scratch_bytes(&m));                                         \
    } while (0)
    EXPECT_BAD(m.format_version = 99);
    EXPECT_BAD(m.precision = LIDET_PN_F32);
    EXPECT_BAD(m.kind = 7);
    EXPECT_BAD(m.n_points = LIDET_PROPOSAL_POINTS + 1);
    EXPECT_BAD(m.n_points = 0);
    EXPECT_BAD(m.energy_t_q16 = 0);
    EXPECT_BAD(m.pvle_bin[2] = 0);
    EXPECT_BAD(m.stage[0].use_onehot = 1);
    EXPECT_BAD(m.stage[0].n_point = LIDET_PN_MAX_LAYERS + 1);
    EXPECT_BAD(p0.w_t = NULL);
    EXPECT_BAD(p0.n_in = 4);
    EXPECT_BAD(p0.b = big_b);
    EXPECT_BAD(p0.b_list = k_lb_bad); /* the list kernel's starting sums, one off b - 128 sum w */
    EXPECT_BAD(p0.shift = bad_s);
    EXPECT_BAD(p0.out = LIDET_PNQ_OUT_Q16);
    EXPECT_BAD(g_head[0].out = LIDET_PNQ_OUT_S8);
    EXPECT_BAD(g_head[0].n_out = 2); /* not n_classes logits */
#undef EXPECT_BAD
    make_model();
    g_point[0].b_list = k_lb; /* exactly b - 128 sum w: accepted */
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_pointnet_q_check(&g_model, LIDET_PN_CLASSIFIER, 2));
    make_model();
}

void test_scratch_and_state(void)
{
    static lidet_pointnet_q_t pn;
    lidet_pointnet_q_class_out_t o;
    lidet_pointnet_q_box_out_t bo;
    lidet_proposal_q_t p;
    uint32_t need = 0;
    make_model();
    memset(&pn, 0, sizeof pn);
    make_proposal(&p, 1000, 0);
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_STATE, lidet_pointnet_q_classify(&pn, &p, &o));
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_BUFFER, lidet_pointnet_q_init(&pn, &g_model, g_scratch, 16, &need));
    TEST_ASSERT_EQUAL_UINT32(lidet_pointnet_q_scratch_bytes(&g_model), need);
    TEST_ASSERT_EQUAL_UINT32(LIDET_POINTNET_Q_SCRATCH_BYTES(3, 8), need);
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_BUFFER, lidet_pointnet_q_init(&pn, &g_model, NULL, 0, NULL));
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_ARG,
                          lidet_pointnet_q_init(&pn, &g_model, (uint8_t *)g_scratch + 1, sizeof g_scratch - 4, NULL));
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_pointnet_q_init(&pn, &g_model, g_scratch, need, NULL));
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_MODEL, lidet_pointnet_q_box(&pn, &p, 0, &bo));
    p.n_points = 3;
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_ARG, lidet_pointnet_q_classify(&pn, &p, &o));
    make_proposal(&p, INT32_MAX, 0); /* not a mean of points within the coordinate limits */
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_ARG, lidet_pointnet_q_classify(&pn, &p, &o));
    make_proposal(&p, 0, 0); /* on the z axis: frame (1, 0) */
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_pointnet_q_classify(&pn, &p, &o));
    TEST_ASSERT_EQUAL_INT32(148 * 65536, o.logits_q16[0]);
}

void test_generated_int8_models(void)
{
    static lidet_pointnet_q_t cls, box;
    lidet_pointnet_q_class_out_t co;
    lidet_pointnet_q_box_out_t bo;
    lidet_proposal_q_t p;
    uint32_t i;
    TEST_ASSERT_TRUE(LIDET_WEIGHTS_N_MODELS_S8 >= 2);
    for (i = 0; i < LIDET_WEIGHTS_N_MODELS_S8; ++i)
    {
        const lidet_pointnet_q_model_t *m = lidet_weights_models_s8[i].model;
        TEST_ASSERT_EQUAL_INT_MESSAGE(LIDET_OK, lidet_pointnet_q_check(m, 0, 0), lidet_weights_models_s8[i].name);
        TEST_ASSERT_EQUAL_PTR(m, lidet_pointnet_q_find(lidet_weights_models_s8, LIDET_WEIGHTS_N_MODELS_S8, m->name));
        TEST_ASSERT_TRUE(lidet_pointnet_q_scratch_bytes(m) <= sizeof g_scratch);
    }
    TEST_ASSERT_NULL(lidet_pointnet_q_find(lidet_weights_models_s8, LIDET_WEIGHTS_N_MODELS_S8, "nope"));
    TEST_ASSERT_EQUAL_UINT32(CLS_HDL64_S8_SCRATCH_BYTES, lidet_pointnet_q_scratch_bytes(&lidet_model_cls_hdl64_s8));
    TEST_ASSERT_EQUAL_UINT32(BOX_HDL64_S8_SCRATCH_BYTES, lidet_pointnet_q_scratch_bytes(&lidet_model_box_hdl64_s8));
    memset(&p, 0, sizeof p);
    p.n_points = lidet_model_cls_hdl64_s8.n_points;
    for (i = 0; i < p.n_points; ++i)
    {
        /* a car-sized blob, 4 mm steps */
        p.xyz[i][0] = (int16_t)(50 * (int32_t)(i % 17) - 400);
        p.xyz[i][1] = (int16_t)(25 * (int32_t)(i % 9) - 100);
        p.xyz[i][2] = (int16_t)(20 * (int32_t)(i % 11) - 100);
    }
    p.mean_4mm[0] = 3750; /* 15 m */
    p.mean_4mm[1] = -750;
    p.mean_4mm[2] = -250;
    p.voxel[2] = 15;
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_pointnet_q_init(&cls, &lidet_model_cls_hdl64_s8, g_scratch, sizeof g_scratch,
                                                          NULL));
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_pointnet_q_classify(&cls, &p, &co));
    TEST_ASSERT_TRUE(co.cls < LIDET_N_CLASSES && co.energy_q16 < 0);
    TEST_ASSERT_INT32_WITHIN(3, 32768, co.prob_q15[0] + co.prob_q15[1] + co.prob_q15[2]);
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_pointnet_q_init(&box, &lidet_model_box_hdl64_s8, g_scratch, sizeof g_scratch,
                                                          NULL));
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_pointnet_q_box(&box, &p, co.cls, &bo));
    /* the box lies near the proposal (within 5 m of the mean) and has a positive size */
    TEST_ASSERT_INT32_WITHIN(5000, 15000, bo.box.cx_mm);
    TEST_ASSERT_INT32_WITHIN(5000, -3000, bo.box.cy_mm);
    TEST_ASSERT_TRUE(bo.box.l_mm > 0 && bo.box.w_mm > 0 && bo.box.h_mm > 0);
    TEST_ASSERT_EQUAL_INT32(bo.energy_heading_q16 + bo.energy_size_q16, bo.energy_q16);
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_ARG, lidet_pointnet_q_box(&box, &p, LIDET_N_CLASSES, &bo));
    /* points at the int16 limits and a mean at the coordinate limit: saturation, no overflow (UBSan build) */
    for (i = 0; i < p.n_points; ++i)
    {
        p.xyz[i][0] = (int16_t)(i & 1u ? 32767 : -32768);
        p.xyz[i][1] = (int16_t)(i & 2u ? 32767 : -32768);
        p.xyz[i][2] = (int16_t)(i & 4u ? 32767 : -32768);
    }
    p.mean_4mm[0] = -LIDET_Q_COORD_MAX_MM / 4;
    p.mean_4mm[1] = LIDET_Q_COORD_MAX_MM / 4;
    p.mean_4mm[2] = LIDET_Q_COORD_MAX_MM / 4;
    p.voxel[0] = INT16_MIN;
    p.voxel[2] = INT16_MAX;
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_pointnet_q_classify(&cls, &p, &co));
    TEST_ASSERT_TRUE(co.cls < LIDET_N_CLASSES);
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_pointnet_q_box(&box, &p, co.cls, &bo));
}

/* A proposal of a cluster of n_src < n_points members repeats rows of its first n_src (the resampling rule):
 * classify and box run the shared layers on those rows only (internal/lidet_proposal_rule.h). Every generated
 * model, n_src 1, 5 and n - 1: the outputs equal those of the same rows without the hint (n_points_src 0: every
 * row); and a last row that is no copy (a proposal made by hand) is still seen: the outputs again equal those
 * of every row, and differ from the copies' (the far row changes the maximum). */
static void repeat_rows(lidet_proposal_q_t *p, uint32_t n, uint32_t n_src)
{
    uint32_t i;
    memset(p, 0, sizeof *p);
    p->n_points = n;
    for (i = 0; i < n; ++i)
    {
        const uint32_t k = i < n_src ? i : (7u * i + 3u) % n_src;
        p->xyz[i][0] = (int16_t)(37 * (int32_t)(k % 13) - 220); /* 4 mm steps: a blob of about 2 m */
        p->xyz[i][1] = (int16_t)(29 * (int32_t)(k % 7) - 90);
        p->xyz[i][2] = (int16_t)(23 * (int32_t)(k % 11) - 110);
    }
    p->mean_4mm[0] = 2500; /* 10 m ahead, 2 m left */
    p->mean_4mm[1] = 500;
    p->mean_4mm[2] = -100;
    p->voxel[2] = 10;
}

static void run_one(lidet_pointnet_q_t *pn, const lidet_proposal_q_t *p, uint32_t cls, lidet_pointnet_q_class_out_t *co,
                    lidet_pointnet_q_box_out_t *bo)
{
    memset(co, 0, sizeof *co);
    memset(bo, 0, sizeof *bo);
    if (pn->model->kind == LIDET_PN_CLASSIFIER)
    {
        TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_pointnet_q_classify(pn, p, co));
    }
    else
    {
        TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_pointnet_q_box(pn, p, cls, bo));
    }
}

/* the outputs with the hint n_points_src = n_src (into co, bo) equal those without it (every row) */
static void same_with_and_without_hint(lidet_pointnet_q_t *pn, lidet_proposal_q_t *p, uint32_t cls, uint32_t n_src,
                                       lidet_pointnet_q_class_out_t *co, lidet_pointnet_q_box_out_t *bo)
{
    lidet_pointnet_q_class_out_t c_all;
    lidet_pointnet_q_box_out_t b_all;
    p->n_points_src = 0;
    run_one(pn, p, cls, &c_all, &b_all);
    p->n_points_src = n_src;
    run_one(pn, p, cls, co, bo);
    TEST_ASSERT_EQUAL_MEMORY_MESSAGE(&c_all, co, sizeof c_all, pn->model->name);
    TEST_ASSERT_EQUAL_MEMORY_MESSAGE(&b_all, bo, sizeof b_all, pn->model->name);
}

void test_repeated_rows_are_run_once(void)
{
    static lidet_pointnet_q_t pn;
    static const uint32_t srcs[3] = {1u, 5u, 0u};
    lidet_pointnet_q_class_out_t c_hint, c_copy;
    lidet_pointnet_q_box_out_t b_hint, b_copy;
    lidet_proposal_q_t p;
    uint32_t i, j, cls;
    for (i = 0; i < LIDET_WEIGHTS_N_MODELS_S8; ++i)
    {
        const lidet_pointnet_q_model_t *m = lidet_weights_models_s8[i].model;
        const uint32_t n = m->n_points;
        TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_pointnet_q_init(&pn, m, g_scratch, sizeof g_scratch, NULL));
        for (j = 0; j < 3u; ++j)
        {
            const uint32_t n_src = srcs[j] != 0u ? srcs[j] : n - 1u;
            for (cls = 0; cls < (m->kind == LIDET_PN_BOX ? (uint32_t)LIDET_N_CLASSES : 1u); ++cls)
            {
                repeat_rows(&p, n, n_src);
                same_with_and_without_hint(&pn, &p, cls, n_src, &c_copy, &b_copy);
                /* the last row no copy: far to the right and high */
                p.xyz[n - 1u][0] = 1500;
                p.xyz[n - 1u][1] = -2000;
                p.xyz[n - 1u][2] = 600;
                same_with_and_without_hint(&pn, &p, cls, n_src, &c_hint, &b_hint);
                TEST_ASSERT_FALSE_MESSAGE(memcmp(&c_copy, &c_hint, sizeof c_copy) == 0 &&
                                              memcmp(&b_copy, &b_hint, sizeof b_copy) == 0,
                                          m->name);
            }
        }
    }
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_hand_classifier_azimuth_0_and_90);
    RUN_TEST(test_energy);
    RUN_TEST(test_malformed_descriptors);
    RUN_TEST(test_scratch_and_state);
    RUN_TEST(test_generated_int8_models);
    RUN_TEST(test_repeated_rows_are_run_once);
    return UNITY_END();
}
