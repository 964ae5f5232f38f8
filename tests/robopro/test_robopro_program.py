"""``export --to robopro-program``: the generated ROBO Pro program, run by the element interpreter, takes
the engine's decisions tick for tick (random tables, counters, both matching rules); its lists hold the
document's encoding; it keeps to the vocabulary of real programs (always checked against the committed
vocabulary; against the corpus itself in test_robopro_corpus.py)."""

from __future__ import annotations

import itertools
import random
import xml.etree.ElementTree as ET
from dataclasses import astuple, replace
from typing import TYPE_CHECKING

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from core_helpers import EXAMPLE, ROOT
from tablebot.diagnostics import TableBotError
from tablebot.engine import Engine
from tablebot.formats.inputs_csv import TickInput, load_inputs
from tablebot.formats.table_read import load_table
from tablebot.machine import NO_ROW, Machine, compile_table, first_match
from tablebot.robopro.executor import run
from tablebot.robopro.fit import plan, problems
from tablebot.robopro.interpret import InterpreterError, Program, Run
from tablebot.robopro.program import Rule, generate
from tablebot.table import Row, Table
from tablebot.testing.random_tables import Shape, random_case, random_inputs, random_table, with_match
from tablebot.testing.rpp_vocabulary import problems as vocabulary_problems

pytestmark = [pytest.mark.kernel_free]

if TYPE_CHECKING:
    from pathlib import Path
    from typing import Any

COUNTERS = ROOT / "examples" / "bumberbot-counters"


def lists_of(text: str) -> dict[str, list[int]]:
    root = ET.fromstring(text.encode("utf-8"))
    return {
        o.attrib["name"]: [int(i.attrib["value"]) for i in o.findall("init")]
        for o in root.iter("o")
        if o.get("classname") == "ftProDataArray1D"
    }


# --- the reference ------------------------------------------------------------------------------------


def reference(machine: Machine, inputs: list[TickInput], rule: Rule) -> list[tuple]:
    """The tick rule with either matching rule: (event, row, state, timer, outputs, counters) per tick.
    With rule "always" it must equal the engine (checked below), so it is the engine's rule plus the one
    condition the document adds: no lookup on a tick whose event set is empty."""
    state, timer = machine.initial_state, machine.initial_timer
    counters = [0] * len(machine.counter_bits)
    outputs = (0,) * len(machine.output_names)
    by_state = [[r for r in machine.rows if r.state == s] for s in range(len(machine.states))]
    out = []
    for tick, given_input in enumerate(inputs):
        if tick:
            timer = max(0, timer - 1)
            counters = [max(0, c - p) for c, p in zip(counters, given_input.pulses, strict=True)]
        event = given_input.mask & machine.input_mask
        event |= machine.timer_bit if timer == 0 else 0
        event |= sum(b for b, c in zip(machine.counter_bits, counters, strict=True) if c == 0)
        row = None if rule == "document" and event == 0 else first_match(by_state[state], event)
        if row is not None:
            outputs = tuple(old if new is None else new for old, new in zip(outputs, row.outputs, strict=True))
            counters = [old if new is None else new for old, new in zip(counters, row.loads, strict=True)]
            state, timer = row.next, row.timer
        out.append((event, NO_ROW if row is None else row.index, state, timer, outputs, tuple(counters)))
    return out


def engine_ticks(machine: Machine, inputs: list[TickInput]) -> list[tuple]:
    engine = Engine(machine)
    out = []
    for given_input in inputs:
        engine.step(given_input.mask, given_input.pulses)
        out.append((engine.event, engine.row, engine.state, engine.timer, engine.outputs, tuple(engine.counters)))
    return out


def program_ticks(table: Table, text: str, inputs: list[TickInput], rule: Rule) -> list[tuple]:
    """The generated program's decisions (the executor runs ``generate(table, rule)``, which is ``text``)."""
    assert generate(table, rule) == text  # the same table and rule give the same bytes
    return [astuple(d) for d in run(table, inputs, rule)]


