"""The differential harness for robots of several tables (issue 36 §2): every executor that runs several tables
(:attr:`tablebot.testing.harness.Executor.several`) takes a :class:`SeveralCase` (a robot's tables and recorded
inputs in the robot-wide layout of :attr:`RobotTables.input_bits`) and returns a :class:`~tablebot.testing.harness.Run`
whose lines are keyed as :func:`tablebot.replay.record_several` keys a trace (the main table's ``tick, event, row,
state, timer``, the robot's outputs and counters, ``NAME.event, NAME.row, NAME.state, NAME.timer`` of each other
table). :func:`several_differences` holds it to :class:`tablebot.engine.several.Several` tick by tick;
:func:`check_several` runs every registered executor and says which cannot run several tables yet."""

from __future__ import annotations

import dataclasses
import random
from collections.abc import Sequence
from pathlib import Path

from tablebot.engine.as_one import robot_machine
from tablebot.formats.inputs_csv import TickInput
from tablebot.machine import Machine
from tablebot.replay import replay_several
from tablebot.tables import RobotTables
from tablebot.testing.harness import EXECUTORS, Report, Run, SeveralCase, executor_folder, first_difference, wired_for

__all__ = ["SeveralCase", "check_several", "random_several_case", "several_differences", "several_ticks", "wired_robot"]


def several_ticks(rng: random.Random, tables: RobotTables, count: int, density: float = 0.4) -> list[TickInput]:
    """Inputs for a robot of several tables: many ticks with no input at all (where the two matching rules
    part), encoder pulses for every counter."""
    width, counters = len(tables.input_bits), len(tables.robot.counters)
    return [
        TickInput(
            rng.randrange(1 << width) if rng.random() < density else 0,
            tuple(rng.choice((0, 0, 1, 3)) for _ in range(counters)),
        )
        for _ in range(count)
    ]


def random_several_case(seed: int, folder: Path, ticks: int = 240) -> SeveralCase:
    """A random robot of 2-3 tables (:mod:`tablebot.testing.random_robots`, written as a user's files into
    ``folder`` and read back) and random inputs for it."""
    from tablebot.formats.table_read import load_table
    from tablebot.tables import load_tables
    from tablebot.testing.random_robots import RobotShape, random_robot

    rng = random.Random(seed)
    tables = load_tables(load_table(random_robot(rng, folder, RobotShape(tables=2 + seed % 2)) / "t0.csv"))
    return SeveralCase(tables, tuple(several_ticks(rng, tables, ticks)), seed)


def wired_robot(tables: RobotTables, section: str) -> Machine:
    """What a controller of a robot of several tables is wired for (:func:`tablebot.engine.as_one.robot_machine`:
    the robot-wide input layout), its robot file given the section ``section`` as
    :func:`tablebot.testing.harness.wired_for` writes it."""
    wired = wired_for(tables.table, section)
    return dataclasses.replace(robot_machine(tables), table=wired.table)


def several_differences(tables: RobotTables, run: Run, order: Sequence[int] | None = None) -> str | None:
    """The first tick where ``run`` disagrees with :class:`~tablebot.engine.several.Several` (stepping its
    tables in ``order``) on the inputs it read, or None. Every key of the engine's line must be reported."""
    return first_difference(run.lines, list(replay_several(tables, run.inputs, order)))


def check_several(case: SeveralCase, workdir: Path, names: Sequence[str] | None = None) -> Report:
    """Run every registered executor (or ``names``) that runs several tables on ``case`` and compare each with
    the engine; the others are skipped, saying so."""
    report = Report()
    for name in names or list(EXECUTORS):
        executor = EXECUTORS[name]
        why = (
            executor.missing()
            or (None if executor.several else "runs one table only")
            or (None if executor.fits(robot_machine(case.tables)) else "does not take this robot")
        )
        if why or executor.several is None:
            report.skipped[name] = why or ""
            continue
        report.note(name, several_differences(case.tables, executor.several(case, executor_folder(workdir, name))))
    return report
