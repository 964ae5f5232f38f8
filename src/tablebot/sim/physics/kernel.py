"""The simulator's compiled loop: per tick, the engine's tick rule and one robot's physics, in numba.

One robot's loop (:func:`run_robot`) is what ``tablebot sim`` runs; a fleet runs the same function
for many robots, so robot k of a fleet and a single simulated robot cannot differ.
"""

# Per tick t of robot i: the robot's state row ``s`` is the robot at the start of tick t (what its
# sensors read); the engine ticks on that mask and those pulses; the motors then run for one tick
# (physics.advance) and the sensors read again for tick t + 1. Every random number comes from the robot's
# own numpy Generator: given as ``noise`` rows, or drawn here from that Generator's C bit generator
# (sim.physics.normals, the same numbers numpy's standard_normal gives), one row of N_NOISE a tick either way.

from __future__ import annotations

import numpy as np

from tablebot.engine_batch import tick_compiled
from tablebot.jit import njit
from tablebot.sim.columns import N_NOISE
from tablebot.sim.physics.contacts import new_near, reaches
from tablebot.sim.physics.geometry import within
from tablebot.sim.physics.layout import Params, State, as_params, as_state
from tablebot.sim.physics.normals import standard_normal
from tablebot.sim.physics.step import advance, advance_called, aim_turns
from tablebot.sim.physics.structures import NamedRobot, Record, RobotState, Scratch, Wiring, WorldArrays
from tablebot.tick import EVENT, ROW, STATE, TIMER, Program

# --- the integer record of each tick: ints[t, :] -------------------------------------------------
I_MASK, I_EVENT, I_ROW, I_STATE, I_TIMER = 0, 1, 2, 3, 4
I_OUTPUTS = 5  # then one column per output, then per counter its value, then per counter its pulses

# --- what the robot's own rows amount to: acc[:] (float64), folded in as each row is made --------
A_REACHED = 0  # the first robot row within reach of a lamp (-1: none yet)
A_COLLISIONS = 1  # collisions so far (touches closer together than the debounce are one)
A_TOUCHING = 2  # 1 when the last row was touching something
A_LAST_TOUCH = 3  # the last row that touched something (NEVER: none yet)
A_ROWS = 4  # robot rows seen (the start row included)
A_REACH = 5  # metres: the lamp counts as reached this close (set by the caller)
A_DEBOUNCE = 6  # rows: touches within this many rows belong to the last collision (set by the caller)
N_ACC = 7
NEVER = -1e18
NO_TICK = -1  # "never" in a tally's first visits and first light


def new_accumulator(reach: float, debounce_rows: int) -> np.ndarray:
    acc = np.zeros(N_ACC)
    acc[A_REACHED] = -1.0
    acc[A_LAST_TOUCH] = NEVER
    acc[A_REACH], acc[A_DEBOUNCE] = reach, debounce_rows
    return acc


@njit(nogil=True, refcounts=False, inline="always")
def observe(s: State, lamps: np.ndarray, acc: np.ndarray, collisions: np.ndarray) -> None:
    """Fold one robot row into the running summary: reaching a lamp and the start of each collision
    (a rise of any bumper or contact with no touch in the debounce rows before it)."""
    robot_row = acc[A_ROWS]  # the row's number (not tick.py's ROW register, nor a noise row)
    acc[A_ROWS] = robot_row + 1.0
    if acc[A_REACHED] < 0.0:
        for k in range(lamps.shape[0]):
            if within(s.x - lamps[k, 0], s.y - lamps[k, 1], acc[A_REACH]):
                acc[A_REACHED] = robot_row
                break
    touching = s.bump_fr + s.bump_fl + s.bump_rear + s.contact > 0.0
    if touching:
        if acc[A_TOUCHING] == 0.0 and acc[A_LAST_TOUCH] < robot_row - acc[A_DEBOUNCE]:
            n = int(acc[A_COLLISIONS])
            if n < collisions.shape[0]:
                collisions[n] = int(robot_row)
            acc[A_COLLISIONS] = n + 1
        acc[A_LAST_TOUCH] = robot_row
    acc[A_TOUCHING] = 1.0 if touching else 0.0


