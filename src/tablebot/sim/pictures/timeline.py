"""The run's ``timeline.png``: state, motor speeds (and lamps), event bits, and the analog readings behind them
(the BumberBot's light, declared light and distance sensors) against time, collisions marked across.

Made in two steps (:class:`TimelinePicture`): the panels the scene fixes (how many, their labels, ticks and
limits, the title), which a painter makes while the robot runs, then the run drawn into them.
"""

from __future__ import annotations

import pickle
from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING, Any, NamedTuple, cast

import numpy as np
from matplotlib.axes import Axes
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.collections import LineCollection, PolyCollection
from matplotlib.figure import Figure
from matplotlib.ticker import FuncFormatter

from tablebot.colours import state_colours
from tablebot.escape import picture
from tablebot.i18n import N_, _, number
from tablebot.sensors import SensorKind
from tablebot.sim import columns as L
from tablebot.sim.pictures.draw import COLLISION, LIGHT_SEEN, WALL, literal_text
from tablebot.sim.pictures.forked import Forked
from tablebot.sim.pictures.picture import DPI, declared_kinds, deflated, drawn_png, png_of_parts, subtitle_of, title
from tablebot.sim.pictures.view import RunView, SceneView

if TYPE_CHECKING:
    from tablebot.sim.pictures.picture import Run
    from tablebot.sim.summary import Summary

LIGHT_BINS = 1500  # time bins of the light panel, each drawn as its low and high value
#: The sensor kinds' panel labels (tablebot.sensors, which speaks no language: it is data), marked here for the
#: catalog; the panel translates its label when it draws it.
_KIND_LABELS = (N_("distance (cm)\n-- on, ·· off"), N_("light\n(× threshold)"))


@literal_text()
def timeline_figure(result: Run, summary: Summary) -> Figure:
    result = RunView.of(result)
    return TimelinePicture(result.scene, result.ticks, result.seed).finish(result, summary).fig


class Panel(NamedTuple):
    """A reading panel: what the scene fixes on its axes (``setup``), then the run (``draw``)."""

    name: str
    setup: Callable[[Axes, SceneView], None]
    draw: Callable[[Axes, RunView, np.ndarray], None]


