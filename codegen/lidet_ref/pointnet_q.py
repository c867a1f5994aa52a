# SPDX-License-Identifier: MIT
"""Integer reference of the int8 PointNets, bit for bit as lib/src/pointnet/lidet_pointnet_q.c (docs/FIXED_POINT.md,
section "int8 PointNets"): requant, dense, run_stage, forward, energy, decode_box, classify, box.

Vectorized over a batch of proposals (numpy int64; every value fits as in C). It runs on the quantized
descriptor codegen builds (`lidet_codegen.quant.QModel`), i.e. on exactly the arrays weights/<name>_s8.c holds.
Input: integer proposals as lidet_proposal_q_t holds them: xyz (B, N, 3) in 4 mm steps centred on mean_4mm
(B, 3), voxel (B, 3) bins.
"""
from __future__ import annotations

import numpy as np

from lidet_ref import qmath as Q
from lidet_ref.tables import exp2_neg_q30, log2_q30

EXP2 = np.asarray(exp2_neg_q30(), np.int64)
LOG2 = np.asarray(log2_q30(), np.int64)
LOG2E_Q30 = 1549082005   # round(log2(e) * 2^30)
LN2_Q24 = 11629080       # round(ln(2) * 2^24)
E_CUT_Q16 = 24 << 16     # exp(-d) for d >= 24 nats counts as 0
I32 = (-(1 << 31), (1 << 31) - 1)


def requant(acc, layer):
    """The one rounding rule: zp + round_half_up(acc * M / 2^s), clamped (int8: [lo, 127] with lo the zero
    point after a ReLU, else -128; Q16 output: the int32 range). acc int64 (..., n_out)."""
    acc = np.asarray(acc, np.int64)
    v = (acc * layer.mult + (np.int64(1) << (layer.shift - 1))) >> layer.shift
    if layer.out_q16:
        return np.clip(v, *I32)
    lo = layer.out_zp if layer.relu else -128
    return np.clip(v + layer.out_zp, lo, 127)


def dense_acc(x, layer):
    """int32 accumulators b + x W (x int8 or int16 (..., n_in); exact: float64 sums of |v| < 2^53)."""
    a = np.asarray(x, np.float64) @ layer.w_q.astype(np.float64).T
    return np.rint(a).astype(np.int64) + layer.b


def frame_cs(mean_4mm):
    """(c, s) Q30 of the mean's azimuth: (x, y) / r, r = round(sqrt(x^2 + y^2)); (2^30, 0) on the z axis."""
    m = np.asarray(mean_4mm, np.int64).reshape(-1, 3)
    r = Q.sqrt_round(m[:, 0] * m[:, 0] + m[:, 1] * m[:, 1])
    rs = np.where(r == 0, 1, r)
    c = np.where(r == 0, 1 << 30, Q.div_round(m[:, 0] << 30, rs))
    s = np.where(r == 0, 0, Q.div_round(m[:, 1] << 30, rs))
    return c, s


def sat16(v):
    return np.clip(v, -32768, 32767)


def model_frame(xyz_4mm, c, s, shift_mm=None):
    """Points (B, N, 3) 4 mm steps -> model frame in mm (int16, saturated), minus shift_mm (B, 3)."""
    p = np.asarray(xyz_4mm, np.int64)
    c = np.asarray(c, np.int64)[:, None]
    s = np.asarray(s, np.int64)[:, None]
    x, y = p[..., 0], p[..., 1]
    out = np.stack([Q.rshift_round(c * x + s * y, 28), Q.rshift_round(-s * x + c * y, 28), p[..., 2] * 4], -1)
    if shift_mm is not None:
        out = out - np.asarray(shift_mm, np.int64)[:, None, :]
    return sat16(out)


