"""Which walls, obstacle edges and circles may shadow each lamp from each cell of a grid over the world: made
once per world (numpy), so a light sensor tests only those (compiled), with the answer of testing them all.
"""

# A shadow test (geometry.shadowed) asks whether any edge or circle blocks the line from a sensor to a lamp:
# an OR over every piece, so it may test them in any order and skip any piece that surely does not block.
# "Surely" means: whatever the rounding, geometry.shadowed's own floating-point test of that piece says no.
# For an edge cd and a line from s to lamp L, segments_cross says no when both of its orientation pairs
# share a sign, and a pair surely does when both of its values exceed, in size, every rounding error:
#   (A) s and L on one side of the line through cd:   cross(d - c, s - c) and cross(d - c, L - c);
#   (B) c and d on one side of the line through s, L: cross(L - s, c - L) and cross(L - s, d - L)
# (cross(L - s, c - s) is the same number in exact arithmetic: the orientation segments_cross works out).
# Both are affine in s, so over a grid cell (a rectangle) their extremes lie at its corners. A circle is
# skipped when it lies farther than its radius from the line through s and L, or from the box around the
# cell and the lamp (which holds every segment from the cell to the lamp). The margins (TOLERANCE, EDGE)
# are a billionth and a millionth of the world's size: the rounding of these numbers is a million times less.

from __future__ import annotations

import math

import numpy as np

from tablebot.jit import njit
from tablebot.sim.physics.geometry import point_segment_within, segments_cross, shadowed

CELLS = 48  # cells along the world's longer side (a 2.4 m arena: 5 cm cells)
HEADER = 5  # shade[0:5] = x0, y0, cells per metre, columns, rows; then per lamp and cell where its list starts
EDGE = 1e-6  # metres per metre of world size: how far beyond its cell a sensor may be said to lie (rounding)
TOLERANCE = 1e-9  # square metres per square metre of world size: the margin of an orientation's sign
NO_SHADE = np.zeros(0)  # no grid: every piece is tested


def shade_grid(edges: np.ndarray, circles: np.ndarray, lamps: np.ndarray) -> np.ndarray:
    """The grid as one float64 array (``HEADER`` fields, then per lamp and cell where its list starts in the
    items, one more for the end, then the items: an edge index, or the number of edges plus a circle index);
    empty when the world has no lamps or nothing to cast a shadow."""
    if not lamps.shape[0] or not edges.shape[0] + circles.shape[0]:
        return NO_SHADE
    points = np.concatenate(
        [edges[:, :2], edges[:, 2:], circles[:, :2] - circles[:, 2:3], circles[:, :2] + circles[:, 2:3], lamps[:, :2]]
    )
    low, high = points.min(axis=0), points.max(axis=0)
    size = max(1.0, float(np.abs(points).max()), float((high - low).max()))
    scale = CELLS / max(float((high - low).max()), 1e-3)  # cells per metre
    nx, ny = (max(1, math.ceil(float(w) * scale)) for w in high - low)
    margin, tolerance = EDGE * size, TOLERANCE * size * size
    i, j = np.meshgrid(np.arange(nx), np.arange(ny))  # cell j * nx + i
    x0, y0 = i.ravel() / scale + low[0] - margin, j.ravel() / scale + low[1] - margin
    x1, y1 = (i.ravel() + 1) / scale + low[0] + margin, (j.ravel() + 1) / scale + low[1] + margin
    corners = np.stack(
        [np.stack([x0, y0], 1), np.stack([x1, y0], 1), np.stack([x1, y1], 1), np.stack([x0, y1], 1)], 1
    )  # (cells, 4, 2)
    counts: list = []
    items: list = []
    for k, lamp in enumerate(lamps[:, :2]):
        keep = [_edge_may_block(corners, lamp, e, tolerance) for e in edges]
        keep += [
            _circle_may_block(corners, lamp, c, margin, tolerance)
            if int(c[3]) != k  # never its own base
            else np.zeros(nx * ny, bool)
            for c in circles
        ]
        table = np.stack(keep, 1)  # (cells, pieces)
        counts.append(table.sum(1))
        items.append(np.nonzero(table)[1])  # row by row: each cell's pieces in index order
    starts = HEADER + 1 + lamps.shape[0] * nx * ny + np.concatenate([[0], np.cumsum(np.concatenate(counts))])
    return np.concatenate([[low[0], low[1], scale, nx, ny], starts, *items]).astype(np.float64)


