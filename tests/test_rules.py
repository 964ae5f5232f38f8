"""Each rule once: the threshold with hysteresis (tablebot.sensors.threshold_event) and the TXT family's PWM
scaling (tablebot.hw.txt.wiring.level_pwm) are functions the simulator and the TXT call; the TXT 4.0 program is
a standalone file shipped to the controller, so it carries its own copies, proven equal to them here by
driving the program's robot (against the stub of the ``fischertechnik`` calls, tests/txt4_stub)."""

from __future__ import annotations

import json
import random
from pathlib import Path

import numpy as np
import pytest

from tablebot.hw.txt.wiring import PWM_STEP, InputWire, OutputWire, TxtWiring, level_pwm
from tablebot.sensors import Sensor, threshold_event
from tablebot.sim import columns as L
from tablebot.sim.params import sensor_fields
from tablebot.sim.sensing import sensor_events
from test_txt4_export import stub_robot


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


CASES = [(direction, limit, hysteresis) for direction in ("below", "above") for limit in (20, 35)
         for hysteresis in (0, 1, 5)]


@pytest.mark.parametrize(("direction", "limit", "hysteresis"), CASES)
def test_the_simulator_the_txt_and_the_txt4_program_switch_alike(tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
                                                                  direction: str, limit: int, hysteresis: int) -> None:
    readings = walk(random.Random(limit * 7 + hysteresis), limit - 12, limit + 12, 300)
    sensor = Sensor("I1", "ultrasonic", (0.1, 0.0), 0.0, direction, limit / 100, hysteresis / 100, "cm")
    above = direction == "above"
    off = limit - hysteresis if above else limit + hysteresis
    the_rule = events(lambda v, on: threshold_event(v, above, limit, off, on), readings)
    assert True in the_rule and False in the_rule  # the walk crossed the threshold both ways

    wire = InputWire("I1", 0, "ultrasonic", below=None if above else limit, above=limit if above else None,
                     hysteresis=hysteresis)
    assert events(lambda v, on: wire.reads(v, on), readings) == the_rule  # the TXT

    p = np.zeros(L.N_PARAM)  # the simulator's compiled sensing, readings in metres
    p[L.P_SENSOR: L.P_SENSOR + L.SENSOR_FIELDS] = sensor_fields(sensor)
    s, bits = np.zeros(L.N_STATE), np.zeros(L.N_BITS, dtype=np.int64)
    bits[L.B_SENSOR] = 1

    def simulated(value: int, on: bool) -> bool:
        s[L.READING] = value / 100
        return bool(sensor_events(s, p, bits, int(on)))
    assert events(simulated, readings) == events(lambda v, on: sensor.event(v / 100, on), readings)

    table = {"inputs": [{"name": "I1", "terminal": 1, "mode": "ultrasonic", "bit": 1, "invert": False,
                         "below": wire.below, "above": wire.above, "hysteresis": hysteresis}],
             "motors": [], "lamps": [], "counters": [], "n_outputs": 0}
    robot = stub_robot(tmp_path, monkeypatch, table, [[v, 0, 0, 0, 0, 0, 0, 0] for v in readings])
    assert [bool(robot.read()[0]) for _ in readings] == the_rule  # the TXT 4.0 program


def test_the_txt4_program_scales_speeds_and_lamps_as_the_txt(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """Every level -10..10 on a motor, a reversed motor and a lamp: the PWM the TXT 4.0 program sets is the
    one the TXT's wiring sends, both :func:`level_pwm`."""
    levels = list(range(-10, 11))
    assert [level_pwm(v) for v in levels] == [max(0, min(8, v)) * PWM_STEP for v in levels]
    table = {"inputs": [{"name": "I1", "terminal": 1, "mode": "switch", "bit": 1, "invert": False, "below": None,
                         "above": None}],
             "motors": [{"name": "A", "output": 0, "terminal": 1, "reverse": False, "encoder": False},
                        {"name": "B", "output": 1, "terminal": 2, "reverse": True, "encoder": False}],
             "lamps": [{"name": "L", "output": 2, "terminal": 5}], "counters": [], "n_outputs": 3}
    robot = stub_robot(tmp_path, monkeypatch, table, [[0] * 8] * (len(levels) + 1))
    txt = TxtWiring((), (), (OutputWire("A", "motor", 0), OutputWire("B", "motor", 1, reverse=True),
                             OutputWire("L", "lamp", 4)), ())
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
