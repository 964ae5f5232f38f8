"""What ``import --from scxml|xstate`` found in a statechart, made into tablebot's tables again.

The readers (:mod:`.read_scxml`, :mod:`.read_xstate`) collect the robot's names, each table's columns, rule and
start, and each row as the export wrote it; :func:`build` makes the tables; the reader then exports them again and
holds the file to that, so that anything but what tablebot writes is refused where it differs.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

from tablebot.diagnostics import fail
from tablebot.i18n import N_
from tablebot.robot import MATCHES, Counter, Match, Robot, StateId
from tablebot.robot_tables import TableSpec, parse_cross, spec_robot
from tablebot.table import Row, Table

__all__ = ["Found", "FoundRow", "FoundTable", "build"]


@dataclass(frozen=True)
class FoundRow:
    state: StateId
    events: frozenset[str]
    outputs: dict[str, int]
    timer: int
    next: StateId
    description: str
    written: int
    group: str = ""
    index: int = 0  # a group's row: where among the rows the engine runs it is (the rows are sorted by it)


@dataclass
class FoundTable:
    name: str
    events: tuple[str, ...]
    match: str
    initial_state: StateId
    initial_timer: int
    writes: tuple[str, ...] = ()
    rows: list[FoundRow] = field(default_factory=list)


@dataclass
class Found:
    """The robot's names and its tables, as a statechart holds them; ``where``: where to blame a mistake that
    belongs to no one place (the root element, ``$``)."""

    name: str
    tick_ms: int
    inputs: tuple[str, ...]
    motors: tuple[str, ...]
    lamps: tuple[str, ...]
    counters: tuple[Counter, ...]
    tables: list[FoundTable] = field(default_factory=list)


AS_EXPORTED = N_("write what tablebot export wrote")


def build(found: Found, path: str, where: tuple[int | None, int | None] = (None, None)) -> tuple[Table, ...]:
    """The tables (the main one first); no table, or a rule that is neither of tablebot's, is a located error."""
    if not found.tables:
        raise fail(path, N_("the statechart holds no table"), AS_EXPORTED, *where)
    for table in found.tables:
        if table.match not in MATCHES:
            raise fail(
                path,
                N_("matching rule {match!r} is not one of {matches}", match=table.match, matches=tuple(MATCHES)),
                AS_EXPORTED,
                *where,
            )
    robot = Robot(
        name=found.name,
        inputs=found.inputs,
        motors=found.motors,
        lamps=found.lamps,
        counters=found.counters,
        tick_ms=found.tick_ms,
        source=path,
    )
    if len(found.tables) == 1:
        only = found.tables[0]
        robot = replace(
            robot, initial_state=only.initial_state, initial_timer=only.initial_timer, match=_match(only.match)
        )
        return (_table(robot, only, path, ""),)
    specs = tuple(
        TableSpec(t.name, f"{t.name}.csv", t.initial_state, t.initial_timer, _match(t.match)) for t in found.tables
    )
    robot = replace(robot, sections={"tables": specs})
    return tuple(
        _table(spec_robot(robot, spec), table, path, table.name)
        for spec, table in zip(specs, found.tables, strict=True)
    )


def _match(text: str) -> Match:
    return next(m for m in MATCHES if m == text)


def _table(robot: Robot, found: FoundTable, path: str, name: str) -> Table:
    grouped = any(row.group for row in found.rows)  # then every row keeps its index as written (expand_groups)
    rows = tuple(
        Row(
            index=i,
            line=row.written + 2,
            description=row.description,
            state=row.state,
            events=row.events,
            motors=tuple(row.outputs.get(m) for m in robot.motors),
            timer=row.timer,
            next=row.next,
            counters=tuple(row.outputs.get(c) for c in robot.counter_names),
            lamps=tuple(row.outputs.get(lamp) for lamp in robot.lamps),
            group=row.group,
            written=row.written if grouped else None,
        )
        for i, row in enumerate(sorted(found.rows, key=lambda r: (r.written, r.index)))
    )
    cross = {}
    for event in found.events:
        parsed = parse_cross(event, robot) if name else None
        if isinstance(parsed, str):
            raise fail(path, N_("event column {event!r}: {problem}", event=event, problem=parsed), AS_EXPORTED)
        if parsed is not None:
            cross[event] = parsed
    writes = {output: (0, 0) for output in found.writes}
    return Table(robot=robot, events=found.events, rows=rows, path=path, name=name, cross=cross, writes=writes)
