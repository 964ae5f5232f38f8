"""The parsed table: plain immutable rows exactly as the user wrote them, with their file lines.

A row says: in this state, when these events are all present, set these outputs, load the timer
(and counters), and go to the next state. Nothing here knows about files or execution.
"""

from __future__ import annotations

import re
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field, replace
from functools import cached_property
from typing import Any

from tablebot.i18n import N_, NP_
from tablebot.i18n.headers import GERMAN_FIXED
from tablebot.robot import Robot, StateId
from tablebot.robot_tables import CrossEvent, tables_of

#: The document's direction + speed encoding uses speed 7 for "keep".
DOC_KEEP_SPEED = 7
MAX_SPEED = 8
MAX_LAMP = 8
TIMER_EVENT = "T"
#: The fixed columns of a table, and the other spellings the reader takes for them.
FIXED = ("description", "state", "timer", "next")
ALIASES = {
    "desc": "description",
    "next_state": "next",
    "timer_value": "timer",
    "st": "state",
    **GERMAN_FIXED,
}  # Beschreibung, Zustand, Folgezustand: a German table reads the same in any language


def from_direction_speed(direction: int, speed: int) -> int | None:
    """The document's motor form (direction 0 forward / 1 backward, speed 0-8, 7 = keep) as a signed
    speed, None for keep (the direction then does not matter). The one home of that encoding, with
    :func:`to_direction_speed`: the table reader, the table writer and the ROBO Pro lists use them."""
    if speed == DOC_KEEP_SPEED:
        return None
    return -speed if direction else speed


def to_direction_speed(speed: int | None) -> tuple[int, int]:
    """A signed speed (None: keep) in the document's form: (direction, speed), keep as speed 7."""
    if speed is None:
        return 0, DOC_KEEP_SPEED
    return (1 if speed < 0 else 0), abs(speed)


@dataclass(frozen=True)
class Row:
    """One transition; ``index`` is 0-based in the table as written, ``line`` is the file line.

    A motor speed, lamp level or counter load of ``None`` means "leave it as it is".
    """

    index: int
    line: int
    description: str
    state: StateId
    events: frozenset[str]
    motors: tuple[int | None, ...]
    timer: int
    next: StateId
    counters: tuple[int | None, ...] = ()
    lamps: tuple[int | None, ...] = ()
    #: A row written for a state group (``[groups]``) is one row per state of the group, in its place:
    #: ``group`` names the group, ``written`` is its 0-based index among the rows as written (None: ``index``).
    group: str = ""
    written: int | None = None

    @property
    def as_written(self) -> int:
        """The row's 0-based index as the file writes it (what traces and reports name)."""
        return self.index if self.written is None else self.written


