"""``tablebot sweep --grid "clock: line 2 timer=300,600"``: a table cell's values side by side (issue 36 §2: the
timers of every table), each run the run of the tables with that value written in; tune and the others refuse a
cell on their grid (tune has --cells), and a cell of an unknown table is an error naming --grid."""

from __future__ import annotations

import csv
import io
import shutil
from pathlib import Path

from typer.testing import CliRunner

from tablebot.cli import app
from test_tune_several import CLOCK, robot


def sweep(folder: Path, out: Path, *args: str) -> tuple[int, str]:
    result = CliRunner().invoke(
        app,
        [
            "sweep",
            str(folder / "drive.csv"),
            "--robot",
            str(folder / "robot.toml"),
            "--world",
            str(folder / "hall.toml"),
            "--seeds",
            "0..1",
            "--seconds",
            "9",
            "--no-plots",
            "--quiet",
            "--out",
            str(out),
            *args,
        ],
    )
    return result.exit_code, result.output


def results(out: Path) -> list[dict[str, str]]:
    return list(csv.DictReader(io.StringIO((out / "results.csv").read_text(encoding="utf-8"))))


def test_a_sweep_of_another_tables_timer_runs_each_value_as_that_table(tmp_path: Path) -> None:
    (tmp_path / "robot").mkdir()
    folder = robot(tmp_path / "robot")
    code, output = sweep(folder, tmp_path / "grid", "--grid", "clock: line 2 timer=300,600")
    assert code == 0, output
    rows = results(tmp_path / "grid")
    assert [(r["clock: line 2 timer"], r["seed"]) for r in rows] == [
        ("300", "0"),
        ("300", "1"),
        ("600", "0"),
        ("600", "1"),
    ]
    for value in (300, 600):
        edited = tmp_path / f"clock-{value}"
        shutil.copytree(folder, edited)
        (edited / "clock.csv").write_text(CLOCK.replace(",500,", f",{value},"), encoding="utf-8")
        code, output = sweep(edited, tmp_path / f"out-{value}")
        assert code == 0, output
        alone = results(tmp_path / f"out-{value}")
        mine = [r for r in rows if r["clock: line 2 timer"] == str(value)]
        assert [(r["distance_m"], r["final_state"], r["seconds"]) for r in mine] == [
            (r["distance_m"], r["final_state"], r["seconds"]) for r in alone
        ]
    assert float(rows[2]["distance_m"]) > 1.5 * float(rows[0]["distance_m"])  # twice the time driven


def test_tune_refuses_a_cell_on_its_grid_and_a_sweep_an_unknown_table(tmp_path: Path) -> None:
    folder = robot(tmp_path)
    result = CliRunner().invoke(
        app,
        [
            "tune",
            str(folder / "drive.csv"),
            "--robot",
            str(folder / "robot.toml"),
            "--cells",
            "clock: line 2 timer",
            "--grid",
            "clock: line 2 timer=5,6",
            "--out",
            str(tmp_path / "tune"),
        ],
    )
    assert result.exit_code == 2, result.output
    assert result.output.startswith("--grid: error: --grid clock: line 2 timer: only sweep"), result.output
    code, output = sweep(folder, tmp_path / "s", "--grid", "lamps: line 2 timer=5,6")
    assert code == 2 and output.startswith("--grid: error: --grid: 'lamps: line 2 timer': the robot has no table"), (
        output
    )
    code, output = sweep(folder, tmp_path / "s", "--grid", "clock: line 2 timer=5,x")
    assert code == 2 and "'x' is not a whole number from 0 to" in output, output
    assert not (tmp_path / "s").exists()
