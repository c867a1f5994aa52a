# SPDX-License-Identifier: MIT
"""Fine-tune the shipped models of a sensor family on your own labelled scans (docs/TRAINING.md, "Fine-tuning on your
own labelled scans").

    python -m lidet_tools.train.finetune DATA_DIR [DATA_DIR ...] --family hdl64 --out-weights OUT
        [--epochs 8] [--epochs-energy 4] [--sim-mix 0.75] [--sim 60,40,20] [--val-share 0.25]
        [--fov-deg D] [--mount-height M] [--gamma ood|tpr] [--threads 1] [--jobs 1]

Input folders, either layout (told apart by their subfolders; `--layout` forces one):
* lidet's sensor-frame layout: velodyne/<name>.bin (float32 x, y, z, intensity) + boxes/<name>.txt
  (`<class> x y z l w h yaw score` per line, sensor frame), with an optional meta.json of per-folder and per-scan
  values (labelled azimuth field of view, mount height, sensor profile, labelled classes: dataset.py's docstring);
  `--fov-deg` and `--mount-height` give them where meta.json does not. `python -m lidet_tools.real.export` and
  `lidet-sim` write this layout;
* KITTI: velodyne/ + label_2/ + calib/ (labels in the camera's view only, as `dataset.py --kitti`).
The proposals are made by lidet's own C stages and labelled by dataset.py's rules (ID / excluded / OOD). Every
folder's scans are split by a stable hash of the name: `--val-share` of them (at least one of two or more)
form the user's validation split, which selects the epochs, sets the gates' gammas (with the simulated validation
split) and gives the model card's figures; the others are trained on.

What it does:
1. loads weights/cls_<family>.onnx and box_<family>.onnx into the PyTorch models of models.py (`load_onnx`: every
   ONNX initializer goes to one parameter or buffer; a convolution's batch norm, folded by the export, becomes an
   identity), and checks that they reproduce onnxruntime's outputs on a batch of the user's proposals;
2. builds the proposal sets: the user's scans, and simulated scans of the family (data/train/<family>.npz when
   it exists, else a small fresh set: `--sim TRAIN,VAL,TEST` scans with the family's simulator settings);
3. trains each net as its trainer does (train_cls, train_box), from the shipped weights: `--epochs` epochs of the
   first loss (cross-entropy on the ID proposals; the box loss), then `--epochs-energy` epochs of that loss + the
   energy hinge on ID and OOD proposals, with the margins recomputed from the model at that point by the trainers'
   rule (m_in = mean training ID energy, m_out = max(mean OOD energy, m_in + 3)). Every batch mixes the two sources:
   a share `--sim-mix` (default 0.75) of its proposals, ID and OOD alike, is simulated, the rest the user's, so the
   models keep what they learned; an epoch is `--steps` batches (default: enough for every user training proposal
   once, at least 50). Batch norms keep the shipped statistics (the folded ones have none to re-estimate, and a
   few hundred real proposals are too few). Adam, cosine from `--lr` (1e-4; the energy phase from half of it). The user's
   proposals get strong augmentation (`augment_real`): a side, the lower part or a band hidden (half of them), 40-100
   % of the points kept, mirror, +-10 deg about z, scale 0.9-1.1, +-0.15 m shift, 2 cm jitter; the simulated ones
   the trainers' (common.augment). The kept epoch of each phase has the best validation score of its trainer, the
   mean of the user's and the simulated validation splits. The gammas (`--gamma`): by default (ood) each class's
   threshold lets through as many of the validation OOD proposals (both splits together) as that class as the
   shipped gate did, so that the fine-tuned detector's false positives do not grow with a looser gate (the 95 % TPR
   rule loosened the cyclist gate from -6.90 to -5.34 on the real training frames: docs/journal/training.md); tpr
   takes the energy that keeps 95 % of the validation ID proposals of each class, as the trainers do;
4. for a family whose classifier was fine-tuned for int8 (vlp16, vlp16s), runs finetune_q on the merged dataset, as
   `make weights` does;
5. writes OUT/cls_<family>.onnx and box_<family>.onnx (export_onnx: the metadata of the trainers' exports), copies the
   other families' shipped ONNX and calibration files (unless `--only-family`), calibrates the two new models for
   int8 on the user's scans (weights.c_models with `calibrate --scans DATA_DIR`; `calibrate --refit` for hdl64) and
   regenerates every C model of OUT (`python -m lidet_codegen regen OUT`): OUT replaces weights/ in a build with
   `cmake -DLIDET_WEIGHTS_DIR=OUT`;
6. writes OUT/MODEL_CARD_finetune.md: data counts, the command, the ONNX -> PyTorch check, the figures of the
   shipped and the fine-tuned models on the user's validation split and on the simulated test split, the timings.
Work files (proposal sets, logs) go to `--work` (default OUT/work). Exit status 0; 2 with a message for an empty
folder, a folder without labels, a family without shipped weights, or no labelled object to train on.
"""
from __future__ import annotations

import argparse
import hashlib
import json
import math
import os
import pathlib
import shutil
import sys
import time
import zlib

import numpy as np
import torch
import torch.nn.functional as F

from . import common as C
from . import dataset as D
from . import metrics as MX
from . import models as M

ROOT = pathlib.Path(__file__).resolve().parents[3]
WEIGHTS = ROOT / "weights"
CARD = "MODEL_CARD_finetune.md"
#: strong augmentation of the user's proposals (augment_real)
REAL_AUG = dict(occlusion=0.5, keep=(0.4, 1.0), rot_deg=10.0, scale=(0.9, 1.1), shift_xy=0.15, shift_z=0.05,
                jitter=0.02, jitter_clip=0.05)
#: the conversions of the ONNX graph's nodes to the PyTorch modules (ONNX input index -> parameter name)
_PARAMS = {"Conv": ("weight", "bias"), "Gemm": ("weight", "bias"),
           "BatchNormalization": ("weight", "bias", "running_mean", "running_var")}


def _log(msg):
    print(f"[finetune {time.strftime('%H:%M:%S')}] {msg}", file=sys.stderr, flush=True)


# ---- ONNX -> PyTorch ----------------------------------------------------------------------------------------------

def _module_path(node_name: str) -> str:
    """'/point/point.0/Conv' -> 'point.0' (the scope the TorchScript exporter gives each node)."""
    parts = [p for p in node_name.split("/") if p]
    if len(parts) < 2:
        raise ValueError(f"ONNX node {node_name!r}: no module scope in its name")
    path = parts[-2]
    return path[len("inner."):] if path.startswith("inner.") else path


