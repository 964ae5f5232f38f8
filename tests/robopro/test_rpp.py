"""``export --to robopro-rpp``: the three lists written into a ROBO Pro program, every other byte kept."""

from __future__ import annotations

import re
import shutil
import xml.etree.ElementTree as ET
from pathlib import Path
from typing import TYPE_CHECKING

import pytest
from typer.testing import CliRunner

from tablebot.cli import app
from tablebot.diagnostics import TableBotError
from tablebot.formats.table_read import load_table
from tablebot.robopro import lists as robopro
from tablebot.robopro.rpp_edit import find_lists, rewrite, write_lists

pytestmark = [pytest.mark.kernel_free]

if TYPE_CHECKING:
    from tablebot.robopro.lists import Lists

ROOT = Path(__file__).resolve().parents[2]
EXAMPLE = ROOT / "examples" / "bumberbot"
FIXTURES = Path(__file__).resolve().parents[1] / "fixtures" / "rpp"
runner = CliRunner()
INITS = re.compile(rb"""(\s*<init\b[^>]*?(?:/>|>\s*</init>))+""")
N_ATTR = re.compile(rb'\bN="\d+"')


@pytest.fixture
def lists() -> Lists:
    return robopro.encode(load_table(EXAMPLE / "table.csv"))


def _copy(tmp_path: Path, name: str) -> Path:
    target = tmp_path / name
    shutil.copy(FIXTURES / name, target)
    return target


def _list_values(data: bytes) -> dict[str, tuple[str, list[int]]]:
    root = ET.fromstring(data)
    return {
        o.attrib["name"]: (o.attrib["N"], [int(i.attrib["value"]) for i in o.findall("init")])
        for o in root.iter("o")
        if o.get("classname") == "ftProDataArray1D"
    }


def _outside_lists(data: bytes) -> bytes:
    """The file without init children and N attributes: what the export must not touch."""
    return N_ATTR.sub(b'N=""', INITS.sub(b"", data))


def test_cli_writes_the_three_lists_in_place(tmp_path: Path, lists: Lists) -> None:
    program = _copy(tmp_path, "engine.rpp")
    before = program.read_bytes()
    result = runner.invoke(app, ["export", str(EXAMPLE), "--to", "robopro-rpp", "--into", str(program)])
    assert result.exit_code == 0, result.output
    after = program.read_bytes()
    values = _list_values(after)
    assert values["Event"] == ("37", list(lists.event)) and values["Event"][1][0] == 88  # the document's example
    assert values["Action"] == ("64", list(lists.action))  # N=64 was already large enough
    assert values["Timer"] == ("37", list(lists.timer))
    assert values["Other"] == ("3", [1, 2, 3])
    assert _outside_lists(after) == _outside_lists(before)
    assert (
        b'<o classname="ftProDataVariable" id="125" name="Timer" flags=" selectable visible" value="0">\n'
        b'                <init value="7"></init>' in after
    )  # a variable named Timer is not the list


def test_inits_keep_the_programs_layout(tmp_path: Path, lists: Lists) -> None:
    program = _copy(tmp_path, "engine.rpp")
    write_lists(program, {"Event": lists.event, "Action": lists.action, "Timer": lists.timer})
    text = program.read_text()
    assert '                <init value="88"></init>\n                <init value="80"></init>\n' in text
    # the empty Timer list gets its inits as real files lay them out: <init value="…"> and </init> on lines
    # of their own, one step deeper than its closing tag
    assert '</o>\n                <init value="50">\n                </init>\n' in text
    assert (
        '<init value="500">\n                </init>\n            </o>\n            '
        '<o classname="ftProDataArray1D" id="140"' in text
    )
    again = program.read_bytes()
    write_lists(program, {"Event": lists.event, "Action": lists.action, "Timer": lists.timer})
    assert program.read_bytes() == again  # writing the same lists again changes nothing


