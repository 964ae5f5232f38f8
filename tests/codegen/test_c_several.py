"""The generated C of a robot of several tables (issue 36 §2, tablebot.codegen.several): compiled for this computer,
the BumberBot with its lights and random robots of 2-3 tables (cross-table events, a group, a counter loaded by one
table and read by others, either rule per table) run tick for tick as tablebot.engine.several does, in every order
of the tables' steps; export --to c of such a robot writes one unit per table beside the unchanged engine."""

from __future__ import annotations

import itertools
import random
import subprocess
from pathlib import Path

import pytest

from statechart_helpers import random_several, random_ticks
from tablebot.codegen.host import build_host_several, find_compiler, run_host_several
from tablebot.codegen.source import template
from tablebot.loading import Loaded
from tablebot.replay import replay_several

pytestmark = pytest.mark.skipif(
    subprocess.run(["sh", "-c", "command -v cc || command -v gcc"], capture_output=True, check=False).returncode != 0,
    reason="no C compiler",
)
LIGHTS = Path(__file__).resolve().parents[2] / "examples" / "bumberbot-lights"


def test_the_bumberbot_with_its_lights_runs_in_c_as_in_the_engine(tmp_path: Path) -> None:
    tables = Loaded.open(LIGHTS).tables
    assert tables is not None
    inputs = random_ticks(random.Random(7), tables, 600)
    want = list(replay_several(tables, inputs))
    assert {line["lights.state"] for line in want} >= {"flash_left", "blink_on"}  # the lights really ran
    assert run_host_several(build_host_several(tables, tmp_path), tables, inputs) == want


@pytest.mark.parametrize("seed", range(3))
def test_random_robots_run_in_c_as_in_the_engine_in_every_order(tmp_path: Path, seed: int) -> None:
    rng = random.Random(seed)
    tables = random_several(rng, tmp_path / "robot", 2 + seed % 2)
    inputs = random_ticks(rng, tables, 300)
    want = list(replay_several(tables, inputs))
    for k, order in enumerate(itertools.permutations(range(len(tables.machines)))):
        assert list(replay_several(tables, inputs, order)) == want, order
        exe = build_host_several(tables, tmp_path / f"c{k}", "scan" if k % 2 else "auto", order)
        assert run_host_several(exe, tables, inputs) == want, order


def test_export_writes_a_unit_per_table_beside_the_engine_as_it_is(tmp_path: Path) -> None:
    """What a user gets: the engine files byte for byte as for one table, each table's unit, the robot's tick;
    they compile with a main of the user's own (here: the host runner) by the command tb_robot.h gives."""
    out = tmp_path / "c"
    done = subprocess.run(
        [".venv/bin/tablebot", "export", str(LIGHTS), "--to", "c", str(out)],
        capture_output=True,
        text=True,
        check=False,
        cwd=LIGHTS.parents[1],
    )
    assert done.returncode == 0, done.stderr
    assert sorted(p.name for p in out.iterdir()) == [
        "tb_config.h",
        "tb_engine.c",
        "tb_engine.h",
        "tb_robot.c",
        "tb_robot.h",
        "tb_table_drive.c",
        "tb_table_drive_config.h",
        "tb_table_lights.c",
        "tb_table_lights_config.h",
    ]
    for name in ("tb_engine.c", "tb_engine.h"):
        assert (out / name).read_text(encoding="utf-8") == template(name)
    assert "Build: cc tb_robot.c tb_table_drive.c tb_table_lights.c YOUR_MAIN.c" in (out / "tb_robot.h").read_text()
    (out / "main.c").write_text(template("host_several.c"), encoding="utf-8")
    built = subprocess.run(
        [
            find_compiler(),
            "-std=c99",
            "-Wall",
            "-Wextra",
            "-Werror",
            "-o",
            "robot",
            "tb_robot.c",
            "tb_table_drive.c",
            "tb_table_lights.c",
            "main.c",
        ],
        cwd=out,
        capture_output=True,
        text=True,
        check=False,
    )
    assert built.returncode == 0, built.stderr
    ran = subprocess.run([str(out / "robot")], input="0\n16\n", capture_output=True, text=True, check=True)
    assert len(ran.stdout.splitlines()) == 2


def test_a_robot_reading_more_inputs_than_the_c_mask_holds_is_refused(tmp_path: Path) -> None:
    """Each table fits the C engine (at most 32 events), but the robot's input mask is one uint32_t: 34 inputs
    read by two tables are refused at the robot file, before any file is written."""
    names = [f"B{i}" for i in range(34)]
    (tmp_path / "robot.toml").write_text(
        'name = "Wide"\n[inputs]\n'
        + "".join(f'{n} = "button {n}"\n' for n in names)
        + '[motors]\nM1 = "right"\nM2 = "left"\n[tables]\n'
        + 'a = { file = "a.csv", initial_state = 1 }\nb = { file = "b.csv", initial_state = 1 }\n'
    )
    for file, motor, part in (("a.csv", "M1", names[:17]), ("b.csv", "M2", names[17:])):
        (tmp_path / file).write_text(f"state,{','.join(part)},{motor},timer,next\n1,{',' * (len(part) - 1)},1,0,1\n")
    done = subprocess.run(
        [".venv/bin/tablebot", "export", str(tmp_path / "a.csv"), "--to", "c", str(tmp_path / "c")],
        capture_output=True,
        text=True,
        check=False,
        cwd=LIGHTS.parents[1],
    )
    assert done.returncode == 2, done.stdout + done.stderr
    assert "the robot's tables read 34 inputs, more than the 32 the C engine of several tables takes" in done.stderr
    assert not (tmp_path / "c").exists()
