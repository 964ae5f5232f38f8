"""What a sweep runs: the options of ``tablebot sweep`` checked into a spec, the spec expanded into runs
(worlds × grid values × seeds), runs grouped into chunks (the unit of work), and one result row per run.

The spec is plain data (saved as ``spec.json`` beside the results) so that re-running the same command
finds what already ran and resumes.
"""

from __future__ import annotations

import hashlib
import itertools
import json
import math
import re
from collections.abc import Sequence
from dataclasses import asdict, dataclass, fields
from pathlib import Path
from typing import Any

import numpy as np

from tablebot.diagnostics import fail
from tablebot.durations import MAX_NUMBER_CHARS
from tablebot.fleet.cells import CELL_RE
from tablebot.fleet.robots import Pose
from tablebot.i18n import N_, as_typed
from tablebot.sim.model.params import DEFAULTS
from tablebot.sim.model.world import inside

START_STREAM = 0x5747  # random starts come from Generator([seed, START_STREAM]): apart from the robot's noise
MAX_RUNS = 10_000_000
START_COLUMNS = ("start_x", "start_y", "start_heading")  # a run's start pose in its result row
SEEDS_MARK = "\0seeds\0"  # spec.json's seeds while the rest is written (no key or path holds a NUL)
RANGE_RE = re.compile(r"^\s*(-?\d+)\s*\.\.\s*(-?\d+)\s*$")


@dataclass(frozen=True)
class Axis:
    """One ``--grid`` key and its values: ``battery``, ``start`` (poses or "random") or ``section.key``."""

    key: str
    values: tuple[Any, ...]

    @property
    def columns(self) -> tuple[str, ...]:
        return START_COLUMNS if self.key == "start" else (self.key,)


@dataclass(frozen=True)
class SweepSpec:
    table: str  # the table file's text digest and name: a changed table is another sweep
    table_digest: str
    worlds: tuple[str, ...]  # world files ("" = the table's default world)
    world_digests: tuple[str, ...]
    axes: tuple[Axis, ...]
    seeds: tuple[int, ...]
    ticks: int
    robot_digest: str = ""  # the robot file (its [sim] parameters shape every run)
    code: str = ""  # the simulator's sources (tablebot.jit.sources_digest): other code, other runs

    def to_json(self) -> str:
        """``spec.json``'s text: :func:`dataclasses.asdict`'s, without its deep copy of every seed (a tenth of
        a 10,000-robot sweep's planning), and its seeds written as ``json.dumps(indent=1)`` writes a list of
        whole numbers, one a line, in one join: json's indenting encoder is pure Python, a call per seed."""
        data: dict[str, Any] = {f.name: getattr(self, f.name) for f in fields(self)}
        data["axes"] = [asdict(axis) for axis in self.axes]
        data["seeds"] = SEEDS_MARK
        seeds = "[\n  " + ",\n  ".join(map(str, self.seeds)) + "\n ]" if self.seeds else "[]"
        return json.dumps(data, indent=1, sort_keys=True).replace(json.dumps(SEEDS_MARK), seeds, 1) + "\n"

    @property
    def runs_per_world(self) -> int:
        return math.prod(len(axis.values) for axis in self.axes) * len(self.seeds)

    @property
    def total(self) -> int:
        return len(self.worlds) * self.runs_per_world


@dataclass(frozen=True)
class Run:
    """One robot of the sweep: its row number, world, grid values (``None`` start: the world's) and seed."""

    index: int
    world: int
    values: tuple[Any, ...]  # one per axis
    seed: int


def digest(path: Path | None) -> str:
    return "" if path is None else hashlib.sha256(path.read_bytes()).hexdigest()[:16]


# --- options ----------------------------------------------------------------------------------------


