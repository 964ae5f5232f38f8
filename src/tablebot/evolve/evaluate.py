"""Candidates on the fleet: every candidate runs every scenario of the plan (seeds × grid values × worlds,
the same for all: common random numbers), one fleet per candidate and world (a fleet shares one
program), on this machine's cores or a Dask cluster. Each job returns per robot every measure; a
candidate's value is the mean over its scenarios, summed in scenario order, so the numbers are the
same bits whichever backend ran which job in whichever order.

Measures the fleet's summary does not keep (laps, floor covered, time in contact) come from the robots'
poses sampled every ``stride`` ticks as the fleet runs (the fleet's noise is drawn robot by robot, so
cutting the run into short blocks changes no robot's path).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING, Any

import numpy as np

from tablebot.evolve.measures import MEASURES, STATE_SHARE
from tablebot.fleet.work import Job
from tablebot.table import Table

if TYPE_CHECKING:
    from tablebot.fleet.backends import Runner
    from tablebot.fleet.plan import Plan
    from tablebot.fleet.run import Fleet
    from tablebot.sim.world import World

STRIDE = 20  # ticks between pose samples (0.2 s at 10 ms: a robot moves at most 6 cm)
CELL_M = 0.10  # floor squares for area_covered
ROBOTS_PER_JOB = 512


@dataclass
class EvalJob(Job):
    """A fleet job of one candidate in one world, measuring everything ``measures`` needs."""

    stride: int = STRIDE


def run_eval(job: EvalJob) -> tuple[EvalJob, dict[str, np.ndarray]]:
    """Run the job's robots as one fleet; per robot, every measure (a worker's entry point)."""
    from tablebot.fleet.run import Fleet
    from tablebot.fleet.work import use_threads
    from tablebot.machine import compile_table

    use_threads(job)
    fleet = Fleet(job.table, compile_table(job.table), job.world, job.specs, job.robot_params)
    poses = Poses(fleet, job.world)
    fleet.run(job.ticks, progress=lambda done: poses.sample(), block_ticks=job.stride)
    return replace(job, specs=[]), measure_all(fleet, job.world, poses)


class Poses:
    """What the robots' sampled poses add up to: laps round the loop, floor squares visited, contact."""

    def __init__(self, fleet: Fleet, world: World):
        from tablebot.sim.track import loop_of

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
            from tablebot.sim.track import arc_positions

            arc = arc_positions(self.loop, x, y)
            if self.arc is not None:  # crossing the loop's start is a small step, not a lap
                self.laps += ((arc - self.arc + self.loop_m / 2) % self.loop_m - self.loop_m / 2) / self.loop_m
            self.arc = arc


def measure_all(fleet: Fleet, world: World, poses: Poses) -> dict[str, np.ndarray]:
    """Every measure per robot (those the world cannot give are left out)."""
    s = fleet.summary()
    seconds = s.ticks * s.tick_s
    out = {"collisions": s.collisions.astype(float), "collision_share": poses.touching / poses.samples,
           "distance": s.distance_m.astype(float)}
    if world.lamps:
        out["time_to_lamp"] = np.where(s.reached < 0, seconds, s.reached * s.tick_s)
        out["time_to_light"] = np.where(s.first_light < 0, seconds, s.first_light * s.tick_s)
        out["missed_lamp"] = (s.reached < 0).astype(float)
        lamps = np.array([lamp.at for lamp in world.lamps])
        pose = s.final_pose
        out["lamp_distance"] = np.min(np.hypot(pose[:, None, 0] - lamps[None, :, 0],
                                               pose[:, None, 1] - lamps[None, :, 1]), axis=1)
    if len(world.walls) >= 3:
        out["area_covered"] = poses.visited.sum(axis=1) * CELL_M ** 2
    if poses.loop is not None:
        out["laps"] = poses.laps.copy()
    total = np.maximum(1, s.counts.sum(axis=1))
    for k, state in enumerate(s.states):
        out[f"{STATE_SHARE}{state}"] = s.counts[:, k] / total
    return out


Means = dict[str, float]


@dataclass
class Evaluator:
    """Runs candidates on ``plan``'s scenarios through ``runner``; ``names``: the measures to keep."""

    plan: Plan
    runner: Runner
    names: Sequence[str]
    robot_ticks: int = 0  # robot-ticks simulated so far (throughput)

    def jobs(self, key: str, table: Table, plan: Plan | None = None) -> list[EvalJob]:
        """One candidate's jobs: its robots per world, at most ROBOTS_PER_JOB to a job."""
        from tablebot.fleet.spec import runs

        plan = plan or self.plan
        scenarios = runs(plan.spec)
        jobs = []
        for world in range(len(plan.spec.worlds)):
            mine = [run for run in scenarios if run.world == world]
            for a in range(0, len(mine), ROBOTS_PER_JOB):
                chunk = mine[a:a + ROBOTS_PER_JOB]
                jobs.append(EvalJob(table, plan.worlds[world], plan.robot_params, [plan.robot(r) for r in chunk],
                                    plan.spec.ticks, first=chunk[0].index, info={"key": key}))
        return jobs

    def run(self, candidates: Sequence[tuple[str, Table]], done: Callable[[str, Means, dict[str, np.ndarray]], None],
            plan: Plan | None = None) -> None:
        """Evaluate every candidate; ``done(key, means, values)`` as soon as all of one candidate's jobs are
        in (``values``: per measure, each scenario's number in scenario order)."""
        plan = plan or self.plan
        total = plan.spec.total
        values: dict[str, dict[str, np.ndarray]] = {}
        waiting: dict[str, int] = {}
        jobs = []
        for key, table in candidates:
            mine = self.jobs(key, table, plan)
            waiting[key] = len(mine)
            values[key] = {name: np.full(total, np.nan) for name in self.names}
            jobs += mine

        def finished(job: Any, measured: dict[str, np.ndarray]) -> None:
            key = job.info["key"]
            n = len(next(iter(measured.values())))
            for name in self.names:
                values[key][name][job.first:job.first + n] = measured[name]
            self.robot_ticks += n * plan.spec.ticks
            waiting[key] -= 1
            if waiting[key] == 0:
                mine = values.pop(key)
                done(key, {name: float(np.sum(v) / total) for name, v in mine.items()}, mine)

        self.runner.run(jobs, finished, run_eval)  # type: ignore[call-arg]


def known(name: str) -> bool:
    return name in MEASURES or name.startswith(STATE_SHARE)
