# SPDX-License-Identifier: MIT
"""`lidet cluster`: JSON contract, ids per point equal the bindings', picture."""
import json
import subprocess

import numpy as np
from PIL import Image

from lidet_tools import native



def _scene(tmp_path):
    """Flat ground 1.73 m below the sensor plus two upright faces (a car front, a pedestrian)."""
    rng = np.random.default_rng(3)
    g = np.c_[rng.uniform(-30, 30, 30000), rng.uniform(-30, 30, 30000), np.full(30000, -1.73)]
    faces = []
    for c, w, h, n in [((10, 0, -0.9), 1.8, 1.5, 5000), ((8, 4, -0.85), 0.5, 1.7, 1500)]:
        c = np.asarray(c, float)
        t = np.array([-c[1], c[0], 0]) / np.hypot(c[0], c[1])
        faces.append(c + rng.uniform(-.5, .5, (n, 1)) * w * t + rng.uniform(-.5, .5, (n, 1)) * h * np.array([0, 0, 1]))
    pts = np.r_[g, *faces]
    pts = np.c_[pts, np.zeros(len(pts))].astype(np.float32)
    p = tmp_path / "scene.bin"
    pts.tofile(p)
    return p, pts


def test_cluster_json_out_png(cli, tmp_path):
    scan, pts = _scene(tmp_path)
    out, png = tmp_path / "ids.bin", tmp_path / "bev.png"
    r = subprocess.run([cli, "cluster", scan, "--sensor", "hdl64", "--json", "--repeat", "3", "--out", out,
                        "--png", png], capture_output=True, text=True, check=True)
    j = json.loads(r.stdout)
    assert j["points"] == len(pts) and j["clusters"] == 2 and j["proposals"] == 2
    assert j["cluster_ms"] > 0 and j["total_ms"] >= j["cluster_ms"]
    ids = np.fromfile(out, np.uint32)
    assert ids.shape == (len(pts),)
    high = pts[:, 2] > -1.4  # the flat ground cut (0.25 m above the ground) takes the faces' feet
    car = np.unique(ids[30000:35000][high[30000:35000]])
    ped = np.unique(ids[35000:][high[35000:]])
    assert len(car) == 1 and len(ped) == 1 and car[0] > 0 and ped[0] > 0 and car[0] != ped[0]
    # the same ids as the bindings with the same ground: the ground stage (mask + its per-sector
    # planes) when the library has it, as the CLI does; else the flat ground cut
    if hasattr(native, "ground"):
        gr = native.ground(pts, "hdl64")
        c = native.cluster(pts, "hdl64", ground=gr.mask_point, planes=gr.planes)
    else:
        ground = pts[:, 2] < -(1.73 - 0.25)
        c = native.cluster(pts, "hdl64", ground=ground)
    np.testing.assert_array_equal(c.point_labels, ids)
    im = Image.open(png)
    # the 800 x 800 scene in its frame (title, axes, legend: tests/python/test_cli_png.py)
    assert im.size[0] == 800 + 96 and im.size[1] > 800 + 150


def test_cluster_labels_option_and_errors(cli, tmp_path):
    scan, pts = _scene(tmp_path)
    lab = np.where(pts[:, 2] < -1.7, 40, 10).astype(np.uint32)
    lp = tmp_path / "scene.label"
    lab.tofile(lp)
    j = json.loads(subprocess.run([cli, "cluster", scan, "--labels", lp, "--json"], capture_output=True, text=True,
                                  check=True).stdout)
    assert j["ground"] == "labels" and j["clusters"] == 2
    lab[:10].tofile(lp)
    r = subprocess.run([cli, "cluster", scan, "--labels", lp], capture_output=True, text=True)
    assert r.returncode != 0 and "labels" in r.stderr


def test_cluster_set_option(cli, root, tmp_path):
    """--set overrides lidet_cluster_cfg_t fields: the rescue on the shipped VLP-16 sample gives the
    bindings' ids with and without it; unknown keys and invalid values are clear errors."""
    d = root / "tests" / "data" / "sim_vlp16"
    scan, lp = d / "velodyne" / "000000.bin", d / "labels" / "000000.label"
    pts = np.fromfile(scan, np.float32).reshape(-1, 4)
    ground = np.isin(np.fromfile(lp, np.uint32) & 0xFFFF, [40, 44, 48, 49, 60, 72])
    out = tmp_path / "ids.bin"
    for sets, cfg in [([], {}), (["--set", "rescue_gap_m=0"], {"rescue_gap_m": 0.0}),
                      (["--set", "rescue_cols=3", "--set", "min_points=8"], {"rescue_cols": 3, "min_points": 8})]:
        j = json.loads(subprocess.run([cli, "cluster", scan, "--sensor", "vlp16", "--labels", lp, "--json",
                                       "--out", out, *sets], capture_output=True, text=True, check=True).stdout)
        c = native.cluster(pts, "vlp16", ground=ground, **cfg)
        np.testing.assert_array_equal(np.fromfile(out, np.uint32), c.point_labels)
        assert j["clusters"] == len(c) and j["fragments"] == c.stats["n_fragments"]
        assert j["rescue_pixels"] == c.stats["n_rescue_pixels"]
        assert (j["fragments"] == 0) == (cfg.get("rescue_gap_m") == 0.0)
    for bad, msg in [("nope=1", "bad --set"), ("rescue_cols=x", "bad --set"), ("min_points=-1", "bad --set"),
                     ("rescue_cols=16", "cluster init"), ("theta_rad=2", "cluster init")]:
        r = subprocess.run([cli, "cluster", scan, "--sensor", "vlp16", "--set", bad], capture_output=True, text=True)
        assert r.returncode == 1 and msg in r.stderr, (bad, r.stderr)
