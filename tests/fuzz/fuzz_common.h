/* SPDX-License-Identifier: MIT */
/* Input decoding shared by the libFuzzer harnesses of tests/fuzz (byte layout: tests/fuzz/README.md).
 *
 * A scan input is: a header (sensor geometry, flags, projection configuration), then the harness's own
 * knob bytes, then the points: records of `stride` raw float32 (little endian, any bit pattern: NaN,
 * Inf, denormals and 1e30 included) each followed by a uint16 ring index when the rings flag is set.
 * The payload can be tiled up to 4 times, so scans above LIDET_MAX_POINTS stay small inputs.
 * Reads past the end of the input yield zeros: every byte string is a valid input. */
#ifndef LIDET_FUZZ_COMMON_H
#define LIDET_FUZZ_COMMON_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "lidet/lidet.h"

/* a property every result must have; a violation is a finding (abort: libFuzzer saves the input) */
#define FZ_CHECK(c)                                                                            \
    do                                                                                         \
    {                                                                                          \
        if (!(c))                                                                              \
        {                                                                                      \
            fprintf(stderr, "fuzz invariant failed: %s (%s:%d)\n", #c, __FILE__, __LINE__);    \
            abort();                                                                           \
        }                                                                                      \
    } while (0)

typedef struct
{
    const uint8_t *p;
    size_t n;
} fz_in_t;

static uint8_t fz_u8(fz_in_t *in)
{
    uint8_t v = 0;
    if (in->n > 0)
    {
        v = in->p[0];
        in->p++;
        in->n--;
    }
    return v;
}

static uint16_t fz_u16(fz_in_t *in)
{
    const uint16_t lo = fz_u8(in);
    return (uint16_t)(lo | (uint16_t)(fz_u8(in) << 8));
}

static uint32_t fz_u32(fz_in_t *in)
{
    const uint32_t lo = fz_u16(in);
    return lo | ((uint32_t)fz_u16(in) << 16);
}

/* any bit pattern, NaN and Inf included */
static float fz_f32(fz_in_t *in)
{
    const uint32_t u = fz_u32(in);
    float f;
    memcpy(&f, &u, sizeof f);
    return f;
}

/* knob = one of a configuration's float fields overwritten with a raw float: the init's validation */
static void fz_poke_f32(fz_in_t *in, float *const *fields, uint32_t n_fields)
{
    const uint8_t sel = fz_u8(in);
    const float v = fz_f32(in);
    if (sel < n_fields)
    {
        *fields[sel] = v;
    }
}

/* static uint64_t name(const model_t *c): the multiply-adds of one forward pass of a descriptor the checks
 * accepted (float lidet_pn_model_t or int8 lidet_pointnet_q_model_t: the same member names) */
#define FZ_DEFINE_MACS(name, model_t, stage_t)                                                       \
    static uint64_t name(const model_t *c)                                                           \
    {                                                                                                \
        uint64_t n = 0;                                                                              \
        uint32_t s, i;                                                                               \
        for (s = 0; s < c->n_stages && s < 2u; ++s)                                                  \
        {                                                                                            \
            const stage_t *st = &c->stage[s];                                                        \
            for (i = 0; i < st->n_point; ++i)                                                        \
            {                                                                                        \
                n += (uint64_t)c->n_points * st->point[i].n_in * st->point[i].n_out;                 \
            }                                                                                        \
            for (i = 0; i < st->n_pvle; ++i)                                                         \
            {                                                                                        \
                n += (uint64_t)st->pvle[i].n_in * st->pvle[i].n_out;                                 \
            }                                                                                        \
            for (i = 0; i < st->n_head; ++i)                                                         \
            {                                                                                        \
                n += (uint64_t)st->head[i].n_in * st->head[i].n_out;                                 \
            }                                                                                        \
        }                                                                                            \
        return n;                                                                                    \
    }

/* ---- scans ---------------------------------------------------------------------------------- */

#define FZ_MAX_STRIDE 6u
#define FZ_MAX_TILE 4u
#define FZ_MAX_IN (FZ_MAX_TILE * LIDET_MAX_POINTS + 64u)

#define FZ_FLAG_TABLE 0x01u  /* beam table follows (else a uniform fov_up, fov_down) */
#define FZ_FLAG_RINGS 0x02u  /* a uint16 ring index after each record */
#define FZ_FLAG_RAW_DIM 0x20u /* n_rows, n_cols taken raw (out of capacity: init errors) */
#define FZ_FLAG_RAW_CFG 0x40u /* min_range, max_range, fov_margin raw floats follow */

typedef struct
{
    lidet_sensor_t sensor;
    float elev[256];
    lidet_proj_cfg_t proj;
    uint8_t flags;
    uint32_t stride;
    uint32_t tile;
    float *pts;    /* n_points records of stride floats */
    uint16_t *ring; /* n_points rings, or NULL */
    uint32_t n_points;
} fz_scan_t;

static float fz_pts[FZ_MAX_IN * FZ_MAX_STRIDE];
static uint16_t fz_ring[FZ_MAX_IN];

/* the header: sensor, flags, projection configuration (the harness reads its knobs next) */
static void fz_scan_header(fz_in_t *in, fz_scan_t *s)
{
    const uint8_t b_rows = fz_u8(in), b_cols = fz_u8(in);
    uint32_t i;
    memset(s, 0, sizeof *s);
    s->flags = fz_u8(in);
    s->stride = 3u + ((s->flags >> 2) & 3u);
    s->tile = 1u + (fz_u8(in) % FZ_MAX_TILE);
    s->sensor.name = "fuzz";
    if (s->flags & FZ_FLAG_RAW_DIM)
    {
        s->sensor.n_rows = b_rows;
        s->sensor.n_cols = (uint16_t)(4u * b_cols);
    }
    else
    {
        s->sensor.n_rows = (uint16_t)(1u + b_rows % LIDET_MAX_ROWS);
        s->sensor.n_cols = (uint16_t)(8u + b_cols % (LIDET_MAX_COLS - 7u));
    }
    if (s->flags & FZ_FLAG_TABLE)
    {
        for (i = 0; i < s->sensor.n_rows && i < 256u; ++i)
        {
            s->elev[i] = fz_f32(in);
        }
        s->sensor.beam_elev_rad = s->elev;
    }
    else
    {
        s->sensor.fov_up_rad = fz_f32(in);
        s->sensor.fov_down_rad = fz_f32(in);
    }
    s->sensor.mount_height_m = 0.25f * (float)(fz_u8(in) % 17u); /* 0 .. 4 m */
    s->sensor.max_range_m = 100.0f;
    lidet_proj_cfg_default(&s->proj, &s->sensor);
    if (s->flags & FZ_FLAG_RAW_CFG)
    {
        s->proj.min_range_m = fz_f32(in);
        s->proj.max_range_m = fz_f32(in);
        s->proj.fov_margin_rad = fz_f32(in);
    }
}

/* the points: the rest of the input, tiled s->tile times */
static void fz_scan_points(fz_in_t *in, fz_scan_t *s)
{
    const uint32_t rec = 4u * s->stride + ((s->flags & FZ_FLAG_RINGS) ? 2u : 0u);
    uint32_t n = (uint32_t)(in->n / rec), i, t;
    if (n > FZ_MAX_IN / s->tile)
    {
        n = FZ_MAX_IN / s->tile;
    }
    /* n whole records are there: copied without fz_u8's per-byte bound check, whose comparisons the
     * fuzzer would otherwise trace for every byte of every input (little-endian, as fz_u32 composes them) */
    for (i = 0; i < n; ++i)
    {
        memcpy(&fz_pts[i * s->stride], in->p, 4u * s->stride);
        in->p += 4u * s->stride;
        fz_ring[i] = 0u;
        if (s->flags & FZ_FLAG_RINGS)
        {
            fz_ring[i] = (uint16_t)(in->p[0] | (in->p[1] << 8));
            in->p += 2;
        }
    }
    in->n -= (size_t)n * rec;
    for (t = 1; t < s->tile; ++t)
    {
        memcpy(&fz_pts[t * n * s->stride], fz_pts, (size_t)n * s->stride * sizeof(float));
        memcpy(&fz_ring[t * n], fz_ring, (size_t)n * sizeof(uint16_t));
    }
    s->pts = fz_pts;
    s->ring = (s->flags & FZ_FLAG_RINGS) ? fz_ring : NULL;
    s->n_points = n * s->tile;
}

/* The compact projection (what a detector workspace keeps) of the scan into static buffers: the image in
 * *img, the status in *rc; point_pixel (LIDET_MAX_POINTS entries) may be NULL. Returns the state (its
 * stats), or NULL when its init fails (*rc says why). */
static const lidet_proj_state_t *fz_project_compact(const fz_scan_t *s, lidet_range_image_t *img, int32_t *point_pixel,
                                                    lidet_status_t *rc)
{
    static lidet_proj_state_t st;
    static int16_t x[LIDET_MAX_ROWS * LIDET_MAX_COLS], y[LIDET_MAX_ROWS * LIDET_MAX_COLS],
        z[LIDET_MAX_ROWS * LIDET_MAX_COLS];
    static uint16_t r[LIDET_MAX_ROWS * LIDET_MAX_COLS];
    static int32_t idx[LIDET_MAX_ROWS * LIDET_MAX_COLS];
    lidet_proj_buffers_t buf;
    *rc = lidet_proj_state_init(&st, &s->proj);
    if (*rc != LIDET_OK)
    {
        return NULL;
    }
    memset(&buf, 0, sizeof buf);
    buf.x_4mm = x;
    buf.y_4mm = y;
    buf.z_4mm = z;
    buf.range_4mm = r;
    buf.point_idx = idx;
    buf.point_pixel = point_pixel;
    *rc = lidet_proj_run_buffers(&st, &buf, s->pts, s->n_points, s->stride, s->ring);
    lidet_proj_image_of(&st, &buf, img);
    return &st;
}

/* properties of a projection's counts that hold for any input */
static void fz_check_proj_stats(const lidet_proj_stats_t *st, uint32_t n_points, uint32_t n_pixels)
{
    FZ_CHECK(st->n_points_in == n_points);
    FZ_CHECK(st->n_pixels_filled <= n_pixels);
    FZ_CHECK(st->n_pixels_filled <= st->n_projected);
    FZ_CHECK((uint64_t)st->n_projected + st->n_nonfinite + st->n_too_close + st->n_too_far + st->n_out_of_fov +
                 st->n_bad_ring + st->n_out_of_window + st->n_truncated ==
             n_points);
    FZ_CHECK(st->n_truncated == (n_points > LIDET_MAX_POINTS ? n_points - LIDET_MAX_POINTS : 0u));
}

#endif /* LIDET_FUZZ_COMMON_H */
