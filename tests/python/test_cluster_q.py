# SPDX-License-Identifier: MIT
"""The integer clustering and proposals (lidet_cluster_q.h): bit for bit against the numpy reference
(codegen/lidet_ref/cluster_q.py) and in agreement with the float stage on the same compact images
(docs/FIXED_POINT.md, "Clustering and proposals"). Scans: the simulated samples, freshly simulated scans of fixed
seeds and the real KITTI / SemanticKITTI scans (skipped when absent)."""
from __future__ import annotations

import pathlib

import numpy as np
import pytest

from lidet_ref import cluster_q as ref
from lidet_tools import native
from lidet_tools.sim import simulate_scan

ROOT = pathlib.Path(__file__).resolve().parents[2]
SIM_SAMPLES = [("hdl64", ROOT / "tests/data/sim_hdl64/velodyne/000000.bin"),
               ("vlp16", ROOT / "tests/data/sim_vlp16/velodyne/000000.bin")]
#: freshly simulated scans: (sensor, seed, index)
SIM_FRESH = [("hdl64", 16, 0), ("hdl64", 16, 1), ("vlp16", 16, 0), ("vlp16", 16, 1), ("vlp16", 17, 2)]


def _load(path) -> np.ndarray:
    return np.fromfile(path, np.float32).reshape(-1, 4)


def _sim_scans():
    out = [(s, _load(p)) for s, p in SIM_SAMPLES]
    out += [(s, simulate_scan(s, seed, i).points) for s, seed, i in SIM_FRESH]
    return out


def _real_scans(real_dir):
    files = sorted((real_dir / "semantickitti" / "velodyne").glob("*.bin"))
    files += sorted((real_dir / "kitti" / "training" / "velodyne").glob("*.bin"))
    return [("hdl64", _load(f)) for f in files]


@pytest.fixture(scope="module")
def sim_scans(need_lib):
    return _sim_scans()


def _recs_equal(recs, c) -> bool:
    got = np.array([[r.n_points, r.first_member, r.seed_pixel, r.n_rescued, *r.mean, *r.min, *r.max, r.height]
                    for r in recs], np.int64).reshape(-1, 14)
    want = np.concatenate([np.stack([c.n_points, c.first_member, c.seed_pixel, c.n_rescued], 1), c.mean, c.min, c.max,
                           c.height[:, None]], 1).astype(np.int64)
    return np.array_equal(got, want)


def _check_bit_exact(sensor, pts, planes=True, ground=True, **cfg):
    scan = native.compact_scan(pts, sensor)
    pq = native.planes_to_q(scan.planes) if planes else None
    c = native.cluster_q(scan, pq, use_ground=ground, **cfg)
    dc, dp = native.cluster_q_defaults(sensor)
    dc.update(cfg)
    lab, mem, recs, st = ref.cluster_q_ref(scan.x, scan.y, scan.z, scan.range, scan.row_elev_bam,
                                           scan.ground if ground else None, pq, dc,
                                           native.capacity()["max_clusters"])
    assert np.array_equal(lab, c.labels), "per-pixel ids differ"
    assert np.array_equal(mem, c.members), "member arrays differ"
    assert st == c.stats
    assert _recs_equal(recs, c), "records differ"
    for i, r in enumerate(recs):
        xyz, mean, vox = ref.make_proposal_q(r, mem, scan.x, scan.y, scan.z, dp)
        assert np.array_equal(xyz, c.prop_xyz[i]) and np.array_equal(mean, c.prop_mean[i])
        assert np.array_equal(vox, c.prop_voxel[i]), (i, vox, c.prop_voxel[i])
    return c


