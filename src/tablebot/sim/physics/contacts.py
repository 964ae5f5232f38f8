"""The robot's body against the world: the broad phase (which pieces may be near), contacts and how the body is
pushed out of them, and the bumpers' switches. Part of the simulator's physics (:mod:`tablebot.sim.physics.step`
calls these each tick), on the same compiled arrays of N robots.
"""

# World geometry: the arrays of tablebot.sim.physics.step (built by tablebot.sim.model.world).
#
# No shapely or pymunk: both work object by object from Python, which would not batch over thousands
# of robots; the few primitives needed (separating axes for convex pieces, segment distances) are short
# compiled functions here. Contacts are resolved by position projection (no masses or impulses): a
# kinematic robot that is pushed back out of whatever it drove into.

from __future__ import annotations

import math

import numpy as np

from tablebot.jit import njit
from tablebot.sim.physics.broad import NEAR_MARGIN as NEAR_MARGIN  # the broad phase's names, here as before
from tablebot.sim.physics.broad import might_be_near, refresh_near
from tablebot.sim.physics.broad import new_near as new_near
from tablebot.sim.physics.geometry import point_segment_within, segments_within, within
from tablebot.sim.physics.layout import Params, State, as_params, as_state

RESOLVE_ITERATIONS = 4  # contact projections per tick; one suffices except in corners
TIE = 1e-7  # metres: features this close in depth count as touching together (head-on = both)

# --- the body ------------------------------------------------------------------------------


@njit(cache=True, refcounts=False, inline="always")
def body_corners_at(s: State, p: Params, c: float, sn: float, out: np.ndarray) -> None:
    """The body rectangle's corners in world coordinates (front-right, front-left, rear-left, rear-right),
    given the heading's cosine ``c`` and sine ``sn``."""
    f, r, w = p.front, -p.rear, p.half_w
    for k, (bx, by) in enumerate(((f, -w), (f, w), (r, w), (r, -w))):
        out[k, 0] = s.x + c * bx - sn * by
        out[k, 1] = s.y + sn * bx + c * by


@njit(cache=True, refcounts=False)
def body_corners(s: np.ndarray, p: np.ndarray, out: np.ndarray) -> None:
    """The body rectangle's corners in world coordinates: front-right, front-left, rear-left, rear-right."""
    row = as_state(s)  # a float64 row from Python, or a record
    body_corners_at(row, as_params(p), math.cos(row.th), math.sin(row.th), out)


@njit(cache=True, refcounts=False, inline="always")
def bounding_radius(p: Params) -> float:
    return math.hypot(max(p.front, p.rear), p.half_w)


@njit(cache=True, refcounts=False, inline="always")
def reaches(p: Params) -> tuple[float, float]:
    """The bounding radius (the contacts' broad phase), and the reach a candidate list must serve (the
    bumpers': the radius plus the switch travel), computed as every caller computes them."""
    reach = bounding_radius(p)
    return reach, max(reach, reach + p.gap)


# --- contacts ------------------------------------------------------------------------------------


