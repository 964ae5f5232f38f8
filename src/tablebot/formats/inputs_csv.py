"""Recorded inputs as CSV: a header of input names (and counter names for pulses), one row per tick
(and, for replaying a recorded run, a run's JSON Lines trace).

The reader and the writer of the format ``tablebot trace --inputs`` reads and ``check`` and ``tests``
write (counterexamples, golden sequences).
"""

from __future__ import annotations

import csv
import io
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from operator import attrgetter
from pathlib import Path
from typing import Any, Protocol

from tablebot.csvtext import Cell, cells_beyond, headerless, read_records, read_text, records_after
from tablebot.diagnostics import Collector, TableBotError, fail
from tablebot.durations import MAX_NUMBER_CHARS
from tablebot.files import write_text
from tablebot.formats.trace_lines import trace_records
from tablebot.i18n import N_
from tablebot.table import TIMER_EVENT, Table


class Events(Protocol):
    """What reading inputs needs of a compiled machine (:class:`tablebot.machine.Machine` is one): the bit
    of each input in the event mask, and the table with its robot."""

    @property
    def input_bits(self) -> Mapping[str, int]: ...
    @property
    def input_mask(self) -> int: ...
    @property
    def table(self) -> Table: ...


@dataclass(frozen=True, slots=True)  # slots: a long recording holds a million of them
class TickInput:
    """What the robot read in one tick: input bits in event layout, and pulses per counter."""

    mask: int
    pulses: tuple[int, ...] = ()


#: The most ticks an inputs file (or a replayed trace) may give: nearly three hours at 10 ms ticks, and a
#: simulated run is at most an hour. Counted as they are read, before more is kept.
MAX_INPUT_TICKS = 1_000_000
#: The most distinct rows remembered while reading (a column of tick numbers makes every row distinct).
MAX_SEEN_ROWS = 4096


def load_inputs(path: str | Path, machine: Events) -> list[TickInput]:
    """Read an inputs CSV: a header of input (and counter-pulse) names, one row per tick, blank = 0; or a
    run's trace (JSON Lines, see :func:`trace_inputs`)."""
    path = Path(path)
    text = read_text(path)
    if path.suffix.lower() == ".jsonl" or text.lstrip().startswith("{"):
        return trace_inputs(path, text, machine)
    records = read_records(text, str(path))  # one at a time: only the ticks are kept
    header = next((record for record in records if not record.is_blank()), None)  # blank lines above it
    if header is None:  # (below it, a blank row is a tick)
        raise fail(
            path, N_("the inputs file is empty"), N_("write a header of input names, then one row per tick"), 1, 1
        )
    after = records_after(text, header.line)
    if after is not None and after > MAX_INPUT_TICKS:  # known at once: no row is read
        raise _too_many_ticks(path, header.line + MAX_INPUT_TICKS + 1)
    out = Collector(path)
    columns = _columns(header.cells, machine, out)
    ticks: list[TickInput] = []
    seen: dict[tuple[str, ...], TickInput] = {}  # a row's texts -> its tick: a recording repeats a few rows
    for record in records:
        _count(ticks, path, record.line)
        key = tuple(map(attrgetter("text"), record.cells))
        tick = seen.get(key)
        if tick is None:
            errors = len(out.items)
            tick = _tick(record.cells, columns, machine, out)
            if len(out.items) == errors and len(seen) < MAX_SEEN_ROWS:  # a bad cell is reported at each place
                seen[key] = tick
        ticks.append(tick)
    out.raise_if_any()
    return ticks


def _count(ticks: list[TickInput], path: Path, line: int) -> None:
    """Refuse the tick about to be added to ``ticks`` (read from ``line``) if it is one too many."""
    if len(ticks) == MAX_INPUT_TICKS:
        raise _too_many_ticks(path, line)


def _too_many_ticks(path: Path, line: int) -> TableBotError:
    return fail(
        path,
        N_("more than {most:,} ticks, the most tablebot replays", most=MAX_INPUT_TICKS),
        N_("replay a shorter recording (split the file)"),
        line,
        1,
    )


