"""The host side of fish.X1 on a serial port: one request at a time, every reply checked (frame, checksum,
reply code, transaction id, session id) before it is trusted, a deadline on every reply, and a stream
that stays in step when Ctrl-C cuts a request or a reply short.

Every failure (no port, silence, garbage, a bad checksum, a wrong answer, a new session, a pulled cable)
becomes :class:`tablebot.loop.LinkLost` with a sentence saying what happened; nothing here prints or
starts threads. Sources: see :mod:`tablebot.hw.robotx.protocol`.
"""

from __future__ import annotations

import contextlib
import time
from collections.abc import Sequence

from tablebot.hw.robotx import protocol as wire
from tablebot.hw.robotx.protocol import Command, Frame
from tablebot.hw.serial_port import PortInfo, SerialPort, serial_ports
from tablebot.i18n import N_
from tablebot.loop import LinkLost

#: The USB id of a ROBO TX Controller (a USB CDC serial port "ROBO TX Controller" by "fischertechnik"), as
#: Linux logs it when one is plugged in (cvjb.de, "ROBOPro and Fischertechnik ROBO TX via USB cable with
#: openSUSE 13.1", 2014); fttxpy (``fttxpy/dev_helper.py``) finds it by the same product name.
USB_ID = (0x221D, 0x1000)
PRODUCT = "ROBO TX Controller"
#: ftMscLib opens the port at 38400 baud ("current 38400 fixed"); on USB CDC the rate does not matter.
BAUD = 38400
SETUP_TIMEOUT_S = 1.0  # echo, info, configuration
MAX_JUNK = 4096  # bytes skipped before the first frame (the controller's shell may have printed a prompt)


def candidates(ports: Sequence[PortInfo] | None = None) -> list[PortInfo]:
    """Ports that may be a ROBO TX: its USB id or product name first, then Bluetooth serial ports."""
    ports = serial_ports() if ports is None else ports
    usb = [p for p in ports if (p.vid, p.pid) == USB_ID or PRODUCT.lower() in p.product.lower()]
    bluetooth = [p for p in ports if "rfcomm" in p.device and p not in usb]
    return usb + bluetooth


