"""The table file format's errors: every problem of a table or robot file is reported at once, each as
file:line:column with a hint (what reads well is test_tablefile.py)."""

from __future__ import annotations

from typing import TYPE_CHECKING

import pytest

from core_helpers import (
    MINI_ROBOT,
    column_of,
    find,
    problems,
    write_table,
)
from tablebot.diagnostics import TableBotError
from tablebot.formats.table_read import load_table, parse_table
from tablebot.robot import BUMBERBOT
from test_tablefile import GOOD, HEADER

pytestmark = [pytest.mark.kernel_free]

if TYPE_CHECKING:
    from pathlib import Path

# --- errors: one per kind, located -------------------------------------------------------------------


def test_unknown_column(tmp_path: Path) -> None:
    text = HEADER.replace(",B,", ",Q9,") + "\nGo,1,1,,,,3,,3,10,1\n"
    d = find(problems(write_table(tmp_path, text, MINI_ROBOT)), "unknown column 'Q9'")
    assert (d.line, d.column) == (1, column_of(HEADER, 4))
    assert "known columns" in d.hint and "M1_dir" in d.hint


def test_non_integer(tmp_path: Path) -> None:
    line = "Go,1,1,,,,fast,,3,10,1"
    d = find(problems(write_table(tmp_path, HEADER + "\n" + line + "\n", MINI_ROBOT)), "not an integer")
    assert (d.line, d.column) == (2, column_of(line, 6))
    assert "'fast'" in d.message and d.hint


@pytest.mark.parametrize(
    ("cells", "index", "pattern"),
    [
        ("Go,1,1,,,,9,,3,10,1", 6, r"M1_speed: 9 is out of range 0\.\.8"),
        ("Go,1,1,,,,-1,,3,10,1", 6, r"M1_speed: -1 is out of range"),
        ("Go,1,1,,,2,3,,3,10,1", 5, r"M1_dir: 2 is out of range 0\.\.1"),
        ("Go,1,1,,,,3,,3,65536,1", 9, r"timer: 65536 is out of range 0\.\.65535"),
        ("Go,1,1,,,,3,,3,-1,1", 9, r"timer: -1 is out of range"),
        ("Go,1,2,,,,3,,3,10,1", 2, r"event T: 2 is out of range 0\.\.1"),
        ("Go,1,1,x,,,3,,3,10,1", 3, r"event A: 'x' is not an integer"),
        ("Go,1,1,,,,3,,3,1.5,1", 9, r"timer: '1\.5' is not an integer"),
    ],
)
def test_cell_values_out_of_range(tmp_path: Path, cells: str, index: int, pattern: str) -> None:
    d = find(problems(write_table(tmp_path, HEADER + "\n" + cells + "\n", MINI_ROBOT)), pattern)
    assert (d.line, d.column) == (2, column_of(cells, index))
    assert d.hint


def test_unknown_next_state(tmp_path: Path) -> None:
    line = "Go,1,1,,,,3,,3,10,23"
    d = find(problems(write_table(tmp_path, HEADER + "\n" + line + "\n", MINI_ROBOT)), "next state 23 is unknown")
    assert (d.line, d.column) == (2, column_of(line, 10))
    assert "23" in d.hint


def test_missing_and_bad_states(tmp_path: Path) -> None:
    text = HEADER + "\nGo,,1,,,,3,,3,10,1\nGo,1,1,,,,3,,3,10,\nGo,-4,1,,,,3,,3,10,1\nGo,1,1,,,,3,,3,10,?x\n"
    diagnostics = problems(write_table(tmp_path, text, MINI_ROBOT))
    assert (find(diagnostics, "^state is missing").line) == 2
    assert (find(diagnostics, "^next state is missing").line) == 3
    assert (find(diagnostics, "negative").line) == 4
    assert (find(diagnostics, "not a valid state name").line) == 5


def test_initial_state_without_rows(tmp_path: Path) -> None:
    robot = MINI_ROBOT.replace("initial_state = 1", "initial_state = 5")
    d = find(problems(write_table(tmp_path, GOOD, robot)), "initial state 5")
    assert "has no rows" in d.message
    assert d.path.endswith("robot.toml") and d.line == 2  # points at the robot file's initial_state
    assert d.column is not None and d.hint


