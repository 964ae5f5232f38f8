"""Review regressions: a user's first five minutes with bad inputs and bad output paths.

Every case must end with exit code 2, a message that names the file (and line) or the option, a
hint, and no traceback.
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest
from typer.testing import CliRunner

from core_helpers import EXAMPLE, MINI_ROBOT, example_machine, find, problems, write_table
from tablebot.cli import app
from tablebot.formats.table_read import parse_table
from tablebot.robot import BUMBERBOT

pytestmark = [pytest.mark.kernel_free]

runner = CliRunner()


def fails(*args: object) -> str:
    """Run the app; it must exit 2 without an escaped exception. Returns stderr."""
    result = runner.invoke(app, [str(a) for a in args])
    assert result.exception is None or isinstance(result.exception, SystemExit), result.exc_info
    assert result.exit_code == 2, result.output
    assert "Traceback" not in result.output and "hint: " in result.stderr, result.stderr
    return result.stderr


# --- input files ------------------------------------------------------------------------------------


def test_folder_without_a_table(tmp_path: Path) -> None:
    assert "holds no table.csv" in fails("check", tmp_path)


def test_inputs_that_are_a_folder(tmp_path: Path) -> None:
    assert "is a folder, not a file" in fails("trace", EXAMPLE, "--inputs", tmp_path)


def test_robot_file_with_bad_bytes_names_line_and_column(tmp_path: Path) -> None:
    table = write_table(tmp_path, "state,next\n1,1\n")
    (tmp_path / "robot.toml").write_bytes(b'initial_state = 1\n[motors]\nM1 = "r\xe9chts"\n')
    (d,) = problems(table)
    assert (d.line, d.column) == (3, 8) and "0xe9" in d.message and "UTF-8" in d.hint


def test_huge_state_numbers_are_read_exactly() -> None:
    big = 99999999999999999999999
    table = parse_table(f"state,T,next\n2,1,{big}\n{big},1,2\n", "<mem>", BUMBERBOT)
    assert table.rows[1].state == big


def test_bad_state_name_hint_says_what_a_name_may_hold(tmp_path: Path) -> None:
    table = write_table(tmp_path, 'state,next\n"a ""b",1\n1,1\n', MINI_ROBOT)
    (d,) = problems(table)
    assert "not a valid state name" in d.message and "A-Z" in d.hint


# --- output paths -----------------------------------------------------------------------------------


@pytest.mark.parametrize(
    "command",
    [
        ["tests", EXAMPLE, "--out"],
        ["demo", "--out"],
        ["export", EXAMPLE, "--to", "robopro"],
        ["export", EXAMPLE, "--to", "c"],
    ],
)
def test_output_folder_that_is_a_file(tmp_path: Path, command: list[str | Path]) -> None:
    afile = tmp_path / "afile"
    afile.write_text("keep me")
    assert "names a file, not a folder" in fails(*command, afile)
    assert afile.read_text() == "keep me"


def test_counterexample_folder_that_is_a_file(tmp_path: Path) -> None:
    afile = tmp_path / "afile"
    afile.write_text("")
    err = fails("check", EXAMPLE, "--properties", EXAMPLE / "properties.toml", "--counterexamples", afile)
    assert "--counterexamples names a file" in err


def test_an_unusable_counterexample_folder_still_shows_the_report(tmp_path: Path) -> None:
    afile = tmp_path / "afile"
    afile.write_text("")
    result = runner.invoke(app, ["check", str(EXAMPLE), "--counterexamples", str(afile)])
    assert result.exit_code == 2 and "names a file" in result.stderr
    assert "VIOLATED front_bumper_stops" in result.stdout
    assert "54 ticks (not written)" in result.stdout and "tick 53:" in result.stdout  # the story is kept


@pytest.mark.parametrize(
    "command",
    [
        ["trace", EXAMPLE, "--inputs", EXAMPLE / "inputs.csv", "--out"],
        ["diagram", EXAMPLE, "--format", "dot", "--out"],
    ],
)
def test_output_file_that_is_a_folder(tmp_path: Path, command: list[str | Path]) -> None:
    assert "--out names a folder, not a file" in fails(*command, tmp_path)


def test_output_file_in_a_missing_folder_says_so(tmp_path: Path) -> None:
    err = fails("trace", EXAMPLE, "--inputs", EXAMPLE / "inputs.csv", "--out", tmp_path / "no" / "t.jsonl")
    assert "does not exist" in err


def test_output_file_below_a_file(tmp_path: Path) -> None:
    """It said "--out names a file, not a folder" with a hint to give a folder, of an option that takes a file."""
    (tmp_path / "afile").write_text("mine\n")
    said = fails("diagram", EXAMPLE, "--out", tmp_path / "afile" / "x.dot")
    assert said.startswith(f"{tmp_path / 'afile'}: error: the folder of --out {tmp_path / 'afile' / 'x.dot'} is a file")
    assert "hint: give --out a file in a folder" in said and (tmp_path / "afile").read_text() == "mine\n"


def test_existing_output_file_is_replaced(tmp_path: Path) -> None:
    out = tmp_path / "t.jsonl"
    out.write_text("old")
    result = runner.invoke(app, ["trace", str(EXAMPLE), "--inputs", str(EXAMPLE / "inputs.csv"), "--out", str(out)])
    assert result.exit_code == 0 and out.read_text().startswith('{"tick":0')


def test_a_diagram_format_against_the_out_suffix_is_refused(tmp_path: Path) -> None:
    """--format png --out x.svg wrote PNG bytes into x.svg, which no viewer opens as either."""
    said = fails("diagram", EXAMPLE, "--out", tmp_path / "x.svg", "--format", "png")
    assert said.startswith(f"--format: error: --format png, but --out {tmp_path / 'x.svg'} is named as svg")
    assert not (tmp_path / "x.svg").exists()
    ok = runner.invoke(app, ["diagram", str(EXAMPLE), "--out", str(tmp_path / "x.txt"), "--format", "dot"])
    assert ok.exit_code == 0 and (tmp_path / "x.txt").read_text().startswith("digraph")  # a suffix of no format


def test_unknown_diagram_suffix_names_the_option() -> None:
    assert fails("diagram", EXAMPLE, "--out", Path("x.pdf")).startswith("--out: error: unknown diagram format 'pdf'")


def test_unknown_check_target_names_the_option() -> None:
    assert fails("check", EXAMPLE, "--target", "foo").startswith("--target: error: unknown export target 'foo'")


# --- robot files with wrong types -------------------------------------------------------------------

GOOD_TABLE = "state,T,A,M1,timer,next\n1,1,,3,10,1\n"


@pytest.mark.parametrize(
    ("change", "pattern", "line"),
    [
        (("initial_timer = 0", "initial_timer = true"), "initial_timer must be a whole number 0..65535, not True", 3),
        (("initial_timer = 0", "initial_timer = 1.5"), "initial_timer must be", 3),
        (("initial_state = 1", "initial_state = true"), "initial_state True is not a state", 2),
        (("initial_state = 1", "initial_state = [1]"), r"initial_state \[1\] is not a state", 2),
        (("initial_state = 1", "initial_state = 1.0"), "initial_state 1.0 is not a state", 2),
        (("initial_state = 1", "initial_state = -1"), "initial_state -1 is not a state", 2),
        (("initial_state = 1", "initial_state = {a = 1}"), "is not a state", 2),
        (("initial_state = 1", 'initial_state = "a \\"b"'), "is not a state", 2),
        (('name = "Mini"', "name = 5"), "name must be text, not 5", 1),
        (('M1 = "right"', "M1 = 7"), r"\[motors\] M1: the label must be text, not 7", 8),
        (('A = "left switch"', "A = {a = 1}"), r"\[inputs\] A: the label must be text", 5),
        (("initial_timer = 0", "initial_timer = 0\ntick_ms = 99999999999999999999"), "tick_ms must be a positive", 4),
        (("initial_timer = 0", "initial_timer = 0\ntick_ms = true"), "tick_ms must be a positive whole number", 4),
        (("[motors]", "tick_ms = 5\n[motors]"), r"tick_ms is inside \[inputs\]", 7),
    ],
)
def test_robot_file_wrong_types(tmp_path: Path, change: tuple[str, str], pattern: str, line: int) -> None:
    robot = MINI_ROBOT.replace(*change)
    assert robot != MINI_ROBOT
    d = find(problems(write_table(tmp_path, GOOD_TABLE, robot)), pattern)
    assert d.path.endswith("robot.toml") and d.line == line and d.hint


@pytest.mark.parametrize(
    ("extra", "pattern", "line"),
    [
        ('[states]\n1 = ["x"]\n', r"\[states\] 1: the name must be text", 11),
        ('[states]\n"-3" = "neg"\n', r"\[states\] '-3' is not a state", 11),
        ('[counters]\nC1 = {motor = "M1", extra = 3}\n', "counter C1 may only say motor", 11),
        ("[counters]\nC1 = 5\n", "counter C1 counts motor 5", 11),
    ],
)
def test_robot_file_wrong_types_in_sections(tmp_path: Path, extra: str, pattern: str, line: int) -> None:
    d = find(problems(write_table(tmp_path, GOOD_TABLE, MINI_ROBOT + extra)), pattern)
    assert d.line == line and d.hint


def test_robot_file_errors_go_through_the_cli(tmp_path: Path) -> None:
    table = write_table(tmp_path, GOOD_TABLE, MINI_ROBOT.replace("initial_timer = 0", "initial_timer = true"))
    assert "robot.toml:3:1: error: initial_timer must be" in fails("check", table)


# --- inputs CSVs ------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("text", "where", "pattern"),
    [
        ("I3,I3\n1,0\n", "1:4", "column 'I3' appears twice"),
        ("I3,I4\n1,0,1\n", "2:5", "cell '1' is beyond the last column"),
        ("I3,,I4\n1,x,1\n", "2:3", "cell 'x' is in a column with no header"),
    ],
)
def test_inputs_csv_problems(tmp_path: Path, text: str, where: str, pattern: str) -> None:
    (tmp_path / "in.csv").write_text(text)
    err = fails("trace", EXAMPLE, "--inputs", tmp_path / "in.csv")
    assert f"in.csv:{where}: error: {pattern}" in err


def test_inputs_csv_tick_column_and_trailing_blank_cells_are_fine(tmp_path: Path) -> None:
    (tmp_path / "in.csv").write_text("tick,I3,\n0,1,\n1,,\n")
    result = runner.invoke(app, ["trace", str(EXAMPLE), "--inputs", str(tmp_path / "in.csv")])
    assert result.exit_code == 0 and len(result.stdout.splitlines()) == 2


# --- property files ---------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("body", "pattern"),
    [
        ('[p]\nwhen = "I3"\nthen = "M1 <= 0"\n', "property p: within is missing"),
        ('[p]\nnever = "I3"\ntext = 5\n', "property p: text must be text, not 5"),
        ('[p]\nnever = "I3"\nnote = ["x"]\n', r"property p: note must be text, not \['x'\]"),
        ('[p]\nnever = "I3"\nlevel = "fatal"\n', "property p: level must be error or warning"),
        ('[p]\nnever = "I3"\nlevel = 3\n', "property p: level must be error or warning"),
    ],
)
def test_property_file_problems_have_hints(tmp_path: Path, body: str, pattern: str) -> None:
    (tmp_path / "p.toml").write_text(body)
    err = fails("check", EXAMPLE, "--properties", tmp_path / "p.toml")
    assert re.search(rf"p\.toml:1: error: {pattern}.*\n    hint: \S", err), err


def test_property_too_large_to_search_is_unknown_not_a_table_error(monkeypatch: pytest.MonkeyPatch) -> None:
    from tablebot.analysis import prove
    from tablebot.analysis.conditions import parse_condition
    from tablebot.analysis.properties import Property

    machine = example_machine()
    real = prove.search
    monkeypatch.setattr(prove, "search", lambda model, monitor, budget=1000: real(model, monitor, budget))
    prop = Property(
        "slow",
        "slow",
        "when",
        when=parse_condition("I3", machine),
        then=parse_condition("M1 < 0", machine),
        within=10_000,
    )
    result = prove.check_property(prop, machine)
    assert result.status == "unknown" and "a shorter within" in result.detail


# --- ROBO Pro import --------------------------------------------------------------------------------


@pytest.fixture
def lists(tmp_path: Path) -> Path:
    """The BumberBot exported as ROBO Pro lists."""
    folder = tmp_path / "lists"
    assert runner.invoke(app, ["export", str(EXAMPLE), str(folder), "--to", "robopro"]).exit_code == 0
    return folder


def test_import_robot_with_three_motors_is_refused(tmp_path: Path, lists: Path) -> None:
    robot = tmp_path / "three.toml"
    robot.write_text('initial_state = 2\n[inputs]\nI3 = "a"\n[motors]\nM1 = "a"\nM2 = "b"\nM3 = "c"\n')
    assert "3 motors do not fit the ROBO Pro layout" in fails("import", lists, "--from", "robopro", "--robot", robot)


def test_import_problems_of_the_rebuilt_table_point_into_the_lists(lists: Path) -> None:
    (lists / "event.csv").write_text("88\n89\n")
    (lists / "action.csv").write_text(f"{20 * 256}\n{1 * 256}\n")
    (lists / "timer.csv").write_text("0\n0\n")
    err = fails("import", lists, "--from", "robopro")
    assert f"{lists / 'action.csv'}:1:1: error: next state 20 is unknown" in err
    assert f"{lists / 'event.csv'}: error: initial state 2" in err and "--robot" in err


def test_import_empty_lists(lists: Path) -> None:
    for name in ("event.csv", "action.csv", "timer.csv"):
        (lists / name).write_text("")
    assert "the lists are empty" in fails("import", lists, "--from", "robopro")


@pytest.mark.parametrize(
    ("states", "pattern"),
    [
        ("number,name\n1,seek\n1,turn\n", "is given twice"),
        ("number,name\n1,seek\n2,seek\n", "is given twice"),
        ('number,name\n1,"a ""b"\n', "expected number,name"),
    ],
)
def test_import_bad_state_names(lists: Path, states: str, pattern: str) -> None:
    (lists / "states.csv").write_text(states)
    assert pattern in fails("import", lists, "--from", "robopro")


def test_import_from_a_file_or_nothing(tmp_path: Path) -> None:
    (tmp_path / "afile").write_text("")
    assert "afile: error: not a folder" in fails("import", tmp_path / "afile", "--from", "robopro")
    assert "nope: error: folder not found" in fails("import", tmp_path / "nope", "--from", "robopro")


# --- table parsing order and diagrams ---------------------------------------------------------------


def test_row_errors_come_in_column_order(tmp_path: Path) -> None:
    table = write_table(tmp_path, "state,T,next,\n,1,,junk,more\n1,1,1\n", MINI_ROBOT)
    assert [(d.line, d.column) for d in problems(table)] == [(2, 1), (2, 4), (2, 5), (2, 10)]


def test_mermaid_ids_of_names_that_differ_only_in_punctuation_stay_apart(tmp_path: Path) -> None:
    from tablebot.analysis.diagram import to_mermaid
    from tablebot.formats.table_read import load_table

    robot = MINI_ROBOT.replace("initial_state = 1", 'initial_state = "a.b"')
    table = write_table(
        tmp_path, "state,T,M1,M2,timer,next\na.b,1,1,1,5,a-b\na-b,1,2,2,5,a b\na b,1,0,0,5,a.b\n", robot
    )
    text = to_mermaid(load_table(table))
    assert "s_a_b --> s_a_b_2" in text and "s_a_b_2 --> s_a_b_3" in text and "s_a_b_3 --> s_a_b:" in text


def test_toml_syntax_error_at_the_end_of_the_file_has_a_place(tmp_path: Path) -> None:
    (tmp_path / "p.toml").write_text('[p]\nnever = "I3"\n[q')
    err = fails("check", EXAMPLE, "--properties", tmp_path / "p.toml")
    assert "p.toml:3:3: error: TOML syntax: a [section] header is not closed" in err


def test_top_level_key_below_states_says_where_it_belongs(tmp_path: Path) -> None:
    robot = MINI_ROBOT + '[states]\n1 = "drive"\ntick_ms = 5\n'
    d = find(problems(write_table(tmp_path, GOOD_TABLE, robot)), r"tick_ms is inside \[states\]")
    assert d.line == 12 and "above the first [section]" in d.hint


@pytest.mark.skipif(not Path("/dev/full").exists(), reason="needs Linux's /dev/full")
@pytest.mark.parametrize(
    "command",
    [
        ["trace", EXAMPLE, "--inputs", EXAMPLE / "inputs.csv", "--out"],
        ["diagram", EXAMPLE, "--format", "dot", "--out"],
    ],
)
def test_a_full_disk_names_the_output_file(command: list[str | Path]) -> None:
    assert fails(*command, "/dev/full").startswith("/dev/full: error: cannot write or read: No space left")


# --- what spreadsheets save -------------------------------------------------------------------------


def test_excel_sep_line_names_the_delimiter_and_keeps_line_numbers(tmp_path: Path) -> None:
    from tablebot.formats.table_read import load_table

    table = write_table(tmp_path, "sep=;\nstate;T;M1;timer;next\n1;1;3;10;1\n1;1;9;10;1\n", MINI_ROBOT)
    d = find(problems(table), "out of range")
    assert (d.line, d.column) == (4, 5)
    table.write_text("sep=;\nstate;T;M1;timer;next\n1;1;3;10;1\n")
    assert load_table(table).rows[0].line == 3


def test_inputs_with_a_sep_line_or_blank_lines_above_the_header(tmp_path: Path) -> None:
    for text in ("sep=;\nI3;I4\n1;1\n", "\n\nI3,I4\n1,1\n"):
        (tmp_path / "in.csv").write_text(text)
        result = runner.invoke(app, ["trace", str(EXAMPLE), "--inputs", str(tmp_path / "in.csv")])
        assert result.exit_code == 0 and result.stdout.startswith('{"tick":0,"event":56,'), result.output


@pytest.mark.parametrize("name", ["../../escaped", "a/b", "", ".hidden", "nul\\u0000"])
def test_property_names_must_be_plain_file_names(tmp_path: Path, name: str) -> None:
    (tmp_path / "p.toml").write_text(f'["{name}"]\nreachable = "I3"\n')
    err = fails("check", EXAMPLE, "--properties", tmp_path / "p.toml", "--counterexamples", tmp_path / "cex" / "x")
    assert "cannot name a file" in err
    assert not (tmp_path / "escaped.csv").exists()
