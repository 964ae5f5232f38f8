"""The simulator's physics, one tick of one robot: motors and battery, kinematics, the body's contacts and
bumpers (:mod:`tablebot.sim.physics.contacts`), light and the declared sensors (:mod:`tablebot.sim.physics.sensing`). It
works on numpy arrays of N robots (layout in :mod:`tablebot.sim.columns`), compiled with numba, so one
robot and a batch of thousands (which do not see each other) share this code.
"""

# World geometry (built by tablebot.sim.model.world): ``verts`` (V, 2) and ``pstart`` (P+1,) are convex
# pieces (a wall or segment is a 2-vertex piece, a box a 4-vertex one); ``pbound`` (P, 3) their
# bounding circles; ``edges`` (E, 4) every piece's edges for ray casts; ``circles`` (C, 4) = x, y, r,
# lamp index or -1; ``lamps`` (L, 3) = x, y, intensity; ``lines`` (K, 5) = x0, y0, x1, y1, half width of
# each straight piece of tape on the floor (seen by floor sensors only).

from __future__ import annotations

import math

import numpy as np

from tablebot.jit import njit
from tablebot.sim.columns import (
    B_FL,
    B_FR,
    B_LIGHT_L,
    B_LIGHT_R,
    B_REAR,
    F_KIND,
    Z_LIGHT_L,
    Z_LIGHT_R,
    Z_MOTOR_L,
    Z_MOTOR_R,
)
from tablebot.sim.physics.contacts import resolve, sense_bumpers
from tablebot.sim.physics.layout import Params, State, as_params, as_state
from tablebot.sim.physics.sensing import light_turned, sense_declared, sensor_events
from tablebot.sim.physics.shadows import NO_SHADE
from tablebot.sim.physics.structures import Scratch, WorldArrays

NO_LINES = np.zeros((0, 5))  # a world without tape on its floor

# --- light ---------------------------------------------------------------------------------------


@njit(cache=True, refcounts=False, inline="always")
def light_side(
    s: State,
    c: float,
    sn: float,
    p: Params,
    side: float,
    ct: float,
    st: float,
    edges: np.ndarray,
    circles: np.ndarray,
    lamps: np.ndarray,
    shade: np.ndarray,
) -> float:
    """Light the right (side -1) or left (+1) phototransistor of the BumberBot's wiring receives (``c``,
    ``sn``: the heading's cosine and sine; ``ct``, ``st``: those of its turn, :func:`aim_turns`; ``shade``:
    the world's shadow grid). Most ticks no lamp is in its field of view, or it is in shadow:
    :func:`sim.physics.sensing.light_turned` rules such lamps out cheaply, with light_from's answer."""
    return light_turned(s, c, sn, p, p.lx, side * p.ly, side * p.toe, ct, st, edges, circles, lamps, shade)


@njit(cache=True, refcounts=False, inline="always")
def aim_turns(p: Params, out: np.ndarray) -> None:
    """``out``: cosine and sine of the right phototransistor's turn from the heading, then the left one's."""
    out[0], out[1] = math.cos(-1.0 * p.toe), math.sin(-1.0 * p.toe)
    out[2], out[3] = math.cos(1.0 * p.toe), math.sin(1.0 * p.toe)


@njit(cache=True)
def light_at(
    s: np.ndarray,
    p: np.ndarray,
    side: float,
    edges: np.ndarray,
    circles: np.ndarray,
    lamps: np.ndarray,
    shade: np.ndarray = NO_SHADE,
) -> float:
    """Light the right (side -1) or left (+1) phototransistor of the BumberBot's wiring receives."""
    row, params = as_state(s), as_params(p)  # float64 rows from Python, or records
    turns = np.empty(4)
    aim_turns(params, turns)
    k = 0 if side < 0.0 else 2
    return light_side(
        row, math.cos(row.th), math.sin(row.th), params, side, turns[k], turns[k + 1], edges, circles, lamps, shade
    )


# --- motors, battery, motion ---------------------------------------------------------------------


@njit(cache=True, refcounts=False, inline="always")
def duty(level: int, levels: float) -> float:
    """The fraction of full power a speed level gives (the table's 1..8 are PWM duty level/8)."""
    return min(1.0, abs(level) / levels)


@njit(cache=True, refcounts=False, inline="always")
def pack_volts(full: float, empty: float, charge: float, amps: float, ohms: float) -> float:
    """Battery terminal volts: open-circuit volts fall linearly with the charge and sag with the current."""
    return empty + (full - empty) * charge - amps * ohms


@njit(cache=True, refcounts=False, inline="always")
def motor(s: State, p: Params, level: int, volts: float, right: bool, noise: float) -> None:
    """One motor, the right one when ``right`` (a constant at each call: the branch compiles away): target
    speed ∝ duty × battery volts - friction volts, reached with a first-order lag.

    The encoder counts the motor's own turns (a wheel slipping against a wall still counts). Each field is
    written as soon as it is worked out, as the flat rows' motor wrote its columns: a motor that returned its
    speed, encoder and pulses for the caller to store made the whole kernel x1.15 slower, with the same
    instructions in a different order (benchmarks/kernel.py; sim.physics.layout says more).
    """
    power = duty(level, p.levels)
    gain = s.gain_r if right else s.gain_l
    target = np.sign(level) * gain * p.kv * max(0.0, power * volts - p.vf) * (1.0 + p.nmotor * noise)
    if right:
        s.v_r += (target - s.v_r) * p.alpha
        before = s.enc_r
        s.enc_r += abs(s.v_r) * p.dt / (2.0 * math.pi * p.wheel_r) * p.ppr
        s.pul_r = math.floor(s.enc_r) - math.floor(before)
    else:
        s.v_l += (target - s.v_l) * p.alpha
        before = s.enc_l
        s.enc_l += abs(s.v_l) * p.dt / (2.0 * math.pi * p.wheel_r) * p.ppr
        s.pul_l = math.floor(s.enc_l) - math.floor(before)


