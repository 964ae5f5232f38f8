"""A ROBO Interface as a :class:`tablebot.loop.RobotIO`: one exchange per engine tick on its serial port,
outputs off on every way out.

Each tick's ``write`` sends the engine's outputs at once and keeps the reply, whose inputs the next ``read``
returns: the engine decides on inputs one exchange old. ``open`` makes a first exchange with every output
off, so tick 0 has inputs too. The ROBO Interface has no counters.
"""

from __future__ import annotations

import threading
from collections.abc import Sequence

from tablebot.hw.roboif import protocol as wire
from tablebot.hw.roboif.link import RoboifLink
from tablebot.hw.roboif.wiring import RoboifWiring
from tablebot.loop import LinkLost, Reading

OFF = (0, [0] * wire.N_OUTPUTS)


class RoboifRobot:
    """The ROBO Interface on serial ``device``; a reply missing for ``link_timeout_s`` ends the run."""

    def __init__(self, wiring: RoboifWiring, device: str, *, link_timeout_s: float = 0.05):
        self.wiring = wiring
        self.link = RoboifLink(device, reply_timeout_s=link_timeout_s)
        self.greeting = b""
        self._reading: Reading | None = None
        self._stopped = False
        self._lock = threading.Lock()  # the watchdog may call stop() from its timer thread

    @property
    def target(self) -> str:
        return f"roboif://{self.link.device}"

    def connect(self) -> bytes:
        """Open the port and greet the interface (nothing moves yet); LinkLost if it does not answer as one."""
        self.link.connect()
        try:
            self.greeting = self.link.hello()
        except LinkLost:
            self.link.close()
            raise
        return self.greeting

    # --- RobotIO ----------------------------------------------------------------------------------

    def open(self) -> None:
        if not self.link.port.is_open:
            self.connect()
        self._stopped = False
        with self._lock:
            first = self.link.exchange(*OFF)
        self._reading = self._reading_of(first)

    def read(self) -> Reading:
        if self._reading is None:
            raise LinkLost(f"{self.target} is not online (open() was not called or failed)")
        return self._reading

    def write(self, outputs: Sequence[int]) -> None:
        bits, pwm = OFF if self._stopped else self.wiring.outputs(outputs)
        with self._lock:
            reply = self.link.exchange(bits, pwm)
        self._reading = self._reading_of(reply)

    def stop(self) -> None:
        """Every output off in the very next exchange (even after a fault); never raises."""
        self._stopped = True
        if not self._lock.acquire(timeout=max(0.05, 2 * self.link.reply_timeout_s)):
            return  # another thread is mid-exchange: the loop calls stop() again when it returns
        try:
            if self.link.online:
                self.link.send_best_effort(*OFF, max(0.2, 2 * self.link.reply_timeout_s))
        except Exception:
            pass
        finally:
            self._lock.release()

    def close(self) -> None:
        """The farewell (after :meth:`stop`'s exchange with every output off), then the port closed."""
        self.link.close()

    def _reading_of(self, reply: wire.Inputs) -> Reading:
        previous = self._reading.mask if self._reading is not None else 0
        return Reading(self.wiring.mask(reply, previous), (), self.wiring.raw(reply) or None)
