"""The live serial controllers as executors (:mod:`tablebot.testing.harness`): the table runs on this computer
through ``loop.run`` (free-running, no waiting) with the controller's ``RobotIO`` over a real pseudo-terminal to
its emulator, which serves the case's inputs on the input terminals (and counts on the counters) and records
what reached the outputs. The lines report the engine's decisions with each output as the controller set it on
the wire, decoded here independently of the controller's own scaling, so the wiring, the scaling and the loop
are what is compared.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from tablebot.engine import Engine
from tablebot.engine.as_one import RobotEngine
from tablebot.formats.inputs_csv import TickInput
from tablebot.loop import RunEnd, SimulatedClock, TickBlock, run
from tablebot.machine import Machine
from tablebot.testing.harness import Case, Executor, Run, fits_controller, wired_for
from tablebot.testing.several_cases import SeveralCase, wired_robot

#: Ticks a controller runs of a case at most (each is an exchange over the pseudo-terminal).
SERIAL_TICKS = 1200
#: Silence that ends a run as link_lost. The differential runs test decisions, not timing: generous, so a
#: loaded machine (the emulator's thread starved for a second) does not fail them; it only bounds a hang.
LINK_TIMEOUT_S = 10.0


class _Record:
    """A sink keeping each tick's block."""

    def __init__(self) -> None:
        self.blocks: list[TickBlock] = []
        self.end_reason = ""

    def start(self, info: object) -> None:
        pass

    def block(self, block: TickBlock) -> None:
        self.blocks.append(block)

    def end(self, end: RunEnd) -> None:
        self.end_reason = end.reason


def _levels(terminal: str, values: list[int], step: int) -> int:
    """The signed level an output pair (``M2``: O3 forward, O4 backward) or a single output (``O5``) was set to."""
    index = int(terminal[1:]) - 1
    if terminal[0] == "O":
        return values[index] // step
    forward, backward = values[2 * index], values[2 * index + 1]
    return forward // step if forward else -(backward // step)


def _terminal_values(m: Machine, tick: TickInput) -> list[int]:
    """I1..I8 as a push-button on each table input reads (1 pressed)."""
    values = [0] * 8
    for name, bit in m.input_bits.items():
        values[int(name[1:]) - 1] = int(bool(tick.mask & bit))
    return values


def _lines(
    m: Machine, section: str, record: _Record, outputs: list[dict[str, int]], ticks: int, several: bool = False
) -> Run:
    """The engine's decisions per tick with each output as the wire carried it (``outputs[t]``: by terminal);
    ``several``: a robot of several tables, its main table's row as written and the other tables' fields."""
    if record.end_reason != "done" or len(record.blocks) != ticks or len(outputs) != ticks:
        raise AssertionError(
            f"the run ended {record.end_reason} after {len(record.blocks)} of {ticks} ticks, "
            f"{len(outputs)} exchanges carried outputs"
        )
    inputs, lines = [], []
    terminal_of = m.table.robot.sections[section]  # as wired_for wrote it: name -> terminal
    for t, block in enumerate(record.blocks):
        inputs.append(TickInput(int(block.masks[0]), tuple(int(p) for p in block.pulses[0])))
        row = None if block.rows[0] < 0 else int(block.rows[0])
        if several and row is not None:
            row = m.table.rows[row].as_written
        line: dict[str, Any] = {
            "tick": block.start,
            "event": int(block.events[0]),
            "row": row,
            "state": m.states[block.states[0]],
            "timer": int(block.timers[0]),
        }
        for name in m.output_names:
            line[name] = outputs[t][terminal_of[name]]
        line.update(zip(m.table.robot.counter_names, (int(c) for c in block.counters[0]), strict=True))
        if several:
            line.update({key: values[0] for key, values in block.extra.items() if "." in key})
        lines.append(line)
    return Run(inputs, lines)


def _robotx(case: Case, workdir: Path) -> Run:
    m = wired_for(case.machine.table, "robotx")
    return _robotx_run(m, Engine(m), list(case.inputs[:SERIAL_TICKS]))


def _robotx_several(case: SeveralCase, workdir: Path) -> Run:
    m = wired_robot(case.tables, "robotx")
    return _robotx_run(m, RobotEngine(case.tables), list(case.inputs[:SERIAL_TICKS]), several=True)


