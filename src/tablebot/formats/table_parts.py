"""What reading one table of a robot of several tables (``[tables]``) and with state groups (``[groups]``) adds to
:mod:`tablebot.formats.table_read`: the table's own start and rule, its cross-table event columns, the outputs
it writes, and its group rows as the engine runs them (:mod:`tablebot.robot_tables`, :mod:`tablebot.tables`)."""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import replace
from pathlib import Path

from tablebot.csvtext import Cell
from tablebot.diagnostics import Collector, fail
from tablebot.i18n import N_
from tablebot.robot import Robot
from tablebot.robot_tables import CrossEvent, TableSpec, groups_of, parse_cross, spec_robot, tables_of
from tablebot.table import Row, expand_groups

#: Column kinds (table_read.Column.kind) that write an output: motors (both forms), lamps, counter loads.
WRITING = ("dir", "speed", "signed", "lamp", "load")


def spec_of(path: Path, robot: Robot) -> TableSpec | None:
    """The ``[tables]`` entry whose file is ``path`` (None: a robot of one table); a table file that is none
    of the robot's tables is refused (its cross-table columns and outputs would mean nothing)."""
    specs = tables_of(robot)
    if not specs:
        return None
    base = Path(robot.source).parent
    for spec in specs:
        if (base / spec.file).resolve() == path.resolve():
            return spec
    raise fail(
        path,
        N_(
            "this table is none of the tables of {robot} ({tables})",
            robot=str(robot.source),
            tables=tuple(f"{s.name} = {s.file}" for s in specs),
        ),
        N_("give the robot's folder or robot file, or add this table to its [tables]"),
    )


def robot_for_table(path: Path, robot: Robot) -> tuple[Robot, str]:
    """The robot as the table at ``path`` runs on it (its ``[tables]`` start and rule), and the table's name."""
    spec = spec_of(path, robot)
    return (robot, "") if spec is None else (spec_robot(robot, spec), spec.name)


def cross_column(cell: Cell, robot: Robot, out: Collector) -> CrossEvent | None:
    """The header cell as a cross-table event column (None: it is not one); a bad one is reported at its cell."""
    cross = parse_cross(cell.text, robot)
    if isinstance(cross, str):
        out.error(
            cell.line,
            cell.column,
            cross,
            N_(
                "a cross-table column is NAME=S, NAME=S1,S2 or NAME=20..29 with NAME from [tables] (quote it "
                "in a CSV when it has a comma)"
            ),
        )
        return None
    return None if cross is None else replace(cross, line=cell.line, at=cell.column)


def writes(columns: Iterable[tuple[str, str, Cell]]) -> dict[str, tuple[int, int]]:
    """The outputs a table's header has columns for (kind, name, header cell), each at its first cell."""
    found: dict[str, tuple[int, int]] = {}
    for kind, name, cell in columns:
        if kind in WRITING:
            found.setdefault(name, (cell.line, cell.column))
    return found


def grouped(
    rows: list[Row], robot: Robot, out: Collector, state_cells: dict[int, Cell], next_cells: dict[int, Cell]
) -> list[Row]:
    """The rows with those written for a state group made one per state of it (:func:`expand_groups`); a
    problem is reported at the row's state or next cell (line -> that cell)."""
    groups = groups_of(robot)
    if not groups:
        return rows
    expanded, problems = expand_groups(rows, groups)
    for row, where, message, hint in problems:
        cell = (state_cells if where == "state" else next_cells).get(row.line)
        out.error(row.line, cell.column if cell else None, message, hint)
    return expanded
