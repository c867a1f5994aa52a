/* SPDX-License-Identifier: MIT */
/**
 * @file lidet_pointnet.h
 * @brief The PointNet forward pass: proposal classifier and box net (T-Net centre + box PointNet),
 *        both with the proposal voxel location encoder (PVLE), energies and box decoding.
 *
 * A model is a descriptor (lidet_pn_model_t) generated from ONNX by `python -m lidet_codegen emit`
 * into weights/ (its own CMake target, lidet::weights); lib/ never includes weights/, the caller hands
 * the descriptor in. The forward pass is hand-written here; the descriptor holds data only.
 *
 * A model has one stage (classifier) or two (box net: T-Net, then the box PointNet on the points
 * shifted by the T-Net's centre). Each stage:
 *   points (N x 3) -> shared dense layers (+ bias, ReLU) -> max over the points (fused into the last
 *   layer: a running maximum, no N x C buffer) -> g
 *   voxel (3)      -> PVLE dense layers -> p                              (optional)
 *   [g | onehot(3) (box net) | p] -> dense head layers -> stage output
 * Weights are stored transposed, [n_in][n_out] (output channel contiguous), so the kernel's inner loop
 * runs over output channels for a block of LIDET_PN_BLOCK points (lib/src/nn/lidet_nn_f32.c). Batch
 * norm is folded into the preceding layer by codegen.
 *
 * Frame: the nets see a proposal in the *model frame* (lidet_pn_to_model_frame): points centred on
 * the cluster mean and rotated about +z by minus the mean's azimuth. Box outputs are decoded back
 * into the sensor frame.
 * Energies: E = -T logsumexp(logits / T), computed stably (max subtracted). Gate 1 keeps a proposal
 * when the classifier energy < gamma[class]; gate 2 when E_heading + E_size of the box net < its
 * gamma[class] (values from the model, chosen at 95 % ID recall on validation).
 * Box coding (Frustum PointNets): raw box output [0:3] centre residual, [3:3+H] heading scores,
 * [3+H:3+2H] heading residuals normalised by pi/H, then S size scores and 3S size residuals
 * normalised by the template. Centre = mean + R(azimuth) (tnet + residual); yaw = bin * 2pi/H +
 * residual * pi/H + azimuth, wrapped to (-pi, pi]; size = template * (1 + residual).
 * Mirrored in float64 by codegen/lidet_ref/pointnet.py (function for function).
 *
 * Memory: the caller provides scratch of lidet_pn_scratch_bytes(model) bytes (also emitted as
 * <NAME>_SCRATCH_BYTES by codegen): 4 B * (2 * LIDET_PN_BLOCK * W_point + 3 * W_vec + 3 * LIDET_PN_BLOCK
 * + 8) with W_point the widest shared layer and W_vec the widest vector (concat, head or PVLE layer);
 * a few KiB for lidet's models. No allocation, no recursion.
 * Time: sum over shared layers of N * n_in * n_out multiply-adds plus the head and PVLE layers.
 */
#ifndef LIDET_POINTNET_H
#define LIDET_POINTNET_H

#include "lidet_cluster.h"
#include "lidet_pointnet_common.h"
#include "lidet_types.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Generated arrays are declared with LIDET_ALIGN(64) LIDET_RODATA (float; the int8 ones LIDET_ALIGN(16)) (lidet_opt.h:
 * a port may place them in a flash section). */

/** Scratch bytes for a model whose widest shared layer has wp channels and widest vector wv. */
#define LIDET_PN_SCRATCH_BYTES(wp, wv)                                                                       \
    (4u * (2u * LIDET_PN_BLOCK * (uint32_t)(wp) + 3u * (uint32_t)(wv) + 3u * LIDET_PN_BLOCK + 8u))

/** @brief One dense layer y = act(W x + b); W stored transposed, w_t[i * n_out + o]. */
typedef struct
{
    uint16_t n_in;
    uint16_t n_out;
    uint8_t relu;     /**< 1: ReLU after the bias */
    const float *w_t; /**< n_in * n_out, [in][out] */
    const float *b;   /**< n_out */
} lidet_pn_layer_t;

