"""The program ``export --to txt4`` writes, run as a TXT 4.0 runs it against the ``fischertechnik`` stub
(tests/txt4_stub, written from the real package's sources): it drives the outputs the engine decides,
counts encoder pulses across motor restarts, and stops its outputs however it is ended -- SIGTERM after
the package installed its own handler, SIGTERM while it runs in a worker thread (as harbaum/SofTXT's
run.py runs programs), the runner exiting under it, an exception, Ctrl-C, falling behind."""

from __future__ import annotations

import ast
import importlib
import json
import os
import random
import re
import signal
import subprocess
import sys
from pathlib import Path
from typing import Any

import pytest

import tablebot.hw.txt4.runtime as txt4_runtime
from core_helpers import EXAMPLE
from tablebot.formats.inputs_csv import TickInput
from tablebot.formats.table_read import load_table
from tablebot.hw.txt4.export import export_txt4
from tablebot.machine import compile_table
from tablebot.replay import replay
from test_txt_robot import wired_random_machine

pytestmark = [pytest.mark.realtime]

STUB = Path(__file__).resolve().parents[1] / "txt4_stub"
CCW, CW = 1, -1  # fischertechnik.controller.Motor

#: As harbaum/SofTXT's run.py runs a program: its code exec'd with empty globals in a worker thread, while
#: the main thread keeps calling into Python every 10 ms (SofTXT's Qt event loop with a 10 ms QTimer).
THREAD_RUNNER = """
import os, sys, threading, time
workspace, name, linger = sys.argv[1], sys.argv[2], float(sys.argv[3])
sys.path.append(workspace)
with open(os.path.join(workspace, name + ".py")) as f:
    code = f.read()
worker = threading.Thread(target=lambda: exec(code, {}), daemon=True)
worker.start()
deadline = time.monotonic() + linger
while worker.is_alive() and time.monotonic() < deadline:
    time.sleep(0.01)
print("runner: main thread exits", flush=True)
"""


def run_on_stub(
    folder: Path,
    name: str,
    inputs: list[list[int]],
    pulses: list[list[int]] | None = None,
    runner: list[str] | None = None,
) -> tuple[list[dict], subprocess.CompletedProcess]:
    """Run the exported program as the controller would (``python NAME.py`` in its folder, or through
    ``runner``), without site-packages (so no numpy, no tablebot), against the stub."""
    script, log = folder / "script.json", folder / "calls.jsonl"
    script.write_text(json.dumps({"inputs": inputs, "pulses": pulses or [[0, 0, 0, 0]]}))
    env = {
        "PATH": os.environ["PATH"],
        "PYTHONPATH": str(STUB),
        "TABLEBOT_STUB_SCRIPT": str(script),
        "TABLEBOT_STUB_LOG": str(log),
    }
    done = subprocess.run(
        [sys.executable, "-S", *(runner or [f"{name}.py"])],
        cwd=folder,
        env=env,
        capture_output=True,
        text=True,
        timeout=60,
    )
    return [json.loads(line) for line in log.read_text().splitlines()], done


def outputs_per_tick(calls: list[dict], ticks: int) -> list[dict[str, object]]:
    """What each output was doing after each tick, from the calls the program made."""
    state: dict[str, object] = {}
    per_tick: list[dict[str, object]] = []
    for tick in range(ticks):
        for call in (c for c in calls if c["tick"] == tick and c["phase"] == "run"):
            if call["call"] == "set_speed":
                state[call["device"]] = (call["args"][0], call["args"][1])
            elif call["call"] == "stop":
                state[call["device"]] = 0
            elif call["call"] == "set_brightness":
                state[call["device"]] = call["args"][0]
        per_tick.append(dict(state))
    return per_tick


def motor(speed: int) -> object:
    return (abs(speed) * 64, CCW if speed > 0 else CW) if speed else 0


def stopped_last(calls: list[dict], devices: set[str]) -> bool:
    """The program's own last calls (before any exit-time cleanup of the package) stop every output."""
    last = {}
    for call in (c for c in calls if c["phase"] == "run" and c["device"] in devices):
        last[call["device"]] = (call["call"], call["args"])
    return all(last[d] in (("stop", []), ("set_brightness", [0])) for d in devices)


