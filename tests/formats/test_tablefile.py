"""The table file format: what a spreadsheet saves reads as the table the user meant. Every problem of a file,
reported at once as file:line:column with a hint, is test_tablefile_errors.py."""

from __future__ import annotations

import shutil
from typing import TYPE_CHECKING

import pytest

from core_helpers import (
    EXAMPLE,
    MINI_ROBOT,
    SEED_TSV,
    example_machine,
    machine_of,
    problems,
    write_table,
)
from tablebot.formats.table_read import load_table
from tablebot.machine import compile_table
from tablebot.robot import BUMBERBOT

pytestmark = [pytest.mark.kernel_free]

if TYPE_CHECKING:
    from pathlib import Path

HEADER = "description,state,T,A,B,M1_dir,M1_speed,M2_dir,M2_speed,timer,next"
GOOD = HEADER + "\nGo,1,1,,,,3,,3,10,2\nBack,2,1,,,1,2,,0,5,1\n"


# --- the document's own table ---------------------------------------------------------------------


def test_seed_tsv_without_side_file_is_the_bumberbot(tmp_path: Path) -> None:
    path = tmp_path / "bumberbot-table.tsv"
    shutil.copy(SEED_TSV, path)
    table = load_table(path)
    assert table.robot == BUMBERBOT
    assert table.events == ("T", "I3", "I4", "I5", "I7", "I8")
    assert len(table.rows) == 37
    assert compile_table(table).signature() == example_machine().signature()


def test_seed_first_rows_read_as_printed() -> None:
    rows = load_table(SEED_TSV).rows
    first = rows[0]
    assert (first.index, first.line, first.state, first.next, first.timer) == (0, 2, 1, 20, 50)
    assert first.events == {"I3", "I4"}
    assert first.motors == (0, 0)
    straight = rows[3]
    assert straight.description == "Seek - Straight"
    assert straight.events == {"T"}
    assert straight.motors == (-2, 2)  # M1 direction 1 = backward, as printed
    entry = rows[8]
    assert entry.description == "Collision Entry"
    assert entry.motors == (None, None)  # speed 7: keep


def test_blank_description_continues_the_one_above() -> None:
    rows = load_table(EXAMPLE / "table.csv").rows
    assert [r.description for r in rows[:4]] == ["Collision detection"] * 3 + ["Seek - Straight"]
    assert rows[17].description == rows[18].description == "Collision Rear"


def test_example_uses_its_robot_file() -> None:
    table = load_table(EXAMPLE / "table.csv")
    assert table.robot.name == "BumberBot"
    assert table.robot.source.endswith("robot.toml")
    assert table.robot.initial_state == 2


# --- what spreadsheets save -------------------------------------------------------------------------


@pytest.mark.parametrize("delimiter", [",", "\t", ";"])
def test_delimiter_is_detected(tmp_path: Path, delimiter: str) -> None:
    text = (EXAMPLE / "table.csv").read_text().replace(",", delimiter)
    machine = machine_of(tmp_path, text, (EXAMPLE / "robot.toml").read_text())
    assert machine.signature() == example_machine().signature()


def test_bom_and_crlf(tmp_path: Path) -> None:
    text = "\ufeff" + (EXAMPLE / "table.csv").read_text().replace("\n", "\r\n")
    machine = machine_of(tmp_path, text, (EXAMPLE / "robot.toml").read_text())
    assert machine.signature() == example_machine().signature()


def test_utf16_with_bom_as_excel_saves_unicode_text(tmp_path: Path) -> None:
    text = (EXAMPLE / "table.csv").read_text().replace(",", "\t").replace("\n", "\r\n")
    path = tmp_path / "table.txt"
    path.write_bytes(text.encode("utf-16"))  # with BOM
    (tmp_path / "robot.toml").write_text((EXAMPLE / "robot.toml").read_text())
    assert compile_table(load_table(path)).signature() == example_machine().signature()


def test_old_mac_line_ends(tmp_path: Path) -> None:
    text = (EXAMPLE / "table.csv").read_text().replace("\n", "\r")
    machine = machine_of(tmp_path, text, (EXAMPLE / "robot.toml").read_text())
    assert machine.signature() == example_machine().signature()


def test_quoted_cells(tmp_path: Path) -> None:
    # a table's rows one to a line, as the file has them: left as written
    # fmt: off
    text = (HEADER + '\n"Go, fast ""now""\nand then",1,"1",,,,"3",,3,10,"2"\n'
            "Back,2,1,,,1,2,,0,5,1\n")
    # fmt: on
    table = load_table(write_table(tmp_path, text, MINI_ROBOT))
    assert table.rows[0].description == 'Go, fast "now"\nand then'
    assert table.rows[0].events == {"T"}
    assert table.rows[0].next == 2
    assert table.rows[1].line == 4  # the multi-line cell moved the next record down a line


