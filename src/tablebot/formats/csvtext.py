"""Text files read with located errors, and spreadsheet text as records of cells that remember their place.

Handles what spreadsheets save: UTF-8 with or without BOM (or UTF-16 with its BOM), CRLF or LF, comma, semicolon or tab
separators and RFC 4180 quoting; every cell keeps its 1-based line and column for error messages.
"""

from __future__ import annotations

import codecs
import re
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

from tablebot.diagnostics import Collector, Diagnostic, TableBotError, fail

#: The line Excel may put above the header to name the delimiter: ``sep=;``.
SEP_RE = re.compile(r"^\s*sep=([,;\t])\s*$")
#: A binary file would give thousands of bad lines; the first few say enough.
MAX_BAD_LINES = 10


@dataclass(frozen=True)
class Cell:
    text: str
    line: int
    column: int


@dataclass(frozen=True)
class Record:
    line: int
    cells: tuple[Cell, ...]

    def is_blank(self) -> bool:
        return all(not c.text.strip() for c in self.cells)


#: What to do about a file that is not UTF-8 text, for files a spreadsheet saves.
CSV_ENCODING_HINT = "save the file as 'CSV UTF-8' (Excel) or 'Text CSV' with character set UTF-8 (LibreOffice)"


def read_text(path: Path, encoding_hint: str = CSV_ENCODING_HINT) -> str:
    """Decode a file as UTF-8 (BOM allowed); if it is not, report where (see :func:`_bad_bytes`)."""
    if path.is_dir():
        raise fail(path, "this is a folder, not a file", "give the path of a file")
    try:
        data = path.read_bytes()
    except OSError as exc:
        raise fail(path, f"cannot read: {exc.strerror or exc}", "check the file name") from None
    if data.startswith((codecs.BOM_UTF16_LE, codecs.BOM_UTF16_BE)):  # Excel's "Unicode Text" save
        try:
            return data.decode("utf-16")
        except UnicodeDecodeError:
            pass  # not UTF-16 after all: report it as bad UTF-8 below
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError:
        raise TableBotError(_bad_bytes(path, data, encoding_hint)) from None


def _bad_bytes(path: Path, data: bytes, hint: str) -> list[Diagnostic]:
    """One diagnostic per line holding undecodable bytes, at its first bad byte (columns in characters)."""
    found: list[Diagnostic] = []
    start = 3 if data.startswith(b"\xef\xbb\xbf") else 0  # the BOM is not a character of line 1
    for number, raw in enumerate(re.split(rb"\r\n|\r|\n", data[start:]), start=1):
        try:
            raw.decode("utf-8")
        except UnicodeDecodeError as exc:
            column = len(raw[: exc.start].decode("utf-8")) + 1
            found.append(Diagnostic(str(path), number, column, f"byte 0x{raw[exc.start]:02x} is not UTF-8 text",
                                    hint))
            if len(found) == MAX_BAD_LINES:
                break
    return found


def detect_delimiter(first_line: str) -> str:
    """Tab if the header has one, else semicolon if it has one and no comma, else comma."""
    if "\t" in first_line:
        return "\t"
    if ";" in first_line and "," not in first_line:
        return ";"
    return ","


def _first_filled_line(text: str) -> str:
    """The first line with any text (the header), so blank lines above it do not hide its delimiter."""
    return next((line for line in text.split("\n") if line.strip()), "")


def split_records(text: str, path: str, delimiter: str | None = None) -> list[Record]:
    """Split CSV text into records; a quoted cell may hold delimiters, quotes ("") and newlines."""
    text = text.replace("\r\n", "\n").replace("\r", "\n")
    first = _first_filled_line(text)
    excel = SEP_RE.match(first)
    if excel:  # Excel's "sep=;" line names the delimiter; blanked, so that line numbers stay
        text = text.replace(first, "", 1)
    if delimiter is None:
        delimiter = excel[1] if excel else detect_delimiter(first)
    records: list[Record] = []
    cells: list[Cell] = []
    line, column, i = 1, 1, 0
    record_line = 1
    n = len(text)
    while i <= n:
        start_line, start_col = line, column
        if i < n and text[i] == '"':
            value, i, line, column = _quoted(text, i, line, column, path)
            while i < n and text[i] not in (delimiter, "\n"):  # stray text after a closing quote
                value += text[i]
                i += 1
                column += 1
        else:
            j = i
            while j < n and text[j] not in (delimiter, "\n"):
                j += 1
            value = text[i:j]
            column += j - i
            i = j
        cells.append(Cell(value, start_line, start_col))
        if i < n and text[i] == delimiter:
            i += 1
            column += 1
            continue
        # end of record (newline or end of text)
        records.append(Record(record_line, tuple(cells)))
        cells = []
        i += 1
        line += 1
        column = 1
        record_line = line
    if records and len(records[-1].cells) == 1 and not records[-1].cells[0].text:
        records.pop()  # the empty "record" after the final newline
    return records


def _quoted(text: str, i: int, line: int, column: int, path: str) -> tuple[str, int, int, int]:
    start_line, start_col = line, column
    out: list[str] = []
    i += 1
    column += 1
    n = len(text)
    while i < n:
        ch = text[i]
        if ch == '"':
            if i + 1 < n and text[i + 1] == '"':
                out.append('"')
                i += 2
                column += 2
                continue
            return "".join(out), i + 1, line, column + 1
        out.append(ch)
        if ch == "\n":
            line += 1
            column = 1
        else:
            column += 1
        i += 1
    raise fail(path, "a quoted cell is never closed", 'add the closing " (write "" for a quote inside)',
               start_line, start_col)


def cells_beyond(cells: Sequence[Cell], width: int, out: Collector) -> None:
    """Report the filled cells right of a ``width``-column header (a spreadsheet shows them; nothing reads them)."""
    for cell in cells[width:]:
        if cell.text.strip():
            out.error(cell.line, cell.column, f"cell {cell.text.strip()!r} is beyond the last column",
                      "remove it or add a header for it")


def headerless(cell: Cell, out: Collector) -> None:
    """Report a filled cell in a column whose header is blank."""
    if cell.text.strip():
        out.error(cell.line, cell.column, f"cell {cell.text.strip()!r} is in a column with no header",
                  "name the column in the header, or clear the cell")