@dataclass(frozen=True)
class Table:
    """A robot plus its rows; ``events`` are the event columns in header order (first = highest bit)."""

    robot: Robot
    events: tuple[str, ...]
    rows: tuple[Row, ...]
    path: str = "<table>"
    #: In a robot of several tables (``[tables]``, :mod:`tablebot.tables`): this table's name there, its
    #: cross-table event columns (event name -> what it reads), and the outputs it has columns for, each with
    #: its header cell (line, column): the one writer of each output. Empty for a robot of one table.
    name: str = field(default="", compare=False)
    cross: dict[str, CrossEvent] = field(default_factory=dict, compare=False)
    writes: dict[str, tuple[int, int]] = field(default_factory=dict, compare=False)

    @cached_property
    def states(self) -> tuple[StateId, ...]:
        """Every state a row names, in order of first appearance (states then next states)."""
        seen: dict[StateId, None] = {}
        for row in self.rows:
            seen.setdefault(row.state, None)
        for row in self.rows:
            seen.setdefault(row.next, None)
        return tuple(seen)

    @cached_property
    def rows_by_state(self) -> dict[StateId, tuple[Row, ...]]:
        """Each state's rows in table order (built once: analysis asks per state, per finding)."""
        by_state: dict[StateId, list[Row]] = {}
        for row in self.rows:
            by_state.setdefault(row.state, []).append(row)
        return {state: tuple(rows) for state, rows in by_state.items()}

    @cached_property
    def memo(self) -> dict[str, Any]:
        """Values derived once per table by later stages (the analysis's state and event names), so a
        100,000-row table is not scanned again for every finding."""
        return {}

    @cached_property
    def bits(self) -> dict[str, int]:
        """Each event's bit in the event mask: the first event column is the highest bit."""
        return {event: 1 << (len(self.events) - 1 - i) for i, event in enumerate(self.events)}

    def bit(self, event: str) -> int:
        """The bit of an event in the event mask: the first event column is the highest bit."""
        try:
            return self.bits[event]
        except KeyError:
            raise ValueError(f"{event!r} is not an event column of this table") from None

    def mask(self, events: frozenset[str] | set[str]) -> int:
        bits = self.bits
        return sum(bits[e] for e in events)

    def state_name(self, state: StateId) -> str:
        """A state's name from the robot file's ``[states]``, else "" (the state is then known by its number).

        The one home of state labels. Row descriptions are never used: some tables describe the state a
        row leaves, others the action it starts, and a blank description continues the one above, so
        "search – give up" would name a state.
        """
        return self.robot.state_names.get(state, "")

    def state_title(self, state: StateId) -> str:
        """``2 · Seek: turn`` (named) or ``state 2``: how pictures and views title a state."""
        name = self.state_name(state)
        return f"{state} · {name}" if name else f"state {state}"

    @property
    def input_events(self) -> tuple[str, ...]:
        """Event columns that are robot inputs (not the timer, not counters)."""
        return tuple(e for e in self.events if e in self.robot.inputs)

    @property
    def engine_inputs(self) -> tuple[str, ...]:
        """Event columns the engine is given from outside the table: the robot's inputs and the cross-table
        events (which the robot's other tables make); the same as :attr:`input_events` in a one-table robot."""
        return tuple(e for e in self.events if e in self.robot.inputs or e in self.cross)


@dataclass(frozen=True)
class NoEventRow:
    """A row that requires no event, and what can bring a tick with no event at all in its state: the one place
    the two matching rules (the robot file's ``match``) part. There ``always`` fires the first such row of the
    state and ``document`` fires nothing."""

    row: Row
    #: Why a tick with no event can come in the row's state; "" when it cannot (T is there on every tick).
    quiet: str


def no_event_rows(table: Table) -> list[NoEventRow]:
    """Every row that requires no event (per state, in table order) and whether the matching rule can matter in
    its state.

    A tick in a state has T whenever the timer is 0 on it: when T is an event column, the robot never starts
    in the state with a timer above 0, and every row that leads into it loads the timer with 0 or 1 (1 has
    counted down to 0 by the next tick), the event set is never empty there and both rules agree. Anything
    else (inputs, counters) is assumed to be able to stay silent, so "can come" may be said of a state that
    never sees such a tick (one never reached, say), never the other way round.
    """
    found = []
    for state, rows in table.rows_by_state.items():
        quiet: str | None = None
        for row in rows:
            if not row.events:  # every such row, a later one too: the README promises each of them a finding
                quiet = _quiet_tick(table, state) if quiet is None else quiet
                found.append(NoEventRow(row, quiet))
    return found