def parse_seeds(text: str | None, robots: int | None, option: str = "--seeds") -> tuple[int, ...]:
    """``--seeds 0..999`` (both ends included), ``1,5,9`` or a mix; ``--robots N`` means seeds 0..N-1.
    Errors name ``option`` (the same numbers are read for --check-seeds and --trace)."""
    if text is not None and robots is not None:
        raise fail(
            "--robots",
            N_("give --robots or {option}, not both", option=option),
            N_("--robots N is short for {option} 0..N-1", option=option),
        )
    if text is None:
        if robots is None:
            raise fail(option, N_("say which runs to make"), N_("give {option} 0..99 or --robots 100", option=option))
        if robots < 1:
            raise fail(
                "--robots",
                N_("--robots {n}: there must be at least one robot", n=robots),
                N_("give --robots 1 or more"),
            )
        return tuple(range(robots))
    seeds: list[int] = []
    for part in (p for p in text.split(",") if p.strip()):
        found = RANGE_RE.match(part)
        if found and len(part) <= 2 * MAX_NUMBER_CHARS + 2:  # int() of longer numbers may fail
            low, high = int(found[1]), int(found[2])
            if high < low:
                raise fail(
                    option,
                    N_("{option} {part} is an empty range", option=option, part=part.strip()),
                    N_("write {low}..{high} (low..high)", low=high, high=low),
                )
            if high - low >= MAX_RUNS - len(seeds):  # before the range is made: 0..99999999999 is 800 GB of it
                raise fail(
                    option,
                    N_("{option} gives more than {most:,} seeds", option=option, most=MAX_RUNS),
                    N_("sweep fewer seeds"),
                )
            seeds.extend(range(low, high + 1))
        elif part.strip().isdigit() and len(part.strip()) <= MAX_NUMBER_CHARS:
            seeds.append(int(part))
        else:
            raise fail(
                option,
                N_("{option}: {part!r} is not a seed or a range", option=option, part=part.strip()),
                N_("write whole numbers and ranges: 0..999 or 1,5,9 or 0..9,20"),
            )
        if len(seeds) > MAX_RUNS:
            raise fail(
                option,
                N_("{option} gives more than {most:,} seeds", option=option, most=MAX_RUNS),
                N_("sweep fewer seeds"),
            )
    if not seeds:
        raise fail(option, N_("{option} names no seed", option=option), N_("give {option} 0..99", option=option))
    if min(seeds) < 0:
        raise fail(option, N_("{option}: a seed is never negative", option=option), N_("give seeds from 0 on"))
    if len(set(seeds)) != len(seeds):
        raise fail(option, N_("{option} names a seed twice", option=option), N_("name each seed once"))
    return tuple(seeds)


def parse_grid(items: Sequence[str]) -> tuple[Axis, ...]:
    """Each ``--grid KEY=V1,V2,...``: battery (0..1), start (random or x:y:heading poses) or a [sim]
    parameter as section.key (``motor.friction_volts=0.2,0.4``)."""
    axes: list[Axis] = []
    for item in items:
        raw, sep, values = item.partition("=")
        key = raw.strip().lower()
        cells = [v.strip() for v in values.split(",") if v.strip()]
        if not sep or not key:
            raise fail(
                "--grid", N_("--grid {item!r} is not KEY=VALUES", item=item), N_('write --grid "battery=1.0,0.8,0.6"')
            )
        if not cells:
            raise fail("--grid", N_("--grid {key}= has no values", key=key), N_('write --grid "{key}=V1,V2"', key=key))
        if key in (a.key for a in axes):
            raise fail("--grid", N_("--grid names {key} twice", key=key), N_("give each key once, with all its values"))
        if is_cell(raw):  # a timer or counter load of a table row: its values are program variants
            key = " ".join(raw.split())
            if key in (a.key for a in axes):
                raise fail(
                    "--grid", N_("--grid names {key} twice", key=key), N_("give each key once, with all its values")
                )
            axes.append(Axis(key, _counts(key, cells)))
            continue
        axes.append(Axis(key, _start_values(cells) if key == "start" else _numbers(key, cells)))
    return tuple(axes)


def is_cell(key: str) -> bool:
    """Whether a grid key names a table cell (``line 5 timer``, ``lights: line 4 timer``, ``line 12 C1_load``)."""
    return CELL_RE.match(key.strip()) is not None and "=" not in key


def _counts(key: str, cells: list[str]) -> tuple[int, ...]:
    """A cell axis's values: whole numbers of ticks (or counts) from 0 to MAX_TIMER."""
    from tablebot.robot import MAX_TIMER

    out = []
    for cell in cells:
        if not cell.isdigit() or int(cell) > MAX_TIMER:
            raise fail(
                "--grid",
                N_("--grid {key}: {cell!r} is not a whole number from 0 to {most}", key=key, cell=cell, most=MAX_TIMER),
                N_('write ticks (or counts), e.g. --grid "{key}=20,50,100"', key=key),
            )
        out.append(int(cell))
    return tuple(out)


def known_keys() -> list[str]:
    return ["battery", "start", *(f"{section}.{key}" for section, keys in DEFAULTS.items() for key in keys)]


def param_of(key: str) -> tuple[str, str]:
    """The [sim] section and key a grid key sets."""
    if key == "battery":
        return "battery", "charge"
    section, _, name = key.partition(".")
    return section, name


