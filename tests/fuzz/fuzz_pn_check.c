/* SPDX-License-Identifier: MIT */
/* libFuzzer harness: the model-descriptor checks (lidet_pn_check, lidet_pn_scratch_bytes, lidet_pn_init)
 * on malformed descriptors: a committed model (weights/) copied and mutated field by field by the input
 * (format version, kind, precision, stage and layer counts, layer widths, ReLU flags, NULL arrays, the
 * energy temperature, NULL model), with short and misaligned scratch buffers. A descriptor the checks
 * accept is then run through lidet_pn_forward: every array points into one buffer large enough for any
 * layer the checks allow (LIDET_PN_MAX_WIDTH^2), so an accepted descriptor must be safe to run. */
#include "fuzz_common.h"
#include "lidet_weights.h"

#define W_FLOATS ((uint32_t)LIDET_PN_MAX_WIDTH * LIDET_PN_MAX_WIDTH)
#define SCRATCH_BYTES (LIDET_PN_SCRATCH_BYTES(LIDET_PN_MAX_WIDTH, LIDET_PN_MAX_WIDTH) + 64u)
/* forward passes above this many multiply-adds are skipped (time, not safety) */
#define MAX_MACS 500000u

static float g_w[W_FLOATS];
static uint32_t g_scratch[SCRATCH_BYTES / 4u + 1u];
static lidet_pn_layer_t g_layers[2][3][LIDET_PN_MAX_LAYERS];
static float g_pts[LIDET_PROPOSAL_POINTS * 3];
static float g_out[4096];

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static lidet_pn_layer_t *part_layers(uint32_t s, uint32_t part)
{
    return g_layers[s % 2u][part % 3u];
}

/* a mutable copy of model m whose arrays all point into g_w */
static void copy_model(const lidet_pn_model_t *m, lidet_pn_model_t *c)
{
    uint32_t s, i;
    *c = *m;
    memset(g_layers, 0, sizeof g_layers);
    for (s = 0; s < 2u; ++s)
    {
        const lidet_pn_layer_t *src[3];
        const uint8_t cnt[3] = {m->stage[s].n_point, m->stage[s].n_pvle, m->stage[s].n_head};
        src[0] = m->stage[s].point;
        src[1] = m->stage[s].pvle;
        src[2] = m->stage[s].head;
        for (i = 0; i < 3u; ++i)
        {
            uint32_t l;
            for (l = 0; l < cnt[i] && l < LIDET_PN_MAX_LAYERS && src[i] != NULL; ++l)
            {
                g_layers[s][i][l] = src[i][l];
            }
            for (l = 0; l < LIDET_PN_MAX_LAYERS; ++l)
            {
                g_layers[s][i][l].w_t = g_w;
                g_layers[s][i][l].b = g_w;
            }
        }
        c->stage[s].point = src[0] ? g_layers[s][0] : NULL;
        c->stage[s].pvle = src[1] ? g_layers[s][1] : NULL;
        c->stage[s].head = src[2] ? g_layers[s][2] : NULL;
    }
    if (c->mean_size_m != NULL)
    {
        c->mean_size_m = g_w;
    }
}

static void mutate(fz_in_t *in, lidet_pn_model_t *c)
{
    const uint8_t sel = fz_u8(in);
    const uint32_t v = fz_u32(in);
    lidet_pn_stage_t *st = &c->stage[(v >> 16) & 1u];
    lidet_pn_layer_t *l = &part_layers((v >> 16) & 1u, v >> 17)[(v >> 20) % LIDET_PN_MAX_LAYERS];
    switch (sel % 22u)
    {
    case 0: c->format_version = v; break;
    case 1: c->kind = (uint8_t)v; break;
    case 2: c->precision = (uint8_t)v; break;
    case 3: c->n_stages = (uint8_t)v; break;
    case 4: c->n_classes = (uint8_t)v; break;
    case 5: c->n_points = (uint16_t)v; break;
    case 6: c->n_heading_bins = (uint8_t)v; break;
    case 7: c->n_size_clusters = (uint8_t)v; break;
    case 8: c->mean_size_m = (v & 1u) ? g_w : NULL; break;
    case 9: memcpy(&c->energy_t, &v, sizeof v); break;
    case 10: st->n_point = (uint8_t)v; break;
    case 11: st->n_pvle = (uint8_t)v; break;
    case 12: st->n_head = (uint8_t)v; break;
    case 13: st->use_onehot = (uint8_t)v; break;
    case 14: l->n_in = (uint16_t)v; break;
    case 15: l->n_out = (uint16_t)(v & 0xFFFFu); break;
    case 16: l->relu = (uint8_t)v; break;
    case 17: l->w_t = (v & 1u) ? g_w : NULL; break;
    case 18: l->b = (v & 1u) ? g_w : NULL; break;
    case 19: st->point = (v & 1u) ? part_layers((v >> 16) & 1u, 0) : NULL; break;
    case 20: st->pvle = (v & 1u) ? part_layers((v >> 16) & 1u, 1) : NULL; break;
    default: st->head = (v & 1u) ? part_layers((v >> 16) & 1u, 2) : NULL; break;
    }
}

