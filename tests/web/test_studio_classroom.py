"""The studio in a classroom (issue 37 §1), in a real Chromium against the real server: a projector at
1280×720 (also with A+), a tablet at 1024×768 with touch. Every column of the BumberBot's table, the properties'
verdicts and the arena are on the screen, no cell cuts its text, a counterexample plays in the arena and is marked
where it breaks, an error's note is whole, the diagram is readable, and a folder without a table says so.

One studio and one browser for the module; each test a fresh browser context. Screenshots go to
``studio-classroom`` under pytest's temporary folder (or ``$TABLEBOT_SCREENSHOTS``): look at them.
"""

from __future__ import annotations

import os
import subprocess
import sys
import threading
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from studio_helpers import bumberbot, served, studio_works, wait_for
from tablebot.web.app import Background

NEXT_COL = 13
# What the page shows, measured in the page: boxes as [left, top, right, bottom] in CSS pixels
VIEW = """() => {
  const box = (el) => { const r = el.getBoundingClientRect(); return [r.left, r.top, r.right, r.bottom]; };
  const holder = document.querySelector('#grid');
  return { width: innerWidth, height: innerHeight, pageWide: document.documentElement.scrollWidth,
    gridWide: holder.scrollWidth, gridShown: holder.clientWidth, grid: box(holder),
    heads: [...document.querySelectorAll('table.grid thead th')].map((th) => [th.textContent, box(th)]),
    verdicts: [...document.querySelectorAll('#verdicts button')].map((b) => [b.textContent, box(b)]),
    arena: box(document.querySelector('#arena')), layout: document.body.dataset.layout,
    compact: document.body.classList.contains('compact') };
}"""
SMALL_TARGETS = """() => [...document.querySelectorAll('button, select, input, textarea')]
  .filter((el) => el.offsetParent !== null && el.type !== 'checkbox' && el.type !== 'file')
  .map((el) => [el.id || el.textContent || el.getAttribute('aria-label'), el.getBoundingClientRect()])
  .filter(([, r]) => r.width < 40 || r.height < 40)
  .map(([name, r]) => [name, Math.round(r.width), Math.round(r.height)])"""
CLIPPED = """() => [...document.querySelectorAll('table.grid input, table.grid textarea')]
  .filter((el) => el.scrollWidth > el.clientWidth + 1 || el.scrollHeight > el.clientHeight + 1)
  .map((el) => el.getAttribute('aria-label') + ': ' + el.value)"""
DIAGRAM_TEXT_PX = """() => { const svg = document.querySelector('#diagram svg'), k = svg.getScreenCTM().a;
  return Math.min(...[...svg.querySelectorAll('text')].map((t) => parseFloat(t.getAttribute('font-size')) * k)); }"""


@pytest.fixture(scope="module")
def studio(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Background]:
    yield from served(bumberbot(tmp_path_factory.mktemp("classroom")))


def open_page(
    browser: Any, url: str, width: int = 1280, height: int = 720, touch: bool = False, table: bool = True
) -> Any:
    """A page of the studio in a new browser context; console errors and page errors are collected."""
    context = browser.new_context(viewport={"width": width, "height": height}, has_touch=touch)
    page = context.new_page()
    page.errors = []
    page.on("console", lambda m: page.errors.append(m.text) if m.type == "error" else None)
    page.on("pageerror", lambda e: page.errors.append(str(e)))
    page.goto(url)
    if table:  # (the first page of a module waits for the simulator, which a busy machine compiles slowly)
        page.wait_for_selector("#play:not([disabled])", timeout=120_000)
        studio_works(page)
        page.wait_for_function("() => document.querySelectorAll('#verdicts button').length === 6")
        page.wait_for_timeout(150)  # the layout is fitted on the next frame
    return page


def inside(box: list[float], frame: list[float], slack: float = 0.5) -> bool:
    return (
        box[0] >= frame[0] - slack
        and box[1] >= frame[1] - slack
        and box[2] <= frame[2] + slack
        and box[3] <= frame[3] + slack
    )


