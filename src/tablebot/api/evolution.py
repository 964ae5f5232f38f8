"""``evolve`` from Python: the computer writes the table, under the robot's proved properties, on the fleet
(:class:`Evolution`): a quality-diversity archive of tables that behave differently, written into a folder as
``tablebot evolve`` writes it, resumable."""

from __future__ import annotations

import time
from collections.abc import Sequence
from dataclasses import dataclass, replace
from pathlib import Path
from typing import TYPE_CHECKING, Any

from tablebot.api.progress import Progress, stopped
from tablebot.i18n import N_, _, ngettext

if TYPE_CHECKING:
    from tablebot.evolve.run import Outcome
    from tablebot.fleet.plan import Plan
    from tablebot.loading import Loaded, PathLike


@dataclass(frozen=True)
class Setup:
    """The checked options: the search's settings, what may change, the property files, the measures kept."""

    settings: Any  # tablebot.evolve.run.Settings
    space: Any  # tablebot.evolve.operators.Space
    files: list[Path]
    names: list[str]
    replay: Any = None  # tablebot.evolve.report.Replay: what the report's commands need
    whole: Any = None  # tablebot.evolve.whole.Whole: a robot of several tables, the table evolved (None: one table)

    @property
    def base(self) -> Any:
        """The table evolved (of several, the one ``--table`` names)."""
        return self.whole.table if self.whole is not None else None


@dataclass(frozen=True, eq=False)
class Evolution:
    """An evolution's outcome (:attr:`outcome`: its archive, every candidate and its means, what the search
    did in :attr:`~tablebot.evolve.run.Outcome.counts`), the :attr:`plan` of scenarios every table ran and
    the :attr:`files` written (the best tables, ``report.md``, ``archive.png``, the run's records).

    >>> import tablebot
    >>> robot = tablebot.open("examples/bumberbot")
    >>> evolved = robot.evolve(out="out/evolve-doc", budget=2, batch=1, seeds="0..1", check_seeds="9..10",
    ...                        seconds=1, workers=1)
    >>> "report.md" in [p.name for p in evolved.files], evolved.outcome.order[0] == evolved.outcome.start_key
    (True, True)
    """

    outcome: Outcome
    plan: Plan
    files: tuple[Path, ...]
    wall_s: float

    def report_text(self) -> str:
        """``report.md``, as written."""
        return next(p for p in self.files if p.name == "report.md").read_text(encoding="utf-8")


