/* SPDX-License-Identifier: MIT */
/* Macro template: the proposal refinement's control flow (the rules in lidet_cluster.h, cfg split_people,
 * join_cars): which clusters are examined, the bird's-eye-view grid and its 8-connected parts, the choice of the
 * parts that leave and their slots, the relabelling, and the joins' loop. Nothing here reads a coordinate.
 *
 * Instantiated by (each #include once, after #defining the parameters below and its numeric kernels):
 *   lib/src/cluster/lidet_refine.c    the float stage: lidet_cluster_state_t, lidet_cluster_rec_t,
 *                                    lidet_cluster_cfg_t, lidet_plane_t; coordinates float (m), sums float
 *   lib/src/cluster/lidet_refine_q.c  the integer stage: lidet_cluster_q_state_t, lidet_cluster_q_rec_t,
 *                                    lidet_cluster_q_cfg_t, lidet_plane_q_t; coordinates int32_t (4 mm steps),
 *                                    sums int64_t
 *
 * Parameters:
 *   REFINE_STATE_T      the state (members recs, n_recs, order, labels, members, img, cfg and the rf_* scratch)
 *   REFINE_REC_T        its record type
 *   REFINE_CFG_T        its configuration type
 *   REFINE_PLANE_T      the ground plane type
 *   REFINE_GEOM_T       one examined cluster's grid (its corner, cell size)
 *   REFINE_Z_T          a z coordinate; REFINE_Z_FAR a bound no z reaches
 *   REFINE_V_T          a coordinate; REFINE_S_T a sum of coordinates
 *   REFINE_READ(c, p, v)  pixel p's x, y, z into v[3]
 *   REFINE_MIN(r), REFINE_MAX(r), REFINE_MEAN(r)  record r's bounds and mean (arrays of 3)
 *   REFINE_H(r)         record r's height (an lvalue)
 *   REFINE_HEIGHT(c, seed, mean, planes, n_sectors)  the height of a mean (the clustering's)
 *   REFINE_SPLIT_FN, REFINE_JOIN_FN  the names of the two entry points this file defines
 *                       (lidet_cluster_internal.h, lidet_cluster_q_internal.h)
 * and the numeric kernels, static functions of the including file:
 *   int refine_examined(cfg, rec)  wider than split_min_width in x or y, and at least person_min_height in z
 *   int refine_grid(cfg, rec, geom, nx, ny)  the grid of the cluster: its cells along x and y (0 when a count
 *                       does not fit 32 bits)
 *   uint32_t refine_cell(c, p, geom, nx, ny)  the cell of member pixel p (clamped to the grid)
 *   REFINE_Z_T refine_z(c, p)  the z of pixel p
 *   int refine_person(cfg, geom, n, sx, sy, zlo, zhi, ncols)  a part of n points spanning sx, sy cells, z in
 *                       [zlo, zhi], over ncols image columns, is person-sized
 *   void refine_mean(c, slot, sum)  record `slot`'s mean from the sums of its n_points members
 *   int refine_car_piece(cfg, rec), int refine_joinable(cfg, a, b)  the joins' box tests
 *   void refine_join_mean(c, i, j, first)  cluster j's mean into cluster i's (first: i's first join of the
 *                       pass), before the counts grow
 * Defines: int REFINE_SPLIT_FN(REFINE_STATE_T *c, const REFINE_PLANE_T *planes, uint32_t n_sectors,
 * lidet_cluster_stats_t *st) and REFINE_JOIN_FN (the same arguments), nonzero when they changed anything, and
 * their static functions.
 *
 * Why a template: the two stages' states, records and configurations are different types, which a C99 function
 * cannot take at once (short of void pointers and accessors for every field). The decisions (which parts
 * leave, their slots, the join order and budget) must be the same in both, each compared with its reference
 * (refine_ref in codegen/lidet_ref/cluster.py, refine_q in cluster_q.py); written once, they cannot
 * drift apart, while the arithmetic stays in each stage's kernels.
 * Not a public header; include nowhere else. */

