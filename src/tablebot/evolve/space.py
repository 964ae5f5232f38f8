"""What evolution may change in a table, and a candidate table as plain data.

A candidate is the starting table's rows as :class:`Gene` values (a row plus where it came from); it
becomes a real :class:`~tablebot.table.Table` with :func:`to_table`. The robot's columns, its states,
its properties, event cells of existing rows, lamps and counter loads never change; motor cells,
timers and next states do, and rows are added (copies of rows, or guard rows from the repair),
removed and reordered, within :class:`Limits` the user sets.
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from dataclasses import dataclass, replace

from tablebot.diagnostics import fail
from tablebot.durations import MAX_NUMBER_CHARS
from tablebot.i18n import N_
from tablebot.robot import MAX_TIMER, StateId
from tablebot.table import MAX_SPEED, Row, Table

#: Columns of a row that ``--freeze-cell`` can name besides the motors ("line 5" freezes the whole row).
ROW_COLUMNS = ("timer", "next")
FREEZE_RE = re.compile(r"^line\s+(\d+)(?:\s+([A-Za-z]\w*))?$", re.IGNORECASE)
WHOLE_ROW = "*"


@dataclass(frozen=True)
class Gene:
    """One row of a candidate. ``origin`` is the file line of the starting table's row it descends from
    (None: a row evolution added); ``note`` says in words what evolution did to it (for the description)."""

    state: StateId
    events: frozenset[str]
    motors: tuple[int | None, ...]
    timer: int
    next: StateId
    description: str = ""
    counters: tuple[int | None, ...] = ()
    lamps: tuple[int | None, ...] = ()
    origin: int | None = None
    note: str = ""

    def effect(self) -> tuple:
        """What the row does and when (not where it came from or how it is described)."""
        return (self.state, self.events, self.motors, self.timer, self.next, self.counters, self.lamps)


Candidate = tuple[Gene, ...]


@dataclass(frozen=True)
class Limits:
    """The user's limits: at most ``max_rows`` rows; states whose rows stay exactly as they are; cells
    (``(line, column)``, column ``*`` for a whole row) that never change; the timer's range."""

    max_rows: int
    frozen_states: frozenset[StateId] = frozenset()
    frozen_cells: frozenset[tuple[int, str]] = frozenset()
    timer_max: int = MAX_TIMER
    speeds: tuple[int, ...] = tuple(range(-MAX_SPEED, MAX_SPEED + 1))

    def state_frozen(self, state: StateId) -> bool:
        return state in self.frozen_states

    def cell_frozen(self, gene: Gene, column: str) -> bool:
        """Whether a cell of the gene may not change (a row of a frozen state, a frozen row or cell)."""
        if self.state_frozen(gene.state):
            return True
        return gene.origin is not None and bool({(gene.origin, column), (gene.origin, WHOLE_ROW)} & self.frozen_cells)

    def row_fixed(self, gene: Gene) -> bool:
        """Whether the row may not be removed or moved: its state is frozen, or some cell of it is."""
        return self.state_frozen(gene.state) or (
            gene.origin is not None and any(line == gene.origin for line, _ in self.frozen_cells)
        )


def start(table: Table) -> Candidate:
    """The table as a candidate (every row's origin is its file line)."""
    return tuple(
        Gene(
            row.state,
            row.events,
            row.motors,
            row.timer,
            row.next,
            row.description,
            row.counters,
            row.lamps,
            origin=row.line,
        )
        for row in table.rows
    )


def to_table(candidate: Candidate, base: Table, path: str = "<evolved>") -> Table:
    """The candidate as a table of the starting table's robot and columns. Rows keep their origin's file
    line (a property or a finding then names the row the user knows); added rows get lines after the
    last one (the table written to a file numbers its rows afresh)."""
    last = max((row.line for row in base.rows), default=1)
    rows, added = [], 0
    for index, gene in enumerate(candidate):
        if gene.origin is None or any(g.origin == gene.origin for g in candidate[:index]):
            added += 1
            line = last + added
        else:
            line = gene.origin
        rows.append(
            Row(
                index=index,
                line=line,
                description=gene.description,
                state=gene.state,
                events=gene.events,
                motors=gene.motors,
                timer=gene.timer,
                next=gene.next,
                counters=gene.counters,
                lamps=gene.lamps,
            )
        )
    return replace(base, rows=tuple(rows), path=path)  # its name and cross-table columns too (several tables)