def evolve(
    project: Loaded,
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
    """Evolve the table (``tablebot evolve``, each keyword its option): change its motor cells, timers and next
    states, add, remove and reorder rows, keep only tables that satisfy every property of the robot (the
    project's property files; proved by ``check``), run them on the fleet over the project's worlds x ``grid``
    x ``seeds``, and keep an archive of the best tables that behave differently, in ``out`` (a folder of its
    own: the same call again resumes there; Ctrl-C raises :class:`~tablebot.api.progress.Stopped`). A robot of
    several tables evolves the one ``table`` names (default: the main one) beside the others as they are: each
    candidate is proved and run with them, and only that table's files are written (``NAME.best-1.csv``)."""
    from tablebot.diagnostics import fail
    from tablebot.evolve.whole import choose as chosen_table
    from tablebot.files import out_folder
    from tablebot.fleet.backends import choose
    from tablebot.fleet.plan import make_plan
    from tablebot.fleet.spec import parse_seeds

    folder = Path(out)
    chosen, address = choose(backend, scheduler)
    scenarios = list(grid or ["start=random"])
    plan = make_plan(
        project.path, project.robot_file, project.world_files, scenarios, seeds, None, seconds, every_table=True
    )  # a robot of several tables runs whole; one of them evolves
    whole = chosen_table(plan.tables, table)
    check = replace(plan, spec=replace(plan.spec, seeds=parse_seeds(check_seeds, None, "--check-seeds")))
    if batch is not None and batch > budget:
        raise fail(
            "--batch",
            N_("--batch {batch} is more than --budget {budget}", batch=batch, budget=budget),
            N_("give a --batch up to the budget"),
        )
    batch = batch or 16  # a budget below it takes what it has room for (the batch stays one, for resuming)
    setup = _setup(
        plan,
        objective,
        descriptors,
        cells,
        budget,
        batch,
        seed,
        max_rows,
        list(freeze_state),
        list(freeze_cell),
        list(project.property_files),
        whole,
    )
    setup = replace(setup, replay=_replay(plan, seeds, scenarios, folder))
    _own_folder(folder, plan, setup.files)
    out_folder(folder, "--out")
    with project.writing():
        return _run(plan, check, setup, folder, chosen, address, workers, progress or Progress())


def _setup(
    plan: Plan,
    objective: str | None,
    descriptors: str | None,
    cells: int,
    budget: int,
    batch: int,
    seed: int,
    max_rows: int | None,
    freeze_state: list[str],
    freeze_cell: list[str],
    files: list[Path],
    whole: Any = None,
) -> Setup:
    """Every option checked against the table and its worlds, before anything is written (of several tables,
    the table evolved: ``whole``)."""
    from tablebot.diagnostics import fail
    from tablebot.evolve import measures, space
    from tablebot.evolve.operators import Space
    from tablebot.evolve.proofs import Prover, refuse_fixed, refuse_line_conditions
    from tablebot.evolve.run import Settings

    base = whole.table if whole is not None else plan.table
    seconds = plan.spec.ticks * plan.scenes[0].tick_s
    measure = measures.check_objective(objective or measures.default_objective(plan.worlds), plan.worlds)
    text = measures.default_descriptors(plan.worlds) if descriptors is None else descriptors
    chosen = measures.parse_descriptors(text, plan.worlds, plan.table.states, seconds, cells)  # the fleet counts
    # the main table's states
    rows = max_rows or space.default_max_rows(base)
    if rows < len(base.rows):
        raise fail(
            "--max-rows",
            N_("--max-rows {rows} is fewer than the {n} rows the table starts with", rows=rows, n=len(base.rows)),
            N_("give --max-rows {n} or more", n=len(base.rows)),
        )
    limits = space.Limits(
        rows,
        space.parse_freeze_states(freeze_state, base),
        space.parse_freeze_cells(freeze_cell, base),
        space.default_timer_max(base),
    )
    prover = Prover(files, whole=whole)
    refuse_line_conditions(prover, plan.machine if whole is None else whole.tables.machines[whole.index])
    if whole is not None:
        refuse_fixed(whole, prover)
    names = [n for n in measures.allowed(plan.worlds) if n != "lamp_distance" or n == measure.name]
    names += [d.name for d in chosen if d.name not in names]
    settings = Settings(measure, tuple(chosen), budget, batch, seed)
    writes = frozenset(base.writes) if whole is not None else None  # one table of several: its own columns
    searched = Space(base.states, base.robot.motors, limits, writes, base.robot.lamps)
    return Setup(settings, searched, files, names, whole=whole)


def _own_folder(out: Path, plan: Plan, properties: list[Path]) -> None:
    """--out must not be a folder the run reads from: its tables, reports and records would lie among the
    robot's own files (and a table named best-1.csv there would be a user's)."""
    from tablebot.diagnostics import fail

    tables = plan.tables.tables if plan.tables is not None else (plan.table,)
    inputs = [*(Path(t.path) for t in tables), *(Path(w) for w in plan.spec.worlds if w), *properties]
    if plan.table.robot.source:
        inputs.append(Path(plan.table.robot.source))
    here = out.resolve()
    for path in inputs:
        if path.is_file() and path.resolve().parent == here:
            raise fail(
                "--out",
                N_(
                    "--out {out} is the folder of {name}, which evolve reads: its tables, reports and "
                    "records would lie among the robot's own files",
                    out=str(out),
                    name=path.name,
                ),
                N_("give --out a folder of its own, such as out/evolve"),
            )


def _replay(plan: Plan, seeds: str, grid: list[str], out: Path) -> Any:
    from tablebot.evolve.report import Replay

    return Replay(
        plan.table.robot.source,
        tuple(map(str, plan.spec.worlds)),
        plan.spec.ticks * plan.scenes[0].tick_s,
        seeds,
        tuple(grid),
        out,
    )


def _spec(plan: Plan, setup: Setup) -> dict[str, Any]:
    """What makes two runs the same run (a resumed one must be): the scenarios, properties and options."""
    from tablebot.fleet.spec import digest

    s, limits = setup.settings, setup.space.limits
    return {
        "scenarios": plan.spec.to_json(),
        "properties": {str(f): digest(Path(f)) for f in setup.files},
        "objective": s.objective.name,
        "descriptors": [[d.name, d.low, d.high, d.cells] for d in s.descriptors],
        "batch": s.batch,
        "seed": s.seed,
        "max_rows": limits.max_rows,
        "frozen_states": sorted(map(str, limits.frozen_states)),
        "frozen_cells": sorted(f"{line} {col}" for line, col in limits.frozen_cells),
        "timer_max": limits.timer_max,
        **({"table": setup.whole.name} if setup.whole is not None else {}),
    }


def _run(
    plan: Plan,
    check: Plan,
    setup: Setup,
    out: Path,
    backend: str,
    address: str | None,
    workers: int | None,
    progress: Progress,
) -> Evolution:
    from tablebot.evolve.evaluate import Evaluator
    from tablebot.evolve.pool import Workers
    from tablebot.evolve.proofs import Prover
    from tablebot.evolve.run import Evolution as Search
    from tablebot.evolve.run import Store
    from tablebot.fleet.backends import Runner
    from tablebot.interrupts import INTERRUPTS

    settings = setup.settings
    store = Store(out, _spec(plan, setup))
    prover = Prover(setup.files, store.proofs, whole=setup.whole)
    base = setup.base or plan.table
    started = time.perf_counter()
    search = None
    progress.start("tables", settings.budget)
    try:
        with Workers(setup.files, base, workers, setup.whole) as provers, Runner(backend, address, workers) as runner:
            evaluator = Evaluator(plan, runner, setup.names, evolved=setup.whole.index if setup.whole else 0)
            search = Search(
                base,
                setup.space,
                settings,
                prover,
                evaluator,
                store,
                provers,
                on_eval=progress.advance,
                on_repair=lambda repairs: _said_repairs(repairs, progress),
            )
            outcome = search.run()
            progress.stop()
            from tablebot.evolve.outputs import write_all  # after the run: it imports pyribs, which the run does

            written = write_all(
                outcome, settings, base, prover, evaluator, check, out, setup.names, setup.replay, provers
            )
    except INTERRUPTS as exc:  # SIGTERM raises Terminated while a command runs (cli.common.guarded)
        kept = len(search.store.open()) if search else 0
        raise stopped(N_("{kept} tables evaluated so far are kept in {out}", kept=kept, out=out), exc) from None
    finally:
        progress.stop()
    return Evolution(outcome, plan, tuple(written), time.perf_counter() - started)


def _said_repairs(repairs: list[Any], progress: Progress) -> None:
    for k, r in enumerate(repairs):
        state = _("mended it") if r.ok else _("could not mend {failing}").format(failing=", ".join(r.failing))
        progress.note(
            ngettext(
                "repair {k}: the starting table breaks a property; {n} guard row {state}",
                "repair {k}: the starting table breaks a property; {n} guard rows {state}",
                len(r.steps),
            ).format(k=k + 1, n=len(r.steps), state=state)
        )
