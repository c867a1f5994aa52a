# SPDX-License-Identifier: MIT
"""The committed weights/*.onnx: contract metadata, budgets, and behaviour on fresh simulated scans
(seeds of the test splits, through the C stages, run with onnxruntime)."""
import pathlib

import numpy as np
import pytest

ort = pytest.importorskip("onnxruntime")
onnx = pytest.importorskip("onnx")

from lidet_tools.train import dataset as D  # noqa: E402
from lidet_tools.train import macs  # noqa: E402
from lidet_tools.train import metrics as MX  # noqa: E402
from lidet_tools.train import models as M  # noqa: E402

WEIGHTS = pathlib.Path(__file__).resolve().parents[2] / "weights"
#: family -> (sensor, test-split simulator seed of `make weights`, mounts cycled over the scans, points per
#: proposal); vlp16s: the small VLP-16 pair of the integer firmware
FAMILIES = {"hdl64": ("hdl64", 1002, [None], 64), "vlp16": ("vlp16", 2002, [0.3, 0.5, 0.7, 1.0], 64),
            "vlp16s": ("vlp16", 2002, [0.3, 0.5, 0.7, 1.0], 32), "beams32": ("vlp32c", 3002, [0.7, 1.0, 1.4, 1.84], 64),
            "beams128": ("os1-128", 4002, [0.7, 1.0, 1.4, 1.84], 64), "beams64": ("os1-64", 5002, [0.7, 1.0, 1.4, 1.84], 64)}
#: the presets a family's simulated scans cycle over (dataset --sim-sensors); the others: its own sensor
SIM_SENSORS = {"beams32": ["vlp32c", "hdl32", "os0-32", "os1-32", "os2-32"], "beams128": ["os0-128", "os1-128", "os2-128"],
               "beams64": ["os0-64", "os1-64", "os2-64"]}


def _meta(path):
    return {p.key: p.value for p in onnx.load(str(path)).metadata_props}


@pytest.mark.parametrize("fam", sorted(FAMILIES))
@pytest.mark.parametrize("kind", ["cls", "box"])
def test_shipped_metadata_and_budget(fam, kind):
    p = WEIGHTS / f"{kind}_{fam}.onnx"
    if not p.exists():
        pytest.skip(f"{p} not generated (make weights)")
    m = _meta(p)
    sensor, _, _, npts = FAMILIES[fam]
    assert m["lidet.trained"] == "1" and m["lidet.n_points"] == str(npts) and m["lidet.sensor"] == sensor
    assert m["lidet.kind"] == ("classifier" if kind == "cls" else "box")
    assert m["lidet.classes"] == ",".join(M.CLASSES)
    g = [float(v) for v in m["lidet.gamma"].split(",")]
    assert len(g) == 3 and np.isfinite(g).all()
    c = macs.count(p)
    assert c["macs"] <= (1_000_000 if kind == "cls" else 2_000_000)


@pytest.mark.parametrize("fam", sorted(FAMILIES))
def test_shipped_models_on_fresh_scans(fam, need_lib):
    pc, pb = WEIGHTS / f"cls_{fam}.onnx", WEIGHTS / f"box_{fam}.onnx"
    if not (pc.exists() and pb.exists()):
        pytest.skip("weights not generated (make weights)")
    sensor, seed, mounts, npts = FAMILIES[fam]
    sims = SIM_SENSORS.get(fam, [sensor])
    d = D.concat([D._job(("sim", 2, seed, i, mounts[(i // len(sims)) % len(mounts)], sims[i % len(sims)]), sensor,
                         dict(D.DEFAULTS, n_points=npts))
                  for i in range(max(4, len(sims)))])
    idm = d["label"] >= 0
    assert idm.sum() >= 10
    feeds = {"points": d["points"], "voxel": d["voxel"].astype(np.float32)}
    lg = ort.InferenceSession(str(pc), providers=["CPUExecutionProvider"]).run(None, feeds)[0]
    assert np.mean(lg.argmax(1)[idm] == d["label"][idm]) >= 0.9
    g = np.array([float(v) for v in _meta(pc)["lidet.gamma"].split(",")])
    e = MX.energy_np(lg)
    keep = e < g[lg.argmax(1)]
    assert keep[idm].mean() >= 0.8 and keep[~idm].mean() <= 0.3
    ok = idm & ~np.isnan(d["box"][:, 0])
    oh = np.eye(3, dtype=np.float32)[d["label"][ok]]
    s = ort.InferenceSession(str(pb), providers=["CPUExecutionProvider"])
    dc, bx = s.run(None, {"points": d["points"][ok], "voxel": feeds["voxel"][ok], "onehot": oh})
    iou = MX.iou_3d_pairs(MX.decode_to_boxes(dc, bx), d["box"][ok].astype(np.float64))
    assert np.median(iou) >= 0.5
