/* SPDX-License-Identifier: MIT */
/* Shared between lidet_ground_q.c and lidet_ground_q_fit.c (never installed). */
#ifndef LIDET_GROUND_Q_INTERNAL_H
#define LIDET_GROUND_Q_INTERNAL_H

#include "lidet/lidet_ground_q.h"

/* R of a pixel in 4 mm / 2^LIDET_GROUND_Q_R_SHIFT steps (1/64 mm) */
#define LIDET_GROUND_Q_R_SHIFT 8
/* power iterations on the adjugate of the scatter matrix per refinement */
#define LIDET_GROUND_Q_POWER_ITERS 4
/* |c|^2 (4 mm steps, to the 4th) at or below this: a degenerate triple (the float stage's 1e-8 m^4) */
#define LIDET_GROUND_Q_MIN_CROSS2 39

/* Fits one plane per cell from the gathered samples, applies the fallback (lidet_ground_q_fit.c). */
void lidet__ground_q_fit_sectors(lidet_ground_q_state_t *g, lidet_ground_q_scratch_t *sc,
                                 const lidet_range_image_t *img);

#endif
