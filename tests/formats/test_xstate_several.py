"""Several tables as one XState 5 parallel machine, cross-table events as ``stateIn``, run in XState 5 under Node
tick by tick and equal to tablebot's engine (tablebot.engine.several): the shipped BumberBot with its lights (two
tables, state groups) and random robots of 2-3 tables, and each reads back as the same table bytes."""

from __future__ import annotations

import random
from pathlib import Path

import pytest

from statechart_helpers import first_difference, node_missing, random_several, random_ticks, run_xstate, several
from tablebot.formats.statecharts.read_xstate import read_xstate
from tablebot.formats.statecharts.xstate import export_xstate
from tablebot.formats.table_write import format_table
from tablebot.loading import Loaded
from tablebot.replay import replay_several

pytestmark = pytest.mark.skipif(node_missing() is not None, reason=str(node_missing()))


def test_the_bumberbot_with_its_lights_runs_in_xstate_as_in_the_engine(tmp_path: Path) -> None:
    tables = Loaded.open(Path("examples/bumberbot-lights")).tables
    assert tables is not None
    inputs = random_ticks(random.Random(7), tables, 300)
    got = run_xstate(several(tables), tmp_path, inputs)
    assert first_difference(got, list(replay_several(tables, inputs))) is None
    assert len({line["lights.state"] for line in got}) > 2, "the lights table hardly moved: the case proves little"


@pytest.mark.parametrize("seed", range(6))
def test_random_robots_of_several_tables_run_in_xstate_as_in_the_engine(tmp_path: Path, seed: int) -> None:
    rng = random.Random(seed)
    tables = random_several(rng, tmp_path, 2 + seed % 2)
    inputs = random_ticks(rng, tables, 100)
    got = run_xstate(several(tables), tmp_path, inputs)
    assert first_difference(got, list(replay_several(tables, inputs))) is None


@pytest.mark.parametrize("seed", range(6))
def test_several_tables_read_back_as_the_same_table_bytes(tmp_path: Path, seed: int) -> None:
    tables = random_several(random.Random(seed), tmp_path, 2 + seed % 2)
    back = read_xstate(export_xstate(tables.tables), "machine.json")
    assert [format_table(t) for t in back] == [format_table(t) for t in tables.tables]
    assert [t.name for t in back] == list(tables.names) and export_xstate(back) == export_xstate(tables.tables)
