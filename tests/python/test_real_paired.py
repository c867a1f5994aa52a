# SPDX-License-Identifier: MIT
"""`lidet_tools.real.paired`: two eval_real reports compared frame by frame, on hand-made reports (always runs)."""
from __future__ import annotations

import json

import numpy as np
import pytest

from lidet_tools.real import paired


def _report(path, frames):
    """frames: [(source, frame, {class: [objects, found, detections, right]})] at 40 m (20 m: the same)."""
    rows = []
    for src, fid, c40 in frames:
        counts = {r: {c: list(c40.get(c, [0, 0, 0, 0])) for c in paired.CLASSES} for r in ("20", "40")}
        rows.append({"source": src, "frame": fid, "objects": 0, "detections": 0, "ms": 1.0, "lost": [],
                     "counts": counts})
    path.write_text(json.dumps({"meta": {}, "summary": {}, "frames": rows}))
    return path


def _ten(found_extra=0, on=1, fp_extra=0):
    """ten frames of 5 cars each, 3 found, 1 wrong detection; `on` of them find `found_extra` more and make
    `fp_extra` more wrong detections"""
    out = []
    for i in range(10):
        f = 3 + (found_extra if i < on else 0)
        wrong = 1 + (fp_extra if i < on else 0)
        out.append(("kitti", f"{i:06d}", {"Car": [5, f, f + wrong, f]}))
    return out


def test_same_run_gives_nothing(tmp_path):
    a = _report(tmp_path / "a.json", _ten())
    res = paired.compare(paired.load(a), paired.load(a), boot=500)
    car = res["classes"]["Car"]
    assert (car["objects"], car["found_base"], car["found_new"], car["diff"]) == (50, 30, 30, 0)
    assert car["interval90"] == [0.0, 0.0] and car["p_gain"] == 0.0 and car["frames_changed"] == 0
    assert res["fp_per_frame"]["base"] == pytest.approx(1.0) and res["fp_per_frame"]["diff"] == 0.0


def test_a_gain_on_one_frame_is_not_sure(tmp_path):
    a = _report(tmp_path / "a.json", _ten())
    b = _report(tmp_path / "b.json", _ten(found_extra=2, on=1))
    car = paired.compare(paired.load(a), paired.load(b), boot=4000)["classes"]["Car"]
    assert car["diff"] == 2 and car["frames_changed"] == 1
    lo, hi = car["interval90"]
    assert lo == 0.0 and hi >= 2.0          # a draw without that frame gains nothing
    assert 0.5 < car["p_gain"] < 0.8        # 1 - 0.9^10 = 0.65 of the draws hold the frame


def test_a_gain_on_every_frame_is_sure(tmp_path):
    a = _report(tmp_path / "a.json", _ten())
    b = _report(tmp_path / "b.json", _ten(found_extra=1, on=10, fp_extra=1))
    res = paired.compare(paired.load(a), paired.load(b), boot=1000)
    car = res["classes"]["Car"]
    assert car["diff"] == 10 and car["interval90"] == [10.0, 10.0] and car["p_gain"] == 1.0
    fp = res["fp_per_frame"]
    assert fp["new"] == pytest.approx(2.0) and fp["diff"] == pytest.approx(1.0)
    assert fp["p_gain"] == -1.0             # more false positives in every draw


def test_the_draws_are_reproducible_and_paired(tmp_path):
    a = _report(tmp_path / "a.json", _ten())
    b = _report(tmp_path / "b.json", _ten(found_extra=1, on=4))
    r1 = paired.compare(paired.load(a), paired.load(b), boot=300, seed=5)
    r2 = paired.compare(paired.load(a), paired.load(b), boot=300, seed=5)
    assert r1 == r2
    # swapping the runs mirrors the difference, its interval and P(gain)
    r3 = paired.compare(paired.load(b), paired.load(a), boot=300, seed=5)
    c1, c3 = r1["classes"]["Car"], r3["classes"]["Car"]
    assert c3["diff"] == -c1["diff"] and c3["p_gain"] == -c1["p_gain"]
    assert c3["interval90"] == [-c1["interval90"][1], -c1["interval90"][0]]


def _seed_dir(path, runs):
    """eval_real --seeds' layout: {seed: frames} -> path/seed_<S>/report.json"""
    for sd, frames in runs.items():
        (path / f"seed_{sd}").mkdir(parents=True)
        _report(path / f"seed_{sd}" / "report.json", frames)
    return path


