"""A robot of several tables in the studio (issue 36 §2), in a real Chromium against the real server: a tab per
table (named as in the robot file's [tables]), each edited in the same grid and saved to its own file, its edits
kept while another tab is shown; the arena runs the whole robot and draws its lamps, tick for tick as the engine's
trace has them; the page fits a projector and a tablet without sideways scrolling, in German too.

Screenshots go to ``studio-several`` under pytest's temporary folder (or ``$TABLEBOT_SCREENSHOTS``): look at them.
"""

from __future__ import annotations

import asyncio
import re
import shutil
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path
from typing import Any

import pytest

import tablebot
from core_helpers import ROOT
from studio_helpers import studio_works, wait_for
from tablebot.formats.csv_document import CsvDocument
from tablebot.web.analyse import analyse, robot_for
from tablebot.web.app import Background
from tablebot.web.session import Hub, Session
from tablebot.web.workspace import Workspace

LIGHTS = ROOT / "examples" / "bumberbot-lights"
#: A room with no lamp: the BumberBot seeks, so its lights table flashes the lamps in turn (beside a lamp they burn).
DARK_ROOM = """name = "A dark room"
[arena]
walls = [[0, 0], [2.4, 0], [2.4, 1.8], [0, 1.8]]
[start]
at = [1.2, 0.9]
heading = 0
"""
TIMER_COL = 8  # lights.csv: description, state, T, drive=1,2, drive=11,12, drive=20..29, L1, L2, timer, next
SEEN = """() => { window.seen = []; const arena = document.querySelector('#arena');
  new MutationObserver(() => window.seen.push([+arena.dataset.tick, arena.dataset.lamps]))
    .observe(arena, { attributes: true, attributeFilter: ['data-lamps'] }); }"""


@pytest.fixture(scope="module")
def folder(tmp_path_factory: pytest.TempPathFactory) -> Path:
    root = tmp_path_factory.mktemp("several") / "bot"
    shutil.copytree(LIGHTS, root)
    (root / "arena.toml").write_text(DARK_ROOM, encoding="utf-8")
    return root


def open_page(browser: Any, url: str, width: int = 1280, height: int = 720, locale: str = "en-GB") -> Any:
    context = browser.new_context(viewport={"width": width, "height": height}, locale=locale)
    page = context.new_page()
    page.errors = []
    page.on("pageerror", lambda e: page.errors.append(str(e)))
    page.goto(url)
    page.wait_for_selector("#play:not([disabled])", timeout=120_000)
    studio_works(page)
    page.wait_for_selector("#table-tabs button[data-table=lights]")
    return page


def tabs(page: Any) -> list[list[str]]:
    """The tabs' words, and whether each is the one shown."""
    return page.eval_on_selector_all(
        "#table-tabs button", "bs => bs.map(b => [b.textContent, b.getAttribute('aria-selected')])"
    )


#: Each header cell's column name, without the label under it (which comes with the table: its grid is drawn once).
HEADER_NAMES = (
    "hs => hs.map(h => [...h.childNodes].filter(n => n.nodeName !== 'SMALL').map(n => n.textContent).join(''))"
)


def show(page: Any, name: str, header: str) -> None:
    """Click table ``name``'s tab and wait for its grid (a header cell ``header`` of it)."""
    page.click(f"#table-tabs button[data-table={name}]")
    wait_for(
        lambda: header in page.eval_on_selector_all("table.grid thead th", HEADER_NAMES),
        f"the grid of {name}",
        30,
    )


def cell(page: Any, row: int, col: int) -> Any:
    return page.locator(f'td[data-row="{row}"][data-col="{col}"] input')


def test_a_tab_per_table_each_edited_and_saved_to_its_own_file(
    browser: Any, studio: Background, folder: Path, shots: Path
) -> None:
    drive_before = (folder / "table.csv").read_bytes()
    page = open_page(browser, studio.url)
    assert tabs(page) == [["drive", "true"], ["lights", "false"]]
    show(page, "lights", "drive=1,2")
    assert tabs(page) == [["drive", "false"], ["lights", "true"]]
    cell(page, 2, TIMER_COL).fill("40")  # the left lamp's flash: 40 ticks, not 50
    page.wait_for_selector("#save:not([disabled])")
    assert tabs(page)[1] == ["lights •", "true"]  # not saved yet
    show(page, "drive", "M1_dir")  # another tab shown: the lights table's edit is kept meanwhile
    assert page.locator("#save").is_disabled()
    show(page, "lights", "drive=1,2")
    assert cell(page, 2, TIMER_COL).input_value() == "40" and tabs(page)[1] == ["lights •", "true"]
    page.screenshot(path=str(shots / "lights-tab.png"))
    page.keyboard.press("Control+s")
    wait_for(lambda: b",0,8,40,flash_right" in (folder / "lights.csv").read_bytes(), "lights.csv saved")
    assert (folder / "lights.csv.bak").read_bytes() == (LIGHTS / "lights.csv").read_bytes()
    assert (folder / "table.csv").read_bytes() == drive_before  # each tab saves its own file only
    assert page.errors == []
    page.context.close()


