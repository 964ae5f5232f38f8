"""The studio in a real browser: Debian's Chromium driven by Playwright against the real server.

One server and one browser for the module; each test gets a fresh page (a tab) on a copy of the
BumberBot. Screenshots of every view go to ``studio-browser`` under pytest's temporary folder (or to
``$TABLEBOT_SCREENSHOTS``) for a person to look at. Any console error or page error fails the test.
"""

from __future__ import annotations

import csv
import json
import re
from collections import defaultdict
from collections.abc import Iterator
from pathlib import Path
from typing import TYPE_CHECKING

import pytest

from studio_helpers import Browsers, bumberbot
from tablebot.colours import state_colours
from tablebot.web.app import Background

pytestmark = [pytest.mark.browser]

if TYPE_CHECKING:
    from playwright.sync_api import Locator

    from tablebot.robot import StateId

TIMER_COL, M1_SPEED_COL = 12, 9
# what the browser drew: the timeline's top row of pixels (RGBA), and each state's border in the diagram
TIMELINE = """() => { const c = document.querySelector('#timeline');
  return Array.from(c.getContext('2d').getImageData(0, 1, c.width, 1).data); }"""
BORDERS = """() => [...document.querySelectorAll('#diagram g.node')].map((g) => [g.querySelector('title').textContent,
  getComputedStyle(g.querySelector('path, polygon, ellipse')).stroke])"""


@pytest.fixture(scope="module")
def folder(tmp_path_factory: pytest.TempPathFactory) -> Path:
    root = bumberbot(tmp_path_factory.mktemp("studio-browser"), "bumberbot")
    _write_sim_trace(root)
    return root


def _write_sim_trace(root: Path) -> None:
    from tablebot.cli.common import load
    from tablebot.sim.model.scene import scene_for
    from tablebot.sim.runner import simulate

    table, machine = load(root)
    with (root / "trace.jsonl").open("w", encoding="utf-8") as f:
        simulate(scene_for(table, machine), 20.0, 1).write_trace(f)


class Tab:
    """A page on the studio that records console errors."""

    def __init__(self, browser: object, url: str, shots: Path, name: str) -> None:
        self.context = browser.new_context(viewport={"width": 1366, "height": 768})  # type: ignore[attr-defined]
        self.page = self.context.new_page()
        self.errors: list[str] = []
        self.page.on("console", lambda m: self.errors.append(m.text) if m.type == "error" else None)
        self.page.on("pageerror", lambda e: self.errors.append(str(e)))
        self.shots, self.name = shots, name
        self.page.goto(url)
        self.page.wait_for_selector("table.grid tbody tr")
        self.page.wait_for_function("() => document.querySelector('#counts').textContent.includes('states')")
        self.page.wait_for_selector("#play:not([disabled])")  # the robot is in its arena
        # the page's counters live in a module (the page has no globals): the test takes a handle on them
        self.page.evaluate("import('/static/js/studio/stats.js').then((m) => { window.stats = m.stats; })")

    def cell(self, row: int, col: int) -> Locator:
        return self.page.locator(f'td[data-row="{row}"][data-col="{col}"]')

    def status(self) -> str:
        return self.page.locator("#status").inner_text()

    def shot(self, what: str) -> None:
        self.page.screenshot(path=str(self.shots / f"{self.name}-{what}.png"))

    def close(self) -> None:
        self.context.close()
        assert self.errors == []


@pytest.fixture
def tab(browser: object, studio: Background, shots: Path, request: pytest.FixtureRequest) -> Iterator[Tab]:
    page = Tab(browser, studio.url, shots, request.node.name.removeprefix("test_"))
    yield page
    page.close()


