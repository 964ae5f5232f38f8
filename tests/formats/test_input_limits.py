"""Huge input (issue 33 §4): every number read from user text, and every dimension of a table or an inputs
file, has a limit far beyond real files; just past it is a located error (exit 2, file:line:column, a hint, no
traceback), refused before anything big is built; just below it is read. Limits too large to reach in a fast
test are lowered with monkeypatch, through the same code path."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest
from typer.testing import CliRunner

from core_helpers import EXAMPLE, FIXTURES, MINI_ROBOT, write_table
from tablebot.cli import app
from tablebot.csvtext import MAX_CELL_CHARS, MAX_COLUMNS
from tablebot.diagnostics import Diagnostic, TableBotError
from tablebot.durations import MAX_NUMBER_CHARS
from tablebot.formats import inputs_csv, table_read
from tablebot.formats.inputs_csv import load_inputs
from tablebot.formats.table_read import MAX_EVENT_COLUMNS, MAX_TABLE_BYTES, load_table
from tablebot.machine import compile_table
from tablebot.robopro import lists as robopro
from tablebot.robopro.rpp_edit import rewrite

runner = CliRunner()
#: More digits than Python's int() converts (4,300): what ended in an internal error (exit 70) before.
HUGE = "9" * 5000
HEADER = "description,state,T,A,B,M1,M2,timer,next"


def refused(*args: object) -> str:
    """Run the CLI: exit 2, hints, no traceback. Returns stderr."""
    result = runner.invoke(app, [str(a) for a in args])
    assert result.exception is None or isinstance(result.exception, SystemExit), result.exc_info
    assert result.exit_code == 2, result.output
    assert "Traceback" not in result.output and "internal error" not in result.output
    assert "hint: " in result.stderr, result.stderr
    return result.stderr


def table_dir(tmp_path: Path, rows: list[str], header: str = HEADER, robot: str = MINI_ROBOT) -> Path:
    write_table(tmp_path, "\n".join([header, *rows]) + "\n", robot)
    return tmp_path


def diagnostics_of(path: Path) -> tuple[Diagnostic, ...]:
    with pytest.raises(TableBotError) as info:
        load_table(path)
    return info.value.diagnostics


# --- numbers in table cells ------------------------------------------------------------------------------


@pytest.mark.parametrize("command", ["check", "sim"])
def test_a_cell_of_5000_digits_is_a_located_error(tmp_path: Path, command: str) -> None:
    """Reproduced: int() of more than 4,300 digits raised ValueError in check and sim (exit 70)."""
    folder = table_dir(tmp_path, [f"go,1,1,,,3,3,{HUGE},1"])
    err = refused(command, folder, *(["--seconds", "0.1", "--out", tmp_path / "out"] if command == "sim" else []))
    assert f"table.csv:2:{len('go,1,1,,,3,3,') + 1}: error: this cell is longer than 4,000 characters" in err


@pytest.mark.parametrize(
    ("cell", "message"),
    [
        ("1" + "0" * MAX_NUMBER_CHARS, "timer: a number of 101 characters is out of range 0..65535"),
        ("1" + "0" * MAX_NUMBER_CHARS + "ms", "a number of 101 characters is no duration"),
    ],
)
def test_a_timer_past_the_number_limit_is_refused_at_its_cell(tmp_path: Path, cell: str, message: str) -> None:
    (d,) = diagnostics_of(write_table(tmp_path, f"{HEADER}\ngo,1,1,,,3,3,{cell},1\n", MINI_ROBOT))
    assert (d.line, d.column) == (2, 14) and message in d.message


def test_state_numbers_have_at_most_100_digits(tmp_path: Path) -> None:
    """A state number of 101 digits was read (and carried into every trace and export); 100 still are."""
    longest, over = "9" * MAX_NUMBER_CHARS, "9" * (MAX_NUMBER_CHARS + 1)
    table = load_table(
        write_table(tmp_path, f"{HEADER}\ngo,1,1,,,3,3,0,{longest}\nback,{longest},1,,,3,3,0,1\n", MINI_ROBOT)
    )
    assert table.rows[1].state == int(longest)
    (d,) = diagnostics_of(write_table(tmp_path, f"{HEADER}\ngo,1,1,,,3,3,0,1\nback,{over},1,,,3,3,0,1\n"))
    assert (d.line, d.column) == (3, 6) and "state: a number of 101 characters is too long" in d.message


# --- the table's dimensions --------------------------------------------------------------------------------


def test_a_cell_just_over_the_length_limit_is_refused_and_one_at_it_is_read(tmp_path: Path) -> None:
    at_limit = "x" * MAX_CELL_CHARS
    table = load_table(write_table(tmp_path, f"{HEADER}\n{at_limit},1,1,,,3,3,0,1\n", MINI_ROBOT))
    assert table.rows[0].description == at_limit
    (d,) = diagnostics_of(write_table(tmp_path, f"{HEADER}\ngo,1,1,,,3,3,0,1\n{at_limit}y,1,,1,,3,3,0,1\n"))
    assert (d.line, d.column) == (3, 1) and "longer than 4,000 characters" in d.message


def test_a_quoted_cell_over_the_length_limit_is_refused_where_it_starts(tmp_path: Path) -> None:
    """The quoted path (a cell may span lines) is bounded too, at the cell's first line and column."""
    long = "a\n" + '""' * (MAX_CELL_CHARS // 2)  # a line break and 2,001 quotes: 2,003 characters of value...
    (d,) = diagnostics_of(
        write_table(tmp_path, f'{HEADER}\ngo,1,1,,,3,3,0,1\nx,"{long}{"b" * MAX_CELL_CHARS}",1\n', MINI_ROBOT)
    )
    assert (d.line, d.column) == (3, 3) and "longer than 4,000 characters" in d.message


def test_a_line_of_more_than_1000_cells_is_refused_at_the_first_one_too_many(tmp_path: Path) -> None:
    ok = HEADER + "," * (MAX_COLUMNS - HEADER.count(",") - 1)  # 1,000 cells: the blank ones are ignored
    assert len(load_table(write_table(tmp_path, f"{ok}\ngo,1,1,,,3,3,0,1\n", MINI_ROBOT)).rows) == 1
    (d,) = diagnostics_of(write_table(tmp_path, f"{ok},\ngo,1,1,,,3,3,0,1\n"))
    assert (d.line, d.column) == (1, len(ok) + 2) and "more than 1,000 cells" in d.message


def test_a_200000_column_header_is_refused_by_the_whole_command(tmp_path: Path) -> None:
    """Reproduced: 200,000 unknown columns were 200,000 errors, printed for 70 s; now one, at column 1,001."""
    header = ",".join(f"c{i}" for i in range(200_000))
    path = write_table(tmp_path, header + "\n" + "1," * 199_999 + "1\n")
    done = subprocess.run(
        [sys.executable, "-m", "tablebot", "check", str(path)], capture_output=True, text=True, check=False, timeout=60
    )
    column = len(",".join(f"c{i}" for i in range(1000))) + 2
    assert done.returncode == 2 and "Traceback" not in done.stderr
    assert done.stderr.count("error:") == 1 and f"table.csv:1:{column}: error: this line has more than" in done.stderr


def test_event_columns_beyond_63_are_refused_at_the_first_one_too_many(tmp_path: Path) -> None:
    """Reproduced: sim of a table of 200 event columns ended in OverflowError (the event word is 64-bit)."""
    robot = MINI_ROBOT.replace(
        'A = "left switch"\nB = "right switch"\n', "".join(f'I{i} = "in"\n' for i in range(MAX_EVENT_COLUMNS))
    )
    names = [f"I{i}" for i in range(MAX_EVENT_COLUMNS)]
    write_table(tmp_path, f"state,{','.join(names[:-1])},T,M1,M2,next\n1,{'1,' * 63}3,3,1\n", robot)
    assert len(compile_table(load_table(tmp_path / "table.csv")).table.events) == MAX_EVENT_COLUMNS
    write_table(tmp_path, f"state,{','.join(names)},T,M1,M2,next\n1,{'1,' * 64}3,3,1\n")
    err = refused("sim", tmp_path, "--seconds", "0.1", "--out", tmp_path / "out")
    column = len(f"state,{','.join(names)},") + 1
    assert f"table.csv:1:{column}: error: the table has 64 event columns" in err


def test_sim_of_more_event_columns_than_its_lookup_holds_is_refused_at_the_header(tmp_path: Path) -> None:
    """Reproduced: sim of a table of 11 to 63 event columns ended in an internal error (simrobot's ValueError:
    the compiled simulator's lookup holds 10); check still reads such a table."""
    robot = MINI_ROBOT.replace('A = "left switch"\nB = "right switch"\n', "".join(f'I{i} = "in"\n' for i in range(10)))
    names = ",".join(f"I{i}" for i in range(10))
    write_table(tmp_path, f"state,T,{names},M1,M2,next\n1,1,{'1,' * 10}3,3,1\n", robot)
    assert runner.invoke(app, ["check", str(tmp_path)]).exit_code in (0, 1)
    err = refused("sim", tmp_path, "--seconds", "0.1", "--out", tmp_path / "out")
    assert (
        "table.csv:1: error: the table has 11 event columns (T, inputs and counters); the simulator takes at "
        "most 10" in err
    )


@pytest.mark.parametrize("first", ["go", '"go, first"'])  # without a quote, lines are counted before any is read
def test_lines_below_the_header_are_counted(tmp_path: Path, monkeypatch: pytest.MonkeyPatch, first: str) -> None:
    monkeypatch.setattr(table_read, "MAX_TABLE_ROWS", 4)  # 100,000 in use: the same code, reached sooner
    rows = [f"{first},1,1,,,3,3,0,1", "", "# a comment counts too", "back,1,,1,,3,3,0,1"]
    assert len(load_table(write_table(tmp_path, "\n".join([HEADER, *rows]) + "\n", MINI_ROBOT)).rows) == 2
    write_table(tmp_path, "\n".join([HEADER, *rows, "x,1,,,1,3,3,0,1"]) + "\n")
    assert "table.csv:6:1: error: the table has more than 4 lines below its header" in refused("check", tmp_path)


def test_states_past_the_limit_are_refused_at_the_cell_naming_the_first_too_many(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(table_read, "MAX_STATES", 3)  # 1,000 in use
    rows = ["a,1,1,,,3,3,0,2", "b,2,1,,,3,3,0,3", "c,3,1,,,3,3,0,1"]
    assert len(compile_table(load_table(table_dir(tmp_path, rows) / "table.csv")).states) == 3
    table_dir(tmp_path, [*rows[:2], "c,3,1,,,3,3,0,4", "d,4,1,,,3,3,0,1"])
    err = refused("check", tmp_path)
    assert f"table.csv:4:{len('c,3,1,,,3,3,0,') + 1}: error: the table has more than 3 states" in err


def test_a_table_file_past_16_mb_is_refused_before_it_is_read(tmp_path: Path) -> None:
    path = write_table(tmp_path, HEADER + "\n", MINI_ROBOT)
    with path.open("ab") as stream:
        stream.truncate(MAX_TABLE_BYTES + 1)  # sparse: the test writes no 16 MB
    assert "larger than 16 MB" in refused("check", tmp_path)


# --- recorded inputs ---------------------------------------------------------------------------------------


def test_inputs_past_the_tick_limit_are_refused_as_they_are_read(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Reproduced: 3 M rows of inputs took 2.1 GB in `trace --inputs`; now a limit, counted row by row."""
    monkeypatch.setattr(inputs_csv, "MAX_INPUT_TICKS", 3)  # 1,000,000 in use
    machine = compile_table(load_table(EXAMPLE / "table.csv"))
    ok = tmp_path / "ok.csv"
    ok.write_text("I3,I4\n1,\n\n,1\n")  # a blank row is a tick
    assert len(load_inputs(ok, machine)) == 3
    over = tmp_path / "over.csv"
    for quote in ("", '"'):  # without a quote, the rows are counted before any is read
        over.write_text(f"I3,I4\n1,\n\n,1\n{quote}1{quote},1\n")
        assert "over.csv:5:1: error: more than 3 ticks" in refused("trace", EXAMPLE, "--inputs", over)
    trace = tmp_path / "run.jsonl"
    trace.write_text("".join(f'{{"tick":{t},"event":0}}\n' for t in range(4)))
    assert "run.jsonl:4:1: error: more than 3 ticks" in refused("trace", EXAMPLE, "--inputs", trace)


def test_pulses_of_5000_digits_are_a_located_error(tmp_path: Path) -> None:
    inputs = tmp_path / "in.csv"
    inputs.write_text(f"C1,C2\n{HUGE},0\n")
    counters = EXAMPLE.parent / "bumberbot-counters"
    assert "in.csv:2:1: error: this cell is longer than" in refused("trace", counters, "--inputs", inputs)
    inputs.write_text(f"C1,C2\n{'1' * (MAX_NUMBER_CHARS + 1)},0\n")
    assert "in.csv:2:1: error: C1: a number of 101 characters is too many pulses" in refused(
        "trace", counters, "--inputs", inputs
    )


def test_a_trace_line_with_a_5000_digit_number_says_so_where_it_is(tmp_path: Path) -> None:
    """It said 'nested too deeply' at column 1 (json's int() error taken for a recursion)."""
    trace = tmp_path / "run.jsonl"
    trace.write_text(f'{{"tick":0,"event":{HUGE}}}\n')
    assert "run.jsonl:1:19: error: line 1 has a number too long to read" in refused("trace", EXAMPLE, "--inputs", trace)


# --- numbers in TOML files and properties ------------------------------------------------------------------


@pytest.mark.parametrize(
    ("line", "column"),
    [(f"initial_timer = {HUGE}", 17), (f"initial_timer = 0x{'f' * 99}", 17), (f"initial_timer = -{HUGE}", 17)],
)
def test_a_toml_number_past_100_characters_is_a_located_error(tmp_path: Path, line: str, column: int) -> None:
    """Reproduced: tomllib's int() of 5,000 digits raised ValueError (exit 70); a huge hexadecimal number was read
    and failed wherever it was printed."""
    table_dir(tmp_path, ["go,1,1,,,3,3,0,1"], robot=MINI_ROBOT.replace("initial_timer = 0", line))
    err = refused("check", tmp_path)
    assert f"robot.toml:3:{column}: error: a number of " in err and "more than the 100 tablebot reads" in err


def test_a_toml_number_of_100_characters_is_read(tmp_path: Path) -> None:
    hexadecimal = "0x" + "0" * 97 + "5"
    table_dir(
        tmp_path, ["go,1,1,,,3,3,0,1"], robot=MINI_ROBOT.replace("initial_timer = 0", f"initial_timer = {hexadecimal}")
    )
    assert load_table(tmp_path / "table.csv").robot.initial_timer == 5


def test_a_world_number_of_5000_digits_is_a_located_error(tmp_path: Path) -> None:
    world = tmp_path / "arena.toml"
    world.write_text((EXAMPLE / "arena.toml").read_text() + f"\n[[circle]]\nat = [1, 1]\nradius = {HUGE}\n")
    assert "arena.toml:" in refused("sim", EXAMPLE, "--world", world, "--seconds", "0.1", "--out", tmp_path / "o")


def test_a_quoted_state_of_5000_digits_in_the_robot_file_is_a_located_error(tmp_path: Path) -> None:
    table_dir(tmp_path, ["go,1,1,,,3,3,0,1"], robot=MINI_ROBOT + f'[states]\n"{HUGE}" = "far"\n')
    assert "robot.toml:11:1: error: [states]" in refused("check", tmp_path)


@pytest.mark.parametrize(
    "claim",
    [f'never = "line == {HUGE}"', f'never = "M1 > {HUGE}"', f'when = "M1 > 0"\nthen = "M1 == 0"\nwithin = "{HUGE} ms"'],
)
def test_property_numbers_of_5000_digits_are_located_errors(tmp_path: Path, claim: str) -> None:
    properties = tmp_path / "p.toml"
    properties.write_text(f"[huge]\n{claim}\n")
    err = refused("check", EXAMPLE, "--properties", properties)
    assert "p.toml:" in err and "characters" in err


def test_a_robopro_program_whose_list_size_has_5000_digits_gets_its_lists_written() -> None:
    """Reproduced: export --into a .rpp whose list says N="<5,000 digits>" ended in int()'s ValueError. No real
    list is that long: the size is read as unknown and written as the lists' own."""
    program = (FIXTURES / "rpp" / "engine.rpp").read_text(encoding="utf-8").replace('N="10"', f'N="{HUGE}"', 1)
    lists = robopro.encode(load_table(EXAMPLE / "table.csv"))
    written = rewrite(program, {"Event": lists.event, "Action": lists.action, "Timer": lists.timer})
    assert f'N="{len(lists.event)}"' in written and HUGE not in written


def test_a_robopro_states_csv_with_a_5000_digit_number(tmp_path: Path) -> None:
    for name, text in (("event.csv", "97\n"), ("action.csv", "512\n"), ("timer.csv", "0\n")):
        (tmp_path / name).write_text(text)
    (tmp_path / "states.csv").write_text(f"number,name\n{'9' * 200},seek\n")
    assert "states.csv:2:1: error: expected number,name" in refused("import", tmp_path, "--from", "robopro")


# --- numbers in options ------------------------------------------------------------------------------------


@pytest.mark.parametrize("seeds", [f"0..{HUGE}", HUGE, "0..99999999999"])
def test_sweep_seeds_past_the_limits_are_refused_before_any_is_made(tmp_path: Path, seeds: str) -> None:
    """Reproduced: int() of 5,000 digits (exit 70); and 0..99999999999 was made into a list before the 10 million
    seeds limit was checked (MemoryError)."""
    assert "--seeds: error: --seeds" in refused("sweep", EXAMPLE, "--seeds", seeds, "--out", tmp_path / "s")


def test_evolve_freeze_cell_of_5000_digits_is_refused(tmp_path: Path) -> None:
    assert "--freeze-cell: error:" in refused("evolve", EXAMPLE, "--freeze-cell", f"line {HUGE}", "--out", tmp_path)
