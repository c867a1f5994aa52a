/* SPDX-License-Identifier: MIT */
/* Macro template: the clustering's flood fill (the stage's hot loop): the directional searches with hole and
 * occluder bridging and the breadth-first fill that calls them, written once for every image format and
 * arithmetic.
 *
 * Instantiated by (each #include after #defining the parameters below; #undef between two copies):
 *   lib/src/cluster/lidet_cluster_grow.c    twice: a float image (GROW_RNG_T float, GROW_D_T float, GROW_LINK
 *                                          link, names *_m) and a compact one (GROW_RNG_T uint16_t, GROW_D_T
 *                                          uint32_t, GROW_LINK link_4mm: ranges in 4 mm steps read and ordered
 *                                          as integers, converted exactly for the float test, names *_4mm);
 *                                          tables GROW_TAB_T float
 *   lib/src/cluster/lidet_cluster_grow_q.c  once, the integer stage: GROW_RNG_T uint16_t, GROW_D_T uint32_t,
 *                                          GROW_TAB_T uint32_t, GROW_LINK link_q, names *_q
 *
 * Parameters:
 *   GROW_RNG_T          the range plane's element type
 *   GROW_RANGES(img)    the range plane of image img
 *   GROW_D_T            the type a range is read as: the join test's argument ((GROW_D_T)rng[n])
 *   GROW_TAB_T          the element type of the join test's two angle tables
 *   GROW_TA(c, t)       table A of kind t (col, row, diag) of state c: float sin(alpha), or the integer
 *                       stage's sin(alpha + theta)
 *   GROW_TB(c, t)       table B of that kind: float cos(alpha), or the integer stage's 4 sin^2(alpha / 2)
 *   GROW_LINK(da, db, ta, tb, g)  the join test of two ranges with one entry of each table, nonzero to join
 *   GROW_STATE_T        the stage's state (members labels, members, img and the tables; same names in both)
 *   GROW_PARAM_T        the run's constants (rows, cols, ks, kc, diag, row_magic, bridged, bridge_max)
 *   GROW_FN(name)       the copy's name of function `name` (a suffix per copy)
 *   GROW_NEIGHBOURS(c, g, q, r, dq, occl, take, redo, nonc)  optional (a copy with SIMD): for a pixel away
 *                       from the edges (kc >= 2), the first step of each search (right, left, down, up: bits 0-3)
 *                       and the diagonals (bits 4-7; none without the 8-neighbourhood) decided at once: *take
 *                       the pixels that join there, *redo the searches their first step does not end (a
 *                       non-candidate; with the occluder rule a nearer candidate that fails the test: an
 *                       occluder), *nonc those whose first step is a non-candidate
 *   GROW_POP4(m)        with GROW_NEIGHBOURS: the number of bits set in the 4-bit mask m
 *   GROW_SEARCH4(lab, mem, rng, tail, dq, n0, step, nk, sn, cs, gs, g)  optional, with GROW_NEIGHBOURS: the
 *                       occluder rule's search of at most 4 steps from pixel n0 (its first step; tables sn, cs
 *                       at that step), the same joins and bridged count as GROW_FN(search); the SIMD path
 *                       runs the searches past their first step with it (GROW_FN(search_rest))
 *   GROW_TEST_EVERY     1: the occluder rule's search tests every candidate it meets, for copies whose test
 *                       has no branch of its own (it saves one on the label); 0: a visited candidate is tested
 *                       only when that decides (the float image's copy, whose test orders two floats with a
 *                       branch: measured slower the other way). The same joins either way
 * Also read, from lidet_cluster_common.h: LAB_FREE, LAB_NONCAND, STEPS, lidet__cluster_take. The compact float
 * copy (lidet_cluster_grow.c) defines GROW_NEIGHBOURS and GROW_SEARCH4 on SSE2 hosts; the others run the
 * searches as written.
 * Defines: static GROW_FN(search), GROW_FN(search_wrap), GROW_FN(diagonals), GROW_FN(expand) (one pixel's searches, the occluder
 * rule a constant) and GROW_FN(grow) (the fill; forced inline: the includer wraps it in a function of its own,
 * lidet_cluster_grow.c one per image format with the rule an argument, lidet_cluster_grow_q.c one per rule with
 * the rule a constant: the forms measured fastest on an x86-64 host and on the Cortex-M4 respectively).
 *
 * Why a template: C99 has no generic functions, and the three copies differ in the innermost loop (the range
 * type, the test, the tables). A function taking the test as a function pointer or switching on the format
 * would pay an indirect call or a branch per neighbour looked at; each copy here compiles to the code written
 * for its types (the float copy is exactly the code the float stage had before the compact image, the reads a
 * no-op cast), so none pays for another, and the three keep one control flow (the same joins in the same
 * order, which the tests against codegen/lidet_ref/cluster.py and cluster_q.py rely on).
 * Not a public header; include nowhere else. */

