"""``tablebot tune``: the known optimum of a table whose best timer is computable by hand (grid and
CMA-ES), the tuned table as a new file differing only in the tuned cells, and bad cells named."""

from __future__ import annotations

import json
import shlex
from pathlib import Path

import pytest
from typer.testing import CliRunner

from tablebot.cli import app
from tablebot.sim.model.params import merged, top_speed

ROBOT = """\
name = "TestBot"
tick_ms = 10
initial_state = 1
[inputs]
I3 = "front-right bumper"
[motors]
M1 = "right motor"
M2 = "left motor"
"""
#: A hall with a lamp hanging in the air 1 m straight ahead of the start; exact physics (no noise).
HALL = """\
name = "hall"
[arena]
walls = [[0, 0], [3, 0], [3, 3], [0, 3]]
[start]
at = [0.5, 1.5]
heading = 0
[[lamp]]
at = [1.5, 1.5]
radius = 0
[noise]
motor_spread = 0
motor = 0
light = 0
"""
DISTANCE_M = 1.0


def hand_optimum() -> float:
    """Full speed ahead for X ticks, then stop: a first-order motor lag loses at the start exactly what
    it coasts at the end, so the robot ends X · v · dt ahead, v the steady top speed on a full battery.
    The lamp is 1 m ahead: X = 1 m / (v · 10 ms)."""
    quiet = merged({"noise": {"motor_spread": 0.0, "motor": 0.0, "light": 0.0}})
    return DISTANCE_M / (top_speed(quiet) * 0.010)


def tune(tmp_path: Path, rows: list[str], *args: str, world: str = HALL) -> tuple[int, str, Path]:
    (tmp_path / "robot.toml").write_text(ROBOT, encoding="utf-8")
    table = tmp_path / "table.csv"
    table.write_text("\r\n".join(["description,state,T,I3,M1,M2,timer,next", *rows]) + "\r\n", encoding="utf-8")
    (tmp_path / "hall.toml").write_text(world, encoding="utf-8")
    out = tmp_path / "out"
    result = CliRunner().invoke(
        app,
        [
            "tune",
            str(table),
            "--world",
            str(tmp_path / "hall.toml"),
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
            str(out),
            *args,
        ],
    )
    return result.exit_code, result.output, out


def test_the_grid_finds_the_stopping_time_computed_by_hand(tmp_path: Path) -> None:
    code, output, out = tune(
        tmp_path, ["go,1,1,,8,8,500,2", "stop,2,1,,0,0,0,2"], "--cells", "line 2 timer=0..800", "--budget", "1000"
    )
    assert code == 0, output
    best = round(hand_optimum())
    tuned = (out / "table.tuned.csv").read_bytes()
    assert tuned == (tmp_path / "table.csv").read_bytes().replace(b",500,", f",{best},".encode())  # only that cell
    assert (tmp_path / "table.csv").read_bytes().count(b",500,") == 1  # the input is untouched
    assert f"| line 2 timer | 500 | {best} |" in output
    report = (out / "report.md").read_text(encoding="utf-8")
    assert "grid, 801 candidates" in report
    assert (out / "convergence.png").stat().st_size > 10_000
    command = shlex.split(report.rsplit("`", 2)[1])  # the report's last line: how to simulate the tuned table
    assert command[:3] == ["tablebot", "sim", str(out / "table.tuned.csv")]
    assert command[3:] == ["--robot", str(tmp_path / "robot.toml"), "--world", str(tmp_path / "hall.toml")]
    ran = CliRunner().invoke(app, [*command[1:], "--seconds", "1", "--no-plots", "--out", str(tmp_path / "sim")])
    assert ran.exit_code == 0, ran.output
    first = json.loads((tmp_path / "sim" / "trace.jsonl").read_text(encoding="utf-8").splitlines()[0])
    assert (first["x"], first["y"], first["heading"]) == (0.5, 1.5, 0.0)  # the hall's start, not an empty room's