def fitting(table: Table, sections: dict) -> Table:
    """A random table the program can hold: speeds within the document's 0..6, the robot wired as given."""
    rows = tuple(
        replace(r, motors=tuple(None if m is None else max(-6, min(6, m)) for m in r.motors)) for r in table.rows
    )
    robot = replace(table.robot, sections={"robopro": sections})
    return Table(robot=robot, events=table.events, rows=rows, path=table.path)


# --- the examples ---------------------------------------------------------------------------------------


def test_bumberbot_lists_hold_the_documents_encoding() -> None:
    table = load_table(EXAMPLE / "table.csv")
    lists = lists_of(generate(table, "document"))
    assert sorted(lists) == ["Action", "Event", "Timer"]
    assert (lists["Event"][0], lists["Action"][0], lists["Timer"][0]) == (88, 5120, 50)
    assert len(lists["Event"]) == len(table.rows) == 37


def test_bumberbot_program_keeps_to_real_programs() -> None:
    text = generate(load_table(EXAMPLE / "table.csv"), "document")
    assert vocabulary_problems(text) == []
    assert text.startswith('<?xml version="1.0" encoding="UTF-8" standalone="yes"?>\n')
    names = [
        o.get("name") for o in ET.fromstring(text.encode()).iter("o") if o.get("classname") == "ftProSubroutineFunction"
    ]
    assert names == ["Main program", "DetectEvent", "DetermineAction", "ExecuteAction", "CountDown"]
    assert "Collision Frontal" in text and "Seek: turn" in text  # descriptions and state names as comments


@pytest.mark.parametrize("rule", ["document", "always"])
def test_bumberbot_recorded_run(rule: Rule) -> None:
    """500 ticks of the recorded inputs, from just before its first bump, engine against program."""
    table = load_table(EXAMPLE / "table.csv")
    machine = compile_table(table)
    inputs = load_inputs(EXAMPLE / "inputs.csv", machine)[390:890]
    expected = reference(machine, inputs, rule)
    assert program_ticks(table, generate(table, rule), inputs, rule) == expected
    assert len({row for _, row, *_ in expected}) > 3  # rows did fire


def test_counters_reach_the_program() -> None:
    table = load_table(COUNTERS / "table.csv")
    text = generate(table)
    lists = lists_of(text)
    assert sorted(lists) == ["Action", "C1 load", "C2 load", "Event", "Timer"]
    assert lists["C1 load"][3] == 107 and lists["C1 load"][0] == -1  # Seek - Straight loads 107 pulses
    assert vocabulary_problems(text) == []
    rng = random.Random(4)
    inputs = random_inputs(rng, table, 300, density=0.05, max_pulses=3)
    assert program_ticks(table, text, inputs, table.robot.match) == engine_ticks(compile_table(table), inputs)


# --- random tables ----------------------------------------------------------------------------------------

WIRINGS = st.fixed_dictionaries(
    {"controller": st.sampled_from(["tx", "txt"])},
    optional={
        "I2": st.fixed_dictionaries({"terminal": st.just("I6"), "active": st.sampled_from([0, 1])}),
        "M2": st.fixed_dictionaries({"output": st.just("M4"), "forward": st.sampled_from(["cw", "ccw"])}),
    },
)


@settings(max_examples=30, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    seed=st.integers(0, 2**32),
    counters=st.integers(0, 2),
    inputs=st.integers(0, 3),
    lamps=st.integers(0, 2),
    rule=st.sampled_from(["document", "always"]),
    sections=WIRINGS,
)
def test_random_tables_tick_for_tick(
    seed: int, counters: int, inputs: int, lamps: int, rule: Rule, sections: dict[str, Any]
) -> None:
    rng = random.Random(seed)
    shape = Shape(states=3, rows=8, inputs=inputs, counters=counters, lamps=lamps, max_timer=4, max_load=5)
    table = with_match(fitting(random_table(rng, shape), sections), rule)
    ticks = random_inputs(rng, table, 50, density=0.25, max_pulses=2)
    machine = compile_table(table)
    expected = reference(machine, ticks, rule)
    assert expected == engine_ticks(machine, ticks)  # the reference is the engine's rule, the table's match
    assert program_ticks(table, generate(table, rule), ticks, rule) == expected


