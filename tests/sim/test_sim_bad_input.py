"""Regression tests from a review of ``tablebot sim``'s first five minutes: every bad world, robot or
option is a located error with a hint and exit code 2, never a traceback."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import pytest
from typer.testing import CliRunner

from tablebot.cli import app
from tablebot.diagnostics import TableBotError
from test_sim_helpers import BUMBERBOT, ROBOT, STRAIGHT, bot, room, scene_of, world_errors, write_bot

if TYPE_CHECKING:
    from typer.testing import Result

runner = CliRunner()


def setup_errors(tmp_path: Path, world: str, robot: str = ROBOT) -> list[str]:
    table, world_path = write_bot(tmp_path, STRAIGHT, world, robot)
    with pytest.raises(TableBotError) as info:
        scene_of(table, world_path)
    return [d.render() for d in info.value.diagnostics]


def sim(*args: str) -> Result:
    result = runner.invoke(app, ["sim", *args])
    assert result.exception is None or isinstance(result.exception, SystemExit), result.exception
    return result


# --- wiring and parameters: the message, the file that set the value, its line --------------------


def test_wiring_errors_keep_their_message_and_name_the_robot_file_line(tmp_path: Path) -> None:
    found = setup_errors(tmp_path, room(), ROBOT + '[sim.wiring]\nleft_motor = "M7"\n')
    line = ROBOT.count("\n") + 2
    assert found == [
        f"{tmp_path / 'robot.toml'}:{line}: error: wiring: left_motor = 'M7' is not a motor of "
        "robot TestBot\n    hint: its motors are M1, M2; set [wiring] left_motor in the world or "
        "[sim.wiring] in the robot file"
    ]


def test_wiring_errors_in_the_world_name_the_world_line(tmp_path: Path) -> None:
    found = setup_errors(tmp_path, room(extra='[wiring]\nrear = "I9"\n'))
    assert len(found) == 1 and found[0].startswith(f"{tmp_path / 'world.toml'}:8: error: wiring: rear = 'I9'")


def test_parameter_conflicts_name_the_file_and_line_that_set_them(tmp_path: Path) -> None:
    found = setup_errors(tmp_path, room(), ROBOT + "[sim.battery]\nempty_volts = 9.5\n")
    assert found == [
        f"{tmp_path / 'robot.toml'}:{ROBOT.count(chr(10)) + 2}: error: empty_volts must be below "
        "full_volts\n    hint: fix the value in the world or robot file"
    ]


def test_a_robot_without_two_drive_motors_is_refused_once(tmp_path: Path) -> None:
    robot = ROBOT.replace('M2 = "left motor"\n', "")
    (tmp_path / "robot.toml").write_text(robot, encoding="utf-8")
    table = tmp_path / "table.csv"
    table.write_text("state,T,M1,timer,next\n1,1,4,0,1\n", encoding="utf-8")
    with pytest.raises(TableBotError) as info:
        scene_of(table, None)
    (found,) = info.value.diagnostics
    assert "drives two wheels, but robot TestBot has 1 motor" in found.message and "[motors]" in found.hint


def test_one_motor_for_both_wheels_is_refused(tmp_path: Path) -> None:
    found = setup_errors(tmp_path, room(extra='[wiring]\nleft_motor = "M1"\n'))
    assert any("right_motor and left_motor are both M1" in e for e in found)


def test_unknown_sim_keys_and_a_missing_sim_world_are_located(tmp_path: Path) -> None:
    robot = ROBOT + '[sim]\nworld = "nowhere.toml"\ncolour = 3\n'
    (tmp_path / "robot.toml").write_text(robot, encoding="utf-8")
    (tmp_path / "table.csv").write_text("state,T,M1,M2,timer,next\n1,1,4,4,0,1\n", encoding="utf-8")
    with pytest.raises(TableBotError) as info:
        scene_of(tmp_path / "table.csv")
    found = [d.render() for d in info.value.diagnostics]
    line = ROBOT.count("\n") + 2
    assert any(f"robot.toml:{line + 1}: error: unknown key 'colour' in [sim]" in e for e in found), found
    assert any(f"robot.toml:{line}: error: sim.world:" in e and "is not a file" in e for e in found), found


# --- worlds ---------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("extra", "words"),
    [
        ("[[box]]\nat = [1, 1]\nsize = [0.4, 0.4]\n[[lamp]]\nat = [1.1, 0.9]\n", "inside [[box]] #1"),
        ("[[circle]]\nat = [1, 1]\nradius = 0.2\n[[lamp]]\nat = [1.05, 1]\nradius = 0\n", "inside [[circle]] #1"),
        ("[[segment]]\nfrom = [0.5, 2.5]\nto = [2.5, 2.5]\n[[lamp]]\nat = [1, 2.5]\n", "on a wall"),
    ],
)
def test_a_lamp_shut_in_an_obstacle_or_wall_is_refused(tmp_path: Path, extra: str, words: str) -> None:
    found = world_errors(tmp_path, room(extra=extra))
    assert len(found) == 1 and words in found[0] and "its light cannot reach the robot" in found[0], found


def test_a_lamp_on_the_arena_wall_is_reported_once(tmp_path: Path) -> None:
    found = world_errors(tmp_path, room(extra="[[lamp]]\nat = [3, 1]\n"))
    assert len(found) == 1 and "outside the arena walls" in found[0]


def test_missing_keys_are_named_not_shown_as_none(tmp_path: Path) -> None:
    found = world_errors(tmp_path, room(extra="[[box]]\nangle = 3\n[[circle]]\nat = [1, 1]\n"))
    assert any("[[box]] #1 at is missing" in e for e in found), found
    assert any("[[box]] #1 size is missing" in e for e in found), found
    assert any("[[circle]] #1 radius is missing" in e for e in found), found
    assert not any("None" in e for e in found), found


def test_a_world_without_arena_says_it_is_missing(tmp_path: Path) -> None:
    found = world_errors(tmp_path, 'name = "nothing"\n')
    assert any("[arena] walls is missing" in e and "add an [arena] section" in e for e in found), found


def test_a_section_that_is_not_an_array_of_tables_is_one_located_error(tmp_path: Path) -> None:
    found = world_errors(tmp_path, "box = [1, 2]\n" + room())
    assert found == [
        f"{tmp_path / 'bad.toml'}:1: error: box must be written as [[box]] tables, not [1, 2]\n"
        "    hint: see examples/bumberbot/arena.toml"
    ]


def test_crossing_walls_are_not_also_called_arealess(tmp_path: Path) -> None:
    found = world_errors(tmp_path, "[arena]\nwalls = [[0, 0], [2, 2], [2, 0], [0, 2]]\n[start]\nat = [1, 0.6]\n")
    assert "cross themselves" in found[0] and not any("enclose no area" in e for e in found), found


# --- command line ----------------------------------------------------------------------------------


def test_a_negative_seed_is_a_usage_error(tmp_path: Path) -> None:
    result = sim(str(BUMBERBOT), "--seed", "-1", "--out", str(tmp_path))
    assert result.exit_code == 2 and "--seed" in result.output


def test_out_naming_a_file_fails_before_simulating(tmp_path: Path) -> None:
    afile = tmp_path / "afile"
    afile.write_text("keep me", encoding="utf-8")
    result = sim(str(BUMBERBOT), "--seconds", "3600", "--out", str(afile))
    assert result.exit_code == 2
    assert f"{afile}: error: --out names a file, not a folder" in result.output
    assert afile.read_text(encoding="utf-8") == "keep me"


def test_too_many_ticks_are_refused_before_simulating(tmp_path: Path) -> None:
    robot = ROBOT.replace("tick_ms = 10", "tick_ms = 1")
    table, world = write_bot(tmp_path, STRAIGHT, room(), robot)
    result = sim(str(table), "--world", str(world), "--seconds", "3600", "--out", str(tmp_path / "out"))
    assert result.exit_code == 2
    assert (
        "3,600,000 ticks; a run holds at most 360,000" in result.output
        and "hint: simulate at most 360 s" in result.output
    )
    assert not (tmp_path / "out").exists()


def test_a_bad_robot_wiring_is_exit_2_on_the_command_line(tmp_path: Path) -> None:
    table, world = write_bot(tmp_path, STRAIGHT, room(), ROBOT + '[sim.wiring]\nright_motor = "Q"\n')
    result = sim(str(table), "--world", str(world), "--out", str(tmp_path / "out"))
    assert result.exit_code == 2 and "right_motor = 'Q' is not a motor of robot TestBot" in result.output


def test_setup_helper_still_builds(tmp_path: Path) -> None:
    assert bot(tmp_path, STRAIGHT, room()).drive == (0, 1)


# --- the robot's tick ------------------------------------------------------------------------------


def test_the_motors_do_not_depend_on_the_tables_tick(tmp_path: Path) -> None:
    """The calibration spin is 8.95 s of the document's 10 ms ticks: at 20 ms, 448 ticks turn 270° too."""
    from tablebot.sim.runner import simulate

    robot = ROBOT.replace("tick_ms = 10", "tick_ms = 20")
    rows = ["spin,1,1,,,,,,-2,2,448,2", "stop,2,1,,,,,,0,0,0,3", "rest,3,1,,,,,,0,0,0,3"]
    table, world = write_bot(tmp_path, rows, room(), robot)
    result = simulate(scene_of(table, world), 10.0)
    heading = result.heading_deg()
    assert abs(heading[-1] - heading[0] + 270.0) < 3.0


def test_a_tick_too_coarse_for_the_physics_is_refused_on_its_line(tmp_path: Path) -> None:
    robot = ROBOT.replace("tick_ms = 10", "tick_ms = 1000")
    found = setup_errors(tmp_path, room(), robot)
    assert found == [
        f"{tmp_path / 'robot.toml'}:2: error: tick_ms = 1000 is too coarse for the simulator: the robot "
        "would move up to 15 cm per tick, through thin walls\n    hint: simulate with tick_ms = 258 or "
        "less (the engine and the firmware take any tick)"
    ]