def test_the_program_drives_the_stub_as_the_engine_decides_and_stops_on_sigterm(tmp_path: Path) -> None:
    """The wired random robot of test_txt_robot: a switch, an inverted switch, an ultrasonic threshold, a
    reversed motor on another pair, a lamp on O7 and a counter of M1 (on terminal M2, so on the TXT 4.0 it
    reads M2's distance, whose encoder pulses arrive on C2); 120 ticks, then the stub's SIGTERM -- which
    the program handles although the package installed its own SIGTERM handler when it was imported."""
    machine = wired_random_machine(tmp_path)
    workspace = export_txt4(machine)
    out = tmp_path / "out"
    workspace.write(out)
    rng = random.Random(8)
    inputs = [[rng.randint(0, 1), 0, 0, rng.randint(0, 1), 0, rng.choice([5, 19, 20, 90]), 0, 0] for _ in range(120)]
    pulses = [[0, rng.randint(0, 3), 0, 0] for _ in range(120)]
    calls, done = run_on_stub(out, workspace.name, inputs, pulses)
    assert done.returncode == 0, done.stderr
    assert "tablebot: terminated after 120 ticks" in done.stdout
    assert [c["args"] for c in calls if c["call"] == "initialized"] == [[[]]]  # neither numpy nor tablebot loaded
    assert {"device": "C3", "call": "set_motor", "args": ["M2"], "tick": -1, "phase": "run"} in calls
    bits = machine.input_bits
    ticks = [
        TickInput(
            (bits["I1"] if u[0] else 0) | (bits["I2"] if not u[3] else 0) | (bits["I3"] if u[5] < 20 else 0),
            (pulses[n][1],),
        )
        for n, u in enumerate(inputs)
    ]
    expected = [
        {"M2": motor(-line["M1"]), "M1": motor(line["M2"]), "O7": line["L1"] * 64} for line in replay(machine, ticks)
    ]
    seen = outputs_per_tick(calls, 120)
    assert [{k: s.get(k) for k in ("M1", "M2", "O7")} for s in seen] == expected
    assert stopped_last(calls, {"M1", "M2", "O7"})
    assert [c["call"] for c in calls if c["phase"] == "exit"][:3] == ["off", "stop", "stop"]  # then the package's


def test_the_bumberbot_program_reads_bumpers_and_phototransistors(tmp_path: Path) -> None:
    machine = compile_table(load_table(EXAMPLE / "table.csv"))
    workspace = export_txt4(machine)
    workspace.write(tmp_path)
    inputs = [[0] * 8] * 5 + [[0, 0, 1, 0, 0, 0, 0, 0]] * 10 + [[0] * 8] * 60 + [[0, 0, 0, 0, 0, 0, 1, 1]] * 20
    calls, done = run_on_stub(tmp_path, "BumberBot", inputs)
    assert done.returncode == 0, done.stderr
    bits = machine.input_bits
    masks = [(bits["I3"] if u[2] else 0) | (bits["I7"] if u[6] else 0) | (bits["I8"] if u[7] else 0) for u in inputs]
    expected = list(replay(machine, [TickInput(m) for m in masks]))
    for line, state in zip(expected, outputs_per_tick(calls, len(inputs)), strict=True):
        assert (state.get("M1", 0), state.get("M2", 0)) == (motor(line["M1"]), motor(line["M2"])), (line, state)
    assert {1, 20, 29} <= {line["row"] for line in expected}  # the bumper (row 1) and the light (20, 29) mattered


def test_in_a_worker_thread_sigterm_stops_the_outputs_before_the_process_ends(tmp_path: Path) -> None:
    """No signal handler can be set in a worker thread: the program has the main thread install one, which
    hands SIGTERM to the run, waits for its outputs-off, then lets SIGTERM end the process as before."""
    export_txt4(compile_table(load_table(EXAMPLE / "table.csv"))).write(tmp_path)
    (tmp_path / "runner.py").write_text(THREAD_RUNNER)
    inputs = [[0] * 8] * 5 + [[0, 0, 0, 0, 0, 0, 1, 1]] * 100  # both lights: the motors run when SIGTERM comes
    calls, done = run_on_stub(tmp_path, "BumberBot", inputs, runner=["runner.py", str(tmp_path), "BumberBot", "30"])
    assert done.returncode == -signal.SIGTERM, (done.stdout, done.stderr)  # ended by SIGTERM, as without us
    assert "running in a worker thread; the main thread hands SIGTERM over" in done.stdout
    ended = re.search(r"tablebot: terminated after (\d+) ticks \(\d+ late\); outputs off", done.stdout)
    assert ended and int(ended[1]) >= 105, done.stdout  # the stub's SIGTERM came in the 106th tick
    assert "runner:" not in done.stdout
    assert any(c["call"] == "start" for c in calls) and stopped_last(calls, {"M1", "M2"})
    assert not [c for c in calls if c["phase"] == "exit"]  # killed: the package's atexit never ran


