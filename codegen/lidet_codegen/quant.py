# SPDX-License-Identifier: MIT
"""int8 quantization of lidet's PointNets (docs/FIXED_POINT.md, section "int8 PointNets").

    python -m lidet_tools.train.calibrate weights/cls_hdl64.onnx --sensor hdl64 --out weights/cls_hdl64.calib.json
    python -m lidet_codegen emit --int8 --calib weights/cls_hdl64.calib.json weights/cls_hdl64.onnx --out weights

This module is the quantization itself (ranges, refit and int8 layers from calibration proposals, the C emission);
the calibration proposals come from scans read through the bindings and simulated scans, in lidet_tools
(lidet_tools.train.calibrate), which writes the calibration file (<name>.calib.json) emit --int8 reads.

Scheme (TFLite / CMSIS-NN conventions):
- weights: per output channel, symmetric int8 in [-127, 127], scale max|w| / 127;
- activations: int8 with one zero point per tensor (-128 after a ReLU: real 0..max onto -128..127, the full 8
  bits for non-negative values; else 0, symmetric) and one scale per channel from that channel's calibration
  range (the classifiers; one per tensor in the box nets, where that measured better). The kernel never sees
  those scales: a layer's output scale of channel c is in its requantization multiplier M_c (per channel
  anyway, as the weight scales are), and the consuming layer folds the input scale of column c into its weight
  column c before its per-channel weight quantization (the same fold as the concatenation below). A per-tensor
  scale (TFLite's rule) spends the 8 bits of every channel on the widest channel's range: the raw argmax
  agreement with float went from 98.7 to 99.2 % (docs/FIXED_POINT.md);
- the first shared layer takes the points as int16 millimetres (model frame) and the first PVLE layer the
  voxel bins as int16 integers: int16 x int8, no input quantization at all;
- accumulators and biases int32; the input zero point is folded into the bias (b - zp_in sum w);
- activation ranges: a percentile of |activation| on the calibration set (`activation_ranges`, `CALIB_RULE`): per
  channel, the 99.9th, in the classifiers; per tensor, the 99.95th, in the box nets;
- the concatenation [g | onehot | p]: g and p keep their own scales, folded into the first head layer's weight
  columns before its per-channel quantization (one int8 input vector for the kernel), and the class one-hot is
  folded into that layer as a per-class int32 bias (exact, no quantization);
- requantization: zp_out + round_half_up(acc * M / 2^s), M in [2^30, 2^31), s in [1, 62]: one rounding
  (CMSIS-NN's single-rounding variant), then the clamp ([zp_out, 127] after a ReLU);
- the last layer of each head writes int32 in Q16 (value * 2^16), same rule without the int8 clamp;
- max over the points is taken on the int32 accumulators of the last shared layer (the requantization is
  monotone), so one requantization per channel and proposal.
"""
from __future__ import annotations

import copy
import hashlib
import json
import math
import pathlib
from dataclasses import dataclass, field

import numpy as np

from . import __version__
from .emit import FORMAT_VERSION, Z_ORIGINS, EmitError, Model, load

PNQ_LAYOUT_VERSION = 3  # LIDET_PNQ_LAYOUT_VERSION (lidet_pointnet_q.h): the layer tables' fields (w_pk, b_list)

PREC_S8 = 1  # LIDET_PN_S8
PTS_SCALE = 0.001  # the first shared layer's input: millimetres
INT32_MAX = (1 << 31) - 1
BIAS_LIMIT = 1 << 29  # |bias| bound lidet_pointnet_q_check enforces


@dataclass
class QLayer:
    n_in: int
    n_out: int
    relu: bool
    w_q: np.ndarray        #: (n_out, n_in) int8 values (int64 array)
    b: np.ndarray          #: (n_out,) int32 values, input zero point folded in
    mult: np.ndarray       #: (n_out,) M in [2^30, 2^31) (or 0)
    shift: np.ndarray      #: (n_out,) s in [1, 62]
    out_zp: int            #: int8 zero point of the output (-128 after a ReLU, else 0)
    out_q16: bool          #: output int32 Q16 (the last head layer)
    s_out: float           #: real value of one output step (1 / 65536 for Q16 outputs)
    in_s16: bool = False   #: int16 input (first shared / PVLE layer)


@dataclass
class QStage:
    point: list
    pvle: list
    head: list
    use_onehot: bool
    onehot_b: np.ndarray | None = None   #: (n_classes, head[0].n_out) int32