@njit(nogil=True, refcounts=False, inline="always")
def tally(
    counts: np.ndarray,
    first_visit: np.ndarray,
    first_light: np.ndarray,
    light_bits: int,
    state: int,
    mask: int,
    tick: int,
) -> None:
    """Count a tick that ends in ``state`` (ticks per state, the first tick in each) and note the first tick
    whose input ``mask`` has any of ``light_bits``: what a fleet keeps of a robot's ticks."""
    counts[state] += 1
    if first_visit[state] == NO_TICK:
        first_visit[state] = tick
    if first_light[0] == NO_TICK and mask & light_bits:
        first_light[0] = tick


@njit(nogil=True)
def run_robot(
    robot: RobotState,
    world: WorldArrays,
    program: Program,
    wiring: Wiring,
    ticks: int,
    noise: np.ndarray,
    bitgen: np.uint64,
    record: Record,
) -> None:
    """Run one robot for ``ticks`` ticks, tick t moved by noise row ``noise[t]`` -- or, when ``noise`` has no
    rows, by a row drawn from the numpy Generator whose handle is ``bitgen`` (sim.physics.normals.bitgen_address).

    Writes the robot at the start of each tick into ``record.hist`` (when it has rows) and each tick's
    integer record into ``record.ints`` (when it has rows), folds every new robot row into the robot's
    ``acc``/``collisions`` (see :func:`observe`), and, when ``record.counts`` has room, tallies each tick
    (numbered from ``record.t0``) into the record's counts, first visits and first light (see :func:`tally`).
    """
    mine = named(robot)
    run_ticks(mine, world, program, wiring, ticks, noise, bitgen, record, robot_scratch(mine, world))


@njit(nogil=True, inline="always")
def named(robot: RobotState) -> NamedRobot:
    """``robot`` with its state and parameter rows as records (sim.physics.layout: the physics reads their
    fields by name; the same memory)."""
    return NamedRobot(
        as_state(robot.s),
        as_params(robot.p),
        robot.regs,
        robot.outputs,
        robot.counters,
        robot.acc,
        robot.collisions,
        robot.s,
    )


@njit(nogil=True, inline="always")
def robot_scratch(robot: NamedRobot, world: WorldArrays) -> Scratch:
    """A robot's working space for a run of its table(s): its counters' pulses and one tick of physics."""
    near, centre = new_near(world.pstart, world.circles)
    reach, wide = reaches(robot.p)
    turns = np.empty(4)
    aim_turns(robot.p, turns)
    return Scratch(
        np.zeros(robot.counters.shape[0], dtype=np.int64),
        np.empty((4, 2)),
        near,
        centre,
        turns,
        np.empty(N_NOISE),
        reach,
        wide,
    )


@njit(nogil=True, refcounts=False)
def run_ticks(
    robot: NamedRobot,
    world: WorldArrays,
    program: Program,
    wiring: Wiring,
    ticks: int,
    noise: np.ndarray,
    bitgen: np.uint64,
    record: Record,
    scratch: Scratch,
) -> None:
    """:func:`run_robot`'s loop, given its scratch space (compiled without reference counting: see tablebot.jit)."""
    for t in range(ticks):
        mask = start_tick(t, robot, wiring, record, scratch)
        tick_compiled(robot.regs, robot.outputs, robot.counters, mask, scratch.pulses, program)
        end_tick(t, mask, robot, world, wiring, noise, bitgen, record, scratch)


# The two halves of a tick round the tables' tick, shared by every loop (one table here, several in
# sim.physics.several), so that the rows a robot's run records are written by one piece of code.
@njit(nogil=True, refcounts=False, inline="always")
def start_tick(t: int, robot: NamedRobot, wiring: Wiring, record: Record, scratch: Scratch) -> int:
    """Tick t starts: the robot row (the robot as its sensors read it) into ``record.hist`` when it keeps rows,
    the counters' pulses into ``scratch.pulses``; returns the input mask the tables tick on."""
    row, hist, pulses, pcols = robot.row, record.hist, scratch.pulses, wiring.pulse_columns
    if hist.shape[0]:
        for j in range(row.shape[0]):
            hist[t, j] = row[j]
    for c in range(pulses.shape[0]):  # by column: pulse_columns names the wheel's (sim.model.scene)
        pulses[c] = 0 if pcols[c] < 0 else int(row[pcols[c]])
    return int(robot.s.mask)


