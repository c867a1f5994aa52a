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

#define LIDET_GROUP_MAX_PARTS 4u
#define LIDET_GROUP_MIN_POINTS 20u /* member pixels of a cluster the split examines */
#define LIDET_GROUP_MIN_PART 8u    /* member pixels of each part (the clustering's default min_points) */
#define LIDET_GROUP_ITERS 8u       /* k-means passes at most */

#endif