@dataclass
class QModel:
    name: str
    kind: str
    stages: list
    n_points: int
    n_classes: int
    n_heading_bins: int
    n_size_clusters: int
    mean_size_mm: list
    heading_bam: list
    heading_res_bam: int
    pvle_bin: tuple            #: azimuth, elevation (urad), range (mm)
    energy_t_q16: int
    gamma_q16: list
    classes: str
    source: Model = field(repr=False, default=None)
    z_origin: int = 0  #: lidet_proposal_z_origin_t, as the float model's

    def widths(self):
        wp, wv = 3, 8
        for s in self.stages:
            wp = max([wp] + [l.n_out for l in s.point])
            wv = max([wv, s.head[0].n_in] + [l.n_out for l in s.pvle] + [l.n_out for l in s.head])
        return wp, wv

    def scratch_bytes(self, block: int = 8) -> int:
        """C: LIDET_POINTNET_Q_SCRATCH_BYTES(wp, wv)."""
        wp, wv = self.widths()
        a4 = lambda v: (v + 3) & ~3  # noqa: E731
        return 4 * block * max(wp, wv) + 4 * wp + a4(2 * block * wp) + a4(3 * wv) + a4(6 * block)

    def flash_bytes(self) -> int:
        n = 0
        for s in self.stages:
            for l in s.point + s.pvle + s.head:
                n += l.w_q.size + 4 * l.b.size + 4 * l.mult.size + l.shift.size
            if s.onehot_b is not None:
                n += 4 * s.onehot_b.size
        return n


def _rha(v: float) -> int:
    return int(math.floor(v + 0.5)) if v >= 0 else -int(math.floor(-v + 0.5))


def multiplier(m: float) -> tuple[int, int]:
    """real multiplier m > 0 -> (M, s): m ~ M / 2^s, M in [2^30, 2^31), s in [1, 62] (M smaller when s caps)."""
    if m <= 0 or not math.isfinite(m):
        return 0, 1
    e = math.floor(math.log2(m))
    M = _rha(m * 2.0 ** (30 - e))
    if M >= 1 << 31:
        M //= 2
        e += 1
    s = 30 - e
    if s < 1:
        raise EmitError(f"requantization multiplier {m} too large (>= 2^29)")
    if s > 62:
        M = _rha(m * 2.0 ** 62)
        s = 62
    return M, s


# ---- float forward with intermediates (calibration and per-layer errors) ------------------------

def _dense_f(x, l):
    y = x @ l.w.T + l.b
    return np.maximum(y, 0.0) if l.relu else y


def float_trace(model: Model, pts_m, voxel, cls):
    """Float64 forward of a batch (points (B, N, 3) metres in the model frame) listing every layer's output
    in the order of ref.pointnet_q.run_stage's trace (the last shared layer: the max over the points)."""
    out = []

    def stage(st, p):
        h = p
        for i, l in enumerate(st.point):
            h = _dense_f(h, l)
            out.append(h.max(axis=1) if i + 1 == len(st.point) else h)
        parts = [out[-1]]
        if st.use_onehot:
            parts.append(np.eye(model.n_classes)[cls])
        if st.pvle:
            v = np.asarray(voxel, np.float64)
            for l in st.pvle:
                v = _dense_f(v, l)
                out.append(v)
            parts.append(v)
        x = np.concatenate(parts, -1)
        for l in st.head:
            x = _dense_f(x, l)
            out.append(x)
        return x

    if model.kind == "classifier" or len(model.stages) == 1:
        stage(model.stages[0], pts_m)
    else:
        t = stage(model.stages[0], pts_m)
        stage(model.stages[1], pts_m - t[:, None, :])
    return out


def layer_names(model) -> list[str]:
    names = []
    tags = ["cls"] if model.kind == "classifier" else (["tnet", "box"] if len(model.stages) == 2 else ["box"])
    for tag, st in zip(tags, model.stages):
        names += [f"{tag}.point{i}" for i in range(len(st.point))]
        names += [f"{tag}.pvle{i}" for i in range(len(st.pvle))]
        names += [f"{tag}.head{i}" for i in range(len(st.head))]
    return names


# ---- quantization ------------------------------------------------------------------------------

