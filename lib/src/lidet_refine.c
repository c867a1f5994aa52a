/* SPDX-License-Identifier: MIT */
/* Proposal refinement after the clustering (issue 15; the rule is written in lidet_cluster.h, cfg
 * split_people): people standing 0.2-1 m apart, or beside a car, a pole or a wall, come out of the depth
 * clustering as one cluster. A cluster wider than one person is drawn on a finer bird's-eye-view grid
 * and its person-sized connected parts are cut off into clusters of their own.
 *
 * Runs on the canonical output of the clustering (each cluster's members contiguous, in raster order)
 * and leaves labels and records for one more canonical pass (lidet_cluster.c). Bounded: per examined
 * cluster O(members + cells) with cells <= LIDET_REFINE_MAX_CELLS and parts <= LIDET_REFINE_MAX_PARTS
 * (a cluster needing more is left whole and counted); all scratch is in the state. Deterministic: parts
 * are numbered in the order of the cluster's members, cells filled breadth-first. Decisions use
 * subtractions, one product by the inverse cell size, truncation to a cell index and compares: the
 * integer build does the same in 4 mm steps. The numpy reference is refine_ref in
 * codegen/lidet_codegen/ref/cluster.py. */
#include <string.h>

#include "internal/lidet_cluster_internal.h"

#define CELL_OCC 0xFFFFu

/* cell of member pixel p: its x, y relative to the box corner, times the inverse cell, truncated and
 * clamped to the grid */
static inline uint32_t cell_of(const lidet_range_image_t *img, uint32_t p, const float lo[2], float inv, uint32_t nx,
                               uint32_t ny)
{
    float x, y, z;
    uint32_t ix, iy;
    lidet__img_xyz(img, p, lidet__img_compact(img), &x, &y, &z);
    ix = (uint32_t)((x - lo[0]) * inv);
    iy = (uint32_t)((y - lo[1]) * inv);
    ix = ix < nx ? ix : nx - 1u;
    iy = iy < ny ? iy : ny - 1u;
    return iy * nx + ix;
}

/* 8-connected parts of the occupied cells, numbered in the order their first member is met. Returns
 * the number of parts, or 0 when there are more than LIDET_REFINE_MAX_PARTS */
static uint32_t label_parts(lidet_cluster_state_t *c, uint32_t n, uint32_t nx, uint32_t ny)
{
    uint16_t *grid = c->rf_grid, *q = c->rf_queue;
    uint32_t i, n_parts = 0;
    for (i = 0; i < n; ++i)
    {
        const uint32_t cell = c->rf_cell[i];
        uint32_t head = 0, tail = 0;
        if (grid[cell] != CELL_OCC)
        {
            continue; /* already in a part */
        }
        if (n_parts == LIDET_REFINE_MAX_PARTS)
        {
            return 0;
        }
        grid[cell] = (uint16_t)(n_parts + 1u);
        q[tail++] = (uint16_t)cell;
        while (head < tail)
        {
            const uint32_t cc = q[head++], cx = cc % nx, cy = cc / nx;
            const uint32_t x0 = cx > 0u ? cx - 1u : 0u, x1 = cx + 1u < nx ? cx + 1u : cx;
            const uint32_t y0 = cy > 0u ? cy - 1u : 0u, y1 = cy + 1u < ny ? cy + 1u : cy;
            uint32_t xx, yy;
            for (yy = y0; yy <= y1; ++yy)
            {
                for (xx = x0; xx <= x1; ++xx)
                {
                    const uint32_t nb = yy * nx + xx;
                    if (grid[nb] == CELL_OCC)
                    {
                        grid[nb] = (uint16_t)(n_parts + 1u);
                        q[tail++] = (uint16_t)nb;
                    }
                }
            }
        }
        ++n_parts;
    }
    return n_parts;
}

