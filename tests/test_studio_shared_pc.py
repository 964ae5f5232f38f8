"""The studio on a shared school computer (issue 33, section 3; the cut upload of section 4), tested with the real
command as a user runs it, a real second web server on another loopback port and a real Chromium.

* No process's command line holds the token: the studio opens the browser on a private file (0600, in a
  0700 folder of the user's runtime or temporary folder) that leads to the tokened address, and removes it
  when it stops. The browser here is a stand-in named by ``BROWSER`` that records its own argv; the file it
  was given, opened in Chromium, leads to the studio.
* A cookie of the studio's name planted by a page on another port (``path=/ws``, which the browser sends
  before the studio's own) no longer locks the user out: any cookie of that name holding the token lets
  the page in.
* ``--verbose`` logs show a token as ``[token]`` however it is percent-encoded.
* An upload cut off mid-body is one line in the terminal, not a traceback.
"""

from __future__ import annotations

import json
import os
import re
import shutil
import signal
import socket
import stat
import subprocess
import sys
import threading
import time
import urllib.error
import urllib.request
from collections.abc import Iterator
from dataclasses import dataclass
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from pathlib import Path
from typing import Any

import pytest

from core_helpers import EXAMPLE
from studio_helpers import chromium, studio_works, wait_for
from tablebot.web.app import Background


@pytest.fixture(scope="module")
def folder(tmp_path_factory: pytest.TempPathFactory) -> Path:
    root = tmp_path_factory.mktemp("shared-pc") / "bot"
    shutil.copytree(EXAMPLE, root)
    return root


# --- the command as a process, with a stand-in browser ---------------------------------------------------

@dataclass
class Command:
    """``tablebot studio`` running with BROWSER set to a stand-in that records its argv."""

    process: subprocess.Popen[bytes]
    log: Path  # the terminal (stderr, and stdout: uvicorn's request lines)
    url: str  # the address printed
    record: Path  # where the stand-in browser wrote its argv

    @property
    def token(self) -> str:
        return self.url.split("token=")[1].split("&")[0]

    @property
    def port(self) -> int:
        return int(self.url.split(":")[2].split("/")[0])

    def text(self) -> str:
        return self.log.read_text(errors="replace")

    def argv(self) -> list[str]:
        return json.loads(wait_for(lambda: self.record.exists() and self.record.read_text(), "the browser"))

    def stop(self, how: signal.Signals = signal.SIGINT) -> None:
        self.process.send_signal(how)
        self.process.wait(timeout=20)


def start_command(folder: Path, tmp: Path, env: dict[str, str], *args: str) -> Command:
    record = tmp / "browser-argv.json"
    fake = tmp / "fake-browser"
    fake.write_text(f"#!{sys.executable}\nimport json, os, sys\n"
                    f"open({str(record) + '.tmp'!r}, 'w').write(json.dumps(sys.argv))\n"
                    f"os.replace({str(record) + '.tmp'!r}, {str(record)!r})\n")
    fake.chmod(0o700)
    log = tmp / "terminal.txt"
    with log.open("wb") as terminal:
        process = subprocess.Popen([sys.executable, "-m", "tablebot.cli", "studio", str(folder), "--port", "0",
                                    *args], stdout=terminal, stderr=terminal,
                                   env={**os.environ, "BROWSER": str(fake), **env})
    try:
        url = wait_for(lambda: re.search(r"http://\S+/\?token=\S+", log.read_text()) or process.poll() is not None,
                       "the printed address")
        assert url is not True, log.read_text()
    except BaseException:
        process.kill()
        raise
    return Command(process, log, url[0], record)


