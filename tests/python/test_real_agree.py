# SPDX-License-Identifier: MIT
"""`lidet_tools.real.agree`: the float and integer detectors' candidates compared proposal by proposal, on simulated
scans (always runs with the bindings)."""
from __future__ import annotations

import pytest

from lidet_tools.real import agree


@pytest.fixture(scope="module")
def pairs(nd):
    from lidet_tools.sim import simulate_scan
    out = []
    for i in range(3):
        out += agree.frame_pairs(simulate_scan("hdl64", 1000, i).points, "hdl64")
    return out


def test_the_two_detectors_draw_the_same_points(pairs):
    """Large clusters of one simulated scan: the float detector's and the integer one's proposals hold the same
    points where their clusters have the same members (pixel keys), the energies agree to about the int8 rounding,
    and clusters of other member counts still share most points."""
    assert len(pairs) >= 20
    assert all(p["members_float"] >= 65 for p in pairs)
    s = agree.summary(pairs)
    assert s["all"]["pairs"] == len(pairs) == s["same member count"]["pairs"] + s["other member count"]["pairs"]
    same = s["same member count"]
    assert same["pairs"] >= 10 and same["shared"] > 0.97
    assert same["energy_diff_mean"] < 0.2
    if s["other member count"]["pairs"]:
        assert s["other member count"]["shared"] > 0.6
    md = agree.markdown(s, "test")
    assert "| same member count |" in md and "points shared" in md


def test_summary_of_hand_made_pairs():
    p = [dict(members_float=100, members_int=100, shared=1.0, energy_float=-7.0, energy_int=-7.1),
         dict(members_float=100, members_int=101, shared=0.5, energy_float=-7.0, energy_int=-6.0)]
    s = agree.summary(p)
    assert s["all"]["pairs"] == 2 and s["all"]["over_0_3_nats"] == 1
    assert s["same member count"]["shared"] == 1.0
    assert s["other member count"]["energy_diff_mean"] == pytest.approx(1.0)
    assert agree.summary([])["all"] == {"pairs": 0}


def test_missing_root(tmp_path, capsys):
    assert agree.main(["--root", str(tmp_path / "nope")]) == 2
    assert "not found" in capsys.readouterr().err
