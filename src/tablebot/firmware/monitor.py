"""``tablebot monitor``: a firmware's UART trace stream (a serial port, or a file of captured bytes)
decoded into the core's JSON Lines trace.
"""

from __future__ import annotations

import re
import time
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import IO, Any

from tablebot.codegen.packing import plan
from tablebot.diagnostics import fail, severity_word
from tablebot.firmware.framing import Decoder
from tablebot.firmware.several import SeveralDecoder
from tablebot.formats.trace_lines import dumps
from tablebot.i18n import N_, localise
from tablebot.machine import Machine
from tablebot.tables import RobotTables, several

CHUNK = 4096
MAX_WARNINGS = 20  # a stream of garbage would otherwise print a warning per sync byte
PORT_RE = re.compile(r"^(/dev/|COM\d+$|\\\\\.\\|\w+://)", re.IGNORECASE)  # /dev/tty*, COM3, \\.\COM10, URLs


def chunks_from(source: str, baud: int, seconds: float | None) -> Iterator[bytes]:
    """The bytes of a capture file, or of a serial port when ``source`` names one."""
    path = Path(source)
    if path.is_dir():
        raise fail(source, N_("is a folder, not a capture file or serial port"), N_("give the file of captured bytes"))
    if path.is_file():
        return file_chunks(path)
    if not PORT_RE.match(source):
        raise fail(
            source,
            N_("no such file, and not a serial port name"),
            N_("give a file of captured UART bytes, or a port such as /dev/ttyACM0 or COM3"),
        )
    return serial_chunks(source, baud, seconds)


def file_chunks(path: Path) -> Iterator[bytes]:
    with path.open("rb") as f:
        while chunk := f.read(CHUNK):
            yield chunk


def serial_chunks(port: str, baud: int, seconds: float | None) -> Iterator[bytes]:
    """Bytes from a serial port until ``seconds`` pass (forever if None); needs pyserial."""
    try:
        import serial  # pyserial, only needed for a live port
    except ImportError:
        raise fail(port, N_("reading a serial port needs pyserial"), "pip install pyserial") from None
    try:
        link = serial.Serial(port, baud, timeout=0.1)
    except (serial.SerialException, OSError) as exc:
        raise fail(
            port,
            N_("cannot open serial port: {error}", error=str(exc)),
            N_("check the port name (ls /dev/tty*) and that no other program (an IDE's serial monitor) holds it"),
        ) from None
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
            raise fail(
                source,
                N_(
                    "the firmware runs another table (hash 0x{theirs:08x}, this table 0x{ours:08x})",
                    theirs=hello.table_hash,
                    ours=layout.table_hash,
                ),
                BUILT_FROM,
            )


def monitor(
    machine: Machine,
    chunks: Iterator[bytes],
    out: IO[str],
    source: str,
    ticks: int | None = None,
    warn: Callable[[str], Any] = print,
) -> int:
    """Decode until the chunks end or ``ticks`` lines are written; returns the lines written.

    A stream in which no frame decodes at all is refused: it is not this firmware's trace.
    """
    tables = several(machine.table)
    if tables is not None:  # a robot of several tables: its firmware's frames carry all of them
        return _monitor_several(tables, chunks, out, source, ticks, warn)
    decoder = Decoder(machine, plan(machine))
    written = _copy(decoder, chunks, out, source, ticks, warn, lambda: check_hello(decoder, source))
    if ticks is not None and written >= ticks:
        return written
    _none_decoded(
        decoder,
        source,
        N_("give the UART bytes (115200 baud 8N1, or --baud) of firmware built from this table by `tablebot build`"),
    )
    if decoder.rejected * 10 > decoder.rejected + decoder.ticks:  # more than noise: another table's stream
        raise fail(
            source,
            N_(
                "{rejected} of {count} tick frames are impossible for this table",
                rejected=decoder.rejected,
                count=decoder.rejected + decoder.ticks,
            ),
            BUILT_FROM,
        )
    _leftover(decoder, source, warn)
    return written


#: The hint of a stream from another table's firmware.
BUILT_FROM = N_("give the table the firmware was built from")


def _warning(source: str, text: str) -> str:
    """A warning line in the reader's language: ``SOURCE: warning: TEXT``."""
    return f"{source}: {severity_word('warning')}: {localise(text)}"


def _monitor_several(
    tables: RobotTables,
    chunks: Iterator[bytes],
    out: IO[str],
    source: str,
    ticks: int | None,
    warn: Callable[[str], Any],
) -> int:
    """:func:`monitor` of the firmware of a robot of several tables (tablebot.firmware.several)."""
    decoder = SeveralDecoder(tables)
    written = _copy(decoder, chunks, out, source, ticks, warn)
    if ticks is not None and written >= ticks:
        return written
    _none_decoded(
        decoder,
        source,
        N_("give the UART bytes (115200 baud 8N1, or --baud) of firmware built from this robot by `tablebot build`"),
    )
    _leftover(decoder, source, warn)
    return written


def _copy(
    decoder: Decoder | SeveralDecoder,
    chunks: Iterator[bytes],
    out: IO[str],
    source: str,
    ticks: int | None,
    warn: Callable[[str], Any],
    check: Callable[[], None] = lambda: None,
) -> int:
    """The decoded lines of ``chunks`` onto ``out`` (``ticks`` of them at the most, None: all), the decoder's
    problems passed to ``warn`` as they come; ``check`` after every chunk may refuse the stream. Lines written."""
    written = warned = 0
    for chunk in chunks:
        lines = decoder.feed(chunk)
        check()
        warned = _warn(decoder, source, warn, warned)
        for line in lines[: len(lines) if ticks is None else ticks - written]:
            out.write(dumps(line) + "\n")
            written += 1
        if ticks is not None and written >= ticks:
            return written
        out.flush()
    return written


def _none_decoded(decoder: Decoder | SeveralDecoder, source: str, hint: str) -> None:
    """Refuse a stream in which no frame decoded at all: it is not this firmware's trace."""
    if not decoder.hellos and not decoder.ticks:
        raise fail(source, N_("no trace frame in {count} bytes", count=decoder.consumed + len(decoder.buffer)), hint)


def _leftover(decoder: Decoder | SeveralDecoder, source: str, warn: Callable[[str], Any]) -> None:
    """Warn of bytes at the end that are not a whole frame (the capture was cut)."""
    if decoder.buffer:
        warn(_warning(source, N_("{count} bytes at the end are not a whole frame", count=len(decoder.buffer))))


def _warn(decoder: Decoder | SeveralDecoder, source: str, warn: Callable[[str], Any], warned: int) -> int:
    """Pass the decoder's new problems on, up to MAX_WARNINGS in all; returns how many were passed."""
    for problem in decoder.problems:
        if warned < MAX_WARNINGS:
            warn(_warning(source, problem))
        elif warned == MAX_WARNINGS:
            warn(_warning(source, N_("more problems follow; not shown")))
        warned += 1
    decoder.problems.clear()
    return warned
