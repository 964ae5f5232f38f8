"""The run loop: one engine driving one robot through the :class:`RobotIO` seam, paced by a clock,
observed by sinks, guarded by a watchdog (the clocks, the watchdog and the pace: :mod:`tablebot.pacing`).
Every way a table meets a robot goes through :func:`run`.
"""

# Per tick: wait for the clock, read the robot, step the engine, write the outputs, tell the sinks.
# A robot that can run many ticks in compiled code (the simulator) offers ``advance`` and gets whole
# blocks instead; the sinks see the same columns either way. Whatever ends the run (its length,
# Ctrl-C, SIGTERM, a failing or stalled tick, a lost link, a bug), the robot's outputs are stopped
# first, then the link is closed, then the sinks are told why.

from __future__ import annotations

import contextlib
import signal
import threading
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Protocol, runtime_checkable

from tablebot.engine import Engine
from tablebot.engine.as_one import RobotEngine
from tablebot.i18n import N_, Message
from tablebot.interrupts import Terminated
from tablebot.pacing import (
    BEHIND_WINDOW_S,
    Behind,
    Clock,
    Lateness,
    Pace,
    RealTimeClock,
    SimulatedClock,
    StopRequest,
    Watchdog,
    WatchdogTimeout,
)

if TYPE_CHECKING:
    import numpy as np

#: The loop's own names, and the clocks, watchdog and pace of :mod:`tablebot.pacing` that a run is given.
__all__ = [
    "BEHIND_WINDOW_S",
    "BLOCK_TICKS",
    "EXIT_CODES",
    "BlockIO",
    "Clock",
    "Lateness",
    "LinkLost",
    "Pace",
    "Reading",
    "RealTimeClock",
    "RobotIO",
    "RunEnd",
    "RunInfo",
    "SimulatedClock",
    "Sink",
    "StopRequest",
    "TickBlock",
    "Watchdog",
    "WatchdogTimeout",
    "exchange",
    "run",
]


@dataclass(frozen=True)
class Reading:
    """What a robot senses at the start of a tick."""

    mask: int  # the inputs that read 1, in the machine's event layout (Machine.input_bits)
    pulses: tuple[int, ...] = ()  # encoder pulses per robot counter since the last reading
    extra: Mapping[str, Any] | None = None  # fields the trace appends after the core ones (pose, raw values)


class LinkLost(Exception):
    """The robot stopped answering (or answered nonsense): the run must end, outputs stopped."""


@runtime_checkable
class RobotIO(Protocol):
    """One robot: ``open`` (connect, configure, outputs off), then per tick ``read`` and ``write``;
    ``stop`` (outputs off now: idempotent, never raises) and ``close`` (release the link) end it."""

    def open(self) -> None: ...

    def read(self) -> Reading: ...

    def write(self, outputs: Sequence[int]) -> None: ...

    def stop(self) -> None: ...

    def close(self) -> None: ...


@runtime_checkable
class BlockIO(Protocol):
    """A robot that can advance itself and the engine many ticks at once (in compiled code)."""

    def advance(self, engine: Engine | RobotEngine, ticks: int) -> TickBlock: ...


@dataclass
class TickBlock:
    """Consecutive ticks as columns: what the robot read, what the engine did, extra per-tick fields.

    Columns are lists or numpy arrays; ``outputs``, ``counters`` and ``pulses`` have one row per tick.
    """

    start: int  # the tick number of the first row
    masks: Sequence[int] | np.ndarray
    pulses: Sequence[Sequence[int]] | np.ndarray
    events: Sequence[int] | np.ndarray
    rows: Sequence[int] | np.ndarray  # -1: no row fired
    states: Sequence[int] | np.ndarray  # state indices (Machine.states)
    timers: Sequence[int] | np.ndarray
    outputs: Sequence[Sequence[int]] | np.ndarray
    counters: Sequence[Sequence[int]] | np.ndarray
    extra: Mapping[str, Sequence[Any]] = field(default_factory=dict)  # a dict, or the simulator's LazyColumns
    raw: Any = None  # the robot's own per-tick record, if it keeps one (the simulator: its state rows)

    def __len__(self) -> int:
        return len(self.events)

    @staticmethod
    def of_tick(engine: Engine | RobotEngine, reading: Reading, extra: Mapping[str, Any] | None = None) -> TickBlock:
        """The tick the engine just made, after ``reading`` (a robot of several tables: the main table's
        decisions, the other tables' as extra fields)."""
        fields = {**(reading.extra or {}), **(extra or {})}
        if isinstance(engine, RobotEngine):
            fields.update(engine.fields())
        return TickBlock(
            engine.tick - 1,
            [reading.mask],
            [reading.pulses],
            [engine.event],
            [engine.row],
            [engine.state],
            [engine.timer],
            [engine.outputs],
            [tuple(engine.counters)],
            {k: [v] for k, v in fields.items()},
        )


