"""JSON Lines traces: the format every tablebot tool writes and compares (recorded inputs are read by
:mod:`tablebot.formats.inputs_csv`).

A trace line is one tick: ``tick``, ``event`` (bitmask, first event column highest), ``row``
(0-based fired row or null), ``state`` and ``timer`` after the tick, each motor's signed speed,
each lamp's level and each counter's value. Extra fields (a simulator's pose) may follow.
"""

from __future__ import annotations

import json
import queue
import threading
from collections.abc import Iterable, Iterator
from pathlib import Path
from typing import IO, Any

import numpy as np

from tablebot.diagnostics import Collector
from tablebot.engine import Engine
from tablebot.files import PendingFile
from tablebot.formats.csvtext import read_text
from tablebot.formats.inputs_csv import TickInput, load_inputs  # noqa: F401  (load_inputs: for callers)
from tablebot.loop import RunEnd, RunInfo, TickBlock
from tablebot.machine import NO_ROW, Machine


def record(engine: Engine) -> dict[str, Any]:
    """The trace line of the tick the engine just made."""
    m = engine.machine
    line: dict[str, Any] = {
        "tick": engine.tick - 1,
        "event": engine.event,
        "row": None if engine.row == NO_ROW else engine.row,
        "state": m.states[engine.state],
        "timer": engine.timer,
    }
    line.update(zip(m.output_names, engine.outputs, strict=True))
    line.update(zip(m.table.robot.counter_names, engine.counters, strict=True))
    return line


def replay(machine: Machine, ticks: Iterable[TickInput]) -> Iterator[dict[str, Any]]:
    """Run a fresh engine over recorded inputs, yielding one trace line per tick."""
    engine = Engine(machine)
    for tick in ticks:
        engine.step(tick.mask, tick.pulses)
        yield record(engine)


def dumps(line: dict[str, Any]) -> str:
    """One trace line as compact JSON: the same line always gives the same bytes."""
    return json.dumps(line, separators=(",", ":"), ensure_ascii=False)


def block_lines(block: TickBlock, machine: Machine) -> list[str]:
    """The trace lines of a block of ticks, newline included: the bytes :func:`dumps` gives for
    :func:`record` plus the block's extra fields, made column-wise (a simulated hour in well under a second)."""
    names = [json.dumps(state, ensure_ascii=False) for state in machine.states]
    columns = [*machine.output_names, *machine.table.robot.counter_names]
    template = ('{"tick":%d,"event":%d,"row":%s,"state":%s,"timer":%d'
                + "".join(f",{json.dumps(name)}:%d" for name in columns)
                + "".join(f",{json.dumps(key, ensure_ascii=False)}:%s" for key in block.extra) + "}\n")
    n = len(block)
    values = [range(block.start, block.start + n), _ints(block.events),
              ["null" if r < 0 else str(r) for r in _ints(block.rows)],
              [names[s] for s in _ints(block.states)], _ints(block.timers)]
    values += _int_columns(block.outputs, len(machine.output_names), n)
    values += _int_columns(block.counters, len(machine.table.robot.counter_names), n)
    values += [_json_column(column) for column in block.extra.values()]
    return [template % row for row in zip(*values, strict=True)]


def exact_round(values: Any, digits: int) -> list[float]:
    """``[round(v, digits) for v in values]`` for a float array, vectorised (Python's ``round`` rounds the
    exact binary value half to even; numpy's ``round`` scales first, which can tip a near-half case the
    other way, so those few values are rounded by Python)."""
    array = np.asarray(values, dtype=np.float64)
    scaled = array * 10.0**digits
    rounded = np.rint(scaled) / 10.0**digits  # k / 10^d: IEEE division gives the double nearest k·10^-d
    fraction = np.abs(scaled - np.floor(scaled) - 0.5)
    doubtful = np.flatnonzero((fraction < 1e-6) | ~np.isfinite(scaled) | (np.abs(scaled) > 2.0**52))
    out = rounded.tolist()
    for i in doubtful.tolist():
        out[i] = round(float(array[i]), digits)
    return out


def _ints(column: Any) -> list[int]:
    return column.tolist() if hasattr(column, "tolist") else list(column)


def _int_columns(rows: Any, width: int, n: int) -> list[list[int]]:
    """Per column, the values of a (ticks, width) table given as an array or as a list of tuples."""
    if not width:
        return []
    if isinstance(rows, np.ndarray):
        return [rows[:, k].tolist() for k in range(width)]
    return [list(column) for column in zip(*rows, strict=True)] if n else [[] for _ in range(width)]


def _json_column(column: Any) -> list[str]:
    """JSON text of each value: finite floats as ``json`` writes them (their repr), others through ``json``."""
    values = _ints(column)
    if values and set(map(type, values)) == {float} and np.isfinite(np.asarray(values)).all():
        return repr(values)[1:-1].split(", ")  # one C call makes every float's repr, as json writes it
    return [json.dumps(v, ensure_ascii=False) for v in values]


