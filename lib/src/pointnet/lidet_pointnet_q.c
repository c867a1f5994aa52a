/* SPDX-License-Identifier: MIT */
/* The int8 PointNets (see lidet_pointnet_q.h). Integers only: no <math.h>, no float. Mirrored bit for bit
 * by codegen/lidet_ref/pointnet_q.py: run_stage -> run_stage, forward -> forward, frame_cs ->
 * frame_cs, load_block -> model_frame, lidet_pointnet_q_energy -> energy, decode_box -> decode_box. */
#include "internal/lidet_q_gpr.h" /* first: no FPU register for 64-bit integers */
#include <string.h>

#include "internal/lidet_pn_common.h"
#include "internal/lidet_pointnet_q_internal.h"
#include "internal/lidet_proposal_rule.h"
#include "internal/lidet_qmath.h"
#include "lidet/lidet_pointnet_q.h"

#define LOG2E_Q30 1549082005       /* round(log2(e) * 2^30) */
#define LN2_Q24 11629080           /* round(ln(2) * 2^24) */
#define E_CUT_Q16 (24 << 16)       /* exp(-d) = 0 from d = 24 nats on */
#define BIAS_LIMIT (1 << 29)       /* |bias|, |one-hot bias| below it: int32 accumulators cannot overflow */
#define CENTRE_LIMIT_Q16 (1 << 24) /* box centres clamped to +-256 m before decoding */

/* ---- descriptor checks -------------------------------------------------------------------- */

static int layer_ok(const lidet_pointnet_q_layer_t *l, uint32_t n_in, int last_of_head)
{
    uint32_t o;
    if (l->n_in != n_in || l->n_out == 0 || l->n_out > LIDET_PN_MAX_WIDTH || l->w_t == 0 || l->b == 0 ||
        l->mult == 0 || l->shift == 0 || l->relu > 1 ||
        l->out != (last_of_head ? LIDET_PNQ_OUT_Q16 : LIDET_PNQ_OUT_S8))
    {
        return 0;
    }
    for (o = 0; o < l->n_out; ++o)
    {
        if (l->shift[o] < 1 || l->shift[o] > 62 || l->mult[o] < 0 || l->b[o] <= -BIAS_LIMIT ||
            l->b[o] >= BIAS_LIMIT)
        {
            return 0;
        }
        if (l->b_list != 0)
        {
            /* the list kernel's starting sums must be the bias less 128 times the channel's weights, exactly */
            int32_t v = l->b[o];
            uint32_t i;
            for (i = 0; i < n_in; ++i)
            {
                v -= 128 * (int32_t)l->w_t[i * l->n_out + o];
            }
            if (l->b_list[o] != v)
            {
                return 0;
            }
        }
    }
    return 1;
}

static int layers_ok(const lidet_pointnet_q_layer_t *l, uint32_t n, uint32_t n_in_first, int is_head,
                     uint16_t *widest)
{
    uint32_t i, n_in = n_in_first;
    if (n > LIDET_PN_MAX_LAYERS || (n > 0 && l == 0))
    {
        return 0;
    }
    for (i = 0; i < n; ++i)
    {
        if (!layer_ok(&l[i], n_in, is_head && i + 1u == n))
        {
            return 0;
        }
        n_in = l[i].n_out;
        if (l[i].n_out > *widest)
        {
            *widest = l[i].n_out;
        }
    }
    return 1;
}

static int stage_ok(const lidet_pointnet_q_stage_t *s, uint32_t n_classes, uint32_t n_out, uint16_t *wp,
                    uint16_t *wv)
{
    uint32_t concat, k;
    uint16_t w_pvle = 0, w_head = 0;
    if (s->n_point < 1 || s->n_head < 1 || s->use_onehot > 1 || (s->use_onehot && s->onehot_b == 0))
    {
        return 0;
    }
    if (!layers_ok(s->point, s->n_point, 3u, 0, wp) || !layers_ok(s->pvle, s->n_pvle, 3u, 0, &w_pvle))
    {
        return 0;
    }
    concat = s->point[s->n_point - 1].n_out + (s->n_pvle ? s->pvle[s->n_pvle - 1].n_out : 0u);
    if (concat > LIDET_PN_MAX_WIDTH || !layers_ok(s->head, s->n_head, concat, 1, &w_head) ||
        s->head[s->n_head - 1].n_out != n_out)
    {
        return 0;
    }
    for (k = 0; s->use_onehot && k < n_classes * s->head[0].n_out; ++k)
    {
        if (s->onehot_b[k] <= -BIAS_LIMIT || s->onehot_b[k] >= BIAS_LIMIT)
        {
            return 0;
        }
    }
    *wv = lidet__pn_widest(*wv, concat, w_pvle, w_head);
    return 1;
}

