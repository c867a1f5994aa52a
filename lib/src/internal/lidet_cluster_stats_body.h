/* SPDX-License-Identifier: MIT */
/* One pass over a component's members, written once for the float clustering (lidet_cluster.c: float values
 * and sums) and the integer one (lidet_cluster_q.c: int32 values of the int16 pixels, int64 sums), each of which
 * includes this file once. Parameters: STATS_STATE_T (the state: members, img), STATS_V_T (a coordinate),
 * STATS_S_T (a sum; zero-initialised scalars, kept in registers), STATS_B_T (the sum of one block of 64 members,
 * added to the sum after the block: the integer stage's int32, which holds 64 int16 values exactly and keeps the
 * 64-bit sums out of the member loop; the float stage's STATS_S_T itself, a float sum's order unchanged: it
 * accumulates into the sum directly), STATS_LIM_T (the extent limit),
 * STATS_READ(c, p, compact, x, y, z) (pixel p's coordinates; `compact` the float stage's image format, a
 * constant per copy), STATS_OVER(lo, hi, lim) (an extent above the limit). Not a public header. */

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
