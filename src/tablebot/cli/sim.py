"""The ``sim`` command: run a table on the simulated robot in a world and write its trace and pictures."""

from __future__ import annotations

import contextlib
import sys
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import typer

from tablebot.cli.app import app
from tablebot.cli.common import ROBOT_OPT, TABLE_ARG, console, err_console, guarded, load, out_folder
from tablebot.escape import plain

if TYPE_CHECKING:  # the simulator (numba, matplotlib) is imported only when the command runs
    from tablebot.jit import Compiling
    from tablebot.loop import Sink
    from tablebot.sim.painter import Painter
    from tablebot.sim.runner import SimRun
    from tablebot.sim.scene import Scene
    from tablebot.sim.summary import Summary
    from tablebot.sinks.trace_file import TraceFile


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
    plots: bool = typer.Option(True, "--plots/--no-plots", help="Write trajectory.png and timeline.png."),
    html: bool = typer.Option(False, "--html", help="Also write run.html: the run replayed in any browser, "
                              "no server needed (arena, timeline, table and state diagram)."),
    charge: float | None = typer.Option(None, "--battery", min=0.0, max=1.0,
                                        help="Battery charge at the start, 0..1 (overrides the world)."),
    quiet: bool = typer.Option(False, "--quiet", "-q", help="No progress bar and no summary."),
    robot: Path | None = ROBOT_OPT,
) -> None:
    """Simulate the robot running TABLE: trace.jsonl, trajectory.png, timeline.png (and run.gif, run.html).

    The trace is written while the robot runs; every file appears only when complete. Ctrl-C stops
    the run, keeps what ran as trace.partial.jsonl and leaves the previous run's files as they were.
    """
    import numpy  # noqa: F401 (before the fork: both processes need it, one import serves them)

    # the painter is forked first, before the simulator is imported: it imports matplotlib on the other core
    # while this process imports numba and runs the robot, and draws the pictures when the run is over
    with _painter() if plots else contextlib.nullcontext() as painter:
        _sim(_Run(table, world, seconds, seed, out, view, gif, html, charge, quiet, robot), painter)


def _painter() -> Painter:
    from tablebot.sim.painter import Painter

    return Painter()


@dataclass(frozen=True)
class _Run:
    """The command's options but ``--plots`` (the painter, or its absence, says that)."""

    table: Path
    world: Path | None
    seconds: float
    seed: int
    out: Path
    view: bool
    gif: bool
    html: bool
    charge: float | None
    quiet: bool
    robot: Path | None


def _sim(run: _Run, painter: Painter | None) -> None:
    """The command, once the painter is on its way."""
    from tablebot.fileset import file_set
    from tablebot.sim import scene as sim_scene
    from tablebot.sim.runner import ticks_for
    from tablebot.sim.summary import summarise
    from tablebot.sinks.trace_file import TraceFile

    out, seed = run.out, run.seed
    if run.view:
        from tablebot.sim.animate import check_display
        check_display()
    parsed, machine = load(run.table, run.robot)
    overrides = {"battery": {"charge": run.charge}} if run.charge is not None else {}
    scene = sim_scene.scene_for(parsed, machine, run.world, overrides)
    ticks = ticks_for(scene, run.seconds)  # refuses too long a run before anything is written
    out_folder(out, "--out")  # before the run, so that a bad path fails at once
    from tablebot.jit import Compiling
    from tablebot.sim.kernel import run_robot

    compiling = Compiling("the simulator", run_robot)  # talks until the first ticks have run (first run only)
    # the robot rows are kept only for what draws the run: the painter needs some columns, an animation all
    every_row = run.gif or run.view
    rows = painter.start(scene, ticks, seed, every_row=every_row) if painter is not None else every_row
    drawing = _import_drawing(run.gif, run.html)
    with file_set(out):  # the trace and the pictures replace the previous run's all at once, or not at all
        trace = TraceFile(out / "trace.jsonl", background=True)
        try:
            result = _simulate(scene, run.seconds, seed, None if run.quiet else ticks, trace, rows, painter, compiling)
        finally:
            compiling.done(finished=False)  # an error or Ctrl-C during the compile: the notice stops, says no more
        drawing.join()
        if result.end.complete:
            summary = summarise(result)
            written = [p for p in (trace.written,) if p] + _pictures(result, summary, out, painter, run.gif)
            if run.html:
                assert trace.written is not None  # the trace of a complete run is committed by its end
                written.append(_replay_page(result, trace.written, out / "run.html"))
    if not result.end.complete:
        _stopped(result, trace.written)
    if not run.quiet:
        _report(result, summary, written)
    if run.view:
        from tablebot.sim.animate import show
        show(result, summary)


