"""How fast the engine runs the BumberBot, against baselines that do the same job, in one run.

    .venv/bin/python benchmarks/engine.py [--ticks 1000000] [--repeats 5] [--transitions-ticks 100000]

All contestants run the same random input ticks (each of the five inputs reads 1 with probability
1/8, seeded) from the BumberBot's start and must end in the same state, timer and motor outputs.
They come in two kinds that are never compared with each other:

**Closed loop** (one call per tick, the next input unknown until the robot has moved: what a robot
needs). Each is called once per tick with that tick's mask:

* step          -- ``Engine.step(mask)``
* bare step     -- a dispatch dict per state keyed by the full event mask, in an object with a
                   ``step`` method holding tick, state, timer and outputs: the least a Python engine does
* linear scan   -- per tick, ``tablebot.machine.first_match`` over the current state's rows (the
                   document's rule as written; rows pre-grouped per state, which only helps it)
* transitions   -- the same machine in the ``transitions`` library: one ``tick`` trigger, a
                   transition per row in row order, guarded on the event bits (first match wins)

**Open loop** (all inputs known in advance: replaying a recording, testing). Not a robot's job:

* batch         -- ``Engine.run(masks)`` on a list of masks: many ticks per call, per-tick
                   event/row/state/timer columns (numba-compiled loop; the list-to-array copy counts)
* batch (array) -- the same, given the masks as a uint8 numpy array (no copy): the loop alone
* bare loop     -- the dispatch dicts in a plain ``for`` loop over all the masks

Times are CPU seconds of the benchmark's thread (``time.thread_time``: on a shared machine wall time
also counts the moments the process waits for a core, which lands on whichever contestant is running),
medians of the repeats; rates are ticks per second. The repeats go round-robin, and each target also
shows the range of its ratio over the rounds. The load average is printed with the figures.
``transitions`` is slow, so it runs fewer ticks (the first ``--transitions-ticks`` of the same input)
and is compared per tick.
"""

from __future__ import annotations

import argparse
import os
import random
import statistics
import sys
import time
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

import numpy as np
from transitions import Machine as TransitionsMachine

from tablebot.engine import Engine
from tablebot.formats.table_read import load_table
from tablebot.machine import Machine, compile_table, first_match

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "bumberbot" / "table.csv"
Result = tuple[Any, int, tuple[int | None, ...]]  # final state (name), timer, outputs
Inputs = Sequence[int] | np.ndarray  # a contestant's input masks: a list, or (batch (array)) a numpy array
Contestants = dict[str, tuple[Callable[..., Result], Inputs]]

#: (label, contestant, baseline, the least speed ratio contestant/baseline that meets the target);
#: closed-loop contestants against closed-loop baselines, open-loop against open-loop.
TARGETS = (
    ("step vs bare step (at least as fast)", "step", "bare step", 1.0),
    ("step vs linear scan", "step", "linear scan", 1.0),
    ("step vs transitions", "step", "transitions", 10.0),
    ("batch vs bare loop (open loop)", "batch", "bare loop", 1.0),
)
CLOSED = ("step", "bare step", "linear scan", "transitions")
OPEN = ("batch", "batch (array)", "bare loop")


def random_masks(machine: Machine, ticks: int, seed: int = 2009) -> list[int]:
    """Input masks in the machine's event layout; each input reads 1 with probability 1/8."""
    rng = random.Random(seed)
    bits = list(machine.input_bits.values())
    width = len(bits)
    masks = []
    for _ in range(ticks):
        sample = rng.getrandbits(width) & rng.getrandbits(width) & rng.getrandbits(width)
        masks.append(sum(bit for i, bit in enumerate(bits) if sample >> i & 1))
    return masks


# --- the contestants: each runs all masks from the start and returns (state, timer, outputs) ---------


def engine_batch(machine: Machine, masks: Sequence[int]) -> Result:
    engine = Engine(machine)
    engine.run(masks)
    return machine.states[engine.state], engine.timer, engine.outputs


def engine_batch_array(machine: Machine, masks: np.ndarray) -> Result:
    return engine_batch(machine, masks)  # type: ignore[arg-type]


def engine_step(machine: Machine, masks: Sequence[int]) -> Result:
    engine = Engine(machine)
    step = engine.step
    for mask in masks:
        step(mask)
    return machine.states[engine.state], engine.timer, engine.outputs


