# SPDX-License-Identifier: MIT
"""PyTorch checkpoint -> ONNX (opset 17) with lidet's metadata: the contract of
tools/lidet_tools/train/models.py (input/output names, shapes, metadata keys), which lidet_codegen reads.

    python -m lidet_tools.train.export CHECKPOINT.pt --out weights/<name>.onnx [--name NAME]
    python -m lidet_tools.train.export --untrained classifier|box --out X.onnx [--seed S] [--n-points N] [--cfg JSON]

Checkpoint format (torch.save of a dict): {"kind": "classifier"|"box", "cfg": model.cfg,
"state_dict": ..., "meta": {"n_points": 64, "gamma": [3 floats], "energy_T": 1.0, "trained": 1, ...}}.
`untrained()` builds one from a seeded initialisation (batch-norm statistics set from random
proposal-like inputs, so folding is exercised): models for codegen's tests without training.
"""
from __future__ import annotations

import argparse
import hashlib
import io
import json
import pathlib
import sys
import warnings

import numpy as np


def _torch():
    import torch  # noqa: PLC0415 (optional dependency: only export and training need it)
    return torch


def build_model(kind: str, cfg: dict):
    from . import models as M
    if kind == "classifier":
        return M.ClassifierNet(**cfg)
    if kind == "box":
        return M.BoxNet(**cfg)
    raise ValueError(f"unknown model kind {kind!r} (classifier or box)")


def load_checkpoint(path):
    torch = _torch()
    ck = torch.load(str(path), map_location="cpu", weights_only=False)
    for k in ("kind", "cfg", "state_dict", "meta"):
        if k not in ck:
            raise ValueError(f"{path}: not a lidet checkpoint (missing {k!r})")
    m = build_model(ck["kind"], ck["cfg"])
    m.load_state_dict(ck["state_dict"])
    return m.eval(), ck


def untrained(kind: str, n_points: int = 64, seed: int = 0, cfg: dict | None = None):
    """A seeded, untrained model with non-trivial batch-norm statistics, as a checkpoint dict."""
    torch = _torch()
    torch.manual_seed(seed)
    m = build_model(kind, cfg or {})
    g = torch.Generator().manual_seed(seed + 1)
    m.train()
    with torch.no_grad():
        for _ in range(4):
            pts = torch.randn(64, n_points, 3, generator=g) * torch.tensor([1.5, 0.7, 0.6])
            vox = torch.stack([torch.randint(-18, 18, (64,), generator=g), torch.randint(-3, 2, (64,), generator=g),
                               torch.randint(2, 60, (64,), generator=g)], 1).float()
            if kind == "box":
                oh = torch.nn.functional.one_hot(torch.randint(0, 3, (64,), generator=g), 3).float()
                m(pts, vox, oh)
            else:
                m(pts, vox)
    m.eval()
    meta = dict(n_points=n_points, gamma=[0.0, 0.0, 0.0], energy_T=1.0, trained=0)
    return m, dict(kind=kind, cfg=m.cfg, state_dict=m.state_dict(), meta=meta)


