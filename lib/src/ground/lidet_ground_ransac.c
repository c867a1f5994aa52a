/* SPDX-License-Identifier: MIT */
/* Ground stage: one RANSAC plane per azimuth sector, least-squares refinement, fallback
 * (algorithm in lidet_ground.h). Mirrored by codegen/lidet_ref/ground.py (fit_sectors,
 * fit_plane_lsq). */
#include <string.h>

#include "internal/lidet_assert.h"
#include "internal/lidet_ground_float_internal.h"
#include "internal/lidet_math.h"
#include "internal/lidet_pixel.h"
#include "internal/lidet_rng.h"

/* cross products shorter than this (m^2) are degenerate triples (collinear or repeated points) */
#define MIN_CROSS2 1.0e-8f
#define JACOBI_SWEEPS 12

/* Eigen-decomposition of a symmetric 3x3 matrix by cyclic Jacobi rotations. a is destroyed (its
 * diagonal ends up holding the eigenvalues), v receives the eigenvectors as columns. Jacobi is
 * slower than the closed form but has no acos/cos branch cuts and stays accurate for the very
 * unequal eigenvalues of a ground patch (metres^2 along the ground, centimetres^2 across). */
static void jacobi3(float a[3][3], float v[3][3])
{
    int sweep, p, q, i;
    memset(v, 0, 9 * sizeof(float));
    v[0][0] = v[1][1] = v[2][2] = 1.0f;
    for (sweep = 0; sweep < JACOBI_SWEEPS; ++sweep)
    {
        const float off = fabsf(a[0][1]) + fabsf(a[0][2]) + fabsf(a[1][2]);
        const float diag = fabsf(a[0][0]) + fabsf(a[1][1]) + fabsf(a[2][2]);
        if (!(off > 1.0e-9f * diag) || off == 0.0f)
        {
            break;
        }
        for (p = 0; p < 2; ++p)
        {
            for (q = p + 1; q < 3; ++q)
            {
                float theta, t, c, s, tau, apq = a[p][q];
                if (fabsf(apq) <= 1.0e-12f * (fabsf(a[p][p]) + fabsf(a[q][q])) || apq == 0.0f)
                {
                    continue;
                }
                /* rotation angle zeroing a[p][q]: t = tan(phi), the smaller root of t^2 + 2 theta t - 1 */
                theta = (a[q][q] - a[p][p]) / (2.0f * apq);
                t = 1.0f / (fabsf(theta) + sqrtf(theta * theta + 1.0f));
                if (theta < 0.0f)
                {
                    t = -t;
                }
                c = 1.0f / sqrtf(t * t + 1.0f);
                s = t * c;
                tau = s / (1.0f + c);
                a[p][p] -= t * apq;
                a[q][q] += t * apq;
                a[p][q] = a[q][p] = 0.0f;
                for (i = 0; i < 3; ++i)
                {
                    if (i != p && i != q)
                    {
                        const float aip = a[i][p], aiq = a[i][q];
                        a[i][p] = a[p][i] = aip - s * (aiq + tau * aip);
                        a[i][q] = a[q][i] = aiq + s * (aip - tau * aiq);
                    }
                }
                for (i = 0; i < 3; ++i)
                {
                    const float vip = v[i][p], viq = v[i][q];
                    v[i][p] = vip - s * (viq + tau * vip);
                    v[i][q] = viq + s * (vip - tau * viq);
                }
            }
        }
    }
}

/* Plane from centroid and covariance (mean of shifted coordinates + shift). Returns 0 when the
 * points are (nearly) collinear. eig (optional) gets the eigenvalues ascending. */
