"""The robots of a fleet as plain data: each one's seed, start, parameters and program variant, and the
variants' timers and counter loads. Light (no compiled code), so a worker can read a job before it compiles."""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    from tablebot.machine import Machine
    from tablebot.tables import RobotTables

Pose = tuple[float, float, float]  # x, y (m), heading (degrees)


@dataclass(frozen=True)
class RobotSpec:
    """One robot of a fleet: its seed, where it starts (None: the world's start), its ``[sim]``
    parameter overrides as ``((section, key, value), ...)`` (``("battery", "charge", 0.6)``: the battery)
    and which program variant of the fleet it runs (0: the table as it is)."""

    seed: int
    start: Pose | None = None
    params: tuple[tuple[str, str, float], ...] = ()
    variant: int = 0

    def overrides(self) -> dict[str, dict[str, Any]]:
        out: dict[str, dict[str, Any]] = {}
        for section, key, value in self.params:
            out.setdefault(section, {})[key] = value
        return out


@dataclass
class Variants:
    """Program variants: per variant every row's timer and counter loads (the rest of the table is shared); for a
    robot of several tables, every table's (:meth:`of_tables`: a table's rows, then 0 up to the longest's)."""

    timers: np.ndarray  # (V, rows) int64; several tables: (V, tables, most rows)
    loads: np.ndarray  # (V, rows, counters) int64; several tables: (V, tables, most rows, counters)

    @staticmethod
    def of_tables(tables: RobotTables) -> Variants:
        from tablebot.sim.physics.several import table_values

        return Variants(*table_values(tables))

    @staticmethod
    def of(machine: Machine) -> Variants:
        arrays = machine.arrays
        assert arrays is not None, "the compiled simulator needs a table of at most FLAT_BITS event columns"
        return Variants(arrays.timer[None, :].copy(), arrays.loads[None, :, :].copy())
