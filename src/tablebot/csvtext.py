"""Text files read with located errors, and spreadsheet text as records of cells that remember their place.

Handles what spreadsheets save: UTF-8 with or without BOM (or UTF-16 with its BOM, or Windows-1252 with a note), CRLF or
LF, comma, semicolon or tab separators and RFC 4180 quoting; every cell keeps its 1-based line and column for errors.
Every file is read up to a size limit, so no input (not even /dev/zero) can exhaust memory.
"""

from __future__ import annotations

import codecs
import re
from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from itertools import accumulate, repeat
from operator import add
from pathlib import Path
from typing import NamedTuple

from tablebot import overwrite
from tablebot.diagnostics import Collector, Diagnostic, TableBotError, fail, notify
from tablebot.i18n import N_

#: The line Excel may put above the header to name the delimiter: ``sep=;``.
SEP_RE = re.compile(r"^\s*sep=([,;\t])\s*$")
#: A binary file would give thousands of bad lines; the first few say enough.
MAX_BAD_LINES = 10


class Cell(NamedTuple):
    """One cell's text and where it starts (a tuple: a long table has millions of them)."""

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
CSV_ENCODING_HINT = N_("save the file as 'CSV UTF-8' (Excel) or 'Text CSV' with character set UTF-8 (LibreOffice)")
#: The largest file a loader reads, by default: a 100,000-row table is about 5 MB, an hour of recorded
#: inputs at 10 ms ticks about 6 MB. Anything larger is almost surely the wrong file (or /dev/zero).
MAX_TEXT_BYTES = 64 * 1024 * 1024
#: The widest record and the longest cell a loader reads (:func:`read_records`), far beyond any real file: the
#: examples' tables have up to 16 columns and cells of at most 49 characters. Both are refused before the
#: record is built, so neither a line of a million commas nor a cell of megabytes costs memory.
MAX_COLUMNS = 1000
MAX_CELL_CHARS = 4000
#: Bytes that no text file holds (NUL and the other C0 controls but tab and line ends): binary data.
BINARY_RE = re.compile(rb"[\x00-\x08\x0b\x0c\x0e-\x1f]")
#: A well-formed UTF-8 sequence of two or more bytes: a file that has one is UTF-8 with a few bad bytes,
#: not Windows-1252 (where such pairs, like "Ã©", almost never occur in real text).
UTF8_MULTIBYTE_RE = re.compile(rb"[\xc2-\xdf][\x80-\xbf]|[\xe0-\xef][\x80-\xbf]{2}|[\xf0-\xf4][\x80-\xbf]{3}")


def size_text(limit: int) -> str:
    """``64 MB``, ``512 KB``: a limit as people read it."""
    for unit, size in (("GB", 1 << 30), ("MB", 1 << 20), ("KB", 1 << 10)):
        if limit >= size:
            return f"{limit / size:g} {unit}"
    return f"{limit} bytes"


def read_bytes(path: Path, limit: int | None = None) -> bytes:
    """A file's bytes, refusing a folder, an unreadable file and anything over ``limit`` bytes (read no
    further than that: a device such as /dev/zero never ends); the default limit is MAX_TEXT_BYTES."""
    limit = MAX_TEXT_BYTES if limit is None else limit
    if path.is_dir():
        raise fail(path, N_("this is a folder, not a file"), N_("give the path of a file"))
    try:
        with path.open("rb") as stream:
            data = stream.read(limit + 1)
    except OSError as exc:
        raise fail(path, N_("cannot read: {reason}", reason=exc.strerror or exc), N_("check the file name")) from None
    overwrite.read(path)
    if len(data) > limit:
        raise fail(
            path,
            N_("the file is larger than {size}, the most tablebot reads of such a file", size=size_text(limit)),
            N_("is this the right file? split it, or give a smaller one"),
        )
    return data


def read_text(
    path: Path, encoding_hint: str = CSV_ENCODING_HINT, limit: int | None = None, spreadsheet: bool = True
) -> str:
    """Decode a file as UTF-8 (BOM allowed; UTF-16 with its BOM too).

    A ``spreadsheet`` file (CSV) that is not UTF-8 but is text, with no UTF-8 sequence in it at all, is
    read as Windows-1252 (Latin-1 where that has no character): what a German or French Excel saves as
    "CSV"; a note says so. Otherwise the bad bytes are reported where they are (see :func:`_bad_bytes`).
    """
    data = read_bytes(path, limit)
    if data.startswith((codecs.BOM_UTF16_LE, codecs.BOM_UTF16_BE)):  # Excel's "Unicode Text" save
        try:
            return data.decode("utf-16")
        except UnicodeDecodeError:
            pass  # not UTF-16 after all: report it as bad UTF-8 below
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        if spreadsheet and not BINARY_RE.search(data) and not UTF8_MULTIBYTE_RE.search(data):
            return _legacy(path, data, exc.start + (3 if data.startswith(codecs.BOM_UTF8) else 0))
        raise TableBotError(_bad_bytes(path, data, encoding_hint)) from None