def test_cma_es_finds_the_optimum_of_two_timers_that_add_up(tmp_path: Path) -> None:
    """Two legs of full speed ahead: any X1 + X2 equal to the hand optimum is best."""
    code, output, out = tune(
        tmp_path,
        ["leg one,1,1,,8,8,100,2", "leg two,2,1,,8,8,100,3", "stop,3,1,,0,0,0,3"],
        "--cells",
        "line 2 timer=0..600, line 3 timer=0..600",
        "--method",
        "cma",
        "--budget",
        "400",
        "--seed",
        "3",
    )
    assert code == 0, output
    lines = (out / "table.tuned.csv").read_text(encoding="utf-8").splitlines()
    total = int(lines[1].split(",")[6]) + int(lines[2].split(",")[6])
    assert abs(total - hand_optimum()) <= 2.5, lines
    assert "cma," in (out / "report.md").read_text(encoding="utf-8")


@pytest.mark.parametrize(
    ("cells", "words"),
    [
        ("line 2 M1", "'line 2 M1' is not a timer or a counter load"),
        ("line 9 timer", "line 9 of table.csv is not a row of the table"),
        ("row 2 timer", "does not name a cell"),
        ("line 2 timer=9..3", "the range must be LOW..HIGH"),
        ("line 2 timer, line 2 timer", "names line 2 timer twice"),
        ("", "names no cell"),
    ],
)
def test_bad_cells_are_clear_errors_naming_the_option(tmp_path: Path, cells: str, words: str) -> None:
    code, output, _ = tune(tmp_path, ["go,1,1,,8,8,500,2", "stop,2,1,,0,0,0,2"], "--cells", cells)
    assert code == 2, output
    assert output.startswith("--cells: error:") and words in output, output


def test_bad_objective_and_method_name_their_option(tmp_path: Path) -> None:
    for args, option in (
        (["--objective", "speed"], "--objective"),
        (["--method", "bayes"], "--method"),
        (["--check-seeds", "9..3"], "--check-seeds"),
        (["--grid", "start=0.05:1.5:0"], "--grid"),
    ):
        code, output, _ = tune(tmp_path, ["go,1,1,,8,8,500,2", "stop,2,1,,0,0,0,2"], "--cells", "line 2 timer", *args)
        assert code == 2 and output.startswith(f"{option}: error:"), output
        assert "--seeds" not in output, output  # the option given, not the one whose words it shares


def test_a_second_run_replaces_the_tuned_table_only_with_force(tmp_path: Path) -> None:
    """Refused before the search (nothing else rewritten), as every command refuses to replace a table."""
    rows = ["go,1,1,,8,8,500,2", "stop,2,1,,0,0,0,2"]
    code, output, out = tune(tmp_path, rows, "--cells", "line 2 timer=0..40", "--budget", "3")
    assert code == 0, output
    before = {p.name: p.stat().st_mtime_ns for p in out.iterdir()}
    code, output, _ = tune(tmp_path, rows, "--cells", "line 2 timer=0..40", "--budget", "3")
    assert code == 2 and output.startswith(f"{out / 'table.tuned.csv'}: error:") and "--force" in output, output
    assert {p.name: p.stat().st_mtime_ns for p in out.iterdir()} == before
    code, output, _ = tune(tmp_path, rows, "--cells", "line 2 timer=0..40", "--budget", "3", "--force")
    assert code == 0, output
    assert (out / "table.tuned.csv.bak").read_bytes() == (out / "table.tuned.csv").read_bytes()


