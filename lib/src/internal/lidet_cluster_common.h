/* SPDX-License-Identifier: MIT */
/* What the float clustering (cluster/lidet_cluster.c, lidet_cluster_grow.c, lidet_cluster_rescue.c) and the
 * integer one (their _q twins) share that holds no number format: the pixel states, the queue push, the
 * candidates of a compact image, the flood fill's geometry constants, the per-point ids. Integer only (the
 * integer-only build compiles it). Never installed. */
#ifndef LIDET_CLUSTER_COMMON_H
#define LIDET_CLUSTER_COMMON_H

#include <stdint.h>

#include "lidet/lidet_types.h" /* lidet_member_t */
#include "lidet_qmath.h"       /* lidet__q_row_m26, LIDET_Q_HAVE_MUL64 */
#include "lidet_simd.h"        /* LIDET_HOST_SIMD */

/* pixel states in labels[] during a run (ids 1..LIDET_MAX_CLUSTERS are slots + 1) */
#define LAB_FREE 0u         /* a candidate not visited yet */
#define LAB_SMALL 0xFFFDu   /* a fragment (component below min_points) waiting for the rescue pass */
#define LAB_PENDING 0xFFFEu /* visited: current cluster, or a dropped one */
#define LAB_NONCAND 0xFFFFu /* no point, or ground: bridged over, never joined */

/* LIDET__LAB_WORDS: 1 where four labels are read as one 64-bit word (memcpy) in a few instructions: cores with
 * unaligned loads (x86, aarch64, Armv7-M and up); the label scans then skip four at a time. 0 on cores whose loads
 * must be aligned (ARMv6-M: memcpy of 8 bytes from a 2-byte aligned address is a call to the C library's memcpy,
 * about 60 instructions; RV32: 8 byte loads and 8 byte stores), where the scans read the labels one by one */
#if defined(__x86_64__) || defined(__i386__) || defined(__aarch64__) || defined(__ARM_FEATURE_UNALIGNED)
#define LIDET__LAB_WORDS 1
#else
#define LIDET__LAB_WORDS 0
#endif

#define STEPS LIDET_CLUSTER_MAX_STEPS
#define RESCUE_MAX_COLS                                                                                      \
    15u /* rescue_cols limit (each fragment pixel looks at (2 rows + 1)(2 cols + 1) pixels) */

/* Pushes pixel n onto the queue of the current cluster (members[tail]); returns the new tail. */
static inline uint32_t lidet__cluster_take(uint16_t *lab, lidet_member_t *mem, uint32_t tail, uint32_t n)
{
    lab[n] = (uint16_t)LAB_PENDING;
    mem[tail] = (int32_t)n;
    return tail + 1u;
}

/* Marks the candidates of a compact image in labels: FREE (0) or NONCAND (0xFFFF) = cand - 1 in 16 bits
 * (a pixel holding a point, range_4mm >= 1, that the ground mask, if any, does not mark); no branch, so
 * it vectorises. Returns their count. */
static inline uint32_t lidet__cluster_mark_4mm(const uint16_t *rng, const uint8_t *ground_mask, uint32_t npix,
                                               uint16_t *lab)
{
    uint32_t p, n_cand = 0;
    if (ground_mask == 0)
    {
        for (p = 0; p < npix; ++p)
        {
            const uint32_t cand = (uint32_t)(rng[p] > 0u);
            lab[p] = (uint16_t)(cand - 1u);
            n_cand += cand;
        }
        return n_cand;
    }
    for (p = 0; p < npix; ++p)
    {
        const uint32_t cand = (uint32_t)(rng[p] > 0u) & (uint32_t)(ground_mask[p] == 0u);
        lab[p] = (uint16_t)(cand - 1u);
        n_cand += cand;
    }
    return n_cand;
}

/* The geometry constants of one run's flood fill (the members of lidet__grow_t and of the integer stage's
 * lidet__grow_q_t, which share their names), from the image size and the configuration. The row of pixel q
 * without a division: floor(q * m / 2^32) with m = floor(2^32 / cols) + 1 is floor(q / cols) exactly when
 * q * cols < 2^32 (m exceeds 2^32 / cols by e in (0, 1], so the quotient is overestimated by q e / 2^32
 * < 1 / cols, less than the distance of q / cols to the next integer). q < npix, so npix * cols <= 2^32
 * suffices (128 x 2048: 2^29); else row_magic is 0 and the fill divides. On the cores without a 32 x 32 -> 64
 * multiply (LIDET_Q_HAVE_MUL64 0) that product is a library call or four 16-bit ones: there row_magic is
 * lidet__q_row_m26's m, the row (q m) >> 26 in 32 bits. */
#define LIDET__GROW_GEOMETRY(lk, n_rows, n_cols, cfg)                                                        \
    do                                                                                                       \
    {                                                                                                        \
        (lk).rows = (n_rows);                                                                                \
        (lk).cols = (n_cols);                                                                                \
        (lk).ks = (cfg).max_steps;                                                                           \
        (lk).kc = (lk).ks < (lk).cols - 1u ? (lk).ks : (lk).cols - 1u; /* never wrap onto itself */          \
        (lk).diag = (cfg).diagonals != 0;                                                                    \
        (lk).rrows = (cfg).rescue_rows;                                                                      \
        (lk).rcols = (cfg).rescue_cols < ((lk).cols - 1u) / 2u ? (cfg).rescue_cols : ((lk).cols - 1u) / 2u;  \
        (lk).row_magic = !LIDET_Q_HAVE_MUL64 ? lidet__q_row_m26((lk).rows, (lk).cols)                        \
                         : (uint64_t)(lk).rows * (lk).cols * (lk).cols <= 0xFFFFFFFFu                        \
                             ? (uint32_t)(0xFFFFFFFFu / (lk).cols) + 1u                                      \
                             : 0u;                                                                           \
    } while (0)

/* The rescue's verdict on window pixel n (label l) whose return lies within the rescue distance (dd its
 * squared distance, in the stage's units): a fragment pixel joins the group (queued), a kept pixel is a
 * contact (the nearest one wins, ties: the first met). For both stages' rescue_link / probe. */
#define LIDET__RESCUE_ACCEPT(c, rs, n, l, dd)                                                                \
    do                                                                                                       \
    {                                                                                                        \
        if ((l) == LAB_SMALL)                                                                                \
        {                                                                                                    \
            (c)->labels[n] = (uint16_t)LAB_PENDING;                                                          \
            (c)->members[(rs)->tail++] = (lidet_member_t)(n);                                                \
        }                                                                                                    \
        else if ((dd) < (rs)->best_d2)                                                                       \
        {                                                                                                    \
            (rs)->best_d2 = (dd);                                                                            \
            (rs)->best = (l);                                                                                \
        }                                                                                                    \
    } while (0)

/* Cluster id of every input point from the per-pixel ids (shared by both stages' point_labels). */
static inline void lidet__cluster_point_labels(const uint16_t *labels, uint32_t npix,
                                               const int32_t *point_pixel, uint32_t n_points, uint32_t *out)
{
    uint32_t i;
    for (i = 0; i < n_points; ++i)
    {
        const int32_t p = point_pixel[i];
        out[i] = (p >= 0 && (uint32_t)p < npix) ? labels[p] : 0u;
    }
}

#endif
