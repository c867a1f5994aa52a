/* SPDX-License-Identifier: MIT */
/* Spherical projection of the integer path (see lidet_proj_q.h for the rules and docs/FIXED_POINT.md).
 * Mirrored bit for bit by codegen/lidet_ref/proj_q.py. No float here. */
#include <string.h>

#include "internal/lidet_assert.h"
#include "internal/lidet_proj_rows.h"
#include "internal/lidet_qmath.h"
#include "internal/lidet_qpix.h"
#include "lidet/lidet_proj_q.h"

#define MAX_R2_MM2 ((uint64_t)131000u * 131000u) /* the compact image's range limit, mm^2 */
#define COORD_SPAN ((uint32_t)LIDET_Q_COORD_MAX_MM)
#define BOUND_N_LIMIT (1u << 27) /* n < 2^27 (n * (x^2 + y^2) < 2^62) */
#define EDGE_ONE (1u << 29)      /* 1.0 of the column edges (Q29) */

void lidet_proj_q_cfg_default(lidet_proj_q_cfg_t *cfg, const lidet_sensor_q_t *sensor)
{
    if (cfg == 0)
    {
        return;
    }
    memset(cfg, 0, sizeof *cfg);
    if (sensor != 0)
    {
        cfg->sensor = *sensor;
    }
    cfg->min_range_mm = 100;      /* lidet_proj_cfg_default: 0.1 m */
    cfg->max_range_mm = 0;        /* no limit */
    cfg->fov_margin_urad = 87266; /* 5 deg */
}

/* The boundary at the angle a (BAM32, |a| <= 1.1 rad): tan in Q30 (rounded division at init), squared
 * (Q60, < 2^62 as |tan| < 2) and normalised to n < 2^27 with a rounding shift. Returns tan in Q30. */
static int64_t make_bound(lidet_proj_q_bound_t *b, int32_t a_bam)
{
    const int64_t sn = lidet__q_sin((uint32_t)a_bam), cs = lidet__q_cos((uint32_t)a_bam);
    const int64_t t = lidet__q_div_round(sn * ((int64_t)1 << 30), cs); /* cs > 0 */
    const uint64_t v = (uint64_t)(t * t);
    unsigned sh = 0;
    while ((v >> sh) >= BOUND_N_LIMIT)
    {
        ++sh;
    }
    b->n = (uint32_t)(sh > 0 ? lidet__q_rshift_round((int64_t)v, sh) : (int64_t)v);
    b->q = (uint8_t)(60u - sh);
    b->z2_max = ((uint64_t)1 << (3u + sh)) - 1u; /* z^2 above this: z^2 2^q >= 2^63 */
    b->sign = (int8_t)((t > 0) - (t < 0));
    return t;
}

/* sign(z / rxy - T) for a point with z, z2 = z^2, rxy2 = x^2 + y^2 (not both 0 unless z != 0: z / 0 = +-inf) */
static inline int cmp_tan(int32_t z, uint64_t z2, uint64_t rxy2, const lidet_proj_q_bound_t *b)
{
    const int sz = (z > 0) - (z < 0);
    int mag;
    if (sz != b->sign)
    {
        return sz > b->sign ? 1 : -1;
    }
    if (sz == 0)
    {
        return 0;
    }
    /* same sign: |t| against |T| as z^2 2^q against n rxy2; z^2 2^q >= 2^63 exceeds any n rxy2 (< 2^62) */
    if (z2 > b->z2_max)
    {
        mag = 1;
    }
    else
    {
        /* n rxy2 with rxy2 < 2^35 as n (low 32 bits) + (n (high bits)) 2^32 (n (high bits) < 2^30): a 32 x 32 -> 64
         * product and a 32-bit one, not a 64 x 64 one */
        const uint64_t lhs = z2 << b->q;
        const uint64_t rhs =
            (uint64_t)b->n * (uint32_t)rxy2 + ((uint64_t)(b->n * (uint32_t)(rxy2 >> 32)) << 32);
        mag = (lhs > rhs) - (lhs < rhs);
    }
    return sz > 0 ? mag : -mag;
}

/* 1 when boundary a is strictly below boundary b (exact: n * 2^(max q - q) < 2^27 * 2^35) */
static int bound_below(const lidet_proj_q_bound_t *a, const lidet_proj_q_bound_t *b)
{
    const unsigned qm = a->q > b->q ? a->q : b->q;
    const uint64_t ma = (uint64_t)a->n << (qm - a->q), mb = (uint64_t)b->n << (qm - b->q);
    if (a->sign != b->sign)
    {
        return a->sign < b->sign;
    }
    return a->sign > 0 ? ma < mb : (a->sign < 0 ? ma > mb : 0);
}