@pytest.mark.parametrize("rule", ["document", "always"])
def test_the_program_follows_the_tables_own_rule_where_the_rules_part(rule: Rule) -> None:
    """Generated for the table's own rule (the robot file's match, no rule given), on tables and inputs where
    the two rules take different decisions: the program takes the engine's."""
    table, ticks = random_case(
        random.Random(f"robopro-{rule}"),
        Shape(states=3, rows=8, inputs=2, counters=1, max_timer=4, max_load=5, match=rule),
    )
    table = fitting(table, {"controller": "txt"})  # the TXT counts pulses; the ROBO Interface has no counters
    assert [astuple(d) for d in run(table, ticks)] == engine_ticks(compile_table(table), ticks)


def test_the_rules_differ_where_the_document_says() -> None:
    """A row that requires no event fires on an empty tick under "always", never under "document"."""
    base = random_table(random.Random(7), Shape(states=1, rows=1, inputs=1, counters=0))
    row = replace(base.rows[0], events=frozenset(), timer=3, motors=(2, -2))
    table = fitting(Table(robot=replace(base.robot, initial_timer=5), events=base.events, rows=(row,)), {})
    ticks = [TickInput(0, ())] * 3
    cases: tuple[tuple[Rule, list[int]], ...] = (("always", [0, 0, 0]), ("document", [NO_ROW, NO_ROW, NO_ROW]))
    for rule, fired in cases:
        got = program_ticks(table, generate(table, rule), ticks, rule)
        assert [t[1] for t in got] == fired
        assert got == reference(compile_table(table), ticks, rule)


# --- what does not fit -------------------------------------------------------------------------------------


def test_check_says_why_a_table_does_not_fit(tmp_path: Path) -> None:
    (tmp_path / "robot.toml").write_text(
        'name = "Big"\ninitial_state = 1\n[inputs]\nI1 = "a"\n[motors]\nM1 = "m"\nM2 = "n"\nM3 = "o"\n'
        '[lamps]\nL1 = "lamp"\n[counters]\nC1 = "M1"\n'
    )
    (tmp_path / "t.csv").write_text("state,I1,M1,M2,M3,timer,next\n1,1,7,0,0,40000,300\n300,,0,0,0,0,1\n")
    found = [d.message for d in problems(load_table(tmp_path / "t.csv"))]
    text = "\n".join(found)
    for expected in ("3 motors", "ROBO Interface has no counter inputs", "speed 7", "timer 40000", "number 300"):
        assert expected in text, (expected, found)
    with pytest.raises(TableBotError):
        generate(load_table(tmp_path / "t.csv"))


