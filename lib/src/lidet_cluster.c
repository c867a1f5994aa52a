/* SPDX-License-Identifier: MIT */
/* Depth clustering (see lidet_cluster.h for the algorithm and memory): configuration, the run (candidates,
 * first fill, rescue pass), the filters and records of each component, canonical ids, accessors. The
 * growth is in lidet_cluster_grow.c, the fragment rescue in lidet_cluster_rescue.c.
 * The numpy reference is codegen/lidet_codegen/ref/cluster.py: cluster_ref (these three files) and
 * proposal_indices / make_proposal (lidet_proposal.c). */
#include <math.h>
#include <string.h>

#include "internal/lidet_assert.h"
#include "internal/lidet_cluster_internal.h"
#include "internal/lidet_math.h"

void lidet_cluster_cfg_default(lidet_cluster_cfg_t *cfg, const lidet_sensor_t *sensor)
{
    if (cfg == 0)
    {
        return;
    }
    memset(cfg, 0, sizeof *cfg);
    /* measured on simulated (20 + 20 scans; checked on 12 + 12 scans of other seeds) and real
     * SemanticKITTI scans, docs/BENCHMARKS.md: the 8-neighbourhood keeps the sparse, dotted returns of
     * car bodies together on every profile; a small angle joins the fragments of car bodies (grazing
     * hoods and roofs, dropouts) and the gap bound, growing with range, keeps neighbouring parked cars
     * apart (the merges the angle test alone made on real scans). Dense sensors (> 16 beams) also
     * bridge occluders; 16-beam images use one step less and no occluder rule (speed: >= 100x DBSCAN) */
    cfg->diagonals = 1;
    cfg->max_gap_m = 0.7f;
    if (sensor != 0 && sensor->n_rows <= 16)
    {
        cfg->theta_rad = 0.12f;
        cfg->max_steps = 4u;
        cfg->bridge_occluders = 0;
        cfg->max_gap_per_m = 0.04f;
    }
    else
    {
        cfg->theta_rad = 0.18f;
        cfg->max_steps = 5u;
        cfg->bridge_occluders = 1;
        cfg->max_gap_per_m = 0.025f;
    }
    cfg->max_steps = cfg->max_steps < STEPS ? cfg->max_steps : STEPS;
    cfg->min_points = 10;
    cfg->max_extent_m = 6.0f;
    cfg->max_mean_height_m = 2.5f;
    cfg->mount_height_m = sensor != 0 ? sensor->mount_height_m : 1.73f;
    /* measured (docs/BENCHMARKS.md): see lidet_cluster.h */
    cfg->rescue_gap_m = 0.8f;
    cfg->rescue_gap_per_m = 0.03f;
    cfg->rescue_rows = sensor != 0 && sensor->n_rows <= 16 ? 1u : 2u;
    cfg->rescue_cols = 6u;
    cfg->max_fragment_pixels = sensor != 0 && sensor->n_rows <= 16 ? 2048u : 4096u;
    cfg->max_bridge_per_pixel = 2.0f;
}

