/* SPDX-License-Identifier: MIT */
/* The integer stages' pixel accessor (docs/FIXED_POINT.md, "The integer detector"; docs/MEMORY.md, "The integer
 * detector in 256 KiB"). A compact image either stores x, y, z (x_4mm, y_4mm, z_4mm non-NULL: read) or only the
 * range (the three NULL: the range-only image of LIDET_Q_PIXEL_XYZ 0 or lidet_detector_q_cfg_t.range_only): x, y,
 * z are then decoded from the pixel's row, its column and its range with ONE rule, mirrored bit for bit by
 * codegen/lidet_ref/qmath.py (decode_pixels):
 *   row r:     e = row_elev_bam[r] (the beam's elevation), ce = cos e, se = sin e in Q15, each the Q30 value of
 *              lidet__q_cos/sin rounded: round(v / 2^15);
 *   column c:  t = floor((2c + 1) 2^31 / n_cols) (BAM32: the column centre's angle from azimuth pi, as the
 *              projection numbers its columns), ct = cos t, st = sin t (Q15, rounded the same way); the azimuth's
 *              cosine is -ct, its sine st;
 *   ray:       ux = round(ce (-ct) / 2^15), uy = round(ce st / 2^15), uz = se (Q15);
 *   point:     x = round(range ux / 2^15), y = round(range uy / 2^15), z = round(range uz / 2^15), 4 mm steps;
 *              every rounding halves up ((v + 2^14) >> 15, arithmetic), range = its low 15 bits (valid ones are
 *              <= 32750). An empty pixel (range 0) decodes to 0.
 * Every product fits int32 (|Q15| <= 2^15, range < 2^15): 32-bit multiplications only, no 64-bit helper on a
 * Cortex-M0+. The ray's rounding (2^-16 per component) moves a point by at most ~1 step at the 131 m limit.
 * The tables the projection builds at init (image row_trig_q15, col_trig_q15) hold exactly these sines and
 * cosines (the columns' for the first quarter turn: t of column q n_cols/4 + j is q 2^30 + t_j when n_cols is a
 * multiple of 4, and lidet__q_sin folds quadrants exactly); without them they are computed where read. Integer
 * only; never installed. */
#ifndef LIDET_QPIX_H
#define LIDET_QPIX_H

#include <stdint.h>

#include "lidet/lidet_image.h"
#include "lidet_qmath.h"

/** 1 for a range-only compact image (x, y, z decoded), 0 when it stores them */
static inline int lidet__qpix_range_only(const lidet_range_image_t *img)
{
    return img->x_4mm == 0;
}

/** 1 when a compact image has the coordinates the integer stages read: x, y, z, or none of them and the range
 *  with the row elevations (a range-only image); and no float arrays */
static inline int lidet__qpix_image_ok(const lidet_range_image_t *img)
{
    const int xyz = img->x_4mm != 0 && img->y_4mm != 0 && img->z_4mm != 0;
    const int none = img->x_4mm == 0 && img->y_4mm == 0 && img->z_4mm == 0;
    return img->x_m == 0 && (xyz || (none && img->range_4mm != 0 && img->row_elev_bam != 0));
}

/** t of column c (above): floor((2c + 1) 2^31 / cols) with 32-bit divisions only (cols <= 2^15) */
static inline uint32_t lidet__qpix_col_angle(uint32_t c, uint32_t cols)
{
    const uint32_t q = 0x80000000u / cols, rem = 0x80000000u % cols, k = 2u * c + 1u;
    return k * q + (k * rem) / cols; /* k < 2 cols, rem < cols: k rem < 2^31 for cols <= 2^15 */
}

/** round(v / 2^15), halves up, in 32 bits (|v| < 2^31 - 2^14) */
static inline int32_t lidet__qpix_rs15(int32_t v)
{
    return (v + (1 << 14)) >> 15;
}

/** a Q30 sine or cosine in Q15 */
static inline int32_t lidet__qpix_q15(int32_t v_q30)
{
    return (int32_t)lidet__q_rshift_round(v_q30, 15);
}

/** cos, sin (Q15) of row r's elevation (0, 0 for an image that stores x, y, z) */
typedef struct
{
    int32_t ce, se;
} lidet__qpix_row_t;

static inline lidet__qpix_row_t lidet__qpix_row(const lidet_range_image_t *img, uint32_t r)
{
    lidet__qpix_row_t t;
    if (img->x_4mm != 0) /* stored coordinates: not needed (the elevations may be absent) */
    {
        t.ce = 0;
        t.se = 0;
    }
    else if (img->row_trig_q15 != 0)
    {
        t.ce = img->row_trig_q15[2u * r];
        t.se = img->row_trig_q15[2u * r + 1u];
    }
    else
    {
        t.ce = lidet__qpix_q15(lidet__q_cos((uint32_t)img->row_elev_bam[r]));
        t.se = lidet__qpix_q15(lidet__q_sin((uint32_t)img->row_elev_bam[r]));
    }
    return t;
}

