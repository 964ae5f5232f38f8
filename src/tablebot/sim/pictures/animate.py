"""The run as a moving picture: ``run.gif`` (Agg + pillow, headless) and ``--view``'s live window.

Both replay a finished run: the robot with its bumpers (red when closed), sensor cones (bright when
a sensor reads 1) and lamps (lit when the table switches them on), its trail coloured by state.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import cast

import numpy as np
from matplotlib.animation import FuncAnimation
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.collections import LineCollection
from matplotlib.colors import to_rgba_array
from matplotlib.figure import Figure
from PIL import Image

from tablebot.colours import state_colours
from tablebot.diagnostics import fail
from tablebot.escape import picture
from tablebot.files import atomic_write
from tablebot.i18n import N_, _, number
from tablebot.sim import columns as L
from tablebot.sim.pictures.draw import RobotArtist, draw_world, literal_text, sensor_readings
from tablebot.sim.pictures.plots import subtitle_of, title_of
from tablebot.sim.runner import SimRun
from tablebot.sim.summary import Summary

GIF_FPS = 10
GIF_MAX_FRAMES = 240  # longer runs play faster: a 120 s run becomes a 24 s gif at 5×


class Player:
    """Draws frame k of a run onto a figure; shared by the gif writer and the live window."""

    def __init__(self, fig: Figure, result: SimRun, summary: Summary, ticks_per_frame: int, speed: float) -> None:
        self.result, self.step = result, ticks_per_frame
        scene = result.scene
        self.ax = fig.add_axes((0.08, 0.08, 0.9, 0.78))
        draw_world(self.ax, scene.world)
        fig.suptitle(title_of(result), fontsize=12, fontweight="bold", x=0.08, ha="left", y=0.975)
        fig.text(0.08, 0.93, subtitle_of(summary), fontsize=8, color="#444")
        # the trail at frame resolution: one segment per frame keeps redrawing it cheap
        ticks = np.minimum(np.arange(0, result.ticks + ticks_per_frame, ticks_per_frame), result.ticks)
        points = result.kept_rows()[ticks][:, [L.X, L.Y]]  # an animated run keeps every robot row
        self.segments = np.stack((points[:-1], points[1:]), axis=1)
        colours = to_rgba_array(state_colours(scene.machine.states))
        self.colours = colours[result.states[np.minimum(ticks[:-1], max(0, result.ticks - 1))]]
        self.trail = LineCollection([], linewidths=1.8, zorder=4)
        self.ax.add_collection(self.trail)
        self.robot = RobotArtist(self.ax, scene.params, len(scene.lamp_outputs), sensors=scene.table.robot.sensors)
        self.hud = self.ax.text(
            1.0,
            1.02,
            "",
            transform=self.ax.transAxes,
            va="bottom",
            ha="right",
            fontsize=9,
            family="monospace",
            zorder=20,
        )
        self.speed = speed
        self.frames = result.ticks // ticks_per_frame + 1

    def draw(self, frame: int) -> list:
        r, scene = self.result, self.result.scene
        t = min(frame * self.step, r.ticks)
        # matplotlib's stubs want a sequence of (n, 2) arrays; an (n, 2, 2) array is one
        self.trail.set_segments(cast("Sequence[np.ndarray]", self.segments[:frame]))
        self.trail.set_color(self.colours[:frame])
        assert r.hist is not None  # checked when made
        h = r.hist[t]
        last = r.outputs[t - 1] if t > 0 else np.zeros(len(scene.machine.output_names), dtype=np.int64)
        self.robot.update(
            h[L.X],
            h[L.Y],
            h[L.TH],
            bumpers=(h[L.BUMP_FR] > 0, h[L.BUMP_FL] > 0, h[L.BUMP_REAR] > 0),
            lights=(h[L.LIGHT_R] >= 1, h[L.LIGHT_L] >= 1),
            lamps=tuple(int(last[i]) for i in scene.lamp_outputs),
            readings=sensor_readings(h, scene.table.robot.sensors),
        )
        state = scene.machine.states[r.states[max(0, t - 1)]] if r.ticks else scene.table.robot.initial_state
        names = scene.machine.output_names
        n_motors = scene.machine.n_motors
        on, off = _("on {level}"), _("off")  # a lamp's words
        outputs = "  ".join(
            f"{n} {int(v):+d}" if k < n_motors else f"{n} {on.format(level=int(v)) if v else off}"
            for k, (n, v) in enumerate(zip(names, last, strict=True))
        )
        speed = "   " + _("({speed:g}× speed)").format(speed=self.speed) if self.speed != 1 else ""
        now = picture(f"{scene.table.state_title(state)}   {outputs}")
        self.hud.set_text(f"t = {number(t * r.tick_s, '6.2f')} s{speed}\n{now}")
        return [self.trail, self.hud, *self.robot.artists()]


@literal_text()
def write_gif(result: SimRun, summary: Summary, path: Path) -> Path:
    """An animated gif, at most GIF_MAX_FRAMES frames (long runs are sped up).

    The arena is drawn once and each frame only redraws the moving artists on a copy of it (blitting).
    """
    seconds = result.ticks * result.tick_s
    speed = max(1.0, float(np.ceil(seconds * GIF_FPS / GIF_MAX_FRAMES)))
    ticks_per_frame = max(1, round(speed / GIF_FPS / result.tick_s))
    fig = Figure(figsize=(7.5, 6.2), dpi=80)
    canvas = FigureCanvasAgg(fig)
    player = Player(fig, result, summary, ticks_per_frame, speed)
    moving = player.draw(0)
    for artist in moving:
        artist.set_animated(True)
    canvas.draw()
    background = canvas.copy_from_bbox(fig.bbox)
    frames: list[Image.Image] = []
    for k in range(player.frames):
        canvas.restore_region(background)
        for artist in player.draw(k):
            player.ax.draw_artist(artist)
        frame = Image.fromarray(np.asarray(canvas.buffer_rgba())[:, :, :3].copy())
        # one palette for all frames (from the busiest, last one) keeps colours steady and saving quick
        frames.append(frame)
    palette = frames[-1].quantize(colors=255, method=Image.Quantize.MEDIANCUT)
    indexed = [f.quantize(palette=palette, dither=Image.Dither.NONE) for f in frames]
    with atomic_write(path, "wb") as stream:
        indexed[0].save(
            stream, format="GIF", save_all=True, append_images=indexed[1:], duration=round(1000 / GIF_FPS), loop=0
        )
    return path


def check_display() -> None:
    """Fail with a clear message (before any simulation) when --view cannot open a window."""
    import matplotlib.pyplot as plt

    if not _interactive(plt.get_backend()):
        raise fail(
            "--view",
            N_(
                "no window can be opened here (no display, or matplotlib's backend is {backend!r})",
                backend=plt.get_backend(),
            ),
            N_("run without --view and open the pictures, or use --gif"),
        )


@literal_text()
def show(result: SimRun, summary: Summary) -> None:
    """A live window playing the run in real time."""
    import matplotlib.pyplot as plt

    check_display()
    fig = plt.figure(figsize=(9, 7.5))
    fps = 20
    player = Player(fig, result, summary, max(1, round(1 / fps / result.tick_s)), 1.0)
    animation = FuncAnimation(fig, player.draw, frames=player.frames, interval=1000 / fps, blit=True, repeat=False)
    plt.show()
    del animation


def _interactive(backend: str) -> bool:
    return backend.lower() not in (
        "agg",
        "pdf",
        "ps",
        "svg",
        "cairo",
        "pgf",
        "template",
    ) and not backend.lower().startswith("module://matplotlib_inline")