static int plane_from_cov(float cov[3][3], const float centroid[3], lidet_plane_t *pl, float *eig)
{
    float v[3][3], nx, ny, nz, len;
    int i, lo = 0, hi = 0, mid;
    jacobi3(cov, v);
    for (i = 1; i < 3; ++i)
    {
        if (cov[i][i] < cov[lo][lo])
            lo = i;
        if (cov[i][i] > cov[hi][hi])
            hi = i;
    }
    if (lo == hi)
    {
        hi = lo == 0 ? 1 : 0;
    }
    mid = 3 - lo - hi;
    if (eig != 0)
    {
        eig[0] = cov[lo][lo];
        eig[1] = cov[mid][mid];
        eig[2] = cov[hi][hi];
    }
    if (!(cov[mid][mid] > 1.0e-7f * cov[hi][hi]) || !(cov[hi][hi] > 0.0f))
    {
        return 0; /* a line (or a point): no unique plane */
    }
    nx = v[0][lo];
    ny = v[1][lo];
    nz = v[2][lo];
    len = sqrtf(nx * nx + ny * ny + nz * nz);
    if (!(len > 0.0f))
    {
        return 0;
    }
    len = nz < 0.0f ? -1.0f / len : 1.0f / len;
    pl->nx = nx * len;
    pl->ny = ny * len;
    pl->nz = nz * len;
    pl->d_m = -(pl->nx * centroid[0] + pl->ny * centroid[1] + pl->nz * centroid[2]);
    return 1;
}

/* LANES independent partial sums per moment, combined at the end: the compiler turns the j loop into
 * vector instructions (a plain float reduction would stay scalar without -ffast-math), and the order
 * of additions is fixed, so results are deterministic. */
#define LANES 4
#define GATHER_BLOCK 64 /* indexed samples are gathered in blocks of this many (a multiple of LANES) */

typedef struct
{
    float acc[10][LANES];
    lidet_plane_t p;
    float thr;
    float shift[3];
} moments_t;

/* Adds m contiguous points: lane j takes the points i = j mod LANES of the first LANES * floor(m / LANES),
 * the rest goes to lane 0. Called on consecutive blocks whose sizes are multiples of LANES (but the
 * last), the additions happen in the same order as one call on all the points. Branch-free: each
 * point enters with weight w = 1 (inlier of the plane) or 0. */
static inline void moments_add(moments_t *mo, const float *xs, const float *ys, const float *zs, uint32_t m)
{
    const lidet_plane_t p = mo->p;
    const float thr = mo->thr, s0 = mo->shift[0], s1 = mo->shift[1], s2 = mo->shift[2];
    float acc[10][LANES]; /* a local copy: the compiler keeps it in vector registers */
    uint32_t i;
    int j;
    memcpy(acc, mo->acc, sizeof acc);
    for (i = 0; i + LANES <= m; i += LANES)
    {
        for (j = 0; j < LANES; ++j)
        {
            const float h = p.nx * xs[i + j] + p.ny * ys[i + j] + p.nz * zs[i + j] + p.d_m;
            const float w = fabsf(h) <= thr ? 1.0f : 0.0f;
            const float x = w * (xs[i + j] - s0);
            const float y = w * (ys[i + j] - s1);
            const float z = w * (zs[i + j] - s2);
            acc[0][j] += w;
            acc[1][j] += x;
            acc[2][j] += y;
            acc[3][j] += z;
            acc[4][j] += x * x;
            acc[5][j] += x * y;
            acc[6][j] += x * z;
            acc[7][j] += y * y;
            acc[8][j] += y * z;
            acc[9][j] += z * z;
        }
    }
    for (; i < m; ++i) /* the tail goes to lane 0 */
    {
        const float h = p.nx * xs[i] + p.ny * ys[i] + p.nz * zs[i] + p.d_m;
        const float w = fabsf(h) <= thr ? 1.0f : 0.0f;
        const float x = w * (xs[i] - s0);
        const float y = w * (ys[i] - s1);
        const float z = w * (zs[i] - s2);
        acc[0][0] += w;
        acc[1][0] += x;
        acc[2][0] += y;
        acc[3][0] += z;
        acc[4][0] += x * x;
        acc[5][0] += x * y;
        acc[6][0] += x * z;
        acc[7][0] += y * y;
        acc[8][0] += y * z;
        acc[9][0] += z * z;
    }
    memcpy(mo->acc, acc, sizeof acc);
}

/* Starts the moments of the points (optionally only those within `thr` of `ref`) around `shift`
 * (keeps float sums small: coordinates of a sector are tens of metres, heights centimetres). */
static void moments_start(moments_t *mo, const lidet_plane_t *ref, float thr, const float shift[3])
{
    memset(mo->acc, 0, sizeof mo->acc);
    if (ref != 0)
    {
        mo->p = *ref;
        mo->thr = thr;
    }
    else
    {
        mo->p.nx = mo->p.ny = mo->p.nz = mo->p.d_m = 0.0f; /* h = 0 <= thr: every point counts */
        mo->thr = 1.0f;
    }
    mo->shift[0] = shift[0];
    mo->shift[1] = shift[1];
    mo->shift[2] = shift[2];
}

