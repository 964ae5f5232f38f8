"""``run --on sim`` or ``sim:WORLD``: the simulator as a live robot, paced in real time, registered as a
back-end; the robot file's ``[sim]`` section is read here."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

from tablebot.i18n import N_
from tablebot.registry import LinkOptions, LiveBackend, Opened, register
from tablebot.robot import Robot
from tablebot.tomlfile import Source

if TYPE_CHECKING:
    from tablebot.machine import Machine


def read_section(src: Source, data: Any, robot: Robot) -> Any:
    from tablebot.sim.model.params import read_robot_sim

    return read_robot_sim(src, data, robot)


def open_sim(machine: Machine, link: LinkOptions) -> Opened:
    """The simulator as a robot, paced in real time: a rehearsal on exactly the code path of a real run. A robot
    of several tables is wired for all of them (``machine`` is then the robot's, its rows the main table's)."""
    from tablebot.jit import say_compiling
    from tablebot.sim.model.scene import scene_for
    from tablebot.sim.physics import kernel
    from tablebot.sim.simrobot import SimRobot
    from tablebot.tables import several

    world = link.address.partition(":")[2]
    seed = link.seed
    say_compiling(N_("the simulator"), kernel.move)
    tables = several(machine.table)
    bot = SimRobot(scene_for(machine.table, machine, Path(world) if world else None, tables=tables), seed)
    bot.write((0,) * len(machine.output_names))  # compiles the one-tick physics now, not in the first tick
    bot.reset(seed=seed)
    return Opened(bot, "sim", N_("simulated, seed {seed}", seed=seed))


SIM = register(
    LiveBackend(
        name="sim",
        makes="the simulator, driven in real time by `tablebot run`",
        help="sim[:WORLD] (the simulator, in real time)",
        section="sim",
        read_section=read_section,
        open=open_sim,
        addresses=("sim", "sim:WORLD.toml"),
    )
)
