/* SPDX-License-Identifier: MIT */
/* The integer detector (lidet_detector_q.h): the integer stages chained as lidet_detector.c chains the float
 * ones (same candidate order, budget, gates, size check, score and NMS rules). Integers only; mirrored by
 * codegen/lidet_ref/detector_q.py. */
#include <string.h>

#include "internal/lidet_ground_internal.h"
#include "internal/lidet_ground_q_internal.h"
#include "internal/lidet_group_q.h"
#include "internal/lidet_pointnet_q_internal.h"
#include "internal/lidet_qmath.h"
#include "internal/lidet_qpix.h"
#include "internal/lidet_sort.h"
#include "lidet/lidet_detector_q.h"

#define NMS_IOU_DEFAULT_Q15 3277 /* 0.1 */

void lidet_detector_q_cfg_default(lidet_detector_q_cfg_t *cfg, const lidet_sensor_q_t *sensor)
{
    uint32_t rows;
    int32_t mount;
    if (cfg == 0)
    {
        return;
    }
    memset(cfg, 0, sizeof *cfg);
    rows = sensor != 0 ? sensor->n_rows : 64u;
    mount = sensor != 0 ? sensor->mount_height_mm : 1730;
    lidet_proj_q_cfg_default(&cfg->proj, sensor);
    lidet_ground_q_cfg_default(&cfg->ground, rows, mount);
    lidet_cluster_q_cfg_default(&cfg->cluster, rows, mount > 0 ? (uint32_t)mount : 0u);
    lidet_proposal_q_cfg_default(&cfg->proposal);
    /* as the float detector: 100-300 kept clusters per real HDL-64 scan, 20-50 per simulated VLP-16 scan */
    cfg->max_proposals = rows <= 16u ? 128u : 256u;
    if (cfg->max_proposals > LIDET_MAX_CLUSTERS)
    {
        cfg->max_proposals = LIDET_MAX_CLUSTERS;
    }
    cfg->max_boxes = rows <= 16u ? 24u : 48u;
    if (cfg->max_boxes > LIDET_MAX_CLUSTERS)
    {
        cfg->max_boxes = LIDET_MAX_CLUSTERS;
    }
    cfg->range_only = (uint8_t)!LIDET_Q_PIXEL_XYZ;
    cfg->gate1 = 1u;
    cfg->gate2 = 1u;
    cfg->gate1_margin_q16 = 0;
    cfg->gate2_margin_q16 = 0;
    cfg->gate1_class_margin_q16[LIDET_CLASS_CAR] = 0; /* the float detector's: the models' thresholds */
    cfg->gate1_class_margin_q16[LIDET_CLASS_CYCLIST] = 0;
    cfg->gate1_class_margin_q16[LIDET_CLASS_PEDESTRIAN] = 0;
    cfg->gate1_large_car_margin_q16 = rows <= 16u ? 0 : 65536; /* the float detector's */
    cfg->gate2_class[LIDET_CLASS_CAR] = 1u; /* the float detector's: pedestrians pass gate 2 */
    cfg->gate2_class[LIDET_CLASS_CYCLIST] = 1u;
    cfg->gate2_class[LIDET_CLASS_PEDESTRIAN] = 0u;
    cfg->group_split = rows <= 16u ? 0u : 1u; /* the float detector's */
    cfg->group_max_range_mm = 40000;
    cfg->group_gate1_margin_q16 = 2 * 65536; /* the float detector's */
    /* the float detector's operating point and flat-surface test: 0.6 in Q15 = round(0.6 * 32768) */
    cfg->min_score_q15[LIDET_CLASS_CAR] = 19661;
    cfg->min_score_q15[LIDET_CLASS_CYCLIST] = 0;
    cfg->min_score_q15[LIDET_CLASS_PEDESTRIAN] = 0;
    cfg->car_min_z_spread_mm = rows <= 16u ? 0 : 600;
    cfg->car_ground_mm = !LIDET_Q_PIXEL_XYZ ? 0 : 1000; /* the float detector's car_ground_m */
    cfg->score_box_weight_q16[LIDET_CLASS_CAR] = 32768; /* the float detector's 0.5 */
    cfg->score_box_weight_q16[LIDET_CLASS_CYCLIST] = 0;
    cfg->score_box_weight_q16[LIDET_CLASS_PEDESTRIAN] = 0;
    cfg->score_points_weight_q16[LIDET_CLASS_CAR] = 6554; /* the float detector's 0.1 */
    cfg->score_points_weight_q16[LIDET_CLASS_CYCLIST] = 0;
    cfg->score_points_weight_q16[LIDET_CLASS_PEDESTRIAN] = 0;
    cfg->nms_iou_q15 = NMS_IOU_DEFAULT_Q15;
    cfg->max_height_extent_mm = 2500; /* the float detector's max_height_extent_m */
    lidet_size_limits_q_default(&cfg->size);
}

/* round(ln(64) * 2^16): the score's point count is ln(n / 64) */
#define LN64_Q16 272557
/* the gates' margins: within +-20 nats, as the float detector's */
#define MARGIN_MAX_Q16 (20 * 65536)

