"""Benchmark: the live loop's cadence on each controller, as the whole command a user runs and as the link alone.

Run: ``.venv/bin/python benchmarks/controllers.py [--seconds 10] [--only robotx,roboif]``.

No controller is here: each target is an emulator written from the published sources (a fake) — the ROBO TX
on a pseudo-terminal (fish.X1), the ROBO Interface on a pseudo-terminal as fast as the pty carries bytes and
as slow as its real 38400-baud line, and the TXT as the tests' fake TXT over TCP (pacing replies at 10 ms
like a TXT) for comparison. Two kinds of figure, kept apart:

* **whole command** (a fresh process, what a user waits for): ``tablebot run examples/bumberbot --on TARGET
  --seconds S --out DIR --quiet``; from the emulator's own log of when each exchange arrived: exchanges per
  second and the gaps between consecutive exchanges (median, p95, max; the tick is 10 ms), and the late ticks
  the run counted. Ratios are against the TXT's figures from the same run.
* **link alone** (in this process): one exchange after another with no pacing: the round trip the link
  itself costs (what is left of a 10 ms tick for everything else).
"""

from __future__ import annotations

import argparse
import itertools
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
EXAMPLE = ROOT / "examples" / "bumberbot"
sys.path.insert(0, str(ROOT / "tests"))  # the tests' fake TXT, for the comparison

from tablebot.hw.link_speed import PROBES  # noqa: E402  (after the path is set)


@contextmanager
def target(name: str) -> Iterator[tuple[str, Any, Callable[[], list[float]]]]:
    """(the --on address, the emulator, its exchange arrival times) for one target."""
    if name == "txt":
        from txt_fake import FakeTxt

        with FakeTxt(period_s=0.01) as fake:
            yield f"txt://127.0.0.1:{fake.port}", fake, lambda: [r.t for r in fake.requests("ExchangeData")]
        return
    if name == "robotx":
        from tablebot.testing.robotx_emulator import RobotxEmulator

        emulator: Any = RobotxEmulator()
    else:
        from tablebot.testing.roboif_emulator import RoboifEmulator

        emulator = RoboifEmulator(baud=38400 if name == "roboif@38400" else 0)
    with emulator:
        address = f"{name.split('@')[0]}://{emulator.device}"
        yield address, emulator, lambda: [r.t for r in emulator.requests("exchange")]


def whole_command(name: str, seconds: float) -> dict[str, Any]:
    with target(name) as (address, _emulator, times), tempfile.TemporaryDirectory() as out:
        started = time.perf_counter()
        command = [
            sys.executable,
            "-m",
            "tablebot",
            "run",
            str(EXAMPLE),
            "--on",
            address,
            "--seconds",
            str(seconds),
            "--out",
            out,
            "--quiet",
        ]
        if name == "roboif@38400":  # refused before the run at tick_ms = 10: measured here with slow timers accepted
            command += ["--behind-limit", "0"]
        done = subprocess.run(command, capture_output=True, text=True, timeout=seconds + 60)
        wall = time.perf_counter() - started
        time.sleep(0.2)
        arrived = times()
        summary = json.loads((Path(out) / "summary.json").read_text()) if done.returncode == 0 else {}
    if done.returncode != 0:
        raise SystemExit(f"{name}: tablebot run failed ({done.returncode}): {done.stderr.strip()[-400:]}")
    probes = 0 if name == "txt" else PROBES  # the serial links are timed with exchanges before the run
    run = arrived[
        probes + 1 : -1
    ]  # the ticks' exchanges (not the first with outputs off, nor the last that stops them)
    gaps = sorted(1000 * (b - a) for a, b in itertools.pairwise(run))
    return {
        "per_s": (len(run) - 1) / (run[-1] - run[0]),
        "median": statistics.median(gaps),
        "p95": gaps[int(0.95 * (len(gaps) - 1))],
        "max": gaps[-1],
        "late": summary.get("late_ticks", 0),
        "ticks": summary.get("ticks", len(run)),
        "wall": wall,
    }


def link_alone(name: str, exchanges: int = 500) -> float:
    """Microseconds per exchange, one after another with no pacing."""
    from tablebot.formats.table_read import load_table
    from tablebot.machine import compile_table

    machine = compile_table(load_table(EXAMPLE / "table.csv"))
    with target(name) as (address, _emulator, _times):
        robot = _robot(name, machine, address)
        robot.connect()
        robot.open()
        outputs = (0,) * len(machine.output_names)
        started = time.perf_counter()
        for _ in range(exchanges):
            robot.write(outputs)
        took = time.perf_counter() - started
        robot.stop()
        robot.close()
    return 1e6 * took / exchanges


def _robot(name: str, machine: Any, address: str) -> Any:
    device = address.split("://", 1)[1]
    if name == "txt":
        from tablebot.hw.txt.controller import TxtRobot
        from tablebot.hw.txt.wiring import txt_wiring

        host, port = device.rsplit(":", 1)
        return TxtRobot(txt_wiring(machine), host, int(port), link_timeout_s=1.0)
    if name == "robotx":
        from tablebot.hw.robotx.controller import RobotxRobot
        from tablebot.hw.robotx.wiring import robotx_wiring

        return RobotxRobot(robotx_wiring(machine), device, link_timeout_s=1.0)
    from tablebot.hw.roboif.controller import RoboifRobot
    from tablebot.hw.roboif.wiring import roboif_wiring

    return RoboifRobot(roboif_wiring(machine), device, link_timeout_s=1.0)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--seconds", type=float, default=10.0, help="length of each run (default 10 s)")
    parser.add_argument("--only", default="txt,robotx,roboif,roboif@38400", help="targets, comma-separated")
    args = parser.parse_args()
    names = args.only.split(",")
    print(
        f"tablebot run examples/bumberbot --on TARGET --seconds {args.seconds:g} (whole command, fresh process; "
        "targets are emulators: no controller is here)"
    )
    print(
        f"load average at the start: {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores (a loaded machine "
        "stretches every gap: compare ratios)"
    )
    print(f"{'target':<14}{'exch/s':>8}{'gap median':>12}{'p95':>8}{'max':>8}{'late':>6}   link alone")
    base: dict[str, Any] | None = None
    for name in names:
        figures = whole_command(name, args.seconds)
        alone = link_alone(name)
        base = base or figures
        print(
            f"{name:<14}{figures['per_s']:>8.1f}{figures['median']:>10.2f}ms{figures['p95']:>6.2f}ms"
            f"{figures['max']:>6.1f}ms{figures['late']:>6}   {alone:,.0f} µs/exchange"
            f"   (exch/s {figures['per_s'] / base['per_s']:.2f}x, p95 gap {figures['p95'] / base['p95']:.2f}x "
            f"the {names[0]}'s)"
        )


if __name__ == "__main__":
    main()