class _Imports:
    """The modules of the animation and the replay page (matplotlib, PIL) imported by a thread of their own
    while the robot runs: the run's compiled loop leaves the other core (and the GIL) to them, so their half
    second or more costs nothing, and Ctrl-C, which Python delivers to the main thread only, can never cut
    an import short (a compiled module interrupted mid-import surfaces as an ImportError). :meth:`join`
    waits for them and raises what an import raised."""

    def __init__(self, modules: list[Callable[[], None]]) -> None:
        import threading

        self.modules = modules
        self.failed: BaseException | None = None
        self.thread = threading.Thread(target=self._run, name="picture imports", daemon=True)
        self.thread.start()

    def _run(self) -> None:
        try:
            for load in self.modules:
                load()
        except BaseException as exc:  # raised in the main thread by join
            self.failed = exc

    def join(self) -> None:
        self.thread.join()
        if self.failed is not None:
            raise self.failed


def _import_drawing(gif: bool, html: bool) -> _Imports:
    """Start importing the modules the run's animation and replay page will need (see :class:`_Imports`;
    the pictures are the painter's)."""
    wanted = [(_load_animate, gif), (_load_replay, html)]
    return _Imports([load for load, used in wanted if used])


# Plain import statements (not module names as strings), so that import-linter sees these imports too.
def _load_animate() -> None:
    import tablebot.sim.animate  # noqa: F401


def _load_replay() -> None:
    import tablebot.web.replay  # noqa: F401


def _stopped(result: SimRun, kept: Path | None) -> None:
    """A run cut short (Ctrl-C, SIGTERM): say what was kept and exit with the run's code."""
    err_console.print(f"{result.end.message or result.end.reason} after {result.ticks:,} ticks; "
                      f"kept {plain(str(kept))} (the previous run's files are untouched)", markup=False)
    raise typer.Exit(result.end.exit_code)


def _pictures(result: SimRun, summary: Summary, out: Path, painter: Painter | None, gif: bool) -> list[Path]:
    """trajectory.png and timeline.png (drawn by the painter, when there is one) and, with ``gif``, the
    animation."""
    written = painter.draw(result, summary, out) if painter is not None else []
    if gif:
        from tablebot.sim.animate import write_gif
        written.append(write_gif(result, summary, out / "run.gif"))
    return written


def _replay_page(result: SimRun, trace: Path, path: Path) -> Path:
    """A self-contained HTML page that replays the run from the trace just written (to send to a pupil,
    or put on a class page)."""
    from tablebot.fileset import current
    from tablebot.web.replay import write_html

    scene = result.scene
    lines = current(trace).read_text(encoding="utf-8").splitlines()  # not in place yet: its set is being written
    return write_html(path, lines, scene.world, scene.table, params=scene.params)


def _report(result: SimRun, summary: Summary, written: list[Path]) -> None:
    """The summary on standard output, the files written on standard error."""
    for line in summary.lines(result.scene.table.robot.state_names):
        console.print(plain(line), markup=False)
    speed = result.ticks * result.tick_s / max(result.wall_s, 1e-9)
    console.print(f"[dim](simulated {speed:,.0f}× faster than real time)[/dim]")
    for path in written:
        err_console.print(f"wrote {plain(str(path))}", markup=False)


def _simulate(scene: Scene, seconds: float, seed: int, ticks: int | None, trace: TraceFile,
              rows: bool | tuple[int, ...], painter: Painter | None, compiling: Compiling) -> SimRun:
    """The run, with a progress bar of ``ticks`` on a terminal (None: quiet); history in float32 (half
    the memory, plenty for pictures: the trace is written from the exact values), the pictured part of
    it in memory the painter shares, which learns how far the run is as it goes. A first run compiles the
    simulator before its first tick: ``compiling`` talks meanwhile, and the bar appears once ticks run."""
    import numpy as np

    from tablebot.sim.runner import simulate

    sinks: list[Sink] = [trace] if painter is None else [trace, painter.sink]
    kept: dict[str, Any] = {"history": np.float32, "rows": rows} | ({} if painter is None else {"zeros": painter.zeros})
    if ticks is None or not sys.stderr.isatty():
        compiled = (lambda done: compiling.done()) if compiling.active else None
        return simulate(scene, seconds, seed, progress=compiled, sinks=sinks, **kept)
    from rich.progress import BarColumn, Progress, TextColumn, TimeRemainingColumn

    columns = (TextColumn("simulating"), BarColumn(), TextColumn("{task.percentage:>3.0f}%"), TimeRemainingColumn())
    bar = Progress(*columns, console=err_console, transient=True)
    task = bar.add_task("sim", total=ticks)

    def report(done: int) -> None:
        if not bar.live.is_started:  # the first ticks ran: the compile (if any) is over
            compiling.done()
            bar.start()
        bar.update(task, completed=done)

    try:
        if not compiling.active:
            bar.start()
        return simulate(scene, seconds, seed, progress=report, sinks=sinks, **kept)
    finally:
        bar.stop()
