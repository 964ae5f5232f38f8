"""Thousands of robots' numpy Generators at once: ``np.random.default_rng(seed)`` for every seed, the same
Generators, made without numpy's per-seed hashing in Python.

``default_rng(seed)`` spends most of its ~40 µs hashing the seed (``SeedSequence.generate_state``, one
Python call per seed); a sweep of 10,000 robots made them one by one on the fleet's threads, holding
the GIL the other thread's compiled loop needed. Here the hashing is done for all seeds in one pass of
numpy array arithmetic -- numpy's ``SeedSequence`` algorithm (numpy/random/bit_generator.pyx, after
M. O'Neill's seed_seq), whose output numpy guarantees stable for a seed -- and each ``PCG64`` is seeded
with its four words. :func:`matches_numpy` checks it against numpy on first use (and
tests/fleet/test_fleet_generators.py on many seeds); should it ever differ, every Generator is made by numpy.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np
from numpy.random import PCG64, Generator, SeedSequence
from numpy.random.bit_generator import ISeedSequence

if TYPE_CHECKING:
    from numpy.typing import DTypeLike

__all__ = ["generators", "matches_numpy", "pool_words", "seed_words", "state_words"]

POOL = 4  # SeedSequence's default pool_size (words of entropy kept)
INIT_A, MULT_A = 0x43B0D7E5, 0x931E8875  # mixing the seed into the pool
INIT_B, MULT_B = 0x8B51F9DD, 0x58F38DED  # drawing the state out of the pool
MIX_L, MIX_R = 0xCA01F9DD, 0x4973F715
SHIFT = 16
PCG64_WORDS = 4  # uint64 words PCG64 asks its seed sequence for
_checked: bool | None = None  # whether this numpy's default_rng gives what pool_words/state_words give


class _Words(ISeedSequence):
    """A seed sequence that hands PCG64 the words already worked out for it."""

    __slots__ = ("words",)

    def __init__(self, words: np.ndarray) -> None:
        self.words = words

    def generate_state(self, n_words: int, dtype: DTypeLike = np.uint32) -> np.ndarray:
        assert n_words == PCG64_WORDS and np.dtype(dtype) == np.uint64, "made for PCG64's seeding only"
        return self.words


def _hash_constants(count: int, init: int, mult: int) -> list[np.uint32]:
    """The successive hash constants (the same for every seed: they never depend on the data)."""
    out, value = [], init
    for _ in range(count):
        out.append(np.uint32(value))
        value = value * mult & 0xFFFFFFFF
    return out


def _xorshift(value: np.ndarray) -> np.ndarray:
    return value ^ (value >> np.uint32(SHIFT))


def pool_words(seeds: np.ndarray) -> np.ndarray:
    """``SeedSequence(seed).pool`` for each seed (0 <= seed < 2**128), as an (N, 4) uint32 array."""
    entropy = np.zeros((len(seeds), POOL), dtype=np.uint32)  # the seed's 32-bit words, lowest first, 0-padded
    rest = np.array([int(s) for s in seeds], dtype=object)
    for k in range(POOL):
        entropy[:, k] = (rest & 0xFFFFFFFF).astype(np.uint32)
        rest = rest >> 32
    # hashmix(value): value ^= const; const *= MULT_A; value *= const; value ^= value >> 16
    consts = iter(_hash_constants(POOL + POOL * (POOL - 1) + 1, INIT_A, MULT_A)[1:])
    first = _hash_constants(1, INIT_A, MULT_A)[0]

    def hashmix(value: np.ndarray, before: np.uint32, after: np.uint32) -> np.ndarray:
        return _xorshift((value ^ before) * after)

    const = first
    mixer = np.empty_like(entropy)
    for i in range(POOL):
        nxt = next(consts)
        mixer[:, i] = hashmix(entropy[:, i], const, nxt)
        const = nxt
    for src in range(POOL):
        for dst in range(POOL):
            if src != dst:
                nxt = next(consts)
                hashed = hashmix(mixer[:, src], const, nxt)
                const = nxt
                mixer[:, dst] = _xorshift(np.uint32(MIX_L) * mixer[:, dst] - np.uint32(MIX_R) * hashed)
    return mixer


def state_words(pool: np.ndarray) -> np.ndarray:
    """``generate_state(4, np.uint64)`` of seed sequences with these pools, as an (N, 4) uint64 array."""
    n32 = 2 * PCG64_WORDS
    consts = _hash_constants(n32 + 1, INIT_B, MULT_B)
    out = np.empty((len(pool), n32), dtype=np.uint32)
    for i in range(n32):
        out[:, i] = _xorshift((pool[:, i % POOL] ^ consts[i]) * consts[i + 1])
    return out.astype("<u4").view("<u8").astype(np.uint64)


def matches_numpy() -> bool:
    """Whether :func:`state_words` gives what this numpy's SeedSequence gives (checked once a process)."""
    global _checked
    if _checked is None:
        probe = np.array([0, 1, 7, 2**32 - 1, 2**32 + 5, 2**64 - 3, 12_345_678_901_234_567_890_123], dtype=object)
        ours = state_words(pool_words(probe))
        _checked = all(
            np.array_equal(ours[k], SeedSequence(int(s)).generate_state(PCG64_WORDS, np.uint64))
            for k, s in enumerate(probe)
        )
    return _checked


def seed_words(seeds: Sequence[int]) -> np.ndarray | None:
    """``SeedSequence(seed).generate_state(4, np.uint64)`` for every seed, as an (N, 4) array: what
    ``default_rng(seed)`` seeds its PCG64 with. None where this module cannot tell (no seeds, a seed below 0
    or from 2**128, a numpy whose SeedSequence differs): numpy then makes each Generator itself."""
    if not len(seeds) or not matches_numpy() or min(seeds) < 0 or max(seeds) >= 2**128:
        return None
    return state_words(pool_words(np.asarray(seeds, dtype=object)))


def generators(seeds: Sequence[int]) -> list[Generator]:
    """``[np.random.default_rng(seed) for seed in seeds]``."""
    words = seed_words(seeds)
    if words is None:
        return [np.random.default_rng(seed) for seed in seeds]
    # numpy's stub lists SeedSequence only, but PCG64 takes any ISeedSequence
    return [Generator(PCG64(_Words(row))) for row in words]  # type: ignore[arg-type]
