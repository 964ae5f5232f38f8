"""The front door's first step: :func:`open` finds a robot's files (its table, robot file, worlds and
property files) and reads the table once; the :class:`Project` it returns does the rest, each call in a module
of its own (:mod:`.simulation`, :mod:`.checking`, :mod:`.sweeping`, :mod:`.tuning`, :mod:`.evolution`,
:mod:`.exporting`, :mod:`.running`). Opening imports neither the simulator (numba) nor matplotlib nor Dask:
a call imports what it needs."""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

from tablebot.loading import Loaded, PathLike

if TYPE_CHECKING:
    from tablebot.api.checking import Check
    from tablebot.api.evolution import Evolution
    from tablebot.api.progress import Progress
    from tablebot.api.running import Connection, LiveRun
    from tablebot.api.simulation import Simulation
    from tablebot.api.sweeping import Sweep
    from tablebot.api.tuning import Tuning
    from tablebot.loop import Sink
    from tablebot.registry import Exported

__all__ = ["PathLike", "Project", "open"]


def open(path: PathLike, *, robot: PathLike | None = None, worlds: Sequence[PathLike] = (),
         properties: Sequence[PathLike] | None = None) -> Project:
    """Open a robot: ``path`` is a folder holding ``table.csv`` (or ``table.tsv``), a table file, or a robot
    file (its table is ``NAME.csv`` beside it, else ``table.csv`` there). As the commands find them: the robot
    file is ``robot`` if given, else ``NAME.toml`` or ``robot.toml`` beside the table, else the built-in
    BumberBot; the worlds are ``worlds`` if given, else the robot's ``sim.world``, else ``arena.toml``
    beside the table, else an empty room; the property files are ``properties`` if given, else
    ``NAME.properties.toml`` or ``properties.toml`` beside the table.

    The table and robot file are read now (a mistake is a :class:`~tablebot.diagnostics.TableBotError`
    naming file, line and column); worlds and property files when a call needs them.

    >>> import tablebot
    >>> robot = tablebot.open("examples/bumberbot")
    >>> robot.table.robot.name, len(robot.table.rows)
    ('BumberBot', 36)
    """
    return Project.open(path, robot=robot, worlds=worlds, properties=properties)


class Project(Loaded):
    """A robot opened by :func:`open`: its table (read and compiled) with the files it runs with (see
    :class:`~tablebot.loading.Loaded`: ``table``, ``machine``, ``robot``, ``world_files``,
    ``property_files``, ``worlds``, ``scene()``). Every call below is what the command of its name does, with
    the command's options as keyword arguments; each returns its results as an object (a dataclass) that can
    also write them as the command does.

    >>> import tablebot
    >>> robot = tablebot.open("examples/bumberbot")
    >>> run = robot.simulate(seconds=2, seed=1)
    >>> report = robot.check()
    """

    def simulate(self, seconds: float = 120.0, seed: int = 1, **options: Any) -> Simulation:
        """Simulate the robot (``tablebot sim``); see :func:`tablebot.api.simulation.simulate` for the options."""
        from tablebot.api.simulation import simulate

        return simulate(self, seconds, seed, **options)

    def check(self, **options: Any) -> Check:
        """Check the table and prove its properties (``tablebot check``); see :func:`tablebot.api.checking.check`."""
        from tablebot.api.checking import check

        return check(self, **options)

    def sweep(self, **options: Any) -> Sweep:
        """Many simulated robots (``tablebot sweep``); see :func:`tablebot.api.sweeping.sweep`."""
        from tablebot.api.sweeping import sweep

        return sweep(self, **options)

    def tune(self, cells: str, **options: Any) -> Tuning:
        """Tune timers and counter loads (``tablebot tune``); see :func:`tablebot.api.tuning.tune`."""
        from tablebot.api.tuning import tune

        return tune(self, cells, **options)

    def evolve(self, **options: Any) -> Evolution:
        """Evolve the table under its properties (``tablebot evolve``); see :func:`tablebot.api.evolution.evolve`."""
        from tablebot.api.evolution import evolve

        return evolve(self, **options)

    def export(self, to: str, out: PathLike | None = None, **options: Any) -> Exported:
        """Export the table for another system (``tablebot export``); see :func:`tablebot.api.exporting.export`."""
        from tablebot.api.exporting import export

        return export(self, to, out, **options)

    def connect(self, on: str, **options: Any) -> Connection:
        """A live robot ready to run the table (``tablebot run --on``); see :func:`tablebot.api.running.connect`."""
        from tablebot.api.running import connect

        return connect(self, on, **options)

    def run(self, on: str, seconds: float | None = None, out: PathLike | None = None,
            sinks: Sequence[Sink] = (), progress: Progress | None = None, **options: Any) -> LiveRun:
        """Run the table on a live robot or the simulator in real time (``tablebot run``): :meth:`connect`,
        then :meth:`tablebot.api.running.Connection.run`."""
        return self.connect(on, **options).run(seconds, out, sinks, progress)
