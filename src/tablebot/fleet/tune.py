"""Tuning a table's integer cells (timers, counter loads) against an objective over a fixed scenario set.

Every candidate runs the same scenarios (seeds × grid values × worlds: common random numbers), all
candidates of a generation in one fleet of program variants. One or two cells are searched on a plain
grid (every value when the budget allows); more with CMA-ES with margin for integers (``cmaes.CMAwM``).
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING

import numpy as np

from tablebot.fleet.cells import Cell, cell_variants, parse_cells
from tablebot.fleet.plan import Plan
from tablebot.fleet.robots import Variants
from tablebot.fleet.spec import runs
from tablebot.fleet.work import Job

if TYPE_CHECKING:
    from tablebot.fleet.backends import Runner
    from tablebot.fleet.results import FleetSummary

__all__ = [
    "OBJECTIVES",
    "Cell",
    "Evaluator",
    "best",
    "grid_points",
    "jobs_for",
    "losses",
    "parse_cells",
    "search_cma",
    "search_grid",
    "split",
]

ROBOTS_PER_JOB = 512
OBJECTIVES = {
    "time_to_lamp": "mean seconds until the lamp is reached (a run that never reaches it counts its whole length)",
    "time_to_light": "mean seconds until a light sensor first sees the lamp (never: the whole run)",
    "collisions": "mean number of collisions",
    "lamp_distance": "mean distance (m) from the robot to the nearest lamp when the run ends",
    "missed_lamp": "the share of runs that never reach the lamp",
}


def losses(objective: str, s: FleetSummary, plan: Plan, world: int) -> np.ndarray:
    """Each robot's objective value (lower is better)."""
    seconds = s.ticks * s.tick_s
    if objective == "time_to_lamp":
        return np.where(s.reached < 0, seconds, s.reached * s.tick_s)
    if objective == "time_to_light":
        return np.where(s.first_light < 0, seconds, s.first_light * s.tick_s)
    if objective == "collisions":
        return s.collisions.astype(float)
    if objective == "missed_lamp":
        return (s.reached < 0).astype(float)
    lamps = np.array([lamp.at for lamp in plan.worlds[world].lamps] or [(math.inf, math.inf)])
    pose = s.final_pose
    return np.min(np.hypot(pose[:, None, 0] - lamps[None, :, 0], pose[:, None, 1] - lamps[None, :, 1]), axis=1)


History = list[tuple[tuple[int, ...], float]]


@dataclass
class Evaluator:
    """Runs candidates on the scenario set of ``plan`` through ``runner``.

    ``known`` holds values measured before (an interrupted run's evaluations): such a candidate is not run
    again, so the same search resumed takes the same steps, at once, up to where it stopped.
    ``on_record(history)`` is called after each batch that ran something new (to keep it on disk).
    """

    plan: Plan
    cells: Sequence[Cell]
    objective: str
    runner: Runner
    history: History = field(default_factory=list)
    cache: dict[tuple[int, ...], float] = field(default_factory=dict)
    on_eval: Callable[[int], None] | None = None
    known: dict[tuple[int, ...], float] = field(default_factory=dict)
    on_record: Callable[[History], None] | None = None

    def __call__(self, candidates: Sequence[Sequence[int]]) -> list[float]:
        wanted = [tuple(int(v) for v in c) for c in candidates]
        new = list(dict.fromkeys(c for c in wanted if c not in self.cache))
        to_run = [c for c in new if c not in self.known]
        measured = dict(zip(to_run, self.measure(to_run, self.plan)[self.objective], strict=True))
        for candidate in new:
            value = measured[candidate] if candidate in measured else self.known[candidate]
            self.cache[candidate] = value
            self.history.append((candidate, value))
        if to_run and self.on_record:
            self.on_record(self.history)
        if new and self.on_eval:
            self.on_eval(len(new))
        return [self.cache[c] for c in wanted]

    def measure(
        self, candidates: Sequence[tuple[int, ...]], plan: Plan, metrics: Sequence[str] = ()
    ) -> dict[str, list[float]]:
        """Mean of each metric (default: the objective) per candidate over ``plan``'s scenarios."""
        metrics = tuple(metrics) or (self.objective,)
        if not candidates:
            return {metric: [] for metric in metrics}
        variants = cell_variants(plan.tables, plan.machine, self.cells, candidates)
        jobs = jobs_for(plan, variants, len(candidates), self.runner.slots())
        finished: dict[tuple[int, int], dict[str, np.ndarray]] = {}

        def done(job: Job, summary: FleetSummary) -> None:
            finished[job.info["world"], job.first] = {m: losses(m, summary, plan, job.info["world"]) for m in metrics}

        self.runner.run(jobs, done)
        sums = {metric: np.zeros(len(candidates)) for metric in metrics}
        for job in jobs:  # summed in job order, not in the order the workers finished: the same sums every time
            robots = finished[job.info["world"], job.first]
            for metric in metrics:
                np.add.at(sums[metric], np.asarray(job.info["variants"]), robots[metric])
        return {metric: (total / plan.spec.total).tolist() for metric, total in sums.items()}


