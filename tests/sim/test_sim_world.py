"""World files and simulator parameters: what they accept, and located errors for what they do not."""

from __future__ import annotations

from pathlib import Path

import pytest

from tablebot.diagnostics import TableBotError
from tablebot.sim.model.world import geometry, load_world
from test_sim_helpers import ROBOT, STRAIGHT, bot, room, scene_of, world_errors, write_bot

GOOD = room(
    extra="[[lamp]]\nat = [2, 2]\n[[box]]\nat = [0.5, 2.5]\nsize = [0.2, 0.3]\nangle = 45\n"
    "[[circle]]\nat = [2.5, 0.5]\nradius = 0.1\n[[segment]]\nfrom = [0, 1]\nto = [0.5, 1]\n"
)


def test_a_good_world_loads_into_arrays(tmp_path: Path) -> None:
    path = tmp_path / "w.toml"
    path.write_text(GOOD, encoding="utf-8")
    world = load_world(path)
    geo = geometry(world)
    assert len(world.lamps) == len(world.boxes) == len(world.circles) == len(world.segments) == 1
    assert geo.pstart.tolist() == [0, 2, 4, 6, 8, 10, 14]  # 4 walls, 1 segment, 1 box
    assert geo.edges.shape == (4 + 1 + 4, 4)
    assert geo.circles[:, 3].tolist() == [-1.0, 0.0]  # the pot, then the lamp's base


R = room().count("\n")  # lines of the room text; the bad parts follow it


@pytest.mark.parametrize(
    ("text", "line", "words"),
    [
        ("[arena]\nwalls = [[0, 0], [1, 0]]\n[start]\nat = [0.5, 0.5]\n", 2, "at least three corners"),
        ("[arena]\nwalls = [[0, 0], [1, 1], [1, 0], [0, 1]]\n[start]\nat = [0.5, 0.3]\n", 2, "cross themselves"),
        ("[arena]\nwalls = [[0, 0], [2, 0], [2, 2]]\n[start]\nat = [0.2, 1.5]\n", 4, "outside the arena"),
        (room() + "[[box]]\nat = [1, 1]\nsize = [0.5, -1]\n", R + 3, "size must be positive"),
        (room() + '[[circle]]\nat = [1, 1]\nradius = "big"\n', R + 3, "radius must be a number"),
        (room() + '[[lamp]]\nat = [1, 1]\ncolour = "red"\n', R + 3, "unknown key 'colour'"),
        (room() + "[[lamp]]\nat = [1]\n", R + 2, "must be a point [x, y]"),
        # it said "must be a point [x, y]" of a point, with "at = [...]" as the example for walls too
        (room() + "[[lamp]]\nat = [1e9, 1]\n", R + 2, "[[lamp]] #1 at: the point [1000000000.0, 1] is out of range"),
        (room() + "[battery]\ncharge = 2\n", R + 2, "charge = 2 is out of range 0..1"),
        (room() + "[motor]\nlevels = 8.5\n", R + 2, "must be an integer"),
        (room() + "[[segment]]\nfrom = [1, 1]\nto = [1, 1]\n", R + 3, "has no length"),
        ("walls = 3\n" + room(), 1, "unknown key 'walls'"),
        (room() + "[arena\n", R + 1, "TOML syntax"),
    ],
)
def test_bad_worlds_are_located(tmp_path: Path, text: str, line: int, words: str) -> None:
    found = world_errors(tmp_path, text)
    assert any(f"bad.toml:{line}" in e and words in e for e in found), found


def test_every_problem_is_reported_at_once(tmp_path: Path) -> None:
    found = world_errors(tmp_path, room() + "[[box]]\nat = [1, 1]\nsize = [0, 1]\n[[circle]]\nat = [2, 2]\n")
    assert len(found) == 2


def test_a_start_overlapping_an_obstacle_is_refused(tmp_path: Path) -> None:
    world = room(start=(1.0, 1.0, 0), extra="[[circle]]\nat = [1.1, 1.0]\nradius = 0.1\n")
    with pytest.raises(TableBotError, match=r"world.toml:5: .*overlaps"):
        bot(tmp_path, STRAIGHT, world)


def test_wiring_must_name_robot_inputs(tmp_path: Path) -> None:
    world = room(extra='[wiring]\nlight_left = "I9"\n')
    with pytest.raises(TableBotError, match=r"world.toml:\d+:.*light_left = 'I9' is not an input"):
        bot(tmp_path, STRAIGHT, world)


def test_unconnected_sensors(tmp_path: Path) -> None:
    scene = bot(tmp_path, STRAIGHT, room(extra='[wiring]\nrear = "none"\nlight_left = ""\n'))
    assert scene.bits.tolist() == [16, 8, 0, 2, 0]  # I3 I4 - I7 -
    with pytest.raises(TableBotError, match="right_motor must name a robot input or motor"):
        bot(tmp_path, STRAIGHT, room(extra='[wiring]\nright_motor = ""\n'))


def test_inconsistent_battery_is_refused(tmp_path: Path) -> None:
    with pytest.raises(TableBotError, match="empty_volts must be below full_volts"):
        bot(tmp_path, STRAIGHT, room(extra="[battery]\nempty_volts = 9.5\n"))


def test_robot_file_sim_section_sets_parameters(tmp_path: Path) -> None:
    table, world = write_bot(tmp_path, STRAIGHT, room(), robot=ROBOT + "[sim.body]\nwheel_base = 0.2\n")
    assert scene_of(table, world).params["body"]["wheel_base"] == 0.2
    (tmp_path / "robot.toml").write_text(ROBOT + "[sim.body]\nwheel_base = -1\n", encoding="utf-8")
    with pytest.raises(TableBotError, match=r"robot.toml:14:.*wheel_base = -1 is out of range"):
        scene_of(table, world)
