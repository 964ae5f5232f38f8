"""The ``evolve`` command: the computer writes the table, under the robot's proved properties, on the fleet;
a quality-diversity archive of tables that behave differently, written as tables with a report."""

from __future__ import annotations

import time
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import typer

from tablebot.cli.app import app
from tablebot.cli.common import ROBOT_OPT, TABLE_ARG, console, err_console, guarded, out_folder
from tablebot.cli.sweep import BACKEND_OPT, SCHEDULER_OPT, WORLD_OPT, Bar

EVOLVE_WORKERS_OPT = typer.Option(None, "--workers", min=1, help="Local worker threads for the fleet, and prover "
                                  "processes (default: one per core; 1 proves in this process).")


@dataclass(frozen=True)
class Setup:
    """The checked options: the search's settings, what may change, the property files, the measures kept."""

    settings: Any  # tablebot.evolve.run.Settings (imported when the command runs: --help stays quick)
    space: Any  # tablebot.evolve.operators.Space
    files: list[Path]
    names: list[str]
    replay: Any = None  # tablebot.evolve.report.Replay: what the report's commands need


@app.command("evolve")
@guarded
def evolve_cmd(
    table: Path = TABLE_ARG,
    out: Path = typer.Option(Path("out/evolve"), "--out", help="Folder for the tables, report.md, archive.png and "
                             "the run's records (the same command again resumes from them)."),
    world: list[Path] | None = WORLD_OPT,
    objective: str | None = typer.Option(None, "--objective", help="What to make best (a mean over the scenarios): "
                                         "time_to_lamp, time_to_light, missed_lamp, lamp_distance, collisions, "
                                         "collision_share, distance, area_covered or laps, as the worlds allow "
                                         "(default: time_to_lamp with a lamp, else laps with a closed line)."),
    descriptors: str | None = typer.Option(None, "--descriptors", help='One or two behaviour descriptors for the '
                                           'archive, each with an optional range: "collision_share,'
                                           'area_covered=0..0.5"; also state_share:STATE (default: area_covered,'
                                           'collision_share).'),
    cells: int = typer.Option(8, "--cells", min=2, max=100, help="Archive cells per descriptor."),
    budget: int = typer.Option(200, "--budget", min=1, help="Most tables to run on the fleet (the start included)."),
    batch: int | None = typer.Option(None, "--batch", min=1, help="Tables asked for per generation "
                                     "(default: 16; a last generation takes what the budget has room for)."),
    seeds: str = typer.Option("0..15", "--seeds", help="Seeds of the scenarios every table runs."),
    check_seeds: str = typer.Option("1000..1063", "--check-seeds", help="Fresh seeds for the before/after report."),
    grid: list[str] | None = typer.Option(None, "--grid", help='Scenario grid as in sweep (default: "start=random").'),
    seconds: float = typer.Option(60.0, "--seconds", min=0.01, max=3600, help="Simulated time of each run."),
    max_rows: int | None = typer.Option(None, "--max-rows", min=1, help="Most rows a table may have (default: half "
                                        "as many again as the start, at least 8 more)."),
    freeze_state: list[str] | None = typer.Option(None, "--freeze-state", help="States whose rows stay exactly as "
                                                  "they are: 20,21 (repeat or comma-separate)."),
    freeze_cell: list[str] | None = typer.Option(None, "--freeze-cell", help='Cells that never change: "line 5 '
                                                 'timer", "line 5 M1", "line 5 next", or "line 5" for the whole '
                                                 'row (file lines; the row is then never removed or moved).'),
    properties: list[Path] | None = typer.Option(None, "--properties", help="Property files every kept table must "
                                                 "satisfy (instead of those beside the table; the robot file's "
                                                 "[properties] always count)."),
    seed: int = typer.Option(0, "--seed", min=0, help="Seed of the search itself."),
    backend: str = BACKEND_OPT,
    scheduler: str | None = SCHEDULER_OPT,
    workers: int | None = EVOLVE_WORKERS_OPT,
    quiet: bool = typer.Option(False, "--quiet", "-q", help="No progress bar and no report on the terminal."),
    robot: Path | None = ROBOT_OPT,
) -> None:
    """Evolve TABLE: change its motor cells, timers and next states, add, remove and reorder rows, keep only
    tables that satisfy every property of the robot (proved by check), run them on the fleet, and keep an
    archive of the best tables that behave differently. Ctrl-C keeps what was run; the same command resumes."""
    from tablebot.diagnostics import fail
    from tablebot.fleet.backends import choose
    from tablebot.fleet.plan import make_plan
    from tablebot.fleet.spec import parse_seeds

    chosen, address = choose(backend, scheduler)
    plan = make_plan(table, robot, world or [], grid or ["start=random"], seeds, None, seconds)
    check = replace(plan, spec=replace(plan.spec, seeds=parse_seeds(check_seeds, None, "--check-seeds")))
    if batch is not None and batch > budget:
        raise fail("--batch", f"--batch {batch} is more than --budget {budget}", "give a --batch up to the budget")
    batch = batch or 16  # a budget below it takes what it has room for (the batch stays one, for resuming)
    setup = _setup(plan, objective, descriptors, cells, budget, batch, seed, max_rows, freeze_state or [],
                   freeze_cell or [], properties)
    setup = replace(setup, replay=_replay(plan, seeds, grid or ["start=random"], out))
    _own_folder(out, plan, setup.files)
    out_folder(out, "--out")
    _run(plan, check, setup, out, chosen, address, workers, quiet)


