# SPDX-License-Identifier: MIT
"""The host CLI `lidet` (ports/host): JSON contract, pictures, and clear errors on bad files."""
import json
import os
import subprocess

import numpy as np
import pytest
from PIL import Image

from lidet_tools import kitti



def _scan(tmp_path, n=5000, seed=0):
    rng = np.random.default_rng(seed)
    el = rng.uniform(-0.3, 0.03, n)
    az = rng.uniform(-np.pi, np.pi, n)
    r = rng.uniform(2, 60, n)
    pts = np.stack([r * np.cos(el) * np.cos(az), r * np.cos(el) * np.sin(az), r * np.sin(el), np.zeros(n)], 1)
    pts[:3, 0] = np.nan  # three non-finite points
    p = tmp_path / "scan.bin"
    kitti.write_bin(p, pts.astype(np.float32))
    return p, n


def test_project_json_contract(cli, tmp_path):
    scan, n = _scan(tmp_path)
    out = subprocess.run([cli, "project", scan, "--sensor", "hdl64", "--json", "--repeat", "3"],
                         capture_output=True, text=True, check=True).stdout
    j = json.loads(out)
    assert j["points"] == n
    assert j["dropped_nonfinite"] == 3
    assert j["projected"] + j["dropped"] == n
    assert j["project_ms"] > 0 and j["total_ms"] >= j["project_ms"]
    assert 0 < j["fill_ratio"] <= 1 and j["repeat"] == 3


def test_project_png_and_out(cli, tmp_path):
    scan, n = _scan(tmp_path)
    png, pix = tmp_path / "r.png", tmp_path / "pix.bin"
    subprocess.run([cli, "project", scan, "--sensor", "vlp16", "--png", png, "--out", pix], check=True,
                   capture_output=True)
    im = Image.open(png)
    im.load()  # decodes every byte: catches a broken zlib stream or CRC
    assert im.size == (1800, 16 * 16) and im.mode == "RGB"
    assert np.asarray(im).max() > 0
    pp = np.fromfile(pix, np.int32)
    assert pp.shape == (n,) and (pp[:3] == -1).all() and pp.max() < 16 * 1800


@pytest.mark.parametrize("nbytes", [15, 17, 100])
def test_odd_sized_file_is_a_clear_error(cli, tmp_path, nbytes):
    p = tmp_path / "odd.bin"
    p.write_bytes(b"\0" * nbytes)
    r = subprocess.run([cli, "project", p], capture_output=True, text=True)
    assert r.returncode == 1
    assert "not a multiple of 16" in r.stderr


def test_missing_file_and_bad_sensor(cli, tmp_path):
    r = subprocess.run([cli, "project", tmp_path / "nope.bin"], capture_output=True, text=True)
    assert r.returncode == 1 and "cannot open" in r.stderr
    scan, _ = _scan(tmp_path)
    r = subprocess.run([cli, "project", scan, "--sensor", "hdl65"], capture_output=True, text=True)
    assert r.returncode == 1 and "unknown sensor" in r.stderr
    r = subprocess.run([cli, "frobnicate", scan], capture_output=True, text=True)
    assert r.returncode == 1 and "unknown command" in r.stderr


def test_empty_scan_is_fine(cli, tmp_path):
    p = tmp_path / "empty.bin"
    p.write_bytes(b"")
    j = json.loads(subprocess.run([cli, "project", p, "--json"], capture_output=True, text=True,
                                  check=True).stdout)
    assert j["points"] == 0 and j["pixels_filled"] == 0


def test_real_kitti_reports_every_point(cli, real_dir):
    scan = real_dir / "kitti" / "training" / "velodyne" / "000000.bin"
    j = json.loads(subprocess.run([cli, "project", scan, "--sensor", "hdl64", "--json", "--repeat", "20"],
                                  capture_output=True, text=True, check=True).stdout)
    assert j["points"] == os.path.getsize(scan) // 16
    assert j["projected"] == j["points"] and "project_ms" in j
