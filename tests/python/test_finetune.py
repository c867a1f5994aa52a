# SPDX-License-Identifier: MIT
"""Fine-tuning on a user's labelled scans (lidet_tools.train.finetune, docs/TRAINING.md): the shipped ONNX models
loaded into the PyTorch models reproduce onnxruntime; the sensor-frame folder layout of dataset.py (labelled field of
view, meta.json); the strong augmentation keeps boxes on their points; the command end to end on a tiny folder made
from the simulator's shipped scan (ONNX, C models, card); its error messages; the real-frame export."""
import argparse
import json
import shutil

import numpy as np
import pytest

torch = pytest.importorskip("torch")
ort = pytest.importorskip("onnxruntime")
onnx = pytest.importorskip("onnx")

from conftest import ROOT  # noqa: E402
from lidet_tools.train import dataset as D  # noqa: E402
from lidet_tools.train import finetune as FT  # noqa: E402
from lidet_tools.train import models as M  # noqa: E402

SIM = ROOT / "tests" / "data" / "sim_hdl64"
FAMILIES = sorted(p.stem[4:] for p in (ROOT / "weights").glob("cls_*.onnx"))


def _batch(n_points, n=200, seed=3):
    """Proposal-like inputs: model-frame points (car-sized spread), PVLE bins, classes."""
    g = np.random.default_rng(seed)
    pts = (g.normal(size=(n, n_points, 3)) * [1.5, 0.7, 0.5]).astype(np.float32)
    vox = np.stack([g.integers(-18, 18, n), g.integers(-3, 2, n), g.integers(2, 60, n)], 1).astype(np.float32)
    return pts, vox, g.integers(0, 3, n)


@pytest.mark.parametrize("fam", FAMILIES)
@pytest.mark.parametrize("kind", ["cls", "box"])
def test_onnx_to_pytorch_reproduces_onnxruntime(fam, kind):
    path = ROOT / "weights" / f"{kind}_{fam}.onnx"
    model, k, meta = FT.load_onnx(path)
    assert k == ("classifier" if kind == "cls" else "box")
    pts, vox, cls = _batch(int(meta["lidet.n_points"]))
    par = FT.onnx_parity(model, k, path, pts, vox, cls)
    assert set(par) == ({"logits"} if kind == "cls" else {"center_tnet", "box"})
    for name, (diff, big) in par.items():
        # 1e-5, relative where an output exceeds 1: the box nets' heading scores reach |15-29|, where onnxruntime and
        # PyTorch (both float32) differ by a few ulps, 1.1e-5 at most (docs/TRAINING.md, "Tests and cost")
        assert diff <= 1e-5 * max(1.0, big), \
            f"{path.name} {name}: max |PyTorch - onnxruntime| {diff:.2e} (largest |output| {big:.1f})"
    assert FT.parity_ok(par)
    if kind == "cls":
        assert par["logits"][0] <= 1e-5
    # the loaded widths are the graph's: the same parameter count as the model built from them
    init = {i.name for i in onnx.load(str(path)).graph.initializer}
    assert sum(1 for n in model.state_dict() if not n.endswith("num_batches_tracked")) >= len(init)


def test_onnx_loading_refuses_an_initializer_that_maps_nowhere(tmp_path):
    from onnx import numpy_helper
    m = onnx.load(str(ROOT / "weights" / "cls_hdl64.onnx"))
    m.graph.initializer.append(numpy_helper.from_array(np.zeros(3, np.float32), "stray"))
    p = tmp_path / "cls_x.onnx"
    onnx.save(m, str(p))
    with pytest.raises(ValueError, match="one to one.*stray"):
        FT.load_onnx(p)


def test_gamma_at_the_shipped_ood_count():
    """--gamma ood: per class, the new gate lets through exactly as many OOD rows as the shipped gate did; a class the
    shipped gate let wholly through, or the new model never predicts, keeps the fallback (TPR) gamma."""
    g = np.random.default_rng(5)
    e_old = g.normal(-5, 1, 300)
    c_old = g.integers(0, 3, 300)
    e_new = g.normal(-5.5, 1.2, 300)
    c_new = np.where(g.random(300) < 0.8, c_old, 0)
    c_new[c_new == 1] = 2  # the new model never predicts class 1
    gamma_old = [-6.0, -5.8, -6.5]
    fallback = [-4.0, -4.5, -4.2]
    out = FT.gammas_at_ood((e_new, c_new), (e_old, c_old), gamma_old, fallback)
    for c in (0, 2):
        n_old = int(((c_old == c) & (e_old < gamma_old[c])).sum())
        assert n_old > 0
        assert int(((c_new == c) & (e_new < out[c])).sum()) == n_old
        # the next energy up is the gamma (rounded down to a float32): no looser gamma keeps the count
        e = np.sort(e_new[c_new == c])
        assert e[n_old - 1] < out[c] <= e[n_old] and e[n_old] - out[c] < 1e-6
    assert out[1] == fallback[1]
    # the shipped gate let 3 rows through as class 0, the new model calls only 2 rows class 0: the fallback
    few = FT.gammas_at_ood((np.array([-9.0, -8.0, -7.0]), np.array([0, 0, 2])),
                           (np.array([-3.0, -2.0, -1.0]), np.array([0, 0, 0])), [10.0, 10.0, 10.0], fallback)
    assert few[0] == fallback[0] and few[2] == -7.0


