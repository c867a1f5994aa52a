# SPDX-License-Identifier: MIT
"""ONNX -> lidet model descriptor -> weights/<name>.{c,h} (data only; the forward pass is hand-written
in lib/src/pointnet/lidet_pointnet.c).

The graph is read by a small symbolic interpreter: every tensor gets a meaning (the points input, a
per-point feature chain of dense layers, a max-pooled chain, a vector chain with its concatenated
inputs), and the outputs are then matched against the two model kinds of lidet_pointnet.h. Supported
operators: Conv (1x1), Gemm, MatMul (constant weights), Add (constant bias), BatchNormalization (folded
into the layer before it), Relu, ReduceMax (over the points), Concat, Sub (points minus the T-Net centre),
Transpose, Unsqueeze, Identity, Constant. Anything else, or a supported operator used in a way the C
side cannot run, raises `EmitError` naming the node and the operator: never wrong C.
"""
from __future__ import annotations

import hashlib
import pathlib
import sys
from dataclasses import dataclass, field

import numpy as np

from . import __version__

FORMAT_VERSION = 1  # LIDET_WEIGHTS_FORMAT_VERSION
#: ONNX metadata lidet.z_origin values, in lidet_proposal_z_origin_t order (absent: "mean")
Z_ORIGINS = ("mean", "ground")
KIND = {"classifier": 1, "box": 2}


class EmitError(ValueError):
    """The ONNX graph cannot be turned into a lidet model."""


@dataclass
class Layer:
    w: np.ndarray        #: (n_out, n_in) float64
    b: np.ndarray        #: (n_out,)
    relu: bool = False

    @property
    def n_in(self):
        return self.w.shape[1]

    @property
    def n_out(self):
        return self.w.shape[0]


@dataclass
class Stage:
    point: list
    pvle: list
    head: list
    use_onehot: bool


@dataclass
class Model:
    name: str
    kind: str
    stages: list
    n_points: int
    n_classes: int = 3
    n_heading_bins: int = 0
    n_size_clusters: int = 0
    mean_sizes: np.ndarray | None = None
    pvle_bins: tuple = (0.0, 0.0, 0.0)
    energy_t: float = 1.0
    gamma: tuple = (0.0, 0.0, 0.0)
    classes: str = "Car,Cyclist,Pedestrian"
    meta: dict = field(default_factory=dict)
    z_origin: int = 0  #: lidet_proposal_z_origin_t the model was trained with (0 the cluster mean, 1 the ground)

    def widths(self):
        wp, wv = 3, 8
        for s in self.stages:
            wp = max([wp] + [l.n_out for l in s.point])
            concat = s.point[-1].n_out + (self.n_classes if s.use_onehot else 0) + (s.pvle[-1].n_out if s.pvle else 0)
            wv = max([wv, concat] + [l.n_out for l in s.pvle] + [l.n_out for l in s.head])
        return wp, wv

    def scratch_bytes(self, block: int = 8) -> int:
        wp, wv = self.widths()
        return 4 * (2 * block * wp + 3 * wv + 3 * block + 8)

    def n_outputs(self):
        return self.n_classes if self.kind == "classifier" else 3 + 3 + 2 * self.n_heading_bins + 4 * self.n_size_clusters

    def macs(self) -> int:
        n = 0
        for s in self.stages:
            n += self.n_points * sum(l.n_in * l.n_out for l in s.point)
            n += sum(l.n_in * l.n_out for l in s.pvle) + sum(l.n_in * l.n_out for l in s.head)
        return n

    def params(self) -> int:
        return sum(l.w.size + l.b.size for s in self.stages for l in s.point + s.pvle + s.head)


# ---- symbolic values ---------------------------------------------------------------------------

@dataclass
class Inp:
    name: str            #: points | voxel | onehot


@dataclass
class Pts:
    """Per-point features: the points (shifted by `shift` when not None) through `layers`."""
    shift: object        #: None or the Vec subtracted from the points
    layers: list
    layout: str          #: "BNC" or "BCN"
    open_layer: bool = False  #: the last layer may still take a bias / BN / ReLU


