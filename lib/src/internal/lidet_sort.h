/* SPDX-License-Identifier: MIT */
/* Deterministic in-place heapsort of (key, index) pairs by key, ties by index; no recursion, no allocation.
 * Integer keys, so both builds share it: the float detector sorts non-negative floats by their bit patterns
 * (monotonic for x >= 0), the integer detector its integer keys. */
#ifndef LIDET_SORT_H
#define LIDET_SORT_H

#include <stdint.h>

/** sort key[0..n) ascending, carrying idx along; equal keys in ascending idx order */
void lidet__sort_u32_u16(uint32_t *key, uint16_t *idx, uint32_t n);

/** the detectors' candidate order: sort key[0..n) (ties by idx), then keep the first `max`; each one past it
 *  gets outcome[idx] = code and is counted in *n_over. Returns the number kept (min(n, max)). */
uint32_t lidet__nearest_first(uint32_t *key, uint16_t *idx, uint32_t n, uint32_t max, uint8_t *outcome,
                              uint8_t code, uint32_t *n_over);

#endif
