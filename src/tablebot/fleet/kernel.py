"""The fleet's compiled loop: ``prange`` over robots, each advanced by :func:`tablebot.sim.kernel.run_robot`
(the very loop ``tablebot sim`` runs) on its own rows, then folded into per-robot summary counters.
"""

# Nothing here simulates anything itself: the tick rule, the physics and the collision/lamp
# accumulators are those of sim.kernel. What the fleet adds is the loop over robots, the per-robot
# program (a tuned table's timers and counter loads), and folding each block of tick records into
# counts (time per state, first visit of each state, first light) so no tick needs to be kept.

from __future__ import annotations

import numpy as np

from tablebot.jit import njit, numba, prange  # numba as tablebot.jit imports it (its cache folder, no scipy)
from tablebot.sim.kernel import I_MASK, I_STATE, move, run_robot

NO_TICK = -1  # "never" in first_visit / first_light


@njit(nogil=True, refcounts=False)
def fold(ints, t0, light_bits, counts, first_visit, first_light, i):  # type: ignore[no-untyped-def]
    """Add a block of tick records (``ints``, tick ``t0`` first) to robot ``i``'s counters."""
    for t in range(ints.shape[0]):
        state = ints[t, I_STATE]
        counts[i, state] += 1
        if first_visit[i, state] == NO_TICK:
            first_visit[i, state] = t0 + t
        if first_light[i] == NO_TICK and ints[t, I_MASK] & light_bits:
            first_light[i] = t0 + t


@njit(nogil=True)
def run_one(i, S, P, world, program, timers, loads, variant, regs, outputs, counters, bits, drive, pcols, ticks,
            noise, bitgens, acc, collisions, light_bits, t0, counts, first_visit, first_light, traced, hist,
            ints):  # type: ignore[no-untyped-def]
    """Robot i of :func:`run_fleet`."""
    input_mask, timer_bit, lookup, nxt, _, new_outputs, keep, _, load_set, counter_bits = program
    v = variant[i]
    own = (input_mask, timer_bit, lookup, nxt, timers[v], new_outputs, keep, loads[v], load_set, counter_bits)
    slot = traced[i]
    if slot >= 0:
        rows, record = hist[slot], ints[slot]
    else:
        rows, record = np.empty((0, S.shape[1])), np.empty((ticks, ints.shape[2]), dtype=np.int64)
    run_robot(S[i], P[i], *world, own, regs[i], outputs[i], counters[i], bits, drive, pcols, ticks, noise[i],
              bitgens[i], rows, record, acc[i], collisions[i])
    fold(record, t0, light_bits, counts, first_visit, first_light, i)


@njit(nogil=True, parallel=True)
def run_fleet(S, P, world, program, timers, loads, variant, regs, outputs, counters, bits, drive, pcols, ticks,
              noise, bitgens, acc, collisions, light_bits, t0, counts, first_visit, first_light, traced, hist,
              ints):  # type: ignore[no-untyped-def]
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
def run_fleet_serial(S, P, world, program, timers, loads, variant, regs, outputs, counters, bits, drive, pcols,
                     ticks, noise, bitgens, acc, collisions, light_bits, t0, counts, first_visit, first_light, traced,
                     hist, ints):  # type: ignore[no-untyped-def]
    """:func:`run_fleet` on this thread alone (small fleets, single-threaded workers: no thread pool to wake)."""
    for i in range(S.shape[0]):
        run_one(i, S, P, world, program, timers, loads, variant, regs, outputs, counters, bits, drive, pcols, ticks,
                noise, bitgens, acc, collisions, light_bits, t0, counts, first_visit, first_light, traced, hist, ints)


@njit(nogil=True, parallel=True)
def move_parallel(S, P, world, commands, noise, bits, acc, collisions):  # type: ignore[no-untyped-def]
    for i in prange(S.shape[0]):
        move(S[i], commands[i, 0], commands[i, 1], P[i], *world, noise[i], bits, acc[i], collisions[i])


@njit(nogil=True)
def move_serial(S, P, world, commands, noise, bits, acc, collisions):  # type: ignore[no-untyped-def]
    for i in range(S.shape[0]):
        move(S[i], commands[i, 0], commands[i, 1], P[i], *world, noise[i], bits, acc[i], collisions[i])


#: Robot-ticks of work below which a call runs on the calling thread: waking the thread pool costs tens of
#: microseconds (far more on a busy machine, where idle pool threads also spin for their next job), a
#: BumberBot tick well under one.
PARALLEL_WORK = 4096


def parallel(robots: int, ticks: int) -> bool:
    """Whether a call over ``robots`` robots for ``ticks`` ticks is worth the thread pool."""
    return robots > 1 and robots * ticks >= PARALLEL_WORK and numba.get_num_threads() > 1


def move_fleet(S, P, world, commands, noise, bits, acc, collisions):  # type: ignore[no-untyped-def]
    """One tick of physics for every robot with the motor levels ``commands[i]`` (right, left) given
    from outside (a learned controller): ``sim.kernel.move`` on each robot's rows."""
    kernel = move_parallel if parallel(S.shape[0], 1) else move_serial
    kernel(S, P, world, commands, noise, bits, acc, collisions)
