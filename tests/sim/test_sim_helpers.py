"""Shared builders for the simulator tests: a small robot, a table of signed motor rows, a room world.

Also tests that the builders themselves give a working scene (so a broken builder fails here first).
"""

from __future__ import annotations

import io
from pathlib import Path

import pytest

from tablebot.cli.common import load
from tablebot.diagnostics import TableBotError
from tablebot.sim.model.scene import Scene, scene_for
from tablebot.sim.model.world import load_world
from tablebot.sim.runner import SimRun, simulate

ROOT = Path(__file__).resolve().parents[2]
BUMBERBOT = ROOT / "examples" / "bumberbot"

ROBOT = """\
name = "TestBot"
tick_ms = 10
initial_state = 1
[inputs]
I3 = "front-right bumper"
I4 = "front-left bumper"
I5 = "rear bumper"
I7 = "right phototransistor"
I8 = "left phototransistor"
[motors]
M1 = "right motor"
M2 = "left motor"
"""
HEADER = "description,state,T,I3,I4,I5,I7,I8,M1,M2,timer,next"
QUIET = "[noise]\nmotor_spread = 0\nmotor = 0\nlight = 0\n"


def room(
    start: tuple[float, float, float] = (1.5, 1.5, 0.0), extra: str = "", noise: bool = False, size: float = 3.0
) -> str:
    """A square room world (no lamp unless ``extra`` adds one); exact physics unless ``noise``."""
    x, y, heading = start
    text = (
        f'name = "test room"\n[arena]\nwalls = [[0, 0], [{size}, 0], [{size}, {size}], [0, {size}]]\n'
        f"[start]\nat = [{x}, {y}]\nheading = {heading}\n{extra}\n"
    )
    return text if noise else text + QUIET


def write_bot(tmp_path: Path, rows: list[str], world: str, robot: str = ROBOT) -> tuple[Path, Path]:
    """A table of signed-motor rows (after HEADER) with its robot file, and a world file."""
    (tmp_path / "robot.toml").write_text(robot, encoding="utf-8")
    table = tmp_path / "table.csv"
    table.write_text("\n".join([HEADER, *rows]) + "\n", encoding="utf-8")
    world_path = tmp_path / "world.toml"
    world_path.write_text(world, encoding="utf-8")
    return table, world_path


def scene_of(table: Path, world: Path | None = None, **overrides: dict) -> Scene:
    parsed, machine = load(table)
    return scene_for(parsed, machine, world, overrides)


def bot(tmp_path: Path, rows: list[str], world: str, **overrides: dict) -> Scene:
    table, world_path = write_bot(tmp_path, rows, world)
    return scene_of(table, world_path, **overrides)


def world_errors(tmp_path: Path, text: str) -> list[str]:
    """The rendered diagnostics of a world file that must not load."""
    path = tmp_path / "bad.toml"
    path.write_text(text, encoding="utf-8")
    with pytest.raises(TableBotError) as info:
        load_world(path)
    return [d.render() for d in info.value.diagnostics]


def trace_text(result: SimRun) -> str:
    buf = io.StringIO()
    result.write_trace(buf)
    return buf.getvalue()


#: Drive forward at speed 4 for 5 s, then stop for good.
STRAIGHT = ["go,1,1,,,,,,4,4,500,2", "stop,2,1,,,,,,0,0,0,3", "rest,3,1,,,,,,0,0,0,3"]
#: The document's Seek-Straight spin: right motor back, left forward, speed 2, 895 ticks; then stop.
SPIN = ["spin,1,1,,,,,,-2,2,895,2", "stop,2,1,,,,,,0,0,0,3", "rest,3,1,,,,,,0,0,0,3"]


def test_builders_give_a_runnable_setup(tmp_path: Path) -> None:
    scene = bot(tmp_path, STRAIGHT, room())
    result = simulate(scene, 0.5)
    assert result.ticks == 50
    assert scene.drive == (0, 1)
    assert trace_text(result).count("\n") == 50


def test_bumberbot_example_finds_its_arena() -> None:
    scene = scene_of(BUMBERBOT / "table.csv")
    assert scene.world.name == "BumberBot arena"
    assert scene.world.path.endswith("arena.toml")
