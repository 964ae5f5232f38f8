"""The run's pictures: ``trajectory.png`` (the path in the arena, coloured by state) and ``timeline.png``.

Figures are drawn with the Agg canvas directly, never through pyplot, so they need no display.
"""

from __future__ import annotations

import io
from collections.abc import Callable
from pathlib import Path
from typing import IO, TYPE_CHECKING, Any

import matplotlib.image
import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.collections import LineCollection, PolyCollection
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.patches import Patch

from tablebot.colours import state_colours
from tablebot.escape import picture
from tablebot.files import atomic_write
from tablebot.sensors import SENSOR_KINDS, SensorKind
from tablebot.sim import columns as L
from tablebot.sim.draw import (
    BEAM,
    COLLISION,
    LAMP_ON,
    LIGHT_SEEN,
    REACHED,
    TAPE,
    TAPE_FILL,
    WALL,
    RobotArtist,
    contact_points,
    draw_world,
    literal_text,
    sensor_readings,
)
from tablebot.sim.forked import Forked
from tablebot.sim.painter import RunView, SceneView
from tablebot.sim.summary import Summary

if TYPE_CHECKING:  # only types: the pictures are drawn without the simulator (a painter never imports numba)
    from tablebot.sim.runner import SimRun
    from tablebot.sim.scene import Scene

    Run = SimRun | RunView

DPI = 150
PATH_Z = 4  # the path's z-order: everything the arena draws is below it
PATH_STEP_M = 0.002  # the path is drawn through points 2 mm apart: finer than the picture's pixels
SPIN_M, SPIN_DEG = 0.01, 15.0  # a state that moves the robot less and turns it more is a spin: drawn as a dot
LIGHT_BINS = 1500  # time bins of the light panel, each drawn as its low and high value


def title_of(result: Run) -> str:
    return title(result.scene, result.ticks, result.seed)


def title(scene: SceneView | Scene, ticks: int, seed: int) -> str:
    """The pictures' title: the robot, the world, the run's length and seed (all known before the run)."""
    robot, world = picture(scene.table.robot.name), picture(scene.world.name)
    return f"{robot} in {world} — {ticks * scene.tick_s:g} s, seed {seed}"


def subtitle_of(summary: Summary) -> str:
    def when(v: float | None) -> str:
        return "never" if v is None else f"{v:.1f} s"
    parts = []
    if summary.lamps:
        parts += [f"light first seen: {when(summary.first_light_s)}", f"lamp reached: {when(summary.reached_s)}"]
    if summary.laps is not None:
        parts.append(f"{summary.laps:.2f} laps of the line")
    parts += [f"{summary.collisions} collision{'s' * (summary.collisions != 1)}", f"{summary.distance_m:.2f} m driven"]
    return "   ·   ".join(parts)


@literal_text()
def trajectory(result: Run, summary: Summary, path: Path) -> Path:
    """The arena with the path coloured by state, collisions, first light and lamp reached marked."""
    return save(trajectory_figure(result, summary), path)


@literal_text()
def trajectory_figure(result: Run, summary: Summary) -> Figure:
    result = RunView.of(result)
    return TrajectoryPicture(result.scene, result.ticks, result.seed).finish(result, summary).fig


