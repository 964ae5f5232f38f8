"""The simulated robot as a :class:`tablebot.loop.RobotIO`, one tick per read/write, for the live view.

It follows ``sim.runner.run`` tick for tick (same seed, same noise, same trace); the physics moves the
robot in :meth:`write`, after the engine has decided. It stands in until ``tablebot.sim.robot.SimRobot``
is on main, which the studio then uses instead.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np

from tablebot.loop import Reading
from tablebot.sim import layout as L
from tablebot.sim.physics import step_one
from tablebot.sim.runner import NOISE_BLOCK, initial_state
from tablebot.sim.scene import Scene


class SimIO:
    """One simulated robot in ``scene``; :meth:`reset` (seed) puts it back at the start."""

    def __init__(self, scene: Scene, seed: int = 1):
        self.scene = scene
        geo = scene.geometry
        self._args = (scene.P, geo.verts, geo.pstart, geo.pbound, geo.edges, geo.circles, geo.lamps)
        self._pcols = np.array(scene.pulse_columns, dtype=np.int64)
        self._pulses = np.zeros(len(self._pcols), dtype=np.int64)
        self._cmd = np.zeros((1, 2), dtype=np.int64)
        self._hist = np.zeros((2, L.N_STATE))
        self.reset(seed)

    def reset(self, seed: int | None = None, options: dict[str, Any] | None = None) -> tuple[Reading, dict[str, Any]]:
        """Back to the start pose with fresh seeded noise (Gymnasium-style); returns the first reading."""
        self.seed = 1 if seed is None else seed
        self._rng = np.random.default_rng(self.seed)
        self.S = initial_state(self.scene, self._rng)
        self._noise = self._rng.standard_normal((NOISE_BLOCK, 1, L.N_NOISE))
        self._cmd[:] = 0
        self._mask = step_one(self.S, self._cmd, *self._args, self._noise, 0, self.scene.bits, self._hist, 0,
                              self._pcols, self._pulses)
        self._j = 1
        return self.read(), {}

    # --- RobotIO --------------------------------------------------------------------------------------

    def open(self) -> None:
        pass

    def read(self) -> Reading:
        """What the robot senses now, plus its pose and raw readings for the view."""
        s = self.S[0]
        extra = {"x": float(s[L.X]), "y": float(s[L.Y]), "heading": math.degrees(s[L.TH]),
                 "light_r": float(s[L.LIGHT_R]), "light_l": float(s[L.LIGHT_L]), "battery_v": float(s[L.VBAT]),
                 "bumpers": int(s[L.BUMP_FR] > 0) | int(s[L.BUMP_FL] > 0) << 1 | int(s[L.BUMP_REAR] > 0) << 2,
                 "distance": float(s[L.DIST])}
        return Reading(int(self._mask), tuple(self._pulses.tolist()), extra)

    def write(self, outputs: Sequence[int]) -> None:
        """Run the motors as the engine says for one tick, then sense for the next one."""
        right, left = self.scene.drive
        self._cmd[0, 0], self._cmd[0, 1] = outputs[right], outputs[left]
        if self._j == NOISE_BLOCK:
            self._noise, self._j = self._rng.standard_normal((NOISE_BLOCK, 1, L.N_NOISE)), 0
        self._mask = step_one(self.S, self._cmd, *self._args, self._noise, self._j, self.scene.bits, self._hist, 1,
                              self._pcols, self._pulses)
        self._j += 1

    def stop(self) -> None:
        self._cmd[:] = 0  # nothing moves between ticks: the physics runs only in write()

    def close(self) -> None:
        pass
