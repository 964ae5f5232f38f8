"""The broad phase of the robot's body against the world (part of :mod:`tablebot.sim.physics.contacts`, which names
these too): which convex pieces and circles may be near the robot, kept as a list of candidates from tick to tick."""

from __future__ import annotations

import numpy as np

from tablebot.jit import njit
from tablebot.sim.physics.geometry import within

#: Metres beyond the bumpers' reach within which pieces are kept as candidates (:func:`refresh_near`): the list
#: serves every tick until the robot is half this far from where it was made (about ten ticks at full speed).
NEAR_MARGIN = 0.05


@njit(cache=True, refcounts=False, inline="always")
def might_be_near(
    px: float, py: float, verts: np.ndarray, a: int, b: int, pbound: np.ndarray, k: int, reach: float
) -> bool:
    """Whether convex piece verts[a:b] may come within ``reach`` of point p (the broad phase).

    Never wrong in the other direction: a piece it rules out is farther than ``reach`` (with a 1 µm
    margin over rounding), so skipping it changes no result. Its bounding circle is tested first (the
    test the narrow phase always had); a wall or segment is then tested by its squared distance.
    """
    if not within(pbound[k, 0] - px, pbound[k, 1] - py, pbound[k, 2] + reach):
        return False
    if b - a != 2:
        return True
    ax, ay = verts[a, 0], verts[a, 1]
    ex, ey = verts[a + 1, 0] - ax, verts[a + 1, 1] - ay
    length2 = ex * ex + ey * ey
    t = 0.0 if length2 == 0.0 else min(1.0, max(0.0, ((px - ax) * ex + (py - ay) * ey) / length2))
    dx, dy = px - ax - t * ex, py - ay - t * ey
    margin = reach + 1e-6
    return dx * dx + dy * dy <= margin * margin


@njit(cache=True)
def new_near(pstart: np.ndarray, circles: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Scratch space of one robot's candidate list (see :func:`refresh_near`): the list, and where it was made."""
    return np.zeros(2 + pstart.shape[0] - 1 + circles.shape[0], dtype=np.int64), np.zeros(3)


@njit(cache=True, refcounts=False, inline="always")
def refresh_near(
    x: float,
    y: float,
    reach: float,
    verts: np.ndarray,
    pstart: np.ndarray,
    pbound: np.ndarray,
    circles: np.ndarray,
    near: np.ndarray,
    centre: np.ndarray,
) -> None:
    """Keep ``near`` the list of the pieces and circles that may come within ``reach`` of the robot's centre
    (x, y) -- near[0] pieces, then near[1] circles, their indices from near[2] on, in index order -- remade
    only when the robot is half NEAR_MARGIN away from where it was made (``centre``: x, y, 1 when made).

    Exact: the list is made for ``reach + NEAR_MARGIN``, so what it leaves out is farther than ``reach`` by
    centimetres, far beyond rounding, wherever the robot is until the list is remade; the callers still apply
    their own exact broad-phase test to every candidate, so they decide as if they had scanned every piece.
    Pieces and circles from the 63rd on are always listed (the bumpers' bit masks keep them all).
    """
    dx, dy = x - centre[0], y - centre[1]
    half = 0.5 * NEAR_MARGIN
    if centre[2] > 0.0 and dx * dx + dy * dy < half * half:
        return
    wide = reach + NEAR_MARGIN
    n = 0
    for k in range(pstart.shape[0] - 1):
        if k >= 62 or might_be_near(x, y, verts, pstart[k], pstart[k + 1], pbound, k, wide):
            near[2 + n] = k
            n += 1
    m = 0
    for k in range(circles.shape[0]):
        if k >= 62 or within(circles[k, 0] - x, circles[k, 1] - y, circles[k, 2] + wide + 1e-6):
            near[2 + n + m] = k
            m += 1
    near[0], near[1] = n, m
    centre[0], centre[1], centre[2] = x, y, 1.0
