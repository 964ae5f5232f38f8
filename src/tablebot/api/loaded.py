"""A robot's files found and read (:class:`Loaded`), what every call of the front door starts from;
:func:`tablebot.api.project.open` makes one (a :class:`~tablebot.api.project.Project`)."""

from __future__ import annotations

import os
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from functools import cached_property
from pathlib import Path
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from tablebot.machine import Machine
    from tablebot.robot import Robot
    from tablebot.sim.scene import Scene
    from tablebot.sim.world import World
    from tablebot.table import Table

#: A file or folder name, as ``open`` and the calls take them.
PathLike = str | os.PathLike[str]


@dataclass(frozen=True, eq=False)
class Loaded:
    """A robot's table (read and compiled) with the files it runs with. ``table`` is the parsed table
    (``table.robot`` its robot file's contents, ``table.path`` its file), ``machine`` the compiled one;
    ``world_files`` and ``property_files`` are the files given or found, ``robot_file`` the robot file given
    to :func:`~tablebot.api.project.open` (None: the one beside the table, or the built-in BumberBot)."""

    table: Table
    machine: Machine
    world_files: tuple[Path, ...] = ()
    property_files: tuple[Path, ...] = ()
    robot_file: Path | None = None

    @property
    def path(self) -> Path:
        """The table file."""
        return Path(self.table.path)

    @property
    def robot(self) -> Robot:
        """What the robot file says (inputs, motors, tick, sensors, ...)."""
        return self.table.robot

    @cached_property
    def worlds(self) -> tuple[World, ...]:
        """The worlds it runs in: those given to :func:`open`, else its default one (read on first use)."""
        from tablebot.sim.world import load_world

        if self.world_files:
            return tuple(load_world(path) for path in self.world_files)
        return (self.default_world(),)

    def default_world(self) -> World:
        """The robot's ``sim.world``, else ``arena.toml`` beside the table, else an empty room."""
        from tablebot.sim.scene import find_world, robot_layer

        return find_world(self.table, None, robot_layer(self.robot)[1])

    def scene(self, world: PathLike | None = None, overrides: dict[str, Any] | None = None) -> Scene:
        """Table, robot and world checked and packed for the simulator: ``world`` if given, else the first of
        :attr:`world_files`, else the default one; ``overrides`` are simulator parameters
        (``{"battery": {"charge": 0.5}}``) over the robot file's and the world's."""
        from tablebot.sim.scene import scene_for

        chosen = Path(world) if world is not None else (self.world_files[0] if self.world_files else None)
        return scene_for(self.table, self.machine, chosen, overrides)

    @contextmanager
    def writing(self, force: bool = False) -> Iterator[None]:
        """A call that writes files: none of this robot's own files is ever written over, and a table or robot
        file only with ``force`` (the old one kept as ``NAME.bak``). Inside a command this is the command's
        own rule (:func:`tablebot.overwrite.command`, which knows every file it read)."""
        from tablebot import overwrite

        if overwrite.active():
            yield
            return
        with overwrite.command(force):
            inputs: list[Path] = [self.path, Path(self.robot.source), *self.world_files, *self.property_files]
            for path in inputs:
                if path.is_file():  # (the built-in robot's source names no file)
                    overwrite.read(path)
            yield
