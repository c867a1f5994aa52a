/* SPDX-License-Identifier: MIT */
/* Shared between lidet_ground_filter.c and lidet_ground_ransac.c (never installed). */
#ifndef LIDET_GROUND_INTERNAL_H
#define LIDET_GROUND_INTERNAL_H

#include "lidet/lidet_ground.h"

/* first column of sector s: the smallest c with c * n_sectors / n_cols >= s */
static inline uint32_t lidet__ground_sector_col(uint32_t s, uint32_t n_sectors, uint32_t n_cols)
{
    return (s * n_cols + n_sectors - 1u) / n_sectors;
}

/* Fits one plane per cell from the samples sc->sample_pix (pixels of img) grouped by sc->cell_first /
 * cell_n, applies the fallback, fills g->planes, g->source and the sector counts of g->stats
 * (lidet_ground_ransac.c). */
void lidet__ground_fit_sectors(lidet_ground_state_t *g, lidet_ground_scratch_t *sc, const lidet_range_image_t *img);

#endif