static int cfg_ok(const lidet_detector_q_cfg_t *c)
{
    uint32_t k, j;
    if (c->crop_half_bam < 0 || c->max_range_mm < 0 || c->max_height_extent_mm < 0 ||
        c->max_height_extent_mm > 100000 || c->max_proposals < 1u || c->max_proposals > LIDET_MAX_CLUSTERS ||
        c->max_boxes < 1u || c->max_boxes > LIDET_MAX_CLUSTERS || c->gate1 > 1u || c->gate2 > 1u ||
        c->nms_iou_q15 < 0 || c->nms_iou_q15 > 32768 || c->gate1_margin_q16 < -MARGIN_MAX_Q16 ||
        c->gate1_margin_q16 > MARGIN_MAX_Q16 || c->gate2_margin_q16 < -MARGIN_MAX_Q16 ||
        c->gate2_margin_q16 > MARGIN_MAX_Q16 || c->range_only > 1u || c->group_split > 1u ||
        c->group_max_range_mm < 0 || c->group_max_range_mm > 1000000 || c->group_gate1_margin_q16 < 0 ||
        c->group_gate1_margin_q16 > MARGIN_MAX_Q16 || c->car_min_z_spread_mm < 0 ||
        c->car_min_z_spread_mm > 10000 || (!LIDET_Q_PIXEL_XYZ && c->range_only == 0u) ||
        c->car_ground_mm < 0 || c->car_ground_mm > 10000 || (!LIDET_Q_PIXEL_XYZ && c->car_ground_mm != 0) ||
        c->gate1_large_car_margin_q16 < 0 || c->gate1_large_car_margin_q16 > MARGIN_MAX_Q16 ||
        c->stream_sectors > 1u || (c->stream_sectors && !c->range_only))
    {
        return 0;
    }
    for (k = 0; k < (uint32_t)LIDET_N_CLASSES; ++k)
    {
        if (c->gate2_class[k] > 1u || c->min_score_q15[k] < 0 || c->min_score_q15[k] > 32768 ||
            c->gate1_class_margin_q16[k] < -MARGIN_MAX_Q16 || c->gate1_class_margin_q16[k] > MARGIN_MAX_Q16)
        {
            return 0;
        }
        if (c->score_box_weight_q16[k] < 0 || c->score_box_weight_q16[k] > 4 * 65536 ||
            c->score_points_weight_q16[k] < 0 || c->score_points_weight_q16[k] > 4 * 65536)
        {
            return 0;
        }
        for (j = 0; j < 3u; ++j)
        {
            if (c->size.min_mm[k][j] < 1 || c->size.min_mm[k][j] > c->size.max_mm[k][j] ||
                c->size.max_mm[k][j] > LIDET_Q_BOX_MAX_MM)
            {
                return 0;
            }
        }
    }
    return 1;
}

/* |a - b| <= b / 1000 + 1: a model's PVLE bin against the configuration's (unit conversions round) */
static int near(int64_t a, int64_t b)
{
    const int64_t d = a > b ? a - b : b - a;
    return d <= b / 1000 + 1;
}

lidet_status_t lidet_detector_q_init(lidet_detector_q_t *d, const lidet_detector_q_cfg_t *cfg,
                                     const lidet_pointnet_q_model_t *cls, const lidet_pointnet_q_model_t *box)
{
    lidet_status_t s;
    if (d == 0 || cfg == 0 || cls == 0 || box == 0)
    {
        return LIDET_ERR_ARG;
    }
    d->magic = 0;
    if (!cfg_ok(cfg))
    {
        return LIDET_ERR_CONFIG;
    }
    if (lidet_pointnet_q_check(cls, LIDET_PN_CLASSIFIER, 0) != LIDET_OK ||
        lidet_pointnet_q_check(box, LIDET_PN_BOX, 0) != LIDET_OK || cls->n_points != box->n_points ||
        cls->n_points > LIDET_PROPOSAL_POINTS || cls->z_origin != box->z_origin ||
        cls->z_origin > LIDET_PROPOSAL_Z_GROUND)
    {
        return LIDET_ERR_MODEL;
    }
    /* the voxels the models were trained with: azimuth, elevation in microradians, range in mm */
    if (!near(lidet__q_urad_to_bam(cls->pvle_bin[0]), cfg->proposal.azimuth_bin_bam) ||
        !near(lidet__q_urad_to_bam(cls->pvle_bin[1]), cfg->proposal.elevation_bin_bam) ||
        !near(cls->pvle_bin[2], 4 * (int64_t)cfg->proposal.range_bin_4mm) ||
        cls->pvle_bin[0] != box->pvle_bin[0] || cls->pvle_bin[1] != box->pvle_bin[1] ||
        cls->pvle_bin[2] != box->pvle_bin[2])
    {
        return LIDET_ERR_MODEL;
    }
    d->cfg = *cfg;
    d->cfg.proposal.n_points = cls->n_points;
    d->cfg.proposal.z_origin = cls->z_origin; /* the proposals the models were trained on */
    if (cfg->crop_half_bam > 0)
    {
        /* the crop: the ground's RANSAC draws a stream per cell, as the float detector's crop does, so that
         * both builds draw the same samples of a sector (the float detector needs it for its windows) */
        d->cfg.ground.seed_per_cell = 1u;
    }
    if (cfg->stream_sectors)
    {
        /* a sector's plane from its own samples alone, whichever sector the stream does first */
        d->cfg.ground.seed_per_cell = 1u;
    }
    s = lidet_proj_q_init(&d->proj, &d->cfg.proj);
    if (s == LIDET_OK)
    {
        s = lidet_ground_q_state_init(&d->ground, &d->cfg.ground);
    }
    if (s == LIDET_OK)
    {
        /* the height filter reads the ground's far planes beyond its split (the whole plane table is passed) */
        lidet_cluster_q_cfg_t ccfg = d->cfg.cluster;
        ccfg.plane_split_mm = d->cfg.ground.ring_split_mm;
        s = lidet_cluster_q_state_init(&d->cluster, &ccfg);
    }
    if (s == LIDET_OK)
    {
        s = lidet_pointnet_q_init(&d->cls, cls, d->pn_scratch, sizeof d->pn_scratch, 0);
    }
    if (s == LIDET_OK)
    {
        s = lidet_pointnet_q_init(&d->box, box, d->pn_scratch, sizeof d->pn_scratch, 0);
    }
    if (s != LIDET_OK)
    {
        return s;
    }
    d->n_det = 0;
    memset(&d->stats, 0, sizeof d->stats);
    d->magic = LIDET_INIT_MAGIC;
    return LIDET_OK;
}

/* The ground mask: its own array, or (LIDET_Q_PIXEL_XYZ 0, the 256 KiB VLP-16 build) the ground scratch's sample
 * mask bytes, dead once the samples are gathered; the clustering's members overlay them but are written only
 * after its candidates are marked from the mask (the labels lie past them in the union) */