def _cross(ax: np.ndarray, ay: np.ndarray, bx: np.ndarray, by: np.ndarray) -> np.ndarray:
    return ax * by - ay * bx


def _edge_may_block(corners: np.ndarray, lamp: np.ndarray, edge: np.ndarray, tolerance: float) -> np.ndarray:
    """Per cell: False when neither (A) nor (B) of the module's comment can fail for a sensor in it."""
    cx, cy, dx, dy = edge
    px, py = corners[..., 0], corners[..., 1]
    side_lamp = _cross(dx - cx, dy - cy, lamp[0] - cx, lamp[1] - cy)
    side = _cross(dx - cx, dy - cy, px - cx, py - cy) * np.sign(side_lamp)
    apart = (abs(side_lamp) > tolerance) & (side > tolerance).all(1)  # (A)
    fc = _cross(lamp[0] - px, lamp[1] - py, cx - lamp[0], cy - lamp[1])
    fd = _cross(lamp[0] - px, lamp[1] - py, dx - lamp[0], dy - lamp[1])
    beside = (((fc > tolerance) & (fd > tolerance)).all(1)) | (((fc < -tolerance) & (fd < -tolerance)).all(1))  # (B)
    return ~(apart | beside)


def _circle_may_block(
    corners: np.ndarray, lamp: np.ndarray, circle: np.ndarray, margin: float, tolerance: float
) -> np.ndarray:
    """Per cell: False when the circle is surely farther than its radius from every segment cell -> lamp."""
    cx, cy, r = circle[0], circle[1], circle[2] + margin
    px, py = corners[..., 0], corners[..., 1]
    lo_x, hi_x = np.minimum(px.min(1), lamp[0]), np.maximum(px.max(1), lamp[0])
    lo_y, hi_y = np.minimum(py.min(1), lamp[1]), np.maximum(py.max(1), lamp[1])
    gap = np.hypot(np.maximum(0.0, np.maximum(lo_x - cx, cx - hi_x)), np.maximum(0.0, np.maximum(lo_y - cy, cy - hi_y)))
    far_box = gap > r
    f = _cross(lamp[0] - px, lamp[1] - py, cx - lamp[0], cy - lamp[1])  # |f| = distance to line s-L times |L - s|
    reach = r * np.hypot(lamp[0] - px, lamp[1] - py).max(1) + tolerance
    far_line = (f > reach[:, None]).all(1) | (f < -reach[:, None]).all(1)
    return ~(far_box | far_line)


@njit(cache=True, refcounts=False)
def shadowed_near(
    sx: float, sy: float, lx: float, ly: float, lamp: int, edges: np.ndarray, circles: np.ndarray, shade: np.ndarray
) -> bool:
    """:func:`tablebot.sim.physics.geometry.shadowed`'s answer, testing only the pieces the grid ``shade`` lists for
    the sensor's cell (every piece when there is no grid or the sensor is outside it)."""
    if shade.shape[0] == 0:
        return shadowed(sx, sy, lx, ly, lamp, edges, circles)
    fx, fy = (sx - shade[0]) * shade[2], (sy - shade[1]) * shade[2]
    nx, ny = shade[3], shade[4]
    if not (fx >= 0.0 and fy >= 0.0 and fx < nx and fy < ny):  # outside (or NaN): test everything
        return shadowed(sx, sy, lx, ly, lamp, edges, circles)
    cell = HEADER + lamp * int(nx) * int(ny) + int(fy) * int(nx) + int(fx)
    n_edges = edges.shape[0]
    for j in range(int(shade[cell]), int(shade[cell + 1])):
        k = int(shade[j])
        if k < n_edges:
            if segments_cross(sx, sy, lx, ly, edges[k, 0], edges[k, 1], edges[k, 2], edges[k, 3]):
                return True
        elif point_segment_within(
            circles[k - n_edges, 0], circles[k - n_edges, 1], sx, sy, lx, ly, circles[k - n_edges, 2], True
        ):
            return True
    return False
