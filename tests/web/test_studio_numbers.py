"""The studio's numbers and its last English words in German (issue 38), in a real Chromium against the real
server, at the classroom's projector sizes: a timer's time beside its cell (8,95 s), the status line's seconds
live and in the trace player (0,01 s, 1,37 s), how long the check took, the battery (100 %), the trace player's
Play/Pause button after a click and the T column's "timer ran out" all in the page's language; in English as
before; in the pseudo-language between markers. A cell keeps the ticks as typed: only the text beside it changes.

Screenshots go to ``studio-numbers`` under pytest's temporary folder (or ``$TABLEBOT_SCREENSHOTS``): look at them.
"""

from __future__ import annotations

import json
import re
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

import tablebot
from studio_helpers import bumberbot, served, studio_works, wait_for
from tablebot.web.app import Background

pytestmark = [pytest.mark.browser]

TIMER_COL = 12
POINT = re.compile(r"\d\.\d")  # a decimal point between digits: English, in a German page
SIZES = [(1024, 768), (1280, 720)]  # the classroom's projectors


@pytest.fixture(scope="module")
def folder(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The BumberBot with a trace of two seconds of it in run/ (the trace player's)."""
    root = bumberbot(tmp_path_factory.mktemp("numbers"))
    tablebot.open(root).simulate(seconds=2.0, seed=1).save(root / "run", plots=False)
    return root


@pytest.fixture(scope="module")
def studio(folder: Path) -> Iterator[Background]:
    yield from served(folder)


def open_page(browser: Any, url: str, locale: str, size: tuple[int, int] = SIZES[1], kept: str | None = None) -> Any:
    context = browser.new_context(locale=locale, viewport={"width": size[0], "height": size[1]})
    if kept is not None:
        context.add_init_script(f"localStorage.setItem('tablebot-studio-lang', {json.dumps(kept)})")
    page = context.new_page()
    page.errors = []
    page.on("pageerror", lambda e: page.errors.append(str(e)))
    page.goto(url)
    page.wait_for_selector("#play:not([disabled])", timeout=120_000)
    studio_works(page)
    page.wait_for_function("() => document.querySelector('#analysis-time').textContent !== ''")
    return page


def timer_times(page: Any) -> list[str]:
    """The time shown beside each timer cell (the cells' own values stay ticks)."""
    return page.eval_on_selector_all(f'td[data-col="{TIMER_COL}"] .ms', "els => els.map((e) => e.textContent)")


def step_once(page: Any) -> str:
    """The live robot (paused) stepped until its status line says a tick past 0: that line."""
    past = re.compile(r"(Takt|tick) [1-9]")
    for _ in range(20):
        page.click("#step")
        page.wait_for_timeout(150)
        if past.match(status := page.inner_text("#status")):
            return str(status)
    raise AssertionError(f"the live robot did not step: {status}")


def open_trace(page: Any, tick: int) -> str:
    """The trace player on run/trace.jsonl at ``tick``, Play clicked twice (playing, paused): its status line."""
    page.click("#mode-trace")
    page.evaluate(
        "() => { const s = document.querySelector('#trace-pick');"
        " s.append(new Option('run/trace.jsonl', 'run/trace.jsonl')); }"
    )
    page.select_option("#trace-pick", "run/trace.jsonl")
    wait_for(lambda: page.eval_on_selector("#scrub", "s => +s.max") > tick, "the trace loaded", 30)
    page.click("#tplay")
    page.click("#tplay")
    page.evaluate(
        f"() => {{ const s = document.querySelector('#scrub'); s.value = {tick};"
        " s.dispatchEvent(new Event('input')); }"
    )
    return str(page.inner_text("#status"))


@pytest.mark.parametrize("size", SIZES, ids=[f"{w}x{h}" for w, h in SIZES])
def test_a_german_page_writes_its_numbers_with_a_decimal_comma(
    browser: Any, studio: Background, shots: Path, size: tuple[int, int]
) -> None:
    page = open_page(browser, studio.url, "de-DE", size)
    times = timer_times(page)
    assert "8,95 s" in times and "1,25 s" in times and "500 ms" in times, times
    cells = page.eval_on_selector_all(f'td[data-col="{TIMER_COL}"] input', "els => els.map((e) => e.value)")
    assert "895" in cells and "125" in cells, cells  # the cells keep the ticks as the file has them
    assert "Timer abgelaufen" in page.eval_on_selector("table.grid thead", "e => e.textContent")
    took = page.inner_text("#analysis-time")
    assert re.fullmatch(r"geprüft in \d+(,\d)? ms", took), took
    assert re.fullmatch(r"100\s%", page.inner_text("#battery-text")), page.inner_text("#battery-text")  # German: 100 %
    live = step_once(page)
    assert re.match(r"Takt [1-9]\d* · 0,\d\d s · ", live), live
    page.screenshot(path=str(shots / f"german-live-{size[0]}.png"))
    played = open_trace(page, 137)
    assert played.startswith("Takt 137 · 1,37 s · ") and re.search(r"Timer \d+ \(\d,\d\d s\)", played), played
    assert page.inner_text("#tplay") == "▶ Start"  # after Play and Pause: not "▶ Play"
    page.screenshot(path=str(shots / f"german-trace-{size[0]}.png"))
    shown = [*times, page.inner_text("#analysis-time"), live, played]
    assert [text for text in shown if POINT.search(text)] == []
    assert page.errors == []
    page.context.close()


def test_an_english_page_keeps_its_decimal_point(browser: Any, studio: Background) -> None:
    page = open_page(browser, studio.url, "en-US")
    assert "8.95 s" in timer_times(page)
    assert "timer ran out" in page.eval_on_selector("table.grid thead", "e => e.textContent")
    page.evaluate(
        "() => { const b = document.querySelector('#battery'); b.value = 50; b.dispatchEvent(new Event('input')); }"
    )
    assert page.inner_text("#battery-text") == "50%"
    assert re.match(r"tick [1-9]\d* · 0\.\d\d s · ", step_once(page))
    assert open_trace(page, 137).startswith("tick 137 · 1.37 s · ")
    assert page.inner_text("#tplay") == "▶ Play"
    page.context.close()


def test_in_the_pseudo_language_the_words_found_in_german_are_between_markers(browser: Any, studio: Background) -> None:
    page = open_page(browser, studio.url, "en-US", kept="qps")
    heads = page.eval_on_selector("table.grid thead", "e => e.textContent")
    assert "⟦timer ran out⟧" in heads, heads
    open_trace(page, 10)
    assert page.inner_text("#tplay") == "⟦▶ Play⟧"
    page.context.close()


def test_a_drafts_time_of_day_is_the_pages_language_not_the_browsers(browser: Any, tmp_path: Path) -> None:
    """studio --lang de in an American browser: the page is German, and so is the time it says an unsaved edit
    was made at (13:05, not 01:05 PM: the old code asked the browser's language for it)."""
    for studio in served(bumberbot(tmp_path), lang="de"):
        page = open_page(browser, studio.url, "en-US")
        page.on("dialog", lambda d: d.accept())  # "leave the page with unsaved edits?": yes, on reload
        page.locator(f'td[data-row="3"][data-col="{TIMER_COL}"] input').fill("900")
        page.wait_for_selector("#save.primary")  # the server has the edit: unsaved
        page.wait_for_function("() => Object.keys(localStorage).some((k) => k.startsWith('tablebot-draft:'))")
        page.reload()
        page.wait_for_selector("#ask[open]")
        said = page.locator("#ask").inner_text()
        assert re.search(r"um \d\d:\d\d geändert", said), said
        assert not re.search(r"AM|PM", said), said
        page.context.close()


def diagram_text(page: Any) -> str:
    page.wait_for_selector("#diagram svg", timeout=60_000)
    return str(page.eval_on_selector("#diagram svg", "e => e.textContent"))


def test_a_german_tabs_diagram_is_german_whatever_the_studio_speaks(browser: Any, studio: Background) -> None:
    """The studio process speaks English here (the tests' language): a German tab's state diagram is drawn in
    German all the same (8,95 s on a timer's edge) while an English tab beside it keeps 8.95 s."""
    german, english = open_page(browser, studio.url, "de-DE"), open_page(browser, studio.url, "en-US")
    drawn = {"de": diagram_text(german), "en": diagram_text(english)}
    assert "8,95 s" in drawn["de"] and not POINT.search(drawn["de"]), drawn["de"]
    assert "8.95 s" in drawn["en"] and "8,95" not in drawn["en"], drawn["en"]
    german.context.close()
    english.context.close()
