"""The differential harness (tablebot.testing.executors): every executor of a table -- Engine.step, Engine.run,
the simulator, the fleet, the host C engine, the AVR firmware under simavr, the TXT 4.0 program, the ROBO Pro
program -- takes the Python engine's decisions tick for tick on the same random tables, counters and pulses
included; and every transition the engine makes is a successor in the analysis model."""

from __future__ import annotations

import random
from pathlib import Path

import pytest

from tablebot.analysis.model import Model, Node
from tablebot.engine import Engine
from tablebot.formats.inputs_csv import TickInput
from tablebot.machine import Machine, compile_table
from tablebot.replay import replay
from tablebot.testing.executors import example_case
from tablebot.testing.harness import EXECUTORS, Case, Run, check, differences
from tablebot.testing.random_tables import Shape, random_inputs, random_table

STUB = Path(__file__).resolve().parents[1] / "txt4_stub"
#: The shapes of the random cases: counters tied to the motors as a TXT's encoder motors are, lamps, keep
#: cells, timers that run out, inputs the simulator senses (I3-I5 bumpers, I7-I8 lights) and some it does not.
SHAPES = [
    Shape(states=4, rows=14, inputs=7, motors=2, lamps=0, counters=2, max_timer=40, max_load=30),
    Shape(states=5, rows=16, inputs=5, motors=2, lamps=1, counters=1, max_timer=12, max_load=8),
    Shape(states=3, rows=10, inputs=6, motors=2, lamps=0, counters=2, max_timer=60, max_speed=6),
    Shape(states=6, rows=20, inputs=6, motors=2, lamps=2, counters=2, max_timer=5, max_load=4, keep_chance=0.4),
    Shape(states=4, rows=12, inputs=8, motors=2, lamps=2, counters=0, max_timer=30, max_speed=6),
]
ALL = {
    "python step",
    "engine batch",
    "simulator",
    "fleet",
    "host C",
    "AVR firmware",
    "TXT 4.0 program",
    "ROBO Pro program",
    "ROBO TX",
    "ROBO Interface",
}
#: What takes only some tables: the ROBO Pro program holds speeds 0..6 only (lamps too), the ROBO Interface counts
#: nothing, the AVR firmware has the Uno's pins.
SOME = {"ROBO Pro program", "ROBO Interface", "AVR firmware"}


def case_of(seed: int) -> Case:
    rng = random.Random(seed)
    table = random_table(rng, SHAPES[seed % len(SHAPES)])
    return Case(compile_table(table), tuple(random_inputs(rng, table, 240, density=0.2, max_pulses=3)), seed)


