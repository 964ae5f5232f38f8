"""The page never loses a user's edits (issue 33, section 2), in a real Chromium against the real server: a
table replaced by rename while open asks what to do, and both answers work; the draft is kept in the
browser, so a dropped connection or a reload offers it back. Screenshots (1280x720) of the dialogs go to
``studio-drafts`` under pytest's temporary folder (or to ``$TABLEBOT_SCREENSHOTS``). Any console error or
page error fails the test. The server's side of the same is in test_studio_saves.py.
"""

from __future__ import annotations

import re
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from studio_helpers import bumberbot, served
from tablebot.web.app import Background
from test_studio_saves import marked, replace_by_rename, version

pytestmark = [pytest.mark.browser]

TIMER_COL = 12
TIMER = f'td[data-row="3"][data-col="{TIMER_COL}"] input'
DRAFTS = "() => Object.keys(localStorage).filter((k) => k.startsWith('tablebot-draft:'))"


@pytest.fixture
def folder(tmp_path: Path) -> Path:
    return bumberbot(tmp_path, "bumberbot")


@pytest.fixture
def server(folder: Path) -> Iterator[Background]:
    yield from served(folder)


class Page:
    """A tab on the studio at 1280x720 that records console errors; ``sockets``: its WebSockets, each
    passed through to the server by Playwright (so that a test can drop one)."""

    def __init__(self, browser: Any, server: Background, shots: Path) -> None:
        self.context = browser.new_context(viewport={"width": 1280, "height": 720})
        self.page = self.context.new_page()
        self.errors: list[str] = []
        self.page.on("console", lambda m: self.errors.append(m.text) if m.type == "error" else None)
        self.page.on("pageerror", lambda e: self.errors.append(str(e)))
        self.page.on("dialog", lambda d: d.accept())  # "leave the page with unsaved edits?": yes, on reload
        self.sockets: list[tuple[Any, Any]] = []
        socket = re.compile(r"/ws(\?.*)?$")  # /ws?lang=en: the page says its language as it connects
        self.page.route_web_socket(socket, lambda ws: self.sockets.append((ws, ws.connect_to_server())))
        self.shots = shots
        self.page.goto(server.url)
        self.loaded()

    def loaded(self) -> None:
        self.page.wait_for_selector("table.grid tbody tr")
        self.page.wait_for_function("() => document.querySelector('#counts').textContent.includes('states')")

    def edit_timer(self, value: str) -> None:
        self.page.locator(TIMER).fill(value)
        self.page.wait_for_selector("#save.primary")  # the server has the edit: the draft is unsaved
        self.page.wait_for_function(f"() => ({DRAFTS})().length === 1")

    def asked(self, title: str) -> str:
        self.page.wait_for_selector("#ask[open]")
        text: str = self.page.locator("#ask").inner_text()
        assert self.page.locator("#ask h2").inner_text() == title
        return text

    def answer(self, label: str) -> None:
        self.page.locator("#ask button", has_text=label).click()
        self.page.wait_for_selector("#ask:not([open])", state="attached")

    def save(self) -> None:
        self.page.click("#save")
        self.saved()

    def saved(self) -> None:
        self.page.wait_for_function("() => document.querySelector('#banner').textContent.startsWith('saved table.csv')")

    def shot(self, name: str) -> None:
        self.page.screenshot(path=str(self.shots / f"{name}.png"))

    def close(self) -> None:
        self.context.close()
        assert self.errors == []


@pytest.fixture
def tab(browser: Any, server: Background, shots: Path) -> Iterator[Page]:
    page = Page(browser, server, shots)
    yield page
    page.close()


def test_a_table_replaced_while_open_asks_and_save_mine_keeps_theirs(tab: Page, folder: Path) -> None:
    path = folder / "table.csv"
    original = path.read_bytes()
    theirs = marked(original, 5, "their edit")
    tab.edit_timer("900")
    replace_by_rename(path, theirs)  # an editor's atomic save while the page has edits
    tab.page.click("#save")
    text = tab.asked("table.csv was replaced on disk")
    assert "Another program saved over it since you opened it" in text
    assert "Nothing was saved, and your edits are kept." in text
    tab.shot("conflict-dialog")
    tab.answer("Save mine (keep theirs as table.csv.bak)")
    tab.saved()
    assert "saved table.csv (the previous version is table.csv.bak)" in tab.page.locator("#banner").inner_text()
    assert path.read_bytes() == original.replace(b",895,", b",900,")
    assert (folder / "table.csv.bak").read_bytes() == theirs
    assert tab.page.evaluate(DRAFTS) == [] and tab.page.locator("#save-state").inner_text() == "saved"


def test_load_theirs_shows_their_table_and_drops_mine(tab: Page, folder: Path) -> None:
    path = folder / "table.csv"
    theirs = marked(path.read_bytes(), 5, "their edit")
    tab.edit_timer("901")
    replace_by_rename(path, theirs)
    tab.page.click("#save")
    tab.asked("table.csv was replaced on disk")
    tab.answer("Load theirs (drop my edits)")
    tab.page.wait_for_function(f"() => document.querySelector('{TIMER}').value === '895'")
    description = tab.page.locator('td[data-row="5"][data-col="0"] textarea').input_value()
    assert description == "their edit" and tab.page.locator("#save-state").inner_text() == "saved"
    assert path.read_bytes() == theirs and not (folder / "table.csv.bak").exists()
    assert tab.page.evaluate(DRAFTS) == []


