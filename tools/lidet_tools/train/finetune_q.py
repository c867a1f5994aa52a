# SPDX-License-Identifier: MIT
"""Quantization-aware fine-tuning of a trained classifier, so that its int8 build agrees with it (issue 16).

    python -m lidet_tools.train.finetune_q --onnx weights/cls_vlp16.onnx --data data/train/vlp16.npz \
        --out cls_vlp16_ft.onnx

Why: the int8 classifier (`python -m lidet_codegen emit --int8`) and the float one disagree on the class of a
proposal where the float network's two best logits lie closer than the int8 activations' error. Calibration
cannot remove that (docs/journal/fixed-point.md, "Per-channel activation ranges"): the VLP-16 classifier has 4.6 % of
its proposals within 0.2 nats of a tie, and its int8 build disagrees on about 1.4 % of held-out proposals.

What: a few epochs from the trained (folded) network, every layer a linear map + ReLU, with
- the network's own training loss (class-weighted cross-entropy on the ID proposals + `--lam` x the energy
  hinge on batches of 64 ID + 128 OOD proposals, margins from the starting network as `train_cls` takes them);
- `--consistency` x the squared difference of the centred logits of the float network and of the same network
  with int8 fake quantization (per-row symmetric int8 weights, the concatenation's input scales folded into the
  first head layer's columns as `quant.quantize` does; per-channel activation ranges at `--percentile` of the
  float activations of 4,000 training proposals, recomputed every epoch; rounding and clipping with
  straight-through gradients), which makes the float function flat where the int8 one differs;
- `--margin-weight` x mean(relu(`--margin` - (top logit - second logit))) over all proposals, which moves the
  float network's decisions away from ties (OOD proposals included: their class is arbitrary, but it is what
  the raw agreement counts and what decides which gamma gate 1 uses).
The points are rounded to the 4 mm steps the integer detector sees. Adam, cosine from `--lr`. The output is an
ONNX of the same contract (models.ClassifierNet, batch norms set to identity) with gamma recomputed on the
validation split as `train_cls` does (`--gamma-tpr` of each class's ID proposals: 95 % unless given).

Measured on the shipped VLP-16 classifier (docs/journal/fixed-point.md, "Quantization-aware fine-tuning"): int8
disagreements on 12,662 held-out simulated proposals 171 -> 69-77 (seeds 7, 8, 9; calibrate and quantize as
shipped, no refit), validation balanced accuracy 0.966-0.971 (0.971 before), FPR95 0.083-0.086 (0.091 before).
`make weights` runs it on the VLP-16 classifier after `train_cls` (lidet_tools.train.weights); then calibrate and
emit the output as any model.
"""
from __future__ import annotations

import argparse
import json
import math
import pathlib
import sys

import numpy as np
import torch
import torch.nn.functional as F

from . import common as C
from . import dataset as D
from . import metrics as MX
from . import models as M

GRID_M = 0.004  #: the integer detector's point step


