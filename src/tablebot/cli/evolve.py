"""The ``evolve`` command: the computer writes the table, under the robot's proved properties, on the fleet;
a quality-diversity archive of tables that behave differently, written as tables with a report
(:func:`tablebot.api.evolution.evolve`, its options parsed here and its report printed)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import typer

from tablebot.cli.app import app
from tablebot.cli.common import ROBOT_OPT, TABLE_ARG, console, err_console, guarded, open_project
from tablebot.cli.sweep import BACKEND_OPT, SCHEDULER_OPT, WORLD_OPT, stops
from tablebot.i18n import _, localise, number

EVOLVE_WORKERS_OPT = typer.Option(
    None,
    "--workers",
    min=1,
    help="Local worker threads for the fleet, and prover processes (default: one per core; 1 proves in this process).",
)


@app.command("evolve")
@guarded
def evolve_cmd(
    table: Path = TABLE_ARG,
    out: Path = typer.Option(
        Path("out/evolve"),
        "--out",
        help="Folder for the tables, report.md, archive.png and "
        "the run's records (the same command again resumes from them).",
    ),
    world: list[Path] | None = WORLD_OPT,
    objective: str | None = typer.Option(
        None,
        "--objective",
        help="What to make best (a mean over the scenarios): "
        "time_to_lamp, time_to_light, missed_lamp, lamp_distance, collisions, "
        "collision_share, distance, area_covered or laps, as the worlds allow "
        "(default: time_to_lamp with a lamp, else laps with a closed line).",
    ),
    descriptors: str | None = typer.Option(
        None,
        "--descriptors",
        help="One or two behaviour descriptors for the "
        'archive, each with an optional range: "collision_share,'
        'area_covered=0..0.5"; also state_share:STATE (default: area_covered,'
        "collision_share).",
    ),
    cells: int = typer.Option(8, "--cells", min=2, max=100, help="Archive cells per descriptor."),
    budget: int = typer.Option(200, "--budget", min=1, help="Most tables to run on the fleet (the start included)."),
    batch: int | None = typer.Option(
        None,
        "--batch",
        min=1,
        help="Tables asked for per generation (default: 16; a last generation takes what the budget has room for).",
    ),
    seeds: str = typer.Option("0..15", "--seeds", help="Seeds of the scenarios every table runs."),
    check_seeds: str = typer.Option("1000..1063", "--check-seeds", help="Fresh seeds for the before/after report."),
    grid: list[str] | None = typer.Option(None, "--grid", help='Scenario grid as in sweep (default: "start=random").'),
    seconds: float = typer.Option(60.0, "--seconds", min=0.01, max=3600, help="Simulated time of each run."),
    max_rows: int | None = typer.Option(
        None,
        "--max-rows",
        min=1,
        help="Most rows a table may have (default: half as many again as the start, at least 8 more).",
    ),
    freeze_state: list[str] | None = typer.Option(
        None, "--freeze-state", help="States whose rows stay exactly as they are: 20,21 (repeat or comma-separate)."
    ),
    freeze_cell: list[str] | None = typer.Option(
        None,
        "--freeze-cell",
        help='Cells that never change: "line 5 '
        'timer", "line 5 M1", "line 5 next", or "line 5" for the whole '
        "row (file lines; the row is then never removed or moved).",
    ),
    properties: list[Path] | None = typer.Option(
        None,
        "--properties",
        help="Property files every kept table must "
        "satisfy (instead of those beside the table; the robot file's "
        "[properties] always count).",
    ),
    seed: int = typer.Option(0, "--seed", min=0, help="Seed of the search itself."),
    which_table: str | None = typer.Option(
        None,
        "--table",
        help="A robot of several tables ([tables] in its robot "
        "file): the one to evolve, the others staying as they are (default: the "
        "main table).",
    ),
    backend: str = BACKEND_OPT,
    scheduler: str | None = SCHEDULER_OPT,
    workers: int | None = EVOLVE_WORKERS_OPT,
    quiet: bool = typer.Option(False, "--quiet", "-q", help="No progress bar and no report on the terminal."),
    robot: Path | None = ROBOT_OPT,
) -> None:
    """Evolve TABLE: change its motor cells, timers and next states, add, remove and reorder rows, keep only
    tables that satisfy every property of the robot (proved by check), run them on the fleet, and keep an
    archive of the best tables that behave differently. Ctrl-C keeps what was run; the same command resumes."""
    from tablebot.cli.progress import CountBar

    project = open_project(table, robot, worlds=world, properties=properties)
    with stops():
        evolved = project.evolve(
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
            freeze_state=freeze_state or [],
            freeze_cell=freeze_cell or [],
            seed=seed,
            backend=backend,
            scheduler=scheduler,
            workers=workers,
            progress=CountBar(quiet),
            table=which_table,
        )
    if not quiet:
        console.print(localise(evolved.report_text()), markup=False)
        console.print(_pace(evolved.outcome, evolved.plan, evolved.wall_s), markup=False)
        for path in evolved.files:
            err_console.print(_("wrote {path}").format(path=path), markup=False)


def _pace(outcome: Any, plan: Any, wall: float) -> str:
    """The run's pace: tables and robot-ticks of the search per second of the fleet's time (the fresh-seed
    check after it not counted); a resumed run says how many tables it took from the folder."""
    counts = outcome.counts
    said = _("({tables} tables in {seconds} s").format(tables=len(outcome.order), seconds=number(wall, ".0f"))
    if counts.resumed:
        said += _(", {n} of them from the earlier run in this folder").format(n=counts.resumed)
    if counts.evaluated and counts.fleet_s > 0:
        ticks = counts.evaluated * plan.spec.total * plan.spec.ticks
        said += _("; the search ran {tables} tables/s, {rate} M robot-ticks/s on the fleet").format(
            tables=number(counts.evaluated / counts.fleet_s, ".1f"), rate=number(ticks / counts.fleet_s / 1e6, ".2f")
        )
    return said + ")"
