"""World files: the arena a simulated robot drives in (walls, obstacles, lamps, start pose), read and checked;
what it is made of is :mod:`tablebot.sim.model.shapes` (re-exported here);
``examples/bumberbot/arena.toml`` is the commented reference of the TOML format.
Lengths are metres, angles degrees (0 = +x, counter-clockwise); a world may also hold the parameter
sections of a robot file's ``[sim]`` ([body], [motor], [battery], ...), which win over the robot's.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from tablebot.i18n import N_
from tablebot.sim.model.params import SECTIONS, check_layer
from tablebot.sim.model.plane import Point, area, distance_to_segment, first_outside, inside, self_crossing
from tablebot.sim.model.shapes import (
    TAPE_WIDTH,
    Box,
    Circle,
    Geometry,
    Lamp,
    Line,
    Segment,
    World,
    geometry,
)
from tablebot.tomlfile import Source, Where, known_keys, label, number, point, table_of

__all__ = [
    "DEFAULT_WORLD",
    "ON_A_WALL",
    "TAPE_WIDTH",
    "TOP_KEYS",
    "Box",
    "Circle",
    "Geometry",
    "Lamp",
    "Line",
    "Point",
    "Segment",
    "World",
    "default_world",
    "geometry",
    "inside",
    "load_world",
    "parse_world",
]

ON_A_WALL = 1e-6  # metres: a lamp this close to a wall's line is in it (every ray to it crosses the wall)
TOP_KEYS = ("name", "reach", "arena", "start", "lamp", "box", "circle", "segment", "line", *SECTIONS)


DEFAULT_WORLD = """\
name = "empty room"
[arena]
walls = [[0, 0], [2.5, 0], [2.5, 2.0], [0, 2.0]]
[start]
at = [0.5, 0.5]
heading = 30
[[lamp]]
at = [2.0, 1.5]
"""


def load_world(path: str | Path) -> World:
    return parse_world(Source.read(path))


def default_world() -> World:
    return parse_world(Source.parse("<built-in empty room>", DEFAULT_WORLD))


def parse_world(src: Source) -> World:
    """Check every part of a world file, reporting all problems at once."""
    data = src.data
    known_keys(src, ("", None), data, TOP_KEYS)
    name = data.get("name", Path(src.path).stem)
    if not isinstance(name, str):
        src.error(("", None, "name"), N_("name must be a string"), N_('for example: name = "living room"'))
    reach = number(src, ("", None, "reach"), data.get("reach", 0.25), 0.01, 100.0)
    walls = _walls(src, table_of(src, ("arena", None, None), data.get("arena", {})))
    start = _start(src, table_of(src, ("start", None, None), data.get("start", {})))
    lamps = _many(src, data, "lamp", _lamp)
    boxes = _many(src, data, "box", _box)
    circles = _many(src, data, "circle", _circle)
    segments = _many(src, data, "segment", _segment)
    lines = _many(src, data, "line", _line)
    params = check_layer(src, data)
    if walls and start:
        _inside(
            src,
            walls,
            [("start", None, "at", start[:2])]
            + [("lamp", i, "at", lamp.at) for i, lamp in enumerate(lamps)]
            + [("line", i, "points", first_outside(walls, line.points)) for i, line in enumerate(lines)],
        )
    if walls:
        _lamps_in_the_open(src, walls, lamps, boxes, circles, segments)
    src.raise_if_any()
    return World(
        name=str(name),
        walls=tuple(walls),
        start=start,  # type: ignore[arg-type]  # None only with an error, raised above
        lamps=tuple(lamps),
        boxes=tuple(boxes),
        circles=tuple(circles),
        segments=tuple(segments),
        lines=tuple(lines),
        reach=float(reach or 0.25),
        params=params,
        path=src.path,
        source=src,
    )


def _many(src: Source, data: dict[str, Any], section: str, read: Any) -> list[Any]:
    """Every ``[[section]]`` table, each read by ``read``; anything else is reported once."""
    items = data.get(section, [])
    if isinstance(items, dict):
        items = [items]
    if not isinstance(items, list) or not all(isinstance(item, dict) for item in items):
        src.error(
            ("", None, section),
            N_("{section} must be written as [[{section}]] tables, not {items!r}", section=section, items=items),
            N_("see examples/bumberbot/arena.toml"),
        )
        return []
    found = [read(src, i, item) for i, item in enumerate(items)]
    return [item for item in found if item is not None]


def _point(src: Source, where: Where, table: dict[str, Any]) -> Point | None:
    """The point ``where`` names in ``table``; a missing one is reported as missing."""
    key = where[2]
    if key not in table:
        src.error(where, N_("{name} is missing", name=label(where)), N_("add {key} = [x, y] (metres)", key=key))
        return None
    return point(src, where, table[key])


def _walls(src: Source, arena: dict[str, Any]) -> list[Point]:
    known_keys(src, ("arena", None), arena, ("walls",))
    raw = arena.get("walls")
    where = ("arena", None, "walls")
    if raw is None:
        src.error(
            where,
            N_("[arena] walls is missing: the room's corners"),
            N_(
                "add an [arena] section with walls = [[0, 0], [3, 0], [3, 2], [0, 2]] (metres, in order around "
                "the room)"
            ),
        )
        return []
    if not isinstance(raw, list) or len(raw) < 3:
        src.error(
            where,
            N_("[arena] walls must list at least three corners [x, y]"),
            N_("for example: walls = [[0, 0], [3, 0], [3, 2], [0, 2]]"),
        )
        return []
    corners = [point(src, where, p) for p in raw]
    if any(c is None for c in corners):
        return []
    walls: list[Point] = corners  # type: ignore[assignment]
    crossing = self_crossing(walls)
    if crossing:
        src.error(
            where,
            N_(
                "[arena] walls cross themselves (wall {first} and wall {second})",
                first=crossing[0] + 1,
                second=crossing[1] + 1,
            ),
            N_("list the corners in order around the room, clockwise or counter-clockwise"),
        )
    elif abs(area(walls)) < 1e-6:
        src.error(where, N_("[arena] walls enclose no area"), N_("list the corners of the room in order"))
    return walls


def _start(src: Source, start: dict[str, Any]) -> tuple[float, float, float] | None:
    known_keys(src, ("start", None), start, ("at", "heading"))
    if "at" not in start:
        src.error(
            ("start", None, None),
            N_("[start] needs at = [x, y], the robot's axle centre"),
            N_("add a [start] section with at = [0.5, 0.5] and heading = 0"),
        )
        return None
    at = point(src, ("start", None, "at"), start["at"])
    heading = number(src, ("start", None, "heading"), start.get("heading", 0.0), -3600, 3600)
    if at is None or heading is None:
        return None
    return at[0], at[1], float(heading)


def _lamp(src: Source, i: int, t: dict[str, Any]) -> Lamp | None:
    known_keys(src, ("lamp", i), t, ("at", "intensity", "radius"))
    at = _point(src, ("lamp", i, "at"), t)
    intensity = number(src, ("lamp", i, "intensity"), t.get("intensity", 3.0), 1e-6, 1e6)
    radius = number(src, ("lamp", i, "radius"), t.get("radius", 0.04), 0.0, 10.0)
    if at is None or intensity is None or radius is None:
        return None
    return Lamp(at, float(intensity), float(radius))


def _box(src: Source, i: int, t: dict[str, Any]) -> Box | None:
    known_keys(src, ("box", i), t, ("at", "size", "angle"))
    at = _point(src, ("box", i, "at"), t)
    size = _point(src, ("box", i, "size"), t)
    angle = number(src, ("box", i, "angle"), t.get("angle", 0.0), -3600, 3600)
    if size is not None and min(size) <= 0:
        src.error(
            ("box", i, "size"),
            N_("[[box]] #{n} size must be positive, not {size}", n=i + 1, size=list(size)),
            N_("size = [width, depth] in metres"),
        )
        return None
    if at is None or size is None or angle is None:
        return None
    return Box(at, size, float(angle))


def _circle(src: Source, i: int, t: dict[str, Any]) -> Circle | None:
    known_keys(src, ("circle", i), t, ("at", "radius"))
    at = _point(src, ("circle", i, "at"), t)
    if "radius" not in t:
        src.error(
            ("circle", i, "radius"), N_("[[circle]] #{n} radius is missing", n=i + 1), N_("add radius = 0.1 (metres)")
        )
        return None
    radius = number(src, ("circle", i, "radius"), t["radius"], 0.001, 100.0)
    return None if at is None or radius is None else Circle(at, float(radius))


def _segment(src: Source, i: int, t: dict[str, Any]) -> Segment | None:
    known_keys(src, ("segment", i), t, ("from", "to"))
    a = _point(src, ("segment", i, "from"), t)
    b = _point(src, ("segment", i, "to"), t)
    if a is not None and a == b:
        src.error(("segment", i, "to"), N_("[[segment]] #{n} has no length", n=i + 1), N_("give two different points"))
        return None
    return None if a is None or b is None else Segment(a, b)


def _line(src: Source, i: int, t: dict[str, Any]) -> Line | None:
    known_keys(src, ("line", i), t, ("points", "width", "closed"))
    where = ("line", i, "points")
    raw = t.get("points")
    if not isinstance(raw, list) or len(raw) < 2:
        src.error(
            where,
            N_("[[line]] #{n} needs points = [[x, y], [x, y], ...] (at least two)", n=i + 1),
            N_("list the corners of the tape in order, in metres"),
        )
        return None
    points = [point(src, where, p) for p in raw]
    width = number(src, ("line", i, "width"), t.get("width", TAPE_WIDTH), 0.001, 1.0)
    closed = t.get("closed", False)
    if not isinstance(closed, bool):
        src.error(
            ("line", i, "closed"),
            N_("[[line]] #{n} closed must be true or false, not {closed!r}", n=i + 1, closed=closed),
            N_("closed = true joins the last point back to the first"),
        )
        return None
    if any(p is None for p in points) or width is None:
        return None
    if any(a == b for a, b in itertools.pairwise(points)):
        src.error(
            where, N_("[[line]] #{n} repeats a point: a piece of no length", n=i + 1), N_("remove the repeated point")
        )
        return None
    return Line(tuple(points), float(width), closed)  # type: ignore[arg-type]


def _inside(src: Source, walls: list[Point], places: Sequence[tuple[str, int | None, str, Point]]) -> None:
    for section, index, key, at in places:
        if not inside(walls, at):
            src.error(
                (section, index, key),
                N_("{section} at {at} is outside the arena walls", section=section, at=list(at)),
                N_("move it inside the [arena] walls polygon"),
            )


def _lamps_in_the_open(
    src: Source, walls: list[Point], lamps: list[Lamp], boxes: list[Box], circles: list[Circle], segments: list[Segment]
) -> None:
    """A lamp inside an obstacle or on a wall is dark: every ray from it to the robot is blocked."""
    lines = [*zip(walls, walls[1:] + walls[:1], strict=True), *((s.start, s.end) for s in segments)]
    for i, lamp in enumerate(lamps):
        place = _blocked(lamp.at, lines, boxes, circles) if inside(walls, lamp.at) else None  # else: outside
        if place:
            src.error(
                ("lamp", i, "at"),
                N_(
                    "[[lamp]] #{n} at {at} is {place}: its light cannot reach the robot",
                    n=i + 1,
                    at=list(lamp.at),
                    place=place,
                ),
                N_("move the lamp into the open"),
            )


def _blocked(at: Point, lines: list[tuple[Point, Point]], boxes: list[Box], circles: list[Circle]) -> str | None:
    """Where ``at`` is shut in: inside a box or a circle, or on a wall line; None when in the open."""
    for k, box in enumerate(boxes):
        if inside(box.corners(), at):
            return N_("inside [[box]] #{n}", n=k + 1)
    for k, circle in enumerate(circles):
        if math.dist(circle.at, at) < circle.radius:
            return N_("inside [[circle]] #{n}", n=k + 1)
    if any(distance_to_segment(at, a, b) < ON_A_WALL for a, b in lines):
        return N_("on a wall")
    return None
