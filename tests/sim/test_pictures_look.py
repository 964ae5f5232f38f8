"""What the pictures show (issue 18): the light panel's own labels render and its y-label stays in view,
a state keeps its colour in every picture of a table, legends list only what is drawn, a followed line's
path shows above the tape, diagrams are sharp, and user text is drawn printable and literal."""

from __future__ import annotations

import os
import shutil
import warnings
from pathlib import Path
from typing import TYPE_CHECKING, cast

import numpy as np
import pytest
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.collections import LineCollection, PatchCollection, PolyCollection
from matplotlib.colors import to_hex
from matplotlib.patches import Patch
from matplotlib.text import Text
from PIL import Image
from typer.testing import CliRunner

from tablebot.cli import app
from tablebot.colours import PALETTE, state_colours
from tablebot.sim.pictures import plots, timeline
from tablebot.sim.pictures.animate import Player
from tablebot.sim.pictures.draw import literal_text
from tablebot.sim.runner import simulate
from tablebot.sim.summary import summarise
from test_sim_helpers import BUMBERBOT, ROOT, scene_of

if TYPE_CHECKING:
    from collections.abc import Callable
    from typing import Any

    from matplotlib.figure import Figure

    from tablebot.sim.pictures.timeline import TimelinePicture

TUTORIAL_ROBOT = """\
name = "my-robot"
initial_state = 1
[inputs]
I1 = "distance"
[motors]
M1 = "right motor"
M2 = "left motor"
[states]
1 = "turning"
2 = "driving"
"""
#: The tutorial's table before and after its sensor row: the row makes state 2 the first state written.
BEFORE = "description,state,T,I1,M1,M2,timer,next\nstart driving,1,1,,6,6,8s,2\ntime to turn,2,1,,-5,5,700ms,1\n"
AFTER = (
    "description,state,T,I1,M1,M2,timer,next\nI1 while driving,2,,1,-5,5,1s,1\n"
    "start driving,1,1,,6,6,8s,2\ntime to turn,2,1,,-5,5,700ms,1\n"
)


def drawn(figure_of: Callable[..., Figure], *args: Any) -> Figure:
    """A figure made and drawn as the pictures are (maths parsing off for user text)."""
    with literal_text():
        fig = figure_of(*args)
        fig.canvas.draw()
    return fig


def test_the_light_panel_labels_render_and_its_y_label_is_in_view() -> None:
    """The symlog ticks printed as raw '$\\mathdefault{10^{3}}$' and pushed the y-label out of the picture."""
    result = simulate(scene_of(BUMBERBOT / "table.csv"), 40.0)
    fig = drawn(plots.timeline_figure, result, summarise(result))
    light = fig.axes[-1]
    ticks = [t.get_text() for t in light.get_yticklabels() if t.get_text()]
    assert ticks and not [t for t in ticks if "$" in t or "\\" in t], ticks
    assert {"0", "1", "10"} <= set(ticks)
    label = light.yaxis.label.get_window_extent(cast(FigureCanvasAgg, fig.canvas).get_renderer())
    assert light.get_ylabel().startswith("light") and label.x0 >= 0 and label.x1 <= fig.bbox.x1


def test_a_state_keeps_its_colour_in_every_picture_of_a_table(tmp_path: Path) -> None:
    """The tutorial's 'driving' was orange in one picture and blue in the next: colours went by the
    order states appear in the table, which the added row changed."""
    seen: dict[str, set[str]] = {"1 · turning": set(), "2 · driving": set()}
    for k, text in enumerate((BEFORE, AFTER)):
        folder = tmp_path / f"v{k}"
        folder.mkdir()
        (folder / "robot.toml").write_text(TUTORIAL_ROBOT)
        (folder / "table.csv").write_text(text)
        scene = scene_of(folder / "table.csv")
        result = simulate(scene, 20.0)
        summary = summarise(result)
        trajectory = drawn(plots.trajectory_figure, result, summary)
        for handle in trajectory.legends[0].legend_handles:
            assert isinstance(handle, Patch)  # a state's entry is a coloured patch
            seen[str(handle.get_label()).split("  (")[0]].add(to_hex(handle.get_facecolor()))
        timeline = drawn(plots.timeline_figure, result, summary)
        bars = [c for c in timeline.axes[0].collections if isinstance(c, PolyCollection)]
        labels = [t.get_text() for t in timeline.axes[0].get_yticklabels()]
        for bar in bars:
            row = round(np.asarray(bar.get_paths()[0].vertices)[:, 1].mean())
            seen[labels[row]].add(to_hex(tuple(np.asarray(bar.get_facecolor())[0])))
        with literal_text():
            player = Player(trajectory, result, summary, 50, 1.0)  # the gif's and the window's trail
        for tick, colour in zip(range(0, result.ticks, 50), player.colours, strict=False):
            state = scene.machine.states[result.states[tick]]
            seen[scene.table.state_title(state)].add(to_hex(colour))
        dot = CliRunner().invoke(app, ["diagram", str(folder), "--format", "dot"]).output
        for state in (1, 2):
            seen[scene.table.state_title(state)].add(dot.split(f"s_{state} [label=")[1].split('color="')[1][:7])
    assert seen == {"1 · turning": {PALETTE[0]}, "2 · driving": {PALETTE[1]}}


def test_colours_go_by_the_state_not_its_place() -> None:
    assert state_colours([2, 1]) == state_colours([1, 2])[::-1]
    assert state_colours([1, 2, 3])[:2] == state_colours([1, 2]) == state_colours([1, 2, 40])[:2]
    named = state_colours(["wait", "drive", "follow"])  # names that ask for three different slots
    assert len(set(named)) == 3 and state_colours(["follow", "wait"]) == [named[2], named[0]]
    assert len(set(state_colours(["seek", "back", "turn", "search"]))) == 4  # four that ask for one slot
    assert len(set(state_colours(list(range(1, 17))))) == 16  # no two states of a table share one
    assert len(set(state_colours([1, 17, 33]))) == 3  # states asking for one slot are told apart


