"""Running a firmware under simavr with the project's C harness (``harness/harness.c``, compiled once
per version into a cache folder): recorded inputs in, decoded UART trace and exact cycles out."""

from __future__ import annotations

import hashlib
import os
import shutil
import statistics
import subprocess
from collections.abc import Sequence
from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path
from typing import Any

from tablebot.diagnostics import fail
from tablebot.firmware.boards import Wiring
from tablebot.firmware.build import Firmware
from tablebot.firmware.framing import Decoder, Hello
from tablebot.formats.inputs_csv import TickInput
from tablebot.i18n import N_
from tablebot.machine import Machine

ADC_OPEN_MV = 5000  # an open ftDuino input: pulled up to 5 V
ADC_CLOSED_MV = 0


def harness_source() -> str:
    return resources.files("tablebot.firmware").joinpath("harness").joinpath("harness.c").read_text(encoding="utf-8")


def cache_dir() -> Path:
    base = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    return Path(base) / "tablebot"


def build_harness(where: Path | None = None) -> Path:
    """Compile the harness against libsimavr (once per source version) and return the program."""
    source = harness_source()
    digest = hashlib.sha256(source.encode()).hexdigest()[:12]
    folder = (where or cache_dir()) / f"harness-{digest}"
    exe = folder / "harness"
    if exe.is_file():
        return exe
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "harness.c").write_text(source, encoding="utf-8")
    cc = shutil.which("cc") or shutil.which("gcc")
    flags = subprocess.run(["pkg-config", "--cflags", "simavr"], capture_output=True, text=True, check=False)
    if not cc or flags.returncode:
        raise fail(
            "harness",
            N_("cannot build the simavr harness: need a C compiler and libsimavr-dev"),
            N_("apt-get install gcc simavr libsimavr-dev libelf-dev pkg-config (scripts/bootstrap.sh)"),
        )
    command = [
        cc,
        "-O2",
        "-Wall",
        "-Wextra",
        *flags.stdout.split(),
        str(folder / "harness.c"),
        "-lsimavr",
        "-lelf",
        "-o",
        str(exe) + ".tmp",
    ]
    done = subprocess.run(command, capture_output=True, text=True, check=False)
    if done.returncode:
        raise fail("harness", N_("compiling the harness failed"), N_("check libsimavr-dev"), detail=done.stderr)
    os.replace(str(exe) + ".tmp", exe)  # atomic: parallel test workers may race here
    return exe


# --- inputs as pin levels -----------------------------------------------------------------------


def _signal(wiring: Wiring, name: str) -> tuple[str, int, int]:
    """(harness column, level when active, level when not) of one robot input."""
    board = wiring.board
    column = board.inputs[wiring.inputs[name]]
    closed, open_ = (ADC_CLOSED_MV, ADC_OPEN_MV) if board.name == "ftduino" else (0, 1)  # millivolts or levels
    return (column, open_, closed) if name in wiring.active_high else (column, closed, open_)


def pins_csv(machine: Machine, wiring: Wiring, ticks: Sequence[TickInput]) -> str:
    """The harness's input CSV: one column per driven pin or ADC channel, one row per tick."""
    signals = [(bit, *_signal(wiring, name)) for name, bit in machine.input_bits.items()]
    counters = [wiring.board.counters[wiring.counters[name]] for name in machine.table.robot.counter_names]
    header = [column for _, column, _, _ in signals] + [f"~{pin}" for pin in counters]
    lines = [",".join(header)]
    for tick in ticks:
        cells = [str(active if tick.mask & bit else idle) for bit, _, active, idle in signals]
        pulses = list(tick.pulses) + [0] * len(counters)
        cells += [str(p) for p in pulses[: len(counters)]]
        lines.append(",".join(cells))
    return "\n".join(lines) + "\n"


# --- running ------------------------------------------------------------------------------------


@dataclass(frozen=True)
class TickCycles:
    """Cycles of one tick interrupt: the engine step alone, and the whole interrupt."""

    step: int
    isr: int


@dataclass
class Emulation:
    """What one emulated run gave: the decoded trace, the hello frame, cycles per tick."""

    trace: list[dict[str, Any]]
    hellos: list[Hello]
    problems: list[str]
    cycles: list[TickCycles] = field(default_factory=list)
    overhead: int = 0


