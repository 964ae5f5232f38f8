"""The differential harness: a registry of every executor of a table, and the check that holds each to the
Python engine.

An executor runs a compiled machine on a :class:`Case` (recorded inputs: the input mask and the encoder
pulses of every tick) and returns a :class:`Run`: the inputs it read and one core trace line per tick
(``tick``, ``event``, ``row``, ``state``, ``timer``, each output, each counter: what
:func:`tablebot.replay.record` writes). Most replay the case's inputs; the simulator and the fleet sense
their own (a random table in a small busy room, or a shipped example in its own world) and report what they
read. :func:`differences` replays the inputs an executor read through ``Engine.step`` and names the first
tick and field where it disagrees.

A new executor is one :func:`register` call (the executors of this tablebot: :mod:`tablebot.testing.executors`);
``tests/testing/test_executors.py`` runs every registered one on the same random tables (counters and pulses included)
and the shipped examples. A case carries the matching rule, so an executor that knows only one rule says so in
``rules`` and is left out of cases with the other.
"""

from __future__ import annotations

import dataclasses
import random
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from tablebot.formats.inputs_csv import TickInput
from tablebot.machine import Machine, compile_table
from tablebot.replay import replay
from tablebot.table import Table
from tablebot.tables import RobotTables

#: The core fields every executor reports for every tick.
CORE = ("tick", "event", "row", "state", "timer")


@dataclass(frozen=True)
class Case:
    """A table and recorded inputs to run it on (``seed``: where they came from, for a simulated world)."""

    machine: Machine
    inputs: tuple[TickInput, ...]
    seed: int = 0
    rule: str = "always"  # the matching rule: a row with no required events always matches
    own_world: bool = False  # simulated executors: the robot's own world and [sim], else a busy random room


@dataclass(frozen=True)
class SeveralCase:
    """A robot of several tables and recorded inputs (the robot-wide layout of :attr:`RobotTables.input_bits`)
    to run it on (``seed``: where they came from); :mod:`tablebot.testing.several_cases` runs it."""

    tables: RobotTables
    inputs: tuple[TickInput, ...]
    seed: int = 0


@dataclass(frozen=True)
class Run:
    """What an executor did: the inputs it read and one trace line per tick (a line may leave out fields the
    executor cannot report: they are not compared)."""

    inputs: list[TickInput]
    lines: list[dict[str, Any]]


@dataclass(frozen=True)
class Executor:
    """One way tablebot runs a table. ``run(case, workdir)`` -> :class:`Run`; ``missing()`` says why it cannot
    run here (a tool not installed) or None; ``fits(machine)`` whether it takes that table at all."""

    name: str
    run: Callable[[Case, Path], Run]
    missing: Callable[[], str | None] = lambda: None
    fits: Callable[[Machine], bool] = lambda machine: True
    rules: tuple[str, ...] = ("always",)
    what: str = ""  # which path of tablebot this is, in a few words
    #: How it runs a robot of several tables (:mod:`tablebot.testing.several_cases`), None if it runs one table.
    several: Callable[[SeveralCase, Path], Run] | None = None


EXECUTORS: dict[str, Executor] = {}


def register(executor: Executor) -> Executor:
    EXECUTORS[executor.name] = executor
    return executor


def differences(machine: Machine, run: Run) -> str | None:
    """The first tick where ``run`` disagrees with ``Engine.step`` on the inputs it read, or None. Fields an
    executor's line leaves out are not compared (``Engine.run``'s per-tick columns have no outputs)."""
    return first_difference(run.lines, list(replay(machine, run.inputs)), CORE)


def first_difference(
    lines: Sequence[dict[str, Any]], expected: Sequence[dict[str, Any]], required: Sequence[str] | None = None
) -> str | None:
    """The first tick and field where an executor's ``lines`` disagree with the engine's ``expected`` lines, or
    None; ``required``: the keys each line must report (None: every key of the engine's line)."""
    if len(lines) != len(expected):
        return f"{len(lines)} ticks reported for {len(expected)} inputs"
    for line, want in zip(lines, expected, strict=True):
        missing = [key for key in (want if required is None else required) if key not in line]
        if missing:
            return f"tick {want['tick']}: no {', '.join(missing)} reported"
        for key, value in line.items():
            if want.get(key, value) != value:
                return f"tick {want['tick']}: {key} is {value!r}, the engine says {want[key]!r} ({want})"
    return None


# --- random worlds -------------------------------------------------------------------------------------