def run_stage(stage, pts_mm, voxel, cls, trace=None):
    """Shared layers (max over the points on the accumulators, then one requant), PVLE, head (C: run_stage).
    pts_mm (B, N, 3), voxel (B, 3), cls (B,) (one-hot stages). Returns (B, n_out) Q16 int64."""
    h = np.asarray(pts_mm, np.int64)
    g = None
    for i, l in enumerate(stage.point):
        acc = dense_acc(h, l)
        if i + 1 == len(stage.point):
            g = requant(acc.max(axis=1), l)
            if trace is not None:
                trace.append(g)
        else:
            h = requant(acc, l)
            if trace is not None:
                trace.append(h)
    parts = [g]
    if stage.pvle:
        v = np.asarray(voxel, np.int64)
        for l in stage.pvle:
            v = requant(dense_acc(v, l), l)
            if trace is not None:
                trace.append(v)
        parts.append(v)
    x = np.concatenate(parts, axis=-1)
    for i, l in enumerate(stage.head):
        acc = dense_acc(x, l)
        if i == 0 and stage.onehot_b is not None:
            acc = acc + stage.onehot_b[np.asarray(cls, np.int64)]
        x = requant(acc, l)
        if trace is not None:
            trace.append(x)
    return x


def forward(model, pts_mm, voxel, cls=None, c=None, s=None, trace=None):
    """Raw outputs Q16: logits, or [tnet(3) | box] (C: forward). pts_mm: model frame (mm) when c is None, else
    4 mm steps centred on the mean, rotated here by (c, s)."""
    pts_mm = np.asarray(pts_mm, np.int64)
    b = pts_mm.shape[0]
    if c is not None:
        p0 = model_frame(pts_mm, c, s)
    else:
        p0 = pts_mm
    cls = np.zeros(b, np.int64) if cls is None else np.broadcast_to(np.asarray(cls, np.int64), (b,))
    if model.kind == "classifier":
        return run_stage(model.stages[0], p0, voxel, cls, trace)
    if len(model.stages) == 2:
        t = run_stage(model.stages[0], p0, voxel, cls, trace)
        t_mm = Q.rshift_round(t * 1000, 16)
        p1 = model_frame(pts_mm, c, s, t_mm) if c is not None else sat16(pts_mm - t_mm[:, None, :])
        return np.concatenate([t, run_stage(model.stages[1], p1, voxel, cls, trace)], axis=-1)
    return np.concatenate([np.zeros((b, 3), np.int64), run_stage(model.stages[0], p0, voxel, cls, trace)], -1)


def _exp_neg(d):
    """exp(-d) in Q30 for d >= 0 in Q16 nats (0 from 24 nats on): 2^-(d log2 e), table + interpolation."""
    d = np.asarray(d, np.int64)
    u = Q.rshift_round(np.minimum(d, E_CUT_Q16) * LOG2E_Q30, 30)
    k = u >> 16
    f = u & 0xFFFF
    j = f >> 8
    fr = f & 0xFF
    t0 = EXP2[j]
    v = t0 + Q.rshift_round((EXP2[np.minimum(j + 1, 256)] - t0) * fr, 8)
    ks = np.maximum(k, 1)
    out = np.where(k == 0, v, Q.rshift_round(v, ks))
    return np.where(d >= E_CUT_Q16, 0, out)


def _ln_q16(sum_q30):
    """ln(S / 2^30) in Q16 for S >= 2^30 (Q30 sum of exponentials)."""
    s = np.asarray(sum_q30, np.int64)
    e = np.zeros_like(s)
    m = s.copy()
    for _ in range(40):
        big = m >= (1 << 31)
        if not big.any():
            break
        e = e + big
        m = np.where(big, Q.rshift_round(s, np.maximum(e, 1)), m)
    fr = m - (1 << 30)
    j = fr >> 22
    f = fr & ((1 << 22) - 1)
    t0 = LOG2[j]
    l2 = (e << 30) + t0 + Q.rshift_round((LOG2[np.minimum(j + 1, 256)] - t0) * f, 22)
    return Q.rshift_round(l2 * LN2_Q24, 38)


def energy_parts(v_q16, t_q16=65536):
    """(energy Q16, terms Q30, sum Q30) of rows v (B, n): E = -T (max(v / T) + ln sum exp(v / T - max))."""
    v = np.asarray(v_q16, np.int64)
    u = v if t_q16 == 65536 else Q.div_round(v << 16, t_q16)
    m = u.max(axis=-1, keepdims=True)
    terms = _exp_neg(m - u)
    ssum = terms.sum(axis=-1)
    lse = m[..., 0] + _ln_q16(ssum)
    e = -lse if t_q16 == 65536 else -Q.rshift_round(t_q16 * lse, 16)
    return np.clip(e, *I32), terms, ssum


