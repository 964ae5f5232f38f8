"""What the pictures draw: the tape, the declared sensors, lamp bases, collisions where they touched."""

from __future__ import annotations

import math
import shutil
from pathlib import Path

import pytest
from matplotlib.collections import PatchCollection
from matplotlib.figure import Figure
from matplotlib.patches import Wedge

from tablebot.sim.pictures.draw import RobotArtist, contact_point, draw_world
from tablebot.sim.pictures.plots import legend_marks, reading_panels
from tablebot.sim.runner import simulate
from tablebot.sim.summary import summarise
from test_sim_declared import sensor_scene
from test_sim_helpers import BUMBERBOT, ROOT, room, scene_of


@pytest.mark.parametrize(
    ("pose", "where"),
    [
        ((3.0 - 0.12 - 0.0005, 1.2, 0.0), (3.0, 1.2)),  # nose flat against the right wall
        ((1.0, 0.07 + 0.0005, 90.0), (1.0, 0.0)),  # backed against the bottom wall: the tail touches
    ],
)
def test_a_collision_is_marked_where_the_body_touches(
    tmp_path: Path, pose: tuple[float, float, float], where: tuple[float, float]
) -> None:
    scene = sensor_scene(tmp_path, room())
    x, y, heading = pose
    cx, cy = contact_point(scene.geometry, scene.params, x, y, math.radians(heading))
    assert math.dist((cx, cy), where) < 0.05  # within the body's width of the true point, on the wall
    assert cx == pytest.approx(where[0], abs=1e-9) or cy == pytest.approx(where[1], abs=1e-9)


def test_a_corner_touch_is_marked_at_the_obstacle(tmp_path: Path) -> None:
    post = "[[circle]]\nat = [2.0, 1.5]\nradius = 0.05\n"
    scene = sensor_scene(tmp_path, room(start=(0.5, 0.5, 0), extra=post))
    cx, cy = contact_point(scene.geometry, scene.params, 2.0 - 0.05 - 0.12 - 0.001, 1.5, 0.0)
    assert (cx, cy) == pytest.approx((1.95, 1.5), abs=1e-3)


def test_tape_and_lamp_bases_are_drawn_to_scale() -> None:
    world = scene_of(ROOT / "examples" / "line-follower" / "table.csv").world
    ax = Figure().add_subplot()
    draw_world(ax, world)
    (tape,) = [c for c in ax.collections if isinstance(c, PatchCollection)]
    assert len(tape.get_paths()) == 2 * len(world.lines[0].points)  # a band per piece, a disc per corner
    bumberbot = scene_of(ROOT / "examples" / "bumberbot" / "table.csv").world
    ax = Figure().add_subplot()
    draw_world(ax, bumberbot)
    bases = [p for p in ax.patches if getattr(p, "radius", None) == bumberbot.lamps[0].radius]
    assert bases and bases[0].get_hatch() == "//"  # the base is drawn as the obstacle it is


def test_the_robot_shows_its_own_sensors_and_not_the_bumberbots(tmp_path: Path) -> None:
    scene = scene_of(ROOT / "examples" / "obstacle-avoider" / "table.csv")
    ax = Figure().add_subplot()
    robot = RobotArtist(ax, scene.params, sensors=scene.table.robot.sensors)
    robot.update(1.0, 1.0, 0.0, readings=(0.2, 0.6))
    assert not any(p.get_visible() for p in robot.bumpers + robot.cones)  # no bumpers, no phototransistors
    near, far = robot.declared
    assert isinstance(near, Wedge) and isinstance(far, Wedge)  # distance sensors' beams
    assert (near.r, far.r) == (pytest.approx(0.2), pytest.approx(0.6))  # each beam reaches its echo
    result = simulate(scene, 1.0)
    labels = [h.get_label() for h in legend_marks(result, summarise(result), spins=False)]
    assert "distance beam, out to the echo" in labels and "light first seen" not in labels
    assert [p.name for p in reading_panels(simulate(scene, 1.0))] == ["distance"]


def test_names_with_dollar_signs_are_drawn_as_written(tmp_path: Path) -> None:
    """matplotlib reads text between two $ as maths: a robot called 'cost $\\frac{ room $' crashed the
    pictures. Every picture is drawn with literal text (sim.pictures.draw.literal_text)."""
    from typer.testing import CliRunner

    from tablebot.cli.app import app

    shutil.copytree(BUMBERBOT, tmp_path / "bot")
    robot = tmp_path / "bot" / "robot.toml"
    robot.write_text(robot.read_text().replace('name = "BumberBot"', 'name = "cost $\\\\frac{ room $"'))
    result = CliRunner().invoke(
        app, ["sim", str(tmp_path / "bot"), "--seconds", "2", "--out", str(tmp_path / "o"), "-q", "--gif"]
    )
    assert result.exit_code == 0, result.output
    assert all((tmp_path / "o" / n).stat().st_size > 1000 for n in ("trajectory.png", "timeline.png", "run.gif"))
