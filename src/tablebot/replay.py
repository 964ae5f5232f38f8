"""Recorded inputs through a fresh engine: the trace line of each tick (``tablebot trace --inputs``), the way
every checker and test replays a table."""

from __future__ import annotations

from collections.abc import Iterable, Iterator
from typing import Any

from tablebot.engine import Engine
from tablebot.formats.inputs_csv import TickInput
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
