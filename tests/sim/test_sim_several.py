"""sim of a robot of several tables (issue 36 §2) runs every table: the simulated robot's trace holds the other
tables' NAME.event/row/state/timer keys, its decisions are tablebot.engine.several's on the inputs the robot read
(as the differential harness holds every executor), and the lamps only the lights table writes are lit."""

from __future__ import annotations

import io
import json
import random
import subprocess
import sys
from collections.abc import Sized
from pathlib import Path

import pytest

import tablebot
from tablebot.testing.harness import Run
from tablebot.testing.several_cases import several_differences

ROOT = Path(__file__).resolve().parents[2]
EXAMPLE = ROOT / "examples" / "bumberbot-lights"
OTHERS = ("lights.event", "lights.row", "lights.state", "lights.timer")


def test_sim_runs_every_table_as_several_does() -> None:
    project = tablebot.open(EXAMPLE)
    assert project.tables is not None
    sim = project.simulate(seconds=6, seed=3)
    text = io.StringIO()
    sim.run.write_trace(text)
    lines = [json.loads(line) for line in text.getvalue().splitlines()]
    assert all(key in lines[0] for key in OTHERS)
    assert several_differences(project.tables, Run(sim.run.inputs(), lines)) is None
    states = {line["lights.state"] for line in lines}
    assert len(states) > 1, states  # the lights table moved on, and with it the lamps
    assert {line["L1"] for line in lines} != {0} and {line["L2"] for line in lines} != {0}


def test_sim_command_writes_the_other_tables_keys(tmp_path: Path) -> None:
    """The trace `tablebot sim --out` writes while the robot runs is the one the run makes again afterwards."""
    done = subprocess.run(
        [
            sys.executable,
            "-m",
            "tablebot",
            "sim",
            str(EXAMPLE),
            "--seconds",
            "3",
            "--seed",
            "3",
            "--out",
            str(tmp_path),
        ],
        capture_output=True,
        text=True,
        check=False,
    )
    assert done.returncode == 0, done.stderr
    assert "main table" not in done.stderr  # no note that the lights table is left out
    written = (tmp_path / "trace.jsonl").read_text()
    again = io.StringIO()
    tablebot.open(EXAMPLE).simulate(seconds=3, seed=3).run.write_trace(again)
    assert written == again.getvalue()
    first = json.loads(written.splitlines()[0])
    assert list(first)[-4:] == list(OTHERS)


def test_a_saved_run_writes_the_other_tables_keys(tmp_path: Path) -> None:
    """Simulation.save writes the trace `sim --out` writes (the lights table's keys too)."""
    sim = tablebot.open(EXAMPLE).simulate(seconds=2, seed=5)
    sim.save(tmp_path, plots=False)
    again = io.StringIO()
    sim.run.write_trace(again)
    assert (tmp_path / "trace.jsonl").read_text() == again.getvalue()
    assert all(key in json.loads(again.getvalue().splitlines()[-1]) for key in OTHERS)


def test_the_compiled_loop_is_the_tick_by_tick_run(tmp_path: Path) -> None:
    """sim runs the tables in compiled blocks (tablebot.sim.physics.several); the same robot stepped one tick at a time
    through the run loop's exchange (RobotEngine, as a live controller runs) writes the same trace bytes."""
    from tablebot.engine.as_one import RobotEngine
    from tablebot.loop import TickBlock, exchange
    from tablebot.sim.runner import simulate
    from tablebot.sim.simrobot import SimRobot
    from tablebot.sinks.trace_file import block_lines

    scene = tablebot.open(EXAMPLE).scene(every_table=True)
    assert scene.tables is not None
    compiled, sizes = io.StringIO(), Sizes()
    run = simulate(scene, 4.0, seed=7, sinks=[sizes])
    assert max(sizes.seen) > 1  # whole blocks of ticks: the compiled loop ran them
    run.write_trace(compiled)
    robot, engine = SimRobot(scene, 7), RobotEngine(scene.tables)
    lines: list[str] = []
    for _ in range(run.ticks):
        reading = exchange(engine, robot)
        lines += block_lines(TickBlock.of_tick(engine, reading), scene.machine)
    assert "".join(lines) == compiled.getvalue()


