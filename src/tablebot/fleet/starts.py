"""How a fleet's robots start: each robot's scene (the table in the world with its ``[sim]`` parameters, made
once per parameter set, shared by the chunks of one process) at its own start pose, checked free, and the
:class:`~tablebot.sim.simrobot.Starter` that puts robots of one parameter set at their starts."""

from __future__ import annotations

import threading
from dataclasses import dataclass, field, replace
from typing import Any

from tablebot.diagnostics import fail
from tablebot.fleet.robots import Pose, RobotSpec
from tablebot.i18n import N_
from tablebot.machine import Machine
from tablebot.sim.model.scene import Scene, check_start, prepare
from tablebot.sim.model.world import World, inside
from tablebot.sim.simrobot import Starter
from tablebot.table import Table
from tablebot.tables import RobotTables


@dataclass
class Prepared:
    """What fleets of one table in one world with one robot layer share, by parameter set: the scene
    (:func:`~tablebot.sim.model.scene.prepare`: the world's pieces and shadow grid, milliseconds each) and how its
    robots start. A sweep's chunks in one process share one instead of preparing them again per chunk
    (:func:`tablebot.fleet.work.shared`); scenes and starters are only read once made. Its chunks run on several
    threads at once: each entry is made under ``lock``, once (two threads starting their first chunks both
    prepared the scene, and one could read the scenes while the other added one: "dictionary changed size
    during iteration", the sweep ended by an internal error)."""

    scenes: dict[tuple, Scene] = field(default_factory=dict)
    starters: dict[tuple, Starter] = field(default_factory=dict)
    lock: threading.Lock = field(default_factory=threading.Lock, repr=False, compare=False)


class Starts:
    """The scenes and starters of one fleet's robots: a table in a world with one robot layer."""

    def __init__(
        self,
        table: Table,
        machine: Machine,
        world: World,
        robot_params: dict[str, Any] | None,
        prepared: Prepared | None = None,
        tables: RobotTables | None = None,
    ) -> None:
        self.table, self.machine, self.world, self.robot_params = table, machine, world, robot_params
        self.prepared = prepared or Prepared()
        self.tables = tables  # a robot of several tables: its scenes are wired for all of them

    def scene(self, spec: RobotSpec) -> Scene:
        """The robot's scene: the table in the world with its parameters (made once per parameter set)
        and its start; every robot of a fleet must be wired alike."""
        scenes = self.prepared.scenes
        with self.prepared.lock:
            if spec.params not in scenes:
                scene = prepare(self.table, self.machine, self.world, self.robot_params, spec.overrides(), self.tables)
                first = next(iter(scenes.values()), scene)
                if (scene.bits.tolist(), scene.drive, scene.pulse_columns) != (
                    first.bits.tolist(),
                    first.drive,
                    first.pulse_columns,
                ):
                    raise ValueError("robots of one fleet must share their wiring")
                scenes[spec.params] = scene
            made = scenes[spec.params]
        return with_start(made, spec.start)

    def starter(self, spec: RobotSpec, scene: Scene) -> Starter:
        """How robots with ``spec``'s parameters start (one per parameter set, as their scenes)."""
        starters = self.prepared.starters
        with self.prepared.lock:
            if spec.params not in starters:
                starters[spec.params] = Starter(scene)
            return starters[spec.params]


def with_start(scene: Scene, start: Pose | None) -> Scene:
    """The scene with the robot starting at ``start`` (checked inside the walls, as a world file's [start]
    is, and free of walls and obstacles)."""
    if start is None:
        return scene
    sx, sy, sh = start
    world = replace(scene.world, start=(float(sx), float(sy), float(sh)))
    x, y, heading = world.start
    if world.walls and not inside(world.walls, (x, y)):
        raise fail(
            world.path,
            N_(
                "the robot's start pose ({x:g}, {y:g}, heading {heading:g}°) lies outside the arena walls",
                x=x,
                y=y,
                heading=heading,
            ),
            N_("choose a start inside the [arena] walls"),
        )
    check_start(world, scene.geometry, scene.P)
    return replace(scene, world=world)
