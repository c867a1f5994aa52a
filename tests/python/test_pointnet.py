# SPDX-License-Identifier: MIT
"""The C PointNet forward pass (through the bindings) against onnxruntime on the committed ONNX models, and
against the float64 numpy reference of lidet_ref.pointnet; codegen drift and refusals; export."""
import pathlib
import shutil
import subprocess
import sys

import numpy as np
import pytest

from lidet_codegen import emit as E
from lidet_ref import pointnet as R
from lidet_tools import kitti, native
from lidet_tools.train.models import to_model_frame

ROOT = pathlib.Path(__file__).resolve().parents[2]
WEIGHTS = ROOT / "weights"
ort = pytest.importorskip("onnxruntime")

#: parity tolerances (issue 13): logits / box outputs / energies, absolute
ATOL = 1e-4


def _pairs():
    """(classifier, box net) names of the committed models (weights/cls_<family>.onnx + box_<family>.onnx)."""
    fams = sorted(p.stem[4:] for p in WEIGHTS.glob("cls_*.onnx"))
    return [(f"cls_{f}", f"box_{f}") for f in fams if (WEIGHTS / f"box_{f}.onnx").exists()]


def _scan_proposals(path, sensor, seeds, n_points=64):
    pts = kitti.read_bin(path)
    g = native.ground(pts, sensor)
    cl = native.cluster(pts, sensor, ground=g.mask_point, planes=g.planes)
    out = []
    for s in seeds:
        out.append(native.proposals(cl, n_points=n_points, seed=s))
    return out


def _n_points(name):
    import onnx
    meta = {p.key: p.value for p in onnx.load(str(WEIGHTS / f"{name}.onnx")).metadata_props}
    return int(meta["lidet.n_points"])


@pytest.fixture(scope="module")
def proposals_at(need_lib, real_dir_optional):
    """proposals_at(n): >= 1000 proposals of n points (the models' own setting: 64, or 32 for the small vlp16s
    pair): the shipped simulated scans with 8 resampling seeds, plus the real KITTI scans when
    ../shared/data/real is there."""
    cache = {}

    def get(n_points):
        if n_points in cache:
            return cache[n_points]
        props = []
        seeds = [0x5EED1234 + 977 * k for k in range(8)]
        props += _scan_proposals(ROOT / "tests/data/sim_hdl64/velodyne/000000.bin", "hdl64", seeds, n_points)
        props += _scan_proposals(ROOT / "tests/data/sim_vlp16/velodyne/000000.bin", "vlp16", seeds, n_points)
        n_real = 0
        if real_dir_optional is not None:
            for f in sorted((real_dir_optional / "kitti").glob("*/velodyne/*.bin")):
                p = _scan_proposals(f, "hdl64", seeds[:1], n_points)
                n_real += len(p[0].xyz)
                props += p
        xyz = np.concatenate([p.xyz for p in props])
        mean = np.concatenate([p.mean for p in props])
        vox = np.concatenate([p.voxel for p in props])
        assert len(xyz) >= 1000, len(xyz)
        assert xyz.shape[1] == n_points
        cache[n_points] = (xyz, mean, vox, n_real)
        return cache[n_points]
    return get


@pytest.fixture(scope="module")
def real_dir_optional():
    from conftest import REAL
    return REAL if (REAL / "README.md").exists() else None


def _session(name):
    so = ort.SessionOptions()
    so.intra_op_num_threads = 1
    return ort.InferenceSession(str(WEIGHTS / f"{name}.onnx"), so, providers=["CPUExecutionProvider"])


