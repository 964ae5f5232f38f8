"""``sim`` from Python: :func:`simulate` runs the table on the simulated robot, in memory or straight into a
folder as ``tablebot sim`` does, and returns a :class:`Simulation`."""

from __future__ import annotations

import contextlib
from collections.abc import Callable
from dataclasses import dataclass, replace
from functools import cached_property
from pathlib import Path
from typing import TYPE_CHECKING, Any

from tablebot.api.progress import Progress
from tablebot.files import out_folder
from tablebot.i18n import N_

if TYPE_CHECKING:
    import numpy as np

    from tablebot.loading import Loaded, PathLike
    from tablebot.loop import RunEnd, Sink
    from tablebot.sim.model.scene import Scene
    from tablebot.sim.pictures.painter import Painter
    from tablebot.sim.runner import SimRun
    from tablebot.sim.summary import Summary
    from tablebot.sinks.trace_file import TraceFile


@dataclass(frozen=True)
class Simulation:
    """A simulated run: :attr:`trace` (one numpy record per tick), :attr:`summary` (first light, lamp
    reached, collisions, distance, time per state; None for a run cut short), :attr:`files` it was written
    to, if any, and :attr:`run` (the simulator's own record of it: numpy columns per tick, the robot's rows).
    :meth:`save` writes what ``tablebot sim`` writes.

    >>> import tablebot
    >>> run = tablebot.open("examples/bumberbot").simulate(seconds=2, seed=1)
    >>> len(run.trace), run.summary.seconds
    (200, 2.0)
    """

    run: SimRun
    summary: Summary | None
    files: tuple[Path, ...] = ()

    @property
    def end(self) -> RunEnd:
        """Why the run ended (``end.complete``: it ran its whole length)."""
        return self.run.end

    @property
    def complete(self) -> bool:
        return self.run.end.complete

    @property
    def scene(self) -> Scene:
        """The table, robot, world and simulator parameters it ran with."""
        return self.run.scene

    @cached_property
    def trace(self) -> np.ndarray:
        """The trace, a numpy structured array: ``trace["x"]`` is a column, ``trace[0]`` the first tick.
        Made from the run when it kept its robot rows (a run in memory), else read from the trace it wrote."""
        from tablebot.api import traces

        if traces.exact(self.run):
            return traces.from_run(self.run)
        written = [p for p in self.files if p.name.startswith("trace")]
        if not written:
            raise ValueError("this run kept neither its robot rows nor a trace file")
        return traces.from_file(written[0], self.scene.machine)

    def save(self, folder: PathLike, *, plots: bool = True, gif: bool = False, html: bool = False) -> list[Path]:
        """Write the run into ``folder`` as ``tablebot sim --out FOLDER`` does, byte for byte: ``trace.jsonl``,
        with ``plots`` ``trajectory.png`` and ``timeline.png``, with ``gif`` ``run.gif``, with ``html``
        ``run.html``; they replace an earlier run's all at once. A run cut short writes only
        ``trace.partial.jsonl``. Returns the files written."""
        import numpy  # noqa: F401 (before the painter's fork: both processes need it)

        folder = out_folder(Path(folder), "--out")
        with _painter() if plots and self.complete else contextlib.nullcontext() as painter:
            return _save(self, folder, painter, gif, html)


