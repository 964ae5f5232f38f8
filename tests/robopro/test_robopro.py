"""The document's ROBO Pro lists, both ways: encoding, limits, named states, import."""

from __future__ import annotations

import re
import shutil
from typing import TYPE_CHECKING

import pytest

from core_helpers import EXAMPLE, MINI_ROBOT, SEED_TSV, example_machine, write_table
from tablebot.diagnostics import TableBotError
from tablebot.formats.table_read import load_table, parse_table
from tablebot.machine import compile_table
from tablebot.robopro import lists as robopro
from tablebot.robot import BUMBERBOT

pytestmark = [pytest.mark.kernel_free]

if TYPE_CHECKING:
    from pathlib import Path

    from tablebot.diagnostics import Diagnostic
    from tablebot.table import Table


def example_table() -> Table:
    return load_table(EXAMPLE / "table.csv")


def test_first_row_is_the_documents_worked_example() -> None:
    lists = robopro.encode(example_table())
    assert (lists.event[0], lists.action[0], lists.timer[0]) == (88, 5120, 50)


def test_seed_tsv_encodes_the_same(tmp_path: Path) -> None:
    shutil.copy(SEED_TSV, tmp_path / "seed.tsv")
    assert robopro.encode(load_table(tmp_path / "seed.tsv")) == robopro.encode(example_table())


@pytest.mark.parametrize(
    ("index", "expected"),
    [
        (3, (1 * 64 + 32, 2 * 256 + 128 + 2 * 16 + 2, 895)),  # Seek - Straight: M1 backward
        (8, (20 * 64 + 32, 21 * 256 + 7 * 16 + 7, 0)),  # Collision Entry: speed 7 (keep), direction 0
        (9, (21 * 64 + 16 + 8, 22 * 256 + 128 + 3 * 16 + 8 + 3, 75)),  # Collision Frontal: both backward
        (16, (22 * 64 + 4, 29 * 256 + 3 * 16 + 8 + 3, 150)),  # Collision Rear: I5
        (20, (1 * 64 + 2 + 1, 11 * 256 + 5 * 16 + 5, 125)),  # Seek Light: I7 and I8
        (36, (12 * 64 + 32, 1 * 256 + 4 * 16 + 4, 500)),  # last row
    ],
)
def test_bumberbot_rows_encode_with_the_documents_bit_weights(index: int, expected: tuple[int, int, int]) -> None:
    lists = robopro.encode(example_table())
    assert (lists.event[index], lists.action[index], lists.timer[index]) == expected


def test_write_lists_one_value_per_line(tmp_path: Path) -> None:
    written = robopro.write_lists(robopro.encode(example_table()), tmp_path)
    assert [p.name for p in written] == ["event.csv", "action.csv", "timer.csv"]
    assert (tmp_path / "event.csv").read_text().splitlines()[:3] == ["88", "80", "72"]
    assert len((tmp_path / "timer.csv").read_text().splitlines()) == 37
    assert not (tmp_path / "states.csv").exists()


def test_round_trip_gives_the_same_machine(tmp_path: Path) -> None:
    robopro.write_lists(robopro.encode(example_table()), tmp_path)
    table = robopro.decode(robopro.read_lists(tmp_path), BUMBERBOT)
    assert compile_table(table).signature() == example_machine().signature()
    assert {row.description for row in table.rows} == {""}  # the lists never held descriptions


def test_event_bits_follow_the_robot_not_the_tables_column_order(tmp_path: Path) -> None:
    """DetectEvent in ROBO Pro sets fixed bits per input: a table that reorders or omits event
    columns must still export T=32, I3=16, ..., I8=1."""
    text = "state,I8,T,I3,M1_speed,M2_speed,timer,next\n2,1,,,5,5,10,2\n2,,1,1,1,1,9,2\n"
    table = parse_table(text, "t.csv", BUMBERBOT)
    lists = robopro.encode(table)
    assert lists.event == (2 * 64 + 1, 2 * 64 + 32 + 16)
    robopro.write_lists(lists, tmp_path)
    back = robopro.decode(robopro.read_lists(tmp_path), BUMBERBOT)
    assert [row.events for row in back.rows] == [{"I8"}, {"T", "I3"}]


