"""A pretend serial device for tests and benchmarks: a real pseudo-terminal whose far end a thread answers.

A client opens :attr:`PtyDevice.device` (``/dev/pts/N``) exactly as it would a controller's serial port;
the emulator on the other end reads what it sends and writes replies, and can misbehave on purpose
(fall silent, hang up). This is a FAKE: it stands in for hardware that is not here.
"""

from __future__ import annotations

import contextlib
import os
import select
import threading
import time
import tty
from dataclasses import dataclass, field
from typing import Any, Self


@dataclass
class Request:
    t: float  # time.monotonic() when it was read whole
    name: str
    fields: dict[str, Any] = field(default_factory=dict)


class PtyDevice:
    """Subclasses implement :meth:`feed` (bytes from the client) and answer with :meth:`send`.

    ``baud`` > 0 paces replies like a serial line at that rate (10 bits a byte); 0 writes them at once."""

    def __init__(self, baud: int = 0) -> None:
        self.baud = baud
        self.master, self._slave = os.openpty()
        tty.setraw(self._slave)  # no echo, no line editing, until the client configures it
        self.device = os.ttyname(self._slave)
        self.log: list[Request] = []
        self.hung_up = False
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._serve, daemon=True, name=f"pty {self.device}")
        self._thread.start()

    # --- observations -----------------------------------------------------------------------------

    def requests(self, name: str | None = None) -> list[Request]:
        return [r for r in list(self.log) if name is None or r.name == name]

    def names(self) -> list[str]:
        return [r.name for r in list(self.log)]

    def wait_for(self, name: str, count: int, timeout_s: float = 10.0) -> bool:
        """Whether ``count`` requests called ``name`` arrived within ``timeout_s``."""
        deadline = time.monotonic() + timeout_s
        while len(self.requests(name)) < count:
            if time.monotonic() > deadline:
                return False
            time.sleep(0.01)
        return True

    def note(self, name: str, **fields: Any) -> None:
        self.log.append(Request(time.monotonic(), name, fields))

    # --- lifecycle --------------------------------------------------------------------------------

    def hang_up(self) -> None:
        """Close our end, as a pulled USB cable would: the client's next read or write fails."""
        self.hung_up = True
        self._stop.set()
        for fd in (self.master, self._slave):
            with contextlib.suppress(OSError):
                os.close(fd)

    def close(self) -> None:
        if not self.hung_up:
            self.hang_up()
        self._thread.join(timeout=2)

    def __enter__(self) -> Self:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    # --- the far end ------------------------------------------------------------------------------

    def feed(self, data: bytes) -> None:
        raise NotImplementedError

    def send(self, data: bytes) -> None:
        """Write ``data`` to the client (one write, as a device's UART buffer would hand it over), paced by
        ``baud`` if set."""
        if self.hung_up:
            return
        if self.baud:
            time.sleep(10 * len(data) / self.baud)
        with contextlib.suppress(OSError):
            os.write(self.master, data)

    def _serve(self) -> None:
        while not self._stop.is_set():
            try:
                ready = select.select([self.master], [], [], 0.05)[0]
                if not ready:
                    continue
                data = os.read(self.master, 4096)
            except OSError:  # no client has the port open (EIO), or we hung up
                if self._stop.is_set():
                    return
                time.sleep(0.005)
                continue
            if data:
                self.feed(data)
