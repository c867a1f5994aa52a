# SPDX-License-Identifier: MIT
"""The memory-model benchmark (ports/host/bench_memory.c, tools/bench/bench_memory.py): it runs, the workspace is
smaller than the stage objects, both models agree on the scan, and bad arguments are refused (the timing itself
is `make bench`'s job)."""
import argparse
import importlib.util
import subprocess

import pytest


def _mod(root):
    spec = importlib.util.spec_from_file_location("bench_memory", root / "tools" / "bench" / "bench_memory.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


@pytest.mark.parametrize("sensor", ["hdl64", "vlp16"])
def test_both_models_run_and_agree(root, cli, sensor):
    mod = _mod(root)
    scan = root / "tests" / "data" / f"sim_{sensor}" / "velodyne" / "000000.bin"
    (r,) = mod.measure(cli.parents[2], sensor, [scan], 2)
    assert r["same_mask_cluster_compact_ms"] > 0 and r["same_mask_cluster_float_ms"] > 0
    for model in ("stages", "workspace", "workspace_per_point"):
        parts = [r[f"{model}_{p}_ms"] for p in mod.PARTS]
        assert all(t > 0 for t in parts), (model, parts)
        assert r[f"{model}_ms"] >= 0.9 * sum(parts)  # the whole call holds its three stages
    assert r["workspace_bytes"] < 0.5 * r["stages_bytes"]
    # the 4 mm image moves RANSAC draws a little: nearly every point keeps its labels (measured 98.4-99.4 %)
    assert r["ground_agree_pct"] > 97.0 and r["cluster_agree_pct"] > 97.0, r


def test_section_has_a_row_per_sample(root, cli, tmp_path):
    md = _mod(root).run(argparse.Namespace(build=cli.parents[2], real=tmp_path / "absent", quick=True))
    assert md.startswith("## Memory model")
    assert "| simulated hdl64 sample (1) |" in md and "| simulated vlp16 sample (1) |" in md
    assert "real KITTI" not in md  # no real folder: no real rows


def test_bad_arguments_are_refused(cli, tmp_path):
    exe = cli.parent / "lidet_bench_memory"
    r = subprocess.run([str(exe), "--sensor", "nosuch", "x.bin"], capture_output=True, text=True)
    assert r.returncode == 2 and "unknown sensor" in r.stderr
    bad = tmp_path / "odd.bin"
    bad.write_bytes(b"\0" * 18)  # not records of 4 floats
    r = subprocess.run([str(exe), "--sensor", "hdl64", "--repeat", "1", str(bad)], capture_output=True, text=True)
    assert r.returncode == 1 and "cannot read" in r.stderr and r.stdout == ""
