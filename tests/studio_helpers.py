"""Helpers of the studio's tests: a copy of the BumberBot, a studio served from a thread, waiting for a
condition, a real Chromium, whether its page is up, a folder for screenshots, and a second web server on
another loopback port (the page of someone else's program) that records what the browser sends it."""

from __future__ import annotations

import asyncio
import os
import shutil
import threading
import time
import urllib.error
import urllib.request
from collections.abc import Callable, Coroutine, Iterator
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from pathlib import Path
from typing import Any, TypeVar

import pytest

from core_helpers import EXAMPLE
from tablebot.web.app import Background

#: The browser the studio's tests drive: Debian's chromium-headless-shell, Chromium's own engine (Blink, V8) from
#: the same sources and version as its chromium package, without the desktop browser around it -- what Playwright's
#: own headless tests run by default. The desktop browser in headless mode took twice the CPU for the same pages: the
#: browser tests (``-m "browser and not realtime"``, ``-n 3``) took 158 CPU-s and 83 s with it, 109 CPU-s and 59 s
#: with the shell, on this 2-core machine.
CHROMIUM = Path("/usr/bin/chromium-headless-shell")
#: The desktop Chromium a teacher opens: test_studio_browser drives the studio in it too (``full=True``).
FULL_CHROMIUM = Path("/usr/bin/chromium")
FLAGS = [
    "--no-sandbox",
    "--disable-gpu",
    "--disable-background-networking",
    "--disable-dev-shm-usage",
    "--no-first-run",
    "--disable-extensions",
]


def wait_for(condition: Callable[[], Any], what: str, timeout: float = 60) -> Any:
    """The first true value of ``condition()``, asked every 20 ms for at most ``timeout`` seconds."""
    deadline = time.monotonic() + timeout
    while not (found := condition()):
        assert time.monotonic() < deadline, f"timed out waiting for {what}"
        time.sleep(0.02)
    return found


T = TypeVar("T")


def run_async(coroutine: Coroutine[Any, Any, T]) -> T:
    """``asyncio.run(coroutine)`` on a thread of its own, its result or its exception handed back: the test
    process's Chromium (:class:`Browsers`) keeps Playwright's event loop set on the main thread from the first
    browser module on, and asyncio.run refuses to start a loop where one is set."""
    outcome: list[Any] = []

    def run() -> None:
        try:
            outcome.append((True, asyncio.run(coroutine)))
        except BaseException as exc:  # handed to the caller's thread, raised there
            outcome.append((False, exc))

    thread = threading.Thread(target=run, name="test-asyncio")
    thread.start()
    thread.join()
    ok, value = outcome[0]
    if not ok:
        raise value
    return value


class Browsers:
    """Debian's Chromium through Playwright for a whole test process (a session fixture holds it, tests/web/
    studio_fixtures.py): one Playwright and one browser per set of extra ``flags`` (beside :data:`FLAGS`) -- the
    headless shell (:data:`CHROMIUM`), or with ``full`` the desktop browser headless (:data:`FULL_CHROMIUM`) --
    launched at the first module that asks. A launch costs ~1.3 CPU-s (the browser and Playwright's driver) and
    ~20 modules each launched their own. Each module still gets a browser of its own contexts: :meth:`module`
    closes the contexts it opened when it ends, with their pages' timers and sockets; a browser that went away
    (a crash) is launched again. Skipped where Chromium is missing, except in CI, whose set-up installs it."""

    def __init__(self) -> None:
        self._playwright: Any = None
        self._launched: dict[tuple[bool, tuple[str, ...]], Any] = {}

    def get(self, *flags: str, full: bool = False) -> Any:
        program = FULL_CHROMIUM if full else CHROMIUM
        if not program.exists():
            if os.environ.get("CI"):
                raise RuntimeError(f"{program} is missing: scripts/bootstrap.sh should have installed it")
            pytest.skip(f"the browser tests need Debian's {program.name} (scripts/bootstrap.sh installs it)")
        sync_api = pytest.importorskip("playwright.sync_api", reason="the browser tests need playwright (pip)")
        if self._playwright is None:
            self._playwright = sync_api.sync_playwright().start()
        browser = self._launched.get((full, flags))
        if browser is None or not browser.is_connected():
            # the desktop browser in its headless mode, named as before (the shell has no other)
            args = [*FLAGS, *flags, *(["--headless=new"] if full else [])]
            browser = self._playwright.chromium.launch(executable_path=str(program), args=args)
            self._launched[(full, flags)] = browser
        return browser

    def module(self, *flags: str) -> Iterator[Any]:
        """The browser for one module (its fixture yields from this), its contexts closed afterwards."""
        browser = self.get(*flags)
        before = set(browser.contexts)
        yield browser
        for context in browser.contexts:
            if context not in before:
                context.close()

    def close(self) -> None:
        for browser in self._launched.values():
            if browser.is_connected():
                browser.close()
        if self._playwright is not None:
            self._playwright.stop()