def test_lamps_are_lamp_outputs_and_one_on_a_motors_output_is_refused(tmp_path: Path) -> None:
    """A lamp is ROBO Pro's lamp output (``ftProDataOutSngl``) on the single output the motors leave free, or the
    one ``[robopro]`` names; one wired to a motor's output is refused, naming both."""
    (tmp_path / "robot.toml").write_text(
        'name = "Lit"\ninitial_state = 1\n[inputs]\nI1 = "a"\n[motors]\n'
        'M1 = "m"\n[lamps]\nL1 = "front"\nL2 = "back"\n[robopro]\nL2 = "O8"\n'
    )
    (tmp_path / "t.csv").write_text("state,I1,M1,L1,L2,timer,next\n1,1,3,8,,0,2\n2,,,0,5,0,1\n")
    table = load_table(tmp_path / "t.csv")
    root = ET.fromstring(generate(table).encode("utf-8"))
    assert sorted(o.get("output", "") for o in root.iter("o") if o.get("classname") == "ftProDataOutSngl") == [
        "2",
        "2",
        "2",
        "7",
        "7",
        "7",
    ]  # O3 and O8: each turned off at the start, then Off and On by the lists
    ticks = [TickInput(1, ()), TickInput(0, ()), TickInput(1, ())]
    assert [d.outputs for d in run(table, ticks)] == [(3, 8, 0), (0, 0, 5), (3, 8, 5)]  # a blank L2 keeps it
    assert [astuple(d) for d in run(table, ticks)] == engine_ticks(compile_table(table), ticks)
    (tmp_path / "robot.toml").write_text((tmp_path / "robot.toml").read_text().replace('"O8"', '"O2"'))
    found = [d.message for d in problems(load_table(tmp_path / "t.csv"))]
    assert found == ["lamp L2 is wired to O2, an output of motor M1"]


def test_a_line_sensor_is_refused_with_the_reason() -> None:
    found = problems(load_table(ROOT / "examples" / "line-follower" / "table.csv"))
    assert found and "digital 10 V" in found[0].message and found[0].line is not None


def test_the_interpreter_refuses_an_ambiguous_branch() -> None:
    """TM starting at -1 would make the timer branch read a negative value: "> 0" or "≠ 0"?"""
    text = generate(load_table(EXAMPLE / "table.csv"))
    run = Run(Program(text.replace('"=" datatype="3" value="0"', '"=" datatype="3" value="-1"', 1)))
    with pytest.raises(InterpreterError, match="negative"):
        for _ in range(3):
            run.tick({}, {})


def test_rows_and_state_numbers() -> None:
    table = load_table(EXAMPLE / "table.csv")
    p = plan(table)
    assert p.events == ("T", "I3", "I4", "I5", "I7", "I8") and p.shift == 6
    assert [p.encode(r) for r in table.rows[:1]] == [(88, 5120, 50)]
    assert isinstance(table.rows[0], Row)


# --- the layout ---------------------------------------------------------------------------------------------


def wire_segments(text: str) -> dict[str, list[tuple[str, tuple[int, int], tuple[int, int]]]]:
    found = {}
    for function in ET.fromstring(text.encode()).iter("o"):
        if function.get("classname") == "ftProSubroutineFunction":
            segments = []
            for wire in function.findall("o"):
                if wire.get("classname") in ("ftProFlowWire", "ftProDataWire"):
                    points = [(int(p.attrib["x"]), int(p.attrib["y"])) for p in wire.findall("xy")]
                    segments += [(wire.attrib["id"], a, b) for a, b in itertools.pairwise(points)]
            found[function.attrib["name"]] = segments
    return found


def crossing(one: tuple, other: tuple) -> bool:
    """Two wire segments cross inside both, or run along each other."""
    (_, a1, b1), (_, a2, b2) = one, other
    if (a1[1] == b1[1]) != (a2[1] == b2[1]):
        (ha, hb), (va, vb) = ((a1, b1), (a2, b2)) if a1[1] == b1[1] else ((a2, b2), (a1, b1))
        return min(ha[0], hb[0]) < va[0] < max(ha[0], hb[0]) and min(va[1], vb[1]) < ha[1] < max(va[1], vb[1])
    span = 0 if a1[1] == b1[1] else 1  # both horizontal: they span x; both vertical: y
    if a1[1 - span] != a2[1 - span]:
        return False
    low = max(min(a1[span], b1[span]), min(a2[span], b2[span]))
    return min(max(a1[span], b1[span]), max(a2[span], b2[span])) > low