def test_set_onnx_gamma(tmp_path):
    p = tmp_path / "cls.onnx"
    shutil.copy(ROOT / "weights" / "cls_hdl64.onnx", p)
    FT.set_onnx_gamma(p, [-1.5, -2.25, -3.0])
    a, b = onnx.load(str(ROOT / "weights" / "cls_hdl64.onnx")), onnx.load(str(p))
    meta = {q.key: q.value for q in b.metadata_props}
    assert [float(v) for v in meta["lidet.gamma"].split(",")] == [-1.5, -2.25, -3.0]
    assert a.graph.SerializeToString() == b.graph.SerializeToString()
    assert {q.key: q.value for q in a.metadata_props if q.key != "lidet.gamma"} == \
        {k: v for k, v in meta.items() if k != "lidet.gamma"}
    m = onnx.load(str(p))
    del m.metadata_props[:]
    onnx.save(m, str(p))
    with pytest.raises(ValueError, match="no lidet.gamma"):
        FT.set_onnx_gamma(p, [0.0, 0.0, 0.0])


def test_augment_real_moves_boxes_with_their_points(monkeypatch):
    """Occlusion, dropout, mirror, rotation, scaling and shift move the box target with the points (jitter off)."""
    monkeypatch.setitem(FT.REAL_AUG, "jitter", 0.0)
    g = np.random.default_rng(0)
    B, N = 64, 64
    box = np.tile(np.array([[0.1, -0.2, 0.05, 4.0, 1.8, 1.5, 0.3]], np.float32), (B, 1))
    u = g.uniform(-0.5, 0.5, (B, N, 3)) * box[:, None, 3:6]
    c, s = np.cos(0.3), np.sin(0.3)
    pts = np.stack([c * u[..., 0] - s * u[..., 1], s * u[..., 0] + c * u[..., 1], u[..., 2]], -1) + box[:, None, :3]
    p2, b2 = FT.augment_real(g, pts.astype(np.float32), box)
    assert p2.shape == pts.shape and b2.shape == box.shape
    assert not np.allclose(b2, box)
    for i in range(B):
        inside = D.points_in_box(p2[i], b2[i], margin=1e-3)
        assert inside.all(), f"proposal {i}: {int((~inside).sum())} points left their box"
    assert 0.89 * 4.0 <= b2[:, 3].min() and b2[:, 3].max() <= 1.11 * 4.0


def _folder(tmp_path, names=("a", "b", "c"), meta=None, layout="boxes"):
    """A user folder of copies of the simulator's shipped scan (sensor-frame or KITTI layout)."""
    d = tmp_path / "scans"
    for sub in ("velodyne",) + (("boxes",) if layout == "boxes" else ("label_2", "calib")):
        (d / sub).mkdir(parents=True, exist_ok=True)
    for n in names:
        shutil.copy(SIM / "velodyne" / "000000.bin", d / "velodyne" / f"{n}.bin")
        if layout == "boxes":
            shutil.copy(SIM / "boxes" / "000000.txt", d / "boxes" / f"{n}.txt")
        else:
            shutil.copy(SIM / "label_2" / "000000.txt", d / "label_2" / f"{n}.txt")
            shutil.copy(SIM / "calib" / "000000.txt", d / "calib" / f"{n}.txt")
    if meta is not None:
        (d / "meta.json").write_text(json.dumps(meta))
    return d