class TraceFile:
    """A sink that writes the trace while the run goes: under a temporary name, renamed to ``path`` when
    the run is complete, or to ``NAME.partial.jsonl`` (ending with an ``end`` record saying why) when not.

    With ``background``, blocks are formatted and written by a thread of their own, while the next
    block is computed (the compiled simulator releases the GIL); ``end`` waits for it, and an error
    it met (a full disk) is raised there or at the next block.
    """

    def __init__(self, path: str | Path, background: bool = False):
        self.path = Path(path)
        self.background = background
        self.written: Path | None = None
        self._queue: queue.Queue[TickBlock | None] | None = None
        self._failed: BaseException | None = None

    def start(self, info: RunInfo) -> None:
        self.machine = info.engine.machine
        self.file = PendingFile(self.path)
        if self.background:
            self._queue = queue.Queue(maxsize=4)  # bounded: memory stays a few blocks whatever the disk does
            self._thread = threading.Thread(target=self._drain, name="trace writer", daemon=True)
            self._thread.start()

    def block(self, block: TickBlock) -> None:
        if self._queue is None:
            self._write(block)
            return
        if self._failed is not None:
            raise self._failed
        self._queue.put(block)

    def _write(self, block: TickBlock) -> None:
        self.file.stream.writelines(block_lines(block, self.machine))

    def _drain(self) -> None:
        assert self._queue is not None
        while (block := self._queue.get()) is not None:
            if self._failed is None:
                try:
                    self._write(block)
                except BaseException as exc:  # raised in the loop's thread, at the next block or at the end
                    if isinstance(exc, OSError) and exc.filename is None:
                        exc.filename = str(self.path)  # a full disk names no file of its own
                    self._failed = exc

    def end(self, end: RunEnd) -> None:
        if self._queue is not None:
            self._queue.put(None)
            self._thread.join()
            self._queue = None
            if self._failed is not None:
                self.file.discard()
                raise self._failed
        if end.complete and end.reason == "done":
            self.written = self.file.commit()
            return
        record = {"end": end.reason, "tick": end.ticks, "why": end.message}
        if end.late_ticks:
            record.update(late_ticks=end.late_ticks, worst_late_ms=round(1000 * end.worst_late_s, 1))
        self.file.stream.write(dumps(record) + "\n")
        self.written = self.file.commit() if end.complete else self.file.keep_partial()


def write_trace(lines: Iterable[dict[str, Any]], stream: IO[str]) -> int:
    count = 0
    for line in lines:
        stream.write(dumps(line) + "\n")
        count += 1
    return count


#: The largest trace file read back: a simulated hour at 10 ms ticks is about 60 MB of JSON Lines.
MAX_TRACE_BYTES = 512 * 1024 * 1024


def read_trace(path: str | Path) -> list[dict[str, Any]]:
    """Every tick line of a trace file (an ``end`` record, written when a run was cut short, is skipped);
    a line that is not a JSON object is a located error."""
    path = Path(path)
    text = read_text(path, "a trace is UTF-8 JSON Lines as tablebot writes it", MAX_TRACE_BYTES, spreadsheet=False)
    return parse_trace(text, path)


#: Located errors reported before a bad trace is given up on.
MAX_TRACE_ERRORS = 10


def parse_trace(text: str, path: str | Path, required: tuple[str, ...] = ()) -> list[dict[str, Any]]:
    """The tick lines of a trace's text, stopping at an ``end`` record; every line that is not a JSON
    object (or lacks a ``required`` key) is a located error, all of them (up to ten) reported at once."""
    out = Collector(path)
    lines = [line for _, line in trace_records(text, out, required)]
    out.raise_if_any()
    return lines


def trace_records(text: str, out: Collector, required: tuple[str, ...] = ()) -> Iterator[tuple[int, dict[str, Any]]]:
    """(line number, tick line) of a trace's text up to an ``end`` record; a bad line goes to ``out``.
    The one reader of trace lines: ``tablebot trace --inputs RUN.jsonl``, the studio's player and
    :func:`read_trace` all go through it."""
    hint = "a trace has one JSON object per line, as tablebot sim, trace, run or monitor write it"
    for number, raw in enumerate(text.splitlines(), start=1):
        if len(out.items) >= MAX_TRACE_ERRORS:
            return
        if not raw.strip():
            continue
        try:
            line = json.loads(raw)
        except (ValueError, RecursionError) as exc:  # RecursionError: nesting deeper than the parser's stack
            out.error(number, getattr(exc, "colno", 1),
                      f"line {number} is not JSON: {getattr(exc, 'msg', 'nested too deeply')}", hint)
            continue
        if not isinstance(line, dict):
            out.error(number, 1, f"line {number} is JSON but not an object {{...}}", hint)
        elif "end" in line:
            return
        elif missing := [key for key in required if key not in line]:
            out.error(number, 1, f"a trace line needs {' and '.join(missing)}", hint)
        else:
            yield number, line