def run_harness(harness: Path, args: list[str], timeout: float = 120) -> None:
    done = subprocess.run([str(harness), *args], capture_output=True, text=True, timeout=timeout, check=False)
    if done.returncode:
        raise fail(
            "harness",
            N_("emulation failed ({code}): {error}", code=done.returncode, error=done.stderr.strip()),
            N_("run the harness by hand with the same arguments to see more"),
        )


def read_cycles(path: Path) -> tuple[int, list[TickCycles]]:
    """The harness's per-tick markers: step = m3 - m2 - marker overhead; isr = exit - entry."""
    overhead, cycles = 0, []
    for line in path.read_text().splitlines():
        if line.startswith("#"):
            overhead = int(line.split()[-1])
            continue
        _, entry, _, m2, m3, _, leave = (int(v) for v in line.split(","))
        cycles.append(TickCycles(step=m3 - m2 - overhead, isr=leave - entry))
    return overhead, cycles


def emulate(
    firmware: Firmware, machine: Machine, ticks: Sequence[TickInput], workdir: Path, harness: Path | None = None
) -> Emulation:
    """Run the firmware over recorded inputs and decode what it sent."""
    if firmware.wiring is None:
        raise fail(firmware.elf, N_("this firmware has no wiring (a benchmark build?)"), N_("build with main firmware"))
    ticks_out, uart = run_recorded(firmware, machine, ticks, workdir, harness)
    decoder = Decoder(machine, firmware.layout)
    trace = decoder.feed(uart.read_bytes())
    overhead, cycles = read_cycles(ticks_out)
    return Emulation(trace, decoder.hellos, decoder.problems, cycles, overhead)


def run_recorded(
    firmware: Firmware,
    machine: Machine,
    ticks: Sequence[TickInput],
    workdir: Path,
    harness: Path | None = None,
    extra: Sequence[str] = (),
) -> tuple[Path, Path]:
    """Run the firmware under the simavr harness over recorded inputs (its pins per tick, written into
    ``workdir``; ``extra``: more harness options); returns the files the harness wrote, its per-tick cycle
    markers and the UART bytes the firmware sent."""
    assert firmware.wiring is not None
    workdir.mkdir(parents=True, exist_ok=True)
    pins, ticks_out, uart = workdir / "pins.csv", workdir / "ticks.csv", workdir / "uart.bin"
    pins.write_text(pins_csv(machine, firmware.wiring, ticks), encoding="utf-8")
    board = firmware.board
    run_harness(
        harness or build_harness(),
        [
            "--elf",
            str(firmware.elf),
            "--mcu",
            board.mcu,
            "--freq",
            str(board.f_cpu),
            "--uart",
            str(board.usart),
            "--inputs",
            str(pins),
            "--ticks-out",
            str(ticks_out),
            "--uart-out",
            str(uart),
            *extra,
        ],
    )
    return ticks_out, uart


def summary(values: Sequence[int]) -> dict[str, float]:
    return {"min": min(values), "median": statistics.median(values), "max": max(values)}


def bench_steps(firmware: Firmware, workdir: Path, harness: Path | None = None) -> list[int]:
    """Cycles of every step the benchmark firmware (``tb_bench.c``) times, in its loop order."""
    harness = harness or build_harness()
    workdir.mkdir(parents=True, exist_ok=True)
    marks = workdir / "marks.csv"
    board = firmware.board
    run_harness(
        harness,
        [
            "--elf",
            str(firmware.elf),
            "--mcu",
            board.mcu,
            "--freq",
            str(board.f_cpu),
            "--marks-out",
            str(marks),
            "--max-ms",
            "60000",
        ],
        timeout=600,
    )
    overhead, start, steps = 0, 0, []
    for line in marks.read_text().splitlines():
        value, cycle = (int(v) for v in line.split(","))
        if value == 0xE0:
            start = cycle
        elif value == 0xE1:
            overhead = cycle - start
        elif value == 2:
            start = cycle
        elif value == 3:
            steps.append(cycle - start - overhead)
    return steps
