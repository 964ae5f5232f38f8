"""The engine's compiled batch loop: :func:`tablebot.tick.tick` over many recorded input masks.

Compiled with numba on first use (cached on disk, see :mod:`tablebot.jit`); importing this module
imports numba, so the engine imports it only when a batch runs.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from tablebot.tick import EVENT, ROW, STATE, TIMER, tick

njit: Callable[..., Any] | None
try:
    from tablebot.jit import njit
except ImportError:  # pragma: no cover - numba is a dependency, but the engine works without it
    njit = None

# a numba dispatcher; None without numba, and then nothing calls it (`batch` is not defined either)
tick_compiled: Any = njit(inline="always")(tick) if njit else None


def available() -> bool:
    return njit is not None


if njit is not None:

    @njit(nogil=True)
    def batch(
        masks: np.ndarray,
        pulses: np.ndarray,
        regs: np.ndarray,
        outputs: np.ndarray,
        counters: np.ndarray,
        program: tuple,
        columns: np.ndarray,
    ) -> None:
        """Run one tick per mask, with ``pulses[i]`` per counter (or none when ``pulses`` has no rows), and
        write events, rows, states, timers per tick into ``columns``; ``regs``, ``outputs`` and
        ``counters`` are updated in place."""
        no_pulses = np.zeros(counters.shape[0], dtype=np.int64)
        for i in range(masks.shape[0]):
            tick_compiled(regs, outputs, counters, masks[i], pulses[i] if pulses.shape[0] else no_pulses, program)
            columns[0, i] = regs[EVENT]
            columns[1, i] = regs[ROW]
            columns[2, i] = regs[STATE]
            columns[3, i] = regs[TIMER]