@pytest.mark.parametrize("pair", _pairs())
def test_c_matches_onnxruntime(proposals_at, pair):
    cls_name, box_name = pair
    assert _n_points(cls_name) == _n_points(box_name)
    xyz, mean, vox, _ = proposals_at(_n_points(cls_name))
    mp = to_model_frame(xyz, mean)
    voxf = vox.astype(np.float32)
    # classifier: raw logits, then the whole classify call (rotation in C) and its energy and class
    lo = _session(cls_name).run(None, {"points": mp, "voxel": voxf})[0]
    lc = native.pn_forward(cls_name, mp, voxf)
    assert np.abs(lc - lo).max() <= ATOL
    c = native.pn_classify(cls_name, xyz, mean, vox)
    assert np.abs(c["logits"] - lo).max() <= ATOL
    e_ref = np.array([R.energy(v) for v in lo.astype(np.float64)])
    assert np.abs(c["energy"] - e_ref).max() <= ATOL
    assert np.array_equal(c["cls"], lo.argmax(1))  # same class for 100 % of proposals
    # box net with the classifier's classes
    oh = np.eye(3, dtype=np.float32)[c["cls"]]
    t, b = _session(box_name).run(None, {"points": mp, "voxel": voxf, "onehot": oh})
    bc = native.pn_forward(box_name, mp, voxf, oh)
    assert np.abs(bc[:, :3] - t).max() <= ATOL
    assert np.abs(bc[:, 3:] - b).max() <= ATOL
    bx = native.pn_box(box_name, xyz, mean, vox, c["cls"])
    nh = 12
    eh = np.array([R.energy(v) for v in b[:, 3:3 + nh].astype(np.float64)])
    es = np.array([R.energy(v) for v in b[:, 3 + 2 * nh:3 + 2 * nh + 3].astype(np.float64)])
    assert np.abs(bx["energy_heading"] - eh).max() <= ATOL
    assert np.abs(bx["energy_size"] - es).max() <= ATOL
    np.testing.assert_array_equal(bx["heading_bin"], b[:, 3:3 + nh].argmax(1))


def test_c_matches_numpy_reference(proposals_at):
    for cls_name, box_name in _pairs():
        xyz, mean, vox, _ = proposals_at(_n_points(cls_name))
        mc, mb = E.load(WEIGHTS / f"{cls_name}.onnx"), E.load(WEIGHTS / f"{box_name}.onnx")
        idx = np.linspace(0, len(xyz) - 1, 40).astype(int)
        c = native.pn_classify(cls_name, xyz[idx], mean[idx], vox[idx])
        b = native.pn_box(box_name, xyz[idx], mean[idx], vox[idx], c["cls"])
        for j, i in enumerate(idx):
            r = R.classify(mc, xyz[i], mean[i], vox[i])
            np.testing.assert_allclose(c["logits"][j], r["logits"], atol=ATOL, rtol=0)
            np.testing.assert_allclose(c["prob"][j], r["prob"], atol=1e-5, rtol=0)
            assert abs(c["energy"][j] - r["energy"]) <= ATOL and c["cls"][j] == r["cls"]
            rb = R.box(mb, xyz[i], mean[i], vox[i], int(c["cls"][j]))
            d = b["box"][j] - rb["box"]
            d[6] = (d[6] + np.pi) % (2 * np.pi) - np.pi  # yaw near +-pi
            assert np.abs(d).max() <= 1e-3, (b["box"][j], rb["box"])
            assert abs(b["energy"][j] - rb["energy"]) <= ATOL
            assert b["passed"][j] == rb["passed"]


def test_model_info_matches_onnx_metadata(need_lib):
    import onnx
    for name, m in native.pn_models().items():
        meta = {p.key: p.value for p in onnx.load(str(WEIGHTS / f"{name}.onnx")).metadata_props}
        assert m.kind == meta["lidet.kind"] and m.n_points == int(meta["lidet.n_points"])
        np.testing.assert_allclose(m.gamma, [float(x) for x in meta["lidet.gamma"].split(",")], rtol=1e-6)
        d = native.proposal_defaults()
        np.testing.assert_array_equal(m.pvle_bins, np.float32([d["azimuth_bin_rad"], d["elevation_bin_rad"],
                                                               d["range_bin_m"]]))
        assert m.scratch_bytes == E.load(WEIGHTS / f"{name}.onnx").scratch_bytes()


def test_committed_weights_are_regenerated_exactly(tmp_path):
    """CI's drift check: the committed C files are exactly what codegen makes from the committed ONNX."""
    (tmp_path / "weights").mkdir()
    onnx_files = sorted(WEIGHTS.glob("*.onnx"))
    assert onnx_files, "no committed models"
    for f in onnx_files + sorted(WEIGHTS.glob("*.calib.json")):
        shutil.copy(f, tmp_path / "weights" / f.name)
    # what `make weights` ends with (lidet_codegen.regen: the int8 models (lidet_pointnet_q.h) from the committed
    # calibration files, then the float ones and the index)
    cmd = [sys.executable, "-m", "lidet_codegen", "regen", "weights"]
    subprocess.run(cmd, cwd=tmp_path, check=True, capture_output=True)
    made = sorted(p.name for p in (tmp_path / "weights").glob("*.[ch]"))
    committed = sorted(p.name for p in WEIGHTS.glob("*.[ch]"))
    assert made == committed
    for n in made:
        assert (tmp_path / "weights" / n).read_text() == (WEIGHTS / n).read_text(), \
            f"weights/{n} differs from what codegen makes (regenerate: {' '.join(cmd[1:])})"


