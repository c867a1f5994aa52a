/* SPDX-License-Identifier: MIT */
/* Depth clustering (see lidet_cluster.h for the algorithm and memory).
 * The numpy reference is codegen/lidet_codegen/ref/cluster.py: cluster_ref (this file) and
 * proposal_indices / make_proposal (lidet_proposal.c). */
#include <math.h>
#include <string.h>

#include "internal/lidet_assert.h"
#include "internal/lidet_math.h"
#include "lidet/lidet_cluster.h"

/* pixel states in labels[] during a run (ids 1..LIDET_MAX_CLUSTERS are slots + 1) */
#define LAB_FREE 0u         /* a candidate not visited yet */
#define LAB_PENDING 0xFFFEu /* visited: current cluster, or a dropped one */
#define LAB_NONCAND 0xFFFFu /* no point, or ground: bridged over, never joined */

#define STEPS LIDET_CLUSTER_MAX_STEPS

void lidet_cluster_cfg_default(lidet_cluster_cfg_t *cfg, const lidet_sensor_t *sensor)
{
    if (cfg == 0)
    {
        return;
    }
    memset(cfg, 0, sizeof *cfg);
    /* measured on simulated (20 + 20 scans; checked on 12 + 12 scans of other seeds) and real
     * SemanticKITTI scans, docs/BENCHMARKS.md: the 8-neighbourhood keeps the sparse, dotted returns of
     * car bodies together on every profile; a small angle joins the fragments of car bodies (grazing
     * hoods and roofs, dropouts) and the gap bound, growing with range, keeps neighbouring parked cars
     * apart (the merges the angle test alone made on real scans). Dense sensors (> 16 beams) also
     * bridge occluders; 16-beam images use one step less and no occluder rule (speed: >= 100x DBSCAN) */
    cfg->diagonals = 1;
    cfg->max_gap_m = 0.7f;
    if (sensor != 0 && sensor->n_rows <= 16)
    {
        cfg->theta_rad = 0.12f;
        cfg->max_steps = 4u;
        cfg->bridge_occluders = 0;
        cfg->max_gap_per_m = 0.04f;
    }
    else
    {
        cfg->theta_rad = 0.18f;
        cfg->max_steps = 5u;
        cfg->bridge_occluders = 1;
        cfg->max_gap_per_m = 0.025f;
    }
    cfg->max_steps = cfg->max_steps < STEPS ? cfg->max_steps : STEPS;
    cfg->min_points = 10;
    cfg->max_extent_m = 6.0f;
    cfg->max_mean_height_m = 2.5f;
    cfg->mount_height_m = sensor != 0 ? sensor->mount_height_m : 1.73f;
}

lidet_status_t lidet_cluster_init(lidet_cluster_t *c, const lidet_cluster_cfg_t *cfg)
{
    if (c == 0 || cfg == 0)
    {
        return LIDET_ERR_ARG;
    }
    c->magic = 0;
    if (!lidet__isfinite(cfg->theta_rad) || !(cfg->theta_rad > 0.0f) || !(cfg->theta_rad < 1.5f) ||
        cfg->max_steps < 1 || cfg->max_steps > STEPS || cfg->min_points < 1 ||
        !lidet__isfinite(cfg->max_extent_m) || !(cfg->max_extent_m > 0.0f) ||
        !lidet__isfinite(cfg->max_mean_height_m) || !lidet__isfinite(cfg->mount_height_m) ||
        cfg->mount_height_m < 0.0f || !lidet__isfinite(cfg->max_gap_m) || cfg->max_gap_m < 0.0f ||
        !lidet__isfinite(cfg->max_gap_per_m) || cfg->max_gap_per_m < 0.0f)
    {
        return LIDET_ERR_CONFIG;
    }
    c->cfg = *cfg;
    c->tan_theta = tanf(cfg->theta_rad);
    c->geo_rows = 0;
    c->geo_cols = 0;
    c->n_recs = 0;
    memset(&c->img, 0, sizeof c->img);
    memset(&c->stats, 0, sizeof c->stats);
    c->magic = LIDET_INIT_MAGIC;
    return LIDET_OK;
}

