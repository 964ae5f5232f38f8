"""The host side of the ROBO Interface's serial online protocol: the greeting, one exchange at a time with a
deadline, the farewell.

The exchange reply carries no header or checksum, so a reply can only be judged by its size and timing:
too few bytes by the deadline, bytes before a request was sent, or bytes beyond the 21 expected are each a
lost link (the stream is out of step and nothing after it can be trusted). Every failure becomes
:class:`tablebot.loop.LinkLost` with a sentence saying what happened. Source: see :mod:`tablebot.hw.roboif.protocol`.
"""

from __future__ import annotations

import contextlib
import time
from collections.abc import Sequence

from tablebot.hw.roboif import protocol as wire
from tablebot.hw.serial_port import PortInfo, SerialPort, serial_ports
from tablebot.i18n import N_
from tablebot.loop import LinkLost

SETUP_TIMEOUT_S = 1.0
#: USB serial ports that are known to be other controllers: never greeted by ``roboif://auto``
#: (the ROBO TX Controller 221d:1000, the ftDuino 1c40:0538).
NOT_A_ROBO_INTERFACE = {(0x221D, 0x1000), (0x1C40, 0x0538)}


def candidates(ports: Sequence[PortInfo] | None = None) -> list[PortInfo]:
    """Ports that may hold a ROBO Interface: its serial port has no USB id of its own (it sits behind any
    USB-serial adapter), so every port but those known to be another controller."""
    ports = serial_ports() if ports is None else ports
    return [p for p in ports if (p.vid, p.pid) not in NOT_A_ROBO_INTERFACE]


class RoboifLink:
    """The ROBO Interface on serial ``device``; an exchange must be answered within ``reply_timeout_s``."""

    def __init__(self, device: str, reply_timeout_s: float = 0.05, setup_timeout_s: float = SETUP_TIMEOUT_S) -> None:
        self.device = device
        self.reply_timeout_s, self.setup_timeout_s = reply_timeout_s, setup_timeout_s
        self.port = SerialPort(device, wire.BAUD)
        self.online = False  # greeted: outputs may be set and must be stopped at the end
        self._owed = 0  # reply bytes still to come (a reply a signal cut short, or one given up on)
        self._trusted = True

    def connect(self) -> None:
        self.port.open()
        self._owed, self._trusted = 0, True

    def close(self) -> None:
        """Say goodbye (0xA2, as libroboint's CloseFtDevice) if we said hello, then close the port; never raises."""
        if self.online and self.port.is_open:
            deadline = time.monotonic() + max(0.2, 2 * self.reply_timeout_s)
            with contextlib.suppress(LinkLost):
                self.port.write(wire.BYE, deadline)
                self._owed += 1
                self._discard_owed(deadline)
        self.online = False
        self.port.close()

    def hello(self) -> bytes:
        """The greeting; the interface answers 5 bytes starting with 0x5E (anything else: not a ROBO Interface)."""
        deadline = time.monotonic() + self.setup_timeout_s
        self._expect_quiet(N_("before the greeting"))
        self.port.write(wire.HELLO, deadline)
        reply = self.port.read(wire.HELLO_REPLY_BYTES, deadline, N_("the answer to the greeting"))
        if reply[0] != wire.HELLO_OK:
            self._trusted = False
            raise LinkLost(
                N_(
                    "wrong answer from {device}: {reply} to the greeting (a ROBO Interface answers "
                    "0x{ok:02x} first): is this a ROBO Interface?",
                    device=self.device,
                    reply=reply.hex(" "),
                    ok=wire.HELLO_OK,
                )
            )
        self.online = True
        self._expect_quiet(N_("after the greeting's answer"), settle_s=0.005)
        return reply

    def exchange(self, directions: int, pwm: Sequence[int], timeout_s: float | None = None) -> wire.Inputs:
        """Send the outputs, get the inputs back (within ``timeout_s``; default: the reply timeout of a run)."""
        if not self._trusted:
            raise LinkLost(N_("{device} was out of step earlier: its replies cannot be trusted", device=self.device))
        timeout_s = timeout_s or self.reply_timeout_s
        deadline = time.monotonic() + timeout_s
        self.port.write(b"", deadline)  # the rest of a request a signal cut short: its reply is owed
        self._discard_owed(deadline)
        self._expect_quiet(N_("before a request was sent"))
        self._owed += wire.REPLY_BYTES
        self.port.write(wire.exchange(directions, list(pwm)), deadline)
        data = self.port.read(
            wire.REPLY_BYTES,
            deadline,
            N_("the {size}-byte reply within {ms:.0f} ms", size=wire.REPLY_BYTES, ms=1000 * timeout_s),
        )
        self._owed -= wire.REPLY_BYTES
        self._expect_quiet(N_("beyond the {size}-byte reply", size=wire.REPLY_BYTES))
        return wire.decode(data)

    def send_best_effort(self, directions: int, pwm: Sequence[int], timeout_s: float) -> bool:
        """Send an exchange even after a fault, reading what replies come within ``timeout_s`` without trusting
        them; True if the whole request went out. Never raises (this is how outputs get stopped)."""
        if not self.port.is_open:
            return False
        deadline = time.monotonic() + timeout_s
        try:
            self.port.write(wire.exchange(directions, list(pwm)), deadline)
        except LinkLost:
            return False
        self._owed += wire.REPLY_BYTES
        with contextlib.suppress(LinkLost):
            self._discard_owed(deadline)
        return True

    def _expect_quiet(self, when: str, settle_s: float = 0.0) -> None:
        """Bytes nobody asked for mean the stream is out of step (or the device is not what we think)."""
        if settle_s:
            time.sleep(settle_s)
        extra = self.port.pending()
        if extra:
            self._trusted = False
            raise LinkLost(
                N_(
                    "garbage from {device}: {count} unexpected bytes {when} ({first}{more})",
                    device=self.device,
                    count=len(extra),
                    when=when,
                    first=extra[:8].hex(" "),
                    more=" ..." if len(extra) > 8 else "",
                )
            )

    def _discard_owed(self, deadline: float) -> None:
        while self._owed > 0:
            self._owed -= len(self.port.read_some(self._owed, deadline, "a reply still owed"))


def find(ports: Sequence[PortInfo] | None = None, timeout_s: float = 0.5) -> str | None:
    """The first candidate port whose device answers the greeting as a ROBO Interface (then bid farewell)."""
    for port in candidates(ports):
        link = RoboifLink(port.device, setup_timeout_s=timeout_s)
        try:
            link.connect()
            link.hello()
            return port.device
        except LinkLost:
            continue
        finally:
            link.close()
    return None
