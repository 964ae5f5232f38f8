"""``export --to xstate`` run tick by tick in XState 5 under Node (an engine tablebot did not write), its trace equal
to tablebot's engine's: the shipped examples on the inputs their simulated robots read, and random tables of both
matching rules with lamps, counters and keep cells (tests/statechart_helpers.py runs it)."""

from __future__ import annotations

import json
import random
from dataclasses import replace
from pathlib import Path

import pytest

from statechart_helpers import expected, first_difference, node_missing, one_table, run_xstate
from tablebot.formats.statecharts.xstate import export_xstate
from tablebot.formats.table_read import load_table
from tablebot.robot import MATCHES
from tablebot.testing.executors import example_case
from tablebot.testing.random_tables import Shape, random_case

EXAMPLES = ("bumberbot", "bumberbot-counters", "line-follower", "obstacle-avoider")
pytestmark = pytest.mark.skipif(node_missing() is not None, reason=str(node_missing()))


@pytest.mark.parametrize("example", EXAMPLES)
def test_the_examples_run_in_xstate_as_in_the_engine(tmp_path: Path, example: str) -> None:
    case = example_case(example, seconds=20.0, seed=3)
    table = case.machine.table
    robot, machine = one_table(table)
    got = run_xstate(robot, tmp_path, case.inputs)
    assert first_difference(got, expected(machine, case.inputs)) is None
    assert {line["row"] for line in got} - {None}, "no row fired: the case proves little"


@pytest.mark.parametrize("seed", range(6))
def test_random_tables_run_in_xstate_as_in_the_engine(tmp_path: Path, seed: int) -> None:
    """Tables whose two matching rules part on these inputs (random_case), so a wrong rule shows."""
    rng = random.Random(100 + seed)
    shape = Shape(states=5, rows=14, inputs=3, lamps=seed % 2, counters=seed % 3, match=MATCHES[seed % 2])
    table, inputs = random_case(rng, shape, ticks=400)
    robot, machine = one_table(table)
    assert first_difference(run_xstate(robot, tmp_path, inputs), expected(machine, inputs)) is None


def test_a_wrong_export_is_caught_by_the_comparison(tmp_path: Path) -> None:
    """The comparison can fail: the table the config was made from differs in one timer load."""
    case = example_case("bumberbot", seconds=2.0, seed=3)
    table = case.machine.table
    robot, machine = one_table(table)
    first = next(line["row"] for line in expected(machine, case.inputs) if line["row"] is not None)
    changed = replace(table, rows=tuple(replace(r, timer=r.timer + 1) if r.index == first else r for r in table.rows))
    assert (
        first_difference(
            run_xstate(replace(robot, tables=(changed,)), tmp_path, case.inputs), expected(machine, case.inputs)
        )
        is not None
    )


def test_the_config_is_plain_json_with_named_guards_and_actions() -> None:
    config = json.loads(export_xstate([load_table(Path("examples/bumberbot/table.csv"))]))
    transitions = [t for state in config["states"].values() for t in state["always"]]
    assert {t["guard"]["type"] for t in transitions} == {"row", "idle"}
    assert {a["type"] for t in transitions for a in t["actions"]} == {"fire", "idle"}
    assert "after" not in json.dumps(config)  # the timer is in the context, never a delayed transition
