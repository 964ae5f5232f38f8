"""Pages that are not the studio's attack it in a real Chromium (issue 18, section 1), and fail.

The user has the studio open (its token kept by its page, in no cookie) and visits a hostile page: one
served by a second local HTTP server on another port, and one whose name is rebound to 127.0.0.1 (DNS
rebinding: the page's own origin then reaches the studio's port; Chromium's --host-resolver-rules plays
the DNS server).
Each page tries to read secret.env, .git/config and hook.py over the WebSocket, rewrite and save a file,
send a message nested 100,000 deep, read /api/config, upload a trace, frame the studio and load its API
as an image. The studio's own log shows every one of those requests answered 403, nothing on disk
changes, and afterwards the studio's own page still opens, edits, checks, saves and runs the robot.
"""

from __future__ import annotations

import json
import logging
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from studio_helpers import Browsers, OtherPort, bumberbot, other_port, served
from tablebot.web.app import Background

pytestmark = [pytest.mark.browser]

REBOUND = "rebind.test"
FLAGS = [
    f"--host-resolver-rules=MAP {REBOUND} 127.0.0.1",
    # Chromium's Private Network Access would stop the rebound page before it reaches the studio;
    # other browsers have no such check, and the studio must hold without it
    "--disable-features=BlockInsecurePrivateNetworkRequests,PrivateNetworkAccessRespectPreflightResults,"
    "LocalNetworkAccessChecks",
]
SECRET = "API_KEY=do-not-leak-4711"
TIMER_COL = 12

#: The hostile page: every attack on the studio at TARGET, results in window.results (and on the page).
ATTACK_PAGE = """<!doctype html><html><head><meta charset="utf-8"><title>cute cats</title></head>
<body><h1>cute cats</h1><pre id="out">attacking…</pre><script>
const target = TARGET || location.origin;
function socket() {
  return new Promise((resolve) => {
    const got = [];
    let opened = false, done = false;
    const finish = (how) => { if (!done) { done = true; resolve({ opened, how, got }); } };
    const s = new WebSocket(target.replace("http", "ws") + "/ws");
    s.onopen = () => {
      opened = true;
      for (const path of ["secret.env", ".git/config", "hook.py", "table.csv"]) {
        s.send(JSON.stringify({ op: "open", path }));
      }
      s.send(JSON.stringify({ op: "edit", row: 0, col: 0, value: "pwned" }));
      s.send(JSON.stringify({ op: "save", force: true }));
      s.send("[".repeat(100000));
    };
    s.onmessage = (e) => got.push(e.data.slice(0, 300));
    s.onerror = () => finish("error");
    s.onclose = (e) => finish("closed " + e.code);
    setTimeout(() => { s.close(); finish("timeout"); }, 5000);
  });
}
async function get(path, init) {
  try {
    const r = await fetch(target + path, init);
    return { status: r.status, type: r.type, body: (await r.text()).slice(0, 300) };
  } catch (e) { return { error: String(e) }; }
}
function frame() {
  return new Promise((resolve) => {
    const f = document.createElement("iframe");
    f.onload = () => {
      try { resolve({ read: f.contentDocument.body.innerText.slice(0, 200) }); }
      catch (e) { resolve({ blocked: e.name }); }
    };
    f.src = target + "/";
    document.body.appendChild(f);
    setTimeout(() => resolve({ timeout: true }), 5000);
  });
}
function image() {
  return new Promise((resolve) => {
    const i = new Image();
    i.onload = () => resolve("loaded"); i.onerror = () => resolve("error");
    i.src = target + "/api/config";
  });
}
(async () => {
  const results = {};
  results.socket = await socket();
  results.config = await get("/api/config", { credentials: "include" });
  results.configNoCors = await get("/api/config", { credentials: "include", mode: "no-cors" });
  results.upload = await get("/api/trace?name=x.jsonl", { method: "POST", body: '{"tick":0,"state":1}\\n',
    credentials: "include", mode: "no-cors" });
  results.frame = await frame();
  results.image = await image();
  document.getElementById("out").textContent = JSON.stringify(results, null, 1);
  window.results = results;
})();
</script></body></html>"""


class Log(logging.Handler):
    """The studio's own request log (uvicorn's access and WebSocket lines), as the server wrote it."""

    def __init__(self) -> None:
        super().__init__()
        self.lines: list[str] = []

    def emit(self, record: logging.LogRecord) -> None:
        self.lines.append(record.getMessage())


@pytest.fixture(scope="module")
def folder(tmp_path_factory: pytest.TempPathFactory) -> Path:
    root = bumberbot(tmp_path_factory.mktemp("studio-attacks"))
    (root / "secret.env").write_text(SECRET + "\n")
    (root / "hook.py").write_text("print('hello')\n")
    (root / ".git").mkdir()
    (root / ".git" / "config").write_text("[remote]\nurl = secret\n")
    return root


@pytest.fixture(scope="module")
def log(studio: Background) -> Iterator[Log]:
    """Attached once the server exists (uvicorn sets its loggers' handlers when it is configured)."""
    handler = Log()
    loggers = [logging.getLogger(name) for name in ("uvicorn.access", "uvicorn.error")]
    for logger in loggers:
        logger.addHandler(handler)
    yield handler
    for logger in loggers:
        logger.removeHandler(handler)


@pytest.fixture(scope="module")
def studio(folder: Path) -> Iterator[Background]:
    yield from served(folder, log_level="info")


@pytest.fixture(scope="module")
def attacker(studio: Background) -> Iterator[str]:
    """A second local web server, on another port, serving the hostile page aimed at the studio."""
    server: OtherPort
    for server in other_port(ATTACK_PAGE.replace("TARGET", json.dumps(studio.origin))):
        yield server.origin + "/cats.html"


