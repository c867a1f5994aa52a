# SPDX-License-Identifier: MIT
"""Training smoke test: two simulated scans -> proposals -> one epoch of each phase of both trainers ->
ONNX export -> onnxruntime agrees with PyTorch (max abs diff <= 1e-5) on real proposals. Also the
MAC counter, the energy and gate helpers, and the resumable state."""
import json

import numpy as np
import pytest

torch = pytest.importorskip("torch")
ort = pytest.importorskip("onnxruntime")

from lidet_tools.train import common as C  # noqa: E402
from lidet_tools.train import dataset as D  # noqa: E402
from lidet_tools.train import macs  # noqa: E402
from lidet_tools.train import metrics as MX  # noqa: E402
from lidet_tools.train import train_box, train_cls  # noqa: E402


@pytest.fixture(scope="module")
def tiny(tmp_path_factory, need_lib):
    """Two hdl64 scans: scan 0 is the training split, scan 1 validation."""
    d = D.concat([D._job(("sim", s, 1, s, None), "hdl64", dict(D.DEFAULTS)) for s in range(2)])
    p = tmp_path_factory.mktemp("tiny") / "tiny.npz"
    np.savez_compressed(p, meta=json.dumps({"sensor": "hdl64", "command": "test"}), **d)
    return p, d


def _ort(path, feeds):
    s = ort.InferenceSession(str(path), providers=["CPUExecutionProvider"])
    return dict(zip([o.name for o in s.get_outputs()], s.run(None, feeds)))


def test_train_export_onnx_parity(tiny, tmp_path):
    path, d = tiny
    a = train_cls.add_args(__import__("argparse").ArgumentParser()).parse_args(
        ["--data", str(path), "--work", str(tmp_path / "cw"), "--out", str(tmp_path / "cls.pt"), "--onnx",
         str(tmp_path / "cls.onnx"), "--epochs-ce", "1", "--epochs-energy", "1", "--batch", "8", "--no-progress"])
    ck = train_cls.train(a)
    assert ck["meta"]["trained"] == 1 and len(ck["meta"]["gamma"]) == 3 and np.isfinite(ck["meta"]["gamma"]).all()
    assert ck["meta"]["margins"]["m_out"] >= ck["meta"]["margins"]["m_in"] + 3.0 - 1e-9
    from lidet_tools.train.export import load_checkpoint, torch_forward
    model, _ = load_checkpoint(tmp_path / "cls.pt")
    feeds = {"points": d["points"], "voxel": d["voxel"].astype(np.float32)}
    ref = torch_forward(model, "classifier", feeds["points"], feeds["voxel"])
    got = _ort(tmp_path / "cls.onnx", feeds)
    assert np.abs(got["logits"] - ref["logits"]).max() <= 1e-5

    b = train_box.add_args(__import__("argparse").ArgumentParser()).parse_args(
        ["--data", str(path), "--work", str(tmp_path / "bw"), "--out", str(tmp_path / "box.pt"), "--onnx",
         str(tmp_path / "box.onnx"), "--epochs-box", "1", "--epochs-energy", "1", "--batch", "8", "--no-progress"])
    ckb = train_box.train(b)
    assert ckb["kind"] == "box" and len(ckb["meta"]["gamma"]) == 3
    model, _ = load_checkpoint(tmp_path / "box.pt")
    oh = np.eye(3, dtype=np.float32)[np.arange(len(d["label"])) % 3]
    ref = torch_forward(model, "box", feeds["points"], feeds["voxel"], oh)
    got = _ort(tmp_path / "box.onnx", dict(feeds, onehot=oh))
    for k in ("center_tnet", "box"):
        assert np.abs(got[k] - ref[k]).max() <= 1e-5
    # the evaluation on the validation scan: figures in range, tables rendered
    from lidet_tools.train import evaluate as EV
    res = EV.evaluate(D.load(path), 1, tmp_path / "cls.pt", tmp_path / "box.pt", tmp_path / "en")
    g1 = res["cls"]["gate1"]
    assert g1["n_id"] == int((d["label"][d["split"] == 1] >= 0).sum()) and 0.0 <= g1["auroc"] <= 1.0
    assert 0.0 <= res["boxnet"]["gate2"]["fpr95"] <= 1.0
    assert all(0.0 <= b["iou_mean"] <= 1.0 for b in res["boxnet"]["box"].values() if b.get("n"))
    md = EV.markdown(res, "tiny")
    assert "gate 1 (classifier energy)" in md and "gate 2 (box-net energy)" in md
    assert len(np.load(tmp_path / "en" / "cls_ood.npy")) == g1["n_ood"]
    # budgets, counted from the graphs
    assert macs.count(tmp_path / "cls.onnx")["macs"] <= 1_000_000
    assert macs.count(tmp_path / "box.onnx")["macs"] <= 2_000_000
    # resuming a finished run changes nothing
    ck2 = train_cls.train(a)
    for k, v in ck["state_dict"].items():
        assert torch.equal(v, ck2["state_dict"][k])
    # another share of the validation ID proposals for the gammas resumes the finished state: the same model, the
    # car gate where it keeps that share (a per-class share, `--gamma-tpr`), the other classes' gates as before
    a.gamma_tpr = "0.5,0.95,0.95"
    ck3 = train_cls.train(a)
    for k, v in ck["state_dict"].items():
        assert torch.equal(v, ck3["state_dict"][k])
    assert ck3["meta"]["gamma_tpr"] == [0.5, 0.95, 0.95] and ck["meta"]["gamma_tpr"] == [0.95] * 3
    assert ck3["meta"]["gamma"][1:] == ck["meta"]["gamma"][1:] and ck3["meta"]["gamma"][0] < ck["meta"]["gamma"][0]
    a.gamma_tpr = "0.95"
    # other arguments with the same state folder are refused
    a.epochs_ce = 2
    with pytest.raises(ValueError, match="other arguments"):
        train_cls.train(a)


