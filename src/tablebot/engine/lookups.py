"""The engine's per-state lookups: for each input mask, the tick's event set, the row that fires and what it does,
made from :meth:`tablebot.machine.Machine.lookup` on first use (:class:`tablebot.engine.Engine` indexes them)."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from tablebot.machine import NO_ROW, CompiledRow, Machine

#: What a fired row does: (next state, timer, outputs (None = keep), keeps any, counter loads or ()).
Effect = tuple[int, int, tuple[int | None, ...], bool, tuple[int | None, ...]]
#: A tick's outcome for one input mask: (event set, fired row or -1, the row's effect or None).
Entry = tuple[int, int, Effect | None]


def _effect(row: CompiledRow) -> Effect:
    return row.next, row.timer, row.outputs, row.keeps, row.loads if any(v is not None for v in row.loads) else ()


class Lookups(dict[int, list[Any]]):
    """The engine's own events present (bits of T and of the counters at 0) -> per state, the lookup
    input mask -> :data:`Entry`.

    A state's lookup is a list over every mask of the table's event columns (tables up to FLAT_BITS
    events), empty until :meth:`made` on the first tick that needs it, or a dict that fills itself from
    :meth:`Machine.lookup` (wider tables); either raises IndexError for a mask beyond the event
    columns. A mask's T and Cn bits are ignored, as :meth:`Engine.events_of` ignores them: the engine
    makes those events.
    """

    def __init__(self, machine: Machine) -> None:
        super().__init__()
        self.machine = machine
        self.effects = [_effect(row) for row in machine.rows]
        self.idle: dict[int, Entry] = {}  # the entry of an event set that fires no row, shared by all states

    def __missing__(self, present: int) -> list[Any]:
        m = self.machine
        self[present] = lookups = [
            [] if m.flat is not None else WideEntries(self, state, present) for state in range(len(m.states))
        ]
        return lookups

    def made(self, present: int, state: int) -> list[Entry] | WideEntries:
        """The lookup of ``state`` when ``present`` are in the event set, its list made if still empty."""
        lookup = self[present][state]
        if isinstance(lookup, list) and not lookup:
            m = self.machine
            width = len(m.table.events)
            keep, flat, base = m.input_mask, m.flat, state << width
            entries: dict[int, Entry] = {}  # masks that differ only in T or Cn bits share an entry
            for mask in range(1 << width):
                events = mask & keep | present
                if (entry := entries.get(events)) is None:
                    entry = entries[events] = self.entry(events, flat[base + events])  # type: ignore[index]
                lookup.append(entry)
        return lookup

    def entry(self, events: int, row: int) -> Entry:
        if row == NO_ROW:
            return self.idle.setdefault(events, (events, NO_ROW, None))
        return events, row, self.effects[row]


class WideEntries(dict[int, Entry]):
    """One state's lookup in a table wider than FLAT_BITS events: input mask -> entry, made on first use."""

    def __init__(self, lookups: Lookups, state: int, present: int) -> None:
        super().__init__()
        self.lookups, self.state, self.present = lookups, state, present

    def __missing__(self, mask: int) -> Entry:
        m = self.lookups.machine
        if mask >> len(m.table.events):
            raise IndexError(mask)  # as the list of a narrower table would
        events = mask & m.input_mask | self.present
        self[mask] = entry = self.lookups.entry(events, m.lookup(self.state, events))
        return entry


def mask_of_names(machine: Machine, inputs: Mapping[str, int]) -> int:
    bits = machine.input_bits
    mask = 0
    for name, value in inputs.items():
        if name not in bits:
            raise ValueError(f"unknown input {name!r}; the inputs are {bits_text(machine)}")
        if value not in (0, 1) or not isinstance(value, int | np.integer):
            raise ValueError(f"input {name!r}: {value!r} is not 0 or 1")
        if value:
            mask |= bits[name]
    return mask


def bits_text(machine: Machine) -> str:
    return ", ".join(f"{name}={bit}" for name, bit in machine.input_bits.items()) or "none"


def snapshot_count(snapshot: Mapping[str, Any], key: str) -> int:
    """A snapshot's tick or timer: present, an integer, not negative."""
    if key not in snapshot:
        raise ValueError(f"{key}: missing from the snapshot")
    value = snapshot[key]
    if isinstance(value, bool) or not isinstance(value, int):
        raise ValueError(f"{key}: {value!r} is not an integer")
    if value < 0:
        raise ValueError(f"{key}: {value} must not be negative")
    return value
