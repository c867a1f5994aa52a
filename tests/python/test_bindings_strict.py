# SPDX-License-Identifier: MIT
"""The bindings refuse silent garbage with a clear exception (issue 19's hostile probe): transposed point
arrays, ring ids that do not fit or are not whole numbers, string or NaN ground masks, non-integer or
non-finite configuration values; the CLI refuses a labels file of another length."""
import subprocess

import numpy as np
import pytest

from lidet_tools import kitti, native

SCAN = "tests/data/sim_vlp16/velodyne/000000.bin"


@pytest.fixture(scope="module")
def pts(need_lib, root):
    return kitti.read_bin(root / SCAN)


def test_transposed_points(pts):
    with pytest.raises(ValueError, match="transposed"):
        native.project(np.ascontiguousarray(pts[:1000].T), "vlp16")
    with pytest.raises(TypeError, match="numeric"):
        native.project(np.array([["a", "b", "c"]]), "vlp16")


@pytest.mark.parametrize("ring", [65539, 3.7, np.nan, -1])
def test_bad_rings(pts, ring):
    with pytest.raises(ValueError, match="ring"):
        native.project(pts, "vlp16", ring=np.full(len(pts), ring))


def test_good_rings_and_out_of_range_counted(pts):
    img = native.project(pts, "vlp16", ring=np.full(len(pts), 200, np.int64))  # >= rows: the C side counts them
    assert img.stats["n_bad_ring"] == len(pts)
    img = native.project(pts, "vlp16", ring=np.zeros(len(pts), np.float64))  # whole floats are fine
    assert img.stats["n_bad_ring"] == 0


@pytest.mark.parametrize("ground", [np.array(["a"]), np.array([np.nan]), np.array([2])])
def test_bad_ground_masks(pts, ground):
    with pytest.raises((ValueError, TypeError), match="ground"):
        native.cluster(pts, "vlp16", ground=np.resize(ground, len(pts)))


@pytest.mark.parametrize("kv", [dict(min_points=9.9), dict(diagonals="no"), dict(theta_rad=float("nan")),
                                dict(max_steps=-1), dict(min_points="10")])
def test_bad_cluster_config(pts, kv):
    with pytest.raises((ValueError, TypeError)):
        native.cluster(pts, "vlp16", **kv)


def test_labels_file_of_another_length(cli, root, tmp_path):
    n = len(kitti.read_bin(root / SCAN))
    lab = tmp_path / "l.label"
    np.zeros(n + 5, np.uint32).tofile(lab)
    r = subprocess.run([str(cli), "cluster", str(root / SCAN), "--sensor", "vlp16", "--labels", str(lab)],
                       capture_output=True, text=True)
    assert r.returncode == 1 and "exactly" in r.stderr
    np.zeros(n, np.uint32).tofile(lab)
    r = subprocess.run([str(cli), "cluster", str(root / SCAN), "--sensor", "vlp16", "--labels", str(lab)],
                       capture_output=True, text=True)
    assert r.returncode == 0, r.stderr


def test_status_names_come_from_c():
    """native.status_names() reads every status of lidet_types.h from the C library (none copied by hand)."""
    import re
    from lidet_tools import native
    import pathlib
    hdr = (pathlib.Path(__file__).resolve().parents[2] / "lib" / "include" / "lidet" / "lidet_types.h").read_text()
    enum = {int(v): k for k, v in re.findall(r"\b(LIDET_(?:OK|TRUNCATED|ERR_[A-Z_]+))\s*=\s*(-?\d+)", hdr)}
    assert enum and native.status_names() == enum
    e = native.LidetError(-6, "x")
    assert e.name == "LIDET_ERR_NOT_FOUND" and "no such item" in str(e)
