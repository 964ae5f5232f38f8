"""A table file as the studio edits it (and ``tune``, writing its tuned table): every cell keeps its exact
source text, so saving writes the file back byte for byte except the cells that were edited (delimiter,
quoting, BOM, line ends kept).

Cell values and (line, column) positions follow :func:`tablebot.csvtext.split_records`, so a
diagnostic from the real parser lands on the cell the user sees.
"""

from __future__ import annotations

import codecs
import difflib
from dataclasses import dataclass, field

from tablebot.csvtext import SEP_RE, detect_delimiter, split_records
from tablebot.diagnostics import fail
from tablebot.i18n import N_


class Refused(ValueError):
    """An edit the document will not make; ``str()`` is the sentence a person is shown. The studio answers it
    as its own refusal (:class:`tablebot.web.errors.Refused` is this class).

    A ValueError, so that code that reads a table outside the studio treats it as bad input."""


#: A table larger than this is not a table a person edits in a grid.
MAX_TABLE_BYTES = 1_000_000
#: One cell's text, as typed into the grid.
MAX_CELL_CHARS = 2_000
NEWLINES = ("\r\n", "\n", "\r")


@dataclass
class RawCell:
    raw: str  # exactly as in the file, quotes included
    value: str  # what the parser reads (quotes removed, line ends inside as \n)


@dataclass
class RawRecord:
    cells: list[RawCell]
    end: str  # the line end after it ("" for a last line without one)
    kind: str = "row"  # header | row | blank (blank when loaded: hidden) | sep (Excel's sep= line)


@dataclass
class Dialect:
    delimiter: str
    newline: str  # the most common line end: new rows get it
    encoding: str  # utf-8 | utf-8-sig | utf-16
    quote_all: bool  # every filled cell of the file was quoted: new filled cells are quoted too


