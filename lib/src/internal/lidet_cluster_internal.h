/* SPDX-License-Identifier: MIT */
/* Shared by the clustering's files (never installed): lidet_cluster.c (configuration, filters, records,
 * canonical ids, accessors), lidet_cluster_grow.c (the join test and the flood fill: the unit a port
 * overrides) and lidet_cluster_rescue.c (the fragment rescue). */
#ifndef LIDET_CLUSTER_INTERNAL_H
#define LIDET_CLUSTER_INTERNAL_H

#include "internal/lidet_pixel.h"
#include "lidet/lidet_cluster.h"

/* pixel states in labels[] during a run (ids 1..LIDET_MAX_CLUSTERS are slots + 1) */
#define LAB_FREE 0u         /* a candidate not visited yet */
#define LAB_SMALL 0xFFFDu   /* a fragment (component below min_points) waiting for the rescue pass */
#define LAB_PENDING 0xFFFEu /* visited: current cluster, or a dropped one */
#define LAB_NONCAND 0xFFFFu /* no point, or ground: bridged over, never joined */

#define STEPS LIDET_CLUSTER_MAX_STEPS
#define RESCUE_MAX_COLS 15u /* rescue_cols limit (each fragment pixel looks at (2 rows + 1)(2 cols + 1) pixels) */

/* Pushes pixel n onto the queue of the current cluster (members[tail]); returns the new tail. */
static inline uint32_t lidet__cluster_take(uint16_t *lab, int32_t *mem, uint32_t tail, uint32_t n)
{
    lab[n] = (uint16_t)LAB_PENDING;
    mem[tail] = (int32_t)n;
    return tail + 1u;
}

/* Marks the candidates of a compact image in labels: FREE (0) or NONCAND (0xFFFF) = cand - 1 in 16 bits
 * (a pixel holding a point, range_4mm >= 1, that the ground mask, if any, does not mark); no branch, so
 * it vectorises. Returns their count. */
static inline uint32_t lidet__cluster_mark_4mm(const uint16_t *rng, const uint8_t *ground_mask, uint32_t npix,
                                               uint16_t *lab)
{
    uint32_t p, n_cand = 0;
    for (p = 0; p < npix; ++p)
    {
        const uint32_t cand = (uint32_t)(rng[p] > 0u) & (uint32_t)(ground_mask == 0 || ground_mask[p] == 0);
        lab[p] = (uint16_t)(cand - 1u);
        n_cand += cand;
    }
    return n_cand;
}

/* The geometry constants of one run's flood fill (the members of lidet__grow_t and of the integer stage's
 * lidet__grow_q_t, which share their names), from the image size and the configuration. The row of pixel q
 * without a division: floor(q * m / 2^32) with m = floor(2^32 / cols) + 1 is floor(q / cols) exactly when
 * q * cols < 2^32 (m exceeds 2^32 / cols by e in (0, 1], so the quotient is overestimated by q e / 2^32
 * < 1 / cols, less than the distance of q / cols to the next integer). q < npix, so npix * cols <= 2^32
 * suffices (128 x 2048: 2^29); else row_magic is 0 and the fill divides. */
#define LIDET__GROW_GEOMETRY(lk, n_rows, n_cols, cfg)                                                             \
    do                                                                                                         \
    {                                                                                                          \
        (lk).rows = (n_rows);                                                                                  \
        (lk).cols = (n_cols);                                                                                  \
        (lk).ks = (cfg).max_steps;                                                                             \
        (lk).kc = (lk).ks < (lk).cols - 1u ? (lk).ks : (lk).cols - 1u; /* never wrap onto itself */            \
        (lk).diag = (cfg).diagonals != 0;                                                                      \
        (lk).rrows = (cfg).rescue_rows;                                                                        \
        (lk).rcols = (cfg).rescue_cols < ((lk).cols - 1u) / 2u ? (cfg).rescue_cols : ((lk).cols - 1u) / 2u;    \
        (lk).row_magic = (uint64_t)(lk).rows * (lk).cols * (lk).cols <= 0xFFFFFFFFu                          \
                             ? (uint32_t)(0xFFFFFFFFu / (lk).cols) + 1u                                        \
                             : 0u;                                                                             \
    } while (0)

/* Constants of one run's flood fill. */
typedef struct
{
    uint32_t rows, cols, ks, kc, row_magic;
    int diag;
    uint32_t rrows, rcols; /* rescue window half-sizes (2 rcols < cols) */
    float tan_theta, gap, gpm, rgap, rgpm;
} lidet__grow_t;

/* Running state of one rescue group: the queue tail and the nearest kept pixel met so far. */
typedef struct
{
    uint32_t tail;
    uint32_t best;  /* slot + 1 of the nearest kept cluster met, 0 = none */
    float best_d2;  /* its squared distance */
} lidet__rescue_t;

/* sin/cos of every alpha the search can meet; recomputed only when the image geometry changes
 * (lidet_cluster_grow.c) */
void lidet__cluster_setup_geometry(lidet_cluster_state_t *c, const lidet_range_image_t *img);

/* Breadth-first flood fill of the cluster seeded at members[start] (tail = start + 1); returns the new
 * tail (lidet_cluster_grow.c) */
uint32_t lidet__cluster_grow(lidet_cluster_state_t *c, const lidet__grow_t *g, uint32_t start, uint32_t tail);

/* Breadth-first fill of the rescue group seeded at members[start] (lidet_cluster_rescue.c) */
void lidet__cluster_rescue_grow(lidet_cluster_state_t *c, const lidet__grow_t *g, uint32_t start,
                                lidet__rescue_t *rs);

#endif