class TimelinePicture:
    """The timeline in two steps: the figure with what the scene, the run's length and its seed fix (made
    as the object is), then the run (:meth:`finish`). Artists go in in the order of a figure made at once,
    so the pixels are the same."""

    def __init__(self, scene: SceneView, ticks: int, seed: int) -> None:
        self.scene = scene
        self.readings = reading_panels(scene)
        self.fig = fig = Figure(figsize=(12, 7.2 + 1.8 * len(self.readings)), dpi=DPI)
        FigureCanvasAgg(fig)
        ratios = [2.2, 1.6, 1.6] + [1.3] * len(self.readings)
        self.axes = fig.subplots(len(ratios), 1, sharex=True, gridspec_kw={"height_ratios": ratios, "hspace": 0.12})
        self.axes[0].set_ylabel(_("state"))
        _output_setup(self.axes[1], scene)
        _event_setup(self.axes[2], scene)
        for ax, panel in zip(self.axes[3:], self.readings, strict=True):
            panel.setup(ax, scene)
        for ax in self.axes:
            ax.grid(axis="x", alpha=0.3)
        self.axes[-1].set_xlabel(_("time (s)"))
        self.axes[-1].set_xlim(0, max((ticks - 1) * scene.tick_s, scene.tick_s))
        fig.suptitle(title(scene, ticks, seed), fontsize=15, fontweight="bold", x=0.07, ha="left", y=0.975)
        fig.subplots_adjust(left=0.16, right=0.97, top=0.91, bottom=0.06)
        self.finished: set[int] = set()  # the panels the run is drawn into

    def finish(self, result: RunView, summary: Summary, panels: Sequence[int] | None = None) -> TimelinePicture:
        """Draw the run into the panels (or only into ``panels``, by number: the summary line goes with the
        first), marking its collisions and first light."""
        t, collisions = np.arange(result.ticks) * result.tick_s, np.array(summary.collision_ticks) * result.tick_s
        for k in range(len(self.axes)) if panels is None else panels:
            if k in self.finished:
                continue
            ax = self.axes[k]
            if k == 0:
                _state_panel(ax, result)
            elif k == 1:
                _output_panel(ax, result, t)
            elif k == 2:
                _event_panel(ax, result)
            else:
                self.readings[k - 3].draw(ax, result, t)
            if len(collisions):  # one artist per panel for all of them
                _vlines(ax, collisions)
            if summary.first_light_s is not None:
                ax.axvline(summary.first_light_s, color=LIGHT_SEEN, lw=1.5, ls="--", zorder=0)
            if k == 0:
                key = "   " + (
                    _("(red lines: collisions, dashed: first light)") if summary.lamps else _("(red lines: collisions)")
                )
                self.fig.text(0.07, 0.935, subtitle_of(summary) + key, fontsize=10, color="#444")
            self.finished.add(k)
        return self

    def png(self, result: RunView, summary: Summary) -> bytes:
        """The run drawn into the panels, as PNG, drawn and compressed in two bands at once: the lower panels
        by a fork of this process on the other core (:mod:`tablebot.sim.pictures.forked`), the upper ones here. The
        band's edge runs through the blank gap between two panels, so each band's pixels are those of the
        whole figure drawn at once; when either finds a pixel of the other's rows not blank (or the gap
        not blank), the whole figure is drawn here instead."""
        edge = self._edge()
        with Forked(lambda _: pickle.dumps(self._band(result, summary, edge, lower=True))) as lower:
            upper = self._band(result, summary, edge, lower=False)
            below = pickle.loads(lower.result())
        if upper is None or below is None:
            return drawn_png(self.finish(result, summary).fig)
        width, height = self.fig.canvas.get_width_height(physical=True)
        return png_of_parts([upper, below], width, height, self.fig.dpi)

    def _edge(self) -> int:
        """The pixel row (from the top) where the lower band begins: midway between the two middle panels."""
        split = len(self.axes) // 2
        above, below = self.axes[split - 1].get_position(), self.axes[split].get_position()
        height = self.fig.bbox.height
        return round(height - (above.y0 + below.y1) / 2 * height)

    def _band(self, result: RunView, summary: Summary, edge: int, lower: bool) -> tuple[bytes, int, int] | None:
        """Draw the run into one band's panels (the lower ones and the time axis, or the upper ones and the
        titles), draw them, and compress the band's rows as a part of the PNG
        (:func:`~tablebot.sim.pictures.picture.deflated`); None when the other band's rows, or the gap row above the
        edge, are not blank."""
        split = len(self.axes) // 2
        self.finish(result, summary, range(split, len(self.axes)) if lower else range(split))
        theirs = [*self.axes[:split], *self.fig.texts] if lower else self.axes[split:]
        for artist in theirs:
            artist.set_visible(False)
        try:
            self.fig.canvas.draw()
        finally:  # (without a fork, the other band is drawn next, in this process)
            for artist in theirs:
                artist.set_visible(True)
        pixels = np.asarray(cast(FigureCanvasAgg, self.fig.canvas).buffer_rgba())  # made on an Agg canvas
        others = pixels[:edge] if lower else pixels[edge - 1 :]  # the gap row above the edge must be blank
        if not (others == 255).all():
            return None
        if lower:
            return deflated(pixels[edge:], pixels[edge - 1], last=True)
        return deflated(pixels[:edge], None, last=False)


def envelope(t: np.ndarray, y: np.ndarray, bins: int) -> tuple[np.ndarray, np.ndarray]:
    """A long series drawn as the low and high value of each of ``bins`` time bins (a line zigzagging
    between them), which looks like every point plotted; short series are returned as they are."""
    if len(y) <= 2 * bins:
        return t, y
    edges = np.linspace(0, len(y), bins + 1).astype(np.int64)
    low, high = np.minimum.reduceat(y, edges[:-1]), np.maximum.reduceat(y, edges[:-1])
    return np.repeat(t[edges[:-1]], 2), np.column_stack((low, high)).ravel()


def _vlines(ax: Axes, x: np.ndarray) -> None:
    """Red lines across the panel at times ``x`` (in order): what ``ax.vlines(x, 0, 1, transform=<x axis>)``
    draws, without its data limits (every panel's limits are set), and drawn as a few paths instead of
    one per line (an hour has hundreds): lines far enough apart to share no pixel go in one path, broken
    by NaN, which draws the same pixels; each line comes after every earlier line it touches."""
    segments = np.full((len(x), 3, 2), np.nan)
    segments[:, :2, 0] = x[:, None]
    segments[:, 0, 1], segments[:, 1, 1] = 0.0, 1.0
    paths = [
        np.concatenate(segments[layer])[:-1]
        for layer in _apart(ax.transData.transform(np.column_stack((x, np.zeros(len(x)))))[:, 0])
    ]
    ax.add_collection(
        LineCollection(
            paths, colors=COLLISION, linewidths=0.8, alpha=0.5, zorder=0, transform=ax.get_xaxis_transform()
        ),
        autolim=False,
    )


APART_PX = 4.0  # a 0.8-point line at 150 dpi, snapped to the pixel grid and smoothed, covers under 3 pixels
PATH_LINES = 300  # Agg snaps a path of straight lines to pixels only up to 1024 vertices (3 per line here)


