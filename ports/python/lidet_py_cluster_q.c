/* SPDX-License-Identifier: MIT */
/* Flat C entry points over the integer clustering and proposals (lidet_cluster_q.h) for the Python bindings
 * (tools/lidet_tools/native/_cluster.py: compact_scan, cluster_q, cluster_f_compact): a scan projected into a
 * compact image with the float ground stage on it (what the integer clustering reads until the integer projection
 * and ground land), the integer clustering on it, and the float clustering on the same image (the agreement tests
 * and tools/bench/bench_cluster.py). Each call allocates its states on the heap and frees them. */
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "lidet/lidet.h"

#if defined(_WIN32)
#define LIDET_PY_API __declspec(dllexport)
#else
#define LIDET_PY_API __attribute__((visibility("default")))
#endif

/* record layout of lidet_py_cluster_q_run's out_recs (int32 per cluster) */
#define CQ_REC_INTS 14u

static uint64_t now_ns(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (uint64_t)t.tv_sec * 1000000000u + (uint64_t)t.tv_nsec;
}

/* sizes the Python side checks before it passes configurations as flat arrays: lidet_cluster_q_cfg_t,
 * lidet_proposal_q_cfg_t (all 32-bit fields), ints per record, the cluster capacity */
LIDET_PY_API void lidet_py_cluster_q_sizes(uint32_t out[4])
{
    out[0] = (uint32_t)sizeof(lidet_cluster_q_cfg_t);
    out[1] = (uint32_t)sizeof(lidet_proposal_q_cfg_t);
    out[2] = CQ_REC_INTS;
    out[3] = LIDET_MAX_CLUSTERS;
}

LIDET_PY_API void lidet_py_cluster_q_default(uint32_t rows, uint32_t mount_height_mm, lidet_cluster_q_cfg_t *out,
                                             lidet_proposal_q_cfg_t *out_prop)
{
    lidet_cluster_q_cfg_default(out, rows, mount_height_mm);
    lidet_proposal_q_cfg_default(out_prop);
}

/* Project a scan into a compact image (the float projection's compact path, as a detector workspace does) and
 * run the float ground stage on it. elev_rad: rows elevations in ring order; out_x/y/z/rng: rows * cols;
 * out_elev_bam / out_elev_rad: rows (row order); out_point_pixel: min(n, LIDET_MAX_POINTS); out_mask:
 * rows * cols; out_planes: n_sectors * 4 floats (the near planes the clustering reads). */
LIDET_PY_API int lidet_py_cq_prepare(uint32_t rows, uint32_t cols, const float *elev_rad, float mount_height_m,
                                     const lidet_proj_cfg_t *pcfg, const lidet_ground_cfg_t *gcfg, const float *pts,
                                     uint32_t n, uint32_t stride, int16_t *out_x, int16_t *out_y, int16_t *out_z,
                                     uint16_t *out_rng, int32_t *out_elev_bam, float *out_elev_rad,
                                     int32_t *out_point_pixel, uint8_t *out_mask, float *out_planes)
{
    lidet_proj_state_t *ps = malloc(sizeof *ps);
    lidet_ground_state_t *gs = malloc(sizeof *gs);
    lidet_ground_scratch_t *scr = malloc(sizeof *scr);
    int32_t *idx = malloc((size_t)rows * cols * sizeof(int32_t) + 4u);
    int32_t *pp = malloc((size_t)LIDET_MAX_POINTS * sizeof(int32_t));
    lidet_proj_cfg_t pc;
    lidet_proj_buffers_t b;
    lidet_range_image_t img;
    uint32_t i;
    int rc = LIDET_ERR_ARG;
    if (ps == NULL || gs == NULL || scr == NULL || idx == NULL || pp == NULL || pcfg == NULL || gcfg == NULL)
    {
        goto done;
    }
    pc = *pcfg;
    memset(&pc.sensor, 0, sizeof pc.sensor);
    pc.sensor.name = "python";
    pc.sensor.n_rows = (uint16_t)rows;
    pc.sensor.n_cols = (uint16_t)cols;
    pc.sensor.beam_elev_rad = elev_rad;
    pc.sensor.mount_height_m = mount_height_m;
    rc = lidet_proj_state_init(ps, &pc);
    if (rc < 0)
    {
        goto done;
    }
    memset(&b, 0, sizeof b);
    b.x_4mm = out_x;
    b.y_4mm = out_y;
    b.z_4mm = out_z;
    b.range_4mm = out_rng;
    b.point_idx = idx;
    b.point_pixel = pp;
    rc = lidet_proj_run_buffers(ps, &b, pts, n, stride, NULL);
    if (rc < 0)
    {
        goto done;
    }
    lidet_proj_image_of(ps, &b, &img);
    for (i = 0; i < rows; ++i)
    {
        out_elev_bam[i] = img.row_elev_bam[i];
        out_elev_rad[i] = img.row_elev_rad[i];
    }
    for (i = 0; i < n && i < LIDET_MAX_POINTS; ++i)
    {
        out_point_pixel[i] = pp[i];
    }
    rc = lidet_ground_state_init(gs, gcfg);
    if (rc < 0)
    {
        goto done;
    }
    rc = lidet_ground_run_buffers(gs, scr, out_mask, &img);
    if (rc < 0)
    {
        goto done;
    }
    memcpy(out_planes, gs->planes, gcfg->n_sectors * sizeof(lidet_plane_t));
done:
    free(ps);
    free(gs);
    free(scr);
    free(idx);
    free(pp);
    return rc;
}

