"""``tablebot export --to txt4``: the program's engine equals tablebot's tick for tick on random tables, and
the whole program, run as the TXT 4.0 would run it against a stub of exactly the ``fischertechnik`` calls
it uses, drives the outputs the engine decides and stops them when stopped."""

from __future__ import annotations

import ast
import dataclasses
import importlib.util
import json
import os
import random
import subprocess
import sys
from pathlib import Path
from types import ModuleType
from typing import Any

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from typer.testing import CliRunner

from core_helpers import EXAMPLE
from tablebot.cli import app
from tablebot.engine import Engine
from tablebot.escape import python_string
from tablebot.formats.inputs_csv import TickInput
from tablebot.formats.table_read import load_table
from tablebot.hw.txt4.export import export_txt4
from tablebot.machine import Machine, compile_table
from tablebot.replay import replay
from tablebot.table import Table
from tablebot.testing.random_tables import Shape, random_inputs, random_table
from test_txt_robot import wired_random_machine

STUB = Path(__file__).resolve().parent / "txt4_stub"


def load_program(folder: Path) -> ModuleType:
    """The exported lib/tablebot_program.py, imported from its file (importing runs nothing)."""
    path = folder / "lib" / "tablebot_program.py"
    spec = importlib.util.spec_from_file_location(f"program_{abs(hash(folder))}", path)
    module = importlib.util.module_from_spec(spec)  # type: ignore[arg-type]
    spec.loader.exec_module(module)  # type: ignore[union-attr]
    return module


def with_txt_section(table: Table) -> Machine:
    """A random table's robot wired onto TXT terminals: inputs I1.., motors M1.., lamps on the outputs the
    motors leave free, counters C1.."""
    robot = table.robot
    wiring: dict[str, object] = {name: {"terminal": name, "mode": "switch", "pressed": 1} for name in robot.inputs}
    wiring.update({name: name for name in robot.motors})
    wiring.update({name: f"O{2 * len(robot.motors) + i + 1}" for i, name in enumerate(robot.lamps)})
    wiring.update({name: name for name in robot.counter_names})
    robot = dataclasses.replace(robot, sections={"txt": wiring})
    return compile_table(dataclasses.replace(table, robot=robot))


@pytest.mark.parametrize("seed", range(12))
def test_the_exported_engine_takes_the_python_engines_decisions_tick_for_tick(tmp_path: Path, seed: int) -> None:
    rng = random.Random(seed)
    shape = Shape(states=rng.randint(1, 6), rows=rng.randint(4, 24), inputs=rng.randint(1, 5),
                  motors=rng.randint(1, 2), lamps=rng.randint(0, 3), counters=rng.randint(0, 3))
    machine = with_txt_section(random_table(rng, shape))
    export_txt4(machine).write(tmp_path)
    program = load_program(tmp_path)
    ours, theirs = Engine(machine), program.Engine(program.TABLE)
    for tick in random_inputs(rng, machine.table, 400, max_pulses=3):
        ours.step(tick.mask, tick.pulses)
        theirs.step(tick.mask, list(tick.pulses))
        assert (theirs.state, theirs.timer, theirs.event, theirs.row) == (ours.state, ours.timer, ours.event, ours.row)
        assert (tuple(theirs.outputs), theirs.counters) == (ours.outputs, ours.counters)


def run_on_stub(folder: Path, name: str, inputs: list[list[int]], counts: list[list[int]]) -> tuple[list[dict], str]:
    """Run the exported program as the controller would (``python NAME.py`` in its folder), without
    site-packages (so no numpy, no tablebot), against the stub."""
    script, log = folder / "script.json", folder / "calls.jsonl"
    script.write_text(json.dumps({"inputs": inputs, "counts": counts}))
    env = {"PATH": os.environ["PATH"], "PYTHONPATH": str(STUB), "TABLEBOT_STUB_SCRIPT": str(script),
           "TABLEBOT_STUB_LOG": str(log)}
    done = subprocess.run([sys.executable, "-S", f"{name}.py"], cwd=folder, env=env, capture_output=True, text=True,
                          timeout=60)
    assert done.returncode == 0, done.stderr
    return [json.loads(line) for line in log.read_text().splitlines()], done.stdout