def test_a_timer_written_in_seconds_is_tuned_in_seconds(tmp_path: Path) -> None:
    """``5s`` tuned to N ticks is written N × 10 ms in seconds: a bare N would read as N ticks, far less."""
    from tablebot.durations import to_ticks

    code, output, out = tune(
        tmp_path, ["go,1,1,,8,8,5s,2", "stop,2,1,,0,0,0,2"], "--cells", "line 2 timer=100..800", "--budget", "4"
    )
    assert code == 0, output
    cell = (out / "table.tuned.csv").read_text(encoding="utf-8").splitlines()[1].split(",")[6]
    after = int(next(line for line in output.splitlines() if line.startswith("| line 2 timer |")).split("|")[3])
    assert cell.endswith("s") and not cell.endswith("ms") and to_ticks(cell, 10) == after, (cell, after)
    assert "Timers count ticks of 10 ms" in output


def test_a_lamp_objective_in_a_world_without_lamps_is_refused(tmp_path: Path) -> None:
    """Every candidate would tie (never reached): the objective is named, collisions still tune."""
    dark = HALL.replace("[[lamp]]\nat = [1.5, 1.5]\nradius = 0\n", "")
    rows = ["go,1,1,,8,8,500,2", "stop,2,1,,0,0,0,2"]
    code, output, _ = tune(tmp_path, rows, "--cells", "line 2 timer=0..50", world=dark)
    assert code == 2, output
    assert output.startswith("--objective: error: --objective lamp_distance needs a lamp, and hall has none"), output
    code, output, out = tune(tmp_path, rows, "--cells", "line 2 timer=0..50", "--objective", "collisions", world=dark)
    assert code == 0, output
    report = (out / "report.md").read_text(encoding="utf-8")
    assert "| collisions (objective) |" in report and "lamp_distance" not in report


def test_counter_loads_are_tuned_as_program_variants(tmp_path: Path) -> None:
    """Line 5 of the counters BumberBot loads C1 with 107 pulses (its 270° spin): tuned to 40 pulses, a
    fleet robot runs exactly as that table written with 40 and run alone."""
    from dataclasses import replace

    from tablebot.cli.common import load
    from tablebot.fleet.cells import cell_variants, parse_cells
    from tablebot.fleet.plan import make_plan
    from tablebot.fleet.run import Fleet, RobotSpec
    from tablebot.machine import compile_table
    from tablebot.sim.model.scene import scene_for
    from tablebot.sim.runner import simulate
    from test_sim_helpers import BUMBERBOT, trace_text

    example = BUMBERBOT.parent / "bumberbot-counters"
    plan = make_plan(example, None, [], [], "0", None, 5.0)
    cells = parse_cells("line 5 C1_load=10..200", plan.table)
    assert (cells[0].column, cells[0].value, cells[0].low, cells[0].high) == ("C1_load", 107, 10, 200)
    fleet = Fleet(
        plan.table,
        plan.machine,
        plan.worlds[0],
        [RobotSpec(seed=2, variant=1)],
        plan.robot_params,
        traced=[0],
        variants=cell_variants(plan.tables, plan.machine, cells, [(107,), (40,)]),
    )
    fleet.run(500)
    table, _ = load(example)
    rows = tuple(replace(r, counters=(40, *r.counters[1:])) if r.line == 5 else r for r in table.rows)
    edited = replace(table, rows=rows)
    alone = simulate(scene_for(edited, compile_table(edited)), 5.0, 2)
    assert "".join(fleet.trace_lines(0)) == trace_text(alone)
    with pytest.raises(Exception, match="leaves C1 alone"):
        parse_cells("line 2 C1_load", plan.table)


def test_generations_are_cut_into_even_jobs_for_the_workers() -> None:
    from tablebot.fleet.tune import split

    assert split(528, 2) == [(0, 264), (264, 528)]  # not 512 + 16: one worker would wait on the other
    assert [b - a for a, b in split(1100, 2)] == [275] * 4  # 3 jobs would leave a worker idle half the time
    assert split(512, 2) == [(0, 512)] and split(40, 8) == [(0, 40)]  # one job: it runs on every core at once
    assert all(b - a <= 512 for a, b in split(100_000, 3)) and split(100_000, 3)[-1][1] == 100_000