static void compact_view(lidet_range_image_t *img, uint32_t rows, uint32_t cols, const int16_t *x, const int16_t *y,
                         const int16_t *z, const uint16_t *rng, const float *elev_rad, const int32_t *elev_bam)
{
    memset(img, 0, sizeof *img);
    img->n_rows = (uint16_t)rows;
    img->n_cols = (uint16_t)cols;
    img->x_4mm = x;
    img->y_4mm = y;
    img->z_4mm = z;
    img->range_4mm = rng;
    img->row_elev_rad = elev_rad;
    img->row_elev_bam = elev_bam;
}

/* One stage on a compact image through its own functions, so both bindings below share the driver: init, the
 * timed runs, the counts, then emit(i) for every kept cluster (its record and proposal into the outputs). */
typedef struct
{
    void *st;          /* the stage's state (heap) */
    const void *cfg;   /* its configuration */
    const void *pcfg;  /* its proposal configuration */
    void *out;         /* the binding's outputs */
    int (*init)(void *st, const void *cfg);
    int (*run)(void *st, uint16_t *labels, int32_t *members, const lidet_range_image_t *img, const uint8_t *ground,
               const void *planes, uint32_t n_sectors);
    uint32_t (*count)(const void *st, lidet_cluster_stats_t *stats);
    int (*emit)(const void *st, const void *pcfg, void *out, uint32_t i);
} stage_t;

static int run_stage(const stage_t *s, const lidet_range_image_t *img, const uint8_t *ground, const void *planes,
                     uint32_t n_sectors, uint32_t repeat, uint16_t *out_labels, int32_t *out_members,
                     uint32_t *out_nrec, lidet_cluster_stats_t *out_stats, uint64_t *out_ns)
{
    uint32_t i, k;
    int rc = s->init(s->st, s->cfg);
    for (i = 0; rc >= 0 && i < (repeat > 0u ? repeat : 1u); ++i)
    {
        const uint64_t t0 = now_ns();
        rc = s->run(s->st, out_labels, out_members, img, ground, planes, n_sectors);
        out_ns[i] = now_ns() - t0;
    }
    if (rc < 0)
    {
        return rc;
    }
    k = s->count(s->st, out_stats);
    *out_nrec = k;
    for (i = 0; i < k; ++i)
    {
        const int rp = s->emit(s->st, s->pcfg, s->out, i);
        if (rp < 0)
        {
            return rp;
        }
    }
    return rc;
}

/* run_stage on a compact image view of the arrays and a freshly allocated state of state_bytes (freed after) */
static int run_entry(stage_t *s, size_t state_bytes, const void *cfg, const void *pcfg, void *out, uint32_t rows,
                     uint32_t cols, const int16_t *x, const int16_t *y, const int16_t *z, const uint16_t *rng,
                     const float *elev_rad, const int32_t *elev_bam, const uint8_t *ground, const void *planes,
                     uint32_t n_sectors, uint32_t repeat, uint16_t *out_labels, int32_t *out_members,
                     uint32_t *out_nrec, lidet_cluster_stats_t *out_stats, uint64_t *out_ns)
{
    lidet_range_image_t img;
    int rc = LIDET_ERR_ARG;
    s->cfg = cfg;
    s->pcfg = pcfg;
    s->out = out;
    s->st = malloc(state_bytes);
    compact_view(&img, rows, cols, x, y, z, rng, elev_rad, elev_bam);
    if (s->st != NULL && cfg != NULL && pcfg != NULL)
    {
        rc = run_stage(s, &img, ground, planes, n_sectors, repeat, out_labels, out_members, out_nrec, out_stats,
                       out_ns);
    }
    free(s->st);
    return rc;
}

