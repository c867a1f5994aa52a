/* SPDX-License-Identifier: MIT */
/**
 * @file lidet_pointnet_common.h
 * @brief What the float (lidet_pointnet.h) and the int8 (lidet_pointnet_q.h) PointNets share: model kinds,
 *        weight precisions and the limits a descriptor is checked against. No numeric type in here.
 */
#ifndef LIDET_POINTNET_COMMON_H
#define LIDET_POINTNET_COMMON_H

#include "lidet_types.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Most layers per part of a stage (shared, PVLE, head); a descriptor with more is LIDET_ERR_MODEL. */
#define LIDET_PN_MAX_LAYERS 8
/** Widest layer (channels) the forward pass accepts. */
#define LIDET_PN_MAX_WIDTH 1024
/** Heading bins / size templates the box decoding accepts at most. */
#define LIDET_PN_MAX_HEADING_BINS 64
#define LIDET_PN_MAX_SIZE_CLUSTERS 8

/** @brief Model kinds. */
typedef enum
{
    LIDET_PN_CLASSIFIER = 1, /**< one stage; output: n_classes logits */
    LIDET_PN_BOX = 2         /**< T-Net (optional) + box PointNet; output: 3 + 2H + 4S values */
} lidet_pn_kind_t;

/** @brief Numeric format of the weights. */
typedef enum
{
    LIDET_PN_F32 = 0, /**< float32 weights and activations (lidet_pn_model_t) */
    LIDET_PN_S8 = 1   /**< int8 weights and activations, int32 accumulators (lidet_pointnet_q_model_t) */
} lidet_pn_precision_t;

#ifdef __cplusplus
}
#endif

#endif /* LIDET_POINTNET_COMMON_H */