def _numbers(key: str, cells: list[str]) -> tuple[float, ...]:
    section, name = param_of(key)
    if section not in DEFAULTS or name not in DEFAULTS[section]:
        raise fail(
            "--grid",
            N_("--grid: unknown key {key!r}", key=key),
            N_(
                "use battery, start, or a simulator parameter such as motor.friction_volts, noise.light (all: {keys})",
                keys=", ".join(known_keys()[2:]),
            ),
        )
    default, low, high, _ = DEFAULTS[section][name]
    shown = {"low": as_typed(low), "high": as_typed(high)}  # as --grid takes them: 0.5, not German 0,5
    out = []
    for cell in cells:
        try:
            value = float(cell)
        except ValueError:
            raise fail(
                "--grid",
                N_("--grid {key}: {cell!r} is not a number", key=key, cell=cell),
                N_("write numbers from {low} to {high}", **shown),
            ) from None
        if not low <= value <= high or (isinstance(default, int) and value != int(value)):
            hint = (
                N_("write a whole number from {low} to {high}", **shown)
                if isinstance(default, int)
                else N_("write a number from {low} to {high}", **shown)
            )
            raise fail("--grid", N_("--grid {key}: {cell} is out of range", key=key, cell=cell), hint)
        out.append(int(value) if isinstance(default, int) else value)
    return tuple(out)


def _start_values(cells: list[str]) -> tuple[Any, ...]:
    out: list[Any] = []
    for cell in cells:
        if cell.lower() == "random":
            out.append("random")
            continue
        parts = cell.split(":")
        try:
            pose = tuple(float(p) for p in parts)
        except ValueError:
            pose = ()
        if len(pose) != 3 or not all(math.isfinite(v) for v in pose):
            raise fail(
                "--grid",
                N_("--grid start: {cell!r} is not a pose", cell=cell),
                N_(
                    "write start=random or start=X:Y:HEADING (metres, metres, degrees), e.g. "
                    '"start=0.35:0.35:20,1.0:0.5:90"'
                ),
            )
        out.append(pose)
    return tuple(out)


# --- runs -------------------------------------------------------------------------------------------


def runs(spec: SweepSpec, first: int = 0, stop: int | None = None) -> list[Run]:
    """Runs ``first`` to ``stop`` of the spec, in order: world, then each grid value, then seed."""
    stop = spec.total if stop is None else stop
    combos = list(itertools.product(*(axis.values for axis in spec.axes)))
    per_world = len(combos) * len(spec.seeds)
    out = []
    for index in range(first, stop):
        world, rest = divmod(index, per_world)
        combo, seed = divmod(rest, len(spec.seeds))
        out.append(Run(index, world, combos[combo], spec.seeds[seed]))
    return out


def value_index(spec: SweepSpec, index: int, axis: int) -> int:
    """Which of ``spec.axes[axis]``'s values run ``index`` has (in the order of :func:`runs`: the last
    axis turns fastest)."""
    combo = index % spec.runs_per_world // len(spec.seeds)
    after = math.prod(len(a.values) for a in spec.axes[axis + 1 :])
    return combo // after % len(spec.axes[axis].values)


def chunks(spec: SweepSpec, size: int | None = None) -> list[tuple[int, int]]:
    """The spec's runs cut into chunks ``[a, b)`` that never span two worlds. The size depends on the
    spec alone (never on the machine), so a resumed sweep finds the same chunks."""
    size = size or chunk_size(spec.total)
    out = []
    for world in range(len(spec.worlds)):
        start, stop = world * spec.runs_per_world, (world + 1) * spec.runs_per_world
        out += [(a, min(a + size, stop)) for a in range(start, stop, size)]
    return out


def chunk_size(total: int) -> int:
    """About 32 chunks (enough to spread over the workers and show progress), 8 to 512 robots each."""
    return max(8, min(512, -(-total // 32)))


def random_start(seed: int, walls: tuple[tuple[float, float], ...], free: Any) -> Pose:
    """A start pose drawn for ``seed`` (the same for every grid value: common random numbers): uniform
    inside the walls with any heading, redrawn until ``free(pose)`` says the body touches nothing."""
    rng = np.random.default_rng([seed, START_STREAM])
    xs, ys = [p[0] for p in walls], [p[1] for p in walls]
    for _ in range(10_000):
        x, y = rng.uniform(min(xs), max(xs)), rng.uniform(min(ys), max(ys))
        pose = (round(float(x), 4), round(float(y), 4), round(float(rng.uniform(-180.0, 180.0)), 2))
        if inside(walls, (x, y)) and free(pose):
            return pose
    raise fail(
        "--grid", N_("start=random: found no free start pose in the world"), N_("give the world more free floor")
    )


def refuse_cells(axes: Sequence[Axis]) -> None:
    """``--grid`` of a command other than sweep may not set a table cell (tune searches them with --cells)."""
    for axis in axes:
        if is_cell(axis.key):
            raise fail(
                "--grid",
                N_("--grid {key}: only sweep runs a table cell's values side by side", key=axis.key),
                N_("tune a cell with --cells; give --grid battery, start or a simulator parameter"),
            )