def _apart(pixels: np.ndarray) -> list[list[int]]:
    """The lines at ``pixels`` (increasing) in layers: a line goes one layer above the highest layer of the
    earlier lines less than APART_PX from it, so lines in one layer share no pixel and lines that do are
    drawn in their order; a layer holds at most PATH_LINES lines."""
    layers: list[list[int]] = []
    layer_of: list[int] = []
    near = 0  # the first earlier line that may be less than APART_PX away
    for k, at in enumerate(pixels.tolist()):
        while at - pixels[near] >= APART_PX:
            near += 1
        above = max(layer_of[near:k], default=-1) + 1
        while above < len(layers) and len(layers[above]) >= PATH_LINES:
            above += 1
        if above == len(layers):
            layers.append([])
        layers[above].append(k)
        layer_of.append(above)
    return layers


def _bars(ax: Axes, starts: np.ndarray, widths: np.ndarray, bottom: float, height: float, colour: str) -> None:
    """What ``ax.broken_barh(zip(starts, widths), (bottom, height), facecolors=colour)`` draws, its
    rectangles made by numpy instead of one by one (an hour has thousands; the panels' limits are set)."""
    if not len(starts):
        return
    x0 = np.asarray(starts, dtype=np.float64)
    x1 = x0 + np.asarray(widths, dtype=np.float64)
    y0, y1 = bottom, bottom + height
    corners = np.empty((len(x0), 4, 2))
    corners[:, :, 0] = np.column_stack((x0, x0, x1, x1))
    corners[:, :, 1] = (y0, y1, y1, y0)
    # matplotlib's stubs want a sequence of (n, 2) arrays; an (n, 4, 2) array is one
    ax.add_collection(PolyCollection(cast("Sequence[np.ndarray]", corners), facecolors=colour), autolim=False)


def _state_panel(ax: Axes, result: RunView) -> None:
    """The state after each tick, a row per state visited (its labels depend on the run)."""
    machine = result.scene.machine
    colours = state_colours(machine.states)
    visited = sorted(set(result.states.tolist()))
    rows = {s: k for k, s in enumerate(visited)}
    change = np.flatnonzero(np.diff(result.states)) + 1
    starts = np.concatenate(([0], change))
    ends = np.concatenate((change, [result.ticks]))
    tick, state = result.tick_s, result.states[starts]
    for s in dict.fromkeys(state.tolist()):  # one artist per state (in order of first visit), not per visit
        mine = state == s
        _bars(ax, starts[mine] * tick, (ends[mine] - starts[mine]) * tick, rows[s] - 0.4, 0.8, colours[s])
    ax.set_yticks(range(len(visited)))
    ax.set_yticklabels([picture(result.scene.table.state_title(machine.states[s])) for s in visited], fontsize=8)
    ax.set_ylim(-0.7, len(visited) - 0.3)
    ax.invert_yaxis()


def _output_setup(ax: Axes, scene: SceneView) -> None:
    ax.set_ylim(-8.9, 8.9)
    ax.set_yticks([-8, -4, 0, 4, 8])
    ax.set_ylabel(_("motor speed\n(+ forward)"))


def _output_panel(ax: Axes, result: RunView, t: np.ndarray) -> None:
    names = result.scene.machine.output_names
    n_motors = result.scene.machine.n_motors
    labels = result.scene.table.robot.labels
    for k, name in enumerate(names):
        style = "-" if k < n_motors else ":"
        label = picture(f"{name} ({labels[name]})" if labels.get(name) else name)
        wide = k == 0  # the first drawn wide and pale, so equal speeds show both lines
        values = result.outputs[:, k]
        steps = np.concatenate(([0], np.flatnonzero(np.diff(values)) + 1, [len(values) - 1]))  # where it changes
        ax.step(
            t[steps],
            values[steps],
            where="post",
            lw=3.2 if wide else 1.3,
            alpha=0.55 if wide else 1.0,
            ls=style,
            label=label,
        )
    ax.axhline(0, color="#999", lw=0.6)
    ax.legend(loc="upper right", fontsize=8, ncol=len(names), frameon=False)


def _event_setup(ax: Axes, scene: SceneView) -> None:
    table, labels = scene.table, scene.table.robot.labels
    ax.set_yticks(range(len(table.events)))
    timer, counter = _("timer = 0"), _("counter = 0")  # what an event the robot does not label means
    ax.set_yticklabels(
        [picture(f"{n} {labels.get(n, timer if n == 'T' else counter)}") for n in table.events], fontsize=8
    )
    ax.set_ylim(-0.7, len(table.events) - 0.3)
    ax.invert_yaxis()
    ax.set_ylabel(_("events"))


