# SPDX-License-Identifier: MIT
"""The CLI's bird's-eye-view pictures (`lidet detect/ground/cluster --png`, ports/host/cli_bev.c): the 800 x 800
scene in a larger canvas whose margins carry a title, axes in metres, a scale bar and a legend."""
import subprocess

import numpy as np
import pytest
from PIL import Image

TEXT = np.array([230, 230, 230])  # cli_bev.c k_text
BG = np.array([24, 24, 30])       # cli_bev.c k_bg
AXIS = np.array([160, 160, 170])  # cli_bev.c k_axis
SCENE, LEFT, RIGHT = 800, 72, 24  # scene size, MARGIN_L, MARGIN_R


def _is(a, c):
    return (a == c).all(axis=-1)


def _scene_top(a):
    """Row of the scene's first line: the frame (axis colour) runs one pixel above it, from column LEFT - 1."""
    rows = np.nonzero(_is(a[:, LEFT - 1:LEFT + SCENE + 1], AXIS).all(axis=1))[0]
    assert len(rows) >= 2, "no scene frame"
    assert rows[-1] - rows[0] == SCENE + 1  # the frame's top and bottom lines
    return rows[0] + 1


@pytest.mark.parametrize("cmd,extra", [
    ("detect", ["--gt", "tests/data/sim_hdl64/boxes/000000.txt"]),
    ("ground", []),
    ("cluster", []),
])
def test_bev_picture_has_title_axes_legend(cli, root, tmp_path, cmd, extra):
    png = tmp_path / f"{cmd}.png"
    subprocess.run([cli, cmd, root / "tests/data/sim_hdl64/velodyne/000000.bin", "--sensor", "hdl64", "--png", png,
                    *extra], check=True, capture_output=True, cwd=root)
    im = Image.open(png)
    im.load()
    assert im.mode == "RGB"
    w, h = im.size
    assert w == LEFT + SCENE + RIGHT and h > SCENE + 150  # a bigger canvas than the scene
    a = np.asarray(im).astype(int)
    top = _scene_top(a)
    assert top >= 60
    bottom = top + SCENE
    text = _is(a, TEXT)
    # title lines: text in the first two lines of the top margin, over most of a title's width
    title = text[:top - 30]
    assert title[:, :300].sum() > 300 and title.any(axis=1).sum() >= 2 * 10
    # left axis labels (x in metres) and the bottom ones (y), with ticks in the axis colour
    assert text[top:bottom, :LEFT - 8].sum() > 100
    assert text[bottom + 8:bottom + 8 + 24, LEFT - 20:LEFT + SCENE + 20].sum() > 100
    ticks = _is(a[bottom + 1, LEFT:LEFT + SCENE + 1], AXIS)
    assert ticks.sum() == 9  # every 10 m over 80 m: -40 .. 40
    # legend and scale bar under the axis: text, and swatches in the colours the scene uses
    below = a[bottom + 60:]
    assert _is(below, TEXT).sum() > 500
    scene = a[top:bottom, LEFT:LEFT + SCENE].reshape(-1, 3)
    colours = {tuple(c) for c in np.unique(below.reshape(-1, 3), axis=0)} - {tuple(BG), tuple(TEXT), tuple(AXIS)}
    used = {tuple(c) for c in np.unique(scene, axis=0)}
    assert len(colours & used) >= 2
    # the top margin holds only background and text: nothing of the scene is drawn over it
    assert (_is(a[:top - 1], BG) | text[:top - 1]).all()


def test_detect_legend_lists_classes(cli, root, tmp_path):
    """The detection classes' colours (car red, cyclist cyan, pedestrian yellow) and the ground truth's green are
    in the legend, under the scene, even when no box of a class is drawn."""
    png = tmp_path / "d.png"
    subprocess.run([cli, "detect", root / "tests/data/sim_vlp16/velodyne/000000.bin", "--sensor", "vlp16", "--gt",
                    root / "tests/data/sim_vlp16/boxes/000000.txt", "--png", png], check=True, capture_output=True)
    a = np.asarray(Image.open(png)).astype(int)
    legend = a[_scene_top(a) + SCENE + 60:]
    for c in [(255, 80, 60), (60, 220, 255), (255, 220, 40), (60, 230, 90)]:
        assert _is(legend, np.array(c)).sum() >= 100, c