/* sin/cos of every alpha the search can meet; recomputed only when the image geometry changes */
static void setup_geometry(lidet_cluster_t *c, const lidet_range_image_t *img)
{
    const uint32_t rows = img->n_rows, cols = img->n_cols;
    uint32_t r, k;
    if (c->geo_rows == rows && c->geo_cols == cols &&
        memcmp(c->geo_elev, img->row_elev_rad, rows * sizeof(float)) == 0)
    {
        return;
    }
    for (k = 1; k <= STEPS; ++k)
    {
        /* k * 2pi / cols, reduced to at most pi (the two beams' angle) */
        const float a = LIDET_PI_F * 2.0f * (float)(k % cols) / (float)cols;
        const float a2 = a > LIDET_PI_F ? 2.0f * LIDET_PI_F - a : a;
        c->col_sin[k - 1] = sinf(a2);
        c->col_cos[k - 1] = cosf(a2);
    }
    for (r = 0; r < rows; ++r)
    {
        c->geo_elev[r] = img->row_elev_rad[r];
        for (k = 1; k <= STEPS; ++k)
        {
            float a = r + k < rows ? img->row_elev_rad[r] - img->row_elev_rad[r + k] : 0.0f;
            a = a < 0.0f ? -a : a;
            c->row_sin[r * STEPS + k - 1] = sinf(a);
            c->row_cos[r * STEPS + k - 1] = cosf(a);
        }
    }
    /* diagonal pairs (r, c) - (r + 1, c +- 1): cos of the angle between the two beam directions */
    {
        const float cd = cosf(2.0f * LIDET_PI_F / (float)cols);
        for (r = 0; r + 1 < rows; ++r)
        {
            const float e1 = img->row_elev_rad[r], e2 = img->row_elev_rad[r + 1];
            float cs = sinf(e1) * sinf(e2) + cosf(e1) * cosf(e2) * cd;
            cs = cs > 1.0f ? 1.0f : (cs < -1.0f ? -1.0f : cs);
            c->diag_cos[r] = cs;
            c->diag_sin[r] = sqrtf(1.0f - cs * cs);
        }
    }
    c->geo_rows = (uint16_t)rows;
    c->geo_cols = (uint16_t)cols;
}

/* beta > theta  <=>  d2 sin(a) > tan(theta) (d1 - d2 cos(a)), d1 >= d2 (true when the bracket <= 0).
 * With gap > 0 the two returns must also lie within gap + gap_per_m * d2 of each other; their
 * distance along the two beams is sqrt((d1 - d2 cos a)^2 + (d2 sin a)^2), from the same two terms
 * (no point coordinates are read) */
static inline int link(float da, float db, float gap, float sn, float cs, float tan_theta, float gap_per_m)
{
    const float d1 = da > db ? da : db;
    const float d2 = da > db ? db : da;
    const float u = d1 - d2 * cs, v = d2 * sn;
    if (!(v > tan_theta * u))
    {
        return 0;
    }
    if (gap > 0.0f)
    {
        const float g = gap + gap_per_m * d2;
        return u * u + v * v <= g * g;
    }
    return 1;
}

/* One step of a directional search that met candidate n (dq: range of the pixel being expanded). Joins n
 * when it is free and passes the test. Returns 1 when the search goes on behind n (n is a nearer
 * occluder that fails the test, with occluder bridging on), 0 when it stops there. A visited n is
 * only tested when that decides between the two (joining it again would change nothing). */
static inline int probe(lidet_cluster_t *c, float dq, uint32_t n, float sn, float cs, float tan_theta,
                        float gap, int occl, uint32_t *tail)
{
    const float dn = c->img.range_m[n];
    if (c->labels[n] != LAB_FREE)
    {
        return occl && dn < dq && !link(dq, dn, gap, sn, cs, tan_theta, c->cfg.max_gap_per_m);
    }
    if (link(dq, dn, gap, sn, cs, tan_theta, c->cfg.max_gap_per_m))
    {
        c->labels[n] = (uint16_t)LAB_PENDING;
        c->members[(*tail)++] = (int32_t)n;
        return 0;
    }
    return occl && dn < dq;
}

/* the smallest kept cluster (ties: the later seed), the one capacity drops first */
static uint32_t smallest_slot(const lidet_cluster_t *c)
{
    uint32_t i, m = 0;
    for (i = 1; i < c->n_recs; ++i)
    {
        const lidet_cluster_rec_t *a = &c->recs[i], *b = &c->recs[m];
        if (a->n_points < b->n_points || (a->n_points == b->n_points && a->seed_pixel > b->seed_pixel))
        {
            m = i;
        }
    }
    return m;
}

