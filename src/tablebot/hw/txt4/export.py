"""``tablebot export --to txt4``: a ROBO Pro Coding workspace that runs the table on a TXT 4.0 by itself:
``NAME.py`` starts ``lib/tablebot_program.py``, which is :mod:`tablebot.hw.txt4.runtime` (and the code of
:mod:`tablebot.hw.txt4.runtime_stop`, :func:`runtime_text`) with the compiled table and the robot file's
``[txt]`` wiring appended as plain data (no numpy, no tablebot on the controller). Text from the user's files
reaches the program only as escaped string literals.
"""

from __future__ import annotations

import hashlib
import json
import re
import uuid
from dataclasses import dataclass
from importlib import resources
from pathlib import Path
from typing import Any

from tablebot.engine.as_one import robot_machine
from tablebot.engine.several import cross_bits, input_bits
from tablebot.escape import python_string
from tablebot.files import write_text
from tablebot.fileset import file_set
from tablebot.hw.txt.wiring import TxtWiring, txt_wiring
from tablebot.machine import Machine
from tablebot.tables import RobotTables, several

PROGRAM = "lib/tablebot_program.py"
LAUNCHER = """\
# Runs a tablebot table on this TXT 4.0; written by `tablebot export --to txt4` (see lib/tablebot_program.py).
from lib.tablebot_program import main

main()
"""


@dataclass(frozen=True)
class Workspace:
    """The files of one ROBO Pro Coding workspace, by path relative to its folder."""

    name: str
    files: dict[str, str]

    def write(self, folder: Path) -> list[Path]:
        """The workspace into ``folder``, replacing the previous one's files at once."""
        with file_set(folder):
            return [write_text(folder / relative, text, newline="\n") for relative, text in self.files.items()]


def workspace_name(machine: Machine) -> str:
    """The robot's name as a workspace name: letters, digits and ``_`` (it is a file name and a URL part)."""
    name = re.sub(r"[^A-Za-z0-9_]+", "_", machine.table.robot.name).strip("_")
    return name if name and not name[0].isdigit() else f"tablebot_{name}".rstrip("_")


def export_txt4(machine: Machine) -> Workspace:
    """The workspace for ``machine`` (a robot of several tables: all of them, run as :class:`runtime.Tables`);
    a table that does not fit the TXT's terminals is refused (its robot-file line named) before anything is
    written."""
    tables = several(machine.table)
    if tables is not None:
        machine = robot_machine(tables)  # the robot's inputs, in the layout the runtime's Tables reads
    wiring = txt_wiring(machine)
    name = workspace_name(machine)
    data = table_data(machine, wiring)
    if tables is not None:
        data.update(tables_data(tables))
    table = f"# --- the table, written by `tablebot export --to txt4` ---\n\nTABLE = {literal(data)}\n"
    program = f"{runtime_text()}\n\n{table}"
    digest = hashlib.sha256(program.encode("utf-8")).hexdigest()
    return Workspace(
        name,
        {
            f"{name}.py": LAUNCHER,
            "lib/__init__.py": "",
            PROGRAM: program,
            ".project.json": project_json(name, uuid.uuid5(uuid.NAMESPACE_URL, f"tablebot:{digest}")),
        },
    )


#: The runtime's import of how it stops: the program carries that code itself, so the line is dropped.
STOP_IMPORT = "from tablebot.hw.txt4.runtime_stop import Guard, Stop, Terminated\n"


def runtime_text() -> str:
    """The program's code without its table: :mod:`tablebot.hw.txt4.runtime`, then the code of
    :mod:`tablebot.hw.txt4.runtime_stop` (its imports with it; its docstring and ``__future__`` import, which
    only a file's start may hold, left out), one file needing nothing but the standard library."""
    files = resources.files("tablebot.hw.txt4")
    runtime = files.joinpath("runtime.py").read_text(encoding="utf-8")
    stop = files.joinpath("runtime_stop.py").read_text(encoding="utf-8")
    future = "from __future__ import annotations\n"
    if STOP_IMPORT not in runtime or future not in stop:  # tablebot's own files, changed without this function
        raise RuntimeError("tablebot/hw/txt4: runtime.py no longer imports runtime_stop as export_txt4 expects")
    stop_code = stop.split(future, 1)[1].lstrip("\n")
    return (
        runtime.replace(STOP_IMPORT, "").rstrip("\n")
        + "\n\n\n# --- how the program stops (tablebot.hw.txt4.runtime_stop) ---\n\n"
        + stop_code
    )


def project_json(name: str, project_uuid: uuid.UUID) -> str:
    """``.project.json`` as ROBO Pro Coding writes it: these five keys in this order, on one line, no final
    newline (OliverBerger-ORBIS/ORBIS-Modellfabrik, ``integrations/TXT-*/workspaces/*/.project.json``).
    Mode ``PROFESSIONAL`` is ROBO Pro Coding's Python mode (``FF_AI_24V``: Python files only); an
    ``ADVANCED`` project is edited in blocks and carries ``NAME.blockly`` beside ``NAME.py``, which a
    program written as Python has not."""
    project = {"uuid": str(project_uuid), "name": name, "mode": "PROFESSIONAL", "version": "1.0", "controller": "TXT4"}
    return json.dumps(project, separators=(",", ":"))


