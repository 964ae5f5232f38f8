"""A robot of several tables as the one engine a controller and the run loop know (issue 36 §2): the controllers
read the robot's inputs in one layout and write its outputs in one order, whatever tables decide them, so they
are wired for :func:`robot_machine` (the main table's machine with the robot-wide input layout of
:attr:`RobotTables.input_bits`) and driven by a :class:`RobotEngine`, which steps every table
(:class:`~tablebot.engine.several.Several`) and shows the main table's ``event``, ``row``, ``state`` and
``timer`` where the loop reads one engine's; :meth:`RobotEngine.fields` gives the other tables' as a trace names
them (``NAME.event``, ``NAME.row``, ``NAME.state``, ``NAME.timer``)."""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from tablebot.engine.several import Several
from tablebot.machine import NO_ROW, Machine
from tablebot.tables import RobotTables

__all__ = ["RobotEngine", "robot_machine"]


def robot_machine(tables: RobotTables) -> Machine:
    """What a controller is wired for: the robot's inputs (every input any table reads, in the robot-wide
    layout), its outputs and counters. Its rows are the main table's: nothing steps it as a table."""
    inputs = tables.input_bits
    main = tables.machines[0]
    return dataclasses.replace(main, input_bits=dict(inputs))


class RobotEngine:
    """Every table of a robot stepped as one engine (``step(mask, pulses) -> outputs``, the mask in the robot
    layout); ``machine`` is :func:`robot_machine`'s, ``event``/``row``/``state``/``timer`` the main table's."""

    def __init__(self, tables: RobotTables) -> None:
        self.tables = tables
        self.several = Several(tables)
        self.machine = robot_machine(tables)

    def step(
        self, inputs: int | np.integer | Mapping[str, int] = 0, pulses: Sequence[int] | np.ndarray | None = None
    ) -> tuple[int, ...]:
        return self.several.step(inputs, pulses)

    @property
    def tick(self) -> int:
        return self.several.tick

    @property
    def outputs(self) -> tuple[int, ...]:
        return self.several.outputs

    @property
    def counters(self) -> list[int]:
        return self.several.counters

    @property
    def event(self) -> int:
        return self.several.engines[0].event

    @property
    def row(self) -> int:
        return self.several.engines[0].row

    @property
    def state(self) -> int:
        return self.several.engines[0].state

    @property
    def timer(self) -> int:
        return self.several.engines[0].timer

    def fields(self) -> dict[str, Any]:
        """The other tables' decisions in the last tick, keyed as a trace keys them (rows as written)."""
        found: dict[str, Any] = {}
        for name, engine in zip(self.tables.names[1:], self.several.engines[1:], strict=True):
            rows = engine.machine.table.rows
            found[f"{name}.event"] = engine.event
            found[f"{name}.row"] = None if engine.row == NO_ROW else rows[engine.row].as_written
            found[f"{name}.state"] = engine.machine.states[engine.state]
            found[f"{name}.timer"] = engine.timer
        return found