def test_seed_folders_compare_draw_by_draw(tmp_path, capsys):
    """Two folders of eval_real --seeds: per seed the difference, found and false positives the mean over the
    seeds, the bootstrap over frames on those means, and how many seeds gain and lose."""
    a = _seed_dir(tmp_path / "a", {"1592594996": _ten(), "1": _ten(), "2": _ten()})
    b = _seed_dir(tmp_path / "b", {"1592594996": _ten(found_extra=1, on=10), "1": _ten(),
                                   "2": _ten(found_extra=-1, on=4, fp_extra=3)})
    res = paired.compare_runs(paired.load_runs(a), paired.load_runs(b), boot=500)
    car = res["classes"]["Car"]
    assert res["seeds"] == ["1", "2", "1592594996"]
    assert car["per_seed"] == [0, -4, 10] and (car["seeds_gain"], car["seeds_loss"]) == (1, 1)
    assert car["found_base"] == pytest.approx(30.0) and car["found_new"] == pytest.approx(32.0)
    assert car["diff"] == pytest.approx(2.0) and car["interval90"][0] <= 2.0 <= car["interval90"][1]
    fp = res["fp_per_frame"]
    assert fp["per_seed"] == [0.0, pytest.approx(1.2), 0.0] and (fp["seeds_gain"], fp["seeds_loss"]) == (0, 1)
    assert fp["diff"] == pytest.approx(0.4)
    assert paired.main([str(a), str(b), "--boot", "200"]) == 0
    out = capsys.readouterr().out
    assert "3 draws" in out and "| Car | 50 | 30.0 | 32.0 | +2.0 |" in out and "+0, -4, +10 |" in out
    # one report.json each is the single comparison; different seeds are refused
    single = paired.compare_runs(paired.load_runs(a / "seed_1" / "report.json"),
                                 paired.load_runs(b / "seed_1" / "report.json"), boot=100)
    assert "seeds" not in single and single["classes"]["Car"]["diff"] == 0
    c = _seed_dir(tmp_path / "c", {"1592594996": _ten(), "7": _ten()})
    assert paired.main([str(a), str(c)]) == 2
    assert "different seeds" in capsys.readouterr().err
    (tmp_path / "empty").mkdir()
    assert paired.main([str(a), str(tmp_path / "empty")]) == 2
    assert "seed_*/report.json" in capsys.readouterr().err


def test_errors(tmp_path, capsys):
    a = _report(tmp_path / "a.json", _ten())
    other = _report(tmp_path / "o.json", _ten()[:9] + [("pandaset", "000000", {"Car": [5, 3, 4, 3]})])
    with pytest.raises(paired.PairedError, match="different frames"):
        paired.compare(paired.load(a), paired.load(other))
    moved = _report(tmp_path / "m.json", [(s, f, {"Car": [6, 3, 4, 3]}) for s, f, _ in _ten()])
    with pytest.raises(paired.PairedError, match="different objects"):
        paired.compare(paired.load(a), paired.load(moved))
    old = tmp_path / "old.json"
    rep = json.loads(a.read_text())
    for f in rep["frames"]:
        del f["counts"]
    old.write_text(json.dumps(rep))
    assert paired.main([str(a), str(old)]) == 2
    assert "run python -m lidet_tools.eval_real again" in capsys.readouterr().err
    assert paired.main([str(a), str(tmp_path / "missing.json")]) == 2
    assert "cannot read" in capsys.readouterr().err
    (tmp_path / "bad.json").write_text("{")
    assert paired.main([str(tmp_path / "bad.json"), str(a)]) == 2
    with pytest.raises(paired.PairedError, match="--boot"):
        paired.compare(paired.load(a), paired.load(a), boot=0)


def test_cli_table_and_json(tmp_path, capsys):
    a = _report(tmp_path / "a.json", _ten())
    b = _report(tmp_path / "b.json", _ten(found_extra=1, on=3))
    assert paired.main([str(a), str(b), "--boot", "200"]) == 0
    out = capsys.readouterr().out
    assert "| Car | 50 | 30 | 33 | +3 |" in out and "false positives per frame" in out
    assert "| Pedestrian |" not in out      # no pedestrian in either run
    assert paired.main([str(a), str(b), "--boot", "200", "--json", "--range", "20"]) == 0
    js = json.loads(capsys.readouterr().out)
    assert js["range_m"] == 20.0 and js["classes"]["Car"]["diff"] == 3
    assert np.isclose(js["fp_per_frame"]["base"], 1.0)
