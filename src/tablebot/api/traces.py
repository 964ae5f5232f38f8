"""A simulated run's trace as one numpy record per tick: the fields of ``trace.jsonl`` (tick, event, row,
state, timer, each output and counter, then the simulator's own: pose, battery, sensors, then for a robot of
several tables each other table's ``NAME.event``, ``NAME.row``, ``NAME.state``, ``NAME.timer``), as columns."""

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
        yield TickBlock(
            a,
            run.masks[a:b],
            run.pulses[a:b],
            run.events[a:b],
            run.rows[a:b],
            run.states[a:b],
            run.timers[a:b],
            run.outputs[a:b],
            run.counters[a:b],
            LazyColumns(run.scene, hist[a:b]),
            hist[a:b],
        )


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
    for name in ("event", "timer"):
        out[name] = getattr(run, f"{name}s")
    out["row"] = _as_written(machine)[run.rows]  # a group's row as the file writes it, as trace.jsonl names it
    out["state"] = state_values[run.states]
    for k, name in enumerate(machine.output_names):
        out[name] = run.outputs[:, k]
    for k, name in enumerate(machine.table.robot.counter_names):
        out[name] = run.counters[:, k]
    for key, (values, _) in columns.items():
        out[key] = values
    return _with_others(out, run)


def _as_written(machine: Machine) -> np.ndarray:
    """Per row index (and -1: none fired, the last place), the row as its file writes it."""
    return np.array([row.as_written for row in machine.table.rows] + [-1], dtype=np.int32)


def _with_others(trace: np.ndarray, run: SimRun) -> np.ndarray:
    """The trace with the other tables' columns of a robot of several tables after its own (as ``trace.jsonl``
    has them): ``NAME.row`` -1 where the table fired no row, ``NAME.state`` typed as its table's states are."""
    tables = run.scene.tables
    if tables is None or not run.others:
        return trace
    fields: list[tuple[str, Any]] = []
    for name, machine in zip(tables.names[1:], tables.machines[1:], strict=True):
        fields += [
            (f"{name}.event", np.int64),
            (f"{name}.row", np.int32),
            (f"{name}.state", _state_column(machine)[0]),
            (f"{name}.timer", np.int64),
        ]
    out = np.zeros(len(trace), dtype=np.dtype([*_fields(trace.dtype), *fields]))
    for name in trace.dtype.names or ():
        out[name] = trace[name]
    for key, _ in fields:
        values = run.others[key][: len(trace)]
        out[key] = [-1 if v is None else v for v in values] if key.endswith(".row") else values
    return out


def _fields(dtype: np.dtype) -> list[tuple[str, Any]]:
    return [(name, dtype.fields[name][0]) for name in dtype.names or ()]  # type: ignore[index]


def from_file(path: Path, machine: Machine) -> np.ndarray:
    """The trace a run wrote (``trace.jsonl``, or a cut-short run's ``trace.partial.jsonl``, whose last
    record says why it ended and is not a tick)."""
    with open(path, encoding="utf-8") as f:
        records = [json.loads(line) for line in f if line.strip()]
    ticks = [r for r in records if "tick" in r and "end" not in r]
    known = {"tick", "event", "row", "state", "timer", *machine.output_names, *machine.table.robot.counter_names}
    extra = [key for key in (ticks[0] if ticks else {}) if key not in known]
    fields = [(key, np.int32 if key.endswith(".row") else _kind([r[key] for r in ticks])) for key in extra]
    out = np.zeros(len(ticks), dtype=_dtype(machine, fields))
    for name in out.dtype.names or ():
        values = [r[name] for r in ticks]
        out[name] = [-1 if v is None else v for v in values] if name == "row" or name.endswith(".row") else values
    return out


def _kind(values: list[Any]) -> Any:
    """The dtype of an extra key's column: whole numbers (an other table's row, None where it fired none, is
    -1), else text where any value is text (an other table's state names), else floats."""
    if any(isinstance(v, str) for v in values):
        return np.array([str(v) for v in values]).dtype
    return np.int64 if all(v is None or isinstance(v, int) for v in values) else np.float64