def _qlayer(l, s_in, zp_in, s_out, out_q16, in_s16, keep_cols=None):
    """Quantize layer l. s_in: the input scale, a scalar or one per input column (the concatenation: each part
    its own scale, folded into the weight columns before the per-channel quantization, so the kernel sees one
    int8 input vector). Returns (QLayer, per-channel scale of acc)."""
    w = l.w if keep_cols is None else l.w[:, keep_cols]
    w = w * np.broadcast_to(np.asarray(s_in, np.float64), (w.shape[1],))[None, :]
    amax = np.max(np.abs(w), axis=1)
    s_w = np.where(amax > 0, amax / 127.0, 1.0)
    w_q = np.clip(np.rint(w / s_w[:, None]), -127, 127).astype(np.int64)
    b = np.array([_rha(v) for v in l.b / s_w], np.int64) - zp_in * w_q.sum(axis=1)
    scale_out = 1.0 / 65536.0 if out_q16 else s_out
    ms = [multiplier(sw / so) for sw, so in zip(s_w, np.broadcast_to(np.asarray(scale_out, np.float64), s_w.shape))]
    if np.any(np.abs(b) >= BIAS_LIMIT):
        raise EmitError("int32 bias beyond +-2^29 (the C check's bound against accumulator overflow)")
    zp = 0 if out_q16 else (-128 if l.relu else 0)
    return QLayer(w.shape[1], l.n_out, bool(l.relu), w_q, b, np.array([m for m, _ in ms], np.int64),
                  np.array([s for _, s in ms], np.int64), zp, out_q16, scale_out, in_s16), s_w


def _act_scale(rng_max, relu: bool):
    """The int8 step of a tensor from its calibration range: a scalar (one per tensor) or one per channel."""
    r = np.maximum(np.asarray(rng_max, np.float64), 1e-6)
    r = r / 255.0 if relu else r / 127.0
    return float(r) if r.ndim == 0 else r


def with_refit(model: Model, calib: dict) -> Model:
    """The model with the classifier's last layer the calibration file's `head_refit` (see `refit`), else as is."""
    r = calib.get("head_refit")
    if r is None:
        return model
    if model.kind != "classifier":
        raise EmitError("head_refit: classifiers only")
    m = copy.deepcopy(model)
    last = m.stages[0].head[-1]
    w, b = np.asarray(r["w"], np.float64), np.asarray(r["b"], np.float64)
    if w.shape != last.w.shape or b.shape != last.b.shape:
        raise EmitError(f"head_refit {w.shape} does not fit the last layer {last.w.shape}: refit again")
    last.w, last.b = w, b
    return m


def quantize(model: Model, calib: dict) -> QModel:
    """Model (float64 layers) + calibration ranges (+ the classifier's refit last layer) -> QModel. Its `source`
    stays the float model (the reference every error is measured against)."""
    source = model
    model = with_refit(model, calib)
    rng = calib["ranges"]
    names = iter(layer_names(model))
    stages = []
    for st in model.stages:
        point_names = [next(names) for _ in st.point]
        pvle_names = [next(names) for _ in st.pvle]
        head_names = [next(names) for _ in st.head]
        for l in st.point[:-1] + st.pvle[:-1] + st.head[:-1]:
            if not l.relu:
                raise EmitError("int8: a hidden layer without ReLU is not supported (every hidden layer has one)")
        # the concatenation [g | p]: each part its own scale (folded into head[0]'s weight columns)
        s_g = _act_scale(rng[point_names[-1]], True)
        s_p = _act_scale(rng[pvle_names[-1]], True) if st.pvle else None
        qp = []
        s_in, zp_in, in16 = PTS_SCALE, 0, True
        for i, (l, nm) in enumerate(zip(st.point, point_names)):
            s_out = _act_scale(rng[nm], True)
            q, _ = _qlayer(l, s_in, zp_in, s_out, False, in16)
            qp.append(q)
            s_in, zp_in, in16 = s_out, -128, False
        qv = []
        s_in, zp_in, in16 = 1.0, 0, True
        for i, (l, nm) in enumerate(zip(st.pvle, pvle_names)):
            s_out = _act_scale(rng[nm], True)
            q, _ = _qlayer(l, s_in, zp_in, s_out, False, in16)
            qv.append(q)
            s_in, zp_in, in16 = s_out, -128, False
        n_g = st.point[-1].n_out
        keep = list(range(n_g))
        if st.use_onehot:
            keep += list(range(n_g + model.n_classes, st.head[0].n_in))
        else:
            keep = list(range(st.head[0].n_in))
        qh = []
        onehot_b = None
        s_in = np.concatenate([np.broadcast_to(s_g, (n_g,))]
                              + ([np.broadcast_to(s_p, (st.pvle[-1].n_out,))] if st.pvle else []))
        zp_in = -128
        for i, (l, nm) in enumerate(zip(st.head, head_names)):
            last = i + 1 == len(st.head)
            s_out = None if last else _act_scale(rng[nm], True)
            q, s_w = _qlayer(l, s_in, zp_in, s_out, last, False, keep if i == 0 else None)
            if i == 0 and st.use_onehot:
                cols = l.w[:, n_g:n_g + model.n_classes]  # (n_out, n_classes)
                onehot_b = np.array([[_rha(v) for v in cols[:, k] / s_w] for k in range(model.n_classes)], np.int64)
                if np.any(np.abs(onehot_b) >= BIAS_LIMIT):
                    raise EmitError("one-hot bias beyond +-2^29 (the C check's bound against accumulator overflow)")
            qh.append(q)
            s_in, zp_in = (s_out, -128) if not last else (None, None)
        stages.append(QStage(qp, qv, qh, st.use_onehot, onehot_b))
    nh = model.n_heading_bins
    return QModel(
        name=model.name + "_s8", kind=model.kind, stages=stages, n_points=model.n_points, n_classes=model.n_classes,
        n_heading_bins=nh, n_size_clusters=model.n_size_clusters,
        mean_size_mm=[_rha(v * 1000.0) for v in np.asarray(model.mean_sizes).reshape(-1)] if model.kind == "box"
        else [],
        heading_bam=[((_rha(h * 2.0 ** 32 / nh) + (1 << 31)) % (1 << 32)) - (1 << 31) for h in range(nh)],
        heading_res_bam=_rha(2.0 ** 31 / nh) if nh else 0,
        pvle_bin=(_rha(model.pvle_bins[0] * 1e6), _rha(model.pvle_bins[1] * 1e6), _rha(model.pvle_bins[2] * 1e3)),
        energy_t_q16=_rha(model.energy_t * 65536.0), gamma_q16=[_rha(g * 65536.0) for g in model.gamma],
        classes=model.classes, source=source, z_origin=model.z_origin)


