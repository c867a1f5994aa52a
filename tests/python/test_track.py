# SPDX-License-Identifier: MIT
"""The float tracker (lib/src/track/lidet_track.c) through its bindings (lidet_tools.track) against the numpy
reference (codegen/lidet_ref/track.py) on random sequences: births, deaths, crossings, clutter, heading
flips, bad detections, ego motion, both assignment modes, capacity. Ids, states, classes, counters, detection
indices and statuses are identical; the floats agree bit for bit without ego motion (the reported yaw aside: the
C's atan2f against the reference's correctly rounded atan2, within TOL_YAW) and within TOL_ATOL + TOL_RTOL |ref|
with it (the C's sinf / cosf against correctly rounded values: a few float32 ulps of the state, see the
reference's docstring). The reference's Hungarian method against brute force (and scipy when installed)."""
import itertools
import math

import numpy as np
import pytest

from lidet_ref import track as ref

TOL_ATOL = 1e-4   # metres, m/s, covariances, radians: with ego motion
TOL_RTOL = 1e-5
TOL_YAW = 2e-6    # the reported yaw without ego motion (atan2f: 1 ulp of an angle <= pi is 2.4e-7)
FLOATS = ("x", "y", "z", "l", "w", "h", "yaw", "vx", "vy", "p_pp", "p_pv", "p_vv", "score")
INTS = ("id", "cls", "state", "hits", "misses", "age", "det")


@pytest.fixture(scope="module")
def tn(need_lib):
    from lidet_tools.track import native
    return native


# ---- random sequences ------------------------------------------------------------------------------------------

SIZES = {0: (4.2, 1.8, 1.5), 1: (1.8, 0.6, 1.7), 2: (0.7, 0.7, 1.75)}
SPEEDS = {0: 10.0, 1: 5.0, 2: 1.5}


