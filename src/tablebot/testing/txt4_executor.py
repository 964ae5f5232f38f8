"""The TXT 4.0 program as an executor (:mod:`tablebot.testing.harness`): ``export --to txt4``'s standalone
program run as the controller runs it (``python -S``: no numpy, no tablebot) against a stub of the
``fischertechnik`` package, whose terminals and counters play the case's inputs; a robot of several tables runs
its runtime's ``Tables``.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path
from typing import Any

from tablebot.formats.inputs_csv import TickInput
from tablebot.machine import Machine
from tablebot.testing.harness import Case, Executor, Run, fits_controller, wired_for
from tablebot.testing.several_cases import SeveralCase, wired_robot

#: The stub of the ``fischertechnik`` package the TXT 4.0 program is run against (a checkout's tests/txt4_stub,
#: or the folder this variable names).
TXT4_STUB = "TABLEBOT_TXT4_STUB"
TXT4_DRIVER = """\
import json, sys
from lib import tablebot_program as program
import fischertechnik.factories as factories
from fischertechnik.controller.Motor import Motor

robot = program.Txt4Robot(program.TABLE, factories, Motor)
engine = program.Engine(program.TABLE)
seen = []
for _ in range(int(sys.argv[1])):
    mask, pulses = robot.read()
    outputs = engine.step(mask, pulses)
    robot.write(outputs)
    seen.append([mask, list(pulses), engine.event, engine.row, engine.state, engine.timer, list(engine.outputs),
                 list(engine.counters)])
robot.stop()
print(json.dumps(seen))
"""


TXT4_SEVERAL_DRIVER = """\
import json, sys
from lib import tablebot_program as program
import fischertechnik.factories as factories
from fischertechnik.controller.Motor import Motor

robot = program.Txt4Robot(program.TABLE, factories, Motor)
engine = program.engine_for(program.TABLE)
seen = []
for _ in range(int(sys.argv[1])):
    mask, pulses = robot.read()
    robot.write(engine.step(mask, pulses))
    seen.append([mask, list(pulses), [[e.event, e.row, e.state, e.timer] for e in engine.engines],
                 list(engine.outputs), list(engine.counters)])
robot.stop()
print(json.dumps(seen))
"""


def _txt4_stub() -> Path:
    given = os.environ.get(TXT4_STUB)
    return Path(given) if given else Path(__file__).resolve().parents[3] / "tests" / "txt4_stub"


def _txt4_program(case: Case, workdir: Path) -> Run:
    """``export --to txt4``'s program, as the controller runs it (``python -S``: no numpy, no tablebot) against
    the stub: its robot reads the inputs off the stub's terminals and counters, its engine steps, its robot
    writes; its own pacing loop is proven equal to ``loop.run`` in tests/hw/test_rules.py."""
    from tablebot.codegen.host import trace_line

    m = wired_for(case.machine.table, "txt")
    seen = _run_txt4(m, case.inputs, workdir, TXT4_DRIVER)
    return Run(
        [TickInput(mask, tuple(pulses)) for mask, pulses, *_ in seen],
        [trace_line(m, i, *values[2:]) for i, values in enumerate(seen)],
    )


def _txt4_several(case: SeveralCase, workdir: Path) -> Run:
    """The TXT 4.0 program of a robot of several tables (its runtime's ``Tables``), as :func:`_txt4_program`."""
    tables = case.tables
    m = wired_robot(tables, "txt")
    seen = _run_txt4(m, case.inputs, workdir, TXT4_SEVERAL_DRIVER)
    lines = []
    for tick, (_, _, decisions, outputs, counters) in enumerate(seen):
        line: dict[str, Any] = {"tick": tick}
        for i, (name, machine) in enumerate(zip(tables.names, tables.machines, strict=True)):
            event, row, state, timer = decisions[i]
            key = "" if i == 0 else f"{name}."
            line.update(
                {
                    f"{key}event": event,
                    f"{key}row": None if row < 0 else machine.table.rows[row].as_written,
                    f"{key}state": machine.states[state],
                    f"{key}timer": timer,
                }
            )
            if i == 0:
                line.update(zip(tables.output_names, outputs, strict=True))
                line.update(zip(tables.robot.counter_names, counters, strict=True))
        lines.append(line)
    return Run([TickInput(mask, tuple(pulses)) for mask, pulses, *_ in seen], lines)


def _run_txt4(m: Machine, inputs: tuple[TickInput, ...], workdir: Path, driver: str) -> list[Any]:
    """Export ``m`` for the TXT 4.0 and run ``driver`` on it against the stub, the stub's terminals and counters
    playing ``inputs``; what the driver printed."""
    from tablebot.hw.txt4.export import export_txt4

    folder = workdir / "txt4"
    export_txt4(m).write(folder)
    (folder / "driver.py").write_text(driver, encoding="utf-8")
    terminals = [int(name[1:]) - 1 for name in m.input_bits]
    script = {
        "inputs": [[0] * 8 for _ in range(len(inputs) + 1)],
        "pulses": [[0, 0, 0, 0] for _ in range(len(inputs) + 1)],
    }
    for row, pulses, tick in zip(script["inputs"], script["pulses"], inputs, strict=False):
        for terminal, bit in zip(terminals, m.input_bits.values(), strict=True):
            row[terminal] = int(bool(tick.mask & bit))
        pulses[: len(tick.pulses)] = list(tick.pulses)
    (folder / "script.json").write_text(json.dumps(script), encoding="utf-8")
    env = {
        "PATH": os.environ.get("PATH", ""),
        "PYTHONPATH": str(_txt4_stub()),
        "TABLEBOT_STUB_SCRIPT": str(folder / "script.json"),
        "TABLEBOT_STUB_LOG": str(folder / "calls.jsonl"),
    }
    done = subprocess.run(
        [sys.executable, "-S", "driver.py", str(len(inputs))],
        cwd=folder,
        env=env,
        capture_output=True,
        text=True,
        timeout=120,
        check=False,
    )
    if done.returncode:
        raise AssertionError(f"the TXT 4.0 program failed: {done.stderr}")
    return list(json.loads(done.stdout.splitlines()[-1]))


def _no_txt4_stub() -> str | None:
    stub = _txt4_stub()
    return None if (stub / "fischertechnik").is_dir() else f"no fischertechnik stub at {stub} (set {TXT4_STUB})"


def _fits_txt(machine: Machine) -> bool:
    return fits_controller(machine)


TXT4_EXECUTOR = Executor(
    "TXT 4.0 program",
    _txt4_program,
    missing=_no_txt4_stub,
    fits=_fits_txt,
    several=_txt4_several,
    what="export --to txt4's standalone program against the fischertechnik stub",
)
