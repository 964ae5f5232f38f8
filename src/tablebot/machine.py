"""The compiled machine: a parsed table turned into integer masks and per-state lookup maps.

This module owns the event-matching rule (:meth:`Machine.lookup`): the first row of the current
state, in table order, whose required events are a subset of the present events fires
(:func:`first_match`), except that under the document's rule (the robot file's ``match``) a tick with no
event at all looks up no row. Compilation precomputes that rule per state, so a tick costs O(1) in the
number of rows and every loop that indexes the precomputed lookups follows the table's rule for free.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from functools import cached_property

import numpy as np

from tablebot.robot import MATCH_DOCUMENT, StateId
from tablebot.table import TIMER_EVENT, Table
from tablebot.tick import Program

#: Per state, lookups are precomputed for every combination of the bits its rows use when there
#: are at most this many such bits; beyond that they are computed on first use and cached.
PREFILL_BITS = 12
#: Tables with at most this many event columns also get one flat lookup over (state, full event
#: mask): a single list index per tick, no masking. 10 bits = 1024 entries per state.
FLAT_BITS = 10
NO_ROW = -1


@dataclass(frozen=True)
class CompiledRow:
    """A row in engine terms: masks and state indices instead of names."""

    index: int
    state: int
    mask: int
    next: int
    timer: int
    outputs: tuple[int | None, ...]  # motors then lamps; None = keep
    loads: tuple[int | None, ...]  # per robot counter; None = leave alone
    keeps: bool  # any output kept: the new outputs must be merged with the old ones


def first_match(rows: Sequence[CompiledRow], events: int) -> CompiledRow | None:
    """The first row whose required event bits are all in ``events`` (the rule within one state; the
    document's "if an event is detected" is :meth:`Machine.lookup`'s)."""
    for row in rows:
        if row.mask & events == row.mask:
            return row
    return None


class Dispatch(dict[int, int]):
    """One state's map from (events masked to the bits its rows use) to the first match; key 0 is then
    every event set with none of those bits, so the empty set's answer is :meth:`Machine.lookup`'s."""

    def __init__(self, rows: Sequence[CompiledRow]) -> None:
        super().__init__()
        self.rows = tuple(rows)
        self.relevant = 0
        for row in rows:
            self.relevant |= row.mask
        if self.relevant.bit_count() <= PREFILL_BITS:
            sub = self.relevant
            while True:  # every subset of the relevant bits
                self[sub]
                if sub == 0:
                    break
                sub = (sub - 1) & self.relevant

    def __missing__(self, events: int) -> int:
        row = first_match(self.rows, events)
        self[events] = value = NO_ROW if row is None else row.index
        return value


@dataclass(frozen=True)
class Machine:
    """Everything the engine needs, as plain integers; ``table`` keeps the names for output."""

    table: Table
    states: tuple[StateId, ...]
    rows: tuple[CompiledRow, ...]
    dispatch: tuple[Dispatch, ...]
    timer_bit: int
    counter_bits: tuple[int, ...]
    input_bits: dict[str, int]
    initial_state: int
    initial_timer: int
    #: The document's rule: a tick with no event at all looks up no row (robot file ``match = "document"``).
    needs_event: bool = False

    @property
    def output_names(self) -> tuple[str, ...]:
        robot = self.table.robot
        return (*robot.motors, *robot.lamps)

    @property
    def n_motors(self) -> int:
        return len(self.table.robot.motors)

    @cached_property
    def input_mask(self) -> int:
        return sum(self.input_bits.values())

    def state_index(self, state: StateId) -> int:
        return self.states.index(state)

    def lookup(self, state: int, events: int) -> int:
        """Index of the row that fires in ``state`` for ``events`` (a full event mask), or -1; O(1) after
        compilation. THE matching rule: every other lookup (:attr:`flat`, the arrays, C) is made from it."""
        if not events and self.needs_event:  # the document: a row is looked up only if an event is detected
            return NO_ROW
        dispatch = self.dispatch[state]
        return dispatch[events & dispatch.relevant]

    @cached_property
    def flat(self) -> list[int] | None:
        """Fired row (or -1) at ``state << len(events) | events`` for every state and full event mask;
        None when the table has more than FLAT_BITS event columns (then use :meth:`lookup`)."""
        width = len(self.table.events)
        if width > FLAT_BITS:
            return None
        size = 1 << width
        flat = [dispatch[events & dispatch.relevant] for dispatch in self.dispatch for events in range(size)]
        for state in range(len(self.states)):  # the empty event set is where the two rules differ
            flat[state * size] = self.lookup(state, 0)
        return flat

    @cached_property
    def arrays(self) -> MachineArrays | None:
        """The machine as flat integer arrays (for compiled loops); None when :attr:`flat` is None."""
        if self.flat is None:
            return None
        return MachineArrays.of(self)

    def signature(self) -> tuple:
        """What defines behaviour (not descriptions or file lines): equal signatures, equal machines. The
        document's rule is part of it only where it can matter (a row that requires no event), so a table's
        signature, and the C engine's table hash made from it, is what it was before the rule was a choice."""
        rule = ("needs an event",) if self.needs_event and any(not r.mask for r in self.rows) else ()
        return (
            self.states,
            self.table.events,
            self.timer_bit,
            self.counter_bits,
            tuple((r.state, r.mask, r.next, r.timer, r.outputs, r.loads) for r in self.rows),
            self.initial_state,
            self.initial_timer,
            self.output_names,
            *rule,
        )


