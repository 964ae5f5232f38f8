"""The trace format (one JSON object per tick) and the recorded-inputs CSV it replays."""

from __future__ import annotations

import io
import json
import re
from typing import TYPE_CHECKING

import pytest

from core_helpers import COUNTER_ROBOT, EXAMPLE, example_machine, write_table
from tablebot.diagnostics import TableBotError
from tablebot.formats.inputs_csv import TickInput, load_inputs
from tablebot.formats.table_read import load_table
from tablebot.formats.trace_lines import dumps, read_trace, write_trace
from tablebot.machine import compile_table
from tablebot.replay import replay

pytestmark = [pytest.mark.kernel_free]

if TYPE_CHECKING:
    from pathlib import Path

    from tablebot.diagnostics import Diagnostic
    from tablebot.machine import Machine


def trace_of(tmp_path: Path, inputs_text: str, machine: Machine | None = None) -> list[dict]:
    machine = machine or example_machine()
    path = tmp_path / "inputs.csv"
    path.write_text(inputs_text)
    return list(replay(machine, load_inputs(path, machine)))


def test_keys_in_order_and_the_readme_example(tmp_path: Path) -> None:
    lines = trace_of(tmp_path, "I3,I4,I5,I7,I8\n,,,,\n")
    assert list(lines[0]) == ["tick", "event", "row", "state", "timer", "M1", "M2"]
    assert dumps(lines[0]) == '{"tick":0,"event":32,"row":7,"state":1,"timer":500,"M1":4,"M2":4}'


def test_event_bits_first_column_highest(tmp_path: Path) -> None:
    """T=32, I3=16, I4=8, I5=4, I7=2, I8=1 (after tick 0 the timer holds 500, then 50: no T)."""
    lines = trace_of(tmp_path, "I8,I7,I5,I4,I3\n0,0,0,0,0\n,,,,1\n,,,1,\n,,1,,\n,1,,,\n1,,,,\n1,1,1,1,1\n")
    assert [line["event"] for line in lines] == [32, 16, 8, 4, 2, 1, 31]


def test_row_is_null_when_nothing_fires_and_state_timer_are_after_the_tick(tmp_path: Path) -> None:
    lines = trace_of(tmp_path, "I3\n\n\n1\n")
    assert [(x["row"], x["state"], x["timer"]) for x in lines] == [(7, 1, 500), (None, 1, 499), (1, 20, 50)]
    assert '"row":null' in dumps(lines[1])


def test_motors_are_signed(tmp_path: Path) -> None:
    lines = trace_of(tmp_path, "I3,I4\n\n1,1\n" + "\n" * 50 + "1,1\n")
    assert (lines[-1]["row"], lines[-1]["M1"], lines[-1]["M2"]) == (9, -3, -3)  # Collision Frontal: backward


def test_replay_is_deterministic_byte_for_byte() -> None:
    machine = example_machine()
    ticks = load_inputs(EXAMPLE / "inputs.csv", machine)
    first, second = io.StringIO(), io.StringIO()
    assert write_trace(replay(machine, ticks), first) == len(ticks) == 3000
    write_trace(replay(example_machine(), load_inputs(EXAMPLE / "inputs.csv", machine)), second)
    assert first.getvalue() == second.getvalue()
    assert first.getvalue().endswith("\n") and "\r" not in first.getvalue()


def test_write_and_read_trace(tmp_path: Path) -> None:
    machine = example_machine()
    lines = list(replay(machine, [TickInput(0), TickInput(16)]))
    path = tmp_path / "t.jsonl"
    with path.open("w") as stream:
        write_trace(lines, stream)
    assert read_trace(path) == lines
    assert path.read_text().splitlines()[1] == json.dumps(lines[1], separators=(",", ":"))


def test_counters_and_lamps_follow_the_motors(tmp_path: Path) -> None:
    table = "state,T,A,C1,M1,M2,L1,L2,C1_load,C2_load,timer,next\n1,1,,,3,-2,5,=,4,,9,1\n"
    machine = compile_table(load_table(write_table(tmp_path, table, COUNTER_ROBOT)))
    lines = trace_of(tmp_path, "A,C1,C2\n,,\n,1,2\n", machine)
    assert list(lines[0]) == ["tick", "event", "row", "state", "timer", "M1", "M2", "L1", "L2", "C1", "C2"]
    assert [dumps(x) for x in lines] == [
        '{"tick":0,"event":5,"row":0,"state":1,"timer":9,"M1":3,"M2":-2,"L1":5,"L2":0,"C1":4,"C2":0}',
        '{"tick":1,"event":0,"row":null,"state":1,"timer":8,"M1":3,"M2":-2,"L1":5,"L2":0,"C1":3,"C2":0}',
    ]


# --- the inputs CSV -----------------------------------------------------------------------------------