/** cos t, sin t (Q15) of column c's angle t */
static inline void lidet__qpix_col(const lidet_range_image_t *img, uint32_t c, int32_t *ct, int32_t *st)
{
    const uint32_t cols = img->n_cols;
    if (img->col_trig_q15 != 0)
    {
        /* c = quadrant * cols/4 + j: t = quadrant 2^30 + t_j; sin, cos of t_j in the table */
        const uint32_t qn = cols >> 2;
        const uint32_t quadrant = (uint32_t)(c >= qn) + (uint32_t)(c >= 2u * qn) + (uint32_t)(c >= 3u * qn);
        const uint32_t j = c - quadrant * qn;
        const int32_t s = img->col_trig_q15[2u * j], k = img->col_trig_q15[2u * j + 1u];
        switch (quadrant)
        {
        case 0u:
            *st = s;
            *ct = k;
            break;
        case 1u:
            *st = k;
            *ct = -s;
            break;
        case 2u:
            *st = -s;
            *ct = -k;
            break;
        default:
            *st = -k;
            *ct = s;
            break;
        }
    }
    else
    {
        const uint32_t t = lidet__qpix_col_angle(c, cols);
        *st = lidet__qpix_q15(lidet__q_sin(t));
        *ct = lidet__qpix_q15(lidet__q_cos(t));
    }
}

/** x, y, z (4 mm steps) of a pixel of range rng (< 2^15) on row trig rt and column trig ct, st (the rule above) */
static inline void lidet__qpix_decode(uint32_t rng, lidet__qpix_row_t rt, int32_t ct, int32_t st,
                                      int32_t v[3])
{
    /* the low 15 bits: a valid range is <= 32750 (the compact image's limit); a caller's larger value cannot
     * overflow the products */
    const int32_t r = (int32_t)(rng & 0x7FFFu), ux = lidet__qpix_rs15(-rt.ce * ct),
                  uy = lidet__qpix_rs15(rt.ce * st);
    v[0] = lidet__qpix_rs15(r * ux);
    v[1] = lidet__qpix_rs15(r * uy);
    v[2] = lidet__qpix_rs15(r * rt.se);
}

/** x, y, z of pixel p of an image that stores them */
static inline void lidet__qpix_stored(const lidet_range_image_t *img, uint32_t p, int32_t v[3])
{
    v[0] = img->x_4mm[p];
    v[1] = img->y_4mm[p];
    v[2] = img->z_4mm[p];
}

/** x, y, z of pixel p = r n_cols + c with row r's trig already at hand (stored or decoded) */
static inline void lidet__qpix_xyz_rc(const lidet_range_image_t *img, lidet__qpix_row_t rt, uint32_t c,
                                      uint32_t p, int32_t v[3])
{
    int32_t ct, st;
    if (img->x_4mm != 0)
    {
        lidet__qpix_stored(img, p, v);
        return;
    }
    lidet__qpix_col(img, c, &ct, &st);
    lidet__qpix_decode(img->range_4mm[p], rt, ct, st, v);
}

/** x, y, z of pixel p (4 mm steps), stored or decoded; m26: lidet__q_row_m26 of the image (or 0), which
 *  the cores without a divide instruction use for the row */
static inline void lidet__qpix_xyz_m(const lidet_range_image_t *img, uint32_t p, uint32_t m26, int32_t v[3])
{
    uint32_t r;
    if (img->x_4mm != 0)
    {
        lidet__qpix_stored(img, p, v);
        return;
    }
#if !LIDET_Q_HAVE_DIV
    r = m26 != 0u ? (p * m26) >> 26 : p / img->n_cols;
#else
    (void)m26;
    r = p / img->n_cols;
#endif
    lidet__qpix_xyz_rc(img, lidet__qpix_row(img, r), p - r * img->n_cols, p, v);
}

/** x, y, z of pixel p (4 mm steps), stored or decoded */
static inline void lidet__qpix_xyz(const lidet_range_image_t *img, uint32_t p, int32_t v[3])
{
    lidet__qpix_xyz_m(img, p, 0u, v);
}

/** The tables of the rule for rows rows of elevations elev_bam and cols columns: row_trig 2 rows entries,
 *  col_trig 2 (cols / 4) entries (filled only when cols is a multiple of 4; returns 1 then, else 0) */
static inline int lidet__qpix_tables(const int32_t *elev_bam, uint32_t rows, uint32_t cols, int32_t *row_trig,
                                     int32_t *col_trig)
{
    uint32_t i;
    for (i = 0; i < rows; ++i)
    {
        row_trig[2u * i] = lidet__qpix_q15(lidet__q_cos((uint32_t)elev_bam[i]));
        row_trig[2u * i + 1u] = lidet__qpix_q15(lidet__q_sin((uint32_t)elev_bam[i]));
    }
    if (cols % 4u != 0u)
    {
        return 0;
    }
    for (i = 0; i < cols / 4u; ++i)
    {
        const uint32_t t = lidet__qpix_col_angle(i, cols);
        col_trig[2u * i] = lidet__qpix_q15(lidet__q_sin(t));
        col_trig[2u * i + 1u] = lidet__qpix_q15(lidet__q_cos(t));
    }
    return 1;
}

#endif /* LIDET_QPIX_H */
