/* SPDX-License-Identifier: MIT */
/* libFuzzer harness: the projection (lidet_proj_init, lidet_proj_run with and without rings, and
 * lidet_proj_run_buffers into a compact image), on any sensor geometry the input describes. Checks the
 * counts add up and every per-point pixel lies in the image; the sanitizers check the rest. */
#include "fuzz_common.h"

static lidet_proj_t g_proj;
static int32_t g_pp[LIDET_MAX_POINTS];

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    fz_in_t in = {data, size};
    fz_scan_t s;
    lidet_status_t st;
    lidet_range_image_t img, cimg;
    const lidet_proj_state_t *cst;
    const int32_t *pp;
    uint32_t i, n, n_pix;
    fz_scan_header(&in, &s);
    fz_scan_points(&in, &s);
    st = lidet_proj_init(&g_proj, &s.proj);
    if (st != LIDET_OK)
    {
        FZ_CHECK(st < 0);
        FZ_CHECK(lidet_proj_run(&g_proj, s.pts, s.n_points, s.stride, s.ring) == LIDET_ERR_STATE);
        return 0;
    }
    /* float image, standalone state */
    st = lidet_proj_run(&g_proj, s.pts, s.n_points, s.stride, s.ring);
    FZ_CHECK(st == (s.n_points > LIDET_MAX_POINTS ? LIDET_TRUNCATED : LIDET_OK));
    lidet_proj_image(&g_proj, &img);
    n_pix = (uint32_t)img.n_rows * img.n_cols;
    fz_check_proj_stats(lidet_proj_stats(&g_proj), s.n_points, n_pix);
    pp = lidet_proj_point_pixels(&g_proj, &n);
    FZ_CHECK(n == (s.n_points < LIDET_MAX_POINTS ? s.n_points : LIDET_MAX_POINTS));
    for (i = 0; i < n; ++i)
    {
        FZ_CHECK(pp[i] >= -1 && pp[i] < (int32_t)n_pix);
    }
    for (i = 0; i < n_pix; ++i)
    {
        FZ_CHECK((img.range_m[i] > 0.0f) == (img.point_idx[i] >= 0));
    }
    /* compact image into caller buffers (what a detector workspace does) */
    cst = fz_project_compact(&s, &cimg, g_pp, &st);
    FZ_CHECK(cst != NULL && LIDET_SUCCEEDED(st));
    fz_check_proj_stats(&cst->stats, s.n_points, n_pix);
    for (i = 0; i < n_pix; ++i)
    {
        FZ_CHECK((cimg.range_4mm[i] >= 1) == (cimg.point_idx[i] >= 0));
    }
    for (i = 0; i < n; ++i)
    {
        FZ_CHECK(g_pp[i] >= -1 && g_pp[i] < (int32_t)n_pix);
    }
    return 0;
}
