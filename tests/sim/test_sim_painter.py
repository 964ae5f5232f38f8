"""The pictures a painter draws while the robot runs (sim.pictures.painter): the same pixels as the figures drawn
whole in one process, however they were drawn (the arena first, the path as it grows, the timeline in two
bands, PNGs put together from parts), and no process of the painter's left behind on any way out."""

from __future__ import annotations

import io
import os
import shutil
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
import pytest
from PIL import Image
from typer.testing import CliRunner

from tablebot.cli import app
from tablebot.sim.pictures import forked, plots
from tablebot.sim.pictures.draw import literal_text
from tablebot.sim.pictures.picture import deflated, png_of, png_of_parts
from tablebot.sim.pictures.timeline import TimelinePicture
from tablebot.sim.pictures.view import RunView
from tablebot.sim.runner import simulate
from tablebot.sim.summary import summarise
from test_sim_declared import SENSORS, TABLE
from test_sim_helpers import BUMBERBOT, ROOT, scene_of

if TYPE_CHECKING:
    from collections.abc import Callable

FORKS = sys.platform.startswith("linux") and (os.cpu_count() or 1) > 1
LAMP_ROOM = (BUMBERBOT / "arena.toml").read_text()


def pixels(png: bytes | Path) -> np.ndarray:
    data = png.read_bytes() if isinstance(png, Path) else png
    return np.asarray(Image.open(io.BytesIO(data)).convert("RGBA"))


def whole_figures(folder: Path, seconds: float) -> tuple[np.ndarray, np.ndarray]:
    """The run's two pictures drawn whole, in this process, by savefig (as before there were painters)."""
    world = folder / "arena.toml"
    scene = scene_of(folder / "table.csv", world if world.exists() else None)
    result = simulate(scene, seconds, 1, history=np.float32)
    summary = summarise(result)
    return (
        pixels(plots.png_bytes(plots.trajectory_figure(result, summary))),
        pixels(plots.png_bytes(plots.timeline_figure(result, summary))),
    )


def sensor_bot(tmp_path: Path) -> Path:
    """A robot with declared line, distance and light sensors (a log-scale light panel of its own) by a lamp."""
    folder = tmp_path / "sensorbot"
    folder.mkdir()
    (folder / "robot.toml").write_text(SENSORS)
    (folder / "table.csv").write_text(TABLE)
    (folder / "arena.toml").write_text(LAMP_ROOM)
    return folder


@pytest.mark.parametrize(
    ("example", "seconds"), [("bumberbot", 150), ("line-follower", 60), ("obstacle-avoider", 60), ("sensorbot", 60)]
)
def test_the_painters_pictures_are_the_figures_drawn_whole(tmp_path: Path, example: str, seconds: float) -> None:
    folder = sensor_bot(tmp_path) if example == "sensorbot" else ROOT / "examples" / example
    result = CliRunner().invoke(
        app, ["sim", str(folder), "--seconds", str(seconds), "-q", "--out", str(tmp_path / "out")]
    )
    assert result.exit_code == 0, result.output
    trajectory, timeline = whole_figures(folder, seconds)
    assert np.array_equal(pixels(tmp_path / "out" / "trajectory.png"), trajectory)
    assert np.array_equal(pixels(tmp_path / "out" / "timeline.png"), timeline)


def test_png_parts_made_apart_are_one_image() -> None:
    rng = np.random.default_rng(3)
    image = rng.integers(0, 256, (61, 37, 4), dtype=np.uint8)
    image[20:40] = 255  # a blank band, where the parts meet
    assert np.array_equal(pixels(png_of(image, 150)), image)
    parts = [deflated(image[:30], None, last=False), deflated(image[30:], image[29], last=True)]
    png = png_of_parts(parts, 37, 61, 150)
    assert np.array_equal(pixels(png), image)
    assert Image.open(io.BytesIO(png)).info["dpi"] == pytest.approx((150, 150), abs=0.1)


