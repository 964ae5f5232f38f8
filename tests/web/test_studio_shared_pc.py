"""The studio on a shared school computer (issue 33, section 3; the cut upload of section 4), tested with the real
command as a user runs it, a real second web server on another loopback port and a real Chromium.

* No process's command line holds the token: the studio opens the browser on a private file (0600, in a
  0700 folder of the user's runtime or temporary folder) that leads to the tokened address, and removes it
  when it stops. The browser here is a stand-in named by ``BROWSER`` that records its own argv; the file it
  was given, opened in Chromium, leads to the studio.
* The token is in no cookie, so no other port's server receives it (browsers send a 127.0.0.1 cookie to
  every port): the page keeps it in sessionStorage (per port), out of the address bar and history, and
  sends it in a header and a WebSocket subprotocol. A real second server on another port records every
  Cookie header the browser sends it; its page cannot get in, and the cookies it plants lock nobody out.
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
import time
import urllib.error
import urllib.request
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import pytest

from core_helpers import EXAMPLE
from studio_helpers import OtherPort, other_port, studio_works, wait_for
from tablebot.web.access import TOKEN_HEADER
from tablebot.web.app import Background

pytestmark = [pytest.mark.browser]


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
    fake.write_text(
        f"#!{sys.executable}\nimport json, os, sys\n"
        f"open({str(record) + '.tmp'!r}, 'w').write(json.dumps(sys.argv))\n"
        f"os.replace({str(record) + '.tmp'!r}, {str(record)!r})\n"
    )
    fake.chmod(0o700)
    log = tmp / "terminal.txt"
    with log.open("wb") as terminal:
        process = subprocess.Popen(
            [sys.executable, "-m", "tablebot.cli", "studio", str(folder), "--port", "0", *args],
            stdout=terminal,
            stderr=terminal,
            env={**os.environ, "BROWSER": str(fake), **env},
        )
    try:
        url = wait_for(
            lambda: re.search(r"http://\S+/\?token=\S+", log.read_text()) or process.poll() is not None,
            "the printed address",
        )
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
    running = start_command(folder, tmp_path_factory.mktemp("command"), {"XDG_RUNTIME_DIR": str(runtime)}, "--verbose")
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
    done = subprocess.run(
        [sys.executable, "-c", OPEN_AND_WAIT, visit],
        env={**os.environ, "BROWSER": str(fake)},
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert done.returncode == 0, done.stderr
    assert (tmp_path / "argv").read_text().startswith("file://")
    hint = (
        "the browser has not come to the studio after 0.2 s: if it cannot find "
        f"{(tmp_path / 'argv').read_text().removeprefix('file://')} (a browser installed as a snap cannot read "
        "that folder), open the address above"
    )
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
    assert _get(f"{base}/api/config?table={twice}") == 403
    wait_for(lambda: '"GET /api/config?table=' in command.text(), "the log line of the last request")
    log = command.text()
    for form in (every, some, twice, token):
        assert form not in log.replace(command.url, ""), form  # only the printed address shows it
    assert re.search(r'"GET /\?token=\[token\]&table=table.csv HTTP/1.1" 200', log), log
    assert re.search(r'"GET /api/config\?token=\[token\] HTTP/1.1" 403', log), log
    assert re.search(r'"GET /api/config\?table=\[token\] HTTP/1.1" 403', log), log


# --- an upload cut off -----------------------------------------------------------------------------------


def test_an_upload_cut_off_mid_body_is_one_line_not_a_traceback(command: Command) -> None:
    port = command.port
    head = (
        f"POST /api/trace?name=cut.jsonl HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\n"
        f"Origin: http://127.0.0.1:{port}\r\n{TOKEN_HEADER}: {command.token}\r\n"
        "Content-Type: application/octet-stream\r\nContent-Length: 100000\r\n\r\n"
    )
    body = b'{"tick":0,"state":1}\n' * 50  # 1,050 of the 100,000 bytes announced
    with socket.create_connection(("127.0.0.1", port), timeout=10) as conn:
        conn.sendall(head.encode() + body)
        time.sleep(0.3)  # the server is reading the body when the connection goes
    line = wait_for(lambda: re.search(r".*cut\.jsonl.*", command.text()), "the studio's line about the upload")
    assert "cut off after 1,050 of 100,000 bytes" in line[0], line[0]
    log = command.text()
    assert "Traceback" not in log and "ClientDisconnect" not in log and "Exception in ASGI" not in log, log
    assert _get(f"http://127.0.0.1:{port}/api/config", {TOKEN_HEADER: command.token}) == 200  # and the studio goes on


# --- the token kept by the page, in no cookie ----------------------------------------------------------

#: The page of another program on another port: it reads what it can, plants cookies of the names the
#: studio used, and tries to get in (the studio's API, its WebSocket bare and with a guessed key).
OTHER_PAGE = """<!doctype html><html><body><script>
const studio = STUDIO;
for (const path of ["/ws", "/api/config", "/"]) document.cookie = NAME + "=planted; path=" + path;
function socket(protocols) {
  return new Promise((resolve) => {
    const s = new WebSocket(studio.replace("http", "ws") + "/ws", protocols);
    s.onopen = () => resolve("opened"); s.onerror = () => resolve("refused");
  });
}
(async () => {
  const got = { storage: JSON.stringify([{ ...sessionStorage }, { ...localStorage }]), cookie: document.cookie };
  try { got.config = (await fetch(studio + "/api/config")).status; } catch (e) { got.config = "blocked"; }
  got.bare = await socket();
  got.guessed = await socket(["tablebot-studio", "tablebot-token.planted"]);
  window.got = got;
})();
</script></body></html>"""


@pytest.fixture(scope="module")
def other(studio: Background) -> Iterator[OtherPort]:
    page = OTHER_PAGE.replace("STUDIO", json.dumps(studio.origin))
    yield from other_port(page.replace("NAME", json.dumps(f"tablebot-studio-{studio.access.port}")))


def test_no_other_port_receives_the_token_and_its_page_cannot_get_in(
    browser: Any, studio: Background, other: OtherPort
) -> None:
    token = studio.access.token
    context = browser.new_context()
    page = context.new_page()
    page.goto(studio.url)
    studio_works(page)
    assert page.url == studio.origin + "/"  # the token left the address bar at once
    assert context.cookies() == [] and page.evaluate("sessionStorage.getItem('tablebot-studio-token')") == token
    page.goto(other.origin + "/page.html")  # the user visits another program's page in the same tab
    got = page.wait_for_function("() => window.got").json_value()
    assert token not in json.dumps(got) and got["bare"] == got["guessed"] == "refused", got
    assert got["config"] in (403, "blocked"), got
    page.go_back()  # the studio's entry in the history holds no token, and the page there gets in again
    assert "token" not in page.url
    studio_works(page)
    page.reload()
    studio_works(page)
    second = context.new_page()  # a second tab, opened with the printed address
    second.goto(studio.url)
    studio_works(second)
    second.goto(other.origin + "/again.html")
    second.wait_for_function("() => window.got")
    assert other.cookies and all(token not in cookie for cookie in other.cookies), other.cookies  # its own only
    context.close()


def test_a_websocket_without_the_token_is_refused_on_the_studios_own_page(browser: Any, studio: Background) -> None:
    context = browser.new_context()
    page = context.new_page()
    page.goto(studio.url)
    studio_works(page)
    opened = page.evaluate("""() => Promise.all([[], ["tablebot-studio"], ["tablebot-studio", "tablebot-token.x"]]
      .map((protocols) => new Promise((resolve) => {
        const s = new WebSocket("ws://" + location.host + "/ws", protocols);
        s.onopen = () => resolve("opened"); s.onerror = () => resolve("refused"); })))""")
    assert opened == ["refused", "refused", "refused"]
    context.close()


def test_an_address_without_the_token_says_how_to_get_in(browser: Any, studio: Background) -> None:
    context = browser.new_context()
    page = context.new_page()
    page.goto(studio.origin + "/?table=table.csv")  # an old address, or a new tab opened by hand
    page.wait_for_selector("#banner:not([hidden])")
    assert "open the address that tablebot studio printed" in page.inner_text("#banner")
    context.close()


def test_the_private_file_opened_in_chromium_leads_to_the_studio(browser: Any, command: Command) -> None:
    context = browser.new_context()
    page = context.new_page()
    opened = command.argv()[1]
    assert opened.startswith("file://")
    page.goto(opened)
    page.wait_for_url(f"http://127.0.0.1:{command.port}/**")
    studio_works(page)
    assert "token" not in page.url and context.cookies() == []
    context.close()
