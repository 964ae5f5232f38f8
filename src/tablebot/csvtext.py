"""Spreadsheet text as records of cells that remember their line and column.

Handles what spreadsheets save: UTF-8 with or without BOM, CRLF or LF, comma, semicolon or tab
separators and RFC 4180 quoting; every cell keeps its 1-based line and column for error messages.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from tablebot.diagnostics import fail


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


def read_text(path: Path) -> str:
    """Decode a file as UTF-8 (BOM allowed), naming the line and column of the first bad byte."""
    try:
        data = path.read_bytes()
    except OSError as exc:
        raise fail(path, f"cannot read: {exc.strerror or exc}", "check the file name") from None
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        before = data[: exc.start]
        line = before.count(b"\n") + 1
        column = exc.start - (before.rfind(b"\n") + 1) + 1
        raise fail(path, f"byte 0x{data[exc.start]:02x} is not UTF-8 text", "save the file as "
                   "'CSV UTF-8' (Excel) or 'Text CSV' with character set UTF-8 (LibreOffice)",
                   line, column) from None


def detect_delimiter(first_line: str) -> str:
    """Tab if the header has one, else semicolon if it has one and no comma, else comma."""
    if "\t" in first_line:
        return "\t"
    if ";" in first_line and "," not in first_line:
        return ";"
    return ","


def split_records(text: str, path: str, delimiter: str | None = None) -> list[Record]:
    """Split CSV text into records; a quoted cell may hold delimiters, quotes ("") and newlines."""
    text = text.replace("\r\n", "\n").replace("\r", "\n")
    if delimiter is None:
        delimiter = detect_delimiter(text.split("\n", 1)[0])
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
