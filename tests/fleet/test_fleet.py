"""The fleet kernel: robot k of a fleet runs exactly as ``tablebot sim`` runs the same robot alone.

Same trace bytes, same summary, for the shipped BumberBot (through the real command) and for random
tables in random worlds with random seeds, starts, batteries and parameters.
"""

from __future__ import annotations

import random
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from tablebot.cli import app
from tablebot.cli.common import load
from tablebot.fleet.run import Fleet, RobotSpec, Variants
from tablebot.machine import compile_table
from tablebot.replay import replay
from tablebot.robot import MATCHES, Match
from tablebot.sim.model.scene import prepare, robot_layer, scene_for
from tablebot.sim.model.world import parse_world
from tablebot.sim.runner import simulate
from tablebot.sim.summary import summarise
from tablebot.testing.harness import random_world
from tablebot.testing.random_tables import Shape, random_table, with_match
from tablebot.tomlfile import Source
from test_sim_helpers import BUMBERBOT, trace_text


def test_robot_k_of_a_fleet_writes_the_trace_tablebot_sim_writes(tmp_path: Path) -> None:
    """Through the real command: ``tablebot sim --battery 0.6 --seed 7`` against robot 2 of a fleet."""
    out = tmp_path / "sim"
    result = CliRunner().invoke(
        app,
        [
            "sim",
            str(BUMBERBOT),
            "--seconds",
            "20",
            "--seed",
            "7",
            "--battery",
            "0.6",
            "--no-plots",
            "--quiet",
            "--out",
            str(out),
        ],
    )
    assert result.exit_code == 0, result.output
    table, machine = load(BUMBERBOT)
    scene = scene_for(table, machine)
    specs = [RobotSpec(seed=s, params=(("battery", "charge", c),)) for s, c in ((1, 1.0), (7, 1.0), (7, 0.6), (8, 0.6))]
    fleet = Fleet(table, machine, scene.world, specs, robot_layer(table.robot)[0], traced=[2])
    fleet.run(2000)
    assert "".join(fleet.trace_lines(2)) == (out / "trace.jsonl").read_text(encoding="utf-8")


@pytest.mark.parametrize("example", ["bumberbot", "bumberbot-counters", "line-follower", "obstacle-avoider"])
def test_every_shipped_robot_runs_alike_alone_and_in_a_fleet(example: str) -> None:
    """Counters, tape on the floor and declared sensors (line, distance) come along: one shared loop."""
    table, machine = load(BUMBERBOT.parent / example)
    scene = scene_for(table, machine)
    specs = [RobotSpec(seed=s) for s in (4, 5)]
    fleet = Fleet(table, machine, scene.world, specs, robot_layer(table.robot)[0], traced=[0, 1])
    fleet.run(1500)
    for k, spec in enumerate(specs):
        alone = simulate(scene, 15.0, spec.seed)
        assert "".join(fleet.trace_lines(k)) == trace_text(alone)
        assert fleet.summary().summary(k) == replace(summarise(alone), laps=None)


@pytest.mark.parametrize("case", range(4))
def test_random_tables_worlds_and_seeds_run_alike_alone_and_in_a_fleet(case: int) -> None:
    rng = random.Random(1000 + case)
    table = random_table(
        rng, Shape(states=4, rows=14, inputs=8, counters=case % 2, max_timer=300, max_load=40, event_density=0.25)
    )
    machine = compile_table(table)
    world = parse_world(Source.parse("<random>", random_world(rng)))
    specs = [
        RobotSpec(
            seed=rng.randrange(10**6),
            start=None if k == 0 else (rng.uniform(0.4, 0.7), rng.uniform(0.4, 0.7), rng.uniform(-180, 180)),
            params=(
                ("battery", "charge", rng.choice([1.0, 0.7, 0.3])),
                ("motor", "friction_volts", rng.choice([0.3, 0.5])),
            ),
        )
        for k in range(5)
    ]
    fleet = Fleet(table, machine, world, specs, traced=range(len(specs)))
    fleet.run(900, block_ticks=300)
    summary = fleet.summary()
    for k, spec in enumerate(specs):
        scene = prepare(table, machine, world, None, spec.overrides())
        if spec.start is not None:
            scene = replace(scene, world=replace(world, start=spec.start))
        alone = simulate(scene, 9.0, spec.seed)
        assert "".join(fleet.trace_lines(k)) == trace_text(alone)
        assert summary.summary(k) == summarise(alone)


def test_untraced_robots_get_the_same_summary_as_traced_ones() -> None:
    """Tracing a robot changes nothing in its run; blocks of any length give one run."""
    table, machine = load(BUMBERBOT)
    world = scene_for(table, machine).world
    specs = [RobotSpec(seed=s) for s in range(6)]
    traced = Fleet(table, machine, world, specs, traced=range(6))
    traced.run(1500)
    plain = Fleet(table, machine, world, specs)
    plain.run(1500, block_ticks=97)
    a, b = traced.summary(), plain.summary()
    for name in ("first_light", "reached", "collisions", "distance_m", "battery_end_v", "final_state", "counts"):
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name))


def test_program_variants_run_each_robot_with_its_own_timers() -> None:
    """A variant's timers are those of a table written with them: the fleet equals that table alone."""
    table, machine = load(BUMBERBOT)
    world = scene_for(table, machine).world
    variants = Variants.of(machine)
    changed = variants.timers[0].copy()
    changed[3] = 300  # Seek - Straight: 895 -> 300
    variants = Variants(np.stack([variants.timers[0], changed]), np.repeat(variants.loads, 2, axis=0))
    fleet = Fleet(
        table, machine, world, [RobotSpec(seed=3, variant=1), RobotSpec(seed=3)], traced=[0, 1], variants=variants
    )
    fleet.run(1200)
    rows = tuple(replace(row, timer=300) if row.index == 3 else row for row in table.rows)
    edited = replace(table, rows=rows)
    alone = simulate(scene_for(edited, compile_table(edited)), 12.0, 3)
    assert "".join(fleet.trace_lines(0)) == trace_text(alone)
    assert "".join(fleet.trace_lines(1)) != trace_text(alone)


@pytest.mark.parametrize("match", MATCHES)
def test_the_compiled_simulator_and_the_fleet_follow_the_tables_matching_rule(match: Match) -> None:
    """A random table in a random world on which the two rules drive different runs: the compiled loop,
    alone and as robot 0 of a fleet, takes ``Engine.step``'s decisions over the inputs it sensed."""
    rng = random.Random(5)  # a table and world where the two rules part on 268 of 400 ticks
    table = random_table(
        rng, Shape(states=4, rows=14, inputs=8, max_timer=300, event_density=0.25, no_event_chance=0.3)
    )
    world = parse_world(Source.parse("<random>", random_world(rng)))
    runs = {
        rule: simulate(prepare(t, compile_table(t), world), 4.0, 3)
        for rule in MATCHES
        for t in [with_match(table, rule)]
    }
    assert runs["document"].rows.tolist() != runs["always"].rows.tolist()  # the rules part here
    alone = runs[match]
    machine = alone.scene.machine
    replayed = list(replay(machine, alone.inputs()))
    assert [-1 if line["row"] is None else line["row"] for line in replayed] == alone.rows.tolist()
    assert [machine.state_index(line["state"]) for line in replayed] == alone.states.tolist()
    fleet = Fleet(alone.scene.table, machine, world, [RobotSpec(seed=3)], traced=[0])
    fleet.run(400)
    assert "".join(fleet.trace_lines(0)) == trace_text(alone)