#define REFINE_CELL_OCC 0xFFFFu

/* 8-connected parts of the occupied cells, numbered in the order their first member is met. Returns
 * the number of parts, or 0 when there are more than LIDET_REFINE_MAX_PARTS */
static uint32_t refine_label_parts(REFINE_STATE_T *c, uint32_t n, uint32_t nx, uint32_t ny)
{
    uint16_t *grid = c->rf_grid, *q = c->rf_queue;
    uint32_t i, n_parts = 0;
    for (i = 0; i < n; ++i)
    {
        const uint32_t cell = c->rf_cell[i];
        uint32_t head = 0, tail = 0;
        if (grid[cell] != REFINE_CELL_OCC)
        {
            continue; /* already in a part */
        }
        if (n_parts == LIDET_REFINE_MAX_PARTS)
        {
            return 0;
        }
        grid[cell] = (uint16_t)(n_parts + 1u);
        q[tail++] = (uint16_t)cell;
        while (head < tail)
        {
            const uint32_t cc = q[head++], cx = cc % nx, cy = cc / nx;
            const uint32_t x0 = cx > 0u ? cx - 1u : 0u, x1 = cx + 1u < nx ? cx + 1u : cx;
            const uint32_t y0 = cy > 0u ? cy - 1u : 0u, y1 = cy + 1u < ny ? cy + 1u : cy;
            uint32_t xx, yy;
            for (yy = y0; yy <= y1; ++yy)
            {
                for (xx = x0; xx <= x1; ++xx)
                {
                    const uint32_t nb = yy * nx + xx;
                    if (grid[nb] == REFINE_CELL_OCC)
                    {
                        grid[nb] = (uint16_t)(n_parts + 1u);
                        q[tail++] = (uint16_t)nb;
                    }
                }
            }
        }
        ++n_parts;
    }
    return n_parts;
}

/* record `slot` from the members of src's (contiguous) range now labelled slot + 1: count, seed (its first
 * pixel), bounds, mean and height */
static void refine_rebuild(REFINE_STATE_T *c, uint32_t slot, const REFINE_REC_T *src,
                           const REFINE_PLANE_T *planes, uint32_t n_sectors)
{
    REFINE_REC_T *r = &c->recs[slot];
    REFINE_S_T sum[3] = {0, 0, 0};
    REFINE_V_T lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};
    uint32_t i, n = 0, seed = 0;
    for (i = src->first_member; i < src->first_member + src->n_points; ++i)
    {
        const uint32_t p = (uint32_t)c->members[i];
        REFINE_V_T v[3];
        uint32_t k;
        if (c->labels[p] != slot + 1u)
        {
            continue;
        }
        REFINE_READ(c, p, v);
        if (n == 0u)
        {
            seed = p;
            for (k = 0; k < 3u; ++k)
            {
                lo[k] = v[k];
                hi[k] = v[k];
            }
        }
        for (k = 0; k < 3u; ++k)
        {
            sum[k] += v[k];
            lo[k] = v[k] < lo[k] ? v[k] : lo[k];
            hi[k] = v[k] > hi[k] ? v[k] : hi[k];
        }
        ++n;
    }
    r->n_points = n;
    r->first_member = src->first_member; /* rewritten by the canonical pass */
    r->seed_pixel = seed;
    for (i = 0; i < 3u; ++i)
    {
        REFINE_MIN(r)[i] = lo[i];
        REFINE_MAX(r)[i] = hi[i];
    }
    refine_mean(c, slot, sum);
    REFINE_H(r) = REFINE_HEIGHT(c, seed, REFINE_MEAN(r), planes, n_sectors);
}

/* the extents of the parts of cluster rec (rf_grid: each occupied cell's part + 1, rf_cell: each member's cell):
 * per part its member count rf_n, cell box rf_box (x lo, x hi, y lo, y hi), z range rf_z and image column span
 * rf_col */
