"""A fake fischertechnik TXT for the tests: a real TCP server (in a thread) speaking the online protocol.

Written from the published header (fischertechnik/txt_demo_c_online, ftProInterface2013SocketCom.h and
FtShmemTxt.h) independently of tablebot.hw.txt.protocol, so that a wrong layout in one shows up against the
other (and unmodified ftrobopy keeps this fake honest). It records every request with its time, serves
inputs from a script, paces exchanges like a TXT ("the interface sends the response 10ms after it sent
the previous response") or answers at once like ftrobopy_server on a TXT 4.0, and injects faults.

``single_recv=True`` reads as ftrobopy_server does (ftrobopy/ftrobopy_server, ``src/ftrobopy_server.cpp``,
its ``while (connected)`` loop): one ``recv`` into a 1024-byte buffer per request, the command id from its
first four bytes and every field from fixed offsets of that buffer (bytes a short read did not bring are
left over from earlier requests); an unknown id is answered 0x01020304 and the connection closed. A
request split across reads is then misread, as there: each request is logged with ``whole``.
"""

from __future__ import annotations

import contextlib
import socket
import struct
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

# command id -> (name, request bytes after the id, response id)
COMMANDS = {
    0xDC21219A: ("QueryStatus", 0, 0xBAC9723E),
    0x163FF61D: ("StartOnline", 64, 0xCA689F75),
    0x060EF27E: ("UpdateConfig", 92, 0x9689A68C),  # INT16 config id, INT16 extension id, 88-byte FTX1_CONFIG
    0xCC3597BA: ("ExchangeData", 56, 0x4EEFAC41),  # 27 INT16/UINT16 fields, padded to 60 bytes in all
    0x9BE5082C: ("StopOnline", 0, 0xFBF600D2),
}
EXCHANGE_REPLY_BYTES = 80  # id, 25 INT16/UINT16 fields, five 5-byte IR records, one byte of padding

Script = Callable[[int], tuple[list[int], list[int]]]  # exchange number -> (I1..I8 values, C1..C4 counts)


@dataclass
class Request:
    t: float  # time.monotonic() when it was read
    name: str
    fields: dict[str, Any] = field(default_factory=dict)
    whole: bool = True  # single_recv: the request came in one recv, exactly


def still(n: int) -> tuple[list[int], list[int]]:
    return [0] * 8, [0] * 4