/* filters + bookkeeping of the cluster members[start, tail); returns the new tail */
static uint32_t finish_cluster(lidet_cluster_t *c, uint32_t start, uint32_t tail, const lidet_plane_t *planes,
                               uint32_t n_sectors, lidet_cluster_stats_t *st)
{
    const lidet_range_image_t *img = &c->img;
    const uint32_t n = tail - start;
    const int32_t *mem = c->members;
    float sum[3] = {0.0f, 0.0f, 0.0f};
    float lo[3], hi[3], mean[3], h, inv;
    uint32_t i, slot;
    lidet_cluster_rec_t *rec;

    ++st->n_found;
    if (n < c->cfg.min_points)
    {
        ++st->n_dropped_small;
        return start;
    }
    {
        const int32_t p0 = mem[start];
        lo[0] = hi[0] = img->x_m[p0];
        lo[1] = hi[1] = img->y_m[p0];
        lo[2] = hi[2] = img->z_m[p0];
    }
    {
        const float *xs = img->x_m, *ys = img->y_m, *zs = img->z_m;
        float sx = 0.0f, sy = 0.0f, sz = 0.0f;
        float lx = lo[0], ly = lo[1], lz = lo[2], hx = hi[0], hy = hi[1], hz = hi[2];
        for (i = start; i < tail; ++i)
        {
            const int32_t p = mem[i];
            const float x = xs[p], y = ys[p], z = zs[p];
            sx += x;
            sy += y;
            sz += z;
            lx = x < lx ? x : lx;
            ly = y < ly ? y : ly;
            lz = z < lz ? z : lz;
            hx = x > hx ? x : hx;
            hy = y > hy ? y : hy;
            hz = z > hz ? z : hz;
        }
        sum[0] = sx;
        sum[1] = sy;
        sum[2] = sz;
        lo[0] = lx;
        lo[1] = ly;
        lo[2] = lz;
        hi[0] = hx;
        hi[1] = hy;
        hi[2] = hz;
    }
    if (hi[0] - lo[0] > c->cfg.max_extent_m || hi[1] - lo[1] > c->cfg.max_extent_m ||
        hi[2] - lo[2] > c->cfg.max_extent_m)
    {
        ++st->n_dropped_extent;
        return start;
    }
    inv = 1.0f / (float)n;
    mean[0] = sum[0] * inv;
    mean[1] = sum[1] * inv;
    mean[2] = sum[2] * inv;
    if (planes != 0)
    {
        /* sector of the seed's column; seed < rows * cols so the product fits in 64 bits */
        const uint32_t col = (uint32_t)mem[start] % img->n_cols;
        uint32_t s = (uint32_t)(((uint64_t)col * n_sectors) / img->n_cols);
        const lidet_plane_t *pl;
        s = s < n_sectors ? s : n_sectors - 1;
        pl = &planes[s];
        h = pl->nx * mean[0] + pl->ny * mean[1] + pl->nz * mean[2] + pl->d_m;
    }
    else
    {
        h = mean[2] + c->cfg.mount_height_m;
    }
    if (!(h <= c->cfg.max_mean_height_m))
    {
        ++st->n_dropped_height;
        return start;
    }
    if (c->n_recs < LIDET_MAX_CLUSTERS)
    {
        slot = c->n_recs++;
    }
    else
    {
        /* full: the new cluster has the latest seed, so it loses every tie */
        const uint32_t m = smallest_slot(c);
        ++st->n_dropped_capacity;
        if (n <= c->recs[m].n_points)
        {
            return start;
        }
        /* evict m: its pixels become "visited, dropped"; its member range stays as a hole that the
         * final raster pass compacts away */
        for (i = c->recs[m].first_member; i < c->recs[m].first_member + c->recs[m].n_points; ++i)
        {
            c->labels[mem[i]] = (uint16_t)LAB_PENDING;
        }
        slot = m;
    }
    rec = &c->recs[slot];
    rec->n_points = n;
    rec->first_member = start;
    rec->seed_pixel = (uint32_t)mem[start];
    for (i = 0; i < 3; ++i)
    {
        rec->mean_m[i] = mean[i];
        rec->min_m[i] = lo[i];
        rec->max_m[i] = hi[i];
    }
    rec->height_m = h;
    for (i = start; i < tail; ++i)
    {
        c->labels[mem[i]] = (uint16_t)(slot + 1u);
    }
    return tail;
}

