"""Durations people write (``50``, ``500ms``, ``0.5 s``, ``0,5 s``, ``3 ticks``) as whole engine ticks.

A decimal comma is a decimal point (``0,5s``, ``1,25 s``: a German spreadsheet writes them so; in a comma-separated
file such a cell is quoted, and German Excel separates cells with ``;`` anyway).

One home for the rule, shared by the table's timer cells and the properties' ``within``: a duration
must be a whole number of ticks, and when it is not, the nearest values that are get named.
Arithmetic is exact (fractions), so ``0.1 s`` at 10 ms is 10 ticks, not 9.999….
"""

from __future__ import annotations

import math
import re
from fractions import Fraction

from tablebot.i18n import N_, NP_, Message

DURATION_RE = re.compile(r"^\s*(\d+(?:[.,]\d*)?|[.,]\d+)\s*(ticks?|ms|s)?\s*$", re.IGNORECASE)
MS_PER = {"ms": 1, "s": 1000}
#: The longest number, in characters, read from what people write (table cells, durations, state numbers, the
#: numbers of a TOML file): no count, state or time comes near it, and ``int()`` of a longer one may fail
#: (Python refuses to convert more than 4,300 digits, a guard against conversions that take seconds).
MAX_NUMBER_CHARS = 100


def seconds(ticks: float, tick_ms: int) -> float:
    """``ticks`` ticks of ``tick_ms`` in seconds: the one place a tick count becomes seconds
    (multiplied before dividing, so a whole number of milliseconds stays exact)."""
    return ticks * tick_ms / 1000


class DurationError(ValueError):
    """A duration that cannot be read or is no whole number of ticks; ``hint`` says what to write."""

    def __init__(self, message: Message, hint: Message) -> None:
        super().__init__(message)
        self.message, self.hint = message, hint


def to_ticks(text: str, tick_ms: int) -> int:
    """The whole ticks ``text`` stands for (a bare number counts ticks); raises :class:`DurationError`."""
    match = DURATION_RE.match(text)
    if match is None:
        raise DurationError(N_("{text!r} is not a duration", text=text.strip()), _forms(tick_ms))
    if len(match[1]) > MAX_NUMBER_CHARS:
        raise DurationError(
            N_("a number of {count:,} characters is no duration", count=len(match[1])),
            N_("{forms}; a number has at most {most} characters", forms=_forms(tick_ms), most=MAX_NUMBER_CHARS),
        )
    amount, unit = Fraction(match[1].replace(",", ".")), (match[2] or "ticks").lower()
    ticks = amount if unit.startswith("tick") else amount * MS_PER[unit] / tick_ms
    if ticks.denominator == 1:
        return int(ticks)
    shown = text.strip()
    if unit.startswith("tick"):
        raise DurationError(
            N_("{text} is not a whole number of ticks", text=shown),
            N_(
                "nearest: {below} or {above} (one tick is {tick} ms)",
                below=math.floor(ticks),
                above=math.ceil(ticks),
                tick=tick_ms,
            ),
        )
    below, above = (nearest(t, unit, tick_ms) for t in (math.floor(ticks), math.ceil(ticks)))
    raise DurationError(
        N_("{text} is not a whole number of {tick} ms ticks", text=shown, tick=tick_ms),
        N_("nearest: {below} or {above}", below=below, above=above),
    )


def _forms(tick_ms: int) -> Message:
    """The forms a duration may take, for a hint."""
    return N_("write ticks (50) or a time: 500ms, 0.5s or 0,5s (one tick is {tick} ms)", tick=tick_ms)


def nearest(ticks: int, unit: str, tick_ms: int) -> Message:
    """``500ms (50 ticks)``: a tick count shown in the unit the user wrote."""
    amount = Fraction(ticks * tick_ms, MS_PER[unit])
    number = str(amount.numerator) if amount.denominator == 1 else f"{float(amount):g}"
    return NP_("{number}{unit} ({n} tick)", "{number}{unit} ({n} ticks)", ticks, number=number, unit=unit)
