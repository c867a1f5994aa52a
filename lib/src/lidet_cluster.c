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
#define LAB_SMALL 0xFFFDu   /* a fragment (component below min_points) waiting for the rescue pass */
#define LAB_PENDING 0xFFFEu /* visited: current cluster, or a dropped one */
#define LAB_NONCAND 0xFFFFu /* no point, or ground: bridged over, never joined */

#define STEPS LIDET_CLUSTER_MAX_STEPS
#define RESCUE_MAX_COLS 15u /* rescue_cols limit (each fragment pixel looks at (2 rows + 1)(2 cols + 1) pixels) */

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
    /* measured (docs/BENCHMARKS.md): see lidet_cluster.h */
    cfg->rescue_gap_m = 0.8f;
    cfg->rescue_gap_per_m = 0.03f;
    cfg->rescue_rows = sensor != 0 && sensor->n_rows <= 16 ? 1u : 2u;
    cfg->rescue_cols = 6u;
}

lidet_status_t lidet_cluster_state_init(lidet_cluster_state_t *c, const lidet_cluster_cfg_t *cfg)
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
        !lidet__isfinite(cfg->max_gap_per_m) || cfg->max_gap_per_m < 0.0f ||
        !lidet__isfinite(cfg->rescue_gap_m) || cfg->rescue_gap_m < 0.0f ||
        !lidet__isfinite(cfg->rescue_gap_per_m) || cfg->rescue_gap_per_m < 0.0f ||
        cfg->rescue_rows > LIDET_MAX_ROWS || cfg->rescue_cols > RESCUE_MAX_COLS)
    {
        return LIDET_ERR_CONFIG;
    }
    c->cfg = *cfg;
    c->tan_theta = tanf(cfg->theta_rad);
    c->geo_rows = 0;
    c->geo_cols = 0;
    c->n_recs = 0;
    c->labels = 0;
    c->members = 0;
    memset(&c->img, 0, sizeof c->img);
    memset(&c->stats, 0, sizeof c->stats);
    c->magic = LIDET_INIT_MAGIC;
    return LIDET_OK;
}

/* sin/cos of every alpha the search can meet; recomputed only when the image geometry changes */
static void setup_geometry(lidet_cluster_state_t *c, const lidet_range_image_t *img)
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

/* Constants of one run's flood fill. */
typedef struct
{
    uint32_t rows, cols, ks, kc, row_magic;
    int diag;
    uint32_t rrows, rcols; /* rescue window half-sizes (2 rcols < cols) */
    float tan_theta, gap, gpm, rgap, rgpm;
} grow_t;

/* beta > theta  <=>  d2 sin(a) > tan(theta) (d1 - d2 cos(a)), d1 >= d2 (true when the bracket <= 0).
 * With gap > 0 the two returns must also lie within gap + gap_per_m * d2 of each other; their
 * distance along the two beams is sqrt((d1 - d2 cos a)^2 + (d2 sin a)^2), from the same two terms
 * (no point coordinates are read) */
static inline int link(float da, float db, float sn, float cs, const grow_t *g)
{
    const float d1 = da > db ? da : db;
    const float d2 = da > db ? db : da;
    const float u = d1 - d2 * cs, v = d2 * sn;
    if (!(v > g->tan_theta * u))
    {
        return 0;
    }
    if (g->gap > 0.0f)
    {
        const float gg = g->gap + g->gpm * d2;
        return u * u + v * v <= gg * gg;
    }
    return 1;
}

/* One step of a directional search from a pixel of range dq that met candidate n (label l, range dn):
 * joins n when it is free and passes the test. Returns 1 when the search goes on behind n (n is a
 * nearer occluder that fails the test, with occluder bridging on), 0 when it stops there. A visited
 * n is only tested when that decides between the two (joining it again would change nothing). */
#define PROBE_GOES_ON(l, n, dn, sn, cs)                                                             \
    ((l) == LAB_FREE ? (link(dq, (dn), (sn), (cs), g) ? (lab[n] = (uint16_t)LAB_PENDING,           \
                                                         mem[tail++] = (int32_t)(n), 0)             \
                                                      : (occl && (dn) < dq))                        \
                     : (occl && (dn) < dq && !link(dq, (dn), (sn), (cs), g)))

