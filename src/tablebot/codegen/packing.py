"""How a compiled machine becomes C data: integer widths, the first-match lookup and a table hash.
``dense`` is one entry per state and event set (O(1)); ``scan`` is each state's reachable rows in order."""

from __future__ import annotations

import zlib
from dataclasses import dataclass

from tablebot.diagnostics import fail
from tablebot.i18n import N_
from tablebot.machine import NO_ROW, Machine

#: ``auto`` uses the dense lookup while it needs at most this many bytes.
DENSE_LIMIT_BYTES = 8192
MAX_EVENTS = 32
MAX_COUNTERS = 8  # counter loads are flagged in one byte
KEEP = -128
LOOKUPS = ("auto", "dense", "scan")


@dataclass(frozen=True)
class CType:
    """An unsigned C integer type and its size."""

    name: str
    size: int

    @property
    def reader(self) -> str:
        """The tb_engine.h macro that reads one value of this type from const (PROGMEM) data."""
        return {1: "TB_RD8", 2: "TB_RD16", 4: "TB_RD32"}[self.size]


def unsigned_for(largest: int) -> CType:
    for size in (1, 2, 4):
        if largest < 1 << (8 * size):
            return CType(f"uint{8 * size}_t", size)
    raise ValueError(f"{largest} does not fit 32 bits")


@dataclass(frozen=True)
class Layout:
    """Everything the C text needs besides the machine itself."""

    event: CType
    state: CType
    row: CType
    no_row: int
    dense: bool
    lookup: tuple[int, ...]  # dense: per (state << n_events | events); scan: empty
    scan_start: tuple[int, ...]  # scan: per state, first entry; plus the end
    scan: tuple[tuple[int, int], ...]  # scan: (mask, row) per entry
    table_hash: int

    @property
    def lookup_bytes(self) -> int:
        if self.dense:
            return len(self.lookup) * self.row.size
        return 2 * len(self.scan_start) + len(self.scan) * (self.event.size + self.row.size)


def table_hash(machine: Machine) -> int:
    """A 32-bit fingerprint of behaviour: firmware reports it so a monitor can check its table."""
    return zlib.crc32(repr(machine.signature()).encode("utf-8"))


def check_fits(machine: Machine) -> None:
    """Refuse, naming the table, what the C engine's fixed-width data cannot hold."""
    table = machine.table
    n_events = len(table.events)
    if n_events > MAX_EVENTS:
        raise fail(
            table.path,
            N_("{count} event columns; the C engine holds at most {most}", count=n_events, most=MAX_EVENTS),
            N_("drop event columns the table does not need"),
            1,
        )
    counters = len(table.robot.counters)
    if counters > MAX_COUNTERS:
        raise fail(
            table.robot.source,
            N_("{count} counters; the C engine holds at most {most}", count=counters, most=MAX_COUNTERS),
            N_("use fewer counters"),
        )
    if len(machine.rows) >= 0xFFFF:
        raise fail(
            table.path,
            N_("{count} rows; the C engine holds at most 65534", count=len(machine.rows)),
            N_("split the table"),
        )


def reachable(rows: list[tuple[int, int]]) -> list[tuple[int, int]]:
    """Drop rows that never fire: an earlier row of the state needs a subset of their events."""
    kept: list[tuple[int, int]] = []
    for mask, index in rows:
        if not any(earlier & mask == earlier for earlier, _ in kept):
            kept.append((mask, index))
    return kept


def _scan(machine: Machine) -> tuple[tuple[int, ...], tuple[tuple[int, int], ...]]:
    per_state: list[list[tuple[int, int]]] = [[] for _ in machine.states]
    for row in machine.rows:
        per_state[row.state].append((row.mask, row.index))
    starts, entries = [0], []
    for rows in per_state:
        entries.extend(reachable(rows))
        starts.append(len(entries))
    return tuple(starts), tuple(entries)


def _dense(machine: Machine, no_row: int) -> tuple[int, ...]:
    n = len(machine.table.events)
    return tuple(
        no_row if (r := machine.lookup(s, ev)) == NO_ROW else r
        for s in range(len(machine.states))
        for ev in range(1 << n)
    )


def plan(machine: Machine, lookup: str = "auto") -> Layout:
    """Choose widths and the lookup strategy (``auto``, ``dense`` or ``scan``) for a machine."""
    if lookup not in LOOKUPS:
        raise ValueError(f"lookup must be one of {LOOKUPS}, not {lookup!r}")
    check_fits(machine)
    n_events = len(machine.table.events)
    row = unsigned_for(len(machine.rows))  # the largest value is the "no row" marker
    no_row = (1 << (8 * row.size)) - 1
    dense_bytes = len(machine.states) * (1 << n_events) * row.size if n_events <= 16 else None
    dense = lookup == "dense" or (lookup == "auto" and dense_bytes is not None and dense_bytes <= DENSE_LIMIT_BYTES)
    if dense and dense_bytes is None:
        raise fail(
            machine.table.path,
            N_("a dense lookup of {count} event bits is too large", count=n_events),
            N_("use the scan lookup"),
        )
    starts, entries = ((), ()) if dense else _scan(machine)
    return Layout(
        event=unsigned_for((1 << n_events) - 1 if n_events else 0),
        state=unsigned_for(len(machine.states) - 1),
        row=row,
        no_row=no_row,
        dense=dense,
        lookup=_dense(machine, no_row) if dense else (),
        scan_start=starts,
        scan=entries,
        table_hash=table_hash(machine),
    )