def test_macs_hand_count(tmp_path):
    """The counter against the MACs computed by hand from the default widths at 64 points."""
    from lidet_tools.train.export import export_onnx, untrained
    m, ck = untrained("classifier")
    export_onnx(m, ck, tmp_path / "c.onnx")
    n = 64
    hand = n * (3 * 32 + 32 * 64 + 64 * 128) + (3 * 32 + 32 * 32) + (160 * 64 + 64 * 3)
    assert macs.count(tmp_path / "c.onnx")["macs"] == hand
    assert macs.count(tmp_path / "c.onnx", 128)["macs"] == hand + n * (3 * 32 + 32 * 64 + 64 * 128)


def test_energy_gate_helpers():
    lg = torch.tensor([[10.0, 0.0, 0.0], [0.0, 0.0, 0.0]])
    e = C.energy(lg).numpy()
    np.testing.assert_allclose(e, [-(10 + np.log(1 + 2 * np.exp(-10))), -np.log(3)], rtol=1e-6)
    np.testing.assert_allclose(MX.energy_np(lg.numpy()), e, rtol=1e-6)
    e_id = np.arange(100, dtype=np.float64)   # 0..99
    g = C.threshold_at_tpr(e_id, 0.95)
    assert np.mean(e_id < g) == 0.95
    assert C.fpr_at_tpr(e_id, np.array([50.0, 200.0, 94.0, 95.0])) == 0.5
    assert C.auroc(np.array([0.0, 1.0]), np.array([2.0, 3.0])) == 1.0
    assert C.auroc(np.array([2.0, 3.0]), np.array([0.0, 1.0])) == 0.0
    assert C.auroc(np.array([1.0]), np.array([1.0])) == 0.5
    assert C.hinge(torch.tensor([-5.0, -1.0]), torch.tensor([0.0, -4.0]), -3.0, -2.0).item() == pytest.approx(2.0 + 2.0)


