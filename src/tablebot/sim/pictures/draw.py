"""Drawing pieces shared by the pictures and the animation: arena, tape, obstacles, lamps with their bases,
the robot with its sensors, where a collision touched (state colours: :mod:`tablebot.colours`).

Only matplotlib artists on a given Axes; no figure or backend is chosen here, so headless use
never touches a display.
"""

from __future__ import annotations

import functools
import itertools
import math
from dataclasses import dataclass
from typing import Any

import matplotlib
import numpy as np
from matplotlib.axes import Axes
from matplotlib.collections import PatchCollection
from matplotlib.patches import Circle as CirclePatch
from matplotlib.patches import Polygon, Rectangle, Wedge

from tablebot.sensors import Sensor
from tablebot.sim import columns as L
from tablebot.sim.model.params import Params
from tablebot.sim.model.world import Geometry, World


#: Every picture is drawn inside this: user text (a robot's name, a state's, a label) is drawn as written.
#: matplotlib would read text between two ``$`` as maths, and fail on it or draw formulae: this is the
#: pictures' escape, one switch for all their text (decorate each function that makes a figure).
def literal_text() -> Any:
    return matplotlib.rc_context({"text.parse_math": False})


FLOOR, WALL, OBSTACLE, OBSTACLE_EDGE = "#f6f3ec", "#2f3640", "#a4b0be", "#57606f"
LAMP_ON, LAMP_OFF, BODY, BUMPER, BUMPER_ON = "#ffd32a", "#d2dae2", "#dfe4ea", "#57606f", "#ff3f34"
COLLISION, LIGHT_SEEN, REACHED = "#e8413a", "#f0a500", "#20bf6b"
TAPE, BEAM, BEAM_NEAR = "#1e1e1e", "#4a90d9", "#1f5fa8"
TAPE_FILL = "#a8a49c"  # the tape on the floor: grey, not black, so a path driven along it shows on top
TOUCH_M = 0.001  # outline points this much farther than the nearest still touch (a face flat on a wall)


def draw_world(ax: Axes, world: World, lamp_glow: bool = True) -> None:
    """Floor, walls, obstacles and lamps, with equal axes in metres."""
    floor = Polygon(world.walls, closed=True, facecolor=FLOOR, edgecolor=WALL, linewidth=3, zorder=0)
    ax.add_patch(floor)
    for box in world.boxes:
        ax.add_patch(
            Polygon(
                box.corners(),
                closed=True,
                facecolor=OBSTACLE,
                edgecolor=OBSTACLE_EDGE,
                linewidth=1.2,
                hatch="//",
                zorder=2,
            )
        )
    for circle in world.circles:
        ax.add_patch(
            CirclePatch(
                circle.at,
                circle.radius,
                facecolor=OBSTACLE,
                edgecolor=OBSTACLE_EDGE,
                linewidth=1.2,
                hatch="//",
                zorder=2,
            )
        )
    for seg in world.segments:
        ax.plot(*zip(seg.start, seg.end, strict=True), color=WALL, linewidth=3, solid_capstyle="round", zorder=2)
    draw_tape(ax, world)
    for lamp in world.lamps:
        if lamp_glow:
            for k, radius in enumerate((0.45, 0.3, 0.18)):
                ax.add_patch(
                    CirclePatch(lamp.at, radius, facecolor=LAMP_ON, alpha=0.12 + 0.08 * k, linewidth=0, zorder=1)
                )
            # a sensor looking straight at the lamp reads the threshold at sqrt(intensity) metres
            ring = CirclePatch(
                lamp.at,
                math.sqrt(lamp.intensity),
                fill=False,
                edgecolor="#b8860b",
                linestyle="--",
                linewidth=1,
                alpha=0.6,
                zorder=1,
            )
            ax.add_patch(ring)
            ring.set_clip_path(floor)
        if lamp.radius > 0:  # the lamp's base is an obstacle the robot bumps into: drawn as one, to scale
            ax.add_patch(
                CirclePatch(
                    lamp.at,
                    lamp.radius,
                    facecolor=OBSTACLE,
                    edgecolor=OBSTACLE_EDGE,
                    linewidth=1.2,
                    hatch="//",
                    zorder=2,
                )
            )
        ax.plot(
            *lamp.at,
            marker="*",
            markersize=9 if lamp.radius > 0 else 16,
            color=LAMP_ON,
            markeredgecolor="#b8860b",
            zorder=12,
        )
    xs, ys = zip(*world.walls, strict=True)
    pad = 0.05 * max(max(xs) - min(xs), max(ys) - min(ys))
    ax.set_xlim(min(xs) - pad, max(xs) + pad)
    ax.set_ylim(min(ys) - pad, max(ys) + pad)
    ax.set_aspect("equal")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")


