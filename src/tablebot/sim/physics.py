"""All geometry and physics of the simulator: motors and battery, kinematics, collisions, bumpers, light.
It works on numpy arrays of N robots (layout in :mod:`tablebot.sim.columns`), compiled with numba, so one
robot and a batch of thousands (which do not see each other) share this code.
"""

# World geometry (built by tablebot.sim.world): ``verts`` (V, 2) and ``pstart`` (P+1,) are convex
# pieces (a wall or segment is a 2-vertex piece, a box a 4-vertex one); ``pbound`` (P, 3) their
# bounding circles; ``edges`` (E, 4) every piece's edges for ray casts; ``circles`` (C, 4) = x, y, r,
# lamp index or -1; ``lamps`` (L, 3) = x, y, intensity; ``lines`` (K, 5) = x0, y0, x1, y1, half width of
# each straight piece of tape on the floor (seen by floor sensors only).
#
# No shapely or pymunk: both work object by object from Python, which would not batch over thousands
# of robots; the few primitives needed (separating axes for convex pieces, segment distances, ray
# tests) are short compiled functions here. Contacts are resolved by position projection (no masses
# or impulses): a kinematic robot that is pushed back out of whatever it drove into.

from __future__ import annotations

import math

import numpy as np

from tablebot.jit import njit
from tablebot.sim.columns import (
    AMPS,
    B_FL,
    B_FR,
    B_LIGHT_L,
    B_LIGHT_R,
    B_REAR,
    BUMP_FL,
    BUMP_FR,
    BUMP_REAR,
    CONTACT,
    DIST,
    ENC_L,
    ENC_R,
    F_KIND,
    GAIN_L,
    GAIN_R,
    LIGHT_L,
    LIGHT_R,
    MASK,
    P_ALPHA,
    P_BASE,
    P_CAP,
    P_DT,
    P_FRONT,
    P_GAP,
    P_GYR2,
    P_HALF_W,
    P_IIDLE,
    P_IMOTOR,
    P_KV,
    P_LEVELS,
    P_LX,
    P_LY,
    P_NLIGHT,
    P_NMOTOR,
    P_OVERLAP,
    P_PPR,
    P_REAR,
    P_RINT,
    P_SENSOR,
    P_TOE,
    P_VEMPTY,
    P_VF,
    P_VFULL,
    P_WHEEL_R,
    P_WRAP,
    PUL_L,
    PUL_R,
    SOC,
    TH,
    V_L,
    V_R,
    VBAT,
    Z_LIGHT_L,
    Z_LIGHT_R,
    Z_MOTOR_L,
    Z_MOTOR_R,
    X,
    Y,
)
from tablebot.sim.geometry import point_segment_within, segments_within, within
from tablebot.sim.sensing import light_turned, sense_declared, sensor_events
from tablebot.sim.shadows import NO_SHADE

NO_LINES = np.zeros((0, 5))  # a world without tape on its floor
RESOLVE_ITERATIONS = 4  # contact projections per tick; one suffices except in corners
TIE = 1e-7  # metres: features this close in depth count as touching together (head-on = both)
#: Metres beyond the bumpers' reach within which pieces are kept as candidates (:func:`refresh_near`): the list
#: serves every tick until the robot is half this far from where it was made (about ten ticks at full speed).
NEAR_MARGIN = 0.05

# --- the broad phase and the body ------------------------------------------------------------------------------


@njit(cache=True, refcounts=False, inline="always")
def might_be_near(px, py, verts, a, b, pbound, k, reach):
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
def new_near(pstart, circles):
    """Scratch space of one robot's candidate list (see :func:`refresh_near`): the list, and where it was made."""
    return np.zeros(2 + pstart.shape[0] - 1 + circles.shape[0], dtype=np.int64), np.zeros(3)


@njit(cache=True, refcounts=False, inline="always")
def refresh_near(x, y, reach, verts, pstart, pbound, circles, near, centre):
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


@njit(cache=True, refcounts=False, inline="always")
def body_corners_at(s, p, c, sn, out):
    """The body rectangle's corners in world coordinates (front-right, front-left, rear-left, rear-right),
    given the heading's cosine ``c`` and sine ``sn``."""
    f, r, w = p[P_FRONT], -p[P_REAR], p[P_HALF_W]
    for k, (bx, by) in enumerate(((f, -w), (f, w), (r, w), (r, -w))):
        out[k, 0] = s[X] + c * bx - sn * by
        out[k, 1] = s[Y] + sn * bx + c * by


