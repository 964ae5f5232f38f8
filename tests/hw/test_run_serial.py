"""``tablebot run --on robotx://PTY`` and ``--on roboif://PTY`` end to end, as a process, against the emulators:
the live trace replays to the same decisions, a lost link ends with a record and exit 3, Ctrl-C and SIGTERM stop
the outputs and keep the trace, a table that does not fit is refused before the port is opened."""

from __future__ import annotations

import json
import os
import random
import signal
import subprocess
import sys
from pathlib import Path
from typing import TYPE_CHECKING

import pytest
from typer.testing import CliRunner

from core_helpers import EXAMPLE
from tablebot.cli import app
from tablebot.hw.link_speed import PROBES
from tablebot.testing.roboif_emulator import RoboifEmulator
from tablebot.testing.robotx_emulator import RobotxEmulator

pytestmark = [pytest.mark.realtime]

if TYPE_CHECKING:
    from collections.abc import Callable
    from typing import Any

    from tablebot.testing.pty_device import Request

ROOT = Path(__file__).resolve().parents[2]
CORE = ("tick", "event", "row", "state", "timer", "M1", "M2")
runner = CliRunner()


def bumps(kind: str, seed: int = 3) -> Callable[[int], tuple[list[int], Any]]:  # Any: a list or a dict, by kind
    """Bumpers and light that change every few ticks, so the BumberBot takes many different rows."""
    rng = random.Random(seed)
    held = [
        [0, 0, rng.randint(0, 1), rng.randint(0, 1), rng.randint(0, 1), 0, rng.randint(0, 1), rng.randint(0, 1)]
        for _ in range(200)
    ]
    other: list[int] | dict[str, int] = [0, 0, 0, 0] if kind == "robotx" else {}
    return lambda n: (held[(max(0, n - PROBES) // 7) % len(held)], other)  # the same inputs whatever timing came first


def emulator(kind: str, **options: Any) -> RobotxEmulator | RoboifEmulator:
    return (RobotxEmulator if kind == "robotx" else RoboifEmulator)(bumps(kind), **options)


def off(kind: str, request: Request) -> bool:
    """Whether an exchange the emulator logged switched every output off."""
    if kind == "robotx":
        return request.fields["duty"] == [0] * 8
    return request.fields["outputs"] == 0 and request.fields["pwm"] == [0] * 8


def spawn(args: list[str]) -> subprocess.Popen:
    env = {**os.environ, "PYTHONPATH": str(ROOT / "src")}
    return subprocess.Popen(
        [sys.executable, "-m", "tablebot", *args], env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True
    )


def read_trace(path: Path) -> list[dict]:
    return [json.loads(line) for line in path.read_text(encoding="utf-8").splitlines()]


@pytest.mark.parametrize("kind", ["robotx", "roboif"])
def test_a_run_as_a_process_writes_a_trace_that_tablebot_trace_replays_to_the_same_decisions(
    tmp_path: Path, kind: str
) -> None:
    with emulator(kind) as emu:
        process = spawn(
            [
                "run",
                str(EXAMPLE),
                "--on",
                f"{kind}://{emu.device}",
                "--seconds",
                "0.8",
                "--out",
                str(tmp_path),
                "--link-timeout",
                "0.3",
            ]
        )
        out, err = process.communicate(timeout=60)
    assert process.returncode == 0, err
    assert "ran 80 ticks (0.80 s): done" in out and "Traceback" not in err
    lines = read_trace(tmp_path / "trace.jsonl")
    assert len(lines) == 80 and len({line["row"] for line in lines}) > 3
    replayed = runner.invoke(app, ["trace", str(EXAMPLE), "--inputs", str(tmp_path / "trace.jsonl")])
    assert replayed.exit_code == 0
    assert [json.loads(line) for line in replayed.output.splitlines()] == [{k: x[k] for k in CORE} for x in lines]
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert summary["ended"] == "done" and summary["target"] == f"{kind}://{emu.device}"
    exchanges = emu.requests("exchange")  # the link timed with every output off, then outputs off at open,
    assert len(exchanges) == PROBES + 82  # one per tick and outputs off at the end
    assert all(off(kind, r) for r in exchanges[: PROBES + 1]) and off(kind, exchanges[-1])
    assert not all(off(kind, r) for r in exchanges)
    assert "warning" not in err  # the emulators answer at full speed: the 10 ms tick fits


@pytest.mark.parametrize(("kind", "fault"), [("robotx", "bad_crc"), ("roboif", "silent")])
def test_a_lost_link_ends_the_process_with_exit_3_a_link_lost_record_and_the_outputs_off(
    tmp_path: Path, kind: str, fault: str
) -> None:
    with emulator(kind, fault=(fault, PROBES + 20)) as emu:  # tick 20's exchange, after the link was timed
        process = spawn(
            [
                "run",
                str(EXAMPLE),
                "--on",
                f"{kind}://{emu.device}",
                "--seconds",
                "5",
                "--out",
                str(tmp_path),
                "--link-timeout",
                "0.2",
            ]
        )
        out, err = process.communicate(timeout=60)
        stopped = emu.wait_for("exchange", PROBES + 22, timeout_s=2) and off(kind, emu.requests("exchange")[-1])
    assert process.returncode == 3 and "link_lost" in out and "Traceback" not in err + out
    lines = read_trace(tmp_path / "trace.partial.jsonl")
    assert lines[-1]["end"] == "link_lost" and lines[-1]["tick"] == 20
    assert stopped


@pytest.mark.parametrize(
    ("kind", "sig", "code", "reason"),
    [("robotx", signal.SIGINT, 130, "interrupted"), ("roboif", signal.SIGTERM, 143, "terminated")],
)
def test_a_signal_to_the_process_stops_the_outputs_and_keeps_the_trace(
    tmp_path: Path, kind: str, sig: int, code: int, reason: str
) -> None:
    with emulator(kind) as emu:
        process = spawn(
            [
                "run",
                str(EXAMPLE),
                "--on",
                f"{kind}://{emu.device}",
                "--seconds",
                "30",
                "--out",
                str(tmp_path),
                "--link-timeout",
                "0.3",
            ]
        )
        try:
            assert emu.wait_for("exchange", PROBES + 30, timeout_s=30)
            process.send_signal(sig)
            out, err = process.communicate(timeout=30)
        finally:
            process.kill()
        stopped = emu.wait_for("bye" if kind == "roboif" else "exchange", 1) and off(kind, emu.requests("exchange")[-1])
    assert process.returncode == code, err
    assert "Traceback" not in err + out
    lines = read_trace(tmp_path / "trace.partial.jsonl")
    assert lines[-1]["end"] == reason and len(lines) > 25 and any(line.get("M1") for line in lines)
    assert stopped


def test_a_table_the_interface_cannot_hold_is_refused_before_the_port_is_opened() -> None:
    with RoboifEmulator() as emu:
        result = runner.invoke(
            app, ["run", str(EXAMPLE.parent / "bumberbot-counters"), "--on", f"roboif://{emu.device}"]
        )
        assert emu.names() == []
    assert result.exit_code != 0 and "ROBO Interface has no counter inputs" in result.output


def test_addresses_are_parsed_or_refused_with_the_option_named(tmp_path: Path) -> None:
    for bad in ("robotx://", "roboif://dev/"):
        result = runner.invoke(app, ["run", str(EXAMPLE), "--on", bad])
        assert result.exit_code != 0 and "--on" in result.output and "names no serial device" in result.output
    missing = runner.invoke(app, ["run", str(EXAMPLE), "--on", f"robotx://{tmp_path}/nothing"])
    assert missing.exit_code != 0 and "cannot open" in missing.output and "Traceback" not in missing.output
    with RobotxEmulator() as tx:  # a ROBO TX where a ROBO Interface was said: it does not answer the greeting
        wrong = runner.invoke(app, ["run", str(EXAMPLE), "--on", f"roboif://{tx.device}"])
    assert wrong.exit_code != 0 and "--on" in wrong.output
