/* SPDX-License-Identifier: MIT */
/**
 * @file lidet_pointnet_q.h
 * @brief The int8 PointNets of the integer path: classifier and box net on a lidet_proposal_q_t, integers
 *        only (docs/FIXED_POINT.md, section "int8 PointNets").
 *
 * Same models as lidet_pointnet.h (same stages, block loop, fused max over the points, [g | onehot | PVLE]
 * concatenation, box coding), quantized by `python -m lidet_codegen emit --int8 --calib FILE MODEL.onnx`
 * into weights/<name>_s8.{c,h}:
 * - weights int8 per output channel (symmetric), activations int8 (zero point -128 after a ReLU) with one scale
 *   per channel in the classifiers and per tensor in the box nets, a channel's scale folded into its layer's
 *   multiplier and the next layer's weight column, so the kernel sees one scale per vector (docs/INT8.md);
 *   int32 accumulators and biases (the input zero point folded in);
 * - requantization: y = zp + round_half_up(acc * mult / 2^shift), one rounding, mult in [2^30, 2^31),
 *   shift in [1, 62]; then clamped to [zp, 127] after a ReLU, [-128, 127] otherwise;
 * - the first shared layer takes the points rotated into the model frame as int16 millimetres (saturated:
 *   points farther than 32.767 m from the mean are clipped), the first PVLE layer the voxel bins (int16);
 * - the class one-hot of a box net is folded into its first head layer (a per-class int32 bias);
 * - the max over the points is taken on the last shared layer's int32 accumulators (a running maximum over
 *   blocks of LIDET_PN_BLOCK points), then requantized once;
 * - the last head layer writes int32 Q16 (value * 2^16): logits, T-Net centre (metres), box values.
 * Frame: cos, sin of the mean's azimuth are (x, y) / r in Q30 with r = round(sqrt(x^2 + y^2)) (no angle).
 * Energies: -T logsumexp(v / T) in Q16 nats from a 2^-x table and a log2 table (lidet_pointnet_q_tables.c,
 * generated); scores Q15. Box: centre and size in mm, yaw in BAM32.
 * Mirrored bit for bit by codegen/lidet_ref/pointnet_q.py.
 *
 * Memory: scratch of lidet_pointnet_q_scratch_bytes(model) bytes (LIDET_POINTNET_Q_SCRATCH_BYTES, also
 * emitted as <NAME>_SCRATCH_BYTES): 4 * BLOCK * max(wp, wv) + 4 * wp + 2 * BLOCK * wp + 3 * wv + 6 * BLOCK
 * bytes (each part rounded up to 4), wp the widest shared layer, wv the widest vector; no allocation.
 * Cost: one int8 x int8 -> int32 multiply-add per weight and point (32-bit), one 64-bit requantization per
 * output value; per proposal a square root, two 64-bit divisions (the frame) and an atan2 (the yaw).
 */
#ifndef LIDET_POINTNET_Q_H
#define LIDET_POINTNET_Q_H

#include "lidet_pointnet_common.h"
#include "lidet_q.h"
#include "lidet_types.h"

