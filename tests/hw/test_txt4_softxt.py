"""``tablebot upload`` against harbaum/SofTXT, a pure-software TXT 4.0 serving the web API ROBO Pro Coding
uses, and the uploaded program stopped by SofTXT's own stop (SIGTERM to its runner, whose worker thread
runs the program). SofTXT is not on any registry: this runs only when ``TABLEBOT_SOFTXT`` names a
checkout of it (and ``TABLEBOT_SOFTXT_PYTHON`` a Python with PyQt5 and pyserial, default
/usr/bin/python3; Debian: python3-pyqt5 python3-pyqt5.qtquick python3-serial). SofTXT's code is run as it
is; only the serial port it looks for an ftDuino on is pointed at a pseudo-terminal where a small
device stand-in (below) records the motor commands that reach it."""

from __future__ import annotations

import json
import os
import select
import shutil
import socket
import subprocess
import sys
import threading
import time
from pathlib import Path

import httpx
import pytest

from core_helpers import EXAMPLE

SOFTXT = os.environ.get("TABLEBOT_SOFTXT", "")
PYTHON = os.environ.get("TABLEBOT_SOFTXT_PYTHON", "/usr/bin/python3")
pytestmark = [
    pytest.mark.skipif(
        not (SOFTXT and Path(SOFTXT, "txt-4.0.py").is_file()),
        reason="TABLEBOT_SOFTXT does not name a checkout of harbaum/SofTXT",
    ),
    pytest.mark.realtime,
]

#: SofTXT's factories.py looks for an ftDuino by USB id; this makes it find the pty in $FTDUINO_PTY.
SITECUSTOMIZE = """
import os
if os.environ.get("FTDUINO_PTY"):
    import serial.tools.list_ports as ports
    class Port:
        device = os.environ["FTDUINO_PTY"]
    ports.grep = lambda *args, **kwargs: iter([Port()])
"""


class FtDuino:
    """The device side of the JSON commands SofTXT's factories.py sends an ftDuino: records each, answers
    each input query with 1 (the BumberBot's phototransistors see light, so it drives)."""

    def __init__(self) -> None:
        self.master, self.slave = os.openpty()
        self.path = os.ttyname(self.slave)
        self.commands: list[dict] = []
        self.running = True
        threading.Thread(target=self._serve, daemon=True).start()

    def _serve(self) -> None:
        text, decoder = "", json.JSONDecoder()
        while self.running:
            if not select.select([self.master], [], [], 0.1)[0]:
                continue
            text += os.read(self.master, 4096).decode()
            while text := text.lstrip():
                try:
                    command, end = decoder.raw_decode(text)
                except ValueError:
                    break
                text = text[end:]
                self.commands.append(command)
                if "get" in command:
                    os.write(self.master, json.dumps({"port": command["get"]["port"], "value": 1}).encode())

    def motor_modes(self) -> list[tuple[str, str]]:
        sets = [c["set"] for c in self.commands if "set" in c]
        return [(s["port"], s["mode"]) for s in sets if s["port"].startswith("m")]


def free_port() -> int:
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        return sock.getsockname()[1]


def test_upload_start_and_stop_under_softxt(tmp_path: Path) -> None:
    softxt = tmp_path / "softxt"
    shutil.copytree(SOFTXT, softxt, ignore=shutil.ignore_patterns(".git", "workspaces"))
    (softxt / "workspaces").mkdir()
    (tmp_path / "site").mkdir()
    (tmp_path / "site" / "sitecustomize.py").write_text(SITECUSTOMIZE)
    ftduino, port = FtDuino(), free_port()
    env = {
        "PATH": f"{Path(PYTHON).parent}:/usr/bin:/bin",
        "QT_QPA_PLATFORM": "offscreen",
        "FTDUINO_PTY": ftduino.path,
        "PYTHONPATH": str(tmp_path / "site"),
        "HOME": str(tmp_path),
    }
    server = subprocess.Popen(
        [PYTHON, "txt-4.0.py", "-l", "127.0.0.1", "-p", str(port)],
        cwd=softxt,
        env=env,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
        start_new_session=True,
    )
    try:
        url = f"http://127.0.0.1:{port}"
        wait_for(lambda: httpx.get(f"{url}/api/v1/ping", timeout=1).status_code == 200)
        program = tmp_path / "program"
        tablebot = [str(Path(sys.executable).parent / "tablebot")]
        subprocess.run(
            [*tablebot, "export", str(EXAMPLE), str(program), "--to", "txt4"], check=True, capture_output=True
        )
        lines: list[str] = []
        threading.Thread(target=listen, args=(f"{url}/api/v1/controller/message-stream", lines), daemon=True).start()
        done = subprocess.run(
            [*tablebot, "upload", str(program), "--to", f"txt4://127.0.0.1:{port}"],
            env={**os.environ, "TABLEBOT_TXT4_KEY": "any"},
            capture_output=True,
            text=True,
        )
        assert done.returncode == 0, done.stdout + done.stderr
        assert (softxt / "workspaces" / "BumberBot" / "lib" / "tablebot_program.py").read_bytes() == (
            program / "lib" / "tablebot_program.py"
        ).read_bytes()
        wait_for(lambda: ("m1", "left") in ftduino.motor_modes())  # it drives (SofTXT: CCW is "left")
        assert any("the main thread hands SIGTERM over" in line for line in lines), lines
        httpx.delete(f"{url}/api/v1/stop", timeout=5)
        wait_for(lambda: any("tablebot: terminated after" in line for line in lines))
        wait_for(lambda: {("m1", "brake"), ("m2", "brake")} <= set(ftduino.motor_modes()))
        assert ftduino.motor_modes()[-2:] == [("m1", "brake"), ("m2", "brake")]
    finally:
        ftduino.running = False
        os.killpg(server.pid, 15)  # SofTXT and the runner it started
        server.wait(10)


def listen(url: str, lines: list[str]) -> None:
    """SofTXT's console stream (server-sent events): each line the program prints."""
    with httpx.stream("GET", url, timeout=None) as response:
        for line in response.iter_lines():
            if line.startswith("data: "):
                for message in json.loads(line[6:]):
                    lines.extend(message.get("data", []))


def wait_for(condition: object, timeout_s: float = 20.0) -> None:
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        try:
            if condition():  # type: ignore[operator]
                return
        except httpx.HTTPError:
            pass
        time.sleep(0.05)
    raise AssertionError("timed out")
