"""``export --to scxml`` run tick by tick in python-statemachine (an SCXML engine tablebot did not write), its trace
equal to tablebot's engine's: the shipped examples on the inputs their simulated robots read, and random tables
of both matching rules with lamps, counters and keep cells (tests/statechart_helpers.py runs it)."""

from __future__ import annotations

import random
from dataclasses import replace
from pathlib import Path

import pytest

from statechart_helpers import expected, first_difference, one_table, run_statemachine
from tablebot.formats.statecharts.scxml import export_scxml
from tablebot.formats.table_read import load_table
from tablebot.robot import MATCHES
from tablebot.testing.executors import example_case
from tablebot.testing.random_tables import Shape, random_case

EXAMPLES = ("bumberbot", "bumberbot-counters", "line-follower", "obstacle-avoider")


@pytest.mark.parametrize("example", EXAMPLES)
def test_the_examples_run_in_python_statemachine_as_in_the_engine(example: str) -> None:
    case = example_case(example, seconds=3.0, seed=3)  # 300 ticks: python-statemachine takes some 7 ms a tick
    table = case.machine.table
    robot, machine = one_table(table)
    got = run_statemachine(robot, export_scxml([table]), case.inputs)
    assert first_difference(got, expected(machine, case.inputs)) is None
    assert {line["row"] for line in got} - {None}, "no row fired: the case proves little"


@pytest.mark.parametrize("seed", range(6))
def test_random_tables_run_in_python_statemachine_as_in_the_engine(seed: int) -> None:
    """Tables whose two matching rules part on these inputs (random_case), so a wrong rule shows; lamps,
    counters and pulses, keep cells, named states."""
    rng = random.Random(seed)
    shape = Shape(states=4, rows=10, inputs=3, lamps=seed % 2, counters=seed % 3, match=MATCHES[seed % 2])
    table, inputs = random_case(rng, shape, ticks=120)
    robot, machine = one_table(table)
    assert first_difference(run_statemachine(robot, export_scxml([table]), inputs), expected(machine, inputs)) is None


def test_a_wrong_export_is_caught_by_the_comparison() -> None:
    """The comparison can fail: the export of a table with the timer load of its first row to fire changed runs
    differently."""
    case = example_case("bumberbot", seconds=2.0, seed=3)
    table = case.machine.table
    robot, machine = one_table(table)
    first = next(line["row"] for line in expected(machine, case.inputs) if line["row"] is not None)
    changed = replace(table, rows=tuple(replace(r, timer=r.timer + 1) if r.index == first else r for r in table.rows))
    assert (
        first_difference(run_statemachine(robot, export_scxml([changed]), case.inputs), expected(machine, case.inputs))
        is not None
    )


def test_the_scxml_has_no_delayed_send_and_one_tick_transition(tmp_path: Path) -> None:
    text = export_scxml([load_table(Path("examples/bumberbot/table.csv"))])
    assert "<send" not in text and "delay" not in text
    assert text.count('event="tick"') == 1
