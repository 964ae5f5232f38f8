"""The fleet's compiled loop: ``prange`` over robots, each advanced by :func:`tablebot.sim.physics.kernel.run_robot`
(the very loop ``tablebot sim`` runs) on its own rows, then folded into per-robot summary counters.
"""

# Nothing here simulates anything itself: the tick rule, the physics, the collision/lamp accumulators and
# the tally of each tick (time per state, first visit of each state, first light: sim.physics.kernel.tally, so no
# tick needs to be kept) are those of sim.physics.kernel. What the fleet adds is the loop over robots and the
# per-robot program (a tuned table's timers and counter loads).

from __future__ import annotations

import numpy as np

from tablebot.jit import njit, numba, prange  # numba as tablebot.jit imports it (its cache folder, no scipy)
from tablebot.sim.physics.kernel import NO_TICK as NO_TICK  # fleet.run's "never"
from tablebot.sim.physics.kernel import move, run_robot
from tablebot.sim.physics.several import SeveralProgram, SeveralState, own, run_several
from tablebot.sim.physics.structures import (
    FleetRecord,
    FleetState,
    ProgramVariants,
    Record,
    RobotState,
    Wiring,
    WorldArrays,
)
from tablebot.tick import Program


@njit(nogil=True)
def run_one(
    i: int,
    fleet: FleetState,
    world: WorldArrays,
    program: Program,
    variants: ProgramVariants,
    wiring: Wiring,
    ticks: int,
    noise: np.ndarray,
    bitgens: np.ndarray,
    record: FleetRecord,
) -> None:
    """Robot i of :func:`run_fleet`."""
    v = variants.variant[i]
    own = Program(
        program.input_mask,
        program.timer_bit,
        program.lookup,
        program.next_state,
        variants.timers[v],
        program.outputs,
        program.keep,
        variants.loads[v],
        program.load_set,
        program.counter_bits,
    )
    slot = record.traced[i]
    if slot >= 0:
        rows, ints = record.hist[slot], record.ints[slot]
    else:  # neither rows nor tick records: the tally is all a robot leaves
        rows = np.empty((0, fleet.S.shape[1]))
        ints = np.empty((0, record.ints.shape[2]), dtype=np.int64)
    robot = RobotState(
        fleet.S[i], fleet.P[i], fleet.regs[i], fleet.outputs[i], fleet.counters[i], fleet.acc[i], fleet.collisions[i]
    )
    kept = Record(
        rows, ints, record.counts[i], record.first_visit[i], record.first_light[i : i + 1], record.light_bits, record.t0
    )
    run_robot(robot, world, own, wiring, ticks, noise[i], bitgens[i], kept)


@njit(nogil=True, parallel=True)
def run_fleet(
    fleet: FleetState,
    world: WorldArrays,
    program: Program,
    variants: ProgramVariants,
    wiring: Wiring,
    ticks: int,
    noise: np.ndarray,
    bitgens: np.ndarray,
    record: FleetRecord,
) -> None:
    """Advance every robot ``ticks`` ticks: robot i runs ``run_robot`` on row i of each of the fleet's arrays,
    with its program variant's timers and counter loads (``variants.variant[i]``), its noise rows ``noise[i]``
    or, when they are empty, noise drawn from its Generator (``bitgens[i]``, see sim.physics.normals).

    ``record.traced[i]`` >= 0 names the slot of ``record.hist``/``record.ints`` where robot i's robot rows and
    tick records are kept (for its trace); other robots record into scratch space that is folded and dropped.
    """
    for i in prange(fleet.S.shape[0]):
        run_one(i, fleet, world, program, variants, wiring, ticks, noise, bitgens, record)


@njit(nogil=True)
def run_fleet_serial(
    fleet: FleetState,
    world: WorldArrays,
    program: Program,
    variants: ProgramVariants,
    wiring: Wiring,
    ticks: int,
    noise: np.ndarray,
    bitgens: np.ndarray,
    record: FleetRecord,
) -> None:
    """:func:`run_fleet` on this thread alone (small fleets, single-threaded workers: no thread pool to wake)."""
    for i in range(fleet.S.shape[0]):
        run_one(i, fleet, world, program, variants, wiring, ticks, noise, bitgens, record)


