"""The run loop: one engine driving one robot through the :class:`RobotIO` seam, paced by a clock,
observed by sinks, guarded by a watchdog. Every way a table meets a robot goes through :func:`run`.
"""

# Per tick: wait for the clock, read the robot, step the engine, write the outputs, tell the sinks.
# A robot that can run many ticks in compiled code (the simulator) offers ``advance`` and gets whole
# blocks instead; the sinks see the same columns either way. Whatever ends the run (its length,
# Ctrl-C, SIGTERM, a failing or stalled tick, a lost link, a bug), the robot's outputs are stopped
# first, then the link is closed, then the sinks are told why.

from __future__ import annotations

import contextlib
import itertools
import signal
import threading
import time
from collections import deque
from collections.abc import Callable, Iterator, Mapping, Sequence
from contextlib import contextmanager
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Protocol, runtime_checkable

from tablebot.engine import Engine
from tablebot.engine.as_one import RobotEngine
from tablebot.interrupts import Terminated

if TYPE_CHECKING:
    import numpy as np


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
        return TickBlock(engine.tick - 1, [reading.mask], [reading.pulses], [engine.event], [engine.row],
                         [engine.state], [engine.timer], [engine.outputs], [tuple(engine.counters)],
                         {k: [v] for k, v in fields.items()})


@dataclass(frozen=True)
class RunInfo:
    """What sinks learn when the run starts."""

    engine: Engine | RobotEngine
    tick_s: float
    target: str  # "sim", "txt://192.168.7.2", ...
    ticks: int | None  # planned length, None = until stopped


#: Why a run ended, and the process exit code each reason gives.
EXIT_CODES = {"done": 0, "stopped": 0, "error": 1, "link_lost": 3, "watchdog": 4, "behind": 5,
              "interrupted": 130, "terminated": 143}


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


# --- clocks ---------------------------------------------------------------------------------------


class Clock(Protocol):
    """When each tick may start. ``wait(tick)`` blocks until then and returns how late it is (s);
    ``behind_s`` is then how far the table's time (ticks × tick) trails the wall clock since ``start``
    (0 for a clock that has no wall clock to trail)."""

    free_running: bool
    behind_s: float

    def start(self) -> None: ...

    def wait(self, tick: int) -> float: ...


class SimulatedClock:
    """Simulated time: no waiting, never late (the simulator runs as fast as it can)."""

    free_running = True
    behind_s = 0.0

    def start(self) -> None:
        pass

    def wait(self, tick: int) -> float:
        return 0.0


class RealTimeClock:
    """Wall-clock pacing: ticks are due on a grid ``tick_s`` apart, and ``wait`` sleeps until the tick is due.

    A link that paces itself (a TXT answers every 10 ms) is not slowed, and one that answers at once
    (ftrobopy_server on a TXT 4.0, the simulator) is paced without drift. A tick more than half a tick
    late is reported late and the grid starts again from it: a stall is never made up by a burst of ticks.
    What the grid lets slip is kept in ``behind_s``, which :class:`Pace` judges over a window.
    """

    free_running = False

    def __init__(self, tick_s: float, now: Callable[[], float] = time.monotonic,
                 sleep: Callable[[float], None] = time.sleep) -> None:
        self.tick_s, self.now, self.sleep = tick_s, now, sleep
        self.origin, self.anchor, self.anchor_tick = 0.0, 0.0, 0
        self.behind_s = 0.0

    def start(self) -> None:
        self.origin = self.anchor = self.now()
        self.anchor_tick, self.behind_s = 0, 0.0

    def wait(self, tick: int) -> float:
        due = self.anchor + (tick - self.anchor_tick) * self.tick_s
        now = self.now()
        if due > now:
            self.sleep(due - now)
            now = due
        late = now - due
        self.behind_s = now - self.origin - tick * self.tick_s
        if late > self.tick_s / 2:  # a stall, or a link slower than the tick: the grid starts again here
            self.anchor, self.anchor_tick = now, tick
        return late


# --- watchdog -------------------------------------------------------------------------------------


class WatchdogTimeout(Exception):
    """A tick's I/O did not finish within the watchdog's deadline."""


