"""The cells ``tune`` changes: ``--cells "line 5 timer, lights: line 3 timer=10..100, line 12 C1_load"``, file
lines as an editor numbers them; a robot of several tables names the table of a cell before a colon (none: the
main table). A row written for a group of states (``[groups]``) runs as a row per state: its cell is tuned in
every one of them, as editing the one cell of the file would."""

from __future__ import annotations

import itertools
import re
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any, Protocol

import numpy as np

from tablebot.diagnostics import TableBotError, fail
from tablebot.fleet.robots import Variants
from tablebot.i18n import N_
from tablebot.robot import MAX_TIMER
from tablebot.table import Row, Table
from tablebot.tables import RobotTables

if TYPE_CHECKING:
    from tablebot.machine import Machine

__all__ = ["CELL_RE", "Cell", "cell_variants", "grid_variants", "parse_cells"]

CELL_RE = re.compile(
    r"^(?:([^\s:,]+)\s*:\s*)?line\s+(\d+)\s+([A-Za-z]\w*)\s*(?:=\s*(\d+)\s*\.\.\s*(\d+))?$", re.IGNORECASE
)


@dataclass(frozen=True)
class Cell:
    """One tunable cell: the timer or a counter's load of the row on file line ``line`` of table ``table`` (its
    index in the robot's tables, 0: the main one; ``table_name`` as the option named it, "" when it did not)."""

    line: int
    rows: tuple[int, ...]  # the indices of the rows the line runs as (several for a group's row)
    column: str  # "timer" or "C1_load"
    counter: int | None  # the counter a load cell loads (None: the timer)
    value: int  # as the table has it
    low: int
    high: int
    table: int = 0
    table_name: str = ""

    @property
    def label(self) -> str:
        where = f"line {self.line} {self.column}"
        return f"{self.table_name}: {where}" if self.table_name else where


def parse_cells(text: str, table: Table, tables: RobotTables | None = None, option: str = "--cells") -> list[Cell]:
    """The cells ``text`` names in ``table`` (or, for a robot of several tables, in the one each names); a
    mistake names ``option`` (``--grid`` for a sweep's cells)."""
    try:
        return _parse_cells(text, table, tables)
    except TableBotError as exc:
        if option == "--cells":
            raise
        first = exc.diagnostics[0]
        raise fail(option, first.message.replace("--cells", option, 1), first.hint) from None


def _parse_cells(text: str, table: Table, tables: RobotTables | None) -> list[Cell]:
    cells: list[Cell] = []
    for part in (p.strip() for p in text.split(",") if p.strip()):
        found = CELL_RE.match(part)
        if not found:
            raise fail(
                "--cells",
                N_("--cells: {part!r} does not name a cell", part=part),
                N_(
                    'write "line 5 timer, line 9 timer" (file lines, the header is line 1), optionally with a '
                    'range: "line 5 timer=100..2000"'
                ),
            )
        index, own = _table_of(found[1], part, table, tables)
        cell = _cell(part, found, own, index, found[1] or "")
        if any((c.table, c.line, c.column) == (cell.table, cell.line, cell.column) for c in cells):
            raise fail("--cells", N_("--cells names {cell} twice", cell=cell.label), N_("name each cell once"))
        cells.append(cell)
    if not cells:
        raise fail("--cells", N_("--cells names no cell"), N_('write --cells "line 5 timer, line 9 timer"'))
    return cells


def _table_of(name: str | None, part: str, table: Table, tables: RobotTables | None) -> tuple[int, Table]:
    """The index and table a cell's table name names (none: the main table)."""
    if name is None:
        return 0, table
    if tables is None:
        raise fail(
            "--cells",
            N_("--cells: {part!r} names the table {name}, but the robot has one table", part=part, name=name),
            N_('leave the table out: "line 5 timer"'),
        )
    if name not in tables.names:
        raise fail(
            "--cells",
            N_("--cells: {part!r}: the robot has no table {name}", part=part, name=name),
            N_(
                "its tables ([tables] in {file}): {names}",
                file=Path(tables.robot.source).name,
                names=", ".join(tables.names),
            ),
        )
    k = tables.names.index(name)
    return k, tables.tables[k]