def test_per_class_gamma_shares():
    """gamma per class at its own share of that class's ID energies; a class with too few proposals takes the pooled
    energies at its share; --gamma-tpr is one share or three, each in (0, 1]."""
    e = np.concatenate([np.arange(100.0), 1000.0 + np.arange(100.0), [5000.0] * 5])
    cls = np.array([0] * 100 + [2] * 100 + [1] * 5)
    g = C.per_class_gamma(e, cls, [0.9, 0.95, 0.5])
    assert np.mean(e[cls == 0] < g[0]) == 0.9 and np.mean(e[cls == 2] < g[2]) == 0.5
    assert g[1] == C.threshold_at_tpr(e, 0.95)  # 5 cyclists: the pooled energies
    assert C.per_class_gamma(e, cls, 0.95) == C.per_class_gamma(e, cls, [0.95] * 3)
    assert train_cls.gamma_tprs("0.9") == [0.9] * 3 and train_cls.gamma_tprs("0.9,1,0.5") == [0.9, 1.0, 0.5]
    for bad in ("0.9,0.9", "0", "1.5", "a", "0.9,0.9,0.9,0.9"):
        with pytest.raises(ValueError, match="--gamma-tpr"):
            train_cls.gamma_tprs(bad)


def test_augment_keeps_box_consistent():
    """Mirroring, rotation and translation move points and box together (corners stay in the box frame)."""
    rng = np.random.default_rng(3)
    box = np.array([[1.0, 0.3, 0.1, 4.0, 1.6, 1.5, 0.4]], np.float32)
    u = rng.uniform(-0.5, 0.5, (64, 3)) * box[0, 3:6]
    c, s = np.cos(box[0, 6]), np.sin(box[0, 6])
    pts = np.stack([c * u[:, 0] - s * u[:, 1], s * u[:, 0] + c * u[:, 1], u[:, 2]], 1) + box[0, :3]
    for _ in range(5):
        p, b = C.augment(rng, pts[None].astype(np.float32), box)
        inside = D.points_in_box(p[0], b[0], margin=0.035)
        assert inside.all()


def test_occlude_hides_part_recentres_and_moves_the_box():
    """common.occlude: a hit proposal loses 15-45 % of its distinct points on one side, is re-centred on the mean
    of what stays, and its box target moves by the same offset; p = 0 draws nothing (earlier models' batches)."""
    rng = np.random.default_rng(5)
    B, N = 64, 64
    pts = rng.uniform(-1.0, 1.0, (B, N, 3)).astype(np.float32)
    pts -= pts.mean(1, keepdims=True)
    box = np.tile(np.array([[0.2, -0.1, 0.05, 4.0, 1.6, 1.5, 0.3]], np.float32), (B, 1))
    p, b = pts.copy(), box.copy()
    C.occlude(rng, p, b, 1.0)
    changed = 0
    for i in range(B):
        kept = np.unique(p[i] - (b[i, :3] - box[i, :3]), axis=0)  # undo the re-centring
        d = np.abs(kept[:, None, :] - pts[i][None, :, :]).max(-1).min(1)
        assert d.max() < 1e-5  # only original points, nothing invented
        np.testing.assert_allclose(p[i].mean(0), 0.0, atol=1e-5)  # centred on its own mean
        if len(kept) < N:
            changed += 1
            assert 8 <= len(kept) <= int(np.ceil(0.86 * N))
    assert changed == B  # every proposal was hit (p = 1), each lost at least 14 % of its points
    # p = 0: no random draw, the generator's stream is untouched
    r1, r2 = np.random.default_rng(9), np.random.default_rng(9)
    a1, _ = C.augment(r1, pts, box)
    a2, _ = C.augment(r2, pts, box, occlusion=0.0)
    np.testing.assert_array_equal(a1, a2)


