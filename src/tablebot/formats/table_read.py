"""Reading a table file (CSV/TSV as a spreadsheet saves it) into a parsed :class:`Table`.

Column names come from the robot description; every problem of the file is reported at once
as ``file:line:column: message`` with a hint. Loading never executes anything from the file.
"""

from __future__ import annotations

from dataclasses import dataclass
from operator import attrgetter
from pathlib import Path
from typing import Any

from tablebot.csvtext import Cell, Record, cells_beyond, headerless, read_records, read_text, records_after
from tablebot.diagnostics import Collector, Diagnostic, TableBotError, fail
from tablebot.formats.table_cells import Column, motor_speed, read_value
from tablebot.formats.table_parts import cross_column, grouped, robot_for_table, writes
from tablebot.i18n import N_
from tablebot.i18n.headers import suffix
from tablebot.robot import (
    BUMBERBOT,
    Robot,
    StateId,
    find_robot_file,
    load_robot,
)
from tablebot.robot_tables import tables_of
from tablebot.table import (
    FIXED,
    TIMER_EVENT,
    Row,
    Table,
    missing_states,
    normalise_header,
)

#: The largest table read, far beyond any real one (the examples have up to 41 rows, 10 states and 16 columns; a
#: table of a few thousand rows is big; ROBO Pro's lists hold 128 states) and small enough that ``check`` and
#: ``sim`` of the largest one accepted stay within seconds and a few hundred MB (benchmarks/limits.py): the
#: file's size, its lines below the header (counted as they are read, blank and comment lines too), its states
#: (compiling precomputes up to 4,096 lookups per state) and its event columns (each is a bit of the
#: simulator's 64-bit event word). Columns and cells: :data:`tablebot.csvtext.MAX_COLUMNS`.
MAX_TABLE_BYTES = 16 * 1024 * 1024
MAX_TABLE_ROWS = 100_000
MAX_STATES = 1_000
MAX_EVENT_COLUMNS = 63


def load_table(path: str | Path, robot: Robot | None = None) -> Table:
    """Parse a table file; the robot comes from ``robot``, a side file, or the built-in BumberBot."""
    path = Path(path)
    if robot is None:
        side = find_robot_file(path)
        robot = load_robot(side) if side else BUMBERBOT
    robot, name = robot_for_table(path, robot)  # one of several tables: its own start and rule
    return parse_table(read_text(path, limit=MAX_TABLE_BYTES), str(path), robot, name)


def parse_table(text: str, path: str, robot: Robot, name: str = "") -> Table:
    out = Collector(path)
    records = read_records(text, path)  # one at a time: only the rows made of them are kept
    header = next((record for record in records if not record.is_blank()), None)
    if header is None:
        raise fail(
            path,
            N_("the table is empty"),
            N_(
                "the first line must be a header such as {example}",
                example="description,state,T,I3,M1_dir,M1_speed,timer,next",
            ),
            1,
            1,
        )
    columns = _header(header, robot, out)
    events = tuple(c.name for c in columns if c.kind == "event")
    next_at = next((i for i, c in enumerate(columns) if c.kind == "next"), None)
    state_at = next((i for i, c in enumerate(columns) if c.kind == "state"), None)
    states: set[StateId] = set()
    layout = _Layout.of(columns)
    memo: dict[tuple[int, str], Any] = {}  # (column, cell text) -> value, for cells read without an error
    rows: list[Row] = []
    next_cells: dict[int, Cell] = {}  # line -> its next-state cell, where missing states are reported
    state_cells: dict[int, Cell] = {}  # and its state cell, where a misused group is
    after = records_after(text, header.line)
    if after is not None and after > MAX_TABLE_ROWS:  # known at once: no line is read
        raise _too_many_rows(path, header.line + MAX_TABLE_ROWS + 1)
    for count, record in enumerate(records, start=1):
        if count > MAX_TABLE_ROWS:
            raise _too_many_rows(path, record.line)
        if record.is_blank() or is_comment(record):
            continue
        row = _row(record, layout, robot, out, memo, len(rows), rows[-1].description if rows else "")
        if row is not None:
            rows.append(row)
            _count_states(states, row, record, (state_at, next_at), path)
        if next_at is not None and len(record.cells) > next_at:
            next_cells[record.line] = record.cells[next_at]
        if state_at is not None and len(record.cells) > state_at:
            state_cells[record.line] = record.cells[state_at]
    if not rows and not out.items:
        out.error(
            header.line + 1,
            1,
            N_("the table has a header but no rows"),
            N_("add one row per transition below the header"),
        )
    rows = grouped(rows, robot, out, state_cells, next_cells)
    _check_states(rows, robot, out, next_cells, columns)
    out.raise_if_any()
    cross = {c.name: x for c in columns if c.kind == "event" and (x := cross_column(c.cell, robot, out)) is not None}
    return Table(
        robot=robot,
        events=events,
        rows=tuple(rows),
        path=path,
        name=name,
        cross=cross,
        writes=writes((c.kind, c.name, c.cell) for c in columns),
    )


