# SPDX-License-Identifier: MIT
"""What the two trainers share: seeds and threads, augmentation, energies, OOD metrics, checkpoints.

Augmentation (training batches only, model frame; `augment`):
* mirror about the model frame's x axis with probability 0.5 (y -> -y; a box's centre y and heading
  change sign). The mean stays on +x, so the PVLE voxel is unchanged;
* rotation about z through the mean by U(-5, 5) deg (box centre and heading follow), so the nets do
  not rely on the exact frustum rotation;
* translation of the points by U(-0.1, 0.1) m in x, y and U(-0.05, 0.05) m in z (the box centre
  follows): the authors used +-0.2 / +-0.1 m; lidet's proposals are centred on the exact cluster mean,
  so a smaller shift suffices to cover the mean's shift when points drop out;
* point jitter N(0, 0.01 m) clipped at 0.03 m (range noise);
* point dropout by resampling: keep a random 60-100 % of the 64 points and draw the 64 again from them
  with replacement, as the C resampling does for a sparse cluster.
* optional (`train_box --occlusion P`, default off): in a share P of the proposals, a part hidden as real
  scans hide it (`occlude`), before the dropout.
"""
from __future__ import annotations

import json
import math
import os
import pathlib

import numpy as np
import torch

from . import models as M


def setup(seed: int, threads: int) -> None:
    """Fixed seeds, deterministic kernels, and the thread count (1 on a shared 2-core machine)."""
    torch.manual_seed(seed)
    np.random.seed(seed)
    torch.set_num_threads(max(1, int(threads)))
    torch.use_deterministic_algorithms(True, warn_only=True)


def device(name: str) -> torch.device:
    if name == "cuda" and not torch.cuda.is_available():
        raise RuntimeError("--device cuda asked for, but torch sees no CUDA device")
    return torch.device(name)


def _keep_recentred(rng: np.random.Generator, pts: np.ndarray, box: np.ndarray | None, i: int, keep) -> None:
    """Proposal i of pts (B, N, 3) becomes N points drawn from its points `keep`, re-centred on their own mean (the
    C proposal is centred on the mean of what it holds); its box target moves with them."""
    q = pts[i][keep[rng.integers(0, len(keep), pts.shape[1])]]
    c = q.mean(0)
    pts[i] = q - c
    if box is not None:
        box[i, 0:3] -= c


def occlude(rng: np.random.Generator, pts: np.ndarray, box: np.ndarray | None, p: float) -> None:
    """In place, with probability p per proposal: hide a part of it as real scans do, then re-centre.
    One of three, equally likely: a lateral band (an occluder in front hides a range of azimuths: in the
    model frame, whose x axis is the ray to the mean, the points on one side of y = t), the lower part
    (a kerb, a bonnet or a low wall in front: z below t) or a horizontal band in the upper half (windows,
    which return little on real cars). t hides 15-45 % of the points; at least 8 stay. The C proposal is
    centred on the mean of the points it holds, so the kept points are re-centred on their own mean and
    the box target moves with them (the rotation about the new mean's azimuth is left to the +-5 deg
    rotation of `augment`)."""
    B = pts.shape[0]
    hit = np.nonzero(rng.random(B) < p)[0]
    kind = rng.integers(0, 3, len(hit))
    frac = rng.uniform(0.15, 0.45, len(hit))
    side = rng.random(len(hit)) < 0.5
    for i, kd, f, sd in zip(hit, kind, frac, side):
        q = pts[i]
        if kd == 0:
            v = q[:, 1] if sd else -q[:, 1]
            hide = v < np.quantile(v, f)
        elif kd == 1:
            hide = q[:, 2] < np.quantile(q[:, 2], f)
        else:
            lo = np.quantile(q[:, 2], 0.5 + 0.1 * sd)
            hide = (q[:, 2] >= lo) & (q[:, 2] < np.quantile(q[:, 2], min(1.0, 0.5 + 0.1 * sd + f)))
        keep = np.nonzero(~hide)[0]
        if len(keep) < 8:
            continue
        _keep_recentred(rng, pts, box, i, keep)