def test_narrower_nets_train_and_count_fewer_macs(tiny, tmp_path):
    """--widths (box net) and --point / --pvle / --head (classifier): the layers take those widths, the export
    carries them, and the graphs count the multiply-adds of those widths (a firmware's smaller models)."""
    path, _ = tiny
    b = train_box.add_args(__import__("argparse").ArgumentParser()).parse_args(
        ["--data", str(path), "--work", str(tmp_path / "bw"), "--out", str(tmp_path / "box.pt"), "--onnx",
         str(tmp_path / "box.onnx"), "--epochs-box", "1", "--epochs-energy", "1", "--batch", "8", "--no-progress",
         "--widths", '{"tnet_point": [16, 32], "tnet_head": [32], "point": [24, 48, 80], "head": [64, 32], '
                     '"pvle": [16, 16]}'])
    ckb = train_box.train(b)
    assert ckb["cfg"]["point"] == (24, 48, 80) and ckb["cfg"]["tnet_head"] == (32,) and ckb["cfg"]["pvle"] == (16, 16)
    a = train_cls.add_args(__import__("argparse").ArgumentParser()).parse_args(
        ["--data", str(path), "--work", str(tmp_path / "cw"), "--out", str(tmp_path / "cls.pt"), "--onnx",
         str(tmp_path / "cls.onnx"), "--epochs-ce", "1", "--epochs-energy", "1", "--batch", "8", "--no-progress",
         "--point", "16,32,64", "--pvle", "16,16", "--head", "32"])
    ck = train_cls.train(a)
    assert ck["cfg"]["pvle"] == (16, 16) and ck["cfg"]["point"] == (16, 32, 64)
    n = int(np.load(path)["points"].shape[1])
    # per point: 3*24 + 24*48 + 48*80 (box) + 3*16 + 16*32 (T-Net); per point: 3*16 + 16*32 + 32*64 (classifier)
    assert macs.count(tmp_path / "box.onnx")["macs"] >= n * (3 * 24 + 24 * 48 + 48 * 80 + 3 * 16 + 16 * 32)
    assert macs.count(tmp_path / "box.onnx")["macs"] < n * 6000
    assert n * (3 * 16 + 16 * 32 + 32 * 64) <= macs.count(tmp_path / "cls.onnx")["macs"] < n * 2700


@pytest.mark.parametrize("bad", ['{"point": [0]}', '{"nope": [8]}', '[8]', '{"head": []}', 'not json'])
def test_bad_widths_are_refused(tmp_path, capsys, bad):
    rc = train_box.main(["--data", str(tmp_path / "none.npz"), "--work", str(tmp_path / "w"), "--out",
                         str(tmp_path / "b.pt"), "--widths", bad, "--no-progress"])
    assert rc != 0 and "--widths" in capsys.readouterr().err


@pytest.mark.parametrize("trainer", [train_box, train_cls])
def test_occlusion_out_of_range_is_refused(tmp_path, capsys, trainer):
    rc = trainer.main(["--data", str(tmp_path / "none.npz"), "--work", str(tmp_path / "w"), "--out",
                       str(tmp_path / "b.pt"), "--occlusion", "1.5", "--no-progress"])
    assert rc != 0 and "--occlusion must be a probability" in capsys.readouterr().err


@pytest.mark.parametrize("bad", ['{"nope": 1}', '[0.02]', 'not json'])
def test_classifier_aug_settings_are_checked(tmp_path, capsys, bad):
    rc = train_cls.main(["--data", str(tmp_path / "none.npz"), "--work", str(tmp_path / "w"), "--out",
                         str(tmp_path / "c.pt"), "--aug", bad, "--no-progress"])
    assert rc != 0 and "--aug" in capsys.readouterr().err


def test_classifier_occlusion_and_aug_train_and_resume(tiny, tmp_path):
    """train_cls --occlusion and --aug reach the batches (another model than the defaults') and are part of the
    resumable state's arguments (a state made with other settings is refused)."""
    path, _ = tiny

    def run(work, *extra):
        a = train_cls.add_args(__import__("argparse").ArgumentParser()).parse_args(
            ["--data", str(path), "--work", str(tmp_path / work), "--out", str(tmp_path / f"{work}.pt"),
             "--epochs-ce", "1", "--epochs-energy", "1", "--batch", "8", "--no-progress", *extra])
        return train_cls.train(a)

    plain = run("plain")
    aug = run("aug", "--occlusion", "0.5", "--aug", '{"jitter": 0.02}')
    w0 = np.concatenate([v.cpu().numpy().ravel() for v in plain["state_dict"].values() if v.dtype.is_floating_point])
    w1 = np.concatenate([v.cpu().numpy().ravel() for v in aug["state_dict"].values() if v.dtype.is_floating_point])
    assert w0.shape == w1.shape and not np.array_equal(w0, w1)
    with pytest.raises(ValueError, match="other arguments"):
        run("aug", "--occlusion", "0.3")