class FoldedClassifier:
    """The folded classifier (lidet_codegen.emit.Model) as torch parameters, with a float and a fake-quantized
    forward (the int8 build of lidet_codegen.quant, up to its integer rounding of biases and requantization)."""

    def __init__(self, model):
        if model.kind != "classifier" or len(model.stages) != 1:
            raise ValueError(f"{model.name}: finetune_q takes a classifier")
        st = model.stages[0]
        if not st.pvle or st.use_onehot:
            raise ValueError(f"{model.name}: a classifier with PVLE and without a one-hot input is expected")
        self.model = model
        self.n_point, self.n_pvle, self.n_head = len(st.point), len(st.pvle), len(st.head)
        layers = st.point + st.pvle + st.head
        self.w = [torch.nn.Parameter(torch.tensor(np.asarray(l.w), dtype=torch.float32)) for l in layers]
        self.b = [torch.nn.Parameter(torch.tensor(np.asarray(l.b), dtype=torch.float32)) for l in layers]
        from lidet_codegen import quant as QU
        self.names = QU.layer_names(model)

    def params(self):
        return self.w + self.b

    @staticmethod
    def _ste_round(x):
        return x + (torch.round(x) - x).detach()

    def _wq(self, w, s_in=None):
        """Per-row symmetric int8 weights (of w scaled by the input's per-column scales, when given)."""
        ws = w if s_in is None else w * s_in[None, :]
        s = ws.detach().abs().amax(1, keepdim=True).clamp_min(1e-12) / 127.0
        q = torch.clamp(self._ste_round(ws / s), -127, 127) * s
        return q if s_in is None else q / s_in[None, :]

    def _aq(self, y, r):
        """A ReLU output on 256 steps of r / 255 per channel (zero point -128), saturating at r."""
        step = r / 255.0
        return torch.clamp(self._ste_round(torch.minimum(y, r) / step), 0, 255) * step

    def _act(self, y, k, ranges, trace):
        """Layer k's activation: fake-quantized with `ranges`; float without (then appended to `trace`, if given)."""
        if ranges is not None:
            return self._aq(y, ranges[self.names[k]])
        if trace is not None:
            trace.append(y)
        return y

    def forward(self, pts, vox, ranges=None, trace=None):
        """Logits of points (B, N, 3) in metres (model frame) and voxel bins (B, 3); int8 fake quantization
        with `ranges` (layer name -> per-channel range tensor), float without. `trace` (float only) collects
        every layer's output but the last, in `quant.layer_names` order (the last point layer's after the max)."""
        q = ranges is not None
        k, h = 0, pts
        for i in range(self.n_point):
            h = torch.relu(h @ (self._wq(self.w[k]) if q else self.w[k]).T + self.b[k])
            h = self._act(h.amax(1) if i + 1 == self.n_point else h, k, ranges, trace)
            k += 1
        v = vox
        for _ in range(self.n_pvle):
            v = self._act(torch.relu(v @ (self._wq(self.w[k]) if q else self.w[k]).T + self.b[k]), k, ranges, trace)
            k += 1
        x = torch.cat([h, v], 1)
        s_in = torch.cat([ranges[self.names[self.n_point - 1]], ranges[self.names[k - 1]]]) / 255.0 if q else None
        for i in range(self.n_head):
            x = x @ (self._wq(self.w[k], s_in) if q else self.w[k]).T + self.b[k]
            if i + 1 < self.n_head:
                x = self._act(torch.relu(x), k, ranges, trace)
                s_in = ranges[self.names[k]] / 255.0 if q else None
            k += 1
        return x

    @torch.no_grad()
    def ranges(self, pts, vox, percentile: float) -> dict:
        """Per-channel activation ranges: `percentile` of each layer's float output (the last point layer's
        after the max over the points), as `quant.activation_ranges` takes them for classifiers."""
        outs = []
        self.forward(pts, vox, trace=outs)
        return {nm: torch.tensor(np.maximum(np.percentile(t.reshape(-1, t.shape[-1]).numpy(), percentile, axis=0),
                                            1e-6), dtype=torch.float32) for nm, t in zip(self.names, outs)}

    def to_net(self) -> M.ClassifierNet:
        """models.ClassifierNet with these weights and identity batch norms (the export contract)."""
        st = self.model.stages[0]
        net = M.ClassifierNet(point=[l.n_out for l in st.point], pvle=[l.n_out for l in st.pvle],
                              head=[l.n_out for l in st.head[:-1]], n_classes=st.head[-1].n_out, use_pvle=True)
        order = list(net.point) + list(net.pvle) + list(net.head)  # the folded layers' order
        lin = [m for m in order if isinstance(m, (torch.nn.Conv1d, torch.nn.Linear))]
        bns = [m for m in order if isinstance(m, torch.nn.BatchNorm1d)]
        with torch.no_grad():
            for m, w, b in zip(lin, self.w, self.b):
                m.weight.copy_(w.detach().reshape(m.weight.shape))
                m.bias.copy_(b.detach())
            for bn in bns:
                bn.running_mean.zero_()
                bn.running_var.fill_(1.0)
                bn.weight.fill_(math.sqrt(1.0 + bn.eps))
                bn.bias.zero_()
        return net.eval()


