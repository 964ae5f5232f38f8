"""Each rule once: the threshold with hysteresis (tablebot.sensors.threshold_event) and the TXT family's PWM
scaling (tablebot.hw.txt.wiring.level_pwm) are functions the simulator and the controllers call; the TXT 4.0 program is
a standalone file shipped to the controller, so it carries its own copies, proven equal to them here by
driving the program's robot (against the stub of the ``fischertechnik`` calls, tests/txt4_stub)."""

from __future__ import annotations

import ast
import json
import random
from collections.abc import Sequence
from pathlib import Path

import numpy as np
import pytest

from core_helpers import EXAMPLE
from tablebot.engine import Engine
from tablebot.formats.table_read import load_table
from tablebot.hw.txt.wiring import TxtWiring, level_pwm
from tablebot.hw.txt4.export import export_txt4
from tablebot.hw.wiring import InputWire, OutputWire, Wiring
from tablebot.loop import Reading, RealTimeClock, run
from tablebot.machine import compile_table
from tablebot.sensors import Sensor, threshold_event
from tablebot.sim import columns as L
from tablebot.sim.model.params import sensor_fields
from tablebot.sim.physics.layout import as_params, as_state
from tablebot.sim.physics.sensing import sensor_events
from test_txt4_program import stub_robot

pytestmark = [pytest.mark.realtime]


def walk(rng: random.Random, low: int, high: int, ticks: int) -> list[int]:
    """Readings that wander across a threshold and back, stopping on every value in between."""
    value, out = (low + high) // 2, []
    for _ in range(ticks):
        value = max(low, min(high, value + rng.choice((-3, -1, -1, 0, 1, 1, 3))))
        out.append(value)
    return out


def events(rule: object, readings: list[int]) -> list[bool]:
    """A rule (reading, was_on) -> on, applied tick after tick."""
    on, seen = False, []
    for value in readings:
        on = bool(rule(value, on))  # type: ignore[operator]
        seen.append(on)
    return seen


CASES = [
    (direction, limit, hysteresis) for direction in ("below", "above") for limit in (20, 35) for hysteresis in (0, 1, 5)
]


@pytest.mark.parametrize(("direction", "limit", "hysteresis"), CASES)
def test_the_simulator_the_txt_and_the_txt4_program_switch_alike(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, direction: str, limit: int, hysteresis: int
) -> None:
    readings = walk(random.Random(limit * 7 + hysteresis), limit - 12, limit + 12, 300)
    sensor = Sensor("I1", "ultrasonic", (0.1, 0.0), 0.0, direction, limit / 100, hysteresis / 100, "cm")
    above = direction == "above"
    off = limit - hysteresis if above else limit + hysteresis
    the_rule = events(lambda v, on: threshold_event(v, above, limit, off, on), readings)
    assert True in the_rule and False in the_rule  # the walk crossed the threshold both ways

    wire = InputWire(
        "I1",
        "I1",
        "ultrasonic",
        False,
        below=None if above else limit,
        above=limit if above else None,
        hysteresis=hysteresis,
    )
    assert events(lambda v, on: wire.reads(v, on), readings) == the_rule  # the TXT, the ROBO TX and ROBO Interface
    txt = TxtWiring(Wiring((wire,), (1,), (), ()))
    assert events(lambda v, on: txt.mask([v] + [0] * 7, on), readings) == the_rule  # as the TXT's replies reach it

    p = np.zeros(L.N_PARAM)  # the simulator's compiled sensing, readings in metres
    p[L.P_SENSOR : L.P_SENSOR + L.SENSOR_FIELDS] = sensor_fields(sensor)
    s, bits = np.zeros(L.N_STATE), np.zeros(L.N_BITS, dtype=np.int64)
    bits[L.B_SENSOR] = 1

    def simulated(value: int, on: bool) -> bool:
        s[L.READING] = value / 100
        return bool(sensor_events(as_state(s), as_params(p), bits, int(on)))  # rows read by name

    assert events(simulated, readings) == events(lambda v, on: sensor.event(v / 100, on), readings)

    table = {
        "inputs": [
            {
                "name": "I1",
                "terminal": 1,
                "mode": "ultrasonic",
                "bit": 1,
                "invert": False,
                "below": wire.below,
                "above": wire.above,
                "hysteresis": hysteresis,
            }
        ],
        "motors": [],
        "lamps": [],
        "counters": [],
        "n_outputs": 0,
    }
    robot = stub_robot(tmp_path, monkeypatch, table, [[v, 0, 0, 0, 0, 0, 0, 0] for v in readings])
    assert [bool(robot.read()[0]) for _ in readings] == the_rule  # the TXT 4.0 program


