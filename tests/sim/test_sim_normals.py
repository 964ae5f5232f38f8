"""numpy's standard normal drawn inside compiled code (sim.physics.normals) is numpy's own, number for number and
state for state, on both of its paths (PCG64 stepped inline, any bit generator through numpy's function
pointers): the simulator's noise may come from either without changing a trace byte."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
import pytest

from tablebot.fleet.generators import generators
from tablebot.sim.physics import normals
from tablebot.sim.physics.normals import INLINE, bitgen_address, fill

pytestmark = [pytest.mark.kernel_free]

if TYPE_CHECKING:
    from collections.abc import Callable


class OwnPCG64(np.random.PCG64):
    """numpy's PCG64 under another class: not exactly numpy.random.PCG64, so it takes the function pointers."""


def _state(rng: np.random.Generator) -> object:
    """The bit generator's state, arrays (Philox, MT19937) as lists, for ==."""

    def plain(value: object) -> object:
        if isinstance(value, dict):
            return {key: plain(item) for key, item in value.items()}
        return value.tolist() if isinstance(value, np.ndarray) else value

    return plain(rng.bit_generator.state)


def _same_draws(ours: np.random.Generator, theirs: np.random.Generator, n: int) -> np.ndarray:
    drawn = np.empty(n)
    fill(bitgen_address(ours), drawn)
    expected = theirs.standard_normal(n)
    assert np.array_equal(drawn.view(np.uint64), expected.view(np.uint64))
    # both Generators are left in the same state: numpy's next draws (of any kind) agree
    assert _state(ours) == _state(theirs)
    assert ours.standard_normal(5).tolist() == theirs.standard_normal(5).tolist()
    assert ours.random(3).tolist() == theirs.random(3).tolist()
    return expected


def test_pcg64_takes_the_inline_path_here() -> None:
    assert normals.pcg64_inline() is not None  # this numpy's layout passed the check: the tests below test it
    assert int(bitgen_address(np.random.default_rng(3))) & INLINE
    assert all(int(bitgen_address(rng)) & INLINE for rng in generators([0, 5, 2**70]))
    assert not int(bitgen_address(np.random.Generator(OwnPCG64(3)))) & INLINE
    assert not int(bitgen_address(np.random.Generator(np.random.Philox(3)))) & INLINE


def test_inline_draws_are_numpys_bit_for_bit_tail_included() -> None:
    for seed in (0, 1, 2**40 + 7):
        expected = _same_draws(np.random.default_rng(seed), np.random.default_rng(seed), 300_000)
        assert np.sum(np.abs(expected) > 3.6541528853610088) > 20  # the ziggurat's tail branch ran too


def test_generators_made_at_once_draw_inline_as_default_rng() -> None:
    for seed, rng in zip([7, 2**64 + 1], generators([7, 2**64 + 1]), strict=True):
        _same_draws(rng, np.random.default_rng(seed), 50_000)


@pytest.mark.parametrize("make", [lambda s: OwnPCG64(s), lambda s: np.random.Philox(s), lambda s: np.random.MT19937(s)])
def test_other_bit_generators_draw_through_numpys_pointers(make: Callable[[int], np.random.BitGenerator]) -> None:
    _same_draws(np.random.Generator(make(11)), np.random.Generator(make(11)), 200_000)


def test_a_numpy_failing_the_layout_check_gets_the_pointer_path(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(normals, "_inline_offset", None)
    ours = np.random.default_rng(4)
    assert not int(bitgen_address(ours)) & INLINE
    _same_draws(ours, np.random.default_rng(4), 100_000)


def test_the_layout_check_can_fail(monkeypatch: pytest.MonkeyPatch) -> None:
    assert normals._layout_holds()
    monkeypatch.setattr(normals, "PCG64_MULTIPLIER", normals.PCG64_MULTIPLIER + 2)  # another algorithm
    assert not normals._layout_holds()
    monkeypatch.setattr(normals, "_inline_offset", False)  # not checked yet in this "process"
    assert normals.pcg64_inline() is None
    assert not int(bitgen_address(np.random.default_rng(1))) & INLINE


def test_draws_interleave_with_numpys_on_one_generator() -> None:
    for make in (np.random.default_rng, lambda s: np.random.Generator(OwnPCG64(s))):
        mixed, plain = make(5), make(5)
        out, expected = [], []
        for k in range(60):
            block = np.empty(k % 7 + 1)
            if k % 3 == 0:
                fill(bitgen_address(mixed), block)
            elif k % 3 == 1:
                mixed.standard_normal(out=block)
            else:  # other kinds of draw between: raw 64-bit words, doubles, buffered 32-bit integers
                block = np.concatenate(
                    [
                        mixed.random(2),
                        mixed.integers(0, 2**32, 3, dtype=np.uint32),
                        mixed.bit_generator.random_raw(2).astype(np.float64),
                    ]
                )
                expected.append(
                    np.concatenate(
                        [
                            plain.random(2),
                            plain.integers(0, 2**32, 3, dtype=np.uint32),
                            plain.bit_generator.random_raw(2).astype(np.float64),
                        ]
                    )
                )
                out.append(block)
                continue
            out.append(block)
            expected.append(plain.standard_normal(len(block)))
        assert np.array_equal(np.concatenate(out), np.concatenate(expected))
        assert _state(mixed) == _state(plain)
