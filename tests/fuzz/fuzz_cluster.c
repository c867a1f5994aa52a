/* SPDX-License-Identifier: MIT */
/* libFuzzer harness: the clustering (lidet_cluster_init with fuzzed knobs, lidet_cluster_run on the
 * projection's float image or a compact one, with the ground stage's mask and planes, or none), and,
 * built with FZ_PROPOSALS=1 (harness fuzz_proposal), the proposals of every kept cluster with a fuzzed
 * lidet_proposal_cfg_t, and lidet_proposal_indices. Checks labels, records and members agree. */
#include <math.h>

#include "fuzz_common.h"

#ifndef FZ_PROPOSALS
#define FZ_PROPOSALS 0
#endif

#define NPIX (LIDET_MAX_ROWS * LIDET_MAX_COLS)
static lidet_proj_t g_proj;
static lidet_ground_t g_ground;
static lidet_cluster_t g_cl;
static lidet_cluster_state_t g_cstate;
static uint16_t g_labels[NPIX];
static lidet_member_t g_members[NPIX];
static uint32_t g_point_labels[LIDET_MAX_POINTS];
#if FZ_PROPOSALS
static lidet_proposal_t g_prop;
static uint32_t g_indices[LIDET_PROPOSAL_POINTS + 8];
#endif

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static void cluster_knobs(fz_in_t *in, lidet_cluster_cfg_t *c, uint8_t *mode)
{
    float *const fl[] = {&c->theta_rad, &c->max_gap_m, &c->max_gap_per_m, &c->max_extent_m, &c->max_mean_height_m,
                         &c->mount_height_m, &c->rescue_gap_m, &c->rescue_gap_per_m,
                         &c->max_bridge_per_pixel};
    const uint8_t f = fz_u8(in);
    *mode = f & 3u; /* 0: float image + ground stage, 1: float image, no ground, 2: compact + ground, 3: compact */
    c->bridge_occluders = (f >> 2) & 1u;
    c->diagonals = (f >> 3) & 1u;
    if (f & 0x10u)
    {
        c->rescue_gap_m = 0.0f;
    }
    c->max_steps = fz_u8(in) % (LIDET_CLUSTER_MAX_STEPS + 2u);
    c->min_points = fz_u8(in) % 24u;
    c->rescue_rows = fz_u8(in) % 6u;
    c->rescue_cols = fz_u8(in) % 18u;
    c->max_fragment_pixels = 8u * fz_u8(in); /* 0: no budget */
    c->max_join_pieces = fz_u8(in) % 8u; /* 0: no budget */
    if (f & 0x20u)
    {
        /* the regrowth of over-extent components (off by default on these images of <= 8 rows) and its cut: gap
         * 0-2.55 m, cut 0-2 m above the ground plane, at most 8 x byte pixels (0: any) */
        c->regrow_gap_m = 0.01f * (float)fz_u8(in);
        c->regrow_gap_per_m = 0.02f;
        c->regrow_cut_m = 0.01f * (float)(fz_u8(in) % 201u);
        c->regrow_max_pixels = 8u * fz_u8(in);
    }
    fz_poke_f32(in, fl, (uint32_t)(sizeof fl / sizeof fl[0]));
}

static void check_clusters(const lidet_cluster_state_t *cs, const uint16_t *labels, const lidet_member_t *members,
                           uint32_t n_pix)
{
    uint32_t i, k, total = 0;
    FZ_CHECK(cs->n_recs == cs->stats.n_kept && cs->n_recs <= LIDET_MAX_CLUSTERS);
    for (i = 0; i < n_pix; ++i)
    {
        FZ_CHECK(labels[i] <= cs->n_recs);
    }
    for (k = 0; k < cs->n_recs; ++k)
    {
        const lidet_cluster_rec_t *r = &cs->recs[k];
        FZ_CHECK(r->n_points >= 1 && r->first_member == total);
        for (i = 0; i < r->n_points; ++i)
        {
            const int32_t px = (int32_t)members[r->first_member + i];
            FZ_CHECK(px >= 0 && (uint32_t)px < n_pix && labels[px] == k + 1u);
            FZ_CHECK(i == 0 || px > members[r->first_member + i - 1]);
        }
        total += r->n_points;
    }
    FZ_CHECK(total == cs->stats.n_pixels_kept);
}

#if FZ_PROPOSALS
typedef struct
{
    lidet_proposal_cfg_t cfg;
    uint32_t n_src, n_out; /* lidet_proposal_indices alone */
} proposal_knobs_t;

static void proposal_knobs(fz_in_t *in, proposal_knobs_t *k)
{
    float *const fl[] = {&k->cfg.azimuth_bin_rad, &k->cfg.elevation_bin_rad, &k->cfg.range_bin_m};
    lidet_proposal_cfg_default(&k->cfg);
    k->cfg.n_points = fz_u16(in) % (LIDET_PROPOSAL_POINTS + 3u);
    k->cfg.seed = fz_u32(in);
    fz_poke_f32(in, fl, 3u);
    k->n_src = fz_u32(in) % (NPIX + 1u); /* members of g_members (the last run's, or what the buffer holds) */
    k->n_out = fz_u16(in) % (LIDET_PROPOSAL_POINTS + 8u);
}

