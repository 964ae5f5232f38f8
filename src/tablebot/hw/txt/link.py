"""The client side of the TXT online protocol: one TCP connection, one request at a time, a deadline on
every reply, and a stream that stays in step even when Ctrl-C cuts a request or a reply in half.

Every failure (refused, silent, late, closed, malformed, wrong response id) becomes
:class:`tablebot.loop.LinkLost` with a sentence saying what happened; nothing here prints or starts threads.
"""

from __future__ import annotations

import contextlib
import socket
import time
from collections.abc import Sequence

from tablebot.hw.txt import protocol as wire
from tablebot.hw.txt.protocol import Command
from tablebot.loop import LinkLost

#: Where a TXT answers: USB, Wi-Fi access point, Bluetooth (the order ``txt://auto`` tries them in).
AUTO_HOSTS = ("192.168.7.2", "192.168.8.2", "192.168.9.2")
#: ftrobopy keeps an idle link open with a QueryStatus after a second of silence; so do we.
KEEP_ALIVE_S = 1.0
SETUP_TIMEOUT_S = 2.0  # QueryStatus, StartOnline, UpdateConfig, StopOnline


def find_controller(hosts: Sequence[str] = AUTO_HOSTS, port: int = wire.PORT, timeout_s: float = 0.5) -> str | None:
    """The first of ``hosts`` that accepts a connection on ``port`` (each tried for ``timeout_s``)."""
    for host in hosts:
        try:
            with socket.create_connection((host, port), timeout=timeout_s):
                return host
        except OSError:
            continue
    return None


