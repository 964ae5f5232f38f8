"""The tests that interrupt a command with Ctrl-C (SIGINT) hold however pytest is started: from a shell's
background job (``make test &``, ``nohup .ci/run &``), which starts it with SIGINT ignored, tests/conftest.py
gives the session Python's handler back, so the commands the tests start can be interrupted."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
from pathlib import Path

import pytest

pytestmark = [pytest.mark.kernel_free]

ROOT = Path(__file__).resolve().parents[2]
CHILD = "import signal; print(signal.getsignal(signal.SIGINT) is signal.default_int_handler)"


def test_a_command_started_by_a_test_hears_ctrl_c() -> None:
    assert signal.getsignal(signal.SIGINT) is not signal.SIG_IGN
    done = subprocess.run([sys.executable, "-c", CHILD], capture_output=True, text=True, check=True)
    assert done.stdout.strip() == "True"


def test_a_session_started_with_ctrl_c_ignored_hears_it_again() -> None:
    """pytest started as a background job starts it (SIGINT ignored, inherited through exec), a session of its
    own: not this worker's (xdist's and the numba warm-up's variables left out)."""
    env = {k: v for k, v in os.environ.items() if not k.startswith(("PYTEST_", "TABLEBOT_TEST_", "COV_CORE"))}
    test = f"{Path(__file__).name}::test_a_command_started_by_a_test_hears_ctrl_c"
    done = subprocess.run(
        # -v: the summary line addopts' -q leaves out
        [sys.executable, "-m", "pytest", test, "-v", "-n", "0", "-p", "no:cacheprovider"],
        cwd=Path(__file__).parent,
        env=env,
        capture_output=True,
        text=True,
        timeout=300,
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_IGN),
    )
    assert done.returncode == 0, done.stdout[-3000:] + done.stderr[-2000:]
    assert "1 passed" in done.stdout
