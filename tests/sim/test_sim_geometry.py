"""The simulator's shortcuts in its geometry give the plain tests' answers exactly: sim.physics.geometry.segments_within
refuses segments clear of each other's line before its four distances, and sim.physics.shadows tests only the pieces
its grid lists: both must agree with the plain tests always."""

from __future__ import annotations

import numpy as np

from tablebot.jit import njit
from tablebot.sim.physics.geometry import point_segment_within, segments_cross, segments_within, shadowed
from tablebot.sim.physics.shadows import shadowed_near


@njit
def plain(ax: float, ay: float, bx: float, by: float, cx: float, cy: float, dx: float, dy: float, r: float) -> bool:
    """segments_within as it was: the crossing test, then the four endpoint-to-segment distances."""
    if segments_cross(ax, ay, bx, by, cx, cy, dx, dy):
        return r >= 0.0
    return (
        point_segment_within(ax, ay, cx, cy, dx, dy, r)
        or point_segment_within(bx, by, cx, cy, dx, dy, r)
        or point_segment_within(cx, cy, ax, ay, bx, by, r)
        or point_segment_within(dx, dy, ax, ay, bx, by, r)
    )


@njit
def disagreements(cases: np.ndarray) -> tuple[int, int]:
    bad, near = 0, 0
    for k in range(cases.shape[0]):
        ax, ay, bx, by, cx, cy, dx, dy, r = cases[k]
        answer = segments_within(ax, ay, bx, by, cx, cy, dx, dy, r)
        bad += answer != plain(ax, ay, bx, by, cx, cy, dx, dy, r)
        near += answer
    return bad, near


def test_segments_within_agrees_with_the_plain_test_on_the_threshold_and_on_the_line() -> None:
    rng = np.random.default_rng(11)
    n = 60_000
    cd = rng.uniform(0.0, 3.0, (n, 4))
    r = rng.choice([0.001, 0.0, 0.05], n)
    # ab: a segment at a chosen distance from the line through cd (exactly r, r ± a hair, or anything), at any
    # slant, sometimes on the line itself beyond its ends
    t0, t1 = rng.uniform(-1.5, 2.5, n), rng.uniform(-1.5, 2.5, n)
    ex, ey = cd[:, 2] - cd[:, 0], cd[:, 3] - cd[:, 1]
    length = np.hypot(ex, ey)
    nx, ny = -ey / length, ex / length
    off = r[:, None] + rng.choice([0.0, 1e-15, -1e-15, 1e-10, -1e-10, 1e-3], (n, 2))
    off = np.where(rng.random((n, 1)) < 0.2, rng.uniform(-0.5, 0.5, (n, 2)), off * rng.choice([-1.0, 1.0], (n, 1)))
    off[rng.random(n) < 0.1] = 0.0
    ax, ay = cd[:, 0] + t0 * ex + off[:, 0] * nx, cd[:, 1] + t0 * ey + off[:, 0] * ny
    bx, by = cd[:, 0] + t1 * ex + off[:, 1] * nx, cd[:, 1] + t1 * ey + off[:, 1] * ny
    cases = np.column_stack([ax, ay, bx, by, cd, r])
    bad, near = disagreements(cases)
    assert bad == 0
    assert n // 10 < near < n - n // 10  # both answers were asked for


@njit
def shadow_disagreements(
    points: np.ndarray, lamps: np.ndarray, edges: np.ndarray, circles: np.ndarray, shade: np.ndarray
) -> tuple[int, int]:
    bad, dark = 0, 0
    for k in range(lamps.shape[0]):
        for j in range(points.shape[0]):
            x, y = points[j, 0], points[j, 1]
            answer = shadowed(x, y, lamps[k, 0], lamps[k, 1], k, edges, circles)
            bad += answer != shadowed_near(x, y, lamps[k, 0], lamps[k, 1], k, edges, circles, shade)
            dark += answer
    return bad, dark


def test_the_shadow_grid_gives_every_shadow_test_the_full_scans_answer() -> None:
    """physics.shadows lists per cell only the pieces that may shadow each lamp: its answer must be the scan of every
    piece, also on the lines through a lamp and a corner, on an edge's own line, just off both, and beyond
    the grid -- in a world with two lamps (one in line with a box's side, one with no base), a hanging
    circle and a partition."""
    from tablebot.sim.model.world import geometry, parse_world
    from tablebot.tomlfile import Source

    world = parse_world(
        Source.parse(
            "<w>",
            """
[arena]
walls = [[0, 0], [3, 0], [3, 2], [1.5, 2.6], [0, 2]]
[start]
at = [0.3, 0.3]
[[lamp]]
at = [2.5, 0.5]
[[lamp]]
at = [1.0, 1.2]
radius = 0
[[box]]
at = [2.0, 1.0]
size = [0.4, 0.4]
[[box]]
at = [1.0, 0.6]
size = [0.3, 0.2]
angle = 20
[[circle]]
at = [0.6, 1.6]
radius = 0.15
[[segment]]
from = [1.5, 2.6]
to = [1.5, 1.9]
""",
        )
    )
    g = geometry(world)
    assert g.shade.shape[0] > 0
    rng = np.random.default_rng(11)
    points = [rng.uniform(-0.3, 3.3, size=(20_000, 2))]
    ends = np.concatenate([g.edges[:, :2], g.edges[:, 2:], g.circles[:, :2]])
    for lamp in g.lamps[:, :2]:  # on the lines from each lamp through each corner (and a hair off them)
        t = rng.uniform(-1.5, 2.5, size=(ends.shape[0], 300, 1))
        line = lamp + t * (ends[:, None, :] - lamp)
        points += [line.reshape(-1, 2), line.reshape(-1, 2) + rng.choice([-1e-12, 1e-12, 1e-9], size=(1, 2))]
    for e in g.edges:  # on each edge's own line
        t = rng.uniform(-1.0, 2.0, size=(300, 1))
        points.append(e[:2] + t * (e[2:] - e[:2]))
    bad, dark = shadow_disagreements(np.concatenate(points), g.lamps, g.edges, g.circles, g.shade)
    assert bad == 0
    assert dark > 10_000  # shadows were cast (the boxes, the circle, the partition, the walls' corner)
