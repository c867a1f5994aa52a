# SPDX-License-Identifier: MIT
"""Proposal dataset builder (lidet_tools.train.dataset): labelling rules, frames, splits, errors."""
import numpy as np
import pytest

from lidet_tools.train import dataset as D
from lidet_tools.train import models as M


def test_points_in_box_rotated_and_margin():
    box = (10.0, 5.0, 0.0, 4.0, 2.0, 1.5, np.pi / 2)  # l along +y after the rotation
    pts = np.array([[10.0, 6.9, 0.0], [11.2, 5.0, 0.0], [10.0, 5.0, 0.8], [10.0, 7.05, 0.0]])
    m = D.points_in_box(pts, box)
    assert m.tolist() == [True, False, False, False]
    assert D.points_in_box(pts, box, margin=0.1).tolist() == [True, False, True, True]


def test_box_model_frame_round_trip():
    rng = np.random.default_rng(0)
    mean = rng.uniform(-30, 30, (20, 3)).astype(np.float32)
    box = np.concatenate([mean + rng.normal(0, 1, (20, 3)), rng.uniform(0.5, 4, (20, 3)),
                          rng.uniform(-np.pi, np.pi, (20, 1))], 1).astype(np.float32)
    bm = D.box_to_model_frame(box, mean)
    back = D.box_from_model_frame(bm, mean)
    np.testing.assert_allclose(back[:, :6], box[:, :6], atol=1e-4)
    dyaw = (back[:, 6] - box[:, 6] + np.pi) % (2 * np.pi) - np.pi
    np.testing.assert_allclose(dyaw, 0, atol=1e-5)
    # a box straight ahead along the mean's ray has y = 0 in the model frame
    c = mean[:, :2] / np.linalg.norm(mean[:, :2], axis=1, keepdims=True)
    ahead = box.copy()
    ahead[:, 0:2] = mean[:, :2] + 2.0 * c
    np.testing.assert_allclose(D.box_to_model_frame(ahead, mean)[:, 1], 0, atol=1e-4)


def test_sim_scans_labelled_by_the_rules(need_lib):
    parts = [D._job(("sim", s, 7, s, None), "hdl64", dict(D.DEFAULTS)) for s in range(2)]
    d = D.concat(parts)
    lab = d["label"]
    idm = lab >= 0
    assert idm.sum() >= 5 and (~idm).sum() >= 20
    # ID: mostly one object, holding most of it, with a box target near the proposal
    assert (d["share"][idm] >= 0.8).all() and (d["recall"][idm] >= 0.5).all()
    assert not np.isnan(d["box"][idm]).any() and np.isnan(d["box"][~idm]).all()
    assert (np.hypot(d["box"][idm, 0], d["box"][idm, 1]) < 3.0).all()
    # the size target matches the class (cars are long)
    car = lab == 0
    if car.any():
        assert d["box"][car, 3].min() > 2.5
    # points are in the model frame: centred, and the mean sits on +x
    np.testing.assert_allclose(d["points"], M.to_model_frame(d["xyz"], d["mean"]), atol=0)
    assert d["points"].shape[1:] == (64, 3) and d["voxel"].dtype == np.int16
    assert d["split"].tolist() == [0] * len(parts[0]["label"]) + [1] * len(parts[1]["label"])
    # OOD holds no well-covered pure road user
    ood = ~idm
    assert not ((d["share"][ood] >= 0.8) & (d["recall"][ood] >= 0.5) & np.isin(d["sem"][ood], [10, 30, 31])).any()


def test_bad_input_errors(tmp_path):
    with pytest.raises(FileNotFoundError, match="label_2"):
        D.kitti_scans(tmp_path)
    for s in ("velodyne", "label_2", "calib"):
        (tmp_path / s).mkdir()
    with pytest.raises(ValueError, match="no velodyne"):
        D.kitti_scans(tmp_path)
    assert D.main(["--kitti", str(tmp_path / "nope"), "--out", str(tmp_path / "x.npz")]) == 2
    with pytest.raises(FileNotFoundError):
        D.load(tmp_path / "missing.npz")


