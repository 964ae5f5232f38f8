"""tablebot's engine and robot for the fischertechnik TXT 4.0, running on the controller itself with its
on-board ``fischertechnik`` package (the one ROBO Pro Coding programs use), so the robot keeps its safe
behaviour with no computer attached.

``tablebot export --to txt4`` copies this file into the program it writes and appends the compiled
table as ``TABLE``; it needs only the standard library (Python 3.7 or later) and ``fischertechnik``.
The tick rule is tablebot's (tablebot.engine), written out again here because the controller has no
tablebot; the tests prove the two equal tick for tick on random tables.

Not tried on a real TXT 4.0 (none was at hand). The ``fischertechnik`` calls are the ones Open Roberta's
TXT 4.0 generator emits (Txt4PythonVisitor) and real ROBO Pro Coding programs make (OliverBerger-ORBIS/
ORBIS-Modellfabrik, ``integrations/TXT-*/workspaces/*/lib/controller.py``); what they do is read from the
package's own sources (6.4.2, in leosdad/ft-rc-vehicle, folder ``fischertechnik/``). The tests run this
file against a stub written from those sources (tests/txt4_stub) and, when pointed at a checkout,
under harbaum/SofTXT.
"""

from __future__ import annotations

import collections
import contextlib
import threading
import time
from collections.abc import Callable
from typing import Any

# Exported, the program carries runtime_stop's code itself (below this file's): export drops this line.
from tablebot.hw.txt4.runtime_stop import Guard, Stop, Terminated

PWM_STEP = 64  # speed or lamp level 8 = PWM 512
BEHIND_LIMIT_S = 0.5  # the table's time may fall this far behind the wall clock within BEHIND_WINDOW_S,
BEHIND_WINDOW_S = 5.0  # else the robot stops rather than stretch the table's timers (as tablebot.loop.Pace)
TABLE: dict = {}  # the exported table (appended by ``tablebot export --to txt4``)


class Engine:
    """One tick of the table: timer and counters count down, events are the inputs read plus T and each
    counter at zero, the first row of the state whose required events are all present fires (with the
    robot file's match = "document", a tick with no event at all looks up no row)."""

    def __init__(self, table: dict) -> None:
        self.rows = table["rows"]  # per state: [index, required, next, timer, outputs, loads] (None: keep)
        self.input_mask, self.timer_bit = table["input_mask"], table["timer_bit"]
        self.counter_bits = table["counter_bits"]
        self.needs_event = table["match"] == "document"
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
        if not events and self.needs_event:  # the document: a row is looked up only if an event is detected
            return self.outputs
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


class Tables:
    """A robot of several tables (``table["tables"]``, each an :class:`Engine`'s data, the main one first) as one
    engine: the inputs read once, each table's cross-table events from the states at the start of the tick,
    each output and counter load from its one writer (tablebot.tables); ``event``, ``row``, ``state`` and
    ``timer`` are the main table's."""

    def __init__(self, table: dict) -> None:
        self.engines = [Engine(part) for part in table["tables"]]
        self.inputs, self.cross = table["table_inputs"], table["cross"]  # per table: (robot bit, table bit)s
        self.writers, self.counter_writers = table["writers"], table["counter_writers"]
        self.outputs = [0] * table["n_outputs"]

    def __getattr__(self, name: str) -> Any:  # tick, event, row, state, timer, counters: the main table's
        return getattr(self.engines[0], name)

    def step(self, mask: int, pulses: list | tuple = ()) -> list:
        states = [engine.state for engine in self.engines]  # the start of the tick, before any table fires
        for i, engine in enumerate(self.engines):  # zip(strict=) is newer than the controller's Python
            events = sum(bit for robot_bit, bit in self.inputs[i] if mask & robot_bit)
            for source, bits in self.cross[i]:
                events |= bits[states[source]]
            engine.step(events, pulses)
        self.outputs = [0 if w < 0 else self.engines[w].outputs[k] for k, w in enumerate(self.writers)]
        for c, w in self.counter_writers:  # a load is its writer's: every table then counts from it
            for engine in self.engines:
                engine.counters[c] = self.engines[w].counters[c]
        return self.outputs


