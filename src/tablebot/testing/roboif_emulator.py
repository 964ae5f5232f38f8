"""A FAKE ROBO Interface on a pseudo-terminal, answering its serial online protocol; for tests and benchmarks,
since no interface is here.

Written from ``nxdefiant/libroboint`` (``lib/libroboint.c``: ``OpenFtCommDevice``, ``FtThread``,
``CloseFtDevice``; ``lib/roboint.h``: the transfer area), independently of :mod:`tablebot.hw.roboif.protocol`: the
greeting "\\xA1ft-Robo-ON-V1" is answered with 0x5E and four more bytes (libroboint reads five and checks only
the first, so the other four are zeros here), each 17-byte exchange 0xF2 with 21 bytes, the farewell 0xA2
with 0x5D. ``baud=38400`` makes it as slow as the real serial line (10 bits a byte, both ways). It records
every request with its time, serves scripted inputs and misbehaves on request.
"""

from __future__ import annotations

import time
from collections.abc import Callable

from tablebot.testing.pty_device import PtyDevice

Script = Callable[[int], tuple[list[int], dict[str, int]]]  # exchange number -> (I1..I8 levels, analog values)
FAULTS = ("silent", "late", "short", "extra", "chatter", "hang_up")
GREETING = b"\xa1" + b"ft-Robo-ON-V1"
ANALOG = ("AX", "AY", "A1", "A2", "AZ", "D1", "D2", "AV")


def still(n: int) -> tuple[list[int], dict[str, int]]:
    return [0] * 8, {}


class RoboifEmulator(PtyDevice):
    """``fault = ("late", 40)`` applies from the 40th exchange on (one of :data:`FAULTS`); ``greeting_reply``
    replaces the answer to the greeting (a device that is not a ROBO Interface)."""

    def __init__(
        self,
        script: Script = still,
        *,
        fault: tuple[str, int] | None = None,
        late_s: float = 0.3,
        baud: int = 0,
        greeting_reply: bytes = b"\x5e\x00\x00\x00\x00",
    ) -> None:
        self.script, self.fault, self.late_s = script, fault, late_s
        self.greeting_reply = greeting_reply
        self.exchanges = 0
        self._buffer = bytearray()
        super().__init__(baud)

    def feed(self, data: bytes) -> None:
        self._buffer += data
        while self._buffer:
            first = self._buffer[0]
            need = {0xA1: len(GREETING), 0xF2: 17, 0xA2: 1}.get(first)
            if need is None:
                self.note("unknown byte", byte=first)
                del self._buffer[:1]
                continue
            if len(self._buffer) < need:
                return
            request = bytes(self._buffer[:need])
            del self._buffer[:need]
            self._arrived(need)
            if first == 0xA1:
                self.note("hello", ok=request == GREETING)
                self.send(self.greeting_reply if request == GREETING else b"")
            elif first == 0xA2:
                self.note("bye")
                self.send(b"\x5d")
            else:
                self._exchange(request)

    def _arrived(self, size: int) -> None:
        """The time a real line takes to carry the request to the interface."""
        if self.baud:
            time.sleep(10 * size / self.baud)

    def _exchange(self, out: bytes) -> None:
        n = self.exchanges
        self.exchanges += 1
        a, b, c = out[2], out[3], out[4]
        pwm = [
            a & 7,
            a >> 3 & 7,
            a >> 6 | (b & 1) << 2,
            b >> 1 & 7,
            b >> 4 & 7,
            b >> 7 | (c & 3) << 1,
            c >> 2 & 7,
            c >> 5 & 7,
        ]
        self.note("exchange", outputs=out[1], pwm=pwm, extensions=list(out[5:17]), n=n, raw=out)
        levels, analog = self.script(n)
        reply = bytearray(21)
        reply[0] = sum(1 << i for i, level in enumerate(levels) if level)
        values = {name: analog.get(name, 0) & 0x3FF for name in ANALOG}
        for name, low in zip(ANALOG, (4, 5, 6, 7, 9, 10, 11, 12), strict=True):
            reply[low] = values[name] & 0xFF
        for i, name in enumerate(ANALOG[:4]):  # high two bits of AX, AY, A1, A2 in byte 8
            reply[8] |= (values[name] >> 8) << (2 * i)
        for i, name in enumerate(ANALOG[4:]):  # ... of AZ, D1, D2, AV in byte 13
            reply[13] |= (values[name] >> 8) << (2 * i)
        fault = self.fault[0] if self.fault and n >= self.fault[1] else None
        if fault == "silent":
            return
        if fault == "hang_up":
            self.hang_up()
            return
        if fault == "late":
            time.sleep(self.late_s)
        data = bytes(reply)
        if fault == "short":
            data = data[:20]
        elif fault == "extra":
            data += b"\x00\x5e"
        elif fault == "chatter":  # bytes nobody asked for, after the reply
            self.send(data)
            time.sleep(0.002)
            data = b"\r\n"
        self.send(data)
