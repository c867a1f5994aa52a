# SPDX-License-Identifier: MIT
"""python -m lidet_codegen macs MODEL.onnx ...: multiply-adds per proposal and parameters, counted from
the graph as codegen reads it (the dense layers the C forward pass runs; BN folded)."""
from __future__ import annotations

import argparse
import sys

from .emit import EmitError, load


def count(path) -> dict:
    m = load(path)
    return dict(kind=m.kind, n_points=m.n_points, macs=m.macs(), params=m.params(), scratch_bytes=m.scratch_bytes(),
                layers=[[(l.n_in, l.n_out) for l in s.point + s.pvle + s.head] for s in m.stages])


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m lidet_codegen macs", description=__doc__)
    ap.add_argument("onnx", nargs="+")
    a = ap.parse_args(argv)
    print(f"{'model':40s} {'kind':10s} {'points':>6s} {'MACs':>10s} {'params':>8s} {'scratch B':>9s}")
    try:
        for p in a.onnx:
            c = count(p)
            print(f"{p:40s} {c['kind']:10s} {c['n_points']:6d} {c['macs']:10d} {c['params']:8d} {c['scratch_bytes']:9d}")
    except (EmitError, FileNotFoundError) as e:
        print(f"lidet_codegen macs: error: {e}", file=sys.stderr)
        return 2
    return 0
