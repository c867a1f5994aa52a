# SPDX-License-Identifier: MIT
"""The firmware worst-case benchmark (tools/bench/bench_fw_worst.py): the rings it gives scans that have none (each
point's nearest beam, in the sensor's ring order) and, where the Arm toolchain and QEMU are installed, the one
image it builds and runs, measured on the typical scan as the firmware ctest measures it."""
import pathlib
import shutil

import numpy as np
import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]


def test_rings_of_points_at_each_beam(bench_mod):
    from lidet_tools.sensors import get_sensor
    m = bench_mod("fw_worst")
    el = np.asarray(get_sensor("vlp16").beam_elev_rad, np.float64)
    rng = np.random.default_rng(3)
    ring = rng.integers(0, len(el), 500)
    r = rng.uniform(2, 80, 500)
    az = rng.uniform(-np.pi, np.pi, 500)
    e = el[ring] + rng.uniform(-0.004, 0.004, 500)  # within a fraction of the 2-degree spacing
    pts = np.stack([r * np.cos(e) * np.cos(az), r * np.cos(e) * np.sin(az), r * np.sin(e)], 1).astype(np.float32)
    assert (m.rings_of(pts) == ring).all()
    # the simulated sample's own rings: the nearest beam is the ring the simulator wrote
    scan = np.fromfile(ROOT / "tests/data/sim_vlp16/velodyne/000000.bin", np.float32).reshape(-1, 4)
    sim_ring = np.fromfile(ROOT / "tests/data/sim_vlp16/ring/000000.bin", np.uint16)
    assert (m.rings_of(scan[:, :3]) == sim_ring).mean() > 0.99


@pytest.mark.skipif(shutil.which("arm-none-eabi-gcc") is None or shutil.which("qemu-system-arm") is None,
                    reason="no Arm cross compiler or qemu-system-arm (tools/scripts/install_deps.sh)")
def test_the_typical_scan_measures_as_the_firmware_ctest(tmp_path, bench_mod):
    """_measure on the ctest's scan gives the stage counts of build/firmware/mps2-an386-q's report when there is one
    (the same image), and sane counts otherwise"""
    import json
    m = bench_mod("fw_worst")
    data = ROOT / "tests/data/sim_vlp16"
    r = m._measure(tmp_path / "fw", data / "velodyne/000000.bin", data / "ring/000000.bin", "typical")
    assert "error" not in r, r
    d = r["insn"]["default"]
    assert set(m.STAGES) <= set(d) and d["scan"] > 10_000_000 and r["stats"]["default"]["classified"] > 0
    rep = ROOT / "build/firmware/mps2-an386-q/report.json"
    newest = max(f.stat().st_mtime for f in (ROOT / "lib").rglob("*") if f.is_file())
    if rep.exists() and rep.stat().st_mtime > newest:  # a report of today's library: the same image, the same counts
        assert json.loads(rep.read_text())["insn"]["default"] == d
