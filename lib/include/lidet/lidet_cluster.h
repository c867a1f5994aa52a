/* SPDX-License-Identifier: MIT */
/**
 * @file lidet_cluster.h
 * @brief Depth clustering of the non-ground pixels of a range image, and the proposals (resampled,
 *        centred point sets plus a spherical voxel) handed to the PointNets.
 *
 * Algorithm (Bogoslavskyi & Stachniss 2016, in the variant of Seppänen et al.):
 *  - candidates: pixels holding a point (range_m > 0) that the ground mask does not mark;
 *  - BFS flood fill from every unvisited candidate in raster order, 4-neighbourhood (plus the four
 *    diagonal neighbours with `diagonals`, tested at the true angle between the two beams); columns
 *    wrap around (col 0 and col n_cols - 1 are neighbours), rows do not;
 *  - hole bridging: in each direction the search steps over pixels that are not candidates (no
 *    return, or ground) up to `max_steps` pixels away and tests the first candidate it meets; the
 *    angle alpha between the two beams grows with the steps (columns: k * 2 pi / n_cols; rows: the
 *    real elevation difference of the two beams from the profile's table);
 *  - occluders (bridge_occluders): a candidate that fails the test and is nearer than the current
 *    pixel is stepped over like a hole (the search goes on behind it, still up to max_steps, testing
 *    each further candidate at the wider angle, the occluder's own continuation included). A stricter
 *    variant that never re-tests nearer pixels separates overlapping parked cars better but measured
 *    lower recovery overall (simulated hdl64 cars within 40 m, 4-neighbourhood: 58 % instead of 74 % at 0.35 rad);
 *  - join test: with d1 the larger and d2 the smaller range, beta = atan2(d2 sin a, d1 - d2 cos a);
 *    join when beta > theta. No atan2 at run time: sin/cos of every alpha are precomputed in init
 *    and the test is d2 sin a > tan(theta) (d1 - d2 cos a) (always true when the bracket is <= 0);
 *  - gap bound (max_gap_m > 0, the default): the two returns must also lie within
 *    max_gap_m + max_gap_per_m * d2 of each other, their distance along the two beams being
 *    sqrt((d1 - d2 cos a)^2 + (d2 sin a)^2) (the same two terms; no coordinates are read). The
 *    small default angle joins the fragments of car bodies (grazing hoods and roofs, dropouts) and
 *    this bound keeps parked cars in a row apart; the bound grows with range like the spacing of
 *    the returns;
 *  - per cluster, in one pass over its members: pixel count, mean, axis-aligned min/max; then the
 *    filters: fewer than min_points pixels, an x/y/z extent above max_extent_m, a mean height above
 *    the ground plane (of the seed column's sector, or the flat ground at -mount height; with
 *    plane_split_m > 0 the sector's far plane for a mean at or beyond that range) above
 *    max_mean_height_m;
 *  - regrowth (regrow_gap_m > 0, the default above 16 beams): a component past max_extent_m of at most
 *    regrow_max_pixels pixels and at most regrow_max_height_m tall is not dropped but grown again from
 *    its own pixels (in its fill order; a part's seed is its first pixel in raster order) with the gap
 *    bound regrow_gap_m + regrow_gap_per_m * d2, and each part goes through the filters (not regrown
 *    again). Why: the gap bound above joins cars parked 0.6-1.5 m apart into one component too wide to
 *    keep; with 0.35 m + 0.02 / m the rows come apart. Measured (docs/DETECTOR.md, "Climbing roads and
 *    parked rows"): simulated HDL-64 car AP R40 3D moderate +2.1 to +2.3 on four sets of 200-600 scans;
 *    walls, trees and buildings (taller) are not regrown, which keeps its time below 0.02 ms a crop. With
 *    regrow_cut_m > 0 (off by default) the pixels less than that above their ground plane are left out first
 *    (kerbs that chain a real car to the street);
 *  - capacity: at most LIDET_MAX_CLUSTERS clusters are kept; past it the smallest (pixel count;
 *    ties: the later seed in raster order) is dropped and counted;
 *  - fragment rescue (rescue_gap_m > 0, the default): a component below min_points whose mean
 *    lies within the height limit is not dropped at once but kept as a fragment. After the first
 *    fill, a second one, seeded in raster order, joins fragment pixels whose returns lie within
 *    rescue_gap_m + rescue_gap_per_m * (nearer range) of each other (the 3D distance alone, no
 *    angle test; pixels whose ranges differ by more are not looked at), over the window of
 *    rescue_rows rows and rescue_cols columns around each pixel. A group that comes within the same
 *    distance of a kept cluster's pixel joins the nearest such cluster (squared distance; ties:
 *    the first met): its count, bounds, mean (float: (mean n + group sum) / new n) and height are
 *    updated, the filters are not run again. A group that meets none is a cluster of its own if
 *    it passes the filters and a slot is free (the rescue never evicts; a full capacity drops and
 *    counts it). Why: on sparse sensors a car's window-height ring alternates between the glass
 *    and the far side 1-2 m behind it, and the angle test cuts it into singletons that min_points
 *    dropped. Measured (docs/BENCHMARKS.md): simulated cars within 40 m recovered as one cluster
 *    vlp16 77 -> 90 %, hdl64 87 -> 94 %, real SemanticKITTI 89 -> 92 %;
 *  - refinement, after the rescue (lib/src/cluster/lidet_refine.c; issue 15). Cuts (split_people, the
 *    default): a kept cluster wider than split_min_width_m in x or y is drawn on a bird's-eye-view grid of
 *    cell split_cell_m + split_cell_per_m * r (r = max(|cx|, |cy|) + min(|cx|, |cy|) / 2 of its box centre:
 *    no sqrt) and cut into the 8-connected parts of its occupied cells. Parts spanning at most
 *    person_max_width_m in x and y whose points span at least person_min_height_m and
 *    person_min_aspect times that span in z, over at least person_min_cols image columns, with at least
 *    person_min_points pixels (person-sized), become clusters of their own; the other parts stay together
 *    in the cluster (when every part of min_points pixels or more is person-sized the largest part stays;
 *    when what stays would be below min_points the largest person-sized part stays with it). Records are recomputed,
 *    slots come from the free ones (none free: the rest stays). Clusters needing more than
 *    LIDET_REFINE_MAX_CELLS cells or LIDET_REFINE_MAX_PARTS parts, or holding more than
 *    LIDET_REFINE_MAX_POINTS pixels, stay whole. Joins (join_cars, the default): in slot order (the
 *    canonical ids, then the cut-off parts in the order they were made) each cluster i takes every
 *    later cluster j within join_gap_m of it (squared x-y gap of the two boxes) when neither is upright
 *    by its box (x and y span <= upright_max_width_m, z span >= person_min_height_m), each fits a car
 *    alone, and the union's box spans at most car_max_length_m (longer x-y side, and at least
 *    car_min_length_m), car_max_width_m (shorter side) and car_max_height_m (z); i's box grows with
 *    each join; clusters the cuts made or cut take part in no join, nor car pieces past the first
 *    max_join_pieces (the join budget). Both rules only compare
 *    coordinates, integer cells and counts: the integer build has an exact counterpart. Measured
 *    (docs/BENCHMARKS.md, issue 15's proposal recall within 40 m): simulated crowd scenes people
 *    65 -> 85 % (hdl64), 71 -> 85 % (vlp16), cars 92 -> 93 %, 89 -> 91 %; default scenes and real
 *    SemanticKITTI cars no worse. Profiles of <= 16 beams have defaults of their own, chosen on 80 simulated
 *    VLP-16 crowd scans (seed 2) and checked on 60 of other seeds (21-23) and the default VLP-16 scenes:
 *    max_steps 5, rescue_gap_m 1.0, split_min_width_m 0.7, person_min_points 9, join_gap_m 0.8. Measured
 *    (issue 15's proposal recall within 40 m, docs/BENCHMARKS.md): cars 90.1 -> 93.2 % (80 scans) and
 *    91.7 -> 92.7 % (unseen seeds), people 84.7 -> 86.5 % and 88.9 -> 90.2 %, cyclists 92.5 -> 90.6 % and
 *    87.5 -> 87.5 %; default VLP-16 scenes cars 94.3 -> 95.1 %, people and cyclists unchanged. Then, for every
 *    profile, split_min_width_m 0.7 and person_min_cols 2: simulated HDL-64 crowd people 84.5 -> 85.4 %
 *    (20 scans, seed 1), 87.9 -> 90.4 % (20 unseen scans, seed 11), cars, the default HDL-64 scenes, real
 *    SemanticKITTI cars and the VLP-16 figures unchanged; the HDL-64 detector's AP R40 3D moderate (200
 *    scans) car 82.01 -> 81.98, pedestrian 64.51 -> 64.39, cyclist 87.50;
 *  - output ids are canonical: 1-based in raster order of each kept cluster's first pixel;
 *    0 = no cluster. Each cluster's member pixels are listed contiguously, in raster order.
 * The BFS queue is the member array itself (every pixel is pushed at most once), so it cannot
 * overflow; there is no recursion.
 *
 * Proposals (lidet_proposal_make): a kept cluster resampled to N points (N <= LIDET_PROPOSAL_POINTS)
 * by a deterministic rule that codegen/lidet_ref/cluster.py reproduces exactly:
 *  - n_src <= N: every member once (member order), then N - n_src members drawn with replacement
 *    by an xorshift32 generator whose state starts at seed ^ (n_src * 0x9E3779B9) (0 replaced by
 *    0x6C646574); each draw is one xorshift32 step (13, 17, 5) and returns the new state;
 *  - n_src > N: stratified without replacement: output i takes, of the members b_i .. b_{i+1} - 1
 *    (b_i = floor(i n_src / N)), the one whose pixel p has the smallest key
 *    fmix32(seed ^ (p * 0x9E3779B9)) (fmix32: MurmurHash3's 32-bit finaliser, a bijection, so keys never
 *    tie). The pick depends on the pixels, not on the member count: two clusters that differ by a pixel
 *    (the float and integer projections of one scan, a pixel that changes hands) take the same members
 *    in every stratum that pixel leaves alone. A stratum's member at random, as a generator's draw in it
 *    would be, so the proposals follow the law the networks were trained with;
 *  - points are centred on the cluster mean (record mean_m), and the mean's spherical voxel is
 *    floor(azimuth / az_bin), floor(elevation / el_bin), floor(range / range_bin) (azimuth =
 *    atan2(y, x), elevation = atan2(z, sqrt(x^2 + y^2)), signed bins, clamped to int16).
 *
 * Memory: sizeof(lidet_cluster_t) = LIDET_MAX_ROWS * LIDET_MAX_COLS * 6 B (uint16 label and int32
 * member per pixel) + LIDET_MAX_CLUSTERS * (sizeof(lidet_cluster_rec_t) + 6) B
 * + LIDET_MAX_ROWS * LIDET_CLUSTER_MAX_STEPS * 8 B + the refinement's scratch (LIDET_REFINE_MAX_CELLS
 * * 4 B + LIDET_REFINE_MAX_POINTS * 2 B + LIDET_REFINE_MAX_PARTS * 26 B) + ~200 B: about 1.6 MiB with
 * the defaults (128 x 2048; 1,678,120 B on x86-64), 0.18 MiB for a VLP-16 board (16 x 1800, 64 clusters,
 * refinement caps 2048: 192,448 B). lidet_cluster_bytes() returns the exact figure. Declare it `static`.
 * Time: O(n_rows * n_cols * max_steps) per run worst case, O(n_rows * n_cols) typical; the rescue
 * looks at (2 rescue_rows + 1)(2 rescue_cols + 1) pixels around each fragment pixel, at most
 * max_fragment_pixels of them (the budget that bounds it whatever the scan); plus O(K log LIDET_MAX_CLUSTERS)
 * when K clusters overflow the capacity (a heap of the slots), and at most O(LIDET_MAX_CLUSTERS^2) to
 * order the ids when rescued pixels precede a cluster's seed. The refinement: O(members + cells) per
 * examined cluster (cells <= LIDET_REFINE_MAX_CELLS), O(parts * members) for one it cuts, O(K^2) box tests
 * for the joins of K clusters, and one more canonical pass over the image when anything changed. No
 * allocation. Worst cases measured in docs/ROBUSTNESS.md.
 */