/* One directional search from q (range dq): pixels q + k * step, k = 1..nk, never wrapping (the
 * caller sends the columns within kc of either edge to search_wrap); beam pair sin/cos at
 * sn[(k - 1) * gs], cs[(k - 1) * gs]. Non-candidates are stepped over. */
static inline uint32_t search(uint16_t *lab, int32_t *mem, const float *rng, uint32_t tail, float dq, uint32_t q,
                              int32_t step, uint32_t nk, const float *sn, const float *cs, int32_t gs,
                              const grow_t *g, int occl)
{
    uint32_t k, n = q;
    if (!occl)
    {
        /* the search stops at the first candidate whatever it is: find it, then test it only when
         * free (nk >= 1; k ends at the step of that candidate, or at nk - 1 on a non-candidate) */
        uint32_t l;
        k = 0;
        for (;;)
        {
            n = (uint32_t)((int32_t)n + step);
            l = lab[n];
            if (l != LAB_NONCAND || ++k >= nk)
            {
                break;
            }
        }
        if (l == LAB_FREE && link(dq, rng[n], sn[(int32_t)k * gs], cs[(int32_t)k * gs], g))
        {
            lab[n] = (uint16_t)LAB_PENDING;
            mem[tail++] = (int32_t)n;
        }
        return tail;
    }
    for (k = 0; k < nk; ++k, sn += gs, cs += gs)
    {
        uint32_t l;
        n = (uint32_t)((int32_t)n + step);
        l = lab[n];
        if (l == LAB_NONCAND)
        {
            continue;
        }
        if (!PROBE_GOES_ON(l, n, rng[n], *sn, *cs))
        {
            break;
        }
    }
    return tail;
}

/* The same along a row across the wrap (the rare columns within kc of either edge): step k meets
 * rowbase + (col +- k mod cols); angles col_sin/col_cos */
static uint32_t search_wrap(lidet_cluster_state_t *c, uint32_t tail, float dq, uint32_t rowbase, uint32_t col, int right,
                            const grow_t *g, int occl)
{
    uint16_t *lab = c->labels;
    int32_t *mem = c->members;
    const float *rng = c->img.range_m;
    const uint32_t cols = g->cols;
    uint32_t k;
    for (k = 1; k <= g->kc; ++k)
    {
        const uint32_t cc =
            right ? (col + k >= cols ? col + k - cols : col + k) : (col >= k ? col - k : col + cols - k);
        const uint32_t n = rowbase + cc;
        const uint32_t l = lab[n];
        if (l == LAB_NONCAND)
        {
            continue;
        }
        if (!PROBE_GOES_ON(l, n, rng[n], c->col_sin[k - 1], c->col_cos[k - 1]))
        {
            break;
        }
    }
    return tail;
}

/* a direct (diagonal) neighbour: joins n when free and linked; no bridging */
#define DIAG(n, sn, cs)                                                                             \
    if (lab[n] == LAB_FREE && link(dq, rng[n], (sn), (cs), g))                                      \
    {                                                                                               \
        lab[n] = (uint16_t)LAB_PENDING;                                                             \
        mem[tail++] = (int32_t)(n);                                                                 \
    }

/* Breadth-first flood fill of the cluster seeded at members[start] (tail = start + 1): expands
 * members[head] for head = start .. tail (the member array is the queue, every pixel is pushed at
 * most once). Returns the new tail. Directions in the reference's order: right, left, down, up, then
 * the diagonals down-left, down-right, up-left, up-right. occl is a constant at each call site. */
