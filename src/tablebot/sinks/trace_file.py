"""The trace written while a run goes (a sink of :mod:`tablebot.loop`): the lines of each block of ticks, made
column-wise, in the format of :mod:`tablebot.formats.trace_lines`."""

from __future__ import annotations

import dataclasses
import json
import queue
import threading
from concurrent.futures import Executor, ThreadPoolExecutor
from pathlib import Path
from typing import Any, TextIO, TypeGuard

import numpy as np

from tablebot.files import PendingFile
from tablebot.formats.trace_lines import dumps
from tablebot.loop import RunEnd, RunInfo, TickBlock
from tablebot.machine import Machine

#: Ticks from which a simulator's block is written by compiled code (sinks.trace_text), not by Python.
COMPILED_FROM = 256
#: A run of this many ticks (or one with no planned end) has its trace written by compiled code even when that
#: code is not compiled yet: Python takes 1.4 s for an hour at 10 ms, the compiled code 0.4 s, and compiling it
#: 4-7 s once (then it is in numba's cache). A shorter first run (make demo's two minutes: 0.04 s in Python)
#: is written by Python rather than wait for the compile; the bytes are the same either way.
COMPILE_FOR_TICKS = 100_000


def block_text(block: TickBlock, machine: Machine) -> str:
    """The trace lines of a block of ticks, as one text: :func:`block_lines` joined. A long block of the
    simulator's (numpy columns, its extra fields offering ``number_columns``) is written by compiled code."""
    text = block_bytes_of(block, machine)
    return text.decode("utf-8") if isinstance(text, bytes) else text


def block_bytes_of(block: TickBlock, machine: Machine) -> bytes | str:
    """:func:`block_text` as the compiled code made it (UTF-8 bytes: an hour's 59 MB need no decoding when
    they go straight to a file), or as text when Python made it."""
    views = block_views_of(block, machine, {})
    return b"".join(views) if isinstance(views, list) else views


def block_views_of(
    block: TickBlock,
    machine: Machine,
    scratch: dict[str, np.ndarray],
    helper: Executor | None = None,
    compiled: bool = True,
) -> list[memoryview] | str:
    """:func:`block_bytes_of` as the views of ``scratch``'s memory the compiled code made (see
    trace_text.block_views), or as text when Python made it (always, when not ``compiled``)."""
    block = _rows_as_written(block, machine)
    if compiled and compiled_block(block):
        views = _compiled_text(block, machine, scratch, helper)
        if views is not None:
            return views
    return "".join(_python_lines(block, machine))


def _rows_as_written(block: TickBlock, machine: Machine) -> TickBlock:
    """A trace names a row as its file writes it (:attr:`tablebot.table.Row.as_written`, as
    :func:`tablebot.replay.record` does): a row written for a state group (``[groups]``) is run as one row per
    state, numbered apart. A table without groups is left as it is."""
    written = [row.as_written for row in machine.table.rows]
    if written == list(range(len(written))):
        return block
    rows = [-1 if r < 0 else written[r] for r in _ints(block.rows)]
    return dataclasses.replace(
        block, rows=np.array(rows, dtype=np.int64) if isinstance(block.rows, np.ndarray) else rows
    )


def compiled_block(block: TickBlock) -> bool:
    """Whether compiled code can write ``block``: a long block of the simulator's."""
    return len(block) >= COMPILED_FROM and hasattr(block.extra, "number_columns")


def block_lines(block: TickBlock, machine: Machine) -> list[str]:
    """The trace lines of a block of ticks, newline included: the bytes :func:`dumps` gives for
    :func:`record` plus the block's extra fields, made column-wise (a simulated hour in well under a second)."""
    text = block_text(block, machine)
    return [line + "\n" for line in text.split("\n")[:-1]]  # no JSON text holds a raw newline


def _compiled_text(
    block: TickBlock, machine: Machine, scratch: dict[str, np.ndarray], helper: Executor | None
) -> list[memoryview] | None:
    from tablebot.sinks.trace_text import DECIMAL, INT, ROW, STATE, block_views, json_names

    n_out, n_count = len(machine.output_names), len(machine.table.robot.counter_names)
    arrays = (block.events, block.rows, block.states, block.timers, block.outputs, block.counters)
    if not _all_arrays(arrays):
        return None
    events, rows, states, timers, outputs, counters = arrays
    extra = block.extra.number_columns()  # type: ignore[attr-defined]
    keys = ["tick", "event", "row", "state", "timer", *machine.output_names, *machine.table.robot.counter_names]
    pieces = [("{" if k == 0 else ",") + json.dumps(key, ensure_ascii=False) + ":" for k, key in enumerate(keys)]
    pieces += ["," + json.dumps(key, ensure_ascii=False) + ":" for key, _, _ in extra]
    kinds = [INT, INT, ROW, STATE, INT] + [INT] * (n_out + n_count)
    n = len(block)
    columns = [np.arange(block.start, block.start + n), events, rows, states, timers]
    columns += [outputs[:, k] for k in range(n_out)] + [counters[:, k] for k in range(n_count)]
    decimals = [0] * len(kinds)
    for _, values, places in extra:
        kinds.append(INT if places == 0 else DECIMAL)
        columns.append(values)
        decimals.append(places)
    return block_views(
        [p.encode() for p in [*pieces, "}\n"]], kinds, columns, decimals, json_names(machine.states), scratch, helper
    )


