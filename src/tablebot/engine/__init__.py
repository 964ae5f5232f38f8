"""The engine: one tick of a compiled machine, with the document's exact semantics.

Per tick: after the first tick the timer counts down (never below 0) and each counter counts down
by its pulses; the event set is the inputs that read 1 plus T (and each Cn) at 0; the first
matching row of the current state fires (:meth:`tablebot.machine.Machine.lookup`, which also decides a
tick with no event by the table's rule). The engine knows nothing of files, hardware or time.

The package: :class:`Engine` (one table, here), :class:`~tablebot.engine.batch.Batch` (what a batch of ticks
gives back), the per-state lookups the step indexes (:mod:`tablebot.engine.lookups`) and a robot of several
tables (:class:`tablebot.engine.several.Several`).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from tablebot.engine.batch import Batch, mask_array
from tablebot.engine.lookups import Entry, Lookups, bits_text, mask_of_names, snapshot_count
from tablebot.machine import NO_ROW, Machine, MachineArrays

__all__ = ["Batch", "Engine"]


class Engine:
    """A running machine: ``step(inputs) -> outputs``; its state is plain data (see ``snapshot``).

    The public attributes ``tick``, ``state`` (index into ``machine.states``), ``timer``, ``counters``,
    ``outputs`` (signed motor speeds, then lamp levels), ``event`` and ``row`` (of the last tick) are
    the whole runtime state. ``tick``, ``timer`` and ``counters`` are properties over the form
    :meth:`step` keeps them in (a deadline instead of a counting timer, the lookups for the counters
    now at 0): read and assign them as plain attributes; ``counters`` reads as a copy. Everything
    else starting with ``_`` is the machine, precomputed for speed.
    """

    # set by reset() and the property setters, all called from __init__
    _tick: int
    _deadline: int
    _counters: list[int]
    _zero_counters: int
    _running: list[Any]  # per state, the lookup of Lookups for a running timer
    _at_zero: list[Any]  # and for a timer at 0

    def __init__(self, machine: Machine) -> None:
        self.machine = machine
        self._width = len(machine.table.events)
        self._counter_bits = machine.counter_bits if any(machine.counter_bits) else ()
        self._n_counters = len(machine.counter_bits)
        self._lookups = Lookups(machine)
        self.reset()

    def reset(self) -> None:
        m = self.machine
        self._tick = 0
        self.state = m.initial_state
        self.timer = m.initial_timer
        self.counters = [0] * self._n_counters
        self.outputs: tuple[int, ...] = (0,) * len(m.output_names)
        self.event = 0
        self.row = NO_ROW

    # --- the tick ------------------------------------------------------------------------------

    def step(
        self, inputs: int | np.integer | Mapping[str, int] = 0, pulses: Sequence[int] | np.ndarray | None = None
    ) -> tuple[int, ...]:
        """Advance one tick; ``pulses`` are encoder pulses per robot counter since the last tick (a sequence or
        numpy array; None or () when there are none).

        The rule of :func:`tablebot.tick.tick`, step by step, in the form that costs Python least a tick:

        1. the timer is kept as ``_deadline``, the tick count at which counting it down by one a tick
           (after the first) brings it to 0: T is present from then on, and ``timer`` is worked out when
           read. The counters count down by their pulses in :meth:`_count_down`;
        2. and 3. per state, a list indexed by the input mask gives the tick's event set (the mask's T
           and Cn bits dropped, the engine's own added), the row that fires and its effect, all made
           from :meth:`tablebot.machine.Machine.lookup` (:class:`Lookups`): a list for a running timer
           and one for a timer at 0, for the counters now at 0 (chosen when the counters change);
        4. the effect sets the state, timer, outputs (merging kept ones) and counter loads.

        The lookup checks the mask as well: one beyond the table's event columns falls off the end of
        its list. Anything but a non-negative int (a bool, numpy integer, mapping, ...) goes through
        :meth:`events_of`, which converts or refuses it. A refused tick changes nothing.
        """
        if type(inputs) is not int or inputs < 0:  # type() is a call CPython specialises, x.__class__ is not
            inputs = self.events_of(inputs)
        tick = self._tick + 1
        if pulses is not None and pulses is not _NONE:  # None, and the () of callers without counters: nothing
            self._count_down(pulses, tick, inputs)
        try:
            self.event, self.row, effect = (self._running if tick < self._deadline else self._at_zero)[self.state][
                inputs
            ]
        except IndexError:  # the state's list is not made yet, or the mask is beyond the table's events
            self.event, self.row, effect = self._entry(tick, inputs)
        self._tick = tick
        if effect is None:  # no row fired: nothing else changes (the deadline already counts the timer down)
            return self.outputs
        self.state, timer, outputs, keeps, loads = effect
        self._deadline = tick + timer
        if keeps:
            outputs = tuple(old if new is None else new for old, new in zip(self.outputs, outputs, strict=True))
        self.outputs = outputs
        if loads:  # () unless the row loads a counter
            self._counters = [old if new is None else new for old, new in zip(self._counters, loads, strict=True)]
            self._choose_lookups()
        return outputs

    def events_of(self, inputs: int | np.integer | Mapping[str, int]) -> int:
        """Input bits in the machine's event layout, from a mask or from ``{name: 0/1}``.

        Raises ValueError for an unknown name, a value other than 0/1, a negative mask or a mask with
        bits beyond the table's events (T's and the counters' bits are ignored: the engine makes them).
        """
        m = self.machine
        if isinstance(inputs, Mapping):
            return mask_of_names(m, inputs)
        if isinstance(inputs, bool) or not isinstance(inputs, int | np.integer):
            raise ValueError(f"inputs must be an int mask or a mapping of input names, not {type(inputs).__name__}")
        value = int(inputs)
        width = self._width
        if value < 0 or value >> width:
            raise ValueError(
                f"input mask {value} is not a mask of this table's {width} event columns "
                f"(0..{(1 << width) - 1}); its inputs are {bits_text(m)}"
            )
        return value & m.input_mask

    def _entry(self, tick: int, inputs: int) -> Entry:
        """:meth:`step`'s lookup when it raised IndexError: the state's list is made on its first tick,
        and a mask beyond the table's events is refused here, before anything has changed."""
        present = self._zero_counters if tick < self._deadline else self._zero_counters | self.machine.timer_bit
        try:
            return self._lookups.made(present, self.state)[inputs]
        except IndexError:
            self.events_of(inputs)  # raises for a mask beyond the table's events
            raise  # a state out of range: not the input's fault

    def _count_down(self, pulses: Sequence[int] | np.ndarray, tick: int, inputs: int) -> None:
        """Each counter down by its pulses, from the second tick on; the mask and the pulses are checked
        first, so a refused tick changes nothing."""
        if tick == 1:
            return
        if inputs >> self._width:  # the lookup checks the mask only after the counters have changed: check it now
            self.events_of(inputs)  # raises
        counters = self._counters
        if len(pulses) != len(counters):
            if not len(pulses):
                return
            raise ValueError(
                f"pulses: {len(pulses)} values for {len(counters)} counters "
                f"({', '.join(self.machine.table.robot.counter_names) or 'none'})"
            )
        if min(pulses, default=0) < 0:
            i = next(i for i, count in enumerate(pulses) if count < 0)
            raise ValueError(f"pulses: {pulses[i]} for counter {i + 1} is negative")
        reached_zero = False
        for i, count in enumerate(pulses):
            if count and counters[i]:
                counters[i] = left = max(0, counters[i] - int(count))  # int: numpy counts would leak into JSON
                reached_zero = reached_zero or not left
        if reached_zero:  # a Cn event appears: other lookups (counting down never takes one away)
            self._choose_lookups()

    # --- the state step keeps in its own form --------------------------------------------------

    @property
    def tick(self) -> int:
        return self._tick

    @tick.setter
    def tick(self, value: int) -> None:
        timer = self.timer
        self._tick = value
        self.timer = timer

    @property
    def timer(self) -> int:
        # the deadline counts from tick 1: the first tick does not count the timer down
        return max(0, self._deadline - max(self._tick, 1))

    @timer.setter
    def timer(self, value: int) -> None:
        self._deadline = max(self._tick, 1) + value

    @property
    def counters(self) -> list[int]:
        return list(self._counters)

    @counters.setter
    def counters(self, values: Sequence[int]) -> None:
        self._counters = list(values)
        self._choose_lookups()

    def _choose_lookups(self) -> None:
        """The lookups for the Cn bits of the counters at 0; called whenever a counter may have reached
        or left 0, so that a tick needs no counter test."""
        zero = (
            sum(bit for bit, count in zip(self._counter_bits, self._counters, strict=True) if count == 0)
            if self._counter_bits
            else 0
        )  # () when no counter is an event column
        self._zero_counters = zero
        self._running, self._at_zero = self._lookups[zero], self._lookups[zero | self.machine.timer_bit]

    # --- the batch path ------------------------------------------------------------------------

    def run(
        self,
        masks: Sequence[int] | np.ndarray,
        pulses: Sequence[Sequence[int]] | np.ndarray | None = None,
        *,
        jit: bool | None = None,
    ) -> Batch:
        """Many ticks in one call, inputs as event-layout bitmasks; same semantics as ``step``.

        ``pulses`` (one row per mask, a value per counter) count the counters down; without them the
        counters are loaded by rows but never count down. With numba
        (``jit`` None or True) the loop runs compiled (:func:`tablebot.tick.tick` over the machine's
        arrays); ``jit=False``, a table wider than FLAT_BITS events, or no numba step in Python.
        """
        arrays = self.machine.arrays
        if jit is not False and arrays is not None:
            from tablebot import engine_batch as kernels

            if kernels.available():
                return self._run_compiled(arrays, mask_array(masks, self._width), self._pulse_array(pulses, len(masks)))
        if jit:
            raise RuntimeError("the compiled batch path needs numba and at most FLAT_BITS event columns")
        return self._run_python(masks, pulses)

    def _pulse_array(self, pulses: Sequence[Sequence[int]] | np.ndarray | None, ticks: int) -> np.ndarray:
        n = self._n_counters
        if pulses is None:
            return np.zeros((0, n), dtype=np.int64)
        array = np.asarray(pulses, dtype=np.int64).reshape(-1, n) if n else np.zeros((len(pulses), 0), np.int64)
        if len(array) != ticks or (array.size and array.min() < 0):
            raise ValueError(f"pulses: need one row of {n} counts (0 or more) per mask, {ticks} rows")
        return array

    def _run_compiled(self, arrays: MachineArrays, masks: np.ndarray, pulses: np.ndarray) -> Batch:
        from tablebot import engine_batch as kernels
        from tablebot.tick import registers

        n = len(masks)
        columns = np.empty((4, n), dtype=np.int32)  # half the memory traffic of int64; values fit easily
        regs = registers(self.tick, self.state, self.timer, self.event, self.row)
        outputs = np.array(self.outputs, dtype=np.int64)
        counters = np.array(self.counters, dtype=np.int64)
        kernels.batch(masks, pulses, regs, outputs, counters, arrays.program, columns)
        self._sync(regs, outputs, counters)
        return Batch(*columns)

    def _sync(self, regs: np.ndarray, outputs: np.ndarray, counters: np.ndarray) -> None:
        """Take the registers a compiled loop left (tick.TICK, STATE, ...) as this engine's state."""
        self.tick, self.state, self.timer, self.event, self.row = (int(v) for v in regs[:5])
        self.outputs = tuple(outputs.tolist())
        self.counters = counters.tolist()

    def _run_python(
        self, masks: Sequence[int] | np.ndarray, pulses: Sequence[Sequence[int]] | np.ndarray | None
    ) -> Batch:
        """The batch loop without numba: ``step`` per tick, collecting the columns."""
        columns: tuple[list[int], ...] = ([], [], [], [])
        step = self.step
        per_tick = self._pulse_array(pulses, len(masks)).tolist() if pulses is not None else None
        for i, mask in enumerate(masks):
            step(mask, None if per_tick is None else per_tick[i])
            for column, value in zip(columns, (self.event, self.row, self.state, self.timer), strict=True):
                column.append(value)
        return Batch(*columns)

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
        tick, timer = snapshot_count(snapshot, "tick"), snapshot_count(snapshot, "timer")
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


# pulses that count nothing: a caller's () is this very object in CPython (one empty tuple), so step skips it
# with an identity test; any other empty sequence reaches _count_down, which counts nothing either
_NONE: tuple[int, ...] = ()
