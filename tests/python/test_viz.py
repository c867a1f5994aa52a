# SPDX-License-Identifier: MIT
"""Pictures: BEV (synthetic scene and a real KITTI frame), precision-recall curves, energy histogram."""
import os

os.environ.setdefault("MPLBACKEND", "Agg")

import numpy as np
import pytest
from PIL import Image

from lidet_tools import kitti
from lidet_tools.eval import kitti_ap, synth
from lidet_tools.viz import bev, cli, curves
from lidet_tools.viz.demo import demo_scene


def check_png(path, min_w=500, min_colours=12, min_ink=0.02):
    """A valid PNG, large enough, with more than a few colours and a fair share of non-white pixels."""
    with open(path, "rb") as f:
        assert f.read(8) == b"\x89PNG\r\n\x1a\n"
    im = Image.open(path)
    im.verify()
    a = np.asarray(Image.open(path).convert("RGB"))
    assert a.shape[1] >= min_w and a.shape[0] >= 300
    assert len(np.unique(a.reshape(-1, 3), axis=0)) >= min_colours
    assert (a.min(axis=2) < 235).mean() >= min_ink
    return a


@pytest.fixture(scope="module")
def scene():
    return demo_scene()


def test_demo_scene_is_a_scan(scene):
    pts, clusters, ground, gt, pred = scene
    assert pts.shape[1] == 4 and len(pts) > 20000
    assert ground.mean() > 0.5 and len(np.unique(clusters[~ground])) > 5
    # every road user is hit by some rays, except where it is in another's shadow
    assert sum(((np.abs(pts[:, 0] - b.x) < b.l / 2) & (np.abs(pts[:, 1] - b.y) < b.l / 2)).any()
               for b in gt) >= 8


def test_plot_bev_modes(tmp_path, scene):
    import matplotlib.pyplot as plt
    pts, clusters, ground, gt, pred = scene
    for mode, labels in (("cluster", clusters), ("ground", ground), ("height", None),
                         ("semantic", np.where(ground, 40, 10).astype(np.uint32))):
        fig = bev.plot_bev(pts, labels, gt, pred, color_by=mode, ground=ground if mode == "cluster" else None,
                           xlim=(-20, 45), ylim=(-15, 15), figsize=(6, 4))
        ax = fig.axes[0]
        assert ax.get_aspect() == 1.0 and "x [m]" in ax.get_xlabel() and "y [m]" in ax.get_ylabel()
        labels_txt = [t.get_text() for t in ax.get_legend().get_texts()]
        assert any("ground truth" in t for t in labels_txt) and any("predicted Car" in t for t in labels_txt)
        if mode in ("cluster", "height"):
            fig.savefig(tmp_path / f"{mode}.png")
            check_png(tmp_path / f"{mode}.png")
        plt.close(fig)
    # arrays are accepted as boxes too
    arr = np.array([[b.x, b.y, b.z, b.l, b.w, b.h, b.yaw, b.score] for b in pred])
    fig = bev.plot_bev(pts, None, None, arr)
    assert any("predicted object" in t.get_text() for t in fig.axes[0].get_legend().get_texts())
    plt.close(fig)
    with pytest.raises(ValueError):
        bev.plot_bev(pts, clusters[:10])


def test_cli_bev_and_demo(tmp_path, scene):
    pts, clusters, ground, gt, pred = scene
    kitti.write_bin(tmp_path / "s.bin", pts)
    clusters.astype("<u4").tofile(tmp_path / "c.bin")
    ground.astype("<u1").tofile(tmp_path / "g.bin")
    kitti.write_boxes(tmp_path / "gt.txt", gt)
    kitti.write_boxes(tmp_path / "pred.txt", pred)
    out = tmp_path / "o" / "bev.png"
    assert cli.main(["bev", str(tmp_path / "s.bin"), "--point-labels", str(tmp_path / "c.bin"),
                     "--ground", str(tmp_path / "g.bin"), "--gt", str(tmp_path / "gt.txt"),
                     "--pred", str(tmp_path / "pred.txt"), "--xlim=-20,45", "--ylim=-15,15",
                     "--out", str(out)]) == 0
    check_png(out)
    # a label_2 file without --calib is refused with a message, not a traceback
    gt_l, _ = synth.synth_kitti(1, seed=0)
    synth.write_frames(tmp_path / "l2", gt_l)
    assert cli.main(["bev", str(tmp_path / "s.bin"), "--gt", str(tmp_path / "l2" / "000000.txt"),
                     "--out", str(tmp_path / "x.png")]) == 2
    assert cli.main(["demo", "--out", str(tmp_path / "demo.png")]) == 0
    check_png(tmp_path / "demo.png")


def test_pr_curves_and_energy(tmp_path):
    import matplotlib.pyplot as plt
    gt_l, dt_l = synth.synth_kitti(200, seed=2)
    synth.write_frames(tmp_path / "gt", gt_l)
    synth.write_frames(tmp_path / "dt", dt_l)
    res = kitti_ap.evaluate_dirs(tmp_path / "gt", tmp_path / "dt", warn=False)
    fig = curves.plot_pr(res, "bev")
    assert len(fig.axes) == 3 and fig.axes[0].get_xlabel() == "recall"
    fig.savefig(tmp_path / "pr.png")
    plt.close(fig)
    check_png(tmp_path / "pr.png")
    assert cli.main(["pr", "--gt", str(tmp_path / "gt"), "--pred", str(tmp_path / "dt"),
                     "--metric", "3d", "--out", str(tmp_path / "pr2.png")]) == 0
    check_png(tmp_path / "pr2.png")
    rng = np.random.default_rng(0)
    e_id, e_ood = rng.normal(-8, 1.5, 2000), rng.normal(-3, 1.5, 500)
    assert curves.energy_threshold(e_id, 0.95) == pytest.approx(np.quantile(e_id, 0.95))
    fig = curves.plot_energy_hist(e_id, e_ood)
    assert "95.0 % ID" in fig.axes[0].get_legend().get_texts()[-1].get_text() or \
        any("95.0 % ID" in t.get_text() for t in fig.axes[0].get_legend().get_texts())
    plt.close(fig)
    np.save(tmp_path / "id.npy", e_id)
    np.savetxt(tmp_path / "ood.txt", e_ood)
    assert cli.main(["energy", "--id", str(tmp_path / "id.npy"), "--ood", str(tmp_path / "ood.txt"),
                     "--out", str(tmp_path / "e.png")]) == 0
    check_png(tmp_path / "e.png", min_colours=5)


def test_real_kitti_frame_bev(real_dir, tmp_path):
    """The docs/EVALUATION.md command, on a real KITTI frame with its ground-truth boxes."""
    k = real_dir / "kitti" / "training"
    out = tmp_path / "kitti_000001_bev.png"
    assert cli.main(["bev", str(k / "velodyne" / "000001.bin"), "--gt", str(k / "label_2" / "000001.txt"),
                     "--calib", str(k / "calib" / "000001.txt"), "--xlim=0,80", "--ylim=-40,40",
                     "--out", str(out)]) == 0
    a = check_png(out, min_w=800, min_colours=50)
    # the ground-truth green is drawn (three boxes in this frame)
    green = (np.abs(a.astype(int) - [0x2c, 0xa0, 0x2c]).sum(axis=2) < 40).sum()
    assert green > 200
