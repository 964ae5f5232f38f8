"""Studio speed: edit -> findings latency, and whether the live view keeps up with 10x real time.

    .venv/bin/python benchmarks/studio.py

Edit latency is measured twice: the analysis alone (parse, compile, check with properties: what an
edit costs the server) beside its baseline, the same steps as ``tablebot check`` calls them; and the
whole round trip through a real server and WebSocket (send an edit, receive its findings). The live
view is measured in a real Chromium (when /usr/bin/chromium exists) against a real server: ticks the
page shows per wall second at 10x and at "max", the frames it draws, and how far it trails the robot.
Every tick is simulated; only drawing is decimated (at most 25 frames a second).
"""

from __future__ import annotations

import asyncio
import json
import shutil
import statistics
import sys
import tempfile
import time
from pathlib import Path
from typing import TYPE_CHECKING

import websockets

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "src"))

from tablebot.analysis.check import run_check  # noqa: E402
from tablebot.analysis.properties import find_property_files, load_properties  # noqa: E402
from tablebot.formats.csv_document import CsvDocument  # noqa: E402
from tablebot.formats.table_read import load_table  # noqa: E402
from tablebot.machine import compile_table  # noqa: E402
from tablebot.web.analyse import analyse, robot_for  # noqa: E402
from tablebot.web.app import Background  # noqa: E402

if TYPE_CHECKING:
    from collections.abc import Callable

    from playwright.sync_api import Page
    from websockets.asyncio.client import ClientConnection

EXAMPLE = ROOT / "examples" / "bumberbot"
REPEATS = 30


def median_ms(func: Callable[[], object], repeats: int = REPEATS) -> float:
    times = []
    for _ in range(repeats):
        started = time.perf_counter()
        func()
        times.append(time.perf_counter() - started)
    return 1000 * statistics.median(times)


def cli_check(path: Path) -> None:
    machine = compile_table(load_table(path))
    run_check(machine, load_properties(machine, find_property_files(path)))


def edit_latency(folder: Path) -> None:
    path = folder / "table.csv"
    doc = CsvDocument.from_bytes(path.read_bytes(), str(path))
    robot = robot_for(path)
    baseline = median_ms(lambda: cli_check(path))
    studio = median_ms(lambda: analyse(doc, path, robot, "table.csv"))
    server = Background(folder, "table.csv")
    try:
        trip = asyncio.run(round_trips(server))
    finally:
        server.stop()
    print("edit -> findings, BumberBot (37 rows, 7 properties)")
    print(f"  baseline: tablebot check's steps (parse, compile, check)  {baseline:7.1f} ms")
    print(
        f"  studio analysis of one edit                               {studio:7.1f} ms  "
        f"({studio / baseline:.2f}x the baseline)"
    )
    print(
        f"  round trip through the server (edit sent -> findings in)  {trip:7.1f} ms  "
        f"({trip / baseline:.2f}x the baseline; target < 100 ms: {'met' if trip < 100 else 'MISSED'})"
    )


async def round_trips(server: Background) -> float:
    """Median edit round trip, as the studio's page talks (its Origin and token header)."""
    async with websockets.connect(
        server.origin.replace("http", "ws") + "/ws", max_size=2**24, additional_headers=server.headers
    ) as ws:
        await ws.send(json.dumps({"op": "open", "path": "table.csv"}))
        await _until(ws, lambda m: m["type"] == "analysis")
        times = []
        for seq in range(1, REPEATS + 1):
            value = "9" if seq % 2 else "4"  # alternately break and fix a motor speed
            started = time.perf_counter()
            await ws.send(json.dumps({"op": "edit", "row": 4, "col": 9, "value": value, "seq": seq}))
            await _until(ws, _analysis_of(seq))
            times.append(time.perf_counter() - started)
        return 1000 * statistics.median(times)


def _analysis_of(seq: int) -> Callable[[dict], bool]:
    """Whether a message is the analysis answering edit ``seq``."""
    return lambda message: message["type"] == "analysis" and message.get("seq") == seq


async def _until(ws: ClientConnection, wanted: Callable[[dict], bool]) -> dict:
    while True:
        message = json.loads(await asyncio.wait_for(ws.recv(), 30))
        if wanted(message):
            return message


def live_view(folder: Path) -> None:
    chromium = Path("/usr/bin/chromium")
    if not chromium.exists():
        print("live view: skipped (no /usr/bin/chromium; scripts/bootstrap.sh installs it)")
        return
    from playwright.sync_api import sync_playwright

    server = Background(folder, "table.csv")
    try:
        with sync_playwright() as p:
            browser = p.chromium.launch(
                executable_path=str(chromium), args=["--headless=new", "--no-sandbox", "--disable-gpu"]
            )
            page = browser.new_page(viewport={"width": 1366, "height": 768})
            page.goto(server.url)
            page.wait_for_function("() => document.querySelector('#counts').textContent.includes('states')")
            page.wait_for_selector("#play:not([disabled])")
            # the page's counters live in a module (no globals): take a handle on the same instance
            page.evaluate("import('/static/js/studio/stats.js').then((m) => { window.stats = m.stats; })")
            print("live view in Chromium, BumberBot in its arena (100 ticks per robot second)")
            for speed, label in (("10", "10x"), ("max", "max")):
                _measure(page, speed, label)
            browser.close()
    finally:
        server.stop()


def _measure(page: Page, speed: str, label: str, seconds: float = 6.0) -> None:
    page.click("#reset")
    page.wait_for_timeout(500)
    page.click(f'[data-speed="{speed}"]')
    page.click("#play")
    page.wait_for_function("() => stats.ticks > 50")
    start = page.evaluate("() => ({t: performance.now(), tick: stats.ticks, frames: stats.frames})")
    page.wait_for_timeout(seconds * 1000)
    end = page.evaluate("() => ({t: performance.now(), tick: stats.ticks, frames: stats.frames, draw: stats.drawMs})")
    page.click("#play")  # pause
    wall = (end["t"] - start["t"]) / 1000
    ticks = end["tick"] - start["tick"]
    speedup = ticks / 100 / wall
    frames = (end["frames"] - start["frames"]) / wall
    if speed == "10":
        verdict = "keeps up" if speedup >= 9.8 else "FALLS BEHIND"
        print(
            f"  10x: {speedup:6.2f}x real time shown ({speedup / 10:.3f} of the target: {verdict}), "
            f"{frames:4.1f} frames/s drawn"
        )
    else:
        print(
            f"  max: {speedup:6.0f}x real time shown ({speedup / 10:.0f}x the 10x target), "
            f"{frames:4.1f} frames/s drawn, last draw {end['draw']:.2f} ms"
        )


def main() -> None:
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp) / "bumberbot"
        shutil.copytree(EXAMPLE, folder)
        edit_latency(folder)
        live_view(folder)


if __name__ == "__main__":
    main()
