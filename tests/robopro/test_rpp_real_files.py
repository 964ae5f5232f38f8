"""``export --to robopro-rpp`` on the cases real ROBO Pro programs show: a global list kept once per
subprogram (every copy written), names as character references (compared as ROBO Pro shows them), lists
loaded from a CSV column at start (column 0 leaves ``initcsvcolumn`` out: warned), empty lists (inits laid
out as real files lay them out), float lists (refused). On the corpus's own files when it is here; on a
small hand-made fixture always."""

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
from tablebot.robopro.rpp_edit import csv_loaded, find_lists, rewrite
from tablebot.testing.rpp_corpus import corpus_dir
from test_rpp import EXAMPLE, FIXTURES
from test_rpp import _outside_lists as _without_inits

pytestmark = [pytest.mark.kernel_free]

if TYPE_CHECKING:
    from typer.testing import Result

    from tablebot.robopro.lists import Lists

CORPUS = corpus_dir()


def corpus() -> Path:
    """The corpus folder, in a test marked needs_corpus."""
    assert CORPUS is not None
    return CORPUS


needs_corpus = pytest.mark.skipif(
    CORPUS is None,
    reason="the ROBO Pro corpus is not here: set TABLEBOT_RPP_CORPUS or put shared/rpp-corpus beside the repository",
)
runner = CliRunner()
PIXY = "i2c__Camera-Pixy_v1.0.rpp"
SRF08 = "i2c__Ultraschall-SRF08_v1.2.rpp"
TEACHIN = "sli__FtTxtExamples__SLI_TeachIn__RoboPro__TeachIn_cvl_4D.rpp"


@pytest.fixture(scope="module")
def lists() -> Lists:
    return robopro.encode(load_table(EXAMPLE / "table.csv"))


def _outside_lists(data: bytes) -> bytes:
    """The file without inits and N, whitespace runs as one space: what the export must not touch (an
    empty list's inits come with the line ends and indent they sit on)."""
    return re.sub(rb"\s+", b" ", _without_inits(data))


def copies(data: bytes, name: str) -> list[list[int]]:
    return [
        [int(i.attrib["value"]) for i in o.findall("init")]
        for o in ET.fromstring(data).iter("o")
        if o.get("classname") == "ftProDataArray1D" and o.get("name") == name
    ]


def corpus_copy(tmp_path: Path, name: str) -> Path:
    assert CORPUS is not None
    target = tmp_path / name
    shutil.copy(CORPUS / name, target)  # a copy in the test's temporary folder, never in the project
    target.chmod(0o644)
    return target


def export(program: Path, *names: str) -> Result:
    return runner.invoke(
        app,
        [
            "export",
            str(EXAMPLE),
            "--to",
            "robopro-rpp",
            "--into",
            str(program),
            "--event-list",
            names[0],
            "--action-list",
            names[1],
            "--timer-list",
            names[2],
        ],
    )


@needs_corpus
def test_pixy_global_lists_are_written_in_every_subprogram(tmp_path: Path, lists: Lists) -> None:
    program = corpus_copy(tmp_path, PIXY)
    before = program.read_bytes()
    result = export(program, "Signature", "X", "Y")
    assert result.exit_code == 0, result.output
    after = program.read_bytes()
    assert copies(after, "Signature") == [list(lists.event)] * 2
    assert copies(after, "X") == [list(lists.action)] * 2 and copies(after, "Y") == [list(lists.timer)] * 2
    assert copies(after, "Width") == copies(before, "Width")  # other lists untouched
    assert _outside_lists(after) == _outside_lists(before)  # every other byte kept


@needs_corpus
def test_srf08_names_are_compared_as_robopro_shows_them(tmp_path: Path, lists: Lists) -> None:
    text = (corpus() / SRF08).read_text(encoding="utf-8")
    assert 'name="Abst&#228;nde"' in text
    new = rewrite(text, {"Abstände": list(lists.event)})
    assert copies(new.encode(), "Abstände") == [list(lists.event)] * 2
    assert new.count('name="Abst&#228;nde"') == text.count('name="Abst&#228;nde"')  # the name stays as written
    with pytest.raises(TableBotError, match=r"(?s)no list named .Abstaende.*lists in the program: Abstände, Messwerte"):
        rewrite(text, {"Abstaende": [1]})


@needs_corpus
def test_srf08_float_list_is_refused(tmp_path: Path) -> None:
    text = (corpus() / SRF08).read_text(encoding="utf-8")
    with pytest.raises(TableBotError, match="'Messwerte' holds floats"):
        rewrite(text, {"Messwerte": [1, 2]})


@needs_corpus
def test_teachin_lists_loaded_from_csv_are_warned_with_their_column(tmp_path: Path, lists: Lists) -> None:
    program = corpus_copy(tmp_path, TEACHIN)
    text = program.read_text(encoding="utf-8")
    assert re.search(r'name="Data X"[^>]*initcsvbuffer="true"', text)
    assert not re.search(r'name="Data X"[^>]*initcsvcolumn', text)  # column 0: the attribute is left out
    assert csv_loaded(text, ["Data X", "Data Y", "Data Z"]) == {"Data X": 0, "Data Y": 1, "Data Z": 2}
    result = export(program, "Data X", "Data Y", "Data Z")
    assert result.exit_code == 0, result.output
    said = " ".join(result.output.split())
    assert "list Data X loads its values from column 0" in said and "Data Y loads its values from column 1" in said


@needs_corpus
def test_teachin_empty_lists_get_inits_as_real_files_lay_them_out(tmp_path: Path, lists: Lists) -> None:
    """The empty copies of Data X get their inits where SRF08's lists have theirs: after the blank line that
    follows the last pin, ``<init value="…">`` and ``</init>`` each on a line at the pins' indent."""
    program = corpus_copy(tmp_path, TEACHIN)
    before = program.read_bytes()
    assert all(c == [] for c in copies(before, "Data X"))
    assert export(program, "Data X", "Data Y", "Data Z").exit_code == 0
    after = program.read_text(encoding="utf-8")
    real = (corpus() / SRF08).read_text(encoding="utf-8")
    real_layout = re.search(
        r'pinid="3">\r?\n( *)</o>\r?\n +\r?\n( *)<init value0="2" value1="0" value2="0">'
        r"\r?\n( *)</init>",
        real,
    )
    assert real_layout and real_layout[1] == real_layout[2] == real_layout[3]  # one indent for pin, init, </init>
    ours = re.findall(r'pinid="3">\n( *)</o>\n +\n( *)<init value="88">\n( *)</init>\n', after)
    assert len(ours) == len(copies(before, "Data X")) and all(a == b == c for a, b, c in ours)
    assert all(c == list(lists.event) for c in copies(after.encode(), "Data X"))
    assert _outside_lists(after.encode()) == _outside_lists(before)


# --- the same cases on a small hand-made program (always) ------------------------------------------------------


def test_fixture_cases(tmp_path: Path) -> None:
    text = (FIXTURES / "real_cases.rpp").read_text(encoding="utf-8")
    found = {e.name: e for e in find_lists(text)}
    assert sorted(found) == ["Abstände", "Data X", "Messwerte"]
    new = rewrite(text, {"Abstände": [1, 2, 3], "Data X": [4]})
    assert copies(new.encode(), "Abstände") == [[1, 2, 3], [1, 2, 3]]
    assert (
        '                </o>\n                \n                <init value="4">\n                </init>\n'
        "            </o>" in new
    )
    assert csv_loaded(new, ["Abstände", "Data X"]) == {"Data X": 0}
    with pytest.raises(TableBotError, match="holds floats"):
        rewrite(text, {"Messwerte": [1]})