def random_world(rng: random.Random) -> str:
    """A room with a lamp, a box and a pot in random places (away from the start at (0.5, 0.5)), maybe noise:
    a world file's text."""
    size = rng.uniform(2.0, 3.5)

    def spot() -> tuple[float, float]:
        return rng.uniform(1.2, size - 0.3), rng.uniform(1.2, size - 0.3)

    lx, ly = spot()
    bx, by = spot()
    cx, cy = spot()
    while (cx - lx) ** 2 + (cy - ly) ** 2 < 0.15**2:  # a lamp inside the circle is refused (its light is hidden)
        cx, cy = spot()
    return (
        f'name = "random"\n[arena]\nwalls = [[0, 0], [{size}, 0], [{size}, {size}], [0, {size}]]\n'
        f"[start]\nat = [0.5, 0.5]\nheading = {rng.uniform(-180, 180)}\n"
        f"[[lamp]]\nat = [{lx}, {ly}]\nintensity = {rng.uniform(1, 5)}\n"
        f"[[box]]\nat = [{bx}, {by}]\nsize = [0.3, 0.2]\nangle = {rng.uniform(0, 90)}\n"
        f"[[circle]]\nat = [{cx}, {cy}]\nradius = 0.1\n"
        f"[noise]\nlight = {rng.choice([0.0, 0.05, 0.2])}\nmotor = {rng.choice([0.0, 0.01, 0.05])}\n"
    )


def busy_world(rng: random.Random) -> str:
    """A small room where a robot that moves at all soon bumps into walls and a pot and passes a bright lamp, so
    that a random table's inputs really change: a world file's text."""
    size = rng.uniform(0.9, 1.3)
    return (
        f'name = "busy"\n[arena]\nwalls = [[0, 0], [{size}, 0], [{size}, {size}], [0, {size}]]\n'
        f"[start]\nat = [{size / 2}, {size / 2}]\nheading = {rng.uniform(-180, 180)}\n"
        f"[[lamp]]\nat = [{rng.uniform(0.2, size - 0.2)}, {size - 0.15}]\nintensity = {rng.uniform(3, 8)}\n"
        f"[[circle]]\nat = [{size - 0.2}, 0.2]\nradius = 0.08\n"
        f"[noise]\nlight = {rng.choice([0.0, 0.05])}\nmotor = {rng.choice([0.0, 0.02])}\n"
    )


def wired_for(table: Table, section: str) -> Machine:
    """A table's robot wired onto a fischertechnik controller's terminals (the robot-file section ``section``:
    txt, robotx, roboif): inputs I1.. as push-buttons, motors M1.., lamps on the outputs the motors leave free,
    counters C1.. (a random robot's names are the controller's)."""
    robot = table.robot
    wiring: dict[str, object] = {name: {"terminal": name, "mode": "switch", "pressed": 1} for name in robot.inputs}
    wiring.update({name: name for name in robot.motors})
    wiring.update({name: f"O{2 * len(robot.motors) + i + 1}" for i, name in enumerate(robot.lamps)})
    wiring.update({name: name for name in robot.counter_names})
    robot = dataclasses.replace(robot, sections={**robot.sections, section: wiring})
    return compile_table(dataclasses.replace(table, robot=robot))


def fits_controller(machine: Machine, counters: int = 4) -> bool:
    """A random robot :func:`wired_for` can wire on a controller with I1..I8, M1..M4 (two outputs each) among
    O1..O8 and ``counters`` counters: counter Cn counts motor Mn (an encoder motor's counter is its own input)."""
    robot = machine.table.robot
    names_ok = all(n[:1] == "I" and n[1:].isdigit() and 1 <= int(n[1:]) <= 8 for n in robot.inputs)
    return (
        names_ok
        and len(robot.motors) <= 4
        and 2 * len(robot.motors) + len(robot.lamps) <= 8
        and robot.tick_ms >= 10
        and all(name == f"M{i + 1}" for i, name in enumerate(robot.motors))
        and len(robot.counters) <= counters
        and all((c.name, c.motor) == (f"C{i + 1}", f"M{i + 1}") for i, c in enumerate(robot.counters))
    )


@dataclass
class Report:
    """What one case gave: per executor, None (agrees), a difference, or why it was not run."""

    agreed: list[str] = field(default_factory=list)
    skipped: dict[str, str] = field(default_factory=dict)
    differ: dict[str, str] = field(default_factory=dict)

    def note(self, name: str, difference: str | None) -> None:
        """What executor ``name`` gave: it agreed (None) or its first difference."""
        if difference is None:
            self.agreed.append(name)
        else:
            self.differ[name] = difference


def executor_folder(workdir: Path, name: str) -> Path:
    """The folder executor ``name`` runs a case in, made."""
    folder = workdir / name.replace(" ", "-")
    folder.mkdir(parents=True, exist_ok=True)
    return folder


def check(case: Case, workdir: Path, names: Sequence[str] | None = None) -> Report:
    """Run every registered executor (or ``names``) on ``case`` and compare each with ``Engine.step``."""
    report = Report()
    for name in names or list(EXECUTORS):
        executor = EXECUTORS[name]
        why = (
            executor.missing()
            or (None if executor.fits(case.machine) else "does not take this table")
            or (None if case.rule in executor.rules else f"knows only the rule {executor.rules}")
        )
        if why:
            report.skipped[name] = why
            continue
        report.note(name, differences(case.machine, executor.run(case, executor_folder(workdir, name))))
    return report