/* canonical order: records sorted by seed, labels rewritten, members regrouped in raster order */
static void canonicalise(lidet_cluster_t *c, uint32_t npix, lidet_cluster_stats_t *st)
{
    const uint32_t k = c->n_recs;
    uint32_t i, j, start;
    uint16_t *lab = c->labels;

    /* insertion sort of slots by seed: already sorted unless capacity evictions happened */
    for (i = 0; i < k; ++i)
    {
        const uint16_t s = (uint16_t)i;
        j = i;
        while (j > 0 && c->recs[c->order[j - 1]].seed_pixel > c->recs[s].seed_pixel)
        {
            c->order[j] = c->order[j - 1];
            --j;
        }
        c->order[j] = s;
    }
    c->slot_id[0] = 0;
    for (i = 0; i < k; ++i)
    {
        c->slot_id[c->order[i] + 1u] = (uint16_t)(i + 1u);
    }
    /* gather permutation recs[i] = old recs[order[i]], following cycles (order[] is consumed) */
    for (i = 0; i < k; ++i)
    {
        lidet_cluster_rec_t tmp;
        if (c->order[i] == i)
        {
            continue;
        }
        tmp = c->recs[i];
        j = i;
        for (;;)
        {
            const uint32_t src = c->order[j];
            c->order[j] = (uint16_t)j;
            if (src == i)
            {
                c->recs[j] = tmp;
                break;
            }
            c->recs[j] = c->recs[src];
            j = src;
        }
    }
    start = 0;
    for (i = 0; i < k; ++i)
    {
        c->recs[i].first_member = start; /* a write cursor during the pass below */
        start += c->recs[i].n_points;
    }
    st->n_pixels_kept = start;
    for (i = 0; i < npix; ++i)
    {
        const uint32_t l = lab[i];
        if (l == LAB_FREE || l >= LAB_PENDING)
        {
            lab[i] = 0;
        }
        else
        {
            const uint32_t id = c->slot_id[l];
            lab[i] = (uint16_t)id;
            c->members[c->recs[id - 1u].first_member++] = (int32_t)i;
        }
    }
    for (i = 0; i < k; ++i)
    {
        c->recs[i].first_member -= c->recs[i].n_points;
    }
}