def test_built_in_robot_initial_state_without_rows_points_at_the_table(tmp_path: Path) -> None:
    text = "state,T,I3,M1_speed,M2_speed,timer,next\n1,1,,2,2,10,1\n"
    d = find(problems(write_table(tmp_path, text)), "initial state 2")
    assert d.path.endswith("table.csv") and (d.line, d.column) == (1, 1)


def test_named_state_in_robot_without_rows(tmp_path: Path) -> None:
    robot = MINI_ROBOT + '[states]\n1 = "drive"\n7 = "ghost"\n'
    d = find(problems(write_table(tmp_path, GOOD, robot)), "state 7 is named")
    assert d.path.endswith("robot.toml") and d.line is not None


def test_duplicate_header(tmp_path: Path) -> None:
    header = HEADER + ",timer"
    d = find(problems(write_table(tmp_path, header + "\nGo,1,1,,,,3,,3,10,1,\n", MINI_ROBOT)), "appears twice")
    assert (d.line, d.column) == (1, column_of(header, 11))
    assert f"first at column {column_of(header, 9)}" in d.message


def test_duplicate_alias_header(tmp_path: Path) -> None:
    header = HEADER + ",Timer Value"
    d = find(problems(write_table(tmp_path, header + "\n", MINI_ROBOT)), "appears twice")
    assert d.column == column_of(header, 11)


def test_missing_state_and_next_columns(tmp_path: Path) -> None:
    diagnostics = problems(write_table(tmp_path, "description,T,M1\nGo,1,3\n", MINI_ROBOT))
    assert find(diagnostics, "no 'state' column").line == 1
    assert find(diagnostics, "no 'next' column").line == 1


@pytest.mark.parametrize("text", ["", "\n\n", "\ufeff", " , ,\n"])
def test_empty_table(tmp_path: Path, text: str) -> None:
    diagnostics = problems(write_table(tmp_path, text, MINI_ROBOT))
    assert [d.message for d in diagnostics] == ["the table is empty"]
    assert (diagnostics[0].line, diagnostics[0].column) == (1, 1)
    assert diagnostics[0].hint


def test_header_without_rows(tmp_path: Path) -> None:
    diagnostics = problems(write_table(tmp_path, HEADER + "\n\n", MINI_ROBOT))
    assert [d.message for d in diagnostics] == ["the table has a header but no rows"]
    assert diagnostics[0].line == 2


def test_undecodable_bytes_give_line_and_column_of_the_bad_byte(tmp_path: Path) -> None:
    path = tmp_path / "table.csv"
    (tmp_path / "robot.toml").write_text(MINI_ROBOT)
    # "Grün" in Latin-1: the ü is a lone 0xfc byte; the é before it on the same line is proper UTF-8
    path.write_bytes(b"\xef\xbb\xbf" + HEADER.encode() + "\nRück é Gr".encode() + b"\xfcn,1,1,,,,3,,3,10,1\n")
    diagnostics = problems(path)
    assert len(diagnostics) == 1
    d = diagnostics[0]
    assert (d.line, d.column) == (2, len("Rück é Gr") + 1)  # characters, not bytes
    assert "0xfc" in d.message and "UTF-8" in d.hint


def test_every_bad_line_of_undecodable_file_is_reported(tmp_path: Path) -> None:
    """A binary file (the NUL byte) is not read as Windows-1252: each line with bad bytes is reported."""
    path = tmp_path / "table.csv"
    (tmp_path / "robot.toml").write_text(MINI_ROBOT)
    path.write_bytes(HEADER.encode() + b"\n\xe9t\xe9,1,1,,,,3,,3,10,1\nok\x00,1,,,,,,,,,1\n\xff,1,,,,,,,,,1\n")
    assert [(d.line, d.column) for d in problems(path)] == [(2, 1), (4, 1)]


def test_cell_beyond_the_last_column(tmp_path: Path) -> None:
    line = "Go,1,1,,,,3,,3,10,1,,oops"
    d = find(problems(write_table(tmp_path, HEADER + "\n" + line + "\n", MINI_ROBOT)), "beyond the last column")
    assert (d.line, d.column) == (2, column_of(line, 12))


def test_cell_under_a_blank_header(tmp_path: Path) -> None:
    header = "description,state,,T,A,M1,M2,timer,next"
    line = "Go,1,5,1,,3,3,10,1"
    d = find(problems(write_table(tmp_path, header + "\n" + line + "\n", MINI_ROBOT)), "no header")
    assert (d.line, d.column) == (2, column_of(line, 2))


