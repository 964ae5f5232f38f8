"""The simulator's compiled loop for a robot of several tables (issue 36 §2): every table on every tick under the
rules of :mod:`tablebot.tables`, tick for tick as :class:`tablebot.engine.several.Several` steps them.

Each table is its own :class:`~tablebot.tick.Program` (a tuple of them, one numba type: every array of every
table has the same dtype and number of dimensions), with its own registers, outputs and counters (a row each of
:class:`SeveralState`). The tuple always holds :data:`~tablebot.robot_tables.MAX_TABLES` programs, the robot's
own and then the main table's again, never read (the loop counts the tables by :class:`SeveralState`'s rows):
numba compiles a function once per tuple length, and a minute of compiling for every new number of tables
(two, then three...) is what a user would wait for, on every cold cache.

A tick: the robot's input mask is read once and spread into each table's event layout (``inputs``), each table
gets the cross-table events of the states every table was in at the start of the tick (``cross``), each steps by
the one-table rule, and then each output is its one writer's and each counter load its writer's (``writers``,
``counter_writers``), which every table then sees.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from tablebot.engine.as_one import RobotEngine
from tablebot.engine_batch import tick_compiled
from tablebot.jit import njit
from tablebot.robot_tables import MAX_TABLES
from tablebot.sim.physics.kernel import end_tick, named, robot_scratch, start_tick
from tablebot.sim.physics.structures import NamedRobot, Record, RobotState, Scratch, Wiring, WorldArrays
from tablebot.tables import RobotTables
from tablebot.tick import EVENT, ROW, STATE, TIMER, Program, registers

# --- what the loop keeps of every table each tick: tables[t, k, :] ---------------------------------------
K_EVENT, K_ROW, K_STATE, K_TIMER = 0, 1, 2, 3
N_K = 4


class SeveralProgram(NamedTuple):
    """A robot's tables as the compiled loop reads them (made by :func:`several_program`)."""

    programs: tuple  # MAX_TABLES tick.Programs: each table's, the main one first, then the main one again (unread)
    inputs: np.ndarray  # int64 (tables, robot inputs): table k's event bit for the robot's input bit j (0: none)
    cross: np.ndarray  # int64 (tables, tables, most states): table k's bits while table s is in state i
    writers: np.ndarray  # int64 (outputs,): the table that writes each output, -1: none (it stays 0)
    counter_writers: np.ndarray  # int64 (counters,): the table that loads each counter, -1: none
    timers: np.ndarray  # int64 (tables, most rows): each row's timer (a tuned variant's in a fleet: ``own``)
    loads: np.ndarray  # int64 (tables, most rows, counters): each row's counter loads, likewise


class SeveralState(NamedTuple):
    """Every table's engine as the loop changes it, a row per table (the main one first)."""

    regs: np.ndarray  # int64 (tables, N_REGS)
    outputs: np.ndarray  # int64 (tables, outputs): each table's own, before the writers are chosen
    counters: np.ndarray  # int64 (tables, counters)
    starts: np.ndarray  # int64 (tables,): the states at the start of the tick (scratch)


def several_program(tables: RobotTables) -> SeveralProgram:
    """The compiled form of a robot's tables; ValueError when a table is too wide for the flat lookup."""
    count, robot_bits = len(tables.machines), tables.input_bits
    programs = []
    for machine in tables.machines:
        if machine.arrays is None:
            raise ValueError("the compiled simulator needs tables of at most FLAT_BITS event columns")
        programs.append(machine.arrays.program)
    inputs = np.zeros((count, max(1, len(robot_bits))), dtype=np.int64)
    for k, machine in enumerate(tables.machines):
        for name, bit in robot_bits.items():
            inputs[k, bit.bit_length() - 1] = machine.input_bits.get(name, 0)
    most = max(len(machine.states) for machine in tables.machines)
    cross = np.zeros((count, count, most), dtype=np.int64)
    for k, table in enumerate(tables.tables):
        for name, event in table.cross.items():
            source, states = tables.covers(event)
            for state in states:
                cross[k, source, state] |= table.bit(name)
    writers = np.array(
        [-1 if (w := tables.writer(name)) is None else w for name in tables.output_names], dtype=np.int64
    )
    counter_writers = np.array(
        [-1 if (w := tables.writer(name)) is None else w for name in tables.robot.counter_names], dtype=np.int64
    )
    timers, loads = table_values(tables)
    programs += [programs[0]] * (MAX_TABLES - count)  # one compiled loop for every number of tables
    return SeveralProgram(tuple(programs), inputs, cross, writers, counter_writers, timers[0], loads[0])


def table_values(tables: RobotTables) -> tuple[np.ndarray, np.ndarray]:
    """Every table's timers (1, tables, most rows) and counter loads (1, tables, most rows, counters), each
    table's rows first (the rest 0, never read): the values a tuned variant changes (:func:`own`)."""
    arrays = [machine.arrays for machine in tables.machines]
    most = max(len(a.timer) for a in arrays if a is not None)
    counters = len(tables.robot.counter_names)
    timers = np.zeros((1, len(arrays), most), dtype=np.int64)
    loads = np.zeros((1, len(arrays), most, counters), dtype=np.int64)
    for k, a in enumerate(arrays):
        assert a is not None, "several_program refuses a table too wide for the flat lookup"
        timers[0, k, : len(a.timer)] = a.timer
        loads[0, k, : len(a.timer)] = a.loads.reshape(len(a.timer), counters)
    return timers, loads