/* record of the members of cluster `src` (contiguous range) now labelled `slot` + 1 */
static void rebuild(lidet_cluster_state_t *c, uint32_t slot, const lidet_cluster_rec_t *src, const lidet_plane_t *planes,
                    uint32_t n_sectors)
{
    lidet_cluster_rec_t *r = &c->recs[slot];
    const int compact = lidet__img_compact(&c->img);
    float sum[3] = {0.0f, 0.0f, 0.0f}, lo[3] = {0.0f, 0.0f, 0.0f}, hi[3] = {0.0f, 0.0f, 0.0f};
    uint32_t i, n = 0, seed = 0;
    for (i = src->first_member; i < src->first_member + src->n_points; ++i)
    {
        const uint32_t p = (uint32_t)c->members[i];
        float v[3];
        uint32_t k;
        if (c->labels[p] != slot + 1u)
        {
            continue;
        }
        lidet__img_xyz(&c->img, p, compact, &v[0], &v[1], &v[2]);
        if (n == 0u)
        {
            seed = p;
            for (k = 0; k < 3u; ++k)
            {
                lo[k] = v[k];
                hi[k] = v[k];
            }
        }
        for (k = 0; k < 3u; ++k)
        {
            sum[k] += v[k];
            lo[k] = v[k] < lo[k] ? v[k] : lo[k];
            hi[k] = v[k] > hi[k] ? v[k] : hi[k];
        }
        ++n;
    }
    r->n_points = n;
    r->first_member = src->first_member; /* rewritten by the canonical pass */
    r->seed_pixel = seed;
    for (i = 0; i < 3u; ++i)
    {
        r->mean_m[i] = sum[i] / (float)n;
        r->min_m[i] = lo[i];
        r->max_m[i] = hi[i];
    }
    r->height_m = lidet__cluster_height(c, seed, r->mean_m, planes, n_sectors);
}

