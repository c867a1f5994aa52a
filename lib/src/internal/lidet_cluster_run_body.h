/* SPDX-License-Identifier: MIT */
/* Macro template: the clustering's bookkeeping: the capacity (the smallest kept cluster, a slot for a new one),
 * the filters and records of each component, the canonical ids, the searches for the next seed, and the run's
 * driver (first fill, rescue pass, regrowth, refinement, canonical order). Nothing here reads a coordinate or a
 * range.
 *
 * Instantiated by (each #include once, after #defining the parameters below):
 *   lib/src/cluster/lidet_cluster.c    the float stage: lidet_cluster_state_t, lidet_cluster_rec_t (float
 *                                     metres), lidet__grow_t, lidet_plane_t
 *   lib/src/cluster/lidet_cluster_q.c  the integer stage: lidet_cluster_q_state_t, lidet_cluster_q_rec_t (int32
 *                                     4 mm steps), lidet__grow_q_t, lidet_plane_q_t
 *
 * Parameters:
 *   RUN_STATE_T                 the state (members cfg, n_recs, recs, order, slot_id, labels, members, img,
 *                               stats, magic, geo_rows, geo_cols)
 *   RUN_REC_T                   its record type (members n_points, first_member, seed_pixel, n_rescued)
 *   RUN_MEAN(r), RUN_MIN(r), RUN_MAX(r)  record r's mean, minimum and maximum (arrays of 3)
 *   RUN_HEIGHT(r)               record r's height above the ground
 *   RUN_PARAM_T                 the flood fill's constants
 *   RUN_PLANE_T                 the ground plane type
 *   RUN_SUMMARY_T               what one pass over a component's members gives (members sum, lo, hi, mean, h)
 *   RUN_GROW(c, g, start, tail)  the first fill of one component (the stage's flood fill); returns the new tail
 *   RUN_RESCUE_T                the rescue group's running state (members tail, best, best_d2)
 *   RUN_RESCUE_FAR              its "no contact yet" squared distance (above any)
 *   RUN_RESCUE_GROW(c, g, start, rs)  the rescue fill of one group
 *   RUN_FRAGMENT_BUDGET(c)      the rescue budget in fragment pixels (0: none)
 *   RUN_REFINE_SPLIT(c, planes, n_sectors, st), RUN_REFINE_JOIN(...)  the stage's refinement (cuts, joins);
 *                               nonzero when it changed anything
 * and the numeric kernels, static functions of the including file:
 *   int summarise(c, start, tail, small, s)  sums and bounds into *s; nonzero when an extent exceeds the limit
 *                                          (small: no limit)
 *   int mean_height_ok(c, n, seed, s, planes, n_sectors)  the mean and its height into *s; nonzero when it
 *                                          passes
 *   void record_sums(c, slot, s)           what the stage keeps of s beside the record (or nothing)
 *   void join_mean(c, slot, n, s)          a rescue group of n pixels added to the record's mean (before its
 *                                          count grows)
 *   void reheight(c, slot, planes, n_sectors)  the record's height from its mean and seed
 *   int rescue_on(c)                       the fragment rescue is configured
 *   int regrow_fits(c, s)                  a component the regrowth takes (low enough)
 *   int regrow_param(c, lk, out)           the regrowth's flood fill constants into *out; 0 when it is off
 * Also read, from lidet_cluster_common.h: the LAB_* labels, lidet__cluster_point_labels.
 * Defines, for the includer: the type run_span_t and the static functions init_done, run_check, run_bind,
 * run_fills, run_refine, labels_of_points (the steps of the stage's init and run), besides their own
 * static functions.
 *
 * Why a template: the two stages' states and records are different types with the same member names, which a
 * C99 function cannot take at once (short of void pointers and accessors for every field). The decisions
 * written here (which cluster is dropped at capacity, the slot order, the canonical ids, when the rescue, the
 * regrowth and the refinement run) must be the same in both stages, each of which the tests compare with its
 * reference (codegen/lidet_ref/cluster.py, cluster_q.py); written once, they cannot drift apart. The
 * numeric work stays in each stage's own kernels above.
 * Not a public header; include nowhere else. */

#define RUN_NO_SLOT 0xFFFFFFFFu

