"""What the SCXML and XState exports share: the tick model, and the names a table's parts get in a statechart.

The tick model (docs/statecharts.md): the robot is one statechart whose data model holds every register of the
engine. A program sends one event per tick, ``tick``, carrying the input image (each input 0 or 1, each counter's
encoder pulses since the last tick, by name). The event's one transition, on the wrapper state, is the first half
of the tick: the timers and counters count down (not on the first tick), the event flags are set (``has_T`` when
the timer is 0, ``has_I3`` when I3 reads 1, ``has_C1`` when counter C1 is 0) and each table's ``pending`` is set.
The second half is eventless: in each table's current state the first transition (table order) whose guard holds
fires: a row's guard is ``pending`` and its events; the last transition of every state fires when no row did.
Each clears ``pending``, so the statechart is stable again before the next tick. Cross-table events are ``In()``
(SCXML) and ``stateIn`` (XState): all tables' eventless transitions are selected in one microstep, before any of
them fires, so they see the states at the start of the tick, as the engine's rule says (the W3C SCXML
recommendation, Appendix D, selectEventlessTransitions; statelyai/xstate, packages/core/src/stateUtils.ts,
selectEventlessTransitions and macrostep). The timer lives in the data model: never ``<send delay>``, which is
wall-clock time in every engine.

A table's names: states are ``s12`` (state 12) or ``n_`` and the name with every character but A-Z, a-z, 0-9 as
``_HEX_`` (``Seek turn``: ``n_Seek_20_turn``), so that ids are XML names and JavaScript identifiers and read back
exactly; in a robot of several tables each table's states, timer, flags and ``pending`` carry its name and ``_``
(``drive_s12``, ``drive_timer``), and its region is the table's name. Inputs, outputs and counters are the robot's
and keep their names; the chart's own data items (``is_started``, ``is_pending``, ``fired_row``, ``has_I3``) and the
event data's pulse keys (``C1_pulses``) have an underscore, which no name in a robot file has, so none can clash.
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from dataclasses import dataclass

from tablebot.robot import StateId
from tablebot.table import TIMER_EVENT, Row, Table

__all__ = ["STARTED", "TICK", "WRAPPER", "Chart", "Part", "chart_of", "pulses", "state_id", "state_of"]

#: The one event a program sends per tick.
TICK = "tick"
#: The id of the state (SCXML) that wraps one table, or of the parallel state that holds several.
WRAPPER = "robot_"
#: The data item that says the first tick has come (nothing counts down on it).
STARTED = "is_started"


def pulses(counter: str) -> str:
    """The key of a counter's pulses in a tick's event data (``C1_pulses``: python-statemachine gives the event
    data's keys as names to expressions, before the data model's, so ``C1`` there would hide the counter)."""
    return f"{counter}_pulses"


_PLAIN = re.compile(r"[A-Za-z0-9]")
_CODE = re.compile(r"_([0-9a-f]{1,6})_")


def state_id(state: StateId, prefix: str = "") -> str:
    """A state's id in the statechart: ``s12``, ``n_Seek_20_turn`` (with the table's prefix in a robot of several)."""
    if isinstance(state, int):
        return f"{prefix}s{state}"
    return f"{prefix}n_" + "".join(c if _PLAIN.match(c) else f"_{ord(c):x}_" for c in str(state))


def state_of(ident: str, prefix: str = "") -> StateId | None:
    """The state an id names (:func:`state_id` read back), or None when it is no such id."""
    if not ident.startswith(prefix):
        return None
    body = ident[len(prefix) :]
    if (
        body[:1] == "s"
        and body[1:].isascii()
        and body[1:].isdigit()
        and len(body) <= 10
        and (body == "s0" or body[1] != "0")
    ):
        return int(body[1:])
    if not body.startswith("n_") or len(body) == 2:
        return None
    out, at, text = [], 0, body[2:]
    while at < len(text):
        code = _CODE.match(text, at)
        if code:
            out.append(chr(int(code[1], 16)))
            at = code.end()
        elif _PLAIN.match(text[at]):
            out.append(text[at])
            at += 1
        else:
            return None
    name = "".join(out)
    return name if state_id(name) == body else None


@dataclass(frozen=True)
class Part:
    """One table of the chart: the table, and the prefix (``""`` alone, ``drive_`` among several) and region id
    (``""`` alone, else its name) it has there."""

    table: Table
    prefix: str
    region: str

    def state(self, state: StateId) -> str:
        return state_id(state, self.prefix)

    @property
    def timer(self) -> str:
        return f"{self.prefix}timer"

    @property
    def pending(self) -> str:
        return f"{self.prefix}is_pending"

    @property
    def row(self) -> str:
        return f"{self.prefix}fired_row"

    def flag(self, event: str) -> str | None:
        """The data item that says whether ``event`` is present this tick; None for a cross-table event."""
        if event == TIMER_EVENT:
            return f"{self.prefix}has_T"
        return None if event in self.table.cross else f"has_{event}"

    def cross_states(self, event: str, parts: Sequence[Part]) -> tuple[str, str, tuple[str, ...]]:
        """A cross-table event as the chart tests it: the other table's region, the column, and the ids of its
        states in which the event is present (in that table's order)."""
        cross = self.table.cross[event]
        source = next(p for p in parts if p.table.name == cross.table)
        return source.region, event, tuple(source.state(s) for s in source.table.states if cross.covers(s))

    def states_rows(self) -> list[tuple[StateId, list[Row]]]:
        """Each state with its rows in table order (a group's rows in their place), every state the table
        names, rows or not."""
        return [(state, list(self.table.rows_by_state.get(state, ()))) for state in self.table.states]

    def needs_some(self, row: Row) -> bool:
        """Whether the row's guard must also ask for some event: a row that requires none, under the document's
        rule (a tick with no event at all looks up no row)."""
        return not row.events and self.table.robot.match == "document"


@dataclass(frozen=True)
class Chart:
    """A robot's tables as one statechart: one part alone, or several regions of a parallel state."""

    parts: tuple[Part, ...]

    @property
    def main(self) -> Table:
        return self.parts[0].table

    @property
    def several(self) -> bool:
        return len(self.parts) > 1

    @property
    def inputs(self) -> tuple[str, ...]:
        """The inputs any table reads, in the robot file's order (the robot-wide input image)."""
        used = {name for p in self.parts for name in p.table.input_events}
        return tuple(name for name in self.main.robot.inputs if name in used)


def chart_of(tables: Sequence[Table]) -> Chart:
    """The chart of a robot's tables (the main one first; one table: no prefixes, no regions)."""
    if len(tables) == 1:
        return Chart((Part(tables[0], "", ""),))
    return Chart(tuple(Part(t, f"{t.name}_", t.name) for t in tables))
