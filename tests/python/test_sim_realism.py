# SPDX-License-Identifier: MIT
"""Quick realism checks against the real scans in ../shared/data/real (skipped when absent);
the full comparison is tools/sim_report.py -> docs/SIMULATOR.md."""
import numpy as np

from lidet_tools.sim.report import binned_median, real_stats, sim_stats


def test_sim_close_to_real_scans(real_dir):
    real = real_stats(str(real_dir))
    sim = sim_stats(3, 1000)
    q = np.mean(sim.n_points) / np.mean(real.n_points)
    assert 0.5 <= q <= 2.0, q
    g = np.mean(sim.ground_frac) / np.mean(real.ground_frac)
    assert 0.5 <= g <= 2.0, g
    # near cars: points per car within 2x of the real median
    ms, _ = binned_median(sim.car)
    mr, _ = binned_median(real.car)
    assert 0.5 <= ms[0] / mr[0] <= 2.0