/* One directional search from q (range dq): pixels q + k * step, k = 1..nk, never wrapping (the
 * caller sends the columns within kc of either edge to search_wrap); beam pair sin/cos at
 * sn[(k - 1) * gs], cs[(k - 1) * gs]. Non-candidates are stepped over. */
static inline uint32_t GROW_FN(search)(uint16_t *lab, lidet_member_t *mem, const GROW_RNG_T *rng,
                                       uint32_t tail, GROW_D_T dq, uint32_t q, int32_t step, uint32_t nk,
                                       const GROW_TAB_T *sn, const GROW_TAB_T *cs, int32_t gs,
                                       const GROW_PARAM_T *g, int occl)
{
    uint32_t k, n = q;
    if (!occl)
    {
        /* the search stops at the first candidate whatever it is: find it, then test it only when
         * free (nk >= 1; k ends at the step of that candidate, or at nk - 1 on a non-candidate) */
        uint32_t l;
        k = 0;
        for (;;)
        {
            n = (uint32_t)((int32_t)n + step);
            l = lab[n];
            if (l != LAB_NONCAND || ++k >= nk)
            {
                break;
            }
        }
        if (l == LAB_FREE && GROW_LINK(dq, (GROW_D_T)rng[n], sn[(int32_t)k * gs], cs[(int32_t)k * gs], g))
        {
            tail = lidet__cluster_take(lab, mem, tail, n);
        }
        return tail;
    }
    for (k = 0; k < nk; ++k, sn += gs, cs += gs)
    {
        uint32_t l;
        n = (uint32_t)((int32_t)n + step);
        l = lab[n];
        if (l == LAB_NONCAND)
        {
            continue;
        }
        /* occluder bridging: a free candidate that passes the test joins, and the search ends; one
         * that fails it, or a visited one, ends the search unless it is nearer than q and fails the
         * test (an occluder: the search goes on behind it). */
        const GROW_D_T dn = (GROW_D_T)rng[n];
#if GROW_TEST_EVERY
        /* So any candidate ends the search when it passes the test or is not nearer, and joins when also
         * free: the test made once whatever the label, a branch fewer on data that mispredicts (joining a
         * visited one would change nothing) */
        const int linked = GROW_LINK(dq, dn, *sn, *cs, g);
        if (linked & (l == LAB_FREE))
        {
            tail = lidet__cluster_take(lab, mem, tail, n);
        }
        if (linked | !(dn < dq))
        {
            break;
        }
#else
        /* A visited candidate is only tested when that decides between the two */
        if (l == LAB_FREE)
        {
            if (GROW_LINK(dq, dn, *sn, *cs, g))
            {
                tail = lidet__cluster_take(lab, mem, tail, n);
                break;
            }
            if (!(dn < dq))
            {
                break;
            }
        }
        else if (!(dn < dq) || GROW_LINK(dq, dn, *sn, *cs, g))
        {
            break;
        }
#endif
        ++*g->bridged; /* stepped over an occluder (the run's bridging budget, bridge_max) */
    }
    return tail;
}

/* The same along a row across the wrap (the rare columns within kc of either edge): step k meets
 * rowbase + (col +- k mod cols); angle tables GROW_TA/GROW_TB(c, col) */