def test_a_dropped_connection_offers_the_draft_back(tab: Page, folder: Path) -> None:
    path = folder / "table.csv"
    original = path.read_bytes()
    tab.edit_timer("900")
    page_side, server_side = tab.sockets[-1]
    page_side.close()  # the network drops: the server's session, which held the draft, ends with it
    server_side.close()
    tab.page.wait_for_function("() => document.querySelector('#banner').textContent.includes('lost the connection')")
    assert "Your unsaved edits are kept in this browser" in tab.page.locator("#banner").inner_text()
    text = tab.asked("Restore your unsaved edits to table.csv?")  # connected again: the table and the offer
    assert len(tab.sockets) == 2 and "this browser kept your edits" in text and "changed on disk" not in text
    assert tab.page.locator(TIMER).input_value() == "895"  # the server's table, under the question
    tab.shot("restore-offer")
    tab.answer("Restore my edits")
    tab.page.wait_for_function(f"() => document.querySelector('{TIMER}').value === '900'")
    tab.page.wait_for_selector("#save.primary")
    tab.save()
    assert path.read_bytes() == original.replace(b",895,", b",900,") and tab.page.evaluate(DRAFTS) == []


def test_a_reload_offers_the_draft_back_and_drop_forgets_it(tab: Page, folder: Path) -> None:
    path = folder / "table.csv"
    original = path.read_bytes()
    tab.edit_timer("900")
    for answer in ("Restore my edits", "Drop them"):
        tab.page.reload()
        tab.loaded()
        tab.asked("Restore your unsaved edits to table.csv?")
        tab.answer(answer)
    # restored, the draft was the page's again (kept at every edit) until dropped
    tab.page.wait_for_function(f"() => document.querySelector('{TIMER}').value === '895'")
    assert tab.page.evaluate(DRAFTS) == [] and path.read_bytes() == original
    tab.page.reload()
    tab.loaded()
    tab.page.wait_for_timeout(300)
    assert not tab.page.locator("#ask").evaluate("(d) => d.open")


def test_a_draft_of_a_table_changed_since_says_so_and_save_asks(tab: Page, folder: Path) -> None:
    path = folder / "table.csv"
    original = path.read_bytes()
    tab.edit_timer("900")
    theirs = marked(original, 5, "their edit")
    replace_by_rename(path, theirs)
    tab.page.reload()
    tab.loaded()
    text = tab.asked("Restore your unsaved edits to table.csv?")
    assert "table.csv has changed on disk since" in text
    tab.answer("Restore my edits")
    tab.page.wait_for_selector("#save.primary")
    tab.page.locator(f'td[data-row="4"][data-col="{TIMER_COL}"] input').fill("55")  # kept with the draft's own start
    tab.page.wait_for_function(f"() => JSON.parse(localStorage.getItem(({DRAFTS})()[0])).grid[4][{TIMER_COL}] === '55'")
    kept = tab.page.evaluate(f"() => JSON.parse(localStorage.getItem(({DRAFTS})()[0])).base")
    assert kept == version(original)
    tab.page.reload()
    tab.loaded()
    tab.asked("Restore your unsaved edits to table.csv?")
    tab.answer("Restore my edits")
    tab.page.wait_for_selector("#save.primary")
    tab.page.click("#save")
    tab.asked("table.csv was changed on disk")
    tab.answer("Save mine (keep theirs as table.csv.bak)")
    tab.saved()
    row_4 = b"Collision detection,2,,1,1,,,,,0,,0,%d,20"
    assert path.read_bytes() == original.replace(b",895,", b",900,").replace(row_4 % 50, row_4 % 55)
    assert (folder / "table.csv.bak").read_bytes() == theirs


def test_a_save_in_another_tab_is_said_and_save_mine_keeps_theirs(
    tab: Page, browser: Any, server: Background, shots: Path, folder: Path
) -> None:
    path = folder / "table.csv"
    original = path.read_bytes()
    other = Page(browser, server, shots)
    try:
        tab.edit_timer("900")
        other.page.locator(f'td[data-row="4"][data-col="{TIMER_COL}"] input').fill("60")
        other.page.wait_for_selector("#save.primary")
        other.save()
        theirs = path.read_bytes()
        tab.page.wait_for_function("() => document.querySelector('#banner').textContent.startsWith('another tab')")
        assert (
            tab.page.locator("#banner")
            .inner_text()
            .startswith("another tab saved table.csv while this one has unsaved edits: your edits are kept")
        )
        tab.shot("other-tab-saved")
        tab.page.click("#save")
        assert "Another tab of the studio saved it" in tab.asked("table.csv was saved in another tab")
        tab.answer("Save mine (keep theirs as table.csv.bak)")
        tab.saved()
        assert path.read_bytes() == original.replace(b",895,", b",900,")
        assert (folder / "table.csv.bak").read_bytes() == theirs and b",60," in theirs
    finally:
        other.close()