def test_crossing_sees_crossings() -> None:
    assert crossing(("a", (0, 4), (8, 4)), ("b", (4, 0), (4, 8)))
    assert crossing(("a", (0, 4), (8, 4)), ("b", (4, 4), (12, 4)))  # along each other
    assert not crossing(("a", (0, 4), (8, 4)), ("b", (8, 0), (8, 8)))  # meeting at an end
    assert not crossing(("a", (0, 4), (8, 4)), ("b", (0, 8), (8, 8)))


@pytest.mark.parametrize("which", ["bumberbot-document", "counters", "random"])
def test_wires_do_not_cross_and_everything_sits_on_the_grid(which: str) -> None:
    if which == "bumberbot-document":
        text = generate(load_table(EXAMPLE / "table.csv"), "document")
    elif which == "counters":
        text = generate(load_table(COUNTERS / "table.csv"))
    else:
        table = random_table(random.Random(11), Shape(states=3, rows=8, inputs=3, counters=2))
        text = generate(fitting(table, {"controller": "tx"}))
    for name, segments in wire_segments(text).items():
        crossed = [
            (a[0], b[0]) for n, a in enumerate(segments) for b in segments[n + 1 :] if a[0] != b[0] and crossing(a, b)
        ]
        assert crossed == [], f"{name}: wires cross"
        assert all(x % 4 == 0 and y % 4 == 0 for _, p, q in segments for x, y in (p, q)), name


def test_hostile_texts_stay_text(tmp_path: Path) -> None:
    """Descriptions, state names, labels and the robot name that end tags and attributes stay text: the
    file parses, keeps to the vocabulary, and shows each text as written."""
    from hostile import HOSTILE, INJECTED, write_project

    table = load_table(write_project(tmp_path / "p"))
    text = generate(table)
    root = ET.fromstring(text.encode())
    assert vocabulary_problems(text) == []
    assert not any(element.tag.startswith("evil") for element in root.iter())
    shown = "\n".join(o.get("text", "") for o in root.iter("o")) + root.findtext("title", "")
    for hostile in HOSTILE[2:4] + HOSTILE[9:]:
        assert hostile in shown
    assert "<evil" not in text and INJECTED[2] == "<evil"
    assert run(table, [TickInput(0, ())] * 3)  # and it runs


def test_the_commands(tmp_path: Path) -> None:
    from typer.testing import CliRunner

    from tablebot.cli import app

    runner = CliRunner()
    out = tmp_path / "out"
    result = runner.invoke(app, ["export", str(EXAMPLE), "--to", "robopro-program", str(out)])
    assert result.exit_code == 0, result.output
    assert lists_of((out / "BumberBot.rpp").read_text(encoding="utf-8"))["Event"][0] == 88
    refused = tmp_path / "refused"
    result = runner.invoke(
        app, ["export", str(ROOT / "examples" / "line-follower"), "--to", "robopro-program", str(refused)]
    )
    assert result.exit_code == 2 and "line sensor" in result.output and not refused.exists()
    result = runner.invoke(app, ["check", str(ROOT / "examples" / "line-follower"), "--target", "robopro-program"])
    assert result.exit_code == 2 and "robopro-program: input I1 is a line sensor" in " ".join(result.output.split())


def test_a_wrong_robopro_section_is_a_located_error(tmp_path: Path) -> None:
    from tablebot.robot import load_robot

    (tmp_path / "robot.toml").write_text(
        'name = "W"\ninitial_state = 1\n[inputs]\nI3 = "a"\n[motors]\nM1 = "m"\n[robopro]\ncontroller = "nxt"\n'
        'I3 = "I9"\nM1 = { output = "M1", forward = "left" }\nX1 = "I1"\n'
    )
    with pytest.raises(TableBotError) as info:
        load_robot(tmp_path / "robot.toml")
    found = {(d.line, d.message.split(":")[0]) for d in info.value.diagnostics}
    assert {line for line, _ in found} == {8, 9, 10, 11}
    assert any("forward = 'left'" in d.message for d in info.value.diagnostics)