static inline uint32_t grow(lidet_cluster_state_t *c, const grow_t *g, uint32_t start, uint32_t tail, int occl)
{
    uint16_t *lab = c->labels;
    int32_t *mem = c->members;
    const float *rng = c->img.range_m;
    const uint32_t rows = g->rows, cols = g->cols, ks = g->ks, kc = g->kc;
    uint32_t head = start;
    while (head < tail)
    {
        const uint32_t q = (uint32_t)mem[head++];
        const uint32_t r = g->row_magic != 0u ? (uint32_t)(((uint64_t)q * g->row_magic) >> 32) : q / cols;
        const uint32_t rowbase = r * cols, col = q - rowbase;
        const float dq = rng[q];
        const uint32_t nd = rows - 1u - r < ks ? rows - 1u - r : ks; /* steps that stay in the image */
        const uint32_t nu = r < ks ? r : ks;
        LIDET_ASSERT(tail <= rows * cols);
        /* right, left (wrapping) */
        if (col + kc < cols)
        {
            tail = search(lab, mem, rng, tail, dq, q, 1, kc, c->col_sin, c->col_cos, 1, g, occl);
        }
        else
        {
            tail = search_wrap(c, tail, dq, rowbase, col, 1, g, occl);
        }
        if (col >= kc)
        {
            tail = search(lab, mem, rng, tail, dq, q, -1, kc, c->col_sin, c->col_cos, 1, g, occl);
        }
        else
        {
            tail = search_wrap(c, tail, dq, rowbase, col, 0, g, occl);
        }
        /* down: rows r and r + k, entry [r * STEPS + k - 1]; up: rows r - k and r, entry
         * [(r - k) * STEPS + k - 1] (stored at the upper row), i.e. stride 1 - STEPS from (r - 1) * STEPS */
        if (nd > 0u)
        {
            tail = search(lab, mem, rng, tail, dq, q, (int32_t)cols, nd, c->row_sin + r * STEPS,
                          c->row_cos + r * STEPS, 1, g, occl);
        }
        if (nu > 0u)
        {
            tail = search(lab, mem, rng, tail, dq, q, -(int32_t)cols, nu, c->row_sin + (r - 1u) * STEPS,
                          c->row_cos + (r - 1u) * STEPS, 1 - STEPS, g, occl);
        }
        /* diagonals (8-neighbourhood option): direct neighbours only, no bridging */
        if (g->diag)
        {
            const uint32_t cl = col > 0u ? col - 1u : cols - 1u, cr = col + 1u < cols ? col + 1u : 0u;
            if (r + 1u < rows)
            {
                const uint32_t b = rowbase + cols;
                DIAG(b + cl, c->diag_sin[r], c->diag_cos[r])
                DIAG(b + cr, c->diag_sin[r], c->diag_cos[r])
            }
            if (r > 0u)
            {
                const uint32_t b = rowbase - cols;
                DIAG(b + cl, c->diag_sin[r - 1u], c->diag_cos[r - 1u])
                DIAG(b + cr, c->diag_sin[r - 1u], c->diag_cos[r - 1u])
            }
        }
    }
    return tail;
}

/* ---- fragment rescue ------------------------------------------------------------------------ */

/* Running state of one rescue group: the queue tail and the nearest kept pixel met so far. */
typedef struct
{
    uint32_t tail;
    uint32_t best;  /* slot + 1 of the nearest kept cluster met, 0 = none */
    float best_d2;  /* its squared distance */
} rescue_t;

/* One pixel n (label l < LAB_PENDING, range dn) of the window of group pixel q (range dq): the two returns'
 * distance (from their coordinates) against gg = rgap + rgpm * (nearer range). Within it a fragment
 * pixel joins and a kept pixel is a contact (the nearest one wins, ties: the first met). */
static inline void rescue_link(lidet_cluster_state_t *c, rescue_t *rs, uint32_t n, uint32_t l, float dn, uint32_t q,
                               float dq, const grow_t *g)
{
    const lidet_range_image_t *img = &c->img;
    const float gg = g->rgap + g->rgpm * (dq < dn ? dq : dn);
    const float dx = img->x_m[n] - img->x_m[q], dy = img->y_m[n] - img->y_m[q], dz = img->z_m[n] - img->z_m[q];
    const float dd = dx * dx + dy * dy + dz * dz;
    if (!(dd <= gg * gg))
    {
        return;
    }
    if (l == LAB_SMALL)
    {
        c->labels[n] = (uint16_t)LAB_PENDING;
        c->members[rs->tail++] = (int32_t)n;
    }
    else if (dd < rs->best_d2)
    {
        rs->best_d2 = dd;
        rs->best = l;
    }
}

