"""The line follower and the obstacle avoider do their jobs on the default run and keep their properties."""

from __future__ import annotations

import json
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
import pytest
from typer.testing import CliRunner

from tablebot.cli import app
from tablebot.sim import columns as L
from tablebot.sim.runner import simulate
from tablebot.sim.summary import summarise
from test_sim_helpers import ROOT, scene_of

if TYPE_CHECKING:
    from tablebot.sim.runner import SimRun

EXAMPLES = ROOT / "examples"
DEFAULT_SECONDS = 120.0  # tablebot sim's default run


@pytest.fixture(scope="module")
def follower() -> SimRun:
    return simulate(scene_of(EXAMPLES / "line-follower" / "table.csv"), DEFAULT_SECONDS, seed=1)


def test_the_line_follower_drives_two_laps_without_touching_anything(follower: SimRun) -> None:
    summary = summarise(follower)
    assert summary.laps is not None and summary.laps >= 2.0
    assert summary.collisions == 0


def test_the_hairpin_needs_the_recovery_rows(follower: SimRun) -> None:
    states = follower.scene.machine.states
    spun = {states[s] for s in follower.states.tolist()} & {4, 5}  # lost left / lost right
    assert spun, "the tight curve was followed by steering alone: it is not tight enough"


def test_the_floor_sensors_read_the_tape_under_them(follower: SimRun) -> None:
    """Every tick, each sensor's reading is 1 exactly when its spot lies within the tape's half width."""
    from tablebot.sim.physics.geometry import point_segment_distance

    h, scene = follower.kept_rows(), follower.scene
    lines = scene.geometry.lines
    for k, sensor in enumerate(scene.table.robot.sensors):
        fx, fy = sensor.at
        for row in h[::97]:  # a sample of the run: thousands of checks, on and off the tape
            c, s = float(np.cos(row[L.TH])), float(np.sin(row[L.TH]))
            x, y = float(row[L.X]) + c * fx - s * fy, float(row[L.Y]) + s * fx + c * fy
            gap = min(point_segment_distance(x, y, *seg[:4]) - seg[4] for seg in lines)
            if abs(gap) > 1e-5:  # the history may be float32: leave out spots on the very edge
                assert row[L.READING + k] == (1.0 if gap < 0 else 0.0)


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_the_obstacle_avoider_drives_a_minute_without_touching_anything(seed: int) -> None:
    result = simulate(scene_of(EXAMPLES / "obstacle-avoider" / "table.csv"), 60.0, seed=seed)
    summary = summarise(result)
    assert summary.collisions == 0
    assert summary.distance_m > 4.0  # it drove about, not just turned on the spot
    states = set(result.scene.machine.states[s] for s in result.states.tolist())
    assert {1, 2, 3} <= states  # it met obstacles on both sides and turned away


@pytest.mark.parametrize("example", ["line-follower", "obstacle-avoider"])
def test_the_examples_keep_their_properties(example: str, tmp_path: Path) -> None:
    result = CliRunner().invoke(app, ["check", str(EXAMPLES / example), "--strict", "--counterexamples", str(tmp_path)])
    assert result.exit_code == 0, result.output
    assert result.output.count("holds") == 5 and "VIOLATED" not in result.output


@pytest.mark.parametrize("example", ["line-follower", "obstacle-avoider"])
def test_declared_sensors_are_traced_alike_tick_by_tick_and_compiled(example: str) -> None:
    """Their readings join the trace (I1_line 0/1, I1_cm whole centimetres), and the real-time path and the
    compiled block path give the same bytes."""
    from tablebot.engine import Engine
    from tablebot.loop import SimulatedClock
    from tablebot.loop import run as run_loop
    from tablebot.sim.simrobot import SimRobot
    from test_sim_live import Lines, TickByTick

    scene = scene_of(EXAMPLES / example / "table.csv")
    traces = []
    for clock in (TickByTick(), SimulatedClock()):
        keep, robot = Lines(), SimRobot(scene, 2)
        run_loop(Engine(scene.machine), robot, clock=clock, sinks=[keep], ticks=1500)
        traces.append(keep.lines)
    assert traces[0] == traces[1]
    first = json.loads(traces[0][0])
    suffix = "line" if example == "line-follower" else "cm"
    assert [k for k in first if k.startswith("I")] == [f"I1_{suffix}", f"I2_{suffix}"]
    assert "_light" not in first  # no phototransistors, no light fields
