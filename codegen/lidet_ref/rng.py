# SPDX-License-Identifier: MIT
"""xorshift32 (shifts 13, 17, 5), bit for bit as lib/src/internal/lidet_rng.h."""
from __future__ import annotations

DEFAULT_SEED = 0x9E3779B9
_M = 0xFFFFFFFF


def seed(s: int) -> int:
    """The state a seed gives (0 is replaced by DEFAULT_SEED, as lidet__rng_seed)."""
    s &= _M
    return s if s else DEFAULT_SEED


def cell(s: int, k: int) -> int:
    """The start state of cell k (lidet__rng_cell): seed and cell index mixed by MurmurHash3's finaliser."""
    h = (s ^ (k * 0x9E3779B9)) & _M
    h ^= h >> 16
    h = (h * 0x85EBCA6B) & _M
    h ^= h >> 13
    h = (h * 0xC2B2AE35) & _M
    h ^= h >> 16
    return seed(h)


class XorShift32:
    """Deterministic generator mirroring lidet__rng_next / lidet__rng_below."""

    def __init__(self, s: int):
        self.state = seed(s)

    def next(self) -> int:
        x = self.state
        x ^= (x << 13) & _M
        x ^= x >> 17
        x ^= (x << 5) & _M
        self.state = x
        return x

    def below(self, n: int) -> int:
        """Integer in [0, n): high 32 bits of next() * n."""
        return (self.next() * n) >> 32
