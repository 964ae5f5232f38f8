"""``import --from scxml`` reads what ``export --to scxml`` wrote, the same table bytes back, and refuses anything
else with file, line and column: a changed element, a foreign attribute, a DOCTYPE (an entity bomb), broken XML."""

from __future__ import annotations

import random
import subprocess
import sys
from dataclasses import replace
from pathlib import Path

import pytest

from tablebot.diagnostics import TableBotError
from tablebot.formats.statecharts.read_scxml import read_scxml
from tablebot.formats.statecharts.scxml import export_scxml
from tablebot.formats.table_read import load_table, resolve_table_path
from tablebot.formats.table_write import format_table
from tablebot.table import Table
from tablebot.testing.random_tables import Shape, random_table

EXAMPLES = ("bumberbot", "bumberbot-counters", "line-follower", "obstacle-avoider")


def _rows(table: Table) -> list[object]:
    return [replace(row, line=0) for row in table.rows]  # a CSV's line numbers are not in a statechart


@pytest.mark.parametrize("example", EXAMPLES)
def test_an_example_reads_back_as_the_same_table_bytes(example: str) -> None:
    table = load_table(resolve_table_path(Path("examples") / example))
    text = export_scxml([table])
    (back,) = read_scxml(text, "machine.scxml")
    assert format_table(back) == format_table(table)
    assert _rows(back) == _rows(table) and back.robot.match == table.robot.match
    assert export_scxml([back]) == text


@pytest.mark.parametrize("seed", range(20))
def test_random_tables_read_back_as_the_same_table_bytes(seed: int) -> None:
    rng = random.Random(seed)
    table = random_table(rng, Shape(states=5, rows=12, lamps=seed % 3, counters=seed % 2))
    (back,) = read_scxml(export_scxml([table]), "machine.scxml")
    assert format_table(back) == format_table(table) and _rows(back) == _rows(table)


def _refused(text: str) -> str:
    with pytest.raises(TableBotError) as caught:
        read_scxml(text, "in.scxml")
    return caught.value.diagnostics[0].render()


@pytest.fixture(scope="module")
def text() -> str:
    return export_scxml([load_table(Path("examples/bumberbot/table.csv"))])


def test_a_changed_condition_is_refused_at_its_line_and_column(text: str) -> None:
    lines = text.splitlines()
    at = next(i for i, line in enumerate(lines) if "has_I3 &amp;&amp; has_I4" in line)
    lines[at] = lines[at].replace("has_I3 &amp;&amp; has_I4", "has_I3")
    said = _refused("\n".join(lines))
    assert said.startswith(f"in.scxml:{at + 1}:{lines[at].index('<') + 1}: error: <transition> has cond=")
    assert "where tablebot writes cond='is_pending && has_I3 && has_I4'" in said


def test_a_foreign_attribute_a_missing_element_and_another_namespace_are_refused(text: str) -> None:
    foreign = text.replace('<data id="M1"', '<data foo="1" id="M1"')
    assert "has foo='1', where tablebot writes no foo" in _refused(foreign)
    assert "holds 4 elements, where tablebot writes 5" in _refused(
        text.replace('        <assign location="is_pending" expr="0"/>\n', "", 1)
    )
    assert "in the namespace 'urn:other'" in _refused(text.replace("<scxml ", '<scxml xmlns:o="urn:other" o:x="1" '))


def test_an_entity_bomb_is_refused_before_any_entity_is_declared(text: str) -> None:
    bomb = (
        '<!DOCTYPE scxml [<!ENTITY a "aaaaaaaaaa"><!ENTITY b "&a;&a;&a;&a;&a;&a;&a;&a;&a;&a;">'
        '<!ENTITY c "&b;&b;&b;&b;&b;&b;&b;&b;&b;&b;">]>\n'
    )
    said = _refused(text.replace("<scxml ", bomb + "<scxml ", 1).replace('name="BumberBot"', 'name="&c;"'))
    assert "in.scxml:3:1: error: a DOCTYPE" in said


def test_broken_xml_and_a_state_id_tablebot_never_writes_are_located(text: str) -> None:
    assert _refused(text[:200]).startswith("in.scxml:")
    assert "'s02' is no state id tablebot writes" in _refused(text.replace('initial="s2"', 'initial="s02"'))


def test_the_import_command_writes_the_table_and_refuses_with_a_location(tmp_path: Path, text: str) -> None:
    source = tmp_path / "machine.scxml"
    source.write_text(text, encoding="utf-8")
    command = [sys.executable, "-m", "tablebot", "import", str(source), "--from", "scxml"]
    done = subprocess.run([*command, "--out", str(tmp_path / "table.csv")], capture_output=True, text=True, check=False)
    assert done.returncode == 0, done.stderr
    assert (tmp_path / "table.csv").read_text() == format_table(load_table(Path("examples/bumberbot/table.csv")))
    source.write_text(text.replace('tb:match="document"', 'tb:match="sometimes"'), encoding="utf-8")
    done = subprocess.run(command, capture_output=True, text=True, check=False)
    assert done.returncode == 2 and "Traceback" not in done.stderr
    assert "matching rule 'sometimes' is not one of document, always" in done.stderr


def test_the_documents_name_is_an_identifier_and_the_robots_name_reads_back() -> None:
    """SCION 4 (@scion-scxml/scxml) makes a JavaScript function's name of <scxml name>: "BumberBot with counters" was
    a syntax error there, and a crafted robot name would have been code. The name is now letters, digits and _,
    and the robot's own name is in tb:name."""
    table = load_table(Path("examples/bumberbot-counters/table.csv"))
    text = export_scxml([table])
    assert 'name="BumberBot_with_counters"' in text and 'tb:name="BumberBot with counters"' in text
    (back,) = read_scxml(text, "machine.scxml")
    assert back.robot.name == "BumberBot with counters"
    crafted = replace(table, robot=replace(table.robot, name="x(){}; process.exit(3); function y"))
    assert 'name="x______process_exit_3___function_y"' in export_scxml([crafted])
