# SPDX-License-Identifier: MIT
"""Property-based tests (hypothesis) of the Python readers: whatever bytes or text a file holds, a reader
returns well-formed, finite data or raises ValueError naming the file (and the line for text formats),
never another exception from deep inside numpy or the parser."""
import pathlib
import tempfile

import numpy as np
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from lidet_tools import kitti

SETTINGS = settings(max_examples=100, deadline=None, suppress_health_check=[HealthCheck.too_slow])
TMP = pathlib.Path(tempfile.mkdtemp(prefix="lidet_readers_"))

#: tokens a hostile or broken file may hold
TOKENS = st.sampled_from(["0", "1", "-1", "1.5", "1e30", "-1e-30", "nan", "NaN", "inf", "-inf", "x", "", "1,5",
                          "Car", "Pedestrian", "DontCare", "P2:", "Tr_velo_to_cam:", "R0_rect:", "#", "1e999"])
LINES = st.lists(st.lists(TOKENS, max_size=18).map(" ".join), max_size=6).map("\n".join)


def _write(name, data):
    p = TMP / name
    if isinstance(data, str):
        p.write_text(data)
    else:
        p.write_bytes(data)
    return p


@SETTINGS
@given(st.binary(max_size=200))
def test_read_bin_any_bytes(data):
    p = _write("s.bin", data)
    try:
        pts = kitti.read_bin(p)
    except ValueError as e:
        assert str(p) in str(e) and len(data) % 16 != 0
        return
    assert pts.shape == (len(data) // 16, 4) and pts.dtype == np.float32


@SETTINGS
@given(st.binary(max_size=64), st.integers(0, 20))
def test_read_label_any_bytes(data, n):
    p = _write("s.label", data)
    try:
        sem, inst = kitti.read_label(p, n_points=n)
    except ValueError as e:
        assert str(p) in str(e)
        assert len(data) % 4 != 0 or len(data) // 4 != n
        return
    assert len(sem) == len(inst) == n


@SETTINGS
@given(LINES)
def test_read_label2_any_text(text):
    p = _write("l.txt", text)
    try:
        objs = kitti.read_label2(p)
    except ValueError as e:
        assert str(p) in str(e) and ":" in str(e).replace(str(p), "", 1)  # file:line
        return
    for o in objs:
        assert np.all(np.isfinite(o.loc)) and np.isfinite([o.h, o.w, o.l, o.ry, o.alpha]).all()


@SETTINGS
@given(LINES)
def test_read_boxes_any_text(text):
    p = _write("b.txt", text)
    try:
        boxes = kitti.read_boxes(p)
    except ValueError as e:
        assert str(p) in str(e)
        return
    for b in boxes:
        v = [b.x, b.y, b.z, b.l, b.w, b.h, b.yaw, b.score]
        assert np.isfinite(v).all() and min(b.l, b.w, b.h) >= 0


@SETTINGS
@given(LINES)
def test_read_calib_any_text(text):
    p = _write("c.txt", text)
    try:
        c = kitti.read_calib(p)
    except ValueError as e:
        assert str(p) in str(e)
        return
    assert c.P2.shape == (3, 4) and np.isfinite(c.P2).all() and np.isfinite(c.Tr_velo_to_cam).all()


def test_nan_fields_name_the_line(tmp_path):
    p = tmp_path / "b.txt"
    p.write_text("Car 1 2 3 4 2 1.5 0 1\nCar nan 2 3 4 2 1.5 0 1\n")
    try:
        kitti.read_boxes(p)
    except ValueError as e:
        assert f"{p}:2: non-finite" in str(e)
    else:
        raise AssertionError("NaN accepted")