static uint8_t *ground_mask(lidet_detector_q_t *d)
{
#if LIDET_Q_PIXEL_XYZ
    return d->mask;
#else
    return d->scratch.ground.sample;
#endif
}

static uint32_t now(const lidet_detector_q_t *d)
{
    return d->cfg.clock != 0 ? d->cfg.clock(d->cfg.clock_ctx) : 0u;
}

int32_t lidet_detector_q_score(int32_t energy_q16, int32_t gamma_q16)
{
    /* 1 / (1 + e^t), t = E - gamma: e^-|t| in Q30, then a Q15 quotient */
    const int64_t t = (int64_t)energy_q16 - gamma_q16;
    const int64_t e = lidet__pnq_exp_neg_q30(t >= 0 ? t : -t);
    const int64_t one = (int64_t)1 << 30;
    return (int32_t)(t >= 0 ? (e << 15) / (one + e) : (one << 15) / (one + e));
}

void lidet_detector_q_image(const lidet_detector_q_t *d, lidet_range_image_t *img)
{
    lidet_proj_q_buffers_t b;
    if (d == 0 || img == 0)
    {
        return;
    }
    memset(&b, 0, sizeof b);
#if LIDET_Q_PIXEL_XYZ
    if (!d->cfg.range_only)
    {
        b.x_4mm = (int16_t *)(uintptr_t)d->x_4mm; /* the image is read-only; the buffers type is shared */
        b.y_4mm = (int16_t *)(uintptr_t)d->y_4mm;
        b.z_4mm = (int16_t *)(uintptr_t)d->z_4mm;
    }
#endif
    b.range_4mm = (uint16_t *)(uintptr_t)d->range_4mm;
    b.point_idx = 0;
    lidet_proj_q_image(&d->proj, &b, img);
    img->point_idx = 0; /* overlaid by the later stages' scratch */
}

/* candidates: kept clusters in the azimuth window and range, nearest first, at most max_proposals */
static uint32_t candidates(lidet_detector_q_t *d, lidet_status_t *worst)
{
    lidet_detector_q_stats_t *st = &d->stats;
    const lidet_cluster_q_rec_t *recs = d->cluster.recs;
    const uint32_t n_rec = d->cluster.n_recs;
    const int crop = d->cfg.crop_half_bam > 0;
    const int64_t cs = crop ? lidet__q_sin((uint32_t)d->cfg.crop_half_bam) : 0;
    const int64_t cc = crop ? lidet__q_cos((uint32_t)d->cfg.crop_half_bam) : 0;
    /* max range in 4 mm steps, squared: (mm / 4)^2 compared as 16 r2 > mm^2 */
    const int64_t max_mm2 = (int64_t)d->cfg.max_range_mm * d->cfg.max_range_mm;
    uint32_t i, n = 0;
    for (i = 0; i < n_rec; ++i)
    {
        const int64_t x = recs[i].mean_4mm[0], y = recs[i].mean_4mm[1];
        const int64_t r2 = x * x + y * y; /* < 2^31: |x|, |y| <= 2^15 */
        /* |atan2(y, x)| <= h  <=>  x sin h >= |y| cos h, for any h in (0, pi) */
        if (crop && !(x * cs >= (y < 0 ? -y : y) * cc))
        {
            d->outcome[i] = LIDET_DET_OUT_CROP;
            ++st->n_out_of_crop;
            continue;
        }
        /* z extent in 4 mm steps against the limit in mm: 4 (max - min) > limit (|max - min| < 2^17) */
        if (d->cfg.max_height_extent_mm > 0 &&
            4 * (int64_t)(recs[i].max_4mm[2] - recs[i].min_4mm[2]) > d->cfg.max_height_extent_mm)
        {
            d->outcome[i] = LIDET_DET_OUT_TALL;
            ++st->n_too_tall;
            continue;
        }
        if (d->cfg.max_range_mm > 0 && 16 * r2 > max_mm2)
        {
            d->outcome[i] = LIDET_DET_OUT_RANGE;
            ++st->n_out_of_range;
            continue;
        }
        d->key[n] = (uint32_t)r2;
        d->order[n] = (uint16_t)i;
        ++n;
    }
    if (n > d->cfg.max_proposals)
    {
        *worst = LIDET_TRUNCATED;
    }
    return lidet__nearest_first(d->key, d->order, n, d->cfg.max_proposals, d->outcome, LIDET_DET_OUT_BUDGET,
                                &st->n_over_budget);
}

/* the per-candidate loop (internal/lidet_detector_body.h), with the integer detector's types and numbers */
static void fill_detection(const lidet_detector_q_t *d, lidet_detection_q_t *t, uint32_t ci,
                           const lidet_pointnet_q_class_out_t *co, const lidet_pointnet_q_box_out_t *bo)
{
    (void)ci;
    t->reserved = 0;
    /* the score's energy: E1 + round(w (E2 - gamma2)) - round(v ln(n / 64)) (Q16, |.| < 2^51 before the
     * shifts), saturated to int32; ln n only where v is not 0, as the float detector */
    const int64_t m2 = (int64_t)bo->energy_q16 - d->box.model->gamma_q16[co->cls];
    const int32_t v = d->cfg.score_points_weight_q16[co->cls];
    const uint32_t n = d->proposal.n_points_src; /* the cluster's member pixels, or the group part's */
    int64_t e =
        (int64_t)co->energy_q16 + lidet__q_rshift_round(m2 * d->cfg.score_box_weight_q16[co->cls], 16);
    if (v != 0)
    {
        e -= lidet__q_rshift_round((lidet__pnq_ln_q16((int64_t)(n > 0u ? n : 1u) << 30) - LN64_Q16) * v, 16);
    }
    e = e < INT32_MIN ? INT32_MIN : (e > INT32_MAX ? INT32_MAX : e);
    t->score_q15 = lidet_detector_q_score((int32_t)e, d->cls.model->gamma_q16[co->cls]);
    t->energy_cls_q16 = co->energy_q16;
    t->energy_box_q16 = bo->energy_q16;
    t->n_points = n;
}
/* the float detector's flat_surface in 4 mm steps: at least LIDET_DET_FLAT_MIN_POINTS members and
 * 12 sum dz^2 < (t / 4)^2 n, i.e. 192 sum dz^2 < t^2 n with t in mm (dz from the rounded mean; |sum| < 2^50) */
