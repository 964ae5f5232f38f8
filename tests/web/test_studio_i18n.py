"""The studio in German and English (issue 38 §1), in a real Chromium against the real server: a browser whose
language is German sees the studio in German, the switch on the page changes it and is kept, ``studio --lang en``
wins over a German browser, a table's error comes in the page's language, and in the pseudo-language ``qps``
(every word of the page's catalog between markers) no word the page shows stands outside the markers, except
the user's own table. The catalogs themselves (js/lib/words_en.js, words_de.js) are read under Node.

One studio per module; each test a fresh browser context. Screenshots go to ``studio-i18n`` under pytest's
temporary folder (or ``$TABLEBOT_SCREENSHOTS``): look at them.
"""

from __future__ import annotations

import json
import os
import re
import shutil
import subprocess
import sys
import threading
import urllib.request
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from studio_helpers import bumberbot, served, studio_works, wait_for
from tablebot.web.app import STATIC, Background
from test_studio_classroom import CLIPPED, SIZES, SMALL_TARGETS, VIEW, inside

NEXT_COL = 13
CATALOGS = """
const [en, de] = await Promise.all(["en", "de"].map((lang) => import(`${process.argv[1]}/words_${lang}.js`)));
console.log(JSON.stringify({ en: en.EN, de: de.DE }));
"""