def draw_tape(ax: Axes, world: World) -> None:
    """Each [[line]] to scale: a band of its width along every piece, round at the corners."""
    patches: list = []
    for line in world.lines:
        half = line.width / 2
        for (x0, y0), (x1, y1) in line.segments():
            angle = math.degrees(math.atan2(y1 - y0, x1 - x0))
            length = math.hypot(x1 - x0, y1 - y0)
            c, s = math.cos(math.radians(angle)), math.sin(math.radians(angle))
            patches.append(Rectangle((x0 + s * half, y0 - c * half), length, line.width, angle=angle))
        patches += [CirclePatch(p, half) for p in line.points]
    if patches:
        ax.add_collection(PatchCollection(patches, facecolor=TAPE_FILL, edgecolor="none", zorder=0.5))


def contact_point(geometry: Geometry, params: Params, x: float, y: float, theta: float) -> tuple[float, float]:
    """Where the robot at this pose touches the world (see :func:`contact_points`)."""
    ((cx, cy),) = contact_points(geometry, params, np.array([[x, y, theta]]))
    return float(cx), float(cy)


def contact_points(geometry: Geometry, params: Params, poses: np.ndarray) -> np.ndarray:
    """Where the robot at each pose (x, y, theta rows) touches the world: the point of the wall, obstacle or
    lamp base nearest to its body's outline (sampled every 2 mm); a face lying flat against a wall touches
    along a stretch, marked at its middle. All poses at once (an hour has hundreds of collisions), a few
    hundred at a time; each pose's point is the one the pose alone gives, to the last bit."""
    body = params["body"]
    f, r, w = body["front"], -body["rear"], body["half_width"]
    outline = _outline(f, r, w)
    poses = np.asarray(poses, dtype=np.float64).reshape(-1, 3)
    found = np.empty((len(poses), 2))
    step = max(1, (1 << 18) // len(outline))
    for at in range(0, len(poses), step):
        found[at : at + step] = _touching(geometry, outline, math.hypot(max(f, -r), w), poses[at : at + step])
    return found


def _touching(geometry: Geometry, outline: np.ndarray, reach: float, poses: np.ndarray) -> np.ndarray:
    n = len(poses)
    x, y = poses[:, 0], poses[:, 1]
    # cos and sin of each heading as math gives them (numpy's vector versions may differ in the last bit)
    c = np.array([math.cos(theta) for theta in poses[:, 2].tolist()])[:, None]
    s = np.array([math.sin(theta) for theta in poses[:, 2].tolist()])[:, None]
    px = (x[:, None] + c * outline[:, 0] - s * outline[:, 1])[:, :, None]  # (N, M, 1)
    py = (y[:, None] + s * outline[:, 0] + c * outline[:, 1])[:, :, None]
    where, best, rows = poses[:, :2].copy(), np.full(n, math.inf), np.arange(n)
    # only edges and circles that can hold the nearest point (or one within TOUCH_M of it) are sampled: every
    # outline point lies within ``reach`` of the centre, so a feature farther than the nearest one by more
    # than 2 reach + TOUCH_M (and a micrometre for rounding) is farther from every point of the outline
    edges = _near(_edge_distances(geometry.edges, x, y), 2 * reach + TOUCH_M + 1e-6)  # (N, K): indices
    if edges.shape[1]:
        e = geometry.edges[edges][:, None]  # (N, 1, K, 4)
        ax, ay, bx, by = e[..., 0], e[..., 1], e[..., 2], e[..., 3]
        abx, aby = bx - ax, by - ay
        t = np.clip(((px - ax) * abx + (py - ay) * aby) / np.maximum(abx * abx + aby * aby, 1e-18), 0.0, 1.0)
        nx, ny = ax + t * abx, ay + t * aby  # (N, M, K): each sample's nearest point on each edge
        gap = np.hypot(px - nx, py - ny)
        edge = gap.reshape(n, -1).argmin(axis=1) % gap.shape[2]  # the first nearest, as argmin over (M, K)
        gaps = gap[rows, :, edge]  # (N, M): each pose's gaps to its nearest edge
        best = gaps.min(axis=1)
        touching = gaps <= best[:, None] + TOUCH_M
        points = np.stack((nx[rows, :, edge], ny[rows, :, edge]), axis=-1)  # (N, M, 2)
        for k in range(n):  # the middle of each stretch, summed in the order numpy sums it alone
            where[k] = points[k, touching[k]].mean(axis=0)
    circles = _near(
        np.hypot(geometry.circles[:, 0] - x[:, None], geometry.circles[:, 1] - y[:, None]) - geometry.circles[:, 2],
        2 * reach + 1e-6,
    )
    if circles.shape[1]:
        held = geometry.circles[circles][:, None]  # (N, 1, K, 3)
        ox, oy = px - held[..., 0], py - held[..., 1]
        dist = np.hypot(ox, oy)
        gap = dist - held[..., 2]
        m, k = np.divmod(gap.reshape(n, -1).argmin(axis=1), gap.shape[2])
        closer = gap[rows, m, k] < best
        off = np.stack((ox[rows, m, k], oy[rows, m, k]), axis=-1)
        centre, radius = held[rows, 0, k, :2], held[rows, 0, k, 2]
        rim = centre + off / np.maximum(dist[rows, m, k], 1e-12)[:, None] * radius[:, None]
        where[closer] = rim[closer]
    return where


def _edge_distances(edges: np.ndarray, x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """(N, E): the distance from each (x, y) to each edge."""
    a, ab = edges[:, :2], edges[:, 2:] - edges[:, :2]
    dx, dy = x[:, None] - a[:, 0], y[:, None] - a[:, 1]
    t = np.clip((dx * ab[:, 0] + dy * ab[:, 1]) / np.maximum((ab * ab).sum(-1), 1e-18), 0.0, 1.0)
    return np.hypot(dx - t * ab[:, 0], dy - t * ab[:, 1])


def _near(distance: np.ndarray, slack: float) -> np.ndarray:
    """(N, K): per row, the indices (in order) of the features no farther than the nearest plus ``slack``,
    padded at the end by repeating the last (a repeat never wins an argmin over the one it repeats)."""
    if not distance.shape[1]:
        return np.zeros((len(distance), 0), dtype=np.int64)
    near = distance <= distance.min(axis=1, keepdims=True) + slack
    order = np.sort(np.where(near, np.arange(near.shape[1]), near.shape[1]), axis=1)[:, : near.sum(axis=1).max()]
    last = order[np.arange(len(order)), near.sum(axis=1) - 1]
    return np.where(order == near.shape[1], last[:, None], order)


@functools.lru_cache(maxsize=8)
def _outline(f: float, r: float, w: float) -> np.ndarray:
    """The body's outline in its own frame, a point every 2 mm (made once per body, not per collision)."""
    corners = np.array([(f, -w), (f, w), (r, w), (r, -w), (f, -w)])
    outline = np.concatenate(
        [
            np.linspace(a, b, max(2, int(math.hypot(*(b - a)) / 0.002)), endpoint=False)
            for a, b in itertools.pairwise(corners)
        ]
    )
    outline.flags.writeable = False
    return outline


def _transform(points: np.ndarray, x: float, y: float, theta: float) -> np.ndarray:
    c, s = math.cos(theta), math.sin(theta)
    return np.column_stack((x + c * points[:, 0] - s * points[:, 1], y + s * points[:, 0] + c * points[:, 1]))


@dataclass
class RobotArtist:
    """The robot drawn to scale: body, the bumpers and phototransistor cones it has wired, its declared
    sensors (floor spots dark over tape, distance beams as far as they reach, light cones), lit lamps."""

    ax: Axes
    params: Params
    n_lamps: int = 0
    alpha: float = 1.0
    sensors: tuple[Sensor, ...] = ()

    def __post_init__(self) -> None:
        b, light = self.params["body"], self.params["light"]
        f, r, w, ov = b["front"], -b["rear"], b["half_width"], b["bumper_overlap"]
        self.body_pts = np.array([(f, -w), (f, w), (r, w), (r, -w)])
        t = 0.012  # drawn bumper thickness
        # bumpers drawn just inside the outline (the body outline is what touches)
        self.bump_pts = [
            np.array([(f, -w), (f, ov), (f - t, ov), (f - t, -w)]),
            np.array([(f, -ov), (f, w), (f - t, w), (f - t, -ov)]),
            np.array([(r, -w), (r, w), (r + t, w), (r + t, -w)]),
        ]
        self.lamp_pts = np.array([(r + 0.03 + 0.035 * k, 0.0) for k in range(self.n_lamps)]).reshape(-1, 2)
        self.cone_len = 0.25
        self.sensor_pts = np.array([(light["forward"], -light["sideways"]), (light["forward"], light["sideways"])])
        self.toe = math.radians(light["toe_out"])
        self.fov = light["half_response"]
        z = 8
        self.body = Polygon(
            self.body_pts, closed=True, facecolor=BODY, edgecolor=WALL, lw=1.2, alpha=self.alpha, zorder=z
        )
        self.bumpers = [
            Polygon(p, closed=True, facecolor=BUMPER, lw=0, alpha=self.alpha, zorder=z + 1) for p in self.bump_pts
        ]
        self.cones = [
            Wedge((0, 0), self.cone_len, 0, 1, facecolor=LAMP_ON, alpha=0.18 * self.alpha, lw=0, zorder=z - 1)
            for _ in range(2)
        ]
        self.lamps = [
            CirclePatch((0, 0), 0.016, facecolor=LAMP_OFF, edgecolor=WALL, lw=0.8, alpha=self.alpha, zorder=z + 3)
            for _ in range(self.n_lamps)
        ]
        self.glows = [
            CirclePatch((0, 0), 0.04, facecolor=LAMP_ON, lw=0, alpha=0.0, zorder=z + 2) for _ in range(self.n_lamps)
        ]
        wiring = self.params.wiring  # a bumper or phototransistor not wired to an input is not drawn
        for patch, role in zip(
            [*self.bumpers, *self.cones],
            ("front_right", "front_left", "rear", "light_right", "light_left"),
            strict=True,
        ):
            patch.set_visible(bool(wiring.get(role)))
        self.heading = self.ax.plot([], [], color=WALL, lw=1.5, alpha=self.alpha, zorder=z + 1)[0]
        self.declared = [self._sensor_patch(sensor, z) for sensor in self.sensors]
        for patch in (self.body, *self.bumpers, *self.cones, *self.glows, *self.lamps, *self.declared):
            self.ax.add_patch(patch)

    def _sensor_patch(self, sensor: Sensor, z: int) -> Polygon | Wedge:
        """How its kind is drawn (``SensorKind.draw``): a spot, a beam or a cone."""
        if sensor.sensor_kind.draw == "spot":  # a 12 mm spot on the body, dark while it reads 1 (over tape)
            return Polygon(
                np.zeros((4, 2)), closed=True, facecolor="white", edgecolor=TAPE, lw=0.8, alpha=self.alpha, zorder=z + 4
            )
        colour = BEAM if sensor.sensor_kind.draw == "beam" else LAMP_ON
        return Wedge((0, 0), 0.01, 0, 1, facecolor=colour, alpha=0.2 * self.alpha, lw=0, zorder=z - 1)

    def artists(self) -> list:
        return [self.body, *self.bumpers, *self.cones, *self.glows, *self.lamps, *self.declared, self.heading]

    def update(
        self,
        x: float,
        y: float,
        theta: float,
        bumpers: tuple[bool, bool, bool] = (False,) * 3,
        lights: tuple[bool, bool] = (False, False),
        lamps: tuple[int, ...] = (),
        readings: tuple[float, ...] = (),
    ) -> None:
        """Move to (x, y, theta); ``readings`` are the declared sensors' (``sensor_readings``)."""
        self.body.set_xy(_transform(self.body_pts, x, y, theta))
        for patch, pts, on in zip(self.bumpers, self.bump_pts, bumpers, strict=True):
            patch.set_xy(_transform(pts, x, y, theta))
            patch.set_facecolor(BUMPER_ON if on else BUMPER)
        for cone, pt, side, seen in zip(self.cones, self.sensor_pts, (-1, 1), lights, strict=True):
            cx, cy = _transform(pt[None, :], x, y, theta)[0]
            aim = math.degrees(theta + side * self.toe)
            cone.set_center((cx, cy))
            cone.set_theta1(aim - self.fov)
            cone.set_theta2(aim + self.fov)
            cone.set_alpha((0.45 if seen else 0.15) * self.alpha)
        levels = tuple(lamps) + (0,) * (self.n_lamps - len(lamps))
        for lamp, glow, pt, level in zip(self.lamps, self.glows, self.lamp_pts, levels, strict=True):
            lamp.center = glow.center = tuple(_transform(pt[None, :], x, y, theta)[0])
            lamp.set_facecolor(LAMP_ON if level else LAMP_OFF)
            glow.set_alpha(0.25 + 0.4 * min(level, 8) / 8 if level else 0.0)  # brighter for higher levels
        nose = _transform(np.array([(0.0, 0.0), (self.body_pts[0, 0] * 0.8, 0.0)]), x, y, theta)
        self.heading.set_data(nose[:, 0], nose[:, 1])
        values = tuple(readings) + (0.0,) * (len(self.sensors) - len(readings))
        for spot, sensor, value in zip(self.declared, self.sensors, values, strict=True):
            self._update_sensor(spot, sensor, value, x, y, theta)

    def _update_sensor(
        self, patch: Polygon | Wedge, sensor: Sensor, value: float, x: float, y: float, theta: float
    ) -> None:
        at = np.array(sensor.at)
        if isinstance(patch, Polygon):
            spot = at + np.array([(-1, -1), (1, -1), (1, 1), (-1, 1)]) * 0.006
            patch.set_xy(_transform(spot, x, y, theta))
            patch.set_facecolor(TAPE if value > 0.5 else "white")
            return
        cx, cy = _transform(at[None, :], x, y, theta)[0]
        aim = math.degrees(theta) + sensor.angle
        on = value < sensor.threshold if sensor.direction == "below" else value > sensor.threshold
        kind = sensor.sensor_kind
        section, key = kind.spread or ("light", "half_response")
        half = self.params[section][key]
        if kind.draw == "beam":  # the beam as far as the echo came from
            patch.set_radius(max(value, 0.005))
            patch.set_facecolor(BEAM_NEAR if on else BEAM)
        else:
            patch.set_radius(0.25)
        patch.set_center((cx, cy))
        patch.set_theta1(aim - half)
        patch.set_theta2(aim + half)
        patch.set_alpha((0.45 if on else 0.18) * self.alpha)


def sensor_readings(row: np.ndarray, sensors: tuple[Sensor, ...]) -> tuple[float, ...]:
    """The declared sensors' readings in a robot row of the run's history."""
    return tuple(float(row[L.READING + k]) for k in range(min(len(sensors), L.MAX_SENSORS)))