/* lidet__proj_rows_top_down's order on this file's elevations */
static int beam_above(const void *elev, uint32_t a, uint32_t b)
{
    const int32_t *e = (const int32_t *)elev;
    return e[a] > e[b];
}

static int32_t clamp_elev(int64_t urad)
{
    return urad > LIDET_Q_MAX_ELEV_URAD
               ? LIDET_Q_MAX_ELEV_URAD
               : (urad < -LIDET_Q_MAX_ELEV_URAD ? -LIDET_Q_MAX_ELEV_URAD : (int32_t)urad);
}

/* Column edges: column c starts at u = c / cols of the turn (u = (pi - azimuth) / 2 pi); with 4u = quadrant + f,
 * D = quadrant + sin t / (sin t + cos t), t = f pi/2 (the float projection's init_columns, in BAM32 and Q29). */
static lidet_status_t init_columns(lidet_proj_q_state_t *st, uint32_t cols)
{
    uint32_t c, k;
    for (c = 0; c < cols; ++c)
    {
        const uint32_t quadrant = (4u * c) / cols;
        const int64_t t_bam = lidet__q_div_round((int64_t)((4u * c) % cols) << 30, (int64_t)cols);
        const int64_t sn = lidet__q_sin((uint32_t)t_bam), cs = lidet__q_cos((uint32_t)t_bam);
        st->col_edge_q29[c] = quadrant * EDGE_ONE + (uint32_t)lidet__q_div_round(sn * EDGE_ONE, sn + cs);
    }
    st->col_edge_q29[cols] = 5u * EDGE_ONE; /* above any D (< 4): ends the upward step in the last column */
    /* run() makes one upward step from the table's guess: exact when every column is wider than a bucket
     * (1 / cols in D; a column is at least pi / cols wide), checked here on the integer edges */
    for (c = 1; c < cols; ++c)
    {
        if ((uint64_t)(st->col_edge_q29[c] - st->col_edge_q29[c - 1]) * cols <= (uint64_t)EDGE_ONE)
        {
            return LIDET_ERR_CONFIG;
        }
    }
    c = 0;
    for (k = 0; k <= 4u * cols; ++k) /* bucket k starts at D = k / cols */
    {
        while (c + 1u < cols && (uint64_t)st->col_edge_q29[c + 1u] * cols <= (uint64_t)k * EDGE_ONE)
        {
            ++c;
        }
        st->col_lut[k] = (uint16_t)c;
    }
    return LIDET_OK;
}

lidet_status_t lidet_proj_q_init(lidet_proj_q_state_t *st, const lidet_proj_q_cfg_t *cfg)
{
    const lidet_sensor_q_t *s;
    int32_t elev[LIDET_MAX_ROWS];
    uint8_t ring_of_row[LIDET_MAX_ROWS];
    int64_t t_prev;
    int32_t top, bottom;
    uint32_t rows, r;
    lidet_status_t status;

    if (st == 0 || cfg == 0)
    {
        return LIDET_ERR_ARG;
    }
    st->magic = 0;
    s = &cfg->sensor;
    status = lidet__proj_check_shape(s->n_rows, s->n_cols);
    if (status != LIDET_OK)
    {
        return status;
    }
    if (cfg->min_range_mm < 0 || cfg->min_range_mm > 10000 || cfg->fov_margin_urad < 0 ||
        cfg->fov_margin_urad > 500000 || cfg->max_range_mm < 0 || cfg->max_range_mm > 1000000000 ||
        (cfg->max_range_mm > 0 && cfg->max_range_mm <= cfg->min_range_mm))
    {
        return LIDET_ERR_CONFIG;
    }
    status = lidet_sensor_q_elevations(s, elev);
    if (status != LIDET_OK)
    {
        return status;
    }
    rows = s->n_rows;
    /* rows = beams sorted top to bottom (stable insertion sort; equal elevations are rejected below) */
    lidet__proj_rows_top_down(rows, elev, beam_above, ring_of_row);
    for (r = 0; r < rows; ++r)
    {
        st->row_elev_urad[r] = elev[ring_of_row[r]];
        st->row_elev_bam[r] = lidet__q_urad_to_bam(st->row_elev_urad[r]);
        st->ring_to_row[ring_of_row[r]] = (uint8_t)r;
        if (r > 0 && st->row_elev_urad[r] >= st->row_elev_urad[r - 1])
        {
            return LIDET_ERR_CONFIG; /* two beams at the same elevation */
        }
    }
    /* the field of view, then the mid-angle boundaries (mid-angle = half the BAM32 of the sum, rounded); their
     * tangents must come out strictly decreasing, or the binary search in run() would not be the nearest beam */
    if (s->beam_elev_urad != 0)
    {
        top = clamp_elev((int64_t)st->row_elev_urad[0] + cfg->fov_margin_urad);
        bottom = clamp_elev((int64_t)st->row_elev_urad[rows - 1] - cfg->fov_margin_urad);
    }
    else
    {
        top = clamp_elev((int64_t)s->fov_up_urad + cfg->fov_margin_urad);
        bottom = clamp_elev((int64_t)s->fov_down_urad - cfg->fov_margin_urad);
    }
    t_prev = make_bound(&st->fov_hi, lidet__q_urad_to_bam(top));
    memset(&st->row_bound[0], 0, sizeof st->row_bound[0]);
    for (r = 1; r < rows; ++r)
    {
        const int32_t sum_bam = lidet__q_urad_to_bam(st->row_elev_urad[r - 1] + st->row_elev_urad[r]);
        const int64_t t = make_bound(&st->row_bound[r], (int32_t)lidet__q_rshift_round(sum_bam, 1));
        if (t >= t_prev || (r > 1u && !bound_below(&st->row_bound[r], &st->row_bound[r - 1u])))
        {
            return LIDET_ERR_CONFIG;
        }
        t_prev = t;
    }
    memset(&st->row_bound[rows], 0, sizeof st->row_bound[rows]);
    if (make_bound(&st->fov_lo, lidet__q_urad_to_bam(bottom)) >= t_prev)
    {
        return LIDET_ERR_CONFIG;
    }
    status = init_columns(st, s->n_cols);
    if (status != LIDET_OK)
    {
        return status;
    }
    /* the range-only image's decoding tables (lidet_qpix.h) */
    st->has_col_trig =
        (uint8_t)lidet__qpix_tables(st->row_elev_bam, rows, s->n_cols, st->row_trig_q15, st->col_trig_q15);
    st->cfg = *cfg;
    st->cfg.sensor.beam_elev_urad = 0; /* not retained */
    st->n_points = 0;
    memset(&st->stats, 0, sizeof st->stats);
    st->stream_open = 0;
    st->magic = LIDET_INIT_MAGIC;
    return LIDET_OK;
}

