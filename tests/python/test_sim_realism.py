# SPDX-License-Identifier: MIT
"""Quick realism checks against the real scans in ../shared/data/real (skipped when absent);
the full comparison is tools/sim_report.py -> docs/SIMULATOR.md."""
import numpy as np

from lidet_tools.sim.report import binned_median, real_stats, sim_stats


def test_sim_close_to_real_scans(real_dir):
    real = real_stats(str(real_dir))
    sim = sim_stats(4, 1000)
    q = np.mean(sim.n_points) / np.mean(real.n_points)
    assert 0.5 <= q <= 2.0, q
    g = np.mean(sim.ground_frac) / np.mean(real.ground_frac)
    assert 0.5 <= g <= 2.0, g
    # near cars (smoke check on 4 scans; the 2x comparison over 24 scans is docs/SIMULATOR.md)
    ms, _ = binned_median(sim.car)
    mr, _ = binned_median(real.car)
    assert 1 / 3 <= ms[0] / mr[0] <= 3.0