static uint32_t box_outputs(const lidet_pointnet_q_model_t *m)
{
    return lidet__pn_box_outputs(m->n_heading_bins, m->n_size_clusters);
}

static lidet_status_t check_widths(const lidet_pointnet_q_model_t *m, uint16_t *wp, uint16_t *wv)
{
    uint32_t st;
    *wp = 3;
    *wv = 8;
    if (m->format_version != LIDET_WEIGHTS_FORMAT_VERSION || m->precision != LIDET_PN_S8 ||
        !lidet__pn_dims_ok(m->kind, m->n_stages, m->n_classes, m->n_points, m->n_heading_bins,
                           m->n_size_clusters, m->mean_size_mm != 0 && m->heading_bam != 0) ||
        m->energy_t_q16 <= 0 || m->pvle_bin[0] <= 0 || m->pvle_bin[1] <= 0 || m->pvle_bin[2] <= 0)
    {
        return LIDET_ERR_MODEL;
    }
    if (m->kind == LIDET_PN_CLASSIFIER)
    {
        return !m->stage[0].use_onehot && stage_ok(&m->stage[0], m->n_classes, m->n_classes, wp, wv)
                   ? LIDET_OK
                   : LIDET_ERR_MODEL;
    }
    for (st = 0; st < m->n_stages; ++st)
    {
        const uint32_t n_out = st + 1u == m->n_stages ? box_outputs(m) : 3u;
        if (!stage_ok(&m->stage[st], m->n_classes, n_out, wp, wv))
        {
            return LIDET_ERR_MODEL;
        }
    }
    return LIDET_OK;
}

lidet_status_t lidet_pointnet_q_check(const lidet_pointnet_q_model_t *model, uint32_t kind, uint32_t n_points)
{
    uint16_t wp, wv;
    lidet_status_t st;
    if (model == 0)
    {
        return LIDET_ERR_ARG;
    }
    st = check_widths(model, &wp, &wv);
    return st != LIDET_OK ? st : lidet__pn_match(model->kind, model->n_points, kind, n_points);
}

uint32_t lidet_pointnet_q_scratch_bytes(const lidet_pointnet_q_model_t *model)
{
    uint16_t wp, wv;
    if (model == 0 || check_widths(model, &wp, &wv) != LIDET_OK)
    {
        return 0;
    }
    return LIDET_POINTNET_Q_SCRATCH_BYTES(wp, wv);
}

uint32_t lidet_pointnet_q_n_outputs(const lidet_pointnet_q_model_t *model)
{
    if (model == 0)
    {
        return 0;
    }
    return model->kind == LIDET_PN_BOX ? 3u + box_outputs(model) : model->n_classes;
}

lidet_status_t lidet_pointnet_q_init(lidet_pointnet_q_t *pn, const lidet_pointnet_q_model_t *model,
                                     void *scratch, uint32_t scratch_bytes, uint32_t *required)
{
    uint16_t wp, wv;
    uint32_t need;
    lidet_status_t st;
    if (pn == 0 || model == 0)
    {
        return LIDET_ERR_ARG;
    }
    memset(pn, 0, sizeof *pn);
    st = check_widths(model, &wp, &wv);
    if (st != LIDET_OK)
    {
        return st;
    }
    need = LIDET_POINTNET_Q_SCRATCH_BYTES(wp, wv);
    st = lidet__pn_scratch_ok(scratch, scratch_bytes, need, required);
    if (st != LIDET_OK)
    {
        return st;
    }
    pn->model = model;
    pn->scratch = (uint8_t *)scratch;
    pn->scratch_bytes = scratch_bytes;
    pn->w_point = wp;
    pn->w_vec = wv;
    pn->magic = LIDET_INIT_MAGIC;
    return LIDET_OK;
}

/* ---- the forward pass --------------------------------------------------------------------- */

/* Scratch layout: acc int32 [BLOCK * max(wp, wv)] | gmax int32 [wp] | act int8 [2][BLOCK * wp] |
 * vec int8 [3][wv] | pts int16 [BLOCK * 3] (each part a multiple of 4 bytes) */
typedef struct
{
    int32_t *acc;
    int32_t *gmax;
    int8_t *act[2];
    int8_t *vec[3];
    int16_t *pts;
    uint32_t acc_bytes;
    /* the first layer's table (lidet__nn_s16_3_table) kept in acc while no layer accumulates there: the layer it
     * was made for (NULL: none), and whether it could be made */
    struct first_tab
    {
        const lidet_pointnet_q_layer_t *layer;
        int ok;
    } * tab;
} bufs_t;