/* The winner test's key of a pixel during pass 1: floor(r^2 / 4), the squared range in 4 mm^2 steps (< 2^32 as
 * r^2 <= 131000^2), kept as the float projection keeps its own: high half in range_4mm, low half in z_4mm. All
 * ones (the initial value) exceeds any key. */
static inline uint32_t key_get(const lidet_proj_q_buffers_t *b, uint32_t p)
{
    return ((uint32_t)b->range_4mm[p] << 16) | (uint16_t)b->z_4mm[p];
}

static inline void key_set(const lidet_proj_q_buffers_t *b, uint32_t p, uint32_t k)
{
    b->range_4mm[p] = (uint16_t)(k >> 16);
    b->z_4mm[p] = (int16_t)(uint16_t)k; /* two's complement: C99 int16_t */
}

/* a^2 for a < 2^18 (here a <= LIDET_Q_COORD_MAX_MM); on a core without a 32 x 32 -> 64 multiply (Cortex-M0+, RV32
 * without M) from 32-bit products only (a = h 2^16 + l: h^2 2^32 + h l 2^17 + l^2), so it calls no 64-bit
 * multiplication helper */
static inline uint64_t square_17(uint32_t a)
{
#if LIDET_Q_HAVE_MUL64
    return (uint64_t)a * a; /* one UMULL (Cortex-M3 and up) or MUL + MULHU (RV32 with M) */
#else
    const uint32_t h = a >> 16, l = a & 0xFFFFu;
    return ((uint64_t)(h * h) << 32) + ((uint64_t)(h * l) << 17) + (uint64_t)(l * l);
#endif
}

/* E[c] <= D, i.e. e sum <= num 2^29 = dn, exactly. First in 32 bits, where it is decided unless D is within
 * 2^-11 of the edge: c = floor(e / 2^18) (< 10 241) and num11 = num 2^11 (< 2^31), products < 2.7e9; only the
 * undecided rest takes the 64-bit product (one call to a helper on Cortex-M0+). */
static inline int edge_le(uint32_t e, uint32_t sum, uint32_t num11, uint64_t dn)
{
    const uint32_t c = e >> 18;
    if ((c + 1u) * sum <= num11) /* e < (c + 1) 2^18 */
    {
        return 1;
    }
    if (c * sum > num11) /* e >= c 2^18 */
    {
        return 0;
    }
    return (uint64_t)e * sum <= dn;
}

/* v mm -> 4 mm steps, rounded half up; |v| <= LIDET_Q_COORD_MAX_MM so the result fits int16 */
static inline int16_t to_4mm(int32_t v)
{
    return (int16_t)((v + 2) >> 2);
}

/* Pass 1 of lidet_proj_q_run over points [0, n): range, row, column, the closest point per pixel (key below, all
 * ones = empty); range_only a constant where inlined (the range-only image keeps the key alone, in point_idx) */