# ---- calibration: ranges and refit from proposals ------------------------------------------------
# (the proposals themselves, from scans through the bindings and the simulator: lidet_tools.train.calibrate,
# `python -m lidet_tools.train.calibrate`, which writes the calibration files emit --int8 reads)

ROOT = pathlib.Path(__file__).resolve().parents[2]

#: the range of a tensor (or of each of its channels): a percentile of |activation| over the calibration set (values
#: above it saturate), per model kind: (granularity, percentile). Measured on the 4,240 test proposals of
#: test_pointnet_q.py and 2,654 held-out ones (simulated run seed 4242: 6 HDL-64 + 16 VLP-16 scans, two resampling
#: seeds; docs/journal/fixed-point.md, "Per-channel activation ranges"):
#: - classifiers, raw argmax proposals differing from float (test / held-out): per tensor 99.95 % 49 / 38; per channel
#:   100 % 43 / 38, 99.99 % 54 / 32, 99.95 % 40 / 28, 99.9 % 23 / 30, 99.8 % 45 / 33. An MSE-optimal range per
#:   channel (the percentile among 99 .. 100 % with the least squared quantization error) 42 / 39. Most of what is
#:   left are float near-ties (top-2 margin < 0.2 nats).
#: - box nets, mean BEV IoU with float on the proposals the float gate 1 keeps (HDL-64 test / held-out, VLP-16 test /
#:   held-out): per tensor 99.95 % 0.974 / 0.982 / 0.978 / 0.979; per channel 99.9 % 0.970 / 0.977 / 0.973 / 0.967,
#:   99.95 % 0.967 / 0.976 / 0.970 / 0.963, 99.99 % 0.970 / 0.978 / 0.974 / 0.965: the folded per-channel input
#:   scales make the weight rows of the wider layers quantize coarser, so the box nets keep one range per tensor.
CALIB_RULE = {"classifier": ("channel", 99.9), "box": ("tensor", 99.95)}


def int_proposals(xyz, mean):
    """Float proposals (centred points, mean; metres) -> lidet_proposal_q_t's integers: the member pixels and
    the mean rounded to 4 mm steps, points = pixel - mean (what lidet_proposal_q_make will deliver)."""
    xyz = np.asarray(xyz, np.float64)
    mean = np.asarray(mean, np.float64)
    m4 = np.rint(mean / 0.004).astype(np.int64)
    pix = np.rint((xyz + mean[:, None, :]) / 0.004).astype(np.int64)
    return np.clip(pix - m4[:, None, :], -32768, 32767), m4