@njit(cache=True, refcounts=False)
def body_corners(s, p, out):
    """The body rectangle's corners in world coordinates: front-right, front-left, rear-left, rear-right."""
    body_corners_at(s, p, math.cos(s[TH]), math.sin(s[TH]), out)


@njit(cache=True, refcounts=False, inline="always")
def bounding_radius(p):
    return math.hypot(max(p[P_FRONT], p[P_REAR]), p[P_HALF_W])


@njit(cache=True, refcounts=False, inline="always")
def reaches(p):
    """The bounding radius (the contacts' broad phase), and the reach a candidate list must serve (the
    bumpers': the radius plus the switch travel), computed as every caller computes them."""
    reach = bounding_radius(p)
    return reach, max(reach, reach + p[P_GAP])


# --- contacts ------------------------------------------------------------------------------------


@njit(cache=True, refcounts=False)
def piece_contact(ux, uy, corners, verts, a, b):
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
def circle_contact(s, p, c, sn, cx, cy, radius):
    """Body rectangle (heading cosine ``c``, sine ``sn``) against a circle; the result as :func:`piece_contact`'s."""
    rx, ry = cx - s[X], cy - s[Y]
    bx, by = c * rx + sn * ry, -sn * rx + c * ry  # circle centre in the body frame
    f, r, w = p[P_FRONT], -p[P_REAR], p[P_HALF_W]
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
    return (depth, c * nbx - sn * nby, sn * nbx + c * nby,
            s[X] + c * qx - sn * qy, s[Y] + sn * qx + c * qy)


@njit(cache=True, refcounts=False)
def deepest_near(s, p, corners, verts, pstart, pbound, circles, reach, near):
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
        if not might_be_near(s[X], s[Y], verts, pstart[k], pstart[k + 1], pbound, k, reach):
            continue
        if not ready:
            c, sn, ready = math.cos(s[TH]), math.sin(s[TH]), True
            body_corners_at(s, p, c, sn, corners)
        hit = piece_contact(c, sn, corners, verts, pstart[k], pstart[k + 1])
        if hit[0] > best[0]:
            best = hit
    for j in range(near[1]):
        k = near[2 + n + j]
        if not within(circles[k, 0] - s[X], circles[k, 1] - s[Y], circles[k, 2] + reach):
            continue
        if not ready:
            c, sn, ready = math.cos(s[TH]), math.sin(s[TH]), True
            body_corners_at(s, p, c, sn, corners)
        hit = circle_contact(s, p, c, sn, circles[k, 0], circles[k, 1], circles[k, 2])
        if hit[0] > best[0]:
            best = hit
    return best, c, sn


@njit(cache=True)
def deepest_contact(s, p, corners, verts, pstart, pbound, circles):
    """The deepest overlap of the body with any piece or circle (bounding circles prune the rest)."""
    near, centre = new_near(pstart, circles)
    reach, wide = reaches(p)
    refresh_near(s[X], s[Y], wide, verts, pstart, pbound, circles, near, centre)
    return deepest_near(s, p, corners, verts, pstart, pbound, circles, reach, near)[0]


