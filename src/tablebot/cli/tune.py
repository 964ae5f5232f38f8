"""The ``tune`` command: choose timer values (and counter loads) that make a table do best over a fixed
scenario set, then check the result on fresh seeds; writes the tuned table as a new file
(:func:`tablebot.api.tuning.tune`, its options parsed here and its report printed)."""

from __future__ import annotations

from pathlib import Path

import typer

from tablebot.cli.app import app
from tablebot.cli.common import FORCE_OPT, ROBOT_OPT, TABLE_ARG, console, err_console, guarded, open_project
from tablebot.cli.sweep import BACKEND_OPT, SCHEDULER_OPT, WORKERS_OPT, WORLD_OPT, stops
from tablebot.diagnostics import severity_word
from tablebot.escape import plain, terminal
from tablebot.i18n import _, localise


@app.command("tune")
@guarded
def tune_cmd(
    table: Path = TABLE_ARG,
    cells: str = typer.Option(
        ...,
        "--cells",
        help='Cells to tune: "line 5 timer, line 9 timer" (file lines; '
        'a range: "line 5 timer=100..2000"; counter loads: "line 12 C1_load"; another table '
        'of a robot of several: "lights: line 4 timer").',
    ),
    objective: str = typer.Option(
        "time_to_lamp",
        "--objective",
        help="What to make smallest: time_to_lamp, "
        "time_to_light, collisions, lamp_distance or missed_lamp (means over the "
        "scenarios).",
    ),
    budget: int = typer.Option(300, "--budget", min=1, help="Most candidates to evaluate."),
    method: str = typer.Option(
        "auto", "--method", help="grid, cma (CMA-ES with integer margin) or auto: grid for one or two cells, else cma."
    ),
    world: list[Path] | None = WORLD_OPT,
    grid: list[str] | None = typer.Option(None, "--grid", help='Scenario grid as in sweep (default: "start=random").'),
    seeds: str = typer.Option("0..15", "--seeds", help="Seeds of the scenario set every candidate runs."),
    check_seeds: str = typer.Option("1000..1063", "--check-seeds", help="Fresh seeds for the before/after check."),
    seconds: float = typer.Option(60.0, "--seconds", min=0.01, max=3600, help="Simulated time of each run."),
    seed: int = typer.Option(0, "--seed", min=0, help="Seed of CMA-ES itself."),
    backend: str = BACKEND_OPT,
    scheduler: str | None = SCHEDULER_OPT,
    workers: int | None = WORKERS_OPT,
    out: Path = typer.Option(
        Path("out/tune"), "--out", help="Folder for the tuned table, report.md and convergence.png."
    ),
    quiet: bool = typer.Option(False, "--quiet", "-q", help="No progress bar and no report on the terminal."),
    robot: Path | None = ROBOT_OPT,
    force: bool = FORCE_OPT,
) -> None:
    """Tune TABLE's timers (and counter loads) for an objective over a fixed scenario set (every candidate
    runs the same seeds, starts and batteries), check the best on fresh seeds, and write it as a new table.
    Ctrl-C (or SIGTERM) keeps every evaluation made; the same command again resumes."""
    from tablebot.cli.progress import CountBar

    project = open_project(table, robot, worlds=world)
    with stops():
        tuned = project.tune(
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
            progress=CountBar(quiet),
        )
    if not quiet:
        for line in tuned.report_text().splitlines():  # the report names the table and its cells: user text
            console.print(plain(line), markup=False)
        for path in tuned.files:
            err_console.print(_("wrote {path}").format(path=plain(str(path))), markup=False)
        if not tuned.helped:  # the report says so too; the last word on the terminal must not read as a success
            err_console.print(f"[yellow]{severity_word('note')}:[/yellow] {terminal(str(localise(tuned.verdict())))}")
