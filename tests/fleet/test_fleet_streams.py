"""fleet.streams: robots' noise streams kept as PCG64 states in one array are numpy's ``default_rng(seed)``,
seeded, drawn in compiled code and handed over to a Generator, draw for draw -- and the fleet's results are the
same bytes whichever way its streams are kept."""

from __future__ import annotations

from dataclasses import fields
from typing import Any

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tablebot.cli.common import load
from tablebot.fleet import streams as streams_module
from tablebot.fleet.generators import seed_words
from tablebot.fleet.run import Fleet, RobotSpec
from tablebot.fleet.streams import Streams, arrays_hold
from tablebot.sim.model.scene import robot_layer, scene_for
from tablebot.sim.physics.normals import INLINE, normal_rows, seed_pcg64
from test_sim_helpers import BUMBERBOT

SEEDS = [0, 1, 7, 2**32 - 1, 2**32, 2**63, 2**64 - 1, 2**64, 2**96 + 17, 2**127 - 5, 2**128 - 1, 1_234_567_890_123]


def numpy_words(seed: int) -> list[int]:
    """PCG64(seed)'s state and increment as the four words in memory (low word first)."""
    state = np.random.PCG64(seed).state["state"]
    return [state["state"] & 2**64 - 1, state["state"] >> 64, state["inc"] & 2**64 - 1, state["inc"] >> 64]


@settings(max_examples=60, deadline=None)
@given(st.lists(st.integers(min_value=0, max_value=2**128 - 1), min_size=1, max_size=8))
def test_seed_pcg64_seeds_as_numpys_pcg64(seeds: list[int]) -> None:
    words = seed_words(seeds)
    assert words is not None
    states = np.zeros((len(seeds), 4), dtype=np.uint64)
    seed_pcg64(states, words)
    assert states.tolist() == [numpy_words(seed) for seed in seeds]


def test_the_array_streams_hold_on_this_numpy() -> None:
    assert arrays_hold()  # else every fleet here would test the Generators' path only


def seeded(seeds: list[int]) -> Streams:
    streams = Streams(len(seeds))
    streams.seed(list(range(len(seeds))), seeds)
    return streams


def test_drawn_in_compiled_code_they_are_default_rngs_numbers() -> None:
    streams = seeded(SEEDS)
    assert all(int(h) & INLINE for h in streams.handles)  # the array path, stepped inline
    ours = np.empty((len(SEEDS), 300))
    normal_rows(streams.handles, ours)  # 300 draws each: the ziggurat's rarer branches too
    assert np.array_equal(ours, np.array([np.random.default_rng(seed).standard_normal(300) for seed in SEEDS]))


def test_a_generator_asked_for_goes_on_where_the_stream_got_to_and_the_compiled_code_follows_it() -> None:
    streams, theirs = seeded(SEEDS), [np.random.default_rng(seed) for seed in SEEDS]
    first = np.empty((len(SEEDS), 5))
    normal_rows(streams.handles, first)
    for k, rng in enumerate(theirs):
        assert np.array_equal(first[k], rng.standard_normal(5))
        mine = streams.generator(k)
        assert mine is streams.generator(k)  # made once
        assert np.array_equal(mine.standard_normal(9), rng.standard_normal(9))
        assert mine.integers(0, 2**62) == rng.integers(0, 2**62)  # a Generator like any other
    after = np.empty((len(SEEDS), 4))
    normal_rows(streams.handles, after)
    assert np.array_equal(after, np.array([rng.standard_normal(4) for rng in theirs]))


def test_a_robot_given_its_own_generator_draws_from_it() -> None:
    streams, rng = seeded([5, 6]), np.random.default_rng(99)
    streams.use(1, rng)
    assert streams.generator(1) is rng
    drawn = np.empty((2, 3))
    normal_rows(streams.handles, drawn)
    assert np.array_equal(drawn[1], np.random.default_rng(99).standard_normal(3))
    assert np.array_equal(drawn[0], np.random.default_rng(5).standard_normal(3))


@pytest.mark.parametrize("seeds", [[3, 2**130], [2**128]])
def test_seeds_beyond_the_array_path_get_numpys_generators(seeds: list[int]) -> None:
    drawn = np.empty((len(seeds), 6))
    normal_rows(seeded(seeds).handles, drawn)
    assert np.array_equal(drawn, np.array([np.random.default_rng(seed).standard_normal(6) for seed in seeds]))


def fleet_results(run: bool) -> tuple[list[Any], list[str]]:
    """40 BumberBots (robot 3 traced) after 300 ticks as a sweep runs them (``run``), or tick by tick from Python
    as the Gymnasium env does (every robot's Generator asked for): their summary's arrays and the trace."""
    table, machine = load(BUMBERBOT)
    world, params = scene_for(table, machine).world, robot_layer(table.robot)[0]
    fleet = Fleet(table, machine, world, [RobotSpec(seed=s) for s in range(40)], params, traced=[3])
    if run:
        fleet.run(300)
    else:
        for _ in range(300):
            fleet.tick()
    summary = fleet.summary()
    return [getattr(summary, field.name) for field in fields(summary)], fleet.trace_lines(3)


@pytest.mark.parametrize("run", [True, False], ids=["run", "tick"])
def test_a_fleets_results_are_the_same_with_generators_instead(monkeypatch: pytest.MonkeyPatch, run: bool) -> None:
    with_arrays = fleet_results(run)
    monkeypatch.setattr(streams_module, "_checked", False)  # as on a numpy where the array path does not hold
    with_generators = fleet_results(run)
    assert with_arrays[1] == with_generators[1]
    for ours, theirs in zip(with_arrays[0], with_generators[0], strict=True):
        assert np.array_equal(ours, theirs) if isinstance(ours, np.ndarray) else ours == theirs