def test_legends_list_only_what_the_picture_shows(tmp_path: Path) -> None:
    empty = tmp_path / "empty"
    empty.mkdir()
    (empty / "robot.toml").write_text(TUTORIAL_ROBOT.replace('2 = "driving"\n', ""))
    (empty / "table.csv").write_text("description,state,T,I1,M1,M2,timer,next\nspin,1,1,,0,0,0,1\n")
    (empty / "arena.toml").write_text("[arena]\nwalls = [[0, 0], [2, 0], [2, 2], [0, 2]]\n[start]\nat = [1, 1]\n")
    result = simulate(scene_of(empty / "table.csv"), 5.0)
    fig = drawn(plots.trajectory_figure, result, summarise(result))
    states, marks = ([t.get_text() for t in legend.get_texts()] for legend in fig.legends)
    assert states == ["1 · turning  (5.0 s)"]  # the one state it was in
    assert marks == []  # no collision, no spin, no lamp, no obstacle, no tape: nothing to explain
    result = simulate(scene_of(BUMBERBOT / "table.csv"), 60.0)
    fig = drawn(plots.trajectory_figure, result, summarise(result))
    marks = [t.get_text() for t in fig.legends[1].get_texts()]
    assert "collision (where it touched)" in marks and "light first seen" in marks
    assert "obstacle" in marks  # the arena's box


def test_a_followed_line_shows_its_path_above_the_tape() -> None:
    result = simulate(scene_of(ROOT / "examples" / "line-follower" / "table.csv"), 20.0)
    fig = drawn(plots.trajectory_figure, result, summarise(result))
    ax = fig.axes[0]
    (tape,) = [c for c in ax.collections if isinstance(c, PatchCollection)]
    path = next(c for c in ax.collections if isinstance(c, LineCollection))
    assert path.get_zorder() > tape.get_zorder()
    canvas = cast(FigureCanvasAgg, fig.canvas)  # the pictures are drawn on an Agg canvas
    pixels = np.asarray(canvas.buffer_rgba())
    rows = result.kept_rows()
    x, y = ax.transData.transform(rows[len(rows) // 3, :2])
    near = {
        tuple(pixels[len(pixels) - round(y) + dy, round(x) + dx, :3].tolist()) for dx in (-1, 0, 1) for dy in (-1, 0, 1)
    }
    path_colours = {tuple(round(255 * v) for v in c[:3]) for c in np.asarray(path.get_colors()).tolist()}
    assert near & path_colours, (near, path_colours)  # the path's own colour, drawn over the tape


def test_diagram_pngs_are_sharp_enough_to_read(tmp_path: Path) -> None:
    """The tutorial's two-state diagram was 366×598 px: 9-point labels a few pixels high."""
    (tmp_path / "robot.toml").write_text(TUTORIAL_ROBOT)
    (tmp_path / "table.csv").write_text(BEFORE)
    out = tmp_path / "d.png"
    assert CliRunner().invoke(app, ["diagram", str(tmp_path), "--out", str(out)]).exit_code == 0
    width, height = Image.open(out).size
    assert width >= 1.5 * 366 and height >= 1.5 * 598


def test_names_are_drawn_printable_and_as_written(tmp_path: Path) -> None:
    """A name with a line break, a bell and an escape drew missing glyphs (and a second title line); a
    name between two $ stays as written."""
    shutil.copytree(BUMBERBOT, tmp_path / "bot")
    robot = tmp_path / "bot" / "robot.toml"
    text = robot.read_text().replace('name = "BumberBot"', 'name = "Bot\\nFAKE \\u0007\\u001b[31m $x^2$"')
    robot.write_text(text.replace('1 = "Seek: drive straight"', '1 = "drive\\r\\u0000"'))
    figures = []

    def keeping(encode: Callable[[Figure], bytes]) -> Callable[[Figure], bytes]:
        def keep(fig: Figure) -> bytes:
            figures.append(fig)
            return encode(fig)

        return keep

    with warnings.catch_warnings(record=True) as caught, pytest.MonkeyPatch.context() as patch:
        warnings.simplefilter("always")
        patch.setattr(os, "cpu_count", lambda: 1)  # no painter: both pictures drawn in this process, seen here
        patch.setattr(plots, "png_bytes", keeping(plots.png_bytes))
        patch.setattr(plots, "encoded", keeping(plots.encoded))  # the trajectory's PNG
        finish = timeline.TimelinePicture.finish  # the timeline's PNG is put together from bands: seen as drawn

        def finishing(self: TimelinePicture, *args: Any, **kwargs: Any) -> TimelinePicture:
            figures.append(self.fig)
            return finish(self, *args, **kwargs)

        patch.setattr(timeline.TimelinePicture, "finish", finishing)
        result = CliRunner().invoke(
            app, ["sim", str(tmp_path / "bot"), "--seconds", "3", "-q", "--gif", "--out", str(tmp_path / "o")]
        )
    assert result.exit_code == 0, result.output
    assert len({id(fig) for fig in figures}) >= 2, "both pictures' figures are looked at"
    assert not [w for w in caught if "missing from" in str(w.message)], [str(w.message) for w in caught]
    texts = [t.get_text() for fig in figures for t in fig.findobj(Text)]
    assert any("Bot\\nFAKE \\x07\\x1b[31m $x^2$ in" in t for t in texts)
    assert any("1 · drive\\r\\x00" in t for t in texts)
    assert not [t for t in texts if any(c in t for c in "\x00\x07\x1b\r")]