def test_when_the_runner_exits_under_the_program_its_outputs_are_stopped(tmp_path: Path) -> None:
    """The runner's main thread ends while the program still runs in its (daemon) thread: at exit."""
    export_txt4(compile_table(load_table(EXAMPLE / "table.csv"))).write(tmp_path)
    (tmp_path / "runner.py").write_text(THREAD_RUNNER)
    inputs = [[0] * 8] * 5 + [[0, 0, 0, 0, 0, 0, 1, 1]] * 5000  # 50 s of ticks: the runner exits long before
    calls, done = run_on_stub(tmp_path, "BumberBot", inputs, runner=["runner.py", str(tmp_path), "BumberBot", "0.6"])
    assert done.returncode == 0, done.stderr
    assert "runner: main thread exits" in done.stdout and "tablebot: exit after" in done.stdout
    assert any(c["call"] == "start" for c in calls) and stopped_last(calls, {"M1", "M2"})


def stub_robot(
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    table: dict,
    inputs: list[list[int]],
    pulses: list[list[int]] | None = None,
) -> Any:
    """The runtime's robot for ``table`` in this process, on a fresh import of the stub serving ``inputs``."""
    script = tmp_path / "script.json"
    script.write_text(json.dumps({"inputs": inputs, "pulses": pulses or [[0, 0, 0, 0]]}))
    monkeypatch.setenv("TABLEBOT_STUB_SCRIPT", str(script))
    monkeypatch.setenv("TABLEBOT_STUB_LOG", str(tmp_path / "calls.jsonl"))
    monkeypatch.syspath_prepend(str(STUB))
    for name in [m for m in sys.modules if m.startswith("fischertechnik")]:
        monkeypatch.delitem(sys.modules, name)
    previous = signal.getsignal(signal.SIGTERM)
    factories = importlib.import_module("fischertechnik.factories")  # sets its SIGTERM handler, as the real one
    signal.signal(signal.SIGTERM, previous)
    motor_class = importlib.import_module("fischertechnik.controller.Motor").Motor
    return txt4_runtime.Txt4Robot(table, factories, motor_class)