SIZES = {"projector": (1280, 720, False, 0), "tablet": (1024, 768, True, 0), "projector-A+": (1280, 720, False, 2)}


@pytest.mark.parametrize("size", SIZES)
def test_every_column_the_verdicts_and_the_arena_are_on_the_screen(
    browser: Any, studio: Background, shots: Path, size: str
) -> None:
    width, height, touch, bigger = SIZES[size]
    page = open_page(browser, studio.url, width, height, touch)
    for _ in range(bigger):
        page.click("#bigger")
    page.wait_for_timeout(200)
    page.screenshot(path=str(shots / f"{size}.png"))
    seen = page.evaluate(VIEW)
    screen = [0, 0, seen["width"], seen["height"]]
    assert seen["pageWide"] <= seen["width"] and seen["gridWide"] <= seen["gridShown"], seen  # no sideways scrolling
    shown = [seen["grid"][0], seen["grid"][1], seen["grid"][0] + seen["gridShown"], seen["grid"][3]]
    assert len(seen["heads"]) == 15 and seen["heads"][-1][0] == "next"
    for name, box in seen["heads"]:
        assert inside(box, screen) and inside(box, shown), (name, box, seen["layout"], seen["compact"])
    assert seen["verdicts"][0][0] == "✘ front_bumper_stops"  # the broken one first
    for name, box in seen["verdicts"]:
        assert inside(box, screen), (name, box)
    arena = seen["arena"]
    assert inside(arena, screen) and arena[2] - arena[0] >= 250 and arena[3] - arena[1] >= 150, arena
    if touch:
        assert page.evaluate(SMALL_TARGETS) == []
    assert page.evaluate(CLIPPED) == []
    assert page.errors == []
    page.context.close()


def test_no_cell_cuts_its_text(browser: Any, studio: Background) -> None:
    page = open_page(browser, studio.url)
    timer = page.locator('td[data-row="0"][data-col="12"] input')
    timer.fill("300ms")  # a duration with its unit: shown whole (it was "300m")
    description = page.locator('td[data-row="1"][data-col="0"] textarea')
    description.fill("back off a little, then turn towards the lamp until a bumper is pressed again")
    page.wait_for_selector("#save:not([disabled])")  # the server has the edits
    assert page.evaluate(CLIPPED) == []
    wide = page.evaluate("() => [document.documentElement.scrollWidth, innerWidth]")
    assert wide[0] <= wide[1]
    page.context.close()


def test_a_counterexample_plays_in_the_arena_at_once_and_is_marked_where_it_breaks(
    browser: Any, studio: Background, shots: Path
) -> None:
    page = open_page(browser, studio.url)
    page.locator("#properties li", has_text="front_bumper_stops").locator('button[data-where="arena"]').click()
    page.wait_for_function("() => !document.querySelector('#status').textContent.startsWith('tick 0 ')", timeout=5000)
    note = page.locator("#arena-note")
    note.wait_for(state="visible", timeout=20_000)  # no Play pressed: it plays by itself, then stops
    assert note.inner_text().startswith("✘ front_bumper_stops is broken here, at tick 53: whenever a front bumper")
    assert page.locator("#status").inner_text().startswith("tick 53 ")
    assert page.locator("#play").inner_text() == "▶ Play"  # paused on that tick
    page.screenshot(path=str(shots / "counterexample.png"))
    page.click("#play")  # goes on: the mark and the words go
    note.wait_for(state="hidden")
    assert page.errors == []
    page.context.close()


