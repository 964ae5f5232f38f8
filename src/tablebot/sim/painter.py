"""The run's two pictures drawn by a painter: a copy of this process forked as the command starts, which
imports matplotlib on the other core while this one imports the simulator and runs the robot, then draws
both pictures at once (itself one, a fork of itself the other) and hands their PNG bytes back.

This module imports neither matplotlib nor the simulator, nor even numpy, so that the painter is forked
as early as can be: what it gets is plain data (:class:`RunView`), and the drawing itself is
:func:`tablebot.sim.plots.paint`.
"""

from __future__ import annotations

import pickle
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from tablebot.files import atomic_write
from tablebot.sim import columns as L
from tablebot.sim.forked import Forked, Inbox

if TYPE_CHECKING:  # only types: see the module
    import numpy as np

    from tablebot.machine import Machine
    from tablebot.sim.params import Params
    from tablebot.sim.runner import SimRun
    from tablebot.sim.scene import Scene
    from tablebot.sim.summary import Summary
    from tablebot.sim.world import Geometry, World
    from tablebot.table import Table

#: The pictures' file names, in the order they are written.
PICTURES = ("trajectory.png", "timeline.png")


@dataclass(frozen=True)
class SceneView:
    """The parts of a :class:`~tablebot.sim.scene.Scene` the pictures draw."""

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
    only the columns of the robot rows they draw (a tenth of an hour's rows), in the rows' precision."""

    scene: SceneView
    seed: int
    rows: np.ndarray  # (ticks + 1, len(columns)): hist[:, columns] of the run
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
        return cls(SceneView.of(result.scene), result.seed, result.hist[:, wanted], wanted,
                   result.hist[[0, -1]], result.states, result.outputs, result.events)

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


class Painter:
    """Starts the painter now (see the module); :meth:`start` tells it the run about to start, :meth:`draw`
    hands it the finished run and writes the two pictures. Use it as a context manager: leaving the block
    kills the painter (and its fork) if they still run. Without a second core or ``fork``, the pictures
    are drawn here, one after the other."""

    def __init__(self) -> None:
        self.copy = Forked(_paint)

    def start(self, scene: Scene, ticks: int, seed: int) -> None:
        """The run about to start: the painter draws what it fixes (the arena, the title) while it runs."""
        self.copy.send((SceneView.of(scene), ticks, seed))

    def draw(self, result: SimRun, summary: Summary, folder: Path) -> list[Path]:
        """trajectory.png and timeline.png in ``folder``, in that order, each written under a temporary name
        and renamed into place (the painter writes no file)."""
        self.copy.send((RunView.of(result), summary))
        drawn = pickle.loads(self.copy.result())
        paths = [folder / name for name in PICTURES]
        for path, png in zip(paths, drawn, strict=True):
            with atomic_write(path, "wb") as stream:
                stream.write(png)
        return paths

    def close(self) -> None:
        self.copy.close()

    def __enter__(self) -> Painter:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def _paint(inbox: Inbox) -> bytes:
    """The painter's work: matplotlib imported (and warmed up) before the run arrives."""
    from tablebot.sim.plots import paint

    return paint(inbox)
