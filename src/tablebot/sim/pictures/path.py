"""The run's path as the trajectory draws it: cut where the state changes and thinned to what a picture can
show (:class:`PathPieces`, piece by piece as the run goes), and where a state begins with a turn on the spot
(:func:`spin_starts`). numpy only: :mod:`tablebot.sim.pictures.plots` draws what these give."""

from __future__ import annotations

import numpy as np

PATH_STEP_M = 0.002  # the path is drawn through points 2 mm apart: finer than the picture's pixels
SPIN_M, SPIN_DEG = 0.01, 15.0  # a state that moves the robot less and turns it more is a spin: drawn as a dot


def spin_starts(x: np.ndarray, y: np.ndarray, heading: np.ndarray, states: np.ndarray) -> np.ndarray:
    """Rows where a state begins that turns the robot on the spot: its stretch of the run moves the axle
    less than SPIN_M but turns it more than SPIN_DEG (a line follower's quick state changes are no spins)."""
    change = np.flatnonzero(np.diff(states)) + 1
    starts, ends = np.concatenate(([0], change)), np.concatenate((change, [len(states)]))
    moved = np.hypot(x[ends] - x[starts], y[ends] - y[starts])
    turned = np.degrees(np.abs(heading[ends].astype(np.float64) - heading[starts]))
    return starts[(moved < SPIN_M) & (turned > SPIN_DEG)]


class PathPieces:
    """The run's path cut where the state changes (segment t, from row t to t + 1, has the state after tick
    t), each piece thinned to points about ``step`` apart along it (ends kept): what a picture can show.
    Made as the run goes: each :meth:`grow` gives the pieces completed since the last, the same pieces
    (to the last bit) as the whole run's rows would give at once."""

    def __init__(self, step: float = PATH_STEP_M) -> None:
        self.step = step
        self.start = 0  # the first row of the piece not given yet
        self.known = 0  # the rows whose thinning is known: 0..known
        self.travelled = 0.0  # the distance along the path to row ``known``
        self.kept: list[np.ndarray] = [np.zeros(0, dtype=np.int64)]  # the rows a piece keeps inside it, in order

    def grow(
        self, x: np.ndarray, y: np.ndarray, states: np.ndarray, done: int, last: bool = False
    ) -> tuple[list[np.ndarray], list[int]]:
        """The pieces complete once robot rows 0..done (``x``, ``y``) and ``states[:done]`` are known (with
        ``last``, the run is over: ``done`` is its length, and the last piece ends there)."""
        if done > self.known:
            xy = np.column_stack((x[self.known : done + 1], y[self.known : done + 1])).astype(np.float64)
            travelled = np.cumsum(np.concatenate(([self.travelled], np.hypot(*np.diff(xy, axis=0).T))))
            bucket = np.floor(travelled / self.step)  # a row is kept where the path enters the next step
            self.kept.append(np.flatnonzero(bucket[1:] != bucket[:-1]) + self.known + 1)
            self.known, self.travelled = done, float(travelled[-1])
        change = np.flatnonzero(np.diff(states[self.start : done])) + self.start + 1
        ends = np.concatenate((change, [done])) if last else change
        if not len(ends):
            return [], []
        starts = np.concatenate(([self.start], ends[:-1]))
        self.start = int(ends[-1])
        kept = np.concatenate(self.kept)
        self.kept = [kept]
        inner_from, inner_to = np.searchsorted(kept, starts, "right"), np.searchsorted(kept, ends, "left")
        rows = [
            np.concatenate(([a], kept[i:j], [b]))
            for a, b, i, j in zip(starts.tolist(), ends.tolist(), inner_from.tolist(), inner_to.tolist(), strict=True)
        ]
        every = np.concatenate(rows)
        xy = np.column_stack((x[every], y[every])).astype(np.float64)
        pieces = np.split(xy, np.cumsum([len(r) for r in rows[:-1]]))
        return pieces, states[starts].tolist()
