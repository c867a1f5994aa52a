# SPDX-License-Identifier: MIT
"""The vectorized devkit engine against a literal per-object restatement of the devkit (_devkit_ref)."""
import numpy as np
import pytest

import _devkit_ref as ref
from lidet_tools.eval import engine


def _random_frames(rng, n_frames, conflict):
    frames = []
    for _ in range(n_frames):
        ng, nd = rng.integers(0, 6), rng.integers(0, 8)
        ov = rng.uniform(0, 1, (nd, ng)) * (rng.uniform(size=(nd, ng)) < (0.6 if conflict else 0.15))
        if not conflict and ng:  # at most one candidate ground truth per detection
            keep = rng.integers(0, ng, nd)
            ov = np.where(np.arange(ng)[None, :] == keep[:, None], ov, 0.0)
        frames.append(dict(
            ov=ov, ign_gt=rng.choice([-1, 0, 0, 0, 1], ng), ign_dt=rng.choice([-1, 0, 0, 0, 1], nd),
            scores=np.round(rng.uniform(0, 1, nd), 1 if rng.uniform() < 0.5 else 6),
            dc_hit=rng.uniform(size=nd) < 0.15))
    return frames


def _flatten(frames):
    gf, ig, df, idt, sc, dc, pd, pg, po = [], [], [], [], [], [], [], [], []
    g0 = d0 = 0
    for f, fr in enumerate(frames):
        nd, ng = fr["ov"].shape
        gf += [f] * ng
        df += [f] * nd
        ig += list(fr["ign_gt"])
        idt += list(fr["ign_dt"])
        sc += list(fr["scores"])
        dc += list(fr["dc_hit"])
        for j in range(nd):
            for i in range(ng):
                pd.append(d0 + j)
                pg.append(g0 + i)
                po.append(fr["ov"][j, i])
        g0 += ng
        d0 += nd
    return (len(frames), np.array(gf, int), np.array(ig, int), np.array(df, int), np.array(idt, int),
            np.array(sc, float), np.array(pd, int), np.array(pg, int), np.array(po, float),
            np.array(dc, bool))


@pytest.mark.parametrize("seed,conflict", [(s, c) for s in range(6) for c in (False, True)])
def test_engine_matches_literal_devkit(seed, conflict):
    rng = np.random.default_rng(seed)
    frames = _random_frames(rng, 60, conflict)
    for min_ov in (0.25, 0.5, 0.7):
        r11, r40, prec = ref.eval_class(frames, min_ov)
        n, gf, ig, df, idt, sc, pd, pg, po, dc = _flatten(frames)
        st = engine.pr_statistics(n, gf, ig, df, idt, sc, pd, pg, po, min_ov, dc)
        np.testing.assert_allclose(st["precision"], prec, atol=1e-12)
        assert st["ap_r11"] == pytest.approx(r11, abs=1e-9)
        assert st["ap_r40"] == pytest.approx(r40, abs=1e-9)


def test_get_thresholds_matches_literal():
    rng = np.random.default_rng(3)
    for n_gt in (1, 7, 40, 41, 97, 500):
        for n_tp in {0, 1, n_gt // 2, n_gt}:
            v = rng.uniform(size=n_tp)
            assert list(engine.get_thresholds(v, n_gt)) == ref.get_thresholds(list(v), n_gt)[:41]


def test_empty_inputs():
    st = engine.pr_statistics(3, [], [], [], [], [], [], [], [], 0.5)
    assert st["n_gt"] == 0 and st["ap_r40"] == 0.0


def test_exact_ap_on_a_small_set():
    """15 objects, 13 found with precision 1 and 2 false positives scoring lowest: the exact AP|R40 is the
    share of the 40 recall samples at or below recall 13/15 (34 of them); the devkit's sampling reads one
    precision per true positive as recall i/40 and stays far below."""
    from lidet_tools.eval import engine
    n = 15
    score = np.r_[np.linspace(0.99, 0.5, 13), 0.3, 0.2]
    pair_dt = np.arange(13)
    pair_gt = np.arange(13)
    pair_ov = np.full(13, 0.9)
    args = (1, np.zeros(n, np.int64), np.zeros(n, np.int8), np.zeros(15, np.int64), np.zeros(15, np.int8),
            score, pair_dt, pair_gt, pair_ov, 0.5)
    ex = engine.pr_statistics(*args, exact=True)
    assert ex["ap_r40"] == pytest.approx(34 / 40 * 100)
    assert ex["ap_r11"] == pytest.approx(9 / 11 * 100)  # recall 0, 0.1, ..., 0.8
    dk = engine.pr_statistics(*args)
    assert dk["ap_r40"] == pytest.approx(12 / 40 * 100)  # samples 1..12 of the 13 thresholds, precision 1
    # no detection: 0 both ways
    none = engine.pr_statistics(1, np.zeros(n, np.int64), np.zeros(n, np.int8), np.zeros(0, np.int64),
                                np.zeros(0, np.int8), np.zeros(0), np.zeros(0, np.int64), np.zeros(0, np.int64),
                                np.zeros(0), 0.5, exact=True)
    assert none["ap_r40"] == 0.0