def test_a_timeline_whose_bands_cannot_part_is_drawn_whole(monkeypatch: pytest.MonkeyPatch) -> None:
    """An edge through a panel (its pixels in both bands) must not cut the picture: it is drawn whole."""
    scene = scene_of(BUMBERBOT / "table.csv")
    result = simulate(scene, 30.0, 1, history=np.float32)
    summary, run = summarise(result), RunView.of(result)
    with literal_text():
        picture = TimelinePicture(run.scene, run.ticks, run.seed)
        middle = picture.axes[1].get_window_extent()
        monkeypatch.setattr(picture, "_edge", lambda: round(picture.fig.bbox.height - (middle.y0 + middle.y1) / 2))
        drawn = picture.png(run, summary)
    assert np.array_equal(pixels(drawn), pixels(plots.png_bytes(plots.timeline_figure(result, summary))))


# --- no process left behind ---------------------------------------------------------------------------


def started(pid: int) -> str | None:
    """The process's start time (to tell it from a later process given its number), None when it is gone
    or a zombie (dead, waiting to be reaped)."""
    try:
        fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    except OSError:
        return None
    return None if fields[0] in "ZX" else fields[19]


def painters_of(root: int) -> dict[int, str]:
    """The processes descending from ``root`` that call themselves tablebot-draw, with their start times."""
    parents: dict[int, int] = {}
    names: dict[int, str] = {}
    for entry in Path("/proc").iterdir():
        if entry.name.isdigit():
            try:
                status = dict(
                    line.split(":\t", 1) for line in (entry / "status").read_text().splitlines() if ":\t" in line
                )
            except OSError:
                continue
            parents[int(entry.name)], names[int(entry.name)] = int(status["PPid"]), status["Name"].strip()
    found = {}
    for pid, name in names.items():
        ancestor = pid
        while ancestor in parents and ancestor != root and ancestor > 1:
            ancestor = parents[ancestor]
        if ancestor == root and name == forked.NAME.decode() and (when := started(pid)) is not None:
            found[pid] = when
    return found


class Watch:
    """Notes every painter process (and fork of one) of a command while it runs."""

    def __init__(self, proc: subprocess.Popen) -> None:
        self.proc, self.done = proc, False
        self.seen: dict[int, str | None] = {}  # painter pid: when it started (see started)
        self.thread = threading.Thread(target=self._run, daemon=True)
        self.thread.start()

    def _run(self) -> None:
        while not self.done:
            self.seen.update(painters_of(self.proc.pid))
            time.sleep(0.003)

    def stop(self) -> None:
        self.done = True
        self.thread.join()

    def alive(self) -> list[int]:
        """The painters seen that still run, after waiting a while for them to go."""
        deadline = time.monotonic() + 20
        while (
            left := [pid for pid, when in self.seen.items() if started(pid) == when]
        ) and time.monotonic() < deadline:
            time.sleep(0.02)
        return left


def sim(out: Path, *args: str) -> subprocess.Popen:
    env = {**os.environ, "PYTHONPATH": str(ROOT / "src")}
    return subprocess.Popen(
        [sys.executable, "-m", "tablebot", "sim", str(BUMBERBOT), "--seconds", "3600", "-q", "--out", str(out), *args],
        env=env,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
    )


def wait_for(check: Callable[[], object], proc: subprocess.Popen) -> None:
    deadline = time.monotonic() + 120
    while not check():
        assert proc.poll() is None and time.monotonic() < deadline, proc.communicate()
        time.sleep(0.002)


