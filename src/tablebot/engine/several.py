"""A robot of several tables, tick by tick: one :class:`~tablebot.engine.Engine` per table, run under the rules of
:mod:`tablebot.tables` (inputs read once; each table its own timer and events; cross-table events from the states
at the start of the tick; each output from its one writer; the counters the robot's)."""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence

import numpy as np

from tablebot.engine import Engine
from tablebot.tables import RobotTables

__all__ = ["LIST_BITS", "Several", "cross_bits", "input_bits"]

#: Robot input masks of at most this many bits get a precomputed list per table (robot mask -> table bits).
LIST_BITS = 12


class Several:
    """The robot's tables running together: ``step(inputs) -> outputs`` as :meth:`Engine.step` for one table.

    ``inputs`` are in the robot-wide layout of :attr:`RobotTables.input_bits` (or a mapping of input names);
    ``pulses`` one count per robot counter. ``engines`` holds each table's engine (the main one first), from
    which a trace reads each table's event, row, state and timer; ``outputs`` and ``counters`` are the robot's.
    The order the tables are stepped in changes nothing (each reads the start of the tick, writes its own).
    """

    def __init__(self, tables: RobotTables, order: Sequence[int] | None = None) -> None:
        self.tables = tables
        self.engines = tuple(Engine(machine) for machine in tables.machines)
        #: The order the tables are stepped in (any order gives the same ticks: a test permutes it).
        self.order = tuple(range(len(self.engines)) if order is None else order)
        self.input_maps = [_input_map(tables, i) for i in range(len(self.engines))]
        self.cross_maps = [cross_bits(tables, i) for i in range(len(self.engines))]
        robot = tables.robot
        self._writers = [tables.writer(name) for name in tables.output_names]
        self._counter_writers = [
            (c, w) for c, name in enumerate(robot.counter_names) if (w := tables.writer(name)) is not None
        ]
        self.outputs: tuple[int, ...] = (0,) * len(tables.output_names)

    @property
    def tick(self) -> int:
        return self.engines[0].tick

    @property
    def counters(self) -> list[int]:
        return self.engines[0].counters

    def step(
        self, inputs: int | np.integer | Mapping[str, int] = 0, pulses: Sequence[int] | np.ndarray | None = None
    ) -> tuple[int, ...]:
        """One tick of every table (see :mod:`tablebot.tables`); a refused input changes nothing."""
        mask = self.events_of(inputs)
        states = [engine.state for engine in self.engines]  # the start of the tick, before any table fires
        engines = self.engines
        for i in self.order:
            table_mask = self.input_maps[i](mask)
            for source, bits in self.cross_maps[i]:
                table_mask |= bits[states[source]]
            engines[i].step(table_mask, pulses)
        self.outputs = tuple(0 if w is None else engines[w].outputs[k] for k, w in enumerate(self._writers))
        for c, w in self._counter_writers:  # a load is its writer's: every table then sees the same count
            value = engines[w].counters[c]
            for engine in engines:
                if engine.counters[c] != value:
                    engine.counters = [*engine.counters[:c], value, *engine.counters[c + 1 :]]
        return self.outputs

    def events_of(self, inputs: int | np.integer | Mapping[str, int]) -> int:
        """A robot-wide input mask from a mask or ``{name: 0/1}``; ValueError for anything else."""
        bits = self.tables.input_bits
        if isinstance(inputs, Mapping):
            mask = 0
            for name, value in inputs.items():
                if name not in bits:
                    raise ValueError(f"unknown input {name!r}; the robot's tables read {', '.join(bits) or 'none'}")
                if value not in (0, 1) or not isinstance(value, int | np.integer):  # as Engine.events_of
                    raise ValueError(f"input {name!r}: {value!r} is not 0 or 1")
                mask |= bits[name] if value else 0
            return mask
        if isinstance(inputs, bool) or not isinstance(inputs, int | np.integer) or not 0 <= inputs < 1 << len(bits):
            raise ValueError(
                f"input mask {inputs!r} is not a mask of the robot's {len(bits)} inputs "
                f"({', '.join(f'{n}={b}' for n, b in bits.items()) or 'none'})"
            )
        return int(inputs)


def input_bits(tables: RobotTables, index: int) -> list[tuple[str, int, int]]:
    """(name, robot bit, table bit) of every robot input table ``index`` reads, in the robot's order: where its
    inputs are, as this engine, the generated C and the TXT 4.0's program read them."""
    own = tables.machines[index].input_bits
    return [(name, bit, own[name]) for name, bit in tables.input_bits.items() if name in own]


def cross_bits(tables: RobotTables, index: int) -> list[tuple[int, list[int]]]:
    """Per table that table ``index`` reads the state of, in index order: (its index, its state index -> this
    table's cross-table event bits); the one reading of cross-table events every executor shares."""
    table = tables.tables[index]
    by_source: dict[int, list[int]] = {}
    for name, event in table.cross.items():
        source, states = tables.covers(event)
        bits = by_source.setdefault(source, [0] * len(tables.machines[source].states))
        for state in states:
            bits[state] |= table.bit(name)
    return sorted(by_source.items())


def _input_map(tables: RobotTables, index: int) -> Callable[[int], int]:
    """Robot mask -> the table's input bits: a list when the robot has few inputs, else a loop."""
    pairs = [(bit, own) for _, bit, own in input_bits(tables, index)]
    width = len(tables.input_bits)
    if width <= LIST_BITS:
        return [sum(table_bit for bit, table_bit in pairs if mask & bit) for mask in range(1 << width)].__getitem__
    return lambda mask: sum(table_bit for bit, table_bit in pairs if mask & bit)