def test_quoted_cell_never_closed(tmp_path: Path) -> None:
    diagnostics = problems(write_table(tmp_path, HEADER + '\n"Go,1,1\n', MINI_ROBOT))
    assert [(d.line, d.column) for d in diagnostics] == [(2, 1)]
    assert "never closed" in diagnostics[0].message


def test_header_names_are_forgiving(tmp_path: Path) -> None:
    text = "Description,State,T,A,B,M1 dir,M1-Speed,M2_dir,M2_speed,Timer Value,Next State\nGo,1,1,,,,3,,3,10,1\n"
    table = load_table(write_table(tmp_path, text, MINI_ROBOT))
    assert table.rows[0].motors == (3, 3)
    assert table.rows[0].timer == 10


def test_blank_lines_and_trailing_empty_cells_are_ignored(tmp_path: Path) -> None:
    text = HEADER + ",,\n\nGo,1,1,,,,3,,3,10,2,,\n,,,,\nBack,2,1,,,1,2,,0,5,1\n\n"
    table = load_table(write_table(tmp_path, text, MINI_ROBOT))
    assert [r.line for r in table.rows] == [3, 5]
    assert [r.index for r in table.rows] == [0, 1]


def test_blank_lines_above_the_header(tmp_path: Path) -> None:
    table = load_table(write_table(tmp_path, "\n\t\n" + GOOD.replace(",", "\t"), MINI_ROBOT))
    assert [r.line for r in table.rows] == [4, 5]
    assert table.rows[0].motors == (3, 3)


def test_columns_in_any_order_and_missing_optional_ones(tmp_path: Path) -> None:
    text = "next,timer,M1,state,A\n2,5,-3,1,1\n1,,=,2,\n"
    table = load_table(write_table(tmp_path, text, MINI_ROBOT))
    assert table.events == ("A",)
    assert table.rows[0].motors == (-3, 0)  # no M2 column: every cell blank, and blank means stop
    assert table.rows[1].motors == (None, 0)
    assert table.rows[1].timer == 0
    assert table.rows[0].description == ""


def test_motor_forms_and_keep(tmp_path: Path) -> None:
    # each row's comment on its row: left as written
    # fmt: off
    text = (HEADER + "\n"
            "a,1,,,,1,3,0,3,0,1\n"   # backward 3, forward 3
            "b,1,,,,1,7,1,7,0,1\n"   # speed 7: keep, whatever the direction
            "c,1,,,,1,0,,8,0,1\n")   # backward 0 is stop; speed 8 is a real speed here
    # fmt: on
    rows = load_table(write_table(tmp_path, text, MINI_ROBOT)).rows
    assert [r.motors for r in rows] == [(-3, 3), (None, None), (0, 8)]


def test_integer_like_cells(tmp_path: Path) -> None:
    text = HEADER + "\nGo,01,1.0,,,,+3,,3,10.0,2\nBack,2,1,,,1,2,,0,5,1\n"
    row = load_table(write_table(tmp_path, text, MINI_ROBOT)).rows[0]
    assert (row.state, row.events, row.motors, row.timer) == (1, {"T"}, (3, 3), 10)


def test_named_states(tmp_path: Path) -> None:
    robot = MINI_ROBOT.replace("initial_state = 1", 'initial_state = "seek"')
    text = (
        "state,T,A,M1,M2,timer,next\n"
        "seek,1,,2,2,10,back off\nback off,1,,-2,-2,5,seek\nseek,,1,0,0,0,2\n2,1,,0,0,0,seek\n"
    )
    machine = machine_of(tmp_path, text, robot)
    assert machine.states == ("seek", "back off", 2)
    assert machine.initial_state == 0


def test_robot_initial_state_as_digit_string_means_the_integer_state(tmp_path: Path) -> None:
    robot = MINI_ROBOT.replace("initial_state = 1", 'initial_state = "2"')
    machine = machine_of(tmp_path, GOOD, robot)
    assert machine.states[machine.initial_state] == 2


def test_side_file_named_after_the_table_wins(tmp_path: Path) -> None:
    write_table(tmp_path, GOOD, MINI_ROBOT.replace('"Mini"', '"Folder"'), name="walk.csv")
    (tmp_path / "walk.toml").write_text(MINI_ROBOT.replace('"Mini"', '"Own"'))
    assert load_table(tmp_path / "walk.csv").robot.name == "Own"
    (tmp_path / "walk.toml").unlink()
    assert load_table(tmp_path / "walk.csv").robot.name == "Folder"