static int flat_surface(const lidet_detector_q_t *d, uint32_t ci)
{
    const lidet_cluster_q_state_t *c = &d->cluster;
    const lidet_cluster_q_rec_t *r = &c->recs[ci];
    const int64_t t = d->cfg.car_min_z_spread_mm;
    int64_t szz = 0;
    uint32_t i;
    if (t <= 0 || r->n_points < LIDET_DET_FLAT_MIN_POINTS)
    {
        return 0;
    }
    for (i = 0; i < r->n_points; ++i)
    {
        int32_t v[3];
        lidet__qpix_xyz(&c->img, (uint32_t)c->members[r->first_member + i], v);
        szz += (int64_t)(v[2] - r->mean_4mm[2]) * (v[2] - r->mean_4mm[2]);
    }
    return 192 * szz < t * t * (int64_t)r->n_points;
}
/* the image column of the azimuth of (x, y) (lidet_proj.h's rule, from the BAM32 atan2: floor((pi - az) / 2 pi
 * n_cols)); the projection finds a point's column from its exact edges, which this may miss by one */
static uint32_t column_q(int32_t x_mm, int32_t y_mm, uint32_t cols)
{
    const uint32_t a = 0x80000000u - (uint32_t)lidet__q_atan2(y_mm, x_mm);
    return (uint32_t)(((uint64_t)a * cols) >> 32);
}

/* 1 when (dx, dy) mm from the box centre lies within the doubled half-extents L, W (Q30) in the box frame */
static int in_footprint(int64_t c, int64_t s, int64_t dx, int64_t dy, int64_t L, int64_t W)
{
    const int64_t u2 = 2 * (c * dx + s * dy), v2 = 2 * (c * dy - s * dx);
    return (u2 < 0 ? -u2 : u2) <= L && (v2 < 0 ? -v2 : v2) <= W;
}

/* The float detector's car_to_ground in integer steps (codegen/lidet_ref/detector_q.py ground_box, bit for bit):
 * the footprint test on twice the box-frame coordinates against the doubled extents (Q30 cos, sin of the yaw), the
 * heights in half-millimetres: a pixel's 2 z - (2 bottom - 2 window) in [0, 4 window) goes to bin t / (2 bin); the
 * median's bin i gives g = bottom - window + (i + 1/2) bin, i.e. (window 1000, bin 20, lift < 500) a bottom
 * lifted by 990 - 20 i mm for 25 <= i <= 49: h grows by it, cz goes down by half of it. Corner columns from the
 * rounded corners; the histogram in the PointNets' scratch. Called with car_ground_mm > 0 only (DET_GROUND). */