def test_boxes_folder_field_of_view_and_meta(tmp_path, need_lib):
    d = _folder(tmp_path, names=("a", "b"),
                meta={"fov_half_deg": 30.0, "frames": {"b": {"fov_half_deg": None, "mount_height_m": 1.73}}})
    assert D.boxes_scans(d) == ["a", "b"]
    a = D.boxes_scan(d, "a")
    b = D.boxes_scan(d, "b")
    assert a.fov_half == pytest.approx(np.radians(30.0)) and a.mount is None
    assert b.fov_half is None and b.mount == pytest.approx(1.73)
    cfg = dict(D.DEFAULTS)
    ra, rb = D.process_scan(a, "hdl64", cfg), D.process_scan(b, "hdl64", cfg)
    az = np.degrees(np.abs(np.arctan2(ra["mean"][:, 1], ra["mean"][:, 0])))
    assert len(az) and az.max() <= 30.0 + 1e-6
    assert len(rb["label"]) > len(ra["label"]) and (rb["label"] >= 0).any()
    # a scan labelling cars only: clusters in no box are excluded, the cars stay
    (d / "meta.json").write_text(json.dumps({"classes": ["Car"]}))
    rc = D.process_scan(D.boxes_scan(d, "a"), "hdl64", cfg)
    assert (rc["label"] == 0).sum() == (rb["label"] == 0).sum() and len(rc["label"]) < len(rb["label"])
    (d / "meta.json").write_text(json.dumps({"classes": ["Truck"]}))
    with pytest.raises(ValueError, match="unknown classes"):
        D.boxes_scan(d, "a")


def _run(argv):
    return FT.main([str(x) for x in argv])


def test_finetune_end_to_end(tmp_path, need_lib, monkeypatch, capsys):
    """One epoch of each phase on three copies of the shipped simulated scan, with a tiny simulated mix: OUT holds both
    ONNX models (trained, with the export's metadata), their calibration and C models, the index and the card."""
    from lidet_tools.train import calibrate as CB
    monkeypatch.setattr(CB, "CALIB_N_SIM", 1)  # the calibration's extra simulated scans: one (speed only)
    monkeypatch.setattr(CB, "REFIT_N_SIM", 1)
    d = _folder(tmp_path)
    out = tmp_path / "out"
    rc = _run([d, "--family", "hdl64", "--out-weights", out, "--epochs", 1, "--epochs-energy", 1, "--steps", 2,
               "--batch", 16, "--sim", "2,1,1", "--sim-mix", 0.25, "--only-family", "--no-progress"])
    assert rc == 0, capsys.readouterr().err
    for n in ("cls_hdl64", "box_hdl64"):
        for ext in (".onnx", ".calib.json", ".c", ".h", "_s8.c", "_s8.h"):
            assert (out / f"{n}{ext}").exists(), f"{n}{ext} missing"
        meta = {p.key: p.value for p in onnx.load(str(out / f"{n}.onnx")).metadata_props}
        assert meta["lidet.trained"] == "1" and meta["lidet.name"] == n and meta["lidet.sensor"] == "hdl64"
        assert "lidet_tools.train.finetune" in meta["lidet.command"] and "sim-mix 0.25" in meta["lidet.data"]
        assert len(meta["lidet.gamma"].split(",")) == 3
        cal = json.loads((out / f"{n}.calib.json").read_text())
        assert any(s.endswith("scans/velodyne/a.bin") for s in cal["scans"]), cal["scans"]  # the user's scans
        assert not any(s.startswith("real/") for s in cal["scans"])
    assert "cls_hdl64" in (out / "lidet_weights.c").read_text()
    assert not list(out.glob("*_vlp16*"))  # --only-family
    card = (out / FT.CARD).read_text()
    for part in ("| user train | 2 |", "| user val | 1 |", "--sim-mix 0.25", "ONNX -> PyTorch", "shipped, user validation",
                 "fine-tuned, user validation", "LIDET_WEIGHTS_DIR", "gamma at 95 % TPR", "`--gamma ood`"):
        assert part in card, part
    res = json.loads((out / "work" / "finetune.json").read_text())
    assert res["gamma_rule"] == "ood" and len(res["gamma_tpr"]["cls"]) == 3
    for k, n in (("cls", "cls_hdl64"), ("box", "box_hdl64")):  # the ONNX files carry the chosen gammas
        meta = {p.key: p.value for p in onnx.load(str(out / f"{n}.onnx")).metadata_props}
        assert [float(v) for v in meta["lidet.gamma"].split(",")] == res["gamma"][k]
    # the fine-tuned models load again and changed
    m0, _, _ = FT.load_onnx(ROOT / "weights" / "cls_hdl64.onnx")
    m1, _, _ = FT.load_onnx(out / "cls_hdl64.onnx")
    assert any(not torch.equal(a, b) for a, b in zip(m0.state_dict().values(), m1.state_dict().values()))
    # --install's step on a copy of weights/: the pair and its calibration copied, every C model regenerated there
    w = tmp_path / "weights"
    shutil.copytree(ROOT / "weights", w)
    before = (w / "cls_hdl64.c").read_text()
    FT.install(out, w, "hdl64")
    assert (w / "cls_hdl64.onnx").read_bytes() == (out / "cls_hdl64.onnx").read_bytes()
    assert (w / "box_hdl64.calib.json").read_text() == (out / "box_hdl64.calib.json").read_text()
    after = (w / "cls_hdl64.c").read_text()
    assert after != before and "cmd: python -m lidet_codegen emit weights/" in after
    assert (w / "cls_vlp16.c").read_text() == (ROOT / "weights" / "cls_vlp16.c").read_text()  # the others as shipped
    with pytest.raises(FileNotFoundError, match="lacks"):
        FT.install(out, w, "vlp16")