def _quiet_tick(table: Table, state: StateId) -> str:
    robot = table.robot
    if TIMER_EVENT not in table.events:
        if set(robot.counter_names) & set(table.events):
            return N_(
                "the table has no T column, so a tick on which no input reads 1 and no counter is at 0 has no event"
            )
        return N_("the table has no T column, so a tick on which no input reads 1 has no event")
    if state == robot.initial_state and robot.initial_timer > 0:
        return N_(
            "the robot starts in it with timer {timer}, and T is absent until that runs out", timer=robot.initial_timer
        )
    slow = [r for r in table.rows if r.next == state and r.timer > 1]
    if not slow:
        return ""
    if len(slow) > 1:
        return NP_(
            "line {line} leads into it with timer {timer} (and {n} more row), and T is absent until that runs out",
            "line {line} leads into it with timer {timer} (and {n} more rows), and T is absent until that runs out",
            len(slow) - 1,
            line=slow[0].line,
            timer=slow[0].timer,
        )
    return N_(
        "line {line} leads into it with timer {timer}, and T is absent until that runs out",
        line=slow[0].line,
        timer=slow[0].timer,
    )


#: A state that is used but has no rows: (the row whose next state it is, or None when the robot
#: file names it; where the robot file names it, as (section, key); message; hint).
MissingState = tuple[Row | None, tuple[str, str], str, str]


def missing_states(rows: Sequence[Row], robot: Robot) -> list[MissingState]:
    """Every next state, the initial state and every named state must have rows of its own."""
    with_rows = {row.state for row in rows}
    found: list[MissingState] = [
        (
            row,
            ("", "next"),
            N_("next state {state!r} is unknown: no row has state {state!r}", state=row.next),
            N_("add rows for state {state!r} or fix the next state", state=row.next),
        )
        for row in {r.line: r for r in rows if r.next not in with_rows}.values()
    ]  # a group row once
    if robot.initial_state not in with_rows:
        found.append(
            (
                None,
                ("", "initial_state"),
                N_(
                    "initial state {state!r} (from {source} robot {robot}) has no rows",
                    state=robot.initial_state,
                    source=robot.source,
                    robot=robot.name,
                ),
                N_("add rows for it or change initial_state in the robot file"),
            )
        )
    if tables_of(robot):  # [states] names the states of all the robot's tables (tablebot.tables checks them)
        return found
    found += [
        (
            None,
            ("states", str(state)),
            N_("state {state!r} is named in {source} but has no rows", state=state, source=robot.source),
            N_("add rows for it or remove it from [states]"),
        )
        for state in robot.state_names
        if state not in with_rows
    ]
    return found


def normalise_header(name: str) -> str:
    """A header cell as the table reader reads it: a fixed column (any case, alias, spaces or dashes) by its
    own name, any other name as written (spaces and dashes made ``_``)."""
    key = re.sub(r"[\s-]+", "_", name.strip())
    low = key.lower()
    low = ALIASES.get(low, low)
    return low if low in FIXED else key


def is_table_header(cells: Iterable[str]) -> bool:
    """Whether header cells name a state and a next column (spelled any way :func:`parse_table` takes)."""
    names = {normalise_header(text) for text in cells}
    return "state" in names and "next" in names


#: A row written for a group that cannot be: (the row, "state" or "next": the cell to blame, message, hint).
GroupProblem = tuple[Row, str, str, str]


def expand_groups(rows: Sequence[Row], groups: dict[str, tuple[StateId, ...]]) -> tuple[list[Row], list[GroupProblem]]:
    """The rows as the engine runs them: a row whose state is a group (``[groups]``) becomes one row per state of
    the group, in its place, so that a state's candidate rows are its own and its groups', in table order.
    Indices are renumbered; each row keeps its line and its index as written (:attr:`Row.as_written`). A group
    is no next state: a robot is in one state at a time."""
    used = {row.state for row in rows if row.state in groups}
    if not used:
        return list(rows), []
    problems: list[GroupProblem] = [
        (
            row,
            "next",
            f"next state {row.next!r} is a group ([groups]): a robot is in one state at a time",
            "go to one of its states",
        )
        for row in rows
        if row.next in groups
    ]
    expanded: list[Row] = []
    for row in rows:
        states = groups.get(row.state, (row.state,)) if row.state in used else (row.state,)
        for state in states:
            group = str(row.state) if row.state in used else ""
            expanded.append(replace(row, index=len(expanded), state=state, group=group, written=row.index))
    return expanded, problems
