/* SPDX-License-Identifier: MIT */
/* The generated models of weights/ (lidet::weights): every one passes the descriptor check, its
 * <NAME>_SCRATCH_BYTES macro equals lidet_pn_scratch_bytes (no drift between codegen and lib/), it is
 * found by name, and it runs on a proposal with finite outputs. */
#include <math.h>
#include <string.h>

#include "lidet/lidet.h"
#include "lidet_weights.h"
#include "test_util.h"

static float g_scratch[16384];

void setUp(void)
{
}

void tearDown(void)
{
}

void test_every_model_is_valid(void)
{
    uint32_t i;
    TEST_ASSERT_TRUE(LIDET_WEIGHTS_N_MODELS >= 2);
    for (i = 0; i < LIDET_WEIGHTS_N_MODELS; ++i)
    {
        const lidet_pn_model_t *m = lidet_weights_models[i].model;
        TEST_ASSERT_EQUAL_INT_MESSAGE(LIDET_OK, lidet_pn_check(m, 0, 0), lidet_weights_models[i].name);
        TEST_ASSERT_EQUAL_STRING(lidet_weights_models[i].name, m->name);
        TEST_ASSERT_EQUAL_PTR(m, lidet_pn_find(lidet_weights_models, LIDET_WEIGHTS_N_MODELS, m->name));
        TEST_ASSERT_TRUE(lidet_pn_scratch_bytes(m) <= sizeof g_scratch);
    }
}

void test_scratch_macros_match(void)
{
    TEST_ASSERT_EQUAL_UINT32(CLS_HDL64_SCRATCH_BYTES, lidet_pn_scratch_bytes(&lidet_model_cls_hdl64));
    TEST_ASSERT_EQUAL_UINT32(BOX_HDL64_SCRATCH_BYTES, lidet_pn_scratch_bytes(&lidet_model_box_hdl64));
    TEST_ASSERT_EQUAL_UINT32(CLS_HDL64_N_POINTS, lidet_model_cls_hdl64.n_points);
    TEST_ASSERT_EQUAL_UINT32(BOX_HDL64_N_OUTPUTS, lidet_pn_n_outputs(&lidet_model_box_hdl64));
}

void test_models_run(void)
{
    static lidet_pn_t cls, box;
    lidet_proposal_t p;
    lidet_pn_class_out_t co;
    lidet_pn_box_out_t bo;
    uint32_t i;
    memset(&p, 0, sizeof p);
    p.n_points = lidet_model_cls_hdl64.n_points;
    for (i = 0; i < p.n_points; ++i)
    {
        p.xyz[i][0] = 0.02f * (float)(i % 17) - 0.2f;
        p.xyz[i][1] = 0.01f * (float)(i % 5);
        p.xyz[i][2] = 0.03f * (float)(i % 11) - 0.15f;
    }
    p.mean_m[0] = 15.0f;
    p.mean_m[1] = -3.0f;
    p.mean_m[2] = -1.0f;
    p.voxel[2] = 15;
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_pn_init(&cls, &lidet_model_cls_hdl64, g_scratch, sizeof g_scratch, NULL));
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_pn_classify(&cls, &p, &co));
    TEST_ASSERT_TRUE(co.cls < LIDET_N_CLASSES && isfinite(co.energy));
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_pn_init(&box, &lidet_model_box_hdl64, g_scratch, sizeof g_scratch, NULL));
    TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_pn_box(&box, &p, co.cls, &bo));
    TEST_ASSERT_TRUE(isfinite(bo.box.cx_m) && bo.box.l_m > 0.0f && isfinite(bo.energy));
    /* a classifier is not a box net */
    TEST_ASSERT_EQUAL_INT(LIDET_ERR_MODEL, lidet_pn_box(&cls, &p, 0, &bo));
}

