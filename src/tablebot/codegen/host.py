"""The generated C engine compiled for this computer: build it, feed it ticks, read back a core trace
(the tests' proof that the C engine equals the Python engine; needs a C compiler)."""

from __future__ import annotations

import shutil
import subprocess
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from tablebot.codegen.source import HOST_RUNNER, generate, template_path
from tablebot.diagnostics import fail
from tablebot.formats.inputs_csv import TickInput
from tablebot.i18n import N_
from tablebot.machine import NO_ROW, Machine
from tablebot.tables import RobotTables

WARNINGS = ("-Wall", "-Wextra", "-std=c99", "-pedantic", "-Werror")


NO_COMPILE = N_("the generated C does not compile")
#: The hint of a failure that is tablebot's own, not the user's (the same words as tablebot.firmware.build's).
BUG = N_("report this as a tablebot bug")


def find_compiler(name: str = "cc") -> str:
    found = shutil.which(name) or shutil.which("gcc")
    if not found:
        raise fail(name, N_("no C compiler found"), N_("install gcc (Debian: apt-get install gcc)"))
    return found


def build_host(machine: Machine, outdir: Path, lookup: str = "auto") -> Path:
    """Generate the C files into ``outdir`` and compile them with host_run.c, warnings as errors."""
    generate(machine, lookup).write(outdir)
    exe = outdir / "host_run"
    sources = [str(template_path(HOST_RUNNER)), str(outdir / "tb_engine.c"), str(outdir / "tb_table.c")]
    command = [find_compiler(), *WARNINGS, "-O1", f"-I{outdir}", "-o", str(exe), *sources]
    done = subprocess.run(command, capture_output=True, text=True, check=False)
    if done.returncode:
        raise fail(outdir, NO_COMPILE, BUG, detail=done.stderr)
    return exe


def trace_line(
    machine: Machine,
    tick: int,
    event: int,
    row: int,
    state: int,
    timer: int,
    outputs: Sequence[int],
    counters: Sequence[int],
) -> dict[str, Any]:
    """A core trace line (see :func:`tablebot.formats.trace_lines.record`) from raw engine values."""
    line: dict[str, Any] = {
        "tick": tick,
        "event": event,
        "row": None if row == NO_ROW else row,
        "state": machine.states[state],
        "timer": timer,
    }
    line.update(zip(machine.output_names, outputs, strict=True))
    line.update(zip(machine.table.robot.counter_names, counters, strict=True))
    return line


def run_host(exe: Path, machine: Machine, ticks: Sequence[TickInput]) -> list[dict[str, Any]]:
    """Run the compiled engine over recorded inputs; one trace line per tick."""
    n_counters = len(machine.table.robot.counters)
    text = "".join(
        " ".join(map(str, [t.mask, *(list(t.pulses) + [0] * n_counters)[:n_counters]])) + "\n" for t in ticks
    )
    done = subprocess.run([str(exe)], input=text, capture_output=True, text=True, check=True)
    n_out = len(machine.output_names)
    lines = []
    for tick, raw in enumerate(done.stdout.splitlines()):
        values = [int(v) for v in raw.split()]
        event, row, state, timer = values[:4]
        lines.append(trace_line(machine, tick, event, row, state, timer, values[4 : 4 + n_out], values[4 + n_out :]))
    return lines


HOST_SEVERAL = "host_several.c"


def build_host_several(
    tables: RobotTables, outdir: Path, lookup: str = "auto", order: Sequence[int] | None = None
) -> Path:
    """:func:`build_host` for a robot of several tables (``order``: the order its tick steps the tables in)."""
    from tablebot.codegen.several import generate_several

    source = generate_several(tables, lookup, order)
    source.write(outdir)
    exe = outdir / "host_several"
    units = [str(outdir / name) for name in source.files if name.endswith(".c") and name != "tb_engine.c"]
    command = [
        find_compiler(),
        *WARNINGS,
        "-O1",
        f"-I{outdir}",
        "-o",
        str(exe),
        str(template_path(HOST_SEVERAL)),
        *units,
    ]
    done = subprocess.run(command, capture_output=True, text=True, check=False)
    if done.returncode:
        raise fail(outdir, NO_COMPILE, BUG, detail=done.stderr)
    return exe


def run_host_several(exe: Path, tables: RobotTables, ticks: Sequence[TickInput]) -> list[dict[str, Any]]:
    """Run a robot's compiled tables over recorded inputs (the robot's input layout); one trace line per tick,
    keyed as :func:`tablebot.replay.record_several` keys them."""
    n_counters = len(tables.robot.counters)
    text = "".join(
        " ".join(map(str, [t.mask, *(list(t.pulses) + [0] * n_counters)[:n_counters]])) + "\n" for t in ticks
    )
    done = subprocess.run([str(exe)], input=text, capture_output=True, text=True, check=True)
    n_tables, n_out = len(tables.machines), len(tables.output_names)
    lines = []
    for tick, raw in enumerate(done.stdout.splitlines()):
        values = [int(v) for v in raw.split()]
        line: dict[str, Any] = {"tick": tick}
        for i, (name, machine) in enumerate(zip(tables.names, tables.machines, strict=True)):
            event, row, state, timer = values[4 * i : 4 * i + 4]
            key = "" if i == 0 else f"{name}."
            line[f"{key}event"] = event
            line[f"{key}row"] = None if row < 0 else machine.table.rows[row].as_written
            line[f"{key}state"] = machine.states[state]
            line[f"{key}timer"] = timer
            if i == 0:  # the main table's keys, then the robot's outputs and counters, as a trace has them
                rest = values[4 * n_tables :]
                line.update(zip(tables.output_names, rest[:n_out], strict=True))
                line.update(zip(tables.robot.counter_names, rest[n_out:], strict=True))
        lines.append(line)
    return lines