@pytest.fixture(scope="module")
def runtime(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The user's runtime folder ($XDG_RUNTIME_DIR), private as systemd makes it."""
    path = tmp_path_factory.mktemp("runtime")
    path.chmod(0o700)
    return path


@pytest.fixture(scope="module")
def command(folder: Path, runtime: Path, tmp_path_factory: pytest.TempPathFactory) -> Iterator[Command]:
    running = start_command(folder, tmp_path_factory.mktemp("command"), {"XDG_RUNTIME_DIR": str(runtime)},
                            "--verbose")
    yield running
    running.stop()


def command_lines(token: str) -> list[str]:
    """Every process's command line on this machine that holds ``token``."""
    found = []
    for entry in Path("/proc").iterdir():
        try:
            line = (entry / "cmdline").read_bytes()
        except OSError:  # not a process, or it ended meanwhile
            continue
        if token.encode() in line:
            found.append(line.replace(b"\0", b" ").decode(errors="replace"))
    return found


def test_no_command_line_holds_the_token_the_browser_gets_a_private_file(command: Command, runtime: Path) -> None:
    argv = command.argv()
    assert command.token not in " ".join(argv), argv
    assert command_lines(command.token) == []
    assert len(argv) == 2 and argv[1].startswith("file://"), argv
    opened = Path(argv[1].removeprefix("file://"))
    assert opened.parent.parent == runtime  # a folder of its own in the user's runtime folder
    assert stat.S_IMODE(opened.stat().st_mode) == 0o600 and stat.S_IMODE(opened.parent.stat().st_mode) == 0o700
    assert opened.stat().st_uid == os.getuid()
    assert command.url.replace("&", "&amp;") in opened.read_text()  # it leads to the printed address
    assert command.url in command.text()  # which the terminal still shows (only the user sees it)


@pytest.mark.parametrize("how", [signal.SIGINT, signal.SIGTERM], ids=["SIGINT", "SIGTERM"])
def test_the_file_is_removed_when_the_studio_stops(folder: Path, tmp_path: Path, how: signal.Signals) -> None:
    """Without a private runtime folder the file goes to a private folder in the temporary folder ($TMPDIR)."""
    temp, shared = tmp_path / "tmp", tmp_path / "shared-runtime"
    temp.mkdir()
    shared.mkdir(mode=0o777)
    shared.chmod(0o777)  # another user could read a file there: not used
    running = start_command(folder, tmp_path, {"TMPDIR": str(temp), "XDG_RUNTIME_DIR": str(shared)})
    try:
        opened = Path(running.argv()[1].removeprefix("file://"))
        assert opened.parent.parent == temp and opened.is_file()
        assert running.token not in " ".join(running.argv())
    finally:
        running.stop(how)
    assert not opened.exists() and list(temp.iterdir()) == [] and list(shared.iterdir()) == []
    assert "Traceback" not in running.text()


OPEN_AND_WAIT = """import sys, threading
from tablebot.web.launch import open_in_browser, redirect_file
visited = threading.Event()
if sys.argv[1] == "visited":
    visited.set()
with redirect_file("http://127.0.0.1:1/?token=secret") as path:
    open_in_browser(path, visited, patience_s=0.2)
    next(t for t in threading.enumerate() if t.name == "tablebot-browser").join(20)
"""


@pytest.mark.parametrize("visit", ["visited", "not"])
def test_a_browser_that_does_not_come_gets_the_user_a_hint(tmp_path: Path, visit: str) -> None:
    """A browser installed as a snap cannot read the file: the terminal says to open the printed address."""
    fake = tmp_path / "fake-browser"
    fake.write_text(f"#!{sys.executable}\nimport sys\nopen({str(tmp_path / 'argv')!r}, 'w').write(sys.argv[1])\n")
    fake.chmod(0o700)
    done = subprocess.run([sys.executable, "-c", OPEN_AND_WAIT, visit], env={**os.environ, "BROWSER": str(fake)},
                          capture_output=True, text=True, timeout=60)
    assert done.returncode == 0, done.stderr
    assert (tmp_path / "argv").read_text().startswith("file://")
    hint = ("the browser has not come to the studio after 0.2 s: if it cannot find "
            f"{(tmp_path / 'argv').read_text().removeprefix('file://')} (a browser installed as a snap cannot read "
            "that folder), open the address above")
    assert done.stderr.strip() == ("" if visit == "visited" else hint)


# --- the verbose log -------------------------------------------------------------------------------------

def _get(url: str, headers: dict[str, str] | None = None) -> int:
    try:
        with urllib.request.urlopen(urllib.request.Request(url, headers=headers or {}), timeout=10) as reply:
            return int(reply.status)
    except urllib.error.HTTPError as err:
        return err.code


def test_verbose_logs_hide_a_percent_encoded_token(command: Command) -> None:
    token = command.token
    every = "".join(f"%{ord(c):02X}" for c in token)
    some = "".join(f"%{ord(c):02x}" if i % 2 else c for i, c in enumerate(token))  # lower case, every other one
    twice = "".join(f"%25{ord(c):02X}" for c in token)
    base = f"http://127.0.0.1:{command.port}"
    assert _get(f"{base}/?token={every}&table=table.csv") == 200  # the server decodes it: it is the token
    assert _get(f"{base}/api/config?token={some}") == 403
    assert _get(f"{base}/?table={twice}") == 403
    wait_for(lambda: '"GET /?table=' in command.text(), "the log line of the last request")
    log = command.text()
    for form in (every, some, twice, token):
        assert form not in log.replace(command.url, ""), form  # only the printed address shows it
    assert re.search(r'"GET /\?token=\[token\]&table=table.csv HTTP/1.1" 200', log), log
    assert re.search(r'"GET /api/config\?token=\[token\] HTTP/1.1" 403', log), log
    assert re.search(r'"GET /\?table=\[token\] HTTP/1.1" 403', log), log


# --- an upload cut off -----------------------------------------------------------------------------------

def test_an_upload_cut_off_mid_body_is_one_line_not_a_traceback(command: Command) -> None:
    port = command.port
    head = (f"POST /api/trace?name=cut.jsonl HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\n"
            f"Origin: http://127.0.0.1:{port}\r\nCookie: tablebot-studio-{port}={command.token}\r\n"
            "Content-Type: application/octet-stream\r\nContent-Length: 100000\r\n\r\n")
    body = b'{"tick":0,"state":1}\n' * 50  # 1,050 of the 100,000 bytes announced
    with socket.create_connection(("127.0.0.1", port), timeout=10) as conn:
        conn.sendall(head.encode() + body)
        time.sleep(0.3)  # the server is reading the body when the connection goes
    line = wait_for(lambda: re.search(r".*cut\.jsonl.*", command.text()), "the studio's line about the upload")
    assert "cut off after 1,050 of 100,000 bytes" in line[0], line[0]
    log = command.text()
    assert "Traceback" not in log and "ClientDisconnect" not in log and "Exception in ASGI" not in log, log
    cookie = {"Cookie": f"tablebot-studio-{port}={command.token}"}
    assert _get(f"http://127.0.0.1:{port}/api/config", cookie) == 200  # and the studio goes on


# --- a cookie planted by a page on another port ----------------------------------------------------------

@pytest.fixture(scope="module")
def studio(folder: Path) -> Iterator[Background]:
    server = Background(folder, "table.csv")
    yield server
    server.stop()


def _upgrade(studio: Background, cookie: str) -> int:
    """The status of the page's WebSocket upgrade with this Cookie header (101: accepted)."""
    port = studio.access.port
    request = (f"GET /ws HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\nOrigin: {studio.origin}\r\nCookie: {cookie}\r\n"
               "Upgrade: websocket\r\nConnection: Upgrade\r\nSec-WebSocket-Version: 13\r\n"
               "Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\n\r\n")
    with socket.create_connection(("127.0.0.1", port), timeout=10) as conn:
        conn.sendall(request.encode())
        return int(conn.makefile("rb").readline().split()[1])


def test_any_cookie_of_the_studios_name_with_the_token_lets_the_page_in(studio: Background) -> None:
    """As a browser sends them: the planted path=/ws cookie first (longer path), the studio's after it."""
    name, token = studio.access.cookie, studio.access.token
    planted = f"{name}=planted; {name}={token}"
    assert _get(f"{studio.origin}/api/config", {"Origin": studio.origin, "Cookie": planted}) == 200
    assert _upgrade(studio, planted) == 101
    assert _upgrade(studio, f"{name}=planted; other={token}; {name}=x") == 403  # the name matters
    assert _upgrade(studio, f"{name}=planted; {name}=") == 403


#: The hostile page on another port: it plants cookies of the studio's name (and tries to replace its own).
PLANT_PAGE = """<!doctype html><html><body><script>
for (const path of ["/ws", "/api/config", "/static", "/"]) document.cookie = NAME + "=planted; path=" + path;
document.body.textContent = "planted: " + document.cookie;
window.planted = true;
</script></body></html>"""


@pytest.fixture(scope="module")
def planter(studio: Background) -> Iterator[str]:
    """A second web server on another loopback port, serving the page that plants the cookies."""
    page = PLANT_PAGE.replace("NAME", json.dumps(studio.access.cookie)).encode()

    class Handler(BaseHTTPRequestHandler):
        def do_GET(self) -> None:
            self.send_response(200)
            self.send_header("Content-Type", "text/html; charset=utf-8")
            self.end_headers()
            self.wfile.write(page)

        def log_message(self, *args: Any) -> None:
            pass

    server = ThreadingHTTPServer(("127.0.0.1", 0), Handler)
    threading.Thread(target=server.serve_forever, daemon=True).start()
    yield f"http://127.0.0.1:{server.server_address[1]}/plant.html"
    server.shutdown()
    server.server_close()


@pytest.fixture(scope="module")
def browser() -> Iterator[Any]:
    yield from chromium()


def test_a_cookie_planted_from_another_port_does_not_lock_the_user_out(browser: Any, studio: Background,
                                                                       planter: str) -> None:
    context = browser.new_context()
    page = context.new_page()
    page.goto(studio.url)
    studio_works(page)
    page.goto(planter)
    page.wait_for_function("() => window.planted")
    mine = [c for c in context.cookies() if c["name"] == studio.access.cookie]
    assert sorted(c["path"] for c in mine) == ["/", "/api/config", "/static", "/ws"]  # the attack took hold
    assert [c["value"] for c in mine if c["path"] == "/"] == [studio.access.token]  # HttpOnly: not replaced
    assert studio.access.token not in page.inner_text("body")  # nor read by the page's script
    page.goto(studio.origin + "/")  # the user comes back to the studio (no token in the address)
    studio_works(page)
    context.close()


def test_the_private_file_opened_in_chromium_leads_to_the_studio(browser: Any, command: Command) -> None:
    context = browser.new_context()
    page = context.new_page()
    opened = command.argv()[1]
    assert opened.startswith("file://")
    page.goto(opened)
    page.wait_for_url(f"http://127.0.0.1:{command.port}/**")
    studio_works(page)
    assert "token" not in page.url
    assert f"tablebot-studio-{command.port}" in {c["name"] for c in context.cookies()}
    context.close()
