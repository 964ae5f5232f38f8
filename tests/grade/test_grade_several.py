"""``tablebot grade`` of a challenge whose robot has several tables (issue 36 §2): a pupil's table is the robot's
main table, run beside the challenge's other tables on the fleet (the whole robot's behaviour is graded), and
its score is what a sweep of that robot measures."""

from __future__ import annotations

import csv
import io
from pathlib import Path

from typer.testing import CliRunner

from tablebot.cli import app
from test_tune import HALL
from test_tune_several import CLOCK, DRIVE, ROBOT

CHALLENGE = """\
title = "Stop in time"
robot = "robot.toml"
worlds = ["hall.toml"]
seconds = 9
seeds = "0..3"
score = "distance"
"""


def test_a_pupils_table_runs_beside_the_challenges_other_tables(tmp_path: Path) -> None:
    """The pupil's drive table stops when the challenge's clock table has rung: run alone it would never stop
    (no clock), so the score is the sweep's distance only when the clock runs too."""
    challenge, pupil = tmp_path / "stop-in-time", tmp_path / "pia"
    challenge.mkdir()
    pupil.mkdir()
    for name, text in (
        ("challenge.toml", CHALLENGE),
        ("robot.toml", ROBOT),
        ("drive.csv", DRIVE),
        ("clock.csv", CLOCK),
        ("hall.toml", HALL),
    ):
        (challenge / name).write_text(text, encoding="utf-8")
    (pupil / "table.csv").write_text(DRIVE, encoding="utf-8")
    result = CliRunner().invoke(
        app, ["grade", str(challenge), str(pupil), "--out", str(tmp_path / "out"), "--workers", "1"]
    )
    assert result.exit_code == 0, result.output
    scores = list(csv.DictReader(io.StringIO((tmp_path / "out" / "scores.csv").read_text(encoding="utf-8"))))
    assert [(r["name"], r["rank"], r["why"]) for r in scores] == [("pia", "1", "")]
    swept = CliRunner().invoke(
        app,
        [
            "sweep",
            str(challenge / "drive.csv"),
            "--robot",
            str(challenge / "robot.toml"),
            "--world",
            str(challenge / "hall.toml"),
            "--seeds",
            "0..3",
            "--seconds",
            "9",
            "--no-plots",
            "--out",
            str(tmp_path / "sweep"),
        ],
    )
    assert swept.exit_code == 0, swept.output
    runs = list(csv.DictReader(io.StringIO((tmp_path / "sweep" / "results.csv").read_text(encoding="utf-8"))))
    mean = sum(float(r["distance_m"]) for r in runs) / len(runs)
    assert 0.5 < mean < 1.5  # it stopped: a minute's drive would be several metres (the hall's walls aside)
    assert float(scores[0]["score"]) == round(mean, 3)
    board = (tmp_path / "out" / "leaderboard.html").read_text(encoding="utf-8")
    assert "pia" in board and "best: seed" in board  # its replays were run again after the grading folder went


def test_a_pupils_own_copy_of_another_table_is_graded_with_it(tmp_path: Path) -> None:
    """A pupil who hands in the clock table too (beside the drive table) is graded with it: a clock that never
    rings never stops the robot, which then drives further than with the challenge's clock."""
    challenge, pupil = tmp_path / "stop-in-time", tmp_path / "pia"
    challenge.mkdir()
    pupil.mkdir()
    for name, text in (
        ("challenge.toml", CHALLENGE),
        ("robot.toml", ROBOT),
        ("drive.csv", DRIVE),
        ("clock.csv", CLOCK),
        ("hall.toml", HALL),
    ):
        (challenge / name).write_text(text, encoding="utf-8")
    (pupil / "table.csv").write_text(DRIVE, encoding="utf-8")
    (pupil / "clock.csv").write_text(CLOCK.replace(",500,", ",5000,"), encoding="utf-8")
    scores = {}
    for who in ("pia", "challenge"):
        if who == "challenge":
            (pupil / "clock.csv").unlink()
        out = tmp_path / f"out-{who}"
        result = CliRunner().invoke(app, ["grade", str(challenge), str(pupil), "--out", str(out), "--workers", "1"])
        assert result.exit_code == 0, result.output
        row = next(csv.DictReader(io.StringIO((out / "scores.csv").read_text(encoding="utf-8"))))
        assert row["why"] == "", row
        scores[who] = float(row["score"])
    assert scores["pia"] > scores["challenge"] + 0.2
