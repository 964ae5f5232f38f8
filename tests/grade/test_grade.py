"""`tablebot grade`: the shipped challenges graded from tables, folders and share links; a table that breaks a
rule scores nothing (with the counterexample's words), a broken submission is listed and never stops the
others, a submission reads nothing outside its own files; scores.csv is the same bytes locally and on a real
Dask cluster; leaderboard.html and its replays open offline in Chromium with no console error."""

from __future__ import annotations

import csv
import io
import shutil
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
from typer.testing import CliRunner

from studio_helpers import Browsers
from tablebot import share
from tablebot.cli import app
from test_sweep import dask_cluster, env  # noqa: F401  (dask_cluster: a real scheduler and two workers)

ROOT = Path(__file__).resolve().parents[2]
CHALLENGES = ROOT / "examples" / "challenges"
LAMP, LAPS = CHALLENGES / "find-the-lamp", CHALLENGES / "line-laps"
FIXED = ROOT / "tests" / "fixtures" / "analysis" / "bumberbot_fixed.csv"


def grade(*args: str | Path) -> tuple[int, str]:
    result = CliRunner().invoke(app, ["grade", *map(str, args)])
    return result.exit_code, result.output


def rows(out: Path) -> list[dict[str, str]]:
    return list(csv.DictReader(io.StringIO((out / "scores.csv").read_text(encoding="utf-8"))))


