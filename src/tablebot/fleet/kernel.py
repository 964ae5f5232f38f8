"""The fleet's compiled loop: ``prange`` over robots, each advanced by :func:`tablebot.sim.kernel.run_robot`
(the very loop ``tablebot sim`` runs) on its own rows, then folded into per-robot summary counters.
"""

# Nothing here simulates anything itself: the tick rule, the physics, the collision/lamp accumulators and
# the tally of each tick (time per state, first visit of each state, first light: sim.kernel.tally, so no
# tick needs to be kept) are those of sim.kernel. What the fleet adds is the loop over robots and the
# per-robot program (a tuned table's timers and counter loads).

from __future__ import annotations

import numpy as np

from tablebot.jit import njit, numba, prange  # numba as tablebot.jit imports it (its cache folder, no scipy)
from tablebot.sim.kernel import NO_TICK as NO_TICK  # fleet.run's "never"
from tablebot.sim.kernel import move, run_robot


@njit(nogil=True)
def run_one(i: int, S: np.ndarray, P: np.ndarray, world: tuple[np.ndarray, ...], program: tuple, timers: np.ndarray,
            loads: np.ndarray, variant: np.ndarray, regs: np.ndarray, outputs: np.ndarray, counters: np.ndarray,
            bits: np.ndarray, drive: np.ndarray, pcols: np.ndarray, ticks: int, noise: np.ndarray, bitgens: np.ndarray,
            acc: np.ndarray, collisions: np.ndarray, light_bits: int, t0: int, counts: np.ndarray,
            first_visit: np.ndarray, first_light: np.ndarray, traced: np.ndarray, hist: np.ndarray,
            ints: np.ndarray) -> None:
    """Robot i of :func:`run_fleet`."""
    input_mask, timer_bit, lookup, nxt, _, new_outputs, keep, _, load_set, counter_bits = program
    v = variant[i]
    own = (input_mask, timer_bit, lookup, nxt, timers[v], new_outputs, keep, loads[v], load_set, counter_bits)
    slot = traced[i]
    if slot >= 0:
        rows, record = hist[slot], ints[slot]
    else:  # neither rows nor tick records: the tally is all a robot leaves
        rows, record = np.empty((0, S.shape[1])), np.empty((0, ints.shape[2]), dtype=np.int64)
    run_robot(S[i], P[i], *world, own, regs[i], outputs[i], counters[i], bits, drive, pcols, ticks, noise[i],
              bitgens[i], rows, record, acc[i], collisions[i], counts[i], first_visit[i], first_light[i:i + 1],
              light_bits, t0)


@njit(nogil=True, parallel=True)
def run_fleet(S: np.ndarray, P: np.ndarray, world: tuple[np.ndarray, ...], program: tuple,
              timers: np.ndarray, loads: np.ndarray, variant: np.ndarray, regs: np.ndarray, outputs: np.ndarray,
              counters: np.ndarray, bits: np.ndarray, drive: np.ndarray, pcols: np.ndarray, ticks: int,
              noise: np.ndarray, bitgens: np.ndarray, acc: np.ndarray, collisions: np.ndarray, light_bits: int,
              t0: int, counts: np.ndarray, first_visit: np.ndarray, first_light: np.ndarray, traced: np.ndarray,
              hist: np.ndarray, ints: np.ndarray) -> None:
    """Advance every robot ``ticks`` ticks: robot i runs ``run_robot`` on row i of each per-robot array, with
    its program variant's timers and counter loads (``variant[i]``), its noise rows ``noise[i]`` or, when
    they are empty, noise drawn from its Generator (``bitgens[i]``, see sim.normals).

    ``traced[i]`` >= 0 names the slot of ``hist``/``ints`` where robot i's robot rows and tick records
    are kept (for its trace); other robots record into scratch space that is folded and dropped.
    """
    for i in prange(S.shape[0]):
        run_one(i, S, P, world, program, timers, loads, variant, regs, outputs, counters, bits, drive, pcols, ticks,
                noise, bitgens, acc, collisions, light_bits, t0, counts, first_visit, first_light, traced, hist, ints)


@njit(nogil=True)
def run_fleet_serial(S: np.ndarray, P: np.ndarray, world: tuple[np.ndarray, ...], program: tuple,
                     timers: np.ndarray, loads: np.ndarray, variant: np.ndarray, regs: np.ndarray, outputs: np.ndarray,
                     counters: np.ndarray, bits: np.ndarray, drive: np.ndarray, pcols: np.ndarray, ticks: int,
                     noise: np.ndarray, bitgens: np.ndarray, acc: np.ndarray, collisions: np.ndarray, light_bits: int,
                     t0: int, counts: np.ndarray, first_visit: np.ndarray, first_light: np.ndarray, traced: np.ndarray,
                     hist: np.ndarray, ints: np.ndarray) -> None:
    """:func:`run_fleet` on this thread alone (small fleets, single-threaded workers: no thread pool to wake)."""
    for i in range(S.shape[0]):
        run_one(i, S, P, world, program, timers, loads, variant, regs, outputs, counters, bits, drive, pcols, ticks,
                noise, bitgens, acc, collisions, light_bits, t0, counts, first_visit, first_light, traced, hist, ints)


@njit(nogil=True, parallel=True)
def move_parallel(S: np.ndarray, P: np.ndarray, world: tuple[np.ndarray, ...], commands: np.ndarray, noise: np.ndarray,
                  bits: np.ndarray, acc: np.ndarray, collisions: np.ndarray) -> None:
    for i in prange(S.shape[0]):
        move(S[i], commands[i, 0], commands[i, 1], P[i], *world, noise[i], bits, acc[i], collisions[i])


@njit(nogil=True)
def move_serial(S: np.ndarray, P: np.ndarray, world: tuple[np.ndarray, ...], commands: np.ndarray, noise: np.ndarray,
                bits: np.ndarray, acc: np.ndarray, collisions: np.ndarray) -> None:
    for i in range(S.shape[0]):
        move(S[i], commands[i, 0], commands[i, 1], P[i], *world, noise[i], bits, acc[i], collisions[i])


#: Robot-ticks of work below which a call runs on the calling thread: waking the thread pool costs tens of
#: microseconds (far more on a busy machine, where idle pool threads also spin for their next job), a
#: BumberBot tick well under one.
PARALLEL_WORK = 4096


def parallel(robots: int, ticks: int) -> bool:
    """Whether a call over ``robots`` robots for ``ticks`` ticks is worth the thread pool."""
    return robots > 1 and robots * ticks >= PARALLEL_WORK and numba.get_num_threads() > 1


def move_fleet(S: np.ndarray, P: np.ndarray, world: tuple[np.ndarray, ...], commands: np.ndarray, noise: np.ndarray,
               bits: np.ndarray, acc: np.ndarray, collisions: np.ndarray) -> None:
    """One tick of physics for every robot with the motor levels ``commands[i]`` (right, left) given
    from outside (a learned controller): ``sim.kernel.move`` on each robot's rows."""
    kernel = move_parallel if parallel(S.shape[0], 1) else move_serial
    kernel(S, P, world, commands, noise, bits, acc, collisions)