/** @brief One PointNet stage. */
typedef struct
{
    const lidet_pn_layer_t
        *point; /**< shared per-point layers; the first has n_in 3; max-pool after the last */
    const lidet_pn_layer_t *pvle; /**< PVLE layers (first n_in 3), or NULL */
    const lidet_pn_layer_t *head; /**< head layers; the first takes [g | onehot | p] */
    uint8_t n_point, n_pvle, n_head;
    uint8_t use_onehot; /**< 1: the class one-hot (n_classes) sits between g and p */
} lidet_pn_stage_t;

/** @brief A generated model (weights/<name>.c). All pointers into constant data. */
typedef struct
{
    uint32_t format_version; /**< LIDET_WEIGHTS_FORMAT_VERSION of the generator */
    uint8_t kind;            /**< lidet_pn_kind_t */
    uint8_t precision;       /**< lidet_pn_precision_t */
    uint8_t n_stages;        /**< classifier: 1; box: 2 (T-Net, box) or 1 (no T-Net) */
    uint8_t n_classes;       /**< LIDET_N_CLASSES */
    uint16_t n_points;       /**< points per proposal the model was trained with */
    uint8_t n_heading_bins;  /**< box net: H */
    uint8_t n_size_clusters; /**< box net: S */
    lidet_pn_stage_t stage[2];
    const float *mean_size_m; /**< box net: S x 3 size templates (l, w, h), else NULL */
    float pvle_bin[3]; /**< voxel sizes the model was trained with: azimuth, elevation (rad), range (m) */
    float energy_t;    /**< temperature T (> 0) */
    float gamma[LIDET_N_CLASSES]; /**< gate threshold per class: keep when energy < gamma[class] */
    const char *name;             /**< model name given to codegen */
    const char *class_names;      /**< comma-separated, lidet_class_t order */
    uint8_t z_origin;             /**< lidet_proposal_z_origin_t it was trained on (ONNX lidet.z_origin) */
} lidet_pn_model_t;

/** @brief A model with its scratch buffer, ready to run. */
typedef struct
{
    uint32_t magic;
    const lidet_pn_model_t *model;
    float *scratch;
    uint32_t scratch_bytes;
    uint16_t w_point, w_vec; /* widest shared layer, widest vector */
} lidet_pn_t;

/** @brief Classifier result. */
typedef struct
{
    float logits[LIDET_N_CLASSES];
    float prob[LIDET_N_CLASSES]; /**< softmax of logits / T */
    float energy;                /**< -T logsumexp(logits / T) */
    uint8_t cls;                 /**< arg-max class (lidet_class_t) */
    uint8_t pass;                /**< gate 1: energy < gamma[cls] */
} lidet_pn_class_out_t;

/** @brief Box net result (sensor frame). */
typedef struct
{
    lidet_box_t box;
    float energy_heading; /**< -T logsumexp of the heading scores / T */
    float energy_size;    /**< -T logsumexp of the size scores / T */
    float energy;         /**< energy_heading + energy_size: the gate-2 energy */
    uint8_t heading_bin;
    uint8_t size_cluster;
    uint8_t pass; /**< gate 2: energy < gamma[class] */
} lidet_pn_box_out_t;

/**
 * @brief Check a model descriptor (version, kind, dimensions, pointers, chaining of layer widths).
 * @param[in] model      descriptor (may be NULL: LIDET_ERR_ARG).
 * @param[in] kind       expected lidet_pn_kind_t, or 0 for any.
 * @param[in] n_points   points per proposal the caller will pass, or 0 to skip that check.
 * @return LIDET_OK; LIDET_ERR_ARG (NULL); LIDET_ERR_MODEL (wrong format version, kind or precision,
 *         zero or inconsistent dimensions, NULL arrays, too many layers, n_points not the model's or
 *         above LIDET_PROPOSAL_POINTS).
 */
lidet_status_t lidet_pn_check(const lidet_pn_model_t *model, uint32_t kind, uint32_t n_points);

/** @brief Scratch bytes the model needs (0 for a descriptor lidet_pn_check rejects). */
uint32_t lidet_pn_scratch_bytes(const lidet_pn_model_t *model);

/**
 * @brief Bind a model and a caller-owned scratch buffer.
 * @param[out] pn            state.
 * @param[in]  model         descriptor (retained: must outlive pn; generated ones are static const).
 * @param[in]  scratch       buffer aligned to 4 bytes (retained, used by every run), or NULL to
 *                           only learn the size.
 * @param[in]  scratch_bytes its size.
 * @param[out] required      optional: receives lidet_pn_scratch_bytes(model).
 * @return LIDET_OK; LIDET_ERR_ARG (NULL pn/model, misaligned buffer); LIDET_ERR_MODEL (see
 *         lidet_pn_check); LIDET_ERR_BUFFER (scratch NULL or smaller than required).
 */