def _frame_f(xyz, mean):
    r = np.hypot(mean[:, 0], mean[:, 1])
    ok = r > 1e-6
    c = np.where(ok, mean[:, 0] / np.where(ok, r, 1), 1.0)[:, None]
    s = np.where(ok, mean[:, 1] / np.where(ok, r, 1), 0.0)[:, None]
    x, y = xyz[..., 0], xyz[..., 1]
    return np.stack([c * x + s * y, -s * x + c * y, xyz[..., 2]], -1)


def float_inputs(xyz, mean):
    """The model-frame points (metres, float64) of the integer proposals, as the float nets see them."""
    q, m4 = int_proposals(xyz, mean)
    return _frame_f(q * 0.004, m4 * 0.004)


def calib_classes(model, xyz, mean, vox, folder=None):
    """The class fed to a box net's one-hot during calibration: the float classifier of the same family, the
    cls_<family>.onnx in the box net's own folder (default weights/)."""
    fam = model.name.split("_", 1)[1] if "_" in model.name else model.name
    cp = pathlib.Path(folder or ROOT / "weights") / f"cls_{fam}.onnx"
    if model.kind != "box" or not cp.exists():
        return np.zeros(len(xyz), np.int64)
    cm = load(cp, "cls")
    tr = float_trace(cm, float_inputs(xyz, mean), vox.astype(np.float64), None)
    return tr[-1].argmax(1)


def activation_ranges(model: Model, xyz, mean, vox, folder=None) -> dict:
    """The ranges part of a calibration file: every layer's activation range (CALIB_RULE: per channel or per tensor,
    a percentile of |activation|) over calibration proposals (xyz (B, N, 3) centred points, mean (B, 3) metres,
    vox (B, 3) PVLE bins, as lidet_proposal_t holds them; a box net fed the classes of the classifier in `folder`,
    calib_classes). Returns {"percentile", "ranges_per", "ranges"}."""
    cls = calib_classes(model, xyz, mean, vox, folder)
    tr = float_trace(model, float_inputs(xyz, mean), np.asarray(vox).astype(np.float64), cls)
    names = layer_names(model)
    per, pct = CALIB_RULE[model.kind]
    if per == "channel":
        ranges = {nm: np.percentile(np.abs(t).reshape(-1, t.shape[-1]), pct, axis=0).tolist()
                  for nm, t in zip(names, tr)}
    else:
        ranges = {nm: float(np.percentile(np.abs(t), pct)) for nm, t in zip(names, tr)}
    return {"percentile": pct, "ranges_per": per, "ranges": ranges}


#: the ridge weight toward the float layer of the classifier's last-layer refit (head_refit). Measured on the test
#: proposals of tests/python/test_pointnet_q.py (docs/journal/fixed-point.md, "The classifier's last layer, refitted").
REFIT_MU = 0.1


def refit_check(model: Model, name) -> None:
    """Raises EmitError unless `model` is a classifier whose last layer head_refit can refit."""
    if model.kind != "classifier" or len(model.stages[0].head) < 2:
        raise EmitError(f"{name}: refit needs a classifier with two head layers or more")


def head_refit(model: Model, calib: dict, xyz, mean, vox, mu: float = REFIT_MU) -> dict:
    """The classifier's last layer (linear, Q16 logits) refitted by ridge regression so that, on the int8 network's
    own dequantized inputs, it reproduces the float network's logits: minimises mean |x W^T + b - logits_float|^2
    + mu |(W, b) - (W0, b0)|^2 over the proposals given (xyz, mean, vox as activation_ranges takes them), the int8
    network quantized with the ranges of `calib` (its head_refit ignored). It absorbs the systematic part of the
    error the int8 activations leave in the logits; the layer is then quantized as any other (per-channel int8
    weights). Returns {"mu", "n_proposals", "w", "b"}: a calibration file's head_refit, less where the proposals
    came from (lidet_tools.train.calibrate.refit adds that)."""
    from lidet_ref import pointnet_q as RQ
    refit_check(model, model.name)
    base = {k: v for k, v in calib.items() if k != "head_refit"}
    vox = np.asarray(vox)
    qm = quantize(model, base)
    q4, m4 = int_proposals(xyz, mean)
    c, s = RQ.frame_cs(m4)
    tr = []
    RQ.forward(qm, q4, vox.astype(np.int64), None, c, s, trace=tr)
    prev = qm.stages[0].head[-2]
    x = (tr[-2] - prev.out_zp) * prev.s_out
    y = float_trace(model, float_inputs(xyz, mean), vox.astype(np.float64), None)[-1]
    n, d = x.shape
    xa = np.hstack([x, np.ones((n, 1))])
    last = model.stages[0].head[-1]
    w0 = np.hstack([last.w, last.b[:, None]])
    w = np.linalg.solve(xa.T @ xa + n * mu * np.eye(d + 1), xa.T @ y + n * mu * w0.T).T
    return {"mu": mu, "n_proposals": int(n), "w": w[:, :d].tolist(), "b": w[:, d].tolist()}


