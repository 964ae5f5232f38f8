"""Running a sweep: its runs cut into jobs for a backend, each finished chunk written at once as a part
file, the parts merged into ``results.csv`` (one row per run, in run order).

An interrupted sweep keeps its parts (and writes ``results.partial.csv``); the same command run again
finds ``spec.json`` unchanged and runs only the chunks that have no part yet.
"""

from __future__ import annotations

import csv
import functools
import io
import itertools
import operator
import re
from collections.abc import Callable, Collection, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from tablebot.diagnostics import Diagnostic, TableBotError, fail, notify
from tablebot.files import atomic_write, remove, write_text
from tablebot.fleet.cells import grid_variants
from tablebot.fleet.results import FleetSummary
from tablebot.fleet.robots import RobotSpec, Variants
from tablebot.fleet.run import Fleet
from tablebot.fleet.spec import (
    START_COLUMNS,
    Run,
    SweepSpec,
    chunks,
    digest,
    is_cell,
    param_of,
    parse_grid,
    parse_seeds,
    random_start,
    refuse_cells,
    runs,
    value_index,
)
from tablebot.fleet.starts import with_start
from tablebot.fleet.tables import main_table_only, tables_digest
from tablebot.fleet.work import Job
from tablebot.formats.table_read import load_table, resolve_table_path
from tablebot.formats.trace_lines import exact_round
from tablebot.jit import sources_digest
from tablebot.machine import FLAT_BITS, Machine, compile_table
from tablebot.robot import load_robot
from tablebot.sim.model.scene import Scene, find_world, prepare, robot_layer
from tablebot.sim.model.world import World, load_world
from tablebot.sim.runner import ticks_for
from tablebot.table import Table
from tablebot.tables import RobotTables, several

PART_RE = re.compile(r"^runs-(\d{7})-(\d{7})\.csv$")
RESULT_COLUMNS = ("seconds", "first_light_s", "reached", "reached_s", "collisions", "distance_m",
                  "battery_start_v", "battery_end_v", "final_state")


