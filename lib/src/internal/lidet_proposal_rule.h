/* SPDX-License-Identifier: MIT */
/* The proposals' resampling rule (lidet_cluster.h), integer only: shared by the float proposals
 * (lidet_proposal.c) and the integer ones (lidet_proposal_q.c), so both take the same members. Mirrored by
 * codegen/lidet_ref/cluster.py: proposal_indices. Never installed. */
#ifndef LIDET_PROPOSAL_RULE_H
#define LIDET_PROPOSAL_RULE_H

#include <stdint.h>
#include <string.h>

#include "internal/lidet_rng.h"

/* the generator state of one cluster's resampling: the seed mixed with the member count, so clusters
 * of different sizes draw different streams; 0 (xorshift's only fixed point) is replaced by
 * LIDET_RNG_PROPOSAL_ZERO_SEED (the value the reference, lidet_ref/cluster.py, uses) */
static inline uint32_t lidet__proposal_rng_start(uint32_t seed, uint32_t n_src)
{
    const uint32_t s = seed ^ (n_src * 0x9E3779B9u);
    return s != 0 ? s : LIDET_RNG_PROPOSAL_ZERO_SEED;
}

/* member index of output i (0, 1, ... in order; *s is the generator state). n_src <= n_out: every
 * member once, then draws with replacement; else one member from each of n_out equal runs of the
 * member list (stratified, without replacement). */
static inline uint32_t lidet__proposal_next_index(uint32_t *s, uint32_t i, uint32_t n_src, uint32_t n_out)
{
    if (n_src <= n_out)
    {
        if (i < n_src)
        {
            return i;
        }
        return lidet__rng_next(s) % n_src;
    }
    {
        /* (i + 1) n_src < 2^32 for every real proposal (i < n_out <= 2^16, n_src <= 2^16): 32-bit divisions,
         * one instruction on a Cortex-M3/M4 instead of a 64-bit library call; the same quotients */
        const int small = n_src <= 0xFFFFu && n_out <= 0xFFFFu;
        const uint32_t b0 = small ? (i * n_src) / n_out : (uint32_t)(((uint64_t)i * n_src) / n_out);
        const uint32_t b1 =
            small ? ((i + 1u) * n_src) / n_out : (uint32_t)(((uint64_t)(i + 1u) * n_src) / n_out);
        return b0 + lidet__rng_next(s) % (b1 - b0); /* b1 > b0 because n_src > n_out */
    }
}

/* The rows a per-point network must see (lidet_pointnet.c, lidet_pointnet_q.c). A cluster of n_src < n_out
 * members gives a proposal whose rows n_src, ..., n_out - 1 repeat rows of the first n_src (the rule above).
 * A PointNet's shared layers see each row alone and the rows meet only in a maximum, which a repeated row
 * cannot change: the first n_src rows give the same result, bit for bit, at n_src / n_out of the cost (about a
 * third of the simulated VLP-16 proposals' rows). The repeats are checked, not assumed (a proposal filled by a
 * caller may hold anything): returns n_src where every later row equals one of the first n_src, else n_out.
 * ROW_EQ(i, j): rows i and j are equal (an exact comparison). */
#define LIDET__PROPOSAL_DISTINCT_ROWS(n_out, n_src, ROW_EQ, result)                                          \
    do                                                                                                       \
    {                                                                                                        \
        uint32_t pdr_i_, pdr_j_;                                                                             \
        (result) = (n_out);                                                                                  \
        if ((n_src) >= 1u && (n_src) < (n_out))                                                              \
        {                                                                                                    \
            for (pdr_i_ = (n_src); pdr_i_ < (n_out); ++pdr_i_)                                               \
            {                                                                                                \
                for (pdr_j_ = 0; pdr_j_ < (n_src) && !(ROW_EQ(pdr_i_, pdr_j_)); ++pdr_j_)                    \
                {                                                                                            \
                }                                                                                            \
                if (pdr_j_ == (n_src))                                                                       \
                {                                                                                            \
                    break; /* a row of its own: every row counts */                                          \
                }                                                                                            \
            }                                                                                                \
            (result) = pdr_i_ == (n_out) ? (n_src) : (n_out);                                                \
        }                                                                                                    \
    } while (0)

