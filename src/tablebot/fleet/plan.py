"""Planning a sweep: its options checked into a plan of runs, cut into jobs for a backend, and each finished
chunk's result rows (one per run). Where they are kept -- the part files, ``results.csv`` -- is
:mod:`tablebot.fleet.store`; how they are grouped for the report, :mod:`tablebot.fleet.groups`.
"""

from __future__ import annotations

import itertools
from collections.abc import Callable, Collection, Sequence
from dataclasses import InitVar, dataclass
from pathlib import Path
from typing import Any

from tablebot.diagnostics import TableBotError, fail
from tablebot.files import write_text
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
)
from tablebot.fleet.starts import with_start
from tablebot.fleet.store import Store, cell, csv_text, decimals, read_results, times
from tablebot.fleet.tables import main_table_only, tables_digest
from tablebot.fleet.work import Job
from tablebot.formats.table_read import load_table, resolve_table_path
from tablebot.i18n import N_
from tablebot.jit import sources_digest
from tablebot.machine import FLAT_BITS, Machine, compile_table
from tablebot.robot import load_robot
from tablebot.sim.model.scene import Scene, find_world, prepare, robot_layer
from tablebot.sim.model.world import World, load_world
from tablebot.sim.runner import ticks_for
from tablebot.table import Table
from tablebot.tables import RobotTables, several

__all__ = ["RESULT_COLUMNS", "Plan", "Read", "Store", "csv_text", "make_plan", "read_results"]  # Store, csv_text,
# read_results: where tune and evolve have always found them

#: A robot's table and, for a robot of several, all its tables (tablebot.tables.several), as a caller read them.
Read = tuple[Table, RobotTables | None]
RESULT_COLUMNS = (
    "seconds",
    "first_light_s",
    "reached",
    "reached_s",
    "collisions",
    "distance_m",
    "battery_start_v",
    "battery_end_v",
    "final_state",
)