/* Mean and covariance from the moments. Returns the point count used. */
static uint32_t moments_finish(const moments_t *mo, float cov[3][3], float centroid[3])
{
    float sum[10], inv, mx, my, mz;
    uint32_t m;
    int k;
    for (k = 0; k < 10; ++k)
    {
        sum[k] = (mo->acc[k][0] + mo->acc[k][1]) + (mo->acc[k][2] + mo->acc[k][3]);
    }
    m = (uint32_t)(sum[0] + 0.5f); /* exact: counts stay far below 2^24 */
    if (m == 0u)
    {
        return 0u;
    }
    inv = 1.0f / sum[0];
    mx = sum[1] * inv;
    my = sum[2] * inv;
    mz = sum[3] * inv;
    cov[0][0] = sum[4] * inv - mx * mx;
    cov[0][1] = cov[1][0] = sum[5] * inv - mx * my;
    cov[0][2] = cov[2][0] = sum[6] * inv - mx * mz;
    cov[1][1] = sum[7] * inv - my * my;
    cov[1][2] = cov[2][1] = sum[8] * inv - my * mz;
    cov[2][2] = sum[9] * inv - mz * mz;
    centroid[0] = mx + mo->shift[0];
    centroid[1] = my + mo->shift[1];
    centroid[2] = mz + mo->shift[2];
    return m;
}

/* The moments of n contiguous points. */
static uint32_t accumulate(const float *xs, const float *ys, const float *zs, uint32_t n,
                           const lidet_plane_t *ref, float thr, const float shift[3], float cov[3][3],
                           float centroid[3])
{
    moments_t mo;
    moments_start(&mo, ref, thr, shift);
    moments_add(&mo, xs, ys, zs, n);
    return moments_finish(&mo, cov, centroid);
}

/* The same for the n image pixels idx[0..n) (a cell's samples), gathered in blocks: the same sums, bit
 * for bit, as on a contiguous copy of the points. */
static uint32_t accumulate_idx(const lidet_range_image_t *img, int compact, const lidet_ground_sample_t *idx,
                               uint32_t n, const lidet_plane_t *ref, float thr, const float shift[3],
                               float cov[3][3], float centroid[3])
{
    float bx[GATHER_BLOCK], by[GATHER_BLOCK], bz[GATHER_BLOCK];
    moments_t mo;
    uint32_t base, i;
    moments_start(&mo, ref, thr, shift);
    for (base = 0; base < n; base += GATHER_BLOCK)
    {
        const uint32_t m = n - base < GATHER_BLOCK ? n - base : GATHER_BLOCK;
        for (i = 0; i < m; ++i)
        {
            lidet__img_xyz(img, idx[base + i], compact, &bx[i], &by[i], &bz[i]);
        }
        moments_add(&mo, bx, by, bz, m);
    }
    return moments_finish(&mo, cov, centroid);
}

lidet_status_t lidet_ground_fit_plane(const float *x_m, const float *y_m, const float *z_m, uint32_t n,
                                      lidet_plane_t *plane, float *eigvals)
{
    float cov[3][3], centroid[3], shift[3];
    if (x_m == 0 || y_m == 0 || z_m == 0 || plane == 0 || n < 3u)
    {
        return LIDET_ERR_ARG;
    }
    shift[0] = x_m[0];
    shift[1] = y_m[0];
    shift[2] = z_m[0];
    if (accumulate(x_m, y_m, z_m, n, 0, 0.0f, shift, cov, centroid) < 3u ||
        !plane_from_cov(cov, centroid, plane, eigvals))
    {
        return LIDET_ERR_ARG;
    }
    return LIDET_OK;
}

/* Counts the n contiguous points within thr of the plane (the loop vectorises). */
static uint32_t score(const float *xs, const float *ys, const float *zs, uint32_t n, const lidet_plane_t *p,
                      float thr)
{
    const float nx = p->nx, ny = p->ny, nz = p->nz, d = p->d_m;
    uint32_t i, cnt = 0;
    for (i = 0; i < n; ++i)
    {
        cnt += (uint32_t)(fabsf(nx * xs[i] + ny * ys[i] + nz * zs[i] + d) <= thr);
    }
    return cnt;
}