@pytest.fixture(scope="module")
def catalogs() -> dict[str, dict[str, str]]:
    node = shutil.which("node")
    assert node is not None, "Node runs the page's modules here"
    done = subprocess.run(
        [node, "--input-type=module", "-e", CATALOGS, (STATIC / "js" / "lib").as_uri()],
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert done.returncode == 0, done.stderr
    found: dict[str, dict[str, str]] = json.loads(done.stdout)
    return found


def test_both_catalogs_have_the_same_keys_and_the_same_fields(catalogs: dict[str, dict[str, str]]) -> None:
    en, de = catalogs["en"], catalogs["de"]
    assert sorted(en) == sorted(de)
    fields = re.compile(r"\{(\w+)\}")

    def named(catalog: dict[str, str]) -> dict[str, list[str]]:
        return {key: sorted(fields.findall(text)) for key, text in catalog.items()}

    assert named(en) == named(de)
    assert all(value.strip() for value in [*en.values(), *de.values()])


def test_every_word_the_page_names_is_in_the_catalog(catalogs: dict[str, dict[str, str]]) -> None:
    named = set()
    for path in [*STATIC.glob("*.html"), *STATIC.glob("js/**/*.js")]:
        text = path.read_text(encoding="utf-8")
        named |= set(re.findall(r'data-t(?:-\w+)?="([\w.]+)"', text))
        named |= set(re.findall(r'\bt\("([\w.]+)"[,)]', text)) | set(re.findall(r'\bword\("([\w.]+)"[,)]', text))
    assert len(named) > 100
    assert named - set(catalogs["en"]) == set()


@pytest.fixture(scope="module")
def studio(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Background]:
    yield from served(bumberbot(tmp_path_factory.mktemp("i18n")))


@pytest.fixture(scope="module")
def studio_en(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Background]:
    yield from served(bumberbot(tmp_path_factory.mktemp("i18n-en")), lang="en")


def open_page(
    browser: Any,
    url: str,
    locale: str,
    kept: str | None = None,
    width: int = 1280,
    height: int = 720,
    touch: bool = False,
) -> Any:
    """A page of the studio in a new browser context whose language is ``locale`` (``kept``: the switch's
    choice already in its storage); console errors and page errors are collected."""
    context = browser.new_context(locale=locale, viewport={"width": width, "height": height}, has_touch=touch)
    if kept is not None:
        context.add_init_script(f"localStorage.setItem('tablebot-studio-lang', {json.dumps(kept)})")
    page = context.new_page()
    page.errors = []
    page.on("console", lambda m: page.errors.append(m.text) if m.type == "error" else None)
    page.on("pageerror", lambda e: page.errors.append(str(e)))
    page.goto(url)
    page.wait_for_selector("#play:not([disabled])", timeout=120_000)
    studio_works(page)
    page.wait_for_function("() => document.querySelectorAll('#verdicts button').length === 6")
    page.wait_for_timeout(150)
    return page


def test_a_german_browser_sees_the_studio_in_german(browser: Any, studio: Background, shots: Path) -> None:
    page = open_page(browser, studio.url, "de-DE")
    page.screenshot(path=str(shots / "german.png"))
    assert page.evaluate("document.documentElement.lang") == "de"
    assert page.locator("#save").inner_text() == "Speichern"
    assert page.locator("#mode-trace").inner_text() == "Aufzeichnung"
    assert page.locator("#play").inner_text() == "▶ Start"
    assert page.locator("#reset").get_attribute("title").startswith("von vorn beginnen")
    assert "Zustände" in page.locator("#counts").inner_text()
    assert page.locator("#language").input_value() == "de"
    assert page.errors == []
    page.context.close()


def test_the_switch_changes_the_language_and_is_kept(browser: Any, studio: Background) -> None:
    page = open_page(browser, studio.url, "en-US")
    assert page.locator("#save").inner_text() == "Save"
    page.select_option("#language", "de")
    page.wait_for_selector("#save:text-is('Speichern')")
    assert page.url.endswith("/?lang=de"), page.url  # the choice in the address (the token long out of it)
    again = page.context.new_page()  # another visit, same browser: still German
    again.goto(studio.url)
    again.wait_for_selector("#save:text-is('Speichern')")
    again.select_option("#language", "en")
    again.wait_for_selector("#save:text-is('Save')")
    page.context.close()


def test_studio_lang_en_wins_over_a_german_browser(browser: Any, studio_en: Background) -> None:
    page = open_page(browser, studio_en.url, "de-DE")
    assert page.locator("#save").inner_text() == "Save"
    assert page.locator("#language").input_value() == "en"
    page.context.close()


def test_a_table_error_comes_in_the_pages_language(browser: Any, studio: Background, shots: Path) -> None:
    page = open_page(browser, studio.url, "de-DE")
    page.locator(f'td[data-row="0"][data-col="{NEXT_COL}"] input').fill("nirgendwo")
    page.wait_for_selector(f'td[data-row="0"][data-col="{NEXT_COL}"].err')
    note = page.locator(".cell-note")
    note.wait_for(state="visible")
    problems = page.locator("#problems").inner_text()
    page.screenshot(path=str(shots / "german-error.png"))
    assert "nirgendwo" in problems and "Fehler" in problems, problems
    assert "Zeile" in note.inner_text() and "Folgezustand" in problems, (note.inner_text(), problems)
    assert "does not" not in problems and "hint:" not in problems, problems
    assert "Die Tabelle hat Fehler" in page.locator("#arena-stale").inner_text()
    title = page.locator(f'td[data-row="0"][data-col="{NEXT_COL}"]').get_attribute("title")
    assert title.startswith("table.csv:") and ": Fehler: " in title and "Tipp: " in title, title
    # an English tab on the same studio at the same time: the server says its words in English
    english = open_page(browser, studio.url, "en-GB")
    english.locator(f'td[data-row="0"][data-col="{NEXT_COL}"] input').fill("nowhere")
    english.wait_for_selector(f'td[data-row="0"][data-col="{NEXT_COL}"].err')
    title = english.locator(f'td[data-row="0"][data-col="{NEXT_COL}"]').get_attribute("title")
    assert ": error: " in title and "hint: " in title, title
    assert "Fehler" not in english.locator("#problems").inner_text()
    english.context.close()
    page.context.close()


# Every text node, title, aria-label, placeholder and alt the page shows that has a letter in it and does not
# stand between the pseudo-language's markers; the user's own table (the grid's cells and headers, the diagram,
# the robot file's names) is theirs, and a property's name and text come from their robot file. Titles and labels
# are theirs only in the grid's header and the diagram: every other tip, the cells' and inputs' too, is the page's.
# The why list (which row fired) is the server's, said in the tab's language: it is looked at (a step fills it).
# The status line is left out: it names the user's state and outputs (test_studio_numbers reads it in German).
OUTSIDE_MARKERS = r"""() => {
  const own = (el) => el.closest('table.grid tbody, table.grid thead th:not(.num), #diagram svg, #inputs, #status, '
    + '#table-pick, #trace-pick, .brand, #verdicts, #properties');
  const bare = (text) => {  // markers nest (a message made of messages): take the innermost out until none is left
    for (let left = text.replace(/⟦[^⟦⟧]*⟧/g, ''); ; left = left.replace(/⟦[^⟦⟧]*⟧/g, '')) {
      if (!/⟦[^⟦⟧]*⟧/.test(left)) return left;
    }
  };
  const out = [];
  const walker = document.createTreeWalker(document.body, NodeFilter.SHOW_TEXT);
  for (let node = walker.nextNode(); node; node = walker.nextNode()) {
    const el = node.parentElement;
    if (!el || own(el) || el.closest('[hidden], script') || !el.getClientRects().length) continue;
    if (/\p{L}{2}/u.test(bare(node.textContent))) out.push(node.textContent.trim());
  }
  for (const el of document.querySelectorAll('[title], [aria-label], [placeholder], [alt]')) {
    if (el.closest('#diagram svg, #verdicts, #properties, table.grid thead th:not(.num)')) continue;
    for (const name of ['title', 'aria-label', 'placeholder', 'alt']) {
      const text = el.getAttribute(name);
      if (text && /\p{L}{2}/u.test(bare(text))) out.push(name + ': ' + text);
    }
  }
  return out;
}"""


def test_no_word_of_the_page_is_outside_the_catalog(
    browser: Any, studio: Background, shots: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    from tablebot.cli.studio import link_maker
    from tablebot.web import sharing

    monkeypatch.setattr(sharing, "maker", link_maker)  # as tablebot studio hands it in
    page = open_page(browser, studio.url, "en-US", kept="qps")
    assert page.locator("#save").inner_text() == "⟦Save⟧"
    page.check("#show-info")  # the notes too
    page.click("#step")  # the status line and the why list
    page.wait_for_selector("#why li")
    page.click("#mode-trace")
    seen = page.evaluate(OUTSIDE_MARKERS)
    page.click("#mode-live")
    page.click("#share")  # the share box (a dialog over the page)
    page.wait_for_selector("#ask[open] img, #ask[open] p.muted")
    seen += page.evaluate(OUTSIDE_MARKERS)
    page.keyboard.press("Escape")
    page.click("#open-link")
    page.wait_for_selector("#ask[open] textarea")
    seen += page.evaluate(OUTSIDE_MARKERS)
    page.keyboard.press("Escape")
    page.screenshot(path=str(shots / "pseudo.png"))
    assert seen == [], seen
    page.context.close()


@pytest.mark.parametrize("size", SIZES)
def test_in_german_every_column_the_verdicts_and_the_arena_are_on_the_screen(
    browser: Any, studio: Background, shots: Path, size: str
) -> None:
    """The classroom's sizes (test_studio_classroom.py) with German's longer words: nothing clipped or pushed off."""
    width, height, touch, bigger = SIZES[size]
    page = open_page(browser, studio.url, "de-DE", width=width, height=height, touch=touch)
    for _ in range(bigger):
        page.click("#bigger")
    page.wait_for_timeout(200)
    page.screenshot(path=str(shots / f"german-{size}.png"))
    seen = page.evaluate(VIEW)
    screen = [0, 0, seen["width"], seen["height"]]
    assert seen["pageWide"] <= seen["width"] and seen["gridWide"] <= seen["gridShown"], seen
    shown = [seen["grid"][0], seen["grid"][1], seen["grid"][0] + seen["gridShown"], seen["grid"][3]]
    assert seen["heads"][0][0] == "Zeile" and len(seen["heads"]) == 15
    for name, box in [*seen["heads"]]:
        assert inside(box, screen) and inside(box, shown), (name, box, seen["layout"], seen["compact"])
    for name, box in seen["verdicts"]:
        assert inside(box, screen), (name, box)
    arena = seen["arena"]
    assert inside(arena, screen) and arena[2] - arena[0] >= 250 and arena[3] - arena[1] >= 150, arena
    if touch:
        assert page.evaluate(SMALL_TARGETS) == []
    assert page.evaluate(CLIPPED) == []
    assert page.evaluate(CUT_BUTTONS) == []
    assert page.errors == []
    page.context.close()


# the toolbar's and the controls' buttons, whole: no label cut or spilling out of its button
CUT_BUTTONS = """() => [...document.querySelectorAll(
    'header button, .controls button, .controls label, .row-tools *, table.grid button')]
  .filter((el) => el.offsetParent !== null)
  .filter((el) => el.scrollWidth > el.clientWidth + 1 || el.scrollHeight > el.clientHeight + 1)
  .map((el) => el.textContent)"""


def test_the_replay_file_speaks_its_readers_language_and_switches(browser: Any, tmp_path: Path, shots: Path) -> None:
    from tablebot.cli.common import load
    from tablebot.sim.model.scene import scene_for
    from tablebot.sim.runner import simulate
    from tablebot.sinks.trace_file import block_lines
    from tablebot.web.replay import write_html

    table, machine = load(bumberbot(tmp_path))
    scene = scene_for(table, machine)
    page_file = write_html(
        tmp_path / "run.html",
        block_lines(simulate(scene, 5.0, 1).block(), machine),
        scene.world,
        table,
        params=scene.params,
    )
    context = browser.new_context(locale="de-DE", viewport={"width": 1280, "height": 720})
    page = context.new_page()
    errors: list[str] = []
    page.on("pageerror", lambda e: errors.append(str(e)))
    page.goto(page_file.as_uri())
    page.wait_for_function("() => document.querySelector('#status').textContent.startsWith('Takt 0')", timeout=60_000)
    assert page.locator("#tplay").inner_text() == "▶ Start"
    assert page.locator("table.grid thead th").first.inner_text() == "Zeile"
    page.screenshot(path=str(shots / "replay-german.png"))
    with page.expect_navigation():  # the switch reloads the page: wait in the new one, not in the one going away
        page.select_option("#language", "en")
    page.wait_for_function("() => document.querySelector('#status').textContent.startsWith('tick 0')", timeout=60_000)
    assert page.locator("#tplay").inner_text() == "▶ Play"
    # the choice comes back in the page's address as well as kept: a reload that read only the kept choice read
    # the old language on a busy machine, before the write had reached the browser's store
    assert page.url == page_file.as_uri() + "?lang=en"
    page.goto(page_file.as_uri() + "?lang=de")  # an address's language wins over the kept one
    page.wait_for_function("() => document.querySelector('#status').textContent.startsWith('Takt 0')", timeout=60_000)
    context.close()
    assert errors == []


def test_a_folder_without_a_table_says_so_in_german_and_nothing_outside_the_catalog(
    browser: Any, tmp_path: Path
) -> None:
    empty = tmp_path / "leer"
    empty.mkdir()
    for studio in served(empty, None):
        for locale, kept in (("de-DE", None), ("en-US", "qps")):
            context = browser.new_context(locale=locale, viewport={"width": 1280, "height": 720})
            if kept:
                context.add_init_script(f"localStorage.setItem('tablebot-studio-lang', {json.dumps(kept)})")
            page = context.new_page()
            page.goto(studio.url)
            page.wait_for_selector(".no-table")
            if kept:  # the commands to type and the templates' names are tablebot's own words, in every language
                page.evaluate("document.querySelectorAll('.no-table code, .starts button').forEach((e) => e.remove())")
                assert page.evaluate(OUTSIDE_MARKERS) == []
            else:
                text = page.locator(".no-table").inner_text()
                assert "Hier gibt es keine Tabelle" in text and "In leer gibt es keine Tabelle" in text, text
                assert page.locator("#save-state").inner_text() == "keine Tabelle"
            context.close()


def _page_language_of_studio(folder: Path, *args: str, **env: str) -> Any:
    """The language ``tablebot studio`` (a real process, with ``args`` and ``env``) hands its page: its
    /api/config's ``lang``, fetched with the token it printed."""
    process = subprocess.Popen(
        [sys.executable, "-m", "tablebot", *args, "studio", str(folder), "--no-browser", "--port", "0"],
        env={**os.environ, "COLUMNS": "200", **env},
        stderr=subprocess.PIPE,
        text=True,
    )
    lines: list[str] = []
    threading.Thread(target=lambda: lines.extend(process.stderr), daemon=True).start()  # type: ignore[arg-type]
    try:
        found = wait_for(
            lambda: re.search(r"(http://127\.0\.0\.1:\d+)/\?token=([\w-]+)", "".join(lines)), "the studio's address", 30
        )
        request = urllib.request.Request(found[1] + "/api/config", headers={"X-Tablebot-Token": found[2]})
        with urllib.request.urlopen(request, timeout=10) as reply:
            return json.load(reply)["lang"]
    finally:
        process.terminate()
        process.wait(10)


def test_studio_hands_lang_to_its_page_and_the_system_locale_leaves_it_to_the_browser(tmp_path: Path) -> None:
    folder = bumberbot(tmp_path)
    plain = {"TABLEBOT_LANG": "", "LC_ALL": "", "LC_MESSAGES": ""}
    assert _page_language_of_studio(folder, "--lang", "de", **plain, LANG="C.UTF-8") == "de"
    assert _page_language_of_studio(folder, **{**plain, "TABLEBOT_LANG": "en"}, LANG="de_DE.UTF-8") == "en"
    assert _page_language_of_studio(folder, **plain, LANG="de_DE.UTF-8") is None  # the browser's, then