@njit(nogil=True, inline="always")
def own(sp: SeveralProgram, timers: np.ndarray, loads: np.ndarray) -> SeveralProgram:
    """``sp`` with the timers and counter loads of one program variant (a robot of a tuning's fleet)."""
    return SeveralProgram(sp.programs, sp.inputs, sp.cross, sp.writers, sp.counter_writers, timers, loads)


def several_state(engine: RobotEngine) -> SeveralState:
    """The loop's rows of every table, from the engines of ``engine`` as they are now."""
    engines = engine.several.engines
    regs = np.stack([registers(e.tick, e.state, e.timer, e.event, e.row) for e in engines])
    outputs = np.array([e.outputs for e in engines], dtype=np.int64).reshape(len(engines), -1)
    counters = np.array([e.counters for e in engines], dtype=np.int64).reshape(len(engines), -1)
    return SeveralState(regs, outputs, counters, np.zeros(len(engines), dtype=np.int64))


def sync(engine: RobotEngine, state: SeveralState, outputs: np.ndarray) -> None:
    """Leave ``engine``'s tables where the loop left its rows (as as many ``step`` calls would have)."""
    for k, table_engine in enumerate(engine.several.engines):
        table_engine._sync(state.regs[k], state.outputs[k], state.counters[k])
    engine.several.outputs = tuple(outputs.tolist())


@njit(nogil=True, refcounts=False, inline="always")
def tick_several(sp: SeveralProgram, st: SeveralState, outputs: np.ndarray, mask: int, pulses: np.ndarray) -> None:
    """One tick of every table (see the module's docstring); ``outputs`` gets the robot's outputs."""
    count = st.regs.shape[0]
    for k in range(count):
        st.starts[k] = st.regs[k, STATE]
    for k in range(count):
        events = 0
        for j in range(sp.inputs.shape[1]):
            if (mask >> j) & 1:
                events |= sp.inputs[k, j]
        for source in range(count):
            events |= sp.cross[k, source, st.starts[source]]
        p = sp.programs[k]  # with the timers and loads of this robot's variant
        program = Program(
            p.input_mask,
            p.timer_bit,
            p.lookup,
            p.next_state,
            sp.timers[k],
            p.outputs,
            p.keep,
            sp.loads[k],
            p.load_set,
            p.counter_bits,
        )
        tick_compiled(st.regs[k], st.outputs[k], st.counters[k], events, pulses, program)
    for o in range(outputs.shape[0]):
        writer = sp.writers[o]
        outputs[o] = 0 if writer < 0 else st.outputs[writer, o]
    for c in range(sp.counter_writers.shape[0]):
        writer = sp.counter_writers[c]
        if writer >= 0:
            value = st.counters[writer, c]
            for k in range(count):
                st.counters[k, c] = value


@njit(nogil=True)
def run_several(
    robot: RobotState,
    world: WorldArrays,
    sp: SeveralProgram,
    st: SeveralState,
    wiring: Wiring,
    ticks: int,
    noise: np.ndarray,
    bitgen: np.uint64,
    record: Record,
    tables: np.ndarray,
) -> None:
    """:func:`.kernel.run_robot` for a robot of several tables: ``robot.regs`` and ``robot.counters``
    are the main table's rows of ``st``, ``robot.outputs`` the robot's; ``tables[t]`` (when it has rows) gets
    every table's event, row, state and timer of tick t."""
    mine = named(robot)
    several_ticks(mine, world, sp, st, wiring, ticks, noise, bitgen, record, tables, robot_scratch(mine, world))


@njit(nogil=True, refcounts=False)
def several_ticks(
    robot: NamedRobot,
    world: WorldArrays,
    sp: SeveralProgram,
    st: SeveralState,
    wiring: Wiring,
    ticks: int,
    noise: np.ndarray,
    bitgen: np.uint64,
    record: Record,
    tables: np.ndarray,
    scratch: Scratch,
) -> None:
    """:func:`run_several`'s loop, given its scratch space: compiled without reference counting (tablebot.jit), as
    the one-table loop (kernel.run_ticks) is."""
    for t in range(ticks):
        mask = start_tick(t, robot, wiring, record, scratch)
        tick_several(sp, st, robot.outputs, mask, scratch.pulses)
        if tables.shape[0]:
            for k in range(st.regs.shape[0]):
                tables[t, k, K_EVENT] = st.regs[k, EVENT]
                tables[t, k, K_ROW] = st.regs[k, ROW]
                tables[t, k, K_STATE] = st.regs[k, STATE]
                tables[t, k, K_TIMER] = st.regs[k, TIMER]
        end_tick(t, mask, robot, world, wiring, noise, bitgen, record, scratch)


def table_columns(tables: RobotTables, kept: np.ndarray) -> dict[str, list]:
    """The other tables' trace keys (``NAME.event``, ``NAME.row``, ``NAME.state``, ``NAME.timer``) of the ticks
    ``kept`` holds (:func:`run_several`'s ``tables``), rows as the table's file writes them, states by name."""
    columns: dict[str, list] = {}
    for k in range(1, len(tables.machines)):
        name, machine = tables.names[k], tables.machines[k]
        written = [row.as_written for row in machine.table.rows]
        columns[f"{name}.event"] = kept[:, k, K_EVENT].tolist()
        columns[f"{name}.row"] = [None if r < 0 else written[r] for r in kept[:, k, K_ROW].tolist()]
        columns[f"{name}.state"] = [machine.states[s] for s in kept[:, k, K_STATE].tolist()]
        columns[f"{name}.timer"] = kept[:, k, K_TIMER].tolist()
    return columns