def drawn_colours(page: object, ticks: list[str], cursor: int) -> dict[str, set[str]]:
    """The colours the page drew for each state: over its ticks in the timeline (``ticks``: the state of each
    tick of the trace shown; the cursor, at tick ``cursor``, left out) and as its border in the diagram."""
    pixels = page.evaluate(TIMELINE)  # type: ignore[attr-defined]
    band = [_hex(pixels[i : i + 3]) for i in range(0, len(pixels), 4)]
    drawn: dict[str, set[str]] = defaultdict(set)
    at = cursor / max(1, len(ticks) - 1) * (len(band) - 2) + 1
    for x, colour in enumerate(band):  # pixel column x shows tick floor(x / width * ticks), as the page draws it
        if abs(x - at) > 3:
            drawn[ticks[min(len(ticks) - 1, int(x / len(band) * len(ticks)))]].add(colour)
    for title, stroke in page.evaluate(BORDERS):  # type: ignore[attr-defined]
        if title.startswith("s_"):
            drawn[title[2:]].add(_hex([int(v) for v in re.findall(r"\d+", stroke)[:3]]))
    return drawn


def _hex(rgb: list[int]) -> str:
    return "#" + "".join(f"{v:02x}" for v in rgb)


def pictures_colours(states: tuple[StateId, ...]) -> dict[str, set[str]]:
    """Each state's colour in the PNGs of a run (tablebot.colours)."""
    return {str(s): {c} for s, c in zip(states, state_colours(states), strict=True)}


def test_the_bumberbot_loads_with_37_rows_and_10_states(tab: Tab) -> None:
    page = tab.page
    assert page.locator("table.grid tbody tr").count() == 37
    assert re.search(r"37 rows · 10 states · 0 errors · 1 warning", page.locator("#counts").inner_text())
    page.wait_for_selector("#diagram svg g.node")
    states = page.eval_on_selector_all("#diagram g.node title", "ts => ts.map(t => t.textContent)")
    assert len([s for s in states if s.startswith("s_")]) == 10
    assert "front_bumper_stops" in page.locator("#properties").inner_text()
    tab.shot("table")


def test_the_desktop_chromium_a_teacher_opens_runs_the_studio_too(
    browsers: Browsers, studio: Background, shots: Path
) -> None:
    """The other tests drive Chromium's headless shell (half the CPU); the desktop browser loads the same page,
    draws its diagram and plays the robot, without an error in its console."""
    tab = Tab(browsers.get(full=True), studio.url, shots, "desktop")
    try:
        page = tab.page
        assert re.search(r"37 rows · 10 states", page.locator("#counts").inner_text())
        page.wait_for_selector("#diagram svg g.node")
        page.click("#play")
        page.wait_for_function("() => stats.ticks > 50")
        tab.shot("playing")
    finally:
        tab.close()


def test_a_broken_cell_shows_its_located_error_then_clears(tab: Tab) -> None:
    page = tab.page
    speed = tab.cell(4, M1_SPEED_COL).locator("input")
    speed.fill("9")
    page.wait_for_selector(f'td[data-row="4"][data-col="{M1_SPEED_COL}"].err')
    note = page.locator(".cell-note")
    assert "line 6, column 32: M1_speed: 9 is out of range 0..8" in note.inner_text()
    assert "hint: write a whole number from 0 to 8" in note.inner_text()
    assert "table.csv:6:32: M1_speed: 9 is out of range 0..8" in page.locator("#problems").inner_text()
    assert "does not read" in page.locator("#counts").inner_text()
    tab.shot("error")
    speed.fill("4")
    page.wait_for_function("() => !document.querySelector('td.err')")
    assert page.locator(".cell-note").is_hidden()
    assert "37 rows" in page.locator("#counts").inner_text()


def test_play_leaves_state_2_for_1_within_a_second_of_robot_time(tab: Tab) -> None:
    page = tab.page
    # idle, the page asks the browser for no frame (a loop drawing nothing kept ~6 % of a core busy); the robot
    # playing, the arena is drawn again and again
    page.evaluate("""() => { window.frames_asked = 0; const ask = window.requestAnimationFrame.bind(window);
        window.requestAnimationFrame = (f) => { window.frames_asked += 1; return ask(f); }; }""")
    before = page.evaluate("() => document.querySelector('#arena').toDataURL()")
    page.wait_for_timeout(1000)
    assert page.evaluate("() => window.frames_asked") == 0
    page.click("#play")
    seen = page.wait_for_function("""() => {
        const status = document.querySelector('#status').textContent;
        const node = document.querySelector('#diagram g.node.current title');
        return status.includes('state 1 (') && node && node.textContent === 's_1' && status; }""").json_value()
    tick = int(re.match(r"tick (\d+)", seen)[1])  # type: ignore[index]
    assert tick < 100  # state 1 was reached within 100 ticks = 1 s of robot time
    page.wait_for_function("() => stats.ticks > 150")
    assert page.evaluate("() => window.frames_asked") > 10
    assert page.evaluate("() => document.querySelector('#arena').toDataURL()") != before  # the robot moved
    tab.shot("live")