static uint32_t GROW_FN(search_wrap)(GROW_STATE_T *c, uint32_t tail, GROW_D_T dq, uint32_t rowbase,
                                     uint32_t col, int right, const GROW_PARAM_T *g, int occl)
{
    uint16_t *lab = c->labels;
    lidet_member_t *mem = c->members;
    const GROW_RNG_T *rng = GROW_RANGES(&c->img);
    const uint32_t cols = g->cols;
    uint32_t k;
    for (k = 1; k <= g->kc; ++k)
    {
        const uint32_t cc =
            right ? (col + k >= cols ? col + k - cols : col + k) : (col >= k ? col - k : col + cols - k);
        const uint32_t n = rowbase + cc;
        const uint32_t l = lab[n];
        if (l == LAB_NONCAND)
        {
            continue;
        }
        const GROW_D_T dn = (GROW_D_T)rng[n];
        const GROW_TAB_T sn = GROW_TA(c, col)[k - 1], cs = GROW_TB(c, col)[k - 1];
        if (l == LAB_FREE && GROW_LINK(dq, dn, sn, cs, g))
        {
            tail = lidet__cluster_take(lab, mem, tail, n); /* joins, and the search ends */
            break;
        }
        /* without occluder bridging any candidate ends the search; with it, one nearer than q that
         * fails the test is stepped over (as in search) */
        if (!occl || !(dn < dq) || (l != LAB_FREE && GROW_LINK(dq, dn, sn, cs, g)))
        {
            break;
        }
        ++*g->bridged;
    }
    return tail;
}

/* The diagonals of pixel (r, col) (8-neighbourhood option): direct neighbours only, no bridging; each joins when
 * free and linked (down-left, down-right, up-left, up-right). Returns the new tail. */
#if defined(__GNUC__)
__attribute__((always_inline))
#endif
static inline uint32_t
GROW_FN(diagonals)(GROW_STATE_T *c, const GROW_PARAM_T *g, uint32_t tail, uint32_t r, uint32_t col,
                   uint32_t rowbase, GROW_D_T dq)
{
    uint16_t *lab = c->labels;
    lidet_member_t *mem = c->members;
    const GROW_RNG_T *rng = GROW_RANGES(&c->img);
    const uint32_t rows = g->rows, cols = g->cols;
    const uint32_t cl = col > 0u ? col - 1u : cols - 1u, cr = col + 1u < cols ? col + 1u : 0u;
    if (r + 1u < rows)
    {
        const uint32_t dl = rowbase + cols + cl, dr = rowbase + cols + cr;
        if (lab[dl] == LAB_FREE &&
            GROW_LINK(dq, (GROW_D_T)rng[dl], GROW_TA(c, diag)[r], GROW_TB(c, diag)[r], g))
        {
            tail = lidet__cluster_take(lab, mem, tail, dl);
        }
        if (lab[dr] == LAB_FREE &&
            GROW_LINK(dq, (GROW_D_T)rng[dr], GROW_TA(c, diag)[r], GROW_TB(c, diag)[r], g))
        {
            tail = lidet__cluster_take(lab, mem, tail, dr);
        }
    }
    if (r > 0u)
    {
        const uint32_t ul = rowbase - cols + cl, ur = rowbase - cols + cr;
        if (lab[ul] == LAB_FREE &&
            GROW_LINK(dq, (GROW_D_T)rng[ul], GROW_TA(c, diag)[r - 1u], GROW_TB(c, diag)[r - 1u], g))
        {
            tail = lidet__cluster_take(lab, mem, tail, ul);
        }
        if (lab[ur] == LAB_FREE &&
            GROW_LINK(dq, (GROW_D_T)rng[ur], GROW_TA(c, diag)[r - 1u], GROW_TB(c, diag)[r - 1u], g))
        {
            tail = lidet__cluster_take(lab, mem, tail, ur);
        }
    }
    return tail;
}

#ifdef GROW_NEIGHBOURS
/* A search of the SIMD path (GROW_NEIGHBOURS) from its second step: GROW_SEARCH4 where the copy has it (the
 * occluder rule, at most four steps), else GROW_FN(search) */
#if defined(__GNUC__)
__attribute__((always_inline))
#endif
static inline uint32_t
GROW_FN(search_rest)(uint16_t *lab, lidet_member_t *mem, const GROW_RNG_T *rng, uint32_t tail, GROW_D_T dq,
                     uint32_t n0, int32_t step, uint32_t nk, const GROW_TAB_T *sn, const GROW_TAB_T *cs,
                     int32_t gs, const GROW_PARAM_T *g, int occl)
{
#ifdef GROW_SEARCH4
    if (occl && nk <= 4u)
    {
        return GROW_SEARCH4(lab, mem, rng, tail, dq, n0, step, nk, sn, cs, gs, g);
    }
#endif
    return GROW_FN(search)(lab, mem, rng, tail, dq, n0 - (uint32_t)step, step, nk, sn, cs, gs, g, occl);
}
#endif