def test_finetune_q_round_trip_emulation_and_training(tiny, tmp_path, capsys):
    """finetune_q (quantization-aware fine-tuning of a classifier): with no epoch it writes the same network back
    (identity batch norms); its fake-quantized forward is the int8 build of lidet_codegen.quant up to that build's
    integer rounding; an epoch changes the weights, keeps the ONNX contract (onnxruntime = the folded float
    network) and reports the figures; bad input gets a clear error."""
    from lidet_codegen import emit as E
    from lidet_codegen import quant as QU
    from lidet_ref import pointnet_q as RQ
    from lidet_tools.train import finetune_q as FQ
    path, d = tiny
    a = train_cls.add_args(__import__("argparse").ArgumentParser()).parse_args(
        ["--data", str(path), "--work", str(tmp_path / "cw"), "--out", str(tmp_path / "cls.pt"), "--onnx",
         str(tmp_path / "cls.onnx"), "--epochs-ce", "1", "--epochs-energy", "1", "--batch", "8", "--no-progress"])
    train_cls.train(a)
    m = E.load(tmp_path / "cls.onnx", "cls")
    x = QU.float_inputs(d["xyz"], d["mean"])
    vox = d["voxel"].astype(np.float64)
    ref = QU.float_trace(m, x, vox, None)[-1]
    base = ["--onnx", str(tmp_path / "cls.onnx"), "--data", str(path), "--batch", "8"]
    assert FQ.main(base + ["--out", str(tmp_path / "ft0.onnx"), "--epochs", "0"]) == 0
    m0 = E.load(tmp_path / "ft0.onnx", "ft0")
    assert np.abs(QU.float_trace(m0, x, vox, None)[-1] - ref).max() <= 1e-4
    assert m0.n_points == m.n_points and np.isfinite(m0.gamma).all()

    # the fake-quantized forward against the int8 reference, with the same per-channel ranges
    fc = FQ.FoldedClassifier(m)
    pts, vt = torch.tensor(x, dtype=torch.float32), torch.tensor(vox, dtype=torch.float32)
    rng = fc.ranges(pts, vt, 99.9)
    qm = QU.quantize(m, {"ranges": {k: v.tolist() for k, v in rng.items()}})
    q4, m4 = QU.int_proposals(d["xyz"], d["mean"])
    lq = RQ.classify(qm, q4, m4, d["voxel"].astype(np.int64))["logits"] / 65536.0
    with torch.no_grad():
        fq = fc.forward(pts, vt, rng).numpy()
        ff = fc.forward(pts, vt).numpy()
    err_fq, err_f = np.abs(fq - lq).mean(), np.abs(ff - lq).mean()
    assert err_fq <= 0.02 and err_fq < 0.5 * err_f, (err_fq, err_f)  # closer to the int8 build than float is

    capsys.readouterr()
    assert FQ.main(base + ["--out", str(tmp_path / "ft1.onnx"), "--epochs", "1", "--margins=-6,-3"]) == 0
    res = json.loads(capsys.readouterr().out)
    assert set(res["before"]) == {"bal_acc", "fpr95", "fake_q_disagree"} and res["margins"] == {"m_in": -6.0, "m_out": -3.0}
    m1 = E.load(tmp_path / "ft1.onnx", "ft1")
    assert max(np.abs(a.w - b.w).max() for a, b in zip(m1.stages[0].point, m.stages[0].point)) > 1e-6
    got = _ort(tmp_path / "ft1.onnx", {"points": x.astype(np.float32), "voxel": vox.astype(np.float32)})["logits"]
    assert np.abs(got - QU.float_trace(m1, x, vox, None)[-1]).max() <= 1e-4
    assert FQ.main(base + ["--out", str(tmp_path / "x.onnx"), "--data", str(tmp_path / "missing.npz")]) == 2
    assert "finetune_q:" in capsys.readouterr().err


