/* SPDX-License-Identifier: MIT */
/* Clustering, the growth (see lidet_cluster.h): the join test of two neighbouring returns, the
 * directional searches with hole and occluder bridging, and the breadth-first flood fill. The hot
 * loop of the stage and the unit a port overrides. Mirrors codegen/lidet_codegen/ref/cluster.py:
 * cluster_ref (link, search, grow). */
#include <math.h>
#include <string.h>

#include "internal/lidet_assert.h"
#include "internal/lidet_cluster_internal.h"
#include "internal/lidet_math.h"

void lidet__cluster_setup_geometry(lidet_cluster_state_t *c, const lidet_range_image_t *img)
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

/* The ranges the flood fill reads: the float image's in metres, or the compact image's in 4 mm steps
 * (converted to float, not scaled: the angle test is homogeneous in the ranges, and the gap bound is
 * scaled to steps once, in lidet__cluster_grow). compact is a constant in each copy of grow(), so the
 * test folds away. */
typedef struct
{
    const float *f;
    const uint16_t *q;
} rng_t;

static inline rng_t rng_view(const lidet_range_image_t *img)
{
    rng_t v;
    v.f = img->range_m;
    v.q = img->range_4mm;
    return v;
}

static inline float rng_at(rng_t v, uint32_t n, int compact)
{
    return compact ? (float)v.q[n] : v.f[n];
}

/* beta > theta  <=>  d2 sin(a) > tan(theta) (d1 - d2 cos(a)), d1 >= d2 (true when the bracket <= 0).
 * With gap > 0 the two returns must also lie within gap + gap_per_m * d2 of each other; their
 * distance along the two beams is sqrt((d1 - d2 cos a)^2 + (d2 sin a)^2), from the same two terms
 * (no point coordinates are read) */
static inline int link(float da, float db, float sn, float cs, const lidet__grow_t *g)
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

/* Pushes pixel n onto the queue of the current cluster (members[tail]); returns the new tail. */
static inline uint32_t take(uint16_t *lab, int32_t *mem, uint32_t tail, uint32_t n)
{
    lab[n] = (uint16_t)LAB_PENDING;
    mem[tail] = (int32_t)n;
    return tail + 1u;
}

/* One directional search from q (range dq): pixels q + k * step, k = 1..nk, never wrapping (the
 * caller sends the columns within kc of either edge to search_wrap); beam pair sin/cos at
 * sn[(k - 1) * gs], cs[(k - 1) * gs]. Non-candidates are stepped over. */
static inline uint32_t search(uint16_t *lab, int32_t *mem, rng_t rng, uint32_t tail, float dq, uint32_t q,
                              int32_t step, uint32_t nk, const float *sn, const float *cs, int32_t gs,
                              const lidet__grow_t *g, int occl, int compact)
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
        if (l == LAB_FREE && link(dq, rng_at(rng, n, compact), sn[(int32_t)k * gs], cs[(int32_t)k * gs], g))
        {
            tail = take(lab, mem, tail, n);
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
        /* occluder bridging: a free candidate that passes the test joins, and the search ends; one
         * that fails it, or a visited one, ends the search unless it is nearer than q and fails the
         * test (an occluder: the search goes on behind it). A visited candidate is only tested when
         * that decides between the two (joining it again would change nothing) */
        const float dn = rng_at(rng, n, compact);
        if (l == LAB_FREE)
        {
            if (link(dq, dn, *sn, *cs, g))
            {
                tail = take(lab, mem, tail, n);
                break;
            }
            if (!(dn < dq))
            {
                break;
            }
        }
        else if (!(dn < dq) || link(dq, dn, *sn, *cs, g))
        {
            break;
        }
    }
    return tail;
}

/* The same along a row across the wrap (the rare columns within kc of either edge): step k meets
 * rowbase + (col +- k mod cols); angles col_sin/col_cos */
static uint32_t search_wrap(lidet_cluster_state_t *c, uint32_t tail, float dq, uint32_t rowbase, uint32_t col, int right,
                            const lidet__grow_t *g, int occl, int compact)
{
    uint16_t *lab = c->labels;
    int32_t *mem = c->members;
    const rng_t rng = rng_view(&c->img);
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
        const float dn = rng_at(rng, n, compact), sn = c->col_sin[k - 1], cs = c->col_cos[k - 1];
        if (l == LAB_FREE && link(dq, dn, sn, cs, g))
        {
            tail = take(lab, mem, tail, n); /* joins, and the search ends */
            break;
        }
        /* without occluder bridging any candidate ends the search; with it, one nearer than q that
         * fails the test is stepped over (as in search) */
        if (!occl || !(dn < dq) || (l != LAB_FREE && link(dq, dn, sn, cs, g)))
        {
            break;
        }
    }
    return tail;
}

/* Breadth-first flood fill of the cluster seeded at members[start] (tail = start + 1): expands
 * members[head] for head = start .. tail (the member array is the queue, every pixel is pushed at
 * most once). Returns the new tail. Directions in the reference's order: right, left, down, up, then
 * the diagonals down-left, down-right, up-left, up-right. occl is a constant at each call site. */