@dataclass
class Pooled:
    pts: Pts


@dataclass
class Vec:
    inputs: list         #: concatenated parts: Pooled | Inp | Vec
    layers: list
    open_layer: bool = False


@dataclass
class Cat:
    parts: list


def _attr(node, name, default=None):
    import onnx
    for a in node.attribute:
        if a.name == name:
            return onnx.helper.get_attribute_value(a)
    return default


def _err(node, msg):
    raise EmitError(f"node '{node.name or '(unnamed)'}' ({node.op_type}): {msg}")


def parse(model_proto, name: str | None = None) -> Model:
    """ONNX ModelProto -> Model (float64 layers, BN folded)."""
    import onnx
    from onnx import numpy_helper

    g = model_proto.graph
    meta = {p.key: p.value for p in model_proto.metadata_props}
    kind = meta.get("lidet.kind")
    if kind not in KIND:
        raise EmitError(f"metadata lidet.kind is {kind!r}: expected 'classifier' or 'box' (export with lidet_tools.train.export)")
    if int(meta.get("lidet.format", -1)) != FORMAT_VERSION:
        raise EmitError(f"metadata lidet.format is {meta.get('lidet.format')!r}, this codegen writes {FORMAT_VERSION}")
    consts = {i.name: numpy_helper.to_array(i).astype(np.float64) for i in g.initializer}
    vals: dict = {}
    for i in g.input:
        if i.name in consts:
            continue
        if i.name not in ("points", "voxel", "onehot"):
            raise EmitError(f"graph input {i.name!r}: expected points, voxel (and onehot for a box net)")
        vals[i.name] = Inp(i.name)

    def const(node, idx):
        nm = node.input[idx]
        if nm not in consts:
            _err(node, f"input {idx} ({nm}) must be a constant")
        return consts[nm]

    def dense_on(node, v, w):
        """A new dense layer (w: (n_out, n_in)) applied to value v."""
        if isinstance(v, Pts):
            if v.open_layer:
                _err(node, "two dense layers in a row without an activation are not supported")
            return Pts(v.shift, v.layers + [Layer(w, np.zeros(w.shape[0]))], v.layout, True)
        if isinstance(v, Inp) and v.name == "points":
            return Pts(None, [Layer(w, np.zeros(w.shape[0]))], "BNC", True)
        if isinstance(v, Vec):
            if v.open_layer:
                _err(node, "two dense layers in a row without an activation are not supported")
            return Vec(list(v.inputs), v.layers + [Layer(w, np.zeros(w.shape[0]))], True)
        if isinstance(v, (Pooled, Cat, Inp)):
            parts = v.parts if isinstance(v, Cat) else [v]
            return Vec(parts, [Layer(w, np.zeros(w.shape[0]))], True)
        _err(node, "dense layer on an unsupported value")

    def last_layer(node, v):
        if not isinstance(v, (Pts, Vec)) or not v.layers or not v.open_layer:
            _err(node, "must directly follow a dense layer (Conv 1x1, Gemm or MatMul)")
        return v.layers[-1]

    def copy_v(v):
        if isinstance(v, Pts):
            return Pts(v.shift, [Layer(l.w.copy(), l.b.copy(), l.relu) for l in v.layers], v.layout, v.open_layer)
        return Vec(list(v.inputs), [Layer(l.w.copy(), l.b.copy(), l.relu) for l in v.layers], v.open_layer)

    for node in g.node:
        op = node.op_type
        ins = [vals.get(x) if x in vals else (consts.get(x) if x in consts else None) for x in node.input]
        out = None
        if op == "Constant":
            t = _attr(node, "value")
            if t is None:
                _err(node, "only tensor constants are supported")
            consts[node.output[0]] = numpy_helper.to_array(t).astype(np.float64)
            continue
        if op == "Identity":
            if node.input[0] in consts:
                consts[node.output[0]] = consts[node.input[0]]
                continue
            out = ins[0]
        elif op == "Transpose":
            v = ins[0]
            perm = list(_attr(node, "perm", []))
            if not isinstance(v, (Pts, Inp)) or perm != [0, 2, 1]:
                _err(node, f"only the (0, 2, 1) transpose of per-point data is supported (perm {perm})")
            if isinstance(v, Inp):
                if v.name != "points":
                    _err(node, "transpose of a non-point input")
                out = Pts(None, [], "BCN")
            else:
                out = Pts(v.shift, v.layers, "BNC" if v.layout == "BCN" else "BCN", False)
        elif op == "Conv":
            v = ins[0]
            w = const(node, 1)
            ks = list(_attr(node, "kernel_shape", [1]))
            if w.ndim != 3 or w.shape[2] != 1 or ks != [1] or _attr(node, "group", 1) != 1 or \
                    any(x != 0 for x in _attr(node, "pads", [0, 0])) or any(x != 1 for x in _attr(node, "strides", [1])) \
                    or any(x != 1 for x in _attr(node, "dilations", [1])):
                _err(node, f"only 1x1 Conv1d without padding/stride/dilation/groups is supported (weight {w.shape})")
            if not isinstance(v, Pts) or v.layout != "BCN":
                _err(node, "Conv must run on per-point features laid out (batch, channels, points)")
            out = Pts(v.shift, v.layers + [Layer(w[:, :, 0].copy(), np.zeros(w.shape[0]))], "BCN", True)
            if len(node.input) > 2 and node.input[2]:
                out.layers[-1].b = const(node, 2).copy()
        elif op in ("Gemm", "MatMul"):
            v = ins[0]
            w = const(node, 1)
            if op == "Gemm":
                if _attr(node, "transA", 0) or _attr(node, "alpha", 1.0) != 1.0 or _attr(node, "beta", 1.0) != 1.0:
                    _err(node, "Gemm with transA, alpha or beta != 1 is not supported")
                w = w if _attr(node, "transB", 0) else w.T
            else:
                if w.ndim != 2:
                    _err(node, f"MatMul weight of rank {w.ndim}")
                w = w.T
            if isinstance(v, Pts) and v.layout != "BNC":
                _err(node, "per-point MatMul must run on (batch, points, channels)")
            out = dense_on(node, v, w.copy())
            if op == "Gemm" and len(node.input) > 2 and node.input[2]:
                b = const(node, 2)
                out.layers[-1].b = np.broadcast_to(b, (w.shape[0],)).astype(np.float64).copy()
        elif op == "Add":
            v, c = (ins[0], node.input[1]) if node.input[1] in consts else (ins[1], node.input[0])
            if c not in consts:
                _err(node, "Add of two computed tensors is not supported (only a constant bias)")
            v = copy_v(v) if isinstance(v, (Pts, Vec)) else v
            l = last_layer(node, v)
            if l.relu:
                _err(node, "bias after ReLU")
            b = consts[c].reshape(-1)
            if b.size not in (1, l.n_out):
                _err(node, f"bias of {b.size} values for {l.n_out} channels")
            l.b = l.b + b
            out = v
        elif op == "BatchNormalization":
            v = copy_v(ins[0]) if isinstance(ins[0], (Pts, Vec)) else ins[0]
            l = last_layer(node, v)
            if l.relu:
                _err(node, "BatchNormalization after ReLU cannot be folded into the layer before it")
            sc, bi, mu, var = (const(node, k) for k in (1, 2, 3, 4))
            eps = _attr(node, "epsilon", 1e-5)
            a = sc / np.sqrt(var + eps)
            l.w = l.w * a[:, None]
            l.b = (l.b - mu) * a + bi
            out = v
        elif op == "Relu":
            v = copy_v(ins[0]) if isinstance(ins[0], (Pts, Vec)) else ins[0]
            l = last_layer(node, v)
            l.relu = True
            v.open_layer = False
            out = v
        elif op == "ReduceMax":
            v = ins[0]
            axes = _attr(node, "axes")
            if axes is None and len(node.input) > 1:
                axes = consts[node.input[1]].astype(int).tolist()
            keep = _attr(node, "keepdims", 1)
            pax = 2 if isinstance(v, Pts) and v.layout == "BCN" else 1
            if not isinstance(v, Pts) or not v.layers or list(axes or []) != [pax] or keep != 0:
                _err(node, "only a max over the points axis of per-point features (keepdims 0) is supported")
            out = Pooled(v)
        elif op == "Concat":
            parts = []
            for x in ins:
                if x is None or isinstance(x, np.ndarray):
                    _err(node, "Concat of constants is not supported")
                if isinstance(x, Pts):
                    _err(node, "Concat of per-point features is not supported (PointNet concatenates vectors)")
                parts += x.parts if isinstance(x, Cat) else [x]
            if _attr(node, "axis") not in (1, -1):
                _err(node, "Concat must join feature vectors along axis 1")
            out = Cat(parts)
        elif op == "Unsqueeze":
            v = ins[0]
            if not isinstance(v, Vec):
                _err(node, "only the T-Net centre (a vector) may be unsqueezed")
            out = ("unsq", v)
        elif op == "Sub":
            a, b = ins[0], ins[1]
            if not (isinstance(a, Inp) and a.name == "points" and isinstance(b, tuple) and b[0] == "unsq"):
                _err(node, "only points - T-Net centre is supported")
            out = Pts(b[1], [], "BNC")
        else:
            _err(node, "operator not supported by lidet's forward pass "
                       "(supported: Conv 1x1, Gemm, MatMul, Add, BatchNormalization, Relu, ReduceMax, Concat, "
                       "Sub, Transpose, Unsqueeze, Identity, Constant)")
        vals[node.output[0]] = out
        for extra in node.output[1:]:
            if extra:
                _err(node, "nodes with several outputs are not supported")

    def stage_of(v, what, use_onehot_expected):
        if not isinstance(v, Vec) or not v.layers:
            raise EmitError(f"output {what}: not a dense head over pooled point features")
        if v.layers[-1].relu:
            raise EmitError(f"output {what}: the last layer must not have a ReLU (raw logits)")
        parts = v.inputs
        if not parts or not isinstance(parts[0], Pooled):
            raise EmitError(f"output {what}: the head's input must start with the max-pooled point features")
        pts = parts[0].pts
        rest = parts[1:]
        use_onehot = bool(rest) and isinstance(rest[0], Inp) and rest[0].name == "onehot"
        if use_onehot:
            rest = rest[1:]
        if use_onehot != use_onehot_expected:
            raise EmitError(f"output {what}: the one-hot class input is {'present' if use_onehot else 'missing'}"
                            f" (expected {'[g | onehot | pvle]' if use_onehot_expected else '[g | pvle]'})")
        pvle = []
        if rest:
            p = rest[0]
            if len(rest) != 1 or not isinstance(p, Vec) or len(p.inputs) != 1 or \
                    not (isinstance(p.inputs[0], Inp) and p.inputs[0].name == "voxel"):
                raise EmitError(f"output {what}: after g (and the one-hot) only the PVLE of the voxel may follow")
            pvle = p.layers
        if pts.layers[0].n_in != 3:
            raise EmitError(f"output {what}: the first shared layer takes {pts.layers[0].n_in} inputs, not 3")
        return Stage(list(pts.layers), list(pvle), list(v.layers), use_onehot), pts.shift

    outs = [o.name for o in g.output]
    n_points = int(meta.get("lidet.n_points", 0))
    if n_points <= 0:
        raise EmitError("metadata lidet.n_points missing")
    gamma = tuple(float(x) for x in meta.get("lidet.gamma", "0,0,0").split(","))
    if len(gamma) != 3:
        raise EmitError("metadata lidet.gamma needs 3 values (one per class)")
    common = dict(name=name or meta.get("lidet.name", "model"), kind=kind, n_points=n_points,
                  pvle_bins=tuple(float(x) for x in meta.get("lidet.pvle_bins", "0,0,0").split(",")),
                  energy_t=float(meta.get("lidet.energy_T", 1.0)), gamma=gamma,
                  classes=meta.get("lidet.classes", "Car,Cyclist,Pedestrian"), meta=meta)
    if common["energy_t"] <= 0:
        raise EmitError("metadata lidet.energy_T must be > 0")
    z_origin = meta.get("lidet.z_origin", "mean")
    if z_origin not in Z_ORIGINS:
        raise EmitError(f"metadata lidet.z_origin {z_origin!r}: expected one of {', '.join(Z_ORIGINS)}")
    common["z_origin"] = Z_ORIGINS.index(z_origin)
    if kind == "classifier":
        if outs != ["logits"]:
            raise EmitError(f"classifier outputs {outs}: expected ['logits']")
        st, shift = stage_of(vals.get("logits"), "logits", False)
        if shift is not None:
            raise EmitError("classifier: shifted points are not supported")
        m = Model(stages=[st], **common)
        if st.head[-1].n_out != 3:
            raise EmitError(f"classifier: {st.head[-1].n_out} logits, expected 3")
    else:
        nh = int(meta.get("lidet.n_heading_bins", 0))
        ms = np.array([float(x) for x in meta.get("lidet.mean_sizes", "").split(",") if x], np.float64).reshape(-1, 3)
        if nh < 1 or len(ms) < 1:
            raise EmitError("box net: metadata lidet.n_heading_bins / lidet.mean_sizes missing")
        stages = []
        box_st, shift = stage_of(vals.get("box"), "box", True)
        if outs == ["center_tnet", "box"]:
            t = vals.get("center_tnet")
            if shift is None or shift is not t:
                raise EmitError("box net: the box stage must run on points - center_tnet")
            t_st, t_shift = stage_of(t, "center_tnet", True)
            if t_shift is not None or t_st.head[-1].n_out != 3:
                raise EmitError("box net: the T-Net must run on the raw points and output 3 values")
            stages = [t_st, box_st]
        elif outs == ["box"]:
            if shift is not None:
                raise EmitError("box net without center_tnet output cannot shift the points")
            stages = [box_st]
        else:
            raise EmitError(f"box net outputs {outs}: expected ['center_tnet', 'box'] or ['box']")
        m = Model(stages=stages, n_heading_bins=nh, n_size_clusters=len(ms), mean_sizes=ms, **common)
        want = 3 + 2 * nh + 4 * len(ms)
        if box_st.head[-1].n_out != want:
            raise EmitError(f"box net: {box_st.head[-1].n_out} box outputs, expected {want} (3 + 2H + 4S)")
    for s in m.stages:
        for part in (s.point, s.pvle, s.head):
            if len(part) > 8:
                raise EmitError("more than LIDET_PN_MAX_LAYERS (8) layers in one part")
            for l in part:
                if l.n_out > 1024:
                    raise EmitError(f"layer of {l.n_out} channels above LIDET_PN_MAX_WIDTH (1024)")
                if not (np.all(np.isfinite(l.w)) and np.all(np.isfinite(l.b))):
                    raise EmitError("non-finite weight")
                if np.max(np.abs(l.w), initial=0) > 3.0e38 or np.max(np.abs(l.b), initial=0) > 3.0e38:
                    raise EmitError("weight outside float32 range")
    return m


