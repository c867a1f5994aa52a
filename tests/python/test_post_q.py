# SPDX-License-Identifier: MIT
"""The integer path's post-processing (lib/src/detector/lidet_post_q.c): BEV IoU, size check and NMS equal the numpy
reference (codegen/lidet_ref/post_q.py) bit for bit, and agree with the float detector's IoU."""
import math

import numpy as np
import pytest

from lidet_ref import post_q as ref

BAM = 2**32 / (2 * math.pi)


@pytest.fixture(scope="module")
def nq(need_lib):
    from lidet_tools import native
    return native


def _random_pairs(rng, n):
    """Overlapping-ish pairs of road-user-sized boxes; a's centre anywhere within 80 m."""
    a = np.zeros((n, 7), np.int64)
    a[:, 0:2] = rng.integers(-80_000, 80_001, (n, 2))
    a[:, 2] = rng.integers(-2000, 2001, n)
    a[:, 3] = rng.integers(300, 6001, n)
    a[:, 4] = rng.integers(300, 2501, n)
    a[:, 5] = rng.integers(500, 3001, n)
    a[:, 6] = rng.integers(-(2**31), 2**31, n)
    b = a.copy()
    b[:, 0:2] += rng.integers(-4000, 4001, (n, 2))
    b[:, 3] = np.clip(a[:, 3] + rng.integers(-800, 801, n), 1, None)
    b[:, 4] = np.clip(a[:, 4] + rng.integers(-500, 501, n), 1, None)
    b[:, 6] = a[:, 6] + rng.integers(-(2**30), 2**30, n)
    b[:, 6] = (b[:, 6] + 2**31) % 2**32 - 2**31
    return a, b


def test_iou_bit_exact_with_reference(nq):
    a, b = _random_pairs(np.random.default_rng(5), 3000)
    c = nq.bev_iou_q(a, b)
    r = np.array([ref.bev_iou(x, y) for x, y in zip(a.tolist(), b.tolist())])
    np.testing.assert_array_equal(c, r)
    assert (c > 0).mean() > 0.25 and (c == 0).any()  # the set exercises overlap and no overlap


def test_iou_agrees_with_float_detector(nq):
    a, b = _random_pairs(np.random.default_rng(6), 3000)
    q = nq.bev_iou_q(a, b) / 32768.0
    fa = np.column_stack([a[:, :6] / 1000.0, a[:, 6] / BAM]).astype(np.float32)
    fb = np.column_stack([b[:, :6] / 1000.0, b[:, 6] / BAM]).astype(np.float32)
    f = nq.bev_iou_float(fa, fb)
    # millimetre corners and half-mm rounding of intersections: well under 1e-3 IoU on road-user boxes
    assert np.max(np.abs(q - f)) < 2e-3


def test_iou_exact_cases(nq):
    box = [1000, 2000, 0, 4000, 2000, 1500, 0]
    same = nq.bev_iou_q([box], [box])[0]
    assert same == 32768
    half = [3000, 2000, 0, 4000, 2000, 1500, 0]  # shifted by half its length: 1/3
    assert nq.bev_iou_q([box], [half])[0] == 32768 // 3
    rot = list(box)
    rot[6] = 2**30  # 90 degrees: a 2x2 m overlap of 8 m^2 boxes -> 4 / 12
    assert abs(nq.bev_iou_q([box], [rot])[0] - 32768 // 3) <= 1
    far = [200_000, 0, 0, 4000, 2000, 1500, 0]
    assert nq.bev_iou_q([box], [far])[0] == 0
    bad = [0, 0, 0, 0, 2000, 1500, 0]  # zero length
    big = [0, 0, 0, 60_000, 2000, 1500, 0]
    assert nq.bev_iou_q([box, box], [bad, big]).tolist() == [0, 0]
    extreme = [2**31 - 1, -(2**31), 0, 50_000, 50_000, 50_000, -(2**31)]
    assert nq.bev_iou_q([extreme, box], [box, extreme]).tolist() == [0, 0]


def test_size_check_and_nms_match_reference(nq):
    rng = np.random.default_rng(7)
    for trial in range(20):
        n = int(rng.integers(1, 60))
        boxes = np.zeros((n, 7), np.int64)
        boxes[:, 0:2] = rng.integers(-6000, 6001, (n, 2))  # crowded: many overlaps
        boxes[:, 3] = rng.integers(100, 8001, n)
        boxes[:, 4] = rng.integers(100, 3201, n)
        boxes[:, 5] = rng.integers(500, 3500, n)
        boxes[:, 6] = rng.integers(-(2**31), 2**31, n)
        score = rng.integers(1, 32768, n)
        score[: n // 3] = score[0]  # ties, broken by cluster id
        # every other trial: shared cluster ids (a group cut's parts), whose pairs have their own NMS bound
        cid = rng.permutation(np.arange(1, n + 1)) if trial % 2 == 0 else rng.integers(1, n // 3 + 2, n)
        cls = rng.integers(0, 3, n)
        iou = int(rng.integers(0, 32769))
        c = nq.post_q(boxes, score, cid, cls, iou)
        assert c["size_ok"].tolist() == [ref.size_ok(int(k), bx) for k, bx in zip(cls, boxes.tolist())]
        dets = sorted(({"box": bx, "score_q15": int(s), "cluster_id": int(i)}
                       for bx, s, i in zip(boxes.tolist(), score, cid)), key=ref.sort_key)
        kept, flags = ref.nms(dets, iou)
        assert c["kept"] == [d["cluster_id"] for d in kept]
        assert c["suppressed"] == flags
        if iou == 32768:
            assert len(kept) == n  # nothing exceeds IoU 1


def test_nms_between_parts_of_one_group(nq):
    """Two parts of one group cut (one cluster id) suppress each other only past max(iou_q15, 0.25): people side
    by side give part boxes that touch; parts overlapping more are one person cut twice."""
    a = [10_000, 0, 0, 1000, 700, 1700, 0]
    touch = [10_650, 0, 0, 1000, 700, 1700, 0]  # 0.35 x 0.7 m shared of 0.7 + 0.7: IoU 0.212
    same = [10_300, 0, 0, 1000, 700, 1700, 0]   # IoU 0.538
    assert 0.2 * 32768 < nq.bev_iou_q([a], [touch])[0] < 0.25 * 32768 < nq.bev_iou_q([a], [same])[0]
    boxes = np.array([a, touch], np.int64)
    score = np.array([30000, 20000])
    cls = np.array([2, 2])
    assert nq.post_q(boxes, score, np.array([5, 5]), cls, 3277)["suppressed"] == [0, 0]  # one cut: both stand
    assert nq.post_q(boxes, score, np.array([5, 6]), cls, 3277)["suppressed"] == [0, 1]  # two clusters: dropped
    boxes = np.array([a, same], np.int64)
    assert nq.post_q(boxes, score, np.array([5, 5]), cls, 3277)["suppressed"] == [0, 1]  # one person cut twice
    assert nq.post_q(boxes, score, np.array([5, 5]), cls, 32768)["suppressed"] == [0, 0]  # NMS off: off for all
    dets = [{"box": b, "score_q15": int(s), "cluster_id": 5} for b, s in zip(boxes.tolist(), score)]
    assert ref.nms(dets, 3277)[1] == [0, 1] and ref.nms(dets, 32768)[1] == [0, 0]
