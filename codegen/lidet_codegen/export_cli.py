# SPDX-License-Identifier: MIT
"""python -m lidet_codegen export: a checkpoint (or a seeded untrained model) -> ONNX."""
from __future__ import annotations

import argparse
import json
import sys


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m lidet_codegen export",
                                 description="PyTorch checkpoint -> ONNX (opset 17) with lidet's metadata")
    src = ap.add_mutually_exclusive_group(required=True)
    src.add_argument("checkpoint", nargs="?", help="checkpoint .pt written by lidet's training")
    src.add_argument("--untrained", choices=["classifier", "box"],
                     help="a seeded untrained model (to exercise codegen before training)")
    ap.add_argument("--out", required=True, help="output .onnx")
    ap.add_argument("--name", help="model name stored in the metadata (default: the output's stem)")
    ap.add_argument("--seed", type=int, default=0, help="seed of --untrained (default 0)")
    ap.add_argument("--n-points", type=int, default=64, help="points per proposal of --untrained (default 64)")
    ap.add_argument("--cfg", metavar="JSON",
                    help="layer widths of --untrained as the model's constructor arguments, e.g. "
                         "'{\"point\": [8, 16], \"pvle\": [4], \"head\": [8]}' (default: the trained models' widths)")
    a = ap.parse_args(argv)
    cfg = None
    if a.cfg is not None:
        if not a.untrained:
            ap.error("--cfg needs --untrained (a checkpoint carries its own widths)")
        try:
            cfg = json.loads(a.cfg)
        except json.JSONDecodeError as e:
            ap.error(f"--cfg: not JSON: {e}")
        if not isinstance(cfg, dict):
            ap.error("--cfg: a JSON object of constructor arguments")
    from . import export as E
    try:
        if a.untrained:
            model, ck = E.untrained(a.untrained, a.n_points, a.seed, cfg)
        else:
            model, ck = E.load_checkpoint(a.checkpoint)
    except (OSError, ValueError, TypeError) as e:
        print(f"lidet_codegen export: error: {e}", file=sys.stderr)
        return 2
    p = E.export_onnx(model, ck, a.out, a.name)
    print(f"{p}: {ck['kind']}, sha256 {E.sha256(p)}")
    return 0
