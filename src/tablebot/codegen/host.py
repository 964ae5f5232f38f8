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
from tablebot.machine import NO_ROW, Machine

WARNINGS = ("-Wall", "-Wextra", "-std=c99", "-pedantic", "-Werror")


def find_compiler(name: str = "cc") -> str:
    found = shutil.which(name) or shutil.which("gcc")
    if not found:
        raise fail(name, "no C compiler found", "install gcc (Debian: apt-get install gcc)")
    return found


def build_host(machine: Machine, outdir: Path, lookup: str = "auto") -> Path:
    """Generate the C files into ``outdir`` and compile them with host_run.c, warnings as errors."""
    generate(machine, lookup).write(outdir)
    exe = outdir / "host_run"
    sources = [str(template_path(HOST_RUNNER)), str(outdir / "tb_engine.c"), str(outdir / "tb_table.c")]
    command = [find_compiler(), *WARNINGS, "-O1", f"-I{outdir}", "-o", str(exe), *sources]
    done = subprocess.run(command, capture_output=True, text=True, check=False)
    if done.returncode:
        raise fail(outdir, "the generated C does not compile", "report this as a tablebot bug", detail=done.stderr)
    return exe


def trace_line(machine: Machine, tick: int, event: int, row: int, state: int, timer: int,
               outputs: Sequence[int], counters: Sequence[int]) -> dict[str, Any]:
    """A core trace line (see :func:`tablebot.formats.trace_lines.record`) from raw engine values."""
    line: dict[str, Any] = {"tick": tick, "event": event, "row": None if row == NO_ROW else row,
                            "state": machine.states[state], "timer": timer}
    line.update(zip(machine.output_names, outputs, strict=True))
    line.update(zip(machine.table.robot.counter_names, counters, strict=True))
    return line


def run_host(exe: Path, machine: Machine, ticks: Sequence[TickInput]) -> list[dict[str, Any]]:
    """Run the compiled engine over recorded inputs; one trace line per tick."""
    n_counters = len(machine.table.robot.counters)
    text = "".join(" ".join(map(str, [t.mask, *(list(t.pulses) + [0] * n_counters)[:n_counters]])) + "\n"
                   for t in ticks)
    done = subprocess.run([str(exe)], input=text, capture_output=True, text=True, check=True)
    n_out = len(machine.output_names)
    lines = []
    for tick, raw in enumerate(done.stdout.splitlines()):
        values = [int(v) for v in raw.split()]
        event, row, state, timer = values[:4]
        lines.append(trace_line(machine, tick, event, row, state, timer,
                                values[4:4 + n_out], values[4 + n_out:]))
    return lines
