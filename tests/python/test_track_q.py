# SPDX-License-Identifier: MIT
"""The integer tracker (lib/src/track/lidet_track_q.c) through its bindings (lidet_tools.track.native_q) against
the numpy reference (codegen/lidet_ref/track_q.py), bit for bit: every output row, status and counter of
every scan of random sequences (births, deaths, crossings, clutter, heading flips, bad detections, ego motion,
both assignment modes, capacity overflow, extreme values and configurations). The assignment alone: C and
reference identical, and the Hungarian method's total cost equal to brute force and to
scipy.optimize.linear_sum_assignment (when scipy is installed). Then the integer tracker against the float one
(lidet_tools.track.native.Tracker) on a simulated-like sequence: the same ids for the same objects, centres within
TOL_POS_M and velocities within TOL_VEL_MPS."""
import itertools
import math

import numpy as np
import pytest

from lidet_ref import track_q as ref

# integer vs float tracker on the simulated-like sequence (inputs quantised to mm, BAM32, Q15; covariances and
# gains in integers): measured max |dp| 1.6 mm, |dv| 9 mm/s, |dyaw| 1e-3 rad (test_integer_agrees_with_float
# prints them)
TOL_POS_M = 0.005
TOL_VEL_MPS = 0.03
TOL_YAW_RAD = 0.01


@pytest.fixture(scope="module")
def nq(need_lib):
    from lidet_tools.track import native_q
    return native_q


@pytest.fixture(scope="module")
def cap(nq):
    return nq.capacity()


# ---- random sequences ------------------------------------------------------------------------------------------

SIZES = {0: (4.2, 1.8, 1.5), 1: (1.8, 0.6, 1.7), 2: (0.7, 0.7, 1.75)}
SPEEDS = {0: 12.0, 1: 6.0, 2: 2.0}


