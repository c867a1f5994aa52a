/* SPDX-License-Identifier: MIT */
/* Macro template: one pass over a component's members (member_stats_of): the sums, minima and maxima of their
 * x, y, z, stopped early when an extent exceeds the limit.
 *
 * Instantiated by (each #include once, after #defining the parameters below):
 *   lib/src/cluster/lidet_cluster.c    the float clustering: float values and float sums (STATS_BLOCK_SUMS 0);
 *                                     its member_stats calls the copy with `compact` a constant 0 or 1
 *   lib/src/cluster/lidet_cluster_q.c  the integer clustering: int32 values of the int16 pixels, int64 sums
 *                                     added from int32 block sums (STATS_BLOCK_SUMS 1)
 *
 * Parameters:
 *   STATS_STATE_T       the stage's state (members members, img)
 *   STATS_V_T           a coordinate (float, int32_t)
 *   STATS_S_T           a sum of coordinates (float, int64_t); zero-initialised scalars, kept in registers
 *   STATS_BLOCK_SUMS    1: each block of 64 members is summed in STATS_B_T, then added to the sum (the 64-bit
 *                       sums stay out of the member loop); 0: members are added to the sum directly (a float
 *                       sum's order unchanged)
 *   STATS_B_T           with STATS_BLOCK_SUMS 1 only: a block's sum (int32_t holds 64 int16 values exactly)
 *   STATS_LIM_T         the extent limit's type (float m, uint32_t mm)
 *   STATS_READ(c, p, compact, x, y, z)  pixel p's coordinates into *x, *y, *z (`compact` the float stage's
 *                       image format; the integer stage ignores it)
 *   STATS_OVER(lo, hi, lim)  nonzero when the extent hi - lo exceeds the limit
 * Defines: static inline int member_stats_of(const STATS_STATE_T *c, uint32_t start, uint32_t tail,
 * STATS_LIM_T max_extent, STATS_S_T sum[3], STATS_V_T lo[3], STATS_V_T hi[3], int compact).
 *
 * Why a template: the loop runs over every member of every component, and its two copies differ in the value
 * and sum types and in where the sums are taken; a C99 function can take neither type, and reading a pixel
 * through a function pointer would cost a call per member. The float sum must keep its order (the float
 * reference's sums) and the integer one must be exact: the template writes the loop once and lets each copy
 * keep its arithmetic.
 * Not a public header; include nowhere else. */

/* sums, min and max of the coordinates of members[start, tail) (tail > start). Returns 1 (the sums then
 * incomplete) as soon as an x, y or z extent exceeds max_extent: the test runs after every block of
 * 64 members, so a wall stops early instead of being summed to its end */
static inline int member_stats_of(const STATS_STATE_T *c, uint32_t start, uint32_t tail,
                                  STATS_LIM_T max_extent, STATS_S_T sum[3], STATS_V_T lo[3], STATS_V_T hi[3],
                                  int compact)
{
    const lidet_member_t *mem = c->members;
    (void)compact; /* read by the float stage's STATS_READ only */
    STATS_S_T sx = 0, sy = 0, sz = 0;
    STATS_V_T lx, ly, lz, hx, hy, hz;
    uint32_t i = start, over = 0;
    STATS_READ(c, (uint32_t)mem[start], compact, &lx, &ly, &lz);
    hx = lx;
    hy = ly;
    hz = lz;
    while (i < tail && over == 0u)
    {
        const uint32_t e = tail - i < 64u ? tail : i + 64u;
#if STATS_BLOCK_SUMS
        STATS_B_T bx = 0, by = 0, bz = 0;
#define STATS_ADD(b, s, v) ((b) += (v))
#else
#define STATS_ADD(b, s, v) ((s) += (v))
#endif
        for (; i < e; ++i)
        {
            STATS_V_T x, y, z;
            STATS_READ(c, (uint32_t)mem[i], compact, &x, &y, &z);
            STATS_ADD(bx, sx, x);
            STATS_ADD(by, sy, y);
            STATS_ADD(bz, sz, z);
            lx = x < lx ? x : lx;
            ly = y < ly ? y : ly;
            lz = z < lz ? z : lz;
            hx = x > hx ? x : hx;
            hy = y > hy ? y : hy;
            hz = z > hz ? z : hz;
        }
#if STATS_BLOCK_SUMS
        sx += bx;
        sy += by;
        sz += bz;
#endif
#undef STATS_ADD
        over = (uint32_t)STATS_OVER(lx, hx, max_extent) | (uint32_t)STATS_OVER(ly, hy, max_extent) |
               (uint32_t)STATS_OVER(lz, hz, max_extent);
    }
    sum[0] = sx;
    sum[1] = sy;
    sum[2] = sz;
    lo[0] = lx;
    lo[1] = ly;
    lo[2] = lz;
    hi[0] = hx;
    hi[1] = hy;
    hi[2] = hz;
    return over != 0u;
}