def sequence(seed: int, n_scans: int = 60, ego: bool = False, n_objects: int = 12, clutter: float = 1.0,
             p_detect: float = 0.85, bad: float = 0.0, dt: float = 0.1):
    """Scans of detections of constant-velocity objects in a world frame seen from a sensor that moves (ego):
    each object lives over a random span of scans, is detected with p_detect with centre noise, a heading flipped
    by pi one time in five and sometimes the wrong class; two pairs of them cross each other; clutter adds
    Poisson-many random detections, bad a share of rows with a NaN, a bad class or a zero size. Yields (dets,
    dt, ego) with dets (n, 9) float32 sorted by score (as the detector writes them)."""
    rng = np.random.default_rng(seed)
    objs = []
    for k in range(n_objects):
        c = int(rng.integers(0, 3))
        p = rng.uniform([-30, -30], [30, 30])
        hd = rng.uniform(-math.pi, math.pi)
        sp = rng.uniform(0.0, SPEEDS[c])
        v = sp * np.array([math.cos(hd), math.sin(hd)])
        t0 = int(rng.integers(0, n_scans // 2))
        t1 = int(rng.integers(t0 + 3, n_scans + 1))
        objs.append([c, p, v, hd if sp > 0.2 else rng.uniform(-math.pi, math.pi), t0, t1])
    for k in range(2):  # crossing pairs: both reach the same point at scan tc
        c = int(rng.integers(0, 3))
        tc = int(rng.integers(n_scans // 4, n_scans - n_scans // 4))
        meet = rng.uniform([-15, -15], [15, 15])
        for sgn in (1, -1):
            hd = rng.uniform(-math.pi, math.pi) if sgn == 1 else hd + math.pi / 2 * rng.choice([-1, 1])
            sp = 0.6 * SPEEDS[c]
            v = sp * np.array([math.cos(hd), math.sin(hd)])
            objs.append([c, meet - v * dt * tc, v, hd, 0, n_scans])
    pose = np.zeros(3)  # sensor x, y, heading in the world
    w_ego = np.array([rng.uniform(2, 8), rng.uniform(-0.3, 0.3)]) if ego else np.zeros(2)  # speed, yaw rate
    for t in range(n_scans):
        e = None
        if ego and t > 0:
            jitter = rng.normal(0, [0.3, 0.05])
            s, w = w_ego + jitter
            dyaw = w * dt
            d_local = np.array([s * dt, 0.02 * rng.normal()])
            c0, s0 = math.cos(pose[2]), math.sin(pose[2])
            pose[:2] += [c0 * d_local[0] - s0 * d_local[1], s0 * d_local[0] + c0 * d_local[1]]
            pose[2] += dyaw
            e = (float(d_local[0]), float(d_local[1]), float(dyaw))
        c0, s0 = math.cos(pose[2]), math.sin(pose[2])
        rows = []
        for c, p, v, hd, t0, t1 in objs:
            if not t0 <= t < t1 or rng.random() > p_detect:
                continue
            wp = p + v * dt * t
            rel = wp - pose[:2]
            sx, sy = c0 * rel[0] + s0 * rel[1], -s0 * rel[0] + c0 * rel[1]
            yaw = hd - pose[2] + (math.pi if rng.random() < 0.2 else 0.0) + rng.normal(0, 0.1)
            yaw = (yaw + math.pi) % (2 * math.pi) - math.pi
            cls = c if rng.random() > 0.05 else int(rng.integers(0, 3))
            l, w_, h = SIZES[c]
            rows.append([cls, sx + rng.normal(0, 0.15), sy + rng.normal(0, 0.15), -1.0 + rng.normal(0, 0.05),
                         l * rng.uniform(0.9, 1.1), w_ * rng.uniform(0.9, 1.1), h * rng.uniform(0.9, 1.1), yaw,
                         rng.uniform(0.3, 1.0)])
        for _ in range(rng.poisson(clutter)):
            cls = int(rng.integers(0, 3))
            l, w_, h = SIZES[cls]
            rows.append([cls, *rng.uniform([-40, -40], [40, 40]), -1.0, l, w_, h, rng.uniform(-math.pi, math.pi),
                         rng.uniform(0.05, 0.6)])
        d = np.array(rows, np.float32).reshape(-1, 9)
        if bad > 0 and len(d):
            for i in np.flatnonzero(rng.random(len(d)) < bad):
                kind = int(rng.integers(0, 4))
                if kind == 0:
                    d[i, int(rng.integers(1, 9))] = np.nan
                elif kind == 1:
                    d[i, 0] = rng.choice([3.0, -1.0, 0.5])
                elif kind == 2:
                    d[i, int(rng.integers(4, 7))] = 0.0
                else:
                    d[i, 1] = np.inf
        d = d[np.argsort(-np.nan_to_num(d[:, 8], nan=-1.0), kind="stable")]
        yield d, dt, e


def compare(a: np.ndarray, b: np.ndarray, exact: bool, where: str) -> float:
    """a (C) against b (reference): integers equal, floats per the tolerances; returns the largest float
    difference (the reported yaw's aside when exact)."""
    assert len(a) == len(b), f"{where}: {len(a)} C tracks, {len(b)} reference tracks"
    for f in INTS:
        np.testing.assert_array_equal(a[f], b[f], err_msg=f"{where}: {f}")
    worst = 0.0
    for f in FLOATS:
        x, y = a[f].astype(np.float64), b[f].astype(np.float64)
        if f == "yaw":  # angles: compare on the circle
            diff = np.abs((x - y + math.pi) % (2 * math.pi) - math.pi)
        else:
            diff = np.abs(x - y)
        if exact and f != "yaw":
            np.testing.assert_array_equal(a[f], b[f], err_msg=f"{where}: {f}")
            continue
        tol = TOL_YAW if exact else TOL_ATOL + TOL_RTOL * np.abs(y)
        assert np.all(diff <= tol), f"{where}: {f} differs by {diff.max()}"
        if len(diff):
            worst = max(worst, float(diff.max()))
    return worst


def run_pair(tn, seq, cfg=None, flags=3):
    """The C and the reference over one sequence; returns (worst float difference, summed stats)."""
    cfg = cfg or {}
    c = tn.Tracker(**cfg)
    cap = tn.capacity()
    r = ref.Tracker(max_tracks=cap["max_tracks"], max_dets=cap["max_dets"], **cfg)
    worst, total = 0.0, dict.fromkeys(ref.STATS, 0)
    for t, (d, dt, e) in enumerate(seq):
        a = c.update(d, dt, ego=e, flags=flags)
        st = r.update(d, dt, ego=e)
        assert c.status == st, f"scan {t}: status {c.status} != {st}"
        assert c.stats() == r.stats, f"scan {t}: {c.stats()} != {r.stats}"
        worst = max(worst, compare(a, r.tracks(flags), e is None, f"scan {t}"))
        for k, v in r.stats.items():
            total[k] += v
    return worst, total


@pytest.mark.parametrize("assign", ["optimal", "greedy"])
@pytest.mark.parametrize("seed", range(4))
def test_matches_reference_without_ego(tn, assign, seed):
    seq = sequence(100 + seed, bad=0.05)
    _, tot = run_pair(tn, seq, {"assign": ref.ASSIGN_GREEDY if assign == "greedy" else ref.ASSIGN_OPTIMAL})
    # the sequence exercised what it is meant to
    assert tot["n_births"] > 10 and tot["n_deaths"] > 3 and tot["n_matched"] > 100 and tot["n_bad_dets"] > 0


@pytest.mark.parametrize("assign", ["optimal", "greedy"])
@pytest.mark.parametrize("seed", range(4))
def test_matches_reference_with_ego(tn, assign, seed):
    seq = sequence(200 + seed, ego=True, clutter=2.0)
    worst, tot = run_pair(tn, seq, {"assign": assign})
    assert tot["n_births"] > 10 and tot["n_matched"] > 100
    assert worst <= TOL_ATOL


def test_matches_reference_other_settings(tn):
    """Non-default settings: tight gates, no class penalty, confirm at the first hit, long coasting, a birth
    threshold, heading from velocity for every class, no heading speed."""
    cfg = {"gate_chi2": 5.99, "class_penalty": 0.0, "confirm_hits": 1, "max_misses": 8, "birth_min_score": 0.4,
           "heading_from_velocity": 7, "heading_speed_mps": 0.0, "yaw_alpha": 0.8, "size_alpha": 1.0,
           "meas_sigma_m": [0.5, 0.4, 0.3], "gate_max_m": [6.0, 4.0, 3.0]}
    run_pair(tn, sequence(300, n_scans=50, clutter=3.0, p_detect=0.6), cfg)
    run_pair(tn, sequence(301, n_scans=50, ego=True, clutter=3.0, p_detect=0.6), dict(cfg, assign=1))


def test_matches_reference_crowded(tn):
    """A dense scene: many objects close together (ambiguous assignments), the Hungarian method's real work."""
    seq = sequence(400, n_scans=30, n_objects=45, clutter=4.0, p_detect=0.9)
    _, tot = run_pair(tn, seq)
    assert tot["n_feasible_pairs"] > tot["n_matched"]


def test_capacity_births_and_detections(tn):
    """More detections than LIDET_TRACK_MAX_DETS (the first ones used, LIDET_TRUNCATED) and more live tracks
    than LIDET_TRACK_MAX_TRACKS (births counted as dropped): as the reference."""
    cap = tn.capacity()
    rng = np.random.default_rng(7)
    n = cap["max_dets"] + 10
    scans = []
    for t in range(6):  # a row of static objects seen twice (confirmed, then coasting), then rows elsewhere
        xy = np.stack(np.meshgrid(np.arange(n) * 5.0, [max(t - 1, 0) * 7.0]), -1).reshape(-1, 2)[:n]
        d = np.zeros((n, 9), np.float32)
        d[:, 0] = 2
        d[:, 1:3] = xy + rng.normal(0, 0.01, xy.shape)
        d[:, 3:7] = [-1, 0.7, 0.7, 1.7]
        d[:, 8] = np.linspace(0.9, 0.5, n)
        scans.append((d, 0.1, None))
    c = tn.Tracker(max_misses=10)
    r = ref.Tracker(max_tracks=cap["max_tracks"], max_dets=cap["max_dets"], max_misses=10)
    saw_drop = False
    for t, (d, dt, e) in enumerate(scans):
        a = c.update(d, dt, flags=3)
        assert r.update(d, dt) == c.status == 1
        s = c.stats()
        assert s == r.stats
        assert s["n_dets_dropped"] == 10
        saw_drop |= s["n_births_dropped"] > 0
        assert s["n_tracks"] <= cap["max_tracks"]
        compare(a, r.tracks(3), True, f"scan {t}")
    assert saw_drop


def test_track_dtype_and_defaults(tn):
    assert tn.TRACK_DTYPE == ref.TRACK_DTYPE
    d = tn.cfg_default()
    for k, v in ref.cfg_default().items():
        np.testing.assert_array_equal(np.float32(d[k]), np.float32(v), err_msg=k)
    assert tn.capacity()["bytes"] > 0


# ---- error cases through the binding ---------------------------------------------------------------------------

def test_errors(tn):
    from lidet_tools import native
    t = tn.Tracker()
    d = np.array([[0, 10, 0, -1, 4, 1.8, 1.5, 0, 0.9]], np.float32)
    t.update(d, 0.1)
    for dt in (0.0, -0.1, 10.5, float("nan"), float("inf")):
        with pytest.raises(native.LidetError) as e:
            t.update(d, dt)
        assert e.value.name == "LIDET_ERR_ARG"
    for ego in ((float("nan"), 0, 0), (0, float("inf"), 0), (0, 0, 4.0), (1001.0, 0, 0)):
        with pytest.raises(native.LidetError) as e:
            t.update(d, 0.1, ego=ego)
        assert e.value.name == "LIDET_ERR_ARG"
    # the failed calls changed nothing: the second scan confirms the track
    out = t.update(d, 0.1)
    assert len(out) == 1 and out["id"][0] == 1 and out["state"][0] == tn.CONFIRMED and out["age"][0] == 1
    # bad configurations
    for bad in ({"gate_chi2": 0.0}, {"gate_chi2": float("nan")}, {"meas_sigma": [0.3, 0.0, 0.2]},
                {"accel_sigma": -1.0}, {"gate_max": [4, 3, float("inf")]}, {"confirm_hits": 0},
                {"max_misses": 1001}, {"yaw_alpha": 1.5}, {"size_alpha": -0.1}, {"birth_min_score": 2.0},
                {"heading_speed": 101.0}, {"heading_from_velocity": 8}, {"assign": 2}, {"class_penalty": -1}):
        with pytest.raises(native.LidetError) as e:
            tn.Tracker(**bad)
        assert e.value.name == "LIDET_ERR_CONFIG", bad
    with pytest.raises(TypeError):
        tn.Tracker(no_such_field=1)
    with pytest.raises(ValueError):
        tn.Tracker(assign="fastest")
    with pytest.raises(ValueError):
        t.update(np.zeros((2, 8), np.float32), 0.1)
    # bad detections are counted, not fatal
    bad = np.array([[0, np.nan, 0, -1, 4, 1.8, 1.5, 0, 0.9], [5, 1, 0, -1, 4, 1.8, 1.5, 0, 0.9],
                    [0, 1, 0, -1, 0, 1.8, 1.5, 0, 0.9], [0, 1, 0, -1, 4, 1.8, 1.5, np.inf, 0.9]], np.float32)
    t.update(bad, 0.1)
    assert t.stats()["n_bad_dets"] == 4 and t.stats()["n_births"] == 0
    # no detections at all
    t.update(np.zeros((0, 9), np.float32), 0.1)
    assert t.stats()["n_bad_dets"] == 0


def test_reset_and_flags(tn):
    t = tn.Tracker()
    d = np.array([[0, 10, 0, -1, 4, 1.8, 1.5, 0, 0.9]], np.float32)
    assert len(t.update(d, 0.1)) == 0                       # tentative: not without the flag
    assert len(t.update(d, 0.1)) == 1                       # second hit: confirmed
    assert len(t.tracks()) == 1
    t.update(np.zeros((0, 9), np.float32), 0.1)
    # a car that missed one scan is still reported (report_misses 1, 1, 0), as coasting, without a detection
    out = t.tracks()
    assert len(out) == 1 and out["state"][0] == tn.COASTING and out["det"][0] == -1
    t.update(np.zeros((0, 9), np.float32), 0.1)
    assert len(t.tracks()) == 0 and len(t.tracks(tn.OUT_COASTING)) == 1
    assert t.tracks(tn.OUT_COASTING)["det"][0] == -1
    # a pedestrian is not (report_misses 0), nor a car with report_misses 0
    for cls, rep in ((2, None), (0, [0, 1, 0])):
        t = tn.Tracker() if rep is None else tn.Tracker(report_misses=rep)
        dp = d.copy()
        dp[0, 0] = cls
        t.update(dp, 0.1)
        t.update(dp, 0.1)
        t.update(np.zeros((0, 9), np.float32), 0.1)
        assert len(t.tracks()) == 0 and len(t.tracks(tn.OUT_COASTING)) == 1
    with pytest.raises(ValueError):
        tn.Tracker(report_misses=0.5)
    t.reset()
    assert len(t.tracks(3)) == 0
    out = t.update(d, 0.1, flags=tn.OUT_TENTATIVE)
    assert out["id"].tolist() == [1] and out["state"].tolist() == [tn.TENTATIVE]


def test_fixed_delegates_to_the_integer_tracker(tn):
    """Tracker(fixed=True) runs lidet_tools.track.native_q.TrackerQ behind the same interface, or, without it,
    says so clearly."""
    try:
        import lidet_tools.track.native_q  # noqa: F401
    except ImportError:
        with pytest.raises(ImportError, match="integer tracker"):
            tn.Tracker(fixed=True)
        return
    t = tn.Tracker(fixed=True)
    d = np.array([[0, 10, 2, -1, 4, 1.8, 1.5, 0.2, 0.9]], np.float32)
    t.update(d, 0.1)
    out = t.update(d, 0.1, flags=tn.OUT_TENTATIVE)
    assert out.dtype.names == tn.TRACK_DTYPE.names
    assert out["id"].tolist() == [1] and out["state"].tolist() == [tn.CONFIRMED]
    assert abs(float(out["x"][0]) - 10.0) < 0.01 and t.stats()["n_matched"] == 1
    t.reset()
    assert len(t.tracks(3)) == 0


# ---- the assignment ---------------------------------------------------------------------------------------------

def _brute(a: np.ndarray) -> float:
    n = len(a)
    return min(sum(float(a[i, p[i]]) for i in range(n)) for p in itertools.permutations(range(n)))


def _total(a: np.ndarray, p: np.ndarray) -> float:
    return sum(float(a[p[j] - 1, j - 1]) for j in range(1, len(a) + 1))


def test_hungarian_against_brute_force():
    rng = np.random.default_rng(11)
    for trial in range(150):
        n = int(rng.integers(1, 7))
        a = rng.uniform(0, 12, (n, n)).astype(np.float32)
        if trial % 3 == 0:  # gated matrices: many equal "infeasible" entries and ties
            a[rng.random((n, n)) < 0.5] = np.float32(12.21)
            a = np.round(a)
        p = ref.hungarian(a)
        assert sorted(p[1:].tolist()) == list(range(1, n + 1))
        assert _total(a, p) == pytest.approx(_brute(a), abs=1e-4)


def test_hungarian_against_scipy():
    opt = pytest.importorskip("scipy.optimize")
    rng = np.random.default_rng(12)
    for trial in range(40):
        n = int(rng.integers(1, 40))
        a = rng.uniform(0, 12, (n, n)).astype(np.float32)
        if trial % 2:
            a[rng.random((n, n)) < 0.7] = np.float32(12.21)
        r, c = opt.linear_sum_assignment(a.astype(np.float64))
        p = ref.hungarian(a)
        assert _total(a, p) == pytest.approx(float(a[r, c].astype(np.float64).sum()), abs=1e-3)


def test_greedy_worse_than_optimal_by_hand(tn):
    """Two tracks, two detections: the cheapest pair (track 1 - detection 0) leaves track 2 without a feasible
    detection (and detection 1 starts a new track); the optimal assignment gives both tracks one."""
    def run(assign):
        t = tn.Tracker(assign=assign, confirm_hits=1, meas_sigma=1.0, init_vel_sigma=0.0, accel_sigma=0.0,
                       gate_max=10.0)
        t.update(np.array([[0, 0.0, 0, -1, 4, 1.8, 1.5, 0, 0.9], [0, 3.0, 0, -1, 4, 1.8, 1.5, 0, 0.8]],
                          np.float32), 0.1)
        # S = p_pp + r = 2, the gate m <= 9.21 <=> d <= 4.29 m. Detection 0 at 1.4: m 0.98 to track 1, 1.28 to
        # track 2; detection 1 at -2.5: m 3.125 to track 1, infeasible to track 2 (5.5 m). Greedy takes the
        # cheapest pair (track 1, detection 0) and track 2 is left without one; optimal: 3.125 + 1.28.
        out = t.update(np.array([[0, 1.4, 0, -1, 4, 1.8, 1.5, 0, 0.9], [0, -2.5, 0, -1, 4, 1.8, 1.5, 0, 0.8]],
                                np.float32), 0.1, flags=3)
        return t.stats(), out
    s_opt, o_opt = run("optimal")
    s_gr, o_gr = run("greedy")
    assert s_opt["n_matched"] == 2 and s_opt["n_births"] == 0
    assert s_gr["n_matched"] == 1 and s_gr["n_births"] == 1
    assert o_opt["det"].tolist() == [1, 0]  # track 1 took detection 1, track 2 detection 0