def load_onnx(path):
    """(PyTorch model in eval mode, kind 'classifier' | 'box', metadata dict) of a lidet ONNX file. Every
    initializer must go to exactly one parameter or buffer of models.ClassifierNet / BoxNet (widths read from the
    graph) and every parameter and buffer must be set, either from the graph or, for the batch norm after a
    convolution (folded into it by the export), as an identity (an initializer the exporter shared between equal
    tensors through Identity nodes goes to each of them); ValueError naming what does not map otherwise."""
    import onnx
    from onnx import numpy_helper
    path = pathlib.Path(path)
    om = onnx.load(str(path))
    meta = {p.key: p.value for p in om.metadata_props}
    kind = meta.get("lidet.kind")
    if kind not in ("classifier", "box"):
        raise ValueError(f"{path}: not a lidet model (lidet.kind {kind!r})")
    inits = {i.name: numpy_helper.to_array(i) for i in om.graph.initializer}
    # the exporter shares equal tensors (e.g. the zero running means of identity batch norms, finetune_q's) through
    # Identity nodes: their outputs are aliases of one initializer
    alias = {n.output[0]: n.input[0] for n in om.graph.node if n.op_type == "Identity" and n.input[0] in inits}
    layers = {}  # module path -> (op, {param: initializer name}, attributes)
    for n in om.graph.node:
        if n.op_type not in _PARAMS:
            continue
        mp = _module_path(n.name)
        if mp in layers:
            raise ValueError(f"{path}: two {n.op_type} nodes for module {mp}")
        attrs = {a.name: onnx.helper.get_attribute_value(a) for a in n.attribute}
        if n.op_type == "Gemm" and (attrs.get("transB", 0) != 1 or attrs.get("transA", 0) != 0
                                    or attrs.get("alpha", 1.0) != 1.0 or attrs.get("beta", 1.0) != 1.0):
            raise ValueError(f"{path}: Gemm {n.name} is not a torch Linear (attributes {attrs})")
        layers[mp] = (n.op_type, dict(zip(_PARAMS[n.op_type], n.input[1:])), attrs)

    def widths(prefix):
        ks = sorted((int(p.rsplit(".", 1)[1]), p) for p, v in layers.items()
                    if p.rsplit(".", 1)[0] == prefix and v[0] in ("Conv", "Gemm"))
        return [int(inits[layers[p][1]["weight"]].shape[0]) for _, p in ks]

    if kind == "classifier":
        head = widths("head")
        cfg = dict(point=widths("point"), pvle=widths("pvle") or [32, 32], head=head[:-1], n_classes=head[-1],
                   use_pvle=bool(widths("pvle")))
    else:
        use_tnet = bool(widths("tnet_point"))
        cfg = dict(point=widths("point"), head=widths("head")[:-1], pvle=widths("pvle") or [32, 32],
                   use_pvle=bool(widths("pvle")), use_tnet=use_tnet)
        if use_tnet:
            cfg.update(tnet_point=widths("tnet_point"), tnet_head=widths("tnet_head")[:-1])
    from .export import build_model
    model = build_model(kind, cfg)
    sd = model.state_dict()
    want = {k for k in sd if not k.endswith("num_batches_tracked")}
    new, used, direct = {}, [], []
    mods = dict(model.named_modules())
    for mp, (op, params, attrs) in layers.items():
        for pn, iname in params.items():
            key = f"{mp}.{pn}"
            if key not in sd:
                raise ValueError(f"{path}: initializer {iname} ({op} {mp}.{pn}) has no parameter in the PyTorch model")
            if iname in alias:
                iname = alias[iname]
            else:
                direct.append(iname)
            if iname not in inits:
                raise ValueError(f"{path}: {op} {mp} reads {iname}, which is not an initializer")
            v = torch.from_numpy(np.array(inits[iname], np.float32))
            if tuple(v.shape) != tuple(sd[key].shape):
                raise ValueError(f"{path}: {iname} has shape {tuple(v.shape)}, {key} {tuple(sd[key].shape)}")
            new[key] = v
            used.append(iname)
        if op == "BatchNormalization" and abs(float(attrs.get("epsilon", 1e-5)) - mods[mp].eps) > 1e-9:
            raise ValueError(f"{path}: {mp} epsilon {attrs.get('epsilon')} differs from the model's {mods[mp].eps}")
        if op == "Conv":  # the export folded the batch norm after it into it: an identity here
            head, i = mp.rsplit(".", 1)
            bn = f"{head}.{int(i) + 1}"
            if not isinstance(mods.get(bn), torch.nn.BatchNorm1d) or bn in layers:
                raise ValueError(f"{path}: convolution {mp} is not followed by a folded batch norm in the model")
            m = mods[bn]
            new[f"{bn}.weight"] = torch.ones(m.num_features)
            new[f"{bn}.bias"] = torch.zeros(m.num_features)
            new[f"{bn}.running_mean"] = torch.zeros(m.num_features)
            # (x - 0) / sqrt(var + eps) * 1 + 0 = x exactly: var + eps rounds to 1 in float32
            new[f"{bn}.running_var"] = torch.full((m.num_features,), 1.0 - m.eps)
    dup = sorted({u for u in direct if direct.count(u) > 1})
    unused = sorted(set(inits) - set(used))
    missing = sorted(want - set(new))
    extra = sorted(set(new) - want)
    if dup or unused or missing or extra:
        raise ValueError(f"{path}: the initializers do not map one to one onto {type(model).__name__}: "
                         f"used twice {dup}, unused {unused}, parameters not set {missing}, unknown {extra}")
    for k, v in sd.items():
        if k.endswith("num_batches_tracked"):
            new[k] = v
    model.load_state_dict(new, strict=True)
    return model.eval(), kind, meta


def onnx_parity(model, kind: str, onnx_path, points: np.ndarray, voxel: np.ndarray, cls=None) -> dict:
    """{output: (max abs difference, largest |output|)} of the PyTorch model against onnxruntime on one batch."""
    import onnxruntime as ort
    from .export import torch_forward
    feeds = {"points": np.ascontiguousarray(points, np.float32), "voxel": np.ascontiguousarray(voxel, np.float32)}
    if kind == "box":
        feeds["onehot"] = np.eye(M.N_CLASSES, dtype=np.float32)[np.asarray(cls, np.int64)]
    ref = torch_forward(model, kind, feeds["points"], feeds["voxel"], feeds.get("onehot"))
    sess = ort.InferenceSession(str(onnx_path), providers=["CPUExecutionProvider"])
    got = dict(zip([o.name for o in sess.get_outputs()], sess.run(None, feeds)))
    return {k: (float(np.abs(got[k] - ref[k]).max()), float(np.abs(got[k]).max())) for k in got}


def parity_ok(par: dict, tol: float = 1e-5) -> bool:
    """Within tol, relative to the output's size where it exceeds 1 (float32 ulps of a |20| score are ~2e-6)."""
    return all(d <= tol * max(1.0, big) for d, big in par.values())


# ---- data ---------------------------------------------------------------------------------------------------------

def folder_layout(folder, layout: str = "auto") -> str:
    """'boxes' or 'kitti' for a user folder; FileNotFoundError / ValueError with a clear message otherwise."""
    folder = pathlib.Path(folder)
    if not folder.is_dir():
        raise FileNotFoundError(f"{folder}: no such folder")
    if not (folder / "velodyne").is_dir() or not any((folder / "velodyne").glob("*.bin")):
        raise ValueError(f"{folder}: no scans: expected velodyne/*.bin (float32 x, y, z, intensity) with labels in "
                         "boxes/ (sensor frame) or label_2/ + calib/ (KITTI)")
    has_boxes = (folder / "boxes").is_dir()
    has_kitti = (folder / "label_2").is_dir()
    if layout in ("auto", "boxes") and has_boxes:
        return "boxes"
    if layout in ("auto", "kitti") and has_kitti:
        if not (folder / "calib").is_dir():
            raise ValueError(f"{folder}: label_2/ but no calib/ (KITTI labels are in the camera frame: calib/ maps them)")
        return "kitti"
    want = {"auto": "boxes/ (sensor frame: '<class> x y z l w h yaw score' lines) or label_2/ + calib/ (KITTI)",
            "boxes": "boxes/", "kitti": "label_2/ + calib/"}[layout]
    raise ValueError(f"{folder}: scans without labels: expected {want} beside velodyne/")


def val_names(names: list, share: float) -> set:
    """The scans of one folder in the user's validation split: the round(share n) of smallest name hash (at least
    one of two or more scans when share > 0)."""
    if share <= 0 or len(names) < 2:
        return set()
    k = min(len(names) - 1, max(1, int(round(share * len(names)))))
    return set(sorted(names, key=lambda n: (zlib.crc32(n.encode()), n))[:k])


