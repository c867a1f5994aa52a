/* SPDX-License-Identifier: MIT */
/* PointNet forward pass, energies and box decoding (see lidet_pointnet.h). Mirrored function for
 * function by codegen/lidet_ref/pointnet.py: check -> (descriptor checks in emit.py),
 * run_stage -> run_stage, lidet_pn_energy -> energy, decode_box -> decode_box,
 * lidet_pn_to_model_frame -> to_model_frame. */
#include <math.h>
#include <string.h>

#include "internal/lidet_math.h"
#include "internal/lidet_nn.h"
#include "internal/lidet_pn_common.h"
#include "internal/lidet_proposal_rule.h"
#include "lidet/lidet_pointnet.h"

#define NEG_BIG (-3.0e38f)
#define TWO_PI_F 6.28318531f

/* ---- descriptor checks -------------------------------------------------------------------- */

static int layers_ok(const lidet_pn_layer_t *l, uint32_t n, uint32_t n_in_first, uint16_t *widest)
{
    uint32_t i, n_in = n_in_first;
    if (n > LIDET_PN_MAX_LAYERS || (n > 0 && l == 0))
    {
        return 0;
    }
    for (i = 0; i < n; ++i)
    {
        if (l[i].n_in != n_in || l[i].n_out == 0 || l[i].n_out > LIDET_PN_MAX_WIDTH || l[i].w_t == 0 ||
            l[i].b == 0 || l[i].relu > 1)
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

/* widths of a valid stage; 0 when the stage is malformed */
static int stage_ok(const lidet_pn_stage_t *s, uint32_t n_classes, uint32_t n_out, uint16_t *wp, uint16_t *wv)
{
    uint32_t concat;
    uint16_t w_pvle = 0, w_head = 0;
    if (s->n_point < 1 || s->n_head < 1 || s->use_onehot > 1)
    {
        return 0;
    }
    if (!layers_ok(s->point, s->n_point, 3u, wp) || !layers_ok(s->pvle, s->n_pvle, 3u, &w_pvle))
    {
        return 0;
    }
    concat = s->point[s->n_point - 1].n_out + (s->use_onehot ? n_classes : 0u) +
             (s->n_pvle ? s->pvle[s->n_pvle - 1].n_out : 0u);
    if (concat > LIDET_PN_MAX_WIDTH || !layers_ok(s->head, s->n_head, concat, &w_head) ||
        s->head[s->n_head - 1].n_out != n_out)
    {
        return 0;
    }
    *wv = lidet__pn_widest(*wv, concat, w_pvle, w_head);
    return 1;
}

static uint32_t box_outputs(const lidet_pn_model_t *m)
{
    return lidet__pn_box_outputs(m->n_heading_bins, m->n_size_clusters);
}

static lidet_status_t check_widths(const lidet_pn_model_t *m, uint16_t *wp, uint16_t *wv)
{
    uint32_t st;
    *wp = 3;
    *wv = 8;
    if (m->format_version != LIDET_WEIGHTS_FORMAT_VERSION || m->precision != LIDET_PN_F32 ||
        !lidet__pn_dims_ok(m->kind, m->n_stages, m->n_classes, m->n_points, m->n_heading_bins,
                           m->n_size_clusters, m->mean_size_m != 0) ||
        !lidet__isfinite(m->energy_t) || !(m->energy_t > 0.0f))
    {
        return LIDET_ERR_MODEL;
    }
    if (m->kind == LIDET_PN_CLASSIFIER)
    {
        return stage_ok(&m->stage[0], m->n_classes, m->n_classes, wp, wv) && !m->stage[0].use_onehot
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

lidet_status_t lidet_pn_check(const lidet_pn_model_t *model, uint32_t kind, uint32_t n_points)
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

uint32_t lidet_pn_scratch_bytes(const lidet_pn_model_t *model)
{
    uint16_t wp, wv;
    if (model == 0 || check_widths(model, &wp, &wv) != LIDET_OK)
    {
        return 0;
    }
    return LIDET_PN_SCRATCH_BYTES(wp, wv);
}

uint32_t lidet_pn_n_outputs(const lidet_pn_model_t *model)
{
    if (model == 0)
    {
        return 0;
    }
    return model->kind == LIDET_PN_BOX ? 3u + box_outputs(model) : model->n_classes;
}

lidet_status_t lidet_pn_init(lidet_pn_t *pn, const lidet_pn_model_t *model, void *scratch,
                             uint32_t scratch_bytes, uint32_t *required)
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
    need = LIDET_PN_SCRATCH_BYTES(wp, wv);
    st = lidet__pn_scratch_ok(scratch, scratch_bytes, need, required);
    if (st != LIDET_OK)
    {
        return st;
    }
    pn->model = model;
    pn->scratch = (float *)scratch;
    pn->scratch_bytes = scratch_bytes;
    pn->w_point = wp;
    pn->w_vec = wv;
    pn->magic = LIDET_INIT_MAGIC;
    return LIDET_OK;
}

/* ---- the forward pass --------------------------------------------------------------------- */

/* Scratch layout (floats): act[2][BLOCK * w_point] | vec[3][w_vec] | shifted[BLOCK * 3] | small[8] */
typedef struct
{
    float *act[2];
    float *vec[3];
    float *shifted;
} bufs_t;

static void split_scratch(const lidet_pn_t *pn, bufs_t *b)
{
    float *p = pn->scratch;
    const uint32_t na = (uint32_t)LIDET_PN_BLOCK * pn->w_point;
    b->act[0] = p;
    b->act[1] = p + na;
    p += 2u * na;
    b->vec[0] = p;
    b->vec[1] = p + pn->w_vec;
    b->vec[2] = p + 2u * pn->w_vec;
    b->shifted = p + 3u * pn->w_vec;
}

/* Runs the head-style layers l[0..n) on one vector: in -> alternating buffers -> out (n_out floats of
 * the last layer). tmp0/tmp1 hold the intermediate vectors; in may be tmp0 or tmp1's sibling. */
static void run_vec_layers(const lidet_pn_layer_t *l, uint32_t n, const float *in, float *tmp0, float *tmp1,
                           float *out)
{
    uint32_t i;
    const float *cur = in;
    for (i = 0; i < n; ++i)
    {
        float *dst = i + 1u == n ? out : (cur == tmp0 ? tmp1 : tmp0);
        lidet__nn_dense_f32(cur, 1u, l[i].n_in, l[i].w_t, l[i].b, l[i].n_out, l[i].relu, dst);
        cur = dst;
    }
}

/* the frame of one stage's points: rotation by cs (cos, sin of the mean's azimuth; NULL: already in the model
 * frame) and minus `shift` (the T-Net centre; NULL: none) */
typedef struct
{
    const float *cs;
    const float *shift;
} frame_t;

/* one block of points into the model frame (b->shifted), or the points themselves when there is nothing to do */
static const void *load_block(const bufs_t *b, const float *pts, uint32_t nb, const frame_t *f)
{
    const float c = f->cs != 0 ? f->cs[0] : 1.0f, sn = f->cs != 0 ? f->cs[1] : 0.0f;
    const float sx = f->shift != 0 ? f->shift[0] : 0.0f, sy = f->shift != 0 ? f->shift[1] : 0.0f;
    const float sz = f->shift != 0 ? f->shift[2] : 0.0f;
    uint32_t i;
    if (f->cs == 0 && f->shift == 0)
    {
        return pts;
    }
    for (i = 0; i < nb; ++i)
    {
        const float x = pts[3u * i], y = pts[3u * i + 1u];
        b->shifted[3u * i + 0u] = (c * x + sn * y) - sx;
        b->shifted[3u * i + 1u] = (-sn * x + c * y) - sy;
        b->shifted[3u * i + 2u] = pts[3u * i + 2u] - sz;
    }
    return b->shifted;
}

static void max_init(const bufs_t *b, uint32_t n)
{
    uint32_t i;
    for (i = 0; i < n; ++i)
    {
        b->vec[0][i] = NEG_BIG;
    }
}

/* the shared layers (internal/lidet_pn_points_body.h): layer l writes act[l & 1], the last one is folded into
 * the running maximum g = vec[0] */
#define PNB_FN run_points
#define PNB_LAYER_T lidet_pn_layer_t
#define PNB_BUFS_T bufs_t
#define PNB_PTS_T float
#define PNB_FRAME_T frame_t
#define PNB_MAX_INIT(b, n) max_init(b, n)
#define PNB_LOAD(b, pts, nb, f) load_block(b, pts, nb, f)
#define PNB_DENSE(ly, in, nb, b, l)                                                                          \
    lidet__nn_dense_f32((const float *)(in), nb, (ly)->n_in, (ly)->w_t, (ly)->b, (ly)->n_out, (ly)->relu,    \
                        (b)->act[(l)&1u])
#define PNB_STORE(ly, nb, b, dst) ((void)0)
#define PNB_FUSED(ly, in, nb, b, l, dst) 0
#define PNB_FOLD_MAX(ly, nb, b, l) lidet__nn_max_rows_f32((b)->act[(l)&1u], nb, (ly)->n_out, (b)->vec[0])
#include "internal/lidet_pn_points_body.h"

/* One stage (ref: run_stage): the points, rotated into the model frame by cs (cos, sin of the mean's
 * azimuth; NULL: already there) and shifted by minus `shift` (NULL: none) one block at a time, through
 * the shared layers with the fused max over the n points; then [g | onehot | pvle(voxel)] -> head -> out. */
static void run_stage(const lidet_pn_stage_t *s, const bufs_t *b, const float *points, uint32_t n,
                      const float *cs, const float *shift, const float voxel[3], const float *onehot,
                      uint32_t n_classes, float *out)
{
    const lidet_pn_layer_t *last = &s->point[s->n_point - 1];
    float *g = b->vec[0];
    frame_t f;
    uint32_t i, pos;
    f.cs = cs;
    f.shift = shift;
    run_points(s->point, s->n_point, b, points, n, &f);
    pos = last->n_out;
    if (s->use_onehot)
    {
        for (i = 0; i < n_classes; ++i)
        {
            g[pos + i] = onehot[i];
        }
        pos += n_classes;
    }
    if (s->n_pvle > 0)
    {
        run_vec_layers(s->pvle, s->n_pvle, voxel, b->vec[1], b->vec[2], g + pos);
    }
    run_vec_layers(s->head, s->n_head, g, b->vec[1], b->vec[2], out);
}

/* ref: forward. out = [logits] or [tnet(3) | box]; the caller checked the arguments. */
static void forward(const lidet_pn_t *pn, const float *points, uint32_t n, const float *cs,
                    const float voxel[3], const float *onehot, float *out)
{
    const lidet_pn_model_t *m = pn->model;
    bufs_t b;
    split_scratch(pn, &b);
    if (m->kind == LIDET_PN_CLASSIFIER)
    {
        run_stage(&m->stage[0], &b, points, n, cs, 0, voxel, 0, m->n_classes, out);
    }
    else if (m->n_stages == 2)
    {
        run_stage(&m->stage[0], &b, points, n, cs, 0, voxel, onehot, m->n_classes, out);
        run_stage(&m->stage[1], &b, points, n, cs, out, voxel, onehot, m->n_classes, out + 3);
    }
    else
    {
        out[0] = out[1] = out[2] = 0.0f;
        run_stage(&m->stage[0], &b, points, n, cs, 0, voxel, onehot, m->n_classes, out + 3);
    }
}

static lidet_status_t check_run(const lidet_pn_t *pn, uint32_t kind)
{
    if (pn->magic != LIDET_INIT_MAGIC || pn->model == 0)
    {
        return LIDET_ERR_STATE;
    }
    return kind != 0 && pn->model->kind != kind ? LIDET_ERR_MODEL : LIDET_OK;
}

lidet_status_t lidet_pn_forward(lidet_pn_t *pn, const float *points, uint32_t n_points, const float voxel[3],
                                const float *onehot, float *out, uint32_t n_out)
{
    const lidet_pn_model_t *m;
    lidet_status_t st;
    if (pn == 0 || points == 0 || voxel == 0 || out == 0)
    {
        return LIDET_ERR_ARG;
    }
    st = check_run(pn, 0);
    if (st != LIDET_OK)
    {
        return st;
    }
    m = pn->model;
    if (n_points != m->n_points || n_out < lidet_pn_n_outputs(m) || (m->kind == LIDET_PN_BOX && onehot == 0))
    {
        return LIDET_ERR_ARG;
    }
    forward(pn, points, n_points, 0, voxel, onehot, out);
    return LIDET_OK;
}

/* ---- energies, frame, decoding ------------------------------------------------------------ */

float lidet_pn_energy(const float *v, uint32_t n, float t)
{
    uint32_t i;
    float mx, sum = 0.0f;
    if (v == 0 || n == 0)
    {
        return 0.0f;
    }
    mx = v[0] / t;
    for (i = 1; i < n; ++i)
    {
        const float u = v[i] / t;
        mx = u > mx ? u : mx;
    }
    for (i = 0; i < n; ++i)
    {
        sum += expf(v[i] / t - mx);
    }
    return -t * (mx + logf(sum));
}

void lidet_pn_to_model_frame(const float *xyz, uint32_t n, const float mean[3], float *out, float cs[2])
{
    uint32_t i;
    const float r = sqrtf(mean[0] * mean[0] + mean[1] * mean[1]);
    float c = 1.0f, s = 0.0f;
    if (r > 1e-6f)
    {
        c = mean[0] / r;
        s = mean[1] / r;
    }
    for (i = 0; i < n; ++i)
    {
        const float x = xyz[3u * i], y = xyz[3u * i + 1u];
        out[3u * i] = c * x + s * y;
        out[3u * i + 1u] = -s * x + c * y;
        out[3u * i + 2u] = xyz[3u * i + 2u];
    }
    if (cs != 0)
    {
        cs[0] = c;
        cs[1] = s;
    }
}

static uint32_t argmax(const float *v, uint32_t n)
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

/* cos, sin of the mean's azimuth (ref: azimuth_cos_sin) and the voxel as floats */
static void frame_of(const lidet_proposal_t *p, float cs[2], float voxel[3])
{
    const float r = sqrtf(p->mean_m[0] * p->mean_m[0] + p->mean_m[1] * p->mean_m[1]);
    cs[0] = 1.0f;
    cs[1] = 0.0f;
    if (r > 1e-6f)
    {
        cs[0] = p->mean_m[0] / r;
        cs[1] = p->mean_m[1] / r;
    }
    voxel[0] = (float)p->voxel[0];
    voxel[1] = (float)p->voxel[1];
    voxel[2] = (float)p->voxel[2];
}

/* a row's bucket for LIDET__PROPOSAL_DISTINCT_ROWS_HASHED: a hash of its bits (rows ROW_EQ calls equal have
 * the same bits) */
static uint32_t row_hash(const float *row)
{
    uint32_t a, b, c;
    memcpy(&a, &row[0], sizeof a);
    memcpy(&b, &row[1], sizeof b);
    memcpy(&c, &row[2], sizeof c);
    return lidet__proposal_row_hash(a, b, c);
}

/* the rows the shared layers must see (internal/lidet_proposal_rule.h): the first n_points_src where the rest
 * repeat them, compared by value and by bits (a NaN row matches none, as its place in the maximum matters; -0
 * and +0 do not match each other), through the rule's hash table (LIDET__PROPOSAL_DISTINCT_ROWS_HASHED) */
static uint32_t distinct_rows(const lidet_proposal_t *p)
{
    uint32_t n;
#define ROW_EQ(i, j)                                                                                         \
    (p->xyz[i][0] == p->xyz[j][0] && p->xyz[i][1] == p->xyz[j][1] && p->xyz[i][2] == p->xyz[j][2] &&         \
     memcmp(p->xyz[i], p->xyz[j], sizeof p->xyz[i]) == 0)
#define ROW_HASH(i) row_hash(p->xyz[i])
    LIDET__PROPOSAL_DISTINCT_ROWS_HASHED(p->n_points, p->n_points_src, ROW_EQ, ROW_HASH, n);
#undef ROW_EQ
#undef ROW_HASH
    return n;
}

lidet_status_t lidet_pn_classify(lidet_pn_t *pn, const lidet_proposal_t *p, lidet_pn_class_out_t *out)
{
    float voxel[3], cs[2], logits[LIDET_N_CLASSES];
    const lidet_pn_model_t *m;
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
    if (p->n_points != m->n_points)
    {
        return LIDET_ERR_ARG;
    }
    frame_of(p, cs, voxel);
    forward(pn, &p->xyz[0][0], distinct_rows(p), cs, voxel, 0, logits);
    out->energy = lidet_pn_energy(logits, m->n_classes, m->energy_t);
    out->cls = (uint8_t)argmax(logits, m->n_classes);
    for (i = 0; i < m->n_classes; ++i)
    {
        /* softmax(l / T) = exp(l / T + E / T), since E = -T logsumexp(l / T) */
        out->logits[i] = logits[i];
        out->prob[i] = expf((logits[i] + out->energy) / m->energy_t);
    }
    out->pass = out->energy < m->gamma[out->cls] ? 1u : 0u;
    return LIDET_OK;
}

/* a heading wrapped to (-pi, pi]. fmodf is exact, so the loops below run at most once whatever the
 * magnitude (a network fed hostile points can output 1e38 or Inf: the loops alone never ended, issue 19,
 * found by fuzz_pointnet); a non-finite heading is returned as NaN (the box is invalid). */
static float wrap_pi(float a)
{
    if (!lidet__isfinite(a))
    {
        return a - a; /* NaN for Inf and NaN */
    }
    if (a > TWO_PI_F || a < -TWO_PI_F)
    {
        a = fmodf(a, TWO_PI_F);
    }
    while (a > LIDET_PI_F)
    {
        a -= TWO_PI_F;
    }
    while (a <= -LIDET_PI_F)
    {
        a += TWO_PI_F;
    }
    return a;
}

/* ref: decode_box. raw = [tnet(3) | box(3 + 2H + 4S)] in the model frame. */
static void decode_box(const lidet_pn_model_t *m, const float *raw, const float mean[3], const float cs[2],
                       lidet_pn_box_out_t *out)
{
    const uint32_t nh = m->n_heading_bins, ns = m->n_size_clusters;
    const float *bx = raw + 3;
    const float *hs = bx + 3, *hr = bx + 3 + nh, *ss = bx + 3 + 2u * nh, *sr = bx + 3 + 2u * nh + ns;
    const float apb = TWO_PI_F / (float)nh;
    const uint32_t hb = argmax(hs, nh), sc = argmax(ss, ns);
    const float cx = raw[0] + bx[0], cy = raw[1] + bx[1], cz = raw[2] + bx[2];
    const float yaw_m = (float)hb * apb + hr[hb] * (apb * 0.5f);
    uint32_t k;
    out->box.cx_m = mean[0] + cs[0] * cx - cs[1] * cy;
    out->box.cy_m = mean[1] + cs[1] * cx + cs[0] * cy;
    out->box.cz_m = mean[2] + cz;
    out->box.yaw_rad = wrap_pi(yaw_m + atan2f(cs[1], cs[0]));
    for (k = 0; k < 3; ++k)
    {
        const float v = m->mean_size_m[3u * sc + k] * (1.0f + sr[3u * sc + k]);
        (&out->box.l_m)[k] = v;
    }
    out->heading_bin = (uint8_t)hb;
    out->size_cluster = (uint8_t)sc;
    out->energy_heading = lidet_pn_energy(hs, nh, m->energy_t);
    out->energy_size = lidet_pn_energy(ss, ns, m->energy_t);
    out->energy = out->energy_heading + out->energy_size;
}

lidet_status_t lidet_pn_box(lidet_pn_t *pn, const lidet_proposal_t *p, uint32_t cls, lidet_pn_box_out_t *out)
{
    float voxel[3], cs[2], onehot[LIDET_N_CLASSES];
    float raw[6 + 2 * LIDET_PN_MAX_HEADING_BINS + 4 * LIDET_PN_MAX_SIZE_CLUSTERS];
    const lidet_pn_model_t *m;
    lidet_status_t st;
    uint32_t i;
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
    if (p->n_points != m->n_points || cls >= m->n_classes)
    {
        return LIDET_ERR_ARG;
    }
    for (i = 0; i < LIDET_N_CLASSES; ++i)
    {
        onehot[i] = i == cls ? 1.0f : 0.0f;
    }
    frame_of(p, cs, voxel);
    forward(pn, &p->xyz[0][0], distinct_rows(p), cs, voxel, onehot, raw);
    decode_box(m, raw, p->mean_m, cs, out);
    out->pass = out->energy < m->gamma[cls] ? 1u : 0u;
    return LIDET_OK;
}

const lidet_pn_model_t *lidet_pn_find(const lidet_pn_entry_t *table, uint32_t n, const char *name)
{
    uint32_t i;
    if (table == 0 || name == 0)
    {
        return 0;
    }
    i = lidet__pn_find_index(table, n, sizeof *table, name);
    return i < n ? table[i].model : 0;
}
