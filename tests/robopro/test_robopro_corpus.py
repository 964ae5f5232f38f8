"""The vocabulary of real ROBO Pro programs, and the generated program held against it.

With the corpus present (``../shared/rpp-corpus`` beside the repository, or ``$TABLEBOT_RPP_CORPUS``), the
whole corpus is read once: the committed ``testing/rpp_vocabulary.json`` must be exactly what it yields, and
the generated programs are checked against that fresh reading. Without it (CI), the generated programs are
checked against the committed vocabulary (test_robopro_program.py) and the checker is shown to catch
what it must.
"""

from __future__ import annotations

import json
import random
import re
import time
import xml.etree.ElementTree as ET
from typing import Any

import pytest

from core_helpers import EXAMPLE, ROOT
from tablebot.formats.table_read import load_table
from tablebot.robopro.processes import generate_several
from tablebot.robopro.program import generate
from tablebot.tables import load_tables
from tablebot.testing.random_tables import Shape, random_table
from tablebot.testing.rpp_corpus import corpus_dir, dump, read_corpus
from tablebot.testing.rpp_vocabulary import BEYOND_CORPUS, SERIES, VOCABULARY, problems, vocabulary
from test_robopro_program import fitting

pytestmark = [pytest.mark.kernel_free]

CORPUS = corpus_dir()
needs_corpus = pytest.mark.skipif(
    CORPUS is None,
    reason="the ROBO Pro corpus is not here: set TABLEBOT_RPP_CORPUS or put shared/rpp-corpus beside the repository",
)


@pytest.fixture(scope="module")
def fresh() -> dict[str, object]:
    """The whole corpus, read once (about 36 MB of XML; the time is printed with -s)."""
    assert CORPUS is not None
    started = time.perf_counter()
    found = read_corpus(CORPUS)
    print(f"read {found['files']} programs in {time.perf_counter() - started:.1f} s")
    return found


def programs() -> list[str]:
    table = fitting(
        random_table(random.Random(3), Shape(states=3, rows=6, inputs=3, counters=2)),
        {"controller": "tx", "I3": {"terminal": "I8", "active": 0}},
    )
    return [
        generate(load_table(EXAMPLE / "table.csv"), "document"),
        generate(load_table(ROOT / "examples" / "bumberbot-counters" / "table.csv")),
        generate(table, "always"),
        generate_several(load_tables(load_table(ROOT / "examples" / "bumberbot-lights" / "table.csv"))),
    ]


@needs_corpus
def test_the_committed_vocabulary_is_what_the_corpus_yields(fresh: dict[str, object]) -> None:
    assert fresh["files"] == 79
    assert dump(fresh) == VOCABULARY.read_text(encoding="utf-8"), "regenerate it: python -m tablebot.testing.rpp_corpus"


@needs_corpus
def test_generated_programs_against_the_corpus(fresh: dict[str, object]) -> None:
    for text in programs():
        assert problems(text, json.loads(dump(fresh))) == []


@needs_corpus
def test_processes_are_the_corpus_own_and_the_lamp_output_is_not(fresh: dict[str, Any]) -> None:
    """A robot of several tables runs a process per table: real main programs hold several Starts (the TeachIn
    robot's, 11). No program of the corpus drives a lamp output: that element comes from BEYOND_CORPUS (real
    programs outside the corpus), and this says so the day the corpus has one."""
    assert CORPUS is not None
    starts = [
        len(re.findall(r'classname="ftProProcessStart"', f.read_text(encoding="utf-8"))) for f in CORPUS.glob("*.rpp")
    ]
    assert max(starts) >= 2
    assert not set(BEYOND_CORPUS) & set(fresh["elements"])


@needs_corpus
def test_the_series_the_generator_extends_are_the_corpus_own() -> None:
    """Inputs 160.. are read as switches (inputMode 1, among other modes) and 176.. as counts (inputMode 6)
    wherever the corpus uses them: the rule the generator follows for I5–I8 and C2, C4."""
    assert CORPUS is not None
    modes: dict[int, set[str]] = {}
    pattern = re.compile(r'classname="ftProDataIn"[^>]*?input="(\d+)"[^>]*?inputMode="(\d+)"')
    for path in CORPUS.glob("*.rpp"):
        for code, mode in pattern.findall(path.read_text(encoding="utf-8")):
            modes.setdefault(int(code), set()).add(mode)
    inputs, counts = SERIES[("ftProDataIn", "input")]
    assert sorted(code for code in modes if code in inputs) == [160, 161, 162, 163]
    assert all("1" in modes[code] for code in modes if code in inputs)
    assert {code: modes[code] for code in modes if code in counts} == {176: {"6"}, 178: {"6"}}


def test_every_real_header_is_the_generated_one() -> None:
    text = programs()[0]
    root = ET.fromstring(text.encode())
    assert vocabulary()["headers"] == [[c.get("classname", c.tag) if c.tag == "o" else c.tag for c in root]]


@pytest.mark.parametrize(
    ("change", "complaint"),
    [
        (('classname="ftProFlowIf"', 'classname="ftProFlowLoop"'), "appears in no real program"),
        (('operation="XOR"', 'operation="NAND"'), "not a value real programs use"),
        ((' id="100003"', ' id="100002"'), "used twice"),
        (("<roboprover>04060600", "<roboprover>09000000"), "not a value real programs use"),
    ],
)
def test_the_check_catches_what_real_programs_never_have(change: tuple[str, str], complaint: str) -> None:
    text = programs()[0]
    old, new = change
    assert old in text
    assert complaint in "\n".join(problems(text.replace(old, new, 1)))


def test_the_check_catches_a_resolveid_that_does_not_point_back() -> None:
    text = programs()[0]
    first = re.search(r' resolveid="\d+"', text)
    assert first is not None
    element = re.search(r'<o classname="ftProSubroutineFlowIn" id="(\d+)"', text)
    assert element is not None
    assert "does not point back" in "\n".join(problems(text.replace(first[0], f' resolveid="{element[1]}"', 1)))
