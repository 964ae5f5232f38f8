"""Laps of a line follower: how far round a closed ``[[line]]`` of the world the robot has come.

The robot's axle centre is projected onto the loop (its nearest point), the arc length there is
unwrapped tick by tick, and the net progress divided by the loop's length is the number of laps (negative
when driven the other way round). A robot that leaves the tape keeps its nearest point, so cutting a
corner counts, turning round and driving back unwinds.
"""

from __future__ import annotations

import numpy as np

from tablebot.sim.model.world import Line, World


def loop_of(world: World) -> Line | None:
    """The world's first closed line (the track), if it has one."""
    return next((line for line in world.lines if line.closed), None)


def arc_positions(line: Line, xs: np.ndarray, ys: np.ndarray) -> np.ndarray:
    """Arc length (m, from the line's first point) of each point's nearest point on the line."""
    pieces = line.segments()
    a = np.array([p for p, _ in pieces], dtype=np.float64)
    b = np.array([q for _, q in pieces], dtype=np.float64)
    edge = b - a
    length = np.hypot(edge[:, 0], edge[:, 1])
    start = np.concatenate(([0.0], np.cumsum(length)[:-1]))
    best = np.full(len(xs), np.inf)
    where = np.zeros(len(xs))
    for k in range(len(pieces)):  # a loop has tens of pieces: a loop over them, vectorised over points
        t = ((xs - a[k, 0]) * edge[k, 0] + (ys - a[k, 1]) * edge[k, 1]) / (length[k] ** 2)
        t = np.clip(t, 0.0, 1.0)
        gap = np.hypot(xs - a[k, 0] - t * edge[k, 0], ys - a[k, 1] - t * edge[k, 1])
        closer = gap < best
        best[closer] = gap[closer]
        where[closer] = start[k] + t[closer] * length[k]
    return where


def laps(world: World, xs: np.ndarray, ys: np.ndarray) -> float | None:
    """Net laps round the world's loop along the path (xs, ys); None when the world has no loop."""
    line = loop_of(world)
    if line is None or len(xs) < 2:
        return None
    total = sum(float(np.hypot(q[0] - p[0], q[1] - p[1])) for p, q in line.segments())
    arc = arc_positions(line, np.asarray(xs, dtype=np.float64), np.asarray(ys, dtype=np.float64))
    step = np.diff(arc)
    step = (step + total / 2) % total - total / 2  # crossing the start point is a small step, not a lap
    return float(step.sum() / total)