def occlude_from_above(rng: np.random.Generator, pts: np.ndarray, box: np.ndarray | None, p: float,
                       hide=(0.35, 0.7)) -> None:
    """In place, with probability p per proposal: keep only the part above a cut, as a person or cyclist standing
    behind a parked car is seen over its roof (the real frames' people behind parked cars are seen from 0.8-1.2 m
    up: docs/journal/real-streets.md). The cut hides a share drawn from `hide` of the proposal's z extent, far more
    than `occlude`'s lower part (15-45 % of the points); at least 8 points stay, else the proposal is left as it
    was. The kept points are resampled to N and re-centred on their own mean, the box target moving with them."""
    B = pts.shape[0]
    hit = np.nonzero(rng.random(B) < p)[0]
    frac = rng.uniform(hide[0], hide[1], len(hit))
    for i, f in zip(hit, frac):
        q = pts[i]
        z0, z1 = float(q[:, 2].min()), float(q[:, 2].max())
        keep = np.nonzero(q[:, 2] >= z0 + f * (z1 - z0))[0]
        if len(np.unique(keep)) < 8 or len(np.unique(q[keep], axis=0)) < 8:
            continue
        _keep_recentred(rng, pts, box, i, keep)


def ground_cut(rng: np.random.Generator, pts: np.ndarray, box: np.ndarray | None, p: float, max_m: float) -> None:
    """In place, with probability p per proposal: drop the points within h of its lowest point, h drawn from [0,
    max_m] metres, as a real ground stage eats a car's sills and a person's feet (on the real training frames a close
    car's cluster starts 0.35 m above its box bottom, a simulated one's 0.22 m: docs/journal/real-streets.md). At
    least 8 distinct points stay, else the proposal is left as it was. The kept points are resampled to N and
    re-centred on their own mean, the box target moving with them (as `occlude`)."""
    B = pts.shape[0]
    hit = np.nonzero(rng.random(B) < p)[0]
    cut = rng.uniform(0.0, max_m, len(hit))
    for i, h in zip(hit, cut):
        q = pts[i]
        keep = np.nonzero(q[:, 2] >= float(q[:, 2].min()) + h)[0]
        if len(np.unique(q[keep], axis=0)) < 8:
            continue
        _keep_recentred(rng, pts, box, i, keep)


#: the trainers' augmentation of simulated proposals (augment's defaults); ground_cut: (probability, max metres)
#: of `ground_cut`, (0, 0) draws nothing (the batches of earlier models)
SIM_AUG = dict(keep=(0.6, 1.0), min_keep=4, rot_deg=5.0, scale=None, shift_xy=0.1, shift_z=0.05, jitter=0.01,
               jitter_clip=0.03, ground_cut=(0.0, 0.0))


def augment(rng: np.random.Generator, pts: np.ndarray, box: np.ndarray | None = None, occlusion: float = 0.0,
            **params):
    """Augment a batch: pts (B, N, 3) model frame, box (B, 7) model-frame targets (or None). Copies.
    occlusion: the probability of `occlude` per proposal (0: no draw, the batches of earlier models).
    params: SIM_AUG's settings to change (keep: share of the points kept, min_keep, rot_deg: rotation about z,
    scale: (lo, hi) about the mean with the box, or None for no draw, shift_xy / shift_z, jitter / jitter_clip,
    ground_cut: (probability, max metres) of `ground_cut`)."""
    unknown = set(params) - set(SIM_AUG)
    if unknown:
        raise TypeError(f"unknown augmentation setting(s) {sorted(unknown)}")
    g = {**SIM_AUG, **params}
    pts = np.array(pts, np.float32, copy=True)
    B, N, _ = pts.shape
    box = None if box is None else np.array(box, np.float32, copy=True)
    if occlusion > 0.0:
        occlude(rng, pts, box, occlusion)
    gc = g["ground_cut"]
    if not (isinstance(gc, (tuple, list)) and len(gc) == 2 and 0.0 <= gc[0] <= 1.0 and 0.0 <= gc[1] <= 1.0):
        raise ValueError(f"ground_cut: (probability in [0, 1], max metres in [0, 1]), got {gc!r}")
    gc_p, gc_m = gc
    if gc_p > 0.0:
        ground_cut(rng, pts, box, float(gc_p), float(gc_m))
    # dropout by resampling
    keep = rng.uniform(*g["keep"], B)
    for i in range(B):
        k = max(g["min_keep"], int(round(keep[i] * N)))
        src = rng.permutation(N)[:k]
        pts[i] = pts[i, src[rng.integers(0, k, N)]]
    # mirror
    flip = rng.random(B) < 0.5
    pts[flip, :, 1] *= -1
    if box is not None:
        box[flip, 1] *= -1
        box[flip, 6] *= -1
    # rotation about z through the mean
    a = rng.uniform(-math.radians(g["rot_deg"]), math.radians(g["rot_deg"]), B).astype(np.float32)
    c, s = np.cos(a)[:, None], np.sin(a)[:, None]
    x, y = pts[..., 0].copy(), pts[..., 1].copy()
    pts[..., 0], pts[..., 1] = c * x - s * y, s * x + c * y
    sc = None if g["scale"] is None else rng.uniform(*g["scale"], B).astype(np.float32)
    if sc is not None:
        pts *= sc[:, None, None]
    if box is not None:
        bx, by = box[:, 0].copy(), box[:, 1].copy()
        box[:, 0], box[:, 1] = c[:, 0] * bx - s[:, 0] * by, s[:, 0] * bx + c[:, 0] * by
        box[:, 6] += a
        if sc is not None:
            box[:, 0:6] *= sc[:, None]
    # translation
    t = np.concatenate([rng.uniform(-g["shift_xy"], g["shift_xy"], (B, 2)),
                        rng.uniform(-g["shift_z"], g["shift_z"], (B, 1))], 1).astype(np.float32)
    pts += t[:, None, :]
    if box is not None:
        box[:, 0:3] += t
    # jitter
    pts += np.clip(rng.normal(0, g["jitter"], pts.shape), -g["jitter_clip"], g["jitter_clip"]).astype(np.float32)
    return pts.astype(np.float32), (None if box is None else box.astype(np.float32))


