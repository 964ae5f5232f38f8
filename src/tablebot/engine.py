"""The engine: one tick of a compiled machine, with the document's exact semantics.

Per tick: after the first tick the timer counts down (never below 0) and each counter counts down
by its pulses; the event set is the inputs that read 1 plus T (and each Cn) at 0; the first
matching row of the current state fires. The engine knows nothing of files, hardware or time.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from typing import Any

import numpy as np

from tablebot.machine import NO_ROW, CompiledRow, Machine, MachineArrays


class Batch:
    """Per-tick results of :meth:`Engine.run`: event mask, fired row (-1: none), state index, timer.

    The compiled path fills integer arrays (:attr:`arrays`); the list attributes are made from them
    on first use, so a caller that only wants the arrays (or nothing) pays nothing for lists.
    """

    FIELDS = ("events", "rows", "states", "timers")

    def __init__(self, events: Sequence[int], rows: Sequence[int], states: Sequence[int], timers: Sequence[int]):
        self._columns: dict[str, Sequence[int]] = dict(zip(self.FIELDS, (events, rows, states, timers), strict=True))

    def _list(self, name: str) -> list[int]:
        column = self._columns[name]
        if not isinstance(column, list):
            column = self._columns[name] = np.asarray(column).tolist()
        return column

    @property
    def events(self) -> list[int]:
        return self._list("events")

    @property
    def rows(self) -> list[int]:
        return self._list("rows")

    @property
    def states(self) -> list[int]:
        return self._list("states")

    @property
    def timers(self) -> list[int]:
        return self._list("timers")

    @property
    def arrays(self) -> tuple[np.ndarray, ...]:
        """events, rows, states, timers as integer numpy arrays (no copy on the compiled path)."""
        return tuple(np.asarray(self._columns[name]) for name in self.FIELDS)

    def __len__(self) -> int:
        return len(self._columns["events"])

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Batch):
            return NotImplemented
        return all(self._list(name) == other._list(name) for name in self.FIELDS)

    __hash__ = None  # type: ignore[assignment]  # mutable caches; equality is by value

    def __repr__(self) -> str:
        return f"Batch({', '.join(f'{name}={self._list(name)!r}' for name in self.FIELDS)})"


class Engine:
    """A running machine: ``step(inputs) -> outputs``; its state is plain data (see ``snapshot``).

    The public attributes ``tick``, ``state`` (index into ``machine.states``), ``timer``, ``counters``,
    ``outputs`` (signed motor speeds, then lamp levels), ``event`` and ``row`` (of the last tick) are
    the whole runtime state; everything starting with ``_`` is a copy of the machine kept for speed.
    """

    def __init__(self, machine: Machine):
        self.machine = machine
        # Hot-loop constants, read once here instead of through properties on every tick.
        self._input_mask = machine.input_mask
        self._timer_bit = machine.timer_bit
        self._counter_bits = machine.counter_bits if any(machine.counter_bits) else ()
        self._rows = machine.rows
        self._flat = machine.flat
        self._width = len(machine.table.events)
        self._lookup = machine.lookup  # tables too wide for the flat list
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
        if isinstance(inputs, Mapping):
            bits = self.machine.input_bits
            return sum(bits[name] for name, value in inputs.items() if value and name in bits)
        return int(inputs) & self._input_mask  # also numpy integers

    def step(self, inputs: int | Mapping[str, int] = 0, pulses: Sequence[int] = ()) -> tuple[int, ...]:
        """Advance one tick; ``pulses`` are encoder pulses per robot counter since the last tick."""
        # type(...) is int: the common case skips events_of's isinstance checks (this runs per tick)
        events = inputs & self._input_mask if type(inputs) is int else self.events_of(inputs)
        if self.tick:
            if self.timer:
                self.timer -= 1
            if len(pulses):  # len, not truth: pulses may be a numpy array
                self._count_down(pulses)
        self.tick += 1
        if not self.timer:
            events |= self._timer_bit
        if self._counter_bits:
            events |= self._counter_events()
        self.event = events
        flat = self._flat
        index = flat[self.state << self._width | events] if flat is not None else self._lookup(self.state, events)
        self.row = index
        if index != NO_ROW:
            self._fire(self._rows[index])
        return self.outputs

    def _count_down(self, pulses: Sequence[int]) -> None:
        counters = self.counters
        for i, count in enumerate(pulses):
            counters[i] = max(0, counters[i] - int(count))  # int: numpy counts would leak into JSON

    def _fire(self, row: CompiledRow) -> None:
        if row.keeps:
            self.outputs = tuple(old if new is None else new
                                 for old, new in zip(self.outputs, row.outputs, strict=True))
        else:
            self.outputs = row.outputs  # type: ignore[assignment]  # no None in a row that keeps nothing
        self.timer = row.timer
        if row.loads:
            self.counters = [old if new is None else new for old, new in zip(self.counters, row.loads, strict=True)]
        self.state = row.next

    def _counter_events(self) -> int:
        """Cn bits of the counters at zero (0 when no counter is an event column)."""
        if not self._counter_bits:
            return 0
        return sum(b for b, c in zip(self._counter_bits, self.counters, strict=True) if c == 0)

    # --- the batch path ------------------------------------------------------------------------

    def run(self, masks: Sequence[int] | np.ndarray, *, jit: bool | None = None) -> Batch:
        """Many ticks in one call, inputs as event-layout bitmasks; same semantics as ``step``.

        No pulses arrive on this path: counters are loaded by rows but never count down. With numba
        (``jit`` None or True) the loop runs compiled over the machine's arrays; ``jit=False``, a
        table wider than FLAT_BITS events, or no numba, run the same loop in Python.
        """
        kernel = _kernel() if jit is not False and self.machine.arrays is not None else None
        if kernel is None:
            if jit:
                raise RuntimeError("the compiled batch path needs numba and at most FLAT_BITS event columns")
            return self._run_python(masks)
        return self._run_compiled(kernel, self.machine.arrays, masks)  # type: ignore[arg-type]

    def _run_compiled(self, kernel: Callable[..., Any], arrays: MachineArrays, masks: Sequence[int]) -> Batch:
        masks = _mask_array(masks)
        n = len(masks)
        columns = np.empty((4, n), dtype=np.int32)  # half the memory traffic of int64; values fit easily
        outputs = np.array(self.outputs, dtype=np.int64)
        counters = np.array(self.counters, dtype=np.int64)
        a = arrays
        self.state, self.timer = kernel(
            masks, self._input_mask, self._timer_bit, a.lookup, a.next, a.timer, a.outputs, a.keep, a.loads,
            a.load_set, a.counter_bits, self.state, self.timer, self.tick == 0, outputs, counters, columns)
        self._finish(n, tuple(outputs.tolist()), counters.tolist())
        if n:
            self.event, self.row = int(columns[0, -1]), int(columns[1, -1])
        return Batch(*columns)

    def _run_python(self, masks: Sequence[int]) -> Batch:
        """The batch loop without numba: step's semantics with the per-tick work inlined."""
        rows, input_mask, timer_bit = self._rows, self._input_mask, self._timer_bit
        flat, width, lookup = self._flat, self._width, self._lookup
        state, timer, first, outputs = self.state, self.timer, self.tick == 0, self.outputs
        counter_bits = self._counter_events()
        events_out: list[int] = []
        rows_out: list[int] = []
        states_out: list[int] = []
        timers_out: list[int] = []
        for mask in masks:
            if first:
                first = False
            elif timer:
                timer -= 1
            events = (int(mask) & input_mask) | counter_bits
            if not timer:
                events |= timer_bit
            index = flat[state << width | events] if flat is not None else lookup(state, events)
            if index != NO_ROW:
                row = rows[index]
                outputs = (tuple(o if n is None else n for o, n in zip(outputs, row.outputs, strict=True))
                           if row.keeps else row.outputs)
                timer, state = row.timer, row.next
                if row.loads:
                    self.counters = [c if n is None else n for c, n in zip(self.counters, row.loads, strict=True)]
                    counter_bits = self._counter_events()
            events_out.append(events)
            rows_out.append(index)
            states_out.append(state)
            timers_out.append(timer)
        self.state, self.timer = state, timer
        self._finish(len(events_out), outputs, self.counters)  # type: ignore[arg-type]
        if events_out:
            self.event, self.row = events_out[-1], rows_out[-1]
        return Batch(events_out, rows_out, states_out, timers_out)

    def _finish(self, ticks: int, outputs: tuple[int, ...], counters: list[int]) -> None:
        self.tick += ticks
        self.outputs, self.counters = outputs, counters

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


