"""Declared sensors ([sensors] in the robot file): floor line sensors, the ultrasonic distance sensor's
ray cast, light sensors anywhere on the body, and threshold events with hysteresis."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from tablebot.sim import columns as L
from tablebot.sim.model.scene import Scene
from tablebot.sim.physics.kernel import sense
from tablebot.sim.physics.layout import as_params, as_state
from tablebot.sim.physics.sensing import sensor_events
from tablebot.sim.physics.step import light_at
from tablebot.sim.runner import simulate
from tablebot.sim.simrobot import world_arrays
from test_sim_helpers import room, scene_of

SENSORS = """\
name = "SensorBot"
initial_state = 1
[inputs]
I1 = "left floor"
I2 = "right floor"
I3 = "wall ahead"
I4 = "light"
[motors]
M1 = "right motor"
M2 = "left motor"
[sensors]
I1 = { sensor = "line", at = [0.1, 0.01] }
I2 = { sensor = "line", at = [0.1, -0.01] }
I3 = { sensor = "distance", below = "20 cm", hysteresis = "5 cm", at = [0.12, 0] }
I4 = { sensor = "phototransistor", above = 1.0, at = [0.11, -0.03], angle = -10 }
"""
#: Forward at speed 3 until the wall is near (I3), then back at speed 3 until it is not, and again.
TABLE = """description,state,T,I1,I2,I3,I4,M1,M2,timer,next
go,1,,,,1,,-3,-3,0,2
go,1,,,,,,3,3,0,1
back,2,,,,1,,-3,-3,0,2
back,2,,,,,,3,3,0,1
"""


def sensor_scene(tmp_path: Path, world: str, robot: str = SENSORS, table: str = TABLE) -> Scene:
    (tmp_path / "robot.toml").write_text(robot, encoding="utf-8")
    (tmp_path / "table.csv").write_text(table, encoding="utf-8")
    (tmp_path / "world.toml").write_text(world, encoding="utf-8")
    return scene_of(tmp_path / "table.csv", tmp_path / "world.toml")


def read_at(scene: Scene, x: float, y: float, heading: float) -> np.ndarray:
    """The robot's state row after sensing at a pose (no motion)."""
    s = np.zeros(L.N_STATE)
    s[L.X], s[L.Y], s[L.TH] = x, y, math.radians(heading)
    sense(s, scene.P[0], world_arrays(scene), np.zeros(L.N_NOISE), scene.bits)  # the simulator's own first reading
    return s


TAPE = "[[line]]\npoints = [[0.5, 1.0], [2.5, 1.0]]\nwidth = 0.02\n"


@pytest.mark.parametrize("offset", [-0.035, -0.0201, -0.0199, -0.012, -0.004, 0.003, 0.0199, 0.0201, 0.035])
def test_floor_sensors_read_1_exactly_over_the_tape(tmp_path: Path, offset: float) -> None:
    scene = sensor_scene(tmp_path, room(extra=TAPE))
    # heading 0: the left sensor (I1) is 1 cm left of the axle line, so it sits at y = 1.01 + offset
    s = read_at(scene, 1.5 - 0.1, 1.0 + offset, 0.0)
    left, right = s[L.READING], s[L.READING + 1]
    assert left == (1.0 if abs(offset + 0.01) <= 0.01 else 0.0)
    assert right == (1.0 if abs(offset - 0.01) <= 0.01 else 0.0)
    mask = int(s[L.MASK])
    assert bool(mask & scene.machine.input_bits["I1"]) == (left == 1.0)


def test_a_closed_line_joins_its_last_point_to_its_first(tmp_path: Path) -> None:
    loop = "[[line]]\npoints = [[1, 1], [2, 1], [2, 2]]\nclosed = true\n"
    scene = sensor_scene(tmp_path, room(extra=loop))
    s = read_at(scene, 1.5 - 0.1 * math.cos(math.radians(45)), 1.5 - 0.1 * math.sin(math.radians(45)) - 0.007, 45)
    assert s[L.READING] == 1.0 or s[L.READING + 1] == 1.0  # the closing piece from (2, 2) back to (1, 1)


@pytest.mark.parametrize("gap", [0.05, 0.3, 1.0, 2.0])
def test_a_wall_ahead_reads_its_distance_to_the_resolution(tmp_path: Path, gap: float) -> None:
    scene = sensor_scene(tmp_path, room())
    s = read_at(scene, 3.0 - gap - 0.12, 1.5, 0.0)  # the sensor sits 12 cm ahead of the axle centre
    assert abs(s[L.READING + 2] - gap) <= 0.01 + 1e-12
    assert round(s[L.READING + 2] * 100) == pytest.approx(s[L.READING + 2] * 100)  # whole centimetres