def json_object_arg(text: str, flag: str, keys) -> dict:
    """A command-line option holding a JSON object whose keys are among `keys` ({} when empty); ValueError naming
    the option otherwise (train_cls --aug, train_box --widths)."""
    if not text:
        return {}
    try:
        d = json.loads(text)
    except json.JSONDecodeError as e:
        raise ValueError(f"{flag}: not JSON ({e})") from None
    if not isinstance(d, dict) or set(d) - set(keys):
        raise ValueError(f"{flag}: a JSON object with keys among {tuple(keys)}, got {text!r}")
    return d


def energy(logits: torch.Tensor, T: float = 1.0) -> torch.Tensor:
    """E = -T logsumexp(logits / T) over the last axis."""
    return -T * torch.logsumexp(logits / T, dim=-1)


def box_energy(box_out: torch.Tensor, T: float = 1.0) -> torch.Tensor:
    """Gate-2 energy of box-net outputs (B, 39): E(heading scores) + E(size scores)."""
    h = box_out[:, 3:3 + M.N_HEADING_BINS]
    o = 3 + 2 * M.N_HEADING_BINS
    s = box_out[:, o:o + M.N_SIZE_CLUSTERS]
    return energy(h, T) + energy(s, T)


def hinge(e_in: torch.Tensor, e_out: torch.Tensor, m_in: float, m_out: float) -> torch.Tensor:
    """energy_ood's squared hinge: mean(relu(E_in - m_in)^2) + mean(relu(m_out - E_out)^2)."""
    return (torch.relu(e_in - m_in) ** 2).mean() + (torch.relu(m_out - e_out) ** 2).mean()


def auroc(e_id: np.ndarray, e_ood: np.ndarray) -> float:
    """AUROC of ID (positive) vs OOD with score -energy (ties count half)."""
    s = np.concatenate([-np.asarray(e_id, np.float64), -np.asarray(e_ood, np.float64)])
    y = np.concatenate([np.ones(len(e_id)), np.zeros(len(e_ood))])
    if len(e_id) == 0 or len(e_ood) == 0:
        return float("nan")
    order = np.argsort(s, kind="mergesort")
    ranks = np.empty(len(s))
    ss = s[order]
    # average ranks of ties
    i = 0
    while i < len(ss):
        j = i
        while j + 1 < len(ss) and ss[j + 1] == ss[i]:
            j += 1
        ranks[order[i:j + 1]] = 0.5 * (i + j) + 1
        i = j + 1
    n1, n0 = len(e_id), len(e_ood)
    return float((ranks[y == 1].sum() - n1 * (n1 + 1) / 2) / (n1 * n0))


def threshold_at_tpr(e_id: np.ndarray, tpr: float = 0.95) -> float:
    """The gate threshold that keeps at least `tpr` of the ID energies: the gate keeps E < gamma, so
    gamma is the next float32 above the ceil(tpr n)-th smallest ID energy."""
    e = np.sort(np.asarray(e_id, np.float64))
    if len(e) == 0:
        return float("nan")
    k = int(math.ceil(tpr * len(e))) - 1
    k = min(max(k, 0), len(e) - 1)
    return float(np.nextafter(np.float32(e[k]), np.float32(np.inf)))