static void split_scratch(const lidet_pointnet_q_t *pn, bufs_t *b)
{
    uint8_t *p = pn->scratch;
    const uint32_t w = pn->w_point > pn->w_vec ? pn->w_point : pn->w_vec;
    const uint32_t na = (uint32_t)LIDET_PN_BLOCK * pn->w_point;
    b->acc = (int32_t *)(void *)p;
    b->acc_bytes = 4u * LIDET_PN_BLOCK * w;
    p += 4u * LIDET_PN_BLOCK * w;
    b->gmax = (int32_t *)(void *)p;
    p += 4u * pn->w_point;
    b->act[0] = (int8_t *)p;
    b->act[1] = (int8_t *)p + na;
    p += LIDET_PNQ_ALIGN4(2u * na);
    b->vec[0] = (int8_t *)p;
    b->vec[1] = (int8_t *)p + pn->w_vec;
    b->vec[2] = (int8_t *)p + 2u * pn->w_vec;
    p += LIDET_PNQ_ALIGN4(3u * pn->w_vec);
    b->pts = (int16_t *)(void *)p;
}

static int16_t sat16(int64_t v)
{
    return (int16_t)(v < -32768 ? -32768 : (v > 32767 ? 32767 : v));
}

/* rotation and shift of one proposal's points into the model frame (ref: model_frame) */
typedef struct
{
    int32_t c, s;            /* Q30 cos, sin of the mean's azimuth */
    int rotate;              /* 0: the points are in the model frame (mm) already */
    const int32_t *shift_mm; /* T-Net centre, or NULL */
} frame_t;

static const void *load_block(const bufs_t *b, const int16_t *xyz, uint32_t nb, const frame_t *f)
{
    int16_t *out = b->pts;
    uint32_t i;
    const int32_t sx = f->shift_mm != 0 ? f->shift_mm[0] : 0, sy = f->shift_mm != 0 ? f->shift_mm[1] : 0;
    const int32_t sz = f->shift_mm != 0 ? f->shift_mm[2] : 0;
    /* without a 32 x 32 -> 64 multiply (LIDET_Q_HAVE_MUL64 0): c and s split into 15-bit halves, the two sums
     * from 32-bit products (lidet__q_dot2_r28_split; the same values) where |ch| + |sh| allows it (every frame of
     * a mean farther than a few steps from the sensor) */
    const int32_t ch = (int32_t)(((int64_t)f->c + (1 << 14)) >> 15);
    const int32_t sh = (int32_t)(((int64_t)f->s + (1 << 14)) >> 15);
    const int32_t cl = f->c - (int32_t)((uint32_t)ch << 15), sl = f->s - (int32_t)((uint32_t)sh << 15);
    const int split = !LIDET_Q_HAVE_MUL64 && f->rotate && (ch < 0 ? -ch : ch) + (sh < 0 ? -sh : sh) <= 65000;
    for (i = 0; i < nb; ++i)
    {
        const int64_t x = xyz[3u * i], y = xyz[3u * i + 1u], z = xyz[3u * i + 2u];
        int64_t xr = x, yr = y, zr = z;
        if (split)
        {
            xr = lidet__q_dot2_r28_split(ch, cl, sh, sl, (int32_t)x, (int32_t)y);
            yr = lidet__q_dot2_r28_split(-sh, -sl, ch, cl, (int32_t)x, (int32_t)y);
            zr = z * 4;
        }
        else if (f->rotate)
        {
            /* 4 mm steps -> mm: Q30 products shifted by 28 */
            xr = lidet__q_rshift_round((int64_t)f->c * x + (int64_t)f->s * y, 28);
            yr = lidet__q_rshift_round(-(int64_t)f->s * x + (int64_t)f->c * y, 28);
            zr = z * 4;
        }
        out[3u * i] = sat16(xr - sx);
        out[3u * i + 1u] = sat16(yr - sy);
        out[3u * i + 2u] = sat16(zr - sz);
    }
    return out;
}

/* an int8 x int8 layer into the accumulators: the packed copy of its weights where the model has one (cores
 * with the DSP extension, LIDET_PNQ_WEIGHTS_PK), else the [in][out] weights; the same int32 sums either way */
static void acc_s8(const lidet_pointnet_q_layer_t *ly, const int8_t *in, uint32_t n_rows, int32_t *acc)
{
    if (ly->w_pk != 0)
    {
        lidet__nn_acc_s8_pk(in, n_rows, ly->n_in, ly->w_pk, ly->w_t, ly->b, ly->n_out, acc);
    }
    else
    {
        lidet__nn_acc_s8(in, n_rows, ly->n_in, ly->w_t, ly->b, ly->b_list, ly->n_out, acc);
    }
}