def test_paused_hold_i3_and_step_fires_a_collision_row(tab: Tab) -> None:
    page = tab.page
    page.click("#play")
    page.wait_for_function("() => stats.ticks > 20")
    page.click("#play")  # pause
    page.wait_for_selector("#step:not([disabled])")
    page.click('#inputs button[data-input="I3"]')
    page.wait_for_selector('#inputs button[data-input="I3"].held-on')
    before = page.evaluate("stats.ticks")
    page.click("#step")
    page.wait_for_function(f"() => stats.ticks > {before}")
    page.wait_for_function("() => document.querySelector('#status').textContent.includes('state 20')")
    fired = page.locator("#why li.why-fired").inner_text()
    # the robot may be seeking (state 1 or 2) or following the light (11): each has its own I3 row
    # one numbering: the file's lines, as the grid shows them, in the why list and the status line alike
    match = re.match(r"line (\d+) (\([^)]*\) )?fired: it needs I3, all present", fired)
    assert match and match[1] in {"3", "7", "29"}, fired
    assert re.search(r"line \d+ (\([^)]*\) )?did not fire: it needs I4", page.locator("#why").inner_text())
    assert page.locator("tr.fired td.num").inner_text() == match[1]
    assert f"line {match[1]} fired" in tab.status()
    tab.shot("step")


def test_save_changes_only_the_edited_cell_and_keeps_a_backup(
    tab: Tab, folder: Path, browser: object, studio: Background, shots: Path
) -> None:
    page = tab.page
    path = folder / "table.csv"
    original = path.read_bytes()
    other = Tab(browser, studio.url, shots, "other-tab")
    try:
        tab.cell(3, TIMER_COL).locator("input").fill("900")
        page.wait_for_selector("#save.primary")
        page.click("#save")
        page.wait_for_selector(".banner:not(.bad)")
        line5 = b"Seek - Straight,1,1,,,,,,1,2,,2,%d,2\n"
        assert path.read_bytes() == original.replace(line5 % 895, line5 % 900)
        assert original.count(b",895,") == 1 and (folder / "table.csv.bak").read_bytes() == original
        # the other tab sees the save
        timer = f'td[data-row="3"][data-col="{TIMER_COL}"] input'
        other.page.wait_for_function(f"() => document.querySelector('{timer}').value === '900'")
        other.shot("saw-save")
        # someone changes the file on disk: the next save is refused, not silent
        path.write_bytes(original)
        tab.cell(3, TIMER_COL).locator("input").fill("901")
        page.wait_for_selector("#save.primary")
        page.click("#save")
        page.wait_for_selector("#ask[open]")  # what each answer does: test_studio_drafts.py
        assert "table.csv was changed on disk" in page.locator("#ask").inner_text()
        assert path.read_bytes() == original
        tab.shot("conflict")
    finally:
        path.write_bytes(original)
        other.close()


def test_a_trace_file_plays_in_the_player(tab: Tab) -> None:
    page = tab.page
    page.click("#mode-trace")
    page.select_option("#trace-pick", "trace.jsonl")
    page.wait_for_function("() => document.querySelector('#status').textContent.startsWith('tick 0')")
    page.locator("#scrub").fill("1500")
    page.wait_for_function("() => document.querySelector('#status').textContent.startsWith('tick 1500')")
    assert page.locator("#timeline").is_visible()
    assert page.locator("#diagram g.node.current").count() == 1
    tab.shot("trace")