def load(path, name: str | None = None) -> Model:
    import onnx
    return parse(onnx.load(str(path)), name)


# ---- C emission -----------------------------------------------------------------------------------

def _f32(v) -> str:
    """Round-trip exact float32 literal."""
    f = np.float32(v)
    if not np.isfinite(f):
        raise EmitError(f"non-finite value {v}")
    s = np.format_float_positional(f, unique=True, trim="0") if abs(f) >= 1e-4 or f == 0 else \
        np.format_float_scientific(f, unique=True, trim="0")
    if "." not in s and "e" not in s:
        s += ".0"
    if s.endswith("."):
        s += "0"
    return s + "f"


def _array(cname: str, data: np.ndarray, comment: str) -> str:
    vals = [_f32(x) for x in np.asarray(data, np.float32).reshape(-1)]
    lines = [", ".join(vals[i:i + 8]) for i in range(0, len(vals), 8)]
    body = ",\n    ".join(lines)
    # 64-byte aligned: a cache line, so the host kernel's 64-byte (AVX-512) weight loads never straddle two
    # (measured on the VLP-16 sample: classifier 0.57 -> 0.51 ms, box net 0.25 -> 0.22 ms per scan)
    return (f"/* {comment} */\nLIDET_ALIGN(64) LIDET_RODATA static const float {cname}[{len(vals)}] = {{\n"
            f"    {body}\n}};\n")


