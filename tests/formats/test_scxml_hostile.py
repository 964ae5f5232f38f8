"""A project whose every free text is hostile (tests/hostile.py: texts that end comments, strings and tags, drive a
terminal, or hold characters XML cannot) exports to SCXML and XState that both engines run as tablebot's engine
does, its texts inert, and reads back: exactly from XState's JSON, and from SCXML but for the characters XML 1.0
cannot hold at all (NUL, most controls), which become U+FFFD there."""

from __future__ import annotations

import random
from dataclasses import replace
from pathlib import Path

import pytest

from hostile import HOSTILE, write_project
from statechart_helpers import expected, first_difference, node_missing, one_table, run_statemachine, run_xstate
from tablebot.formats.inputs_csv import TickInput
from tablebot.formats.statecharts.read_scxml import read_scxml
from tablebot.formats.statecharts.read_xstate import read_xstate
from tablebot.formats.statecharts.scxml import export_scxml
from tablebot.formats.statecharts.xstate import export_xstate
from tablebot.formats.table_read import load_table
from tablebot.table import Table


@pytest.fixture(scope="module")
def table(tmp_path_factory: pytest.TempPathFactory) -> Table:
    return load_table(write_project(tmp_path_factory.mktemp("hostile")))


def _inputs(table: Table) -> list[TickInput]:
    rng = random.Random(5)
    return [TickInput(rng.randrange(1 << len(table.input_events))) for _ in range(60)]


def test_the_hostile_table_runs_in_python_statemachine_as_in_the_engine(table: Table) -> None:
    robot, machine = one_table(table)
    inputs = _inputs(table)
    assert first_difference(run_statemachine(robot, export_scxml([table]), inputs), expected(machine, inputs)) is None


@pytest.mark.skipif(node_missing() is not None, reason=str(node_missing()))
def test_the_hostile_table_runs_in_xstate_as_in_the_engine(tmp_path: Path, table: Table) -> None:
    robot, machine = one_table(table)
    inputs = _inputs(table)
    assert first_difference(run_xstate(robot, tmp_path, inputs), expected(machine, inputs)) is None


def test_the_hostile_table_reads_back(table: Table) -> None:
    (from_json,) = read_xstate(export_xstate([table]), "machine.json")
    assert [replace(r, line=0) for r in from_json.rows] == [replace(r, line=0) for r in table.rows]
    (from_xml,) = read_scxml(export_scxml([table]), "machine.scxml")
    unholdable = {i for i, text in enumerate(HOSTILE) if "\x00" in text or "\x1b" in text}
    assert unholdable, "the hostile texts hold no character XML cannot"
    for row, back in zip(table.rows, from_xml.rows, strict=True):
        if row.index in unholdable:
            assert back.description == row.description.replace("\x1b", "\ufffd").replace("\x07", "\ufffd").replace(
                "\x00", "\ufffd"
            )
        else:
            assert replace(back, line=0) == replace(row, line=0)