static void requant_s8(const lidet_pointnet_q_layer_t *l, const int32_t *acc, uint32_t n_rows, int8_t *out)
{
    lidet__nn_requant_s8(acc, n_rows, l->n_out, l->mult, l->shift, l->out_zp, l->relu ? l->out_zp : -128,
                         out);
}

/* PVLE or head layers on one vector: in (int8, or the int16 voxel for a PVLE's first layer) -> tmp0/tmp1
 * alternately -> out_s8 (int8) or out_q16 (the last head layer). onehot_b: added to layer 0's accumulators. */
static void run_vec_layers(const lidet_pointnet_q_layer_t *l, uint32_t n, const int16_t *in16,
                           const int8_t *in8, const int32_t *onehot_b, const bufs_t *b, int8_t *out_s8,
                           int32_t *out_q16)
{
    uint32_t i, o;
    const int8_t *cur = in8;
    b->tab->layer = 0; /* acc is written below */
    for (i = 0; i < n; ++i)
    {
        int8_t *dst = i + 1u == n ? out_s8 : (cur == b->vec[1] ? b->vec[2] : b->vec[1]);
        if (i == 0 && in16 != 0)
        {
            lidet__nn_acc_s16(in16, 1u, l[i].n_in, l[i].w_t, l[i].b, l[i].n_out, b->acc);
        }
        else if (!(i == 0 && onehot_b != 0) && l[i].out != LIDET_PNQ_OUT_Q16 && l[i].w_pk != 0 &&
                 lidet__nn_acc_s8_pk_fused(cur, 1u, l[i].n_in, l[i].w_pk, l[i].b, l[i].n_out, l[i].mult,
                                           l[i].shift, l[i].out_zp, l[i].relu ? l[i].out_zp : -128, dst, 0))
        {
            cur = dst; /* accumulated and requantized in one pass */
            continue;
        }
        else
        {
            acc_s8(&l[i], cur, 1u, b->acc);
        }
        if (i == 0 && onehot_b != 0)
        {
            for (o = 0; o < l[i].n_out; ++o)
            {
                b->acc[o] += onehot_b[o];
            }
        }
        if (l[i].out == LIDET_PNQ_OUT_Q16)
        {
            lidet__nn_requant_q16(b->acc, l[i].n_out, l[i].mult, l[i].shift, out_q16);
            return;
        }
        requant_s8(&l[i], b->acc, 1u, dst);
        cur = dst;
    }
}

static void max_init(const bufs_t *b, uint32_t n)
{
    uint32_t i;
    for (i = 0; i < n; ++i)
    {
        b->gmax[i] = INT32_MIN;
    }
}

/* layer l into the int32 accumulators: int16 x int8 for the first (the points in mm), int8 x int8 after */
static void dense_acc(const lidet_pointnet_q_layer_t *ly, const void *in, uint32_t nb, const bufs_t *b,
                      uint32_t l)
{
    b->tab->layer = 0; /* acc is written here */
    if (l == 0)
    {
        lidet__nn_acc_s16((const int16_t *)in, nb, 3u, ly->w_t, ly->b, ly->n_out, b->acc);
    }
    else
    {
        acc_s8(ly, (const int8_t *)in, nb, b->acc);
    }
}

/* layer l in one pass: l > 0 (int8 inputs) where the model has the packed weights, requantized into dst or, for
 * the last layer (dst NULL), folded into the running maximum; the first (int16 x, y, z) on cores without SIMD;
 * 0 where it does not apply */
static int fused_s8(const lidet_pointnet_q_layer_t *ly, const void *in, uint32_t nb, const bufs_t *b,
                    uint32_t l, int8_t *dst)
{
    if (l == 0)
    {
        /* the points' layer (x, y, z): on cores without SIMD in one pass when it is a hidden layer */
        if (LIDET_NN_SIMD || ly->n_in != 3u || dst == 0)
        {
            return 0;
        }
        if (LIDET_NN_S16_3_TABLE && b->tab->layer != ly)
        {
            /* the layer's constants once per stage, not once per block (the fused layers after it leave acc
             * alone) */
            b->tab->layer = ly;
            b->tab->ok = lidet__nn_s16_3_table(ly->w_t, ly->b, ly->n_out, ly->mult, ly->shift, ly->out_zp,
                                               ly->relu ? ly->out_zp : -128, b->acc, b->acc_bytes);
        }
        if (LIDET_NN_S16_3_TABLE && b->tab->ok)
        {
            lidet__nn_s16_3_table_run((const int16_t *)in, nb, b->acc, ly->n_out, dst);
            return 1;
        }
        lidet__nn_acc_s16_3_requant((const int16_t *)in, nb, ly->w_t, ly->b, ly->n_out, ly->mult, ly->shift,
                                    ly->out_zp, ly->relu ? ly->out_zp : -128, dst);
        return 1;
    }
#if LIDET_NN_S8_KERNEL == LIDET_NN_S8_KERNEL_LIST
    /* the last layer: its rows' sums folded into the running maximum as they are made (not written, then read) */
    if (dst == 0 && ly->w_pk == 0 &&
        lidet__nn_acc_s8_list_max((const int8_t *)in, nb, ly->n_in, ly->w_t, ly->b, ly->b_list, ly->n_out,
                                  b->acc, b->gmax))
    {
        b->tab->layer = 0; /* acc is written */
        return 1;
    }
#endif
    if (ly->w_pk == 0)
    {
        return 0;
    }
    return lidet__nn_acc_s8_pk_fused((const int8_t *)in, nb, ly->n_in, ly->w_pk, ly->b, ly->n_out, ly->mult,
                                     ly->shift, ly->out_zp, ly->relu ? ly->out_zp : -128, dst,
                                     dst == 0 ? b->gmax : 0);
}

