"""``tablebot monitor``: a firmware's UART trace stream (a serial port, or a file of captured bytes)
decoded into the core's JSON Lines trace.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import IO, Any

from tablebot.codegen.layout import plan
from tablebot.diagnostics import fail
from tablebot.firmware.framing import Decoder
from tablebot.machine import Machine
from tablebot.trace import dumps

CHUNK = 4096


def file_chunks(path: Path) -> Iterator[bytes]:
    with path.open("rb") as f:
        while chunk := f.read(CHUNK):
            yield chunk


def serial_chunks(port: str, baud: int, seconds: float | None) -> Iterator[bytes]:
    """Bytes from a serial port until ``seconds`` pass (forever if None); needs pyserial."""
    try:
        import serial  # type: ignore[import-untyped]  # pyserial, only needed for a live port
    except ImportError:
        raise fail(port, "reading a serial port needs pyserial", "pip install pyserial") from None
    try:
        link = serial.Serial(port, baud, timeout=0.1)
    except (serial.SerialException, OSError) as exc:
        raise fail(port, f"cannot open serial port: {exc}", "check the port name (ls /dev/tty*) and "
                   "that no other program (an IDE's serial monitor) holds it") from None
    end = None if seconds is None else time.monotonic() + seconds
    with link:
        while end is None or time.monotonic() < end:
            data = link.read(CHUNK)
            if data:
                yield data


def check_hello(decoder: Decoder, source: str) -> None:
    """Refuse a stream from firmware built from another table: its hash names the table."""
    layout = decoder.layout
    assert layout is not None
    for hello in decoder.hellos:
        if hello.table_hash != layout.table_hash:
            raise fail(source, f"the firmware runs another table (hash 0x{hello.table_hash:08x}, "
                       f"this table 0x{layout.table_hash:08x})", "give the table the firmware was built from")


def monitor(machine: Machine, chunks: Iterator[bytes], out: IO[str], source: str,
            ticks: int | None = None, warn: Callable[[str], Any] = print) -> int:
    """Decode until the chunks end or ``ticks`` lines are written; returns the lines written."""
    decoder = Decoder(machine, plan(machine))
    written = 0
    for chunk in chunks:
        lines = decoder.feed(chunk)
        check_hello(decoder, source)
        for problem in decoder.problems:
            warn(f"{source}: warning: {problem}")
        decoder.problems.clear()
        for line in lines:
            out.write(dumps(line) + "\n")
            written += 1
            if ticks is not None and written >= ticks:
                return written
        out.flush()
    if decoder.buffer:
        warn(f"{source}: warning: {len(decoder.buffer)} bytes at the end are not a whole frame")
    return written