def table_data(machine: Machine, wiring: TxtWiring) -> dict[str, Any]:
    """The compiled table and its wiring as plain data for :mod:`tablebot.hw.txt4.runtime`."""
    table, robot = machine.table, machine.table.robot
    per_state: list[list[list[Any]]] = [[] for _ in machine.states]
    for row in machine.rows:
        per_state[row.state].append([row.index, row.mask, row.next, row.timer, list(row.outputs), list(row.loads)])
    wired = wiring.wired
    motors = [(i, out) for i, out in enumerate(wired.outputs) if out.kind == "motor"]
    counted = {c.motor for c in robot.counters}
    terminal_of = {out.name: _number(out.terminal) for _, out in motors}
    return {
        "name": robot.name,
        "source": table.path,
        "tick_ms": robot.tick_ms,
        "states": list(machine.states),
        "initial_state": machine.initial_state,
        "initial_timer": machine.initial_timer,
        "input_mask": machine.input_mask,
        "timer_bit": machine.timer_bit,
        "counter_bits": list(machine.counter_bits),
        "match": robot.match,
        "n_outputs": len(machine.output_names),
        "rows": per_state,
        "inputs": [
            {
                "name": w.name,
                "terminal": _number(w.terminal),
                "mode": w.mode,
                "invert": w.invert,
                "below": w.below,
                "above": w.above,
                "hysteresis": w.hysteresis,
                "bit": bit,
            }
            for w, bit in zip(wired.inputs, wired.bits, strict=True)
        ],
        "motors": [
            {
                "name": out.name,
                "output": i,
                "terminal": _number(out.terminal),
                "reverse": out.reverse,
                "encoder": out.name in counted,
            }
            for i, out in motors
        ],
        "lamps": [
            {"name": out.name, "output": i, "terminal": _number(out.terminal)}
            for i, out in enumerate(wired.outputs)
            if out.kind == "lamp"
        ],
        "counters": [
            {"name": c.name, "terminal": _number(t), "motor": terminal_of.get(c.motor)}
            for c, t in zip(robot.counters, wired.counters, strict=True)
        ],
    }


def engine_data(machine: Machine) -> dict[str, Any]:
    """What :class:`runtime.Engine` needs of one table."""
    per_state: list[list[list[Any]]] = [[] for _ in machine.states]
    for row in machine.rows:
        per_state[row.state].append([row.index, row.mask, row.next, row.timer, list(row.outputs), list(row.loads)])
    return {
        "states": list(machine.states),
        "initial_state": machine.initial_state,
        "initial_timer": machine.initial_timer,
        "input_mask": machine.input_mask,
        "timer_bit": machine.timer_bit,
        "counter_bits": list(machine.counter_bits),
        "match": machine.table.robot.match,
        "n_outputs": len(machine.output_names),
        "rows": per_state,
    }


def tables_data(tables: RobotTables) -> dict[str, Any]:
    """What :class:`runtime.Tables` adds for a robot of several tables: each table's engine, where its inputs
    are in the robot's input layout, its cross-table events per state of each table it reads, and the writer
    of each output and counter (tablebot.tables)."""
    indices = range(len(tables.machines))
    cross = [[[source, bits] for source, bits in cross_bits(tables, i)] for i in indices]
    writers = [tables.writer(name) for name in tables.output_names]
    counter_writers = [
        [c, w] for c, name in enumerate(tables.robot.counter_names) if (w := tables.writer(name)) is not None
    ]
    return {
        "table_names": list(tables.names),
        "tables": [engine_data(m) for m in tables.machines],
        "table_inputs": [[[bit, own] for _, bit, own in input_bits(tables, i)] for i in indices],
        "cross": cross,
        "writers": [-1 if w is None else w for w in writers],
        "counter_writers": counter_writers,
    }


def _number(terminal: str) -> int:
    """A terminal's number, as the TXT 4.0's factories take it: ``"I3"`` -> 3."""
    return int(terminal[1:])


def literal(value: Any, depth: int = 0) -> str:
    """``value`` (None, bools, ints, strings, lists, dicts) as Python source; strings through
    :func:`tablebot.escape.python_string`. Top-level entries and rows go one per line."""
    if value is None or isinstance(value, bool):
        return repr(value)
    if isinstance(value, int):
        return repr(int(value))
    if isinstance(value, str):
        return python_string(value)
    if isinstance(value, list | tuple):
        items = [literal(v, depth + 1) for v in value]
        if depth < 2 and any(isinstance(v, list | dict) for v in value):
            pad = "    " * (depth + 1)
            return "[\n" + "".join(f"{pad}{item},\n" for item in items) + "    " * depth + "]"
        return "[" + ", ".join(items) + "]"
    if isinstance(value, dict):
        items = [f"{literal(k)}: {literal(v, depth + 1)}" for k, v in value.items()]
        if depth == 0:
            return "{\n" + "".join(f"    {item},\n" for item in items) + "}"
        return "{" + ", ".join(items) + "}"
    raise TypeError(f"no Python literal for {type(value).__name__}")
