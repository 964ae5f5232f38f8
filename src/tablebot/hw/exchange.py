"""What every live controller's :class:`tablebot.loop.RobotIO` shares: one exchange per engine tick whose reply
the next ``read`` returns, outputs off on every way out, and counters read as pulses since the last reply.

A controller subclasses :class:`ExchangeRobot` with its link, its wiring and four small hooks (``OFF``,
``_command``, ``_exchange``, ``_send_off``) and its own ``open``, ``close`` and ``_reading_of``.
"""

from __future__ import annotations

import threading
from collections.abc import Sequence
from typing import Any

from tablebot.i18n import N_
from tablebot.loop import LinkLost, Reading

COUNTER_WRAP = 1 << 16  # the TXT's and the ROBO TX's counters count up in 16 bits


class ExchangeRobot:
    """The tick-by-tick part of a live controller: ``read``, ``write`` and the safe ``stop``."""

    OFF: Any  # the controller's command with every output off
    link: Any  # the controller's link: ``reply_timeout_s``, ``online``

    def __init__(self) -> None:
        self._reading: Reading | None = None
        self._counts: list[int] = []
        self._stopped = False
        self._lock = threading.Lock()  # the watchdog may call stop() from its timer thread

    @property
    def target(self) -> str:
        raise NotImplementedError

    def read(self) -> Reading:
        if self._reading is None:
            raise LinkLost(N_("{target} is not online (open() was not called or failed)", target=self.target))
        return self._reading

    def write(self, outputs: Sequence[int]) -> None:
        command = self.OFF if self._stopped else self._command(outputs)
        with self._lock:
            reply = self._exchange(command)
        self._reading = self._reading_of(reply)

    def stop(self) -> None:
        """Every output off in the very next exchange (even after a fault); never raises."""
        self._stopped = True
        if not self._lock.acquire(timeout=max(0.05, 2 * self.link.reply_timeout_s)):
            return  # another thread is mid-exchange: the loop calls stop() again when it returns
        try:
            if self.link.online:
                self._send_off(self._shutdown_s)
        except Exception:
            pass
        finally:
            self._lock.release()

    @property
    def _shutdown_s(self) -> float:
        """How long stopping waits for each reply: enough for a live link, short for a dead one."""
        return max(0.2, 2 * self.link.reply_timeout_s)

    def _first_exchange(self, counters: Sequence[int] = ()) -> None:
        """``open``'s first exchange, every output off: tick 0 has inputs, and counting starts here."""
        self._stopped = False
        with self._lock:
            first = self._exchange(self.OFF)
        self._counts = [first.counter_values[t] for t in counters]
        self._reading = self._reading_of(first)

    def _previous_mask(self) -> int:
        """Last tick's input bits (0 before the first reply): an analog input's hysteresis remembers them."""
        return self._reading.mask if self._reading is not None else 0

    def _pulses(self, values: Sequence[int], counters: Sequence[int]) -> tuple[int, ...]:
        """Pulses per robot counter since the last reply: a count that went back (the counter was reset) gives
        0 and a new start."""
        pulses = []
        for i, terminal in enumerate(counters):
            step = (values[terminal] - self._counts[i]) % COUNTER_WRAP
            pulses.append(0 if step >= COUNTER_WRAP // 2 else step)
            self._counts[i] = values[terminal]
        return tuple(pulses)

    # --- each controller's own -------------------------------------------------------------------

    def _command(self, outputs: Sequence[int]) -> Any:
        """The engine's outputs as the controller's command."""
        raise NotImplementedError

    def _exchange(self, command: Any) -> Any:
        """Send ``command``, return the reply (LinkLost when there is none)."""
        raise NotImplementedError

    def _send_off(self, timeout_s: float) -> None:
        """Send :attr:`OFF` once more, waiting at most ``timeout_s`` for the reply; may raise."""
        raise NotImplementedError

    def _reading_of(self, reply: Any) -> Reading:
        raise NotImplementedError
