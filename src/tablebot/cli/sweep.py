"""The ``sweep`` command: thousands of simulated robots over worlds × grid values × seeds, on this
machine's cores or a Dask cluster, one result row per run, pictures, resumable."""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import TYPE_CHECKING

import typer

from tablebot.cli.app import app
from tablebot.cli.common import ROBOT_OPT, TABLE_ARG, console, err_console, guarded, open_project
from tablebot.escape import plain
from tablebot.i18n import _, localise

if TYPE_CHECKING:
    from tablebot.api.sweeping import Sweep

WORLD_OPT = typer.Option(None, "--world", help="World TOML; repeat for several worlds (default: the table's arena).")
BACKEND_OPT = typer.Option(
    "auto",
    "--backend",
    help="local (this machine's cores) or dask (a cluster); auto: dask when a scheduler is named, else local.",
)
SCHEDULER_OPT = typer.Option(
    None, "--scheduler", help="Dask scheduler address, tcp://HOST:8786 (or set DASK_SCHEDULER_ADDRESS)."
)
WORKERS_OPT = typer.Option(None, "--workers", min=1, help="Local worker threads (default: one per core).")


@app.command("sweep")
@guarded
def sweep_cmd(
    table: Path = TABLE_ARG,
    world: list[Path] | None = WORLD_OPT,
    robots: int | None = typer.Option(None, "--robots", help="Run N robots: seeds 0..N-1 (or use --seeds)."),
    grid: list[str] | None = typer.Option(
        None,
        "--grid",
        help="KEY=V1,V2,...: battery=1.0,0.6, start=random "
        "(or X:Y:HEADING poses), a simulator parameter such as "
        'motor.friction_volts=0.2,0.4, or a table cell: "line 5 timer=300,600" '
        '("lights: line 4 timer=20,50": another table). Repeat: every '
        "combination runs.",
    ),
    seeds: str | None = typer.Option(None, "--seeds", help="Seeds of each combination: 0..999, 1,5,9 or a mix."),
    seconds: float = typer.Option(60.0, "--seconds", min=0.01, max=3600, help="Simulated time of each run."),
    backend: str = BACKEND_OPT,
    scheduler: str | None = SCHEDULER_OPT,
    workers: int | None = WORKERS_OPT,
    out: Path = typer.Option(Path("out/sweep"), "--out", help="Folder for results.csv, its parts and pictures."),
    plots: bool = typer.Option(True, "--plots/--no-plots", help="Write outcomes.png, starts.png, best.png, worst.png."),
    trace: str | None = typer.Option(
        None,
        "--trace",
        help="Runs to write whole as OUT/trace-RUN.jsonl (the trace "
        "tablebot sim writes for that robot): run numbers, e.g. 0,17 or 0..9.",
    ),
    quiet: bool = typer.Option(False, "--quiet", "-q", help="No progress bar and no summary."),
    robot: Path | None = ROBOT_OPT,
) -> None:
    """Run TABLE on many simulated robots: every world × grid combination × seed, one row per run in
    OUT/results.csv, with pictures. Ctrl-C (or SIGTERM) keeps every finished chunk; the same command again
    resumes."""
    from tablebot.cli.progress import CountBar

    project = open_project(table, robot, worlds=world, properties=[])  # a sweep proves nothing: none looked for
    with stops():
        result = project.sweep(
            robots=robots,
            seeds=seeds,
            grid=grid or [],
            seconds=seconds,
            backend=backend,
            scheduler=scheduler,
            workers=workers,
            out=out,
            plots=plots,
            trace=trace,
            progress=CountBar(quiet),
        )
    if not quiet:
        report(result)


@contextmanager
def stops() -> Iterator[None]:
    """Ctrl-C or SIGTERM during a sweep, tune or evolve: what was kept, where, then exit 130 (143)."""
    from tablebot.api.progress import Stopped

    try:
        yield
    except Stopped as stopped:
        err_console.print(
            _("{word}: {kept}; run the same command again to resume").format(
                word=localise(stopped.word), kept=plain(str(localise(stopped.kept)))
            ),
            markup=False,
        )
        raise typer.Exit(stopped.exit_code) from None


def report(result: Sweep) -> None:
    """Success rate per grid value on standard output; the files written on standard error."""
    for line in result.lines():
        console.print(plain(str(localise(line))), markup=False)
    if result.ran:
        rate = result.ran * result.plan.spec.ticks / max(result.wall_s, 1e-9)
        console.print(
            "[dim]"
            + _("({runs:,} runs in {seconds:.1f} s: {rate:.2f} M robot-ticks/s)").format(
                runs=result.ran, seconds=result.wall_s, rate=rate / 1e6
            )
            + "[/dim]"
        )
    for p in result.files:
        err_console.print(_("wrote {path}").format(path=plain(str(p))), markup=False)