def energy(v_q16, t_q16=65536):
    """-T logsumexp(v / T) in Q16 nats of rows v (Q16) (C: lidet_pointnet_q_energy)."""
    return energy_parts(v_q16, t_q16)[0]


def classify(model, xyz_4mm, mean_4mm, voxel):
    """Logits (Q16), prob (Q15), energy (Q16), class, gate 1 of a batch (C: lidet_pointnet_q_classify)."""
    c, s = frame_cs(mean_4mm)
    lo = forward(model, xyz_4mm, voxel, None, c, s)
    e, terms, ssum = energy_parts(lo, model.energy_t_q16)
    cls = lo.argmax(axis=1)
    prob = (terms * 32768 + ssum[:, None] // 2) // ssum[:, None]
    passed = e < np.asarray(model.gamma_q16, np.int64)[cls]
    return dict(logits=lo, prob=prob, energy=e, cls=cls, passed=passed)


def decode_box(model, raw, mean_4mm, c, s):
    """[tnet | box] Q16 -> box (cx, cy, cz, l, w, h mm; yaw BAM32), energies Q16, bins (C: decode_box)."""
    nh, ns = model.n_heading_bins, model.n_size_clusters
    raw = np.asarray(raw, np.int64)
    mean = np.asarray(mean_4mm, np.int64).reshape(-1, 3)
    bx = raw[:, 3:]
    hs, hr = bx[:, 3:3 + nh], bx[:, 3 + nh:3 + 2 * nh]
    ss, sr = bx[:, 3 + 2 * nh:3 + 2 * nh + ns], bx[:, 3 + 2 * nh + ns:]
    hb, sc = hs.argmax(1), ss.argmax(1)
    lim = 1 << 24
    cen = np.clip(raw[:, 0:3] + bx[:, 0:3], -lim, lim)
    cmm8 = Q.rshift_round(cen * 1000, 8)
    cx = mean[:, 0] * 4 + Q.rshift_round(c * cmm8[:, 0] - s * cmm8[:, 1], 38)
    cy = mean[:, 1] * 4 + Q.rshift_round(s * cmm8[:, 0] + c * cmm8[:, 1], 38)
    cz = mean[:, 2] * 4 + Q.rshift_round(cen[:, 2] * 1000, 16)
    az = Q.atan2(mean[:, 1], mean[:, 0])
    hres = hr[np.arange(len(hb)), hb]
    yaw = np.asarray(model.heading_bam, np.int64)[hb] + Q.rshift_round(hres * model.heading_res_bam, 16) + az
    yaw = ((yaw + (1 << 31)) & 0xFFFFFFFF) - (1 << 31)
    tm = np.asarray(model.mean_size_mm, np.int64).reshape(-1, 3)[sc]
    srs = np.stack([sr[np.arange(len(sc)), 3 * sc + k] for k in range(3)], 1)
    size = np.clip(tm + Q.rshift_round(tm * srs, 16), *I32)
    eh = energy(hs, model.energy_t_q16)
    es = energy(ss, model.energy_t_q16)
    box = np.stack([cx, cy, cz, size[:, 0], size[:, 1], size[:, 2], yaw], 1)
    return dict(box=box, energy_heading=eh, energy_size=es, energy=np.clip(eh + es, *I32), heading_bin=hb,
                size_cluster=sc)


def box(model, xyz_4mm, mean_4mm, voxel, cls):
    """Box, energies, gate 2 of a batch of proposals of classes cls (C: lidet_pointnet_q_box)."""
    c, s = frame_cs(mean_4mm)
    cls = np.broadcast_to(np.asarray(cls, np.int64), (len(c),))
    raw = forward(model, xyz_4mm, voxel, cls, c, s)
    out = decode_box(model, raw, mean_4mm, c, s)
    out["passed"] = out["energy"] < np.asarray(model.gamma_q16, np.int64)[cls]
    return out