def outputs_per_tick(calls: list[dict], ticks: int) -> list[dict[str, object]]:
    """What each output was doing after each tick, from the calls the program made."""
    state: dict[str, object] = {}
    per_tick: list[dict[str, object]] = []
    for tick in range(ticks):
        for call in (c for c in calls if c["tick"] == tick):
            if call["call"] == "set_speed":
                state[call["device"]] = (call["args"][0], call["args"][1])
            elif call["call"] == "stop":
                state[call["device"]] = 0
            elif call["call"] == "set_brightness":
                state[call["device"]] = call["args"][0]
        per_tick.append(dict(state))
    return per_tick


def test_the_exported_program_drives_the_stub_as_the_engine_decides_and_stops_on_sigterm(tmp_path: Path) -> None:
    """The wired random robot of test_txt_robot: a switch, an inverted switch, an ultrasonic threshold, a
    reversed motor on another pair, a lamp on O7 and a counter on C3; 120 ticks, then SIGTERM."""
    machine = wired_random_machine(tmp_path)
    workspace = export_txt4(machine)
    out = tmp_path / "out"
    workspace.write(out)
    rng = random.Random(8)
    inputs = [[rng.randint(0, 1), 0, 0, rng.randint(0, 1), 0, rng.choice([5, 19, 20, 90]), 0, 0] for _ in range(120)]
    counts, total = [], 0
    for _ in range(120):
        total += rng.randint(0, 3)
        counts.append([0, 0, total, 0])
    calls, printed = run_on_stub(out, workspace.name, inputs, counts)
    assert "tablebot: terminated after 120 ticks" in printed
    assert [c["args"] for c in calls if c["call"] == "initialized"] == [[[]]]  # neither numpy nor tablebot loaded
    assert {"device": "C3", "call": "set_motor", "args": ["M2"], "tick": -1} in calls  # C1 counts M1, wired on M2
    bits = machine.input_bits
    ticks = [TickInput((bits["I1"] if u[0] else 0) | (bits["I2"] if not u[3] else 0) | (bits["I3"] if u[5] < 20 else 0),
                       (0 if n == 0 else counts[n][2] - counts[n - 1][2],)) for n, u in enumerate(inputs)]
    expected = []
    for line in replay(machine, ticks):
        m1, m2 = -line["M1"], line["M2"]  # M1 reversed on terminal M2; M2 on M1
        expected.append({"M2": (abs(m1) * 64, "CCW" if m1 > 0 else "CW") if m1 else 0,
                         "M1": (abs(m2) * 64, "CCW" if m2 > 0 else "CW") if m2 else 0, "O7": line["L1"] * 64})
    seen = outputs_per_tick(calls, 120)
    assert [{k: s.get(k) for k in ("M1", "M2", "O7")} for s in seen] == expected
    assert any(s["M1"] or s["M2"] for s in seen)  # the motors did run
    last = [(c["device"], c["call"], c["args"]) for c in calls if c["tick"] >= 119][-3:]
    assert sorted(last) == [("M1", "stop", []), ("M2", "stop", []), ("O7", "set_brightness", [0])]