#if defined(__GNUC__)
__attribute__((noinline)) /* out of the candidates loop's frame (the 16-beam images never call it) */
#endif
static void
car_to_ground(lidet_detector_q_t *d, lidet_box_q_t *b)
{
    const int64_t r = d->cfg.car_ground_mm;
    const lidet_range_image_t *img = &d->cluster.img;
    const uint8_t *mask = ground_mask(d);
    const uint32_t rows = img->n_rows, cols = img->n_cols;
    const int64_t c = lidet__q_cos((uint32_t)b->yaw_bam), s = lidet__q_sin((uint32_t)b->yaw_bam);
    const int64_t a2 = (int64_t)b->l_mm + 2 * r, w2 = (int64_t)b->w_mm + 2 * r;
    const int64_t L = a2 * ((int64_t)1 << 30), W = w2 * ((int64_t)1 << 30);
    const int64_t lo2 = 2 * (int64_t)b->cz_mm - b->h_mm - 2 * LIDET_DET_GROUND_WINDOW_MM;
    int32_t *hist = d->pn_scratch;
    uint32_t n = 0, k, i, col0, span, half, cum;
    if (rows == 0u || cols == 0u)
    {
        return;
    }
    for (i = 0; i < (uint32_t)LIDET_DET_GROUND_BINS; ++i)
    {
        hist[i] = 0;
    }
    if (in_footprint(c, s, -(int64_t)b->cx_mm, -(int64_t)b->cy_mm, L, W))
    {
        col0 = 0u; /* the footprint holds the sensor: every column */
        span = cols;
    }
    else
    {
        const int32_t cc = (int32_t)column_q(b->cx_mm, b->cy_mm, cols), half_cols = (int32_t)(cols / 2u);
        int32_t omin = 0, omax = 0, first, last;
        for (k = 0; k < 4u; ++k)
        {
            const int64_t a = (k & 1u) ? a2 : -a2, w = (k & 2u) ? w2 : -w2;
            const int32_t x = (int32_t)(b->cx_mm + lidet__q_rshift_round(c * a - s * w, 31));
            const int32_t y = (int32_t)(b->cy_mm + lidet__q_rshift_round(s * a + c * w, 31));
            int32_t o = (int32_t)column_q(x, y, cols) - cc;
            o = o > half_cols ? o - (int32_t)cols : (o < -half_cols ? o + (int32_t)cols : o);
            omin = o < omin ? o : omin;
            omax = o > omax ? o : omax;
        }
        first = cc + omin - 1;
        last = cc + omax + 1;
        span = (uint32_t)(last - first + 1);
        span = span > cols ? cols : span;
        col0 = (uint32_t)((first % (int32_t)cols + (int32_t)cols) % (int32_t)cols);
    }
    /* row by row over the span's one or two runs of columns (it may wrap past the last column); the counts do not
     * depend on the order */
    for (k = 0; k < rows * 2u; ++k)
    {
        const uint32_t row = k >> 1, a = (k & 1u) ? 0u : col0;
        const uint32_t e = (k & 1u) ? (col0 + span > cols ? col0 + span - cols : 0u)
                                    : (col0 + span > cols ? cols : col0 + span);
        uint32_t p;
        for (p = row * cols + a; p < row * cols + e; ++p)
        {
            int32_t v[3];
            int64_t t;
            if (!mask[p] || img->range_4mm[p] == 0u)
            {
                continue;
            }
            lidet__qpix_xyz(img, p, v);
            t = 8 * (int64_t)v[2] - lo2;
            if (t < 0 || t >= 4 * LIDET_DET_GROUND_WINDOW_MM ||
                !in_footprint(c, s, 4 * (int64_t)v[0] - b->cx_mm, 4 * (int64_t)v[1] - b->cy_mm, L, W))
            {
                continue;
            }
            ++hist[t / (2 * LIDET_DET_GROUND_BIN_MM)];
            ++n;
        }
    }
    if (n < LIDET_DET_GROUND_MIN_PIXELS)
    {
        return;
    }
    half = (n + 1u) / 2u; /* the lower median */
    for (i = 0, cum = 0; i < (uint32_t)LIDET_DET_GROUND_BINS; ++i)
    {
        cum += (uint32_t)hist[i];
        if (cum >= half)
        {
            break;
        }
    }
    {
        /* lift = bottom - g = window - (i + 1/2) bin, in (0, max lift) */
        const int32_t lift2 = 2 * LIDET_DET_GROUND_WINDOW_MM - (2 * (int32_t)i + 1) * LIDET_DET_GROUND_BIN_MM;
        if (lift2 > 0 && lift2 < 2 * LIDET_DET_GROUND_MAX_LIFT_MM)
        {
            /* the bottom down by lift = 990 - 20 i mm (even), the top kept: the centre down by half of it */
            b->h_mm += lift2 / 2;
            b->cz_mm -= lift2 / 4;
        }
    }
}
#define DET_T lidet_detector_q_t
#define DET_CLS_OUT_T lidet_pointnet_q_class_out_t
#define DET_BOX_OUT_T lidet_pointnet_q_box_out_t
#define DET_DETECTION_T lidet_detection_q_t
#define DET_PROPOSAL(d, ci) lidet_proposal_q_make(&(d)->cluster, (ci), &(d)->cfg.proposal, &(d)->proposal)
#define DET_CLASSIFY(d, co) lidet_pointnet_q_classify(&(d)->cls, &(d)->proposal, (co))
#define DET_BOX(d, cls, bo) lidet_pointnet_q_box(&(d)->box, &(d)->proposal, (cls), (bo))
#define DET_SIZE_OK(d, cls, box) lidet_size_ok_q(&(d)->cfg.size, (cls), (box))
#define DET_FLAT(d, ci) flat_surface((d), (ci))
#define DET_GROUND(d, box) ((d)->cfg.car_ground_mm > 0 ? car_to_ground((d), (box)) : (void)0)
#define DET_SCORE_OK(d, t) ((int32_t)(t)->score_q15 >= (d)->cfg.min_score_q15[(t)->cls])
/* gate 1's threshold for classifier output co in Q16 nats (64 bits: gamma and three margins of up to 20 nats);
 * the large-car margin when the proposal just made is a car cluster's of >= LIDET_DET_FLAT_MIN_POINTS members */
#define DET_GATE1_AT(d, co)                                                                                  \
    ((int64_t)(d)->cls.model->gamma_q16[(co)->cls] + (d)->cfg.gate1_margin_q16 +                             \
     (d)->cfg.gate1_class_margin_q16[(co)->cls] +                                                            \
     ((co)->cls == LIDET_CLASS_CAR && (d)->proposal.n_points_src >= LIDET_DET_FLAT_MIN_POINTS                \
          ? (d)->cfg.gate1_large_car_margin_q16                                                              \
          : 0))
#define DET_GATE1_PASS(d, co) ((int64_t)(co)->energy_q16 < DET_GATE1_AT(d, co))
#define DET_GROUP_GATE1_PASS(d, co)                                                                          \
    ((int64_t)(co)->energy_q16 < DET_GATE1_AT(d, co) + (d)->cfg.group_gate1_margin_q16)
#define DET_GATE2_PASS(d, cls, bo)                                                                           \
    ((int64_t)(bo)->energy_q16 < (int64_t)(d)->box.model->gamma_q16[(cls)] + (d)->cfg.gate2_margin_q16)
#define DET_FILL fill_detection
#define DET_INSERT lidet_detections_q_insert
#define DET_NOW now
#define DET_GROUP_T lidet_group_q_t
#define DET_GROUP_ON(d) ((d)->cfg.group_split != 0u)
#define DET_GROUP_SHAPE(d, ci, g) lidet__group_q_shape(&(d)->cluster, (ci), (d)->cfg.group_max_range_mm, (g))
#define DET_GROUP_CUT(d, ci, g, k) lidet__group_q_cut(&(d)->cluster, (ci), (g), (k))
#define DET_GROUP_PROPOSAL(d, ci, g, j)                                                                      \
    lidet__group_q_proposal(&(d)->cluster, (ci), (g), (j), &(d)->cfg.proposal, &(d)->proposal)
#include "internal/lidet_detector_body.h"

/* a detector to run: LIDET_OK, LIDET_ERR_ARG (NULL) or LIDET_ERR_STATE (not initialised) */
static lidet_status_t det_check(const lidet_detector_q_t *d)
{
    if (d == 0)
    {
        return LIDET_ERR_ARG;
    }
    return d->magic != LIDET_INIT_MAGIC ? LIDET_ERR_STATE : LIDET_OK;
}

/* the start of a run (or a stream): checks, counts cleared */
static lidet_status_t det_start(lidet_detector_q_t *d)
{
    const lidet_status_t s = det_check(d);
    if (s != LIDET_OK)
    {
        return s;
    }
    memset(&d->stats, 0, sizeof d->stats);
    d->n_det = 0;
    return LIDET_OK;
}

