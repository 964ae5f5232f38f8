"""A ROBO TX Controller as a :class:`tablebot.loop.RobotIO`: one fish.X1 exchange per engine tick, outputs off
on every way out.

Each tick's ``write`` sends the engine's outputs at once and keeps the reply, whose inputs the next ``read``
returns: the engine decides on inputs one exchange old and its decisions reach the motors without waiting a
tick. ``open`` configures the inputs and makes a first exchange with every output off, so tick 0 has inputs.
"""

from __future__ import annotations

import threading
from collections.abc import Sequence

from tablebot.hw.robotx import protocol as wire
from tablebot.hw.robotx.link import RobotxLink
from tablebot.hw.robotx.wiring import RobotxWiring
from tablebot.loop import LinkLost, Reading

ZERO = [0] * wire.N_OUTPUTS
COUNTER_WRAP = 1 << 16


class RobotxRobot:
    """The ROBO TX on serial ``device``; a reply missing for ``link_timeout_s`` (or malformed) ends the run."""

    def __init__(self, wiring: RobotxWiring, device: str, *, link_timeout_s: float = 0.05):
        self.wiring = wiring
        self.link = RobotxLink(device, reply_timeout_s=link_timeout_s)
        self.info: wire.Info | None = None
        self._reading: Reading | None = None
        self._counts: list[int] = []
        self._stopped = False
        self._lock = threading.Lock()  # the watchdog may call stop() from its timer thread

    @property
    def target(self) -> str:
        return f"robotx://{self.link.device}"

    def connect(self) -> wire.Info:
        """Open the port and ask the controller who it is (nothing moves yet)."""
        self.link.connect()
        try:
            self.info = self.link.hello()
        except LinkLost:
            self.link.close()
            raise
        return self.info

    # --- RobotIO ----------------------------------------------------------------------------------

    def open(self) -> None:
        """Configure inputs and outputs, then make a first exchange with every output off."""
        if not self.link.port.is_open:
            self.connect()
        self._stopped = False
        self.link.configure(self.wiring.config())
        with self._lock:
            first = self.link.exchange(ZERO)
        self._counts = [first.counter_values[t] for t in self.wiring.counters]
        self._reading = self._reading_of(first)

    def read(self) -> Reading:
        if self._reading is None:
            raise LinkLost(f"{self.target} is not online (open() was not called or failed)")
        return self._reading

    def write(self, outputs: Sequence[int]) -> None:
        duty = ZERO if self._stopped else self.wiring.duty(outputs)
        with self._lock:
            reply = self.link.exchange(duty)
        self._reading = self._reading_of(reply)

    def stop(self) -> None:
        """Zero duty on every output in the very next exchange (even after a fault); never raises."""
        self._stopped = True
        if not self._lock.acquire(timeout=max(0.05, 2 * self.link.reply_timeout_s)):
            return  # another thread is mid-exchange: the loop calls stop() again when it returns
        try:
            if self.link.online:
                self.link.send_best_effort(ZERO, max(0.2, 2 * self.link.reply_timeout_s))
        except Exception:
            pass
        finally:
            self._lock.release()

    def close(self) -> None:
        """Close the port (fish.X1 has no "go offline" command: the zero exchange of :meth:`stop` came first)."""
        self.link.close()

    # --- inputs -----------------------------------------------------------------------------------

    def _reading_of(self, reply: wire.Inputs) -> Reading:
        previous = self._reading.mask if self._reading is not None else 0  # hysteresis remembers last tick
        return Reading(self.wiring.mask(reply, previous), self._pulses(reply.counter_values),
                       self.wiring.raw(reply) or None)

    def _pulses(self, values: Sequence[int]) -> tuple[int, ...]:
        """Pulses per robot counter since the last reply: counts go up in 16 bits; a count that went back (the
        counter was reset) gives 0 and a new start."""
        pulses = []
        for i, terminal in enumerate(self.wiring.counters):
            step = (values[terminal] - self._counts[i]) % COUNTER_WRAP
            pulses.append(0 if step >= COUNTER_WRAP // 2 else step)
            self._counts[i] = values[terminal]
        return tuple(pulses)
