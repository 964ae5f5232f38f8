"""Whole runs: the shipped arena, determinism, the trace format, the summary and the ``tablebot sim`` command."""

from __future__ import annotations

import json
import math
import re
from pathlib import Path
from typing import TYPE_CHECKING

import pytest
from PIL import Image
from PIL.GifImagePlugin import GifImageFile
from typer.testing import CliRunner

from tablebot.cli.app import app
from tablebot.engine import Engine
from tablebot.replay import record
from tablebot.sim.runner import simulate
from tablebot.sim.summary import summarise
from test_sim_helpers import BUMBERBOT, room, scene_of, trace_text

if TYPE_CHECKING:
    from tablebot.sim.runner import SimRun

CORE_KEYS = ["tick", "event", "row", "state", "timer", "M1", "M2"]


@pytest.fixture(scope="module")
def arena_run() -> SimRun:
    return simulate(scene_of(BUMBERBOT / "table.csv"), 120.0, seed=1)


def test_bumberbot_finds_the_lamp_in_its_arena_within_the_default_run(arena_run: SimRun) -> None:
    summary = summarise(arena_run)
    assert summary.first_light_s is not None and summary.reached_s is not None
    assert summary.first_light_s < summary.reached_s < 120.0
    assert summary.collisions >= 1  # the lamp's base is an obstacle: it bumps into it
    assert 11 in summary.state_seconds and 20 in summary.state_seconds
    assert abs(sum(summary.state_seconds.values()) - 120.0) < 1e-9


def test_the_lamp_is_found_with_other_seeds_too() -> None:
    scene = scene_of(BUMBERBOT / "table.csv")
    for seed in (2, 3):
        assert summarise(simulate(scene, 120.0, seed=seed)).reached_s is not None


def test_same_seed_same_trace_bytes(arena_run: SimRun) -> None:
    again = simulate(scene_of(BUMBERBOT / "table.csv"), 120.0, seed=1)
    assert trace_text(again) == trace_text(arena_run)


def test_another_seed_is_the_same_robot_with_other_noise() -> None:
    """Another seed changes the simulated noise, nothing else: the run starts from the same pose with the same
    first tick, the path drifts apart from the first ticks on by millimetres, then centimetres, and in its
    first second (nothing seen yet) the table decides exactly the same."""
    scene = scene_of(BUMBERBOT / "table.csv")
    one, two = (
        [json.loads(line) for line in trace_text(simulate(scene, 20.0, seed=seed)).splitlines()] for seed in (1, 2)
    )
    assert len(one) == len(two) == 2000 and one[0] == two[0]
    assert one[0]["x"] == one[0]["y"] == 0.35 and one[0]["heading"] == 20.0  # the arena's start
    apart = [math.dist((a["x"], a["y"]), (b["x"], b["y"])) for a, b in zip(one, two, strict=True)]
    assert 0 < next(i for i, d in enumerate(apart) if d > 0) <= 10  # the noise acts from the start
    assert 0 < apart[100] < 0.01 and 0.001 < apart[500] < 0.05  # at 1 s and 5 s: drift, not another start
    assert [[r[k] for k in CORE_KEYS] for r in one[:100]] == [[r[k] for k in CORE_KEYS] for r in two[:100]]


def test_trace_is_the_core_trace_plus_pose_and_sensors(arena_run: SimRun) -> None:
    lines = [json.loads(line) for line in trace_text(arena_run).splitlines()]
    assert len(lines) == arena_run.ticks
    assert list(lines[0])[:7] == CORE_KEYS
    assert list(lines[0])[7:] == ["x", "y", "heading", "I7_light", "I8_light", "battery_v"]
    engine = Engine(arena_run.scene.machine)  # the core, stepped live on the recorded inputs
    for line, tick in zip(lines[:3000], arena_run.inputs()[:3000], strict=True):
        engine.step(tick.mask, tick.pulses)
        assert {k: line[k] for k in CORE_KEYS} == record(engine)
    assert lines[0]["x"] == 0.35 and lines[0]["heading"] == 20.0
    assert all(-180 <= line["heading"] < 180 for line in lines)


