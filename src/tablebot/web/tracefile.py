"""Trace files (``sim``, a real robot run, firmware ``monitor``) read into columns for the trace player,
with a located error for a line that is not a trace line."""

from __future__ import annotations

from collections.abc import Iterable
from typing import Any

from tablebot.diagnostics import fail
from tablebot.formats.trace_lines import parse_trace
from tablebot.i18n import N_

#: The largest trace the browser's player opens (it holds every column in the page); tablebot itself reads
#: traces up to :data:`tablebot.formats.trace_lines.MAX_TRACE_BYTES`.
MAX_PLAYER_TRACE_BYTES = 64 * 1024 * 1024
REQUIRED = ("tick", "state")
#: Columns the player draws when a trace has them (core fields, then the simulator's pose).
KNOWN = ("tick", "event", "row", "state", "timer", "x", "y", "heading", "battery_v")


def trace_columns(lines: Iterable[dict[str, Any]]) -> dict[str, list[Any]]:
    """Trace lines as columns: every key that any line has (missing values are null)."""
    rows = list(lines)
    keys: dict[str, None] = {}
    for line in rows:
        for key in line:
            keys.setdefault(key, None)
    return {key: [line.get(key) for line in rows] for key in keys}


def read_trace_bytes(data: bytes, name: str) -> list[dict[str, Any]]:
    """Parse JSON Lines (through the one trace reader, :func:`tablebot.formats.trace_lines.parse_trace`); every bad line
    is reported (the first ten) with its number."""
    if len(data) > MAX_PLAYER_TRACE_BYTES:
        raise fail(
            name,
            N_(
                "the trace has {size:,} bytes; the player opens traces up to {limit:,}",
                size=len(data),
                limit=MAX_PLAYER_TRACE_BYTES,
            ),
            N_("cut the run shorter (--seconds) or open a part of it"),
        )
    try:
        text = data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        raise fail(name, N_("byte {at} is not UTF-8 text", at=exc.start), N_("a trace is JSON Lines text")) from None
    lines = parse_trace(text, name, REQUIRED)
    if not lines:
        raise fail(name, N_("the trace has no lines"), N_("open a trace.jsonl written by tablebot"))
    return lines
