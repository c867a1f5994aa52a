# SPDX-License-Identifier: MIT
"""The integer math of the fixed-point path: C (lib/src/qmath/lidet_qmath.c) equals the numpy reference
(codegen/lidet_ref/qmath.py) bit for bit, both are accurate, and the generated tables are current."""
import math

import numpy as np
import pytest

from lidet_codegen import qtables
from lidet_ref import qmath as ref


@pytest.fixture(scope="module")
def nq(need_lib):
    from lidet_tools import native
    return native


def _angles(rng, n):
    edges = np.array([0, 1, 2, (1 << 30) - 1, 1 << 30, (1 << 30) + 1, (1 << 31) - 1, 1 << 31, (1 << 31) + 1,
                      3 << 30, (1 << 32) - 1, 1 << 20, (1 << 20) - 1], dtype=np.int64)
    return np.concatenate([edges, rng.integers(0, 1 << 32, n, dtype=np.int64)])


def test_tables_are_generated_from_the_committed_command(root):
    assert (root / "lib/src/qmath/lidet_qmath_tables.c").read_text() == qtables.render()


@pytest.mark.parametrize("op", ["sin", "cos"])
def test_sin_cos_bit_exact_and_accurate(nq, op):
    a = _angles(np.random.default_rng(1), 200_000)
    c = nq.qmath(op, a)
    r = getattr(ref, op)(a)
    np.testing.assert_array_equal(c, r)
    exact = getattr(np, op)(a.astype(np.float64) * (2 * math.pi / 2**32)) * 2**30
    assert np.max(np.abs(c - exact)) <= 330.0  # Q30 LSBs: (pi/2048)^2/8 * 2^30 = 316 + rounding


def test_sin_cos_exact_at_the_axes(nq):
    a = np.array([0, 1 << 30, 1 << 31, 3 << 30], dtype=np.int64)
    np.testing.assert_array_equal(nq.qmath("sin", a), [0, 1 << 30, 0, -(1 << 30)])
    np.testing.assert_array_equal(nq.qmath("cos", a), [1 << 30, 0, -(1 << 30), 0])


def test_atan2_bit_exact_and_accurate(nq):
    rng = np.random.default_rng(2)
    lim = np.array([0, 1, -1, 2**31 - 1, -(2**31)], dtype=np.int64)
    y = np.concatenate([np.repeat(lim, 5), rng.integers(-(2**31), 2**31, 100_000), rng.integers(-300, 301, 50_000)])
    x = np.concatenate([np.tile(lim, 5), rng.integers(-(2**31), 2**31, 100_000), rng.integers(-300, 301, 50_000)])
    c = nq.qmath("atan2", y, x)
    np.testing.assert_array_equal(c, ref.atan2(y, x))
    assert c.min() >= -(2**31) and c.max() < 2**31
    exact = np.arctan2(y.astype(np.float64), x.astype(np.float64))
    err = np.angle(np.exp(1j * (c * (2 * math.pi / 2**32) - exact)))
    nz = (x != 0) | (y != 0)
    assert np.max(np.abs(err[nz])) < 2e-7
    assert c[~nz].tolist() == [0] * int((~nz).sum())


def test_isqrt_exact(nq):
    rng = np.random.default_rng(3)
    v = np.concatenate([np.array([0, 1, 2, 3, 4, 15, 16, 17, 2**32 - 1, 2**32, 2**62, 2**63 - 1], dtype=np.uint64),
                        rng.integers(0, 2**63, 50_000, dtype=np.uint64),
                        rng.integers(0, 2**20, 50_000).astype(np.uint64) ** 2])
    # the 32-bit root plus Newton correction of lidet__q_isqrt64 (v in [2^32, 2^60), cores with a divide): every
    # bit length, exact squares and their neighbours (where a correction off by one would show), both ends
    bits = rng.integers(32, 61, 50_000)
    logu = (rng.integers(0, 2**62, 50_000, dtype=np.uint64) >> (np.uint64(62) - bits.astype(np.uint64))) | (
        np.uint64(1) << (bits - 1).astype(np.uint64))
    sq = rng.integers(2**16, 2**30, 20_000).astype(np.uint64) ** 2
    v = np.concatenate([v, logu, sq, sq - np.uint64(1), sq + np.uint64(1), np.array(
        [2**60 - 1, 2**60, (2**30 - 1) ** 2, (2**30 - 1) ** 2 - 1, 2**32 + 1, 2**34 - 1], dtype=np.uint64)])
    hi, lo = (v >> np.uint64(32)).astype(np.int64), (v & np.uint64(0xFFFFFFFF)).astype(np.int64)
    c = nq.qmath("isqrt", hi, lo)
    np.testing.assert_array_equal(c, ref.isqrt(v))
    for val, r in zip(v[:12].tolist(), c[:12].tolist()):
        assert r == math.isqrt(val)
    cr = nq.qmath("sqrt_round", hi, lo)
    small = v < np.uint64(2**62)
    np.testing.assert_array_equal(cr[small], ref.sqrt_round(v[small].astype(np.int64)))
    for val, r in zip(v[:11].tolist(), cr[:11].tolist()):
        assert r == round(math.sqrt(val)) or abs(r * r - val) <= r


def test_urad_to_bam(nq):
    u = np.concatenate([np.arange(-3_141_592, 3_141_593, 997), [-3_141_592, 3_141_592]]).astype(np.int64)
    c = nq.qmath("urad_to_bam", u)
    np.testing.assert_array_equal(c, ref.urad_to_bam(u))
    assert np.max(np.abs(c - u * 1e-6 * 2**32 / (2 * math.pi))) <= 0.6
