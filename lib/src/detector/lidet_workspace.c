/* SPDX-License-Identifier: MIT */
/* The detector workspace (see lidet_workspace.h for the memory model): the three stages run on
 * their states and on buffers placed by lifetime, the scratch of each overlaid with the others'. */
#include <string.h>

#include "internal/lidet_cluster_internal.h" /* lidet__cluster_run_edges */
#include "internal/lidet_math.h"
#include "lidet/lidet_workspace.h"

void lidet_workspace_cfg_default(lidet_workspace_cfg_t *cfg, const lidet_sensor_t *sensor)
{
    if (cfg == 0)
    {
        return;
    }
    lidet_proj_cfg_default(&cfg->proj, sensor);
    lidet_ground_cfg_default(&cfg->ground, sensor);
    lidet_cluster_cfg_default(&cfg->cluster, sensor);
}

lidet_status_t lidet_workspace_init(lidet_workspace_t *ws, const lidet_workspace_cfg_t *cfg)
{
    lidet_status_t st;
    if (ws == 0 || cfg == 0)
    {
        return LIDET_ERR_ARG;
    }
    ws->magic = 0;
    st = lidet_proj_state_init(&ws->proj, &cfg->proj);
    if (st != LIDET_OK)
    {
        return st;
    }
    st = lidet_ground_state_init(&ws->ground, &cfg->ground);
    if (st != LIDET_OK)
    {
        return st;
    }
    {
        /* a ground window works on an image with no point outside it: the projection's window must lie within it
         * (the same column rule on both, so a smaller or equal half-angle) */
        const float gw = cfg->ground.azimuth_half_rad, pw = cfg->proj.azimuth_half_rad;
        if (gw > 0.0f && gw < LIDET_PI_F && !(pw > 0.0f && pw <= gw))
        {
            return LIDET_ERR_CONFIG;
        }
    }
    {
        /* the clustering's height filter reads the ground's far planes beyond its split (the workspace passes
         * the whole plane table) */
        lidet_cluster_cfg_t ccfg = cfg->cluster;
        ccfg.plane_split_m = cfg->ground.ring_split_m;
        st = lidet_cluster_state_init(&ws->cluster, &ccfg);
    }
    if (st != LIDET_OK)
    {
        return st;
    }
    ws->magic = LIDET_INIT_MAGIC;
    return LIDET_OK;
}

/* the workspace's R plane, or NULL (the ground stage then computes R itself); and the clustering's edge plane in
 * the same memory (R is read by the ground stage alone), or NULL */
#if LIDET_WORKSPACE_KEEP_R
#define WS_RXY(ws) ((ws)->r.rxy_m)
#define WS_EDGES(ws) ((ws)->r.edges)
#else
#define WS_RXY(ws) 0
#define WS_EDGES(ws) 0
#endif

/* the image the later stages read: R for the ground stage only with LIDET_WORKSPACE_KEEP_R (else the ground stage
 * recomputes it into its scratch), never after it (the clustering writes its edge plane there); no point_idx (the
 * overlay reuses it once the projection is done) */
static void ws_image(const lidet_workspace_t *ws, lidet_range_image_t *img, int with_r)
{
    img->n_rows = ws->proj.cfg.sensor.n_rows;
    img->n_cols = ws->proj.cfg.sensor.n_cols;
    img->x_m = 0; /* a compact image */
    img->y_m = 0;
    img->z_m = 0;
    img->range_m = 0;
    img->x_4mm = ws->x_4mm;
    img->y_4mm = ws->y_4mm;
    img->z_4mm = ws->z_4mm;
    img->range_4mm = ws->range_4mm;
    img->rxy_m = 0;
    if (with_r)
    {
        img->rxy_m = WS_RXY(ws);
    }
    img->point_idx = 0;
    img->row_elev_rad = ws->proj.row_elev_rad;
    img->row_elev_bam = ws->proj.row_elev_bam;
}

lidet_status_t lidet_workspace_run(lidet_workspace_t *ws, const float *points, uint32_t n_points,
                                   uint32_t stride, const uint16_t *ring, int32_t *point_pixel)
{
    return lidet_workspace_run_timed(ws, points, n_points, stride, ring, point_pixel, 0, 0, 0);
}

static uint32_t tick(lidet_clock_fn clock, void *ctx)
{
    return clock != 0 ? clock(ctx) : 0u;
}

lidet_status_t lidet_workspace_run_timed(lidet_workspace_t *ws, const float *points, uint32_t n_points,
                                         uint32_t stride, const uint16_t *ring, int32_t *point_pixel,
                                         lidet_clock_fn clock, void *clock_ctx, uint32_t ticks[3])
{
    uint32_t t0, t1;
    uint32_t dummy[3];
    lidet_proj_buffers_t b;
    lidet_range_image_t img;
    lidet_status_t st, worst;
    if (ws == 0)
    {
        return LIDET_ERR_ARG;
    }
    if (ws->magic != LIDET_INIT_MAGIC)
    {
        return LIDET_ERR_STATE;
    }
    /* the previous scan's clusters live in the overlay: forget them before the projection reuses it */
    ws->cluster.labels = 0;
    ws->cluster.members = 0;
    ws->cluster.n_recs = 0;
    b.x_m = 0; /* a compact image */
    b.y_m = 0;
    b.z_m = 0;
    b.range_m = 0;
    b.x_4mm = ws->x_4mm;
    b.y_4mm = ws->y_4mm;
    b.z_4mm = ws->z_4mm;
    b.range_4mm = ws->range_4mm;
    b.rxy_m = WS_RXY(ws);
    b.point_idx = ws->overlay.proj_point_idx;
    b.point_pixel = point_pixel;
    if (ticks == 0)
    {
        ticks = dummy;
    }
    ticks[0] = ticks[1] = ticks[2] = 0u;
    t0 = tick(clock, clock_ctx);
    st = lidet_proj_run_buffers(&ws->proj, &b, points, n_points, stride, ring);
    t1 = tick(clock, clock_ctx);
    ticks[0] = t1 - t0;
    if (st < 0)
    {
        return st;
    }
    worst = st;
    ws_image(ws, &img, 1);
    st = lidet_ground_run_buffers(&ws->ground, &ws->overlay.ground, ws->ground_mask, &img);
    t0 = tick(clock, clock_ctx);
    ticks[1] = t0 - t1;
    if (st < 0)
    {
        return st;
    }
    worst = st > worst ? st : worst;
    ws_image(ws, &img, 0); /* R is dead: its plane takes the clustering's edges */
    st = lidet__cluster_run_edges(&ws->cluster, ws->overlay.cluster.labels, ws->overlay.cluster.members,
                                  WS_EDGES(ws), &img, ws->ground_mask, ws->ground.planes,
                                  ws->ground.cfg.n_sectors);
    ticks[2] = tick(clock, clock_ctx) - t0;
    if (st < 0)
    {
        return st;
    }
    return st > worst ? st : worst;
}

