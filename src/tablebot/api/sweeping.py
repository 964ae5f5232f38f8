"""``sweep`` from Python: many simulated robots over worlds x grid values x seeds, one result row per robot
(:class:`Sweep`), in memory or into a folder as ``tablebot sweep`` writes it (resumable)."""

from __future__ import annotations

import csv
import io
import time
from collections.abc import Sequence
from dataclasses import dataclass, field
from functools import cached_property
from pathlib import Path
from typing import TYPE_CHECKING, Any

from tablebot.api.progress import Progress, stopped
from tablebot.i18n import N_

if TYPE_CHECKING:
    import numpy as np

    from tablebot.fleet.backends import Runner
    from tablebot.fleet.plan import Plan
    from tablebot.fleet.run import FleetSummary
    from tablebot.fleet.store import Store
    from tablebot.fleet.work import Job
    from tablebot.loading import Loaded, PathLike

#: What ``--trace`` takes: run numbers as text (``0,17`` or ``0..9``) or as numbers.
Traced = str | Sequence[int] | None


@dataclass(frozen=True, eq=False)
class Sweep:
    """A sweep's runs: :attr:`results` has one numpy record per robot with the columns of ``results.csv``
    (``run``, ``world``, ``seed``, the grid's values, the start, ``reached``, ``collisions``,
    ``distance_m``, time per state, ...; a blank cell, "never", is NaN); :attr:`files` are those written.
    :meth:`save` writes ``results.csv`` and the pictures as ``tablebot sweep`` does.

    >>> import tablebot
    >>> sweep = tablebot.open("examples/bumberbot").sweep(robots=4, seconds=1)
    >>> len(sweep.results), sweep.results["run"].tolist()
    (4, [0, 1, 2, 3])
    """

    plan: Plan
    files: tuple[Path, ...] = ()
    text_in_memory: str | None = None  # results.csv's text, for a sweep that wrote no folder
    wall_s: float = 0.0
    ran: int = 0  # runs made by this call (a resumed sweep took the others from its folder)
    read: list[dict[str, str]] | None = field(default=None, repr=False)  # every row, when read already

    def csv_text(self) -> str:
        """``results.csv``, byte for byte."""
        if self.text_in_memory is not None:
            return self.text_in_memory
        return self.files[0].read_text(encoding="utf-8")

    def rows(self, columns: Sequence[str] | None = None) -> list[dict[str, str]]:
        """The result rows as ``results.csv`` has them: text cells by column name (only ``columns``, if given)."""
        if self.read is None and self.text_in_memory is None:
            from tablebot.fleet.store import read_results

            return read_results(self.files[0], columns)  # only the columns asked for: a third of the time
        rows = self.read if self.read is not None else list(csv.DictReader(io.StringIO(self.csv_text())))
        return rows if columns is None else [{c: row[c] for c in columns} for row in rows]

    @cached_property
    def results(self) -> np.ndarray:
        return _records(self.csv_text())

    def lines(self) -> list[str]:
        """What the sweep amounts to, a line per grid value (or one for all runs): the lamp reached, or
        collisions and distance driven where no world has a lamp."""
        from tablebot.fleet.groups import REPORT_COLUMNS, groups

        lamps = any(world.lamps for world in self.plan.worlds)
        out: list[str] = []
        for key, values in groups(self.plan, self.rows(REPORT_COLUMNS)):
            for label, chosen in values:
                name = N_("all runs") if key == "all runs" else f"{key} {label}"
                if lamps:
                    line = N_(
                        "{reached}/{runs} reached the lamp",
                        reached=sum(int(r["reached"]) for r in chosen),
                        runs=len(chosen),
                    )
                else:
                    collisions = sum(int(r["collisions"]) for r in chosen) / max(1, len(chosen))
                    metres = sum(float(r["distance_m"]) for r in chosen) / max(1, len(chosen))
                    line = N_(
                        "{runs} runs, {collisions:.1f} collisions and {metres:.2f} m driven a run",
                        runs=len(chosen),
                        collisions=collisions,
                        metres=metres,
                    )
                out.append(N_("{name}: {result}", name=name, result=line))
        return out

    def save(self, folder: PathLike, *, plots: bool = True, trace: Traced = None) -> list[Path]:
        """``results.csv`` in ``folder`` (with ``plots`` ``outcomes.png``, ``starts.png``, ``best.png``,
        ``worst.png``; the runs ``trace`` names as ``trace-RUN.jsonl``), replacing an earlier sweep's at once."""
        from tablebot.files import out_folder, write_text
        from tablebot.fileset import file_set

        folder = out_folder(Path(folder), "--out")
        traced = trace_runs(trace, self.plan.spec.total)
        with file_set(folder, remove=["results.partial.csv"]):
            path = write_text(folder / "results.csv", self.csv_text())
            return [path, *_extras(self.plan, traced, folder, plots, self.rows() if plots else [])]


