"""What the run's two pictures share: their resolution, title and summary line, the sensor kinds they show,
and how a figure becomes PNG bytes (with the Agg canvas directly, never through pyplot: no display needed).
"""

from __future__ import annotations

import io
import struct
import zlib
from pathlib import Path
from typing import IO, TYPE_CHECKING, Any, TypeAlias, cast

import matplotlib
import matplotlib.image
import numpy as np
from matplotlib.figure import Figure

from tablebot.escape import picture
from tablebot.files import atomic_write
from tablebot.i18n import _, current, ngettext, number
from tablebot.sensors import SENSOR_KINDS, SensorKind

if TYPE_CHECKING:  # only types: the pictures are drawn without the simulator (a painter never imports numba)
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    from tablebot.sim.model.scene import Scene
    from tablebot.sim.pictures.view import RunView, SceneView
    from tablebot.sim.runner import SimRun
    from tablebot.sim.summary import Summary

    Run: TypeAlias = SimRun | RunView  # declared: mypy may take a union of classes not yet seen for a value

DPI = 150
#: zlib's fastest level: the same pixels as Pillow's default (6) in two thirds of the time, files ~25 % larger
PNG_LEVEL = 1


def title_of(result: Run) -> str:
    return title(result.scene, result.ticks, result.seed)


def title(scene: SceneView | Scene, ticks: int, seed: int) -> str:
    """The pictures' title: the robot, the world, the run's length and seed (all known before the run)."""
    robot, world = picture(scene.table.robot.name), picture(scene.world.name)
    return _("{robot} in {world} — {seconds:g} s, seed {seed}").format(
        robot=robot, world=world, seconds=ticks * scene.tick_s, seed=seed
    )


def subtitle_of(summary: Summary) -> str:
    """The summary line under the title, in the reader's language (numbers with
    a decimal point, the same as the axes' ticks and every file tablebot writes)."""

    def when(v: float | None) -> str:
        return _("never") if v is None else f"{v:.1f} s"

    parts = []
    if summary.lamps:
        parts += [
            _("light first seen: {when}").format(when=when(summary.first_light_s)),
            _("lamp reached: {when}").format(when=when(summary.reached_s)),
        ]
    if summary.laps is not None:
        parts.append(_("{laps:.2f} laps of the line").format(laps=summary.laps))
    parts += [
        ngettext("{n} collision", "{n} collisions", summary.collisions).format(n=summary.collisions),
        _("{metres:.2f} m driven").format(metres=summary.distance_m),
    ]
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
    """The figure's canvas, as drawn so far, as PNG: the pixels :func:`png_bytes` gives when the canvas holds
    what a whole draw would, in half the time (see :func:`png_of`)."""
    canvas = cast("FigureCanvasAgg", fig.canvas)  # the pictures' figures are made on an Agg canvas
    return png_of(np.asarray(canvas.buffer_rgba()), fig.dpi)


def drawn_png(fig: Figure) -> bytes:
    """The figure drawn and encoded as PNG: the pixels of :func:`png_bytes`, sooner (see :func:`png_of`)."""
    fig.canvas.draw()
    return encoded(fig)


#: The Software note matplotlib writes into its PNGs, written into ours too.
SOFTWARE = f"Matplotlib version{matplotlib.__version__}, https://matplotlib.org/"


def png_of(rgba: np.ndarray, dpi: float) -> bytes:
    """An (height, width, 4) uint8 image as PNG: each row filtered as the difference from the row above
    (PNG's "Up"), at zlib's fastest level. Pillow's encoder, which matplotlib's savefig uses, makes the
    same pixels, files of the same size, in twice the time (it tries the five filters on every row)."""
    return png_of_parts([deflated(rgba, None, last=True)], rgba.shape[1], rgba.shape[0], dpi)


def deflated(rows: np.ndarray, above: np.ndarray | None, last: bool) -> tuple[bytes, int, int]:
    """Rows of an image (its first ones, or with the row ``above`` them, any after) filtered and
    compressed as one part of a PNG's image data: its deflate blocks (ending on a whole byte unless
    ``last``, so that the next part follows on), the Adler-32 and the length of what they hold. Parts
    made apart (by two processes) put together with :func:`png_of_parts` are one valid PNG."""
    height, width, _ = rows.shape
    filtered = np.empty((height, 1 + 4 * width), dtype=np.uint8)
    filtered[:, 0] = 2  # Up
    flat = rows.reshape(height, 4 * width)
    if above is None:
        filtered[0, 1:] = flat[0]  # the first row: the row above is taken as zeros
    else:
        np.subtract(flat[0], above.reshape(-1), out=filtered[0, 1:])
    np.subtract(flat[1:], flat[:-1], out=filtered[1:, 1:])  # modulo 256, as PNG's filters are
    packer = zlib.compressobj(PNG_LEVEL, zlib.DEFLATED, -15)  # raw deflate: the zlib frame is made once
    # the ignores: numpy's stubs give ndarray a __buffer__ only for Python 3.12 on (mypy checks as 3.11)
    data = packer.compress(filtered) + packer.flush(  # type: ignore[arg-type]
        zlib.Z_FINISH if last else zlib.Z_FULL_FLUSH
    )
    return data, zlib.adler32(filtered), filtered.size  # type: ignore[arg-type]


def png_of_parts(parts: list[tuple[bytes, int, int]], width: int, height: int, dpi: float) -> bytes:
    """The PNG of an RGBA image whose rows, in order, are in ``parts`` (see :func:`deflated`)."""
    check = 1
    for _data, adler, length in parts:
        check = _adler32_combine(check, adler, length)
    stream = b"".join((b"\x78\x01", *(data for data, _adler, _length in parts), struct.pack(">I", check)))
    per_metre = int(dpi / 0.0254 + 0.5)
    return b"".join(
        (
            b"\x89PNG\r\n\x1a\n",
            _chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 6, 0, 0, 0)),
            _chunk(b"pHYs", struct.pack(">IIB", per_metre, per_metre, 1)),
            _chunk(b"tEXt", b"Software\0" + SOFTWARE.encode("latin-1")),
            _chunk(b"IDAT", stream),
            _chunk(b"IEND", b""),
        )
    )


def _adler32_combine(first: int, second: int, length: int) -> int:
    """The Adler-32 of two pieces one after the other, from theirs (zlib's adler32_combine)."""
    base = 65521
    low = ((first & 0xFFFF) + (second & 0xFFFF) - 1) % base
    high = ((first >> 16) + (second >> 16) + length * (first & 0xFFFF) - length) % base
    return low | high << 16


def _chunk(kind: bytes, data: bytes) -> bytes:
    return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))


def readers_numbers(fig: Figure) -> Figure:
    """The axes' numbers as the reader's language writes them (0,5 in German): an axis with matplotlib's own
    number formatter gets tablebot.i18n.number's; an axis that labels its ticks otherwise (state names, a
    formatter of its own) is left as it is, and so is every axis in English."""
    from matplotlib.ticker import FuncFormatter, ScalarFormatter

    language = current()  # the figure's, whatever is in use when it is drawn
    if number(0.5, language=language) == "0.5":
        return fig
    for ax in fig.axes:
        for axis in (ax.xaxis, ax.yaxis):
            if type(axis.get_major_formatter()) is ScalarFormatter:
                axis.set_major_formatter(FuncFormatter(lambda value, _pos: number(value, "g", language)))
    return fig


def _write_png(fig: Figure, stream: IO[bytes]) -> None:
    readers_numbers(fig)
    fig.savefig(stream, format="png", facecolor="white", pil_kwargs={"compress_level": PNG_LEVEL})