def renumbered(table: Table) -> Table:
    """The table with rows on the lines a written file gives them (header on line 1)."""
    return replace(table, rows=tuple(replace(row, line=row.index + 2) for row in table.rows))


def valid(candidate: Candidate, states: Sequence[StateId], limits: Limits) -> bool:
    """Every state keeps at least one row and the row limit holds (states and next states never leave
    the starting table's states, so every next state has rows)."""
    if not candidate or len(candidate) > limits.max_rows:
        return False
    return set(states) <= {gene.state for gene in candidate}


# --- the user's options ---------------------------------------------------------------------------


def parse_freeze_states(values: Sequence[str], table: Table) -> frozenset[StateId]:
    """``--freeze-state 20,21`` (or repeated): states whose rows never change."""
    by_text = {str(state): state for state in table.states}
    out: set[StateId] = set()
    for value in values:
        for part in (p.strip() for p in value.split(",") if p.strip()):
            if part not in by_text:
                raise fail(
                    "--freeze-state",
                    N_("--freeze-state {part}: the table has no state {part}", part=part),
                    N_("name states of the table: {states}", states=tuple(map(str, table.states))),
                )
            out.add(by_text[part])
    return frozenset(out)


def parse_freeze_cells(values: Sequence[str], table: Table) -> frozenset[tuple[int, str]]:
    """``--freeze-cell "line 5 timer"``, ``"line 5 M1"``, ``"line 5 next"`` or ``"line 5"`` (the whole
    row), comma-separated or repeated; file lines as an editor numbers them (the header is line 1)."""
    lines = {row.line for row in table.rows}
    own = [m for m in table.robot.motors if not table.name or m in table.writes]  # one of several: its own motors
    own += [lamp for lamp in table.robot.lamps if table.name and lamp in table.writes]  # and lamps
    columns = {c.lower(): c for c in (*own, *ROW_COLUMNS)}
    out: set[tuple[int, str]] = set()
    for value in values:
        for part in (p.strip() for p in value.split(",") if p.strip()):
            found = FREEZE_RE.match(part)
            if not found or len(found[1]) > MAX_NUMBER_CHARS:  # int() of a longer number may fail
                raise fail(
                    "--freeze-cell",
                    N_("--freeze-cell: {part!r} does not name a cell", part=part),
                    N_('write "line 5 timer", "line 5 M1", "line 5 next" or "line 5" (the whole row)'),
                )
            line = int(found[1])
            if line not in lines:
                raise fail(
                    "--freeze-cell",
                    N_(
                        "--freeze-cell: line {line} of {path} is not a row of the table",
                        line=line,
                        path=str(table.path),
                    ),
                    N_("rows are on lines {first}..{last}", first=min(lines), last=max(lines)),
                )
            column = found[2]
            if column is not None and column.lower() not in columns:
                raise fail(
                    "--freeze-cell",
                    N_("--freeze-cell: {column!r} is not a cell evolution changes", column=column),
                    N_("name one of {known}, or give just the line to freeze the row", known=tuple(columns.values())),
                )
            out.add((line, WHOLE_ROW if column is None else columns[column.lower()]))
    return frozenset(out)


def default_max_rows(table: Table) -> int:
    """Room for a repair's guard rows and a few more: half as many rows again, at least 8 more."""
    return len(table.rows) + max(8, len(table.rows) // 2)


def default_timer_max(table: Table) -> int:
    """Twice the longest timer of the table, at least 10 s worth of ticks."""
    longest = max((row.timer for row in table.rows), default=0)
    return min(MAX_TIMER, max(2 * longest, 10_000 // max(1, table.robot.tick_ms)))
