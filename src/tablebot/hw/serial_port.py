"""A serial device for a controller's online protocol: opened raw and exclusive with pyserial, then read and
written byte-exact against deadlines, so that silence, a short reply or a pulled cable becomes
:class:`tablebot.loop.LinkLost` with a sentence saying what happened (never a hang, never a traceback).

Bytes go through the port's own file descriptor (pyserial leaves it non-blocking): a request that Ctrl-C
cuts short keeps its unsent rest here (:attr:`SerialPort.unsent`), so the link can finish it before
anything else and the device never sees half a request followed by another. Windows has no descriptor to
wait on (a COM port is a handle, and select takes sockets only): there pyserial's own reads and writes do the
waiting, each with the time left as its timeout (:data:`FD_IO` False).
"""

from __future__ import annotations

import contextlib
import errno
import os
import select
import time
from dataclasses import dataclass

import serial
from serial.tools import list_ports

from tablebot.i18n import N_
from tablebot.loop import LinkLost

#: How long a read waits at most when a caller passes no deadline (seconds).
DEFAULT_WAIT_S = 1.0
#: Bytes through the port's file descriptor, waited for with select (POSIX); else through pyserial's read and
#: write with timeouts (Windows, where a COM port has no descriptor).
FD_IO = os.name != "nt"


@dataclass(frozen=True)
class PortInfo:
    """One serial port as the system lists it (USB ids are None for a port that is not on USB)."""

    device: str
    vid: int | None = None
    pid: int | None = None
    product: str = ""
    description: str = ""


def serial_ports() -> list[PortInfo]:
    """Every serial port the system lists (pyserial's ``list_ports``), sorted by device name."""
    ports = [PortInfo(p.device, p.vid, p.pid, p.product or "", p.description or "") for p in list_ports.comports()]
    return sorted(ports, key=lambda p: p.device)


