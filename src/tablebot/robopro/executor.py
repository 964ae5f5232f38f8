"""The ROBO Pro program as an executor of tables: generate it for a table and a matching rule, run it in
the element interpreter on recorded inputs, and read its decisions back in the engine's terms, so that it
can be compared tick for tick with every other executor."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

from tablebot.formats.inputs_csv import TickInput
from tablebot.machine import NO_ROW, compile_table
from tablebot.robopro.fit import plan
from tablebot.robopro.interpret import Program, Run
from tablebot.robopro.program import EXECUTE, EXIT, Rule, generate
from tablebot.table import Table


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
        found.append(Decision(
            event=sum(table.bit(name) for name in table.events if v["EV"] & p.bits[name]),
            row=v["ROW"] if (EXECUTE, EXIT) in tick.exits else NO_ROW,
            state=index_of[v["ST"]], timer=v["TM"], outputs=tuple(motors),
            counters=tuple(v.get(name, 0) for name in table.robot.counter_names)))
    return found
