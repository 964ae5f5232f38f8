"""What the run's two pictures share: their resolution, title and summary line, the sensor kinds they show,
and how a figure becomes PNG bytes (with the Agg canvas directly, never through pyplot: no display needed).
"""

from __future__ import annotations

import io
from pathlib import Path
from typing import IO, TYPE_CHECKING, Any

import matplotlib.image
from matplotlib.figure import Figure

from tablebot.escape import picture
from tablebot.files import atomic_write
from tablebot.sensors import SENSOR_KINDS, SensorKind

if TYPE_CHECKING:  # only types: the pictures are drawn without the simulator (a painter never imports numba)
    from tablebot.sim.runner import SimRun
    from tablebot.sim.scene import Scene
    from tablebot.sim.summary import Summary
    from tablebot.sim.view import RunView, SceneView

    Run = SimRun | RunView

DPI = 150
#: zlib's fastest level: the same pixels as Pillow's default (6) in two thirds of the time, files ~25 % larger
PNG_LEVEL = 1


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


def declared_kinds(run_or_scene: Any) -> list[SensorKind]:
    """The kinds of the robot's declared sensors (of a run or a scene), each once, in the order they are
    registered."""
    kinds = {s.kind for s in getattr(run_or_scene, "scene", run_or_scene).table.robot.sensors}
    return [kind for name, kind in SENSOR_KINDS.items() if name in kinds]


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


def encoded(fig: Figure) -> bytes:
    """The figure's canvas, as drawn so far, encoded as PNG as :func:`png_bytes` encodes it (matplotlib's
    print_png): the bytes :func:`png_bytes` gives when the canvas holds what a whole draw would."""
    stream = io.BytesIO()
    matplotlib.image.imsave(stream, fig.canvas.buffer_rgba(), format="png", origin="upper", dpi=fig.dpi,
                            pil_kwargs={"compress_level": PNG_LEVEL})
    return stream.getvalue()


def _write_png(fig: Figure, stream: IO[bytes]) -> None:
    fig.savefig(stream, format="png", facecolor="white", pil_kwargs={"compress_level": PNG_LEVEL})