def _logits(fc: FoldedClassifier, d: dict, ranges=None, bs: int = 2048, grid: bool = True) -> np.ndarray:
    out = []
    with torch.no_grad():
        for i in range(0, len(d["label"]), bs):
            idx = np.arange(i, min(i + bs, len(d["label"])))
            p, v = C.tensors(d, idx, "cpu")
            out.append(fc.forward(torch.round(p / GRID_M) * GRID_M if grid else p, v, ranges).numpy())
    return np.concatenate(out) if out else np.zeros((0, M.N_CLASSES), np.float32)


def _figures(fc, d, ranges) -> dict:
    lf, lq = _logits(fc, d), _logits(fc, d, ranges)
    res = MX.cls_figures(lf, d["label"])
    bal = float(np.mean([res["acc"][c]["acc"] for c in M.CLASSES if res["acc"][c]["n"] > 0]))
    return dict(bal_acc=bal, fpr95=res["gate1"]["fpr95"], fake_q_disagree=float(np.mean(lf.argmax(1) != lq.argmax(1))))


def add_args(ap):
    ap.add_argument("--onnx", type=pathlib.Path, required=True, help="the trained classifier (lidet ONNX contract)")
    ap.add_argument("--data", type=pathlib.Path, required=True, help="its proposal dataset (lidet_tools.train.dataset)")
    ap.add_argument("--out", type=pathlib.Path, required=True, help="the fine-tuned classifier's ONNX")
    ap.add_argument("--epochs", type=int, default=6)
    ap.add_argument("--lr", type=float, default=1e-4)
    ap.add_argument("--batch", type=int, default=64)
    ap.add_argument("--consistency", type=float, default=1.0, help="weight of the float / fake-int8 logit term")
    ap.add_argument("--margin", type=float, default=0.5, help="top-2 logit margin (nats) the margin term asks for")
    ap.add_argument("--margin-weight", type=float, default=1.0)
    ap.add_argument("--lam", type=float, default=0.3, help="weight of the energy hinge (the network's training value)")
    ap.add_argument("--margins", default=None, help="m_in,m_out of the energy hinge: the ones the network was "
                    "trained with (weights/MODEL_CARD.md); default: from the network, as train_cls takes them")
    ap.add_argument("--min-gap", type=float, default=3.0, help="least m_out - m_in, as train_cls")
    ap.add_argument("--percentile", type=float, default=99.9, help="activation ranges (quant.CALIB_RULE's)")
    ap.add_argument("--gamma-tpr", default="0.95",
                    help="share of each class's validation ID proposals gate 1 keeps (train_cls --gamma-tpr: one "
                         "share, or three for Car, Cyclist, Pedestrian); give the network's own training value")
    ap.add_argument("--seed", type=int, default=7)
    ap.add_argument("--threads", type=int, default=1)
    ap.add_argument("--checkpoint", type=pathlib.Path, default=None,
                    help="the network's checkpoint (train_cls --out): its margins are used unless --margins is given, "
                    "and it is rewritten with the fine-tuned weights, its training history kept (make weights)")
    ap.add_argument("--card", type=pathlib.Path, default=None,
                    help="a model card (weights/MODEL_CARD.md) whose row of --out gets the new gamma and whose "
                    "section 'Int8 fine-tuning' gets this run (what make weights writes after the same step)")
    return ap