def emit_c(m: Model, onnx_path, cmd: str, src_sha: str) -> tuple[str, str]:
    """(header text, source text) for model m."""
    n = m.name
    up = n.upper()
    rel = pathlib.Path(onnx_path).name
    banner = (f"/* GENERATED by lidet_codegen {__version__} (weights format {FORMAT_VERSION}) from {rel} "
              f"sha256={src_sha}\n * cmd: {cmd}\n * DO NOT EDIT */\n")
    wp, wv = m.widths()
    h = [banner, f"#ifndef LIDET_MODEL_{up}_H\n#define LIDET_MODEL_{up}_H\n\n#include \"lidet/lidet_pointnet.h\"\n\n",
         f"#ifdef __cplusplus\nextern \"C\" {{\n#endif\n\n",
         f"/** {m.kind} '{n}': {m.n_points} points per proposal, {m.macs()} multiply-adds, {m.params()} parameters */\n",
         f"extern const lidet_pn_model_t lidet_model_{n};\n\n",
         f"#define {up}_N_POINTS {m.n_points}u\n#define {up}_N_CLASSES {m.n_classes}u\n",
         f"#define {up}_N_OUTPUTS {m.n_outputs()}u\n",
         f"/** scratch bytes for lidet_pn_init (equals lidet_pn_scratch_bytes(&lidet_model_{n})) */\n",
         f"#define {up}_SCRATCH_BYTES LIDET_PN_SCRATCH_BYTES({wp}, {wv})\n\n",
         f"#ifdef __cplusplus\n}}\n#endif\n\n#endif\n"]
    c = [banner, f"#include \"{n}.h\"\n\n",
         f"#if LIDET_WEIGHTS_FORMAT_VERSION != {FORMAT_VERSION}\n"
         f"#error \"{n}: generated for weights format {FORMAT_VERSION}; regenerate with python -m lidet_codegen emit\"\n"
         f"#endif\n\n"]
    stage_names = ["tnet", "box"] if m.kind == "box" and len(m.stages) == 2 else [m.kind if m.kind == "box" else "cls"]
    stage_c = []
    for sn, s in zip(stage_names, m.stages):
        parts_c = {}
        for pn, layers in (("point", s.point), ("pvle", s.pvle), ("head", s.head)):
            if not layers:
                parts_c[pn] = None
                continue
            entries = []
            for i, l in enumerate(layers):
                base = f"{n}_{sn}_{pn}{i}"
                c.append(_array(base + "_w", l.w.T, f"{sn}.{pn}[{i}] weights, shape [{l.n_in}][{l.n_out}] "
                                                   f"(in, out: transposed, BN folded), float32"))
                c.append(_array(base + "_b", l.b, f"{sn}.{pn}[{i}] bias, shape [{l.n_out}], float32"))
                entries.append(f"    {{{l.n_in}u, {l.n_out}u, {1 if l.relu else 0}u, {base}_w, {base}_b}}")
            arr = f"{n}_{sn}_{pn}"
            c.append(f"static const lidet_pn_layer_t {arr}[{len(layers)}] = {{\n" + ",\n".join(entries) + "\n};\n\n")
            parts_c[pn] = arr
        stage_c.append(f"{{{parts_c['point']}, {parts_c['pvle'] or '0'}, {parts_c['head']}, "
                       f"{len(s.point)}u, {len(s.pvle)}u, {len(s.head)}u, {1 if s.use_onehot else 0}u}}")
    while len(stage_c) < 2:
        stage_c.append("{0, 0, 0, 0u, 0u, 0u, 0u}")
    ms = "0"
    if m.kind == "box":
        c.append(_array(f"{n}_mean_size", m.mean_sizes, f"size templates, shape [{m.n_size_clusters}][3] (l, w, h), metres"))
        ms = f"{n}_mean_size"
    c.append(f"const lidet_pn_model_t lidet_model_{n} = {{\n"
             f"    {FORMAT_VERSION}u, /* format_version */\n"
             f"    {'LIDET_PN_CLASSIFIER' if m.kind == 'classifier' else 'LIDET_PN_BOX'}, LIDET_PN_F32,\n"
             f"    {len(m.stages)}u, {m.n_classes}u, /* stages, classes */\n"
             f"    {m.n_points}u, /* points per proposal */\n"
             f"    {m.n_heading_bins}u, {m.n_size_clusters}u, /* heading bins, size templates */\n"
             f"    {{{', '.join(stage_c)}}},\n"
             f"    {ms},\n"
             f"    {{{', '.join(_f32(b) for b in m.pvle_bins)}}}, /* PVLE bins: azimuth, elevation (rad), range (m) */\n"
             f"    {_f32(m.energy_t)}, /* energy temperature */\n"
             f"    {{{', '.join(_f32(g) for g in m.gamma)}}}, /* gate thresholds per class */\n"
             f"    \"{n}\",\n    \"{m.classes}\",\n"
             f"    {m.z_origin}u /* proposal z origin: {Z_ORIGINS[m.z_origin]} */\n}};\n")
    return "".join(h), "".join(c)