@dataclass
class CsvDocument:
    """Records with their exact text; :meth:`text` rebuilds the file."""

    records: list[RawRecord]
    dialect: Dialect
    lead: str = ""  # text before the first record (none today; kept for symmetry)
    row_ids: list[int] = field(default_factory=list)  # grid row -> index into records

    # --- reading ---------------------------------------------------------------------------------

    @classmethod
    def from_bytes(cls, data: bytes, path: str) -> CsvDocument:
        if len(data) > MAX_TABLE_BYTES:
            raise fail(
                path,
                N_(
                    "the file has {size:,} bytes; the studio edits tables up to {limit:,}",
                    size=len(data),
                    limit=MAX_TABLE_BYTES,
                ),
                N_("edit it in a spreadsheet or split it"),
            )
        try:
            if data.startswith((codecs.BOM_UTF16_LE, codecs.BOM_UTF16_BE)):
                text, encoding = data.decode("utf-16"), "utf-16"
            elif data.startswith(codecs.BOM_UTF8):
                text, encoding = data[3:].decode("utf-8"), "utf-8-sig"
            else:
                text, encoding = data.decode("utf-8"), "utf-8"
        except UnicodeDecodeError as exc:
            line = data[: exc.start].count(b"\n") + 1
            raise fail(
                path,
                N_(
                    "byte {at} is not {encoding} text: the studio edits tables saved as UTF-8 or UTF-16",
                    at=exc.start,
                    encoding=exc.encoding.upper(),
                ),
                N_("save it as UTF-8 (Excel: CSV UTF-8), or edit it in a spreadsheet"),
                line,
            ) from None
        return cls.from_text(text, encoding, path)

    @classmethod
    def from_text(cls, text: str, encoding: str = "utf-8", path: str = "<table>") -> CsvDocument:
        first = next((line for line in text.replace("\r\n", "\n").replace("\r", "\n").split("\n") if line.strip()), "")
        excel = SEP_RE.match(first)
        delimiter = excel[1] if excel else detect_delimiter(first)
        try:
            records = _tokenise(text, delimiter)
        except ValueError:
            split_records(text, path)  # raises the located error of the unclosed quote
            raise
        ends = [r.end for r in records if r.end]
        newline = max(NEWLINES, key=ends.count) if ends else "\n"
        filled = [c for r in records for c in r.cells if c.value]
        quote_all = bool(filled) and all(c.raw.startswith('"') for c in filled)
        doc = cls(records, Dialect(delimiter, newline, encoding, quote_all))
        doc._classify(excel is not None)
        return doc

    def _classify(self, has_sep: bool) -> None:
        header_seen = False
        for record in self.records:
            if _blank(record):
                record.kind = "blank"
            elif has_sep and not header_seen and SEP_RE.match(record_text(record, self.dialect.delimiter)):
                record.kind, has_sep = "sep", False
            elif not header_seen:
                record.kind, header_seen = "header", True
            else:
                record.kind = "row"
        self.row_ids = [i for i, r in enumerate(self.records) if r.kind == "row"]

    # --- what the grid shows ----------------------------------------------------------------------

    @property
    def header(self) -> RawRecord | None:
        return next((r for r in self.records if r.kind == "header"), None)

    def header_values(self) -> list[str]:
        header = self.header
        return [c.value for c in header.cells] if header else []

    def grid(self) -> list[list[str]]:
        """Cell values per grid row, padded or cut to the header's width."""
        width = len(self.header_values())
        rows = []
        for index in self.row_ids:
            values = [c.value for c in self.records[index].cells]
            rows.append((values + [""] * width)[:width] if width else values)
        return rows

    # --- editing ------------------------------------------------------------------------------------

    def set_cell(self, row: int, column: int, value: str) -> None:
        """Set one cell of a grid row (``row`` -1: the header); other cells keep their bytes."""
        if len(value) > MAX_CELL_CHARS:
            raise Refused(f"a cell holds at most {MAX_CELL_CHARS} characters")
        value = _one_line_end(value)
        record = self._record(row)
        if column < 0 or column > max(len(self.header_values()), len(record.cells)):
            raise Refused(f"there is no column {column + 1}")
        while len(record.cells) <= column:
            record.cells.append(RawCell("", ""))
        old = record.cells[column]
        if old.value == value:
            return
        record.cells[column] = RawCell(self._encode(value, old.raw.startswith('"')), value)

    def insert_row(self, after: int, values: list[str] | None = None) -> int:
        """A new grid row after grid row ``after`` (-1: first); returns its grid index."""
        if after < -1 or after >= len(self.row_ids):
            raise Refused(f"there is no row {after + 1}")
        width = len(self.header_values())
        values = [_one_line_end(v) for v in values or []]
        values += [""] * max(0, width - len(values))
        cells = [RawCell(self._encode(v, False), v) for v in values]
        at = (self.row_ids[after] if after >= 0 else self._header_index()) + 1
        if at == len(self.records) and self.records and not self.records[-1].end:
            self.records[-1].end = self.dialect.newline  # the old last line had no line end
            end = ""
        else:
            end = self.dialect.newline
        self.records.insert(at, RawRecord(cells, end, "row"))
        self.row_ids = [i for i, r in enumerate(self.records) if r.kind == "row"]
        return after + 1

    def delete_row(self, row: int) -> None:
        index = self.row_ids[self._check_row(row)]
        removed = self.records.pop(index)
        if not removed.end and index > 0:  # it was the last line: the new last line keeps the old style
            self.records[index - 1].end = ""
        self.row_ids = [i for i, r in enumerate(self.records) if r.kind == "row"]

    def replace_grid(self, header: list[str], rows: list[list[str]]) -> None:
        """Make the grid ``header`` and ``rows`` (a draft the page kept), changing only what differs: rows
        alike keep their bytes, rows edited are edited cell by cell, others inserted or deleted."""
        width = len(self.header_values())
        if len(header) != width or any(len(row) > width for row in rows):
            raise Refused(
                f"the table now has {width} columns, the edits {max(map(len, [header, *rows]))}: "
                "they cannot be put back (copy them from the page by hand)"
            )
        for column, value in enumerate(header):
            if value != self.header_values()[column]:
                self.set_cell(-1, column, value)
        old = [tuple(row) for row in self.grid()]
        new = [tuple(_one_line_end(v) for v in row) + ("",) * (width - len(row)) for row in rows]
        matcher = difflib.SequenceMatcher(None, old, new, autojunk=False)
        for tag, first, last, start, end in reversed(matcher.get_opcodes()):  # from the end: indices stay valid
            if tag == "equal":
                continue
            paired = min(last - first, end - start)
            for offset in range(paired):
                self._set_row(first + offset, old[first + offset], new[start + offset])
            for _ in range(last - first - paired):  # old rows beyond the new ones
                self.delete_row(first + paired)
            for offset in range(paired, end - start):  # new rows beyond the old ones
                self.insert_row(first + offset - 1, list(new[start + offset]))

    def _set_row(self, row: int, old: tuple[str, ...], new: tuple[str, ...]) -> None:
        for column, (was, value) in enumerate(zip(old, new, strict=True)):
            if was != value:
                self.set_cell(row, column, value)

    def _check_row(self, row: int) -> int:
        if not 0 <= row < len(self.row_ids):
            raise Refused(f"there is no row {row + 1}")
        return row

    def _record(self, row: int) -> RawRecord:
        if row == -1:
            if self.header is None:
                raise Refused("the table has no header")
            return self.header
        return self.records[self.row_ids[self._check_row(row)]]

    def _header_index(self) -> int:
        return next((i for i, r in enumerate(self.records) if r.kind == "header"), -1)

    def _encode(self, value: str, was_quoted: bool) -> str:
        """A value as the file writes cells: quoted when it must be, or when the file (or the old cell) quotes."""
        delimiter = self.dialect.delimiter
        must = any(ch in value for ch in (delimiter, '"', "\n", "\r")) or value != value.strip()
        if must or (value and (was_quoted or self.dialect.quote_all)):
            inner = value.replace('"', '""').replace("\n", self.dialect.newline)
            return f'"{inner}"'
        return value

    # --- writing --------------------------------------------------------------------------------------

    def text(self) -> str:
        delimiter = self.dialect.delimiter
        return self.lead + "".join(delimiter.join(c.raw for c in r.cells) + r.end for r in self.records)

    def to_bytes(self) -> bytes:
        text = self.text()
        if self.dialect.encoding == "utf-16":
            return text.encode("utf-16")  # with the BOM the file had
        data = text.encode("utf-8")
        return codecs.BOM_UTF8 + data if self.dialect.encoding == "utf-8-sig" else data

    def positions(self) -> list[list[tuple[int, int]]]:
        """(line, column) of every cell of every record, as the parser numbers them."""
        out: list[list[tuple[int, int]]] = []
        line, column = 1, 1
        delimiter = self.dialect.delimiter
        for record in self.records:
            places = []
            for k, cell in enumerate(record.cells):
                if k:
                    column += len(delimiter)
                places.append((line, column))
                line, column = _advance(cell.raw, line, column)
            out.append(places)
            if record.end:
                line, column = line + 1, 1
        return out

    def record_lines(self) -> list[int]:
        """The file line each record starts on."""
        return [places[0][0] if places else 0 for places in self.positions()]


