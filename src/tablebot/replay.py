"""Recorded inputs through a fresh engine: the trace line of each tick (``tablebot trace --inputs``), the way
every checker and test replays a table."""

from __future__ import annotations

from collections.abc import Iterable, Iterator, Sequence
from typing import Any

from tablebot.engine import Engine
from tablebot.engine.several import Several
from tablebot.formats.inputs_csv import TickInput
from tablebot.machine import NO_ROW, Machine
from tablebot.tables import RobotTables


def record(engine: Engine) -> dict[str, Any]:
    """The trace line of the tick the engine just made."""
    m = engine.machine
    line: dict[str, Any] = {
        "tick": engine.tick - 1,
        "event": engine.event,
        "row": None if engine.row == NO_ROW else m.table.rows[engine.row].as_written,  # a group row: as written
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


def record_several(robot: Several) -> dict[str, Any]:
    """The trace line of a robot of several tables (:mod:`tablebot.tables`): a one-table line of the main table
    with the robot's outputs and counters, then ``NAME.event``, ``NAME.row``, ``NAME.state``, ``NAME.timer``
    of each other table."""
    main, *others = robot.engines
    line = record(main)
    line.update(zip(robot.tables.output_names, robot.outputs, strict=True))
    line.update(zip(robot.tables.robot.counter_names, robot.counters, strict=True))
    for name, engine in zip(robot.tables.names[1:], others, strict=True):
        row = engine.row
        line[f"{name}.event"] = engine.event
        line[f"{name}.row"] = None if row == NO_ROW else engine.machine.table.rows[row].as_written
        line[f"{name}.state"] = engine.machine.states[engine.state]
        line[f"{name}.timer"] = engine.timer
    return line


def replay_several(
    tables: RobotTables, ticks: Iterable[TickInput], order: Sequence[int] | None = None
) -> Iterator[dict[str, Any]]:
    """:func:`replay` for a robot of several tables, its inputs in the robot-wide layout (``order``: the order
    the tables are stepped in, which changes nothing)."""
    robot = Several(tables, order)
    for tick in ticks:
        robot.step(tick.mask, tick.pulses)
        yield record_several(robot)
