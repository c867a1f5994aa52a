# SPDX-License-Identifier: MIT
"""Gate 2 per class (lidet_detector_cfg_t.gate2_class, default car 1, cyclist 1, pedestrian 0): the float
detector through the bindings and the CLI (`lidet detect --set gate2.pedestrian=1`), on the shipped VLP-16 sample,
where gate 2 would reject pedestrians. The integer detector's flags are checked bit for bit against the numpy
reference in test_detector_q.py (case gate2_all)."""
from __future__ import annotations

import json
import pathlib
import subprocess

import numpy as np
import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
SCAN = ROOT / "tests/data/sim_vlp16/velodyne/000000.bin"
PED = 2  # lidet_class_t


def _pts():
    from lidet_tools import kitti
    return kitti.read_bin(SCAN)


def test_pedestrians_pass_gate2_by_default(nd):
    pts = _pts()
    dflt = nd.detect(pts, "vlp16")
    every = nd.detect(pts, "vlp16", gate2_class=(1, 1, 1))
    gamma_ped = float(nd.pn_models()["box_vlp16"].gamma[PED])
    # the default keeps pedestrians whose box energy fails the model's gate; judging them drops exactly those
    failing = [i for i in range(len(dflt.cls)) if dflt.cls[i] == PED and dflt.energy_box[i] >= gamma_ped]
    assert failing, "the sample should hold a pedestrian that gate 2 would reject"
    assert every.stats["n_gate2_rejected"] == dflt.stats["n_gate2_rejected"] + len(failing)
    assert len(every.cls) == len(dflt.cls) - len(failing)
    assert all(not (c == PED and e >= gamma_ped) for c, e in zip(every.cls, every.energy_box))
    # cars and cyclists are judged either way: no car or cyclist of the default run fails its gate
    for c, e in zip(dflt.cls, dflt.energy_box):
        if c != PED:
            assert e < float(nd.pn_models()["box_vlp16"].gamma[c])
    # no class judged: the same as gate 2 off
    none = nd.detect(pts, "vlp16", gate2_class=(0, 0, 0))
    off = nd.detect(pts, "vlp16", gate2=False)
    np.testing.assert_array_equal(none.cls, off.cls)
    np.testing.assert_array_equal(none.box, off.box)
    with pytest.raises(ValueError):
        nd.detect(pts, "vlp16", gate2_class=(1, 1))


def test_cli_set_gate2_per_class(nd):
    from lidet_tools.detect import find_cli
    exe = find_cli()

    def run(*sets):
        cmd = [str(exe), "detect", str(SCAN), "--sensor", "vlp16", "--json"]
        for s in sets:
            cmd += ["--set", s]
        return subprocess.run(cmd, capture_output=True, text=True)

    pts = _pts()
    for sets, flags in (((), None), (("gate2.pedestrian=1",), (1, 1, 1)), (("gate2.car=0", "gate2.cyclist=0"), (0, 0, 0))):
        r = run(*sets)
        assert r.returncode == 0, r.stderr
        got = json.loads(r.stdout)["boxes"]
        want = nd.detect(pts, "vlp16", gate2_class=flags)
        assert [b["class"] for b in got] == [nd.CLASSES[int(c)] for c in want.cls], sets
    r = run("gate2.pedestrian=2")  # a flag: 0 or 1
    assert r.returncode != 0 and "gate2.pedestrian=2" in r.stderr