def _too_many_rows(path: str, line: int) -> TableBotError:
    return fail(
        path,
        N_("the table has more than {most:,} lines below its header, the most tablebot reads", most=MAX_TABLE_ROWS),
        N_("split it into smaller tables; is this the right file?"),
        line,
        1,
    )


def _count_states(states: set[StateId], row: Row, record: Record, at: tuple[int | None, int | None], path: str) -> None:
    """Add the states ``row`` names (from ``record``; ``at``: its state and next-state columns) to ``states``,
    refusing the one past MAX_STATES at its cell."""
    for value, column in ((row.state, at[0]), (row.next, at[1])):
        if value not in states:
            states.add(value)
            if len(states) > MAX_STATES:
                where = record.cells[column].column if column is not None and column < len(record.cells) else 1
                raise fail(
                    path,
                    N_("the table has more than {most:,} states, the most tablebot reads", most=MAX_STATES),
                    N_("split the robot's behaviour into smaller tables; is this the right file?"),
                    record.line,
                    where,
                )


def is_comment(record: Record) -> bool:
    """A line below the header whose first cell starts with ``#`` is a comment for people (``tablebot new``
    writes an example row that way); the table ignores it. Before the header it would be read as the header."""
    return bool(record.cells) and record.cells[0].text.lstrip().startswith("#")


# --- header -------------------------------------------------------------------------------------


def _classify(name: str, robot: Robot) -> tuple[str, str] | None:
    if name in FIXED:
        return name, name
    if name == TIMER_EVENT or name in robot.inputs or name in robot.counter_names:
        return "event", name
    if name in robot.motors:
        return "signed", name
    if name in robot.lamps:
        return "lamp", name
    base, _, end = name.rpartition("_")
    part = suffix(end)  # M1_Richtung, M1_Tempo, C1_Laden: German names (tablebot.i18n.headers)
    if base in robot.motors and part in ("dir", "speed"):
        return part, base
    if base in robot.counter_names and part == "load":
        return "load", base
    return None


def _header(record: Record, robot: Robot, out: Collector) -> list[Column]:
    columns: list[Column] = []
    seen: dict[tuple[str, str], Cell] = {}
    known = (
        *FIXED,
        TIMER_EVENT,
        *robot.inputs,
        *robot.counter_names,
        *(N_("{m}_dir/{m}_speed or {m}", m=m) for m in robot.motors),
        *robot.lamps,
        *(f"{c}_load" for c in robot.counter_names),
    )
    for cell in record.cells:
        name = normalise_header(cell.text)
        if not name:
            columns.append(Column("ignore", "", cell))
            continue
        if "=" in name and tables_of(robot):  # a cross-table event (several tables: tablebot.robot_tables)
            cross = cross_column(cell, robot, out)
            columns.append(Column("event", cross.column, cell) if cross else Column("ignore", name, cell))
            continue
        kind_name = _classify(name, robot)
        if kind_name is None:
            out.error(
                cell.line,
                cell.column,
                N_("unknown column {name!r} for robot {robot}", name=cell.text.strip(), robot=robot.name),
                N_("known columns: {known}; declare new inputs or outputs in the robot file", known=known),
            )
            columns.append(Column("ignore", name, cell))
            continue
        if kind_name in seen:
            first = seen[kind_name]
            out.error(
                cell.line,
                cell.column,
                N_(
                    "column {name!r} appears twice (first at column {first})",
                    name=cell.text.strip(),
                    first=first.column,
                ),
                N_("delete or rename one of them"),
            )
        seen[kind_name] = cell
        columns.append(Column(kind_name[0], kind_name[1], cell))
    events = [c.cell for c in columns if c.kind == "event"]
    if len(events) > MAX_EVENT_COLUMNS:
        cell = events[MAX_EVENT_COLUMNS]
        out.error(
            cell.line,
            cell.column,
            N_(
                "the table has {count} event columns (T, inputs and counters), more "
                "than the {most} the engines' 64-bit event word holds",
                count=len(events),
                most=MAX_EVENT_COLUMNS,
            ),
            N_("keep at most {most} event columns (this is the first one too many)", most=MAX_EVENT_COLUMNS),
        )
    for required in ("state", "next"):
        if (required, required) not in seen:
            out.error(
                record.line,
                None,
                N_("the header has no {name!r} column", name=required),
                N_("every table needs state and next columns"),
            )
    for motor in robot.motors:
        forms = {k for (k, n) in seen if n == motor}
        if "signed" in forms and forms & {"dir", "speed"}:
            cell = seen[("signed", motor)]
            out.error(
                cell.line,
                cell.column,
                N_("motor {m} is given both as {m} and as {m}_dir/{m}_speed", m=motor),
                N_("use one form per motor"),
            )
        elif "dir" in forms and "speed" not in forms:
            cell = seen[("dir", motor)]
            out.error(
                cell.line,
                cell.column,
                N_("{m}_dir has no {m}_speed column", m=motor),
                N_("add a {m}_speed column (or use one signed column {m})", m=motor),
            )
    return columns