/* the shared layers (internal/lidet_pn_points_body.h): hidden layers requantized into act[l & 1], the last
 * one's accumulators folded into the running maximum gmax (requantized once by run_stage) */
#define PNB_FN run_points
#define PNB_LAYER_T lidet_pointnet_q_layer_t
#define PNB_BUFS_T bufs_t
#define PNB_PTS_T int16_t
#define PNB_FRAME_T frame_t
#define PNB_MAX_INIT(b, n) max_init(b, n)
#define PNB_LOAD(b, pts, nb, f) load_block(b, pts, nb, f)
#define PNB_DENSE(ly, in, nb, b, l) dense_acc(ly, in, nb, b, l)
#define PNB_STORE(ly, nb, b, dst) requant_s8(ly, (b)->acc, nb, dst)
#define PNB_FOLD_MAX(ly, nb, b, l) lidet__nn_max_rows_s32((b)->acc, nb, (ly)->n_out, (b)->gmax)
#define PNB_FUSED(ly, in, nb, b, l, dst) fused_s8(ly, in, nb, b, l, dst)
#include "internal/lidet_pn_points_body.h"

/* One stage (ref: run_stage): blocks of points -> model frame (int16 mm) -> shared layers, the last one's
 * accumulators folded into a running max; requantized once -> g; [g | pvle(voxel)] -> head -> out (Q16). */
static void run_stage(const lidet_pointnet_q_stage_t *s, const bufs_t *b, const int16_t *xyz, uint32_t n,
                      const frame_t *f, const int16_t voxel[3], uint32_t cls, uint32_t n_classes,
                      int32_t *out)
{
    const lidet_pointnet_q_layer_t *last = &s->point[s->n_point - 1];
    (void)n_classes;
    run_points(s->point, s->n_point, b, xyz, n, f);
    requant_s8(last, b->gmax, 1u, b->vec[0]);
    if (s->n_pvle > 0)
    {
        run_vec_layers(s->pvle, s->n_pvle, voxel, 0, 0, b, b->vec[0] + last->n_out, 0);
    }
    run_vec_layers(s->head, s->n_head, 0, b->vec[0], s->use_onehot ? s->onehot_b + cls * s->head[0].n_out : 0,
                   b, 0, out);
}

/* ref: forward. out = [logits] or [tnet(3) | box] (Q16); the caller checked the arguments. */
static void forward(const lidet_pointnet_q_t *pn, const int16_t *xyz, uint32_t n, const frame_t *f,
                    const int16_t voxel[3], uint32_t cls, int32_t *out)
{
    const lidet_pointnet_q_model_t *m = pn->model;
    bufs_t b;
    struct first_tab tab;
    split_scratch(pn, &b);
    tab.layer = 0;
    tab.ok = 0;
    b.tab = &tab;
    if (m->kind == LIDET_PN_CLASSIFIER)
    {
        run_stage(&m->stage[0], &b, xyz, n, f, voxel, 0, m->n_classes, out);
    }
    else if (m->n_stages == 2)
    {
        int32_t t_mm[3];
        frame_t f2 = *f;
        uint32_t k;
        run_stage(&m->stage[0], &b, xyz, n, f, voxel, cls, m->n_classes, out);
        for (k = 0; k < 3u; ++k)
        {
            t_mm[k] = (int32_t)lidet__q_rshift_round((int64_t)out[k] * 1000, 16);
        }
        f2.shift_mm = t_mm;
        run_stage(&m->stage[1], &b, xyz, n, &f2, voxel, cls, m->n_classes, out + 3);
    }
    else
    {
        out[0] = out[1] = out[2] = 0;
        run_stage(&m->stage[0], &b, xyz, n, f, voxel, cls, m->n_classes, out + 3);
    }
}

