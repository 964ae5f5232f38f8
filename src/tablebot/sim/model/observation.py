"""What a learning agent observes of a simulated robot: its pose, the light its two phototransistors
receive, its bumpers, its battery, then the reading of every sensor its robot file declares, as one vector
per robot row (the Gymnasium environments' space).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from tablebot.sim import columns as L
from tablebot.sim.model.scene import Scene

#: The robot's own part of every observation, in order, and the state column each is read from.
BUILT_IN = (
    ("x", L.X),
    ("y", L.Y),
    ("cos_heading", L.TH),
    ("sin_heading", L.TH),
    ("light_right", L.LIGHT_R),
    ("light_left", L.LIGHT_L),
    ("bump_front_right", L.BUMP_FR),
    ("bump_front_left", L.BUMP_FL),
    ("bump_rear", L.BUMP_REAR),
    ("battery_v", L.VBAT),
)


@dataclass(frozen=True)
class Observation:
    """The observation of a scene's robot: ``names`` in order, the state ``columns`` they come from, and the
    bounds of each (``low``, ``high``). Call it with robot rows (N, N_STATE) for an (N, len(names)) array."""

    names: tuple[str, ...]
    columns: tuple[int, ...]
    low: np.ndarray
    high: np.ndarray
    declared: tuple[float, ...] = ()  # the scale of each declared sensor's reading (its trace form's)

    @staticmethod
    def of(scene: Scene) -> Observation:
        """The observation of ``scene``'s robot: each declared sensor as its trace writes it (``I3_cm``, the
        reading in its trace's scale), bounded by its kind (``SensorKind.high``)."""
        names, columns = zip(*BUILT_IN, strict=True)
        xs, ys = zip(*scene.world.walls, strict=True)
        top_volts = float(scene.params["battery"]["full_volts"]) + 1.0
        # the most light a sensor can get: every lamp at the nearest distance counted, with noise to spare
        near = scene.params["light"]["near"]
        light = 10.0 * max(1.0, sum(lamp.intensity for lamp in scene.world.lamps)) / near**2
        low = [min(xs) - 1, min(ys) - 1, -1, -1, 0, 0, 0, 0, 0, 0]
        high = [max(xs) + 1, max(ys) + 1, 1, 1, light, light, 1, 1, 1, top_volts]
        scales = []
        for k, sensor in enumerate(scene.table.robot.sensors[: L.MAX_SENSORS]):
            kind = sensor.sensor_kind
            suffix, scale, _ = kind.trace
            names, columns = (*names, f"{sensor.name}_{suffix}"), (*columns, L.READING + k)
            low.append(0.0)
            high.append(kind.high(scene.params, light) * scale)
            scales.append(scale)
        return Observation(
            names, columns, np.array(low, dtype=np.float64), np.array(high, dtype=np.float64), tuple(scales)
        )

    def __call__(self, rows: np.ndarray) -> np.ndarray:
        """The observations of robot rows ``rows`` (N, N_STATE): the heading as its cosine and sine, the
        light in threshold units (1 = where a phototransistor switches), bumpers 0/1, volts, then the
        declared sensors' readings."""
        obs = rows[:, list(self.columns)].copy()
        obs[:, 2], obs[:, 3] = np.cos(rows[:, L.TH]), np.sin(rows[:, L.TH])
        if self.declared:
            obs[:, len(BUILT_IN) :] *= np.array(self.declared)
        return obs