/* The searches from pixel q (row r) in the reference's order: right, left, down, up, then the diagonals
 * down-left, down-right, up-left, up-right. occl is a constant at each call site (forced inline: each copy is
 * compiled for its own rule, with no test of the rule per search). Returns the new tail. */
#if defined(__GNUC__)
__attribute__((always_inline))
#endif
static inline uint32_t
GROW_FN(expand)(GROW_STATE_T *c, const GROW_PARAM_T *g, uint32_t tail, uint32_t q, uint32_t r, int occl)
{
    uint16_t *lab = c->labels;
    lidet_member_t *mem = c->members;
    const GROW_RNG_T *rng = GROW_RANGES(&c->img);
    const uint32_t rows = g->rows, cols = g->cols, ks = g->ks, kc = g->kc;
    const uint32_t rowbase = r * cols, col = q - rowbase;
    const GROW_D_T dq = (GROW_D_T)rng[q];
    const uint32_t nd = rows - 1u - r < ks ? rows - 1u - r : ks; /* steps that stay in the image */
    const uint32_t nu = r < ks ? r : ks;
#ifdef GROW_NEIGHBOURS
    /* a pixel away from the image's edges (no wrap, a row above and below): the first step of the four
     * searches and the four diagonals decided at once (GROW_NEIGHBOURS, the same tests); a search is run only
     * where its first step does not end it (a non-candidate, or an occluder to step over), from its second
     * step. The pixels looked at here are distinct, and no search reaches another search's or a diagonal's,
     * so deciding them first changes nothing; the joins keep the order right, left, down, up, then the
     * diagonals down-left, down-right, up-left, up-right (the same members in the same order) */
    if (r > 0u && r + 1u < rows && kc >= 2u && col >= kc && col + kc < cols)
    {
        uint32_t take, redo, nonc; /* bits: right, left, down, up, down-left, down-right, up-left, up-right */
        GROW_NEIGHBOURS(c, g, q, r, dq, occl, &take, &redo, &nonc);
        if ((take | redo) == 0u)
        {
            return tail; /* nothing joins, no search goes on */
        }
        /* a search that goes on past its first step goes on from its second: a first step that is an occluder
         * counted here as the search would (a non-candidate is not), the search run over the steps after it
         * (down and up: their table entries from the second, [r * STEPS + 1] and [(r - 2) * STEPS + 1]) */
        *g->bridged += GROW_POP4(redo & ~nonc);
        if (redo & 1u)
        {
            tail = GROW_FN(search_rest)(lab, mem, rng, tail, dq, q + 2u, 1, kc - 1u, GROW_TA(c, col) + 1,
                                        GROW_TB(c, col) + 1, 1, g, occl);
        }
        else if (take & 1u)
        {
            tail = lidet__cluster_take(lab, mem, tail, q + 1u);
        }
        if (redo & 2u)
        {
            tail = GROW_FN(search_rest)(lab, mem, rng, tail, dq, q - 2u, -1, kc - 1u, GROW_TA(c, col) + 1,
                                        GROW_TB(c, col) + 1, 1, g, occl);
        }
        else if (take & 2u)
        {
            tail = lidet__cluster_take(lab, mem, tail, q - 1u);
        }
        if ((redo & 4u) && nd > 1u)
        {
            tail = GROW_FN(search_rest)(lab, mem, rng, tail, dq, q + 2u * cols, (int32_t)cols, nd - 1u,
                                        GROW_TA(c, row) + r * STEPS + 1, GROW_TB(c, row) + r * STEPS + 1, 1,
                                        g, occl);
        }
        else if (take & 4u)
        {
            tail = lidet__cluster_take(lab, mem, tail, q + cols);
        }
        if ((redo & 8u) && nu > 1u)
        {
            tail = GROW_FN(search_rest)(lab, mem, rng, tail, dq, q - 2u * cols, -(int32_t)cols, nu - 1u,
                                        GROW_TA(c, row) + (r - 2u) * STEPS + 1,
                                        GROW_TB(c, row) + (r - 2u) * STEPS + 1, 1 - STEPS, g, occl);
        }
        else if (take & 8u)
        {
            tail = lidet__cluster_take(lab, mem, tail, q - cols);
        }
        if (take & 0xF0u)
        {
            if (take & 0x10u)
            {
                tail = lidet__cluster_take(lab, mem, tail, q + cols - 1u);
            }
            if (take & 0x20u)
            {
                tail = lidet__cluster_take(lab, mem, tail, q + cols + 1u);
            }
            if (take & 0x40u)
            {
                tail = lidet__cluster_take(lab, mem, tail, q - cols - 1u);
            }
            if (take & 0x80u)
            {
                tail = lidet__cluster_take(lab, mem, tail, q - cols + 1u);
            }
        }
        return tail;
    }
#endif
    /* right, left (wrapping) */
    if (col + kc < cols)
    {
        tail =
            GROW_FN(search)(lab, mem, rng, tail, dq, q, 1, kc, GROW_TA(c, col), GROW_TB(c, col), 1, g, occl);
    }
    else
    {
        tail = GROW_FN(search_wrap)(c, tail, dq, rowbase, col, 1, g, occl);
    }
    if (col >= kc)
    {
        tail =
            GROW_FN(search)(lab, mem, rng, tail, dq, q, -1, kc, GROW_TA(c, col), GROW_TB(c, col), 1, g, occl);
    }
    else
    {
        tail = GROW_FN(search_wrap)(c, tail, dq, rowbase, col, 0, g, occl);
    }
    /* down: rows r and r + k, entry [r * STEPS + k - 1]; up: rows r - k and r, entry
     * [(r - k) * STEPS + k - 1] (stored at the upper row), i.e. stride 1 - STEPS from (r - 1) * STEPS */
    if (nd > 0u)
    {
        tail = GROW_FN(search)(lab, mem, rng, tail, dq, q, (int32_t)cols, nd, GROW_TA(c, row) + r * STEPS,
                               GROW_TB(c, row) + r * STEPS, 1, g, occl);
    }
    if (nu > 0u)
    {
        tail = GROW_FN(search)(lab, mem, rng, tail, dq, q, -(int32_t)cols, nu,
                               GROW_TA(c, row) + (r - 1u) * STEPS, GROW_TB(c, row) + (r - 1u) * STEPS,
                               1 - STEPS, g, occl);
    }
    /* diagonals (8-neighbourhood option) */
    if (g->diag)
    {
        tail = GROW_FN(diagonals)(c, g, tail, r, col, rowbase, dq);
    }
    return tail;
}