def _event_panel(ax: Axes, result: RunView) -> None:
    table, ev = result.scene.table, result.events
    tick, least = result.tick_s, result.ticks * result.tick_s / 500  # one-tick events stay visible
    for k, name in enumerate(table.events):
        on = np.concatenate(([False], (ev & table.bit(name)) != 0, [False])).astype(np.int8)
        edges = np.flatnonzero(np.diff(on))
        a, b = edges[::2], edges[1::2]
        _bars(ax, a * tick, np.maximum((b - a) * tick, least), k - 0.38, 0.76, "#2f3640")


def reading_panels(run_or_scene: Any) -> list[Panel]:
    """The reading panels this robot (of a run or a scene) needs, in their places: light (wired
    phototransistors, or declared light sensors), then each declared kind's panel (``SensorKind.panel``).
    A kind without a panel (a line sensor reads 1 or 0) shows on the event panel."""
    scene = getattr(run_or_scene, "scene", run_or_scene)
    wiring = scene.params.wiring
    builtin = bool(wiring.get("light_right") or wiring.get("light_left"))
    panels: list[tuple[int, Panel]] = [(0, Panel("light", _light_setup, _light_panel))] if builtin else []
    for kind in declared_kinds(scene):
        if kind.panel is not None and not (builtin and kind.panel.position == 0):
            panels.append((kind.panel.position, _panel_of(kind)))
    return [panel for _, panel in sorted(panels, key=lambda p: p[0])]


def _panel_of(kind: SensorKind) -> Panel:
    """The panel of one declared kind: its sensors, each with its thresholds (``SensorKind.panel``)."""
    panel = kind.panel
    assert panel is not None

    def setup(ax: Axes, scene: SceneView) -> None:
        if panel.log:
            _log_scale(ax)
        else:  # the range where the table's thresholds act, not the far wall
            ax.set_ylim(
                0,
                max(level * panel.scale for _, sensor in _sensors(scene, kind.name) for level in sensor.switch_points())
                * 3,
            )
        ax.set_ylabel(_(panel.label))  # marked in _KIND_LABELS

    def draw(ax: Axes, result: RunView, t: np.ndarray) -> None:
        for k, sensor in _sensors(result.scene, kind.name):
            label = f"{sensor.name} {result.scene.table.robot.labels.get(sensor.name, '')}".strip()
            reading = result.column(L.READING + k)[:-1] * panel.scale
            line = ax.plot(*envelope(t, reading, LIGHT_BINS), lw=1.1, label=picture(label))[0]
            on, off = sensor.switch_points()
            ax.axhline(on * panel.scale, color=line.get_color(), lw=1, ls="--")
            if off != on:
                ax.axhline(off * panel.scale, color=line.get_color(), lw=0.8, ls=":")
        ax.legend(loc="upper right", fontsize=8, ncol=3, frameon=False)

    return Panel(kind.name, setup, draw)


def _sensors(scene: SceneView, kind: str) -> list[Any]:
    """(slot, sensor) of each declared sensor of ``kind``."""
    return [(k, s) for k, s in enumerate(scene.table.robot.sensors[: L.MAX_SENSORS]) if s.kind == kind]


def _light_setup(ax: Axes, scene: SceneView) -> None:
    _log_scale(ax)
    ax.set_ylabel(_("light\n(× threshold)"))


def _light_panel(ax: Axes, result: RunView, t: np.ndarray) -> None:
    """The BumberBot's wired phototransistors against their threshold."""
    wiring = result.scene.params.wiring
    right, left = result.column(L.LIGHT_R)[:-1], result.column(L.LIGHT_L)[:-1]
    right_name = picture(_("{sensor} right").format(sensor=wiring["light_right"]))
    left_name = picture(_("{sensor} left").format(sensor=wiring["light_left"]))
    ax.plot(*envelope(t, right, LIGHT_BINS), lw=1.1, color="#e67e22", label=right_name)
    ax.plot(*envelope(t, left, LIGHT_BINS), lw=1.1, color="#8e44ad", label=left_name)
    ax.axhline(1.0, color=WALL, lw=1, ls="--", label=_("threshold"))
    ax.set_ylim(0, max(10.0, float(max(right.max(), left.max())) * 1.5))
    ax.legend(loc="upper right", fontsize=8, ncol=3, frameon=False)


def _log_scale(ax: Axes) -> None:
    """A reading (light) on a symmetric log scale (0, then 0.1 to 100s), its ticks written as plain numbers: the
    pictures draw text with maths parsing off (for user text), so matplotlib's 10^n labels would print
    as raw TeX."""
    ax.set_yscale("symlog", linthresh=0.1)
    ax.yaxis.set_major_formatter(FuncFormatter(lambda value, _: number(value)))  # 0,1 in German
