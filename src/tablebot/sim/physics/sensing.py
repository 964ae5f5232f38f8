"""The physics of the robot file's declared sensors ([sensors]): tape under a floor sensor, an ultrasonic
echo inside a beam, light at any point of the body, and the threshold events with their hysteresis.

Each is a compiled function of one robot's state row ``s``, its parameter row ``p`` (sensor slots in
:mod:`tablebot.sim.columns`) and the world's arrays, so any loop over robots can call them.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

from tablebot.jit import njit
from tablebot.sensors import SENSOR_KINDS, threshold_event
from tablebot.sim.columns import (
    B_SENSOR,
    F_AIM,
    F_KIND,
    F_OFF,
    F_ON,
    F_SIGN,
    F_X,
    F_Y,
    MAX_SENSORS,
)
from tablebot.sim.physics.geometry import point_segment_distance, point_segment_within
from tablebot.sim.physics.layout import Params, State
from tablebot.sim.physics.shadows import NO_SHADE, shadowed_near

if TYPE_CHECKING:
    import numpy as np

threshold = njit(inline="always")(threshold_event)  # the rule of every analog input, compiled in
#: The codes of the kinds whose physics is here (tablebot.sensors.SENSOR_KINDS): a branch each below.
K_LINE, K_DISTANCE, K_LIGHT = (SENSOR_KINDS[name].code for name in ("line", "distance", "light"))


@njit(cache=True, refcounts=False, inline="always")
def light_from(
    s: State,
    c: float,
    sn: float,
    p: Params,
    lx: float,
    ly: float,
    turn: float,
    edges: np.ndarray,
    circles: np.ndarray,
    lamps: np.ndarray,
    shade: np.ndarray = NO_SHADE,
) -> float:
    """Light a sensor at (lx, ly) in the body frame, pointing ``turn`` radians left of ahead, receives:
    sum of intensity / d² × cos(angle)^k over unshadowed lamps (``c``, ``sn``: the heading's cosine and sine;
    ``shade``: the world's shadow grid, sim.physics.shadows).

    The response fades to zero over the last quarter of the field of view (a lens tube's edge).
    """
    sx, sy = s.x + c * lx - sn * ly, s.y + sn * lx + c * ly
    aim = s.th + turn
    ax, ay = math.cos(aim), math.sin(aim)
    total = 0.0
    for k in range(lamps.shape[0]):
        dx, dy = lamps[k, 0] - sx, lamps[k, 1] - sy
        ahead = dx * ax + dy * ay
        if ahead <= 0.0 and p.cos_fov >= 0.0 and (dx != 0.0 or dy != 0.0):
            continue  # behind the sensor: its cosine (ahead / d, d > 0) is <= 0 <= cos_fov, no hypot needed
        d = math.hypot(dx, dy)
        cosine = 1.0 if d == 0.0 else ahead / d
        if cosine <= p.cos_fov:
            continue
        if not shadowed_near(sx, sy, lamps[k, 0], lamps[k, 1], k, edges, circles, shade):  # first: spares the power
            total += lamp_light(p, lamps[k, 2], cosine, d)
    return total


@njit(cache=True, refcounts=False, inline="always")
def lamp_light(p: Params, intensity: float, cosine: float, d: float) -> float:
    """What one unshadowed lamp in view gives at distance ``d`` and ``cosine`` off the sensor's axis."""
    d = max(d, p.dmin)
    # cos^k response, tapered linearly to 0 at the field of view: no jump for the robot to dither on
    taper = min(1.0, (cosine - p.cos_fov) / (1.0 - p.cos_fov) * 4.0)
    return intensity * cosine**p.exp * taper / (d * d)


@njit(cache=True, refcounts=False, inline="always")
def light_turned(
    s: State,
    c: float,
    sn: float,
    p: Params,
    lx: float,
    ly: float,
    turn: float,
    ct: float,
    st: float,
    edges: np.ndarray,
    circles: np.ndarray,
    lamps: np.ndarray,
    shade: np.ndarray,
) -> float:
    """:func:`light_from`'s answer, for a sensor whose turn from the heading has cosine ``ct`` and sine ``st``:
    each lamp is first ruled out cheaply when surely out of view (:func:`out_of_view`) or in shadow, and only
    the lamps left are worked out as light_from does (the aim's cos/sin and the hypot only for them).
    Exact: a lamp out of view or shadowed adds nothing there either, and the others add the same terms in
    the same order."""
    cos_fov = p.cos_fov
    sx, sy = s.x + c * lx - sn * ly, s.y + sn * lx + c * ly  # as light_from places the sensor
    bx, by = c * ct - sn * st, sn * ct + c * st  # the aim, to within AIM_SLACK
    ax = ay = 0.0
    aimed = False
    total = 0.0
    for k in range(lamps.shape[0]):
        dx, dy = lamps[k, 0] - sx, lamps[k, 1] - sy
        if cos_fov >= 0.0 and out_of_view(dx, dy, bx, by, cos_fov):
            continue
        if shadowed_near(sx, sy, lamps[k, 0], lamps[k, 1], k, edges, circles, shade):
            continue
        if not aimed:
            aim = s.th + turn
            ax, ay, aimed = math.cos(aim), math.sin(aim), True
        ahead = dx * ax + dy * ay
        if ahead <= 0.0 and cos_fov >= 0.0 and (dx != 0.0 or dy != 0.0):
            continue
        d = math.hypot(dx, dy)
        cosine = 1.0 if d == 0.0 else ahead / d
        if cosine <= cos_fov:
            continue
        total += lamp_light(p, lamps[k, 2], cosine, d)
    return total


#: How far the aim's direction worked out by the angle-sum rule (:func:`light_turned`) may be from the one
#: light_from takes from cos/sin of the summed angle: rounding of the sum (an ulp of the heading, which is
#: never wrapped: 1e-12 after thousands of turns) and of the products, with orders of magnitude to spare.
AIM_SLACK = 1e-9


@njit(cache=True, refcounts=False, inline="always")
def out_of_view(dx: float, dy: float, ax: float, ay: float, cos_fov: float) -> bool:
    """Whether a lamp at (dx, dy) from a sensor whose aim is (ax, ay) to within AIM_SLACK is surely outside
    its field of view (``cos_fov`` >= 0) -- decided with neither the aim's own cos/sin nor a hypot, both
    dearer than the test. True only when no rounding can make it wrong: light_from then skips the lamp."""
    size = abs(dx) + abs(dy)  # at least the distance d, at most 1.5 d
    if size == 0.0:
        return False
    # light_from's dot product (d times the cosine) is below this bound, whatever the rounding
    top = dx * ax + dy * ay + 2.0 * AIM_SLACK * size
    return not (top > 0.0 and top * top > cos_fov * cos_fov * (dx * dx + dy * dy) * (1.0 - AIM_SLACK))


@njit(cache=True, refcounts=False)
def on_a_line(x: float, y: float, lines: np.ndarray) -> float:
    """1.0 when the floor point (x, y) lies on a piece of tape (within its half width of its middle), else 0.0."""
    for k in range(lines.shape[0]):
        if point_segment_within(x, y, lines[k, 0], lines[k, 1], lines[k, 2], lines[k, 3], lines[k, 4]):
            return 1.0
    return 0.0


@njit(cache=True, refcounts=False)
def beam_segment(ux: float, uy: float, cb: float, sb: float, ax: float, ay: float, bx: float, by: float) -> float:
    """Distance from the beam's apex (the origin) to the nearest point of segment ab inside the beam.

    (ux, uy) is the beam's axis, cb and sb the cosine and sine of its half angle; a and b are relative to
    the apex. The segment is clipped to the two half planes whose intersection is the beam (Liang-Barsky),
    then the nearest point of what remains is exact. Returns inf when no part lies inside.
    """
    fa, ga = ax * ux + ay * uy, ux * ay - uy * ax  # forward and leftward coordinates
    fb, gb = bx * ux + by * uy, ux * by - uy * bx
    t0, t1 = 0.0, 1.0
    for sign in (1.0, -1.0):  # inside: sin(half) * forward - sign * cos(half) * leftward >= 0
        ha, hb = sb * fa - sign * cb * ga, sb * fb - sign * cb * gb
        if ha < 0.0 and hb < 0.0:
            return math.inf
        if ha < 0.0:
            t0 = max(t0, ha / (ha - hb))
        elif hb < 0.0:
            t1 = min(t1, ha / (ha - hb))
    if t0 > t1:
        return math.inf
    return point_segment_distance(
        0.0, 0.0, ax + t0 * (bx - ax), ay + t0 * (by - ay), ax + t1 * (bx - ax), ay + t1 * (by - ay)
    )


@njit(cache=True, refcounts=False)
def beam_circle(ux: float, uy: float, cb: float, sb: float, cx: float, cy: float, radius: float) -> float:
    """Distance from the beam's apex to the nearest point of a disc (centre relative to the apex) inside the beam.

    The nearest point of the disc lies towards its centre; when the centre is outside the beam the
    nearest point inside lies on one of the beam's two edge rays. Returns inf when the beam misses it.
    """
    d = math.hypot(cx, cy)
    if d <= radius:
        return 0.0
    forward, left = cx * ux + cy * uy, ux * cy - uy * cx
    if forward > 0.0 and abs(left) * cb <= forward * sb:
        return d - radius
    best = math.inf
    for sign in (1.0, -1.0):
        rx, ry = ux * cb - sign * uy * sb, uy * cb + sign * ux * sb  # the edge ray's direction
        along = rx * cx + ry * cy
        disc = along * along - (d * d - radius * radius)
        if disc >= 0.0 and along - math.sqrt(disc) >= 0.0:
            best = min(best, along - math.sqrt(disc))
    return best


@njit(cache=True, refcounts=False)
def echo(sx: float, sy: float, aim: float, p: Params, edges: np.ndarray, circles: np.ndarray) -> float:
    """An ultrasonic sensor's reading in metres: the nearest wall, obstacle edge or circle inside its beam.

    Rounded to the sensor's resolution and never below its blind zone; with nothing in range it reads
    the range itself. Every surface echoes (no glancing-angle misses): see params.py's [distance].
    """
    ux, uy = math.cos(aim), math.sin(aim)
    cb, sb = math.cos(p.dbeam), math.sin(p.dbeam)
    best = p.drange
    hit = False
    for k in range(edges.shape[0]):
        ax, ay, bx, by = edges[k, 0] - sx, edges[k, 1] - sy, edges[k, 2] - sx, edges[k, 3] - sy
        if point_segment_distance(0.0, 0.0, ax, ay, bx, by) >= best:
            continue
        d = beam_segment(ux, uy, cb, sb, ax, ay, bx, by)
        if d < best:
            best, hit = d, True
    for k in range(circles.shape[0]):
        cx, cy = circles[k, 0] - sx, circles[k, 1] - sy
        if math.hypot(cx, cy) - circles[k, 2] >= best:
            continue
        d = beam_circle(ux, uy, cb, sb, cx, cy, circles[k, 2])
        if d < best:
            best, hit = d, True
    if not hit:
        return p.drange
    return max(p.dmin_range, round(best / p.dres) * p.dres)


@njit(cache=True, refcounts=False)
def sense_declared(
    s: State,
    c: float,
    sn: float,
    p: Params,
    edges: np.ndarray,
    circles: np.ndarray,
    lamps: np.ndarray,
    lines: np.ndarray,
    shade: np.ndarray = NO_SHADE,
) -> None:
    """Fill the reading of every declared sensor slot: line 1/0, distance in metres, light in light units
    (``c``, ``sn``: the heading's cosine and sine; ``shade``: the world's shadow grid, sim.physics.shadows)."""
    for k in range(MAX_SENSORS):
        kind = p.sensor[k, F_KIND]
        if kind == 0.0:
            continue
        bx, by = p.sensor[k, F_X], p.sensor[k, F_Y]
        if kind == K_LIGHT:
            s.reading[k] = light_from(s, c, sn, p, bx, by, p.sensor[k, F_AIM], edges, circles, lamps, shade)
            continue
        sx, sy = s.x + c * bx - sn * by, s.y + sn * bx + c * by
        if kind == K_LINE:
            s.reading[k] = on_a_line(sx, sy, lines)
        elif kind == K_DISTANCE:
            s.reading[k] = echo(sx, sy, s.th + p.sensor[k, F_AIM], p, edges, circles)


@njit(cache=True, refcounts=False, inline="always")
def sensor_events(s: State, p: Params, bits: np.ndarray, previous: int) -> int:
    """The event bits of the declared sensors (:func:`tablebot.sensors.threshold_event`: a reading past its
    threshold turns the event on; once on, it stays on until the reading is back past the threshold by the
    hysteresis; ``previous`` = last mask)."""
    mask = 0
    for k in range(min(MAX_SENSORS, bits.shape[0] - B_SENSOR)):
        bit = bits[B_SENSOR + k]
        if bit == 0 or p.sensor[k, F_KIND] == 0.0:
            continue
        on, off = p.sensor[k, F_ON], p.sensor[k, F_OFF]
        if threshold(s.reading[k], p.sensor[k, F_SIGN] > 0.0, on, off, (previous & bit) != 0):
            mask |= bit
    return mask