def jobs_for(plan: Plan, variants: Variants, count: int, slots: int = 1) -> list[Job]:
    """Every candidate on every scenario, cut into jobs within one world: at most ROBOTS_PER_JOB robots each,
    as many jobs as that needs rounded up to a multiple of ``slots`` (the workers that run them at once),
    and sizes that differ by one robot at most, so that no worker waits on another's last job (528 robots
    on two workers: 264 + 264, not 512 + 16)."""
    jobs: list[Job] = []
    scenarios = runs(plan.spec)
    robots = [plan.robot(run) for run in scenarios]
    for world in range(len(plan.spec.worlds)):
        mine = [(run, robot) for run, robot in zip(scenarios, robots, strict=True) if run.world == world]
        specs = [replace(robot, variant=v) for v in range(count) for _, robot in mine]
        for a, b in split(len(specs), slots):
            chunk = specs[a:b]
            jobs.append(
                Job(
                    plan.table,
                    plan.worlds[world],
                    plan.robot_params,
                    chunk,
                    plan.spec.ticks,
                    first=a,
                    variants=variants,
                    info={"world": world, "variants": [s.variant for s in chunk]},
                    tables=plan.tables,
                )
            )
    return jobs


def split(robots: int, slots: int, most: int = ROBOTS_PER_JOB) -> list[tuple[int, int]]:
    """Robots 0..robots-1 cut into ranges [a, b) of at most ``most``, as many as that needs rounded up to a
    multiple of ``slots`` (the workers that run them at once), sizes within one robot of each other."""
    parts = max(1, -(-robots // most))
    if parts > 1:
        parts = min(robots, -(-parts // slots) * slots)
    return list(itertools.pairwise(k * robots // parts for k in range(parts + 1)))


# --- search ------------------------------------------------------------------------------------------


def grid_points(cells: Sequence[Cell], budget: int) -> list[tuple[int, ...]]:
    """Every value of one or two cells when the budget allows, else evenly spaced values."""
    per_cell = max(2, int(budget ** (1 / len(cells))))
    axes = []
    for cell in cells:
        size = cell.high - cell.low + 1
        axes.append(
            list(range(cell.low, cell.high + 1))
            if size <= per_cell or math.prod(c.high - c.low + 1 for c in cells) <= budget
            else sorted({round(v) for v in np.linspace(cell.low, cell.high, per_cell)})
        )
    if len(axes) == 1:
        return [(v,) for v in axes[0]]
    return [(a, b) for a in axes[0] for b in axes[1]]


def search_grid(evaluate: Evaluator, budget: int, batch: int = 64) -> None:
    points = grid_points(evaluate.cells, budget)
    for a in range(0, len(points), batch):
        evaluate(points[a : a + batch])


def search_cma(evaluate: Evaluator, budget: int, seed: int = 0) -> None:
    """CMA-ES with margin (integer steps of 1), started at the table's values; stops after ``budget``
    distinct candidates (repeats come from the cache and cost nothing)."""
    from cmaes import CMAwM

    cells = evaluate.cells
    bounds = np.array([[c.low, c.high] for c in cells], dtype=float)
    mean = np.clip([c.value for c in cells], bounds[:, 0], bounds[:, 1]).astype(float)
    sigma = float(np.mean((bounds[:, 1] - bounds[:, 0]) / 4)) or 1.0
    optimizer = CMAwM(mean=mean, sigma=sigma, bounds=bounds, steps=np.ones(len(cells)), seed=seed)
    stale = 0
    while len(evaluate.history) < budget and stale < 50:
        asked = [optimizer.ask() for _ in range(optimizer.population_size)]
        before = len(evaluate.history)
        values = evaluate([np.rint(x_eval).astype(int) for x_eval, _ in asked])
        optimizer.tell([(x_tell, value) for (_, x_tell), value in zip(asked, values, strict=True)])
        stale = stale + 1 if len(evaluate.history) == before else 0
        if optimizer.should_stop():
            break


def best(history: Sequence[tuple[tuple[int, ...], float]]) -> tuple[tuple[int, ...], float]:
    """The lowest objective (the first one evaluated among equals)."""
    return min(history, key=lambda item: item[1])