def export_onnx(model, ck: dict, out_path, name: str | None = None) -> pathlib.Path:
    """Export `model` (eval mode) with the contract's names and metadata. Returns the path."""
    torch = _torch()
    import onnx

    from . import models as M

    kind = ck["kind"]
    meta = ck["meta"]
    n = int(meta["n_points"])
    model = model.eval()
    pts = torch.zeros(2, n, 3)
    vox = torch.zeros(2, 3)
    if kind == "classifier":
        args, in_names, out_names = (pts, vox), ["points", "voxel"], ["logits"]
        wrapped = model
    else:
        oh = torch.zeros(2, 3)
        args, in_names = (pts, vox, oh), ["points", "voxel", "onehot"]
        if model.cfg["use_tnet"]:
            out_names = ["center_tnet", "box"]
            wrapped = model
        else:
            out_names = ["box"]

            class _NoTnet(torch.nn.Module):
                def __init__(self, inner):
                    super().__init__()
                    self.inner = inner

                def forward(self, p, v, o):
                    return self.inner(p, v, o)[1]

            wrapped = _NoTnet(model).eval()
    buf = io.BytesIO()
    dyn = {k: {0: "batch"} for k in in_names + out_names}
    # The TorchScript exporter (dynamo=False) writes the plain Conv / Gemm / BatchNormalization / Relu graph
    # codegen reads; the torch.export-based one needs onnxscript and was not checked against codegen. Its
    # deprecation warning is expected.
    warnings.filterwarnings("ignore", category=DeprecationWarning, module=r"torch\.onnx.*")
    warnings.filterwarnings("ignore", message=".*legacy TorchScript-based ONNX export.*")
    torch.onnx.export(wrapped, args, buf, dynamo=False, opset_version=17, input_names=in_names,
                      output_names=out_names, dynamic_axes=dyn, do_constant_folding=True)
    om = onnx.load_from_string(buf.getvalue())
    props = {
        "lidet.kind": kind,
        "lidet.format": str(M.FORMAT_VERSION),
        "lidet.n_points": str(n),
        "lidet.classes": ",".join(M.CLASSES),
        "lidet.frame": "azimuth",
        "lidet.z_origin": str(meta.get("z_origin", "mean")),
        "lidet.pvle_bins": ",".join(repr(float(b)) for b in meta.get("pvle_bins", M.PVLE_BINS)),
        "lidet.energy_T": repr(float(meta.get("energy_T", 1.0))),
        "lidet.gamma": ",".join(repr(float(g)) for g in meta["gamma"]),
        "lidet.trained": str(int(meta.get("trained", 1))),
        "lidet.name": name or pathlib.Path(out_path).stem,
    }
    if kind == "box":
        props["lidet.n_heading_bins"] = str(M.N_HEADING_BINS)
        props["lidet.mean_sizes"] = ",".join(repr(float(v)) for v in M.MEAN_SIZES.reshape(-1))
    for k in ("sensor", "data", "command"):
        if k in meta:
            props["lidet." + k] = str(meta[k])
    del om.metadata_props[:]
    for k in sorted(props):
        e = om.metadata_props.add()
        e.key, e.value = k, props[k]
    # the producer the committed ONNX files name: an export of the same checkpoint gives the same bytes (the C models
    # carry their sha256)
    om.producer_name, om.producer_version = "lidet_codegen", ""
    out_path = pathlib.Path(out_path)
    out_path.parent.mkdir(parents=True, exist_ok=True)
    out_path.write_bytes(om.SerializeToString())
    return out_path


def sha256(path) -> str:
    return hashlib.sha256(pathlib.Path(path).read_bytes()).hexdigest()


def torch_forward(model, kind, points: np.ndarray, voxel: np.ndarray, onehot: np.ndarray | None = None):
    """The PyTorch outputs as numpy (for the export parity test)."""
    torch = _torch()
    with torch.no_grad():
        p = torch.from_numpy(np.ascontiguousarray(points, np.float32))
        v = torch.from_numpy(np.ascontiguousarray(voxel, np.float32))
        if kind == "classifier":
            return {"logits": model(p, v).numpy()}
        o = torch.from_numpy(np.ascontiguousarray(onehot, np.float32))
        dc, box = model(p, v, o)
        return {"center_tnet": dc.numpy(), "box": box.numpy()}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m lidet_tools.train.export",
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
    try:
        if a.untrained:
            model, ck = untrained(a.untrained, a.n_points, a.seed, cfg)
        else:
            model, ck = load_checkpoint(a.checkpoint)
    except (OSError, ValueError, TypeError) as e:
        print(f"lidet_tools.train.export: error: {e}", file=sys.stderr)
        return 2
    p = export_onnx(model, ck, a.out, a.name)
    print(f"{p}: {ck['kind']}, sha256 {sha256(p)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
