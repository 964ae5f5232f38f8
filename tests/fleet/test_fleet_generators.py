"""fleet.generators: the Generators a fleet makes at once are numpy's ``default_rng(seed)``, draw for draw."""

from __future__ import annotations

import numpy as np
import pytest

from tablebot.fleet.generators import generators, matches_numpy, pool_words

pytestmark = [pytest.mark.kernel_free]

SEEDS = [
    *range(300),
    2**31,
    2**32 - 1,
    2**32,
    2**32 + 1,
    2**40 + 3,
    2**63,
    2**64 - 1,
    2**64,
    2**96 + 17,
    2**128 - 1,
    123_456_789_012_345_678,
]


def test_the_seed_hashing_is_numpys() -> None:
    assert matches_numpy()
    ours = pool_words(np.array(SEEDS, dtype=object))
    assert all(np.array_equal(row, np.random.SeedSequence(seed).pool) for row, seed in zip(ours, SEEDS, strict=True))


def test_each_generator_draws_what_default_rng_draws() -> None:
    for seed, rng in zip(SEEDS, generators(SEEDS), strict=True):
        numpy_own = np.random.default_rng(seed)
        assert np.array_equal(rng.standard_normal(64), numpy_own.standard_normal(64)), seed
        assert rng.integers(0, 2**62) == numpy_own.integers(0, 2**62)
        assert rng.bit_generator.state == numpy_own.bit_generator.state


@pytest.mark.parametrize("seeds", [[], [2**128], [3, 2**130]])
def test_seeds_beyond_the_shortcut_go_to_numpy(seeds: list[int]) -> None:
    assert [r.bit_generator.state for r in generators(seeds)] == [
        np.random.default_rng(s).bit_generator.state for s in seeds
    ]


def test_a_negative_seed_is_numpys_error() -> None:
    with pytest.raises(ValueError):
        generators([1, -1])
