"""``tablebot run --on txt://...`` end to end against the fake TXT: the live trace replays to the same
decisions, faults end with a link_lost record and exit 3, and Ctrl-C / SIGTERM sent to the process stop
the outputs, keep the trace and print no traceback."""

from __future__ import annotations

import json
import os
import random
import signal
import subprocess
import sys
import time
from pathlib import Path
from typing import TYPE_CHECKING

import pytest
from rich.console import Console
from typer.testing import CliRunner

from core_helpers import EXAMPLE
from tablebot import registry
from tablebot.cli import app
from tablebot.engine import Engine
from tablebot.formats.table_read import load_table
from tablebot.hw.txt.backend import ADDRESS_HINT, parse_address
from tablebot.loop import Reading, RunInfo, TickBlock
from tablebot.machine import compile_table
from tablebot.sinks.live_view import LiveView
from txt_fake import FakeTxt

pytestmark = [pytest.mark.kernel_free]

if TYPE_CHECKING:
    from typer.testing import Result

    from txt_fake import Script

ROOT = Path(__file__).resolve().parents[2]
runner = CliRunner()
CORE = ("tick", "event", "row", "state", "timer", "M1", "M2")


def bumps(seed: int = 3) -> Script:
    """Bumpers and light that change every few ticks, so the BumberBot takes many different rows."""
    rng = random.Random(seed)
    held = [
        [0, 0, rng.randint(0, 1), rng.randint(0, 1), rng.randint(0, 1), 0, rng.randint(0, 1), rng.randint(0, 1)]
        for _ in range(200)
    ]
    return lambda n: (held[(n // 7) % len(held)], [0, 0, 0, 0])


def read_trace(path: Path) -> list[dict]:
    """Every line of a trace file, the end record too."""
    return [json.loads(line) for line in path.read_text(encoding="utf-8").splitlines()]


def invoke(*args: object) -> Result:
    result = runner.invoke(app, [str(a) for a in args])
    assert result.exception is None or isinstance(result.exception, SystemExit), result.exception
    return result


def test_a_run_writes_a_live_trace_that_tablebot_trace_replays_to_the_same_decisions(tmp_path: Path) -> None:
    with FakeTxt(bumps()) as fake:
        result = invoke(
            "run",
            EXAMPLE,
            "--on",
            f"txt://127.0.0.1:{fake.port}",
            "--seconds",
            "0.8",
            "--out",
            tmp_path,
            "--link-timeout",
            "0.2",
        )
    assert result.exit_code == 0, result.output
    assert "ran 80 ticks (0.80 s): done" in result.output
    lines = read_trace(tmp_path / "trace.jsonl")
    assert len(lines) == 80 and all("wall" in line and "late_ms" in line for line in lines)
    assert len({line["row"] for line in lines}) > 3  # the inputs made it take several rows
    replayed = invoke("trace", EXAMPLE, "--inputs", tmp_path / "trace.jsonl")
    assert replayed.exit_code == 0
    again = [json.loads(line) for line in replayed.output.splitlines()]
    assert again == [{k: line[k] for k in CORE} for line in lines]
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert summary["ended"] == "done" and summary["ticks"] == 80 and summary["trace"] == "trace.jsonl"
    assert summary["target"] == f"txt://127.0.0.1:{fake.port}"
    visited = list(dict.fromkeys(str(line["state"]) for line in lines))  # in order of first visit
    assert list(summary["seconds_per_state"]) == visited
    assert summary["seconds_per_state"] == {
        s: round(0.01 * sum(str(x["state"]) == s for x in lines), 3) for s in visited
    }
    assert summary["rows_fired"] == sum(line["row"] is not None for line in lines)
    assert not (tmp_path / "trace.partial.jsonl").exists()


def test_a_lost_link_ends_with_a_record_a_partial_trace_and_exit_3(tmp_path: Path) -> None:
    (tmp_path / "trace.jsonl").write_text("the previous complete run\n")
    with FakeTxt(fault=("silent", 20)) as fake:
        result = invoke(
            "run",
            EXAMPLE,
            "--on",
            f"txt://127.0.0.1:{fake.port}",
            "--seconds",
            "5",
            "--out",
            tmp_path,
            "--link-timeout",
            "0.1",
        )
    assert result.exit_code == 3 and "link_lost — no answer from" in result.output
    assert "Traceback" not in result.output
    lines = read_trace(tmp_path / "trace.partial.jsonl")
    assert lines[-1]["end"] == "link_lost" and len(lines) - 1 == 19  # tick 19's exchange failed
    assert lines[-1]["tick"] == 20  # the ticks the engine made (as RunEnd.ticks)
    assert "expected a reply to EXCHANGE_DATA within 100 ms" in lines[-1]["why"]
    assert (tmp_path / "trace.jsonl").read_text() == "the previous complete run\n"
    assert json.loads((tmp_path / "summary.partial.json").read_text())["exit_code"] == 3
    assert fake.last_exchange_before_stop().fields["pwm"] == [0] * 8
    replay = invoke("trace", EXAMPLE, "--inputs", tmp_path / "trace.partial.jsonl")
    assert replay.exit_code == 0 and len(replay.output.splitlines()) == 19


def test_link_timeout_is_an_option(tmp_path: Path) -> None:
    with FakeTxt(fault=("late", 5), late_s=0.1) as fake:
        slow = invoke(
            "run", EXAMPLE, "--on", f"txt://127.0.0.1:{fake.port}", "--seconds", "0.2", "--link-timeout", "0.5"
        )
    assert slow.exit_code == 0, slow.output
    with FakeTxt(fault=("late", 5), late_s=0.1) as fake:
        default = invoke("run", EXAMPLE, "--on", f"txt://127.0.0.1:{fake.port}", "--seconds", "0.2")
    assert default.exit_code == 3 and "within 50 ms" in default.output  # the default: 5 ticks


def spawn(args: list[str]) -> subprocess.Popen:
    env = {**os.environ, "PYTHONPATH": str(ROOT / "src")}
    return subprocess.Popen(
        [sys.executable, "-c", "from tablebot.cli import main; main()", *args],
        env=env,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )


@pytest.mark.parametrize(
    ("seconds", "sig", "code", "reason", "trace"),
    [
        (None, signal.SIGINT, 0, "stopped", "trace.jsonl"),
        ("30", signal.SIGINT, 130, "interrupted", "trace.partial.jsonl"),
        ("30", signal.SIGTERM, 143, "terminated", "trace.partial.jsonl"),
    ],
)
def test_a_signal_to_the_process_stops_the_outputs_and_keeps_the_trace(
    tmp_path: Path, seconds: str | None, sig: int, code: int, reason: str, trace: str
) -> None:
    with FakeTxt(bumps()) as fake:
        args = [
            "run",
            str(EXAMPLE),
            "--on",
            f"txt://127.0.0.1:{fake.port}",
            "--out",
            str(tmp_path),
            "--link-timeout",
            "0.3",
        ]
        process = spawn(args + (["--seconds", seconds] if seconds else []))
        try:
            fake.wait_for(30)
            process.send_signal(sig)
            out, err = process.communicate(timeout=20)
        finally:
            process.kill()
        time.sleep(0.05)
    assert process.returncode == code, err
    assert "Traceback" not in err and "Traceback" not in out
    lines = read_trace(tmp_path / trace)
    assert lines[-1]["end"] == reason and len(lines) - 1 <= lines[-1]["tick"] <= len(lines) and len(lines) > 25
    assert any(line.get("M1") for line in lines)  # the motors ran
    assert fake.last_exchange_before_stop().fields["pwm"] == [0] * 8
    assert fake.names()[-2:] == ["StopOnline", "closed"]


def test_targets_are_parsed_or_refused_with_the_option_named() -> None:
    assert parse_address("txt://192.168.7.2", ADDRESS_HINT) == ("192.168.7.2", 65000)
    assert parse_address("txt://10.0.0.9:6500", ADDRESS_HINT) == ("10.0.0.9", 6500)
    assert parse_address("txt://auto", ADDRESS_HINT) == (None, 65000)
    assert registry.live_for("sim:arena.toml") is registry.get("sim")
    assert registry.live_for("txt://auto") is registry.get("txt") and registry.live_for("usb") is None
    for bad in ("usb", "txt://", "txt://host:99999", "txt://host:x"):
        result = invoke("run", EXAMPLE, "--on", bad)
        assert result.exit_code == 2 and result.output.startswith("--on: error:"), (bad, result.output)


def test_an_unreachable_controller_is_a_located_error_with_what_to_check() -> None:
    with FakeTxt() as fake:
        port = fake.port
    result = invoke("run", EXAMPLE, "--on", f"txt://127.0.0.1:{port}")
    assert result.exit_code == 2 and f"--on: error: cannot connect to 127.0.0.1:{port}" in result.output
    assert "ftrobopy_server" in result.output


def test_the_live_view_shows_state_inputs_motors_and_lateness_with_user_text_made_safe(tmp_path: Path) -> None:
    robot = (EXAMPLE / "robot.toml").read_text().replace('2 = "Seek: turn"', '2 = "Seek\\u001b[31m turn [bold]"')
    (tmp_path / "robot.toml").write_text(robot)
    (tmp_path / "table.csv").write_text((EXAMPLE / "table.csv").read_text())
    machine = compile_table(load_table(tmp_path / "table.csv"))
    engine = Engine(machine)
    engine.step(0)
    console = Console(record=True, width=110, force_terminal=True, color_system=None)
    view = LiveView(console, "TXT-fake 4.6.6")
    view.info = RunInfo(engine, 0.01, "txt://127.0.0.1:65000", None)
    engine.restore({**engine.snapshot(), "state": 2, "timer": 37, "outputs": {"M1": -4, "M2": 8}})
    view.block(
        TickBlock.of_tick(engine, Reading(machine.input_bits["I3"] | machine.input_bits["I8"]), {"late_ms": 7.5})
    )
    console.print(view)
    text = console.export_text()
    assert "state 2  Seek[31m turn [bold]" in text  # shown as it is written, never read as markup
    assert "\x1b" not in text
    assert "● I3 (front-right bumper)" in text and "○ I4" in text and "● I8" in text
    assert "[    ████|        ] -4" in text and "[        |████████] +8" in text
    assert "timer 37" in text and "ticks late 1" in text


def test_a_run_trace_that_cannot_be_replayed_is_a_located_error(tmp_path: Path) -> None:
    bad = tmp_path / "trace.jsonl"
    bad.write_text('{"tick":0,"event":32}\n{"tick":1,"event":\n{"tick":2}\n')
    result = invoke("trace", EXAMPLE, "--inputs", bad)
    assert result.exit_code == 2
    assert f"{bad}:2:" in result.output and "line 2 is not JSON" in result.output
    assert f"{bad}:3:1: error: this trace line has no whole-number event" in result.output
    counters = ROOT / "examples" / "bumberbot-counters"
    result = invoke("trace", counters, "--inputs", tmp_path / "trace.jsonl")
    assert f"{bad}:1:1: error: this trace line has no whole-number C1_pulses" in result.output


def test_the_live_view_lets_no_control_character_of_a_label_reach_the_terminal(tmp_path: Path) -> None:
    """A NUL, a shift-out (switches a VT100's character set) and a one-byte C1 CSI act on a terminal as an
    ESC does; none of them reaches it, while the label's brackets stay as written."""
    robot = (
        (EXAMPLE / "robot.toml")
        .read_text()
        .replace('I3 = "front-right bumper"', 'I3 = "front\\u0000\\u000e\\u009b31m [right]"')
    )
    (tmp_path / "robot.toml").write_text(robot)
    (tmp_path / "table.csv").write_text((EXAMPLE / "table.csv").read_text())
    machine = compile_table(load_table(tmp_path / "table.csv"))
    engine = Engine(machine)
    engine.step(0)
    console = Console(record=True, width=110, force_terminal=True, color_system=None)
    view = LiveView(console)
    view.info = RunInfo(engine, 0.01, "txt://127.0.0.1:65000", None)
    view.block(TickBlock.of_tick(engine, Reading(0)))
    console.print(view)
    text = console.export_text()
    assert "○ I3 (front31m [right])" in text
    assert not any((0 <= ord(c) < 32 and c != "\n") or 0x7F <= ord(c) <= 0x9F for c in text), repr(text)


def test_what_the_controller_calls_itself_reaches_the_terminal_as_text() -> None:
    """The device name comes off the network: an escape sequence in it is shown, markup is not read."""
    with FakeTxt(device="\x1b[2J[red]TX") as fake:
        result = invoke("run", EXAMPLE, "--on", f"txt://127.0.0.1:{fake.port}", "--seconds", "0.05")
    assert result.exit_code == 0, result.output
    assert "(\\x1b[2J[red]TX 4.6.6); Ctrl-C stops it" in result.output and "\x1b" not in result.output


def test_auto_runs_on_the_address_that_answers_as_a_txt(monkeypatch: pytest.MonkeyPatch) -> None:
    """txt://auto with the controller addresses replaced by loopback ones (never the real ones): an HTTP
    server that answers garbage with an HTTP error on one, nothing on another, the fake TXT on a third."""
    from tablebot.hw.txt import link as txt_link
    from test_txt_link import Listener

    with FakeTxt(host="127.0.0.9") as fake:
        other = Listener("127.0.0.7", fake.port, "400")
        try:
            monkeypatch.setattr(txt_link, "AUTO_HOSTS", ("127.0.0.7", "127.0.0.8", "127.0.0.9"))
            result = invoke(
                "run", EXAMPLE, "--on", f"txt://auto:{fake.port}", "--seconds", "0.05", "--link-timeout", "1"
            )
            monkeypatch.setattr(txt_link, "AUTO_HOSTS", ("127.0.0.7", "127.0.0.8"))
            none = invoke("run", EXAMPLE, "--on", f"txt://auto:{fake.port}", "--seconds", "0.05")
        finally:
            other.close()
    assert result.exit_code == 0, result.output
    said = " ".join(result.output.split())  # the console wraps long lines where the checkout's path makes it
    assert f"on txt://127.0.0.9:{fake.port}" in said and "(TXT-fake 4.6.6)" in said
    assert none.exit_code == 2 and "--on: error: txt://auto found no TXT: 127.0.0.7: malformed reply" in none.output
    assert "127.0.0.8: cannot connect" in none.output


def test_firmware_older_than_4_6_6_is_refused_before_anything_moves() -> None:
    """As fischertechnik's online client refuses it (BeginTransfer: GetVersion() < 0x04060600)."""
    with FakeTxt(version=0x04060500) as fake:
        result = invoke("run", EXAMPLE, "--on", f"txt://127.0.0.1:{fake.port}", "--seconds", "0.05")
        time.sleep(0.05)
    assert result.exit_code == 2
    assert "runs firmware 4.6.5 (0x04060500); the online protocol needs 4.6.6 or later" in result.output
    assert "update the TXT's firmware to 4.6.6 or later" in result.output
    assert fake.names() == ["QueryStatus", "closed"]  # never went online
