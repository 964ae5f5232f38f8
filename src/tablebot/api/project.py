"""The front door's first step: :func:`open` finds a robot's files (its table, robot file, worlds and
property files) and reads the table once; the :class:`Project` it returns does the rest, each call in a module
of its own (:mod:`.simulation`, :mod:`.checking`, :mod:`.sweeping`, :mod:`.tuning`, :mod:`.evolution`,
:mod:`.exporting`, :mod:`.running`). Opening imports neither the simulator (numba) nor matplotlib nor Dask:
a call imports what it needs."""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

from tablebot.loading import Loaded, PathLike

if TYPE_CHECKING:
    from tablebot.api.checking import Check
    from tablebot.api.evolution import Evolution
    from tablebot.api.progress import Progress
    from tablebot.api.running import Connection, LiveRun
    from tablebot.api.simulation import Simulation
    from tablebot.api.sweeping import Sweep, Traced
    from tablebot.api.tuning import Tuning
    from tablebot.loop import Sink
    from tablebot.registry import Exported

__all__ = ["PathLike", "Project", "open"]


def open(
    path: PathLike,
    *,
    robot: PathLike | None = None,
    worlds: Sequence[PathLike] = (),
    properties: Sequence[PathLike] | None = None,
) -> Project:
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
    ('BumberBot', 37)
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

    def simulate(
        self,
        seconds: float = 120.0,
        seed: int = 1,
        *,
        world: PathLike | None = None,
        battery: float | None = None,
        out: PathLike | None = None,
        plots: bool = True,
        gif: bool = False,
        html: bool = False,
        every_row: bool = False,
        progress: Progress | None = None,
    ) -> Simulation:
        """Simulate the robot (``tablebot sim``): :func:`tablebot.api.simulation.simulate`."""
        from tablebot.api.simulation import simulate

        return simulate(
            self,
            seconds,
            seed,
            world=world,
            battery=battery,
            out=out,
            plots=plots,
            gif=gif,
            html=html,
            every_row=every_row,
            progress=progress,
        )

    def check(self, *, targets: Sequence[str] = (), progress: Progress | None = None) -> Check:
        """Check the table and prove its properties (``tablebot check``): :func:`tablebot.api.checking.check`."""
        from tablebot.api.checking import check

        return check(self, targets=targets, progress=progress)

    def sweep(
        self,
        *,
        robots: int | None = None,
        seeds: str | None = None,
        grid: Sequence[str] = (),
        seconds: float = 60.0,
        backend: str = "auto",
        scheduler: str | None = None,
        workers: int | None = None,
        out: PathLike | None = None,
        plots: bool = True,
        trace: Traced = None,
        progress: Progress | None = None,
    ) -> Sweep:
        """Many simulated robots (``tablebot sweep``): :func:`tablebot.api.sweeping.sweep`."""
        from tablebot.api.sweeping import sweep

        return sweep(
            self,
            robots=robots,
            seeds=seeds,
            grid=grid,
            seconds=seconds,
            backend=backend,
            scheduler=scheduler,
            workers=workers,
            out=out,
            plots=plots,
            trace=trace,
            progress=progress,
        )

    def tune(
        self,
        cells: str,
        *,
        objective: str = "time_to_lamp",
        budget: int = 300,
        method: str = "auto",
        grid: Sequence[str] | None = None,
        seeds: str = "0..15",
        check_seeds: str = "1000..1063",
        seconds: float = 60.0,
        seed: int = 0,
        backend: str = "auto",
        scheduler: str | None = None,
        workers: int | None = None,
        out: PathLike | None = None,
        force: bool = False,
        progress: Progress | None = None,
    ) -> Tuning:
        """Tune timers and counter loads (``tablebot tune``): :func:`tablebot.api.tuning.tune`."""
        from tablebot.api.tuning import tune

        return tune(
            self,
            cells,
            objective=objective,
            budget=budget,
            method=method,
            grid=grid,
            seeds=seeds,
            check_seeds=check_seeds,
            seconds=seconds,
            seed=seed,
            backend=backend,
            scheduler=scheduler,
            workers=workers,
            out=out,
            force=force,
            progress=progress,
        )

    def evolve(
        self,
        *,
        out: PathLike = "out/evolve",
        objective: str | None = None,
        descriptors: str | None = None,
        cells: int = 8,
        budget: int = 200,
        batch: int | None = None,
        seeds: str = "0..15",
        check_seeds: str = "1000..1063",
        grid: Sequence[str] | None = None,
        seconds: float = 60.0,
        max_rows: int | None = None,
        freeze_state: Sequence[str] = (),
        freeze_cell: Sequence[str] = (),
        seed: int = 0,
        backend: str = "auto",
        scheduler: str | None = None,
        workers: int | None = None,
        progress: Progress | None = None,
        table: str | None = None,
    ) -> Evolution:
        """Evolve the table under its properties (``tablebot evolve``; ``table``: which of a robot's several
        tables, default the main one): :func:`tablebot.api.evolution.evolve`."""
        from tablebot.api.evolution import evolve

        return evolve(
            self,
            out=out,
            objective=objective,
            descriptors=descriptors,
            cells=cells,
            budget=budget,
            batch=batch,
            seeds=seeds,
            check_seeds=check_seeds,
            grid=grid,
            seconds=seconds,
            max_rows=max_rows,
            freeze_state=freeze_state,
            freeze_cell=freeze_cell,
            seed=seed,
            backend=backend,
            scheduler=scheduler,
            workers=workers,
            progress=progress,
            table=table,
        )

    def export(
        self,
        to: str,
        out: PathLike | None = None,
        *,
        into: PathLike | None = None,
        lists: Sequence[str] | None = None,
        lookup: str = "auto",
    ) -> Exported:
        """Export the table for another system (``tablebot export``): :func:`tablebot.api.exporting.export`."""
        from tablebot.api.exporting import export

        return export(self, to, out, into=into, lists=lists, lookup=lookup)

    def connect(
        self, on: str, *, link_timeout: float | None = None, behind_limit: float = 0.5, seed: int = 1
    ) -> Connection:
        """A live robot ready to run the table (``tablebot run --on``): :func:`tablebot.api.running.connect`."""
        from tablebot.api.running import connect

        return connect(self, on, link_timeout=link_timeout, behind_limit=behind_limit, seed=seed)

    def run(
        self,
        on: str,
        seconds: float | None = None,
        out: PathLike | None = None,
        *,
        sinks: Sequence[Sink] = (),
        progress: Progress | None = None,
        link_timeout: float | None = None,
        behind_limit: float = 0.5,
        seed: int = 1,
    ) -> LiveRun:
        """Run the table on a live robot or the simulator in real time (``tablebot run``): :meth:`connect`,
        then :meth:`tablebot.api.running.Connection.run`."""
        connection = self.connect(on, link_timeout=link_timeout, behind_limit=behind_limit, seed=seed)
        return connection.run(seconds, out, sinks, progress)
