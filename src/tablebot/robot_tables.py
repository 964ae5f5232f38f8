"""A robot file's ``[tables]`` and ``[groups]``: several tables in one robot, and state groups (issue 36).

What a robot file says about them, read and checked here; the tables themselves, loaded and run together, are
:mod:`tablebot.tables` (the multi-table model's one home, with the semantics in its docstring)::

    [tables]                                   # the first is the main table
    drive  = { file = "table.csv", initial_state = 2, initial_timer = 0 }
    lights = { file = "lights.csv", initial_state = 1, match = "always" }

    [groups]                                   # a row whose state is a group is a row of each of its states
    seeking = [1, 2, 11]

A table's event column may be a **cross-table event**, ``NAME=S``, ``NAME=S1,S2``, ``NAME=20..29`` (state
names too, and lists of both): present on a tick when table ``NAME`` was in one of those states at the start
of the tick. :func:`parse_cross` reads such a header; :class:`CrossEvent` is what it says.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from typing import Any, cast

from tablebot.i18n import N_
from tablebot.robot import (
    MATCH_HINT,
    MATCHES,
    MAX_TIMER,
    NAME_RE,
    STATE_HINT,
    STATE_RE,
    Match,
    Robot,
    StateId,
    register_section,
)
from tablebot.tomlfile import Source

__all__ = ["CrossEvent", "TableSpec", "groups_of", "parse_cross", "spec_robot", "tables_of"]

#: The keys a ``[tables]`` entry may have.
SPEC_KEYS = ("file", "initial_state", "initial_timer", "match")
#: At most this many tables in one robot (each is a process on ROBO Pro, a task on a controller).
MAX_TABLES = 8
RANGE_RE = re.compile(r"^(\d{1,9})\.\.(\d{1,9})$")
TABLES_HINT = N_('write [tables] as NAME = { file = "table.csv", initial_state = 1 }, the main table first')


@dataclass(frozen=True)
class TableSpec:
    """One entry of ``[tables]``: the table's name and file (relative to the robot file), and how it starts
    (the robot file's top-level ``initial_state``, ``initial_timer`` and ``match`` where it does not say)."""

    name: str
    file: str
    initial_state: StateId
    initial_timer: int
    match: Match


@dataclass(frozen=True)
class CrossEvent:
    """A cross-table event column: present when table ``table`` was in one of ``states`` (or in a range of
    ``ranges``, both ends included) at the start of the tick. ``column`` is the header as read (spaces
    dropped), which is the event's name in the table; ``line`` and ``at`` locate its header cell."""

    column: str
    table: str
    states: tuple[StateId, ...]
    ranges: tuple[tuple[int, int], ...] = ()
    line: int = 0
    at: int = 0

    def covers(self, state: StateId) -> bool:
        """Whether the event is present while its table is in ``state``."""
        if state in self.states:
            return True
        return isinstance(state, int) and any(low <= state <= high for low, high in self.ranges)


def tables_of(robot: Robot) -> tuple[TableSpec, ...]:
    """The robot's tables, the main one first; () for a robot of one table (no ``[tables]``)."""
    return cast(tuple[TableSpec, ...], robot.sections.get("tables", ()))


def groups_of(robot: Robot) -> dict[str, tuple[StateId, ...]]:
    """The robot's state groups: name -> its states, as ``[groups]`` lists them."""
    return cast(dict[str, tuple[StateId, ...]], robot.sections.get("groups", {}))


def spec_robot(robot: Robot, spec: TableSpec) -> Robot:
    """The robot as one of its tables runs on it: that table's start and matching rule."""
    from dataclasses import replace

    return replace(robot, initial_state=spec.initial_state, initial_timer=spec.initial_timer, match=spec.match)


def parse_cross(text: str, robot: Robot) -> CrossEvent | str | None:
    """A header cell as a cross-table event (``drive=20..29``): the event, a message saying what is wrong
    with it, or None when the cell is no cross-table column at all (no ``=``, or a robot of one table)."""
    specs = tables_of(robot)
    if "=" not in text or not specs:
        return None
    name, _, what = (part.strip() for part in text.strip().partition("="))
    names = [spec.name for spec in specs]
    if name not in names:
        return N_(
            "{text!r} names table {name!r}, which is not in [tables] ({names})",
            text=text.strip(),
            name=name,
            names=tuple(names),
        )
    states: list[StateId] = []
    ranges: list[tuple[int, int]] = []
    for part in (p.strip() for p in what.split(",")):
        span = RANGE_RE.match(part)
        if span and int(span[1]) <= int(span[2]):
            ranges.append((int(span[1]), int(span[2])))
            continue
        state = _state(part)
        if state is None:
            return N_(
                "{part!r} in {text!r} is no state, list of states or range LOW..HIGH of table {name}",
                part=part,
                text=text.strip(),
                name=name,
            )
        states.append(state)
    column = f"{name}={','.join(p.strip() for p in what.split(','))}"
    return CrossEvent(column, name, tuple(states), tuple(ranges))


def _state(text: str) -> StateId | None:
    """A state as a table writes it: a whole number (0 or more, at most nine digits) or a name."""
    if text.isascii() and text.isdigit() and len(text) <= 9:
        return int(text)
    return text if STATE_RE.match(text) else None


# --- reading the robot file's sections ------------------------------------------------------------------


def _read_tables(src: Source, data: Any, robot: Robot) -> tuple[TableSpec, ...]:
    """``[tables]``: NAME = { file = ..., initial_state = ..., initial_timer = ..., match = ... }."""
    if not isinstance(data, dict) or not data:
        src.key_error(("", None, "tables"), N_("[tables] must name at least one table"), TABLES_HINT)
        return ()
    specs: list[TableSpec] = []
    files: dict[str, str] = {}
    for name, entry in data.items():
        spec = _spec(src, name, entry, robot)
        if spec is None:
            continue
        if spec.file in files:
            src.key_error(
                ("tables", None, name),
                N_("tables {first} and {second} both read {file}", first=files[spec.file], second=name, file=spec.file),
                N_("give each table its own file"),
            )
        files.setdefault(spec.file, name)
        specs.append(spec)
    if len(data) > MAX_TABLES:
        src.key_error(
            ("", None, "tables"),
            N_("[tables] names {count} tables, more than {most}", count=len(data), most=MAX_TABLES),
            N_("join tables that drive the same outputs; a robot runs at most eight at once"),
        )
    return tuple(specs)


def _spec(src: Source, name: str, entry: Any, robot: Robot) -> TableSpec | None:
    where = ("tables", None, name)
    if not NAME_RE.match(name):
        src.key_error(
            where,
            N_("bad table name {name!r}", name=name),
            N_("use a letter then letters/digits, like drive or lights"),
        )
        return None
    if not isinstance(entry, dict) or not isinstance(entry.get("file"), str) or not entry["file"].strip():
        src.key_error(
            where,
            N_("table {name} must say which file it is", name=name),
            N_('write {name} = {{ file = "{name}.csv" }}', name=name),
        )
        return None
    for key in entry:
        if key not in SPEC_KEYS:
            src.key_error(
                where,
                N_("table {name}: unknown key {key!r}", name=name, key=key),
                N_("known keys: {keys}", keys=tuple(SPEC_KEYS)),
            )
    state = entry.get("initial_state", src.data.get("initial_state"))
    initial = _state(str(state)) if isinstance(state, int | str) and not isinstance(state, bool) else None
    if initial is None:
        src.key_error(
            where,
            N_("table {name}: initial_state {state!r} is not a state", name=name, state=state)
            if state is not None
            else N_("table {name} has no initial_state (and the robot file none above [tables])", name=name),
            N_("write {name} = {{ file = ..., initial_state = 1 }}; {hint}", name=name, hint=STATE_HINT),
        )
    timer = entry.get("initial_timer", robot.initial_timer)
    if not isinstance(timer, int) or isinstance(timer, bool) or not 0 <= timer <= MAX_TIMER:
        src.key_error(
            where,
            N_(
                "table {name}: initial_timer must be a whole number 0..{most}, not {timer!r}",
                name=name,
                most=MAX_TIMER,
                timer=timer,
            ),
            N_("the timer counts ticks; 0 means it has expired"),
        )
        timer = 0
    match = entry.get("match", robot.match)
    if match not in MATCHES:
        src.key_error(
            where,
            N_(
                "table {name}: match must be one of {matches}, not {match!r}",
                name=name,
                matches=tuple(MATCHES),
                match=match,
            ),
            MATCH_HINT,
        )
        match = robot.match
    return TableSpec(name, entry["file"], initial if initial is not None else 0, timer, cast(Match, match))


def _read_groups(src: Source, data: Any, robot: Robot) -> dict[str, tuple[StateId, ...]]:
    """``[groups]``: NAME = [state, state, ...]; a row whose state is NAME is a row of each of them."""
    del robot  # groups are checked against the tables when they are read
    if not isinstance(data, dict):
        src.key_error(
            ("", None, "groups"),
            N_("[groups] must be a table of NAME = [states]"),
            N_("for example: {example}", example="seeking = [1, 2, 11]"),
        )
        return {}
    groups: dict[str, tuple[StateId, ...]] = {}
    for name, members in data.items():
        where = ("groups", None, name)
        if _state(name) is None or name.isdigit():
            src.key_error(where, N_("group name {name!r} must be a state name, not a number", name=name), STATE_HINT)
            continue
        states = (
            [_state(str(m)) if isinstance(m, int | str) and not isinstance(m, bool) else None for m in members]
            if isinstance(members, list)
            else [None]
        )
        if not states or None in states:
            src.key_error(
                where,
                N_("group {name} must list its states, not {members!r}", name=name, members=members),
                N_("for example: {example}", example=name + " = [1, 2, 11]"),
            )
            continue
        if len(set(states)) != len(states):
            src.key_error(where, N_("group {name} lists a state twice", name=name), N_("list each state once"))
            continue
        if name in states:
            src.key_error(
                where, N_("group {name} lists itself", name=name), N_("a group lists states, not other groups")
            )
            continue
        groups[name] = tuple(s for s in states if s is not None)
    return groups


register_section("tables", _read_tables)
register_section("groups", _read_groups)