def _cell(part: str, found: re.Match[str], table: Table, index: int, name: str) -> Cell:
    by_line: dict[int, list[Row]] = {}
    for row in table.rows:
        by_line.setdefault(row.line, []).append(row)
    counters = table.robot.counter_names
    line, column = int(found[2]), found[3]
    if line not in by_line:
        raise fail(
            "--cells",
            N_("--cells: line {line} of {file} is not a row of the table", line=line, file=Path(table.path).name),
            N_("rows are on lines {first}..{last}", first=min(by_line), last=max(by_line)),
        )
    row = by_line[line][0]
    counter = _counter_of(column, counters)
    if column.lower() != "timer" and counter is None:
        raise fail(
            "--cells",
            N_("--cells: {part!r} is not a timer or a counter load", part=part),
            N_(
                "only timer cells (timer) and counter loads ({loads}) can be tuned",
                loads=", ".join(f"{c}_load" for c in counters) or N_("none in this robot"),
            ),
        )
    value = row.timer if counter is None else row.counters[counter]
    if value is None:
        raise fail(
            "--cells",
            N_("--cells: line {line} leaves {counter} alone (its load is blank)", line=line, counter=counters[counter]),  # type: ignore[index]
            N_("tune a load the row sets, or write a load into the cell first"),
        )
    low, high = (int(found[4]), int(found[5])) if found[4] else (0, min(MAX_TIMER, max(2 * value, 100)))
    if not 0 <= low <= high <= MAX_TIMER:
        raise fail(
            "--cells",
            N_("--cells: {part!r}: the range must be LOW..HIGH within 0..{most}", part=part, most=MAX_TIMER),
            N_("write for example line 5 timer=100..2000"),
        )
    return Cell(
        line,
        tuple(r.index for r in by_line[line]),
        "timer" if counter is None else f"{counters[counter]}_load",
        counter,
        value,
        low,
        high,
        index,
        name,
    )


def _counter_of(column: str, counters: tuple[str, ...]) -> int | None:
    for k, name in enumerate(counters):
        if column.lower() == f"{name.lower()}_load":
            return k
    return None


def cell_variants(
    tables: RobotTables | None, machine: Machine, cells: Sequence[Cell], candidates: Sequence[Sequence[int]]
) -> Variants:
    """The table's timers and loads with each candidate's values written into its cells (a robot of several
    tables: every table's, each cell in its own table)."""
    several = tables is not None
    base = Variants.of_tables(tables) if tables is not None else Variants.of(machine)
    timers = np.repeat(base.timers, len(candidates), axis=0)
    loads = np.repeat(base.loads, len(candidates), axis=0)
    for v, values in enumerate(candidates):
        for cell, value in zip(cells, values, strict=True):
            for row in cell.rows:
                at = (v, cell.table, row) if several else (v, row)
                if cell.counter is None:
                    timers[at] = value
                else:
                    loads[(*at, cell.counter)] = value
    return Variants(timers, loads)


class _Axis(Protocol):
    """A sweep's grid axis (:class:`tablebot.fleet.spec.Axis`, which imports this module)."""

    @property
    def key(self) -> str: ...

    @property
    def values(self) -> tuple[Any, ...]: ...


def grid_variants(
    axes: Sequence[_Axis], table: Table, tables: RobotTables | None, machine: Machine
) -> tuple[Variants | None, dict[tuple[Any, ...], int]]:
    """A sweep's table cells on its grid (``--grid "lights: line 4 timer=20,50"``, ``axes``): a program variant
    per combination of their values, and each combination's variant (none without such a key)."""
    if not axes:
        return None, {}
    cells = parse_cells(", ".join(axis.key for axis in axes), table, tables, "--grid")
    combos = list(itertools.product(*(axis.values for axis in axes)))
    return cell_variants(tables, machine, cells, combos), {combo: v for v, combo in reversed(list(enumerate(combos)))}
