# SPDX-License-Identifier: MIT
"""The two PointNets of lidet (PyTorch), sized for a microcontroller, and the contract their ONNX
export keeps with the C side (codegen/lidet_codegen/emit.py, lib/src/pointnet/lidet_pointnet.c).

Both nets see a proposal in the *model frame*: the cluster's resampled points centred on the cluster
mean and rotated about +z by minus the mean's azimuth, so the sensor looks along +x at every object
(the frustum rotation of Frustum PointNets; the authors trained with it). The class of an object's
point pattern depends on the side the sensor sees, not on where around the sensor it stands, so one
canonical view lets a 360-degree scan reuse every training example at every azimuth. PVLE still gets
the mean's voxel (azimuth, elevation, range bins), so location stays known to the nets.

Classifier (per proposal, N points):
    points (N, 3) -> shared MLP 3 -> 32 -> 64 -> 128 (conv1x1 + BN + ReLU) -> max over points -> g (128)
    voxel (3)     -> PVLE 3 -> 32 -> 32 (linear + BN + ReLU)                                  -> p (32)
    [g | p] (160) -> FC 64 (BN + ReLU) -> FC 3 -> logits (Car, Cyclist, Pedestrian: lidet_class_t order)
Box net:
    T-Net:  points -> shared MLP 3 -> 32 -> 64 -> max -> [g | onehot(3) | PVLE_t (32)] -> FC 64 -> FC 3 = dc1
    box:    points - dc1 -> shared MLP 3 -> 48 -> 96 -> 160 -> max -> [g | onehot | PVLE_b (32)]
            -> FC 128 -> FC 64 -> FC 39 (Frustum PointNets layout, below)
    box[0:3] centre residual, [3:15] heading scores (12 bins), [15:27] heading residuals normalised by
    (pi / 12), [27:30] size scores (one template per class), [30:39] size residuals normalised by the
    template (3 per template). Centre (model frame) = dc1 + box[0:3].

ONNX contract (opset 17; fixed names; batch axis "batch" dynamic, N fixed at export):
    classifier: inputs points [B, N, 3], voxel [B, 3]                 -> output logits [B, 3]
    box:        inputs points [B, N, 3], voxel [B, 3], onehot [B, 3]  -> outputs center_tnet [B, 3], box [B, 39]
    voxel holds the integer bins as float32. Energies, gates and box decoding are not in the graph: the
    C forward pass and `lidet_ref.pointnet` compute them from these outputs.
    metadata_props (all strings): lidet.kind (classifier|box), lidet.format, lidet.n_points, lidet.classes,
    lidet.frame (azimuth), lidet.pvle_bins (az rad, el rad, range m), lidet.energy_T, lidet.gamma (one per
    class), lidet.trained (0|1), and for the box net lidet.n_heading_bins, lidet.mean_sizes (l w h per class).
"""
from __future__ import annotations

import math

import numpy as np
import torch
from torch import nn

CLASSES = ("Car", "Cyclist", "Pedestrian")  # lidet_class_t order
N_CLASSES = 3
N_HEADING_BINS = 12
N_SIZE_CLUSTERS = 3
#: size templates (l, w, h) per class, metres: the KITTI means Frustum PointNets and the authors use
MEAN_SIZES = np.array([[3.883, 1.629, 1.526], [1.763, 0.597, 1.737], [0.844, 0.661, 1.763]], np.float32)
BOX_OUT = 3 + 2 * N_HEADING_BINS + 4 * N_SIZE_CLUSTERS  # 39
#: PVLE voxel sizes: azimuth, elevation (rad), range (m); the paper's 10 deg / 10 deg / 1 m, equal to
#: lidet_proposal_cfg_default (float32 values)
PVLE_BINS = (float(np.float32(math.radians(10.0))), float(np.float32(math.radians(10.0))), 1.0)
FORMAT_VERSION = 1  # LIDET_WEIGHTS_FORMAT_VERSION


def to_model_frame(xyz: np.ndarray, mean: np.ndarray) -> np.ndarray:
    """Proposal points (..., N, 3) centred on `mean` (..., 3) -> the model frame: rotated about +z by
    minus the mean's azimuth (float32, the same operations as the C code: c = x / R, s = y / R)."""
    xyz = np.asarray(xyz, np.float32)
    mean = np.asarray(mean, np.float32)
    c, s = azimuth_cos_sin(mean)
    x, y = xyz[..., 0], xyz[..., 1]
    out = xyz.copy()
    out[..., 0] = c[..., None] * x + s[..., None] * y
    out[..., 1] = -s[..., None] * x + c[..., None] * y
    return out


def azimuth_cos_sin(mean: np.ndarray):
    """cos and sin of the mean's azimuth (1, 0 when the mean is on the z axis), float32."""
    mean = np.asarray(mean, np.float32)
    r = np.sqrt(mean[..., 0] * mean[..., 0] + mean[..., 1] * mean[..., 1]).astype(np.float32)
    ok = r > np.float32(1e-6)
    rs = np.where(ok, r, np.float32(1.0)).astype(np.float32)
    c = np.where(ok, mean[..., 0] / rs, np.float32(1.0)).astype(np.float32)
    s = np.where(ok, mean[..., 1] / rs, np.float32(0.0)).astype(np.float32)
    return c, s


def _point_mlp(widths):
    """Shared per-point MLP over (B, C, N): conv1x1 + BN + ReLU for every layer."""
    layers, c = [], 3
    for w in widths:
        layers += [nn.Conv1d(c, w, 1), nn.BatchNorm1d(w), nn.ReLU()]
        c = w
    return nn.Sequential(*layers)


