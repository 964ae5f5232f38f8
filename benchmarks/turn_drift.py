"""The document's lesson, measured: a timed 90° turn shrinks as the battery drains; a pulse-counted one does not.

Run: ``.venv/bin/python benchmarks/turn_drift.py [--out out/turn_drift] [--seeds 5]``. For battery charges
100 % … 0 % it simulates examples/bumberbot-counters/turn90/timed.csv and counted.csv (seeded motor and
sensor noise, several seeds), and both BumberBots (timed, with counters) in their arena for 120 s.
Writes turn_drift.png, turn_drift.csv and turn_drift.md; exits 1 if the timed turn does not drift to
80° and below or the counted turn leaves 90° ± 3°.
"""

from __future__ import annotations

import argparse
import csv
import statistics
import sys
from dataclasses import dataclass
from pathlib import Path

from matplotlib.axes import Axes
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from tablebot.cli.common import load
from tablebot.sim.model.scene import scene_for
from tablebot.sim.runner import simulate
from tablebot.sim.summary import summarise
from tablebot.testing.turn_drift import Turn, turns

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "examples"
TARGET, TOLERANCE, DRIFTED = 90.0, 3.0, 80.0
TIMED, COUNTED = "#d35400", "#2471a3"


@dataclass(frozen=True)
class Level:
    charge: float
    volts: float
    timed: list[float]
    counted: list[float]
    timed_lamp: list[float | None]  # seconds to reach the lamp per seed; None = not within the run
    counted_lamp: list[float | None]


def lamp_times(folder: Path, charge: float, seeds: list[int]) -> list[float | None]:
    table, machine = load(folder)
    scene = scene_for(table, machine, overrides={"battery": {"charge": charge}})
    return [summarise(simulate(scene, 120.0, seed)).reached_s for seed in seeds]


def measure(charges: list[float], seeds: list[int]) -> list[Level]:
    folder = EXAMPLES / "bumberbot-counters" / "turn90"
    timed = turns(folder / "timed.csv", charges, seeds)
    counted = turns(folder / "counted.csv", charges, seeds)
    levels = []
    for charge in charges:

        def pick(found: list[Turn], c: float = charge) -> list[Turn]:
            return [t for t in found if t.charge == c]

        levels.append(
            Level(
                charge,
                pick(timed)[0].volts,
                [t.degrees for t in pick(timed)],
                [t.degrees for t in pick(counted)],
                lamp_times(EXAMPLES / "bumberbot", charge, seeds),
                lamp_times(EXAMPLES / "bumberbot-counters", charge, seeds),
            )
        )
    return levels


def found(times: list[float | None]) -> str:
    hits = [t for t in times if t is not None]
    return f"{len(hits)}/{len(times)}" + (f" ({statistics.mean(hits):.0f} s)" if hits else "")


def write_table(levels: list[Level], out: Path) -> str:
    with (out / "turn_drift.csv").open("w", newline="", encoding="utf-8") as f:
        w = csv.writer(f, lineterminator="\n")
        w.writerow(
            [
                "charge",
                "volts",
                "timed_mean",
                "timed_min",
                "timed_max",
                "counted_mean",
                "counted_min",
                "counted_max",
                "timed_bot_found",
                "counters_bot_found",
            ]
        )
        for lv in levels:
            w.writerow(
                [
                    f"{lv.charge:.2f}",
                    f"{lv.volts:.3f}",
                    *(f"{v:.2f}" for d in (lv.timed, lv.counted) for v in (statistics.mean(d), min(d), max(d))),
                    sum(t is not None for t in lv.timed_lamp),
                    sum(t is not None for t in lv.counted_lamp),
                ]
            )
    lines = [
        "| battery | volts | timed turn (°) | counted turn (°) | BumberBot finds the lamp | with counters |",
        "|---:|---:|---:|---:|---:|---:|",
    ]
    for lv in levels:
        lines.append(
            f"| {lv.charge:.0%} | {lv.volts:.2f} | {statistics.mean(lv.timed):.1f} "
            f"({min(lv.timed):.1f}…{max(lv.timed):.1f}) | {statistics.mean(lv.counted):.1f} "
            f"({min(lv.counted):.1f}…{max(lv.counted):.1f}) | {found(lv.timed_lamp)} | "
            f"{found(lv.counted_lamp)} |"
        )
    text = "\n".join(lines) + "\n"
    (out / "turn_drift.md").write_text(text, encoding="utf-8")
    return text


def plot(levels: list[Level], seeds: int, out: Path) -> Path:
    """turn_drift.png: turn angles against battery charge, and the time each BumberBot takes to find the lamp."""
    fig = Figure(figsize=(12, 5.2), dpi=150)
    FigureCanvasAgg(fig)
    ax, lamp = fig.subplots(1, 2, gridspec_kw={"width_ratios": [1.5, 1], "wspace": 0.25})
    x = [100 * lv.charge for lv in levels]
    _turn_panel(ax, levels, x)
    _lamp_panel(lamp, levels, x)
    fig.suptitle(
        "Timer or pulse counter: the BumberBot's turns as the battery drains",
        fontsize=14,
        fontweight="bold",
        x=0.06,
        ha="left",
        y=0.99,
    )
    fig.text(
        0.06,
        0.9,
        f"simulated, {seeds} seeds per point (band: min…max); examples/bumberbot-counters, benchmarks/turn_drift.py",
        fontsize=9,
        color="#444",
    )
    fig.subplots_adjust(left=0.06, right=0.98, top=0.8, bottom=0.11)
    path = out / "turn_drift.png"
    fig.savefig(path, facecolor="white")
    return path