typedef struct
{
    const lidet_proj_q_state_t *st;
    const lidet_proj_q_buffers_t *buf;
    const int32_t *points;
    uint32_t stride, rows, cols, npix;
    const uint16_t *ring;
    uint64_t min2, max2;
} pass1_t;

#if defined(__GNUC__)
__attribute__((always_inline))
#endif
static inline void
project_points(const pass1_t *P, uint32_t n, lidet_proj_stats_t *stats, const int range_only)
{
    const lidet_proj_q_state_t *st = P->st;
    const lidet_proj_q_buffers_t *buf = P->buf;
    const int32_t *points = P->points;
    const uint32_t stride = P->stride, rows = P->rows, cols = P->cols, npix = P->npix;
    const uint16_t *ring = P->ring;
    const uint64_t min2 = P->min2, max2 = P->max2;
    const uint32_t *edge = st->col_edge_q29;
    int32_t *point_pixel = buf->point_pixel;
    uint32_t *key = (uint32_t *)buf->point_idx; /* range-only: int32_t storage read as its unsigned type */
    lidet_proj_stats_t sts = *stats;
    uint32_t i, pix, row_guess = 0, col_guess = 0;
    (void)npix;
    for (i = 0; i < n; ++i)
    {
        const int32_t *pt = points + (size_t)i * stride;
        const int32_t x = pt[0], y = pt[1], z = pt[2];
        uint64_t rxy2, z2, r2;
        uint32_t ax, ay, az, sum, num, row, col;
        int32_t out = -1;
        /* |coordinate| <= LIDET_Q_COORD_MAX_MM on the magnitudes, taken in unsigned arithmetic (INT32_MIN's is
         * 2^31, no overflow), which the squares reuse */
        ax = x < 0 ? 0u - (uint32_t)x : (uint32_t)x;
        ay = y < 0 ? 0u - (uint32_t)y : (uint32_t)y;
        az = z < 0 ? 0u - (uint32_t)z : (uint32_t)z;
        if (ax > COORD_SPAN || ay > COORD_SPAN || az > COORD_SPAN)
        {
            ++sts.n_too_far;
            goto next;
        }
        rxy2 = square_17(ax) + square_17(ay);
        z2 = square_17(az);
        r2 = rxy2 + z2;
        if (r2 < min2)
        {
            ++sts.n_too_close;
            goto next;
        }
        if (r2 > max2)
        {
            ++sts.n_too_far;
            goto next;
        }
        if (ring != 0)
        {
            if (ring[i] >= rows)
            {
                ++sts.n_bad_ring;
                goto next;
            }
            row = st->ring_to_row[ring[i]];
        }
        else
        {
            /* the row r with T[r] > t >= T[r + 1] (T[0] = +inf, T[rows] = -inf): unique, as the boundaries
             * strictly decrease (checked in init) and each test is exact. Tried first: the previous point's row
             * (scans come ring by ring: usually right, two tests); else a binary search (log2(rows) tests). */
            row = row_guess;
            if ((row > 0u && cmp_tan(z, z2, rxy2, &st->row_bound[row]) >= 0) ||
                (row + 1u < rows && cmp_tan(z, z2, rxy2, &st->row_bound[row + 1u]) < 0))
            {
                uint32_t lo = 0, hi = rows - 1u;
                while (lo < hi)
                {
                    const uint32_t mid = (lo + hi) >> 1;
                    const int at_or_above = cmp_tan(z, z2, rxy2, &st->row_bound[mid + 1u]) >= 0;
                    hi = at_or_above ? mid : hi;
                    lo = at_or_above ? lo : mid + 1u;
                }
                row = lo;
            }
            row_guess = row;
            /* the field of view: fov_hi > T[1] > ... > T[rows - 1] > fov_lo (init), so only the edge rows
             * can hold a point outside it (x = y = 0, t = +-inf, included) */
            if ((row == 0u && cmp_tan(z, z2, rxy2, &st->fov_hi) > 0) ||
                (row + 1u == rows && cmp_tan(z, z2, rxy2, &st->fov_lo) < 0))
            {
                ++sts.n_out_of_fov;
                goto next;
            }
        }
        /* column: D = num / sum in [0, 4); x = y = 0 (ring path only) is straight ahead, D = 2. The column c
         * with E[c] <= D < E[c + 1] (exact cross-multiplications): the previous point's column and its two
         * neighbours first (consecutive points share or neighbour columns in both the ring-by-ring and the
         * firing order), else the bucket floor(D cols) (one division), its table entry and one step up. */
        sum = ax + ay;
        num = y >= 0 ? sum + (uint32_t)x : 3u * sum - (uint32_t)x; /* unsigned wrap-around is exact here */
        if (sum == 0u)
        {
            sum = 1u;
            num = 2u;
        }
        {
            const uint64_t dn = (uint64_t)num << 29; /* D in Q29, times sum */
            const uint32_t num11 = num << 11;        /* num <= 4 sum < 2^20 */
            int lo_ok, hi_ok;                        /* E[col] <= D, D < E[col + 1] */
            col = col_guess;
            lo_ok = edge_le(edge[col], sum, num11, dn);
            hi_ok = !edge_le(edge[col + 1u], sum, num11, dn);
            if (!lo_ok && col > 0u) /* one column down: its upper edge is the old lower one */
            {
                --col;
                lo_ok = edge_le(edge[col], sum, num11, dn);
                hi_ok = 1;
            }
            else if (
                !hi_ok) /* one up: its lower edge is the old upper one (the sentinel stops it at cols - 1) */
            {
                ++col;
                lo_ok = 1;
                hi_ok = !edge_le(edge[col + 1u], sum, num11, dn);
            }
            if (!lo_ok || !hi_ok)
            {
#if LIDET_MAX_COLS <= 4096
                const uint32_t bucket = num * cols / sum; /* num * cols <= 4 * 262000 * 4096 < 2^32 */
#else /* builds for more than 4096 columns: one 64-bit division on this fallback */
                const uint32_t bucket = (uint32_t)((uint64_t)num * cols / sum);
#endif
                col = st->col_lut[bucket];
                col += (uint32_t)edge_le(edge[col + 1u], sum, num11, dn);
            }
            col_guess = col;
        }
        pix = row * cols + col;
        LIDET_ASSERT(pix < npix);
        out = (int32_t)pix;
        ++sts.n_projected;
        if (range_only)
        {
            /* the key alone, in the point_idx buffer (all ones = empty, as above) */
            key[pix] = (uint32_t)(r2 >> 2) < key[pix] ? (uint32_t)(r2 >> 2) : key[pix];
        }
        else if ((uint32_t)(r2 >> 2) < key_get(buf, pix)) /* strict: ties keep the earlier point */
        {
            key_set(buf, pix, (uint32_t)(r2 >> 2));
            buf->point_idx[pix] = (int32_t)i;
        }
    next:
        if (point_pixel != 0)
        {
            point_pixel[i] = out;
        }
    }

    *stats = sts;
}

