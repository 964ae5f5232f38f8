"""Candidates on the fleet: every candidate runs every scenario of the plan (seeds × grid values × worlds,
the same for all: common random numbers), on this machine's cores or a Dask cluster. A batch of
candidates runs as few large fleets as keep every slot of the backend busy: a fleet runs one table, so
the candidates of a job are put side by side in one *joint* table (:func:`joint`), each under states of
its own, and each robot starts in its candidate's start state: a robot only ever reaches its own
candidate's rows, so it drives exactly as in a fleet of that candidate alone. Each job returns per robot
every measure; a candidate's value is the mean over its scenarios, summed in scenario order, so the
numbers are the same bits whichever backend ran which robots in which job in whichever order.

Measures the fleet's summary does not keep (laps, floor covered, time in contact) come from the robots'
poses sampled every ``stride`` ticks as the fleet runs (the fleet's noise is drawn robot by robot, so
cutting the run into short blocks changes no robot's path).
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING, Any

import numpy as np

from tablebot.evolve.measures import MEASURES, STATE_SHARE
from tablebot.fleet.work import Job
from tablebot.table import Row, Table

if TYPE_CHECKING:
    from tablebot.fleet.backends import Runner
    from tablebot.fleet.plan import Plan
    from tablebot.fleet.robots import RobotSpec
    from tablebot.fleet.run import Fleet
    from tablebot.machine import Machine
    from tablebot.sim.model.world import World
    from tablebot.tables import RobotTables

STRIDE = 20  # ticks between pose samples (0.2 s at 10 ms: a robot moves at most 6 cm)
CELL_M = 0.10  # floor squares for area_covered
ROBOTS_PER_JOB = 512  # most robots in one job (a job is one fleet: it returns only when all are done)


@dataclass(frozen=True)
class Part:
    """One candidate's robots in a job, in the job's order: its key and each robot's scenario index."""

    key: str
    scenarios: tuple[int, ...]


@dataclass
class EvalJob(Job):
    """A fleet job in one world of the robots of one or more candidates (``table``: their joint table,
    the robots in the order of ``parts``), measuring everything ``measures`` needs."""

    stride: int = STRIDE
    parts: tuple[Part, ...] = ()


def joint(tables: Sequence[Table]) -> Table:
    """The candidates' rows side by side as one table, candidate k's states renamed ``(k, state)`` (so no
    row of one can ever lead into another's); it starts in candidate 0's start state (:func:`starts`)."""
    robot = tables[0].robot
    rows: list[Row] = []
    for k, table in enumerate(tables):
        rows += [
            replace(row, index=len(rows) + i, state=(k, row.state), next=(k, row.next))
            for i, row in enumerate(table.rows)
        ]
    return Table(replace(robot, initial_state=(0, robot.initial_state)), tables[0].events, tuple(rows), tables[0].path)


def starts(machine: Machine, parts: int) -> np.ndarray:
    """Per candidate of a joint machine, the index of its own start state."""
    joint_start = machine.table.robot.initial_state
    assert isinstance(joint_start, tuple)  # a joint table starts in (0, candidate 0's start state)
    start = joint_start[1]
    return np.array([machine.state_index((k, start)) for k in range(parts)], dtype=np.int64)


def run_eval(job: EvalJob) -> tuple[EvalJob, dict[str, np.ndarray]]:
    """Run the job's robots as one fleet of the joint table, each robot started in its own candidate's
    start state; per robot, every measure (a worker's entry point)."""
    from tablebot.fleet.run import Fleet
    from tablebot.fleet.work import use_threads
    from tablebot.machine import compile_table
    from tablebot.tick import STATE

    use_threads(job)
    owner = np.repeat(np.arange(len(job.parts)), [len(part.scenarios) for part in job.parts])
    if job.tables is not None:  # one candidate, every table of the robot (no joint table: see Evaluator.jobs)
        fleet = Fleet(job.table, job.tables.machines[0], job.world, job.specs, job.robot_params, tables=job.tables)
    else:
        machine = compile_table(job.table)
        fleet = Fleet(job.table, machine, job.world, job.specs, job.robot_params)
        fleet.regs[:, STATE] = starts(machine, len(job.parts))[owner]  # the registers before the first tick
    poses = Poses(fleet, job.world)
    fleet.run(job.ticks, progress=lambda done: poses.sample(), block_ticks=job.stride)
    return replace(job, specs=[]), measure_all(fleet, job.world, poses, owner)