@njit(cache=True, refcounts=False, inline="always")
def resolve(s, p, corners, verts, pstart, pbound, circles, reach, wide, near, centre):
    """Push the body out of whatever it overlaps (position-based: the push splits into shift and turn);
    returns whether it moved the robot. ``reach``/``wide``: :func:`reaches`; ``near``/``centre``: the
    robot's candidate list (:func:`refresh_near`).

    A corner touching first turns the robot about it, as a real robot pushing one bumper corner
    against a wall swings square to it; the touching point is clamped to the body.
    """
    s[CONTACT] = 0.0
    moved = False
    for _ in range(RESOLVE_ITERATIONS):
        refresh_near(s[X], s[Y], wide, verts, pstart, pbound, circles, near, centre)
        if near[0] == 0 and near[1] == 0:  # in the open nothing can overlap the body (most ticks)
            return moved
        hit, c, sn = deepest_near(s, p, corners, verts, pstart, pbound, circles, reach, near)
        depth, dx, dy, px, py = hit
        if depth <= 0.0:
            return moved
        s[CONTACT] = 1.0
        moved = True
        rx, ry = px - s[X], py - s[Y]
        bx = min(p[P_FRONT], max(-p[P_REAR], c * rx + sn * ry))
        by = min(p[P_HALF_W], max(-p[P_HALF_W], -sn * rx + c * ry))
        rx, ry = c * bx - sn * by, sn * bx + c * by
        arm = rx * dy - ry * dx  # turning leverage of the push about the axle centre
        weight = 1.0 + arm * arm / p[P_GYR2]
        s[X] += dx * depth / weight
        s[Y] += dy * depth / weight
        s[TH] += arm / p[P_GYR2] * depth / weight
    return moved


# --- sensing -------------------------------------------------------------------------------------


@njit(cache=True, refcounts=False)
def near_plate(s, c, sn, gap, x0, y0, x1, y1, verts, pstart, near, circles, near_circles):
    """Whether anything lies within the switch travel ``gap`` of a bumper plate given in the body frame
    (``c``, ``sn``: the heading's cosine and sine; ``near``/``near_circles``: bits of the pieces and
    circles the broad phase kept, the 63rd bit standing for every piece from the 63rd on)."""
    ax, ay = s[X] + c * x0 - sn * y0, s[Y] + sn * x0 + c * y0
    bx, by = s[X] + c * x1 - sn * y1, s[Y] + sn * x1 + c * y1
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
                circles[k, 0], circles[k, 1], ax, ay, bx, by, circles[k, 2] + gap):
            return True
    return False


@njit(cache=True, refcounts=False, inline="always")
def broad_phase(s, reach, verts, pstart, pbound, circles, near):
    """Bits of the pieces and of the circles of candidate list ``near`` that may lie within ``reach`` of the
    robot's centre (exact: what it rules out is farther); pieces and circles from the 63rd on share bit 62
    and are kept. The same bits as a scan of every piece, since the list leaves out only far ones."""
    bits = np.int64(0)
    n = near[0]
    for j in range(n):
        k = near[2 + j]
        if k >= 62 or might_be_near(s[X], s[Y], verts, pstart[k], pstart[k + 1], pbound, k, reach):
            bits |= np.int64(1) << min(k, 62)
    bits_circles = np.int64(0)
    for j in range(near[1]):
        k = near[2 + n + j]
        if k >= 62 or within(circles[k, 0] - s[X], circles[k, 1] - s[Y], circles[k, 2] + reach + 1e-6):
            bits_circles |= np.int64(1) << min(k, 62)
    return bits, bits_circles


@njit(cache=True, refcounts=False, inline="always")
def sense_bumpers(s, p, c, sn, verts, pstart, pbound, circles, reach, wide, near, centre):
    """Front-right, front-left (each a half plate wrapping round its corner; they overlap in the middle) and
    rear; ``c``/``sn``: the heading's cosine and sine; the rest as :func:`resolve`'s."""
    f, r, w, ov, wrap, gap = p[P_FRONT], -p[P_REAR], p[P_HALF_W], p[P_OVERLAP], p[P_WRAP], p[P_GAP]
    refresh_near(s[X], s[Y], wide, verts, pstart, pbound, circles, near, centre)
    near_p, near_c = broad_phase(s, reach + gap, verts, pstart, pbound, circles, near)
    fr = fl = rear = False
    if near_p or near_c:  # in the open (most ticks) no plate can touch anything
        fr = (near_plate(s, c, sn, gap, f, -w, f, ov, verts, pstart, near_p, circles, near_c)
              or near_plate(s, c, sn, gap, f - wrap, -w, f, -w, verts, pstart, near_p, circles, near_c))
        fl = (near_plate(s, c, sn, gap, f, -ov, f, w, verts, pstart, near_p, circles, near_c)
              or near_plate(s, c, sn, gap, f - wrap, w, f, w, verts, pstart, near_p, circles, near_c))
        rear = near_plate(s, c, sn, gap, r, -w, r, w, verts, pstart, near_p, circles, near_c)
    s[BUMP_FR], s[BUMP_FL], s[BUMP_REAR] = (1.0 if fr else 0.0), (1.0 if fl else 0.0), (1.0 if rear else 0.0)