# --- named states -------------------------------------------------------------------------------------

NAMED = """\
state,T,A,M1,M2,timer,next
seek,1,,3,3,100,back off
seek,,1,0,0,5,3
back off,1,,-2,-2,50,1
1,1,,=,=,0,seek
3,1,,1,-1,20,seek
"""


def named_table(tmp_path: Path) -> Table:
    robot = MINI_ROBOT.replace("initial_state = 1", 'initial_state = "seek"')
    return load_table(write_table(tmp_path, NAMED, robot))


def test_named_states_are_numbered_and_written_beside_the_lists(tmp_path: Path) -> None:
    table = named_table(tmp_path)
    lists = robopro.encode(table)
    assert lists.numbers == {1: 1, 3: 3, "seek": 2, "back off": 4}
    assert lists.event[0] == 2 * 64 + 4  # MINI's layout: T=4, A=2, B=1
    assert lists.action[0] == 4 * 256 + 3 * 16 + 3
    assert lists.action[3] == 2 * 256 + 7 * 16 + 7  # keep is speed 7
    out = tmp_path / "lists"
    robopro.write_lists(lists, out)
    assert (out / "states.csv").read_text() == "number,name\n2,seek\n4,back off\n"


def test_named_states_come_back_on_import(tmp_path: Path) -> None:
    table = named_table(tmp_path)
    robopro.write_lists(robopro.encode(table), tmp_path / "lists")
    back = robopro.decode(robopro.read_lists(tmp_path / "lists"), table.robot)
    assert [row.state for row in back.rows] == ["seek", "seek", "back off", 1, 3]
    assert back.events == ("T", "A", "B")  # the robot's layout; the table had no B column

    def behaviour(t: Table) -> list[tuple[object, ...]]:
        return [(r.state, r.events, r.motors, r.timer, r.next) for r in t.rows]

    assert behaviour(back) == behaviour(table)


# --- limits -------------------------------------------------------------------------------------------


def fit_errors(tmp_path: Path, text: str, robot: str = MINI_ROBOT) -> tuple[Diagnostic, ...]:
    table = load_table(write_table(tmp_path, text, robot))
    with pytest.raises(TableBotError) as info:
        robopro.encode(table)
    return info.value.diagnostics


HEADER = "description,state,T,A,M1,M2,timer,next\n"


@pytest.mark.parametrize(
    ("rows", "line", "pattern"),
    [
        ("a,1,1,,1,1,5,128\nb,128,1,,0,0,0,1\n", 2, r"row 0: next state 128 is number 128, over 127"),
        ("a,1,1,,1,1,32768,1\n", 2, r"row 0: timer 32768 is over 32767"),
        ("a,1,1,,1,1,5,1\nb,1,,1,-7,1,5,1\n", 3, r"row 1: M1 speed 7 does not fit"),
        ("a,1,1,,1,8,5,1\n", 2, r"row 0: M2 speed 8 does not fit"),
    ],
)
def test_rows_that_do_not_fit_are_named(tmp_path: Path, rows: str, line: int, pattern: str) -> None:
    diagnostics = fit_errors(tmp_path, HEADER + rows)
    hits = [d for d in diagnostics if re.search(pattern, d.message)]
    assert len(hits) == 1, [d.message for d in diagnostics]
    assert hits[0].line == line and hits[0].hint


def test_state_over_127_names_both_places(tmp_path: Path) -> None:
    diagnostics = fit_errors(tmp_path, HEADER + "a,1,1,,1,1,5,200\nb,200,1,,0,0,0,1\n")
    assert sorted((d.line, d.message.split(":")[0]) for d in diagnostics) == [(2, "row 0"), (3, "row 1")]


def test_every_problem_at_once(tmp_path: Path) -> None:
    diagnostics = fit_errors(tmp_path, HEADER + "a,1,1,,7,8,40000,1\n")
    assert len(diagnostics) == 3