def layer_errors(qm: QModel, xyz, mean, vox, folder=None):
    """[(layer, max abs error, mean abs error)] of every layer's dequantized output against float (a box net fed
    the classes of the classifier in `folder`, as calib_classes)."""
    from lidet_ref import pointnet_q as RQ
    model = qm.source
    cls = calib_classes(model, xyz, mean, vox, folder)
    ft = float_trace(model, float_inputs(xyz, mean), vox.astype(np.float64), cls)
    q4, m4 = int_proposals(xyz, mean)
    c, s = RQ.frame_cs(m4)
    qt = []
    RQ.forward(qm, q4, vox.astype(np.int64), cls if model.kind == "box" else None, c, s, trace=qt)
    layers = [l for st in qm.stages for l in st.point + st.pvle + st.head]
    out = []
    for nm, f, q, l in zip(layer_names(model), ft, qt, layers):
        deq = (q - l.out_zp) * l.s_out
        e = np.abs(deq - f)
        out.append((nm, float(e.max()), float(e.mean())))
    return out


# ---- C emission --------------------------------------------------------------------------------

def _ints(cname, ctype, vals, comment, suffix=""):
    vals = [int(v) for v in np.asarray(vals).reshape(-1)]
    lines = [", ".join(f"{v}{suffix}" for v in vals[i:i + 16]) for i in range(0, len(vals), 16)]
    body = ",\n    ".join(lines)
    return (f"/* {comment} */\nLIDET_ALIGN(16) LIDET_RODATA static const {ctype} {cname}[{len(vals)}] = {{\n"
            f"    {body}\n}};\n")


def pack_pk(w_q: np.ndarray) -> np.ndarray:
    """The DSP kernel's packed weights (lidet_pointnet_q_layer_t.w_pk; lidet__nn_pack_s8_pk in
    lib/src/nn/lidet_nn_s8.c writes the same words) from w_q [out][in] int8, n_in a multiple of 4: for each pair of
    channels (c, c + 1) and group of 4 inputs i..i+3 the uint32 words (w[c][i], w[c][i+2]), (w[c+1][i],
    w[c+1][i+2]), (w[c][i+1], w[c][i+3]), (w[c+1][i+1], w[c+1][i+3]), the first value in the low half (int16);
    an odd last channel is left out (the kernel takes it from w_t)."""
    w = np.asarray(w_q, dtype=np.int64)
    n_out, n_in = w.shape
    if n_in % 4:
        raise ValueError(f"pack_pk: n_in {n_in} is not a multiple of 4")
    words = []
    for c in range(0, n_out - 1, 2):
        for g in range(0, n_in, 4):
            for k in range(4):
                o, i = c + (k & 1), g + (k >> 1)
                words.append((int(w[o, i]) & 0xFFFF) | ((int(w[o, i + 2]) & 0xFFFF) << 16))
    return np.array(words, dtype=np.uint64)


def list_bias(l) -> np.ndarray:
    """The list kernel's starting sums of an int8 x int8 layer (lidet_pointnet_q_layer_t.b_list): b - 128 sum_i w,
    per output channel (int64 here; within int32 for any layer lidet_pointnet_q_init accepts)."""
    return np.asarray(l.b, dtype=np.int64) - 128 * np.asarray(l.w_q, dtype=np.int64).sum(axis=1)