@njit(cache=True, refcounts=False, inline="always")
def light_side(s, c, sn, p, side, ct, st, edges, circles, lamps, shade):
    """Light the right (side -1) or left (+1) phototransistor of the BumberBot's wiring receives (``c``,
    ``sn``: the heading's cosine and sine; ``ct``, ``st``: those of its turn, :func:`aim_turns`; ``shade``:
    the world's shadow grid). Most ticks no lamp is in its field of view, or it is in shadow:
    :func:`sim.sensing.light_turned` rules such lamps out cheaply, with light_from's answer."""
    return light_turned(s, c, sn, p, p[P_LX], side * p[P_LY], side * p[P_TOE], ct, st, edges, circles, lamps, shade)


@njit(cache=True, refcounts=False, inline="always")
def aim_turns(p, out):
    """``out``: cosine and sine of the right phototransistor's turn from the heading, then the left one's."""
    out[0], out[1] = math.cos(-1.0 * p[P_TOE]), math.sin(-1.0 * p[P_TOE])
    out[2], out[3] = math.cos(1.0 * p[P_TOE]), math.sin(1.0 * p[P_TOE])


@njit(cache=True)
def light_at(s, p, side, edges, circles, lamps, shade=NO_SHADE):
    """Light the right (side -1) or left (+1) phototransistor of the BumberBot's wiring receives."""
    turns = np.empty(4)
    aim_turns(p, turns)
    k = 0 if side < 0.0 else 2
    return light_side(s, math.cos(s[TH]), math.sin(s[TH]), p, side, turns[k], turns[k + 1], edges, circles, lamps,
                      shade)


# --- motors, battery, motion ---------------------------------------------------------------------


@njit(cache=True, refcounts=False, inline="always")
def duty(level, levels):
    """The fraction of full power a speed level gives (the table's 1..8 are PWM duty level/8)."""
    return min(1.0, abs(level) / levels)


@njit(cache=True, refcounts=False, inline="always")
def pack_volts(full, empty, charge, amps, ohms):
    """Battery terminal volts: open-circuit volts fall linearly with the charge and sag with the current."""
    return empty + (full - empty) * charge - amps * ohms


@njit(cache=True, refcounts=False, inline="always")
def motor(s, p, level, volts, gain, speed, enc, pul, noise):
    """One motor: target speed ∝ duty × battery volts - friction volts, reached with a first-order lag.

    The encoder counts the motor's own turns (a wheel slipping against a wall still counts).
    """
    power = duty(level, p[P_LEVELS])
    target = np.sign(level) * s[gain] * p[P_KV] * max(0.0, power * volts - p[P_VF]) * (1.0 + p[P_NMOTOR] * noise)
    s[speed] += (target - s[speed]) * p[P_ALPHA]
    before = s[enc]
    s[enc] += abs(s[speed]) * p[P_DT] / (2.0 * math.pi * p[P_WHEEL_R]) * p[P_PPR]
    s[pul] = math.floor(s[enc]) - math.floor(before)


@njit(cache=True, refcounts=False, inline="always")
def drive(s, cmd, p, z):
    """One tick of battery (open-circuit volts fall with charge, sag with current), motors and wheels."""
    dt = p[P_DT]
    amps = p[P_IIDLE] + p[P_IMOTOR] * (duty(cmd[0], p[P_LEVELS]) + duty(cmd[1], p[P_LEVELS]))
    volts = pack_volts(p[P_VFULL], p[P_VEMPTY], s[SOC], amps, p[P_RINT])
    s[AMPS], s[VBAT] = amps, volts
    s[SOC] = max(0.0, s[SOC] - amps * dt / p[P_CAP])
    motor(s, p, cmd[0], volts, GAIN_R, V_R, ENC_R, PUL_R, z[Z_MOTOR_R])
    motor(s, p, cmd[1], volts, GAIN_L, V_L, ENC_L, PUL_L, z[Z_MOTOR_L])
    turn = (s[V_R] - s[V_L]) / p[P_BASE] * dt
    ahead = 0.5 * (s[V_R] + s[V_L]) * dt
    mid = s[TH] + 0.5 * turn  # midpoint heading: exact for straight runs and spins, close on arcs
    s[X] += ahead * math.cos(mid)
    s[Y] += ahead * math.sin(mid)
    s[TH] += turn