class Poses:
    """What the robots' sampled poses add up to: laps round the loop, floor squares visited, contact."""

    def __init__(self, fleet: Fleet, world: World) -> None:
        from tablebot.sim.model.track import loop_of

        self.fleet, self.n = fleet, len(fleet)
        self.loop = loop_of(world)
        self.samples = 0
        self.touching = np.zeros(self.n)
        self.laps = np.zeros(self.n)
        if self.loop is not None:
            self.loop_m = sum(math.hypot(q[0] - p[0], q[1] - p[1]) for p, q in self.loop.segments())
        xs, ys = [p[0] for p in world.walls] or [0.0], [p[1] for p in world.walls] or [0.0]
        self.origin = (min(xs), min(ys))
        self.nx = max(1, math.ceil((max(xs) - min(xs)) / CELL_M))
        self.ny = max(1, math.ceil((max(ys) - min(ys)) / CELL_M))
        self.visited = np.zeros((self.n, self.nx * self.ny), dtype=bool)
        self.arc: np.ndarray | None = None
        self.sample()

    def sample(self) -> None:
        from tablebot.sim import columns as L

        s = self.fleet.S
        x, y = s[:, L.X], s[:, L.Y]
        self.samples += 1
        self.touching += (s[:, L.BUMP_FR] + s[:, L.BUMP_FL] + s[:, L.BUMP_REAR] + s[:, L.CONTACT]) > 0
        ix = np.minimum(np.maximum(((x - self.origin[0]) / CELL_M).astype(np.int64), 0), self.nx - 1)
        iy = np.minimum(np.maximum(((y - self.origin[1]) / CELL_M).astype(np.int64), 0), self.ny - 1)
        self.visited[np.arange(self.n), ix * self.ny + iy] = True
        if self.loop is not None:
            from tablebot.sim.model.track import arc_positions

            arc = arc_positions(self.loop, x, y)
            if self.arc is not None:  # crossing the loop's start is a small step, not a lap
                self.laps += ((arc - self.arc + self.loop_m / 2) % self.loop_m - self.loop_m / 2) / self.loop_m
            self.arc = arc


def measure_all(fleet: Fleet, world: World, poses: Poses, owner: np.ndarray) -> dict[str, np.ndarray]:
    """Every measure per robot (those the world cannot give are left out); ``owner``: each robot's
    candidate in the joint table (its share of time per state is read from that candidate's states)."""
    s = fleet.summary()
    seconds = s.ticks * s.tick_s
    out = {
        "collisions": s.collisions.astype(float),
        "collision_share": poses.touching / poses.samples,
        "distance": s.distance_m.astype(float),
    }
    if world.lamps:
        out["time_to_lamp"] = np.where(s.reached < 0, seconds, s.reached * s.tick_s)
        out["time_to_light"] = np.where(s.first_light < 0, seconds, s.first_light * s.tick_s)
        out["missed_lamp"] = (s.reached < 0).astype(float)
        lamps = np.array([lamp.at for lamp in world.lamps])
        pose = s.final_pose
        out["lamp_distance"] = np.min(
            np.hypot(pose[:, None, 0] - lamps[None, :, 0], pose[:, None, 1] - lamps[None, :, 1]), axis=1
        )
    if len(world.walls) >= 3:
        out["area_covered"] = poses.visited.sum(axis=1) * CELL_M**2
    if poses.loop is not None:
        out["laps"] = poses.laps.copy()
    total = np.maximum(1, s.counts.sum(axis=1))
    column: dict[str, np.ndarray] = {}  # per state: its column in the joint table for each candidate
    for j, named in enumerate(s.states):  # a joint table's (candidate, state), or one candidate's own states
        k, state = named if isinstance(named, tuple) else (0, named)
        column.setdefault(f"{STATE_SHARE}{state}", np.zeros(int(owner.max()) + 1, dtype=np.int64))[k] = j
    robots = np.arange(len(owner))
    for name, columns in column.items():
        out[name] = s.counts[robots, columns[owner]] / total
    return out


Means = dict[str, float]
Scenario = tuple[int, int, "RobotSpec"]  # world, scenario index, the fleet robot


