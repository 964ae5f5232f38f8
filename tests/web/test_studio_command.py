"""``tablebot studio`` as a user runs it, a real process (issue 18, section 1): it hides its token in its logs,
stops on Ctrl-C even with a pipe in the folder, and warns that serving a network address lets anyone with the
address read and change the folder's tables. What its server lets a page reach is test_studio_access.py.
"""

from __future__ import annotations

import json
import os
import re
import signal
import subprocess
import sys
import time
import urllib.error
import urllib.request
from pathlib import Path

import pytest

from studio_helpers import bumberbot
from tablebot.web.access import TOKEN_HEADER


@pytest.fixture
def folder(tmp_path: Path) -> Path:
    return bumberbot(tmp_path)


def _start(*args: str) -> tuple[subprocess.Popen[str], str]:
    """``tablebot studio ARGS`` as a user runs it; the address it printed."""
    process = subprocess.Popen(
        [sys.executable, "-m", "tablebot.cli", "studio", *args, "--port", "0", "--no-browser"],
        stderr=subprocess.PIPE,
        stdout=subprocess.PIPE,
        text=True,
    )
    assert process.stderr is not None
    lines = []
    deadline = time.monotonic() + 60
    while time.monotonic() < deadline:
        line = process.stderr.readline()
        lines.append(line)
        found = re.search(r"http://\S+/\?token=\S+", line)
        if found:
            return process, found[0] + "\n" + "".join(lines)
        assert line or process.poll() is None, "".join(lines)
    raise AssertionError("no address printed: " + "".join(lines))


def test_the_command_hides_its_token_in_logs_and_ctrl_c_stops_it_with_a_pipe_in_the_folder(folder: Path) -> None:
    os.mkfifo(folder / "notes.csv")
    process, printed = _start(str(folder), "--verbose")
    url = printed.splitlines()[0]
    token = url.split("token=")[1].split("&")[0]
    port = int(url.split(":")[2].split("/")[0])
    try:
        with urllib.request.urlopen(url, timeout=10) as reply:  # the first visit, as the browser makes it
            assert reply.headers.get_all("Set-Cookie") is None
        request = urllib.request.Request(f"http://127.0.0.1:{port}/api/config", headers={TOKEN_HEADER: token})
        with urllib.request.urlopen(request, timeout=10) as reply:
            assert "notes.csv" not in json.loads(reply.read())["tables"]
        with pytest.raises(urllib.error.HTTPError):
            urllib.request.urlopen(f"http://127.0.0.1:{port}/api/config?token={token}", timeout=10)
    finally:
        process.send_signal(signal.SIGINT)
        out, err = process.communicate(timeout=20)  # Ctrl-C stops it: no hang on the pipe
    log = printed + out + err
    assert process.returncode is not None
    assert log.count(token) == 2, log  # the printed address (kept twice above), never a log line
    assert re.search(r'"GET /\?token=\[token\]&table=table.csv HTTP/1.1" 200', log), log
    assert re.search(r'"GET /api/config\?token=\[token\] HTTP/1.1" 403', log), log


def test_serving_the_network_warns_that_the_token_opens_the_folder(folder: Path) -> None:
    process, printed = _start(str(folder), "--host", "0.0.0.0")
    try:
        port = int(printed.splitlines()[0].split(":")[2].split("/")[0])
        assert printed.splitlines()[0].startswith("http://127.0.0.1:")
        with pytest.raises(urllib.error.HTTPError) as err:  # still only with the token
            urllib.request.urlopen(f"http://127.0.0.1:{port}/api/config", timeout=10)
        assert err.value.code == 403
    finally:
        process.send_signal(signal.SIGINT)
        process.communicate(timeout=20)
    text = " ".join(printed.split())
    assert "warning: serving" in text and "0.0.0.0" in text
    assert (
        "anyone who can reach it and has the address below (with its token) can read the folder's tables, robot "
        "and world files and traces, and change its tables" in text
    )
