# SPDX-License-Identifier: MIT
"""python -m lidet_tools.mount: the mount height read from scans by the library's ground stage."""
import json
import subprocess
import sys

import numpy as np

from lidet_tools import kitti, mount
from lidet_tools.sim.simulate import simulate_scan


def test_estimates_simulated_mounts(need_lib):
    for h in (0.4, 1.0):
        est = [mount.estimate(simulate_scan("vlp16", seed=8100, index=k, mount_height_m=h).points, "vlp16")
               for k in range(3)]
        med = np.median([e for e, _ in est])
        assert abs(med - h) < 0.1, (h, est)
        assert all(n >= 8 for _, n in est)
    e, n = mount.estimate(simulate_scan("hdl64", seed=8100, index=0).points, "hdl64")
    assert abs(e - 1.73) < 0.15 and n >= 8
    # an empty scan has no plane: nan, not an exception
    e, n = mount.estimate(np.zeros((0, 4), np.float32), "vlp16")
    assert np.isnan(e) and n == 0


def test_cli(tmp_path, need_lib):
    d = tmp_path / "scans" / "velodyne"
    d.mkdir(parents=True)
    for k in range(2):
        simulate_scan("vlp16", seed=8101, index=k, mount_height_m=1.0).points.astype(np.float32).tofile(
            d / f"{k:06d}.bin")
    r = subprocess.run([sys.executable, "-m", "lidet_tools.mount", str(tmp_path / "scans"), "--sensor", "vlp16",
                        "--json"], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    js = json.loads(r.stdout)
    assert len(js["scans"]) == 2 and abs(js["mount_height_m"] - 1.0) < 0.15 and js["profile_mount_height_m"] == 0.5
    r = subprocess.run([sys.executable, "-m", "lidet_tools.mount", str(d / "000000.bin"), "--sensor", "vlp16"],
                       capture_output=True, text=True)
    assert r.returncode == 0 and "lidet detect --mount-height" in r.stdout
    (tmp_path / "empty").mkdir()
    bad = tmp_path / "bad.bin"
    bad.write_bytes(b"\0" * 18)  # not a whole number of 16-byte records
    for args, msg in (([str(tmp_path / "empty")], "no scans"), ([str(bad)], "bad.bin"),
                      ([str(d), "--sensor", "nosuch"], "unknown sensor")):
        r = subprocess.run([sys.executable, "-m", "lidet_tools.mount", *args], capture_output=True, text=True)
        assert r.returncode == 1 and msg in r.stderr, (args, r.stderr)
    assert kitti.read_bin(d / "000000.bin").shape[1] == 4


def test_warns_when_the_planes_lie_at_the_sensors_height(tmp_path, need_lib):
    """An estimate below LOW_MOUNT_M (a sensor on the surface it sees, no floor in view) gives a warning on stderr
    and in the JSON; a plausible one none."""
    for h, warned in ((0.05, True), (0.4, False)):
        f = tmp_path / f"m{h}.bin"
        simulate_scan("vlp16", seed=8100, index=0, mount_height_m=h).points.astype(np.float32).tofile(f)
        r = subprocess.run([sys.executable, "-m", "lidet_tools.mount", str(f), "--sensor", "vlp16", "--json"],
                           capture_output=True, text=True)
        assert r.returncode == 0, r.stderr
        js = json.loads(r.stdout)
        assert (js["mount_height_m"] < mount.LOW_MOUNT_M) == warned
        assert ("warning:" in r.stderr) == warned and (js["warning"] is not None) == warned
        r = subprocess.run([sys.executable, "-m", "lidet_tools.mount", str(f), "--sensor", "vlp16"],
                           capture_output=True, text=True)
        assert r.returncode == 0 and ("lidet detect --mount-height" in r.stdout) != warned


def test_warns_when_the_cloud_is_not_in_lidets_frame(tmp_path, need_lib):
    """A scan turned upside down (y and z negated: the ground above the sensor) leaves many of its points outside
    the sensor's beams; the tool says so, on stderr and in the JSON, and gives no --mount-height advice. The scan
    as simulated puts none there."""
    p = simulate_scan("hdl64", seed=8100, index=0).points.astype(np.float32)
    q = p.copy()
    q[:, 1:3] *= -1.0
    assert mount.out_of_beams(p, "hdl64") == 0.0 and mount.out_of_beams(q, "hdl64") > mount.OUT_OF_BEAMS_SHARE
    for pts, warned in ((p, False), (q, True)):
        f = tmp_path / f"s{int(warned)}.bin"
        pts.tofile(f)
        r = subprocess.run([sys.executable, "-m", "lidet_tools.mount", str(f), "--sensor", "hdl64", "--json"],
                           capture_output=True, text=True)
        assert r.returncode == 0, r.stderr
        w = json.loads(r.stdout)["warning"]
        assert (w is not None and "x forward, y left, z up" in w and "outside the hdl64's beams" in w) == warned
        r = subprocess.run([sys.executable, "-m", "lidet_tools.mount", str(f), "--sensor", "hdl64"],
                           capture_output=True, text=True)
        assert r.returncode == 0 and ("lidet detect --mount-height" in r.stdout) != warned
