"""The trace of a live run, written as it happens: :class:`tablebot.trace.TraceFile` (the core trace line
of every tick; ``trace.jsonl`` when complete, ``trace.partial.jsonl`` ending with an ``end`` record when
cut short) plus each tick's wall-clock time and each counter's pulses, flushed tick by tick, and a
summary of the run beside it.
"""

from __future__ import annotations

import dataclasses
import json
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

from tablebot.files import partial_name, write_text
from tablebot.loop import RunEnd, RunInfo, TickBlock
from tablebot.machine import NO_ROW
from tablebot.trace import TraceFile

WALL_KEY = "wall"  # Unix time (s, ms resolution) when the tick's line was written


def pulses_key(counter: str) -> str:
    return f"{counter}_pulses"


class RunTrace(TraceFile):
    """Writes ``trace.jsonl`` and ``summary.json`` into ``folder`` while the run goes."""

    def __init__(self, folder: Path, clock: Callable[[], float] = time.time):
        super().__init__(folder / "trace.jsonl")
        self.folder, self.clock = folder, clock
        self.info: RunInfo | None = None
        self.visits: dict[int, int] = {}  # state index -> ticks
        self.fired = 0
        self.started = 0.0

    def start(self, info: RunInfo) -> None:
        super().start(info)
        self.info = info
        self.started = time.monotonic()

    def block(self, block: TickBlock) -> None:
        n = len(block)
        counters = self.machine.table.robot.counter_names
        extra: dict[str, Any] = {WALL_KEY: [round(self.clock(), 3)] * n}
        extra.update({pulses_key(c): [int(p[i]) for p in block.pulses] for i, c in enumerate(counters)})
        extra.update(block.extra)
        super().block(dataclasses.replace(block, extra=extra))
        self.file.stream.flush()  # a crash keeps every tick so far (in the temporary file)
        for state, row in zip(block.states, block.rows, strict=True):
            self.visits[int(state)] = self.visits.get(int(state), 0) + 1
            self.fired += int(row) != NO_ROW

    def end(self, end: RunEnd) -> None:
        if self.info is None:
            return
        super().end(end)
        assert self.written is not None
        summary = self.folder / "summary.json"
        summary = summary if self.written.name == self.path.name else partial_name(summary)
        write_text(summary, json.dumps(self.summary(end), indent=2, ensure_ascii=False) + "\n")
        self.summary_written = summary

    @property
    def files(self) -> list[Path]:
        return [p for p in (self.written, getattr(self, "summary_written", None)) if p is not None]

    def summary(self, end: RunEnd) -> dict[str, Any]:
        """What the run did, as plain JSON."""
        assert self.info is not None and self.written is not None
        tick_s, states = self.info.tick_s, self.machine.states
        return {
            "target": self.info.target,
            "table": self.machine.table.path,
            "ended": end.reason,
            "exit_code": end.exit_code,
            "why": end.message,
            "ticks": end.ticks,
            "seconds": round(end.ticks * tick_s, 3),
            "wall_seconds": round(time.monotonic() - self.started, 3),
            "late_ticks": end.late_ticks,
            "worst_late_ms": round(1000 * end.worst_late_s, 3),
            "rows_fired": self.fired,
            "seconds_per_state": {str(states[s]): round(n * tick_s, 3) for s, n in self.visits.items()},
            "trace": self.written.name,
        }
