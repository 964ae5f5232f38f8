"""Numbers as the reader writes them (issue 38): a decimal comma and a thousands point in German, Python's
point in English and the pseudo-locale; a file's own syntax (a robot file's range, a value it echoes) keeps
the point in every language, because that is what the reader must type."""

from __future__ import annotations

from pathlib import Path

import pytest

from tablebot.diagnostics import TableBotError
from tablebot.i18n import N_, localise, number, use
from tablebot.tomlfile import Source
from tablebot.tomlfile import number as file_number

ROOT = Path(__file__).resolve().parents[2]

pytestmark = [pytest.mark.kernel_free]


def test_number_in_each_language() -> None:
    assert number(29.23, ".1f", "de") == "29,2" and number(29.23, ".1f", "en") == "29.2"
    assert number(12000, ",", "de") == "12.000" and number(12000, ",", "en") == "12,000"
    assert number(-0.1234, "+.3f", "de") == "-0,123" and number(0.5, language="de") == "0,5"
    assert number(0.5, ".0%", "de") == "50%" and number(0.5, language="pseudo") == "0.5"


def test_number_follows_the_language_in_use() -> None:
    try:
        use("de")
        assert number(1.5, ".2f") == "1,50"
    finally:
        use("en")
    assert number(1.5, ".2f") == "1.50"


def test_a_message_renders_its_numbers_in_the_readers_language() -> None:
    message = N_("ran {ticks} ticks ({seconds:.2f} s): {reason}", ticks=1500, seconds=1.5, reason="done")
    assert message == "ran 1500 ticks (1.50 s): done"  # its English value (logs, JSON) keeps the point
    assert "(1,50 s)" in message.render("de")
    assert "1.50" in message.render("pseudo")


def test_a_robot_files_range_keeps_its_point_in_german(tmp_path: Path) -> None:
    src = Source.parse(tmp_path / "robot.toml", "[robot]\nwheel = 9.5\n")
    assert file_number(src, ("robot", None, "wheel"), 9.5, 0.01, 0.5) is None
    with pytest.raises(TableBotError) as caught:
        src.raise_if_any()
    said = " ".join(f"{localise(d.message, 'de')} {localise(d.hint, 'de')}" for d in caught.value.diagnostics)
    assert "9.5" in said and "0.01..0.5" in said and "0,01" not in said, said


def test_a_translated_texts_format_writes_the_readers_numbers() -> None:
    """``_("...{rate:.2f}...").format(rate=...)``, the way most of the command line fills its texts."""
    import numpy as np

    from tablebot.i18n import _, ngettext

    try:
        use("de")
        assert _("message too large ({n:,} characters)").format(n=12000) == "Nachricht zu groß (12.000 Zeichen)"
        assert _("simulated {seconds:.1f} s").format(seconds=np.float64(5)) == "5,0 s simuliert"
        assert ngettext("{n} tick", "{n} ticks", 2).format(n=12000) == "12000 Takte"
    finally:
        use("en")
    assert _("simulated {seconds:.1f} s").format(seconds=5) == "simulated 5.0 s"


def test_sims_summary_in_german(tmp_path: Path) -> None:
    from tablebot.sim.summary import Summary

    summary = Summary(
        seconds=120.0,
        first_light_s=None,
        reached_s=1.5,
        collisions=1,
        collision_ticks=(3,),
        distance_m=2.79,
        state_seconds={1: 120.0},
        battery_start_v=9.05,
        battery_end_v=8.9,
    )
    try:
        use("de")
        german = "\n".join(summary.lines())
    finally:
        use("en")
    assert "120,0 s simuliert" in german and "2,79 m" in german and "9,05 V -> 8,90 V" in german, german
    assert "1,50 s" in german and "100,0 %" in german and "120.0" not in german, german
    assert "distance driven:  2.79 m" in "\n".join(summary.lines())