/* Proposals of clusters smaller than n_points repeat their first n_src rows: classify and box run the shared
 * layers on those rows only (internal/lidet_proposal_rule.h). Every generated model: the same outputs, bit for
 * bit, as without the hint (n_points_src 0: every row), and a last row that is no copy is still seen. */
static void repeat_rows(lidet_proposal_t *p, uint32_t n, uint32_t n_src)
{
    uint32_t i;
    memset(p, 0, sizeof *p);
    p->n_points = n;
    for (i = 0; i < n; ++i)
    {
        const uint32_t k = i < n_src ? i : (7u * i + 3u) % n_src;
        p->xyz[i][0] = 0.15f * (float)(k % 13) - 0.9f;
        p->xyz[i][1] = 0.11f * (float)(k % 7) - 0.35f;
        p->xyz[i][2] = 0.09f * (float)(k % 11) - 0.45f;
    }
    p->mean_m[0] = 10.0f;
    p->mean_m[1] = 2.0f;
    p->mean_m[2] = -0.4f;
    p->voxel[2] = 10;
}

static void run_one(lidet_pn_t *pn, const lidet_proposal_t *p, uint32_t cls, lidet_pn_class_out_t *co,
                    lidet_pn_box_out_t *bo)
{
    memset(co, 0, sizeof *co);
    memset(bo, 0, sizeof *bo);
    if (pn->model->kind == LIDET_PN_CLASSIFIER)
    {
        TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_pn_classify(pn, p, co));
    }
    else
    {
        TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_pn_box(pn, p, cls, bo));
    }
}

/* the outputs with the hint n_points_src = n_src (into co, bo) equal those without it (every row) */
static void same_with_and_without_hint(lidet_pn_t *pn, lidet_proposal_t *p, uint32_t cls, uint32_t n_src,
                                       lidet_pn_class_out_t *co, lidet_pn_box_out_t *bo)
{
    lidet_pn_class_out_t c_all;
    lidet_pn_box_out_t b_all;
    p->n_points_src = 0;
    run_one(pn, p, cls, &c_all, &b_all);
    p->n_points_src = n_src;
    run_one(pn, p, cls, co, bo);
    TEST_ASSERT_EQUAL_MEMORY_MESSAGE(&c_all, co, sizeof c_all, pn->model->name);
    TEST_ASSERT_EQUAL_MEMORY_MESSAGE(&b_all, bo, sizeof b_all, pn->model->name);
}

void test_repeated_rows_are_run_once(void)
{
    static lidet_pn_t pn;
    static const uint32_t srcs[3] = {1u, 5u, 0u};
    lidet_pn_class_out_t c_hint, c_copy;
    lidet_pn_box_out_t b_hint, b_copy;
    lidet_proposal_t p;
    uint32_t i, j, cls;
    for (i = 0; i < LIDET_WEIGHTS_N_MODELS; ++i)
    {
        const lidet_pn_model_t *m = lidet_weights_models[i].model;
        const uint32_t n = m->n_points;
        TEST_ASSERT_EQUAL_INT(LIDET_OK, lidet_pn_init(&pn, m, g_scratch, sizeof g_scratch, NULL));
        for (j = 0; j < 3u; ++j)
        {
            const uint32_t n_src = srcs[j] != 0u ? srcs[j] : n - 1u;
            for (cls = 0; cls < (m->kind == LIDET_PN_BOX ? (uint32_t)LIDET_N_CLASSES : 1u); ++cls)
            {
                repeat_rows(&p, n, n_src);
                same_with_and_without_hint(&pn, &p, cls, n_src, &c_copy, &b_copy);
                /* the last row no copy: far to the right and high */
                p.xyz[n - 1u][0] = 6.0f;
                p.xyz[n - 1u][1] = -8.0f;
                p.xyz[n - 1u][2] = 2.4f;
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
    RUN_TEST(test_every_model_is_valid);
    RUN_TEST(test_scratch_macros_match);
    RUN_TEST(test_models_run);
    RUN_TEST(test_repeated_rows_are_run_once);
    return UNITY_END();
}
