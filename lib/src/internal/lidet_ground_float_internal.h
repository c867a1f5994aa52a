/* SPDX-License-Identifier: MIT */
/* Shared between the float ground stage's two files, lidet_ground_filter.c and lidet_ground_ransac.c: the float
 * types (lidet_ground.h) and the RANSAC's entry. What they share with the integer stage is lidet_ground_internal.h;
 * the integer stage's counterpart of this header is lidet_ground_q_internal.h. Never installed. */
#ifndef LIDET_GROUND_FLOAT_INTERNAL_H
#define LIDET_GROUND_FLOAT_INTERNAL_H

#include "internal/lidet_ground_internal.h"
#include "lidet/lidet_ground.h"

/* Fits one plane per cell from the samples sc->sample_pix (pixels of img) grouped by sc->cell_first /
 * cell_n, applies the fallback, fills g->planes, g->source and the sector counts of g->stats
 * (lidet_ground_ransac.c). */
void lidet__ground_fit_sectors(lidet_ground_state_t *g, lidet_ground_scratch_t *sc,
                               const lidet_range_image_t *img);

#endif