static lidet_status_t check_run(const lidet_pointnet_q_t *pn, uint32_t kind)
{
    if (pn->magic != LIDET_INIT_MAGIC || pn->model == 0)
    {
        return LIDET_ERR_STATE;
    }
    return kind != 0 && pn->model->kind != kind ? LIDET_ERR_MODEL : LIDET_OK;
}

lidet_status_t lidet_pointnet_q_forward(lidet_pointnet_q_t *pn, const int16_t *points_mm, uint32_t n_points,
                                        const int16_t voxel[3], uint32_t cls, int32_t *out, uint32_t n_out)
{
    const lidet_pointnet_q_model_t *m;
    frame_t f;
    lidet_status_t st;
    if (pn == 0 || points_mm == 0 || voxel == 0 || out == 0)
    {
        return LIDET_ERR_ARG;
    }
    st = check_run(pn, 0);
    if (st != LIDET_OK)
    {
        return st;
    }
    m = pn->model;
    if (n_points != m->n_points || n_out < lidet_pointnet_q_n_outputs(m) ||
        (m->kind == LIDET_PN_BOX && cls >= m->n_classes))
    {
        return LIDET_ERR_ARG;
    }
    f.c = LIDET_Q_ONE_Q30;
    f.s = 0;
    f.rotate = 0;
    f.shift_mm = 0;
    forward(pn, points_mm, n_points, &f, voxel, m->kind == LIDET_PN_BOX ? cls : 0u, out);
    return LIDET_OK;
}

/* ---- energies, frame, decoding ------------------------------------------------------------ */

/* exp(-d) in Q30, d >= 0 in Q16 nats: 2^-(d log2 e) from the 2^-x table, interpolated */
static int64_t exp_neg_q30(int64_t d)
{
    int64_t u, v;
    int32_t k, j, fr, t0;
    if (d >= E_CUT_Q16)
    {
        return 0;
    }
    u = lidet__q_rshift_round(d * LOG2E_Q30, 30);
    k = (int32_t)(u >> 16);
    j = (int32_t)((u & 0xFFFF) >> 8);
    fr = (int32_t)(u & 0xFF);
    t0 = lidet__pnq_exp2_neg_q30[j];
    v = t0 + lidet__q_rshift_round((int64_t)(lidet__pnq_exp2_neg_q30[j + 1] - t0) * fr, 8);
    return k == 0 ? v : lidet__q_rshift_round(v, (unsigned)k);
}

/* ln(S / 2^30) in Q16 for a sum S >= 2^30 (Q30): S = m 2^e, m in [2^30, 2^31); log2 m from the table */
int64_t lidet__pnq_ln_q16(int64_t sum)
{
    int64_t m = sum, fr, l2;
    int32_t e = 0, j, t0;
    while (m >= ((int64_t)1 << 31))
    {
        ++e;
        m = lidet__q_rshift_round(sum, (unsigned)e);
    }
    fr = m - ((int64_t)1 << 30);
    j = (int32_t)(fr >> 22);
    t0 = lidet__pnq_log2_q30[j];
    l2 = ((int64_t)e << 30) + t0 +
         lidet__q_rshift_round((int64_t)(lidet__pnq_log2_q30[j + 1] - t0) * (fr & ((1 << 22) - 1)), 22);
    return lidet__q_rshift_round(l2 * LN2_Q24, 38);
}

static int32_t sat32(int64_t v)
{
    return v < INT32_MIN ? INT32_MIN : (v > INT32_MAX ? INT32_MAX : (int32_t)v);
}

/* ref: energy_parts. Energy (Q16), and when terms != NULL the exp terms (Q30) and their sum. */
static int32_t energy_parts(const int32_t *v, uint32_t n, int32_t t_q16, int64_t *terms, int64_t *sum_out)
{
    int64_t mx = INT64_MIN, sum = 0, lse;
    uint32_t i;
    for (i = 0; i < n; ++i)
    {
        const int64_t u = t_q16 == 65536 ? v[i] : lidet__q_div_round((int64_t)v[i] * 65536, t_q16);
        mx = u > mx ? u : mx;
    }
    for (i = 0; i < n; ++i)
    {
        const int64_t u = t_q16 == 65536 ? v[i] : lidet__q_div_round((int64_t)v[i] * 65536, t_q16);
        const int64_t e = exp_neg_q30(mx - u);
        if (terms != 0)
        {
            terms[i] = e;
        }
        sum += e;
    }
    if (sum_out != 0)
    {
        *sum_out = sum;
    }
    lse = mx + lidet__pnq_ln_q16(sum);
    return sat32(t_q16 == 65536 ? -lse : -lidet__q_rshift_round((int64_t)t_q16 * lse, 16));
}