class Watchdog:
    """Bounds each tick's robot I/O: past ``deadline_s`` the tick is abandoned and the run ends.

    In the main thread a SIGALRM timer interrupts even a blocking call; elsewhere a timer thread
    stops the robot's outputs at the deadline and the loop ends when the call returns.
    """

    def __init__(self, deadline_s: float | None) -> None:
        self.deadline_s = deadline_s
        self._use_signal = False
        self._timer: threading.Timer | None = None
        self.fired = False
        self._on_fire: Callable[[], None] = lambda: None

    @contextmanager
    def installed(self, on_fire: Callable[[], None]) -> Iterator[None]:
        self._on_fire, self.fired = on_fire, False  # a watchdog may guard one run after another
        self._use_signal = (self.deadline_s is not None and hasattr(signal, "setitimer")
                            and threading.current_thread() is threading.main_thread())
        previous = signal.signal(signal.SIGALRM, self._alarm) if self._use_signal else None
        try:
            yield
        finally:
            self.disarm()
            if self._use_signal:
                signal.signal(signal.SIGALRM, previous)

    def arm(self) -> None:
        if self.deadline_s is None:
            return
        if self._use_signal:
            signal.setitimer(signal.ITIMER_REAL, self.deadline_s)
        else:
            self._timer = threading.Timer(self.deadline_s, self._thread_fire)
            self._timer.daemon = True
            self._timer.start()

    def disarm(self) -> None:
        if self._use_signal:
            signal.setitimer(signal.ITIMER_REAL, 0)
        elif self._timer is not None:
            self._timer.cancel()
            self._timer = None
        if self.fired:
            raise WatchdogTimeout(self._message())

    def _message(self) -> str:
        return f"a tick's robot I/O took longer than the watchdog's {1000 * (self.deadline_s or 0):g} ms"

    def _alarm(self, signum: int, frame: Any) -> None:
        self.fired = True
        raise WatchdogTimeout(self._message())

    def _thread_fire(self) -> None:
        self.fired = True
        self._on_fire()


class StopRequest:
    """Ctrl-C (SIGINT) and SIGTERM during a run only ask it to stop: the loop stops between ticks (or
    blocks), so every tick it reports has reached every sink and no sink sees half a block. A second
    Ctrl-C interrupts at once (a robot call that never returns cannot hold the user hostage)."""

    def __init__(self) -> None:
        self.signal: int | None = None

    def __call__(self, signum: int, frame: Any) -> None:
        if self.signal is not None and signum == signal.SIGINT:
            raise KeyboardInterrupt
        self.signal = self.signal or signum

    def check(self) -> None:
        if self.signal == signal.SIGTERM:
            raise Terminated("terminated by SIGTERM")
        if self.signal is not None:
            raise KeyboardInterrupt

    @contextmanager
    def installed(self) -> Iterator[StopRequest]:
        if threading.current_thread() is not threading.main_thread():
            yield self
            return
        previous = {sig: signal.signal(sig, self) for sig in (signal.SIGINT, signal.SIGTERM)}
        try:
            yield self
        finally:
            for sig, handler in previous.items():
                signal.signal(sig, handler)


# --- the loop -------------------------------------------------------------------------------------


@dataclass
class Lateness:
    """Ticks that started late (by more than half a tick) and the worst delay: what the live view and the
    summary show."""

    tick_s: float
    count: int = 0
    worst_s: float = 0.0

    def note(self, late_s: float) -> None:
        if late_s > self.tick_s / 2:
            self.count += 1
        self.worst_s = max(self.worst_s, late_s)


#: The window :class:`Pace` judges a run over (s): the table's time may fall at most the behind-limit
#: behind the wall clock within any this long. With the default limit of 0.5 s: one stall of 0.5 s, or
#: ticks 10 % longer than the table's tick on average.
BEHIND_WINDOW_S = 5.0


