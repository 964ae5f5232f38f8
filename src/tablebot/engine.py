"""The engine: one tick of a compiled machine, with the document's exact semantics.

Per tick: after the first tick the timer counts down (never below 0) and each counter counts down
by its pulses; the event set is the inputs that read 1 plus T (and each Cn) at 0; the first
matching row of the current state fires. The engine knows nothing of files, hardware or time.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

from tablebot.machine import NO_ROW, Machine


@dataclass(frozen=True)
class Batch:
    """Per-tick results of :meth:`Engine.run`: event mask, fired row (-1: none), state index, timer."""

    events: list[int]
    rows: list[int]
    states: list[int]
    timers: list[int]


class Engine:
    """A running machine: ``step(inputs) -> outputs``; its state is plain data (see ``snapshot``)."""

    def __init__(self, machine: Machine):
        self.machine = machine
        self.reset()

    def reset(self) -> None:
        m = self.machine
        self.tick = 0
        self.state = m.initial_state
        self.timer = m.initial_timer
        self.counters = [0] * len(m.counter_bits)
        self.outputs: tuple[int, ...] = (0,) * len(m.output_names)
        self.event = 0
        self.row = NO_ROW

    # --- the tick ------------------------------------------------------------------------------

    def events_of(self, inputs: int | Mapping[str, int]) -> int:
        """Input bits in the machine's event layout, from a mask or from ``{name: 0/1}``."""
        m = self.machine
        if isinstance(inputs, int):
            return inputs & m.input_mask
        bits = m.input_bits
        return sum(bits[name] for name, value in inputs.items() if value and name in bits)

    def step(self, inputs: int | Mapping[str, int] = 0, pulses: Sequence[int] = ()) -> tuple[int, ...]:
        """Advance one tick; ``pulses`` are encoder pulses per robot counter since the last tick."""
        m = self.machine
        events = self.events_of(inputs)
        if self.tick:
            if self.timer:
                self.timer -= 1
            for i, count in enumerate(pulses):
                self.counters[i] = max(0, self.counters[i] - count)
        self.tick += 1
        if self.timer == 0:
            events |= m.timer_bit
        if self.counters:
            events |= self._counter_events()
        self.event = events
        dispatch = m.dispatch[self.state]
        self.row = index = dispatch[events & dispatch.relevant]
        if index != NO_ROW:
            self._fire(index)
        return self.outputs

    def _fire(self, index: int) -> None:
        row = self.machine.rows[index]
        if row.keeps:
            merged = zip(self.outputs, row.outputs, strict=True)
            self.outputs = tuple(old if new is None else new for old, new in merged)
        else:
            self.outputs = row.outputs  # type: ignore[assignment]  # no None when not keeps
        self.timer = row.timer
        for i, load in enumerate(row.loads):
            if load is not None:
                self.counters[i] = load
        self.state = row.next

    # --- the batch path ------------------------------------------------------------------------

    def run(self, masks: Sequence[int]) -> Batch:
        """Many ticks in one call, inputs as event-layout bitmasks; same semantics as ``step``.

        No pulses arrive on this path: counters are loaded by rows but never count down.
        """
        m = self.machine
        rows, dispatch, input_mask, timer_bit = m.rows, m.dispatch, m.input_mask, m.timer_bit
        counters = self.counters
        const_bits = self._counter_events()
        state, timer, first = self.state, self.timer, self.tick == 0
        events_out: list[int] = []
        rows_out: list[int] = []
        states_out: list[int] = []
        timers_out: list[int] = []
        outputs = self.outputs
        for mask in masks:
            if first:
                first = False
            elif timer:
                timer -= 1
            events = (mask & input_mask) | const_bits
            if timer == 0:
                events |= timer_bit
            d = dispatch[state]
            index = d[events & d.relevant]
            if index != NO_ROW:
                row = rows[index]
                outputs = (tuple(o if n is None else n for o, n in zip(outputs, row.outputs, strict=True))
                           if row.keeps else row.outputs)
                timer = row.timer
                state = row.next
                if row.loads:
                    counters[:] = [c if n is None else n for c, n in zip(counters, row.loads, strict=True)]
                    const_bits = self._counter_events()
            events_out.append(events)
            rows_out.append(index)
            states_out.append(state)
            timers_out.append(timer)
        self.tick += len(masks)
        self.state, self.timer, self.outputs = state, timer, outputs  # type: ignore[assignment]
        if rows_out:
            self.event, self.row = events_out[-1], rows_out[-1]
        return Batch(events_out, rows_out, states_out, timers_out)

    def _counter_events(self) -> int:
        return sum(b for b, c in zip(self.machine.counter_bits, self.counters, strict=True) if c == 0)

    # --- saving and resuming -------------------------------------------------------------------

    def snapshot(self) -> dict[str, Any]:
        """The whole runtime state as plain JSON-able data."""
        m = self.machine
        return {
            "tick": self.tick,
            "state": m.states[self.state],
            "timer": self.timer,
            "counters": dict(zip(m.table.robot.counter_names, self.counters, strict=True)),
            "outputs": dict(zip(m.output_names, self.outputs, strict=True)),
        }

    def restore(self, snapshot: Mapping[str, Any]) -> None:
        """Resume from :meth:`snapshot` output; raises ValueError naming a field that does not fit.

        Everything is checked before anything changes, so a refused snapshot leaves the engine as it was.
        """
        m = self.machine
        tick, timer = _count(snapshot, "tick"), _count(snapshot, "timer")
        if "state" not in snapshot:
            raise ValueError("state: missing from the snapshot")
        if snapshot["state"] not in m.states:
            raise ValueError(f"state: {snapshot['state']!r} is not a state of this table")
        names = m.table.robot.counter_names
        counters = snapshot.get("counters", {})
        outputs = snapshot.get("outputs", {})
        if set(counters) != set(names) or set(outputs) != set(m.output_names):
            raise ValueError(f"counters/outputs must name exactly {names} and {m.output_names}")
        try:
            counter_values = [int(counters[n]) for n in names]
            output_values = tuple(int(outputs[n]) for n in m.output_names)
        except (TypeError, ValueError):
            raise ValueError("counters/outputs: every value must be an integer") from None
        self.tick, self.state, self.timer = tick, m.states.index(snapshot["state"]), timer
        self.counters, self.outputs = counter_values, output_values


def _count(snapshot: Mapping[str, Any], key: str) -> int:
    """A snapshot's tick or timer: present, an integer, not negative."""
    if key not in snapshot:
        raise ValueError(f"{key}: missing from the snapshot")
    value = snapshot[key]
    if isinstance(value, bool) or not isinstance(value, int):
        raise ValueError(f"{key}: {value!r} is not an integer")
    if value < 0:
        raise ValueError(f"{key}: {value} must not be negative")
    return value
