"""``tablebot run --on txt://...`` of a robot of several tables (issue 36 §2) against the fake TXT on loopback:
every table runs (the lamps the lights table writes reach the controller, the trace names the lights table's
decisions) and ``tablebot trace`` replays the live trace's inputs to the same decisions of both tables."""

from __future__ import annotations

import json
from pathlib import Path

from test_run_cli import bumps, invoke, read_trace
from txt_fake import FakeTxt

LIGHTS = Path(__file__).resolve().parents[2] / "examples" / "bumberbot-lights"


def test_a_live_run_of_several_tables_replays_to_the_same_decisions(tmp_path: Path) -> None:
    with FakeTxt(bumps()) as fake:
        result = invoke(
            "run",
            LIGHTS,
            "--on",
            f"txt://127.0.0.1:{fake.port}",
            "--seconds",
            "0.8",
            "--out",
            tmp_path,
            "--link-timeout",
            "1",
        )
    assert result.exit_code == 0, result.output
    lines = read_trace(tmp_path / "trace.jsonl")
    assert len(lines) == 80
    assert len({line["lights.state"] for line in lines}) >= 2  # the lights table ran
    assert any(line["L1"] or line["L2"] for line in lines)  # and its lamps are the robot's
    replayed = invoke("trace", LIGHTS, "--inputs", tmp_path / "trace.jsonl")
    assert replayed.exit_code == 0, replayed.output
    again = [json.loads(line) for line in replayed.output.splitlines()]
    assert again == [{key: line[key] for key in want} for line, want in zip(lines, again, strict=True)]
    assert {"lights.event", "lights.row", "lights.state", "lights.timer"} <= set(again[0])


def test_a_lost_link_stops_every_tables_outputs(tmp_path: Path) -> None:
    """The lamps the lights table drives are off when the link is lost, as the motors are: one loop stops them."""
    with FakeTxt(bumps(), fault=("silent", 20)) as fake:
        result = invoke(
            "run",
            LIGHTS,
            "--on",
            f"txt://127.0.0.1:{fake.port}",
            "--seconds",
            "5",
            "--out",
            tmp_path,
            "--link-timeout",
            "0.1",
        )
    assert result.exit_code == 3 and "link_lost" in result.output and "Traceback" not in result.output
    lines = read_trace(tmp_path / "trace.partial.jsonl")
    assert lines[-1]["end"] == "link_lost" and any(line.get("L1") or line.get("L2") for line in lines[:-1])
    assert fake.last_exchange_before_stop().fields["pwm"] == [0] * 8
