"""Several tables in one robot and state groups (issue 36): what a robot file and its tables say, and the
located errors of a robot that cannot run (two writers of one output, a cross-table event of no state)."""

from __future__ import annotations

from pathlib import Path

import pytest

from tablebot.diagnostics import TableBotError
from tablebot.formats.table_read import load_table
from tablebot.loading import Loaded
from tablebot.tables import several
from tables_helpers import DRIVE, LIGHTS, ROBOT, robot


def errors(folder: Path) -> list[str]:
    with pytest.raises(TableBotError) as caught:
        Loaded.open(folder)
    return [item.render() for item in caught.value.diagnostics]


def test_a_group_row_is_a_row_of_each_of_its_states_in_its_place(tmp_path: Path) -> None:
    table = load_table(robot(tmp_path) / "table.csv")
    assert [(r.state, r.line, r.as_written, r.group) for r in table.rows] == [
        (1, 2, 0, "moving"),
        (2, 2, 0, "moving"),
        (1, 3, 1, ""),
        (2, 4, 2, ""),
        (3, 5, 3, ""),
    ]
    assert [r.index for r in table.rows] == [0, 1, 2, 3, 4]


def test_the_tables_of_a_robot_with_their_own_start_rule_and_outputs(tmp_path: Path) -> None:
    loaded = Loaded.open(robot(tmp_path))
    tables = loaded.tables
    assert tables is not None and tables.names == ("drive", "lights")
    assert loaded.table is tables.table and loaded.table.name == "drive"
    drive, lights = tables.tables
    assert (drive.robot.match, lights.robot.match) == ("document", "always")
    assert set(drive.writes) == {"M1", "M2"} and set(lights.writes) == {"L1"}
    assert lights.rows[0].motors == (None, None)  # no motor column: the motors are the drive table's
    assert drive.rows[0].lamps == (None,)
    assert tables.input_bits == {"I1": 2, "I2": 1}
    assert tables.covers(lights.cross["drive=3"]) == (0, (tables.machines[0].states.index(3),))


def test_two_writers_of_one_output_is_an_error_at_the_second_naming_both(tmp_path: Path) -> None:
    lights = 'state,T,"drive=3",I2,L1,M2,timer,next\n1,,1,,8,0,0,2\n1,1,,,0,,3,1\n2,1,,1,4,,0,1\n'
    found = errors(robot(tmp_path, lights=lights))
    assert len(found) == 1
    assert "lights.csv:1:25: error: M2 is written by two tables, drive (" in found[0]
    assert "table.csv:1:15) and lights" in found[0]


def test_a_cross_table_event_must_name_states_its_table_has(tmp_path: Path) -> None:
    found = errors(robot(tmp_path, lights=LIGHTS.replace('"drive=3"', '"drive=3,7,40..49"')))
    assert [f.split(": error: ")[1].splitlines()[0] for f in found] == [
        "drive=3,7,40..49: table drive has no state 7",
        "drive=3,7,40..49: table drive has no state 40..49",
    ]
    assert all(":1:9:" in f for f in found)
    found = errors(robot(tmp_path, lights=LIGHTS.replace('"drive=3"', '"wheels=3"')))
    assert "lights.csv:1:9: error: 'wheels=3' names table 'wheels', which is not in [tables]" in found[0]


def test_a_group_is_no_next_state(tmp_path: Path) -> None:
    found = errors(robot(tmp_path, drive=DRIVE.replace("-5,5,4,1", "-5,5,4,moving")))
    assert "table.csv:4:13: error: next state 'moving' is a group ([groups])" in found[0]


def test_a_robot_file_says_what_is_wrong_with_its_tables_and_groups(tmp_path: Path) -> None:
    bad = ROBOT.replace('initial_state = 1, match = "always"', 'match = "sometimes", color = 1')
    bad = bad.replace("moving = [1, 2]", "moving = [1, 1]\n12 = [3]")
    found = "\n".join(errors(robot(tmp_path, robot_file=bad)))
    assert "robot.toml:17:1: error: table lights: unknown key 'color'" in found
    assert "robot.toml:17:1: error: table lights has no initial_state" in found
    assert "robot.toml:17:1: error: table lights: match must be one of document, always" in found
    assert "robot.toml:20:1: error: group moving lists a state twice" in found
    assert "robot.toml:21:1: error: group name '12' must be a state name" in found


def test_a_table_of_another_robot_file_is_refused_and_one_table_is_as_ever(tmp_path: Path) -> None:
    folder = robot(tmp_path)
    (folder / "other.csv").write_text(DRIVE)
    with pytest.raises(TableBotError, match="this table is none of the tables of"):
        load_table(folder / "other.csv")
    bumberbot = Loaded.open("examples/bumberbot")
    assert bumberbot.tables is None and several(bumberbot.table) is None
    assert all(r.written is None and r.group == "" for r in bumberbot.table.rows)