static void refine_part_extents(REFINE_STATE_T *c, const REFINE_REC_T *rec, uint32_t nx, uint32_t n_parts)
{
    uint32_t i, p;
    for (p = 0; p < n_parts; ++p)
    {
        c->rf_n[p] = 0;
        c->rf_box[p][0] = 0xFFFFu;
        c->rf_box[p][1] = 0;
        c->rf_box[p][2] = 0xFFFFu;
        c->rf_box[p][3] = 0;
        c->rf_z[p][0] = REFINE_Z_FAR;
        c->rf_z[p][1] = -REFINE_Z_FAR;
        c->rf_col[p][0] = 0xFFFFu;
        c->rf_col[p][1] = 0;
    }
    for (i = 0; i < rec->n_points; ++i)
    {
        const uint32_t px = (uint32_t)c->members[rec->first_member + i];
        const uint32_t cell = c->rf_cell[i], cx = cell % nx, cy = cell / nx;
        const uint32_t q = c->rf_grid[cell] - 1u;
        const REFINE_Z_T z = refine_z(c, px);
        const uint32_t col = px % c->img.n_cols;
        ++c->rf_n[q];
        c->rf_box[q][0] = (uint16_t)(cx < c->rf_box[q][0] ? cx : c->rf_box[q][0]);
        c->rf_box[q][1] = (uint16_t)(cx > c->rf_box[q][1] ? cx : c->rf_box[q][1]);
        c->rf_box[q][2] = (uint16_t)(cy < c->rf_box[q][2] ? cy : c->rf_box[q][2]);
        c->rf_box[q][3] = (uint16_t)(cy > c->rf_box[q][3] ? cy : c->rf_box[q][3]);
        c->rf_z[q][0] = z < c->rf_z[q][0] ? z : c->rf_z[q][0];
        c->rf_z[q][1] = z > c->rf_z[q][1] ? z : c->rf_z[q][1];
        c->rf_col[q][0] = (uint16_t)(col < c->rf_col[q][0] ? col : c->rf_col[q][0]);
        c->rf_col[q][1] = (uint16_t)(col > c->rf_col[q][1] ? col : c->rf_col[q][1]);
    }
}

/* which parts leave: person-sized parts leave (rf_target 1), the rest stays (0); when every part of min_points is
 * person-sized the largest part stays, and when too few points would stay the largest person-sized part stays
 * too (ties of size: the first part). Returns 0 (nothing leaves) when no part is person-sized. */
static int refine_leaving(REFINE_STATE_T *c, const REFINE_GEOM_T *geo, uint32_t n_parts)
{
    const REFINE_CFG_T *cfg = &c->cfg;
    const uint32_t pmin = cfg->person_min_points;
    uint32_t p, largest = 0, largest_person = n_parts, n_stay = 0;
    int any_person = 0, all_person = 1;
    for (p = 0; p < n_parts; ++p)
    {
        const int person =
            c->rf_n[p] >= pmin &&
            refine_person(cfg, geo, c->rf_n[p], (uint32_t)(c->rf_box[p][1] - c->rf_box[p][0]) + 1u,
                          (uint32_t)(c->rf_box[p][3] - c->rf_box[p][2]) + 1u, c->rf_z[p][0], c->rf_z[p][1],
                          (uint32_t)(c->rf_col[p][1] - c->rf_col[p][0]) + 1u);
        c->rf_target[p] = (uint16_t)(person ? 1u : 0u);
        any_person |= person;
        if (c->rf_n[p] >= cfg->min_points)
        {
            all_person &= person;
        }
        largest = c->rf_n[p] > c->rf_n[largest] ? p : largest;
        if (person && (largest_person == n_parts || c->rf_n[p] > c->rf_n[largest_person]))
        {
            largest_person = p;
        }
    }
    if (!any_person)
    {
        return 0;
    }
    if (all_person)
    {
        c->rf_target[largest] = 0;
    }
    for (p = 0; p < n_parts; ++p)
    {
        n_stay += c->rf_target[p] == 0u ? c->rf_n[p] : 0u;
    }
    if (n_stay < cfg->min_points)
    {
        c->rf_target[largest_person] = 0;
    }
    return 1;
}