def emit_c_s8(qm: QModel, onnx_path, calib_path, cmd: str, src_sha: str, calib_sha: str) -> tuple[str, str]:
    n = qm.name
    up = n.upper()
    banner = (f"/* GENERATED by lidet_codegen {__version__} (weights format {FORMAT_VERSION}, int8) from "
              f"{pathlib.Path(onnx_path).name} sha256={src_sha}\n * calibration {pathlib.Path(calib_path).name} "
              f"sha256={calib_sha}\n * cmd: {cmd}\n * DO NOT EDIT */\n")
    wp, wv = qm.widths()
    h = [banner, f"#ifndef LIDET_MODEL_{up}_H\n#define LIDET_MODEL_{up}_H\n\n#include \"lidet/lidet_pointnet_q.h\"\n\n",
         "#ifdef __cplusplus\nextern \"C\" {\n#endif\n\n",
         f"/** int8 {qm.kind} '{n}': {qm.n_points} points per proposal, {qm.flash_bytes()} bytes of weights */\n",
         f"extern const lidet_pointnet_q_model_t lidet_model_{n};\n\n",
         f"#define {up}_N_POINTS {qm.n_points}u\n",
         f"/** scratch bytes for lidet_pointnet_q_init (equals lidet_pointnet_q_scratch_bytes(&lidet_model_{n})) */\n",
         f"#define {up}_SCRATCH_BYTES LIDET_POINTNET_Q_SCRATCH_BYTES({wp}, {wv})\n\n",
         "#ifdef __cplusplus\n}\n#endif\n\n#endif\n"]
    c = [banner, f"#include \"{n}.h\"\n\n",
         f"#if LIDET_WEIGHTS_FORMAT_VERSION != {FORMAT_VERSION}\n"
         f"#error \"{n}: generated for weights format {FORMAT_VERSION}; regenerate with python -m lidet_codegen emit\"\n"
         f"#endif\n"
         f"#if !defined(LIDET_PNQ_LAYOUT_VERSION) || LIDET_PNQ_LAYOUT_VERSION != {PNQ_LAYOUT_VERSION}\n"
         f"#error \"{n}: generated for the int8 layer layout {PNQ_LAYOUT_VERSION}; regenerate with python -m lidet_codegen "
         f"emit --int8\"\n#endif\n\n"]
    tags = ["cls"] if qm.kind == "classifier" else (["tnet", "box"] if len(qm.stages) == 2 else ["box"])
    stage_c = []
    for tag, st in zip(tags, qm.stages):
        parts_c = {}
        for pn, layers in (("point", st.point), ("pvle", st.pvle), ("head", st.head)):
            if not layers:
                parts_c[pn] = None
                continue
            entries = []
            for i, l in enumerate(layers):
                base = f"{n}_{tag}_{pn}{i}"
                c.append(_ints(base + "_w", "int8_t", l.w_q.T, f"{tag}.{pn}[{i}] weights [{l.n_in}][{l.n_out}] int8 "
                                                                 f"(per-channel scale)"))
                c.append(_ints(base + "_b", "int32_t", l.b, f"{tag}.{pn}[{i}] bias int32 (input zero point folded)"))
                c.append(_ints(base + "_m", "int32_t", l.mult, f"{tag}.{pn}[{i}] requantization multipliers"))
                c.append(_ints(base + "_s", "uint8_t", l.shift, f"{tag}.{pn}[{i}] requantization shifts"))
                pk = "0"
                # every int8 x int8 layer with n_in a multiple of 4 (and two channels or more): the weights again,
                # widened and packed for the DSP kernel (LIDET_PNQ_WEIGHTS_PK; int16 x int8 first layers take w_t)
                if not l.in_s16 and l.n_in % 4 == 0 and l.n_out >= 2:
                    c.append("#if LIDET_PNQ_WEIGHTS_PK\n" + _ints(base + "_wpk", "uint32_t", pack_pk(l.w_q),
                                                                 f"{tag}.{pn}[{i}] weights int16 pairs packed for "
                                                                 f"the DSP kernel, the same as _w", suffix="u")
                             + "#endif\n")
                    pk = f"LIDET_PNQ_PK({base}_wpk)"
                lb = "0"
                # the shared point layers after the first (blocks of points, inputs at the ReLU's zero point
                # -128 skipped): the list kernel's starting sums (LIDET_PNQ_LIST_BIAS; offsets within 16 bits)
                if pn == "point" and not l.in_s16 and l.n_in * l.n_out <= 65536:
                    c.append("#if LIDET_PNQ_LIST_BIAS\n" + _ints(base + "_lb", "int32_t", list_bias(l),
                                                                 f"{tag}.{pn}[{i}] the list kernel's starting sums, "
                                                                 f"b - 128 sum_i w[i]") + "#endif\n")
                    lb = f"LIDET_PNQ_LB({base}_lb)"
                kind = "LIDET_PNQ_OUT_Q16" if l.out_q16 else "LIDET_PNQ_OUT_S8"
                entries.append(f"    {{{l.n_in}u, {l.n_out}u, {1 if l.relu else 0}u, {kind}, {l.out_zp}, "
                               f"{base}_w, {base}_b, {base}_m, {base}_s, {pk}, {lb}}}")
            arr = f"{n}_{tag}_{pn}"
            c.append(f"static const lidet_pointnet_q_layer_t {arr}[{len(layers)}] = {{\n" + ",\n".join(entries)
                     + "\n};\n\n")
            parts_c[pn] = arr
        oh = "0"
        if st.onehot_b is not None:
            c.append(_ints(f"{n}_{tag}_onehot_b", "int32_t", st.onehot_b,
                           f"{tag}: class one-hot folded into head[0], [class][out] int32"))
            oh = f"{n}_{tag}_onehot_b"
        stage_c.append(f"{{{parts_c['point']}, {parts_c['pvle'] or '0'}, {parts_c['head']}, {oh}, "
                       f"{len(st.point)}u, {len(st.pvle)}u, {len(st.head)}u, {1 if st.use_onehot else 0}u}}")
    while len(stage_c) < 2:
        stage_c.append("{0, 0, 0, 0, 0u, 0u, 0u, 0u}")
    ms = hb = "0"
    if qm.kind == "box":
        c.append(_ints(f"{n}_mean_size", "int32_t", qm.mean_size_mm, "size templates [S][3] (l, w, h), mm"))
        c.append(_ints(f"{n}_heading_bam", "int32_t", qm.heading_bam, "heading bin angles, BAM32"))
        ms, hb = f"{n}_mean_size", f"{n}_heading_bam"
    c.append(f"const lidet_pointnet_q_model_t lidet_model_{n} = {{\n"
             f"    {FORMAT_VERSION}u, /* format_version */\n"
             f"    {'LIDET_PN_CLASSIFIER' if qm.kind == 'classifier' else 'LIDET_PN_BOX'}, LIDET_PN_S8,\n"
             f"    {len(qm.stages)}u, {qm.n_classes}u, /* stages, classes */\n"
             f"    {qm.n_points}u, /* points per proposal */\n"
             f"    {qm.n_heading_bins}u, {qm.n_size_clusters}u, /* heading bins, size templates */\n"
             f"    {{{', '.join(stage_c)}}},\n"
             f"    {ms}, {hb}, {qm.heading_res_bam}, /* size templates, heading bins, pi / H in BAM32 */\n"
             f"    {{{', '.join(str(v) for v in qm.pvle_bin)}}}, "
             "/* PVLE bins: azimuth, elevation (urad), range (mm) */\n"
             f"    {qm.energy_t_q16}, /* energy temperature, Q16 */\n"
             f"    {{{', '.join(str(g) for g in qm.gamma_q16)}}}, /* gate thresholds per class, Q16 nats */\n"
             f"    \"{n}\",\n    \"{qm.classes}\",\n"
             f"    {qm.z_origin}u /* proposal z origin: {Z_ORIGINS[qm.z_origin]} */\n}};\n")
    return "".join(h), "".join(c)