@dataclass(frozen=True)
class MachineArrays:
    """A machine as int64/bool arrays: what a compiled tick loop (numba, C) indexes directly.

    ``lookup[state, events]`` is the fired row or -1; per row, ``outputs``/``keep`` give each output's
    new value or "keep", ``loads``/``load_set`` each counter's load or "leave alone".
    """

    lookup: np.ndarray
    next: np.ndarray
    timer: np.ndarray
    outputs: np.ndarray
    keep: np.ndarray
    loads: np.ndarray
    load_set: np.ndarray
    counter_bits: np.ndarray
    input_mask: int = 0
    timer_bit: int = 0

    @cached_property
    def program(self) -> Program:
        """The arrays as compiled loops take them (:class:`Program`)."""
        return Program(
            input_mask=self.input_mask,
            timer_bit=self.timer_bit,
            lookup=self.lookup,
            next_state=self.next,
            timers=self.timer,
            outputs=self.outputs,
            keep=self.keep,
            loads=self.loads,
            load_set=self.load_set,
            counter_bits=self.counter_bits,
        )

    @staticmethod
    def of(machine: Machine) -> MachineArrays:
        rows, width = machine.rows, len(machine.table.events)
        n_out, n_counters = len(machine.output_names), len(machine.counter_bits)
        outputs = [[0 if v is None else v for v in row.outputs] for row in rows]
        loads = [[0 if v is None else v for v in row.loads] for row in rows]
        return MachineArrays(
            lookup=np.array(machine.flat, dtype=np.int64).reshape(len(machine.states), 1 << width),
            next=np.array([row.next for row in rows], dtype=np.int64),
            timer=np.array([row.timer for row in rows], dtype=np.int64),
            outputs=np.array(outputs, dtype=np.int64).reshape(len(rows), n_out),
            keep=np.array([[v is None for v in row.outputs] for row in rows], dtype=np.bool_).reshape(len(rows), n_out),
            loads=np.array(loads, dtype=np.int64).reshape(len(rows), n_counters),
            load_set=np.array([[v is not None for v in row.loads] for row in rows], dtype=np.bool_).reshape(
                len(rows), n_counters
            ),
            counter_bits=np.array(machine.counter_bits, dtype=np.int64).reshape(n_counters),
            input_mask=machine.input_mask,
            timer_bit=machine.timer_bit,
        )


def compile_table(table: Table) -> Machine:
    """Turn names into bits and indices, and precompute the first-match lookup of every state."""
    states = table.states
    index = {state: i for i, state in enumerate(states)}
    robot = table.robot
    rows = tuple(
        CompiledRow(
            index=row.index,
            state=index[row.state],
            mask=table.mask(row.events),
            next=index[row.next],
            timer=row.timer,
            outputs=(*row.motors, *row.lamps),
            loads=row.counters,
            keeps=None in (*row.motors, *row.lamps),
        )
        for row in table.rows
    )
    per_state: list[list[CompiledRow]] = [[] for _ in states]
    for row in rows:
        per_state[row.state].append(row)
    bit = table.bit
    return Machine(
        table=table,
        states=states,
        rows=rows,
        dispatch=tuple(Dispatch(r) for r in per_state),
        timer_bit=bit(TIMER_EVENT) if TIMER_EVENT in table.events else 0,
        counter_bits=tuple(bit(c) if c in table.events else 0 for c in robot.counter_names),
        input_bits={name: bit(name) for name in table.engine_inputs},  # inputs and cross-table events
        initial_state=index[robot.initial_state],
        initial_timer=robot.initial_timer,
        needs_event=robot.match == MATCH_DOCUMENT,
    )
