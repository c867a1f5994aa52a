/* SPDX-License-Identifier: MIT */
/* Shared by the clustering's files (never installed): lidet_cluster.c (configuration, filters, records,
 * canonical ids, accessors), lidet_cluster_grow.c (the join test and the flood fill: the unit a port
 * overrides) and lidet_cluster_rescue.c (the fragment rescue). */
#ifndef LIDET_CLUSTER_INTERNAL_H
#define LIDET_CLUSTER_INTERNAL_H

#include "internal/lidet_cluster_common.h"
#include "internal/lidet_pixel.h"
#include "lidet/lidet_cluster.h"

/* Constants of one run's flood fill. */
typedef struct
{
    uint32_t rows, cols, ks, kc, row_magic;
    int diag;
    uint32_t rrows, rcols; /* rescue window half-sizes (2 rcols < cols) */
    float tan_theta, gap, gpm, rgap, rgpm;
    uint32_t
        bridge_max;    /* occluder bridging budget of the run (max_bridge_per_pixel * candidates; 0xFFFFFFFF:
                          * none) */
    uint32_t *bridged; /* steps bridged so far in the run; a pixel bridges only while below bridge_max */
    const uint32_t *edges; /* the first fill's searches decided beforehand (lidet__cluster_edges), or NULL */
} lidet__grow_t;

/* Running state of one rescue group: the queue tail and the nearest kept pixel met so far. */
typedef struct
{
    uint32_t tail;
    uint32_t best; /* slot + 1 of the nearest kept cluster met, 0 = none */
    float best_d2; /* its squared distance */
} lidet__rescue_t;

/* sin/cos of every alpha the search can meet; recomputed only when the image geometry changes
 * (lidet_cluster_grow.c) */
void lidet__cluster_setup_geometry(lidet_cluster_state_t *c, const lidet_range_image_t *img);

/* Breadth-first flood fill of the cluster seeded at members[start] (tail = start + 1); returns the new
 * tail (lidet_cluster_grow.c) */
uint32_t lidet__cluster_grow(lidet_cluster_state_t *c, const lidet__grow_t *g, uint32_t start, uint32_t tail);

/* The first fill's searches of every candidate pixel decided before the fill, into edges (rows * cols words):
 * returns edges when it did (x86-64 hosts with AVX-512, the compact image, max_steps <= 7, no regrowth cut), else
 * NULL, and the fill then runs the searches as it goes; the same clusters either way (lidet_cluster_grow.c) */
const uint32_t *lidet__cluster_edges(const lidet_cluster_state_t *c, const lidet__grow_t *g, uint32_t *edges);

/* lidet_cluster_run_buffers with the edge plane of lidet__cluster_edges (rows * cols words, or NULL) */
lidet_status_t lidet__cluster_run_edges(lidet_cluster_state_t *c, uint16_t *labels, lidet_member_t *members,
                                        uint32_t *edges, const lidet_range_image_t *img,
                                        const uint8_t *ground_mask, const lidet_plane_t *planes,
                                        uint32_t n_sectors);

/* Breadth-first fill of the rescue group seeded at members[start] (lidet_cluster_rescue.c) */
void lidet__cluster_rescue_grow(lidet_cluster_state_t *c, const lidet__grow_t *g, uint32_t start,
                                lidet__rescue_t *rs);

/* signed height of `mean` above the ground plane of the sector of pixel `seed`'s column, or the flat
 * ground (lidet_cluster.c) */
float lidet__cluster_height(const lidet_cluster_state_t *c, uint32_t seed, const float mean[3],
                            const lidet_plane_t *planes, uint32_t n_sectors);

/* The refinement (lidet_refine.c) on the canonical output of a run: cuts person-sized parts off wide
 * clusters (cfg split_people). Labels and records are left for one more canonical pass; returns 1 when
 * anything changed */
int lidet__refine_split(lidet_cluster_state_t *c, const lidet_plane_t *planes, uint32_t n_sectors,
                        lidet_cluster_stats_t *st);

/* The refinement's joins of car fragments (cfg join_cars) on the records after the cuts: a joined
 * cluster's pixels are relabelled and its record left empty with seed 0xFFFFFFFF (the canonical pass
 * orders it last; the caller then drops it); order[] holds 1 for clusters the cuts made or cut (they
 * take part in no join) and gets 2 for the joined ones. Returns 1 when anything joined */
int lidet__refine_join(lidet_cluster_state_t *c, const lidet_plane_t *planes, uint32_t n_sectors,
                       lidet_cluster_stats_t *st);

/* a proposal's PVLE voxel of mean (mx, my, mz): floor(azimuth, elevation, range / their bins), saturated to int16
 * (lidet_proposal.c; the group split's parts take theirs the same way) */
void lidet__proposal_voxel(float mx, float my, float mz, const lidet_proposal_cfg_t *cfg, int16_t voxel[3]);

#endif