class TxtLink:
    """A connection to ``host:port``. Exchanges must be answered within ``reply_timeout_s``."""

    def __init__(self, host: str, port: int = wire.PORT, reply_timeout_s: float = 0.05,
                 setup_timeout_s: float = SETUP_TIMEOUT_S):
        self.host, self.port = host, port
        self.reply_timeout_s, self.setup_timeout_s = reply_timeout_s, setup_timeout_s
        self.sock: socket.socket | None = None
        self.online = False  # StartOnline was sent and StopOnline was not
        self.config_id = 0
        self.last_reply = 0.0  # time.monotonic() of the last whole reply
        self._unsent = b""  # the rest of a request a signal cut short: sent before anything else
        self._owed = 0  # bytes of replies still to come (a reply a signal cut short, or one given up on)
        self._trusted = True  # False after a malformed reply: later bytes cannot be parsed reliably

    @property
    def where(self) -> str:
        return f"{self.host}:{self.port}"

    # --- connection -------------------------------------------------------------------------------

    def connect(self, timeout_s: float = 3.0) -> None:
        try:
            self.sock = socket.create_connection((self.host, self.port), timeout=timeout_s)
        except socket.gaierror as exc:
            raise LinkLost(f"cannot find the controller {self.host}: {exc.strerror}") from None
        except TimeoutError:
            raise LinkLost(f"no controller answered at {self.where} within {timeout_s:g} s") from None
        except OSError as exc:
            raise LinkLost(f"cannot connect to {self.where}: {exc.strerror or exc}") from None
        self.sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)  # one small packet per request, at once
        self.last_reply = time.monotonic()

    def close(self) -> None:
        """Close the socket (never raises). A TXT 4.0's ftrobopy_server stops its motors when it sees this."""
        sock, self.sock, self.online = self.sock, None, False
        if sock is not None:
            with contextlib.suppress(OSError):
                sock.close()

    # --- commands ---------------------------------------------------------------------------------

    def query_status(self) -> wire.Status:
        return wire.decode_status(self._request(Command.QUERY_STATUS, wire.query_status(), self.setup_timeout_s))

    def start_online(self, name: str = "tablebot") -> None:
        self.online = True  # from the moment the request may have arrived, outputs must be stopped at the end
        self._request(Command.START_ONLINE, wire.start_online(name), self.setup_timeout_s)

    def update_config(self, config: wire.Config) -> None:
        self.config_id = self.config_id % 0x7FFF + 1
        self._request(Command.UPDATE_CONFIG, wire.update_config(config, self.config_id), self.setup_timeout_s)

    def exchange(self, pwm: Sequence[int]) -> wire.Inputs:
        """Send O1..O8's PWM, get the inputs back (the TXT answers 10 ms after its previous answer)."""
        return wire.decode_exchange(self._request(Command.EXCHANGE_DATA, wire.exchange(list(pwm)),
                                                  self.reply_timeout_s))

    def stop_online(self) -> None:
        self.online = False
        self._request(Command.STOP_ONLINE, wire.stop_online(), self.setup_timeout_s)

    def keep_alive(self, idle_s: float = KEEP_ALIVE_S) -> bool:
        """Send a QueryStatus if nothing was exchanged for ``idle_s`` (the TXT drops a silent link)."""
        if time.monotonic() - self.last_reply < idle_s:
            return False
        self.query_status()
        return True

    def send_best_effort(self, command: Command, payload: bytes, timeout_s: float) -> bool:
        """Send ``payload`` even after a fault, then read what replies come within ``timeout_s`` without
        trusting them; True if the whole request went out. Never raises (this is how outputs get stopped)."""
        if self.sock is None:
            return False
        deadline = time.monotonic() + timeout_s
        try:
            self._flush(deadline, command)
            self._owed += wire.REPLY_SIZE[command]
            self._unsent = payload
            self._flush(deadline, command)
        except LinkLost:
            return False
        with contextlib.suppress(LinkLost):
            self._discard_owed(deadline, command)
        return True

    # --- one request, one reply -------------------------------------------------------------------

    def _request(self, command: Command, payload: bytes, timeout_s: float) -> bytes:
        if self.sock is None:
            raise LinkLost(f"not connected to {self.where}")
        if not self._trusted:
            raise LinkLost(f"{self.where} sent a malformed reply earlier: its replies cannot be trusted")
        deadline = time.monotonic() + timeout_s
        self._flush(deadline, command)  # the rest of a request a signal interrupted: its reply is owed
        self._discard_owed(deadline, command)
        self._owed = wire.REPLY_SIZE[command]
        self._unsent = payload
        self._flush(deadline, command)
        data = self._receive(wire.REPLY_SIZE[command], deadline, command, timeout_s)
        self.last_reply = time.monotonic()
        return data

    def _flush(self, deadline: float, command: Command) -> None:
        sock = self._socket()
        while self._unsent:
            sock.settimeout(self._remaining(deadline, command, "sending"))
            try:
                sent = sock.send(self._unsent)
            except TimeoutError:
                raise LinkLost(f"{self.where} did not take {command.name} in time (its buffer is full)") from None
            except OSError as exc:
                raise self._lost(exc, command) from None
            self._unsent = self._unsent[sent:]

    def _discard_owed(self, deadline: float, command: Command) -> None:
        while self._owed > 0:
            self._chunk(min(self._owed, 4096), deadline, command, "a late reply")

    def _receive(self, size: int, deadline: float, command: Command, timeout_s: float) -> bytes:
        data = bytearray()
        while len(data) < size:
            what = f"a reply to {command.name} within {1000 * timeout_s:.0f} ms"
            data += self._chunk(size - len(data), deadline, command, what)
            if len(data) >= 4 and not self._id_ok(command, data):
                break
        try:
            wire.check_reply(command, bytes(data))
        except wire.WireError as exc:
            self._trusted = False
            raise LinkLost(f"malformed reply from {self.where}: {exc}") from None
        return bytes(data)

    @staticmethod
    def _id_ok(command: Command, data: bytearray) -> bool:
        """Whether the reply starts with the right response id (a wrong one is reported at once)."""
        return int.from_bytes(data[:4], "little") == wire.REPLY_ID[command]

    def _chunk(self, most: int, deadline: float, command: Command, what: str) -> bytes:
        sock = self._socket()
        sock.settimeout(self._remaining(deadline, command, what))
        try:
            chunk = sock.recv(most)
        except TimeoutError:
            raise LinkLost(f"no answer from {self.where}: expected {what}") from None
        except OSError as exc:
            raise self._lost(exc, command) from None
        if not chunk:
            raise LinkLost(f"{self.where} closed the connection (during {command.name})")
        self._owed -= len(chunk)
        return chunk

    def _remaining(self, deadline: float, command: Command, what: str) -> float:
        left = deadline - time.monotonic()
        if left <= 0:
            raise LinkLost(f"no answer from {self.where}: expected {what}")
        return left

    def _socket(self) -> socket.socket:
        if self.sock is None:
            raise LinkLost(f"not connected to {self.where}")
        return self.sock

    def _lost(self, exc: OSError, command: Command) -> LinkLost:
        return LinkLost(f"lost the connection to {self.where} during {command.name}: {exc.strerror or exc}")
