"""Small compiled geometry shared by the physics core and the sensors: distances between points and
segments, segment crossings, and whether anything blocks a straight line of sight.
"""

# World arrays as in tablebot.sim.physics.step: ``edges`` (E, 4) = x0, y0, x1, y1 of every wall and obstacle
# edge, ``circles`` (C, 4) = x, y, r, lamp index or -1.

from __future__ import annotations

import math
from typing import TYPE_CHECKING

from tablebot.jit import njit

if TYPE_CHECKING:
    import numpy as np


@njit(cache=True, refcounts=False)
def point_segment_distance(px: float, py: float, ax: float, ay: float, bx: float, by: float) -> float:
    """Distance from point p to segment ab."""
    ex, ey = bx - ax, by - ay
    length2 = ex * ex + ey * ey
    t = 0.0 if length2 == 0.0 else ((px - ax) * ex + (py - ay) * ey) / length2
    t = min(1.0, max(0.0, t))
    return math.hypot(px - ax - t * ex, py - ay - t * ey)


#: A squared distance above r² times this is surely farther than r, whatever the rounding of either
#: (a few ulps, 1e-16 each): the fast answer of :func:`within` is then the answer hypot would give.
FAR = 1.0 + 1e-12
TINY = 1e-100  # below this, r² loses precision (underflow): such radii always take the exact path


@njit(cache=True, refcounts=False)
def within(dx: float, dy: float, r: float, strict: bool = False) -> bool:
    """``math.hypot(dx, dy) <= r`` (``< r`` when ``strict``): exactly that answer, but hypot (about 15 ns
    here, five times a square root) runs only when the squared distance does not already show that the
    point is farther. Most tests of a broad phase, a bumper or a lamp are far misses."""
    if r > TINY and dx * dx + dy * dy > r * r * FAR:
        return False
    return math.hypot(dx, dy) < r if strict else math.hypot(dx, dy) <= r


@njit(cache=True, refcounts=False)
def point_segment_within(
    px: float, py: float, ax: float, ay: float, bx: float, by: float, r: float, strict: bool = False
) -> bool:
    """``point_segment_distance(px, py, ax, ay, bx, by) <= r`` (``< r`` when ``strict``), by :func:`within`."""
    ex, ey = bx - ax, by - ay
    length2 = ex * ex + ey * ey
    t = 0.0 if length2 == 0.0 else ((px - ax) * ex + (py - ay) * ey) / length2
    t = min(1.0, max(0.0, t))
    return within(px - ax - t * ex, py - ay - t * ey, r, strict)


#: Metres by which both ends of a segment must clear the line through another, beyond the distance asked
#: about, for :func:`segments_within` to answer without its four distances (rounding is ~1e-15 m here).
LINE_MARGIN = 1e-9


@njit(cache=True, refcounts=False)
def segments_within(
    ax: float, ay: float, bx: float, by: float, cx: float, cy: float, dx: float, dy: float, r: float
) -> bool:
    """Whether segments ab and cd come within ``r`` of each other (0 apart when they cross): the nearest
    of the four endpoint-to-segment distances, each tested by :func:`within`.

    First the sides of a and b against the line through cd (the products :func:`segments_cross` starts
    with): when both lie on one side, farther from the line than ``r`` by LINE_MARGIN, all of ab is, so
    neither segment comes within ``r`` of the other and the four distances would all say so."""
    ex, ey = dx - cx, dy - cy
    d3 = ex * (ay - cy) - ey * (ax - cx)
    d4 = ex * (by - cy) - ey * (bx - cx)
    if d3 * d4 > 0.0:
        clear = (r + LINE_MARGIN) * (r + LINE_MARGIN) * (ex * ex + ey * ey)
        if d3 * d3 > clear and d4 * d4 > clear:
            return False
    if segments_cross(ax, ay, bx, by, cx, cy, dx, dy):
        return r >= 0.0
    return (
        point_segment_within(ax, ay, cx, cy, dx, dy, r)
        or point_segment_within(bx, by, cx, cy, dx, dy, r)
        or point_segment_within(cx, cy, ax, ay, bx, by, r)
        or point_segment_within(dx, dy, ax, ay, bx, by, r)
    )


@njit(cache=True, refcounts=False)
def segments_cross(ax: float, ay: float, bx: float, by: float, cx: float, cy: float, dx: float, dy: float) -> bool:
    """Whether segments ab and cd intersect (touching counts). The sides of a and b against line cd are
    compared first: most pairs are refused there, before the sides of c and d are worked out."""
    d3 = (dx - cx) * (ay - cy) - (dy - cy) * (ax - cx)
    d4 = (dx - cx) * (by - cy) - (dy - cy) * (bx - cx)
    if not d3 * d4 <= 0.0:
        return False
    d1 = (bx - ax) * (cy - ay) - (by - ay) * (cx - ax)
    d2 = (bx - ax) * (dy - ay) - (by - ay) * (dx - ax)
    return d1 * d2 <= 0.0 and not (d1 == 0.0 and d2 == 0.0)


@njit(cache=True, refcounts=False)
def shadowed(sx: float, sy: float, lx: float, ly: float, lamp: int, edges: np.ndarray, circles: np.ndarray) -> bool:
    """Whether a wall, obstacle edge or circle blocks the straight line from sensor to lamp."""
    for k in range(edges.shape[0]):
        if segments_cross(sx, sy, lx, ly, edges[k, 0], edges[k, 1], edges[k, 2], edges[k, 3]):
            return True
    for k in range(circles.shape[0]):
        if int(circles[k, 3]) != lamp and point_segment_within(
            circles[k, 0], circles[k, 1], sx, sy, lx, ly, circles[k, 2], True
        ):
            return True
    return False
