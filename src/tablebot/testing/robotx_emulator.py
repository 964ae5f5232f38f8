"""A FAKE ROBO TX Controller on a pseudo-terminal, answering the "fish.X1" online protocol; for tests and
benchmarks, since no controller is here.

Written from the published sources, independently of :mod:`tablebot.hw.robotx.protocol` (so that a wrong layout
in one shows up against the other): the frame of fischertechnik's PC programming manual (ch. 13.1, copy in
``ski7777/fttxpy`` ``TXC-Programming/``), and the device side of ``fischertechniker/ROBO-Pro-for-ftDuino``
(``fishx1.ino``: a byte-by-byte parser, replies with the request's code + 100, the request's TID echoed, a new
session when a request comes with SID 0 and TID 1, TA_INFO "ROBO TX-000" firmware 1.30). It records every
request with its time, serves scripted inputs and counters, and misbehaves on request.
"""

from __future__ import annotations

import os
import struct
import time
from collections.abc import Callable

from tablebot.testing.pty_device import PtyDevice

Script = Callable[[int], tuple[list[int], list[int]]]  # exchange number -> (I1..I8 values, C1..C4 counts)
FAULTS = ("silent", "late", "garbage", "bad_crc", "wrong_tid", "wrong_code", "new_session", "short", "hang_up")


def still(n: int) -> tuple[list[int], list[int]]:
    return [0] * 8, [0] * 4


class RobotxEmulator(PtyDevice):
    """``fault = ("late", 40)`` applies from the 40th exchange on (one of :data:`FAULTS`); ``delay_s`` delays
    every reply (a slow link); ``junk`` is written before the first reply (a shell prompt)."""

    def __init__(
        self,
        script: Script = still,
        *,
        device_name: str = "ROBO TX-000",
        fault: tuple[str, int] | None = None,
        delay_s: float = 0.0,
        late_s: float = 0.3,
        junk: bytes = b"",
    ) -> None:
        self.script, self.device_name, self.fault = script, device_name, fault
        self.delay_s, self.late_s, self.junk = delay_s, late_s, junk
        self.exchanges = 0
        self.session = 0
        self.bad_frames = 0  # requests dropped for a wrong checksum or end mark
        self._buffer = bytearray()
        super().__init__()

    # --- the parser (the device side: frames found by STX 0x55, checked by length, sum and ETX) -------

    def feed(self, data: bytes) -> None:
        self._buffer += data
        while True:
            start = self._buffer.find(b"\x02\x55")
            if start < 0:
                del self._buffer[:-1]
                return
            del self._buffer[:start]
            if len(self._buffer) < 4:
                return
            length = (self._buffer[2] << 8) | self._buffer[3]
            total = length + 7
            if len(self._buffer) < total:
                return
            packet = bytes(self._buffer[:total])
            del self._buffer[:total]
            total_sum = sum(packet[2 : 4 + length]) & 0xFFFF
            sent = (packet[4 + length] << 8) | packet[5 + length]
            if packet[-1] != 0x03 or (total_sum + sent) & 0xFFFF:
                self.bad_frames += 1
                self.note("bad frame")
                continue
            self._answer(packet[4 : 4 + length])

    def _answer(self, body: bytes) -> None:
        tid, sid, code, count = struct.unpack_from("<HHII", body, 8)
        if sid == 0 and tid == 1:
            self.session += 1
        data = body[20:]
        handler = {1: self._echo, 2: self._exchange, 5: self._config, 6: self._info, 7: self._state}.get(code)
        if handler is None:
            self.note("unknown", code=code)
            return
        handler(tid, sid, count, data)

    # --- commands ---------------------------------------------------------------------------------

    def _echo(self, tid: int, sid: int, count: int, data: bytes) -> None:
        self.note("echo", tid=tid, sid=sid)
        self._reply(101, tid, [])

    def _info(self, tid: int, sid: int, count: int, data: bytes) -> None:
        self.note("info", tid=tid, sid=sid)
        name = self.device_name.encode("ascii")[:16].ljust(17, b"\0")
        info = name + b"00:00:00:00:00:00\0" + b"\0" + bytes(12)
        info += bytes((0x43, 0, 0, 0)) + bytes((0, 6, 1, 30)) + bytes((1, 1, 1, 8)) + bytes(4)  # 'C', 1.30, TA 1.08
        self._reply(106, tid, [info])

    def _state(self, tid: int, sid: int, count: int, data: bytes) -> None:
        self.note("state", tid=tid, sid=sid)
        self._reply(107, tid, [bytes(24)])

    def _config(self, tid: int, sid: int, count: int, data: bytes) -> None:
        ta = data[4:]
        self.note(
            "config",
            tid=tid,
            sid=sid,
            ta=int.from_bytes(data[:4], "little"),
            motors=list(ta[0:4]),
            uni=list(ta[4:12]),
            cnt=list(ta[12:16]),
            size=len(ta),
            raw=ta,
        )
        self._reply(105, tid, [b""])

    def _exchange(self, tid: int, sid: int, count: int, data: bytes) -> None:
        n = self.exchanges
        self.exchanges += 1
        out = data[4:]
        duty = list(struct.unpack_from("<8h", out, 12)) if len(out) >= 28 else []
        self.note("exchange", tid=tid, sid=sid, duty=duty, size=len(out), n=n, raw=out)
        uni, counts = self.script(n)
        levels = [0, 0, 0, 0]
        payload = struct.pack("<8h", *uni) + bytes(levels) + struct.pack("<4H", *[c & 0xFFFF for c in counts])
        payload += bytes(4 + 16)  # display buttons, cnt_resetted, motor_pos_reached
        fault = self.fault[0] if self.fault and n >= self.fault[1] else None
        self._reply(102, tid, [payload], fault)

    # --- replies ----------------------------------------------------------------------------------

    def _reply(self, code: int, tid: int, areas: list[bytes], fault: str | None = None) -> None:
        if fault == "silent":
            return
        if fault == "hang_up":
            self.hang_up()
            return
        if fault == "new_session":
            self.session += 1
        if fault == "wrong_tid":
            tid = (tid + 7) & 0xFFFF
        if fault == "wrong_code":
            code = 105
        if fault == "short":
            areas = [a[:40] for a in areas]
        body = struct.pack("<IIHHII", 2, 2, tid, self.session, code, len(areas))
        body += b"".join(struct.pack("<I", 0) + a for a in areas)
        head = len(body).to_bytes(2, "big") + body
        crc = (0x10000 - sum(head)) & 0xFFFF
        if fault == "bad_crc":
            crc ^= 0x5A5A
        frame = b"\x02\x55" + head + crc.to_bytes(2, "big") + b"\x03"
        if fault == "garbage":
            frame = os.urandom(len(frame)).replace(b"\x02", b"\x07")
        if self.junk:
            frame, self.junk = self.junk + frame, b""
        delay = self.delay_s + (self.late_s if fault == "late" else 0.0)
        if delay:
            time.sleep(delay)
        self.send(frame)