def test_the_arena_runs_every_table_and_shows_the_lamps_as_the_engine_has_them(
    browser: Any, studio: Background, folder: Path, shots: Path
) -> None:
    page = open_page(browser, studio.url)
    show(page, "lights", "drive=1,2")
    page.click("#reset")  # the robot as the files are now (the lights table saved by the test before)
    page.wait_for_timeout(300)
    page.evaluate(SEEN)
    page.click("#play")
    wait_for(lambda: page.evaluate("() => new Set(window.seen.map((s) => s[1])).size") >= 2, "the lamps changing", 60)
    page.click("#play")  # pause
    page.screenshot(path=str(shots / "lamps.png"))
    seen = page.evaluate("() => window.seen")
    trace = tablebot.open(folder).simulate(seconds=seen[-1][0] * 0.01 + 0.1, seed=1).trace
    for tick, lamps in seen:  # every frame's lamps the page drew, at its tick
        assert lamps == f"L1={trace['L1'][tick]} L2={trace['L2'][tick]}", (tick, lamps)
    assert {lamps for _, lamps in seen} >= {"L1=0 L2=8", "L1=8 L2=0"}  # they flash in turn
    state = page.eval_on_selector("#status", "s => s.textContent")
    assert "flash_" in state  # the status line speaks of the table shown: the lights table's state
    assert page.errors == []
    page.context.close()


@pytest.mark.parametrize(
    ("width", "height", "locale"),
    [(1280, 720, "en-GB"), (1280, 720, "de-DE"), (1024, 768, "de-DE"), (1024, 768, "en-GB")],
)
def test_the_tabs_fit_a_classroom_screen(
    browser: Any, studio: Background, shots: Path, width: int, height: int, locale: str
) -> None:
    page = open_page(browser, studio.url, width, height, locale)
    show(page, "lights", "drive=1,2")
    page.wait_for_timeout(200)
    page.screenshot(path=str(shots / f"tabs-{width}-{locale}.png"))
    wide = page.evaluate(
        "() => [document.documentElement.scrollWidth, innerWidth, "
        "document.querySelector('#grid').scrollWidth, document.querySelector('#grid').clientWidth]"
    )
    assert wide[0] <= wide[1] and wide[2] <= wide[3], wide
    title = page.get_attribute("#table-tabs button[data-table=lights]", "title")
    assert title == ("Tabelle lights (lights.csv)" if locale == "de-DE" else "table lights (lights.csv)")
    assert page.errors == []
    page.context.close()


def test_the_trace_player_says_every_tables_state_and_line(
    browser: Any, studio: Background, folder: Path, shots: Path
) -> None:
    """A trace of the whole robot played on the lights tab: the lights table's state, row and timer speak (its
    timeline, lit row and diagram), and the drive table's state and line are said beside them, as the trace has
    them; on the drive tab the other way round."""
    run = tablebot.open(folder).simulate(seconds=1.2, seed=1)
    run.save(folder / "run", plots=False)
    trace = run.trace
    page = open_page(browser, studio.url)
    show(page, "lights", "drive=1,2")
    page.click("#mode-trace")
    page.evaluate(
        "() => { const s = document.querySelector('#trace-pick');"
        " s.append(new Option('run/trace.jsonl', 'run/trace.jsonl')); }"
    )
    page.select_option("#trace-pick", "run/trace.jsonl")
    wait_for(lambda: "drive:" in page.inner_text("#status"), "the player's status line", 30)
    tick = next(k for k in range(len(trace)) if trace["row"][k] >= 0)  # a drive row fired: a group row, as written
    page.evaluate(
        f"() => {{ const s = document.querySelector('#scrub'); s.value = {tick};"
        " s.dispatchEvent(new Event('input')); }"
    )
    status = page.inner_text("#status")
    page.screenshot(path=str(shots / "player-lights.png"))
    lights_state, drive_state = trace["lights.state"][tick], trace["state"][tick]
    assert f"state {lights_state}" in status.split(" · drive:")[0], status
    drive_row = trace["row"][tick]  # as written: a group's row once
    table = tablebot.open(folder).table
    line = next((r.line for r in table.rows if r.as_written == drive_row), None)
    said = f"drive: state {drive_state}, line {line} fired"
    assert said in status, (said, status)
    assert page.get_attribute("#arena", "data-lamps") == f"L1={trace['L1'][tick]} L2={trace['L2'][tick]}"
    assert page.errors == []
    page.context.close()