# --- rows ---------------------------------------------------------------------------------------


@dataclass(frozen=True)
class _Layout:
    """The header's columns, found once for all rows: those read (``named``, with their index) and those under a
    blank header (``blank``), where only a filled cell matters (a wide table may have hundreds)."""

    columns: list[Column]
    named: list[tuple[int, Column]]
    blank: list[int]

    @staticmethod
    def of(columns: list[Column]) -> _Layout:
        return _Layout(
            columns,
            [(i, c) for i, c in enumerate(columns) if c.kind != "ignore"],
            [i for i, c in enumerate(columns) if c.kind == "ignore" and not c.name],
        )

    def headerless(self, cells: list[Cell], out: Collector) -> None:
        """Report the filled cells under a blank header (their texts joined in C first: they are mostly empty)."""
        if "".join(map(attrgetter("text"), map(cells.__getitem__, self.blank))).strip():
            for i in self.blank:
                headerless(cells[i], out)


def _row(
    record: Record,
    layout: _Layout,
    robot: Robot,
    out: Collector,
    memo: dict[tuple[int, str], Any],
    index: int,
    above: str,
) -> Row | None:
    """The row of one record (the ``index``-th, 0-based; a blank description continues ``above``, the
    one of the row before), or None when its state or next state is unreadable.

    A row with other bad cells is still returned (with the bad cells at their blank value) so that
    its state counts as having rows; the collected errors stop the table from being used.
    """
    width = len(layout.columns)
    cells = list(record.cells[:width])
    end = (cells[-1].column + len(cells[-1].text) + 1) if cells else 1
    cells += [Cell("", record.line, end)] * (width - len(cells))
    values = {(c.kind, c.name): _cached(i, c, cells[i], out, memo, robot.tick_ms) for i, c in layout.named}
    layout.headerless(cells, out)
    cells_beyond(record.cells, width, out)
    state, nxt = values.get(("state", "state")), values.get(("next", "next"))
    if state is None or nxt is None:
        return None
    return Row(
        index=index,
        line=record.line,
        description=values.get(("description", "description")) or above,
        state=state,
        events=frozenset(name for (kind, name), v in values.items() if kind == "event" and v),
        motors=tuple(motor_speed(motor, values, bool(tables_of(robot))) for motor in robot.motors),
        timer=values.get(("timer", "timer")) or 0,
        next=nxt,
        counters=tuple(values.get(("load", c.name)) for c in robot.counters),
        lamps=tuple(values.get(("lamp", lamp)) for lamp in robot.lamps),
    )


def _cached(
    index: int, column: Column, cell: Cell, out: Collector, memo: dict[tuple[int, str], Any], tick_ms: int
) -> Any:
    """:func:`~tablebot.formats.table_cells.read_value`, remembered per column and text: a long table repeats
    the same few cell texts. A cell with an error is never remembered, so every bad cell is reported at its own
    place."""
    if column.kind == "description":
        return cell.text.strip()
    key = (index, cell.text)
    if key in memo:
        return memo[key]
    errors = len(out.items)
    value = read_value(column, cell, out, tick_ms)
    if len(out.items) == errors:
        memo[key] = value
    return value


def _check_states(
    rows: list[Row], robot: Robot, out: Collector, next_cells: dict[int, Cell], columns: list[Column]
) -> None:
    """Report :func:`missing_states` at the next-state cell, or where the robot names the state."""
    if not rows:
        return
    for row, where, message, hint in missing_states(rows, robot):
        if row is None:
            _robot_error(out, robot, where, columns, message, hint)
        else:
            cell = next_cells.get(row.line)
            out.error(row.line, cell.column if cell else None, message, hint)


def _robot_error(
    out: Collector, robot: Robot, where: tuple[str, str], columns: list[Column], message: str, hint: str
) -> None:
    """A problem that comes from the robot description: located at its line in the robot file, or,
    for the built-in robot, at the table's state column (where the missing rows belong)."""
    line = robot.line(*where)
    if line is not None:
        out.items.append(Diagnostic(robot.source, line, 1, message, hint))
        return
    state = next((c.cell for c in columns if c.kind == "state"), None)
    out.error(state.line if state else 1, state.column if state else 1, message, hint)


def resolve_table_path(path: Path) -> Path:
    """A folder stands for the table.csv inside it, so ``tablebot trace examples/bumberbot`` works."""
    if path.is_dir():
        for name in ("table.csv", "table.tsv"):
            if (path / name).is_file():
                return path / name
        raise fail(
            path,
            N_("this folder holds no table.csv or table.tsv"),
            N_("give the table file itself, or a folder that holds table.csv"),
        )
    return path