@njit(nogil=True, refcounts=False, inline="always")
def end_tick(
    t: int,
    mask: int,
    robot: NamedRobot,
    world: WorldArrays,
    wiring: Wiring,
    noise: np.ndarray,
    bitgen: np.uint64,
    record: Record,
    scratch: Scratch,
) -> None:
    """Tick t ends, the tables ticked: its integer record into ``record.ints`` and its tally into the record's
    counts (each when it has rows), then the robot moves one tick on noise row t (or a row drawn from
    ``bitgen``: see :func:`run_robot`) and its new row is folded into its summary."""
    regs, outputs, z = robot.regs, robot.outputs, scratch.z
    if record.ints.shape[0]:
        _record(record.ints, t, mask, regs, outputs, robot.counters, scratch.pulses)
    if record.counts.shape[0]:
        tally(
            record.counts, record.first_visit, record.first_light, record.light_bits, regs[STATE], mask, record.t0 + t
        )
    if noise.shape[0]:
        for k in range(N_NOISE):
            z[k] = noise[t, k]
    else:
        for k in range(N_NOISE):
            z[k] = standard_normal(bitgen)
    drive = wiring.drive
    advance(robot.s, outputs[drive[0]], outputs[drive[1]], robot.p, world, wiring.bits, True, scratch)
    observe(robot.s, world.lamps, robot.acc, robot.collisions)


@njit(nogil=True, refcounts=False, inline="always")
def _record(
    ints: np.ndarray, t: int, mask: int, regs: np.ndarray, outputs: np.ndarray, counters: np.ndarray, pulses: np.ndarray
) -> None:
    ints[t, I_MASK] = mask
    ints[t, I_EVENT] = regs[EVENT]
    ints[t, I_ROW] = regs[ROW]
    ints[t, I_STATE] = regs[STATE]
    ints[t, I_TIMER] = regs[TIMER]
    k = I_OUTPUTS
    for j in range(outputs.shape[0]):
        ints[t, k] = outputs[j]
        k += 1
    for j in range(counters.shape[0]):
        ints[t, k] = counters[j]
        k += 1
    for j in range(pulses.shape[0]):
        ints[t, k] = pulses[j]
        k += 1


@njit(nogil=True)
def sense(s: np.ndarray, p: np.ndarray, world: WorldArrays, z: np.ndarray, bits: np.ndarray) -> None:
    """Read the sensors without moving (the start of a run)."""
    # not the constants 0 and False: numba would compile advance_called again for their literal types
    # (half a minute), since move passes variables
    still, moving = np.int64(0), np.bool_(False)
    params = as_params(p)
    advance_called(as_state(s), still, still, params, world, bits, moving, _scratch(params, world, z))


@njit(nogil=True)
def move(
    s: np.ndarray,
    right: int,
    left: int,
    p: np.ndarray,
    world: WorldArrays,
    z: np.ndarray,
    bits: np.ndarray,
    acc: np.ndarray,
    collisions: np.ndarray,
) -> None:
    """One tick of physics for one robot, driven from Python (the real-time, tick-by-tick path)."""
    row, params = as_state(s), as_params(p)  # float64 rows from Python, or records
    advance_called(row, right, left, params, world, bits, np.bool_(True), _scratch(params, world, z))  # see sense
    observe(row, world.lamps, acc, collisions)


@njit(nogil=True)
def first_readings(
    S: np.ndarray,
    p: np.ndarray,
    world: WorldArrays,
    rows: np.ndarray,
    draws: np.ndarray,
    bits: np.ndarray,
    acc: np.ndarray,
    collisions: np.ndarray,
) -> None:
    """Robots ``rows`` of ``S`` read their sensors where they start (:func:`sense`, robot ``rows[k]`` moved by
    noise row ``draws[k, 2:]``) and fold that first row into their summaries (:func:`observe`): a fleet's
    robots start in one call, not two calls from Python each."""
    z, params = np.empty(N_NOISE), as_params(p)
    for k in range(rows.shape[0]):
        i = rows[k]
        for j in range(N_NOISE):
            z[j] = draws[k, 2 + j]
        sense(S[i], params, world, z, bits)
        observe(as_state(S[i]), world.lamps, acc[i], collisions[i])


@njit(nogil=True, inline="always")
def _scratch(p: Params, world: WorldArrays, z: np.ndarray) -> Scratch:
    """A robot's working space for one tick of physics alone (no table: no pulses)."""
    near, centre = new_near(world.pstart, world.circles)
    reach, wide = reaches(p)
    turns = np.empty(4)
    aim_turns(p, turns)
    return Scratch(np.zeros(0, dtype=np.int64), np.empty((4, 2)), near, centre, turns, z, reach, wide)