@njit(cache=True, refcounts=False)
def piece_contact(
    ux: float, uy: float, corners: np.ndarray, verts: np.ndarray, a: int, b: int
) -> tuple[float, float, float, float, float]:
    """Separating-axis test of the body (heading cosine ``ux`` and sine ``uy``, corners ``corners``) against
    convex piece verts[a:b].

    Returns (depth, dx, dy, px, py): push the robot by depth along (dx, dy); (px, py) is where they
    touch. depth <= 0 means apart. Piece axes are tried first so that a face-to-face touch is taken
    on the piece's normal and its contact point lies between the touching corners.
    """
    k = b - a
    n_piece = 1 if k == 2 else k
    best, dx, dy, robot_axis = 1e300, 0.0, 0.0, False
    for ai in range(n_piece + 2):
        if ai < n_piece:
            j0, j1 = a + ai, a + (ai + 1) % k
            ex, ey = verts[j1, 0] - verts[j0, 0], verts[j1, 1] - verts[j0, 1]
            length = math.hypot(ex, ey)
            if length == 0.0:
                continue
            ax, ay = -ey / length, ex / length
        elif ai == n_piece:
            ax, ay = ux, uy
        else:
            ax, ay = -uy, ux
        rmin, rmax = 1e300, -1e300
        for m in range(4):
            q = corners[m, 0] * ax + corners[m, 1] * ay
            rmin, rmax = min(rmin, q), max(rmax, q)
        pmin, pmax = 1e300, -1e300
        for j in range(a, b):
            q = verts[j, 0] * ax + verts[j, 1] * ay
            pmin, pmax = min(pmin, q), max(pmax, q)
        back, ahead = rmax - pmin, pmax - rmin  # push along -axis by back, or along +axis by ahead
        if back <= 0.0 or ahead <= 0.0:
            return 0.0, 0.0, 0.0, 0.0, 0.0
        overlap = min(back, ahead)
        if overlap < best - (TIE if ai >= n_piece else 0.0):
            best, robot_axis = overlap, ai >= n_piece
            dx, dy = (-ax, -ay) if back < ahead else (ax, ay)
    # the touching features: robot corners deepest against -d, or piece vertices deepest along d
    px = py = 0.0
    count = 0
    if robot_axis:
        top = -1e300
        for j in range(a, b):
            top = max(top, verts[j, 0] * dx + verts[j, 1] * dy)
        for j in range(a, b):
            if verts[j, 0] * dx + verts[j, 1] * dy >= top - TIE:
                px, py, count = px + verts[j, 0], py + verts[j, 1], count + 1
    else:
        low = 1e300
        for m in range(4):
            low = min(low, corners[m, 0] * dx + corners[m, 1] * dy)
        for m in range(4):
            if corners[m, 0] * dx + corners[m, 1] * dy <= low + TIE:
                px, py, count = px + corners[m, 0], py + corners[m, 1], count + 1
    return best, dx, dy, px / count, py / count


@njit(cache=True, refcounts=False)
def circle_contact(
    s: State, p: Params, c: float, sn: float, cx: float, cy: float, radius: float
) -> tuple[float, float, float, float, float]:
    """Body rectangle (heading cosine ``c``, sine ``sn``) against a circle; the result as :func:`piece_contact`'s."""
    rx, ry = cx - s.x, cy - s.y
    bx, by = c * rx + sn * ry, -sn * rx + c * ry  # circle centre in the body frame
    f, r, w = p.front, -p.rear, p.half_w
    qx, qy = min(f, max(r, bx)), min(w, max(-w, by))
    if qx == bx and qy == by:  # centre inside the body: leave through the nearest face
        faces = (f - bx, bx - r, w - by, by + w)
        normals = ((1.0, 0.0), (-1.0, 0.0), (0.0, 1.0), (0.0, -1.0))
        k = 0
        for m in range(1, 4):
            if faces[m] < faces[k]:
                k = m
        depth = faces[k] + radius
        nbx, nby = -normals[k][0], -normals[k][1]  # the robot moves away from the centre
        qx, qy = bx + normals[k][0] * faces[k], by + normals[k][1] * faces[k]
    else:
        gap = math.hypot(qx - bx, qy - by)
        if gap >= radius:
            return 0.0, 0.0, 0.0, 0.0, 0.0
        depth = radius - gap
        nbx, nby = (qx - bx) / gap, (qy - by) / gap
    return (depth, c * nbx - sn * nby, sn * nbx + c * nby, s.x + c * qx - sn * qy, s.y + sn * qx + c * qy)