def test_defaults_are_the_float_defaults_rounded(need_lib):
    for s in ("hdl64", "vlp16"):
        f = native.cluster_defaults(s)
        q, p = native.cluster_q_defaults(s)
        assert q["theta_urad"] == round(f["theta_rad"] * 1e6)
        assert q["max_gap_mm"] == round(f["max_gap_m"] * 1e3)
        assert q["max_gap_per_m_q16"] == round(f["max_gap_per_m"] * 65536)
        assert q["max_extent_mm"] == round(f["max_extent_m"] * 1e3)
        assert q["max_mean_height_mm"] == round(f["max_mean_height_m"] * 1e3)
        assert q["mount_height_mm"] == round(f["mount_height_m"] * 1e3)
        assert q["rescue_gap_mm"] == round(f["rescue_gap_m"] * 1e3)
        assert q["rescue_gap_per_m_q16"] == round(f["rescue_gap_per_m"] * 65536)
        for k in ("max_steps", "bridge_occluders", "diagonals", "min_points", "rescue_rows", "rescue_cols",
                  "max_fragment_pixels", "split_people", "join_cars", "person_min_cols", "person_min_points",
                  "max_join_pieces"):
            assert q[k] == f[k], k
        assert q["max_bridge_per_pixel_q16"] == round(f["max_bridge_per_pixel"] * 65536)
        assert q["split_cell_per_m_q16"] == round(f["split_cell_per_m"] * 65536)
        assert q["person_min_aspect_q16"] == round(f["person_min_aspect"] * 65536)
        for k in ("split_min_width", "split_cell", "person_max_width", "person_min_height", "join_gap", "car_max_length",
                  "car_max_width", "car_max_height", "car_min_length", "upright_max_width"):
            assert q[k + "_mm"] == round(f[k + "_m"] * 1e3), k
        fp = native.proposal_defaults()
        assert p["n_points"] == fp["n_points"] and p["seed"] == fp["seed"]
        # 10 deg exactly (2^32 / 36); the float default is 10 deg rounded to float32 (3 BAM32 off)
        assert p["azimuth_bin_bam"] == round(2 ** 32 / 36) == p["elevation_bin_bam"]
        assert abs(p["azimuth_bin_bam"] - fp["azimuth_bin_rad"] / (2 * np.pi) * 2 ** 32) < 8
        assert abs(p["elevation_bin_bam"] - fp["elevation_bin_rad"] / (2 * np.pi) * 2 ** 32) < 8
        assert p["range_bin_4mm"] == round(fp["range_bin_m"] / 0.004)


def test_bit_exact_simulated(sim_scans):
    for sensor, pts in sim_scans:
        c = _check_bit_exact(sensor, pts)
        assert len(c) > 10 and c.stats["n_rescue_joined"] > 0


def test_bit_exact_regrowth(sim_scans):
    """Over-extent components grown again with the tighter gap (regrow_gap_mm, on by default above 16 beams): bit for
    bit with the reference, with the defaults and with a small extent limit that sends most components through it;
    off, they are dropped."""
    regrown = 0
    for sensor, pts in sim_scans:
        if sensor == "hdl64":
            c = _check_bit_exact(sensor, pts)
            regrown += c.stats["n_regrown"]
    assert regrown > 0
    sensor, pts = sim_scans[0]
    on = _check_bit_exact(sensor, pts, max_extent_mm=2500, regrow_max_pixels=0, regrow_cut_mm=0)
    assert on.stats["n_regrown"] > 5 and on.stats["n_regrow_parts"] > on.stats["n_regrown"]
    off = _check_bit_exact(sensor, pts, max_extent_mm=2500, regrow_gap_mm=0)
    assert off.stats["n_regrown"] == 0 and len(off) < len(on)
    assert native.cluster_q_defaults("vlp16")[0]["regrow_gap_mm"] == 0  # off on 16 beams (measured above 16 only)


def test_bit_exact_regrowth_cut(sim_scans):
    """regrow_cut_mm (default 0: off): the regrowth leaves out the component's pixels less
    than the cut above their ground plane, bit for bit with the reference (with the sector planes and the flat ground);
    the scene's outcome on a hand-made street: tests/unit/test_cluster.c, test_regrow_cut."""
    assert native.cluster_q_defaults("hdl64")[0]["regrow_cut_mm"] == 0 == native.cluster_defaults("hdl64")["regrow_cut_m"]
    sensor, pts = sim_scans[0]
    kw = dict(max_extent_mm=2500, regrow_max_pixels=0)
    uncut = _check_bit_exact(sensor, pts, **kw)
    for cut_mm in (250, 600):
        cut = _check_bit_exact(sensor, pts, regrow_cut_mm=cut_mm, **kw)
        assert cut.stats["n_regrown"] == uncut.stats["n_regrown"] > 5
        assert not np.array_equal(cut.labels, uncut.labels)  # the cut changes the parts
    _check_bit_exact(sensor, pts, planes=False, regrow_cut_mm=400, **kw)
    with pytest.raises(native.LidetError):
        native.cluster_q(native.compact_scan(pts, sensor), None, regrow_cut_mm=2001)