def _setup(plan: Any, objective: str | None, descriptors: str | None, cells: int, budget: int, batch: int, seed: int,
           max_rows: int | None, freeze_state: list[str], freeze_cell: list[str],
           properties: list[Path] | None) -> Setup:
    """Every option checked against the table and its worlds, before anything is written."""
    from tablebot.analysis.properties import find_property_files
    from tablebot.diagnostics import fail
    from tablebot.evolve import measures, space
    from tablebot.evolve.operators import Space
    from tablebot.evolve.proofs import Prover, refuse_line_conditions
    from tablebot.evolve.run import Settings

    base = plan.table
    seconds = plan.spec.ticks * plan.scenes[0].tick_s
    measure = measures.check_objective(objective or measures.default_objective(plan.worlds), plan.worlds)
    text = measures.default_descriptors(plan.worlds) if descriptors is None else descriptors
    chosen = measures.parse_descriptors(text, plan.worlds,
                                        base.states, seconds, cells)
    rows = max_rows or space.default_max_rows(base)
    if rows < len(base.rows):
        raise fail("--max-rows", f"--max-rows {rows} is fewer than the {len(base.rows)} rows the table starts with",
                   f"give --max-rows {len(base.rows)} or more")
    limits = space.Limits(rows, space.parse_freeze_states(freeze_state, base), space.parse_freeze_cells(freeze_cell,
                          base), space.default_timer_max(base))
    files = list(properties) if properties is not None else find_property_files(Path(base.path))
    prover = Prover(files)
    refuse_line_conditions(prover, plan.machine)
    names = [n for n in measures.allowed(plan.worlds) if n != "lamp_distance" or n == measure.name]
    names += [d.name for d in chosen if d.name not in names]
    settings = Settings(measure, tuple(chosen), budget, batch, seed)
    return Setup(settings, Space(base.states, base.robot.motors, limits), files, names)


def _own_folder(out: Path, plan: Any, properties: list[Path]) -> None:
    """--out must not be a folder the run reads from: its tables, reports and records would lie among the
    robot's own files (and a table named best-1.csv there would be a user's)."""
    from tablebot.diagnostics import fail

    inputs = [Path(plan.table.path), *(Path(w) for w in plan.spec.worlds if w), *properties]
    if plan.table.robot.source:
        inputs.append(Path(plan.table.robot.source))
    here = out.resolve()
    for path in inputs:
        if path.is_file() and path.resolve().parent == here:
            raise fail("--out", f"--out {out} is the folder of {path.name}, which evolve reads: its tables, reports "
                       "and records would lie among the robot's own files", "give --out a folder of its own, such as "
                       "out/evolve")