def test_a_tab_clicked_while_a_trace_plays_speaks_for_that_table(
    browser: Any, studio: Background, folder: Path, shots: Path
) -> None:
    """The trace playing on the drive tab, the lights tab clicked: the player goes on at the same tick with the
    lights table speaking (its state in the status line, the drive table's said beside it, its timeline), without
    the trace opened again; it kept the drive table's view until then (issue 36's leftover)."""
    run = tablebot.open(folder).simulate(seconds=20.0, seed=2)
    run.save(folder / "played", plots=False)
    trace = run.trace
    page = open_page(browser, studio.url)
    page.click("#mode-trace")
    page.evaluate(
        "() => { const s = document.querySelector('#trace-pick');"
        " s.append(new Option('played/trace.jsonl', 'played/trace.jsonl')); }"
    )
    page.select_option("#trace-pick", "played/trace.jsonl")
    wait_for(lambda: "lights:" in page.inner_text("#status"), "the drive tab's status line", 30)
    page.click("#tplay")
    wait_for(lambda: int(page.eval_on_selector("#scrub", "s => +s.value")) > 0, "the trace playing", 30)
    show(page, "lights", "drive=1,2")
    wait_for(lambda: "drive:" in page.inner_text("#status"), "the lights table speaking", 10)
    page.click("#tplay")  # paused: the tick shown and the status line stay together
    index = int(page.eval_on_selector("#scrub", "s => +s.value"))
    status = page.inner_text("#status")
    page.screenshot(path=str(shots / "player-tab-switched.png"))
    assert 0 < index < len(trace["tick"]) - 1, index  # switched while it played, not after the end
    head, drive = status.split(" · drive:")
    assert head.startswith(f"tick {trace['tick'][index]} · "), status
    assert re.search(rf"· state {re.escape(str(trace['lights.state'][index]))}( \(| ·|$)", head), status
    assert drive.startswith(f" state {trace['state'][index]},"), status
    assert page.errors == []
    page.context.close()


def test_a_german_walk_through_the_tabs(browser: Any, studio: Background, shots: Path) -> None:
    """A German browser: the tabs' tips, why each row of the drive table and of the lights table fired or not (said
    by the server in the tab's language), and the lights tab's status line speak German."""
    page = open_page(browser, studio.url, 1280, 720, "de-DE")
    assert page.inner_text("#save") == "Speichern"
    page.click("#step")
    wait_for(lambda: page.eval_on_selector_all("#why li", "ls => ls.map(l => l.textContent)"), "the why list", 30)
    why = page.eval_on_selector_all("#why li", "ls => ls.map(l => l.textContent)")
    assert why and all(line.startswith(("Zeile ", "keine Zeile")) for line in why), why
    assert any("hat geschaltet" in line for line in why), why
    show(page, "lights", "drive=1,2")
    page.click("#step")
    wait_for(lambda: "Zustand flash_" in page.inner_text("#status"), "the lights table's state, in German", 30)
    # why the lights table's rows of its state fired or not: its own rows (a group's row among them), by line
    wait_for(
        lambda: any(
            line.startswith("Zeile 5 (Seeking: flash right) hat nicht geschaltet: sie braucht T")
            for line in page.eval_on_selector_all("#why li", "ls => ls.map(l => l.textContent)")
        ),
        "why the lights table's rows did not fire",
        30,
    )
    assert page.get_attribute("#table-tabs button[data-table=drive]", "title") == "Tabelle drive (table.csv)"
    page.screenshot(path=str(shots / "german-walk.png"))
    assert page.errors == []
    page.context.close()


@pytest.mark.parametrize(
    ("old", "new", "column", "words"),
    [
        ("drive=20..29", "drive=99", 5, "drive=99: table drive has no state 99"),
        (",L1,", ",M1_speed,", 6, "M1 is written by two tables, drive ("),
    ],
)
def test_an_error_across_the_tables_is_marked_on_its_cell_in_its_tab(
    folder: Path, old: str, new: str, column: int, words: str
) -> None:
    """An error only the tables together show (a cross-table column naming a state its table lacks, a second writer
    of an output) is on its header cell in the tab of the table it is in, named by its file as the page names it."""
    path = folder / "lights.csv"
    doc = CsvDocument.from_text(path.read_text(encoding="utf-8").replace(old, new, 1))
    found = analyse(doc, path, robot_for(path), "lights.csv").data["diagnostics"]
    assert [(d["file"], d["row"], d["col"]) for d in found] == [("lights.csv", -1, column)], found
    assert found[0]["message"].startswith(words)