def cuts(n: int, count: int) -> list[tuple[int, int]]:
    """``range(n)`` cut into ``count`` runs of consecutive items, their lengths at most one apart."""
    bounds = [k * n // count for k in range(count + 1)]
    return [(a, b) for a, b in itertools.pairwise(bounds) if b > a]


@dataclass
class Evaluator:
    """Runs candidates on ``plan``'s scenarios through ``runner``; ``names``: the measures to keep."""

    plan: Plan
    runner: Runner
    names: Sequence[str]
    robot_ticks: int = 0  # robot-ticks simulated so far (throughput)
    evolved: int = 0  # a robot of several tables: the index of the table the candidates are (0: the main one)

    def __post_init__(self) -> None:
        self._scenarios: dict[int, tuple[Plan, list[Scenario]]] = {}

    def scenarios(self, plan: Plan) -> list[Scenario]:
        """Every scenario of ``plan`` with its fleet robot, in scenario order (drawn once per plan: every
        candidate runs the same robots)."""
        from tablebot.fleet.spec import runs

        held = self._scenarios.get(id(plan))
        if held is None or held[0] is not plan:
            held = self._scenarios[id(plan)] = (plan, [(r.world, r.index, plan.robot(r)) for r in runs(plan.spec)])
        return held[1]

    def jobs(self, candidates: Sequence[tuple[str, Table]], plan: Plan | None = None) -> list[EvalJob]:
        """The candidates' robots (candidate by candidate, each in scenario order) cut into as many jobs
        as the backend has slots (or a multiple, at most ROBOTS_PER_JOB robots a job), each cut again
        where its robots change world."""
        plan = plan or self.plan
        if plan.tables is not None:
            return self.several_jobs(candidates, plan)
        robots = [(k, *scenario) for k in range(len(candidates)) for scenario in self.scenarios(plan)]
        slots = self.runner.slots()
        count = slots * math.ceil(len(robots) / (slots * ROBOTS_PER_JOB))
        jobs = []
        for a, b in cuts(len(robots), count):
            chunk = robots[a:b]
            for world in dict.fromkeys(r[1] for r in chunk):
                jobs.append(self.job(candidates, [r for r in chunk if r[1] == world], plan, world))
        return jobs

    def several_jobs(self, candidates: Sequence[tuple[str, Table]], plan: Plan) -> list[EvalJob]:
        """A robot of several tables: each candidate (table ``evolved`` of the robot) beside the robot's other
        tables as they are, its robots in jobs of its own (a joint table would rename the states the other
        tables read), cut as :meth:`jobs` cuts them."""
        scenarios = self.scenarios(plan)
        share = max(1, self.runner.slots() // max(1, len(candidates)))
        count = max(share, math.ceil(len(scenarios) / ROBOTS_PER_JOB))
        jobs = []
        for key, table in candidates:
            tables = with_table(plan, self.evolved, table)
            for a, b in cuts(len(scenarios), count):
                chunk = scenarios[a:b]
                for world in dict.fromkeys(r[0] for r in chunk):
                    mine = [r for r in chunk if r[0] == world]
                    jobs.append(
                        EvalJob(
                            tables.table,
                            plan.worlds[world],
                            plan.robot_params,
                            [r[2] for r in mine],
                            plan.spec.ticks,
                            first=mine[0][1],
                            tables=tables,
                            parts=(Part(key, tuple(r[1] for r in mine)),),
                        )
                    )
        return jobs

    @staticmethod
    def job(
        candidates: Sequence[tuple[str, Table]], robots: list[tuple[int, int, int, RobotSpec]], plan: Plan, world: int
    ) -> EvalJob:
        """One fleet of ``robots`` (candidate, world, scenario index, robot), all in ``world``."""
        order = list(dict.fromkeys(r[0] for r in robots))
        parts = tuple(Part(candidates[k][0], tuple(r[2] for r in robots if r[0] == k)) for k in order)
        specs = [r[3] for k in order for r in robots if r[0] == k]
        return EvalJob(
            joint([candidates[k][1] for k in order]),
            plan.worlds[world],
            plan.robot_params,
            specs,
            plan.spec.ticks,
            first=robots[0][2],
            parts=parts,
        )

    def run(
        self,
        candidates: Sequence[tuple[str, Table]],
        done: Callable[[str, Means, dict[str, np.ndarray]], None],
        plan: Plan | None = None,
    ) -> None:
        """Evaluate every candidate; ``done(key, means, values)`` as soon as all of one candidate's robots
        are in (``values``: per measure, each scenario's number in scenario order)."""
        plan = plan or self.plan
        total = plan.spec.total
        candidates = list(dict(candidates).items())  # each key once
        jobs = self.jobs(candidates, plan)
        values = {key: {name: np.full(total, np.nan) for name in self.names} for key, _ in candidates}
        waiting: dict[str, int] = {}
        for job in jobs:
            for part in job.parts:
                waiting[part.key] = waiting.get(part.key, 0) + 1

        def finished(job: Any, measured: dict[str, np.ndarray]) -> None:
            at = 0
            for part in job.parts:
                n, where = len(part.scenarios), list(part.scenarios)
                for name in self.names:
                    values[part.key][name][where] = measured[name][at : at + n]
                at += n
                self.robot_ticks += n * plan.spec.ticks
                waiting[part.key] -= 1
                if waiting[part.key] == 0:
                    mine = values.pop(part.key)
                    done(part.key, {name: float(np.sum(v) / total) for name, v in mine.items()}, mine)

        self.runner.run(jobs, finished, run_eval)


def with_table(plan: Plan, k: int, table: Table) -> RobotTables:
    """The plan's tables with table ``k`` replaced by ``table`` (the plan's own when it is that table), checked
    together as the robot file's tables are (a cross-table column must still name a state its table has)."""
    from tablebot.tables import load_tables

    tables = plan.tables
    assert tables is not None, "a plan of several tables"
    if tables.tables[k] is table:
        return tables
    given = {t.name: t for t in tables.tables} | {tables.names[k]: table}
    return load_tables(given[tables.names[0]], given)


def known(name: str) -> bool:
    return name in MEASURES or name.startswith(STATE_SHARE)
