"""A simulated run's trace as one numpy record per tick: the fields of ``trace.jsonl`` (tick, event, row,
state, timer, each output and counter, then the simulator's own: pose, battery, sensors), as columns."""

from __future__ import annotations

import json
from collections.abc import Iterator, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    from tablebot.loop import TickBlock
    from tablebot.machine import Machine
    from tablebot.sim.runner import SimRun


def exact(run: SimRun) -> bool:
    """Whether the run kept every robot row as it was (float64, all columns): its trace can be made again."""
    return run.hist is not None and run.hist_columns is None and run.hist.dtype == np.float64


def blocks(run: SimRun, size: int) -> Iterator[TickBlock]:
    """The run as the blocks of ticks its sinks saw (``size`` ticks each), with the simulator's trace fields:
    what a trace writer makes the same lines of as it did while the run went."""
    from tablebot.loop import TickBlock
    from tablebot.sim.simrobot import LazyColumns

    hist = run.kept_rows()
    for a in range(0, run.ticks, size):
        b = min(a + size, run.ticks)
        yield TickBlock(a, run.masks[a:b], run.pulses[a:b], run.events[a:b], run.rows[a:b], run.states[a:b],
                        run.timers[a:b], run.outputs[a:b], run.counters[a:b], LazyColumns(run.scene, hist[a:b]),
                        hist[a:b])


def _state_column(machine: Machine) -> tuple[Any, np.ndarray]:
    """The dtype of the ``state`` field and each state index's value in it: the state ids themselves, as
    numbers when every id is a number."""
    states = machine.states
    if all(isinstance(s, int) for s in states):
        return np.int64, np.array(states, dtype=np.int64)
    values = np.array([str(s) for s in states])
    return values.dtype, values


def _dtype(machine: Machine, fields: Sequence[tuple[str, Any]]) -> np.dtype:
    state_type, _ = _state_column(machine)
    names = [("tick", np.int64), ("event", np.int64), ("row", np.int32), ("state", state_type), ("timer", np.int64)]
    names += [(name, np.int64) for name in (*machine.output_names, *machine.table.robot.counter_names)]
    return np.dtype(names + list(fields))


def from_run(run: SimRun) -> np.ndarray:
    """The trace of a run that kept its robot rows exactly (:func:`exact`): the values ``trace.jsonl`` holds,
    the simulator's rounded as it writes them; ``row`` is -1 where no row fired (JSON's null)."""
    from tablebot.sim.simrobot import number_columns

    machine = run.scene.machine
    columns = number_columns(run.scene, run.kept_rows()[:-1])
    fields = [(key, np.int64 if decimals == 0 else np.float64) for key, (_, decimals) in columns.items()]
    out = np.zeros(run.ticks, dtype=_dtype(machine, fields))
    _, state_values = _state_column(machine)
    out["tick"] = np.arange(run.ticks)
    for name in ("event", "row", "timer"):
        out[name] = getattr(run, f"{name}s")
    out["state"] = state_values[run.states]
    for k, name in enumerate(machine.output_names):
        out[name] = run.outputs[:, k]
    for k, name in enumerate(machine.table.robot.counter_names):
        out[name] = run.counters[:, k]
    for key, (values, _) in columns.items():
        out[key] = values
    return out


def from_file(path: Path, machine: Machine) -> np.ndarray:
    """The trace a run wrote (``trace.jsonl``, or a cut-short run's ``trace.partial.jsonl``, whose last
    record says why it ended and is not a tick)."""
    with open(path, encoding="utf-8") as f:
        records = [json.loads(line) for line in f if line.strip()]
    ticks = [r for r in records if "tick" in r and "end" not in r]
    known = {"tick", "event", "row", "state", "timer", *machine.output_names, *machine.table.robot.counter_names}
    extra = [key for key in (ticks[0] if ticks else {}) if key not in known]
    fields = [(key, np.int64 if all(isinstance(r[key], int) for r in ticks) else np.float64) for key in extra]
    out = np.zeros(len(ticks), dtype=_dtype(machine, fields))
    for name in out.dtype.names or ():
        values = [r[name] for r in ticks]
        out[name] = [-1 if v is None else v for v in values] if name == "row" else values
    return out
