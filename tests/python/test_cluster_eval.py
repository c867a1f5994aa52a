# SPDX-License-Identifier: MIT
"""lidet_tools.cluster_eval: outcomes on crafted labellings, bands, CLI on the real scans."""
import subprocess
import sys

import numpy as np

from lidet_tools import cluster_eval as ce


def _lab(sem, inst):
    return (np.asarray(inst, np.uint32) << 16) | np.asarray(sem, np.uint32)


def test_outcomes():
    n = 100
    pts = np.zeros((6 * n, 3))
    pts[:, 0] = np.repeat([5.0, 15.0, 25.0, 35.0, 45.0, 10.0], n)  # centroid distances
    sem = np.repeat([10, 10, 30, 252, 31, 40], n)
    inst = np.repeat([1, 2, 3, 4, 5, 0], n)
    pred = np.zeros(6 * n, np.int64)
    pred[0:n] = 1                              # car 1: recovered
    pred[n:n + 50] = 2                         # car 2: split in two -> over
    pred[n + 50:2 * n] = 3
    pred[2 * n:3 * n] = 4                      # person merged with the ground -> under
    pred[5 * n:6 * n] = 4
    pred[3 * n:3 * n + 60] = 5                 # moving car: 60 % in one cluster, rest none -> partial
    res = {(r.cls, r.instance): r for r in ce.evaluate_scan(pred, _lab(sem, inst), pts)}
    assert res[("car", 1)].outcome == "recovered" and res[("car", 1)].precision == 1.0
    assert res[("car", 2)].outcome == "over" and res[("car", 2)].n_clusters == 2
    assert res[("person", 3)].outcome == "under" and abs(res[("person", 3)].precision - 0.5) < 1e-9
    assert res[("car", 4)].outcome == "partial" and abs(res[("car", 4)].recall - 0.6) < 1e-9
    assert res[("bicyclist", 5)].outcome == "missed"
    s = ce.summarize(list(res.values()))
    assert s["car"]["0-20"]["n"] == 2 and s["car"]["0-20"]["recovered"] == 0.5
    assert s["car"]["20-40"]["n"] == 1 and s["car"]["0-40"]["n"] == 3
    assert s["bicyclist"]["40+"]["missed"] == 1.0
    assert "| car | 0-20 | 2 | 50% |" in ce.markdown(s)


def test_small_objects_and_unlabelled_instances_skipped():
    pts = np.zeros((15, 3))
    lab = _lab([10] * 5 + [30] * 10, [1] * 5 + [0] * 10)
    assert ce.evaluate_scan(np.zeros(15), lab, pts) == []


def test_cli_on_real_scans(real_dir):
    r = subprocess.run([sys.executable, "-m", "lidet_tools.cluster_eval", str(real_dir / "semantickitti")],
                       capture_output=True, text=True, check=True)
    assert "| car | 0-40 |" in r.stdout