@njit(nogil=True)
def run_one_several(
    i: int,
    fleet: FleetState,
    world: WorldArrays,
    program: SeveralProgram,
    variants: ProgramVariants,
    tables: SeveralState,
    wiring: Wiring,
    ticks: int,
    noise: np.ndarray,
    bitgens: np.ndarray,
    record: FleetRecord,
    kept_tables: np.ndarray,
) -> None:
    """Robot i of :func:`run_fleet_several`: sim.physics.several.run_several on its rows (``tables``: every table's
    registers, outputs and counters, a row per robot; ``kept_tables``: each traced robot's tables per tick),
    every table with its variant's timers and loads (``variants.timers[v]``: tables × rows)."""
    v = variants.variant[i]
    mine = own(program, variants.timers[v], variants.loads[v])
    slot = record.traced[i]
    if slot >= 0:
        rows, ints, kept = record.hist[slot], record.ints[slot], kept_tables[slot]
    else:  # the tally is all a robot leaves
        rows = np.empty((0, fleet.S.shape[1]))
        ints = np.empty((0, record.ints.shape[2]), dtype=np.int64)
        kept = np.empty((0, kept_tables.shape[2], kept_tables.shape[3]), dtype=np.int64)
    state = SeveralState(tables.regs[i], tables.outputs[i], tables.counters[i], tables.starts[i])
    robot = RobotState(
        fleet.S[i], fleet.P[i], state.regs[0], fleet.outputs[i], state.counters[0], fleet.acc[i], fleet.collisions[i]
    )
    record_i = Record(
        rows, ints, record.counts[i], record.first_visit[i], record.first_light[i : i + 1], record.light_bits, record.t0
    )
    run_several(robot, world, mine, state, wiring, ticks, noise[i], bitgens[i], record_i, kept)


@njit(nogil=True)
def run_fleet_several_serial(
    fleet: FleetState,
    world: WorldArrays,
    program: SeveralProgram,
    variants: ProgramVariants,
    tables: SeveralState,
    wiring: Wiring,
    ticks: int,
    noise: np.ndarray,
    bitgens: np.ndarray,
    record: FleetRecord,
    kept_tables: np.ndarray,
) -> None:
    """Advance every robot of several tables ``ticks`` ticks (every table each tick, as ``tablebot sim`` runs them),
    on this thread: numba's parallel loop cannot take a tuple of programs (each table's), so a fleet runs this on
    slices of its robots in threads of its own (:func:`tablebot.fleet.run.in_threads`; it holds no GIL)."""
    for i in range(fleet.S.shape[0]):
        run_one_several(i, fleet, world, program, variants, tables, wiring, ticks, noise, bitgens, record, kept_tables)


@njit(nogil=True, parallel=True)
def move_parallel(
    S: np.ndarray,
    P: np.ndarray,
    world: WorldArrays,
    commands: np.ndarray,
    noise: np.ndarray,
    bits: np.ndarray,
    acc: np.ndarray,
    collisions: np.ndarray,
) -> None:
    for i in prange(S.shape[0]):
        move(S[i], commands[i, 0], commands[i, 1], P[i], world, noise[i], bits, acc[i], collisions[i])


@njit(nogil=True)
def move_serial(
    S: np.ndarray,
    P: np.ndarray,
    world: WorldArrays,
    commands: np.ndarray,
    noise: np.ndarray,
    bits: np.ndarray,
    acc: np.ndarray,
    collisions: np.ndarray,
) -> None:
    for i in range(S.shape[0]):
        move(S[i], commands[i, 0], commands[i, 1], P[i], world, noise[i], bits, acc[i], collisions[i])


#: Robot-ticks of work below which a call runs on the calling thread: waking the thread pool costs tens of
#: microseconds (far more on a busy machine, where idle pool threads also spin for their next job), a
#: BumberBot tick well under one.
PARALLEL_WORK = 4096


def parallel(robots: int, ticks: int) -> bool:
    """Whether a call over ``robots`` robots for ``ticks`` ticks is worth the thread pool."""
    return robots > 1 and robots * ticks >= PARALLEL_WORK and numba.get_num_threads() > 1


def move_fleet(
    S: np.ndarray,
    P: np.ndarray,
    world: WorldArrays,
    commands: np.ndarray,
    noise: np.ndarray,
    bits: np.ndarray,
    acc: np.ndarray,
    collisions: np.ndarray,
) -> None:
    """One tick of physics for every robot with the motor levels ``commands[i]`` (right, left) given
    from outside (a learned controller): ``sim.physics.kernel.move`` on each robot's rows."""
    kernel = move_parallel if parallel(S.shape[0], 1) else move_serial
    kernel(S, P, world, commands, noise, bits, acc, collisions)
