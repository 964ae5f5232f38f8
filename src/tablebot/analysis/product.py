"""The state space of a robot of several tables (:mod:`tablebot.tables`): the product of its tables, tick by tick,
with each table's timer abstracted as :mod:`tablebot.analysis.model` abstracts one table's.

A node is (each table's state, each table's timer class, which counters are at 0, the robot's outputs, first
tick?). A tick enumerates the robot's input image (every input any table reads), and for every table whose timer
is above the horizon and fires nothing, both "still above" and "now at the horizon" (as the one-table model
does). Each table's events are made as the engine makes them (its inputs, its own ``T``, the counters, its
cross-table events from the states at the start of the tick), so the product is exact for everything that does
not count ticks, and sound for what does: the proofs of :mod:`tablebot.analysis.prove` run on it unchanged.

What conditions see of a tick (``Obs``): an event word of the robot's inputs (their bits as in
:attr:`RobotTables.input_bits`), then the main table's ``T``, then one bit per counter at 0; the main table's fired
row; the tuple of every table's state (index into its machine's ``states``); the robot's outputs.
"""

from __future__ import annotations

import itertools
from collections.abc import Iterator, Sequence
from dataclasses import dataclass, field

from tablebot.analysis.model import MAX_ENUMERATED_BITS, ZERO_PULSES, Graph, ModelTooLarge, memoised, reachable, subsets
from tablebot.engine.several import Several
from tablebot.formats.inputs_csv import TickInput
from tablebot.i18n import N_
from tablebot.machine import NO_ROW
from tablebot.tables import RobotTables

#: (each table's state, each table's timer class, counters at 0, outputs, first tick?)
PNode = tuple[tuple[int, ...], tuple[int, ...], int, tuple[int, ...], bool]
#: (event word, counters driven to 0 this tick, the main table's row or -1, node after)
PTick = tuple[int, int, int, PNode]