def test_cli_writes_trace_and_pictures(tmp_path: Path) -> None:
    out = tmp_path / "out"
    result = CliRunner().invoke(app, ["sim", str(BUMBERBOT), "--seconds", "40", "--out", str(out)])
    assert result.exit_code == 0, result.output
    assert "first light seen:" in result.output and "time per state:" in result.output
    assert (out / "trace.jsonl").read_text().count("\n") == 4000
    for name in ("trajectory.png", "timeline.png"):
        with Image.open(out / name) as image:
            assert image.format == "PNG" and image.width >= 1500
    assert not (out / "run.gif").exists()


def test_cli_gif_and_quiet(tmp_path: Path) -> None:
    out = tmp_path / "out"
    result = CliRunner().invoke(app, ["sim", str(BUMBERBOT), "--seconds", "3", "--out", str(out), "--gif", "-q"])
    assert result.exit_code == 0, result.output
    assert result.output == ""
    with Image.open(out / "run.gif") as gif:
        assert isinstance(gif, GifImageFile) and gif.n_frames == 31


def test_cli_bad_world_is_a_located_error(tmp_path: Path) -> None:
    bad = tmp_path / "bad.toml"
    bad.write_text(room() + "[[box]]\nat = [1, 1]\nsize = [0.5, -1]\n", encoding="utf-8")
    result = CliRunner().invoke(app, ["sim", str(BUMBERBOT), "--world", str(bad), "--out", str(tmp_path)])
    assert result.exit_code == 2
    assert f"{bad}:{room().count(chr(10)) + 3}: error: [[box]] #1 size must be positive" in result.output
    assert "Traceback" not in result.output


def test_cli_view_without_display_fails_cleanly(tmp_path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg", force=True)  # as on a machine without a display, even where there is one
    result = CliRunner().invoke(app, ["sim", str(BUMBERBOT), "--seconds", "1", "--out", str(tmp_path), "--view"])
    assert result.exit_code == 2
    assert "no window can be opened" in result.output


LAMP_ROBOT = """name = "FlashBot"
initial_state = 1
[inputs]
I3 = "front-right bumper"
[motors]
M1 = "right motor"
M2 = "left motor"
[lamps]
L1 = "flash light"
[sim.wiring]
front_left = "none"
"""
LAMP_TABLE = "description,state,T,M1,M2,L1,timer,next\nlit,1,1,2,2,8,50,2\ndark,2,1,=,=,0,50,1\n"


def test_lamps_of_the_robot_are_traced_and_drawn_lit(tmp_path: Path) -> None:
    from matplotlib.colors import to_rgba
    from matplotlib.figure import Figure

    from tablebot.sim.pictures.draw import LAMP_OFF, LAMP_ON, RobotArtist

    (tmp_path / "robot.toml").write_text(LAMP_ROBOT, encoding="utf-8")
    (tmp_path / "table.csv").write_text(LAMP_TABLE, encoding="utf-8")
    scene = scene_of(tmp_path / "table.csv")
    result = simulate(scene, 1.2)
    assert scene.lamp_outputs == (2,)
    assert result.outputs[:, 2].tolist() == [8] * 50 + [0] * 50 + [8] * 20
    ax = Figure().add_subplot()
    robot = RobotArtist(ax, scene.params, n_lamps=1)
    robot.update(1.0, 1.0, 0.0, lamps=(8,))
    assert robot.lamps[0].get_facecolor() == to_rgba(LAMP_ON) and (robot.glows[0].get_alpha() or 0) > 0
    robot.update(1.0, 1.0, 0.0, lamps=(0,))
    assert robot.lamps[0].get_facecolor() == to_rgba(LAMP_OFF) and robot.glows[0].get_alpha() == 0


def test_cli_html_replay_is_one_self_contained_page(tmp_path: Path) -> None:
    out = tmp_path / "out"
    result = CliRunner().invoke(
        app, ["sim", str(BUMBERBOT), "--seconds", "5", "--out", str(out), "--html", "--no-plots", "-q"]
    )
    assert result.exit_code == 0, result.output
    page = (out / "run.html").read_text(encoding="utf-8")
    assert page.startswith("<!doctype html>") and "default-src 'none'" in page
    assert not re.search(r"""(src|href|url)\s*[=(]\s*["']?https?:""", page)  # nothing fetched (SVG namespaces aside)
    first = (out / "trace.jsonl").read_text(encoding="utf-8").splitlines()[0]
    assert json.loads(first)["tick"] == 0 and '"battery_v"' in page