class LinearScan:
    """The document's algorithm, one call per tick: scan the state's rows in order for the first whose
    bits are present."""

    def __init__(self, machine: Machine) -> None:
        self.per_state = [[row for row in machine.rows if row.state == s] for s in range(len(machine.states))]
        self.timer_bit = machine.timer_bit
        self.state, self.timer, self.tick = machine.initial_state, machine.initial_timer, 0
        self.outputs: tuple[int | None, ...] = (0,) * len(machine.output_names)

    def step(self, mask: int) -> tuple[int | None, ...]:
        if self.tick and self.timer:
            self.timer -= 1
        self.tick += 1
        row = first_match(self.per_state[self.state], mask | self.timer_bit if self.timer == 0 else mask)
        if row is not None:
            self.outputs = tuple(o if n is None else n for o, n in zip(self.outputs, row.outputs, strict=True))
            self.state, self.timer = row.next, row.timer
        return self.outputs


def linear_scan(machine: Machine, masks: Sequence[int]) -> Result:
    scan = LinearScan(machine)
    step = scan.step
    for mask in masks:
        step(mask)
    return machine.states[scan.state], scan.timer, scan.outputs


def bare_tables(machine: Machine) -> list[dict[int, tuple[int, int, int, tuple[int | None, ...], bool]]]:
    """Per state: full event mask -> (row, next, timer, outputs, keeps), for every mask that fires a row."""
    width = len(machine.table.events)
    tables: list[dict[int, tuple[int, int, int, tuple[int | None, ...], bool]]] = []
    for state in range(len(machine.states)):
        rows = [row for row in machine.rows if row.state == state]
        tables.append(
            {
                events: (row.index, row.next, row.timer, row.outputs, row.keeps)
                for events in range(1 << width)
                if (row := first_match(rows, events)) is not None
            }
        )
    return tables


class BareStep:
    """The dispatch dicts behind a ``step`` method doing the engine's job per tick (count down, look up,
    apply; keep tick, state, timer, outputs, and the event set and fired row a trace needs), with
    nothing else: no input checks, no counters. The least a closed-loop Python engine must do."""

    def __init__(self, machine: Machine) -> None:
        self.tables, self.timer_bit = bare_tables(machine), machine.timer_bit
        self.state, self.timer, self.tick, self.event, self.row = machine.initial_state, machine.initial_timer, 0, 0, -1
        self.outputs: tuple[int | None, ...] = (0,) * len(machine.output_names)

    def step(self, mask: int) -> tuple[int | None, ...]:
        timer = self.timer
        if self.tick and timer:
            timer -= 1
        self.tick += 1
        events = mask | self.timer_bit if timer == 0 else mask
        self.event = events
        hit = self.tables[self.state].get(events)
        if hit is None:
            self.row = -1
        else:
            self.row, self.state, timer, new, keeps = hit
            self.outputs = (
                tuple(o if n is None else n for o, n in zip(self.outputs, new, strict=True)) if keeps else new
            )
        self.timer = timer
        return self.outputs


def bare_step(machine: Machine, masks: Sequence[int]) -> Result:
    bare = BareStep(machine)
    step = bare.step
    for mask in masks:
        step(mask)
    return machine.states[bare.state], bare.timer, bare.outputs


def bare_loop(machine: Machine, masks: Sequence[int]) -> Result:
    tables, t_bit = bare_tables(machine), machine.timer_bit
    state, timer, first = machine.initial_state, machine.initial_timer, True
    out: tuple[int | None, ...] = (0,) * len(machine.output_names)
    for mask in masks:
        if first:
            first = False
        elif timer:
            timer -= 1
        hit = tables[state].get(mask | t_bit if timer == 0 else mask)
        if hit is not None:
            _, state, timer, new, keeps = hit
            out = tuple(o if n is None else n for o, n in zip(out, new, strict=True)) if keeps else new
    return machine.states[state], timer, out


class Bot:
    """The model ``transitions`` drives: the timer, outputs and this tick's events live here."""

    def __init__(self, machine: Machine) -> None:
        self.timer = machine.initial_timer
        self.outputs: tuple[int | None, ...] = (0,) * len(machine.output_names)
        self.events = 0


def build_transitions(machine: Machine) -> Bot:
    """The table as a ``transitions`` machine: one ``tick(events)`` trigger, one transition per row."""
    bot = Bot(machine)
    names = [str(s) for s in machine.states]
    fsm = TransitionsMachine(
        model=bot, states=names, initial=names[machine.initial_state], auto_transitions=False, send_event=False
    )
    for row in machine.rows:  # added in row order, and transitions tries them in that order
        fsm.add_transition(
            "tick",
            names[row.state],
            names[row.next],
            conditions=[_guard(row.mask)],
            after=[_action(bot, row.timer, row.outputs)],
        )
    return bot


def _guard(mask: int) -> Callable[[int], bool]:
    return lambda events: events & mask == mask  # trigger arguments reach conditions and callbacks


def _action(bot: Bot, timer: int, outputs: tuple[int | None, ...]) -> Callable[[int], None]:
    def act(_events: int) -> None:
        bot.timer = timer
        bot.outputs = tuple(o if n is None else n for o, n in zip(bot.outputs, outputs, strict=True))

    return act


