"""The ROBO Pro exports of a robot of several tables (issue 36 §2): the whole program runs every table, one
process each (tests/robopro/test_robopro_several.py); the three lists hold its main table alone, and say so, and a main
table with a cross-table column is refused there at that column (the lists' encoder failed there with a
ValueError); a robot of one table gets no such warning."""

from __future__ import annotations

from pathlib import Path

import pytest

from test_run_cli import invoke

ROBOT = """name = "Two"
match = "always"
[inputs]
I1 = "button"
[motors]
M1 = "right"
M2 = "left"
[tables]
drive = { file = "drive.csv", initial_state = 1 }
other = { file = "other.csv", initial_state = 1 }
"""
DRIVE = "state,T,I1,M1,timer,next\n1,1,,3,5,2\n2,,1,0,0,1\n2,1,,-3,5,1\n"
CROSS = "state,T,I1,other=2,M1,timer,next\n1,1,,,3,5,2\n2,,,1,0,0,1\n2,1,,,-3,5,1\n"
OTHER = "state,T,I1,M2,timer,next\n1,,1,4,0,2\n2,1,,0,10,1\n"


def test_a_cross_table_column_is_refused_by_the_lists_where_it_is(tmp_path: Path) -> None:
    (tmp_path / "robot.toml").write_text(ROBOT)
    (tmp_path / "drive.csv").write_text(CROSS)
    (tmp_path / "other.csv").write_text(OTHER)
    result = invoke("export", tmp_path / "drive.csv", "--to", "robopro", tmp_path / "out")
    assert result.exit_code == 2, result.output
    assert f"{tmp_path / 'drive.csv'}:1:12: error: other=2: the ROBO Pro lists hold table drive alone" in " ".join(
        result.output.split()
    )
    assert not (tmp_path / "out").exists()
    program = invoke("export", tmp_path / "drive.csv", "--to", "robopro-program", tmp_path / "program")
    assert program.exit_code == 0 and "process per table (drive, other)" in program.output, program.output


@pytest.mark.parametrize("target", ["robopro", "robopro-program"])
def test_only_the_robopro_lists_of_several_tables_hold_the_main_one(tmp_path: Path, target: str) -> None:
    (tmp_path / "robot.toml").write_text(ROBOT)
    (tmp_path / "drive.csv").write_text(DRIVE)
    (tmp_path / "other.csv").write_text(OTHER)
    result = invoke("export", tmp_path / "drive.csv", "--to", target, tmp_path / "out")
    assert result.exit_code == 0, result.output
    said = " ".join(result.output.split())
    if target == "robopro":
        assert "the robot has 2 tables: the ROBO Pro lists hold its main table (drive) only, not other" in said
    else:
        assert "main table" not in said and "a process per table (drive, other)" in said
    (tmp_path / "robot.toml").write_text(ROBOT.split("[tables]")[0])
    alone = invoke("export", tmp_path / "drive.csv", "--to", target, tmp_path / "out2")
    assert alone.exit_code != 0 or "tables:" not in alone.output