@dataclass
class ProductModel:
    """The robot's tables together under the timer horizon ``horizon``; ``watch`` = event-word bits (robot
    inputs) that properties read. ``relevant``: the tables to run (None: all); the others stay in their initial
    state and fire nothing, which is exact for a property that reads only tables they cannot influence
    (:meth:`RobotTables.influence`): each output has one writer, so they change nothing the property sees."""

    tables: RobotTables
    horizon: int = 1
    watch: int = 0
    relevant: frozenset[int] | None = None
    _succ: dict[PNode, list[PTick]] = field(default_factory=dict, repr=False)

    def __post_init__(self) -> None:
        tables = self.tables
        self.horizon = max(1, self.horizon)
        self.omega = self.horizon + 1
        self.width = len(tables.input_bits)
        if self.width > MAX_ENUMERATED_BITS:
            raise ModelTooLarge(N_("the robot's tables read {count} inputs", count=self.width))
        self.timer_word = 1 << self.width  # the main table's T in the event word
        robot = tables.robot
        self.counter_word = tuple(1 << (self.width + 1 + c) for c in range(len(robot.counters)))
        self.tracked = sum(
            1 << c for c, name in enumerate(robot.counter_names) if any(m.counter_bits[c] for m in tables.machines)
        )
        self.engine = Several(tables)  # its input and cross-table maps, made once
        self.active = tuple(k for k in range(len(tables.machines)) if self.relevant is None or k in self.relevant)
        self.writers = [tables.writer(name) for name in tables.output_names]

    @classmethod
    def exact(cls, tables: RobotTables, watch: int = 0, relevant: frozenset[int] | None = None) -> ProductModel:
        """The model in which no timer value of any (relevant) table is abstracted."""
        return cls(tables, _longest(tables, relevant), watch, relevant)

    @property
    def is_exact(self) -> bool:
        return self.horizon >= _longest(self.tables, self.relevant)

    def timer_class(self, value: int) -> int:
        return value if value <= self.horizon else self.omega

    def initial(self) -> PNode:
        machines = self.tables.machines
        timers = tuple(self.timer_class(m.initial_timer) if k in self.active else 0 for k, m in enumerate(machines))
        return (
            tuple(m.initial_state for m in machines),
            timers,
            self.tracked,
            (0,) * len(self.tables.output_names),
            True,
        )

    def successors(self, node: PNode) -> list[PTick]:
        return memoised(self._succ, node, self._expand)

    def _expand(self, node: PNode) -> Iterator[PTick]:
        states, timers, zero, outputs, first = node
        afters = [timers] if first else [tuple(t if t == self.omega else max(0, t - 1) for t in timers)]
        # (a table left out keeps timer 0 and fires nothing: see _rows)
        zeroings = [0] if first else list(subsets(self.tracked & ~zero))
        seen: set[tuple[int, ...]] = set()
        for after, zeroed in itertools.product(afters, zeroings):
            now_zero = zero | zeroed
            for mask in range(1 << self.width):
                rows = self._rows(states, after, now_zero, mask)
                key = (*rows, mask & self.watch, zeroed)
                if key in seen:
                    continue
                seen.add(key)
                word = (
                    mask
                    | (self.timer_word if after[0] == 0 else 0)
                    | sum(bit for c, bit in enumerate(self.counter_word) if now_zero >> c & 1)
                )
                for nxt in self._fire(rows, states, after, now_zero, outputs, first):
                    yield word, zeroed, rows[0], nxt

    def _rows(self, states: tuple[int, ...], timers: tuple[int, ...], zero: int, mask: int) -> tuple[int, ...]:
        """The row each table fires (or -1) on this input image."""
        engine, machines = self.engine, self.tables.machines
        rows = []
        for k, machine in enumerate(machines):
            if k not in self.active:
                rows.append(NO_ROW)
                continue
            events = engine.input_maps[k](mask)
            for source, bits in engine.cross_maps[k]:
                events |= bits[states[source]]
            if timers[k] == 0:
                events |= machine.timer_bit
            events |= sum(bit for c, bit in enumerate(machine.counter_bits) if zero >> c & 1)
            rows.append(machine.lookup(states[k], events))
        return tuple(rows)

    def _fire(
        self,
        rows: tuple[int, ...],
        states: tuple[int, ...],
        timers: tuple[int, ...],
        zero: int,
        outputs: tuple[int, ...],
        first: bool,
    ) -> Iterator[PNode]:
        """The nodes after the tables fire ``rows``: a table above the horizon that fires nothing may also have
        just come down to it."""
        machines = self.tables.machines
        new_states, new_timers, new_out = list(states), list(timers), list(outputs)
        for k, index in enumerate(rows):
            if index == NO_ROW:
                continue
            row = machines[k].rows[index]
            new_states[k], new_timers[k] = row.next, self.timer_class(row.timer)
            for out, value in enumerate(row.outputs):
                if value is not None and self.writers[out] == k:
                    new_out[out] = value
            for c, load in enumerate(row.loads):
                if load is not None and self.tracked >> c & 1:
                    zero = zero | (1 << c) if load == 0 else zero & ~(1 << c)
        waiting = [k for k in self.active if rows[k] == NO_ROW and timers[k] == self.omega and not first]
        for dropped in subsets(sum(1 << k for k in waiting)):
            after = tuple(self.horizon if dropped >> k & 1 else t for k, t in enumerate(new_timers))
            yield tuple(new_states), after, zero, tuple(new_out), False

    def explore(self, budget: int = 2_000_000) -> Graph:
        """Every node reachable from the initial node (a :class:`Graph`, as the one-table model's)."""
        order = reachable(self.initial(), self.successors, budget)
        return Graph(self, order)  # type: ignore[arg-type]  # the same interface: initial, successors

    def drops(self, before: PNode, tick: PTick) -> bool:
        """Whether some table's timer came down from above the horizon on this tick (a wait shortened)."""
        return any(b == self.omega and a == self.horizon for b, a in zip(before[1], tick[3][1], strict=True))

    def concretize(self, path: Sequence[tuple[PNode, PTick]]) -> tuple[list[TickInput], bool]:
        """Inputs that drive the robot's engine along ``path`` (robot-wide layout); whether it fired the path's
        main rows exactly. In an abstract model a shortened wait is not padded: such a path may not replay."""
        engine = Several(self.tables)
        ticks, faithful = [], True
        n = len(self.tables.robot.counters)
        for before, tick in path:
            word, zeroed, row, _ = tick
            faithful &= not self.drops(before, tick)
            pulses = tuple(ZERO_PULSES if zeroed >> c & 1 else 0 for c in range(n))
            mask = word & ((1 << self.width) - 1)
            engine.step(mask, pulses)
            ticks.append(TickInput(mask, pulses))
            faithful &= engine.engines[0].row == row
        return ticks, faithful


def _longest(tables: RobotTables, relevant: frozenset[int] | None) -> int:
    """The longest timer value the (relevant) tables load or start with: the horizon of the exact model."""
    machines = [m for k, m in enumerate(tables.machines) if relevant is None or k in relevant]
    return max([1, *(r.timer for m in machines for r in m.rows), *(m.initial_timer for m in machines)])