/* Capacity drops (a full record table during the first fill): the smallest kept cluster (ties: the later
 * seed) is the one dropped first. The slots live in a binary min-heap on that order, built in c->order
 * (scratch until canonicalise) at the first drop, so each drop costs O(log LIDET_MAX_CLUSTERS) instead of
 * a scan of every slot (issue 19: 13 k tiny clusters took 9x the typical clustering time). The minimum of a
 * strict order is unique: the same slot as a scan, so the references need no heap. */
static int slot_before(const RUN_STATE_T *c, uint32_t a, uint32_t b)
{
    const RUN_REC_T *ra = &c->recs[a], *rb = &c->recs[b];
    return ra->n_points < rb->n_points || (ra->n_points == rb->n_points && ra->seed_pixel > rb->seed_pixel);
}

static void heap_down(RUN_STATE_T *c, uint32_t i, uint32_t n)
{
    uint16_t *h = c->order;
    for (;;)
    {
        const uint32_t l = 2u * i + 1u, r = l + 1u;
        uint32_t m = i;
        uint16_t t;
        if (l < n && slot_before(c, h[l], h[m]))
        {
            m = l;
        }
        if (r < n && slot_before(c, h[r], h[m]))
        {
            m = r;
        }
        if (m == i)
        {
            return;
        }
        t = h[i];
        h[i] = h[m];
        h[m] = t;
        i = m;
    }
}

static void heap_build(RUN_STATE_T *c)
{
    uint32_t i;
    for (i = 0; i < c->n_recs; ++i)
    {
        c->order[i] = (uint16_t)i;
    }
    for (i = c->n_recs / 2u; i-- > 0u;)
    {
        heap_down(c, i, c->n_recs);
    }
}

/* a slot for a cluster of n pixels that passed the filters, or RUN_NO_SLOT (counted) when the capacity
 * is full and it does not win one: a first-fill cluster evicts the smallest kept one when it is larger
 * (the new one has the latest seed, so it loses every tie); a rescue group never evicts (the rescue runs
 * after the whole first fill, so the heap is built by the first fill's first drop). The evicted cluster's
 * pixels become "visited, dropped"; its member range stays as a hole that the final raster pass compacts
 * away (only first-fill clusters are evicted, and they own exactly their member range). *evicted = 1 when
 * the slot was taken from a kept cluster (the caller restores the heap once the record is written). */
static uint32_t claim_slot(RUN_STATE_T *c, uint32_t n, int rescue, lidet_cluster_stats_t *st, int *evicted)
{
    uint32_t i, m;
    *evicted = 0;
    if (c->n_recs < LIDET_MAX_CLUSTERS)
    {
        return c->n_recs++;
    }
    ++st->n_dropped_capacity;
    if (rescue)
    {
        return RUN_NO_SLOT;
    }
    if (st->n_dropped_capacity == 1u)
    {
        heap_build(c);
    }
    m = c->order[0];
    if (n <= c->recs[m].n_points)
    {
        return RUN_NO_SLOT;
    }
    for (i = c->recs[m].first_member; i < c->recs[m].first_member + c->recs[m].n_points; ++i)
    {
        c->labels[c->members[i]] = (uint16_t)LAB_PENDING;
    }
    *evicted = 1;
    return m;
}

/* canonical id of kept pixel i (label slot + 1, or 0 = none), appended to its cluster's members */
static inline void place_kept(RUN_STATE_T *c, uint16_t *lab, uint32_t i)
{
    const uint32_t l = lab[i];
    if (l != 0u)
    {
        const uint32_t id = c->slot_id[l];
        lab[i] = (uint16_t)id;
        c->members[c->recs[id - 1u].first_member++] = (lidet_member_t)i;
    }
}

/* the pixels a run can label: columns [lo, hi) of every row (the azimuth window of the float stage's cfg
 * azimuth_half_rad; every column without one). The pixels outside are non-candidates throughout the run */
typedef struct
{
    uint32_t rows, cols, lo, hi;
    uint32_t seed_lo, seed_hi; /* the columns [seed_lo, seed_hi) where components may start (float stage's cfg
                                  seed_half_rad; lo, hi without one) */
} run_span_t;