class SerialPort:
    """``device`` opened at ``baudrate`` 8N1, no flow control, exclusive (a second program cannot interleave)."""

    def __init__(self, device: str, baudrate: int) -> None:
        self.device, self.baudrate = device, baudrate
        self.port: serial.Serial | None = None
        self.unsent = b""  # the rest of a write that a signal cut short

    @property
    def is_open(self) -> bool:
        return self.port is not None

    def open(self) -> None:
        try:
            self.port = serial.Serial(self.device, self.baudrate, timeout=0, write_timeout=0, exclusive=True)
        except (serial.SerialException, OSError, ValueError) as exc:
            raise LinkLost(N_("cannot open {device}: {value}", device=self.device, value=_reason(exc))) from None
        self.port.reset_input_buffer()

    def close(self) -> None:
        """Close the port (never raises)."""
        port, self.port, self.unsent = self.port, None, b""
        if port is not None:
            with contextlib.suppress(Exception):
                port.close()

    # --- bytes ------------------------------------------------------------------------------------

    def write(self, data: bytes, deadline: float) -> None:
        """Send ``data`` whole (after the rest of an earlier cut-short write), or raise LinkLost."""
        self.unsent += data
        if not FD_IO:
            self._write_portable(deadline)
            return
        fd = self._fd()
        while self.unsent:
            self._wait(fd, deadline, writing=True, what="the device to take our request")
            try:
                sent = os.write(fd, self.unsent)
            except BlockingIOError:
                continue
            except OSError as exc:
                raise self._lost(exc) from None
            self.unsent = self.unsent[sent:]

    def read(self, size: int, deadline: float, what: str) -> bytes:
        """Exactly ``size`` bytes by ``deadline``, or LinkLost naming ``what`` was awaited."""
        data = bytearray()
        while len(data) < size:
            try:
                data += self.read_some(size - len(data), deadline, what)
            except LinkLost as exc:
                if data and "no answer" in str(exc):
                    raise LinkLost(
                        N_("{exc} (only {value} of {size} bytes came)", exc=exc.args[0], value=len(data), size=size)
                    ) from None
                raise
        return bytes(data)

    def read_some(self, most: int, deadline: float, what: str) -> bytes:
        """1..``most`` bytes as soon as any arrive, by ``deadline``."""
        if not FD_IO:
            return self._read_portable(most, deadline, what)
        fd = self._fd()
        while True:
            self._wait(fd, deadline, writing=False, what=what)
            try:
                chunk = os.read(fd, most)
            except BlockingIOError:
                continue
            except OSError as exc:
                raise self._lost(exc) from None
            if not chunk:  # readable but nothing: the other end hung up
                raise LinkLost(N_("{device} was disconnected (waiting for {what})", device=self.device, what=what))
            return chunk

    def pending(self) -> bytes:
        """Whatever has already arrived, without waiting (b"" if nothing; LinkLost if the device is gone)."""
        if not FD_IO:
            port = self._port()
            try:
                waiting = port.in_waiting
                return port.read(waiting) if waiting else b""
            except (serial.SerialException, OSError) as exc:
                raise self._lost(exc) from None
        fd = self._fd()
        if not select.select([fd], [], [], 0)[0]:
            return b""
        try:
            chunk = os.read(fd, 4096)
        except BlockingIOError:
            return b""
        except OSError as exc:
            raise self._lost(exc) from None
        if not chunk:
            raise LinkLost(N_("{device} was disconnected", device=self.device))
        return chunk

    # --- without a file descriptor (Windows) -----------------------------------------------------------

    def _write_portable(self, deadline: float) -> None:
        port = self._port()
        while self.unsent:
            left = deadline - time.monotonic()
            if left <= 0:
                raise LinkLost(
                    N_("no answer from {device}: expected the device to take our request", device=self.device)
                )
            try:
                port.write_timeout = left
                sent = port.write(self.unsent)
            except serial.SerialTimeoutException:
                raise LinkLost(
                    N_("no answer from {device}: expected the device to take our request", device=self.device)
                ) from None
            except (serial.SerialException, OSError) as exc:
                raise self._lost(exc) from None
            self.unsent = self.unsent[sent if sent is not None else len(self.unsent) :]

    def _read_portable(self, most: int, deadline: float, what: str) -> bytes:
        port = self._port()
        left = deadline - time.monotonic()
        if left <= 0:
            raise LinkLost(N_("no answer from {device}: expected {what}", device=self.device, what=what))
        try:
            port.timeout = left
            chunk = port.read(1)  # the first byte, waited for up to the deadline
            if chunk and most > 1 and (waiting := port.in_waiting):
                chunk += port.read(min(waiting, most - 1))  # and whatever came with it, without waiting
        except (serial.SerialException, OSError) as exc:
            raise self._lost(exc) from None
        if not chunk:
            raise LinkLost(N_("no answer from {device}: expected {what}", device=self.device, what=what))
        return chunk

    # --- helpers ----------------------------------------------------------------------------------

    def _port(self) -> serial.Serial:
        if self.port is None:
            raise LinkLost(N_("{device} is not open", device=self.device))
        return self.port

    def _fd(self) -> int:
        return self._port().fd

    def _wait(self, fd: int, deadline: float, *, writing: bool, what: str) -> None:
        left = deadline - time.monotonic()
        if left <= 0:
            raise LinkLost(N_("no answer from {device}: expected {what}", device=self.device, what=what))
        try:
            ready = select.select([], [fd], [], left) if writing else select.select([fd], [], [], left)
        except (OSError, ValueError) as exc:  # the descriptor was closed under us
            raise LinkLost(N_("{device} was closed ({exc})", device=self.device, exc=exc)) from None
        if not any(ready):
            raise LinkLost(N_("no answer from {device}: expected {what}", device=self.device, what=what))

    def _lost(self, exc: OSError | serial.SerialException) -> LinkLost:
        if "returned no data" in str(exc) or _hung_up(exc):  # pyserial: readable, yet nothing: the other end hung up
            return LinkLost(N_("{device} was disconnected", device=self.device))
        return LinkLost(
            N_(
                "lost {device}: {value} (was it unplugged?)",
                device=self.device,
                value=getattr(exc, "strerror", None) or exc,
            )
        )


def _hung_up(exc: BaseException) -> bool:
    """EIO on the port or on configuring it (pyserial wraps termios' error, which is no OSError): a USB adapter
    pulled out, or a pty whose other end closed."""
    seen: BaseException | None = exc
    while seen is not None:
        termios_eio = seen.args[:1] == (errno.EIO,) and not isinstance(seen, OSError)
        if getattr(seen, "errno", None) == errno.EIO or termios_eio:
            return True
        seen = seen.__cause__ or seen.__context__
    return False


def _reason(exc: BaseException) -> str:
    text = str(exc)
    return text.split(": ", 1)[-1] if "could not open port" in text else text