def test_finetune_q_checkpoint_and_card(tiny, tmp_path, capsys):
    """What make weights uses: --checkpoint takes the network's margins from its checkpoint and rewrites it with
    the fine-tuned weights (the training record kept, the step added; the same network as the ONNX); --card puts
    the new gamma in the file's row and this run in the section, replacing an earlier run's lines."""
    from lidet_tools.train.export import load_checkpoint, torch_forward
    from lidet_tools.train import finetune_q as FQ
    path, d = tiny
    a = train_cls.add_args(__import__("argparse").ArgumentParser()).parse_args(
        ["--data", str(path), "--work", str(tmp_path / "cw"), "--out", str(tmp_path / "cls.pt"), "--onnx",
         str(tmp_path / "cls_t.onnx"), "--epochs-ce", "1", "--epochs-energy", "1", "--batch", "8", "--no-progress"])
    ck0 = train_cls.train(a)
    card = tmp_path / "CARD.md"
    row = "| `cls_t.onnx` | hdl64 | classifier | 64 | 1 | 1 | 1.0 KiB | 9.000, 9.000, 9.000 | -1.00 / 2.00 | 2 |"
    card.write_text("# card\n\n## Files\n\n" + row + "\n\n## Known limits\n\n- none\n")
    argv = ["--onnx", str(tmp_path / "cls_t.onnx"), "--data", str(path), "--out", str(tmp_path / "cls_t.onnx"),
            "--batch", "8", "--epochs", "1", "--checkpoint", str(tmp_path / "cls.pt"), "--card", str(card)]
    for _ in range(2):
        capsys.readouterr()
        assert FQ.main(argv) == 0
        res = json.loads(capsys.readouterr().out)
    assert res["margins"] == {k: ck0["meta"]["margins"][k] for k in ("m_in", "m_out")}
    model, ck = load_checkpoint(tmp_path / "cls.pt")
    assert ck["meta"]["best_epoch"] == ck0["meta"]["best_epoch"] and ck["meta"]["history"] == ck0["meta"]["history"]
    assert ck["meta"]["gamma"] == res["gamma"] and ck["meta"]["finetune"]["epochs"] == 1
    feeds = {"points": d["points"], "voxel": d["voxel"].astype(np.float32)}
    ref = torch_forward(model, "classifier", feeds["points"], feeds["voxel"])["logits"]
    assert np.abs(_ort(tmp_path / "cls_t.onnx", feeds)["logits"] - ref).max() <= 1e-4
    text = card.read_text()
    assert ", ".join(f"{g:.3f}" for g in res["gamma"]) in text and "9.000" not in text
    assert text.count(FQ.CARD_SECTION) == 1 and text.count("`cls_t.onnx` was fine-tuned") == 1
    assert text.index(FQ.CARD_SECTION) < text.index("## Known limits") and "- none" in text


