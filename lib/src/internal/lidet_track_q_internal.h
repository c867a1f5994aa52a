/* SPDX-License-Identifier: MIT */
/* The integer tracker's assignment (lib/src/track/lidet_track_q.c), declared for the bindings' tests
 * (ports/python/lidet_py_track_q.c) that check it alone against scipy and the numpy reference. */
#ifndef LIDET_TRACK_Q_INTERNAL_H
#define LIDET_TRACK_Q_INTERNAL_H

#include "lidet/lidet_track_q.h"

/* Assign the n_rows x n_cols costs in t->cost (row stride LIDET_TRACK_MAX_DETS; costs in [0, big], big: no pair)
 * with lidet_track_assign_t mode: t->row_col[r] = the column of row r, or -1 (no column, or only at cost big);
 * t->col_row the inverse. n_rows <= LIDET_TRACK_MAX_TRACKS, n_cols <= LIDET_TRACK_MAX_DETS, big < 2^31.
 * codegen/lidet_ref/track_q.py: hungarian, greedy. */
void lidet__track_q_assign(lidet_tracker_q_t *t, uint32_t n_rows, uint32_t n_cols, int32_t big,
                           uint32_t mode);

#endif