def test_the_live_path_is_coloured_by_the_states_of_the_table_shown(folder: Path) -> None:
    """The arena's path carries the state of the table whose tab is shown (the page colours it with that table's
    colours; the main table's states there would be grey), and the main table's again on its tab."""

    async def path_states(first: str, then: str) -> tuple[set[str], set[str]]:
        sent: list[dict[str, Any]] = []

        async def send(message: dict[str, Any]) -> None:
            sent.append(message)

        async def run_for(ticks: int) -> set[str]:
            sent.clear()
            await session.handle({"op": "sim", "action": "speed", "speed": "max"})
            await session.handle({"op": "sim", "action": "play"})
            while not any(m["type"] == "frame" and m["tick"] >= ticks for m in sent):
                await asyncio.sleep(0.04)
                await session.frame()
            await session.handle({"op": "sim", "action": "pause"})
            for _ in range(5):  # what it drew up to the pause (the next tab's frames are that tab's)
                await asyncio.sleep(0.04)
                await session.frame()
            return {p[2] for m in sent if m["type"] == "frame" for p in m["path"]}

        session = Session(Workspace(folder), Hub(), send)
        try:
            await session.handle({"op": "open", "path": first})
            seen_first = await run_for(300)
            await session.handle({"op": "open", "path": then})
            seen_then = await run_for(600)
        finally:
            session.close()
        return seen_first, seen_then

    with ThreadPoolExecutor(1) as thread:  # the browser tests' Playwright holds this thread's event loop
        lights, drive = thread.submit(asyncio.run, path_states("lights.csv", "table.csv")).result()
    assert lights and lights <= {"flash_left", "flash_right", "burn", "blink_on", "blink_off"}, lights
    assert drive and drive <= {"1", "2", "11", "12", "20", "21", "22", "24", "26", "29"}, drive


def test_the_robot_starts_over_when_its_table_is_read_again_not_when_another_tab_is_shown(folder: Path) -> None:
    """The first look at another table's tab leaves the robot running; the table shown read again (its file
    loaded after a conflict, the page reconnecting) starts it over with the file as it is, as it always did."""

    async def arenas() -> list[int]:
        sent: list[dict[str, Any]] = []

        async def send(message: dict[str, Any]) -> None:
            sent.append(message)

        session = Session(Workspace(folder), Hub(), send)
        counts = []
        try:
            for path in ("table.csv", "lights.csv", "table.csv", "table.csv"):
                sent.clear()
                await session.handle({"op": "open", "path": path})
                counts.append(sum(m["type"] == "arena" for m in sent))
        finally:
            session.close()
        return counts

    with ThreadPoolExecutor(1) as thread:
        assert thread.submit(asyncio.run, arenas()).result() == [1, 0, 0, 1]


def test_a_counterexample_on_the_table_replays_every_table(folder: Path) -> None:
    """A broken property's counterexample played on the table (the trace player) is the whole robot's run: the
    lights table's columns and the lamps as tablebot's engine of several tables has them on those inputs."""
    from tablebot.replay import replay_several
    from tablebot.tables import several

    async def columns() -> dict[str, Any]:
        sent: list[dict[str, Any]] = []

        async def send(message: dict[str, Any]) -> None:
            sent.append(message)

        session = Session(Workspace(folder), Hub(), send)
        try:
            await session.handle({"op": "open", "path": "lights.csv"})
            sent.clear()
            await session.handle({"op": "counterexample", "name": "front_bumper_stops"})
            analysis = session.draft.analysis
            assert analysis is not None and analysis.report is not None
            result = next(r for r in analysis.report.results if r.prop.name == "front_bumper_stops")
        finally:
            session.close()
        (trace,) = [m for m in sent if m["type"] == "trace"]
        tables = several(tablebot.open(folder).table)
        assert tables is not None
        expected = list(replay_several(tables, result.inputs))
        assert trace["columns"]["lights.state"] == [line["lights.state"] for line in expected]
        return trace["columns"]

    with ThreadPoolExecutor(1) as thread:
        found = thread.submit(asyncio.run, columns()).result()
    assert {"lights.state", "lights.row", "L1", "L2"} <= set(found)
    assert any(found["L1"]) and any(found["L2"])  # the lamps the lights table lit on the way
