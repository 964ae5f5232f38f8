"""A sweep's output folder and its CSV text: ``spec.json``, a part file per finished chunk
(``parts/runs-A-B.csv``), merged into ``results.csv`` (one row per run, in run order); each cell written as
``csv.writer`` writes it.

An interrupted sweep keeps its parts (and writes ``results.partial.csv``); the same command run again finds
``spec.json`` unchanged and runs only the chunks that have no part yet.
"""

from __future__ import annotations

import csv
import functools
import io
import operator
import re
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from tablebot.diagnostics import Diagnostic, fail, notify
from tablebot.files import atomic_write, remove, write_text
from tablebot.fleet.spec import chunks
from tablebot.formats.trace_lines import exact_round
from tablebot.i18n import N_

if TYPE_CHECKING:
    from tablebot.fleet.spec import SweepSpec
    from tablebot.fleet.work import Job

PART_RE = re.compile(r"^runs-(\d{7})-(\d{7})\.csv$")


class Store:
    """``DIR/spec.json``, ``DIR/parts/runs-A-B.csv`` per finished chunk, ``DIR/results.csv`` at the end."""

    def __init__(self, folder: Path, spec: SweepSpec, columns: Sequence[str]) -> None:
        """The folder of the sweep ``spec``, whose result rows have ``columns`` (:meth:`Plan.columns`)."""
        self.folder, self.spec, self.columns = folder, spec, list(columns)
        self.parts = folder / "parts"

    def open(self) -> set[tuple[int, int]]:
        """Check the folder holds this spec's sweep (or none) and return the chunks already finished."""
        spec_file = self.folder / "spec.json"
        text = self.spec.to_json()
        if spec_file.exists() and spec_file.read_text(encoding="utf-8") != text:
            raise fail(
                self.folder,
                N_(
                    "--out holds the results of a different sweep (another table, robot file, "
                    "world, grid, seeds, length or simulator version)"
                ),
                N_("give --out a new folder, or delete this one to start over"),
            )
        self.parts.mkdir(parents=True, exist_ok=True)
        if not spec_file.exists():
            write_text(spec_file, text)
        wanted = set(chunks(self.spec))
        found = {(int(m[1]), int(m[2])) for p in self.parts.iterdir() if (m := PART_RE.match(p.name))}
        return {chunk for chunk in found & wanted if self._whole(*chunk)}

    def _whole(self, a: int, b: int) -> bool:
        """Whether the part of runs a..b-1 holds what this sweep writes there: its header, then one whole row
        per run, in order. A part is written whole or not at all, so only a damaged or edited one fails:
        it is said, and its runs are made again (the same rows: a part is deterministic) over it."""
        part = self.parts / f"runs-{a:07d}-{b:07d}.csv"
        columns = self.columns
        with open(part, encoding="utf-8", errors="replace", newline="") as f:
            text = f.read()
        rows = list(csv.reader(io.StringIO(text)))  # cells may hold quoted commas (a world's path)
        if (
            text.endswith("\n")
            and rows[:1] == [columns]
            and [row[0] for row in rows[1:] if row] == [str(run) for run in range(a, b)]
            and all(len(row) == len(columns) for row in rows[1:])
        ):
            return True
        notify(
            Diagnostic(
                str(part),
                None,
                None,
                N_(
                    "this part of the sweep is damaged (not the rows this sweep writes for runs {first}..{last}): "
                    "its runs are made again",
                    first=a,
                    last=b - 1,
                ),
                severity="note",
            )
        )
        return False

    def write_part(self, job: Job, text: str) -> Path:
        """A finished chunk's rows (:meth:`Plan.part_text`) as its part file."""
        return write_text(self.parts / f"runs-{job.first:07d}-{job.info['stop']:07d}.csv", text)

    def merge(self, complete: bool) -> tuple[Path, int]:
        """All finished parts in run order as ``results.csv`` (or ``results.partial.csv`` when not complete),
        streamed part by part (a sweep of millions of runs is never held in memory whole)."""
        count = 0
        path = self.folder / ("results.csv" if complete else "results.partial.csv")
        with atomic_write(path) as out:
            out.write(csv_text(self.columns, []))
            for a, b in chunks(self.spec):
                part = self.parts / f"runs-{a:07d}-{b:07d}.csv"
                if part.exists():
                    with open(part, encoding="utf-8") as f:
                        next(f)  # its header
                        for line in f:
                            out.write(line)
                            count += 1
        if complete:
            remove(self.folder / "results.partial.csv")  # with the new results, when they are in a set
        return path, count


def csv_text(columns: Sequence[str], rows: Sequence[dict[str, Any]]) -> str:
    """Rows as CSV text: floats as Python writes them (exact), blank for "never" (None) and for a column a
    row lacks; what csv.DictWriter writes, without its check of every row's keys."""
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow(columns)
    writer.writerows([row.get(column) for column in columns] for row in rows)
    return buffer.getvalue()


def read_results(path: Path, columns: Sequence[str] | None = None) -> list[dict[str, str]]:
    """The rows of a results file, each with every column, or only ``columns`` (a third of the time)."""
    with open(path, encoding="utf-8", newline="") as f:
        if columns is None:
            return list(csv.DictReader(f))
        reader = csv.reader(f)
        header = next(reader)
        places = [header.index(column) for column in columns]
        cells = operator.itemgetter(*places, *places[:1])  # two at least: a tuple, the last one dropped by zip
        return [dict(zip(columns, cells(row), strict=False)) for row in reader]


def times(ticks: np.ndarray, tick_s: float) -> list[str]:
    """Ticks as seconds, 6 decimals; blank for never (-1)."""
    rounded = exact_round(ticks * tick_s, 6)
    return ["" if tick < 0 else repr(value) for tick, value in zip(ticks.tolist(), rounded, strict=True)]


def decimals(values: np.ndarray) -> list[str]:
    """Numbers rounded to 6 decimals as Python's ``round`` does, written as Python writes floats."""
    return list(map(repr, exact_round(values, 6)))


@functools.lru_cache(maxsize=4096)
def _text_cell(text: str) -> str:
    buffer = io.StringIO()
    csv.writer(buffer, lineterminator="\n").writerow([text, ""])
    return buffer.getvalue()[: -len(",\n")]


def cell(value: Any) -> str:
    """One value as ``csv.writer`` writes it in a row of several: blank for None, text quoted where it
    must be, anything else as ``str``."""
    if value is None:
        return ""
    return _text_cell(value) if isinstance(value, str) else str(value)
