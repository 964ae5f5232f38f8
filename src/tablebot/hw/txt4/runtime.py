"""tablebot's engine and robot for the fischertechnik TXT 4.0, running on the controller itself with its
on-board ``fischertechnik`` package (the one ROBO Pro Coding programs use), so the robot keeps its safe
behaviour with no computer attached.

``tablebot export --to txt4`` copies this file into the program it writes and appends the compiled
table as ``TABLE``; it needs only the standard library (Python 3.7 or later) and ``fischertechnik``.
The tick rule is tablebot's (tablebot.engine), written out again here because the controller has no
tablebot; the tests prove the two equal tick for tick on random tables.

Not tried on a real TXT 4.0 (none was at hand): the ``fischertechnik`` calls are the ones Open Roberta's
TXT 4.0 generator emits (Txt4PythonVisitor); the tests run this file against a stub of exactly those calls.
"""

from __future__ import annotations

import contextlib
import signal
import time
from collections.abc import Callable
from typing import Any

PWM_STEP = 64  # speed or lamp level 8 = PWM 512
BEHIND_LIMIT_S = 0.5  # a tick this late stops the robot rather than stretch the table's timers
TABLE: dict = {}  # the exported table (appended by ``tablebot export --to txt4``)


class Engine:
    """One tick of the table: timer and counters count down, events are the inputs read plus T and each
    counter at zero, the first row of the state whose required events are all present fires."""

    def __init__(self, table: dict):
        self.rows = table["rows"]  # per state: [index, required, next, timer, outputs, loads] (None: keep)
        self.input_mask, self.timer_bit = table["input_mask"], table["timer_bit"]
        self.counter_bits = table["counter_bits"]
        self.state, self.timer = table["initial_state"], table["initial_timer"]
        self.counters = [0] * len(self.counter_bits)
        self.outputs = [0] * table["n_outputs"]
        self.tick, self.event, self.row = 0, 0, -1

    def step(self, mask: int, pulses: list | tuple = ()) -> list:
        events = mask & self.input_mask
        if self.tick:
            if self.timer:
                self.timer -= 1
            for i in range(len(pulses)):
                self.counters[i] = max(0, self.counters[i] - pulses[i])
        self.tick += 1
        if not self.timer:
            events |= self.timer_bit
        for i in range(len(self.counter_bits)):
            if self.counters[i] == 0:
                events |= self.counter_bits[i]
        self.event, self.row = events, -1
        for index, required, following, timer, outputs, loads in self.rows[self.state]:
            if required & events == required:
                self.row = index
                for k in range(len(outputs)):
                    if outputs[k] is not None:
                        self.outputs[k] = outputs[k]
                for k in range(len(loads)):
                    if loads[k] is not None:
                        self.counters[k] = loads[k]
                self.timer, self.state = timer, following
                break
        return self.outputs


