"""The ROBO Pro program as an executor of tables: generate it for a table and a matching rule, run it in
the element interpreter on recorded inputs, and read its decisions back in the engine's terms, so that it
can be compared tick for tick with every other executor."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from tablebot.formats.inputs_csv import TickInput
from tablebot.machine import NO_ROW, compile_table
from tablebot.robopro.fit import Plan, plan
from tablebot.robopro.interpret import Program, Run, Tick
from tablebot.robopro.program import EXECUTE, EXIT, Rule, generate
from tablebot.table import Table

if TYPE_CHECKING:
    from tablebot.tables import RobotTables


@dataclass(frozen=True)
class Decision:
    """One tick as the engine reports it: the event mask (table event columns), the fired row (``NO_ROW``:
    none), the state index, the timer, the outputs (motor speeds, signed, then lamp levels) and the counters."""

    event: int
    row: int
    state: int
    timer: int
    outputs: tuple[int, ...]
    counters: tuple[int, ...]


def run(table: Table, inputs: Sequence[TickInput], rule: Rule | None = None) -> list[Decision]:
    """Run ``table``'s generated program on ``inputs`` (the input mask and the counters' pulses per tick), under
    ``rule`` (default: the table's own, the robot file's ``match``)."""
    p = plan(table, rule)
    index_of = {p.numbers[s]: i for i, s in enumerate(compile_table(table).states)}
    machine = Run(Program(generate(table, rule)))
    counts = dict.fromkeys(p.wiring.counters.values(), 0)
    found = []
    for given in inputs:
        digital = {}
        for name, (terminal, active) in p.wiring.inputs.items():
            present = name in table.events and bool(given.mask & table.bit(name))
            digital[terminal] = int(present) if active else int(not present)
        for counter, pulses in zip(p.wiring.counters.values(), given.pulses, strict=True):
            counts[counter] += pulses
        tick = machine.tick(digital, counts)
        v = tick.variables
        motors = []
        for motor in table.robot.motors:
            output, forward = p.wiring.motors[motor]
            command, speed = tick.motors[output]
            motors.append(speed if command == forward else -speed)
        motors += [tick.lamps[p.wiring.lamps[lamp]] for lamp in table.robot.lamps]
        found.append(
            Decision(
                event=sum(table.bit(name) for name in table.events if v["EV"] & p.bits[name]),
                row=v["ROW"] if (EXECUTE, EXIT) in tick.exits else NO_ROW,
                state=index_of[v["ST"]],
                timer=v["TM"],
                outputs=tuple(motors),
                counters=tuple(v.get(name, 0) for name in table.robot.counter_names),
            )
        )
    return found


def run_several(tables: RobotTables, inputs: Sequence[TickInput], seed: int | None = None) -> list[dict[str, Any]]:
    """Run the program of a robot of several tables (:func:`tablebot.robopro.processes.generate_several`) on
    ``inputs`` (the robot-wide layout of :attr:`RobotTables.input_bits`), its processes switched at random after
    any element when ``seed`` is given; one trace line per tick, keyed as :func:`tablebot.replay.record_several`."""
    from tablebot.robopro.processes import generate_several, plans

    ps = plans(tables)
    wired = ps[0].wiring
    machine = Run(Program(generate_several(tables)), seed)
    counts = dict.fromkeys(wired.counters.values(), 0)
    robot = tables.robot
    lines = []
    for tick, given in enumerate(inputs):
        digital = {
            terminal: int(bool(given.mask & bit)) if active else int(not given.mask & bit)
            for name, bit in tables.input_bits.items()
            for terminal, active in [wired.inputs[name]]
        }
        for counter, pulses in zip(wired.counters.values(), given.pulses, strict=True):
            counts[counter] += pulses
        done = machine.tick(digital, counts)
        line: dict[str, Any] = {"tick": tick}
        for i, p in enumerate(ps):
            line.update(_table_line(p, done, "" if i == 0 else f"{p.table.name}."))
            if i == 0:
                for motor in robot.motors:
                    output, forward = wired.motors[motor]
                    command, speed = done.motors.get(output, (forward, 0))
                    line[motor] = speed if command == forward else -speed
                line.update({lamp: done.lamps.get(wired.lamps[lamp], 0) for lamp in robot.lamps})
                line.update({name: done.variables.get(name, 0) for name in robot.counter_names})
        lines.append(line)
    return lines


def _table_line(p: Plan, done: Tick, key: str) -> dict[str, Any]:
    """One table's event, row (as written), state and timer at the end of a tick."""
    table, v = p.table, done.variables
    name = f"{table.name} "
    states = {number: state for state, number in p.numbers.items()}
    fired = (f"{name}{EXECUTE}", EXIT) in done.exits
    return {
        f"{key}event": sum(table.bit(e) for e in table.events if v[f"{name}EV"] & p.bits[e]),
        f"{key}row": table.rows[v[f"{name}ROW"]].as_written if fired else None,
        f"{key}state": states[v[f"{name}ST"]],
        f"{key}timer": v[f"{name}TM"],
    }
