"""Simulated sensors: bumpers on contact (and the BumberBot's reaction), light seen and shadowed."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from tablebot.sim import columns as L
from tablebot.sim.runner import simulate
from test_sim_helpers import BUMBERBOT, STRAIGHT, bot, room, scene_of, write_bot

if TYPE_CHECKING:
    from tablebot.sim.model.scene import Scene

STILL = ["wait,1,1,,,,,,0,0,100,1"]
LAMP = "[[lamp]]\nat = [{x}, {y}]\nintensity = 2.0\n"


def bumberbot_in(tmp_path: Path, world: str) -> Scene:
    (tmp_path / "world.toml").write_text(world, encoding="utf-8")
    return scene_of(BUMBERBOT / "table.csv", tmp_path / "world.toml")


def first_tick(column_values: np.ndarray) -> int:
    hits = np.flatnonzero(column_values > 0)
    assert len(hits), "never happened"
    return int(hits[0])


def test_head_on_contact_closes_both_front_switches(tmp_path: Path) -> None:
    scene = bot(tmp_path, STRAIGHT, room(start=(2.6, 1.5, 0), noise=True))
    h = simulate(scene, 6.0, seed=5).kept_rows()
    right, left = first_tick(h[:, L.BUMP_FR]), first_tick(h[:, L.BUMP_FL])
    assert abs(right - left) <= 5  # within the document's 50 ms wait
    assert h[-1, L.BUMP_REAR] == 0


def test_a_side_hit_closes_only_that_side(tmp_path: Path) -> None:
    scene = bot(tmp_path, STRAIGHT, room(start=(2.7, 1.5, 30)))
    h = simulate(scene, 3.0).kept_rows()  # the right front corner meets the wall first
    closed = np.flatnonzero(h[:, L.BUMP_FR] + h[:, L.BUMP_FL] > 0)
    assert h[closed[0], L.BUMP_FR] == 1 and h[closed[0], L.BUMP_FL] == 0


def test_the_rear_switch_closes_when_backing_into_a_wall(tmp_path: Path) -> None:
    scene = bot(tmp_path, ["back,1,1,,,,,,-4,-4,500,1"], room(start=(0.3, 1.5, 0)))
    h = simulate(scene, 4.0).kept_rows()
    assert h[-1, L.BUMP_REAR] == 1 and h[-1, L.BUMP_FR] == h[-1, L.BUMP_FL] == 0
    assert abs(h[-1, L.X] - scene.params["body"]["rear"]) < 1e-6


def test_bumberbot_hitting_a_wall_goes_to_state_20_then_21(tmp_path: Path) -> None:
    scene = bumberbot_in(tmp_path, room(start=(2.6, 1.5, 0), noise=True))
    result = simulate(scene, 6.0)
    states = [scene.machine.states[s] for s in result.states.tolist()]
    bumps = (result.masks & (scene.machine.input_bits["I3"] | scene.machine.input_bits["I4"])) != 0
    hit = int(np.flatnonzero(bumps)[0])
    assert states[hit] == 20
    assert states[hit:].index(21) == 50  # after the 50-tick wait
    assert 22 in states[hit:]  # a head-on hit: "Collision Frontal" backs off


def test_a_lamp_in_front_is_seen(tmp_path: Path) -> None:
    scene = bot(tmp_path, STILL, room(start=(1.0, 1.5, 0), extra=LAMP.format(x=1.9, y=1.5)))
    h = simulate(scene, 0.1).kept_rows()
    assert h[0, L.LIGHT_R] > 1 and h[0, L.LIGHT_L] > 1
    bits = scene.bits[L.B_LIGHT_R] | scene.bits[L.B_LIGHT_L]
    assert int(h[0, L.MASK]) & bits == bits


def test_a_lamp_to_one_side_is_seen_by_that_side_only(tmp_path: Path) -> None:
    scene = bot(tmp_path, STILL, room(start=(1.0, 1.5, 0), extra=LAMP.format(x=1.8, y=1.1)))
    h = simulate(scene, 0.1).kept_rows()  # 27° to the right
    assert h[0, L.LIGHT_R] >= 1 > h[0, L.LIGHT_L]


def test_a_lamp_behind_the_robot_is_not_seen(tmp_path: Path) -> None:
    scene = bot(tmp_path, STILL, room(start=(1.0, 1.5, 180), extra=LAMP.format(x=1.9, y=1.5)))
    h = simulate(scene, 0.1).kept_rows()
    assert h[0, L.LIGHT_R] == h[0, L.LIGHT_L] == 0


def test_a_lamp_behind_a_wall_is_not_seen(tmp_path: Path) -> None:
    wall = "[[segment]]\nfrom = [1.5, 1.0]\nto = [1.5, 2.0]\n"
    scene = bot(tmp_path, STILL, room(start=(1.0, 1.5, 0), extra=LAMP.format(x=1.9, y=1.5) + wall))
    h = simulate(scene, 0.1).kept_rows()
    assert h[0, L.LIGHT_R] == h[0, L.LIGHT_L] == 0
    boxed = "[[box]]\nat = [1.5, 1.5]\nsize = [0.1, 0.6]\n"
    scene = bot(tmp_path, STILL, room(start=(1.0, 1.5, 0), extra=LAMP.format(x=1.9, y=1.5) + boxed))
    assert simulate(scene, 0.1).kept_rows()[0, L.LIGHT_L] == 0


def test_light_falls_with_distance_squared(tmp_path: Path) -> None:
    readings = []
    sensor, aim = np.array([1.11, 1.47]), np.radians(-10)  # the right phototransistor and its axis
    for d in (0.5, 1.0):
        x, y = sensor + d * np.array([np.cos(aim), np.sin(aim)])
        table, world = write_bot(tmp_path, STILL, room(start=(1.0, 1.5, 0), extra=LAMP.format(x=x, y=y)))
        readings.append(simulate(scene_of(table, world), 0.1).kept_rows()[0, L.LIGHT_R])
    assert abs(readings[0] - 2.0 / 0.5**2) < 1e-9  # intensity 2 straight on at 0.5 m
    assert abs(readings[0] / readings[1] - 4.0) < 1e-9


def test_the_quick_out_of_view_test_never_hides_a_lamp_light_from_sees(tmp_path: Path) -> None:
    """physics.light_side (sensing.light_turned) first rules out lamps surely out of view (no cos/sin of the aim,
    no hypot) or in shadow: its answer must be exactly light_from's, also for lamps a hair
    inside or outside the field of view's edge and for headings after thousands of turns."""
    import math

    from tablebot.sim.physics.layout import as_params, as_state
    from tablebot.sim.physics.sensing import light_from
    from tablebot.sim.physics.step import light_at

    scene = bumberbot_in(tmp_path, room(extra="[[lamp]]\nat = [2.0, 1.5]\nintensity = 3.0\n"))
    p, g = scene.P[0], scene.geometry
    fov = math.acos(p[L.P_COS_FOV])
    rng = np.random.default_rng(3)
    s, hidden = np.zeros(L.N_STATE), 0
    for k in range(6000):
        side = -1.0 if k % 2 else 1.0
        s[L.X], s[L.Y] = rng.uniform(0.3, 2.7), rng.uniform(0.3, 2.7)
        turns = rng.integers(-2000, 2000) * 2 * math.pi
        # aim at the lamp, then off by the field of view plus or minus a hair (or anything)
        sx, sy = s[L.X] + p[L.P_LX], s[L.Y] + side * p[L.P_LY]
        towards = math.atan2(1.5 - sy, 2.0 - sx) - side * p[L.P_TOE]
        off = fov * rng.choice([-1.0, 1.0]) + rng.choice([0.0, 1e-13, -1e-13, 1e-9, -1e-9, rng.uniform(-3, 3)])
        s[L.TH] = towards + off + turns
        c, sn = math.cos(s[L.TH]), math.sin(s[L.TH])
        row, params = as_state(s), as_params(p)  # the physics reads rows' fields by name
        exact = light_from(
            row, c, sn, params, p[L.P_LX], side * p[L.P_LY], side * p[L.P_TOE], g.edges, g.circles, g.lamps
        )
        assert light_at(s, p, side, g.edges, g.circles, g.lamps) == exact
        assert light_at(s, p, side, g.edges, g.circles, g.lamps, g.shade) == exact  # the shadow grid
        hidden += exact == 0.0
    assert 1000 < hidden < 5000  # both sides of the edge were tried