/* Breadth-first flood fill of the cluster seeded at members[start] (tail = start + 1): expands
 * members[head] for head = start .. tail (the member array is the queue, every pixel is pushed at
 * most once). Returns the new tail. occl: whether the occluder rule is on (cfg bridge_occluders); it applies
 * to a pixel's searches while the run's bridging budget lasts (decided per pixel), so each pixel runs the
 * expansion compiled for the rule or the one without it. */
#if defined(__GNUC__)
__attribute__((always_inline))
#endif
static inline uint32_t
GROW_FN(grow)(GROW_STATE_T *c, const GROW_PARAM_T *g, uint32_t start, uint32_t tail, int occl)
{
    const lidet_member_t *mem = c->members;
    uint32_t head = start;
    /* g->cols is read where it is used (the division without row_magic, the assertion), not held over the loop: a
     * register more for the expansion. A VLP-16 scan's clustering, instructions: Cortex-M4 integer 5.42 -> 5.37 M,
     * RV32IMAC 4.96 -> 4.94 M; an HDL-64 scan's, float: Cortex-M7 29.34 -> 29.33 M, RV32IMAFC 23.52 -> 23.46 M */
    while (head < tail)
    {
        const uint32_t q = (uint32_t)mem[head++];
#if LIDET_Q_HAVE_MUL64
        const uint32_t r =
            g->row_magic != 0u ? (uint32_t)(lidet__q_umul32(q, g->row_magic) >> 32) : q / g->cols;
#else
        const uint32_t r = g->row_magic != 0u ? (q * g->row_magic) >> 26 : q / g->cols; /* lidet__q_row_m26 */
#endif
        LIDET_ASSERT(tail <= g->rows * g->cols);
        if (occl && *g->bridged < g->bridge_max)
        {
            tail = GROW_FN(expand)(c, g, tail, q, r, 1);
        }
        else
        {
            tail = GROW_FN(expand)(c, g, tail, q, r, 0);
        }
    }
    return tail;
}
