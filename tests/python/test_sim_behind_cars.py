# SPDX-License-Identifier: MIT
"""lidet-sim --behind-cars (crowd.behind_cars): people standing just behind parked cars, seen from the waist up."""
import numpy as np
import pytest

from lidet_tools.sim import cli as sim_cli
from lidet_tools.sim.simulate import simulate_scan
from lidet_tools.where_lost import points_in_box

STREET = dict(scene_kind="street")


def _behind(p, c) -> bool:
    """Pedestrian box p stands beside car box c on the car's flank away from the sensor (the origin), along it."""
    cs, sn = np.cos(c.yaw), np.sin(c.yaw)
    far = 1.0 if (-sn * c.x + cs * c.y) >= 0.0 else -1.0
    lx = cs * (p.x - c.x) + sn * (p.y - c.y)
    ly = -sn * (p.x - c.x) + cs * (p.y - c.y)
    return abs(lx) < c.l / 2 + 1.5 and c.w / 2 - 0.05 < far * ly < c.w / 2 + 1.6


def _peds(r):
    return [b for b in r.boxes if b.cls == "Pedestrian"]


def test_zero_rate_is_the_default_scene():
    """The option at 0 draws nothing: the same points and boxes as without it."""
    a = simulate_scan("vlp16", 5, 1, **STREET)
    b = simulate_scan("vlp16", 5, 1, behind_cars=0.0, **STREET)
    np.testing.assert_array_equal(a.points, b.points)
    assert [(x.cls, x.x, x.y) for x in a.boxes] == [(x.cls, x.x, x.y) for x in b.boxes]


def test_people_stand_behind_parked_cars_and_are_seen_from_above_their_feet():
    """Over a few street scans, the option adds pedestrians; each added one stands beside a car, farther from the
    sensor than that car's centre, and the added ones are seen, by the median, from well above their feet (the
    default people of the same scans from near their feet)."""
    added, default_low, added_low = 0, [], []
    for i in range(6):
        base = simulate_scan("hdl64", 77, i, **STREET)
        r = simulate_scan("hdl64", 77, i, behind_cars=5.0, keep_scene=True, **STREET)
        old = [(b.x, b.y) for b in _peds(base)]
        peds = _peds(r)
        assert len(peds) >= len(old)
        cars = [b for b in r.boxes if b.cls in ("Car", "Van", "Truck")]
        xyz = r.points[:, :3]
        for p in peds:
            m = points_in_box(xyz, [p.x, p.y, p.z, p.l, p.w, p.h, p.yaw])
            low = float(np.percentile(xyz[m, 2], 5) - (p.z - p.h / 2)) if m.sum() >= 10 else None
            if any(np.hypot(p.x - x, p.y - y) < 0.01 for x, y in old):  # the default scene's own
                if low is not None:
                    default_low.append(low)
                continue
            added += 1
            assert any(_behind(p, c) for c in cars), (p.x, p.y)
            if low is not None:
                added_low.append(low)
    assert added >= 6, added
    assert len(added_low) >= 4 and np.median(added_low) > 0.4, added_low
    assert np.median(default_low) < 0.2, default_low


def test_cli_refuses_a_bad_rate(tmp_path, capsys):
    assert sim_cli.main(["--scenes", "1", "--out", str(tmp_path), "--behind-cars", "-1"]) == 2
    assert "--behind-cars" in capsys.readouterr().err


@pytest.mark.parametrize("rate", ["-0.5", "51"])
def test_dataset_refuses_a_bad_rate(rate, tmp_path):
    from lidet_tools.train import dataset
    with pytest.raises(SystemExit):
        dataset.main(["--sim", "1,0,0", "--sim-behind-cars", rate, "--out", str(tmp_path / "d.npz")])