/* a stage's init, run and count behind the stage_t signatures */
#define STAGE_ADAPTERS(prefix, state_t, init_fn, run_fn, cfg_t, plane_t)                                           \
    static int prefix##_init(void *st, const void *cfg)                                                      \
    {                                                                                                        \
        return init_fn((state_t *)st, (const cfg_t *)cfg);                                                   \
    }                                                                                                        \
    static int prefix##_run(void *st, uint16_t *labels, int32_t *members, const lidet_range_image_t *img,    \
                            const uint8_t *ground, const void *planes, uint32_t n_sectors)                   \
    {                                                                                                        \
        return run_fn((state_t *)st, labels, members, img, ground, (const plane_t *)planes, n_sectors);      \
    }                                                                                                        \
    static uint32_t prefix##_count(const void *st, lidet_cluster_stats_t *stats)                             \
    {                                                                                                        \
        *stats = ((const state_t *)st)->stats;                                                               \
        return ((const state_t *)st)->n_recs;                                                                \
    }

/* ---- the integer stage ---- */

typedef struct
{
    int32_t *recs; /* LIDET_MAX_CLUSTERS * CQ_REC_INTS */
    int16_t *pxyz;
    int32_t *pmean;
    int16_t *pvox;
    lidet_proposal_q_t pr;
} q_out_t;

STAGE_ADAPTERS(q, lidet_cluster_q_state_t, lidet_cluster_q_state_init, lidet_cluster_q_run_buffers,
               lidet_cluster_q_cfg_t, lidet_plane_q_t)

static int q_emit(const void *st, const void *pcfg, void *out, uint32_t i)
{
    const lidet_cluster_q_rec_t *r = &((const lidet_cluster_q_state_t *)st)->recs[i];
    const lidet_proposal_q_cfg_t *pc = pcfg;
    q_out_t *o = out;
    int32_t *v = o->recs + i * CQ_REC_INTS;
    uint32_t a;
    const int rc = lidet_proposal_q_make(st, i, pc, &o->pr);
    v[0] = (int32_t)r->n_points;
    v[1] = (int32_t)r->first_member;
    v[2] = (int32_t)r->seed_pixel;
    v[3] = (int32_t)r->n_rescued;
    for (a = 0; a < 3; ++a)
    {
        v[4 + a] = r->mean_4mm[a];
        v[7 + a] = r->min_4mm[a];
        v[10 + a] = r->max_4mm[a];
        o->pmean[i * 3u + a] = o->pr.mean_4mm[a];
        o->pvox[i * 3u + a] = o->pr.voxel[a];
    }
    v[13] = r->height_4mm;
    memcpy(o->pxyz + (size_t)i * pc->n_points * 3u, o->pr.xyz, pc->n_points * 3u * sizeof(int16_t));
    return rc;
}

/* The integer clustering of a compact image, `repeat` times (out_ns: each run's nanoseconds), then the
 * proposals of every kept cluster. planes_q: n_sectors * 4 int32 (nx, ny, nz Q30, d_4mm) or NULL. Outputs:
 * labels rows * cols, members rows * cols, recs LIDET_MAX_CLUSTERS * CQ_REC_INTS (n_points, first_member,
 * seed_pixel, n_rescued, mean xyz, min xyz, max xyz, height), proposals LIDET_MAX_CLUSTERS * n_points * 3
 * int16, means * 3 int32, voxels * 3 int16. */