def record_text(record: RawRecord, delimiter: str) -> str:
    return delimiter.join(c.raw for c in record.cells)


def _one_line_end(value: str) -> str:
    """A cell's line breaks as the grid has them (\\n): a client's \\r\\n or \\r would be written as two line
    ends, or a \\r alone, and the cell would gain a line."""
    return value.replace("\r\n", "\n").replace("\r", "\n")


def _blank(record: RawRecord) -> bool:
    return all(not c.value.strip() for c in record.cells)


def _advance(raw: str, line: int, column: int) -> tuple[int, int]:
    """Line and column after ``raw`` (\\r\\n, \\r and \\n each end a line, as the parser counts)."""
    normal = raw.replace("\r\n", "\n").replace("\r", "\n")
    breaks = normal.count("\n")
    if not breaks:
        return line, column + len(normal)
    return line + breaks, len(normal) - normal.rfind("\n")


def _tokenise(text: str, delimiter: str) -> list[RawRecord]:
    """Records with raw cell text; a quoted cell may hold delimiters, doubled quotes and line ends."""
    records: list[RawRecord] = []
    cells: list[RawCell] = []
    i, n = 0, len(text)
    while True:
        start = i
        if i < n and text[i] == '"':
            i, value = _quoted_end(text, i)
            while i < n and text[i] not in (delimiter, "\n", "\r"):  # stray text after the closing quote
                value += text[i]
                i += 1
        else:
            while i < n and text[i] not in (delimiter, "\n", "\r"):
                i += 1
            value = text[start:i]
        cells.append(RawCell(text[start:i], value))
        if i < n and text[i] == delimiter:
            i += 1
            continue
        end = "\r\n" if text.startswith("\r\n", i) else text[i] if i < n else ""
        records.append(RawRecord(cells, end))
        cells = []
        i += len(end)
        if i >= n:
            break
    return records


def _quoted_end(text: str, i: int) -> tuple[int, str]:
    """Index after the closing quote of the quoted cell at ``i``, and its value (line ends as \\n)."""
    out: list[str] = []
    i += 1
    n = len(text)
    while i < n:
        ch = text[i]
        if ch == '"':
            if text.startswith('""', i):
                out.append('"')
                i += 2
                continue
            return i + 1, "".join(out).replace("\r\n", "\n").replace("\r", "\n")
        out.append(ch)
        i += 1
    raise Refused("a quoted cell is never closed")