def test_every_input_mode_reads_through_its_own_call(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    def wire(terminal: int, mode: str, bit: int, **how: object) -> dict:
        return {
            "name": f"X{terminal}",
            "terminal": terminal,
            "mode": mode,
            "bit": bit,
            "invert": how.get("invert", False),
            "below": how.get("below"),
            "above": how.get("above"),
        }

    table = {
        "inputs": [
            wire(1, "switch", 1),
            wire(2, "phototransistor", 2, invert=True),
            wire(3, "ultrasonic", 4, below=20),
            wire(4, "voltage", 8, above=5000),
            wire(5, "resistance", 16, below=1000),
            wire(6, "trail", 32, invert=True),
        ],
        "motors": [],
        "lamps": [],
        "counters": [],
        "n_outputs": 0,
    }
    robot = stub_robot(tmp_path, monkeypatch, table, [[1, 1, 19, 6000, 900, 0, 0, 0], [0, 0, 20, 5000, 1000, 1, 0, 0]])
    assert [robot.read() for _ in range(2)] == [(1 | 4 | 8 | 16 | 32, []), (2, [])]


def test_encoder_pulses_are_counted_across_restarts_and_reversals(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A motor's distance starts again from 0 at each start, whichever way it turns: every pulse is
    counted once (a count that only followed differences would lose them at each restart)."""
    table = {
        "inputs": [
            {"name": "I1", "terminal": 1, "mode": "switch", "bit": 1, "invert": False, "below": None, "above": None}
        ],
        "motors": [{"name": "M1", "output": 0, "terminal": 1, "reverse": False, "encoder": True}],
        "lamps": [],
        "counters": [{"name": "C1", "terminal": 1, "motor": 1}],
        "n_outputs": 1,
    }
    rng = random.Random(3)
    pulses = [[rng.randint(1, 5), 0, 0, 0] for _ in range(40)]
    robot = stub_robot(tmp_path, monkeypatch, table, [[0] * 8] * 40, pulses)
    speeds = [rng.choice([8, 8, -8, 4, -4, 0]) for _ in range(40)]
    seen = []
    for speed in speeds:
        seen.append(robot.read()[1][0])
        robot.write([speed])
    assert seen == [p[0] for p in pulses]
    calls = [json.loads(line) for line in (tmp_path / "calls.jsonl").read_text().splitlines()]
    assert len([c for c in calls if c["call"] == "start"]) >= 10
    assert {c["args"][1] for c in calls if c["call"] == "set_speed"} == {CW, CCW}


class CountingRobot:
    def __init__(self) -> None:
        self.writes: list[list[int]] = []
        self.stops = 0

    def read(self) -> tuple[int, list[int]]:
        return 0, []

    def write(self, outputs: list[int]) -> None:
        self.writes.append(list(outputs))

    def stop(self) -> None:
        self.stops += 1


def bumberbot_table() -> dict:
    workspace = export_txt4(compile_table(load_table(EXAMPLE / "table.csv")))
    return ast.literal_eval(workspace.files["lib/tablebot_program.py"].split("\nTABLE = ", 1)[1])


def test_the_on_board_loop_stops_when_it_falls_behind_is_interrupted_asked_or_fails() -> None:
    table = bumberbot_table()
    clock = iter([0.0, 0.0, 0.01, 0.02, 0.7, 0.7, 0.7])  # a 0.7 s stall before tick 3
    robot, said = CountingRobot(), list[str]()
    reason = txt4_runtime.run(table, robot, 10, now=lambda: next(clock), sleep=lambda s: None, log=said.append)
    assert reason == "behind"
    assert len(robot.writes) == 3 and robot.stops == 1 and "stopping rather than stretching" in said[0]

    ticks = iter(range(10_000))  # every tick 14.3 ms against the table's 10: never one stall, always too slow
    robot = CountingRobot()
    reason = txt4_runtime.run(
        table, robot, 1000, now=lambda: 0.0143 * next(ticks), sleep=lambda s: None, log=said.append
    )
    assert reason == "behind" and 110 <= len(robot.writes) <= 120 and "fell 0.50 s behind" in said[-2]
    ticks = iter(range(10_000))
    assert (
        txt4_runtime.run(
            table, CountingRobot(), 500, now=lambda: 0.0105 * next(ticks), sleep=lambda s: None, log=said.append
        )
        == "done"
    )  # 5 % slow: within the limit

    class Interrupted(CountingRobot):
        def read(self) -> tuple[int, list[int]]:
            if len(self.writes) == 4:
                raise KeyboardInterrupt
            return 0, []

    robot = Interrupted()
    assert txt4_runtime.run(table, robot, None, sleep=lambda s: None, log=said.append) == "stopped"
    assert robot.stops == 1 and "stopped after 4 ticks" in said[-1]

    class Failing(CountingRobot):
        def read(self) -> tuple[int, list[int]]:
            if len(self.writes) == 2:
                raise TypeError("'<' not supported between instances of 'NoneType' and 'int'")
            return 0, []

    robot = Failing()
    with pytest.raises(TypeError):
        txt4_runtime.run(table, robot, None, sleep=lambda s: None, log=said.append)
    assert robot.stops == 1 and "error after 2 ticks" in said[-1]

    stop, robot = txt4_runtime.Stop(), CountingRobot()
    stop.request("asked")
    assert txt4_runtime.run(table, robot, None, log=said.append, stop=stop) == "asked"
    assert robot.writes == [] and robot.stops == 1 and stop.done.is_set()


def test_the_on_board_program_keeps_the_declared_hysteresis(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """An ultrasonic input below 25 cm with 5 cm hysteresis: on at 24, still on at 29, off at 30."""
    rows = [[cm, 0, 0, 0, 0, 0, 0, 0] for cm in (40, 24, 29, 30, 24)]
    table = {
        "inputs": [
            {
                "name": "I1",
                "terminal": 1,
                "mode": "ultrasonic",
                "bit": 1,
                "invert": False,
                "below": 25,
                "above": None,
                "hysteresis": 5,
            }
        ],
        "motors": [],
        "lamps": [],
        "counters": [],
        "n_outputs": 0,
    }
    robot = stub_robot(tmp_path, monkeypatch, table, rows)
    assert [robot.read()[0] for _ in rows] == [0, 1, 1, 0, 1]


def test_the_line_follower_program_reads_its_track_sensor(tmp_path: Path) -> None:
    """create_trail_follower(...).get_state(): 0 over the line (fischertechnik's FTS program), so I1/I2 read 1 there."""
    machine = compile_table(load_table(EXAMPLE.parent / "line-follower" / "table.csv"))
    workspace = export_txt4(machine)
    workspace.write(tmp_path)
    assert "create_trail_follower" in workspace.files["lib/tablebot_program.py"]
    inputs = [[0, 0] + [0] * 6] * 5 + [[1, 0] + [0] * 6] * 5 + [[0, 1] + [0] * 6] * 5
    calls, done = run_on_stub(tmp_path, workspace.name, inputs)
    assert done.returncode == 0, done.stderr
    bits = machine.input_bits
    masks = [(0 if u[0] else bits["I1"]) | (0 if u[1] else bits["I2"]) for u in inputs]
    expected = list(replay(machine, [TickInput(m) for m in masks]))
    seen = outputs_per_tick(calls, len(inputs))
    assert [(s.get("M1"), s.get("M2")) for s in seen] == [(motor(e["M1"]), motor(e["M2"])) for e in expected]
    assert {(3 * 64, CCW), (6 * 64, CCW)} <= {s.get("M1") for s in seen}  # it steered both ways
