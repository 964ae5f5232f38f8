"""Compile (or load) every numba kernel the tests run, once, before pytest-xdist starts its workers.

Run by ``tests/conftest.py`` in the main pytest process. Each part calls the public paths the tests
take, on the smallest input that reaches each kernel with the argument types the tests give it:
``loop`` (one robot's loop), ``fleet`` (the fleet loop, which calls it), ``tick`` (the tick-by-tick robot,
the env's physics-only loop, the engine's batch loop on both mask types), ``several`` (the loop of a robot of
several tables) and ``archive`` (pyribs' grid archive, which compiles numpy_groupies' kernels: half a minute,
in every evolve process of a cold cache).
Numba caches one machine code per argument types, so a kernel reached here with other types than a test's is
compiled again by that test; conftest gives each worker a cache folder of its own, so that costs time, not safety.
"""

from __future__ import annotations

import sys
from pathlib import Path
from unittest import mock

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "examples"


def warm_loop() -> None:
    """One robot's compiled loop (``tablebot sim``'s, and the run loop's block path)."""
    from tablebot.cli.common import load
    from tablebot.engine import Engine
    from tablebot.loop import SimulatedClock
    from tablebot.loop import run as run_loop
    from tablebot.sim.model.scene import scene_for
    from tablebot.sim.physics import kernel
    from tablebot.sim.runner import simulate
    from tablebot.sim.simrobot import SimRobot

    table, machine = load(EXAMPLES / "bumberbot" / "table.csv")
    scene = scene_for(table, machine)
    # A robot's first reading (kernel.sense) calls physics.advance_called, which the part beside this one
    # ("tick") compiles first; skipped here while the loop compiles, so that the two parts do not both spend
    # half a minute on it (the readings are wrong, the argument types the same: only the cache matters)
    # (a robot starts through kernel.first_readings, compiled code that calls sense: both are skipped, since a
    # Python stand-in for sense alone cannot be called from compiled code)
    with (
        mock.patch.object(kernel, "sense", lambda *args: None),
        mock.patch.object(kernel, "first_readings", lambda *args: None),
    ):
        simulate(scene, 0.05, 1)
    run_loop(Engine(machine), SimRobot(scene, 1), clock=SimulatedClock(), sinks=[], ticks=3)


def warm_fleet() -> None:
    """The fleet's loop, which calls one robot's (``loop`` first), and a robot's first reading, which calls
    physics.advance_called (by then in the cache: ``tick`` compiles it first)."""
    from tablebot.fleet.plan import make_plan
    from tablebot.fleet.work import warm

    warm(make_plan(EXAMPLES / "bumberbot" / "table.csv", None, [], [], "0", None, 1.0).jobs()[0])


def warm_tick() -> None:
    """What runs a tick at a time from Python: a robot's tick (physics.advance_called, compiled once for all of
    them), the Gymnasium env's physics-only loop, and the engine's batch loop on both mask types."""
    from tablebot.cli.common import load
    from tablebot.engine import Engine
    from tablebot.fleet.env import TableBotVectorEnv
    from tablebot.sim.model.scene import scene_for
    from tablebot.sim.simrobot import SimRobot

    table, machine = load(EXAMPLES / "bumberbot" / "table.csv")
    robot = SimRobot(scene_for(table, machine), 1)
    robot.reset(seed=1)
    robot.write([0] * len(machine.output_names))
    env = TableBotVectorEnv(num_envs=2, seconds=0.05)
    env.reset(seed=1)
    env.step(np.zeros((2, 2)))
    env.close()
    for dtype in (np.uint8, np.int64):  # the two mask types the batch kernel is compiled for
        Engine(machine).run(np.zeros(3, dtype=dtype))


def warm_archive() -> None:
    from tablebot.evolve.archive import add, make_archive
    from tablebot.evolve.measures import Descriptor

    for descriptors in ([Descriptor("a", 0.0, 1.0, 4)], [Descriptor("a", 0.0, 1.0, 4), Descriptor("b", 0.0, 1.0, 4)]):
        add(make_archive(descriptors), ["x", "y"], [1.0, 2.0], [[0.2] * len(descriptors), [0.7] * len(descriptors)])


def warm_several() -> None:
    """The loop of a robot of several tables (sim.physics.several.run_several) and its fleet's (the BumberBot with
    its lights, as sweep, tune and evolve run it): one compiled loop serves every number of tables (their programs
    come as a tuple of MAX_TABLES), so one robot of three tables warms it for all (~40 CPU-s, in every test process
    that simulates such a robot on a cold cache otherwise)."""
    import random
    import tempfile

    import tablebot
    from tablebot.sim.physics import kernel
    from tablebot.sim.runner import simulate
    from tablebot.testing.random_robots import RobotShape, random_robot

    # As in warm_loop: a robot's first reading calls physics.advance_called, which the other part ("tick", its
    # first) compiles meanwhile; skipped here while the two loops compile, loaded from the cache by the fleet below
    with (
        mock.patch.object(kernel, "sense", lambda *args: None),
        mock.patch.object(kernel, "first_readings", lambda *args: None),
        tempfile.TemporaryDirectory(prefix="tablebot-warm-") as tmp,
    ):
        folder = random_robot(random.Random(3), Path(tmp), RobotShape(tables=3))
        project = tablebot.open(folder / "t0.csv", robot=folder / "robot.toml")
        simulate(project.scene(every_table=True), 0.05, seed=1)
    from tablebot.fleet.plan import make_plan
    from tablebot.fleet.work import warm

    warm(make_plan(EXAMPLES / "bumberbot-lights", None, [], [], "0", None, 1.0, every_table=True).jobs()[0])


PARTS = {"loop": warm_loop, "fleet": warm_fleet, "tick": warm_tick, "archive": warm_archive, "several": warm_several}

if __name__ == "__main__":
    for name in sys.argv[1:] or list(PARTS):
        PARTS[name]()