/* a run's counts zeroed but the inputs and those past LIDET_MAX_POINTS (not looked at); returns the count read */
static uint32_t begin_stats(lidet_proj_stats_t *sts, uint32_t n_in)
{
    const uint32_t n = n_in > LIDET_MAX_POINTS ? LIDET_MAX_POINTS : n_in;
    memset(sts, 0, sizeof *sts);
    sts->n_points_in = n_in;
    sts->n_truncated = n_in - n;
    return n;
}

/* the runs' checks of the state and buffers; *range_only: the buffers make a range-only image */
static lidet_status_t check_run(const lidet_proj_q_state_t *st, const lidet_proj_q_buffers_t *buf,
                                int *range_only)
{
    if (st == 0 || buf == 0 || buf->range_4mm == 0 || buf->point_idx == 0)
    {
        return LIDET_ERR_ARG;
    }
    /* x, y, z all stored, or none (a range-only image) */
    *range_only = buf->x_4mm == 0;
    if ((buf->y_4mm == 0) != *range_only || (buf->z_4mm == 0) != *range_only)
    {
        return LIDET_ERR_ARG;
    }
    return st->magic != LIDET_INIT_MAGIC ? LIDET_ERR_STATE : LIDET_OK;
}

lidet_status_t lidet_proj_q_run(lidet_proj_q_state_t *st, const lidet_proj_q_buffers_t *buf,
                                const int32_t *points, uint32_t n_points, uint32_t stride,
                                const uint16_t *ring)
{
    uint32_t n, rows, cols, npix, pix;
    uint64_t min2, max2;
    int range_only;
    lidet_proj_stats_t sts;

    lidet_status_t s = check_run(st, buf, &range_only);
    if (s != LIDET_OK)
    {
        return s;
    }
    if (stride < 3 || (points == 0 && n_points > 0))
    {
        return LIDET_ERR_ARG;
    }
    st->stream_open = 0; /* a run closes an open stream of returns */
    rows = st->cfg.sensor.n_rows;
    cols = st->cfg.sensor.n_cols;
    npix = rows * cols;
    n = begin_stats(&sts, n_points);
    min2 = (uint64_t)st->cfg.min_range_mm * (uint64_t)st->cfg.min_range_mm;
    min2 = min2 > 0u ? min2 : 1u; /* zero range is always too close */
    max2 = st->cfg.max_range_mm > 0 ? (uint64_t)st->cfg.max_range_mm * (uint64_t)st->cfg.max_range_mm
                                    : MAX_R2_MM2;
    max2 = max2 < MAX_R2_MM2 ? max2 : MAX_R2_MM2;

    /* pass 1, point by point: range, row, column, the closest point per pixel (key above, all ones = empty) */
    memset(buf->point_idx, 0xFF, (size_t)npix * sizeof buf->point_idx[0]);
    if (!range_only)
    {
        memset(buf->range_4mm, 0xFF, (size_t)npix * sizeof buf->range_4mm[0]);
        memset(buf->z_4mm, 0xFF, (size_t)npix * sizeof buf->z_4mm[0]);
    }
    {
        pass1_t P;
        P.st = st;
        P.buf = buf;
        P.points = points;
        P.stride = stride;
        P.rows = rows;
        P.cols = cols;
        P.npix = npix;
        P.ring = ring;
        P.min2 = min2;
        P.max2 = max2;
        if (range_only)
        {
            project_points(&P, n, &sts, 1);
        }
        else
        {
            project_points(&P, n, &sts, 0);
        }
    }
    /* pass 2, over pixels: the winners' coordinates and ranges in 4 mm steps (one isqrt per filled pixel) */
    if (range_only)
    {
        const uint32_t *key = (const uint32_t *)buf->point_idx;
        uint16_t *range = buf->range_4mm;
        uint32_t filled = 0;
        for (pix = 0; pix < npix; ++pix)
        {
            /* the range from the key as below; an empty pixel (all ones) gets 0 */
            const uint32_t k = key[pix];
            uint32_t rq = 0u;
            if (k != 0xFFFFFFFFu)
            {
                rq = (lidet__q_isqrt32_inl(k) + 1u) >> 1;
                rq = rq > 0u ? rq : 1u;
                ++filled;
            }
            range[pix] = (uint16_t)rq;
        }
        sts.n_pixels_filled += filled;
    }
    for (pix = 0; !range_only && pix < npix; ++pix)
    {
        const int32_t k = buf->point_idx[pix];
        if (k < 0)
        {
            buf->x_4mm[pix] = 0;
            buf->y_4mm[pix] = 0;
            buf->z_4mm[pix] = 0;
            buf->range_4mm[pix] = 0;
        }
        else
        {
            const int32_t *pt = points + (size_t)k * stride;
            /* round(sqrt(r2) / 4) = (floor(sqrt(r2) / 2) + 1) / 2, halves up, and floor(sqrt(r2) / 2) =
             * floor(sqrt(floor(r2 / 4))), the root of the key pass 1 kept (32-bit); >= 1 for a valid pixel */
            const uint32_t rq = (lidet__q_isqrt32_inl(key_get(buf, pix)) + 1u) >> 1;
            buf->x_4mm[pix] = to_4mm(pt[0]);
            buf->y_4mm[pix] = to_4mm(pt[1]);
            buf->z_4mm[pix] = to_4mm(pt[2]);
            buf->range_4mm[pix] = (uint16_t)(rq > 0u ? rq : 1u);
            ++sts.n_pixels_filled;
        }
    }
    st->n_points = n;
    st->stats = sts;
    return sts.n_truncated > 0 ? LIDET_TRUNCATED : LIDET_OK;
}

