"""Internal: a robot's files found and read the one way every part of tablebot finds them -- its table, robot
file, worlds and property files -- and what is made of them: the simulator's scene, the check of the table.
The front door (:mod:`tablebot.api`, above the studio) and the studio (:mod:`tablebot.web`, which edits a
table it has not saved) both start here. Nothing here imports the simulator (numba), matplotlib or Dask until
a call needs it."""

from __future__ import annotations

import os
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass
from functools import cached_property
from pathlib import Path
from typing import TYPE_CHECKING, Any, TypeVar

from tablebot.diagnostics import fail
from tablebot.i18n import N_, Message

if TYPE_CHECKING:
    from tablebot.analysis.check import CheckReport
    from tablebot.analysis.properties import Property
    from tablebot.machine import Machine
    from tablebot.robot import Robot
    from tablebot.sim.model.scene import Scene
    from tablebot.sim.model.world import World
    from tablebot.table import Table
    from tablebot.tables import RobotTables

#: A file or folder name, as the front door takes them.
PathLike = str | os.PathLike[str]
TABLE_NAMES = ("table.csv", "table.tsv")
L = TypeVar("L", bound="Loaded")


def robot_for(table_path: Path) -> Robot:
    """The robot a table file runs on: its side file (``NAME.toml``, else ``robot.toml`` beside it), else the
    built-in BumberBot."""
    from tablebot.robot import BUMBERBOT, find_robot_file, load_robot

    side = find_robot_file(table_path)
    return load_robot(side) if side else BUMBERBOT


def property_files(table_path: Path) -> list[Path]:
    """The property files beside a table (``NAME.properties.toml``, else ``properties.toml``), if any."""
    from tablebot.analysis.properties import find_property_files

    return find_property_files(table_path)


def table_path(given: Path) -> Path:
    """The table a path names: a folder's ``table.csv`` (or ``.tsv``); a robot file's ``NAME.csv`` (or
    ``.tsv``) beside it, else ``table.csv`` there; else the path itself."""
    from tablebot.formats.table_read import resolve_table_path

    if given.suffix.lower() != ".toml":
        return resolve_table_path(given)
    if not given.is_file():
        raise fail(given, N_("no such robot file"), N_("give a folder, a table file or a robot file that exists"))
    candidates = [given.with_suffix(".csv"), given.with_suffix(".tsv"), *(given.parent / n for n in TABLE_NAMES)]
    for candidate in candidates:
        if candidate.is_file():
            return candidate
    raise fail(
        given,
        N_("no table beside this robot file ({names})", names=tuple(c.name for c in candidates[:3])),
        N_("give the table file itself, with robot= naming this file"),
    )