def test_nothing_in_range_reads_the_range(tmp_path: Path) -> None:
    scene = sensor_scene(tmp_path, room(size=9.0, start=(1.0, 4.5, 0)))
    s = read_at(scene, 1.0, 4.5, 0.0)
    assert s[L.READING + 2] == scene.params["distance"]["range"] == 4.0


@pytest.mark.parametrize(("bearing", "seen"), [(0, True), (12, True), (20, False), (-25, False), (180, False)])
def test_an_obstacle_is_seen_only_inside_the_beam(tmp_path: Path, bearing: float, seen: bool) -> None:
    """A 5 cm post 60 cm from the sensor, at a bearing off the axis; the beam is 15° either side."""
    sx, sy = 1.0 + 0.12, 1.5
    cx, cy = sx + 0.6 * math.cos(math.radians(bearing)), sy + 0.6 * math.sin(math.radians(bearing))
    scene = sensor_scene(tmp_path, room(start=(0.5, 0.5, 0), extra=f"[[circle]]\nat = [{cx}, {cy}]\nradius = 0.025\n"))
    reading = read_at(scene, 1.0, 1.5, 0.0)[L.READING + 2]
    # the post's edge reaches the beam when its centre is within 15° + asin(2.5 / 60) ≈ 17.4°
    assert (abs(reading - 0.575) <= 0.01) == seen
    if not seen:
        assert reading == pytest.approx(3.0 - sx)  # the wall behind it


def test_a_wall_seen_at_a_slant_reads_the_nearest_point_inside_the_beam(tmp_path: Path) -> None:
    scene = sensor_scene(tmp_path, room())
    heading = 60.0  # the wall x = 3 is met by the beam's right edge (45° off its normal) first
    sx = 2.5
    s = read_at(
        scene, sx - 0.12 * math.cos(math.radians(heading)), 1.5 - 0.12 * math.sin(math.radians(heading)), heading
    )
    edge = math.radians(heading - 15)
    expected = (3.0 - sx) / math.cos(edge)
    assert abs(s[L.READING + 2] - expected) <= 0.01


def test_a_declared_light_sensor_matches_the_bumberbot_phototransistor(tmp_path: Path) -> None:
    scene = sensor_scene(tmp_path, room(extra="[[lamp]]\nat = [2.5, 1.2]\nintensity = 2.0\n"))
    s = read_at(scene, 1.5, 1.5, -5.0)
    g = scene.geometry
    expected = light_at(s, scene.P[0], -1.0, g.edges, g.circles, g.lamps)  # right sensor: 0.11, -0.03, toe 10°
    assert expected > 1.0
    assert s[L.READING + 3] == expected
    assert int(s[L.MASK]) & scene.machine.input_bits["I4"]


def test_thresholds_switch_with_the_declared_hysteresis(tmp_path: Path) -> None:
    scene = sensor_scene(tmp_path, room())
    p, bits, bit = scene.P[0], scene.bits, scene.machine.input_bits["I3"]
    s = np.zeros(L.N_STATE)
    mask, seen = 0, []
    for cm in (30, 21, 20, 19, 22, 24, 24.9, 25, 26, 20, 19.5):
        s[L.READING + 2] = cm / 100
        mask = sensor_events(as_state(s), as_params(p), bits, mask)  # the physics reads rows' fields by name
        seen.append(bool(mask & bit))
    #            30     21     20     19    22    24    24.9  25     26     20     19.5
    assert seen == [False, False, False, True, True, True, True, False, False, False, True]


def test_the_robot_turns_back_at_the_declared_thresholds(tmp_path: Path) -> None:
    scene = sensor_scene(tmp_path, room(start=(2.5, 1.5, 0)))  # the sensor 38 cm from the wall
    result = simulate(scene, 12.0)
    h, events, bit = result.kept_rows(), result.events, scene.machine.input_bits["I3"]
    readings = np.round(h[:-1, L.READING + 2] * 100).astype(int)
    on = (events & bit) != 0
    switched_on = np.flatnonzero(on[1:] & ~on[:-1]) + 1
    switched_off = np.flatnonzero(~on[1:] & on[:-1]) + 1
    assert len(switched_on) >= 2 and len(switched_off) >= 2  # it goes to and fro
    assert all(readings[t] < 20 and readings[t - 1] >= 20 for t in switched_on)
    assert all(readings[t] >= 25 and readings[t - 1] < 25 for t in switched_off)