@pytest.mark.skipif(not FORKS, reason="the painter is forked on Linux with two cores or more")
@pytest.mark.parametrize("moment", ["running", "drawing"])
@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM, signal.SIGKILL])
def test_no_painter_outlives_the_command(tmp_path: Path, moment: str, sig: signal.Signals) -> None:
    """The signal goes to the command alone (not to its process group, as Ctrl-C at a terminal would): the
    command kills its painter, or (SIGKILL) the painter and its forks die with the process they came from."""
    out = tmp_path / "out"
    proc = sim(out)
    watch = Watch(proc)
    try:
        if moment == "running":  # the trace is being written
            wait_for(lambda: out.is_dir() and any(p.name.startswith(".trace.jsonl.") for p in out.rglob("*")), proc)
        else:  # the trace is done (it waits in the staging folder) and the timeline is being drawn by a fork
            wait_for(lambda: bool(list(out.glob(".tablebot-*/trace.jsonl"))) and len(watch.seen) >= 2, proc)
        proc.send_signal(sig)
        _, err = proc.communicate(timeout=120)
    finally:
        proc.kill()
        watch.stop()
    assert proc.returncode == {signal.SIGINT: 130, signal.SIGTERM: 143, signal.SIGKILL: -9}[sig], err
    assert watch.seen and watch.alive() == []
    assert not (out / "trajectory.png").exists()


@pytest.mark.skipif(not FORKS, reason="the painter is forked on Linux with two cores or more")
def test_a_painter_killed_while_the_robot_runs_leaves_the_pictures_to_the_command(tmp_path: Path) -> None:
    out = tmp_path / "out"
    proc = sim(out, "--seconds", "300")
    watch = Watch(proc)
    try:
        wait_for(lambda: any(p.name.startswith(".trace.jsonl.") for p in out.rglob("*")) and watch.seen, proc)
        for pid in list(watch.seen):
            os.kill(pid, signal.SIGKILL)
        _, err = proc.communicate(timeout=120)
    finally:
        proc.kill()
        watch.stop()
    assert proc.returncode == 0, err
    reference = tmp_path / "reference"
    done = subprocess.run(
        [sys.executable, "-m", "tablebot", "sim", str(BUMBERBOT), "--seconds", "300", "-q", "--out", str(reference)],
        env={**os.environ, "PYTHONPATH": str(ROOT / "src")},
        timeout=300,
    )
    assert done.returncode == 0
    for name in ("trace.jsonl", "trajectory.png", "timeline.png"):
        assert (
            np.array_equal(pixels(out / name), pixels(reference / name))
            if name.endswith(".png")
            else (out / name).read_bytes() == (reference / name).read_bytes()
        )


def test_without_a_second_core_the_command_draws_its_pictures_itself(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(os, "cpu_count", lambda: 1)
    shutil.copytree(BUMBERBOT, tmp_path / "bot")
    result = CliRunner().invoke(
        app, ["sim", str(tmp_path / "bot"), "--seconds", "60", "-q", "--out", str(tmp_path / "out")]
    )
    assert result.exit_code == 0, result.output
    trajectory, timeline = whole_figures(tmp_path / "bot", 60)
    assert np.array_equal(pixels(tmp_path / "out" / "trajectory.png"), trajectory)
    assert np.array_equal(pixels(tmp_path / "out" / "timeline.png"), timeline)


@pytest.mark.parametrize("case", ["no shared memory", "every row kept (an animation too)"])
def test_the_pictures_are_the_same_whatever_the_painter_is_handed(
    tmp_path: Path, case: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Without memory to share, the arrays go to the painter when the run is over; with --gif the run keeps
    every column of every robot row, and the painter draws from those."""
    from tablebot.sim.pictures import painter

    def refuse(self: painter.Shared) -> None:
        raise OSError("no memory to map")

    args = ["--gif"] if case.startswith("every") else []
    if case == "no shared memory":
        monkeypatch.setattr(painter.Shared, "__init__", refuse)
    result = CliRunner().invoke(
        app, ["sim", str(BUMBERBOT), "--seconds", "40", "-q", "--out", str(tmp_path / "out"), *args]
    )
    assert result.exit_code == 0, result.output
    trajectory, timeline = whole_figures(BUMBERBOT, 40)
    assert np.array_equal(pixels(tmp_path / "out" / "trajectory.png"), trajectory)
    assert np.array_equal(pixels(tmp_path / "out" / "timeline.png"), timeline)