def user_tasks(folders, layout: str, share: float, defaults: dict) -> list:
    tasks = []
    for f in folders:
        kind = folder_layout(f, layout)
        names = D.boxes_scans(f) if kind == "boxes" else D.kitti_scans(f)
        val = val_names(names, share)
        for n in names:
            if kind == "boxes":
                D.boxes_settings(f, n, defaults)  # a malformed meta.json fails here
            tasks.append((kind, 1 if n in val else 0, str(pathlib.Path(f)), n, defaults if kind == "boxes" else None))
    return tasks


def build(tasks, sensor: str, n_points: int, jobs: int, progress: bool, z_origin: str = "mean") -> dict:
    """dataset.concat of the proposals of the tasks (dataset._job), run with `jobs` processes; z_origin: the models'
    (ONNX lidet.z_origin)."""
    import functools
    cfg = dict(D.DEFAULTS, n_points=n_points, z_origin=z_origin)
    job = functools.partial(D._job, sensor=sensor, cfg=cfg)
    if jobs > 1:
        import multiprocessing as mp
        with mp.get_context("spawn").Pool(jobs) as pool:
            parts = list(C.progress(pool.imap(job, tasks, chunksize=2), progress, total=len(tasks), desc="proposals"))
    else:
        parts = [job(t) for t in C.progress(tasks, progress, desc="proposals")]
    d = D.concat(parts)
    d["n_excluded"] = int(sum(p["n_excluded"] for p in parts))
    return d


def sim_data(fam: str, spec: dict, a, z_origin: str = "mean") -> tuple[dict, str, bool]:
    """The family's simulated proposals: data/train/<fam>.npz (or --sim-data) when it exists, else a fresh set of
    --sim scans with the family's simulator settings (cached in --work). (dataset dict, its command, made now).
    The set's proposals must start where the models' do (z_origin)."""
    cached = a.sim_data or ROOT / "data" / "train" / f"{fam}.npz"
    if cached.exists():
        d = D.load(cached)
        if d["meta"].get("z_origin", "mean") != z_origin:
            raise ValueError(f"{cached}: proposals with z from the {d['meta'].get('z_origin', 'mean')}, the models' from "
                             f"the {z_origin}: give --sim-data a set made with dataset --z-origin {z_origin}")
        return d, d["meta"].get("command", str(cached)), False
    out = a.work / (f"sim_{fam}_{a.sim.replace(',', '_')}" + ("" if z_origin == "mean" else f"_z{z_origin}") + ".npz")
    argv = list(spec["dataset"])
    if "--z-origin" not in argv:
        argv += ["--z-origin", z_origin]
    i = argv.index("--sim")
    argv[i + 1] = a.sim
    argv += ["--jobs", str(a.jobs), "--out", str(out)] + ([] if a.progress else ["--no-progress"])
    made = not out.exists()
    if made:
        _log(f"simulated proposals ({a.sim} scans) -> {out}")
        if D.main(argv):
            raise RuntimeError("the simulated proposal set failed")
    d = D.load(out)
    return d, d["meta"].get("command", "python -m lidet_tools.train.dataset " + " ".join(argv)), made


KEYS = ("points", "voxel", "label", "box", "split", "scan")


def merge(sim: dict, user: dict) -> dict:
    """One dataset of both sources: `src` 0 simulated, 1 the user's; scans renumbered."""
    out = {}
    for k in KEYS:
        a, b = np.asarray(sim[k]), np.asarray(user[k])
        if k == "scan":
            b = b + (int(a.max()) + 1 if len(a) else 0)
        out[k] = np.concatenate([a, b.astype(a.dtype)])
    out["src"] = np.concatenate([np.zeros(len(sim["label"]), np.int8), np.ones(len(user["label"]), np.int8)])
    return out


def sub(d: dict, m: np.ndarray) -> dict:
    return {k: v[m] for k, v in d.items() if isinstance(v, np.ndarray) and v.shape[:1] == m.shape}


# ---- augmentation -------------------------------------------------------------------------------------------------

def augment_real(rng: np.random.Generator, pts: np.ndarray, box: np.ndarray | None = None):
    """Strong augmentation of the user's proposals (B, N, 3) model frame, box (B, 7) targets or None; copies. Hide a
    part (common.occlude, half of them), keep 40-100 % of the points, mirror, rotate about z by up to 10 deg, scale by
    0.9-1.1 about the mean (the box's centre and size follow), shift, jitter (REAL_AUG)."""
    g = dict(REAL_AUG)
    return C.augment(rng, pts, box, occlusion=g.pop("occlusion"), min_keep=8, **g)


# ---- training -----------------------------------------------------------------------------------------------------

def train_mode(model):
    """Training mode with the batch norms' statistics frozen (eval): see the module docstring."""
    model.train()
    for m in model.modules():
        if isinstance(m, torch.nn.BatchNorm1d):
            m.eval()
    return model


class Mixer:
    """Training batches of two sources: n_sim simulated and n_user user proposals per batch of `size` (the user's
    drawn without replacement through the epoch, cycling; the simulated ones at random), each row of the user's
    drawn with probability weights `pw_user` when given (box net: n_c^-0.5)."""

    def __init__(self, tr: dict, ok: np.ndarray, size: int, sim_mix: float, pw=None):
        self.user = np.nonzero(ok & (tr["src"] == 1))[0]
        self.sim = np.nonzero(ok & (tr["src"] == 0))[0]
        n_sim = int(round(sim_mix * size)) if len(self.sim) else 0
        if len(self.user) == 0:
            n_sim = size if len(self.sim) else 0
        self.n_sim, self.n_user = n_sim, size - n_sim
        self.pw = pw

    def batch(self, rng, order, step):
        parts = []
        if self.n_user:
            if self.pw is None:
                j = np.arange(step * self.n_user, (step + 1) * self.n_user) % len(order)
                parts.append(order[j])
            else:
                p = self.pw[self.user] / self.pw[self.user].sum()
                parts.append(self.user[rng.choice(len(self.user), self.n_user, p=p)])
        if self.n_sim:
            if self.pw is None:
                parts.append(self.sim[rng.integers(0, len(self.sim), self.n_sim)])
            else:
                p = self.pw[self.sim] / self.pw[self.sim].sum()
                parts.append(self.sim[rng.choice(len(self.sim), self.n_sim, p=p)])
        return np.concatenate(parts)


def _aug(rng, tr, idx, with_box, top_occlusion: float = 0.0):
    """Augmented points (and box targets) of rows idx: the user's strongly (augment_real), the simulated ones as
    their trainer does (common.augment). top_occlusion: first, the share of the cyclists' and pedestrians' rows
    (both sources) seen only from above (common.occlude_from_above)."""
    pts = np.empty((len(idx),) + tr["points"].shape[1:], np.float32)
    box = np.empty((len(idx), 7), np.float32) if with_box else None
    src_pts = tr["points"][idx]
    src_box = tr["box"][idx] if with_box else None
    if top_occlusion > 0.0:
        src_pts = np.array(src_pts, np.float32, copy=True)
        src_box = None if src_box is None else np.array(src_box, np.float32, copy=True)
        vru = np.nonzero(np.isin(tr["label"][idx], (M.CLASSES.index("Cyclist"), M.CLASSES.index("Pedestrian"))))[0]
        if len(vru):
            p, b = src_pts[vru], (None if src_box is None else src_box[vru])
            C.occlude_from_above(rng, p, b, top_occlusion)
            src_pts[vru] = p
            if b is not None:
                src_box[vru] = b
    u = tr["src"][idx] == 1
    for m, fn in ((u, augment_real), (~u, C.augment)):
        if m.any():
            p, b = fn(rng, src_pts[m], src_box[m] if with_box else None)
            pts[m] = p
            if with_box:
                box[m] = b
    return pts, box


