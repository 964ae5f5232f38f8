"""The pictures in the reader's language (issue 38): titles, axes, legends and notes of the trajectory and the
timeline, read back from the drawn figures' text artists, and a whole `tablebot sim --lang de` run's pictures."""

from __future__ import annotations

import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

import pytest
from matplotlib.figure import Figure
from matplotlib.text import Text

from tablebot import i18n
from tablebot.sim.pictures.plots import timeline_figure, trajectory_figure
from tablebot.sim.runner import SimRun, simulate
from tablebot.sim.summary import summarise
from test_sim_helpers import BUMBERBOT, ROOT, scene_of

#: Texts each picture shows, English and German (the catalog's words: Zustand, Startwert, Schwelle ...).
TRAJECTORY = {
    "en": ["seed 1", "path colour = state (time in it)", "m driven", "lamp reached: never", "obstacle"],
    "de": ["Startwert 1", "Farbe der Bahn = Zustand (Zeit darin)", "m gefahren", "Lampe erreicht: nie", "Hindernis"],
}
TIMELINE = {
    "en": ["time (s)", "state", "events", "threshold", "motor speed\n(+ forward)", "(red lines: collisions"],
    "de": ["Zeit (s)", "Zustand", "Ereignisse", "Schwelle", "Motortempo\n(+ vorwärts)", "(rote Linien:"],
}


@pytest.fixture(scope="module")
def run() -> SimRun:
    return simulate(scene_of(ROOT / "examples" / "bumberbot" / "table.csv"), 3.0)


def drawn(language: str, run: SimRun, picture: str) -> list[str]:
    """Every text the picture draws (title, notes, axis labels, ticks, legends), in ``language``."""
    i18n.use(language)
    try:
        draw = trajectory_figure if picture == "trajectory" else timeline_figure
        fig = draw(run, summarise(run))
    finally:
        i18n.use("en")
    return [t.get_text() for t in texts(fig)]


def texts(fig: Figure) -> Iterator[Text]:
    return (t for t in fig.findobj(Text) if isinstance(t, Text) and t.get_text())


@pytest.mark.parametrize("language", ["en", "de"])
@pytest.mark.parametrize(("picture", "expected"), [("trajectory", TRAJECTORY), ("timeline", TIMELINE)])
def test_a_picture_speaks_the_readers_language(
    run: SimRun, language: str, picture: str, expected: dict[str, list[str]]
) -> None:
    words = "\n".join(drawn(language, run, picture))
    other = "de" if language == "en" else "en"
    assert all(w in words for w in expected[language]), words
    assert not any(w in words for w in expected[other] if w not in expected[language]), words


#: The table's and robot's own words in the BumberBot's pictures (names, state titles, sensor labels), and units.
THEIRS = (
    "BumberBot",
    "arena",
    "M1",
    "M2",
    "T",
    "I3",
    "I4",
    "I5",
    "I7",
    "I8",
    "Seek:",
    "drive",
    "straight",
    "turn",
    "right",
    "left",
    "front-right",
    "front-left",
    "rear",
    "bumper",
    "phototransistor",
    "motor)",
    "(right",
    "(left",
    "timer",
    "s",
    "s)",
    "m",
    "x",
    "y",
    "(m)",
)


def unmarked(text: str) -> list[str]:
    """The words of ``text`` outside the pseudo-locale's markers (a marked text's arguments are inside them)."""
    while i18n.PSEUDO_OPEN in text:
        start = text.index(i18n.PSEUDO_OPEN)
        text = text[:start] + text[text.index(i18n.PSEUDO_CLOSE, start) + 1 :]
    return [w for w in text.split() if any(c.isalpha() for c in w)]


@pytest.mark.parametrize("picture", ["trajectory", "timeline"])
def test_every_word_of_a_picture_is_translated(run: SimRun, picture: str) -> None:
    """In the pseudo-locale every text tablebot wrote is between markers; what stands outside is the table's
    and robot's own words, numbers and units."""
    outside = [t for t in drawn(i18n.PSEUDO, run, picture) if set(unmarked(t)) - set(THEIRS)]
    assert not outside, outside


def test_sim_with_lang_de_draws_german_pictures(tmp_path: Path) -> None:
    """The whole command: the painter (a fork made as the command starts) draws in the language --lang chose.
    The same run in English and German differs in the pictures' words only: same trace, other PNG bytes."""
    pictures = {}
    for language in ("en", "de"):
        out = tmp_path / language
        subprocess.run(
            [
                sys.executable,
                "-m",
                "tablebot",
                "--lang",
                language,
                "sim",
                str(BUMBERBOT),
                "--seconds",
                "2",
                "--out",
                str(out),
                "-q",
            ],
            check=True,
            capture_output=True,
            timeout=120,
        )
        pictures[language] = {n: (out / n).read_bytes() for n in ("trace.jsonl", "trajectory.png", "timeline.png")}
    assert pictures["en"]["trace.jsonl"] == pictures["de"]["trace.jsonl"]
    assert pictures["en"]["trajectory.png"] != pictures["de"]["trajectory.png"]
    assert pictures["en"]["timeline.png"] != pictures["de"]["timeline.png"]