def test_make_weights_family_with_int8_fine_tuning(tmp_path, monkeypatch, need_lib):
    """weights.run_family with a family that has `cls_finetune` (as vlp16 in make weights): the classifier's
    checkpoint and ONNX are the fine-tuned network, and the model card shows its gamma and the step."""
    import argparse
    from lidet_tools.train.export import load_checkpoint
    from lidet_tools.train import weights as Wt
    d = D.concat([D._job(("sim", s, 1, s, None), "hdl64", dict(D.DEFAULTS)) for s in range(3)])
    work, wdir = tmp_path / "work", tmp_path / "weights"
    work.mkdir()
    np.savez_compressed(work / "tiny.npz", meta=json.dumps({"sensor": "hdl64", "command": "test"}), **d)
    small = ["--batch", "8"]
    monkeypatch.setitem(Wt.FAMILIES, "tiny", dict(
        sensor="hdl64", dataset=[],
        cls=["--epochs-ce", "1", "--epochs-energy", "1", "--gamma-tpr", "0.9,0.95,0.97"] + small,
        box=["--epochs-box", "1", "--epochs-energy", "1"] + small, cls_finetune=["--epochs", "1"] + small))
    a = argparse.Namespace(work=work, weights=wdir, docs_img=tmp_path / "img", jobs=1, threads=1, device="cpu",
                           seed=0, no_progress=True)
    wdir.mkdir()
    a.docs_img.mkdir()
    timings = {}
    res = Wt.run_family("tiny", a, timings)
    _, ck = load_checkpoint(work / "tiny_cls.pt")
    assert ck["meta"]["finetune"]["epochs"] == 1 and "finetune_q" in ck["meta"]["finetune"]["command"]
    # the fine-tuning's gates keep the shares the family trained with (train_cls --gamma-tpr)
    assert ck["meta"]["gamma_tpr"] == [0.9, 0.95, 0.97]
    assert "--gamma-tpr 0.9,0.95,0.97" in ck["meta"]["finetune"]["command"]
    # a family named apart from its sensor (as vlp16s) trains for the sensor its spec names
    assert ck["meta"]["sensor"] == "hdl64" and "--sensor hdl64" in ck["meta"]["command"]
    g = [float(v) for v in {p.key: p.value for p in __import__("onnx").load(str(wdir / "cls_tiny.onnx")).metadata_props}
         ["lidet.gamma"].split(",")]
    np.testing.assert_allclose(g, ck["meta"]["gamma"], rtol=1e-6)
    card = Wt.model_card(a, {"tiny": res}, {}, dict(timings, total=1.0))
    assert "## Int8 fine-tuning" in card and "`cls_tiny.onnx` was fine-tuned" in card
    assert ", ".join(f"{v:.3f}" for v in ck["meta"]["gamma"]) in card


def _centred_proposals(rng, B, N, half_xy, half_z, box):
    """B proposals of N points uniform in +-half_xy (x, y) and +-half_z (z), each centred on its mean, and B copies
    of one box target."""
    pts = rng.uniform(-half_xy, half_xy, (B, N, 3)).astype(np.float32)
    pts[..., 2] = rng.uniform(-half_z, half_z, (B, N))
    pts -= pts.mean(1, keepdims=True)
    return pts, np.tile(np.array([box], np.float32), (B, 1))


def _kept_points(before, after, box_before, box_after):
    """A proposal cut and re-centred by common's occlusions: (the box target's offset, its points moved back);
    asserts that it holds only points it had and is centred on their mean."""
    off = box_after[:3] - box_before[:3]
    orig = after - off  # undo the re-centring
    d = np.abs(orig[:, None, :] - before[None, :, :]).max(-1).min(1)
    assert d.max() < 1e-5  # only original points
    np.testing.assert_allclose(after.mean(0), 0.0, atol=1e-5)
    return off, orig


def test_occlude_from_above_keeps_the_top_recentres_and_moves_the_box():
    """common.occlude_from_above: a hit proposal keeps only its points above a cut at 35-70 % of its z extent (a
    person seen over a parked car's roof), re-centred on their own mean, the box target moved by the same offset;
    a proposal that would keep fewer than 8 distinct points is left as it was."""
    rng = np.random.default_rng(3)
    B, N = 32, 64
    pts, box = _centred_proposals(rng, B, N, 0.3, 0.9, [0.0, 0.0, 0.0, 0.8, 0.6, 1.8, 0.0])
    p, b = pts.copy(), box.copy()
    C.occlude_from_above(rng, p, b, 1.0)
    for i in range(B):
        off, orig = _kept_points(pts[i], p[i], box[i], b[i])
        z0, z1 = pts[i, :, 2].min(), pts[i, :, 2].max()
        cut = orig[:, 2].min()
        assert cut >= z0 + 0.35 * (z1 - z0) - 1e-5  # the lower 35 % at least is gone (resampled: the top may be too)
        assert off[2] < -0.1  # the mean rose: the box target sits lower relative to the kept points
    # too few points above any cut: left untouched
    few = np.zeros((1, N, 3), np.float32)
    few[0, :, 2] = np.where(np.arange(N) < N - 3, -1.0, np.linspace(0.5, 1.0, N)[:N])  # 3 distinct points on top
    f2 = few.copy()
    C.occlude_from_above(rng, f2, None, 1.0)
    np.testing.assert_array_equal(f2, few)