def _cls_scores(model, vals: dict, phase: str) -> tuple[float, dict]:
    """The trainer's validation score (lower is better), the mean over the validation sets that can give it."""
    from .train_cls import balanced_acc
    s, figs = [], {}
    for name, v in vals.items():
        if not (v["label"] >= 0).any():
            continue
        res = MX.cls_figures(MX.cls_logits(model, v), v["label"])
        bal = balanced_acc(res)
        f = res["gate1"]["fpr95"]
        figs[name] = dict(bal_acc=bal, fpr95=f, auroc=res["gate1"]["auroc"])
        if phase == "energy":
            if not math.isnan(f):
                s.append(f + 1 - bal)
        else:
            s.append(-bal)
    return (float(np.mean(s)) if s else float("inf")), figs


def _box_scores(model, vals: dict, phase: str) -> tuple[float, dict]:
    s, figs = [], {}
    for name, v in vals.items():
        if not ((v["label"] >= 0) & ~np.isnan(v["box"][:, 0])).any():
            continue
        r = MX.eval_box(model, v)
        miou = MX.mean_iou(r)
        f = r["gate2"]["fpr95"]
        figs[name] = dict(mean_iou=miou, fpr95=f, auroc=r["gate2"]["auroc"])
        if phase == "energy":
            if not math.isnan(f):
                s.append(f - miou)
        else:
            s.append(-miou)
    return (float(np.mean(s)) if s else float("inf")), figs


def _mix_mean(e: np.ndarray, src: np.ndarray, sim_mix: float) -> float:
    """Mean of e over a batch of the mixer's composition: sim_mix x the simulated mean + the rest x the user's."""
    ms, mu = e[src == 0], e[src == 1]
    if len(ms) == 0 or len(mu) == 0:
        return float(e.mean())
    return float(sim_mix * ms.mean() + (1 - sim_mix) * mu.mean())


def finetune_net(kind: str, model, tr: dict, vals: dict, a, lam: float) -> dict:
    """Both phases of one net (kind 'classifier' or 'box') on the merged training rows `tr`. Returns the record:
    history, margins, best epochs, scores; the model holds the kept weights (eval mode)."""
    from .train_box import Targets, box_loss
    is_box = kind == "box"
    ok_id = (tr["label"] >= 0) & (~np.isnan(tr["box"][:, 0]) if is_box else True)
    ok_ood = tr["label"] < 0
    pw = None
    if is_box:  # n_c^-0.5 per source, as train_box draws its targets
        pw = np.zeros(len(tr["label"]))
        for s in (0, 1):
            m = ok_id & (tr["src"] == s)
            cnt = np.bincount(tr["label"][m], minlength=M.N_CLASSES).astype(np.float64)
            pw[m] = 1.0 / np.sqrt(np.maximum(cnt, 1))[tr["label"][m]]
    ids = Mixer(tr, ok_id, a.batch, a.sim_mix, pw)
    oods = Mixer(tr, ok_ood, 2 * a.batch, a.sim_mix)
    if len(ids.user) == 0:
        raise ValueError(f"no {'box targets' if is_box else 'ID proposals'} of the user's training scans: nothing to "
                         "fine-tune on (labelled Car / Cyclist / Pedestrian objects, mostly in one cluster)")
    steps = a.steps or max(math.ceil(len(ids.user) / max(ids.n_user, 1)), 50)
    cw = None
    if not is_box:
        # class weights (n / (3 n_c))^0.5 of the ID proposals as the batches hold them
        cnt = np.zeros(M.N_CLASSES)
        for rows, n in ((ids.user, ids.n_user), (ids.sim, ids.n_sim)):
            if len(rows) and n:
                cnt += n * np.bincount(tr["label"][rows], minlength=M.N_CLASSES) / len(rows)
        cw = torch.tensor(np.sqrt(cnt.sum() / (M.N_CLASSES * np.maximum(cnt, 1e-3))), dtype=torch.float32)
    score_fn = _box_scores if is_box else _cls_scores
    E1, E2 = a.epochs, a.epochs_energy
    s0, f0 = score_fn(model, vals, "first")
    e0, fe0 = score_fn(model, vals, "energy")
    rec = dict(steps=steps, n_user=ids.n_user, n_sim=ids.n_sim, ood_user=oods.n_user, ood_sim=oods.n_sim,
               shipped=dict(score_first=s0, score_energy=e0, val=f0, val_energy=fe0), history=[], margins=None)
    best = {"first": dict(score=s0, epoch=0, state=_copy(model)), "energy": None}
    t0 = time.perf_counter()
    name = "box" if is_box else "cls"
    for ep in range(E1 + E2):
        phase = "first" if ep < E1 else "energy"
        if ep == E1:
            model.load_state_dict(best["first"]["state"])
            m_in, m_out, e_id, e_ood = _margins(model, tr, ok_id, ok_ood, is_box, a)
            rec["margins"] = dict(m_in=m_in, m_out=m_out, e_id_mean=e_id, e_ood_mean=e_ood)
        lr0, ne, k = (a.lr, E1, ep) if phase == "first" else (a.lr / 2, E2, ep - E1)
        if k == 0:
            opt = torch.optim.Adam(model.parameters(), lr=lr0)
        lr = 1e-6 + 0.5 * (lr0 - 1e-6) * (1 + math.cos(math.pi * k / max(ne, 1)))
        for g in opt.param_groups:
            g["lr"] = lr
        torch.manual_seed(a.seed * 1000 + ep)
        rng = np.random.default_rng([a.seed, ep, 1 if is_box else 0])
        order = rng.permutation(ids.user)
        train_mode(model)
        tot = 0.0
        for st in C.progress(range(steps), a.progress, desc=f"{name} {phase} {ep + 1}/{E1 + E2}", leave=False):
            idx = ids.batch(rng, order, st)
            p, bx = _aug(rng, tr, idx, is_box, a.top_occlusion)
            if phase == "energy":
                oi = oods.batch(rng, rng.permutation(oods.user), 0)
                po, _ = _aug(rng, tr, oi, False, a.top_occlusion)
                pts, vox = C.tensors(tr, np.concatenate([idx, oi]), "cpu", np.concatenate([p, po]))
            else:
                oi = np.zeros(0, np.int64)
                pts, vox = C.tensors(tr, idx, "cpu", p)
            n = len(idx)
            if is_box:
                cls = tr["label"][idx].astype(np.int64)
                T = Targets(bx, cls, "cpu")
                cls_all = np.concatenate([cls, rng.integers(0, M.N_CLASSES, len(oi))])
                oh = F.one_hot(torch.from_numpy(cls_all), M.N_CLASSES).float()
                dc1, out = model(pts, vox, oh)
                loss, _ = box_loss(dc1[:n], out[:n], T, model.cfg["use_tnet"])
                e = C.box_energy(out) if phase == "energy" else None
            else:
                y = torch.from_numpy(tr["label"][idx].astype(np.int64))
                logits = model(pts, vox)
                loss = F.cross_entropy(logits[:n], y, weight=cw)
                e = C.energy(logits) if phase == "energy" else None
            if e is not None:
                loss = loss + lam * C.hinge(e[:n], e[n:], rec["margins"]["m_in"], rec["margins"]["m_out"])
            opt.zero_grad()
            loss.backward()
            opt.step()
            tot += float(loss.detach())
        model.eval()
        score, figs = score_fn(model, vals, phase)
        h = dict(epoch=ep + 1, phase=phase, lr=lr, loss=tot / steps, score=score, val=figs,
                 seconds=time.perf_counter() - t0)
        rec["history"].append(h)
        if best[phase] is None or score < best[phase]["score"]:
            best[phase] = dict(score=score, epoch=ep + 1, state=_copy(model))
        _log(f"{name} {phase} epoch {ep + 1}: loss {h['loss']:.4f} score {score:.4f} "
             + " ".join(f"{s}:{' '.join(f'{k} {v:.3f}' for k, v in f.items())}" for s, f in figs.items()))
    keep = best["energy"] if (E2 > 0 and best["energy"] is not None) else best["first"]
    model.load_state_dict(keep["state"])
    model.eval()
    rec.update(best_epoch=keep["epoch"], best_score=keep["score"], seconds=time.perf_counter() - t0)
    return rec


