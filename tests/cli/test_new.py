"""`tablebot new`: every template gives a folder that check, sim and tests accept; names can be your own."""

from __future__ import annotations

import json
import shlex
from pathlib import Path

import pytest
from typer.testing import CliRunner

from tablebot.cli import app
from tablebot.formats.table_read import load_table

runner = CliRunner()


def invoke(*args: str | Path) -> str:
    result = runner.invoke(app, [str(a) for a in args])
    assert result.exit_code == 0, result.output
    return result.output


@pytest.mark.parametrize("template", ["empty", "bumberbot", "line-follower", "obstacle-avoider"])
def test_every_template_passes_check_sim_and_tests(tmp_path: Path, template: str) -> None:
    folder = tmp_path / "mine"
    out = invoke("new", folder, "--from", template)
    assert sorted(p.name for p in folder.iterdir()) == ["arena.toml", "properties.toml", "robot.toml", "table.csv"]
    assert "tablebot sim" in out
    check = invoke("check", folder, "--counterexamples", tmp_path / "ce")
    assert "holds" in check and "0 errors" in check
    invoke("sim", folder, "--seconds", "3", "--out", tmp_path / "sim", "--no-plots", "-q")
    assert (tmp_path / "sim" / "trace.jsonl").read_text().count("\n") == 300
    invoke("tests", folder, "--out", tmp_path / "golden")
    assert json.loads((tmp_path / "golden" / "coverage.json").read_text())["rows_covered"] > 0


def test_the_next_commands_can_be_pasted_into_a_shell(tmp_path: Path) -> None:
    folder = tmp_path / "my robot"
    out = invoke("new", folder)
    commands = [shlex.split(line) for line in out.split("next:", 1)[1].splitlines() if line.strip()]
    assert commands == [["tablebot", command, str(folder)] for command in ("check", "sim", "diagram")]


def test_the_empty_template_uses_your_names_and_shows_an_example_row(tmp_path: Path) -> None:
    folder = tmp_path / "rover"
    invoke("new", folder, "--inputs", "Bump=front bumper,Dark", "--motors", "R,L=left wheel")
    text = (folder / "table.csv").read_text()
    assert text.splitlines()[0] == "description,state,T,Bump,Dark,R,L,timer,next"
    assert "\n# Bump reads 1 while driving" in text  # the commented example row, ignored by the reader
    table = load_table(folder / "table.csv")
    assert len(table.rows) == 2 and table.robot.name == "rover"
    assert table.robot.labels == {"Bump": "front bumper", "Dark": "input 2", "R": "right motor", "L": "left wheel"}
    assert 'when = "R == 0 and L == 0"' in (folder / "properties.toml").read_text()


def test_a_renamed_bumberbot_runs_exactly_like_the_bumberbot(tmp_path: Path) -> None:
    invoke("new", tmp_path / "a", "--from", "bumberbot")
    invoke("new", tmp_path / "b", "--from", "bumberbot", "--inputs", "I1,I2,I3,I4,I5", "--motors", "A,B")
    robot = (tmp_path / "b" / "robot.toml").read_text()
    assert 'A = "M1"' in robot and 'I1 = { terminal = "I3"' in robot  # your names on the template's terminals
    for name in "ab":
        invoke("sim", tmp_path / name, "--seconds", "20", "--out", tmp_path / f"sim-{name}", "--no-plots", "-q")
    original = (tmp_path / "sim-a" / "trace.jsonl").read_text()
    renamed = (tmp_path / "sim-b" / "trace.jsonl").read_text()
    for old, new in (('"M1"', '"A"'), ('"M2"', '"B"'), ('"I7_light"', '"I4_light"'), ('"I8_light"', '"I5_light"')):
        original = original.replace(old, new)
    assert renamed == original  # the same bumpers and light sensors, wired under their new names


@pytest.mark.parametrize(
    ("args", "words"),
    [
        (["--from", "line-follower", "--inputs", "I1"], "template has 2 inputs (I1, I2); --inputs gives 1"),
        (["--inputs", "T,X"], "'T' cannot name a column"),
        (["--motors", "M1,M1"], "M1 given twice"),
        (
            ["--from", "rocket"],
            "--from: error: 'rocket' is not one of the choices of --from\n    hint: use one of: "
            "bumberbot, line-follower, obstacle-avoider, empty",
        ),  # tablebot's words, not the parser's
    ],
)
def test_bad_options_are_named(tmp_path: Path, args: list[str], words: str) -> None:
    result = runner.invoke(app, ["new", str(tmp_path / "x"), *args])
    assert result.exit_code == 2 and words in result.output
    assert not (tmp_path / "x").exists()


def test_a_folder_with_anything_in_it_is_refused(tmp_path: Path) -> None:
    folder = tmp_path / "busy"
    folder.mkdir()
    (folder / "notes.txt").write_text("mine", encoding="utf-8")
    result = runner.invoke(app, ["new", str(folder)])
    assert result.exit_code == 2 and "this folder is not empty" in result.output
    assert [p.name for p in folder.iterdir()] == ["notes.txt"]
    empty = tmp_path / "empty"
    empty.mkdir()
    invoke("new", empty)  # an empty folder is fine


def test_the_empty_robots_example_row_and_sensor_work_once_uncommented(tmp_path: Path) -> None:
    """The tutorial's second step: the robot that bumped into a wall turns away from it instead."""
    folder = tmp_path / "mine"
    invoke("new", folder)
    bumped = invoke("sim", folder, "--out", tmp_path / "before", "--no-plots")
    assert "collisions:       0" not in bumped  # it drives into a wall
    robot = (folder / "robot.toml").read_text()
    robot = robot.replace("# [sensors]", "[sensors]")
    robot = robot.replace('# I1 = { sensor = "distance"', 'I1 = { sensor = "distance"')
    (folder / "robot.toml").write_text(robot, encoding="utf-8")
    table = (folder / "table.csv").read_text().replace("# I1 reads 1 while driving", "I1 reads 1 while driving")
    (folder / "table.csv").write_text(table, encoding="utf-8")
    turned = invoke("sim", folder, "--out", tmp_path / "after", "--no-plots")
    assert "collisions:       0" in turned
    assert "holds" in invoke("check", folder, "--counterexamples", tmp_path / "ce")
