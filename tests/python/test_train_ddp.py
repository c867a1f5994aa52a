# SPDX-License-Identifier: MIT
"""Several-process training through PyTorch's own launcher: a real 2-process CPU (gloo) run of each
trainer under `python -m torch.distributed.run --nproc_per_node 2` on two simulated scans, one epoch of
each phase. Checks: exit 0, one checkpoint + one ONNX (rank 0 only), the ranks trained on different
shards of the ID and OOD rows (LIDET_TRAIN_SHARD_DUMP), and the ONNX agrees with the checkpoint."""
import json
import os
import subprocess
import sys

import numpy as np
import pytest

torch = pytest.importorskip("torch")
ort = pytest.importorskip("onnxruntime")
if not torch.distributed.is_available():
    pytest.skip("torch.distributed not available", allow_module_level=True)

from lidet_tools.train import dataset as D  # noqa: E402


@pytest.fixture(scope="module")
def tiny(tmp_path_factory, need_lib):
    """Two hdl64 scans: scan 0 is the training split, scan 1 validation (as test_train_smoke)."""
    d = D.concat([D._job(("sim", s, 1, s, None), "hdl64", dict(D.DEFAULTS)) for s in range(2)])
    p = tmp_path_factory.mktemp("tiny_ddp") / "tiny.npz"
    np.savez_compressed(p, meta=json.dumps({"sensor": "hdl64", "command": "test"}), **d)
    return p, d


def _torchrun(module, args, tmp_path):
    env = dict(os.environ, OMP_NUM_THREADS="1", LIDET_TRAIN_SHARD_DUMP=str(tmp_path / "shards"))
    for k in ("WORLD_SIZE", "RANK", "LOCAL_RANK", "MASTER_ADDR", "MASTER_PORT"):
        env.pop(k, None)
    cmd = [sys.executable, "-m", "torch.distributed.run", "--standalone", "--nproc_per_node", "2",
           "-m", module, *args, "--device", "cpu", "--no-progress"]
    return subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=240)


@pytest.mark.parametrize("kind", ["cls", "box"])
def test_torchrun_two_ranks_gloo(tiny, tmp_path, kind):
    path, d = tiny
    ep = ["--epochs-ce", "1"] if kind == "cls" else ["--epochs-box", "1"]
    r = _torchrun(f"lidet_tools.train.train_{kind}",
                  ["--data", str(path), "--work", str(tmp_path / "w"), "--out", str(tmp_path / "o" / f"{kind}.pt"),
                   "--onnx", str(tmp_path / "o" / f"{kind}.onnx"), *ep, "--epochs-energy", "1", "--batch", "8"],
                  tmp_path)
    assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-3000:]
    # one result line (rank 0), the per-rank shard lines of both ranks
    out = json.loads(r.stdout.strip().splitlines()[-1])
    assert len(out["gamma"]) == 3 and np.isfinite(out["gamma"]).all()
    assert sum(1 for ln in r.stdout.splitlines() if ln.startswith("{")) == 1
    for rank in (0, 1):
        assert f"rank {rank} of 2, epoch 1:" in r.stderr
    # rank 0 alone wrote the checkpoint, the ONNX and the state
    assert sorted(p.name for p in (tmp_path / "o").iterdir()) == [f"{kind}.onnx", f"{kind}.pt"]
    assert sorted(p.name for p in (tmp_path / "w").iterdir()) == ["state.pt"]
    ck = torch.load(tmp_path / "o" / f"{kind}.pt", map_location="cpu", weights_only=False)
    assert ck["meta"]["world_size"] == 2 and len(ck["meta"]["history"]) == 2
    # the ranks saw different shards: disjoint ID rows each epoch, OOD rows split between them
    sh = [json.loads((tmp_path / "shards" / f"{kind}_rank{k}.json").read_text()) for k in (0, 1)]
    tr = d["split"] == 0
    lab = d["label"][tr]
    ok_id = lab >= 0 if kind == "cls" else (lab >= 0) & ~np.isnan(d["box"][tr][:, 0])
    n_id, n_ood = int(ok_id.sum()), int((lab < 0).sum())
    for e0, e1 in zip(sh[0]["epochs"], sh[1]["epochs"]):
        a, b = set(e0["id"]), set(e1["id"])
        assert a and b and not (a & b) and len(a) + len(b) == 2 * (n_id // 2)
        assert set(e0["ood"]) != set(e1["ood"]) and len(set(e0["ood"]) | set(e1["ood"])) == n_ood
    # the exported graph is the checkpoint's model
    from lidet_tools.train.export import load_checkpoint, torch_forward
    model, _ = load_checkpoint(tmp_path / "o" / f"{kind}.pt")
    feeds = {"points": d["points"], "voxel": d["voxel"].astype(np.float32)}
    s = ort.InferenceSession(str(tmp_path / "o" / f"{kind}.onnx"), providers=["CPUExecutionProvider"])
    if kind == "cls":
        ref = torch_forward(model, "classifier", feeds["points"], feeds["voxel"])["logits"]
        got = s.run(["logits"], feeds)[0]
    else:
        oh = np.eye(3, dtype=np.float32)[np.arange(len(d["label"])) % 3]
        ref = torch_forward(model, "box", feeds["points"], feeds["voxel"], oh)["box"]
        got = s.run(["box"], dict(feeds, onehot=oh))[0]
    assert np.abs(got - ref).max() <= 1e-5
