"""A sweep's pictures: ``outcomes.png`` (success rate and time-to-light per grid value), ``starts.png``
(start positions coloured by outcome) and the best and worst runs' trajectories (``best.png``, ``worst.png``).

Drawn on the Agg canvas directly (no display needed), from the result rows; the best and worst runs are
run again as traced robots of a small fleet, which gives exactly the runs the sweep made.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from tablebot.escape import picture
from tablebot.fleet.groups import groups
from tablebot.fleet.plan import Plan
from tablebot.i18n import _
from tablebot.sim.pictures.draw import REACHED, draw_world, literal_text
from tablebot.sim.pictures.plots import save, trajectory
from tablebot.sim.summary import summarise

NEVER = "#b2bec3"
Row = dict[str, Any]


def number(value: Any) -> float | None:
    return None if value in (None, "") else float(value)


@literal_text()
def outcomes(plan: Plan, rows: Sequence[Row], path: Path) -> Path:
    """Per grid axis: the share of runs that reached the lamp, and the time to first light (box plot)."""
    return save(outcomes_figure(plan, rows), path)


@literal_text()
def outcomes_figure(plan: Plan, rows: Sequence[Row]) -> Figure:
    panels = groups(plan, rows)
    fig = Figure(figsize=(11, 3.6 * len(panels) + 0.8), dpi=120)
    FigureCanvasAgg(fig)
    seconds = plan.spec.ticks * plan.scenes[0].tick_s
    for k, (key, values) in enumerate(panels):
        left, right = fig.add_subplot(len(panels), 2, 2 * k + 1), fig.add_subplot(len(panels), 2, 2 * k + 2)
        labels = [picture(label) for label, _chosen in values]
        rates = [float(np.mean([int(r["reached"]) for r in chosen])) if chosen else 0.0 for _label, chosen in values]
        bars = left.bar(labels, [100 * r for r in rates], color=REACHED)
        left.bar_label(
            bars, [f"{100 * r:.0f}%\n(n={len(c)})" for r, (_label, c) in zip(rates, values, strict=True)], fontsize=8
        )
        left.set_ylim(0, 118)
        left.set_ylabel(_("reached the lamp (%)"))
        left.set_xlabel(key)
        times = [[t for r in chosen if (t := number(r["first_light_s"])) is not None] for _label, chosen in values]
        never = [sum(number(r["first_light_s"]) is None for r in chosen) for _label, chosen in values]
        right.boxplot([t or [math.nan] for t in times], tick_labels=labels, showfliers=True)
        for i, ts in enumerate(times):
            jitter = np.random.default_rng(i).uniform(-0.15, 0.15, len(ts))  # fixed: the picture is reproducible
            right.scatter(np.full(len(ts), i + 1.0) + jitter, ts, s=6, alpha=0.35, color="#f0a500", zorder=3)
            right.text(
                i + 1, seconds * 1.02, _("never: {n}").format(n=never[i]), ha="center", fontsize=8, color="#636e72"
            )
        right.set_ylim(0, seconds * 1.1)
        right.set_ylabel(_("time to first light (s)"))
        right.set_xlabel(key)
    fig.suptitle(
        _("{robot}: {runs:,} runs of {seconds:g} s").format(
            robot=picture(plan.table.robot.name), runs=len(rows), seconds=seconds
        ),
        fontsize=13,
        fontweight="bold",
    )
    fig.tight_layout(rect=(0, 0, 1, 0.96))
    return fig


@literal_text()
def starts(plan: Plan, rows: Sequence[Row], path: Path) -> Path:
    """Start positions in the (first) world: each start coloured by the time it took to reach the lamp,
    grey when it never did; with many runs, a hexagon heat map of the success rate instead."""
    return save(starts_figure(plan, rows), path)


@literal_text()
def starts_figure(plan: Plan, rows: Sequence[Row]) -> Figure:
    world_rows = [r for r in rows if r["world"] == plan.spec.worlds[0]]
    world = plan.worlds[0]
    fig = Figure(figsize=(9, 7), dpi=120)
    FigureCanvasAgg(fig)
    ax = fig.add_axes((0.08, 0.08, 0.78, 0.84))
    draw_world(ax, world, lamp_glow=False)
    xs = np.array([float(r["start_x"]) for r in world_rows])
    ys = np.array([float(r["start_y"]) for r in world_rows])
    reached = np.array([int(r["reached"]) for r in world_rows])
    if len(world_rows) > 600:
        cells = ax.hexbin(
            xs,
            ys,
            C=reached * 100.0,
            reduce_C_function=np.mean,
            gridsize=24,
            cmap="RdYlGn",
            vmin=0,
            vmax=100,
            alpha=0.85,
            zorder=3,
            mincnt=1,
        )
        fig.colorbar(cells, cax=fig.add_axes((0.88, 0.15, 0.025, 0.7)), label=_("reached the lamp (% of starts here)"))
    else:
        times = np.array([number(r["reached_s"]) or math.nan for r in world_rows])
        headings = np.radians([float(r["start_heading"]) for r in world_rows])
        ok = ~np.isnan(times)
        ax.quiver(
            xs, ys, np.cos(headings), np.sin(headings), color="#2d3436", alpha=0.5, scale=40, width=0.003, zorder=3
        )
        if (~ok).any():  # the legend says only what the picture shows
            ax.scatter(xs[~ok], ys[~ok], s=28, color=NEVER, marker="x", zorder=4, label=_("never reached the lamp"))
        dots = ax.scatter(
            xs[ok], ys[ok], c=times[ok], s=30, cmap="viridis_r", edgecolors="white", linewidths=0.5, zorder=5
        )
        if ok.any():
            fig.colorbar(dots, cax=fig.add_axes((0.88, 0.15, 0.025, 0.7)), label=_("time to reach the lamp (s)"))
        if (~ok).any():
            ax.legend(loc="lower right", fontsize=8)
    ax.set_title(
        _("Start positions in {world}: {reached} of {runs} reached the lamp").format(
            world=picture(world.name), reached=int(reached.sum()), runs=len(world_rows)
        ),
        fontsize=12,
        fontweight="bold",
    )
    return fig


def best_and_worst(rows: Sequence[Row]) -> tuple[Row | None, Row | None]:
    """The best run reached the lamp soonest; the worst never reached it (most collisions, then latest light),
    else reached it last."""
    if not rows:
        return None, None

    def cost(r: Row) -> tuple[float, ...]:
        reached = number(r["reached_s"])
        light = number(r["first_light_s"])
        return (
            math.inf if reached is None else reached,
            int(r["collisions"]),
            math.inf if light is None else light,
            int(r["run"]),
        )

    ordered = sorted(rows, key=cost)
    return ordered[0], ordered[-1] if len(ordered) > 1 else None


@literal_text()
def trajectories(plan: Plan, rows: Sequence[Row], folder: Path) -> list[Path]:
    """``best.png`` and ``worst.png``: the two runs again, traced, drawn as ``tablebot sim`` draws a run."""
    written = []
    for name, row in zip(("best", "worst"), best_and_worst(rows), strict=True):
        if row is None:
            continue
        result = plan.traced(int(row["run"])).result(0)
        written.append(trajectory(result, summarise(result), folder / f"{name}.png"))
    return written


def write_all(plan: Plan, rows: Sequence[Row], folder: Path) -> list[Path]:
    if not rows:
        return []
    return [
        outcomes(plan, rows, folder / "outcomes.png"),
        starts(plan, rows, folder / "starts.png"),
        *trajectories(plan, rows, folder),
    ]