lidet_status_t lidet_cluster_run(lidet_cluster_t *c, const lidet_range_image_t *img,
                                 const uint8_t *ground_mask, const lidet_plane_t *planes, uint32_t n_sectors)
{
    uint32_t rows, cols, npix, p, tail, kc, ks;
    uint16_t *lab;
    int32_t *mem;
    float tan_theta;
    int occl, diag;
    float gap, gpm;
    lidet_cluster_stats_t st;

    if (c == 0 || img == 0 || (planes != 0 && n_sectors == 0))
    {
        return LIDET_ERR_ARG;
    }
    if (c->magic != LIDET_INIT_MAGIC)
    {
        return LIDET_ERR_STATE;
    }
    rows = img->n_rows;
    cols = img->n_cols;
    if (rows < 1 || cols < 2 || rows > LIDET_MAX_ROWS || cols > LIDET_MAX_COLS)
    {
        return LIDET_ERR_BUFFER;
    }
    if (img->range_m == 0 || img->point_idx == 0 || img->row_elev_rad == 0 || img->x_m == 0 ||
        img->y_m == 0 || img->z_m == 0)
    {
        return LIDET_ERR_ARG;
    }
    npix = rows * cols;
    setup_geometry(c, img);
    c->img = *img;
    c->n_recs = 0;
    memset(&st, 0, sizeof st);
    lab = c->labels;
    mem = c->members;
    tan_theta = c->tan_theta;
    occl = c->cfg.bridge_occluders != 0;
    gap = c->cfg.max_gap_m;
    gpm = c->cfg.max_gap_per_m;
    diag = c->cfg.diagonals != 0;
    ks = c->cfg.max_steps;
    kc = ks < cols - 1 ? ks : cols - 1; /* never wrap onto itself */

    for (p = 0; p < npix; ++p)
    {
        const int cand = img->point_idx[p] >= 0 && (ground_mask == 0 || ground_mask[p] == 0);
        lab[p] = (uint16_t)(cand ? LAB_FREE : LAB_NONCAND);
        st.n_candidates += (uint32_t)cand;
    }

    tail = 0;
    for (p = 0; p < npix; ++p)
    {
        uint32_t head, start;
        if (lab[p] != LAB_FREE)
        {
            continue;
        }
        start = tail;
        head = tail;
        lab[p] = (uint16_t)LAB_PENDING;
        mem[tail++] = (int32_t)p;
        while (head < tail)
        {
            const uint32_t q = (uint32_t)mem[head++];
            const uint32_t r = q / cols, col = q - r * cols, rowbase = r * cols;
            const float dq = img->range_m[q];
            uint32_t k;
            LIDET_ASSERT(tail <= npix);
            /* right (wrapping) */
            for (k = 1; k <= kc; ++k)
            {
                uint32_t cc = col + k;
                uint32_t n;
                cc = cc >= cols ? cc - cols : cc;
                n = rowbase + cc;
                if (lab[n] == LAB_NONCAND)
                    continue;
                if (!probe(c, dq, n, c->col_sin[k - 1], c->col_cos[k - 1], tan_theta, gap, occl, &tail))
                    break;
            }
            /* left (wrapping) */
            for (k = 1; k <= kc; ++k)
            {
                const uint32_t cc = col >= k ? col - k : col + cols - k;
                const uint32_t n = rowbase + cc;
                if (lab[n] == LAB_NONCAND)
                    continue;
                if (!probe(c, dq, n, c->col_sin[k - 1], c->col_cos[k - 1], tan_theta, gap, occl, &tail))
                    break;
            }
            /* down: rows r and r + k */
            for (k = 1; k <= ks && r + k < rows; ++k)
            {
                const uint32_t n = q + k * cols;
                const uint32_t e = r * STEPS + k - 1;
                if (lab[n] == LAB_NONCAND)
                    continue;
                if (!probe(c, dq, n, c->row_sin[e], c->row_cos[e], tan_theta, gap, occl, &tail))
                    break;
            }
            /* up: rows r - k and r (the pair's entry is stored at the upper row) */
            for (k = 1; k <= ks && k <= r; ++k)
            {
                const uint32_t n = q - k * cols;
                const uint32_t e = (r - k) * STEPS + k - 1;
                if (lab[n] == LAB_NONCAND)
                    continue;
                if (!probe(c, dq, n, c->row_sin[e], c->row_cos[e], tan_theta, gap, occl, &tail))
                    break;
            }
            /* diagonals (8-neighbourhood option): direct neighbours only, no bridging */
            if (diag)
            {
                const uint32_t cl = col > 0 ? col - 1 : cols - 1, cr = col + 1 < cols ? col + 1 : 0;
                uint32_t j;
                for (j = 0; j < 4; ++j)
                {
                    const int down = j < 2;
                    uint32_t n, e;
                    if (down ? r + 1 >= rows : r == 0)
                        continue;
                    n = (down ? rowbase + cols : rowbase - cols) + ((j & 1u) ? cr : cl);
                    e = down ? r : r - 1;
                    if (lab[n] == LAB_FREE &&
                        link(dq, img->range_m[n], gap, c->diag_sin[e], c->diag_cos[e], tan_theta, gpm))
                    {
                        lab[n] = (uint16_t)LAB_PENDING;
                        mem[tail++] = (int32_t)n;
                    }
                }
            }
        }
        tail = finish_cluster(c, start, tail, planes, n_sectors, &st);
    }
    canonicalise(c, npix, &st);
    st.n_kept = c->n_recs;
    c->stats = st;
    return st.n_dropped_capacity > 0 ? LIDET_TRUNCATED : LIDET_OK;
}

const uint16_t *lidet_cluster_labels(const lidet_cluster_t *c)
{
    return c == 0 ? 0 : c->labels;
}

const lidet_cluster_rec_t *lidet_cluster_records(const lidet_cluster_t *c, uint32_t *n_clusters)
{
    if (c == 0)
    {
        return 0;
    }
    if (n_clusters != 0)
    {
        *n_clusters = c->n_recs;
    }
    return c->recs;
}

const int32_t *lidet_cluster_members(const lidet_cluster_t *c)
{
    return c == 0 ? 0 : c->members;
}

const lidet_cluster_stats_t *lidet_cluster_stats(const lidet_cluster_t *c)
{
    return c == 0 ? 0 : &c->stats;
}

lidet_status_t lidet_cluster_point_labels(const lidet_cluster_t *c, const int32_t *point_pixel,
                                          uint32_t n_points, uint32_t *out)
{
    uint32_t i, npix;
    if (c == 0 || ((point_pixel == 0 || out == 0) && n_points > 0))
    {
        return LIDET_ERR_ARG;
    }
    if (c->magic != LIDET_INIT_MAGIC || c->img.point_idx == 0)
    {
        return LIDET_ERR_STATE;
    }
    npix = (uint32_t)c->img.n_rows * c->img.n_cols;
    for (i = 0; i < n_points; ++i)
    {
        const int32_t p = point_pixel[i];
        out[i] = (p >= 0 && (uint32_t)p < npix) ? c->labels[p] : 0u;
    }
    return LIDET_OK;
}

uint32_t lidet_cluster_bytes(void)
{
    return (uint32_t)sizeof(lidet_cluster_t);
}