@dataclass(frozen=True, eq=False)
class Loaded:
    """A robot's table (read and compiled) with the files it runs with. ``table`` is the parsed table
    (``table.robot`` its robot file's contents, ``table.path`` its file), ``machine`` the compiled one;
    ``world_files`` and ``property_files`` are the files given or found, ``robot_file`` the robot file given
    (None: the one beside the table, or the built-in BumberBot)."""

    table: Table
    machine: Machine
    world_files: tuple[Path, ...] = ()
    property_files: tuple[Path, ...] = ()
    robot_file: Path | None = None
    #: A robot of several tables (``[tables]``): all of them, ``table`` the main one (:mod:`tablebot.tables`).
    tables: RobotTables | None = None

    @classmethod
    def open(
        cls: type[L],
        path: PathLike,
        *,
        robot: PathLike | None = None,
        worlds: Sequence[PathLike] = (),
        properties: Sequence[PathLike] | None = None,
    ) -> L:
        """Find and read a robot's files (see :func:`tablebot.api.project.open`)."""
        from tablebot.formats.table_read import load_table
        from tablebot.machine import compile_table
        from tablebot.robot import load_robot
        from tablebot.tables import several

        given = Path(path)
        robot_file = Path(robot) if robot is not None else given if given.suffix.lower() == ".toml" else None
        robot_read = load_robot(robot_file) if robot_file is not None else None  # first, as every command reads it
        found = table_path(given)
        table = load_table(found, robot_read)
        tables = several(table)  # every table of the robot, checked together; the main one is the robot's table
        if tables is not None:
            table = tables.table
        props = property_files(found) if properties is None else [Path(p) for p in properties]
        return cls(table, compile_table(table), tuple(Path(w) for w in worlds), tuple(props), robot_file, tables)

    @classmethod
    def of(cls: type[L], table: Table, machine: Machine) -> L:
        """A table read from elsewhere (the studio's editor), with the property files beside its path."""
        return cls(table, machine, property_files=tuple(property_files(Path(table.path))))

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
        """The worlds it runs in: those given, else its default one (read on first use)."""
        from tablebot.sim.model.world import load_world

        if self.world_files:
            return tuple(load_world(path) for path in self.world_files)
        return (self.default_world(),)

    def robot_world(self) -> Path | None:
        """The world the robot file names (``[sim] world``), if it names one."""
        from tablebot.sim.model.scene import robot_layer

        return robot_layer(self.robot)[1]

    def default_world(self) -> World:
        """The robot's ``sim.world``, else ``arena.toml`` beside the table, else an empty room."""
        from tablebot.sim.model.scene import find_world

        return find_world(self.table, None, self.robot_world())

    def scene(
        self, world: PathLike | World | None = None, overrides: dict[str, Any] | None = None, every_table: bool = True
    ) -> Scene:
        """Table, robot and world checked and packed for the simulator: ``world`` (a file, or a world already
        read) if given, else the first of :attr:`world_files`, else the default one; ``overrides`` are
        simulator parameters (``{"battery": {"charge": 0.5}}``) over the robot file's and the world's.
        A robot of several tables is simulated whole, as every command runs it; ``every_table=False`` runs its
        main table alone, with a note saying so (the other tables' lamps stay dark)."""
        from tablebot.sim.model.scene import prepare, robot_layer, scene_for
        from tablebot.sim.model.world import World

        tables = self.tables if every_table else None
        if self.tables is not None and tables is None:  # said, not hidden: the other tables' lamps stay dark
            self._main_table_only(N_("the simulator"))
        if isinstance(world, World):
            return prepare(self.table, self.machine, world, robot_layer(self.robot)[0], overrides, tables)
        chosen = Path(world) if world is not None else (self.world_files[0] if self.world_files else None)
        return scene_for(self.table, self.machine, chosen, overrides, tables)

    def _main_table_only(self, what: Message) -> None:
        """A note that ``what`` runs only the main table of a robot of several (the others not yet)."""
        from tablebot.diagnostics import Diagnostic, notify

        assert self.tables is not None
        others = ", ".join(self.tables.names[1:])
        robot = self.robot
        notify(
            Diagnostic(
                robot.source,
                robot.line("tables"),
                1,
                N_(
                    "{what} runs the main table ({main}) only so far, not {others}: the outputs only they write "
                    "stay at 0",
                    what=what,
                    main=self.tables.names[0],
                    others=others,
                ),
                N_("tablebot trace, check and diagram run every table (docs/engine.md, Several tables)"),
                "note",
            )
        )

    def properties(self) -> list[Property]:
        """The robot file's ``[properties]`` and those of :attr:`property_files`, read and checked."""
        from tablebot.analysis.properties import load_properties

        return load_properties(self.machine, list(self.property_files), self.tables)

    def check_report(
        self,
        targets: Sequence[str] = (),
        step: Callable[[str], None] = lambda what: None,
        properties: list[Property] | None = None,
    ) -> CheckReport:
        """``check``'s exploration, findings and proofs of :meth:`properties` (or ``properties``, read
        already); ``targets``: export targets whose limits to check too; ``step`` is told what starts next."""
        from tablebot.analysis.check import run_check
        from tablebot.analysis.check_tables import run_check_tables

        props = self.properties() if properties is None else properties
        report = (
            run_check_tables(self.tables, props, tuple(targets), step)
            if self.tables is not None
            else run_check(self.machine, props, tuple(targets), step)
        )
        report.property_files = list(self.property_files)
        return report

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