def transitions_run(machine: Machine, masks: Sequence[int]) -> Result:
    bot = build_transitions(machine)
    t_bit, first = machine.timer_bit, True
    for mask in masks:
        if first:
            first = False
        elif bot.timer:
            bot.timer -= 1
        bot.tick(mask | t_bit if bot.timer == 0 else mask)  # type: ignore[attr-defined]  # added by transitions
    state = bot.state  # type: ignore[attr-defined]
    return next(s for s in machine.states if str(s) == state), bot.timer, bot.outputs


# --- measuring ------------------------------------------------------------------------------------------


def measure(
    contestants: Contestants, machine: Machine, repeats: int
) -> tuple[dict[str, list[float]], dict[str, Result]]:
    """CPU seconds of each repeat per contestant, and each one's result.

    The repeats go round-robin (every contestant once, then again), so a machine that gets busier
    or quieter during the run slows all contestants alike instead of skewing the ratios.
    """
    times: dict[str, list[float]] = {name: [] for name in contestants}
    results: dict[str, Result] = {}
    for _ in range(repeats):
        for name, (run, ticks) in contestants.items():
            start = time.thread_time()
            results[name] = run(machine, ticks)
            times[name].append(time.thread_time() - start)
    return times, results


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--ticks", type=int, default=1_000_000)
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--transitions-ticks", type=int, default=100_000)
    args = parser.parse_args(argv)
    machine = compile_table(load_table(EXAMPLE))
    masks = random_masks(machine, args.ticks)
    few = masks[: args.transitions_ticks]
    contestants: Contestants = {
        "step": (engine_step, masks),
        "bare step": (bare_step, masks),
        "linear scan": (linear_scan, masks),
        "transitions": (transitions_run, few),
        "batch": (engine_batch, masks),
        "batch (array)": (engine_batch_array, np.array(masks, np.uint8)),
        "bare loop": (bare_loop, masks),
    }
    print(
        f"BumberBot, {args.ticks:,} random input ticks ({len(few):,} for transitions), "
        f"median of {args.repeats}, Python {sys.version.split()[0]}, load average {_load()}"
    )
    start = time.perf_counter()
    Engine(machine).run(masks[:10])
    print(
        f"  (first batch call, compiling the loop or loading it from numba's cache: "
        f"{time.perf_counter() - start:.2f} s, not counted below)"
    )
    times, results = measure(contestants, machine, args.repeats)
    seconds = {name: statistics.median(t) for name, t in times.items()}
    rates = {name: len(contestants[name][1]) / seconds[name] for name in contestants}
    for kind, names in (
        ("closed loop (a call per tick, as a robot needs)", CLOSED),
        ("open loop (all inputs known in advance)", OPEN),
    ):
        print(f" {kind}:")
        for name in names:
            rate = rates[name]
            print(f"  {name:<14} {seconds[name]:8.3f} s CPU {rate:>12,.0f} ticks/s  {1e9 / rate:8.1f} ns/tick")
    check_agreement(machine, results, few)
    ticks = {name: len(contestants[name][1]) for name in contestants}
    rounds = {name: [ticks[name] / t for t in times[name]] for name in contestants}  # rates per round
    code = report(rates, rounds)
    print(f"  (load average after: {_load()})")
    return code


def _load() -> str:
    return " ".join(f"{v:.2f}" for v in os.getloadavg())


def check_agreement(machine: Machine, results: dict[str, Result], few: Sequence[int]) -> None:
    """Every contestant ends where the engine ends (transitions on its shorter input)."""
    full = {name: r for name, r in results.items() if name != "transitions"}
    assert len(set(full.values())) == 1, f"contestants disagree: {full}"
    assert results["transitions"] == engine_step(machine, few), "transitions disagrees with the engine"


def report(rates: dict[str, float], rounds: dict[str, list[float]]) -> int:
    """The targets on the median rates; beside each, the range of the ratio round by round."""
    missed = 0
    print("targets (speed ratio of median rates, higher is faster; in brackets its range over the rounds):")
    for label, contestant, baseline, target in TARGETS:
        ratio = rates[contestant] / rates[baseline]
        each = [a / b for a, b in zip(rounds[contestant], rounds[baseline], strict=True)]
        ok = ratio >= target
        missed += not ok
        goal = f">= {target:g}x" if target >= 1 else f">= {target:.3g}x (within {1 / target:g}x)"
        print(
            f"  {label:<32} {ratio:7.2f}x ({min(each):.2f}..{max(each):.2f})   target {goal:<24} "
            f"{'ok' if ok else 'MISSED'}"
        )
    return 1 if missed else 0


if __name__ == "__main__":
    sys.exit(main())
