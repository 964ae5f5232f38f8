"""``tablebot run --on sim``: the simulator through exactly the real run's code path (the loop one tick at a
time, paced in real time, the live trace) takes the decisions ``tablebot sim`` takes."""

from __future__ import annotations

import json
from pathlib import Path

from typer.testing import CliRunner

from core_helpers import EXAMPLE
from tablebot.cli import app

# A small room: the BumberBot meets the lamp and a wall within a second and a half.
BOX = """\
name = "small box"
reach = 0.1
[arena]
walls = [[0, 0], [0.6, 0], [0.6, 0.45], [0, 0.45]]
[start]
at = [0.25, 0.22]
heading = 10
[[lamp]]
at = [0.55, 0.4]
intensity = 1.0
"""
CORE = ("tick", "event", "row", "state", "timer", "M1", "M2")


def lines(path: Path) -> list[dict]:
    return [json.loads(line) for line in path.read_text(encoding="utf-8").splitlines()]


def test_run_on_sim_takes_the_decisions_tablebot_sim_takes_for_the_same_recorded_inputs(tmp_path: Path) -> None:
    world = tmp_path / "box.toml"
    world.write_text(BOX, encoding="utf-8")
    runner = CliRunner()
    live = runner.invoke(
        app,
        [
            "run",
            str(EXAMPLE),
            "--on",
            f"sim:{world}",
            "--seconds",
            "1.5",
            "--seed",
            "3",
            "--out",
            str(tmp_path / "run"),
        ],
    )
    assert live.exit_code == 0, live.output
    batch = runner.invoke(
        app,
        [
            "sim",
            str(EXAMPLE),
            "--world",
            str(world),
            "--seconds",
            "1.5",
            "--seed",
            "3",
            "--out",
            str(tmp_path / "sim"),
            "--no-plots",
            "-q",
        ],
    )
    assert batch.exit_code == 0, batch.output
    ran, simulated = lines(tmp_path / "run" / "trace.jsonl"), lines(tmp_path / "sim" / "trace.jsonl")
    assert len(ran) == len(simulated) == 150
    assert [{k: v for k, v in line.items() if k not in ("wall", "late_ms")} for line in ran] == simulated
    assert len({line["row"] for line in simulated}) >= 4  # it met the lamp and turned: real decisions
    replayed = runner.invoke(app, ["trace", str(EXAMPLE), "--inputs", str(tmp_path / "run" / "trace.jsonl")])
    assert [json.loads(line) for line in replayed.output.splitlines()] == [
        {k: line[k] for k in CORE} for line in simulated
    ]
