# SPDX-License-Identifier: MIT
"""Multiply-accumulates and parameters of an exported lidet PointNet, counted from the ONNX graph.

    python -m lidet_tools.train.macs weights/cls_hdl64.onnx weights/box_hdl64.onnx [--points 64] [--json]

The graph is shape-inferred with batch 1 and the points count of its metadata (or --points). MACs:
Conv = C_out x C_in / group x kernel x output length; Gemm = M x K x N; MatMul = (output elements) x K.
Element-wise work (batch norm left unfused, ReLU, max-pool, the T-Net subtraction) is not a MAC and
is not counted. Parameters: the elements of all float initialisers (weights and biases after the
exporter folded batch norm into the convolutions; BatchNormalization nodes it left count their
scale, bias, mean and variance).
"""
from __future__ import annotations

import argparse
import json
import sys

import numpy as np


def count(path, n_points: int | None = None) -> dict:
    import onnx
    from onnx import numpy_helper, shape_inference

    m = onnx.load(str(path))
    meta = {p.key: p.value for p in m.metadata_props}
    n = int(n_points or meta.get("lidet.n_points", 64))
    g = m.graph
    inits = {i.name: numpy_helper.to_array(i) for i in g.initializer}
    for inp in g.input:
        if inp.name in inits:
            continue
        dims = inp.type.tensor_type.shape.dim
        dims[0].ClearField("dim_param")
        dims[0].dim_value = 1
        if inp.name == "points":
            dims[1].ClearField("dim_param")
            dims[1].dim_value = n
    for out in g.output:
        d0 = out.type.tensor_type.shape.dim[0]
        d0.ClearField("dim_param")
        d0.dim_value = 1
    m = shape_inference.infer_shapes(m)
    shapes = {}
    for vi in list(m.graph.value_info) + list(m.graph.input) + list(m.graph.output):
        shapes[vi.name] = [d.dim_value for d in vi.type.tensor_type.shape.dim]
    for k, v in inits.items():
        shapes[k] = list(v.shape)
    macs, per_op = 0, {}
    for node in m.graph.node:
        k = 0
        if node.op_type == "Conv":
            w = shapes[node.input[1]]
            out = shapes[node.output[0]]
            k = int(np.prod(w)) * int(np.prod(out[2:]))  # C_out * C_in/g * kernel * L
        elif node.op_type == "Gemm":
            a, b = shapes[node.input[0]], shapes[node.input[1]]
            attrs = {x.name: x.i for x in node.attribute}
            M_ = a[1] if attrs.get("transA", 0) else a[0]
            K = a[0] if attrs.get("transA", 0) else a[1]
            N = b[0] if attrs.get("transB", 0) else b[1]
            k = M_ * K * N
        elif node.op_type == "MatMul":
            a = shapes[node.input[0]]
            out = shapes[node.output[0]]
            k = int(np.prod(out)) * a[-1]
        if k:
            macs += k
            per_op[node.op_type] = per_op.get(node.op_type, 0) + k
    params = int(sum(v.size for v in inits.values() if v.dtype.kind == "f"))
    return dict(path=str(path), kind=meta.get("lidet.kind", ""), n_points=n, macs=int(macs), params=params,
                per_op=per_op, weight_bytes_fp32=4 * params)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m lidet_tools.train.macs", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("onnx", nargs="+")
    ap.add_argument("--points", type=int, default=None, help="points per proposal (default: the model's)")
    ap.add_argument("--json", action="store_true")
    a = ap.parse_args(argv)
    rows = []
    for p in a.onnx:
        try:
            rows.append(count(p, a.points))
        except FileNotFoundError as e:
            print(f"macs: {e}", file=sys.stderr)
            return 2
    if a.json:
        print(json.dumps(rows, indent=1))
    else:
        print("| model | kind | points | MACs | parameters | fp32 weights |")
        print("|---|---|---:|---:|---:|---:|")
        for r in rows:
            print(f"| {r['path']} | {r['kind']} | {r['n_points']} | {r['macs']:,} | {r['params']:,} | "
                  f"{r['weight_bytes_fp32'] / 1024:.1f} KiB |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
