/* SPDX-License-Identifier: MIT */
/* Shared by the integer clustering's files (never installed): lidet_cluster_q.c (configuration, filters,
 * records, the run), lidet_cluster_grow_q.c (the angle tables, the join test and the flood fill) and
 * lidet_cluster_rescue_q.c (the fragment rescue), lidet_refine_q.c (the refinement). Integer only. */
#ifndef LIDET_CLUSTER_Q_INTERNAL_H
#define LIDET_CLUSTER_Q_INTERNAL_H

#include "internal/lidet_cluster_common.h"
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
