"""What a fleet's run amounts to: per robot the numbers a sweep keeps (:class:`FleetSummary`), and for a traced
robot its trace and whole run (:class:`Trace`), as ``tablebot sim`` gives them for that robot."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from tablebot.loop import RunEnd, TickBlock
from tablebot.machine import Machine
from tablebot.sim import columns as L
from tablebot.sim.physics import kernel as K
from tablebot.sim.runner import PATH_STRIDE, SimRun
from tablebot.sim.simrobot import SimRobot
from tablebot.sim.summary import Summary
from tablebot.sinks.run_trace import seconds_per_state
from tablebot.sinks.trace_file import block_lines

FLEET_COLLISIONS = 16  # collision starts remembered per robot (the count goes on beyond)


@dataclass
class FleetSummary:
    """Per robot, what a sweep needs: arrays indexed by robot (``NO_TICK``/-1: never)."""

    ticks: int
    tick_s: float
    states: tuple[Any, ...]  # the machine's states (indices in final_state and counts)
    first_light: np.ndarray  # tick whose reading first held a light bit
    reached: np.ndarray  # robot row that first came within reach of a lamp
    collisions: np.ndarray
    distance_m: np.ndarray
    battery_start_v: np.ndarray
    battery_end_v: np.ndarray
    final_state: np.ndarray  # state index after the last tick
    counts: np.ndarray  # (N, states): ticks spent in each state (the state after each tick)
    first_visit: np.ndarray  # (N, states): first tick after which the robot was in that state
    collision_rows: np.ndarray  # (N, FLEET_COLLISIONS): the first collision starts
    final_pose: np.ndarray  # (N, 3): x, y (m) and heading (radians, unwrapped) after the last tick
    lamps: bool = True  # whether the world has lamps (as in sim.summary.Summary)

    def __len__(self) -> int:
        return len(self.first_light)

    def summary(self, i: int) -> Summary:
        """Robot i's numbers as :func:`tablebot.sim.summary.summarise` gives them for a single run, but for
        laps round a track (they need the whole path, which a fleet does not keep: None)."""

        def seconds(tick: int) -> float | None:
            return None if tick < 0 else tick * self.tick_s

        count = int(self.collisions[i])
        return Summary(
            seconds=self.ticks * self.tick_s,
            first_light_s=seconds(int(self.first_light[i])),
            reached_s=seconds(int(self.reached[i])),
            collisions=count,
            collision_ticks=tuple(self.collision_rows[i, : min(count, FLEET_COLLISIONS)].tolist()),
            distance_m=float(self.distance_m[i]),
            state_seconds=seconds_per_state(self.counts[i], self.first_visit[i], self.states, self.tick_s),
            battery_start_v=float(self.battery_start_v[i]),
            battery_end_v=float(self.battery_end_v[i]),
            lamps=self.lamps,
        )


@dataclass
class Trace:
    """A traced robot's run, kept block by block (its SimRobot makes the blocks, as in ``tablebot sim``)."""

    robot: SimRobot
    blocks: list[TickBlock] = field(default_factory=list)
    rows: list[np.ndarray] = field(default_factory=list)  # robot rows at the start of each tick

    def lines(self, machine: Machine) -> list[str]:
        """The trace, line for line what ``tablebot sim`` writes."""
        return [line for block in self.blocks for line in block_lines(block, machine)]

    def result(self, s: np.ndarray, acc: np.ndarray, collisions: np.ndarray, ticks: int) -> SimRun:
        """The whole run as the single-robot runner's :class:`SimRun` (for its pictures), the robot now at
        row ``s`` with summary ``acc`` and collision starts ``collisions`` after ``ticks`` ticks."""
        blocks, robot = self.blocks, self.robot

        def column(name: str) -> np.ndarray:
            return np.concatenate([np.asarray(getattr(b, name)) for b in blocks])

        hist = np.concatenate([*self.rows, s[None, :]])
        count = int(acc[K.A_COLLISIONS])
        reached = int(acc[K.A_REACHED])
        return SimRun(
            scene=robot.scene,
            seed=robot.seed,
            hist=hist,
            ends=hist[[0, -1]],
            path=hist[::PATH_STRIDE, [L.X, L.Y]],
            masks=column("masks"),
            events=column("events"),
            rows=column("rows"),
            states=column("states"),
            timers=column("timers"),
            outputs=column("outputs"),
            counters=column("counters"),
            pulses=column("pulses"),
            collision_rows=collisions[: min(count, FLEET_COLLISIONS)].tolist(),
            collision_count=count,
            reached_row=None if reached < 0 else reached,
            end=RunEnd("done", ticks),
            wall_s=0.0,
        )