class RobotxLink:
    """fish.X1 on ``device``; an exchange must be answered within ``reply_timeout_s``."""

    def __init__(self, device: str, reply_timeout_s: float = 0.05, setup_timeout_s: float = SETUP_TIMEOUT_S) -> None:
        self.device = device
        self.reply_timeout_s, self.setup_timeout_s = reply_timeout_s, setup_timeout_s
        self.port = SerialPort(device, BAUD)
        self.tid = 0  # the last transaction id sent (the first request of a connection carries 1)
        self.sid: int | None = None  # the controller's session id, once it gave one
        self.online = False  # outputs may have been set: they must be stopped at the end
        self._owed = 0  # replies still to come for requests sent (a reply a signal cut short, or one given up on)
        self._trusted = True  # False after a malformed or wrong reply: later bytes cannot be relied on

    # --- connection -------------------------------------------------------------------------------

    def connect(self) -> None:
        self.port.open()
        self.tid, self.sid, self._owed, self._trusted = 0, None, 0, True

    def close(self) -> None:
        self.online = False
        self.port.close()

    def hello(self) -> wire.Info:
        """Echo (the controller starts a session and names its id), then ask who it is."""
        self._request(Command.ECHO, (), self.setup_timeout_s, first=True)
        reply = self._request(Command.INFO, ((wire.TA_LOCAL, b""),), self.setup_timeout_s)
        return wire.decode_info(self._area(reply, Command.INFO, wire.INFO_BYTES))

    # --- commands ---------------------------------------------------------------------------------

    def configure(self, config: wire.Config) -> None:
        self.online = True  # from here on the controller may drive outputs
        self._request(Command.CONFIG, ((wire.TA_LOCAL, wire.config(config)),), self.setup_timeout_s)

    def exchange(self, duty: Sequence[int], timeout_s: float | None = None) -> wire.Inputs:
        """Send O1..O8's duty, get the inputs back (within ``timeout_s``; default: the reply timeout of a run)."""
        self.online = True
        reply = self._request(
            Command.EXCHANGE, ((wire.TA_LOCAL, wire.output(list(duty))),), timeout_s or self.reply_timeout_s
        )
        return wire.decode_inputs(self._area(reply, Command.EXCHANGE, wire.INPUT_BYTES))

    def send_best_effort(self, duty: Sequence[int], timeout_s: float) -> bool:
        """Send an exchange even after a fault, then read what comes within ``timeout_s`` without trusting it;
        True if the whole request went out. Never raises (this is how outputs get stopped)."""
        if not self.port.is_open:
            return False
        deadline = time.monotonic() + timeout_s
        frame = self._frame(Command.EXCHANGE, ((wire.TA_LOCAL, wire.output(list(duty))),))
        try:
            self.port.write(frame, deadline)
        except LinkLost:
            return False
        self._owed += 1
        with contextlib.suppress(LinkLost):
            self._discard_owed(deadline)
        return True

    # --- one request, one reply -------------------------------------------------------------------

    def _frame(self, command: Command, areas: tuple[tuple[int, bytes], ...]) -> bytes:
        self.tid = self.tid % 0xFFFF + 1  # 1..65535
        return wire.encode(Frame(command, self.tid, self.sid or 0, areas))

    def _request(
        self, command: Command, areas: tuple[tuple[int, bytes], ...], timeout_s: float, first: bool = False
    ) -> Frame:
        if not self._trusted:
            raise LinkLost(
                N_(
                    "{device} sent a malformed or wrong reply earlier: its replies cannot be trusted",
                    device=self.device,
                )
            )
        deadline = time.monotonic() + timeout_s
        self.port.write(b"", deadline)  # the rest of a request a signal cut short (its reply is owed)
        self._discard_owed(deadline)
        frame = self._frame(command, areas)
        self._owed += 1
        self.port.write(frame, deadline)
        what = N_("the reply to {name} within {ms:.0f} ms", name=command.name, ms=1000 * timeout_s)
        try:
            reply = self._read_frame(deadline, what, skip_junk=first)
        except wire.WireError as exc:
            self._trusted = False
            raise LinkLost(N_("garbage from {device}: {exc}", device=self.device, exc=exc.args[0])) from None
        self._owed -= 1
        self._check(reply, command)
        return reply

    def _check(self, reply: Frame, command: Command) -> None:
        problem = ""
        if reply.command != command.reply:
            problem = N_(
                "reply code {code} to {name} (expected {expected})",
                code=reply.command,
                name=command.name,
                expected=command.reply,
            )
        elif reply.tid != self.tid:
            problem = N_("the reply to transaction {got} where {sent} was sent", got=reply.tid, sent=self.tid)
        elif self.sid is not None and reply.sid != self.sid:
            problem = N_(
                "session {got} where it was {was}: the controller started a new session (it ended the online link)",
                got=reply.sid,
                was=self.sid,
            )
        if problem:
            self._trusted = False
            raise LinkLost(N_("wrong answer from {device}: {problem}", device=self.device, problem=problem))
        if self.sid is None:
            self.sid = reply.sid  # the controller names the session in its reply to the first request

    def _area(self, reply: Frame, command: Command, size: int) -> bytes:
        data = reply.area(wire.TA_LOCAL)
        if data is None or len(data) != size:
            self._trusted = False
            got = N_("no data for the controller") if data is None else N_("{count} bytes", count=len(data))
            raise LinkLost(
                N_(
                    "wrong answer from {device}: {got} in the reply to {name} (expected {size} bytes)",
                    device=self.device,
                    got=got,
                    name=command.name,
                    size=size,
                )
            )
        return data

    def _read_frame(self, deadline: float, what: str, skip_junk: bool = False) -> Frame:
        start = self._start(deadline, what) if skip_junk else self.port.read(4, deadline, what)
        rest = self.port.read(wire.frame_length(start) - 4, deadline, what)
        return wire.decode(start + rest)

    def _start(self, deadline: float, what: str) -> bytes:
        """The first four bytes of a frame, skipping anything before ``STX 0x55`` (a shell prompt)."""
        previous = -1
        for _ in range(MAX_JUNK):
            byte = self.port.read(1, deadline, what)[0]
            if previous == wire.STX and byte == wire.MARK:
                return bytes((wire.STX, wire.MARK)) + self.port.read(2, deadline, what)
            previous = byte
        raise wire.WireError(
            N_("{MAX_JUNK} bytes without a fish.X1 frame: is this a ROBO TX Controller?", MAX_JUNK=MAX_JUNK)
        )

    def _discard_owed(self, deadline: float) -> None:
        """Read and drop the replies still owed (each frame found by its start, whatever came before)."""
        while self._owed > 0:
            with contextlib.suppress(wire.WireError):
                self._read_frame(deadline, N_("a reply still owed"), skip_junk=True)
            self._owed -= 1


def find(ports: Sequence[PortInfo] | None = None, timeout_s: float = 0.5) -> tuple[str, wire.Info] | None:
    """The first candidate port that answers fish.X1 (an echo, then who it is), with what it said."""
    for port in candidates(ports):
        link = RobotxLink(port.device, setup_timeout_s=timeout_s)
        try:
            link.connect()
            return port.device, link.hello()
        except LinkLost:
            continue
        finally:
            link.close()
    return None