/* cut cluster k; returns 1 when it was cut */
static int split_one(lidet_cluster_state_t *c, uint32_t k, const lidet_plane_t *planes, uint32_t n_sectors,
                     lidet_cluster_stats_t *st)
{
    const lidet_cluster_cfg_t *cfg = &c->cfg;
    const lidet_cluster_rec_t rec = c->recs[k]; /* a copy: recs[k] is rebuilt below */
    const float ex = rec.max_m[0] - rec.min_m[0], ey = rec.max_m[1] - rec.min_m[1];
    float ax, ay, r, cs, inv, lo[2];
    uint32_t nx, ny, n_parts, i, p, largest, largest_person, n_stay, n_new;
    int any_person = 0, all_person = 1;

    /* examined: wider than one person. Two early outs that change no decision, only the time: a cut
     * needs two parts of min_points each, and no part spans more in z than the whole (measured: a limit
     * on the cluster's height, skipping walls and trees, saved no time and lost people beside poles) */
    if ((!(ex > cfg->split_min_width_m) && !(ey > cfg->split_min_width_m)) || rec.n_points < 2u * cfg->min_points ||
        rec.n_points > LIDET_REFINE_MAX_POINTS ||
        !(rec.max_m[2] - rec.min_m[2] >= cfg->person_min_height_m))
    {
        return 0;
    }
    ax = 0.5f * (rec.min_m[0] + rec.max_m[0]);
    ay = 0.5f * (rec.min_m[1] + rec.max_m[1]);
    ax = ax < 0.0f ? -ax : ax;
    ay = ay < 0.0f ? -ay : ay;
    r = ax > ay ? ax + 0.5f * ay : ay + 0.5f * ax;
    cs = cfg->split_cell_m + cfg->split_cell_per_m * r;
    inv = 1.0f / cs;
    nx = (uint32_t)(ex * inv) + 1u;
    ny = (uint32_t)(ey * inv) + 1u;
    if (nx > LIDET_REFINE_MAX_CELLS || ny > LIDET_REFINE_MAX_CELLS / nx)
    {
        ++st->n_split_skipped;
        return 0;
    }
    lo[0] = rec.min_m[0];
    lo[1] = rec.min_m[1];
    memset(c->rf_grid, 0, (size_t)nx * ny * sizeof c->rf_grid[0]);
    for (i = 0; i < rec.n_points; ++i)
    {
        const uint32_t cell = cell_of(&c->img, (uint32_t)c->members[rec.first_member + i], lo, inv, nx, ny);
        c->rf_cell[i] = (uint16_t)cell;
        c->rf_grid[cell] = (uint16_t)CELL_OCC;
    }
    n_parts = label_parts(c, rec.n_points, nx, ny);
    if (n_parts == 0u)
    {
        ++st->n_split_skipped;
        return 0;
    }
    if (n_parts == 1u)
    {
        return 0;
    }
    for (p = 0; p < n_parts; ++p)
    {
        c->rf_n[p] = 0;
        c->rf_box[p][0] = 0xFFFFu;
        c->rf_box[p][1] = 0;
        c->rf_box[p][2] = 0xFFFFu;
        c->rf_box[p][3] = 0;
        c->rf_z[p][0] = 3.0e38f;
        c->rf_z[p][1] = -3.0e38f;
        c->rf_col[p][0] = 0xFFFFu;
        c->rf_col[p][1] = 0;
    }
    for (i = 0; i < rec.n_points; ++i)
    {
        const uint32_t px = (uint32_t)c->members[rec.first_member + i];
        const uint32_t cell = c->rf_cell[i], cx = cell % nx, cy = cell / nx;
        const uint32_t q = c->rf_grid[cell] - 1u;
        const float z = lidet__img_z(&c->img, px);
        const uint32_t col = px % c->img.n_cols;
        ++c->rf_n[q];
        c->rf_box[q][0] = (uint16_t)(cx < c->rf_box[q][0] ? cx : c->rf_box[q][0]);
        c->rf_box[q][1] = (uint16_t)(cx > c->rf_box[q][1] ? cx : c->rf_box[q][1]);
        c->rf_box[q][2] = (uint16_t)(cy < c->rf_box[q][2] ? cy : c->rf_box[q][2]);
        c->rf_box[q][3] = (uint16_t)(cy > c->rf_box[q][3] ? cy : c->rf_box[q][3]);
        c->rf_z[q][0] = z < c->rf_z[q][0] ? z : c->rf_z[q][0];
        c->rf_z[q][1] = z > c->rf_z[q][1] ? z : c->rf_z[q][1];
        c->rf_col[q][0] = (uint16_t)(col < c->rf_col[q][0] ? col : c->rf_col[q][0]);
        c->rf_col[q][1] = (uint16_t)(col > c->rf_col[q][1] ? col : c->rf_col[q][1]);
    }
    /* person-sized parts leave (target 1), the rest stays (target 0); ties of size: the first part */
    largest = 0;
    largest_person = n_parts;
    for (p = 0; p < n_parts; ++p)
    {
        const float wx = (float)(c->rf_box[p][1] - c->rf_box[p][0] + 1u) * cs;
        const float wy = (float)(c->rf_box[p][3] - c->rf_box[p][2] + 1u) * cs;
        const float wz = c->rf_z[p][1] - c->rf_z[p][0];
        const int person = c->rf_n[p] >= cfg->min_points && wx <= cfg->person_max_width_m &&
                           wy <= cfg->person_max_width_m && wz >= cfg->person_min_height_m &&
                           wz >= cfg->person_min_aspect * (wx > wy ? wx : wy) &&
                           (uint32_t)(c->rf_col[p][1] - c->rf_col[p][0]) + 1u >= cfg->person_min_cols;
        c->rf_target[p] = (uint16_t)(person ? 1u : 0u);
        any_person |= person;
        if (c->rf_n[p] >= cfg->min_points)
        {
            all_person &= person;
        }
        largest = c->rf_n[p] > c->rf_n[largest] ? p : largest;
        if (person && (largest_person == n_parts || c->rf_n[p] > c->rf_n[largest_person]))
        {
            largest_person = p;
        }
    }
    if (!any_person)
    {
        return 0;
    }
    if (all_person)
    {
        c->rf_target[largest] = 0;
    }
    n_stay = 0;
    for (p = 0; p < n_parts; ++p)
    {
        n_stay += c->rf_target[p] == 0u ? c->rf_n[p] : 0u;
    }
    if (n_stay < cfg->min_points)
    {
        c->rf_target[largest_person] = 0;
    }
    /* slots: 0 -> k, leaving parts -> free slots in part order (none free: it stays) */
    n_new = 0;
    for (p = 0; p < n_parts; ++p)
    {
        if (c->rf_target[p] == 0u)
        {
            c->rf_target[p] = (uint16_t)k;
        }
        else if (c->n_recs < LIDET_MAX_CLUSTERS)
        {
            c->rf_target[p] = (uint16_t)c->n_recs++;
            ++n_new;
        }
        else
        {
            c->rf_target[p] = (uint16_t)k; /* no free slot: it stays */
        }
    }
    if (n_new == 0u)
    {
        return 0;
    }
    for (i = 0; i < rec.n_points; ++i)
    {
        c->labels[c->members[rec.first_member + i]] = (uint16_t)(c->rf_target[c->rf_grid[c->rf_cell[i]] - 1u] + 1u);
    }
    rebuild(c, k, &rec, planes, n_sectors);
    c->recs[k].n_rescued = rec.n_rescued < c->recs[k].n_points ? rec.n_rescued : c->recs[k].n_points;
    for (p = 0; p < n_parts; ++p)
    {
        if (c->rf_target[p] != k)
        {
            rebuild(c, c->rf_target[p], &rec, planes, n_sectors);
            c->recs[c->rf_target[p]].n_rescued = 0;
        }
    }
    c->order[k] = 1u; /* cut: no join */
    for (p = 0; p < n_parts; ++p)
    {
        c->order[c->rf_target[p]] = 1u;
    }
    ++st->n_split;
    st->n_split_parts += n_new;
    return 1;
}

