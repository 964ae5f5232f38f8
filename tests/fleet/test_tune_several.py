"""``tune`` of a robot of several tables (issue 36 §2): a cell names its table (``clock: line 2 timer``), every
candidate runs every table on the fleet as ``tablebot sim`` runs them, and the tuned table is written beside the
others untouched; a group's row is tuned in every state it runs in; an unknown table is a clear error."""

from __future__ import annotations

import io
import shutil
from pathlib import Path

import pytest
from typer.testing import CliRunner

import tablebot
from tablebot.cli import app
from tablebot.fleet.cells import cell_variants, parse_cells
from tablebot.fleet.plan import make_plan
from tablebot.fleet.run import Fleet, RobotSpec
from tablebot.sim.model.scene import robot_layer
from tablebot.sim.runner import simulate
from test_tune import HALL, hand_optimum

LIGHTS = Path(__file__).resolve().parents[2] / "examples" / "bumberbot-lights"
ROBOT = """\
name = "TestBot"
tick_ms = 10
match = "always"
[inputs]
I3 = "front-right bumper"
[motors]
M1 = "right motor"
M2 = "left motor"
[tables]
drive = { file = "drive.csv", initial_state = 1 }
clock = { file = "clock.csv", initial_state = 1 }
"""
#: The drive table goes full speed ahead until the clock table has rung (its state 3): the clock's timer is the
#: time the robot drives, the one cell worth tuning, in the table that moves no motor.
DRIVE = "description,state,clock=3,M1,M2,timer,next\nstop,1,1,0,0,0,2\ngo,1,,8,8,0,1\nhalt,2,,0,0,0,2\n"
CLOCK = "description,state,T,timer,next\nwait,1,1,500,2\nring,2,1,0,3\nrung,3,1,0,3\n"


def robot(tmp_path: Path) -> Path:
    for name, text in (("robot.toml", ROBOT), ("drive.csv", DRIVE), ("clock.csv", CLOCK), ("hall.toml", HALL)):
        (tmp_path / name).write_text(text, encoding="utf-8")
    return tmp_path


def tune(folder: Path, *args: str) -> tuple[int, str]:
    result = CliRunner().invoke(
        app,
        [
            "tune",
            str(folder / "drive.csv"),
            "--robot",
            str(folder / "robot.toml"),
            "--world",
            str(folder / "hall.toml"),
            "--grid",
            "battery=1.0",
            "--seeds",
            "0..1",
            "--check-seeds",
            "7..8",
            "--seconds",
            "9",
            "--objective",
            "lamp_distance",
            "--workers",
            "1",
            "--out",
            str(folder / "out"),
            *args,
        ],
    )
    return result.exit_code, result.output


def test_the_other_tables_timer_is_tuned_to_the_stopping_time_computed_by_hand(tmp_path: Path) -> None:
    """The clock's timer X stops the robot X + 2 ticks after the start (the clock fires on tick 0, rings X
    ticks later, and the drive table sees it rung on the next tick): the best X is the hand optimum less 2."""
    folder = robot(tmp_path)
    code, output = tune(folder, "--cells", "clock: line 2 timer=560..700", "--budget", "200")
    assert code == 0, output
    out = folder / "out"
    assert sorted(p.name for p in out.glob("*.tuned.csv")) == ["clock.tuned.csv"]  # the drive table is as it was
    tuned = (out / "clock.tuned.csv").read_text(encoding="utf-8")
    best = int(tuned.splitlines()[1].split(",")[3])
    assert abs(best + 2 - hand_optimum()) <= 1.5, tuned
    assert tuned == CLOCK.replace(",500,", f",{best},")
    report = (out / "report.md").read_text(encoding="utf-8")
    assert f"| clock: line 2 timer | 500 | {best} |" in report
    assert "clock.tuned.csv → clock.csv" in report


def test_a_variant_of_the_lights_table_runs_as_sim_of_the_edited_table(tmp_path: Path) -> None:
    """Robot k of a fleet of program variants of a robot of several tables gives the trace ``tablebot sim``
    gives for the tables with the variant's values written into them (the lights' flashing slowed down, and a
    drive row written for a group of states, tuned in each of them)."""
    plan = make_plan(LIGHTS, None, [], [], "1", None, 1.0, every_table=True)
    cells = parse_cells("lights: line 4 timer, lights: line 5 timer, line 2 timer", plan.table, plan.tables)
    assert [len(c.rows) for c in cells] == [1, 1, 3]  # line 2 of table.csv is a row of the group seeking
    edited = tmp_path / "edited"
    shutil.copytree(LIGHTS, edited)
    for name, values in (("lights.csv", {3: "17", 4: "23"}), ("table.csv", {1: "33"})):
        lines = (edited / name).read_text(encoding="utf-8").splitlines(keepends=True)
        for k, value in values.items():
            cells_of = lines[k].split(",")
            lines[k] = ",".join([*cells_of[:-2], value, cells_of[-1]])
        (edited / name).write_text("".join(lines), encoding="utf-8")
    project = tablebot.open(LIGHTS)
    variants = cell_variants(plan.tables, plan.machine, cells, [tuple(c.value for c in cells), (17, 23, 33)])
    specs = [RobotSpec(seed=3, variant=1), RobotSpec(seed=3, variant=0)]
    fleet = Fleet(
        project.table,
        project.machine,
        project.scene(every_table=True).world,
        specs,
        robot_layer(project.robot)[0],
        traced=[0, 1],
        variants=variants,
        tables=plan.tables,
    )
    fleet.run(600)
    for k, folder in ((0, edited), (1, LIGHTS)):
        alone = simulate(tablebot.open(folder).scene(every_table=True), 6.0, 3)
        text = io.StringIO()
        alone.write_trace(text)
        assert "".join(fleet.trace_lines(k)) == text.getvalue(), folder
    assert fleet.trace_lines(0) != fleet.trace_lines(1)


@pytest.mark.parametrize(
    ("cells", "words"),
    [
        ("lamps: line 2 timer", "--cells: 'lamps: line 2 timer': the robot has no table lamps"),
        ("clock: line 9 timer", "line 9 of clock.csv is not a row of the table"),
        ("clock: line 2 timer, clock:line 2 timer", "names clock: line 2 timer twice"),
    ],
)
def test_bad_cells_of_several_tables_name_the_option(tmp_path: Path, cells: str, words: str) -> None:
    code, output = tune(robot(tmp_path), "--cells", cells)
    assert code == 2, output
    assert output.startswith("--cells: error:") and words in output, output
    assert "its tables ([tables] in robot.toml): drive, clock" in output or "lamps" not in cells


def test_a_table_named_for_a_robot_of_one_table_is_a_clear_error(tmp_path: Path) -> None:
    (tmp_path / "table.csv").write_text("description,state,T,M1,M2,timer,next\ngo,2,1,8,8,5,2\n", encoding="utf-8")
    result = CliRunner().invoke(
        app,
        [
            "tune",
            str(tmp_path / "table.csv"),
            "--cells",
            "lights: line 2 timer",
            "--seeds",
            "0",
            "--check-seeds",
            "1",
            "--seconds",
            "1",
            "--workers",
            "1",
            "--out",
            str(tmp_path / "out"),
        ],
    )
    assert result.exit_code == 2, result.output
    assert "names the table lights, but the robot has one table" in result.output