def emit_s8(onnx_path, calib_path, out_dir, cmd: str):
    """The int8 model <name>_s8.{c,h} of an ONNX file and its calibration file, in out_dir. Returns the QModel.
    (Each layer's error against float on the calibration proposals: python -m lidet_tools.train.calibrate --report.)"""
    onnx_path, calib_path = pathlib.Path(onnx_path), pathlib.Path(calib_path)
    calib = json.loads(calib_path.read_text())
    name = onnx_path.stem
    src_sha = hashlib.sha256(onnx_path.read_bytes()).hexdigest()
    if calib.get("onnx_sha256") != src_sha:
        raise EmitError(f"{calib_path}: calibrated on another {name}.onnx (sha256 differs): recalibrate")
    qm = quantize(load(onnx_path, name), calib)
    h, c = emit_c_s8(qm, onnx_path, calib_path, cmd, src_sha, hashlib.sha256(calib_path.read_bytes()).hexdigest())
    out_dir = pathlib.Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    (out_dir / f"{qm.name}.h").write_text(h)
    (out_dir / f"{qm.name}.c").write_text(c)
    print(f"{onnx_path} + {calib_path} -> {out_dir / (qm.name + '.c')}: int8 {qm.kind}, "
          f"{qm.flash_bytes()} B of weights, scratch {qm.scratch_bytes()} B")
    return qm
