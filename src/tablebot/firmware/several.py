"""The AVR firmware of a robot of several tables (issue 36 §2): the C of :mod:`tablebot.codegen.several` (one
engine struct per table, ``tb_robot_tick`` over them) in ``tb_firmware_several.c``'s tick interrupt, wired for
every input any table reads (:func:`tablebot.engine.as_one.robot_machine`), built with avr-gcc and run under
simavr as a one-table firmware is. Its tick frame (``'S'``) carries every table's event, row, state and timer,
then the robot's outputs and counters; :func:`decode` turns the UART stream into trace lines keyed as
:func:`tablebot.replay.record_several` keys them."""

from __future__ import annotations

import struct
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from tablebot.codegen.several import generate_several
from tablebot.diagnostics import fail
from tablebot.engine.as_one import robot_machine
from tablebot.files import replacing, write_text
from tablebot.fileset import current, file_set
from tablebot.firmware.board_header import board_header
from tablebot.firmware.boards import load_board, wire
from tablebot.firmware.build import CFLAGS, Firmware, _run, c_source, sizes, tool
from tablebot.firmware.emulate import build_harness, pins_csv, run_harness
from tablebot.firmware.framing import SYNC, checksum
from tablebot.formats.inputs_csv import TickInput
from tablebot.machine import Machine
from tablebot.tables import RobotTables

__all__ = ["MAIN", "build_several", "decode", "emulate_several", "tick_payload"]

MAIN = "tb_firmware_several.c"
HELLO, TICK, VERSION = ord("H"), ord("S"), 2
TABLE_FORMAT = "<IhHH"  # per table: event, row (-1: none), state, timer
#: Emulated time after the last tick: the UART sends the frames in its ring whole (two of up to 128 bytes at
#: 115200 baud); the ticks the firmware makes meanwhile are not the recording's and are dropped.
FLUSH_MS = 25


def tick_payload(tables: RobotTables) -> int:
    """Bytes of a tick frame's payload: tick, each table's decisions, the outputs, the counters."""
    return 2 + struct.calcsize(TABLE_FORMAT) * len(tables.machines) + len(tables.output_names) \
        + 2 * len(tables.robot.counters)


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
        write_text(srcdir / MAIN, c_source(MAIN))
        units = [name for name in source.files if name.endswith(".c") and name != "tb_engine.c"]
        sources = [str(current(srcdir / name)) for name in (MAIN, *units)]
        with replacing(elf) as temp:
            _run([tool("avr-gcc"), f"-mmcu={board.mcu}", f"-DF_CPU={board.f_cpu}UL", *CFLAGS,
                  f"-I{current(srcdir)}", "-Wl,--gc-sections", "-o", str(temp), *sources], "avr-gcc")
        with replacing(hexfile) as temp:
            _run([tool("avr-objcopy"), "-O", "ihex", "-R", ".eeprom", str(current(elf)), str(temp)], "avr-objcopy")
        flash, ram = sizes(current(elf))
    return Firmware(elf, hexfile, board, wiring, source.layout, flash, ram)


def emulate_several(firmware: Firmware, tables: RobotTables, ticks: Sequence[TickInput], workdir: Path,
                    machine: Machine | None = None) -> list[dict[str, Any]]:
    """Run the firmware under simavr over recorded inputs (the robot's input layout); the decoded trace."""
    assert firmware.wiring is not None
    machine = machine or robot_machine(tables)
    workdir.mkdir(parents=True, exist_ok=True)
    pins, ticks_out, uart = workdir / "pins.csv", workdir / "ticks.csv", workdir / "uart.bin"
    pins.write_text(pins_csv(machine, firmware.wiring, ticks), encoding="utf-8")
    board = firmware.board
    run_harness(build_harness(), ["--elf", str(firmware.elf), "--mcu", board.mcu, "--freq", str(board.f_cpu),
                                  "--uart", str(board.usart), "--inputs", str(pins), "--ticks-out", str(ticks_out),
                                  "--uart-out", str(uart), "--flush-ms", str(FLUSH_MS)])
    lines = decode(tables, uart.read_bytes())
    if len(lines) < len(ticks):
        raise fail("uart", f"{len(lines)} tick frames for {len(ticks)} ticks", "report this as a tablebot bug")
    return lines[:len(ticks)]


def decode(tables: RobotTables, data: bytes) -> list[dict[str, Any]]:
    """The trace lines of a firmware's UART stream: a hello frame, then one tick frame per tick; anything
    else (a bad checksum, a gap in the tick numbers) is refused, saying where."""
    lengths = {HELLO: 4, TICK: tick_payload(tables)}
    lines: list[dict[str, Any]] = []
    at = 0
    while at < len(data):
        kind = data[at + 1] if at + 1 < len(data) else None
        if data[at] != SYNC or kind not in lengths:
            raise fail("uart", f"byte {at}: no frame starts here", "report this as a tablebot bug")
        end = at + 2 + lengths[kind]
        body = data[at + 1:end + 1]
        if len(body) < lengths[kind] + 2:  # the run ended inside a frame
            break
        if checksum(body[:-1]) != body[-1]:
            raise fail("uart", f"byte {at}: bad checksum", "report this as a tablebot bug")
        if kind == TICK:
            lines.append(_line(tables, body[1:-1], len(lines)))
        elif body[1] != VERSION or body[2] != len(tables.machines):
            raise fail("uart", f"the firmware says version {body[1]}, {body[2]} tables", "build it again")
        at = end + 1
    return lines


def _line(tables: RobotTables, payload: bytes, expected: int) -> dict[str, Any]:
    tick = struct.unpack_from("<H", payload)[0]
    if tick != expected & 0xFFFF:
        raise fail("uart", f"tick frame {expected} says tick {tick}: a frame was dropped", "use a slower tick")
    line: dict[str, Any] = {"tick": expected}
    at, size = 2, struct.calcsize(TABLE_FORMAT)
    for i, (name, machine) in enumerate(zip(tables.names, tables.machines, strict=True)):
        event, row, state, timer = struct.unpack_from(TABLE_FORMAT, payload, at)
        at += size
        key = "" if i == 0 else f"{name}."
        line.update({f"{key}event": event, f"{key}row": None if row < 0 else machine.table.rows[row].as_written,
                     f"{key}state": machine.states[state], f"{key}timer": timer})
    n_out = len(tables.output_names)
    outputs = struct.unpack_from(f"<{n_out}b", payload, at)
    counters = struct.unpack_from(f"<{len(tables.robot.counters)}H", payload, at + n_out)
    main = {**dict(zip(tables.output_names, outputs, strict=True)),
            **dict(zip(tables.robot.counter_names, counters, strict=True))}
    keys = list(line)
    return {**{k: line[k] for k in keys[:5]}, **main, **{k: line[k] for k in keys[5:]}}