def _columns(header: Sequence[Cell], machine: Events, out: Collector) -> list[tuple[str, str]]:
    """(kind, name) per header cell: ``input``, ``pulses`` (a counter), ``tick`` or ``blank`` (read
    but ignored), or ``bad`` (already reported)."""
    robot = machine.table.robot
    columns: list[tuple[str, str]] = []
    seen: dict[str, Cell] = {}
    for cell in header:
        name = cell.text.strip()
        kind = (
            "input"
            if name in robot.inputs
            else "pulses"
            if name in robot.counter_names
            else "tick"
            if name == "tick"
            else "blank"
            if not name
            else "bad"
        )
        if name == TIMER_EVENT:
            out.error(
                cell.line,
                cell.column,
                N_("T is never an input: the engine makes it from the timer"),
                N_("remove the T column"),
            )
        elif kind == "bad":
            out.error(
                cell.line,
                cell.column,
                N_("unknown input {name!r} for robot {robot}", name=name, robot=robot.name),
                N_(
                    "inputs are {inputs}; counters (pulses per tick) are {counters}",
                    inputs=", ".join(robot.inputs),
                    counters=", ".join(robot.counter_names) or N_("none"),
                ),
            )
        elif name in seen:
            out.error(
                cell.line,
                cell.column,
                N_("column {name!r} appears twice (first at column {first})", name=name, first=seen[name].column),
                N_("delete or rename one of them"),
            )
            kind = "bad"
        if name:
            seen.setdefault(name, cell)
        columns.append((kind, name))
    return columns


def _tick(cells: Sequence[Cell], columns: list[tuple[str, str]], machine: Events, out: Collector) -> TickInput:
    counters = machine.table.robot.counter_names
    mask = 0
    pulses = [0] * len(counters)
    for (kind, name), cell in zip(columns, cells, strict=False):
        text = cell.text.strip()
        if kind in ("bad", "tick") or not text:
            continue
        if kind == "blank":
            headerless(cell, out)
        elif not (text.isascii() and text.isdigit()) or (kind == "input" and text not in ("0", "1")):
            if kind == "input":
                out.error(
                    cell.line,
                    cell.column,
                    N_("{name}: {text!r} is not 0 or 1", name=name, text=text),
                    N_("write 0 or 1; blank means 0"),
                )
            else:
                out.error(
                    cell.line,
                    cell.column,
                    N_("{name}: {text!r} is not a pulse count (0 or more)", name=name, text=text),
                    N_("write a pulse count (0 or more); blank means 0"),
                )
        elif kind == "input":
            mask |= machine.input_bits.get(name, 0) if text == "1" else 0
        elif len(text) > MAX_NUMBER_CHARS:  # int() of it may fail, and no encoder counts that many in a tick
            out.error(
                cell.line,
                cell.column,
                N_("{name}: a number of {count:,} characters is too many pulses", name=name, count=len(text)),
                N_("write the pulses of one tick (a few at most); blank means 0"),
            )
        else:
            pulses[counters.index(name)] = int(text)
    cells_beyond(cells, len(columns), out)
    return TickInput(mask, tuple(pulses))


def write_inputs(machine: Events, ticks: Sequence[TickInput], path: Path) -> Path:
    """Write ``ticks`` as an inputs CSV (1 for an input that reads 1, blank for 0; pulses per counter)."""
    return write_text(path, format_inputs(machine, ticks))


def format_inputs(machine: Events, ticks: Sequence[TickInput]) -> str:
    names = list(machine.input_bits)
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow([*names, *machine.table.robot.counter_names])
    for tick in ticks:
        cells = ["1" if tick.mask & machine.input_bits[n] else "" for n in names]
        cells += [str(p) if p else "" for p in tick.pulses]
        writer.writerow(cells)
    return buffer.getvalue()


def pulses_key(counter: str) -> str:
    """The field of a run's trace that records counter ``counter``'s encoder pulses in each tick."""
    return f"{counter}_pulses"


def trace_inputs(path: Path, text: str, machine: Events) -> list[TickInput]:
    """The inputs a recorded run gave the engine (``tablebot run --out``, ``tablebot sim``): per line, the
    input bits of ``event`` and each counter's ``<counter>_pulses``; an ``{"end": ...}`` record ends it.
    Replaying them with the same table takes the same decisions."""

    out = Collector(path)
    keys = ("event", *(pulses_key(c) for c in machine.table.robot.counter_names))
    ticks: list[TickInput] = []
    seen: dict[tuple[Any, ...], TickInput] = {}  # one tick object per distinct tick: a run repeats a few
    for number, data in trace_records(text, out):
        values: list[Any] = [data.get(key) for key in keys]  # JSON values, checked just below
        bad = [
            key for key, v in zip(keys, values, strict=True) if isinstance(v, bool) or not isinstance(v, int) or v < 0
        ]
        if bad:
            out.error(
                number,
                1,
                N_("this trace line has no whole-number {key}", key=bad[0]),
                N_("replay a trace that a run of this table recorded (tablebot run --out)"),
            )
            continue
        _count(ticks, path, number)
        key = (values[0] & machine.input_mask, *values[1:])
        tick = seen.get(key) or TickInput(key[0], key[1:])
        if len(seen) < MAX_SEEN_ROWS:
            seen[key] = tick
        ticks.append(tick)
    out.raise_if_any()
    return ticks
