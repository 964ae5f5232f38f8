"""The trace of a live run, written as it happens: the core trace line of every tick plus the wall-clock
time, each counter's pulses and what else the robot reported. A run that did not finish normally ends
with ``{"end": REASON, "tick": N, "why": ...}``, N being the tick it ended in (the first one not traced).
A summary of the run goes beside it.

Files go through :class:`tablebot.files.PendingFile`: a complete run becomes ``trace.jsonl``, a planned
run cut short ``trace.partial.jsonl``; the previous complete run's files are never overwritten by a
partial one.
"""

from __future__ import annotations

import json
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

from tablebot.files import PendingFile, partial_name, write_text
from tablebot.loop import RunEnd, RunInfo, TickBlock
from tablebot.machine import NO_ROW, Machine
from tablebot.trace import dumps

#: Keys a run trace adds after the core ones (besides ``<counter>_pulses`` and the robot's own extras).
WALL_KEY = "wall"
END_KEY = "end"


def pulses_key(counter: str) -> str:
    return f"{counter}_pulses"


def tick_lines(machine: Machine, block: TickBlock, wall: float | None = None) -> list[dict[str, Any]]:
    """One trace line per tick of ``block``: the core keys exactly as :func:`tablebot.trace.record` writes
    them, then ``wall`` (Unix time, ms), ``<counter>_pulses``, then the block's extra columns."""
    names, counters = machine.output_names, machine.table.robot.counter_names
    lines = []
    for i in range(len(block)):
        row = int(block.rows[i])
        line: dict[str, Any] = {"tick": block.start + i, "event": int(block.events[i]),
                                "row": None if row == NO_ROW else row,
                                "state": machine.states[int(block.states[i])], "timer": int(block.timers[i])}
        line.update(zip(names, (int(v) for v in block.outputs[i]), strict=True))
        line.update(zip(counters, (int(v) for v in block.counters[i]), strict=True))
        if wall is not None:
            line[WALL_KEY] = round(wall, 3)
        line.update({pulses_key(c): int(p) for c, p in zip(counters, block.pulses[i], strict=True)})
        line.update({key: column[i] for key, column in block.extra.items()})
        lines.append(line)
    return lines


class TraceSink:
    """Writes ``trace.jsonl`` and ``summary.json`` into ``folder`` while the run goes."""

    def __init__(self, folder: Path, clock: Callable[[], float] = time.time):
        self.folder, self.clock = folder, clock
        self.file: PendingFile | None = None
        self.info: RunInfo | None = None
        self.written: list[Path] = []
        self.visits: dict[Any, int] = {}
        self.fired = 0
        self.count = 0  # tick lines written
        self.started = 0.0

    def start(self, info: RunInfo) -> None:
        self.info = info
        self.file = PendingFile(self.folder / "trace.jsonl")
        self.started = time.monotonic()

    def block(self, block: TickBlock) -> None:
        assert self.file is not None and self.info is not None
        machine = self.info.engine.machine
        lines = tick_lines(machine, block, self.clock())
        self.file.stream.write("".join(dumps(line) + "\n" for line in lines))
        self.file.stream.flush()  # a crash keeps every tick written so far (in the temporary file)
        self.count += len(lines)
        for line in lines:
            self.visits[line["state"]] = self.visits.get(line["state"], 0) + 1
            self.fired += line["row"] is not None

    def end(self, end: RunEnd) -> None:
        if self.file is None or self.info is None:
            return
        if end.reason != "done":
            # "tick": the tick the run ended in, the first one the trace does not have
            self.file.stream.write(dumps({END_KEY: end.reason, "tick": self.count, "why": end.message}) + "\n")
        trace = self.file.commit() if end.complete else self.file.keep_partial()
        summary = self.folder / "summary.json"
        summary = summary if end.complete else partial_name(summary)
        write_text(summary, json.dumps(self.summary(end, trace), indent=2, ensure_ascii=False) + "\n")
        self.written = [trace, summary]

    def summary(self, end: RunEnd, trace: Path) -> dict[str, Any]:
        """What the run did, as plain JSON."""
        assert self.info is not None
        tick_s = self.info.tick_s
        return {
            "target": self.info.target,
            "table": self.info.engine.machine.table.path,
            "ended": end.reason,
            "exit_code": end.exit_code,
            "why": end.message,
            "ticks": end.ticks,
            "seconds": round(end.ticks * tick_s, 3),
            "wall_seconds": round(time.monotonic() - self.started, 3),
            "late_ticks": end.late_ticks,
            "worst_late_ms": round(1000 * end.worst_late_s, 3),
            "rows_fired": self.fired,
            "seconds_per_state": {str(state): round(n * tick_s, 3) for state, n in self.visits.items()},
            "trace": trace.name,
        }