FZ_DEFINE_MACS(macs, lidet_pn_model_t, lidet_pn_stage_t)

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static int filled = 0;
    fz_in_t in = {data, size};
    lidet_pn_model_t c;
    lidet_pn_t pn;
    const uint8_t which = fz_u8(&in), n_mut = fz_u8(&in) % 17u, scratch_mode = fz_u8(&in);
    uint32_t i, need = 0, req = 0, n_out, bytes, kind;
    lidet_status_t st, st_init;
    const float voxel[3] = {0.1f, -0.2f, 3.0f}, onehot[LIDET_N_CLASSES] = {1.0f, 0.0f, 0.0f};
    uint8_t *scratch = (uint8_t *)g_scratch;
    if (!filled)
    {
        for (i = 0; i < W_FLOATS; ++i)
        {
            g_w[i] = (float)((int)(i % 7u) - 3) * 0.01f;
        }
        filled = 1;
    }
    copy_model(lidet_weights_models[which % LIDET_WEIGHTS_N_MODELS].model, &c);
    FZ_CHECK(lidet_pn_check(&c, 0, 0) == LIDET_OK); /* the copy itself is valid */
    for (i = 0; i < n_mut; ++i)
    {
        mutate(&in, &c);
    }
    FZ_CHECK(lidet_pn_check(NULL, 0, 0) == LIDET_ERR_ARG && lidet_pn_scratch_bytes(NULL) == 0);
    FZ_CHECK(lidet_pn_init(&pn, NULL, g_scratch, sizeof g_scratch, NULL) == LIDET_ERR_ARG);
    kind = fz_u8(&in) % 4u;
    (void)lidet_pn_check(&c, kind, fz_u8(&in));
    st = lidet_pn_check(&c, 0, 0);
    FZ_CHECK(st == LIDET_OK || st == LIDET_ERR_MODEL);
    need = lidet_pn_scratch_bytes(&c);
    FZ_CHECK((need == 0) == (st != LIDET_OK));
    FZ_CHECK(need <= SCRATCH_BYTES);
    /* scratch: enough, short by a few bytes, NULL, or misaligned */
    bytes = need;
    switch (scratch_mode % 4u)
    {
    case 0: bytes = SCRATCH_BYTES; break;
    case 1: bytes = need > 0 ? need - 1u - (scratch_mode >> 2) % need : 0u; break;
    case 2: scratch = NULL; break;
    default: scratch += 1 + (scratch_mode >> 2) % 3u; bytes = need + 4u; break;
    }
    st_init = lidet_pn_init(&pn, &c, scratch, bytes, &req);
    if (st != LIDET_OK)
    {
        FZ_CHECK(st_init == st);
        return 0;
    }
    FZ_CHECK(req == need);
    if (scratch == NULL || bytes < need)
    {
        FZ_CHECK(st_init == LIDET_ERR_BUFFER);
        return 0;
    }
    if (((uintptr_t)scratch & 3u) != 0)
    {
        FZ_CHECK(st_init == LIDET_ERR_ARG);
        return 0;
    }
    FZ_CHECK(st_init == LIDET_OK);
    n_out = lidet_pn_n_outputs(&c);
    FZ_CHECK(n_out >= 1 && n_out <= sizeof g_out / sizeof g_out[0]);
    if (macs(&c) > MAX_MACS)
    {
        return 0;
    }
    for (i = 0; i < 3u * LIDET_PROPOSAL_POINTS; ++i)
    {
        g_pts[i] = (float)(i % 11u) * 0.1f - 0.5f;
    }
    FZ_CHECK(lidet_pn_forward(&pn, g_pts, c.n_points, voxel, onehot, g_out, n_out) == LIDET_OK);
    return 0;
}