class TrajectoryPicture:
    """The trajectory in steps: the arena and the title, known before the run (a painter draws them at once:
    :meth:`render_arena`), the path as the run goes (:meth:`grow`), then the rest of the run on top
    (:meth:`finish`, :meth:`png`). The pixels are those of the whole figure drawn at once: each step draws
    above the one before (z-order), and the title and tick labels lie outside the axes, where nothing later
    draws (all of the run is clipped to the axes, the summary line and legends are outside them)."""

    def __init__(self, scene: SceneView | Scene, ticks: int, seed: int):
        world = scene.world
        xs, ys = zip(*world.walls, strict=True)
        aspect = (max(ys) - min(ys)) / max(1e-9, max(xs) - min(xs))
        self.fig = Figure(figsize=(11, max(4.5, 7.2 * aspect + 1.2)), dpi=DPI)
        FigureCanvasAgg(self.fig)
        self.ax = self.fig.add_axes((0.06, 0.08, 0.62, 0.8))
        draw_world(self.ax, world)
        self.title = self.fig.suptitle(title(scene, ticks, seed), fontsize=15, fontweight="bold", x=0.06, ha="left",
                                       y=0.975)
        self.colours = state_colours(scene.machine.states)
        self.path = PathPieces()
        self.drawn: list[Any] | None = None  # what is in the canvas already, once render_arena ran

    def render_arena(self) -> None:
        """Draw everything below the path (floor, tape, obstacles, walls, axes, ticks, title) into the
        canvas now; :meth:`grow` and :meth:`png` draw the rest on top."""
        below = [a for a in self.ax.get_children() if a.get_zorder() < PATH_Z]
        later = [a for a in self.ax.get_children() if a not in below]  # the lamps' stars: above the robot
        for artist in later:
            artist.set_animated(True)  # left out of this draw
        self.fig.canvas.draw()
        for artist in later:
            artist.set_animated(False)
        self.drawn = below

    def grow(self, x: np.ndarray, y: np.ndarray, states: np.ndarray, done: int) -> None:
        """Draw the pieces of the path complete once robot rows 0..done and ``states[:done]`` are known."""
        assert self.drawn is not None, "the path is drawn as it grows only over the arena (render_arena)"
        pieces = self._add_path(*self.path.grow(x, y, states, done))
        if pieces is not None:
            pieces.draw(self.fig.canvas.get_renderer())
            self.drawn.append(pieces)

    def _add_path(self, pieces: list[np.ndarray], piece_states: list[int]) -> LineCollection | None:
        if not pieces:
            return None
        lines = LineCollection(pieces, colors=[self.colours[s] for s in piece_states], linewidths=2.2,
                               capstyle="round", joinstyle="round", zorder=PATH_Z)
        return self.ax.add_collection(lines, autolim=False)  # the arena set the limits

    def finish(self, result: RunView, summary: Summary) -> TrajectoryPicture:
        """Add the rest of the run: the path's last pieces, spins, collisions, first light, lamp reached,
        the robot at its start and end, the summary line and the legends."""
        ax, fig, colours = self.ax, self.fig, self.colours
        x, y = result.column(L.X), result.column(L.Y)
        self._add_path(*self.path.grow(x, y, result.states, result.ticks, last=True))
        # spins in place draw no line: a dot where such a state begins shows them
        spins = spin_starts(x, y, result.column(L.TH), result.states)
        ax.scatter(x[spins], y[spins], s=18, c=[colours[s] for s in result.states[spins].tolist()],
                   edgecolors="white", linewidths=0.6, zorder=5)
        _markers(ax, result, summary)
        _robot_poses(ax, result)
        fig.text(0.06, 0.915, subtitle_of(summary), fontsize=10.5, color="#444")
        _legend(fig, result, summary, len(spins) > 0)
        return self

    def png(self) -> bytes:
        """The picture as PNG: the bytes :func:`png_bytes` gives for the whole figure."""
        if self.drawn is None:
            return png_bytes(self.fig)
        renderer = self.fig.canvas.get_renderer()
        # what Axes.draw and Figure.draw would draw after what is drawn, in their order (by z-order, stably)
        rest = sorted((a for a in self.ax.get_children() if a not in self.drawn), key=lambda a: a.get_zorder())
        assert not rest or min(a.get_zorder() for a in rest) >= max(a.get_zorder() for a in self.drawn)
        for artist in rest:
            artist.draw(renderer)
        texts = [t for t in self.fig.texts if t is not self.title]  # the title was drawn with the arena
        for artist in sorted([*texts, *self.fig.legends], key=lambda a: a.get_zorder()):
            artist.draw(renderer)
        return _encoded(self.fig)