def _copy(model) -> dict:
    return {k: v.detach().clone() for k, v in model.state_dict().items()}


def _margins(model, tr, ok_id, ok_ood, is_box, a):
    """The trainers' margins at the start of the energy phase, the means taken as the batches mix the sources."""
    if is_box:
        d = sub(tr, ok_id | ok_ood)
        r = MX.eval_box(model, d)
        ok = (d["label"] >= 0) & ~np.isnan(d["box"][:, 0])
        e_id = _mix_mean(r["energies"]["id"], d["src"][ok], a.sim_mix)
        e_ood = _mix_mean(r["energies"]["ood"], d["src"][d["label"] < 0], a.sim_mix)
    else:
        e = MX.energy_np(MX.cls_logits(model, tr))
        e_id = _mix_mean(e[ok_id], tr["src"][ok_id], a.sim_mix)
        e_ood = _mix_mean(e[ok_ood], tr["src"][ok_ood], a.sim_mix)
    return e_id, max(e_ood, e_id + a.min_gap), e_id, e_ood


def gate_energies(model, kind: str, d: dict) -> dict:
    """The gate's (energy, class) on the rows of d, from one pass of the model: 'id' the ID rows (the classifier's
    predicted class; the box net's true class, rows with a box target), 'ood' the OOD rows (the classifier's predicted
    class; the box net's one-hot of a class drawn as metrics.eval_box draws it, the same draw for any model)."""
    if kind == "classifier":
        lg = MX.cls_logits(model, d)
        e, c, idm = MX.energy_np(lg), lg.argmax(1), d["label"] >= 0
        return {"id": (e[idm], c[idm]), "ood": (e[~idm], c[~idm])}
    r = MX.eval_box(model, d)["energies"]
    return {"id": (r["id"], r["id_cls"]), "ood": (r["ood"], r["ood_cls"])}


def gammas_at_ood(new: tuple, old: tuple, gamma_old: list, fallback: list) -> list:
    """gamma per class that lets through as many of the OOD rows as that class (E < gamma) as the shipped gate did:
    with n the shipped gate's count (old energies below gamma_old), the new model's (n + 1)-th smallest energy of the
    class (as float32, rounded down), which the strict test E < gamma leaves out. `fallback` (the TPR gammas) for a
    class of which the shipped gate let every row through or the new model predicts none. new, old: gate_energies'
    'ood' of the fine-tuned and the shipped model on the same rows."""
    (e_new, c_new), (e_old, c_old) = new, old
    out = []
    for c in range(M.N_CLASSES):
        n = int(((c_old == c) & (e_old < gamma_old[c])).sum())
        e = np.sort(np.asarray(e_new[c_new == c], np.float64))
        if n >= len(e):
            out.append(float(fallback[c]))
            continue
        g = np.float32(e[n])  # the gates compare float32 energies: the float32 at or just below the (n + 1)-th
        out.append(float(np.nextafter(g, np.float32(-np.inf)) if g > e[n] else g))
    return out


def set_onnx_gamma(path, gamma: list) -> None:
    """Rewrites the lidet.gamma metadata of an exported model (the graph untouched)."""
    import onnx
    m = onnx.load(str(path))
    for p in m.metadata_props:
        if p.key == "lidet.gamma":
            p.value = ",".join(repr(float(g)) for g in gamma)
            break
    else:
        raise ValueError(f"{path}: no lidet.gamma metadata")
    onnx.save(m, str(path))


def gammas(energies: dict) -> list:
    """gamma per class, as the trainers: 95 % of the validation ID proposals (gate_energies' 'id': the classifier's
    predicted class; the box net's true class) kept; pooled for a class with fewer than 20."""
    return C.per_class_gamma(*energies["id"])


# ---- the command --------------------------------------------------------------------------------------------------

def shipped_families(wdir=WEIGHTS) -> list:
    return sorted(p.stem[4:] for p in pathlib.Path(wdir).glob("cls_*.onnx") if (pathlib.Path(wdir) / f"box_{p.stem[4:]}.onnx").exists())


def add_args(ap):
    ap.add_argument("data", nargs="+", type=pathlib.Path, metavar="DATA_DIR",
                    help="folders of labelled scans: velodyne/ + boxes/ (sensor frame) or velodyne/ + label_2/ + calib/")
    ap.add_argument("--family", required=True, help="the shipped models to start from (weights/cls_<family>.onnx, box_...)")
    ap.add_argument("--out-weights", type=pathlib.Path, required=True, help="the output weights folder")
    ap.add_argument("--epochs", type=int, default=8, help="epochs of the first phase (cross-entropy; box loss)")
    ap.add_argument("--epochs-energy", type=int, default=4, help="epochs of the energy phase")
    ap.add_argument("--steps", type=int, default=0,
                    help="batches per epoch (default: every user training proposal once, at least 50)")
    ap.add_argument("--sim-mix", type=float, default=0.75,
                    help="share of simulated proposals in every batch (ID and OOD; default 0.75)")
    ap.add_argument("--sim", default="60,40,20",
                    help="simulated scans TRAIN,VAL,TEST of a fresh set when data/train/<family>.npz is absent")
    ap.add_argument("--sim-data", type=pathlib.Path, default=None,
                    help="the simulated proposal set to use (default data/train/<family>.npz when it exists)")
    ap.add_argument("--val-share", type=float, default=0.25,
                    help="share of each folder's scans in the user's validation split (by name hash)")
    ap.add_argument("--layout", choices=("auto", "boxes", "kitti"), default="auto",
                    help="the folders' label layout (auto: boxes/ when present, else label_2/)")
    ap.add_argument("--fov-deg", type=float, default=None,
                    help="sensor-frame folders: half the labelled azimuth field of view, where meta.json does not say")
    ap.add_argument("--mount-height", type=float, default=None,
                    help="sensor-frame folders: the sensor's height above the road (m), where meta.json does not say")
    ap.add_argument("--top-occlusion", type=float, default=0.0,
                    help="share of the cyclist and pedestrian proposals seen only from above a cut (people behind "
                         "parked cars; common.occlude_from_above; default 0)")
    ap.add_argument("--gamma", choices=("ood", "tpr"), default="ood",
                    help="the gates' thresholds: ood (default) lets through, per class, as many of the validation "
                         "splits' OOD proposals as the shipped gates do; tpr keeps 95 %% of their ID proposals per "
                         "class, as the trainers")
    ap.add_argument("--lr", type=float, default=1e-4, help="Adam learning rate of the first phase (energy: half)")
    ap.add_argument("--batch", type=int, default=64)
    ap.add_argument("--min-gap", type=float, default=3.0, help="least m_out - m_in (the trainers')")
    ap.add_argument("--only-family", action="store_true",
                    help="OUT holds this family's models only (default: the other shipped families' too)")
    ap.add_argument("--weights", type=pathlib.Path, default=WEIGHTS, help="the shipped weights folder")
    ap.add_argument("--install", action="store_true",
                    help="then make the fine-tuned pair the shipped one: copy its ONNX and calibration files from OUT "
                         "into --weights and regenerate every C model there (python -m lidet_codegen regen weights); "
                         "the next build of the detector, the CLI and the firmware uses them")
    ap.add_argument("--work", type=pathlib.Path, default=None, help="work files (default OUT/work)")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--threads", type=int, default=1)
    ap.add_argument("--jobs", type=int, default=1, help="processes making the proposal sets")
    ap.add_argument("--no-progress", action="store_true")
    return ap