class Txt4Robot:
    """The table's inputs, motors, lamps and counters on this controller's terminals."""

    #: mode -> (the input factory's create call, the device's reading call), as Open Roberta emits them
    READERS = (("switch", "create_mini_switch", "get_state"),
               ("phototransistor", "create_photo_transistor", "is_bright"),
               ("ultrasonic", "create_ultrasonic_distance_meter", "get_distance"),
               ("voltage", "create_color_sensor", "get_voltage"),
               ("resistance", "create_ntc_resistor", "get_resistance"))

    def __init__(self, table: dict, factory: Any, motor_class: Any):
        self.table, self.motor_class = table, motor_class
        factory.init()
        factory.init_input_factory()
        if table["lamps"]:
            factory.init_output_factory()
        if table["motors"]:
            factory.init_motor_factory()
        if table["counters"]:
            factory.init_counter_factory()
        txt = factory.controller_factory.create_graphical_controller()
        self.inputs = []
        for inp in table["inputs"]:
            create, read = next((c, r) for mode, c, r in self.READERS if mode == inp["mode"])
            self.inputs.append((getattr(getattr(factory.input_factory, create)(txt, inp["terminal"]), read), inp))
        self.motors = {}
        for motor in table["motors"]:
            motors = factory.motor_factory
            create = motors.create_encodermotor if motor["encoder"] else motors.create_motor
            self.motors[motor["terminal"]] = create(txt, motor["terminal"])
        self.lamps = {}
        for lamp in table["lamps"]:
            self.lamps[lamp["terminal"]] = factory.output_factory.create_led(txt, lamp["terminal"])
        self.counters = []
        for counter in table["counters"]:
            device = factory.counter_factory.create_encodermotor_counter(txt, counter["terminal"])
            if counter["motor"] is not None:
                device.set_motor(self.motors[counter["motor"]])
            self.counters.append(device)
        factory.initialized()
        time.sleep(0.1)  # as ROBO Pro Coding programs do after initialized()
        self.counts = [device.get_count() for device in self.counters]
        self.sent: list = [None] * table["n_outputs"]
        self.last_mask = 0

    def read(self) -> tuple:
        mask = 0
        for read, inp in self.inputs:
            value = read()
            slack = inp.get("hysteresis", 0) if self.last_mask & inp["bit"] else 0  # once on, stays on longer
            if inp["below"] is not None:
                on = value < inp["below"] + slack
            elif inp["above"] is not None:
                on = value > inp["above"] - slack
            else:
                on = bool(value) != inp["invert"]
            if on:
                mask |= inp["bit"]
        self.last_mask = mask
        pulses = []
        for i in range(len(self.counters)):
            count = self.counters[i].get_count()
            pulses.append(max(0, count - self.counts[i]))  # a count that went back was reset: no pulses
            self.counts[i] = count
        return mask, pulses

    def write(self, outputs: list) -> None:
        """Only what changed is sent: a motor's speed and direction, a lamp's brightness."""
        for motor in self.table["motors"]:
            value = outputs[motor["output"]]
            if value == self.sent[motor["output"]]:
                continue
            self.sent[motor["output"]] = value
            device = self.motors[motor["terminal"]]
            speed = -value if motor["reverse"] else value
            if speed == 0:
                device.stop()
                continue
            device.set_speed(min(8, abs(speed)) * PWM_STEP, self.motor_class.CCW if speed > 0 else self.motor_class.CW)
            device.start()
        for lamp in self.table["lamps"]:
            value = outputs[lamp["output"]]
            if value != self.sent[lamp["output"]]:
                self.sent[lamp["output"]] = value
                self.lamps[lamp["terminal"]].set_brightness(max(0, min(8, value)) * PWM_STEP)

    def stop(self) -> None:
        """Every motor stopped, every lamp off; one failing call does not keep the others from happening."""
        for device in self.motors.values():
            with contextlib.suppress(Exception):
                device.stop()
        for device in self.lamps.values():
            with contextlib.suppress(Exception):
                device.set_brightness(0)
        self.sent = [None] * len(self.sent)


class Terminated(Exception):
    """SIGTERM (ROBO Pro Coding's stop, or ``DELETE /api/v1/stop``) arrived."""


def run(table: dict, robot: Txt4Robot, ticks: int | None = None, now: Callable[[], float] = time.monotonic,
        sleep: Callable[[float], None] = time.sleep, log: Callable[..., None] = print) -> str:
    """Run the table until ``ticks`` (None: until stopped); the outputs are stopped on every way out.
    Ticks are paced on a fixed grid; a tick later than half a tick restarts the grid (counted as late),
    one later than BEHIND_LIMIT_S ends the run. Returns why it ended."""
    engine, tick_s = Engine(table), table["tick_ms"] / 1000
    anchor, anchor_tick, late_ticks, reason = now(), 0, 0, "done"
    try:
        while ticks is None or engine.tick < ticks:
            ahead = anchor + (engine.tick - anchor_tick) * tick_s - now()
            if ahead > 0:
                sleep(ahead)
            elif -ahead > tick_s / 2:
                late_ticks += 1
                if -ahead > BEHIND_LIMIT_S:
                    reason = "behind"
                    log(f"tablebot: tick {engine.tick} started {-1000 * ahead:.0f} ms late: stopping rather than "
                        "stretching the table's timers")
                    break
                anchor, anchor_tick = now(), engine.tick
            mask, pulses = robot.read()
            robot.write(engine.step(mask, pulses))
    except KeyboardInterrupt:
        reason = "stopped"
    except Terminated:
        reason = "terminated"
    finally:
        robot.stop()
    log(f"tablebot: {reason} after {engine.tick} ticks ({late_ticks} late); outputs off")
    return reason


def main(table: dict | None = None) -> str:
    """On the controller: build the robot with the ``fischertechnik`` package and run until stopped."""
    table = TABLE if table is None else table

    def terminate(signum: int, frame: object) -> None:
        raise Terminated()

    with contextlib.suppress(ValueError):  # not the main thread (a runner that starts programs in a thread)
        signal.signal(signal.SIGTERM, terminate)
    import fischertechnik.factories as txt_factory
    from fischertechnik.controller.Motor import Motor

    print("tablebot: running", table["name"], "from", table["source"], "-", len(table["states"]), "states")
    return run(table, Txt4Robot(table, txt_factory, Motor))