int lidet__refine_split(lidet_cluster_state_t *c, const lidet_plane_t *planes, uint32_t n_sectors,
                        lidet_cluster_stats_t *st)
{
    const uint32_t k0 = c->n_recs;
    uint32_t k;
    int changed = 0;
    for (k = 0; k < k0; ++k)
    {
        changed |= split_one(c, k, planes, n_sectors, st);
    }
    return changed;
}

/* a join candidate by its own box: not upright (a person, a cyclist, a pole: narrow in x and y, tall),
 * and it fits a car */
static int car_piece(const lidet_cluster_cfg_t *cfg, const lidet_cluster_rec_t *r)
{
    const float wx = r->max_m[0] - r->min_m[0], wy = r->max_m[1] - r->min_m[1], wz = r->max_m[2] - r->min_m[2];
    const int upright = wx <= cfg->upright_max_width_m && wy <= cfg->upright_max_width_m && wz >= cfg->person_min_height_m;
    return !upright && wz <= cfg->car_max_height_m && (wx > wy ? wx : wy) <= cfg->car_max_length_m &&
           (wx > wy ? wy : wx) <= cfg->car_max_width_m;
}

/* can cluster b join a (boxes): near enough, and the union fits a car */
static int joinable(const lidet_cluster_cfg_t *cfg, const lidet_cluster_rec_t *a, const lidet_cluster_rec_t *b)
{
    float gx = b->min_m[0] - a->max_m[0], gy = b->min_m[1] - a->max_m[1], ux, uy, uz, lo, hi;
    const float g2 = cfg->join_gap_m * cfg->join_gap_m;
    gx = a->min_m[0] - b->max_m[0] > gx ? a->min_m[0] - b->max_m[0] : gx;
    gy = a->min_m[1] - b->max_m[1] > gy ? a->min_m[1] - b->max_m[1] : gy;
    gx = gx > 0.0f ? gx : 0.0f;
    gy = gy > 0.0f ? gy : 0.0f;
    if (gx * gx + gy * gy > g2)
    {
        return 0;
    }
    lo = a->min_m[0] < b->min_m[0] ? a->min_m[0] : b->min_m[0];
    hi = a->max_m[0] > b->max_m[0] ? a->max_m[0] : b->max_m[0];
    ux = hi - lo;
    lo = a->min_m[1] < b->min_m[1] ? a->min_m[1] : b->min_m[1];
    hi = a->max_m[1] > b->max_m[1] ? a->max_m[1] : b->max_m[1];
    uy = hi - lo;
    lo = a->min_m[2] < b->min_m[2] ? a->min_m[2] : b->min_m[2];
    hi = a->max_m[2] > b->max_m[2] ? a->max_m[2] : b->max_m[2];
    uz = hi - lo;
    return uz <= cfg->car_max_height_m && (ux > uy ? ux : uy) <= cfg->car_max_length_m &&
           (ux > uy ? ux : uy) >= cfg->car_min_length_m && (ux > uy ? uy : ux) <= cfg->car_max_width_m;
}

