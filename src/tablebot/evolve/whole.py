"""Evolving one table of a robot of several (``evolve --table NAME``, issue 36 §2): the candidates are that
table's, and everything that judges one sees the whole robot, the other tables as they are. A candidate is
proved with the others over their product (:mod:`tablebot.analysis.prove_product`; a property may name any
table's states), its repair's counterexamples replay every table (:class:`tablebot.engine.several.Several`),
and the fleet runs every table (:meth:`tablebot.evolve.evaluate.Evaluator.several_jobs`).

A property only other tables decide (the evolved one is not among the tables its tables read from,
:meth:`~tablebot.tables.RobotTables.influence`) holds or fails alike for every candidate: it is proved once,
and when it fails in the robot as it is, no table evolve could find keeps it, which is said before the search
starts (:func:`tablebot.evolve.proofs.refuse_fixed`).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

from tablebot.diagnostics import fail
from tablebot.i18n import N_
from tablebot.machine import NO_ROW, Machine
from tablebot.robot import StateId
from tablebot.table import Table
from tablebot.tables import RobotTables

if TYPE_CHECKING:
    from tablebot.analysis.properties import Property
    from tablebot.formats.inputs_csv import TickInput

__all__ = ["Tick", "Whole", "choose"]

#: One tick of a replayed counterexample as a repair reads it: the evolved table's state before the tick, the
#: inputs that read 1, and the index of the evolved table's row that fired (None: none).
Tick = tuple[StateId, set[str], int | None]


@dataclass(frozen=True, eq=False)
class Whole:
    """A robot of several tables (``tables``, as its files are) whose table ``index`` evolves."""

    tables: RobotTables
    index: int

    @property
    def name(self) -> str:
        return self.tables.names[self.index]

    @property
    def table(self) -> Table:
        """The evolved table as it starts."""
        return self.tables.tables[self.index]

    @property
    def others(self) -> tuple[str, ...]:
        return tuple(n for k, n in enumerate(self.tables.names) if k != self.index)

    def robot(self, machine: Machine) -> RobotTables:
        """The robot with the candidate (``machine``, compiled from a table of the evolved table's columns and
        states) in the evolved table's place. Evolution changes no column and no state, so the checks
        :func:`tablebot.tables.load_tables` makes of a robot (cross-table columns name states their table has, one
        writer per output) hold as they held for the robot's own files."""
        k = self.index
        return RobotTables(
            tuple(machine.table if i == k else t for i, t in enumerate(self.tables.tables)),
            tuple(machine if i == k else m for i, m in enumerate(self.tables.machines)),
        )

    def depends(self, prop: Property) -> bool:
        """Whether a candidate can change what ``prop`` sees (the evolved table is one its tables read from)."""
        return self.index in self.tables.influence(prop.tables)

    def ticks(self, machine: Machine, inputs: Sequence[TickInput]) -> list[Tick]:
        """A counterexample replayed on the whole robot, as the evolved table lives through it."""
        from tablebot.engine.several import Several

        robot = Several(self.robot(machine))
        mine = robot.engines[self.index]
        bits = robot.tables.input_bits
        out: list[Tick] = []
        for tick in inputs:
            before = machine.states[mine.state]
            robot.step(tick.mask, tick.pulses)
            pressed = {name for name, bit in bits.items() if tick.mask & bit}
            out.append((before, pressed, None if mine.row == NO_ROW else mine.row))
        return out

    def watched(self, prop: Property) -> set[str]:
        """The inputs ``prop`` reads (its bits are in the robot-wide layout)."""
        return {name for name, bit in self.tables.input_bits.items() if bit & prop.watch}


def choose(tables: RobotTables | None, name: str | None) -> Whole | None:
    """``--table NAME`` checked against the robot: the table evolved (default: the main one), or None for a
    robot of one table without ``--table``."""
    if tables is None:
        if name is not None:
            raise fail(
                "--table",
                N_("--table {name}: the robot has one table, so there is no other to name", name=name),
                N_("leave --table out (it names one of the tables a robot file's [tables] lists)"),
            )
        return None
    if name is None:
        return Whole(tables, 0)
    if name not in tables.names:
        raise fail(
            "--table",
            N_("--table {name}: the robot has no table of that name", name=name),
            N_("name one of its tables: {names}", names=", ".join(tables.names)),
        )
    return Whole(tables, tables.names.index(name))
