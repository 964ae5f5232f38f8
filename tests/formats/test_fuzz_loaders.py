"""Fuzzing every loader with structure-aware generated files (issue 14): tables, robot files, worlds, inputs,
properties, ROBO Pro lists and states.csv, .rpp programs and traces, with deep nesting, wrong types in
every key, huge numbers, NUL bytes and non-UTF-8. Only a located TableBotError may ever escape; through
the CLI, no internal error.

CI runs a fixed, derandomized set in well under a minute. A person runs the long mode with
``TABLEBOT_FUZZ=long`` (1,500 examples per loader, random seeds) or ``TABLEBOT_FUZZ=N`` examples. The strategies
and checks are tests/formats/fuzz_helpers.py.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest
from hypothesis import given
from hypothesis import strategies as st

from fuzz_helpers import (
    FUZZ,
    SCALAR,
    TEXT,
    VALUE,
    csv_text,
    deep,
    document,
    expect_located,
    in_folder,
    mangle,
    no_internal_error,
    toml_key,
    toml_value,
)
from tablebot.analysis.properties import load_properties
from tablebot.formats.inputs_csv import load_inputs
from tablebot.formats.table_read import load_table
from tablebot.formats.trace_lines import read_trace
from tablebot.machine import compile_table
from tablebot.robopro.lists import read_table
from tablebot.robopro.rpp_edit import write_lists
from tablebot.robot import BUMBERBOT, load_robot
from tablebot.sim.model.world import load_world

pytestmark = [pytest.mark.kernel_free]

ROOT = Path(__file__).resolve().parents[2]
EXAMPLE = ROOT / "examples" / "bumberbot"
RPP = Path(__file__).resolve().parents[1] / "fixtures" / "rpp" / "engine.rpp"
MACHINE = compile_table(load_table(EXAMPLE / "table.csv"))

TABLE_HEADER = [
    "description",
    "state",
    "T",
    "I3",
    "I4",
    "I5",
    "I7",
    "I8",
    "M1_dir",
    "M1_speed",
    "M2_dir",
    "M2_speed",
    "timer",
    "next",
]
ROBOT_KEYS = ["name", "tick_ms", "initial_state", "initial_timer"]
ROBOT_SECTIONS = {
    "inputs": ["I3", "A", "T"],
    "motors": ["M1", "M2"],
    "counters": ["C1"],
    "lamps": ["L1"],
    "states": ["1", "2", "seek"],
    "sim": ["world"],
    "wiring": ["I3"],
    "properties": ["p"],
}
WORLD_SECTIONS = {
    "arena": ["walls"],
    "start": ["at", "heading"],
    "lamp": ["at", "intensity", "radius"],
    "box": ["at", "size", "angle"],
    "circle": ["at", "radius"],
    "segment": ["from", "to"],
}
PROPERTY_VALUES = st.one_of(
    VALUE,
    st.lists(
        st.sampled_from(
            [
                "state",
                "==",
                "20",
                "and",
                "or",
                "not",
                "(",
                ")",
                "M1",
                ">",
                "-1",
                "I3",
                "T",
                "in",
                "[",
                "]",
                ",",
                "line",
                "fired",
                "99999999999999999999",
                "²",
                "ticks",
                "ms",
                "s",
            ]
        ),
        max_size=8,
    ).map(" ".join),
)


# --- the loaders ------------------------------------------------------------------------------------------


@FUZZ
@given(st.data(), csv_text(TABLE_HEADER), deep(document(ROBOT_KEYS, ROBOT_SECTIONS)), st.booleans())
def test_table_and_robot(data: st.DataObject, table: str, robot: str, with_robot: bool) -> None:
    files = {"table.csv": mangle(table, data)}
    if with_robot:
        files["robot.toml"] = mangle(robot, data)

    def run(folder: Path) -> None:
        expect_located(lambda: compile_table(load_table(folder / "table.csv")))
        no_internal_error("check", folder / "table.csv")

    in_folder(files, run)


@FUZZ
@given(st.data(), deep(document(ROBOT_KEYS, ROBOT_SECTIONS)))
def test_robot_file(data: st.DataObject, robot: str) -> None:
    in_folder({"robot.toml": mangle(robot, data)}, lambda f: expect_located(lambda: load_robot(f / "robot.toml")))


@FUZZ
@given(st.data(), deep(document(["name", "reach"], WORLD_SECTIONS)))
def test_world_file(data: st.DataObject, world: str) -> None:
    in_folder({"arena.toml": mangle(world, data)}, lambda f: expect_located(lambda: load_world(f / "arena.toml")))


@FUZZ
@given(st.data(), csv_text(["I3", "I4", "I5", "I7", "I8", "tick", "T"]))
def test_inputs(data: st.DataObject, inputs: str) -> None:
    def run(folder: Path) -> None:
        expect_located(lambda: load_inputs(folder / "in.csv", MACHINE))
        no_internal_error("trace", EXAMPLE, "--inputs", folder / "in.csv")

    in_folder({"in.csv": mangle(inputs, data)}, run)


@FUZZ
@given(
    st.data(),
    st.dictionaries(
        st.one_of(st.sampled_from(["p", "bad name", "../x", "a\x00"]), st.text(max_size=4)),
        st.one_of(
            st.dictionaries(
                st.sampled_from(
                    [
                        "text",
                        "level",
                        "note",
                        "never",
                        "always",
                        "reachable",
                        "always_reachable",
                        "when",
                        "then",
                        "within",
                        "other",
                    ]
                ),
                PROPERTY_VALUES,
                max_size=5,
            ),
            VALUE,
        ),
        max_size=3,
    ),
)
def test_properties(data: st.DataObject, props: dict[str, Any]) -> None:
    text = "\n".join(f"{toml_key(k)} = {toml_value(v)}" for k, v in props.items()) + "\n"
    in_folder(
        {"p.toml": mangle(text, data)}, lambda f: expect_located(lambda: load_properties(MACHINE, [f / "p.toml"]))
    )


LIST_LINE = st.one_of(st.integers(-5, 70000).map(str), TEXT, st.just(""))


@FUZZ
@given(
    st.data(),
    st.lists(st.lists(LIST_LINE, max_size=5), min_size=3, max_size=3),
    st.one_of(st.none(), csv_text(["number", "name"])),
)
def test_robopro_lists_and_states(data: st.DataObject, lists: list[list[str]], states: str | None) -> None:
    files = {
        name: mangle("\n".join(lines) + "\n", data)
        for name, lines in zip(("event.csv", "action.csv", "timer.csv"), lists, strict=True)
    }
    if states is not None:
        files["states.csv"] = mangle(states, data)

    def run(folder: Path) -> None:
        expect_located(lambda: read_table(folder, BUMBERBOT))
        no_internal_error("import", folder, "--from", "robopro")

    in_folder(files, run)


RPP_TEXT = RPP.read_text(encoding="utf-8")
XMLISH = st.sampled_from(
    [
        '<o classname="ftProDataArray1D" name="Event" N="x²">',
        "</o>",
        "<init/>",
        "<init value='1'>",
        "<!--",
        "-->",
        "<![CDATA[",
        "]]>",
        '<?xml version="1.0" encoding="rot13"?>',
        "<cvg>",
        '<o classname="ftProDataArray1D" name="Event"/>',
        "\x00",
        "&",
        "<",
        ">",
        '"',
    ]
)


@FUZZ
@given(st.data(), st.lists(st.tuples(st.integers(0, len(RPP_TEXT)), st.integers(0, 40), XMLISH), max_size=4))
def test_rpp(data: st.DataObject, edits: list[tuple[int, int, str]]) -> None:
    text = RPP_TEXT
    for at, cut, insert in edits:
        text = text[:at] + insert + text[at + cut :]

    def run(folder: Path) -> None:
        lists = {"Event": [1, 2], "Action": [3, 4], "Timer": [5, 6]}
        expect_located(lambda: write_lists(folder / "engine.rpp", lists, folder / "out.rpp"))

    in_folder({"engine.rpp": mangle(text, data)}, run)


TRACE_KEYS = st.sampled_from(["tick", "event", "row", "state", "M1"])
TRACE_LINE = st.one_of(
    st.dictionaries(TRACE_KEYS, SCALAR).map(json.dumps),
    VALUE.map(json.dumps),
    TEXT,
    st.integers(1, 3000).map(lambda n: "[" * n + "]" * n),
)


@FUZZ
@given(st.data(), st.lists(TRACE_LINE, max_size=5))
def test_trace_files(data: st.DataObject, lines: list[str]) -> None:
    in_folder(
        {"t.jsonl": mangle("\n".join(lines) + "\n", data)}, lambda f: expect_located(lambda: read_trace(f / "t.jsonl"))
    )
