"""`tablebot studio --open LINK` (issue 37 §2): a real studio process opens the table a share link carries,
exactly as shared, cell for cell in a real Chromium; a second open never writes over the first; a cut link is
refused in words, naming --open."""

from __future__ import annotations

import csv
import os
import re
import subprocess
import sys
import threading
from pathlib import Path
from typing import Any

import pytest

from core_helpers import EXAMPLE
from studio_helpers import wait_for
from tablebot import share

pytestmark = [pytest.mark.browser]  # a real Chromium: on the one worker that drives browsers

CELLS = """() => [...document.querySelectorAll('table.grid tbody tr')]
  .map((tr) => [...tr.querySelectorAll('td[data-col]')].map((td) => {
    const b = td.querySelector('button.flag'), i = td.querySelector('input, textarea');
    return b ? (b.getAttribute('aria-pressed') === 'true' ? '1' : '') : i.value; }))"""


class Studio:
    """``tablebot studio --open LINK`` in ``folder``, a real process; ``said`` what it wrote to the terminal."""

    def __init__(self, folder: Path, link: str) -> None:
        self.process = subprocess.Popen(
            [sys.executable, "-m", "tablebot", "studio", "--no-browser", "--port", "0", "--open", link],
            cwd=folder,
            env={**os.environ, "COLUMNS": "300"},
            stderr=subprocess.PIPE,
            text=True,
        )
        self.lines: list[str] = []  # read in a thread: a line that never comes must not block the test
        reader = threading.Thread(target=lambda: self.lines.extend(self.process.stderr), daemon=True)  # type: ignore[arg-type]
        reader.start()

    @property
    def said(self) -> str:
        return "".join(self.lines)

    def url(self) -> str:
        return wait_for(lambda: re.search(r"http://127\.0\.0\.1:\d+/\?token=\S+", self.said), "the address", 60)[0]

    def stop(self) -> None:
        self.process.terminate()
        self.process.wait(10)


def test_a_link_opens_its_table_exactly_as_shared_and_never_over_a_folder(browser: Any, tmp_path: Path) -> None:
    link = share.encode(share.collect(EXAMPLE))
    studio = Studio(tmp_path, link)
    try:
        page = browser.new_page(viewport={"width": 1280, "height": 720})
        page.goto(studio.url())
        page.wait_for_function("() => document.querySelectorAll('table.grid tbody tr').length === 37")
        with (EXAMPLE / "table.csv").open(newline="", encoding="utf-8") as f:
            rows = list(csv.reader(f))[1:]
        assert page.evaluate(CELLS) == rows  # cell for cell
        assert page.locator("#table-pick").input_value() == "bumberbot/table.csv"
        assert "the link's table is bumberbot/table.csv in" in studio.said
        page.close()
    finally:
        studio.stop()
    for name in ("table.csv", "robot.toml", "arena.toml"):
        assert (tmp_path / "bumberbot" / name).read_bytes() == (EXAMPLE / name).read_bytes()
    again = Studio(tmp_path, link)
    try:
        assert again.url().endswith("table=bumberbot-2/table.csv")  # the first is kept as it is
    finally:
        again.stop()
    assert (tmp_path / "bumberbot-2" / "table.csv").read_bytes() == (EXAMPLE / "table.csv").read_bytes()


def test_a_cut_link_is_refused_in_words(tmp_path: Path) -> None:
    link = share.encode(share.collect(EXAMPLE))
    done = subprocess.run(
        [sys.executable, "-m", "tablebot", "studio", "--no-browser", "--port", "0", "--open", link[:300]],
        cwd=tmp_path,
        env={**os.environ, "COLUMNS": "300"},
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert done.returncode == 2 and "--open: error: this share link is cut short or damaged" in done.stderr
    assert list(tmp_path.iterdir()) == []  # nothing written


def test_the_share_button_gives_the_link_of_the_table_as_edited_and_its_qr_code(browser: Any, tmp_path: Path) -> None:
    from studio_helpers import bumberbot, served
    from tablebot.cli.studio import link_maker
    from tablebot.web import sharing

    sharing.maker = link_maker  # as tablebot studio hands it in
    errors: list[str] = []
    for studio in served(bumberbot(tmp_path)):
        page = browser.new_page(viewport={"width": 1280, "height": 720})
        page.on("console", lambda m: errors.append(m.text) if m.type == "error" else None)
        page.goto(studio.url)
        page.wait_for_selector("#share:not([disabled])")
        page.locator('td[data-row="0"][data-col="12"] input').fill("55")  # not saved: the link carries it
        page.wait_for_selector("#save:not([disabled])")
        page.click("#share")
        page.wait_for_selector("dialog#ask[open] .share-qr")
        link = page.locator("dialog#ask .share-link").input_value()
        assert page.evaluate("document.querySelector('dialog#ask .share-qr').naturalWidth") > 100
        page.screenshot(path=str(tmp_path / "share.png"))
        page.close()
    sharing.maker = None
    assert errors == []
    shared = share.decode(link)
    text = (EXAMPLE / "table.csv").read_text(encoding="utf-8")
    assert shared.table == (
        "table.csv",
        text.replace("Collision detection,1,,1,1,,,,,0,,0,50,20", "Collision detection,1,,1,1,,,,,0,,0,55,20", 1),
    )
    assert link.startswith(share.STUDIO + "#share=1.")


def test_a_link_in_the_pages_address_or_pasted_in_opens_its_table(browser: Any, tmp_path: Path) -> None:
    from studio_helpers import bumberbot, served
    from tablebot.cli.studio import link_opener
    from tablebot.web import sharing

    link = share.encode(share.collect(EXAMPLE / "../line-follower"))
    sharing.opener = link_opener  # as tablebot studio hands it in
    errors: list[str] = []
    for studio in served(bumberbot(tmp_path)):
        page = browser.new_page(viewport={"width": 1280, "height": 720})
        page.on("console", lambda m: errors.append(m.text) if m.type == "error" else None)
        page.goto(studio.url + link[link.index("#") :])  # pasted into the address bar of a running studio
        page.wait_for_function("() => document.querySelector('#table-pick').value === 'line-follower/table.csv'")
        assert "#" not in page.url  # the address is put back without the link
        page.click("#open-link")
        page.fill("dialog#ask textarea", link[:200])  # cut short in a chat
        page.click('dialog#ask button:text-is("Open")')
        page.wait_for_function("() => document.querySelector('#banner').textContent.includes('cut short')")
        page.close()
    sharing.opener = None
    assert errors == []
    line_follower = (EXAMPLE / "../line-follower/table.csv").resolve()
    assert (tmp_path / "bot" / "line-follower" / "table.csv").read_bytes() == line_follower.read_bytes()