class Painting:
    """Both pictures as the painter (:mod:`tablebot.sim.painter`) draws them: what the scene fixes at once,
    the path as the run goes (:meth:`grow`), the rest when it is over (:meth:`finish`: the timeline by a
    fork of this process on the other core, :mod:`tablebot.sim.forked`)."""

    def __init__(self, scene: SceneView, ticks: int, seed: int):
        with literal_text():
            self.trajectory = TrajectoryPicture(scene, ticks, seed)
            self.trajectory.render_arena()

    def grow(self, x: np.ndarray, y: np.ndarray, states: np.ndarray, done: int) -> None:
        with literal_text():
            self.trajectory.grow(x, y, states, done)

    @literal_text()
    def finish(self, result: RunView, summary: Summary) -> tuple[bytes, bytes]:
        """The two pictures' PNG bytes, trajectory first."""
        with Forked(lambda _: png_bytes(timeline_figure(result, summary))) as timeline_png:
            return self.trajectory.finish(result, summary).png(), timeline_png.result()


def spin_starts(x: np.ndarray, y: np.ndarray, heading: np.ndarray, states: np.ndarray) -> np.ndarray:
    """Rows where a state begins that turns the robot on the spot: its stretch of the run moves the axle
    less than SPIN_M but turns it more than SPIN_DEG (a line follower's quick state changes are no spins)."""
    change = np.flatnonzero(np.diff(states)) + 1
    starts, ends = np.concatenate(([0], change)), np.concatenate((change, [len(states)]))
    moved = np.hypot(x[ends] - x[starts], y[ends] - y[starts])
    turned = np.degrees(np.abs(heading[ends].astype(np.float64) - heading[starts]))
    return starts[(moved < SPIN_M) & (turned > SPIN_DEG)]


def save(fig: Figure, path: Path) -> Path:
    """Write the figure as PNG under a temporary name, renamed into place when complete."""
    with atomic_write(path, "wb") as stream:
        _write_png(fig, stream)
    return path


def png_bytes(fig: Figure) -> bytes:
    """The figure as PNG, the bytes :func:`save` writes."""
    stream = io.BytesIO()
    _write_png(fig, stream)
    return stream.getvalue()


def _encoded(fig: Figure) -> bytes:
    """The figure's canvas, as drawn, encoded as PNG as :func:`png_bytes` encodes it (matplotlib's print_png)."""
    stream = io.BytesIO()
    matplotlib.image.imsave(stream, fig.canvas.buffer_rgba(), format="png", origin="upper", dpi=fig.dpi,
                            pil_kwargs={"compress_level": PNG_LEVEL})
    return stream.getvalue()


#: zlib's fastest level: the same pixels as Pillow's default (6) in two thirds of the time, files ~25 % larger
PNG_LEVEL = 1


def _write_png(fig: Figure, stream: IO[bytes]) -> None:
    fig.savefig(stream, format="png", facecolor="white", pil_kwargs={"compress_level": PNG_LEVEL})


class PathPieces:
    """The run's path cut where the state changes (segment t, from row t to t + 1, has the state after tick
    t), each piece thinned to points about ``step`` apart along it (ends kept): what a picture can show.
    Made as the run goes: each :meth:`grow` gives the pieces completed since the last, the same pieces
    (to the last bit) as the whole run's rows would give at once."""

    def __init__(self, step: float = PATH_STEP_M):
        self.step = step
        self.start = 0  # the first row of the piece not given yet
        self.known = 0  # the rows whose thinning is known: 0..known
        self.travelled = 0.0  # the distance along the path to row ``known``
        self.kept: list[np.ndarray] = [np.zeros(0, dtype=np.int64)]  # the rows a piece keeps inside it, in order

    def grow(self, x: np.ndarray, y: np.ndarray, states: np.ndarray, done: int,
             last: bool = False) -> tuple[list[np.ndarray], list[int]]:
        """The pieces complete once robot rows 0..done (``x``, ``y``) and ``states[:done]`` are known (with
        ``last``, the run is over: ``done`` is its length, and the last piece ends there)."""
        if done > self.known:
            xy = np.column_stack((x[self.known:done + 1], y[self.known:done + 1])).astype(np.float64)
            travelled = np.cumsum(np.concatenate(([self.travelled], np.hypot(*np.diff(xy, axis=0).T))))
            bucket = np.floor(travelled / self.step)  # a row is kept where the path enters the next step
            self.kept.append(np.flatnonzero(bucket[1:] != bucket[:-1]) + self.known + 1)
            self.known, self.travelled = done, float(travelled[-1])
        change = np.flatnonzero(np.diff(states[self.start:done])) + self.start + 1
        ends = np.concatenate((change, [done])) if last else change
        if not len(ends):
            return [], []
        starts = np.concatenate(([self.start], ends[:-1]))
        self.start = int(ends[-1])
        kept = np.concatenate(self.kept)
        self.kept = [kept]
        inner_from, inner_to = np.searchsorted(kept, starts, "right"), np.searchsorted(kept, ends, "left")
        rows = [np.concatenate(([a], kept[i:j], [b]))
                for a, b, i, j in zip(starts.tolist(), ends.tolist(), inner_from.tolist(), inner_to.tolist(),
                                      strict=True)]
        every = np.concatenate(rows)
        xy = np.column_stack((x[every], y[every])).astype(np.float64)
        pieces = np.split(xy, np.cumsum([len(r) for r in rows[:-1]]))
        return pieces, states[starts].tolist()


