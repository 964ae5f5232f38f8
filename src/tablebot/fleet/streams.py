"""Each robot of a fleet draws its noise from its own numpy Generator, ``default_rng(seed)``; this keeps those
streams for thousands of robots without thousands of Python objects where it can.

The compiled loop needs only each stream's handle (sim.physics.normals.bitgen_address). Where the inline path
holds, the robots' PCG64 states are rows of one array, seeded as ``default_rng(seed)`` seeds its PCG64 and
stepped in place by the compiled code: a fleet's 10,000 robots start without 10,000 Generators (making them,
taking their addresses and drawing their first numbers one Python call each was most of a sweep chunk's
set-up, holding the GIL the other chunk's thread came back for). A robot's Generator is made only when asked
for (:meth:`Streams.generator`: the tick-by-tick path draws its noise in Python) from its row's state at that
moment, and the compiled code follows it from then on. Elsewhere (another numpy, seeds beyond 128 bits) every
robot gets its Generator at once, as before.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from tablebot.fleet.generators import generators, seed_words
from tablebot.sim.physics.normals import (
    bitgen_address,
    pcg64_inline,
    pcg64_ints,
    pcg64_words,
    seed_pcg64,
    state_handles,
)

__all__ = ["Streams", "arrays_hold"]

_checked: bool | None = None  # whether seed_pcg64 seeds as this numpy's PCG64 does (checked once a process)


def arrays_hold() -> bool:
    """Whether robots' streams can live in an array here: numpy's PCG64 steps as the inline path steps it
    (:func:`pcg64_inline`), and :func:`seed_pcg64` leaves the state and increment numpy's PCG64 has for a
    few probe seeds (once a process)."""
    global _checked
    if _checked is None:
        _checked = pcg64_inline() is not None and _seeds_as_numpy([0, 1, 2**64 + 7, 2**127 - 5])
    return _checked


def _seeds_as_numpy(seeds: list[int]) -> bool:
    words = seed_words(seeds)
    if words is None:
        return False
    states = np.zeros((len(seeds), 4), dtype=np.uint64)
    seed_pcg64(states, words)
    for row, seed in zip(states.tolist(), seeds, strict=True):
        theirs = np.random.PCG64(seed).state["state"]
        if pcg64_words(theirs["state"], theirs["inc"]) != row:
            return False
    return True


class Streams:
    """The noise streams of ``n`` robots: ``handles`` for the compiled code, a robot's Generator on demand."""

    def __init__(self, n: int) -> None:
        self.handles = np.zeros(n, dtype=np.uint64)  # each robot's handle (sim.physics.normals.bitgen_address)
        self._states = np.zeros((n, 4), dtype=np.uint64)  # PCG64 words of the robots whose Generator is not made
        self._state_handles = state_handles(self._states)  # each row's inline handle (the array stays in place)
        self._rngs: list[np.random.Generator | None] = [None] * n

    def seed(self, rows: Sequence[int], seeds: Sequence[int]) -> None:
        """Robots ``rows`` start the streams of ``default_rng(seed)`` for their ``seeds``."""
        words = seed_words(seeds) if arrays_hold() else None
        if words is None:
            for i, rng in zip(rows, generators(seeds), strict=True):
                self.use(i, rng)
            return
        index = np.asarray(rows, dtype=np.int64)
        states = np.zeros((len(index), 4), dtype=np.uint64)
        seed_pcg64(states, words)
        self._states[index] = states
        self.handles[index] = self._state_handles[index]
        for i in rows:
            self._rngs[i] = None

    def use(self, i: int, rng: np.random.Generator) -> None:
        """Robot ``i`` draws from ``rng`` from now on (a traced robot's SimRobot, a robot placed again)."""
        self._rngs[i], self.handles[i] = rng, bitgen_address(rng)

    def generator(self, i: int) -> np.random.Generator:
        """Robot ``i``'s Generator, where its stream has got to (made from its row's state when first asked for)."""
        rng = self._rngs[i]
        if rng is None:
            state, inc = pcg64_ints(self._states[i].tolist())
            bit_generator = np.random.PCG64(0)  # any seed (0: no entropy read from the system): its state is set
            bit_generator.state = {
                "bit_generator": "PCG64",
                "state": {"state": state, "inc": inc},
                "has_uint32": 0,
                "uinteger": 0,
            }
            rng = np.random.Generator(bit_generator)
            self.use(i, rng)
        return rng