def test_fuzz_models_are_regenerated_exactly(tmp_path):
    """The fuzz harnesses' tiny models (tests/fuzz/make_models.sh): their C is what codegen makes from their
    committed ONNX and calibration files, float and int8."""
    src = ROOT / "tests" / "fuzz" / "models"
    dst = tmp_path / "tests" / "fuzz" / "models"
    dst.mkdir(parents=True)
    stems = sorted(f.stem for f in src.glob("*.onnx"))
    assert len(stems) == 4, stems
    for f in sorted(src.glob("*.onnx")) + sorted(src.glob("*.calib.json")):
        shutil.copy(f, dst / f.name)
    for stem in stems:  # as make_models.sh runs them
        for extra in ([], ["--int8"]):
            subprocess.run([sys.executable, "-m", "lidet_codegen", "emit", *extra, "--out", "tests/fuzz/models",
                            f"tests/fuzz/models/{stem}.onnx"], cwd=tmp_path, check=True, capture_output=True)
    made = sorted(p.name for p in dst.glob("*.[ch]"))
    assert made == sorted(p.name for p in src.glob("*.[ch]"))
    for n in made:
        assert (dst / n).read_text() == (src / n).read_text(), f"tests/fuzz/models/{n}: run tests/fuzz/make_models.sh"


# ---- codegen refuses what the C side cannot run ---------------------------------------------------

def _graph(nodes, inits, outputs, meta=None, inputs=("points", "voxel")):
    import onnx
    from onnx import TensorProto, helper, numpy_helper
    ins = [helper.make_tensor_value_info("points", TensorProto.FLOAT, ["B", 8, 3]),
           helper.make_tensor_value_info("voxel", TensorProto.FLOAT, ["B", 3])][:len(inputs)]
    outs = [helper.make_tensor_value_info(o, TensorProto.FLOAT, None) for o in outputs]
    g = helper.make_graph(nodes, "t", ins, outs, [numpy_helper.from_array(v.astype(np.float32), k)
                                                   for k, v in inits.items()])
    m = helper.make_model(g, opset_imports=[helper.make_opsetid("", 17)])
    for k, v in (meta or {"lidet.kind": "classifier", "lidet.format": "1", "lidet.n_points": "8",
                          "lidet.gamma": "0,0,0"}).items():
        e = m.metadata_props.add()
        e.key, e.value = k, v
    return m


def _tiny_nodes(act="Relu"):
    from onnx import helper
    rng = np.random.default_rng(0)
    inits = {"w1": rng.normal(size=(4, 3, 1)), "b1": rng.normal(size=4), "wh": rng.normal(size=(3, 4)),
             "bh": rng.normal(size=3)}
    nodes = [helper.make_node("Transpose", ["points"], ["t"], perm=[0, 2, 1], name="tr"),
             helper.make_node("Conv", ["t", "w1", "b1"], ["c1"], kernel_shape=[1], name="conv1"),
             helper.make_node(act, ["c1"], ["r1"], name="act1"),
             helper.make_node("ReduceMax", ["r1"], ["g"], axes=[2], keepdims=0, name="pool"),
             helper.make_node("Gemm", ["g", "wh", "bh"], ["logits"], transB=1, name="head")]
    return nodes, inits


def test_emit_accepts_a_handmade_graph_and_matches_onnxruntime():
    nodes, inits = _tiny_nodes()
    m = E.parse(_graph(nodes, inits, ["logits"]), "t")
    assert [len(s.point) for s in m.stages] == [1] and m.stages[0].pvle == []
    pts = np.random.default_rng(1).normal(size=(8, 3))
    s = ort.InferenceSession(_graph(nodes, inits, ["logits"]).SerializeToString(), providers=["CPUExecutionProvider"])
    want = s.run(None, {"points": pts[None].astype(np.float32), "voxel": np.zeros((1, 3), np.float32)})[0][0]
    np.testing.assert_allclose(R.forward(m, pts, np.zeros(3)), want, atol=1e-5)


