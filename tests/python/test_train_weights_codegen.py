# SPDX-License-Identifier: MIT
"""`make weights` ends with the C models of what it trained (issue 36): the whole pipeline
(lidet_tools.train.weights) on a tiny family, into a --weights folder that holds stale C and calibration files;
afterwards every float and int8 C file there, and lidet_weights.{c,h}, is what codegen makes from the new ONNX
files there (lidet_codegen.regen, the drift check's commands), with calibration files of those ONNX files."""
import hashlib
import re
import shutil

import pytest

pytest.importorskip("torch")
pytest.importorskip("onnxruntime")

from lidet_codegen import quant as Q  # noqa: E402
from lidet_codegen import regen  # noqa: E402
from lidet_tools.train import calibrate as CB  # noqa: E402
from lidet_tools.train import weights as W  # noqa: E402

#: one HDL-64 scan per split, one epoch per phase; the classifier not fine-tuned for int8, so it gets the refit
TINY = dict(sensor="hdl64", dataset=["--sensor", "hdl64", "--sim", "1,1,1", "--seed", "1000"],
            cls=["--epochs-ce", "1", "--epochs-energy", "1", "--batch", "8"],
            box=["--epochs-box", "1", "--epochs-energy", "1", "--batch", "8"])
STALE = "/* stale: made from other ONNX files */\n"


def _sha(p):
    return hashlib.sha256(p.read_bytes()).hexdigest()


def test_make_weights_regenerates_the_c_models(tmp_path, monkeypatch, need_lib):
    monkeypatch.setitem(W.FAMILIES, "tiny", TINY)
    # the calibration and refit sets, smaller (the commands and the files are the same otherwise)
    monkeypatch.setattr(CB, "CALIB_N_SIM", 1)
    monkeypatch.setattr(CB, "REFIT_N_SIM", 1)
    monkeypatch.chdir(tmp_path)
    wd = tmp_path / "weights"
    wd.mkdir()
    stale = [f"{m}{s}.{e}" for m in ("cls_tiny", "box_tiny") for s in ("", "_s8") for e in ("c", "h")] + \
        ["lidet_weights.c", "lidet_weights.h"]
    for n in stale:
        (wd / n).write_text(STALE)
    for n in ("cls_tiny", "box_tiny"):  # calibration files of other models: the old ONNX files' sha256
        (wd / f"{n}.calib.json").write_text('{"onnx_sha256": "0"}\n')

    rc = W.main(["--work", "work", "--weights", "weights", "--docs-img", "img", "--families", "tiny", "--jobs", "1",
                 "--real", "no_real_scans", "--no-progress"])
    assert rc == 0

    made = sorted(p.name for p in wd.glob("*.[ch]"))
    assert made == sorted(stale)
    onnx_sha = {n: _sha(wd / f"{n}.onnx") for n in ("cls_tiny", "box_tiny")}
    for n, sha in onnx_sha.items():
        cal = (wd / f"{n}.calib.json").read_text()
        assert f'"onnx_sha256": "{sha}"' in cal
        assert ('"head_refit"' in cal) == (n == "cls_tiny")  # no cls_finetune: the classifier's last layer refitted
        assert f"from {n}.onnx sha256={sha}\n" in (wd / f"{n}.c").read_text()
        s8 = (wd / f"{n}_s8.c").read_text()
        assert f"from {n}.onnx sha256={sha}\n" in s8
        assert f"calibration {n}.calib.json sha256={_sha(wd / f'{n}.calib.json')}\n" in s8
    index = (wd / "lidet_weights.c").read_text()
    assert all(f"&lidet_model_{n}" in index for n in ("cls_tiny", "box_tiny", "cls_tiny_s8", "box_tiny_s8"))
    assert not any((wd / n).read_text() == STALE for n in made)

    # byte for byte what codegen makes from the ONNX and calibration files left there
    again = tmp_path / "again"
    (again / "weights").mkdir(parents=True)
    for p in list(wd.glob("*.onnx")) + list(wd.glob("*.calib.json")):
        shutil.copy(p, again / "weights" / p.name)
    monkeypatch.chdir(again)
    regen.emit_all("weights")
    assert sorted(p.name for p in (again / "weights").glob("*.[ch]")) == made
    for n in made:
        assert (again / "weights" / n).read_text() == (wd / n).read_text(), n
    # the card names the step
    assert re.search(r"\| int8 calibration and C models \(all families\) \| \d+ \|", (wd / "MODEL_CARD.md").read_text())


def test_box_calibration_takes_the_classifier_beside_it(tmp_path, need_lib):
    """A box net is calibrated on the classes of cls_<family>.onnx in its own folder (a --weights folder other than
    weights/ holds the classifier trained with it), not on weights/'s."""
    import json
    root = CB.ROOT
    cal = json.loads((root / "weights" / "box_vlp16.calib.json").read_text())
    xyz, mean, vox = CB.calib_set(dict(cal, scans=[s for s in cal["scans"] if s.startswith("tests/")][:1]))
    box = Q.load(root / "weights" / "box_vlp16.onnx", "box_vlp16")
    committed = Q.calib_classes(box, xyz, mean, vox)
    assert committed.any()  # the committed classifier's classes, not all 0
    assert (Q.calib_classes(box, xyz, mean, vox, tmp_path) == 0).all()  # no classifier beside it
    shutil.copy(root / "weights" / "cls_vlp16.onnx", tmp_path / "cls_vlp16.onnx")
    assert (Q.calib_classes(box, xyz, mean, vox, tmp_path) == committed).all()