/* score() on the image pixels idx[0, stride, 2 stride, ...) (a cell too large for the scoring copy) */
static uint32_t score_idx(const lidet_range_image_t *img, int compact, const lidet_ground_sample_t *idx,
                          uint32_t n, uint32_t stride, const lidet_plane_t *p, float thr)
{
    const float nx = p->nx, ny = p->ny, nz = p->nz, d = p->d_m;
    uint32_t i, cnt = 0;
    for (i = 0; i < n; i += stride)
    {
        float x, y, z;
        lidet__img_xyz(img, idx[i], compact, &x, &y, &z);
        cnt += (uint32_t)(fabsf(nx * x + ny * y + nz * z + d) <= thr);
    }
    return cnt;
}

/* The RANSAC draws of one sector: ransac_iters triples of its n samples; a plane within max_tilt (cos2: cos^2 of
 * it) is scored on the scoring subset (copied: its contiguous copy sc->ev_*, n_eval points; else the samples
 * idx[0, stride, ...)), and the highest count wins (ties: the first), with the adaptive stop. Returns 1 with
 * *best and *best_cnt set when any hypothesis was scored. */
static int best_hypothesis(lidet_ground_state_t *g, const lidet_ground_scratch_t *sc,
                           const lidet_range_image_t *img, int compact, const lidet_ground_sample_t *idx,
                           uint32_t n, uint32_t stride, uint32_t n_eval, int copied, float cos2,
                           lidet_plane_t *best, uint32_t *best_cnt)
{
    const lidet_ground_cfg_t *cfg = &g->cfg;
    uint32_t it;
    int have = 0;
    for (it = 0; it < cfg->ransac_iters; ++it)
    {
        const uint32_t i0 = lidet__rng_below(&g->rng, n);
        const uint32_t i1 = lidet__rng_below(&g->rng, n);
        const uint32_t i2 = lidet__rng_below(&g->rng, n);
        float x0, y0, z0, ux, uy, uz, vx, vy, vz, cx, cy, cz, len2, inv;
        lidet_plane_t p;
        uint32_t cnt;
        if (i0 == i1 || i0 == i2 || i1 == i2)
        {
            continue;
        }
        {
            float x1, y1, z1, x2, y2, z2;
            lidet__img_xyz(img, idx[i0], compact, &x0, &y0, &z0);
            lidet__img_xyz(img, idx[i1], compact, &x1, &y1, &z1);
            lidet__img_xyz(img, idx[i2], compact, &x2, &y2, &z2);
            ux = x1 - x0;
            uy = y1 - y0;
            uz = z1 - z0;
            vx = x2 - x0;
            vy = y2 - y0;
            vz = z2 - z0;
        }
        cx = uy * vz - uz * vy;
        cy = uz * vx - ux * vz;
        cz = ux * vy - uy * vx;
        len2 = cx * cx + cy * cy + cz * cz;
        /* degenerate triple, or tilted beyond max_tilt (cz^2 < cos^2 * |c|^2): skip before scoring */
        if (!(len2 > MIN_CROSS2) || !(cz * cz >= cos2 * len2))
        {
            continue;
        }
        inv = 1.0f / sqrtf(len2);
        if (cz < 0.0f)
        {
            inv = -inv;
        }
        p.nx = cx * inv;
        p.ny = cy * inv;
        p.nz = cz * inv;
        p.d_m = -(p.nx * x0 + p.ny * y0 + p.nz * z0);
        ++g->stats.n_hypotheses;
        cnt = copied ? score(sc->ev_x_m, sc->ev_y_m, sc->ev_z_m, n_eval, &p, cfg->inlier_m)
                     : score_idx(img, compact, idx, n, stride, &p, cfg->inlier_m);
        if (!have || cnt > *best_cnt)
        {
            *best = p;
            *best_cnt = cnt;
            have = 1;
            /* adaptive stop (deterministic: depends on counts only): enough hypotheses were drawn
             * to pick an all-inlier triple with probability `confidence`, given the inlier share w
             * of the best plane: stop once (1 - w^3)^(it + 1) <= 1 - confidence */
            if (cfg->confidence > 0.0f)
            {
                const float w = (float)cnt / (float)n_eval;
                float miss = 1.0f, q = 1.0f - w * w * w;
                uint32_t k;
                for (k = 0; k <= it; ++k)
                {
                    miss *= q;
                }
                if (miss <= 1.0f - cfg->confidence)
                {
                    break;
                }
            }
        }
    }
    return have;
}

