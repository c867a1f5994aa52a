/* SPDX-License-Identifier: MIT */
/* libFuzzer harness: the int8 PointNets of the integer build (lidet_pointnet_q_*).
 * Mode 0 (first byte even): one of the tiny int8 models of tests/fuzz/models (classifier or box net, 16 or 64
 * points) through lidet_pointnet_q_forward, _classify, _box and _energy on points, voxels, means, classes and
 * proposals taken raw from the input (int16 / int32 at their limits included). Checks statuses, classes and
 * bins in range, Q15 scores in [0, 32768], gates 0 or 1.
 * Mode 1 (first byte odd): the model-descriptor checks (lidet_pointnet_q_check, _scratch_bytes, _init) on a
 * tiny model copied and mutated field by field and value by value (format version, kind, precision, counts,
 * widths, output kinds, zero points, multipliers, shifts, biases, one-hot biases, box tables, temperature,
 * NULL arrays), with short and misaligned scratch. Every array of the copy points into buffers large enough
 * for any layer the checks allow, so a descriptor the checks accept must be safe to run: it is run. */
#include "fuzz_common.h"
#include "fuzz_models.h"
#include "lidet/lidet_pointnet_q.h"

#define MAXW LIDET_PN_MAX_WIDTH
#define SCRATCH_BYTES (LIDET_POINTNET_Q_SCRATCH_BYTES(MAXW, MAXW) + 64u)
/* forward passes of accepted descriptors above this many multiply-adds are skipped (time, not safety) */
#define MAX_MACS 300000u

static int8_t g_w[MAXW * MAXW];
static int32_t g_b[MAXW], g_mult[MAXW], g_onehot[LIDET_N_CLASSES * MAXW], g_table[3u * 256u];
static uint8_t g_shift[MAXW];
static uint32_t g_scratch[SCRATCH_BYTES / 4u + 1u];
static lidet_pointnet_q_layer_t g_layers[2][3][LIDET_PN_MAX_LAYERS];
static int16_t g_pts[LIDET_PROPOSAL_POINTS * 3];
static int32_t g_out[4096];
static lidet_proposal_q_t g_prop;

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static void fill_once(void)
{
    static int filled = 0;
    uint32_t i;
    if (filled)
    {
        return;
    }
    for (i = 0; i < MAXW * MAXW; ++i)
    {
        g_w[i] = (int8_t)((int)(i % 7u) - 3);
    }
    for (i = 0; i < MAXW; ++i)
    {
        g_mult[i] = 1 << 30;
        g_shift[i] = 36;
    }
    for (i = 0; i < 3u * 256u; ++i)
    {
        g_table[i] = 1000 + (int32_t)(i % 5u) * 300;
    }
    filled = 1;
}

/* a mutable copy of m whose layers live in g_layers and whose arrays all point into the g_ buffers */
static void copy_model(const lidet_pointnet_q_model_t *m, lidet_pointnet_q_model_t *c)
{
    uint32_t s, i, l;
    *c = *m;
    memset(g_layers, 0, sizeof g_layers);
    memset(g_b, 0, sizeof g_b);
    memset(g_onehot, 0, sizeof g_onehot);
    for (s = 0; s < 2u; ++s)
    {
        const lidet_pointnet_q_layer_t *src[3] = {m->stage[s].point, m->stage[s].pvle, m->stage[s].head};
        const uint8_t cnt[3] = {m->stage[s].n_point, m->stage[s].n_pvle, m->stage[s].n_head};
        for (i = 0; i < 3u; ++i)
        {
            for (l = 0; l < cnt[i] && l < LIDET_PN_MAX_LAYERS && src[i] != NULL; ++l)
            {
                g_layers[s][i][l] = src[i][l];
            }
            for (l = 0; l < LIDET_PN_MAX_LAYERS; ++l)
            {
                g_layers[s][i][l].w_t = g_w;
                g_layers[s][i][l].b = g_b;
                g_layers[s][i][l].mult = g_mult;
                g_layers[s][i][l].shift = g_shift;
            }
        }
        c->stage[s].point = src[0] ? g_layers[s][0] : NULL;
        c->stage[s].pvle = src[1] ? g_layers[s][1] : NULL;
        c->stage[s].head = src[2] ? g_layers[s][2] : NULL;
        c->stage[s].onehot_b = m->stage[s].onehot_b ? g_onehot : NULL;
    }
    c->mean_size_mm = m->mean_size_mm ? g_table : NULL;
    c->heading_bam = m->heading_bam ? g_table : NULL;
}