/* canonicalise's last pass over pixels [b, e): every pixel not in a kept cluster (non-candidate, dropped, or
 * still free: no seed of a seed window reached it) -> 0, kept pixels slot + 1 -> id, appended to their cluster's
 * members */
static void relabel_pixels(RUN_STATE_T *c, uint16_t *lab, uint32_t b, uint32_t e)
{
    uint32_t i;
#if !LIDET_HOST_SIMD
    /* cores without SIMD: one pass, a branch per pixel (the two passes below cost a second read and write of
     * every label there) */
    for (i = b; i < e; ++i)
    {
        const uint32_t l = lab[i];
        if (l >= LAB_SMALL)
        {
            lab[i] = 0u;
        }
        else if (l != 0u)
        {
            place_kept(c, lab, i);
        }
    }
    return;
#endif
    /* without a branch (it vectorises); kept pixels keep slot + 1 */
    for (i = b; i < e; ++i)
    {
        const uint32_t l = lab[i];
        lab[i] = (uint16_t)(l < LAB_SMALL ? l : 0u);
    }
    /* slot + 1 -> id and the members in raster order, a run of one cluster's pixels along the row at a time: its
     * next member's place kept in a register over the run, not read back from the record pixel by pixel (each
     * increment there waited for the one before, through memory; on the 17 real KITTI scans this pass went from
     * 3.3 to 3.1 % of the detector, perf). Blocks of four labels that are all 0 (one 64-bit word, read with memcpy)
     * are skipped at once. The cores without SIMD keep the one pass above: there the runs cost more instructions
     * (the Cortex-M4 integer image's clustering 5.37 -> 5.47 M a VLP-16 scan) */
    i = b;
    while (i < e)
    {
        uint32_t l;
        if (i + 4u <= e)
        {
            uint64_t w;
            memcpy(&w, &lab[i], sizeof w);
            if (w == 0u)
            {
                i += 4u;
                continue;
            }
        }
        l = lab[i];
        if (l == 0u)
        {
            ++i;
            continue;
        }
        {
            const uint32_t id = c->slot_id[l];
            RUN_REC_T *r = &c->recs[id - 1u];
            uint32_t m = r->first_member;
            do
            {
                lab[i] = (uint16_t)id;
                c->members[m++] = (lidet_member_t)i;
                ++i;
            } while (i < e && lab[i] == l);
            r->first_member = m;
        }
    }
}

/* canonical order: records sorted by seed, labels rewritten, members regrouped in raster order */
static void canonicalise(RUN_STATE_T *c, const run_span_t *sp, lidet_cluster_stats_t *st)
{
    const uint32_t k = c->n_recs;
    uint32_t i, j, start;
    uint16_t *lab = c->labels;

    /* insertion sort of slots by seed: already sorted unless capacity evictions happened or the rescue
     * added clusters or moved a seed */
    for (i = 0; i < k; ++i)
    {
        const uint16_t s = (uint16_t)i;
        j = i;
        while (j > 0 && c->recs[c->order[j - 1]].seed_pixel > c->recs[s].seed_pixel)
        {
            c->order[j] = c->order[j - 1];
            --j;
        }
        c->order[j] = s;
    }
    c->slot_id[0] = 0;
    for (i = 0; i < k; ++i)
    {
        c->slot_id[c->order[i] + 1u] = (uint16_t)(i + 1u);
    }
    /* gather permutation recs[i] = old recs[order[i]], following cycles (order[] is consumed) */
    for (i = 0; i < k; ++i)
    {
        RUN_REC_T tmp;
        if (c->order[i] == i)
        {
            continue;
        }
        tmp = c->recs[i];
        j = i;
        for (;;)
        {
            const uint32_t src = c->order[j];
            c->order[j] = (uint16_t)j;
            if (src == i)
            {
                c->recs[j] = tmp;
                break;
            }
            c->recs[j] = c->recs[src];
            j = src;
        }
    }
    start = 0;
    for (i = 0; i < k; ++i)
    {
        c->recs[i].first_member = start; /* a write cursor during the pass below */
        start += c->recs[i].n_points;
    }
    st->n_pixels_kept = start;
    /* the labels and members in raster order: over the window's columns only (the columns outside hold
     * non-candidates: set to 0), row by row, so the members stay in raster order */
    if (sp->lo == 0u && sp->hi == sp->cols)
    {
        relabel_pixels(c, lab, 0u, sp->rows * sp->cols);
    }
    else
    {
        uint32_t r;
        for (r = 0; r < sp->rows; ++r)
        {
            const uint32_t row = r * sp->cols;
            memset(lab + row, 0, sp->lo * sizeof lab[0]);
            relabel_pixels(c, lab, row + sp->lo, row + sp->hi);
            memset(lab + row + sp->hi, 0, (sp->cols - sp->hi) * sizeof lab[0]);
        }
    }
    for (i = 0; i < k; ++i)
    {
        c->recs[i].first_member -= c->recs[i].n_points;
    }
}