def studio_works(page: Any) -> None:
    """The studio's page fetched its config and talks over its WebSocket: the table and the robot are up."""
    page.wait_for_selector("#play:not([disabled])", timeout=20_000)
    assert page.locator("#banner").is_hidden() or "stopped" not in page.locator("#banner").inner_text()


def bumberbot(parent: Path, name: str = "bot") -> Path:
    """A copy of the BumberBot example in ``parent/name``."""
    root = parent / name
    shutil.copytree(EXAMPLE, root)
    return root


def served(folder: Path, table: str | None = "table.csv", **options: Any) -> Iterator[Background]:
    """The studio for ``folder`` from a thread (a fixture yields from it), stopped afterwards."""
    studio = Background(folder, table, **options)
    yield studio
    studio.stop()


def screenshots(tmp_path_factory: pytest.TempPathFactory, name: str) -> Path:
    """Where a module's screenshots go: ``$TABLEBOT_SCREENSHOTS``, or ``name`` in pytest's temporary folder."""
    folder = Path(os.environ.get("TABLEBOT_SCREENSHOTS") or tmp_path_factory.mktemp(name))
    folder.mkdir(parents=True, exist_ok=True)
    return folder


class OtherPort:
    """A second web server on another loopback port, as another program of this machine: ``page`` (HTML)
    at every path; ``cookies`` holds every Cookie header a request brought (none: nothing kept)."""

    def __init__(self, page: str) -> None:
        self.cookies: list[str] = []
        body, cookies = page.encode(), self.cookies

        class Handler(BaseHTTPRequestHandler):
            def do_GET(self) -> None:
                cookies.extend(self.headers.get_all("Cookie") or [])
                self.send_response(200)
                self.send_header("Content-Type", "text/html; charset=utf-8")
                self.send_header("Content-Length", str(len(body)))
                self.end_headers()
                self.wfile.write(body)

            def log_message(self, *args: Any) -> None:
                pass

        self.server = ThreadingHTTPServer(("127.0.0.1", 0), Handler)
        self.origin = f"http://127.0.0.1:{self.server.server_address[1]}"
        threading.Thread(target=self.server.serve_forever, daemon=True).start()

    def close(self) -> None:
        self.server.shutdown()
        self.server.server_close()


def other_port(page: str) -> Iterator[OtherPort]:
    """An :class:`OtherPort` serving ``page`` (a fixture yields from it), closed afterwards."""
    server = OtherPort(page)
    yield server
    server.close()


def http(
    server: Background, path: str, headers: dict[str, str] | None = None, data: bytes | None = None, timeout: float = 10
) -> tuple[int, bytes]:
    """Status and body of a request to the studio; ``headers`` replace the page's own."""
    request = urllib.request.Request(
        f"{server.origin}/{path}", data=data, headers=server.headers if headers is None else headers
    )
    try:
        with urllib.request.urlopen(request, timeout=timeout) as reply:
            return reply.status, reply.read()
    except urllib.error.HTTPError as err:
        return err.code, err.read()