def test_a_diagrams_timer_in_german() -> None:
    from test_i18n_catalog import run_in

    bumberbot = str(Path(__file__).resolve().parents[2] / "examples" / "bumberbot")
    assert "1,5 s" in run_in("de", ["diagram", bumberbot, "--format", "mermaid"])
    assert "1.5 s" in run_in("en", ["diagram", bumberbot, "--format", "mermaid"])


def test_an_evolved_rows_description_in_german() -> None:
    """A table evolve writes says in each changed row's description what changed, in the reader's language."""
    from dataclasses import replace

    from tablebot.evolve import space
    from tablebot.evolve.report import describe
    from tablebot.formats.table_read import load_table

    table = load_table(str(Path(__file__).resolve().parents[2] / "examples" / "bumberbot" / "table.csv"))
    gene = next(g for g in space.start(table) if g.timer)
    changed = replace(gene, timer=gene.timer + 5, motors=(None, *gene.motors[1:]))
    try:
        use("de")
        german = describe(changed, table)
    finally:
        use("en")
    assert "entwickelt:" in german and f"Timer {gene.timer}->{gene.timer + 5}" in german, german
    assert "evolved:" in describe(changed, table)


def test_a_pictures_axes_write_the_readers_numbers() -> None:
    """A picture's numbered axes read 0,5 in German (evolve's archive, tune's convergence, sim's pictures);
    an axis labelled otherwise (state names) keeps its labels."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    from tablebot.sim.pictures.picture import readers_numbers

    def labels(language: str) -> tuple[list[str], list[str]]:
        fig = Figure()
        FigureCanvasAgg(fig)
        ax = fig.add_subplot()
        ax.plot([0, 0.5, 1.0], [0, 1, 2])
        ax.set_yticks([0, 1, 2], ["a", "b", "c"])
        try:
            use(language)
            readers_numbers(fig)
        finally:
            use("en")
        fig.canvas.draw()
        return [t.get_text() for t in ax.get_xticklabels()], [t.get_text() for t in ax.get_yticklabels()]

    german, english = labels("de"), labels("en")
    assert "0,4" in german[0] and "0.4" not in german[0] and german[1] == ["a", "b", "c"], german
    assert "0.4" in english[0], english


def test_speaking_is_one_threads_language_and_ends_with_its_block() -> None:
    """The studio draws a German tab's diagram in a thread while the process (and another tab) speaks English:
    the language of :func:`speaking` holds in its thread's block alone."""
    import threading

    from tablebot.i18n import current, speaking

    use("en")  # the process's language, as a command's main() leaves it
    seen: dict[str, str] = {}

    def german() -> None:
        with speaking("de"):
            seen["inside"] = number(0.5)
            barrier.wait(5)  # the main thread reads its language while this block still speaks German
            barrier.wait(5)
        seen["after"] = number(0.5)

    barrier = threading.Barrier(2)
    worker = threading.Thread(target=german)
    worker.start()
    barrier.wait(5)
    seen["main"] = f"{current()} {number(0.5)}"
    barrier.wait(5)
    worker.join(5)
    assert seen == {"inside": "0,5", "main": "en 0.5", "after": "0.5"}
    with pytest.raises(ValueError, match="xx"), speaking("xx"):
        pass


def test_a_bound_the_reader_types_next_keeps_its_point_in_german() -> None:
    """The command line reads 0.01, not 0,01: a German hint that says which values an option takes writes them
    as they are typed (a range error's message and hint, --grid's), though its other numbers are German."""
    import subprocess
    import sys

    def german(*args: str) -> str:
        run = [sys.executable, "-m", "tablebot", "--lang", "de", *args]
        done = subprocess.run(run, capture_output=True, text=True, timeout=120, cwd=ROOT)
        assert done.returncode != 0, done.stdout
        return done.stderr

    said = german("sim", str(ROOT / "examples" / "bumberbot"), "--seconds", "99999")
    assert "von 0.01 bis 3600" in said and "0,01" not in said, said
    said = german("sweep", str(ROOT / "examples" / "bumberbot"), "--robots", "2", "--grid", "battery=7")
    assert "von 0.0 bis 1.0" in said and "0,0" not in said, said
