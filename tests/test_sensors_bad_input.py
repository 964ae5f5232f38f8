"""Bad [sensors] declarations and [[line]] tape are located errors with a hint, never tracebacks."""

from __future__ import annotations

from pathlib import Path

import pytest

from tablebot.diagnostics import TableBotError
from tablebot.robot import load_robot
from test_sim_declared import SENSORS, TABLE, sensor_scene
from test_sim_helpers import room, world_errors

pytestmark = [pytest.mark.kernel_free]

HEAD = """\
name = "Bad"
initial_state = 1
[inputs]
I1 = "a"
I2 = "b"
[motors]
M1 = "right motor"
M2 = "left motor"
[sensors]
"""


def robot_errors(tmp_path: Path, sensors: str) -> list[str]:
    path = tmp_path / "robot.toml"
    path.write_text(HEAD + sensors, encoding="utf-8")
    with pytest.raises(TableBotError) as info:
        load_robot(path)
    return [d.render() for d in info.value.diagnostics]


@pytest.mark.parametrize(
    ("line", "words"),
    [
        ('I1 = { sensor = "sonar", at = [0.1, 0] }', "sensor = 'sonar' is not a sensor kind"),
        ('I1 = { sensor = "distance", below = 20, at = [0.1, 0] }', "below must be a length with its unit"),
        ('I1 = { sensor = "distance", below = "20 parsecs", at = [0.1, 0] }', "below must be a length"),
        ('I1 = { sensor = "distance", at = [0.1, 0] }', "needs a threshold"),
        ('I1 = { sensor = "distance", below = "2 cm", above = "9 cm", at = [0.1, 0] }', "not both"),
        ('I1 = { sensor = "distance", below = "20 cm", hysteresis = "-1 cm", at = [0.1, 0] }', "must not be negative"),
        ('I1 = { sensor = "distance", below = "20 cm" }', "at must be [forward, left]"),
        ('I1 = { sensor = "line", at = [0.1, 0], below = 1 }', "a line sensor has no below"),
        ('I1 = { sensor = "phototransistor", above = "bright", at = [0.1, 0] }', "must be a light level"),
        ('I1 = { sensor = "distance", below = "20 cm", at = [0.1, 0], range = 3 }', "unknown key range"),
        ('I1 = { sensor = "distance", below = "20 cm", at = [0.1, 0], angle = 270 }', "angle must be degrees"),
        ('I9 = { sensor = "line", at = [0.1, 0] }', "I9 is not an input of the robot"),
        ('I1 = "line"', "must be a table like"),
    ],
)
def test_bad_sensor_declarations_name_their_line(tmp_path: Path, line: str, words: str) -> None:
    errors = robot_errors(tmp_path, line + "\n")
    assert len(errors) == 1, errors
    assert f"robot.toml:{HEAD.count(chr(10)) + 1}:1: error:" in errors[0]
    assert words in errors[0] and "hint:" in errors[0]


def test_good_declarations_read_as_metres_and_light_units(tmp_path: Path) -> None:
    path = tmp_path / "robot.toml"
    path.write_text(SENSORS, encoding="utf-8")
    robot = load_robot(path)
    line, _, distance, light = robot.sensors
    assert (line.kind, line.at) == ("line", (0.1, 0.01))
    assert (distance.kind, distance.direction, distance.unit) == ("distance", "below", "cm")
    assert distance.switch_points() == pytest.approx((0.20, 0.25))
    assert distance.describe() == "distance below 20 cm (hysteresis 5 cm)"
    assert (light.kind, light.direction, light.threshold, light.angle) == ("light", "above", 1.0, -10.0)


@pytest.mark.parametrize(
    ("text", "words"),
    [
        ("[[line]]\npoints = [[1, 1]]\n", "needs points"),
        ("[[line]]\npoints = [[1, 1], [9, 1]]\n", "outside the arena walls"),
        ("[[line]]\npoints = [[1, 1], [2, 1]]\nwidth = 0\n", "width = 0 is out of range"),
        ("[[line]]\npoints = [[1, 1], [2, 1]]\nclosed = 1\n", "closed must be true or false"),
        ("[[line]]\npoints = [[1, 1], [1, 1], [2, 1]]\n", "repeats a point"),
        ("[[line]]\npoints = [[1, 1], [2, 1]]\ncolour = 'black'\n", "unknown key 'colour'"),
    ],
)
def test_bad_lines_are_located(tmp_path: Path, text: str, words: str) -> None:
    errors = world_errors(tmp_path, room(extra=text))
    assert len(errors) == 1, errors
    assert words in errors[0] and "hint:" in errors[0]


def test_a_wiring_role_may_not_take_a_declared_sensor(tmp_path: Path) -> None:
    robot = SENSORS.replace("[sensors]", '[sim.wiring]\nfront_right = "I3"\n[sensors]')
    with pytest.raises(TableBotError) as info:
        sensor_scene(tmp_path, room(), robot=robot, table=TABLE)
    text = str(info.value)
    assert "front_right = 'I3', but I3 is declared in [sensors] as a distance sensor" in text