int32_t lidet_pointnet_q_energy(const int32_t *v_q16, uint32_t n, int32_t t_q16)
{
    if (v_q16 == 0 || n == 0 || t_q16 <= 0)
    {
        return 0;
    }
    return energy_parts(v_q16, n, t_q16, 0, 0);
}

/* cos, sin (Q30) of the mean's azimuth (ref: frame_cs) */
static void frame_of(const lidet_proposal_q_t *p, frame_t *f)
{
    const int64_t x = p->mean_4mm[0], y = p->mean_4mm[1];
    const int64_t r = lidet__q_sqrt_round64((uint64_t)(x * x + y * y));
    f->c = LIDET_Q_ONE_Q30;
    f->s = 0;
    if (r > 0)
    {
        f->c = (int32_t)lidet__q_div_round(x * ((int64_t)1 << 30), r);
        f->s = (int32_t)lidet__q_div_round(y * ((int64_t)1 << 30), r);
    }
    f->rotate = 1;
    f->shift_mm = 0;
}

static uint32_t argmax32(const int32_t *v, uint32_t n)
{
    uint32_t i, best = 0;
    for (i = 1; i < n; ++i)
    {
        if (v[i] > v[best])
        {
            best = i;
        }
    }
    return best;
}

static lidet_status_t check_proposal(const lidet_pointnet_q_model_t *m, const lidet_proposal_q_t *p)
{
    uint32_t k;
    if (p->n_points != m->n_points)
    {
        return LIDET_ERR_ARG;
    }
    for (k = 0; k < 3u; ++k)
    {
        /* the mean of a proposal of points within LIDET_Q_COORD_MAX_MM: anything else is not one */
        if (p->mean_4mm[k] < -LIDET_Q_COORD_MAX_MM / 4 - 1 || p->mean_4mm[k] > LIDET_Q_COORD_MAX_MM / 4 + 1)
        {
            return LIDET_ERR_ARG;
        }
    }
    return LIDET_OK;
}

/* the rows the shared layers must see (internal/lidet_proposal_rule.h): the first n_points_src where the rest
 * repeat them */
static uint32_t distinct_rows(const lidet_proposal_q_t *p)
{
    uint32_t n;
#define ROW_EQ(i, j)                                                                                         \
    (p->xyz[i][0] == p->xyz[j][0] && p->xyz[i][1] == p->xyz[j][1] && p->xyz[i][2] == p->xyz[j][2])
    LIDET__PROPOSAL_DISTINCT_ROWS(p->n_points, p->n_points_src, ROW_EQ, n);
#undef ROW_EQ
    return n;
}

lidet_status_t lidet_pointnet_q_classify(lidet_pointnet_q_t *pn, const lidet_proposal_q_t *p,
                                         lidet_pointnet_q_class_out_t *out)
{
    int32_t logits[LIDET_N_CLASSES];
    int64_t terms[LIDET_N_CLASSES], sum = 0;
    const lidet_pointnet_q_model_t *m;
    frame_t f;
    lidet_status_t st;
    uint32_t i;
    if (pn == 0 || p == 0 || out == 0)
    {
        return LIDET_ERR_ARG;
    }
    st = check_run(pn, LIDET_PN_CLASSIFIER);
    if (st != LIDET_OK)
    {
        return st;
    }
    m = pn->model;
    st = check_proposal(m, p);
    if (st != LIDET_OK)
    {
        return st;
    }
    frame_of(p, &f);
    forward(pn, &p->xyz[0][0], distinct_rows(p), &f, p->voxel, 0, logits);
    out->energy_q16 = energy_parts(logits, m->n_classes, m->energy_t_q16, terms, &sum);
    out->cls = (uint8_t)argmax32(logits, m->n_classes);
    for (i = 0; i < m->n_classes; ++i)
    {
        out->logits_q16[i] = logits[i];
        out->prob_q15[i] = (int32_t)lidet__q_div_round(terms[i] * 32768, sum); /* sum >= 2^30 */
    }
    out->pass = out->energy_q16 < m->gamma_q16[out->cls] ? 1u : 0u;
    return LIDET_OK;
}