def test_the_bumberbot_program_reads_bumpers_and_phototransistors(tmp_path: Path) -> None:
    machine = compile_table(load_table(EXAMPLE / "table.csv"))
    workspace = export_txt4(machine)
    workspace.write(tmp_path)
    inputs = [[0] * 8] * 5 + [[0, 0, 1, 0, 0, 0, 0, 0]] * 10 + [[0] * 8] * 60 + [[0, 0, 0, 0, 0, 0, 1, 1]] * 20
    calls, _ = run_on_stub(tmp_path, "BumberBot", inputs, [[0, 0, 0, 0]])
    bits = machine.input_bits
    masks = [(bits["I3"] if u[2] else 0) | (bits["I7"] if u[6] else 0) | (bits["I8"] if u[7] else 0) for u in inputs]
    expected = list(replay(machine, [TickInput(m) for m in masks]))
    seen = outputs_per_tick(calls, len(inputs))
    for line, state in zip(expected, seen, strict=True):
        for motor in ("M1", "M2"):
            want = (abs(line[motor]) * 64, "CCW" if line[motor] > 0 else "CW") if line[motor] else 0
            assert state.get(motor, 0) == want, (line, state)
    assert {1, 20, 29} <= {line["row"] for line in expected}  # the bumper (row 1) and the light (20, 29) mattered


def test_export_writes_a_workspace_and_refuses_a_table_that_does_not_fit(tmp_path: Path) -> None:
    runner = CliRunner()
    result = runner.invoke(app, ["export", str(EXAMPLE), str(tmp_path / "ok"), "--to", "txt4"])
    assert result.exit_code == 0, result.output
    assert sorted(p.relative_to(tmp_path / "ok").as_posix() for p in (tmp_path / "ok").rglob("*") if p.is_file()) == [
        ".project.json", "BumberBot.py", "lib/__init__.py", "lib/tablebot_program.py"]
    assert "tablebot upload" in result.output
    again = runner.invoke(app, ["export", str(EXAMPLE), str(tmp_path / "again"), "--to", "txt4"])
    assert again.exit_code == 0
    for name in ("BumberBot.py", "lib/tablebot_program.py", ".project.json"):  # the same table, the same bytes
        assert (tmp_path / "ok" / name).read_bytes() == (tmp_path / "again" / name).read_bytes()
    (tmp_path / "bad").mkdir()
    (tmp_path / "bad" / "table.csv").write_text((EXAMPLE / "table.csv").read_text())
    (tmp_path / "bad" / "robot.toml").write_text((EXAMPLE / "robot.toml").read_text().replace('M2 = "M2"', 'M2 = "M7"'))
    refused = runner.invoke(app, ["export", str(tmp_path / "bad"), str(tmp_path / "nothing"), "--to", "txt4"])
    assert refused.exit_code == 2 and "motor M2: the TXT has no motor terminal 'M7'" in refused.output
    assert not (tmp_path / "nothing").exists()


def test_user_text_reaches_the_program_only_as_string_literals(tmp_path: Path) -> None:
    evil = "x'); import os; os.system('touch PWNED'); ('\n\"\"\" \\ \u2028 \x00 é"
    (tmp_path / "table.csv").write_text((EXAMPLE / "table.csv").read_text())
    robot = (EXAMPLE / "robot.toml").read_text().replace('name = "BumberBot"', f"name = {json.dumps(evil)}")
    (tmp_path / "robot.toml").write_text(robot)
    result = CliRunner().invoke(app, ["export", str(tmp_path), str(tmp_path / "out"), "--to", "txt4"])
    assert result.exit_code == 0, result.output
    (program_file,) = (tmp_path / "out" / "lib").glob("tablebot_program.py")
    tree = ast.parse(program_file.read_text(encoding="utf-8"))
    (table_node,) = [n for n in tree.body if isinstance(n, ast.Assign) and n.targets[0].id == "TABLE"]  # type: ignore[attr-defined]
    assert ast.literal_eval(table_node.value)["name"] == evil  # pure data, and exactly the user's text
    assert program_file.read_text(encoding="utf-8").isascii()
    assert load_program(tmp_path / "out").TABLE["name"] == evil
    assert not (tmp_path / "out" / "PWNED").exists()


@settings(max_examples=60, deadline=None)
@given(st.text())
def test_python_string_is_a_literal_that_reads_back_exactly(text: str) -> None:
    literal = python_string(text)
    assert literal.isascii() and "\n" not in literal and "\r" not in literal
    assert ast.literal_eval(literal) == text