/* the first free pixel (label 0) at or after p, npix if none. Seeds are rare once most pixels are
 * visited: where LIDET__LAB_WORDS, four labels at a time (a 64-bit word, read with memcpy) are skipped when
 * none is 0 (elsewhere one label at a time). The test (w - 0x0001..) & ~w & 0x8000.. is nonzero exactly when
 * some 16-bit lane of w is zero (a borrow only starts at a zero lane, and the lowest zero lane always sets its
 * top bit) */
static inline uint32_t next_free(const uint16_t *lab, uint32_t p, uint32_t npix)
{
    for (;;)
    {
        while (LIDET__LAB_WORDS && p + 4u <= npix)
        {
            uint64_t w;
            memcpy(&w, &lab[p], sizeof w);
            if (((w - 0x0001000100010001u) & ~w & 0x8000800080008000u) != 0u)
            {
                break;
            }
            p += 4u;
        }
        if (p >= npix || lab[p] == LAB_FREE)
        {
            return p < npix ? p : npix;
        }
        ++p;
    }
}

/* the first fragment pixel (LAB_SMALL) at or after p, npix if none: blocks of 64 labels are tested
 * in a loop without branches (it vectorises), and only a block that holds one is searched */
static uint32_t next_fragment(const uint16_t *lab, uint32_t p, uint32_t npix)
{
    while (p < npix)
    {
        const uint32_t e = npix - p < 64u ? npix : p + 64u;
        uint32_t i;
        uint16_t any = 0;
        for (i = p; i < e; ++i)
        {
            any |= (uint16_t)(lab[i] == LAB_SMALL);
        }
        if (any != 0u)
        {
            for (i = p; lab[i] != LAB_SMALL; ++i)
            {
            }
            return i;
        }
        p = e;
    }
    return npix;
}

/* the end of a successful init: no geometry, run or record yet */
static lidet_status_t init_done(RUN_STATE_T *c)
{
    c->geo_rows = 0;
    c->geo_cols = 0;
    c->n_recs = 0;
    c->labels = 0;
    c->members = 0;
    memset(&c->img, 0, sizeof c->img);
    memset(&c->stats, 0, sizeof c->stats);
    c->magic = LIDET_INIT_MAGIC;
    return LIDET_OK;
}

/* the checks every run starts with (arguments, state, image size) */
static lidet_status_t run_check(const RUN_STATE_T *c, const uint16_t *labels, const lidet_member_t *members,
                                const lidet_range_image_t *img, const RUN_PLANE_T *planes, uint32_t n_sectors)
{
    if (c == 0 || labels == 0 || members == 0 || img == 0 || (planes != 0 && n_sectors == 0))
    {
        return LIDET_ERR_ARG;
    }
    if (c->magic != LIDET_INIT_MAGIC)
    {
        return LIDET_ERR_STATE;
    }
    if (img->n_rows < 1 || img->n_cols < 2 || img->n_rows > LIDET_MAX_ROWS || img->n_cols > LIDET_MAX_COLS)
    {
        return LIDET_ERR_BUFFER;
    }
    return LIDET_OK;
}

/* the cluster id of every input point from the last run's per-pixel ids (point_labels of both stages) */
static lidet_status_t labels_of_points(const RUN_STATE_T *c, const int32_t *point_pixel, uint32_t n_points,
                                       uint32_t *out)
{
    if (c == 0 || ((point_pixel == 0 || out == 0) && n_points > 0))
    {
        return LIDET_ERR_ARG;
    }
    if (c->magic != LIDET_INIT_MAGIC || c->labels == 0)
    {
        return LIDET_ERR_STATE;
    }
    lidet__cluster_point_labels(c->labels, (uint32_t)c->img.n_rows * c->img.n_cols, point_pixel, n_points,
                                out);
    return LIDET_OK;
}

