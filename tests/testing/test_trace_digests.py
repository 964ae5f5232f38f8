"""Golden digests: the simulator's and the fleet's output bytes, recorded, so that a change to the compiled
kernels (how they are called, how they are laid out) that changes any number they make is caught.

Each case below runs a path of the compiled code -- one robot's loop (``tablebot sim``), a fleet on one
thread and on numba's pool, tuned program variants, the tick-by-tick fleet with and without motor commands,
the engine's batch loop -- and digests everything it made: trace lines, every robot row (float64 bytes), the
fleet's summary arrays. The digests in ``fixtures/trace_digests.json`` were recorded by this file's
``--record`` from the code before the kernels took named structures; they hold for the platform they were
recorded on (floating point through the C library's sin/cos may round otherwise elsewhere), and the test
says so and skips on another. Record again only for a change that is meant to change the numbers:
``.venv/bin/python tests/testing/test_trace_digests.py --record``.
"""

from __future__ import annotations

import hashlib
import json
import platform
import sys
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[2]
EXAMPLES = ROOT / "examples"
GOLDEN = Path(__file__).resolve().parents[1] / "fixtures" / "trace_digests.json"
PLATFORM = f"{sys.platform}-{platform.machine()}"


class Digest:
    """sha256 over labelled pieces: text lines, and arrays by dtype, shape and bytes."""

    def __init__(self) -> None:
        self.h = hashlib.sha256()

    def text(self, label: str, lines: list[str]) -> None:
        self.h.update(f"{label}\n".encode())
        self.h.update("\n".join(lines).encode())

    def array(self, label: str, value: object) -> None:
        a = np.ascontiguousarray(np.asarray(value))
        self.h.update(f"{label} {a.dtype.str} {a.shape}\n".encode())
        self.h.update(a.tobytes())

    def hex(self) -> str:
        return self.h.hexdigest()


def _load(example: str) -> tuple:
    from tablebot.cli.common import load

    return load(EXAMPLES / example)


def sim_case(example: str, seconds: float, seed: int, busy: int | None = None) -> str:
    """``tablebot sim``'s loop: the trace lines and every robot row of one run."""
    from tablebot.loop import RunEnd, RunInfo, TickBlock
    from tablebot.sim.model.scene import prepare, scene_for
    from tablebot.sim.runner import simulate
    from tablebot.sinks.trace_file import block_lines

    table, machine = _load(example)
    if busy is None:
        scene = scene_for(table, machine)
    else:
        from tablebot.testing.executors import _busy_world

        scene = prepare(table, machine, _busy_world(busy), None)
    lines: list[str] = []

    class Lines:  # a sink that keeps the trace lines as tablebot sim writes them
        def start(self, info: RunInfo) -> None: ...
        def block(self, block: TickBlock) -> None:
            lines.extend(block_lines(block, machine))

        def end(self, end: RunEnd) -> None: ...

    run = simulate(scene, seconds, seed, sinks=[Lines()])
    d = Digest()
    d.text("trace", lines)
    d.array("hist", run.kept_rows())
    d.array("collisions", run.collision_rows)
    d.text("ends", [repr(run.collision_count), repr(run.reached_row)])
    return d.hex()


def _summary(d: Digest, fleet: object) -> None:
    summary = fleet.summary()  # type: ignore[attr-defined]
    for name in (
        "first_light",
        "reached",
        "collisions",
        "distance_m",
        "battery_start_v",
        "battery_end_v",
        "final_state",
        "counts",
        "first_visit",
        "collision_rows",
        "final_pose",
    ):
        d.array(name, getattr(summary, name))
    d.array("S", fleet.S)  # type: ignore[attr-defined]
    d.array("acc", fleet.acc)  # type: ignore[attr-defined]


def fleet_case(threads: bool, variants: bool = False) -> str:
    """A fleet of 6 BumberBots (batteries, starts, seeds, program variants) in blocks of 97 ticks, robot 2
    traced: its trace lines and rows, and every robot's summary."""
    from tablebot.fleet.robots import RobotSpec, Variants
    from tablebot.fleet.run import Fleet
    from tablebot.sim.model.scene import robot_layer, scene_for

    table, machine = _load("bumberbot")
    world = scene_for(table, machine).world
    chosen = Variants.of(machine)
    if variants:  # a second variant: every timer a tick longer (as tune makes them)
        chosen = Variants(np.concatenate([chosen.timers, chosen.timers + 1]), np.concatenate([chosen.loads] * 2))
    specs = [
        RobotSpec(
            seed=10 + k,
            start=None if k % 2 else (0.3 + 0.1 * k, 0.4, 30.0 * k),
            params=(("battery", "charge", 1.0 - 0.1 * k),) if k % 3 == 0 else (),
            variant=k % 2 if variants else 0,
        )
        for k in range(6)
    ]
    fleet = Fleet(table, machine, world, specs, robot_layer(table.robot)[0], traced=[2], variants=chosen)
    fleet.run(1500, block_ticks=97, threads=threads)
    d = Digest()
    d.text("trace", fleet.trace_lines(2))
    d.array("rows", fleet.result(2).kept_rows())
    _summary(d, fleet)
    return d.hex()


