"""A fleet of robots of several tables (issue 36 §2): robot k runs every table as ``tablebot sim`` runs it, the
same trace bytes (the lights table's keys too) and the same summary; untraced robots tally as traced ones."""

from __future__ import annotations

import io
import json
import subprocess
import sys
import warnings
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

import tablebot
from tablebot.fleet.plan import make_plan
from tablebot.fleet.run import Fleet, RobotSpec
from tablebot.fleet.spec import digest
from tablebot.sim.model.scene import robot_layer
from tablebot.sim.runner import simulate
from tablebot.sim.summary import summarise

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "bumberbot-lights"


def test_robot_k_of_a_fleet_of_several_tables_runs_as_sim() -> None:
    project = tablebot.open(EXAMPLE)
    assert project.tables is not None
    scene = project.scene(every_table=True)
    specs = [RobotSpec(seed=s, params=(("battery", "charge", c),)) for s, c in ((4, 1.0), (5, 0.6), (4, 1.0))]
    fleet = Fleet(
        project.table,
        project.machine,
        scene.world,
        specs,
        robot_layer(project.robot)[0],
        traced=[0, 1],
        tables=project.tables,
    )
    fleet.run(700, block_ticks=256)
    for k, spec in enumerate(specs[:2]):
        alone = simulate(project.scene(every_table=True, overrides=spec.overrides()), 7.0, spec.seed)
        text = io.StringIO()
        alone.write_trace(text)
        assert "".join(fleet.trace_lines(k)) == text.getvalue()
        assert "lights.state" in fleet.trace_lines(k)[-1]
        assert fleet.summary().summary(k) == replace(summarise(alone), laps=None)
    summary = fleet.summary()  # robot 2 is robot 0 untraced: the same tally
    assert np.array_equal(summary.counts[2], summary.counts[0]) and summary.final_state[2] == summary.final_state[0]


def test_a_sweep_of_several_tables_is_n_sims(tmp_path: Path) -> None:
    """tablebot sweep of the BumberBot with its lights: each run's trace is what tablebot sim writes for its seed
    (every table, the lights table's keys too); the spec's table digest covers the lights table."""
    sweep = tmp_path / "sweep"
    done = subprocess.run(
        [
            sys.executable,
            "-m",
            "tablebot",
            "sweep",
            str(EXAMPLE),
            "--seeds",
            "2,3",
            "--seconds",
            "3",
            "--trace",
            "0,1",
            "--no-plots",
            "--out",
            str(sweep),
        ],
        capture_output=True,
        text=True,
        check=False,
    )
    assert done.returncode == 0, done.stderr
    assert "main table" not in done.stderr
    for run, seed in ((0, 2), (1, 3)):
        alone = simulate(tablebot.open(EXAMPLE).scene(every_table=True), 3.0, seed)
        text = io.StringIO()
        alone.write_trace(text)
        assert (sweep / f"trace-{run}.jsonl").read_text() == text.getvalue()
    spec = json.loads((sweep / "spec.json").read_text())
    assert spec["table_digest"] != digest(EXAMPLE / "table.csv")


def test_a_plan_of_the_main_table_alone_says_so() -> None:
    """tune, evolve and grade plan a robot of several tables' main table alone: a note at its [tables] says so;
    sweep's plan runs them all and says nothing."""
    with pytest.warns(UserWarning, match=r"robot.toml:31:1: note: this runs the main table \(drive\) only"):
        alone = make_plan(EXAMPLE, None, [], [], "1", None, 1.0)
    assert alone.tables is None
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        whole = make_plan(EXAMPLE, None, [], [], "1", None, 1.0, every_table=True)
    assert whole.tables is not None and whole.spec.table_digest != alone.spec.table_digest
