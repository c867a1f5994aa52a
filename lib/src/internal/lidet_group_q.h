/* SPDX-License-Identifier: MIT */
/* The group split's integer rule (internal/lidet_group_common.h has the rule): its state and functions
 * (lib/src/cluster/lidet_group_q.c, mirrored by codegen/lidet_ref/group_q.py), called by the integer detector.
 * Integer only. Never installed. */
#ifndef LIDET_GROUP_Q_H
#define LIDET_GROUP_Q_H

#include <stdint.h>

#include "internal/lidet_group_common.h"
#include "lidet/lidet_cluster_q.h"

/* the integer rule's state (lidet_group_q.c); lengths in 4 mm steps, the axis in Q30 */
typedef struct
{
    int32_t mean[3];
    int32_t c, s;
    int32_t spread;
    uint32_t k_min, k_max;
    uint32_t k;
    int32_t bound[LIDET_GROUP_MAX_PARTS - 1u];
    uint32_t n[LIDET_GROUP_MAX_PARTS];
    int32_t part_mean[LIDET_GROUP_MAX_PARTS][3];
} lidet_group_q_t;

/* the float functions of internal/lidet_group.h in integers (max_range_mm horizontal, in mm) */
int lidet__group_q_shape(const lidet_cluster_q_state_t *c, uint32_t ci, int32_t max_range_mm,
                         lidet_group_q_t *g);
int lidet__group_q_cut(const lidet_cluster_q_state_t *c, uint32_t ci, lidet_group_q_t *g, uint32_t k);
lidet_status_t lidet__group_q_proposal(const lidet_cluster_q_state_t *c, uint32_t ci,
                                       const lidet_group_q_t *g, uint32_t part,
                                       const lidet_proposal_q_cfg_t *cfg, lidet_proposal_q_t *out);

#endif