def check_args(a) -> tuple[str, dict]:
    """(sensor, family spec); ValueError / FileNotFoundError with the message for the user."""
    from .weights import FAMILIES
    fams = shipped_families(a.weights)
    if not (a.weights / f"cls_{a.family}.onnx").exists() or not (a.weights / f"box_{a.family}.onnx").exists():
        raise FileNotFoundError(f"--family {a.family}: no shipped weights ({a.weights}/cls_{a.family}.onnx and "
                                f"box_{a.family}.onnx); families with shipped weights: {', '.join(fams) or 'none'}")
    if a.family not in FAMILIES:
        raise ValueError(f"--family {a.family}: no simulator settings in lidet_tools.train.weights.FAMILIES "
                         f"({', '.join(sorted(FAMILIES))})")
    if not 0.0 <= a.sim_mix < 1.0:
        raise ValueError(f"--sim-mix must be in [0, 1), got {a.sim_mix}")
    if not 0.0 <= a.top_occlusion <= 1.0:
        raise ValueError(f"--top-occlusion must be a probability in [0, 1], got {a.top_occlusion}")
    if not 0.0 <= a.val_share < 1.0:
        raise ValueError(f"--val-share must be in [0, 1), got {a.val_share}")
    if a.epochs < 0 or a.epochs_energy < 0 or a.epochs + a.epochs_energy == 0:
        raise ValueError("--epochs and --epochs-energy: at least one epoch")
    counts = a.sim.split(",")
    if len(counts) != 3 or not all(c.isdigit() for c in counts) or int(counts[0]) == 0 or int(counts[1]) == 0:
        raise ValueError(f"--sim takes TRAIN,VAL,TEST scan counts (train and val > 0), got {a.sim!r}")
    for f in a.data:
        folder_layout(f, a.layout)
    out = a.out_weights.resolve()
    # the shipped folder of this checkout, or of any lidet checkout (a tree with lib/include/lidet/lidet.h beside its
    # weights/: another worktree run with this one's environment)
    if out == a.weights.resolve() or (out.name == "weights" and (out.parent / "lib/include/lidet/lidet.h").is_file()):
        raise ValueError(f"--out-weights {a.out_weights}: that is the shipped weights folder; write elsewhere")
    spec = FAMILIES[a.family]
    return spec.get("sensor", a.family), spec


def _arg_value(argv: list, key: str, default):
    return type(default)(argv[argv.index(key) + 1]) if key in argv else default


def _sha(p) -> str:
    return hashlib.sha256(pathlib.Path(p).read_bytes()).hexdigest()


def finetune(a) -> dict:
    from .export import export_onnx
    t_all = time.perf_counter()
    timings = {}
    sensor, spec = check_args(a)
    a.work = a.work or a.out_weights / "work"
    a.progress = not a.no_progress
    a.work.mkdir(parents=True, exist_ok=True)
    a.out_weights.mkdir(parents=True, exist_ok=True)
    C.setup(a.seed, a.threads)
    torch.use_deterministic_algorithms(False)  # as finetune_q: the CPU kernels here repeat run to run on one thread
    fam = a.family
    src_onnx = {k: a.weights / f"{k}_{fam}.onnx" for k in ("cls", "box")}
    models = {}
    for k, kind in (("cls", "classifier"), ("box", "box")):
        models[k] = load_onnx(src_onnx[k])
        if models[k][1] != kind:
            raise ValueError(f"{src_onnx[k]}: lidet.kind {models[k][1]}, expected {kind}")
    n_points = int(models["cls"][2].get("lidet.n_points", 64))
    z_origin = models["cls"][2].get("lidet.z_origin", "mean")
    if models["box"][2].get("lidet.z_origin", "mean") != z_origin:
        raise ValueError(f"{src_onnx['cls']} and {src_onnx['box']} were trained on proposals of different z origins")

    # 1. proposal sets
    t = time.perf_counter()
    defaults = dict(fov_half_deg=a.fov_deg, mount_height_m=a.mount_height)
    tasks = user_tasks(a.data, a.layout, a.val_share, defaults)
    _log(f"{len(tasks)} user scans ({sum(t[1] == 1 for t in tasks)} validation) -> proposals")
    user = build(tasks, sensor, n_points, a.jobs, a.progress, z_origin)
    timings["user proposals"] = time.perf_counter() - t
    if not (user["label"] >= 0).any():
        raise ValueError(f"{', '.join(map(str, a.data))}: no labelled Car / Cyclist / Pedestrian proposal in "
                         f"{len(tasks)} scans (objects whose cluster holds most of them): nothing to fine-tune on")
    t = time.perf_counter()
    sim, sim_cmd, made = sim_data(fam, spec, a, z_origin)
    timings["simulated proposals" + ("" if made else " (an existing set, read)")] = time.perf_counter() - t
    if int(sim["points"].shape[1]) != n_points:
        raise ValueError(f"the simulated set has {sim['points'].shape[1]} points per proposal, the models {n_points}")
    data = merge(sim, user)
    tr = sub(data, data["split"] == 0)
    vals = {"user": sub(data, (data["split"] == 1) & (data["src"] == 1)),
            "sim": sub(data, (data["split"] == 1) & (data["src"] == 0))}
    va_all = sub(data, data["split"] == 1)
    sim_test = sub(data, (data["split"] == 2) & (data["src"] == 0))

    # 2. the loaded models against onnxruntime, on a batch of the user's proposals
    rows = np.nonzero(data["src"] == 1)[0][:256]
    parity = {}
    for k in ("cls", "box"):
        m, kind, _ = models[k]
        cls = np.maximum(data["label"][rows], 0)
        parity[k] = onnx_parity(m, kind, src_onnx[k], data["points"][rows], data["voxel"][rows], cls)
        if not parity_ok(parity[k]):
            raise RuntimeError(f"{src_onnx[k]}: the loaded PyTorch model differs from onnxruntime: {parity[k]}")
    _log("ONNX -> PyTorch: " + "; ".join(f"{k}.{o} max |diff| {d:.1e}" for k, p in parity.items() for o, (d, _) in p.items()))

    # 3. shipped figures, training, gammas
    shipped_gamma = {k: [float(v) for v in models[k][2]["lidet.gamma"].split(",")] for k in ("cls", "box")}
    before = {s: _evaluate(v, models, shipped_gamma) for s, v in (("user", vals["user"]), ("sim_test", sim_test))}
    lam = {"cls": _arg_value(spec["cls"], "--lam", 0.1), "box": _arg_value(spec["box"], "--lam", 0.1)}
    kinds = {"cls": "classifier", "box": "box"}
    # the shipped gates on the validation OOD proposals (--gamma ood holds the fine-tuned ones to their counts)
    ood_shipped = {k: gate_energies(models[k][0], kinds[k], va_all)["ood"] for k in kinds}
    records, gamma, gamma_tpr = {}, {}, {}
    for k, kind in kinds.items():
        t = time.perf_counter()
        _log(f"{k}: {a.epochs} + {a.epochs_energy} epochs")
        records[k] = finetune_net(kind, models[k][0], tr, vals, a, lam[k])
        g = gate_energies(models[k][0], kind, va_all)
        gamma[k] = gamma_tpr[k] = gammas(g)
        if a.gamma == "ood":
            gamma[k] = gammas_at_ood(g["ood"], ood_shipped[k], shipped_gamma[k], gamma_tpr[k])
        _log(f"{k}: gamma {', '.join(f'{g:.3f}' for g in gamma[k])} (--gamma {a.gamma}; 95 % TPR: "
             f"{', '.join(f'{g:.3f}' for g in gamma_tpr[k])}; shipped: {', '.join(f'{g:.3f}' for g in shipped_gamma[k])})")
        timings[f"{k} training"] = time.perf_counter() - t

    # 4. ONNX (and the int8 fine-tuning of the families that have it)
    cmd = getattr(a, "command", None) or "python -m lidet_tools.train.finetune"
    data_desc = (f"finetune of {src_onnx['cls'].parent.name}/{{cls,box}}_{fam}.onnx on "
                 + ", ".join(str(d) for d in a.data) + f" + {sim_cmd} (sim-mix {a.sim_mix})")
    out = {k: a.out_weights / f"{k}_{fam}.onnx" for k in ("cls", "box")}
    for k, kind in (("cls", "classifier"), ("box", "box")):
        meta = dict(n_points=n_points, gamma=gamma[k], energy_T=1.0, trained=1, sensor=sensor, data=data_desc,
                    command=cmd, z_origin=z_origin)
        export_onnx(models[k][0].cpu(), dict(kind=kind, meta=meta), out[k])
    qat = None
    if spec.get("cls_finetune"):
        from . import finetune_q as FQ
        npz = a.work / "merged.npz"
        np.savez_compressed(npz, meta=json.dumps(dict(sensor=sensor, command=data_desc, z_origin=z_origin)),
                            **{k: v for k, v in data.items()})
        fargv = ["--onnx", str(out["cls"]), "--data", str(npz), "--out", str(out["cls"]), "--threads", str(a.threads)] \
            + spec["cls_finetune"]
        _log(f"cls: fine-tuned for int8 (finetune_q {' '.join(spec['cls_finetune'])})")
        fp = FQ.add_args(argparse.ArgumentParser()).parse_args(fargv)
        fp.command = "python -m lidet_tools.train.finetune_q " + " ".join(fargv)
        t = time.perf_counter()
        qat = FQ.finetune(fp)
        timings["cls int8 fine-tuning"] = time.perf_counter() - t
        m, _, meta = load_onnx(out["cls"])
        models["cls"] = (m, "classifier", meta)
        gamma["cls"] = gamma_tpr["cls"] = [float(v) for v in meta["lidet.gamma"].split(",")]
        if a.gamma == "ood":
            gamma["cls"] = gammas_at_ood(gate_energies(m, "classifier", va_all)["ood"], ood_shipped["cls"],
                                         shipped_gamma["cls"], gamma_tpr["cls"])
            set_onnx_gamma(out["cls"], gamma["cls"])

    # 5. the other families, int8 calibration on the user's scans, every C model
    t = time.perf_counter()
    if not a.only_family:
        for f in shipped_families(a.weights):
            if f == fam:
                continue
            for k in ("cls", "box"):
                for ext in (".onnx", ".calib.json"):
                    p = a.weights / f"{k}_{f}{ext}"
                    if p.exists():
                        shutil.copy(p, a.out_weights / p.name)
    from .weights import c_models
    ca = argparse.Namespace(weights=a.out_weights, real=None)
    emit_cmds = c_models(ca, [fam], scan_dirs=[d for d in a.data])
    timings["int8 calibration and C models"] = time.perf_counter() - t

    # 6. figures and the card
    after = {s: _evaluate(v, models, gamma) for s, v in (("user", vals["user"]), ("sim_test", sim_test))}
    timings["total"] = time.perf_counter() - t_all
    res = dict(family=fam, sensor=sensor, command=cmd, data=[str(d) for d in a.data], sim_command=sim_cmd,
               sim_mix=a.sim_mix, parity=parity, records=records, gamma=gamma, gamma_rule=a.gamma,
               gamma_tpr=gamma_tpr, shipped_gamma=shipped_gamma,
               before=before, after=after, timings=timings, qat=qat, emit=emit_cmds,
               counts=_counts(data, tasks), tasks=[(t[0], t[1], t[2], t[3]) for t in tasks],
               shipped_sha={k: _sha(p) for k, p in src_onnx.items()}, n_excluded=user["n_excluded"])
    (a.work / "finetune.json").write_text(json.dumps(res, indent=1, default=_json))
    (a.out_weights / CARD).write_text(card(res, a))
    _log(f"done in {timings['total']:.0f} s: {a.out_weights}/{{cls,box}}_{fam}.onnx, C models, {CARD}")
    return res