def _replay(plan: Any, seeds: str, grid: list[str], out: Path) -> Any:
    from tablebot.evolve.report import Replay

    return Replay(plan.table.robot.source, tuple(map(str, plan.spec.worlds)), plan.spec.ticks * plan.scenes[0].tick_s,
                  seeds, tuple(grid), out)


def _spec(plan: Any, setup: Setup) -> dict[str, Any]:
    """What makes two runs the same run (a resumed one must be): the scenarios, properties and options."""
    from tablebot.fleet.spec import digest

    s, limits = setup.settings, setup.space.limits
    return {"scenarios": plan.spec.to_json(), "properties": {str(f): digest(Path(f)) for f in setup.files},
            "objective": s.objective.name, "descriptors": [[d.name, d.low, d.high, d.cells] for d in s.descriptors],
            "batch": s.batch, "seed": s.seed, "max_rows": limits.max_rows,
            "frozen_states": sorted(map(str, limits.frozen_states)),
            "frozen_cells": sorted(f"{line} {col}" for line, col in limits.frozen_cells),
            "timer_max": limits.timer_max}


def _run(plan: Any, check: Any, setup: Setup, out: Path, backend: str, address: str | None,
         workers: int | None, quiet: bool) -> None:
    from tablebot.evolve.evaluate import Evaluator
    from tablebot.evolve.pool import Workers
    from tablebot.evolve.proofs import Prover
    from tablebot.evolve.run import Evolution, Store
    from tablebot.fleet.backends import Runner
    from tablebot.interrupts import INTERRUPTS, Terminated

    settings = setup.settings
    store = Store(out, _spec(plan, setup))
    prover = Prover(setup.files, store.proofs)
    started = time.perf_counter()
    evolution = None
    try:
        with Workers(setup.files, plan.table, workers) as provers, Runner(backend, address, workers) as runner, \
                Bar("tables", settings.budget, quiet) as bar:
            evaluator = Evaluator(plan, runner, setup.names)
            evolution = Evolution(plan.table, setup.space, settings, prover, evaluator, store, provers,
                                  on_eval=bar.advance, on_repair=lambda repairs: _said_repairs(repairs, quiet))
            outcome = evolution.run()
            from tablebot.evolve.outputs import write_all  # after the run: it imports pyribs, which the run does

            written = write_all(outcome, settings, plan.table, prover, evaluator, check, out, setup.names,
                                setup.replay, provers)
    except INTERRUPTS as exc:  # SIGTERM raises Terminated while a command runs (cli.common.guarded)
        kept = len(evolution.store.open()) if evolution else 0
        err_console.print(f"{'terminated' if isinstance(exc, Terminated) else 'interrupted'}: {kept} tables "
                          f"evaluated so far are kept in {out}; run the same command again to resume",
                          markup=False, soft_wrap=True)
        raise typer.Exit(143 if isinstance(exc, Terminated) else 130) from None
    if not quiet:
        console.print((out / "report.md").read_text(encoding="utf-8"), markup=False)
        console.print(_pace(outcome, plan, time.perf_counter() - started), markup=False)
        for path in written:
            err_console.print(f"wrote {path}", markup=False)


def _pace(outcome: Any, plan: Any, wall: float) -> str:
    """The run's pace: tables and robot-ticks of the search per second of the fleet's time (the fresh-seed
    check after it not counted); a resumed run says how many tables it took from the folder."""
    counts = outcome.counts
    said = f"({len(outcome.order)} tables in {wall:.0f} s"
    if counts.resumed:
        said += f", {counts.resumed} of them from the earlier run in this folder"
    if counts.evaluated and counts.fleet_s > 0:
        ticks = counts.evaluated * plan.spec.total * plan.spec.ticks
        said += (f"; the search ran {counts.evaluated / counts.fleet_s:.1f} tables/s, "
                 f"{ticks / counts.fleet_s / 1e6:.2f} M robot-ticks/s on the fleet")
    return said + ")"


def _said_repairs(repairs: list[Any], quiet: bool) -> None:
    if quiet:
        return
    for k, r in enumerate(repairs):
        state = "mended it" if r.ok else f"could not mend {', '.join(r.failing)}"
        err_console.print(f"repair {k + 1}: the starting table breaks a property; {len(r.steps)} guard rows "
                          f"{state}", markup=False)
