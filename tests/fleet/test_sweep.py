"""``tablebot sweep``: result rows, resume after an interrupt, pictures (on a Dask cluster: test_sweep_cluster.py;
bad options: test_sweep_errors.py)."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path
from typing import TYPE_CHECKING

import pytest
from typer.testing import CliRunner

from tablebot.cli import app
from tablebot.cli.common import load
from tablebot.fleet.run import Fleet, RobotSpec
from tablebot.fleet.store import read_results
from tablebot.sim.model.scene import robot_layer, scene_for
from tablebot.testing.dask_cluster import local_cluster
from test_sim_helpers import BUMBERBOT

if TYPE_CHECKING:
    from collections.abc import Iterator

ROOT = Path(__file__).resolve().parents[2]
SRC = ROOT / "src"


def sweep(*args: str) -> tuple[int, str]:
    result = CliRunner().invoke(app, ["sweep", str(BUMBERBOT), *args])
    return result.exit_code, result.output


def env() -> dict[str, str]:
    return {**os.environ, "PYTHONPATH": os.pathsep.join([str(SRC), os.environ.get("PYTHONPATH", "")])}


def test_a_sweep_writes_one_row_per_run_equal_to_the_fleet_and_resumes(tmp_path: Path) -> None:
    out = tmp_path / "s"
    code, output = sweep(
        "--grid",
        "battery=1.0,0.6",
        "--seeds",
        "3..5",
        "--seconds",
        "8",
        "--workers",
        "1",
        "--out",
        str(out),
        "--no-plots",
        "--trace",
        "4",
    )
    assert code == 0, output
    rows = read_results(out / "results.csv")
    alone = CliRunner().invoke(
        app,
        [
            "sim",
            str(BUMBERBOT),
            "--seconds",
            "8",
            "--seed",
            "4",
            "--battery",
            "0.6",
            "--no-plots",
            "--quiet",
            "--out",
            str(tmp_path / "sim"),
        ],
    )
    assert alone.exit_code == 0, alone.output
    assert (out / "trace-4.jsonl").read_bytes() == (tmp_path / "sim" / "trace.jsonl").read_bytes()
    assert [(r["run"], r["battery"], r["seed"]) for r in rows] == [
        ("0", "1.0", "3"),
        ("1", "1.0", "4"),
        ("2", "1.0", "5"),
        ("3", "0.6", "3"),
        ("4", "0.6", "4"),
        ("5", "0.6", "5"),
    ]
    table, machine = load(BUMBERBOT)
    fleet = Fleet(
        table,
        machine,
        scene_for(table, machine).world,
        [RobotSpec(seed=5, params=(("battery", "charge", 0.6),))],
        robot_layer(table.robot)[0],
    )
    fleet.run(800)
    sixth = fleet.summary().summary(0)
    assert float(rows[5]["distance_m"]) == round(sixth.distance_m, 6)
    assert int(rows[5]["collisions"]) == sixth.collisions
    assert float(rows[5]["battery_end_v"]) == round(sixth.battery_end_v, 6)
    before = {p.name: p.stat().st_mtime_ns for p in (out / "parts").iterdir()}
    code, output = sweep(
        "--grid",
        "battery=1.0,0.6",
        "--seeds",
        "3..5",
        "--seconds",
        "8",
        "--workers",
        "1",
        "--out",
        str(out),
        "--no-plots",
    )
    assert code == 0, output
    assert {p.name: p.stat().st_mtime_ns for p in (out / "parts").iterdir()} == before  # nothing ran again
    code, output = sweep("--seeds", "3..5", "--seconds", "9", "--out", str(out), "--no-plots")
    assert code == 2 and "--out holds the results of a different sweep" in output


@pytest.mark.parametrize("damage", ["cut", "empty", "edited"])
def test_a_damaged_part_is_made_again_not_merged(tmp_path: Path, damage: str) -> None:
    """A part cut short (a full disk, a copy stopped half way) was merged as it was: results.csv lost rows and
    joined two of them, and the sweep said nothing."""
    out, args = tmp_path / "s", ("--robots", "40", "--seconds", "2", "--no-plots", "--quiet")
    code, output = sweep(*args, "--out", str(out))
    assert code == 0, output
    whole = (out / "results.csv").read_bytes()
    parts = sorted((out / "parts").iterdir())
    assert len(parts) == 5, parts  # 8 robots each
    kept = {p.name: p.stat().st_mtime_ns for p in parts}
    text = parts[2].read_text(encoding="utf-8")
    parts[2].write_text(
        {"cut": text[: len(text) // 2], "empty": "", "edited": text.replace("\n17,", "\n71,")}[damage], encoding="utf-8"
    )
    code, output = sweep(*args, "--out", str(out))
    assert code == 0, output
    assert f"{parts[2]}: note: this part of the sweep is damaged" in output and "runs 16..23" in output
    assert (out / "results.csv").read_bytes() == whole
    assert {p.name: p.stat().st_mtime_ns for p in parts if p != parts[2]} == {
        name: ns for name, ns in kept.items() if name != parts[2].name
    }  # only the damaged part ran again


def test_each_row_carries_the_start_its_robot_ran_from(tmp_path: Path) -> None:
    """Random starts as the plan draws them (the traced run begins there), given poses as given."""
    from tablebot.fleet.plan import make_plan
    from tablebot.fleet.spec import runs

    out = tmp_path / "s"
    code, output = sweep(
        "--grid",
        "start=random,0.5:0.5:20",
        "--seeds",
        "0..2",
        "--seconds",
        "1",
        "--workers",
        "1",
        "--out",
        str(out),
        "--no-plots",
        "--trace",
        "1",
    )
    assert code == 0, output
    rows = read_results(out / "results.csv")
    starts = [(float(r["start_x"]), float(r["start_y"]), float(r["start_heading"])) for r in rows]
    plan = make_plan(BUMBERBOT, None, [], ["start=random"], "0..2", None, 1.0)
    assert starts[:3] == [plan.robot(run).start for run in runs(plan.spec)]
    assert len(set(starts[:3])) == 3 and starts[3:] == [(0.5, 0.5, 20.0)] * 3
    first = json.loads((out / "trace-1.jsonl").read_text(encoding="utf-8").splitlines()[0])
    assert (first["x"], first["y"], first["heading"]) == starts[1]
    counted = [line.split(": ")[1].split()[0] for line in output.splitlines() if line.startswith("start ")]
    assert [c.split("/")[1] for c in counted] == ["3", "3"], output  # random starts are not every start


def test_a_random_start_fits_every_body_of_the_grid(tmp_path: Path) -> None:
    """Drawn once per seed for every grid value (common random numbers), so free for the widest body too."""
    out = tmp_path / "s"
    code, output = sweep(
        "--grid",
        "start=random",
        "--grid",
        "body.half_width=0.09,0.2",
        "--robots",
        "60",
        "--seconds",
        "0.1",
        "--workers",
        "1",
        "--out",
        str(out),
        "--no-plots",
    )
    assert code == 0, output
    rows = read_results(out / "results.csv")
    starts = [(r["seed"], r["start_x"], r["start_y"], r["start_heading"]) for r in rows]
    assert starts[:60] == starts[60:] and len(set(starts)) == 60


def test_worlds_are_told_apart_by_name(tmp_path: Path) -> None:
    """Two files both called arena.toml: the summary (and outcomes.png) name each world, its own runs."""
    other = BUMBERBOT.parent / "obstacle-avoider" / "arena.toml"
    code, output = sweep(
        "--world",
        str(BUMBERBOT / "arena.toml"),
        "--world",
        str(other),
        "--seeds",
        "0..1",
        "--seconds",
        "1",
        "--workers",
        "1",
        "--out",
        str(tmp_path / "s"),
        "--no-plots",
    )
    assert code == 0, output
    worlds = [line.split(": ")[0] for line in output.splitlines() if line.startswith("world ")]
    assert worlds == ["world BumberBot arena", "world cluttered room"], output
    assert output.count("/2 ") == 2, output


def test_ctrl_c_keeps_finished_chunks_and_the_same_command_resumes(tmp_path: Path) -> None:
    out = tmp_path / "s"
    command = [
        sys.executable,
        "-m",
        "tablebot",
        "sweep",
        str(BUMBERBOT),
        "--grid",
        "start=random",
        "--seeds",
        "0..255",
        "--seconds",
        "30",
        "--workers",
        "2",
        "--out",
        str(out),
        "--no-plots",
    ]
    proc = subprocess.Popen(command, env=env(), stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 120
    while not ((out / "parts").is_dir() and any((out / "parts").glob("runs-*.csv"))):  # a finished part
        assert proc.poll() is None and time.monotonic() < deadline, proc.communicate()
        time.sleep(0.05)
    proc.send_signal(signal.SIGINT)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 130, err
    assert "run the same command again to resume" in err
    kept = read_results(out / "results.partial.csv")
    assert 0 < len(kept) < 256 and not (out / "results.csv").exists()
    parts = {p.name: p.read_bytes() for p in (out / "parts").iterdir()}
    done = subprocess.run(command, env=env(), capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    rows = read_results(out / "results.csv")
    assert [int(r["run"]) for r in rows] == list(range(256))
    assert {r["run"]: r for r in kept}.items() <= {r["run"]: r for r in rows}.items()
    assert all((out / "parts" / name).read_bytes() == data for name, data in parts.items())
    assert not (out / "results.partial.csv").exists()


@pytest.fixture
def dask_cluster() -> Iterator[str]:
    """A real Dask scheduler and two single-threaded workers on this machine (separate processes), one of
    them started with tablebot's preload (tablebot.fleet.worker), one plain."""
    pytest.importorskip("distributed", reason="the Dask backend needs the cluster extra (the dev extra has it)")
    with local_cluster([[], ["--preload", "tablebot.fleet.worker"]], env()) as cluster:
        yield cluster.address