/* slots: the staying parts -> k, the leaving ones -> free slots in part order (none free: it stays); rf_target
 * becomes each part's slot. Returns the number of new slots. */
static uint32_t refine_slots(REFINE_STATE_T *c, uint32_t k, uint32_t n_parts)
{
    uint32_t p, n_new = 0;
    for (p = 0; p < n_parts; ++p)
    {
        if (c->rf_target[p] == 0u)
        {
            c->rf_target[p] = (uint16_t)k;
        }
        else if (c->n_recs < LIDET_MAX_CLUSTERS)
        {
            c->rf_target[p] = (uint16_t)c->n_recs++;
            ++n_new;
        }
        else
        {
            c->rf_target[p] = (uint16_t)k; /* no free slot: it stays */
        }
    }
    return n_new;
}

/* cut cluster k; returns 1 when it was cut */
static int refine_split_one(REFINE_STATE_T *c, uint32_t k, const REFINE_PLANE_T *planes, uint32_t n_sectors,
                            lidet_cluster_stats_t *st)
{
    const REFINE_CFG_T *cfg = &c->cfg;
    const REFINE_REC_T rec = c->recs[k]; /* a copy: recs[k] is rebuilt below */
    REFINE_GEOM_T geo;
    const uint32_t pmin = cfg->person_min_points; /* [1, 1000000] (validated) */
    uint32_t nx, ny, n_parts, i, p, n_new;

    /* examined: wider than one person. Two early outs that change no decision, only the time: a cut
     * needs a leaving part of person_min_points and a staying one of min_points or, when a person-sized
     * part stays, person_min_points; and no part spans more in z than the whole (measured: a limit on the
     * cluster's height, skipping walls and trees, saved no time and lost people beside poles) */
    if (rec.n_points < pmin + (pmin < cfg->min_points ? pmin : cfg->min_points) ||
        rec.n_points > LIDET_REFINE_MAX_POINTS || !refine_examined(cfg, &rec))
    {
        return 0;
    }
    if (!refine_grid(cfg, &rec, &geo, &nx, &ny) || nx > LIDET_REFINE_MAX_CELLS ||
        ny > LIDET_REFINE_MAX_CELLS / nx)
    {
        ++st->n_split_skipped;
        return 0;
    }
    memset(c->rf_grid, 0, (size_t)nx * ny * sizeof c->rf_grid[0]);
    for (i = 0; i < rec.n_points; ++i)
    {
        const uint32_t cell = refine_cell(c, (uint32_t)c->members[rec.first_member + i], &geo, nx, ny);
        c->rf_cell[i] = (uint16_t)cell;
        c->rf_grid[cell] = (uint16_t)REFINE_CELL_OCC;
    }
    n_parts = refine_label_parts(c, rec.n_points, nx, ny);
    if (n_parts == 0u)
    {
        ++st->n_split_skipped;
        return 0;
    }
    if (n_parts == 1u)
    {
        return 0;
    }
    refine_part_extents(c, &rec, nx, n_parts);
    if (!refine_leaving(c, &geo, n_parts))
    {
        return 0;
    }
    n_new = refine_slots(c, k, n_parts);
    if (n_new == 0u)
    {
        return 0;
    }
    /* the cut: the members relabelled by part, the records rebuilt from them, none of them joins */
    for (i = 0; i < rec.n_points; ++i)
    {
        c->labels[c->members[rec.first_member + i]] =
            (uint16_t)(c->rf_target[c->rf_grid[c->rf_cell[i]] - 1u] + 1u);
    }
    refine_rebuild(c, k, &rec, planes, n_sectors);
    c->recs[k].n_rescued = rec.n_rescued < c->recs[k].n_points ? rec.n_rescued : c->recs[k].n_points;
    for (p = 0; p < n_parts; ++p)
    {
        if (c->rf_target[p] != k)
        {
            refine_rebuild(c, c->rf_target[p], &rec, planes, n_sectors);
            c->recs[c->rf_target[p]].n_rescued = 0;
        }
    }
    c->order[k] = 1u; /* cut: no join */
    for (p = 0; p < n_parts; ++p)
    {
        c->order[c->rf_target[p]] = 1u;
    }
    ++st->n_split;
    st->n_split_parts += n_new;
    return 1;
}

