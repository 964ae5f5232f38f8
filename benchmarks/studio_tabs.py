"""Studio with many tabs: its memory before, with and after many live tabs, and how long a new request waits.

    .venv/bin/python benchmarks/studio_tabs.py [--tabs 60] [--rounds 3]

One real ``tablebot studio`` process (as a user starts it) on a copy of the BumberBot; its resident size is
read from /proc. Each round opens ``--tabs`` tabs as the page does (a WebSocket, open the table: its robot
starts in the arena) and plays them all as fast as they go, then measures how long a new request waits
(GET /api/config, median of 5) beside the same request in the idle studio of this run (the baseline), then
closes every tab. The studio serves at most ``tablebot.web.app.MAX_TABS`` tabs at once: the others are
turned away (counted). Memory is given as the size with the tabs open and after they closed, against the
size after the first tab (the baseline): "given back" is the share of what the tabs took that the studio
returned once they were gone, and the size after each round says whether it keeps growing.

The studio is the ``tablebot`` the interpreter imports: ``PYTHONPATH=<another tree>/src`` measures that
tree's (an older studio serves every tab: run it the same way to compare).
"""

from __future__ import annotations

import argparse
import asyncio
import json
import re
import shutil
import signal
import statistics
import subprocess
import sys
import tempfile
import time
import urllib.request
from pathlib import Path
from typing import Any

import websockets

ROOT = Path(__file__).resolve().parents[1]
EXAMPLE = ROOT / "examples" / "bumberbot"
SETTLE_S = 2.0  # after the tabs open or close, before measuring: the live threads start or end


class Studio:
    """A ``tablebot studio`` process and what its page sends (Origin, token header)."""

    def __init__(self, folder: Path) -> None:
        self.process = subprocess.Popen(
            [sys.executable, "-m", "tablebot.cli", "studio", str(folder), "--port", "0", "--no-browser"],
            stderr=subprocess.PIPE,
            text=True,
        )
        assert self.process.stderr is not None
        while not (found := re.search(r"http://127\.0\.0\.1:(\d+)/\?token=([\w-]+)", self.process.stderr.readline())):
            if self.process.poll() is not None:
                raise SystemExit("the studio did not start")
        self.port, token = int(found[1]), found[2]
        self.origin = f"http://127.0.0.1:{self.port}"
        self.headers = {"Origin": self.origin, "X-Tablebot-Token": token}

    def rss_mb(self) -> float:
        status = Path(f"/proc/{self.process.pid}/status").read_text()
        return int(re.search(r"VmRSS:\s+(\d+) kB", status)[1]) / 1024  # type: ignore[index]

    def request_ms(self) -> float:
        """Median wait of a new request for the folder's listing."""
        times = []
        for _ in range(5):
            started = time.perf_counter()
            request = urllib.request.Request(self.origin + "/api/config", headers=self.headers)
            with urllib.request.urlopen(request, timeout=120) as reply:
                reply.read()
            times.append(time.perf_counter() - started)
        return 1000 * statistics.median(times)

    def stop(self) -> None:
        self.process.send_signal(signal.SIGINT)
        self.process.communicate(timeout=30)


async def open_tab(studio: Studio) -> tuple[Any, bool]:
    """A tab as the page opens it, playing its robot as fast as it goes; whether the studio took it."""
    ws = await websockets.connect(
        studio.origin.replace("http", "ws") + "/ws", additional_headers=studio.headers, max_size=2**24
    )
    await ws.send(json.dumps({"op": "open", "path": "table.csv"}))
    while (message := json.loads(await asyncio.wait_for(ws.recv(), 120)))["type"] not in ("arena", "error"):
        pass
    if message["type"] == "error":
        return ws, False
    for action in ({"action": "speed", "speed": "max"}, {"action": "play"}):
        await ws.send(json.dumps({"op": "sim", **action}))
    return ws, True


async def drain(ws: Any) -> None:
    """Read the tab's frames as the page would (a page that stops reading would stall its sender)."""
    try:
        async for _ in ws:
            pass
    except websockets.ConnectionClosed:
        pass


async def one_round(studio: Studio, tabs: int) -> dict[str, float]:
    opened = [await open_tab(studio) for _ in range(tabs)]
    readers = [asyncio.create_task(drain(ws)) for ws, _ in opened]
    await asyncio.sleep(SETTLE_S)
    wait_ms = await asyncio.to_thread(studio.request_ms)
    size = studio.rss_mb()
    for ws, _ in opened:
        await ws.close()
    await asyncio.gather(*readers)
    await asyncio.sleep(SETTLE_S)
    return {
        "accepted": sum(took for _, took in opened),
        "wait_ms": wait_ms,
        "open_mb": size,
        "closed_mb": studio.rss_mb(),
    }


async def measure(studio: Studio, tabs: int, rounds: int) -> None:
    ws, _ = await open_tab(studio)  # the first tab loads what every tab shares (numba, the table, Graphviz)
    await ws.close()
    await asyncio.sleep(SETTLE_S)
    base_mb, idle_ms = studio.rss_mb(), await asyncio.to_thread(studio.request_ms)
    print(f"studio with {tabs} tabs opened at once, each robot playing as fast as it goes ({rounds} rounds)")
    print(f"  baseline (one tab opened and closed): {base_mb:6.1f} MB resident, a new request {idle_ms:6.1f} ms")
    for number in range(1, rounds + 1):
        r = await one_round(studio, tabs)
        took = r["open_mb"] - base_mb
        back = (r["open_mb"] - r["closed_mb"]) / took if took > 0 else 1.0
        print(
            f"  round {number}: {r['accepted']:.0f} of {tabs} tabs served; a new request waited "
            f"{r['wait_ms']:7.1f} ms ({r['wait_ms'] / idle_ms:5.1f}x the baseline); {r['open_mb']:6.1f} MB "
            f"open (+{took:5.1f}), {r['closed_mb']:6.1f} MB closed (+{r['closed_mb'] - base_mb:5.1f}: "
            f"{100 * back:3.0f}% given back)"
        )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--tabs", type=int, default=60)
    parser.add_argument("--rounds", type=int, default=3)
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp) / "bumberbot"
        shutil.copytree(EXAMPLE, folder)
        studio = Studio(folder)
        try:
            asyncio.run(measure(studio, args.tabs, args.rounds))
        finally:
            studio.stop()


if __name__ == "__main__":
    main()