def _robotx_run(m: Machine, engine: Engine | RobotEngine, ticks: list[TickInput], several: bool = False) -> Run:
    """The ROBO TX over fish.X1 (``hw.robotx``) against ``testing.robotx_emulator``: exchange n (0: at open)
    answers tick n's inputs and the counters' running counts; exchange n + 1 carries tick n's duty (0..512)."""
    from tablebot.hw.robotx.controller import RobotxRobot
    from tablebot.hw.robotx.wiring import robotx_wiring
    from tablebot.testing.robotx_emulator import RobotxEmulator

    counts, running = [], [0, 0, 0, 0]  # C1..C4's running counts at each exchange
    for n, tick in enumerate(ticks):
        if n:  # the reply at open is the counters' baseline: tick 0 reads no pulses
            for k, pulses in enumerate(tick.pulses):
                running[k] += pulses
        counts.append(list(running))

    def script(n: int) -> tuple[list[int], list[int]]:
        if n >= len(ticks):
            return [0] * 8, counts[-1] if counts else [0] * 4
        return _terminal_values(m, ticks[n]), counts[n]

    record = _Record()
    with RobotxEmulator(script) as emulator:
        robot = RobotxRobot(robotx_wiring(m), emulator.device, link_timeout_s=LINK_TIMEOUT_S)
        robot.connect()
        run(engine, robot, clock=SimulatedClock(), sinks=[record], ticks=len(ticks), target="robotx")
        duties = [r.fields["duty"] for r in emulator.requests("exchange")]
    outputs = [
        {f"{kind}{i + 1}": _levels(f"{kind}{i + 1}", duty, 64) for kind in "MO" for i in range(8 if kind == "O" else 4)}
        for duty in duties[1 : len(ticks) + 1]
    ]
    return _lines(m, "robotx", record, outputs, len(ticks), several)


def _roboif(case: Case, workdir: Path) -> Run:
    m = wired_for(case.machine.table, "roboif")
    return _roboif_run(m, Engine(m), list(case.inputs[:SERIAL_TICKS]))


def _roboif_several(case: SeveralCase, workdir: Path) -> Run:
    m = wired_robot(case.tables, "roboif")
    return _roboif_run(m, RobotEngine(case.tables), list(case.inputs[:SERIAL_TICKS]), several=True)


def _roboif_run(m: Machine, engine: Engine | RobotEngine, ticks: list[TickInput], several: bool = False) -> Run:
    """The ROBO Interface (``hw.roboif``) against ``testing.roboif_emulator``: the exchange after open answers
    tick 0's inputs; each tick's outputs arrive as output bits and 3-bit PWM (level 1..8 as 0..7)."""
    from tablebot.hw.roboif.controller import RoboifRobot
    from tablebot.hw.roboif.wiring import roboif_wiring
    from tablebot.testing.roboif_emulator import RoboifEmulator

    def script(n: int) -> tuple[list[int], dict[str, int]]:
        return (_terminal_values(m, ticks[n]) if n < len(ticks) else [0] * 8), {}

    record = _Record()
    with RoboifEmulator(script) as emulator:
        robot = RoboifRobot(roboif_wiring(m), emulator.device, link_timeout_s=LINK_TIMEOUT_S)
        robot.connect()
        run(engine, robot, clock=SimulatedClock(), sinks=[record], ticks=len(ticks), target="roboif")
        exchanges = [(r.fields["outputs"], r.fields["pwm"]) for r in emulator.requests("exchange")]

    def level(bits: int, pwm: list[int], terminal: str) -> int:
        index = int(terminal[1:]) - 1
        if terminal[0] == "O":
            return pwm[index] + 1 if bits >> index & 1 else 0
        if bits >> (2 * index) & 1:
            return pwm[2 * index] + 1
        return -(pwm[2 * index + 1] + 1) if bits >> (2 * index + 1) & 1 else 0

    outputs = [
        {f"{kind}{i + 1}": level(bits, pwm, f"{kind}{i + 1}") for kind in "MO" for i in range(8 if kind == "O" else 4)}
        for bits, pwm in exchanges[1 : len(ticks) + 1]
    ]
    return _lines(m, "roboif", record, outputs, len(ticks), several)


SERIAL_EXECUTORS = (
    Executor(
        "ROBO TX",
        _robotx,
        fits=fits_controller,
        several=_robotx_several,
        what="run --on robotx://: loop.run with the ROBO TX over fish.X1 to its emulator on a pty",
    ),
    Executor(
        "ROBO Interface",
        _roboif,
        fits=lambda m: fits_controller(m, counters=0),
        several=_roboif_several,
        what="run --on roboif://: loop.run with the ROBO Interface to its emulator on a pty",
    ),
)
