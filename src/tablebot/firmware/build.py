"""``tablebot build``: the generated engine, table and wiring compiled with avr-gcc into .elf and .hex;
the sources stay next to the products (``OUT/src``) for inspection."""

from __future__ import annotations

import shutil
import subprocess
from collections.abc import Sequence
from dataclasses import dataclass
from importlib import resources
from pathlib import Path

from tablebot.codegen.packing import Layout
from tablebot.codegen.source import generate
from tablebot.diagnostics import fail
from tablebot.files import replacing, write_text
from tablebot.fileset import current, file_set
from tablebot.firmware.board_header import board_header
from tablebot.firmware.boards import Board, Wiring, load_board, wire
from tablebot.i18n import N_
from tablebot.machine import Machine

# -O2 with link-time optimisation: tb_tick() is inlined into the tick interrupt, so the engine
# state is addressed directly (about half the cycles of a call through a pointer).
CFLAGS = ("-std=c99", "-Wall", "-Wextra", "-Werror", "-O2", "-flto", "-ffunction-sections", "-fdata-sections")
FIRMWARE_MAIN = "tb_firmware.c"
BENCH_MAIN = "tb_bench.c"
#: The C every main includes beside the generated files: the cycle markers, and main(), the tick interrupt and
#: the frame ring that tb_firmware.c and tb_firmware_several.c share.
SHARED_HEADERS = ("tb_mark.h", "tb_tick_frames.h")


@dataclass(frozen=True)
class Firmware:
    """What a build produced, and how big it is."""

    elf: Path
    hex: Path
    board: Board
    wiring: Wiring | None
    layout: Layout
    flash: int  # bytes: .text + .data
    ram: int  # bytes of static RAM: .data + .bss (the stack comes on top)


#: The hint of a failure that is tablebot's own, not the user's.
BUG = N_("report this as a tablebot bug")


def tool(name: str) -> str:
    found = shutil.which(name)
    if not found:
        raise fail(
            name,
            N_("{name} not found (only firmware needs it)", name=name),
            N_(
                "install the AVR toolchain: on Debian or Ubuntu sudo apt-get install gcc-avr avr-libc; on macOS "
                "brew tap osx-cross/avr, then brew install avr-gcc; on Windows unpack Microchip's AVR 8-bit "
                "Toolchain (Windows) and add its bin folder to PATH (docs/install.md)"
            ),
        )
    return found


def c_source(name: str) -> str:
    return resources.files("tablebot.firmware").joinpath("c").joinpath(name).read_text(encoding="utf-8")


def write_sources(
    machine: Machine, board: Board, srcdir: Path, lookup: str = "auto", main: str = FIRMWARE_MAIN
) -> tuple[Wiring | None, Layout]:
    """All C files of one firmware into ``srcdir``; the benchmark main needs no wiring."""
    source = generate(machine, lookup)
    source.write(srcdir)
    wiring = None
    if main == FIRMWARE_MAIN:
        wiring = wire(machine.table.robot, board)
        write_text(srcdir / "tb_board.h", board_header(machine, wiring, source.layout))
        write_text(srcdir / f"board_{board.name}.h", c_source(f"board_{board.name}.h"))
    write_main(srcdir, main)
    return wiring, source.layout


def write_main(srcdir: Path, main: str) -> None:
    """A firmware's main C file and the headers it shares with the other mains into ``srcdir``."""
    for name in (*SHARED_HEADERS, main):
        write_text(srcdir / name, c_source(name))


def _run(command: list[str], what: str) -> str:
    done = subprocess.run(command, capture_output=True, text=True, check=False)
    if done.returncode:
        raise fail(command[0], N_("{tool} failed", tool=what), BUG, detail=done.stderr.strip())
    return done.stdout


def sizes(elf: Path) -> tuple[int, int]:
    """(flash, static RAM) in bytes from avr-size's Berkeley format: text+data, data+bss."""
    text, data, bss = (int(v) for v in _run([tool("avr-size"), str(elf)], "avr-size").splitlines()[1].split()[:3])
    return text + data, data + bss


def build(machine: Machine, board_name: str, outdir: Path, lookup: str = "auto", main: str = FIRMWARE_MAIN) -> Firmware:
    """Generate, compile and link; ``outdir`` gets ``src/``, ``NAME.elf`` and ``NAME.hex``."""
    board = load_board(board_name)
    srcdir = outdir / "src"
    stem = "tablebot" if main == FIRMWARE_MAIN else "bench"
    elf, hexfile = outdir / f"{stem}.elf", outdir / f"{stem}.hex"
    with file_set(outdir):  # sources, .elf and .hex replace the previous build's at once
        wiring, layout = write_sources(machine, board, srcdir, lookup, main)
        flash, ram = compile_and_link(board, srcdir, (main, "tb_engine.c", "tb_table.c"), elf, hexfile)
    return Firmware(elf, hexfile, board, wiring, layout, flash, ram)


def compile_and_link(board: Board, srcdir: Path, units: Sequence[str], elf: Path, hexfile: Path) -> tuple[int, int]:
    """avr-gcc the C ``units`` of ``srcdir`` into ``elf`` and ``hexfile``, inside a :func:`file_set` of their
    folder; (flash, static RAM) in bytes."""
    # until the set is swapped in, the tools read the files where they are being written
    sources = [str(current(srcdir / name)) for name in units]
    with replacing(elf) as temp:  # the tools write in place: a half-written .elf or .hex must not stay
        _run(
            [
                tool("avr-gcc"),
                f"-mmcu={board.mcu}",
                f"-DF_CPU={board.f_cpu}UL",
                *CFLAGS,
                f"-I{current(srcdir)}",
                "-Wl,--gc-sections",
                "-o",
                str(temp),
                *sources,
            ],
            "avr-gcc",
        )
    with replacing(hexfile) as temp:
        _run([tool("avr-objcopy"), "-O", "ihex", "-R", ".eeprom", str(current(elf)), str(temp)], "avr-objcopy")
    return sizes(current(elf))