def test_bit_exact_far_planes(sim_scans):
    """plane_split_mm: the planes hold the near planes then the far ones, and a mean beyond the split takes its
    sector's far plane (here the near planes lowered by 0.5 m: such heights grow by exactly 125 steps of 4 mm)."""
    sensor, pts = sim_scans[0]
    scan = native.compact_scan(pts, sensor)
    near = native.planes_to_q(scan.planes)
    far = near.copy()
    far[:, 3] += 125
    both = np.concatenate([near, far])
    dc, dp = native.cluster_q_defaults(sensor)
    dc["plane_split_mm"] = 15000
    lab, mem, recs, st = ref.cluster_q_ref(scan.x, scan.y, scan.z, scan.range, scan.row_elev_bam, scan.ground, both,
                                           dc, native.capacity()["max_clusters"])
    c = native.cluster_q(scan, both, plane_split_mm=15000)
    assert np.array_equal(lab, c.labels) and st == c.stats and _recs_equal(recs, c)
    cols, ns = scan.shape[1], len(near)

    def height(seed, mean, table):
        nx, ny, nz, d = (int(v) for v in table[min(int(seed) % cols * ns // cols, ns - 1)])
        return ((nx * int(mean[0]) + ny * int(mean[1]) + nz * int(mean[2]) + (1 << 29)) >> 30) + d
    is_far = [16 * (int(m[0]) ** 2 + int(m[1]) ** 2) >= 15000 ** 2 for m in c.mean]
    assert sum(is_far) > 5 and not all(is_far)
    for s, m, h, f in zip(c.seed_pixel, c.mean, c.height, is_far):
        assert int(h) == height(s, m, far if f else near)
    with pytest.raises(ValueError):
        native.cluster_q(scan, both[:-1], plane_split_mm=15000)


def test_bit_exact_other_paths(sim_scans):
    """Flat ground (no planes), no ground mask, the 4-neighbourhood, occluder bridging on a 16-beam image, no
    gap bound, no rescue, a small extent limit."""
    sensor, pts = sim_scans[1]
    _check_bit_exact(sensor, pts, planes=False, bridge_occluders=1, max_steps=6)
    _check_bit_exact(sensor, pts, ground=False, diagonals=0, max_gap_mm=0, rescue_gap_mm=0)
    sensor, pts = sim_scans[0]
    _check_bit_exact(sensor, pts, planes=False, bridge_occluders=0, max_extent_mm=2500, rescue_rows=3,
                     rescue_cols=9, min_points=20)


def test_bit_exact_capacity(sim_scans):
    """More components than LIDET_MAX_CLUSTERS: the smallest are evicted (first fill) or dropped (rescue groups),
    counted, LIDET_TRUNCATED; the same in the reference."""
    sensor, pts = sim_scans[0]
    c = _check_bit_exact(sensor, pts, min_points=2, theta_urad=800000, max_gap_mm=300, max_gap_per_m_q16=0,
                         join_cars=0)  # (joins would free slots; cuts find none free and leave clusters whole)
    assert c.status == 1 and c.stats["n_dropped_capacity"] > 0 and len(c) == native.capacity()["max_clusters"]


#: fresh crowd scenes (lidet-sim --crowd): (sensor, seed, index)
SIM_CROWD = [("hdl64", 4242, 0), ("hdl64", 4242, 1), ("vlp16", 4242, 0), ("vlp16", 4242, 1)]


@pytest.fixture(scope="module")
def crowd_scans(need_lib):
    return [(s, simulate_scan(s, seed, i, crowd=True).points) for s, seed, i in SIM_CROWD]


def test_bit_exact_crowd(crowd_scans):
    """Crowd scenes: the refinement cuts people out of groups (and joins car pieces), bit for bit."""
    n_split = n_joined = 0
    for sensor, pts in crowd_scans:
        c = _check_bit_exact(sensor, pts)
        n_split += c.stats["n_split"]
        n_joined += c.stats["n_joined"]
    assert n_split > 0 and n_joined > 0, (n_split, n_joined)


def test_bit_exact_refinement_paths(sim_scans):
    """The refinement off, each rule alone, a growing cell and a tight part cap (coarse cells)."""
    sensor, pts = sim_scans[0]
    c = _check_bit_exact(sensor, pts, split_people=0, join_cars=0)
    assert c.stats["n_split"] == c.stats["n_joined"] == 0
    c = _check_bit_exact(sensor, pts, join_cars=0)
    assert c.stats["n_split"] > 0 and c.stats["n_joined"] == 0
    c = _check_bit_exact(sensor, pts, split_people=0)
    assert c.stats["n_split"] == 0 and c.stats["n_joined"] > 0
    _check_bit_exact(sensor, pts, split_cell_per_m_q16=655, split_min_width_mm=600, person_min_aspect_q16=65536)
    c = _check_bit_exact(sim_scans[1][0], sim_scans[1][1], split_cell_mm=5)  # grids past LIDET_REFINE_MAX_CELLS
    assert c.stats["n_split_skipped"] > 0


def test_bit_exact_budgets(sim_scans):
    """Issue 19's bounds in the integer stage: the rescue budget (fragments past max_fragment_pixels dropped and
    counted) and the bridging budget (occluder bridging stops once the run has stepped over
    max_bridge_per_pixel * candidates), the same as the reference; 0 disables each."""
    sensor, pts = sim_scans[1]
    free = _check_bit_exact(sensor, pts, max_fragment_pixels=0)
    assert free.stats["n_dropped_fragment_budget"] == 0 and free.stats["n_fragment_pixels"] > 200
    c = _check_bit_exact(sensor, pts, max_fragment_pixels=200)
    assert c.stats["n_dropped_fragment_budget"] > 0 and c.stats["n_fragment_pixels"] <= 200
    assert c.stats["n_rescue_pixels"] < free.stats["n_rescue_pixels"]
    sensor, pts = sim_scans[0]  # hdl64: occluder bridging on by default
    free = _check_bit_exact(sensor, pts, max_bridge_per_pixel_q16=0)
    c = _check_bit_exact(sensor, pts, max_bridge_per_pixel_q16=3277)  # 0.05 steps per candidate
    bound = (3277 * c.stats["n_candidates"]) >> 16
    # the budget is checked per pixel: one pixel's searches (4 directions of max_steps) may cross it
    assert bound <= c.stats["n_bridge_steps"] <= bound + 4 * 16 < free.stats["n_bridge_steps"]


def test_bit_exact_real(real_dir, need_lib):
    for sensor, pts in _real_scans(real_dir):
        _check_bit_exact(sensor, pts)


# ---- agreement with the float stage on the same compact images -----------------------------------------


def _majority(a: np.ndarray, b: np.ndarray) -> dict:
    """id in a (> 0) -> the id in b (> 0) holding most of its points (ties: the smaller id); none when all of
    its points have b = 0"""
    m = (a > 0) & (b > 0)
    out = {}
    if m.any():
        pairs, counts = np.unique(np.stack([a[m], b[m]], 1), axis=0, return_counts=True)
        order = np.lexsort((pairs[:, 1], -counts))
        for (ia, ib), _ in zip(pairs[order], counts[order]):
            out.setdefault(int(ia), int(ib))
    return out


def id_agreement(qa: np.ndarray, fa: np.ndarray) -> tuple[float, float, int]:
    """Cluster-id agreement of two labellings of the same points (0 = no cluster): the share of points whose
    integer cluster maps to the float cluster holding most of its points (points in no cluster agree when they
    are in none on the other side too), and the same from the float side. Returns (q->f, f->q, points)."""
    mq, mf = _majority(qa, fa), _majority(fa, qa)
    to_f = np.array([mq.get(int(v), -1) if v else 0 for v in qa]) == fa
    to_q = np.array([mf.get(int(v), -1) if v else 0 for v in fa]) == qa
    return float(to_f.mean()), float(to_q.mean()), len(qa)


def agreement(scans) -> dict:
    """Agreement figures over a list of (sensor, points), summed over scans (docs/FIXED_POINT.md)."""
    n_pts = qf = fq = 0.0
    pairs = same_members = same_vox = 0
    max_dev = 0.0
    for sensor, pts in scans:
        scan = native.compact_scan(pts, sensor)
        cq = native.cluster_q(scan, native.planes_to_q(scan.planes))
        cf = native.cluster_f_compact(scan, scan.planes)
        pp = scan.point_pixel
        keep = (pp >= 0)
        keep[keep] = scan.ground.ravel()[pp[keep]] == 0
        a, b = cq.labels.ravel()[pp[keep]].astype(np.int64), cf.labels.ravel()[pp[keep]].astype(np.int64)
        x, y, n = id_agreement(a, b)
        qf, fq, n_pts = qf + x * n, fq + y * n, n_pts + n
        # proposals of the clusters matched both ways
        mq, mf = _majority(cq.labels.ravel(), cf.labels.ravel()), _majority(cf.labels.ravel(), cq.labels.ravel())
        for iq, i_f in mq.items():
            if mf.get(i_f) != iq:
                continue
            pairs += 1
            mem_q = cq.members[cq.first_member[iq - 1]:][: cq.n_points[iq - 1]]
            mem_f = cf.members[cf.first_member[i_f - 1]:][: cf.n_points[i_f - 1]]
            if not np.array_equal(mem_q, mem_f):
                continue
            same_members += 1
            same_vox += int(np.array_equal(cq.prop_voxel[iq - 1], cf.prop_voxel[i_f - 1]))
            dev = np.abs(cq.prop_xyz[iq - 1].astype(np.float64) * 0.004 - cf.prop_xyz[i_f - 1]).max()
            max_dev = max(max_dev, float(dev))
    return {"points": int(n_pts), "ids_q_to_f": qf / n_pts, "ids_f_to_q": fq / n_pts, "matched_clusters": pairs,
            "same_members": same_members / pairs, "same_voxel": same_vox / same_members,
            "max_point_dev_mm": max_dev * 1e3}


def _assert_agreement(a: dict):
    assert a["ids_q_to_f"] >= 0.99 and a["ids_f_to_q"] >= 0.99, a
    assert a["same_voxel"] >= 0.99, a
    assert a["max_point_dev_mm"] <= 4.0, a


def test_id_agreement_definition():
    """The measure: a merge costs the smaller part's points (seen from the merged side), a dropped cluster its
    points (both ways)."""
    q = np.array([1, 1, 1, 1, 2, 2, 0, 0, 3, 3])
    f = np.array([5, 5, 5, 5, 5, 5, 0, 0, 0, 0])  # float merged 1 and 2, dropped 3
    x, y, n = id_agreement(q, f)
    assert n == 10 and x == pytest.approx(0.8) and y == pytest.approx(0.6)
    assert id_agreement(q, q)[:2] == (1.0, 1.0)


def test_agreement_with_float_simulated(sim_scans):
    a = agreement(sim_scans)
    print(f"\nagreement, {len(sim_scans)} simulated scans: {a}")  # the figures of docs/FIXED_POINT.md (pytest -s)
    _assert_agreement(a)


def test_agreement_with_float_crowd(crowd_scans):
    a = agreement(crowd_scans)
    print(f"\nagreement, {len(crowd_scans)} crowd scans: {a}")
    _assert_agreement(a)


def test_agreement_with_float_real(real_dir, need_lib):
    scans = _real_scans(real_dir)
    a = agreement(scans)
    print(f"\nagreement, {len(scans)} real scans: {a}")
    _assert_agreement(a)


def test_bad_config_refused(sim_scans):
    sensor, pts = sim_scans[1]
    scan = native.compact_scan(pts, sensor)
    for bad in (dict(theta_urad=0), dict(max_steps=17), dict(min_points=0), dict(max_extent_mm=0),
                dict(rescue_gap_per_m_q16=16385), dict(rescue_cols=16), dict(split_people=2), dict(split_cell_mm=0),
                dict(car_max_width_mm=0), dict(max_bridge_per_pixel_q16=(64 << 16) + 1), dict(regrow_gap_mm=100001),
                dict(regrow_max_height_mm=0), dict(plane_split_mm=500001)):
        with pytest.raises(native.LidetError):
            native.cluster_q(scan, **bad)
    with pytest.raises(native.LidetError):
        native.cluster_q(scan, proposal_cfg=dict(range_bin_4mm=0))
    with pytest.raises(TypeError):
        native.cluster_q(scan, theta_rad=1)


def _integer_chain_scan(sensor, pts):
    """The integer projection's compact image of the scan (points rounded to mm), with the float ground stage's
    mask and planes of the float projection of the same scan (the integer ground stage is not there yet)."""
    s = native.compact_scan(pts, sensor)
    pq = native.project_q(np.round(pts[:, :3].astype(np.float64) * 1000).astype(np.int32), sensor)
    rows, cols = s.shape
    return native.CompactScan(s.sensor, pq["x_4mm"].reshape(rows, cols), pq["y_4mm"].reshape(rows, cols),
                              pq["z_4mm"].reshape(rows, cols), pq["range_4mm"].reshape(rows, cols),
                              pq["row_elev_bam"], s.row_elev_rad, pq["point_pixel"], s.ground, s.planes), s


def _on_integer_projection(scans, what):
    """On the integer projection's image (lidet_proj_q): bit for bit with the reference, and the per-point ids of
    the integer chain (integer projection + integer clustering) against the float chain (float compact
    projection + float clustering), both with the float ground stage's mask."""
    n = qf = fq = 0.0
    for sensor, pts in scans:
        scan_q, scan_f = _integer_chain_scan(sensor, pts)
        c = native.cluster_q(scan_q, native.planes_to_q(scan_q.planes))
        dc, _ = native.cluster_q_defaults(sensor)
        lab, mem, recs, st = ref.cluster_q_ref(scan_q.x, scan_q.y, scan_q.z, scan_q.range, scan_q.row_elev_bam,
                                               scan_q.ground, native.planes_to_q(scan_q.planes), dc)
        assert np.array_equal(lab, c.labels) and np.array_equal(mem, c.members) and st == c.stats
        f = native.cluster_f_compact(scan_f, scan_f.planes)
        ppq, ppf = scan_q.point_pixel, scan_f.point_pixel
        keep = (ppq >= 0) & (ppf >= 0)
        keep[keep] = scan_f.ground.ravel()[ppf[keep]] == 0
        x, y, k = id_agreement(c.labels.ravel()[ppq[keep]].astype(np.int64),
                               f.labels.ravel()[ppf[keep]].astype(np.int64))
        n, qf, fq = n + k, qf + x * k, fq + y * k
    print(f"\nwhole integer chain vs float chain, {len(scans)} {what} scans, {int(n)} points: "
          f"ids int -> float {qf / n:.5f}, float -> int {fq / n:.5f}")
    assert qf / n >= 0.99 and fq / n >= 0.99


def test_on_integer_projection_simulated(sim_scans):
    _on_integer_projection(sim_scans, "simulated")


def test_on_integer_projection_real(real_dir, need_lib):
    _on_integer_projection(_real_scans(real_dir), "real")


def test_proposals_from_the_ground_bit_exact(sim_scans):
    """lidet_proposal_q_make with z_origin LIDET_PROPOSAL_Z_GROUND against lidet_ref, and against the mean's origin:
    the same x, y and voxels, z shifted up by each record's height (4 mm steps)."""
    sensor, pts = sim_scans[0]
    scan = native.compact_scan(pts, sensor)
    pq = native.planes_to_q(scan.planes)
    a = native.cluster_q(scan, pq)
    b = native.cluster_q(scan, pq, proposal_cfg=dict(z_origin=1))
    dc, dp = native.cluster_q_defaults(sensor)
    lab, mem, recs, st = ref.cluster_q_ref(scan.x, scan.y, scan.z, scan.range, scan.row_elev_bam, scan.ground, pq, dc,
                                           native.capacity()["max_clusters"])
    assert len(recs) > 10
    for i, r in enumerate(recs):
        xyz, mean, vox = ref.make_proposal_q(r, mem, scan.x, scan.y, scan.z, dict(dp, z_origin=1))
        assert np.array_equal(xyz, b.prop_xyz[i]) and np.array_equal(mean, b.prop_mean[i])
        assert np.array_equal(b.prop_voxel[i], a.prop_voxel[i])
        assert mean[2] == r.mean[2] - r.height
    assert np.array_equal(a.prop_xyz[..., :2], b.prop_xyz[..., :2])
    with pytest.raises(native.LidetError):
        native.cluster_q(scan, pq, proposal_cfg=dict(z_origin=2))
