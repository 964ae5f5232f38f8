"""Plane geometry for checking a world file: a polygon's area, whether it crosses itself, whether a point is
inside it, how far a point is from a segment (the simulator has its own compiled geometry)."""

from __future__ import annotations

import math

Point = tuple[float, float]


def area(poly: list[Point]) -> float:
    """The signed area of a polygon (shoelace formula): 0 for one with no inside."""
    return 0.5 * sum(x0 * y1 - x1 * y0 for (x0, y0), (x1, y1) in zip(poly, poly[1:] + poly[:1], strict=True))


def _cross(a: Point, b: Point, c: Point, d: Point) -> bool:
    def orient(p: Point, q: Point, r: Point) -> float:
        return (q[0] - p[0]) * (r[1] - p[1]) - (q[1] - p[1]) * (r[0] - p[0])

    return orient(a, b, c) * orient(a, b, d) < 0 and orient(c, d, a) * orient(c, d, b) < 0


def self_crossing(poly: list[Point]) -> tuple[int, int] | None:
    """The first two edges of a polygon that cross (by their first corners' indexes), or None."""
    n = len(poly)
    for i in range(n):
        for j in range(i + 2, n):
            if i == 0 and j == n - 1:
                continue  # neighbours through the closing corner
            if _cross(poly[i], poly[(i + 1) % n], poly[j], poly[(j + 1) % n]):
                return i, j
    return None


def inside(poly: tuple[Point, ...] | list[Point], p: Point) -> bool:
    """Even-odd rule point-in-polygon."""
    x, y = p
    result = False
    for (x0, y0), (x1, y1) in zip(poly, [*poly[1:], poly[0]], strict=True):
        if (y0 > y) != (y1 > y) and x < x0 + (y - y0) * (x1 - x0) / (y1 - y0):
            result = not result
    return result


def first_outside(walls: list[Point], points: tuple[Point, ...]) -> Point:
    """The first point of a line outside the walls (or its first point, inside: nothing to report)."""
    return next((p for p in points if not inside(walls, p)), points[0])


def distance_to_segment(p: Point, a: Point, b: Point) -> float:
    """Distance from p to segment ab (for checking a world file; the simulator has its own compiled one)."""
    ex, ey = b[0] - a[0], b[1] - a[1]
    length2 = ex * ex + ey * ey
    t = 0.0 if length2 == 0.0 else min(1.0, max(0.0, ((p[0] - a[0]) * ex + (p[1] - a[1]) * ey) / length2))
    return math.hypot(p[0] - a[0] - t * ex, p[1] - a[1] - t * ey)
