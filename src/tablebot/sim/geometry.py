"""Small compiled geometry shared by the physics core and the sensors: distances between points and
segments, segment crossings, and whether anything blocks a straight line of sight.
"""

# World arrays as in tablebot.sim.physics: ``edges`` (E, 4) = x0, y0, x1, y1 of every wall and obstacle
# edge, ``circles`` (C, 4) = x, y, r, lamp index or -1.

from __future__ import annotations

import math

from tablebot.jit import njit


@njit(cache=True)
def point_segment_distance(px, py, ax, ay, bx, by):
    """Distance from point p to segment ab."""
    ex, ey = bx - ax, by - ay
    length2 = ex * ex + ey * ey
    t = 0.0 if length2 == 0.0 else ((px - ax) * ex + (py - ay) * ey) / length2
    t = min(1.0, max(0.0, t))
    return math.hypot(px - ax - t * ex, py - ay - t * ey)


@njit(cache=True)
def segments_cross(ax, ay, bx, by, cx, cy, dx, dy):
    """Whether segments ab and cd intersect (touching counts)."""
    d1 = (bx - ax) * (cy - ay) - (by - ay) * (cx - ax)
    d2 = (bx - ax) * (dy - ay) - (by - ay) * (dx - ax)
    d3 = (dx - cx) * (ay - cy) - (dy - cy) * (ax - cx)
    d4 = (dx - cx) * (by - cy) - (dy - cy) * (bx - cx)
    return d1 * d2 <= 0.0 and d3 * d4 <= 0.0 and not (d1 == 0.0 and d2 == 0.0)


@njit(cache=True)
def segment_distance(ax, ay, bx, by, cx, cy, dx, dy):
    """Distance between segments ab and cd (0 when they cross)."""
    if segments_cross(ax, ay, bx, by, cx, cy, dx, dy):
        return 0.0
    return min(point_segment_distance(ax, ay, cx, cy, dx, dy), point_segment_distance(bx, by, cx, cy, dx, dy),
               point_segment_distance(cx, cy, ax, ay, bx, by), point_segment_distance(dx, dy, ax, ay, bx, by))



@njit(cache=True)
def shadowed(sx, sy, lx, ly, lamp, edges, circles):
    """Whether a wall, obstacle edge or circle blocks the straight line from sensor to lamp."""
    for k in range(edges.shape[0]):
        if segments_cross(sx, sy, lx, ly, edges[k, 0], edges[k, 1], edges[k, 2], edges[k, 3]):
            return True
    for k in range(circles.shape[0]):
        if int(circles[k, 3]) != lamp and point_segment_distance(
                circles[k, 0], circles[k, 1], sx, sy, lx, ly) < circles[k, 2]:
            return True
    return False
