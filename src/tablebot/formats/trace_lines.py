"""JSON Lines traces: the format every tablebot tool writes and compares, its writer and its one reader
(recorded inputs are read by :mod:`tablebot.formats.inputs_csv`).

A trace line is one tick: ``tick``, ``event`` (bitmask, first event column highest), ``row``
(0-based fired row or null), ``state`` and ``timer`` after the tick, each motor's signed speed,
each lamp's level and each counter's value. Extra fields (a simulator's pose) may follow.
"""

from __future__ import annotations

import json
import re
from collections.abc import Iterable, Iterator
from pathlib import Path
from typing import IO, Any

import numpy as np

from tablebot.csvtext import read_text
from tablebot.diagnostics import Collector
from tablebot.i18n import N_


def dumps(line: dict[str, Any]) -> str:
    """One trace line as compact JSON: the same line always gives the same bytes."""
    return json.dumps(line, separators=(",", ":"), ensure_ascii=False)


def exact_round(values: Any, digits: int) -> list[float]:
    """``[round(v, digits) for v in values]`` for a float array, vectorised (Python's ``round`` rounds the
    exact binary value half to even; numpy's ``round`` scales first, which can tip a near-half case the
    other way, so those few values are rounded by Python)."""
    return exact_round_array(values, digits).tolist()


def exact_round_array(values: Any, digits: int) -> np.ndarray:
    """:func:`exact_round` as an array."""
    array = np.asarray(values, dtype=np.float64)
    scaled = array * 10.0**digits
    rounded = np.rint(scaled) / 10.0**digits  # k / 10^d: IEEE division gives the double nearest k·10^-d
    fraction = np.abs(scaled - np.floor(scaled) - 0.5)
    doubtful = np.flatnonzero((fraction < 1e-6) | ~np.isfinite(scaled) | (np.abs(scaled) > 2.0**52))
    for i in doubtful.tolist():
        rounded[i] = round(float(array[i]), digits)
    return rounded


def write_trace(lines: Iterable[dict[str, Any]], stream: IO[str]) -> int:
    count = 0
    for line in lines:
        stream.write(dumps(line) + "\n")
        count += 1
    return count


#: The largest trace file read back: a simulated hour at 10 ms ticks is about 60 MB of JSON Lines.
MAX_TRACE_BYTES = 512 * 1024 * 1024


def read_trace(path: str | Path) -> list[dict[str, Any]]:
    """Every tick line of a trace file (an ``end`` record, written when a run was cut short, is skipped);
    a line that is not a JSON object is a located error."""
    path = Path(path)
    text = read_text(path, "a trace is UTF-8 JSON Lines as tablebot writes it", MAX_TRACE_BYTES, spreadsheet=False)
    return parse_trace(text, path)


#: A run of more digits than Python turns into an int (json.loads raises a plain ValueError on it).
LONG_NUMBER_RE = re.compile(r"\d{4301,}")
#: Located errors reported before a bad trace is given up on.
MAX_TRACE_ERRORS = 10


def parse_trace(text: str, path: str | Path, required: tuple[str, ...] = ()) -> list[dict[str, Any]]:
    """The tick lines of a trace's text, stopping at an ``end`` record; every line that is not a JSON
    object (or lacks a ``required`` key) is a located error, all of them (up to ten) reported at once."""
    out = Collector(path)
    lines = [line for _, line in trace_records(text, out, required)]
    out.raise_if_any()
    return lines


#: One line and its end (``\n``, ``\r\n`` or ``\r``; at the end of the text, none).
LINE_RE = re.compile(r"([^\r\n]*)(?:\r\n|\r|\n|$)")


def lines_of(text: str) -> Iterator[str]:
    """The lines of ``text``, one at a time (a 64 MB trace split at once is a list of half a million strings), each
    without its end. Only line ends end a line: a JSON string may hold U+2028, which str.splitlines also splits at."""
    for line in LINE_RE.finditer(text):
        if not line[0]:  # the empty match at the very end
            return
        yield line[1]


def trace_records(text: str, out: Collector, required: tuple[str, ...] = ()) -> Iterator[tuple[int, dict[str, Any]]]:
    """(line number, tick line) of a trace's text up to an ``end`` record; a bad line goes to ``out``.
    The one reader of trace lines: ``tablebot trace --inputs RUN.jsonl``, the studio's player and
    :func:`read_trace` all go through it."""
    hint = N_("a trace has one JSON object per line, as tablebot sim, trace, run or monitor write it")
    for number, raw in enumerate(lines_of(text), start=1):
        if len(out.items) >= MAX_TRACE_ERRORS:
            return
        if not raw.strip():
            continue
        try:
            line = json.loads(raw)
        except json.JSONDecodeError as exc:
            out.error(number, exc.colno, N_("line {n} is not JSON: {reason}", n=number, reason=exc.msg), hint)
            continue
        except RecursionError:  # nesting deeper than the parser's stack
            out.error(number, 1, N_("line {n} is not JSON: nested too deeply", n=number), hint)
            continue
        except ValueError:  # int() of a number past Python's 4,300 digits
            long = LONG_NUMBER_RE.search(raw)
            out.error(
                number, long.start() + 1 if long else 1, N_("line {n} has a number too long to read", n=number), hint
            )
            continue
        if not isinstance(line, dict):
            out.error(number, 1, N_("line {n} is JSON but not an object {{...}}", n=number), hint)
        elif "end" in line:
            return
        elif missing := [key for key in required if key not in line]:
            out.error(number, 1, N_("a trace line needs {keys}", keys=" and ".join(missing)), hint)
        else:
            yield number, line
