# SPDX-License-Identifier: MIT
"""The bindings' frame check (`native.detect`, `native.frame_warning`): a cloud that is not in lidet's frame (x
forward, y left, z up, metres) still runs, and a LidetFrameWarning says what looks wrong, by the rule of the CLI's
warning (docs/ROBUSTNESS.md, "A cloud in another frame")."""
import pathlib
import warnings

import numpy as np
import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
SCAN = ROOT / "tests" / "data" / "sim_hdl64" / "velodyne" / "000000.bin"


def _frame_warned(run, points, sensor):
    """run(points, sensor)'s result and the LidetFrameWarnings it gave."""
    from lidet_tools import native
    with warnings.catch_warnings(record=True) as got:
        warnings.simplefilter("always")
        d = run(points, sensor)
    return d, [w for w in got if issubclass(w.category, native.LidetFrameWarning)]


def _detect(points, sensor="hdl64"):
    from lidet_tools import native
    return _frame_warned(native.detect, points, sensor)


def test_detect_names_a_cloud_in_another_frame(need_lib):
    from lidet_tools import native
    p = np.fromfile(SCAN, np.float32).reshape(-1, 4)
    d, w = _detect(p)
    assert w == [] and d.stats["n_points_in"] == len(p) and d.stats["n_out_of_fov"] == 0
    assert native.frame_warning(d.stats, "hdl64") is None
    flip, mm = p.copy(), p.copy()
    flip[:, 1:3] *= -1.0
    mm[:, :3] *= 1000.0
    d, w = _detect(flip)
    assert len(w) == 1 and "outside the hdl64's beams" in str(w[0].message)
    assert "x forward, y left, z up" in str(w[0].message) and d.stats["n_out_of_fov"] > len(p) // 10
    d, w = _detect(mm)
    assert len(w) == 1 and "are the coordinates in metres?" in str(w[0].message) and d.stats["n_too_far"] == len(p)
    # the rule's edges: a tenth outside the beams passes, one point more warns; a tiny scan is not judged
    st = dict(n_points_in=1000, n_out_of_fov=100, n_too_far=250)
    assert native.frame_warning(st, "vlp16") is None
    assert "vlp16's beams" in native.frame_warning(dict(st, n_out_of_fov=101), "vlp16")
    assert "metres" in native.frame_warning(dict(st, n_too_far=251), "vlp16")
    assert native.frame_warning(dict(n_points_in=99, n_out_of_fov=99, n_too_far=99), "vlp16") is None


@pytest.mark.parametrize("source", ["kitti", "pandaset", "argoverse"])
def test_real_frames_draw_no_frame_warning(need_lib, real_dir, source):
    """The real labelled frames, each on its source's preset, put about 0.5 % of their points at most outside its beams."""
    from lidet_tools import eval_real, real
    frames = [(s, f) for s, f, _ in eval_real.read_split(eval_real.SPLIT) if s == source]
    if not frames:
        pytest.skip(f"no {source} frames in the split")
    fr = real.load_frame(real_dir, *frames[0])
    d, w = _detect(fr.points, fr.sensor)
    assert w == [] and d.stats["n_out_of_fov"] <= 0.01 * d.stats["n_points_in"], d.stats


def _detect_q(points_mm, sensor="hdl64"):
    from lidet_tools import native
    return _frame_warned(native.detect_q, points_mm, sensor)


def test_detect_q_names_a_cloud_in_another_frame_or_unit(need_lib):
    """The integer detector's bindings take millimetres: the same rule, and a cloud in metres given as whole numbers
    (every point within a few mm of the sensor) is named too; metres as floats are refused before they are cast."""
    from lidet_tools import native
    p = np.fromfile(SCAN, np.float32).reshape(-1, 4)
    mm = native.to_mm(p)
    d, w = _detect_q(mm)
    st = d["stats"]
    assert w == [] and st["n_points_in"] == len(p) and st["n_out_of_fov"] == 0 and len(d["cls"]) > 0
    flip = mm.copy()
    flip[:, 1:3] *= -1
    d, w = _detect_q(flip)
    assert len(w) == 1 and "outside the hdl64's beams" in str(w[0].message)
    assert d["stats"]["n_out_of_fov"] > len(p) // 10
    metres = np.round(p[:, :3]).astype(np.int32)  # metres where millimetres belong
    d, w = _detect_q(metres)
    assert len(w) == 1 and "detect_q takes millimetres" in str(w[0].message)
    assert d["stats"]["n_too_close"] > len(p) // 4 and len(d["cls"]) == 0
    with pytest.raises(TypeError, match="whole millimetres"):
        native.detect_q(p[:, :3], "hdl64")
    # whole millimetres in a float array are taken as they are
    a = native.detect_q(mm.astype(np.float64), "hdl64")
    np.testing.assert_array_equal(a["boxes"], native.detect_q(mm, "hdl64")["boxes"])
    # the unit rule's edge, and only for millimetres
    st = dict(n_points_in=1000, n_out_of_fov=0, n_too_far=0, n_too_close=250)
    assert native.frame_warning(st, "hdl64", unit="mm") is None
    assert "millimetres" in native.frame_warning(dict(st, n_too_close=251), "hdl64", unit="mm")
    assert native.frame_warning(dict(st, n_too_close=251), "hdl64") is None
    with pytest.raises(ValueError, match="unit"):
        native.frame_warning(st, "hdl64", unit="cm")