def _legacy(path: Path, data: bytes, first_bad: int) -> str:
    """Text in Excel's Western European code page, with a note naming the encoding assumed and the first
    byte (at ``first_bad``) that is not UTF-8."""
    try:
        text, name = data.decode("cp1252"), "Windows-1252"
    except UnicodeDecodeError:  # cp1252 leaves five bytes undefined; Latin-1 has them all
        text, name = data.decode("latin-1"), "Latin-1 (ISO-8859-1)"
    bad = _bad_bytes(path, data, "")[0]
    notify(
        Diagnostic(
            str(path),
            bad.line,
            bad.column,
            N_(
                "not UTF-8 (byte 0x{byte:02x}); read as {name}, as a Western European Excel saves 'CSV'",
                byte=data[first_bad],
                name=name,
            ),
            N_("if characters look wrong, {hint}", hint=CSV_ENCODING_HINT),
            "note",
        )
    )
    return text


def _bad_bytes(path: Path, data: bytes, hint: str) -> list[Diagnostic]:
    """One diagnostic per line holding undecodable bytes, at its first bad byte (columns in characters)."""
    found: list[Diagnostic] = []
    start = 3 if data.startswith(b"\xef\xbb\xbf") else 0  # the BOM is not a character of line 1
    for number, raw in enumerate(re.split(rb"\r\n|\r|\n", data[start:]), start=1):
        try:
            raw.decode("utf-8")
        except UnicodeDecodeError as exc:
            column = len(raw[: exc.start].decode("utf-8")) + 1
            found.append(
                Diagnostic(
                    str(path), number, column, N_("byte 0x{byte:02x} is not UTF-8 text", byte=raw[exc.start]), hint
                )
            )
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
    """The first line with any text (the header), so blank lines above it do not hide its delimiter (found
    line by line: splitting a whole file of millions of lines would build a list of all of them)."""
    start = 0
    while start <= len(text):
        end = text.find("\n", start)
        end = len(text) if end < 0 else end
        if text[start:end].strip():
            return text[start:end]
        start = end + 1
    return ""


def records_after(text: str, line: int) -> int | None:
    """How many records follow line ``line`` (1-based) of ``text``, counted in C, when the text has no quote: each
    record is then one line, so a loader refuses too many before reading any. None when it has one (a quoted cell
    may span lines): the loader counts the records as it reads them."""
    if '"' in text:
        return None
    breaks = text.count("\n") + text.count("\r") - text.count("\r\n")
    return breaks + (0 if not text or text.endswith(("\n", "\r")) else 1) - line


def split_records(text: str, path: str, delimiter: str | None = None) -> list[Record]:
    """Split CSV text into records; a quoted cell may hold delimiters, quotes ("") and newlines. Any width
    and cell length: for a glance at a file (is it a table?) and the studio; loaders use :func:`read_records`."""
    return list(_records(text, path, delimiter, bounded=False))


def read_records(text: str, path: str, delimiter: str | None = None) -> Iterator[Record]:
    """:func:`split_records` one record at a time (a loader keeps only what it makes of each), refusing a record
    of more than MAX_COLUMNS cells and a cell of more than MAX_CELL_CHARS characters where it is, before
    building it."""
    return _records(text, path, delimiter, bounded=True)


def _records(text: str, path: str, delimiter: str | None, bounded: bool) -> Iterator[Record]:
    """Every record, but the empty one after the final newline (held back one record to see which is last)."""
    held = None
    for record in _all_records(text, path, delimiter, bounded):
        if held is not None:
            yield held
        held = record
    if held is not None and (len(held.cells) > 1 or held.cells[0].text):
        yield held


def _all_records(text: str, path: str, delimiter: str | None, bounded: bool) -> Iterator[Record]:
    text = text.replace("\r\n", "\n").replace("\r", "\n")
    first = _first_filled_line(text)
    excel = SEP_RE.match(first)
    if excel:  # Excel's "sep=;" line names the delimiter; blanked, so that line numbers stay
        text = text.replace(first, "", 1)
    if delimiter is None:
        delimiter = excel[1] if excel else detect_delimiter(first)
    stop = re.compile(f"[{re.escape(delimiter)}\n]")
    cells: list[Cell] = []
    line, column, i = 1, 1, 0
    record_line = 1
    n = len(text)
    while i <= n:
        if not cells:  # a record starts: a whole line without quotes is split at once (the usual case)
            end = text.find("\n", i)
            end = n if end < 0 else end
            if '"' not in text[i:end]:
                if bounded:
                    _check_line(text[i:end], delimiter, path, line)
                yield Record(line, _split_line(text[i:end], delimiter, line))
                i, line = end + 1, line + 1
                record_line = line
                continue
        start_line, start_col = line, column
        if i < n and text[i] == '"':
            value, i, line, column = _quoted(text, i, line, column, path, bounded)
            found = stop.search(text, i)  # stray text after the closing quote belongs to the cell
            j = found.start() if found else n
            value, column, i = value + text[i:j], column + j - i, j
        else:
            found = stop.search(text, i)  # the cell's end, found in C: a long table has millions of characters
            j = found.start() if found else n
            value = text[i:j]
            column += j - i
            i = j
        cells.append(Cell(value, start_line, start_col))
        if bounded:
            _check_cell(cells, path)
        if i < n and text[i] == delimiter:
            i += 1
            column += 1
            continue
        # end of record (newline or end of text)
        yield Record(record_line, tuple(cells))
        cells = []
        i += 1
        line += 1
        column = 1
        record_line = line


