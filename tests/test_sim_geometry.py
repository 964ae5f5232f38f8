"""The simulator's shortcuts in its geometry give the plain tests' answers exactly: sim.geometry.segments_within
refuses segments clear of each other's line before its four distances, and must agree with them always."""

from __future__ import annotations

import numpy as np

from tablebot.jit import njit
from tablebot.sim.geometry import point_segment_within, segments_cross, segments_within


@njit
def plain(ax, ay, bx, by, cx, cy, dx, dy, r):  # type: ignore[no-untyped-def]
    """segments_within as it was: the crossing test, then the four endpoint-to-segment distances."""
    if segments_cross(ax, ay, bx, by, cx, cy, dx, dy):
        return r >= 0.0
    return (point_segment_within(ax, ay, cx, cy, dx, dy, r) or point_segment_within(bx, by, cx, cy, dx, dy, r)
            or point_segment_within(cx, cy, ax, ay, bx, by, r) or point_segment_within(dx, dy, ax, ay, bx, by, r))


@njit
def disagreements(cases):  # type: ignore[no-untyped-def]
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
