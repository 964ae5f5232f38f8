"""The client side of the TXT online protocol: one TCP connection, one request at a time, each request
sent whole, a deadline on every reply, and a stream that stays in step even when Ctrl-C cuts a reply short.

Whole requests matter: ftrobopy_server (ftrobopy/ftrobopy_server, ``src/ftrobopy_server.cpp``) reads each
request with a single ``recv`` and takes its first four bytes as the command id; the rest of a request
that arrived in two pieces would be read as a command of its own (answered 0x01020304, connection
closed) and the first piece parsed with stale bytes. So a request goes out in one ``sendall`` with
SIGINT and SIGTERM held until it is out, never as a remainder resumed later.

Every failure (refused, silent, late, closed, malformed, wrong response id) becomes
:class:`tablebot.loop.LinkLost` with a sentence saying what happened; nothing here prints or starts threads.
"""

from __future__ import annotations

import contextlib
import signal
import socket
import threading
import time
from collections.abc import Iterator, Sequence
from concurrent.futures import ThreadPoolExecutor

from tablebot.hw.txt import protocol as wire
from tablebot.hw.txt.protocol import Command
from tablebot.i18n import N_
from tablebot.loop import LinkLost

#: Where a TXT answers: USB, Wi-Fi access point, Bluetooth (the order ``txt://auto`` tries them in).
AUTO_HOSTS = ("192.168.7.2", "192.168.8.2", "192.168.9.2")
#: ftrobopy keeps an idle link open with a QueryStatus after a second of silence; so do we.
KEEP_ALIVE_S = 1.0
SETUP_TIMEOUT_S = 2.0  # QueryStatus, StartOnline, UpdateConfig, StopOnline


def probe(host: str, port: int = wire.PORT, timeout_s: float = 0.5) -> wire.Status | str:
    """Whether ``host`` answers the TXT handshake (QueryStatus): its status, or what it did instead."""
    link = TxtLink(host, port, setup_timeout_s=timeout_s)
    try:
        link.connect(timeout_s)
        return link.query_status()
    except LinkLost as exc:
        return str(exc)
    finally:
        link.close()


def find_controller(
    hosts: Sequence[str] = AUTO_HOSTS, port: int = wire.PORT, timeout_s: float = 0.5
) -> tuple[str | None, list[str]]:
    """The first of ``hosts`` that answers as a TXT (all asked at once, each for ``timeout_s``), and what
    each of the others did. A server that merely accepts the connection does not count."""
    with ThreadPoolExecutor(max_workers=max(1, len(hosts))) as pool:
        answers = list(pool.map(lambda host: probe(host, port, timeout_s), hosts))
    found = next((host for host, answer in zip(hosts, answers, strict=True) if isinstance(answer, wire.Status)), None)
    return found, [
        f"{host}: {answer}" for host, answer in zip(hosts, answers, strict=True) if not isinstance(answer, wire.Status)
    ]


@contextlib.contextmanager
def signals_held() -> Iterator[None]:
    """SIGINT and SIGTERM wait (in this thread) until the block is done: Ctrl-C cannot cut a request."""
    if threading.current_thread() is not threading.main_thread() or not hasattr(signal, "pthread_sigmask"):
        yield  # Python runs signal handlers in the main thread only: nothing can interrupt this one
        return
    old = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT, signal.SIGTERM})
    try:
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, old)