@pytest.fixture(scope="module")
def pupils(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A class's work on find-the-lamp: the BumberBot as shipped (it breaks a rule), a fixed one in a folder,
    a table with an error, a folder with no table, a line follower (another robot), and two share links
    (the fixed BumberBot's, and one cut short) in a text file."""
    root = tmp_path_factory.mktemp("pupils")
    (root / "anna").mkdir()
    shutil.copy(FIXED, root / "anna" / "table.csv")
    shutil.copytree(ROOT / "examples" / "bumberbot", root / "ben")
    (root / "carl.csv").write_text("description,state,T,I3,I4,I5,I7,I8,M1,M2,timer,next\ngo,1,1,,,,,,9,6,1s,1\n")
    (root / "dora").mkdir()
    shutil.copytree(ROOT / "examples" / "line-follower", root / "emil")
    link = share.encode(share.collect(root / "anna"))
    (root / "links.txt").write_text(f"# the class's links\n{link}\n\n{link[:-30]}\n")
    return root


@pytest.fixture(scope="module")
def graded(pupils: Path, tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("graded") / "out"
    code, output = grade(
        LAMP,
        *(pupils / n for n in ("anna", "ben", "carl.csv", "dora", "emil", "links.txt")),
        "--out",
        out,
        "--workers",
        "2",
    )
    assert code == 0, output
    return out


def test_the_class_is_graded_and_ranked(graded: Path) -> None:
    table = rows(graded)
    assert [r["name"] for r in table] == ["anna", "anna (2)", "ben", "carl.csv", "dora", "emil", "links.txt:4"]
    assert [r["rank"] for r in table] == ["1", "1", "", "", "", "", ""]  # the same table by link: a tie
    assert table[0]["score"] == table[1]["score"] and 0 < float(table[0]["score"]) < 60
    assert all(r["score"] == "" for r in table[2:]) and all(r["why"] for r in table[2:])
    assert table[0]["why"] == ""


def test_a_table_that_breaks_a_rule_scores_nothing_with_the_counterexamples_words(graded: Path) -> None:
    ben = next(r for r in rows(graded) if r["name"] == "ben")
    assert ben["score"] == "" and ben["why"].startswith(
        "breaks front_bumper_stops (whenever a front bumper is "
        "pressed, within 1 tick both motors are stopped or reversing)"
    )
    assert "state 29" in ben["why"] and "(it shows here)" in ben["why"]


def test_broken_submissions_are_listed_with_their_errors(graded: Path) -> None:
    why = {r["name"]: r["why"] for r in rows(graded)}
    assert why["carl.csv"].startswith("carl.csv:2:") and "9" in why["carl.csv"]  # the motor of 9, located
    assert why["dora"] == "no table.csv in this folder"
    assert why["emil"].startswith("robot.toml: its robot file is not the challenge's robot: its inputs differ")
    assert "cut short or damaged" in why["links.txt:4"]
    assert "/" not in why["carl.csv"].split(":")[0]  # no path of this machine in scores.csv


def test_the_linked_submission_is_kept_for_the_teacher(graded: Path, pupils: Path) -> None:
    assert (graded / "submissions" / "anna" / "table.csv").read_bytes() == (pupils / "anna" / "table.csv").read_bytes()


def test_a_submission_reads_nothing_outside_its_own_files(tmp_path: Path) -> None:
    secret = tmp_path / "elsewhere.toml"
    secret.write_text((ROOT / "examples" / "bumberbot" / "arena.toml").read_text())
    linked = tmp_path / "linked"
    linked.mkdir()
    (linked / "table.csv").symlink_to(FIXED)
    worldly = tmp_path / "worldly"
    worldly.mkdir()
    shutil.copy(FIXED, worldly / "table.csv")
    robot = (LAMP / "robot.toml").read_text() + f'\n[sim]\nworld = "{secret}"\n'
    (worldly / "robot.toml").write_text(robot)
    code, output = grade(LAMP, linked, worldly, "--out", tmp_path / "out", "--workers", "1")
    assert code == 0, output
    why = {r["name"]: r["why"] for r in rows(tmp_path / "out")}
    assert (
        why["linked"] == "table.csv: this file is a link to a file outside the submission (hand in the file "
        "itself, not a link to it)"
    )
    assert why["worldly"].startswith(f"robot.toml: sim.world names {secret}, a file outside the submission")


def test_line_laps_ranks_more_laps_first(tmp_path: Path) -> None:
    slow = tmp_path / "slow"
    shutil.copytree(ROOT / "examples" / "line-follower", slow)
    text = (slow / "table.csv").read_text()
    (slow / "table.csv").write_text(text.replace(",6,6,", ",4,4,", 1))
    code, output = grade(
        "line-laps", ROOT / "examples" / "line-follower", slow, "--out", tmp_path / "out", "--workers", "2"
    )  # a shipped challenge by its name
    assert code == 0, output
    table = rows(tmp_path / "out")
    assert [r["rank"] for r in table] == ["1", "2"], table
    assert [r["name"] for r in table] == ["line-follower", "slow"] and float(table[0]["score"]) > 1


def test_dask_grades_both_shipped_challenges_byte_for_byte_as_this_machine(
    graded: Path,
    pupils: Path,
    tmp_path: Path,
    dask_cluster: str,  # noqa: F811  (the fixture imported from test_sweep)
) -> None:
    code, output = grade(
        LAMP,
        *(pupils / n for n in ("anna", "ben", "carl.csv", "dora", "emil", "links.txt")),
        "--out",
        tmp_path / "dask",
        "--scheduler",
        dask_cluster,
    )
    assert code == 0, output
    assert (tmp_path / "dask" / "scores.csv").read_bytes() == (graded / "scores.csv").read_bytes()
    assert (tmp_path / "dask" / "leaderboard.html").read_bytes() == (graded / "leaderboard.html").read_bytes()
    laps = [ROOT / "examples" / "line-follower", pupils / "emil"]
    code, output = grade(LAPS, *laps, "--out", tmp_path / "laps-local", "--workers", "2")
    assert code == 0, output
    code, output = grade(LAPS, *laps, "--out", tmp_path / "laps-dask", "--scheduler", dask_cluster)
    assert code == 0, output
    local = (tmp_path / "laps-local" / "scores.csv").read_bytes()
    assert local == (tmp_path / "laps-dask" / "scores.csv").read_bytes() and local.count(b",,") == 0  # both ranked


@pytest.fixture(scope="module")
def browser(browsers: Browsers) -> Iterator[Any]:
    yield from browsers.module()


def test_the_leaderboard_opens_offline_with_no_console_error(graded: Path, browser: Any) -> None:
    """One file: the board, and each replay unpacked from it into a frame over the board (Esc closes it)."""
    assert sorted(p.name for p in graded.iterdir()) == ["leaderboard.html", "scores.csv", "submissions"]
    context = browser.new_context(offline=True, viewport={"width": 1280, "height": 720})
    page = context.new_page()
    errors: list[str] = []
    page.on("console", lambda m: errors.append(m.text) if m.type == "error" else None)
    page.on("pageerror", lambda e: errors.append(str(e)))
    requests: list[str] = []
    page.on("request", lambda r: requests.append(r.url))
    page.goto((graded / "leaderboard.html").as_uri())
    assert page.locator("tbody tr").count() == 7
    assert "breaks front_bumper_stops" in page.locator("tbody").inner_text()
    page.screenshot(path=str(graded.parent / "leaderboard.png"), full_page=True)
    page.locator("button.replay", has_text="worst").first.click()
    replay = page.frame_locator("#viewer iframe")
    replay.locator("#title").wait_for(timeout=20_000)
    assert replay.locator("#title").inner_text().startswith("anna: worst: seed ")
    replay.locator("#tplay").click()
    page.wait_for_timeout(500)
    page.screenshot(path=str(graded.parent / "replay.png"))
    page.keyboard.press("Escape")
    assert page.locator("#viewer").is_hidden()
    assert errors == [] and all(url.startswith("file://") for url in requests), (errors, requests)
    context.close()


@pytest.mark.parametrize("module", ["tablebot.grade", "tablebot.share"])
def test_the_examples_in_the_docstrings_hold(module: str, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    import doctest
    import importlib

    (tmp_path / "examples").symlink_to(ROOT / "examples")
    monkeypatch.chdir(tmp_path)
    result = doctest.testmod(importlib.import_module(module))
    assert result.attempted and not result.failed


def test_a_broken_challenge_is_refused_with_every_mistake_located(tmp_path: Path) -> None:
    for name in ("robot.toml", "rules.toml", "track.toml"):
        shutil.copy(LAPS / name, tmp_path / name)
    (tmp_path / "challenge.toml").write_text(
        'title = "x"\nrobot = "robot.toml"\nworlds = ["track.toml", "nowhere"]\n'
        'seconds = 99999\nseeds = "5..1"\nscore = "laps"\ncolour = 3\n'
    )
    code, output = grade(tmp_path, ROOT / "examples" / "line-follower", "--out", tmp_path / "out")
    assert code == 2 and "Traceback" not in output
    for words in (
        "challenge.toml:7: error: unknown key 'colour'",
        "challenge.toml:3:1: error: worlds[1]: nowhere is neither a file",
        "challenge.toml:4: error: seconds = 99999 is out of range",
        "challenge.toml:5:1: error: seeds 5..1 is an empty range",
    ):
        assert words in output
    (tmp_path / "challenge.toml").write_text(
        'title = "x"\nrobot = "robot.toml"\nworlds = ["track.toml"]\n'
        'seconds = 9\nseeds = "0..1"\nscore = "time_to_lamp"\n'
    )
    code, output = grade(tmp_path, ROOT / "examples" / "line-follower", "--out", tmp_path / "out")
    assert code == 2 and "challenge.toml:6:1: error: score = 'time_to_lamp': the worlds cannot measure it" in output
    assert not (tmp_path / "out").exists()
