"""The AVR firmware of a robot of several tables (issue 36 §2): the C of :mod:`tablebot.codegen.several` (one
engine struct per table, ``tb_robot_tick`` over them) in ``tb_firmware_several.c``'s tick interrupt, wired for
every input any table reads (:func:`tablebot.engine.as_one.robot_machine`), built with avr-gcc and run under
simavr as a one-table firmware is. Its tick frame (``'S'``) carries every table's event, row, state and timer,
then the robot's outputs and counters; :func:`decode` turns the UART stream into trace lines keyed as
:func:`tablebot.replay.record_several` keys them."""

from __future__ import annotations

import struct
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from tablebot.codegen.several import generate_several
from tablebot.diagnostics import fail
from tablebot.engine.as_one import robot_machine
from tablebot.files import write_text
from tablebot.fileset import file_set
from tablebot.firmware.board_header import board_header
from tablebot.firmware.boards import load_board, wire
from tablebot.firmware.build import BUG, Firmware, c_source, compile_and_link, write_main
from tablebot.firmware.emulate import run_recorded
from tablebot.firmware.framing import take_frames
from tablebot.formats.inputs_csv import TickInput
from tablebot.i18n import N_
from tablebot.machine import Machine
from tablebot.tables import RobotTables

__all__ = ["MAIN", "SeveralDecoder", "build_several", "decode", "emulate_several", "tick_payload"]

MAIN = "tb_firmware_several.c"
HELLO, TICK, VERSION = ord("H"), ord("S"), 2
TABLE_FORMAT = "<IhHH"  # per table: event, row (-1: none), state, timer
#: Emulated time after the last tick: the UART sends the frames in its ring whole (two of up to 128 bytes at
#: 115200 baud); the ticks the firmware makes meanwhile are not the recording's and are dropped.
FLUSH_MS = 25


def tick_payload(tables: RobotTables) -> int:
    """Bytes of a tick frame's payload: tick, each table's decisions, the outputs, the counters."""
    return (
        2
        + struct.calcsize(TABLE_FORMAT) * len(tables.machines)
        + len(tables.output_names)
        + 2 * len(tables.robot.counters)
    )


def build_several(tables: RobotTables, board_name: str, outdir: Path, machine: Machine | None = None) -> Firmware:
    """Generate, compile and link the firmware of ``tables`` (``machine``: what it is wired for, by default
    :func:`robot_machine`); ``outdir`` gets ``src/``, ``tablebot.elf`` and ``tablebot.hex``."""
    board = load_board(board_name)
    machine = machine or robot_machine(tables)
    srcdir = outdir / "src"
    elf, hexfile = outdir / "tablebot.elf", outdir / "tablebot.hex"
    payload = tick_payload(tables)
    with file_set(outdir):
        source = generate_several(tables)
        source.write(srcdir)
        wiring = wire(machine.table.robot, board)
        write_text(srcdir / "tb_board.h", board_header(machine, wiring, source.layout, payload))
        write_text(srcdir / f"board_{board.name}.h", c_source(f"board_{board.name}.h"))
        write_main(srcdir, MAIN)
        units = [name for name in source.files if name.endswith(".c") and name != "tb_engine.c"]
        flash, ram = compile_and_link(board, srcdir, (MAIN, *units), elf, hexfile)
    return Firmware(elf, hexfile, board, wiring, source.layout, flash, ram)


def emulate_several(
    firmware: Firmware, tables: RobotTables, ticks: Sequence[TickInput], workdir: Path, machine: Machine | None = None
) -> list[dict[str, Any]]:
    """Run the firmware under simavr over recorded inputs (the robot's input layout); the decoded trace."""
    machine = machine or robot_machine(tables)
    _, uart = run_recorded(firmware, machine, ticks, workdir, extra=("--flush-ms", str(FLUSH_MS)))
    lines = decode(tables, uart.read_bytes())
    if len(lines) < len(ticks):
        raise fail("uart", N_("{frames} tick frames for {ticks} ticks", frames=len(lines), ticks=len(ticks)), BUG)
    return lines[: len(ticks)]


def decode(tables: RobotTables, data: bytes) -> list[dict[str, Any]]:
    """The trace lines of a whole UART stream; anything wrong in it (a bad checksum, a lost tick, a hello of
    another firmware) is refused, saying where."""
    decoder = SeveralDecoder(tables)
    lines = decoder.feed(data)
    if decoder.problems:
        raise fail("uart", decoder.problems[0], BUG)
    return lines


@dataclass
class SeveralDecoder:
    """Feed it UART bytes in any chunks; it returns trace lines (keyed as a trace of several tables is) and
    notes what went wrong in ``problems``: it resynchronises on the next sync byte after a bad checksum,
    extends tick numbers past 16 bits and names lost ticks (``tablebot monitor``)."""

    tables: RobotTables
    problems: list[str] = field(default_factory=list)
    hellos: int = 0
    ticks: int = 0
    consumed: int = 0
    buffer: bytearray = field(default_factory=bytearray)
    last_tick: int | None = None

    def feed(self, data: bytes) -> list[dict[str, Any]]:
        lines: list[dict[str, Any]] = []

        def take(kind: int, payload: bytes) -> None:
            if kind == TICK:
                lines.append(self._line(payload))
            else:
                self._hello(payload)

        take_frames(self, data, {HELLO: 4, TICK: tick_payload(self.tables)}, take)
        self.ticks += len(lines)
        return lines

    def _hello(self, payload: bytes) -> None:
        self.hellos += 1
        self.last_tick = None  # the firmware restarted: its tick count starts again at 0
        if payload[0] != VERSION or payload[1] != len(self.tables.machines):
            self.problems.append(
                N_(
                    "the firmware says version {version}, {count} tables: not this robot's",
                    version=payload[0],
                    count=payload[1],
                )
            )

    def _line(self, payload: bytes) -> dict[str, Any]:
        tables = self.tables
        tick16 = struct.unpack_from("<H", payload)[0]
        tick = tick16 if self.last_tick is None else self.last_tick + ((tick16 - self.last_tick) & 0xFFFF)
        if self.last_tick is not None and tick != self.last_tick + 1:
            self.problems.append(
                N_("ticks {first}..{last} missing from the stream", first=self.last_tick + 1, last=tick - 1)
            )
        self.last_tick = tick
        line: dict[str, Any] = {"tick": tick}
        at, size = 2, struct.calcsize(TABLE_FORMAT)
        later: dict[str, Any] = {}  # the other tables' keys come after the robot's outputs and counters
        for i, (name, machine) in enumerate(zip(tables.names, tables.machines, strict=True)):
            event, row, state, timer = struct.unpack_from(TABLE_FORMAT, payload, at)
            at += size
            key, into = ("", line) if i == 0 else (f"{name}.", later)
            into.update(
                {
                    f"{key}event": event,
                    f"{key}row": None if row < 0 else machine.table.rows[row].as_written,
                    f"{key}state": machine.states[state],
                    f"{key}timer": timer,
                }
            )
        n_out = len(tables.output_names)
        line.update(zip(tables.output_names, struct.unpack_from(f"<{n_out}b", payload, at), strict=True))
        counters = struct.unpack_from(f"<{len(tables.robot.counters)}H", payload, at + n_out)
        line.update(zip(tables.robot.counter_names, counters, strict=True))
        return {**line, **later}