int REFINE_SPLIT_FN(REFINE_STATE_T *c, const REFINE_PLANE_T *planes, uint32_t n_sectors,
                    lidet_cluster_stats_t *st)
{
    const uint32_t k0 = c->n_recs;
    uint32_t k;
    int changed = 0;
    for (k = 0; k < k0; ++k)
    {
        changed |= refine_split_one(c, k, planes, n_sectors, st);
    }
    return changed;
}

#define REFINE_JOIN_PIECE 4u

int REFINE_JOIN_FN(REFINE_STATE_T *c, const REFINE_PLANE_T *planes, uint32_t n_sectors,
                   lidet_cluster_stats_t *st)
{
    const REFINE_CFG_T *cfg = &c->cfg;
    const uint32_t k = c->n_recs;
    uint32_t i, j, n_joined = 0, n_pieces = 0;
    /* order[]: 1 = cut by the split, 2 = joined into an earlier cluster, REFINE_JOIN_PIECE = a car piece within
     * the join budget (max_join_pieces, in slot order). A record changes only at its own turn (it takes) or when
     * it is taken (then it is skipped), so whether it is a car piece is decided once, here, as the pair loop
     * would decide it at its turn: the budget bounds the loop to max_join_pieces x k pairs */
    for (i = 0; i < k; ++i)
    {
        if (c->order[i] == 0u && refine_car_piece(cfg, &c->recs[i]))
        {
            if (cfg->max_join_pieces != 0u && n_pieces >= cfg->max_join_pieces)
            {
                ++st->n_join_skipped;
                continue;
            }
            c->order[i] = REFINE_JOIN_PIECE;
            ++n_pieces;
        }
    }
    for (i = 0; i < k; ++i)
    {
        REFINE_REC_T *a = &c->recs[i];
        int first = 1;
        if (c->order[i] != REFINE_JOIN_PIECE)
        {
            continue;
        }
        for (j = i + 1u; j < k; ++j)
        {
            REFINE_REC_T *b = &c->recs[j];
            uint32_t m;
            if (c->order[j] != REFINE_JOIN_PIECE || !refine_joinable(cfg, a, b))
            {
                continue;
            }
            /* b joins a: count, bounds, mean, seed, height. b was neither cut nor has it taken anything (later
             * clusters take only at their own turn), so its record is the canonical one: its members are
             * members[first_member, + n_points) */
            uint32_t d;
            refine_join_mean(c, i, j, first);
            first = 0;
            for (d = 0; d < 3u; ++d)
            {
                REFINE_MIN(a)[d] = REFINE_MIN(b)[d] < REFINE_MIN(a)[d] ? REFINE_MIN(b)[d] : REFINE_MIN(a)[d];
                REFINE_MAX(a)[d] = REFINE_MAX(b)[d] > REFINE_MAX(a)[d] ? REFINE_MAX(b)[d] : REFINE_MAX(a)[d];
            }
            for (m = b->first_member; m < b->first_member + b->n_points; ++m)
            {
                c->labels[c->members[m]] = (uint16_t)(i + 1u);
            }
            a->n_points += b->n_points;
            a->n_rescued += b->n_rescued;
            a->seed_pixel = b->seed_pixel < a->seed_pixel ? b->seed_pixel : a->seed_pixel;
            REFINE_H(a) = REFINE_HEIGHT(c, a->seed_pixel, REFINE_MEAN(a), planes, n_sectors);
            /* b is left empty with the largest seed: the canonical pass puts it last, then it is dropped */
            b->n_points = 0;
            b->seed_pixel = 0xFFFFFFFFu;
            c->order[j] = 2u;
            ++n_joined;
        }
    }
    st->n_joined += n_joined;
    return n_joined > 0u;
}