def test_more_than_six_event_columns(tmp_path: Path) -> None:
    robot = MINI_ROBOT.replace('B = "right switch"', 'B = ""\nC = ""\nD = ""\nE = ""\nF = ""')
    d = fit_errors(tmp_path, "state,T,A,M1,timer,next\n1,1,,1,0,1\n", robot)
    assert len(d) == 1 and "7 event columns" in d[0].message and "at most 6" in d[0].message


def test_more_than_two_motors(tmp_path: Path) -> None:
    robot = MINI_ROBOT.replace('M2 = "left"', 'M2 = "left"\nM3 = "arm"')
    d = fit_errors(tmp_path, "state,T,M1,M2,M3,timer,next\n1,1,1,1,1,0,1\n", robot)
    assert len(d) == 1 and "3 motors" in d[0].message and "at most 2" in d[0].message


def test_counters_and_lamps_do_not_fit(tmp_path: Path) -> None:
    robot = MINI_ROBOT + '[counters]\nC1 = "M1"\n[lamps]\nL1 = "lamp"\n'
    d = fit_errors(tmp_path, "state,T,M1,timer,next\n1,1,1,0,1\n", robot)
    assert sorted(x.message.split(" (")[0] for x in d) == ["the robot has counters", "the robot has lamps"]


# --- import errors ------------------------------------------------------------------------------------


def lists_dir(tmp_path: Path, event: str = "88\n", action: str = "5120\n", timer: str = "50\n") -> Path:
    folder = tmp_path / "lists"
    folder.mkdir(exist_ok=True)
    for name, text in (("event.csv", event), ("action.csv", action), ("timer.csv", timer)):
        (folder / name).write_text(text)
    return folder


def read_error(folder: Path) -> Diagnostic:
    with pytest.raises(TableBotError) as info:
        robopro.read_lists(folder)
    (d,) = info.value.diagnostics
    return d


def test_import_tolerates_extra_columns_and_blank_lines(tmp_path: Path) -> None:
    lists = robopro.read_lists(
        lists_dir(tmp_path, event="\ufeff88;x\n\n96\n", action="5120\n674\n", timer="50,1\n895\n")
    )
    assert (lists.event, lists.action, lists.timer) == ((88, 96), (5120, 674), (50, 895))


@pytest.mark.parametrize(
    ("files", "name", "line", "pattern"),
    [
        ({"event": "88\nabc\n"}, "event.csv", 2, "'abc' is not an integer"),
        ({"timer": "-3\n"}, "timer.csv", 1, "-3 is not a value"),
        ({"action": "70000\n"}, "action.csv", 1, "70000 is not a value"),
    ],
)
def test_import_errors_are_located(tmp_path: Path, files: dict[str, str], name: str, line: int, pattern: str) -> None:
    d = read_error(lists_dir(tmp_path, **files))
    assert d.path.endswith(name) and d.line == line and pattern in d.message


def test_import_lists_of_different_length(tmp_path: Path) -> None:
    assert "differ in length" in read_error(lists_dir(tmp_path, event="88\n88\n")).message


def test_import_missing_list(tmp_path: Path) -> None:
    folder = lists_dir(tmp_path)
    (folder / "timer.csv").unlink()
    assert "not found" in read_error(folder).message


def test_import_bad_states_file(tmp_path: Path) -> None:
    folder = lists_dir(tmp_path)
    (folder / "states.csv").write_text("number,name\nseek\n")
    d = read_error(folder)
    assert d.path.endswith("states.csv") and d.line == 2


def test_import_event_bits_beyond_the_robots_layout(tmp_path: Path) -> None:
    lists = robopro.read_lists(lists_dir(tmp_path))  # 88 = state 1, I3 and I4 (bits 16, 8)
    robot = load_table(write_table(tmp_path, "state,T,M1,timer,next\n1,1,1,0,1\n", MINI_ROBOT)).robot
    with pytest.raises(TableBotError, match="bits beyond the 3 events"):
        robopro.decode(lists, robot)