def emit(onnx_path, name: str, out_dir, cmd: str | None = None) -> tuple[pathlib.Path, pathlib.Path, Model]:
    onnx_path = pathlib.Path(onnx_path)
    if not name.isidentifier():
        raise EmitError(f"--name {name!r} must be a C identifier")
    m = load(onnx_path, name)
    sha = hashlib.sha256(onnx_path.read_bytes()).hexdigest()
    cmd = cmd or f"python -m lidet_codegen emit {onnx_path.as_posix()} --name {name} --out {pathlib.Path(out_dir).as_posix()}"
    h, c = emit_c(m, onnx_path, cmd, sha)
    out_dir = pathlib.Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    hp, cp = out_dir / f"{name}.h", out_dir / f"{name}.c"
    hp.write_text(h)
    cp.write_text(c)
    return hp, cp, m


def emit_index(names, out_dir, cmd: str, names_s8=()) -> pathlib.Path:
    """weights/lidet_weights.{c,h}: the table of every generated model (data only; lidet_pn_find looks up), and
    of every int8 model (<name>_s8, lidet_pointnet_q_find)."""
    out_dir = pathlib.Path(out_dir)
    names = sorted(names)
    names_s8 = sorted(names_s8)
    banner = f"/* GENERATED by lidet_codegen {__version__}\n * cmd: {cmd}\n * DO NOT EDIT */\n"
    s8_h = ""
    s8_c = ""
    if names_s8:
        s8_h = ("#include \"lidet/lidet_pointnet_q.h\"\n" + "".join(f"#include \"{n}.h\"\n" for n in names_s8)
                + "\n/** every int8 model of weights/, by name (lidet_pointnet_q_find(lidet_weights_models_s8, "
                  "LIDET_WEIGHTS_N_MODELS_S8, name)) */\n"
                  f"#define LIDET_WEIGHTS_N_MODELS_S8 {len(names_s8)}u\n"
                  "extern const lidet_pointnet_q_entry_t lidet_weights_models_s8[LIDET_WEIGHTS_N_MODELS_S8];\n\n")
        s8_c = ("\nconst lidet_pointnet_q_entry_t lidet_weights_models_s8[LIDET_WEIGHTS_N_MODELS_S8] = {\n"
                + ",\n".join(f"    {{\"{n}\", &lidet_model_{n}}}" for n in names_s8) + "\n};\n")
    h = (banner + "#ifndef LIDET_WEIGHTS_H\n#define LIDET_WEIGHTS_H\n\n#include \"lidet/lidet_pointnet.h\"\n\n"
         "#ifdef __cplusplus\nextern \"C\" {\n#endif\n\n"
         + "".join(f"#include \"{n}.h\"\n" for n in names)
         + f"\n/** every model of weights/, by name (lidet_pn_find(lidet_weights_models, LIDET_WEIGHTS_N_MODELS, name)) */\n"
           f"#define LIDET_WEIGHTS_N_MODELS {len(names)}u\n"
           "extern const lidet_pn_entry_t lidet_weights_models[LIDET_WEIGHTS_N_MODELS];\n\n"
         + s8_h +
           "#ifdef __cplusplus\n}\n#endif\n\n#endif\n")
    c = (banner + "#include \"lidet_weights.h\"\n\nconst lidet_pn_entry_t lidet_weights_models[LIDET_WEIGHTS_N_MODELS] = {\n"
         + ",\n".join(f"    {{\"{n}\", &lidet_model_{n}}}" for n in names) + "\n};\n" + s8_c)
    (out_dir / "lidet_weights.h").write_text(h)
    (out_dir / "lidet_weights.c").write_text(c)
    return out_dir / "lidet_weights.c"


