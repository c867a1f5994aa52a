/* SPDX-License-Identifier: MIT */
/* Macro template: the fragment rescue's window walk (rescue_grow): the breadth-first fill of one rescue group,
 * looking at every pixel of each member's window, four labels at a time where they can be skipped.
 *
 * Instantiated by (each #include once, after #defining the parameters below):
 *   lib/src/cluster/lidet_cluster_rescue.c    the float stage: lidet_cluster_state_t, lidet__grow_t,
 *                                            lidet__rescue_t; windows window_t (float ranges, m or 4 mm steps)
 *   lib/src/cluster/lidet_cluster_rescue_q.c  the integer stage: lidet_cluster_q_state_t, lidet__grow_q_t,
 *                                            lidet__rescue_q_t; windows window_q_t (integer 4 mm steps)
 *
 * Parameters:
 *   RESCUE_STATE_T      the stage's state (members members, labels)
 *   RESCUE_PARAM_T      the run's constants (rows, cols, rrows, rcols: the window's half height and width)
 *   RESCUE_RS_T         the group's running state (member tail; the nearest contact)
 *   RESCUE_WIN_T        what the stage derives from a group pixel before its window is looked at
 *   RESCUE_WIN_SET(c, win, q, g, compact)  fill *win from group pixel q (its range, the bounds of a partner's)
 *   RESCUE_PROBE(c, rs, lab, n, win, g, compact)  the test of window pixel n: it joins the group, is recorded
 *                       as a contact, or is passed over
 *   RESCUE_ROW(c, rs, lab, b, e, win, g, compact)  optional (a copy with SIMD): the probes of window pixels
 *                       [b, e) of one row, in order; nonzero when it made them (else the loop below does)
 * `compact` is the float stage's image format (a constant in each of its calls); the integer stage ignores it.
 * Also read, from lidet_cluster_common.h: LAB_PENDING, LAB_NONCAND.
 * Defines: static inline void rescue_grow(RESCUE_STATE_T *c, const RESCUE_PARAM_T *g, uint32_t start,
 * RESCUE_RS_T *rs, int compact), called by the includer's entry point (lidet__cluster_rescue_grow,
 * lidet__cluster_q_rescue_grow).
 *
 * Why a template: the two stages' states, windows and distance tests are different types (float ranges and
 * coordinates, or integer 4 mm steps), which no C99 function can take at once; RESCUE_PROBE runs once per window
 * pixel, so a function pointer would cost an indirect call per pixel and keep the float stage's `compact` test in
 * the loop. The template keeps one walk (the same pixels in the same order, so the same first contact on
 * ties, as both references, codegen/lidet_ref/cluster.py and cluster_q.py, require) with each stage's test
 * inlined.
 * Not a public header; include nowhere else. */

/* Breadth-first fill of the rescue group seeded at members[start]. Around each member q it looks at
 * every pixel of the window rescue_rows rows up and down and rescue_cols columns left and right
 * (wrapping), row by row from the top left, q itself excepted. Where LIDET__LAB_WORDS, four labels at a
 * time (a 64-bit word) are skipped when all are LAB_PENDING or LAB_NONCAND (0xFFFE, 0xFFFF: the only labels
 * with every bit but the lowest set); elsewhere each label is read alone. Fragments are few (hundreds of pixels
 * per scan), windows small. */
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
#ifdef RESCUE_ROW
                if (RESCUE_ROW(c, rs, lab, n, end, &win, g, compact))
                {
                    continue; /* the row's probes made, in the same order */
                }
#endif
                for (; LIDET__LAB_WORDS && n + 4u <= end; n += 4u)
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
                    /* one label at a time (all of them where !LIDET__LAB_WORDS): the probe only where it can do
                     * anything there (the label read inline; the probe may be a call) */
                    if (LIDET__LAB_WORDS || lab[n] < LAB_PENDING)
                    {
                        RESCUE_PROBE(c, rs, lab, n, &win, g, compact);
                    }
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