def engine_for(table: dict) -> Any:
    """The engine of a table, or of a robot's several tables."""
    return Tables(table) if "tables" in table else Engine(table)


class Txt4Robot:
    """The table's inputs, motors, lamps and counters on this controller's terminals. ``stop`` may be
    called from another thread than ``read``/``write`` (a SIGTERM handled in the main thread)."""

    #: mode -> (the input factory's create call, the device's reading call), as ROBO Pro Coding emits them
    READERS = (
        ("switch", "create_mini_switch", "get_state"),
        ("phototransistor", "create_photo_transistor", "is_bright"),
        ("trail", "create_trail_follower", "get_state"),
        ("ultrasonic", "create_ultrasonic_distance_meter", "get_distance"),
        ("voltage", "create_color_sensor", "get_voltage"),
        ("resistance", "create_ntc_resistor", "get_resistance"),
    )

    def __init__(self, table: dict, factory: Any, motor_class: Any) -> None:
        self.table, self.motor_class = table, motor_class
        self.lock = threading.Lock()
        self.stopped = False
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
            if counter["motor"] is None:  # Txt4Counter: get_count() is the input's own count
                device = factory.counter_factory.create_counter(txt, counter["terminal"])
            else:  # Txt4EncodermotorCounter: get_count() is the motor's distance (never read it unset)
                device = factory.counter_factory.create_encodermotor_counter(txt, counter["terminal"])
                device.set_motor(self.motors[counter["motor"]])
            self.counters.append(device)
        factory.initialized()
        time.sleep(0.1)  # as ROBO Pro Coding programs do after initialized()
        self.counts = [device.get_count() for device in self.counters]
        self.carry = [0] * len(self.counters)  # pulses counted just before a motor restarted its count
        self.sent: list = [None] * table["n_outputs"]
        self.last_mask = 0

    def read(self) -> tuple:
        mask = 0
        for read, inp in self.inputs:
            if _reads(inp, read(), bool(self.last_mask & inp["bit"])):
                mask |= inp["bit"]
        self.last_mask = mask
        pulses = []
        for i in range(len(self.counters)):
            pulses.append(self.carry[i] + self._counted(i))
            self.carry[i] = 0
        return mask, pulses

    def _counted(self, i: int) -> int:
        """Pulses since counter ``i`` was last read. A motor's distance counts up from 0 again at each
        start, whichever way it turns, so a count below the last one is what came after a restart."""
        count = self.counters[i].get_count()
        last, self.counts[i] = self.counts[i], count
        return count - last if count >= last else count

    def write(self, outputs: list) -> None:
        """Only what changed is sent: a motor's speed and direction, a lamp's brightness."""
        with self.lock:
            if self.stopped:
                return
            for motor in self.table["motors"]:
                value = outputs[motor["output"]]
                if value != self.sent[motor["output"]]:
                    self.sent[motor["output"]] = value
                    self._drive(motor, -value if motor["reverse"] else value)
            for lamp in self.table["lamps"]:
                value = outputs[lamp["output"]]
                if value != self.sent[lamp["output"]]:
                    self.sent[lamp["output"]] = value
                    self.lamps[lamp["terminal"]].set_brightness(max(0, min(8, value)) * PWM_STEP)

    def _drive(self, motor: dict, speed: int) -> None:
        device = self.motors[motor["terminal"]]
        if speed == 0:
            device.stop()
            return
        for i, counter in enumerate(self.table["counters"]):
            if counter["motor"] == motor["terminal"]:  # its distance restarts at 0: keep what it counted
                self.carry[i] += self._counted(i)
                self.counts[i] = 0
        device.set_speed(min(8, abs(speed)) * PWM_STEP, self.motor_class.CCW if speed > 0 else self.motor_class.CW)
        device.start()

    def stop(self) -> None:
        """Every motor stopped, every lamp off; one failing call does not keep the others from happening.
        Waits briefly for a write in progress in another thread, then stops anyway."""
        got = self.lock.acquire(timeout=0.2)
        try:
            self.stopped = True
            for device in self.motors.values():
                with contextlib.suppress(Exception):
                    device.stop()
            for device in self.lamps.values():
                with contextlib.suppress(Exception):
                    device.set_brightness(0)
            self.sent = [None] * len(self.sent)
        finally:
            if got:
                self.lock.release()


