"""The simulator through the run loop: live trace = replayed trace, tick-by-tick = compiled, Ctrl-C keeps files."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path
from typing import TYPE_CHECKING

import pytest

from tablebot.engine import Engine
from tablebot.formats.trace_lines import dumps
from tablebot.loop import SimulatedClock, TickBlock
from tablebot.loop import run as run_loop
from tablebot.replay import replay
from tablebot.sim.runner import simulate
from tablebot.sim.simrobot import SimRobot
from tablebot.sinks.trace_file import TraceFile, block_lines
from test_sim_helpers import BUMBERBOT, ROOT, scene_of

if TYPE_CHECKING:
    from tablebot.loop import RunEnd, RunInfo

EXAMPLES = [
    (BUMBERBOT / "table.csv", None),
    (ROOT / "examples" / "bumberbot-counters" / "table.csv", BUMBERBOT / "arena.toml"),
]


class Lines:
    """A sink keeping the trace lines (without the real-time fields, which only the tick path has)."""

    def __init__(self) -> None:
        self.lines: list[str] = []

    def start(self, info: RunInfo) -> None:
        self.machine = info.engine.machine

    def block(self, block: TickBlock) -> None:
        block.extra = {k: v for k, v in block.extra.items() if k != "late_ms"}
        self.lines.extend(block_lines(block, self.machine))

    def end(self, end: RunEnd) -> None:
        pass


class TickByTick(SimulatedClock):
    free_running = False  # the loop then reads, steps and writes one tick at a time


@pytest.mark.parametrize("table, world", EXAMPLES)
def test_the_live_trace_is_the_replayed_trace(tmp_path: Path, table: Path, world: Path | None) -> None:
    """What the old runner wrote by replaying the engine over the recorded inputs, the sink writes live."""
    scene = scene_of(table, world)
    sink = TraceFile(tmp_path / "trace.jsonl")
    result = simulate(scene, 60.0, seed=4, sinks=[sink])
    live = (tmp_path / "trace.jsonl").read_text(encoding="utf-8").splitlines()
    robot = SimRobot(scene, 4)
    replayed = []
    for line, row in zip(replay(scene.machine, result.inputs()), result.kept_rows()[:-1], strict=True):
        line.update(robot.trace_fields(row))
        replayed.append(dumps(line))
    assert live == replayed and len(live) == 6000


@pytest.mark.parametrize("table, world", EXAMPLES)
def test_tick_by_tick_and_compiled_runs_are_the_same_run(table: Path, world: Path | None) -> None:
    """The real-time path (read/step/write per tick) and the compiled block path cannot differ."""
    scene = scene_of(table, world)
    traces = []
    for clock in (TickByTick(), SimulatedClock()):
        keep, robot = Lines(), SimRobot(scene, 9)
        run_loop(Engine(scene.machine), robot, clock=clock, sinks=[keep], ticks=3000)
        traces.append((keep.lines, robot.s.tolist(), robot.collisions, robot.reached_row))
    assert traces[0] == traces[1]


def test_reset_with_a_seed_starts_the_same_run_again() -> None:
    scene = scene_of(BUMBERBOT / "table.csv")
    robot = SimRobot(scene, 3)
    first, _ = robot.reset(seed=5)
    engine = Engine(scene.machine)
    robot.advance(engine, 500)
    after = robot.s.copy()
    again, info = robot.reset(seed=5)
    assert again == first and info == {"seed": 5}
    robot.advance(Engine(scene.machine), 500)
    assert (robot.s == after).all()


def test_ctrl_c_keeps_the_previous_run_and_a_partial_trace(tmp_path: Path) -> None:
    out = tmp_path / "out"
    sim = [sys.executable, "-m", "tablebot", "sim", str(BUMBERBOT), "--out", str(out), "-q"]
    subprocess.run([*sim, "--seconds", "2"], check=True)
    before = {p.name: p.read_bytes() for p in out.iterdir()}
    proc = subprocess.Popen([*sim, "--seconds", "3600"], stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 60
    while not any(p.name.startswith(".trace.jsonl.") for p in out.rglob("*")):  # the live trace has begun
        assert time.monotonic() < deadline and proc.poll() is None
        time.sleep(0.01)
    time.sleep(0.05)
    proc.send_signal(signal.SIGINT)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 130, err
    assert "Traceback" not in err and "trace.partial.jsonl" in err
    assert {p.name: p.read_bytes() for p in out.iterdir() if p.name in before} == before  # untouched
    assert sorted(p.name for p in out.iterdir()) == sorted([*before, "trace.partial.jsonl"])  # no temporary left
    lines = (out / "trace.partial.jsonl").read_text().splitlines()
    end = json.loads(lines[-1])
    assert end["end"] == "interrupted" and end["tick"] == len(lines) - 1 and end["why"] == "stopped by Ctrl-C"
    assert json.loads(lines[-2])["tick"] == end["tick"] - 1


def test_sigterm_stops_the_run_the_same_way(tmp_path: Path) -> None:
    out = tmp_path / "out"
    proc = subprocess.Popen(
        [sys.executable, "-m", "tablebot", "sim", str(BUMBERBOT), "--out", str(out), "-q", "--seconds", "3600"],
        stderr=subprocess.PIPE,
        text=True,
    )
    deadline = time.monotonic() + 60
    while not out.is_dir() or not any(p.name.startswith(".trace.jsonl.") for p in out.rglob("*")):
        assert time.monotonic() < deadline and proc.poll() is None
        time.sleep(0.01)
    os.kill(proc.pid, signal.SIGTERM)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 143, err
    assert json.loads((out / "trace.partial.jsonl").read_text().splitlines()[-1])["end"] == "terminated"
    assert not (out / "trace.jsonl").exists()


def test_a_disk_that_fills_up_under_the_trace_is_a_clear_error_and_leaves_nothing(tmp_path: Path) -> None:
    """A real write failure (the process may write files of at most 1 MB): the background trace writer's
    error reaches the command, which names the file; no half trace and no temporary file are left."""
    import resource

    def small_files() -> None:
        resource.setrlimit(resource.RLIMIT_FSIZE, (1 << 20, 1 << 20))
        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)  # a write past the limit then fails with EFBIG

    out = tmp_path / "out"
    out.mkdir()
    proc = subprocess.run(
        [
            sys.executable,
            "-m",
            "tablebot",
            "sim",
            str(BUMBERBOT),
            "--out",
            str(out),
            "-q",
            "--seconds",
            "600",
            "--no-plots",
        ],
        capture_output=True,
        text=True,
        preexec_fn=small_files,
        timeout=120,
    )
    assert proc.returncode == 2, proc.stderr
    assert f"{out / 'trace.jsonl'}: error: cannot write or read: File too large" in proc.stderr
    assert "Traceback" not in proc.stderr and list(out.iterdir()) == []


@pytest.mark.parametrize("example", ["bumberbot", "line-follower"])
def test_a_run_that_keeps_no_robot_rows_sums_up_the_same(example: str) -> None:
    """Without pictures only the first and last robot rows and a thinned path are kept: same summary."""
    from tablebot.sim.summary import summarise

    scene = scene_of(ROOT / "examples" / example / "table.csv")
    full, lean = simulate(scene, 90.0, seed=2), simulate(scene, 90.0, seed=2, rows=False)
    assert lean.hist is None and summarise(lean) == summarise(full)
    assert (lean.path == full.kept_rows()[::5, :2]).all()
