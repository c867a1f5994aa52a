/* SPDX-License-Identifier: MIT */
/* The proposals' resampling rule (lidet_cluster.h), integer only: shared by the float proposals
 * (lidet_proposal.c) and the integer ones (lidet_proposal_q.c), so both take the same members. Mirrored by
 * codegen/lidet_ref/cluster.py: proposal_indices. Never installed. */
#ifndef LIDET_PROPOSAL_RULE_H
#define LIDET_PROPOSAL_RULE_H

#include <stdint.h>
#include <string.h>

#include "internal/lidet_rng.h"
#include "lidet/lidet_types.h" /* lidet_member_t */

/* the generator state of one cluster's resampling: the seed mixed with the member count, so clusters
 * of different sizes draw different streams; 0 (xorshift's only fixed point) is replaced by
 * LIDET_RNG_PROPOSAL_ZERO_SEED (the value the reference, lidet_ref/cluster.py, uses) */
static inline uint32_t lidet__proposal_rng_start(uint32_t seed, uint32_t n_src)
{
    const uint32_t s = seed ^ (n_src * 0x9E3779B9u);
    return s != 0 ? s : LIDET_RNG_PROPOSAL_ZERO_SEED;
}

/* member index of output i (0, 1, ... in order; *s is the generator state) of a cluster of n_src <= n_out
 * members: every member once, then draws with replacement (a larger cluster: lidet__proposal_pick) */
static inline uint32_t lidet__proposal_next_index(uint32_t *s, uint32_t i, uint32_t n_src)
{
    if (i < n_src)
    {
        return i;
    }
    return lidet__rng_next(s) % n_src;
}

/* The strata of a cluster of n_src > n_out members: stratum i is members b_i .. b_{i+1} - 1 with
 * b_i = floor(i n_src / n_out), walked without a division per stratum: with n_src = q n_out + r,
 * b_{i+1} = b_i + q, plus one when the running remainder (i + 1) r mod n_out wraps (the same integers; two
 * divisions per cluster, where a Cortex-M0+ has no divide instruction). */
typedef struct
{
    uint32_t b, q, r, acc, n_out;
} lidet__strata_t;

/* s->b = b_0 = 0 */
static inline void lidet__strata_init(lidet__strata_t *s, uint32_t n_src, uint32_t n_out)
{
    s->b = 0;
    s->q = n_src / n_out;
    s->r = n_src % n_out;
    s->acc = 0;
    s->n_out = n_out;
}

/* from b_i to b_{i+1}; returns it */
static inline uint32_t lidet__strata_next(lidet__strata_t *s)
{
    s->b += s->q;
    s->acc += s->r;
    if (s->acc >= s->n_out)
    {
        s->acc -= s->n_out;
        s->b += 1u;
    }
    return s->b;
}

/* The key of member pixel p in the draw seeded with seed: MurmurHash3's 32-bit finaliser of seed ^ (p times
 * the golden ratio), a bijection of p, so two pixels never tie. A cluster of n_src > n_out members takes from
 * each stratum [b_i, b_{i+1}) the member whose pixel has the smallest key: the pick depends on the pixels
 * themselves, not on how many members the cluster has or where the stratum starts, so two clusters that
 * differ by a pixel or two (the float and integer projections, a pixel that changes hands) take the same
 * points in all but the strata those pixels touch. */
static inline uint32_t lidet__proposal_key(uint32_t seed, uint32_t p)
{
    return lidet__rng_mix(seed, p);
}

/* the member of stratum [b0, b1) (b1 > b0) of the member list mem whose pixel has the smallest key; and the n_out
 * member indices of a cluster whose n_src members are mem[0 .. n_src - 1] (lidet_proposal_q.c, in the float and the
 * integer-only library) */
uint32_t lidet__proposal_pick(const lidet_member_t *mem, uint32_t b0, uint32_t b1, uint32_t seed);
void lidet__proposal_indices_of(const lidet_member_t *mem, uint32_t n_src, uint32_t n_out, uint32_t seed,
                                uint32_t *idx);

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