def _fc(n_in, widths, n_out):
    """FC head: linear + BN + ReLU per hidden width, then a plain linear to n_out."""
    layers, c = [], n_in
    for w in widths:
        layers += [nn.Linear(c, w), nn.BatchNorm1d(w), nn.ReLU()]
        c = w
    layers.append(nn.Linear(c, n_out))
    return nn.Sequential(*layers)


def _pvle(widths):
    """Proposal voxel location encoder: voxel bins (3) -> linear + BN + ReLU layers."""
    layers, c = [], 3
    for w in widths:
        layers += [nn.Linear(c, w), nn.BatchNorm1d(w), nn.ReLU()]
        c = w
    return nn.Sequential(*layers)


class ClassifierNet(nn.Module):
    """PointNet classifier with PVLE. forward(points [B, N, 3], voxel [B, 3]) -> logits [B, 3]."""

    def __init__(self, point=(32, 64, 128), pvle=(32, 32), head=(64,), n_classes=N_CLASSES, use_pvle=True):
        super().__init__()
        self.cfg = dict(point=tuple(point), pvle=tuple(pvle), head=tuple(head), n_classes=n_classes,
                        use_pvle=bool(use_pvle))
        self.point = _point_mlp(point)
        self.pvle = _pvle(pvle) if use_pvle else None
        self.head = _fc(point[-1] + (pvle[-1] if use_pvle else 0), head, n_classes)

    def forward(self, points, voxel):
        g = self.point(points.transpose(1, 2)).amax(dim=2)
        if self.pvle is not None:
            g = torch.cat([g, self.pvle(voxel)], dim=1)
        return self.head(g)


class BoxNet(nn.Module):
    """T-Net + box PointNet with PVLE. forward(points, voxel, onehot) -> (center_tnet [B, 3], box [B, 39])."""

    def __init__(self, tnet_point=(32, 64), tnet_head=(64,), point=(48, 96, 160), head=(128, 64), pvle=(32, 32),
                 use_pvle=True, use_tnet=True):
        super().__init__()
        self.cfg = dict(tnet_point=tuple(tnet_point), tnet_head=tuple(tnet_head), point=tuple(point),
                        head=tuple(head), pvle=tuple(pvle), use_pvle=bool(use_pvle), use_tnet=bool(use_tnet))
        pv = pvle[-1] if use_pvle else 0
        if use_tnet:
            self.tnet_point = _point_mlp(tnet_point)
            self.tnet_pvle = _pvle(pvle) if use_pvle else None
            self.tnet_head = _fc(tnet_point[-1] + N_CLASSES + pv, tnet_head, 3)
        self.point = _point_mlp(point)
        self.pvle = _pvle(pvle) if use_pvle else None
        self.head = _fc(point[-1] + N_CLASSES + pv, head, BOX_OUT)

    def forward(self, points, voxel, onehot):
        if self.cfg["use_tnet"]:
            g = self.tnet_point(points.transpose(1, 2)).amax(dim=2)
            parts = [g, onehot] + ([self.tnet_pvle(voxel)] if self.tnet_pvle is not None else [])
            dc1 = self.tnet_head(torch.cat(parts, dim=1))
            points = points - dc1.unsqueeze(1)
        else:
            dc1 = torch.zeros(points.shape[0], 3, dtype=points.dtype, device=points.device)
        g = self.point(points.transpose(1, 2)).amax(dim=2)
        parts = [g, onehot] + ([self.pvle(voxel)] if self.pvle is not None else [])
        return dc1, self.head(torch.cat(parts, dim=1))


# ---- box coding (Frustum PointNets) ----------------------------------------------------------------

ANGLE_PER_BIN = 2.0 * math.pi / N_HEADING_BINS


def heading_to_bin(yaw):
    """Heading (rad, model frame) -> (bin index, residual normalised by half a bin), numpy."""
    a = np.mod(np.asarray(yaw, np.float64), 2 * math.pi)
    b = np.floor((a + ANGLE_PER_BIN / 2) / ANGLE_PER_BIN).astype(np.int64) % N_HEADING_BINS
    res = a - b * ANGLE_PER_BIN
    res = (res + math.pi) % (2 * math.pi) - math.pi
    return b, res / (ANGLE_PER_BIN / 2)


def decode_box(center_tnet: np.ndarray, box: np.ndarray):
    """Raw outputs -> (centre (B, 3) model frame, yaw (B,) model frame, size (B, 3) l w h, heading bin,
    size class). float64 numpy; lidet_ref.pointnet mirrors the C decode exactly."""
    box = np.asarray(box, np.float64)
    c = np.asarray(center_tnet, np.float64) + box[:, 0:3]
    hb = np.argmax(box[:, 3:3 + N_HEADING_BINS], axis=1)
    hr = box[np.arange(len(box)), 3 + N_HEADING_BINS + hb]
    yaw = hb * ANGLE_PER_BIN + hr * (ANGLE_PER_BIN / 2)
    o = 3 + 2 * N_HEADING_BINS
    sc = np.argmax(box[:, o:o + N_SIZE_CLUSTERS], axis=1)
    sr = box[:, o + N_SIZE_CLUSTERS:].reshape(-1, N_SIZE_CLUSTERS, 3)[np.arange(len(box)), sc]
    size = MEAN_SIZES[sc].astype(np.float64) * (1.0 + sr)
    return c, yaw, size, hb, sc


def count_params(model: nn.Module) -> int:
    return int(sum(p.numel() for p in model.parameters()))
