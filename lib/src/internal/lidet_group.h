/* SPDX-License-Identifier: MIT */
/* The group split's float rule (internal/lidet_group_common.h has the rule): its state and functions
 * (lib/src/cluster/lidet_group.c), called by the float detector. Never installed. */
#ifndef LIDET_GROUP_H
#define LIDET_GROUP_H

#include <stdint.h>

#include "internal/lidet_group_common.h"
#include "lidet/lidet_cluster.h"

/* the float rule's state for one cluster (lidet_group.c) */
typedef struct
{
    float mean[3];                           /* the cluster's mean (m) */
    float c, s;                              /* its principal horizontal axis (cos, sin) */
    float spread;                            /* sqrt(12 var t), m */
    uint32_t k_min, k_max;                   /* the cuts to try, k_max first */
    uint32_t k;                              /* the last cut made */
    float bound[LIDET_GROUP_MAX_PARTS - 1u]; /* part j: bound[j - 1] <= t < bound[j] */
    uint32_t n[LIDET_GROUP_MAX_PARTS];       /* members per part */
    float part_mean[LIDET_GROUP_MAX_PARTS][3];
} lidet_group_t;

/* 1 when cluster ci of the last run is shaped like a group (rule 1); fills g's mean, axis, spread and cuts */
int lidet__group_shape(const lidet_cluster_state_t *c, uint32_t ci, float max_range_m, lidet_group_t *g);
/* the k-part cut of rule 3 into g; 1 when every part holds LIDET_GROUP_MIN_PART members (the part means are
 * set only then). scratch: n_scratch floats the cut may overwrite (the members' offsets t), or NULL */
int lidet__group_cut(const lidet_cluster_state_t *c, uint32_t ci, lidet_group_t *g, uint32_t k,
                     float *scratch, uint32_t n_scratch);
/* part `part` of g's last cut as a proposal (rule 4) */
lidet_status_t lidet__group_proposal(const lidet_cluster_state_t *c, uint32_t ci, const lidet_group_t *g,
                                     uint32_t part, const lidet_proposal_cfg_t *cfg, lidet_proposal_t *out);

#endif
