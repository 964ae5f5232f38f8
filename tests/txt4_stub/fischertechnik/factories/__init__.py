"""``fischertechnik.factories`` (stub), following the real package 6.4.2 (leosdad/ft-rc-vehicle):

- ``factories/__init__.py``: on import, ``signal.signal(SIGTERM, onSignal)`` where ``onSignal`` calls
  ``sys.exit()``, skipped on ``ValueError`` outside the main thread (lines 48-54); ``atexit.register(
  onDestroy)`` (line 46); ``init()`` creates the controller factory (lines 32-35).
- ``controller/txt4/Txt4Controller.py``: the controller registers ``cleanup`` with ``atexit`` when it is
  made: every output off, every motor stopped, every counter reset.
- ``controller/Motor.py``, ``Output.py``, ``Counter.py``: ``__del__`` stops the motor, switches the output
  off, resets the counter. ``set_speed(speed, direction)`` refuses |speed| > 512 and drives speed *
  direction; ``set_brightness`` refuses values outside 0..512.
- ``controller/txt4/Txt4EncodermotorCounter.py``: ``get_count()`` is the motor's ``motor_distance`` once
  ``set_motor`` was called, the counter's own ``distance`` after ``set_motor(None)``, and an
  AttributeError before (``self.motor`` is never set otherwise).

Only the native ``ft`` layer is scripted. What ``motor_distance`` does is not in the package's Python:
fischertechnik's own FTS program (OliverBerger-ORBIS/ORBIS-Modellfabrik, ``integrations/TXT-FTS/
workspaces/fts_main/lib/line_follower.py``) says "Changing speed or direction resets the motor counters"
and adds each count up before restarting, and ``integrations/TXT-DPS/.../lib/Axes1Ref.py`` subtracts the
count for a move backwards: so here a motor's distance is the pulses on its own counter input (Mn on Cn)
since its last ``start()``, counted up whichever way it turns.

``TABLEBOT_STUB_SCRIPT`` names a JSON file {"inputs": [[I1..I8] per tick], "pulses": [[C1..C4] per tick]}
(pulses arriving on each counter input during that tick); a tick begins when the program reads its
first input device. When the script runs out the stub sends SIGTERM to its own process, as ROBO Pro
Coding's stop would. Every call is appended to the JSON Lines file ``TABLEBOT_STUB_LOG`` with its tick and
phase ("run", or "exit" once the controller's atexit cleanup began).
"""

from __future__ import annotations

import atexit
import json
import os
import signal
import sys

with open(os.environ["TABLEBOT_STUB_SCRIPT"], encoding="utf-8") as _f:
    _SCRIPT = json.load(_f)
_LOG = open(os.environ["TABLEBOT_STUB_LOG"], "a", encoding="utf-8")  # noqa: SIM115 - open for the process's life
_state: dict = {"tick": -1, "first": None, "initialized": False, "phase": "run"}
_counted = [0, 0, 0, 0]  # ft layer: pulses on C1..C4 since each counter's reset
_distance = [0, 0, 0, 0]  # ft layer: motor Mn's distance, pulses on Cn since Mn's last start

controller_factory = None
counter_factory = None
input_factory = None
output_factory = None
motor_factory = None


def _log(device: str, call: str, *args: object) -> None:
    try:
        _LOG.write(
            json.dumps(
                {"tick": _state["tick"], "phase": _state["phase"], "device": device, "call": call, "args": list(args)}
            )
            + "\n"
        )
        _LOG.flush()
    except (ValueError, AttributeError, TypeError):  # a __del__ during interpreter teardown
        pass


def _row(key: str) -> list:
    rows = _SCRIPT.get(key) or [[0, 0, 0, 0]]
    return rows[min(max(_state["tick"], 0), len(rows) - 1)]


def _next_tick() -> None:
    _state["tick"] += 1
    if _state["tick"] >= len(_SCRIPT["inputs"]):
        _log("stub", "script ran out: SIGTERM")
        os.kill(os.getpid(), signal.SIGTERM)
        return
    for n, pulses in enumerate(_row("pulses")):
        _counted[n] += pulses
        _distance[n] += pulses


def onDestroy() -> None:  # the real name
    _log("factory", "onDestroy")


atexit.register(onDestroy)


def onSignal(*args: object) -> None:  # the real name
    sys.exit()


try:  # noqa: SIM105 - as the real package has it
    signal.signal(signal.SIGTERM, onSignal)
except ValueError:  # not the main thread
    pass


class _Controller:
    def __init__(self) -> None:
        self._output: list = [None] * 8
        self._motor: list = [None] * 4
        self._counter: list = [None] * 4
        atexit.register(self.cleanup)

    def cleanup(self, *args: object) -> None:
        _state["phase"] = "exit"
        for output in self._output:
            if output is not None:
                output.off()
        for motor in self._motor:
            if motor is not None:
                motor.stop()
        for counter in self._counter:
            if counter is not None:
                counter.reset()


