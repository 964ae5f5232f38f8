"""The fleet's compiled loop: ``prange`` over robots, each advanced by :func:`tablebot.sim.kernel.run_robot`
(the very loop ``tablebot sim`` runs) on its own rows, then folded into per-robot summary counters.
"""

# Nothing here simulates anything itself: the tick rule, the physics and the collision/lamp
# accumulators are those of sim.kernel. What the fleet adds is the loop over robots, the per-robot
# program (a tuned table's timers and counter loads), and folding each block of tick records into
# counts (time per state, first visit of each state, first light) so no tick needs to be kept.

from __future__ import annotations

import numpy as np

from tablebot.jit import njit, prange
from tablebot.sim.kernel import I_MASK, I_STATE, move, run_robot

NO_TICK = -1  # "never" in first_visit / first_light


@njit(nogil=True)
def fold(ints, t0, light_bits, counts, first_visit, first_light, i):  # type: ignore[no-untyped-def]
    """Add a block of tick records (``ints``, tick ``t0`` first) to robot ``i``'s counters."""
    for t in range(ints.shape[0]):
        state = ints[t, I_STATE]
        counts[i, state] += 1
        if first_visit[i, state] == NO_TICK:
            first_visit[i, state] = t0 + t
        if first_light[i] == NO_TICK and ints[t, I_MASK] & light_bits:
            first_light[i] = t0 + t


@njit(nogil=True, parallel=True)
def run_fleet(S, P, world, program, timers, loads, variant, regs, outputs, counters, bits, drive, pcols,
              noise, acc, collisions, light_bits, t0, counts, first_visit, first_light, traced, hist,
              ints):  # type: ignore[no-untyped-def]
    """Advance every robot ``noise.shape[1]`` ticks: robot i runs ``run_robot`` on row i of each
    per-robot array, with its program variant's timers and counter loads (``variant[i]``).

    ``traced[i]`` >= 0 names the slot of ``hist``/``ints`` where robot i's robot rows and tick records
    are kept (for its trace); other robots record into scratch space that is folded and dropped.
    """
    input_mask, timer_bit, lookup, nxt, _, new_outputs, keep, _, load_set, counter_bits = program
    width = ints.shape[2]
    for i in prange(S.shape[0]):
        v = variant[i]
        own = (input_mask, timer_bit, lookup, nxt, timers[v], new_outputs, keep, loads[v], load_set,
               counter_bits)
        slot = traced[i]
        if slot >= 0:
            rows, record = hist[slot], ints[slot]
        else:
            rows, record = np.empty((0, S.shape[1])), np.empty((noise.shape[1], width), dtype=np.int64)
        run_robot(S[i], P[i], *world, own, regs[i], outputs[i], counters[i], bits, drive, pcols, noise[i],
                  rows, record, acc[i], collisions[i])
        fold(record, t0, light_bits, counts, first_visit, first_light, i)


@njit(nogil=True, parallel=True)
def move_fleet(S, P, world, commands, noise, bits, acc, collisions):  # type: ignore[no-untyped-def]
    """One tick of physics for every robot with the motor levels ``commands[i]`` (right, left) given
    from outside (a learned controller): ``sim.kernel.move`` on each robot's rows."""
    for i in prange(S.shape[0]):
        move(S[i], commands[i, 0], commands[i, 1], P[i], *world, noise[i], bits, acc[i], collisions[i])