def test_emit_refuses_unsupported_operator():
    nodes, inits = _tiny_nodes("Sigmoid")
    with pytest.raises(E.EmitError, match=r"node 'act1' \(Sigmoid\): operator not supported"):
        E.parse(_graph(nodes, inits, ["logits"]))


def test_emit_refuses_wider_conv_and_bad_metadata():
    nodes, inits = _tiny_nodes()
    inits["w1"] = np.zeros((4, 3, 3))
    nodes[1].attribute[0].ints[:] = [3]
    with pytest.raises(E.EmitError, match=r"node 'conv1' \(Conv\): only 1x1"):
        E.parse(_graph(nodes, inits, ["logits"]))
    nodes, inits = _tiny_nodes()
    with pytest.raises(E.EmitError, match="lidet.kind"):
        E.parse(_graph(nodes, inits, ["logits"], meta={"lidet.format": "1"}))
    with pytest.raises(E.EmitError, match="lidet.format"):
        E.parse(_graph(nodes, inits, ["logits"], meta={"lidet.kind": "classifier", "lidet.format": "9"}))


def test_emit_z_origin_metadata():
    """lidet.z_origin (the proposals' z origin the model was trained on) reaches the C model; absent means the mean."""
    nodes, inits = _tiny_nodes()
    base = {"lidet.kind": "classifier", "lidet.format": "1", "lidet.n_points": "8", "lidet.gamma": "0,0,0"}
    assert E.parse(_graph(nodes, inits, ["logits"], meta=base)).z_origin == 0
    m = E.parse(_graph(nodes, inits, ["logits"], meta=dict(base, **{"lidet.z_origin": "ground"})))
    assert m.z_origin == 1
    _, c = E.emit_c(m, "t.onnx", "cmd", "0" * 64)
    assert "1u /* proposal z origin: ground */" in c
    with pytest.raises(E.EmitError, match="lidet.z_origin 'floor'"):
        E.parse(_graph(nodes, inits, ["logits"], meta=dict(base, **{"lidet.z_origin": "floor"})))


def test_emit_cli_reports_errors(tmp_path):
    nodes, inits = _tiny_nodes("Tanh")
    p = tmp_path / "bad.onnx"
    p.write_bytes(_graph(nodes, inits, ["logits"]).SerializeToString())
    r = subprocess.run([sys.executable, "-m", "lidet_codegen", "emit", str(p), "--out", str(tmp_path)],
                       capture_output=True, text=True)
    assert r.returncode == 2 and "(Tanh): operator not supported" in r.stderr
    assert not list(tmp_path.glob("*.c"))


def test_export_matches_pytorch(tmp_path):
    """PyTorch -> ONNX: onnxruntime equals the PyTorch model (max abs diff <= 1e-5) on both kinds."""
    pytest.importorskip("torch")
    from lidet_tools.train import export as X
    rng = np.random.default_rng(3)
    pts = rng.normal(size=(16, 64, 3)).astype(np.float32)
    vox = rng.integers(-5, 40, (16, 3)).astype(np.float32)
    oh = np.eye(3, dtype=np.float32)[rng.integers(0, 3, 16)]
    for kind in ("classifier", "box"):
        model, ck = X.untrained(kind, 64, seed=5)
        path = X.export_onnx(model, ck, tmp_path / f"{kind}.onnx")
        want = X.torch_forward(model, kind, pts, vox, oh)
        s = ort.InferenceSession(str(path), providers=["CPUExecutionProvider"])
        feeds = {"points": pts, "voxel": vox} if kind == "classifier" else {"points": pts, "voxel": vox, "onehot": oh}
        got = dict(zip([o.name for o in s.get_outputs()], s.run(None, feeds)))
        for k, v in want.items():
            assert np.abs(got[k] - v).max() <= 1e-5, k
        # and codegen's descriptor (BN folded) gives the same through the numpy reference
        m = E.load(path)
        i = 3
        ref = R.forward(m, pts[i], vox[i], oh[i]) if kind == "box" else R.forward(m, pts[i], vox[i])
        full = np.concatenate([want["center_tnet"][i], want["box"][i]]) if kind == "box" else want["logits"][i]
        np.testing.assert_allclose(ref, full, atol=1e-4)