class _Input:
    def __init__(self, controller: _Controller, terminal: int) -> None:
        self.terminal = terminal
        if _state["first"] is None:
            _state["first"] = self

    def get_state(self) -> int:
        assert _state["initialized"], "read before txt_factory.initialized()"
        if _state["first"] is self:
            _next_tick()
        return _row("inputs")[self.terminal - 1]


class _PhotoTransistor(_Input):
    def is_dark(self) -> bool:
        return self.get_state() == 0

    def is_bright(self) -> bool:
        return self.get_state() == 1


class _Ultrasonic(_Input):
    def get_distance(self) -> int:
        return self.get_state()


class _ColorSensor(_Input):
    def get_voltage(self) -> int:
        return self.get_state()


class _NtcResistor(_Input):
    def get_resistance(self) -> int:
        return self.get_state()


class _InputFactory:
    def create_mini_switch(self, controller: _Controller, terminal: int) -> _Input:
        return _Input(controller, terminal)

    def create_trail_follower(self, controller: _Controller, terminal: int) -> _Input:
        return _Input(controller, terminal)

    def create_photo_transistor(self, controller: _Controller, terminal: int) -> _PhotoTransistor:
        return _PhotoTransistor(controller, terminal)

    def create_ultrasonic_distance_meter(self, controller: _Controller, terminal: int) -> _Ultrasonic:
        return _Ultrasonic(controller, terminal)

    def create_color_sensor(self, controller: _Controller, terminal: int) -> _ColorSensor:
        return _ColorSensor(controller, terminal)

    def create_ntc_resistor(self, controller: _Controller, terminal: int) -> _NtcResistor:
        return _NtcResistor(controller, terminal)


class _Motor:
    def __init__(self, controller: _Controller, terminal: int, encoder: bool) -> None:
        self.terminal, self.name = terminal, f"M{terminal}"
        controller._motor[terminal - 1] = self
        _log(self.name, "create_encodermotor" if encoder else "create_motor")

    def __del__(self) -> None:
        self.stop()

    def set_speed(self, speed: int, direction: int = 1) -> None:
        if speed < -512 or speed > 512:
            raise ValueError("Speed must be >=-512 and <=512")
        _log(self.name, "set_speed", speed, direction)

    def start(self) -> None:
        _distance[self.terminal - 1] = 0
        _log(self.name, "start")

    def stop(self) -> None:
        _log(self.name, "stop")


class _MotorFactory:
    def create_motor(self, controller: _Controller, terminal: int) -> _Motor:
        return _Motor(controller, terminal, False)

    def create_encodermotor(self, controller: _Controller, terminal: int) -> _Motor:
        return _Motor(controller, terminal, True)


class _Led:
    def __init__(self, controller: _Controller, terminal: int) -> None:
        self.name = f"O{terminal}"
        controller._output[terminal - 1] = self

    def __del__(self) -> None:
        self.off()

    def set_brightness(self, brightness: int) -> None:
        if brightness < 0 or brightness > 512:
            raise ValueError("Value must be >0 and <=512")
        _log(self.name, "set_brightness", brightness)

    def off(self) -> None:
        _log(self.name, "off")


class _OutputFactory:
    def create_led(self, controller: _Controller, terminal: int) -> _Led:
        return _Led(controller, terminal)


class _Counter:
    def __init__(self, controller: _Controller, terminal: int) -> None:
        self.terminal, self.name = terminal, f"C{terminal}"
        controller._counter[terminal - 1] = self

    def __del__(self) -> None:
        self.reset()

    def get_count(self) -> int:
        return _counted[self.terminal - 1]

    def reset(self) -> None:
        _counted[self.terminal - 1] = 0
        _log(self.name, "reset")


class _EncodermotorCounter(_Counter):
    def get_count(self) -> int:
        if self.motor is not None:  # AttributeError unless set_motor() was called, as in the real class
            return _distance[self.motor.terminal - 1]
        return super().get_count()

    def set_motor(self, motor: _Motor | None) -> None:
        self.motor = motor
        _log(self.name, "set_motor", None if motor is None else motor.name)


class _CounterFactory:
    def create_counter(self, controller: _Controller, terminal: int) -> _Counter:
        return _Counter(controller, terminal)

    def create_encodermotor_counter(self, controller: _Controller, terminal: int) -> _EncodermotorCounter:
        return _EncodermotorCounter(controller, terminal)


class _ControllerFactory:
    def create_graphical_controller(self, ext: int = 0) -> _Controller:
        return _Controller()


def init() -> None:
    global controller_factory
    _log("factory", "init")
    controller_factory = _ControllerFactory()


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
