"""Timer cells written as times (500ms, 0.5s) read as whole ticks; a time that is no whole number of ticks
is a located error naming the nearest valid values; exports and firmware still get ticks."""

from __future__ import annotations

from typing import TYPE_CHECKING

import pytest

from core_helpers import MINI_ROBOT, column_of, find, problems, write_table
from tablebot.diagnostics import TableBotError
from tablebot.durations import DurationError, to_ticks
from tablebot.formats.table_read import parse_table
from tablebot.robopro.lists import encode
from tablebot.robot import BUMBERBOT, Robot

pytestmark = [pytest.mark.kernel_free]

if TYPE_CHECKING:
    from pathlib import Path

ROBOT7 = 'name = "Seven"\ntick_ms = 7\ninitial_state = 1\n[inputs]\nA = "a"\n[motors]\nM1 = "m"\n'
HEADER = "state,T,A,M1,timer,next"


def timers(text: str, robot: Robot = BUMBERBOT) -> list[int]:
    header = "state,T,I3,M1_speed,M2_speed,timer,next"
    rows = "".join(f"2,1,,2,2,{cell},2\n" for cell in text.split("|"))
    return [row.timer for row in parse_table(header + "\n" + rows, "<mem>", robot).rows]


def test_times_and_ticks_read_as_ticks() -> None:
    assert timers("50|500ms|0.5s|0.5 s|500 MS|3 ticks|1 tick|.25s|1.5s|0ms|") == [
        50,
        50,
        50,
        50,
        50,
        3,
        1,
        25,
        150,
        0,
        0,
    ]


@pytest.mark.parametrize(
    ("cell", "message", "hint"),
    [
        ("505ms", "timer: 505ms is not a whole number of 10 ms ticks", "nearest: 500ms (50 ticks) or 510ms (51 ticks)"),
        (
            "0.505s",
            "timer: 0.505s is not a whole number of 10 ms ticks",
            "nearest: 0.5s (50 ticks) or 0.51s (51 ticks)",
        ),
        ("5ms", "timer: 5ms is not a whole number of 10 ms ticks", "nearest: 0ms (0 ticks) or 10ms (1 tick)"),
        ("2.5 ticks", "timer: 2.5 ticks is not a whole number of ticks", "nearest: 2 or 3"),
        ("700s", "timer: 700s is 70000 ticks, more than the timer holds (65535)", "655.35 s at 10 ms a tick"),
        ("5 min", "timer: '5 min' is not a duration", "500ms, 0.5s"),
    ],
)
def test_bad_times_are_located_with_the_nearest_valid_values(
    tmp_path: Path, cell: str, message: str, hint: str
) -> None:
    line = f"1,1,,3,{cell},1"
    d = find(problems(write_table(tmp_path, f"{HEADER}\n{line}\n", MINI_ROBOT)), "^timer")
    assert (d.line, d.column) == (2, column_of(line, 4))
    assert d.message == message
    assert hint in d.hint


def test_nearest_values_use_the_robots_tick(tmp_path: Path) -> None:
    (tmp_path / "robot.toml").write_text(ROBOT7, encoding="utf-8")
    table = tmp_path / "table.csv"
    table.write_text(f"{HEADER}\n1,1,,3,100ms,1\n1,,,3,98ms,1\n", encoding="utf-8")
    from tablebot.formats.table_read import load_table

    with pytest.raises(TableBotError) as info:
        load_table(table)
    (d,) = info.value.diagnostics
    assert d.message == "timer: 100ms is not a whole number of 7 ms ticks"
    assert d.hint == "nearest: 98ms (14 ticks) or 105ms (15 ticks)"


def test_robopro_lists_get_ticks() -> None:
    header = "state,T,I3,I4,I5,I7,I8,M1_dir,M1_speed,M2_dir,M2_speed,timer,next"
    table = parse_table(header + "\n2,1,,,,,,,2,,2,8.95s,2\n", "<mem>", BUMBERBOT)
    assert list(encode(table).timer) == [895]


def test_durations_are_exact() -> None:
    assert to_ticks("0.1s", 10) == 10 and to_ticks("0.3 s", 10) == 30 and to_ticks("655.35s", 10) == 65535
    with pytest.raises(DurationError):
        to_ticks("0.1s", 3)


def test_comment_lines_below_the_header_are_ignored() -> None:
    header = "state,T,I3,M1_speed,M2_speed,timer,next"
    text = f"{header}\n# an example: 2,1,1,4,4,500ms,2\n2,1,,2,2,10,2\n  #another, with, commas\n2,,1,0,0,0,2\n"
    table = parse_table(text, "<mem>", BUMBERBOT)
    assert [(row.line, row.timer) for row in table.rows] == [(3, 10), (5, 0)]  # lines keep their numbers
