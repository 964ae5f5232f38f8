"""The tick rule for compiled loops: count down, gather the events, fire the first matching row.

Plain Python over integer arrays, compiled by numba into every loop that runs many ticks (the
engine's batch path, the simulator, the fleet). ``Engine.step`` is the same rule specialised for
one tick at a time in Python; tests prove the two agree tick for tick on random tables.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

# The engine's registers, one int64 array per robot: what a tick reads and changes besides the
# outputs and counters arrays.
TICK, STATE, TIMER, EVENT, ROW = 0, 1, 2, 3, 4
N_REGS = 5


class Program(NamedTuple):
    """A compiled table as :func:`tick` reads it: one table's rule as integer arrays, by name (made by
    :attr:`tablebot.machine.MachineArrays.program`). numba passes it as the arrays it holds, at no cost beside
    separate arguments; a robot that runs several tables would take one Program per table (a tuple of them).

    ``lookup[state, events]`` is the fired row or -1; per row, ``next_state`` and ``timers`` (the timer it
    loads), ``outputs``/``keep`` each output's new value or "keep", ``loads``/``load_set`` each counter's load
    or "leave alone"; ``counter_bits[c]`` is counter c's event bit (0: no column), ``input_mask`` the events
    that come from inputs, ``timer_bit`` the T column's bit (0: none).
    """

    input_mask: int
    timer_bit: int
    lookup: np.ndarray
    next_state: np.ndarray
    timers: np.ndarray
    outputs: np.ndarray
    keep: np.ndarray
    loads: np.ndarray
    load_set: np.ndarray
    counter_bits: np.ndarray


def tick(
    regs: np.ndarray, outputs: np.ndarray, counters: np.ndarray, inputs: int, pulses: np.ndarray, program: Program
) -> int:
    """One tick of the document's engine; returns the fired row (-1: none).

    1. after the first tick the timer counts down (never below 0) and each counter by its pulses;
    2. the events are the inputs that read 1, plus T when the timer is 0, plus Cn when counter n is 0;
    3. the first row of the current state whose required events are all present fires (precomputed
       into ``lookup[state, events]`` by :meth:`tablebot.machine.Machine.lookup`, so the table's rule for a
       tick with no event at all, the robot file's ``match``, is in ``lookup[state, 0]``: no flag here);
    4. it sets each output it does not keep, loads the timer and the counters it names, and moves on.
    """
    n_counters = counters.shape[0]
    if regs[TICK] > 0:
        if regs[TIMER] > 0:
            regs[TIMER] -= 1
        for c in range(n_counters):
            counters[c] = max(0, counters[c] - pulses[c])
    regs[TICK] += 1
    events = inputs & program.input_mask
    if regs[TIMER] == 0:
        events |= program.timer_bit
    for c in range(n_counters):
        if counters[c] == 0:
            events |= program.counter_bits[c]
    row = program.lookup[regs[STATE], events]
    regs[EVENT] = events
    regs[ROW] = row
    if row >= 0:
        for k in range(outputs.shape[0]):
            if not program.keep[row, k]:
                outputs[k] = program.outputs[row, k]
        for c in range(n_counters):
            if program.load_set[row, c]:
                counters[c] = program.loads[row, c]
        regs[TIMER] = program.timers[row]
        regs[STATE] = program.next_state[row]
    return row


def registers(tick_count: int, state: int, timer: int, event: int = 0, row: int = -1) -> np.ndarray:
    regs = np.zeros(N_REGS, dtype=np.int64)
    regs[TICK], regs[STATE], regs[TIMER], regs[EVENT], regs[ROW] = tick_count, state, timer, event, row
    return regs