lidet_status_t lidet_pn_init(lidet_pn_t *pn, const lidet_pn_model_t *model, void *scratch,
                             uint32_t scratch_bytes, uint32_t *required);

/**
 * @brief The raw network: points already in the model frame.
 * @param[in]  pn       initialised state.
 * @param[in]  points   n_points x 3 floats (model frame), n_points = the model's.
 * @param[in]  n_points must equal model->n_points.
 * @param[in]  voxel    3 floats (the voxel bins as floats).
 * @param[in]  onehot   n_classes floats (box net), ignored by a classifier (may be NULL there).
 * @param[out] out      classifier: n_classes logits; box net: 3 T-Net centre values (0 without a
 *                      T-Net) followed by the 3 + 2H + 4S box values.
 * @param[in]  n_out    capacity of out in floats.
 * @return LIDET_OK; LIDET_ERR_ARG (NULL, n_points not the model's, n_out too small, onehot NULL for
 *         a box net); LIDET_ERR_STATE (not initialised).
 */
lidet_status_t lidet_pn_forward(lidet_pn_t *pn, const float *points, uint32_t n_points, const float voxel[3],
                                const float *onehot, float *out, uint32_t n_out);

/** @brief Outputs of lidet_pn_forward for this model (n_classes, or 3 + 3 + 2H + 4S). */
uint32_t lidet_pn_n_outputs(const lidet_pn_model_t *model);

/**
 * @brief Rotate centred proposal points into the model frame: about +z by minus the azimuth of mean.
 * @param[in]  xyz    n x 3 points centred on mean.
 * @param[in]  n      count.
 * @param[in]  mean   the cluster mean (sensor frame).
 * @param[out] out    n x 3 (may alias xyz).
 * @param[out] cs     optional: cos and sin of the azimuth (1, 0 when the mean is on the z axis).
 */
void lidet_pn_to_model_frame(const float *xyz, uint32_t n, const float mean[3], float *out, float cs[2]);

/**
 * @brief Classify a proposal (model frame, forward, softmax, energy, gate 1).
 * @param[in]  pn  initialised classifier (kind LIDET_PN_CLASSIFIER).
 * @param[in]  p   proposal from lidet_proposal_make with p->n_points == model->n_points.
 * @param[out] out result.
 * @return LIDET_OK; LIDET_ERR_ARG (NULL, wrong point count); LIDET_ERR_MODEL (not a classifier);
 *         LIDET_ERR_STATE.
 */
lidet_status_t lidet_pn_classify(lidet_pn_t *pn, const lidet_proposal_t *p, lidet_pn_class_out_t *out);

/**
 * @brief Box of a proposal of class cls (model frame, forward, decoding, energies, gate 2).
 * @param[in]  pn  initialised box net (kind LIDET_PN_BOX).
 * @param[in]  p   proposal (n_points == model->n_points).
 * @param[in]  cls class from the classifier (< n_classes): the one-hot input and the gate threshold.
 * @param[out] out box in the sensor frame and energies.
 * @return LIDET_OK; LIDET_ERR_ARG; LIDET_ERR_MODEL (not a box net); LIDET_ERR_STATE.
 */
lidet_status_t lidet_pn_box(lidet_pn_t *pn, const lidet_proposal_t *p, uint32_t cls, lidet_pn_box_out_t *out);

/**
 * @brief Energy -T logsumexp(v / T) of n values, computed stably (max subtracted first).
 * @return the energy; +inf-free for finite inputs; n == 0 gives 0.
 */
float lidet_pn_energy(const float *v, uint32_t n, float t);

/** @brief One entry of a generated model table (weights/lidet_weights.c). */
typedef struct
{
    const char *name;
    const lidet_pn_model_t *model;
} lidet_pn_entry_t;

/**
 * @brief Find a model by name in a table (e.g. lidet_weights_models of the lidet::weights target).
 * @return the model, or NULL when absent (or NULL arguments).
 */
const lidet_pn_model_t *lidet_pn_find(const lidet_pn_entry_t *table, uint32_t n, const char *name);

#ifdef __cplusplus
}
#endif

#endif /* LIDET_POINTNET_H */