def test_all_problems_of_a_file_in_one_run(tmp_path: Path) -> None:
    text = (
        HEADER.replace("description", "descr") + "\n"
        "Go,1,1,,,,9,,3,10,1\n"
        "Go,1,1,,,,3,,3,99999,1\n"
        "Go,1,1,,,,3,,3,10,42\n"
        "Go,x y!,1,,,,3,,3,10,1\n"
    )
    diagnostics = problems(write_table(tmp_path, text, MINI_ROBOT))
    assert [d.line for d in diagnostics] == [1, 2, 3, 5, 4]
    assert all(d.hint for d in diagnostics)
    assert all(d.path.endswith("table.csv") for d in diagnostics)


def test_a_row_with_a_bad_cell_still_declares_its_state(tmp_path: Path) -> None:
    """State 2's only row has a bad speed: that is the one problem, not also 'next state 2 unknown'."""
    text = HEADER + "\nGo,1,1,,,,3,,3,10,2\nBack,2,1,,,1,9,,0,5,1\n"
    diagnostics = problems(write_table(tmp_path, text, MINI_ROBOT))
    assert [d.message for d in diagnostics] == ["M1_speed: 9 is out of range 0..8"]


def test_mixed_motor_forms(tmp_path: Path) -> None:
    header = "state,T,M1,M1_dir,M1_speed,M2,timer,next"
    d = find(problems(write_table(tmp_path, header + "\n1,1,3,,3,0,0,1\n", MINI_ROBOT)), "both as M1 and")
    assert (d.line, d.column) == (1, column_of(header, 2))


def test_direction_without_speed(tmp_path: Path) -> None:
    header = "state,T,M1_dir,M2,timer,next"
    d = find(problems(write_table(tmp_path, header + "\n1,1,1,0,0,1\n", MINI_ROBOT)), "M1_dir has no M1_speed")
    assert (d.line, d.column) == (1, column_of(header, 2))


def test_rendered_diagnostic_is_file_line_column(tmp_path: Path) -> None:
    path = write_table(tmp_path, HEADER + "\nGo,1,1,,,,9,,3,10,1\n", MINI_ROBOT)
    with pytest.raises(TableBotError) as info:
        load_table(path)
    line = str(info.value).splitlines()
    assert line[0] == f"{path}:2:{column_of('Go,1,1,,,,9,,3,10,1', 6)}: error: M1_speed: 9 is out of range 0..8"
    assert line[1].startswith("    hint: ")


def test_missing_file(tmp_path: Path) -> None:
    with pytest.raises(TableBotError) as info:
        load_table(tmp_path / "nope.csv")
    assert "cannot read" in info.value.diagnostics[0].message


def test_parse_table_directly() -> None:
    table = parse_table("state,T,I3,M1_speed,M2_speed,timer,next\n2,1,,4,4,500,2\n", "<mem>", BUMBERBOT)
    assert table.path == "<mem>"
    assert table.rows[0].motors == (4, 4)


# --- robot files -----------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("robot", "pattern", "line"),
    [
        ("colour = 3\n" + MINI_ROBOT, "unknown key 'colour'", 1),
        (MINI_ROBOT.replace("initial_state = 1\n", ""), "initial_state is missing", None),
        ("tick_ms = 0\n" + MINI_ROBOT, "tick_ms must be a positive", 1),
        (MINI_ROBOT.replace('A = "left switch"', 'T = "oops"'), "bad inputs name 'T'", 5),
        (MINI_ROBOT.replace('B = "right switch"', 'M1 = "twice"'), "M1 is used twice", 6),
        (MINI_ROBOT + '[counters]\nC1 = "M9"\n', "counter C1 counts motor 'M9'", 11),
        (MINI_ROBOT + '[counters]\nT = "M1"\n', "bad counters name 'T'", 11),
    ],
)
def test_robot_file_problems(tmp_path: Path, robot: str, pattern: str, line: int | None) -> None:
    d = find(problems(write_table(tmp_path, GOOD, robot)), pattern)
    assert d.path.endswith("robot.toml")
    assert d.line == line
    assert d.hint


def test_robot_toml_syntax_error_has_line_and_column(tmp_path: Path) -> None:
    d = find(problems(write_table(tmp_path, GOOD, MINI_ROBOT + "oops = \n")), "TOML syntax")
    assert d.line == 10 and d.column is not None
