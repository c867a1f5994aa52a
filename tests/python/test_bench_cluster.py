# SPDX-License-Identifier: MIT
"""Smoke test of the clustering benchmark on the real scans (the timing itself is `make bench`'s job):
the simulated sets and the DBSCAN peer are switched off here to keep `make test` short."""
import argparse
import importlib.util
import os
import pathlib

import pytest


def test_bench_cluster_runs(root, real_dir):
    build = pathlib.Path(os.environ.get("LIDET_BUILD_DIR", root / "build"))
    if not (build / "ports" / "host" / "lidet").exists():
        pytest.skip("CLI not built")
    spec = importlib.util.spec_from_file_location("bench_cluster", root / "tools" / "bench" / "bench_cluster.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    mod._sim_dir = lambda sensor, quick, crowd=False, seed=None: None
    mod._open3d = lambda: None
    md = mod.run(argparse.Namespace(real=real_dir, build=build, quick=True))
    assert md.startswith("## Clustering (issue 6)")
    assert "| real SemanticKITTI 00 (3 labelled scans) | lidet |" in md and "DBSCAN columns skipped" in md
    assert "| | lidet, no rescue |" in md and "| | lidet, no refinement |" in md
    assert "### Proposal recall (issue 15)" in md
    # the KITTI object frames, scored from their label_2 boxes (the pedestrian of 000000 within 40 m)
    n_kitti = len(list((real_dir / "kitti" / "training" / "velodyne").glob("*.bin")))
    row = [ln for ln in md.splitlines() if ln.startswith(f"| real KITTI object frames ({n_kitti} frames, label_2 boxes")]
    assert len(row) == 2 and "| lidet |" in row[0]  # the clustering table and the proposal-recall table
    # its person cell: recall (n objects: at least the pedestrian of 000000) / merged / split / missed
    import re
    m = re.search(r"\((\d+)\) /", row[1].split("|")[4])
    assert m and int(m.group(1)) >= 1
    assert "| | lidet integer (lidet_cluster_q), same images |" in md