/* Least-squares refinement of *best on the inliers of the current plane (all n samples of the sector), up to
 * refine_iters times, keeping the last good plane. It works on a contiguous copy of the samples: the scoring copy
 * when it holds them all (stride 1), else, when they fit, the row scratch of the label pass (free until that
 * pass: x_row, y_row, z_rows[0]) filled once here, so the iterations neither gather nor decode again; the sums
 * are those of the gathered blocks, bit for bit */
static void refine_plane(const lidet_ground_cfg_t *cfg, lidet_ground_scratch_t *sc,
                         const lidet_range_image_t *img, int compact, const lidet_ground_sample_t *idx,
                         uint32_t n, int copied, uint32_t stride, float cos2, lidet_plane_t *best)
{
    const float *rx = 0, *ry = 0, *rz = 0;
    uint32_t r, i;
    if (copied && stride == 1u)
    {
        rx = sc->ev_x_m;
        ry = sc->ev_y_m;
        rz = sc->ev_z_m;
    }
    else if (n <= (uint32_t)LIDET_MAX_COLS && cfg->refine_iters > 1u)
    {
        for (i = 0; i < n; ++i)
        {
            lidet__img_xyz(img, idx[i], compact, &sc->x_row[i], &sc->y_row[i], &sc->z_rows[0][i]);
        }
        rx = sc->x_row;
        ry = sc->y_row;
        rz = sc->z_rows[0];
    }
    for (r = 0; r < cfg->refine_iters; ++r)
    {
        float cov[3][3], centroid[3], shift[3];
        lidet_plane_t p;
        /* shift: the point of the plane under the sector's first sample */
        float z_first;
        lidet__img_xyz(img, idx[0], compact, &shift[0], &shift[1], &z_first);
        shift[2] =
            best->nz > 0.0f ? -(best->nx * shift[0] + best->ny * shift[1] + best->d_m) / best->nz : z_first;
        if ((rx != 0
                 ? accumulate(rx, ry, rz, n, best, cfg->inlier_m, shift, cov, centroid)
                 : accumulate_idx(img, compact, idx, n, best, cfg->inlier_m, shift, cov, centroid)) < 3u ||
            !plane_from_cov(cov, centroid, &p, 0) || !(p.nz * p.nz >= cos2))
        {
            break; /* keep the last good plane */
        }
        *best = p;
    }
}

/* RANSAC on one sector (mirrors lidet_ref/ground.py: ransac_sector): the draws (best_hypothesis), the
 * least-squares refinement (refine_plane), the checks. Returns 1 with *out set when a plane passes every check. */
static int fit_sector(lidet_ground_state_t *g, lidet_ground_scratch_t *sc, const lidet_range_image_t *img,
                      const lidet_ground_sample_t *idx, uint32_t n, const lidet_plane_t *near, float at_x,
                      float at_y, lidet_plane_t *out)
{
    const int compact = lidet__img_compact(img);
    const lidet_ground_cfg_t *cfg = &g->cfg;
    const float cos_tilt = cosf(cfg->max_tilt_rad);
    const float cos2 = cos_tilt * cos_tilt;
    const uint32_t stride = (n + cfg->eval_samples - 1u) / cfg->eval_samples;
    const uint32_t n_eval = (n + stride - 1u) / stride; /* size of the strided subset */
    lidet_plane_t best;
    /* the scoring subset: the strided one of the cell's samples (pixel indices into the image), copied
     * once into the scratch when it fits, so that every hypothesis scores a contiguous block (same
     * points, same counts); a larger subset is scored through the indices */
    const int copied = n_eval <= LIDET_GROUND_EVAL_MAX;
    uint32_t best_cnt = 0, i;
    memset(&best, 0, sizeof best);
    if (copied)
    {
        for (i = 0; i < n_eval; ++i)
        {
            lidet__img_xyz(img, idx[i * stride], compact, &sc->ev_x_m[i], &sc->ev_y_m[i], &sc->ev_z_m[i]);
        }
    }
    if (!best_hypothesis(g, sc, img, compact, idx, n, stride, n_eval, copied, cos2, &best, &best_cnt) ||
        best_cnt < cfg->min_inliers)
    {
        return 0;
    }
    refine_plane(cfg, sc, img, compact, idx, n, copied, stride, cos2, &best);
    if (!(best.nz >= cos_tilt))
    {
        return 0;
    }
    if (near != 0)
    {
        /* a far cell with far_max_step_m: its plane meets its sector's near plane at the split (at_x, at_y)
         * within the step, whatever the sensor's height above it (a road that climbs or falls) */
        const float hn = -(near->nx * at_x + near->ny * at_y + near->d_m) / near->nz;
        const float hf = -(best.nx * at_x + best.ny * at_y + best.d_m) / best.nz;
        if (!(fabsf(hf - hn) <= cfg->far_max_step_m))
        {
            return 0;
        }
    }
    else if (!(fabsf(best.d_m - cfg->mount_height_m) <= cfg->max_height_dev_m))
    {
        return 0;
    }
    *out = best;
    return 1;
}