@dataclass(frozen=True)
class RunInfo:
    """What sinks learn when the run starts."""

    engine: Engine | RobotEngine
    tick_s: float
    target: str  # "sim", "txt://192.168.7.2", ...
    ticks: int | None  # planned length, None = until stopped


#: Why a run ended, and the process exit code each reason gives.
EXIT_CODES = {
    "done": 0,
    "stopped": 0,
    "error": 1,
    "link_lost": 3,
    "watchdog": 4,
    "behind": 5,
    "interrupted": 130,
    "terminated": 143,
}


@dataclass(frozen=True)
class RunEnd:
    reason: str  # a key of EXIT_CODES
    ticks: int  # ticks completed
    message: str = ""
    late_ticks: int = 0
    worst_late_s: float = 0.0

    @property
    def complete(self) -> bool:
        """Whether the run did what was asked: its whole length, or until the user stopped an open-ended run."""
        return self.reason in ("done", "stopped")

    @property
    def exit_code(self) -> int:
        return EXIT_CODES[self.reason]


class Sink(Protocol):
    """Observes a run: ``start`` once, ``block`` per batch of ticks, ``end`` once (always, even after a fault)."""

    def start(self, info: RunInfo) -> None: ...

    def block(self, block: TickBlock) -> None: ...

    def end(self, end: RunEnd) -> None: ...


# --- the loop -------------------------------------------------------------------------------------


BLOCK_TICKS = 4096  # ticks per block on the compiled path: few Python round trips, bounded memory


def run(
    engine: Engine | RobotEngine,
    robot: RobotIO,
    *,
    clock: Clock | None = None,
    sinks: Sequence[Sink] = (),
    ticks: int | None = None,
    watchdog: Watchdog | None = None,
    target: str = "",
    behind_limit_s: float | None = None,
    block_ticks: int = BLOCK_TICKS,
) -> RunEnd:
    """Drive ``robot`` with ``engine`` for ``ticks`` ticks (None: until stopped) and return why it ended.

    The robot's outputs are stopped and its link closed on every way out; sinks always get ``end``.
    A bug (any other exception) is re-raised after that, so it is never silent.
    """
    clock = clock or SimulatedClock()
    watchdog = watchdog or Watchdog(None)
    tick_s = engine.machine.table.robot.tick_s
    late = Lateness(tick_s)
    pace = Pace(tick_s, behind_limit_s) if behind_limit_s else None
    info = RunInfo(engine, tick_s, target, ticks)
    started: list[Sink] = []
    end: RunEnd | None = None
    bug: BaseException | None = None
    try:
        with StopRequest().installed() as stop, watchdog.installed(robot.stop):
            robot.open()
            for sink in sinks:
                sink.start(info)
                started.append(sink)
            clock.start()
            if clock.free_running and isinstance(robot, BlockIO):
                _run_blocks(engine, robot, started, ticks, block_ticks, stop)
            else:
                _run_ticks(engine, robot, clock, started, ticks, watchdog, late, pace, stop)
            end = RunEnd("done" if ticks is not None else "stopped", engine.tick)
    except KeyboardInterrupt:
        end = RunEnd("stopped" if ticks is None else "interrupted", engine.tick, N_("stopped by Ctrl-C"))
    except Terminated as exc:
        end = RunEnd("terminated", engine.tick, _why(exc))
    except WatchdogTimeout as exc:
        end = RunEnd("watchdog", engine.tick, _why(exc))
    except LinkLost as exc:
        end = RunEnd("link_lost", engine.tick, _why(exc))
    except Behind as exc:
        end = RunEnd("behind", engine.tick, _why(exc))
    except BaseException as exc:
        end, bug = RunEnd("error", engine.tick, f"{type(exc).__name__}: {exc}"), exc
    finally:
        _shut_down(robot)
        final = end or RunEnd("error", engine.tick, N_("the run ended without a reason"))
        final = RunEnd(final.reason, final.ticks, final.message, late.count, late.worst_s)
        failed = _end_sinks(started, final)
    if bug is not None:
        raise bug
    if failed is not None:  # a sink could not finish (a full disk under the trace): after every sink has ended
        raise failed
    return final