#define JOIN_PIECE 4u

int lidet__refine_join(lidet_cluster_state_t *c, const lidet_plane_t *planes, uint32_t n_sectors,
                       lidet_cluster_stats_t *st)
{
    const lidet_cluster_cfg_t *cfg = &c->cfg;
    const uint32_t k = c->n_recs;
    uint32_t i, j, n_joined = 0, n_pieces = 0;
    /* order[]: 1 = cut by the split, 2 = joined into an earlier cluster, JOIN_PIECE = a car piece within the
     * budget. A record changes only at its own turn (it takes) or when it is taken (then it is skipped), so
     * whether it is a car piece is decided once, here, as the pair loop would decide it at its turn */
    for (i = 0; i < k; ++i)
    {
        if (c->order[i] == 0u && car_piece(cfg, &c->recs[i]))
        {
            if (cfg->max_join_pieces != 0u && n_pieces >= cfg->max_join_pieces)
            {
                ++st->n_join_skipped;
                continue;
            }
            c->order[i] = JOIN_PIECE;
            ++n_pieces;
        }
    }
    for (i = 0; i < k; ++i)
    {
        lidet_cluster_rec_t *a = &c->recs[i];
        if (c->order[i] != JOIN_PIECE)
        {
            continue;
        }
        for (j = i + 1u; j < k; ++j)
        {
            lidet_cluster_rec_t *b = &c->recs[j];
            uint32_t d, m;
            float inv;
            if (c->order[j] != JOIN_PIECE || !joinable(cfg, a, b))
            {
                continue;
            }
            /* b joins a: count, bounds, mean (float, weighted), seed, height. b was neither cut nor has it
             * taken anything (later clusters take only at their own turn), so its record is the canonical
             * one: its members are members[first_member, + n_points) */
            inv = 1.0f / (float)(a->n_points + b->n_points);
            for (d = 0; d < 3u; ++d)
            {
                a->mean_m[d] = (a->mean_m[d] * (float)a->n_points + b->mean_m[d] * (float)b->n_points) * inv;
                a->min_m[d] = b->min_m[d] < a->min_m[d] ? b->min_m[d] : a->min_m[d];
                a->max_m[d] = b->max_m[d] > a->max_m[d] ? b->max_m[d] : a->max_m[d];
            }
            for (m = b->first_member; m < b->first_member + b->n_points; ++m)
            {
                c->labels[c->members[m]] = (uint16_t)(i + 1u);
            }
            a->n_points += b->n_points;
            a->n_rescued += b->n_rescued;
            a->seed_pixel = b->seed_pixel < a->seed_pixel ? b->seed_pixel : a->seed_pixel;
            a->height_m = lidet__cluster_height(c, a->seed_pixel, a->mean_m, planes, n_sectors);
            /* b is left empty with the largest seed: the canonical pass puts it last, then it is dropped */
            b->n_points = 0;
            b->seed_pixel = 0xFFFFFFFFu;
            c->order[j] = 2u;
            ++n_joined;
        }
    }
    st->n_joined += n_joined;
    return n_joined > 0u;
}