LIDET_PY_API int lidet_py_cluster_q_run(uint32_t rows, uint32_t cols, const int16_t *x, const int16_t *y,
                                        const int16_t *z, const uint16_t *rng, const int32_t *elev_bam,
                                        const uint8_t *ground, const int32_t *planes_q, uint32_t n_sectors,
                                        const lidet_cluster_q_cfg_t *cfg, const lidet_proposal_q_cfg_t *pcfg,
                                        uint32_t repeat, uint16_t *out_labels, int32_t *out_members,
                                        int32_t *out_recs, uint32_t *out_nrec, lidet_cluster_stats_t *out_stats,
                                        int16_t *out_pxyz, int32_t *out_pmean, int16_t *out_pvox, uint64_t *out_ns)
{
    static q_out_t o; /* the proposal scratch (host bindings: one call at a time) */
    stage_t s = {NULL, NULL, NULL, NULL, q_init, q_run, q_count, q_emit};
    o.recs = out_recs;
    o.pxyz = out_pxyz;
    o.pmean = out_pmean;
    o.pvox = out_pvox;
    return run_entry(&s, sizeof(lidet_cluster_q_state_t), cfg, pcfg, &o, rows, cols, x, y, z, rng, NULL, elev_bam,
                     ground, planes_q, n_sectors, repeat, out_labels, out_members, out_nrec, out_stats, out_ns);
}

/* ---- the float stage on the same image ---- */

typedef struct
{
    uint32_t *ru; /* LIDET_MAX_CLUSTERS * 4 */
    float *rf;    /* LIDET_MAX_CLUSTERS * 10 */
    float *pxyz;
    float *pmean;
    int16_t *pvox;
    lidet_proposal_t pr;
} f_out_t;

STAGE_ADAPTERS(f, lidet_cluster_state_t, lidet_cluster_state_init, lidet_cluster_run_buffers, lidet_cluster_cfg_t,
               lidet_plane_t)

static int f_emit(const void *st, const void *pcfg, void *out, uint32_t i)
{
    const lidet_cluster_rec_t *r = &((const lidet_cluster_state_t *)st)->recs[i];
    const lidet_proposal_cfg_t *pc = pcfg;
    f_out_t *o = out;
    uint32_t a;
    const int rc = lidet_proposal_make_of(st, i, pc, &o->pr);
    o->ru[i * 4u] = r->n_points;
    o->ru[i * 4u + 1u] = r->first_member;
    o->ru[i * 4u + 2u] = r->seed_pixel;
    o->ru[i * 4u + 3u] = r->n_rescued;
    for (a = 0; a < 3; ++a)
    {
        o->rf[i * 10u + a] = r->mean_m[a];
        o->rf[i * 10u + 3u + a] = r->min_m[a];
        o->rf[i * 10u + 6u + a] = r->max_m[a];
        o->pmean[i * 3u + a] = o->pr.mean_m[a];
        o->pvox[i * 3u + a] = o->pr.voxel[a];
    }
    o->rf[i * 10u + 9u] = r->height_m;
    memcpy(o->pxyz + (size_t)i * pc->n_points * 3u, o->pr.xyz, pc->n_points * 3u * sizeof(float));
    return rc;
}

/* The float clustering and proposals on the same compact image (arguments as lidet_py_cluster_q_run; planes
 * n_sectors * 4 floats or NULL; out_ru LIDET_MAX_CLUSTERS * 4 uint32 (n_points, first_member, seed_pixel,
 * n_rescued), out_rf * 10 floats (mean, min, max, height), proposals as floats). */
LIDET_PY_API int lidet_py_cluster_f_compact(uint32_t rows, uint32_t cols, const int16_t *x, const int16_t *y,
                                            const int16_t *z, const uint16_t *rng, const float *elev_rad,
                                            const int32_t *elev_bam, const uint8_t *ground, const float *planes,
                                            uint32_t n_sectors, const lidet_cluster_cfg_t *cfg,
                                            const lidet_proposal_cfg_t *pcfg, uint32_t repeat, uint16_t *out_labels,
                                            int32_t *out_members, uint32_t *out_ru, float *out_rf, uint32_t *out_nrec,
                                            lidet_cluster_stats_t *out_stats, float *out_pxyz, float *out_pmean,
                                            int16_t *out_pvox, uint64_t *out_ns)
{
    static f_out_t o; /* the proposal scratch (host bindings: one call at a time) */
    stage_t s = {NULL, NULL, NULL, NULL, f_init, f_run, f_count, f_emit};
    o.ru = out_ru;
    o.rf = out_rf;
    o.pxyz = out_pxyz;
    o.pmean = out_pmean;
    o.pvox = out_pvox;
    return run_entry(&s, sizeof(lidet_cluster_state_t), cfg, pcfg, &o, rows, cols, x, y, z, rng, elev_rad, elev_bam,
                     ground, planes, n_sectors, repeat, out_labels, out_members, out_nrec, out_stats, out_ns);
}
