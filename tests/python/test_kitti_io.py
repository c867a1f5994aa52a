# SPDX-License-Identifier: MIT
import numpy as np
import pytest

from lidet_tools import kitti


def test_bin_roundtrip_and_truncation(tmp_path):
    pts = np.random.default_rng(0).normal(size=(100, 4)).astype(np.float32)
    p = tmp_path / "a" / "s.bin"
    kitti.write_bin(p, pts)
    assert np.array_equal(kitti.read_bin(p), pts)
    with open(p, "ab") as f:
        f.write(b"\0\0")
    with pytest.raises(ValueError, match="not a multiple"):
        kitti.read_bin(p)


def test_label_roundtrip(tmp_path):
    sem = np.array([10, 40, 30, 0], np.uint16)
    ins = np.array([3, 0, 7, 0], np.uint16)
    p = tmp_path / "l.label"
    kitti.write_label(p, sem, ins)
    raw = np.fromfile(p, "<u4")
    assert raw[0] == (3 << 16) | 10
    s2, i2 = kitti.read_label(p, 4)
    assert np.array_equal(s2, sem) and np.array_equal(i2, ins)
    with pytest.raises(ValueError, match="labels for"):
        kitti.read_label(p, 5)


def test_box_kitti_roundtrip_default_calib():
    c = kitti.Calib()
    rng = np.random.default_rng(1)
    for _ in range(50):
        b = kitti.Box3D("Car", rng.uniform(5, 40), rng.uniform(-10, 10), rng.uniform(-1.5, 0),
                        4.0, 1.7, 1.5, rng.uniform(-np.pi, np.pi))
        o = kitti.box_to_kitti(b, c)
        b2 = kitti.kitti_to_box(o, c)
        assert np.allclose([b.x, b.y, b.z], [b2.x, b2.y, b2.z], atol=1e-6)
        assert abs(np.angle(np.exp(1j * (b.yaw - b2.yaw)))) < 1e-6


def test_real_label2_roundtrip(real_dir):
    d = real_dir / "kitti" / "training"
    for f in sorted((d / "label_2").glob("*.txt")):
        c = kitti.read_calib(d / "calib" / f.name)
        for o in kitti.read_label2(f):
            if o.type == "DontCare":
                continue
            o2 = kitti.box_to_kitti(kitti.kitti_to_box(o, c), c)
            assert np.abs(o2.loc - o.loc).max() < 1e-3
            assert abs(np.angle(np.exp(1j * (o2.ry - o.ry)))) < 1e-3