def envelope(t: np.ndarray, y: np.ndarray, bins: int) -> tuple[np.ndarray, np.ndarray]:
    """A long series drawn as the low and high value of each of ``bins`` time bins (a line zigzagging
    between them), which looks like every point plotted; short series are returned as they are."""
    if len(y) <= 2 * bins:
        return t, y
    edges = np.linspace(0, len(y), bins + 1).astype(np.int64)
    low, high = np.minimum.reduceat(y, edges[:-1]), np.maximum.reduceat(y, edges[:-1])
    return np.repeat(t[edges[:-1]], 2), np.column_stack((low, high)).ravel()


def _markers(ax, result: RunView, summary: Summary) -> None:
    scene, rows = result.scene, list(summary.collision_ticks)
    x, y, heading = result.column(L.X), result.column(L.Y), result.column(L.TH)
    if rows:  # where the body touched the wall or obstacle; one artist for all of them: an hour has hundreds
        poses = np.column_stack((x[rows], y[rows], heading[rows])).astype(np.float64)
        touched = contact_points(scene.geometry, scene.params, poses)
        ax.plot(touched[:, 0], touched[:, 1], ls="", marker="X", markersize=11, color=COLLISION,
                markeredgecolor="white", markeredgewidth=1.2, zorder=9)
    tick = result.tick_s
    if summary.first_light_s is not None:
        row = round(summary.first_light_s / tick)
        ax.plot(x[row], y[row], marker="o", markersize=12, color=LIGHT_SEEN, markeredgecolor=WALL, zorder=9)
    if summary.reached_s is not None:
        row = round(summary.reached_s / tick)
        ax.plot(x[row], y[row], marker="D", markersize=11, color=REACHED, markeredgecolor=WALL, zorder=9)


def _robot_poses(ax, result: RunView) -> None:
    """The robot at its start (faded) and at its end, with its lamps as they were last set."""
    (first, last_row), scene = result.ends, result.scene
    n_lamps, sensors = len(scene.lamp_outputs), scene.table.robot.sensors
    start = RobotArtist(ax, scene.params, n_lamps, alpha=0.35, sensors=sensors)
    start.update(first[L.X], first[L.Y], first[L.TH], readings=sensor_readings(first, sensors))
    end = RobotArtist(ax, scene.params, n_lamps, sensors=sensors)
    last = result.outputs[-1] if result.ticks else ()
    end.update(last_row[L.X], last_row[L.Y], last_row[L.TH],
               bumpers=(last_row[L.BUMP_FR] > 0, last_row[L.BUMP_FL] > 0, last_row[L.BUMP_REAR] > 0),
               lights=(last_row[L.LIGHT_R] >= 1, last_row[L.LIGHT_L] >= 1),
               lamps=tuple(int(last[i]) for i in scene.lamp_outputs), readings=sensor_readings(last_row, sensors))


