# SPDX-License-Identifier: MIT
"""Smoke test of the evaluation benchmark (the timing itself is `make bench`'s job)."""
import argparse
import importlib.util


def test_bench_eval_runs_on_a_few_frames(root):
    spec = importlib.util.spec_from_file_location("bench_eval", root / "tools" / "bench" / "bench_eval.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    md = mod.run(argparse.Namespace(eval_frames=60, real=None, build=None))
    assert md.startswith("## Evaluation speed") and "60 synthetic" in md and "| evaluation core" in md
