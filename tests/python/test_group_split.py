# SPDX-License-Identifier: MIT
"""lidet_tools.real.group_split: the deterministic k-means and the group shape test on made-up point sets (the
measurement on the real frames needs ../shared and the bindings: `python -m lidet_tools.real.group_split`)."""
from __future__ import annotations

import numpy as np

from lidet_tools.real.group_split import group_shaped, kmeans_along_axis


def _person(rng, x, y, n=120, ground=-1.73):
    """Points of a standing person: 0.45 m across, 1.75 m tall, feet on the ground."""
    return np.column_stack([x + rng.normal(0, 0.1, n), y + rng.normal(0, 0.08, n), ground + rng.uniform(0.1, 1.75, n)])


def test_kmeans_splits_people_side_by_side():
    rng = np.random.default_rng(3)
    xs = (-0.7, 0.0, 0.7)
    pts = np.concatenate([_person(rng, 15.0, y) for y in xs])  # three people in a row along y
    lab = kmeans_along_axis(pts[:, :2], 3)
    for j, y in enumerate(xs):  # each person lies in one part, and each part holds one person
        part = lab[j * 120:(j + 1) * 120]
        assert (part == part[0]).mean() > 0.97
    assert len(set(lab[::120].tolist())) == 3
    np.testing.assert_array_equal(lab, kmeans_along_axis(pts[:, :2], 3))  # deterministic


def test_group_shape():
    rng = np.random.default_rng(4)
    group = np.concatenate([_person(rng, 12.0, y) for y in (-0.5, 0.2, 0.9)])
    span = group_shaped(group)
    assert span is not None and 1.2 < span < 2.2
    assert group_shaped(_person(rng, 12.0, 0.0)) is None  # one person: too narrow to be a group
    car = np.column_stack([rng.uniform(10, 14.2, 400), rng.uniform(-0.9, 0.9, 400), rng.uniform(-1.7, -0.2, 400)])
    assert group_shaped(car) is None  # 4 m long
    far = group.copy()
    far[:, 0] += 40.0
    assert group_shaped(far) is None  # beyond 40 m
    assert group_shaped(group[:10]) is None  # too few points