# --- the compiled batch loop ----------------------------------------------------------------------

def _mask_array(masks: Sequence[int] | np.ndarray) -> np.ndarray:
    """Masks as a contiguous uint8 or int64 array (the two types the kernel is compiled for).

    A list of masks below 256 (any table with at most eight event columns) goes through
    ``bytearray``, about 2 ns per tick, where ``np.array(list)`` costs about 17.
    """
    if isinstance(masks, np.ndarray):
        return np.ascontiguousarray(masks, dtype=np.uint8 if masks.dtype == np.uint8 else np.int64)
    try:
        return np.frombuffer(bytearray(masks), dtype=np.uint8)
    except (TypeError, ValueError):  # a mask of 256 or more (or a negative one): the general path
        return np.asarray(masks, dtype=np.int64)


_KERNEL: list[Callable[..., Any] | None] = []


def _kernel() -> Callable[..., Any] | None:
    """The numba-compiled batch loop, built on first use (importing numba costs ~0.2 s, compiling
    ~1 s, cached on disk after); None when numba is not installed."""
    if not _KERNEL:
        try:
            import numba
        except ImportError:  # pragma: no cover - numba is a dependency, but the engine works without it
            _KERNEL.append(None)
        else:
            _KERNEL.append(numba.njit(cache=True, nogil=True)(_batch_loop))
    return _KERNEL[0]


def _batch_loop(masks, input_mask, timer_bit, lookup, nxt, timers, new_outputs, keep, loads, load_set,
                counter_bits, state, timer, first, outputs, counters, columns):  # type: ignore[no-untyped-def]
    """Engine.step's semantics over arrays (see MachineArrays); writes events, rows, states, timers
    per tick into ``columns`` and updates ``outputs``/``counters`` in place; returns (state, timer)."""
    present = 0
    for c in range(counters.shape[0]):
        if counters[c] == 0:
            present |= counter_bits[c]
    for i in range(masks.shape[0]):
        if first:
            first = False
        elif timer > 0:
            timer -= 1
        events = (masks[i] & input_mask) | present
        if timer == 0:
            events |= timer_bit
        row = lookup[state, events]
        if row >= 0:
            for k in range(outputs.shape[0]):
                if not keep[row, k]:
                    outputs[k] = new_outputs[row, k]
            timer = timers[row]
            state = nxt[row]
            if counters.shape[0]:
                present = 0
                for c in range(counters.shape[0]):
                    if load_set[row, c]:
                        counters[c] = loads[row, c]
                    if counters[c] == 0:
                        present |= counter_bits[c]
        columns[0, i] = events
        columns[1, i] = row
        columns[2, i] = state
        columns[3, i] = timer
    return state, timer