def _turn_panel(ax: Axes, levels: list[Level], x: list[float]) -> None:
    ax.axhspan(TARGET - TOLERANCE, TARGET + TOLERANCE, color=COUNTED, alpha=0.12, label="90° ± 3°")
    ax.axhline(DRIFTED, color="#555", ls=":", lw=1)
    ax.text(x[0], DRIFTED + 0.6, ' 80°: the document\'s "80° and less"', fontsize=8, color="#555", ha="left")
    for key, colour, label in (
        ("timed", TIMED, "timed: 298 ticks of the timer"),
        ("counted", COUNTED, "counted: 35 encoder pulses per wheel"),
    ):
        data = [getattr(lv, key) for lv in levels]
        ax.fill_between(x, [min(d) for d in data], [max(d) for d in data], color=colour, alpha=0.25, lw=0)
        ax.plot(x, [statistics.mean(d) for d in data], "o-", color=colour, lw=2, label=label)
    ax.set_xlim(102, -2)
    ax.set_ylim(min(58.0, min(min(lv.timed) for lv in levels) - 3), 96)
    ax.set_xlabel("battery charge (%)  —  draining →")
    ax.set_ylabel("turn angle (degrees)")
    ax.set_title("A 90° left turn at speed 2 (top: battery volts under load)", fontsize=11, loc="left", pad=22)
    ax.legend(loc="lower left", fontsize=9, frameon=False)
    ax.grid(alpha=0.3)
    top = ax.secondary_xaxis("top", functions=(lambda c: c, lambda c: c))
    top.set_xticks(x[::2], [f"{lv.volts:.1f} V" for lv in levels[::2]], fontsize=8)


def _lamp_panel(lamp: Axes, levels: list[Level], x: list[float]) -> None:
    for key, colour, label, dx in (
        ("timed_lamp", TIMED, "BumberBot (timed turns)", -1.2),
        ("counted_lamp", COUNTED, "with counters", 1.2),
    ):
        for lv, xi in zip(levels, x, strict=True):
            times = getattr(lv, key)
            hits = [t for t in times if t is not None]
            misses = len(times) - len(hits)
            lamp.scatter([xi + dx] * len(hits), hits, color=colour, s=14, alpha=0.8)
            if misses:
                lamp.scatter([xi + dx], [125], marker="x", color=colour, s=20 + 12 * misses)
        lamp.scatter([], [], color=colour, s=14, label=label)
    lamp.scatter([], [], marker="x", color="#555", s=32, label="not found in 120 s (bigger: more seeds)")
    lamp.axhline(120, color="#555", lw=0.8)
    lamp.set_xlim(104, -4)
    lamp.set_ylim(0, 135)
    lamp.set_xlabel("battery charge (%)")
    lamp.set_ylabel("time to reach the lamp (s)")
    lamp.set_title("Finding the lamp in the arena (120 s runs)", fontsize=11, loc="left", pad=22)
    lamp.legend(loc="upper left", bbox_to_anchor=(0.0, 0.9), fontsize=9, frameon=False)
    lamp.grid(alpha=0.3)


def verdict(levels: list[Level]) -> list[str]:
    """Failures of the two claims (empty when both hold)."""
    problems = []
    lowest = min(min(lv.timed) for lv in levels)
    if lowest > DRIFTED:
        problems.append(f"the timed turn never drifted to {DRIFTED:g}° (lowest {lowest:.1f}°)")
    worst = max(abs(a - TARGET) for lv in levels for a in lv.counted)
    if worst > TOLERANCE:
        problems.append(f"the counted turn strayed {worst:.1f}° from {TARGET:g}°")
    return problems


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=ROOT / "out" / "turn_drift")
    parser.add_argument("--seeds", type=int, default=5)
    args = parser.parse_args(argv)
    args.out.mkdir(parents=True, exist_ok=True)
    charges = [round(1.0 - k / 10, 1) for k in range(11)]
    levels = measure(charges, list(range(1, args.seeds + 1)))
    print(write_table(levels, args.out))
    print(f"wrote {plot(levels, args.seeds, args.out)}, turn_drift.csv, turn_drift.md")
    full, empty = levels[0], levels[-1]
    print(f"timed:   {statistics.mean(full.timed):.1f}° full -> {statistics.mean(empty.timed):.1f}° empty")
    worst = max(abs(a - TARGET) for lv in levels for a in lv.counted)
    print(f"counted: every run within {worst:.2f}° of {TARGET:g}°")
    problems = verdict(levels)
    for problem in problems:
        print(f"FAIL: {problem}", file=sys.stderr)
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