def fpr_at_tpr(e_id: np.ndarray, e_ood: np.ndarray, tpr: float = 0.95) -> float:
    """Share of OOD kept (E < gamma) at the gamma that keeps `tpr` of the ID samples."""
    if len(e_ood) == 0 or len(e_id) == 0:
        return float("nan")
    g = threshold_at_tpr(e_id, tpr)
    return float(np.mean(np.asarray(e_ood) < g))


def per_class_gamma(e: np.ndarray, cls: np.ndarray, tpr=0.95, min_n: int = 20) -> list:
    """gamma per class at `tpr` ID recall (one share, or one per class); a class with fewer than min_n samples gets
    the pooled value at its share."""
    tprs = [float(tpr)] * M.N_CLASSES if np.isscalar(tpr) else [float(t) for t in tpr]
    out = []
    for c in range(M.N_CLASSES):
        m = cls == c
        out.append(threshold_at_tpr(e[m], tprs[c]) if m.sum() >= min_n else threshold_at_tpr(e, tprs[c]))
    return out


def save_atomic(obj, path) -> None:
    path = pathlib.Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(path.name + ".tmp")
    torch.save(obj, tmp)
    os.replace(tmp, path)


def batches(rng: np.random.Generator, n: int, bs: int, drop_last: bool = True):
    idx = rng.permutation(n)
    stop = n - (n % bs) if (drop_last and n >= bs) else n
    for i in range(0, stop, bs):
        yield idx[i:i + bs]


def tensors(d: dict, idx, dev, pts=None):
    """points, voxel (float32) tensors of rows idx (pts overrides the points, e.g. augmented)."""
    p = d["points"][idx] if pts is None else pts
    return (torch.from_numpy(np.ascontiguousarray(p, np.float32)).to(dev),
            torch.from_numpy(d["voxel"][idx].astype(np.float32)).to(dev))


def split(d: dict, s: int) -> dict:
    """Rows of split s (0 train, 1 val, 2 test) as a new dict of arrays."""
    m = d["split"] == s
    return {k: (v[m] if isinstance(v, np.ndarray) and v.shape[:1] == m.shape else v) for k, v in d.items()}


def progress(it, enabled: bool, **kw):
    if not enabled:
        return it
    from tqdm import tqdm
    return tqdm(it, **kw)


# --- several processes (torchrun) -----------------------------------------------------------------
# Without the launcher's environment (WORLD_SIZE unset or 1) `dist_from_env` returns None and the
# trainers run their single-process code unchanged (same numerics, same RNG use).

class Dist:
    """One process of a `torchrun` job: rank, world size, device, and the few collectives the
    trainers need. BatchNorm keeps per-rank statistics (no SyncBatchNorm): each rank normalises its own
    batch of `--batch` proposals, as one process does, and the running statistics are averaged over the
    ranks after every epoch (`sync`), so validation, checkpoints and ONNX see one model."""

    def __init__(self, rank: int, world: int, local_rank: int, dev: torch.device, backend: str):
        self.rank, self.world, self.local_rank, self.dev, self.backend = rank, world, local_rank, dev, backend

    @property
    def main(self) -> bool:
        return self.rank == 0

    def wrap(self, model):
        from torch.nn.parallel import DistributedDataParallel as DDP
        ids = [self.dev.index] if self.dev.type == "cuda" else None
        # buffers (BN running statistics) stay per rank during the epoch; `sync` averages them. Newer
        # torch names this forward_sync_buffers (it still syncs once at init: every rank starts equal)
        import inspect
        kw = ("forward_sync_buffers" if "forward_sync_buffers" in inspect.signature(DDP.__init__).parameters
              else "broadcast_buffers")
        return DDP(model, device_ids=ids, **{kw: False})

    def shard(self, n: int, epoch: int, seed: int, drop_last: bool = True) -> np.ndarray:
        """This rank's indices into range(n) for `epoch` (DistributedSampler, shuffled, set_epoch)."""
        from torch.utils.data.distributed import DistributedSampler
        s = DistributedSampler(range(n), num_replicas=self.world, rank=self.rank, shuffle=True, seed=seed,
                               drop_last=drop_last)
        s.set_epoch(epoch)
        return np.asarray(list(s), np.int64)

    def sum(self, values):
        """All-reduced sums of a few floats."""
        import torch.distributed as dist
        t = torch.tensor([float(v) for v in values], dtype=torch.float64, device=self.dev)
        dist.all_reduce(t)
        return [float(v) for v in t.cpu()]

    def bcast(self, obj):
        """rank 0's Python object on every rank."""
        import torch.distributed as dist
        box = [obj]
        dist.broadcast_object_list(box, src=0)
        return box[0]

    def sync(self, model) -> None:
        """Average the floating-point buffers (BN running mean / var) over the ranks, then give every
        rank rank 0's parameters and buffers (guards against any drift, e.g. after loading a state)."""
        import torch.distributed as dist
        with torch.no_grad():
            for b in model.buffers():
                if b.is_floating_point():
                    dist.all_reduce(b)
                    b /= self.world
            for t in list(model.parameters()) + list(model.buffers()):
                dist.broadcast(t.data, src=0)

    def barrier(self) -> None:
        import torch.distributed as dist
        if self.dev.type == "cuda":
            dist.barrier(device_ids=[self.dev.index])
        else:
            dist.barrier()