def _legend(fig: Figure, result: RunView, summary: Summary, spins: bool) -> None:
    """The states the run was in (their colours and time), and the marks this picture shows."""
    machine = result.scene.machine
    colours = state_colours(machine.states)
    handles = [Patch(color=colours[machine.states.index(state)],
                     label=picture(f"{result.scene.table.state_title(state)}  ({secs:.1f} s)"))
               for state, secs in summary.state_seconds.items() if secs > 0]
    states_legend = fig.legend(handles=handles, title="path colour = state (time in it)", loc="upper left",
                               bbox_to_anchor=(0.70, 0.88), frameon=False, fontsize=9, title_fontsize=10)
    states_legend._legend_box.align = "left"
    fig.legend(handles=legend_marks(result, summary, spins), loc="lower left", bbox_to_anchor=(0.70, 0.08),
               frameon=False, fontsize=9)


def legend_marks(result: Run, summary: Summary, spins: bool) -> list:
    """What the trajectory's marks mean: only those it shows (a collision, first light, a spin that
    happened; the world's lamps, tape and obstacles; the robot's floor sensors and beams)."""
    world, drawn = result.scene.world, [k.draw for k in declared_kinds(result)]
    marks = []
    if summary.collision_ticks:
        marks.append(Line2D([], [], marker="X", ls="", color=COLLISION, markeredgecolor="white", markersize=10,
                            label="collision (where it touched)"))
    if world.lamps and summary.first_light_s is not None:
        marks.append(Line2D([], [], marker="o", ls="", color=LIGHT_SEEN, markeredgecolor=WALL, markersize=10,
                            label="light first seen"))
    if world.lamps and summary.reached_s is not None:
        marks.append(Line2D([], [], marker="D", ls="", color=REACHED, markeredgecolor=WALL, markersize=9,
                            label=f"lamp reached (≤ {world.reach:g} m)"))
    if spins:
        marks.append(Line2D([], [], marker="o", ls="", color="#888", markeredgecolor="white", markersize=6,
                            label="a state begins with a turn on the spot"))
    if world.lamps:
        marks += [Line2D([], [], marker="*", ls="", color=LAMP_ON, markeredgecolor="#b8860b", markersize=11,
                         label="lamp, on its base (an obstacle)"),
                  Line2D([], [], ls="--", color="#b8860b", label="lamp visible inside (sensor facing it)")]
    if world.lines:
        marks.append(Patch(facecolor=TAPE_FILL, label="tape on the floor"))
    if "spot" in drawn:
        marks.append(Line2D([], [], marker="s", ls="", color=TAPE, markerfacecolor="white", markersize=7,
                            label="floor sensor (dark over tape)"))
    if "beam" in drawn:
        marks.append(Patch(facecolor=BEAM, alpha=0.45, label="distance beam, out to the echo"))
    if world.boxes or world.circles:
        marks.append(Patch(facecolor="#a4b0be", edgecolor="#57606f", hatch="//", label="obstacle"))
    return marks


# --- timeline ------------------------------------------------------------------------------------


@literal_text()
def timeline(result: Run, summary: Summary, path: Path) -> Path:
    """State, motor speeds (and lamps), event bits, and the analog readings behind them (the BumberBot's
    light, declared light and distance sensors) against time."""
    return save(timeline_figure(result, summary), path)


@literal_text()
def timeline_figure(result: Run, summary: Summary) -> Figure:
    result = RunView.of(result)
    t = np.arange(result.ticks) * result.tick_s
    readings = reading_panels(result)
    fig = Figure(figsize=(12, 7.2 + 1.8 * len(readings)), dpi=DPI)
    FigureCanvasAgg(fig)
    ratios = [2.2, 1.6, 1.6] + [1.3] * len(readings)
    axes = fig.subplots(len(ratios), 1, sharex=True, gridspec_kw={"height_ratios": ratios, "hspace": 0.12})
    _state_panel(axes[0], result)
    _output_panel(axes[1], result, t)
    _event_panel(axes[2], result, t)
    for ax, panel in zip(axes[3:], readings, strict=True):
        panel(ax, result, t)
    collisions = np.array(summary.collision_ticks) * result.tick_s
    for ax in axes:
        if len(collisions):  # one artist per panel for all of them
            _vlines(ax, collisions)
        if summary.first_light_s is not None:
            ax.axvline(summary.first_light_s, color=LIGHT_SEEN, lw=1.5, ls="--", zorder=0)
        ax.grid(axis="x", alpha=0.3)
    axes[-1].set_xlabel("time (s)")
    axes[-1].set_xlim(0, max(t[-1], result.tick_s))
    fig.suptitle(title_of(result), fontsize=15, fontweight="bold", x=0.07, ha="left", y=0.975)
    key = "   (red lines: collisions" + (", dashed: first light)" if summary.lamps else ")")
    fig.text(0.07, 0.935, subtitle_of(summary) + key, fontsize=10, color="#444")
    fig.subplots_adjust(left=0.16, right=0.97, top=0.91, bottom=0.06)
    return fig


