/* SPDX-License-Identifier: MIT */
/* Shared by the integer clustering's files (never installed): lidet_cluster_q.c (configuration, filters,
 * records, the run), lidet_cluster_grow_q.c (the angle tables, the join test and the flood fill) and
 * lidet_cluster_rescue_q.c (the fragment rescue), lidet_refine_q.c (the refinement). Integer only. */
#ifndef LIDET_CLUSTER_Q_INTERNAL_H
#define LIDET_CLUSTER_Q_INTERNAL_H

#include "internal/lidet_cluster_common.h"
#include "internal/lidet_qmath.h"
#include "lidet/lidet_cluster_q.h"

/* Constants of one run's flood fill (the geometry members named as lidet__grow_t's: the templates read
 * both). Distances in 4 mm steps, ratios Q16. */
typedef struct
{
    uint32_t rows, cols, ks, kc, row_magic;
    int diag;
    uint32_t rrows, rcols;
    uint32_t sin_t;      /* sin(theta), Q16 */
    uint32_t gap_on;     /* max_gap_mm > 0 */
    uint32_t gap, gpm;   /* gap bound: gap + (gpm d2 >> 16, rounded) */
    uint32_t rgap, rgpm; /* rescue distance: rgap + (rgpm min(d1, d2) >> 16, rounded) */
    uint32_t bridge_max; /* occluder bridging budget of the run (the shared flood fill reads it) */
    uint32_t *bridged;   /* steps bridged so far in the run */
} lidet__grow_q_t;

/* The join test's gap bound without a 64-bit product: dd^2 + floor((x h + 2^29) / 2^30) <= gg^2 for dd <= gg
 * (x = d1 d2 and h the table's 4 sin^2(alpha / 2), Q30, both uint32), exactly. With gg < 2^16, R = gg^2 - dd^2 fits
 * 32 bits and the bound is x h < (R + 1/2) 2^30; from x = xh 2^16 + xl and h = hh 2^16 + hl, x h lies in
 * [L 2^32, (L + xh + hh + 1) 2^32) with L = xh hh, so L > R / 4 rejects and L + xh + hh + 1 <= R / 4 accepts (the
 * second test only reached when L <= R / 4 < 2^30: no wrap); between them, or with gg >= 2^16, the exact 64-bit
 * test (the form of cores without a 32 x 32 -> 64 multiply, lidet_cluster_grow_q.c; compiled everywhere, so that the
 * host tests check it) */
static inline int lidet__cluster_q_gap_ok(uint32_t dd, uint32_t gg, uint32_t x, uint32_t h)
{
    if (gg < 65536u)
    {
        const uint32_t q = (gg * gg - dd * dd) >> 2, xh = x >> 16, hh = h >> 16, lo = xh * hh;
        if (lo > q)
        {
            return 0;
        }
        if (lo + xh + hh + 1u <= q)
        {
            return 1;
        }
    }
    /* dd <= 65535 (a range difference): dd^2 in 32 bits */
    return (uint64_t)(dd * dd) + ((lidet__q_umul32(x, h) + ((uint64_t)1 << 29)) >> 30) <=
           lidet__q_umul32(gg, gg);
}

/* Running state of one rescue group. */
typedef struct
{
    uint32_t tail;
    uint32_t best;    /* slot + 1 of the nearest kept cluster met, 0 = none */
    uint32_t best_d2; /* its squared distance (4 mm steps squared) */
} lidet__rescue_q_t;

/* S and H of every alpha the search can meet; recomputed only when the geometry changes */
void lidet__cluster_q_setup_geometry(lidet_cluster_q_state_t *c, const lidet_range_image_t *img);

uint32_t lidet__cluster_q_grow(lidet_cluster_q_state_t *c, const lidet__grow_q_t *g, uint32_t start,
                               uint32_t tail);

void lidet__cluster_q_rescue_grow(lidet_cluster_q_state_t *c, const lidet__grow_q_t *g, uint32_t start,
                                  lidet__rescue_q_t *rs);

/* height of `mean` above the plane of the seed column's sector (or the flat ground), 4 mm steps
 * (lidet_cluster_q.c) */
int32_t lidet__cluster_q_height(const lidet_cluster_q_state_t *c, uint32_t seed, const int32_t mean[3],
                                const lidet_plane_q_t *planes, uint32_t n_sectors);

/* The refinement (lidet_refine_q.c) on the canonical output of a run, as lidet__refine_split and
 * lidet__refine_join (lidet_cluster_internal.h) */
int lidet__refine_q_split(lidet_cluster_q_state_t *c, const lidet_plane_q_t *planes, uint32_t n_sectors,
                          lidet_cluster_stats_t *st);
int lidet__refine_q_join(lidet_cluster_q_state_t *c, const lidet_plane_q_t *planes, uint32_t n_sectors,
                         lidet_cluster_stats_t *st);

/* a proposal's PVLE voxel of the mean (mx, my, mz) in 4 mm steps, from integer atan2 and square roots
 * (lidet_proposal_q.c; the group split's parts take theirs the same way) */
void lidet__proposal_q_voxel(int32_t mx, int32_t my, int32_t mz, const lidet_proposal_q_cfg_t *cfg,
                             int16_t voxel[3]);

#endif
