"""How a run keeps time and is guarded (:func:`tablebot.loop.run` uses them all): the clocks that pace its ticks,
the watchdog that bounds each tick's robot I/O, the stop request that turns Ctrl-C and SIGTERM into a stop between
ticks, and the lateness and pace that judge whether the robot keeps the table's tick."""

from __future__ import annotations

import itertools
import signal
import threading
import time
from collections import deque
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from typing import Any, Protocol

from tablebot.i18n import N_, Message
from tablebot.interrupts import Terminated

__all__ = [
    "BEHIND_WINDOW_S",
    "Behind",
    "Clock",
    "Lateness",
    "Pace",
    "RealTimeClock",
    "SimulatedClock",
    "StopRequest",
    "Watchdog",
    "WatchdogTimeout",
]


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

    def __init__(
        self, tick_s: float, now: Callable[[], float] = time.monotonic, sleep: Callable[[float], None] = time.sleep
    ) -> None:
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
        self._use_signal = (
            self.deadline_s is not None
            and hasattr(signal, "setitimer")
            and threading.current_thread() is threading.main_thread()
        )
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

    def _message(self) -> Message:
        return N_("a tick's robot I/O took longer than the watchdog's {ms:g} ms", ms=1000 * (self.deadline_s or 0))

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
            raise Terminated(N_("terminated by SIGTERM"))
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


# --- keeping the tick -----------------------------------------------------------------------------


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
            raise Behind(self._message(fell, tick - first_tick, wall - first_wall))

    def _message(self, fell: float, ticks: int, wall: float) -> Message:
        longest = max(b[1] - a[1] for a, b in itertools.pairwise(self._ticks))
        limit = N_("limit {limit:g} s within any {window:g} s", limit=self.limit_s, window=self.window_s)
        if longest - self.tick_s >= fell / 2:  # mostly one gap: a stall, not a slow robot
            return N_(
                "the run fell {fell:.2f} s behind the wall clock ({limit}): one tick started {gap:.0f} ms after "
                "the one before it (the robot's link or this machine stalled), and the table's timers would "
                "stretch by as much",
                fell=fell,
                limit=limit,
                gap=1000 * longest,
            )
        ms, mean = 1000 * self.tick_s, 1000 * wall / ticks
        return N_(
            "the robot cannot keep the table's {ms:g} ms tick: over the last {wall:.1f} s its ticks took "
            "{mean:.1f} ms on average, so the table's timers would run {slow} slow ({fell:.2f} s behind "
            "the wall clock; {limit}). Give the robot file a longer tick_ms (write the table's timers as times, "
            "such as 500ms, so they keep their length) or use a faster link; --behind-limit 0 runs on with slow "
            "timers",
            ms=ms,
            wall=wall,
            mean=mean,
            slow=f"{100 * (mean / ms - 1):.0f} %",
            fell=fell,
            limit=limit,
        )


class Behind(Exception):
    """The run fell behind the wall clock by more than its limit (:class:`Pace`)."""