def _evaluate(v: dict, models: dict, gamma: dict):
    """evaluate.evaluate of both nets on the rows v (None when empty)."""
    from . import evaluate as EV
    if not len(v["label"]):
        return None
    d = dict(v, split=np.zeros(len(v["label"]), np.int8))
    return EV.evaluate(d, 0, cls_model=(models["cls"][0], gamma["cls"]), box_model=(models["box"][0], gamma["box"]))


def _json(v):
    if isinstance(v, (np.generic,)):
        return v.item()
    if isinstance(v, np.ndarray):
        return v.tolist()
    if isinstance(v, pathlib.Path):
        return str(v)
    return float(v)


def _counts(data: dict, tasks: list) -> dict:
    """Scans and proposals (Car, Cyclist, Pedestrian, OOD) per source and split."""
    out = {}
    for s, sn in ((1, "user"), (0, "simulated")):
        for sp, spn in enumerate(D.SPLITS):
            m = (data["src"] == s) & (data["split"] == sp)
            if s == 1:
                scans = sum(1 for t in tasks if t[1] == sp)
            else:
                scans = int(len(np.unique(data["scan"][m])))
            if not m.any() and not scans:
                continue
            lab = data["label"][m]
            out[f"{sn} {spn}"] = dict(scans=scans, **{c: int((lab == i).sum()) for i, c in enumerate(M.CLASSES)},
                                      OOD=int((lab < 0).sum()))
    return out


