"""What a world is made of: its lamps, boxes, circles, wall segments and floor lines, the :class:`World` of
them (read from a world file by :mod:`tablebot.sim.model.world`), and the world packed as the physics core's
arrays (:func:`geometry`)."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from tablebot.sim.model.plane import Point
from tablebot.tomlfile import Source

TAPE_WIDTH = 0.019  # metres: a line's default width, that of common PVC insulating tape (15 or 19 mm)


@dataclass(frozen=True)
class Lamp:
    at: Point
    intensity: float = 3.0  # threshold units at 1 m, straight ahead: seen on-axis up to √3 ≈ 1.7 m
    radius: float = 0.04  # its base is an obstacle; 0 = a lamp hanging in the air


@dataclass(frozen=True)
class Box:
    at: Point
    size: Point
    angle: float = 0.0

    def corners(self) -> list[Point]:
        c, s = math.cos(math.radians(self.angle)), math.sin(math.radians(self.angle))
        w, h = self.size[0] / 2, self.size[1] / 2
        corners = ((-w, -h), (w, -h), (w, h), (-w, h))
        return [(self.at[0] + c * x - s * y, self.at[1] + s * x + c * y) for x, y in corners]


@dataclass(frozen=True)
class Circle:
    at: Point
    radius: float


@dataclass(frozen=True)
class Segment:
    start: Point
    end: Point


@dataclass(frozen=True)
class Line:
    """A line on the floor (tape) that floor sensors see: a polyline of ``width``, closed into a loop or not.
    It does not block the robot, its light or its distance sensors."""

    points: tuple[Point, ...]
    width: float = TAPE_WIDTH
    closed: bool = False

    def segments(self) -> list[tuple[Point, Point]]:
        pts = list(self.points)
        ends = pts[1:] + (pts[:1] if self.closed else [])
        return list(zip(pts, ends, strict=False))


@dataclass(frozen=True)
class World:
    """A checked world; ``params`` holds its parameter sections, ``line`` finds a key's line for errors."""

    name: str
    walls: tuple[Point, ...]
    start: tuple[float, float, float]  # x, y, heading in degrees
    lamps: tuple[Lamp, ...] = ()
    boxes: tuple[Box, ...] = ()
    circles: tuple[Circle, ...] = ()
    segments: tuple[Segment, ...] = ()
    lines: tuple[Line, ...] = ()
    reach: float = 0.25  # the lamp counts as found when the axle centre is this close
    params: dict[str, dict[str, Any]] = field(default_factory=dict)
    path: str = "<world>"
    source: Source | None = field(default=None, compare=False, repr=False)

    def line(self, section: str, key: str | None = None) -> int | None:
        return self.source.line(section, None, key) if self.source else None


@dataclass(frozen=True)
class Geometry:
    """A world as the physics core's arrays (see :mod:`tablebot.sim.physics.step`)."""

    verts: np.ndarray
    pstart: np.ndarray
    pbound: np.ndarray
    edges: np.ndarray
    circles: np.ndarray
    lamps: np.ndarray
    lines: np.ndarray = field(default_factory=lambda: np.zeros((0, 5)))  # (K, 5): x0, y0, x1, y1, half width
    shade: np.ndarray = field(default_factory=lambda: np.zeros(0))  # the pieces that may shadow a lamp (.shadows)


def geometry(world: World) -> Geometry:
    """The world as convex pieces (each wall and segment a 2-vertex piece, each box a 4-vertex one)."""
    pieces: list[list[Point]] = []
    walls = list(world.walls)
    pieces += [[a, b] for a, b in zip(walls, walls[1:] + walls[:1], strict=True)]
    pieces += [[s.start, s.end] for s in world.segments]
    pieces += [b.corners() for b in world.boxes]
    verts = np.array([v for piece in pieces for v in piece], dtype=np.float64).reshape(-1, 2)
    pstart = np.cumsum([0] + [len(piece) for piece in pieces]).astype(np.int64)
    pbound = np.zeros((len(pieces), 3))
    edges: list[tuple[float, float, float, float]] = []
    for k, piece in enumerate(pieces):
        arr = np.array(piece)
        centre = arr.mean(axis=0)
        pbound[k] = (*centre, np.hypot(*(arr - centre).T).max())
        pairs = [(piece[0], piece[1])] if len(piece) == 2 else list(zip(piece, piece[1:] + piece[:1], strict=True))
        edges += [(a[0], a[1], b[0], b[1]) for a, b in pairs]
    circles = [(c.at[0], c.at[1], c.radius, -1.0) for c in world.circles]
    circles += [
        (lamp.at[0], lamp.at[1], lamp.radius, float(k)) for k, lamp in enumerate(world.lamps) if lamp.radius > 0
    ]
    lamps = [(lamp.at[0], lamp.at[1], lamp.intensity) for lamp in world.lamps]
    lines = [(a[0], a[1], b[0], b[1], line.width / 2) for line in world.lines for a, b in line.segments()]
    from tablebot.sim.physics.shadows import shade_grid  # compiled code: loaded only when a world is packed for it

    edge_array = np.array(edges, dtype=np.float64).reshape(-1, 4)
    circle_array = np.array(circles, dtype=np.float64).reshape(-1, 4)
    lamp_array = np.array(lamps, dtype=np.float64).reshape(-1, 3)
    return Geometry(
        verts=verts,
        pstart=pstart,
        pbound=pbound,
        edges=edge_array,
        circles=circle_array,
        lamps=lamp_array,
        lines=np.array(lines, dtype=np.float64).reshape(-1, 5),
        shade=shade_grid(edge_array, circle_array, lamp_array),
    )
