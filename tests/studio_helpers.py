"""Helpers of the studio's tests: waiting for a condition, a real Chromium, and whether its page is up."""

from __future__ import annotations

import os
import time
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import pytest

CHROMIUM = Path("/usr/bin/chromium")
FLAGS = ["--headless=new", "--no-sandbox", "--disable-gpu", "--disable-background-networking",
         "--disable-dev-shm-usage", "--no-first-run", "--disable-extensions"]


def wait_for(condition: Callable[[], Any], what: str, timeout: float = 60) -> Any:
    """The first true value of ``condition()``, asked every 20 ms for at most ``timeout`` seconds."""
    deadline = time.monotonic() + timeout
    while not (found := condition()):
        assert time.monotonic() < deadline, f"timed out waiting for {what}"
        time.sleep(0.02)
    return found


def chromium() -> Iterator[Any]:
    """Debian's Chromium through Playwright (a module fixture yields from it); skipped where it is missing,
    except in CI, whose set-up installs it."""
    if not CHROMIUM.exists():
        if os.environ.get("CI"):
            raise RuntimeError("/usr/bin/chromium is missing: scripts/bootstrap.sh should have installed it")
        pytest.skip("the browser tests need Debian's chromium (scripts/bootstrap.sh installs it)")
    sync_api = pytest.importorskip("playwright.sync_api", reason="the browser tests need playwright (pip)")
    with sync_api.sync_playwright() as p:
        browser = p.chromium.launch(executable_path=str(CHROMIUM), args=FLAGS)
        yield browser
        browser.close()


def studio_works(page: Any) -> None:
    """The studio's page fetched its config and talks over its WebSocket: the table and the robot are up."""
    page.wait_for_selector("#play:not([disabled])", timeout=20_000)
    assert page.locator("#banner").is_hidden() or "stopped" not in page.locator("#banner").inner_text()
