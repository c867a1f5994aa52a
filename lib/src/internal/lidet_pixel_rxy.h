/* SPDX-License-Identifier: MIT */
/* R (the horizontal range) of a row of a compact image's pixels, in one place for the two stages that make it:
 * the projection writes it when a compact image keeps R (lidet_proj_buffers_t rxy_m with x_4mm ...; the detector
 * workspace on hosts, LIDET_WORKSPACE_KEEP_R), the ground stage computes it row by row when the image has none.
 * The projection's expression (lidet__rxy) on the decoded 4 mm values: the same bits either way, so a stage's
 * results do not depend on which of them made it. Include only where it is called (a static function). */
#ifndef LIDET_PIXEL_RXY_INTERNAL_H
#define LIDET_PIXEL_RXY_INTERNAL_H

#include "lidet_math.h"
#include "lidet_pixel.h"
#include "lidet_simd.h"

/* out[c] = R of the decoded x[c], y[c] (4 mm steps); a streaming loop (AVX2 variant on x86-64 hosts) */
LIDET_CLONES_AVX2 static void lidet__rxy_4mm(const int16_t *x, const int16_t *y, uint32_t n, float *out)
{
    uint32_t c;
    for (c = 0; c < n; ++c)
    {
        out[c] = lidet__rxy(lidet__pix_m(x[c]), lidet__pix_m(y[c]));
    }
}

#endif