static void mutate(fz_in_t *in, lidet_pointnet_q_model_t *c)
{
    const uint8_t sel = fz_u8(in);
    const uint32_t v = fz_u32(in), s = (v >> 16) & 1u, k = (v >> 8) % MAXW;
    lidet_pointnet_q_stage_t *st = &c->stage[s];
    lidet_pointnet_q_layer_t *l = &g_layers[s][(v >> 17) % 3u][(v >> 20) % LIDET_PN_MAX_LAYERS];
    switch (sel % 30u)
    {
    case 0: c->format_version = v; break;
    case 1: c->kind = (uint8_t)v; break;
    case 2: c->precision = (uint8_t)v; break;
    case 3: c->n_stages = (uint8_t)v; break;
    case 4: c->n_classes = (uint8_t)v; break;
    case 5: c->n_points = (uint16_t)v; break;
    case 6: c->n_heading_bins = (uint8_t)v; break;
    case 7: c->n_size_clusters = (uint8_t)v; break;
    case 8: c->mean_size_mm = (v & 1u) ? g_table : NULL; break;
    case 9: c->heading_bam = (v & 1u) ? g_table : NULL; break;
    case 10: c->energy_t_q16 = (int32_t)v; break;
    case 11: c->pvle_bin[v % 3u] = (int32_t)fz_u32(in); break;
    case 12: c->heading_res_bam = (int32_t)v; break;
    case 13: st->n_point = (uint8_t)v; break;
    case 14: st->n_pvle = (uint8_t)v; break;
    case 15: st->n_head = (uint8_t)v; break;
    case 16: st->use_onehot = (uint8_t)v; break;
    case 17: l->n_in = (uint16_t)v; break;
    case 18: l->n_out = (uint16_t)(v & 0xFFFFu); break;
    case 19: l->relu = (uint8_t)v; break;
    case 20: l->out = (uint8_t)v; break;
    case 21: l->out_zp = (int8_t)v; break;
    case 22: l->w_t = (v & 1u) ? g_w : NULL; break;
    case 23: l->mult = (v & 1u) ? g_mult : NULL; break;
    case 24: g_mult[k] = (int32_t)fz_u32(in); break;
    case 25: g_shift[k] = (uint8_t)v; break;
    case 26: g_b[k] = (int32_t)fz_u32(in); break;
    case 27: g_onehot[(v >> 8) % (LIDET_N_CLASSES * MAXW)] = (int32_t)fz_u32(in); break;
    case 28: g_table[(v >> 8) % (3u * 256u)] = (int32_t)fz_u32(in); break;
    default: st->onehot_b = (v & 1u) ? g_onehot : NULL; break;
    }
}

FZ_DEFINE_MACS(macs, lidet_pointnet_q_model_t, lidet_pointnet_q_stage_t)

static void read_proposal(fz_in_t *in, uint32_t n_pts)
{
    uint32_t i;
    memset(&g_prop, 0, sizeof g_prop);
    for (i = 0; i < 3u; ++i)
    {
        g_prop.mean_4mm[i] = (int32_t)fz_u32(in);
        g_prop.voxel[i] = (int16_t)fz_u16(in);
    }
    memcpy(g_prop.xyz, g_pts, sizeof g_pts);
    g_prop.n_points = n_pts;
    g_prop.n_points_src = n_pts;
}

/* classify / box a proposal with an initialised pn: LIDET_OK exactly when the count is the model's, the mean
 * is one a proposal of points within LIDET_Q_COORD_MAX_MM can have and (box net) the class exists */
