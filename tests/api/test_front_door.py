"""The front door (tablebot.api) and the commands write the same bytes: each command is the library call with
its options, so a call's results saved by the library, in memory or straight into a folder, are the files the
command writes for the same arguments (sim's trace and pictures, check --format json and its counterexamples,
sweep's results, tune's and evolve's outputs, export to C). The commands run in this process (CliRunner), in a
copy of the examples; report.md's seconds of wall-clock time are the one thing that may differ."""

from __future__ import annotations

import doctest
import importlib
import json
import re
import shutil
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

import tablebot
from doc_commands import examples_copy
from tablebot.cli import app
from tablebot.diagnostics import TableBotError

#: report.md says how long tune and evolve took: wall-clock seconds, different in every run.
WALL_RE = re.compile(r"\b\d+(\.\d+)? s\b")


@pytest.fixture
def here(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """A folder with a copy of the examples, the working folder of the test."""
    monkeypatch.chdir(examples_copy(tmp_path))
    return tmp_path


def command(*argv: str) -> str:
    """Run a tablebot command; its standard output (it must succeed)."""
    result = CliRunner().invoke(app, list(argv), catch_exceptions=False)
    assert result.exit_code == 0, result.output
    return result.stdout


def contents(folder: Path) -> dict[str, bytes]:
    """Every file under ``folder`` by its path there; report.md with its wall-clock seconds masked."""
    found = {}
    for path in sorted(p for p in folder.rglob("*") if p.is_file()):
        data = path.read_bytes()
        if path.name == "report.md":
            data = WALL_RE.sub("N s", data.decode("utf-8")).encode("utf-8")
        found[str(path.relative_to(folder))] = data
    return found


def moved(folder: str, to: str) -> Path:
    """``folder`` renamed to ``to``: the next writer uses the same name (the outputs name their folder)."""
    return Path(shutil.move(folder, to))


def test_sim_saved_from_memory_and_run_into_a_folder_is_what_sim_writes(here: Path) -> None:
    # 42 s: two of the trace writer's blocks (4096 ticks each), and the painter draws the path as the run goes
    command(
        "sim",
        "examples/bumberbot",
        "--seconds",
        "42",
        "--seed",
        "3",
        "--battery",
        "0.7",
        "--html",
        "--out",
        "cli",
        "-q",
    )
    robot = tablebot.open("examples/bumberbot")
    run = robot.simulate(seconds=42, seed=3, battery=0.7)
    assert [p.name for p in run.save("memory", html=True)] == [
        "trace.jsonl",
        "trajectory.png",
        "timeline.png",
        "run.html",
    ]
    into = robot.simulate(seconds=42, seed=3, battery=0.7, out="into", html=True)
    expected = contents(Path("cli"))
    assert set(expected) == {"trace.jsonl", "trajectory.png", "timeline.png", "run.html"}
    assert contents(Path("memory")) == expected
    assert contents(Path("into")) == expected
    # the trace as numbers: one record per tick, the values the trace file holds (no row fired: -1, not null)
    lines = [json.loads(line) for line in (here / "cli" / "trace.jsonl").read_text().splitlines()]
    for trace in (run.trace, into.trace):  # made from the run's rows, and read from the trace it wrote
        assert len(trace) == len(lines) == 4200
        assert list(trace.dtype.names or ()) == list(lines[0])
        for key in lines[0]:
            assert trace[key].tolist() == [-1 if line[key] is None else line[key] for line in lines], key
    assert run.summary == into.summary and run.summary is not None and run.summary.seconds == 42


def test_a_sim_animation_is_the_commands(here: Path) -> None:
    command("sim", "examples/bumberbot", "--seconds", "2", "--gif", "--no-plots", "--out", "cli", "-q")
    robot = tablebot.open("examples/bumberbot")
    robot.simulate(seconds=2).save("memory", plots=False, gif=True)
    robot.simulate(seconds=2, out="into", plots=False, gif=True)
    expected = contents(Path("cli"))
    assert set(expected) == {"trace.jsonl", "run.gif"}
    assert contents(Path("memory")) == contents(Path("into")) == expected


def test_check_json_and_counterexamples_are_the_commands(here: Path) -> None:
    printed = command("check", "examples/bumberbot", "--format", "json", "--counterexamples", "cex")
    cli = contents(moved("cex", "cli"))  # the JSON names the files: the library writes them under the same name
    report = tablebot.open("examples/bumberbot").check()
    written = report.write_counterexamples("cex")
    assert report.json_text() == printed
    assert written and contents(Path("cex")) == cli
    said = json.loads(printed)
    assert report.ok == (said["exit_code"] == 0)
    assert {p.name: p.status for p in report.properties} == {p["name"]: p["status"] for p in said["properties"]}
    assert [f.as_json() for f in report.findings] == said["findings"]


def test_sweep_results_traces_and_pictures_are_the_commands(here: Path) -> None:
    options = ["--robots", "3", "--seconds", "2", "--grid", "battery=1.0,0.6", "--trace", "0,5"]
    command("sweep", "examples/bumberbot", *options, "--out", "cli", "-q")
    robot = tablebot.open("examples/bumberbot")
    memory = robot.sweep(robots=3, seconds=2, grid=["battery=1.0,0.6"])
    memory.save("memory", trace=[0, 5])
    robot.sweep(robots=3, seconds=2, grid=["battery=1.0,0.6"], trace="0,5", out="into")
    expected = contents(Path("cli"))
    assert {"results.csv", "trace-0.jsonl", "trace-5.jsonl", "outcomes.png"} <= set(expected)
    assert contents(Path("into")) == expected  # parts and spec.json too: the same sweep, resumable by either
    assert contents(Path("memory")) == {k: v for k, v in expected.items() if k != "spec.json" and "parts" not in k}
    assert list(memory.results["run"]) == list(range(6))
    assert list(memory.results["battery"]) == [1.0, 1.0, 1.0, 0.6, 0.6, 0.6]
    assert memory.results.dtype["distance_m"] == np.float64 and memory.results.dtype["world"].kind == "U"


def test_tune_outputs_are_the_commands(here: Path) -> None:
    options = {"objective": "collisions", "budget": 3, "seeds": "0..1", "check_seeds": "9..10", "seconds": 2}
    command(
        "tune",
        "examples/bumberbot",
        "--cells",
        "line 5 timer",
        "--objective",
        "collisions",
        "--budget",
        "3",
        "--seeds",
        "0..1",
        "--check-seeds",
        "9..10",
        "--seconds",
        "2",
        "--out",
        "out",
        "-q",
    )
    cli = contents(moved("out", "cli"))
    robot = tablebot.open("examples/bumberbot")
    into = robot.tune("line 5 timer", out="out", **options)  # type: ignore[arg-type]  # (a dict of mixed values)
    assert contents(moved("out", "into")) == cli
    memory = robot.tune("line 5 timer", **options)  # type: ignore[arg-type]
    memory.save("out")
    assert contents(Path("out")) == cli
    assert set(cli) == {"table.tuned.csv", "evaluations.csv", "convergence.png", "report.md"}
    assert len(into.history) == 3 and into.winner == memory.winner


def test_evolve_outputs_are_the_commands(here: Path) -> None:
    command(
        "evolve",
        "examples/bumberbot",
        "--budget",
        "2",
        "--batch",
        "1",
        "--seeds",
        "0..1",
        "--check-seeds",
        "9..10",
        "--seconds",
        "1",
        "--workers",
        "1",
        "--out",
        "out",
        "-q",
    )
    cli = contents(moved("out", "cli"))
    evolved = tablebot.open("examples/bumberbot").evolve(
        out="out", budget=2, batch=1, seeds="0..1", check_seeds="9..10", seconds=1, workers=1
    )
    assert contents(Path("out")) == cli
    assert {"report.md", "archive.png", "best-1.csv", "evaluations.csv"} <= set(cli)
    assert len(evolved.outcome.order) >= 2


def test_export_to_c_is_the_commands(here: Path) -> None:
    command("export", "examples/bumberbot", "cli", "--to", "c")
    done = tablebot.open("examples/bumberbot").export(to="c", out="library")
    assert contents(Path("library")) == contents(Path("cli"))
    assert sorted(p.name for p in done.files) == ["tb_config.h", "tb_engine.c", "tb_engine.h", "tb_table.c"]


@pytest.mark.parametrize(
    "module",
    [
        "api",
        "api.project",
        "api.simulation",
        "api.checking",
        "api.sweeping",
        "api.tuning",
        "api.evolution",
        "api.exporting",
        "api.running",
        "api.progress",
    ],
)
def test_the_examples_in_the_docstrings_hold(module: str, here: Path) -> None:
    """Each result type's docstring shows it in use (docs/api.md shows them): what they show is what it does."""
    result = doctest.testmod(importlib.import_module(f"tablebot.{module}"))
    assert result.attempted and not result.failed


def test_the_library_keeps_the_commands_rule_on_replacing_a_users_table(here: Path) -> None:
    """A tuned table is a table a user may have edited since: a second tuning into the same folder replaces it
    only with force=True (the command's --force), the old one kept as NAME.bak, from Python as from the command."""
    robot = tablebot.open("examples/bumberbot")
    options = {"objective": "collisions", "budget": 2, "seeds": "0..1", "check_seeds": "9..10", "seconds": 1}
    robot.tune("line 5 timer", out="out", **options)  # type: ignore[arg-type]  # (a dict of mixed values)
    tuned = here / "out" / "table.tuned.csv"
    tuned.write_text(tuned.read_text() + "# my note\n")
    with pytest.raises(TableBotError, match="not replaced without --force"):
        robot.tune("line 5 timer", out="out", **options)  # type: ignore[arg-type]
    assert tuned.read_text().endswith("# my note\n")
    robot.tune("line 5 timer", out="out", force=True, **options)  # type: ignore[arg-type]
    assert (here / "out" / "table.tuned.csv.bak").read_text().endswith("# my note\n")
    assert not tuned.read_text().endswith("# my note\n")