static void proposals(const proposal_knobs_t *pk, const lidet_cluster_state_t *cs)
{
    uint32_t k, i;
    lidet_status_t st;
    for (k = 0; k <= cs->n_recs; ++k) /* one past the last: LIDET_ERR_ARG */
    {
        st = lidet_proposal_make_of(cs, k, &pk->cfg, &g_prop);
        if (k == cs->n_recs) /* the configuration is checked first */
        {
            FZ_CHECK(st == LIDET_ERR_ARG || st == LIDET_ERR_CONFIG);
            break;
        }
        if (st != LIDET_OK)
        {
            FZ_CHECK(st == LIDET_ERR_CONFIG);
            break;
        }
        FZ_CHECK(g_prop.n_points == pk->cfg.n_points && g_prop.n_points_src == cs->recs[k].n_points);
    }
    st = lidet_proposal_indices(g_members, pk->n_src, pk->n_out, pk->cfg.seed, g_indices);
    FZ_CHECK(st == ((pk->n_src == 0 || pk->n_out == 0) ? LIDET_ERR_ARG : LIDET_OK));
    for (i = 0; st == LIDET_OK && i < pk->n_out; ++i)
    {
        FZ_CHECK(g_indices[i] < pk->n_src);
        /* a large cluster: one member of each stratum */
        FZ_CHECK(pk->n_src <= pk->n_out ||
                 (g_indices[i] >= (uint32_t)((uint64_t)i * pk->n_src / pk->n_out) &&
                  g_indices[i] < (uint32_t)((uint64_t)(i + 1u) * pk->n_src / pk->n_out)));
    }
    st = lidet_proposal_indices(0, pk->n_src, pk->n_out, pk->cfg.seed, g_indices); /* no pixels */
    FZ_CHECK(st == ((pk->n_src == 0 || pk->n_out == 0 || pk->n_src > pk->n_out) ? LIDET_ERR_ARG : LIDET_OK));
}
#endif

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    fz_in_t in = {data, size};
    fz_scan_t s;
    lidet_cluster_cfg_t ccfg;
    lidet_ground_cfg_t gcfg;
    lidet_range_image_t img;
    lidet_status_t st;
    uint8_t mode;
    const uint8_t *mask = NULL;
    const lidet_plane_t *planes = NULL;
    uint32_t n_sectors = 0, n_pix, n;
    const int32_t *pp;
    fz_scan_header(&in, &s);
    lidet_cluster_cfg_default(&ccfg, &s.sensor);
    lidet_ground_cfg_default(&gcfg, &s.sensor);
    if (gcfg.n_sectors > LIDET_GROUND_MAX_SECTORS)
    {
        gcfg.n_sectors = LIDET_GROUND_MAX_SECTORS;
    }
    cluster_knobs(&in, &ccfg, &mode);
#if FZ_PROPOSALS
    proposal_knobs_t pk;
    proposal_knobs(&in, &pk);
#endif
    fz_scan_points(&in, &s);
    if (lidet_proj_init(&g_proj, &s.proj) != LIDET_OK || lidet_ground_init(&g_ground, &gcfg) != LIDET_OK)
    {
        return 0;
    }
    st = lidet_cluster_init(&g_cl, &ccfg);
    if (st != LIDET_OK)
    {
        FZ_CHECK(st < 0);
        return 0;
    }
    if (mode < 2)
    {
        FZ_CHECK(LIDET_SUCCEEDED(lidet_proj_run(&g_proj, s.pts, s.n_points, s.stride, s.ring)));
        lidet_proj_image(&g_proj, &img);
    }
    else
    {
        FZ_CHECK(fz_project_compact(&s, &img, NULL, &st) != NULL && LIDET_SUCCEEDED(st));
    }
    n_pix = (uint32_t)img.n_rows * img.n_cols;
    if ((mode & 1u) == 0 && LIDET_SUCCEEDED(lidet_ground_run(&g_ground, &img)))
    {
        mask = lidet_ground_mask(&g_ground);
        planes = lidet_ground_planes(&g_ground, &n_sectors);
    }
    st = lidet_cluster_run(&g_cl, &img, mask, planes, n_sectors);
    if (img.n_cols < 2)
    {
        FZ_CHECK(st == LIDET_ERR_BUFFER);
        return 0;
    }
    FZ_CHECK(st == LIDET_OK || st == LIDET_TRUNCATED);
    FZ_CHECK((st == LIDET_TRUNCATED) == (g_cl.state.stats.n_dropped_capacity > 0));
    check_clusters(&g_cl.state, lidet_cluster_labels(&g_cl), lidet_cluster_members(&g_cl), n_pix);
    if (mode < 2)
    {
        pp = lidet_proj_point_pixels(&g_proj, &n);
        FZ_CHECK(lidet_cluster_point_labels(&g_cl, pp, n, g_point_labels) == LIDET_OK);
    }
    /* the same run into caller buffers gives the same labels */
    FZ_CHECK(lidet_cluster_state_init(&g_cstate, &ccfg) == LIDET_OK);
    FZ_CHECK(lidet_cluster_run_buffers(&g_cstate, g_labels, g_members, &img, mask, planes, n_sectors) == st);
    FZ_CHECK(memcmp(g_labels, lidet_cluster_labels(&g_cl), n_pix * sizeof(uint16_t)) == 0);
    check_clusters(&g_cstate, g_labels, g_members, n_pix);
#if FZ_PROPOSALS
    proposals(&pk, &g_cstate);
#endif
    return 0;
}
