#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# The tiny models of the network fuzz harnesses (tests/fuzz/models/): seeded untrained PointNets of the same
# structure as the shipped ones (classifier: shared MLP, max-pool, PVLE, head; box net: T-Net, shared MLP, PVLE,
# head with the class one-hot) but 8-16 channels wide, with 16 or 64 points per proposal, so a forward pass costs a
# few thousand multiply-adds instead of 0.7-1.5 M: the harnesses then run the same C code (every layer kind,
# every kernel, float and int8) ~100x more often per second. Float C from the ONNX, int8 C from a calibration
# on the simulated samples only (--real none: the same bytes with or without ../shared).
# Usage: tests/fuzz/make_models.sh [PYTHON]   (regenerates every file of tests/fuzz/models)
set -euo pipefail
cd "$(dirname "$0")/../.."
PY=${1:-${PYTHON:-.venv/bin/python}}
export PYTHONPATH=tools:codegen${PYTHONPATH:+:$PYTHONPATH}
out=tests/fuzz/models
mkdir -p "$out"
for n in 16 64; do
  "$PY" -m lidet_tools.train.export --untrained classifier --seed 11 --n-points $n \
    --cfg '{"point": [8, 16], "pvle": [4], "head": [8]}' --out "$out/fuzz_cls$n.onnx"
  "$PY" -m lidet_tools.train.export --untrained box --seed 12 --n-points $n \
    --cfg '{"tnet_point": [8], "tnet_head": [8], "point": [8, 16], "head": [8], "pvle": [4]}' \
    --out "$out/fuzz_box$n.onnx"
done
for m in fuzz_cls16 fuzz_box16 fuzz_cls64 fuzz_box64; do
  "$PY" -m lidet_codegen emit --out "$out" "$out/$m.onnx"
  "$PY" -m lidet_tools.train.calibrate --sensor vlp16 --real none "$out/$m.onnx"
  "$PY" -m lidet_codegen emit --int8 --out "$out" "$out/$m.onnx"
done
