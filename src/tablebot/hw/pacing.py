"""Real-time pacing for a robot whose link may pace itself too: a TXT answers one exchange every 10 ms,
ftrobopy_server on a TXT 4.0 answers at once, the simulator never waits.

Ticks are due on a fixed grid (``tick_s`` apart), so a link that answers at once is paced without drift.
A tick that starts later than half a tick is reported as late and the grid starts again from it: a link
that cannot catch up (a TXT after a stall, or one whose exchanges take a little longer than the tick) is
then not counted late on every later tick, and a single stall longer than the loop's behind-limit ends
the run (see :class:`tablebot.loop.Lateness`).
"""

from __future__ import annotations

import time
from collections.abc import Callable


class PacedClock:
    """A :class:`tablebot.loop.Clock`: ``wait(tick)`` sleeps until the tick is due and returns how late it
    started (seconds)."""

    free_running = False

    def __init__(self, tick_s: float, now: Callable[[], float] = time.monotonic,
                 sleep: Callable[[float], None] = time.sleep):
        self.tick_s, self.now, self.sleep = tick_s, now, sleep
        self.anchor, self.anchor_tick = 0.0, 0

    def start(self) -> None:
        self.anchor, self.anchor_tick = self.now(), 0

    def wait(self, tick: int) -> float:
        due = self.anchor + (tick - self.anchor_tick) * self.tick_s
        ahead = due - self.now()
        if ahead > 0:
            self.sleep(ahead)
            return 0.0
        late = -ahead
        if late > self.tick_s / 2:  # a stall, or a link slower than the tick: the grid starts again here
            self.anchor, self.anchor_tick = due + late, tick
        return late