class FakeTxt:
    """``period_s`` paces exchange replies on a grid (0: answer at once, as ftrobopy_server does). A ``fault`` like
    ``("silent", 40)`` applies from the 40th ExchangeData on: silent, late, close, garbage, wrong_id."""

    def __init__(
        self,
        script: Script = still,
        period_s: float = 0.01,
        device: str = "TXT-fake",
        version: int = 0x04060600,
        fault: tuple[str, int] | None = None,
        late_s: float = 0.2,
        i2c: bool = False,
        drift_s: float = 0.0,
        host: str = "127.0.0.1",
        port: int = 0,
        single_recv: bool = False,
        latency_s: float = 0.0,
    ) -> None:
        self.script, self.period_s, self.device, self.version = script, period_s, device, version
        self.latency_s = latency_s  # before every reply: a controller far away (a bad Wi-Fi)
        self.single_recv = single_recv
        self.drift_s = drift_s  # added to every period: a TXT whose exchanges take a little longer
        self.fault, self.late_s = fault, late_s
        self.log: list[Request] = []
        self.exchanges = 0
        self.connections = 0
        self._stop = threading.Event()
        self._server, self._i2c = self._listen(i2c, host, port)
        self.port = self._server.getsockname()[1]
        self._threads = [threading.Thread(target=self._serve, daemon=True)]
        if self._i2c is not None:
            self._threads.append(threading.Thread(target=self._hold_i2c, daemon=True))
        for thread in self._threads:
            thread.start()

    # --- observations -----------------------------------------------------------------------------

    def requests(self, name: str | None = None) -> list[Request]:
        return [r for r in list(self.log) if name is None or r.name == name]

    def names(self) -> list[str]:
        return [r.name for r in list(self.log)]

    def last_exchange_before_stop(self) -> Request:
        """The last ExchangeData before the (first) StopOnline."""
        names = self.names()
        stop = names.index("StopOnline")
        return next(r for r in reversed(self.log[:stop]) if r.name == "ExchangeData")

    def wait_for(self, exchanges: int, timeout_s: float = 10.0) -> None:
        deadline = time.monotonic() + timeout_s
        while self.exchanges < exchanges:
            if time.monotonic() > deadline:
                raise TimeoutError(f"only {self.exchanges} exchanges in {timeout_s} s")
            time.sleep(0.005)

    def close(self) -> None:
        self._stop.set()
        for sock in (self._server, self._i2c):
            if sock is not None:
                with contextlib.suppress(OSError):  # shutdown wakes a thread blocked in accept(); close does not
                    sock.shutdown(socket.SHUT_RDWR)
                sock.close()
        for thread in self._threads:
            thread.join(2)

    def __enter__(self) -> FakeTxt:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    # --- the server -------------------------------------------------------------------------------

    @staticmethod
    def _listen(i2c: bool, host: str, port: int) -> tuple[socket.socket, socket.socket | None]:
        """A listening socket on ``host``, on ``port`` or a free one (and, for ftrobopy, one on port + 2,
        its I2C channel)."""
        for _ in range(50):
            main = socket.socket()
            main.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
            main.bind((host, port))
            if not i2c:
                main.listen()
                return main, None
            extra = socket.socket()
            try:
                extra.bind((host, main.getsockname()[1] + 2))
            except OSError:
                main.close()
                extra.close()
                continue
            main.listen()
            extra.listen()
            return main, extra
        raise RuntimeError("no free pair of ports")

    def _hold_i2c(self) -> None:
        held = []
        while not self._stop.is_set():
            try:
                conn, _ = self._i2c.accept()  # type: ignore[union-attr]
            except OSError:
                break
            held.append(conn)
        for conn in held:
            conn.close()

    def _serve(self) -> None:
        while not self._stop.is_set():
            try:
                conn, _ = self._server.accept()
            except OSError:
                return
            self.connections += 1
            with conn:
                conn.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
                self._session(conn)
            self.log.append(Request(time.monotonic(), "closed"))

    def _read(self, conn: socket.socket, size: int) -> bytes | None:
        data = b""
        while len(data) < size:
            try:
                chunk = conn.recv(size - len(data))
            except OSError:
                return None
            if not chunk:
                return None
            data += chunk
        return data

    def _next(self, conn: socket.socket, buffer: bytearray) -> tuple[int, bytes, bool] | None:
        """The next request: (command id, the bytes after it, whether it came whole); None when closed."""
        if self.single_recv:  # one recv per request, fields from the persistent buffer
            try:
                chunk = conn.recv(len(buffer))
            except OSError:
                return None
            if not chunk:
                return None
            buffer[: len(chunk)] = chunk
            (command,) = struct.unpack_from("<I", buffer)
            extra = COMMANDS[command][1] if command in COMMANDS else 0
            return command, bytes(buffer[4 : 4 + extra]), len(chunk) == 4 + extra
        head = self._read(conn, 4)
        if head is None:
            return None
        (command,) = struct.unpack("<I", head)
        extra = COMMANDS[command][1] if command in COMMANDS else 0
        body = self._read(conn, extra) if extra else b""
        return None if body is None else (command, body, True)

    def _session(self, conn: socket.socket) -> None:
        last_reply = 0.0
        silent = False
        buffer = bytearray(1024)
        previous = ""
        while True:
            got = self._next(conn, buffer)
            if got is None:
                return
            command, body, whole = got
            if command not in COMMANDS:
                self.log.append(Request(time.monotonic(), f"unknown 0x{command:08X}", whole=whole))
                if self.single_recv:
                    conn.sendall(struct.pack("<I", 0x01020304))
                return
            name, _, response = COMMANDS[command]
            request = Request(time.monotonic(), name, self._fields(name, body), whole)
            self.log.append(request)
            previous, before = name, previous
            if self.latency_s:
                time.sleep(self.latency_s)
            if name != "ExchangeData":
                if not silent:
                    conn.sendall(self._reply(name, response))
                if self.single_recv and name == "StopOnline" and before != "QueryStatus":
                    return  # ftrobopy_server ends the connection (right after QueryStatus: ftScratchTXT's way)
                continue
            number = self.exchanges
            kind = self.fault[0] if self.fault and number >= self.fault[1] else None
            silent = silent or kind == "silent"
            if silent:
                self.exchanges += 1
                continue
            if self.period_s:  # 10 ms after the previous reply was due; at once if the request came later
                due = last_reply + self.period_s + self.drift_s
                time.sleep(max(0.0, due - time.monotonic()))
                last_reply = max(due, time.monotonic())
            if kind == "late" and number == self.fault[1]:  # type: ignore[index]
                time.sleep(self.late_s)
            if kind == "close":
                self.exchanges += 1
                return
            payload = self._exchange_reply(number)
            if kind == "garbage":
                payload = bytes((i * 37 + 11) % 256 for i in range(EXCHANGE_REPLY_BYTES))
            elif kind == "wrong_id":
                payload = struct.pack("<I", 0xBAC9723E) + payload[4:]
            conn.sendall(payload)
            last_reply = last_reply if self.period_s else time.monotonic()
            self.exchanges += 1

    # --- the structs, from the header -------------------------------------------------------------

    @staticmethod
    def _fields(name: str, body: bytes) -> dict[str, Any]:
        if name == "StartOnline":
            return {"client": body.split(b"\0", 1)[0].decode("latin-1")}
        if name == "UpdateConfig":
            config_id, extension = struct.unpack_from("<hh", body, 0)
            config = body[4:]  # FTX1_CONFIG: pgm_state_req, old_FtTransfer, dummy[2], motor[4], ...
            motors = list(config[4:8])
            inputs = [(config[8 + 4 * i], config[9 + 4 * i]) for i in range(8)]  # UNI_CONFIG: mode, digital, dummy[2]
            counters = [config[40 + 4 * i] for i in range(4)]  # CNT_CONFIG: mode, dummy[3]
            return {
                "config_id": config_id,
                "extension": extension,
                "motors": motors,
                "inputs": inputs,
                "counters": counters,
            }
        if name == "ExchangeData":
            values = struct.unpack_from("<24h3H", body, 0)
            return {
                "pwm": list(values[0:8]),
                "master": list(values[8:12]),
                "distance": list(values[12:16]),
                "motor_ids": list(values[16:20]),
                "counter_reset_ids": list(values[20:24]),
            }
        return {}

    def _reply(self, name: str, response: int) -> bytes:
        if name == "QueryStatus":
            return (
                struct.pack("<I", response)
                + self.device.encode()[:15].ljust(16, b"\0")
                + struct.pack("<I", self.version)
            )
        return struct.pack("<I", response)

    def _exchange_reply(self, number: int) -> bytes:
        universal, counts = self.script(number)
        words = [*universal, 0, 0, 0, 0, *counts, 0, 0, 0, 0, 0, 0, 0, 0]  # inputs, cnt_in, counter, ids, ids
        reply = struct.pack("<I24hH", 0x4EEFAC41, *words, 0) + bytes(25) + b"\0"  # sound id, IR[5], padding
        assert len(reply) == EXCHANGE_REPLY_BYTES
        return reply