/* the projection's buffers: the detector's image and scratch, the caller's point_pixel */
static void det_buffers(lidet_detector_q_t *d, lidet_proj_q_buffers_t *buf, int32_t *point_pixel)
{
    memset(buf, 0, sizeof *buf);
#if LIDET_Q_PIXEL_XYZ
    if (!d->cfg.range_only) /* else x, y, z stay NULL: a range-only image */
    {
        buf->x_4mm = d->x_4mm;
        buf->y_4mm = d->y_4mm;
        buf->z_4mm = d->z_4mm;
    }
#endif
    buf->range_4mm = d->range_4mm;
    buf->point_idx = d->scratch.point_idx;
    buf->point_pixel = point_pixel;
}

/* the stages after the projection (whose status is s, begun at clock t_proj after proj_ticks of earlier calls)
 * on the finished image; the clock is read where run_scan always read it, so a firmware that rebuilds 64-bit
 * stage counts from the timestamps sees the same sequence */
static lidet_status_t det_after_projection(lidet_detector_q_t *d, const lidet_proj_q_buffers_t *buf,
                                           lidet_status_t s, uint32_t t_proj, uint32_t proj_ticks,
                                           int streamed)
{
    lidet_detector_q_stats_t *st = &d->stats;
    lidet_range_image_t img;
    lidet_status_t worst = s;
    uint32_t n_cand, i, t0, t1, box_ticks = 0, n_sectors;
    uint8_t suppressed[LIDET_MAX_DETECTIONS];

    lidet_proj_q_image(&d->proj, buf, &img);
    img.point_idx = 0; /* the ground stage's scratch overlays it from here on */
    t1 = now(d);
    st->ticks[LIDET_DET_STAGE_PROJECT] = proj_ticks + (t1 - t_proj);
    s = LIDET_ERR_STATE;
    if (streamed)
    {
        /* the sectors the stream has not done yet (lidet_detector_q_stream_returns); samples dropped make the
         * buffer's order, hence which are dropped, follow the sectors' order: then the whole stage again */
        s = lidet__ground_q_stream_end(&d->ground, &d->scratch.ground, ground_mask(d), &img);
    }
    if (s == LIDET_OK)
    {
        st->n_stream_sectors = d->stream_done;
    }
    else
    {
        s = lidet_ground_q_run_buffers(&d->ground, &d->scratch.ground, ground_mask(d), &img);
    }
    st->ground = d->ground.stats;
    if (!LIDET_SUCCEEDED(s))
    {
        return s;
    }
    worst = s != LIDET_OK ? s : worst;
    t0 = now(d);
    st->ticks[LIDET_DET_STAGE_GROUND] = t0 - t1;
    n_sectors = d->cfg.ground.n_sectors;
    /* the members (over the mask's bytes) are written after the candidates are marked from the mask */
    s = lidet_cluster_q_run_buffers(&d->cluster, d->scratch.cluster.labels, d->scratch.cluster.members, &img,
                                    ground_mask(d), d->ground.planes, n_sectors);
    st->cluster = d->cluster.stats;
    if (!LIDET_SUCCEEDED(s))
    {
        return s;
    }
    worst = s != LIDET_OK ? s : worst;
    t1 = now(d);
    st->ticks[LIDET_DET_STAGE_CLUSTER] = t1 - t0;

    /* candidates, proposals, the networks (the clock is called as the float detector calls it: a firmware that
     * rebuilds 64-bit stage counts from the timestamps reads both the same way) */
    t0 = now(d);
    st->n_clusters = d->cluster.n_recs;
    n_cand = candidates(d, &worst);
    s = det_candidates(d, n_cand, &worst, &box_ticks);
    if (s != LIDET_OK)
    {
        return s; /* cannot happen after a successful init and run */
    }
    t1 = now(d);
    st->ticks[LIDET_DET_STAGE_CLASSIFY] = (t1 - t0) - box_ticks;
    st->ticks[LIDET_DET_STAGE_BOX] = box_ticks;

    /* NMS: the outcome of each dropped detection, in score order */
    t1 = now(d);
    {
        uint16_t ids[LIDET_MAX_DETECTIONS];
        const uint32_t n = d->n_det;
        for (i = 0; i < n; ++i)
        {
            ids[i] = d->det[i].cluster_id;
        }
        d->n_det = lidet_detections_q_nms(d->det, n, d->cfg.nms_iou_q15, suppressed);
        for (i = 0; i < n; ++i)
        {
            if (suppressed[i])
            {
                if (d->outcome[ids[i] - 1u] == LIDET_DET_OUT_DETECTED)
                {
                    d->outcome[ids[i] - 1u] = LIDET_DET_OUT_NMS; /* a group keeps its outcome */
                }
                ++st->n_nms_suppressed;
            }
        }
    }
    st->n_detections = d->n_det;
    st->ticks[LIDET_DET_STAGE_POST] = now(d) - t1;
    return worst;
}

/* one run on points (use_returns 0) or on returns */
static lidet_status_t run_scan(lidet_detector_q_t *d, const int32_t *points_mm, uint32_t n_points,
                               uint32_t stride, const uint16_t *ring, const lidet_return_t *returns,
                               int use_returns, int32_t *point_pixel)
{
    lidet_proj_q_buffers_t buf;
    lidet_status_t s = det_start(d);
    uint32_t t0;
    if (s != LIDET_OK)
    {
        return s;
    }
    det_buffers(d, &buf, point_pixel);
    t0 = now(d);
    s = use_returns ? lidet_proj_q_run_returns(&d->proj, &buf, returns, n_points)
                    : lidet_proj_q_run(&d->proj, &buf, points_mm, n_points, stride, ring);
    d->stats.proj = d->proj.stats;
    if (!LIDET_SUCCEEDED(s))
    {
        return s;
    }
    return det_after_projection(d, &buf, s, t0, 0u, 0);
}

