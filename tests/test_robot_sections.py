"""The robot file is read once into typed sections: every section checked on its line, unknown ones refused."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from tablebot.diagnostics import TableBotError
from tablebot.robot import load_robot
from tablebot.sim.model.params import SimSection

pytestmark = [pytest.mark.kernel_free]

BASE = 'name = "Bot"\ninitial_state = 1\n[inputs]\nI3 = "bumper"\n[motors]\nM1 = "right"\nM2 = "left"\n'


def errors(tmp_path: Path, extra: str) -> list[str]:
    path = tmp_path / "robot.toml"
    path.write_text(BASE + extra, encoding="utf-8")
    with pytest.raises(TableBotError) as info:
        load_robot(path)
    return [d.render() for d in info.value.diagnostics]


def test_a_top_level_wiring_section_is_refused_on_its_line(tmp_path: Path) -> None:
    found = errors(tmp_path, '[wiring]\nright_motor = "M9"\n')
    assert found == [
        f"{tmp_path / 'robot.toml'}:8:1: error: unknown section 'wiring'\n"
        "    hint: the simulator's wiring goes in [sim.wiring] in a robot file "
        "([wiring] is for world files)"
    ]


@pytest.mark.parametrize(
    "extra, line, message",
    [
        ("[gearbox]\nratio = 3\n", 8, "unknown section 'gearbox'"),
        ("[battery]\ncharge = 0.5\n", 8, "unknown section 'battery'"),
        ("[sim.battery]\ncharge = 5\n", 9, "charge"),
        ('[sim]\nworld = "nowhere.toml"\n', 9, "sim.world"),
        ("[sim]\nspeed = 3\n", 9, "speed"),
        ('[board.arduino]\nI3 = "D2"\n', 8, "unknown board 'arduino'"),
        ('[board.uno]\nI3 = "D99"\n', 9, "input I3 cannot use 'D99'"),
    ],
)
def test_every_section_is_checked_when_the_file_is_read(tmp_path: Path, extra: str, line: int, message: str) -> None:
    found = errors(tmp_path, extra)
    assert any(f"robot.toml:{line}" in e and message in e for e in found), found


def test_sections_are_typed(tmp_path: Path) -> None:
    room = "[arena]\nwalls = [[0, 0], [1, 0], [1, 1], [0, 1]]\n[start]\nat = [0.5, 0.5]\n"
    (tmp_path / "arena.toml").write_text(room)
    path = tmp_path / "robot.toml"
    path.write_text(BASE + '[sim]\nworld = "arena.toml"\n[sim.battery]\ncharge = 0.5\n[board.uno]\nI3 = "D4"\n')
    robot = load_robot(path)
    assert robot.sections["sim"] == SimSection({"battery": {"charge": 0.5}}, tmp_path / "arena.toml")
    assert robot.sections["board"]["uno"].terminals == {"I3": "D4"}


def test_reading_robot_and_world_files_does_not_load_the_simulator() -> None:
    code = (
        "import sys; from tablebot.robot import load_robot; from tablebot.sim.model.world import load_world; "
        "load_robot('examples/bumberbot/robot.toml'); load_world('examples/bumberbot/arena.toml'); "
        "print(sorted(m for m in ('numba', 'matplotlib', 'tablebot.sim.physics.step') if m in sys.modules))"
    )
    done = subprocess.run(
        [sys.executable, "-c", code],
        capture_output=True,
        text=True,
        check=True,
        cwd=Path(__file__).resolve().parents[1],
    )
    assert done.stdout.strip() == "[]"


def test_mistakes_in_the_core_and_in_a_stages_section_are_reported_together(tmp_path: Path) -> None:
    """A lamp label that is no text and a bad [sim.battery] value: both in one run, not the second only
    after fixing the first."""
    found = errors(tmp_path, "[lamps]\nL1 = 5\n[sim.battery]\ncharge = 5\n")
    assert any("the label must be text" in e for e in found) and any("charge" in e for e in found), found
