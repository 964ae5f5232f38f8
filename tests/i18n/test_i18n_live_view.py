"""The live view of ``tablebot run`` in German (issue 38): its title, state, timer, time, tick and lateness, the
device the simulator names and why the run ended once read "state 11 ... timer 125 ... ticks late", "(simulated,
seed 3)" and ": done" in a German run."""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

pytestmark = [pytest.mark.realtime]

ROOT = Path(__file__).resolve().parents[2]
EXAMPLE = ROOT / "examples" / "bumberbot"
#: A small room: the BumberBot meets the lamp within a second (as tests/cli/test_run_sim.py's).
BOX = """\
name = "small box"
[arena]
walls = [[0, 0], [0.6, 0], [0.6, 0.45], [0, 0.45]]
[start]
at = [0.25, 0.22]
heading = 10
[[lamp]]
at = [0.55, 0.4]
intensity = 1.0
"""
ESCAPES = re.compile(r"\x1b\[[0-9;?]*[A-Za-z]")


def test_the_live_view_of_a_run_on_the_simulator_speaks_german(tmp_path: Path) -> None:
    """A real ``tablebot --lang de run --on sim`` whose stderr rich takes for a terminal (TTY_COMPATIBLE)."""
    (tmp_path / "box.toml").write_text(BOX, encoding="utf-8")
    env = {**os.environ, "TTY_COMPATIBLE": "1", "COLUMNS": "100", "NO_COLOR": "1"}
    env.pop("TABLEBOT_LANG", None)
    done = subprocess.run(
        [
            sys.executable,
            "-m",
            "tablebot",
            "--lang",
            "de",
            "run",
            str(EXAMPLE),
            "--on",
            f"sim:{tmp_path / 'box.toml'}",
            "--seconds",
            "0.5",
            "--seed",
            "3",
            "--behind-limit",
            "0",
        ],
        cwd=tmp_path,
        env=env,
        capture_output=True,
        text=True,
        timeout=300,
        check=False,
    )
    view = ESCAPES.sub("", done.stderr)
    assert done.returncode == 0, view
    assert "tablebot run — sim (simuliert, Seed 3)" in view
    assert re.search(r"Zustand \d+ .*Timer \d+ +t +0,\d\d s +Takt \d+", view), view
    assert "Takte verspätet" in view
    assert "50 Takte gefahren (0,50 s): fertig" in done.stdout
    for english in ("state ", "timer ", "tick ", "ticks late", "simulated", "connecting", "done"):
        assert english not in view + done.stdout, english