def main(argv=None) -> int:
    import argparse
    ap = argparse.ArgumentParser(prog="python -m lidet_codegen emit",
                                 description="ONNX model -> weights/<name>.{c,h} (const arrays + a lidet_pn_model_t)")
    ap.add_argument("onnx", nargs="+", help="model(s) exported by lidet's training (lidet_tools.train.export)")
    ap.add_argument("--name", help="C name of the model (default: the file's stem); one model only")
    ap.add_argument("--out", default="weights", help="output folder (default weights/)")
    ap.add_argument("--index", action="store_true",
                    help="also write lidet_weights.{c,h}: the table of every *.onnx model in --out (and of the int8 "
                         "<name>_s8 model of every <name>.calib.json there)")
    ap.add_argument("--int8", action="store_true",
                    help="write the int8 model weights/<name>_s8.{c,h} instead (needs a calibration file)")
    ap.add_argument("--calib", help="--int8: calibration file (python -m lidet_tools.train.calibrate); default "
                                    "<name>.calib.json beside the model")
    a = ap.parse_args(argv)
    if a.name and len(a.onnx) > 1:
        ap.error("--name needs exactly one model")
    if a.calib and len(a.onnx) > 1:
        ap.error("--calib needs exactly one model")
    try:
        if a.int8:
            from . import quant
            for p in a.onnx:
                cal = a.calib or pathlib.Path(p).with_suffix(".calib.json").as_posix()
                cmd = (f"python -m lidet_codegen emit --int8 --calib {cal} {pathlib.Path(p).as_posix()} "
                       f"--out {pathlib.Path(a.out).as_posix()}")
                quant.emit_s8(p, cal, a.out, cmd)
            return 0
        for p in a.onnx:
            name = a.name or pathlib.Path(p).stem
            hp, cp, m = emit(p, name, a.out)
            print(f"{p} -> {cp}, {hp}: {m.kind}, {m.macs()} MACs at {m.n_points} points, {m.params()} parameters, "
                  f"scratch {m.scratch_bytes()} B")
        if a.index:
            names = sorted(pathlib.Path(x).stem for x in pathlib.Path(a.out).glob("*.onnx"))
            od = pathlib.Path(a.out).as_posix()
            names_s8 = sorted(pathlib.Path(x).name[:-len(".calib.json")] + "_s8"
                              for x in pathlib.Path(a.out).glob("*.calib.json"))
            emit_index(names, a.out, "python -m lidet_codegen emit " + " ".join(f"{od}/{n}.onnx" for n in names)
                       + f" --out {od} --index", names_s8)
    except (EmitError, FileNotFoundError) as e:
        print(f"lidet_codegen emit: error: {e}", file=sys.stderr)
        return 2
    return 0
