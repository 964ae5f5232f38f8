"""What the simulator's compiled loops take, by name: the world, a robot's wiring, what a run keeps of its
ticks, a robot's working space; a fleet's robots and program variants (the table's compiled program is
:class:`tablebot.machine.Program`).

Each is a NamedTuple of arrays (and a few numbers): numba hands a tuple to a compiled function as the values
it holds, so a kernel taking four of them costs what the same kernel taking their thirty-odd fields costs,
and reads each by name. A robot's own rows stay float64 arrays whose columns :mod:`tablebot.sim.columns` names
outside the compiled loops; inside them they are records read by name (:mod:`tablebot.sim.physics.layout`).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, NamedTuple

import numpy as np

if TYPE_CHECKING:  # not at run time: this module stays free of numba (sim.physics.layout compiles)
    from tablebot.sim.physics.layout import Params, State


class WorldArrays(NamedTuple):
    """A world's geometry as the physics reads it (made by :func:`tablebot.sim.model.world.geometry`)."""

    verts: np.ndarray  # (V, 2) the vertices of every convex piece (a wall: 2, a box: 4)
    pstart: np.ndarray  # (P+1,) where each piece's vertices start in verts
    pbound: np.ndarray  # (P, 3) each piece's bounding circle
    edges: np.ndarray  # (E, 4) every piece's edges, for ray casts
    circles: np.ndarray  # (C, 4) x, y, r, lamp index or -1
    lamps: np.ndarray  # (L, 3) x, y, intensity
    lines: np.ndarray  # (K, 5) tape on the floor: x0, y0, x1, y1, half width
    shade: np.ndarray  # the shadow grid (sim.physics.shadows)


class Wiring(NamedTuple):
    """How a robot's body meets its table: the event bit of each input role, the drive motors' outputs, and
    the robot-row column each counter counts."""

    bits: np.ndarray  # int64 (N_BITS or fewer,): event bit per input role (sim.columns B_*), 0: not wired
    drive: np.ndarray  # int64 (2,): the outputs of the right and the left drive motor
    pulse_columns: np.ndarray  # int64 (counters,): the robot row's pulse column of each counter, -1: none


class RobotState(NamedTuple):
    """One robot as a run changes it: its row (pose, battery, sensors: sim.columns), its parameters, its
    engine (registers, outputs, counters) and the running summary of its rows (see sim.physics.kernel.observe)."""

    s: np.ndarray  # float64 (N_STATE,)
    p: np.ndarray  # float64 (N_PARAM,)
    regs: np.ndarray  # int64 (N_REGS,): tablebot.tick's registers
    outputs: np.ndarray  # int64 (outputs,)
    counters: np.ndarray  # int64 (counters,)
    acc: np.ndarray  # float64 (N_ACC,): sim.physics.kernel's A_* fields
    collisions: np.ndarray  # int64: the robot rows where collisions began (as many as fit)


class NamedRobot(NamedTuple):
    """:class:`RobotState` inside the compiled loops: its state and parameter rows as records, read by name
    (sim.physics.layout; sim.physics.kernel.named makes it, no copy), and the state row as it is, which the
    trace copies and the counters' pulses are read from by column."""

    s: State
    p: Params
    regs: np.ndarray
    outputs: np.ndarray
    counters: np.ndarray
    acc: np.ndarray
    collisions: np.ndarray
    row: np.ndarray  # float64 (N_STATE,): the memory of ``s``


class Record(NamedTuple):
    """What a run keeps of its ticks: each robot row and integer record (arrays with no rows: none) and the
    tally of a fleet's robot (``counts`` with no room: none; see sim.physics.kernel.tally)."""

    hist: np.ndarray  # float64 (ticks or 0, N_STATE): the robot at the start of each tick
    ints: np.ndarray  # int64 (ticks or 0, width): each tick's integer record (sim.physics.kernel I_*)
    counts: np.ndarray  # int64 (states,): ticks that ended in each state
    first_visit: np.ndarray  # int64 (states,): the first tick that ended in each state
    first_light: np.ndarray  # int64 (1,): the first tick whose input mask held a light bit
    light_bits: int  # the light sensors' event bits
    t0: int  # the number of the run's first tick


class Scratch(NamedTuple):
    """A robot's working space for a run: worked out once (``reach``, ``wide``, ``turns``: sim.physics.contacts.reaches,
    sim.physics.step.aim_turns), kept from tick to tick (``near``, ``centre``: the candidate obstacles), or
    overwritten every tick (``pulses``, ``corners``, ``z``)."""

    pulses: np.ndarray  # int64 (counters,)
    corners: np.ndarray  # float64 (4, 2)
    near: np.ndarray
    centre: np.ndarray
    turns: np.ndarray  # float64 (4,)
    z: np.ndarray  # float64 (N_NOISE,): this tick's noise row
    reach: float
    wide: float


class FleetState(NamedTuple):
    """N robots' :class:`RobotState`, a row each."""

    S: np.ndarray
    P: np.ndarray
    regs: np.ndarray
    outputs: np.ndarray
    counters: np.ndarray
    acc: np.ndarray
    collisions: np.ndarray


class FleetRecord(NamedTuple):
    """What a fleet keeps: every robot's tally (a row each of :class:`Record`'s) and, for the robots whose
    ``traced`` slot is >= 0, their rows and records in that slot of ``hist``/``ints``."""

    counts: np.ndarray  # (N, states)
    first_visit: np.ndarray  # (N, states)
    first_light: np.ndarray  # (N,)
    traced: np.ndarray  # int64 (N,): the robot's slot in hist/ints, -1: not traced
    hist: np.ndarray  # (traced, ticks, N_STATE)
    ints: np.ndarray  # (traced, ticks, width)
    light_bits: int
    t0: int


class ProgramVariants(NamedTuple):
    """A fleet's program variants (a tuned table's timers and counter loads): robot i runs the program with
    ``timers[variant[i]]`` and ``loads[variant[i]]``."""

    timers: np.ndarray  # int64 (variants, rows)
    loads: np.ndarray  # int64 (variants, rows, counters)
    variant: np.ndarray  # int64 (N,)


def untallied(hist: np.ndarray, ints: np.ndarray) -> Record:
    """A single robot's :class:`Record`: its rows and records (or none), no tally (its records say it all)."""
    empty = np.zeros(0, dtype=np.int64)
    return Record(hist, ints, empty, empty, empty, 0, 0)