def test_a_state_has_its_pictures_colour_and_keeps_it_when_rows_move(tab: Tab, folder: Path) -> None:
    """The first collision rows of states 1 and 2 (alike but for their state) swap places: the same motions,
    but the table now names state 2 first. The page still draws each state in its colour in the PNGs."""
    from tablebot.cli.common import load

    page = tab.page
    rows = list(csv.reader((folder / "table.csv").open(encoding="utf-8")))[1:]
    for row, other in ((0, 4), (4, 0)):
        for col, (mine, theirs) in enumerate(zip(rows[row], rows[other], strict=True)):
            if mine != theirs:
                tab.cell(row, col).locator("input").fill(theirs)
    page.wait_for_timeout(300)  # a typed cell is sent 120 ms after its last key; the trace is asked for after it
    page.click("#mode-trace")
    page.select_option("#trace-pick", "trace.jsonl")
    page.wait_for_function("() => document.querySelector('#status').textContent.startsWith('tick 0')")
    ticks = [str(json.loads(line)["state"]) for line in (folder / "trace.jsonl").open(encoding="utf-8")]
    assert page.locator('td[data-row="0"][data-col="1"] input').input_value() == "2" and {"1", "2"} <= set(ticks)
    assert drawn_colours(page, ticks, 0) == pictures_colours(load(folder)[1].states)
    tab.shot("colours")


def test_a_counterexample_plays_on_the_table(tab: Tab) -> None:
    page = tab.page
    page.locator("#properties li", has_text="front_bumper_stops").locator('button[data-where="table"]').click()
    page.wait_for_function("() => document.querySelector('#trace-pick').value.startsWith('counterexample')")
    assert page.locator("#status").inner_text().startswith("tick")
    tab.shot("counterexample")


def test_the_replay_file_plays_alone_and_keeps_hostile_text_inert(browser: object, tmp_path: Path, shots: Path) -> None:
    from tablebot.cli.common import load
    from tablebot.sim.model.scene import scene_for
    from tablebot.sim.runner import simulate
    from tablebot.sinks.trace_file import block_lines
    from tablebot.web.replay import write_html

    folder = bumberbot(tmp_path)
    table_csv = folder / "table.csv"
    hostile = '</script><script>window.pwned=1</script><img src=x onerror="window.pwned=2">'
    table_csv.write_text(table_csv.read_text().replace("Seek - Turn", hostile.replace('"', '""').join('""')))
    table, machine = load(folder)
    scene = scene_for(table, machine)
    result = simulate(scene, 30.0, 1)
    page_file = write_html(
        tmp_path / "run.html", block_lines(result.block(), machine), scene.world, table, params=scene.params
    )
    text = page_file.read_text()
    assert text.lower().count("</script") == 2
    assert "http:" not in text.replace("http://www.w3.org/", "") and "https:" not in text  # SVG namespaces
    context = browser.new_context(viewport={"width": 1366, "height": 768})  # type: ignore[attr-defined]
    page = context.new_page()
    errors: list[str] = []
    page.on("console", lambda m: errors.append(m.text) if m.type == "error" else None)
    page.on("pageerror", lambda e: errors.append(str(e)))
    page.route("**/*", lambda route: route.abort() if not route.request.url.startswith("file:") else route.continue_())
    page.goto(page_file.as_uri())
    page.wait_for_function("() => document.querySelector('#status').textContent.startsWith('tick 0')")
    assert page.locator("table.grid tbody tr").count() == 37
    assert page.locator('td[data-row="7"][data-col="0"] textarea').input_value() == hostile
    page.locator("#scrub").fill("2000")
    page.wait_for_function("() => document.querySelector('#status').textContent.startsWith('tick 2000')")
    assert page.locator("#diagram g.node.current").count() == 1
    assert page.evaluate("() => window.pwned === undefined")
    ticks = [str(machine.states[i]) for i in result.states]
    assert drawn_colours(page, ticks, 2000) == pictures_colours(machine.states)
    page.screenshot(path=str(shots / "replay-file.png"))
    context.close()
    assert errors == []
