"""A simulated run: the run loop driving a :class:`~tablebot.sim.simrobot.SimRobot`, with a sink that
keeps the run's history for the summary and the pictures (and any other sinks, such as the trace).
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import IO, Any

import numpy as np

from tablebot.diagnostics import fail
from tablebot.engine import Engine
from tablebot.engine.as_one import RobotEngine
from tablebot.formats.inputs_csv import TickInput
from tablebot.i18n import N_
from tablebot.loop import RunEnd, RunInfo, Sink, TickBlock
from tablebot.loop import run as run_loop
from tablebot.sim import columns as L
from tablebot.sim.model.scene import Scene
from tablebot.sim.simrobot import SimRobot, field_columns
from tablebot.sinks.trace_file import block_lines

MAX_TICKS = 360_000  # an hour at the BumberBot's 10 ms: the whole history is kept in memory
PATH_STRIDE = 5  # robot rows per point of the thinned path (the robot moves well under 1 cm a tick)

#: Where History keeps a column: ``zeros(name, shape, dtype)`` gives a zeroed array (numpy's by default; a
#: painter's gives memory it shares, for the pictures drawn while the robot runs).
Zeros = Callable[[str, tuple[int, ...], Any], np.ndarray]


def _zeros(name: str, shape: tuple[int, ...], dtype: Any) -> np.ndarray:
    return np.zeros(shape, dtype)


@dataclass
class SimRun:
    """A finished run. ``hist[t]`` is the robot at the start of tick t (what the engine sensed then;
    one more row than ticks: the robot after the last tick); the other columns have a row per tick:
    the inputs read, the event set, the fired row (-1: none), and state index, timer, outputs,
    counters after the tick."""

    scene: Scene
    seed: int
    hist: np.ndarray | None  # (ticks + 1, N_STATE), float64 or float32; None when not kept (no pictures)
    #: (or, with ``hist_columns``, only those columns of each row: what the pictures draw)
    ends: np.ndarray  # (2, N_STATE): the robot before the first tick and after the last
    path: np.ndarray  # (rows, 2): x, y of every PATH_STRIDE-th robot row (for the summary's laps)
    masks: np.ndarray  # (ticks,)
    events: np.ndarray
    rows: np.ndarray
    states: np.ndarray
    timers: np.ndarray
    outputs: np.ndarray  # (ticks, n_outputs)
    counters: np.ndarray  # (ticks, n_counters)
    pulses: np.ndarray  # (ticks, n_counters)
    collision_rows: list[int]  # hist rows where each collision began (the first MAX_COLLISIONS of them)
    collision_count: int  # all collisions
    reached_row: int | None  # the first hist row within reach of a lamp
    end: RunEnd
    wall_s: float  # how long the loop took; shown to people, never written into result files
    hist_columns: tuple[int, ...] | None = None  # the sim.columns hist holds (None: all of them)
    #: A robot of several tables: the other tables' decisions per tick, keyed as a trace keys them
    #: (``NAME.event``, ``NAME.row``, ``NAME.state``, ``NAME.timer``); empty for one table.
    others: dict[str, list] = field(default_factory=dict)

    def kept_rows(self) -> np.ndarray:
        """``hist``, for a run that kept the robot's rows (``simulate``'s default); a run that kept none says so."""
        if self.hist is None:
            raise ValueError("this run kept no robot rows: simulate it with rows=True (the default)")
        return self.hist

    @property
    def ticks(self) -> int:
        return len(self.states)

    @property
    def held(self) -> tuple[int, ...]:
        """The sim.columns each row of ``hist`` holds, in order."""
        return self.hist_columns or tuple(range(L.N_STATE))

    def column(self, column: int) -> np.ndarray:
        """One column (sim.columns) of every robot row."""
        return self.kept_rows()[:, self.held.index(column)]

    @property
    def tick_s(self) -> float:
        return self.scene.tick_s

    def inputs(self) -> list[TickInput]:
        """The engine's inputs per tick, as recorded: replaying them gives the same run."""
        pulses = self.pulses.tolist()
        return [TickInput(int(m), tuple(p)) for m, p in zip(self.masks.tolist(), pulses, strict=True)]

    def block(self) -> TickBlock:
        """The whole run as one block of ticks, with the simulator's trace fields."""
        assert self.hist is not None and self.hist_columns is None, "the trace needs every robot row"
        return TickBlock(
            0,
            self.masks,
            self.pulses,
            self.events,
            self.rows,
            self.states,
            self.timers,
            self.outputs,
            self.counters,
            {**field_columns(self.scene, self.hist[:-1]), **self.others},
        )

    def write_trace(self, stream: IO[str]) -> int:
        """Write the run's trace as JSON Lines (what ``tablebot sim`` writes live); returns the number of ticks."""
        stream.writelines(block_lines(self.block(), self.scene.machine))
        return self.ticks

    def heading_deg(self) -> np.ndarray:
        """Unwrapped heading in degrees per hist row (a turn of 270° reads 270, not -90)."""
        return np.degrees(self.column(L.TH).astype(np.float64))


