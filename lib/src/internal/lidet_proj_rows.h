/* SPDX-License-Identifier: MIT */
/* What the float projection (lidet_proj.c) and the integer one (lidet_proj_q.c) share of their init, whatever the
 * number format: the image-shape check and the order of the beams top to bottom. */
#ifndef LIDET_PROJ_ROWS_H
#define LIDET_PROJ_ROWS_H

#include "lidet/lidet_types.h"

/** LIDET_ERR_CONFIG for 0 rows or fewer than 8 columns, LIDET_ERR_BUFFER beyond the compile-time capacity. */
static inline lidet_status_t lidet__proj_check_shape(uint32_t rows, uint32_t cols)
{
    if (rows == 0u || cols < 8u)
    {
        return LIDET_ERR_CONFIG;
    }
    if (rows > LIDET_MAX_ROWS || cols > LIDET_MAX_COLS)
    {
        return LIDET_ERR_BUFFER;
    }
    return LIDET_OK;
}

/** 1 when beam a is strictly above beam b (elev: the caller's table, in its own number format) */
typedef int (*lidet__beam_above_fn)(const void *elev, uint32_t a, uint32_t b);

/** ring_of_row[r] = the ring of image row r: the beams sorted top to bottom by a stable insertion sort (equal
 *  elevations keep ring order; the callers reject them). */
static inline void lidet__proj_rows_top_down(uint32_t rows, const void *elev, lidet__beam_above_fn above,
                                             uint8_t *ring_of_row)
{
    uint32_t r;
    for (r = 0; r < rows; ++r)
    {
        uint32_t j = r;
        while (j > 0 && above(elev, r, ring_of_row[j - 1]))
        {
            ring_of_row[j] = ring_of_row[j - 1];
            --j;
        }
        ring_of_row[j] = (uint8_t)r;
    }
}

#endif