def finetune(a) -> dict:
    from lidet_codegen.emit import load
    from . import train_cls as TC
    from .export import export_onnx
    C.setup(a.seed, a.threads)
    # torch's deterministic kernels made an epoch 25x slower here (50 s against 2 s on the VLP-16 set); the CPU
    # kernels this loop uses give the same result run to run with one thread (tests/python/test_train_smoke.py)
    torch.use_deterministic_algorithms(False)
    fc = FoldedClassifier(load(a.onnx, a.onnx.stem))
    data = D.load(a.data)
    tr, va = C.split(data, 0), C.split(data, 1)
    if int(data["points"].shape[1]) != fc.model.n_points:
        raise ValueError(f"{a.data}: {data['points'].shape[1]} points per proposal, the model takes {fc.model.n_points}")
    tr_id, tr_ood = np.nonzero(tr["label"] >= 0)[0], np.nonzero(tr["label"] < 0)[0]
    if len(tr_id) < a.batch or len(tr_ood) == 0 or len(va["label"]) == 0:
        raise ValueError(f"{a.data}: too few proposals ({len(tr_id)} training ID, {len(tr_ood)} OOD, "
                         f"{len(va['label'])} validation)")
    counts = np.bincount(tr["label"][tr_id], minlength=M.N_CLASSES).astype(np.float64)
    cw = torch.tensor(np.sqrt(counts.sum() / (M.N_CLASSES * np.maximum(counts, 1))), dtype=torch.float32)
    rng = np.random.default_rng(a.seed)
    calib = rng.choice(len(tr["label"]), min(4000, len(tr["label"])), replace=False)

    def ranges():
        p, v = C.tensors(tr, calib, "cpu")
        return fc.ranges(torch.round(p / GRID_M) * GRID_M, v, a.percentile)

    # the margins of the energy hinge: the network's own (weights/MODEL_CARD.md, the checkpoint's meta), else as
    # train_cls takes them, from the network it starts from
    src = None
    if a.checkpoint is not None and a.checkpoint.exists():
        src = torch.load(a.checkpoint, map_location="cpu", weights_only=False)
    if a.margins:
        m_in, m_out = (float(v) for v in a.margins.split(","))
    elif src is not None and (src["meta"].get("margins") or {}).get("m_in") is not None:
        m_in, m_out = src["meta"]["margins"]["m_in"], src["meta"]["margins"]["m_out"]
    else:
        e = MX.energy_np(_logits(fc, tr))
        m_in = float(e[tr["label"] >= 0].mean())
        m_out = max(float(e[tr["label"] < 0].mean()), m_in + a.min_gap)
    before = _figures(fc, va, ranges())
    opt = torch.optim.Adam(fc.params(), lr=a.lr)
    history = []
    for ep in range(a.epochs):
        R = ranges()
        lr = 1e-6 + 0.5 * (a.lr - 1e-6) * (1 + math.cos(math.pi * ep / max(a.epochs, 1)))
        for g in opt.param_groups:
            g["lr"] = lr
        tot = np.zeros(3)
        nb = 0
        for bi in C.batches(rng, len(tr_id), a.batch):
            idx = tr_id[bi]
            p, _ = C.augment(rng, tr["points"][idx])
            oi = tr_ood[rng.integers(0, len(tr_ood), 2 * a.batch)]
            po, _ = C.augment(rng, tr["points"][oi])
            pts, vox = C.tensors(tr, np.concatenate([idx, oi]), "cpu", np.concatenate([p, po]))
            pts = torch.round(pts / GRID_M) * GRID_M
            y = torch.from_numpy(tr["label"][idx].astype(np.int64))
            lf, lq = fc.forward(pts, vox), fc.forward(pts, vox, R)
            en = C.energy(lf)
            task = F.cross_entropy(lf[:len(idx)], y, weight=cw) + a.lam * C.hinge(en[:len(idx)], en[len(idx):], m_in, m_out)
            dl = (lq - lq.mean(1, keepdim=True)) - (lf - lf.mean(1, keepdim=True))
            cons = (dl ** 2).sum(1).mean()
            top2 = lf.topk(2, 1).values
            marg = torch.relu(a.margin - (top2[:, 0] - top2[:, 1])).mean()
            loss = task + a.consistency * cons + a.margin_weight * marg
            opt.zero_grad()
            loss.backward()
            opt.step()
            tot += [float(task.detach()), float(cons.detach()), float(marg.detach())]
            nb += 1
        h = dict(epoch=ep + 1, lr=lr, task=tot[0] / nb, consistency=tot[1] / nb, margin=tot[2] / nb)
        history.append(h)
        print(f"finetune_q epoch {ep + 1}: task {h['task']:.4f} consistency {h['consistency']:.4f} "
              f"margin {h['margin']:.4f}", file=sys.stderr, flush=True)
    after = _figures(fc, va, ranges())
    lg = _logits(fc, va, grid=False)  # the points as train_cls takes its gamma from them
    idm = va["label"] >= 0
    tprs = TC.gamma_tprs(a.gamma_tpr)
    gamma = C.per_class_gamma(MX.energy_np(lg)[idm], lg.argmax(1)[idm], tprs)
    net = fc.to_net()
    meta = dict(n_points=fc.model.n_points, gamma=gamma, gamma_tpr=tprs, energy_T=1.0, trained=1,
                sensor=data["meta"].get("sensor", ""), data=data["meta"].get("command", str(a.data)),
                command=getattr(a, "command", None) or "python -m lidet_tools.train.finetune_q",
                z_origin=data["meta"].get("z_origin", "mean"))
    res = dict(before=before, after=after, gamma=gamma, margins=dict(m_in=m_in, m_out=m_out), history=history)
    export_onnx(net, dict(kind="classifier", meta=meta), a.out)
    if a.checkpoint is not None:
        # the training's record kept (margins, best epoch, history, seconds), this step added
        keep = dict(src["meta"]) if src is not None else dict(margins=dict(m_in=m_in, m_out=m_out), best_epoch=0)
        keep.update(gamma=gamma, gamma_tpr=tprs,
                    finetune=dict(command=meta["command"], epochs=a.epochs, before=before, after=after))
        C.save_atomic(dict(kind="classifier", cfg=dict(net.cfg), state_dict=net.state_dict(), meta=keep), a.checkpoint)
    if a.card is not None:
        update_card(a.card, a.out.name, gamma, meta["command"], before, after)
    return res