/* LIDET__PROPOSAL_DISTINCT_ROWS with a hash table of the first n_src rows: the same result for every input,
 * each later row compared only with the first rows in its bucket. ROW_HASH(i): row i's bucket (below
 * LIDET__PDR_BUCKETS), the same for any two rows ROW_EQ calls equal (a hash of the row's bits, where ROW_EQ
 * implies equal bits), so a row equal to one of the first n_src always meets it in its bucket; the rows
 * skipped are rows ROW_EQ would reject. Measured on the 17 real KITTI HDL-64 scans' proposals (64 rows; 130 a
 * scan with repeats, 41 repeated rows each): 9.6 row comparisons per repeated row by the linear search, 1.07
 * here; the float detector's distinct_rows 0.14 -> 0.03 ms a scan (perf). 383 B of stack; above
 * LIDET__PDR_MAX_SRC first rows (the links are uint8) the linear search runs. */
#define LIDET__PDR_BUCKETS 128u
/* a ROW_HASH for it: a row's bucket from the bits of its three coordinates (7 bits: LIDET__PDR_BUCKETS) */
static inline uint32_t lidet__proposal_row_hash(uint32_t a, uint32_t b, uint32_t c)
{
    return ((a ^ b * 0x85EBCA77u ^ c * 0xC2B2AE3Du) * 0x9E3779B1u) >> 25;
}
#define LIDET__PDR_MAX_SRC 255u
#define LIDET__PROPOSAL_DISTINCT_ROWS_HASHED(n_out, n_src, ROW_EQ, ROW_HASH, result)                         \
    do                                                                                                       \
    {                                                                                                        \
        uint8_t pdh_head_[LIDET__PDR_BUCKETS], pdh_next_[LIDET__PDR_MAX_SRC];                                \
        uint32_t pdh_i_, pdh_j_;                                                                             \
        if ((n_src) > LIDET__PDR_MAX_SRC)                                                                    \
        {                                                                                                    \
            LIDET__PROPOSAL_DISTINCT_ROWS(n_out, n_src, ROW_EQ, result);                                     \
            break;                                                                                           \
        }                                                                                                    \
        (result) = (n_out);                                                                                  \
        if ((n_src) >= 1u && (n_src) < (n_out))                                                              \
        {                                                                                                    \
            memset(pdh_head_, 0, sizeof pdh_head_);                                                          \
            for (pdh_j_ = 0; pdh_j_ < (n_src); ++pdh_j_) /* links: row + 1, 0 ends a bucket */               \
            {                                                                                                \
                const uint32_t pdh_h_ = (ROW_HASH(pdh_j_));                                                  \
                pdh_next_[pdh_j_] = pdh_head_[pdh_h_];                                                       \
                pdh_head_[pdh_h_] = (uint8_t)(pdh_j_ + 1u);                                                  \
            }                                                                                                \
            for (pdh_i_ = (n_src); pdh_i_ < (n_out); ++pdh_i_)                                               \
            {                                                                                                \
                for (pdh_j_ = pdh_head_[ROW_HASH(pdh_i_)]; pdh_j_ != 0u && !(ROW_EQ(pdh_i_, pdh_j_ - 1u));   \
                     pdh_j_ = pdh_next_[pdh_j_ - 1u])                                                        \
                {                                                                                            \
                }                                                                                            \
                if (pdh_j_ == 0u)                                                                            \
                {                                                                                            \
                    break; /* a row of its own: every row counts */                                          \
                }                                                                                            \
            }                                                                                                \
            (result) = pdh_i_ == (n_out) ? (n_src) : (n_out);                                                \
        }                                                                                                    \
    } while (0)

#endif
