"""The trace of a live run, written as it happens: :class:`tablebot.sinks.trace_file.TraceFile` (the core trace line
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

import numpy as np

from tablebot.files import partial_name, write_text
from tablebot.fileset import file_set
from tablebot.formats.inputs_csv import pulses_key
from tablebot.loop import RunEnd, RunInfo, TickBlock
from tablebot.machine import NO_ROW
from tablebot.robot import StateId
from tablebot.sinks.trace_file import TraceFile

WALL_KEY = "wall"  # Unix time (s, ms resolution) when the tick's line was written


class RunTrace(TraceFile):
    """Writes ``trace.jsonl`` and ``summary.json`` into ``folder`` while the run goes."""

    def __init__(self, folder: Path, clock: Callable[[], float] = time.time) -> None:
        super().__init__(folder / "trace.jsonl")
        self.folder, self.clock = folder, clock
        self.info: RunInfo | None = None
        self.counts: list[int] = []  # per state index: ticks after which the robot was in it
        self.first_seen: list[int] = []  # per state index: the first such tick (-1: never)
        self.fired = 0
        self.started = 0.0
        self.summary_written: Path | None = None

    def start(self, info: RunInfo) -> None:
        super().start(info)
        self.info = info
        self.counts = [0] * len(self.machine.states)
        self.first_seen = [-1] * len(self.machine.states)
        self.started = time.monotonic()

    def block(self, block: TickBlock) -> None:
        n = len(block)
        counters = self.machine.table.robot.counter_names
        extra: dict[str, Any] = {WALL_KEY: [round(self.clock(), 3)] * n}
        extra.update({pulses_key(c): [int(p[i]) for p in block.pulses] for i, c in enumerate(counters)})
        extra.update(block.extra)
        super().block(dataclasses.replace(block, extra=extra))
        self.file.stream.flush()  # a crash keeps every tick so far (in the temporary file)
        for tick, (state, row) in enumerate(zip(block.states, block.rows, strict=True), start=block.start):
            self.counts[state] += 1
            if self.first_seen[state] < 0:
                self.first_seen[state] = tick
            self.fired += int(row) != NO_ROW

    def end(self, end: RunEnd) -> None:
        """The trace and its summary replace the previous run's together (the trace was written beside
        them as the run went, so a crash still leaves its ticks in the temporary file)."""
        if self.info is None:
            return
        with file_set(self.folder):
            super().end(end)
            assert self.written is not None
            summary = self.folder / "summary.json"
            summary = summary if self.written.name == self.path.name else partial_name(summary)
            write_text(summary, json.dumps(self.summary(end), indent=2, ensure_ascii=False) + "\n")
        self.summary_written = summary

    @property
    def files(self) -> list[Path]:
        return [p for p in (self.written, self.summary_written) if p is not None]

    def summary(self, end: RunEnd) -> dict[str, Any]:
        """What the run did, as plain JSON."""
        assert self.info is not None and self.written is not None
        tick_s = self.info.tick_s
        per_state = seconds_per_state(np.array(self.counts), np.array(self.first_seen), self.machine.states, tick_s)
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
            "seconds_per_state": {str(state): round(seconds, 3) for state, seconds in per_state.items()},
            "trace": self.written.name,
        }


def seconds_per_state(
    counts: np.ndarray, first_seen: np.ndarray, names: tuple[StateId, ...], tick_s: float
) -> dict[StateId, float]:
    """Seconds per state from its tick count and the tick it was first seen (-1: never), in order of
    first visit (a fleet keeps only these two per robot)."""
    visited = np.flatnonzero(first_seen >= 0)
    order = visited[np.argsort(first_seen[visited], kind="stable")]
    return {names[index]: float(counts[index] * tick_s) for index in order.tolist()}