def _why(exc: BaseException) -> str:
    """Why ``exc`` ended the run: its message as raised (a :class:`Message` stays one, to be said in the reader's
    language where it is shown; its text is the English one)."""
    said = exc.args[0] if len(exc.args) == 1 else None
    return said if isinstance(said, Message) else str(exc)


def _end_sinks(sinks: Sequence[Sink], end: RunEnd) -> Exception | None:
    """Tell every sink the run ended, even when one of them fails; returns the first failure."""
    first = None
    for sink in sinks:
        try:
            sink.end(end)
        except Exception as exc:
            first = first or exc
    return first


def exchange(engine: Engine | RobotEngine, robot: RobotIO) -> Reading:
    """One tick's work with a robot: read it, step the engine on what it read, write the outputs; returns the
    reading. The loop does this every tick (inside the watchdog); so does the Gymnasium env when the table
    drives, so that a tick means the same everywhere."""
    reading = robot.read()
    robot.write(engine.step(reading.mask, reading.pulses))
    return reading


def _run_ticks(
    engine: Engine | RobotEngine,
    robot: RobotIO,
    clock: Clock,
    sinks: Sequence[Sink],
    ticks: int | None,
    watchdog: Watchdog,
    late: Lateness,
    pace: Pace | None,
    stop: StopRequest,
) -> None:
    """One tick at a time: the path of real robots and of the real-time rehearsal."""
    while ticks is None or engine.tick < ticks:
        stop.check()
        delay = clock.wait(engine.tick)
        late.note(delay)
        if pace is not None:
            pace.note(engine.tick, clock.behind_s)
        watchdog.arm()
        reading = exchange(engine, robot)
        watchdog.disarm()
        block = TickBlock.of_tick(
            engine, reading, {"late_ms": round(1000 * delay, 3)} if not clock.free_running else None
        )
        for sink in sinks:
            sink.block(block)


def _run_blocks(
    engine: Engine | RobotEngine,
    robot: BlockIO,
    sinks: Sequence[Sink],
    ticks: int | None,
    block_ticks: int,
    stop: StopRequest,
) -> None:
    """Many ticks per call: the compiled simulator."""
    while ticks is None or engine.tick < ticks:
        stop.check()
        n = block_ticks if ticks is None else min(block_ticks, ticks - engine.tick)
        block = robot.advance(engine, n)
        for sink in sinks:
            sink.block(block)


def _shut_down(robot: RobotIO) -> None:
    """Outputs off, then the link closed; a second Ctrl-C or SIGTERM meanwhile cannot skip either."""
    old = {}
    if threading.current_thread() is threading.main_thread():
        for sig in (signal.SIGINT, signal.SIGTERM):
            old[sig] = signal.signal(sig, signal.SIG_IGN)
    try:
        for step in (robot.stop, robot.close):
            with contextlib.suppress(Exception):  # stopping must go on to closing whatever the robot says
                step()
    finally:
        for sig, handler in old.items():
            signal.signal(sig, handler)