@pytest.mark.parametrize("seed", range(len(SHAPES)))
def test_every_executor_takes_the_engines_decisions_on_random_tables(
    tmp_path: Path, seed: int, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv("TABLEBOT_TXT4_STUB", str(STUB))
    case = case_of(seed)
    report = check(case, tmp_path)
    assert report.differ == {}
    assert set(report.agreed) >= ALL - SOME, report.skipped
    assert set(report.agreed) | set(report.skipped) == ALL == set(EXECUTORS)


@pytest.mark.parametrize("example", ["bumberbot", "bumberbot-counters", "line-follower", "obstacle-avoider"])
def test_every_executor_takes_the_engines_decisions_on_the_examples(
    tmp_path: Path, example: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The shipped robots in their own worlds: the simulated ones bump, see light, follow tape and count,
    and every other executor replays what the simulated robot read."""
    monkeypatch.setenv("TABLEBOT_TXT4_STUB", str(STUB))
    # The line follower visits all the rows it ever visits (0 1 4 5 7 13) within 10 s: a longer run only
    # repeats them, at the price of 3000 more ticks through each serial emulator.
    case = example_case(example, seconds=10.0 if example == "line-follower" else 40.0, seed=4)
    rows = {line["row"] for line in replay(case.machine, case.inputs)} - {None}
    assert len(rows) >= 6  # the run really went somewhere
    report = check(case, tmp_path)
    assert report.differ == {}
    assert ALL - SOME - {"TXT 4.0 program", "ROBO TX"} <= set(report.agreed), report.skipped


def test_the_harness_runs_every_registered_executor_somewhere(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """Over the cases above, no executor is only ever skipped (each entry of the registry is really run)."""
    monkeypatch.setenv("TABLEBOT_TXT4_STUB", str(STUB))
    fits = {
        name: [seed for seed in range(len(SHAPES)) if executor.fits(case_of(seed).machine)]
        for name, executor in EXECUTORS.items()
    }
    assert all(fits.values()), fits
    assert all(executor.missing() is None for executor in EXECUTORS.values()), {
        name: e.missing() for name, e in EXECUTORS.items()
    }


def test_a_wrong_decision_is_found_at_its_tick() -> None:
    """The comparison can fail: one row changed in one tick's line is named with its tick and field."""
    case = case_of(1)
    run = EXECUTORS["python step"].run(case, Path("."))
    assert differences(case.machine, run) is None
    bad = [dict(line) for line in run.lines]
    bad[57]["state"] = "nowhere"
    found = differences(case.machine, Run(run.inputs, bad))
    assert found is not None and found.startswith("tick 57: state is 'nowhere'")


# --- the analysis model -------------------------------------------------------------------------------


def node_of(model: Model, engine: Engine) -> Node:
    """The model's node for the engine's situation: state, timer class, which tracked counters are at 0,
    outputs, whether no tick has been made yet."""
    zero = sum(1 << i for i, value in enumerate(engine.counters) if model.tracked >> i & 1 and value == 0)
    return engine.state, model.timer_class(engine.timer), zero, tuple(engine.outputs), engine.tick == 0


def walk(machine: Machine, model: Model, inputs: list[TickInput]) -> int:
    """Step the engine; at every tick demand a successor of the node before with the engine's event mask, the
    counters its pulses brought to 0, its fired row and the node after. Returns the ticks checked."""
    engine = Engine(machine)
    for tick in inputs:
        before = node_of(model, engine)
        counting = [max(0, c - p) if engine.tick else c for c, p in zip(engine.counters, tick.pulses, strict=True)]
        zeroed = sum(
            1 << i
            for i, (old, new) in enumerate(zip(engine.counters, counting, strict=True))
            if model.tracked >> i & 1 and old != 0 and new == 0
        )
        engine.step(tick.mask, tick.pulses)
        made = (engine.event, zeroed, engine.row, node_of(model, engine))
        assert made in model.successors(before), (engine.tick - 1, before, made)
    return len(inputs)


@pytest.mark.parametrize("seed", range(8))
def test_every_engine_transition_is_a_successor_in_the_analysis_model(seed: int) -> None:
    """In the exact model (no timer value abstracted, every input watched so each event mask is its own
    class) each tick is a successor exactly as the engine made it: event mask, counters driven to 0 by
    pulses, fired row, and the next node (state, timer, counters at 0, outputs). In the abstract model
    (horizon 1, what ``check`` explores first) the same ticks are successors of the abstracted nodes:
    the abstraction is sound on real runs, counters included."""
    rng = random.Random(seed)
    shape = Shape(
        states=rng.randint(2, 6),
        rows=rng.randint(6, 18),
        inputs=rng.randint(1, 4),
        counters=rng.randint(0, 2),
        lamps=rng.randint(0, 1),
        max_timer=8,
        max_load=5,
    )
    machine = compile_table(random_table(rng, shape))
    inputs = random_inputs(rng, machine.table, 300, density=0.3, max_pulses=2)
    exact = Model.exact(machine, watch=machine.input_mask)
    assert exact.is_exact and walk(machine, exact, inputs) == 300
    assert walk(machine, Model(machine, horizon=1, watch=machine.input_mask), inputs) == 300