def test_ground_cut_drops_the_lowest_points_recentres_and_moves_the_box():
    """common.ground_cut: a hit proposal loses its points within h <= max_m of its lowest one (a real ground stage
    eating a car's sills), re-centred on the kept points' mean, the box target moved by the same offset; a proposal
    that would keep fewer than 8 distinct points is left as it was; augment's ground_cut (0, 0) draws nothing and a
    bad setting is refused."""
    rng = np.random.default_rng(4)
    B, N = 32, 64
    pts, box = _centred_proposals(rng, B, N, 1.0, 0.7, [0.1, 0.0, 0.05, 4.0, 1.7, 1.4, 0.2])
    p, b = pts.copy(), box.copy()
    C.ground_cut(rng, p, b, 1.0, 0.3)
    cuts = []
    for i in range(B):
        _, orig = _kept_points(pts[i], p[i], box[i], b[i])
        cuts.append(orig[:, 2].min() - pts[i, :, 2].min())
    cuts = np.array(cuts)
    # cuts drawn up to 0.3 m (the resampling may also miss a few of the lowest kept points: up to 0.1 m more)
    assert cuts.min() >= 0.0 and cuts.max() <= 0.3 + 0.1 and np.median(cuts) > 0.08
    few = np.zeros((1, N, 3), np.float32)
    few[0, :, 2] = np.where(np.arange(N) < N - 3, -0.5, np.linspace(0.5, 1.0, N)[:N])  # 3 distinct points on top
    f2 = few.copy()
    C.ground_cut(np.random.default_rng(0), f2, None, 1.0, 1.0)
    np.testing.assert_array_equal(f2, few)
    a0, _ = C.augment(np.random.default_rng(1), pts)
    a1, _ = C.augment(np.random.default_rng(1), pts, ground_cut=(0.0, 0.0))
    a2, _ = C.augment(np.random.default_rng(1), pts, ground_cut=[0.5, 0.2])  # as JSON gives it (--aug)
    np.testing.assert_array_equal(a0, a1)
    assert not np.array_equal(a0, a2)
    for bad in ((1.5, 0.1), (0.5, -0.1), (0.5,), 0.5):
        with pytest.raises(ValueError, match="ground_cut"):
            C.augment(rng, pts, ground_cut=bad)


def test_top_occlusion_touches_only_cyclists_and_pedestrians():
    """finetune._aug with top_occlusion: only Cyclist and Pedestrian rows are cut from above (their highest point
    stays the highest, their lowest rises); Car and OOD rows get the plain augmentation."""
    from lidet_tools.train import finetune as FT
    rng = np.random.default_rng(1)
    K, N = 40, 64
    pts = rng.uniform(-0.3, 0.3, (K, N, 3)).astype(np.float32)
    pts[..., 2] = rng.uniform(-0.8, 0.8, (K, N))
    tr = dict(points=pts, label=np.array([0, 1, 2, -1] * 10, np.int8), src=np.zeros(K, np.int8),
              box=np.zeros((K, 7), np.float32))
    idx = np.arange(K)
    a, _ = FT._aug(np.random.default_rng(7), tr, idx, False, 1.0)
    b, _ = FT._aug(np.random.default_rng(7), tr, idx, False, 0.0)
    span_a = a[..., 2].max(1) - a[..., 2].min(1)
    span_b = b[..., 2].max(1) - b[..., 2].min(1)
    vru = np.isin(tr["label"], (1, 2))
    assert (span_a[vru] < 0.75 * span_b[vru]).all()
    assert (span_a[~vru] > 0.8 * span_b[~vru]).mean() > 0.9