def card(r: dict, a) -> str:
    from . import evaluate as EV
    fam = r["family"]
    L = [f"# Fine-tuned {fam} models: model card", "",
         f"Made by `python -m lidet_tools.train.finetune` (docs/TRAINING.md, \"Fine-tuning on your own labelled scans\") "
         f"from the shipped `cls_{fam}.onnx` (sha256 {r['shipped_sha']['cls'][:12]}) and `box_{fam}.onnx` (sha256 "
         f"{r['shipped_sha']['box'][:12]}). Generated; do not edit by hand.", "", "    " + r["command"], ""]
    L += ["## Data", "",
          f"The user's scans: {', '.join(f'`{d}`' for d in r['data'])} ({len(r['tasks'])} scans; "
          f"{sum(t[1] == 1 for t in r['tasks'])} of them, chosen by name hash (`--val-share {a.val_share}`), are the "
          f"user's validation split). {r['n_excluded']} clusters excluded (ignored classes, DontCare, outside the "
          "labelled field of view, unlabelled classes). Simulated scans: "
          f"`{r['sim_command']}`.", "",
          "| source, split | scans | Car | Cyclist | Pedestrian | OOD |", "|---|---:|---:|---:|---:|---:|"]
    for k, v in r["counts"].items():
        L.append(f"| {k} | {v['scans']} | {v['Car']} | {v['Cyclist']} | {v['Pedestrian']} | {v['OOD']} |")
    val_scans = [t[3] for t in r["tasks"] if t[1] == 1]
    L += ["", f"User validation scans: {', '.join(val_scans) if val_scans else 'none'}.", ""]
    rc, rb = r["records"]["cls"], r["records"]["box"]
    L += ["## Training", "",
          f"Every batch: {rc['n_sim']} simulated + {rc['n_user']} user ID proposals for the classifier, "
          f"{rb['n_sim']} + {rb['n_user']} box targets for the box net (`--sim-mix {r['sim_mix']}`: "
          f"{100 * r['sim_mix']:.0f} % simulated); in the energy phase also {rc['ood_sim']} simulated + {rc['ood_user']} "
          f"user OOD proposals. {rc['steps']} batches per epoch (classifier), {rb['steps']} (box net); "
          f"{a.epochs} epochs of the first loss, then {a.epochs_energy} of the energy phase; Adam from lr {a.lr} "
          f"(energy phase {a.lr / 2}), cosine; seed {a.seed}. Augmentation of the user's proposals: "
          + ", ".join(f"{k} {v}" for k, v in REAL_AUG.items()) + "; of the simulated ones the trainers' (common.augment)."
          + (f" First, {100 * a.top_occlusion:.0f} % of the cyclists and pedestrians of both sources seen only from "
             "above a cut (`--top-occlusion`, common.occlude_from_above)." if a.top_occlusion > 0 else ""),
          "", ("The gammas now (`--gamma ood`) let through, per class, as many of the validation OOD proposals as "
               "the shipped gates did; beside them the gammas that keep 95 % of the validation ID proposals (the "
               "trainers' rule, `--gamma tpr`)." if r.get("gamma_rule") == "ood" else
               "The gammas now keep 95 % of the validation ID proposals per class (`--gamma tpr`, the trainers' rule)."),
          "", "| net | margins m_in / m_out | kept epoch | gamma shipped (Car, Cyclist, Pedestrian) | gamma now | gamma at 95 % TPR |",
          "|---|---|---:|---|---|---|"]
    for k in ("cls", "box"):
        rr = r["records"][k]
        mg = rr["margins"] or {}
        L.append(f"| {k} | {mg.get('m_in', float('nan')):.2f} / {mg.get('m_out', float('nan')):.2f} | "
                 f"{rr['best_epoch']} | {', '.join(f'{g:.3f}' for g in r['shipped_gamma'][k])} | "
                 f"{', '.join(f'{g:.3f}' for g in r['gamma'][k])} | "
                 f"{', '.join(f'{g:.3f}' for g in r.get('gamma_tpr', r['gamma'])[k])} |")
    L += ["", "Validation score per epoch (the trainer's; lower is better; epoch 0 = the shipped model):", "",
          "| net | epoch | phase | loss | score | user val | simulated val |", "|---|---:|---|---:|---:|---|---|"]
    for k in ("cls", "box"):
        rr = r["records"][k]
        sh = rr["shipped"]
        L.append(f"| {k} | 0 | shipped | - | {sh['score_first']:.4f} / {sh['score_energy']:.4f} (energy) | "
                 f"{_figs(sh['val_energy'].get('user'))} | {_figs(sh['val_energy'].get('sim'))} |")
        for h in rr["history"]:
            L.append(f"| {k} | {h['epoch']} | {h['phase']} | {h['loss']:.4f} | {h['score']:.4f} | "
                     f"{_figs(h['val'].get('user'))} | {_figs(h['val'].get('sim'))} |")
    if r.get("qat"):
        q = r["qat"]
        L += ["", f"The classifier was then fine-tuned for int8 (finetune_q): validation balanced accuracy "
              f"{q['before']['bal_acc']:.3f} -> {q['after']['bal_acc']:.3f}, fake-int8 disagreement "
              f"{100 * q['before']['fake_q_disagree']:.2f} % -> {100 * q['after']['fake_q_disagree']:.2f} %."]
    L += ["", "ONNX -> PyTorch check (the shipped models loaded into models.py against onnxruntime, "
          "256 user proposals; max |difference|, largest |output|): "
          + "; ".join(f"{k}.{o} {d:.1e} ({big:.1f})" for k, p in r["parity"].items() for o, (d, big) in p.items()) + ".", ""]
    L += ["## Figures", "",
          "Proposal-level (evaluate.markdown), each model with its own gammas: in the gate tables the columns "
          "\"shipped gamma\" hold the TPR / FPR at the shipped gammas for the shipped models and at the recomputed "
          "ones for the fine-tuned models. The user's validation split is small: read the counts.", ""]
    for s, title in (("user", "user validation split"), ("sim_test", "simulated test split (scans never trained on)")):
        for when, lab in (("before", "shipped"), ("after", "fine-tuned")):
            res = r[when].get(s)
            if res is None:
                L += [f"**{lab}, {title}**: no proposals", ""]
                continue
            L.append(EV.markdown(res, f"{lab}, {title}"))
    t = r["timings"]
    L += ["## C models", "",
          f"`{a.out_weights}` holds the fine-tuned `cls_{fam}` and `box_{fam}`"
          + ("" if a.only_family else " and the other shipped families unchanged")
          + f", their int8 calibration on the user's scans (`python -m lidet_tools.train.calibrate ... --scans "
          + " --scans ".join(r["data"]) + "`) and every C model (`python -m lidet_codegen regen "
          f"{a.out_weights}`). Build the detector with them:", "",
          f"    cmake -S . -B build_ft -DCMAKE_BUILD_TYPE=Release -DLIDET_WEIGHTS_DIR={a.out_weights.resolve()}",
          "    cmake --build build_ft --target lidet_cli lidet_py", "",
          "## Timings (seconds)", "", "| step | s |", "|---|---:|"]
    L += [f"| {k} | {v:.0f} |" for k, v in t.items()]
    L += ["", "## Known limits", "",
          "- The user's validation split is a few scans: its figures are anecdotes; measure the detector on held-out "
          "frames (e.g. `python -m lidet_tools.eval_real` for the real frames of ../shared).",
          "- Batch norms keep the shipped statistics.",
          "- The box net is evaluated with the true class as its one-hot; gate-2 OOD figures use a random class.", ""]
    return "\n".join(L)


def _figs(f) -> str:
    if not f:
        return "-"
    return ", ".join(f"{k} {v:.3f}" for k, v in f.items())


def main(argv=None) -> int:
    ap = add_args(argparse.ArgumentParser(prog="python -m lidet_tools.train.finetune", description=__doc__,
                                          formatter_class=argparse.RawDescriptionHelpFormatter))
    a = ap.parse_args(argv)
    import shlex
    a.command = "python -m lidet_tools.train.finetune " + shlex.join(argv if argv is not None else sys.argv[1:])
    try:
        finetune(a)
        if a.install:
            install(a.out_weights, a.weights, a.family)
    except (FileNotFoundError, ValueError, RuntimeError) as e:
        print(f"finetune: {e}", file=sys.stderr)
        return 2
    return 0


def install(out: pathlib.Path, weights: pathlib.Path, family: str) -> list:
    """The fine-tuned pair of `family` in `out` becomes the one in `weights`: its ONNX and calibration files copied,
    then every C model of `weights` regenerated (lidet_codegen.regen, run from the folder above `weights` so the
    generated files name it as the committed ones do). Returns the files copied."""
    from lidet_codegen import regen
    names = [f"{k}_{family}{ext}" for k in ("cls", "box") for ext in (".onnx", ".calib.json")]
    missing = [n for n in names if not (out / n).exists()]
    if missing:
        raise FileNotFoundError(f"--install: {out} lacks {', '.join(missing)}")
    for n in names:
        shutil.copy(out / n, weights / n)
    cwd = os.getcwd()
    try:
        os.chdir(weights.resolve().parent)
        regen.emit_all(weights.resolve().name)
    finally:
        os.chdir(cwd)
    print(f"finetune: installed {', '.join(names)} into {weights} and regenerated its C models; rebuild "
          "(make build) to run them", file=sys.stderr)
    return names


if __name__ == "__main__":
    sys.exit(main())