/* Pass 1 of lidet_proj_q_run_returns, over one chunk of the scan: the nearest return per pixel. A range-only
 * image keeps its range_4mm directly (0 = empty; nothing else to do); an image with x, y, z keeps the range in
 * mm as the key in its range and z planes (key_set, all ones = empty) and the winner's index in the scan (base +
 * its index in the chunk: point_idx), for its second pass. point_pixel, when set, is the chunk's. The counts
 * are added to sts (a chunk at a time). range_only
 * is a constant where inlined; the firmware's loop (a range-only image) is about 35 instructions per return on a
 * Cortex-M4. */
#if defined(__GNUC__)
__attribute__((always_inline))
#endif
static inline void
returns_pass1(const lidet_proj_q_state_t *st, const lidet_proj_q_buffers_t *buf, const lidet_return_t *ret,
              uint32_t n, uint32_t base, uint32_t min_mm, uint32_t max_mm, lidet_proj_stats_t *sts,
              const int range_only)
{
    const uint32_t rows = st->cfg.sensor.n_rows, cols = st->cfg.sensor.n_cols;
    const uint8_t *ring_to_row = st->ring_to_row;
    uint16_t *range = buf->range_4mm;
    int32_t *point_pixel = buf->point_pixel;
    /* the fast test takes ranges in [lo2, max_mm] with lo2 >= 2 (round(r / 4) >= 1 without a clamp) and rings
     * below fast_rows; a 1 mm limit (max_mm < lo2, an empty interval) makes fast_rows 0, so every return takes
     * the rare branch, which decides with the real limits */
    const uint32_t lo2 = min_mm > 2u ? min_mm : 2u;
    const uint32_t span2 = max_mm >= lo2 ? max_mm - lo2 : 0u;
    const uint32_t fast_rows = max_mm >= lo2 ? rows : 0u;
    const lidet_return_t *p = ret, *const end = ret + n;
    uint32_t n_dropped = 0, filled = 0;
    for (; p != end; ++p)
    {
        const uint32_t r = p->range_mm, ring = p->ring;
        uint32_t pix, rq = (r + 2u) >> 2;
        if (r - lo2 > span2 || ring >= fast_rows) /* one unsigned compare for both range limits */
        {
            /* the rare case: which limit (or a valid 1 mm return when min_mm <= 1: round(1 / 4) = 0 -> 1) */
            const int in = r >= min_mm && r <= max_mm;
            if (!in || ring >= rows)
            {
                sts->n_too_close += (uint32_t)(r < min_mm);
                sts->n_too_far += (uint32_t)(r > max_mm);
                sts->n_bad_ring += (uint32_t)in;
                ++n_dropped;
                if (point_pixel != 0)
                {
                    point_pixel[p - ret] = -1;
                }
                continue;
            }
            rq = rq > 0u ? rq : 1u;
        }
        /* u 2^16 = 2^15 - azimuth (mod 2^16); n_cols <= 2^16, so the product fits 32 bits */
        pix =
            (uint32_t)ring_to_row[ring] * cols + (((uint32_t)(uint16_t)(0x8000u - p->azimuth) * cols) >> 16);
        if (point_pixel != 0)
        {
            point_pixel[p - ret] = (int32_t)pix;
        }
        if (range_only)
        {
            /* round(r / 4) >= 1, kept where smaller than the pixel's (0: empty, wraps to the largest in the
             * unsigned test): the minimum of the rounded ranges is the rounded minimum; no second pass */
            const uint32_t cur = range[pix];
            filled += (uint32_t)(cur == 0u);
            range[pix] = (uint16_t)(rq - 1u < cur - 1u ? rq : cur);
        }
        else if (r < key_get(buf, pix)) /* strict: ties keep the earlier return */
        {
            key_set(buf, pix, r);
            buf->point_idx[pix] = (int32_t)(base + (uint32_t)(p - ret));
        }
    }
    sts->n_projected += n - n_dropped;
    sts->n_pixels_filled += filled; /* range-only; the other image counts in its second pass */
}