/* the run's image and buffers bound to the state, the records and counts cleared */
static void run_bind(RUN_STATE_T *c, uint16_t *labels, lidet_member_t *members,
                     const lidet_range_image_t *img, lidet_cluster_stats_t *st)
{
    c->img = *img;
    c->labels = labels;
    c->members = members;
    c->n_recs = 0;
    memset(st, 0, sizeof *st);
}

/* a record's numbers from the summary of its members */
static void record_numbers(RUN_STATE_T *c, uint32_t slot, const RUN_SUMMARY_T *s)
{
    RUN_REC_T *rec = &c->recs[slot];
    uint32_t i;
    for (i = 0; i < 3; ++i)
    {
        RUN_MEAN(rec)[i] = s->mean[i];
        RUN_MIN(rec)[i] = s->lo[i];
        RUN_MAX(rec)[i] = s->hi[i];
    }
    RUN_HEIGHT(rec) = s->h;
    record_sums(c, slot, s);
}

/* filters + bookkeeping of the component members[start, tail); returns the new tail. rescue = 0:
 * a component of the first fill (one below min_points becomes a fragment when the rescue is on);
 * 1: a rescue group that joined no cluster (dropped when small; takes only a free slot) */
static uint32_t regrow(RUN_STATE_T *c, const RUN_PARAM_T *tight, uint32_t start, uint32_t tail, uint32_t npix,
                       const RUN_PLANE_T *planes, uint32_t n_sectors, lidet_cluster_stats_t *st);

static uint32_t finish_cluster(RUN_STATE_T *c, uint32_t start, uint32_t tail, const RUN_PLANE_T *planes,
                               uint32_t n_sectors, lidet_cluster_stats_t *st, int rescue,
                               const RUN_PARAM_T *tight, uint32_t npix)
{
    const uint32_t n = tail - start;
    const lidet_member_t *mem = c->members;
    RUN_SUMMARY_T sm;
    uint32_t i, slot;
    int small, evicted;
    RUN_REC_T *rec;

    if (!rescue)
    {
        ++st->n_found;
    }
    small = n < c->cfg.min_points;
    if (small && (rescue || !rescue_on(c)))
    {
        ++st->n_dropped_small;
        return start;
    }
    /* the rescue budget (RUN_FRAGMENT_BUDGET(c), 0 = none), before any statistics: past it a fragment-to-be
     * costs nothing more */
    if (small && RUN_FRAGMENT_BUDGET(c) != 0u && st->n_fragment_pixels + n > RUN_FRAGMENT_BUDGET(c))
    {
        ++st->n_dropped_fragment_budget;
        return start;
    }
    /* the same filters for a fragment-to-be (small: no extent limit), so that one above the height
     * limit (canopies, wires: nothing a road user would take in) never reaches the rescue; it saves
     * a third of the rescue's work */
    if (summarise(c, start, tail, small, &sm))
    {
        if (tight != 0 && !small && (c->cfg.regrow_max_pixels == 0u || n <= c->cfg.regrow_max_pixels))
        {
            /* the full bounds (summarise stopped at the first extent past the limit) */
            (void)summarise(c, start, tail, 1, &sm);
            if (regrow_fits(c, &sm))
            {
                return regrow(c, tight, start, tail, npix, planes, n_sectors, st);
            }
        }
        ++st->n_dropped_extent;
        return start;
    }
    if (!mean_height_ok(c, n, (uint32_t)mem[start], &sm, planes, n_sectors))
    {
        ++st->n_dropped_height;
        return start;
    }
    if (small)
    {
        st->n_fragment_pixels += n;
        ++st->n_fragments;
        for (i = start; i < tail; ++i)
        {
            c->labels[mem[i]] = (uint16_t)LAB_SMALL;
        }
        return start;
    }
    slot = claim_slot(c, n, rescue, st, &evicted);
    if (slot == RUN_NO_SLOT)
    {
        return start;
    }
    rec = &c->recs[slot];
    rec->n_points = n;
    rec->first_member = start;
    rec->seed_pixel = (uint32_t)mem[start];
    rec->n_rescued = rescue ? n : 0u;
    record_numbers(c, slot, &sm);
    if (evicted)
    {
        heap_down(c, 0u, LIDET_MAX_CLUSTERS); /* the slot at the top grew: restore the heap */
    }
    if (rescue)
    {
        st->n_rescue_pixels += n;
    }
    for (i = start; i < tail; ++i)
    {
        c->labels[mem[i]] = (uint16_t)(slot + 1u);
    }
    return tail;
}

