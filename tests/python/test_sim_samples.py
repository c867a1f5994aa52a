# SPDX-License-Identifier: MIT
"""The simulated sample scans committed under tests/data are complete and consistent."""
import numpy as np
import pytest

from lidet_tools import kitti
from lidet_tools.sensors import get_sensor
from lidet_tools.sim import SUBDIRS, read_ring, scan_paths


@pytest.mark.parametrize("name,sensor", [("sim_hdl64", "hdl64"), ("sim_vlp16", "vlp16")])
def test_sample_scan_layout(root, name, sensor):
    d = root / "tests" / "data" / name
    for sub in SUBDIRS:
        assert (d / sub).is_dir(), sub
    p = scan_paths(d, "000000")
    pts = kitti.read_bin(p["velodyne"])
    sem, inst = kitti.read_label(p["labels"], len(pts))
    ring = read_ring(p["ring"])
    assert len(ring) == len(pts) > 10000
    assert ring.max() < get_sensor(sensor).rows
    assert np.isin(sem, kitti.GROUND_IDS).mean() > 0.3
    boxes = kitti.read_boxes(p["boxes"])
    assert boxes and all(b.cls in ("Car", "Van", "Truck", "Pedestrian", "Cyclist", "Misc") for b in boxes)
    kitti.read_label2(p["label_2"])
    kitti.read_calib(p["calib"])
    assert len(np.unique(inst[inst > 0])) >= len(boxes)
