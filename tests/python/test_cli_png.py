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


@pytest.mark.parametrize("half,ticks", [(40, 9), (20, 9), (10, 11), (5, 11)])
def test_detect_png_range(cli, root, tmp_path, half, ticks):
    """`lidet detect --png-range M`: the scene shows M metres each way, its ticks every 10 m from 30 m, 5 m from
    15 m, 2 m from 6 m, 1 m below (9 ticks over -40..40 and -20..20, 11 over -10..10 and -5..5); a box drawn at
    the same place moves away from the centre by 40 / M; the default is 40; values outside [5, 200] are refused."""
    box = tmp_path / "box.txt"
    box.write_text("Car 3.0 0.0 -1.0 4.0 1.8 1.5 0.0 1.0\n")  # 3 m ahead
    png = tmp_path / f"r{half}.png"
    scan = root / "tests/data/sim_hdl64/velodyne/000000.bin"
    subprocess.run([cli, "detect", scan, "--gt", box, "--png", png, "--png-range", str(half)], check=True,
                   capture_output=True, cwd=root)
    a = np.asarray(Image.open(png).convert("RGB")).astype(int)
    top = _scene_top(a)
    bottom = top + SCENE
    assert _is(a[bottom + 1, LEFT:LEFT + SCENE + 1], AXIS).sum() == ticks
    green = _is(a[top:bottom, LEFT:LEFT + SCENE], np.array([60, 230, 90]))
    rows = np.nonzero(green.any(axis=1))[0]
    # the box's far end (5 m ahead) lies 5 / (M / 400) pixels above the centre row
    assert abs((SCENE // 2 - rows.min()) - 5.0 * 400 / half) <= 2
    if half == 40:
        dflt = tmp_path / "default.png"
        subprocess.run([cli, "detect", scan, "--gt", box, "--png", dflt], check=True, capture_output=True, cwd=root)
        b = np.asarray(Image.open(dflt).convert("RGB")).astype(int)
        assert np.array_equal(a[top - 1:], b[top - 1:])  # all but the title (it holds the run's time)
    for bad in ("4.9", "201", "nan", "x"):
        r = subprocess.run([cli, "detect", scan, "--png", tmp_path / "bad.png", "--png-range", bad],
                           capture_output=True, text=True, cwd=root)
        assert r.returncode != 0 and "--png-range needs metres in [5, 200]" in r.stderr


def test_track_png_range(cli, root, tmp_path):
    """`lidet track --png-range M` as lidet detect's: 11 ticks over -10..10 m, refused outside [5, 200]."""
    scan = root / "tests/data/sim_hdl64/velodyne/000000.bin"
    png = tmp_path / "t.png"
    subprocess.run([cli, "track", scan, scan, "--png", png, "--png-range", "10"], check=True, capture_output=True,
                   cwd=root)
    a = np.asarray(Image.open(png).convert("RGB")).astype(int)
    top = _scene_top(a)
    assert _is(a[top + SCENE + 1, LEFT:LEFT + SCENE + 1], AXIS).sum() == 11
    r = subprocess.run([cli, "track", scan, "--png", png, "--png-range", "300"], capture_output=True, text=True,
                       cwd=root)
    assert r.returncode != 0 and "--png-range needs metres in [5, 200]" in r.stderr