def test_real_kitti_frames(real_dir, need_lib, tmp_path):
    out = tmp_path / "real.npz"
    assert D.main(["--kitti", str(real_dir / "kitti" / "training"), "--split", "test", "--out", str(out),
                   "--no-progress"]) == 0
    d = D.load(out)
    assert (d["split"] == 2).all() and (d["label"] >= 0).sum() >= 1


def test_jobs_do_not_change_the_dataset(need_lib, tmp_path):
    """--jobs 2 (worker processes) gives the same proposals, in the same order, as --jobs 1."""
    outs = []
    for j in (1, 2):
        out = tmp_path / f"j{j}.npz"
        assert D.main(["--sensor", "vlp16", "--mounts", "0.5", "--sim", "1,1,1", "--seed", "5", "--jobs", str(j),
                       "--out", str(out), "--no-progress"]) == 0
        outs.append(D.load(out))
    a, b = outs
    assert a["meta"]["jobs"] == 1 and b["meta"]["jobs"] == 2
    for k in ("points", "voxel", "label", "box", "split", "scan"):
        np.testing.assert_array_equal(a[k], b[k])
    assert sorted(set(a["split"].tolist())) == [0, 1, 2]


def test_sim_scans_run_the_stages_at_their_mount_height(monkeypatch, need_lib):
    """A simulated robot mount is processed with that mount height (as `lidet detect --mount-height` configures
    the detector on that robot), a scan at the profile's height with the profile."""
    from lidet_tools import native
    seen = []
    real_ground = native.ground

    def spy(points, sensor="hdl64", *a, **k):
        seen.append(sensor.mount_height_m)
        return real_ground(points, sensor, *a, **k)
    monkeypatch.setattr(native, "ground", spy)
    out = D._job(("sim", 0, 2000, 0, 1.0), "vlp16", dict(D.DEFAULTS))
    D._job(("sim", 0, 2000, 1, None), "vlp16", dict(D.DEFAULTS))
    assert seen == [1.0, 0.5]
    assert len(out["label"]) > 0 and (out["label"] >= 0).any()


def test_sim_sensors_mix_presets_at_every_mount(need_lib, tmp_path):
    """--sim-sensors: the simulated scans cycle over the presets (fastest) and the mounts, each scan made and run
    through the C stages as its own sensor; unknown presets and --sim-sensors without --sim are refused."""
    import argparse
    a = argparse.Namespace(sim="4,0,0", mounts="0.7,1.4", seed=9, sim_sensors="vlp32c,os1-32", kitti=None,
                           semantickitti=None, boxes=None, split=None)
    tasks = D.build_tasks(a)
    assert [(t[4], t[5]) for t in tasks] == [(0.7, "vlp32c"), (0.7, "os1-32"), (1.4, "vlp32c"), (1.4, "os1-32")]
    out = tmp_path / "mix.npz"
    assert D.main(["--sensor", "vlp32c", "--sim-sensors", "vlp32c,os1-32", "--mounts", "1.0", "--sim", "2,0,0",
                   "--seed", "9", "--out", str(out), "--no-progress"]) == 0
    d = D.load(out)
    names = [str(n) for n in d["scan_names"]]
    assert names[0].startswith("sim:vlp32c:") and names[1].startswith("sim:os1-32:")
    assert d["meta"]["sim_sensors"] == "vlp32c,os1-32"
    # each scan's proposals are those of its own preset: the os1-32 scan alone gives the same proposals
    one = D._job(("sim", 0, 9, 1, 1.0, "os1-32"), "vlp32c", dict(D.DEFAULTS))
    np.testing.assert_array_equal(d["points"][d["scan"] == 1], one["points"])
    with pytest.raises(SystemExit):
        D.main(["--sim-sensors", "vlp32c,nope", "--sim", "1,0,0", "--out", str(out), "--no-progress"])
    with pytest.raises(SystemExit):
        D.main(["--sim-sensors", "vlp32c", "--kitti", str(tmp_path), "--out", str(out), "--no-progress"])