CARD_SECTION = "## Int8 fine-tuning"


def card_lines(name: str, command: str, before: dict, after: dict) -> list:
    """The model card's lines on one fine-tuned classifier (weights.model_card and --card write the same)."""
    return [f"`{name}` was fine-tuned for the int8 build after its training (`lidet_tools.train.finetune_q`; "
            "docs/FIXED_POINT.md, \"Quantization-aware fine-tuning\"):", "", f"    {command}", "",
            "| validation split | balanced accuracy | FPR95 (gate 1) | argmax float vs fake-int8 differs |",
            "|---|---:|---:|---:|",
            f"| before | {before['bal_acc']:.3f} | {before['fpr95']:.3f} | {100 * before['fake_q_disagree']:.2f} % |",
            f"| after | {after['bal_acc']:.3f} | {after['fpr95']:.3f} | {100 * after['fake_q_disagree']:.2f} % |", ""]


def update_card(card: pathlib.Path, name: str, gamma, command: str, before: dict, after: dict) -> None:
    """The row of `name` in the card's file table gets the new gamma; the section CARD_SECTION gets this run's
    lines (added before "## Known limits", or replacing the ones of the same file)."""
    lines = card.read_text().split("\n")
    hit = False
    for i, l in enumerate(lines):
        if l.startswith(f"| `{name}` |"):
            cells = l.split(" | ")
            cells[7] = ", ".join(f"{g:.3f}" for g in gamma)
            lines[i] = " | ".join(cells)
            hit = True
    if not hit:
        raise ValueError(f"{card}: no row for {name}")
    new = card_lines(name, command, before, after)
    if CARD_SECTION not in lines:
        at = lines.index("## Known limits") if "## Known limits" in lines else len(lines)
        lines[at:at] = [CARD_SECTION, ""] + new
    else:
        start = lines.index(CARD_SECTION) + 2
        end = start
        while end < len(lines) and not lines[end].startswith("## "):
            end += 1
        # drop this file's previous lines (card_lines writes a fixed number of them)
        body = lines[start:end]
        at = next((i for i, l in enumerate(body) if l.startswith(f"`{name}` was fine-tuned")), None)
        if at is not None:
            del body[at:at + len(new)]
        lines[start:end] = body + new
    card.write_text("\n".join(lines))


def main(argv=None) -> int:
    ap = add_args(argparse.ArgumentParser(prog="python -m lidet_tools.train.finetune_q", description=__doc__,
                                          formatter_class=argparse.RawDescriptionHelpFormatter))
    a = ap.parse_args(argv)
    a.command = "python -m lidet_tools.train.finetune_q " + " ".join(argv if argv is not None else sys.argv[1:])
    try:
        res = finetune(a)
    except (FileNotFoundError, ValueError) as e:
        print(f"finetune_q: {e}", file=sys.stderr)
        return 2
    print(json.dumps(res, default=float))
    return 0


if __name__ == "__main__":
    sys.exit(main())