lidet_status_t lidet_detector_q_run(lidet_detector_q_t *d, const int32_t *points_mm, uint32_t n_points,
                                    uint32_t stride, const uint16_t *ring, int32_t *point_pixel)
{
    return run_scan(d, points_mm, n_points, stride, ring, 0, 0, point_pixel);
}

lidet_status_t lidet_detector_q_run_returns(lidet_detector_q_t *d, const lidet_return_t *returns,
                                            uint32_t n_returns, int32_t *point_pixel)
{
    return run_scan(d, 0, n_returns, 0u, 0, returns, 1, point_pixel);
}

/* stream_flags: the streamed ground is on (cfg.stream_sectors, its begin succeeded); the first return's column is
 * known; a return came where a done sector had read (stream_end runs the whole ground stage) */
#define STREAM_ON 1u
#define STREAM_FIRST 2u
#define STREAM_LATE 4u

/* the image column of a return (lidet_proj_q's: (2^15 - azimuth) mod 2^16 scaled to the columns) */
static inline uint32_t return_col(const lidet_return_t *p, uint32_t cols)
{
    return ((uint32_t)(uint16_t)(0x8000u - p->azimuth) * cols) >> 16;
}

/* the smallest 2^15 - azimuth (mod 2^16) in column c (return_col's inverse; c = cols gives 2^16) */
static inline uint32_t col_start_u(uint32_t c, uint32_t cols)
{
    return (c * 65536u + cols - 1u) / cols;
}

/* columns travelled from the stream's first column to column c (mod cols), in the stream's direction */
static inline uint32_t stream_travel(const lidet_detector_q_t *d, uint32_t c, uint32_t cols)
{
    const uint32_t f = d->stream_first_col;
    const uint32_t t = d->stream_dir > 0 ? c + cols - f : f + cols - c;
    return t >= cols ? t - cols : t;
}

/* After a chunk: a return of it where a done sector read (its columns and two on each side) makes the streamed
 * ground stale (stream_end then runs the whole stage: the same results, later); else the stream's position (the
 * chunk's last return, moving on by less than half a turn) and every sector, in the order the stream visits
 * them from the one after its first return's, whose columns and their neighbours all lie at least a margin
 * behind it: done now. The margin is 1/32 turn, or the widest chunk's azimuth spread so far if more (a packet's
 * firings and the beams' azimuth offsets: a real Ouster OS0-128's span +-11 degrees, which the default would not
 * cover), + 4 columns. The first return's sector, and those whose columns start within the margin after its
 * column, wait for stream_end: the rotation's last returns come back there. Measured on real captures
 * (tests/python/test_cli_pcap.py): 25-29 of 32 sectors done early on VLP-16 and Ouster OS0/OS1/OS2 rotations,
 * the same boxes as the whole scan. */
static void stream_sectors(lidet_detector_q_t *d, const lidet_proj_q_buffers_t *buf,
                           const lidet_return_t *ret, uint32_t n)
{
    const uint32_t cols = d->cfg.proj.sensor.n_cols, ns = d->cfg.ground.n_sectors;
    const uint16_t u0 = (uint16_t)(0x8000u - ret[0].azimuth), lo = d->stream_late_u,
                   span = d->stream_late_span;
    const uint32_t check = d->stream_done > 0u;
    lidet_range_image_t img;
    uint32_t i, t, seam, margin, late = 0u, spread;
    int32_t dmin = 0, dmax = 0;
    /* one pass over the chunk: whether a return falls where a done sector read (in the azimuth's units: the columns
     * are ranges of (2^15 - azimuth) mod 2^16, no division per return), and the chunk's azimuth spread about its
     * first return (a packet's firings and the beams' azimuth offsets: an Ouster OS0's span +-11 degrees) */
    for (i = 0; i < n; ++i)
    {
        const uint16_t u = (uint16_t)(0x8000u - ret[i].azimuth);
        const uint32_t du = (uint16_t)(u - u0);
        const int32_t dv = du < 32768u ? (int32_t)du : (int32_t)du - 65536;
        dmin = dv < dmin ? dv : dmin;
        dmax = dv > dmax ? dv : dmax;
        late |= check & (uint32_t)((uint16_t)(u - lo) <= span);
    }
    if (late)
    {
        d->stream_flags |= STREAM_LATE;
        return;
    }
    spread = (uint32_t)(dmax - dmin);
    d->stream_spread_u =
        spread > d->stream_spread_u ? (uint16_t)(spread < 65535u ? spread : 65535u) : d->stream_spread_u;
    /* the margin: 1/32 turn, or the widest chunk's spread so far if more, + 4 columns */
    spread = ((uint32_t)d->stream_spread_u * cols + 65535u) >> 16;
    margin = (spread > cols / 32u ? spread : cols / 32u) + 4u;
    if (!(d->stream_flags & STREAM_FIRST))
    {
        d->stream_first_col = (uint16_t)return_col(&ret[0], cols);
        d->stream_flags |= STREAM_FIRST;
    }
    if (d->stream_dir == 0)
    {
        /* the direction: the first chunk that ends more than the margin from the first return (beams' azimuth
         * offsets put a chunk's last return a few columns either side of its column) */
        const uint32_t c = return_col(&ret[n - 1u], cols), f = d->stream_first_col;
        const uint32_t ahead = c >= f ? c - f : c + cols - f;
        if (ahead > margin && ahead + margin < cols)
        {
            d->stream_dir = (int8_t)(ahead < cols / 2u ? 1 : -1);
        }
        if (d->stream_dir == 0)
        {
            return;
        }
    }
    t = stream_travel(d, return_col(&ret[n - 1u], cols), cols);
    if (t < d->stream_pos || t - d->stream_pos >= cols / 2u)
    {
        return; /* back, or a jump of half a turn: the position stays */
    }
    d->stream_pos = (uint16_t)t;
    lidet_proj_q_image(&d->proj, buf, &img);
    img.point_idx = 0;
    seam = (uint32_t)d->stream_first_col * ns / cols; /* the sector of column c: c ns / cols */
    while (d->stream_next + 1u < ns)
    {
        const uint32_t k = d->stream_next + 1u;
        const uint32_t s = d->stream_dir > 0 ? (seam + k) % ns : (seam + ns - k) % ns;
        const uint32_t c0 = lidet__ground_sector_col(s, ns, cols),
                       c1 = lidet__ground_sector_col(s + 1u, ns, cols);
        const uint32_t c_lo = c0 > 0u ? c0 - 1u : cols - 1u, c_hi = c1 + 1u < cols ? c1 + 1u : c1 + 1u - cols;
        const uint32_t t_lo = stream_travel(d, c_lo, cols), t_hi = stream_travel(d, c_hi, cols);
        const uint32_t first = d->stream_dir > 0 ? t_lo : t_hi, last = d->stream_dir > 0 ? t_hi : t_lo;
        if (first > last || first < margin)
        {
            /* across the first column, or within the margin after it (the rotation's last returns come back
             * there): left for stream_end */
            d->stream_next = (uint16_t)k;
            continue;
        }
        if (last + margin > t)
        {
            break; /* not passed yet */
        }
        lidet__ground_q_stream_sector(&d->ground, &d->scratch.ground, ground_mask(d), &img, s);
        d->stream_next = (uint16_t)k;
        ++d->stream_done;
        {
            /* the columns the done sectors read: from the first one's trailing neighbour to this one's leading
             * one (travel first .. last), as a range of 2^15 - azimuth; the first return's sector is not in it
             * (a rotation ends where it began) */
            const uint32_t f = d->stream_first_col,
                           far = d->stream_dir > 0 ? (f + last) % cols : (f + cols - last) % cols;
            uint32_t ca, cb;
            if (d->stream_done == 1u)
            {
                d->stream_start_col =
                    (uint16_t)(d->stream_dir > 0 ? (f + first) % cols : (f + cols - first) % cols);
            }
            ca = d->stream_dir > 0 ? d->stream_start_col : far;
            cb = d->stream_dir > 0 ? far : d->stream_start_col;
            d->stream_late_u = (uint16_t)col_start_u(ca, cols);
            d->stream_late_span = (uint16_t)(col_start_u(cb + 1u, cols) - 1u - d->stream_late_u);
        }
    }
}

