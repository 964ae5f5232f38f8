"""Long runs that are interrupted keep their work (issue 18): ``sweep`` on SIGTERM as on Ctrl-C (the
finished chunks kept, the same command resumes, the terminal gets its cursor back), and ``tune`` keeps
its evaluations on Ctrl-C or SIGTERM and the same command resumes where it stopped, to the same result."""

from __future__ import annotations

import json
import os
import pty
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

from typer.testing import CliRunner

from tablebot.cli import app
from tablebot.fleet.plan import read_results
from tablebot.interrupts import FAULT_ENV
from test_sim_helpers import BUMBERBOT
from test_tune import HALL, ROBOT

ROOT = Path(__file__).resolve().parents[1]
ENV = {**os.environ, "PYTHONPATH": str(ROOT / "src"), "TERM": "xterm-256color", "COLUMNS": "100"}
SHOW_CURSOR, HIDE_CURSOR = b"\x1b[?25h", b"\x1b[?25l"


def test_sigterm_ends_a_sweep_as_ctrl_c_does_and_gives_the_terminal_its_cursor_back(tmp_path: Path) -> None:
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
        "0..31",
        "--seconds",
        "200",
        "--workers",
        "2",
        "--out",
        str(out),
        "--no-plots",
    ]
    main, terminal = pty.openpty()  # stderr a terminal: the progress bar is drawn (and hides the cursor)
    proc = subprocess.Popen(command, env=ENV, stdout=subprocess.PIPE, stderr=terminal, stdin=subprocess.DEVNULL)
    os.close(terminal)
    screen = bytearray()

    def read() -> None:
        while True:
            try:
                data = os.read(main, 4096)
            except OSError:  # the child closed the terminal
                return
            if not data:
                return
            screen.extend(data)

    reader = threading.Thread(target=read, daemon=True)
    reader.start()
    deadline = time.monotonic() + 120
    while not ((out / "parts").is_dir() and any((out / "parts").glob("runs-*.csv"))):  # a finished part
        assert proc.poll() is None and time.monotonic() < deadline, bytes(screen)
        time.sleep(0.02)
    proc.send_signal(signal.SIGTERM)
    proc.wait(timeout=60)
    reader.join(timeout=10)
    os.close(main)
    text = bytes(screen)
    assert proc.returncode == 143, text
    assert b"terminated:" in text and b"run the same command again to resume" in text
    assert HIDE_CURSOR in text and text.rfind(SHOW_CURSOR) > text.rfind(HIDE_CURSOR), text[-300:]
    kept = read_results(out / "results.partial.csv")
    assert 0 < len(kept) < 32 and not (out / "results.csv").exists()
    # the same command resumes (here in one process: the number of workers is no part of a sweep's spec)
    done = CliRunner().invoke(app, [*command[3:], "--workers", "1"])
    assert done.exit_code == 0, done.output
    rows = read_results(out / "results.csv")
    assert [int(r["run"]) for r in rows] == list(range(32))
    assert {r["run"]: r for r in kept}.items() <= {r["run"]: r for r in rows}.items()
    assert not (out / "results.partial.csv").exists()


def tune_command(folder: Path, out: Path) -> list[str]:
    (folder / "robot.toml").write_text(ROBOT, encoding="utf-8")
    (folder / "table.csv").write_text(
        "description,state,T,I3,M1,M2,timer,next\ngo,1,1,,8,8,500,2\nstop,2,1,,0,0,0,2\n", encoding="utf-8"
    )
    (folder / "hall.toml").write_text(HALL, encoding="utf-8")
    return [
        "tune",
        str(folder / "table.csv"),
        "--world",
        str(folder / "hall.toml"),
        "--grid",
        "battery=1.0",
        "--seeds",
        "0..3",
        "--check-seeds",
        "9..9",
        "--seconds",
        "9",
        "--objective",
        "lamp_distance",
        "--cells",
        "line 2 timer=0..899",
        "--budget",
        "256",
        "--workers",
        "1",
        "--out",
        str(out),
    ]


def test_tune_keeps_its_evaluations_when_interrupted_and_the_same_command_resumes(tmp_path: Path) -> None:
    reference = CliRunner().invoke(app, tune_command(tmp_path, tmp_path / "ref"))
    assert reference.exit_code == 0, reference.output
    out = tmp_path / "out"
    command = tune_command(tmp_path, out)
    journal = out / "evaluations.partial.json"
    proc = subprocess.Popen(
        [sys.executable, "-m", "tablebot", *command],
        env=ENV,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
    )
    deadline = time.monotonic() + 120
    while not journal.exists():
        assert proc.poll() is None and time.monotonic() < deadline, proc.communicate()
        time.sleep(0.005)
    proc.send_signal(signal.SIGINT)  # a real Ctrl-C, while later batches still run
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 130, err
    kept = json.loads(journal.read_text())["evaluations"]
    assert f"interrupted: {len(kept)} evaluations kept in {journal}" in err
    assert 0 < len(kept) < 256 and not (out / "table.tuned.csv").exists()
    # SIGTERM keeps them the same way (sent by the process itself at its next file step: the next batch's)
    again = CliRunner().invoke(app, command, env={FAULT_ENV: "1:TERM"})
    assert again.exit_code == 143, again.output
    assert f"resuming: {len(kept)} evaluations" in again.output
    more = json.loads(journal.read_text())["evaluations"]
    assert more[: len(kept)] == kept and len(more) > len(kept)
    done = CliRunner().invoke(app, command)
    assert done.exit_code == 0, done.output
    assert f"resuming: {len(more)} evaluations" in done.output
    for name in ("evaluations.csv", "table.tuned.csv"):  # the resumed search took the same steps
        assert (out / name).read_bytes() == (tmp_path / "ref" / name).read_bytes(), name
    assert not journal.exists()
