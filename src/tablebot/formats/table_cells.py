"""What one cell of a table file says (:mod:`tablebot.formats.table_read` reads the file, its header and its rows):
a header cell's :class:`Column`, and a row's cells read by their column's kind: whole numbers in range, state
numbers and names, timers as ticks or times, a motor's signed speed. Errors go to a :class:`Collector` at the
cell's line and column, with a hint."""

from __future__ import annotations

import re
from dataclasses import dataclass
from typing import Any

from tablebot.csvtext import Cell
from tablebot.diagnostics import Collector
from tablebot.durations import MAX_NUMBER_CHARS, DurationError, seconds, to_ticks
from tablebot.i18n import N_, Message
from tablebot.robot import MAX_TIMER, STATE_HINT, STATE_RE, StateId
from tablebot.table import MAX_LAMP, MAX_SPEED, from_direction_speed

__all__ = [
    "INT_RE",
    "KEEP_WORDS",
    "NUMBERS",
    "TIME_RE",
    "Column",
    "motor_speed",
    "range_hint",
    "read_int",
    "read_state",
    "read_timer",
    "read_value",
    "whole",
]

KEEP_WORDS = {"=", "keep", "k"}
INT_RE = re.compile(r"^[+-]?\d+(\.0*)?$")
TIME_RE = re.compile(r"[A-Za-z]\s*$")  # a timer cell that ends in a unit (500ms, 0.5 s, 3 ticks) is a duration


@dataclass(frozen=True)
class Column:
    """What one header cell means: a fixed column, an event, or one field of an output."""

    kind: str  # description|state|timer|next|event|dir|speed|signed|lamp|load, or ignore (no such column)
    name: str  # event/motor/lamp/counter name, or the fixed column's name
    cell: Cell


def whole(text: str) -> int:
    """The integer of a cell that matches INT_RE ("3", "+3", "3.0"), exactly: no detour through float."""
    return int(text.partition(".")[0])


def read_int(
    cell: Cell, what: str, low: int, high: int, out: Collector, blank: int | None = 0, keep: bool = False
) -> int | None:
    text = cell.text.strip()
    if not text:
        return blank
    if keep and text.lower() in KEEP_WORDS:
        return None
    hint = range_hint(low, high, keep)
    if not INT_RE.match(text):
        out.error(cell.line, cell.column, N_("{what}: {text!r} is not an integer", what=what, text=text), hint)
        return blank
    if len(text) > MAX_NUMBER_CHARS:  # never in range, and int() of it may fail
        out.error(
            cell.line,
            cell.column,
            N_(
                "{what}: a number of {count:,} characters is out of range {low}..{high}",
                what=what,
                count=len(text),
                low=low,
                high=high,
            ),
            hint,
        )
        return blank
    value = whole(text)
    if not low <= value <= high:
        out.error(
            cell.line,
            cell.column,
            N_("{what}: {value} is out of range {low}..{high}", what=what, value=value, low=low, high=high),
            hint,
        )
        return blank
    return value


def range_hint(low: int, high: int, keep: bool) -> Message:
    if (low, high) == (0, 1):  # event and direction cells: a flag, not a quantity
        return N_("write 1 or 0 (a blank cell is 0)")
    if (low, high, keep) == (0, MAX_TIMER, False):  # the timer: ticks or a time
        return N_("write a whole number of ticks from 0 to {high}, or a time such as 500ms, 0.5s or 0,5s", high=high)
    if keep:
        return N_("write a whole number from {low} to {high}, or = to keep it as it is", low=low, high=high)
    return N_("write a whole number from {low} to {high}", low=low, high=high)


def read_state(cell: Cell, what: str, out: Collector) -> StateId | None:
    text = cell.text.strip()
    if not text:
        out.error(cell.line, cell.column, N_("{what} is missing", what=what), N_("write a state number or name"))
        return None
    if INT_RE.match(text) and len(text) > MAX_NUMBER_CHARS:  # int() of it may fail
        out.error(
            cell.line,
            cell.column,
            N_("{what}: a number of {count:,} characters is too long", what=what, count=len(text)),
            N_("a state number has at most {most} characters; or use a name", most=MAX_NUMBER_CHARS),
        )
        return None
    if INT_RE.match(text):
        value = whole(text)
        if value < 0:
            out.error(
                cell.line,
                cell.column,
                N_("{what} {value} is negative", what=what, value=value),
                N_("states are 0 or more"),
            )
        return value
    if not STATE_RE.match(text):
        out.error(
            cell.line, cell.column, N_("{what} {text!r} is not a valid state name", what=what, text=text), STATE_HINT
        )
        return None
    return text


#: How read_int reads each numeric column kind: (low, high, value of a blank cell, whether "=" keeps).
NUMBERS: dict[str, tuple[int, int, int | None, bool]] = {
    "timer": (0, MAX_TIMER, 0, False),
    "event": (0, 1, 0, False),
    "dir": (0, 1, 0, False),
    "speed": (0, MAX_SPEED, 0, False),
    "signed": (-MAX_SPEED, MAX_SPEED, 0, True),
    "lamp": (0, MAX_LAMP, None, True),
    "load": (0, MAX_TIMER, None, True),
}


def read_value(column: Column, cell: Cell, out: Collector, tick_ms: int) -> Any:
    """What one cell says (never a description: :func:`_cached` takes those as they are): a state, a
    number or None (keep); errors go to ``out``."""
    kind, text = column.kind, cell.text.strip()
    if kind == "timer" and TIME_RE.search(text):
        return read_timer(cell, tick_ms, out)
    if kind in ("state", "next"):
        return read_state(cell, N_("next state") if kind == "next" else N_("state"), out)
    if kind in NUMBERS:
        low, high, blank, keep = NUMBERS[kind]
        label = column.cell.text.strip()
        what = N_("timer") if kind == "timer" else N_("event {label}", label=label) if kind == "event" else label
        return read_int(cell, what, low, high, out, blank, keep)
    return None  # an ignored column: one with a name was reported in the header, a blank one by _Layout


def read_timer(cell: Cell, tick_ms: int, out: Collector) -> int:
    """A timer cell written as a time (``500ms``, ``0.5s``, ``3 ticks``): whole ticks, or 0 after an error."""
    text = cell.text.strip()
    try:
        ticks = to_ticks(text, tick_ms)
    except DurationError as exc:
        out.error(cell.line, cell.column, N_("timer: {problem}", problem=exc.message), exc.hint)
        return 0
    if ticks > MAX_TIMER:
        out.error(
            cell.line,
            cell.column,
            N_(
                "timer: {text} is {ticks} ticks, more than the timer holds ({most})",
                text=text,
                ticks=ticks,
                most=MAX_TIMER,
            ),
            N_(
                "the longest timer is {most} ticks ({seconds:g} s at {tick} ms a tick)",
                most=MAX_TIMER,
                seconds=seconds(MAX_TIMER, tick_ms),
                tick=tick_ms,
            ),
        )
        return 0
    return ticks


def motor_speed(motor: str, values: dict[tuple[str, str], Any], several: bool = False) -> int | None:
    """The signed speed (None = keep) from either the document's dir+speed form or a signed cell; in a robot
    of ``several`` tables, a motor the table has no column for is another table's: kept."""
    if ("signed", motor) in values:
        return values[("signed", motor)]
    if several and ("dir", motor) not in values and ("speed", motor) not in values:
        return None
    return from_direction_speed(values.get(("dir", motor)) or 0, values.get(("speed", motor)) or 0)
