"""benchmarks/kernel.py's case of a robot of several tables: its fleet against the same robot's main table alone."""

from __future__ import annotations

import statistics
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


SEVERAL = "bumberbot-lights"  # a robot of two tables: its drive table alone, and with its lights table


def several_against_one(repeats: int) -> dict[str, float]:
    """ns per robot-tick of a fleet of 300 robots of several tables (every table each tick) and of the same robot
    running its main table alone, 1,000 ticks on this thread, and their ratio: what a robot's other tables cost."""
    import tablebot
    from tablebot.fleet.run import Fleet, RobotSpec
    from tablebot.sim.model.scene import robot_layer

    project = tablebot.open(ROOT / "examples" / SEVERAL)
    layer = robot_layer(project.robot)[0]

    def run(every: bool) -> float:
        scene = project.scene(every_table=every)
        fleet = Fleet(
            project.table,
            project.machine,
            scene.world,
            [RobotSpec(seed=s) for s in range(300)],
            layer,
            tables=project.tables if every else None,
        )
        started = time.process_time()
        fleet.run(1000, threads=False)
        return (time.process_time() - started) / 300e3 * 1e9

    run(True), run(False)  # compiled or loaded, warm
    several = statistics.median(run(True) for _ in range(repeats))
    one = statistics.median(run(False) for _ in range(repeats))
    return {
        f"{SEVERAL}: several tables": several,
        f"{SEVERAL}: main table alone": one,
        f"{SEVERAL}: several / alone": several / one,
    }