@njit(cache=True, refcounts=False)
def deepest_near(
    s: State,
    p: Params,
    corners: np.ndarray,
    verts: np.ndarray,
    pstart: np.ndarray,
    pbound: np.ndarray,
    circles: np.ndarray,
    reach: float,
    near: np.ndarray,
) -> tuple[tuple[float, float, float, float, float], float, float]:
    """The deepest overlap of the body with the pieces and circles of candidate list ``near`` that the
    broad phase keeps for ``reach`` (bounding circles prune the rest), scanned in index order; and the
    heading's cosine and sine (worked out, with the corners, only when something is that near).
    """
    best = (0.0, 0.0, 0.0, 0.0, 0.0)
    c = sn = 0.0
    ready = False
    n = near[0]
    for j in range(n):
        k = near[2 + j]
        if not might_be_near(s.x, s.y, verts, pstart[k], pstart[k + 1], pbound, k, reach):
            continue
        if not ready:
            c, sn, ready = math.cos(s.th), math.sin(s.th), True
            body_corners_at(s, p, c, sn, corners)
        hit = piece_contact(c, sn, corners, verts, pstart[k], pstart[k + 1])
        if hit[0] > best[0]:
            best = hit
    for j in range(near[1]):
        k = near[2 + n + j]
        if not within(circles[k, 0] - s.x, circles[k, 1] - s.y, circles[k, 2] + reach):
            continue
        if not ready:
            c, sn, ready = math.cos(s.th), math.sin(s.th), True
            body_corners_at(s, p, c, sn, corners)
        hit = circle_contact(s, p, c, sn, circles[k, 0], circles[k, 1], circles[k, 2])
        if hit[0] > best[0]:
            best = hit
    return best, c, sn


@njit(cache=True)
def deepest_contact(
    s: np.ndarray,
    p: np.ndarray,
    corners: np.ndarray,
    verts: np.ndarray,
    pstart: np.ndarray,
    pbound: np.ndarray,
    circles: np.ndarray,
) -> tuple[float, float, float, float, float]:
    """The deepest overlap of the body with any piece or circle (bounding circles prune the rest)."""
    row, params = as_state(s), as_params(p)  # float64 rows from Python, or records
    near, centre = new_near(pstart, circles)
    reach, wide = reaches(params)
    refresh_near(row.x, row.y, wide, verts, pstart, pbound, circles, near, centre)
    return deepest_near(row, params, corners, verts, pstart, pbound, circles, reach, near)[0]


@njit(cache=True, refcounts=False, inline="always")
def resolve(
    s: State,
    p: Params,
    corners: np.ndarray,
    verts: np.ndarray,
    pstart: np.ndarray,
    pbound: np.ndarray,
    circles: np.ndarray,
    reach: float,
    wide: float,
    near: np.ndarray,
    centre: np.ndarray,
) -> bool:
    """Push the body out of whatever it overlaps (position-based: the push splits into shift and turn);
    returns whether it moved the robot. ``reach``/``wide``: :func:`reaches`; ``near``/``centre``: the
    robot's candidate list (:func:`refresh_near`).

    A corner touching first turns the robot about it, as a real robot pushing one bumper corner
    against a wall swings square to it; the touching point is clamped to the body.
    """
    s.contact = 0.0
    moved = False
    for _ in range(RESOLVE_ITERATIONS):
        refresh_near(s.x, s.y, wide, verts, pstart, pbound, circles, near, centre)
        if near[0] == 0 and near[1] == 0:  # in the open nothing can overlap the body (most ticks)
            return moved
        hit, c, sn = deepest_near(s, p, corners, verts, pstart, pbound, circles, reach, near)
        depth, dx, dy, px, py = hit
        if depth <= 0.0:
            return moved
        s.contact = 1.0
        moved = True
        rx, ry = px - s.x, py - s.y
        bx = min(p.front, max(-p.rear, c * rx + sn * ry))
        by = min(p.half_w, max(-p.half_w, -sn * rx + c * ry))
        rx, ry = c * bx - sn * by, sn * bx + c * by
        arm = rx * dy - ry * dx  # turning leverage of the push about the axle centre
        weight = 1.0 + arm * arm / p.gyr2
        s.x += dx * depth / weight
        s.y += dy * depth / weight
        s.th += arm / p.gyr2 * depth / weight
    return moved


# --- the bumpers' switches -----------------------------------------------------------------------


