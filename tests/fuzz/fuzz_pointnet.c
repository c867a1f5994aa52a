/* SPDX-License-Identifier: MIT */
/* libFuzzer harness: the PointNet forward pass with the tiny models of tests/fuzz/models:
 * lidet_pn_forward, lidet_pn_classify, lidet_pn_box, lidet_pn_to_model_frame and lidet_pn_energy on
 * points, voxels, means and classes taken raw from the input (NaN, Inf, 1e38 and denormals included).
 * Checks statuses, class and bin indices in range, probabilities in [0, 1] for finite logits. */
#include <math.h>

#include "fuzz_common.h"
#include "fuzz_models.h"

static float g_scratch[LIDET_DETECTOR_PN_SCRATCH / 4];
static float g_pts[LIDET_PROPOSAL_POINTS * 3];
static float g_out[512];
static lidet_proposal_t g_prop;

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    fz_in_t in = {data, size};
    const uint8_t which = fz_u8(&in), flags = fz_u8(&in), cls_b = fz_u8(&in);
    /* the tiny models of tests/fuzz/models: the same layer kinds and kernels as the committed ones at ~200x
     * fewer multiply-adds. The committed models are not fuzzed here: with them in, libFuzzer keeps their
     * inputs for their loop counts and spends 90 % of the time in their dense layers (2,060 against 11,600
     * executions per second); they run in the unit, determinism and sanitizer tests. */
    const lidet_pn_model_t *m = fz_tiny_model(which & 1u, (which >> 1) & 1u);
    lidet_pn_t pn;
    float voxel[3], mean[3], onehot[LIDET_N_CLASSES] = {0.0f, 0.0f, 0.0f}, cs[2];
    uint32_t i, n_out, n_pts;
    lidet_status_t st;
    FZ_CHECK(lidet_pn_check(m, 0, 0) == LIDET_OK);
    FZ_CHECK(lidet_pn_init(&pn, m, g_scratch, sizeof g_scratch, NULL) == LIDET_OK);
    for (i = 0; i < 3; ++i)
    {
        voxel[i] = fz_f32(&in);
        mean[i] = fz_f32(&in);
    }
    onehot[cls_b % LIDET_N_CLASSES] = 1.0f;
    n_pts = (flags & 1u) ? (uint32_t)(flags >> 1) : m->n_points; /* sometimes a wrong count */
    for (i = 0; i < 3u * LIDET_PROPOSAL_POINTS; ++i)
    {
        g_pts[i] = fz_f32(&in);
    }
    n_out = lidet_pn_n_outputs(m);
    FZ_CHECK(n_out > 0 && n_out <= sizeof g_out / sizeof g_out[0]);
    st = lidet_pn_forward(&pn, g_pts, n_pts, voxel, m->kind == LIDET_PN_BOX ? onehot : NULL, g_out, n_out);
    FZ_CHECK(st == (n_pts == m->n_points ? LIDET_OK : LIDET_ERR_ARG));
    FZ_CHECK(lidet_pn_forward(&pn, g_pts, m->n_points, voxel, onehot, g_out, n_out - 1u) == LIDET_ERR_ARG);
    (void)lidet_pn_energy(g_out, n_out, m->energy_t);
    /* a proposal from the same bytes, through the model frame and the decoding */
    memset(&g_prop, 0, sizeof g_prop);
    memcpy(g_prop.xyz, g_pts, sizeof g_prop.xyz);
    memcpy(g_prop.mean_m, mean, sizeof mean);
    for (i = 0; i < 3; ++i)
    {
        g_prop.voxel[i] = (int16_t)fz_u16(&in);
    }
    g_prop.n_points = n_pts;
    g_prop.n_points_src = n_pts;
    lidet_pn_to_model_frame(g_pts, m->n_points, mean, g_pts, cs);
    if (m->kind == LIDET_PN_CLASSIFIER)
    {
        lidet_pn_class_out_t co;
        st = lidet_pn_classify(&pn, &g_prop, &co);
        FZ_CHECK(st == (n_pts == m->n_points ? LIDET_OK : LIDET_ERR_ARG));
        if (st == LIDET_OK)
        {
            FZ_CHECK(co.cls < LIDET_N_CLASSES && co.pass <= 1);
            for (i = 0; i < LIDET_N_CLASSES; ++i)
            {
                FZ_CHECK(!(co.prob[i] < 0.0f) && !(co.prob[i] > 1.0f));
            }
        }
    }
    else
    {
        lidet_pn_box_out_t bo;
        st = lidet_pn_box(&pn, &g_prop, cls_b, &bo);
        FZ_CHECK(st == ((n_pts == m->n_points && cls_b < LIDET_N_CLASSES) ? LIDET_OK : LIDET_ERR_ARG));
        if (st == LIDET_OK)
        {
            FZ_CHECK(bo.heading_bin < m->n_heading_bins && bo.size_cluster < m->n_size_clusters && bo.pass <= 1);
        }
    }
    return 0;
}