/* the float stage's side of lidet__ground_cells */
typedef struct
{
    lidet_ground_state_t *g;
    lidet_ground_scratch_t *sc;
    const lidet_range_image_t *img;
} fit_ctx_t;

static int fit_cell(void *ctx, uint32_t k)
{
    fit_ctx_t *f = (fit_ctx_t *)ctx;
    const lidet_ground_cfg_t *cfg = &f->g->cfg;
    const uint32_t a = f->sc->cell_first[k], n = f->sc->cell_n[k], ns = cfg->n_sectors;
    LIDET_ASSERT(a + n <= LIDET_GROUND_MAX_SAMPLES);
    if (cfg->seed_per_cell)
    {
        f->g->rng = lidet__rng_cell(cfg->seed, k);
    }
    if (k >= ns && cfg->far_max_step_m > 0.0f)
    {
        /* a far cell meets its near plane at ring_split_m, a third cell its far plane at far2_split_m: on the
         * split circle at the middle azimuth of sector s (columns s cols / ns ...: azimuth pi (1 - 2 (s + 1/2) /
         * ns)) */
        const float az = LIDET_PI_F * (1.0f - (2.0f * (float)(k % ns) + 1.0f) / (float)ns);
        const float split = k < 2u * ns ? cfg->ring_split_m : cfg->far2_split_m;
        return fit_sector(f->g, f->sc, f->img, f->sc->sample_pix + a, n, &f->g->planes[k - ns],
                          split * cosf(az), split * sinf(az), &f->g->planes[k]);
    }
    return fit_sector(f->g, f->sc, f->img, f->sc->sample_pix + a, n, 0, 0.0f, 0.0f, &f->g->planes[k]);
}

/* a sample at or beyond far2_split_m (the third cells) */
static int beyond_far2(void *ctx, lidet_ground_sample_t p)
{
    const fit_ctx_t *f = (const fit_ctx_t *)ctx;
    const float s2 = f->g->cfg.far2_split_m;
    float x, y, z;
    lidet__img_xyz(f->img, p, lidet__img_compact(f->img), &x, &y, &z);
    return x * x + y * y >= s2 * s2;
}

static void copy_plane(void *ctx, uint32_t dst, int32_t src)
{
    lidet_ground_state_t *g = ((fit_ctx_t *)ctx)->g;
    if (src >= 0)
    {
        g->planes[dst] = g->planes[src];
    }
    else
    {
        g->planes[dst].nx = 0.0f;
        g->planes[dst].ny = 0.0f;
        g->planes[dst].nz = 1.0f;
        g->planes[dst].d_m = g->cfg.mount_height_m;
    }
}

void lidet__ground_fit_sectors(lidet_ground_state_t *g, lidet_ground_scratch_t *sc,
                               const lidet_range_image_t *img)
{
    const uint32_t ns = g->cfg.n_sectors;
    fit_ctx_t f;
    f.g = g;
    f.sc = sc;
    f.img = img;
    lidet__ground_cells(g->source, sc->cell_n, ns, g->cfg.ring_split_m > 0.0f ? 2u * ns : ns,
                        g->cfg.min_samples, g->cfg.fallback_sectors, &g->stats, fit_cell, copy_plane, &f);
    if (lidet__ground_far2_on(&g->cfg))
    {
        lidet__ground_far2_cells(g->source, sc->cell_first, sc->cell_n, sc->sample_pix, ns,
                                 g->cfg.min_samples, &g->stats, beyond_far2, fit_cell, copy_plane, &f);
    }
}