@njit(cache=True, refcounts=False)
def near_plate(
    s: State,
    c: float,
    sn: float,
    gap: float,
    x0: float,
    y0: float,
    x1: float,
    y1: float,
    verts: np.ndarray,
    pstart: np.ndarray,
    near: int,
    circles: np.ndarray,
    near_circles: int,
) -> bool:
    """Whether anything lies within the switch travel ``gap`` of a bumper plate given in the body frame
    (``c``, ``sn``: the heading's cosine and sine; ``near``/``near_circles``: bits of the pieces and
    circles the broad phase kept, the 63rd bit standing for every piece from the 63rd on)."""
    ax, ay = s.x + c * x0 - sn * y0, s.y + sn * x0 + c * y0
    bx, by = s.x + c * x1 - sn * y1, s.y + sn * x1 + c * y1
    for k in range(pstart.shape[0] - 1):
        if not near >> min(k, 62) & 1:
            continue
        a, b = pstart[k], pstart[k + 1]
        n_edges = 1 if b - a == 2 else b - a
        for j in range(n_edges):
            j0, j1 = a + j, a + (j + 1) % (b - a)
            if segments_within(ax, ay, bx, by, verts[j0, 0], verts[j0, 1], verts[j1, 0], verts[j1, 1], gap):
                return True
    for k in range(circles.shape[0]):
        if near_circles >> min(k, 62) & 1 and point_segment_within(
            circles[k, 0], circles[k, 1], ax, ay, bx, by, circles[k, 2] + gap
        ):
            return True
    return False


@njit(cache=True, refcounts=False, inline="always")
def broad_phase(
    s: State,
    reach: float,
    verts: np.ndarray,
    pstart: np.ndarray,
    pbound: np.ndarray,
    circles: np.ndarray,
    near: np.ndarray,
) -> tuple[np.int64, np.int64]:
    """Bits of the pieces and of the circles of candidate list ``near`` that may lie within ``reach`` of the
    robot's centre (exact: what it rules out is farther); pieces and circles from the 63rd on share bit 62
    and are kept. The same bits as a scan of every piece, since the list leaves out only far ones."""
    bits = np.int64(0)
    n = near[0]
    for j in range(n):
        k = near[2 + j]
        if k >= 62 or might_be_near(s.x, s.y, verts, pstart[k], pstart[k + 1], pbound, k, reach):
            bits |= np.int64(1) << min(k, 62)
    bits_circles = np.int64(0)
    for j in range(near[1]):
        k = near[2 + n + j]
        if k >= 62 or within(circles[k, 0] - s.x, circles[k, 1] - s.y, circles[k, 2] + reach + 1e-6):
            bits_circles |= np.int64(1) << min(k, 62)
    return bits, bits_circles


@njit(cache=True, refcounts=False, inline="always")
def sense_bumpers(
    s: State,
    p: Params,
    c: float,
    sn: float,
    verts: np.ndarray,
    pstart: np.ndarray,
    pbound: np.ndarray,
    circles: np.ndarray,
    reach: float,
    wide: float,
    near: np.ndarray,
    centre: np.ndarray,
) -> None:
    """Front-right, front-left (each a half plate wrapping round its corner; they overlap in the middle) and
    rear; ``c``/``sn``: the heading's cosine and sine; the rest as :func:`resolve`'s."""
    f, r, w, ov, wrap, gap = p.front, -p.rear, p.half_w, p.overlap, p.wrap, p.gap
    refresh_near(s.x, s.y, wide, verts, pstart, pbound, circles, near, centre)
    near_p, near_c = broad_phase(s, reach + gap, verts, pstart, pbound, circles, near)
    fr = fl = rear = False
    if near_p or near_c:  # in the open (most ticks) no plate can touch anything
        fr = near_plate(s, c, sn, gap, f, -w, f, ov, verts, pstart, near_p, circles, near_c) or near_plate(
            s, c, sn, gap, f - wrap, -w, f, -w, verts, pstart, near_p, circles, near_c
        )
        fl = near_plate(s, c, sn, gap, f, -ov, f, w, verts, pstart, near_p, circles, near_c) or near_plate(
            s, c, sn, gap, f - wrap, w, f, w, verts, pstart, near_p, circles, near_c
        )
        rear = near_plate(s, c, sn, gap, r, -w, r, w, verts, pstart, near_p, circles, near_c)
    s.bump_fr, s.bump_fl, s.bump_rear = (1.0 if fr else 0.0), (1.0 if fl else 0.0), (1.0 if rear else 0.0)