def sequence(seed: int, n_scans: int = 50, ego: bool = False, n_objects: int = 10, clutter: float = 1.0,
             p_detect: float = 0.85, bad: float = 0.0, dt: float = 0.1, noise: float = 0.05, spread: float = 30.0,
             flip: float = 0.2, wrong_class: float = 0.05, crossings: int = 2):
    """Float scans (dets (n, 9), dt, ego) of constant-velocity objects in a world frame seen from a sensor that
    moves (ego): each object lives over a random span, is detected with p_detect with centre noise, a heading
    flipped by pi with probability flip and sometimes the wrong class; `crossings` pairs of objects meet at one
    point; Poisson(clutter) random detections per scan; a share `bad` of rows with a NaN, a bad class or a zero
    size. Rows sorted by score, best first (as the detector writes them)."""
    rng = np.random.default_rng(seed)
    objs = []
    for _ in range(n_objects):
        c = int(rng.integers(0, 3))
        p = rng.uniform(-spread, spread, 2)
        hd = rng.uniform(-math.pi, math.pi)
        sp = rng.uniform(0.0, SPEEDS[c])
        t0 = int(rng.integers(0, max(n_scans // 2, 1)))
        objs.append([c, p, sp * np.array([math.cos(hd), math.sin(hd)]), hd, t0,
                     int(rng.integers(t0 + 2, n_scans + 2))])
    for _ in range(crossings):
        c = int(rng.integers(0, 3))
        tc = int(rng.integers(n_scans // 4, max(n_scans - n_scans // 4, n_scans // 4 + 1)))
        meet = rng.uniform(-spread / 2, spread / 2, 2)
        hd = rng.uniform(-math.pi, math.pi)
        for turn in (0.0, math.pi / 2 * rng.choice([-1, 1])):
            v = 0.6 * SPEEDS[c] * np.array([math.cos(hd + turn), math.sin(hd + turn)])
            objs.append([c, meet - v * dt * tc, v, hd + turn, 0, n_scans])
    pose = np.zeros(3)
    w_ego = np.array([rng.uniform(2, 8), rng.uniform(-0.3, 0.3)])
    for t in range(n_scans):
        e = None
        if ego and t > 0:
            s, w = w_ego + rng.normal(0, [0.3, 0.05])
            d_local = np.array([s * dt, 0.02 * rng.normal()])
            c0, s0 = math.cos(pose[2]), math.sin(pose[2])
            pose[:2] += [c0 * d_local[0] - s0 * d_local[1], s0 * d_local[0] + c0 * d_local[1]]
            pose[2] += w * dt
            e = (float(d_local[0]), float(d_local[1]), float(w * dt))
        c0, s0 = math.cos(pose[2]), math.sin(pose[2])
        rows = []
        for c, p, v, hd, t0, t1 in objs:
            if not t0 <= t < t1 or rng.random() > p_detect:
                continue
            wx, wy = p + v * dt * t - pose[:2]
            x, y = c0 * wx + s0 * wy, -s0 * wx + c0 * wy
            yaw = hd - pose[2] + (math.pi if rng.random() < flip else 0.0)
            cls = c if rng.random() > wrong_class else int(rng.integers(0, 3))
            l, w_, h = np.array(SIZES[c]) * rng.uniform(0.9, 1.1, 3)
            rows.append([cls, x + rng.normal(0, noise), y + rng.normal(0, noise), rng.normal(-0.8, 0.05), l, w_, h,
                         yaw, rng.uniform(0.3, 1.0)])
        for _ in range(rng.poisson(clutter)):
            c = int(rng.integers(0, 3))
            rows.append([c, *rng.uniform(-spread, spread, 2), -0.8, *SIZES[c], rng.uniform(-4, 4),
                         rng.uniform(0.05, 0.6)])
        d = np.array(rows, np.float64).reshape(-1, 9)
        for r in range(len(d)):
            if rng.random() < bad:
                k = int(rng.integers(0, 3))
                if k == 0:
                    d[r, int(rng.integers(1, 9))] = np.nan
                elif k == 1:
                    d[r, 0] = 5
                else:
                    d[r, int(rng.integers(4, 7))] = 0.0
        d = d[np.argsort(-np.nan_to_num(d[:, 8], nan=-1.0), kind="stable")]
        yield d, dt, e


def run_both(nq, cap, scans, **cfg):
    """Feed the quantised scans to the C tracker and the reference; assert every scan identical; return the
    number of scans and the largest number of tracks seen."""
    c = nq.TrackerQ(**cfg)
    r = ref.TrackerQ(max_tracks=cap["max_tracks"], max_dets=cap["max_dets"], **cfg)
    n, most = 0, 0
    for dq, dt_ms, eq in scans:
        got = c.update_q(dq, dt_ms, eq, flags=ref.OUT_COASTING | ref.OUT_TENTATIVE, check=False)
        st = r.update(dq, dt_ms, eq)
        exp = r.tracks(ref.OUT_COASTING | ref.OUT_TENTATIVE)
        assert c.status == st, f"scan {n}: status {c.status} != {st}"
        np.testing.assert_array_equal(got, exp, err_msg=f"scan {n}")
        assert c.stats() == r.stats, f"scan {n}"
        for flags in (0, ref.OUT_COASTING):
            np.testing.assert_array_equal(c.tracks_q(flags), r.tracks(flags))
        np.testing.assert_array_equal(c.tracks_q(ref.OUT_TENTATIVE, cap=3), r.tracks(ref.OUT_TENTATIVE, cap=3))
        n += 1
        most = max(most, len(exp))
    return n, most


def quantised(scans):
    for d, dt, e in scans:
        yield ref.quantise_dets(d), ref.quantise_dt(dt), ref.quantise_ego(e)


# ---- configuration and conversions ---------------------------------------------------------------------------

def test_cfg_default_matches_c(nq):
    np.testing.assert_array_equal(nq.cfg_default_c(), ref.cfg_to_array(ref.cfg_default()))
    # the float defaults converted give the integer defaults
    si = dict(meas_sigma_m=[0.30, 0.25, 0.20], accel_sigma_mps2=[2.0, 2.5, 1.5], init_vel_sigma_mps=[10, 6, 3],
              gate_max_m=[4.0, 3.0, 2.0], gate_chi2=9.21, class_penalty=2.0, birth_min_score=0.0, yaw_alpha=0.5,
              size_alpha=0.3, heading_speed_mps=1.0)
    assert ref.cfg_from(**si) == ref.cfg_default()
    assert ref.cfg_from(meas_sigma=0.1, assign="greedy", heading_from_velocity=["car"])["meas_sigma_mm"] == [100] * 3
    assert ref.cfg_from(heading_from_velocity=["car", 2])["heading_from_velocity"] == 5
    with pytest.raises(TypeError):
        ref.cfg_from(no_such_field=1)


def test_cfg_validation_matches_c(nq):
    rng = np.random.default_rng(3)
    base = ref.cfg_to_array(ref.cfg_default())
    lo = np.array([1] * 3 + [0] * 3 + [0] * 3 + [1] * 3 + [1, 0, 0, 1, 0, 0, 0, 0, 0, 0] + [0] * 3)
    hi = np.array([10000] * 3 + [100000] * 3 + [46340] * 3 + [1000000] * 3
                  + [1000 * 65536, 1000 * 65536, 1, 1000, 1000, 32768, 32768, 32768, 100000, 7] + [1000] * 3)
    names = [n for n, k in ref.CFG_FIELDS for _ in range(k)]
    n_bad = 0
    for trial in range(400):
        a = base.copy()
        for i in rng.choice(len(a), int(rng.integers(1, 3)), replace=False):
            a[i] = rng.choice([lo[i] - 1, lo[i], hi[i], hi[i] + 1, int(rng.integers(lo[i], hi[i] + 1)),
                               -(2**40), 2**40])
        cfg = {}
        pos = 0
        for name, k in ref.CFG_FIELDS:
            cfg[name] = [int(x) for x in a[pos:pos + k]] if k > 1 else int(a[pos])
            pos += k
        ok = ref.cfg_ok(cfg)
        expect_ok = bool(np.all((a >= lo) & (a <= hi)))
        assert ok == expect_ok, (trial, dict(zip(names, a)))
        if ok:
            nq.TrackerQ(**cfg)
        else:
            n_bad += 1
            with pytest.raises(ValueError):
                nq.TrackerQ(**cfg)
    assert 100 < n_bad < 390


def test_quantisation():
    d = np.array([[0, 1.0005, -1.0005, 0.0004999, 4.2, 1.8, 1.5, math.pi, 0.5],
                  [2, -0.0005, 2e9, 0, 0.7, 0.7, 1.7, -math.pi / 2, 1.5],
                  [1, np.nan, 0, 0, 1, 1, 1, 0, 0.5],
                  [3, 0, 0, 0, 1, 1, 1, 0, 0.5],
                  [1.5, 0, 0, 0, 1, 1, 1, 0, -0.2]])
    q = ref.quantise_dets(d)
    assert q[0].tolist() == [0, 1001, -1001, 0, 4200, 1800, 1500, -(2**31), 16384]
    assert q[1].tolist() == [2, -1, 2**31 - 1, 0, 700, 700, 1700, -(2**30), 32768]
    assert q[2, 0] == 255 and q[3, 0] == 255 and q[4, 0] == 255 and q[4, 8] == 0
    assert ref.quantise_ego((0.0015, -0.0015, 2 * math.pi)) == (2, -2, 0)
    assert ref.quantise_dt(0.1) == 100


# ---- bit-exact: C against the reference -------------------------------------------------------------------------

@pytest.mark.parametrize("seed,assign,ego", [(1, 0, False), (2, 1, False), (3, 0, True), (4, 1, True),
                                             (5, 0, True)])
def test_bit_exact_random_sequences(nq, cap, seed, assign, ego):
    scans = sequence(seed, n_scans=50, ego=ego, n_objects=12, clutter=1.5, bad=0.05)
    n, most = run_both(nq, cap, quantised(scans), assign=assign)
    assert n == 50 and most >= 5


@pytest.mark.parametrize("seed,assign", [(6, 0), (7, 1)])
def test_bit_exact_dense(nq, cap, seed, assign):
    """Objects within a few metres of each other with 20 cm noise: many pairs inside several gates."""
    r = ref.TrackerQ(max_tracks=cap["max_tracks"], max_dets=cap["max_dets"], assign=assign)
    scans = list(quantised(sequence(seed, n_scans=50, ego=True, n_objects=12, clutter=2, spread=6, noise=0.2)))
    run_both(nq, cap, scans, assign=assign)
    matched = feasible = 0
    for d, dt, e in scans:
        r.update(d, dt, e)
        matched += r.stats["n_matched"]
        feasible += r.stats["n_feasible_pairs"]
    assert feasible > matched + 50  # the assignment has choices to make


@pytest.mark.parametrize("seed,assign", [(11, 0), (12, 1)])
def test_bit_exact_crowded_and_over_capacity(nq, cap, seed, assign):
    """More objects and clutter than the capacities: births dropped, detections dropped (LIDET_TRUNCATED)."""
    mt, md = cap["max_tracks"], cap["max_dets"]
    scans = list(quantised(sequence(seed, n_scans=14, n_objects=md + 10, clutter=15, spread=40, p_detect=0.95,
                                    crossings=4)))
    assert max(len(d) for d, _, _ in scans) > md
    c = nq.TrackerQ(confirm_hits=1, max_misses=5, assign=assign)
    saw = {"drop": False, "births": False}
    r = ref.TrackerQ(max_tracks=mt, max_dets=md, confirm_hits=1, max_misses=5, assign=assign)
    for dq, dt_ms, eq in scans:
        got = c.update_q(dq, dt_ms, eq, flags=3, check=False)
        assert c.status == r.update(dq, dt_ms, eq)
        np.testing.assert_array_equal(got, r.tracks(3))
        assert c.stats() == r.stats
        saw["drop"] |= r.stats["n_dets_dropped"] > 0
        saw["births"] |= r.stats["n_births_dropped"] > 0
    assert saw["drop"] and (saw["births"] or mt > md)


def test_bit_exact_irregular_dt_and_flags(nq, cap):
    """dt from 1 ms to 10 s, bursts of missed scans, heading classes and thresholds changed."""
    rng = np.random.default_rng(21)
    scans = []
    for d, _, e in sequence(22, n_scans=60, ego=True, n_objects=8, p_detect=0.6, flip=0.5, wrong_class=0.3):
        dt = float(rng.choice([0.001, 0.05, 0.1, 0.5, 2.0, 10.0]))
        scans.append((ref.quantise_dets(d), ref.quantise_dt(dt), ref.quantise_ego(e)))
    run_both(nq, cap, scans, heading_from_velocity=7, heading_speed_mps=0.0, birth_min_score=0.5,
             yaw_alpha=1.0, size_alpha=0.0, class_penalty=0.0, confirm_hits=3, max_misses=0)
    run_both(nq, cap, scans, heading_from_velocity=0, gate_chi2=1000.0, gate_max_m=50.0, accel_sigma_mps2=0.0,
             init_vel_sigma_mps=0.0, assign=1)


def test_bit_exact_extreme_values(nq, cap):
    """Centres at and beyond +-2^20 mm, sizes and scores at and past their limits, jumps across the whole range,
    dt at both ends, ego motions at the limit, every configuration value at the end that makes numbers large:
    no overflow anywhere (C and reference agree, and the covariance stays positive definite)."""
    rng = np.random.default_rng(31)
    M = ref.COORD_MAX_MM
    cfg = dict(meas_sigma_mm=[10000, 1, 5000], accel_sigma_mmps2=[100000, 0, 100000],
               init_vel_sigma_mmps=[46340, 0, 1], gate_max_mm=[1000000, 1, 1000000], gate_chi2_q16=1000 * 65536,
               class_penalty_q16=1000 * 65536, confirm_hits=1, max_misses=1000, heading_speed_mmps=0,
               heading_from_velocity=5)
    for assign in (0, 1):
        scans = []
        for t in range(80):
            n = int(rng.integers(0, 8))
            d = np.zeros((n, 9), np.int64)
            d[:, 0] = rng.integers(-1, 4, n)
            d[:, 1:4] = rng.choice([-M - 1, -M, -M + 1, 0, M - 1, M, M + 1, int(rng.integers(-M, M))], (n, 3))
            d[:, 4:7] = rng.choice([0, 1, 2, 100, 99999, 100000, 100001], (n, 3))
            d[:, 7] = rng.integers(-(2**31), 2**31, n)
            d[:, 8] = rng.choice([-1, 0, 1, 16384, 32767, 32768, 32769], n)
            dt = int(rng.choice([0, 1, 2, 999, 10000, 10001]))
            ego = None if rng.random() < 0.5 else (int(rng.choice([-M - 1, -M, 0, M, 12345])),
                                                   int(rng.choice([-M, 0, M, M + 1])),
                                                   int(rng.integers(-(2**31), 2**31)))
            scans.append((d, dt, ego))
        run_both(nq, cap, scans, assign=assign, **cfg)
        # the invariants on the reference's state after the run
        r = ref.TrackerQ(max_tracks=cap["max_tracks"], max_dets=cap["max_dets"], assign=assign, **cfg)
        for d, dt, e in scans:
            r.update(d, dt, e)
            a = r.active
            assert np.all(r.pp[a] >= 1) and np.all(r.vv[a] >= 1) and np.all(r.pp[a] <= ref.P_MAX)
            assert np.all([int(p) ** 2 < int(q) * int(v) for p, q, v in zip(r.pv[a], r.pp[a], r.vv[a])])
            assert np.all(np.abs(r.x[a]) <= ref.COORD_MAX_Q8) and np.all(np.abs(r.vx[a]) <= ref.VMAX_Q8)


def test_fast_objects_and_long_gaps(nq, cap):
    """Objects at 60-100 m/s near the edge of the coordinate range (they leave it and die), large dt."""
    rng = np.random.default_rng(41)
    M = ref.COORD_MAX_MM
    scans = []
    pos = np.array([[M - 300000, 0], [-M + 1000, M - 1000], [0, -M + 50000]], np.float64)
    vel = np.array([[90000, 0], [60000, -60000], [-1000, -99000]], np.float64)
    for t in range(40):
        dt = int(rng.choice([100, 100, 100, 1000, 3000]))
        pos += vel * dt / 1000.0
        keep = np.all(np.abs(pos) <= M, axis=1)
        d = np.zeros((int(keep.sum()), 9), np.int64)
        d[:, 0] = 0
        d[:, 1:3] = np.round(pos[keep])
        d[:, 4:7] = [4000, 1800, 1500]
        d[:, 8] = 30000
        scans.append((d, dt, None))
    run_both(nq, cap, scans, gate_max_mm=[1000000] * 3, gate_chi2_q16=1000 * 65536)


# ---- the assignment ---------------------------------------------------------------------------------------------

def _padded_total(cost, row_col, big):
    nr, nc = cost.shape
    n = max(nr, nc)
    m = row_col >= 0
    return int(cost[np.flatnonzero(m), row_col[m]].sum()) + big * (n - int(m.sum()))


def _random_costs(rng, nr, nc):
    big = int(rng.choice([10, 1000, 603587 + 131072 + 65536]))
    c = rng.integers(0, big, (nr, nc))
    c[rng.random((nr, nc)) < rng.uniform(0, 0.7)] = big  # infeasible pairs
    if rng.random() < 0.3:
        c = np.minimum(c, rng.integers(0, 4, (nr, nc)) * (big // 4))  # many ties
    return c.astype(np.int64), big


def test_assignment_c_equals_reference_and_brute_force(nq):
    rng = np.random.default_rng(51)
    for trial in range(300):
        nr, nc = int(rng.integers(0, 7)), int(rng.integers(0, 7))
        cost, big = _random_costs(rng, nr, nc)
        for mode in (ref.ASSIGN_OPTIMAL, ref.ASSIGN_GREEDY):
            got = nq.assign_q(cost, big, mode)
            exp = ref.assign(cost, big, mode) if nr and nc else np.full(nr, -1)
            np.testing.assert_array_equal(got, exp, err_msg=f"trial {trial} mode {mode}")
            cols = got[got >= 0]
            assert len(set(cols.tolist())) == len(cols)
            assert np.all(cost[np.flatnonzero(got >= 0), cols] < big)
        if nr and nc:
            n = max(nr, nc)
            a = np.full((n, n), big, np.int64)
            a[:nr, :nc] = cost
            best = min(int(a[np.arange(n), list(p)].sum()) for p in itertools.permutations(range(n)))
            assert _padded_total(cost, nq.assign_q(cost, big, 0), big) == best
            # greedy is never better than optimal
            assert _padded_total(cost, nq.assign_q(cost, big, 1), big) >= best


def test_assignment_large_against_scipy(nq, cap):
    scipy_opt = pytest.importorskip("scipy.optimize")
    rng = np.random.default_rng(61)
    for trial in range(40):
        nr = int(rng.integers(1, cap["max_tracks"] + 1))
        nc = int(rng.integers(1, cap["max_dets"] + 1))
        cost, big = _random_costs(rng, nr, nc)
        n = max(nr, nc)
        a = np.full((n, n), big, np.int64)
        a[:nr, :nc] = cost
        ri, ci = scipy_opt.linear_sum_assignment(a)
        got = nq.assign_q(cost, big, 0)
        assert _padded_total(cost, got, big) == int(a[ri, ci].sum()), trial
        np.testing.assert_array_equal(got, ref.hungarian(cost, big))


def test_assignment_large_c_equals_reference(nq, cap):
    """Full-size random matrices (no scipy needed): C and reference identical, never worse than greedy."""
    rng = np.random.default_rng(62)
    for trial in range(6):
        nr, nc = cap["max_tracks"], int(rng.integers(1, cap["max_dets"] + 1))
        cost, big = _random_costs(rng, nr, nc)
        opt = nq.assign_q(cost, big, 0)
        np.testing.assert_array_equal(opt, ref.hungarian(cost, big))
        gr = nq.assign_q(cost, big, 1)
        np.testing.assert_array_equal(gr, ref.greedy(cost, big))
        assert _padded_total(cost, opt, big) <= _padded_total(cost, gr, big)


# ---- the integer tracker against the float one ------------------------------------------------------------------

def test_integer_agrees_with_float(nq):
    """A simulated-like sequence (cars, cyclists, pedestrians well apart, a moving and turning sensor, centre
    noise 5 cm, missed detections): the float tracker (lidet_tools.track.native.Tracker) on float32 detections,
    the integer one on the same detections quantised. Same ids, states, classes, detection indices; centres within
    TOL_POS_M, velocities within TOL_VEL_MPS, reported yaws within TOL_YAW_RAD."""
    tn = pytest.importorskip("lidet_tools.track.native")
    rng = np.random.default_rng(71)
    # objects on a 12 m grid (no two within a gate of each other), gentle speeds
    objs = []
    for k, (gx, gy) in enumerate(itertools.product(range(-2, 3), range(-2, 3))):
        c = k % 3
        hd = rng.uniform(-math.pi, math.pi)
        sp = rng.uniform(0.3, 0.5) * SPEEDS[c]
        objs.append((c, np.array([12.0 * gx + 40, 12.0 * gy]), sp * np.array([math.cos(hd), math.sin(hd)]), hd))
    f = tn.Tracker()
    q = tn.Tracker(fixed=True)
    assert isinstance(q._impl, nq.TrackerQ)
    pose = np.zeros(3)
    worst = {"pos": 0.0, "vel": 0.0, "yaw": 0.0}
    n_compared = 0
    dt = 0.1
    for t in range(80):
        ego = None
        if t > 0:
            s, w = 5.0 + rng.normal(0, 0.2), 0.1 + rng.normal(0, 0.02)
            c0, s0 = math.cos(pose[2]), math.sin(pose[2])
            pose[:2] += [c0 * s * dt, s0 * s * dt]
            pose[2] += w * dt
            ego = (s * dt, 0.0, w * dt)
        c0, s0 = math.cos(pose[2]), math.sin(pose[2])
        rows = []
        for c, p, v, hd in objs:
            if rng.random() > 0.9:
                continue
            wx, wy = p + v * dt * t - pose[:2]
            rows.append([c, c0 * wx + s0 * wy + rng.normal(0, 0.05), -s0 * wx + c0 * wy + rng.normal(0, 0.05),
                         -0.8, *SIZES[c], hd - pose[2], rng.uniform(0.5, 1.0)])
        d = np.array(rows, np.float32)
        d = d[np.argsort(-d[:, 8], kind="stable")]
        a = f.update(d, dt, ego=ego, flags=3)
        b = q.update(d, dt, ego=ego, flags=3)
        assert f.stats() == q.stats(), t
        for name in ("id", "state", "cls", "det", "hits", "misses", "age"):
            np.testing.assert_array_equal(a[name], b[name], err_msg=f"scan {t}: {name}")
        if len(a):
            worst["pos"] = max(worst["pos"], float(np.max(np.hypot(a["x"] - b["x"], a["y"] - b["y"]))))
            worst["vel"] = max(worst["vel"], float(np.max(np.hypot(a["vx"] - b["vx"], a["vy"] - b["vy"]))))
            conf = a["hits"] >= 4  # the heading test (|v|^2 >= 4 p_vv) may differ on a track's first scans
            if conf.any():
                dyaw = np.angle(np.exp(1j * (a["yaw"].astype(np.float64) - b["yaw"])))[conf]
                worst["yaw"] = max(worst["yaw"], float(np.max(np.abs(dyaw))))
            n_compared += len(a)
    print(f"integer vs float: max |dp| {worst['pos'] * 1000:.2f} mm, max |dv| {worst['vel'] * 1000:.1f} mm/s, "
          f"max |dyaw| {worst['yaw']:.2e} rad over {n_compared} tracks")
    assert n_compared > 1000
    assert worst["pos"] <= TOL_POS_M
    assert worst["vel"] <= TOL_VEL_MPS
    assert worst["yaw"] <= TOL_YAW_RAD
