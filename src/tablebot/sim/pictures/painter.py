"""The run's two pictures drawn by a painter: a copy of this process forked as the command starts, which
imports matplotlib on the other core while this one imports the simulator; it draws the arena as soon as
it knows the scene, the path as the robot drives it, and the rest of both pictures when the run is over
(itself the trajectory, a fork of itself the timeline), handing their PNG bytes back.

The run's columns the pictures draw are kept in memory this process maps before the fork and shares with
the painter (:class:`Shared`): nothing is copied to it; it is told, block by block, how far the run is.
This module imports neither matplotlib nor the simulator, nor even numpy, so that the painter is forked
as early as can be; the drawing itself is :class:`tablebot.sim.pictures.plots.Painting`.
"""

from __future__ import annotations

import contextlib
import functools
import mmap
import os
import pickle
import sys
from pathlib import Path
from typing import TYPE_CHECKING, Any

from tablebot.files import atomic_write
from tablebot.sim import columns as L
from tablebot.sim.pictures.forked import Forked, Inbox
from tablebot.sim.pictures.view import RunView, SceneView, ends_of, picture_columns

if TYPE_CHECKING:  # only types: see the module
    import numpy as np

    from tablebot.loop import RunEnd, RunInfo, TickBlock
    from tablebot.sim.model.scene import Scene
    from tablebot.sim.runner import SimRun
    from tablebot.sim.summary import Summary

#: The pictures' file names, in the order they are written.
PICTURES = ("trajectory.png", "timeline.png")
#: The run's arrays (runner.History's names) the pictures draw: kept in shared memory when they fit.
PICTURED = ("hist", "states", "outputs", "events")


