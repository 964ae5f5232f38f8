"""`tablebot diagram`: states, merged edges, motion words and colours, every output format."""

from __future__ import annotations

from pathlib import Path

import pytest
from typer.testing import CliRunner

from tablebot.analysis.diagram import condition, edges, motion_of, render, to_mermaid
from tablebot.cli import app
from tablebot.formats.table_read import load_table

pytestmark = [pytest.mark.kernel_free]

FIX = Path(__file__).resolve().parents[1] / "fixtures" / "analysis"
EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "bumberbot"
BB = load_table(EXAMPLE / "table.csv")
runner = CliRunner()


def test_parallel_rows_are_merged() -> None:
    by_pair = {(e.source, e.target): e for e in edges(BB)}
    assert len(by_pair) == 20  # 37 rows, 20 distinct (state, next) pairs
    (stop,) = by_pair[(1, 20)].lines
    assert stop[0] == "I3 or I4" and stop[1].text == "stop" and stop[1].timer == "500 ms"
    assert [c for c, _ in by_pair[(1, 11)].lines] == ["I7+I8", "I7", "I8"]  # different actions stay apart
    assert by_pair[(22, 29)].lines[0][0] == "T or I5"


def test_condition_drops_sets_that_add_nothing() -> None:
    sets = [frozenset({"I3", "I4"}), frozenset({"I3"}), frozenset({"I4"})]
    assert condition(BB, sets) == "I3 or I4"
    assert condition(BB, [frozenset()]) == "always"


@pytest.mark.parametrize(
    ("motors", "words", "kind"),
    [
        ((4, 4), "forward 4", "forward"),
        ((-3, -3), "reverse 3", "reverse"),
        ((0, 0), "stop", "stop"),
        ((None, None), "keep", "keep"),
        ((-2, 2), "spin right L2 R-2", "turn"),  # M1 is the right motor
        ((1, 5), "curve right L5 R1", "turn"),
        ((-3, -2), "back, turn right L-2 R-3", "reverse"),
    ],
)
def test_motion_words(motors: tuple[int | None, int | None], words: str, kind: str) -> None:
    assert motion_of(BB, motors) == (words, kind)


def test_dot_source_marks_the_initial_state_and_labels_states() -> None:
    source = render(BB, "dot").decode()
    assert source.count("s_2 [label=<<b>2</b><br/>Seek: turn>") == 1
    assert "\t__start -> s_2 [" in source  # the initial state drawn wider, in its colour from the pictures
    assert 's_2 [label=<<b>2</b><br/>Seek: turn> color="#ff7f0e" fillcolor="#fff7d6" penwidth=3]' in source
    for state in BB.states:
        assert f"s_{state} [" in source
    assert "I3 or I4" in source and "#c62828" in source  # reverse edges are red


def test_mermaid() -> None:
    text = to_mermaid(BB)
    assert text.startswith("stateDiagram-v2\n") and "[*] --> s_2" in text
    assert "s_1 --> s_20: I3 or I4 / stop 500 ms" in text
    assert ":" not in text.split("s_12 --> s_1: ")[1].splitlines()[0]  # no stray colons in labels


def test_png_and_svg(tmp_path: Path) -> None:
    assert render(BB, "png").startswith(b"\x89PNG")
    svg = render(BB, "svg").decode()
    assert "<svg" in svg and "Collision entry" in svg


def test_command_infers_the_format_from_the_file_name(tmp_path: Path) -> None:
    out = tmp_path / "bb.png"
    result = runner.invoke(app, ["diagram", str(EXAMPLE), "--out", str(out)])
    assert result.exit_code == 0, result.output
    assert out.read_bytes().startswith(b"\x89PNG")


def test_command_mermaid_to_stdout_and_bad_format() -> None:
    result = runner.invoke(app, ["diagram", str(FIX / "bump.csv"), "--format", "mermaid"])
    assert result.exit_code == 0 and "s_3 --> s_1: T / spin left L-3 R3 300 ms" in result.stdout
    bad = runner.invoke(app, ["diagram", str(FIX / "bump.csv"), "--format", "gif"])
    assert bad.exit_code == 2 and "unknown diagram format" in bad.stderr


def test_a_fallback_row_reads_otherwise_and_descriptions_never_name_states(tmp_path: Path) -> None:
    robot = (FIX / "robot.toml").read_text()
    (tmp_path / "robot.toml").write_text(robot, encoding="utf-8")
    (tmp_path / "t.csv").write_text(
        "description,state,T,A,B,M1,M2,timer,next\n"
        "search,1,,1,,3,3,0,2\n"
        "search – give up,1,,,,0,0,0,1\n"
        "wait,2,,,,0,0,0,1\n",
        encoding="utf-8",
    )
    table = load_table(tmp_path / "t.csv")
    by_pair = {(e.source, e.target): e for e in edges(table)}
    assert by_pair[(1, 1)].lines[0][0] == "otherwise"  # tried after the row that needs A
    assert by_pair[(2, 1)].lines[0][0] == "always"  # state 2's only row
    mermaid = to_mermaid(table)
    assert 'state "1" as s_1' in mermaid and "give up" not in mermaid.split("s_1 --> s_2")[0]
