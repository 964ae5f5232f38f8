"""Several tables in one robot (issue 36): the multi-table model's one home.

A robot file may name several tables (``[tables]``, read by :mod:`tablebot.robot_tables`; the first is the
main one). They run together, tick by tick, under these rules (docs/engine.md, "Several tables"):

1. the inputs are read once: every table sees the same input image;
2. each table counts its own timer down (as one table does: not on the first tick) and builds its own event
   set: the inputs that read 1, its own ``T`` when its timer is 0, the counter events, and its **cross-table
   events**: a column ``NAME=S`` (``NAME=S1,S2``, ``NAME=20..29``, state names too) is present when table
   ``NAME`` was in one of those states *at the start of the tick*, before any table fired;
3. each table fires the first matching row of its current state under its own matching rule (``match``);
4. **each output has one writer**: a motor, lamp or counter load may have a column in one table only (two is a
   located error naming both tables and the output). A table leaves every output it has no column for alone.

So the tables' order never changes what the robot does: each table's tick reads only the input image and the
states at the start of the tick, and writes only its own outputs. The counters are the robot's: every table
sees the same values; the one that loads a counter is its writer. State groups (``[groups]``) are plain
syntax, made into rows when a table is read (:func:`tablebot.table.expand_groups`).

A trace keeps a one-table robot's keys for the main table (``tick, event, row, state, timer``, the outputs, the
counters), then ``NAME.event, NAME.row, NAME.state, NAME.timer`` for each other table
(:func:`tablebot.replay.record`). The engine is :class:`tablebot.engine.several.Several`.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from functools import cached_property
from pathlib import Path

from tablebot.diagnostics import Diagnostic, TableBotError
from tablebot.formats.table_read import load_table
from tablebot.i18n import N_
from tablebot.machine import Machine, compile_table
from tablebot.robot import Robot, StateId
from tablebot.robot_tables import CrossEvent, TableSpec, tables_of
from tablebot.table import Table

__all__ = ["RobotTables", "load_tables", "several"]


@dataclass(frozen=True, eq=False)
class RobotTables:
    """A robot's tables, the main one first, each compiled; the robot-wide input layout (``input_bits``: each
    input any table reads, in the robot file's order, the first the highest bit) is the one recorded inputs
    are read in (:func:`tablebot.formats.inputs_csv.load_inputs` takes this object as it takes a machine)."""

    tables: tuple[Table, ...]
    machines: tuple[Machine, ...]

    @property
    def names(self) -> tuple[str, ...]:
        return tuple(t.name for t in self.tables)

    @property
    def table(self) -> Table:
        """The main table."""
        return self.tables[0]

    @property
    def robot(self) -> Robot:
        return self.tables[0].robot

    @cached_property
    def input_bits(self) -> dict[str, int]:
        used = {name for t in self.tables for name in t.input_events}
        names = [name for name in self.robot.inputs if name in used]
        return {name: 1 << (len(names) - 1 - i) for i, name in enumerate(names)}

    @property
    def input_mask(self) -> int:
        return sum(self.input_bits.values())

    @property
    def output_names(self) -> tuple[str, ...]:
        return self.machines[0].output_names

    def writer(self, output: str) -> int | None:
        """The index of the table that writes ``output`` (a motor, lamp or counter), None if none does."""
        return next((i for i, t in enumerate(self.tables) if output in t.writes), None)

    def influence(self, read: frozenset[int]) -> frozenset[int]:
        """The tables whose runs decide what the tables ``read`` do: they, the tables their cross-table events
        name, the writers of the counters they read, and so on. The others cannot change them (each output has
        one writer), so a proof about ``read`` may leave them out."""
        found, todo = set(read), list(read)
        while todo:
            table = self.tables[todo.pop()]
            sources = {self.index(e.table) for e in table.cross.values()}
            sources |= {w for c in self.robot.counter_names if c in table.events and (w := self.writer(c)) is not None}
            for source in sources - found:
                found.add(source)
                todo.append(source)
        return frozenset(found)

    def index(self, name: str) -> int:
        return self.names.index(name)

    def covers(self, event: CrossEvent) -> tuple[int, tuple[int, ...]]:
        """A cross-table event as the engine reads it: its table's index and that table's state indices
        (into its machine's ``states``) in which it is present."""
        source = self.index(event.table)
        states = self.machines[source].states
        return source, tuple(i for i, state in enumerate(states) if event.covers(state))


def several(table: Table) -> RobotTables | None:
    """All the tables of ``table``'s robot when it names several (``[tables]``), else None (one table, run as
    ever)."""
    return load_tables(table) if tables_of(table.robot) else None


def load_tables(table: Table, given: Mapping[str, Table] | None = None) -> RobotTables:
    """Every table of ``table``'s robot (``table`` itself is one of them, read already; ``given``: others read
    already, by name, such as the studio's drafts), checked together: cross-table events name states their
    table has, and every output has one writer."""
    specs = tables_of(table.robot)
    base = Path(table.robot.source).parent
    read = {**(given or {}), table.name: table}
    tables = tuple(read[spec.name] if spec.name in read else _load(base, spec, table.robot) for spec in specs)
    problems = [*_cross_problems(tables), *_writer_problems(tables), *_named_problems(tables)]
    if problems:
        raise TableBotError(problems)
    return RobotTables(tables, tuple(compile_table(t) for t in tables))


def _load(base: Path, spec: TableSpec, robot: Robot) -> Table:
    return load_table(base / spec.file, robot)


def _cross_problems(tables: tuple[Table, ...]) -> list[Diagnostic]:
    """A cross-table column that names a state its table does not have, or a range that holds none of them."""
    states: Mapping[str, tuple[StateId, ...]] = {t.name: t.states for t in tables}
    found = []
    for table in tables:
        for event in table.cross.values():
            known = states[event.table]
            missing = [s for s in event.states if s not in known]
            empty = [
                f"{low}..{high}"
                for low, high in event.ranges
                if not any(isinstance(s, int) and low <= s <= high for s in known)
            ]
            for what in (*(repr(s) for s in missing), *empty):
                found.append(
                    Diagnostic(
                        table.path,
                        event.line,
                        event.at,
                        N_(
                            "{column}: table {table} has no state {state}",
                            column=event.column,
                            table=event.table,
                            state=what,
                        ),
                        N_("its states: {states}", states=tuple(map(str, known))),
                    )
                )
    return found


def _writer_problems(tables: tuple[Table, ...]) -> list[Diagnostic]:
    """Each output has one writer: a second table with a column for it is reported at that column."""
    first: dict[str, Table] = {}
    found = []
    for table in tables:
        for output, (line, column) in table.writes.items():
            owner = first.setdefault(output, table)
            if owner is not table:
                at = owner.writes[output]
                found.append(
                    Diagnostic(
                        table.path,
                        line,
                        column,
                        N_(
                            "{output} is written by two tables, {first} ({place}) and {second}",
                            output=output,
                            first=owner.name,
                            place=":".join(map(str, (owner.path, *at))),
                            second=table.name,
                        ),
                        N_(
                            "each motor, lamp and counter load has one writer: "
                            "remove the {output} column from one table",
                            output=output,
                        ),
                    )
                )
    return found


def _named_problems(tables: tuple[Table, ...]) -> list[Diagnostic]:
    """A state ``[states]`` names that no table has rows for (the names are the robot's, for all its tables)."""
    robot = tables[0].robot
    with_rows = {row.state for t in tables for row in t.rows}
    return [
        Diagnostic(
            robot.source,
            robot.line("states", str(state)),
            1,
            N_("state {state!r} is named in {file} but no table has rows for it", state=state, file=robot.source),
            N_("add rows for it or remove it from [states]"),
        )
        for state in robot.state_names
        if state not in with_rows
    ]