class Shared:
    """Anonymous memory mapped before the painter is forked, so that both processes see it: arrays made
    here by this process (:meth:`zeros`) are read in place by the painter (:meth:`arrays`), which learns
    where they are from a small message. What does not fit goes to ordinary memory."""

    SIZE = 64 << 20  # an hour's pictured columns take about 25 MB; address space only, until written

    def __init__(self) -> None:
        # no swap is reserved for the pages not written (Linux's MAP_NORESERVE, which Python does not name)
        unreserved = getattr(mmap, "MAP_NORESERVE", 0x4000 if sys.platform.startswith("linux") else 0)
        self.memory = mmap.mmap(-1, self.SIZE, flags=mmap.MAP_SHARED | unreserved)
        self.used = 0
        self.made: dict[str, tuple[int, tuple[int, ...], str]] = {}  # name: offset, shape, dtype

    def zeros(self, name: str, shape: tuple[int, ...], dtype: Any) -> np.ndarray:
        """A zeroed array for runner.History: shared when it is pictured and fits, else numpy's own."""
        import numpy as np

        dtype = np.dtype(dtype)
        size = int(np.prod(shape)) * dtype.itemsize
        at = -(-self.used // 64) * 64
        if name not in PICTURED or name in self.made or at + size > self.SIZE:
            return np.zeros(shape, dtype)
        self.used = at + size
        self.made[name] = (at, tuple(shape), dtype.str)
        return np.ndarray(shape, dtype, buffer=self.memory, offset=at)

    def arrays(self, made: dict[str, tuple[int, tuple[int, ...], str]]) -> dict[str, np.ndarray]:
        """The arrays another process made with :meth:`zeros` (``made`` is its :attr:`made`)."""
        import numpy as np

        return {
            name: np.ndarray(shape, np.dtype(dtype), buffer=self.memory, offset=at)
            for name, (at, shape, dtype) in made.items()
        }


class Painter:
    """Starts the painter now (see the module). Then: :meth:`start` tells it the run about to start; the
    run's History keeps its columns with :meth:`zeros` and the run has :meth:`sink` among its sinks;
    :meth:`draw` hands it the finished run and writes the two pictures. Use it as a context manager:
    leaving the block kills the painter (and its fork) if they still run. Without a second core or
    ``fork``, the pictures are drawn here, one after the other, when the run is over."""

    def __init__(self) -> None:
        self.shared: Shared | None = None
        if hasattr(os, "fork"):  # (else the work is done here: nothing to share)
            with contextlib.suppress(OSError, ValueError):  # no memory to map: the arrays go when the run is over
                self.shared = Shared()
        self.copy = Forked(functools.partial(_paint, self.shared))

    def start(self, scene: Scene, ticks: int, seed: int, every_row: bool = False) -> bool | tuple[int, ...]:
        """The run about to start: the painter draws what it fixes (the arena, the title) while it runs.
        Returns what of the robot rows the run's History keeps (its ``rows``): the columns the pictures
        draw, or, with ``every_row`` (an animation will be drawn too), all of them."""
        kept = tuple(range(L.N_STATE)) if every_row else picture_columns(scene.table)
        self.copy.send(("start", SceneView.of(scene), ticks, seed, kept))
        return True if every_row else kept

    def zeros(self, name: str, shape: tuple[int, ...], dtype: Any) -> np.ndarray:
        """Where runner.History keeps each array (runner.Zeros)."""
        if self.shared is None:
            import numpy as np

            return np.zeros(shape, dtype)
        return self.shared.zeros(name, shape, dtype)

    @property
    def sink(self) -> _Progress:
        """A sink of the run (after its History): tells the painter how far the run is, block by block."""
        return _Progress(self)

    def draw(self, result: SimRun, summary: Summary, folder: Path) -> list[Path]:
        """trajectory.png and timeline.png in ``folder``, in that order, each written under a temporary name
        and renamed into place (the painter writes no file)."""
        made = self.shared.made if self.shared is not None else {}
        unshared = {name: getattr(result, name) for name in PICTURED if name not in made}
        self.copy.send(("done", result.ticks, ends_of(result), summary, unshared))
        drawn = pickle.loads(self.copy.result())
        paths = [folder / name for name in PICTURES]
        for path, png in zip(paths, drawn, strict=True):
            with atomic_write(path, "wb") as stream:
                stream.write(png)
        return paths

    def close(self) -> None:
        self.copy.close()

    def __enter__(self) -> Painter:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


class _Progress:
    """A sink that tells the painter where the run's shared arrays are, then how far the run is."""

    def __init__(self, painter: Painter) -> None:
        self.painter = painter

    def start(self, info: RunInfo) -> None:
        shared = self.painter.shared
        self.painter.copy.send(("arrays", dict(shared.made) if shared is not None else {}))

    def block(self, block: TickBlock) -> None:
        self.painter.copy.send(("rows", block.start + len(block)))

    def end(self, end: RunEnd) -> None:
        pass


def _paint(shared: Shared | None, inbox: Inbox) -> bytes:
    """The painter's work: the messages of :class:`Painter`, in order, turned into the pictures' PNG bytes
    (pickled, trajectory first)."""
    from tablebot.sim.pictures.plots import Painting  # matplotlib: imported at once, while this process waits

    _, scene, ticks, seed, kept = inbox.get()
    painting = Painting(scene, ticks, seed)
    arrays: dict[str, np.ndarray] = {}
    drawn = 0  # the rows of the path drawn so far
    while (message := inbox.get())[0] != "done":
        if message[0] == "arrays" and shared is not None:
            arrays = shared.arrays(message[1])
        elif (
            message[0] == "rows"
            and "hist" in arrays
            and "states" in arrays
            and message[1] - drawn >= ticks // 8
            and not inbox.waiting()
        ):  # the path so far, an eighth of the run at a time (more news: the next)
            hist, drawn = arrays["hist"], message[1]
            painting.grow(hist[:, kept.index(L.X)], hist[:, kept.index(L.Y)], arrays["states"], drawn)
    _, ticks, ends, summary, unshared = message
    arrays.update(unshared)
    # the run's History kept the columns start chose (kept)
    run = RunView(
        scene,
        seed,
        arrays["hist"][: ticks + 1],
        kept,
        ends,
        arrays["states"][:ticks],
        arrays["outputs"][:ticks],
        arrays["events"][:ticks],
    )
    return pickle.dumps(painting.finish(run, summary), protocol=5)
