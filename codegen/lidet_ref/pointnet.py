# SPDX-License-Identifier: MIT
"""float64 reference of the PointNet forward pass (mirrors lib/src/pointnet/lidet_pointnet.c function for function):
to_model_frame / azimuth_cos_sin, dense, run_stage, forward, energy, decode_box, classify, box.

It runs on the descriptor codegen builds from an ONNX file (`lidet_codegen.emit.load`), i.e. on exactly the
layers (BN folded) that weights/<name>.c holds, so it checks codegen and the C kernels separately from
onnxruntime.
"""
from __future__ import annotations

import math

import numpy as np


def azimuth_cos_sin(mean):
    """cos, sin of the mean's azimuth; (1, 0) on the z axis (C: frame_of)."""
    mean = np.asarray(mean, np.float64)
    r = math.hypot(mean[0], mean[1])
    if r > 1e-6:
        return mean[0] / r, mean[1] / r
    return 1.0, 0.0


def to_model_frame(xyz, cs, shift=None):
    """Rotate centred points by minus the azimuth (cs = cos, sin), then subtract `shift` (C: run_stage)."""
    p = np.asarray(xyz, np.float64)
    c, s = cs
    out = np.empty_like(p)
    out[:, 0] = c * p[:, 0] + s * p[:, 1]
    out[:, 1] = -s * p[:, 0] + c * p[:, 1]
    out[:, 2] = p[:, 2]
    if shift is not None:
        out = out - np.asarray(shift, np.float64)[None, :]
    return out


def dense(x, layer):
    """y = act(x W^T + b) (C: lidet__nn_dense_f32); x (rows, n_in)."""
    y = x @ layer.w.T + layer.b
    return np.maximum(y, 0.0) if layer.relu else y


def run_stage(stage, pts, voxel, onehot, n_classes):
    """Shared layers, max over the points, [g | onehot | pvle], head (C: run_stage)."""
    h = pts
    for l in stage.point:
        h = dense(h, l)
    parts = [h.max(axis=0)]
    if stage.use_onehot:
        parts.append(np.asarray(onehot, np.float64).reshape(n_classes))
    if stage.pvle:
        v = np.asarray(voxel, np.float64).reshape(1, 3)
        for l in stage.pvle:
            v = dense(v, l)
        parts.append(v[0])
    v = np.concatenate(parts)[None, :]
    for l in stage.head:
        v = dense(v, l)
    return v[0]


def forward(model, points, voxel, onehot=None, cs=(1.0, 0.0)):
    """Raw outputs: logits, or [tnet(3) | box] (C: forward). points centred; cs the frame rotation."""
    p = to_model_frame(points, cs)
    if model.kind == "classifier":
        return run_stage(model.stages[0], p, voxel, None, model.n_classes)
    if len(model.stages) == 2:
        t = run_stage(model.stages[0], p, voxel, onehot, model.n_classes)
        b = run_stage(model.stages[1], to_model_frame(points, cs, t), voxel, onehot, model.n_classes)
        return np.concatenate([t, b])
    return np.concatenate([np.zeros(3), run_stage(model.stages[0], p, voxel, onehot, model.n_classes)])


def energy(v, t=1.0):
    """-T logsumexp(v / T), max subtracted first (C: lidet_pn_energy)."""
    u = np.asarray(v, np.float64) / t
    m = u.max()
    return -t * (m + math.log(np.exp(u - m).sum()))


def wrap_pi(a):
    while a > math.pi:
        a -= 2 * math.pi
    while a <= -math.pi:
        a += 2 * math.pi
    return a


def decode_box(model, raw, mean, cs):
    """[tnet | box] -> dict(box=(cx, cy, cz, l, w, h, yaw), energies, bins) (C: decode_box)."""
    nh, ns = model.n_heading_bins, model.n_size_clusters
    bx = raw[3:]
    hs, hr = bx[3:3 + nh], bx[3 + nh:3 + 2 * nh]
    ss, sr = bx[3 + 2 * nh:3 + 2 * nh + ns], bx[3 + 2 * nh + ns:]
    hb, sc = int(np.argmax(hs)), int(np.argmax(ss))
    apb = 2 * math.pi / nh
    cx, cy, cz = raw[0] + bx[0], raw[1] + bx[1], raw[2] + bx[2]
    c, s = cs
    yaw = wrap_pi(hb * apb + hr[hb] * apb / 2 + math.atan2(s, c))
    size = model.mean_sizes[sc] * (1.0 + sr[3 * sc:3 * sc + 3])
    eh, es = energy(hs, model.energy_t), energy(ss, model.energy_t)
    mean = np.asarray(mean, np.float64)
    return dict(box=np.array([mean[0] + c * cx - s * cy, mean[1] + s * cx + c * cy, mean[2] + cz, *size, yaw]),
                energy_heading=eh, energy_size=es, energy=eh + es, heading_bin=hb, size_cluster=sc)


def classify(model, xyz, mean, voxel):
    """Logits, softmax, energy, class, gate 1 of one proposal (C: lidet_pn_classify)."""
    cs = azimuth_cos_sin(mean)
    logits = forward(model, xyz, np.asarray(voxel, np.float64), cs=cs)
    e = energy(logits, model.energy_t)
    cls = int(np.argmax(logits))
    prob = np.exp((logits + e) / model.energy_t)
    return dict(logits=logits, prob=prob, energy=e, cls=cls, passed=e < model.gamma[cls])


def box(model, xyz, mean, voxel, cls):
    """Box, energies, gate 2 of one proposal of class cls (C: lidet_pn_box)."""
    cs = azimuth_cos_sin(mean)
    onehot = np.eye(model.n_classes)[cls]
    raw = forward(model, xyz, np.asarray(voxel, np.float64), onehot, cs)
    out = decode_box(model, raw, mean, cs)
    out["passed"] = out["energy"] < model.gamma[cls]
    return out
