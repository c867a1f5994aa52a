# SPDX-License-Identifier: MIT
"""Figures of the two nets on one split of a proposal dataset (validation during training, test for
docs/TRAINING.md): per-class ID accuracy, gate AUROC and FPR at 95 % TPR, 3D IoU and heading error."""
from __future__ import annotations

import math

import numpy as np
import torch

from . import common as C
from . import models as M
from ..eval.iou import iou_3d_pairs

IOU_GOAL = (0.7, 0.5, 0.5)  # Car, Cyclist, Pedestrian (KITTI)


@torch.no_grad()
def cls_logits(model, d: dict, dev=torch.device("cpu"), bs: int = 1024) -> np.ndarray:
    model.eval()
    out = []
    for i in range(0, len(d["label"]), bs):
        idx = np.arange(i, min(i + bs, len(d["label"])))
        p, v = C.tensors(d, idx, dev)
        out.append(model(p, v).cpu().numpy())
    return np.concatenate(out) if out else np.zeros((0, M.N_CLASSES), np.float32)


@torch.no_grad()
def box_outputs(model, d: dict, onehot_cls: np.ndarray, dev=torch.device("cpu"), bs: int = 1024):
    """(center_tnet (K, 3), box (K, 39)) with the one-hot of onehot_cls (K,)."""
    model.eval()
    dcs, bxs = [], []
    for i in range(0, len(onehot_cls), bs):
        idx = np.arange(i, min(i + bs, len(onehot_cls)))
        p, v = C.tensors(d, idx, dev)
        oh = torch.nn.functional.one_hot(torch.from_numpy(onehot_cls[idx].astype(np.int64)), M.N_CLASSES).float().to(dev)
        dc, b = model(p, v, oh)
        dcs.append(dc.cpu().numpy())
        bxs.append(b.cpu().numpy())
    if not dcs:
        return np.zeros((0, 3), np.float32), np.zeros((0, M.BOX_OUT), np.float32)
    return np.concatenate(dcs), np.concatenate(bxs)


def energy_np(logits: np.ndarray, T: float = 1.0) -> np.ndarray:
    z = np.asarray(logits, np.float64) / T
    m = z.max(axis=1, keepdims=True)
    return -T * (m[:, 0] + np.log(np.exp(z - m).sum(axis=1)))


def box_energy_np(box: np.ndarray, T: float = 1.0) -> np.ndarray:
    o = 3 + 2 * M.N_HEADING_BINS
    return energy_np(box[:, 3:3 + M.N_HEADING_BINS], T) + energy_np(box[:, o:o + M.N_SIZE_CLUSTERS], T)


def gate_figures(e_id: np.ndarray, e_ood: np.ndarray, gamma=None, cls_id=None, cls_ood=None) -> dict:
    """AUROC and FPR at 95 % TPR (threshold from these ID energies); with gamma (per class) and the
    classes the gate uses, also TPR / FPR of the shipped thresholds."""
    out = dict(n_id=int(len(e_id)), n_ood=int(len(e_ood)), auroc=C.auroc(e_id, e_ood),
               fpr95=C.fpr_at_tpr(e_id, e_ood, 0.95))
    if gamma is not None and cls_id is not None:
        g = np.asarray(gamma, np.float64)
        out["tpr_gamma"] = float(np.mean(e_id < g[cls_id])) if len(e_id) else float("nan")
        out["fpr_gamma"] = float(np.mean(e_ood < g[cls_ood])) if len(e_ood) else float("nan")
    return out


def cls_figures(logits: np.ndarray, label: np.ndarray, gamma=None) -> dict:
    """Per-class accuracy of the ID samples, confusion matrix, gate-1 figures."""
    idm = label >= 0
    pred = logits.argmax(1)
    e = energy_np(logits)
    acc = {}
    for c, name in enumerate(M.CLASSES):
        m = label == c
        acc[name] = dict(n=int(m.sum()), acc=float(np.mean(pred[m] == c)) if m.any() else float("nan"))
    conf = np.zeros((M.N_CLASSES, M.N_CLASSES), int)
    for t, p in zip(label[idm], pred[idm]):
        conf[t, p] += 1
    res = dict(acc=acc, acc_all=float(np.mean(pred[idm] == label[idm])) if idm.any() else float("nan"),
               confusion=conf.tolist(), gate1=gate_figures(e[idm], e[~idm], gamma, pred[idm], pred[~idm]))
    return res