/* Pixel n of the window: looked at when it is a fragment or kept pixel (labels below LAB_PENDING;
 * visited, dropped and empty pixels are looked past) and its range lies in [lo, hi], the ranges
 * whose difference to dq can be within the gap (it bounds the distance from below; most pixels
 * stop here, before their coordinates are read) */
#define RESCUE_PROBE(n)                                                                             \
    {                                                                                               \
        const uint32_t l_ = lab[n];                                                                 \
        const float d_ = rng[n];                                                                    \
        if (l_ < LAB_PENDING && d_ >= lo && d_ <= hi && (n) != q)                                   \
        {                                                                                           \
            rescue_link(c, rs, (n), l_, d_, q, dq, g);                                              \
        }                                                                                           \
    }

/* Breadth-first fill of the rescue group seeded at members[start]. Around each member q it looks at
 * every pixel of the window rescue_rows rows up and down and rescue_cols columns left and right
 * (wrapping), row by row from the top left, q itself excepted. Four labels at a time (a 64-bit
 * word) are skipped when all are LAB_PENDING or LAB_NONCAND (0xFFFE, 0xFFFF: the only labels with
 * every bit but the lowest set). Fragments are few (hundreds of pixels per scan), windows small. */
static void rescue_grow(lidet_cluster_state_t *c, const grow_t *g, uint32_t start, rescue_t *rs)
{
    const int32_t *mem = c->members;
    const uint16_t *lab = c->labels;
    const float *rng = c->img.range_m;
    const uint32_t rows = g->rows, cols = g->cols, wr = g->rrows, wc = g->rcols;
    uint32_t head = start;
    while (head < rs->tail)
    {
        const uint32_t q = (uint32_t)mem[head++];
        const uint32_t r = q / cols, col = q - r * cols;
        const uint32_t r0 = r >= wr ? r - wr : 0u, r1 = r + wr < rows ? r + wr : rows - 1u;
        const uint32_t c0 = col >= wc ? col - wc : col + cols - wc; /* 2 wc < cols: none repeats */
        const float dq = rng[q];
        /* |d - dq| <= rgap + rgpm * min(d, dq)  <=>  lo <= d <= hi */
        const float hi = dq * (1.0f + g->rgpm) + g->rgap, lo = (dq - g->rgap) / (1.0f + g->rgpm);
        uint32_t rr, k;
        LIDET_ASSERT(rs->tail <= rows * cols);
        for (rr = r0; rr <= r1; ++rr)
        {
            const uint32_t base = rr * cols;
            if (c0 + 2u * wc < cols)
            {
                const uint32_t end = base + c0 + 2u * wc + 1u;
                uint32_t n = base + c0;
                for (; n + 4u <= end; n += 4u)
                {
                    uint64_t w;
                    memcpy(&w, &lab[n], sizeof w);
                    if ((w | 0x0001000100010001u) != 0xFFFFFFFFFFFFFFFFu)
                    {
                        RESCUE_PROBE(n)
                        RESCUE_PROBE(n + 1u)
                        RESCUE_PROBE(n + 2u)
                        RESCUE_PROBE(n + 3u)
                    }
                }
                for (; n < end; ++n)
                {
                    RESCUE_PROBE(n)
                }
            }
            else
            {
                uint32_t cc = c0;
                for (k = 0; k <= 2u * wc; ++k)
                {
                    RESCUE_PROBE(base + cc)
                    cc = cc + 1u < cols ? cc + 1u : 0u;
                }
            }
        }
    }
}
#undef RESCUE_PROBE

/* the smallest kept cluster (ties: the later seed), the one capacity drops first */
static uint32_t smallest_slot(const lidet_cluster_state_t *c)
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

/* sum, min and max of the points of members[start, tail) (tail > start). Returns 1 (the sums then
 * incomplete) as soon as an x, y or z extent exceeds max_extent: the test runs after every block of
 * 64 members, so a wall stops early instead of being summed to its end */
