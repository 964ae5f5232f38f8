"""A run as its pictures see it: the scene's plain parts and the run's arrays they draw, with no tie to the
simulator (numba) or to matplotlib, so that a painter process can have it (:mod:`tablebot.sim.pictures.painter`)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

from tablebot.sim import columns as L

if TYPE_CHECKING:  # only types: see the module
    import numpy as np

    from tablebot.machine import Machine
    from tablebot.sim.model.params import Params
    from tablebot.sim.model.scene import Scene
    from tablebot.sim.model.world import Geometry, World
    from tablebot.sim.runner import SimRun
    from tablebot.table import Table


@dataclass(frozen=True)
class SceneView:
    """The parts of a :class:`~tablebot.sim.model.scene.Scene` the pictures draw."""

    table: Table
    machine: Machine
    world: World
    params: Params
    geometry: Geometry
    lamp_outputs: tuple[int, ...]

    @classmethod
    def of(cls, scene: Scene | SceneView) -> SceneView:
        if isinstance(scene, SceneView):
            return scene
        return cls(scene.table, scene.machine, scene.world, scene.params, scene.geometry, scene.lamp_outputs)

    @property
    def tick_s(self) -> float:
        return self.table.robot.tick_s


@dataclass(frozen=True)
class RunView:
    """A finished run as its pictures see it: the scene's plain parts, the per-tick columns they draw, and
    the columns of the robot rows they draw, in the rows' precision."""

    scene: SceneView
    seed: int
    rows: np.ndarray  # (ticks + 1, len(columns)): those columns of the run's hist
    columns: tuple[int, ...]  # the sim.columns held by ``rows``
    ends: np.ndarray  # (2, N_STATE): the robot before the first tick and after the last, in the rows' dtype
    states: np.ndarray
    outputs: np.ndarray
    events: np.ndarray

    @classmethod
    def of(cls, result: SimRun | RunView) -> RunView:
        if isinstance(result, RunView):
            return result
        assert result.hist is not None, "a run drawn keeps its robot rows (simulate with rows=True)"
        wanted = picture_columns(result.scene.table)
        rows = result.hist if result.hist_columns == wanted else result.hist[:, _indices(result, wanted)]
        return cls(
            SceneView.of(result.scene),
            result.seed,
            rows,
            wanted,
            ends_of(result),
            result.states,
            result.outputs,
            result.events,
        )

    @property
    def ticks(self) -> int:
        return len(self.states)

    @property
    def tick_s(self) -> float:
        return self.scene.tick_s

    def column(self, column: int) -> np.ndarray:
        """One column (sim.columns) of every robot row."""
        return self.rows[:, self.columns.index(column)]


def picture_columns(table: Table) -> tuple[int, ...]:
    """The columns of the robot rows the pictures draw: the pose, the phototransistors, the declared sensors."""
    sensors = range(L.READING, L.READING + min(len(table.robot.sensors), L.MAX_SENSORS))
    return (L.X, L.Y, L.TH, L.LIGHT_R, L.LIGHT_L, *sensors)


def _indices(result: SimRun, wanted: tuple[int, ...]) -> list[int]:
    return [result.held.index(c) for c in wanted]


def ends_of(result: SimRun) -> np.ndarray:
    """The first and last robot rows, whole, in the precision of the run's rows (as hist[0] and hist[-1])."""
    assert result.hist is not None
    return result.ends.astype(result.hist.dtype)
