"""The table's state space, tick by tick, with a sound abstraction of timer and counter values.

A node is what decides the future: (state, timer class, which counters are at 0, outputs, first
tick?). Inputs and encoder pulses are free each tick, so a node's successors are one per distinct
outcome over all input combinations (and all choices of which running counters reach 0).

Timer abstraction, with a horizon ``H`` (at least 1): a timer value ``v <= H`` is kept exactly;
every value above ``H`` is one class, OMEGA ("more than H ticks left"). A tick turns an exact
``v`` into ``v - 1`` and OMEGA into OMEGA *or* ``H`` (we no longer know which). This is sound: every
real run is a run of the model (values above ``H`` only ever count down by one per tick, and ``T``
needs 0, which OMEGA never is), so a property that holds in the model holds on the robot. It is
exact for everything that does not count ticks (which rows can fire, which states can be reached,
``never``/``always`` properties): all timer values above 1 allow the same rows, so ``H = 1`` already
gives the real answers, only with waits shortened. A property that counts up to ``N`` ticks needs
``H >= N + 1``; with ``H`` = the largest timer value in the table nothing is abstracted at all (the
*exact* model), which is what counterexamples are taken from so that they replay tick for tick.

Counter abstraction: only "is 0" or "is running" is kept. Pulses are an input like any other (the
engine subtracts whatever the encoder reports), so in any tick a running counter may reach 0 or
not: that choice is made explicitly, which makes this part exact, not just sound.
"""

from __future__ import annotations

from collections import deque
from collections.abc import Callable, Iterable, Iterator, Sequence
from dataclasses import dataclass
from typing import Any, TypeVar

from tablebot.engine import Engine
from tablebot.formats.inputs_csv import TickInput
from tablebot.i18n import N_
from tablebot.machine import NO_ROW, Machine

Node = tuple[int, int, int, tuple[int, ...], bool]
#: One tick: (event mask, counters driven to 0 by pulses this tick, fired row or -1, node after)
Tick = tuple[int, int, int, Node]
#: Pulses written for a counter that must reach 0 this tick: more than any load can hold.
ZERO_PULSES = 65535
K = TypeVar("K")
V = TypeVar("V")
#: Input bits a state is enumerated over; beyond this the model would be too large to explore.
MAX_ENUMERATED_BITS = 16


class ModelTooLarge(Exception):
    """The exploration needed more nodes than its budget allows."""


