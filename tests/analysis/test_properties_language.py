"""The property file format and the condition language: parsing, evaluation, located errors."""

from __future__ import annotations

from pathlib import Path

import pytest

from tablebot.analysis.conditions import ConditionError, parse_condition
from tablebot.analysis.properties import Property, find_property_files, load_properties
from tablebot.diagnostics import TableBotError
from tablebot.formats.table_read import load_table
from tablebot.machine import compile_table

pytestmark = [pytest.mark.kernel_free]

FIX = Path(__file__).resolve().parents[1] / "fixtures" / "analysis"
EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "bumberbot" / "table.csv"
BB = compile_table(load_table(EXAMPLE))
I3, I4, T = BB.input_bits["I3"], BB.input_bits["I4"], BB.timer_bit


def holds(text: str, events: int = 0, row: int = -1, state: int = 1, outputs: tuple[int, ...] = (0, 0)) -> bool:
    return parse_condition(text, BB)((events, row, BB.state_index(state), outputs))


def test_events_states_outputs_and_rows() -> None:
    assert holds("I3", I3) and not holds("I3", I4) and holds("not I3", I4)
    assert holds("I3 or I4", I4) and not holds("I3 and I4", I4) and holds("I3 and I4", I3 | I4)
    assert holds("T", T) and not holds("T")
    assert holds("state == 20", state=20) and holds("state != 20", state=1)
    assert holds("state in [22, 24, 26]", state=24) and not holds("state in [22, 24]", state=26)
    assert holds("M1 < 0 and M2 >= 3", outputs=(-1, 3)) and not holds("M1 <= -2", outputs=(-1, 3))
    assert holds("line == 2", row=0) and not holds("line == 2", row=1) and holds("fired", row=5)
    assert holds("line in [2, 38]", row=36)
    assert holds("true") and not holds("false")


def test_precedence_and_parentheses() -> None:
    # not > and > or: "I3 or I4 and T" is I3 or (I4 and T)
    assert holds("I3 or I4 and T", I3) and not holds("I3 or I4 and T", I4)
    assert not holds("(I3 or I4) and T", I3) and holds("(I3 or I4) and T", I3 | T)
    assert holds("not (I3 and I4)", I3)


def test_input_bits_are_recorded_for_the_model() -> None:
    assert parse_condition("I3 or (state == 1 and not I4)", BB).input_bits == I3 | I4
    assert parse_condition("T and M1 > 0", BB).input_bits == 0
    both = Property("p", "p", "when", when=parse_condition("I3", BB), then=parse_condition("not I3", BB))
    assert both.watch == I3  # shared inputs are OR-ed (a sum once turned I3 into another bit)


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("I9", "unknown name 'I9'"),
        ("state == 23", "no state 23"),
        ("state < 3", "==, != or in"),
        ("I3 == 1", "I3 is an event"),
        ("M1", "the condition ends too early"),
        ("M1 > fast", "needs a number"),
        ("(I3 or I4", "the condition ends too early"),
        ("I3 I4", "unexpected 'I4'"),
        ("line == 1", "no row of the table is on line 1"),
        ("", "empty"),
        ("__import__('os').system('true')", "cannot read"),  # no eval, ever
    ],
)
def test_bad_conditions(text: str, message: str) -> None:
    with pytest.raises(ConditionError, match=message.replace("(", r"\(").replace("[", r"\[")):
        parse_condition(text, BB)


def write(tmp_path: Path, text: str) -> Path:
    path = tmp_path / "p.toml"
    path.write_text(text)
    return path


def test_kinds_and_durations(tmp_path: Path) -> None:
    path = write(
        tmp_path,
        """
[a]
never = "state == 20 and M1 > 0"
[b]
when = "I3"
then = "state == 20"
within = "50 ms"
[c]
when = "I3"
then = "state == 20"
within = "1.5 s"
[d]
when = "I3"
then = "state == 20"
within = 3
[e]
always_reachable = "state == 1"
text = "back to 1"
level = "warning"
note = "why"
""",
    )
    props = {p.name: p for p in load_properties(BB, [path])}
    assert props["a"].kind == "never" and props["a"].horizon == 1
    assert (props["b"].within, props["c"].within, props["d"].within) == (5, 150, 3)
    assert props["b"].horizon == 6  # the model keeps timer values up to within + 1 exact
    assert props["e"].text == "back to 1" and props["e"].level == "warning" and props["e"].note == "why"
    assert props["b"].line == 4 and props["b"].source == str(path)


def test_errors_are_all_reported_with_lines(tmp_path: Path) -> None:
    path = write(
        tmp_path,
        """[ok]
never = "I3"

[two_kinds]
never = "I3"
always = "I4"

[bad_duration]
when = "I3"
then = "I4"
within = "15 ms"

[typo]
nevr = "I3"
""",
    )
    with pytest.raises(TableBotError) as info:
        load_properties(BB, [path])
    found = [(d.line, d.message) for d in info.value.diagnostics]
    assert (
        4,
        "property two_kinds needs exactly one of never, always, reachable, always_reachable, when (found 2)",
    ) in found
    assert any(line == 8 and "not a whole number of 10 ms ticks" in m for line, m in found)
    assert any(line == 13 and "unknown key 'nevr'" in m for line, m in found)


def test_toml_syntax_error_is_located(tmp_path: Path) -> None:
    with pytest.raises(TableBotError) as info:
        load_properties(BB, [write(tmp_path, '[a]\nnever = "I3\n')])
    (d,) = info.value.diagnostics
    assert d.line == 2 and "TOML syntax" in d.message


def test_properties_in_the_robot_file(tmp_path: Path) -> None:
    robot = (FIX / "robot.toml").read_text() + '\n[properties.stops]\nnever = "state == 2 and M1 != 0"\n'
    (tmp_path / "robot.toml").write_text(robot)
    (tmp_path / "t.csv").write_text((FIX / "bump.csv").read_text())
    machine = compile_table(load_table(tmp_path / "t.csv"))
    (prop,) = load_properties(machine, [])
    assert prop.name == "stops" and prop.source == str(tmp_path / "robot.toml")
    assert prop.line == robot.splitlines().index("[properties.stops]") + 1


def test_a_copied_properties_section_reads_in_a_side_file(tmp_path: Path) -> None:
    path = write(tmp_path, '[properties.x]\nnever = "I3"\n')
    assert [p.name for p in load_properties(BB, [path])] == ["x"]


def test_property_files_beside_the_table(tmp_path: Path) -> None:
    assert find_property_files(FIX / "bump.csv") == [FIX / "bump.properties.toml"]
    assert find_property_files(EXAMPLE) == [EXAMPLE.parent / "properties.toml"]
    assert find_property_files(tmp_path / "t.csv") == []