static void run_heads(lidet_pointnet_q_t *pn, const lidet_pointnet_q_model_t *m, uint32_t n_pts, uint32_t cls)
{
    lidet_status_t st;
    uint32_t i, ok = n_pts == m->n_points;
    for (i = 0; i < 3u; ++i)
    {
        ok &= g_prop.mean_4mm[i] >= -LIDET_Q_COORD_MAX_MM / 4 - 1 && g_prop.mean_4mm[i] <= LIDET_Q_COORD_MAX_MM / 4 + 1;
    }
    if (m->kind == LIDET_PN_CLASSIFIER)
    {
        lidet_pointnet_q_class_out_t co;
        st = lidet_pointnet_q_classify(pn, &g_prop, &co);
        FZ_CHECK(st == (ok ? LIDET_OK : LIDET_ERR_ARG));
        if (st == LIDET_OK)
        {
            FZ_CHECK(co.cls < m->n_classes && co.pass <= 1);
            for (i = 0; i < m->n_classes && i < LIDET_N_CLASSES; ++i)
            {
                FZ_CHECK(co.prob_q15[i] >= 0 && co.prob_q15[i] <= 32768);
            }
        }
    }
    else
    {
        lidet_pointnet_q_box_out_t bo;
        st = lidet_pointnet_q_box(pn, &g_prop, cls, &bo);
        FZ_CHECK(st == ((ok && cls < m->n_classes) ? LIDET_OK : LIDET_ERR_ARG));
        if (st == LIDET_OK)
        {
            FZ_CHECK(bo.heading_bin < m->n_heading_bins && bo.size_cluster < m->n_size_clusters && bo.pass <= 1);
        }
    }
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    fz_in_t in = {data, size};
    const uint8_t mode = fz_u8(&in), flags = fz_u8(&in), cls_b = fz_u8(&in);
    const lidet_pointnet_q_model_t *m = tiny_s8_model((mode >> 1) & 1u, (mode >> 2) & 1u);
    lidet_pointnet_q_model_t c;
    lidet_pointnet_q_t pn;
    int16_t voxel[3];
    uint32_t i, n_pts, n_out, need = 0;
    lidet_status_t st, st_init;
    uint8_t *scratch = (uint8_t *)g_scratch;
    uint32_t scratch_bytes = (uint32_t)sizeof g_scratch - 4u;
    fill_once();
    if (mode & 1u)
    {
        const uint32_t n_mut = fz_u8(&in) % 17u;
        const uint8_t scratch_mode = fz_u8(&in);
        copy_model(m, &c);
        for (i = 0; i < n_mut; ++i)
        {
            mutate(&in, &c);
        }
        m = &c;
        if (scratch_mode & 1u)
        {
            scratch += 1 + (scratch_mode >> 6); /* misaligned: 1 .. 4 bytes in */
        }
        if (scratch_mode & 2u)
        {
            scratch_bytes = (scratch_mode >> 2) * 16u; /* short */
        }
    }
    st = lidet_pointnet_q_check(m, m->kind, m->n_points);
    need = lidet_pointnet_q_scratch_bytes(m);
    FZ_CHECK((st == LIDET_OK) == (need > 0));
    FZ_CHECK(lidet_pointnet_q_check(NULL, 0, 0) == LIDET_ERR_ARG);
    st_init = lidet_pointnet_q_init(&pn, m, scratch, scratch_bytes, NULL);
    if (st != LIDET_OK)
    {
        FZ_CHECK(st < 0 && st_init < 0);
        return 0;
    }
    FZ_CHECK(need <= SCRATCH_BYTES);
    if (st_init != LIDET_OK)
    {
        FZ_CHECK(((uintptr_t)scratch & 3u) != 0 || scratch_bytes < need);
        return 0;
    }
    if (macs(m) > MAX_MACS)
    {
        return 0;
    }
    n_pts = (flags & 1u) ? (uint32_t)(flags >> 1) : m->n_points; /* sometimes a wrong count */
    for (i = 0; i < 3u; ++i)
    {
        voxel[i] = (int16_t)fz_u16(&in);
    }
    {
        /* the points: raw int16, the rest of what the proposal needs read first */
        const size_t want = sizeof g_pts, have = in.n < want ? in.n : want;
        memset(g_pts, 0, sizeof g_pts);
        memcpy(g_pts, in.p, have);
        in.p += have;
        in.n -= have;
    }
    n_out = lidet_pointnet_q_n_outputs(m);
    FZ_CHECK(n_out > 0 && n_out <= sizeof g_out / sizeof g_out[0]);
    st = lidet_pointnet_q_forward(&pn, g_pts, n_pts, voxel, cls_b, g_out, n_out);
    FZ_CHECK(st == ((n_pts == m->n_points && (m->kind != LIDET_PN_BOX || cls_b < m->n_classes)) ? LIDET_OK
                                                                                                  : LIDET_ERR_ARG));
    FZ_CHECK(lidet_pointnet_q_forward(&pn, g_pts, m->n_points, voxel, 0, g_out, n_out - 1u) == LIDET_ERR_ARG);
    (void)lidet_pointnet_q_energy(g_out, n_out < 8u ? n_out : 8u, m->energy_t_q16);
    read_proposal(&in, n_pts);
    run_heads(&pn, m, n_pts, cls_b % 4u);
    return 0;
}