def _vlines(ax, x: np.ndarray) -> None:
    """Red lines across the panel at times ``x``: what ``ax.vlines(x, 0, 1, transform=<x axis>)`` draws,
    without its data limits (a quarter second for an hour's collisions; every panel's limits are set)."""
    segments = np.zeros((len(x), 2, 2))
    segments[:, :, 0] = x[:, None]
    segments[:, 1, 1] = 1.0
    ax.add_collection(LineCollection(segments, colors=COLLISION, linewidths=0.8, alpha=0.5, zorder=0,
                                     transform=ax.get_xaxis_transform()), autolim=False)


def _bars(ax, starts: np.ndarray, widths: np.ndarray, bottom: float, height: float, colour: str) -> None:
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
    ax.add_collection(PolyCollection(corners, facecolors=colour), autolim=False)


def _state_panel(ax, result: Run) -> None:
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
    ax.set_ylabel("state")


def _output_panel(ax, result: Run, t: np.ndarray) -> None:
    names = result.scene.machine.output_names
    n_motors = result.scene.machine.n_motors
    labels = result.scene.table.robot.labels
    for k, name in enumerate(names):
        style = "-" if k < n_motors else ":"
        label = picture(f"{name} ({labels[name]})" if labels.get(name) else name)
        wide = k == 0  # the first drawn wide and pale, so equal speeds show both lines
        values = result.outputs[:, k]
        steps = np.concatenate(([0], np.flatnonzero(np.diff(values)) + 1, [len(values) - 1]))  # where it changes
        ax.step(t[steps], values[steps], where="post", lw=3.2 if wide else 1.3, alpha=0.55 if wide else 1.0,
                ls=style, label=label)
    ax.axhline(0, color="#999", lw=0.6)
    ax.set_ylim(-8.9, 8.9)
    ax.set_yticks([-8, -4, 0, 4, 8])
    ax.set_ylabel("motor speed\n(+ forward)")
    ax.legend(loc="upper right", fontsize=8, ncol=len(names), frameon=False)


def _event_panel(ax, result: Run, t: np.ndarray) -> None:
    table = result.scene.table
    ev = result.events
    labels = table.robot.labels
    tick, least = result.tick_s, result.ticks * result.tick_s / 500  # one-tick events stay visible
    for k, name in enumerate(table.events):
        on = np.concatenate(([False], (ev & table.bit(name)) != 0, [False])).astype(np.int8)
        edges = np.flatnonzero(np.diff(on))
        a, b = edges[::2], edges[1::2]
        _bars(ax, a * tick, np.maximum((b - a) * tick, least), k - 0.38, 0.76, "#2f3640")
    ax.set_yticks(range(len(table.events)))
    ax.set_yticklabels([picture(f"{n} {labels.get(n, 'timer = 0' if n == 'T' else 'counter = 0')}")
                        for n in table.events], fontsize=8)
    ax.set_ylim(-0.7, len(table.events) - 0.3)
    ax.invert_yaxis()
    ax.set_ylabel("events")


def declared_kinds(result: Run) -> list[SensorKind]:
    """The kinds of the robot's declared sensors, each once, in the order they are registered."""
    kinds = {s.kind for s in result.scene.table.robot.sensors}
    return [kind for name, kind in SENSOR_KINDS.items() if name in kinds]