/* An over-extent component members[start, tail) grown again from its own pixels with the tighter join test
 * `tight` (cfg regrow_gap_m: cars parked bumper to bumper, or a car and the hedge behind it, chained by the gap
 * bound): each part goes through the filters (finish_cluster; no part is regrown again). The component's list is
 * first moved to the top of the member buffer: below it the run lists each candidate at most once, so while
 * n_candidates + the component's size fit in the buffer the parts never reach it; else the component is dropped
 * as before. Parts are seeded in the component's own (fill) order; each part's seed pixel is its first in raster
 * order. Returns the new tail. */
static uint32_t regrow(RUN_STATE_T *c, const RUN_PARAM_T *tight, uint32_t start, uint32_t tail, uint32_t npix,
                       const RUN_PLANE_T *planes, uint32_t n_sectors, lidet_cluster_stats_t *st)
{
    lidet_member_t *mem = c->members;
    uint16_t *lab = c->labels;
    const uint32_t n = tail - start;
    uint32_t i, top, w = start;
    if (st->n_candidates > npix || n > npix - st->n_candidates)
    {
        ++st->n_dropped_extent;
        return start;
    }
    top = npix - n;
    memmove(mem + top, mem + start, n * sizeof *mem);
    for (i = top; i < npix; ++i)
    {
        const uint32_t p = (uint32_t)mem[i];
        lab[p] = (uint16_t)(regrow_cut(c, p, planes, n_sectors) ? LAB_NONCAND : LAB_FREE);
    }
    ++st->n_regrown;
    for (i = top; i < npix; ++i)
    {
        const uint32_t p = (uint32_t)mem[i];
        uint32_t e;
        if (lab[p] != (uint16_t)LAB_FREE)
        {
            continue;
        }
        lab[p] = (uint16_t)LAB_PENDING;
        mem[w] = (lidet_member_t)p;
        e = RUN_GROW(c, tight, w, w + 1u);
        ++st->n_regrow_parts;
        {
            /* the part's seed is its first pixel in raster order, as every cluster's (the height's sector, the
             * canonical order): moved to the front of its members */
            uint32_t j, k = w;
            lidet_member_t t;
            for (j = w + 1u; j < e; ++j)
            {
                k = mem[j] < mem[k] ? j : k;
            }
            t = mem[w];
            mem[w] = mem[k];
            mem[k] = t;
        }
        w = finish_cluster(c, w, e, planes, n_sectors, st, 0, 0, npix);
    }
    return w;
}

/* a rescue group members[start, tail) joins kept cluster `slot`: count, bounds and mean are updated and the
 * height recomputed (no filter). The group's seed is its first pixel in raster order, so the cluster's first
 * pixel is the smaller of the two seeds (the height uses that pixel's sector, as for any cluster) */
static void rescue_join(RUN_STATE_T *c, uint32_t slot, uint32_t start, uint32_t tail,
                        const RUN_PLANE_T *planes, uint32_t n_sectors, lidet_cluster_stats_t *st)
{
    RUN_REC_T *rec = &c->recs[slot];
    const uint32_t n = tail - start, seed = (uint32_t)c->members[start];
    RUN_SUMMARY_T sm;
    uint32_t i;
    (void)summarise(c, start, tail, 1, &sm);
    join_mean(c, slot, n, &sm);
    for (i = 0; i < 3; ++i)
    {
        RUN_MIN(rec)[i] = sm.lo[i] < RUN_MIN(rec)[i] ? sm.lo[i] : RUN_MIN(rec)[i];
        RUN_MAX(rec)[i] = sm.hi[i] > RUN_MAX(rec)[i] ? sm.hi[i] : RUN_MAX(rec)[i];
    }
    for (i = start; i < tail; ++i)
    {
        c->labels[c->members[i]] = (uint16_t)(slot + 1u);
    }
    rec->n_points += n;
    rec->n_rescued += n;
    rec->seed_pixel = seed < rec->seed_pixel ? seed : rec->seed_pixel;
    reheight(c, slot, planes, n_sectors);
    ++st->n_rescue_joined;
    st->n_rescue_pixels += n;
}

