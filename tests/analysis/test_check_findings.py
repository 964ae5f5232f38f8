"""Static findings on small hand-made tables with known defects, and on the BumberBot."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import pytest

from tablebot.analysis.lints import find_all, overlaps, shadowed_rows
from tablebot.analysis.model import Model
from tablebot.formats.table_read import load_table
from tablebot.machine import compile_table

pytestmark = [pytest.mark.kernel_free]

if TYPE_CHECKING:
    from tablebot.analysis.finding import Finding

FIX = Path(__file__).resolve().parents[1] / "fixtures" / "analysis"
EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "bumberbot" / "table.csv"


def findings(name: str | Path, targets: tuple[str, ...] = ()) -> list[Finding]:
    machine = compile_table(load_table(FIX / name if isinstance(name, str) else name))
    return find_all(machine, targets=targets)


def only(found: list[Finding], code: str) -> Finding:
    hits = [f for f in found if f.code == code]
    assert len(hits) == 1, [f.message for f in found]
    return hits[0]


def test_shadowed_row_names_both_lines() -> None:
    f = only(findings("shadowed.csv"), "shadowed-row")
    assert f.severity == "warning" and f.lines == (4, 3)
    assert "line 4 can never fire" in f.message and "earlier row on line 3" in f.message
    assert "A (left switch)" in f.message  # the hobbyist sees what the input is


def test_unreachable_state() -> None:
    f = only(findings("unreachable.csv"), "unreachable-state")
    assert f.state == 3 and f.lines == (4,)
    assert "can never be reached from the initial state 1" in f.message and "no row leads to it" in f.message


def test_zero_time_loop_that_an_input_can_break_is_a_warning() -> None:
    f = only(findings("zeroloop.csv"), "zero-time-loop")
    assert f.severity == "warning" and f.lines == (2, 4)
    assert "only leaves when an input arrives" in f.message


def test_zero_time_loop_with_no_way_out_is_an_error() -> None:
    f = only(findings("stuckloop.csv"), "zero-time-loop")
    assert f.severity == "error" and f.lines == (3, 4)
    assert "stuck for good" in f.message and f.detail["states"] == [2, 3]


def test_dead_end() -> None:
    f = only(findings("deadend.csv"), "dead-end")
    assert f.state == 2 and "can never leave" in f.message


def test_dead_end_because_the_way_out_never_fires() -> None:
    found = findings("busy.csv")
    assert not [f for f in found if f.code == "dead-end"]  # Bump (line 4) still leads out


def test_timer_that_never_runs_out() -> None:
    found = findings("busy.csv")
    f = only(found, "timer-never-expires")
    assert f.lines == (3,) and "(line 5)" in f.message and "never runs out" in f.message
    # line 5 fires every tick but changes nothing after the first time: not a loop between states
    assert not [f for f in found if f.code == "zero-time-loop"]


def test_a_row_that_changes_nothing_is_not_a_loop(tmp_path: Path) -> None:
    (tmp_path / "robot.toml").write_text((FIX / "robot.toml").read_text())
    (tmp_path / "t.csv").write_text("state,T,A,M1,M2,timer,next\n1,1,,3,3,0,2\n2,1,,0,0,0,2\n")
    found = findings(tmp_path / "t.csv")
    assert [f.code for f in found if f.severity != "info"] == ["dead-end"]  # a deliberate halt


def test_row_that_never_fires_because_t_is_always_there() -> None:
    f = only(findings("always_expired.csv"), "row-never-fires")
    assert f.lines == (4,)
    assert "line 3 fires first" in f.message and "always T" in f.message


def test_rows_waiting_for_a_counter_are_reachable_with_pulses() -> None:
    found = findings("counters.csv")
    assert [f for f in found if f.severity != "info"] == []


def test_overlap_reports_the_combination_and_the_winner() -> None:
    table = load_table(FIX / "trap.csv")
    (f,) = overlaps(table)
    assert f.lines == (2, 3) and f.detail["events"] == ["T", "B"] and f.detail["winner"] == 2
    assert "line 2 wins because it comes first" in f.message


def test_ignored_inputs_per_state() -> None:
    found = findings("deadend.csv")
    ignored = {f.state: f.detail["inputs"] for f in found if f.code == "ignored-inputs"}
    assert ignored == {1: ["B"], 2: ["A"]}


def test_encoding_limits_only_for_the_target_asked(tmp_path: Path) -> None:
    text = (FIX / "shadowed.csv").read_text().replace("Drive,1,1,,,3,3,100,2", "Drive,1,1,,,8,3,40000,2")
    (tmp_path / "robot.toml").write_text((FIX / "robot.toml").read_text())
    (tmp_path / "t.csv").write_text(text)
    assert not [f for f in findings(tmp_path / "t.csv") if f.code.startswith("encoding")]
    found = [f for f in findings(tmp_path / "t.csv", ("robopro",)) if f.code == "encoding-robopro"]
    assert {f.lines for f in found} == {(2,)} and len(found) == 2  # the speed 8 and the timer 40000
    assert all(f.severity == "error" for f in found)


def test_bumberbot_has_no_warnings_and_every_state_is_reachable() -> None:
    machine = compile_table(load_table(EXAMPLE))
    graph = Model(machine).explore()
    assert graph.states() == set(range(len(machine.states)))
    assert graph.fired_rows() == {r.index for r in machine.table.rows}
    found = find_all(machine, graph, ("robopro",))
    assert [f for f in found if f.severity != "info"] == []
    ignored = {f.state: f.detail["inputs"] for f in found if f.code == "ignored-inputs"}
    assert ignored[29] == ["I3", "I4", "I5", "I7", "I8"]  # the root of the found bug


def test_bumberbot_overlaps_include_timer_against_light() -> None:
    table = load_table(EXAMPLE)
    pairs = {f.lines for f in overlaps(table)}
    assert (5, 22) in pairs  # state 1: timer runs out while both eyes see light: line 5 wins
    assert not shadowed_rows(table)


@pytest.mark.parametrize("name", ["shadowed.csv", "unreachable.csv", "zeroloop.csv", "deadend.csv", "busy.csv"])
def test_findings_name_real_lines_of_the_file(name: str) -> None:
    lines = (FIX / name).read_text().splitlines()
    for f in findings(name):
        for line in f.lines:
            assert 2 <= line <= len(lines), f
