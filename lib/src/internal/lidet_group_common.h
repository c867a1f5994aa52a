/* SPDX-License-Identifier: MIT */
/* The group split (lidet_detector_cfg_t group_split, lidet_detector_q_cfg_t group_split): a classified cluster
 * that gave no detection and is shaped like people standing side by side is cut along its principal horizontal
 * axis into k = 2..4 parts by a one-dimensional k-means; the detector keeps the cut when the classifier calls
 * every part a pedestrian or a cyclist passing gate 1 as that class, one at least a pedestrian, and boxes every part
 * as a pedestrian (docs/DETECTOR.md, "People in groups").
 *
 * The rule, the same in both builds (the float one in metres, lidet_group.c; the integer one in 4 mm steps,
 * lidet_group_q.c, mirrored bit for bit by codegen/lidet_ref/group_q.py):
 *  1. shape: at least LIDET_GROUP_MIN_POINTS member pixels, the mean within max_range horizontally; the moments
 *     about the cluster mean give the z spread s_z = sqrt(12 var z) and the principal horizontal axis (angle
 *     atan2(2 sxy, sxx - syy) / 2); the spread along it s = sqrt(12 var t) (t: a member's offset from the mean
 *     along the axis). sqrt(12 var) is the length of a uniform spread of that variance: moments keep the rule
 *     to two passes over the members with no sort, and stray points move them less than a min/max span. A group:
 *     1.0 <= s_z <= 2.2 m and 0.9 <= s <= 3.5 m (one person is narrower, a car longer);
 *  2. cuts: k from min(4, round(s / 0.5 m)) down to max(2, round(s / 0.7 m)) (about 0.7 m a person), the
 *     first cut whose every part qualifies is kept;
 *  3. one cut: centres at -s/2 + (j + 1/2) s / k; at most LIDET_GROUP_ITERS passes of assigning each member to
 *     the part whose bounds hold its t (bounds: midpoints of neighbouring centres; part j: bound[j-1] <= t <
 *     bound[j]) and moving each centre to its part's mean t (an empty part keeps its centre), until no centre
 *     moves; the parts of the last assignment stand, each needing LIDET_GROUP_MIN_PART members;
 *  4. each part's proposal is made from its members as a cluster's is (the same resampling rule over the part's
 *     members in member order, points about the part's mean, the voxel of that mean; the z origin of a ground
 *     origin model is the cluster's ground under its mean).
 * The float rule's state and functions: internal/lidet_group.h; the integer one's: internal/lidet_group_q.h.
 * Never installed. */
#ifndef LIDET_GROUP_COMMON_H
#define LIDET_GROUP_COMMON_H

#include "internal/lidet_proposal_rule.h"
#include "lidet/lidet_types.h" /* lidet_status_t */

#define LIDET_GROUP_MAX_PARTS 4u
#define LIDET_GROUP_MIN_POINTS 20u /* member pixels of a cluster the split examines */
#define LIDET_GROUP_MIN_PART 8u    /* member pixels of each part (the clustering's default min_points) */
#define LIDET_GROUP_ITERS 8u       /* k-means passes at most */
/* The NMS between two parts of one cut (they share their cluster id): dropped past this BEV IoU or the detector's
 * nms_iou, the larger. People side by side give part boxes that touch (BEV IoU about 0.1 at 0.6 m apart, past the
 * default nms_iou of 0.1); two parts overlapping past the loose pedestrian match (0.25) are one person cut twice */
#define LIDET_GROUP_NMS_IOU_Q15 8192 /* 0.25 */
#define LIDET_GROUP_NMS_IOU                                                                                  \
    ((float)LIDET_GROUP_NMS_IOU_Q15 / 32768.0f) /* the float detector's, the same 0.25 */

/* Rule 4's resampling walk, the same in both builds: the proposal rule (lidet_proposal_rule.h) over a part's n_src
 * members, found in one pass over the cluster's n_members members in member order. n_src <= n_out: the part's
 * members in order, then draws among them; else from each of the n_out strata of the part's members the one whose
 * pixel has the smallest key. PIXEL(m): member m's pixel; IN_PART(m): member m is in the part; WRITE(i, m): output
 * row i from member m; COPY(i, k): row i from row k. status: LIDET_OK, or LIDET_ERR_STATE when the part does not
 * hold n_src members (cannot happen after the cut counted them). */
#define LIDET__GROUP_RESAMPLE(seed, n_src, n_out, n_members, PIXEL, IN_PART, WRITE, COPY, status)            \
    do                                                                                                       \
    {                                                                                                        \
        uint32_t grs_i_ = 0, grs_ord_ = 0, grs_m_;                                                           \
        if ((n_src) <= (n_out))                                                                              \
        {                                                                                                    \
            uint32_t grs_state_ = lidet__proposal_rng_start((seed), (n_src));                                \
            for (grs_m_ = 0; grs_m_ < (n_members) && grs_i_ < (n_src); ++grs_m_)                             \
            {                                                                                                \
                if (IN_PART(grs_m_))                                                                         \
                {                                                                                            \
                    WRITE(grs_i_, grs_m_);                                                                   \
                    ++grs_i_;                                                                                \
                }                                                                                            \
            }                                                                                                \
            (status) = grs_i_ == (n_src) ? LIDET_OK : LIDET_ERR_STATE;                                       \
            for (; (status) == LIDET_OK && grs_i_ < (n_out); ++grs_i_) /* draws among the rows */            \
            {                                                                                                \
                const uint32_t grs_k_ = lidet__proposal_next_index(&grs_state_, grs_i_, (n_src));            \
                COPY(grs_i_, grs_k_);                                                                        \
            }                                                                                                \
        }                                                                                                    \
        else                                                                                                 \
        {                                                                                                    \
            lidet__strata_t grs_st_;                                                                         \
            uint32_t grs_start_ = 0, grs_end_;                                                               \
            uint32_t grs_best_ = 0, grs_key_ = 0;                                                            \
            lidet__strata_init(&grs_st_, (n_src), (n_out));                                                  \
            grs_end_ = lidet__strata_next(&grs_st_);                                                         \
            for (grs_m_ = 0; grs_m_ < (n_members) && grs_i_ < (n_out); ++grs_m_)                             \
            {                                                                                                \
                uint32_t grs_k_;                                                                             \
                if (!(IN_PART(grs_m_)))                                                                      \
                {                                                                                            \
                    continue;                                                                                \
                }                                                                                            \
                grs_k_ = lidet__proposal_key((seed), (PIXEL(grs_m_)));                                       \
                if (grs_ord_ == grs_start_ || grs_k_ < grs_key_)                                             \
                {                                                                                            \
                    grs_key_ = grs_k_;                                                                       \
                    grs_best_ = grs_m_;                                                                      \
                }                                                                                            \
                if (++grs_ord_ == grs_end_) /* the stratum's last member */                                  \
                {                                                                                            \
                    WRITE(grs_i_, grs_best_);                                                                \
                    grs_start_ = grs_end_;                                                                   \
                    ++grs_i_;                                                                                \
                    grs_end_ = lidet__strata_next(&grs_st_);                                                 \
                }                                                                                            \
            }                                                                                                \
            (status) = grs_i_ == (n_out) ? LIDET_OK : LIDET_ERR_STATE;                                       \
        }                                                                                                    \
    } while (0)

#endif
