# SPDX-License-Identifier: MIT
"""Determinism (issue 19): the same scan gives byte-identical results across runs, through the CLI and the
bindings, and across builds: this build's CLI against the sanitizer build's (-O0, ASan + UBSan) when that
build exists ($LIDET_ASAN_BUILD_DIR, else build-asan/; `make test-asan` runs this file again with it). The
-O0 build is compared with this one by the ctest determinism_O0 (tests/determinism.cmake)."""
from __future__ import annotations

import os
import pathlib
import subprocess

import numpy as np
import pytest

from lidet_tools import kitti

ROOT = pathlib.Path(__file__).resolve().parents[2]
SCANS = [("hdl64", ROOT / "tests/data/sim_hdl64/velodyne/000000.bin"),
         ("vlp16", ROOT / "tests/data/sim_vlp16/velodyne/000000.bin")]


def run_dump(exe, scan, sensor, out):
    subprocess.run([str(exe), "detect", str(scan), "--sensor", sensor, "--dump", str(out)], check=True,
                   capture_output=True)
    return out.read_bytes()


def parse_dump(b: bytes, n_prop_points: int = 64):
    """cli_detect.c write_dump: per-point labels, cluster records + outcomes + proposals, detections."""
    assert b[:4] == b"LDTD"
    n, n_cl, n_det = np.frombuffer(b, np.uint32, 3, 4)
    off = 16
    rec = np.frombuffer(b, np.dtype([("id", "<u4"), ("g", "u1")]), int(n), off)
    off += int(n) * 5
    cl_size = 4 * 4 + 9 * 4 + n_prop_points * 12 + 3 * 8
    off += int(n_cl) * cl_size
    det = np.frombuffer(b, np.dtype([("cls", "<u4"), ("cid", "<u4"), ("np", "<u4"), ("f", "<f4", 10)]),
                        int(n_det), off)
    assert off + int(n_det) * 52 == len(b)
    return rec["id"], rec["g"], det


@pytest.mark.parametrize("sensor,scan", SCANS, ids=[s for s, _ in SCANS])
def test_cli_runs_identical(cli, tmp_path, sensor, scan):
    a = run_dump(cli, scan, sensor, tmp_path / "a.bin")
    b = run_dump(cli, scan, sensor, tmp_path / "b.bin")
    assert len(a) > 1000 and a == b


@pytest.mark.parametrize("sensor,scan", SCANS, ids=[s for s, _ in SCANS])
def test_cli_and_bindings_identical(cli, need_lib, tmp_path, sensor, scan):
    from lidet_tools import native
    ids, ground, det = parse_dump(run_dump(cli, scan, sensor, tmp_path / "d.bin"))
    d = native.detect(kitti.read_bin(scan), sensor)
    d2 = native.detect(kitti.read_bin(scan), sensor)
    assert len(det) == len(d.cls) > 0
    np.testing.assert_array_equal(ids, d.point_cluster)
    np.testing.assert_array_equal(ground, d.point_ground)
    np.testing.assert_array_equal(det["cls"], d.cls)
    np.testing.assert_array_equal(det["cid"], d.cluster_id)
    # floats bit for bit: score, energies, box
    got = np.column_stack([d.score, d.energy_cls, d.energy_box, d.box]).astype(np.float32)
    assert got.tobytes() == np.ascontiguousarray(det["f"]).tobytes()
    # the bindings twice
    assert d.point_cluster.tobytes() == d2.point_cluster.tobytes() and d.box.tobytes() == d2.box.tobytes()


def asan_cli():
    d = pathlib.Path(os.environ.get("LIDET_ASAN_BUILD_DIR", ROOT / "build-asan"))
    exe = d / "ports" / "host" / "lidet"
    if not exe.exists():
        pytest.skip(f"no sanitizer build at {d} (make test-asan builds it and runs this test with it)")
    return exe


@pytest.mark.parametrize("cmd", ["detect", "cluster", "ground", "project"])
@pytest.mark.parametrize("sensor,scan", SCANS, ids=[s for s, _ in SCANS])
def test_release_and_sanitizer_builds_identical(cli, tmp_path, sensor, scan, cmd):
    other = asan_cli()
    opt = "--dump" if cmd == "detect" else "--out"
    outs = []
    for i, exe in enumerate((cli, other)):
        p = tmp_path / f"{i}.bin"
        subprocess.run([str(exe), cmd, str(scan), "--sensor", sensor, opt, str(p)], check=True, capture_output=True)
        outs.append(p.read_bytes())
    assert len(outs[0]) > 0 and outs[0] == outs[1]


def test_detect_mount_height_argument():
    """native.detect(mount_height_m=...): the profile's own height changes nothing, a bad one is refused."""
    from lidet_tools import kitti, native
    pts = kitti.read_bin(ROOT / "tests" / "data" / "sim_vlp16" / "velodyne" / "000000.bin")
    a = native.detect(pts, "vlp16")
    b = native.detect(pts, "vlp16", mount_height_m=0.5)
    assert np.array_equal(a.box, b.box) and np.array_equal(a.point_ground, b.point_ground)
    c = native.detect(pts, "vlp16", mount_height_m=1.2)
    assert not np.array_equal(a.point_ground, c.point_ground)
    for bad in (float("nan"), -0.5, 11.0):
        with pytest.raises(ValueError, match="mount_height_m"):
            native.detect(pts, "vlp16", mount_height_m=bad)