def reading_panels(result: Run) -> list:
    """The reading panels this robot needs, in their places: light (wired phototransistors, or declared light
    sensors), then each declared kind's panel (``SensorKind.panel``). A kind without a panel (a line sensor
    reads 1 or 0) shows on the event panel."""
    wiring = result.scene.params.wiring
    builtin = bool(wiring.get("light_right") or wiring.get("light_left"))
    panels: list[tuple[int, Any]] = [(0, _light_panel)] if builtin else []
    for kind in declared_kinds(result):
        if kind.panel is not None and not (builtin and kind.panel.position == 0):
            panels.append((kind.panel.position, _panel_of(kind)))
    return [panel for _, panel in sorted(panels, key=lambda p: p[0])]


def _declared(ax, result: Run, t: np.ndarray, kind: str, scale: float) -> list[float]:
    """Plot each declared sensor of ``kind`` (reading × ``scale``) with its threshold; returns the thresholds."""
    levels = []
    for k, sensor in enumerate(result.scene.table.robot.sensors[: L.MAX_SENSORS]):
        if sensor.kind != kind:
            continue
        label = f"{sensor.name} {result.scene.table.robot.labels.get(sensor.name, '')}".strip()
        reading = result.column(L.READING + k)[:-1] * scale
        line = ax.plot(*envelope(t, reading, LIGHT_BINS), lw=1.1, label=picture(label))[0]
        on, off = sensor.switch_points()
        ax.axhline(on * scale, color=line.get_color(), lw=1, ls="--")
        if off != on:
            ax.axhline(off * scale, color=line.get_color(), lw=0.8, ls=":")
        levels += [on * scale, off * scale]
    return levels


def _panel_of(kind: SensorKind) -> Callable[..., None]:
    """The panel of one declared kind, named after it (``_distance_panel``)."""
    def panel(ax, result: Run, t: np.ndarray) -> None:
        _kind_panel(ax, result, t, kind)
    panel.__name__ = f"_{kind.name}_panel"
    return panel


def _kind_panel(ax, result: Run, t: np.ndarray, kind: SensorKind) -> None:
    """The declared sensors of one kind, each with its thresholds (``SensorKind.panel``)."""
    panel = kind.panel
    assert panel is not None
    levels = _declared(ax, result, t, kind.name, panel.scale)
    if panel.log:
        _log_scale(ax)
    else:
        ax.set_ylim(0, max(levels) * 3)  # the range where the table's thresholds act, not the far wall
    ax.set_ylabel(panel.label)
    ax.legend(loc="upper right", fontsize=8, ncol=3, frameon=False)


def _light_panel(ax, result: Run, t: np.ndarray) -> None:
    """The BumberBot's wired phototransistors against their threshold."""
    wiring = result.scene.params.wiring
    right, left = result.column(L.LIGHT_R)[:-1], result.column(L.LIGHT_L)[:-1]
    ax.plot(*envelope(t, right, LIGHT_BINS), lw=1.1, color="#e67e22", label=picture(f"{wiring['light_right']} right"))
    ax.plot(*envelope(t, left, LIGHT_BINS), lw=1.1, color="#8e44ad", label=picture(f"{wiring['light_left']} left"))
    ax.axhline(1.0, color=WALL, lw=1, ls="--", label="threshold")
    _log_scale(ax)
    ax.set_ylim(0, max(10.0, float(max(right.max(), left.max())) * 1.5))
    ax.set_ylabel("light\n(× threshold)")
    ax.legend(loc="upper right", fontsize=8, ncol=3, frameon=False)


def _log_scale(ax) -> None:
    """A reading (light) on a symmetric log scale (0, then 0.1 to 100s), its ticks written as plain numbers: the
    pictures draw text with maths parsing off (for user text), so matplotlib's 10^n labels would print
    as raw TeX."""
    from matplotlib.ticker import FuncFormatter

    ax.set_yscale("symlog", linthresh=0.1)
    ax.yaxis.set_major_formatter(FuncFormatter(lambda value, _: f"{value:g}"))
