/* SPDX-License-Identifier: MIT */
/* Deterministic in-place heapsort of (key, index) pairs by key, ties by index; no recursion, no allocation.
 * Integer keys, so both builds share it: the float detector sorts non-negative floats by their bit patterns
 * (monotonic for x >= 0), the integer detector its integer keys. */
#ifndef LIDET_SORT_H
#define LIDET_SORT_H

#include <stdint.h>

/** sort key[0..n) ascending, carrying idx along; equal keys in ascending idx order */
void lidet__sort_u32_u16(uint32_t *key, uint16_t *idx, uint32_t n);

#endif