def sweep(
    project: Loaded,
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
    """Run the table on many simulated robots (``tablebot sweep``): every world of the project x every
    combination of ``grid`` values (``["battery=1.0,0.6", "start=random"]``) x every seed (``robots``: seeds
    0..N-1, or ``seeds``: ``"0..999"``), ``seconds`` each, on this machine's cores (``workers`` threads) or a
    Dask cluster (``backend="dask"``, ``scheduler``). Without ``out`` the results stay in memory; with ``out``
    each finished chunk is written at once and the sweep resumes there (Ctrl-C raises
    :class:`~tablebot.api.progress.Stopped` after keeping them), then ``results.csv``, the ``trace`` runs and
    (``plots``) the pictures replace an earlier sweep's."""
    from tablebot.fleet.backends import Runner, choose

    shown = progress or Progress()
    chosen, address = choose(backend, scheduler)
    with Runner(chosen, address, workers) as runner:
        plan = _start(project, runner, grid, seeds, robots, seconds, plots and out is not None)
        traced = trace_runs(trace, plan.spec.total)
        if out is None:
            return _in_memory(plan, runner, chosen, shown)
        with project.writing():
            store, ran, wall_s = _into(plan, runner, chosen, Path(out), shown)
    with project.writing():
        return _finish(plan, store, traced, plots, wall_s, ran)


def _start(
    project: Loaded,
    runner: Runner,
    grid: Sequence[str],
    seeds: str | None,
    robots: int | None,
    seconds: float,
    pictures: bool,
) -> Plan:
    """The fleet's modules imported and the sweep planned, while a cluster's workers start up or this process's
    compiled code loads on a thread (:meth:`Runner.load_compiled`, started as soon as the kernel's modules are
    imported); the robot's tables as ``project`` read them."""
    runner.start(imported=False)  # a cluster's workers start up while this process imports and plans
    runner.load_compiled()  # locally: the kernel's machine code loads on a thread while the rest imports and plans
    from tablebot.fleet.plan import make_plan

    if pictures:  # before the run (an interrupt never lands in matplotlib's import)
        import tablebot.fleet.plots  # noqa: F401
    runner.imported()  # this process's compiled code is sent to them, or loaded here, while it plans
    return make_plan(
        project.path,
        project.robot_file,
        project.world_files,
        grid,
        seeds,
        robots,
        seconds,
        every_table=True,
        grid_cells=True,
        read=(project.table, project.tables),
    )


def trace_runs(runs: Traced, total: int) -> list[int]:
    """The run numbers of ``--trace`` (text as ``--seeds`` reads numbers), each one of the sweep's runs."""
    from tablebot.diagnostics import TableBotError, fail
    from tablebot.fleet.spec import parse_seeds

    if runs is None:
        return []
    if isinstance(runs, str):
        try:
            runs = parse_seeds(runs, None, "--trace")
        except TableBotError as exc:  # the words of --seeds, with a hint about run numbers
            raise fail("--trace", exc.diagnostics[0].message, N_("give run numbers: 0,17 or 0..9")) from None
    beyond = [k for k in runs if not 0 <= k < total]
    if beyond:
        raise fail(
            "--trace",
            N_("--trace {run}: the sweep has runs 0..{last}", run=beyond[0], last=total - 1),
            N_("give run numbers it has"),
        )
    return list(runs)


def _compiling(progress: Progress, backend: str, jobs: Sequence[Job]) -> None:
    if backend == "local" and jobs:
        from tablebot.fleet.kernel import run_fleet, run_fleet_serial

        progress.compiling(
            N_("the fleet simulator"),  # one job: the threaded kernel
            run_fleet if len(jobs) == 1 else run_fleet_serial,
        )


def _in_memory(plan: Plan, runner: Runner, backend: str, progress: Progress) -> Sweep:
    from tablebot.fleet.store import csv_text

    jobs = plan.jobs()
    parts: dict[int, str] = {}
    _compiling(progress, backend, jobs)
    started = time.perf_counter()
    progress.start("robots", plan.spec.total, 0, plan.spec.ticks)
    try:

        def done(job: Job, summary: FleetSummary) -> None:
            parts[job.first] = plan.part_text(job, summary).partition("\n")[2]  # its rows, below its header
            progress.advance(len(summary))

        runner.run(jobs, done)
    finally:
        progress.stop()
    text = csv_text(plan.columns(), []) + "".join(parts[first] for first in sorted(parts))
    return Sweep(plan, (), text, time.perf_counter() - started, plan.spec.total)


def _into(plan: Plan, runner: Runner, backend: str, out: Path, progress: Progress) -> tuple[Store, int, float]:
    """The runs not in ``out`` yet, each finished chunk written there at once: the store, the runs made and
    how long they took. Ctrl-C merges the finished chunks into results.partial.csv and raises Stopped."""
    from tablebot.files import out_folder
    from tablebot.fleet.store import Store
    from tablebot.interrupts import INTERRUPTS

    out_folder(out, "--out")
    store = Store(out, plan.spec, plan.columns())
    finished = store.open()
    jobs = plan.jobs(skip=finished)
    total, already = plan.spec.total, sum(b - a for a, b in finished)
    _compiling(progress, backend, jobs)
    started = time.perf_counter()
    progress.start("robots", total, already, plan.spec.ticks)
    try:

        def done(job: Job, summary: FleetSummary) -> None:
            store.write_part(job, plan.part_text(job, summary))
            progress.advance(len(summary))

        runner.run(jobs, done)
    except INTERRUPTS as exc:
        runner.close(failed=True)
        path, count = store.merge(complete=False)
        raise stopped(
            N_("{count:,} of {total:,} runs finished, kept in {path}", count=count, total=total, path=path), exc
        ) from None
    finally:
        progress.stop()
    return store, total - already, time.perf_counter() - started


def _finish(plan: Plan, store: Store, traced: list[int], plots: bool, wall_s: float, ran: int) -> Sweep:
    """results.csv merged from the parts, the traced runs and the pictures: all at once."""
    from tablebot.fileset import current, file_set
    from tablebot.fleet.store import read_results

    out = store.folder
    with file_set(out, remove=["results.partial.csv"]):
        path, _ = store.merge(complete=True)
        rows = read_results(current(path)) if plots else []  # the pictures read every column
        written = [path, *_extras(plan, traced, out, plots, rows)]
    return Sweep(plan, tuple(written), None, wall_s, ran, rows or None)


def _extras(plan: Plan, traced: list[int], folder: Path, plots: bool, rows: list[dict[str, str]]) -> list[Path]:
    written = plan.write_traces(traced, folder)
    if plots:
        from tablebot.fleet.plots import write_all

        written += write_all(plan, rows, folder)
    return written


def _records(text: str) -> np.ndarray:
    """CSV text as one numpy record per row: a column of whole numbers as int64, of numbers (blank: NaN)
    as float64, else text."""
    import numpy as np

    reader = csv.reader(io.StringIO(text))
    header = next(reader)
    columns = list(zip(*reader, strict=True)) or [() for _ in header]
    arrays: list[tuple[str, Any]] = [(name, _column(values)) for name, values in zip(header, columns, strict=True)]
    out = np.zeros(len(columns[0]) if header else 0, dtype=[(name, values.dtype) for name, values in arrays])
    for name, values in arrays:
        out[name] = values
    return out


def _column(cells: Sequence[str]) -> np.ndarray:
    import numpy as np

    try:
        return np.array([int(c) for c in cells], dtype=np.int64)
    except ValueError:
        pass
    try:
        return np.array([float(c) if c else np.nan for c in cells], dtype=np.float64)
    except ValueError:
        return np.array(cells, dtype=str)