#ifndef LIDET_CLUSTER_H
#define LIDET_CLUSTER_H

#include "lidet_cluster_stats.h"
#include "lidet_image.h"
#include "lidet_proj.h"
#include "lidet_sensor.h"
#include "lidet_types.h"

#ifdef __cplusplus
extern "C" {
#endif

/** @brief Runtime configuration of the clustering. Fill with lidet_cluster_cfg_default(). */
typedef struct
{
    float theta_rad;           /**< join when beta > theta; (0, pi/2). Defaults per profile (measured with
                                  the gap bound below, docs/BENCHMARKS.md): > 16 beams (hdl64, vlp32c,
                                  os1) 0.18 rad, <= 16 beams (vlp16) 0.12 rad (without the gap bound
                                  0.35 / 0.30 were best: smaller angles merged parked cars); the
                                  authors used 0.4 / 0.15 */
    uint32_t max_steps;        /**< hole bridging: search up to this many pixels away in each direction
                                  (1 = direct neighbours only); [1, LIDET_CLUSTER_MAX_STEPS]; default 5
                                  (both kinds of profile; <= 16 beams used 4 before issue 15's crowd
                                  scenes: 5 without occluder bridging costs about 1 % of the clustering's
                                  time there); the authors used 9 */
    uint32_t bridge_occluders; /**< 1: the search also steps over a candidate that fails the test and is
                                  nearer than the current pixel (a pole or branch in front of the
                                  object), so objects seen through occluders stay whole; 0: stop at
                                  the first candidate (the authors' variant). Default 1 for > 16 beams,
                                  0 for <= 16 beams (measured; speed) */
    uint32_t diagonals;        /**< 1 (default, measured): also test the 4 diagonal neighbours
                                  (8-neighbourhood; no bridging on them); 0: the 4-neighbourhood of
                                  the paper and of depth_clustering */
    float max_gap_m;           /**< 0: the angle test alone; > 0: neighbours also need a distance along
                                  their beams <= max_gap_m + max_gap_per_m * (nearer range) to join.
                                  Default 0.7 m (measured: simulated hdl64 cars within 40 m 79 -> 87 %,
                                  vlp16 58 -> 77 %, real 81 -> 89 %, under-segmented real cars 14 -> 6 %,
                                  with the angles above; docs/BENCHMARKS.md) */
    float max_gap_per_m;       /**< growth of the gap bound per metre of the nearer range; >= 0; default
                                  0.025 (> 16 beams), 0.04 (<= 16 beams): 1.45 m / 2.3 m at 30 m
                                  (measured with max_gap_m; a fixed bound of 1 m split far simulated
                                  cars, 71-81 % at 0.15-0.35 rad; 1.5 m merged real parked cars) */
    uint32_t min_points;       /**< drop clusters with fewer pixels; >= 1, default 8: measured end to end,
                                  docs/DETECTOR.md (10 before: sparse far and VLP-16 pedestrians lost) */
    float max_extent_m;        /**< drop clusters wider than this in x, y or z; > 0, default 6 m */
    float max_mean_height_m;   /**< drop clusters whose mean lies higher above the ground plane; default
                                  2.5 m; a huge value (e.g. 1e30) disables the filter */
    float mount_height_m;      /**< sensor height above a flat ground, used when no planes are given
                                  (copied from the sensor profile); >= 0 */
    float rescue_gap_m;        /**< fragment rescue (file comment): 0 disables it; > 0: fragments below
                                  min_points join each other and the nearest kept cluster within
                                  rescue_gap_m + rescue_gap_per_m * (nearer range). Default 0.8 m
                                  (> 16 beams), 1.0 m (<= 16 beams; issue 15, below) */
    float rescue_gap_per_m;    /**< growth of the rescue distance per metre of range; >= 0; default 0.03 */
    uint32_t rescue_rows;      /**< rescue window: rows looked at above and below a fragment pixel;
                                  <= LIDET_MAX_ROWS; default 1 (<= 16 beams), 2 (> 16 beams) */
    uint32_t rescue_cols;      /**< columns looked at left and right (wrapping; at most (n_cols - 1) / 2
                                  are used); <= 15; default 6 */
    /* proposal refinement after the clustering (lib/src/cluster/lidet_refine.c, issue 15) */
    uint32_t split_people;      /**< 1 (default): a cluster wider than split_min_width_m is cut into its
                                  connected parts on a finer bird's-eye-view grid, and every part that
                                  is person-sized becomes a cluster of its own (people in groups, a
                                  person beside a car, a pole or a wall); 0: off */
    float split_min_width_m;    /**< clusters whose x or y extent exceeds this are examined; > 0; default 0.7
                                  (two people seen by a few rings span less than 0.9 m; issue 15, below;
                                  0.9 before, when the simulated HDL-64 crowd persons were 84.5 %) */
    float split_cell_m;         /**< cell of the finer grid at range 0; > 0; default 0.12 m */
    float split_cell_per_m;     /**< its growth per metre of range (range of the cluster's box centre,
                                  max(|x|,|y|) + min(|x|,|y|) / 2); >= 0; default 0 (measured: a
                                  growth of 0.002-0.008 m/m recovered fewer people in crowds) */
    float person_max_width_m;   /**< a part is person-sized when its cells span at most this in x and in
                                  y; > 0; default 1.0 m */
    float person_min_height_m;  /**< ... its points at least this in z; >= 0; default 0.9 m */
    float person_min_aspect;    /**< ... and at least this times its wider cell span in z (people are
                                  slender; the end of a car cut off by dropouts is not); >= 0; default 1.8
                                  (measured: 0 cut simulated cars, 1.8 none more than without the
                                  refinement) */
    uint32_t person_min_cols;   /**< ... and its pixels span at least this many image columns (a slice of a
                                  car's flank or a wall seen at a grazing angle, one column per cell, is
                                  not a person); default 2 (3 before; 2 and split_min_width_m 0.7
                                  took the simulated HDL-64 crowd persons from 197 to 199 of 233 and,
                                  on unseen crowd scenes (seed 11), from 275 to 283 of 313, cars and the
                                  VLP-16 figures unchanged) */
    uint32_t person_min_points; /**< ... and it holds at least this many pixels (a part cut off becomes a
                                  cluster of its own even below min_points, down to this); [1, 1000000];
                                  default 10 (> 16 beams, = min_points), 9 (<= 16 beams: people in groups
                                  seen by a few rings; issue 15, below. 8 recovered 2-4 more people of 378
                                  and 307 but lowered the VLP-16 detector's pedestrian AP by up to 1.8;
                                  min_points 8 instead recovered more people and raised that AP by 3-7
                                  points, but made 11-14 % more clusters and the VLP-16 detector 14 %
                                  slower: docs/BENCHMARKS.md) */
    uint32_t join_cars;         /**< 1 (default): after the cuts, two clusters whose boxes lie within
                                  join_gap_m of each other in x-y and whose union fits a car (x-y
                                  spans at most car_max_length_m and car_max_width_m, z span at most
                                  car_max_height_m), neither upright, become one (a car cut by dark
                                  paint, glass or wheel dropouts); 0: off */
    float join_gap_m;           /**< >= 0; default 0.5 m (> 16 beams; measured: 0.8 joined a cyclist to a
                                  car), 0.8 m (<= 16 beams: the rings of a car's body and cabin lie up to
                                  0.8 m apart; issue 15, below) */
    float car_max_length_m;     /**< > 0; default 5.2 m */
    float car_max_width_m;      /**< > 0; default 2.2 m (measured: 2.3-2.4 joined neighbouring real parked
                                  cars, real SemanticKITTI cars within 40 m 94 -> 89 %) */
    float car_max_height_m;     /**< > 0; default 2.0 m */
    float car_min_length_m;     /**< ... and the union's longer x-y side at least this (two people or a
                                  person and a bin seen by a few rings do not make a car); >= 0;
                                  default 2.5 m */
    float upright_max_width_m;  /**< a cluster spanning at most this in x and in y and at least
                                  person_min_height_m in z is upright (a person, a cyclist, a pole)
                                  and joins nothing; >= 0; default 1.3 m */
    float azimuth_half_rad;     /**< 0 (default): the whole image; in (0, pi): only pixels whose column lies
                                       within this azimuth of straight ahead (+x; one column more on each
                                       side) are candidates (the others are not counted in n_candidates). The
                                       detector's crop sets it to the crop + 15 deg, so a cropped scan is
                                       clustered on that part only; pi: no limit */
    float seed_half_rad;        /**< 0 (default): a component may start anywhere; in (0, pi): components start
                                       (are seeded, in raster order) only at pixels whose column lies within
                                       this azimuth of straight ahead (one column more on each side), and
                                       still grow over every candidate; a component no such seed reaches is
                                       not formed, and a component's seed pixel (the canonical order, the
                                       height's sector) is its first pixel in those columns. The detector's
                                       crop sets it to the crop, with azimuth_half_rad the crop + 15 deg: the
                                       margin's pixels are visited only when they join an object that reaches
                                       into the crop (issue 14: clustering 1.02 -> 0.93 ms on the 11 real KITTI
                                       crops, one pair of runs; docs/journal/detector.md, "The crop's
                                       speed") */
    uint32_t max_join_pieces;   /**< join budget (bounds the joins' time whatever the scan): only the first
                                  max_join_pieces car pieces in slot order take part in the joins, the rest
                                  join nothing (stats n_join_skipped); the joins then test at most
                                  max_join_pieces x LIDET_MAX_CLUSTERS pairs instead of
                                  LIDET_MAX_CLUSTERS^2 / 2. 0 = no limit. Default 256: 2.3x the most car
                                  pieces measured on real scans (KITTI 25-113, 3 frames; SemanticKITTI
                                  43-61, 5; simulated HDL-64 39-101, 5); a VLP-16 scan of 2,400 tiny
                                  clusters: 1.9 -> 0.8 ms of clustering (docs/ROBUSTNESS.md) */
    float max_bridge_per_pixel; /**< occluder bridging budget (bounds the first fill's time whatever the
                                  scan): the run steps over at most about this many nearer candidates per
                                  candidate pixel in all (a pixel's searches bridge only while the run's
                                  count is below max_bridge_per_pixel * n_candidates; then they stop at the
                                  first candidate, as with bridge_occluders 0). [0, 64], 0 = no limit.
                                  Default 2: real KITTI / SemanticKITTI scans bridge 0.4-1.15 steps per
                                  candidate with the ground removed, 0.6-1.4 without a ground mask (9
                                  frames), a scan of random ranges 5 (docs/ROBUSTNESS.md) */
    uint32_t max_fragment_pixels; /**< rescue budget (bounds the rescue's time whatever the scan): fragments
                                  enter the rescue in raster order while their pixels sum to at most this;
                                  one that would exceed it is dropped (stats n_dropped_fragment_budget).
                                  0 = no limit. Default 4096 (> 16 beams), 2048 (<= 16 beams): about 2x
                                  the most fragment pixels measured on real KITTI scans (2074) and 2.5x
                                  the simulated VLP-16 sample's (816; docs/ROBUSTNESS.md) */
    float regrow_gap_m; /**< a component whose extent exceeds max_extent_m is not dropped at once but grown
                                  again from its own pixels with the gap bound regrow_gap_m + regrow_gap_per_m * d2
                                  (tighter than max_gap_m's: cars parked bumper to bumper, chained by it), and
                                  each part goes through the filters (stats n_regrown, n_regrow_parts); 0 = off
                                  (dropped). [0, 100] */
    float regrow_gap_per_m;     /**< its growth per metre of range; [0, 1] */
    uint32_t regrow_max_pixels; /**< only components of at most this many pixels are grown again (walls and
                                  buildings, the large ones, cost the time and hold no car chain); 0 = no limit */
    float regrow_max_height_m; /**< ... and whose z extent is at most this (a row of cars is low; walls, trees
                                  and buildings are not); (0, 100] */
    float regrow_cut_m;  /**< the regrowth leaves out the component's pixels less than this above the ground
                                  plane (as the mean height's plane: the pixel's sector, far plane past
                                  plane_split_m; the flat ground without planes): curbs and kerb-high clutter that
                                  chain a car to the street are cut away. 0 = none, the default (0.25 m found
                                  1.6 more of 113 real training cars for 0.08 more false positives a frame, the
                                  integer detector none: docs/journal/real-streets.md). [0, 2] */
    float plane_split_m; /**< with planes: 0 (default) measures every mean against its sector's plane,
                                  planes[s]; > 0: planes holds 2 * n_sectors planes, near then far (the ground
                                  stage's layout with ring_split_m, lidet_ground_planes), and a mean at or beyond
                                  this horizontal range is measured against its sector's far plane,
                                  planes[n_sectors + s] (a car up a climbing road is not "high above" the near
                                  plane's extension). lidet_workspace and the detectors set it to the ground's
                                  ring_split_m. [0, 500] */
} lidet_cluster_cfg_t;

/** @brief One kept cluster. Coordinates in the sensor frame (metres). */
typedef struct
{
    uint32_t n_points;     /**< member pixels (points that lost their pixel to a closer one are not
                                counted; lidet_cluster_point_labels still labels them) */
    uint32_t first_member; /**< index of its first member in the member array */
    uint32_t seed_pixel;   /**< its first pixel in raster order (row * n_cols + col) */
    uint32_t n_rescued;    /**< member pixels that came from fragments (the rescue pass) */
    float mean_m[3];       /**< mean of the member pixels' points (x, y, z) */
    float min_m[3];        /**< axis-aligned bounds */
    float max_m[3];
    float height_m; /**< mean's signed height above the ground plane used by the filter */
} lidet_cluster_rec_t;

/**
 * @brief What the clustering keeps across runs and its small outputs: configuration, the angle tables
 *        of the image geometry, the kept clusters' records and the counts, plus where the last run
 *        wrote its per-pixel outputs (labels, members). No per-pixel array:
 *        LIDET_MAX_ROWS * LIDET_CLUSTER_MAX_STEPS * 8 B + LIDET_MAX_CLUSTERS * (sizeof(lidet_cluster_rec_t) + 4) B + ~300 B.
 */
typedef struct
{
    uint32_t magic;
    lidet_cluster_cfg_t cfg;
    float tan_theta;
    /* derived from the image's geometry on the first run (and when it changes) */
    uint16_t geo_rows, geo_cols;
    float geo_elev[LIDET_MAX_ROWS];
    float col_sin[LIDET_CLUSTER_MAX_STEPS], col_cos[LIDET_CLUSTER_MAX_STEPS]; /* alpha = k 2pi/cols */
    float row_sin[LIDET_MAX_ROWS * LIDET_CLUSTER_MAX_STEPS]; /* [r * STEPS + k - 1]: rows r, r + k */
    float row_cos[LIDET_MAX_ROWS * LIDET_CLUSTER_MAX_STEPS];
    float diag_sin[LIDET_MAX_ROWS], diag_cos[LIDET_MAX_ROWS]; /* [r]: rows r, r + 1, one column apart */
    /* outputs of the last run */
    lidet_cluster_rec_t recs[LIDET_MAX_CLUSTERS];
    uint16_t order[LIDET_MAX_CLUSTERS];       /* scratch: slots in seed order; during the
                                                            refinement 1 = a slot the cuts made or cut */
    uint16_t slot_id[LIDET_MAX_CLUSTERS + 1]; /* scratch: slot + 1 -> canonical id */
    lidet_range_image_t img;                  /* the image of the last run (a view) */
    uint16_t *labels;                         /* the last run's per-pixel ids (its buffer) */
    lidet_member_t *members;                  /* the last run's member pixels (its buffer) */
    uint32_t n_recs;
    lidet_cluster_stats_t stats;
    /* scratch of the refinement (lidet_refine.c) */
    uint16_t rf_grid[LIDET_REFINE_MAX_CELLS];   /* cell -> part + 1 (0 = empty, 0xFFFF = occupied) */
    uint16_t rf_queue[LIDET_REFINE_MAX_CELLS];  /* cells of the part being filled */
    uint16_t rf_cell[LIDET_REFINE_MAX_POINTS];  /* cell of each member of the examined cluster */
    uint16_t rf_target[LIDET_REFINE_MAX_PARTS]; /* part -> slot it goes to */
    uint32_t rf_n[LIDET_REFINE_MAX_PARTS];      /* points per part */
    uint16_t rf_box[LIDET_REFINE_MAX_PARTS][4]; /* cell bounds: ix0, ix1, iy0, iy1 */
    float rf_z[LIDET_REFINE_MAX_PARTS][2];      /* z bounds of its points */
    uint16_t rf_col[LIDET_REFINE_MAX_PARTS][2]; /* image column bounds of its pixels */
} lidet_cluster_state_t;

/** @brief Clustering with every buffer inside (the standalone form): the state plus its per-pixel
 *         outputs. Caller-owned; declare it static. */
typedef struct
{
    lidet_cluster_state_t state;
    uint16_t labels[LIDET_MAX_ROWS * LIDET_MAX_COLS];        /* per pixel, canonical id, 0 = none */
    lidet_member_t members[LIDET_MAX_ROWS * LIDET_MAX_COLS]; /* member pixels, cluster after cluster */
} lidet_cluster_t;

/**
 * @brief Default configuration for a sensor profile (theta measured per profile; see the field docs).
 * @param[out] cfg    filled with defaults.
 * @param[in]  sensor profile (its name picks theta, its mount height is copied); NULL gives the
 *                    hdl64 values and a 1.73 m mount.
 */
void lidet_cluster_cfg_default(lidet_cluster_cfg_t *cfg, const lidet_sensor_t *sensor);

/**
 * @brief Validate the configuration and precompute tan(theta). No allocation.
 * @param[out] c   state to initialise.
 * @param[in]  cfg configuration (copied).
 * @return LIDET_OK; LIDET_ERR_ARG (NULL); LIDET_ERR_CONFIG (theta outside (0, pi/2), max_steps
 *         outside [1, LIDET_CLUSTER_MAX_STEPS], min_points 0, extent <= 0, height or mount height
 *         not finite / negative mount, a gap or rescue distance negative or not finite).
 */
lidet_status_t lidet_cluster_init(lidet_cluster_t *c, const lidet_cluster_cfg_t *cfg);

/**
 * @brief Cluster one range image.
 * @param[in,out] c           initialised state; labels, members, records and stats are overwritten.
 * @param[in]     img         range image (lidet_proj_image; float or compact, lidet_range_image_t);
 *                            n_rows <= LIDET_MAX_ROWS,
 *                            n_cols <= LIDET_MAX_COLS; its row_elev_rad gives the vertical alphas
 *                            (sin/cos recomputed only when the geometry changes).
 * @param[in]     ground_mask n_rows * n_cols bytes, 1 = ground (not clustered), or NULL (no ground).
 * @param[in]     planes      n_sectors ground planes (sector of column c = c * n_sectors / n_cols),
 *                            or NULL: flat ground at z = -mount_height_m. Read by the height filter.
 * @param[in]     n_sectors   number of planes; ignored when planes is NULL, else >= 1.
 * @return LIDET_OK; LIDET_TRUNCATED when clusters were dropped for capacity (counted in stats);
 *         LIDET_ERR_ARG (NULL c/img, planes with n_sectors 0); LIDET_ERR_BUFFER (image larger than
 *         the capacities, or n_cols < 2); LIDET_ERR_STATE (not initialised).
 */
lidet_status_t lidet_cluster_run(lidet_cluster_t *c, const lidet_range_image_t *img,
                                 const uint8_t *ground_mask, const lidet_plane_t *planes, uint32_t n_sectors);

/**
 * @brief Per-pixel labels of the last run: n_rows * n_cols canonical ids (0 = none). Valid until
 *        the next run/init.
 */
const uint16_t *lidet_cluster_labels(const lidet_cluster_t *c);

/**
 * @brief Kept clusters of the last run; record i has id i + 1. Valid until the next run/init.
 * @param[out] n_clusters may be NULL.
 */
const lidet_cluster_rec_t *lidet_cluster_records(const lidet_cluster_t *c, uint32_t *n_clusters);

/**
 * @brief The member pixels of the last run: cluster i owns members[first_member .. + n_points),
 *        in raster order. Valid until the next run/init.
 */
const lidet_member_t *lidet_cluster_members(const lidet_cluster_t *c);

/** @brief Counts of the last run. */
const lidet_cluster_stats_t *lidet_cluster_stats(const lidet_cluster_t *c);

/**
 * @brief Cluster id of every input point, in input order: a projected point takes its pixel's id
 *        (also points that lost the pixel to a closer point); point_pixel -1 or out of the image -> 0.
 * @param[in]  c           state after a run.
 * @param[in]  point_pixel n_points pixels (lidet_proj_point_pixels), -1 = not projected.
 * @param[in]  n_points    number of points.
 * @param[out] out         n_points ids (0 = none). May not alias point_pixel.
 * @return LIDET_OK; LIDET_ERR_ARG (NULL with n_points > 0); LIDET_ERR_STATE (never run).
 */
lidet_status_t lidet_cluster_point_labels(const lidet_cluster_t *c, const int32_t *point_pixel,
                                          uint32_t n_points, uint32_t *out);

/** @brief sizeof(lidet_cluster_t): the bytes firmware must place for this stage. */
uint32_t lidet_cluster_bytes(void);

/** @brief lidet_cluster_init on the state alone, for a caller that places the per-pixel buffers. */
lidet_status_t lidet_cluster_state_init(lidet_cluster_state_t *st, const lidet_cluster_cfg_t *cfg);

/**
 * @brief lidet_cluster_run writing into caller-placed buffers; same results, bit for bit.
 * @param[out] labels  n_rows * n_cols uint16: the per-pixel ids (also the fill's scratch).
 * @param[out] members n_rows * n_cols int32: the member pixels (also the fill's queue).
 * Both must stay untouched while the records, labels or proposals of this run are read.
 * @return as lidet_cluster_run; LIDET_ERR_ARG also for NULL buffers.
 */
lidet_status_t lidet_cluster_run_buffers(lidet_cluster_state_t *st, uint16_t *labels, lidet_member_t *members,
                                         const lidet_range_image_t *img, const uint8_t *ground_mask,
                                         const lidet_plane_t *planes, uint32_t n_sectors);

/** @brief lidet_cluster_point_labels on a state (the buffers of its last run). */
lidet_status_t lidet_cluster_point_labels_of(const lidet_cluster_state_t *st, const int32_t *point_pixel,
                                             uint32_t n_points, uint32_t *out);

/** @brief sizeof(lidet_cluster_state_t). */
uint32_t lidet_cluster_state_bytes(void);

/* ---- proposals ------------------------------------------------------------------------------ */

/** @brief How proposals are built. Fill with lidet_proposal_cfg_default(). */
typedef struct
{
    uint32_t n_points;     /**< points per proposal, [1, LIDET_PROPOSAL_POINTS]; default 64 (or the
                                  capacity when smaller) */
    uint32_t seed;         /**< resampling seed; default 0x5EED1234 */
    float azimuth_bin_rad; /**< voxel sizes (> 0); defaults 10 deg, 10 deg, 1 m (the paper) */
    float elevation_bin_rad;
    float range_bin_m;
    uint32_t z_origin; /**< lidet_proposal_z_origin_t: where the points' z is measured from; default
                              LIDET_PROPOSAL_Z_MEAN. A model says which one it was trained with
                              (lidet_pn_model_t z_origin) and the detectors set it from the model. */
} lidet_proposal_cfg_t;

/** @brief One proposal: what the PointNets see. */
typedef struct
{
    float xyz[LIDET_PROPOSAL_POINTS][3]; /**< first n_points rows used: member points minus mean_m */
    float mean_m[3];                     /**< the cluster mean (sensor frame); with LIDET_PROPOSAL_Z_GROUND,
                                              mean_m[2] is the ground height under it */
    int16_t voxel[3];                    /**< azimuth, elevation, range bins of the cluster mean (signed) */
    uint32_t n_points;                   /**< rows of xyz filled (= cfg n_points) */
    uint32_t n_points_src;               /**< member pixels of the cluster */
} lidet_proposal_t;

/** @brief Default proposal configuration (64 points, 10 deg / 10 deg / 1 m voxels). */
void lidet_proposal_cfg_default(lidet_proposal_cfg_t *cfg);

/**
 * @brief Build the proposal of kept cluster `cluster_index` (0-based, id - 1) of the last run.
 * @param[in]  c             state after lidet_cluster_run; the range image that run saw must still
 *                           be alive and unchanged (the points are read through it).
 * @param[in]  cluster_index < number of kept clusters.
 * @param[in]  cfg           proposal configuration.
 * @param[out] out           the proposal.
 * @return LIDET_OK; LIDET_ERR_ARG (NULL, index out of range);
 *         LIDET_ERR_CONFIG (n_points outside [1, LIDET_PROPOSAL_POINTS], a bin size <= 0 or not finite,
 *         z_origin not a lidet_proposal_z_origin_t);
 *         LIDET_ERR_STATE (never run).
 */
lidet_status_t lidet_proposal_make(const lidet_cluster_t *c, uint32_t cluster_index,
                                   const lidet_proposal_cfg_t *cfg, lidet_proposal_t *out);

/** @brief lidet_proposal_make on a state (the image and buffers of its last run). */
lidet_status_t lidet_proposal_make_of(const lidet_cluster_state_t *st, uint32_t cluster_index,
                                      const lidet_proposal_cfg_t *cfg, lidet_proposal_t *out);

/**
 * @brief The resampling rule alone: writes n_out member indices (each < n_src) for a cluster whose
 *        n_src member pixels are pixels[0 .. n_src - 1] in member order (see the file comment; the
 *        pixels are read only when n_src > n_out and may be NULL otherwise). Exposed for tests and the
 *        Python reference.
 * @return LIDET_OK; LIDET_ERR_ARG (NULL out, n_src 0, n_out 0, NULL pixels with n_src > n_out).
 */
lidet_status_t lidet_proposal_indices(const lidet_member_t *pixels, uint32_t n_src, uint32_t n_out,
                                      uint32_t seed, uint32_t *out);

#ifdef __cplusplus
}
#endif

#endif /* LIDET_CLUSTER_H */