def _reads(inp: dict, value: Any, was_on: bool) -> bool:
    """What the table reads for one input's value: a digital input's state (closed, lit, a light floor
    under a trail sensor) flipped by ``invert``; an analog value against ``below``/``above``, with
    hysteresis once on."""
    slack = inp.get("hysteresis", 0) if was_on else 0
    if inp["below"] is not None:
        return value < inp["below"] + slack
    if inp["above"] is not None:
        return value > inp["above"] - slack
    return bool(value) != inp["invert"]


def say(*words: object) -> None:
    """Print at once: a runner reading our output through a pipe or pty sees each line as it happens."""
    print(*words, flush=True)


def run(
    table: dict,
    robot: Any,
    ticks: int | None = None,
    now: Callable[[], float] = time.monotonic,
    sleep: Callable[[float], Any] | None = None,
    log: Callable[..., None] = say,
    stop: Stop | None = None,
) -> str:
    """Run the table until ``ticks`` (None: until stopped); the outputs are stopped on every way out.
    Ticks are paced on a fixed grid; a tick later than half a tick restarts the grid (counted as late); the
    table's time falling more than BEHIND_LIMIT_S behind the wall clock within BEHIND_WINDOW_S (one stall,
    or every tick a little too slow) ends the run. Returns why it ended."""
    stop = stop or Stop()
    pause = sleep or stop.requested.wait
    engine, tick_s = engine_for(table), table["tick_ms"] / 1000
    anchor, anchor_tick, late_ticks, reason = now(), 0, 0, "done"
    recent = collections.deque([(0, anchor)])  # (tick, when it started) over the last BEHIND_WINDOW_S
    try:
        while ticks is None or engine.tick < ticks:
            due, started = anchor + (engine.tick - anchor_tick) * tick_s, now()
            if due > started:
                pause(due - started)
                started = due
            if started - due > tick_s / 2:
                late_ticks += 1
                anchor, anchor_tick = started, engine.tick
            recent.append((engine.tick, started))
            while len(recent) > 1 and recent[1][1] <= started - BEHIND_WINDOW_S:
                recent.popleft()
            fell = started - recent[0][1] - (engine.tick - recent[0][0]) * tick_s
            if fell > BEHIND_LIMIT_S:
                reason = "behind"
                log(
                    f"tablebot: the table's time fell {fell:.2f} s behind the wall clock by tick {engine.tick}: "
                    "stopping rather than stretching the table's timers"
                )
                break
            if stop.requested.is_set():
                reason = stop.reason
                break
            mask, pulses = robot.read()
            robot.write(engine.step(mask, pulses))
    except KeyboardInterrupt:
        reason = "stopped"
    except (Terminated, SystemExit):  # SystemExit: the package's own SIGTERM handler (sys.exit) got there
        reason = "terminated"
    except BaseException:
        reason = "error"
        raise
    finally:
        stop.request(reason)  # from now on a signal only waits for this
        robot.stop()
        with contextlib.suppress(Exception):
            log(f"tablebot: {reason} after {engine.tick} ticks ({late_ticks} late); outputs off")
        stop.done.set()
    return reason


def main(table: dict | None = None) -> str:
    """On the controller: build the robot with the ``fischertechnik`` package and run until stopped."""
    table = TABLE if table is None else table
    import fischertechnik.factories as txt_factory  # installs its own SIGTERM handler (sys.exit) when imported
    from fischertechnik.controller.Motor import Motor

    say("tablebot: running", table["name"], "from", table["source"], "-", len(table["states"]), "states")
    stop = Stop()
    guard = Guard(stop)
    say(guard.install())
    try:
        guard.attach(Txt4Robot(table, txt_factory, Motor))
    except Terminated:
        say("tablebot: terminated while setting up; nothing was started")
        return "terminated"
    return run(table, guard.robot, stop=stop)