def test_a_sweep_draws_its_pictures(tmp_path: Path) -> None:
    """Outcomes, start positions, and the best and worst runs' trajectories (rerun alone, drawn like sim's)."""
    from PIL import Image

    out = tmp_path / "s"
    code, output = sweep(
        "--grid", "start=random", "--seeds", "0..5", "--seconds", "20", "--workers", "1", "--out", str(out)
    )
    assert code == 0, output
    for name in ("outcomes", "starts", "best", "worst"):
        with Image.open(out / f"{name}.png") as image:
            assert image.format == "PNG" and image.width > 600, name


def test_result_rows_are_what_csv_writes_for_each_robots_own_numbers(tmp_path: Path) -> None:
    """results.csv (built column by column) against a row per robot, as dicts through csv.DictWriter, of the
    fleet's own numbers rounded by Python's round: two worlds (one behind a path csv must quote), a grid."""
    import csv
    import io
    import shutil

    from tablebot.fleet.plan import make_plan
    from tablebot.fleet.spec import runs

    quoted = tmp_path / 'a "b", c' / "arena.toml"
    quoted.parent.mkdir()
    shutil.copy(BUMBERBOT.parent / "obstacle-avoider" / "arena.toml", quoted)
    worlds, grid = [BUMBERBOT / "arena.toml", quoted], ["battery=1.0,0.55"]
    code, output = sweep(
        *(a for w in worlds for a in ("--world", str(w))),
        "--grid",
        grid[0],
        "--seeds",
        "0..4",
        "--seconds",
        "3",
        "--out",
        str(tmp_path / "s"),
        "--no-plots",
    )
    assert code == 0, output
    plan = make_plan(BUMBERBOT, None, worlds, grid, "0..4", None, 3.0)
    tick_s = plan.machine.table.robot.tick_s

    def when(tick: int) -> float | None:
        return None if tick < 0 else round(tick * tick_s, 6)

    rows = []
    for world in range(2):
        chosen = [run for run in runs(plan.spec) if run.world == world]
        fleet = Fleet(
            plan.table, plan.machine, plan.worlds[world], [plan.robot(run) for run in chosen], plan.robot_params
        )
        fleet.run(plan.spec.ticks)
        s = fleet.summary()
        for k, run in enumerate(chosen):
            rows.append(
                {
                    "run": run.index,
                    "world": plan.spec.worlds[world],
                    "seed": run.seed,
                    "battery": run.values[0],
                    **dict(zip(("start_x", "start_y", "start_heading"), plan.worlds[world].start, strict=True)),
                    "seconds": round(s.ticks * tick_s, 6),
                    "first_light_s": when(s.first_light[k]),
                    "reached": int(s.reached[k] >= 0),
                    "reached_s": when(s.reached[k]),
                    "collisions": int(s.collisions[k]),
                    "distance_m": round(float(s.distance_m[k]), 6),
                    "battery_start_v": round(float(s.battery_start_v[k]), 6),
                    "battery_end_v": round(float(s.battery_end_v[k]), 6),
                    "final_state": plan.machine.states[s.final_state[k]],
                    **{
                        f"time_{state}_s": round(float(s.counts[k, j]) * tick_s, 6)
                        for j, state in enumerate(plan.machine.states)
                    },
                }
            )
    expected = io.StringIO()
    writer = csv.DictWriter(expected, plan.columns(), lineterminator="\n")
    writer.writeheader()
    writer.writerows(rows)
    assert (tmp_path / "s" / "results.csv").read_text(encoding="utf-8") == expected.getvalue()
    assert '"' in expected.getvalue()
