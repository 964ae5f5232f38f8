"""``fischertechnik.factories`` as the exported program uses it (stub).

``TABLEBOT_STUB_SCRIPT`` names a JSON file {"inputs": [[I1..I8] per tick], "counts": [[C1..C4] per tick]};
a tick begins when the program reads its first input device. When the script runs out the stub sends
SIGTERM to its own process, as ROBO Pro Coding's stop would. Every call is appended to the JSON Lines
file ``TABLEBOT_STUB_LOG`` with the tick it happened in.
"""

from __future__ import annotations

import json
import os
import signal
import sys

with open(os.environ["TABLEBOT_STUB_SCRIPT"], encoding="utf-8") as _f:
    _SCRIPT = json.load(_f)
_LOG = open(os.environ["TABLEBOT_STUB_LOG"], "a", encoding="utf-8")  # noqa: SIM115 - open for the process's life
_state = {"tick": -1, "first": None, "initialized": False}


def _log(device: str, call: str, *args: object) -> None:
    _LOG.write(json.dumps({"tick": _state["tick"], "device": device, "call": call, "args": list(args)}) + "\n")
    _LOG.flush()


def _row(key: str) -> list:
    rows = _SCRIPT[key]
    return rows[min(max(_state["tick"], 0), len(rows) - 1)]


class _Controller:
    pass


class _Input:
    def __init__(self, terminal: int, kind: str):
        self.terminal, self.kind = terminal, kind
        if _state["first"] is None:
            _state["first"] = self

    def _value(self) -> int:
        assert _state["initialized"], "read before txt_factory.initialized()"
        if _state["first"] is self:
            _state["tick"] += 1
            if _state["tick"] >= len(_SCRIPT["inputs"]):
                _log("stub", "script ran out: SIGTERM")
                os.kill(os.getpid(), signal.SIGTERM)
        return _row("inputs")[self.terminal - 1]


class _MiniSwitch(_Input):
    def get_state(self) -> int:
        return self._value()


class _PhotoTransistor(_Input):
    def is_bright(self) -> bool:
        return bool(self._value())


class _Ultrasonic(_Input):
    def get_distance(self) -> int:
        return self._value()


class _ColorSensor(_Input):
    def get_voltage(self) -> int:
        return self._value()


class _NtcResistor(_Input):
    def get_resistance(self) -> int:
        return self._value()


class _InputFactory:
    def create_mini_switch(self, controller: _Controller, terminal: int) -> _MiniSwitch:
        return _MiniSwitch(terminal, "switch")

    def create_photo_transistor(self, controller: _Controller, terminal: int) -> _PhotoTransistor:
        return _PhotoTransistor(terminal, "phototransistor")

    def create_ultrasonic_distance_meter(self, controller: _Controller, terminal: int) -> _Ultrasonic:
        return _Ultrasonic(terminal, "ultrasonic")

    def create_color_sensor(self, controller: _Controller, terminal: int) -> _ColorSensor:
        return _ColorSensor(terminal, "voltage")

    def create_ntc_resistor(self, controller: _Controller, terminal: int) -> _NtcResistor:
        return _NtcResistor(terminal, "resistance")


class _Motor:
    def __init__(self, terminal: int, encoder: bool):
        self.name = f"M{terminal}"
        _log(self.name, "create_encodermotor" if encoder else "create_motor")

    def set_speed(self, speed: int, direction: str) -> None:
        assert 0 <= speed <= 512 and direction in ("CW", "CCW"), (speed, direction)
        _log(self.name, "set_speed", speed, direction)

    def start(self) -> None:
        _log(self.name, "start")

    def stop(self) -> None:
        _log(self.name, "stop")


class _MotorFactory:
    def create_motor(self, controller: _Controller, terminal: int) -> _Motor:
        return _Motor(terminal, False)

    def create_encodermotor(self, controller: _Controller, terminal: int) -> _Motor:
        return _Motor(terminal, True)


class _Led:
    def __init__(self, terminal: int):
        self.name = f"O{terminal}"

    def set_brightness(self, brightness: int) -> None:
        assert 0 <= brightness <= 512, brightness
        _log(self.name, "set_brightness", brightness)


class _OutputFactory:
    def create_led(self, controller: _Controller, terminal: int) -> _Led:
        return _Led(terminal)


class _Counter:
    def __init__(self, terminal: int):
        self.terminal = terminal

    def set_motor(self, motor: _Motor) -> None:
        _log(f"C{self.terminal}", "set_motor", motor.name)

    def get_count(self) -> int:
        return _row("counts")[self.terminal - 1]


class _CounterFactory:
    def create_encodermotor_counter(self, controller: _Controller, terminal: int) -> _Counter:
        return _Counter(terminal)


class _ControllerFactory:
    def create_graphical_controller(self) -> _Controller:
        return _Controller()


controller_factory = _ControllerFactory()


def init() -> None:
    _log("factory", "init")


def init_input_factory() -> None:
    global input_factory
    input_factory = _InputFactory()


def init_output_factory() -> None:
    global output_factory
    output_factory = _OutputFactory()


def init_motor_factory() -> None:
    global motor_factory
    motor_factory = _MotorFactory()


def init_counter_factory() -> None:
    global counter_factory
    counter_factory = _CounterFactory()


def initialized() -> None:
    _state["initialized"] = True
    _log("factory", "initialized", sorted(m for m in sys.modules if m.split(".")[0] in ("numpy", "tablebot")))
