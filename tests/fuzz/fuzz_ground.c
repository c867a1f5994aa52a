/* SPDX-License-Identifier: MIT */
/* libFuzzer harness: the ground stage (lidet_ground_init with fuzzed knobs, lidet_ground_run on the float
 * image of the projection or lidet_ground_run_buffers on a compact image, per-point labels). Checks the
 * mask marks only filled pixels and the planes are unit normals pointing up. */
#include <math.h>

#include "fuzz_common.h"

#define NPIX (LIDET_MAX_ROWS * LIDET_MAX_COLS)
static lidet_proj_t g_proj;
static lidet_ground_t g_ground;
static lidet_ground_state_t g_gstate;
static lidet_ground_scratch_t g_scratch;
static uint8_t g_mask[NPIX];
static uint8_t g_labels[LIDET_MAX_POINTS];

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

/* the ground knobs: integer fields from bytes (in and out of their ranges), one float field raw */
static void ground_knobs(fz_in_t *in, lidet_ground_cfg_t *c, uint8_t *compact)
{
    const uint8_t f = fz_u8(in);
    float *const fl[] = {&c->fy_max, &c->fx_max_m, &c->gate_above_m, &c->gate_below_m, &c->mount_height_m,
                         &c->confidence, &c->inlier_m, &c->max_tilt_rad, &c->max_height_dev_m, &c->ring_split_m,
                         &c->ground_m, &c->ground_m_per_m, &c->below_factor, &c->veto_slope, &c->veto_min_dz_m};
    *compact = f & 1u;
    c->fx_on_z = (f >> 1) & 1u;
    c->require_descending = (f >> 2) & 1u;
    c->height_gate = (f >> 3) & 1u;
    if (f & 0x10u)
    {
        c->veto_slope = 0.0f;
    }
    c->n_sectors = (uint16_t)(1u + fz_u8(in) % (LIDET_GROUND_MAX_SECTORS + 2u));
    c->ransac_iters = (uint16_t)(1u + fz_u8(in));
    c->sample_step = (uint16_t)(1u + fz_u8(in) % 5u);
    c->sample_col_step = (uint16_t)(1u + fz_u8(in) % 5u);
    c->eval_samples = (uint16_t)(2u + fz_u8(in));
    c->min_samples = (uint16_t)(2u + fz_u8(in) % 40u);
    c->min_inliers = (uint16_t)(2u + fz_u8(in) % 40u);
    c->refine_iters = (uint8_t)(fz_u8(in) % 12u);
    c->fallback_sectors = (uint16_t)(fz_u8(in) % 20u);
    c->seed = fz_u32(in);
    fz_poke_f32(in, fl, (uint32_t)(sizeof fl / sizeof fl[0]));
}

static void check_result(const lidet_ground_state_t *gs, const uint8_t *mask, const lidet_range_image_t *img,
                         uint32_t n_pix)
{
    uint32_t i, n_ground = 0;
    for (i = 0; i < n_pix; ++i)
    {
        const int filled = img->x_m ? img->range_m[i] > 0.0f : img->range_4mm[i] >= 1;
        FZ_CHECK(mask[i] <= 1);
        FZ_CHECK(!mask[i] || filled);
        n_ground += mask[i];
    }
    FZ_CHECK(n_ground == gs->stats.n_ground);
    for (i = 0; i < 2u * gs->cfg.n_sectors; ++i)
    {
        const lidet_plane_t *p = &gs->planes[i];
        const float len = p->nx * p->nx + p->ny * p->ny + p->nz * p->nz;
        FZ_CHECK(p->nz > 0.0f && fabsf(len - 1.0f) < 1e-3f);
        FZ_CHECK(gs->source[i] <= LIDET_GROUND_PLANE_NEAR);
    }
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    fz_in_t in = {data, size};
    fz_scan_t s;
    lidet_ground_cfg_t gcfg;
    lidet_range_image_t img;
    lidet_status_t st;
    uint8_t compact;
    uint32_t n_pix, n;
    const int32_t *pp;
    fz_scan_header(&in, &s);
    lidet_ground_cfg_default(&gcfg, &s.sensor);
    ground_knobs(&in, &gcfg, &compact);
    fz_scan_points(&in, &s);
    if (lidet_proj_init(&g_proj, &s.proj) != LIDET_OK)
    {
        return 0;
    }
    st = lidet_ground_init(&g_ground, &gcfg);
    if (st != LIDET_OK)
    {
        FZ_CHECK(st < 0);
        return 0;
    }
    FZ_CHECK(LIDET_SUCCEEDED(lidet_proj_run(&g_proj, s.pts, s.n_points, s.stride, s.ring)));
    if (!compact)
    {
        lidet_proj_image(&g_proj, &img);
        n_pix = (uint32_t)img.n_rows * img.n_cols;
        st = lidet_ground_run(&g_ground, &img);
        if (st == LIDET_ERR_CONFIG) /* fewer columns than sectors */
        {
            FZ_CHECK(gcfg.n_sectors > img.n_cols);
            return 0;
        }
        FZ_CHECK(LIDET_SUCCEEDED(st));
        check_result(&g_ground.state, lidet_ground_mask(&g_ground), &img, n_pix);
        pp = lidet_proj_point_pixels(&g_proj, &n);
        FZ_CHECK(lidet_ground_point_labels(&g_ground, pp, n, g_labels) == LIDET_OK);
        return 0;
    }
    {
        FZ_CHECK(fz_project_compact(&s, &img, NULL, &st) != NULL && LIDET_SUCCEEDED(st));
        n_pix = (uint32_t)img.n_rows * img.n_cols;
        FZ_CHECK(lidet_ground_state_init(&g_gstate, &gcfg) == LIDET_OK);
        st = lidet_ground_run_buffers(&g_gstate, &g_scratch, g_mask, &img);
        if (st == LIDET_ERR_CONFIG)
        {
            FZ_CHECK(gcfg.n_sectors > img.n_cols);
            return 0;
        }
        FZ_CHECK(LIDET_SUCCEEDED(st));
        check_result(&g_gstate, g_mask, &img, n_pix);
    }
    return 0;
}
