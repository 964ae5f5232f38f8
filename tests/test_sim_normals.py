"""numpy's standard normal drawn inside compiled code (sim.normals) is numpy's own, number for number and
state for state: the simulator's noise may come from either without changing a trace byte."""

from __future__ import annotations

import numpy as np

from tablebot.sim.normals import bitgen_address, fill


def test_compiled_draws_are_numpys_bit_for_bit_tail_included() -> None:
    for seed in (0, 1, 2**40 + 7):
        ours, theirs = np.random.default_rng(seed), np.random.default_rng(seed)
        drawn = np.empty(300_000)
        fill(bitgen_address(ours), drawn)
        expected = theirs.standard_normal(300_000)
        assert np.array_equal(drawn.view(np.uint64), expected.view(np.uint64))
        assert np.sum(np.abs(expected) > 3.6541528853610088) > 20  # the ziggurat's tail branch ran too
        # both Generators are left in the same state: numpy's next draws (of any kind) agree
        assert ours.bit_generator.state == theirs.bit_generator.state
        assert ours.standard_normal(5).tolist() == theirs.standard_normal(5).tolist()


def test_draws_interleave_with_numpys_on_one_generator() -> None:
    mixed, plain = np.random.default_rng(5), np.random.default_rng(5)
    out = []
    for k in range(50):
        block = np.empty(k % 7 + 1)
        if k % 2:
            fill(bitgen_address(mixed), block)
        else:
            mixed.standard_normal(out=block)
        out.append(block)
    assert np.array_equal(np.concatenate(out), plain.standard_normal(sum(len(b) for b in out)))
