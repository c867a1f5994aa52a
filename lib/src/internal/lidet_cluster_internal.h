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

/* Constants of one run's flood fill. */
typedef struct
{
    uint32_t rows, cols, ks, kc, row_magic;
    int diag;
    uint32_t rrows, rcols; /* rescue window half-sizes (2 rcols < cols) */
    float tan_theta, gap, gpm, rgap, rgpm;
    uint32_t bridge_max; /* occluder bridging budget of the run (max_bridge_per_pixel * candidates; 0xFFFFFFFF:
                          * none) */
    uint32_t *bridged;   /* steps bridged so far in the run; a pixel bridges only while below bridge_max */
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
