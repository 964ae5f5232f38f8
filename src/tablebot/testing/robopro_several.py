"""The ROBO Pro program of a robot of several tables in the differential harness: the executor
(:func:`robopro_several`, registered with the ROBO Pro program's one-table executor in
:mod:`tablebot.testing.executors`), what it takes (:func:`fits_robopro_several`) and random robots it takes
(:func:`robopro_several_case`: :mod:`tablebot.testing.random_robots`' robots with the document's speeds, 0..6,
wired for a TXT, whose program has counters)."""

from __future__ import annotations

import csv
import dataclasses
import io
import random
from typing import TYPE_CHECKING

from tablebot.testing.harness import Run, SeveralCase

if TYPE_CHECKING:
    from pathlib import Path

    from tablebot.machine import Machine
    from tablebot.table import Table
    from tablebot.tables import RobotTables

__all__ = ["ROBOPRO_SEVERAL_TICKS", "fits_robopro_several", "robopro_several", "robopro_several_case", "wired_txt"]

#: Ticks of a case the interpreter runs (every element of every process, about 5 ms a tick of three tables).
ROBOPRO_SEVERAL_TICKS = 400


def wired_txt(table: Table) -> Table:
    """A table's robot with a ``[robopro]`` section for a TXT (the controller whose program has counters)."""
    return dataclasses.replace(
        table,
        robot=dataclasses.replace(table.robot, sections={**table.robot.sections, "robopro": {"controller": "txt"}}),
    )


def _tables(main: Table) -> RobotTables:
    from tablebot.tables import load_tables

    return load_tables(wired_txt(main))


def fits_robopro_several(machine: Machine) -> bool:
    """Whether the program of the robot ``machine``'s table belongs to takes all its tables."""
    from tablebot.diagnostics import TableBotError
    from tablebot.robopro.processes import several_problems

    try:
        return not several_problems(_tables(machine.table))
    except TableBotError:
        return False


def robopro_several(case: SeveralCase, workdir: Path) -> Run:
    """``export --to robopro-program``'s program of the case's robot in the element interpreter, its processes
    switched at random after any element (the case's seed), on the first ROBOPRO_SEVERAL_TICKS ticks."""
    from tablebot.robopro.executor import run_several

    inputs = list(case.inputs[:ROBOPRO_SEVERAL_TICKS])
    return Run(inputs, run_several(_tables(case.tables.table), inputs, seed=case.seed))


def robopro_several_case(seed: int, folder: Path, ticks: int = 240) -> SeveralCase:
    """A random robot of 2–3 tables (as :func:`tablebot.testing.several_cases.random_several_case` makes them)
    whose motor speeds are within the document's 0..6, and random inputs for it."""
    from tablebot.formats.table_read import load_table
    from tablebot.tables import load_tables
    from tablebot.testing.random_robots import RobotShape, random_robot
    from tablebot.testing.several_cases import several_ticks

    rng = random.Random(seed)
    random_robot(rng, folder, RobotShape(tables=2 + seed % 2))
    for path in sorted(folder.glob("t*.csv")):
        path.write_text(_document_speeds(path.read_text(encoding="utf-8")), encoding="utf-8")
    tables = load_tables(load_table(folder / "t0.csv"))
    return SeveralCase(tables, tuple(several_ticks(rng, tables, ticks)), seed)


def _document_speeds(text: str) -> str:
    """A table's CSV with every motor speed above 6 written as 6 (the document's action word holds 0..6)."""
    rows = list(csv.reader(io.StringIO(text)))
    motors = [i for i, name in enumerate(rows[0]) if name.startswith("M")]
    for row in rows[1:]:
        for i in motors:
            if row[i].lstrip("-").isdigit() and abs(int(row[i])) > 6:
                row[i] = "-6" if row[i].startswith("-") else "6"
    out = io.StringIO()
    csv.writer(out, lineterminator="\n").writerows(rows)
    return out.getvalue()