def test_an_error_note_is_whole_and_the_arena_says_it_runs_the_last_good_table(
    browser: Any, studio: Background, shots: Path
) -> None:
    page = open_page(browser, studio.url)
    stale = page.locator("#arena-stale")
    assert stale.is_hidden()
    cell = page.locator(f'td[data-row="0"][data-col="{NEXT_COL}"] input')
    cell.fill("nowhere")
    page.wait_for_selector(f'td[data-row="0"][data-col="{NEXT_COL}"].err')
    note = page.locator(".cell-note")
    note.wait_for(state="visible")
    box = note.bounding_box()
    width = page.evaluate("innerWidth")
    assert box["x"] >= 0 and box["x"] + box["width"] <= width and box["width"] > 200, box
    # nothing covers it or cuts it: its far corner is the note's own
    corner = page.evaluate(
        f"document.elementFromPoint({box['x'] + box['width'] - 4}, {box['y'] + box['height'] - 4})"
        ".closest('.cell-note') !== null"
    )
    assert corner and "nowhere" in note.inner_text()
    assert stale.is_visible() and "runs the last table that read" in stale.inner_text()
    page.screenshot(path=str(shots / "error.png"))
    cell.fill("20")
    stale.wait_for(state="hidden")
    page.context.close()


def test_the_diagram_is_readable_zooms_and_enlarges_beside_the_arena(
    browser: Any, studio: Background, shots: Path
) -> None:
    page = open_page(browser, studio.url)
    page.wait_for_selector("#diagram svg")
    assert page.evaluate(DIAGRAM_TEXT_PX) >= 11
    page.click("#diagram .diagram-view")
    page.wait_for_selector("#diagram.big")
    big, arena = page.locator("#diagram").bounding_box(), page.locator("#arena").bounding_box()
    assert big["x"] + big["width"] <= arena["x"] or arena["x"] + arena["width"] <= big["x"], (big, arena)
    before = page.evaluate(DIAGRAM_TEXT_PX)
    page.click('#diagram .diagram-tools button[title="larger"]')
    assert page.evaluate(DIAGRAM_TEXT_PX) > before
    page.screenshot(path=str(shots / "diagram.png"))
    page.keyboard.press("Escape")
    page.wait_for_selector("#diagram:not(.big)")
    assert page.errors == []
    page.context.close()


def test_a_folder_without_a_table_says_so_in_the_page_and_the_terminal(
    browser: Any, tmp_path: Path, shots: Path
) -> None:
    empty = tmp_path / "empty"
    empty.mkdir()
    said = _terminal_of_studio(empty)
    assert f"there is no table in {empty}" in said and "tablebot new my-robot --from line-follower" in said
    for studio in served(empty, None):
        page = open_page(browser, studio.url, table=False)
        page.wait_for_selector(".no-table")
        text = page.locator(".no-table").inner_text()
        assert "There is no table in empty" in text and "tablebot new my-robot --from bumberbot" in text
        assert page.locator("#save").is_disabled() and page.locator("#add-row").is_disabled()
        page.screenshot(path=str(shots / "empty.png"))
        page.fill("#new-name", "../outside")  # one plain name, inside the folder: refused in words
        page.click('.no-table button:text-is("bumberbot")')
        page.wait_for_function("() => document.querySelector('#banner').textContent.includes('a new robot')")
        page.fill("#new-name", "robo")
        page.click('.no-table button:text-is("bumberbot")')
        page.wait_for_function("() => document.querySelectorAll('table.grid tbody tr').length === 37")
        assert (empty / "robo" / "table.csv").is_file() and not (tmp_path / "outside").exists()
        assert page.locator("#table-pick").input_value() == "robo/table.csv" and page.locator("#save").is_disabled()
        assert page.errors == []
        page.context.close()


def _terminal_of_studio(folder: Path) -> str:
    """What ``tablebot studio`` (a real process, started in ``folder``) writes before it serves."""
    env = {**os.environ, "COLUMNS": "200"}
    process = subprocess.Popen(
        [sys.executable, "-m", "tablebot", "studio", "--no-browser", "--port", "0"],
        cwd=folder,
        env=env,
        stderr=subprocess.PIPE,
        text=True,
    )
    lines: list[str] = []  # read in a thread: a line that never comes must not block the test
    reader = threading.Thread(target=lambda: lines.extend(process.stderr), daemon=True)  # type: ignore[arg-type]
    reader.start()
    try:
        wait_for(
            lambda: "tablebot studio my-robot" in "".join(lines) or process.poll() is not None, "the studio's notes", 30
        )
        return "".join(lines)
    finally:
        process.terminate()
        process.wait(10)