/* check_run, and a stream open (lidet_proj_q_returns_begin): else LIDET_ERR_STATE */
static lidet_status_t check_stream(const lidet_proj_q_state_t *st, const lidet_proj_q_buffers_t *buf,
                                   int *range_only)
{
    const lidet_status_t s = check_run(st, buf, range_only);
    if (s != LIDET_OK)
    {
        return s;
    }
    return st->stream_open ? LIDET_OK : LIDET_ERR_STATE;
}

/* the returns' range limits, mm: [min_mm, max_mm] */
static void returns_limits(const lidet_proj_q_state_t *st, uint32_t *min_mm, uint32_t *max_mm)
{
    *min_mm =
        st->cfg.min_range_mm > 0 ? (uint32_t)st->cfg.min_range_mm : 1u; /* zero range is always too close */
    *max_mm = st->cfg.max_range_mm > 0 && (uint32_t)st->cfg.max_range_mm < 131000u
                  ? (uint32_t)st->cfg.max_range_mm
                  : 131000u;
}

lidet_status_t lidet_proj_q_returns_begin(lidet_proj_q_state_t *st, const lidet_proj_q_buffers_t *buf)
{
    uint32_t npix;
    int range_only;
    const lidet_status_t s = check_run(st, buf, &range_only);
    if (s != LIDET_OK)
    {
        return s;
    }
    npix = st->cfg.sensor.n_rows * st->cfg.sensor.n_cols;
    (void)begin_stats(&st->stats, 0u);
    st->n_points = 0;
    if (!range_only)
    {
        memset(buf->point_idx, 0xFF, (size_t)npix * sizeof buf->point_idx[0]);
        memset(buf->range_4mm, 0xFF, (size_t)npix * sizeof buf->range_4mm[0]);
        memset(buf->z_4mm, 0xFF, (size_t)npix * sizeof buf->z_4mm[0]);
    }
    else
    {
        memset(buf->range_4mm, 0, (size_t)npix * sizeof buf->range_4mm[0]);
    }
    st->stream_open = 1;
    return LIDET_OK;
}