def simulate(
    project: Loaded,
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
    """Simulate ``seconds`` of the robot running the table (``tablebot sim``): in ``world`` (default: the
    project's), with ``battery`` its charge at the start (0..1; default: the world's), every noise drawn
    from ``seed`` (same seed, same trace). Without ``out`` the run stays in memory (:meth:`Simulation.save`
    writes it); with ``out`` the trace is written while the robot runs and the pictures are drawn meanwhile
    (``plots``, ``gif``, ``html`` as in :meth:`Simulation.save`), as the command does. ``every_row`` keeps
    every robot row of a run into ``out`` (an animation of it needs them; else only what the pictures draw).
    Ctrl-C ends the run early: the result says so (``complete`` False) and keeps what ran.
    """
    overrides = {"battery": {"charge": battery}} if battery is not None else {}
    shown = progress or Progress()
    if out is None:
        return _in_memory(project.scene(world, overrides, every_table=True), seconds, seed, shown)
    import numpy  # noqa: F401 (before the fork: both processes need it, one import serves them)

    # the painter is forked first, before the simulator is imported: it imports matplotlib on the other core
    # while this process imports numba and runs the robot, and draws the pictures when the run is over
    with _painter() if plots else contextlib.nullcontext() as painter, project.writing():
        scene = project.scene(world, overrides, every_table=True)
        return _into(scene, seconds, seed, Path(out), painter, gif, html, every_row or gif, shown)


def _painter() -> Painter:
    from tablebot.sim.pictures.painter import Painter

    return Painter()


def _in_memory(scene: Scene, seconds: float, seed: int, progress: Progress) -> Simulation:
    from tablebot.sim.summary import summarise

    result = _run(scene, seconds, seed, progress)
    return Simulation(result, summarise(result) if result.end.complete else None)


def _into(
    scene: Scene,
    seconds: float,
    seed: int,
    out: Path,
    painter: Painter | None,
    gif: bool,
    html: bool,
    every_row: bool,
    progress: Progress,
) -> Simulation:
    """The run written into ``out`` as it goes, once the painter (if any) is on its way."""
    import numpy as np

    from tablebot.fileset import file_set
    from tablebot.sim.runner import ticks_for
    from tablebot.sim.summary import summarise
    from tablebot.sinks.trace_file import TraceFile

    ticks = ticks_for(scene, seconds)  # refuses too long a run before anything is written
    out_folder(out, "--out")  # before the run, so that a bad path fails at once
    rows = painter.start(scene, ticks, seed, every_row=every_row) if painter is not None else every_row
    drawing = _import_drawing(gif, html)
    summary = None
    with file_set(out):  # the trace and the pictures replace the previous run's all at once, or not at all
        trace = TraceFile(out / "trace.jsonl", background=True)
        sinks: list[Sink] = [trace] if painter is None else [trace, painter.sink]
        kept: dict[str, Any] = {"history": np.float32, "rows": rows}
        if painter is not None:
            kept["zeros"] = painter.zeros  # the pictured columns in memory the painter shares
        result = _run(scene, seconds, seed, progress, sinks, **kept)
        drawing.join()
        written = [p for p in (trace.written,) if p]
        if result.end.complete:
            summary = summarise(result)
            written += _pictures(result, summary, out, painter, gif)
            if html:
                written.append(_replay_page(result, _current(trace), out / "run.html"))
    return Simulation(result, summary, tuple(written))


def _run(
    scene: Scene, seconds: float, seed: int, progress: Progress, sinks: list[Sink] | None = None, **kept: Any
) -> SimRun:
    """The run, telling ``progress`` the ticks done after each block (a first run compiles the simulator
    before its first tick: ``progress.compiling`` is told first)."""
    from tablebot.sim.physics.kernel import run_robot
    from tablebot.sim.physics.several import run_several
    from tablebot.sim.runner import simulate, ticks_for

    progress.compiling(N_("the simulator"), run_robot if scene.tables is None else run_several)
    progress.start("ticks", ticks_for(scene, seconds))
    done = 0

    def report(ticks: int) -> None:
        nonlocal done
        progress.advance(ticks - done)
        done = ticks

    try:
        return simulate(scene, seconds, seed, progress=report, sinks=sinks or [], **kept)
    finally:
        progress.stop()


def _current(trace: TraceFile) -> Path:
    assert trace.written is not None  # the trace of a complete run is committed by its end
    return trace.written


def _save(sim: Simulation, folder: Path, painter: Painter | None, gif: bool, html: bool) -> list[Path]:
    """:meth:`Simulation.save`, once the painter (if any) is on its way: the trace made again from the run
    (or copied from the trace it wrote), the pictures drawn from its columns as the command keeps them."""
    from tablebot.fileset import file_set

    run = sim.run
    drawing = _import_drawing(gif and sim.complete, html and sim.complete)
    with file_set(folder):
        trace = _write_trace(sim, folder)
        drawing.join()
        written = [trace]
        if sim.complete and sim.summary is not None:
            if painter is not None or gif:
                rows = painter.start(run.scene, run.ticks, run.seed, every_row=gif) if painter else True
                written += _pictures(_as_kept(run, rows), sim.summary, folder, painter, gif)
            if html:
                written.append(_replay_page(run, trace, folder / "run.html"))
    return written


def _write_trace(sim: Simulation, folder: Path) -> Path:
    """The run's trace in ``folder``, made by the trace writer of a run from the blocks the run's sinks saw
    (the same lines), or, for a run that kept only what its pictures draw, the trace it wrote, copied."""
    from tablebot.api import traces
    from tablebot.engine import Engine
    from tablebot.files import write_bytes
    from tablebot.loop import BLOCK_TICKS, RunInfo
    from tablebot.sinks.trace_file import TraceFile

    run = sim.run
    if not traces.exact(run):
        written = next((p for p in sim.files if p.name.startswith("trace")), None)
        if written is None:
            raise ValueError("this run kept neither its robot rows nor a trace file")
        return write_bytes(folder / written.name, written.read_bytes())
    trace = TraceFile(folder / "trace.jsonl")
    trace.start(RunInfo(Engine(run.scene.machine), run.tick_s, "sim", run.ticks))
    # a robot of several tables: its other tables' keys are the run's, not its robot rows' (one block, the same lines)
    for block in [run.block()] if run.others else traces.blocks(run, BLOCK_TICKS):
        trace.block(block)
    trace.end(run.end)
    assert trace.written is not None
    return trace.written


def _as_kept(run: SimRun, rows: bool | tuple[int, ...]) -> SimRun:
    """The run's robot rows as ``sim`` keeps them for its pictures: float32, only the columns drawn (all of
    them for an animation) -- what the pictures of the command's run are drawn from, to the last bit."""
    import numpy as np

    hist = run.kept_rows()
    if run.hist_columns is not None:  # kept so already, by a run into a folder
        return run
    columns = None if isinstance(rows, bool) else tuple(rows)
    kept = hist if columns is None else hist[:, list(columns)]
    return replace(run, hist=kept.astype(np.float32), hist_columns=columns)


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
    import tablebot.sim.pictures.animate  # noqa: F401


def _load_replay() -> None:
    import tablebot.web.replay  # noqa: F401


def _pictures(result: SimRun, summary: Summary, out: Path, painter: Painter | None, gif: bool) -> list[Path]:
    """trajectory.png and timeline.png (drawn by the painter, when there is one) and, with ``gif``, the
    animation."""
    written = painter.draw(result, summary, out) if painter is not None else []
    if gif:
        from tablebot.sim.pictures.animate import write_gif

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