@njit(cache=True, refcounts=False, inline="always")
def drive(s: State, cmd: tuple[int, int], p: Params, z: np.ndarray) -> None:
    """One tick of battery (open-circuit volts fall with charge, sag with current), motors and wheels."""
    dt = p.dt
    amps = p.iidle + p.imotor * (duty(cmd[0], p.levels) + duty(cmd[1], p.levels))
    volts = pack_volts(p.vfull, p.vempty, s.soc, amps, p.rint)
    s.amps, s.vbat = amps, volts
    s.soc = max(0.0, s.soc - amps * dt / p.cap)
    motor(s, p, cmd[0], volts, True, z[Z_MOTOR_R])
    motor(s, p, cmd[1], volts, False, z[Z_MOTOR_L])
    turn = (s.v_r - s.v_l) / p.base * dt
    ahead = 0.5 * (s.v_r + s.v_l) * dt
    mid = s.th + 0.5 * turn  # midpoint heading: exact for straight runs and spins, close on arcs
    s.x += ahead * math.cos(mid)
    s.y += ahead * math.sin(mid)
    s.th += turn


@njit(cache=True, refcounts=False, inline="always")
def input_mask(s: State, bits: np.ndarray) -> int:
    """The engine's input bits from the switch states and the light readings (1 = above threshold)."""
    mask = 0
    if s.bump_fr > 0.0:
        mask |= bits[B_FR]
    if s.bump_fl > 0.0:
        mask |= bits[B_FL]
    if s.bump_rear > 0.0:
        mask |= bits[B_REAR]
    if s.light_r >= 1.0:
        mask |= bits[B_LIGHT_R]
    if s.light_l >= 1.0:
        mask |= bits[B_LIGHT_L]
    return mask


@njit(cache=True, refcounts=False, inline="always")
def sense_near(
    s: State,
    p: Params,
    z: np.ndarray,
    verts: np.ndarray,
    pstart: np.ndarray,
    pbound: np.ndarray,
    edges: np.ndarray,
    circles: np.ndarray,
    lamps: np.ndarray,
    lines: np.ndarray,
    shade: np.ndarray,
    bits: np.ndarray,
    reach: float,
    wide: float,
    near: np.ndarray,
    centre: np.ndarray,
    turns: np.ndarray,
) -> None:
    """Everything one robot senses where it stands: bumpers, phototransistors, the sensors its robot file
    declares (sim.physics.sensing), and the input mask they make (hysteresis reads the previous mask). The heading's
    cosine and sine are worked out once for all of them."""
    c, sn = math.cos(s.th), math.sin(s.th)
    sense_bumpers(s, p, c, sn, verts, pstart, pbound, circles, reach, wide, near, centre)
    right = light_side(s, c, sn, p, -1.0, turns[0], turns[1], edges, circles, lamps, shade)
    s.light_r = max(0.0, right * (1.0 + p.nlight * z[Z_LIGHT_R]))
    left = light_side(s, c, sn, p, 1.0, turns[2], turns[3], edges, circles, lamps, shade)
    s.light_l = max(0.0, left * (1.0 + p.nlight * z[Z_LIGHT_L]))
    if p.sensor[0, F_KIND] != 0.0:  # declared sensors fill the slots from the first: none declared, no pass
        sense_declared(s, c, sn, p, edges, circles, lamps, lines, shade)
    previous = int(s.mask)
    s.mask = input_mask(s, bits) | sensor_events(s, p, bits, previous)


@njit(cache=True, refcounts=False, inline="always")
def advance(
    s: State,
    right: int,
    left: int,
    p: Params,
    world: WorldArrays,
    bits: np.ndarray,
    move: bool,
    scratch: Scratch,
) -> None:
    """One robot, one tick: drive with motor levels ``right``/``left`` (when ``move``), resolve contacts,
    sense, moved by the noise row ``scratch.z``; fills the robot's MASK column. ``scratch`` also keeps the
    robot's candidate obstacles from tick to tick (:func:`~tablebot.sim.physics.contacts.new_near`)."""
    w, near, centre = world, scratch.near, scratch.centre
    if move:
        x0, y0 = s.x, s.y
        cmd = (right, left)
        drive(s, cmd, p, scratch.z)
        resolve(
            s, p, scratch.corners, w.verts, w.pstart, w.pbound, w.circles, scratch.reach, scratch.wide, near, centre
        )
        s.dist += math.hypot(s.x - x0, s.y - y0)
    sense_near(
        s,
        p,
        scratch.z,
        w.verts,
        w.pstart,
        w.pbound,
        w.edges,
        w.circles,
        w.lamps,
        w.lines,
        w.shade,
        bits,
        scratch.reach,
        scratch.wide,
        near,
        centre,
        scratch.turns,
    )


@njit(cache=True, refcounts=False)
def advance_called(
    s: State,
    right: int,
    left: int,
    p: Params,
    world: WorldArrays,
    bits: np.ndarray,
    move: bool,
    scratch: Scratch,
) -> None:
    """:func:`advance` compiled once as a function of its own, for sim.physics.kernel.move and sense: the tick-by-tick
    robot, a fleet's first readings and the Gymnasium env's physics-only loop (fleet.kernel.move_serial),
    where a call per robot-tick costs little beside the rest of a controller's step, and each inlined copy
    took numba ~20 s to compile. The loops that run the table too (run_robot) inline :func:`advance` itself."""
    advance(s, right, left, p, world, bits, move, scratch)