lidet_status_t lidet_cluster_state_init(lidet_cluster_state_t *c, const lidet_cluster_cfg_t *cfg)
{
    if (c == 0 || cfg == 0)
    {
        return LIDET_ERR_ARG;
    }
    c->magic = 0;
    if (!lidet__isfinite(cfg->theta_rad) || !(cfg->theta_rad > 0.0f) || !(cfg->theta_rad < 1.5f) ||
        cfg->max_steps < 1 || cfg->max_steps > STEPS || cfg->min_points < 1 ||
        !lidet__isfinite(cfg->max_extent_m) || !(cfg->max_extent_m > 0.0f) ||
        !lidet__isfinite(cfg->max_mean_height_m) || !lidet__isfinite(cfg->mount_height_m) ||
        cfg->mount_height_m < 0.0f || !lidet__isfinite(cfg->max_gap_m) || cfg->max_gap_m < 0.0f ||
        !lidet__isfinite(cfg->max_gap_per_m) || cfg->max_gap_per_m < 0.0f ||
        !(cfg->max_bridge_per_pixel >= 0.0f && cfg->max_bridge_per_pixel <= 64.0f) ||
        !lidet__isfinite(cfg->rescue_gap_m) || cfg->rescue_gap_m < 0.0f ||
        !lidet__isfinite(cfg->rescue_gap_per_m) || cfg->rescue_gap_per_m < 0.0f ||
        cfg->rescue_rows > LIDET_MAX_ROWS || cfg->rescue_cols > RESCUE_MAX_COLS)
    {
        return LIDET_ERR_CONFIG;
    }
    c->cfg = *cfg;
    c->tan_theta = tanf(cfg->theta_rad);
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


/* Capacity drops (a full record table during the first fill): the smallest kept cluster (ties: the later
 * seed) is the one dropped first. The slots live in a binary min-heap on that order, built in c->order
 * (scratch until canonicalise) at the first drop, so each drop costs O(log LIDET_MAX_CLUSTERS) instead of
 * a scan of every slot (issue 19: 13 k tiny clusters took 9x the typical clustering time). */
static int slot_before(const lidet_cluster_state_t *c, uint32_t a, uint32_t b)
{
    const lidet_cluster_rec_t *ra = &c->recs[a], *rb = &c->recs[b];
    return ra->n_points < rb->n_points || (ra->n_points == rb->n_points && ra->seed_pixel > rb->seed_pixel);
}

static void heap_down(lidet_cluster_state_t *c, uint32_t i, uint32_t n)
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

static void heap_build(lidet_cluster_state_t *c)
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

/* sum, min and max of the points of members[start, tail) (tail > start). Returns 1 (the sums then
 * incomplete) as soon as an x, y or z extent exceeds max_extent: the test runs after every block of
 * 64 members, so a wall stops early instead of being summed to its end */
static inline int member_stats_of(const lidet_cluster_state_t *c, uint32_t start, uint32_t tail, float max_extent,
                                  float sum[3], float lo[3], float hi[3], int compact)
{
    const lidet_range_image_t *img = &c->img;
    const int32_t *mem = c->members;
    float sx = 0.0f, sy = 0.0f, sz = 0.0f;
    float lx, ly, lz, hx, hy, hz;
    uint32_t i = start, over = 0;
    lidet__img_xyz(img, (uint32_t)mem[start], compact, &lx, &ly, &lz);
    hx = lx;
    hy = ly;
    hz = lz;
    while (i < tail && over == 0u)
    {
        const uint32_t e = tail - i < 64u ? tail : i + 64u;
        for (; i < e; ++i)
        {
            float x, y, z;
            lidet__img_xyz(img, (uint32_t)mem[i], compact, &x, &y, &z);
            sx += x;
            sy += y;
            sz += z;
            lx = x < lx ? x : lx;
            ly = y < ly ? y : ly;
            lz = z < lz ? z : lz;
            hx = x > hx ? x : hx;
            hy = y > hy ? y : hy;
            hz = z > hz ? z : hz;
        }
        over = (uint32_t)(hx - lx > max_extent) | (uint32_t)(hy - ly > max_extent) | (uint32_t)(hz - lz > max_extent);
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

/* member_stats_of with the image format a constant in each copy */
static int member_stats(const lidet_cluster_state_t *c, uint32_t start, uint32_t tail, float max_extent, float sum[3],
                        float lo[3], float hi[3])
{
    return lidet__img_compact(&c->img) ? member_stats_of(c, start, tail, max_extent, sum, lo, hi, 1)
                                       : member_stats_of(c, start, tail, max_extent, sum, lo, hi, 0);
}

/* height of `mean` above the ground plane of the sector of the seed's column (or the flat ground) */
static float height_above_ground(const lidet_cluster_state_t *c, uint32_t seed, const float mean[3],
                                 const lidet_plane_t *planes, uint32_t n_sectors)
{
    if (planes != 0)
    {
        /* seed < rows * cols so the product fits in 64 bits */
        const uint32_t col = seed % c->img.n_cols;
        uint32_t s = (uint32_t)(((uint64_t)col * n_sectors) / c->img.n_cols);
        const lidet_plane_t *pl;
        s = s < n_sectors ? s : n_sectors - 1;
        pl = &planes[s];
        return pl->nx * mean[0] + pl->ny * mean[1] + pl->nz * mean[2] + pl->d_m;
    }
    return mean[2] + c->cfg.mount_height_m;
}

/* filters + bookkeeping of the component members[start, tail); returns the new tail. rescue = 0:
 * a component of the first fill (one below min_points becomes a fragment when the rescue is on);
 * 1: a rescue group that joined no cluster (dropped when small; takes only a free slot) */
static uint32_t finish_cluster(lidet_cluster_state_t *c, uint32_t start, uint32_t tail, const lidet_plane_t *planes,
                               uint32_t n_sectors, lidet_cluster_stats_t *st, int rescue)
{
    const uint32_t n = tail - start;
    const int32_t *mem = c->members;
    float sum[3], lo[3], hi[3], mean[3], h, inv;
    uint32_t i, slot;
    int small, evicted = 0;
    lidet_cluster_rec_t *rec;

    if (!rescue)
    {
        ++st->n_found;
    }
    small = n < c->cfg.min_points;
    if (small && (rescue || !(c->cfg.rescue_gap_m > 0.0f)))
    {
        ++st->n_dropped_small;
        return start;
    }
    /* the rescue budget, before any statistics: past it a fragment-to-be costs nothing more */
    if (small && c->cfg.max_fragment_pixels != 0u && st->n_fragment_pixels + n > c->cfg.max_fragment_pixels)
    {
        ++st->n_dropped_fragment_budget;
        return start;
    }
    /* the same filters for a fragment-to-be (small: no extent limit), so that one above the height
     * limit (canopies, wires: nothing a road user would take in) never reaches the rescue; it saves
     * a third of the rescue's work */
    if (member_stats(c, start, tail, small ? 3.0e38f : c->cfg.max_extent_m, sum, lo, hi))
    {
        ++st->n_dropped_extent;
        return start;
    }
    inv = 1.0f / (float)n;
    mean[0] = sum[0] * inv;
    mean[1] = sum[1] * inv;
    mean[2] = sum[2] * inv;
    h = height_above_ground(c, (uint32_t)mem[start], mean, planes, n_sectors);
    if (!(h <= c->cfg.max_mean_height_m))
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
    if (c->n_recs < LIDET_MAX_CLUSTERS)
    {
        slot = c->n_recs++;
    }
    else
    {
        /* full: the new cluster has the latest seed, so it loses every tie. A rescue group takes only a
         * free slot; in the first fill the heap (built at the first drop) holds the smallest at its top */
        uint32_t m;
        ++st->n_dropped_capacity;
        if (rescue)
        {
            return start;
        }
        if (st->n_dropped_capacity == 1u)
        {
            heap_build(c);
        }
        m = c->order[0];
        if (n <= c->recs[m].n_points)
        {
            return start;
        }
        /* evict m: its pixels become "visited, dropped"; its member range stays as a hole that the
         * final raster pass compacts away (only first-fill clusters are evicted, and they own
         * exactly their member range) */
        for (i = c->recs[m].first_member; i < c->recs[m].first_member + c->recs[m].n_points; ++i)
        {
            c->labels[mem[i]] = (uint16_t)LAB_PENDING;
        }
        slot = m;
        evicted = 1;
    }
    rec = &c->recs[slot];
    rec->n_points = n;
    rec->first_member = start;
    rec->seed_pixel = (uint32_t)mem[start];
    rec->n_rescued = rescue ? n : 0u;
    for (i = 0; i < 3; ++i)
    {
        rec->mean_m[i] = mean[i];
        rec->min_m[i] = lo[i];
        rec->max_m[i] = hi[i];
    }
    rec->height_m = h;
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

/* a rescue group members[start, tail) joins kept cluster `slot`: count, bounds and mean are
 * updated (mean = (mean * n_old + group sum) / n_new, in float) and the height recomputed. The
 * group's seed is its first pixel in raster order, so the cluster's first pixel is the smaller of
 * the two seeds (the height uses that pixel's sector, as for any cluster) */
static void rescue_join(lidet_cluster_state_t *c, uint32_t slot, uint32_t start, uint32_t tail, const lidet_plane_t *planes,
                        uint32_t n_sectors, lidet_cluster_stats_t *st)
{
    lidet_cluster_rec_t *rec = &c->recs[slot];
    const uint32_t n = tail - start, seed = (uint32_t)c->members[start];
    const float inv = 1.0f / (float)(rec->n_points + n);
    float sum[3], lo[3], hi[3];
    uint32_t i;
    (void)member_stats(c, start, tail, 3.0e38f, sum, lo, hi);
    for (i = 0; i < 3; ++i)
    {
        rec->mean_m[i] = (rec->mean_m[i] * (float)rec->n_points + sum[i]) * inv;
        rec->min_m[i] = lo[i] < rec->min_m[i] ? lo[i] : rec->min_m[i];
        rec->max_m[i] = hi[i] > rec->max_m[i] ? hi[i] : rec->max_m[i];
    }
    for (i = start; i < tail; ++i)
    {
        c->labels[c->members[i]] = (uint16_t)(slot + 1u);
    }
    rec->n_points += n;
    rec->n_rescued += n;
    rec->seed_pixel = seed < rec->seed_pixel ? seed : rec->seed_pixel;
    rec->height_m = height_above_ground(c, rec->seed_pixel, rec->mean_m, planes, n_sectors);
    ++st->n_rescue_joined;
    st->n_rescue_pixels += n;
}

/* canonical id of kept pixel i (label slot + 1, or 0 = none), appended to its cluster's members */
static inline void place_kept(lidet_cluster_state_t *c, uint16_t *lab, uint32_t i)
{
    const uint32_t l = lab[i];
    if (l != 0u)
    {
        const uint32_t id = c->slot_id[l];
        lab[i] = (uint16_t)id;
        c->members[c->recs[id - 1u].first_member++] = (int32_t)i;
    }
}

/* canonical order: records sorted by seed, labels rewritten, members regrouped in raster order */
static void canonicalise(lidet_cluster_state_t *c, uint32_t npix, lidet_cluster_stats_t *st)
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
        lidet_cluster_rec_t tmp;
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
    /* every pixel that is not in a kept cluster (non-candidate, dropped; none is still free) -> 0,
     * without a branch (it vectorises); kept pixels keep slot + 1 */
    for (i = 0; i < npix; ++i)
    {
        const uint32_t l = lab[i];
        lab[i] = (uint16_t)(l < LAB_SMALL ? l : 0u);
    }
    /* slot + 1 -> id and the members in raster order. Kept pixels are a minority: blocks of four
     * labels that are all 0 (one 64-bit word, read with memcpy) are skipped at once */
    for (i = 0; i + 4u <= npix; i += 4u)
    {
        uint64_t w;
        memcpy(&w, &lab[i], sizeof w);
        if (w != 0u)
        {
            place_kept(c, lab, i);
            place_kept(c, lab, i + 1u);
            place_kept(c, lab, i + 2u);
            place_kept(c, lab, i + 3u);
        }
    }
    for (; i < npix; ++i)
    {
        place_kept(c, lab, i);
    }
    for (i = 0; i < k; ++i)
    {
        c->recs[i].first_member -= c->recs[i].n_points;
    }
}

/* the first free pixel (label 0) at or after p, npix if none. Seeds are rare once most pixels are
 * visited: four labels at a time (a 64-bit word, read with memcpy) are skipped when none is 0. The
 * test (w - 0x0001..) & ~w & 0x8000.. is nonzero exactly when some 16-bit lane of w is zero (a
 * borrow only starts at a zero lane, and the lowest zero lane always sets its top bit) */
static inline uint32_t next_free(const uint16_t *lab, uint32_t p, uint32_t npix)
{
    for (;;)
    {
        while (p + 4u <= npix)
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

lidet_status_t lidet_cluster_run_buffers(lidet_cluster_state_t *c, uint16_t *labels, int32_t *members,
                                         const lidet_range_image_t *img, const uint8_t *ground_mask,
                                         const lidet_plane_t *planes, uint32_t n_sectors)
{
    uint32_t rows, cols, npix, p, tail, ks;
    uint16_t *lab;
    int32_t *mem;
    lidet__grow_t lk;
    lidet_cluster_stats_t st;

    if (c == 0 || labels == 0 || members == 0 || img == 0 || (planes != 0 && n_sectors == 0))
    {
        return LIDET_ERR_ARG;
    }
    if (c->magic != LIDET_INIT_MAGIC)
    {
        return LIDET_ERR_STATE;
    }
    rows = img->n_rows;
    cols = img->n_cols;
    if (rows < 1 || cols < 2 || rows > LIDET_MAX_ROWS || cols > LIDET_MAX_COLS)
    {
        return LIDET_ERR_BUFFER;
    }
    if (img->row_elev_rad == 0 || !lidet__img_complete(img))
    {
        return LIDET_ERR_ARG;
    }
    npix = rows * cols;
    lidet__cluster_setup_geometry(c, img);
    c->img = *img;
    c->labels = labels;
    c->members = members;
    c->n_recs = 0;
    memset(&st, 0, sizeof st);
    lab = c->labels;
    mem = c->members;
    ks = c->cfg.max_steps;
    lk.rows = rows;
    lk.cols = cols;
    lk.ks = ks;
    lk.kc = ks < cols - 1 ? ks : cols - 1; /* never wrap onto itself */
    lk.diag = c->cfg.diagonals != 0;
    lk.tan_theta = c->tan_theta;
    lk.gap = c->cfg.max_gap_m;
    lk.gpm = c->cfg.max_gap_per_m;
    lk.rgap = c->cfg.rescue_gap_m;
    lk.rgpm = c->cfg.rescue_gap_per_m;
    lk.rrows = c->cfg.rescue_rows;
    lk.rcols = c->cfg.rescue_cols < (cols - 1u) / 2u ? c->cfg.rescue_cols : (cols - 1u) / 2u;
    lk.bridge_max = 0xFFFFFFFFu; /* set once the candidates are counted */
    lk.bridged = &st.n_bridge_steps;
    /* row of pixel q without a division: floor(q * m / 2^32) with m = floor(2^32 / cols) + 1 is
     * floor(q / cols) exactly when q * cols < 2^32 (m exceeds 2^32 / cols by e in (0, 1], so the
     * quotient is overestimated by q e / 2^32 < 1 / cols, less than the distance of q / cols to the
     * next integer). q < npix, so npix * cols <= 2^32 suffices (128 x 2048: 2^29); else divide */
    lk.row_magic = (uint64_t)npix * cols <= 0xFFFFFFFFu ? (uint32_t)(0xFFFFFFFFu / cols) + 1u : 0u;

    /* candidates: FREE (0) or NONCAND (0xFFFF) = cand - 1 in 16 bits; no branch, so it vectorises.
     * A pixel holds a point iff its range is > 0 (the image contract; point_idx may be absent) */
    {
        const float *prng = img->range_m;
        uint32_t n_cand = 0;
        if (lidet__img_compact(img))
        {
            /* compact image: a valid pixel has range_4mm >= 1 */
            const uint16_t *qrng = img->range_4mm;
            for (p = 0; p < npix; ++p)
            {
                const uint32_t cand =
                    (uint32_t)(qrng[p] > 0u) & (uint32_t)(ground_mask == 0 || ground_mask[p] == 0);
                lab[p] = (uint16_t)(cand - 1u);
                n_cand += cand;
            }
        }
        else if (ground_mask != 0)
        {
            for (p = 0; p < npix; ++p)
            {
                const uint32_t cand = (uint32_t)(prng[p] > 0.0f) & (uint32_t)(ground_mask[p] == 0);
                lab[p] = (uint16_t)(cand - 1u);
                n_cand += cand;
            }
        }
        else
        {
            for (p = 0; p < npix; ++p)
            {
                const uint32_t cand = (uint32_t)(prng[p] > 0.0f);
                lab[p] = (uint16_t)(cand - 1u);
                n_cand += cand;
            }
        }
        st.n_candidates = n_cand;
        if (c->cfg.max_bridge_per_pixel > 0.0f)
        {
            /* <= 64 * 2^24 * 4: fits */
            lk.bridge_max = (uint32_t)(c->cfg.max_bridge_per_pixel * (float)n_cand);
        }
    }

    tail = 0;
    for (p = next_free(lab, 0, npix); p < npix; p = next_free(lab, p + 1u, npix))
    {
        uint32_t start;
        start = tail;
        lab[p] = (uint16_t)LAB_PENDING;
        mem[tail++] = (int32_t)p;
        tail = lidet__cluster_grow(c, &lk, start, tail);
        tail = finish_cluster(c, start, tail, planes, n_sectors, &st, 0);
    }
    /* the rescue pass over the fragments (LAB_SMALL), groups seeded in raster order. Kept pixels,
     * the fragments and the current group are distinct pixels, so the member array holds them */
    if (st.n_fragments > 0u)
    {
        for (p = next_fragment(lab, 0, npix); p < npix; p = next_fragment(lab, p + 1u, npix))
        {
            lidet__rescue_t rs;
            const uint32_t start = tail;
            lab[p] = (uint16_t)LAB_PENDING;
            mem[tail++] = (int32_t)p;
            rs.tail = tail;
            rs.best = 0u;
            rs.best_d2 = 3.0e38f;
            lidet__cluster_rescue_grow(c, &lk, start, &rs);
            if (rs.best != 0u)
            {
                rescue_join(c, rs.best - 1u, start, rs.tail, planes, n_sectors, &st);
                tail = start;
            }
            else
            {
                tail = finish_cluster(c, start, rs.tail, planes, n_sectors, &st, 1);
            }
        }
    }
    canonicalise(c, npix, &st);
    st.n_kept = c->n_recs;
    c->stats = st;
    return st.n_dropped_capacity > 0 ? LIDET_TRUNCATED : LIDET_OK;
}

lidet_status_t lidet_cluster_init(lidet_cluster_t *c, const lidet_cluster_cfg_t *cfg)
{
    return c == 0 ? LIDET_ERR_ARG : lidet_cluster_state_init(&c->state, cfg);
}

lidet_status_t lidet_cluster_run(lidet_cluster_t *c, const lidet_range_image_t *img, const uint8_t *ground_mask,
                                 const lidet_plane_t *planes, uint32_t n_sectors)
{
    if (c == 0)
    {
        return LIDET_ERR_ARG;
    }
    return lidet_cluster_run_buffers(&c->state, c->labels, c->members, img, ground_mask, planes, n_sectors);
}

const uint16_t *lidet_cluster_labels(const lidet_cluster_t *c)
{
    return c == 0 ? 0 : c->labels;
}

const lidet_cluster_rec_t *lidet_cluster_records(const lidet_cluster_t *c, uint32_t *n_clusters)
{
    if (c == 0)
    {
        return 0;
    }
    if (n_clusters != 0)
    {
        *n_clusters = c->state.n_recs;
    }
    return c->state.recs;
}

const int32_t *lidet_cluster_members(const lidet_cluster_t *c)
{
    return c == 0 ? 0 : c->members;
}

const lidet_cluster_stats_t *lidet_cluster_stats(const lidet_cluster_t *c)
{
    return c == 0 ? 0 : &c->state.stats;
}

lidet_status_t lidet_cluster_point_labels_of(const lidet_cluster_state_t *c, const int32_t *point_pixel,
                                             uint32_t n_points, uint32_t *out)
{
    uint32_t i, npix;
    if (c == 0 || ((point_pixel == 0 || out == 0) && n_points > 0))
    {
        return LIDET_ERR_ARG;
    }
    if (c->magic != LIDET_INIT_MAGIC || c->labels == 0)
    {
        return LIDET_ERR_STATE;
    }
    npix = (uint32_t)c->img.n_rows * c->img.n_cols;
    for (i = 0; i < n_points; ++i)
    {
        const int32_t p = point_pixel[i];
        out[i] = (p >= 0 && (uint32_t)p < npix) ? c->labels[p] : 0u;
    }
    return LIDET_OK;
}

lidet_status_t lidet_cluster_point_labels(const lidet_cluster_t *c, const int32_t *point_pixel,
                                          uint32_t n_points, uint32_t *out)
{
    return c == 0 ? LIDET_ERR_ARG : lidet_cluster_point_labels_of(&c->state, point_pixel, n_points, out);
}

uint32_t lidet_cluster_bytes(void)
{
    return (uint32_t)sizeof(lidet_cluster_t);
}

uint32_t lidet_cluster_state_bytes(void)
{
    return (uint32_t)sizeof(lidet_cluster_state_t);
}
