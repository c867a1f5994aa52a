/* SPDX-License-Identifier: MIT */
/* What the float (lidet_pointnet.c) and the int8 (lidet_pointnet_q.c) PointNets share, numeric-agnostic: the
 * model-level dimension checks, the box output count, the scratch checks of init, the kind / point-count
 * filter of *_check and the lookup of a generated model table by name. No float in here. */
#ifndef LIDET_PN_COMMON_H
#define LIDET_PN_COMMON_H

#include <stddef.h>
#include <string.h>

#include "lidet/lidet_pointnet_common.h"
#include "lidet/lidet_types.h"

/* raw box outputs: centre residual (3), H heading scores and residuals, S size scores, 3S size residuals */
static inline uint32_t lidet__pn_box_outputs(uint32_t nh, uint32_t ns)
{
    return 3u + 2u * nh + 4u * ns;
}

/* the descriptor's kind, stage count, classes, points per proposal and box dimensions (has_box_tables: the
 * size template / heading arrays are there) */
static inline int lidet__pn_dims_ok(uint32_t kind, uint32_t n_stages, uint32_t n_classes, uint32_t n_points,
                                    uint32_t nh, uint32_t ns, int has_box_tables)
{
    if (n_classes != LIDET_N_CLASSES || n_points < 1 || n_points > LIDET_PROPOSAL_POINTS)
    {
        return 0;
    }
    if (kind == LIDET_PN_CLASSIFIER)
    {
        return n_stages == 1;
    }
    return kind == LIDET_PN_BOX && n_stages >= 1 && n_stages <= 2 && nh >= 1 &&
           nh <= LIDET_PN_MAX_HEADING_BINS && ns >= 1 && ns <= LIDET_PN_MAX_SIZE_CLUSTERS && has_box_tables;
}

/* the widest vector: the concatenation, the PVLE and the head layers */
static inline uint16_t lidet__pn_widest(uint16_t wv, uint32_t concat, uint16_t w_pvle, uint16_t w_head)
{
    uint32_t w = concat > wv ? concat : wv;
    w = w_pvle > w ? w_pvle : w;
    w = w_head > w ? w_head : w;
    return (uint16_t)w;
}

/* init's scratch checks: *required = need; LIDET_ERR_BUFFER (NULL or too small), LIDET_ERR_ARG (misaligned) */
static inline lidet_status_t lidet__pn_scratch_ok(const void *scratch, uint32_t bytes, uint32_t need,
                                                  uint32_t *required)
{
    if (required != 0)
    {
        *required = need;
    }
    if (scratch == 0 || bytes < need)
    {
        return LIDET_ERR_BUFFER;
    }
    return ((uintptr_t)scratch & 3u) != 0 ? LIDET_ERR_ARG : LIDET_OK;
}

/* *_check's filter: kind (0: any) and points per proposal (0: any) */
static inline lidet_status_t lidet__pn_match(uint32_t model_kind, uint32_t model_points, uint32_t kind,
                                             uint32_t n_points)
{
    return (kind != 0 && model_kind != kind) || (n_points != 0 && n_points != model_points) ? LIDET_ERR_MODEL
                                                                                            : LIDET_OK;
}

/* index of name in a table of n entries of `stride` bytes whose first member is the name; n when absent */
static inline uint32_t lidet__pn_find_index(const void *table, uint32_t n, size_t stride, const char *name)
{
    uint32_t i;
    for (i = 0; i < n; ++i)
    {
        const char *const *e = (const char *const *)(const void *)((const char *)table + i * stride);
        if (*e != 0 && strcmp(*e, name) == 0)
        {
            return i;
        }
    }
    return n;
}

#endif