static int member_stats(const lidet_cluster_state_t *c, uint32_t start, uint32_t tail, float max_extent, float sum[3],
                        float lo[3], float hi[3])
{
    const float *xs = c->img.x_m, *ys = c->img.y_m, *zs = c->img.z_m;
    const int32_t *mem = c->members;
    const int32_t p0 = mem[start];
    float sx = 0.0f, sy = 0.0f, sz = 0.0f;
    float lx = xs[p0], ly = ys[p0], lz = zs[p0], hx = lx, hy = ly, hz = lz;
    uint32_t i = start, over = 0;
    while (i < tail && over == 0u)
    {
        const uint32_t e = tail - i < 64u ? tail : i + 64u;
        for (; i < e; ++i)
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
        over = (uint32_t)(hx - lx > max_extent) | (uint32_t)(hy - ly > max_extent) | (uint32_t)(hz - lz > max_extent);
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
    return over != 0u;
}

/* height of `mean` above the ground plane of the sector of the seed's column (or the flat ground) */
static float height_above_ground(const lidet_cluster_state_t *c, uint32_t seed, const float mean[3],
                                 const lidet_plane_t *planes, uint32_t n_sectors)
{
    if (planes != 0)
    {
        /* seed < rows * cols so the product fits in 64 bits */
        const uint32_t col = seed % c->img.n_cols;
        uint32_t s = (uint32_t)(((uint64_t)col * n_sectors) / c->img.n_cols);
        const lidet_plane_t *pl;
        s = s < n_sectors ? s : n_sectors - 1;
        pl = &planes[s];
        return pl->nx * mean[0] + pl->ny * mean[1] + pl->nz * mean[2] + pl->d_m;
    }
    return mean[2] + c->cfg.mount_height_m;
}

/* filters + bookkeeping of the component members[start, tail); returns the new tail. rescue = 0:
 * a component of the first fill (one below min_points becomes a fragment when the rescue is on);
 * 1: a rescue group that joined no cluster (dropped when small; takes only a free slot) */
static uint32_t finish_cluster(lidet_cluster_state_t *c, uint32_t start, uint32_t tail, const lidet_plane_t *planes,
                               uint32_t n_sectors, lidet_cluster_stats_t *st, int rescue)
{
    const uint32_t n = tail - start;
    const int32_t *mem = c->members;
    float sum[3], lo[3], hi[3], mean[3], h, inv;
    uint32_t i, slot;
    int small;
    lidet_cluster_rec_t *rec;

    if (!rescue)
    {
        ++st->n_found;
    }
    small = n < c->cfg.min_points;
    if (small && (rescue || !(c->cfg.rescue_gap_m > 0.0f)))
    {
        ++st->n_dropped_small;
        return start;
    }
    /* the same filters for a fragment-to-be (small: no extent limit), so that one above the height
     * limit (canopies, wires: nothing a road user would take in) never reaches the rescue; it saves
     * a third of the rescue's work */
    if (member_stats(c, start, tail, small ? 3.0e38f : c->cfg.max_extent_m, sum, lo, hi))
    {
        ++st->n_dropped_extent;
        return start;
    }
    inv = 1.0f / (float)n;
    mean[0] = sum[0] * inv;
    mean[1] = sum[1] * inv;
    mean[2] = sum[2] * inv;
    h = height_above_ground(c, (uint32_t)mem[start], mean, planes, n_sectors);
    if (!(h <= c->cfg.max_mean_height_m))
    {
        ++st->n_dropped_height;
        return start;
    }
    if (small)
    {
        ++st->n_fragments;
        for (i = start; i < tail; ++i)
        {
            c->labels[mem[i]] = (uint16_t)LAB_SMALL;
        }
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
        if (rescue || n <= c->recs[m].n_points)
        {
            return start;
        }
        /* evict m: its pixels become "visited, dropped"; its member range stays as a hole that the
         * final raster pass compacts away (only first-fill clusters are evicted, and they own
         * exactly their member range) */
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
    rec->n_rescued = rescue ? n : 0u;
    for (i = 0; i < 3; ++i)
    {
        rec->mean_m[i] = mean[i];
        rec->min_m[i] = lo[i];
        rec->max_m[i] = hi[i];
    }
    rec->height_m = h;
    if (rescue)
    {
        st->n_rescue_pixels += n;
    }
    for (i = start; i < tail; ++i)
    {
        c->labels[mem[i]] = (uint16_t)(slot + 1u);
    }
    return tail;
}

/* a rescue group members[start, tail) joins kept cluster `slot`: count, bounds and mean are
 * updated (mean = (mean * n_old + group sum) / n_new, in float) and the height recomputed. The
 * group's seed is its first pixel in raster order, so the cluster's first pixel is the smaller of
 * the two seeds (the height uses that pixel's sector, as for any cluster) */
static void rescue_join(lidet_cluster_state_t *c, uint32_t slot, uint32_t start, uint32_t tail, const lidet_plane_t *planes,
                        uint32_t n_sectors, lidet_cluster_stats_t *st)
{
    lidet_cluster_rec_t *rec = &c->recs[slot];
    const uint32_t n = tail - start, seed = (uint32_t)c->members[start];
    const float inv = 1.0f / (float)(rec->n_points + n);
    float sum[3], lo[3], hi[3];
    uint32_t i;
    (void)member_stats(c, start, tail, 3.0e38f, sum, lo, hi);
    for (i = 0; i < 3; ++i)
    {
        rec->mean_m[i] = (rec->mean_m[i] * (float)rec->n_points + sum[i]) * inv;
        rec->min_m[i] = lo[i] < rec->min_m[i] ? lo[i] : rec->min_m[i];
        rec->max_m[i] = hi[i] > rec->max_m[i] ? hi[i] : rec->max_m[i];
    }
    for (i = start; i < tail; ++i)
    {
        c->labels[c->members[i]] = (uint16_t)(slot + 1u);
    }
    rec->n_points += n;
    rec->n_rescued += n;
    rec->seed_pixel = seed < rec->seed_pixel ? seed : rec->seed_pixel;
    rec->height_m = height_above_ground(c, rec->seed_pixel, rec->mean_m, planes, n_sectors);
    ++st->n_rescue_joined;
    st->n_rescue_pixels += n;
}

/* canonical id of kept pixel i (label slot + 1, or 0 = none), appended to its cluster's members */
static inline void place_kept(lidet_cluster_state_t *c, uint16_t *lab, uint32_t i)
{
    const uint32_t l = lab[i];
    if (l != 0u)
    {
        const uint32_t id = c->slot_id[l];
        lab[i] = (uint16_t)id;
        c->members[c->recs[id - 1u].first_member++] = (int32_t)i;
    }
}

/* canonical order: records sorted by seed, labels rewritten, members regrouped in raster order */
static void canonicalise(lidet_cluster_state_t *c, uint32_t npix, lidet_cluster_stats_t *st)
{
    const uint32_t k = c->n_recs;
    uint32_t i, j, start;
    uint16_t *lab = c->labels;

    /* insertion sort of slots by seed: already sorted unless capacity evictions happened or the rescue
     * added clusters or moved a seed */
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
    /* every pixel that is not in a kept cluster (non-candidate, dropped; none is still free) -> 0,
     * without a branch (it vectorises); kept pixels keep slot + 1 */
    for (i = 0; i < npix; ++i)
    {
        const uint32_t l = lab[i];
        lab[i] = (uint16_t)(l < LAB_SMALL ? l : 0u);
    }
    /* slot + 1 -> id and the members in raster order. Kept pixels are a minority: blocks of four
     * labels that are all 0 (one 64-bit word, read with memcpy) are skipped at once */
    for (i = 0; i + 4u <= npix; i += 4u)
    {
        uint64_t w;
        memcpy(&w, &lab[i], sizeof w);
        if (w != 0u)
        {
            place_kept(c, lab, i);
            place_kept(c, lab, i + 1u);
            place_kept(c, lab, i + 2u);
            place_kept(c, lab, i + 3u);
        }
    }
    for (; i < npix; ++i)
    {
        place_kept(c, lab, i);
    }
    for (i = 0; i < k; ++i)
    {
        c->recs[i].first_member -= c->recs[i].n_points;
    }
}

/* the first free pixel (label 0) at or after p, npix if none. Seeds are rare once most pixels are
 * visited: four labels at a time (a 64-bit word, read with memcpy) are skipped when none is 0. The
 * test (w - 0x0001..) & ~w & 0x8000.. is nonzero exactly when some 16-bit lane of w is zero (a
 * borrow only starts at a zero lane, and the lowest zero lane always sets its top bit) */
static inline uint32_t next_free(const uint16_t *lab, uint32_t p, uint32_t npix)
{
    for (;;)
    {
        while (p + 4u <= npix)
        {
            uint64_t w;
            memcpy(&w, &lab[p], sizeof w);
            if (((w - 0x0001000100010001u) & ~w & 0x8000800080008000u) != 0u)
            {
                break;
            }
            p += 4u;
        }
        if (p >= npix || lab[p] == LAB_FREE)
        {
            return p < npix ? p : npix;
        }
        ++p;
    }
}

/* the first fragment pixel (LAB_SMALL) at or after p, npix if none: blocks of 64 labels are tested
 * in a loop without branches (it vectorises), and only a block that holds one is searched */
static uint32_t next_fragment(const uint16_t *lab, uint32_t p, uint32_t npix)
{
    while (p < npix)
    {
        const uint32_t e = npix - p < 64u ? npix : p + 64u;
        uint32_t i;
        uint16_t any = 0;
        for (i = p; i < e; ++i)
        {
            any |= (uint16_t)(lab[i] == LAB_SMALL);
        }
        if (any != 0u)
        {
            for (i = p; lab[i] != LAB_SMALL; ++i)
            {
            }
            return i;
        }
        p = e;
    }
    return npix;
}

lidet_status_t lidet_cluster_run_buffers(lidet_cluster_state_t *c, uint16_t *labels, int32_t *members,
                                         const lidet_range_image_t *img, const uint8_t *ground_mask,
                                         const lidet_plane_t *planes, uint32_t n_sectors)
{
    uint32_t rows, cols, npix, p, tail, ks;
    uint16_t *lab;
    int32_t *mem;
    grow_t lk;
    lidet_cluster_stats_t st;

    if (c == 0 || labels == 0 || members == 0 || img == 0 || (planes != 0 && n_sectors == 0))
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
    if (img->range_m == 0 || img->row_elev_rad == 0 || img->x_m == 0 ||
        img->y_m == 0 || img->z_m == 0)
    {
        return LIDET_ERR_ARG;
    }
    npix = rows * cols;
    setup_geometry(c, img);
    c->img = *img;
    c->labels = labels;
    c->members = members;
    c->n_recs = 0;
    memset(&st, 0, sizeof st);
    lab = c->labels;
    mem = c->members;
    ks = c->cfg.max_steps;
    lk.rows = rows;
    lk.cols = cols;
    lk.ks = ks;
    lk.kc = ks < cols - 1 ? ks : cols - 1; /* never wrap onto itself */
    lk.diag = c->cfg.diagonals != 0;
    lk.tan_theta = c->tan_theta;
    lk.gap = c->cfg.max_gap_m;
    lk.gpm = c->cfg.max_gap_per_m;
    lk.rgap = c->cfg.rescue_gap_m;
    lk.rgpm = c->cfg.rescue_gap_per_m;
    lk.rrows = c->cfg.rescue_rows;
    lk.rcols = c->cfg.rescue_cols < (cols - 1u) / 2u ? c->cfg.rescue_cols : (cols - 1u) / 2u;
    /* row of pixel q without a division: floor(q * m / 2^32) with m = floor(2^32 / cols) + 1 is
     * floor(q / cols) exactly when q * cols < 2^32 (m exceeds 2^32 / cols by e in (0, 1], so the
     * quotient is overestimated by q e / 2^32 < 1 / cols, less than the distance of q / cols to the
     * next integer). q < npix, so npix * cols <= 2^32 suffices (128 x 2048: 2^29); else divide */
    lk.row_magic = (uint64_t)npix * cols <= 0xFFFFFFFFu ? (uint32_t)(0xFFFFFFFFu / cols) + 1u : 0u;

    /* candidates: FREE (0) or NONCAND (0xFFFF) = cand - 1 in 16 bits; no branch, so it vectorises.
     * A pixel holds a point iff its range is > 0 (the image contract; point_idx may be absent) */
    {
        const float *prng = img->range_m;
        uint32_t n_cand = 0;
        if (ground_mask != 0)
        {
            for (p = 0; p < npix; ++p)
            {
                const uint32_t cand = (uint32_t)(prng[p] > 0.0f) & (uint32_t)(ground_mask[p] == 0);
                lab[p] = (uint16_t)(cand - 1u);
                n_cand += cand;
            }
        }
        else
        {
            for (p = 0; p < npix; ++p)
            {
                const uint32_t cand = (uint32_t)(prng[p] > 0.0f);
                lab[p] = (uint16_t)(cand - 1u);
                n_cand += cand;
            }
        }
        st.n_candidates = n_cand;
    }

    tail = 0;
    for (p = next_free(lab, 0, npix); p < npix; p = next_free(lab, p + 1u, npix))
    {
        uint32_t start;
        start = tail;
        lab[p] = (uint16_t)LAB_PENDING;
        mem[tail++] = (int32_t)p;
        /* two copies of the flood fill, with the occluder rule a constant in each */
        tail = c->cfg.bridge_occluders != 0 ? grow(c, &lk, start, tail, 1) : grow(c, &lk, start, tail, 0);
        tail = finish_cluster(c, start, tail, planes, n_sectors, &st, 0);
    }
    /* the rescue pass over the fragments (LAB_SMALL), groups seeded in raster order. Kept pixels,
     * the fragments and the current group are distinct pixels, so the member array holds them */
    if (st.n_fragments > 0u)
    {
        for (p = next_fragment(lab, 0, npix); p < npix; p = next_fragment(lab, p + 1u, npix))
        {
            rescue_t rs;
            const uint32_t start = tail;
            lab[p] = (uint16_t)LAB_PENDING;
            mem[tail++] = (int32_t)p;
            rs.tail = tail;
            rs.best = 0u;
            rs.best_d2 = 3.0e38f;
            rescue_grow(c, &lk, start, &rs);
            if (rs.best != 0u)
            {
                rescue_join(c, rs.best - 1u, start, rs.tail, planes, n_sectors, &st);
                tail = start;
            }
            else
            {
                tail = finish_cluster(c, start, rs.tail, planes, n_sectors, &st, 1);
            }
        }
    }
    canonicalise(c, npix, &st);
    st.n_kept = c->n_recs;
    c->stats = st;
    return st.n_dropped_capacity > 0 ? LIDET_TRUNCATED : LIDET_OK;
}

lidet_status_t lidet_cluster_init(lidet_cluster_t *c, const lidet_cluster_cfg_t *cfg)
{
    return c == 0 ? LIDET_ERR_ARG : lidet_cluster_state_init(&c->state, cfg);
}

lidet_status_t lidet_cluster_run(lidet_cluster_t *c, const lidet_range_image_t *img, const uint8_t *ground_mask,
                                 const lidet_plane_t *planes, uint32_t n_sectors)
{
    if (c == 0)
    {
        return LIDET_ERR_ARG;
    }
    return lidet_cluster_run_buffers(&c->state, c->labels, c->members, img, ground_mask, planes, n_sectors);
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
        *n_clusters = c->state.n_recs;
    }
    return c->state.recs;
}

const int32_t *lidet_cluster_members(const lidet_cluster_t *c)
{
    return c == 0 ? 0 : c->members;
}

const lidet_cluster_stats_t *lidet_cluster_stats(const lidet_cluster_t *c)
{
    return c == 0 ? 0 : &c->state.stats;
}

lidet_status_t lidet_cluster_point_labels_of(const lidet_cluster_state_t *c, const int32_t *point_pixel,
                                             uint32_t n_points, uint32_t *out)
{
    uint32_t i, npix;
    if (c == 0 || ((point_pixel == 0 || out == 0) && n_points > 0))
    {
        return LIDET_ERR_ARG;
    }
    if (c->magic != LIDET_INIT_MAGIC || c->labels == 0)
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

lidet_status_t lidet_cluster_point_labels(const lidet_cluster_t *c, const int32_t *point_pixel,
                                          uint32_t n_points, uint32_t *out)
{
    return c == 0 ? LIDET_ERR_ARG : lidet_cluster_point_labels_of(&c->state, point_pixel, n_points, out);
}

uint32_t lidet_cluster_bytes(void)
{
    return (uint32_t)sizeof(lidet_cluster_t);
}

uint32_t lidet_cluster_state_bytes(void)
{
    return (uint32_t)sizeof(lidet_cluster_state_t);
}