@pytest.fixture(scope="module")
def browser(browsers: Browsers) -> Iterator[Any]:
    yield from browsers.module(*FLAGS)


@pytest.fixture
def context(browser: Any, studio: Background) -> Iterator[Any]:
    """A browser profile in which the user opened the studio (its page holds the token) and keeps it open."""
    context = browser.new_context(viewport={"width": 1366, "height": 768})
    own = context.new_page()
    own.goto(studio.url)
    own.wait_for_selector("#play:not([disabled])")
    assert context.cookies() == []  # the token is in no cookie: the page keeps it in sessionStorage
    assert "token" not in own.url  # the page took it out of the address bar and history
    yield context
    context.close()


def _attack(context: Any, url: str, log: Log, shots: Path, name: str) -> tuple[dict[str, Any], list[str]]:
    log.lines.clear()
    page = context.new_page()
    page.goto(url)
    results = page.wait_for_function("() => window.results", timeout=30_000).json_value()
    page.screenshot(path=str(shots / f"attack-{name}.png"))
    page.close()
    studio_lines = [line for line in log.lines if "cats.html" not in line]
    return results, studio_lines


def _files(folder: Path) -> dict[str, bytes]:
    return {str(p.relative_to(folder)): p.read_bytes() for p in sorted(folder.rglob("*")) if p.is_file()}


def test_a_page_on_another_port_gets_nothing_and_changes_nothing(
    context: Any, attacker: str, folder: Path, log: Log, shots: Path
) -> None:
    before = _files(folder)
    results, lines = _attack(context, attacker, log, shots, "other-port")
    socket = results["socket"]
    assert not socket["opened"] and socket["got"] == []
    assert "error" in results["config"]  # the browser's CORS check; the server refused anyway (below)
    assert results["configNoCors"]["type"] == "opaque" and results["upload"]["type"] == "opaque"
    assert results["image"] == "error"
    assert SECRET not in json.dumps(results)
    # the studio's log: every request the page made was refused before reaching a route
    requests = [line for line in lines if '"GET' in line or '"POST' in line or '"WebSocket' in line]
    assert len(requests) >= 6, lines
    assert all(line.rstrip().endswith(("403", "403 Forbidden")) for line in requests), requests
    assert any('"WebSocket /ws" 403' in line for line in requests)
    assert any('"POST /api/trace?name=x.jsonl HTTP/1.1" 403' in line for line in requests)
    assert _files(folder) == before


def test_a_rebound_name_meets_the_host_check(
    context: Any, studio: Background, folder: Path, log: Log, shots: Path
) -> None:
    """The hostile page's origin is http://rebind.test:PORT, its name now resolving to 127.0.0.1: to the
    browser the studio is the page's own origin, so the page could read any answer; it reads only 403s."""
    url = f"http://{REBOUND}:{studio.access.port}/cats.html"
    page_html = ATTACK_PAGE.replace("TARGET", "null")
    context.route(url, lambda route: route.fulfill(status=200, content_type="text/html", body=page_html))
    before = _files(folder)
    results, lines = _attack(context, url, log, shots, "rebound")
    host = f"{REBOUND}:{studio.access.port}"
    for key in ("config", "configNoCors", "upload"):
        reply = results[key]
        assert reply["status"] == 403, (key, reply)
        assert f"this studio does not answer to the address '{host}'" in reply["body"]
    assert not results["socket"]["opened"] and results["socket"]["got"] == []
    frame = results["frame"]
    assert "read" not in frame or "does not answer" in frame["read"], frame  # framed: the 403 text at most
    requests = [line for line in lines if '"GET' in line or '"POST' in line or '"WebSocket' in line]
    assert len(requests) >= 6 and all(line.rstrip().endswith(("403", "403 Forbidden")) for line in requests), lines
    assert _files(folder) == before


def test_the_studios_own_page_still_works_end_to_end(
    context: Any, attacker: str, folder: Path, log: Log, shots: Path
) -> None:
    """After an attack in the next tab: open, edit (a located error, then fixed), save, live robot."""
    _attack(context, attacker, log, shots, "before-own-use")
    page = context.pages[0]
    errors: list[str] = []
    page.on("pageerror", lambda e: errors.append(str(e)))
    page.reload()
    page.wait_for_selector("#play:not([disabled])")
    assert page.locator("table.grid tbody tr").count() == 37
    original = (folder / "table.csv").read_bytes()
    try:
        page.locator(f'td[data-row="3"][data-col="{TIMER_COL}"] input').fill("900")
        page.wait_for_selector("#save.primary")
        page.click("#save")
        page.wait_for_selector(".banner:not(.bad)")
        assert (folder / "table.csv").read_bytes() == original.replace(b",895,", b",900,")
        assert (folder / "table.csv.bak").read_bytes() == original
    finally:
        (folder / "table.csv").write_bytes(original)
        (folder / "table.csv.bak").unlink(missing_ok=True)
    speed = page.locator('td[data-row="4"][data-col="9"] input')
    speed.fill("9")
    page.wait_for_selector('td[data-row="4"][data-col="9"].err')
    assert "M1_speed: 9 is out of range 0..8" in page.locator("#problems").inner_text()
    speed.fill("0")  # as it was
    page.wait_for_function("() => !document.querySelector('td.err')")
    page.click("#play")
    page.wait_for_function("() => /^tick ([2-9]\\d\\d|\\d{4,})/.test(document.querySelector('#status').textContent)")
    page.screenshot(path=str(shots / "own-page-after-attacks.png"))
    assert errors == []