def _all_arrays(columns: tuple[object, ...]) -> TypeGuard[tuple[np.ndarray, ...]]:
    return all(isinstance(a, np.ndarray) for a in columns)


def _python_lines(block: TickBlock, machine: Machine) -> list[str]:
    names = [json.dumps(state, ensure_ascii=False) for state in machine.states]
    columns = [*machine.output_names, *machine.table.robot.counter_names]
    template = (
        '{"tick":%d,"event":%d,"row":%s,"state":%s,"timer":%d'
        + "".join(f",{json.dumps(name)}:%d" for name in columns)
        + "".join(f",{json.dumps(key, ensure_ascii=False)}:%s" for key in block.extra)
        + "}\n"
    )
    n = len(block)
    values = [
        range(block.start, block.start + n),
        _ints(block.events),
        ["null" if r < 0 else str(r) for r in _ints(block.rows)],
        [names[s] for s in _ints(block.states)],
        _ints(block.timers),
    ]
    values += _int_columns(block.outputs, len(machine.output_names), n)
    values += _int_columns(block.counters, len(machine.table.robot.counter_names), n)
    values += [_json_column(column) for column in block.extra.values()]
    return [template % row for row in zip(*values, strict=True)]


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


def _utf8_as_written(stream: Any) -> TypeGuard[TextIO]:
    """Whether bytes may go to the stream's binary buffer: a UTF-8 text file (PendingFile writes newlines
    as they are)."""
    return hasattr(stream, "buffer") and str(getattr(stream, "encoding", "")).lower().replace("-", "") == "utf8"


class TraceFile:
    """A sink that writes the trace while the run goes: under a temporary name, renamed to ``path`` when
    the run is complete, or to ``NAME.partial.jsonl`` (ending with an ``end`` record saying why) when not.

    With ``background``, blocks are formatted and written by a thread of their own, while the next
    block is computed (the compiled simulator releases the GIL), with a second thread writing half of each
    long block's lines meanwhile (the writing takes longer than the simulating); ``end`` waits for them,
    and an error met (a full disk) is raised there or at the next block.
    """

    def __init__(self, path: str | Path, background: bool = False) -> None:
        self.path = Path(path)
        self.background = background
        self.written: Path | None = None
        self._queue: queue.Queue[TickBlock | None] | None = None
        self._failed: BaseException | None = None
        self._scratch: dict[str, np.ndarray] = {}  # the formatting's arrays, reused block after block
        self._helper: ThreadPoolExecutor | None = None
        self._ticks: int | None = None
        self._compiled: bool | None = None  # compiled code writes this run's long blocks (decided at the first)

    def start(self, info: RunInfo) -> None:
        self.machine = info.engine.machine
        self._ticks = info.ticks
        self.file = PendingFile(self.path)
        if self.background:
            self._queue = queue.Queue(maxsize=4)  # bounded: memory stays a few blocks whatever the disk does
            self._helper = ThreadPoolExecutor(1, thread_name_prefix="trace lines")
            self._thread = threading.Thread(target=self._drain, name="trace writer", daemon=True)
            self._thread.start()

    def block(self, block: TickBlock) -> None:
        if self._queue is None:
            self._write(block)
            return
        if self._failed is not None:
            raise self._failed
        self._queue.put(block)

    def _use_compiled(self) -> bool:
        """Whether compiled code writes this run's long blocks: when numba has it in its cache, or when the
        run is long enough to be worth compiling it for (:data:`COMPILE_FOR_TICKS`)."""
        if self._compiled is None:
            from tablebot import jit
            from tablebot.sinks.trace_text import _lines

            long = self._ticks is None or self._ticks >= COMPILE_FOR_TICKS
            self._compiled = long or jit.compiled(_lines)
        return self._compiled

    def _write(self, block: TickBlock) -> None:
        compiled = compiled_block(block) and self._use_compiled()  # a controller's blocks never import numba
        text = block_views_of(block, self.machine, self._scratch, self._helper, compiled)
        stream = self.file.stream
        if isinstance(text, str):
            stream.write(text)
        elif _utf8_as_written(stream):  # past the text layer (flushed) as it is
            stream.flush()  # first so that the order of the lines holds
            for view in text:
                stream.buffer.write(view)
        else:
            stream.write(b"".join(text).decode("utf-8"))

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
            if self._helper is not None:
                self._helper.shutdown()
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