def decode_to_boxes(dc: np.ndarray, box: np.ndarray) -> np.ndarray:
    """Raw outputs -> (K, 7) model-frame boxes (x, y, z, l, w, h, heading)."""
    c, yaw, size, _, _ = M.decode_box(dc, box)
    return np.concatenate([c, size, yaw[:, None]], 1)


def wrap(a):
    return (np.asarray(a) + np.pi) % (2 * np.pi) - np.pi


def box_figures(pred_boxes: np.ndarray, gt: np.ndarray, label: np.ndarray) -> dict:
    """Per class: n, mean 3D IoU, share >= the class's KITTI threshold, heading error (deg; median,
    mean, and the share within 30 deg), centre error (m)."""
    out = {}
    iou = iou_3d_pairs(pred_boxes.astype(np.float64), gt.astype(np.float64)) if len(gt) else np.zeros(0)
    herr = np.degrees(np.abs(wrap(pred_boxes[:, 6] - gt[:, 6]))) if len(gt) else np.zeros(0)
    cerr = np.linalg.norm(pred_boxes[:, :3] - gt[:, :3], axis=1) if len(gt) else np.zeros(0)
    for c, name in enumerate(M.CLASSES):
        m = label == c
        if not m.any():
            out[name] = dict(n=0)
            continue
        out[name] = dict(n=int(m.sum()), iou_mean=float(iou[m].mean()), iou_thr=IOU_GOAL[c],
                         share_iou=float(np.mean(iou[m] >= IOU_GOAL[c])),
                         heading_err_median_deg=float(np.median(herr[m])), heading_err_mean_deg=float(herr[m].mean()),
                         heading_within_30deg=float(np.mean(herr[m] <= 30.0)),
                         centre_err_median_m=float(np.median(cerr[m])))
    return out


def eval_box(model, d: dict, dev=torch.device("cpu"), gamma=None) -> dict:
    """Box figures on the ID samples with a box target (true-class one-hot), and gate 2: ID energies
    with the true class vs OOD energies with the one-hot of a class drawn from a fixed generator (the
    classifier's choice for a real OOD proposal is not known to the box net alone)."""
    ok = (d["label"] >= 0) & ~np.isnan(d["box"][:, 0])
    did = {k: v[ok] for k, v in d.items() if isinstance(v, np.ndarray) and v.shape[:1] == ok.shape}
    dc, bx = box_outputs(model, did, did["label"], dev)
    pred = decode_to_boxes(dc, bx)
    res = dict(box=box_figures(pred, did["box"], did["label"]))
    ood = d["label"] < 0
    dood = {k: v[ood] for k, v in d.items() if isinstance(v, np.ndarray) and v.shape[:1] == ood.shape}
    rc = np.random.default_rng(12345).integers(0, M.N_CLASSES, int(ood.sum()))
    _, bo = box_outputs(model, dood, rc, dev)
    e_id, e_ood = box_energy_np(bx), box_energy_np(bo)
    res["gate2"] = gate_figures(e_id, e_ood, gamma, did["label"], rc)
    res["energies"] = dict(id=e_id, ood=e_ood, id_cls=did["label"], ood_cls=rc)
    return res


def mean_iou(res: dict) -> float:
    v = [res["box"][c]["iou_mean"] for c in M.CLASSES if res["box"][c].get("n", 0)]
    return float(np.mean(v)) if v else float("nan")


def fmt(v, pct=False, nd=2):
    if v is None or (isinstance(v, float) and math.isnan(v)):
        return "-"
    return f"{100 * v:.1f} %" if pct else f"{v:.{nd}f}"