@dataclass
class Plan:
    """A checked sweep: the spec, the table, its worlds and robot parameters, ready to cut into jobs."""

    spec: SweepSpec
    table: Table
    machine: Machine
    worlds: list[World]
    robot_params: dict[str, Any]
    tables: RobotTables | None = None  # a robot of several tables run whole (``table`` is its main one)
    first: InitVar[Scene | None] = None  # the first world's scene, prepared already (make_plan's)

    def __post_init__(self, first: Scene | None) -> None:
        self.cell_axes = [k for k, axis in enumerate(self.spec.axes) if is_cell(axis.key)]
        self.variants: Variants | None  # the grid's table cells' program variants (fleet.cells.grid_variants)
        self.variants, self.variant_of = grid_variants(
            [self.spec.axes[k] for k in self.cell_axes], self.table, self.tables, self.machine
        )
        self.scenes: list[Scene] = [
            first
            if k == 0 and first is not None
            else prepare(self.table, self.machine, w, self.robot_params, tables=self.tables)
            for k, w in enumerate(self.worlds)
        ]
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
                start = (
                    random_start(run.seed, self.worlds[run.world].walls, self._free(run.world))
                    if value == "random"
                    else tuple(value)
                )
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
            out.append(
                Job(
                    self.table,
                    self.worlds[a // self.spec.runs_per_world],
                    self.robot_params,
                    robots,
                    self.spec.ticks,
                    first=a,
                    info={"stop": b, "starts": [robot.start for robot in robots]},
                    tables=self.tables,
                    variants=self.variants,
                )
            )
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
            seeds = spec.seeds[k : k + stop - index]
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
            overrides = RobotSpec(
                0, params=tuple((*param_of(a.key), v) for a, v in zip(axes, values, strict=True))
            ).overrides()
            for world, found in zip(self.worlds, bodies, strict=True):
                try:
                    scene = prepare(self.table, self.machine, world, self.robot_params, overrides, self.tables)
                except TableBotError as exc:
                    setting = " ".join(f"{a.key}={v}" for a, v in zip(axes, values, strict=True))
                    raise fail(
                        "--grid",
                        N_("--grid {setting}: {problem}", setting=setting, problem=exc.diagnostics[0].message),
                        N_("choose --grid values the simulated robot can take"),
                    ) from None
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
                        raise fail(
                            "--grid",
                            N_("--grid start: {problem}", problem=exc.diagnostics[0].message),
                            N_("choose a start pose inside the walls, clear of walls and obstacles"),
                        ) from None

    def traced(self, index: int) -> Fleet:
        """Run ``index`` of the sweep again as the traced robot of a fleet of one (the same run it made)."""
        run = runs(self.spec, index, index + 1)[0]
        fleet = Fleet(
            self.table,
            self.machine,
            self.worlds[run.world],
            [self.robot(run)],
            self.robot_params,
            traced=[0],
            tables=self.tables,
            variants=self.variants,
        )
        fleet.run(self.spec.ticks)
        return fleet

    def write_traces(self, indices: Sequence[int], folder: Path) -> list[Path]:
        """``trace-RUN.jsonl`` of each run: the trace ``tablebot sim`` writes for that robot."""
        return [
            write_text(folder / f"trace-{index}.jsonl", "".join(self.traced(index).trace_lines(0))) for index in indices
        ]

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
            "run": list(map(str, range(a, b))),
            "world": [cell(spec.worlds[world])] * (b - a),
            "seed": [str(spec.seeds[k % count]) for k in per_seed],
            **{column: [str(start[j]) for start in starts] for j, column in enumerate(START_COLUMNS)},
            **{
                axis.key: [cell(combos[k // count][j]) for k in per_seed]
                for j, axis in enumerate(spec.axes)
                if axis.key != "start"
            },
        }
        state_cells = [cell(state) for state in states]
        cells.update(
            seconds=[cell(round(summary.ticks * tick_s, 6))] * (b - a),
            first_light_s=times(summary.first_light, tick_s),
            reached=["0" if tick < 0 else "1" for tick in summary.reached.tolist()],
            reached_s=times(summary.reached, tick_s),
            collisions=list(map(str, summary.collisions.tolist())),
            distance_m=decimals(summary.distance_m),
            battery_start_v=decimals(summary.battery_start_v),
            battery_end_v=decimals(summary.battery_end_v),
            final_state=[state_cells[k] for k in summary.final_state.tolist()],
        )
        cells.update((f"time_{state}_s", decimals(summary.counts[:, k] * tick_s)) for k, state in enumerate(states))
        columns = self.columns()
        lines = map(",".join, zip(*(cells[column] for column in columns), strict=True))
        return csv_text(columns, []) + "".join(line + "\n" for line in lines)


def make_plan(
    table: Path,
    robot: Path | None,
    worlds: Sequence[Path],
    grid: Sequence[str],
    seeds: str | None,
    robots: int | None,
    seconds: float,
    every_table: bool = False,
    grid_cells: bool = False,
    read: Read | None = None,
) -> Plan:
    """The table, its worlds and the checked options (``--grid``, ``--seeds`` or ``--robots``, ``--seconds``)
    as a plan of runs; every mistake is a located error before anything is written. ``every_table``: a robot of
    several tables runs all of them (``sweep``, ``tune``, ``grade``, ``evolve``), else its main table alone.
    ``grid_cells``: ``--grid`` may set table cells (``sweep``: ``--grid "lights: line 4 timer=20,50"``).
    ``read``: the robot's tables as the caller read them from ``table`` and ``robot`` (with ``every_table``),
    not read again."""
    axes = parse_grid(list(grid))
    if not grid_cells:  # sweep's alone: tune has --cells
        refuse_cells(axes)
    seed_list = parse_seeds(seeds, robots)
    parsed, tables = read if read is not None and every_table else _read(table, robot, every_table)
    machine = tables.machines[0] if tables is not None else compile_table(parsed)
    if machine.arrays is None:
        raise fail(
            parsed.path,
            N_(
                "the table has {n} event columns; the compiled fleet takes at most {most}",
                n=len(parsed.events),
                most=FLAT_BITS,
            ),
            N_("simulate it one robot at a time with tablebot sim, or use fewer inputs"),
        )
    layer, robot_world = robot_layer(parsed.robot)
    loaded = [load_world(w) for w in worlds] or [find_world(parsed, None, robot_world)]
    paths = [str(w) for w in worlds] or [loaded[0].path]
    first = prepare(parsed, machine, loaded[0], layer, tables=tables)
    ticks = ticks_for(first, seconds)
    files = [Path(p) if Path(p).is_file() else None for p in paths]
    robot_file = Path(parsed.robot.source)
    spec = SweepSpec(
        table=str(Path(parsed.path).name),
        table_digest=tables_digest(parsed, tables),
        worlds=tuple(paths),
        world_digests=tuple(digest(f) for f in files),
        axes=axes,
        seeds=seed_list,
        ticks=ticks,
        robot_digest=digest(robot_file if robot_file.is_file() else None),
        code=sources_digest(),
    )
    return Plan(spec, parsed, machine, loaded, layer, tables, first)


def _read(table: Path, robot: Path | None, every_table: bool) -> Read:
    """The table (the robot file first, as every command reads them) and, with ``every_table``, all the robot's
    tables; without, a robot of several tables is told that its main table runs alone."""
    parsed = load_table(resolve_table_path(table), load_robot(robot) if robot else None)
    tables = several(parsed) if every_table else None
    if tables is None:
        main_table_only(parsed.robot)
    return (tables.table if tables is not None else parsed), tables


def _body(scene: Scene) -> tuple:
    """What decides whether a start pose is free for the robot: its body's measures."""
    return tuple(sorted(scene.params["body"].items()))