lidet_status_t lidet_proj_q_returns_add(lidet_proj_q_state_t *st, const lidet_proj_q_buffers_t *buf,
                                        const lidet_return_t *returns, uint32_t n_returns)
{
    uint32_t room, n, min_mm, max_mm;
    int range_only;
    const lidet_status_t s = check_stream(st, buf, &range_only);
    if (s != LIDET_OK)
    {
        return s;
    }
    if (returns == 0 && n_returns > 0)
    {
        return LIDET_ERR_ARG;
    }
    /* n_points counts the returns looked at so far (the scan's first LIDET_MAX_POINTS) */
    room = LIDET_MAX_POINTS - st->n_points;
    n = n_returns < room ? n_returns : room;
    st->stats.n_points_in += n_returns;
    st->stats.n_truncated += n_returns - n;
    returns_limits(st, &min_mm, &max_mm);
    if (range_only) /* the firmware's case */
    {
        returns_pass1(st, buf, returns, n, st->n_points, min_mm, max_mm, &st->stats, 1);
    }
    else
    {
        returns_pass1(st, buf, returns, n, st->n_points, min_mm, max_mm, &st->stats, 0);
    }
    st->n_points += n;
    return n < n_returns ? LIDET_TRUNCATED : LIDET_OK;
}

lidet_status_t lidet_proj_q_returns_end(lidet_proj_q_state_t *st, const lidet_proj_q_buffers_t *buf)
{
    uint32_t rows, cols, pix, filled = 0;
    int range_only;
    const lidet_status_t s = check_stream(st, buf, &range_only);
    if (s != LIDET_OK)
    {
        return s;
    }
    st->stream_open = 0;
    rows = st->cfg.sensor.n_rows;
    cols = st->cfg.sensor.n_cols;
    /* pass 2, an image with x, y, z: range_4mm = round(range_mm / 4) (>= 1), x, y, z decoded as the range-only
     * image's readers would (lidet_qpix.h) */
    if (!range_only)
    {
        lidet_range_image_t img;
        uint32_t r, c;
        lidet_proj_q_image(st, buf, &img);
        img.x_4mm = img.y_4mm = img.z_4mm = 0; /* decode */
        for (r = 0, pix = 0; r < rows; ++r)
        {
            const lidet__qpix_row_t rt = lidet__qpix_row(&img, r);
            for (c = 0; c < cols; ++c, ++pix)
            {
                int32_t v[3] = {0, 0, 0}, ct, sn;
                uint32_t rq = 0u;
                if (buf->point_idx[pix] >= 0)
                {
                    rq = (key_get(buf, pix) + 2u) >> 2;
                    rq = rq > 0u ? rq : 1u;
                    lidet__qpix_col(&img, c, &ct, &sn);
                    lidet__qpix_decode(rq, rt, ct, sn, v);
                    ++filled;
                }
                buf->range_4mm[pix] = (uint16_t)rq;
                buf->x_4mm[pix] = (int16_t)v[0];
                buf->y_4mm[pix] = (int16_t)v[1];
                buf->z_4mm[pix] = (int16_t)v[2];
            }
        }
        st->stats.n_pixels_filled = filled;
    }
    return st->stats.n_truncated > 0 ? LIDET_TRUNCATED : LIDET_OK;
}

lidet_status_t lidet_proj_q_run_returns(lidet_proj_q_state_t *st, const lidet_proj_q_buffers_t *buf,
                                        const lidet_return_t *returns, uint32_t n_returns)
{
    int range_only;
    lidet_status_t s = check_run(st, buf, &range_only);
    if (s != LIDET_OK)
    {
        return s;
    }
    if (returns == 0 && n_returns > 0)
    {
        return LIDET_ERR_ARG;
    }
    s = lidet_proj_q_returns_begin(st, buf);
    if (s != LIDET_OK)
    {
        return s;
    }
    s = lidet_proj_q_returns_add(st, buf, returns, n_returns);
    if (!LIDET_SUCCEEDED(s))
    {
        st->stream_open = 0;
        return s;
    }
    return lidet_proj_q_returns_end(st, buf);
}

void lidet_proj_q_image(const lidet_proj_q_state_t *st, const lidet_proj_q_buffers_t *buf,
                        lidet_range_image_t *img)
{
    if (st == 0 || buf == 0 || img == 0)
    {
        return;
    }
    memset(img, 0, sizeof *img);
    img->n_rows = st->cfg.sensor.n_rows;
    img->n_cols = st->cfg.sensor.n_cols;
    img->x_4mm = buf->x_4mm;
    img->y_4mm = buf->y_4mm;
    img->z_4mm = buf->z_4mm;
    img->range_4mm = buf->range_4mm;
    img->point_idx = buf->x_4mm != 0 ? buf->point_idx : 0; /* range-only: the buffer held the keys */
    img->row_elev_bam = st->row_elev_bam;
    img->row_trig_q15 = st->row_trig_q15;
    img->col_trig_q15 = st->has_col_trig ? st->col_trig_q15 : 0;
}

const lidet_proj_stats_t *lidet_proj_q_stats(const lidet_proj_q_state_t *st)
{
    return st == 0 ? 0 : &st->stats;
}

uint32_t lidet_proj_q_state_bytes(void)
{
    return (uint32_t)sizeof(lidet_proj_q_state_t);
}