class Pace:
    """Whether the run keeps the table's tick: the run ends as ``behind`` when the table's time falls more
    than ``limit_s`` behind the wall clock within any ``window_s`` — one long stall, or a robot whose every
    tick is a little too slow (which the clock's restarted grid would otherwise hide while the table's
    timers run slow). ``note`` takes each tick's number and the clock's ``behind_s``."""

    def __init__(self, tick_s: float, limit_s: float, window_s: float = BEHIND_WINDOW_S) -> None:
        self.tick_s, self.limit_s, self.window_s = tick_s, limit_s, window_s
        self._ticks: deque[tuple[int, float]] = deque()  # (tick, wall time since start) of recent ticks

    def note(self, tick: int, behind_s: float) -> None:
        wall = tick * self.tick_s + behind_s
        ticks = self._ticks
        ticks.append((tick, wall))
        while len(ticks) > 1 and ticks[1][1] <= wall - self.window_s:  # the first stays at or before the window
            ticks.popleft()
        first_tick, first_wall = ticks[0]
        fell = (wall - first_wall) - (tick - first_tick) * self.tick_s
        if fell > self.limit_s:
            raise _Behind(self._message(fell, tick - first_tick, wall - first_wall))

    def _message(self, fell: float, ticks: int, wall: float) -> str:
        longest = max(b[1] - a[1] for a, b in itertools.pairwise(self._ticks))
        limit = f"limit {self.limit_s:g} s within any {self.window_s:g} s"
        if longest - self.tick_s >= fell / 2:  # mostly one gap: a stall, not a slow robot
            return (f"the run fell {fell:.2f} s behind the wall clock ({limit}): one tick started "
                    f"{1000 * longest:.0f} ms after the one before it (the robot's link or this machine stalled), "
                    "and the table's timers would stretch by as much")
        ms, mean = 1000 * self.tick_s, 1000 * wall / ticks
        slow = 100 * (mean / ms - 1)
        return (f"the robot cannot keep the table's {ms:g} ms tick: over the last {wall:.1f} s its ticks took "
                f"{mean:.1f} ms on average, so the table's timers would run {slow:.0f} % slow ({fell:.2f} s behind "
                f"the wall clock; {limit}). Give the robot file a longer tick_ms (write the table's timers as "
                "times, such as 500ms, so they keep their length) or use a faster link; --behind-limit 0 runs on "
                "with slow timers")


class _Behind(Exception):
    pass


BLOCK_TICKS = 4096  # ticks per block on the compiled path: few Python round trips, bounded memory


def run(engine: Engine | RobotEngine, robot: RobotIO, *, clock: Clock | None = None, sinks: Sequence[Sink] = (),
        ticks: int | None = None, watchdog: Watchdog | None = None, target: str = "",
        behind_limit_s: float | None = None, block_ticks: int = BLOCK_TICKS) -> RunEnd:
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
        end = RunEnd("stopped" if ticks is None else "interrupted", engine.tick, "stopped by Ctrl-C")
    except Terminated as exc:
        end = RunEnd("terminated", engine.tick, str(exc))
    except WatchdogTimeout as exc:
        end = RunEnd("watchdog", engine.tick, str(exc))
    except LinkLost as exc:
        end = RunEnd("link_lost", engine.tick, str(exc))
    except _Behind as exc:
        end = RunEnd("behind", engine.tick, str(exc))
    except BaseException as exc:
        end, bug = RunEnd("error", engine.tick, f"{type(exc).__name__}: {exc}"), exc
    finally:
        _shut_down(robot)
        final = end or RunEnd("error", engine.tick, "the run ended without a reason")
        final = RunEnd(final.reason, final.ticks, final.message, late.count, late.worst_s)
        failed = _end_sinks(started, final)
    if bug is not None:
        raise bug
    if failed is not None:  # a sink could not finish (a full disk under the trace): after every sink has ended
        raise failed
    return final


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


def _run_ticks(engine: Engine | RobotEngine, robot: RobotIO, clock: Clock, sinks: Sequence[Sink], ticks: int | None,
               watchdog: Watchdog, late: Lateness, pace: Pace | None, stop: StopRequest) -> None:
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
        block = TickBlock.of_tick(engine, reading, {"late_ms": round(1000 * delay, 3)} if not clock.free_running
                                  else None)
        for sink in sinks:
            sink.block(block)


def _run_blocks(engine: Engine | RobotEngine, robot: BlockIO, sinks: Sequence[Sink], ticks: int | None,
                block_ticks: int, stop: StopRequest) -> None:
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