@dataclass
class Plan:
    """A checked sweep: the spec, the table, its worlds and robot parameters, ready to cut into jobs."""

    spec: SweepSpec
    table: Table
    machine: Machine
    worlds: list[World]
    robot_params: dict[str, Any]
    tables: RobotTables | None = None  # a robot of several tables run whole (``table`` is its main one)

    def __post_init__(self) -> None:
        self.cell_axes = [k for k, axis in enumerate(self.spec.axes) if is_cell(axis.key)]
        self.variants: Variants | None  # the grid's table cells' program variants (fleet.cells.grid_variants)
        self.variants, self.variant_of = grid_variants([self.spec.axes[k] for k in self.cell_axes], self.table,
                                                       self.tables, self.machine)
        self.scenes: list[Scene] = [prepare(self.table, self.machine, w, self.robot_params, tables=self.tables)
                                    for w in self.worlds]
        self.bodies: list[list[Scene]] = self._check_params()
        self._check_starts()

    def columns(self) -> list[str]:
        axes = [c for axis in self.spec.axes for c in axis.columns]
        start = [] if any(axis.key == "start" for axis in self.spec.axes) else list(START_COLUMNS)
        states = [f"time_{state}_s" for state in self.machine.states]
        return ["run", "world", "seed", *axes, *start, *RESULT_COLUMNS, *states]

    def robot(self, run: Run) -> RobotSpec:
        """The fleet robot of one run (a random start drawn for its seed, checked free; the program variant of
        its values of the grid's table cells)."""
        params, start = [], None
        for k, (axis, value) in enumerate(zip(self.spec.axes, run.values, strict=True)):
            if axis.key == "start":
                start = random_start(run.seed, self.worlds[run.world].walls, self._free(run.world)) \
                    if value == "random" else tuple(value)
            elif k not in self.cell_axes:
                params.append((*param_of(axis.key), value))
        variant = self.variant_of.get(tuple(run.values[k] for k in self.cell_axes), 0)
        return RobotSpec(seed=run.seed, start=start, params=tuple(params), variant=variant)

    def _free(self, world: int) -> Callable[[tuple[float, float, float]], bool]:
        """Whether a pose is a free start in the world for every robot body of the grid (a random start
        serves every grid value of its seed)."""
        def free(pose: tuple[float, float, float]) -> bool:
            try:
                for scene in self.bodies[world]:
                    with_start(scene, pose)
            except TableBotError:
                return False
            return True
        return free

    def jobs(self, skip: Collection[tuple[int, int]] = ()) -> list[Job]:
        """A job per chunk of the spec that is not in ``skip`` (chunks already finished); its info keeps
        each robot's start (None: the world's) for the result rows."""
        out = []
        combos = list(itertools.product(*(axis.values for axis in self.spec.axes)))
        for a, b in chunks(self.spec):
            if (a, b) in skip:
                continue
            robots = self._robots(a, b, combos)
            out.append(Job(self.table, self.worlds[a // self.spec.runs_per_world], self.robot_params, robots,
                           self.spec.ticks, first=a, info={"stop": b, "starts": [robot.start for robot in robots]},
                           tables=self.tables, variants=self.variants))
        return out

    def _robots(self, a: int, b: int, combos: Sequence[tuple[Any, ...]]) -> list[RobotSpec]:
        """:meth:`robot` of runs ``a`` .. ``b - 1`` (as :func:`runs` orders them): the parameters and fixed
        start of a grid combination worked out once for all its seeds, a random start drawn per seed."""
        spec, out = self.spec, []
        count = len(spec.seeds)
        index = a
        while index < b:
            world, rest = divmod(index, spec.runs_per_world)
            combo, k = divmod(rest, count)
            stop, values = min(b, index + count - k), combos[combo]
            seeds = spec.seeds[k: k + stop - index]
            if "random" in values:
                out += [self.robot(Run(index + j, world, values, seed)) for j, seed in enumerate(seeds)]
            else:
                first = self.robot(Run(index, world, values, seeds[0]))
                out += [RobotSpec(seed, first.start, first.params, first.variant) for seed in seeds]
            index = stop
        return out

    def _check_params(self) -> list[list[Scene]]:
        """Every combination of ``--grid`` parameters makes a scene in every world (the simulator's limits,
        the tick, the robot's body at the world's start), checked here before anything is written or run:
        a worker would blame the robot file for a value the grid set. Returns per world a scene for each
        robot body the grid gives (the starts must fit them all)."""
        axes = [axis for k, axis in enumerate(self.spec.axes) if axis.key != "start" and k not in self.cell_axes]
        bodies = [{_body(scene): scene} for scene in self.scenes]
        for values in itertools.product(*(axis.values for axis in axes)) if axes else ():
            overrides = RobotSpec(0, params=tuple((*param_of(a.key), v) for a, v in zip(axes, values,
                                                                                          strict=True))).overrides()
            for world, found in zip(self.worlds, bodies, strict=True):
                try:
                    scene = prepare(self.table, self.machine, world, self.robot_params, overrides, self.tables)
                except TableBotError as exc:
                    setting = " ".join(f"{a.key}={v}" for a, v in zip(axes, values, strict=True))
                    raise fail("--grid", f"--grid {setting}: {exc.diagnostics[0].message}",
                               "choose --grid values the simulated robot can take") from None
                found.setdefault(_body(scene), scene)
        return [list(found.values()) for found in bodies]

    def _check_starts(self) -> None:
        """Every ``--grid start`` pose is free in every world for every robot body: checked once, before
        anything is written or run, not per seed (random starts are drawn free)."""
        poses = [tuple(v) for axis in self.spec.axes if axis.key == "start" for v in axis.values if v != "random"]
        for scenes in self.bodies:
            for scene in scenes:
                for pose in poses:
                    try:
                        with_start(scene, pose)
                    except TableBotError as exc:  # the world's words, about the option
                        raise fail("--grid", f"--grid start: {exc.diagnostics[0].message}",
                                   "choose a start pose inside the walls, clear of walls and obstacles") from None

    def traced(self, index: int) -> Fleet:
        """Run ``index`` of the sweep again as the traced robot of a fleet of one (the same run it made)."""
        run = runs(self.spec, index, index + 1)[0]
        fleet = Fleet(self.table, self.machine, self.worlds[run.world], [self.robot(run)], self.robot_params,
                      traced=[0], tables=self.tables, variants=self.variants)
        fleet.run(self.spec.ticks)
        return fleet

    def write_traces(self, indices: Sequence[int], folder: Path) -> list[Path]:
        """``trace-RUN.jsonl`` of each run: the trace ``tablebot sim`` writes for that robot."""
        return [write_text(folder / f"trace-{index}.jsonl", "".join(self.traced(index).trace_lines(0)))
                for index in indices]

    def part_text(self, job: Job, summary: FleetSummary) -> str:
        """A finished chunk's result rows as CSV text (header first), one row per robot, its start as
        :meth:`jobs` kept it: the numbers of :meth:`FleetSummary.summary`, rounded to 6 decimals as
        Python's ``round`` does, each cell as ``csv.writer`` writes it -- built column by column for the
        whole chunk (row by row, as dicts through ``csv.writer``, it held the GIL the fleet's other thread
        needed for a third of a second per 10,000 robots)."""
        spec, a, b = self.spec, job.first, job.info["stop"]
        per_world = spec.runs_per_world
        world = a // per_world  # a chunk never spans two worlds
        per_seed = range(a - world * per_world, b - world * per_world)  # the runs' places in their world
        combos = list(itertools.product(*(axis.values for axis in spec.axes)))
        count = len(spec.seeds)
        tick_s, states = summary.tick_s, self.machine.states
        starts = [start or self.worlds[world].start for start in job.info["starts"]]
        cells: dict[str, list[str]] = {
            "run": list(map(str, range(a, b))), "world": [cell(spec.worlds[world])] * (b - a),
            "seed": [str(spec.seeds[k % count]) for k in per_seed],
            **{column: [str(start[j]) for start in starts] for j, column in enumerate(START_COLUMNS)},
            **{axis.key: [cell(combos[k // count][j]) for k in per_seed]
               for j, axis in enumerate(spec.axes) if axis.key != "start"}}
        state_cells = [cell(state) for state in states]
        cells.update(seconds=[cell(round(summary.ticks * tick_s, 6))] * (b - a),
                     first_light_s=_times(summary.first_light, tick_s),
                     reached=["0" if tick < 0 else "1" for tick in summary.reached.tolist()],
                     reached_s=_times(summary.reached, tick_s), collisions=list(map(str, summary.collisions.tolist())),
                     distance_m=_decimals(summary.distance_m), battery_start_v=_decimals(summary.battery_start_v),
                     battery_end_v=_decimals(summary.battery_end_v),
                     final_state=[state_cells[k] for k in summary.final_state.tolist()])
        cells.update((f"time_{state}_s", _decimals(summary.counts[:, k] * tick_s)) for k, state in enumerate(states))
        columns = self.columns()
        lines = map(",".join, zip(*(cells[column] for column in columns), strict=True))
        return csv_text(columns, []) + "".join(line + "\n" for line in lines)


def _times(ticks: np.ndarray, tick_s: float) -> list[str]:
    """Ticks as seconds, 6 decimals; blank for never (-1)."""
    rounded = exact_round(ticks * tick_s, 6)
    return ["" if tick < 0 else repr(value) for tick, value in zip(ticks.tolist(), rounded, strict=True)]


def _decimals(values: np.ndarray) -> list[str]:
    """Numbers rounded to 6 decimals as Python's ``round`` does, written as Python writes floats."""
    return list(map(repr, exact_round(values, 6)))


@functools.lru_cache(maxsize=4096)
def _text_cell(text: str) -> str:
    buffer = io.StringIO()
    csv.writer(buffer, lineterminator="\n").writerow([text, ""])
    return buffer.getvalue()[: -len(",\n")]


def cell(value: Any) -> str:
    """One value as ``csv.writer`` writes it in a row of several: blank for None, text quoted where it
    must be, anything else as ``str``."""
    if value is None:
        return ""
    return _text_cell(value) if isinstance(value, str) else str(value)


def make_plan(table: Path, robot: Path | None, worlds: Sequence[Path], grid: Sequence[str], seeds: str | None,
              robots: int | None, seconds: float, every_table: bool = False, grid_cells: bool = False) -> Plan:
    """The table, its worlds and the checked options (``--grid``, ``--seeds`` or ``--robots``, ``--seconds``)
    as a plan of runs; every mistake is a located error before anything is written. ``every_table``: a robot of
    several tables runs all of them (``sweep``, ``tune``, ``grade``, ``evolve``), else its main table alone.
    ``grid_cells``: ``--grid`` may set table cells (``sweep``: ``--grid "lights: line 4 timer=20,50"``)."""
    axes = parse_grid(list(grid))
    if not grid_cells:  # sweep's alone: tune has --cells
        refuse_cells(axes)
    seed_list = parse_seeds(seeds, robots)
    robot_file_given = load_robot(robot) if robot else None  # read first, as every command reads them
    parsed = load_table(resolve_table_path(table), robot_file_given)
    tables = several(parsed) if every_table else None
    if tables is None:
        main_table_only(parsed.robot)
    parsed = tables.table if tables is not None else parsed
    machine = tables.machines[0] if tables is not None else compile_table(parsed)
    if machine.arrays is None:
        raise fail(parsed.path, f"the table has {len(parsed.events)} event columns; the compiled fleet takes at most "
                   f"{FLAT_BITS}", "simulate it one robot at a time with tablebot sim, or use fewer inputs")
    layer, robot_world = robot_layer(parsed.robot)
    loaded = [load_world(w) for w in worlds] or [find_world(parsed, None, robot_world)]
    paths = [str(w) for w in worlds] or [loaded[0].path]
    ticks = ticks_for(prepare(parsed, machine, loaded[0], layer, tables=tables), seconds)
    files = [Path(p) if Path(p).is_file() else None for p in paths]
    robot_file = Path(parsed.robot.source)
    spec = SweepSpec(table=str(Path(parsed.path).name), table_digest=tables_digest(parsed, tables),
                     worlds=tuple(paths), world_digests=tuple(digest(f) for f in files), axes=axes,
                     seeds=seed_list, ticks=ticks, robot_digest=digest(robot_file if robot_file.is_file() else None),
                     code=sources_digest())
    return Plan(spec, parsed, machine, loaded, layer, tables)


def _body(scene: Scene) -> tuple:
    """What decides whether a start pose is free for the robot: its body's measures."""
    return tuple(sorted(scene.params["body"].items()))


# --- the output folder ------------------------------------------------------------------------------


class Store:
    """``DIR/spec.json``, ``DIR/parts/runs-A-B.csv`` per finished chunk, ``DIR/results.csv`` at the end."""

    def __init__(self, folder: Path, plan: Plan) -> None:
        self.folder, self.plan = folder, plan
        self.parts = folder / "parts"

    def open(self) -> set[tuple[int, int]]:
        """Check the folder holds this spec's sweep (or none) and return the chunks already finished."""
        spec_file = self.folder / "spec.json"
        text = self.plan.spec.to_json()
        if spec_file.exists() and spec_file.read_text(encoding="utf-8") != text:
            raise fail(self.folder, "--out holds the results of a different sweep (another table, robot file, "
                       "world, grid, seeds, length or simulator version)",
                       "give --out a new folder, or delete this one to start over")
        self.parts.mkdir(parents=True, exist_ok=True)
        if not spec_file.exists():
            write_text(spec_file, text)
        wanted = set(chunks(self.plan.spec))
        found = {(int(m[1]), int(m[2])) for p in self.parts.iterdir() if (m := PART_RE.match(p.name))}
        return {chunk for chunk in found & wanted if self._whole(*chunk)}

    def _whole(self, a: int, b: int) -> bool:
        """Whether the part of runs a..b-1 holds what this sweep writes there: its header, then one whole row
        per run, in order. A part is written whole or not at all, so only a damaged or edited one fails:
        it is said, and its runs are made again (the same rows: a part is deterministic) over it."""
        part = self.parts / f"runs-{a:07d}-{b:07d}.csv"
        columns = list(self.plan.columns())
        with open(part, encoding="utf-8", errors="replace", newline="") as f:
            text = f.read()
        rows = list(csv.reader(io.StringIO(text)))  # cells may hold quoted commas (a world's path)
        if text.endswith("\n") and rows[:1] == [columns] and [row[0] for row in rows[1:] if row] == \
                [str(run) for run in range(a, b)] and all(len(row) == len(columns) for row in rows[1:]):
            return True
        notify(Diagnostic(str(part), None, None, "this part of the sweep is damaged (not the rows this sweep "
                          f"writes for runs {a}..{b - 1}): its runs are made again", severity="note"))
        return False

    def write_part(self, job: Job, text: str) -> Path:
        """A finished chunk's rows (:meth:`Plan.part_text`) as its part file."""
        return write_text(self.parts / f"runs-{job.first:07d}-{job.info['stop']:07d}.csv", text)

    def merge(self, complete: bool) -> tuple[Path, int]:
        """All finished parts in run order as ``results.csv`` (or ``results.partial.csv`` when not complete),
        streamed part by part (a sweep of millions of runs is never held in memory whole)."""
        count = 0
        path = self.folder / ("results.csv" if complete else "results.partial.csv")
        with atomic_write(path) as out:
            out.write(csv_text(self.plan.columns(), []))
            for a, b in chunks(self.plan.spec):
                part = self.parts / f"runs-{a:07d}-{b:07d}.csv"
                if part.exists():
                    with open(part, encoding="utf-8") as f:
                        next(f)  # its header
                        for line in f:
                            out.write(line)
                            count += 1
        if complete:
            remove(self.folder / "results.partial.csv")  # with the new results, when they are in a set
        return path, count


def csv_text(columns: Sequence[str], rows: Sequence[dict[str, Any]]) -> str:
    """Rows as CSV text: floats as Python writes them (exact), blank for "never" (None) and for a column a
    row lacks; what csv.DictWriter writes, without its check of every row's keys."""
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow(columns)
    writer.writerows([row.get(column) for column in columns] for row in rows)
    return buffer.getvalue()


REPORT_COLUMNS = ("run", "reached", "collisions", "distance_m")  # what the summary of a sweep reads


def read_results(path: Path, columns: Sequence[str] | None = None) -> list[dict[str, str]]:
    """The rows of a results file, each with every column, or only ``columns`` (a third of the time)."""
    with open(path, encoding="utf-8", newline="") as f:
        if columns is None:
            return list(csv.DictReader(f))
        reader = csv.reader(f)
        header = next(reader)
        places = [header.index(column) for column in columns]
        cells = operator.itemgetter(*places, *places[:1])  # two at least: a tuple, the last one dropped by zip
        return [dict(zip(columns, cells(row), strict=False)) for row in reader]


# How a sweep's results are grouped, for its report and its pictures (here, not in the picture module, so that
# a sweep without pictures never loads matplotlib).
def groups(plan: Plan, rows: Sequence[dict[str, Any]]) -> list[tuple[str, list[tuple[str, list[dict[str, Any]]]]]]:
    """Per grid axis (or "all runs" without one): its values, each with the rows that had it."""
    out = []
    if len(plan.spec.worlds) > 1:
        by_world: list[list[dict[str, Any]]] = [[] for _ in plan.worlds]
        for r in rows:
            by_world[int(r["run"]) // plan.spec.runs_per_world].append(r)
        out.append(("world", list(zip(world_labels(plan), by_world, strict=True))))
    for k, axis in enumerate(plan.spec.axes):
        if len(axis.values) < 2:
            continue
        # by the run's value (a random start has no other mark)
        chosen: list[list[dict[str, Any]]] = [[] for _ in axis.values]
        for r in rows:
            chosen[value_index(plan.spec, int(r["run"]), k)].append(r)
        labels = [":".join(f"{v:g}" for v in value) if isinstance(value, tuple) else str(value)
                  for value in axis.values]
        out.append((axis.key, list(zip(labels, chosen, strict=True))))
    return out or [("all runs", [("all", list(rows))])]


def world_labels(plan: Plan) -> list[str]:
    """Each world's name, numbered where two share one (two files both called arena.toml, say)."""
    names = [world.name for world in plan.worlds]
    return [f"{name} ({k + 1})" if names.count(name) > 1 else name for k, name in enumerate(names)]