def test_the_leaderboard_speaks_the_readers_language(tmp_path: Path) -> None:
    """grade's leaderboard.html: its headings, the line under the title, a score's spread, the replays' buttons
    and the viewer in German (the page says lang="de"); scores.csv, a data file, stays as it is."""
    from typer.testing import CliRunner

    from tablebot.cli import app

    pupil = tmp_path / "anna"
    pupil.mkdir()
    (pupil / "table.csv").write_bytes((ROOT / "tests" / "fixtures" / "analysis" / "bumberbot_fixed.csv").read_bytes())
    i18n.use("de")
    try:
        result = CliRunner().invoke(
            app,
            [
                "grade",
                str(ROOT / "examples" / "challenges" / "find-the-lamp"),
                str(pupil),
                "--out",
                str(tmp_path / "out"),
            ],
        )
    finally:
        i18n.use("en")
    assert result.exit_code == 0, result.output
    page = (tmp_path / "out" / "leaderboard.html").read_text(encoding="utf-8")
    head = page[: page.index("<script")]  # the board, not the packed replays
    for german in (
        '<html lang="de">',
        "Rangliste</title>",
        "<th>Platz</th>",
        "<th>Punkte</th>",
        "<th>Regeln</th>",
        "1 Einreichung, gefahren auf",
        "(niedrig ist besser)",
        " bis ",
        "▶ beste: Startwert",
        "schließen (Esc)",
    ):
        assert german in page, german
    for english in ("leaderboard", "<th>rank", "submission", "is better", " to ", "seed ", "close"):
        assert english not in head, english
    assert (tmp_path / "out" / "scores.csv").read_text(encoding="utf-8").startswith("rank,name,score,why\n")


def test_sweeps_pictures_speak_the_readers_language(tmp_path: Path) -> None:
    """sweep's outcomes and starts: titles, axes, notes and legend in German, and no English left in them."""
    from typer.testing import CliRunner

    from tablebot.cli import app
    from tablebot.fleet.plan import make_plan, read_results
    from tablebot.fleet.plots import outcomes_figure, starts_figure

    out = tmp_path / "s"
    result = CliRunner().invoke(
        app,
        [
            "sweep",
            str(BUMBERBOT),
            "--seeds",
            "0..3",
            "--seconds",
            "1",
            "--workers",
            "1",
            "--out",
            str(out),
            "--no-plots",
        ],
    )
    assert result.exit_code == 0, result.output
    plan, rows = make_plan(BUMBERBOT, None, [], [], "0..3", None, 1.0), read_results(out / "results.csv")
    words = {}
    for language in ("en", "de"):
        i18n.use(language)
        try:
            figures = (outcomes_figure(plan, rows), starts_figure(plan, rows))
        finally:
            i18n.use("en")
        words[language] = "\n".join(t.get_text() for fig in figures for t in texts(fig))
    english = [
        "4 runs of 1 s",
        "reached the lamp (%)",
        "never: 4",
        "time to first light (s)",
        "Start positions in",
        "0 of 4 reached the lamp",
        "never reached the lamp",
    ]
    german = [
        "4 Fahrten zu je 1 s",
        "erreichten die Lampe (%)",
        "nie: 4",
        "Zeit bis zum ersten Licht (s)",
        "Startpositionen in",
        "0 von 4 erreichten die Lampe",
        "erreichte die Lampe nie",
    ]
    assert all(w in words["en"] for w in english), words["en"]
    assert all(w in words["de"] for w in german) and not any(w in words["de"] for w in english), words["de"]


def test_tunes_convergence_picture_speaks_the_readers_language(tmp_path: Path) -> None:
    """tune's convergence.png: a real evaluator runs three candidates of one timer cell on the fleet; the
    picture drawn from its history has German title, axes and legend."""
    from tablebot.api.tune_files import convergence_figure
    from tablebot.fleet.backends import Runner
    from tablebot.fleet.plan import make_plan
    from tablebot.fleet.tune import Evaluator, parse_cells

    plan = make_plan(BUMBERBOT, None, [], [], "0", None, 1.0)
    cells = parse_cells("line 2 timer=100..300", plan.table)
    with Runner("local", None, 1) as runner:
        evaluate = Evaluator(plan, cells, "distance_m", runner)
        evaluate([(100,), (200,), (300,)])
    words = {}
    for language in ("en", "de"):
        i18n.use(language)
        try:
            words[language] = "\n".join(t.get_text() for t in texts(convergence_figure(evaluate, "grid")))
        finally:
            i18n.use("en")
    english = ["grid: 3 candidates", "evaluation", "best so far", "the table as it was", "(ticks)"]
    german = ["grid: 3 Kandidaten", "Bewertung", "bisher bester", "die ursprüngliche Tabelle", "(Takte)"]
    assert all(w in words["en"] for w in english), words["en"]
    assert all(w in words["de"] for w in german) and not any(w in words["de"] for w in english), words["de"]


def test_view_without_a_window_says_so_in_german(tmp_path: Path) -> None:
    """sim --view where no window can open: the error and its hint in the reader's language."""
    import os

    done = subprocess.run(
        [
            sys.executable,
            "-m",
            "tablebot",
            "--lang",
            "de",
            "sim",
            str(BUMBERBOT),
            "--seconds",
            "1",
            "--view",
            "--out",
            str(tmp_path / "o"),
        ],
        capture_output=True,
        text=True,
        timeout=60,
        env={**os.environ, "MPLBACKEND": "agg"},
    )
    assert done.returncode != 0
    assert "--view: Fehler: hier lässt sich kein Fenster öffnen" in done.stderr + done.stdout
    assert "Tipp: ohne --view starten und die Bilder öffnen" in done.stderr + done.stdout