void lidet_workspace_image(const lidet_workspace_t *ws, lidet_range_image_t *img)
{
    if (ws == 0 || img == 0)
    {
        return;
    }
    ws_image(ws, img, 0);
}

const uint8_t *lidet_workspace_ground_mask(const lidet_workspace_t *ws)
{
    return ws == 0 ? 0 : ws->ground_mask;
}

const lidet_plane_t *lidet_workspace_planes(const lidet_workspace_t *ws, uint32_t *n_sectors)
{
    if (ws == 0)
    {
        return 0;
    }
    if (n_sectors != 0)
    {
        *n_sectors = ws->ground.cfg.n_sectors;
    }
    return ws->ground.planes;
}

const lidet_cluster_rec_t *lidet_workspace_clusters(const lidet_workspace_t *ws, uint32_t *n_clusters)
{
    if (ws == 0)
    {
        return 0;
    }
    if (n_clusters != 0)
    {
        *n_clusters = ws->cluster.n_recs;
    }
    return ws->cluster.recs;
}

const uint16_t *lidet_workspace_labels(const lidet_workspace_t *ws)
{
    return ws == 0 ? 0 : ws->cluster.labels;
}

const lidet_member_t *lidet_workspace_members(const lidet_workspace_t *ws)
{
    return ws == 0 ? 0 : ws->cluster.members;
}

lidet_status_t lidet_workspace_proposal(const lidet_workspace_t *ws, uint32_t cluster_index,
                                        const lidet_proposal_cfg_t *cfg, lidet_proposal_t *out)
{
    return ws == 0 ? LIDET_ERR_ARG : lidet_proposal_make_of(&ws->cluster, cluster_index, cfg, out);
}

lidet_status_t lidet_workspace_point_labels(const lidet_workspace_t *ws, const int32_t *point_pixel,
                                            uint32_t n_points, uint32_t *cluster_id, uint8_t *ground)
{
    lidet_status_t st = LIDET_OK;
    if (ws == 0 || (point_pixel == 0 && n_points > 0u))
    {
        return LIDET_ERR_ARG;
    }
    if (ws->magic != LIDET_INIT_MAGIC || ws->cluster.labels == 0)
    {
        return LIDET_ERR_STATE;
    }
    if (cluster_id != 0)
    {
        st = lidet_cluster_point_labels_of(&ws->cluster, point_pixel, n_points, cluster_id);
    }
    if (st == LIDET_OK && ground != 0)
    {
        st = lidet_ground_point_labels_of(&ws->ground, ws->ground_mask, point_pixel, n_points, ground);
    }
    return st;
}

void lidet_workspace_stats(const lidet_workspace_t *ws, lidet_workspace_stats_t *out)
{
    if (ws == 0 || out == 0)
    {
        return;
    }
    out->proj = ws->proj.stats;
    out->ground = ws->ground.stats;
    out->cluster = ws->cluster.stats;
}

uint32_t lidet_workspace_bytes(void)
{
    return (uint32_t)sizeof(lidet_workspace_t);
}

void lidet_workspace_sizes(lidet_workspace_sizes_t *out)
{
    const lidet_workspace_t *w = 0; /* sizeof only: never dereferenced */
    if (out == 0)
    {
        return;
    }
    memset(out, 0, sizeof *out);
    out->proj_state = (uint32_t)sizeof w->proj;
    out->ground_state = (uint32_t)sizeof w->ground;
    out->cluster_state = (uint32_t)sizeof w->cluster;
    out->image = (uint32_t)(sizeof w->x_4mm + sizeof w->y_4mm + sizeof w->z_4mm + sizeof w->range_4mm);
#if LIDET_WORKSPACE_KEEP_R
    out->image += (uint32_t)sizeof w->r;
#endif
    out->ground_mask = (uint32_t)sizeof w->ground_mask;
    out->overlay_proj = (uint32_t)sizeof w->overlay.proj_point_idx;
    out->overlay_ground = (uint32_t)sizeof w->overlay.ground;
    out->overlay_cluster = (uint32_t)sizeof w->overlay.cluster;
    out->overlay = (uint32_t)sizeof w->overlay;
#ifdef LIDET__WS_ALIAS_GAP
    out->alias_gap = (uint32_t)sizeof w->alias_gap;
#endif
    out->total = (uint32_t)sizeof(lidet_workspace_t);
    out->stages_standalone = lidet_proj_bytes() + lidet_ground_bytes() + lidet_cluster_bytes();
}