def test_the_txt4_program_scales_speeds_and_lamps_as_the_txt(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """Every level -10..10 on a motor, a reversed motor and a lamp: the PWM the TXT 4.0 program sets is the
    one the TXT's wiring sends, both :func:`level_pwm`."""
    levels = list(range(-10, 11))
    assert [level_pwm(v) for v in levels] == [max(0, min(8, v)) * 64 for v in levels]  # level 8 = PWM 512
    table = {
        "inputs": [
            {"name": "I1", "terminal": 1, "mode": "switch", "bit": 1, "invert": False, "below": None, "above": None}
        ],
        "motors": [
            {"name": "A", "output": 0, "terminal": 1, "reverse": False, "encoder": False},
            {"name": "B", "output": 1, "terminal": 2, "reverse": True, "encoder": False},
        ],
        "lamps": [{"name": "L", "output": 2, "terminal": 5}],
        "counters": [],
        "n_outputs": 3,
    }
    robot = stub_robot(tmp_path, monkeypatch, table, [[0] * 8] * (len(levels) + 1))
    txt = TxtWiring(
        Wiring(
            (),
            (),
            (
                OutputWire("A", "motor", "M1"),
                OutputWire("B", "motor", "M2", reverse=True),
                OutputWire("L", "lamp", "O5"),
            ),
            (),
        )
    )
    expected = []
    for tick, level in enumerate(levels):
        robot.read()
        robot.write([level, level, level])
        pwm = txt.pwm([level, level, level])
        expected.append({"M1": pwm[0] or pwm[1], "M2": pwm[2] or pwm[3], "O5": pwm[4], "tick": tick})
        assert pwm[4] == level_pwm(level) and max(pwm[0], pwm[1]) == level_pwm(abs(level))
    set_to: dict[str, int] = {}
    seen = []
    calls = [json.loads(line) for line in (tmp_path / "calls.jsonl").read_text().splitlines()]
    for tick in range(len(levels)):
        for call in (c for c in calls if c["tick"] == tick):
            if call["call"] in ("set_speed", "set_brightness"):
                set_to[call["device"]] = call["args"][0]
            elif call["call"] == "stop":
                set_to[call["device"]] = 0
        seen.append({**set_to, "tick": tick})
    assert seen == expected


class SimulatedTime:
    """A clock both loops read: ``now`` is the simulated time, ``sleep`` advances it (and is noted)."""

    def __init__(self) -> None:
        self.t = 0.0
        self.sleeps: list[float] = []

    def now(self) -> float:
        return self.t

    def sleep(self, seconds: float) -> None:
        self.sleeps.append(round(seconds, 9))
        self.t += seconds


class LinkRobot:
    """A robot whose link takes ``delays[n]`` seconds to answer read ``n``, which reads ``masks[n]``; it notes
    when each write arrives and what it says. ``read`` answers in the TXT 4.0 program's form (mask, pulses)."""

    def __init__(self, time: SimulatedTime, masks: list[int], delays: list[float]) -> None:
        self.time, self.masks, self.delays = time, masks, delays
        self.n, self.stops = 0, 0
        self.writes: list[tuple[float, tuple[int, ...]]] = []

    def read(self) -> tuple[int, list[int]]:
        self.time.t += self.delays[self.n]
        self.n += 1
        return self.masks[self.n - 1], []

    def write(self, outputs: Sequence[int]) -> None:
        self.writes.append((round(self.time.t, 9), tuple(outputs)))

    def stop(self) -> None:
        self.stops += 1

    def open(self) -> None:
        pass

    def close(self) -> None:
        pass


class LoopRobot(LinkRobot):
    """The same robot behind the RobotIO seam of tablebot.loop."""

    def read(self) -> Reading:  # type: ignore[override]
        mask, pulses = super().read()
        return Reading(mask, tuple(pulses))


STALLS = {
    "a quick link": {},
    "a 0.3 s stall": {5: 0.3},
    "a 0.7 s stall": {5: 0.7},
    "a link slower than the tick": dict.fromkeys(range(60), 0.013),
    "a jittery link": {n: random.Random(n).uniform(0.0, 0.02) for n in range(60)},
}


@pytest.mark.parametrize("case", STALLS)
def test_the_txt4_programs_loop_paces_stops_and_falls_behind_as_the_run_loop(case: str) -> None:
    """The TXT 4.0 program runs its own loop (it has no tablebot); driven with the same robot and the same
    simulated time as :func:`tablebot.loop.run` with a real-time clock and the program's behind-limit, it
    sleeps the same, writes the same outputs at the same moments, counts the same late ticks and ends for
    the same reason (both re-anchor a late tick's grid on the moment it started: the loop as due + late, the
    program by reading the clock again, equal to 1e-9 s)."""
    from tablebot.hw.txt4 import runtime as txt4_runtime

    machine = compile_table(load_table(EXAMPLE / "table.csv"))
    table = ast.literal_eval(export_txt4(machine).files["lib/tablebot_program.py"].split("\nTABLE = ", 1)[1])
    rng = random.Random(3)
    masks = [sum(b for b in machine.input_bits.values() if rng.random() < 0.15) for _ in range(60)]
    delays = [STALLS[case].get(n, 0.002) for n in range(60)]
    program_time, loop_time, said = SimulatedTime(), SimulatedTime(), list[str]()
    program_robot, loop_robot = LinkRobot(program_time, masks, delays), LoopRobot(loop_time, masks, delays)
    reason = txt4_runtime.run(table, program_robot, 60, now=program_time.now, sleep=program_time.sleep, log=said.append)
    clock = RealTimeClock(machine.table.robot.tick_s, now=loop_time.now, sleep=loop_time.sleep)
    end = run(Engine(machine), loop_robot, clock=clock, ticks=60, behind_limit_s=txt4_runtime.BEHIND_LIMIT_S)
    assert (reason, program_robot.writes, program_time.sleeps, program_robot.stops) == (
        end.reason,
        loop_robot.writes,
        loop_time.sleeps,
        loop_robot.stops,
    )
    assert f"({end.late_ticks} late)" in said[-1]
    assert end.reason == ("behind" if case == "a 0.7 s stall" else "done")
    assert end.late_ticks > 0 or case == "a quick link"
