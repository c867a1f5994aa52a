/* SPDX-License-Identifier: MIT */
/* xorshift32 (Marsaglia 2003, shifts 13, 17, 5): the one deterministic generator of every randomised
 * stage (the ground RANSAC, lidet_ground_ransac.c; the proposal resampling, lidet_proposal.c). Mirrored
 * bit for bit by codegen/lidet_ref/rng.py and lidet_ref/cluster.py. Never installed. */
#ifndef LIDET_RNG_H
#define LIDET_RNG_H

#include <stdint.h>

/* seed 0 would stay 0 forever: it is replaced by this fixed non-zero value */
#define LIDET_RNG_DEFAULT_SEED 0x9E3779B9u
/* the proposals' replacement for a zero start state ("ldet"; lidet_cluster.h documents the rule) */
#define LIDET_RNG_PROPOSAL_ZERO_SEED 0x6C646574u

static inline uint32_t lidet__rng_seed(uint32_t seed)
{
    return seed != 0u ? seed : LIDET_RNG_DEFAULT_SEED;
}

/* a 32-bit mix (the finaliser of MurmurHash3) of seed and k: seed ^ (k * 0x9E3779B9), then a bijection, so for one
 * seed two values of k never give the same result */
static inline uint32_t lidet__rng_mix(uint32_t seed, uint32_t k)
{
    uint32_t h = seed ^ (k * 0x9E3779B9u);
    h ^= h >> 16;
    h *= 0x85EBCA6Bu;
    h ^= h >> 13;
    h *= 0xC2B2AE35u;
    h ^= h >> 16;
    return h;
}

/* the start state of cell k of a stage seeded with seed: the mix of both, so every cell draws from a stream of its
 * own, whatever the other cells held */
static inline uint32_t lidet__rng_cell(uint32_t seed, uint32_t k)
{
    return lidet__rng_seed(lidet__rng_mix(seed, k));
}

/* advances *state and returns the new value (never 0 for a non-zero state) */
static inline uint32_t lidet__rng_next(uint32_t *state)
{
    uint32_t x = *state;
    x ^= x << 13;
    x ^= x >> 17;
    x ^= x << 5;
    *state = x;
    return x;
}

/* uniform-ish integer in [0, n), n >= 1: the high 32 bits of x * n (no division, bias < n / 2^32) */
static inline uint32_t lidet__rng_below(uint32_t *state, uint32_t n)
{
    return (uint32_t)(((uint64_t)lidet__rng_next(state) * (uint64_t)n) >> 32);
}

#endif