/* the whole run after the candidates are marked in labels (FREE / NONCAND) and the stats zeroed but
 * n_candidates: the first fill in raster order, the rescue pass over the fragments (LAB_SMALL), groups
 * seeded in raster order (kept pixels, the fragments and the current group are distinct pixels, so the
 * member array holds them), and the canonical order */
static void run_fills(RUN_STATE_T *c, const RUN_PARAM_T *lk, const run_span_t *sp, const RUN_PLANE_T *planes,
                      uint32_t n_sectors, lidet_cluster_stats_t *st)
{
    RUN_PARAM_T tk;
    const RUN_PARAM_T *const tight = regrow_param(c, lk, &tk) ? &tk : 0;
    const uint32_t npix = sp->rows * sp->cols;
    uint16_t *lab = c->labels;
    lidet_member_t *mem = c->members;
    uint32_t p, r, tail = 0;
    /* seeds in raster order over the seed columns [seed_lo, seed_hi) of each row (the window's columns without a
     * seed window, every column without either) */
    for (r = 0; r < sp->rows; ++r)
    {
        const uint32_t b = r * sp->cols + sp->seed_lo, e = r * sp->cols + sp->seed_hi;
        for (p = next_free(lab, b, e); p < e; p = next_free(lab, p + 1u, e))
        {
            const uint32_t start = tail;
            lab[p] = (uint16_t)LAB_PENDING;
            mem[tail++] = (int32_t)p;
            tail = RUN_GROW(c, lk, start, tail);
            tail = finish_cluster(c, start, tail, planes, n_sectors, st, 0, tight, npix);
        }
    }
    if (st->n_fragments > 0u)
    {
        /* the fragments' pixels not yet in a group: the search stops at the last one instead of the image's end */
        uint32_t left = st->n_fragment_pixels;
        for (p = next_fragment(lab, 0, npix); p < npix;
             p = left == 0u ? npix : next_fragment(lab, p + 1u, npix))
        {
            RUN_RESCUE_T rs;
            const uint32_t start = tail;
            lab[p] = (uint16_t)LAB_PENDING;
            mem[tail++] = (int32_t)p;
            rs.tail = tail;
            rs.best = 0u;
            rs.best_d2 = RUN_RESCUE_FAR;
            RUN_RESCUE_GROW(c, lk, start, &rs);
            left -= rs.tail - start < left ? rs.tail - start : left; /* the group: fragment pixels only */
            if (rs.best != 0u)
            {
                rescue_join(c, rs.best - 1u, start, rs.tail, planes, n_sectors, st);
                tail = start;
            }
            else
            {
                tail = finish_cluster(c, start, rs.tail, planes, n_sectors, st, 1, 0, npix);
            }
        }
    }
    canonicalise(c, sp, st);
    st->n_kept = c->n_recs;
}

/* the refinement after the fills (cfg split_people, join_cars): people cut out of wide clusters, car fragments
 * joined; the canonical order again when it changed anything, then the joined (emptied) records, ordered last,
 * are dropped */
static void run_refine(RUN_STATE_T *c, const run_span_t *sp, const RUN_PLANE_T *planes, uint32_t n_sectors,
                       lidet_cluster_stats_t *st)
{
    int changed;
    memset(c->order, 0, sizeof c->order); /* the cut marks */
    changed = c->cfg.split_people != 0u && RUN_REFINE_SPLIT(c, planes, n_sectors, st);
    changed |= c->cfg.join_cars != 0u && RUN_REFINE_JOIN(c, planes, n_sectors, st);
    if (changed)
    {
        canonicalise(c, sp, st);
        c->n_recs -= st->n_joined;
    }
    st->n_kept = c->n_recs;
}