static inline uint32_t grow(lidet_cluster_state_t *c, const lidet__grow_t *g, uint32_t start, uint32_t tail,
                            int occl, int compact)
{
    uint16_t *lab = c->labels;
    int32_t *mem = c->members;
    const rng_t rng = rng_view(&c->img);
    const uint32_t rows = g->rows, cols = g->cols, ks = g->ks, kc = g->kc;
    uint32_t head = start;
    while (head < tail)
    {
        const uint32_t q = (uint32_t)mem[head++];
        const uint32_t r = g->row_magic != 0u ? (uint32_t)(((uint64_t)q * g->row_magic) >> 32) : q / cols;
        const uint32_t rowbase = r * cols, col = q - rowbase;
        const float dq = rng_at(rng, q, compact);
        const uint32_t nd = rows - 1u - r < ks ? rows - 1u - r : ks; /* steps that stay in the image */
        const uint32_t nu = r < ks ? r : ks;
        LIDET_ASSERT(tail <= rows * cols);
        /* right, left (wrapping) */
        if (col + kc < cols)
        {
            tail = search(lab, mem, rng, tail, dq, q, 1, kc, c->col_sin, c->col_cos, 1, g, occl, compact);
        }
        else
        {
            tail = search_wrap(c, tail, dq, rowbase, col, 1, g, occl, compact);
        }
        if (col >= kc)
        {
            tail = search(lab, mem, rng, tail, dq, q, -1, kc, c->col_sin, c->col_cos, 1, g, occl, compact);
        }
        else
        {
            tail = search_wrap(c, tail, dq, rowbase, col, 0, g, occl, compact);
        }
        /* down: rows r and r + k, entry [r * STEPS + k - 1]; up: rows r - k and r, entry
         * [(r - k) * STEPS + k - 1] (stored at the upper row), i.e. stride 1 - STEPS from (r - 1) * STEPS */
        if (nd > 0u)
        {
            tail = search(lab, mem, rng, tail, dq, q, (int32_t)cols, nd, c->row_sin + r * STEPS,
                          c->row_cos + r * STEPS, 1, g, occl, compact);
        }
        if (nu > 0u)
        {
            tail = search(lab, mem, rng, tail, dq, q, -(int32_t)cols, nu, c->row_sin + (r - 1u) * STEPS,
                          c->row_cos + (r - 1u) * STEPS, 1 - STEPS, g, occl, compact);
        }
        /* diagonals (8-neighbourhood option): direct neighbours only, no bridging; each joins when
         * free and linked (down-left, down-right, up-left, up-right) */
        if (g->diag)
        {
            const uint32_t cl = col > 0u ? col - 1u : cols - 1u, cr = col + 1u < cols ? col + 1u : 0u;
            if (r + 1u < rows)
            {
                const uint32_t dl = rowbase + cols + cl, dr = rowbase + cols + cr;
                if (lab[dl] == LAB_FREE &&
                    link(dq, rng_at(rng, dl, compact), c->diag_sin[r], c->diag_cos[r], g))
                {
                    tail = take(lab, mem, tail, dl);
                }
                if (lab[dr] == LAB_FREE &&
                    link(dq, rng_at(rng, dr, compact), c->diag_sin[r], c->diag_cos[r], g))
                {
                    tail = take(lab, mem, tail, dr);
                }
            }
            if (r > 0u)
            {
                const uint32_t ul = rowbase - cols + cl, ur = rowbase - cols + cr;
                if (lab[ul] == LAB_FREE &&
                    link(dq, rng_at(rng, ul, compact), c->diag_sin[r - 1u], c->diag_cos[r - 1u], g))
                {
                    tail = take(lab, mem, tail, ul);
                }
                if (lab[ur] == LAB_FREE &&
                    link(dq, rng_at(rng, ur, compact), c->diag_sin[r - 1u], c->diag_cos[r - 1u], g))
                {
                    tail = take(lab, mem, tail, ur);
                }
            }
        }
    }
    return tail;
}

uint32_t lidet__cluster_grow(lidet_cluster_state_t *c, const lidet__grow_t *g, uint32_t start, uint32_t tail)
{
    /* four copies of the flood fill, with the occluder rule and the image format constants in each */
    lidet__grow_t gs;
    if (!lidet__img_compact(&c->img))
    {
        return c->cfg.bridge_occluders != 0 ? grow(c, g, start, tail, 1, 0) : grow(c, g, start, tail, 0, 0);
    }
    gs = *g; /* ranges in 4 mm steps: the gap bound in steps (gap_per_m is a ratio) */
    gs.gap = g->gap * LIDET_PIXEL_PER_M;
    return c->cfg.bridge_occluders != 0 ? grow(c, &gs, start, tail, 1, 1) : grow(c, &gs, start, tail, 0, 1);
}