class History:
    """A sink that keeps every tick of a simulated run in arrays sized for the planned run (robot rows as
    ``dtype``: float32 halves the memory of an hour's run and is plenty for pictures; the trace is
    written from the exact values). With ``rows=False`` it keeps the per-tick columns, the first and
    last robot rows and a thinned path, but not every robot row (a run without pictures); with a tuple
    of columns (sim.columns), only those columns of every row (what the pictures draw). Each array is
    made by ``zeros`` (see :data:`Zeros`)."""

    COLUMNS = ("masks", "events", "rows", "states", "timers", "outputs", "counters", "pulses")

    def __init__(
        self, robot: SimRobot, dtype: type = np.float64, rows: bool | tuple[int, ...] = True, zeros: Zeros = _zeros
    ) -> None:
        self.robot, self.dtype, self.zeros = robot, dtype, zeros
        self.rows = bool(rows)
        self.kept = None if isinstance(rows, bool) else tuple(rows)  # the columns kept (None: all)
        self._kept = np.array(self.kept or (), dtype=np.intp)
        self.ended: RunEnd | None = None
        self.done = 0
        self.others: dict[str, list] = {}  # the other tables' keys of a robot of several tables, per tick

    def start(self, info: RunInfo) -> None:
        machine = info.engine.machine
        ticks = info.ticks or 0
        n_out, n_c = len(machine.output_names), len(machine.counter_bits)
        width = L.N_STATE if self.kept is None else len(self.kept)
        self.hist = self.zeros("hist", (ticks + 1 if self.rows else 0, width), self.dtype)
        self.first = self.robot.s.copy()
        self.path = np.zeros((ticks // PATH_STRIDE + 1, 2))
        self._keep_row(0, self.robot.s)
        small = np.int16 if len(machine.states) < 32768 and len(machine.rows) < 32768 else np.int32
        shapes = {
            "masks": ((ticks,), np.int32),
            "events": ((ticks,), np.int32),
            "rows": ((ticks,), small),
            "states": ((ticks,), small),
            "timers": ((ticks,), np.int32),
            "outputs": ((ticks, n_out), np.int8),
            "counters": ((ticks, n_c), np.int32),
            "pulses": ((ticks, n_c), np.int32),
        }
        self.columns = {name: self.zeros(name, shape, dtype) for name, (shape, dtype) in shapes.items()}

    def block(self, block: TickBlock) -> None:
        a, b = block.start, block.start + len(block)
        for name in self.COLUMNS:
            self.columns[name][a:b] = getattr(block, name)
        if self.robot.scene.tables is not None and block.extra is not None:
            for key in other_keys(self.robot.scene):
                self.others.setdefault(key, []).extend(block.extra[key])
        if block.raw is not None:  # the robot at the start of each tick; the one after the last comes below
            if self.rows:
                self.hist[a:b] = block.raw if self.kept is None else block.raw[:, self._kept]
            first = -(-a // PATH_STRIDE) * PATH_STRIDE  # the first row of the block on the path's stride
            points = block.raw[first - a :: PATH_STRIDE][:, [L.X, L.Y]]
            self.path[first // PATH_STRIDE : first // PATH_STRIDE + len(points)] = points
        self._keep_row(b, self.robot.s)
        self.done = b

    def _keep_row(self, row: int, s: np.ndarray) -> None:
        if self.rows:
            self.hist[row] = s if self.kept is None else s[self._kept]
        if row % PATH_STRIDE == 0 and row // PATH_STRIDE < len(self.path):
            self.path[row // PATH_STRIDE] = s[[L.X, L.Y]]

    def end(self, end: RunEnd) -> None:
        self.ended = end

    def result(self, scene: Scene, seed: int, wall_s: float) -> SimRun:
        robot, n = self.robot, self.done
        cut = {name: column[:n] for name, column in self.columns.items()}  # a run cut short keeps what ran
        return SimRun(
            scene=scene,
            seed=seed,
            hist=self.hist[: n + 1] if self.rows else None,
            ends=np.stack((self.first, robot.s)),
            path=self.path[: n // PATH_STRIDE + 1],
            **cut,
            collision_rows=robot.collisions,
            collision_count=robot.collision_count,
            reached_row=robot.reached_row,
            end=self.ended,  # type: ignore[arg-type]
            wall_s=wall_s,
            hist_columns=self.kept,
            others={k: v[:n] for k, v in self.others.items()},
        )


def other_keys(scene: Scene) -> list[str]:
    """The trace keys of a robot's tables other than the main one (none for one table)."""
    names = scene.tables.names[1:] if scene.tables is not None else ()
    return [f"{name}.{key}" for name in names for key in ("event", "row", "state", "timer")]


class Progress:
    """A sink that reports ticks done (every block) to a callback."""

    def __init__(self, report: Callable[[int], None]) -> None:
        self.report = report

    def start(self, info: RunInfo) -> None:
        pass

    def block(self, block: TickBlock) -> None:
        self.report(block.start + len(block))

    def end(self, end: RunEnd) -> None:
        pass


def engine_for(scene: Scene) -> Engine | RobotEngine:
    """The engine a run of ``scene`` steps: its table's, or every table of a robot of several. The run loop
    runs an Engine in compiled blocks, a RobotEngine tick by tick from Python (every table, slower)."""
    return RobotEngine(scene.tables) if scene.tables is not None else Engine(scene.machine)


def ticks_for(scene: Scene, seconds: float) -> int:
    """The ticks in ``seconds`` of robot time (at least one); more than MAX_TICKS are refused."""
    ticks = max(1, round(seconds / scene.tick_s))
    if ticks > MAX_TICKS:
        raise fail(
            "--seconds",
            N_(
                "{seconds:g} s at tick_ms = {tick_ms} is {ticks:,} ticks; a run holds at most {most:,}",
                seconds=seconds,
                tick_ms=scene.table.robot.tick_ms,
                ticks=ticks,
                most=MAX_TICKS,
            ),
            N_("simulate at most {most:g} s", most=MAX_TICKS * scene.tick_s),
        )
    return ticks


def simulate(
    scene: Scene,
    seconds: float,
    seed: int = 1,
    progress: Callable[[int], None] | None = None,
    sinks: Sequence[Sink] = (),
    history: type = np.float64,
    rows: bool | tuple[int, ...] = True,
    zeros: Zeros = _zeros,
) -> SimRun:
    """Simulate ``seconds`` of robot time through the run loop; ``progress(ticks_done)`` is called
    after each block of ticks and ``sinks`` (a trace writer, say) see the run as it happens, after the
    run's :class:`History` (made with ``history``, ``rows`` and ``zeros``) has kept each block.

    Everything random comes from the robot's numpy Generator seeded with ``seed``, and nothing depends
    on the wall clock, so a table, world and seed always give the same trace bytes.
    """
    ticks = ticks_for(scene, seconds)
    robot = SimRobot(scene, seed)
    keep = History(robot, history, rows, zeros)
    extra = [Progress(progress)] if progress else []
    started = time.perf_counter()
    run_loop(engine_for(scene), robot, sinks=[keep, *sinks, *extra], ticks=ticks, target="sim")
    return keep.result(scene, seed, time.perf_counter() - started)