def sweep_case() -> str:
    """A sweep's chunk as a worker runs it (fleet.work.run_job): a grid over batteries and starts."""
    from tablebot.fleet.plan import make_plan
    from tablebot.fleet.work import run_job

    plan = make_plan(
        EXAMPLES / "bumberbot" / "table.csv", None, [], ["battery=1.0,0.5", "start=random"], "0..5", None, 8.0
    )
    d = Digest()
    for job in plan.jobs():
        done, summary = run_job(job)
        # the world column names the world file by its path: the checkout's place is no part of the bytes made
        d.text("part", [plan.part_text(done, summary).replace(str(EXAMPLES), "EXAMPLES")])
    return d.hex()


def tick_case(commands: bool) -> str:
    """The fleet a tick at a time (the Gymnasium env's path): the table drives it, or motor commands do."""
    from tablebot.fleet.robots import RobotSpec
    from tablebot.fleet.run import Fleet
    from tablebot.sim.model.scene import robot_layer, scene_for

    table, machine = _load("bumberbot")
    fleet = Fleet(
        table,
        machine,
        scene_for(table, machine).world,
        [RobotSpec(seed=s) for s in range(3)],
        robot_layer(table.robot)[0],
    )
    rng = np.random.default_rng(5)
    for _ in range(300):
        fleet.tick(rng.integers(-8, 9, size=(3, 2)) if commands else None)
    d = Digest()
    _summary(d, fleet)
    d.array("observations", fleet.observations())
    return d.hex()


def engine_case() -> str:
    """The engine's compiled batch loop over random masks and counter pulses."""
    from tablebot.engine import Engine

    _, machine = _load("bumberbot-counters")
    rng = np.random.default_rng(9)
    n = len(machine.counter_bits)
    masks = rng.integers(0, 1 << len(machine.table.events), size=3000)
    engine = Engine(machine)
    batch = engine.run(masks, rng.integers(0, 3, size=(3000, n)).tolist(), jit=True)
    d = Digest()
    for name in ("events", "rows", "states", "timers"):
        d.array(name, getattr(batch, name))
    d.array("outputs", engine.outputs)
    d.array("counters", engine.counters)
    return d.hex()


def _example(name: str) -> Callable[[], str]:
    return lambda: sim_case(name, 30.0, 4)


CASES: dict[str, Callable[[], str]] = {
    **{
        f"sim {name}": _example(name)
        for name in (
            "bumberbot",
            "bumberbot-counters",
            "document/bumberbot-table.tsv",
            "line-follower",
            "obstacle-avoider",
        )
    },
    "sim bumberbot in a busy room": lambda: sim_case("bumberbot", 30.0, 2, busy=7),
    "sim obstacle-avoider in a busy room": lambda: sim_case("obstacle-avoider", 30.0, 3, busy=11),
    "fleet on one thread": lambda: fleet_case(False),
    "fleet on numba's threads": lambda: fleet_case(True),
    "fleet with program variants": lambda: fleet_case(False, variants=True),
    "sweep chunks": sweep_case,
    "fleet tick by tick": lambda: tick_case(False),
    "fleet driven by motor commands": lambda: tick_case(True),
    "engine batch": engine_case,
}


def _golden() -> dict[str, str]:
    recorded = json.loads(GOLDEN.read_text(encoding="utf-8"))
    if PLATFORM not in recorded:
        pytest.skip(
            f"golden digests are recorded for {', '.join(recorded)}, not {PLATFORM}: "
            "run tests/testing/test_trace_digests.py --record there to make them"
        )
    return dict(recorded[PLATFORM])


@pytest.mark.parametrize("case", list(CASES))
def test_the_compiled_code_makes_the_recorded_bytes(case: str) -> None:
    assert CASES[case]() == _golden()[case], f"{case}: the output's bytes changed"


def test_every_case_has_a_recorded_digest() -> None:
    assert set(_golden()) == set(CASES)


if __name__ == "__main__":
    if sys.argv[1:] != ["--record"]:
        raise SystemExit(f"usage: {sys.argv[0]} --record   (overwrites {GOLDEN.name} for {PLATFORM})")
    recorded = json.loads(GOLDEN.read_text(encoding="utf-8")) if GOLDEN.exists() else {}
    recorded[PLATFORM] = {name: case() for name, case in CASES.items()}
    GOLDEN.write_text(json.dumps(recorded, indent=1, sort_keys=True) + "\n", encoding="utf-8")
    print(f"recorded {len(CASES)} digests for {PLATFORM} in {GOLDEN}")