class Sizes:
    """A sink that notes how many ticks each block it is given holds."""

    def __init__(self) -> None:
        self.seen: list[int] = []

    def start(self, info: object) -> None:
        pass

    def block(self, block: Sized) -> None:
        self.seen.append(len(block))

    def end(self, end: object) -> None:
        pass


@pytest.mark.parametrize("seed", [1, 2, 3, 6])
def test_random_robots_simulate_as_several_steps_them(seed: int, tmp_path: Path) -> None:
    """Random robots of 2-3 tables (cross-table columns, a state group, a counter on the right motor loaded by one
    table and read by others, either matching rule): the simulated decisions are Several's on the inputs and
    pulses the simulated robot read."""
    from tablebot.sim.runner import simulate
    from tablebot.testing.random_robots import RobotShape, random_robot

    folder = random_robot(random.Random(seed), tmp_path, RobotShape(tables=2 + seed % 2))
    project = tablebot.open(folder / "t0.csv", robot=folder / "robot.toml")
    assert project.tables is not None
    run = simulate(project.scene(every_table=True), 3.0, seed=seed)
    text = io.StringIO()
    run.write_trace(text)
    lines = [json.loads(line) for line in text.getvalue().splitlines()]
    assert several_differences(project.tables, Run(run.inputs(), lines)) is None
    if seed == 1:  # its right motor runs: the counter counts its pulses (seed 6's is loaded, seed 3's held at 5)
        assert run.pulses.any()


def test_robots_of_any_number_of_tables_share_one_compiled_loop(tmp_path: Path) -> None:
    """The compiled loop takes every robot's programs as a tuple of MAX_TABLES (the main table's repeated after
    the robot's own), so robots of 2, 3 and MAX_TABLES tables run on one compiled loop -- numba compiles once
    per tuple length: a minute of compiling for each new number of tables otherwise -- and each still steps as
    Several does (the padding is never read)."""
    from tablebot.robot_tables import MAX_TABLES
    from tablebot.sim.physics.several import run_several
    from tablebot.sim.runner import simulate
    from tablebot.testing.random_robots import RobotShape, random_robot

    for count in (2, 3, MAX_TABLES):
        # two states a table, seed 1: many random robots of MAX_TABLES tables have a table of more event columns
        # (cross-table ones) than the compiled simulator takes
        folder = random_robot(random.Random(1), tmp_path / str(count), RobotShape(tables=count, states=2))
        project = tablebot.open(folder / "t0.csv", robot=folder / "robot.toml")
        assert project.tables is not None and len(project.tables.machines) == count
        run = simulate(project.scene(every_table=True), 1.0, seed=count)
        text = io.StringIO()
        run.write_trace(text)
        lines = [json.loads(line) for line in text.getvalue().splitlines()]
        assert several_differences(project.tables, Run(run.inputs(), lines)) is None, count
    assert len(run_several.signatures) == 1, run_several.signatures


def test_run_on_sim_steps_every_table(tmp_path: Path) -> None:
    """tablebot run --on sim (the simulator paced in real time, the code path of a controller) of the BumberBot with
    its lights runs both tables: its trace is sim's for the seed, the lights table's keys too (and the clock's)."""
    project = tablebot.open(EXAMPLE)
    connection = project.connect("sim", seed=4)
    assert connection.tables is not None
    live = connection.run(seconds=0.3, out=tmp_path)
    assert live.end.reason == "done"
    written = next(p for p in live.files if p.name.startswith("trace"))
    lines = [json.loads(line) for line in written.read_text().splitlines()]
    text = io.StringIO()
    project.simulate(seconds=0.3, seed=4).run.write_trace(text)
    expected = [json.loads(line) for line in text.getvalue().splitlines()]
    assert [{k: v for k, v in line.items() if k not in ("late_ms", "wall")} for line in lines] == expected
