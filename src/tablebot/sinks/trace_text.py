"""A simulator block's trace lines made in compiled code: the bytes :func:`tablebot.sinks.trace_file.block_lines`
makes in Python, at a tenth of the time (a simulated hour is 360,000 lines).

Only numbers need formatting: whole numbers, and decimals rounded to a few places. A double that is the
nearest one to k / 10^d (what Python's ``round(x, d)`` returns) prints in Python as that decimal, trailing
zeros dropped but one (``repr`` gives the shortest text that reads back as the same double, and no shorter
decimal lies within an ulp of it), in exponent form below 1e-4 (``5e-05``), as ``json`` writes it. A block
this module cannot write so (a number not finite, or too large for that rule) goes the Python way.
"""

from __future__ import annotations

import json
import math
from collections.abc import Sequence
from concurrent.futures import Executor

import numpy as np

from tablebot.jit import njit

# what each field of a line is (kinds): a whole number, a fired row (null when none), a state, a decimal
INT, ROW, STATE, DECIMAL = 0, 1, 2, 3
LARGEST = 2.0**50  # k / 10^d beyond this is left to Python (the rule above needs k well inside a double's 53 bits)
POW10 = np.array([10.0**d for d in range(16)])
DIGITS = 20  # at most, for an int64 with its sign


def _reused(scratch: dict[str, np.ndarray], name: str, size: int, dtype: type) -> np.ndarray:
    """A flat array of at least ``size`` items kept in ``scratch`` from one block to the next (its content is
    whatever the last block left), so that each block's few megabytes are not fresh memory to map again."""
    array = scratch.get(name)
    if array is None or len(array) < size:
        array = scratch[name] = np.empty(max(size, 2 * len(array) if array is not None else 0), dtype)
    return array


def block_bytes(
    pieces: Sequence[bytes],
    kinds: Sequence[int],
    columns: Sequence[np.ndarray],
    decimals: Sequence[int],
    names: Sequence[bytes],
) -> bytes | None:
    """The lines of a block: field f of each line is ``pieces[f]``, then the value of ``columns[f]`` for that
    line, written as ``kinds[f]`` says (DECIMAL: rounded to ``decimals[f]`` places; STATE: ``names[value]``);
    ``pieces[-1]`` ends each line. None when a DECIMAL value cannot be written here (see the module)."""
    views = block_views(pieces, kinds, columns, decimals, names, {})
    return None if views is None else b"".join(views)


SPLIT_FROM = 1024  # lines from which a helper thread writes the second half of a block at the same time


def block_views(
    pieces: Sequence[bytes],
    kinds: Sequence[int],
    columns: Sequence[np.ndarray],
    decimals: Sequence[int],
    names: Sequence[bytes],
    scratch: dict[str, np.ndarray],
    helper: Executor | None = None,
) -> list[memoryview] | None:
    """:func:`block_bytes` as views of ``scratch``'s memory (a writer's own dict of arrays, reused from one
    block to the next: the views are good until its next block), in one piece or, with ``helper`` (a
    thread) and a long block, two: the second half's lines written by ``helper`` meanwhile (the compiled
    writer leaves the GIL, so the halves take the two cores)."""
    own = scratch
    n, width = (len(columns[0]) if columns else 0), len(kinds)
    ints = _reused(own, "ints", n * width, np.int64)[: n * width].reshape(n, width)
    floats = _reused(own, "floats", n * width, np.float64)[: n * width].reshape(n, width)
    decimal = np.array(kinds) == DECIMAL
    for f, (kind, column) in enumerate(zip(kinds, columns, strict=True)):
        if kind == DECIMAL:
            floats[:, f] = column
        else:
            ints[:, f] = column
    if (ints[:, ~decimal] == np.iinfo(np.int64).min).any():
        return None
    if decimal.any():
        values = floats[:, decimal]
        places = np.array(decimals)[decimal]
        if not np.isfinite(values).all() or (np.abs(values) * POW10[places] >= LARGEST).any():
            return None
    piece_bytes = np.frombuffer(b"".join(pieces), dtype=np.uint8)
    piece_ends = np.cumsum([len(p) for p in pieces]).astype(np.int64)
    name_bytes = np.frombuffer(b"".join(names) or b" ", dtype=np.uint8)
    name_ends = np.cumsum([len(name) for name in names]).astype(np.int64)
    widest = max((len(name) for name in names), default=0) + DIGITS + 8
    line = len(piece_bytes) + widest * width  # the most a line can take
    fixed = (piece_bytes, piece_ends, np.array(kinds, dtype=np.int64))
    names_at = (np.array(decimals, dtype=np.int64), name_bytes, name_ends)
    half = n // 2 if helper is not None and n >= SPLIT_FROM else n
    out = _reused(own, "out", half * line, np.uint8)
    later = None
    if half < n:
        second = _reused(own, "second", (n - half) * line, np.uint8)
        assert helper is not None  # half < n only with a helper
        args = (second, *fixed, ints[half:], floats[half:], *names_at)  # one tuple: mypy misreads several *args
        later = helper.submit(_lines, *args)
    # numpy's stubs give ndarray a __buffer__ only for Python 3.12 on (mypy checks as 3.11)
    views = [memoryview(out)[: _lines(out, *fixed, ints[:half], floats[:half], *names_at)]]  # type: ignore[arg-type]
    if later is not None:
        views.append(memoryview(second)[: later.result()])  # type: ignore[arg-type]  # as above
    return views


