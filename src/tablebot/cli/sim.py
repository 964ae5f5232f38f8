"""The ``sim`` command: run a table on the simulated robot in a world and write its trace and pictures."""

from __future__ import annotations

import sys
from pathlib import Path
from typing import TYPE_CHECKING

import typer
from rich.progress import BarColumn, Progress, TextColumn, TimeRemainingColumn

from tablebot.cli.app import app
from tablebot.cli.common import ROBOT_OPT, TABLE_ARG, console, err_console, guarded, load, out_folder

if TYPE_CHECKING:  # the simulator (numba, matplotlib) is imported only when the command runs
    from tablebot.sim.runner import Result
    from tablebot.sim.summary import Summary


@app.command("sim")
@guarded
def sim_cmd(
    table: Path = TABLE_ARG,
    world: Path | None = typer.Option(None, "--world", help="World TOML (default: the robot's sim.world, "
                                      "else arena.toml beside the table, else an empty room)."),
    seconds: float = typer.Option(120.0, "--seconds", min=0.01, max=3600, help="Simulated time (up to an hour)."),
    seed: int = typer.Option(1, "--seed", min=0, help="Seed of all simulated noise: same seed, same trace bytes."),
    out: Path = typer.Option(Path("out/sim"), "--out", help="Folder for trace.jsonl and the pictures."),
    view: bool = typer.Option(False, "--view", help="Show the run in a window, in real time."),
    gif: bool = typer.Option(False, "--gif", help="Also write run.gif, an animation of the run."),
    charge: float | None = typer.Option(None, "--battery", min=0.0, max=1.0,
                                        help="Battery charge at the start, 0..1 (overrides the world)."),
    quiet: bool = typer.Option(False, "--quiet", "-q", help="No progress bar and no summary."),
    robot: Path | None = ROBOT_OPT,
) -> None:
    """Simulate the robot running TABLE: trace.jsonl, trajectory.png, timeline.png (and run.gif)."""
    from tablebot.sim import scene as sim_scene
    from tablebot.sim.runner import run, ticks_for
    from tablebot.sim.summary import summarise

    if view:
        from tablebot.sim.animate import check_display
        check_display()
    parsed, machine = load(table, robot)
    overrides = {"battery": {"charge": charge}} if charge is not None else {}
    scene = sim_scene.scene_for(parsed, machine, world, overrides)
    ticks = ticks_for(scene, seconds)  # refuses too long a run before anything is written
    out_folder(out, "--out")  # before the run, so that a bad path fails at once
    result = _run_with_progress(run, scene, seconds, seed, None if quiet else ticks)
    summary = summarise(result)
    written = _write_files(result, summary, out, gif)
    if not quiet:
        _report(result, summary, written)
    if view:
        from tablebot.sim.animate import show
        show(result, summary)


def _write_files(result: Result, summary: Summary, out: Path, gif: bool) -> list[Path]:
    """trace.jsonl, the two pictures and, with ``gif``, the animation."""
    from tablebot.sim import plots
    from tablebot.sim.runner import write_trace

    with (out / "trace.jsonl").open("w", encoding="utf-8") as stream:
        write_trace(result, stream)
    written = [out / "trace.jsonl", plots.trajectory(result, summary, out / "trajectory.png"),
               plots.timeline(result, summary, out / "timeline.png")]
    if gif:
        from tablebot.sim.animate import write_gif
        written.append(write_gif(result, summary, out / "run.gif"))
    return written


def _report(result: Result, summary: Summary, written: list[Path]) -> None:
    """The summary on standard output, the files written on standard error."""
    from tablebot.sim.draw import state_names

    for line in summary.lines(state_names(result.scene.table)):
        console.print(line)
    speed = result.ticks * result.tick_s / max(result.wall_s, 1e-9)
    console.print(f"[dim](simulated {speed:,.0f}× faster than real time)[/dim]")
    for path in written:
        err_console.print(f"wrote {path}")


def _run_with_progress(run, scene, seconds: float, seed: int, ticks: int | None):  # type: ignore[no-untyped-def]
    """``run`` with a progress bar of ``ticks`` on a terminal (None: quiet)."""
    if ticks is None or not sys.stderr.isatty():
        return run(scene, seconds, seed)
    columns = (TextColumn("simulating"), BarColumn(), TextColumn("{task.percentage:>3.0f}%"), TimeRemainingColumn())
    with Progress(*columns, console=err_console, transient=True) as bar:
        task = bar.add_task("sim", total=ticks)
        return run(scene, seconds, seed, progress=lambda done: bar.update(task, completed=done))