def test_latin1_crlf_program_with_other_names(tmp_path: Path) -> None:
    program = _copy(tmp_path, "german_latin1_crlf.rpp")
    before = program.read_bytes()
    result = runner.invoke(
        app,
        [
            "export",
            str(EXAMPLE),
            "--to",
            "robopro-rpp",
            "--into",
            str(program),
            "--event-list",
            "Ereignis",
            "--action-list",
            "Aktion",
            "--timer-list",
            "Zeit",
        ],
    )
    assert result.exit_code == 0, result.output
    assert "Zeit loads its values from column" in " ".join(result.output.split())
    after = program.read_bytes()
    assert "Maschine für Tabellen".encode("latin-1") in after
    assert b"\n" not in after.replace(b"\r\n", b"")  # no bare LF was introduced
    assert _outside_lists(after) == _outside_lists(before)
    assert b'<init value="88"/>\r\n            <init value="80"/>' in after
    assert b'<!-- <o classname="ftProDataArray1D" name="Ereignis" N="1"><init value="0"/></o> -->' in after
    assert _list_values(after)["Aktion"][0] == "37"


def test_outdir_leaves_the_program_untouched(tmp_path: Path) -> None:
    program = _copy(tmp_path, "engine.rpp")
    before = program.read_bytes()
    result = runner.invoke(
        app, ["export", str(EXAMPLE), str(tmp_path / "out"), "--to", "robopro-rpp", "--into", str(program)]
    )
    assert result.exit_code == 0, result.output
    assert program.read_bytes() == before
    assert _list_values((tmp_path / "out" / "engine.rpp").read_bytes())["Timer"][0] == "37"


def test_a_missing_list_is_refused_and_nothing_is_written(tmp_path: Path) -> None:
    program = _copy(tmp_path, "missing_timer.rpp")
    before = program.read_bytes()
    result = runner.invoke(app, ["export", str(EXAMPLE), "--to", "robopro-rpp", "--into", str(program)])
    assert result.exit_code == 2
    assert "no list named 'Timer'" in result.output and "lists in the program: Action, Event" in result.output
    assert program.read_bytes() == before


def test_a_global_list_is_written_in_every_subprogram_that_has_it() -> None:
    text = (
        '<cvg><o classname="ftProDataArray1D" name="Event" globalname="Event" N="1"></o>\n'
        '<o classname="ftProDataArray1D" name="Event" globalname="Event" N="1"></o></cvg>'
    )
    assert [
        [int(i.attrib["value"]) for i in o.findall("init")]
        for o in ET.fromstring(rewrite(text, {"Event": [4, 5]})).iter("o")
    ] == [[4, 5], [4, 5]]


def test_two_different_lists_of_one_name_are_refused() -> None:
    text = (
        '<cvg><o classname="ftProDataArray1D" name="Event" globalname="Event" N="1"></o>\n'
        '<o classname="ftProDataArray1D" name="Event" globalname="Other" N="1"></o></cvg>'
    )
    with pytest.raises(TableBotError, match="2 different lists are named 'Event'"):
        rewrite(text, {"Event": [1]})


def test_not_a_program_and_missing_file(tmp_path: Path) -> None:
    other = tmp_path / "notes.rpp"
    other.write_text("hello")
    result = runner.invoke(app, ["export", str(EXAMPLE), "--to", "robopro-rpp", "--into", str(other)])
    assert result.exit_code == 2 and "not a ROBO Pro program" in result.output
    result = runner.invoke(app, ["export", str(EXAMPLE), "--to", "robopro-rpp", "--into", str(tmp_path / "x.rpp")])
    assert result.exit_code == 2 and "cannot read" in result.output


def test_find_lists_sees_nested_children_only_as_the_lists_own() -> None:
    text = (FIXTURES / "engine.rpp").read_text()
    found = {e.name: e for e in find_lists(text)}
    assert sorted(found) == ["Action", "Event", "Other", "Timer"]
    assert len(found["Event"].inits) == 3 and found["Timer"].inits == [] and found["Event"].n_value == 10