@njit(nogil=True, refcounts=False)
def _lines(
    out: np.ndarray,
    pieces: np.ndarray,
    piece_ends: np.ndarray,
    kinds: np.ndarray,
    ints: np.ndarray,
    floats: np.ndarray,
    decimals: np.ndarray,
    names: np.ndarray,
    name_ends: np.ndarray,
) -> int:
    at = 0
    for t in range(ints.shape[0]):
        start = 0
        for f in range(kinds.shape[0]):
            at = _copy(out, at, pieces, start, piece_ends[f])
            start = piece_ends[f]
            kind = kinds[f]
            if kind == DECIMAL:
                at = _decimal(out, at, floats[t, f], decimals[f])
            elif kind == STATE:
                s = ints[t, f]
                at = _copy(out, at, names, 0 if s == 0 else name_ends[s - 1], name_ends[s])
            elif kind == ROW and ints[t, f] < 0:
                out[at], out[at + 1], out[at + 2], out[at + 3] = 110, 117, 108, 108  # null
                at += 4
            else:
                at = _whole(out, at, ints[t, f])
        at = _copy(out, at, pieces, start, piece_ends[piece_ends.shape[0] - 1])
    return at


@njit(nogil=True, refcounts=False, inline="always")
def _copy(out: np.ndarray, at: int, source: np.ndarray, a: int, b: int) -> int:
    for k in range(a, b):
        out[at] = source[k]
        at += 1
    return at


@njit(nogil=True, refcounts=False, inline="always")
def _digits(out: np.ndarray, at: int, value: int, width: int) -> int:
    """The decimal digits of ``value`` >= 0, at least ``width`` of them (leading zeros); returns the end."""
    count, power = 1, 10
    while count < 19 and value >= power:
        count += 1
        power *= 10
    end = at + max(count, width)
    rest = np.uint64(value)  # unsigned: division by the constant 10 needs no sign fix-ups
    for k in range(end - 1, at - 1, -1):
        out[k] = 48 + rest % np.uint64(10)
        rest //= np.uint64(10)
    return end


@njit(nogil=True, refcounts=False, inline="always")
def _whole(out: np.ndarray, at: int, value: int) -> int:
    """``str(value)`` of an int64 (but its most negative value, which block_bytes leaves to Python)."""
    if value < 0:
        out[at] = 45  # -
        at += 1
        value = -value
    return _digits(out, at, value, 1)


@njit(nogil=True, refcounts=False, inline="always")
def _decimal(out: np.ndarray, at: int, value: float, places: int) -> int:
    """``repr(value)`` of the double nearest k / 10^places (see the module), |k| < LARGEST."""
    if value < 0.0 or (value == 0.0 and math.copysign(1.0, value) < 0.0):
        out[at] = 45  # -
        at += 1
    k = np.int64(np.rint(abs(value) * POW10[places]))
    if k == 0:
        out[at], out[at + 1], out[at + 2] = 48, 46, 48  # 0.0
        return at + 3
    count, power = 1, 10
    while count < 19 and k >= power:
        count += 1
        power *= 10
    if count - places <= -4:  # below 1e-4: repr's exponent form, e.g. 5e-05 or 1.2e-05
        trimmed = k
        while trimmed % 10 == 0:
            trimmed //= 10
        first = _digits(out, at, trimmed, 1)
        if first - at > 1:  # d.ddd: move the digits after the first one place right for the point
            for j in range(first, at + 1, -1):
                out[j] = out[j - 1]
            out[at + 1] = 46  # .
            first += 1
        out[first], out[first + 1] = 101, 45  # e-
        return _digits(out, first + 2, places - count + 1, 2)
    # k's digits (at least one before the point), the point put in before the last ``places`` of them, and
    # trailing zeros of the fraction dropped but one
    end = _digits(out, at, k, places + 1)
    point = end - places
    for j in range(end, point, -1):
        out[j] = out[j - 1]
    out[point] = 46  # .
    end += 1
    while end - 1 > point + 1 and out[end - 1] == 48:
        end -= 1
    return end


def json_names(names: Sequence[object]) -> list[bytes]:
    """Each state as the trace writes it (JSON, UTF-8)."""
    return [json.dumps(name, ensure_ascii=False).encode() for name in names]
