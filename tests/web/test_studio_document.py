"""The studio's table document: the file comes back byte for byte, edits touch only their cell, and
cell values and places agree with the real CSV reader."""

from __future__ import annotations

import codecs

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from core_helpers import EXAMPLE
from tablebot.csvtext import split_records
from tablebot.diagnostics import TableBotError
from tablebot.formats.csv_document import CsvDocument

pytestmark = [pytest.mark.kernel_free]

cell_text = st.text(alphabet=st.sampled_from(list('ab1 ,;\t"\r\n=é')), max_size=6)


@st.composite
def csv_files(draw: st.DrawFn) -> str:
    delimiter = draw(st.sampled_from([",", ";", "\t"]))
    newline = draw(st.sampled_from(["\n", "\r\n", "\r"]))
    rows = draw(st.lists(st.lists(cell_text, min_size=1, max_size=4), min_size=1, max_size=5))
    lines = []
    for row in rows:
        cells = []
        for value in row:
            if any(ch in value for ch in (delimiter, '"', "\r", "\n")) or draw(st.booleans()):
                cells.append('"' + value.replace('"', '""') + '"')
            else:
                cells.append(value)
        lines.append(delimiter.join(cells))
    header = delimiter.join(["state", "next"])
    return header + newline + newline.join(lines) + (newline if draw(st.booleans()) else "")


@settings(max_examples=300, deadline=None)
@given(csv_files())
def test_text_round_trips_and_cells_agree_with_the_reader(text: str) -> None:
    doc = CsvDocument.from_text(text)
    assert doc.text() == text
    records = split_records(text, "t.csv", doc.dialect.delimiter)
    mine, places = doc.records, doc.positions()
    if len(mine) == len(records) + 1 and [c.value for c in mine[-1].cells] == [""]:
        mine, places = mine[:-1], places[:-1]  # the reader drops a last line of one empty cell ('""')
    for record, raw, where in zip(records, mine, places, strict=True):
        assert [c.text for c in record.cells] == [c.value for c in raw.cells]
        assert [(c.line, c.column) for c in record.cells] == where


def test_the_bumberbot_round_trips_and_one_edit_changes_one_cell() -> None:
    data = (EXAMPLE / "table.csv").read_bytes()
    doc = CsvDocument.from_bytes(data, "table.csv")
    assert doc.to_bytes() == data
    assert len(doc.grid()) == 37 and doc.header_values()[:2] == ["description", "state"]
    doc.set_cell(4, doc.header_values().index("timer"), "123")
    new = doc.to_bytes().decode().splitlines()
    old = data.decode().splitlines()
    assert [i for i, (a, b) in enumerate(zip(old, new, strict=True)) if a != b] == [5]
    assert new[5].split(",")[-2] == "123"


def test_bom_crlf_semicolons_and_quotes_are_kept() -> None:
    text = 'sep=;\r\n\r\n"description";"state";"next"\r\n"a; b";1;1\r\n"c";1;1'
    data = codecs.BOM_UTF8 + text.encode()
    doc = CsvDocument.from_bytes(data, "t.csv")
    assert doc.to_bytes() == data and doc.dialect.delimiter == ";" and not doc.dialect.quote_all
    assert doc.grid() == [["a; b", "1", "1"], ["c", "1", "1"]]
    doc.set_cell(1, 0, "x")
    row = doc.insert_row(1, ["new", "1", "1"])
    assert row == 2
    assert doc.to_bytes() == codecs.BOM_UTF8 + (text[:-7] + '"x";1;1\r\nnew;1;1').encode()
    doc.delete_row(2)
    assert doc.to_bytes() == codecs.BOM_UTF8 + (text[:-7] + '"x";1;1').encode()


def test_values_that_need_quotes_get_them() -> None:
    doc = CsvDocument.from_text("description,state,next\nx,1,1\n")
    doc.set_cell(0, 0, 'say "hi", then\nstop')
    assert doc.text() == 'description,state,next\n"say ""hi"", then\nstop",1,1\n'
    assert doc.grid()[0][0] == 'say "hi", then\nstop'


def test_an_unclosed_quote_is_the_readers_located_error() -> None:
    with pytest.raises(TableBotError, match=r"t.csv:2:1: error: a quoted cell is never closed"):
        CsvDocument.from_text('state,next\n"1,1\n', path="t.csv")


def test_bad_edits_are_refused() -> None:
    doc = CsvDocument.from_text("state,next\n1,1\n")
    with pytest.raises(ValueError, match="no row 5"):
        doc.set_cell(4, 0, "1")
    with pytest.raises(ValueError, match="at most"):
        doc.set_cell(0, 0, "x" * 5000)
