"""The run's pictures: ``trajectory.png`` (the path in the arena, coloured by state, drawn here) and
``timeline.png`` (:mod:`tablebot.sim.pictures.timeline`), and the two drawn at once by a painter (:class:`Painting`).

Figures are drawn with the Agg canvas directly, never through pyplot, so they need no display.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any, cast

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.collections import LineCollection
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.patches import Patch

from tablebot.colours import state_colours
from tablebot.escape import picture
from tablebot.i18n import _, number
from tablebot.sim import columns as L
from tablebot.sim.pictures.draw import (
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
from tablebot.sim.pictures.forked import Forked
from tablebot.sim.pictures.path import PathPieces, spin_starts
from tablebot.sim.pictures.picture import (  # noqa: F401 (title_of: other modules import it from here)
    DPI,
    declared_kinds,
    encoded,
    png_bytes,
    save,
    subtitle_of,
    title,
    title_of,
)
from tablebot.sim.pictures.timeline import (  # noqa: F401 (the timeline's public functions, imported from here too)
    TimelinePicture,
    reading_panels,
    timeline_figure,
)
from tablebot.sim.pictures.view import RunView, SceneView
from tablebot.sim.summary import Summary

if TYPE_CHECKING:  # only types: the pictures are drawn without the simulator (a painter never imports numba)
    from matplotlib.axes import Axes

    from tablebot.sim.model.scene import Scene
    from tablebot.sim.pictures.picture import Run

PATH_Z = 4  # the path's z-order: everything the arena draws is below it


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

    def __init__(self, scene: SceneView | Scene, ticks: int, seed: int) -> None:
        world = scene.world
        xs, ys = zip(*world.walls, strict=True)
        aspect = (max(ys) - min(ys)) / max(1e-9, max(xs) - min(xs))
        self.fig = Figure(figsize=(11, max(4.5, 7.2 * aspect + 1.2)), dpi=DPI)
        FigureCanvasAgg(self.fig)
        self.ax = self.fig.add_axes((0.06, 0.08, 0.62, 0.8))
        draw_world(self.ax, world)
        self.title = self.fig.suptitle(
            title(scene, ticks, seed), fontsize=15, fontweight="bold", x=0.06, ha="left", y=0.975
        )
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
            pieces.draw(cast(FigureCanvasAgg, self.fig.canvas).get_renderer())  # made on an Agg canvas
            self.drawn.append(pieces)

    def _add_path(self, pieces: list[np.ndarray], piece_states: list[int]) -> LineCollection | None:
        if not pieces:
            return None
        lines = LineCollection(
            pieces,
            colors=[self.colours[s] for s in piece_states],
            linewidths=2.2,
            capstyle="round",
            joinstyle="round",
            zorder=PATH_Z,
        )
        self.ax.add_collection(lines, autolim=False)  # the arena set the limits
        return lines

    def finish(self, result: RunView, summary: Summary) -> TrajectoryPicture:
        """Add the rest of the run: the path's last pieces, spins, collisions, first light, lamp reached,
        the robot at its start and end, the summary line and the legends."""
        ax, fig, colours = self.ax, self.fig, self.colours
        x, y = result.column(L.X), result.column(L.Y)
        self._add_path(*self.path.grow(x, y, result.states, result.ticks, last=True))
        # spins in place draw no line: a dot where such a state begins shows them
        spins = spin_starts(x, y, result.column(L.TH), result.states)
        ax.scatter(
            x[spins],
            y[spins],
            s=18,
            c=[colours[s] for s in result.states[spins].tolist()],
            edgecolors="white",
            linewidths=0.6,
            zorder=5,
        )
        _markers(ax, result, summary)
        _robot_poses(ax, result)
        fig.text(0.06, 0.915, subtitle_of(summary), fontsize=10.5, color="#444")
        _legend(fig, result, summary, len(spins) > 0)
        return self

    def png(self) -> bytes:
        """The picture as PNG: the bytes :func:`png_bytes` gives for the whole figure."""
        assert self.drawn is not None, "the rest is drawn over the arena (render_arena)"
        renderer = cast(FigureCanvasAgg, self.fig.canvas).get_renderer()  # made on an Agg canvas
        # what Axes.draw and Figure.draw would draw after what is drawn, in their order (by z-order, stably)
        rest = sorted((a for a in self.ax.get_children() if a not in self.drawn), key=lambda a: a.get_zorder())
        assert not rest or min(a.get_zorder() for a in rest) >= max(a.get_zorder() for a in self.drawn)
        for artist in rest:
            artist.draw(renderer)
        texts = [t for t in self.fig.texts if t is not self.title]  # the title was drawn with the arena
        for artist in sorted([*texts, *self.fig.legends], key=lambda a: a.get_zorder()):
            artist.draw(renderer)
        return encoded(self.fig)


class Painting:
    """Both pictures as the painter (:mod:`tablebot.sim.pictures.painter`) draws them: what the scene fixes at once
    (the arena drawn, the timeline's panels made), the path as the run goes (:meth:`grow`), the rest when
    it is over (:meth:`finish`: the timeline by a fork of this process on the other core,
    :mod:`tablebot.sim.pictures.forked`)."""

    def __init__(self, scene: SceneView, ticks: int, seed: int) -> None:
        with literal_text():  # the timeline first: when the run ends early, its fork can start at once
            self.timeline = TimelinePicture(scene, ticks, seed)
            self.trajectory = TrajectoryPicture(scene, ticks, seed)
            self.trajectory.render_arena()

    def grow(self, x: np.ndarray, y: np.ndarray, states: np.ndarray, done: int) -> None:
        with literal_text():
            self.trajectory.grow(x, y, states, done)

    @literal_text()
    def finish(self, result: RunView, summary: Summary) -> tuple[bytes, bytes]:
        """The two pictures' PNG bytes, trajectory first."""
        with Forked(lambda _: self.timeline.png(result, summary)) as timeline_png:
            return self.trajectory.finish(result, summary).png(), timeline_png.result()


def _markers(ax: Axes, result: RunView, summary: Summary) -> None:
    scene, rows = result.scene, list(summary.collision_ticks)
    x, y, heading = result.column(L.X), result.column(L.Y), result.column(L.TH)
    if rows:  # where the body touched the wall or obstacle; one artist for all of them: an hour has hundreds
        poses = np.column_stack((x[rows], y[rows], heading[rows])).astype(np.float64)
        touched = contact_points(scene.geometry, scene.params, poses)
        ax.plot(
            touched[:, 0],
            touched[:, 1],
            ls="",
            marker="X",
            markersize=11,
            color=COLLISION,
            markeredgecolor="white",
            markeredgewidth=1.2,
            zorder=9,
        )
    tick = result.tick_s
    if summary.first_light_s is not None:
        row = round(summary.first_light_s / tick)
        ax.plot(x[row], y[row], marker="o", markersize=12, color=LIGHT_SEEN, markeredgecolor=WALL, zorder=9)
    if summary.reached_s is not None:
        row = round(summary.reached_s / tick)
        ax.plot(x[row], y[row], marker="D", markersize=11, color=REACHED, markeredgecolor=WALL, zorder=9)


def _robot_poses(ax: Axes, result: RunView) -> None:
    """The robot at its start (faded) and at its end, with its lamps as they were last set."""
    (first, last_row), scene = result.ends, result.scene
    n_lamps, sensors = len(scene.lamp_outputs), scene.table.robot.sensors
    start = RobotArtist(ax, scene.params, n_lamps, alpha=0.35, sensors=sensors)
    start.update(first[L.X], first[L.Y], first[L.TH], readings=sensor_readings(first, sensors))
    end = RobotArtist(ax, scene.params, n_lamps, sensors=sensors)
    last = result.outputs[-1] if result.ticks else ()
    end.update(
        last_row[L.X],
        last_row[L.Y],
        last_row[L.TH],
        bumpers=(last_row[L.BUMP_FR] > 0, last_row[L.BUMP_FL] > 0, last_row[L.BUMP_REAR] > 0),
        lights=(last_row[L.LIGHT_R] >= 1, last_row[L.LIGHT_L] >= 1),
        lamps=tuple(int(last[i]) for i in scene.lamp_outputs),
        readings=sensor_readings(last_row, sensors),
    )


def _legend(fig: Figure, result: RunView, summary: Summary, spins: bool) -> None:
    """The states the run was in (their colours and time), and the marks this picture shows."""
    machine = result.scene.machine
    colours = state_colours(machine.states)
    handles = [
        Patch(
            color=colours[machine.states.index(state)],
            label=picture(f"{result.scene.table.state_title(state)}  ({number(secs, '.1f')} s)"),
        )
        for state, secs in summary.state_seconds.items()
        if secs > 0
    ]
    states_legend = fig.legend(
        handles=handles,
        title=_("path colour = state (time in it)"),
        loc="upper left",
        bbox_to_anchor=(0.70, 0.88),
        frameon=False,
        fontsize=9,
        title_fontsize=10,
    )
    states_legend._legend_box.align = "left"  # type: ignore[attr-defined]  # private: not in matplotlib's stubs
    fig.legend(
        handles=legend_marks(result, summary, spins),
        loc="lower left",
        bbox_to_anchor=(0.70, 0.08),
        frameon=False,
        fontsize=9,
    )


def legend_marks(result: Run, summary: Summary, spins: bool) -> list:
    """What the trajectory's marks mean: only those it shows (a collision, first light, a spin that
    happened; the world's lamps, tape and obstacles; the robot's floor sensors and beams)."""
    world, drawn = result.scene.world, [k.draw for k in declared_kinds(result)]
    marks: list[Line2D | Patch] = []
    if summary.collision_ticks:
        marks.append(
            Line2D(
                [],
                [],
                marker="X",
                ls="",
                color=COLLISION,
                markeredgecolor="white",
                markersize=10,
                label=_("collision (where it touched)"),
            )
        )
    if world.lamps and summary.first_light_s is not None:
        marks.append(
            Line2D(
                [],
                [],
                marker="o",
                ls="",
                color=LIGHT_SEEN,
                markeredgecolor=WALL,
                markersize=10,
                label=_("light first seen"),
            )
        )
    if world.lamps and summary.reached_s is not None:
        marks.append(
            Line2D(
                [],
                [],
                marker="D",
                ls="",
                color=REACHED,
                markeredgecolor=WALL,
                markersize=9,
                label=_("lamp reached (≤ {reach:g} m)").format(reach=world.reach),
            )
        )
    if spins:
        marks.append(
            Line2D(
                [],
                [],
                marker="o",
                ls="",
                color="#888",
                markeredgecolor="white",
                markersize=6,
                label=_("a state begins with a turn on the spot"),
            )
        )
    if world.lamps:
        marks += [
            Line2D(
                [],
                [],
                marker="*",
                ls="",
                color=LAMP_ON,
                markeredgecolor="#b8860b",
                markersize=11,
                label=_("lamp, on its base (an obstacle)"),
            ),
            Line2D([], [], ls="--", color="#b8860b", label=_("lamp visible inside (sensor facing it)")),
        ]
    if world.lines:
        marks.append(Patch(facecolor=TAPE_FILL, label=_("tape on the floor")))
    if "spot" in drawn:
        marks.append(
            Line2D(
                [],
                [],
                marker="s",
                ls="",
                color=TAPE,
                markerfacecolor="white",
                markersize=7,
                label=_("floor sensor (dark over tape)"),
            )
        )
    if "beam" in drawn:
        marks.append(Patch(facecolor=BEAM, alpha=0.45, label=_("distance beam, out to the echo")))
    if world.boxes or world.circles:
        marks.append(Patch(facecolor="#a4b0be", edgecolor="#57606f", hatch="//", label=_("obstacle")))
    return marks