#ifdef __cplusplus
extern "C" {
#endif

#define LIDET_PNQ_ALIGN4(v) (((uint32_t)(v) + 3u) & ~3u)
/** Scratch bytes for a model whose widest shared layer has wp channels and widest vector wv. */
#define LIDET_POINTNET_Q_SCRATCH_BYTES(wp, wv)                                                               \
    (4u * LIDET_PN_BLOCK * ((uint32_t)(wp) > (uint32_t)(wv) ? (uint32_t)(wp) : (uint32_t)(wv)) +             \
     4u * (uint32_t)(wp) + LIDET_PNQ_ALIGN4(2u * LIDET_PN_BLOCK * (uint32_t)(wp)) +                          \
     LIDET_PNQ_ALIGN4(3u * (uint32_t)(wv)) + LIDET_PNQ_ALIGN4(6u * LIDET_PN_BLOCK))

/** @brief Output format of a layer. */
typedef enum
{
    LIDET_PNQ_OUT_S8 = 0, /**< int8 activations (hidden layers) */
    LIDET_PNQ_OUT_Q16 = 1 /**< int32 Q16 (the last layer of a head) */
} lidet_pnq_out_t;

/** @brief One int8 dense layer: acc = b + sum_i x_i w_t[i][o]; y = requant(acc). */
typedef struct
{
    uint16_t n_in;
    uint16_t n_out;
    uint8_t relu;         /**< 1: ReLU (the clamp at the zero point) */
    uint8_t out;          /**< lidet_pnq_out_t */
    int8_t out_zp;        /**< int8 output zero point (-128 after a ReLU, else 0) */
    const int8_t *w_t;    /**< n_in * n_out, [in][out] */
    const int32_t *b;     /**< n_out, input zero point folded in */
    const int32_t *mult;  /**< n_out, in [0, 2^31) */
    const uint8_t *shift; /**< n_out, in [1, 62] */
    const uint32_t
        *w_pk; /**< optional: the same weights widened to int16 and packed two to a word in the order
                               the DSP kernel reads them (n_in * (n_out & ~1) / 2 words, n_in a multiple of 4;
                               lidet__nn_pack_s8_pk in nn/lidet_nn_s8.c defines the order); NULL: w_t only. The
                               generated models fill it for every int8 x int8 layer with n_in a multiple of 4
                               where LIDET_PNQ_WEIGHTS_PK is 1 (the default on cores with the DSP extension:
                               Cortex-M4, M7, M33) and leave it NULL elsewhere (no second copy in flash) */
    const int32_t
        *b_list; /**< optional: b[o] - 128 sum_i w_t[i][o] (n_out), the list kernel's starting sums for
                                inputs counted from the ReLU's zero point -128 (LIDET_NN_S8_KERNEL_LIST); NULL:
                                the kernel sums the weights itself, once per block of points. The generated
                                models fill it for the shared point layers after the first where
                                LIDET_PNQ_LIST_BIAS is 1 (the default where the list kernel is) and leave it NULL
                                elsewhere; lidet_pointnet_q_init refuses a model whose b_list is not exactly that */
} lidet_pointnet_q_layer_t;

/* the generated int8 layer tables name their packed copy through this macro: NULL where LIDET_PNQ_WEIGHTS_PK
 * (lidet_opt.h) is 0 */
#if LIDET_PNQ_WEIGHTS_PK
#define LIDET_PNQ_PK(a) (a)
#else
#define LIDET_PNQ_PK(a) 0
#endif
/* and their list kernel's starting sums through this one: NULL where LIDET_PNQ_LIST_BIAS (lidet_opt.h) is 0 */
#if LIDET_PNQ_LIST_BIAS
#define LIDET_PNQ_LB(a) (a)
#else
#define LIDET_PNQ_LB(a) 0
#endif
/** The layout of the generated int8 layer tables (3: b_list; 2 had w_pk, not b_list; 1 had an int8 [out][in]
 *  copy, w_oi): the generated files refuse to compile against another. */
#define LIDET_PNQ_LAYOUT_VERSION 3
/* a file of layout 1 names its [out][in] copy through this macro: the compiler's error then names the fix */
#define LIDET_PNQ_OI(a) lidet_weights_of_layout_1_regenerate_them_with_lidet_codegen_emit_int8

/** @brief One stage: points -> shared layers -> max; [g | p]; the one-hot folded into head[0]'s bias. */
typedef struct
{
    const lidet_pointnet_q_layer_t *point; /**< the first takes 3 int16 inputs (mm) */
    const lidet_pointnet_q_layer_t *pvle;  /**< the first takes the 3 int16 voxel bins; or NULL */
    const lidet_pointnet_q_layer_t *head;  /**< the first takes [g | p] (int8, one scale) */
    const int32_t *onehot_b; /**< use_onehot: n_classes x head[0].n_out added to the accumulators */
    uint8_t n_point, n_pvle, n_head;
    uint8_t use_onehot;
} lidet_pointnet_q_stage_t;

/** @brief A generated int8 model (weights/<name>_s8.c). */
typedef struct
{
    uint32_t format_version; /**< LIDET_WEIGHTS_FORMAT_VERSION */
    uint8_t kind;            /**< lidet_pn_kind_t */
    uint8_t precision;       /**< LIDET_PN_S8 */
    uint8_t n_stages;
    uint8_t n_classes; /**< LIDET_N_CLASSES */
    uint16_t n_points;
    uint8_t n_heading_bins;
    uint8_t n_size_clusters;
    lidet_pointnet_q_stage_t stage[2];
    const int32_t *mean_size_mm; /**< box net: S x 3 (l, w, h) */
    const int32_t *heading_bam;  /**< box net: H bin angles, BAM32 */
    int32_t heading_res_bam;     /**< box net: pi / H in BAM32 (a residual of 1.0) */
    int32_t pvle_bin[3]; /**< voxel sizes the model was trained with: azimuth, elevation (urad), range (mm) */
    int32_t energy_t_q16;               /**< temperature, Q16 (> 0) */
    int32_t gamma_q16[LIDET_N_CLASSES]; /**< gate thresholds, Q16 nats: keep when energy < gamma[class] */
    const char *name;
    const char *class_names;
    uint8_t z_origin; /**< lidet_proposal_z_origin_t it was trained on (ONNX lidet.z_origin) */
} lidet_pointnet_q_model_t;

/** @brief A model with its scratch buffer. */
typedef struct
{
    uint32_t magic;
    const lidet_pointnet_q_model_t *model;
    uint8_t *scratch;
    uint32_t scratch_bytes;
    uint16_t w_point, w_vec;
} lidet_pointnet_q_t;

/** @brief Classifier result. */
typedef struct
{
    int32_t logits_q16[LIDET_N_CLASSES];
    int32_t prob_q15[LIDET_N_CLASSES]; /**< softmax of logits / T, Q15 */
    int32_t energy_q16;                /**< -T logsumexp(logits / T), Q16 nats */
    uint8_t cls;                       /**< arg-max class (first on ties) */
    uint8_t pass;                      /**< gate 1: energy < gamma[cls] */
} lidet_pointnet_q_class_out_t;

/** @brief Box net result (sensor frame). */
typedef struct
{
    lidet_box_q_t box;
    int32_t energy_heading_q16;
    int32_t energy_size_q16;
    int32_t energy_q16; /**< heading + size: the gate-2 energy */
    uint8_t heading_bin;
    uint8_t size_cluster;
    uint8_t pass;
} lidet_pointnet_q_box_out_t;

/** @brief One entry of a generated model table (weights/lidet_weights.c: lidet_weights_models_s8). */
typedef struct
{
    const char *name;
    const lidet_pointnet_q_model_t *model;
} lidet_pointnet_q_entry_t;

/**
 * @brief Check an int8 model descriptor.
 * @param kind     expected lidet_pn_kind_t or 0; n_points: the caller's points per proposal or 0.
 * @return LIDET_OK; LIDET_ERR_ARG (NULL); LIDET_ERR_MODEL (format version, kind, precision, widths that do not
 *         chain, NULL arrays, shifts outside [1, 62], multipliers < 0, too many layers, points per proposal,
 *         PVLE bins <= 0, temperature <= 0).
 */
lidet_status_t lidet_pointnet_q_check(const lidet_pointnet_q_model_t *model, uint32_t kind,
                                      uint32_t n_points);

/** @brief Scratch bytes of a model (0 for one lidet_pointnet_q_check rejects). */
uint32_t lidet_pointnet_q_scratch_bytes(const lidet_pointnet_q_model_t *model);

/** @brief Outputs of lidet_pointnet_q_forward: n_classes, or 3 + 3 + 2H + 4S. */
uint32_t lidet_pointnet_q_n_outputs(const lidet_pointnet_q_model_t *model);

/**
 * @brief Bind a model and a caller-owned scratch buffer (aligned to 4 bytes).
 * @return LIDET_OK; LIDET_ERR_ARG (NULL, misaligned); LIDET_ERR_MODEL; LIDET_ERR_BUFFER (too small; *required
 *         receives the size when not NULL).
 */
lidet_status_t lidet_pointnet_q_init(lidet_pointnet_q_t *pn, const lidet_pointnet_q_model_t *model,
                                     void *scratch, uint32_t scratch_bytes, uint32_t *required);

/**
 * @brief The raw network on points already in the model frame.
 * @param points_mm n_points x 3 int16 millimetres (model frame); n_points must be the model's.
 * @param voxel     the 3 voxel bins.
 * @param cls       box net: the class of the one-hot (< n_classes); ignored by a classifier.
 * @param out       Q16: logits, or T-Net centre (3, 0 without a T-Net) then the box values; n_out its capacity.
 * @return LIDET_OK; LIDET_ERR_ARG; LIDET_ERR_STATE.
 */
lidet_status_t lidet_pointnet_q_forward(lidet_pointnet_q_t *pn, const int16_t *points_mm, uint32_t n_points,
                                        const int16_t voxel[3], uint32_t cls, int32_t *out, uint32_t n_out);

/** @brief Classify an integer proposal (frame, forward, energy, scores, gate 1). LIDET_ERR_ARG when its
 *         n_points is not the model's or its mean is farther than LIDET_Q_COORD_MAX_MM (+ 4 mm) on an axis. */
lidet_status_t lidet_pointnet_q_classify(lidet_pointnet_q_t *pn, const lidet_proposal_q_t *p,
                                         lidet_pointnet_q_class_out_t *out);

/** @brief Box of an integer proposal of class cls (frame, forward, decoding, energies, gate 2). */
lidet_status_t lidet_pointnet_q_box(lidet_pointnet_q_t *pn, const lidet_proposal_q_t *p, uint32_t cls,
                                    lidet_pointnet_q_box_out_t *out);

/**
 * @brief Energy -T logsumexp(v / T) of n Q16 values, in Q16 nats (t_q16 the temperature, > 0).
 * @return the energy; 0 for n == 0, v NULL or t_q16 <= 0.
 */
int32_t lidet_pointnet_q_energy(const int32_t *v_q16, uint32_t n, int32_t t_q16);

/** @brief Find an int8 model by name in a table; NULL when absent. */
const lidet_pointnet_q_model_t *lidet_pointnet_q_find(const lidet_pointnet_q_entry_t *table, uint32_t n,
                                                      const char *name);

#ifdef __cplusplus
}
#endif

#endif /* LIDET_POINTNET_Q_H */
