"""Shared helpers for the core tests (a plain module, not conftest, so other suites stay independent)."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from tablebot.diagnostics import Diagnostic, TableBotError
from tablebot.formats.table_read import load_table
from tablebot.machine import Machine, compile_table

ROOT = Path(__file__).resolve().parents[1]
EXAMPLE = ROOT / "examples" / "bumberbot"
FIXTURES = Path(__file__).resolve().parent / "fixtures"
SEED_TSV = FIXTURES / "bumberbot-table.tsv"

#: A tiny robot for semantic tests: two inputs, two motors, start in state 1 with timer 0.
MINI_ROBOT = """\
name = "Mini"
initial_state = 1
initial_timer = 0
[inputs]
A = "left switch"
B = "right switch"
[motors]
M1 = "right"
M2 = "left"
"""

#: A robot with the issue-4 extras: a counter per motor and two lamps.
COUNTER_ROBOT = """\
name = "Counter"
initial_state = 1
[inputs]
A = "switch"
[motors]
M1 = "right"
M2 = "left"
[counters]
C1 = "M1"
C2 = "M2"
[lamps]
L1 = "front lamp"
L2 = "rear lamp"
"""


def write_table(
    tmp_path: Path, text: str, robot: str | None = None, name: str = "table.csv", encoding: str = "utf-8"
) -> Path:
    """Write a table (and its robot.toml when given) into ``tmp_path``; returns the table path."""
    path = tmp_path / name
    path.write_bytes(text.encode(encoding))
    if robot is not None:
        (tmp_path / "robot.toml").write_text(robot, encoding="utf-8")
    return path


def machine_of(tmp_path: Path, text: str, robot: str | None = None, name: str = "table.csv") -> Machine:
    return compile_table(load_table(write_table(tmp_path, text, robot, name)))


def example_machine() -> Machine:
    return compile_table(load_table(EXAMPLE / "table.csv"))


def problems(path: Path) -> tuple[Diagnostic, ...]:
    """Every diagnostic that loading ``path`` reports (the load must fail)."""
    with pytest.raises(TableBotError) as info:
        load_table(path)
    return info.value.diagnostics


def column_of(line: str, cell: int, delimiter: str = ",") -> int:
    """1-based character column where the ``cell``-th (0-based) cell of an unquoted line starts."""
    return sum(len(part) + 1 for part in line.split(delimiter)[:cell]) + 1


def find(diagnostics: tuple[Diagnostic, ...], pattern: str) -> Diagnostic:
    """The one diagnostic whose message matches ``pattern`` (fails the test if not exactly one)."""
    hits = [d for d in diagnostics if re.search(pattern, d.message)]
    assert len(hits) == 1, f"{pattern!r} matched {[d.message for d in hits]} in {[d.message for d in diagnostics]}"
    return hits[0]
