"""Repeated runs of one table over battery charges and seeds: how far a robot turns (the document's lesson).

Used by ``benchmarks/turn_drift.py`` and its tests: a timed turn shrinks as the battery drains, a turn
counted in encoder pulses does not.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from tablebot.formats.table_read import load_table
from tablebot.machine import compile_table
from tablebot.sim import columns as L
from tablebot.sim.model.scene import prepare, robot_layer
from tablebot.sim.model.world import World, parse_world
from tablebot.sim.runner import simulate
from tablebot.tomlfile import Source

#: An empty room with the robot in the middle: nothing to bump into while it turns.
OPEN_ROOM = """\
name = "open room"
[arena]
walls = [[0, 0], [2, 0], [2, 2], [0, 2]]
[start]
at = [1, 1]
heading = 90
"""


@dataclass(frozen=True)
class Turn:
    charge: float  # battery state of charge at the start, 0..1
    seed: int
    degrees: float  # heading change once the robot has come to rest (counter-clockwise positive)
    volts: float  # battery volts under load while it turned


def open_room() -> World:
    return parse_world(Source.parse("<open room>", OPEN_ROOM))


def turns(
    table_path: Path, charges: list[float], seeds: list[int], seconds: float = 6.0, world: World | None = None
) -> list[Turn]:
    """Run ``table_path`` once per (charge, seed) and measure how far the robot turned."""
    table = load_table(table_path)
    machine = compile_table(table)
    layer, _ = robot_layer(table.robot)
    world = world or open_room()
    found = []
    for charge in charges:
        scene = prepare(table, machine, world, layer, {"battery": {"charge": charge}})
        for seed in seeds:
            result = simulate(scene, seconds, seed)
            heading = result.heading_deg()
            found.append(Turn(charge, seed, float(heading[-1] - heading[0]), float(result.kept_rows()[1, L.VBAT])))
    return found