@dataclass
class Model:
    """A machine's successor function under the timer horizon ``horizon``; ``watch`` = input bits
    that properties read, so ticks that differ only in them are kept apart."""

    machine: Machine
    horizon: int = 1
    watch: int = 0

    def __post_init__(self) -> None:
        m = self.machine
        # Without a T column nothing reads the timer: one class is then exact and much smaller.
        self.timed = m.timer_bit != 0
        self.horizon = max(1, self.horizon) if self.timed else 1
        self.omega = self.horizon + 1
        self.watch &= m.input_mask
        # Counters whose event column is missing cannot change what fires: do not track them.
        self.counter_event = tuple(m.counter_bits)
        self.tracked = sum(1 << i for i, bit in enumerate(m.counter_bits) if bit)
        self._classes: dict[tuple[int, int], list[tuple[int, int]]] = {}
        self._succ: dict[Node, list[Tick]] = {}

    @classmethod
    def exact(cls, machine: Machine, watch: int = 0) -> Model:
        """The model in which no timer value is abstracted."""
        loads = [row.timer for row in machine.rows]
        return cls(machine, max([machine.initial_timer, 1, *loads]), watch)

    @property
    def is_exact(self) -> bool:
        loads = [self.machine.initial_timer, *(r.timer for r in self.machine.rows)]
        return not self.timed or self.horizon >= max(loads)

    # --- nodes ----------------------------------------------------------------------------------

    def timer_class(self, value: int) -> int:
        if not self.timed:
            return 0
        return value if value <= self.horizon else self.omega

    def initial(self) -> Node:
        m = self.machine
        # The engine starts with every counter at 0, so their events are present from tick 0.
        return (m.initial_state, self.timer_class(m.initial_timer), self.tracked, (0,) * len(m.output_names), True)

    def counter_events(self, zero: int) -> int:
        return sum(bit for i, bit in enumerate(self.counter_event) if zero >> i & 1)

    def classes(self, state: int, context: int) -> list[tuple[int, int]]:
        """Per distinct outcome in ``state`` with timer/counter events ``context``: (events, row).

        Input combinations that fire the same row and agree on the watched inputs are one class;
        its representative presses as few inputs as possible (it becomes a line of a CSV).
        """
        key = (state, context)
        cached = self._classes.get(key)
        if cached is not None:
            return cached
        m = self.machine
        bits = (m.dispatch[state].relevant | self.watch) & m.input_mask
        if m.needs_event and not context and m.input_mask & ~bits:
            # Under the document's rule whether any event is present matters too: the lowest input the
            # rows do not use stands for "some other input reads 1".
            spare = m.input_mask & ~bits
            bits |= spare & -spare
        if bits.bit_count() > MAX_ENUMERATED_BITS:
            raise ModelTooLarge(
                N_("state {state} depends on {count} inputs", state=m.states[state], count=bits.bit_count())
            )
        seen: dict[tuple[int, int], int] = {}
        for inputs in sorted(subsets(bits), key=lambda x: (x.bit_count(), x)):
            events = inputs | context
            row = m.lookup(state, events)
            seen.setdefault((row, inputs & self.watch), events)
        result = [(events, row) for (row, _), events in seen.items()]
        self._classes[key] = result
        return result

    def successors(self, node: Node) -> list[Tick]:
        return memoised(self._succ, node, self._expand)

    def _expand(self, node: Node) -> Iterator[Tick]:
        state, timer, zero, outputs, first = node
        m = self.machine
        if first:  # the engine does not count down on the very first tick
            choices = [(timer, 0)]
        else:
            after = timer if timer == self.omega else max(0, timer - 1)
            choices = [(after, z) for z in subsets(self.tracked & ~zero)]
        for after, zeroed in choices:
            now_zero = zero | zeroed
            context = (m.timer_bit if after == 0 else 0) | self.counter_events(now_zero)
            for events, index in self.classes(state, context):
                if index == NO_ROW:
                    yield events, zeroed, NO_ROW, (state, after, now_zero, outputs, False)
                    if after == self.omega and not first:  # it may just have come down to the horizon
                        yield events, zeroed, NO_ROW, (state, self.horizon, now_zero, outputs, False)
                    continue
                yield events, zeroed, index, self._fire(index, now_zero, outputs)

    def _fire(self, index: int, zero: int, outputs: tuple[int, ...]) -> Node:
        row = self.machine.rows[index]
        if row.keeps:
            outputs = tuple(old if new is None else new for old, new in zip(outputs, row.outputs, strict=True))
        else:
            outputs = row.outputs  # type: ignore[assignment]  # no None when the row keeps nothing
        for i, load in enumerate(row.loads):
            if load is not None and self.tracked >> i & 1:
                zero = zero | (1 << i) if load == 0 else zero & ~(1 << i)
        return (row.next, self.timer_class(row.timer), zero, outputs, False)

    # --- whole graphs ---------------------------------------------------------------------------

    def explore(self, budget: int = 2_000_000) -> Graph:
        """Every node reachable from the initial node, with its ticks."""
        return Graph(self, reachable(self.initial(), self.successors, budget))

    def drops(self, before: Node, tick: Tick) -> bool:
        """Whether this tick is OMEGA coming down to the horizon (a wait that must be padded)."""
        return tick[2] == NO_ROW and before[1] == self.omega and tick[3][1] == self.horizon

    def concretize(self, path: Sequence[tuple[Node, Tick]]) -> tuple[list[TickInput], bool]:
        """Inputs that drive the real engine along ``path``; waits shortened by OMEGA are padded.

        Returns the inputs and whether the engine fired exactly the path's rows.
        """
        m = self.machine
        engine = Engine(m)
        ticks: list[TickInput] = []
        no_pulses = (0,) * len(self.counter_event)
        faithful = True
        for before, tick in path:
            events, zeroed, row, _ = tick
            mask = events & m.input_mask
            if self.drops(before, tick):
                while engine.timer > self.omega:  # idle until the next tick brings it to the horizon
                    engine.step(mask, no_pulses)
                    ticks.append(TickInput(mask, no_pulses))
            pulses = tuple(ZERO_PULSES if zeroed >> i & 1 else 0 for i in range(len(self.counter_event)))
            engine.step(mask, pulses)
            ticks.append(TickInput(mask, pulses))
            faithful &= engine.row == row
        return ticks, faithful


@dataclass
class Graph:
    """An explored model: ``nodes`` in breadth-first order (the first is the initial node)."""

    model: Model
    nodes: list[Node]

    def ticks(self) -> Iterator[tuple[Node, Tick]]:
        for node in self.nodes:
            for tick in self.model.successors(node):
                yield node, tick

    def fired_rows(self) -> set[int]:
        return {tick[2] for _, tick in self.ticks() if tick[2] != NO_ROW}

    def states(self) -> set[int]:
        return {node[0] for node in self.nodes}


def walk_back(parent: dict[K, tuple[K, Tick] | None], key: K) -> list[tuple[K, Tick]]:
    """The steps of a breadth-first search from its start (whose parent is None) to ``key``, in order:
    each step is (where it was taken, the tick taken)."""
    steps = []
    while (step := parent[key]) is not None:
        steps.append(step)
        key = step[0]
    steps.reverse()
    return steps


def memoised(cache: dict[K, list[V]], key: K, make: Callable[[K], Iterable[V]]) -> list[V]:
    """``make(key)`` as a list, made once per key: a model's successors, asked again by every search."""
    cached = cache.get(key)
    if cached is None:
        cached = cache[key] = list(make(key))
    return cached


def reachable(start: K, successors: Callable[[K], Iterable[tuple[Any, ...]]], budget: int) -> list[K]:
    """Every node reachable from ``start`` in breadth-first order, a tick's node after being its last item
    (the one-table model's and the product's); ModelTooLarge past ``budget`` nodes."""
    order, seen, queue = [start], {start}, deque([start])
    while queue:
        for tick in successors(queue.popleft()):
            nxt = tick[-1]
            if nxt not in seen:
                seen.add(nxt)
                order.append(nxt)
                queue.append(nxt)
                if len(order) > budget:
                    raise ModelTooLarge(N_("more than {budget} reachable situations", budget=budget))
    return order


def subsets(bits: int) -> Iterator[int]:
    """Every subset of ``bits``, the empty one first."""
    sub = 0
    while True:
        yield sub
        sub = (sub - bits) & bits
        if sub == 0:
            return