def test_inputs_blank_is_zero_and_tick_column_is_ignored(tmp_path: Path) -> None:
    machine = example_machine()
    path = tmp_path / "in.csv"
    path.write_text("tick,I7,I3\n0,,\n1,1,\n2,1,1\n")
    assert [t.mask for t in load_inputs(path, machine)] == [0, 2, 18]


def inputs_error(tmp_path: Path, text: str, machine: Machine | None = None) -> tuple[Diagnostic, ...]:
    path = tmp_path / "in.csv"
    path.write_text(text)
    with pytest.raises(TableBotError) as info:
        load_inputs(path, machine or example_machine())
    return info.value.diagnostics


@pytest.mark.parametrize(
    ("text", "where", "pattern"),
    [
        ("I3,T\n1,\n", (1, 4), "T is never an input"),
        ("I3,I9\n1,\n", (1, 4), "unknown input 'I9'"),
        ("I3,I4\n1,2\n", (2, 3), r"I4: '2' is not 0 or 1"),
        ("I3,I4\n1,x\n", (2, 3), r"I4: 'x' is not 0 or 1"),
        ("I3\n²\n", (2, 1), r"I3: '²' is not 0 or 1"),
    ],
)
def test_inputs_errors_are_located(tmp_path: Path, text: str, where: tuple[int, int], pattern: str) -> None:
    diagnostics = inputs_error(tmp_path, text)
    assert len(diagnostics) == 1
    d = diagnostics[0]
    assert (d.line, d.column) == where
    assert re.search(pattern, d.message) and d.hint


def test_inputs_all_problems_at_once(tmp_path: Path) -> None:
    assert len(inputs_error(tmp_path, "I3,T,I9\n5,,\n1,,\nx,,\n")) == 4


def test_inputs_empty_file(tmp_path: Path) -> None:
    (d,) = inputs_error(tmp_path, "")
    assert "empty" in d.message and (d.line, d.column) == (1, 1)


@pytest.mark.parametrize("value", ["-1", "²", "1.5"])
def test_inputs_pulses_must_be_counts(tmp_path: Path, value: str) -> None:
    table = "state,T,C1,M1,C1_load,timer,next\n1,1,,3,4,9,1\n"
    machine = compile_table(load_table(write_table(tmp_path, table, COUNTER_ROBOT)))
    (d,) = inputs_error(tmp_path, f"C1\n{value}\n", machine)
    assert "pulse count" in d.message and (d.line, d.column) == (2, 1)


def test_the_compiled_trace_writer_writes_pythons_bytes() -> None:
    """sinks.trace_text writes a simulator block's lines in compiled code: every number as Python writes it
    (json: repr of the rounded double, exponent form below 1e-4, -0.0, ties rounded half to even on the
    binary value), state names as JSON (quotes, non-ASCII), rows null when none fired."""
    import numpy as np

    from tablebot.formats.trace_lines import exact_round_array
    from tablebot.sinks.trace_text import DECIMAL, INT, ROW, STATE, block_bytes, json_names

    rng = np.random.default_rng(4)
    n = 20_000
    hairs = rng.choice([0.0, 5e-6, -5e-6, 4.99999e-6], n // 4)  # ties and near-ties at five places
    raw = np.concatenate(
        [
            rng.uniform(-3, 3, n // 4),
            rng.uniform(-1e-4, 1e-4, n // 4),
            rng.integers(-(10**6), 10**6, n // 4) / 10**5 + hairs,
            rng.choice([0.0, -0.0, 1e-5, -1e-5, 9.5e-5, 1e-4, 123456.78912, -7.0, 0.5, 2.5e-6], n // 4),
        ]
    )
    states = ["Seek", 29, 'Dreh\u00fcng "rechts"', "\u2028x"]
    names = json_names(states)
    ints = rng.integers(-(2**40), 2**40, n)
    rows = rng.integers(-1, 30, n)
    which = rng.integers(0, len(states), n)
    for places in (1, 3, 4, 5, 6):
        rounded = exact_round_array(raw, places)
        text = block_bytes(
            [b'{"t":', b',"row":', b',"state":', b',"x":', b"}\n"],
            [INT, ROW, STATE, DECIMAL],
            [ints, rows, which, rounded],
            [0, 0, 0, places],
            names,
        )
        assert text is not None
        expected = "".join(
            json.dumps(
                {"t": int(i), "row": None if r < 0 else int(r), "state": states[s], "x": x},
                separators=(",", ":"),
                ensure_ascii=False,
            )
            + "\n"
            for i, r, s, x in zip(ints, rows, which, rounded.tolist(), strict=True)
        )
        assert text.decode() == expected
    # what it cannot write the Python way, it leaves to Python
    assert block_bytes([b"", b"\n"], [DECIMAL], [np.array([np.inf])], [3], []) is None
    assert block_bytes([b"", b"\n"], [DECIMAL], [np.array([2.0**60])], [3], []) is None