def test_finetune_errors(tmp_path, capsys):
    out = tmp_path / "out"
    empty = tmp_path / "empty"
    empty.mkdir()
    assert _run([empty, "--family", "hdl64", "--out-weights", out]) == 2
    assert "no scans: expected velodyne/*.bin" in capsys.readouterr().err
    assert _run([tmp_path / "absent", "--family", "hdl64", "--out-weights", out]) == 2
    assert "no such folder" in capsys.readouterr().err
    unlabelled = tmp_path / "unlabelled"
    (unlabelled / "velodyne").mkdir(parents=True)
    shutil.copy(SIM / "velodyne" / "000000.bin", unlabelled / "velodyne" / "a.bin")
    assert _run([unlabelled, "--family", "hdl64", "--out-weights", out]) == 2
    assert "scans without labels: expected boxes/" in capsys.readouterr().err
    (unlabelled / "label_2").mkdir()
    assert _run([unlabelled, "--family", "hdl64", "--out-weights", out]) == 2
    assert "label_2/ but no calib/" in capsys.readouterr().err
    d = _folder(tmp_path)
    assert _run([d, "--family", "vlp32c", "--out-weights", out]) == 2
    err = capsys.readouterr().err
    assert "--family vlp32c: no shipped weights" in err and "hdl64" in err
    assert _run([d, "--family", "hdl64", "--out-weights", ROOT / "weights"]) == 2
    assert "shipped weights folder" in capsys.readouterr().err
    other = tmp_path / "other_checkout"  # another checkout's weights (a worktree run with this one's environment)
    (other / "lib" / "include" / "lidet").mkdir(parents=True)
    (other / "lib" / "include" / "lidet" / "lidet.h").write_text("/* lidet */\n")
    (other / "weights").mkdir()
    assert _run([d, "--family", "hdl64", "--out-weights", other / "weights"]) == 2
    assert "shipped weights folder" in capsys.readouterr().err
    assert not out.exists()


def test_finetune_without_labelled_objects(tmp_path, need_lib, capsys):
    """Scans whose boxes hold no road user: a clear message, no output models."""
    d = _folder(tmp_path, names=("a", "b"))
    for n in ("a", "b"):
        (d / "boxes" / f"{n}.txt").write_text("")
    out = tmp_path / "out"
    assert _run([d, "--family", "hdl64", "--out-weights", out, "--no-progress"]) == 2
    assert "no labelled Car / Cyclist / Pedestrian proposal" in capsys.readouterr().err
    assert not list(out.glob("*.onnx"))


def test_real_export(tmp_path, real_dir):
    from lidet_tools import kitti
    from lidet_tools.real import export as EX
    assert EX.main(["--side", "train", "--sources", "kitti,kitti360", "--root", str(real_dir), "--out",
                    str(tmp_path / "rt")]) == 0
    meta = json.loads((tmp_path / "rt" / "meta.json").read_text())
    names = sorted(meta["frames"])
    assert names and all(n.startswith(("kitti_", "kitti360_")) for n in names)
    assert sorted(p.stem for p in (tmp_path / "rt" / "velodyne").glob("*.bin")) == names
    for n in names:
        f = meta["frames"][n]
        assert f["sensor"] == "hdl64" and f["mount_height_m"] > 1.0
        assert (f["fov_half_deg"] is None) == n.startswith("kitti360_")
        assert f["classes"] == (["Car"] if n.startswith("kitti360_") else ["Car", "Pedestrian", "Cyclist"])
        assert len(kitti.read_boxes(tmp_path / "rt" / "boxes" / f"{n}.txt")) == sum(f["boxes"].values())
    from lidet_tools.eval_real import read_split
    val = {f"{s}_{i}" for s, i, side in read_split() if side == "val"}
    assert not val & set(names)
    assert EX.main(["--side", "train", "--sources", "argoverse", "--root", str(real_dir), "--out",
                    str(tmp_path / "x")]) == 2