class TxtLink:
    """A connection to ``host:port``. Exchanges must be answered within ``reply_timeout_s``."""

    def __init__(
        self, host: str, port: int = wire.PORT, reply_timeout_s: float = 0.05, setup_timeout_s: float = SETUP_TIMEOUT_S
    ) -> None:
        self.host, self.port = host, port
        self.reply_timeout_s, self.setup_timeout_s = reply_timeout_s, setup_timeout_s
        self.sock: socket.socket | None = None
        self.online = False  # StartOnline was sent and StopOnline was not
        self.config_id = 0
        self.last_reply = 0.0  # time.monotonic() of the last whole reply
        self._owed = 0  # bytes of replies still to come (a reply a signal cut short, or one given up on)
        self._trusted = True  # False after a malformed reply: later bytes cannot be parsed reliably
        self._sendable = True  # False once a request may have gone out in part: nothing more can follow it

    @property
    def where(self) -> str:
        return f"{self.host}:{self.port}"

    # --- connection -------------------------------------------------------------------------------

    def connect(self, timeout_s: float = 3.0) -> None:
        try:
            self.sock = socket.create_connection((self.host, self.port), timeout=timeout_s)
        except socket.gaierror as exc:
            raise LinkLost(
                N_("cannot find the controller {host}: {strerror}", host=self.host, strerror=exc.strerror)
            ) from None
        except TimeoutError:
            raise LinkLost(
                N_("no controller answered at {where} within {timeout_s:g} s", where=self.where, timeout_s=timeout_s)
            ) from None
        except OSError as exc:
            raise LinkLost(
                N_("cannot connect to {where}: {value}", where=self.where, value=exc.strerror or exc)
            ) from None
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
        return wire.decode_exchange(
            self._request(Command.EXCHANGE_DATA, wire.exchange(list(pwm)), self.reply_timeout_s)
        )

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
        if self.sock is None or not self._sendable:
            return False
        deadline = time.monotonic() + timeout_s
        try:
            self._owed += wire.REPLY_SIZE[command]
            self._send(payload, deadline, command)
        except LinkLost:
            return False
        with contextlib.suppress(LinkLost):
            self._discard_owed(deadline, command)
        return True

    # --- one request, one reply -------------------------------------------------------------------

    def _request(self, command: Command, payload: bytes, timeout_s: float) -> bytes:
        if self.sock is None:
            raise LinkLost(N_("not connected to {where}", where=self.where))
        if not self._trusted:
            raise LinkLost(
                N_("{where} sent a malformed reply earlier: its replies cannot be trusted", where=self.where)
            )
        deadline = time.monotonic() + timeout_s
        self._discard_owed(deadline, command)  # the rest of a reply a signal cut short, or one given up on
        self._owed = wire.REPLY_SIZE[command]  # owed from the moment the request may be out
        self._send(payload, deadline, command)
        data = self._receive(wire.REPLY_SIZE[command], deadline, command, timeout_s)
        self.last_reply = time.monotonic()
        return data

    def _send(self, payload: bytes, deadline: float, command: Command) -> None:
        """The whole request in one ``sendall``, signals held; a request that may have gone out in part
        leaves the connection unusable (what follows would be misread)."""
        if not self._sendable:
            raise LinkLost(
                N_("{where}: a request went out in part earlier; nothing more can be sent", where=self.where)
            )
        sock = self._socket()
        sock.settimeout(self._remaining(deadline, command, "sending"))
        with signals_held():
            try:
                sock.sendall(payload)
            except TimeoutError:
                self._sendable = False
                raise LinkLost(
                    N_("{where} did not take {name} in time (its buffer is full)", where=self.where, name=command.name)
                ) from None
            except OSError as exc:
                self._sendable = False
                raise self._lost(exc, command) from None

    def _discard_owed(self, deadline: float, command: Command) -> None:
        while self._owed > 0:
            self._chunk(min(self._owed, 4096), deadline, command, N_("a late reply"))

    def _receive(self, size: int, deadline: float, command: Command, timeout_s: float) -> bytes:
        data = bytearray()
        while len(data) < size:
            what = N_("a reply to {name} within {ms:.0f} ms", name=command.name, ms=1000 * timeout_s)
            data += self._chunk(size - len(data), deadline, command, what)
            if len(data) >= 4 and not self._id_ok(command, data):
                break
        try:
            wire.check_reply(command, bytes(data))
        except wire.WireError as exc:
            self._trusted = False
            raise LinkLost(N_("malformed reply from {where}: {exc}", where=self.where, exc=exc.args[0])) from None
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
            raise LinkLost(N_("no answer from {where}: expected {what}", where=self.where, what=what)) from None
        except OSError as exc:
            raise self._lost(exc, command) from None
        if not chunk:
            raise LinkLost(N_("{where} closed the connection (during {name})", where=self.where, name=command.name))
        self._owed -= len(chunk)
        return chunk

    def _remaining(self, deadline: float, command: Command, what: str) -> float:
        left = deadline - time.monotonic()
        if left <= 0:
            raise LinkLost(N_("no answer from {where}: expected {what}", where=self.where, what=what))
        return left

    def _socket(self) -> socket.socket:
        if self.sock is None:
            raise LinkLost(N_("not connected to {where}", where=self.where))
        return self.sock

    def _lost(self, exc: OSError, command: Command) -> LinkLost:
        return LinkLost(
            N_(
                "lost the connection to {where} during {name}: {value}",
                where=self.where,
                name=command.name,
                value=exc.strerror or exc,
            )
        )