@njit(cache=True, refcounts=False, inline="always")
def input_mask(s, bits):
    """The engine's input bits from the switch states and the light readings (1 = above threshold)."""
    mask = 0
    if s[BUMP_FR] > 0.0:
        mask |= bits[B_FR]
    if s[BUMP_FL] > 0.0:
        mask |= bits[B_FL]
    if s[BUMP_REAR] > 0.0:
        mask |= bits[B_REAR]
    if s[LIGHT_R] >= 1.0:
        mask |= bits[B_LIGHT_R]
    if s[LIGHT_L] >= 1.0:
        mask |= bits[B_LIGHT_L]
    return mask


@njit(cache=True, refcounts=False, inline="always")
def sense_near(s, p, z, verts, pstart, pbound, edges, circles, lamps, lines, shade, bits, reach, wide, near, centre,
               turns):
    """Everything one robot senses where it stands: bumpers, phototransistors, the sensors its robot file
    declares (sim.sensing), and the input mask they make (hysteresis reads the previous mask). The heading's
    cosine and sine are worked out once for all of them."""
    c, sn = math.cos(s[TH]), math.sin(s[TH])
    sense_bumpers(s, p, c, sn, verts, pstart, pbound, circles, reach, wide, near, centre)
    right = light_side(s, c, sn, p, -1.0, turns[0], turns[1], edges, circles, lamps, shade)
    s[LIGHT_R] = max(0.0, right * (1.0 + p[P_NLIGHT] * z[Z_LIGHT_R]))
    left = light_side(s, c, sn, p, 1.0, turns[2], turns[3], edges, circles, lamps, shade)
    s[LIGHT_L] = max(0.0, left * (1.0 + p[P_NLIGHT] * z[Z_LIGHT_L]))
    if p[P_SENSOR + F_KIND] != 0.0:  # declared sensors fill the slots from the first: none declared, no pass
        sense_declared(s, c, sn, p, edges, circles, lamps, lines, shade)
    previous = int(s[MASK])
    s[MASK] = input_mask(s, bits) | sensor_events(s, p, bits, previous)


@njit(cache=True, refcounts=False, inline="always")
def advance(s, right, left, p, verts, pstart, pbound, edges, circles, lamps, lines, shade, z, bits, move, corners,
            reach, wide, near, centre, turns):
    """One robot, one tick: drive with motor levels ``right``/``left`` (when ``move``), resolve contacts,
    sense; fills the robot's MASK column. ``corners`` is scratch space of shape (4, 2); ``reach``, ``wide``:
    :func:`reaches`; ``near`` and ``centre`` the robot's candidate list (:func:`new_near`), kept from tick to tick;
    ``turns``: :func:`aim_turns`."""
    if move:
        x0, y0 = s[X], s[Y]
        cmd = (right, left)
        drive(s, cmd, p, z)
        resolve(s, p, corners, verts, pstart, pbound, circles, reach, wide, near, centre)
        s[DIST] += math.hypot(s[X] - x0, s[Y] - y0)
    sense_near(s, p, z, verts, pstart, pbound, edges, circles, lamps, lines, shade, bits, reach, wide, near, centre,
               turns)


@njit(cache=True, refcounts=False)
def advance_called(s, right, left, p, verts, pstart, pbound, edges, circles, lamps, lines, shade, z, bits, move,
                   corners, reach, wide, near, centre, turns):
    """:func:`advance` compiled once as a function of its own, for sim.kernel.move and sense: the tick-by-tick
    robot, a fleet's first readings and the Gymnasium env's physics-only loop (fleet.kernel.move_serial),
    where a call per robot-tick costs little beside the rest of a controller's step, and each inlined copy
    took numba ~20 s to compile. The loops that run the table too (run_robot) inline :func:`advance` itself."""
    advance(s, right, left, p, verts, pstart, pbound, edges, circles, lamps, lines, shade, z, bits, move, corners,
            reach, wide, near, centre, turns)
