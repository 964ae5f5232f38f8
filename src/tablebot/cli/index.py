"""The index of tablebot's commands: each command's name, the module that defines it, and its one-line summary.

``tablebot --help`` lists the commands from here, without importing the modules that define them (rich, the
table machinery and each command's own imports cost more than the rest of ``--help`` together); a command's
module is imported when the command runs or its own help is asked for (:class:`Commands`). A new command adds
its line here, in the place ``--help`` lists it (tests/cli/test_cli_index.py checks that every registered command
is in the index and every entry registers its command).
"""

from __future__ import annotations

import importlib
from collections.abc import Callable, Iterator, MutableMapping
from typing import Any, NamedTuple

from tablebot.i18n import N_, Message


class Entry(NamedTuple):
    name: str
    module: str  # under tablebot.cli
    summary: Message  # the line ``tablebot --help`` shows beside the name


COMMANDS: tuple[Entry, ...] = (
    Entry("new", "new", N_("Create a folder for a robot of your own: table, robot file, world, properties.")),
    Entry("sim", "sim", N_("Simulate the robot running a table: its trace and pictures.")),
    Entry("check", "analysis", N_("Check a table: rows that never fire, dead ends, loops, properties.")),
    Entry("tests", "analysis", N_("Generate golden tests that fire every row that can fire.")),
    Entry("diagram", "analysis", N_("Draw the table's state diagram.")),
    Entry("studio", "studio", N_("Edit a table in the browser and watch the robot run it.")),
    Entry("run", "run", N_("Run a table on a real robot, or on the simulator in real time.")),
    Entry("upload", "run", N_("Install an exported TXT 4.0 program on the controller and start it.")),
    Entry("import", "core", N_("Rebuild a table from ROBO Pro lists or an exported statechart.")),
    Entry("trace", "core", N_("Replay recorded inputs through the engine: one JSON line per tick.")),
    Entry("demo", "core", N_("Replay the BumberBot on its built-in recorded inputs.")),
    Entry("export", "export", N_("Export a table for another system: ROBO Pro, C, statecharts.")),
    Entry("build", "firmware", N_("Build firmware (.hex, .elf) that runs the table on a board.")),
    Entry("flash", "firmware", N_("Write the firmware to a board with avrdude.")),
    Entry("monitor", "firmware", N_("Decode a firmware's trace stream into a JSON Lines trace.")),
    Entry("sweep", "sweep", N_("Run a table on many simulated robots: one row per run.")),
    Entry("tune", "tune", N_("Tune a table's timers and counter loads for an objective.")),
    Entry("evolve", "evolve", N_("Evolve a table, keeping only tables that satisfy its properties.")),
    Entry("share", "share", N_("Print a link that carries a robot's table, robot file and world.")),
    Entry("grade", "grade", N_("Grade submitted tables on a challenge and rank them.")),
)
BY_NAME = {entry.name: entry for entry in COMMANDS}


def load_module(name: str) -> None:
    """Import the module that defines command ``name`` (it registers the command on the app)."""
    importlib.import_module(f"tablebot.cli.{BY_NAME[name].module}")


class Commands(MutableMapping[str, Any]):
    """A command group's commands by name, each built when first looked up: its module imported, its click
    command built by ``build`` (typer's, then tablebot's own touches). Iterating gives the names alone (in
    the index's order), so listing the commands imports nothing; ``values()`` and ``items()`` build them all."""

    def __init__(self, built: dict[str, Any], build: Callable[[str], Any]) -> None:
        self._built = dict(built)
        self._build = build

    def __getitem__(self, name: str) -> Any:
        if name not in self._built:
            if name not in BY_NAME:
                raise KeyError(name)
            self._built[name] = self._build(name)
        return self._built[name]

    def __setitem__(self, name: str, command: Any) -> None:
        self._built[name] = command

    def __delitem__(self, name: str) -> None:
        del self._built[name]

    def __iter__(self) -> Iterator[str]:
        yield from (entry.name for entry in COMMANDS)
        yield from (name for name in self._built if name not in BY_NAME)

    def __len__(self) -> int:
        return len(COMMANDS) + sum(name not in BY_NAME for name in self._built)

    def __contains__(self, name: object) -> bool:
        return name in BY_NAME or name in self._built

    def loaded(self, name: str) -> Any | None:
        """The command if it has been built, without building it."""
        return self._built.get(name)