lidet_status_t lidet_detector_q_stream_begin(lidet_detector_q_t *d)
{
    lidet_proj_q_buffers_t buf;
    lidet_status_t s = det_start(d);
    uint32_t t0;
    if (s != LIDET_OK)
    {
        return s;
    }
    det_buffers(d, &buf, 0);
    t0 = now(d);
    s = lidet_proj_q_returns_begin(&d->proj, &buf);
    d->stream_ticks = now(d) - t0;
    d->stream_flags = 0;
    d->stream_dir = 0;
    d->stream_pos = d->stream_done = d->stream_next = d->stream_first_col = d->stream_start_col = 0;
    d->stream_spread_u = 0;
    d->stream_late_u = d->stream_late_span = 0;
    if (s == LIDET_OK && d->cfg.stream_sectors)
    {
        lidet_range_image_t img;
        lidet_proj_q_image(&d->proj, &buf, &img);
        img.point_idx = 0;
        if (lidet__ground_q_stream_begin(&d->ground, &img) == LIDET_OK)
        {
            d->stream_flags = STREAM_ON;
        }
    }
    return s;
}

lidet_status_t lidet_detector_q_stream_returns(lidet_detector_q_t *d, const lidet_return_t *returns,
                                               uint32_t n_returns, int32_t *point_pixel)
{
    lidet_proj_q_buffers_t buf;
    lidet_status_t s = det_check(d);
    uint32_t t0;
    if (s != LIDET_OK)
    {
        return s;
    }
    det_buffers(d, &buf, point_pixel);
    t0 = now(d);
    s = lidet_proj_q_returns_add(&d->proj, &buf, returns, n_returns);
    if (LIDET_SUCCEEDED(s) && (d->stream_flags & (STREAM_ON | STREAM_LATE)) == STREAM_ON && n_returns > 0u)
    {
        stream_sectors(d, &buf, returns, n_returns); /* timed with the projection: one clock pair a call */
    }
    d->stream_ticks += now(d) - t0;
    return s;
}

lidet_status_t lidet_detector_q_stream_end(lidet_detector_q_t *d)
{
    lidet_proj_q_buffers_t buf;
    lidet_status_t s = det_check(d);
    uint32_t t0;
    int streamed;
    if (s != LIDET_OK)
    {
        return s;
    }
    det_buffers(d, &buf, 0);
    t0 = now(d);
    s = lidet_proj_q_returns_end(&d->proj, &buf);
    d->stats.proj = d->proj.stats;
    streamed = (d->stream_flags & (STREAM_ON | STREAM_LATE)) == STREAM_ON;
    d->stream_flags = 0;
    if (!LIDET_SUCCEEDED(s))
    {
        return s;
    }
    return det_after_projection(d, &buf, s, t0, d->stream_ticks, streamed);
}

const lidet_detection_q_t *lidet_detector_q_detections(const lidet_detector_q_t *d, uint32_t *n_detections)
{
    if (n_detections != 0)
    {
        *n_detections = d != 0 && d->magic == LIDET_INIT_MAGIC ? d->n_det : 0u;
    }
    return d != 0 ? d->det : 0;
}

const uint8_t *lidet_detector_q_outcomes(const lidet_detector_q_t *d, uint32_t *n_clusters)
{
    if (n_clusters != 0)
    {
        *n_clusters = d != 0 && d->magic == LIDET_INIT_MAGIC ? d->stats.n_clusters : 0u;
    }
    return d != 0 ? d->outcome : 0;
}

const lidet_detector_q_stats_t *lidet_detector_q_stats(const lidet_detector_q_t *d)
{
    return d != 0 ? &d->stats : 0;
}

uint32_t lidet_detector_q_bytes(void)
{
    return (uint32_t)sizeof(lidet_detector_q_t);
}