def _split_line(text: str, delimiter: str, line: int) -> tuple[Cell, ...]:
    """The cells of a line without quotes, made in C (no Python-level step per cell: a wide table has millions):
    each starts one past the end of the one before."""
    values = text.split(delimiter)
    columns = accumulate(map(add, map(len, values), repeat(1)), initial=1)
    return tuple(map(tuple.__new__, repeat(Cell), zip(values, repeat(line), columns)))


def _check_line(text: str, delimiter: str, path: str, line: int) -> None:
    """Refuse a line (without quotes) of too many cells, or with a cell too long, before it is split."""
    if text.count(delimiter) >= MAX_COLUMNS:
        rest = text.split(delimiter, MAX_COLUMNS)[-1]
        raise _too_wide(path, line, len(text) - len(rest) + 1)
    if len(text) > MAX_CELL_CHARS:
        column = 1
        for value in text.split(delimiter):
            if len(value) > MAX_CELL_CHARS:
                raise _too_long(path, line, column)
            column += len(value) + 1


def _check_cell(cells: list[Cell], path: str) -> None:
    """Refuse the cell just read (of a record with quotes) if it is one too many or too long."""
    cell = cells[-1]
    if len(cells) > MAX_COLUMNS:
        raise _too_wide(path, cell.line, cell.column)
    if len(cell.text) > MAX_CELL_CHARS:
        raise _too_long(path, cell.line, cell.column)


def _too_wide(path: str, line: int, column: int) -> TableBotError:
    return fail(
        path,
        N_("this line has more than {most:,} cells, the most tablebot reads", most=MAX_COLUMNS),
        N_("a table has a column per input and output, a few dozen at most: is this the right file?"),
        line,
        column,
    )


def _too_long(path: str, line: int, column: int) -> TableBotError:
    return fail(
        path,
        N_("this cell is longer than {most:,} characters, the most tablebot reads", most=MAX_CELL_CHARS),
        N_("shorten it (a description is a sentence or two); is this the right file?"),
        line,
        column,
    )


def _quoted(text: str, i: int, line: int, column: int, path: str, bounded: bool) -> tuple[str, int, int, int]:
    """The value of the quoted cell at ``i`` (its opening quote), and where its closing quote ends (index, line,
    column). Each quote is found in C; a ``bounded`` read stops at a cell longer than MAX_CELL_CHARS."""
    start = i
    parts: list[str] = []
    j = i + 1
    while True:
        k = text.find('"', j)
        if k < 0 or (bounded and k - start > 2 * MAX_CELL_CHARS + 2):  # "" is 2 characters of the file for 1
            break
        parts.append(text[j:k])
        if text.startswith('"', k + 1):  # a doubled quote: one quote in the value
            parts.append('"')
            j = k + 2
            continue
        raw = text[start : k + 1]
        newlines = raw.count("\n")
        column = len(raw) - raw.rfind("\n") if newlines else column + len(raw)
        return "".join(parts), k + 1, line + newlines, column
    if k >= 0:
        raise _too_long(path, line, column)
    raise fail(
        path, N_("a quoted cell is never closed"), N_('add the closing " (write "" for a quote inside)'), line, column
    )


def cells_beyond(cells: Sequence[Cell], width: int, out: Collector) -> None:
    """Report the filled cells right of a ``width``-column header (a spreadsheet shows them; nothing reads them)."""
    for cell in cells[width:]:
        if cell.text.strip():
            out.error(
                cell.line,
                cell.column,
                N_("cell {text!r} is beyond the last column", text=cell.text.strip()),
                N_(
                    "remove it or add a header for it; a cell holding a comma (0,5s in a comma-separated "
                    'file) is written in quotes: "0,5s"'
                ),
            )


def headerless(cell: Cell, out: Collector) -> None:
    """Report a filled cell in a column whose header is blank."""
    if cell.text.strip():
        out.error(
            cell.line,
            cell.column,
            N_("cell {text!r} is in a column with no header", text=cell.text.strip()),
            N_("name the column in the header, or clear the cell"),
        )