def dist_from_env(device_name: str) -> Dist | None:
    """Initialise torch.distributed when started by torchrun (WORLD_SIZE > 1): nccl on CUDA (one GPU per
    process, cuda:LOCAL_RANK), gloo on CPU. None otherwise."""
    world = int(os.environ.get("WORLD_SIZE", "1"))
    if world <= 1:
        return None
    import torch.distributed as dist
    rank = int(os.environ["RANK"])
    local = int(os.environ.get("LOCAL_RANK", "0"))
    if device_name.startswith("cuda"):
        if not torch.cuda.is_available():
            raise RuntimeError("--device cuda asked for, but torch sees no CUDA device")
        torch.cuda.set_device(local)
        dev, backend = torch.device("cuda", local), "nccl"
    else:
        dev, backend = torch.device(device_name), "gloo"
    if not dist.is_initialized():
        dist.init_process_group(backend=backend)
    return Dist(rank, world, local, dev, backend)


def dist_close() -> None:
    """Destroy the process group, if one was initialised."""
    import torch.distributed as dist
    if dist.is_available() and dist.is_initialized():
        dist.destroy_process_group()


def dump_shards(dd: Dist | None, name: str, shards: list) -> None:
    """Debug: with LIDET_TRAIN_SHARD_DUMP=DIR, every rank writes DIR/<name>_rank<r>.json with the
    training rows (ID, OOD) it was given, per epoch (the test checks that the ranks' shards differ)."""
    out = os.environ.get("LIDET_TRAIN_SHARD_DUMP")
    if dd is None or not out:
        return
    import json
    p = pathlib.Path(out)
    p.mkdir(parents=True, exist_ok=True)
    (p / f"{name}_rank{dd.rank}.json").write_text(json.dumps(dict(rank=dd.rank, world=dd.world, epochs=shards)))


def write_outputs(ck: dict, model, a, main: bool, dd) -> dict:
    """The trainers' last step: checkpoint and ONNX from rank 0 only, then a barrier so that no rank leaves
    before rank 0 has written its files. Returns ck."""
    if main:
        save_atomic(ck, a.out)
        if a.onnx:
            from .export import export_onnx
            export_onnx(model.cpu(), ck, a.onnx)
    if dd:
        dd.barrier()
    return ck


def run_cli(module: str, add_args, train, doc: str, argv=None) -> int:
    """`python -m lidet_tools.train.<module>`: parse, train, close the process group; rank 0 prints the
    result line (gamma, margins, best epoch) as JSON."""
    import argparse
    import json
    import sys
    ap = add_args(argparse.ArgumentParser(prog=f"python -m lidet_tools.train.{module}", description=doc,
                                          formatter_class=argparse.RawDescriptionHelpFormatter))
    a = ap.parse_args(argv)
    a.command = f"python -m lidet_tools.train.{module} " + " ".join(argv if argv is not None else sys.argv[1:])
    try:
        ck = train(a)
    except (FileNotFoundError, ValueError, RuntimeError) as e:
        print(f"{module}: {e}", file=sys.stderr)
        return 2
    finally:
        dist_close()
    if int(os.environ.get("RANK", "0")) != 0:
        return 0
    print(json.dumps(dict(gamma=ck["meta"]["gamma"], margins=ck["meta"]["margins"], best_epoch=ck["meta"]["best_epoch"])))
    return 0