def stub_robot(tmp_path: Path, monkeypatch: pytest.MonkeyPatch, table: dict, inputs: list[list[int]]) -> Any:
    """The runtime's robot for ``table`` in this process, on a fresh import of the stub serving ``inputs``."""
    from tablebot.hw.txt4 import runtime as txt4_runtime

    script = tmp_path / "script.json"
    script.write_text(json.dumps({"inputs": inputs, "counts": [[0, 0, 0, 0]] * len(inputs)}))
    monkeypatch.setenv("TABLEBOT_STUB_SCRIPT", str(script))
    monkeypatch.setenv("TABLEBOT_STUB_LOG", str(tmp_path / "calls.jsonl"))
    monkeypatch.syspath_prepend(str(STUB))
    for name in [m for m in sys.modules if m.startswith("fischertechnik")]:
        monkeypatch.delitem(sys.modules, name)
    factories = importlib.import_module("fischertechnik.factories")
    motor = importlib.import_module("fischertechnik.controller.Motor").Motor
    return txt4_runtime.Txt4Robot(table, factories, motor)


def test_every_input_mode_reads_through_its_own_call(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    def wire(terminal: int, mode: str, bit: int, **how: object) -> dict:
        return {"name": f"X{terminal}", "terminal": terminal, "mode": mode, "bit": bit,
                "invert": how.get("invert", False), "below": how.get("below"), "above": how.get("above")}

    table = {"inputs": [wire(1, "switch", 1), wire(2, "phototransistor", 2, invert=True),
                        wire(3, "ultrasonic", 4, below=20), wire(4, "voltage", 8, above=5000),
                        wire(5, "resistance", 16, below=1000)],
             "motors": [], "lamps": [], "counters": [], "n_outputs": 0}
    robot = stub_robot(tmp_path, monkeypatch, table, [[1, 1, 19, 6000, 900, 0, 0, 0]])
    assert robot.read() == (1 | 4 | 8 | 16, [])


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


def test_the_on_board_loop_stops_when_it_falls_behind_or_is_interrupted() -> None:
    from tablebot.hw.txt4 import runtime as txt4_runtime

    machine = compile_table(load_table(EXAMPLE / "table.csv"))
    workspace = export_txt4(machine)
    table = ast.literal_eval(workspace.files["lib/tablebot_program.py"].split("\nTABLE = ", 1)[1])
    clock = iter([0.0, 0.0, 0.01, 0.02, 0.7, 0.7, 0.7])  # a 0.7 s stall before tick 3
    robot, said = CountingRobot(), []
    reason = txt4_runtime.run(table, robot, 10, now=lambda: next(clock), sleep=lambda s: None, log=said.append)
    assert reason == "behind"
    assert len(robot.writes) == 3 and robot.stops == 1 and "stopping rather than stretching" in said[0]

    class Interrupted(CountingRobot):
        def read(self) -> tuple[int, list[int]]:
            if len(self.writes) == 4:
                raise KeyboardInterrupt
            return 0, []

    robot = Interrupted()
    assert txt4_runtime.run(table, robot, None, sleep=lambda s: None, log=said.append) == "stopped"
    assert robot.stops == 1 and "stopped after 4 ticks" in said[-1]


def test_the_on_board_program_keeps_the_declared_hysteresis(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """An ultrasonic input below 25 cm with 5 cm hysteresis: on at 24, still on at 29, off at 30."""
    rows = [[cm, 0, 0, 0, 0, 0, 0, 0] for cm in (40, 24, 29, 30, 24)]
    table = {"inputs": [{"name": "I1", "terminal": 1, "mode": "ultrasonic", "bit": 1, "invert": False,
                         "below": 25, "above": None, "hysteresis": 5}],
             "motors": [], "lamps": [], "counters": [], "n_outputs": 0}
    robot = stub_robot(tmp_path, monkeypatch, table, rows)
    assert [robot.read()[0] for _ in rows] == [0, 1, 1, 0, 1]