/* ref: decode_box. raw = [tnet(3) | box(3 + 2H + 4S)] Q16, model frame. */
static void decode_box(const lidet_pointnet_q_model_t *m, const int32_t *raw, const lidet_proposal_q_t *p,
                       const frame_t *f, lidet_pointnet_q_box_out_t *out)
{
    const uint32_t nh = m->n_heading_bins, ns = m->n_size_clusters;
    const int32_t *bx = raw + 3;
    const int32_t *hs = bx + 3, *hr = bx + 3 + nh, *ss = bx + 3 + 2u * nh, *sr = bx + 3 + 2u * nh + ns;
    const uint32_t hb = argmax32(hs, nh), sc = argmax32(ss, ns);
    int64_t cen[3], cm8[3];
    int32_t size[3];
    uint32_t k, yaw;
    for (k = 0; k < 3u; ++k)
    {
        cen[k] = (int64_t)raw[k] + bx[k];
        cen[k] = cen[k] < -CENTRE_LIMIT_Q16 ? -CENTRE_LIMIT_Q16
                                            : (cen[k] > CENTRE_LIMIT_Q16 ? CENTRE_LIMIT_Q16 : cen[k]);
        cm8[k] = lidet__q_rshift_round(cen[k] * 1000, 8); /* mm, Q8 */
    }
    out->box.cx_mm = (int32_t)((int64_t)p->mean_4mm[0] * 4 +
                               lidet__q_rshift_round((int64_t)f->c * cm8[0] - (int64_t)f->s * cm8[1], 38));
    out->box.cy_mm = (int32_t)((int64_t)p->mean_4mm[1] * 4 +
                               lidet__q_rshift_round((int64_t)f->s * cm8[0] + (int64_t)f->c * cm8[1], 38));
    out->box.cz_mm = (int32_t)((int64_t)p->mean_4mm[2] * 4 + lidet__q_rshift_round(cen[2] * 1000, 16));
    yaw = (uint32_t)m->heading_bam[hb] +
          (uint32_t)lidet__q_rshift_round((int64_t)hr[hb] * m->heading_res_bam, 16) +
          (uint32_t)lidet__q_atan2(p->mean_4mm[1], p->mean_4mm[0]);
    out->box.yaw_bam = (int32_t)(yaw >= 0x80000000u ? -(int32_t)(0xFFFFFFFFu - yaw) - 1 : (int32_t)yaw);
    for (k = 0; k < 3u; ++k)
    {
        const int64_t t = m->mean_size_mm[3u * sc + k];
        size[k] = sat32(t + lidet__q_rshift_round(t * sr[3u * sc + k], 16));
    }
    out->box.l_mm = size[0];
    out->box.w_mm = size[1];
    out->box.h_mm = size[2];
    out->heading_bin = (uint8_t)hb;
    out->size_cluster = (uint8_t)sc;
    out->energy_heading_q16 = energy_parts(hs, nh, m->energy_t_q16, 0, 0);
    out->energy_size_q16 = energy_parts(ss, ns, m->energy_t_q16, 0, 0);
    out->energy_q16 = sat32((int64_t)out->energy_heading_q16 + out->energy_size_q16);
}

lidet_status_t lidet_pointnet_q_box(lidet_pointnet_q_t *pn, const lidet_proposal_q_t *p, uint32_t cls,
                                    lidet_pointnet_q_box_out_t *out)
{
    int32_t raw[6 + 2 * LIDET_PN_MAX_HEADING_BINS + 4 * LIDET_PN_MAX_SIZE_CLUSTERS];
    const lidet_pointnet_q_model_t *m;
    frame_t f;
    lidet_status_t st;
    if (pn == 0 || p == 0 || out == 0)
    {
        return LIDET_ERR_ARG;
    }
    st = check_run(pn, LIDET_PN_BOX);
    if (st != LIDET_OK)
    {
        return st;
    }
    m = pn->model;
    if (cls >= m->n_classes)
    {
        return LIDET_ERR_ARG;
    }
    st = check_proposal(m, p);
    if (st != LIDET_OK)
    {
        return st;
    }
    frame_of(p, &f);
    forward(pn, &p->xyz[0][0], distinct_rows(p), &f, p->voxel, cls, raw);
    decode_box(m, raw, p, &f, out);
    out->pass = out->energy_q16 < m->gamma_q16[cls] ? 1u : 0u;
    return LIDET_OK;
}

const lidet_pointnet_q_model_t *lidet_pointnet_q_find(const lidet_pointnet_q_entry_t *table, uint32_t n,
                                                      const char *name)
{
    uint32_t i;
    if (table == 0 || name == 0)
    {
        return 0;
    }
    i = lidet__pn_find_index(table, n, sizeof *table, name);
    return i < n ? table[i].model : 0;
}

int64_t lidet__pnq_exp_neg_q30(int64_t d_q16)
{
    return d_q16 <= 0 ? ((int64_t)1 << 30) : exp_neg_q30(d_q16);
}
