/* SPDX-License-Identifier: MIT */
/* The fragment rescue's window walk, written once for the float stage (lidet_cluster_rescue.c) and the
 * integer one (lidet_cluster_rescue_q.c), each of which includes this file once. Parameters:
 *   RESCUE_STATE_T, RESCUE_PARAM_T, RESCUE_RS_T  the state, the run's constants, the group's running state;
 *   RESCUE_WIN_T, RESCUE_WIN_SET(c, win, q, g, compact)  what the stage derives from group pixel q before its
 *                window is looked at (its range and the range bounds of a possible partner);
 *   RESCUE_PROBE(c, rs, lab, n, win, g, compact)  the test of window pixel n (joins or records a contact).
 * `compact` is the float stage's image format (a constant per copy); the integer stage ignores it.
 * Not a public header; include nowhere else. */

/* Breadth-first fill of the rescue group seeded at members[start]. Around each member q it looks at
 * every pixel of the window rescue_rows rows up and down and rescue_cols columns left and right
 * (wrapping), row by row from the top left, q itself excepted. Four labels at a time (a 64-bit
 * word) are skipped when all are LAB_PENDING or LAB_NONCAND (0xFFFE, 0xFFFF: the only labels with
 * every bit but the lowest set). Fragments are few (hundreds of pixels per scan), windows small. */
static inline void rescue_grow(RESCUE_STATE_T *c, const RESCUE_PARAM_T *g, uint32_t start, RESCUE_RS_T *rs,
                               int compact)
{
    const lidet_member_t *mem = c->members;
    const uint16_t *lab = c->labels;
    const uint32_t rows = g->rows, cols = g->cols, wr = g->rrows, wc = g->rcols;
    uint32_t head = start;
    while (head < rs->tail)
    {
        const uint32_t q = (uint32_t)mem[head++];
        const uint32_t r = q / cols, col = q - r * cols;
        const uint32_t r0 = r >= wr ? r - wr : 0u, r1 = r + wr < rows ? r + wr : rows - 1u;
        const uint32_t c0 = col >= wc ? col - wc : col + cols - wc; /* 2 wc < cols: none repeats */
        RESCUE_WIN_T win;
        uint32_t rr, k;
        RESCUE_WIN_SET(c, &win, q, g, compact);
        LIDET_ASSERT(rs->tail <= rows * cols);
        for (rr = r0; rr <= r1; ++rr)
        {
            const uint32_t base = rr * cols;
            if (c0 + 2u * wc < cols)
            {
                const uint32_t end = base + c0 + 2u * wc + 1u;
                uint32_t n = base + c0;
                for (; n + 4u <= end; n += 4u)
                {
                    uint64_t w4;
                    memcpy(&w4, &lab[n], sizeof w4);
                    if ((w4 | 0x0001000100010001u) != 0xFFFFFFFFFFFFFFFFu)
                    {
                        RESCUE_PROBE(c, rs, lab, n, &win, g, compact);
                        RESCUE_PROBE(c, rs, lab, n + 1u, &win, g, compact);
                        RESCUE_PROBE(c, rs, lab, n + 2u, &win, g, compact);
                        RESCUE_PROBE(c, rs, lab, n + 3u, &win, g, compact);
                    }
                }
                for (; n < end; ++n)
                {
                    RESCUE_PROBE(c, rs, lab, n, &win, g, compact);
                }
            }
            else
            {
                uint32_t cc = c0;
                for (k = 0; k <= 2u * wc; ++k)
                {
                    RESCUE_PROBE(c, rs, lab, base + cc, &win, g, compact);
                    cc = cc + 1u < cols ? cc + 1u : 0u;
                }
            }
        }
    }
}
