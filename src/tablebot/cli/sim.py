"""The ``sim`` command: run a table on the simulated robot in a world and write its trace and pictures
(:func:`tablebot.api.simulation.simulate`, its options parsed here and its results printed)."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import typer

from tablebot.cli.app import app
from tablebot.cli.common import ROBOT_OPT, TABLE_ARG, console, err_console, guarded, open_project
from tablebot.escape import plain
from tablebot.i18n import _, localise

if TYPE_CHECKING:  # the simulator (numba, matplotlib) is imported only when the command runs
    from tablebot.api.simulation import Simulation


@app.command("sim")
@guarded
def sim_cmd(
    table: Path = TABLE_ARG,
    world: Path | None = typer.Option(
        None,
        "--world",
        help="World TOML (default: the robot's sim.world, else arena.toml beside the table, else an empty room).",
    ),
    seconds: float = typer.Option(120.0, "--seconds", min=0.01, max=3600, help="Simulated time (up to an hour)."),
    seed: int = typer.Option(1, "--seed", min=0, help="Seed of all simulated noise: same seed, same trace bytes."),
    out: Path = typer.Option(Path("out/sim"), "--out", help="Folder for trace.jsonl and the pictures."),
    view: bool = typer.Option(False, "--view", help="Show the run in a window, in real time."),
    gif: bool = typer.Option(False, "--gif", help="Also write run.gif, an animation of the run."),
    plots: bool = typer.Option(True, "--plots/--no-plots", help="Write trajectory.png and timeline.png."),
    html: bool = typer.Option(
        False,
        "--html",
        help="Also write run.html: the run replayed in any browser, "
        "no server needed (arena, timeline, table and state diagram).",
    ),
    charge: float | None = typer.Option(
        None, "--battery", min=0.0, max=1.0, help="Battery charge at the start, 0..1 (overrides the world)."
    ),
    quiet: bool = typer.Option(False, "--quiet", "-q", help="No progress bar and no summary."),
    robot: Path | None = ROBOT_OPT,
) -> None:
    """Simulate the robot running TABLE: trace.jsonl, trajectory.png, timeline.png (and run.gif, run.html).

    The trace is written while the robot runs; every file appears only when complete. Ctrl-C stops
    the run, keeps what ran as trace.partial.jsonl and leaves the previous run's files as they were.
    """
    from tablebot.cli.progress import TickBar

    if view:
        from tablebot.sim.pictures.animate import check_display

        check_display()
    project = open_project(table, robot)
    bar = TickBar(quiet)
    try:
        run = project.simulate(
            seconds,
            seed,
            world=world,
            battery=charge,
            out=out,
            plots=plots,
            gif=gif,
            html=html,
            every_row=view,
            progress=bar,
        )
    finally:
        bar.loading.done(finished=False)  # a refusal before the run (a bad --out) ends the loading notice too
    if not run.complete:
        _stopped(run)
    if not quiet:
        _report(run)
    if view:
        from tablebot.sim.pictures.animate import show

        assert run.summary is not None
        show(run.run, run.summary)


def _stopped(run: Simulation) -> None:
    """A run cut short (Ctrl-C, SIGTERM): say what was kept and exit with the run's code."""
    end = run.end
    kept = run.files[0] if run.files else None
    err_console.print(
        _("{why} after {ticks:,} ticks; kept {kept} (the previous run's files are untouched)").format(
            why=localise(end.message or end.reason), ticks=run.run.ticks, kept=plain(str(kept))
        ),
        markup=False,
    )
    raise typer.Exit(end.exit_code)


def _report(run: Simulation) -> None:
    """The summary on standard output, the files written on standard error."""
    assert run.summary is not None
    for line in run.summary.lines(run.scene.table.robot.state_names):
        console.print(plain(str(localise(line))), markup=False)
    result = run.run
    speed = result.ticks * result.tick_s / max(result.wall_s, 1e-9)
    console.print("[dim]" + _("(simulated {speed:,.0f}× faster than real time)").format(speed=speed) + "[/dim]")
    for path in run.files:
        err_console.print(_("wrote {path}").format(path=plain(str(path))), markup=False)
